//! # tirroi-core
//!
//! The flight core of tirroi: `#![no_std]`, no heap, bounded memory known at compile
//! time. It holds what a thermal-infrared (TIR) camera and the first image-processing
//! step of a spacecraft's guidance, navigation and control (GNC) chain do on board:
//! the camera model (radiance → DN → noisy frame) and region-of-interest (ROI)
//! detection on 328×248 frames of digital numbers (DN).
//!
//! - [`sensor`]: the camera model of the paper's Sections 3.1 and 3.3: response, band
//!   radiance, view-factor flux, DN conversion, noise, and the frame pass.
//! - [`frame`]: a validated, borrowed view of a DN frame ([`Frame`]).
//! - [`roi`]: boxes ([`Roi`]), the shared [`Detector`] interface, the four detectors
//!   of the paper: [`roi::otsu`], [`roi::adaptive`], [`roi::wge`], [`roi::dog`], and our
//!   scene-aware [`roi::auto`] (with a tracking mode).
//! - `link` (cargo feature `spi`, on by default): frame input over SPI, CRC-checked
//!   rows read through an embedded-hal 1.0 `SpiDevice` by `link::FrameReader`, and a
//!   `link::SimulatedCamera` serving a stored frame.
//!
//! ## Memory per detector
//!
//! Each detector works in a [`roi::Scratch`] whose size is fixed at compile time; the
//! caller owns it (a `static` on flight hardware, a local on the host). Bytes beyond
//! the input frame on x86-64 (32-bit targets save a few bytes of `usize` fields); the
//! budgets are asserted by tests:
//!
//! | detector | scratch type | bytes | budget |
//! |---|---|---|---|
//! | Otsu | [`roi::otsu::OtsuScratch`] | [`roi::otsu::SCRATCH_BYTES`] = 15 216 | 16 KiB |
//! | adaptive | [`roi::adaptive::AdaptiveScratch`] | [`roi::adaptive::SCRATCH_BYTES`] = 11 576 | 16 KiB |
//! | WGE | [`roi::wge::WgeScratch`] | [`roi::wge::SCRATCH_BYTES`] = 14 352 | 16 KiB |
//! | DoG | [`roi::dog::DogScratch`] | [`roi::dog::SCRATCH_BYTES`] = 74 296 | 96 KiB |
//! | auto | [`roi::auto::AutoScratch`] | [`roi::auto::SCRATCH_BYTES`] = 25 456 | 32 KiB |
//!
//! The exact figures are printed by `tirroi memory` and listed in the README.
//!
//! ## Memory of the camera model
//!
//! | piece | bytes |
//! |---|---|
//! | [`sensor::BandRadiance`] (170 quadrature nodes in f64 and f32; room for 240) | 5 872 |
//! | [`sensor::BandLut`] (the fast path's 352 intervals) | 11 264 |
//! | [`sensor::NoiseField`] (generator, one row of 1/f filter state) | 1 360 |
//!
//! The frame pass [`sensor::expose_frame`] needs nothing beyond its input and output.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod capacity;
pub mod frame;
#[cfg(feature = "spi")]
pub mod link;
pub mod roi;
pub mod sensor;

pub use capacity::{Capacity, FrameCapacity, Reference};
pub use frame::{Frame, FrameError};
pub use roi::{BoxRule, DetectError, Detection, Detector, Method, Roi};
