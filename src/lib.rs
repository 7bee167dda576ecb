//! # tirroi
//!
//! Synthetic thermal-infrared (TIR) imaging and flight-ready region-of-interest (ROI)
//! detection for spacecraft close-proximity navigation.
//!
//! This root crate only re-exports the two crates of the workspace:
//! - [`core`] (`tirroi-core`): the `#![no_std]` flight core (camera model, ROI detectors);
//! - [`host`] (`tirroi-host`): the host harness (scenes, renderer, evaluation, CLI).
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub use tirroi_core as core;
pub use tirroi_host as host;
