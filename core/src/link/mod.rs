//! Frame input over SPI, in three parts, the wire format apart from the devices (as
//! smoltcp splits its `wire` module from its devices): [`wire`], a framed, checksummed
//! row protocol; [`reader`], a [`FrameReader`] generic over
//! [`embedded_hal::spi::SpiDevice`]; and [`camera`], a [`SimulatedCamera`] that speaks
//! the camera side of the protocol (hardware-in-the-loop, ground tests, firmware demo).
//! Everything is re-exported here (`tirroi_core::link::FrameReader`, ...).
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
//! with **one** [`SpiDevice::transaction`](embedded_hal::spi::SpiDevice::transaction) per row (chip select held for the whole
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

pub mod camera;
pub mod reader;
pub mod wire;

pub use camera::{SimError, SimulatedCamera};
pub use reader::{FrameReader, ReadStats};
pub use wire::{
    CMD_READ_ROW, CRC_BYTES, CRC_TABLE_BYTES, DEFAULT_RETRIES, FILL_BYTE, HEADER_BYTES, LinkError,
    MAX_HEIGHT, MAX_ROW_BYTES, MAX_WIDTH, REQUEST_BYTES, ROW_OVERHEAD_BYTES, SYNC, crc16,
    encode_row, pixels_to_be, row_bytes,
};

#[cfg(test)]
mod tests {
    use super::camera::FAULT_WORDS;
    use super::wire::{CRC16, check_reply};
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
