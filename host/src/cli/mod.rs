//! The `tirroi` command line: [`Cli`] parses the arguments, [`main`] dispatches to one
//! module per subcommand. Each module holds its options (`clap::Args`) and a `run`
//! function; only this stage parses arguments or prints for the user.
//!
//! | subcommand | module |
//! |---|---|
//! | `detect` | [`detect`] |
//! | `memory` | [`memory`] |
//! | `fixtures` | [`fixtures`] |
//! | `demo` | [`demo`] |
//! | `sensor` | [`sensor`] |
//! | `sensor-fit` | [`sensor_fit`] |
//! | `eval` | [`eval`] |
//! | `paper` (the default) | [`paper`] |
//! | `render` | [`render`] |
//! | `merge` | [`merge`] |
//! | `tune` | [`tune`] |
//! | `testset` | [`testset`] |
//!
//! `--method` of `detect`, `eval` and `tune` is parsed in one place, [`methods`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

pub mod demo;
pub mod detect;
pub mod earth_texture;
pub mod eval;
pub mod fixtures;
pub mod memory;
pub mod merge;
pub mod methods;
pub mod paper;
pub mod render;
pub mod sensor;
pub mod sensor_fit;
pub mod testset;
pub mod tune;

/// Exit code for bad input (files, sizes, parameters), as clap uses for bad arguments.
pub const EXIT_BAD_INPUT: u8 = 2;

/// The one range of `--repeat` (runs per frame and method, the time reported is their
/// median) in every subcommand that times detectors: at least 1, at most 1000 (a
/// 1000-run median is far below the wall-clock drift of a shared machine).
pub const REPEAT_RANGE: std::ops::RangeInclusive<i64> = 1..=1000;

/// The parser of every `--repeat`: an integer in [`REPEAT_RANGE`].
pub fn repeat_parser() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(REPEAT_RANGE)
}

/// The help of every `--repeat`, with its range.
pub fn repeat_help() -> String {
    format!(
        "Runs per frame and method, {}..={}; the reported time is the median",
        REPEAT_RANGE.start(),
        REPEAT_RANGE.end()
    )
}

/// tirroi: synthetic thermal-infrared frames and flight-ready ROI detection.
#[derive(Debug, Parser)]
#[command(
    name = "tirroi",
    version,
    about = "Synthetic thermal-infrared frames and flight-ready ROI detection for spacecraft navigation"
)]
pub struct Cli {
    /// What to do (default: `demo`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Detect the ROI in 8/16-bit grayscale PNG, TIFF or FITS frames.
    ///
    /// One line per frame and method: the box [x0, y0, x1, y1] (x1, y1 exclusive; none
    /// when no pixel is foreground), the score (confidence 0-1 that the box is the
    /// target; the paper's four report 1 for any box), the median core time, then
    /// threshold: the value the detector cut its response at to make the foreground
    /// mask (in the detector's own unit, e.g. DN for otsu; docs/detectors.md), and
    /// foreground: the pixels in that mask (before the box rule draws the box from
    /// it). --json prints {"file","method","bbox","score","time_us"}.
    Detect(detect::DetectArgs),
    /// Print the scratch memory of each detector, in bytes (the README's memory table
    /// is this output).
    Memory,
    /// Write the procedural fixture frames as 16-bit PNG with a `truth.csv`.
    ///
    /// With --count, a seeded family of that many frames (as `testset --kind fixtures`).
    Fixtures {
        /// Output directory (created if missing).
        #[arg(long, default_value = "fixtures")]
        out: PathBuf,
        /// Frames of the seeded family (omitted: the four standard fixtures).
        #[arg(long)]
        count: Option<usize>,
        /// Seed of the family (with --count).
        #[arg(long, default_value_t = 16, requires = "count")]
        seed: u64,
    },
    /// Run every detector on the built-in procedural frames and print IoU and time.
    Demo {
        /// Runs per frame and method (the one range of `REPEAT_RANGE`); the median time is reported.
        #[arg(long, default_value_t = 21, value_parser = repeat_parser(), help = repeat_help())]
        repeat: u32,
        /// Also write each frame with the detectors' boxes (largest-component rule) as
        /// PNG into this directory.
        #[arg(long)]
        figures: Option<PathBuf>,
    },
    /// Print the thermal camera model: noise budget, noise voltage density, and the
    /// band radiance, emissive power, radiometry DN and T_rad of scene temperatures.
    ///
    /// Every number comes from `tirroi_core::sensor` (Table 1 bolometer, Eqs. 1-17).
    /// Bad input prints one line `tirroi: error: ...` and exits with code 2.
    ///
    /// With --json, one JSON object on stdout:
    ///   {"response":"hayabusa2"|"tir"|"flat", "level":"netd"|"paper-literal"|"paper-visible",
    ///    "netd_k":0.4, "t_ref_k":300, "bits":14, "emissivity":1,
    ///    "mapping":{"t_lo_k","t_hi_k","f_min_w_m2","f_max_w_m2","gain_dn_per_w_m2",
    ///               "offset_dn","max_dn"},
    ///    "noise":{"reading":"table2"|"as-printed"|"physical",
    ///             "johnson_v","flicker_v","thermal_v","total_v",          (V)
    ///             "johnson_dn","flicker_dn","thermal_dn","total_dn",      (DN, chosen level)
    ///             "dn_per_k", "netd_equivalent_k",                        (DN/K, K)
    ///             "levels":[{"level","total_dn","netd_equivalent_k"}]},   (every level)
    ///    "nvd":[{"bandwidth_hz","nvd_v_per_sqrt_hz"}],
    ///    "temperatures":[{"t_k","radiance_w_m2_sr","emissive_power_w_m2",
    ///                     "sigma_t4_over_pi_w_m2_sr","dn","saturated","t_rad_k"}]}
    #[command(verbatim_doc_comment)]
    Sensor(sensor::SensorArgs),
    /// Fit the camera's own signature (shading, column/row pattern, hot and dead pixels,
    /// per-pixel residual, gain) on a real FITS frame and write the calibration TOML.
    SensorFit(sensor_fit::SensorFitArgs),
    /// Score detectors (and --predictions made elsewhere) on a directory of PNG, TIFF
    /// or FITS frames with a truth.csv: mean and median IoU, hit rate (IoU >= 0.5),
    /// false alarms, AUC and calibration of the confidence, and core time per method
    /// and per group (mode, scale, target, material, illumination, range band, SCR).
    /// Markdown on stdout; scores.csv, summary.csv, summary.json, confidence.csv and
    /// calibration.csv in --out.
    Eval(eval::EvalArgs),
    /// Reproduce the paper's results: render (or reuse) the datasets, score every
    /// detector, print Tables 6, 7 and 8 beside the paper's, and write the figures.
    /// The default command (`cargo run --release`): a reduced run of 1 200 + 300 images.
    Paper(paper::PaperArgs),
    /// Render a labelled synthetic dataset: 16-bit PNG of DN, truth.csv, coco.json and
    /// metadata.jsonl (optionally masks/ and preview/), from a preset or a TOML file.
    ///
    /// Presets (`--list-presets`): paper (12 000 images, Section 4.1), tango (1 000,
    /// Section 5), quick (24), realistic (12 000), realistic-tango (1 000),
    /// realistic-approach (2 448: sequences of 24 frames). The same seed gives the same
    /// bytes. A manifest (tirroi-run.json) records the run: a
    /// non-empty directory that is not a tirroi run is never written to, a previous
    /// run is replaced only with --force, and --resume continues a stopped one (Ctrl-C
    /// prints the command). --shard I/N and `tirroi merge` split a run over machines.
    Render(render::RenderArgs),
    /// Join the parts of a dataset rendered with `render --shard I/N` (on several
    /// machines or job-array tasks) into one directory: the same bytes as rendering it
    /// on one machine.
    Merge(merge::MergeArgs),
    /// Tune each detector's parameters on labelled frames: a fixed grid, then
    /// coordinate refinement, scored by mean IoU on the tune part (about 30 % of the
    /// frames, by a hash of the file name), then checked on the test part. Markdown on
    /// stdout; every trial in --out/trials.csv. Bad input: one line
    /// `tirroi: error: ...`, exit code 2.
    Tune(tune::TuneArgs),
    /// Statistics of the Earth's cloud texture (`earth_model.texture = "clouds"`) at
    /// 4 km per pixel: 2-px steps, their shares over 5/10/20 K, the 2-D spectral slope
    /// (8-200 km) and BT percentiles, beside a real longwave image (--real PNG, value =
    /// BT x 50); --preview writes ours and the real image side by side (220-300 K).
    EarthTexture(earth_texture::EarthTextureArgs),
    /// Write labelled test frames to score detectors on, never to tune them.
    ///
    /// Kinds: the seeded procedural fixtures, the real Hayabusa2 TIR dark frame with
    /// and without rendered targets, or rendered targets over windows of a real LWIR
    /// Earth image. 16-bit PNG, truth.csv (as `render` writes, both truth conventions)
    /// and metadata.jsonl; `tirroi eval --images DIR` scores it. docs/testsets.md.
    Testset(testset::TestsetArgs),
}

/// Runs the command line; returns the process exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli
        .command
        .unwrap_or_else(|| Command::Paper(paper::PaperArgs::default()))
    {
        Command::Detect(args) => detect::run(&args),
        Command::Memory => memory::run(),
        Command::Demo { repeat, figures } => demo::run(repeat as usize, figures.as_deref()),
        Command::Fixtures { out, count, seed } => exit_code(fixtures::run(&out, count, seed)),
        Command::Sensor(args) => sensor::run(&args),
        Command::SensorFit(args) => exit_code(sensor_fit::run(&args)),
        Command::Eval(args) => exit_code(eval::run(&args)),
        Command::Paper(args) => exit_code(paper::run(&args)),
        Command::Tune(args) => exit_code(tune::run(&args)),
        Command::Render(args) => exit_code(render::run(&args)),
        Command::Merge(args) => exit_code(merge::run(&args)),
        Command::EarthTexture(args) => exit_code(earth_texture::run(&args)),
        Command::Testset(args) => exit_code(testset::run(&args)),
    }
}

/// Success, or the error as one line `tirroi: error: ...` and [`EXIT_BAD_INPUT`].
fn exit_code(result: Result<(), String>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tirroi: error: {e}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}
