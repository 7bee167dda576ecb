//! # tirroi-firmware
//!
//! The flight demo's workload, the same on the emulated Cortex-M7 (`src/main.rs`) and
//! on the host (`examples/host.rs`, the reference the firmware's boxes are compared
//! with and the program callgrind counts x86 instructions in):
//!
//! 1. every embedded frame ([`frames::FRAMES`], rendered by the host) is streamed in
//!    through the SPI frame link of the core ([`tirroi_core::link`]) from a simulated
//!    camera into the one frame buffer, with one corrupted row to show a retry;
//! 2. every detector of the core runs on it ([`detectors::Detectors`]), then the
//!    trackers (`auto`, `auto-v2`) in tracking mode, each with its own box as the prior,
//!    and `auto-v2`'s sequence tracker steps on to it ([`tirroi_core::roi::track`]: the
//!    frames taken as one sequence, so every step searches and registers the ground);
//! 3. the camera model makes a frame on board ([`synth`]: band radiance table, DN map,
//!    noise, row by row into the same buffer), and the detectors run on that too.
//!
//! Each step is measured by a [`Meter`] (instructions and stack depth on the target,
//! nothing on the host) and reported as an [`Event`], one text line each.
#![no_std]
#![deny(missing_docs)]

pub mod adversarial;
pub mod detectors;
pub mod frames;
pub mod report;
pub mod synth;
#[cfg(all(target_arch = "arm", target_os = "none"))]
pub mod systick;

use core::hint::black_box;

use tirroi_core::frame::{DEFAULT_BIT_DEPTH, FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};
use tirroi_core::link::{FrameReader, SimulatedCamera};
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::{Frame, Method};

pub use detectors::{DEMO_METHODS, Detectors};
pub use report::{Event, MeterReading};

/// Bit depth of every frame of the demo (the renderer's and the camera's): the core's
/// default.
pub const BITS: u8 = DEFAULT_BIT_DEPTH;

/// The embedded frame whose row [`RETRY_ROW`] the simulated camera corrupts once, so
/// the link has to re-request it.
pub const RETRY_FRAME: usize = 1;
/// See [`RETRY_FRAME`].
pub const RETRY_ROW: u16 = 100;

/// Measures one step: instructions and stack depth on the target.
pub trait Meter {
    /// Prepares the measurement (e.g. paints the free stack) and starts counting.
    /// Called right before the measured call, from the same stack frame.
    fn start(&mut self);
    /// Stops counting and returns what was measured since [`Meter::start`].
    fn stop(&mut self) -> MeterReading;
}

/// A [`Meter`] that measures nothing (the host reference).
#[derive(Debug, Default, Clone, Copy)]
pub struct NoMeter;

impl Meter for NoMeter {
    fn start(&mut self) {}
    fn stop(&mut self) -> MeterReading {
        MeterReading::default()
    }
}

/// Everything the demo needs besides the code: one frame buffer, the detectors'
/// scratch memory and the camera model's tables, borrowed from the caller (statics on
/// the target, so each lands in `.bss` or `.data` and is counted in the ELF's sizes).
pub struct Workspace<'a> {
    /// The one frame buffer, row-major DN (162 688 bytes).
    pub frame: &'a mut [u16; FRAME_PIXELS],
    /// The detectors with their scratch memory.
    pub detectors: &'a mut Detectors,
    /// The camera model's tables (built on board by [`synth::setup`]).
    pub tables: &'a mut synth::Tables,
}

/// Pixel pairs [`run_demo`] checks the core's lane operations on before the frames
/// (`lanes::self_check`, outside every meter): edge and random values of both lanes.
const LANE_CHECK_WORDS: u32 = 4096;

/// Runs the whole demo and hands each [`Event`] to `emit`, in order.
pub fn run_demo<M: Meter>(ws: &mut Workspace<'_>, meter: &mut M, emit: &mut dyn FnMut(&Event)) {
    emit(&Event::Start {
        frames: frames::FRAMES.len(),
        methods: DEMO_METHODS.len(),
    });
    // The core's DSP lane operations (`auto-v2`'s cell plane; inline assembly on a
    // Cortex-M4/M7) against per-lane arithmetic, where no unit test runs.
    if !tirroi_core::roi::auto::learned::lanes::self_check(LANE_CHECK_WORDS) {
        emit(&Event::Error {
            frame: "-",
            what: "lane operations differ from per-lane arithmetic",
        });
    }
    for &method in DEMO_METHODS {
        emit(&Event::Memory {
            method,
            scratch_bytes: method.scratch_bytes(),
        });
    }
    for (index, embedded) in frames::FRAMES.iter().enumerate() {
        let Ok(mut camera) = SimulatedCamera::new(embedded.be_bytes, FRAME_WIDTH, FRAME_HEIGHT)
        else {
            emit(&Event::Error {
                frame: embedded.name,
                what: "embedded frame is not 328x248 DN",
            });
            continue;
        };
        if index == RETRY_FRAME {
            camera.corrupt_row_once(RETRY_ROW);
        }
        meter.start();
        let read = black_box(receive_frame(camera, ws.frame));
        let reading = meter.stop();
        match read {
            Ok(stats) => emit(&Event::Link {
                frame: embedded.name,
                rows: stats.rows,
                retries: stats.retries,
                meter: reading,
            }),
            Err(_) => {
                emit(&Event::Error {
                    frame: embedded.name,
                    what: "SPI frame link failed",
                });
                continue;
            }
        }
        detect_all(ws, embedded.name, Some(embedded.truth), meter, emit);
    }

    // The camera model on board: tables, the radiance and the DN + noise passes alone
    // (to count each), then a frame of radiance → DN + noise.
    meter.start();
    synth::setup(ws);
    let setup = meter.stop();
    meter.start();
    let radiance = black_box(synth::radiance_only(ws));
    let radiance_meter = meter.stop();
    meter.start();
    let dn_noise = black_box(synth::dn_noise_only(ws));
    let dn_noise_meter = meter.stop();
    meter.start();
    let made = black_box(synth::expose_scene(ws));
    let expose = meter.stop();
    match made.and(radiance).and(dn_noise) {
        Ok(()) => {
            emit(&Event::Sensor {
                checksum: synth::checksum(&ws.frame[..]),
                setup,
                radiance: radiance_meter,
                dn_noise: dn_noise_meter,
                expose,
            });
            detect_all(ws, synth::NAME, None, meter, emit);
        }
        Err(_) => emit(&Event::Error {
            frame: synth::NAME,
            what: "camera model refused its input",
        }),
    }
    emit(&Event::Done);
}

/// Streams one frame from `camera` into `frame` through the core's SPI frame reader.
/// Never inlined, so that its stack is measured as its own.
#[inline(never)]
fn receive_frame(
    camera: SimulatedCamera<'_>,
    frame: &mut [u16; FRAME_PIXELS],
) -> Result<tirroi_core::link::ReadStats, tirroi_core::link::LinkError<tirroi_core::link::SimError>>
{
    FrameReader::new(camera).read_frame(&mut frame[..], FRAME_WIDTH, FRAME_HEIGHT)
}

/// Runs every method of [`DEMO_METHODS`] on the frame in `ws.frame`.
fn detect_all<M: Meter>(
    ws: &mut Workspace<'_>,
    name: &'static str,
    truth: Option<tirroi_core::Roi>,
    meter: &mut M,
    emit: &mut dyn FnMut(&Event),
) {
    let Workspace {
        frame, detectors, ..
    } = ws;
    let frame: &[u16] = &frame[..];
    let frame = match Frame::new(frame, FRAME_WIDTH, FRAME_HEIGHT, BITS) {
        Ok(frame) => frame,
        Err(_) => {
            emit(&Event::Error {
                frame: name,
                what: "frame does not fit the bit depth",
            });
            return;
        }
    };
    // Each tracker's box, the prior of its tracking call below.
    let mut priors = [(Method::Auto, None), (Method::AutoV2, None)];
    for &method in DEMO_METHODS {
        meter.start();
        let result = black_box(detectors.run(method, &frame));
        let reading = meter.stop();
        let found = report_detection(emit, name, method, None, truth, result, reading);
        if let Some((_, prior)) = priors.iter_mut().find(|(m, _)| *m == method) {
            *prior = found;
        }
    }
    // Tracking: each tracker again, given its own box as the last frame's (and, for
    // `auto-v2`, that box's look, taken as a tracker takes it after each frame:
    // counted with the call).
    for (method, prior) in priors {
        let Some(prior) = prior else { continue };
        meter.start();
        let look = Look::measure(&frame, prior);
        let result = black_box(detectors.track(method, prior, look, &frame));
        let reading = meter.stop();
        report_detection(emit, name, method, Some(prior), truth, result, reading);
    }
    // The sequence tracker's step on this frame, the demo's frames taken as one
    // sequence: unrelated frames, so the last box is refused and each step pays the
    // search, the ground's registration and the candidate's refinement (a tracker
    // acquiring, not one locked on).
    meter.start();
    let result = black_box(detectors.sequence_step(&frame));
    let reading = meter.stop();
    report_call(
        emit,
        name,
        Method::AutoV2,
        (None, true),
        truth,
        result,
        reading,
    );
}

/// Emits the event of one detector call; returns its box.
fn report_detection(
    emit: &mut dyn FnMut(&Event),
    frame: &'static str,
    method: Method,
    prior: Option<tirroi_core::Roi>,
    truth: Option<tirroi_core::Roi>,
    result: Result<tirroi_core::Detection, tirroi_core::DetectError>,
    meter: MeterReading,
) -> Option<tirroi_core::Roi> {
    report_call(emit, frame, method, (prior, false), truth, result, meter)
}

/// Emits the event of one call (`(prior, sequence)`: its tracking prior, and whether
/// it was a step of the sequence tracker); returns its box.
fn report_call(
    emit: &mut dyn FnMut(&Event),
    frame: &'static str,
    method: Method,
    (prior, sequence): (Option<tirroi_core::Roi>, bool),
    truth: Option<tirroi_core::Roi>,
    result: Result<tirroi_core::Detection, tirroi_core::DetectError>,
    meter: MeterReading,
) -> Option<tirroi_core::Roi> {
    match result {
        Ok(detection) => {
            emit(&Event::Detect {
                frame,
                method,
                prior,
                sequence,
                roi: detection.roi,
                foreground_px: detection.foreground_px,
                iou: truth.map(|t| detection.roi.map_or(0.0, |r| r.iou(&t))),
                meter,
            });
            detection.roi
        }
        Err(_) => {
            emit(&Event::Error {
                frame,
                what: "detector refused its parameters",
            });
            None
        }
    }
}
