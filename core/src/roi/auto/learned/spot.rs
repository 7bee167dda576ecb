//! Stage 5e: a small target among clutter (a *spot*), the last look when every other
//! stage answers "no target". A far target (3–12 px) over the Earth is a compact blob
//! of a few pixels; its 8-px cells move by a fraction of its contrast and the cell
//! classifier, trained on cells, does not see it (`realistic` family A: radiometry far,
//! signal-to-clutter ≥ 3, mean IoU 0.03). At the pixel scale it stands out against the
//! clutter around it: the contrast of a pixel's 3×3 mean against the ring of the 13×13
//! square less its 7×7 core (sampled every second pixel, [`RING_STRIDE_PX`]), over the
//! ring's own standard deviation (the local clutter, not the pixel noise; floored at the
//! noise σ),
//!
//! z = (3×3 mean − ring mean) / max(ring σ, noise σ),
//!
//! close to the signal-to-clutter ratio the datasets label targets by (`docs/scenes.md`:
//! the target's mean against a ring's σ).
//! Cloud cells of the same size reach z ≈ 7 too, so z alone does not decide: the
//! [`SPOTS`] strongest spots at least [`SEPARATION_PX`] apart (z ≥ [`MIN_Z16`] / 16)
//! are each grown to a region (the pixels departing [`GROW_SIGMAS`] spreads from the
//! ring's mean, 8-connected to the centre, within [`REACH_PX`]) and rated by a small
//! forest of boosted trees (`spot_trees.rs`, `scripts/train-auto.py --spots`) over
//! [`SPOT_FEATURES`] integer statistics of the spot, its region, its rank among the
//! frame's spots and its context (does it stand alone, has it hot and cold faces, how
//! sharp its outline is): the calibrated P(the grown box is a hit). The most confident spot's
//! box is the answer when it reaches the detector's gate.
//!
//! Memory: the column sums of the ring's sampled rows and of the hole's (DN and DN² in
//! 32 bits, of DN brought to 12 bits), 2 words per sampled column each, and of the
//! core's 3 rows, 1 word per column, in the three integral planes the caller lends
//! (`auto-v2`'s, free at this stage; every capacity's planes hold them). On the stack:
//! the [`SPOTS`] spots (56 B each on the M7) and the rated spots with their features
//! (152 B each): 1 664 B for 8 (1 040 B for session 47's 5), and a region's bit rows;
//! `auto-v2`'s stack peak (12 440 B on the M7, `scripts/flight.sh`) lies elsewhere and
//! did not move.
//! Cost (Cortex-M7): per sampled row each band moved down (a row in and a row out, of
//! DN and DN², one band per pass) and the core's column sums; per centre of the search
//! grid (every second pixel of every second row) the DN sums moved along the row and a
//! comparison, the DN² sums and the variance only where the contrast passes the noise
//! floor (`reject_below`), the division and square root only for a centre that would
//! enter the spots; then the [`SPOTS`] spots' 3×3 refinement, regions and forest.
//! Session 34 measured at most 5.49 M instructions per 328×248 window (67 per pixel);
//! session 49's loops (both bands and the DN² sums carried along the row before) took
//! 1.3 M off the flight demo's far and Tango frames, where the stage runs.

use super::features::FrameLevels;
use super::forest::{self, Node};
use super::narrow::isqrt_u64;
use super::spot_trees;
use crate::frame::Frame;
use crate::roi::Roi;
use crate::roi::components::NEIGHBOURS_8;
use crate::roi::plane::Window;

/// Spots rated per frame: the strongest, at least [`SEPARATION_PX`] apart. 8, chosen on
/// family A (session 48, the forest as trained on 5 per frame: its rank feature splits
/// at 0 and 3, so spots 5–7 are rated as the fifth): with 5, 8, 12, 16 spots the summed
/// mean IoU of famA, paperA, fixA and famAF is 2.4167, 2.4261, 2.4261, 2.4343, the
/// false alarms on famAE 11, 11, 11, 12 of 300 (famAT 3, 2, 2, 2); the fewest spots of
/// the best tie without a false alarm added. On today's renders the target is the
/// strongest spot of 32 % of famAF's frames with signal-to-clutter ≥ 3, among the five
/// strongest of 43 % and the eight of 47 % (famA's radiometry-far frames: 51, 69, 71 %).
pub const SPOTS: usize = 8;

/// Integer features of a rated spot (the order of [`spot_features`]).
pub const SPOT_FEATURES: usize = 21;

/// Half side of the square around a spot whose departing pixels (beyond its region's
/// box grown by [`CONTEXT_GAP_PX`]) say whether it stands alone, px: 31 px across, two
/// of the ring's squares (a cloud field's neighbouring cells lie within it).
pub const CONTEXT_HALF_PX: usize = 15;

/// The context leaves out the region's box grown by this many pixels: the target's
/// blur.
pub const CONTEXT_GAP_PX: usize = 2;

/// Side of the spot's core square, px: a 3-px target fills it.
pub const INNER_PX: usize = 3;

/// Side of the square the ring leaves out, px: the core of a target up to 7 px and its
/// blur, so the target does not count in its own clutter.
pub const HOLE_PX: usize = 7;

/// Side of the ring's outer square, px: three cloud-texture grains across at the
/// `realistic` world's far range, inside one 16-px context box.
pub const RING_PX: usize = 13;

/// The ring is sampled every this many pixels in both axes, on the lattice through the
/// centre: 40 of its 120 pixels (Chebyshev distance 4–6), enough for its mean and σ
/// (the σ's own relative error ≈ 11 %), and the search's column sums then move by one
/// sampled row and column per step of the search grid. On the Cortex-M7 the full ring
/// cost the stage 104 instructions per pixel (`scripts/worst-case.sh`, 8.45 M per
/// frame), the sampled one 70 (5.67 M; 67, 5.49 M with the context features' forest);
/// on family A (seed 7001) the sampled ring boxes
/// as well (summed mean IoU 2.226 against 2.217, forest retrained for each).
pub const RING_STRIDE_PX: usize = 2;

/// Least z of a spot, 1/16 units: 3 (48/16). Below it the spot is within three of its
/// clutter's σ: the far goal starts at a signal-to-clutter ratio of 3.
pub const MIN_Z16: u32 = 48;

/// Two spots are at least this many pixels apart (Chebyshev) in either axis: one
/// target, one spot (a 12-px target's centre to its far edge is 6 px, plus blur).
pub const SEPARATION_PX: usize = 8;

/// A spot's region grows at most this many pixels from its centre: a 17-px square
/// holds the largest far target (12 px) and its blur.
pub const REACH_PX: usize = 8;

/// A pixel joins the spot's region when it departs from the ring's mean by this many
/// spreads (max(ring σ, noise σ)), either sign: the faint faces of a target are kept
/// (of 3, 4 and ½ of the peak, 3 boxed family A's found targets best: mean IoU 0.69
/// against 0.69 / 0.58 at 4 / ½ peak, and a target's cold and hot faces alike).
pub const GROW_SIGMAS: i64 = 3;

/// Sampled pixels of the ring: 7² − 3² (the lattice's points of the 13×13 square less
/// those of the 7×7).
const RING_COUNT: i64 = {
    let outer = RING_PX.div_ceil(RING_STRIDE_PX);
    let hole = HOLE_PX / RING_STRIDE_PX;
    (outer * outer - hole * hole) as i64
};
const _: () = assert!(RING_COUNT == 40);
/// Pixels of the core.
const INNER_COUNT: i64 = (INNER_PX * INNER_PX) as i64;
/// Bit rows of a region: 2 × [`REACH_PX`] + 1.
const REGION_PX: usize = 2 * REACH_PX + 1;

/// A spot: where, how strong, and its ring's statistics (the inputs of its features).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Spot {
    /// Column of the centre, px (frame coordinates).
    pub x: u16,
    /// Row of the centre, px.
    pub y: u16,
    /// |z|, 1/16 units (module docs).
    pub z16: u32,
    /// True when the core is colder than its ring.
    pub colder: bool,
    /// Sum of the ring's 120 pixels, in units of 2^`shift` DN.
    pub ring_sum: i64,
    /// Sum of the core's 9 pixels, in units of 2^`shift` DN.
    pub inner_sum: i64,
    /// 120² × the ring's variance, (2^`shift` DN)².
    pub var_n2: u64,
    /// 120 × the ring's standard deviation (integer square root), 2^`shift` DN.
    pub clutter_n: u64,
    /// 120 × the spread, max(ring σ, noise σ), 2^`shift` DN.
    pub spread_n: u64,
    /// The stage's DN unit: 2^`shift` DN (the frame's bits above 12).
    pub shift: u8,
}

impl Spot {
    /// The spot with its [`Spot::clutter_n`] and [`Spot::spread_n`] (spread floored at
    /// `floor`).
    fn with_spreads(self, floor: Floor) -> Spot {
        Spot {
            clutter_n: self.var_n2.isqrt(),
            spread_n: self.var_n2.max(floor.n2).isqrt(),
            ..self
        }
    }
}

/// A rated spot: its box (the grown region's), its features and its confidence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RatedSpot {
    /// The spot.
    pub spot: Spot,
    /// The region's box, frame coordinates.
    pub roi: Roi,
    /// The features the forest rated ([`spot_features`]'s order).
    pub features: [i32; SPOT_FEATURES],
    /// P(the box is a hit), ‰.
    pub score_permille: u16,
}

/// The forest that rates spots (`spot_trees.rs`), checked at compile time: every split
/// on one of the [`SPOT_FEATURES`], no path deeper than the walk's guard.
const _: () = assert!(
    forest::max_depth_of(&spot_trees::NODES, &spot_trees::ROOTS, SPOT_FEATURES) <= 8,
    "spot_trees.rs: a tree deeper than 8 or a split on no feature"
);

/// Column sums of a band of rows: DN and DN², of DN shifted right by the frame's bits
/// above 12 ([`dn_shift`]; 13 × 13 × 4095² < 2³², so every sum fits 32 bits).
struct Band<'a> {
    dn: &'a mut [u32],
    sq: &'a mut [u32],
}

/// Right shift that brings the frame's DN to 12 bits: the spot stage's unit is
/// 2^shift DN (1 DN for the 12-bit flight camera; 4 DN at 14 bits, under the noise of
/// every 14- and 16-bit dataset here).
fn dn_shift(max_dn: u16) -> u32 {
    (16 - max_dn.leading_zeros()).saturating_sub(12)
}

impl Band<'_> {
    /// Adds the sampled columns (every [`RING_STRIDE_PX`]-th from the window's first)
    /// of window row `row` (DN ≤ `max_dn`, shifted by `shift`) to the band.
    fn add(&mut self, row: &[u16], max_dn: u16, shift: u32) {
        let sampled = row.iter().step_by(RING_STRIDE_PX);
        for ((dn, sq), &v) in self.dn.iter_mut().zip(self.sq.iter_mut()).zip(sampled) {
            let v = u32::from(v.min(max_dn) >> shift);
            *dn += v;
            *sq += v * v;
        }
    }

    /// Moves the band one sampled row down: window row `row_in` (DN ≤ `max_dn`,
    /// shifted by `shift`) enters, `row_out` leaves. One band per pass, so the loop
    /// holds its pointers in registers (both bands in one pass spilled them on the M7:
    /// 59 instructions per sampled column). The sums are exact, so the wrapping
    /// arithmetic never wraps; it spares the M7 an overflow check per column.
    fn step(&mut self, row_in: &[u16], row_out: &[u16], max_dn: u16, shift: u32) {
        // The sampled columns as the first pixel of each chunk of `RING_STRIDE_PX` (and
        // of the last, shorter chunk of an odd row): a strided read the compiler
        // vectorises on a host (x86-64 callgrind, 20 frames of famAF: `auto-v2` 7.99 →
        // 6.97 M instructions; `step_by` it does not).
        let (ins, outs) = (
            row_in.chunks_exact(RING_STRIDE_PX),
            row_out.chunks_exact(RING_STRIDE_PX),
        );
        let tail = (ins.remainder().first(), outs.remainder().first());
        let pixels = ins.map(|c| c[0]).zip(outs.map(|c| c[0]));
        let mut n = 0usize;
        for ((dn, sq), (a, b)) in self.dn.iter_mut().zip(self.sq.iter_mut()).zip(pixels) {
            let [a, b] = [a, b].map(|v| u32::from(v.min(max_dn) >> shift));
            *dn = dn.wrapping_add(a).wrapping_sub(b);
            *sq = sq.wrapping_add(a * a).wrapping_sub(b * b);
            n += 1;
        }
        // The odd row's last sampled column, after the full chunks' (the loop's body
        // again: one closure for both, the tail's column from the chunk count, cost
        // the M7's far and Tango frames +0.07 M, `scripts/flight.sh`).
        if let ((Some(&a), Some(&b)), Some(dn), Some(sq)) =
            (tail, self.dn.get_mut(n), self.sq.get_mut(n))
        {
            let [a, b] = [a, b].map(|v| u32::from(v.min(max_dn) >> shift));
            *dn = dn.wrapping_add(a).wrapping_sub(b);
            *sq = sq.wrapping_add(a * a).wrapping_sub(b * b);
        }
    }
}

/// The spread's floor ([`floor_n2`]) and its square root, 120 × the noise σ: computed
/// once per window (a 64-bit square root is a loop on the M7).
#[derive(Clone, Copy)]
struct Floor {
    n2: u64,
    n: u64,
}

/// The spot centred at (x, y) (frame coordinates; its 13×13 square in the window) from
/// its sums: `s_inner` of the 3×3, `ring_sum` / `ring_sq` of the ring (DN and DN², in
/// units of 2^`shift` DN); `None` when its z is under `admit16` / 16.
#[allow(clippy::too_many_arguments)]
fn spot_of(
    x: usize,
    y: usize,
    s_inner: i32,
    ring_sum: i32,
    ring_sq: u32,
    floor: Floor,
    admit16: u32,
    shift: u32,
) -> Option<Spot> {
    let floor_n2 = floor.n2;
    // 9 × 120 × (core mean − ring mean); ≤ 120 · 9 · 4095 < 2^23 in magnitude.
    let num = RING_COUNT as i32 * s_inner - INNER_COUNT as i32 * ring_sum;
    let a = u64::from(num.unsigned_abs());
    if under_floor(a, admit16, floor) {
        return None;
    }
    // 120² × the ring's variance (exact in these units; ≥ 0).
    let var_n2 = (RING_COUNT as u64 * u64::from(ring_sq))
        .saturating_sub(u64::from(ring_sum.unsigned_abs()).pow(2));
    let den = var_n2.max(floor_n2);
    let a2 = a * a;
    // z16 ≥ admit16 ⇔ 256 a² ≥ 81 admit16² den (a² < 2^45: no overflow; the right side
    // saturates, which only rejects).
    let admit2 = u64::from(admit16).pow(2);
    if 256 * a2 < admit2.saturating_mul(81).saturating_mul(den) {
        return None;
    }
    let z2 = (256 * a2).checked_div(81 * den).unwrap_or(0);
    // A 32-bit square root where it fits (z < 4096: every spot of a real frame).
    let z16 = isqrt_u64(z2);
    Some(Spot {
        x: u16::try_from(x).ok()?,
        y: u16::try_from(y).ok()?,
        z16: u32::try_from(z16).unwrap_or(u32::MAX),
        colder: num < 0,
        ring_sum: i64::from(ring_sum),
        inner_sum: i64::from(s_inner),
        var_n2,
        // Set for the spots kept ([`Spot::with_spreads`]): two square roots each.
        clutter_n: 0,
        spread_n: 0,
        shift: shift as u8,
    })
}

/// Pixel columns the core's 3×3 spans over one step of the search, its first two
/// leaving and its last two entering (the loop's pattern `[o0, o1, _, i0, i1]` assumes
/// a 3-px core and a 2-px step).
const CORE_STEP_PX: usize = INNER_PX + RING_STRIDE_PX;
const _: () = assert!(INNER_PX == 3 && RING_STRIDE_PX == 2 && CORE_STEP_PX == 5);

/// One sampled row of [`strongest_spots`]' search: what a centre that passed the first
/// test ([`reject_below`]) needs to become a spot.
struct Centres<'a> {
    /// Column sums of DN² of the ring's and the hole's sampled rows, per sampled column.
    ring_sq: &'a [u32],
    core_sq: &'a [u32],
    /// Frame column of centre 0; centre k is `RING_STRIDE_PX · k` to its right.
    x0: usize,
    /// Frame row of the centres.
    y: usize,
    floor: Floor,
    shift: u32,
}

impl Centres<'_> {
    /// Centre `k` with its DN sums (`s_inner` of the 3×3, `ring_sum` of the ring): its
    /// DN² sums summed directly (the ring's 7 sampled columns less the hole's 3; the same
    /// sums and wrapping arithmetic as sums run along the row), [`spot_of`], and the
    /// spot offered to `list`, raising `admit16` when the list is full. Returns the
    /// first test's bound: `reject_below` as it was, or recomputed when `admit16` rose.
    /// Out of line: the search loop keeps its registers.
    #[inline(never)]
    fn consider(
        &self,
        list: &mut [Option<Spot>; SPOTS],
        admit16: &mut u32,
        reject_below: u32,
        k: usize,
        (s_inner, ring_sum): (i32, i32),
    ) -> u32 {
        let (rs, gs) = (RING_PX / 2 / RING_STRIDE_PX, HOLE_PX / 2 / RING_STRIDE_PX);
        let sum_sq = |b: &[u32]| b.iter().fold(0u32, |s, &v| s.wrapping_add(v));
        let (Some(rq), Some(gq)) = (
            self.ring_sq.get(k..=k + 2 * rs),
            self.core_sq.get(k + rs - gs..=k + rs + gs),
        ) else {
            return reject_below;
        };
        let Some(s) = spot_of(
            self.x0 + RING_STRIDE_PX * k,
            self.y,
            s_inner,
            ring_sum,
            sum_sq(rq).wrapping_sub(sum_sq(gq)),
            self.floor,
            *admit16,
            self.shift,
        ) else {
            return reject_below;
        };
        offer(list, s);
        match list.last() {
            Some(Some(last)) if last.z16.saturating_add(1) > *admit16 => {
                *admit16 = last.z16.saturating_add(1);
                self::reject_below(*admit16, self.floor)
            }
            _ => reject_below,
        }
    }
}

/// `spot_of`'s first test, a necessary condition without the variance (the spread is at
/// least the floor): true when `a` = |9 × 120 × (core mean − ring mean)| is too small
/// for z ≥ `admit16` / 16 even at the floor's spread.
#[inline(always)]
fn under_floor(a: u64, admit16: u32, floor: Floor) -> bool {
    16 * a < 9 * u64::from(admit16) * floor.n
}

/// The least |9 × 120 × (core mean − ring mean)| (`spot_of`'s `num`, under 2^23) that
/// passes `spot_of`'s first test at `admit16`: `16 |num| < 9 admit16 floor.n` rejects,
/// so this is ⌈9 admit16 floor.n / 16⌉, saturated at `u32::MAX` (which rejects every
/// `num`, as the 64-bit test does then).
fn reject_below(admit16: u32, floor: Floor) -> u32 {
    let bound = (9 * u64::from(admit16))
        .saturating_mul(floor.n)
        .div_ceil(16);
    u32::try_from(bound).unwrap_or(u32::MAX)
}

/// The spot at (x, y) from direct sums over its 13×13 square (`None` when the square
/// leaves the window or z is under `admit16` / 16): the refinement's and the tests'
/// reference.
fn spot_at(
    frame: &Frame<'_>,
    win: Window,
    x: usize,
    y: usize,
    floor: Floor,
    admit16: u32,
) -> Option<Spot> {
    let (r, g) = (RING_PX / 2, HOLE_PX / 2);
    if x < win.x0 + r || y < win.y0 + r || x + r >= win.x0 + win.w || y + r >= win.y0 + win.h {
        return None;
    }
    let max_dn = frame.max_dn();
    let shift = dn_shift(max_dn);
    let (mut inner, mut ring, mut ring_sq) = (0i32, 0i32, 0u32);
    for yy in y - r..=y + r {
        let row = frame.row(yy)?.get(x - r..=x + r)?;
        for (i, &v) in row.iter().enumerate() {
            let v = v.min(max_dn) >> shift;
            let (dx, dy) = (i.abs_diff(r), yy.abs_diff(y));
            if dx <= 1 && dy <= 1 {
                inner += i32::from(v);
            }
            let on_lattice = dx % RING_STRIDE_PX == 0 && dy % RING_STRIDE_PX == 0;
            if on_lattice && (dx > g || dy > g) {
                ring += i32::from(v);
                ring_sq += u32::from(v) * u32::from(v);
            }
        }
    }
    spot_of(x, y, inner, ring, ring_sq, floor, admit16, shift)
}

/// The spread's floor, 120 × the noise σ (in the stage's DN unit, at least 1), and its
/// square: a variance below it is the noise's.
fn floor_of(sigma_dn: u32, shift: u32) -> Floor {
    let n = RING_COUNT as u64 * u64::from((sigma_dn >> shift).max(1));
    Floor { n2: n * n, n }
}

/// Offers `s` to the spots `list` (strongest first): it replaces every spot within
/// [`SEPARATION_PX`] of it when it is stronger than all of them (else it is dropped),
/// or takes a free place, or the weakest's when it is stronger.
fn offer(list: &mut [Option<Spot>; SPOTS], s: Spot) {
    let near = |e: &Spot| {
        usize::from(e.x.abs_diff(s.x)) <= SEPARATION_PX
            && usize::from(e.y.abs_diff(s.y)) <= SEPARATION_PX
    };
    if list.iter().flatten().any(|e| near(e) && e.z16 >= s.z16) {
        return;
    }
    let mut placed = false;
    for slot in list.iter_mut() {
        if slot.is_some_and(|e| near(&e)) {
            *slot = if placed { None } else { Some(s) };
            placed = true;
        }
    }
    if !placed {
        if let Some(slot) = list.iter_mut().find(|e| e.is_none()) {
            *slot = Some(s);
        } else if let Some(last) = list.last_mut() {
            if last.is_some_and(|e| s.z16 > e.z16) {
                *last = Some(s);
            }
        }
    }
    sort_spots(list);
}

/// The columns of `b` from `k` on (none when `k` is past its end).
fn from(b: &[u32], k: usize) -> &[u32] {
    b.get(k..).unwrap_or(&[])
}

/// Strongest first, free places last (insertion sort of 5; stable).
fn sort_spots(list: &mut [Option<Spot>; SPOTS]) {
    for i in 1..SPOTS {
        let mut j = i;
        while j > 0 {
            let (a, b) = (list[j - 1], list[j]);
            let swap = match (a, b) {
                (None, Some(_)) => true,
                (Some(a), Some(b)) => b.z16 > a.z16,
                _ => false,
            };
            if !swap {
                break;
            }
            list.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// The [`SPOTS`] strongest spots of window `win` (pixel noise `sigma_dn`), strongest
/// first. Searched on the pixels of even offset from the window's first centre in both
/// axes (a target of 2 px or more holds one; the ring's lattice is then the grid's),
/// each spot then moved to the strongest of its 3×3 (exact sums, [`spot_at`]); a spot
/// needs z ≥ [`MIN_Z16`] / 16 and is at least [`SEPARATION_PX`] from a stronger one on
/// the grid. All `None` when the window is under [`RING_PX`] a side or a buffer is
/// short: `ring` and `core` need 2 words per sampled column of the window (⌈w / 2⌉),
/// `inner` one per column.
pub(crate) fn strongest_spots(
    frame: &Frame<'_>,
    win: Window,
    sigma_dn: u32,
    ring: &mut [u32],
    core: &mut [u32],
    inner: &mut [u32],
) -> [Option<Spot>; SPOTS] {
    let mut list = [None; SPOTS];
    let (w, h) = (win.w, win.h);
    if w < RING_PX || h < RING_PX {
        return list;
    }
    let ws = w.div_ceil(RING_STRIDE_PX);
    let (Some(ring), Some(core), Some(inner)) = (
        ring.get_mut(..2 * ws),
        core.get_mut(..2 * ws),
        inner.get_mut(..w),
    ) else {
        return list;
    };
    let (Some((ring_dn, ring_sq)), Some((core_dn, core_sq))) =
        (ring.split_at_mut_checked(ws), core.split_at_mut_checked(ws))
    else {
        return list;
    };
    let mut ring = Band {
        dn: ring_dn,
        sq: ring_sq,
    };
    let mut core = Band {
        dn: core_dn,
        sq: core_sq,
    };
    let max_dn = frame.max_dn();
    let shift = dn_shift(max_dn);
    // Half sides in pixels, and in sampled columns: the ring's 7 and the hole's 3.
    let (r, g) = (RING_PX / 2, HOLE_PX / 2);
    let (rs, gs) = (r / RING_STRIDE_PX, g / RING_STRIDE_PX);
    let floor = floor_of(sigma_dn, shift);
    let mut admit16 = MIN_Z16;
    let first = win.y0 + r;
    for cy in (first..win.y0 + h - r).step_by(RING_STRIDE_PX) {
        if cy == first {
            for b in [&mut *ring.dn, &mut *ring.sq, &mut *core.dn, &mut *core.sq] {
                b.fill(0);
            }
            for y in (cy - r..=cy + r).step_by(RING_STRIDE_PX) {
                ring.add(win.row(frame, y), max_dn, shift);
            }
            for y in (cy - 2 * gs..=cy + 2 * gs).step_by(RING_STRIDE_PX) {
                core.add(win.row(frame, y), max_dn, shift);
            }
        } else {
            // One sampled row down: one row in, one out of each band.
            ring.step(
                win.row(frame, cy + r),
                win.row(frame, cy - r - RING_STRIDE_PX),
                max_dn,
                shift,
            );
            core.step(
                win.row(frame, cy + 2 * gs),
                win.row(frame, cy - 2 * gs - RING_STRIDE_PX),
                max_dn,
                shift,
            );
        }
        // The core's 3 rows, summed per column (rebuilt: 3 reads per column).
        let rows = [
            win.row(frame, cy - 1),
            win.row(frame, cy),
            win.row(frame, cy + 1),
        ];
        for (((col, &a), &b), &c) in inner.iter_mut().zip(rows[0]).zip(rows[1]).zip(rows[2]) {
            *col = [a, b, c]
                .map(|v| u32::from(v.min(max_dn) >> shift))
                .iter()
                .sum();
        }
        // Sums of at most 40 sampled pixels of 12 bits: DN in i32, DN² in u32.
        let sum_dn = |b: &[u32]| b.iter().map(|&v| v as i32).sum::<i32>();
        let (Some(r0), Some(g0), Some(i0)) = (
            ring.dn.get(..=2 * rs),
            core.dn.get(rs - gs..=rs + gs),
            inner.get(r - 1..=r + 1),
        ) else {
            continue;
        };
        let (mut s_ring, mut s_core, mut s_inner) = (sum_dn(r0), sum_dn(g0), sum_dn(i0));
        // Centre k (pixel column r + 2k of the window) moves the ring's and the hole's
        // sums one sampled column right (the first column of a window leaves, its last
        // enters) and the core's two pixel columns. Only the DN sums run along the row
        // and a centre is dropped on them alone (`reject_below`), so the loop keeps its
        // sums in registers; the few centres that pass go to `consider`.
        let centres = Centres {
            ring_sq: ring.sq,
            core_sq: core.sq,
            x0: win.x0 + r,
            y: cy,
            floor,
            shift,
        };
        let mut steps = ring
            .dn
            .windows(2 * rs + 2)
            .zip(from(core.dn, rs - gs).windows(2 * gs + 2))
            .zip(
                from(inner, r - 1)
                    .windows(CORE_STEP_PX)
                    .step_by(RING_STRIDE_PX),
            );
        let mut reject_below = reject_below(admit16, floor);
        let mut k = 0usize;
        loop {
            let ring_sum = s_ring - s_core;
            // `spot_of`'s first test, on 32 bits: |num| < 2^23.
            let num = RING_COUNT as i32 * s_inner - INNER_COUNT as i32 * ring_sum;
            if num.unsigned_abs() >= reject_below {
                let sums = (s_inner, ring_sum);
                reject_below = centres.consider(&mut list, &mut admit16, reject_below, k, sums);
            }
            let Some(((&[rd_out, .., rd_in], &[cd_out, .., cd_in]), &[o0, o1, _, i0, i1])) =
                steps.next()
            else {
                break;
            };
            s_ring += rd_in as i32 - rd_out as i32;
            s_core += cd_in as i32 - cd_out as i32;
            s_inner += (i0 as i32 + i1 as i32) - (o0 as i32 + o1 as i32);
            k += 1;
        }
    }
    // Each spot to the strongest centre of its 3×3 (the grid's own first on a tie).
    for slot in list.iter_mut() {
        let Some(s) = slot else { continue };
        let (x, y) = (usize::from(s.x), usize::from(s.y));
        for (dx, dy) in NEIGHBOURS_8 {
            let (Some(xx), Some(yy)) = (x.checked_add_signed(dx), y.checked_add_signed(dy)) else {
                continue;
            };
            if let Some(better) = spot_at(frame, win, xx, yy, floor, s.z16.saturating_add(1)) {
                *s = better;
            }
        }
        *s = s.with_spreads(floor);
    }
    sort_spots(&mut list);
    list
}

/// The region of spot `s`: the pixels within [`REACH_PX`] of its centre (and in the
/// window) departing [`GROW_SIGMAS`] spreads from the ring's mean, 8-connected to the
/// centre (which is in it). Its box, pixel count, and whether it reached the square's
/// edge.
fn region(frame: &Frame<'_>, win: Window, s: &Spot) -> (Roi, u32, bool) {
    let (cx, cy) = (usize::from(s.x), usize::from(s.y));
    let x_lo = cx.saturating_sub(REACH_PX).max(win.x0);
    let y_lo = cy.saturating_sub(REACH_PX).max(win.y0);
    let x_hi = (cx + REACH_PX + 1).min(win.x0 + win.w);
    let y_hi = (cy + REACH_PX + 1).min(win.y0 + win.h);
    let cut = GROW_SIGMAS as u64 * s.spread_n;
    let mut mask = [0u32; REGION_PX];
    for (m, y) in mask.iter_mut().zip(y_lo..y_hi) {
        let row = frame.row(y).unwrap_or(&[]);
        for (i, x) in (x_lo..x_hi).enumerate() {
            let v = row
                .get(x)
                .map_or(0, |&v| i64::from(v.min(frame.max_dn()) >> s.shift));
            if (v * RING_COUNT - s.ring_sum).unsigned_abs() >= cut {
                *m |= 1 << i;
            }
        }
    }
    let rows = y_hi - y_lo;
    let mut reached = [0u32; REGION_PX];
    if let Some(m) = reached.get_mut(cy - y_lo) {
        *m = 1 << (cx - x_lo);
    }
    // Grow by one pixel per pass until nothing joins (each pass adds one at least:
    // at most 17² passes).
    for _ in 0..REGION_PX * REGION_PX {
        let mut changed = false;
        let mut next = reached;
        for (i, ((n, &here), &m)) in next
            .iter_mut()
            .zip(&reached)
            .zip(&mask)
            .enumerate()
            .take(rows)
        {
            let up = i
                .checked_sub(1)
                .and_then(|j| reached.get(j))
                .copied()
                .unwrap_or(0);
            let down = reached.get(i + 1).copied().unwrap_or(0);
            let near = up | here | down;
            let grown = (near | near << 1 | near >> 1) & m | here;
            changed |= grown != here;
            *n = grown;
        }
        reached = next;
        if !changed {
            break;
        }
    }
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    let mut px = 0;
    for (i, &m) in reached.iter().enumerate().take(rows) {
        if m == 0 {
            continue;
        }
        px += m.count_ones();
        y0 = y0.min(i);
        y1 = i + 1;
        x0 = x0.min(m.trailing_zeros() as usize);
        x1 = x1.max(32 - m.leading_zeros() as usize);
    }
    let to_u16 = |v: usize| u16::try_from(v).unwrap_or(u16::MAX);
    let roi = Roi {
        x0: to_u16(x_lo + x0),
        y0: to_u16(y_lo + y0),
        x1: to_u16(x_lo + x1),
        y1: to_u16(y_lo + y1),
    };
    let edge = (x0 == 0 && x_lo + REACH_PX == cx)
        || (y0 == 0 && y_lo + REACH_PX == cy)
        || (x1 == x_hi - x_lo && x_hi == cx + REACH_PX + 1)
        || (y1 == rows && y_hi == cy + REACH_PX + 1);
    (roi, px, edge)
}

/// Features of spot `k` of `spots` (strongest first) with its region's box, pixels
/// and reach, in the rating forest's order:
/// 0 z (1/16), 1 sign (+1 hotter, −1 colder than the ring), 2 the strongest spot's z
/// over the second's (‰; the second missing: over [`MIN_Z16`]), 3 this spot's z over
/// the next weaker one's (‰, the same rule), 4 the hottest pixel of its 5×5 above the
/// ring's mean and 5 the coldest below it (1/16 spreads), 6 the ring's σ over the noise
/// σ (1/16), 7 the core's mean in the window's 2–98 % range of cell means (‰), 8–9
/// the box's width and height (px), 10 the region's pixels, 11 their share of the box
/// (‰), 12 pixels at the top DN and 13 at 0 in the 7×7 around the centre, 14 pixels
/// from the centre to the window's nearest side, 15 the rank k, 16 whether the region
/// reached [`REACH_PX`]; its context (session 34, [`spot_context`]): 17 the share of
/// the pixels around it departing like it (‰) and 18 departing either way (‰), 19 the
/// smaller of its box's hottest and coldest departure (1/16 spreads: a body with hot
/// and cold faces; negative when the whole box lies on one side of the ring's mean),
/// 20 the largest step between neighbours in a row of its box grown
/// by a pixel (1/16 spreads: an outline's sharpness).
fn spot_features(
    frame: &Frame<'_>,
    win: Window,
    lv: &FrameLevels,
    spots: &[Option<Spot>; SPOTS],
    k: usize,
    s: &Spot,
    (roi, px, edge): (Roi, u32, bool),
) -> [i32; SPOT_FEATURES] {
    let ctx = spot_context(frame, win, s, roi);
    let clamp = |v: i64| v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
    // Ratios without a panic path (every divisor is ≥ 1 here).
    let ratio = |a: i64, b: i64| a.checked_div(b).unwrap_or(0);
    let z_of = |i: usize| -> i64 {
        spots
            .get(i)
            .copied()
            .flatten()
            .map_or(i64::from(MIN_Z16), |e| i64::from(e.z16))
            .max(1)
    };
    let (cx, cy) = (usize::from(s.x), usize::from(s.y));
    let (x_end, y_end) = (win.x0 + win.w, win.y0 + win.h);
    let (mut hot, mut cold) = (i64::MIN, i64::MAX);
    let (mut top, mut zero) = (0i64, 0i64);
    for y in cy.saturating_sub(3).max(win.y0)..(cy + 4).min(y_end) {
        let row = frame.row(y).unwrap_or(&[]);
        for x in cx.saturating_sub(3).max(win.x0)..(cx + 4).min(x_end) {
            let v = row.get(x).map_or(0, |&v| v.min(frame.max_dn()));
            top += i64::from(v >= frame.max_dn());
            zero += i64::from(v == 0);
            if x.abs_diff(cx) <= 2 && y.abs_diff(cy) <= 2 {
                let v = i64::from(v >> s.shift);
                hot = hot.max(v);
                cold = cold.min(v);
            }
        }
    }
    let spread = (s.spread_n as i64).max(1);
    let n_sigma = RING_COUNT * i64::from(lv.sigma.max(1));
    let range = i64::from(lv.p98.saturating_sub(lv.p2).max(1));
    let (w, h) = (i64::from(roi.width()), i64::from(roi.height()));
    let edge_px = (cx - win.x0)
        .min(cy - win.y0)
        .min(x_end - 1 - cx)
        .min(y_end - 1 - cy);
    [
        clamp(i64::from(s.z16)),
        if s.colder { -1 } else { 1 },
        clamp(ratio(1000 * z_of(0), z_of(1))),
        clamp(ratio(1000 * i64::from(s.z16), z_of(k + 1))),
        clamp(ratio(16 * (RING_COUNT * hot - s.ring_sum), spread)),
        clamp(ratio(16 * (s.ring_sum - RING_COUNT * cold), spread)),
        clamp(ratio(16 * s.clutter_n as i64, n_sigma)),
        clamp(ratio(
            1000 * (s.inner_sum - INNER_COUNT * i64::from(lv.p2)),
            INNER_COUNT * range,
        )),
        clamp(w),
        clamp(h),
        clamp(i64::from(px)),
        clamp(ratio(1000 * i64::from(px), w * h)),
        clamp(top),
        clamp(zero),
        clamp(edge_px as i64),
        k as i32,
        i32::from(edge),
        ctx.alike_permille,
        ctx.any_permille,
        ctx.both_sixteenths,
        ctx.step_sixteenths,
    ]
}

/// A spot's context: [`spot_features`] 17–20.
struct Context {
    alike_permille: i32,
    any_permille: i32,
    both_sixteenths: i32,
    step_sixteenths: i32,
}

/// The context of spot `s` with region box `roi` in window `win` ([`spot_features`]
/// 17–20): in the square of [`CONTEXT_HALF_PX`] around the centre, outside the box
/// grown by [`CONTEXT_GAP_PX`], the shares of pixels departing [`GROW_SIGMAS`] spreads
/// from the ring's mean with the spot's sign and with either; in the box, the smaller
/// of the hottest and coldest departures; in the box grown by one pixel, the largest
/// step between row neighbours. At most 31 × 31 + 14 × 15 pixel reads.
fn spot_context(frame: &Frame<'_>, win: Window, s: &Spot, roi: Roi) -> Context {
    let (cx, cy) = (usize::from(s.x), usize::from(s.y));
    let (x_end, y_end) = (win.x0 + win.w, win.y0 + win.h);
    let px = |v: u16| i64::from(v.min(frame.max_dn()) >> s.shift);
    let cut = GROW_SIGMAS * s.spread_n as i64;
    let spread = (s.spread_n as i64).max(1);
    let sign = if s.colder { -1 } else { 1 };
    let (bx0, by0) = (usize::from(roi.x0), usize::from(roi.y0));
    let (bx1, by1) = (usize::from(roi.x1), usize::from(roi.y1));
    let gap = |v: usize| v.saturating_sub(CONTEXT_GAP_PX);
    let (gx0, gy0, gx1, gy1) = (
        gap(bx0),
        gap(by0),
        bx1 + CONTEXT_GAP_PX,
        by1 + CONTEXT_GAP_PX,
    );
    let (mut counted, mut alike, mut any) = (0i64, 0i64, 0i64);
    for y in cy.saturating_sub(CONTEXT_HALF_PX).max(win.y0)..(cy + CONTEXT_HALF_PX + 1).min(y_end) {
        let row = frame.row(y).unwrap_or(&[]);
        let inside_rows = (gy0..gy1).contains(&y);
        for x in
            cx.saturating_sub(CONTEXT_HALF_PX).max(win.x0)..(cx + CONTEXT_HALF_PX + 1).min(x_end)
        {
            if inside_rows && (gx0..gx1).contains(&x) {
                continue;
            }
            let d = row.get(x).map_or(0, |&v| px(v)) * RING_COUNT - s.ring_sum;
            counted += 1;
            alike += i64::from(d * sign >= cut);
            any += i64::from(d.abs() >= cut);
        }
    }
    let (mut hot, mut cold) = (i64::MIN, i64::MAX);
    let mut step = 0i64;
    for y in by0.saturating_sub(1).max(win.y0)..(by1 + 1).min(y_end) {
        let row = frame.row(y).unwrap_or(&[]);
        let xs = bx0.saturating_sub(1).max(win.x0)..(bx1 + 1).min(x_end);
        let mut last: Option<i64> = None;
        for x in xs {
            let v = row.get(x).map_or(0, |&v| px(v));
            if let Some(l) = last {
                step = step.max((v - l).abs());
            }
            last = Some(v);
            if (by0..by1).contains(&y) && (bx0..bx1).contains(&x) {
                hot = hot.max(v);
                cold = cold.min(v);
            }
        }
    }
    let clamp = |v: i64| v.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
    let ratio = |a: i64, b: i64| a.checked_div(b).unwrap_or(0);
    let both = if hot < cold {
        0
    } else {
        (RING_COUNT * hot - s.ring_sum).min(s.ring_sum - RING_COUNT * cold)
    };
    Context {
        alike_permille: clamp(ratio(1000 * alike, counted)),
        any_permille: clamp(ratio(1000 * any, counted)),
        both_sixteenths: clamp(ratio(16 * both, spread)),
        step_sixteenths: clamp(ratio(16 * RING_COUNT * step, spread)),
    }
}

/// Every spot of window `win` rated (strongest first; `None` past the last): the
/// spots, their regions, features and confidences. The buffers as
/// [`strongest_spots`]'s (2, 2 and 1 words per column of the window).
pub(crate) fn rated_spots(
    frame: &Frame<'_>,
    win: Window,
    lv: &FrameLevels,
    ring: &mut [u32],
    core: &mut [u32],
    inner: &mut [u32],
) -> [Option<RatedSpot>; SPOTS] {
    let spots = strongest_spots(frame, win, lv.sigma, ring, core, inner);
    let mut out = [None; SPOTS];
    for (k, (o, s)) in out.iter_mut().zip(&spots).enumerate() {
        let Some(s) = s else { break };
        let reg = region(frame, win, s);
        let features = spot_features(frame, win, lv, &spots, k, s, reg);
        *o = Some(RatedSpot {
            spot: *s,
            roi: reg.0,
            features,
            score_permille: score_permille(&features),
        });
    }
    out
}

/// The rating forest's P(hit) of a spot's features, ‰.
pub fn score_permille(features: &[i32; SPOT_FEATURES]) -> u16 {
    let nodes: &[Node] = &spot_trees::NODES;
    super::logistic_permille(forest::score(
        nodes,
        &spot_trees::ROOTS,
        spot_trees::BIAS,
        features,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};
    extern crate std;
    use std::vec::Vec;

    /// The search's 32-bit first test (`reject_below`) drops exactly the centres
    /// `spot_of`'s 64-bit test drops: on every |num| within 2 of the bound and on random
    /// ones, over noise σ of 1–65 535 DN at every shift and least z from 3 to 2^24.
    #[test]
    fn the_32_bit_first_test_is_spot_ofs() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut dropped = 0u32;
        for _ in 0..20_000 {
            let sigma = 1 + (next() % 65_535) as u32;
            let floor = floor_of(sigma, (next() % 5) as u32);
            let admit16 = MIN_Z16 + (next() % (1 << (next() % 25))) as u32;
            let bound = reject_below(admit16, floor);
            let random = (next() % (1 << 23)) as u32;
            for a in [
                bound.saturating_sub(2),
                bound.saturating_sub(1),
                bound,
                bound.saturating_add(1),
                random,
            ] {
                let a = a.min((1 << 23) - 1);
                let drops = under_floor(u64::from(a), admit16, floor);
                assert_eq!(
                    a < bound,
                    drops,
                    "a {a} admit16 {admit16} floor {}",
                    floor.n
                );
                dropped += u32::from(drops);
            }
        }
        // Both answers occur (of 100 000 tests).
        assert!(dropped > 1_000 && dropped < 99_000, "{dropped}");
    }

    /// A textured background (sums of xorshift noise at two scales) with an optional
    /// 5×4-px block `contrast` DN above it at (200, 120).
    fn textured(contrast: i32) -> Vec<u16> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 41) as i32 - 20
        };
        let coarse: Vec<i32> = (0..(FRAME_WIDTH / 6 + 1) * (FRAME_HEIGHT / 6 + 1))
            .map(|_| next() * 3)
            .collect();
        let mut px = std::vec![0u16; FRAME_WIDTH * FRAME_HEIGHT];
        for y in 0..FRAME_HEIGHT {
            for x in 0..FRAME_WIDTH {
                let c = coarse[(y / 6) * (FRAME_WIDTH / 6 + 1) + x / 6];
                let t = if (200..205).contains(&x) && (120..124).contains(&y) {
                    contrast
                } else {
                    0
                };
                px[y * FRAME_WIDTH + x] = (2000 + c + next() / 4 + t) as u16;
            }
        }
        px
    }

    /// Brute force: z16 of the pixel (x, y) from direct sums in f64 (the ring: the
    /// pixels of even offsets in both axes, 4–6 px from the centre).
    fn brute_z16(px: &[u16], x: usize, y: usize, sigma: f64) -> (f64, bool) {
        let at = |xx: usize, yy: usize| f64::from(px[yy * FRAME_WIDTH + xx]);
        let mut ring = Vec::new();
        let mut inner = 0.0;
        for yy in y - 6..=y + 6 {
            for xx in x - 6..=x + 6 {
                let (dx, dy) = (xx.abs_diff(x), yy.abs_diff(y));
                if dx % 2 == 0 && dy % 2 == 0 && (dx > 3 || dy > 3) {
                    ring.push(at(xx, yy));
                }
                if xx.abs_diff(x) <= 1 && yy.abs_diff(y) <= 1 {
                    inner += at(xx, yy) / 9.0;
                }
            }
        }
        let m = ring.iter().sum::<f64>() / ring.len() as f64;
        let sd = (ring.iter().map(|v| (v - m).powi(2)).sum::<f64>() / ring.len() as f64).sqrt();
        (16.0 * (inner - m).abs() / sd.max(sigma), inner < m)
    }

    /// The stage's column-sum buffers for a reference-width window: ring, core, inner.
    fn buffers() -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        (
            std::vec![0u32; 2 * FRAME_WIDTH],
            std::vec![0u32; 2 * FRAME_WIDTH],
            std::vec![0u32; FRAME_WIDTH],
        )
    }

    fn levels(sigma: u32, max_dn: u16) -> FrameLevels {
        FrameLevels {
            p2: 1900,
            p50: 2000,
            p98: 2100,
            sigma,
            sd_shift: 0,
            max_dn,
            step_rank_code: 0,
        }
    }

    /// A band's column sums after rows enter and leave ([`Band::add`], [`Band::step`])
    /// are the sums of its rows' sampled columns, on rows of odd and even lengths (an
    /// odd row's last pixel is a sampled column) and DN above the top.
    #[test]
    fn band_sums_equal_brute_force() {
        let mut rand = super::super::xorshift32(0xBA_4D5);
        for w in [1usize, 2, 3, 13, 14, 327, 328] {
            let ws = w.div_ceil(RING_STRIDE_PX);
            let (max_dn, shift) = (4095u16, 1u32);
            let rows: Vec<Vec<u16>> = (0..9)
                .map(|_| (0..w).map(|_| (rand() % 5000) as u16).collect())
                .collect();
            let (mut dn, mut sq) = (std::vec![0u32; ws], std::vec![0u32; ws]);
            let mut band = Band {
                dn: &mut dn,
                sq: &mut sq,
            };
            for r in &rows[..4] {
                band.add(r, max_dn, shift);
            }
            // Rows 4.. enter one at a time, rows 0.. leave: the band holds 4 rows.
            for k in 4..rows.len() {
                band.step(&rows[k], &rows[k - 4], max_dn, shift);
            }
            let v = |x: u16| u32::from(x.min(max_dn) >> shift);
            for c in 0..ws {
                let held = &rows[rows.len() - 4..];
                let want_dn: u32 = held.iter().map(|r| v(r[c * RING_STRIDE_PX])).sum();
                let want_sq: u32 = held.iter().map(|r| v(r[c * RING_STRIDE_PX]).pow(2)).sum();
                assert_eq!(
                    (band.dn[c], band.sq[c]),
                    (want_dn, want_sq),
                    "w {w} column {c}"
                );
            }
        }
    }

    fn spots_of(px: &[u16], sigma: u32) -> [Option<Spot>; SPOTS] {
        let frame = Frame::new(px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let (mut a, mut b, mut c) = buffers();
        strongest_spots(&frame, Window::full(&frame), sigma, &mut a, &mut b, &mut c)
    }

    /// The streaming sums give every spot's z of direct sums (to the 1/16 unit the
    /// square root floors); each spot is the strongest centre of its 3×3; every centre
    /// of the search grid stronger than the weakest spot is near a spot (the spots are
    /// the grid's strongest, apart); the target is the strongest.
    #[test]
    fn spots_equal_brute_force() {
        let px = textured(400);
        let sigma = 3;
        let spots = spots_of(&px, sigma);
        let s0 = spots[0].expect("a spot");
        assert!(
            (200..205).contains(&s0.x) && (120..124).contains(&s0.y),
            "{s0:?}"
        );
        let z_at = |x: usize, y: usize| brute_z16(&px, x, y, f64::from(sigma)).0;
        let found: Vec<Spot> = spots.iter().flatten().copied().collect();
        assert_eq!(found.len(), SPOTS, "a textured frame fills the spots");
        for s in &found {
            let (x, y) = (usize::from(s.x), usize::from(s.y));
            let (z, colder) = brute_z16(&px, x, y, f64::from(sigma));
            assert!((f64::from(s.z16) - z.floor()).abs() <= 1.0, "{s:?} vs {z}");
            assert_eq!(s.colder, colder);
            assert!(s.z16 >= MIN_Z16);
            for yy in y - 1..=y + 1 {
                for xx in x - 1..=x + 1 {
                    assert!(z_at(xx, yy) <= z + 1.0, "({xx}, {yy}) beats {s:?}");
                }
            }
        }
        let weakest = f64::from(found.last().unwrap().z16);
        for y in (6..FRAME_HEIGHT - 6).step_by(2) {
            for x in (6..FRAME_WIDTH - 6).step_by(2) {
                if z_at(x, y) > weakest + 1.0 {
                    assert!(
                        found.iter().any(|s| {
                            x.abs_diff(usize::from(s.x)) <= SEPARATION_PX + 1
                                && y.abs_diff(usize::from(s.y)) <= SEPARATION_PX + 1
                        }),
                        "grid centre ({x}, {y}) z {} above every spot's reach",
                        z_at(x, y)
                    );
                }
            }
        }
        for (i, a) in found.iter().enumerate() {
            for b in &found[i + 1..] {
                assert!(a.z16 >= b.z16);
            }
        }
    }

    /// At 14 bits the stage works in 4-DN units: the same spot as the 12-bit frame of
    /// the DN / 4.
    #[test]
    fn deeper_frames_work_in_twelve_bits() {
        let px = textured(400);
        let deep: Vec<u16> = px.iter().map(|&v| v * 4 + 3).collect();
        let frame = Frame::new(&deep, FRAME_WIDTH, FRAME_HEIGHT, 14).unwrap();
        let (mut a, mut b, mut c) = buffers();
        let s14 = strongest_spots(&frame, Window::full(&frame), 12, &mut a, &mut b, &mut c);
        let s12 = spots_of(&px, 3);
        for (a, b) in s14.iter().zip(&s12) {
            let (a, b) = (a.unwrap(), b.unwrap());
            assert_eq!((a.x, a.y, a.z16, a.ring_sum), (b.x, b.y, b.z16, b.ring_sum));
            assert_eq!(a.shift, 2);
        }
    }

    /// The target's region is the block, and its features say so.
    #[test]
    fn the_region_is_the_target() {
        let px = textured(400);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let win = Window::full(&frame);
        let (mut a, mut b, mut c) = buffers();
        let rated = rated_spots(&frame, win, &levels(3, 4095), &mut a, &mut b, &mut c);
        let r = rated[0].expect("rated");
        assert_eq!(
            (r.roi.x0, r.roi.y0, r.roi.x1, r.roi.y1),
            (200, 120, 205, 124)
        );
        assert_eq!(r.features[10], 20, "20 px");
        assert_eq!(r.features[11], 1000, "fills its box");
        assert_eq!(r.features[1], 1, "hotter");
        assert_eq!(r.features[15], 0, "rank");
        assert!(r.score_permille <= 1000);
    }

    /// A cold spot, the frame's border and the region's reach.
    #[test]
    fn a_cold_spot_and_a_reaching_region() {
        let mut px = textured(0);
        // A cold 3×3 block at (20, 20) and a 40-px-wide warm band (reaches the edge).
        for y in 19..22 {
            for x in 19..22 {
                px[y * FRAME_WIDTH + x] -= 300;
            }
        }
        for y in 100..140 {
            for x in 100..140 {
                px[y * FRAME_WIDTH + x] += 400;
            }
        }
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let win = Window::full(&frame);
        let (mut a, mut b, mut c) = buffers();
        let rated = rated_spots(&frame, win, &levels(3, 4095), &mut a, &mut b, &mut c);
        let cold = rated
            .iter()
            .flatten()
            .find(|r| r.spot.colder)
            .expect("the cold block");
        assert_eq!(
            (cold.roi.x0, cold.roi.y0, cold.roi.x1, cold.roi.y1),
            (19, 19, 22, 22)
        );
        assert_eq!(cold.features[1], -1);
        assert_eq!(cold.features[14], 20, "20 px from the frame's edge");
        // A spot inside the band: its region fills the 17-px square and reaches its edge.
        let inside = Spot {
            x: 120,
            y: 120,
            z16: 100,
            colder: false,
            ring_sum: RING_COUNT * 2000,
            inner_sum: INNER_COUNT * 2400,
            var_n2: (120 * 20) * (120 * 20),
            clutter_n: 120 * 20,
            spread_n: 120 * 20,
            shift: 0,
        };
        let (roi, px, edge) = region(&frame, win, &inside);
        assert_eq!((roi.x0, roi.y0, roi.x1, roi.y1), (112, 112, 129, 129));
        assert_eq!(px, 17 * 17);
        assert!(edge);
        // Cut by the frame: the square's part in it, and the frame's side is no reach.
        let corner = Spot {
            x: 2,
            y: 3,
            ..inside
        };
        let flat: Vec<u16> = std::vec![2400; FRAME_WIDTH * FRAME_HEIGHT];
        let flat_frame = Frame::new(&flat, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let (roi, px, edge) = region(&flat_frame, win, &corner);
        assert_eq!((roi.x0, roi.y0, roi.x1, roi.y1), (0, 0, 11, 12));
        assert_eq!(px, 11 * 12);
        assert!(edge, "the right and bottom sides reach");
        let (_, _, edge) = region(
            &frame,
            win,
            &Spot {
                x: 20,
                y: 20,
                ..inside
            },
        );
        assert!(!edge, "the cold block alone");
    }

    /// The context: an isolated warm block on a flat sky has no departing pixel
    /// around it and no cold face, and its step is its contrast; the same block in a
    /// field of warm blocks has its neighbours around it, and a block with a cold half
    /// has both faces.
    #[test]
    fn the_context_tells_a_lone_block_from_a_field() {
        let flat = |blocks: &[(usize, usize, i32)]| {
            let mut px = std::vec![2000u16; FRAME_WIDTH * FRAME_HEIGHT];
            for &(bx, by, c) in blocks {
                for y in by..by + 4 {
                    for x in bx..bx + 4 {
                        px[y * FRAME_WIDTH + x] = (2000 + c) as u16;
                    }
                }
            }
            px
        };
        let spot = Spot {
            x: 101,
            y: 101,
            z16: 100,
            colder: false,
            ring_sum: RING_COUNT * 2000,
            inner_sum: INNER_COUNT * 2300,
            var_n2: 0,
            clutter_n: 0,
            // A spread of 10 DN.
            spread_n: RING_COUNT as u64 * 10,
            shift: 0,
        };
        let roi = Roi {
            x0: 100,
            y0: 100,
            x1: 104,
            y1: 104,
        };
        let ctx_of = |px: &[u16]| {
            let frame = Frame::new(px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
            spot_context(&frame, Window::full(&frame), &spot, roi)
        };
        let lone = ctx_of(&flat(&[(100, 100, 300)]));
        assert_eq!((lone.alike_permille, lone.any_permille), (0, 0));
        assert_eq!(
            lone.both_sixteenths,
            -16 * 300 / 10,
            "no cold face: its coldest 300 DN above"
        );
        assert_eq!(
            lone.step_sixteenths,
            16 * 300 / 10,
            "300 DN in 10-DN spreads"
        );
        // Four neighbours 8 px away, 16 px each, in the 31² − 8² = 897 context pixels.
        let field = ctx_of(&flat(&[
            (100, 100, 300),
            (108, 100, 300),
            (92, 100, 300),
            (100, 108, 300),
            (100, 92, 300),
        ]));
        assert_eq!(field.alike_permille, 1000 * 64 / 897);
        assert_eq!(field.any_permille, field.alike_permille);
        // A cold neighbour counts as departing, not alike.
        let mixed = ctx_of(&flat(&[(100, 100, 300), (108, 100, -300)]));
        assert_eq!(
            (mixed.alike_permille, mixed.any_permille),
            (0, 1000 * 16 / 897)
        );
        // A block with a cold half: both faces, the smaller 200 DN.
        let mut two = flat(&[(100, 100, 300)]);
        for y in 102..104 {
            for x in 100..104 {
                two[y * FRAME_WIDTH + x] = 1800;
            }
        }
        assert_eq!(ctx_of(&two).both_sixteenths, 16 * 200 / 10);
    }

    /// Windows under the ring and short buffers: no spot, no panic.
    #[test]
    fn small_windows_and_short_buffers_have_no_spot() {
        let px = textured(400);
        let frame = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 12).unwrap();
        let tiny = Window::clipped(&frame, 0, 0, 12, 40).unwrap();
        let (mut a, mut b, mut c) = buffers();
        assert_eq!(
            strongest_spots(&frame, tiny, 3, &mut a, &mut b, &mut c),
            [None; SPOTS]
        );
        let mut short = std::vec![0u32; FRAME_WIDTH - 1];
        let full = Window::full(&frame);
        assert_eq!(
            strongest_spots(&frame, full, 3, &mut short, &mut b, &mut c),
            [None; SPOTS]
        );
        // A window of exactly the ring around the target's centre: one centre, which
        // the 3×3 cannot leave (its ring misses the 5×4 target).
        let one = Window::clipped(&frame, 196, 116, 196 + RING_PX, 116 + RING_PX).unwrap();
        let s = strongest_spots(&frame, one, 3, &mut a, &mut b, &mut c);
        assert!(s.iter().flatten().all(|s| (s.x, s.y) == (202, 122)));
        assert!(s[0].is_some(), "the target's corner is a spot");
    }
}
