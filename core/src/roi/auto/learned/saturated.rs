//! The box of a saturated target. A target far hotter than the top DN saturates every
//! pixel the optics' point-spread function carries any of its light to: the
//! saturated blob is the target's outline dilated by the kernel's reach (2 px for the
//! TIR's 5×5 kernel), plus the target's edge pixels that it covers less than half.
//! The truth (pixels at least half covered) lies inside, about
//! [`PSF_RADIUS_PX`] + ½ px in from each side, and no pixel value inside the blob
//! says where (they are all at the top DN). So a box that is the saturated blob (plus
//! at most its halo) is cut by a fixed number of pixels per side, chosen on our
//! family-A renders (`AutoV2::saturated_erode_px`); a side on the frame's edge is
//! kept (the target goes on beyond it).

use crate::frame::Frame;
use crate::roi::Roi;

/// Reach of the optics' point-spread function, px: the half-width of the TIR's 5×5
/// kernel (`tirroi-host` `imaging/psf.rs`, `PSF_RADIUS_PX`): light falls at most this
/// far from the pixel it came from.
pub const PSF_RADIUS_PX: u16 = 2;

/// Fewest pixels at the top DN for a box to count as a saturated blob: a 2×2 core (hot
/// pixels come alone).
pub const MIN_BLOB_PX: u32 = 4;

/// The box of the pixels of `roi` at the frame's top DN and how many there are.
fn saturated_hull(frame: &Frame<'_>, roi: Roi) -> (Roi, u32) {
    let top = frame.max_dn();
    let mut hull = Roi::EMPTY;
    let mut n = 0u32;
    let (x0, x1) = (usize::from(roi.x0), usize::from(roi.x1));
    for y in usize::from(roi.y0)..usize::from(roi.y1) {
        let Some(row) = frame.row(y).and_then(|r| r.get(x0..x1)) else {
            continue;
        };
        for (i, &v) in row.iter().enumerate() {
            if v < top {
                continue;
            }
            let (x, y) = ((x0 + i) as u16, y as u16);
            hull = if n == 0 {
                Roi {
                    x0: x,
                    y0: y,
                    x1: x + 1,
                    y1: y + 1,
                }
            } else {
                Roi {
                    x0: hull.x0.min(x),
                    y0: hull.y0.min(y),
                    x1: hull.x1.max(x + 1),
                    y1: hull.y1.max(y + 1),
                }
            };
            n += 1;
        }
    }
    (hull, n)
}

/// Cuts `[a, b)` by `e` px at each end that is not on the frame's edge (`a == 0`,
/// `b == limit`), keeping at least 1 px (the middle one).
fn cut_span(a: u16, b: u16, e: u16, limit: u16) -> (u16, u16) {
    let ea = if a == 0 { 0 } else { e };
    let eb = if b >= limit { 0 } else { e };
    let w = b - a;
    if ea + eb < w {
        (a + ea, b - eb)
    } else {
        // Nothing would be left: the pixel at the kept end, else the middle one.
        let mid = if ea == 0 {
            a
        } else if eb == 0 {
            b - 1
        } else {
            a + (w - 1) / 2
        };
        (mid, mid + 1)
    }
}

/// The box of the saturated pixels of `roi` when `roi` is a saturated blob: at least
/// [`MIN_BLOB_PX`] pixels at the top DN, `roi` reaching at most [`PSF_RADIUS_PX`] + 1
/// px beyond their box on every side (the blob and its halo, not a larger body with a
/// saturated face); `None` otherwise.
fn blob_hull(frame: &Frame<'_>, roi: Roi) -> Option<Roi> {
    if roi.x1 <= roi.x0 || roi.y1 <= roi.y0 {
        return None;
    }
    let (hull, n) = saturated_hull(frame, roi);
    if n < MIN_BLOB_PX {
        return None;
    }
    let reach = PSF_RADIUS_PX + 1;
    // The hull lies inside `roi` (it holds ≥ 4 of its pixels): no underflow.
    let halo_only = hull.x0 - roi.x0 <= reach
        && hull.y0 - roi.y0 <= reach
        && roi.x1 - hull.x1 <= reach
        && roi.y1 - hull.y1 <= reach;
    halo_only.then_some(hull)
}

/// True when `roi` is a saturated blob and its halo ([`saturated_box`] cuts it).
pub fn is_saturated_blob(frame: &Frame<'_>, roi: Roi) -> bool {
    blob_hull(frame, roi).is_some()
}

/// `roi` cut to the saturated target inside it (see the module): when `roi` holds at
/// least [`MIN_BLOB_PX`] pixels at the top DN and reaches at most
/// [`PSF_RADIUS_PX`] + 1 px beyond their box on every side (it is that blob and its
/// halo, not a larger body with a saturated face), the blob's box cut by `erode_px` per
/// side off the frame's edges; otherwise `roi` unchanged. The result lies inside `roi`.
pub fn saturated_box(frame: &Frame<'_>, roi: Roi, erode_px: u16) -> Roi {
    let Some(hull) = blob_hull(frame, roi) else {
        return roi;
    };
    let (fw, fh) = (frame.width() as u16, frame.height() as u16);
    let (x0, x1) = cut_span(hull.x0, hull.x1, erode_px, fw);
    let (y0, y1) = cut_span(hull.y0, hull.y1, erode_px, fh);
    Roi { x0, y0, x1, y1 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;

    /// A brute-force reference of the blob: a sharp rectangle far above the top DN,
    /// blurred by a 5×5 box (every pixel within 2 px of a covered one saturates), is
    /// cut back to the rectangle by 2 px per side, and not on the frame's edge.
    #[test]
    fn a_saturated_blob_is_cut_back_by_the_psf_reach() {
        let top = 4095u32;
        let rect = (100usize, 50usize, 108usize, 56usize);
        let mut px = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        let put = |px: &mut [u16], (rx0, ry0, rx1, ry1): (usize, usize, usize, usize)| {
            for y in 0..FRAME_HEIGHT {
                for x in 0..FRAME_WIDTH {
                    let mut covered = 0u32;
                    for dy in 0..5 {
                        for dx in 0..5 {
                            let (sx, sy) = ((x + dx).wrapping_sub(2), (y + dy).wrapping_sub(2));
                            covered +=
                                u32::from((rx0..rx1).contains(&sx) && (ry0..ry1).contains(&sy));
                        }
                    }
                    if covered > 0 {
                        // Face 100× the top DN: any light saturates.
                        px[y * FRAME_WIDTH + x] = (700 + covered * top * 100 / 25).min(top) as u16;
                    }
                }
            }
        };
        put(&mut px, rect);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        // The blob plus one pixel of halo, as the boundary rule finds it.
        let found = Roi::new(97, 47, 111, 59);
        let got = saturated_box(&frame, found, PSF_RADIUS_PX);
        assert_eq!(got, Roi::new(100, 50, 108, 56));
        // No cut: the blob's box.
        assert_eq!(saturated_box(&frame, found, 0), Roi::new(98, 48, 110, 58));
        // A larger body with a saturated face: unchanged.
        let body = Roi::new(60, 20, 140, 90);
        assert_eq!(saturated_box(&frame, body, 2), body);
        // On the frame's corner: the sides on the edge stay.
        let mut px2 = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        put(&mut px2, (0, 0, 6, 5));
        let frame = Frame::new(&px2, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        assert_eq!(
            saturated_box(&frame, Roi::new(0, 0, 10, 9), 2),
            Roi::new(0, 0, 6, 5)
        );
        // Unsaturated: unchanged.
        let flat = std::vec![700u16; FRAME_WIDTH * FRAME_HEIGHT];
        let frame = Frame::new(&flat, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        assert_eq!(saturated_box(&frame, found, 2), found);
    }

    #[test]
    fn spans_keep_a_pixel_and_stay_inside() {
        for a in 0u16..12 {
            for b in a + 1..20 {
                for e in 0..6 {
                    let (c, d) = cut_span(a, b, e, 20);
                    assert!(a <= c && c < d && d <= b, "{a} {b} {e}: {c} {d}");
                    if a > 0 && b < 20 && 2 * e < b - a {
                        assert_eq!((c, d), (a + e, b - e));
                    }
                }
            }
        }
    }
}
