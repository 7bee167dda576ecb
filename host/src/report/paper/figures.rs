//! The paper's figures from a finished run ([`figures`]): which frames and scores each
//! figure draws.

use std::path::{Path, PathBuf};

use tirroi_core::Method;

use crate::eval::scoring::{self, FrameScore, TruthRow};
use crate::eval::{split, tune};
use crate::report::plots;

use super::tables::group_of;
use super::{PaperOptions, PaperScores, has};

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
        DatasetDirs::of_world(options, super::World::Paper)
    }

    /// The directories of `world`'s two presets (`<preset>` or `<preset>-full`).
    pub fn of_world(options: &PaperOptions, world: super::World) -> DatasetDirs {
        let (paper, tango) = world.presets();
        let dir = |p: &str| {
            options.out.join(if options.full {
                format!("{p}-full")
            } else {
                p.to_string()
            })
        };
        DatasetDirs {
            paper: dir(paper),
            tango: dir(tango),
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
            // IoU is scored over frames with a target (`eval::scoring`).
            .filter(|s| s.has_target())
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
            &Method::PAPER.map(Method::name),
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
        &Method::PAPER.map(Method::name),
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
