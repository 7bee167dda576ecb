//! Borrowed, validated views of camera frames of digital numbers (DN).
//!
//! A [`Frame`] is checked once when it is built (dimensions, length, bit depth), like
//! smoltcp's `check_len`; every accessor after that is infallible, so flight code can
//! hand the detectors a DMA buffer without copying it.

use core::fmt;
use core::slice::ChunksExact;

/// Width of the reference sensor (Hayabusa2 TIR, paper Table 4), in pixels.
pub const FRAME_WIDTH: usize = 328;
/// Height of the reference sensor (Hayabusa2 TIR, paper Table 4), in pixels.
pub const FRAME_HEIGHT: usize = 248;
/// Pixels in a full reference frame (328 × 248 = 81 344).
pub const FRAME_PIXELS: usize = FRAME_WIDTH * FRAME_HEIGHT;
/// Default bit depth of a DN: 14 bits, DN 0..=16383 (the project's convention; the
/// host reads a 16-bit PNG whose values fit as 14-bit DN).
pub const DEFAULT_BIT_DEPTH: u8 = 14;
/// Largest frame side a [`Frame`] accepts, pixels (box coordinates are `u16`). The
/// detectors hold less: each refuses a frame above its scratch's capacity
/// ([`crate::roi::DetectError::FrameTooLarge`], [`crate::capacity`]).
pub const MAX_FRAME_SIDE: usize = u16::MAX as usize - 1;
/// Largest supported bit depth: a DN is a `u16`.
pub const MAX_BIT_DEPTH: u8 = 16;

/// Why a slice of DN could not be viewed as a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// Width or height is zero.
    ZeroSize,
    /// Width or height exceeds [`MAX_FRAME_SIDE`] (a detector's own capacity is
    /// checked when it runs: [`crate::roi::DetectError::FrameTooLarge`]).
    TooLarge {
        /// Requested width in pixels.
        width: usize,
        /// Requested height in pixels.
        height: usize,
    },
    /// The slice does not hold `width × height` DN.
    WrongLength {
        /// `width × height`.
        expected: usize,
        /// Length of the slice that was given.
        actual: usize,
    },
    /// Bit depth outside 1..=16.
    BadBitDepth(u8),
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            FrameError::ZeroSize => write!(f, "frame width and height must be at least 1 pixel"),
            FrameError::TooLarge { width, height } => write!(
                f,
                "frame is {width}x{height} px, a side above {MAX_FRAME_SIDE} px"
            ),
            FrameError::WrongLength { expected, actual } => write!(
                f,
                "frame buffer holds {actual} DN, expected width x height = {expected}"
            ),
            FrameError::BadBitDepth(b) => {
                write!(f, "bit depth {b} is outside 1..={MAX_BIT_DEPTH}")
            }
        }
    }
}

/// A row-major frame of DN borrowed from the caller, at most [`MAX_FRAME_SIDE`] pixels
/// a side (the detectors check their own capacity, 328×248 by default).
///
/// Pixel (x, y) is `pixels()[y * width + x]`, x right and y down. DN above
/// [`Frame::max_dn`] are not rejected (that would cost a pass over the frame); every
/// detector treats them as saturated, i.e. clamps them to `max_dn`.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a> {
    pixels: &'a [u16],
    width: usize,
    height: usize,
    bits: u8,
}

impl<'a> Frame<'a> {
    /// Views `pixels` as a `width` × `height` frame of `bits`-bit DN.
    ///
    /// # Errors
    /// [`FrameError`] when a dimension is zero or too large, the length is not
    /// `width × height`, or `bits` is not in 1..=16.
    pub fn new(
        pixels: &'a [u16],
        width: usize,
        height: usize,
        bits: u8,
    ) -> Result<Self, FrameError> {
        if width == 0 || height == 0 {
            return Err(FrameError::ZeroSize);
        }
        if width > MAX_FRAME_SIDE || height > MAX_FRAME_SIDE {
            return Err(FrameError::TooLarge { width, height });
        }
        if bits == 0 || bits > MAX_BIT_DEPTH {
            return Err(FrameError::BadBitDepth(bits));
        }
        let expected = width * height;
        if pixels.len() != expected {
            return Err(FrameError::WrongLength {
                expected,
                actual: pixels.len(),
            });
        }
        Ok(Frame {
            pixels,
            width,
            height,
            bits,
        })
    }

    /// Views a full 328 × 248 reference frame at the default 14-bit depth.
    ///
    /// # Errors
    /// [`FrameError::WrongLength`] unless `pixels.len() == 81 344`.
    pub fn reference(pixels: &'a [u16]) -> Result<Self, FrameError> {
        Self::new(pixels, FRAME_WIDTH, FRAME_HEIGHT, DEFAULT_BIT_DEPTH)
    }

    /// Width in pixels (1..=[`MAX_FRAME_SIDE`]).
    pub const fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels (1..=[`MAX_FRAME_SIDE`]).
    pub const fn height(&self) -> usize {
        self.height
    }

    /// Bit depth of a DN (1..=16).
    pub const fn bits(&self) -> u8 {
        self.bits
    }

    /// Largest valid DN, `2^bits − 1` (saturation).
    pub const fn max_dn(&self) -> u16 {
        ((1u32 << self.bits) - 1) as u16
    }

    /// All DN, row-major, `width × height` of them.
    pub const fn pixels(&self) -> &'a [u16] {
        self.pixels
    }

    /// The rows, top to bottom, each `width` DN long.
    pub fn rows(&self) -> ChunksExact<'a, u16> {
        // `width ≥ 1` by `new`; `max(1)` says so to the compiler, which then drops
        // `chunks_exact`'s zero-size panic from the flight build.
        self.pixels.chunks_exact(self.width.max(1))
    }

    /// Row `y`, or `None` when `y >= height`.
    pub fn row(&self, y: usize) -> Option<&'a [u16]> {
        let start = y.checked_mul(self.width)?;
        self.pixels.get(start..start + self.width)
    }
}
