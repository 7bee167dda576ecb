//! The SPI frame link: `FrameReader` against a scripted `embedded-hal-mock` device
//! (exact bytes on the wire, every error), against `SimulatedCamera` (full reference
//! frames, fault injection), and `encode_row` against an independent CRC.
#![cfg(feature = "spi")]

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::spi::{Mock, Transaction};
use tirroi_core::link::{
    CMD_READ_ROW, DEFAULT_RETRIES, FILL_BYTE, FrameReader, LinkError, MAX_HEIGHT, MAX_ROW_BYTES,
    MAX_WIDTH, ROW_OVERHEAD_BYTES, ReadStats, SYNC, SimError, SimulatedCamera, crc16, encode_row,
    pixels_to_be, row_bytes,
};

// ---------------------------------------------------------------------------------
// Helpers

/// Bitwise CRC-16/CCITT-FALSE, written from the definition (poly 0x1021, init 0xFFFF,
/// MSB first, no reflection, no final XOR), independent of the `crc` crate.
fn crc16_bitwise(bytes: &[u8]) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for &b in bytes {
        crc ^= u16::from(b) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// A reply built by hand from the documented layout (not with `encode_row`), padded
/// with `pad` bytes of 0xFF.
fn reply_by_hand(row: u16, pixels: &[u16], pad: usize) -> Vec<u8> {
    let mut v = vec![0x54, 0x52];
    v.extend_from_slice(&[(row >> 8) as u8, row as u8]);
    let n = pixels.len() as u16;
    v.extend_from_slice(&[(n >> 8) as u8, n as u8]);
    for &p in pixels {
        v.push((p >> 8) as u8);
        v.push(p as u8);
    }
    let crc = crc16_bitwise(&v);
    v.push((crc >> 8) as u8);
    v.push(crc as u8);
    v.extend(std::iter::repeat_n(0xFF, pad));
    v
}

/// The four mock expectations of one row transaction: CS start, the 3-byte request
/// (command 0x52, row big-endian), the reply read, CS end.
fn exchange(row: u16, reply: Vec<u8>) -> Vec<Transaction<u8>> {
    vec![
        Transaction::transaction_start(),
        Transaction::write_vec(vec![0x52, (row >> 8) as u8, row as u8]),
        Transaction::read_vec(reply),
        Transaction::transaction_end(),
    ]
}

fn pixels_3x4() -> Vec<u16> {
    vec![
        0, 1, 16383, 0xFFFF, //
        0x1234, 0xABCD, 0x00FF, 0xFF00, //
        7, 0x8000, 0x7FFF, 42,
    ]
}

/// Reference-size test pattern: includes 0, 16383 (14-bit saturation) and 0xFFFF.
fn pattern(width: usize, height: usize) -> Vec<u16> {
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width, i / width);
            match i % 11 {
                0 => 0,
                1 => 16383,
                2 => 0xFFFF,
                _ => ((x * 37 + y * 101) ^ (x * y)) as u16,
            }
        })
        .collect()
}

fn to_be(pixels: &[u16]) -> Vec<u8> {
    let mut bytes = vec![0u8; pixels.len() * 2];
    assert_eq!(pixels_to_be(pixels, &mut bytes), Ok(pixels.len() * 2));
    bytes
}

// ---------------------------------------------------------------------------------
// Constants and the byte layout

#[test]
fn documented_constants() {
    assert_eq!(CMD_READ_ROW, 0x52);
    assert_eq!(SYNC, *b"TR");
    assert_eq!(ROW_OVERHEAD_BYTES, 8);
    assert_eq!(row_bytes(328), 664);
    assert_eq!(MAX_ROW_BYTES, 664);
    assert_eq!((MAX_WIDTH, MAX_HEIGHT), (328, 248));
    assert_eq!(DEFAULT_RETRIES, 2);
}

#[test]
fn encode_row_layout_is_big_endian_byte_by_byte() {
    let mut out = [0xAAu8; 20];
    let n = encode_row(0x0102, &[0x0304, 0xFFFE, 0], &mut out).unwrap();
    assert_eq!(n, 14);
    let crc = crc16_bitwise(&out[..12]);
    assert_eq!(
        out[..14],
        [
            0x54,
            0x52, // sync "TR"
            0x01,
            0x02, // row 0x0102
            0x00,
            0x03, // width 3
            0x03,
            0x04, // pixel 0
            0xFF,
            0xFE, // pixel 1
            0x00,
            0x00, // pixel 2
            (crc >> 8) as u8,
            crc as u8,
        ]
    );
    assert_eq!(
        out[14..],
        [0xAA; 6],
        "bytes after the reply are left untouched"
    );
    assert_eq!(
        out[..14],
        reply_by_hand(0x0102, &[0x0304, 0xFFFE, 0], 0)[..]
    );
}

#[test]
fn crc_matches_check_value_and_bitwise_reference() {
    assert_eq!(crc16(b"123456789"), 0x29B1);
    assert_eq!(crc16_bitwise(b"123456789"), 0x29B1);
    // Pseudo-random rows of every width class, compared with the bitwise CRC.
    let mut state: u32 = 0x1234_5678;
    for width in [0usize, 1, 2, 7, 64, 327, 328] {
        let pixels: Vec<u16> = (0..width)
            .map(|_| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 16) as u16
            })
            .collect();
        let mut out = vec![0u8; row_bytes(width)];
        let row = (state >> 8) as u16;
        assert_eq!(encode_row(row, &pixels, &mut out), Ok(row_bytes(width)));
        let body = &out[..6 + 2 * width];
        let carried = u16::from_be_bytes([out[6 + 2 * width], out[7 + 2 * width]]);
        assert_eq!(carried, crc16_bitwise(body), "width {width}");
        assert_eq!(crc16(body), carried);
        assert_eq!(out, reply_by_hand(row, &pixels, 0));
    }
}

#[test]
fn encode_row_size_errors() {
    let mut out = [0u8; 13];
    assert_eq!(encode_row(0, &[1, 2, 3], &mut out), Err(LinkError::Size));
    assert_eq!(out, [0; 13], "nothing written on error");
    let too_wide = vec![0u16; MAX_WIDTH + 1];
    let mut big = vec![0u8; row_bytes(MAX_WIDTH + 1)];
    assert_eq!(encode_row(0, &too_wide, &mut big), Err(LinkError::Size));
    let mut empty = [0u8; 8];
    assert_eq!(encode_row(9, &[], &mut empty), Ok(8));
    assert_eq!(pixels_to_be(&[1, 2], &mut [0u8; 3]), Err(LinkError::Size));
}

// ---------------------------------------------------------------------------------
// FrameReader against the embedded-hal mock

#[test]
fn mock_three_rows_read_exactly() {
    let px = pixels_3x4();
    let mut expectations = Vec::new();
    for (y, row) in px.chunks(4).enumerate() {
        expectations.extend(exchange(y as u16, reply_by_hand(y as u16, row, 0)));
    }
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0x5555u16; 12];
    let stats = reader.read_frame(&mut frame, 4, 3).unwrap();
    assert_eq!(
        stats,
        ReadStats {
            rows: 3,
            retries: 0
        }
    );
    assert_eq!(frame, px, "pixels bit for bit");
    reader.release().done();
}

#[test]
fn mock_bad_crc_then_good_resend_counts_one_retry() {
    let px = pixels_3x4();
    let mut bad = reply_by_hand(1, &px[4..8], 0);
    bad[9] ^= 0x10; // a payload bit flipped on the wire
    let mut expectations = exchange(0, reply_by_hand(0, &px[0..4], 0));
    expectations.extend(exchange(1, bad));
    expectations.extend(exchange(1, reply_by_hand(1, &px[4..8], 0)));
    expectations.extend(exchange(2, reply_by_hand(2, &px[8..12], 0)));
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; 12];
    let stats = reader.read_frame(&mut frame, 4, 3).unwrap();
    assert_eq!(stats.retries, 1);
    assert_eq!(stats.rows, 3);
    assert_eq!(frame, px);
    reader.release().done();
}

#[test]
fn mock_bad_crc_on_every_try_is_a_checksum_error() {
    let px = pixels_3x4();
    let good = reply_by_hand(0, &px[0..4], 0);
    let mut bad = good.clone();
    bad[15] ^= 0x01; // low byte of the CRC (4 pixels: CRC at bytes 14..16)
    let carried = u16::from_be_bytes([bad[14], bad[15]]);
    let computed = crc16_bitwise(&good[..14]);
    assert_eq!(carried ^ 1, computed);
    // 1 try + DEFAULT_RETRIES re-requests.
    let mut expectations = Vec::new();
    for _ in 0..=DEFAULT_RETRIES {
        expectations.extend(exchange(0, bad.clone()));
    }
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![7u16; 12];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::Checksum {
            row: 0,
            expected: carried,
            computed
        })
    );
    assert_eq!(frame, vec![7u16; 12], "a failed row is not written");
    reader.release().done();

    // With no retries: exactly one transfer.
    let mock = Mock::new(&exchange(0, bad.clone()));
    let mut reader = FrameReader::new(mock).with_retries(0);
    assert_eq!(reader.retries(), 0);
    assert!(matches!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::Checksum { row: 0, .. })
    ));
    reader.release().done();
}

#[test]
fn mock_short_row_is_reported_without_retry() {
    let px = pixels_3x4();
    // Row 1 comes back with 2 pixels (valid CRC), then 2×2 + 0 fill bytes to reach
    // the 16 bytes the reader clocks for 4 pixels.
    let mut expectations = exchange(0, reply_by_hand(0, &px[0..4], 0));
    expectations.extend(exchange(1, reply_by_hand(1, &px[4..6], 4)));
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; 12];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::ShortRow { row: 1, pixels: 2 })
    );
    assert_eq!(frame[..4], px[..4], "rows before the error are written");
    assert_eq!(frame[4..], [0; 8]);
    reader.release().done();
}

#[test]
fn mock_long_row_is_retried_then_reported() {
    let px = pixels_3x4();
    // The camera announces 5 pixels; the reader clocks only the 16 bytes of 4.
    let long = reply_by_hand(0, &[1, 2, 3, 4, 5], 0)[..16].to_vec();
    let mut expectations = Vec::new();
    for _ in 0..=DEFAULT_RETRIES {
        expectations.extend(exchange(0, long.clone()));
    }
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; px.len()];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::LongRow { row: 0, pixels: 5 })
    );
    reader.release().done();
}

#[test]
fn mock_wrong_row_index_is_row_mismatch() {
    let px = pixels_3x4();
    let mut expectations = exchange(0, reply_by_hand(0, &px[0..4], 0));
    expectations.extend(exchange(1, reply_by_hand(2, &px[8..12], 0)));
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; 12];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::RowMismatch {
            expected: 1,
            got: 2
        })
    );
    reader.release().done();
}

#[test]
fn mock_bad_sync() {
    let px = pixels_3x4();
    let mut bad = reply_by_hand(0, &px[0..4], 0);
    bad[1] = 0x53;
    // Bad on every try: Sync error after 1 + 2 transfers.
    let mut expectations = Vec::new();
    for _ in 0..=DEFAULT_RETRIES {
        expectations.extend(exchange(0, bad.clone()));
    }
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; 12];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::Sync { row: 0 })
    );
    reader.release().done();

    // An all-0xFF reply (camera not driving MISO), then a good one: recovered.
    let mut expectations = exchange(0, vec![0xFF; 16]);
    for (y, row) in px.chunks(4).enumerate() {
        expectations.extend(exchange(y as u16, reply_by_hand(y as u16, row, 0)));
    }
    let mock = Mock::new(&expectations);
    let mut reader = FrameReader::new(mock);
    let stats = reader.read_frame(&mut frame, 4, 3).unwrap();
    assert_eq!(
        stats,
        ReadStats {
            rows: 3,
            retries: 1
        }
    );
    assert_eq!(frame, px);
    reader.release().done();
}

#[test]
fn mock_size_errors_before_any_spi_traffic() {
    let mock = Mock::new(&[]);
    let mut reader = FrameReader::new(mock);
    let mut frame = vec![0u16; 12];
    for (len, w, h) in [
        (12, 4, 4),
        (12, 3, 3),
        (0, 0, 0),
        (12, 0, 12),
        (12, 12, 0),
        (MAX_WIDTH + 1, MAX_WIDTH + 1, 1),
        (MAX_HEIGHT + 1, 1, MAX_HEIGHT + 1),
        (12, usize::MAX, 2),
    ] {
        frame.resize(len, 0);
        assert_eq!(
            reader.read_frame(&mut frame, w, h),
            Err(LinkError::Size),
            "{len} px as {w}x{h}"
        );
    }
    assert_eq!(reader.read_row(0, &mut []), Err(LinkError::Size));
    assert_eq!(
        reader.read_row(0, &mut [0u16; MAX_WIDTH + 1]),
        Err(LinkError::Size)
    );
    reader.release().done();
}

/// Serves a `SimulatedCamera` but fails transaction number `fail_at` (0-based) with
/// `ErrorKind::Overrun`.
struct FlakyBus<'a> {
    camera: SimulatedCamera<'a>,
    fail_at: usize,
    count: usize,
}

impl ErrorType for FlakyBus<'_> {
    type Error = ErrorKind;
}

impl SpiDevice for FlakyBus<'_> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        let n = self.count;
        self.count += 1;
        if n == self.fail_at {
            return Err(ErrorKind::Overrun);
        }
        self.camera
            .transaction(operations)
            .map_err(|_| ErrorKind::Other)
    }
}

#[test]
fn spi_error_propagates_without_retry() {
    let px = pixels_3x4();
    let bytes = to_be(&px);
    let camera = SimulatedCamera::new(&bytes, 4, 3).unwrap();
    let bus = FlakyBus {
        camera,
        fail_at: 1,
        count: 0,
    };
    let mut reader = FrameReader::new(bus);
    let mut frame = vec![9u16; 12];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 3),
        Err(LinkError::Spi(ErrorKind::Overrun))
    );
    assert_eq!(frame[..4], px[..4]);
    assert_eq!(frame[4..], [9; 8]);
    let bus = reader.release();
    assert_eq!(bus.count, 2, "no retry after an SPI error");
}

// ---------------------------------------------------------------------------------
// FrameReader against SimulatedCamera

#[test]
fn simulated_camera_round_trip_of_a_reference_frame() {
    let (w, h) = (MAX_WIDTH, MAX_HEIGHT);
    let px = pattern(w, h);
    assert!(px.contains(&0) && px.contains(&16383) && px.contains(&0xFFFF));
    let bytes = to_be(&px);
    let camera = SimulatedCamera::new(&bytes, w, h).unwrap();
    assert_eq!((camera.width(), camera.height()), (w, h));
    let mut reader = FrameReader::new(camera);
    let mut frame = vec![0u16; w * h];
    let stats = reader.read_frame(&mut frame, w, h).unwrap();
    assert_eq!(
        stats,
        ReadStats {
            rows: 248,
            retries: 0
        }
    );
    assert!(frame == px, "frame differs after the round trip");

    // Same reader, second frame with three corrupted rows: one retry each.
    let mut camera = reader.release();
    assert_eq!(camera.transfers(), 248);
    camera.corrupt_row_once(0);
    camera.corrupt_row_once(100);
    camera.corrupt_row_once(247);
    camera.corrupt_row_once(248); // outside the frame: ignored
    let mut reader = FrameReader::new(camera);
    frame.fill(0);
    let stats = reader.read_frame(&mut frame, w, h).unwrap();
    assert_eq!(
        stats,
        ReadStats {
            rows: 248,
            retries: 3
        }
    );
    assert!(frame == px);
    let camera = reader.release();
    assert_eq!(camera.transfers(), 248 + 251);

    // "Once": the next frame is clean again.
    let mut reader = FrameReader::new(camera);
    assert_eq!(reader.read_frame(&mut frame, w, h).unwrap().retries, 0);
}

#[test]
fn simulated_camera_corruption_without_retries_is_a_checksum_error() {
    let px = pattern(8, 4);
    let bytes = to_be(&px);
    let mut camera = SimulatedCamera::new(&bytes, 8, 4).unwrap();
    camera.corrupt_row_once(2);
    let mut reader = FrameReader::new(camera).with_retries(0);
    let mut frame = vec![0u16; 32];
    let err = reader.read_frame(&mut frame, 8, 4).unwrap_err();
    let LinkError::Checksum {
        row,
        expected,
        computed,
    } = err
    else {
        panic!("expected a checksum error, got {err:?}");
    };
    assert_eq!(row, 2);
    assert_ne!(expected, computed);
    assert_eq!(frame[..16], px[..16]);
    // The corruption was for one transfer only: row 2 now reads fine.
    let mut row2 = [0u16; 8];
    assert_eq!(reader.read_row(2, &mut row2), Ok(0));
    assert_eq!(row2[..], px[16..24]);
}

#[test]
fn simulated_camera_serves_the_documented_bytes() {
    let px = pixels_3x4();
    let bytes = to_be(&px);
    let mut camera = SimulatedCamera::new(&bytes, 4, 3).unwrap();

    // One read of exactly the reply.
    let mut reply = [0u8; 16];
    camera
        .transaction(&mut [Operation::Write(&[0x52, 0, 2]), Operation::Read(&mut reply)])
        .unwrap();
    assert_eq!(reply[..], reply_by_hand(2, &px[8..12], 0)[..]);

    // Split over three reads, with a delay, and 4 bytes too many: same bytes + fill.
    let (mut a, mut b, mut c) = ([0u8; 5], [0u8; 9], [0u8; 6]);
    camera
        .transaction(&mut [
            Operation::Write(&[0x52, 0, 2]),
            Operation::Read(&mut a),
            Operation::DelayNs(1000),
            Operation::Read(&mut b),
            Operation::Read(&mut c),
        ])
        .unwrap();
    let joined: Vec<u8> = a.iter().chain(&b).chain(&c).copied().collect();
    assert_eq!(joined[..16], reply[..]);
    assert_eq!(joined[16..], [FILL_BYTE; 4]);

    // Corrupted: exactly one bit differs, in pixel 0's low byte.
    camera.corrupt_row_once(2);
    let mut bad = [0u8; 16];
    camera
        .transaction(&mut [Operation::Write(&[0x52, 0, 2]), Operation::Read(&mut bad)])
        .unwrap();
    let diff: Vec<(usize, u8)> = bad
        .iter()
        .zip(&reply)
        .enumerate()
        .filter(|(_, (x, y))| x != y)
        .map(|(i, (x, y))| (i, x ^ y))
        .collect();
    assert_eq!(diff, vec![(7, 0x01)]);
    assert_eq!(camera.transfers(), 3);
}

#[test]
fn simulated_camera_errors() {
    let bytes = to_be(&pixels_3x4());
    assert!(SimulatedCamera::new(&bytes, 4, 3).is_ok());
    assert_eq!(
        SimulatedCamera::new(&bytes[..23], 4, 3).err(),
        Some(LinkError::Size)
    );
    assert_eq!(
        SimulatedCamera::new(&bytes, 12, 1).map(|c| c.height()),
        Ok(1)
    );
    assert_eq!(
        SimulatedCamera::new(&bytes, 0, 3).err(),
        Some(LinkError::Size)
    );
    assert_eq!(
        SimulatedCamera::new(&[], MAX_WIDTH + 1, 0).err(),
        Some(LinkError::Size)
    );

    let mut camera = SimulatedCamera::new(&bytes, 4, 3).unwrap();
    let mut buf = [0u8; 16];
    assert_eq!(
        camera.transaction(&mut [Operation::Read(&mut buf)]),
        Err(SimError::NoCommand)
    );
    assert_eq!(
        camera.transaction(&mut [Operation::Write(&[0x51, 0, 0])]),
        Err(SimError::BadCommand)
    );
    assert_eq!(
        camera.transaction(&mut [Operation::Write(&[0x52, 0])]),
        Err(SimError::BadCommand)
    );
    assert_eq!(
        camera.transaction(&mut [Operation::Write(&[0x52, 0, 3]), Operation::Read(&mut buf)]),
        Err(SimError::RowOutOfRange { row: 3 })
    );
    assert_eq!(
        camera.transaction(&mut [Operation::TransferInPlace(&mut buf)]),
        Err(SimError::Unsupported)
    );
    assert_eq!(camera.transfers(), 0);
    assert_eq!(
        embedded_hal::spi::Error::kind(&SimError::NoCommand),
        ErrorKind::Other
    );

    // Through the reader: a frame taller than the camera's is an SPI error at row 3.
    let mut reader = FrameReader::new(camera);
    let mut frame = vec![0u16; 16];
    assert_eq!(
        reader.read_frame(&mut frame, 4, 4),
        Err(LinkError::Spi(SimError::RowOutOfRange { row: 3 }))
    );
    // A reader expecting narrower rows than the camera's: long row.
    let mut narrow = vec![0u16; 9];
    assert_eq!(
        reader.read_frame(&mut narrow, 3, 3),
        Err(LinkError::LongRow { row: 0, pixels: 4 })
    );
    // Wider: short row (the camera's CRC is valid, the fill is ignored).
    let mut wide = vec![0u16; 15];
    assert_eq!(
        reader.read_frame(&mut wide, 5, 3),
        Err(LinkError::ShortRow { row: 0, pixels: 4 })
    );
}

#[test]
fn errors_display_and_implement_error() {
    let errors: [LinkError<SimError>; 7] = [
        LinkError::Spi(SimError::NoCommand),
        LinkError::Size,
        LinkError::Sync { row: 3 },
        LinkError::RowMismatch {
            expected: 1,
            got: 2,
        },
        LinkError::ShortRow { row: 4, pixels: 1 },
        LinkError::LongRow {
            row: 5,
            pixels: 400,
        },
        LinkError::Checksum {
            row: 6,
            expected: 0x1234,
            computed: 0xABCD,
        },
    ];
    for e in &errors {
        let dyn_err: &dyn std::error::Error = e;
        assert!(!dyn_err.to_string().is_empty());
    }
    assert!(errors[6].to_string().contains("0x1234"));
    assert!(errors[6].to_string().contains("0xabcd"));
    assert!(errors[2].to_string().contains("row 3"));
    let sim: &dyn std::error::Error = &SimError::RowOutOfRange { row: 9 };
    assert!(sim.to_string().contains("row 9"));
}
