//! `tirroi testset`: writes a labelled test set (frames detectors are scored on, never
//! tuned on): the procedural fixture family, the real dark frame, or real-Earth
//! composites ([`crate::dataset::testset`]).

use std::path::PathBuf;

use crate::dataset::testset::{self, DEFAULT_REFERENCE_DIR, Kind, TestsetOptions};

/// The options of `tirroi testset`.
#[derive(Debug, clap::Args)]
pub struct TestsetArgs {
    /// Which test set: fixtures (the procedural generator of `tirroi fixtures`, seeded:
    /// Earth or space, target size/position/contrast, saturation, texture, noise),
    /// dark (the real Hayabusa2 TIR deep-space frame read out at fixed gain, noise,
    /// bit-depth and gain variants, with and without rendered targets), or real-earth
    /// (rendered targets over windows of a real 10.7 um image of the Earth).
    #[arg(long, value_parser = Kind::parse)]
    pub kind: Kind,
    /// Frames to write.
    #[arg(long, default_value_t = 200)]
    pub count: usize,
    /// Seed: the same seed gives the same bytes.
    #[arg(long, default_value_t = 16)]
    pub seed: u64,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Folder with hayabusa2-tir/ and earth-lwir/ (dark and real-earth kinds).
    #[arg(long, default_value = DEFAULT_REFERENCE_DIR)]
    pub reference: PathBuf,
    /// Share of frames without a target, 0..1 (default: fixtures 0.2, dark 0.5,
    /// real-earth 0.35).
    #[arg(long)]
    pub no_target_fraction: Option<f64>,
    /// Also write preview/ (contrast-stretched RGB with the truth box in green).
    #[arg(long)]
    pub preview: bool,
    /// real-earth only: frames per sequence (2..=100). The camera's window slides over
    /// the real image by a fixed step per frame (up to 5 px per axis), the target stays
    /// where it is in the frame; truth.csv gains `sequence,frame` (for `tirroi eval
    /// --track sequence`), and --no-target-fraction counts sequences.
    #[arg(long, value_name = "N")]
    pub sequence_frames: Option<usize>,
}

/// Runs `tirroi testset`.
///
/// # Errors
/// One line: a bad count or share, missing reference data (the file named), an
/// unwritable output.
pub fn run(args: &TestsetArgs) -> Result<(), String> {
    let opts = TestsetOptions {
        kind: args.kind,
        count: args.count,
        seed: args.seed,
        reference: args.reference.clone(),
        no_target_fraction: args.no_target_fraction,
        preview: args.preview,
        progress: true,
        sequence_frames: args.sequence_frames,
    };
    let s = testset::write_testset(&opts, &args.out).map_err(|e| e.to_string())?;
    println!(
        "wrote {} {} frames ({} without a target), truth.csv and metadata.jsonl to {}",
        s.frames,
        args.kind.name(),
        s.no_target,
        args.out.display()
    );
    Ok(())
}
