//! Stage 1, noise and scene: the pixel noise σ from horizontal differences on a few
//! rows, and whether the window is (clean) deep space.

use super::super::plane::Window;
use super::rules::{
    CLEAN_ZERO_PER_MIXED, FIRST_DIFF_SIGMA, MIN_NOISE_SAMPLES, NOISE_ROWS, SECOND_DIFF_SIGMA,
    SPACE_ZERO_SHARE,
};
use crate::frame::Frame;

/// Bins of the noise histogram (16 exact bins, then 4 per octave up to 2^16).
pub(super) const NOISE_BINS: usize = 64;
/// The extra bin of the noise histograms that takes the samples not counted (so the
/// sampling loop has no branches).
const SKIP_BIN: usize = NOISE_BINS;

/// What stage 1 found.
#[derive(Debug, Clone, Copy)]
pub(super) struct Noise {
    /// Pixel noise σ in DN, at least 1.
    pub sigma: u32,
    /// Clean deep space: 0 DN nearly everywhere, clipped noise a sparse sprinkle (the
    /// refinement then also accepts faint faces, see [`super::refine`]).
    pub clean: bool,
}

/// Noise histogram bin of an absolute difference: exact below 16, then 4 per octave.
pub(super) fn noise_bin(d: u32) -> usize {
    if d < 16 {
        return d as usize;
    }
    let l = 31 - d.leading_zeros(); // 4..=16
    let sub = (d >> (l - 2)) & 3;
    (16 + (l - 4) * 4 + sub).min(NOISE_BINS as u32 - 1) as usize
}

/// The middle of the values of bin `b` (inverse of [`noise_bin`]).
pub(super) fn bin_value(b: usize) -> u32 {
    if b < 16 {
        return b as u32;
    }
    let l = (b as u32 - 16) / 4 + 4;
    let sub = (b as u32 - 16) % 4;
    let lo = (4 + sub) << (l - 2);
    lo + (1 << (l - 2)) / 2
}

/// Median of the values counted in `hist` (`None` below [`MIN_NOISE_SAMPLES`] counts): the middle of
/// its bin.
fn hist_median(hist: &[u32]) -> Option<u32> {
    let n: u32 = hist.iter().sum();
    if n < MIN_NOISE_SAMPLES {
        return None;
    }
    let mut seen = 0;
    hist.iter()
        .position(|&c| {
            seen += c;
            2 * seen > n
        })
        .map(bin_value)
}

/// Calls `f(a, b, c)` with the clamped pixels at `x, x + 1, x + 2` for every other `x`
/// of at most [`NOISE_ROWS`] evenly spaced rows of `win` (about 2 600 samples on a full frame:
/// plenty for a median). `buf` holds one clamped row.
fn for_each_noise_sample(
    frame: &Frame<'_>,
    win: Window,
    buf: &mut [u16],
    mut f: impl FnMut(u16, u16, u16),
) {
    let max_dn = frame.max_dn();
    let stride = (win.h / NOISE_ROWS).max(1);
    for y in (win.y0 + stride / 2..win.y0 + win.h).step_by(stride) {
        let row = win.row(frame, y);
        let Some(clamped) = buf.get_mut(..row.len()) else {
            continue;
        };
        for (c, &v) in clamped.iter_mut().zip(row) {
            *c = v.min(max_dn);
        }
        for abc in clamped.windows(3).step_by(2) {
            f(abc[0], abc[1], abc[2]);
        }
    }
}

/// σ in DN from the median of the first differences `|b − a|` (σ = median / 0.954;
/// pairs both at 0 DN or both saturated skipped) or, with `SECOND`, of the second
/// differences `|a − 2b + c|` (σ = median / 1.652; triples all at 0 DN or all
/// saturated skipped); `None` below 16 samples.
fn difference_sigma<const SECOND: bool>(
    frame: &Frame<'_>,
    win: Window,
    hist: &mut [u32; NOISE_BINS + 1],
    buf: &mut [u16],
) -> Option<u32> {
    let max_dn = frame.max_dn();
    hist.fill(0);
    for_each_noise_sample(frame, win, buf, |a, b, c| {
        let (skip, d) = if SECOND {
            let d2 = (i32::from(a) + i32::from(c) - 2 * i32::from(b)).unsigned_abs();
            (((a | b | c) == 0) | ((a & b & c) == max_dn), d2)
        } else {
            let d1 = u32::from(a.abs_diff(b));
            (((a | b) == 0) | ((a & b) == max_dn), d1)
        };
        hist[if skip { SKIP_BIN } else { noise_bin(d) }] += 1;
    });
    let m = hist_median(&hist[..NOISE_BINS])?;
    // σ = m · num / den, rounded.
    let (num, den) = if SECOND {
        SECOND_DIFF_SIGMA
    } else {
        FIRST_DIFF_SIGMA
    };
    Some((m * num + den / 2) / den)
}

/// Pixel noise σ in DN (≥ 1) of `win`, from horizontal differences (see
/// [`for_each_noise_sample`]; runs at 0 DN or saturated are skipped: clipped noise
/// says nothing), and whether deep space is clean (see below).
///
/// Two estimates: first differences, which also see the Earth's smooth texture, so
/// that texture stays below the edge thresholds; and second differences, blind to
/// smooth shading. The scene decides: when most sampled pairs are both at 0 DN (deep
/// space fills the frame), the only texture is the target's own shading, which must
/// not raise the thresholds, and the second-difference estimate is used; otherwise the
/// first. A first pass counts the pairs at 0 DN; only the histogram the scene needs
/// is built (the other one too when that one has too few samples).
pub(super) fn noise_sigma(
    frame: &Frame<'_>,
    win: Window,
    hist: &mut [u32; NOISE_BINS + 1],
    buf: &mut [u16],
) -> Noise {
    let (mut pairs, mut zero_pairs, mut one_zero) = (0u32, 0u32, 0u32);
    for_each_noise_sample(frame, win, buf, |a, b, _| {
        let both_zero = (a | b) == 0;
        pairs += 1;
        zero_pairs += u32::from(both_zero);
        one_zero += u32::from((a.min(b) == 0) & !both_zero);
    });
    let space = SPACE_ZERO_SHARE * zero_pairs > pairs;
    let sigma = if space {
        difference_sigma::<true>(frame, win, hist, buf)
            .or_else(|| difference_sigma::<false>(frame, win, hist, buf))
    } else {
        difference_sigma::<false>(frame, win, hist, buf)
            .or_else(|| difference_sigma::<true>(frame, win, hist, buf))
    };
    // Clean deep space: at 0 DN nearly everywhere (sunlit frames), with at most a
    // sparse sprinkle of clipped-noise pixels (noise clipped at 0 around a level at 0
    // makes two pairs touching 0 with one side above it for every pair both at 0).
    let clean = space && zero_pairs >= CLEAN_ZERO_PER_MIXED * one_zero;
    Noise {
        sigma: sigma.unwrap_or(1).max(1),
        clean,
    }
}

/// Pixel noise σ in DN (≥ 1) of `win` from second differences only (blind to smooth
/// shading and to the Earth's texture gradients; runs at 0 DN or saturated skipped),
/// falling back to first differences when too few samples remain.
pub(super) fn noise_sigma_second(
    frame: &Frame<'_>,
    win: Window,
    hist: &mut [u32; NOISE_BINS + 1],
    buf: &mut [u16],
) -> u32 {
    difference_sigma::<true>(frame, win, hist, buf)
        .or_else(|| difference_sigma::<false>(frame, win, hist, buf))
        .unwrap_or(1)
        .max(1)
}
