//! `tirroi tune`: tunes each detector's parameters on the tune part of a labelled
//! directory and checks them on the test part (the search: [`crate::eval::tune`]).

use std::path::PathBuf;

use tirroi_core::BoxRule;

use super::methods::{MethodChoice, method_help, parse_methods};
use crate::eval::scoring;
use crate::eval::split::{Split, TUNE_PERCENT, Where, filter, parse_where, split};
use crate::eval::tune::{SearchOptions, defaults, evaluate, grid, search, trials_csv};
use crate::progress;

/// The options of `tirroi tune`.
#[derive(Debug, clap::Args)]
pub struct TuneArgs {
    /// Directory of frames.
    #[arg(long)]
    pub images: PathBuf,
    /// Labels (default: IMAGES/truth.csv), header `file,x0,y0,x1,y1[,extra...]`.
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// The detectors (help generated from the core registry by `method_help`).
    #[arg(long, default_value = "all", value_parser = parse_methods, help = method_help("Detector to tune"))]
    pub method: MethodChoice,
    /// Keep only frames with this group label, `key=value`; key: mode, scale, target,
    /// material, illumination or range (close <= 50 m, far >= 300 m, else mid).
    /// Repeat it: different keys must all match, values of one key are alternatives.
    #[arg(long = "where", value_name = "KEY=VALUE", value_parser = parse_where)]
    pub wheres: Vec<Where>,
    /// Bit depth of the DN, 1..=16 (default: a 16-bit PNG's `sBIT` depth, else 14 for
    /// 16-bit files whose DN fit).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub bits: Option<u8>,
    /// Most refinement moves per method after the grid, 0..=100 (0: grid only).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(0..=100))]
    pub refine_steps: u32,
    /// Grid sets refined per method (the best by mean IoU), 1..=20.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=20))]
    pub starts: u32,
    /// Write trials.csv (method,params,mean_iou,median_iou,mean_time_ms) here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Which truth box scores: half (x0,y0,x1,y1: pixels covered at least the
    /// dataset's truth_coverage, ½ by default) or quarter (x0_quarter..y1_quarter:
    /// pixels covered more than ¼). Scoring: docs/results.md § Scoring.
    #[arg(long, default_value = "half", value_parser = scoring::TruthCoverage::parse)]
    pub truth_coverage: scoring::TruthCoverage,
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
    let rows = scoring::read_truth_with(&truth, args.truth_coverage).map_err(|e| e.to_string())?;
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
    let bar = progress::bar(planned, "trials");
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
        let default_set = defaults(m, BoxRule::LargestComponent);
        let default_tune = result
            .trials
            .iter()
            .find(|t| t.method == m.name() && t.params == default_set.to_string())
            .map(|t| t.mean_iou)
            .unwrap_or(f64::NAN);
        let default_test = evaluate(&args.images, &test_rows, &default_set, args.bits)
            .map_err(|e| e.to_string())?;
        table.push_str(&format!(
            "| {m} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {default_tune:.3} | {:.3} |\n",
            best.params,
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
