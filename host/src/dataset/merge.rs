//! `tirroi merge`: joins the parts of a dataset rendered with `render --shard I/N`
//! (on several machines) into one directory whose bytes equal the single-machine run's:
//! frames, masks and previews are copied, the label files are written from the parts'
//! `metadata.jsonl` records in index order, by the same writer as a single run.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use super::DatasetError;
use super::images::ImageRecord;
use super::labels::write_labels;
use super::manifest::{Manifest, OutState, clear_run, inspect};
use crate::world::scene::SceneFile;

/// What a merge did.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeSummary {
    /// Images in the merged dataset.
    pub images: usize,
    /// Parts joined.
    pub parts: usize,
    /// The merged run's manifest.
    pub manifest: Manifest,
}

/// Joins `parts` (directories of `render --shard I/N` runs, any order) into `out`.
///
/// `out` follows the rules of `render --out`: new or empty, or a previous tirroi run
/// when `force` (its files are removed first).
///
/// # Errors
/// One actionable line, before anything is written to `out`: a part that is not a
/// tirroi run, unfinished, of another configuration, missing or given twice, a record
/// that does not belong to its part, or an output that is not free.
pub fn merge(out: &Path, parts: &[PathBuf], force: bool) -> Result<MergeSummary, DatasetError> {
    let err = |m: String| Err(DatasetError(m));
    if parts.is_empty() {
        return err("no PART directories given: expected the parts of `render --shard`".into());
    }
    let mut manifests = Vec::new();
    for p in parts {
        let Some(m) = Manifest::read(p)? else {
            return err(format!(
                "{}: no {} here, so not a tirroi run (or not a directory)",
                p.display(),
                super::MANIFEST_FILE
            ));
        };
        let Some(shard) = m.shard else {
            return err(format!(
                "{}: a whole dataset, not a part of one (rendered without --shard)",
                p.display()
            ));
        };
        if !m.complete {
            return err(format!(
                "{}: shard {shard} is unfinished; finish it first: {}",
                p.display(),
                m.command(p, true)
            ));
        }
        manifests.push((p, m, shard));
    }
    let (first_dir, first, first_shard) = &manifests[0];
    let mut seen: BTreeMap<usize, &PathBuf> = BTreeMap::new();
    for (p, m, shard) in &manifests {
        let same_shard = Manifest {
            shard: Some(*first_shard),
            ..m.clone()
        };
        let diff = first.differences(&same_shard);
        if !diff.is_empty() || shard.of != first_shard.of {
            let mut diff = diff;
            if shard.of != first_shard.of {
                diff.push(format!(
                    "it is split in {} parts, not {}",
                    shard.of, first_shard.of
                ));
            }
            return err(format!(
                "{} is not a part of the same dataset as {}: {}",
                p.display(),
                first_dir.display(),
                diff.join("; ")
            ));
        }
        if let Some(other) = seen.insert(shard.index, p) {
            return err(format!(
                "shard {shard} is given twice: {} and {}",
                other.display(),
                p.display()
            ));
        }
    }
    let missing: Vec<usize> = (0..first_shard.of)
        .filter(|i| !seen.contains_key(i))
        .collect();
    if let Some(&m0) = missing.first() {
        let names: Vec<String> = missing
            .iter()
            .map(|i| format!("{i}/{}", first_shard.of))
            .collect();
        let example = Manifest {
            shard: Some(super::Shard {
                index: m0,
                of: first_shard.of,
            }),
            ..first.clone()
        };
        return err(format!(
            "missing shard{} {} of {} parts; render each like: {}",
            if missing.len() > 1 { "s" } else { "" },
            names.join(", "),
            first_shard.of,
            example.command(Path::new(&format!("part-{m0}")), false)
        ));
    }
    let out_canon = out.canonicalize().ok();
    for (p, _, _) in &manifests {
        if out_canon.is_some() && p.canonicalize().ok() == out_canon {
            return err(format!(
                "--out {} is one of the parts; give a new directory",
                out.display()
            ));
        }
    }

    // Every part's records, each checked to belong to its part.
    let mut records: BTreeMap<usize, (ImageRecord, &Path)> = BTreeMap::new();
    for (p, _, shard) in &manifests {
        let path = p.join("metadata.jsonl");
        let text = fs::read_to_string(&path)
            .map_err(|e| DatasetError(format!("{}: cannot read: {e}", path.display())))?;
        for (n, line) in text.lines().enumerate() {
            let rec: ImageRecord = serde_json::from_str(line).map_err(|e| {
                DatasetError(format!(
                    "{}:{}: not an image record: {e}",
                    path.display(),
                    n + 1
                ))
            })?;
            if !shard.contains(rec.index) || rec.index >= first.count {
                return err(format!(
                    "{}:{}: image {} does not belong to shard {shard} of {} images",
                    path.display(),
                    n + 1,
                    rec.index,
                    first.count
                ));
            }
            records.insert(rec.index, (rec, p.as_path()));
        }
    }
    if records.len() != first.count {
        return err(format!(
            "the parts hold {} images, the dataset has {}: a part's metadata.jsonl is incomplete",
            records.len(),
            first.count
        ));
    }
    let file = SceneFile::parse(&first.scene, "the parts' tirroi-run.json")
        .map_err(|e| DatasetError(e.to_string()))?;

    match inspect(out)? {
        OutState::Free => {}
        OutState::Run(m) if force => {
            clear_run(out)?;
            drop(m);
        }
        OutState::Run(m) => {
            return err(format!(
                "--out {} holds a tirroi run ({}); add --force to replace it",
                out.display(),
                m.summary()
            ));
        }
    }
    let io = |p: &Path, e: std::io::Error| DatasetError(format!("{}: {e}", p.display()));
    fs::create_dir_all(out).map_err(|e| io(out, e))?;
    let merged = Manifest {
        shard: None,
        complete: false,
        ..first.clone()
    };
    merged.write(out)?;
    let mut subs = vec![""];
    if merged.outputs.masks {
        subs.push("masks");
    }
    if merged.outputs.preview {
        subs.push("preview");
    }
    for sub in &subs[1..] {
        let d = out.join(sub);
        fs::create_dir_all(&d).map_err(|e| io(&d, e))?;
    }
    for (rec, part) in records.values() {
        for sub in &subs {
            let from = part.join(sub).join(&rec.file);
            let to = out.join(sub).join(&rec.file);
            fs::copy(&from, &to).map_err(|e| {
                DatasetError(format!(
                    "{} -> {}: cannot copy: {e}",
                    from.display(),
                    to.display()
                ))
            })?;
        }
    }
    write_labels(&file, out, records.values().map(|(r, _)| r))?;
    let merged = Manifest {
        complete: true,
        ..merged
    };
    merged.write(out)?;
    Ok(MergeSummary {
        images: records.len(),
        parts: manifests.len(),
        manifest: merged,
    })
}
