//! The frame's straight edges (line segments), the cue an eye reads a spacecraft by
//! over the Earth: its outline and face boundaries are long straight steps that meet
//! at corners, where cloud edges are ragged and short and the limb is one smooth arc.
//!
//! A region-growing line-segment detector after Grompone von Gioi et al.'s LSD (IPOL
//! 2012), in integers and `f32`, bounded memory and no allocation:
//! 1. the gradient of every 2×2 block (`gx = (b + d) − (a + c)`, `gy = (c + d) − (a +
//!    b)`: each component's noise is 2 σ) is an *edge* when its magnitude reaches
//!    [`EDGE_SIGMAS`] of that noise, a *seed* from [`SEED_SIGMAS`];
//! 2. from each seed not yet in a region (raster order), the region grows over the
//!    8-connected edge blocks whose gradient direction lies within
//!    [`ANGLE_TOLERANCE_DEG`] of the region's mean direction (updated with each block,
//!    so a slowly bending arc is followed only while it stays straight);
//! 3. a region is a segment when its blocks' spread along the direction across its
//!    gradient, read as a uniform distribution, spans at least [`MIN_LENGTH_PX`] and
//!    [`MIN_ELONGATION`] times its spread across (the edge's width: the optics blur a
//!    step over 2–3 px).
//!
//! The segment keeps its mean gradient direction (towards the brighter side), so a
//! group of segments knows on which side of each edge its darker region lies.
//!
//! Memory: one bit per pixel, lent by the caller ([`Marks`], 10 168 B at 328×248 in two
//! slices of `auto-v2`'s integral planes, free at this stage); on the stack a frontier
//! of [`FRONTIER_BLOCKS`] block indices (1 KiB) and the [`MAX_SEGMENTS`] segments
//! (16 B each, 1 536 B).
//! Cost: per pixel one 2×2 gradient (4 reads) against the seed threshold; per block
//! added to a region a square root and its 8 neighbours' gradients, at most
//! [`MAX_FRAME_BLOCKS`] blocks per frame.

use crate::frame::Frame;
use crate::roi::components::NEIGHBOURS_8;

/// Segments kept per frame: the longest when more are found. A spacecraft's outline
/// and face boundaries give 3–12 segments of ≥ 10 px (famA's radiometry-close frames,
/// session 55, OpenCV's LSD); a textured Earth 10–70 more.
pub const MAX_SEGMENTS: usize = 96;

/// A 2×2 block is an edge when its gradient magnitude reaches this many noise σ of a
/// component (each is a difference of two sums of two pixels, σ·2): 3 such σ leave a
/// noise block in about e⁻⁴·⁵ ≈ 1 % (the magnitude of two Gaussian components is
/// Rayleigh); such a block only matters beside a region, whose direction test it must
/// also pass. Lower than the 4 σ before session 65: the frame's σ estimate also reads
/// the fixed pattern and the Earth's pixel-scale texture as noise (famAT, over the
/// temporal σ: Earth frames median 1.10, 90th percentile 1.65; deep space 0.96 and
/// 1.58), and an edge blurred by the optics fell under 4 such σ. Chosen on family
/// A with [`SEED_SIGMAS`] (4/8 → 3/6, `scripts/families.sh compare`, ½ convention):
/// summed mean IoU +0.0034 (famA +0.0035, paper A +0.0032, fixtures A −0.0033, famAF
/// 0); reported beside: famAT −0.0049, paper Tango A +0.0023; held out +0.0169 (famB
/// +0.0057, famBT +0.0118, famBW +0.0033, real Earth −0.0109); no false alarm changed
/// on any set. Of the grid (edge 2.5–4, seed 5–8): 3/5 +0.0029, 2.5/6 +0.0023 (two more
/// false alarms on the held-out fixtures), 3.5/6 0, 3/7 −0.0005, 3/8 −0.0042, 4/6
/// −0.0019.
pub const EDGE_SIGMAS: u32 = 3;

/// A block seeds a region from this many noise σ of a component: twice the edge
/// threshold, so regions start on real steps and grow into their weaker ends (noise
/// alone seeds a block with probability e⁻¹⁸ ≈ 1.5·10⁻⁸: about 10⁻³ of the 81 000
/// blocks of a frame). 8 before session 65, chosen
/// with [`EDGE_SIGMAS`].
pub const SEED_SIGMAS: u32 = 6;

/// Largest angle between a block's gradient and its region's mean direction, degrees:
/// LSD's τ = 22.5° (π/8): two blocks of a straight step agree within it under noise
/// at the edge threshold, a corner of a polygon (≥ 30°) breaks the region.
pub const ANGLE_TOLERANCE_DEG: f32 = 22.5;

/// Shortest segment, pixels: a spacecraft's face edge at close range spans tens of
/// pixels; cloud edges reach 10 px straight now and then (the grouping decides).
pub const MIN_LENGTH_PX: f32 = 10.0;

/// Least ratio of a segment's length to its width (both from the spread of its blocks):
/// a blurred straight step is 2–3 px wide, so a 10-px segment is 3–5 times longer than
/// wide; a blob of texture is not.
pub const MIN_ELONGATION: f32 = 3.0;

/// Blocks waiting to be grown from at once (a region whose frontier is longer stops
/// widening there: a straight edge's frontier is a few blocks).
pub const FRONTIER_BLOCKS: usize = 256;

/// A region stops growing at this many blocks (a 300-px edge 3 px wide is 900; the
/// sums stay exact in `i64` and the cost bounded).
pub const MAX_REGION_BLOCKS: u32 = 4096;

/// Fewest blocks of a region read as a segment (a 10-px edge 1 px wide).
const MIN_REGION_BLOCKS: u32 = 10;

/// Blocks taken into regions per frame, at most: the detector stops there (the
/// segments found so far stand). A real frame's segments hold up to 3 535 blocks
/// (session 55: famA, famAT, famB, famBW, fixtures A, paper A, the real Earth), its
/// regions a few thousand more; a frame of edges everywhere (`plate-holes-2` of the
/// worst-case set: every block an edge) would take every one of its 81 000 blocks,
/// each testing 8 neighbours: 80 M Cortex-M7 instructions before this cap, about
/// 2.4 M with it (≈ 290 per block). Since session 65's lower [`EDGE_SIGMAS`] a
/// textured frame can reach it (`famAT/000234`: 24 segments under the cap, 65 without);
/// 16 384 was measured and not taken (family A +0.0015 over the shipped thresholds,
/// one more false alarm on the real Earth, twice the worst case's growth).
pub const MAX_FRAME_BLOCKS: u32 = 8192;

/// `cos(ANGLE_TOLERANCE_DEG)`.
const COS_TOLERANCE: f32 = 0.923_879_5;

/// Fixed-point scale of a segment's unit gradient direction.
pub const DIRECTION_ONE: i32 = 1024;

/// One straight edge of the frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Segment {
    /// First end, quarter pixels (pixel (x, y)'s centre at (4x, 4y)).
    pub x0_q: i16,
    /// First end, quarter pixels.
    pub y0_q: i16,
    /// Second end, quarter pixels.
    pub x1_q: i16,
    /// Second end, quarter pixels.
    pub y1_q: i16,
    /// Mean gradient direction (dark → bright), x, unit vector × [`DIRECTION_ONE`].
    pub dir_x: i16,
    /// Mean gradient direction, y, unit vector × [`DIRECTION_ONE`].
    pub dir_y: i16,
    /// Length, quarter pixels.
    pub length_q: u16,
    /// 2×2 blocks of its region (≤ [`MAX_REGION_BLOCKS`]).
    pub blocks: u16,
}

/// One bit per pixel (a block's "in a region" mark), in two slices lent by the caller.
pub struct Marks<'a> {
    lo: &'a mut [u32],
    hi: &'a mut [u32],
}

impl<'a> Marks<'a> {
    /// Marks over `lo` then `hi` for `pixels` pixels, cleared; `None` when the two hold
    /// fewer than `pixels` bits.
    pub fn new(lo: &'a mut [u32], hi: &'a mut [u32], pixels: usize) -> Option<Self> {
        if (lo.len() + hi.len()) * 32 < pixels {
            return None;
        }
        lo.fill(0);
        hi.fill(0);
        Some(Marks { lo, hi })
    }

    fn word(&mut self, i: usize) -> Option<&mut u32> {
        let w = i / 32;
        let n = self.lo.len();
        if w < n {
            self.lo.get_mut(w)
        } else {
            self.hi.get_mut(w - n)
        }
    }

    fn get(&mut self, i: usize) -> bool {
        self.word(i).is_some_and(|w| *w & (1 << (i % 32)) != 0)
    }

    fn set(&mut self, i: usize) {
        if let Some(w) = self.word(i) {
            *w |= 1 << (i % 32);
        }
    }
}

/// The gradient of the 2×2 block at (x, y)..(x + 1, y + 1), `i = y·width + x`, DN
/// clamped to `top`: `(b + d − a − c, c + d − a − b)` (0 off the pixels).
#[inline(always)]
fn gradient(px: &[u16], width: usize, i: usize, top: u16) -> (i32, i32) {
    let pair = |k: usize| match px.get(k..k + 2) {
        Some(&[p, q]) => (i32::from(p.min(top)), i32::from(q.min(top))),
        _ => (0, 0),
    };
    let ((a, b), (c, d)) = (pair(i), pair(i + width));
    (b + d - a - c, c + d - a - b)
}

/// The running sums of a growing region.
struct Region {
    /// Σ unit gradient directions.
    sx: f32,
    sy: f32,
    /// Blocks, and Σ of their offsets from the seed and of the offsets' products.
    n: u32,
    dx: i64,
    dy: i64,
    dxx: i64,
    dxy: i64,
    dyy: i64,
}

impl Region {
    fn add(&mut self, ux: f32, uy: f32, ox: i64, oy: i64) {
        self.sx += ux;
        self.sy += uy;
        self.n += 1;
        self.dx += ox;
        self.dy += oy;
        self.dxx += ox * ox;
        self.dxy += ox * oy;
        self.dyy += oy * oy;
    }

    /// Whether gradient (gx, gy) of squared magnitude `m2` lies within the tolerance of
    /// the mean direction (no square root: `(g·S)² ≥ cos²τ |g|² |S|²` with `g·S > 0`).
    fn agrees(&self, gx: f32, gy: f32, m2: f32) -> bool {
        let dot = gx * self.sx + gy * self.sy;
        let norm2 = self.sx * self.sx + self.sy * self.sy;
        dot > 0.0 && dot * dot >= COS_TOLERANCE * COS_TOLERANCE * m2 * norm2
    }

    /// The region as a segment (seed block at (x, y)), or `None` when it is too short,
    /// too wide or too small.
    fn segment(&self, x: usize, y: usize) -> Option<Segment> {
        if self.n < MIN_REGION_BLOCKS {
            return None;
        }
        let n = self.n as f32;
        let norm = libm::sqrtf(self.sx * self.sx + self.sy * self.sy);
        if norm <= 0.0 {
            return None;
        }
        let (gx, gy) = (self.sx / norm, self.sy / norm);
        // The line runs across the gradient.
        let (lx, ly) = (-gy, gx);
        // Central second moments, exact in i64 (n · Σx² − (Σx)²) then scaled.
        let nn = i64::from(self.n);
        let cxx = (nn * self.dxx - self.dx * self.dx) as f32 / (n * n);
        let cxy = (nn * self.dxy - self.dx * self.dy) as f32 / (n * n);
        let cyy = (nn * self.dyy - self.dy * self.dy) as f32 / (n * n);
        let along = lx * lx * cxx + 2.0 * lx * ly * cxy + ly * ly * cyy;
        let across = gx * gx * cxx + 2.0 * gx * gy * cxy + gy * gy * cyy;
        // A uniform spread over L has variance L²/12.
        let length = libm::sqrtf(12.0 * along.max(0.0));
        let width = libm::sqrtf(12.0 * across.max(0.0)).max(1.0);
        if length < MIN_LENGTH_PX || length < MIN_ELONGATION * width {
            return None;
        }
        // Centre: the seed plus the mean offset, plus half a pixel (the block's centre).
        let cx = x as f32 + self.dx as f32 / n + 0.5;
        let cy = y as f32 + self.dy as f32 / n + 0.5;
        let h = length / 2.0;
        let q = |v: f32| (v * 4.0) as i16;
        Some(Segment {
            x0_q: q(cx - lx * h),
            y0_q: q(cy - ly * h),
            x1_q: q(cx + lx * h),
            y1_q: q(cy + ly * h),
            dir_x: (gx * DIRECTION_ONE as f32) as i16,
            dir_y: (gy * DIRECTION_ONE as f32) as i16,
            length_q: (length * 4.0).min(f32::from(u16::MAX)) as u16,
            blocks: self.n.min(u32::from(u16::MAX)) as u16,
        })
    }
}

/// The straight edges of `frame` (noise σ `sigma` DN) into `out`, the longest kept when
/// there are more; returns how many (≤ `out.len()`). `marks` holds one bit per pixel
/// (cleared by [`Marks::new`]).
pub fn detect(frame: &Frame<'_>, sigma: u32, marks: &mut Marks<'_>, out: &mut [Segment]) -> usize {
    let (w, h) = (frame.width(), frame.height());
    if w < 2 || h < 2 || out.is_empty() {
        return 0;
    }
    let top = frame.max_dn();
    // Component noise 2σ; thresholds on the squared magnitude.
    let unit = 2 * i64::from(sigma.max(1));
    let edge2 = (i64::from(EDGE_SIGMAS) * unit).pow(2);
    let seed2 = (i64::from(SEED_SIGMAS) * unit).pow(2);
    let mut found = 0usize;
    // |g| ≤ |gx| + |gy|: a block under the seed threshold in that sum is no seed (the
    // scan's cheap test; most blocks stop there).
    let seed_l1 = i32::try_from(i64::from(SEED_SIGMAS) * unit).unwrap_or(i32::MAX);
    let mut grower = Grower {
        px: frame.pixels(),
        w,
        h,
        top,
        edge2,
        frontier: [0u32; FRONTIER_BLOCKS],
        left: MAX_FRAME_BLOCKS,
    };
    for y in 0..h - 1 {
        let (Some(r0), Some(r1)) = (frame.row(y), frame.row(y + 1)) else {
            break;
        };
        let mut from = 0;
        while let Some((x, gx, gy)) = next_seed(r0, r1, from, top, seed_l1) {
            from = x + 1;
            if grower.left == 0 {
                return found;
            }
            let m2 = i64::from(gx) * i64::from(gx) + i64::from(gy) * i64::from(gy);
            let i = y * w + x;
            if m2 < seed2 || marks.get(i) {
                continue;
            }
            let Some(s) = grower.segment_from(marks, x, y, gx, gy, m2) else {
                continue;
            };
            if found < out.len() {
                if let Some(slot) = out.get_mut(found) {
                    *slot = s;
                }
                found += 1;
            } else if let Some(shortest) = out.iter_mut().min_by_key(|t| t.length_q) {
                if shortest.length_q < s.length_q {
                    *shortest = s;
                }
            }
        }
    }
    found
}

/// The first block of the row pair `r0` over `r1` at or after column `from` whose
/// |gx| + |gy| reaches `seed_l1` (|g| ≤ |gx| + |gy|: every seed passes), with its
/// gradient; `None` when the row holds no more. The scan's one tight loop: the block's
/// left column (a over c) carried from the last block's right one.
///
/// Its cheap test: with a b over c d, gx + gy = 2 (d − a) and gx − gy = 2 (b − c), so
/// |gx| + |gy| = 2 max(|d − a|, |b − c|), and a seed's diagonal differences reach
/// ⌈`seed_l1` / 2⌉. Clamping to `top` never widens a difference, so the test on the
/// raw DN passes every seed (one add and one unsigned compare per difference, no
/// clamp); the clamped gradient then decides.
#[inline(always)]
fn next_seed(
    r0: &[u16],
    r1: &[u16],
    from: usize,
    top: u16,
    seed_l1: i32,
) -> Option<(usize, i32, i32)> {
    let (r0, r1) = (r0.get(from..)?, r1.get(from..)?);
    // |x| ≥ half ⟺ x + (half − 1) lies outside 0..=2 (half − 1), as u32.
    let half = seed_l1.max(1) / 2 + (seed_l1.max(1) & 1);
    let bias = half - 1;
    let span = 2 * (bias as u32);
    let far = |x: i32| x.wrapping_add(bias) as u32 > span;
    // The block a b over c d passes the cheap test.
    let near_seed = |a: i32, b: i32, c: i32, d: i32| far(d - a) | far(b - c);
    // The block's clamped gradient, when it is a seed.
    let clamp = |v: i32| v.min(i32::from(top));
    let seed = |a: i32, b: i32, c: i32, d: i32| {
        let (a, b, c, d) = (clamp(a), clamp(b), clamp(c), clamp(d));
        let (gx, gy) = (b + d - a - c, c + d - a - b);
        (gx.abs() + gy.abs() >= seed_l1).then_some((gx, gy))
    };
    // On a host with vector units, first skip [`WIDE_BLOCKS`] blocks at a time whose
    // diagonal differences all stay under `half` ([`wide_skip`]); the flight targets
    // start at `from` (the same code as before the skip: their counts are the budget's).
    #[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
    let (r0, r1, from) = {
        let skip = wide_skip(r0, r1, half)?;
        (r0.get(skip..)?, r1.get(skip..)?, from + skip)
    };
    let (mut a, mut c) = (i32::from(*r0.first()?), i32::from(*r1.first()?));
    let (b_row, d_row) = (r0.get(1..)?, r1.get(1..)?);
    // Four blocks per step, one branch for the four (most steps hold no seed).
    let mut k = 0usize;
    for (p, q) in b_row
        .chunks_exact(STEP_BLOCKS)
        .zip(d_row.chunks_exact(STEP_BLOCKS))
    {
        let (&[b0, b1, b2, b3], &[d0, d1, d2, d3]) = (p, q) else {
            break;
        };
        let [b0, b1, b2, b3, d0, d1, d2, d3] = [b0, b1, b2, b3, d0, d1, d2, d3].map(i32::from);
        if near_seed(a, b0, c, d0)
            | near_seed(b0, b1, d0, d1)
            | near_seed(b1, b2, d1, d2)
            | near_seed(b2, b3, d2, d3)
        {
            let blocks = [
                (a, b0, c, d0),
                (b0, b1, d0, d1),
                (b1, b2, d1, d2),
                (b2, b3, d2, d3),
            ];
            for (j, &(a, b, c, d)) in blocks.iter().enumerate() {
                if let Some((gx, gy)) = seed(a, b, c, d) {
                    return Some((from + k + j, gx, gy));
                }
            }
        }
        (a, c) = (b3, d3);
        k += STEP_BLOCKS;
    }
    // The row's last blocks, one at a time.
    for (&b, &d) in b_row.iter().zip(d_row).skip(k) {
        let (b, d) = (i32::from(b), i32::from(d));
        if near_seed(a, b, c, d) {
            if let Some((gx, gy)) = seed(a, b, c, d) {
                return Some((from + k, gx, gy));
            }
        }
        (a, c) = (b, d);
        k += 1;
    }
    None
}

/// Blocks [`next_seed`]'s cheap test takes per branch: most of a frame holds no seed,
/// so one branch per four blocks instead of one per block (x86-64, the flight demo's
/// Tango frame: `auto-v2` 8.23 M → 6.68 M instructions).
const STEP_BLOCKS: usize = 4;

/// Blocks per test of [`wide_skip`]: one 256-bit or two 128-bit vectors of 16-bit
/// lanes.
#[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
const WIDE_BLOCKS: usize = 16;

/// [`next_seed`]'s start on a host whose vector units take 16-bit lanes (x86-64 with
/// SSE4.1, AArch64): the first multiple of [`WIDE_BLOCKS`] blocks into the row pair
/// `r0` over `r1` where a block of the next [`WIDE_BLOCKS`] may pass the cheap test
/// (a diagonal difference of `half` or more; the compiler turns the test into a few
/// vector instructions), or the last such multiple; `None` when `half` exceeds every
/// difference of two 16-bit DN (no seed in the row). x86-64 (callgrind, the flight
/// demo's Tango frame, where stage 5f runs): `auto-v2` 6.70 → 6.00 M instructions.
/// The flight targets have no such unit and skip nothing (their counts are the flight
/// budget's).
#[cfg(any(target_arch = "x86_64", target_arch = "aarch64"))]
#[inline(always)]
fn wide_skip(r0: &[u16], r1: &[u16], half: i32) -> Option<usize> {
    let half16 = u16::try_from(half).ok()?;
    let mut k = 0usize;
    while let (Some(p), Some(q)) = (
        r0.get(k..k + WIDE_BLOCKS + 1)
            .and_then(|p| <&[u16; WIDE_BLOCKS + 1]>::try_from(p).ok()),
        r1.get(k..k + WIDE_BLOCKS + 1)
            .and_then(|q| <&[u16; WIDE_BLOCKS + 1]>::try_from(q).ok()),
    ) {
        let mut largest = 0u16;
        for i in 0..WIDE_BLOCKS {
            largest = largest
                .max(q[i + 1].abs_diff(p[i]))
                .max(p[i + 1].abs_diff(q[i]));
        }
        if largest >= half16 {
            break;
        }
        k += WIDE_BLOCKS;
    }
    Some(k)
}

/// What growing a region needs: the frame, the edge thresholds, the frontier and the
/// blocks the frame's regions may still take ([`MAX_FRAME_BLOCKS`]).
struct Grower<'a> {
    px: &'a [u16],
    w: usize,
    h: usize,
    top: u16,
    edge2: i64,
    frontier: [u32; FRONTIER_BLOCKS],
    left: u32,
}

impl Grower<'_> {
    /// The region grown from the seed block at (x, y) (gradient (gx, gy), squared
    /// magnitude `m2`), as a segment when it is one; its blocks are marked.
    #[inline(never)]
    fn segment_from(
        &mut self,
        marks: &mut Marks<'_>,
        x: usize,
        y: usize,
        gx: i32,
        gy: i32,
        m2: i64,
    ) -> Option<Segment> {
        let (w, h) = (self.w, self.h);
        let i = y * w + x;
        let m = libm::sqrtf(m2 as f32);
        let mut region = Region {
            sx: 0.0,
            sy: 0.0,
            n: 0,
            dx: 0,
            dy: 0,
            dxx: 0,
            dxy: 0,
            dyy: 0,
        };
        region.add(gx as f32 / m, gy as f32 / m, 0, 0);
        marks.set(i);
        self.left -= 1;
        self.frontier[0] = i as u32;
        let mut len = 1usize;
        while len > 0 && region.n < MAX_REGION_BLOCKS && self.left > 0 {
            len -= 1;
            let p = self.frontier.get(len).copied().unwrap_or(0) as usize;
            // (`w ≥ 2` by `detect`; `max(1)` says so to the compiler: no division panic.)
            let (px_, py_) = (p % w.max(1), p / w.max(1));
            for (ox, oy) in NEIGHBOURS_8 {
                let (qx, qy) = (px_ as isize + ox, py_ as isize + oy);
                if qx < 0 || qy < 0 || qx as usize >= w - 1 || qy as usize >= h - 1 {
                    continue;
                }
                let q = qy as usize * w + qx as usize;
                if marks.get(q) {
                    continue;
                }
                let (gx, gy) = gradient(self.px, w, q, self.top);
                let m2 = i64::from(gx) * i64::from(gx) + i64::from(gy) * i64::from(gy);
                if m2 < self.edge2 {
                    // No edge: no region takes it and it seeds none (the seed
                    // threshold is higher), so it is marked and never read again.
                    marks.set(q);
                    continue;
                }
                let (fx, fy, fm2) = (gx as f32, gy as f32, m2 as f32);
                if !region.agrees(fx, fy, fm2) || self.left == 0 {
                    continue;
                }
                let m = libm::sqrtf(fm2);
                let (ux, uy) = (fx / m, fy / m);
                marks.set(q);
                self.left -= 1;
                region.add(ux, uy, qx as i64 - x as i64, qy as i64 - y as i64);
                if let Some(slot) = self.frontier.get_mut(len) {
                    *slot = q as u32;
                    len += 1;
                }
            }
        }
        region.segment(x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec;

    const W: usize = 120;
    const H: usize = 90;

    fn run(px: &[u16], sigma: u32) -> std::vec::Vec<Segment> {
        let frame = Frame::new(px, W, H, 14).unwrap();
        let (mut lo, mut hi) = (vec![0u32; 200], vec![0u32; 200]);
        let mut marks = Marks::new(&mut lo, &mut hi, W * H).unwrap();
        let mut out = [Segment::default(); MAX_SEGMENTS];
        let n = detect(&frame, sigma, &mut marks, &mut out);
        out[..n].to_vec()
    }

    #[test]
    fn a_dark_rectangle_gives_its_four_sides() {
        // A 60 × 40 px rectangle at 1 000 DN on 3 000 DN, corners (30, 25)–(89, 64).
        let px: std::vec::Vec<u16> = (0..W * H)
            .map(|i| {
                let (x, y) = (i % W, i / W);
                if (30..90).contains(&x) && (25..65).contains(&y) {
                    1000
                } else {
                    3000
                }
            })
            .collect();
        let segs = run(&px, 2);
        assert_eq!(segs.len(), 4, "{segs:?}");
        for s in &segs {
            let (x0, y0, x1, y1) = (
                s.x0_q as f32 / 4.0,
                s.y0_q as f32 / 4.0,
                s.x1_q as f32 / 4.0,
                s.y1_q as f32 / 4.0,
            );
            let horizontal = (y0 - y1).abs() < 1.0;
            if horizontal {
                // Top edge between rows 24 and 25 (block centre 24.5), bottom 64.5.
                let y = (y0 + y1) / 2.0;
                assert!((y - 24.5).abs() < 0.6 || (y - 64.5).abs() < 0.6, "{s:?}");
                let len = (x1 - x0).abs();
                assert!((len - 60.0).abs() < 4.0, "{s:?}");
                // The gradient points to the brighter side: outwards.
                assert_eq!(s.dir_y.signum(), if y < 40.0 { -1 } else { 1 }, "{s:?}");
            } else {
                assert!((x0 - x1).abs() < 1.0, "{s:?}");
                let x = (x0 + x1) / 2.0;
                assert!((x - 29.5).abs() < 0.6 || (x - 89.5).abs() < 0.6, "{s:?}");
                assert!(((y1 - y0).abs() - 40.0).abs() < 4.0, "{s:?}");
            }
        }
    }

    #[test]
    fn a_disc_and_noise_give_no_long_segment() {
        // A disc of radius 30 px: its edge bends 22.5° every ~12 px, so pieces stay
        // short; flat noise gives none.
        let mut state = 12345u32;
        let px: std::vec::Vec<u16> = (0..W * H)
            .map(|i| {
                state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
                let noise = (state >> 16) % 7;
                let (x, y) = (i % W, i / W);
                let r2 = (x as i32 - 60).pow(2) + (y as i32 - 45).pow(2);
                (if r2 < 900 { 1000 } else { 3000 }) + noise as u16
            })
            .collect();
        let segs = run(&px, 2);
        for s in &segs {
            assert!(s.length_q < 4 * 16, "{s:?}");
        }
        let flat: std::vec::Vec<u16> = (0..W * H)
            .map(|_| {
                state = state.wrapping_mul(1_103_515_245).wrapping_add(12345);
                3000 + ((state >> 16) % 7) as u16
            })
            .collect();
        assert!(run(&flat, 2).is_empty());
    }

    #[test]
    fn the_scan_finds_the_first_seed_as_the_plain_test_does() {
        // Brute force: the first block at or after `from` whose clamped
        // |gx| + |gy| reaches the threshold (the definition the cheap test must keep),
        // on rows with DN above the top (clamped), steps of every size and row lengths
        // around the four-block step and the wide skip's 16 blocks.
        let brute = |r0: &[u16], r1: &[u16], from: usize, top: u16, l1: i32| {
            let c = |v: u16| i32::from(v.min(top));
            (from..r0.len().min(r1.len()).saturating_sub(1)).find_map(|x| {
                let (a, b, cc, d) = (c(r0[x]), c(r0[x + 1]), c(r1[x]), c(r1[x + 1]));
                let (gx, gy) = (b + d - a - cc, cc + d - a - b);
                (gx.abs() + gy.abs() >= l1).then_some((x, gx, gy))
            })
        };
        let mut state = 2024u32;
        let mut rand = |m: u32| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state % m
        };
        let mut checked = 0;
        for _ in 0..4000 {
            let len = 1 + rand(53) as usize;
            let top = [255u16, 4095, 16383, u16::MAX][rand(4) as usize];
            let spread = [3u32, 40, 900, 70_000][rand(4) as usize];
            let mut row = || -> std::vec::Vec<u16> {
                (0..len)
                    .map(|_| (1000 + rand(spread)).min(65_535) as u16)
                    .collect()
            };
            let (r0, r1) = (row(), row());
            let l1 = [1i32, 2, 7, 16, 64, 301, 5000, i32::MAX][rand(8) as usize];
            for from in 0..=len {
                assert_eq!(
                    next_seed(&r0, &r1, from, top, l1),
                    brute(&r0, &r1, from, top, l1),
                    "{r0:?} over {r1:?} from {from}, top {top}, threshold {l1}"
                );
                checked += 1;
            }
        }
        assert!(checked > 40_000);
    }
}
