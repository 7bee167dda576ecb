//! `tirroi eval`: scores detectors on a labelled directory of frames.

use std::path::{Path, PathBuf};

use tirroi_core::BoxRule;

use super::methods::{MethodChoice, method_help, parse_methods};
use crate::eval::bank::DetectorBank;
use crate::eval::scoring;
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
    /// The detectors (help generated from the core registry by `method_help`).
    #[arg(long, default_value = "all", value_parser = parse_methods, help = method_help("Detector"))]
    pub method: MethodChoice,
    /// Runs per frame and method (the one range of `REPEAT_RANGE`); the median time is reported.
    #[arg(long, default_value_t = 3, value_parser = super::repeat_parser(), help = super::repeat_help())]
    pub repeat: u32,
    /// Mask-to-box rule: largest-component or all-foreground.
    #[arg(long, default_value = "largest-component", value_parser = parse_box_rule)]
    pub box_rule: BoxRule,
    /// Bit depth of the DN, 1..=16 (default: 14 for 16-bit files whose DN fit).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub bits: Option<u8>,
    /// Write scores.csv, summary.csv and summary.json here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Tracking prior for auto: off (search every frame whole); jitter (the truth
    /// box moved by up to 4 px and each side by up to 10 %, as a tracker would hand
    /// it over); sequence (frames in file-name order, each frame's prior is auto's
    /// box on the previous one; one thread).
    #[arg(long, default_value = "off", value_parser = parse_track)]
    pub track: scoring::Track,
    /// Which truth box scores: half (x0,y0,x1,y1: pixels covered at least the
    /// dataset's truth_coverage, ½ by default) or quarter (x0_quarter..y1_quarter:
    /// pixels covered more than ¼). Scoring: docs/results.md § Scoring.
    #[arg(long, default_value = "half", value_parser = scoring::TruthCoverage::parse)]
    pub truth_coverage: scoring::TruthCoverage,
}

fn parse_box_rule(s: &str) -> Result<BoxRule, String> {
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
/// One line: unreadable labels or frames, an unwritable output.
pub fn run(args: &EvalArgs) -> Result<(), String> {
    let options = scoring::EvalOptions {
        methods: args.method.0.clone(),
        repeat: args.repeat as usize,
        box_rule: Some(args.box_rule),
        bits: args.bits,
        track: args.track,
    };
    let (images, truth, options, out) = (
        args.images.as_path(),
        args.truth.as_deref(),
        &options,
        args.out.as_deref(),
    );
    let truth = truth.map_or_else(|| images.join("truth.csv"), Path::to_path_buf);
    let rows = scoring::read_truth_with(&truth, args.truth_coverage).map_err(|e| e.to_string())?;
    let bar = progress::bar(rows.len(), "frames");
    let scores = scoring::score(images, &rows, options, &DetectorBank::default, &|| {
        bar.inc(1)
    })
    .map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    let stats = scoring::summarise(&scores);
    print!("{}", scoring::markdown(&stats));
    if let Some(out) = out {
        scoring::write_reports(out, &scores, &stats).map_err(|e| e.to_string())?;
        println!(
            "\nwrote scores.csv, summary.csv and summary.json to {}",
            out.display()
        );
    }
    Ok(())
}
