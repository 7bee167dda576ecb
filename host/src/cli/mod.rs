//! The `tirroi` command line.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use serde::Serialize;
use tirroi_core::{BoxRule, Method};

use crate::cli::sensor::{self as sensor_view, SensorRequest};
use crate::eval::bank::DetectorBank;
use crate::eval::scoring;
use crate::imaging::image_io::read_frame;
use crate::imaging::{fixture, overlay};
use crate::report::paper;
use crate::world::scene::{self, SceneFile};
use crate::{dataset, progress};

/// `tirroi sensor`: the thermal camera model of `tirroi_core::sensor` as tables or JSON.
pub mod sensor;

/// Exit code for bad input (files, sizes, parameters), as clap uses for bad arguments.
pub const EXIT_BAD_INPUT: u8 = 2;

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
    /// Detect the ROI in 8/16-bit grayscale PNG (or TIFF) frames.
    Detect {
        /// Detector: otsu, adaptive, wge, dog, auto, or all (the five).
        #[arg(long, default_value = "all", value_parser = parse_methods)]
        method: MethodChoice,
        /// Runs per frame and method; the reported time is the median.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
        repeat: u32,
        /// Print one JSON object per frame and method.
        #[arg(long)]
        json: bool,
        /// Bit depth of the DN (default: 8 for 8-bit files; 14 for 16-bit files whose
        /// DN fit, else 16).
        #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
        bits: Option<u8>,
        /// Frames to process.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Print the scratch memory of each detector, in bytes.
    Memory,
    /// Write the procedural fixture frames as 16-bit PNG with a `truth.csv`.
    Fixtures {
        /// Output directory (created if missing).
        #[arg(long, default_value = "fixtures")]
        out: PathBuf,
    },
    /// Run every detector on the built-in procedural frames and print IoU and time.
    Demo {
        /// Runs per frame and method; the reported time is the median.
        #[arg(long, default_value_t = 21)]
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
    ///   {"response":"tir"|"flat", "level":"netd"|"paper-literal"|"paper-visible",
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
    Sensor(SensorArgs),
    /// Score detectors on a directory of 16-bit PNG frames with a truth.csv: mean and
    /// median IoU, hit rate (IoU >= 0.5) and core time per method and per group
    /// (mode, scale, target, material, illumination, range band). Markdown on stdout;
    /// scores.csv, summary.csv and summary.json in --out.
    Eval {
        /// Directory of frames.
        #[arg(long)]
        images: PathBuf,
        /// Labels (default: IMAGES/truth.csv), header `file,x0,y0,x1,y1[,extra...]`.
        #[arg(long)]
        truth: Option<PathBuf>,
        /// Detector: otsu, adaptive, wge, dog, auto, or all (the five).
        #[arg(long, default_value = "all", value_parser = parse_methods)]
        method: MethodChoice,
        /// Runs per frame and method; the reported time is the median.
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
        repeat: u32,
        /// Mask-to-box rule: largest-component or all-foreground.
        #[arg(long, default_value = "largest-component", value_parser = parse_box_rule)]
        box_rule: BoxRule,
        /// Bit depth of the DN (default: 14 for 16-bit files whose DN fit).
        #[arg(long, value_parser = clap::value_parser!(u8).range(1..=16))]
        bits: Option<u8>,
        /// Write scores.csv, summary.csv and summary.json here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Tracking prior for auto: off (search every frame whole); jitter (the truth
        /// box moved by up to 4 px and each side by up to 10 %, as a tracker would hand
        /// it over); sequence (frames in file-name order, each frame's prior is auto's
        /// box on the previous one; one thread).
        #[arg(long, default_value = "off", value_parser = parse_track)]
        track: scoring::Track,
    },
    /// Reproduce the paper's results: render (or reuse) the datasets, score every
    /// detector, print Tables 6, 7 and 8 beside the paper's, and write the figures.
    /// The default command (`cargo run --release`): a reduced run of 1 200 + 300 images.
    Paper {
        /// Where datasets, reports and figures go.
        #[arg(long, default_value = "paper-run")]
        out: PathBuf,
        /// Where the figures go (PNG).
        #[arg(long, default_value = "docs/paper")]
        figures: PathBuf,
        /// Full-size datasets: 12 000 + 1 000 images.
        #[arg(long)]
        full: bool,
        /// Runs per frame and method for the timing (median).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
        repeat: u32,
    },
    /// Render a labelled synthetic dataset: 16-bit PNG of DN, truth.csv, coco.json and
    /// metadata.jsonl (optionally masks/ and preview/), from a preset or a TOML file.
    ///
    /// Presets: paper (12 000 images, Section 4.1), tango (1 000, Section 5), quick (24).
    /// The same seed gives the same bytes; a stopped run can continue with --resume.
    Render(RenderArgs),
    /// Tune each detector's parameters on labelled frames: a fixed grid, then
    /// coordinate refinement, scored by mean IoU on the tune part (about 30 % of the
    /// frames, by a hash of the file name), then checked on the test part. Markdown on
    /// stdout; every trial in --out/trials.csv. Bad input: one line
    /// `tirroi: error: ...`, exit code 2.
    Tune(crate::eval::tune::TuneArgs),
}

/// The options of `tirroi render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// A built-in scene set: paper, tango or quick.
    #[arg(long, conflicts_with = "config", required_unless_present_any = ["config", "list_presets"])]
    pub preset: Option<String>,
    /// A TOML scene/dataset file (format: the module docs of `tirroi_host::world::scene`, or
    /// `--print-config` of a preset).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output directory (created if missing).
    #[arg(long, default_value = "dataset")]
    pub out: PathBuf,
    /// Images in total, spread over the scene kinds in proportion (default: as in the
    /// preset or file).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=10_000_000))]
    pub count: Option<u64>,
    /// Dataset seed (default: the preset's or file's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Also write contrast-stretched 8-bit previews with the truth box (preview/).
    #[arg(long)]
    pub preview: bool,
    /// Also write 8-bit target coverage masks (masks/).
    #[arg(long)]
    pub masks: bool,
    /// Continue a stopped run in the same directory (skips finished images).
    #[arg(long)]
    pub resume: bool,
    /// Print the preset or file as TOML (after --count and --seed) and exit.
    #[arg(long)]
    pub print_config: bool,
    /// List the presets and exit.
    #[arg(long)]
    pub list_presets: bool,
}

/// The options of `tirroi sensor`. They are taken as text and checked by
/// [`sensor_view::report`], so that every bad value gets the same one-line error.
#[derive(Debug, clap::Args)]
pub struct SensorArgs {
    /// Noise level of the sigma in DN: netd (total sigma = NETD (K) x dDN/dT (DN/K) at
    /// --t-ref-k), paper-literal (Eq. 16: 2470 ADU/V x RMS (V)), paper-visible (Eq. 16 x
    /// (2^bits - 1)).
    #[arg(long, value_name = "LEVEL", default_value = "netd")]
    pub level: String,
    /// NETD of the `netd` level, K.
    #[arg(
        long,
        value_name = "K",
        default_value = "0.4",
        allow_hyphen_values = true
    )]
    pub netd_k: String,
    /// Reference scene temperature of the `netd` level (where dDN/dT is taken), K.
    #[arg(
        long,
        value_name = "K",
        default_value = "300",
        allow_hyphen_values = true
    )]
    pub t_ref_k: String,
    /// RMS voltages (V) of the three noise sources: table2 (the published Table 2),
    /// as-printed (Eqs. 11, 13, 14 as printed), physical (consistent bandwidths).
    #[arg(long, value_name = "READING", default_value = "table2")]
    pub reading: String,
    /// Bit depth of the DN, 1..=16.
    #[arg(
        long,
        value_name = "N",
        default_value = "14",
        allow_hyphen_values = true
    )]
    pub bits: String,
    /// Scene temperatures, K, comma-separated (0..=10000).
    #[arg(
        long,
        value_name = "K,K,...",
        default_value = "150,200,250,300,350,400,460",
        allow_hyphen_values = true
    )]
    pub temps: String,
    /// Gray-body emissivity of the scene (and of the range), 0 < emissivity <= 1.
    #[arg(
        long,
        value_name = "E",
        default_value = "1.0",
        allow_hyphen_values = true
    )]
    pub emissivity: String,
    /// Radiometry auto range (Eq. 17), K: F(T_lo) maps to DN 0, F(T_hi) to 2^bits - 1.
    #[arg(
        long,
        value_name = "T_LO,T_HI",
        default_value = "150,460",
        allow_hyphen_values = true
    )]
    pub range_k: String,
    /// Measurement bandwidths of the noise voltage density, Hz, comma-separated (> 0).
    #[arg(
        long,
        value_name = "HZ,HZ,...",
        default_value = "1,10,100,1000,10000,83333,1000000",
        allow_hyphen_values = true
    )]
    pub bandwidths: String,
    /// Spectral response: tir (the Hayabusa2 TIR band model, 8-12 um) or flat (R = 1, so
    /// that i = emissivity x sigma T^4/pi (W m^-2 sr^-1)).
    #[arg(long, value_name = "RESPONSE", default_value = "tir")]
    pub response: String,
    /// Print one JSON object (shape in `tirroi sensor --help`) instead of the tables.
    #[arg(long)]
    pub json: bool,
}

fn parse_box_rule(s: &str) -> Result<BoxRule, String> {
    match s {
        "largest-component" => Ok(BoxRule::LargestComponent),
        "all-foreground" => Ok(BoxRule::AllForeground),
        _ => Err(format!(
            "unknown box rule `{s}`; expected largest-component or all-foreground"
        )),
    }
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

/// One method or all of them.
#[derive(Debug, Clone)]
pub struct MethodChoice(pub Vec<Method>);

fn parse_methods(s: &str) -> Result<MethodChoice, String> {
    if s == "all" {
        return Ok(MethodChoice(Method::ALL.to_vec()));
    }
    Method::from_name(s)
        .map(|m| MethodChoice(vec![m]))
        .ok_or_else(|| {
            format!("unknown method `{s}`; expected otsu, adaptive, wge, dog, auto or all")
        })
}

/// The JSON line of `tirroi detect --json` (DESIGN.md).
#[derive(Debug, Serialize)]
struct DetectLine<'a> {
    file: &'a str,
    method: &'static str,
    bbox: Option<[u16; 4]>,
    time_us: f64,
}

/// Runs the command line; returns the process exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command.unwrap_or(Command::Paper {
        out: PathBuf::from("paper-run"),
        figures: PathBuf::from("docs/paper"),
        full: false,
        repeat: 3,
    }) {
        Command::Detect {
            method,
            repeat,
            json,
            bits,
            files,
        } => detect(&method.0, repeat as usize, json, bits, &files),
        Command::Memory => {
            println!("| detector | scratch bytes |");
            println!("|---|---|");
            for m in Method::ALL {
                println!("| {m} | {} |", m.scratch_bytes());
            }
            ExitCode::SUCCESS
        }
        Command::Demo { repeat, figures } => demo(repeat as usize, figures.as_deref()),
        Command::Fixtures { out } => exit_code(write_fixtures(&out)),
        Command::Sensor(args) => sensor(&args),
        Command::Eval {
            images,
            truth,
            method,
            repeat,
            box_rule,
            bits,
            out,
            track,
        } => {
            let options = scoring::EvalOptions {
                methods: method.0,
                repeat: repeat as usize,
                box_rule: Some(box_rule),
                bits,
                track,
            };
            exit_code(run_eval(
                &images,
                truth.as_deref(),
                &options,
                out.as_deref(),
            ))
        }
        Command::Paper {
            out,
            figures,
            full,
            repeat,
        } => {
            let options = paper::PaperOptions {
                out,
                figures,
                full,
                repeat: repeat as usize,
                progress: true,
            };
            exit_code(run_paper(&options))
        }
        Command::Tune(args) => exit_code(crate::eval::tune::run(&args)),
        Command::Render(args) => exit_code(render_dataset(&args)),
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

fn run_eval(
    images: &std::path::Path,
    truth: Option<&std::path::Path>,
    options: &scoring::EvalOptions,
    out: Option<&std::path::Path>,
) -> Result<(), String> {
    let truth = truth.map_or_else(|| images.join("truth.csv"), std::path::Path::to_path_buf);
    let rows = scoring::read_truth(&truth).map_err(|e| e.to_string())?;
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

fn run_paper(options: &paper::PaperOptions) -> Result<(), String> {
    let start = std::time::Instant::now();
    let scores = paper::run(options)?;
    let report = paper::report(&scores);
    println!("{report}");
    let path = options.out.join("tables.md");
    std::fs::write(&path, &report).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    let figures = paper::figures(options, &scores)?;
    println!("figures:");
    for f in &figures {
        println!("  {}", f.display());
    }
    println!(
        "tables: {} ({:.0} s in all)",
        path.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn render_dataset(args: &RenderArgs) -> Result<(), String> {
    if args.list_presets {
        for (name, about, _) in scene::PRESETS {
            println!("{name:8} {about}");
        }
        return Ok(());
    }
    let mut file = match (&args.preset, &args.config) {
        (Some(name), _) => SceneFile::preset(name),
        (None, Some(path)) => SceneFile::load(path),
        (None, None) => return Err("give --preset NAME or --config FILE".into()),
    }
    .map_err(|e| e.to_string())?;
    if let Some(seed) = args.seed {
        file.dataset.seed = seed;
    }
    if let Some(count) = args.count {
        file.rescale_count(count as usize)
            .map_err(|e| e.to_string())?;
    }
    if args.print_config {
        print!("{}", toml::to_string(&file).map_err(|e| e.to_string())?);
        return Ok(());
    }
    let total = file.image_count();
    eprintln!(
        "rendering {total} images of `{}` (seed {}) into {}",
        file.dataset.name,
        file.dataset.seed,
        args.out.display()
    );
    let options = dataset::WriteOptions {
        masks: args.masks,
        preview: args.preview,
        resume: args.resume,
        progress: true,
    };
    let s = dataset::write_dataset(&file, &args.out, &options).map_err(|e| e.to_string())?;
    let render_s = s.wall_s[1].max(1e-9);
    let cpu: f64 = s.stage_cpu_s.iter().sum();
    let pct = |v: f64| if cpu > 0.0 { 100.0 * v / cpu } else { 0.0 };
    println!(
        "{} images rendered ({} resumed) in {:.2} s: {:.1} images/s; library {:.2} s ({} meshes {:.2} s, {} thermal solutions {:.2} s, {} Earth maps {:.2} s); labels {:.2} s",
        s.rendered,
        s.skipped,
        s.wall_s.iter().sum::<f64>(),
        s.rendered as f64 / render_s,
        s.wall_s[0],
        s.library_counts.0,
        s.library_s[0],
        s.library_counts.1,
        s.library_s[1],
        s.library_counts.2,
        s.library_s[2],
        s.wall_s[2],
    );
    println!(
        "per-image CPU time by stage: target {:.1} % | Earth {:.1} % | DN + noise {:.1} % | PNG encode + write {:.1} % ({:.2} ms per image)",
        pct(s.stage_cpu_s[0]),
        pct(s.stage_cpu_s[1]),
        pct(s.stage_cpu_s[2]),
        pct(s.stage_cpu_s[3]),
        if s.rendered > 0 {
            cpu * 1e3 / s.rendered as f64
        } else {
            0.0
        },
    );
    println!("labels: {}", dataset::truth_path(&args.out).display());
    Ok(())
}

fn sensor(args: &SensorArgs) -> ExitCode {
    let request = SensorRequest {
        level: &args.level,
        reading: &args.reading,
        response: &args.response,
        netd_k: &args.netd_k,
        t_ref_k: &args.t_ref_k,
        bits: &args.bits,
        temps: &args.temps,
        emissivity: &args.emissivity,
        range_k: &args.range_k,
        bandwidths: &args.bandwidths,
    };
    let report = match sensor_view::report(&request) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("tirroi: error: {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let text = if args.json {
        match serde_json::to_string(&report) {
            Ok(s) => s + "\n",
            Err(e) => {
                eprintln!("tirroi: error: cannot write JSON: {e}");
                return ExitCode::from(EXIT_BAD_INPUT);
            }
        }
    } else {
        report.markdown()
    };
    // A closed stdout (e.g. piped into `head`) is not an error worth a panic.
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
    ExitCode::SUCCESS
}

fn detect(
    methods: &[Method],
    repeat: usize,
    json: bool,
    bits: Option<u8>,
    files: &[PathBuf],
) -> ExitCode {
    let mut bank = DetectorBank::default();
    let mut failed = false;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for path in files {
        let frame = match read_frame(path, bits) {
            Ok(f) => f,
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
        for &method in methods {
            let (d, time_us) = match bank.detect_timed(method, &view, repeat) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("tirroi: error: {method}: {e}");
                    return ExitCode::from(EXIT_BAD_INPUT);
                }
            };
            let file = path.to_string_lossy();
            let written = if json {
                let line = DetectLine {
                    file: &file,
                    method: method.name(),
                    bbox: d.roi.map(|r| r.to_array()),
                    time_us: (time_us * 1000.0).round() / 1000.0,
                };
                serde_json::to_string(&line)
                    .map_err(std::io::Error::other)
                    .and_then(|s| writeln!(out, "{s}"))
            } else {
                let bbox = d
                    .roi
                    .map(|r| format!("{:?}", r.to_array()))
                    .unwrap_or_else(|| "none".into());
                writeln!(
                    out,
                    "{file}  {:<8}  bbox {bbox:<22}  {time_us:>9.1} us  threshold {}  foreground {} px",
                    method.name(),
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

fn demo(repeat: usize, figures: Option<&std::path::Path>) -> ExitCode {
    if let Some(dir) = figures {
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("tirroi: error: {}: cannot create: {e}", dir.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    }
    println!(
        "tirroi demo: the paper's four detectors and `auto` on procedural 328x248 14-bit frames"
    );
    println!(
        "(not physically rendered: the renderer and the paper's tables come with later work)\n"
    );
    let mut bank = DetectorBank::default();
    println!(
        "| frame | method | box, all foreground | IoU | box, largest component | IoU | truth | median time [us] |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, spec) in fixture::standard_set() {
        let fx = fixture::render(&spec);
        let Ok(view) = fx.frame.view() else {
            eprintln!("tirroi: error: fixture {name} does not fit the core");
            return ExitCode::from(EXIT_BAD_INPUT);
        };
        let mut drawn = vec![(fx.truth, overlay::TRUTH_COLOUR)];
        for (method, colour) in Method::ALL.into_iter().zip(overlay::METHOD_COLOURS) {
            let mut cells = Vec::new();
            let mut time_us = 0.0;
            for rule in [BoxRule::AllForeground, BoxRule::LargestComponent] {
                bank.set_box_rule(rule);
                match bank.detect_timed(method, &view, repeat) {
                    Ok((d, t)) => {
                        let iou = d.roi.map_or(0.0, |r| r.iou(&fx.truth));
                        let bbox = d
                            .roi
                            .map_or("none".into(), |r| format!("{:?}", r.to_array()));
                        cells.push(format!("{bbox} | {iou:.3}"));
                        if rule == BoxRule::AllForeground {
                            time_us = t;
                        } else if let Some(r) = d.roi {
                            drawn.push((r, colour));
                        }
                    }
                    Err(e) => {
                        eprintln!("tirroi: error: {method}: {e}");
                        return ExitCode::from(EXIT_BAD_INPUT);
                    }
                }
            }
            println!(
                "| {name} | {method} | {} | {:?} | {time_us:.1} |",
                cells.join(" | "),
                fx.truth.to_array()
            );
        }
        if let Some(dir) = figures {
            let img = overlay::frame_with_boxes(&fx.frame, &drawn, 1);
            if let Err(e) = overlay::save(&img, &dir.join(format!("demo-{name}.png"))) {
                eprintln!("tirroi: error: {e}");
                return ExitCode::from(EXIT_BAD_INPUT);
            }
        }
    }
    if let Some(dir) = figures {
        println!(
            "\nFigures: {}/demo-*.png (green: truth; largest-component boxes: red Otsu, blue adaptive, yellow WGE, magenta DoG, cyan auto).",
            dir.display()
        );
    }
    println!(
        "\nTimes are for the all-foreground rule (auto has no box rule: both columns are the same). Scratch memory per detector: `tirroi memory`."
    );
    ExitCode::SUCCESS
}

fn write_fixtures(out: &std::path::Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let mut csv = String::from("file,x0,y0,x1,y1\n");
    for (name, spec) in fixture::standard_set() {
        let fx = fixture::render(&spec);
        let file = format!("{name}.png");
        crate::imaging::image_io::write_png16(&out.join(&file), &fx.frame)
            .map_err(|e| e.to_string())?;
        let [x0, y0, x1, y1] = fx.truth.to_array();
        csv.push_str(&format!("{file},{x0},{y0},{x1},{y1}\n"));
    }
    let truth = out.join("truth.csv");
    std::fs::write(&truth, csv).map_err(|e| format!("{}: cannot write: {e}", truth.display()))?;
    println!(
        "wrote {} frames and truth.csv to {}",
        fixture::standard_set().len(),
        out.display()
    );
    Ok(())
}
