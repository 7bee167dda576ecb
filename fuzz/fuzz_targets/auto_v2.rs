//! Fuzz target: `auto-v2` on arbitrary frames and parameters never panics; its box lies
//! inside the frame; its confidence is in 0..=1000 ‰, at least the threshold for a box
//! and 0 for `null`; a threshold just above the box's confidence gives `null`; and the
//! same frame gives the same answer twice.
//!
//! Input layout: byte 0 width − 1 (mod 328), byte 1 height − 1 (mod 248), byte 2 bit
//! depth − 1 (mod 16), byte 3 `fine_sigma` − 1 (mod 40), bytes 4..6 `cell_score`
//! (little-endian i16, mod 8193 − 4096), bytes 6..8 `min_score_permille` (little-endian
//! u16, mod 1001), byte 8 `saturated_erode_px` (mod 9) and, by its top bit, the body
//! stage on (`BodyParams::DEFAULT`) or off; when byte 2's top bit is set, bytes 9..17
//! a tracking prior (x0, y0, x1, y1, little-endian u16: any box, cut to the frame by
//! the detector) and, when byte 3's bit 1 is set, the prior's look on the frame
//! (`auto-v2`'s fast tracking path); the rest the DN (little-endian u16, repeated to fill the frame;
//! none: a black frame). When byte 2's bit 6 is set (and there are more than 48 DN), a
//! smooth frame instead, the ground of stage 2c (deep space): the first 48 DN are an
//! 8 × 6 grid of levels interpolated bilinearly over the frame (kinks and steps between
//! grid points depart from any polynomial), the rest a small periodic pattern (their
//! top 6 bits) on top; clipped to the bit depth. Byte 8's bit 5 turns stage 2c off,
//! bit 4 stage 2d on. Byte 2's bits 4–5 are the components stage 4b rates − 1.
//! Byte 3's bit 2 sets a tracker's candidate floor (half the gate): a candidate only
//! without a box, in [floor, gate), and the same answer as without the floor. Byte 3's
//! bit 3 also runs the frame as a three-frame sequence through the core's tracker
//! (`roi::track::Tracker`; the DN moved by one pixel per frame): every step answers
//! `Ok`, its box inside the frame with a confidence in range and at the gate.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tirroi_core::roi::auto::learned::body::BodyParams;
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::roi::auto::learned::{AutoV2, AutoV2Scratch, BlobRule};
use tirroi_core::roi::track::Tracker;
use tirroi_core::{Detector, Frame, Roi, SCORE_FULL_PERMILLE};

/// Control points of the smooth frames across and down.
const GRID_X: usize = 8;
const GRID_Y: usize = 6;

/// A smooth `w × h` frame from `dn` (see the input layout).
fn smooth_frame(dn: &[u16], w: usize, h: usize, bits: u8) -> Vec<u16> {
    let max = if bits >= 16 {
        u16::MAX
    } else {
        (1u16 << bits) - 1
    };
    let (grid, rest) = dn.split_at(GRID_X * GRID_Y);
    let at =
        |gx: usize, gy: usize| f64::from(grid[gy.min(GRID_Y - 1) * GRID_X + gx.min(GRID_X - 1)]);
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let fx = x as f64 / w.max(2) as f64 * (GRID_X - 1) as f64;
            let fy = y as f64 / h.max(2) as f64 * (GRID_Y - 1) as f64;
            let (gx, gy) = (fx as usize, fy as usize);
            let (tx, ty) = (fx - gx as f64, fy - gy as f64);
            let top = at(gx, gy) * (1.0 - tx) + at(gx + 1, gy) * tx;
            let bottom = at(gx, gy + 1) * (1.0 - tx) + at(gx + 1, gy + 1) * tx;
            let level = top * (1.0 - ty) + bottom * ty;
            let pattern = rest.get(i % rest.len().max(1)).map_or(0, |&v| v >> 10);
            (level + f64::from(pattern)).min(f64::from(max)) as u16
        })
        .collect()
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 9 {
        return;
    }
    let w = 1 + usize::from(data[0]) % 328;
    let h = 1 + usize::from(data[1]) % 248;
    let bits = 1 + data[2] % 16;
    let word = |i: usize| u16::from_le_bytes([data[i], data[i + 1]]);
    let (prior, dn_from) = if data[2] & 0x80 != 0 && data.len() >= 17 {
        (Some(Roi::new(word(9), word(11), word(13), word(15))), 17)
    } else {
        (None, 9)
    };
    let det = AutoV2 {
        prior,
        look: None,
        fine_sigma: 1 + u16::from(data[3] % 40),
        cell_score: (i32::from(i16::from_le_bytes([data[4], data[5]])).rem_euclid(8193) - 4096)
            as i16,
        min_score_permille: u16::from_le_bytes([data[6], data[7]]) % 1001,
        saturated_erode_px: data[8] % 9,
        body: if data[8] & 0x80 == 0 {
            BodyParams::DEFAULT
        } else {
            BodyParams::OFF
        },
        prescreen: data[8] & 0x40 == 0,
        deep_space: data[8] & 0x20 == 0,
        sky_beside_earth: data[1] & 0x01 == 0,
        small_target: data[8] & 0x10 != 0,
        blob: match data[3] / 64 {
            0 => BlobRule::Off,
            1 => BlobRule::Always,
            _ => BlobRule::Compete,
        },
        candidates: 1 + ((data[2] >> 4) & 3),
        spot: data[3] & 0x01 == 0,
        // The default, or any of 0..=1000 (0: the spots do not compete).
        spot_competes_below_permille: if data[3] & 0x02 == 0 {
            AutoV2::DEFAULT.spot_competes_below_permille
        } else {
            (u16::from(data[7]) * 4).min(1000)
        },
        outline: data[3] & 0x04 == 0,
        // 1..=3 (the width's byte's top bits: every value is also a width).
        link_cells: 1 + (data[0] >> 6) % 3,
        candidate_floor_permille: None,
    };
    let dn: Vec<u16> = data[dn_from..]
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    let pixels: Vec<u16> = if data[2] & 0x40 != 0 && dn.len() > GRID_X * GRID_Y {
        smooth_frame(&dn, w, h, bits)
    } else {
        (0..w * h)
            .map(|i| if dn.is_empty() { 0 } else { dn[i % dn.len()] })
            .collect()
    };
    let frame = Frame::new(&pixels, w, h, bits).expect("valid dimensions");
    // The look a tracker carries: the prior's on this frame (its fast path), by byte
    // 3's bit 1.
    let det = if data[3] & 0x02 != 0 {
        det.with_look(prior.and_then(|p| Look::measure(&frame, p)))
    } else {
        det
    };
    let det = AutoV2 {
        candidate_floor_permille: (data[3] & 0x04 != 0).then_some(det.min_score_permille / 2),
        ..det
    };
    let mut scratch = Box::new(AutoV2Scratch::new());
    let d = det.detect(&frame, &mut scratch).expect("valid parameters");
    if let Some((r, score)) = scratch.work().candidate() {
        let floor = det
            .candidate_floor_permille
            .expect("a candidate only with a floor");
        assert!(
            d.roi.is_none() && score >= floor && score < det.min_score_permille,
            "{d:?} {score}"
        );
        assert!(
            !r.is_empty() && usize::from(r.x1) <= w && usize::from(r.y1) <= h,
            "{r:?}"
        );
    }
    let no_floor = AutoV2 {
        candidate_floor_permille: None,
        ..det
    };
    assert_eq!(no_floor.detect(&frame, &mut scratch).unwrap(), d);
    assert!(d.score_permille <= SCORE_FULL_PERMILLE, "{d:?}");
    match d.roi {
        Some(r) => {
            assert!(!r.is_empty(), "{r:?}");
            assert!(
                usize::from(r.x1) <= w && usize::from(r.y1) <= h,
                "{r:?} in {w}x{h}"
            );
            assert!(d.score_permille >= det.min_score_permille, "{d:?}");
            if d.score_permille < SCORE_FULL_PERMILLE && det.prior.is_none() {
                // A threshold just above the confidence: no target (without a prior:
                // with one, a box gated in the tracking window sends the search to the
                // whole frame, whose winner may pass).
                let stricter = AutoV2 {
                    min_score_permille: d.score_permille + 1,
                    ..det
                };
                let n = stricter
                    .detect(&frame, &mut scratch)
                    .expect("valid parameters");
                assert_eq!((n.roi, n.score_permille), (None, 0), "{d:?}");
            }
        }
        None => assert_eq!(d.score_permille, 0, "{d:?}"),
    }
    // The same frame again in the same scratch gives the same detection.
    assert_eq!(det.detect(&frame, &mut scratch).unwrap(), d);
    // The frame as a short sequence through the tracker (the DN moved by a pixel per
    // frame: the ground's registration and the candidate's run see motion).
    if data[3] & 0x08 != 0 {
        let mut tracker = Tracker::new(det);
        for k in 0..3 {
            let moved: Vec<u16> = (0..w * h).map(|i| pixels[(i + k) % (w * h)]).collect();
            let f = Frame::new(&moved, w, h, bits).expect("valid dimensions");
            let t = tracker.step(&f, &mut scratch).expect("valid parameters");
            assert!(t.score_permille <= SCORE_FULL_PERMILLE, "{t:?}");
            match t.roi {
                Some(r) => {
                    assert!(!r.is_empty() && usize::from(r.x1) <= w && usize::from(r.y1) <= h);
                    assert!(t.score_permille >= det.min_score_permille, "{t:?}");
                }
                None => assert_eq!(t.score_permille, 0, "{t:?}"),
            }
            assert_eq!(tracker.prior(), t.roi);
        }
    }
});
