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
//!   scene-aware [`roi::auto`] (with a tracking mode); [`roi::track`]: `auto-v2` over a
//!   sequence of frames (its last box, and targets acquired by their motion against the
//!   ground).
//! - `link` (cargo feature `spi`, on by default): frame input over SPI, CRC-checked
//!   rows read through an embedded-hal 1.0 `SpiDevice` by `link::FrameReader`, and a
//!   `link::SimulatedCamera` serving a stored frame.
//!
//! ## Example: find the target in one frame
//!
//! A 328×248 frame of 14-bit DN: deep space at 200 DN, a warm target at 9 000 DN
//! filling columns 100..180 and rows 60..140. `auto` needs no tuning; its scratch
//! (about 25 KB) is boxed here, a `static` on flight hardware.
//!
//! ```
//! use tirroi_core::roi::auto::{Auto, AutoScratch};
//! use tirroi_core::{Detector, Frame, Roi};
//!
//! const W: usize = 328;
//! const H: usize = 248;
//! let mut pixels = vec![200u16; W * H];
//! for y in 60..140 {
//!     pixels[y * W + 100..y * W + 180].fill(9_000);
//! }
//! let frame = Frame::new(&pixels, W, H, 14).unwrap();
//!
//! let mut scratch: Box<AutoScratch> = Box::new(AutoScratch::new());
//! let found = Auto::default().detect(&frame, &mut scratch).unwrap();
//!
//! // Boxes are [x0, y0, x1, y1]: x right, y down, (x0, y0) inclusive, (x1, y1) exclusive.
//! assert_eq!(found.roi, Some(Roi::new(100, 60, 180, 140)));
//!
//! // Tracking: the next frame, with this box as the prior, searches a window around it.
//! let tracker = Auto::default().with_prior(found.roi);
//! let next = tracker.detect(&frame, &mut scratch).unwrap();
//! assert_eq!(next.roi, found.roi);
//! ```
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
//! | Otsu | [`roi::otsu::OtsuScratch`] | [`roi::otsu::SCRATCH_BYTES`] = 15 224 | 16 KiB |
//! | adaptive | [`roi::adaptive::AdaptiveScratch`] | [`roi::adaptive::SCRATCH_BYTES`] = 11 576 | 16 KiB |
//! | WGE | [`roi::wge::WgeScratch`] | [`roi::wge::SCRATCH_BYTES`] = 14 352 | 16 KiB |
//! | DoG | [`roi::dog::DogScratch`] | [`roi::dog::SCRATCH_BYTES`] = 74 296 | 96 KiB |
//! | auto | [`roi::auto::AutoScratch`] | [`roi::auto::SCRATCH_BYTES`] = 25 456 | 32 KiB |
//! | auto-v2 | [`roi::auto::learned::AutoV2Scratch`] | [`roi::auto::learned::SCRATCH_BYTES`] = 48 784 | 48 KiB |
//!
//! The exact figures are printed by `tirroi memory` and listed in `docs/detectors.md`.
//! A sequence tracker ([`roi::track::Tracker`]: `auto-v2` over consecutive frames)
//! keeps its own state beside `auto-v2`'s scratch: [`roi::track::TRACKER_BYTES`] =
//! 8 408 (budget 9 KiB).
//!
//! ## Frame capacity
//!
//! Every scratch is sized by the largest frame it holds, a type parameter
//! [`FrameCapacity`] (the marker [`capacity::Capacity`]`<W, H>`); 328×248
//! ([`Reference`]) is the default, so `OtsuScratch` is `OtsuScratch<Reference>`. A
//! larger frame than the scratch holds is refused with
//! [`DetectError::FrameTooLarge`](roi::DetectError), never cropped. Bytes on x86-64 at
//! the supported capacities of larger cores (`tirroi memory` prints them all):
//!
//! | detector | 328×248 | 640×512 | 1024×768 |
//! |---|---|---|---|
//! | Otsu | 15 224 | 25 696 | 36 064 |
//! | adaptive | 11 576 | 22 496 | 35 936 |
//! | WGE | 14 352 | 24 024 | 35 928 |
//! | DoG | 74 296 | 275 640 | 644 984 |
//! | auto | 25 456 | 66 448 | 136 208 |
//! | auto-v2 | 48 784 | 159 376 | 358 544 |
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
// No `unsafe` anywhere but the Cortex-M4/M7 build's DSP lane operations (inline
// assembly, `roi::auto::learned::lanes`): every other build forbids it.
#![cfg_attr(
    not(all(target_arch = "arm", target_feature = "dsp")),
    forbid(unsafe_code)
)]
#![cfg_attr(all(target_arch = "arm", target_feature = "dsp"), deny(unsafe_code))]
#![deny(missing_docs)]

pub mod capacity;
pub mod frame;
#[cfg(feature = "spi")]
pub mod link;
pub mod roi;
pub mod sensor;

pub use capacity::{Capacity, FrameCapacity, Reference};
pub use frame::{Frame, FrameError};
pub use roi::{BoxRule, DetectError, Detection, Detector, Method, Roi, SCORE_FULL_PERMILLE};
