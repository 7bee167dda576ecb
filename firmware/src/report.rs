//! What the demo reports: one [`Event`] per step, printed as one line of
//! `key=value` fields (scripts/flight.sh parses them).

use core::fmt;

use tirroi_core::{Method, Roi};

/// What a [`crate::Meter`] measured for one step.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct MeterReading {
    /// Instructions executed, when counted.
    pub instructions: Option<u64>,
    /// Deepest stack use below the caller's stack pointer, bytes, when measured.
    pub stack_bytes: Option<u32>,
}

/// The suffix of a `detect` line's method: `+sequence` for a step of the sequence
/// tracker, `+prior` for a tracking call, none for a whole-frame search.
fn call_suffix(prior: &Option<Roi>, sequence: bool) -> &'static str {
    if sequence {
        "+sequence"
    } else if prior.is_some() {
        "+prior"
    } else {
        ""
    }
}

/// One step of the demo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// The demo starts.
    Start {
        /// Embedded frames.
        frames: usize,
        /// Methods run on each frame.
        methods: usize,
    },
    /// A detector's scratch memory on this target.
    Memory {
        /// The detector.
        method: Method,
        /// Bytes of its `Scratch` on this target ([`Method::scratch_bytes`]).
        scratch_bytes: usize,
    },
    /// A frame came in over the SPI link.
    Link {
        /// Frame name.
        frame: &'static str,
        /// Rows received.
        rows: u16,
        /// Rows that had to be re-requested (bad checksum or sync).
        retries: u16,
        /// Cost of the whole frame transfer (the simulated camera included).
        meter: MeterReading,
    },
    /// A detector ran on a frame.
    Detect {
        /// Frame name.
        frame: &'static str,
        /// The detector.
        method: Method,
        /// The tracking prior it was given (the trackers, `auto` and `auto-v2`, only),
        /// `None` for a full-frame search.
        prior: Option<Roi>,
        /// A step of `auto-v2`'s sequence tracker (`roi::track::Tracker`, over the
        /// demo's frames in order), not a single call.
        sequence: bool,
        /// Its box, `None` when nothing was foreground.
        roi: Option<Roi>,
        /// Foreground pixels of its mask.
        foreground_px: u32,
        /// IoU against the renderer's truth box, when the frame has one.
        iou: Option<f32>,
        /// Instructions and stack of the call.
        meter: MeterReading,
    },
    /// The camera model made a frame on board.
    Sensor {
        /// FNV-1a of the frame's DN ([`crate::synth::checksum`]).
        checksum: u64,
        /// Building the band-radiance quadrature and table.
        setup: MeterReading,
        /// Band radiance of every pixel from the table (the first stage of `expose`).
        radiance: MeterReading,
        /// The DN map + noise pass alone over a frame (the second stage of `expose`).
        dn_noise: MeterReading,
        /// Radiance, DN and noise for the whole frame.
        expose: MeterReading,
    },
    /// A step failed; the demo goes on with the next.
    Error {
        /// Frame name.
        frame: &'static str,
        /// What failed.
        what: &'static str,
    },
    /// The demo is over.
    Done,
}

impl Event {
    /// True for [`Event::Error`].
    pub fn is_error(&self) -> bool {
        matches!(self, Event::Error { .. })
    }
}

struct Opt<T>(Option<T>);

impl<T: fmt::Display> fmt::Display for Opt<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Some(v) => v.fmt(f),
            None => f.write_str("-"),
        }
    }
}

impl fmt::Display for MeterReading {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "insns={} stack={}",
            Opt(self.instructions),
            Opt(self.stack_bytes)
        )
    }
}

impl fmt::Display for Event {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Event::Start { frames, methods } => {
                write!(f, "start frames={frames} methods={methods}")
            }
            Event::Memory {
                method,
                scratch_bytes,
            } => write!(f, "memory method={method} scratch={scratch_bytes}"),
            Event::Link {
                frame,
                rows,
                retries,
                meter,
            } => write!(
                f,
                "link frame={frame} rows={rows} retries={retries} {meter}"
            ),
            Event::Detect {
                frame,
                method,
                prior,
                sequence,
                roi,
                foreground_px,
                iou,
                meter,
            } => {
                write!(f, "detect frame={frame} method={method}")?;
                f.write_str(call_suffix(&prior, sequence))?;
                f.write_str(" box=")?;
                match roi {
                    Some(r) => write!(f, "{},{},{},{}", r.x0, r.y0, r.x1, r.y1)?,
                    None => f.write_str("none")?,
                }
                write!(f, " fg={foreground_px} iou=")?;
                match iou {
                    Some(v) => write!(f, "{v:.3}")?,
                    None => f.write_str("-")?,
                }
                write!(f, " {meter}")
            }
            Event::Sensor {
                checksum,
                setup,
                radiance,
                dn_noise,
                expose,
            } => write!(
                f,
                "sensor checksum={checksum:016x} setup_insns={} setup_stack={} radiance_insns={} dn_noise_insns={} expose_insns={} expose_stack={}",
                Opt(setup.instructions),
                Opt(setup.stack_bytes),
                Opt(radiance.instructions),
                Opt(dn_noise.instructions),
                Opt(expose.instructions),
                Opt(expose.stack_bytes)
            ),
            Event::Error { frame, what } => write!(f, "error frame={frame} what={what:?}"),
            Event::Done => f.write_str("done"),
        }
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for MeterReading {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "insns={=?} stack={=?}",
            self.instructions,
            self.stack_bytes
        );
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Event {
    fn format(&self, f: defmt::Formatter<'_>) {
        match *self {
            Event::Start { frames, methods } => {
                defmt::write!(f, "start frames={=usize} methods={=usize}", frames, methods)
            }
            Event::Memory {
                method,
                scratch_bytes,
            } => defmt::write!(
                f,
                "memory method={=str} scratch={=usize}",
                method.name(),
                scratch_bytes
            ),
            Event::Link {
                frame,
                rows,
                retries,
                meter,
            } => defmt::write!(
                f,
                "link frame={=str} rows={=u16} retries={=u16} {}",
                frame,
                rows,
                retries,
                meter
            ),
            Event::Detect {
                frame,
                method,
                prior,
                sequence,
                roi,
                foreground_px,
                iou,
                meter,
            } => {
                let b = roi.map(|r| [r.x0, r.y0, r.x1, r.y1]);
                defmt::write!(
                    f,
                    "detect frame={=str} method={=str}{=str} box={=?} fg={=u32} iou={=?} {}",
                    frame,
                    method.name(),
                    call_suffix(&prior, sequence),
                    b,
                    foreground_px,
                    iou,
                    meter
                )
            }
            Event::Sensor {
                checksum,
                setup,
                radiance,
                dn_noise,
                expose,
            } => defmt::write!(
                f,
                "sensor checksum={=u64:x} setup={} radiance={} dn_noise={} expose={}",
                checksum,
                setup,
                radiance,
                dn_noise,
                expose
            ),
            Event::Error { frame, what } => {
                defmt::write!(f, "error frame={=str} what={=str}", frame, what)
            }
            Event::Done => defmt::write!(f, "done"),
        }
    }
}
