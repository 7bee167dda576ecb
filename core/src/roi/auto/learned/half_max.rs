//! The half-maximum box of a small target. A far target (3–12 px in the `realistic`
//! preset) is blurred by the optics over 2–3 px on each side, and `auto`'s boundary
//! rule (steps above `fine_sigma` σ) finds the outer end of that blur: boxes come out
//! 2–3 px too wide per side, which halves a 5-px target's IoU. The truth marks the
//! pixels at least half covered by the target; across a blurred edge of a uniform
//! face that is where the signal crosses half its height above the background. So a
//! small box is cut to the pixels whose departure from the local background reaches
//! half the peak departure (same sign as the peak).

use super::order::select;
use crate::frame::Frame;
use crate::roi::Roi;

/// Boxes with both sides at most this many pixels are cut to their half maximum: the
/// largest far target (12 px) plus the blur on both sides (2 × 3 px) and margin.
pub const MAX_SIDE_PX: u16 = 24;

/// The peak departure must reach this many noise σ, else the box is kept: below it
/// half the peak is within 4 σ of the background and noise would pick the pixels.
pub const MIN_PEAK_SIGMA: u32 = 8;

/// Background samples: the one-pixel ring around a box of up to [`MAX_SIDE_PX`] per
/// side, `4 · (24 + 1)` = 100 pixels (rounded up).
const RING_PX: usize = 128;

/// Median DN of the one-pixel ring around `roi` (cut to the frame), or `None` when the
/// ring is empty (a box covering the frame).
fn ring_median(frame: &Frame<'_>, roi: Roi) -> Option<u16> {
    let mut buf = [0u16; RING_PX];
    let mut n = 0usize;
    let (w, h) = (frame.width(), frame.height());
    let (x0, y0) = (usize::from(roi.x0), usize::from(roi.y0));
    let (x1, y1) = (usize::from(roi.x1), usize::from(roi.y1));
    let mut push = |v: u16| {
        if let Some(slot) = buf.get_mut(n) {
            *slot = v;
            n += 1;
        }
    };
    let xa = x0.saturating_sub(1);
    let xb = (x1 + 1).min(w);
    for y in [y0.checked_sub(1), Some(y1).filter(|&y| y < h)]
        .into_iter()
        .flatten()
    {
        if let Some(row) = frame.row(y) {
            for &v in row.get(xa..xb).unwrap_or(&[]) {
                push(v);
            }
        }
    }
    for y in y0..y1.min(h) {
        if let Some(row) = frame.row(y) {
            for x in [x0.checked_sub(1), Some(x1).filter(|&x| x < w)]
                .into_iter()
                .flatten()
            {
                if let Some(&v) = row.get(x) {
                    push(v);
                }
            }
        }
    }
    let ring = buf.get(..n).filter(|r| !r.is_empty())?;
    // The element at index n/2 of the sorted ring.
    let median = select(
        || ring.iter().map(|&v| u32::from(v)),
        n / 2,
        u32::from(u16::MAX),
    );
    u16::try_from(median).ok()
}

/// `roi` cut to its half maximum (see the module): boxes larger than
/// [`MAX_SIDE_PX`], or whose peak departs less than [`MIN_PEAK_SIGMA`] · `sigma_dn`
/// from the ring's median, come back unchanged. The result lies inside `roi` and
/// holds the peak pixel.
pub fn half_max_box(frame: &Frame<'_>, roi: Roi, sigma_dn: u32) -> Roi {
    if roi.x1 <= roi.x0
        || roi.y1 <= roi.y0
        || roi.x1 - roi.x0 > MAX_SIDE_PX
        || roi.y1 - roi.y0 > MAX_SIDE_PX
    {
        return roi;
    }
    let Some(bg) = ring_median(frame, roi) else {
        return roi;
    };
    let bg = i32::from(bg);
    let (x0, x1) = (usize::from(roi.x0), usize::from(roi.x1));
    let rows = usize::from(roi.y0)..usize::from(roi.y1).min(frame.height());
    // The peak departure, signed.
    let mut peak = 0i32;
    for y in rows.clone() {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for &v in row {
            let d = i32::from(v) - bg;
            if d.abs() > peak.abs() {
                peak = d;
            }
        }
    }
    if peak.unsigned_abs() < MIN_PEAK_SIGMA.saturating_mul(sigma_dn.max(1)) {
        return roi;
    }
    let mut cut = Roi::EMPTY;
    let mut found = false;
    for y in rows {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for (i, &v) in row.iter().enumerate() {
            let d = i32::from(v) - bg;
            // Same sign as the peak and above half of it.
            if d.signum() == peak.signum() && 2 * d.abs() > peak.abs() {
                let (x, y) = ((x0 + i) as u16, y as u16);
                if found {
                    cut.x0 = cut.x0.min(x);
                    cut.y0 = cut.y0.min(y);
                    cut.x1 = cut.x1.max(x + 1);
                    cut.y1 = cut.y1.max(y + 1);
                } else {
                    cut = Roi {
                        x0: x,
                        y0: y,
                        x1: x + 1,
                        y1: y + 1,
                    };
                    found = true;
                }
            }
        }
    }
    if found { cut } else { roi }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;

    /// A uniform rectangle blurred by a box filter of radius 2 over a flat background:
    /// the half-maximum box is the rectangle itself (a blurred step crosses half its
    /// height at the edge), from a box 3 px wider per side.
    #[test]
    fn a_blurred_rectangle_is_cut_to_its_edges() {
        let (bg, top) = (1000i32, 5000i32);
        let (rx0, ry0, rx1, ry1) = (100usize, 50usize, 106usize, 54usize);
        let sharp = |x: usize, y: usize| {
            if (rx0..rx1).contains(&x) && (ry0..ry1).contains(&y) {
                top
            } else {
                bg
            }
        };
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 2..FRAME_HEIGHT - 2 {
            for x in 2..FRAME_WIDTH - 2 {
                // 5×5 box blur: the brute-force reference of a soft edge.
                let mut s = 0;
                for dy in 0..5 {
                    for dx in 0..5 {
                        s += sharp(x + dx - 2, y + dy - 2);
                    }
                }
                px[y * FRAME_WIDTH + x] = (s / 25) as u16;
            }
        }
        let frame = Frame::reference(&px).unwrap();
        let wide = Roi {
            x0: 97,
            y0: 47,
            x1: 109,
            y1: 57,
        };
        let got = half_max_box(&frame, wide, 10);
        // Along x the blurred step reaches half at the edge pixels (3/5 and 2/5 of
        // the step on either side): the rectangle; along y the 4-px height keeps
        // rows with at least half the (lower, 4/5) peak.
        assert_eq!((got.x0, got.x1), (rx0 as u16, rx1 as u16), "{got:?}");
        assert_eq!((got.y0, got.y1), (ry0 as u16, ry1 as u16), "{got:?}");
        // A cold target the same way, and a large box left alone.
        let inv: std::vec::Vec<u16> = px.iter().map(|&v| 6000 - v).collect();
        let frame = Frame::reference(&inv).unwrap();
        assert_eq!(half_max_box(&frame, wide, 10), got);
        let big = Roi {
            x0: 90,
            y0: 40,
            x1: 120,
            y1: 60,
        };
        assert_eq!(half_max_box(&frame, big, 10), big);
        // Below the peak threshold: unchanged.
        assert_eq!(half_max_box(&frame, wide, 4000), wide);
    }

    #[test]
    fn ring_median_equals_the_sorted_ring() {
        // A pseudo-random frame (ties included: values 0..64) and boxes everywhere,
        // also at the frame's edges; reference: the ring collected by brute force and
        // sorted.
        let mut s = 0x9e37_79b9u32;
        let px: std::vec::Vec<u16> = (0..FRAME_WIDTH * FRAME_HEIGHT)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s % 64) as u16
            })
            .collect();
        let frame = Frame::reference(&px).unwrap();
        for (x0, y0, x1, y1) in [
            (0u16, 0u16, 5u16, 3u16),
            (10, 10, 30, 20),
            (300, 200, 328, 248),
            (0, 100, 24, 124),
            (163, 0, 164, 1),
        ] {
            let roi = Roi::new(x0, y0, x1, y1);
            let mut ring = std::vec::Vec::new();
            for y in i32::from(y0) - 1..=i32::from(y1) {
                for x in i32::from(x0) - 1..=i32::from(x1) {
                    let inside = x >= i32::from(x0)
                        && x < i32::from(x1)
                        && y >= i32::from(y0)
                        && y < i32::from(y1);
                    let in_frame = x >= 0
                        && y >= 0
                        && (x as usize) < FRAME_WIDTH
                        && (y as usize) < FRAME_HEIGHT;
                    if !inside && in_frame {
                        ring.push(px[y as usize * FRAME_WIDTH + x as usize]);
                    }
                }
            }
            ring.sort_unstable();
            assert_eq!(
                ring_median(&frame, roi),
                Some(ring[ring.len() / 2]),
                "{roi:?}"
            );
        }
    }

    #[test]
    fn boxes_at_the_frame_edge_and_degenerate_boxes_are_safe() {
        let px = std::vec![7u16; FRAME_WIDTH * FRAME_HEIGHT];
        let frame = Frame::reference(&px).unwrap();
        for roi in [
            Roi::EMPTY,
            Roi {
                x0: 0,
                y0: 0,
                x1: 5,
                y1: 5,
            },
            Roi {
                x0: 320,
                y0: 240,
                x1: 328,
                y1: 248,
            },
        ] {
            // A flat frame has no peak: the box comes back unchanged.
            assert_eq!(half_max_box(&frame, roi, 1), roi);
        }
    }
}
