//! Tuning the detectors' parameters on labelled frames, the way the paper "fine-tuned
//! the hyper-parameters" before its Tables 6–8, but reproducibly and with a held-out
//! test split.
//!
//! # Split
//!
//! [`split`] puts a frame in the [`Split::Tune`] part when the 64-bit FNV-1a hash of its
//! file name (the `file` column of `truth.csv`, as written, bytes of the UTF-8 text),
//! passed through the SplitMix64 finaliser so that file names differing in one digit
//! land far apart, is below [`TUNE_PERCENT`] % of the hash range: `mix(fnv1a(file)) %
//! 100 < 30`. About 30 % of the frames are tuned on, the rest are the test part. The
//! rule depends on nothing but the file name: the same frame is in the same part in
//! every dataset, run, platform and thread count, and the two parts are disjoint and
//! cover every row.
//!
//! The parts are disjoint within one rendered dataset only. Two renders of a preset
//! with the same seed and different `--count` share scenes under other file names
//! (the j-th frame of each scene kind has the same pose and range, with other noise),
//! so parameters tuned on one must not be tested on the other: tune on a render with
//! another seed, or on the same render's tune part.
//!
//! # Search
//!
//! [`search`] scores every set of a fixed grid per method ([`grid`]) on the given
//! frames, then refines each of the [`SearchOptions::starts`] best grid sets of a
//! method by steepest ascent on finer ladders of each coordinate (one ladder step up or
//! down per coordinate, and the other box rule), at most
//! [`SearchOptions::refine_steps`] moves each, and keeps the best end point. A
//! candidate's score is its mean IoU; equal means (within 10⁻⁹) go to the clearly lower
//! mean core time, else to the candidate scored first ([`Trial::beats`]). Every
//! candidate scored, grid or refinement, is kept as a [`Trial`] (each once), so the
//! trials double as the run-time-against-IoU scatter of a method.
//!
//! Grids, each set with both box rules (the core defaults are among them):
//!
//! | method | coordinates | grid |
//! |---|---|---|
//! | otsu | box rule | all-foreground, largest-component |
//! | adaptive | `block` (px) × `offset_dn` (DN) | {11, 21, 41, 61, 81, 121, 161} × {0, 32, 64, 128, 256, 512, 1024, 2048, 4096} |
//! | wge | `drop_fraction` × `min_gradient` (Prewitt L1 DN) | {0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998} × {0, 48, 128, 256, 512, 1024, 2048, 4096, 8192} |
//! | dog | `sigma0_px` × `levels` × `min_response_dn` (`sigma_ratio` 1.6) | {2, 4, 8} × {3, 5, 7} × {64, 128, 256, 512, 1024, 2048} (the 6 sets whose widest σ exceeds the core's bound skipped) |
//!
//! | auto | `coarse_sigma` × `fine_sigma` (noise units; no box rule) | {6, 8, 10, 12, 16} × {6, 8, 12, 16} |
//!
//! That is 2 + 126 + 144 + 96 (+ 12 for auto) grid sets; the refinement adds some 20–150 trials per
//! method. Refinement ladders are the `*_LADDER` constants. Frames are scored through
//! [`eval::score`] (in parallel, one run each); while the grids run, each pass over
//! the frames scores one grid set of every method, so a frame is decoded once per pass
//! rather than once per set. Measured (release, 2 cores shared with other work): four
//! methods on 88 tune frames in 16–21 s, on 367–373 tune frames in 32–90 s.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use tirroi_core::roi::adaptive::Adaptive;
use tirroi_core::roi::auto::Auto;
use tirroi_core::roi::dog::Dog;
use tirroi_core::roi::otsu::Otsu;
use tirroi_core::roi::wge::Wge;
use tirroi_core::{BoxRule, Detector, Method};

use crate::eval::{self, EvalError, EvalOptions, FrameScore, GROUP_COLUMNS, TruthRow};
use crate::run::DetectorBank;

/// Percentage of frames (by file-name hash) in the [`Split::Tune`] part.
pub const TUNE_PERCENT: u64 = 30;

/// A part of a labelled dataset (see the module documentation for the rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Split {
    /// About [`TUNE_PERCENT`] % of the frames: the parameters are chosen on these.
    Tune,
    /// The rest: scored once with the chosen parameters.
    Test,
}

/// 64-bit FNV-1a hash of `bytes` (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The SplitMix64 finaliser: a bijection that spreads every input bit over the output.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The part a frame belongs to: [`Split::Tune`] when `mix64(fnv1a64(file)) % 100 <`
/// [`TUNE_PERCENT`].
pub fn split_of(file: &str) -> Split {
    if mix64(fnv1a64(file.as_bytes())) % 100 < TUNE_PERCENT {
        Split::Tune
    } else {
        Split::Test
    }
}

/// The rows of `rows` in `part`, in their order (see [`split_of`]).
pub fn split(rows: &[TruthRow], part: Split) -> Vec<TruthRow> {
    rows.iter()
        .filter(|r| split_of(&r.file) == part)
        .cloned()
        .collect()
}

/// A filter on a group label, `key=value` (`tirroi tune --where`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Where {
    /// Group column: one of [`GROUP_COLUMNS`] or `range`.
    pub key: String,
    /// Value the column must have (for `range`: `close`, `mid` or `far`, see
    /// [`eval::range_band`]).
    pub value: String,
}

/// Parses `key=value` with a known group column.
///
/// # Errors
/// One line naming the bad text and what is accepted.
pub fn parse_where(s: &str) -> Result<Where, String> {
    let Some((key, value)) = s.split_once('=') else {
        return Err(format!(
            "`{s}`: expected key=value, e.g. mode=radiometry or range=close"
        ));
    };
    let (key, value) = (key.trim(), value.trim());
    if !(GROUP_COLUMNS.contains(&key) || key == "range") {
        return Err(format!(
            "`{s}`: unknown group `{key}`; expected one of {}, range",
            GROUP_COLUMNS.join(", ")
        ));
    }
    if value.is_empty() {
        return Err(format!("`{s}`: empty value"));
    }
    if key == "range" && !["close", "mid", "far"].contains(&value) {
        return Err(format!(
            "`{s}`: unknown range band `{value}`; expected close, mid or far"
        ));
    }
    Ok(Where {
        key: key.into(),
        value: value.into(),
    })
}

/// The rows whose labels pass every filter: for each key named, the row's value of that
/// group is one of the values given for it (filters on different keys combine with
/// "and", filters on the same key with "or"). No filters keep every row.
pub fn filter(rows: &[TruthRow], wheres: &[Where]) -> Vec<TruthRow> {
    rows.iter()
        .filter(|row| {
            let mut keys: Vec<&str> = wheres.iter().map(|w| w.key.as_str()).collect();
            keys.sort_unstable();
            keys.dedup();
            keys.iter().all(|&key| {
                let value = row
                    .groups
                    .iter()
                    .find(|(k, _)| k == key)
                    .map(|(_, v)| v.as_str());
                wheres
                    .iter()
                    .any(|w| w.key == key && Some(w.value.as_str()) == value)
            })
        })
        .cloned()
        .collect()
}

/// One detector's parameter set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Params {
    /// Otsu parameters.
    Otsu(Otsu),
    /// Adaptive-threshold parameters.
    Adaptive(Adaptive),
    /// WGE parameters.
    Wge(Wge),
    /// DoG parameters.
    Dog(Dog),
    /// `auto` parameters (it has no box rule: setting one does nothing).
    Auto(Auto),
}

/// The command-line name of a box rule.
pub fn box_rule_name(rule: BoxRule) -> &'static str {
    match rule {
        BoxRule::AllForeground => "all-foreground",
        BoxRule::LargestComponent => "largest-component",
    }
}

fn other_rule(rule: BoxRule) -> BoxRule {
    match rule {
        BoxRule::AllForeground => BoxRule::LargestComponent,
        BoxRule::LargestComponent => BoxRule::AllForeground,
    }
}

impl Params {
    /// The core's default parameters of `method` with box rule `rule`.
    pub fn defaults(method: Method, rule: BoxRule) -> Params {
        let mut p = match method {
            Method::Otsu => Params::Otsu(Otsu::default()),
            Method::Adaptive => Params::Adaptive(Adaptive::default()),
            Method::Wge => Params::Wge(Wge::default()),
            Method::Dog => Params::Dog(Dog::default()),
            Method::Auto => Params::Auto(Auto::default()),
        };
        p.set_box_rule(rule);
        p
    }

    /// The parameters of `method` in `bank`.
    pub fn from_bank(bank: &DetectorBank, method: Method) -> Params {
        match method {
            Method::Otsu => Params::Otsu(bank.otsu),
            Method::Adaptive => Params::Adaptive(bank.adaptive),
            Method::Wge => Params::Wge(bank.wge),
            Method::Dog => Params::Dog(bank.dog),
            Method::Auto => Params::Auto(bank.auto),
        }
    }

    /// The detector these parameters belong to.
    pub fn method(&self) -> Method {
        match self {
            Params::Otsu(_) => Method::Otsu,
            Params::Adaptive(_) => Method::Adaptive,
            Params::Wge(_) => Method::Wge,
            Params::Dog(_) => Method::Dog,
            Params::Auto(_) => Method::Auto,
        }
    }

    /// The mask-to-box rule.
    pub fn box_rule(&self) -> BoxRule {
        match self {
            Params::Otsu(p) => p.box_rule,
            Params::Adaptive(p) => p.box_rule,
            Params::Wge(p) => p.box_rule,
            Params::Dog(p) => p.box_rule,
            Params::Auto(p) => p.box_rule(),
        }
    }

    /// Sets the mask-to-box rule.
    pub fn set_box_rule(&mut self, rule: BoxRule) {
        match self {
            Params::Otsu(p) => p.box_rule = rule,
            Params::Adaptive(p) => p.box_rule = rule,
            Params::Wge(p) => p.box_rule = rule,
            Params::Dog(p) => p.box_rule = rule,
            Params::Auto(_) => {}
        }
    }

    /// Whether the core accepts these parameters.
    pub fn is_valid(&self) -> bool {
        match self {
            Params::Otsu(p) => p.validate().is_ok(),
            Params::Adaptive(p) => p.validate().is_ok(),
            Params::Wge(p) => p.validate().is_ok(),
            Params::Dog(p) => p.validate().is_ok(),
            Params::Auto(p) => p.validate().is_ok(),
        }
    }

    /// Puts these parameters into `bank` (the other detectors are left as they are).
    pub fn apply(&self, bank: &mut DetectorBank) {
        match *self {
            Params::Otsu(p) => bank.otsu = p,
            Params::Adaptive(p) => bank.adaptive = p,
            Params::Wge(p) => bank.wge = p,
            Params::Dog(p) => bank.dog = p,
            Params::Auto(p) => bank.auto = p,
        }
    }

    /// `name=value` pairs separated by spaces, the box rule last, e.g.
    /// `block=41 offset_dn=64 box=largest-component` (no commas: a CSV field as is).
    pub fn describe(&self) -> String {
        let rule = box_rule_name(self.box_rule());
        match self {
            Params::Otsu(_) => format!("box={rule}"),
            Params::Adaptive(p) => {
                format!("block={} offset_dn={} box={rule}", p.block, p.offset_dn)
            }
            Params::Wge(p) => format!(
                "drop_fraction={} min_gradient={} box={rule}",
                p.drop_fraction, p.min_gradient
            ),
            Params::Dog(p) => format!(
                "sigma0_px={} sigma_ratio={} levels={} min_response_dn={} box={rule}",
                p.sigma0_px, p.sigma_ratio, p.levels, p.min_response_dn
            ),
            Params::Auto(p) => format!(
                "coarse_sigma={} fine_sigma={} margin_px={}",
                p.coarse_sigma, p.fine_sigma, p.margin_px
            ),
        }
    }

    /// The refinement neighbours: one ladder step down and up of each coordinate, and
    /// the other box rule; only valid sets.
    pub fn neighbours(&self) -> Vec<Params> {
        let mut out = Vec::new();
        let mut flipped = *self;
        flipped.set_box_rule(other_rule(self.box_rule()));
        if flipped != *self {
            out.push(flipped);
        }
        match *self {
            Params::Otsu(_) => {}
            Params::Adaptive(p) => {
                for block in steps(&BLOCK_LADDER, p.block) {
                    out.push(Params::Adaptive(Adaptive { block, ..p }));
                }
                for offset_dn in steps(&OFFSET_LADDER, p.offset_dn) {
                    out.push(Params::Adaptive(Adaptive { offset_dn, ..p }));
                }
            }
            Params::Wge(p) => {
                for drop_fraction in steps(&DROP_LADDER, p.drop_fraction) {
                    out.push(Params::Wge(Wge { drop_fraction, ..p }));
                }
                for min_gradient in steps(&GRADIENT_LADDER, p.min_gradient) {
                    out.push(Params::Wge(Wge { min_gradient, ..p }));
                }
            }
            Params::Dog(p) => {
                for sigma0_px in steps(&SIGMA0_LADDER, p.sigma0_px) {
                    out.push(Params::Dog(Dog { sigma0_px, ..p }));
                }
                for sigma_ratio in steps(&RATIO_LADDER, p.sigma_ratio) {
                    out.push(Params::Dog(Dog { sigma_ratio, ..p }));
                }
                for levels in [p.levels.wrapping_sub(1), p.levels.saturating_add(1)] {
                    out.push(Params::Dog(Dog { levels, ..p }));
                }
                for min_response_dn in steps(&RESPONSE_LADDER, p.min_response_dn) {
                    out.push(Params::Dog(Dog {
                        min_response_dn,
                        ..p
                    }));
                }
            }
            Params::Auto(p) => {
                for coarse_sigma in steps(&AUTO_SIGMA_LADDER, p.coarse_sigma) {
                    out.push(Params::Auto(Auto { coarse_sigma, ..p }));
                }
                for fine_sigma in steps(&AUTO_SIGMA_LADDER, p.fine_sigma) {
                    out.push(Params::Auto(Auto { fine_sigma, ..p }));
                }
            }
        }
        out.retain(Params::is_valid);
        out
    }
}

/// The nearest ladder values below and above `v` (either may be missing).
fn steps<T: PartialOrd + Copy>(ladder: &[T], v: T) -> Vec<T> {
    let below = ladder.iter().rev().find(|&&x| x < v).copied();
    let above = ladder.iter().find(|&&x| x > v).copied();
    below.into_iter().chain(above).collect()
}

/// Refinement ladder of the adaptive `block` (odd pixels).
pub const BLOCK_LADDER: [u16; 29] = [
    3, 5, 7, 9, 11, 13, 15, 17, 21, 25, 29, 33, 37, 41, 47, 53, 61, 71, 81, 91, 101, 111, 121, 141,
    161, 181, 201, 225, 249,
];
/// Refinement ladder of the adaptive `offset_dn` (DN).
pub const OFFSET_LADDER: [i32; 25] = [
    -256, -128, -64, -32, -16, 0, 8, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024,
    1536, 2048, 3072, 4096, 6144,
];
/// Refinement ladder of the WGE `drop_fraction`.
pub const DROP_LADDER: [f32; 19] = [
    0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.93, 0.95, 0.96, 0.97, 0.975, 0.98, 0.985, 0.99, 0.993, 0.995,
    0.997, 0.998, 0.999,
];
/// Refinement ladder of the WGE `min_gradient` (Prewitt L1 DN).
pub const GRADIENT_LADDER: [u32; 25] = [
    0, 8, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144,
    8192, 12288, 16384, 24576, 32768,
];
/// Refinement ladder of the DoG `sigma0_px`.
pub const SIGMA0_LADDER: [f32; 11] = [1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0];
/// Refinement ladder of the DoG `sigma_ratio`.
pub const RATIO_LADDER: [f32; 7] = [1.2, 1.3, 1.4, 1.6, 1.8, 2.0, 2.4];
/// Refinement ladder of the DoG `min_response_dn` (DN).
pub const RESPONSE_LADDER: [u32; 17] = [
    16, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024, 1536, 2048, 3072, 4096, 6144,
];

/// Refinement ladder of `auto`'s `coarse_sigma` and `fine_sigma` (noise units).
pub const AUTO_SIGMA_LADDER: [u16; 11] = [3, 4, 5, 6, 8, 10, 12, 16, 20, 24, 32];

/// The candidate grid of `method` (see the module documentation): every set of the
/// grid with the largest-component rule, then every set with the all-foreground rule;
/// the core defaults are among them; only valid sets.
pub fn grid(method: Method) -> Vec<Params> {
    let mut base = Vec::new();
    match method {
        Method::Otsu => base.push(Params::Otsu(Otsu::default())),
        Method::Adaptive => {
            for block in [11, 21, 41, 61, 81, 121, 161] {
                for offset_dn in [0, 32, 64, 128, 256, 512, 1024, 2048, 4096] {
                    base.push(Params::Adaptive(Adaptive {
                        block,
                        offset_dn,
                        ..Adaptive::default()
                    }));
                }
            }
        }
        Method::Wge => {
            for drop_fraction in [0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998] {
                for min_gradient in [0, 48, 128, 256, 512, 1024, 2048, 4096, 8192] {
                    base.push(Params::Wge(Wge {
                        drop_fraction,
                        min_gradient,
                        ..Wge::default()
                    }));
                }
            }
        }
        Method::Auto => {
            for coarse_sigma in [6, 8, 10, 12, 16] {
                for fine_sigma in [6, 8, 12, 16] {
                    base.push(Params::Auto(Auto {
                        coarse_sigma,
                        fine_sigma,
                        ..Auto::default()
                    }));
                }
            }
        }
        Method::Dog => {
            for sigma0_px in [2.0, 4.0, 8.0] {
                for levels in [3, 5, 7] {
                    for min_response_dn in [64, 128, 256, 512, 1024, 2048] {
                        base.push(Params::Dog(Dog {
                            sigma0_px,
                            sigma_ratio: 1.6,
                            levels,
                            min_response_dn,
                            ..Dog::default()
                        }));
                    }
                }
            }
        }
    }
    base.retain(Params::is_valid);
    let mut out = Vec::with_capacity(2 * base.len() + 2);
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        for p in &base {
            let mut q = *p;
            q.set_box_rule(rule);
            if !out.contains(&q) {
                out.push(q);
            }
        }
    }
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        let d = Params::defaults(method, rule);
        if !out.contains(&d) {
            out.push(d);
        }
    }
    out
}

/// One parameter set of one method scored on a set of frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// Method name.
    pub method: &'static str,
    /// The parameters, as [`Params::describe`].
    pub params: String,
    /// Mean IoU over the frames.
    pub mean_iou: f64,
    /// Median IoU over the frames.
    pub median_iou: f64,
    /// Mean core time per frame, ms (one run per frame, frames in parallel).
    pub mean_time_ms: f64,
}

impl Trial {
    /// Whether `self` scores better than `other`: a higher mean IoU, or a mean IoU
    /// within 10⁻⁹ and a mean time at least 25 % lower. (One-run times of frames scored
    /// in parallel, beside PNG decoding and whatever else the machine runs, scatter by
    /// 10–20 %: without the margin, equal detections would be ranked by timing noise
    /// and the search would not repeat itself.)
    pub fn beats(&self, other: &Trial) -> bool {
        const EPS: f64 = 1e-9;
        self.mean_iou > other.mean_iou + EPS
            || ((self.mean_iou - other.mean_iou).abs() <= EPS
                && self.mean_time_ms < 0.75 * other.mean_time_ms)
    }
}

/// How to search.
#[derive(Debug, Clone)]
pub struct SearchOptions {
    /// Bit depth of the frames (None: from the file, as `tirroi eval`).
    pub bits: Option<u8>,
    /// Most refinement moves after the grid (0: the grid alone). Default 12.
    pub refine_steps: usize,
    /// Grid sets refined per method (the best by mean IoU). Default 3.
    pub starts: usize,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            bits: None,
            refine_steps: 12,
            starts: 3,
        }
    }
}

/// The best parameter set of one method and its trial.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodBest {
    /// The parameters.
    pub params: Params,
    /// Their scores on the frames searched.
    pub trial: Trial,
    /// Refinement moves made from the grid set this one was reached from (fewer than
    /// [`SearchOptions::refine_steps`]: the refinement stopped at a local optimum).
    pub moves: usize,
}

/// What [`search`] found.
pub struct TuneResult {
    /// Every candidate scored, grouped by method (in the order asked), each method's
    /// in the order scored.
    pub trials: Vec<Trial>,
    /// The best set of each method, in the order asked.
    pub best: Vec<MethodBest>,
    /// Default detectors with each searched method's best set in place.
    pub bank: DetectorBank,
}

/// Scores `params` on `rows` (frames in parallel, one run each).
///
/// # Errors
/// [`EvalError`] naming the frame for an unreadable file or a detector error.
pub fn evaluate(
    images: &Path,
    rows: &[TruthRow],
    params: &Params,
    bits: Option<u8>,
) -> Result<Trial, EvalError> {
    let mut trials = evaluate_together(images, rows, &[*params], bits)?;
    Ok(trials.remove(0))
}

/// Scores several parameter sets, of different methods and with one box rule, in one
/// pass over the frames (each frame is read once for all of them); one trial per set,
/// in order.
///
/// # Errors
/// [`EvalError`] when two sets are of one method or their box rules differ, and as
/// [`evaluate`].
pub fn evaluate_together(
    images: &Path,
    rows: &[TruthRow],
    sets: &[Params],
    bits: Option<u8>,
) -> Result<Vec<Trial>, EvalError> {
    if sets.is_empty() {
        return Ok(Vec::new());
    }
    let methods: Vec<Method> = sets.iter().map(Params::method).collect();
    for (k, p) in sets.iter().enumerate() {
        if methods[..k].contains(&p.method()) {
            return Err(EvalError(format!(
                "parameter sets scored together need distinct methods: {}",
                sets.iter()
                    .map(|p| format!("{} {}", p.method(), p.describe()))
                    .collect::<Vec<_>>()
                    .join("; ")
            )));
        }
    }
    // Each set brings its own box rule (`Params::apply`).
    let options = EvalOptions {
        methods,
        repeat: 1,
        box_rule: None,
        bits,
        track: eval::Track::Off,
    };
    let make_bank = || {
        let mut bank = DetectorBank::default();
        for p in sets {
            p.apply(&mut bank);
        }
        bank
    };
    let scores = eval::score(images, rows, &options, &make_bank, &|| {})?;
    Ok(sets
        .iter()
        .map(|p| {
            let name = p.method().name();
            let mine: Vec<&FrameScore> = scores.iter().filter(|s| s.method == name).collect();
            let s = eval::stats(name, "all", "all", &mine);
            Trial {
                method: name,
                params: p.describe(),
                mean_iou: s.mean_iou,
                median_iou: s.median_iou,
                mean_time_ms: s.mean_time_ms,
            }
        })
        .collect())
}

/// One method's search: its trials so far, each parameter set once.
struct MethodSearch {
    method: Method,
    trials: Vec<Trial>,
    seen: HashMap<String, usize>,
    grid: Vec<(Params, usize)>,
}

impl MethodSearch {
    fn record(&mut self, p: &Params, t: Trial, on_trial: &dyn Fn(&Trial)) -> usize {
        on_trial(&t);
        self.trials.push(t);
        let i = self.trials.len() - 1;
        self.seen.insert(p.describe(), i);
        i
    }

    /// Index of the trial of `p`, scoring it first when new.
    fn score(
        &mut self,
        p: &Params,
        images: &Path,
        rows: &[TruthRow],
        options: &SearchOptions,
        on_trial: &dyn Fn(&Trial),
    ) -> Result<usize, EvalError> {
        if let Some(&i) = self.seen.get(&p.describe()) {
            return Ok(i);
        }
        let t = evaluate(images, rows, p, options.bits)?;
        Ok(self.record(p, t, on_trial))
    }

    /// Steepest ascent from each of the best grid sets; the best end point.
    fn refine(
        &mut self,
        images: &Path,
        rows: &[TruthRow],
        options: &SearchOptions,
        on_trial: &dyn Fn(&Trial),
    ) -> Result<MethodBest, EvalError> {
        let mut ranked = self.grid.clone();
        // By mean IoU, grid order among equals.
        ranked.sort_by(|a, b| {
            self.trials[b.1]
                .mean_iou
                .total_cmp(&self.trials[a.1].mean_iou)
        });
        let mut best: Option<(Params, usize, usize)> = None;
        for &(start, start_at) in ranked.iter().take(options.starts.max(1)) {
            let (mut here, mut at, mut moves) = (start, start_at, 0);
            while moves < options.refine_steps {
                let mut next: Option<(Params, usize)> = None;
                for p in here.neighbours() {
                    let i = self.score(&p, images, rows, options, on_trial)?;
                    let incumbent = next.map_or(at, |(_, n)| n);
                    if self.trials[i].beats(&self.trials[incumbent]) {
                        next = Some((p, i));
                    }
                }
                match next {
                    Some((p, i)) => {
                        (here, at) = (p, i);
                        moves += 1;
                    }
                    None => break,
                }
            }
            if best.is_none_or(|(_, b, _)| self.trials[at].beats(&self.trials[b])) {
                best = Some((here, at, moves));
            }
        }
        let Some((params, at, moves)) = best else {
            return Err(EvalError(format!("{}: empty candidate grid", self.method)));
        };
        Ok(MethodBest {
            params,
            trial: self.trials[at].clone(),
            moves,
        })
    }
}

/// Searches the parameters of `method` on `rows`: [`search`] with one method. Returns
/// every trial, in the order scored, and the best.
///
/// # Errors
/// As [`search`].
pub fn search_method(
    images: &Path,
    rows: &[TruthRow],
    method: Method,
    options: &SearchOptions,
    on_trial: &dyn Fn(&Trial),
) -> Result<(Vec<Trial>, MethodBest), EvalError> {
    let mut result = search(images, rows, &[method], options, on_trial)?;
    let best = result.best.remove(0);
    Ok((result.trials, best))
}

/// Searches the parameters of every method of `methods` on `rows` (see the module
/// documentation). The grids of all methods run side by side: each pass over the
/// frames scores one grid set of every method (with the same box rule), so a frame is
/// read once per pass, not once per set. Then each method is refined on its own.
/// `on_trial` sees each trial as it is scored (progress).
///
/// # Errors
/// [`EvalError`] for no rows, an unreadable frame or a detector error.
pub fn search(
    images: &Path,
    rows: &[TruthRow],
    methods: &[Method],
    options: &SearchOptions,
    on_trial: &dyn Fn(&Trial),
) -> Result<TuneResult, EvalError> {
    if rows.is_empty() {
        return Err(EvalError(format!(
            "{}: no frames to tune on",
            images.display()
        )));
    }
    let mut searches: Vec<MethodSearch> = Vec::new();
    for &method in methods {
        if !searches.iter().any(|s| s.method == method) {
            searches.push(MethodSearch {
                method,
                trials: Vec::new(),
                seen: HashMap::new(),
                grid: Vec::new(),
            });
        }
    }
    // Largest-component sets first, then all-foreground ones: the scoring order decides
    // ties (the first scored wins), and the tuned sets in `crate::tuned` came from it.
    for rule in [BoxRule::LargestComponent, BoxRule::AllForeground] {
        let lists: Vec<Vec<Params>> = searches
            .iter()
            .map(|s| {
                grid(s.method)
                    .into_iter()
                    .filter(|p| p.box_rule() == rule)
                    .collect()
            })
            .collect();
        let passes = lists.iter().map(Vec::len).max().unwrap_or(0);
        for pass in 0..passes {
            let mut sets = Vec::new();
            let mut owners = Vec::new();
            for (k, list) in lists.iter().enumerate() {
                if let Some(p) = list.get(pass) {
                    if !searches[k].seen.contains_key(&p.describe()) {
                        sets.push(*p);
                        owners.push(k);
                    }
                }
            }
            let trials = evaluate_together(images, rows, &sets, options.bits)?;
            for ((p, t), k) in sets.iter().zip(trials).zip(owners) {
                let i = searches[k].record(p, t, on_trial);
                searches[k].grid.push((*p, i));
            }
        }
    }
    let mut result = TuneResult {
        trials: Vec::new(),
        best: Vec::new(),
        bank: DetectorBank::default(),
    };
    for mut s in searches {
        let best = s.refine(images, rows, options, on_trial)?;
        best.params.apply(&mut result.bank);
        result.trials.append(&mut s.trials);
        result.best.push(best);
    }
    Ok(result)
}

/// `trials.csv`: `method,params,mean_iou,median_iou,mean_time_ms`, one row per trial.
pub fn trials_csv(trials: &[Trial]) -> String {
    let mut s = String::from("method,params,mean_iou,median_iou,mean_time_ms\n");
    for t in trials {
        s.push_str(&format!(
            "{},{},{:.4},{:.4},{:.4}\n",
            t.method, t.params, t.mean_iou, t.median_iou, t.mean_time_ms
        ));
    }
    s
}

/// The options of `tirroi tune`.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// Directory of frames.
    #[arg(long)]
    pub images: PathBuf,
    /// Labels (default: IMAGES/truth.csv), header `file,x0,y0,x1,y1[,extra...]`.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Detector to tune: otsu, adaptive, wge, dog, or all.
    #[arg(long, default_value = "all", value_parser = parse_method_list)]
    pub method: MethodList,
    /// Keep only frames with this group label, `key=value`; key: mode, scale, target,
    /// material, illumination or range (close <= 50 m, far >= 300 m, else mid).
    /// Repeat it: different keys must all match, values of one key are alternatives.
    #[arg(long = "where", value_name = "KEY=VALUE", value_parser = parse_where)]
    pub wheres: Vec<Where>,
    /// Bit depth of the DN (default: 14 for 16-bit files whose DN fit).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub bits: Option<u8>,
    /// Most refinement moves per method after the grid (0: grid only).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(0..=100))]
    pub refine_steps: u32,
    /// Grid sets refined per method (the best by mean IoU).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=20))]
    pub starts: u32,
    /// Write trials.csv (method,params,mean_iou,median_iou,mean_time_ms) here.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The methods of `--method`.
#[derive(Debug, Clone)]
pub struct MethodList(pub Vec<Method>);

/// Parses `all` or one method name.
///
/// # Errors
/// One line naming the accepted names.
pub fn parse_method_list(s: &str) -> Result<MethodList, String> {
    if s == "all" {
        return Ok(MethodList(Method::ALL.to_vec()));
    }
    Method::from_name(s)
        .map(|m| MethodList(vec![m]))
        .ok_or_else(|| {
            format!("unknown method `{s}`; expected otsu, adaptive, wge, dog, auto or all")
        })
}

/// Runs `tirroi tune`: filters the rows, splits them, searches each method on the tune
/// part, scores the best and the default sets on both parts, prints a Markdown table
/// and writes `trials.csv` into `--out`.
///
/// # Errors
/// One line: unreadable labels or frames, no frame left by the filters, an empty tune
/// or test part, an unwritable output.
pub fn run(args: &TuneArgs) -> Result<(), String> {
    let truth = args
        .truth
        .clone()
        .unwrap_or_else(|| args.images.join("truth.csv"));
    let rows = eval::read_truth(&truth).map_err(|e| e.to_string())?;
    let rows = filter(&rows, &args.wheres);
    if rows.is_empty() {
        let w: Vec<String> = args
            .wheres
            .iter()
            .map(|w| format!("{}={}", w.key, w.value))
            .collect();
        return Err(format!(
            "{}: no frame matches --where {}",
            truth.display(),
            w.join(" --where ")
        ));
    }
    let (tune_rows, test_rows) = (split(&rows, Split::Tune), split(&rows, Split::Test));
    if tune_rows.is_empty() || test_rows.is_empty() {
        return Err(format!(
            "{}: {} frames give {} to tune on and {} to test; need at least one of each",
            truth.display(),
            rows.len(),
            tune_rows.len(),
            test_rows.len()
        ));
    }
    let options = SearchOptions {
        bits: args.bits,
        refine_steps: args.refine_steps as usize,
        starts: args.starts as usize,
    };
    let methods = &args.method.0;
    let planned: usize = methods.iter().map(|&m| grid(m).len()).sum();
    let bar = crate::progress::bar(planned, "trials");
    let start = std::time::Instant::now();
    let result = search(&args.images, &tune_rows, methods, &options, &|_| {
        bar.inc(1);
        if bar.position() > bar.length().unwrap_or(0) {
            bar.set_length(bar.position());
        }
    })
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let search_s = start.elapsed().as_secs_f64();

    let mut table = String::from(
        "| method | parameters | refine moves | tune mean IoU | tune median IoU | test mean IoU | test median IoU | mean time [ms] | defaults: tune mean IoU | defaults: test mean IoU |\n|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for best in &result.best {
        let m = best.params.method();
        let test = evaluate(&args.images, &test_rows, &best.params, args.bits)
            .map_err(|e| e.to_string())?;
        let defaults = Params::defaults(m, BoxRule::LargestComponent);
        let default_tune = result
            .trials
            .iter()
            .find(|t| t.method == m.name() && t.params == defaults.describe())
            .map(|t| t.mean_iou)
            .unwrap_or(f64::NAN);
        let default_test =
            evaluate(&args.images, &test_rows, &defaults, args.bits).map_err(|e| e.to_string())?;
        table.push_str(&format!(
            "| {m} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {default_tune:.3} | {:.3} |\n",
            best.params.describe(),
            best.moves,
            best.trial.mean_iou,
            best.trial.median_iou,
            test.mean_iou,
            test.median_iou,
            test.mean_time_ms,
            default_test.mean_iou,
        ));
    }
    print!("{table}");
    println!(
        "\n{} frames ({} tune, {} test; split: mix64(fnv1a64(file)) % 100 < {TUNE_PERCENT}); {} trials in {search_s:.1} s. Defaults: the core's with the largest-component rule. Mean time: test part, one run per frame.",
        rows.len(),
        tune_rows.len(),
        test_rows.len(),
        result.trials.len(),
    );
    if let Some(out) = &args.out {
        std::fs::create_dir_all(out)
            .map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
        let p = out.join("trials.csv");
        std::fs::write(&p, trials_csv(&result.trials))
            .map_err(|e| format!("{}: cannot write: {e}", p.display()))?;
        println!("wrote {}", p.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_reference_vectors() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn grids_hold_the_defaults_and_are_valid() {
        for m in Method::ALL {
            let g = grid(m);
            for rule in [BoxRule::AllForeground, BoxRule::LargestComponent] {
                assert!(g.contains(&Params::defaults(m, rule)), "{m} {rule:?}");
            }
            assert!(g.iter().all(|p| p.is_valid() && p.method() == m));
            let mut names: Vec<String> = g.iter().map(Params::describe).collect();
            names.sort();
            names.dedup();
            assert_eq!(names.len(), g.len(), "{m}: a set twice");
        }
        // The sizes the module documentation gives.
        let sizes = Method::ALL.map(|m| grid(m).len());
        assert_eq!(sizes, [2, 126, 144, 96, 20]);
    }

    #[test]
    fn sets_scored_together_need_distinct_methods_and_keep_their_own_rules() {
        let lc = BoxRule::LargestComponent;
        let af = BoxRule::AllForeground;
        let a = Params::defaults(Method::Adaptive, lc);
        let none = Path::new("/nonexistent");
        assert!(evaluate_together(none, &[], &[a, a], None).is_err());
        assert_eq!(evaluate_together(none, &[], &[], None), Ok(Vec::new()));

        // The procedural fixture frames, on disk with their truth.
        let dir = std::env::temp_dir().join(format!("tirroi-tune-rules-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut rows = Vec::new();
        for (name, spec) in crate::fixture::standard_set() {
            let fx = crate::fixture::render(&spec);
            let file = format!("{name}.png");
            crate::image_io::write_png16(&dir.join(&file), &fx.frame).unwrap();
            rows.push(TruthRow {
                file,
                roi: fx.truth,
                groups: Vec::new(),
                range_m: None,
            });
        }
        // Sets of different rules scored together score as each alone.
        let sets = [a, Params::defaults(Method::Wge, af)];
        let together = evaluate_together(&dir, &rows, &sets, None).unwrap();
        for (p, t) in sets.iter().zip(&together) {
            let alone = evaluate(&dir, &rows, p, None).unwrap();
            assert_eq!((&t.params, t.mean_iou), (&alone.params, alone.mean_iou));
        }
        // And the rule matters on these frames, so the check above has teeth.
        let wge_lc = evaluate(&dir, &rows, &Params::defaults(Method::Wge, lc), None).unwrap();
        assert!((wge_lc.mean_iou - together[1].mean_iou).abs() > 0.05);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn neighbours_step_one_rung() {
        let p = Params::defaults(Method::Adaptive, BoxRule::LargestComponent);
        let n: Vec<String> = p.neighbours().iter().map(Params::describe).collect();
        assert_eq!(
            n,
            [
                "block=41 offset_dn=64 box=all-foreground",
                "block=37 offset_dn=64 box=largest-component",
                "block=47 offset_dn=64 box=largest-component",
                "block=41 offset_dn=48 box=largest-component",
                "block=41 offset_dn=96 box=largest-component",
            ]
        );
        let top = Params::Dog(Dog {
            levels: 8,
            ..Dog::default()
        });
        assert!(top.neighbours().iter().all(Params::is_valid));
    }

    #[test]
    fn where_parses_and_filters() {
        assert!(parse_where("mode").is_err());
        assert!(parse_where("colour=red").is_err());
        assert!(parse_where("range=near").is_err());
        assert!(parse_where("mode=").is_err());
        let w = |s: &str| parse_where(s).unwrap();
        let row = |file: &str, g: &[(&str, &str)]| TruthRow {
            file: file.into(),
            roi: tirroi_core::Roi::new(0, 0, 1, 1),
            groups: g
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
            range_m: None,
        };
        let rows = [
            row("a", &[("mode", "radiometry"), ("range", "close")]),
            row("b", &[("mode", "radiometry"), ("range", "far")]),
            row("c", &[("mode", "detection"), ("range", "close")]),
            row("d", &[]),
        ];
        let files = |ws: &[Where]| -> Vec<String> {
            filter(&rows, ws).into_iter().map(|r| r.file).collect()
        };
        assert_eq!(files(&[]), ["a", "b", "c", "d"]);
        assert_eq!(files(&[w("mode=radiometry"), w("range=close")]), ["a"]);
        assert_eq!(files(&[w("range=close"), w("range=far")]), ["a", "b", "c"]);
        assert!(files(&[w("material=mono")]).is_empty());
    }
}
