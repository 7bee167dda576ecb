//! Weak gradient elimination (WGE) of the Sharma–Ventura–D'Amico (SVD) architecture
//! (paper ref. [4]): keep the pixels of strongest gradient, box what remains.
//!
//! The gradient is the Prewitt operator, its magnitude the L1 norm
//! `g = |g_x| + |g_y|` (integers, ≤ 6·max_dn), on interior pixels only (the one-pixel
//! border has no full 3×3 neighbourhood and is never foreground). The weakest
//! `drop_fraction` of the interior gradients are eliminated: with `N` interior pixels
//! and `k = ⌊drop_fraction·N⌋`, the threshold is the `k`-th smallest gradient
//! (0-based), raised to at least `min_gradient`, and a pixel is foreground when
//! `g ≥ threshold`. The order statistic is exact: a coarse histogram of
//! [`COARSE_BINS`] bins finds the bin holding it, a second pass histograms that bin at
//! full resolution, and a third pass streams the mask. No gradient image is stored;
//! each pass recomputes the gradients of one row from three frame rows.

use super::{BoxRule, DetectError, Detector, RoiBuilder, Scratch};
use crate::frame::{FRAME_WIDTH, Frame};

/// Coarse bins of the gradient histogram; the refinement pass reuses them as
/// full-resolution counters (a bin spans at most 2^(16+3−10) = 512 gradient values).
pub const COARSE_BINS: usize = 1024;
const COARSE_BITS: u8 = 10;

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

/// WGE's buffers: the gradient histogram, one gradient row and one mask row.
#[derive(Debug, Clone)]
pub struct WgeWork {
    hist: [u32; COARSE_BINS],
    gradient: [u32; FRAME_WIDTH],
    mask: [bool; FRAME_WIDTH],
}

/// The WGE detector's scratch memory.
pub type WgeScratch = Scratch<WgeWork>;

/// Bytes of [`WgeScratch`] (budget: 16 KiB).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<WgeScratch>();

impl WgeScratch {
    /// Fresh scratch memory (a `const fn`, so it can be a `static`).
    pub const fn new() -> Self {
        Scratch {
            work: WgeWork {
                hist: [0; COARSE_BINS],
                gradient: [0; FRAME_WIDTH],
                mask: [false; FRAME_WIDTH],
            },
            roi: RoiBuilder::new(),
        }
    }
}

impl Default for WgeScratch {
    fn default() -> Self {
        Self::new()
    }
}

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

impl Wge {
    /// Number of interior gradients eliminated out of `n`: `⌊drop_fraction·n⌋`.
    pub fn drop_count(&self, n: u32) -> u32 {
        ((self.drop_fraction * n as f32) as u32).min(n)
    }

    /// The `k`-th smallest interior gradient (0-based), or `None` when `k ≥ N`.
    fn order_statistic(&self, frame: &Frame<'_>, work: &mut WgeWork, k: u32) -> Option<u32> {
        let w = frame.width();
        let shift = (frame.bits() + 3).saturating_sub(COARSE_BITS);
        let WgeWork { hist, gradient, .. } = work;
        let grad = &mut gradient[..w];
        hist.fill(0);
        for_each_gradient_row(frame, grad, |_, g| {
            for &v in &g[1..w - 1] {
                // `& (COARSE_BINS − 1)` never changes the index (g ≤ 6·max_dn <
                // 2^(bits+3)); it lets the compiler drop the bounds check.
                hist[(v >> shift) as usize & (COARSE_BINS - 1)] += 1;
            }
        });
        // The coarse bin holding the k-th value and how many lie below it.
        let mut below = 0u32;
        let mut bin = None;
        for (b, &c) in hist.iter().enumerate() {
            if below + c > k {
                bin = Some(b as u32);
                break;
            }
            below += c;
        }
        let bin = bin?;
        if shift == 0 {
            return Some(bin);
        }
        // Full resolution inside that bin, reusing the histogram.
        hist.fill(0);
        let lo = bin << shift;
        let width = 1u32 << shift;
        for_each_gradient_row(frame, grad, |_, g| {
            for &v in &g[1..w - 1] {
                let d = v.wrapping_sub(lo);
                if d < width {
                    hist[d as usize & (COARSE_BINS - 1)] += 1;
                }
            }
        });
        for (i, &c) in hist[..width as usize].iter().enumerate() {
            if below + c > k {
                return Some(lo + i as u32);
            }
            below += c;
        }
        None
    }
}

impl Detector for Wge {
    type Work = WgeWork;
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

    /// Foreground: interior pixels with Prewitt L1 gradient `≥ threshold`. Threshold:
    /// the exact order statistic (see the module documentation), at least
    /// `min_gradient`; `u32::MAX` when everything is eliminated.
    fn foreground<F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut WgeWork,
        mut sink: F,
    ) -> u32 {
        let (w, h) = (frame.width(), frame.height());
        let interior = (w.saturating_sub(2) * h.saturating_sub(2)) as u32;
        let k = self.drop_count(interior);
        let threshold = match interior {
            0 => None,
            _ => self.order_statistic(frame, work, k),
        }
        .map_or(u32::MAX, |t| t.max(self.min_gradient));
        let WgeWork { gradient, mask, .. } = work;
        let mask = &mut mask[..w];
        mask.fill(false);
        if interior == 0 || threshold == u32::MAX {
            for y in 0..h {
                sink(y, mask);
            }
            return threshold;
        }
        sink(0, mask);
        for_each_gradient_row(frame, &mut gradient[..w], |y, g| {
            for (m, &v) in mask[1..w - 1].iter_mut().zip(&g[1..w - 1]) {
                *m = v >= threshold;
            }
            sink(y, mask);
        });
        mask.fill(false);
        sink(h - 1, mask);
        threshold
    }
}
