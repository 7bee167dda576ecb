//! The SPI master: [`FrameReader`] fetches a frame row by row over an embedded-hal
//! [`SpiDevice`], with the framing and retry rules of the [link docs](super).

use embedded_hal::spi::{Operation, SpiDevice};

use super::wire::{
    CMD_READ_ROW, DEFAULT_RETRIES, HEADER_BYTES, LinkError, MAX_HEIGHT, MAX_ROW_BYTES, MAX_WIDTH,
    check_reply, row_bytes,
};

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
/// [link docs](super).
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
    /// [link docs](super) otherwise.
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
