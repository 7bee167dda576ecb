//! Stage 5, reports: the paper's tables and figures from scored datasets.
//!
//! - [`paper`]: renders (or reuses) the paper's datasets, scores them with the tuned
//!   sets and prints Tables 6–8 beside the paper's;
//! - [`plots`]: the PNG figures.
//!
//! Imports every lower stage, never `cli`.

pub mod paper;
pub mod plots;
