//! The label files of a finished dataset: `truth.csv`, `coco.json`, `metadata.jsonl`.

use std::path::Path;

use tirroi_core::Roi;

use super::DatasetError;
use super::images::{ImageRecord, atomic_write};
use crate::world::scene::SceneFile;

/// The header line of `truth.csv` (with its newline): the box, the group and metadata
/// columns, the quarter-coverage box, the signal-to-clutter ratio and the target's
/// visible share ([`crate::dataset`] module docs). Test sets ([`crate::dataset::testset`]) write the same.
pub const TRUTH_CSV_HEADER: &str = "file,x0,y0,x1,y1,mode,scale,target,material,illumination,range_m,earth_fraction,noise_seed,bits,x0_quarter,y0_quarter,x1_quarter,y1_quarter,signal_to_clutter,visible_share\n";

/// The columns `truth.csv` ends with when the dataset has approach sequences (scene
/// `sequence`), after [`TRUTH_CSV_HEADER`]'s: the sequence (0, 1, …) and the frame in
/// it, empty for an image outside one. `tirroi eval --track sequence` starts each
/// sequence without a prior.
pub const SEQUENCE_COLUMNS: &str = ",sequence,frame";

/// Writes `truth.csv`, `coco.json` and `metadata.jsonl` (each atomically).
pub(super) fn write_labels<'a>(
    file: &SceneFile,
    dir: &Path,
    records: impl Iterator<Item = &'a ImageRecord>,
) -> Result<(), DatasetError> {
    // Sequences add their two columns (every other dataset keeps its bytes).
    let sequences = file.scenes.iter().any(|s| s.sequence.is_some());
    let mut csv = String::from(TRUTH_CSV_HEADER.trim_end());
    if sequences {
        csv.push_str(SEQUENCE_COLUMNS);
    }
    csv.push('\n');
    let mut jsonl = String::new();
    let mut images = Vec::new();
    let mut annotations = Vec::new();
    // An empty box (no target in view) is written as empty fields: no target.
    let boxed = |b: [u16; 4]| {
        if Roi::new(b[0], b[1], b[2], b[3]).is_empty() {
            ",,,".to_string()
        } else {
            format!("{},{},{},{}", b[0], b[1], b[2], b[3])
        }
    };
    for r in records {
        let [x0, y0, x1, y1] = r.bbox;
        csv.push_str(&format!(
            "{},{},{},{},{},{},{},{:.3},{:.4},{},{},{},{},{}",
            r.file,
            boxed(r.bbox),
            r.mode,
            r.scale.map_or(String::new(), |s| s.to_string()),
            r.target,
            r.material.as_deref().unwrap_or(""),
            r.illumination,
            r.range_m,
            r.earth_fraction,
            r.noise_seed.map_or(String::new(), |s| s.to_string()),
            r.bits,
            boxed(r.bbox_quarter),
            r.signal_to_clutter
                .map_or(String::new(), |s| format!("{s:.4}")),
            r.visible_share.map_or(String::new(), |s| format!("{s:.4}")),
        ));
        if sequences {
            // `,sequence,frame`, empty outside a sequence.
            let opt = |v: Option<usize>| v.map_or(String::new(), |v| v.to_string());
            csv.push_str(&format!(",{},{}", opt(r.sequence), opt(r.frame)));
        }
        csv.push('\n');
        jsonl.push_str(&serde_json::to_string(r).map_err(|e| DatasetError(e.to_string()))?);
        jsonl.push('\n');
        images.push(serde_json::json!({
            "id": r.index + 1,
            "file_name": r.file,
            "width": file.camera.width,
            "height": file.camera.height,
        }));
        let roi = Roi::new(x0, y0, x1, y1);
        if !roi.is_empty() {
            annotations.push(serde_json::json!({
                "id": r.index + 1,
                "image_id": r.index + 1,
                "category_id": 1,
                "bbox": [x0, y0, roi.width(), roi.height()],
                "area": r.mask_px,
                "iscrowd": 0,
            }));
        }
    }
    let coco = serde_json::json!({
        "info": {
            "description": format!("tirroi synthetic thermal-infrared dataset `{}`", file.dataset.name),
            "version": env!("CARGO_PKG_VERSION"),
        },
        "images": images,
        "annotations": annotations,
        "categories": [{"id": 1, "name": "spacecraft", "supercategory": "target"}],
    });
    let coco = serde_json::to_string(&coco).map_err(|e| DatasetError(e.to_string()))?;
    atomic_write(&dir.join("truth.csv"), csv.as_bytes())?;
    atomic_write(&dir.join("coco.json"), coco.as_bytes())?;
    atomic_write(&dir.join("metadata.jsonl"), jsonl.as_bytes())?;
    Ok(())
}
