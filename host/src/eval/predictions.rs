//! Boxes made elsewhere (`tirroi eval --predictions FILE`), read and scored by the same
//! definition as the built-in methods ([`crate::eval::scoring`]).
//!
//! Three formats, told apart by the first non-blank character of the file:
//! - `{`: **JSON lines** as `tirroi detect --json` prints them,
//!   `{"file","method","bbox":[x0,y0,x1,y1] or null,"score","time_us"}`; `method`,
//!   `score` (default 1 for a box) and `time_us` (default 0) are optional. Each method in
//!   the file becomes one set, named `NAME:METHOD` when the file holds several.
//! - `[`: **COCO results** JSON, `[{"image_id","bbox":[x,y,w,h],"score"}, ...]`, mapped to
//!   files through the `images` of the dataset's COCO annotations (`coco.json`, which
//!   `tirroi render` writes). The box is `x0 = round(x)`, `x1 = round(x + w)` (likewise
//!   y), so the integer boxes `tirroi render` writes come back exactly; where an image
//!   has several results, the highest score is its box (one box per frame, as the
//!   built-in detectors give; ties: the first in the file).
//! - anything else: **CSV** with the header `file,x0,y0,x1,y1[,score]`; four empty box
//!   fields mean no box; an empty or missing score is 1 for a box.
//!
//! A prediction's `file` names a truth row when it equals the row's `file` or ends with
//! `/` + it (so `detect --json DIR/*.png` lines match `truth.csv`'s bare names); the
//! longest such match wins. A frame of the truth without a prediction counts as `null`
//! (no box); a prediction for a file that is not in the truth, a frame predicted twice
//! by the same set, a malformed box or a score outside 0–1 are errors naming the file
//! and line (the entry for COCO results).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::Value;
use tirroi_core::Roi;

use crate::eval::scoring::{EvalError, FrameScore, TruthRow};

/// One predicted frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// The frame file as the predictions name it.
    pub file: String,
    /// The box, `None` for no box.
    pub bbox: Option<Roi>,
    /// Confidence 0–1 (0 without a box).
    pub score: f32,
    /// Time the detector took, µs (0 when the file does not say).
    pub time_us: f64,
    /// Where it was read: line (1-based) for JSON lines and CSV, entry (1-based) for COCO.
    pub line: usize,
}

/// The predictions of one detector.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictionSet {
    /// Name in the tables (`NAME` or `NAME:METHOD`).
    pub name: String,
    /// The file read.
    pub source: PathBuf,
    /// `line` for JSON lines and CSV, `entry` for COCO results (for messages).
    pub unit: &'static str,
    /// The predictions, in file order.
    pub predictions: Vec<Prediction>,
}

impl PredictionSet {
    /// `FILE:LINE` (JSON lines, CSV) or `FILE: entry N` (COCO results).
    pub fn at(&self, line: usize) -> String {
        if self.unit == "line" {
            format!("{}:{line}", self.source.display())
        } else {
            format!("{}: {} {line}", self.source.display(), self.unit)
        }
    }
}

/// Parses a `--predictions` value: `NAME=FILE`, or `FILE` named by its stem.
///
/// # Errors
/// A message for an empty name or file.
pub fn parse_spec(spec: &str) -> Result<(String, PathBuf), String> {
    let (name, file) = match spec.split_once('=') {
        Some((n, f)) => (n.to_string(), PathBuf::from(f)),
        None => {
            let p = PathBuf::from(spec);
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            (stem, p)
        }
    };
    if name.is_empty() || file.as_os_str().is_empty() {
        return Err(format!(
            "`{spec}`: expected FILE or NAME=FILE with a non-empty name and file"
        ));
    }
    Ok((name, file))
}

/// Reads a predictions file (module docs) into one set per method; `coco` is the
/// dataset's COCO annotations file, needed for COCO results only.
///
/// # Errors
/// [`EvalError`] naming the file and line (entry) of the first malformed prediction, an
/// unreadable file, or COCO results without a readable `coco`.
pub fn read_predictions(
    path: &Path,
    name: &str,
    coco: Option<&Path>,
) -> Result<Vec<PredictionSet>, EvalError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| EvalError(format!("{}: cannot read: {e}", path.display())))?;
    match text.trim_start().chars().next() {
        Some('{') => read_json_lines(path, name, &text),
        Some('[') => {
            let coco = coco.ok_or_else(|| {
                EvalError(format!(
                    "{}: COCO results need the dataset's COCO annotations (coco.json) to map image_id to files",
                    path.display()
                ))
            })?;
            Ok(vec![read_coco_results(path, name, &text, coco)?])
        }
        Some(_) => Ok(vec![read_csv(path, name, &text)?]),
        None => Err(EvalError(format!(
            "{}: empty file: expected JSON lines, a CSV file,x0,y0,x1,y1[,score] or COCO results",
            path.display()
        ))),
    }
}

fn at(path: &Path, line: usize) -> String {
    format!("{}:{line}", path.display())
}

/// A box from four coordinates: x0 < x1 and y0 < y1, each in 0..=65535.
fn make_box(c: [f64; 4]) -> Result<Roi, String> {
    if c.iter()
        .any(|v| !v.is_finite() || *v < 0.0 || *v > f64::from(u16::MAX))
    {
        return Err(format!("box {c:?}: expected coordinates in 0..=65535"));
    }
    let [x0, y0, x1, y1] = c.map(|v| v.round() as u16);
    if x0 >= x1 || y0 >= y1 {
        return Err(format!(
            "box [{x0}, {y0}, {x1}, {y1}]: expected x0 < x1 and y0 < y1 (no box: null or empty fields)"
        ));
    }
    Ok(Roi::new(x0, y0, x1, y1))
}

fn check_score(score: f64) -> Result<f32, String> {
    if score.is_finite() && (0.0..=1.0).contains(&score) {
        Ok(score as f32)
    } else {
        Err(format!("score {score}: expected a confidence in 0..=1"))
    }
}

fn read_json_lines(path: &Path, name: &str, text: &str) -> Result<Vec<PredictionSet>, EvalError> {
    let mut by_method: Vec<(String, Vec<Prediction>)> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let fail = |what: String| EvalError(format!("{}: {what}", at(path, i + 1)));
        let v: Value =
            serde_json::from_str(line).map_err(|e| fail(format!("not a JSON object: {e}")))?;
        let file = v["file"]
            .as_str()
            .ok_or_else(|| fail("no \"file\" string".into()))?
            .to_string();
        let method = match &v["method"] {
            Value::Null => String::new(),
            Value::String(m) => m.clone(),
            other => return Err(fail(format!("\"method\" = {other}: expected a string"))),
        };
        let bbox = match &v["bbox"] {
            Value::Null => None,
            Value::Array(a) if a.len() == 4 && a.iter().all(Value::is_number) => {
                let c = [0, 1, 2, 3].map(|k| a[k].as_f64().unwrap_or(f64::NAN));
                Some(make_box(c).map_err(fail)?)
            }
            other => {
                return Err(fail(format!(
                    "\"bbox\" = {other}: expected [x0, y0, x1, y1] or null"
                )));
            }
        };
        let score = match &v["score"] {
            Value::Null => f64::from(u8::from(bbox.is_some())),
            s => s
                .as_f64()
                .ok_or_else(|| fail(format!("\"score\" = {s}: expected a number")))?,
        };
        let score = check_score(score).map_err(fail)?;
        let time_us = v["time_us"].as_f64().unwrap_or(0.0);
        let p = Prediction {
            file,
            bbox,
            score: if bbox.is_some() { score } else { 0.0 },
            time_us,
            line: i + 1,
        };
        match by_method.iter_mut().find(|(m, _)| *m == method) {
            Some((_, list)) => list.push(p),
            None => by_method.push((method, vec![p])),
        }
    }
    let several = by_method.len() > 1;
    Ok(by_method
        .into_iter()
        .map(|(method, predictions)| PredictionSet {
            name: if several {
                format!("{name}:{method}")
            } else {
                name.to_string()
            },
            source: path.to_path_buf(),
            unit: "line",
            predictions,
        })
        .collect())
}

fn read_csv(path: &Path, name: &str, text: &str) -> Result<PredictionSet, EvalError> {
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = lines
        .next()
        .map(|(_, h)| h.split(',').map(str::trim).collect())
        .unwrap_or_default();
    if header.len() < 5 || header[..5] != ["file", "x0", "y0", "x1", "y1"] {
        return Err(EvalError(format!(
            "{}: header `{}`: expected file,x0,y0,x1,y1[,score] (or JSON lines, or COCO results)",
            at(path, 1),
            header.join(",")
        )));
    }
    let score_col = header.iter().position(|h| *h == "score");
    let mut predictions = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let fail = |what: String| EvalError(format!("{}: {what}", at(path, i + 1)));
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        if cols.len() < 5 {
            return Err(fail(format!(
                "{} columns: expected file,x0,y0,x1,y1[,score]",
                cols.len()
            )));
        }
        let bbox = if cols[1..5].iter().all(|c| c.is_empty()) {
            None
        } else {
            let mut c = [0.0; 4];
            for k in 0..4 {
                c[k] = cols[k + 1].parse().map_err(|_| {
                    fail(format!(
                        "{} = `{}`: expected a number (or all four box fields empty: no box)",
                        header[k + 1],
                        cols[k + 1]
                    ))
                })?;
            }
            Some(make_box(c).map_err(fail)?)
        };
        let score = match score_col
            .and_then(|c| cols.get(c))
            .filter(|s| !s.is_empty())
        {
            None => f64::from(u8::from(bbox.is_some())),
            Some(s) => s
                .parse::<f64>()
                .map_err(|_| fail(format!("score = `{s}`: expected a number in 0..=1")))?,
        };
        let score = check_score(score).map_err(fail)?;
        predictions.push(Prediction {
            file: cols[0].to_string(),
            bbox,
            score: if bbox.is_some() { score } else { 0.0 },
            time_us: 0.0,
            line: i + 1,
        });
    }
    Ok(PredictionSet {
        name: name.to_string(),
        source: path.to_path_buf(),
        unit: "line",
        predictions,
    })
}

/// `image_id → file_name` of a COCO annotations file.
fn coco_images(coco: &Path) -> Result<BTreeMap<u64, String>, EvalError> {
    let fail = |what: String| EvalError(format!("{}: {what}", coco.display()));
    let text = std::fs::read_to_string(coco).map_err(|e| fail(format!("cannot read: {e}")))?;
    let v: Value = serde_json::from_str(&text).map_err(|e| fail(format!("not JSON: {e}")))?;
    let images = v["images"]
        .as_array()
        .ok_or_else(|| fail("no \"images\" array: expected COCO annotations".into()))?;
    let mut map = BTreeMap::new();
    for (k, im) in images.iter().enumerate() {
        match (im["id"].as_u64(), im["file_name"].as_str()) {
            (Some(id), Some(f)) => {
                map.insert(id, f.to_string());
            }
            _ => {
                return Err(fail(format!(
                    "images entry {}: expected \"id\" and \"file_name\"",
                    k + 1
                )));
            }
        }
    }
    Ok(map)
}

fn read_coco_results(
    path: &Path,
    name: &str,
    text: &str,
    coco: &Path,
) -> Result<PredictionSet, EvalError> {
    let images = coco_images(coco)?;
    let v: Value = serde_json::from_str(text)
        .map_err(|e| EvalError(format!("{}: not JSON: {e}", path.display())))?;
    let entries = v.as_array().ok_or_else(|| {
        EvalError(format!(
            "{}: expected a JSON array of results",
            path.display()
        ))
    })?;
    // Best result per image: (index in `predictions`, score).
    let mut best: BTreeMap<u64, usize> = BTreeMap::new();
    let mut predictions: Vec<Prediction> = Vec::new();
    for (k, e) in entries.iter().enumerate() {
        let fail = |what: String| EvalError(format!("{}: entry {}: {what}", path.display(), k + 1));
        let id = e["image_id"]
            .as_u64()
            .ok_or_else(|| fail("no integer \"image_id\"".into()))?;
        let file = images.get(&id).ok_or_else(|| {
            fail(format!(
                "image_id {id} is not an image of {}",
                coco.display()
            ))
        })?;
        let b = match &e["bbox"] {
            Value::Array(a) if a.len() == 4 && a.iter().all(Value::is_number) => {
                [0, 1, 2, 3].map(|j| a[j].as_f64().unwrap_or(f64::NAN))
            }
            other => return Err(fail(format!("\"bbox\" = {other}: expected [x, y, w, h]"))),
        };
        let bbox = make_box([b[0], b[1], b[0] + b[2], b[1] + b[3]]).map_err(fail)?;
        let score = match &e["score"] {
            Value::Null => 1.0,
            s => s
                .as_f64()
                .ok_or_else(|| fail(format!("\"score\" = {s}: expected a number")))?,
        };
        let score = check_score(score).map_err(fail)?;
        let p = Prediction {
            file: file.clone(),
            bbox: Some(bbox),
            score,
            time_us: 0.0,
            line: k + 1,
        };
        match best.get(&id) {
            Some(&j) if predictions[j].score >= score => {}
            Some(&j) => predictions[j] = p,
            None => {
                best.insert(id, predictions.len());
                predictions.push(p);
            }
        }
    }
    Ok(PredictionSet {
        name: name.to_string(),
        source: path.to_path_buf(),
        unit: "entry",
        predictions,
    })
}

/// Scores a set against the truth: one [`FrameScore`] per truth row, in the rows'
/// order (a row without a prediction: no box).
///
/// # Errors
/// [`EvalError`] naming the predictions file and line for a prediction whose file is
/// not in the truth, or a frame predicted twice.
pub fn score_predictions(
    set: &PredictionSet,
    rows: &[TruthRow],
) -> Result<Vec<FrameScore>, EvalError> {
    let index: BTreeMap<&str, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, r)| (r.file.as_str(), i))
        .collect();
    let mut found: Vec<Option<&Prediction>> = vec![None; rows.len()];
    for p in &set.predictions {
        let fail = |what: String| EvalError(format!("{}: {what}", set.at(p.line)));
        let i = match_file(&p.file, &index).ok_or_else(|| {
            fail(format!(
                "`{}` is not a frame of the truth file: expected one of its `file` names (or a path ending in one)",
                p.file
            ))
        })?;
        if let Some(q) = found[i] {
            return Err(fail(format!(
                "`{}` predicted twice (also at {}): expected one box per frame",
                rows[i].file,
                set.at(q.line)
            )));
        }
        found[i] = Some(p);
    }
    Ok(rows
        .iter()
        .zip(found)
        .map(|(row, p)| {
            let bbox = p.and_then(|p| p.bbox);
            FrameScore {
                file: row.file.clone(),
                method: set.name.clone(),
                bbox: bbox.map(|r| r.to_array()),
                score: if bbox.is_some() {
                    p.map_or(0.0, |p| p.score)
                } else {
                    0.0
                },
                truth: row.roi.to_array(),
                iou: bbox.map_or(0.0, |r| r.iou(&row.roi)),
                time_us: p.map_or(0.0, |p| p.time_us),
                // A predictions file names no stage.
                stage: None,
                groups: row.groups.clone(),
                range_m: row.range_m,
            }
        })
        .collect())
}

/// The truth row of a predicted file name: equal, else the longest `/`-bounded suffix.
fn match_file(file: &str, index: &BTreeMap<&str, usize>) -> Option<usize> {
    let file = file.replace('\\', "/");
    if let Some(&i) = index.get(file.as_str()) {
        return Some(i);
    }
    let mut rest = file.as_str();
    while let Some((_, tail)) = rest.split_once('/') {
        if let Some(&i) = index.get(tail) {
            return Some(i);
        }
        rest = tail;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(file: &str, b: [u16; 4]) -> TruthRow {
        TruthRow {
            file: file.into(),
            roi: Roi::new(b[0], b[1], b[2], b[3]),
            groups: vec![],
            range_m: None,
            bits: None,
            signal_to_clutter: None,
            sequence: None,
        }
    }

    #[test]
    fn specs_and_file_matching() {
        assert_eq!(
            parse_spec("runs/mine.csv").unwrap(),
            ("mine".into(), PathBuf::from("runs/mine.csv"))
        );
        assert_eq!(
            parse_spec("yolo=a/b.json").unwrap(),
            ("yolo".into(), PathBuf::from("a/b.json"))
        );
        assert!(parse_spec("=a.csv").is_err());
        let rows = [row("a.png", [0; 4]), row("sub/b.png", [0; 4])];
        let index: BTreeMap<&str, usize> = [("a.png", 0), ("sub/b.png", 1)].into_iter().collect();
        assert_eq!(match_file("a.png", &index), Some(0));
        assert_eq!(match_file("/tmp/ds/a.png", &index), Some(0));
        assert_eq!(match_file("/tmp/ds/sub/b.png", &index), Some(1));
        assert_eq!(match_file("/tmp/ds/xa.png", &index), None);
        assert_eq!(match_file("b.png", &index), None);
        assert_eq!(rows.len(), 2);
    }

    #[test]
    fn scoring_by_hand() {
        let rows = [
            row("a.png", [0, 0, 10, 10]),
            row("b.png", [0, 0, 10, 10]),
            row("c.png", [0, 0, 0, 0]),
        ];
        let set = PredictionSet {
            name: "mine".into(),
            source: "p.csv".into(),
            unit: "line",
            predictions: vec![Prediction {
                file: "dir/a.png".into(),
                bbox: Some(Roi::new(0, 0, 10, 5)),
                score: 0.4,
                time_us: 0.0,
                line: 2,
            }],
        };
        let s = score_predictions(&set, &rows).unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(
            (s[0].iou, s[0].score, s[0].bbox),
            (0.5, 0.4, Some([0, 0, 10, 5]))
        );
        assert_eq!((s[1].iou, s[1].bbox, s[2].bbox), (0.0, None, None));
        let mut twice = set.clone();
        twice.predictions.push(Prediction {
            line: 3,
            ..set.predictions[0].clone()
        });
        let e = score_predictions(&twice, &rows).unwrap_err().0;
        assert!(e.starts_with("p.csv:3:") && e.contains("p.csv:2"), "{e}");
        let mut stranger = set.clone();
        stranger.predictions[0].file = "zzz.png".into();
        let e = score_predictions(&stranger, &rows).unwrap_err().0;
        assert!(e.starts_with("p.csv:2:") && e.contains("zzz.png"), "{e}");
    }
}
