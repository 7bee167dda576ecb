//! `tirroi eval`: scores detectors on a labelled directory of frames.

use std::path::PathBuf;

use tirroi_core::BoxRule;

use super::methods::{MethodChoice, method_help, parse_methods};
use crate::eval::bank::{self, DetectorBank};
use crate::eval::confidence_report;
use crate::eval::predictions::{self, PredictionSet};
use crate::eval::scoring::{self, EvalError, TruthCoverage, TruthRow};
use crate::imaging::image_io;
use crate::progress;

/// The options of `tirroi eval`.
#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// Directory of frames.
    #[arg(long)]
    pub images: PathBuf,
    /// Labels (default: IMAGES/truth.csv), header `file,x0,y0,x1,y1[,extra...]`.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// The detectors (help generated from the core registry by `method_help`), or none
    /// (only the --predictions).
    #[arg(long, default_value = "all", value_parser = parse_eval_methods, help = eval_method_help())]
    pub method: MethodChoice,
    /// Boxes made elsewhere, scored beside the methods: FILE (named by its stem) or
    /// NAME=FILE; repeatable. JSON lines of `tirroi detect --json` (one row per method
    /// in the file), CSV file,x0,y0,x1,y1[,score] (empty box fields: no box), or COCO
    /// results [{"image_id","bbox":[x,y,w,h],"score"}] (needs --coco). A frame without
    /// a prediction counts as no box.
    #[arg(long = "predictions", value_name = "[NAME=]FILE")]
    pub predictions: Vec<String>,
    /// COCO annotations mapping image_id to files, for COCO results (default:
    /// IMAGES/coco.json, as `tirroi render` writes it).
    #[arg(long)]
    pub coco: Option<PathBuf>,
    /// Write the curve of hit rate against false-alarm rate as the score threshold
    /// sweeps (every method and predictions set, both truth conventions) to this CSV.
    #[arg(long, value_name = "FILE.csv")]
    pub curve: Option<PathBuf>,
    /// FITS frames: DN added to each value before rounding and clamping to the bit
    /// depth (default: 1024 for float data, 0 for integer data; docs/cli.md § FITS).
    #[arg(long, value_name = "DN", allow_negative_numbers = true)]
    pub fits_offset: Option<f64>,
    /// Score only this part of every frame: x0,y0,x1,y1 (px, x1 and y1 exclusive) or
    /// hayabusa2-tir (the TIR's 328x248 effective area of its 384x256 FITS frames);
    /// truth boxes are in the cropped frame.
    #[arg(long, value_parser = image_io::parse_crop)]
    pub crop: Option<[usize; 4]>,
    /// Runs per frame and method (the one range of `REPEAT_RANGE`); the median time is reported.
    #[arg(long, default_value_t = 3, value_parser = super::repeat_parser(), help = super::repeat_help())]
    pub repeat: u32,
    /// Mask-to-box rule: largest-component or all-foreground.
    #[arg(long, default_value = "largest-component", value_parser = parse_box_rule)]
    pub box_rule: BoxRule,
    /// Bit depth of the DN, 1..=16, for frames whose `truth.csv` row has none (default: a
    /// 16-bit PNG's `sBIT` depth, else 14 for 16-bit files whose DN fit).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub bits: Option<u8>,
    /// Write scores.csv, summary.csv and summary.json here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Tracking prior for auto and auto-v2: off (search every frame whole); jitter
    /// (the truth box moved by up to 4 px and each side by up to 10 %, as a tracker
    /// would hand it over); sequence (frames in file-name order, each frame's prior is
    /// the tracker's own box on the previous one; a `sequence` column in truth.csv, as
    /// `render --preset realistic-approach` writes, starts each sequence without one;
    /// the trackers' frames are grouped `prior = yes|no`; one thread).
    #[arg(long, default_value = "off", value_parser = parse_track)]
    pub track: scoring::Track,
    /// Which truth box scores: half (x0,y0,x1,y1: pixels covered at least the
    /// dataset's truth_coverage, ½ by default) or quarter (x0_quarter..y1_quarter:
    /// pixels covered more than ¼). Scoring: docs/results.md § Scoring.
    #[arg(long, default_value = "half", value_parser = scoring::TruthCoverage::parse)]
    pub truth_coverage: scoring::TruthCoverage,
}

/// `--method` of eval: [`parse_methods`], or `none` (predictions only).
fn parse_eval_methods(s: &str) -> Result<MethodChoice, String> {
    if s == "none" {
        Ok(MethodChoice(Vec::new()))
    } else {
        parse_methods(s).map_err(|e| format!("{e} (or none: only --predictions)"))
    }
}

/// Parses a `--box-rule` value (`eval`, `detect`).
///
/// # Errors
/// One line naming the two rules.
pub fn parse_box_rule(s: &str) -> Result<BoxRule, String> {
    BoxRule::from_name(s).ok_or_else(|| {
        format!("unknown box rule `{s}`; expected largest-component or all-foreground")
    })
}

fn parse_track(s: &str) -> Result<scoring::Track, String> {
    match s {
        "off" => Ok(scoring::Track::Off),
        "jitter" => Ok(scoring::Track::Jitter),
        "sequence" => Ok(scoring::Track::Sequence),
        _ => Err(format!(
            "unknown tracking mode `{s}`; expected off, jitter or sequence"
        )),
    }
}

/// Runs `tirroi eval`: scores, the markdown summary and (with `--out`) the reports.
///
/// # Errors
/// One line: unreadable or invalid labels, predictions or frames, an unwritable output.
pub fn run(args: &EvalArgs) -> Result<(), String> {
    let options = scoring::EvalOptions {
        methods: args.method.0.clone(),
        repeat: args.repeat as usize,
        box_rule: Some(args.box_rule),
        bits: args.bits,
        track: args.track,
        fits_offset_dn: args.fits_offset,
        crop: args.crop,
    };
    if options.methods.is_empty() && args.predictions.is_empty() {
        return Err("--method none and no --predictions: nothing to score".into());
    }
    let images = args.images.as_path();
    let truth = args
        .truth
        .clone()
        .unwrap_or_else(|| images.join("truth.csv"));
    let lines =
        scoring::read_truth_lines(&truth, args.truth_coverage).map_err(|e| e.to_string())?;
    // The other truth convention, when the file has it: the confidence figures are
    // reported under both.
    let other_coverage = match args.truth_coverage {
        TruthCoverage::Half => TruthCoverage::Quarter,
        TruthCoverage::Quarter => TruthCoverage::Half,
    };
    let other = scoring::read_truth_lines(&truth, other_coverage).ok();
    let dims = |file: &str| {
        image_io::frame_dimensions(&images.join(file), &options.read_options(None))
            .map_err(|e| EvalError(e.to_string()))
    };
    scoring::check_truth_boxes(&truth, &lines, &dims).map_err(|e| e.to_string())?;
    if let Some(o) = &other {
        scoring::check_truth_boxes(&truth, o, &dims).map_err(|e| e.to_string())?;
    }
    let rows: Vec<TruthRow> = lines.into_iter().map(|(_, r)| r).collect();
    // Predictions are read and matched before any detector runs: a bad file fails fast.
    let coco = args
        .coco
        .clone()
        .unwrap_or_else(|| images.join("coco.json"));
    let mut predicted = Vec::new();
    for spec in &args.predictions {
        let (name, file) = predictions::parse_spec(spec)?;
        for set in
            predictions::read_predictions(&file, &name, Some(&coco)).map_err(|e| e.to_string())?
        {
            if options.methods.iter().any(|m| m.name() == set.name)
                || predicted
                    .iter()
                    .any(|(s, _): &(PredictionSet, _)| s.name == set.name)
            {
                return Err(format!(
                    "{}: the name `{}` is taken: give it another with NAME={}",
                    file.display(),
                    set.name,
                    file.display()
                ));
            }
            let scores = predictions::score_predictions(&set, &rows).map_err(|e| e.to_string())?;
            predicted.push((set, scores));
        }
    }
    let mut scores = if options.methods.is_empty() {
        Vec::new()
    } else {
        // `auto-v2`'s saturated cut is the camera's: from the dataset's manifest.
        let erode_px = bank::saturated_erode_px_of_dataset(images)?;
        let make_bank = || {
            let mut bank = DetectorBank::default();
            bank.set_saturated_erode_px(erode_px);
            bank
        };
        let bar = progress::bar(rows.len(), "frames");
        let s = scoring::score(images, &rows, &options, &make_bank, &|| bar.inc(1))
            .map_err(|e| e.to_string())?;
        bar.finish_and_clear();
        s
    };
    for (_, s) in predicted {
        scores.extend(s);
    }
    let stats = scoring::summarise(&scores);
    print!("{}", scoring::markdown(&stats));
    // Confidence under both truth conventions (the chosen one first).
    let mut conventions = vec![(args.truth_coverage, scores.clone())];
    if let Some(o) = other {
        let boxes: std::collections::BTreeMap<&str, tirroi_core::Roi> =
            o.iter().map(|(_, r)| (r.file.as_str(), r.roi)).collect();
        conventions.push((other_coverage, scoring::with_truth(&scores, &boxes)));
    }
    let report = confidence_report::Report::new(&conventions);
    print!("\n{}", report.markdown());
    if let Some(path) = &args.curve {
        report.write_curve(path).map_err(|e| e.to_string())?;
        println!("\nwrote the curve to {}", path.display());
    }
    if let Some(out) = args.out.as_deref() {
        scoring::write_reports(out, &scores, &stats).map_err(|e| e.to_string())?;
        report.write_tables(out).map_err(|e| e.to_string())?;
        println!(
            "\nwrote scores.csv, summary.csv, summary.json, confidence.csv and calibration.csv to {}",
            out.display()
        );
    }
    Ok(())
}

/// `eval --method` help: the registry's names (`method_help`), or none.
fn eval_method_help() -> String {
    format!(
        "{}, or none (only the --predictions)",
        method_help("Detector")
    )
}
