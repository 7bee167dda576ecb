//! Weak gradient elimination (WGE) of the Sharma–Ventura–D'Amico (SVD) architecture
//! (paper ref. \[4\]): keep the pixels of strongest gradient, box what remains.
//!
//! The gradient is the Prewitt operator, its magnitude the L1 norm
//! `g = |g_x| + |g_y|` (integers, ≤ 6·max_dn), on interior pixels only (the one-pixel
//! border has no full 3×3 neighbourhood and is never foreground). The weakest
//! `drop_fraction` of the interior gradients are eliminated: with `N` interior pixels
//! and `k = ⌊drop_fraction·N⌋`, the threshold is the `k`-th smallest gradient
//! (0-based), raised to at least `min_gradient`, and a pixel is foreground when
//! `g ≥ threshold`. The order statistic is exact: a coarse histogram of
//! [`COARSE_BINS`] bins finds the bin holding it, a second pass histograms that bin at
//! full resolution, and a third pass streams the mask. For the all-foreground rule the
//! second pass also keeps the hull of the pixels above that bin and, per gradient
//! value inside it, the hull of its pixels, so the box needs no third pass (up to
//! 14-bit DN, when `min_gradient` does not lift the threshold out of the bin). No
//! gradient image is stored; each pass recomputes the gradients of one row from three
//! frame rows.

use super::{BoxRule, DetectError, Detection, Detector, Roi, Scratch};
use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::Frame;

/// Counters of the gradient histogram: [`COARSE_LANES`] interleaved copies of
/// `COARSE_BINS / COARSE_LANES` coarse bins (a bin spans `2^(bits+3−9)` gradient
/// values: 256 at 14 bits), reused by the refinement pass as full-resolution counters.
pub const COARSE_BINS: usize = 1024;
/// Interleaved copies of the coarse histogram: neighbouring pixels, which in a flat
/// sky share a bin, count into different copies so increments do not wait on each
/// other.
pub const COARSE_LANES: usize = 2;
const LANE_BINS: usize = COARSE_BINS / COARSE_LANES;
const COARSE_BITS: u8 = 9;

/// Parameters of the WGE detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wge {
    /// Fraction of interior pixels, weakest gradients first, to eliminate: 0..=1.
    /// Default 0.97 (keep the strongest 3 %, about the edge pixels of a close target).
    pub drop_fraction: f32,
    /// Smallest gradient ever kept, in Prewitt L1 units (DN): keeps flat frames empty.
    /// Default 48 (a step of 8 DN seen by all six taps).
    pub min_gradient: u32,
    /// Mask-to-box rule (default [`BoxRule::AllForeground`]).
    pub box_rule: BoxRule,
}

impl Default for Wge {
    fn default() -> Self {
        Wge {
            drop_fraction: 0.97,
            min_gradient: 48,
            box_rule: BoxRule::AllForeground,
        }
    }
}

/// WGE's buffers at capacity `C`: the gradient histogram, one gradient row and one
/// mask row. Counts are `u32` (at most the interior pixels, `< W·H`); gradients are at
/// most `6 · 65 535`; hull rows are `u16` (`H < 65 535`).
#[derive(Debug, Clone)]
pub struct WgeWork<C: FrameCapacity = Reference> {
    hist: [u32; COARSE_BINS],
    gradient: C::Row<u32>,
    mask: C::Row<bool>,
}

impl<C: FrameCapacity> ConstInit for WgeWork<C> {
    const INIT: Self = WgeWork {
        hist: [0; COARSE_BINS],
        gradient: ConstInit::INIT,
        mask: ConstInit::INIT,
    };
}

/// The WGE detector's scratch memory at capacity `C` (default 328×248).
pub type WgeScratch<C = Reference> = Scratch<WgeWork<C>, C>;

/// Bytes of [`WgeScratch`] at 328×248 (budget: 16 KiB).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<WgeScratch>();

/// Prewitt L1 gradient magnitudes of interior row `y` (1..h−1) into `out[1..w−1]`;
/// `out[0]` and `out[w−1]` are 0. `rows` are rows y−1, y, y+1; DN above `max_dn`
/// count as `max_dn`.
pub fn prewitt_row(rows: [&[u16]; 3], max_dn: u16, out: &mut [u32]) {
    let [r0, r1, r2] = rows;
    let w = out.len().min(r0.len()).min(r1.len()).min(r2.len());
    if w < 3 {
        out.fill(0);
        return;
    }
    let n = w - 2;
    // Nine equal-length shifted views: no bounds checks, and the loop vectorises.
    let (t0, t1, t2) = (&r0[..n], &r0[1..=n], &r0[2..n + 2]);
    let (m0, m2) = (&r1[..n], &r1[2..n + 2]);
    let (b0, b1, b2) = (&r2[..n], &r2[1..=n], &r2[2..n + 2]);
    let inner = &mut out[1..=n];
    if u32::from(max_dn) * 3 <= u32::from(u16::MAX) {
        // Up to 14-bit DN, sums of three fit a u16 and |a − b| = max − min: the loop
        // runs on twice as many SIMD lanes as in i32.
        let c = |v: u16| v.min(max_dn);
        for i in 0..n {
            let left = c(t0[i]) + c(m0[i]) + c(b0[i]);
            let right = c(t2[i]) + c(m2[i]) + c(b2[i]);
            let top = c(t0[i]) + c(t1[i]) + c(t2[i]);
            let bottom = c(b0[i]) + c(b1[i]) + c(b2[i]);
            let gx = right.max(left) - right.min(left);
            let gy = bottom.max(top) - bottom.min(top);
            inner[i] = u32::from(gx) + u32::from(gy);
        }
    } else {
        let c = |v: u16| i32::from(v.min(max_dn));
        for i in 0..n {
            let left = c(t0[i]) + c(m0[i]) + c(b0[i]);
            let right = c(t2[i]) + c(m2[i]) + c(b2[i]);
            let top = c(t0[i]) + c(t1[i]) + c(t2[i]);
            let bottom = c(b0[i]) + c(b1[i]) + c(b2[i]);
            inner[i] = (right - left).unsigned_abs() + (bottom - top).unsigned_abs();
        }
    }
    out[0] = 0;
    out[w - 1] = 0;
}

/// Calls `f(y, gradients)` for every interior row of `frame`.
fn for_each_gradient_row(frame: &Frame<'_>, buf: &mut [u32], mut f: impl FnMut(usize, &[u32])) {
    let max_dn = frame.max_dn();
    let mut rows = frame.rows();
    let (Some(mut r0), Some(mut r1)) = (rows.next(), rows.next()) else {
        return;
    };
    for (i, r2) in rows.enumerate() {
        prewitt_row([r0, r1, r2], max_dn, buf);
        f(i + 1, buf);
        (r0, r1) = (r1, r2);
    }
}

/// The interior of a row (without its first and last pixel; empty below 3 pixels):
/// `&row[1..len − 1]` without a panic branch.
fn inner_px(row: &[u32]) -> &[u32] {
    row.get(1..row.len().saturating_sub(1)).unwrap_or_default()
}

/// [`inner_px`] of a mask row, mutable.
fn inner_px_mut(row: &mut [bool]) -> &mut [bool] {
    let end = row.len().saturating_sub(1);
    row.get_mut(1..end).unwrap_or_default()
}

/// What the histogram passes found.
struct Passes {
    /// The threshold (order statistic raised to `min_gradient`), `u32::MAX` when
    /// everything is eliminated.
    threshold: u32,
    /// For the all-foreground rule, when the second pass could collect it: the hull of
    /// the foreground and the foreground pixel count.
    hull: Option<(Option<Roi>, u32)>,
}

impl Wge {
    /// Number of interior gradients eliminated out of `n`: `⌊drop_fraction·n⌋`.
    pub fn drop_count(&self, n: u32) -> u32 {
        ((self.drop_fraction * n as f32) as u32).min(n)
    }

    /// The threshold: the `k`-th smallest interior gradient (0-based) by a coarse and a
    /// fine histogram pass, raised to `min_gradient`. With `want_hull`, the fine pass
    /// also collects the hull of the pixels above the bin and, per gradient value in
    /// the bin, the hull of its pixels, so that the all-foreground box needs no third
    /// pass (when the threshold stays inside the bin).
    fn passes<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        work: &mut WgeWork<C>,
        want_hull: bool,
    ) -> Passes {
        let (w, h) = (frame.width(), frame.height());
        let interior = (w.saturating_sub(2) * h.saturating_sub(2)) as u32;
        let none = Passes {
            threshold: u32::MAX,
            hull: want_hull.then_some((None, 0)),
        };
        if interior == 0 {
            return none;
        }
        let k = self.drop_count(interior);
        let shift = (frame.bits() + 3).saturating_sub(COARSE_BITS);
        let WgeWork { hist, gradient, .. } = work;
        let grad = &mut gradient.as_mut()[..w];
        hist.fill(0);
        {
            let (even, odd) = hist.split_at_mut(LANE_BINS);
            // `& (LANE_BINS − 1)` never changes an index (g ≤ 6·max_dn < 2^(bits+3));
            // it lets the compiler drop the bounds check.
            let bin = |v: u32| (v >> shift) as usize & (LANE_BINS - 1);
            for_each_gradient_row(frame, grad, |_, g| {
                let mut pairs = inner_px(g).chunks_exact(2);
                for pair in &mut pairs {
                    even[bin(pair[0])] += 1;
                    odd[bin(pair[1])] += 1;
                }
                for &v in pairs.remainder() {
                    even[bin(v)] += 1;
                }
            });
            for (e, &o) in even.iter_mut().zip(odd.iter()) {
                *e += o;
            }
        }
        let hist_coarse = &hist[..LANE_BINS];
        // The coarse bin holding the k-th value, how many lie below and above it.
        let mut below = 0u32;
        let Some(bin) = hist_coarse.iter().position(|&c| {
            below += c;
            below > k
        }) else {
            return none;
        };
        below -= hist_coarse[bin];
        let above = interior - below - hist_coarse[bin];
        let bin = bin as u32;
        if shift == 0 {
            return Passes {
                threshold: bin.max(self.min_gradient),
                hull: None,
            };
        }

        // Full resolution inside that bin, reusing the histogram: counts, and with
        // `want_hull` the hull of each value's pixels (x0, x1, y0 << 16 | y1).
        let lo = bin << shift;
        let width = 1usize << shift;
        let hi = lo + width as u32 - 1;
        // Tracking hulls costs four counter updates per pixel of the bin: when the bin
        // holds most of the frame (a flat sky), the third pass is cheaper.
        let in_bin = interior - below - above;
        let want_hull = want_hull && 4 * width <= COARSE_BINS && in_bin <= interior / 4;
        // Without hulls, a second lane of counters (odd pixels) when it fits.
        let lanes = !want_hull && 2 * width <= COARSE_BINS;
        let hull_width = if want_hull || lanes { width } else { 0 };
        // The splits always fit (width ≤ 2^10 = COARSE_BINS; with hulls 4·width ≤
        // COARSE_BINS, with lanes 2·width ≤ COARSE_BINS): the checked forms only keep
        // panic branches out of the flight build.
        let Some((counts, rest)) = hist.split_at_mut_checked(width) else {
            return none;
        };
        let Some((x0s, rest)) = rest.split_at_mut_checked(hull_width) else {
            return none;
        };
        let Some((x1s, yys)) = rest.split_at_mut_checked(if want_hull { width } else { 0 }) else {
            return none;
        };
        counts.fill(0);
        x0s.fill(0);
        let mut definite = Roi::EMPTY;
        for_each_gradient_row(frame, grad, |y, g| {
            if !want_hull {
                let inner = inner_px(g);
                // Without lanes, chunks longer than the row leave it all as remainder.
                let mut pairs = inner.chunks_exact(if lanes { 2 } else { inner.len() + 1 });
                if lanes {
                    for pair in &mut pairs {
                        let (d0, d1) = (pair[0].wrapping_sub(lo), pair[1].wrapping_sub(lo));
                        // In range when `d < width`: `get_mut` drops the bounds check's
                        // panic branch (x0s is as long as counts when lanes are on).
                        if let Some(c) = counts.get_mut(d0 as usize) {
                            *c += 1;
                        }
                        if let Some(c) = x0s.get_mut(d1 as usize) {
                            *c += 1;
                        }
                    }
                }
                for &v in pairs.remainder() {
                    if let Some(c) = counts.get_mut(v.wrapping_sub(lo) as usize) {
                        *c += 1;
                    }
                }
                return;
            }
            let inner = inner_px(g);
            for (i, &v) in inner.iter().enumerate() {
                let d = v.wrapping_sub(lo) as usize;
                // All four have `width` entries or more (with hulls): `get_mut` instead
                // of indexing keeps panic branches out of the flight build.
                if let (Some(c), Some(x0), Some(x1), Some(yy)) = (
                    counts.get_mut(d),
                    x0s.get_mut(d),
                    x1s.get_mut(d),
                    yys.get_mut(d),
                ) {
                    let (xs, ys) = (i as u32 + 1, y as u32);
                    if *c == 0 {
                        (*x0, *x1, *yy) = (xs, xs, ys << 16 | ys);
                    } else {
                        *x0 = (*x0).min(xs);
                        *x1 = (*x1).max(xs);
                        *yy = (*yy & 0xFFFF_0000) | ys;
                    }
                    *c += 1;
                }
            }
            if let (Some(first), Some(last)) = (first_above(inner, hi), last_above(inner, hi)) {
                let row = Roi::new(first as u16 + 1, y as u16, last as u16 + 2, y as u16 + 1);
                definite = definite.hull(&row);
            }
        });
        if lanes {
            for (c, &o) in counts.iter_mut().zip(x0s.iter()) {
                *c += o;
            }
        }
        let Some(offset) = counts.iter().position(|&c| {
            below += c;
            below > k
        }) else {
            return none;
        };
        let threshold = (lo + offset as u32).max(self.min_gradient);
        let hull = (want_hull && threshold <= hi).then(|| {
            let from = (threshold - lo) as usize;
            let mut roi = definite;
            let mut n = above;
            let values = counts
                .iter()
                .zip(x0s.iter())
                .zip(x1s.iter())
                .zip(yys.iter());
            for (((&count, &x0), &x1), &yy) in values.take(width).skip(from) {
                if count > 0 {
                    let (y0, y1) = ((yy >> 16) as u16, (yy & 0xFFFF) as u16);
                    let r = Roi::new(x0 as u16, y0, x1 as u16 + 1, y1 + 1);
                    roi = roi.hull(&r);
                    n += count;
                }
            }
            ((!roi.is_empty()).then_some(roi), n)
        });
        Passes { threshold, hull }
    }

    /// Streams the mask `g ≥ threshold` (interior only) to `sink`, every row once.
    fn mask_pass<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        frame: &Frame<'_>,
        work: &mut WgeWork<C>,
        threshold: u32,
        mut sink: F,
    ) {
        let (w, h) = (frame.width(), frame.height());
        let WgeWork { gradient, mask, .. } = work;
        let mask = &mut mask.as_mut()[..w];
        mask.fill(false);
        if w < 3 || h < 3 || threshold == u32::MAX {
            for y in 0..h {
                sink(y, mask);
            }
            return;
        }
        sink(0, mask);
        for_each_gradient_row(frame, &mut gradient.as_mut()[..w], |y, g| {
            for (m, &v) in inner_px_mut(mask).iter_mut().zip(inner_px(g)) {
                *m = v >= threshold;
            }
            sink(y, mask);
        });
        mask.fill(false);
        sink(h - 1, mask);
    }
}

/// The parameters as `name=value` pairs separated by spaces (as in tuning reports
/// and tuned sets).
impl core::fmt::Display for Wge {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "drop_fraction={} min_gradient={} box={}",
            self.drop_fraction, self.min_gradient, self.box_rule
        )
    }
}

impl Detector for Wge {
    type Work<C: FrameCapacity> = WgeWork<C>;
    const NAME: &'static str = "wge";

    fn validate(&self) -> Result<(), DetectError> {
        if !(0.0..=1.0).contains(&self.drop_fraction) {
            return Err(DetectError::InvalidParameter {
                name: "drop_fraction",
                expected: "a fraction in 0..=1",
            });
        }
        Ok(())
    }

    fn box_rule(&self) -> BoxRule {
        self.box_rule
    }

    fn set_box_rule(&mut self, rule: BoxRule) {
        self.box_rule = rule;
    }

    /// Foreground: interior pixels with Prewitt L1 gradient `≥ threshold`. Threshold:
    /// the exact order statistic (see the module documentation), at least
    /// `min_gradient`; `u32::MAX` when everything is eliminated.
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut WgeWork<C>,
        sink: F,
    ) -> u32 {
        let threshold = self.passes(frame, work, false).threshold;
        Self::mask_pass(frame, work, threshold, sink);
        threshold
    }

    /// As the provided method, but the all-foreground box usually comes out of the
    /// histogram passes (two gradient passes instead of three); the result is the same.
    fn detect<C: FrameCapacity>(
        &self,
        frame: &Frame<'_>,
        scratch: &mut Scratch<WgeWork<C>, C>,
    ) -> Result<Detection, DetectError> {
        self.validate()?;
        DetectError::check_capacity::<C>(frame)?;
        let Scratch { work, roi } = scratch;
        let all = self.box_rule == BoxRule::AllForeground;
        let passes = self.passes(frame, work, all);
        if let Some((found, foreground_px)) = passes.hull {
            return Ok(Detection {
                score_permille: Detection::certain_if_found(&found),
                roi: found,
                threshold: passes.threshold,
                foreground_px,
            });
        }
        roi.start(self.box_rule, frame.width());
        Self::mask_pass(frame, work, passes.threshold, |y, m| roi.push_row(y, m));
        let (found, foreground_px) = roi.finish();
        Ok(Detection {
            score_permille: Detection::certain_if_found(&found),
            roi: found,
            threshold: passes.threshold,
            foreground_px,
        })
    }
}

/// Width of the blocks [`first_above`] and [`last_above`] test at once.
const SCAN: usize = 16;

/// Index of the first value above `t`, skipping whole blocks whose maximum is not.
fn first_above(g: &[u32], t: u32) -> Option<usize> {
    let mut blocks = g.chunks_exact(SCAN);
    for (b, block) in (&mut blocks).enumerate() {
        if block.iter().copied().max().unwrap_or(0) > t {
            return block.iter().position(|&v| v > t).map(|i| b * SCAN + i);
        }
    }
    let tail = g.len() - blocks.remainder().len();
    blocks
        .remainder()
        .iter()
        .position(|&v| v > t)
        .map(|i| tail + i)
}

/// Index of the last value above `t`, skipping whole blocks whose maximum is not.
fn last_above(g: &[u32], t: u32) -> Option<usize> {
    let mut blocks = g.rchunks_exact(SCAN);
    for (b, block) in (&mut blocks).enumerate() {
        if block.iter().copied().max().unwrap_or(0) > t {
            let start = g.len() - (b + 1) * SCAN;
            return block.iter().rposition(|&v| v > t).map(|i| start + i);
        }
    }
    blocks.remainder().iter().rposition(|&v| v > t)
}
