//! Test sets: labelled frames that detectors are *scored* on and never tuned on
//! (`tirroi testset`, issue 16). Three kinds, each deterministic from a seed:
//!
//! - [`Kind::Fixtures`]: the procedural generator of `tirroi fixtures` / `tirroi demo`
//!   ([`crate::imaging::fixture`]; multi-octave texture, a limb, a two-part target)
//!   made a seeded family: background (Earth or deep space), target size and position,
//!   contrast (warm and cold targets), saturation, texture amplitude, noise, and frames
//!   without a target ([`fixtures`]);
//! - [`Kind::Dark`]: the real Hayabusa2 TIR deep-space frame (`dark_20180629_083003.fit`,
//!   its 328 × 248 effective area) read out as the renderer's fixed-gain readout reads
//!   deep space, with new noise realisations at the camera's NETD, bit depths and gains;
//!   half of the frames without a target, the rest with a rendered target composited
//!   in ([`dark`]);
//! - [`Kind::RealEarth`]: rendered targets composited over 328 × 248 windows of a real
//!   10.7 µm satellite image of the Earth at 4 km per pixel, its brightness temperature
//!   turned into band radiance by the camera model, read out (auto range or fixed
//!   gain) with noise; a third of the windows without a target ([`real_earth`]).
//!
//! Targets come from the renderer itself ([`targets`]): the cube + cylinder and the
//! Tango-like satellite, thermal solutions, attitudes and ranges planned as a dataset
//! is, rendered noise-free over deep space, so each frame has the target's signal F
//! (W m⁻², coverage-weighted on partial pixels) and its coverage. A composite is then
//! physical: F = F_target + (1 − coverage)·F_background per pixel, read out by the
//! renderer's own readout stage ([`crate::imaging::render::read_out`]).
//!
//! **Output** (the dataset format of `tirroi render`, so `tirroi eval` scores it):
//! `NNNNNN.png` (16-bit grayscale DN), `truth.csv` ([`crate::dataset::TRUTH_CSV_HEADER`];
//! four empty box fields on frames without a target; the `*_quarter` box beside the ½
//! box), `metadata.jsonl` (one [`TestRecord`] per frame), and with `preview` the
//! frames contrast-stretched with their truth box in `preview/`.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use tirroi_core::Roi;

use super::DatasetError;
use super::images::atomic_write;
use super::labels::{SEQUENCE_COLUMNS, TRUTH_CSV_HEADER};
use crate::imaging::image_io::{FrameBuf, write_png16};
use crate::imaging::overlay;
use crate::progress;

pub mod composite;
pub mod dark;
pub mod fixtures;
pub mod real_earth;
pub mod targets;

/// The default reference folder, relative to the repository root (the working
/// directory of a `tirroi` run from the repository).
pub const DEFAULT_REFERENCE_DIR: &str = "../shared/reference";

/// Minimum frames of a test set: enough that a no-target share and a hit rate are
/// measured to a few percent.
pub const MIN_COUNT: usize = 1;

/// Largest `count` accepted (a guard against a typo that would fill the disk).
pub const MAX_COUNT: usize = 100_000;

/// Colour of the truth box in previews (green).
const TRUTH_COLOUR: [u8; 3] = [0, 230, 0];

/// Which test set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The procedural family of `tirroi fixtures`.
    Fixtures,
    /// The real Hayabusa2 TIR dark frame, with and without rendered targets.
    Dark,
    /// Rendered targets over windows of a real LWIR image of the Earth.
    RealEarth,
}

impl Kind {
    /// The kind's name on the command line and in `metadata.jsonl`.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Fixtures => "fixtures",
            Kind::Dark => "dark",
            Kind::RealEarth => "real-earth",
        }
    }

    /// Parses `fixtures`, `dark` or `real-earth`.
    ///
    /// # Errors
    /// A message naming the choices.
    pub fn parse(s: &str) -> Result<Kind, String> {
        match s {
            "fixtures" => Ok(Kind::Fixtures),
            "dark" => Ok(Kind::Dark),
            "real-earth" => Ok(Kind::RealEarth),
            _ => Err(format!(
                "unknown test set `{s}`; expected fixtures, dark or real-earth"
            )),
        }
    }

    /// The default share of frames without a target: fixtures 0.2; dark 0.5 (its
    /// point is the false alarms on the real camera's deep space); real Earth 0.35
    /// (at least 30 % windows without a target, for the false-alarm rate).
    pub fn default_no_target_fraction(self) -> f64 {
        match self {
            Kind::Fixtures => 0.2,
            Kind::Dark => 0.5,
            Kind::RealEarth => 0.35,
        }
    }
}

/// What to write.
#[derive(Debug, Clone)]
pub struct TestsetOptions {
    /// Which test set.
    pub kind: Kind,
    /// Frames (1..=[`MAX_COUNT`]).
    pub count: usize,
    /// Seed: every frame derives from it and its index alone.
    pub seed: u64,
    /// Folder holding `hayabusa2-tir/` and `earth-lwir/` (dark and real-Earth kinds).
    pub reference: PathBuf,
    /// Share of frames without a target, 0..=1 (`None`: [`Kind::default_no_target_fraction`]).
    pub no_target_fraction: Option<f64>,
    /// Also write `preview/`.
    pub preview: bool,
    /// Show a progress bar.
    pub progress: bool,
    /// Frames per sequence (real-Earth only): the window slides over the real image
    /// from frame to frame ([`real_earth::frames`]); `None`: independent frames.
    pub sequence_frames: Option<usize>,
}

/// The labels and provenance of one test frame (a line of `metadata.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct TestRecord {
    /// Index in the set.
    pub index: usize,
    /// PNG file name.
    pub file: String,
    /// Test set kind ([`Kind::name`]).
    pub kind: String,
    /// What lies behind the target: `space` or `earth` (fixtures), `dark-frame`,
    /// `real-earth`.
    pub background: String,
    /// Truth box [x0, y0, x1, y1) of the pixels covered at least ½ (all 0: no target).
    pub bbox: [u16; 4],
    /// Truth box of the pixels covered more than ¼ (all 0: no target).
    pub bbox_quarter: [u16; 4],
    /// `fixture`, the rendered target's model (`cube-cylinder`, `tango`), or `none`.
    pub target: String,
    /// Material case of a rendered cube + cylinder.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// `sunlit` or `eclipse` (rendered targets).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub illumination: Option<String>,
    /// Camera–target distance, m (rendered targets).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_m: Option<f64>,
    /// Mode label of `truth.csv` (`radiometry` for the real-data kinds; none for fixtures).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mode: Option<String>,
    /// DN map: `fixed-gain`, `auto` (Eq. 17) or `fixture` (the generator's own DN).
    pub readout: String,
    /// Bit depth of the DN.
    pub bits: u8,
    /// Factor on the DN map's gain (1: the readout as is).
    pub gain_factor: f64,
    /// Noise seed (`None`: no added noise).
    pub noise_seed: Option<u64>,
    /// Added noise σ, DN.
    pub noise_sigma_dn: f64,
    /// Fraction of the frame's pixels that see the Earth (not the target).
    pub earth_fraction: f64,
    /// Pixels at the DN map's maximum.
    pub saturated_px: usize,
    /// Pixels in the target mask (coverage ≥ ½).
    pub mask_px: usize,
    /// Fixtures: the generator's spec (target, Earth and texture DN, noise σ, seed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fixture: Option<FixtureParams>,
    /// Real Earth: the window's top-left corner in the source image, px, and its
    /// flip (0 none, 1 left-right, 2 up-down, 3 both).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub window: Option<[usize; 3]>,
    /// Real Earth: min and max brightness temperature of the window, K.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub window_bt_k: Option<[f64; 2]>,
    /// The sequence the frame belongs to (`--sequence-frames`), 0, 1, …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<usize>,
    /// The frame's place in its sequence, 0, 1, …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<usize>,
}

/// The procedural generator's parameters of a fixture frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FixtureParams {
    /// Mean DN of the target's brightest face (above 2ⁿ − 1: saturated).
    pub target_dn: u16,
    /// Mean DN of the Earth texture.
    pub earth_dn: u16,
    /// Peak-to-peak amplitude of the Earth texture, DN.
    pub texture_dn: u16,
    /// σ of the additive noise, DN.
    pub noise_dn: f64,
    /// The generator's seed.
    pub seed: u64,
}

/// One finished test frame.
#[derive(Debug, Clone)]
pub struct TestFrame {
    /// The DN frame.
    pub frame: FrameBuf,
    /// Its labels.
    pub record: TestRecord,
}

/// Totals of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TestsetSummary {
    /// Frames written.
    pub frames: usize,
    /// Frames without a target.
    pub no_target: usize,
}

/// The box as four numbers, all 0 for an empty box.
pub(crate) fn box_array(r: Roi) -> [u16; 4] {
    if r.is_empty() { [0; 4] } else { r.to_array() }
}

/// Whether frame `index` of a set has no target: the first ⌈share × count⌉ of a
/// seeded permutation (so the share is exact, and the frames mix with every variant).
pub fn no_target_frames(count: usize, share: f64, seed: u64) -> Vec<bool> {
    use rand::SeedableRng;
    use rand::seq::SliceRandom;
    let k = ((share.clamp(0.0, 1.0) * count as f64).ceil() as usize).min(count);
    let mut order: Vec<usize> = (0..count).collect();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(crate::seed::splitmix64(seed ^ NO_TARGET_SALT));
    order.shuffle(&mut rng);
    let mut none = vec![false; count];
    for &i in &order[..k] {
        none[i] = true;
    }
    none
}

/// Salt of the no-target permutation's seed.
const NO_TARGET_SALT: u64 = 0x7E57_0000_0000_00A0;

/// The reference file `rel` under `reference`, or an error naming it and the flag.
///
/// # Errors
/// A message naming the missing file.
pub fn reference_file(reference: &Path, rel: &str) -> Result<PathBuf, DatasetError> {
    let p = reference.join(rel);
    if p.is_file() {
        Ok(p)
    } else {
        Err(DatasetError(format!(
            "{}: not found: this test set needs the reference data (`{rel}` under the folder given by --reference, default {DEFAULT_REFERENCE_DIR})",
            p.display()
        )))
    }
}

/// Makes the frames of a test set in memory (deterministic; in parallel).
///
/// # Errors
/// [`DatasetError`] for a bad count or share, missing or unreadable reference data, or
/// a frame the renderer refuses.
pub fn make_frames(
    opts: &TestsetOptions,
    bar: &ProgressBar,
) -> Result<Vec<TestFrame>, DatasetError> {
    if !(MIN_COUNT..=MAX_COUNT).contains(&opts.count) {
        return Err(DatasetError(format!(
            "--count {}: expected {MIN_COUNT}..={MAX_COUNT}",
            opts.count
        )));
    }
    let share = opts
        .no_target_fraction
        .unwrap_or_else(|| opts.kind.default_no_target_fraction());
    if !(0.0..=1.0).contains(&share) {
        return Err(DatasetError(format!(
            "--no-target-fraction {share}: expected 0..=1"
        )));
    }
    let none = match opts.sequence_frames {
        None => no_target_frames(opts.count, share, opts.seed),
        Some(n) if opts.kind == Kind::RealEarth && (2..=MAX_SEQUENCE_FRAMES).contains(&n) => {
            // The share counts sequences: a sequence is with or without a target.
            let sequences = no_target_frames(opts.count.div_ceil(n), share, opts.seed);
            (0..opts.count).map(|i| sequences[i / n]).collect()
        }
        Some(n) => {
            return Err(DatasetError(format!(
                "--sequence-frames {n}: expected 2..={MAX_SEQUENCE_FRAMES}, with --kind real-earth"
            )));
        }
    };
    match opts.kind {
        Kind::Fixtures => Ok(fixtures::frames(opts.seed, &none, bar)),
        Kind::Dark => dark::frames(&opts.reference, opts.seed, &none, bar),
        Kind::RealEarth => {
            real_earth::frames(&opts.reference, opts.seed, &none, opts.sequence_frames, bar)
        }
    }
}

/// Most frames per real-Earth sequence (`--sequence-frames`).
pub const MAX_SEQUENCE_FRAMES: usize = 100;

/// The frame file name of index `i`.
pub fn file_name(i: usize) -> String {
    format!("{i:06}.png")
}

/// Writes a test set into `dir`: PNG frames, `truth.csv`, `metadata.jsonl`, and
/// `preview/` with `opts.preview` (module docs).
///
/// # Errors
/// [`DatasetError`] as [`make_frames`], or an unwritable output (named).
pub fn write_testset(opts: &TestsetOptions, dir: &Path) -> Result<TestsetSummary, DatasetError> {
    let io = |p: &Path, e: std::io::Error| DatasetError(format!("{}: {e}", p.display()));
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    if opts.preview {
        let p = dir.join("preview");
        std::fs::create_dir_all(&p).map_err(|e| io(&p, e))?;
    }
    let bar = if opts.progress {
        progress::bar(opts.count, "frames")
    } else {
        ProgressBar::hidden()
    };
    let frames = make_frames(opts, &bar)?;
    bar.finish_and_clear();
    frames.par_iter().try_for_each(|f| {
        write_png16(&dir.join(&f.record.file), &f.frame)
            .map_err(|e| DatasetError(e.to_string()))?;
        if opts.preview {
            let truth = Roi::new(
                f.record.bbox[0],
                f.record.bbox[1],
                f.record.bbox[2],
                f.record.bbox[3],
            );
            let img = overlay::frame_with_boxes(&f.frame, &[(truth, TRUTH_COLOUR)], 2);
            overlay::save(&img, &dir.join("preview").join(&f.record.file))
                .map_err(|e| DatasetError(e.to_string()))?;
        }
        Ok::<(), DatasetError>(())
    })?;
    let (csv, jsonl) = labels(&frames)?;
    atomic_write(&dir.join("truth.csv"), csv.as_bytes())?;
    atomic_write(&dir.join("metadata.jsonl"), jsonl.as_bytes())?;
    Ok(TestsetSummary {
        frames: frames.len(),
        no_target: frames.iter().filter(|f| f.record.bbox == [0; 4]).count(),
    })
}

/// `truth.csv` and `metadata.jsonl` of `frames` (the renderer's columns).
///
/// # Errors
/// A serialisation error (not expected).
pub fn labels(frames: &[TestFrame]) -> Result<(String, String), DatasetError> {
    // Sequences add the renderer's two columns (other sets keep their bytes).
    let sequences = frames.iter().any(|f| f.record.sequence.is_some());
    let mut csv = String::from(TRUTH_CSV_HEADER.trim_end());
    if sequences {
        csv.push_str(SEQUENCE_COLUMNS);
    }
    csv.push('\n');
    let mut jsonl = String::new();
    let boxed = |b: [u16; 4]| {
        if Roi::new(b[0], b[1], b[2], b[3]).is_empty() {
            ",,,".to_string()
        } else {
            format!("{},{},{},{}", b[0], b[1], b[2], b[3])
        }
    };
    for f in frames {
        let r = &f.record;
        // file, box, mode, scale, target, material, illumination, range_m,
        // earth_fraction, noise_seed, bits, quarter box, signal_to_clutter and
        // visible_share (not computed for test frames: empty).
        csv.push_str(&format!(
            "{},{},{},,{},{},{},{},{:.4},{},{},{},,",
            r.file,
            boxed(r.bbox),
            r.mode.as_deref().unwrap_or(""),
            r.target,
            r.material.as_deref().unwrap_or(""),
            r.illumination.as_deref().unwrap_or(""),
            r.range_m.map_or(String::new(), |v| format!("{v:.3}")),
            r.earth_fraction,
            r.noise_seed.map_or(String::new(), |s| s.to_string()),
            r.bits,
            boxed(r.bbox_quarter),
        ));
        if sequences {
            let field = |v: Option<usize>| v.map_or(String::new(), |v| v.to_string());
            csv.push_str(&format!(",{},{}", field(r.sequence), field(r.frame)));
        }
        csv.push('\n');
        jsonl.push_str(&serde_json::to_string(r).map_err(|e| DatasetError(e.to_string()))?);
        jsonl.push('\n');
    }
    Ok((csv, jsonl))
}

/// For tests: the repository's `../shared/reference` folder when it holds `file`;
/// otherwise prints `SKIPPED` and gives `None` (the real data is not in every checkout).
#[cfg(test)]
pub(crate) fn test_reference(file: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference");
    if p.join(file).is_file() {
        Some(p)
    } else {
        println!("SKIPPED: no reference data at {}", p.display());
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_target_share_is_exact_and_seeded() {
        for (count, share) in [(10, 0.35), (200, 0.2), (7, 1.0), (5, 0.0)] {
            let a = no_target_frames(count, share, 42);
            let k = a.iter().filter(|&&b| b).count();
            assert_eq!(k, (share * count as f64).ceil() as usize);
            assert_eq!(a, no_target_frames(count, share, 42));
        }
        assert_ne!(no_target_frames(200, 0.5, 1), no_target_frames(200, 0.5, 2));
    }

    #[test]
    fn kind_names_round_trip() {
        for k in [Kind::Fixtures, Kind::Dark, Kind::RealEarth] {
            assert_eq!(Kind::parse(k.name()), Ok(k));
        }
        assert!(Kind::parse("earth").unwrap_err().contains("real-earth"));
    }

    #[test]
    fn fixture_family_writes_same_bytes_and_valid_truth() {
        let dir = std::env::temp_dir().join(format!("tirroi-testset-{}", std::process::id()));
        let opts = TestsetOptions {
            kind: Kind::Fixtures,
            count: 10,
            seed: 3,
            reference: PathBuf::from("/nonexistent"),
            no_target_fraction: None,
            preview: false,
            progress: false,
            sequence_frames: None,
        };
        let s = write_testset(&opts, &dir.join("a")).expect("a");
        write_testset(&opts, &dir.join("b")).expect("b");
        assert_eq!(s.frames, 10);
        assert_eq!(s.no_target, 2);
        for f in ["truth.csv", "metadata.jsonl", "000000.png", "000009.png"] {
            let a = std::fs::read(dir.join("a").join(f)).expect("read");
            assert_eq!(
                a,
                std::fs::read(dir.join("b").join(f)).expect("read"),
                "{f}"
            );
        }
        // eval's reader takes both conventions; boxes lie in the frame.
        let truth = dir.join("a").join("truth.csv");
        for coverage in [
            crate::eval::scoring::TruthCoverage::Half,
            crate::eval::scoring::TruthCoverage::Quarter,
        ] {
            let rows = crate::eval::scoring::read_truth_with(&truth, coverage).expect("truth");
            assert_eq!(rows.len(), 10);
            assert_eq!(rows.iter().filter(|r| !r.has_target()).count(), 2);
            for r in rows.iter().filter(|r| r.has_target()) {
                assert!(r.roi.x1 <= 328 && r.roi.y1 <= 248, "{:?}", r.roi);
            }
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn missing_reference_names_the_file() {
        let opts = TestsetOptions {
            kind: Kind::Dark,
            count: 2,
            seed: 1,
            reference: PathBuf::from("/nonexistent/reference"),
            no_target_fraction: None,
            preview: false,
            progress: false,
            sequence_frames: None,
        };
        let e = make_frames(&opts, &ProgressBar::hidden()).unwrap_err().0;
        assert!(
            e.contains("dark_20180629_083003.fit") && e.contains("--reference"),
            "{e}"
        );
    }
}
