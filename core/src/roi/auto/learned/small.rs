//! Stage 2d: a small target over deep space, searched at the pixel scale. When stage 2c
//! takes the window for deep space but no cell departs as a target's, a far target of
//! 3–12 px may still be there: its 8-px cell mean moves by a fraction of its contrast
//! (a 20-px target of 14 clutter σ by about 4 of the cells' spreads, under stage 2c's
//! threshold of 6), while its pixels stand far above the camera's noise. Behind it
//! there is only the camera's own signal: a shading smooth over the frame and the
//! cell-scale field (about 30 px, `host` docs/camera-model.md), both nearly flat within
//! 11 px.
//!
//! So each pixel's local contrast is measured against a ring: z = (mean of its 3×3 −
//! mean of the 11×11 square less the 5×5) / (σ/3), σ the window's pixel noise and σ/3
//! the noise of a 3×3 mean; only a warmer departure counts (nothing in the scene is
//! colder than deep space). The strongest z of at least [`MIN_Z`] wins, where at least
//! [`MIN_BRIGHT_PX`] pixels of the 3×3 stand [`BRIGHT_SIGMA`] σ above the ring (a single
//! hot pixel, the real camera's signature, does not). Its box grows from the centre of
//! that 3×3 while a pixel just outside a side stands [`BOX_SIGMA`] σ above the ring (and
//! [`BOX_PEAK_FRACTION`] of the peak): over deep space nothing but the target does, so
//! its fainter faces are kept (a cut at half the peak dropped them); a box that reaches
//! [`SEARCH_HALF_PX`] from the peak is no small target.
//!
//! Compared on family A (`docs/detectors.md` § Session 30): the grown box against a
//! half-maximum cut (which dropped the fainter faces), [`BOX_SIGMA`] 3/4/6 and
//! [`BOX_PEAK_FRACTION`] 4/8/16 (within 0.001 but 6σ), [`MIN_Z`] 6–12 (the same boxes:
//! not binding). Set by their reason: those values, the ring (inside the field's
//! scale, outside a 12-px target's blur), the bright-pixel rule and the reach.
//! Off by default from session 30 to 67 (`AutoV2::small_target`): at [`MIN_Z`] 8 it
//! boxed the real camera's own departures (the real dark frame's left-edge columns and
//! a bump), and its boxes hit under the gate. On since session 68: [`MIN_Z`] 12,
//! [`MIN_SIDE_PX`] and [`BOX_SIGMA`] 2, chosen on family A (§ Session 68).
//!
//! Memory: three rows of `u32` column sums the caller lends (`auto-v2`'s integral
//! planes, filled after this stage). Cost: per pixel three column sums updated by a
//! row entering and one leaving, three running row sums and a comparison; the bright
//! count only where z reaches [`MIN_Z`].

use crate::frame::Frame;
use crate::roi::Roi;
use crate::roi::adaptive::{add_row, sub_row};
use crate::roi::plane::Window;

/// Least local contrast of a small target, in noise σ of a 3×3 mean: a Gaussian
/// exceeds 8 σ once in 10¹⁵ draws, so over the 81 000 windows of a frame noise alone
/// never does; what remains is the camera's own: its cell-scale field and hot-pixel
/// clusters, which on family A's target-less deep space (famAE, famAF) reach 8–11 σ
/// at the 3×3 scale, while its far targets of signal-to-clutter ≥ 3 stand 12 σ and
/// more. 12 since session 68 (8 before), chosen on family A (seeds 7001–7201, stage 2d
/// on, its boxes at 4 σ, `docs/detectors.md` § Session 68): 8 (2-px boxes allowed) /
/// 10 / **12** / 14 / 16 → summed mean IoU +0.0269 / +0.0237 / **+0.0233** / +0.0212 /
/// +0.0201 against the stage off, false alarms on famAE 18 / 7 / **6** / 6 / 6 of 300
/// (6 with the stage off); the lowest value that adds none there.
pub const MIN_Z: u32 = 12;

/// Narrowest box of stage 2d, px (each side): the optics blur a point of the scene over
/// 3 px or more, and the module's far targets span 3–12 px; a departure 2 px wide is
/// the sensor's own (a pair of hot pixels, a speck of the field). Session 68, chosen
/// with [`MIN_Z`] on family A: at 2 px a Tango frame's speck is boxed (famAT 0 → 1
/// false alarm of 30), at 4 px the summed mean IoU falls 0.0233 → 0.0169.
pub const MIN_SIDE_PX: u16 = 3;

/// Side of the inner square, px (a 3-px target fills it).
pub const INNER_PX: usize = 3;

/// Side of the square the ring leaves out, px (a 5-px target's core and its blur).
pub const HOLE_PX: usize = 5;

/// Side of the ring's outer square, px: within it the field (correlation length
/// ≈ 30 px) and the shading change by a small part of their σ.
pub const RING_PX: usize = 11;

/// Pixels of the 3×3 that must stand [`BRIGHT_SIGMA`] σ above the ring: a target of
/// 3 px or more has them, a hot pixel has one.
pub const MIN_BRIGHT_PX: u32 = 3;

/// Departure of a bright pixel, noise σ.
pub const BRIGHT_SIGMA: u32 = 3;

/// Half side of the square the box may grow in around the peak, px: a target at the
/// near end of the far range (130 m, 14 px) from any of its pixels.
pub const SEARCH_HALF_PX: usize = 14;

/// A pixel joins the box from this many noise σ above the ring. The faint faces of a
/// far target in eclipse lie 2–4 σ above the sky, and at 4 σ (one noise pixel in
/// 30 000, before session 68) the box stopped at its brightest face, inside the truth:
/// on family A 12 of 31 stage-2d boxes hit. At 2 σ a noise pixel joins a side with a
/// few per cent odds, so the box is at times a pixel wider, which costs less than a
/// missing face, and a box that runs on into the noise reaches [`SEARCH_HALF_PX`] and is
/// dropped. Chosen on family A (session 68, with [`MIN_Z`] 12): 4 / 3 / **2** σ →
/// summed mean IoU +0.0233 / +0.0304 / **+0.0280** against the stage off, its boxes'
/// hit rate 12 of 31 / 18 of 33 / **18 of 27**; only at 2 σ does that rate, the
/// boxes' calibrated confidence ([`super::SMALL_TARGET_SCORE_PERMILLE`]), reach the
/// default gate (550 ‰), so only there do the boxes show.
pub const BOX_SIGMA: i64 = 2;

/// … and from this share of the peak's departure, 1/`BOX_PEAK_FRACTION`: the optics'
/// spill beside a bright face stays under it.
pub const BOX_PEAK_FRACTION: i64 = 8;

/// Pixels of the ring: 11² − 5².
const RING_COUNT: i64 = (RING_PX * RING_PX - HOLE_PX * HOLE_PX) as i64;
/// Pixels of the inner square.
const INNER_COUNT: i64 = (INNER_PX * INNER_PX) as i64;

/// Where stage 2d found its candidate: the centre pixel and its z.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidate {
    /// Column of the peak, px (frame coordinates).
    pub x: usize,
    /// Row of the peak, px.
    pub y: usize,
    /// Its local contrast, noise σ of a 3×3 mean (integer part).
    pub z: u32,
    /// Sum of the ring's pixels (its mean times the ring's 96 pixels), DN.
    pub ring_sum: i64,
}

/// Column sums over `rows` rows of the window starting at frame row `top`, into
/// `sums[..w]` (`adaptive`'s row adder, DN clipped to the frame's depth).
fn column_sums(frame: &Frame<'_>, win: Window, top: usize, rows: usize, sums: &mut [u32]) {
    sums.fill(0);
    for y in top..top + rows {
        add_row(sums, win.row(frame, y), frame.max_dn());
    }
}

/// Stage 2d on the window `win` with pixel noise `sigma_dn`: the strongest small
/// target (module docs), or `None` when no pixel reaches [`MIN_Z`] with the bright
/// pixels, the window is under [`RING_PX`] a side or a buffer is shorter than its width.
/// `col_ring`, `col_hole`, `col_inner` are scratch rows of at least the window's width.
pub(crate) fn strongest_small_target(
    frame: &Frame<'_>,
    win: Window,
    sigma_dn: u32,
    col_ring: &mut [u32],
    col_hole: &mut [u32],
    col_inner: &mut [u32],
) -> Option<Candidate> {
    let (w, h) = (win.w, win.h);
    if w < RING_PX || h < RING_PX {
        return None;
    }
    let col_ring = col_ring.get_mut(..w)?;
    let col_hole = col_hole.get_mut(..w)?;
    let col_inner = col_inner.get_mut(..w)?;
    let (r, m, i) = (RING_PX / 2, HOLE_PX / 2, INNER_PX / 2);
    let sigma = i64::from(sigma_dn.max(1));
    // z ≥ MIN_Z ⇔ 9·ring_count·(inner mean − ring mean) ≥ MIN_Z · ring_count · 3 σ.
    let z_unit = RING_COUNT * 3 * sigma;
    let threshold = i64::from(MIN_Z) * z_unit;
    let mut best: Option<(i64, usize, usize, i64)> = None;
    for cy in win.y0 + r..win.y0 + h - r {
        if cy == win.y0 + r {
            column_sums(frame, win, cy - r, RING_PX, col_ring);
            column_sums(frame, win, cy - m, HOLE_PX, col_hole);
            column_sums(frame, win, cy - i, INNER_PX, col_inner);
        } else {
            // Each band one row down: a row in, a row out.
            let max_dn = frame.max_dn();
            for (col, half) in [
                (&mut *col_ring, r),
                (&mut *col_hole, m),
                (&mut *col_inner, i),
            ] {
                add_row(col, win.row(frame, cy + half), max_dn);
                sub_row(col, win.row(frame, cy - half - 1), max_dn);
            }
        }
        // Running sums along the row, centred on column c (window coordinates).
        let sum_of = |cols: &[u32], c: usize, half: usize| -> i64 {
            cols.get(c - half..=c + half)
                .map_or(0, |s| s.iter().map(|&v| i64::from(v)).sum())
        };
        let (mut s_ring, mut s_hole, mut s_inner) = (
            sum_of(col_ring, r, r),
            sum_of(col_hole, r, m),
            sum_of(col_inner, r, i),
        );
        for c in r..w - r {
            if c > r {
                let at = |cols: &[u32], k: usize| cols.get(k).map_or(0, |&v| i64::from(v));
                s_ring += at(col_ring, c + r) - at(col_ring, c - r - 1);
                s_hole += at(col_hole, c + m) - at(col_hole, c - m - 1);
                s_inner += at(col_inner, c + i) - at(col_inner, c - i - 1);
            }
            let ring = s_ring - s_hole;
            let contrast = s_inner * RING_COUNT - ring * INNER_COUNT;
            if contrast < threshold || best.is_some_and(|(b, _, _, _)| contrast <= b) {
                continue;
            }
            // The bright pixels of the 3×3: p − ring mean ≥ BRIGHT_SIGMA σ.
            let bright_at = ring + i64::from(BRIGHT_SIGMA) * sigma * RING_COUNT;
            let mut bright = 0u32;
            for y in cy - i..=cy + i {
                let row = win.row(frame, y);
                for &v in row.get(c - i..=c + i).unwrap_or(&[]) {
                    bright += u32::from(i64::from(v) * RING_COUNT >= bright_at);
                }
            }
            if bright >= MIN_BRIGHT_PX {
                best = Some((contrast, win.x0 + c, cy, ring));
            }
        }
    }
    let (contrast, x, y, ring_sum) = best?;
    Some(Candidate {
        x,
        y,
        z: u32::try_from(contrast.checked_div(z_unit).unwrap_or(0)).unwrap_or(u32::MAX),
        ring_sum,
    })
}

/// The target's box around candidate `c` (module docs): grown from its centre pixel in
/// the window while a pixel just outside a side (the side's span and one pixel beyond
/// each end) departs from the ring's mean by at least [`BOX_SIGMA`] σ and 1 /
/// [`BOX_PEAK_FRACTION`] of the peak's departure. `None` when the box reaches
/// [`SEARCH_HALF_PX`] from the peak (no small target) or the peak does not depart.
pub(crate) fn grown_box(
    frame: &Frame<'_>,
    win: Window,
    c: Candidate,
    sigma_dn: u32,
) -> Option<Roi> {
    let px = |x: usize, y: usize| -> i64 {
        frame
            .row(y)
            .and_then(|r| r.get(x))
            .map_or(0, |&v| i64::from(v))
    };
    // Departures × RING_COUNT (the ring's mean without a division).
    let dep = |x: usize, y: usize| px(x, y) * RING_COUNT - c.ring_sum;
    let (x_lo, y_lo) = (win.x0, win.y0);
    let (x_hi, y_hi) = (win.x0 + win.w, win.y0 + win.h);
    let mut peak = 0i64;
    for y in c.y.saturating_sub(1).max(y_lo)..(c.y + 2).min(y_hi) {
        for x in c.x.saturating_sub(1).max(x_lo)..(c.x + 2).min(x_hi) {
            peak = peak.max(dep(x, y));
        }
    }
    let sigma = i64::from(sigma_dn.max(1));
    let cut = (BOX_SIGMA * sigma * RING_COUNT).max(peak / BOX_PEAK_FRACTION);
    if peak < cut {
        return None;
    }
    let joins = |x: usize, y: usize| dep(x, y) >= cut;
    // [x0, x1) × [y0, y1), frame coordinates; starts on the peak pixel alone.
    let (mut x0, mut y0, mut x1, mut y1) = (c.x, c.y, c.x + 1, c.y + 1);
    let reach = SEARCH_HALF_PX;
    loop {
        let mut grown = false;
        let (sx0, sx1) = (x0.saturating_sub(1).max(x_lo), (x1 + 1).min(x_hi));
        let (sy0, sy1) = (y0.saturating_sub(1).max(y_lo), (y1 + 1).min(y_hi));
        if y0 > y_lo && (sx0..sx1).any(|x| joins(x, y0 - 1)) {
            y0 -= 1;
            grown = true;
        }
        if y1 < y_hi && (sx0..sx1).any(|x| joins(x, y1)) {
            y1 += 1;
            grown = true;
        }
        if x0 > x_lo && (sy0..sy1).any(|y| joins(x0 - 1, y)) {
            x0 -= 1;
            grown = true;
        }
        if x1 < x_hi && (sy0..sy1).any(|y| joins(x1, y)) {
            x1 += 1;
            grown = true;
        }
        if c.x - x0 >= reach || x1 - c.x > reach || c.y - y0 >= reach || y1 - c.y > reach {
            return None;
        }
        if !grown {
            break;
        }
    }
    let to_u16 = |v: usize| u16::try_from(v).ok();
    Some(Roi {
        x0: to_u16(x0)?,
        y0: to_u16(y0)?,
        x1: to_u16(x1)?,
        y1: to_u16(y1)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;
    use std::vec::Vec;

    /// A shaded sky with white noise (σ ≈ 3 DN, a fixed pseudo-random sequence), hot
    /// pixels, and optionally a 4×5-px target `contrast` DN above it at (150, 100).
    fn sky(contrast: u16) -> Vec<u16> {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut noise = || {
            // Sum of 4 uniforms on ±3 DN: σ ≈ 3.5 DN.
            (0..4)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state % 7) as i32 - 3
                })
                .sum::<i32>()
        };
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 0..FRAME_HEIGHT {
            for x in 0..FRAME_WIDTH {
                let (dx, dy) = (x as i32 - 164, y as i32 - 124);
                let shading = 1000 + (dx * dx + dy * dy) / 300;
                px[y * FRAME_WIDTH + x] = (shading + noise()) as u16;
            }
        }
        for (x, y) in [(20, 30), (200, 40), (300, 200), (151, 120)] {
            px[y * FRAME_WIDTH + x] += 300;
        }
        for y in 100..105 {
            for x in 150..154 {
                px[y * FRAME_WIDTH + x] += contrast;
            }
        }
        px
    }

    fn run(px: &[u16], sigma: u32) -> Option<Candidate> {
        let frame = Frame::reference(px).unwrap();
        let win = Window::full(&frame);
        let (mut a, mut b, mut c) = (
            std::vec![0u32; FRAME_WIDTH],
            std::vec![0u32; FRAME_WIDTH],
            std::vec![0u32; FRAME_WIDTH],
        );
        strongest_small_target(&frame, win, sigma, &mut a, &mut b, &mut c)
    }

    /// Brute force: the same contrast from direct sums at every pixel.
    fn brute_z(px: &[u16], x: usize, y: usize, sigma: i64) -> i64 {
        let at = |xx: usize, yy: usize| i64::from(px[yy * FRAME_WIDTH + xx]);
        let square = |half: usize| -> i64 {
            (y - half..=y + half)
                .flat_map(|yy| (x - half..=x + half).map(move |xx| (xx, yy)))
                .map(|(xx, yy)| at(xx, yy))
                .sum()
        };
        let ring = square(5) - square(2);
        (square(1) * RING_COUNT - ring * INNER_COUNT) / (RING_COUNT * 3 * sigma)
    }

    #[test]
    fn a_small_target_is_found_and_hot_pixels_are_not() {
        // The sky's noise: a sum of 4 uniforms on −3..=3 DN, σ = √(4 · 4) = 4 DN.
        let px = sky(40);
        let c = run(&px, 4).expect("the target");
        assert!(
            (150..154).contains(&c.x) && (100..105).contains(&c.y),
            "{c:?}"
        );
        assert_eq!(i64::from(c.z), brute_z(&px, c.x, c.y, 4));
        assert!(c.z >= MIN_Z);
        // Its grown box holds the target and, where a noise pixel beside a side
        // passes BOX_SIGMA, at most a pixel more on that side.
        let frame = Frame::reference(&px).unwrap();
        let b = grown_box(&frame, Window::full(&frame), c, 4).expect("a box");
        assert!(
            b.x0 <= 150 && b.y0 <= 100 && b.x1 >= 154 && b.y1 >= 105,
            "{b:?}"
        );
        assert!(
            b.x0 >= 149 && b.y0 >= 99 && b.x1 <= 155 && b.y1 <= 106,
            "{b:?}"
        );
        // Without the target: the hot pixels (a 3×3 mean 300 / 9 = 33 DN up, z ≈ 33 /
        // (4 / 3) = 25, but one bright pixel of the 3×3) do not count.
        assert_eq!(run(&sky(0), 4), None);
        // A faint target (12 DN, z ≈ 12 / (4 / 3) = 9) is under MIN_Z.
        assert_eq!(run(&sky(12), 4), None);
    }

    #[test]
    fn small_windows_and_short_buffers_are_no_answer() {
        let px = sky(40);
        let frame = Frame::reference(&px).unwrap();
        let tiny = Window::clipped(&frame, 0, 0, 10, 10).unwrap();
        let mut a = std::vec![0u32; FRAME_WIDTH];
        let mut b = a.clone();
        let mut c = a.clone();
        assert_eq!(
            strongest_small_target(&frame, tiny, 3, &mut a, &mut b, &mut c),
            None
        );
        let mut short = std::vec![0u32; 10];
        let full = Window::full(&frame);
        assert_eq!(
            strongest_small_target(&frame, full, 3, &mut short, &mut b, &mut c),
            None
        );
    }
}
