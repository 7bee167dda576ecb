//! Stage 4, evaluation: running the flight detectors on labelled frames and scoring
//! them.
//!
//! - [`bank`]: one detector of each method with its scratch, timed runs;
//! - [`scoring`]: labels (`truth.csv`, validated), per-frame IoU and time, group
//!   statistics, reports;
//! - [`confidence`]: what a detection's score is worth: the hit-rate / false-alarm curve
//!   over the threshold, its AUC, calibration per score decile;
//! - [`confidence_report`]: those figures per method, group and truth convention
//!   (Markdown, `confidence.csv`, `calibration.csv`, `--curve`);
//! - [`predictions`]: boxes made elsewhere (detect JSON lines, CSV, COCO results) scored
//!   like the built-in methods;
//! - [`split`]: the tune/test split (a hash of the file name) and `--where` filters;
//! - [`tune`]: the parameter search;
//! - [`tuned`]: the parameter sets that search produced, one per dataset kind.
//!
//! Imports [`imaging`](crate::imaging) (frame files) and lower stages, never
//! `report` or `cli`. Inside the stage: `bank` ← `scoring` ← `split` ← `tune`;
//! `confidence` ← `scoring` ← `predictions`, `confidence_report`; `tuned` needs only
//! `bank`.

pub mod bank;
pub mod confidence;
pub mod confidence_report;
pub mod predictions;
pub mod scoring;
pub mod split;
pub mod tune;
pub mod tuned;
