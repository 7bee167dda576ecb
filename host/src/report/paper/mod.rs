//! The paper's results section end to end (`tirroi paper`, the main job): render the
//! datasets (or reuse them), score the detectors with the core, and print our Tables 6,
//! 7 and 8 beside the paper's.
//!
//! The reduced run renders the `paper` preset at 300 images per scene kind (radiometry
//! and detection, close and far) and the `tango` preset at 300; `--full` renders them at
//! full size (12 000 and 1 000). Close range (15–50 m) is the headline, as in the paper;
//! far range (340–440 m) is reported after it.

use std::path::{Path, PathBuf};

use tirroi_core::Method;

use crate::dataset::{self, WriteOptions};
use crate::eval::bank::saturated_erode_px_of_dataset;
use crate::eval::scoring::{self, EvalOptions, FrameScore, TruthRow};
use crate::eval::split;
use crate::eval::tuned::{TunedFor, tuned_bank};
use crate::progress;
use crate::world::scene::SceneFile;

mod figures;
mod tables;

pub use figures::{DatasetDirs, figures};
pub use tables::{auto_table, false_alarm_table, far_table, realistic_report, report, table};

/// One row of the paper's Tables 6–8: method, group, mean IoU, median IoU, mean time (ms).
pub type PaperRow = (&'static str, &'static str, f64, f64, f64);

/// Table 6 (radiometry, close range), as printed.
pub const TABLE6: [PaperRow; 12] = [
    ("otsu", "mono", 0.063, 0.051, 0.844),
    ("otsu", "multi-1", 0.045, 0.025, 1.616),
    ("otsu", "multi-2", 0.028, 0.022, 1.274),
    ("adaptive", "mono", 0.806, 0.916, 0.754),
    ("adaptive", "multi-1", 0.602, 0.666, 0.966),
    ("adaptive", "multi-2", 0.729, 0.777, 0.882),
    ("wge", "mono", 0.822, 0.897, 3.940),
    ("wge", "multi-1", 0.721, 0.759, 5.468),
    ("wge", "multi-2", 0.638, 0.703, 5.216),
    ("dog", "mono", 0.150, 0.150, 57.436),
    ("dog", "multi-1", 0.104, 0.070, 69.391),
    ("dog", "multi-2", 0.045, 0.058, 60.963),
];

/// Table 7 (detection, close range), as printed.
pub const TABLE7: [PaperRow; 12] = [
    ("otsu", "1", 0.124, 0.031, 1.002),
    ("otsu", "2", 0.576, 0.867, 0.337),
    ("otsu", "3", 0.904, 0.900, 0.328),
    ("adaptive", "1", 0.677, 0.832, 1.564),
    ("adaptive", "2", 0.715, 0.837, 0.406),
    ("adaptive", "3", 0.714, 0.838, 0.373),
    ("wge", "1", 0.767, 0.804, 4.444),
    ("wge", "2", 0.837, 0.881, 4.003),
    ("wge", "3", 0.838, 0.882, 3.970),
    ("dog", "1", 0.802, 0.697, 15.28),
    ("dog", "2", 0.862, 0.698, 13.546),
    ("dog", "3", 0.860, 0.714, 13.766),
];

/// Table 8 (Tango, radiometry), as printed.
pub const TABLE8: [PaperRow; 2] = [
    ("adaptive", "tango", 0.625, 0.705, 1.217),
    ("wge", "tango", 0.393, 0.161, 6.123),
];

/// Added to each preset's seed for the evaluation datasets, so that none of their frames
/// took part in the tuning (`crate::eval::tuned` used seed 1; this keeps the evaluation
/// datasets independent of the presets' own seeds too).
pub const EVAL_SEED_OFFSET: u64 = 1000;

/// What `tirroi paper` does.
#[derive(Debug, Clone)]
pub struct PaperOptions {
    /// Where datasets, reports and figures go.
    pub out: PathBuf,
    /// Where the figures go.
    pub figures: PathBuf,
    /// Full-size datasets (12 000 + 1 000 images) instead of the reduced run.
    pub full: bool,
    /// Runs per frame and method for the timing (median).
    pub repeat: usize,
    /// Show progress bars.
    pub progress: bool,
}

/// The scores of one run, by table.
#[derive(Debug, Clone, Default)]
pub struct PaperScores {
    /// Radiometry frames of the cube + cylinder (close and far).
    pub radiometry: Vec<FrameScore>,
    /// Detection frames (close and far).
    pub detection: Vec<FrameScore>,
    /// Tango frames.
    pub tango: Vec<FrameScore>,
}

/// Renders `preset` into `dir` unless the complete run of the same resolved
/// configuration and tirroi version is there (its `tirroi-run.json` says so); an
/// unfinished run of it is resumed, anything else of tirroi's in `dir` (another
/// configuration or version, or a directory from before manifests) is replaced. Files
/// that are not tirroi's are left alone.
fn dataset(
    preset: &str,
    count: Option<usize>,
    dir: &Path,
    progress: bool,
) -> Result<Vec<TruthRow>, String> {
    let mut file = SceneFile::preset(preset).map_err(|e| e.to_string())?;
    // A seed of its own keeps every scored frame unseen by the tuning (which used seed
    // 1), on top of the test split.
    file.dataset.seed += EVAL_SEED_OFFSET;
    if let Some(n) = count {
        file.rescale_count(n).map_err(|e| e.to_string())?;
    }
    let outputs = dataset::Outputs {
        masks: false,
        preview: false,
    };
    let manifest = dataset::Manifest::new(
        dataset::RunSource::Preset(preset.into()),
        &file,
        outputs,
        None,
    )
    .map_err(|e| e.to_string())?;
    let truth = dir.join("truth.csv");
    let old = dataset::Manifest::read(dir).map_err(|e| e.to_string())?;
    let same = old.as_ref().filter(|m| m.differences(&manifest).is_empty());
    if same.is_some_and(|m| m.complete) {
        eprintln!("reusing {} ({})", dir.display(), manifest.summary());
        return scoring::read_truth(&truth).map_err(|e| e.to_string());
    }
    let resume = same.is_some();
    if !resume && dir.exists() {
        match &old {
            Some(m) => eprintln!(
                "replacing {} ({}): {}",
                dir.display(),
                m.summary(),
                m.differences(&manifest).join("; ")
            ),
            None => eprintln!(
                "replacing the frames in {} (no {}: rendered before run manifests)",
                dir.display(),
                dataset::MANIFEST_FILE
            ),
        }
        dataset::clear_run(dir).map_err(|e| e.to_string())?;
    }
    eprintln!(
        "rendering {} images of `{preset}` into {}",
        file.image_count(),
        dir.display()
    );
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    manifest.write(dir).map_err(|e| e.to_string())?;
    let options = WriteOptions {
        masks: false,
        preview: false,
        resume,
        progress,
        shard: None,
    };
    dataset::write_dataset(&file, dir, &options).map_err(|e| e.to_string())?;
    dataset::Manifest {
        complete: true,
        ..manifest
    }
    .write(dir)
    .map_err(|e| e.to_string())?;
    scoring::read_truth(&truth).map_err(|e| e.to_string())
}

fn has(row: &TruthRow, key: &str, value: &str) -> bool {
    row.groups.iter().any(|(k, v)| k == key && v == value)
}

/// Scores `rows` of `dir` with every method, with the parameters (and box rules) tuned
/// for `kind`.
fn score(
    dir: &Path,
    rows: &[TruthRow],
    kind: TunedFor,
    options: &PaperOptions,
    what: &str,
) -> Result<Vec<FrameScore>, String> {
    let bar = if options.progress {
        progress::bar(rows.len(), what)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let eval_options = EvalOptions {
        methods: Method::ALL.to_vec(),
        repeat: options.repeat,
        box_rule: None,
        bits: None,
        track: scoring::Track::Off,
        fits_offset_dn: None,
        crop: None,
    };
    // `auto-v2`'s saturated cut is the camera's: from the dataset's manifest.
    let erode_px = saturated_erode_px_of_dataset(dir)?;
    let make_bank = || {
        let mut bank = tuned_bank(kind);
        bank.set_saturated_erode_px(erode_px);
        bank
    };
    let scores = scoring::score(dir, rows, &eval_options, &make_bank, &|| bar.inc(1))
        .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    Ok(scores)
}

/// The two worlds of the main job: the paper's (`paper` + `tango` presets) and the
/// realistic one (`realistic` + `realistic-tango`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum World {
    /// The paper's world (its Earth, readout and no sensor signature).
    Paper,
    /// The world a flight detector meets (issue 15).
    Realistic,
}

impl World {
    /// The presets of the cube + cylinder and the Tango datasets.
    pub const fn presets(self) -> (&'static str, &'static str) {
        match self {
            World::Paper => ("paper", "tango"),
            World::Realistic => ("realistic", "realistic-tango"),
        }
    }
}

/// Renders (or reuses) the paper world's datasets and scores them.
///
/// # Errors
/// A one-line message for unwritable outputs or unreadable frames.
pub fn run(options: &PaperOptions) -> Result<PaperScores, String> {
    run_world(options, World::Paper)
}

/// Renders (or reuses) one world's datasets and scores every method with the tuned
/// parameters of the paper world's kinds (the realistic world tunes nothing: it tests).
///
/// # Errors
/// A one-line message for unwritable outputs or unreadable frames.
pub fn run_world(options: &PaperOptions, world: World) -> Result<PaperScores, String> {
    let (paper_count, tango_count) = if options.full {
        (None, None)
    } else {
        (Some(1200), Some(300))
    };
    let DatasetDirs {
        paper: paper_dir,
        tango: tango_dir,
    } = DatasetDirs::of_world(options, world);
    let (paper_preset, tango_preset) = world.presets();
    // Scores come from the test split only (`split::split`), of datasets whose seeds the
    // tuning never used (`EVAL_SEED_OFFSET`).
    let test = |rows: Vec<TruthRow>| split::split(&rows, split::Split::Test);
    let paper_rows = test(dataset(
        paper_preset,
        paper_count,
        &paper_dir,
        options.progress,
    )?);
    let tango_rows = test(dataset(
        tango_preset,
        tango_count,
        &tango_dir,
        options.progress,
    )?);
    let (radiometry, detection): (Vec<TruthRow>, Vec<TruthRow>) = paper_rows
        .into_iter()
        .partition(|r| has(r, "mode", "radiometry"));
    Ok(PaperScores {
        radiometry: score(
            &paper_dir,
            &radiometry,
            TunedFor::Radiometry,
            options,
            "radiometry frames",
        )?,
        detection: score(
            &paper_dir,
            &detection,
            TunedFor::Detection,
            options,
            "detection frames",
        )?,
        tango: score(
            &tango_dir,
            &tango_rows,
            TunedFor::Tango,
            options,
            "Tango frames",
        )?,
    })
}
