//! `tirroi merge`: joins the parts of `render --shard I/N` into one dataset.

use std::path::PathBuf;

use crate::dataset;

/// The options of `tirroi merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Output directory: new or empty, or a previous tirroi run with --force (the same
    /// rules as `render --out`).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace a previous tirroi run in --out.
    #[arg(long)]
    pub force: bool,
    /// The part directories (any order): every shard I/N of one run, each complete.
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,
}

/// Runs `tirroi merge`.
///
/// # Errors
/// One line: a part that is not a complete shard of the same run, a missing or repeated
/// shard, an output that is not free.
pub fn run(args: &MergeArgs) -> Result<(), String> {
    let s = dataset::merge(&args.out, &args.parts, args.force).map_err(|e| e.to_string())?;
    println!(
        "merged {} parts: {} images ({}) into {}",
        s.parts,
        s.images,
        s.manifest.summary(),
        args.out.display()
    );
    Ok(())
}
