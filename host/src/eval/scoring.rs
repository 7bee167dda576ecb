//! Scoring detectors on a directory of frames with a `truth.csv` (ours or anyone's):
//! IoU against the truth box and the core's run time, per method and per group
//! (material case, scale, illumination, range band, target, signal-to-clutter bin),
//! as the paper's Tables 6–8.
//!
//! `truth.csv` needs the columns `file,x0,y0,x1,y1` first (the project's box
//! convention, `docs/architecture.md`: x0, y0 inclusive, x1, y1 exclusive); extra
//! columns become group labels when they are one of `mode`, `scale`, `target`,
//! `material`, `illumination`, `range_m` gives the range band (close ≤ 50 m, far
//! ≥ 300 m, else mid), `signal_to_clutter` the SCR bin ([`scr_bin`]; without that
//! column, from the `metadata.jsonl` beside `truth.csv` when there is one) and
//! `visible_share` the visible bin ([`visible_bin`]). Timing is the
//! core call alone on one thread, the median of `repeat` runs; images are scored in
//! parallel.
//!
//! **The scoring definition** (one everywhere: `tirroi eval`, `tune`, `paper`'s tables
//! and plots; `docs/results.md` § Scoring). A frame has a target when its truth box is
//! not empty (empty `x0..y1` fields mean *no target*; a zero-area box is an error). Over a group's frames with a target: mean
//! and median IoU (a frame where the detector returned no box scores 0) and the hit
//! rate, the share with IoU ≥ [`HIT_IOU`]. Over its frames without a target: the
//! false-alarm rate, the share where the detector returned any box. Times are over
//! all frames. The detector's confidence (`FrameScore::score`) gives each group its
//! AUC and calibration by the definitions of [`crate::eval::confidence`].
//!
//! **Truth validation** ([`read_truth_lines`], [`check_truth_boxes`]): a header-only
//! file, a frame listed twice, a zero-area box and a box reaching outside its frame are
//! errors naming the file and line.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Serialize;
use tirroi_core::roi::auto::learned::AutoV2;
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::roi::track::Tracker;
use tirroi_core::{BoxRule, DetectError, Detection, Method, Roi};

use crate::eval::bank::{DetectorBank, TRACKERS, median};
use crate::eval::confidence::{self, Outcome};
use crate::imaging::image_io::{ReadOptions, read_frame, read_frame_with};
use crate::seed::{fnv1a64, stir};

/// A row of `truth.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct TruthRow {
    /// Frame file, relative to the images directory.
    pub file: String,
    /// Truth box.
    pub roi: Roi,
    /// Group labels from the extra columns: (column, value).
    pub groups: Vec<(String, String)>,
    /// Camera–target distance, m, when the file has a `range_m` column.
    pub range_m: Option<f64>,
    /// Bit depth of the frame's DN, when the file has a `bits` column: it takes
    /// precedence over [`EvalOptions::bits`] for this frame.
    pub bits: Option<u8>,
    /// Signal-to-clutter ratio, when the file has a `signal_to_clutter` column and the
    /// frame a target.
    pub signal_to_clutter: Option<f64>,
    /// The approach sequence the frame belongs to, when the file has a `sequence`
    /// column (rendered sequences, [`crate::dataset::labels::SEQUENCE_COLUMNS`]):
    /// [`Track::Sequence`] starts each sequence without a prior.
    pub sequence: Option<u64>,
}

impl TruthRow {
    /// Whether the frame has a target (its truth box is not empty).
    pub fn has_target(&self) -> bool {
        !self.roi.is_empty()
    }
}

/// IoU at or above which a frame counts as a hit (the paper's and COCO's ½).
pub const HIT_IOU: f32 = 0.5;

/// Which truth box of a `truth.csv` to score against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TruthCoverage {
    /// `x0,y0,x1,y1`: pixels covered at least the dataset's `truth_coverage` (½ by default).
    #[default]
    Half,
    /// `x0_quarter,y0_quarter,x1_quarter,y1_quarter`: pixels covered more than ¼.
    Quarter,
}

impl TruthCoverage {
    /// `half` or `quarter`, as `--truth-coverage` takes it.
    pub fn name(self) -> &'static str {
        match self {
            TruthCoverage::Half => "half",
            TruthCoverage::Quarter => "quarter",
        }
    }

    /// `half` or `quarter`.
    pub fn from_name(name: &str) -> Option<TruthCoverage> {
        match name {
            "half" => Some(TruthCoverage::Half),
            "quarter" => Some(TruthCoverage::Quarter),
            _ => None,
        }
    }

    /// Parses a `--truth-coverage` value, with an error naming the choices.
    ///
    /// # Errors
    /// A message for anything but `half` or `quarter`.
    pub fn parse(name: &str) -> Result<TruthCoverage, String> {
        TruthCoverage::from_name(name).ok_or_else(|| {
            format!("unknown truth coverage `{name}`; expected half (x0..y1) or quarter (x0_quarter..y1_quarter)")
        })
    }
}

/// The `truth.csv` columns of the quarter-coverage box ([`TruthCoverage::Quarter`]).
pub const QUARTER_COLUMNS: [&str; 4] = ["x0_quarter", "y0_quarter", "x1_quarter", "y1_quarter"];

/// The signal-to-clutter bins eval reports, upper bounds exclusive: `<1`, `1-3`,
/// `3-10`, `>=10` (below 1 the target is fainter than the background's own variation;
/// from 10 on it stands far above it).
pub const SCR_BIN_EDGES: [f64; 3] = [1.0, 3.0, 10.0];

/// The bin label of a signal-to-clutter ratio ([`SCR_BIN_EDGES`]); the group key is `scr`.
pub fn scr_bin(scr: f64) -> &'static str {
    if scr < SCR_BIN_EDGES[0] {
        "<1"
    } else if scr < SCR_BIN_EDGES[1] {
        "1-3"
    } else if scr < SCR_BIN_EDGES[2] {
        "3-10"
    } else {
        ">=10"
    }
}

/// The visible-share bins eval reports (`truth.csv`'s `visible_share`: the truth box's
/// share a detector can see at all, `imaging::render::clutter`), upper bounds
/// exclusive: `<0.5` (even the ideal box of the visible pixels is no hit), `0.5-0.9`,
/// `>=0.9` (the ideal box reaches issue 16's IoU goal of 0.9).
pub const VISIBLE_BIN_EDGES: [f64; 2] = [0.5, 0.9];

/// The bin label of a visible share ([`VISIBLE_BIN_EDGES`]); the group key is `visible`.
pub fn visible_bin(share: f64) -> &'static str {
    if share < VISIBLE_BIN_EDGES[0] {
        "<0.5"
    } else if share < VISIBLE_BIN_EDGES[1] {
        "0.5-0.9"
    } else {
        ">=0.9"
    }
}

/// Columns that become groups; `range_m` becomes `range` (close / mid / far).
pub const GROUP_COLUMNS: [&str; 5] = ["mode", "scale", "target", "material", "illumination"];

/// Why an evaluation could not run; `Display` is one line naming the file (and line).
#[derive(Debug, Clone, PartialEq)]
pub struct EvalError(pub String);

impl fmt::Display for EvalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for EvalError {}

/// The range band of a camera–target distance: `close` (≤ 50 m, the paper's headline),
/// `far` (≥ 300 m) or `mid`.
pub fn range_band(range_m: f64) -> &'static str {
    if range_m <= 50.0 {
        "close"
    } else if range_m >= 300.0 {
        "far"
    } else {
        "mid"
    }
}

/// The row of the paper's tables a frame belongs to, the group key `row`: its mode and
/// range band, e.g. `radiometry close` (Table 6), `detection close` (Table 7),
/// `radiometry far`; `None` unless both `mode` and `range` are among `groups`. The
/// marginal groups alone cannot give a row's figure (close range holds both modes), and
/// issue 16 scores `auto-v2` per row.
pub fn table_row(groups: &[(String, String)]) -> Option<String> {
    let of = |key: &str| groups.iter().find(|(k, _)| k == key).map(|(_, v)| v);
    Some(format!("{} {}", of("mode")?, of("range")?))
}

/// Reads `truth.csv`, scoring against the `x0,y0,x1,y1` box ([`TruthCoverage::Half`]).
///
/// # Errors
/// As [`read_truth_with`].
pub fn read_truth(path: &Path) -> Result<Vec<TruthRow>, EvalError> {
    read_truth_with(path, TruthCoverage::Half)
}

/// Reads `truth.csv` with the box of `coverage`. Four empty box fields mean no target.
///
/// # Errors
/// As [`read_truth_lines`].
pub fn read_truth_with(path: &Path, coverage: TruthCoverage) -> Result<Vec<TruthRow>, EvalError> {
    Ok(read_truth_lines(path, coverage)?
        .into_iter()
        .map(|(_, r)| r)
        .collect())
}

/// Reads `truth.csv` with the box of `coverage`, each row with its line number (1-based,
/// the header is line 1). Four empty box fields mean no target.
///
/// # Errors
/// [`EvalError`] naming the file and line for a missing header (or missing quarter
/// columns for [`TruthCoverage::Quarter`]), a file with no row after the header, a
/// short row, a frame listed twice (both lines named), or a box that is neither four
/// empty fields nor four integers with x0 < x1, y0 < y1 (a zero-area box is refused:
/// write four empty fields for a frame without a target).
pub fn read_truth_lines(
    path: &Path,
    coverage: TruthCoverage,
) -> Result<Vec<(usize, TruthRow)>, EvalError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| EvalError(format!("{}: cannot read: {e}", path.display())))?;
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = match lines.next() {
        Some((_, h)) => h.split(',').map(str::trim).collect(),
        None => return Err(EvalError(format!("{}: empty file", path.display()))),
    };
    if header.len() < 5 || header[..5] != ["file", "x0", "y0", "x1", "y1"] {
        return Err(EvalError(format!(
            "{}:1: header `{}`: expected it to start with file,x0,y0,x1,y1",
            path.display(),
            header.join(",")
        )));
    }
    let box_columns: [usize; 4] = match coverage {
        TruthCoverage::Half => [1, 2, 3, 4],
        TruthCoverage::Quarter => {
            let mut at = [0usize; 4];
            for (k, name) in QUARTER_COLUMNS.iter().enumerate() {
                at[k] = header.iter().position(|h| h == name).ok_or_else(|| {
                    EvalError(format!(
                        "{}:1: no `{name}` column: the quarter-coverage box needs {} (a dataset rendered by this version)",
                        path.display(),
                        QUARTER_COLUMNS.join(",")
                    ))
                })?;
            }
            at
        }
    };
    let mut rows = Vec::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let cols: Vec<&str> = line.split(',').map(str::trim).collect();
        let at = || format!("{}:{}", path.display(), i + 1);
        if cols.len() < 5 {
            return Err(EvalError(format!(
                "{}: {} columns: expected at least file,x0,y0,x1,y1",
                at(),
                cols.len()
            )));
        }
        let mut b = [0u16; 4];
        let field = |c: usize| cols.get(c).copied().unwrap_or("");
        let empty = box_columns.iter().all(|&c| field(c).is_empty());
        if !empty {
            for (k, v) in b.iter_mut().enumerate() {
                let c = box_columns[k];
                *v = field(c).parse().map_err(|_| {
                    EvalError(format!(
                        "{}: {} = `{}`: expected an integer 0..=65535 (or all four box fields empty: no target)",
                        at(),
                        header[c],
                        field(c)
                    ))
                })?;
            }
        }
        if b[0] > b[2] || b[1] > b[3] {
            return Err(EvalError(format!(
                "{}: box {b:?}: expected x0 <= x1 and y0 <= y1",
                at()
            )));
        }
        if !empty && (b[0] == b[2] || b[1] == b[3]) {
            return Err(EvalError(format!(
                "{}: box {b:?} has zero area: expected x0 < x1 and y0 < y1 (four empty box fields for a frame without a target)",
                at()
            )));
        }
        if let Some(first) = seen.insert(cols[0].to_string(), i + 1) {
            return Err(EvalError(format!(
                "{}: `{}` is listed twice (lines {first} and {}): expected one row per frame",
                at(),
                cols[0],
                i + 1
            )));
        }
        let roi = Roi::new(b[0], b[1], b[2], b[3]);
        let mut groups = Vec::new();
        let mut range_m = None;
        let mut bits = None;
        let mut signal_to_clutter = None;
        let mut sequence = None;
        for (name, value) in header.iter().zip(&cols).skip(5) {
            if value.is_empty() {
                continue;
            }
            if GROUP_COLUMNS.contains(name) {
                groups.push((name.to_string(), value.to_string()));
            } else if *name == "bits" {
                bits = Some(
                    value
                        .parse::<u8>()
                        .ok()
                        .filter(|b| (1..=16).contains(b))
                        .ok_or_else(|| {
                            EvalError(format!(
                                "{}: bits = `{value}`: expected a bit depth 1..=16",
                                at()
                            ))
                        })?,
                );
            } else if *name == "sequence" {
                sequence = Some(value.parse::<u64>().map_err(|_| {
                    EvalError(format!(
                        "{}: sequence = `{value}`: expected a sequence number 0, 1, … (or empty outside a sequence)",
                        at()
                    ))
                })?);
            } else if *name == "range_m" {
                if let Ok(r) = value.parse::<f64>() {
                    groups.push(("range".into(), range_band(r).into()));
                    range_m = Some(r);
                }
            } else if *name == "signal_to_clutter" && !roi.is_empty() {
                if let Ok(r) = value.parse::<f64>() {
                    if r.is_finite() {
                        groups.push(("scr".into(), scr_bin(r).into()));
                        signal_to_clutter = Some(r);
                    }
                }
            } else if *name == "visible_share" && !roi.is_empty() {
                if let Ok(v) = value.parse::<f64>() {
                    if v.is_finite() {
                        groups.push(("visible".into(), visible_bin(v).into()));
                    }
                }
            }
        }
        rows.push((
            i + 1,
            TruthRow {
                file: cols[0].to_string(),
                roi,
                groups,
                range_m,
                bits,
                signal_to_clutter,
                sequence,
            },
        ));
    }
    if rows.is_empty() {
        return Err(EvalError(format!(
            "{}:1: only a header: expected at least one row `file,x0,y0,x1,y1` after it",
            path.display()
        )));
    }
    if !header.contains(&"signal_to_clutter") {
        scr_from_metadata(path, rows.iter_mut().map(|(_, r)| r));
    }
    // Last, whatever gave the other groups: the same order with or without the
    // `signal_to_clutter` column.
    for (_, r) in &mut rows {
        if let Some(row) = table_row(&r.groups) {
            r.groups.push(("row".into(), row));
        }
    }
    Ok(rows)
}

/// The size of a frame file (width, height, px) by its `truth.csv` name, as
/// [`check_truth_boxes`] takes it.
pub type FrameSize<'a> = dyn Fn(&str) -> Result<(usize, usize), EvalError> + Sync + 'a;

/// Checks that every truth box lies inside its frame, reading each frame's size from
/// its file header only (`dimensions(file)`, e.g.
/// [`frame_dimensions`](crate::imaging::image_io::frame_dimensions) after a crop).
///
/// # Errors
/// [`EvalError`] naming `truth` and the line of the first box reaching past its frame's
/// width or height, or the frame file when its header cannot be read.
pub fn check_truth_boxes(
    truth: &Path,
    rows: &[(usize, TruthRow)],
    dimensions: &FrameSize<'_>,
) -> Result<(), EvalError> {
    rows.par_iter()
        .filter(|(_, r)| r.has_target())
        .map(|(line, r)| {
            let (w, h) = dimensions(&r.file)?;
            let b = r.roi;
            if usize::from(b.x1) > w || usize::from(b.y1) > h {
                return Err(EvalError(format!(
                    "{}:{line}: box {:?} reaches outside the {w}x{h} px frame `{}`: expected x1 <= {w} and y1 <= {h}",
                    truth.display(),
                    b.to_array(),
                    r.file
                )));
            }
            Ok(())
        })
        .collect::<Result<Vec<()>, EvalError>>()
        .map(|_| ())
}

/// For a `truth.csv` without a `signal_to_clutter` column: the ratios of the
/// `metadata.jsonl` beside it (the dataset's, by file name), when there is one.
/// Unreadable lines and files are skipped: the ratio only adds a group.
fn scr_from_metadata<'a>(truth: &Path, rows: impl Iterator<Item = &'a mut TruthRow>) {
    let Some(text) = truth
        .parent()
        .and_then(|d| std::fs::read_to_string(d.join("metadata.jsonl")).ok())
    else {
        return;
    };
    let mut by_file = BTreeMap::new();
    for line in text.lines() {
        if let Ok(v) = serde_json::from_str::<serde_json::Value>(line) {
            if let (Some(f), Some(r)) = (v["file"].as_str(), v["signal_to_clutter"].as_f64()) {
                by_file.insert(f.to_string(), r);
            }
        }
    }
    for row in rows.filter(|r| r.has_target()) {
        if let Some(&r) = by_file.get(&row.file) {
            if r.is_finite() {
                row.groups.push(("scr".into(), scr_bin(r).into()));
                row.signal_to_clutter = Some(r);
            }
        }
    }
}

/// One detector on one frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameScore {
    /// Frame file.
    pub file: String,
    /// Method name (a built-in method, or the name of a predictions file).
    pub method: String,
    /// Predicted box, `None` when nothing was found.
    pub bbox: Option<[u16; 4]>,
    /// The detector's confidence in its box, 0–1 (0 without a box; 1 for a predicted
    /// box without a score).
    pub score: f32,
    /// Truth box (all 0: no target).
    pub truth: [u16; 4],
    /// IoU of prediction and truth (0 when none, and on a frame without a target).
    pub iou: f32,
    /// Median core time over the repeats, µs.
    pub time_us: f64,
    /// The stage of `auto-v2` that gave the box (`tracked`, `blob`, `deep-space`,
    /// `classifier`, `spot`, `outline`: `learned::Stage::name`); `None` for the other
    /// methods and without a box. Also the frame's [`STAGE_GROUP`] group.
    pub stage: Option<&'static str>,
    /// Group labels.
    pub groups: Vec<(String, String)>,
    /// Camera–target distance, m, when known.
    pub range_m: Option<f64>,
}

impl FrameScore {
    /// Whether the frame has a target (its truth box is not empty).
    pub fn has_target(&self) -> bool {
        let [x0, y0, x1, y1] = self.truth;
        !Roi::new(x0, y0, x1, y1).is_empty()
    }

    /// Whether the detector returned a (non-empty) box.
    pub fn detected(&self) -> bool {
        self.bbox
            .is_some_and(|[x0, y0, x1, y1]| !Roi::new(x0, y0, x1, y1).is_empty())
    }

    /// A box on a frame without a target.
    pub fn false_alarm(&self) -> bool {
        !self.has_target() && self.detected()
    }

    /// The frame as the confidence measures see it ([`confidence::Outcome`]).
    pub fn outcome(&self) -> Outcome {
        let has_target = self.has_target();
        Outcome {
            has_target,
            score: self.detected().then_some(self.score),
            hit: has_target && self.detected() && self.iou >= HIT_IOU,
        }
    }
}

/// How to run an evaluation.
#[derive(Debug, Clone)]
pub struct EvalOptions {
    /// Methods to run.
    pub methods: Vec<Method>,
    /// Runs per frame and method (median time).
    pub repeat: usize,
    /// Mask-to-box rule for every detector; `None` keeps each detector's own rule from
    /// `make_bank` (e.g. tuned per method).
    pub box_rule: Option<BoxRule>,
    /// Bit depth of the frames without a `bits` column in `truth.csv` (None: from the
    /// file: a 16-bit PNG's `sBIT`, else 14 for 16-bit files that fit); a row's own `bits` wins.
    pub bits: Option<u8>,
    /// Where `auto` gets its tracking prior (the other methods have none).
    pub track: Track,
    /// FITS frames: DN added before rounding (`None`: the default of
    /// [`crate::imaging::image_io::default_fits_offset_dn`]).
    pub fits_offset_dn: Option<f64>,
    /// Part of every frame to score, `[x0, y0, x1, y1)` px (truth boxes are in it).
    pub crop: Option<[usize; 4]>,
}

impl EvalOptions {
    /// How to read a frame whose own bit depth (`truth.csv`'s `bits`) is `row_bits`.
    pub fn read_options(&self, row_bits: Option<u8>) -> ReadOptions {
        ReadOptions {
            bits: row_bits.or(self.bits),
            fits_offset_dn: self.fits_offset_dn,
            crop: self.crop,
        }
    }
}

/// Where `auto` gets its tracking prior during an evaluation ([`EvalOptions::track`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Track {
    /// No prior: every frame is searched whole.
    #[default]
    Off,
    /// The truth box as a tracker would hand it over: moved by up to ±4 px in x and y
    /// and each side grown or shrunk by up to 10 % of the box size, from a hash of the
    /// file name ([`jittered_prior`]), so the same frame always gets the same prior.
    Jitter,
    /// The frames, in file-name order, are one sequence: each frame's prior is the
    /// tracker's (`auto`'s, `auto-v2`'s) own box on the previous frame (none on the
    /// first frame and after a miss). With a `sequence` column (rendered approach
    /// sequences) each sequence starts without a prior. Frames are scored one after the
    /// other on one thread.
    Sequence,
}

/// The prior of [`Track::Jitter`]: `truth` moved by `dx, dy ∈ [−4, 4]` px and each
/// side moved out or in by up to 10 % of the box's width or height (rounded), all from
/// the FNV-1a hash of `file`; cut to the frame by the detector.
pub fn jittered_prior(truth: Roi, file: &str) -> Roi {
    let mut h = fnv1a64(file.as_bytes());
    let mut next = |n: i32| {
        h = stir(h);
        let v = ((h >> 33) % (2 * n as u64 + 1)) as i32;
        v - n
    };
    let (w, hh) = (i32::from(truth.width()), i32::from(truth.height()));
    let (dx, dy) = (next(4), next(4));
    let side = |size: i32, r: i32| (size * r + 50) / 100;
    let x0 = i32::from(truth.x0) + dx - side(w, next(10));
    let x1 = i32::from(truth.x1) + dx + side(w, next(10));
    let y0 = i32::from(truth.y0) + dy - side(hh, next(10));
    let y1 = i32::from(truth.y1) + dy + side(hh, next(10));
    let c = |v: i32| v.clamp(0, i32::from(u16::MAX)) as u16;
    Roi::new(c(x0), c(y0), c(x1), c(y1))
}

/// Scores every `(row, method)`; `make_bank` gives each worker thread its detectors
/// (their parameters), so tuned or default parameters come from one place.
///
/// # Errors
/// [`EvalError`] naming the frame for an unreadable file or a detector error.
pub fn score(
    images: &Path,
    rows: &[TruthRow],
    options: &EvalOptions,
    make_bank: &(dyn Fn() -> DetectorBank + Sync),
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<FrameScore>, EvalError> {
    if options.track == Track::Sequence {
        return score_sequence(images, rows, options, make_bank, progress);
    }
    let per_row: Vec<Result<Vec<FrameScore>, EvalError>> = rows
        .par_iter()
        .map_init(
            || {
                let mut bank = make_bank();
                if let Some(rule) = options.box_rule {
                    bank.set_box_rule(rule);
                }
                bank
            },
            |bank, row| {
                let path: PathBuf = images.join(&row.file);
                let frame = read_row_frame_with(images, row, options)?;
                let view = frame
                    .view()
                    .map_err(|e| EvalError(format!("{}: {e}", path.display())))?;
                let mut out = Vec::with_capacity(options.methods.len());
                if options.track == Track::Jitter {
                    // No target, nothing for a tracker to hand over. The look a tracker
                    // took of its last box: the prior's, on this frame (the jitter
                    // stands for the last frame's box).
                    let prior = row.has_target().then(|| jittered_prior(row.roi, &row.file));
                    bank.set_prior(prior);
                    bank.set_look(prior.and_then(|p| Look::measure(&view, p)));
                }
                for &m in &options.methods {
                    out.push(score_one(bank, m, &view, row, &path, options.repeat)?.0);
                }
                progress();
                Ok(out)
            },
        )
        .collect();
    let mut scores = Vec::new();
    for r in per_row {
        scores.extend(r?);
    }
    Ok(scores)
}

/// Reads the frame of `row` from `images` at the row's own bit depth (`truth.csv`'s
/// `bits` column), else at `bits` (else as [`read_frame`] infers it).
///
/// # Errors
/// [`EvalError`] naming the file when it cannot be read.
pub fn read_row_frame(
    images: &Path,
    row: &TruthRow,
    bits: Option<u8>,
) -> Result<crate::imaging::image_io::FrameBuf, EvalError> {
    read_frame(&images.join(&row.file), row.bits.or(bits)).map_err(|e| EvalError(e.to_string()))
}

/// [`read_row_frame`] under every reading option of `options` (bit depth, FITS offset,
/// crop); warnings are dropped.
///
/// # Errors
/// [`EvalError`] naming the file when it cannot be read.
pub fn read_row_frame_with(
    images: &Path,
    row: &TruthRow,
    options: &EvalOptions,
) -> Result<crate::imaging::image_io::FrameBuf, EvalError> {
    read_frame_with(&images.join(&row.file), &options.read_options(row.bits))
        .map(|(f, _)| f)
        .map_err(|e| EvalError(e.to_string()))
}

/// Runs `method` on one frame (`repeat` times, median time) and scores its box against
/// the row's truth; also returns the box.
fn score_one(
    bank: &mut DetectorBank,
    method: Method,
    view: &tirroi_core::Frame<'_>,
    row: &TruthRow,
    path: &Path,
    repeat: usize,
) -> Result<(FrameScore, Option<Roi>), EvalError> {
    let timed = bank.detect_timed(method, view, repeat);
    let stage = stage_of(bank, method, view, &timed);
    frame_score(timed, stage, method, row, path)
}

/// The `auto-v2` stage that gave `timed`'s box ([`DetectorBank::stage`]), as its
/// name; `None` for the other methods, an error or no box.
fn stage_of(
    bank: &mut DetectorBank,
    method: Method,
    view: &tirroi_core::Frame<'_>,
    timed: &Result<(Detection, f64), DetectError>,
) -> Option<&'static str> {
    let (d, _) = timed.as_ref().ok()?;
    bank.stage(method, view, d.roi).map(|s| s.name())
}

/// The group each `auto-v2` frame with a box gets, valued by the stage that gave it
/// ([`FrameScore::stage`]): `summary.csv` and the Markdown table then show each
/// stage's boxes, mean IoU, hit rate and calibration gap.
pub const STAGE_GROUP: &str = "stage";

/// A timed detection of `method` scored against the row's truth, and its box; `stage`
/// the `auto-v2` stage that gave it ([`stage_of`]).
fn frame_score(
    timed: Result<(Detection, f64), DetectError>,
    stage: Option<&'static str>,
    method: Method,
    row: &TruthRow,
    path: &Path,
) -> Result<(FrameScore, Option<Roi>), EvalError> {
    let (d, time_us) =
        timed.map_err(|e| EvalError(format!("{}: {method}: {e}", path.display())))?;
    let score = FrameScore {
        file: row.file.clone(),
        method: method.name().to_string(),
        bbox: d.roi.map(|r| r.to_array()),
        score: if d.roi.is_some() { d.score() } else { 0.0 },
        truth: row.roi.to_array(),
        iou: d.roi.map_or(0.0, |r| r.iou(&row.roi)),
        time_us,
        stage,
        groups: row
            .groups
            .iter()
            .cloned()
            .chain(stage.map(|s| (STAGE_GROUP.to_string(), s.to_string())))
            .collect(),
        range_m: row.range_m,
    };
    Ok((score, d.roi))
}

/// The group [`Track::Sequence`] gives each tracker's frames: `yes` when the tracker
/// had a box on the frame before (in the same sequence), `no` when it came in without
/// one and searched the whole frame.
pub const PRIOR_GROUP: &str = "prior";

/// [`score`] for [`Track::Sequence`]: one bank, frames in file-name order, each
/// tracker's (`auto`, `auto-v2`) prior from its own box on the previous frame; `auto-v2`
/// runs as the core's [`Tracker`] (its look, and targets acquired by their motion
/// against the ground), `auto` with its last box.
fn score_sequence(
    images: &Path,
    rows: &[TruthRow],
    options: &EvalOptions,
    make_bank: &(dyn Fn() -> DetectorBank + Sync),
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<FrameScore>, EvalError> {
    let mut bank = make_bank();
    if let Some(rule) = options.box_rule {
        bank.set_box_rule(rule);
    }
    let mut order: Vec<&TruthRow> = rows.iter().collect();
    order.sort_by(|a, b| a.file.cmp(&b.file));
    // `auto`'s box on the previous frame; `auto-v2`'s history is its tracker's.
    let mut previous: Option<Roi> = None;
    let mut tracker = Tracker::new(AutoV2::default());
    let mut scores = Vec::with_capacity(rows.len() * options.methods.len());
    let mut last_sequence = None;
    for row in order {
        // A new rendered sequence: no tracker carries a box into it.
        if row.sequence != last_sequence {
            previous = None;
            tracker.reset();
            last_sequence = row.sequence;
        }
        let path: PathBuf = images.join(&row.file);
        let frame = read_row_frame_with(images, row, options)?;
        let view = frame
            .view()
            .map_err(|e| EvalError(format!("{}: {e}", path.display())))?;
        for &m in &options.methods {
            let had = TRACKERS.contains(&m).then(|| match m {
                Method::AutoV2 => tracker.prior().is_some(),
                _ => previous.is_some(),
            });
            let (mut score, roi) = if m == Method::AutoV2 {
                let timed = bank.track_timed(&mut tracker, &view, options.repeat);
                let stage = stage_of(&mut bank, m, &view, &timed);
                frame_score(timed, stage, m, row, &path)?
            } else {
                bank.set_prior_of(m, previous);
                score_one(&mut bank, m, &view, row, &path, options.repeat)?
            };
            if let Some(had) = had {
                // Whether the tracker came in with a box: a tracked frame, or one where
                // it searched the whole frame (acquisition), each its own group.
                let had = if had { "yes" } else { "no" };
                score.groups.push((PRIOR_GROUP.into(), had.into()));
            }
            if m == Method::Auto {
                previous = roi;
            }
            scores.push(score);
        }
        progress();
    }
    Ok(scores)
}

/// The same scores against other truth boxes (e.g. the other [`TruthCoverage`]), by
/// file: truth and IoU replaced, boxes and scores kept; a file missing from `truth`
/// keeps its box.
pub fn with_truth(scores: &[FrameScore], truth: &BTreeMap<&str, Roi>) -> Vec<FrameScore> {
    scores
        .iter()
        .map(|s| {
            let mut s = s.clone();
            if let Some(t) = truth.get(s.file.as_str()) {
                s.truth = t.to_array();
                s.iou = s
                    .bbox
                    .map_or(0.0, |[x0, y0, x1, y1]| Roi::new(x0, y0, x1, y1).iou(t));
            }
            s
        })
        .collect()
}

/// Statistics of one method over one group of frames.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GroupStats {
    /// Method name.
    pub method: String,
    /// Group column (`all` for every frame).
    pub group: String,
    /// Group value.
    pub value: String,
    /// Frames (with and without a target).
    pub frames: usize,
    /// Frames with a target (the IoU statistics are over these).
    pub target_frames: usize,
    /// Mean IoU over the frames with a target (0 when there are none).
    pub mean_iou: f64,
    /// Median IoU over the frames with a target (0 when there are none).
    pub median_iou: f64,
    /// Share of the frames with a target whose IoU ≥ [`HIT_IOU`].
    pub hit_rate: f64,
    /// Share of the frames without a target where the detector returned a box
    /// (0 when there are none).
    pub false_alarm_rate: f64,
    /// Mean core time per frame, ms.
    pub mean_time_ms: f64,
    /// Median core time per frame, ms.
    pub median_time_ms: f64,
    /// Area under the hit-rate / false-positive-rate curve of the confidence
    /// ([`confidence::auc`]); `None` without frames with a target or without negatives.
    pub auc: Option<f64>,
    /// Largest `|hit rate − mean score|` over the score deciles holding boxes
    /// ([`confidence::max_gap`]); `None` without boxes.
    pub calibration_gap: Option<f64>,
}

/// Statistics of a set of scores, by the module's scoring definition.
pub fn stats(method: &str, group: &str, value: &str, scores: &[&FrameScore]) -> GroupStats {
    let n = scores.len();
    let mut ious: Vec<f64> = scores
        .iter()
        .filter(|s| s.has_target())
        .map(|s| f64::from(s.iou))
        .collect();
    let targets = ious.len();
    let empty = n - targets;
    let alarms = scores.iter().filter(|s| s.false_alarm()).count();
    let mut times: Vec<f64> = scores.iter().map(|s| s.time_us * 1e-3).collect();
    let outcomes: Vec<Outcome> = scores.iter().map(|s| s.outcome()).collect();
    let mean = |v: &[f64]| {
        if v.is_empty() {
            0.0
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    GroupStats {
        method: method.into(),
        group: group.into(),
        value: value.into(),
        frames: n,
        target_frames: targets,
        mean_iou: mean(&ious),
        hit_rate: if targets == 0 {
            0.0
        } else {
            ious.iter().filter(|&&v| v >= f64::from(HIT_IOU)).count() as f64 / targets as f64
        },
        false_alarm_rate: if empty == 0 {
            0.0
        } else {
            alarms as f64 / empty as f64
        },
        median_iou: median(&mut ious),
        mean_time_ms: mean(&times),
        median_time_ms: median(&mut times),
        auc: confidence::auc(&outcomes),
        calibration_gap: confidence::max_gap(&confidence::calibration(&outcomes)),
    }
}

/// Per method: all frames, then each value of each group column present.
pub fn summarise(scores: &[FrameScore]) -> Vec<GroupStats> {
    let mut methods: Vec<&str> = Vec::new();
    for s in scores {
        if !methods.contains(&s.method.as_str()) {
            methods.push(&s.method);
        }
    }
    let mut out = Vec::new();
    for m in methods {
        let mine: Vec<&FrameScore> = scores.iter().filter(|s| s.method == m).collect();
        out.push(stats(m, "all", "all", &mine));
        let mut by: BTreeMap<(String, String), Vec<&FrameScore>> = BTreeMap::new();
        for s in &mine {
            for (k, v) in &s.groups {
                by.entry((k.clone(), v.clone())).or_default().push(s);
            }
        }
        for ((k, v), group) in by {
            out.push(stats(m, &k, &v, &group));
        }
    }
    out
}

/// The statistics as a Markdown table.
pub fn markdown(stats: &[GroupStats]) -> String {
    let mut s = String::from(
        "| method | group | frames | mean IoU | median IoU | IoU >= 0.5 | target frames | false alarms | AUC | calib. gap | mean time [ms] | median time [ms] |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for g in stats {
        let group = if g.group == "all" {
            "all".to_string()
        } else {
            format!("{} = {}", g.group, g.value)
        };
        // IoU columns need frames with a target, the false-alarm rate frames without.
        let iou = |v: f64| {
            if g.target_frames == 0 {
                "–".to_string()
            } else {
                format!("{v:.3}")
            }
        };
        let alarms = if g.frames == g.target_frames {
            "–".to_string()
        } else {
            format!("{:.3}", g.false_alarm_rate)
        };
        let opt = |v: Option<f64>| v.map_or_else(|| "–".to_string(), |v| format!("{v:.3}"));
        s.push_str(&format!(
            "| {} | {group} | {} | {} | {} | {} | {} | {alarms} | {} | {} | {:.3} | {:.3} |\n",
            g.method,
            g.frames,
            iou(g.mean_iou),
            iou(g.median_iou),
            iou(g.hit_rate),
            g.target_frames,
            opt(g.auc),
            opt(g.calibration_gap),
            g.mean_time_ms,
            g.median_time_ms
        ));
    }
    s
}

/// Writes `scores.csv`, `summary.csv` and `summary.json` into `out`.
///
/// # Errors
/// [`EvalError`] naming the file that cannot be written.
pub fn write_reports(
    out: &Path,
    scores: &[FrameScore],
    stats: &[GroupStats],
) -> Result<(), EvalError> {
    let io = |p: &Path, e: std::io::Error| EvalError(format!("{}: cannot write: {e}", p.display()));
    std::fs::create_dir_all(out).map_err(|e| io(out, e))?;
    let mut csv = String::from(
        "file,method,x0,y0,x1,y1,truth_x0,truth_y0,truth_x1,truth_y1,iou,time_us,score,stage\n",
    );
    // No target: empty truth fields, as in `truth.csv`.
    for s in scores {
        let b = s.bbox.map_or(",,,".to_string(), |b| {
            format!("{},{},{},{}", b[0], b[1], b[2], b[3])
        });
        let t = s.truth;
        let t = if s.has_target() {
            format!("{},{},{},{}", t[0], t[1], t[2], t[3])
        } else {
            ",,,".to_string()
        };
        csv.push_str(&format!(
            "{},{},{b},{t},{:.4},{:.2},{:.3},{}\n",
            s.file,
            s.method,
            s.iou,
            s.time_us,
            s.score,
            s.stage.unwrap_or("")
        ));
    }
    let p = out.join("scores.csv");
    std::fs::write(&p, csv).map_err(|e| io(&p, e))?;
    let mut csv = String::from(
        "method,group,value,frames,mean_iou,median_iou,hit_rate,mean_time_ms,median_time_ms,target_frames,false_alarm_rate,auc,calibration_gap\n",
    );
    for g in stats {
        csv.push_str(&format!(
            "{},{},{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{},{:.4},{},{}\n",
            g.method,
            g.group,
            g.value,
            g.frames,
            g.mean_iou,
            g.median_iou,
            g.hit_rate,
            g.mean_time_ms,
            g.median_time_ms,
            g.target_frames,
            g.false_alarm_rate,
            g.auc.map_or(String::new(), |v| format!("{v:.4}")),
            g.calibration_gap
                .map_or(String::new(), |v| format!("{v:.4}")),
        ));
    }
    let p = out.join("summary.csv");
    std::fs::write(&p, csv).map_err(|e| io(&p, e))?;
    let p = out.join("summary.json");
    let json = serde_json::to_string_pretty(stats).map_err(|e| EvalError(e.to_string()))?;
    std::fs::write(&p, json).map_err(|e| io(&p, e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn score(iou: f32, time_us: f64, groups: &[(&str, &str)]) -> FrameScore {
        FrameScore {
            file: "f.png".into(),
            method: "otsu".into(),
            bbox: None,
            score: 0.0,
            truth: [0, 0, 1, 1],
            iou,
            time_us,
            stage: None,
            groups: groups
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            range_m: None,
        }
    }

    #[test]
    fn stats_by_hand() {
        let s = [
            score(0.2, 100.0, &[("scale", "1")]),
            score(0.6, 300.0, &[("scale", "1")]),
            score(0.9, 200.0, &[("scale", "3")]),
        ];
        let all = summarise(&s);
        assert_eq!(all.len(), 3);
        let a = &all[0];
        assert_eq!((a.group.as_str(), a.frames), ("all", 3));
        assert!((a.mean_iou - (0.2 + 0.6 + 0.9) / 3.0).abs() < 1e-6);
        assert!((a.median_iou - 0.6).abs() < 1e-6);
        assert!((a.hit_rate - 2.0 / 3.0).abs() < 1e-12);
        assert!((a.mean_time_ms - 0.2).abs() < 1e-12 && (a.median_time_ms - 0.2).abs() < 1e-12);
        let s1 = &all[1];
        assert_eq!((s1.value.as_str(), s1.frames), ("1", 2));
        assert!((s1.median_iou - 0.4).abs() < 1e-6);
    }

    #[test]
    fn no_target_frames_by_hand() {
        // Two target frames (IoU 0.8 hit, a miss with no box) and three without a
        // target: one where the detector returned a box (a false alarm), two without.
        let mut s = vec![score(0.8, 100.0, &[]), score(0.0, 100.0, &[])];
        s[0].bbox = Some([0, 0, 1, 1]);
        for alarm in [true, false, false] {
            let mut f = score(0.0, 100.0, &[]);
            f.truth = [0; 4];
            f.bbox = alarm.then_some([3, 3, 9, 9]);
            s.push(f);
        }
        let a = &summarise(&s)[0];
        assert_eq!((a.frames, a.target_frames), (5, 2));
        assert!((a.mean_iou - 0.4).abs() < 1e-6, "{}", a.mean_iou);
        assert!((a.median_iou - 0.4).abs() < 1e-6);
        assert!((a.hit_rate - 0.5).abs() < 1e-12);
        assert!((a.false_alarm_rate - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn scr_bins() {
        assert_eq!(scr_bin(0.5), "<1");
        assert_eq!(scr_bin(1.0), "1-3");
        assert_eq!(scr_bin(9.99), "3-10");
        assert_eq!(scr_bin(10.0), ">=10");
    }

    #[test]
    fn table_rows_cross_mode_and_range() {
        let g = |pairs: &[(&str, &str)]| -> Vec<(String, String)> {
            pairs
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        };
        let both = g(&[("mode", "radiometry"), ("scale", "2"), ("range", "close")]);
        assert_eq!(table_row(&both).as_deref(), Some("radiometry close"));
        assert_eq!(
            table_row(&g(&[("range", "far"), ("mode", "detection")])).as_deref(),
            Some("detection far")
        );
        assert_eq!(table_row(&g(&[("mode", "detection")])), None);
        assert_eq!(table_row(&g(&[("range", "mid")])), None);
    }

    #[test]
    fn range_bands() {
        assert_eq!(range_band(15.0), "close");
        assert_eq!(range_band(50.0), "close");
        assert_eq!(range_band(120.0), "mid");
        assert_eq!(range_band(440.0), "far");
    }
}
