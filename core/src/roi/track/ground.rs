//! The ground's shift between consecutive frames: block matching of a few textured
//! patches, a flight-sized registration.
//!
//! On the last frame, in each cell of a [`GRID`] × [`GRID`] grid, the [`PATCH_PX`] ×
//! [`PATCH_PX`] patch with the most gradient (top-left corners on a [`LATTICE_PX`]
//! lattice) is kept ([`GroundPatches::capture`]). On the next frame each patch is
//! searched within ±[`SEARCH_PX`] px, least sum of absolute differences with each
//! side's mean removed (a readout whose gain or offset moved between frames does not
//! move the match): first at half resolution (2 × 2 sums, even shifts), then at full
//! resolution ±1 px around the best. The ground's shift is the median of the patches'
//! moves, trusted when at least [`MIN_AGREEING`] of them lie within [`AGREE_PX`] of it
//! ([`GroundPatches::shift_to`]); deep space, whose patches hold only noise, gives no
//! agreement and so no shift.
//!
//! Cost per frame at 328×248: the gradient of the frame once (2 absolute differences
//! per pixel, on every other row) and, per patch, 169 half-resolution positions of 64 differences plus 9
//! full-resolution ones of 256: about 0.25 M differences in all, against 2.6 M for
//! the exhaustive full-resolution search it replaces (`scripts/sequence-confirmation.py
//! --ground patches`). Memory: the patches, [`PATCHES_BYTES`].

use crate::frame::Frame;

/// Patches per axis of the grid: 16 patches, enough that a moving target or a few
/// clouds changing shape leave a majority of patches on the ground.
pub const GRID: usize = 4;

/// Side of a patch, px: cloud texture at 4 km per pixel varies over a few pixels, so
/// 16 × 16 holds several features to match.
pub const PATCH_PX: usize = 16;

/// Largest shift searched per axis, px per frame (the approach sequences of the
/// renderer slide the ground by up to about 5 px per frame; more than twice that for
/// margin). The patches are kept this far from the frame's borders.
pub const SEARCH_PX: usize = 12;

/// Step of the lattice on which patch corners are chosen, px (the gradient is summed
/// over blocks of this side).
pub const LATTICE_PX: usize = 4;

/// A patch's move agrees with the median when each axis lies within this, px.
pub const AGREE_PX: i32 = 1;

/// The median is trusted when at least this many of the [`GRID`]² patches agree with
/// it: half (`scripts/sequence-confirmation.py`: the share 0.25–0.9 gives the same
/// figures on family A and held out; without the check deep space's noise shifts
/// confirm hot pixels).
pub const MIN_AGREEING: usize = GRID * GRID / 2;

const PATCHES: usize = GRID * GRID;
const PATCH_AREA: usize = PATCH_PX * PATCH_PX;
const HALF_PX: usize = PATCH_PX / 2;
/// Half-resolution cells of the search area per axis (the patch and ±[`SEARCH_PX`]).
const AREA_HALF: usize = (PATCH_PX + 2 * SEARCH_PX) / 2;
/// Half-resolution shifts per axis (even shifts −[`SEARCH_PX`]..=[`SEARCH_PX`]).
const HALF_SHIFTS: usize = SEARCH_PX + 1;
/// Blocks of the gradient per patch side.
const PATCH_BLOCKS: usize = PATCH_PX / LATTICE_PX;
/// Most block columns a frame row holds (the core's widest frame, 1024 px, / 4).
const MAX_BLOCK_COLUMNS: usize = 256;

/// Bytes of [`GroundPatches`]: the patches' pixels (16-bit) and corners.
pub const PATCHES_BYTES: usize = core::mem::size_of::<GroundPatches>();

/// The ground's shift from the last frame to this one, px (x right, y down): where
/// the last frame's ground lies now, minus where it lay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GroundShift {
    /// Shift along x, px.
    pub dx_px: i16,
    /// Shift along y, px.
    pub dy_px: i16,
    /// Patches whose move agrees with it ([`AGREE_PX`]), of [`GRID`]².
    pub agreeing: u8,
}

/// The last frame's patches ([`GroundPatches::capture`]).
#[derive(Debug, Clone)]
pub struct GroundPatches {
    pixels: [[u16; PATCH_AREA]; PATCHES],
    /// Top-left corners (x, y), px.
    corners: [(u16, u16); PATCHES],
    /// Patches held: 0 (none yet, or a frame too small) or [`GRID`]².
    count: usize,
    /// The frame size they came from (a frame of another size is not compared).
    size: (usize, usize),
}

impl GroundPatches {
    /// No patches: the next [`Self::shift_to`] gives `None`.
    pub const EMPTY: GroundPatches = GroundPatches {
        pixels: [[0; PATCH_AREA]; PATCHES],
        corners: [(0, 0); PATCHES],
        count: 0,
        size: (0, 0),
    };

    /// Forgets the patches (a new sequence, or a frame not captured).
    pub fn clear(&mut self) {
        self.count = 0;
    }

    /// Whether patches of the last frame are held (else [`Self::shift_to`] has nothing
    /// to compare: a frame too small, or none captured).
    pub fn is_captured(&self) -> bool {
        self.count == PATCHES
    }

    /// Keeps `frame`'s patches: in each grid cell, the patch of most gradient (sum of
    /// |∂x| + |∂y| over its pixels; the first on a tie, rows first). A frame narrower
    /// or lower than 2·[`SEARCH_PX`] + [`PATCH_PX`] + [`GRID`]·[`LATTICE_PX`] px, or
    /// wider than 1 024, keeps none.
    pub fn capture(&mut self, frame: &Frame<'_>) {
        self.count = 0;
        let (w, h) = (frame.width(), frame.height());
        let least = 2 * SEARCH_PX + PATCH_PX + GRID * LATTICE_PX;
        if w < least || h < least || w / LATTICE_PX > MAX_BLOCK_COLUMNS {
            return;
        }
        let (xs, ys) = (lattice_spans(w), lattice_spans(h));
        // Best (gradient, x, y) per cell.
        let mut best = [(0u32, 0usize, 0usize); PATCHES];
        let mut found = [false; PATCHES];
        // Gradient per 4 × 4 block, a ring of the last `PATCH_BLOCKS` block rows.
        let mut ring = [[0u32; MAX_BLOCK_COLUMNS]; PATCH_BLOCKS];
        let first_row = ys[0] / LATTICE_PX;
        let last_row = ys[GRID] / LATTICE_PX + PATCH_BLOCKS;
        let columns = (xs[GRID] / LATTICE_PX + PATCH_BLOCKS).min(MAX_BLOCK_COLUMNS);
        let first_col = xs[0] / LATTICE_PX;
        for by in first_row..last_row {
            let slot = &mut ring[by % PATCH_BLOCKS];
            block_gradients(frame, by, first_col, columns, slot);
            // Each block's sum with the next PATCH_BLOCKS − 1 (a patch row's worth).
            for bx in first_col..columns {
                let end = (bx + PATCH_BLOCKS).min(columns);
                slot[bx] = slot[bx..end].iter().sum();
            }
            // Patches whose top block row is `by - 3`, once all their rows are in.
            let Some(top) = (by + 1).checked_sub(PATCH_BLOCKS) else {
                continue;
            };
            if top < first_row {
                continue;
            }
            let y = top * LATTICE_PX;
            let Some(gy) = (0..GRID).find(|&g| ys[g] <= y && y < ys[g + 1]) else {
                continue;
            };
            for gx in 0..GRID {
                for x in (xs[gx]..xs[gx + 1]).step_by(LATTICE_PX) {
                    let bx = x / LATTICE_PX;
                    let g = ring
                        .iter()
                        .map(|row| row.get(bx).copied().unwrap_or(0))
                        .fold(0u32, u32::saturating_add);
                    let k = gy * GRID + gx;
                    if !found[k] || g > best[k].0 {
                        best[k] = (g, x, y);
                        found[k] = true;
                    }
                }
            }
        }
        if found.iter().any(|f| !f) {
            return;
        }
        for (k, &(_, x, y)) in best.iter().enumerate() {
            for (r, dst) in self.pixels[k].chunks_exact_mut(PATCH_PX).enumerate() {
                match frame.row(y + r).and_then(|row| row.get(x..x + PATCH_PX)) {
                    Some(src) => dst.copy_from_slice(src),
                    None => return,
                }
            }
            self.corners[k] = (x as u16, y as u16);
        }
        self.count = PATCHES;
        self.size = (w, h);
    }

    /// The ground's shift from the captured frame to `frame`, when the patches agree
    /// on one ([`MIN_AGREEING`]); `None` without patches, for a frame of another size
    /// or without agreement.
    pub fn shift_to(&self, frame: &Frame<'_>) -> Option<GroundShift> {
        if self.count != PATCHES || self.size != (frame.width(), frame.height()) {
            return None;
        }
        let mut moves = [(0i32, 0i32); PATCHES];
        for (k, m) in moves.iter_mut().enumerate() {
            *m = self.patch_move(k, frame)?;
        }
        let (mx2, my2) = (
            median_twice(moves.map(|m| m.0)),
            median_twice(moves.map(|m| m.1)),
        );
        // |move − median| ≤ AGREE_PX on both axes, in half pixels (the median of an
        // even count is a half-integer at worst).
        let agreeing = moves
            .iter()
            .filter(|&&(x, y)| {
                (2 * x - mx2).abs() <= 2 * AGREE_PX && (2 * y - my2).abs() <= 2 * AGREE_PX
            })
            .count();
        (agreeing >= MIN_AGREEING).then_some(GroundShift {
            // Toward zero, as the study's `int(np.median(...))`.
            dx_px: (mx2 / 2) as i16,
            dy_px: (my2 / 2) as i16,
            agreeing: agreeing as u8,
        })
    }

    /// Patch `k`'s move on `frame`: the half-resolution search, then ±1 px at full
    /// resolution; `None` if the patch's search area leaves the frame.
    fn patch_move(&self, k: usize, frame: &Frame<'_>) -> Option<(i32, i32)> {
        let (x, y) = self.corners[k];
        let (x, y) = (usize::from(x), usize::from(y));
        let patch = &self.pixels[k];
        // The patch at half resolution (2 × 2 sums) and its sum.
        let mut half = [0u32; HALF_PX * HALF_PX];
        for (i, h) in half.iter_mut().enumerate() {
            let (cx, cy) = (2 * (i % HALF_PX), 2 * (i / HALF_PX));
            let at = |dx: usize, dy: usize| u32::from(patch[(cy + dy) * PATCH_PX + cx + dx]);
            *h = at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1);
        }
        // The search area at half resolution: corner (x, y) − SEARCH_PX.
        let (ax, ay) = (x.checked_sub(SEARCH_PX)?, y.checked_sub(SEARCH_PX)?);
        let mut area = [0u32; AREA_HALF * AREA_HALF];
        for (r, row_cells) in area.chunks_exact_mut(AREA_HALF).enumerate() {
            let top = frame.row(ay + 2 * r)?.get(ax..ax + 2 * AREA_HALF)?;
            let bottom = frame.row(ay + 2 * r + 1)?.get(ax..ax + 2 * AREA_HALF)?;
            for (c, cell) in row_cells.iter_mut().enumerate() {
                *cell = u32::from(top[2 * c])
                    + u32::from(top[2 * c + 1])
                    + u32::from(bottom[2 * c])
                    + u32::from(bottom[2 * c + 1]);
            }
        }
        let half_sum: u32 = half.iter().fold(0, |a, &v| a.wrapping_add(v));
        // Summed-area table of the area: each window's sum in four reads.
        let mut table = [0u32; (AREA_HALF + 1) * (AREA_HALF + 1)];
        for r in 0..AREA_HALF {
            let mut run = 0u32;
            for c in 0..AREA_HALF {
                run = run.wrapping_add(area[r * AREA_HALF + c]);
                table[(r + 1) * (AREA_HALF + 1) + c + 1] =
                    table[r * (AREA_HALF + 1) + c + 1].wrapping_add(run);
            }
        }
        let corner = |r: usize, c: usize| table[r * (AREA_HALF + 1) + c];
        let mut best = (u32::MAX, 0usize, 0usize);
        for sy in 0..HALF_SHIFTS {
            for sx in 0..HALF_SHIFTS {
                let window_sum = corner(sy + HALF_PX, sx + HALF_PX)
                    .wrapping_sub(corner(sy, sx + HALF_PX))
                    .wrapping_sub(corner(sy + HALF_PX, sx))
                    .wrapping_add(corner(sy, sx));
                let offset = rounded_mean_difference(half_sum, window_sum, HALF_PX * HALF_PX);
                let mut cost = 0u32;
                for (r, p) in half.chunks_exact(HALF_PX).enumerate() {
                    let start = (sy + r) * AREA_HALF + sx;
                    let q = area.get(start..start + HALF_PX).unwrap_or(&[]);
                    cost = cost.wrapping_add(sad_row(p, q, offset));
                }
                if cost < best.0 {
                    best = (cost, sx, sy);
                }
            }
        }
        // Full resolution, ±1 px around the even shift found.
        let (cx, cy) = (
            2 * best.1 as i32 - SEARCH_PX as i32,
            2 * best.2 as i32 - SEARCH_PX as i32,
        );
        let patch_sum: u32 = patch.iter().map(|&v| u32::from(v)).sum();
        let mut fine = (u32::MAX, cx, cy);
        for dy in cy - 1..=cy + 1 {
            for dx in cx - 1..=cx + 1 {
                let (Ok(qx), Ok(qy)) = (
                    usize::try_from(x as i32 + dx),
                    usize::try_from(y as i32 + dy),
                ) else {
                    continue;
                };
                let mut rows = [&[][..]; PATCH_PX];
                let mut inside = true;
                for (r, slot) in rows.iter_mut().enumerate() {
                    match frame.row(qy + r).and_then(|row| row.get(qx..qx + PATCH_PX)) {
                        Some(s) => *slot = s,
                        None => inside = false,
                    }
                }
                if !inside {
                    continue;
                }
                let window_sum: u32 = rows
                    .iter()
                    .map(|r| r.iter().map(|&v| u32::from(v)).sum::<u32>())
                    .sum();
                let offset = rounded_mean_difference(patch_sum, window_sum, PATCH_AREA);
                let mut cost = 0u32;
                for (p, q) in patch.chunks_exact(PATCH_PX).zip(rows) {
                    cost = cost.wrapping_add(sad_row(p, q, offset));
                }
                if cost < fine.0 {
                    fine = (cost, dx, dy);
                }
            }
        }
        Some((fine.1, fine.2))
    }
}

/// The lattice spans of the grid along a side of `n` px: cell `g` takes corners
/// `spans[g]..spans[g + 1]` (multiples of [`LATTICE_PX`]), from [`SEARCH_PX`] to
/// where a patch and the search still fit.
fn lattice_spans(n: usize) -> [usize; GRID + 1] {
    let room = n - 2 * SEARCH_PX - PATCH_PX;
    let mut spans = [0; GRID + 1];
    for (g, s) in spans.iter_mut().enumerate() {
        let at = SEARCH_PX + g * room / GRID;
        *s = at - at % LATTICE_PX;
    }
    spans
}

/// Rows of a block whose gradient counts: every other (a patch is chosen by its
/// texture, which half its rows show as well; half the cost of the capture).
const GRADIENT_ROW_STEP: usize = 2;

/// Gradient (|∂x| + |∂y|, forward differences) of block row `by`'s blocks
/// `first..columns` into `out` (by block column), on every [`GRADIENT_ROW_STEP`]th
/// pixel row.
fn block_gradients(frame: &Frame<'_>, by: usize, first: usize, columns: usize, out: &mut [u32]) {
    for b in out.iter_mut() {
        *b = 0;
    }
    let (x0, x1) = (first * LATTICE_PX, columns * LATTICE_PX);
    let Some(blocks) = out.get_mut(first..columns) else {
        return;
    };
    for y in (by * LATTICE_PX..(by + 1) * LATTICE_PX).step_by(GRADIENT_ROW_STEP) {
        let (Some(row), Some(below)) = (frame.row(y), frame.row(y + 1)) else {
            return;
        };
        let (Some(row), Some(below)) = (row.get(x0..=x1), below.get(x0..x1)) else {
            return;
        };
        let Some(right) = row.get(1..) else {
            return;
        };
        for (((b, here), next), under) in blocks
            .iter_mut()
            .zip(row.chunks_exact(LATTICE_PX))
            .zip(right.chunks_exact(LATTICE_PX))
            .zip(below.chunks_exact(LATTICE_PX))
        {
            let mut g = 0u32;
            for i in 0..LATTICE_PX {
                g += u32::from(here[i].abs_diff(next[i])) + u32::from(here[i].abs_diff(under[i]));
            }
            *b += g;
        }
    }
}

/// The mean of `q` minus the mean of `p`, both sums of `n` values, rounded to a whole
/// DN (sums of at most [`PATCH_AREA`] values of at most 18 bits: 32-bit arithmetic).
fn rounded_mean_difference(p_sum: u32, q_sum: u32, n: usize) -> i32 {
    let n = n.max(1) as i32;
    let diff = q_sum as i32 - p_sum as i32;
    (diff + diff.signum() * n / 2) / n
}

/// Σ |p + offset − q| over a row: the sum of absolute differences with the means
/// removed ([`rounded_mean_difference`]). Values of at most 18 bits over at most
/// [`PATCH_AREA`] pixels stay far below 2³²: plain (wrapping) additions.
fn sad_row<P: Copy + Into<u32>, Q: Copy + Into<u32>>(p: &[P], q: &[Q], offset: i32) -> u32 {
    p.iter()
        .zip(q)
        .map(|(&a, &b)| (a.into() as i32 + offset - b.into() as i32).unsigned_abs())
        .fold(0u32, u32::wrapping_add)
}

/// Twice the median of 16 values (the mean of the middle two, doubled: exact).
fn median_twice(mut v: [i32; PATCHES]) -> i32 {
    v.sort_unstable();
    v[PATCHES / 2 - 1] + v[PATCHES / 2]
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::roi::auto::learned::xorshift32;
    use std::vec;
    use std::vec::Vec;

    const W: usize = 328;
    const H: usize = 248;

    /// A textured scene (sums of random square bumps) sampled at an offset: the ground
    /// moved by `offset` px.
    fn scene(offset: (i32, i32), seed: u32) -> Vec<u16> {
        const PAD: usize = 40;
        let (cw, ch) = (W + 2 * PAD, H + 2 * PAD);
        let mut canvas = vec![3000i32; cw * ch];
        let mut next = xorshift32(seed);
        for _ in 0..1500 {
            let (x, y) = ((next() as usize) % cw, (next() as usize) % ch);
            let r = 2 + (next() % 7) as usize;
            let a = 200 + (next() % 1500) as i32;
            for yy in y.saturating_sub(r)..(y + r + 1).min(ch) {
                for v in &mut canvas[yy * cw + x.saturating_sub(r)..yy * cw + (x + r + 1).min(cw)] {
                    *v += a;
                }
            }
        }
        let mut px = vec![0u16; W * H];
        for y in 0..H {
            for x in 0..W {
                let cx = (x as i32 + PAD as i32 - offset.0) as usize;
                let cy = (y as i32 + PAD as i32 - offset.1) as usize;
                px[y * W + x] = canvas[cy * cw + cx].min(16_383) as u16;
            }
        }
        px
    }

    #[test]
    fn finds_known_shifts_of_a_textured_ground() {
        let last = scene((0, 0), 7);
        let mut patches = GroundPatches::EMPTY;
        patches.capture(&Frame::new(&last, W, H, 14).unwrap());
        for (dx, dy) in [(0, 0), (3, -2), (-7, 5), (12, -12), (-11, 1)] {
            let now = scene((dx, dy), 7);
            let s = patches
                .shift_to(&Frame::new(&now, W, H, 14).unwrap())
                .unwrap();
            assert_eq!((s.dx_px, s.dy_px), (dx as i16, dy as i16));
            assert!(usize::from(s.agreeing) >= MIN_AGREEING);
        }
    }

    #[test]
    fn a_gain_and_offset_change_does_not_move_the_match() {
        let last = scene((0, 0), 11);
        let now: Vec<u16> = scene((4, 3), 11).iter().map(|&v| v / 2 + 900).collect();
        let mut patches = GroundPatches::EMPTY;
        patches.capture(&Frame::new(&last, W, H, 14).unwrap());
        let s = patches
            .shift_to(&Frame::new(&now, W, H, 14).unwrap())
            .unwrap();
        assert_eq!((s.dx_px, s.dy_px), (4, 3));
    }

    #[test]
    fn noise_alone_gives_no_shift() {
        let mut next = xorshift32(99);
        let noise = |next: &mut dyn FnMut() -> u32| -> Vec<u16> {
            (0..W * H).map(|_| 1000 + (next() % 40) as u16).collect()
        };
        let (a, b) = (noise(&mut next), noise(&mut next));
        let mut patches = GroundPatches::EMPTY;
        patches.capture(&Frame::new(&a, W, H, 14).unwrap());
        assert_eq!(patches.shift_to(&Frame::new(&b, W, H, 14).unwrap()), None);
    }

    #[test]
    fn no_patches_no_shift() {
        let px = vec![5u16; 40 * 40];
        let small = Frame::new(&px, 40, 40, 14).unwrap();
        let mut patches = GroundPatches::EMPTY;
        assert_eq!(patches.shift_to(&small), None);
        patches.capture(&small);
        assert_eq!(patches.shift_to(&small), None);
    }

    /// The half-resolution search then ±1 px finds what the exhaustive full-resolution
    /// search of every shift in ±`SEARCH_PX` finds (the study's registration).
    #[test]
    fn coarse_to_fine_matches_the_exhaustive_search() {
        let last = scene((0, 0), 23);
        let now = scene((5, -3), 23);
        let (fa, fb) = (
            Frame::new(&last, W, H, 14).unwrap(),
            Frame::new(&now, W, H, 14).unwrap(),
        );
        let mut patches = GroundPatches::EMPTY;
        patches.capture(&fa);
        for k in 0..PATCHES {
            let (x, y) = patches.corners[k];
            let (x, y) = (i32::from(x), i32::from(y));
            let mut best = (u32::MAX, 0, 0);
            let s = SEARCH_PX as i32;
            for dy in -s..=s {
                for dx in -s..=s {
                    let q = (0..PATCH_PX).flat_map(|r| {
                        let row = fb.row((y + dy) as usize + r).unwrap();
                        let x0 = (x + dx) as usize;
                        row[x0..x0 + PATCH_PX].iter().map(|&v| u32::from(v))
                    });
                    let q: Vec<u32> = q.collect();
                    let p = &patches.pixels[k];
                    let ps: u32 = p.iter().map(|&v| u32::from(v)).sum();
                    let offset = rounded_mean_difference(ps, q.iter().sum(), PATCH_AREA);
                    let c = sad_row(p, &q, offset);
                    if c < best.0 {
                        best = (c, dx, dy);
                    }
                }
            }
            assert_eq!(
                patches.patch_move(k, &fb),
                Some((best.1, best.2)),
                "patch {k}"
            );
        }
    }
}
