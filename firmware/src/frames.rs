//! The frames the demo embeds in flash, rendered by the host (`scripts/flight-frames.sh`
//! from `firmware/frames.toml`): deep space, the Earth behind, a multi-material target
//! in eclipse, detection mode at Scale 2, far range (400 m) and the Tango-like satellite.
//! `build.rs` embeds `frames/*.png` as big-endian DN, the byte order of the SPI link.

use tirroi_core::Roi;

/// One embedded 328×248 frame.
#[derive(Debug, Clone, Copy)]
pub struct EmbeddedFrame {
    /// The scene kind (the PNG's file stem).
    pub name: &'static str,
    /// The renderer's truth box.
    pub truth: Roi,
    /// DN as big-endian `u16`, row-major, 328 × 248 × 2 bytes.
    pub be_bytes: &'static [u8],
}

include!(concat!(env!("OUT_DIR"), "/frames.rs"));
