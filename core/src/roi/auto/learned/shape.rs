//! Statistics of the winning component that do not count the background: its outline's
//! length (compactness) and the contrast of its cells against the ring of background
//! cells just around it, in pixel noise σ and in the ring's own spread. The confidence
//! model (`confidence_weights.rs`) reads them; unlike the number of target-like
//! components in the frame, none of them grows with the clutter elsewhere in the frame
//! (on real GOES texture the forest finds about 5 components per frame, on our renders
//! one).

use super::features::log_code;

/// Width of the ring of background cells around the winner's cell box, cells: one cell
/// (8 px) is the nearest background whose level the target's border must stand out
/// against; wider rings mix in the texture farther away.
pub const RING_CELLS: usize = 1;

/// A cell mean averages 64 pixels, so its noise is σ / 8: the floor of the ring's
/// spread (a ring of flat sky must not give an infinite contrast).
const CELL_MEAN_NOISE_DIVISOR: u64 = 8;

/// The winner's shape and border statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WinnerShape {
    /// Cell sides between the component and anything else (other cells or the frame's
    /// edge), cells: 4 for one cell, 4·√n for a square of n cells, 2n + 2 for a line.
    pub perimeter_cells: u16,
    /// [`log_code`] of |mean DN of the component's cells − mean DN of the ring| · 4 / σ
    /// (pixel noise σ): 16 per doubling, 0 for no contrast.
    pub contrast_code: u16,
    /// [`log_code`] of the same difference · 4 / the ring's spread (the standard
    /// deviation of its cell means, at least σ / 8): the contrast in clutter units.
    pub clutter_code: u16,
}

/// The statistics of the component whose cells are marked non-zero in `member`
/// (a plane of `plane.0 × plane.1` cells, row-major) with the inclusive cell box
/// `bx = (x0, y0, x_last, y_last)`. `codes` marks target cells of any component
/// (non-zero), which the ring leaves out; `mean_dn` holds the cells' mean DN; `sigma` is
/// the pixel noise, DN. Slices shorter than the plane read as background (no panic).
pub fn winner_shape(
    member: &[u8],
    codes: &[u8],
    mean_dn: &[u16],
    plane: (usize, usize),
    bx: (usize, usize, usize, usize),
    sigma: u32,
) -> WinnerShape {
    let (pw, ph) = plane;
    let is_member = |x: usize, y: usize| member.get(y * pw + x).is_some_and(|&m| m != 0);
    let (x0, y0, x1, y1) = bx;
    let (rx0, ry0) = (x0.saturating_sub(RING_CELLS), y0.saturating_sub(RING_CELLS));
    let (rx1, ry1) = (
        (x1 + RING_CELLS).min(pw.saturating_sub(1)),
        (y1 + RING_CELLS).min(ph.saturating_sub(1)),
    );
    let mut perimeter = 0u32;
    let (mut in_sum, mut in_n) = (0u64, 0u64);
    let (mut ring_sum, mut ring_sq, mut ring_n) = (0u64, 0u64, 0u64);
    for y in ry0..=ry1 {
        for x in rx0..=rx1 {
            let i = y * pw + x;
            let m = u64::from(mean_dn.get(i).copied().unwrap_or_default());
            if is_member(x, y) {
                in_sum += m;
                in_n += 1;
                // Each side facing a non-member (or the frame's edge) is outline.
                let left = x > 0 && is_member(x - 1, y);
                let right = x + 1 < pw && is_member(x + 1, y);
                let up = y > 0 && is_member(x, y - 1);
                let down = y + 1 < ph && is_member(x, y + 1);
                perimeter +=
                    4 - u32::from(left) - u32::from(right) - u32::from(up) - u32::from(down);
            } else if codes.get(i).is_some_and(|&c| c == 0) {
                ring_sum += m;
                ring_sq += m * m;
                ring_n += 1;
            }
        }
    }
    if in_n == 0 {
        return WinnerShape::default();
    }
    let inner = in_sum / in_n;
    let (diff, spread) = match ring_sum.checked_div(ring_n) {
        Some(ring) => {
            let var = (ring_sq / ring_n).saturating_sub(ring * ring);
            (inner.abs_diff(ring), var.isqrt())
        }
        // No background around it (the component fills the frame): no contrast.
        None => (0, 0),
    };
    let sigma = u64::from(sigma.max(1));
    let spread = spread.max(sigma / CELL_MEAN_NOISE_DIVISOR).max(1);
    let code = |d: u64, unit: u64| {
        log_code((d.saturating_mul(4) / unit).min(u64::from(u32::MAX)) as u32).clamp(0, 1000) as u16
    };
    WinnerShape {
        perimeter_cells: perimeter.min(u32::from(u16::MAX)) as u16,
        contrast_code: code(diff, sigma),
        clutter_code: code(diff, spread),
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Brute force over a plane: a 3×2 block of member cells at level 500 on a ring of
    /// alternating 100 / 140 (mean 120, spread 20), with another component's cell at
    /// 900 in the ring that must be left out.
    #[test]
    fn shape_equals_brute_force() {
        let (pw, ph) = (10usize, 8usize);
        let mut member = std::vec![0u8; pw * ph];
        let mut codes = std::vec![0u8; pw * ph];
        let mut mean = std::vec![0u16; pw * ph];
        for y in 0..ph {
            for x in 0..pw {
                mean[y * pw + x] = if (x + y) % 2 == 0 { 100 } else { 140 };
            }
        }
        for y in 3..5 {
            for x in 4..7 {
                member[y * pw + x] = 1;
                codes[y * pw + x] = 9;
                mean[y * pw + x] = 500;
            }
        }
        codes[2 * pw + 3] = 5;
        mean[2 * pw + 3] = 900;
        let s = winner_shape(&member, &codes, &mean, (pw, ph), (4, 3, 6, 4), 40);
        // A 3×2 rectangle: outline 2·(3 + 2) cell sides.
        assert_eq!(s.perimeter_cells, 10);
        // Ring: the 5×4 box minus the 6 members minus the other component's cell: 13
        // cells of the checkerboard, 7 of one colour and 6 of the other.
        let ring: std::vec::Vec<u64> = (2..6)
            .flat_map(|y| (3..8).map(move |x| (x, y)))
            .filter(|&(x, y)| member[y * pw + x] == 0 && codes[y * pw + x] == 0)
            .map(|(x, y)| u64::from(mean[y * pw + x]))
            .collect();
        assert_eq!(ring.len(), 13);
        let rm = ring.iter().sum::<u64>() / 13;
        let var = ring.iter().map(|v| v * v).sum::<u64>() / 13 - rm * rm;
        let sd = (var as f64).sqrt().floor() as u64;
        assert_eq!(
            s.contrast_code as i32,
            log_code(((500 - rm) * 4 / 40) as u32)
        );
        assert_eq!(
            s.clutter_code as i32,
            log_code(((500 - rm) * 4 / sd) as u32)
        );
        // A line of 5 cells along the frame's top edge: 2·5 + 2 sides, frame edge included.
        let mut line = std::vec![0u8; pw * ph];
        line[..5].fill(1);
        let l = winner_shape(&line, &line, &mean, (pw, ph), (0, 0, 4, 0), 40);
        assert_eq!(l.perimeter_cells, 12);
        // Nothing marked: all zero; short slices: no panic.
        let none = winner_shape(&[], &[], &[], (pw, ph), (0, 0, 9, 7), 40);
        assert_eq!(none, WinnerShape::default());
    }

    /// A flat ring: the spread is floored at σ / 8, so the clutter contrast is finite
    /// and equals the noise contrast × 8.
    #[test]
    fn flat_ring_floors_the_spread() {
        let (pw, ph) = (5usize, 5usize);
        let mut member = std::vec![0u8; pw * ph];
        let mut mean = std::vec![200u16; pw * ph];
        member[12] = 1;
        mean[12] = 264;
        let s = winner_shape(&member, &member, &mean, (pw, ph), (2, 2, 2, 2), 16);
        assert_eq!(s.perimeter_cells, 4);
        assert_eq!(s.contrast_code as i32, log_code(64 * 4 / 16));
        assert_eq!(s.clutter_code as i32, log_code(64 * 4 / 2));
    }
}
