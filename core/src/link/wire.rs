//! The wire format of the SPI frame link (see the [link docs](super)): the row
//! request, the reply's header and CRC-16, [`encode_row`] for the sender side and the
//! checks the reader applies to a reply. No I/O here.

use core::convert::Infallible;
use core::fmt;

use crc::{CRC_16_IBM_3740, Crc, Table};

#[cfg(doc)]
use super::{FrameReader, SimulatedCamera};
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
pub(super) static CRC16: Crc<u16, Table<1>> = Crc::<u16, Table<1>>::new(&CRC_16_IBM_3740);

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
pub(super) fn header(row: u16, width: u16) -> [u8; HEADER_BYTES] {
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
/// the [link docs](super): sync, row, width = `pixels.len()`, pixels, CRC, all
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
/// link docs. `reply` is the `row_bytes(width)` bytes read.
pub(super) fn check_reply(
    reply: &[u8],
    row: u16,
    width: usize,
) -> Result<(), LinkError<Infallible>> {
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
