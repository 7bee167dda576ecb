//! # tirroi-host
//!
//! The host harness of tirroi: it drives the flight core (`tirroi-core`) exactly as
//! flight would, from PNG frames or procedural fixtures, and hosts the `tirroi` CLI.
//!
//! # Crate map
//!
//! The modules follow the data: a scene is described, rendered into DN frames, written
//! as a labelled dataset, scored (and tuned), then reported; the CLI drives each step.
//!
//! | stage | module | what lives there |
//! |---|---|---|
//! | 0 | [`seed`], [`progress`] | foundation: hashing and seeding (SplitMix64, FNV-1a), progress bars |
//! | 1 | [`world`] | scene descriptions and presets, geometry, physical constants, the Earth's OLR field ([`world::earth`]), target meshes and their thermal solution ([`world::spacecraft`]) |
//! | 2 | [`imaging`] | the renderer (world → DN frame), procedural fixtures, PNG/TIFF frame I/O, box overlays |
//! | 3 | [`dataset`] | rendering whole labelled datasets: plans, images, labels, the resume journal |
//! | 4 | [`eval`] | the detector bank, scoring against labels, the tune/test split, the parameter search and the tuned sets |
//! | 5 | [`report`] | the paper's tables and the PNG figures |
//! | 6 | [`cli`] | the `tirroi` command line, one file per subcommand |
//!
//! Rule for imports: a module may use its own stage and the stages above it in this
//! table (lower numbers), never a later one. So `world` knows nothing of rendering,
//! `eval` nothing of the paper, and only `cli` parses command-line arguments.
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod cli;
pub mod dataset;
pub mod eval;
pub mod imaging;
pub mod progress;
pub mod report;
pub mod seed;
pub mod world;
