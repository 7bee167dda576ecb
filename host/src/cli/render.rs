//! `tirroi render`: renders a labelled synthetic dataset.
//!
//! Files are safe (`dataset::inspect`): the output is a new or empty directory, or a
//! previous tirroi run (known by its `tirroi-run.json`) that `--force` replaces or
//! `--resume` continues with the same resolved configuration. Every refusal is one line
//! and exit code 2, with nothing written. Ctrl-C prints the command that resumes.

use std::path::{Path, PathBuf};

use crate::dataset::{self, Manifest, OutState, Outputs, RunSource, Shard};
use crate::world::scene::{self, SceneFile};

/// Exit code after Ctrl-C (128 + SIGINT, the shell's convention).
pub const EXIT_INTERRUPTED: i32 = 130;

/// The options of `tirroi render`.
#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// A built-in scene set (`--list-presets`: paper, tango, quick, realistic,
    /// realistic-tango).
    #[arg(long, conflicts_with = "config", required_unless_present_any = ["config", "list_presets"])]
    pub preset: Option<String>,
    /// A TOML scene/dataset file (format: the module docs of `tirroi_host::world::scene`, or
    /// `--print-config` of a preset).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Output directory: new or empty (created if missing), or a previous tirroi run
    /// with --force or --resume. A non-empty directory that is not a tirroi run, `/`
    /// and the home directory are refused.
    #[arg(long, default_value = "dataset")]
    pub out: PathBuf,
    /// Images in total, exactly (1..=10000000), spread over the scene kinds in
    /// proportion to their counts (default: as in the preset or file).
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
    /// Continue a stopped run in the same directory (skips finished images); refused
    /// unless preset or file content, seed, count, --masks, --preview and --shard are
    /// the run's (from its tirroi-run.json). A complete run is left as it is.
    #[arg(long, conflicts_with = "force")]
    pub resume: bool,
    /// Replace a previous tirroi run in --out: its frames, masks, previews, labels and
    /// manifest are removed first (other files are kept).
    #[arg(long)]
    pub force: bool,
    /// Render part I of N (0 <= I < N): the images whose index i has i mod N = I, with
    /// the label files of that part; `tirroi merge` joins the N parts into the bytes of
    /// the whole run. For job arrays (Slurm, Kubernetes indexed Jobs): README.
    #[arg(long, value_name = "I/N", value_parser = Shard::parse)]
    pub shard: Option<Shard>,
    /// Print the preset or file as TOML (after --count and --seed) and exit.
    #[arg(long)]
    pub print_config: bool,
    /// List the presets and exit.
    #[arg(long)]
    pub list_presets: bool,
}

/// Runs `tirroi render`: lists or prints presets, or renders the dataset.
///
/// # Errors
/// One line: a bad preset or file, an unwritable output.
pub fn run(args: &RenderArgs) -> Result<(), String> {
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
    let source = match (&args.preset, &args.config) {
        (Some(name), _) => RunSource::Preset(name.clone()),
        (None, Some(path)) => {
            let bytes =
                std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
            RunSource::File {
                path: path.display().to_string(),
                sha256: dataset::sha256_hex(&bytes),
            }
        }
        (None, None) => return Err("give --preset NAME or --config FILE".into()),
    };
    let outputs = Outputs {
        masks: args.masks,
        preview: args.preview,
    };
    let manifest = Manifest::new(source, &file, outputs, args.shard).map_err(|e| e.to_string())?;
    let out = &args.out;
    let mut resume = false;
    match dataset::inspect(out).map_err(|e| e.to_string())? {
        OutState::Free => {}
        OutState::Run(old) if args.resume => {
            let diff = old.differences(&manifest);
            if !diff.is_empty() {
                return Err(format!(
                    "--resume refused: {} is another run ({}): {}; resume it with `{}`, or replace it with --force",
                    out.display(),
                    old.summary(),
                    diff.join("; "),
                    old.command(out, true)
                ));
            }
            if old.complete {
                println!(
                    "{} is complete ({}): nothing to resume",
                    out.display(),
                    old.summary()
                );
                return Ok(());
            }
            resume = true;
        }
        OutState::Run(_) if args.force => {
            let n = dataset::clear_run(out).map_err(|e| e.to_string())?;
            eprintln!(
                "--force: removed {n} files of the previous run in {}",
                out.display()
            );
        }
        OutState::Run(old) if old.complete => {
            return Err(format!(
                "{} holds a complete tirroi run ({}); add --force to replace it, or give another --out",
                out.display(),
                old.summary()
            ));
        }
        OutState::Run(old) => {
            return Err(format!(
                "{} holds an unfinished tirroi run ({}); continue it with `{}`, or add --force to replace it",
                out.display(),
                old.summary(),
                old.command(out, true)
            ));
        }
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    manifest.write(out).map_err(|e| e.to_string())?;
    on_interrupt(&manifest, out);

    let total = file.image_count();
    let shard = args.shard.map_or(String::new(), |s| format!(", shard {s}"));
    eprintln!(
        "rendering {total} images of `{}` (seed {}{shard}) into {}",
        file.dataset.name,
        file.dataset.seed,
        out.display()
    );
    let options = dataset::WriteOptions {
        masks: args.masks,
        preview: args.preview,
        resume,
        progress: true,
        shard: args.shard,
    };
    let s = dataset::write_dataset(&file, out, &options).map_err(|e| e.to_string())?;
    Manifest {
        complete: true,
        ..manifest
    }
    .write(out)
    .map_err(|e| e.to_string())?;
    let render_s = s.wall_s[1].max(1e-9);
    let cpu: f64 = s.stage_cpu_s.iter().sum::<f64>() + s.other_cpu_s;
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
        "per-image CPU time by stage: target {:.1} % | Earth {:.1} % | PSF + signature {:.1} % | DN + noise {:.1} % | PNG encode + write {:.1} % | signal-to-clutter twin {:.1} % | other {:.1} % ({:.2} ms per image)",
        pct(s.stage_cpu_s[0]),
        pct(s.stage_cpu_s[1]),
        pct(s.stage_cpu_s[2]),
        pct(s.stage_cpu_s[3]),
        pct(s.stage_cpu_s[4]),
        pct(s.stage_cpu_s[5]),
        pct(s.other_cpu_s),
        if s.rendered > 0 {
            cpu * 1e3 / s.rendered as f64
        } else {
            0.0
        },
    );
    // Steady state: the render phase alone (library set-up and labels excluded), and
    // how busy the workers were (per-image time over the phase's thread-seconds).
    println!(
        "steady state: {:.1} frames/s on {} threads, workers {:.0} % busy in images",
        s.rendered as f64 / render_s,
        s.threads,
        100.0 * cpu / (render_s * s.threads.max(1) as f64),
    );
    println!("labels: {}", dataset::truth_path(&args.out).display());
    Ok(())
}

/// Ctrl-C: prints the exact command that continues the run, and exits with
/// [`EXIT_INTERRUPTED`]. Finished images are safe: each file is renamed into place
/// whole and journalled after it.
fn on_interrupt(manifest: &Manifest, out: &Path) {
    let command = manifest.command(out, true);
    // Only one handler per process; a second install (a library caller rendering
    // twice) keeps the first, which names the first run.
    let _ = ctrlc::set_handler(move || {
        eprintln!("\ntirroi: interrupted; finished images are kept. Continue with:\n  {command}");
        std::process::exit(EXIT_INTERRUPTED);
    });
}
