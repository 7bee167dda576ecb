//! `tirroi detect`: the ROI of each frame file, as text or JSON lines.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use serde::Serialize;

use super::EXIT_BAD_INPUT;
use super::methods::{MethodChoice, method_help, parse_methods};
use crate::eval::bank::DetectorBank;
use crate::imaging::image_io::{ReadOptions, parse_box_px, parse_crop, read_frame_with};
use tirroi_core::Method;
use tirroi_core::roi::auto::learned::AutoV2;
use tirroi_core::roi::auto::{BudgetReport, WorkBudget};
use tirroi_core::roi::track::Tracker;

/// The options of `tirroi detect`.
#[derive(Debug, clap::Args)]
pub struct DetectArgs {
    /// The detectors (help generated from the core registry by `method_help`).
    #[arg(long, default_value = "all", value_parser = parse_methods, help = method_help("Detector"))]
    pub method: MethodChoice,
    /// Runs per frame and method (the one range of `REPEAT_RANGE`); the median time is reported.
    #[arg(long, default_value_t = 1, value_parser = super::repeat_parser(), help = super::repeat_help())]
    pub repeat: u32,
    /// Print one JSON object per frame and method.
    #[arg(long)]
    pub json: bool,
    /// Bit depth of the DN, 1..=16 (default: 8 for 8-bit files; a 16-bit PNG's `sBIT`
    /// depth, which tirroi's renders write; else 14 for 16-bit files whose DN fit, else 16).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
    pub bits: Option<u8>,
    /// Mask-to-box rule for every detector: largest-component or all-foreground
    /// (default: each detector's own; `eval` uses largest-component unless told).
    #[arg(long, value_parser = super::eval::parse_box_rule)]
    pub box_rule: Option<tirroi_core::BoxRule>,
    /// FITS frames: DN added to each value before rounding and clamping to the bit
    /// depth (default: 1024 for float data, 0 for integer data; docs/cli.md § FITS).
    #[arg(long, value_name = "DN", allow_negative_numbers = true)]
    pub fits_offset: Option<f64>,
    /// Detect only in this part of every frame: x0,y0,x1,y1 (px, x1 and y1 exclusive)
    /// or hayabusa2-tir (the TIR's 328x248 effective area of its 384x256 FITS frames);
    /// boxes are in the cropped frame.
    #[arg(long, value_parser = parse_crop)]
    pub crop: Option<[usize; 4]>,
    /// `auto` only: run it within this work budget, in Cortex-M7 instructions
    /// (`Auto::detect_within`: each stage's worst case is charged before it runs; when
    /// the next does not fit, the best box so far). Adds what was charged and where it
    /// stopped to each `auto` line; the other methods run as without it. Frames up to
    /// 328x248.
    #[arg(long, value_name = "INSTRUCTIONS")]
    pub budget: Option<u32>,
    /// `auto-v2` only: its saturated blob's cut, px per side, 0..=8: the reach of the
    /// camera's optics blur (`AutoV2::saturated_erode_px`). The default, 2, is the
    /// flight camera's (the Hayabusa2 TIR with its optics PSF: scenes with `[camera]
    /// optics_psf = true`); 0 for frames without optics blur (the `paper` world, the
    /// fixtures). `eval` takes it from the dataset's manifest instead.
    #[arg(long, value_name = "PX", default_value_t = AutoV2::default().saturated_erode_px,
          value_parser = clap::value_parser!(u8).range(0..=8))]
    pub saturated_erode_px: u8,
    /// The trackers (`auto`, `auto-v2`) only: the target's box on the frame before the
    /// first file, x0,y0,x1,y1 (px, x1 and y1 exclusive); each searches a window around
    /// it first (the box found there stands when it passes, else the whole frame is
    /// searched). The other methods ignore it.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_prior)]
    pub prior: Option<tirroi_core::Roi>,
    /// The files are a sequence, in the order given: each tracker's prior on a file is
    /// its own box on the file before (none after a miss; on the first file,
    /// `--prior`). `auto-v2` runs as the core's tracker: it carries that box's look
    /// (its level against the background on each side) to take its fast path (the last
    /// box's cells refined without the classifier, kept when the new box looks the
    /// same), and without a box it acquires a target rated under the gate once that
    /// moved against the ground over 3 frames (score 0.667).
    #[arg(long)]
    pub track: bool,
    /// Frames to process (PNG, TIFF or FITS).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// The JSON line of `tirroi detect --json`: `{"file","method","bbox":[x0,y0,x1,y1] or
/// null,"score","time_us"}`, `score` the detector's confidence in 0–1 (0 for `null`;
/// see `Detection::score_permille`), `time_us` the median over `--repeat` runs of the core call alone
/// (the conventions in `docs/architecture.md`); on `auto-v2` lines with a box also
/// `"stage"`, the stage that gave it (`learned::Stage::name`).
#[derive(Debug, Serialize)]
struct DetectLine<'a> {
    file: &'a str,
    method: &'static str,
    bbox: Option<[u16; 4]>,
    score: f32,
    time_us: f64,
    /// `auto-v2` lines with a box: the stage that gave it.
    #[serde(skip_serializing_if = "Option::is_none")]
    stage: Option<&'static str>,
    /// With `--budget`, on `auto` lines only.
    #[serde(skip_serializing_if = "Option::is_none")]
    budget: Option<BudgetLine>,
}

/// What a budgeted `auto` call spent: `{"instructions","charged","stopped"}`, `stopped`
/// the stage that did not fit (`noise`, `step-plane`, `candidates`, `refinement`, with
/// `+tracking` after a tracking pass) or `null` when it ran to its end.
#[derive(Debug, Serialize)]
struct BudgetLine {
    instructions: u32,
    charged: u32,
    stopped: Option<String>,
}

impl BudgetLine {
    fn new(budget: WorkBudget, report: &BudgetReport) -> Self {
        BudgetLine {
            instructions: budget.instructions,
            charged: report.charged,
            stopped: report.stopped.map(|s| {
                let tracking = if s.after_tracking { "+tracking" } else { "" };
                format!("{}{tracking}", s.stage.name())
            }),
        }
    }
}

/// Parses `--prior`: four integers x0,y0,x1,y1 (px, 0..=65535) with x0 < x1 and
/// y0 < y1.
fn parse_prior(s: &str) -> Result<tirroi_core::Roi, String> {
    parse_box_px::<u16>(s).map(|[x0, y0, x1, y1]| tirroi_core::Roi::new(x0, y0, x1, y1))
}

/// Runs `tirroi detect`: every method on every frame, one line (or JSON object) each.
pub fn run(args: &DetectArgs) -> ExitCode {
    let (methods, repeat, json, bits, files) = (
        &args.method.0,
        args.repeat as usize,
        args.json,
        args.bits,
        &args.files,
    );
    let mut bank = DetectorBank::default();
    bank.set_saturated_erode_px(args.saturated_erode_px);
    if let Some(rule) = args.box_rule {
        bank.set_box_rule(rule);
    }
    let mut failed = false;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    // Each method's prior for the next file (used by the trackers only).
    let mut priors = vec![args.prior; methods.len()];
    // `--track`: `auto-v2`'s tracker (its last box and look, the ground, the run of
    // candidates); `--prior` has no frame, so no look: there the window is searched.
    let mut tracker = Tracker::new(AutoV2::default());
    tracker.set_prior(args.prior, None);
    for path in files {
        let options = ReadOptions {
            bits,
            fits_offset_dn: args.fits_offset,
            crop: args.crop,
        };
        let frame = match read_frame_with(path, &options) {
            Ok((f, warnings)) => {
                for w in warnings {
                    eprintln!("tirroi: warning: {}: {w}", path.display());
                }
                f
            }
            Err(e) => {
                eprintln!("tirroi: error: {e}");
                failed = true;
                continue;
            }
        };
        let view = match frame.view() {
            Ok(v) => v,
            Err(e) => {
                eprintln!("tirroi: error: {}: {e}", path.display());
                failed = true;
                continue;
            }
        };
        for (&method, prior) in methods.iter().zip(priors.iter_mut()) {
            bank.set_prior_of(method, *prior);
            let budget = args
                .budget
                .filter(|_| method == Method::Auto)
                .map(WorkBudget::instructions);
            let timed = match budget {
                Some(b) => bank
                    .auto_within_timed(&view, b, repeat)
                    .map(|(d, report, t)| (d, t, Some(BudgetLine::new(b, &report)))),
                None if args.track && method == Method::AutoV2 => bank
                    .track_timed(&mut tracker, &view, repeat)
                    .map(|(d, t)| (d, t, None)),
                None => bank
                    .detect_timed(method, &view, repeat)
                    .map(|(d, t)| (d, t, None)),
            };
            let (d, time_us, spent) = match timed {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("tirroi: error: {}: {method}: {e}", path.display());
                    return ExitCode::from(EXIT_BAD_INPUT);
                }
            };
            if args.track {
                *prior = d.roi;
            }
            let stage = bank.stage(method, &view, d.roi).map(|s| s.name());
            let file = path.to_string_lossy();
            let written = if json {
                let line = DetectLine {
                    file: &file,
                    method: method.name(),
                    bbox: d.roi.map(|r| r.to_array()),
                    score: d.score(),
                    time_us: (time_us * 1000.0).round() / 1000.0,
                    stage,
                    budget: spent,
                };
                serde_json::to_string(&line)
                    .map_err(std::io::Error::other)
                    .and_then(|s| writeln!(out, "{s}"))
            } else {
                let bbox = d
                    .roi
                    .map(|r| format!("{:?}", r.to_array()))
                    .unwrap_or_else(|| "none".into());
                let stage = stage.map(|s| format!("  stage {s}")).unwrap_or_default();
                let spent = spent
                    .map(|b| {
                        format!(
                            "  budget {} charged {} stopped {}",
                            b.instructions,
                            b.charged,
                            b.stopped.as_deref().unwrap_or("no")
                        )
                    })
                    .unwrap_or_default();
                writeln!(
                    out,
                    "{file}  {:<8}  bbox {bbox:<22}  score {:.3}  {time_us:>9.1} us  threshold {}  foreground {} px{stage}{spent}",
                    method.name(),
                    d.score(),
                    d.threshold,
                    d.foreground_px
                )
            };
            if written.is_err() {
                // Output closed (e.g. piped into `head`): stop quietly.
                return ExitCode::SUCCESS;
            }
        }
    }
    if failed {
        ExitCode::from(EXIT_BAD_INPUT)
    } else {
        ExitCode::SUCCESS
    }
}
