//! Frame input over SPI: a framed, checksummed row protocol, a [`FrameReader`] generic
//! over [`embedded_hal::spi::SpiDevice`], and a [`SimulatedCamera`] that speaks the
//! camera side of the protocol (hardware-in-the-loop, ground tests, firmware demo).
//!
//! Only with the cargo feature `spi` (on by default). No heap, no `unsafe`, no panic on
//! any reply: every malformed reply is a [`LinkError`].
//!
//! # Framing
//!
//! **All multi-byte fields are big-endian** (most significant byte first on the wire),
//! whatever the byte order of the processor: one flight target, SPARC LEON3, is
//! big-endian, the Cortex-M targets are little-endian, and both read the same bytes.
//!
//! The reader is the SPI master. It fetches a frame row by row, top (y = 0) to bottom,
//! with **one** [`SpiDevice::transaction`] per row (chip select held for the whole
//! exchange): `[Operation::Write(&request), Operation::Read(&mut reply)]`.
//!
//! Request, master → camera, [`REQUEST_BYTES`] = 3 bytes:
//!
//! | offset | bytes | field | value |
//! |---|---|---|---|
//! | 0 | 1 | command | [`CMD_READ_ROW`] = `0x52` (ASCII `R`) |
//! | 1 | 2 | row | u16 big-endian, 0-based row index y |
//!
//! Reply, camera → master, clocked in the same transaction. The master reads
//! [`row_bytes`]`(W)` = `8 + 2·W` bytes, W being the row width it expects; the camera
//! sends a row of `n` pixels:
//!
//! | offset | bytes | field | value |
//! |---|---|---|---|
//! | 0 | 2 | sync | [`SYNC`] = `0x54 0x52` (ASCII `TR`) |
//! | 2 | 2 | row | u16 big-endian, the row index this reply holds |
//! | 4 | 2 | width | u16 big-endian, `n`: pixels in this reply, as sent by the camera |
//! | 6 | 2·n | pixels | `n` DN, u16 big-endian each, x = 0, 1, …, n − 1 |
//! | 6 + 2·n | 2 | crc | u16 big-endian, CRC-16/CCITT-FALSE of bytes `0 .. 6 + 2·n` |
//!
//! A well-formed reply has `n = W` and is exactly `row_bytes(W)` bytes long
//! ([`ROW_OVERHEAD_BYTES`] = 8 bytes of sync, row, width and CRC around the pixels).
//! When `n < W` the bytes after the CRC are clocked out but ignored
//! ([`SimulatedCamera`] sends [`FILL_BYTE`]).
//!
//! CRC-16/CCITT-FALSE (catalogued as `CRC_16_IBM_3740`): polynomial `0x1021`, initial
//! value `0xFFFF`, no reflection, no final XOR; check value `0x29B1` for the ASCII bytes
//! `123456789`. It is computed with a 256-entry table of `u16` (the `crc` crate's
//! `Table<1>`), one lookup per byte: [`CRC_TABLE_BYTES`] = 512 bytes of read-only data,
//! held once in a `static` of 516 bytes on 32-bit targets (table + a pointer to the
//! crate's algorithm descriptor; 520 bytes on 64-bit hosts). The table-less variant
//! would save those bytes at 8 shift/XOR steps per byte (5 312 per 328-pixel row).
//!
//! # Checks on a reply, in order
//!
//! 1. sync ≠ [`SYNC`] → [`LinkError::Sync`] (framing lost);
//! 2. width `n` > W → [`LinkError::LongRow`] (its CRC lies beyond the bytes read, so
//!    the reply cannot be verified);
//! 3. CRC at offset `6 + 2·n` ≠ CRC of bytes `0 .. 6 + 2·n` → [`LinkError::Checksum`];
//! 4. row ≠ requested row → [`LinkError::RowMismatch`];
//! 5. `n` < W → [`LinkError::ShortRow`].
//!
//! Errors 1–3 say the reply could not be verified (a bit error on the wire looks like
//! one of them), so the reader re-requests the row, up to [`FrameReader::with_retries`]
//! times (default [`DEFAULT_RETRIES`] = 2), before it returns the last error. Errors 4
//! and 5 come from a reply whose CRC checked out: the camera really sent that, asking
//! again would get the same answer, so they are returned at once. An SPI error
//! ([`LinkError::Spi`]) is returned at once as well.
//!
//! # Memory
//!
//! [`FrameReader`] owns its row buffer: [`MAX_ROW_BYTES`] = 664 bytes, plus one byte of
//! retry count and the `SpiDevice` itself (665 bytes with a zero-sized device). It writes
//! the pixels of each verified row straight into the caller's frame, so no frame-sized
//! buffer is needed beyond the caller's. [`SimulatedCamera`] borrows its frame and
//! holds a 32-byte fault-injection bit set: 48 bytes on 32-bit targets, 56 on 64-bit.
//!
//! # Example
//!
//! ```
//! use tirroi_core::link::{FrameReader, SimulatedCamera, pixels_to_be};
//!
//! let pixels: [u16; 6] = [0, 1, 16383, 42, 7, 65535]; // a 3 × 2 frame
//! let mut wire = [0u8; 12];
//! pixels_to_be(&pixels, &mut wire)?;
//! let mut camera = SimulatedCamera::new(&wire, 3, 2)?;
//! camera.corrupt_row_once(1); // one bit error on the wire: row 1 is asked for twice
//!
//! let mut reader = FrameReader::new(camera);
//! let mut frame = [0u16; 6];
//! let stats = reader.read_frame(&mut frame, 3, 2)?;
//! assert_eq!((stats.rows, stats.retries), (2, 1));
//! assert_eq!(frame, pixels);
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```

use core::convert::Infallible;
use core::fmt;
use core::iter;

use crc::{CRC_16_IBM_3740, Crc, Table};
use embedded_hal::spi::{self, ErrorType, Operation, SpiDevice};

use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};

/// Command byte of a row request: `0x52` (ASCII `R`), first byte of every request.
pub const CMD_READ_ROW: u8 = 0x52;
/// Bytes of a row request: command, row (u16 big-endian).
pub const REQUEST_BYTES: usize = 3;
/// Sync word that opens every row reply: `0x54 0x52` (ASCII `TR`).
pub const SYNC: [u8; 2] = [0x54, 0x52];
/// Bytes of a reply's header: sync (2), row (2), width (2).
pub const HEADER_BYTES: usize = 6;
/// Bytes of a reply's trailing CRC-16.
pub const CRC_BYTES: usize = 2;
/// Bytes of a reply beyond its pixels: header (6) + CRC (2) = 8.
pub const ROW_OVERHEAD_BYTES: usize = HEADER_BYTES + CRC_BYTES;
/// Widest row the reader accepts, in pixels: the reference sensor's 328
/// ([`FRAME_WIDTH`]).
pub const MAX_WIDTH: usize = FRAME_WIDTH;
/// Most rows the reader accepts per frame: the reference sensor's 248
/// ([`FRAME_HEIGHT`]).
pub const MAX_HEIGHT: usize = FRAME_HEIGHT;
/// Bytes of a reply of [`MAX_WIDTH`] pixels: `row_bytes(328)` = 664; the size of
/// [`FrameReader`]'s row buffer.
pub const MAX_ROW_BYTES: usize = row_bytes(MAX_WIDTH);
/// Re-requests of an unverifiable row before [`FrameReader::read_frame`] gives up,
/// unless set with [`FrameReader::with_retries`]: 2 (so at most 3 transfers per row).
pub const DEFAULT_RETRIES: u8 = 2;
/// Byte [`SimulatedCamera`] clocks out after a reply's CRC when the master reads more.
pub const FILL_BYTE: u8 = 0xFF;
/// Read-only data of the CRC-16 table: 256 entries × 2 bytes = 512 bytes.
pub const CRC_TABLE_BYTES: usize = 256 * 2;

/// The row checksum: CRC-16/CCITT-FALSE with one 256-entry table ([`CRC_TABLE_BYTES`]).
/// A `static`, not a `const`, so the table exists once in read-only data.
static CRC16: Crc<u16, Table<1>> = Crc::<u16, Table<1>>::new(&CRC_16_IBM_3740);

/// Bytes of a reply carrying `width` pixels: `8 + 2 · width` (header, pixels, CRC).
///
/// Saturates at `usize::MAX` instead of overflowing, so it never panics.
pub const fn row_bytes(width: usize) -> usize {
    width.saturating_mul(2).saturating_add(ROW_OVERHEAD_BYTES)
}

/// CRC-16/CCITT-FALSE of `bytes` (poly `0x1021`, init `0xFFFF`, no reflection, no final
/// XOR), the checksum of the row framing; `0x29B1` for ASCII `123456789`.
pub fn crc16(bytes: &[u8]) -> u16 {
    CRC16.checksum(bytes)
}

/// Why a frame (or a row) could not be read or encoded.
///
/// `E` is the SPI device's error type; functions that do no SPI use
/// [`Infallible`]. Row indices are 0-based, widths are in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkError<E> {
    /// The SPI device failed; returned at once, without retry.
    Spi(E),
    /// Bad sizes, checked before any SPI traffic: the frame buffer's length is not
    /// `width × height`, width is not in 1..=[`MAX_WIDTH`], or height is not in
    /// 1..=[`MAX_HEIGHT`]; for [`encode_row`], more than [`MAX_WIDTH`] pixels or an
    /// output buffer shorter than [`row_bytes`]; for [`SimulatedCamera::new`], a byte
    /// slice that is not `2 × width × height` long.
    Size,
    /// The reply for `row` did not start with [`SYNC`] (on every try).
    Sync {
        /// Requested row.
        row: u16,
    },
    /// A reply with a valid CRC held another row than the one requested.
    RowMismatch {
        /// Requested row.
        expected: u16,
        /// Row index in the reply.
        got: u16,
    },
    /// A reply with a valid CRC held fewer pixels than the frame width.
    ShortRow {
        /// Requested row.
        row: u16,
        /// Pixels in the reply (its width field).
        pixels: u16,
    },
    /// A reply's width field announced more pixels than the frame width (on every try).
    LongRow {
        /// Requested row.
        row: u16,
        /// Pixels announced by the reply (its width field).
        pixels: u16,
    },
    /// The reply's CRC did not match its content (on every try).
    Checksum {
        /// Requested row.
        row: u16,
        /// CRC carried by the reply.
        expected: u16,
        /// CRC computed over the reply's header and pixels.
        computed: u16,
    },
}

impl<E> LinkError<E> {
    /// `true` for the errors of an unverifiable reply ([`Sync`](Self::Sync),
    /// [`LongRow`](Self::LongRow), [`Checksum`](Self::Checksum)), which the reader
    /// re-requests before returning them.
    pub const fn is_retryable(&self) -> bool {
        matches!(
            self,
            LinkError::Sync { .. } | LinkError::LongRow { .. } | LinkError::Checksum { .. }
        )
    }
}

impl LinkError<Infallible> {
    /// The same error with any SPI error type (this one holds no SPI error).
    pub fn widen<E>(self) -> LinkError<E> {
        match self {
            LinkError::Spi(never) => match never {},
            LinkError::Size => LinkError::Size,
            LinkError::Sync { row } => LinkError::Sync { row },
            LinkError::RowMismatch { expected, got } => LinkError::RowMismatch { expected, got },
            LinkError::ShortRow { row, pixels } => LinkError::ShortRow { row, pixels },
            LinkError::LongRow { row, pixels } => LinkError::LongRow { row, pixels },
            LinkError::Checksum {
                row,
                expected,
                computed,
            } => LinkError::Checksum {
                row,
                expected,
                computed,
            },
        }
    }
}

impl<E: fmt::Debug> fmt::Display for LinkError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinkError::Spi(e) => write!(f, "SPI error: {e:?}"),
            LinkError::Size => write!(
                f,
                "bad size: frame must be width x height DN with width 1..={MAX_WIDTH} and height 1..={MAX_HEIGHT}, buffers at least row_bytes(width)"
            ),
            LinkError::Sync { row } => {
                write!(f, "row {row}: reply does not start with sync 0x5452")
            }
            LinkError::RowMismatch { expected, got } => {
                write!(f, "requested row {expected}, camera sent row {got}")
            }
            LinkError::ShortRow { row, pixels } => {
                write!(
                    f,
                    "row {row}: camera sent {pixels} pixels, fewer than the frame width"
                )
            }
            LinkError::LongRow { row, pixels } => {
                write!(
                    f,
                    "row {row}: camera announced {pixels} pixels, more than the frame width"
                )
            }
            LinkError::Checksum {
                row,
                expected,
                computed,
            } => write!(
                f,
                "row {row}: CRC mismatch, reply carries {expected:#06x}, computed {computed:#06x}"
            ),
        }
    }
}

impl<E: fmt::Debug> core::error::Error for LinkError<E> {}

/// The 6 header bytes of a reply: sync, row, width (big-endian).
fn header(row: u16, width: u16) -> [u8; HEADER_BYTES] {
    let [r0, r1] = row.to_be_bytes();
    let [w0, w1] = width.to_be_bytes();
    [SYNC[0], SYNC[1], r0, r1, w0, w1]
}

/// Writes `pixels` as big-endian bytes (2 per pixel) into the start of `out`; returns
/// the bytes written, `2 × pixels.len()`. Builds the byte frame a [`SimulatedCamera`]
/// serves.
///
/// # Errors
/// [`LinkError::Size`] when `out` is shorter than `2 × pixels.len()` (nothing written).
pub fn pixels_to_be(pixels: &[u16], out: &mut [u8]) -> Result<usize, LinkError<Infallible>> {
    let n = pixels.len().checked_mul(2).ok_or(LinkError::Size)?;
    let out = out.get_mut(..n).ok_or(LinkError::Size)?;
    for (dst, px) in out.chunks_exact_mut(2).zip(pixels) {
        dst.copy_from_slice(&px.to_be_bytes());
    }
    Ok(n)
}

/// Sender side (camera, simulator, ground test): writes one framed row reply for row
/// `row` holding `pixels` (DN, x = 0, 1, …) into the start of `out`, as laid out in
/// the [module docs](self): sync, row, width = `pixels.len()`, pixels, CRC, all
/// big-endian. Returns the bytes written, [`row_bytes`]`(pixels.len())`; the rest of
/// `out` is left untouched. Zero pixels is allowed (an 8-byte reply).
///
/// # Errors
/// [`LinkError::Size`] when `pixels` has more than [`MAX_WIDTH`] pixels or `out` is
/// shorter than `row_bytes(pixels.len())` (nothing written).
pub fn encode_row(
    row: u16,
    pixels: &[u16],
    out: &mut [u8],
) -> Result<usize, LinkError<Infallible>> {
    if pixels.len() > MAX_WIDTH {
        return Err(LinkError::Size);
    }
    let width = u16::try_from(pixels.len()).map_err(|_| LinkError::Size)?;
    let n = row_bytes(pixels.len());
    let out = out.get_mut(..n).ok_or(LinkError::Size)?;
    let (body, crc) = out.split_at_mut(n - CRC_BYTES);
    let (head, payload) = body.split_at_mut(HEADER_BYTES);
    head.copy_from_slice(&header(row, width));
    pixels_to_be(pixels, payload)?;
    crc.copy_from_slice(&crc16(body).to_be_bytes());
    Ok(n)
}

/// Checks one reply of a row expected to be `width` pixels wide, in the order of the
/// module docs. `reply` is the `row_bytes(width)` bytes read.
fn check_reply(reply: &[u8], row: u16, width: usize) -> Result<(), LinkError<Infallible>> {
    let (head, _) = reply
        .split_first_chunk::<HEADER_BYTES>()
        .ok_or(LinkError::Size)?;
    let [s0, s1, r0, r1, w0, w1] = *head;
    if [s0, s1] != SYNC {
        return Err(LinkError::Sync { row });
    }
    let sent = u16::from_be_bytes([w0, w1]);
    let sent_px = usize::from(sent);
    if sent_px > width {
        return Err(LinkError::LongRow { row, pixels: sent });
    }
    let (body, tail) = reply
        .split_at_checked(HEADER_BYTES + 2 * sent_px)
        .ok_or(LinkError::Size)?;
    let carried = tail.first_chunk::<CRC_BYTES>().ok_or(LinkError::Size)?;
    let expected = u16::from_be_bytes(*carried);
    let computed = crc16(body);
    if expected != computed {
        return Err(LinkError::Checksum {
            row,
            expected,
            computed,
        });
    }
    let got = u16::from_be_bytes([r0, r1]);
    if got != row {
        return Err(LinkError::RowMismatch { expected: row, got });
    }
    if sent_px < width {
        return Err(LinkError::ShortRow { row, pixels: sent });
    }
    Ok(())
}

/// What [`FrameReader::read_frame`] did to read a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadStats {
    /// Rows read and written into the frame (the frame's height).
    pub rows: u16,
    /// Re-requests over the whole frame (replies that failed sync, width or CRC and
    /// were asked for again); 0 on a clean link. Saturates at `u16::MAX`.
    pub retries: u16,
}

/// Reads frames row by row from a camera on an SPI bus, with the framing of the
/// [module docs](self).
///
/// Owns the [`SpiDevice`] (chip select included, as embedded-hal 1.0 devices do) and a
/// row buffer of [`MAX_ROW_BYTES`] = 664 bytes: `size_of::<FrameReader<D>>()` is 665
/// bytes plus `size_of::<D>()`, rounded up to `D`'s alignment. Nothing else is
/// allocated; pixels go straight into the caller's frame.
#[derive(Debug)]
pub struct FrameReader<D> {
    spi: D,
    retries: u8,
    buf: [u8; MAX_ROW_BYTES],
}

impl<D: SpiDevice> FrameReader<D> {
    /// A reader that talks to the camera through `spi`, with [`DEFAULT_RETRIES`] = 2
    /// re-requests per unverifiable row.
    pub fn new(spi: D) -> Self {
        FrameReader {
            spi,
            retries: DEFAULT_RETRIES,
            buf: [0; MAX_ROW_BYTES],
        }
    }

    /// Sets how many times a row whose reply fails sync, width or CRC is re-requested
    /// before the error is returned (0..=255; 0 = never, one transfer per row).
    pub fn with_retries(mut self, retries: u8) -> Self {
        self.retries = retries;
        self
    }

    /// Re-requests per unverifiable row (see [`with_retries`](Self::with_retries)).
    pub fn retries(&self) -> u8 {
        self.retries
    }

    /// Streams `height` rows into `frame` (row-major, `width × height` DN, pixel
    /// (x, y) at `y · width + x`), row by row from y = 0, one SPI transaction per row
    /// plus one per retry.
    ///
    /// On error, rows before the failing one have been written; the failing row and
    /// those after it are left as they were.
    ///
    /// # Errors
    /// [`LinkError::Size`] (before any SPI traffic) when width is not in
    /// 1..=[`MAX_WIDTH`], height not in 1..=[`MAX_HEIGHT`], or `frame.len() ≠ width ×
    /// height`; [`LinkError::Spi`] when the device fails; the reply errors of the
    /// [module docs](self) otherwise.
    pub fn read_frame(
        &mut self,
        frame: &mut [u16],
        width: usize,
        height: usize,
    ) -> Result<ReadStats, LinkError<D::Error>> {
        if width == 0 || width > MAX_WIDTH || height == 0 || height > MAX_HEIGHT {
            return Err(LinkError::Size);
        }
        if frame.len() != width * height {
            return Err(LinkError::Size);
        }
        let mut stats = ReadStats::default();
        for (y, out) in frame.chunks_exact_mut(width).enumerate() {
            let row = u16::try_from(y).map_err(|_| LinkError::Size)?;
            let retries = self.read_row(row, out)?;
            stats.rows = row.saturating_add(1);
            stats.retries = stats.retries.saturating_add(u16::from(retries));
        }
        Ok(stats)
    }

    /// Reads row `row` into `out` (`out.len()` = the frame width in pixels), for a
    /// caller that consumes rows as they arrive. Returns the re-requests it took
    /// (0..=[`retries`](Self::retries)). `out` is written only once the reply is
    /// verified.
    ///
    /// # Errors
    /// [`LinkError::Size`] (before any SPI traffic) when `out.len()` is not in
    /// 1..=[`MAX_WIDTH`]; otherwise as [`read_frame`](Self::read_frame).
    pub fn read_row(&mut self, row: u16, out: &mut [u16]) -> Result<u8, LinkError<D::Error>> {
        let width = out.len();
        if width == 0 || width > MAX_WIDTH {
            return Err(LinkError::Size);
        }
        let reply = self
            .buf
            .get_mut(..row_bytes(width))
            .ok_or(LinkError::Size)?;
        let [r0, r1] = row.to_be_bytes();
        let request = [CMD_READ_ROW, r0, r1];
        let mut tries: u8 = 0;
        loop {
            self.spi
                .transaction(&mut [Operation::Write(&request), Operation::Read(&mut *reply)])
                .map_err(LinkError::Spi)?;
            match check_reply(reply, row, width) {
                Ok(()) => break,
                Err(e) if e.is_retryable() && tries < self.retries => tries += 1,
                Err(e) => return Err(e.widen()),
            }
        }
        let payload = reply
            .get(HEADER_BYTES..HEADER_BYTES + 2 * width)
            .ok_or(LinkError::Size)?;
        for (px, bytes) in out.iter_mut().zip(payload.chunks_exact(2)) {
            if let &[hi, lo] = bytes {
                *px = u16::from_be_bytes([hi, lo]);
            }
        }
        Ok(tries)
    }

    /// Gives the SPI device back.
    pub fn release(self) -> D {
        self.spi
    }
}

/// Why [`SimulatedCamera`] refused an SPI transaction (its `SpiDevice` error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimError {
    /// A write that is not a 3-byte [`CMD_READ_ROW`] request.
    BadCommand,
    /// A read in a transaction without a request before it.
    NoCommand,
    /// A request for a row at or beyond the simulated frame's height.
    RowOutOfRange {
        /// Requested row.
        row: u16,
    },
    /// A full-duplex transfer operation, which the protocol does not use.
    Unsupported,
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::BadCommand => write!(
                f,
                "simulated camera: write is not a 3-byte read-row request"
            ),
            SimError::NoCommand => write!(f, "simulated camera: read without a request"),
            SimError::RowOutOfRange { row } => {
                write!(f, "simulated camera: row {row} is outside the frame")
            }
            SimError::Unsupported => {
                write!(
                    f,
                    "simulated camera: full-duplex transfers are not part of the protocol"
                )
            }
        }
    }
}

impl core::error::Error for SimError {}

impl spi::Error for SimError {
    fn kind(&self) -> spi::ErrorKind {
        spi::ErrorKind::Other
    }
}

/// Words of [`SimulatedCamera`]'s fault bit set: one bit per row up to [`MAX_HEIGHT`].
const FAULT_WORDS: usize = MAX_HEIGHT.div_ceil(32);
/// Reply byte [`SimulatedCamera::corrupt_row_once`] damages: the low byte of pixel 0.
const FAULT_BYTE: usize = HEADER_BYTES + 1;
/// Bit flipped in [`FAULT_BYTE`]: bit 0, the pixel's least significant bit.
const FAULT_MASK: u8 = 0x01;

/// A camera on the far side of the SPI link, serving a stored frame with the framing
/// of the [module docs](self): product code for hardware-in-the-loop tests and the
/// firmware demo.
///
/// It borrows the frame as big-endian bytes (2 per pixel, row-major; see
/// [`pixels_to_be`]) and holds a 32-byte fault bit set and a transfer counter. As an
/// [`SpiDevice`] it answers a transaction `[Write(request), Read(reply)…]`: the
/// request selects the row, the reads receive the reply's bytes in order (several
/// reads continue the same reply), then [`FILL_BYTE`] if more is read. A reply shorter
/// than the read (the master expects a wider row) ends early; a longer one is cut.
#[derive(Debug, Clone)]
pub struct SimulatedCamera<'a> {
    frame: &'a [u8],
    width: u16,
    height: u16,
    faults: [u32; FAULT_WORDS],
    transfers: u32,
}

/// The row a transaction of [`SimulatedCamera`] is serving.
struct Serving<'f> {
    head: [u8; HEADER_BYTES],
    payload: &'f [u8],
    crc: [u8; CRC_BYTES],
    corrupt: bool,
    offset: usize,
}

impl<'a> SimulatedCamera<'a> {
    /// A camera serving the `width × height` frame `frame_be` (big-endian DN, 2 bytes
    /// per pixel, row-major).
    ///
    /// # Errors
    /// [`LinkError::Size`] when width is not in 1..=[`MAX_WIDTH`], height not in
    /// 1..=[`MAX_HEIGHT`], or `frame_be.len() ≠ 2 × width × height`.
    pub fn new(
        frame_be: &'a [u8],
        width: usize,
        height: usize,
    ) -> Result<Self, LinkError<Infallible>> {
        if width == 0 || width > MAX_WIDTH || height == 0 || height > MAX_HEIGHT {
            return Err(LinkError::Size);
        }
        if frame_be.len() != 2 * width * height {
            return Err(LinkError::Size);
        }
        Ok(SimulatedCamera {
            frame: frame_be,
            width: u16::try_from(width).map_err(|_| LinkError::Size)?,
            height: u16::try_from(height).map_err(|_| LinkError::Size)?,
            faults: [0; FAULT_WORDS],
            transfers: 0,
        })
    }

    /// Width of the served frame, in pixels.
    pub const fn width(&self) -> usize {
        self.width as usize
    }

    /// Height of the served frame, in rows.
    pub const fn height(&self) -> usize {
        self.height as usize
    }

    /// Row requests served so far (wraps at `u32::MAX`).
    pub const fn transfers(&self) -> u32 {
        self.transfers
    }

    /// Fault injection: the next reply for `row` has bit 0 of its pixel 0 flipped after
    /// the CRC was computed, so the reader sees a CRC error and re-requests the row,
    /// which then comes back intact. Several rows may be pending at once; a row
    /// outside the frame is ignored.
    pub fn corrupt_row_once(&mut self, row: u16) {
        if row < self.height {
            if let Some(word) = self.faults.get_mut(usize::from(row / 32)) {
                *word |= 1 << (row % 32);
            }
        }
    }

    /// Clears and returns the fault bit of `row`.
    fn take_fault(&mut self, row: u16) -> bool {
        match self.faults.get_mut(usize::from(row / 32)) {
            Some(word) => {
                let bit = 1 << (row % 32);
                let set = *word & bit != 0;
                *word &= !bit;
                set
            }
            None => false,
        }
    }

    /// Starts serving `request`.
    fn start(&mut self, request: &[u8]) -> Result<Serving<'a>, SimError> {
        let &[CMD_READ_ROW, r0, r1] = request else {
            return Err(SimError::BadCommand);
        };
        let row = u16::from_be_bytes([r0, r1]);
        if row >= self.height {
            return Err(SimError::RowOutOfRange { row });
        }
        let row_len = 2 * usize::from(self.width);
        let start = usize::from(row) * row_len;
        let payload = self
            .frame
            .get(start..start + row_len)
            .ok_or(SimError::RowOutOfRange { row })?;
        let head = header(row, self.width);
        let mut digest = CRC16.digest();
        digest.update(&head);
        digest.update(payload);
        self.transfers = self.transfers.wrapping_add(1);
        Ok(Serving {
            head,
            payload,
            crc: digest.finalize().to_be_bytes(),
            corrupt: self.take_fault(row),
            offset: 0,
        })
    }
}

impl Serving<'_> {
    /// Clocks the next `buf.len()` bytes of the reply into `buf`.
    fn fill(&mut self, buf: &mut [u8]) {
        let stream = self
            .head
            .iter()
            .chain(self.payload)
            .chain(self.crc.iter())
            .copied()
            .chain(iter::repeat(FILL_BYTE))
            .enumerate()
            .skip(self.offset);
        for (dst, (i, byte)) in buf.iter_mut().zip(stream) {
            *dst = if self.corrupt && i == FAULT_BYTE {
                byte ^ FAULT_MASK
            } else {
                byte
            };
        }
        self.offset = self.offset.saturating_add(buf.len());
    }
}

impl ErrorType for SimulatedCamera<'_> {
    type Error = SimError;
}

impl SpiDevice for SimulatedCamera<'_> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), SimError> {
        let mut serving: Option<Serving<'_>> = None;
        for op in operations.iter_mut() {
            match op {
                Operation::Write(request) => serving = Some(self.start(request)?),
                Operation::Read(buf) => serving.as_mut().ok_or(SimError::NoCommand)?.fill(buf),
                Operation::DelayNs(_) => {}
                Operation::Transfer(..) | Operation::TransferInPlace(..) => {
                    return Err(SimError::Unsupported);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_constants() {
        assert_eq!(ROW_OVERHEAD_BYTES, 8);
        assert_eq!(row_bytes(0), 8);
        assert_eq!(row_bytes(3), 14);
        assert_eq!(MAX_ROW_BYTES, 664);
        assert_eq!(row_bytes(usize::MAX), usize::MAX);
        assert_eq!(core::mem::size_of::<FrameReader<()>>(), 665);
        assert_eq!(core::mem::size_of_val(CRC16.table()), CRC_TABLE_BYTES);
        assert_eq!(CRC_TABLE_BYTES, 512);
        assert_eq!(FAULT_WORDS * 4, 32);
        assert_eq!(
            core::mem::size_of::<SimulatedCamera<'_>>(),
            40 + 2 * core::mem::size_of::<usize>()
        );
        assert_eq!(
            core::mem::size_of_val(&CRC16),
            CRC_TABLE_BYTES + core::mem::size_of::<usize>()
        );
    }

    #[test]
    fn crc_check_value() {
        assert_eq!(crc16(b"123456789"), 0x29B1);
        assert_eq!(crc16(b""), 0xFFFF);
    }

    #[test]
    fn check_reply_order_and_retry_classes() {
        let mut buf = [0u8; 14];
        encode_row(5, &[1, 2, 3], &mut buf).unwrap();
        assert_eq!(check_reply(&buf, 5, 3), Ok(()));

        let mut bad = buf;
        bad[0] = 0;
        bad[9] ^= 0x80; // CRC error too, but sync is checked first
        assert_eq!(check_reply(&bad, 5, 3), Err(LinkError::Sync { row: 5 }));

        assert_eq!(
            check_reply(&buf, 4, 3),
            Err(LinkError::RowMismatch {
                expected: 4,
                got: 5
            })
        );

        let mut bad = buf;
        bad[13] ^= 1;
        let crc = u16::from_be_bytes([buf[12], buf[13]]);
        assert_eq!(
            check_reply(&bad, 5, 3),
            Err(LinkError::Checksum {
                row: 5,
                expected: crc ^ 1,
                computed: crc
            })
        );

        // A reply of 3 pixels read as a 2-pixel row: long, unverifiable.
        assert_eq!(
            check_reply(&buf[..12], 5, 2),
            Err(LinkError::LongRow { row: 5, pixels: 3 })
        );

        let mut short = [FILL_BYTE; 14];
        encode_row(5, &[1, 2], &mut short).unwrap();
        assert_eq!(
            check_reply(&short, 5, 3),
            Err(LinkError::ShortRow { row: 5, pixels: 2 })
        );
        // A short reply whose CRC is damaged is a checksum error, not a short row.
        short[11] ^= 4;
        assert!(matches!(
            check_reply(&short, 5, 3),
            Err(LinkError::Checksum { row: 5, .. })
        ));

        assert!(LinkError::<()>::Sync { row: 0 }.is_retryable());
        assert!(LinkError::<()>::LongRow { row: 0, pixels: 9 }.is_retryable());
        assert!(
            LinkError::<()>::Checksum {
                row: 0,
                expected: 0,
                computed: 1
            }
            .is_retryable()
        );
        assert!(
            !LinkError::<()>::RowMismatch {
                expected: 0,
                got: 1
            }
            .is_retryable()
        );
        assert!(!LinkError::<()>::ShortRow { row: 0, pixels: 1 }.is_retryable());
        assert!(!LinkError::<()>::Size.is_retryable());
        assert!(!LinkError::Spi(()).is_retryable());
    }

    #[test]
    fn check_reply_never_panics_on_garbage() {
        // Every width field value, with and without sync, in a short buffer.
        for w in [0u16, 1, 2, 3, 4, 327, 328, 329, u16::MAX] {
            let mut buf = [0u8; 14];
            buf[..2].copy_from_slice(&SYNC);
            buf[4..6].copy_from_slice(&w.to_be_bytes());
            let _ = check_reply(&buf, 0, 3);
            let _ = check_reply(&buf[..6], 0, 0);
            let _ = check_reply(&buf[..3], 0, 3);
        }
    }

    #[test]
    fn fault_bits() {
        let bytes = [0u8; 2 * 2 * 248];
        let mut cam = SimulatedCamera::new(&bytes, 2, 248).unwrap();
        cam.corrupt_row_once(247);
        cam.corrupt_row_once(31);
        cam.corrupt_row_once(248); // ignored
        assert!(!cam.take_fault(0));
        assert!(cam.take_fault(31));
        assert!(!cam.take_fault(31));
        assert!(cam.take_fault(247));
        assert!(!cam.take_fault(248));
        assert!(!cam.take_fault(u16::MAX));
    }
}
