//! Difference-of-Gaussians (DoG) blob detection (Lindeberg / Lowe, paper ref. \[49\]).
//!
//! 1. The frame is averaged over [`DOWNSAMPLE`]×[`DOWNSAMPLE`] blocks (82×62 pixels for
//!    a reference frame): the target at 15–440 m spans 9–150 full pixels, so the
//!    scales that matter survive, and the whole scale space fits in bounded memory.
//! 2. Gaussian levels `G_i`, `σ_i = sigma0_px · sigma_ratio^i` (full-resolution
//!    pixels), are computed one at a time with separable fixed-point kernels (Q15
//!    weights summing exactly to 1, replicated borders). Only four levels are kept in
//!    a ring: the three DoG layers an extremum test needs come from them. Levels of
//!    σ ≥ [`DECIMATE_SIGMA`] plane pixels (the widest two or three) continue from the
//!    2×2 means of the first level with σ ≥ [`HALVE_SIGMA`], are blurred on that
//!    41×31 half plane and return bilinearly, with the variance of each step
//!    accounted for: a third of the blur cost, within 0.2 % of the direct blur's DN
//!    range away from the border (up to 3 % within σ of it; tested).
//! 3. The scale-normalised response `R_i = (G_i − G_{i+1}) / (k − 1)` with
//!    `k = sigma_ratio` (the difference of Gaussians is already `≈ (k − 1)·σ²∇²G`, so this
//!    reads as σ²∇²G in DN; bright blobs are positive) is searched for local maxima
//!    over space and scale (3×3×3, `≥` every neighbour present) with
//!    `R_i ≥ min_response_dn`. The strongest [`MAX_BLOBS`] are kept.
//! 4. Each blob is the square of half-side `⌈√2·σ_i⌉` around its centre; the union of
//!    the blob squares is the foreground mask handed to the [`BoxRule`] (all blobs'
//!    hull, or the largest group of overlapping blobs).
//!
//! Memory is six 82×62 `u16` planes (base, blur temporary, four levels) plus the blob
//! list and the mask-to-box state: see [`SCRATCH_BYTES`].

use super::plane::{BLOCK, Window, block_means};
pub use super::plane::{PLANE_HEIGHT, PLANE_WIDTH};
use super::{BoxRule, DetectError, Detector, Scratch};
use crate::capacity::{ConstInit, FrameCapacity, Reference};
use crate::frame::Frame;

/// Block side of the downsampling, in pixels.
pub const DOWNSAMPLE: usize = BLOCK;
/// Levels with σ of at least this many plane pixels are blurred on the half plane
/// and brought back bilinearly: a fraction of the cost, for Gaussians far wider than
/// the half plane's pixels.
pub const DECIMATE_SIGMA: f32 = 6.0;
/// The half plane is made from the first level at least this smooth (σ in plane
/// pixels), so that halving it does not alias.
pub const HALVE_SIGMA: f32 = 2.5;
/// Most Gaussian levels (so at most `MAX_LEVELS − 1` DoG layers).
pub const MAX_LEVELS: u8 = 8;
/// Largest Gaussian kernel radius, in downsampled pixels (3σ, σ ≤ 21.3 plane px).
pub const MAX_RADIUS: usize = 64;
/// Most blobs kept per frame (the strongest).
pub const MAX_BLOBS: usize = 64;
/// Lanes of the blur's dot product (taps are padded to a multiple).
const LANES: usize = 8;
/// Kernel taps with padding.
pub(crate) const KERNEL_CAPACITY: usize = (2 * MAX_RADIUS + 1).next_multiple_of(LANES);
/// Fixed-point scale of the kernel weights (Q15).
const ONE_Q15: u32 = 1 << 15;
/// Fixed-point scale of the response normalisation 1/(k − 1) (Q4).
const NORM_Q: i32 = 16;

/// Parameters of the DoG blob detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dog {
    /// Smallest Gaussian σ, in full-resolution pixels, `≥ 1`. Default 4 (one plane
    /// pixel).
    pub sigma0_px: f32,
    /// Ratio between consecutive σ, `≥ 1.001` (default 1.6, as Lowe and scikit-image).
    pub sigma_ratio: f32,
    /// Gaussian levels, 3..=[`MAX_LEVELS`] (default 7: σ = 4 … 67 px, blobs of
    /// half-side 6 … 95 px).
    pub levels: u8,
    /// Smallest scale-normalised response of a blob, in DN (default 256).
    pub min_response_dn: u32,
    /// Mask-to-box rule (default [`BoxRule::AllForeground`]).
    pub box_rule: BoxRule,
}

impl Default for Dog {
    fn default() -> Self {
        Dog {
            sigma0_px: 4.0,
            sigma_ratio: 1.6,
            levels: 7,
            min_response_dn: 256,
            box_rule: BoxRule::AllForeground,
        }
    }
}

/// A detected blob: plane coordinates, level and response.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Blob {
    /// Column in the downsampled plane.
    pub x: u16,
    /// Row in the downsampled plane.
    pub y: u16,
    /// DoG layer `i` (σ_i of the detector).
    pub level: u8,
    /// Scale-normalised response in DN × 16.
    pub response: i32,
}

const NO_BLOB: Blob = Blob {
    x: 0,
    y: 0,
    level: 0,
    response: 0,
};

/// DoG's buffers at capacity `C` (`PW × PH` cells of 4×4 pixels). Plane values are
/// means of DN (`u16`), block sums at most `16 · 65 535`, responses
/// `(G_i − G_{i+1})·16/(k − 1) ≤ 65 535 · 16 000 < 2^31` and blur accumulators
/// `Σ w·v ≤ 2^15 · 2^15`: none depends on the capacity.
#[derive(Debug, Clone)]
pub struct DogWork<C: FrameCapacity = Reference> {
    base: C::Cells<u16>,
    /// 2×2 means of the first level with σ ≥ [`HALVE_SIGMA`], for the coarse levels.
    half: C::HalfCells<u16>,
    /// σ of the level in `half`, in plane pixels (0: none yet this frame).
    half_sigma: f32,
    tmp: C::Cells<u16>,
    ring: [C::Cells<u16>; 4],
    row_sum: C::CellRow<u32>,
    /// A row (or, transposed, a column) of cells plus the kernel's padding.
    pad: C::PaddedCellRow<i16>,
    kernel: [i16; 2 * MAX_RADIUS + 1],
    blobs: [Blob; MAX_BLOBS],
    blob_count: usize,
    mask: C::Row<bool>,
}

impl<C: FrameCapacity> ConstInit for DogWork<C> {
    const INIT: Self = DogWork {
        base: ConstInit::INIT,
        half: ConstInit::INIT,
        half_sigma: 0.0,
        tmp: ConstInit::INIT,
        ring: [ConstInit::INIT; 4],
        row_sum: ConstInit::INIT,
        pad: ConstInit::INIT,
        kernel: [0; 2 * MAX_RADIUS + 1],
        blobs: [NO_BLOB; MAX_BLOBS],
        blob_count: 0,
        mask: ConstInit::INIT,
    };
}

/// The DoG detector's scratch memory at capacity `C` (default 328×248).
pub type DogScratch<C = Reference> = Scratch<DogWork<C>, C>;

/// Bytes of [`DogScratch`] at 328×248 (budget: 96 KiB).
pub const SCRATCH_BYTES: usize = core::mem::size_of::<DogScratch>();

impl<C: FrameCapacity> DogScratch<C> {
    /// The blobs of the last [`Detector::detect`] call, strongest not first.
    pub fn blobs(&self) -> &[Blob] {
        &self.work.blobs[..self.work.blob_count]
    }
}

impl Dog {
    /// σ of Gaussian level `i`, in full-resolution pixels.
    pub fn sigma_px(&self, i: u8) -> f32 {
        let mut s = self.sigma0_px;
        for _ in 0..i {
            s *= self.sigma_ratio;
        }
        s
    }

    /// Half-side of the square of a blob found in DoG layer `i`, in pixels: `⌈√2·σ_i⌉`.
    pub fn blob_radius_px(&self, i: u8) -> u16 {
        libm::ceilf(core::f32::consts::SQRT_2 * self.sigma_px(i)) as u16
    }

    fn radius_plane(&self, i: u8) -> usize {
        libm::ceilf(3.0 * self.sigma_px(i) / DOWNSAMPLE as f32) as usize
    }
}

/// Fills `kernel[..2r+1]` with Q15 Gaussian weights of σ `sigma` (plane pixels) that
/// sum exactly to 2^15 (each below 2^15 for σ ≥ 0.25); returns r.
fn gaussian_kernel(sigma: f32, r: usize, kernel: &mut [i16]) -> usize {
    let r = r.min(MAX_RADIUS);
    let taps = &mut kernel[..2 * r + 1];
    let mut total = 0.0f32;
    let mut raw = [0.0f32; 2 * MAX_RADIUS + 1];
    for (k, g) in raw[..2 * r + 1].iter_mut().enumerate() {
        let d = k as f32 - r as f32;
        *g = libm::expf(-0.5 * d * d / (sigma * sigma));
        total += *g;
    }
    let mut sum = 0i32;
    for (t, &g) in taps.iter_mut().zip(&raw[..2 * r + 1]) {
        *t = libm::roundf(g / total * ONE_Q15 as f32) as i16;
        sum += i32::from(*t);
    }
    // The centre tap takes the rounding remainder (it is the largest weight).
    taps[r] = (i32::from(taps[r]) + ONE_Q15 as i32 - sum).clamp(0, i32::from(i16::MAX)) as i16;
    r
}

/// Blurs every row of the `w`-wide plane `src` with `kernel` (replicated borders,
/// rounded to the nearest integer) and writes the result transposed into `dst`
/// (`dst[x·h + y]`). Two calls make a separable 2-D blur, and both run their dot
/// products along contiguous memory.
///
/// The dot products are i16 × i16 → i32 (x86 `pmaddwd`, Arm `SMLAD`): samples are
/// stored offset by −2^15 in `pad` (one row with its borders), and because the Q15
/// weights sum to exactly 2^15 the offset comes back as the constant 2^30.
fn blur_rows_transposed(src: &[u16], dst: &mut [u16], w: usize, kernel: &[i16], pad: &mut [i16]) {
    // Panic-free for the flight build (checked by scripts/panic-never.sh): the callers
    // pass w ≥ 1, a kernel of 2r + 1 ≤ KERNEL_CAPACITY taps and a pad of w + taps − 1,
    // so every `max(1)`, `get` and checked split below is a no-op that only keeps a
    // panic branch out of the code.
    let w = w.max(1);
    let r = kernel.len() / 2;
    let h = src.len() / w;
    // Taps padded with zero weights to a multiple of 8, so the dot product is whole
    // 8-lane blocks.
    let taps = kernel.len().next_multiple_of(LANES).max(LANES);
    let mut weights = [0i16; KERNEL_CAPACITY];
    for (weight, &k) in weights.iter_mut().zip(kernel) {
        *weight = k;
    }
    let weights = weights.get(..taps).unwrap_or_default();
    let Some(pad) = pad.get_mut(..w + taps - 1) else {
        return;
    };
    let centred = |v: u16| (v ^ 0x8000) as i16;
    for (y, row) in src.chunks_exact(w).enumerate() {
        let Some((left, rest)) = pad.split_at_mut_checked(r) else {
            return;
        };
        let Some((middle, right)) = rest.split_at_mut_checked(w) else {
            return;
        };
        left.fill(centred(row.first().copied().unwrap_or(0)));
        for (m, &v) in middle.iter_mut().zip(row) {
            *m = centred(v);
        }
        right.fill(centred(row.last().copied().unwrap_or(0)));
        // Output column y of the transposed destination: element x at x·h + y.
        let column = dst
            .get_mut(y..)
            .unwrap_or_default()
            .iter_mut()
            .step_by(h.max(1));
        for (out, window) in column.zip(pad.windows(taps)).take(w) {
            let mut acc = 0i32;
            for (kc, vc) in weights.chunks_exact(LANES).zip(window.chunks_exact(LANES)) {
                for (&k, &v) in kc.iter().zip(vc) {
                    acc += i32::from(k) * i32::from(v);
                }
            }
            let acc = (acc + (1 << 30)) as u32;
            *out = ((acc + ONE_Q15 / 2) >> 15) as u16;
        }
    }
}

/// The parameters as `name=value` pairs separated by spaces (as in tuning reports
/// and tuned sets).
impl core::fmt::Display for Dog {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "sigma0_px={} sigma_ratio={} levels={} min_response_dn={} box={}",
            self.sigma0_px, self.sigma_ratio, self.levels, self.min_response_dn, self.box_rule
        )
    }
}

impl Detector for Dog {
    type Work<C: FrameCapacity> = DogWork<C>;
    const NAME: &'static str = "dog";

    fn validate(&self) -> Result<(), DetectError> {
        if !(self.sigma0_px.is_finite() && self.sigma0_px >= 1.0) {
            return Err(DetectError::InvalidParameter {
                name: "sigma0_px",
                expected: "a finite sigma of at least 1 pixel",
            });
        }
        // At least 1.001 keeps the response, (G_i − G_{i+1})·16/(k − 1) ≤ 65 535 · 16 000,
        // inside an i32.
        if !(self.sigma_ratio.is_finite() && self.sigma_ratio >= 1.001) {
            return Err(DetectError::InvalidParameter {
                name: "sigma_ratio",
                expected: "a finite ratio of at least 1.001",
            });
        }
        if self.levels < 3 || self.levels > MAX_LEVELS {
            return Err(DetectError::InvalidParameter {
                name: "levels",
                expected: "3..=8 Gaussian levels",
            });
        }
        if self.radius_plane(self.levels - 1) > MAX_RADIUS {
            return Err(DetectError::InvalidParameter {
                name: "sigma0_px",
                expected: "a largest sigma (sigma0_px * sigma_ratio^(levels-1)) of at most 85 px",
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

    /// Foreground: the union of the blob squares. Threshold: `min_response_dn`.
    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut DogWork<C>,
        mut sink: F,
    ) -> u32 {
        let (w, h) = (frame.width(), frame.height());
        let (pw, ph) = (w.div_ceil(DOWNSAMPLE), h.div_ceil(DOWNSAMPLE));
        block_means(
            frame,
            Window::full(frame),
            work.row_sum.as_mut(),
            work.base.as_mut(),
        );
        find_blobs(self, work, pw, ph);

        let mut squares = [(0u16, 0u16, 0u16, 0u16); MAX_BLOBS];
        let blobs = work.blobs.get(..work.blob_count).unwrap_or_default();
        for (sq, b) in squares.iter_mut().zip(blobs) {
            let r = usize::from(self.blob_radius_px(b.level));
            let cx = (usize::from(b.x) * DOWNSAMPLE + DOWNSAMPLE / 2).min(w - 1);
            let cy = (usize::from(b.y) * DOWNSAMPLE + DOWNSAMPLE / 2).min(h - 1);
            *sq = (
                cx.saturating_sub(r) as u16,
                cy.saturating_sub(r) as u16,
                (cx + r + 1).min(w) as u16,
                (cy + r + 1).min(h) as u16,
            );
        }
        let squares = squares.get(..work.blob_count).unwrap_or_default();
        let mask = &mut work.mask.as_mut()[..w];
        for y in 0..h {
            mask.fill(false);
            for &(x0, y0, x1, y1) in squares {
                if (usize::from(y0)..usize::from(y1)).contains(&y) {
                    // x0 ≤ x1 ≤ w by construction.
                    if let Some(run) = mask.get_mut(usize::from(x0)..usize::from(x1)) {
                        run.fill(true);
                    }
                }
            }
            sink(y, mask);
        }
        self.min_response_dn
    }
}

/// Gaussian level `i` into ring slot `i % 4`.
fn gaussian_level<C: FrameCapacity>(dog: &Dog, work: &mut DogWork<C>, i: u8, pw: usize, ph: usize) {
    let sigma = dog.sigma_px(i) / DOWNSAMPLE as f32;
    let n = pw * ph;
    let slot = usize::from(i) % 4;
    if sigma >= DECIMATE_SIGMA && work.half_sigma > 0.0 {
        // Coarse levels continue from the half plane (2×2 means of a level that is
        // already smooth, so nothing aliases). The 2×2 means (1/4 plane px²) and the
        // bilinear return (3/4 plane px² at the samples) blur by 1 plane px² more;
        // the kernel adds the rest, in half-plane pixels.
        let (hw, hh) = (pw.div_ceil(2), ph.div_ceil(2));
        let m = hw * hh;
        let rest = sigma * sigma - work.half_sigma * work.half_sigma - 1.0;
        let sigma_half = libm::sqrtf(rest.max(0.0)) / 2.0;
        let radius = libm::ceilf(3.0 * sigma_half) as usize;
        let r = gaussian_kernel(sigma_half.max(0.25), radius, &mut work.kernel);
        // Every slice below is in range (planes of the capacity, r ≤ MAX_RADIUS):
        // `get` and the checked split keep panic branches out of the flight build.
        let kernel = work.kernel.get(..2 * r + 1).unwrap_or_default();
        let Some((across, down)) = work.tmp.as_mut().split_at_mut_checked(m) else {
            return;
        };
        let pad = work.pad.as_mut();
        let half = work.half.as_ref().get(..m).unwrap_or_default();
        blur_rows_transposed(half, across, hw, kernel, pad);
        let down = down.get_mut(..m).unwrap_or_default();
        blur_rows_transposed(across, down, hh, kernel, pad);
        let dst = work.ring[slot].as_mut().get_mut(..n).unwrap_or_default();
        upsample(down, hw, dst, pw);
        return;
    }
    let r = gaussian_kernel(sigma, dog.radius_plane(i), &mut work.kernel);
    let kernel = work.kernel.get(..2 * r + 1).unwrap_or_default();
    let pad = work.pad.as_mut();
    blur_rows_transposed(
        work.base.as_ref().get(..n).unwrap_or_default(),
        work.tmp.as_mut().get_mut(..n).unwrap_or_default(),
        pw,
        kernel,
        pad,
    );
    let dst = work.ring[slot].as_mut().get_mut(..n).unwrap_or_default();
    blur_rows_transposed(
        work.tmp.as_ref().get(..n).unwrap_or_default(),
        dst,
        ph,
        kernel,
        pad,
    );
    if sigma >= HALVE_SIGMA && work.half_sigma == 0.0 {
        let level = work.ring[slot].as_ref().get(..n).unwrap_or_default();
        halve(level, pw, work.half.as_mut());
        work.half_sigma = sigma;
    }
}

/// 2×2 block means of the `pw`-wide plane `base` (blocks clipped at odd edges).
fn halve(base: &[u16], pw: usize, half: &mut [u16]) {
    // pw ≥ 1 and every index in range by the caller; `max(1)` and `get` keep panic
    // branches out of the flight build.
    let pw = pw.max(1);
    let ph = base.len() / pw;
    let hw = pw.div_ceil(2);
    for (hy, out) in half.chunks_exact_mut(hw).take(ph.div_ceil(2)).enumerate() {
        let rows = [2 * hy, (2 * hy + 1).min(ph - 1)];
        for (hx, o) in out.iter_mut().enumerate() {
            let cols = [2 * hx, (2 * hx + 1).min(pw - 1)];
            let sum: u32 = rows
                .iter()
                .flat_map(|&y| {
                    cols.iter()
                        .map(move |&x| u32::from(base.get(y * pw + x).copied().unwrap_or(0)))
                })
                .sum();
            *o = ((sum + 2) / 4) as u16;
        }
    }
}

/// Bilinear upsampling of the `hw`-wide half plane `src` onto the `pw`-wide plane
/// `dst`: half-plane pixel j covers plane pixels 2j and 2j + 1, so each plane pixel
/// weighs its two nearest half-plane pixels 3/4 and 1/4 per axis (replicated edges).
fn upsample(src: &[u16], hw: usize, dst: &mut [u16], pw: usize) {
    // hw, pw ≥ 1 and every index in range by the caller; `max(1)` and `get` keep
    // panic branches out of the flight build.
    let (hw, pw) = (hw.max(1), pw.max(1));
    let hh = src.len() / hw;
    let near = |x: usize, len: usize| {
        let j = x / 2;
        let other = if x % 2 == 0 {
            j.saturating_sub(1)
        } else {
            (j + 1).min(len - 1)
        };
        (j, other)
    };
    for (y, out) in dst.chunks_exact_mut(pw).enumerate() {
        let (ya, yb) = near(y, hh);
        let half_row = |y: usize| src.get(y * hw..(y + 1) * hw).unwrap_or_default();
        let (ra, rb) = (half_row(ya), half_row(yb));
        let at = |row: &[u16], x: usize| u32::from(row.get(x).copied().unwrap_or(0));
        for (x, o) in out.iter_mut().enumerate() {
            let (xa, xb) = near(x, hw);
            let v = 9 * at(ra, xa) + 3 * at(ra, xb) + 3 * at(rb, xa) + at(rb, xb);
            *o = ((v + 8) / 16) as u16;
        }
    }
}

/// Scale-space maxima of the normalised DoG into `work.blobs`.
fn find_blobs<C: FrameCapacity>(dog: &Dog, work: &mut DogWork<C>, pw: usize, ph: usize) {
    work.blob_count = 0;
    let levels = dog.levels;
    let layers_total = levels - 1;
    // G(kσ) − G(σ) ≈ (k − 1)·σ²∇²G: the difference is already scale-normalised; only
    // the constant 1/(k − 1) remains, so that responses read as σ²∇²G in DN.
    let norm = libm::roundf(NORM_Q as f32 / (dog.sigma_ratio - 1.0)).max(1.0) as i32;
    let min_response = i32::try_from(dog.min_response_dn)
        .unwrap_or(i32::MAX)
        .saturating_mul(NORM_Q);
    work.half_sigma = 0.0;
    gaussian_level(dog, work, 0, pw, ph);
    gaussian_level(dog, work, 1, pw, ph);
    for i in 0..layers_total {
        if i + 2 < levels {
            gaussian_level(dog, work, i + 2, pw, ph);
        }
        let n = pw * ph;
        let DogWork {
            ring,
            blobs,
            blob_count,
            ..
        } = &mut *work;
        // Layer l is (G_l − G_{l+1})·norm; its two planes come from the ring.
        // In range (planes of n ≤ the capacity's pixels, idx < n): `get` keeps
        // panic branches out of the flight build.
        let planes = |l: u8| {
            (
                ring[usize::from(l) % 4]
                    .as_ref()
                    .get(..n)
                    .unwrap_or_default(),
                ring[usize::from(l + 1) % 4]
                    .as_ref()
                    .get(..n)
                    .unwrap_or_default(),
                norm,
            )
        };
        let response = |(a, b, k): (&[u16], &[u16], i32), idx: usize| {
            let at = |p: &[u16]| i32::from(p.get(idx).copied().unwrap_or(0));
            (at(a) - at(b)) * k
        };
        let current = planes(i);
        // Same layer first (most candidates fail there), then the layers below/above.
        let mut neighbours = [current; 3];
        let mut layers = 1;
        if i > 0 {
            if let Some(slot) = neighbours.get_mut(layers) {
                *slot = planes(i - 1);
                layers += 1;
            }
        }
        if i + 1 < layers_total {
            if let Some(slot) = neighbours.get_mut(layers) {
                *slot = planes(i + 1);
                layers += 1;
            }
        }
        let (upper, lower, _) = current;
        for y in 0..ph {
            let (y0, y1) = (y.saturating_sub(1), (y + 1).min(ph - 1));
            let (Some(upper_row), Some(lower_row)) = (
                upper.get(y * pw..(y + 1) * pw),
                lower.get(y * pw..(y + 1) * pw),
            ) else {
                break;
            };
            for x in 0..pw {
                let r = (i32::from(upper_row[x]) - i32::from(lower_row[x])) * norm;
                if r < min_response || r <= 0 {
                    continue;
                }
                let (x0, x1) = (x.saturating_sub(1), (x + 1).min(pw - 1));
                let beaten = neighbours.iter().take(layers).any(|&layer| {
                    (y0..=y1).any(|ny| (x0..=x1).any(|nx| response(layer, ny * pw + nx) > r))
                });
                if !beaten {
                    keep_blob(
                        blobs,
                        blob_count,
                        Blob {
                            x: x as u16,
                            y: y as u16,
                            level: i,
                            response: r,
                        },
                    );
                }
            }
        }
    }
}

/// Adds `blob`, or replaces the weakest kept blob when the list is full.
fn keep_blob(blobs: &mut [Blob; MAX_BLOBS], count: &mut usize, blob: Blob) {
    if let Some(slot) = blobs.get_mut(*count) {
        *slot = blob;
        *count += 1;
        return;
    }
    if let Some(weakest) = blobs.iter_mut().min_by_key(|b| b.response) {
        if weakest.response < blob.response {
            *weakest = blob;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plane with edges, texture and noise (deterministic), 82×62.
    fn test_plane() -> [u16; PLANE_WIDTH * PLANE_HEIGHT] {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        core::array::from_fn(|i| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let (x, y) = (i % PLANE_WIDTH, i / PLANE_WIDTH);
            let target = if (30..55).contains(&x) && (20..40).contains(&y) {
                9000
            } else {
                0
            };
            let texture = ((x * 37 + y * 91) % 23) as u16 * 150;
            (3000 + target + texture + (state % 200) as u16).min(16383)
        })
    }

    /// The half-plane path against the direct separable blur of the same σ. Away from
    /// the border (one σ and more) the two agree within 0.2 % of the plane's DN range;
    /// nearer the border they differ because the replicated border enters twice (at the
    /// level that is halved and again on the half plane), by under 3 % in a corner.
    #[test]
    fn ratios_too_close_to_one_are_refused() {
        let near_one = Dog {
            sigma_ratio: 1.0005,
            ..Dog::default()
        };
        assert!(near_one.validate().is_err());
        let smallest = Dog {
            sigma_ratio: 1.001,
            sigma0_px: 1.0,
            ..Dog::default()
        };
        assert_eq!(smallest.validate(), Ok(()));
        // The largest response still fits: a full-scale step between two levels.
        let norm = libm::roundf(NORM_Q as f32 / (smallest.sigma_ratio - 1.0)) as i64;
        assert!(65_535 * norm <= i64::from(i32::MAX));
    }

    #[test]
    fn decimated_levels_match_direct_blur() {
        let dog = Dog::default();
        let (pw, ph) = (PLANE_WIDTH, PLANE_HEIGHT);
        let mut work = DogScratch::<Reference>::new().work;
        work.base = test_plane();
        work.half_sigma = 0.0;
        let range = f32::from(work.base.iter().max().unwrap() - work.base.iter().min().unwrap());
        let mut checked = 0;
        for i in 0..dog.levels {
            let sigma = dog.sigma_px(i) / DOWNSAMPLE as f32;
            gaussian_level(&dog, &mut work, i, pw, ph);
            if sigma < DECIMATE_SIGMA {
                continue;
            }
            let decimated = work.ring[usize::from(i) % 4];
            let r = gaussian_kernel(sigma, dog.radius_plane(i), &mut work.kernel);
            let kernel = work.kernel;
            let kernel = &kernel[..2 * r + 1];
            blur_rows_transposed(&work.base, &mut work.tmp, pw, kernel, &mut work.pad);
            let mut direct = [0u16; PLANE_WIDTH * PLANE_HEIGHT];
            blur_rows_transposed(&work.tmp, &mut direct, ph, kernel, &mut work.pad);
            let margin = libm::ceilf(sigma) as usize;
            let (mut inner, mut edge) = (0u32, 0u32);
            for (k, (&a, &b)) in decimated.iter().zip(&direct).enumerate() {
                let (x, y) = (k % pw, k / pw);
                let e = (i32::from(a) - i32::from(b)).unsigned_abs();
                let interior =
                    (margin..pw - margin).contains(&x) && (margin..ph - margin).contains(&y);
                if interior {
                    inner = inner.max(e)
                } else {
                    edge = edge.max(e)
                }
            }
            assert!(
                inner as f32 <= 0.002 * range,
                "level {i}: {inner} DN inside, range {range}"
            );
            assert!(
                edge as f32 <= 0.03 * range,
                "level {i}: {edge} DN at the border, range {range}"
            );
            checked += 1;
        }
        assert!(
            checked >= 2,
            "the default levels must exercise the half plane"
        );
    }
}
