//! `tirroi render`: renders a labelled synthetic dataset.

use std::path::PathBuf;

use crate::dataset;
use crate::world::scene::{self, SceneFile};

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
