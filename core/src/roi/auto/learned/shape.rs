//! Statistics of the winning component that do not count the background: its outline's
//! length (compactness), the contrast of its cells against the ring of background
//! cells just around it, in pixel noise σ and in the ring's own spread, and how it meets
//! the frame's edge and how flat its cells are (a target cut by the frame covers a short
//! stretch of the edge and has flat faces; the Earth's side of the limb or a cloud deck
//! runs along the edge, deep into the frame, with texture in its cells). The confidence
//! model (`confidence_weights.rs`) reads them; unlike the number of target-like
//! components in the frame, none of them grows with the clutter elsewhere in the frame
//! (on real GOES texture the forest finds about 5 components per frame, on our renders
//! one).

use super::cells::CELL_PX;
use super::features::log_code;
use crate::frame::Frame;

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
    /// Cell sides of the component on the frame's edge, cells: 0 for a component
    /// inside the frame, the cut's length for a target cut by it, a long stretch for the
    /// Earth's side of the limb.
    pub edge_sides: u16,
    /// How far the component reaches into the frame: the largest distance of one of
    /// its cells from the frame's nearest edge, cells (0: every cell on the edge).
    pub reach_cells: u16,
    /// Sides of the frame its cell box joins to the opposite side (0..=2: left to right,
    /// top to bottom): a cloud deck or a limb runs across the frame, a target rarely.
    pub spans: u8,
    /// [`log_code`] of the standard deviation of its cells' mean DN · 4 / σ: the spread
    /// of levels inside it (flat faces vs texture; edge cells half on the background
    /// raise it for a target too, so it counts against the contrast).
    pub spread_code: u16,
    /// Mean of its cells' step codes (the cell plane's largest two-pixel step, a log
    /// code of σ units, `cells::CellPlanes::step_code`).
    pub step_mean_code: u16,
    /// Its interior cells (all four neighbours in the component), cells.
    pub interior_cells: u16,
    /// Mean step code of its interior cells (0 without one): a target's interior is
    /// its flat faces, a cloud region's is texture.
    pub interior_step_code: u16,
}

/// The statistics of the component whose cells are marked non-zero in `member`
/// (a plane of `plane.0 × plane.1` cells, row-major) with the inclusive cell box
/// `bx = (x0, y0, x_last, y_last)`. `codes` marks target cells of any component
/// (non-zero), which the ring leaves out; `mean_dn` holds the cells' mean DN and
/// `step_code` their step codes; `sigma` is the pixel noise, DN. Slices shorter than the
/// plane read as background (no panic).
pub fn winner_shape(
    member: &[u8],
    codes: &[u8],
    mean_dn: &[u16],
    step_code: &[u8],
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
    let (mut edge_sides, mut reach) = (0u32, 0usize);
    let (mut step_sum, mut interior_n, mut interior_step) = (0u64, 0u64, 0u64);
    let (mut in_sum, mut in_sq, mut in_n) = (0u64, 0u64, 0u64);
    let (mut ring_sum, mut ring_sq, mut ring_n) = (0u64, 0u64, 0u64);
    for y in ry0..=ry1 {
        for x in rx0..=rx1 {
            let i = y * pw + x;
            let m = u64::from(mean_dn.get(i).copied().unwrap_or_default());
            if is_member(x, y) {
                in_sum += m;
                in_sq += m * m;
                in_n += 1;
                let step = u64::from(step_code.get(i).copied().unwrap_or_default());
                step_sum += step;
                // Each side facing a non-member (or the frame's edge) is outline.
                let left = x > 0 && is_member(x - 1, y);
                let right = x + 1 < pw && is_member(x + 1, y);
                let up = y > 0 && is_member(x, y - 1);
                let down = y + 1 < ph && is_member(x, y + 1);
                perimeter +=
                    4 - u32::from(left) - u32::from(right) - u32::from(up) - u32::from(down);
                edge_sides += u32::from(x == 0)
                    + u32::from(y == 0)
                    + u32::from(x + 1 >= pw)
                    + u32::from(y + 1 >= ph);
                let to_edge = x
                    .min(y)
                    .min(pw.saturating_sub(x + 1))
                    .min(ph.saturating_sub(y + 1));
                reach = reach.max(to_edge);
                if left && right && up && down {
                    interior_n += 1;
                    interior_step += step;
                }
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
    let in_spread = (in_sq / in_n).saturating_sub(inner * inner).isqrt();
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
    let to_u16 = |v: u64| v.min(u64::from(u16::MAX)) as u16;
    let spans = u8::from(x0 == 0 && x1 + 1 >= pw) + u8::from(y0 == 0 && y1 + 1 >= ph);
    WinnerShape {
        perimeter_cells: to_u16(u64::from(perimeter)),
        contrast_code: code(diff, sigma),
        clutter_code: code(diff, spread),
        edge_sides: to_u16(u64::from(edge_sides)),
        reach_cells: to_u16(reach as u64),
        spans,
        spread_code: code(in_spread, sigma),
        step_mean_code: to_u16(step_sum / in_n),
        interior_cells: to_u16(interior_n),
        interior_step_code: to_u16(interior_step.checked_div(interior_n).unwrap_or(0)),
    }
}

/// A second difference along a row above this many pixel σ is "rough": the second
/// difference of pure noise has a standard deviation of √6 σ ≈ 2.45 σ, so 8 σ is
/// 3.3 of those (about 0.1 % of noise pixels); cloud texture at the pixel scale and a
/// boundary's few pixels exceed it, a spacecraft face's interior does not (session 33:
/// median over the box's cells, hits 9 %, false alarms 41 % of their pixels).
pub const ROUGH_SIGMAS: u32 = 8;

/// At most this many of the component's cells are read for its roughness (evenly
/// spaced in raster order): 16 cells × 64 pixels bound the work per rated component
/// (stage 4b rates up to `MAX_CANDIDATES`), whatever its size.
pub const ROUGH_MAX_CELLS: usize = 16;

/// The component's roughness, ‰: the share of rough pixels ([`ROUGH_SIGMAS`]) among the
/// pixels of at most [`ROUGH_MAX_CELLS`] of its 8×8 cells, taken evenly over the
/// `members` cells marked non-zero in `member` (a plane of `plane_w` cells per row over
/// the window `(x0, y0)` of `frame`, pixels). Second differences along rows, each pixel
/// clamped to the frame's top DN; the frame's first and last columns are skipped. The
/// Earth's limb piece or a cloud deck is rough inside, a target's faces are flat, but
/// its outline's pixels count too (a few per row of each edge cell): over family A's
/// components the outline dominates and the confidence weighs roughness positively
/// (docs/detectors.md § Session 33). 0 without a cell read.
///
/// Kept out of line: inlined (through `rate_component` into `run_in`) it cost the M7
/// +0.37 M instructions on every embedded frame (`scripts/flight.sh`: `run_in`'s hot
/// loops spill more; deep space 11.60 → 11.98 M), out of line +0.01–0.03 M (its own
/// work: at most 3 candidates × 16 cells × 64 pixels).
#[inline(never)]
pub fn roughness_permille(
    frame: &Frame<'_>,
    (x0, y0): (usize, usize),
    member: &[u8],
    plane_w: usize,
    members: usize,
    sigma: u32,
) -> u16 {
    let stride = members.div_ceil(ROUGH_MAX_CELLS).max(1);
    let top = frame.max_dn();
    let thr = i32::try_from(sigma.saturating_mul(ROUGH_SIGMAS)).unwrap_or(i32::MAX);
    let (mut rough, mut px) = (0u32, 0u32);
    let mut seen = 0usize;
    for (i, _) in member.iter().enumerate().filter(|&(_, &m)| m != 0) {
        seen += 1;
        if (seen - 1) % stride != 0 {
            continue;
        }
        let (cx, cy) = (i % plane_w.max(1), i / plane_w.max(1));
        let xa = (x0 + cx * CELL_PX).max(1);
        let xb = (x0 + cx * CELL_PX + CELL_PX).min(frame.width().saturating_sub(1));
        for y in y0 + cy * CELL_PX..(y0 + cy * CELL_PX + CELL_PX).min(frame.height()) {
            let Some(row) = frame.row(y).and_then(|r| r.get(xa - 1..xb + 1)) else {
                continue;
            };
            // The triples (x − 1, x, x + 1) as three zipped slices: no bounds checks.
            let (Some(mid), Some(right)) = (row.get(1..), row.get(2..)) else {
                continue;
            };
            for ((&a, &b), &c) in row.iter().zip(mid).zip(right) {
                let (a, b, c) = (
                    i32::from(a.min(top)),
                    i32::from(b.min(top)),
                    i32::from(c.min(top)),
                );
                rough += u32::from((a - 2 * b + c).abs() > thr);
            }
            px += right.len() as u32;
        }
    }
    (u64::from(rough) * 1000 / u64::from(px.max(1))) as u16
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
        let s = winner_shape(&member, &codes, &mean, &[], (pw, ph), (4, 3, 6, 4), 40);
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
        let l = winner_shape(&line, &line, &mean, &[], (pw, ph), (0, 0, 4, 0), 40);
        assert_eq!(l.perimeter_cells, 12);
        // Nothing marked: all zero; short slices: no panic.
        let none = winner_shape(&[], &[], &[], &[], (pw, ph), (0, 0, 9, 7), 40);
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
        let s = winner_shape(&member, &member, &mean, &[], (pw, ph), (2, 2, 2, 2), 16);
        assert_eq!(s.perimeter_cells, 4);
        assert_eq!(s.contrast_code as i32, log_code(64 * 4 / 16));
        assert_eq!(s.clutter_code as i32, log_code(64 * 4 / 2));
    }

    /// Every statistic against a brute force over the whole plane (not the ring box the
    /// function scans): random member sets (not necessarily connected), random other
    /// components, levels and step codes, on planes of 1×1 to 12×9 cells.
    #[test]
    fn every_statistic_equals_brute_force_on_random_planes() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n.max(1)
        };
        for _ in 0..400 {
            let (pw, ph) = (1 + rnd(12) as usize, 1 + rnd(9) as usize);
            let n = pw * ph;
            let density = 1 + rnd(4);
            let mut member = std::vec![0u8; n];
            let mut codes = std::vec![0u8; n];
            let mut mean = std::vec![0u16; n];
            let mut step = std::vec![0u8; n];
            // The members inside a random box, the other components anywhere else.
            let (bx0, by0) = (rnd(pw as u64) as usize, rnd(ph as u64) as usize);
            let (bx1, by1) = (
                bx0 + rnd((pw - bx0) as u64) as usize,
                by0 + rnd((ph - by0) as u64) as usize,
            );
            for y in 0..ph {
                for x in 0..pw {
                    let i = y * pw + x;
                    mean[i] = rnd(4000) as u16;
                    step[i] = rnd(200) as u8;
                    if (bx0..=bx1).contains(&x) && (by0..=by1).contains(&y) && rnd(4) < density {
                        member[i] = 1;
                        codes[i] = 1 + rnd(9) as u8;
                    } else if rnd(6) == 0 {
                        codes[i] = 1 + rnd(9) as u8;
                    }
                }
            }
            let sigma = 1 + rnd(300) as u32;
            let got = winner_shape(
                &member,
                &codes,
                &mean,
                &step,
                (pw, ph),
                (bx0, by0, bx1, by1),
                sigma,
            );
            let cells: std::vec::Vec<(usize, usize)> = (0..n)
                .filter(|&i| member[i] != 0)
                .map(|i| (i % pw, i / pw))
                .collect();
            if cells.is_empty() {
                assert_eq!(got, WinnerShape::default());
                continue;
            }
            let m = |x: isize, y: isize| {
                x >= 0
                    && y >= 0
                    && (x as usize) < pw
                    && (y as usize) < ph
                    && member[y as usize * pw + x as usize] != 0
            };
            let mut want = WinnerShape::default();
            let (mut per, mut edge, mut reach) = (0u16, 0u16, 0u16);
            let (mut steps, mut interior, mut interior_steps) = (0u64, 0u64, 0u64);
            for &(x, y) in &cells {
                let (xi, yi) = (x as isize, y as isize);
                let nb = [(xi - 1, yi), (xi + 1, yi), (xi, yi - 1), (xi, yi + 1)];
                let inside = nb.iter().filter(|&&(a, b)| m(a, b)).count();
                per += 4 - inside as u16;
                // A neighbour off the plane is the frame's edge.
                edge += nb
                    .iter()
                    .filter(|&&(a, b)| a < 0 || b < 0 || a as usize >= pw || b as usize >= ph)
                    .count() as u16;
                reach = reach.max([x, y, pw - 1 - x, ph - 1 - y].into_iter().min().unwrap() as u16);
                steps += u64::from(step[y * pw + x]);
                if inside == 4 {
                    interior += 1;
                    interior_steps += u64::from(step[y * pw + x]);
                }
            }
            let k = cells.len() as u64;
            let vals: std::vec::Vec<u64> = cells
                .iter()
                .map(|&(x, y)| u64::from(mean[y * pw + x]))
                .collect();
            let inner = vals.iter().sum::<u64>() / k;
            let in_sd = (vals.iter().map(|v| v * v).sum::<u64>() / k - inner * inner).isqrt();
            // The ring: the box grown by one cell, non-members of no component.
            let ring: std::vec::Vec<u64> = (by0.saturating_sub(1)..=(by1 + 1).min(ph - 1))
                .flat_map(|y| (bx0.saturating_sub(1)..=(bx1 + 1).min(pw - 1)).map(move |x| (x, y)))
                .filter(|&(x, y)| member[y * pw + x] == 0 && codes[y * pw + x] == 0)
                .map(|(x, y)| u64::from(mean[y * pw + x]))
                .collect();
            let s = u64::from(sigma);
            let (diff, sd) = if ring.is_empty() {
                (0, 0)
            } else {
                let r = ring.iter().sum::<u64>() / ring.len() as u64;
                let v = ring.iter().map(|v| v * v).sum::<u64>() / ring.len() as u64 - r * r;
                (inner.abs_diff(r), v.isqrt())
            };
            let code = |d: u64, unit: u64| log_code((d * 4 / unit) as u32) as u16;
            want.perimeter_cells = per;
            want.contrast_code = code(diff, s);
            want.clutter_code = code(diff, sd.max(s / 8).max(1));
            want.edge_sides = edge;
            want.reach_cells = reach;
            want.spans = u8::from(bx0 == 0 && bx1 == pw - 1) + u8::from(by0 == 0 && by1 == ph - 1);
            want.spread_code = code(in_sd, s);
            want.step_mean_code = (steps / k) as u16;
            want.interior_cells = interior as u16;
            // Floating-point mean, floored (0 without an interior cell).
            want.interior_step_code =
                (interior_steps as f64 / (interior as f64).max(1.0)).floor() as u16;
            assert_eq!(
                got, want,
                "plane {pw}x{ph}, box ({bx0},{by0})-({bx1},{by1})"
            );
        }
    }

    /// A component cut by the frame's left edge against one running along the bottom
    /// edge from side to side: the edge statistics tell them apart.
    #[test]
    fn a_cut_target_and_a_band_along_the_edge() {
        let (pw, ph) = (10usize, 8usize);
        let mean = std::vec![100u16; pw * ph];
        let mut cut = std::vec![0u8; pw * ph];
        for y in 3..6 {
            for x in 0..2 {
                cut[y * pw + x] = 1;
            }
        }
        let c = winner_shape(&cut, &cut, &mean, &[], (pw, ph), (0, 3, 1, 5), 8);
        assert_eq!((c.edge_sides, c.reach_cells, c.spans), (3, 1, 0));
        let mut band = std::vec![0u8; pw * ph];
        band[6 * pw..].fill(1);
        let b = winner_shape(&band, &band, &mean, &[], (pw, ph), (0, 6, 9, 7), 8);
        // Bottom row (10 sides), the two rows' left and right ends (4): 14.
        assert_eq!((b.edge_sides, b.reach_cells, b.spans), (14, 1, 1));
        assert_eq!(b.interior_cells, 0);
    }
    /// Brute force on random frames: the cells read are every `stride`-th member in
    /// raster order (at most [`ROUGH_MAX_CELLS`]), each pixel with both row neighbours
    /// in the frame counts, rough when |v(x−1) − 2v(x) + v(x+1)| > 8σ after clamping;
    /// a window offset and cells cut by the frame's edge included.
    #[test]
    fn roughness_equals_brute_force() {
        use crate::sensor::rng::Xoshiro128pp;
        let mut rng = Xoshiro128pp::seed_from_u64(33);
        for round in 0..200 {
            let (w, h) = (
                20 + (rng.next_u32() % 60) as usize,
                20 + (rng.next_u32() % 50) as usize,
            );
            let top = 4095u16;
            let scale = [0u32, 30, 300, 5000][round % 4];
            let pixels: std::vec::Vec<u16> = (0..w * h)
                .map(|_| {
                    let v = (1000 + rng.next_u32() % (scale + 1)) as u16;
                    if rng.next_u32() % 50 == 0 { 5000 } else { v }
                })
                .collect();
            let frame = Frame::new(&pixels, w, h, 12).unwrap();
            let (x0, y0) = ((rng.next_u32() % 5) as usize, (rng.next_u32() % 5) as usize);
            let (pw, ph) = ((w - x0).div_ceil(8), (h - y0).div_ceil(8));
            let member: std::vec::Vec<u8> = (0..pw * ph)
                .map(|_| u8::from(rng.next_u32() % 3 == 0))
                .collect();
            let members = member.iter().filter(|&&m| m != 0).count();
            let sigma = 1 + rng.next_u32() % 40;
            let got = roughness_permille(&frame, (x0, y0), &member, pw, members, sigma);
            let stride = members.div_ceil(ROUGH_MAX_CELLS).max(1);
            let (mut rough, mut px) = (0u64, 0u64);
            let read: std::vec::Vec<usize> = (0..pw * ph)
                .filter(|&i| member[i] != 0)
                .step_by(stride)
                .collect();
            assert!(read.len() <= ROUGH_MAX_CELLS);
            let at = |x: usize, y: usize| i64::from(pixels[y * w + x].min(top));
            for i in read {
                let (cx, cy) = (i % pw, i / pw);
                for y in y0 + cy * 8..(y0 + cy * 8 + 8).min(h) {
                    for x in x0 + cx * 8..(x0 + cx * 8 + 8).min(w) {
                        if x == 0 || x + 1 >= w {
                            continue;
                        }
                        let d2 = at(x - 1, y) - 2 * at(x, y) + at(x + 1, y);
                        rough += u64::from(d2.abs() > i64::from(8 * sigma));
                        px += 1;
                    }
                }
            }
            let want = rough * 1000 / px.max(1);
            assert_eq!(u64::from(got), want, "{w}x{h} at {x0},{y0}, σ {sigma}");
        }
        // Flat faces are smooth, noise at σ is almost never rough, a checkerboard is.
        let flat = std::vec![700u16; 64 * 64];
        let f = Frame::new(&flat, 64, 64, 12).unwrap();
        let all = std::vec![1u8; 64];
        assert_eq!(roughness_permille(&f, (0, 0), &all, 8, 64, 2), 0);
        let board: std::vec::Vec<u16> = (0..64 * 64)
            .map(|i| if (i % 64 + i / 64) % 2 == 0 { 100 } else { 300 })
            .collect();
        let f = Frame::new(&board, 64, 64, 12).unwrap();
        assert!(roughness_permille(&f, (0, 0), &all, 8, 64, 2) > 950);
    }
}
