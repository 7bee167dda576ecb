//! Tuning the detectors' parameters on labelled frames, the way the paper "fine-tuned
//! the hyper-parameters" before its Tables 6–8, but reproducibly and with a held-out
//! test split (the split itself: [`crate::eval::split`]).
//!
//! # Search
//!
//! [`search`] scores every set of a fixed grid per method ([`grid`]) on the given
//! frames, then refines each of the [`SearchOptions::starts`] best grid sets of a
//! method by steepest ascent on finer ladders of each coordinate (one ladder step up or
//! down per coordinate, and the other box rule), at most
//! [`SearchOptions::refine_steps`] moves each, and keeps the best end point. A
//! candidate's score is its mean IoU over the frames with a target (the scoring
//! definition of [`crate::eval::scoring`]); equal means (within 10⁻⁹) go to the lower
//! false-alarm rate on frames without a target, then to the clearly lower mean core
//! time, else to the candidate scored first ([`Trial::beats`]). Every
//! candidate scored, grid or refinement, is kept as a [`Trial`] (each once), so the
//! trials double as the run-time-against-IoU scatter of a method.
//!
//! Grids, each set with both box rules (the core defaults are among them):
//!
//! | method | coordinates | grid |
//! |---|---|---|
//! | otsu | box rule | all-foreground, largest-component |
//! | adaptive | `block` (px) × `offset_dn` (DN) | {11, 21, 41, 61, 81, 121, 161} × {0, 32, 64, 128, 256, 512, 1024, 2048, 4096} |
//! | wge | `drop_fraction` × `min_gradient` (Prewitt L1 DN) | {0.8, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.998} × {0, 48, 128, 256, 512, 1024, 2048, 4096, 8192} |
//! | dog | `sigma0_px` × `levels` × `min_response_dn` (`sigma_ratio` 1.6) | {2, 4, 8} × {3, 5, 7} × {64, 128, 256, 512, 1024, 2048} (the 6 sets whose widest σ exceeds the core's bound skipped) |
//!
//! | auto | `coarse_sigma` × `fine_sigma` (noise units; no box rule) | {6, 8, 10, 12, 16} × {6, 8, 12, 16} |
//!
//! That is 2 + 126 + 144 + 96 (+ 20 for auto, 1 for auto-v2: its defaults, no grid)
//! grid sets; the refinement adds some 20–150 trials per method. Refinement ladders are the `*_LADDER` constants. Frames are scored through
//! [`crate::eval::scoring::score`] (in parallel, one run each); while the grids run, each pass over
//! the frames scores one grid set of every method, so a frame is decoded once per pass
//! rather than once per set. Measured (release, 2 cores shared with other work): four
//! methods on 88 tune frames in 16–21 s, on 367–373 tune frames in 32–90 s.

mod search;
mod space;
#[cfg(test)]
mod tests;

pub use search::{
    MethodBest, SearchOptions, Trial, TuneResult, evaluate, evaluate_together, search,
    search_method, trials_csv,
};
pub use space::{
    AUTO_SIGMA_LADDER, BLOCK_LADDER, DROP_LADDER, GRADIENT_LADDER, OFFSET_LADDER, RATIO_LADDER,
    RESPONSE_LADDER, SIGMA0_LADDER, defaults, grid, is_valid, neighbours,
};
