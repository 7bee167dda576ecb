//! Labelled datasets: a [`SceneFile`] becomes a plan of images (poses, Earth geometry,
//! thermal state, seeds), the shared pieces (meshes, thermal solutions, Earth maps) are
//! computed once, and the images render in parallel into a directory:
//!
//! - `NNNNNN.png`: 16-bit grayscale DN (the core's sensor model);
//! - `truth.csv`: `file,x0,y0,x1,y1` then metadata columns (the box: (x0, y0)
//!   inclusive, (x1, y1) exclusive, the tight box of the pixels whose target coverage
//!   is ≥ `[dataset] truth_coverage`, ½ by default; four empty fields when there is no
//!   target), then `x0_quarter..y1_quarter` (coverage > ¼), `signal_to_clutter` and
//!   `visible_share` (`imaging::render::clutter`);
//! - `coco.json`: COCO detection labels (one category, `spacecraft`; no annotation for
//!   a frame without a target);
//! - `metadata.jsonl`: one JSON object per image (pose, mode, scale, material,
//!   illumination, Earth fraction, seeds, DN map, noise σ, target temperatures, both
//!   boxes, the signal-to-clutter ratio and its parts, the visible box and share;
//!   [`ImageRecord`]);
//! - `masks/NNNNNN.png` (optional): 8-bit target coverage, 255 = fully covered;
//! - `preview/NNNNNN.png` (optional): contrast-stretched 8-bit RGB with the truth box.
//!
//! Determinism: every image's parameters derive from the dataset seed and its index
//! alone, so the bytes do not depend on the thread count. Safety: each file is written
//! to a temporary name and renamed; finished images are journalled in `progress.jsonl`,
//! and the label files are written (atomically) only when all images are done, so a
//! stopped run leaves no label file describing missing images, and `--resume` continues
//! where it stopped.

use std::collections::BTreeMap;
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use indicatif::ProgressBar;
use rayon::prelude::*;

use crate::imaging::render::RenderStats;
use crate::progress;
use crate::world::scene::SceneFile;

mod images;
mod labels;
mod library;
mod manifest;
mod memory;
mod merge;
mod plan;
pub mod testset;

pub use images::ImageRecord;
pub use labels::TRUTH_CSV_HEADER;
pub use library::{Library, ThermalState};
pub use manifest::{
    JOURNAL_FILE, LABEL_FILES, MANIFEST_FILE, MAX_SHARDS, Manifest, OutState, Outputs, RunSource,
    Shard, clear_run, inspect, quote, sha256_hex,
};
pub use memory::{FrameRenderer, LabelledFrame};
pub use merge::merge;
pub use plan::{EDGE_CUT_KEEP_PX, ImagePlan, MoonPlan, ThermalKey, keep_in_view, plan};

use images::write_image;
use labels::write_labels;

/// Why a dataset could not be made.
#[derive(Debug)]
pub struct DatasetError(pub String);

impl std::fmt::Display for DatasetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DatasetError {}

/// Options of a dataset run.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// Also write `masks/`.
    pub masks: bool,
    /// Also write `preview/`.
    pub preview: bool,
    /// Skip images already journalled in `progress.jsonl`.
    pub resume: bool,
    /// Show a progress bar.
    pub progress: bool,
    /// Render only this part of the dataset (`None`: all of it); the label files then
    /// list its images only, and `tirroi merge` joins the parts.
    pub shard: Option<Shard>,
}

/// Totals of a dataset run.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Images rendered in this run.
    pub rendered: usize,
    /// Images skipped (resumed).
    pub skipped: usize,
    /// Wall-clock seconds: library build, rendering + writing, labels.
    pub wall_s: [f64; 3],
    /// Library build seconds per part: meshes, thermal, Earth maps.
    pub library_s: [f64; 3],
    /// Distinct meshes, thermal solutions and Earth maps.
    pub library_counts: (usize, usize, usize),
    /// Summed per-image CPU time per stage, s: target, Earth, optics PSF + sensor
    /// signature, expose (DN + noise), PNG encode + write, signal-to-clutter twin.
    pub stage_cpu_s: [f64; 6],
    /// Summed per-image time outside those stages, s: the frame's set-up (buffers, DN
    /// map, noise scale), its record and mask count, the journal line.
    pub other_cpu_s: f64,
    /// Worker threads the images were rendered on (rayon's pool size).
    pub threads: usize,
}

/// Renders every image of `file` into `dir` with labels (module docs).
///
/// # Errors
/// [`DatasetError`] for unwritable outputs, bad Earth sources, or an image that cannot
/// be rendered (named).
pub fn write_dataset(
    file: &SceneFile,
    dir: &Path,
    options: &WriteOptions,
) -> Result<RunSummary, DatasetError> {
    let t0 = Instant::now();
    let io = |p: &Path, e: std::io::Error| DatasetError(format!("{}: {e}", p.display()));
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    for (on, sub) in [(options.masks, "masks"), (options.preview, "preview")] {
        if on {
            let p = dir.join(sub);
            fs::create_dir_all(&p).map_err(|e| io(&p, e))?;
        }
    }
    let plans = plan(file);
    let journal_path = dir.join(JOURNAL_FILE);
    let mut done: BTreeMap<usize, ImageRecord> = BTreeMap::new();
    if options.resume && journal_path.exists() {
        let f = File::open(&journal_path).map_err(|e| io(&journal_path, e))?;
        for line in BufReader::new(f).lines().map_while(Result::ok) {
            if let Ok(rec) = serde_json::from_str::<ImageRecord>(&line) {
                if dir.join(&rec.file).exists() {
                    done.insert(rec.index, rec);
                }
            }
        }
    }
    let mine = |i: usize| options.shard.is_none_or(|s| s.contains(i));
    done.retain(|&i, _| mine(i));
    let todo: Vec<&ImagePlan> = plans
        .iter()
        .filter(|p| mine(p.index) && !done.contains_key(&p.index))
        .collect();
    // The whole dataset's library even for a shard: its pieces (the first day's mean
    // Earth flux, the Earth distance, transient orbits) depend on every plan, and a
    // shard's frames must be the single run's bytes.
    let library = Library::build(file, &plans)?;
    let t1 = Instant::now();

    let journal = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&journal_path)
        .map_err(|e| io(&journal_path, e))?;
    let journal = Mutex::new(journal);
    let bar = if options.progress {
        progress::bar(todo.len(), "images")
    } else {
        ProgressBar::hidden()
    };
    let results: Vec<Result<(ImageRecord, RenderStats, f64, f64), DatasetError>> = todo
        .par_iter()
        .map(|plan| {
            let start = Instant::now();
            let (frame, thermal) = library.render(file, plan)?;
            let (rec, write_s) = write_image(dir, file, plan, &frame, &thermal, options)?;
            let mut line = serde_json::to_string(&rec).map_err(|e| DatasetError(e.to_string()))?;
            line.push('\n');
            {
                let mut j = journal
                    .lock()
                    .map_err(|_| DatasetError("journal lock".into()))?;
                // One write per line: a stop leaves at most one torn line, skipped on
                // resume.
                j.write_all(line.as_bytes())
                    .map_err(|e| io(&journal_path, e))?;
            }
            bar.inc(1);
            Ok((rec, frame.stats, write_s, start.elapsed().as_secs_f64()))
        })
        .collect();
    bar.finish_and_clear();
    let mut summary = RunSummary {
        skipped: done.len(),
        library_s: library.build_s,
        library_counts: library.counts(),
        threads: rayon::current_num_threads(),
        ..RunSummary::default()
    };
    for r in results {
        let (rec, stats, write_s, image_s) = r?;
        summary.rendered += 1;
        let stages = [
            stats.target_ns as f64 * 1e-9,
            stats.earth_ns as f64 * 1e-9,
            stats.sensor_ns as f64 * 1e-9,
            stats.expose_ns as f64 * 1e-9,
            write_s,
            stats.clutter_ns as f64 * 1e-9,
        ];
        for (sum, v) in summary.stage_cpu_s.iter_mut().zip(stages) {
            *sum += v;
        }
        summary.other_cpu_s += (image_s - stages.iter().sum::<f64>()).max(0.0);
        done.insert(rec.index, rec);
    }
    let t2 = Instant::now();
    write_labels(file, dir, done.values())?;
    fs::remove_file(&journal_path).map_err(|e| io(&journal_path, e))?;
    summary.wall_s = [
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        t2.elapsed().as_secs_f64(),
    ];
    Ok(summary)
}

/// The output directory's label file, for callers that report it.
pub fn truth_path(dir: &Path) -> PathBuf {
    dir.join("truth.csv")
}
