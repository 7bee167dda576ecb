//! What the `auto-v2` examples share: the frames of a dataset directory from its
//! `metadata.jsonl` (any of `tirroi render`, `fixtures` or `testset`; their records
//! differ, so read as JSON values, not one record type).
use std::path::Path;

use tirroi_core::roi::Roi;

/// A frame of the dataset: file, bit depth, truth box (½ convention; `None` without a
/// target).
pub type Entry = (String, u8, Option<Roi>);

/// Every record of `dir/metadata.jsonl`, in its order, as JSON values; a missing file
/// or a line that is not JSON is one error line naming it, exit code 2.
pub fn metadata(dir: &Path) -> Vec<serde_json::Value> {
    let path = dir.join("metadata.jsonl");
    let meta = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        eprintln!("{}: {e}", path.display());
        std::process::exit(2)
    });
    meta.lines()
        .enumerate()
        .map(|(n, l)| {
            serde_json::from_str(l).unwrap_or_else(|e| {
                eprintln!("{}:{}: not JSON: {e}", path.display(), n + 1);
                std::process::exit(2)
            })
        })
        .collect()
}

/// Every frame of `dir/metadata.jsonl`, in its order ([`metadata`]); a record without
/// a `"file"` is one error line naming it, exit code 2.
pub fn frames(dir: &Path) -> Vec<Entry> {
    let path = dir.join("metadata.jsonl");
    metadata(dir)
        .into_iter()
        .enumerate()
        .map(|(n, v)| {
            let bbox = v["bbox"].as_array().and_then(|b| {
                let c: Vec<u16> = b
                    .iter()
                    .filter_map(|x| x.as_u64())
                    .map(|x| x as u16)
                    .collect();
                (c.len() == 4 && v["target"].as_str() != Some("none"))
                    .then(|| Roi::new(c[0], c[1], c[2], c[3]))
            });
            let Some(file) = v["file"].as_str() else {
                eprintln!("{}:{}: no \"file\"", path.display(), n + 1);
                std::process::exit(2)
            };
            (
                file.to_string(),
                v["bits"].as_u64().unwrap_or(14) as u8,
                bbox,
            )
        })
        .collect()
}
