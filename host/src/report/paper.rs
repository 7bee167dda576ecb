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
use crate::eval::scoring::{self, EvalOptions, FrameScore, TruthRow};
use crate::eval::tuned::{TunedFor, tuned_bank};
use crate::eval::{split, tune};
use crate::progress;
use crate::report::plots;
use crate::world::scene::SceneFile;

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

/// Renders `preset` into `dir` unless a complete dataset of the same size is there.
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
    let truth = dir.join("truth.csv");
    let reuse = scoring::read_truth(&truth)
        .map(|rows| rows.len() == file.image_count())
        .unwrap_or(false);
    if reuse {
        eprintln!("reusing {} ({} images)", dir.display(), file.image_count());
    } else {
        eprintln!(
            "rendering {} images of `{preset}` into {}",
            file.image_count(),
            dir.display()
        );
        let options = WriteOptions {
            masks: false,
            preview: false,
            resume: true,
            progress,
        };
        dataset::write_dataset(&file, dir, &options).map_err(|e| e.to_string())?;
    }
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
    };
    let scores = scoring::score(dir, rows, &eval_options, &|| tuned_bank(kind), &|| {
        bar.inc(1)
    })
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    Ok(scores)
}

/// Renders (or reuses) the datasets and scores them.
///
/// # Errors
/// A one-line message for unwritable outputs or unreadable frames.
pub fn run(options: &PaperOptions) -> Result<PaperScores, String> {
    let (paper_count, tango_count) = if options.full {
        (None, None)
    } else {
        (Some(1200), Some(300))
    };
    let DatasetDirs {
        paper: paper_dir,
        tango: tango_dir,
    } = DatasetDirs::of(options);
    // Scores come from the test split only (`tune::split`), of datasets whose seeds the
    // tuning never used (`EVAL_SEED_OFFSET`).
    let test = |rows: Vec<TruthRow>| split::split(&rows, split::Split::Test);
    let paper_rows = test(dataset("paper", paper_count, &paper_dir, options.progress)?);
    let tango_rows = test(dataset("tango", tango_count, &tango_dir, options.progress)?);
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

fn group_of<'a>(s: &'a FrameScore, key: &str) -> Option<&'a str> {
    s.groups
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// Our numbers for (method, group) over `scores` filtered to a range band.
fn ours(
    scores: &[FrameScore],
    method: &str,
    key: &str,
    value: &str,
    band: &str,
) -> scoring::GroupStats {
    let sel: Vec<&FrameScore> = scores
        .iter()
        .filter(|s| s.method == method)
        .filter(|s| key.is_empty() || group_of(s, key) == Some(value))
        .filter(|s| group_of(s, "range") == Some(band))
        .collect();
    scoring::stats(method, key, value, &sel)
}

/// One table beside the paper's: method, group, ours (mean, median IoU, hit rate, mean
/// time) and the paper's (mean, median IoU, mean time).
pub fn table(
    title: &str,
    scores: &[FrameScore],
    paper: &[PaperRow],
    key: &str,
    band: &str,
) -> String {
    let mut s = format!(
        "{title}\n\n| method | {} | frames | mean IoU | median IoU | IoU ≥ 0.5 | mean time [ms] | paper mean IoU | paper median IoU | paper time [ms] |\n|---|---|---|---|---|---|---|---|---|---|\n",
        if key.is_empty() { "target" } else { key }
    );
    for &(method, value, p_mean, p_median, p_time) in paper {
        let o = ours(scores, method, key, value, band);
        s.push_str(&format!(
            "| {method} | {value} | {} | {:.3} | {:.3} | {:.2} | {:.3} | {p_mean:.3} | {p_median:.3} | {p_time:.3} |\n",
            o.frames, o.mean_iou, o.median_iou, o.hit_rate, o.mean_time_ms
        ));
    }
    // Ours beyond the paper (`auto`): one row per group of the paper's rows.
    let mut values: Vec<&str> = Vec::new();
    for &(_, value, ..) in paper {
        if !values.contains(&value) {
            values.push(value);
        }
    }
    let method = Method::Auto.name();
    for value in values {
        let o = ours(scores, method, key, value, band);
        s.push_str(&format!(
            "| {method} | {value} | {} | {:.3} | {:.3} | {:.2} | {:.3} | – | – | – |\n",
            o.frames, o.mean_iou, o.median_iou, o.hit_rate, o.mean_time_ms
        ));
    }
    s
}

/// The far-range summary: mean IoU per method and group (the paper reports none).
pub fn far_table(title: &str, scores: &[FrameScore], key: &str, values: &[&str]) -> String {
    let mut s = format!("{title}\n\n| method |");
    for v in values {
        s.push_str(&format!(" {key} {v} |"));
    }
    s.push_str(" mean time [ms] |\n|---|");
    s.push_str(&"---|".repeat(values.len() + 1));
    s.push('\n');
    for m in Method::ALL {
        s.push_str(&format!("| {} |", m.name()));
        let mut t = 0.0;
        for v in values {
            let o = ours(scores, m.name(), key, v, "far");
            s.push_str(&format!(" {:.3} ({}) |", o.mean_iou, o.frames));
            t += o.mean_time_ms / values.len() as f64;
        }
        s.push_str(&format!(" {t:.3} |\n"));
    }
    s
}

/// `auto` against the best of the paper's four on every row of Tables 6–8 and of the
/// far-range summaries: mean IoU and median core time per frame (ms) of auto, of the
/// method with the highest mean IoU among the four, and of adaptive (the speed goal).
pub fn auto_table(scores: &PaperScores) -> String {
    let mut s = String::from(
        "`auto` against the best of the paper's four per row (test split; times: median core time per frame)\n\n| table | row | frames | auto mean IoU | best of four | its mean IoU | auto median time [ms] | its median time [ms] | adaptive median time [ms] |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    // (table, its scores, group column, group values, range band)
    type Row<'a> = (&'a str, &'a [FrameScore], &'a str, &'a [&'a str], &'a str);
    let rows: [Row<'_>; 5] = [
        (
            "6",
            &scores.radiometry,
            "material",
            &["mono", "multi-1", "multi-2"],
            "close",
        ),
        ("7", &scores.detection, "scale", &["1", "2", "3"], "close"),
        ("8", &scores.tango, "", &["tango"], "close"),
        (
            "far radiometry",
            &scores.radiometry,
            "material",
            &["mono", "multi-1", "multi-2"],
            "far",
        ),
        (
            "far detection",
            &scores.detection,
            "scale",
            &["1", "2", "3"],
            "far",
        ),
    ];
    for (table, scores, key, values, band) in rows {
        for &value in values {
            let a = ours(scores, Method::Auto.name(), key, value, band);
            let best = Method::PAPER
                .iter()
                .map(|m| ours(scores, m.name(), key, value, band))
                .max_by(|x, y| x.mean_iou.total_cmp(&y.mean_iou));
            let Some(best) = best else { continue };
            let adaptive = ours(scores, Method::Adaptive.name(), key, value, band);
            s.push_str(&format!(
                "| {table} | {value} | {} | {:.3} | {} | {:.3} | {:.3} | {:.3} | {:.3} |\n",
                a.frames,
                a.mean_iou,
                best.method,
                best.mean_iou,
                a.median_time_ms,
                best.median_time_ms,
                adaptive.median_time_ms
            ));
        }
    }
    s
}

/// The three tables (close range) and the far-range summaries, Markdown.
pub fn report(scores: &PaperScores) -> String {
    let mut s = String::new();
    s.push_str(&table(
        "**Table 6** (radiometry, close range 15–50 m, test split; ours, then the paper's)",
        &scores.radiometry,
        &TABLE6,
        "material",
        "close",
    ));
    s.push('\n');
    s.push_str(&table(
        "**Table 7** (detection, close range 15–50 m, test split, by Table 5 scale)",
        &scores.detection,
        &TABLE7,
        "scale",
        "close",
    ));
    s.push('\n');
    s.push_str(&table(
        "**Table 8** (Tango, radiometry, 15–50 m, test split)",
        &scores.tango,
        &TABLE8,
        "",
        "close",
    ));
    s.push('\n');
    s.push_str(&far_table(
        "Far range 340–440 m, radiometry, test split: mean IoU (frames)",
        &scores.radiometry,
        "material",
        &["mono", "multi-1", "multi-2"],
    ));
    s.push('\n');
    s.push_str(&far_table(
        "Far range 340–440 m, detection, test split: mean IoU (frames)",
        &scores.detection,
        "scale",
        &["1", "2", "3"],
    ));
    s.push('\n');
    s.push_str(&auto_table(scores));
    s
}

/// Where the run's frames live, for the figures.
#[derive(Debug, Clone)]
pub struct DatasetDirs {
    /// The `paper` preset's frames.
    pub paper: PathBuf,
    /// The `tango` preset's frames.
    pub tango: PathBuf,
}

impl DatasetDirs {
    /// The directories `run` uses for `options`.
    pub fn of(options: &PaperOptions) -> DatasetDirs {
        DatasetDirs {
            paper: options
                .out
                .join(if options.full { "paper-full" } else { "paper" }),
            tango: options
                .out
                .join(if options.full { "tango-full" } else { "tango" }),
        }
    }
}

fn load(dir: &Path, file: &str) -> Result<crate::imaging::image_io::FrameBuf, String> {
    crate::imaging::image_io::read_frame(&dir.join(file), Some(14)).map_err(|e| e.to_string())
}

/// Per file: the truth and each method's box.
fn boxes_of(
    scores: &[FrameScore],
    file: &str,
) -> (tirroi_core::Roi, Vec<(String, Option<tirroi_core::Roi>)>) {
    let roi = |b: [u16; 4]| tirroi_core::Roi::new(b[0], b[1], b[2], b[3]);
    let mine: Vec<&FrameScore> = scores.iter().filter(|s| s.file == file).collect();
    let truth = mine
        .first()
        .map_or(tirroi_core::Roi::EMPTY, |s| roi(s.truth));
    let boxes = mine
        .iter()
        .map(|s| (s.method.to_string(), s.bbox.map(roi)))
        .collect();
    (truth, boxes)
}

/// Close-range files of `scores` with `key = value`, in file order.
fn files_where(scores: &[FrameScore], key: &str, value: &str) -> Vec<String> {
    let mut files: Vec<String> = scores
        .iter()
        .filter(|s| group_of(s, "range") == Some("close"))
        .filter(|s| key.is_empty() || group_of(s, key) == Some(value))
        .map(|s| s.file.clone())
        .collect();
    files.sort();
    files.dedup();
    files
}

fn example_grid(
    dir: &Path,
    scores: &[FrameScore],
    picks: &[(String, String)],
    methods: &[&str],
    path: &Path,
) -> Result<(), String> {
    let frames: Vec<(String, crate::imaging::image_io::FrameBuf)> = picks
        .iter()
        .map(|(file, caption)| Ok((caption.clone(), load(dir, file)?)))
        .collect::<Result<_, String>>()?;
    let examples: Vec<plots::ExampleFrame<'_>> = frames
        .iter()
        .zip(picks)
        .map(|((caption, f), (file, _))| {
            let (truth, boxes) = boxes_of(scores, file);
            plots::ExampleFrame {
                caption: caption.clone(),
                dn: &f.pixels,
                width: f.width,
                height: f.height,
                truth,
                boxes: boxes
                    .into_iter()
                    .filter(|(m, _)| methods.contains(&m.as_str()))
                    .collect(),
            }
        })
        .collect();
    plots::example_grid(&examples, path).map_err(|e| e.to_string())
}

fn range_of(scores: &[FrameScore], file: &str) -> f64 {
    scores
        .iter()
        .find(|s| s.file == file)
        .and_then(|s| s.range_m)
        .unwrap_or(f64::NAN)
}

/// Writes the figures into `options.figures`; returns their paths.
///
/// # Errors
/// A one-line message naming the figure or frame that failed.
pub fn figures(options: &PaperOptions, scores: &PaperScores) -> Result<Vec<PathBuf>, String> {
    let dirs = DatasetDirs::of(options);
    let out = &options.figures;
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut written = Vec::new();

    // Figs. 10 and 14: IoU against distance, close range, one panel per group.
    let points = |scores: &[FrameScore], key: &str, label: &dyn Fn(&str) -> String| {
        scores
            .iter()
            .filter(|s| group_of(s, "range") == Some("close"))
            .filter_map(|s| {
                Some(plots::IouPoint {
                    method: s.method.to_string(),
                    group: label(group_of(s, key)?),
                    range_m: s.range_m?,
                    iou: f64::from(s.iou),
                })
            })
            .collect::<Vec<_>>()
    };
    let p = out.join("fig10-iou-distance-radiometry.png");
    plots::iou_against_distance(
        &points(&scores.radiometry, "material", &|v| v.to_string()),
        "IoU against distance, radiometry (Fig. 10)",
        &p,
    )
    .map_err(|e| e.to_string())?;
    written.push(p);
    let p = out.join("fig14-iou-distance-detection.png");
    plots::iou_against_distance(
        &points(&scores.detection, "scale", &|v| format!("scale {v}")),
        "IoU against distance, detection (Fig. 14)",
        &p,
    )
    .map_err(|e| e.to_string())?;
    written.push(p);

    // Figs. 12 and 13: one detection pose at the three scales (files share the pose).
    let scale_files: Vec<Vec<String>> = ["1", "2", "3"]
        .iter()
        .map(|s| files_where(&scores.detection, "scale", s))
        .collect();
    if let (Some(f1), Some(f2), Some(f3)) = (
        scale_files[0].first(),
        scale_files[1].first(),
        scale_files[2].first(),
    ) {
        let frames = [load(&dirs.paper, f1)?, load(&dirs.paper, f3)?];
        let p = out.join("fig12-histogram-scale3.png");
        plots::intensity_histogram(
            &[
                ("Scale 1", &frames[0].pixels),
                ("Scale 3", &frames[1].pixels),
            ],
            14,
            "DN histogram of one pose at Scales 1 and 3 (Fig. 12)",
            &p,
        )
        .map_err(|e| e.to_string())?;
        written.push(p);
        let picks: Vec<(String, String)> = [(f1, "Scale 1"), (f2, "Scale 2"), (f3, "Scale 3")]
            .iter()
            .map(|(f, s)| {
                (
                    (*f).clone(),
                    format!("{s}, {:.0} m", range_of(&scores.detection, f)),
                )
            })
            .collect();
        let p = out.join("fig13-boxes-scales.png");
        example_grid(
            &dirs.paper,
            &scores.detection,
            &picks,
            &["otsu", "adaptive", "wge", "dog"],
            &p,
        )?;
        written.push(p);
    }

    // Fig. 11: multi-material examples (radiometry, close).
    let mut picks = Vec::new();
    for (m, label) in [
        ("multi-1", "multi-material 1"),
        ("multi-2", "multi-material 2"),
        ("mono", "mono-material"),
    ] {
        if let Some(f) = files_where(&scores.radiometry, "material", m).first() {
            picks.push((
                f.clone(),
                format!("{label}, {:.0} m", range_of(&scores.radiometry, f)),
            ));
        }
    }
    let p = out.join("fig11-boxes-materials.png");
    example_grid(
        &dirs.paper,
        &scores.radiometry,
        &picks,
        &["otsu", "adaptive", "wge", "dog"],
        &p,
    )?;
    written.push(p);

    // Figs. 16 and 17: Tango frames with adaptive and WGE boxes, and their gradients.
    let tango_files: Vec<String> = files_where(&scores.tango, "", "")
        .into_iter()
        .take(3)
        .collect();
    let picks: Vec<(String, String)> = tango_files
        .iter()
        .zip(["(a)", "(b)", "(c)"])
        .map(|(f, l)| {
            (
                f.clone(),
                format!("{l} Tango, {:.0} m", range_of(&scores.tango, f)),
            )
        })
        .collect();
    let p = out.join("fig16-boxes-tango.png");
    example_grid(&dirs.tango, &scores.tango, &picks, &["adaptive", "wge"], &p)?;
    written.push(p);
    let frames: Vec<crate::imaging::image_io::FrameBuf> = tango_files
        .iter()
        .map(|f| load(&dirs.tango, f))
        .collect::<Result<_, _>>()?;
    let gradient: Vec<plots::GradientFrame<'_>> = frames
        .iter()
        .zip(&picks)
        .map(|(f, (file, caption))| plots::GradientFrame {
            label: caption.clone(),
            dn: &f.pixels,
            width: f.width,
            height: f.height,
            truth: boxes_of(&scores.tango, file).0,
        })
        .collect();
    let p = out.join("fig17-gradients-tango.png");
    plots::gradient_distribution(&gradient, &p).map_err(|e| e.to_string())?;
    written.push(p);

    // Run time against IoU: every candidate parameter set of the tuning grid on the
    // close-range radiometry frames of the test split (one run per frame).
    let dir = &dirs.paper;
    let rows = scoring::read_truth(&dir.join("truth.csv")).map_err(|e| e.to_string())?;
    let rows: Vec<TruthRow> = split::split(&rows, split::Split::Test)
        .into_iter()
        .filter(|r| has(r, "mode", "radiometry") && has(r, "range", "close"))
        .take(150)
        .collect();
    let mut trade = Vec::new();
    for m in Method::ALL {
        for params in tune::grid(m) {
            let t = tune::evaluate(dir, &rows, &params, Some(14)).map_err(|e| e.to_string())?;
            trade.push(plots::TradeoffPoint {
                method: t.method.to_string(),
                params: t.params,
                mean_time_ms: t.mean_time_ms,
                mean_iou: t.mean_iou,
            });
        }
    }
    let p = out.join("tradeoff-time-iou.png");
    plots::runtime_against_iou(
        &trade,
        "Run time against IoU, radiometry close range (every tuning-grid parameter set)",
        &p,
    )
    .map_err(|e| e.to_string())?;
    written.push(p);
    Ok(written)
}
