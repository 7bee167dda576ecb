//! `tirroi paper`: reproduces the paper's tables and figures.

use std::path::PathBuf;

use crate::report::paper;

/// The options of `tirroi paper`.
#[derive(Debug, clap::Args)]
pub struct PaperArgs {
    /// Where datasets, reports and figures go.
    #[arg(long, default_value = "paper-run")]
    pub out: PathBuf,
    /// Where the figures go (PNG).
    #[arg(long, default_value = "docs/paper")]
    pub figures: PathBuf,
    /// Full-size datasets: 12 000 + 1 000 images.
    #[arg(long)]
    pub full: bool,
    /// Runs per frame and method (the one range of `REPEAT_RANGE`); the median time is reported.
    #[arg(long, default_value_t = 3, value_parser = super::repeat_parser(), help = super::repeat_help())]
    pub repeat: u32,
}

impl Default for PaperArgs {
    /// The default command (`tirroi` alone): a reduced run into `paper-run`.
    fn default() -> Self {
        PaperArgs {
            out: PathBuf::from("paper-run"),
            figures: PathBuf::from("docs/paper"),
            full: false,
            repeat: 3,
        }
    }
}

/// Runs `tirroi paper`: the datasets of both worlds, Tables 6–8 of each (printed and in
/// `tables.md`) and the paper world's figures.
///
/// # Errors
/// One line from any step.
pub fn run(args: &PaperArgs) -> Result<(), String> {
    let options = &paper::PaperOptions {
        out: args.out.clone(),
        figures: args.figures.clone(),
        full: args.full,
        repeat: args.repeat as usize,
        progress: true,
    };
    let start = std::time::Instant::now();
    let scores = paper::run(options)?;
    let realistic = paper::run_world(options, paper::World::Realistic)?;
    let report = format!(
        "## The paper's world\n\n{}\n## The realistic world (presets `realistic`, `realistic-tango`)\n\n{}",
        paper::report(&scores),
        paper::realistic_report(&realistic)
    );
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
