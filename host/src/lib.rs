//! # tirroi-host
//!
//! The host harness of tirroi: it drives the flight core (`tirroi-core`) exactly as
//! flight would, from PNG frames or procedural fixtures, and hosts the `tirroi` CLI.
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod cli;
pub mod dataset;
pub mod earth;
pub mod eval;
pub mod figure;
pub mod fixture;
pub mod geom;
pub mod image_io;
pub mod paper;
pub mod plots;
pub mod progress;
pub mod render;
pub mod run;
pub mod scene;
/// `tirroi sensor`: the thermal camera model of `tirroi_core::sensor` as tables or JSON.
pub mod sensor_view;
pub mod target;
pub mod tune;
pub mod tuned;
