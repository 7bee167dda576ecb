//! Otsu's global threshold (Otsu 1979, paper ref. \[47\]), exact on the full bit depth.
//!
//! The threshold `t` splits the DN into a background class `v ≤ t` and a foreground
//! class `v > t`; Otsu's choice maximises the between-class variance
//! `σ_B²(t) ∝ (M·n₀ − N·m₀)² / (n₀·(N − n₀))` (N pixels summing to M; n₀ pixels
//! summing to m₀ in the background class).
//!
//! A full 2^14-bin histogram would take 64 KiB. Instead the detector histograms the
//! frame into [`COARSE_BINS`] bins (count and sum of each), evaluates σ_B² exactly at
//! every bin boundary, and bounds it from above inside every bin (branch and bound).
//! Only bins whose bound reaches the best boundary value (and that pass the
//! nearest-mean condition below) are histogrammed at full resolution in further
//! passes, [`FINE_SLOTS`] DN at a time. All arithmetic is exact
//! integer arithmetic, so the result equals an exhaustive search over every threshold
//! `0..max_dn`, ties going to the smallest threshold. Typical frames need one extra
//! pass, two-valued frames none.
//!
//! **Worst case.** Only bins that can hold an optimal split are refined, and an optimal
//! split obeys the nearest-mean condition. Maximising σ_B² minimises the within-class
//! sum of squares, and Otsu's split minimises it over all two-class partitions (a 1-D
//! 2-means optimum, which always separates the classes by a threshold). Moving one
//! background pixel `x` to the foreground changes that sum by
//! `n₁/(n₁+1)·(x − μ₁)² − n₀/(n₀−1)·(x − μ₀)² ≥ 0`, so `|x − μ₁| ≥ |x − μ₀|`: the brightest
//! background pixel has `x ≤ (μ₀ + μ₁)/2` (trivially when `n₀ = 1`), and likewise the
//! darkest foreground pixel `y ≥ (μ₀ + μ₁)/2`. With `μ₀ ≤ M/N ≤ μ₁` and every DN in
//! `v_min..=v_max`, a split strictly inside a bin `lo..=hi` needs
//! `lo ≤ x ≤ (M/N + v_max)/2` and `hi ≥ y ≥ (v_min + M/N)/2`: the bin's start lies in an
//! interval shorter than `(v_max − v_min)/2 + width < 65 · width`, so at most
//! [`MAX_REFINED_BINS`] = 65 bins are ever refined, in at most
//! [`max_refinement_passes`] frame reads (17 at 14 bits). A histogram whose
//! between-class variance is flat over the whole allowed interval
//! ([`fill_flat_variance`]) makes the branch and bound refine 64 of them: 16 passes at
//! 14 bits.
//!
//! The reported [`Detection::threshold`](super::Detection::threshold) is that smallest
//! maximising `t`, i.e. the brightest DN present in the background class. A frame
//! with a single DN value has no split: its threshold is that DN and no pixel is
//! foreground.

use super::{BoxRule, DetectError, Detector, Scratch};
use crate::capacity::{ConstInit, Counter, FrameCapacity, Reference};
use crate::frame::Frame;

/// Coarse histogram bins (a bin spans `2^(bits − 7)` DN for bit depths above 7).
pub const COARSE_BINS: usize = 128;
const COARSE_SHIFT_BITS: u8 = 7;
/// Interleaved copies of the histograms: consecutive pixels, which in a dark sky all
/// land in the same bin, go to different copies, so increments do not wait on each
/// other (a store-to-load chain through one counter costs ~5 cycles per pixel).
const LANES: usize = 4;
/// Full-resolution counters for the refinement passes (DN values per pass).
pub const FINE_SLOTS: usize = 512;
/// Marks a coarse bin that is not refined in the current pass.
const NOT_REFINED: u8 = u8::MAX;
/// The most coarse bins one call refines at full resolution, for any frame and bit
/// depth: the nearest-mean condition (module documentation) leaves an interval shorter
/// than 65 bin widths for the starts of the bins that may hold the optimal split.
pub const MAX_REFINED_BINS: usize = COARSE_BINS / 2 + 1;

/// Bins refined per frame read at bit depth `bits` (`FINE_SLOTS` / bin width; 4 at 14
/// bits), or 0 when the coarse histogram is already at full resolution (`bits ≤ 7`).
pub const fn bins_per_pass(bits: u8) -> usize {
    let shift = bits.saturating_sub(COARSE_SHIFT_BITS);
    if shift == 0 {
        return 0;
    }
    let per_pass = FINE_SLOTS >> shift;
    if per_pass == 0 {
        1
    } else if per_pass > NOT_REFINED as usize {
        NOT_REFINED as usize
    } else {
        per_pass
    }
}

/// The most refinement passes (frame reads after the histogram pass, before the mask
/// pass) one call makes at bit depth `bits`, on any frame: ⌈[`MAX_REFINED_BINS`] /
/// [`bins_per_pass`]⌉ (17 at 14 bits, 65 at 16 bits, 0 at 7 bits and below).
pub const fn max_refinement_passes(bits: u8) -> usize {
    match bins_per_pass(bits) {
        0 => 0,
        per_pass => MAX_REFINED_BINS.div_ceil(per_pass),
    }
}

/// Parameters of the Otsu detector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Otsu {
    /// Mask-to-box rule (default [`BoxRule::AllForeground`]).
    pub box_rule: BoxRule,
}

/// Otsu's buffers at capacity `C`: the coarse histogram, the refinement counters and
/// a mask row.
#[derive(Debug, Clone)]
pub struct OtsuWork<C: FrameCapacity = Reference> {
    /// Per coarse bin and lane: pixel count in the high 32 bits, sum of `v − bin_start`
    /// in the low 32 (≤ (2^9 − 1) · W·H < 2^32 for every capacity, checked in
    /// [`crate::capacity`]: 4.2·10^7 at 328×248, 4.0·10^8 at 1024×768), so the
    /// histogram pass does one add per pixel. Lane 0 holds the totals after the pass.
    coarse: [[u64; COARSE_BINS]; LANES],
    /// Pixels per DN of the bins being refined, in two lanes (even and odd pixels;
    /// each at most `⌈W·H/2⌉`: 40 672 at 328×248, so `u16` holds them; capacities of
    /// more than 131 070 pixels count in `u32`: [`FrameCapacity::FineCount`]).
    fine: [[C::FineCount; FINE_SLOTS]; 2],
    /// Position of each coarse bin in `fine` (in bins), or [`NOT_REFINED`].
    slot: [u8; COARSE_BINS],
    mask: C::Row<bool>,
    /// Refinement passes (frame reads) of the last call.
    passes: u8,
}

impl<C: FrameCapacity> OtsuWork<C> {
    /// Refinement passes of the last call: frame reads between the histogram pass and
    /// the mask pass, at most [`max_refinement_passes`] of the frame's bit depth (0
    /// before the first call).
    pub fn refinement_passes(&self) -> u8 {
        self.passes
    }
}

impl<C: FrameCapacity> ConstInit for OtsuWork<C> {
    const INIT: Self = OtsuWork {
        coarse: [[0; COARSE_BINS]; LANES],
        fine: [[ConstInit::INIT; FINE_SLOTS]; 2],
        // Zero bytes (a `static` scratch lands in `.bss`): every call fills `slot` with
        // NOT_REFINED before reading it.
        slot: [0; COARSE_BINS],
        mask: ConstInit::INIT,
        passes: 0,
    };
}

/// The Otsu detector's scratch memory at capacity `C` (default 328×248).
pub type OtsuScratch<C = Reference> = Scratch<OtsuWork<C>, C>;

/// Bytes of [`OtsuScratch`] at 328×248 (budget: 16 KiB).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<OtsuScratch>();

/// An exact value of the between-class variance, up to the common factor 1/N⁴:
/// `d² / den` with `d = M·n₀ − N·m₀` and `den = n₀·(N − n₀)`.
///
/// Bounds, for frames up to the largest capacity (N ≤ 1024·768 < 2^20, DN < 2^16):
/// `|d| = n₀·n₁·|μ₁ − μ₀| ≤ (N²/4)·2^16 < 2^54`, so `d² < 2^108`; `den ≤ N²/4 < 2^38`,
/// so the cross-multiplied remainders stay below 2^76; the branch-and-bound's
/// `|d_a| + k·S` (`S ≤ N·2^16`) stays below 2^57. All far inside `u128`/`i128`.
#[derive(Debug, Clone, Copy)]
struct Score {
    d2: u128,
    den: u128,
}

impl Score {
    const ZERO: Score = Score { d2: 0, den: 1 };

    fn of(d: i128, den: u128) -> Score {
        Score {
            d2: d.unsigned_abs() * d.unsigned_abs(),
            den,
        }
    }

    /// Exact comparison of `d2/den` with `other.d2/other.den` without overflow:
    /// compare the integer quotients, then the remainders cross-multiplied
    /// (each remainder is below its denominator ≤ 2^32).
    fn cmp(&self, other: &Score) -> core::cmp::Ordering {
        // Fast path: the f64 ratios differ by far more than their rounding error.
        let a = self.d2 as f64 / self.den as f64;
        let b = other.d2 as f64 / other.den as f64;
        if a > b * (1.0 + 1e-9) {
            return core::cmp::Ordering::Greater;
        }
        if a < b * (1.0 - 1e-9) {
            return core::cmp::Ordering::Less;
        }
        // Every score has `den ≥ 1` (both classes non-empty, or `ZERO`); `max(1)` says
        // so to the compiler, so the flight build has no division-by-zero branch.
        let (den1, den2) = (self.den.max(1), other.den.max(1));
        let (q1, r1) = (self.d2 / den1, self.d2 % den1);
        let (q2, r2) = (other.d2 / den2, other.d2 % den2);
        q1.cmp(&q2).then((r1 * other.den).cmp(&(r2 * self.den)))
    }
}

/// The best split so far: its score and its background-class size (tie-breaker: a
/// smaller background class means a smaller threshold).
#[derive(Debug, Clone, Copy)]
struct Best {
    score: Score,
    n0: u64,
    /// A threshold realising the split (the largest DN of its bin or slot).
    t: u16,
}

impl Best {
    fn offer(&mut self, score: Score, n0: u64, t: u16) {
        let better = match score.cmp(&self.score) {
            core::cmp::Ordering::Greater => true,
            core::cmp::Ordering::Equal => n0 < self.n0,
            core::cmp::Ordering::Less => false,
        };
        if better {
            *self = Best { score, n0, t };
        }
    }
}

/// Totals of the frame used by every score.
struct Totals {
    n: u64,
    m: u64,
}

impl Totals {
    /// Score of the split with `n0` pixels summing to `m0` in the background, or
    /// `None` when a class is empty.
    fn score(&self, n0: u64, m0: u64) -> Option<Score> {
        if n0 == 0 || n0 >= self.n {
            return None;
        }
        let d = i128::from(self.m) * i128::from(n0) - i128::from(self.n) * i128::from(m0);
        Some(Score::of(d, u128::from(n0) * u128::from(self.n - n0)))
    }
}

/// Histogram, boundary scores, branch and bound: a threshold realising the exact
/// optimum (the mask pass later maps it to the smallest such threshold).
fn otsu_split<C: FrameCapacity>(frame: &Frame<'_>, work: &mut OtsuWork<C>) -> u16 {
    let max_dn = frame.max_dn();
    let shift = frame.bits().saturating_sub(COARSE_SHIFT_BITS);
    let bin_width = 1usize << shift;
    // At most COARSE_BINS (max_dn >> shift < 2^7 for any bit depth); `min` tells the
    // compiler, so indexing by a bin needs no bounds check.
    let bins = ((usize::from(max_dn) >> shift) + 1).min(COARSE_BINS);
    let low_mask = (bin_width - 1) as u16;
    work.passes = 0;

    let lanes = &mut work.coarse;
    for lane in lanes.iter_mut() {
        lane.fill(0);
    }
    // `& (COARSE_BINS − 1)` never changes an index (v >> shift < 128); it lets the
    // compiler drop the bounds check.
    let entry = |v: u16| {
        let v = v.min(max_dn);
        let bin = usize::from(v >> shift) & (COARSE_BINS - 1);
        (bin, (1 << 32) | u64::from(v & low_mask))
    };
    let mut quads = frame.pixels().chunks_exact(LANES);
    for quad in &mut quads {
        for (lane, &v) in lanes.iter_mut().zip(quad) {
            let (bin, add) = entry(v);
            lane[bin] += add;
        }
    }
    let [total, rest @ ..] = lanes;
    for &v in quads.remainder() {
        let (bin, add) = entry(v);
        total[bin] += add;
    }
    for lane in rest.iter() {
        for (t, &c) in total.iter_mut().zip(lane) {
            *t += c;
        }
    }
    let coarse = &*total;
    // `b < bins ≤ COARSE_BINS`: the mask never changes the index (no bounds check).
    let count = |b: usize| coarse[b & (COARSE_BINS - 1)] >> 32;
    let sum =
        |b: usize| count(b) * ((b as u64) << shift) + (coarse[b & (COARSE_BINS - 1)] & 0xFFFF_FFFF);
    let totals = Totals {
        n: frame.pixels().len() as u64,
        m: (0..bins).map(sum).sum(),
    };

    // Exact scores at the bin boundaries (threshold = last DN of bin b).
    let mut best = Best {
        score: Score::ZERO,
        n0: u64::MAX,
        t: max_dn,
    };
    let (mut n0, mut m0) = (0u64, 0u64);
    let (mut first_bin, mut last_bin) = (bins, 0);
    for b in 0..bins {
        n0 += count(b);
        m0 += sum(b);
        if count(b) > 0 {
            first_bin = first_bin.min(b);
            last_bin = b;
        }
        if let Some(s) = totals.score(n0, m0) {
            best.offer(s, n0, (((b + 1) << shift) - 1) as u16);
        }
    }
    let nearest = NearestMean::new(&totals, first_bin << shift, ((last_bin + 1) << shift) - 1);
    if bin_width == 1 {
        // Already at full resolution (no split at all: a single DN value, all background).
        return best.t;
    }

    // Branch and bound: histogram at full resolution, a few bins per pass, the bins
    // whose bound reaches the best score so far (in order; later passes prune more).
    // ≥ 1 here (bin_width > 1): the same count the stated pass bound uses.
    let bins_per_pass = bins_per_pass(frame.bits());
    // Bins that can hold an optimal split (at most MAX_REFINED_BINS): a pass count of
    // at most ⌈MAX_REFINED_BINS / bins_per_pass⌉.
    let mut next_bin = 0;
    loop {
        let slot = &mut work.slot;
        slot.fill(NOT_REFINED);
        let mut picked = 0u8;
        let (mut n_a, mut m_a) = (0u64, 0u64);
        for (b, bin_slot) in slot[..bins].iter_mut().enumerate() {
            let (n_b, m_b) = (n_a + count(b), m_a + sum(b));
            if b >= next_bin
                && usize::from(picked) < bins_per_pass
                && count(b) > 1
                && nearest.may_hold_split(b << shift, ((b + 1) << shift) - 1)
                && bin_may_beat(&totals, &best, b, shift, (n_a, m_a), (n_b, m_b))
            {
                *bin_slot = picked;
                picked += 1;
                next_bin = b + 1;
            }
            (n_a, m_a) = (n_b, m_b);
        }
        if picked == 0 {
            return best.t;
        }
        work.passes = work.passes.saturating_add(1);
        let [even, odd] = &mut work.fine;
        // picked ≤ bins_per_pass, so `used` ≤ FINE_SLOTS (bin_width ≤ 2^9 = FINE_SLOTS
        // at 16 bits); `min` only says so.
        let used = (usize::from(picked) * bin_width).min(FINE_SLOTS);
        even[..used].fill(ConstInit::INIT);
        odd[..used].fill(ConstInit::INIT);
        let index = |v: u16| {
            let v = v.min(max_dn);
            let s = slot[usize::from(v >> shift) & (COARSE_BINS - 1)];
            (s != NOT_REFINED).then(|| {
                (usize::from(s) * bin_width + usize::from(v & low_mask)) & (FINE_SLOTS - 1)
            })
        };
        let mut pairs = frame.pixels().chunks_exact(2);
        for pair in &mut pairs {
            if let Some(i) = index(pair[0]) {
                even[i].increment();
            }
            if let Some(i) = index(pair[1]) {
                odd[i].increment();
            }
        }
        for &v in pairs.remainder() {
            if let Some(i) = index(v) {
                even[i].increment();
            }
        }
        // `i < used ≤ FINE_SLOTS`: the mask never changes it (no bounds check).
        let fine = |i: usize| {
            let i = i & (FINE_SLOTS - 1);
            even[i].get() + odd[i].get()
        };
        // Exact scores at every DN of the picked bins.
        let (mut n0, mut m0) = (0u64, 0u64);
        for (b, &s) in slot[..bins].iter().enumerate() {
            if s != NOT_REFINED {
                let (mut n, mut m) = (n0, m0);
                let base = usize::from(s) * bin_width;
                for k in 0..bin_width - 1 {
                    let c = fine(base + k);
                    let v = ((b as u64) << shift) + k as u64;
                    n += u64::from(c);
                    m += u64::from(c) * v;
                    if let Some(sc) = totals.score(n, m) {
                        best.offer(sc, n, v as u16);
                    }
                }
            }
            n0 += count(b);
            m0 += sum(b);
        }
        if usize::from(picked) < bins_per_pass {
            // Every remaining candidate was in this pass.
            return best.t;
        }
    }
}

/// The nearest-mean condition of an optimal split (module documentation), in exact
/// integers: the brightest background DN `x` obeys `2·N·x ≤ M + N·v_max` and the darkest
/// foreground DN `y` obeys `2·N·y ≥ M + N·v_min`.
struct NearestMean {
    /// `2·N`.
    two_n: u64,
    /// `M + N·v_min`.
    low: u64,
    /// `M + N·v_max`.
    high: u64,
}

impl NearestMean {
    /// The condition for a frame of these totals whose DN lie in `v_min..=v_max`
    /// (bounds from the coarse histogram: the first DN of the first occupied bin, the
    /// last of the last; any wider range is also correct, only less tight).
    fn new(totals: &Totals, v_min: usize, v_max: usize) -> Self {
        NearestMean {
            two_n: 2 * totals.n,
            low: totals.m + totals.n * v_min as u64,
            high: totals.m + totals.n * v_max as u64,
        }
    }

    /// False when no optimal split can lie strictly inside the DN `lo..=hi`: it would
    /// need a background pixel `x ≥ lo` and a foreground pixel `y ≤ hi` there.
    /// (`2·N·DN < 2^37` and `M + N·v < 2^37` for every capacity: no overflow.)
    fn may_hold_split(&self, lo: usize, hi: usize) -> bool {
        self.two_n * lo as u64 <= self.high && self.two_n * hi as u64 >= self.low
    }
}

/// Upper bound of σ_B² over the thresholds strictly inside bin `b` (DN
/// `lo..lo + width − 1`), compared with `best`: true when the bin could hold a split
/// at least as good. `(n_a, m_a)` and `(n_b, m_b)` are the background class before
/// and after the bin.
///
/// Inside the bin, `d = M·n₀ − N·m₀` moves from `d_a` to `d_b` by `M − N·v` per pixel
/// of DN `v`, at most `S = max_v |M − N·v|` in size. So at `n₀ = n`,
/// `|d| ≤ |d_a| + (n − n_a)·S` and `|d| ≤ |d_b| + (n_b − n)·S`; and when the bin lies on
/// one side of the mean `M/N` the steps share a sign, so also `|d| ≤ max(|d_a|, |d_b|)`.
/// Each of the first two bounds, squared over `n(N − n)`, is quasiconvex in `n` (a
/// positive linear function over the square root of a positive concave one), so its
/// maximum over the bin is at an end; the third is largest where `n(N − n)` is
/// smallest, also at an end. The smallest of the three maxima bounds σ_B² in the bin.
fn bin_may_beat(
    totals: &Totals,
    best: &Best,
    b: usize,
    shift: u8,
    (n_a, m_a): (u64, u64),
    (n_b, m_b): (u64, u64),
) -> bool {
    let n_lo = n_a.max(1);
    let n_hi = n_b.min(totals.n - 1);
    if n_lo > n_hi {
        return false;
    }
    let (n, m) = (i128::from(totals.n), i128::from(totals.m));
    let lo = (b as i128) << shift;
    let hi = lo + (1i128 << shift) - 1;
    let d_a = (m * i128::from(n_a) - n * i128::from(m_a)).unsigned_abs();
    let d_b = (m * i128::from(n_b) - n * i128::from(m_b)).unsigned_abs();
    let (step_lo, step_hi) = (m - n * lo, m - n * hi);
    let step = step_lo.unsigned_abs().max(step_hi.unsigned_abs());
    let den = |k: u64| u128::from(k) * u128::from(totals.n - k);
    let score = |d: u128, k: u64| Score {
        d2: d * d,
        den: den(k),
    };
    let larger = |x: Score, y: Score| if x.cmp(&y).is_ge() { x } else { y };
    let smaller = |x: Score, y: Score| if x.cmp(&y).is_le() { x } else { y };
    let from_a = |k: u64| score(d_a + u128::from(k - n_a) * step, k);
    let from_b = |k: u64| score(d_b + u128::from(n_b - k) * step, k);
    let mut bound = smaller(
        larger(from_a(n_lo), from_a(n_hi)),
        larger(from_b(n_lo), from_b(n_hi)),
    );
    if (step_lo >= 0) == (step_hi >= 0) {
        let cap = d_a.max(d_b);
        bound = smaller(bound, larger(score(cap, n_lo), score(cap, n_hi)));
    }
    bound.cmp(&best.score).is_ge()
}

/// Otsu's worst case (module documentation, "Worst case"): fills `pixels` (any frame,
/// raster order) with DN in `0..=max_dn` whose between-class variance is as flat as
/// integers allow over the whole interval where an optimal split may lie, so the branch
/// and bound prunes (almost) nothing there. `spike_px` pixels (at least 1) are 0 and as
/// many are `max_dn`; the dark half of the others is placed pixel by pixel, each at the
/// DN that keeps the score of every split equal to the one just after the dark spike
/// (`d(n₀)² = c·n₀·(N − n₀)`, `d` rising by `M − N·v` per pixel of DN `v`); the bright
/// half mirrors it about `max_dn / 2` (so `M = N·max_dn/2`). Spikes of 100 or 1 000 pixels
/// on a 328×248 14-bit frame make [`Otsu`] refine 64 bins in 16 passes
/// ([`max_refinement_passes`]: 17). Integer arithmetic only, no panics (the firmware
/// makes the frame on board).
pub fn fill_flat_variance(pixels: &mut [u16], max_dn: u16, spike_px: usize) {
    let n = pixels.len();
    let half = n / 2;
    let spike = spike_px.clamp(1, half.max(1));
    let n128 = n as u128;
    // Total sum of the mirrored histogram (rounded down for an odd N·max_dn).
    let m = n128 * u128::from(max_dn) / 2;
    let mut m0 = 0u128;
    let (dark, rest) = pixels.split_at_mut(half);
    for (i, px) in dark.iter_mut().enumerate() {
        let v = if i < spike {
            0
        } else {
            // d = M·n₀ − N·m₀ ≥ 0 in the dark half; target after this pixel:
            // t = sqrt(c·den') with c = M²·spike/(N − spike), den' = (n₀+1)(N − n₀ − 1),
            // computed as M·sqrt(spike·den'·2^64/(N − spike))/2^32 (< 2^97: no overflow
            // for N < 2^20, DN < 2^16).
            let n0 = i as u128;
            let d = m * n0 - (n128 * m0).min(m * n0);
            let den = (n0 + 1) * (n128 - n0 - 1);
            let q = ((spike as u128 * den) << 64) / (n128 - spike as u128).max(1);
            let t = (m * q.isqrt()) >> 32;
            ((m + d).saturating_sub(t) / n128.max(1)).min(u128::from(max_dn / 2)) as u16
        };
        *px = v;
        m0 += u128::from(v);
    }
    // The bright half mirrors the dark one (an odd N puts max_dn/2 in the middle).
    for (px, &v) in rest.iter_mut().rev().zip(dark.iter()) {
        *px = max_dn - v;
    }
    if n % 2 == 1 {
        if let Some(middle) = rest.first_mut() {
            *middle = max_dn / 2;
        }
    }
}

/// The parameters as `name=value` pairs separated by spaces (as in tuning reports
/// and tuned sets).
impl core::fmt::Display for Otsu {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "box={}", self.box_rule)
    }
}

impl Detector for Otsu {
    type Work<C: FrameCapacity> = OtsuWork<C>;
    const NAME: &'static str = "otsu";

    fn validate(&self) -> Result<(), DetectError> {
        Ok(())
    }

    fn box_rule(&self) -> BoxRule {
        self.box_rule
    }

    fn set_box_rule(&mut self, rule: BoxRule) {
        self.box_rule = rule;
    }

    /// Foreground: `DN > t`. Threshold: the smallest `t` maximising the between-class
    /// variance, in DN.
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut OtsuWork<C>,
        mut sink: F,
    ) -> u32 {
        let t = otsu_split(frame, work);
        let max_dn = frame.max_dn();
        // The split is the same for every t between the brightest background DN and
        // the darkest foreground DN; report the smallest, as an exhaustive search would.
        let mut brightest_background = 0u16;
        let mask = &mut work.mask.as_mut()[..frame.width()];
        for (y, row) in frame.rows().enumerate() {
            for (m, &v) in mask.iter_mut().zip(row) {
                let v = v.min(max_dn);
                let fg = v > t;
                *m = fg;
                brightest_background = brightest_background.max(if fg { 0 } else { v });
            }
            sink(y, mask);
        }
        u32::from(brightest_background)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::roi::Roi;

    #[test]
    fn score_comparison_is_exact_near_ties() {
        let a = Score { d2: 10, den: 3 };
        let b = Score { d2: 20, den: 6 };
        assert_eq!(a.cmp(&b), core::cmp::Ordering::Equal);
        let c = Score { d2: 21, den: 6 };
        assert_eq!(a.cmp(&c), core::cmp::Ordering::Less);
    }

    #[test]
    fn roi_of_bright_square() {
        let mut px = [100u16; 16 * 12];
        for y in 3..7 {
            for x in 5..9 {
                px[y * 16 + x] = 9000;
            }
        }
        let f = Frame::new(&px, 16, 12, 14).unwrap();
        let mut s = OtsuScratch::new();
        let d = Otsu::default().detect(&f, &mut s).unwrap();
        assert_eq!(d.roi, Some(Roi::new(5, 3, 9, 7)));
        assert_eq!(d.threshold, 100);
        assert_eq!(d.foreground_px, 16);
    }
}
