//! The camera side of the link: [`SimulatedCamera`] serves a stored frame as an
//! embedded-hal [`SpiDevice`] with the framing of the [link docs](super), with
//! injectable bit errors (hardware-in-the-loop, ground tests, the firmware demo).

use core::convert::Infallible;
use core::fmt;
use core::iter;

use embedded_hal::spi::{self, ErrorType, Operation, SpiDevice};

use super::wire::{
    CMD_READ_ROW, CRC_BYTES, CRC16, FILL_BYTE, HEADER_BYTES, LinkError, MAX_HEIGHT, MAX_WIDTH,
    header,
};

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
pub(super) const FAULT_WORDS: usize = MAX_HEIGHT.div_ceil(32);
/// Reply byte [`SimulatedCamera::corrupt_row_once`] damages: the low byte of pixel 0.
const FAULT_BYTE: usize = HEADER_BYTES + 1;
/// Bit flipped in [`FAULT_BYTE`]: bit 0, the pixel's least significant bit.
const FAULT_MASK: u8 = 0x01;

/// A camera on the far side of the SPI link, serving a stored frame with the framing
/// of the [link docs](super): product code for hardware-in-the-loop tests and the
/// firmware demo.
///
/// It borrows the frame as big-endian bytes (2 per pixel, row-major; see
/// [`pixels_to_be`](super::pixels_to_be)) and holds a 32-byte fault bit set and a transfer counter. As an
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
    pub(super) fn take_fault(&mut self, row: u16) -> bool {
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
