//! Shared helpers of the core's integration tests (std, no host): a seeded generator
//! over the core's own noise generator, the committed fixture frames, ASCII-art frames and
//! masks, frame and mask generators, a spy that records a detector's mask, and
//! brute-force references of every detector's documented semantics.
//!
//! The references are written from the module documentation only (never by calling a
//! detector's internals): they are deliberately slow and obvious.

// Each test crate uses a different subset of these helpers.
#![allow(dead_code)]

use std::cell::RefCell;
use std::collections::HashSet;

use tirroi_core::roi::Scratch;
use tirroi_core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi_core::roi::dog::{Dog, DogScratch};
use tirroi_core::roi::otsu::{Otsu, OtsuScratch};
use tirroi_core::roi::wge::{Wge, WgeScratch};
use tirroi_core::sensor::rng::Xoshiro128pp;
use tirroi_core::{BoxRule, DetectError, Detection, Detector, Frame, Roi};
use tirroi_core::{FrameCapacity, Reference};

// ---------------------------------------------------------------------------------
// Seeded generator
// ---------------------------------------------------------------------------------

/// Test data from the core's own noise generator ([`Xoshiro128pp`], the one the
/// camera model draws its noise from, seeded by SplitMix64): one generator for the
/// whole core, the same stream on every target for a seed. 64-bit draws are two 32-bit
/// outputs, high word first.
#[derive(Debug, Clone)]
pub struct Rng(Xoshiro128pp);

impl Rng {
    /// A generator for `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(Xoshiro128pp::seed_from_u64(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let hi = u64::from(self.0.next_u32());
        (hi << 32) | u64::from(self.0.next_u32())
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: u64) -> u64 {
        assert!(n > 0);
        ((u128::from(self.next_u64()) * u128::from(n)) >> 64) as u64
    }

    /// Uniform in `lo..=hi`.
    pub fn range(&mut self, lo: i64, hi: i64) -> i64 {
        assert!(lo <= hi);
        lo + self.below((hi - lo) as u64 + 1) as i64
    }

    /// Uniform in `lo..=hi` (usize).
    pub fn urange(&mut self, lo: usize, hi: usize) -> usize {
        self.range(lo as i64, hi as i64) as usize
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// Roughly normal (sum of four uniforms), mean 0, standard deviation `sigma`.
    pub fn normalish(&mut self, sigma: f64) -> f64 {
        let s: f64 = (0..4).map(|_| self.unit()).sum::<f64>() - 2.0;
        s * sigma * 3f64.sqrt()
    }
}

// ---------------------------------------------------------------------------------
// Owned frames
// ---------------------------------------------------------------------------------

/// An owned frame: DN, dimensions and bit depth.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Img {
    /// DN, row-major.
    pub px: Vec<u16>,
    /// Width.
    pub w: usize,
    /// Height.
    pub h: usize,
    /// Bit depth.
    pub bits: u8,
}

impl Img {
    /// A `w` × `h` frame of constant `v`.
    pub fn constant(w: usize, h: usize, bits: u8, v: u16) -> Self {
        Img {
            px: vec![v; w * h],
            w,
            h,
            bits,
        }
    }

    /// The core's view (panics on sizes the core rejects: tests only build valid ones).
    pub fn frame(&self) -> Frame<'_> {
        Frame::new(&self.px, self.w, self.h, self.bits).expect("test frames are valid")
    }

    /// Largest valid DN.
    pub fn max_dn(&self) -> u16 {
        max_dn(self.bits)
    }

    /// Mutable pixel (x, y).
    pub fn at(&mut self, x: usize, y: usize) -> &mut u16 {
        &mut self.px[y * self.w + x]
    }

    /// Fills `roi` with `v`.
    pub fn fill(&mut self, roi: Roi, v: u16) {
        for y in usize::from(roi.y0)..usize::from(roi.y1) {
            for x in usize::from(roi.x0)..usize::from(roi.x1) {
                *self.at(x, y) = v;
            }
        }
    }
}

/// `2^bits − 1`.
pub fn max_dn(bits: u8) -> u16 {
    ((1u32 << bits) - 1) as u16
}

/// A frame from ASCII art, in the style of embedded-graphics' `assert_pattern`:
/// `'#'` is `hi` DN, `'.'` is `lo` DN; every row must be as long as the first. 14-bit.
pub fn frame_from_pattern(pattern: &[&str], lo: u16, hi: u16) -> Img {
    let h = pattern.len();
    assert!(h > 0, "empty pattern");
    let w = pattern[0].chars().count();
    let mut px = Vec::with_capacity(w * h);
    for (y, row) in pattern.iter().enumerate() {
        assert_eq!(
            row.chars().count(),
            w,
            "pattern row {y} has a different width"
        );
        for c in row.chars() {
            px.push(match c {
                '#' => hi,
                '.' => lo,
                other => panic!("pattern character {other:?} is neither '#' nor '.'"),
            });
        }
    }
    Img { px, w, h, bits: 14 }
}

/// A mask from ASCII art (`'#'` = foreground, `'.'` = background): (mask, w, h).
pub fn mask_from_pattern(pattern: &[&str]) -> (Vec<bool>, usize, usize) {
    let img = frame_from_pattern(pattern, 0, 1);
    (img.px.iter().map(|&v| v == 1).collect(), img.w, img.h)
}

/// The ASCII art of a mask, one string per row (`'#'` = foreground).
pub fn pattern_of_mask(mask: &[bool], w: usize) -> Vec<String> {
    assert!(w > 0 && mask.len() % w == 0);
    mask.chunks(w)
        .map(|row| row.iter().map(|&m| if m { '#' } else { '.' }).collect())
        .collect()
}

/// The ASCII art of a box on a `w` × `h` frame (`'#'` inside the box).
pub fn pattern_of_roi(roi: Option<Roi>, w: usize, h: usize) -> Vec<String> {
    let mut mask = vec![false; w * h];
    if let Some(r) = roi {
        for y in 0..h {
            for x in 0..w {
                mask[y * w + x] = r.contains(x as u16, y as u16);
            }
        }
    }
    pattern_of_mask(&mask, w)
}

/// Asserts that `mask` draws `expected` (a readable diff on failure).
#[track_caller]
pub fn assert_mask_pattern(mask: &[bool], w: usize, expected: &[&str]) {
    let got = pattern_of_mask(mask, w);
    let want: Vec<String> = expected.iter().map(|s| s.to_string()).collect();
    assert_eq!(
        got,
        want,
        "\n got:\n{}\nwant:\n{}",
        got.join("\n"),
        want.join("\n")
    );
}

/// Asserts that `roi` covers exactly the `'#'` of `expected` (a filled rectangle, or
/// all `'.'` for no box).
#[track_caller]
pub fn assert_roi_pattern(roi: Option<Roi>, w: usize, expected: &[&str]) {
    let got = pattern_of_roi(roi, w, expected.len());
    let want: Vec<String> = expected.iter().map(|s| s.to_string()).collect();
    assert_eq!(
        got,
        want,
        "box {roi:?}\n got:\n{}\nwant:\n{}",
        got.join("\n"),
        want.join("\n")
    );
}

// ---------------------------------------------------------------------------------
// Frame generators
// ---------------------------------------------------------------------------------

fn clamp_u16(v: f64) -> u16 {
    v.round().clamp(0.0, 65535.0) as u16
}

/// A random box inside a `w` × `h` frame, at least 1×1.
pub fn random_roi(rng: &mut Rng, w: usize, h: usize) -> Roi {
    let x0 = rng.urange(0, w - 1);
    let y0 = rng.urange(0, h - 1);
    let x1 = rng.urange(x0 + 1, w);
    let y1 = rng.urange(y0 + 1, h);
    Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16)
}

/// Uniform DN in `0..=top` (`top` may exceed the bit depth's `max_dn`).
pub fn uniform_frame(rng: &mut Rng, w: usize, h: usize, bits: u8, top: u16) -> Img {
    let px = (0..w * h)
        .map(|_| rng.below(u64::from(top) + 1) as u16)
        .collect();
    Img { px, w, h, bits }
}

/// A noisy dark background with one or two noisy bright rectangles, and with
/// probability `hot` per pixel a value far above `max_dn`.
pub fn bimodal_frame(rng: &mut Rng, w: usize, h: usize, bits: u8, hot: f64) -> Img {
    let max = f64::from(max_dn(bits));
    let lo = rng.unit() * 0.4 * max;
    let hi = lo + (0.2 + rng.unit() * 0.6) * (max - lo);
    let sigma = rng.unit() * 0.05 * max;
    let mut img = Img {
        px: (0..w * h)
            .map(|_| clamp_u16((lo + rng.normalish(sigma)).min(max)))
            .collect(),
        w,
        h,
        bits,
    };
    for _ in 0..rng.urange(1, 2) {
        let r = random_roi(rng, w, h);
        for y in usize::from(r.y0)..usize::from(r.y1) {
            for x in usize::from(r.x0)..usize::from(r.x1) {
                *img.at(x, y) = clamp_u16((hi + rng.normalish(sigma)).min(max));
            }
        }
    }
    for v in &mut img.px {
        if rng.chance(hot) {
            *v = rng.range(i64::from(max_dn(bits)), 65535) as u16;
        }
    }
    img
}

/// Smooth texture (a few random sinusoids) plus noise plus a bright ellipse.
pub fn textured_frame(rng: &mut Rng, w: usize, h: usize, bits: u8) -> Img {
    let max = f64::from(max_dn(bits));
    let waves: Vec<(f64, f64, f64, f64)> = (0..3)
        .map(|_| {
            (
                rng.unit() * 0.2,
                rng.unit() * 0.2,
                rng.unit() * 6.3,
                rng.unit() * 0.15 * max,
            )
        })
        .collect();
    let base = 0.2 * max + rng.unit() * 0.2 * max;
    let noise = rng.unit() * 0.02 * max;
    let (cx, cy) = (rng.unit() * w as f64, rng.unit() * h as f64);
    let (rx, ry) = (
        1.0 + rng.unit() * w as f64 / 3.0,
        1.0 + rng.unit() * h as f64 / 3.0,
    );
    let target = rng.unit() * 0.35 * max;
    let mut px = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (xf, yf) = (x as f64, y as f64);
            let mut v = base + rng.normalish(noise);
            for &(kx, ky, ph, a) in &waves {
                v += a * (kx * xf + ky * yf + ph).sin();
            }
            let (dx, dy) = ((xf - cx) / rx, (yf - cy) / ry);
            if dx * dx + dy * dy <= 1.0 {
                v += target;
            }
            px.push(clamp_u16(v.min(max)));
        }
    }
    Img { px, w, h, bits }
}

/// Values drawn from a handful of levels (many exact ties in every statistic).
pub fn few_levels_frame(rng: &mut Rng, w: usize, h: usize, bits: u8) -> Img {
    let max = u64::from(max_dn(bits));
    let levels: Vec<u16> = (0..rng.urange(1, 4))
        .map(|_| rng.below(max + 1) as u16)
        .collect();
    let px = (0..w * h)
        .map(|_| levels[rng.below(levels.len() as u64) as usize])
        .collect();
    Img { px, w, h, bits }
}

/// Values in a narrow band `base..base + span` (a low-contrast scene).
pub fn narrow_frame(rng: &mut Rng, w: usize, h: usize, bits: u8, span: u16) -> Img {
    let max = max_dn(bits);
    let span = span.min(max);
    let base = rng.below(u64::from(max - span) + 1) as u16;
    let px = (0..w * h)
        .map(|_| base + rng.below(u64::from(span) + 1) as u16)
        .collect();
    Img { px, w, h, bits }
}

/// A frame of one of the kinds above, chosen at random.
pub fn any_frame(rng: &mut Rng, w: usize, h: usize, bits: u8) -> Img {
    match rng.below(6) {
        0 => uniform_frame(rng, w, h, bits, max_dn(bits)),
        1 => uniform_frame(rng, w, h, bits, u16::MAX),
        2 => bimodal_frame(rng, w, h, bits, 0.002),
        3 => textured_frame(rng, w, h, bits),
        4 => few_levels_frame(rng, w, h, bits),
        _ => {
            let span = rng.range(1, 300) as u16;
            narrow_frame(rng, w, h, bits, span)
        }
    }
}

// ---------------------------------------------------------------------------------
// Mask generators (for the box rules)
// ---------------------------------------------------------------------------------

/// Foreground with probability `p` per pixel.
pub fn random_mask(rng: &mut Rng, w: usize, h: usize, p: f64) -> Vec<bool> {
    (0..w * h).map(|_| rng.chance(p)).collect()
}

/// A few random filled rectangles.
pub fn rects_mask(rng: &mut Rng, w: usize, h: usize, n: usize) -> Vec<bool> {
    let mut m = vec![false; w * h];
    for _ in 0..n {
        let r = random_roi(rng, w, h);
        for y in usize::from(r.y0)..usize::from(r.y1) {
            for x in usize::from(r.x0)..usize::from(r.x1) {
                m[y * w + x] = true;
            }
        }
    }
    m
}

/// Checkerboard of `cell`-pixel squares (cell 1: one 8-connected component).
pub fn checkerboard_mask(w: usize, h: usize, cell: usize) -> Vec<bool> {
    (0..w * h)
        .map(|i| ((i % w) / cell + (i / w) / cell) % 2 == 0)
        .collect()
}

/// A one-pixel-wide square spiral with one-pixel gaps, winding inwards from (0, 0):
/// one component that raster order sees as many pieces merging late.
pub fn spiral_mask(w: usize, h: usize) -> Vec<bool> {
    let mut m = vec![false; w * h];
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h;
    let dirs = [(1i64, 0i64), (0, 1), (-1, 0), (0, -1)];
    let (mut x, mut y, mut d) = (0i64, 0i64, 0usize);
    m[0] = true;
    loop {
        let mut moved = false;
        for _ in 0..2 {
            let (dx, dy) = dirs[d];
            let (nx, ny) = (x + dx, y + dy);
            let (mx, my) = (x + 2 * dx, y + 2 * dy);
            let free = inside(nx, ny) && !m[ny as usize * w + nx as usize];
            let gap = !(inside(mx, my) && m[my as usize * w + mx as usize]);
            if free && gap {
                (x, y) = (nx, ny);
                m[y as usize * w + x as usize] = true;
                moved = true;
                break;
            }
            d = (d + 1) % 4;
        }
        if !moved {
            return m;
        }
    }
}

/// Nested U shapes (open at the top), `gap` pixels apart: each U is two bars that only
/// join in its bottom row.
pub fn nested_u_mask(w: usize, h: usize, gap: usize) -> Vec<bool> {
    let mut m = vec![false; w * h];
    let step = gap + 1;
    let mut k = 0;
    loop {
        let (x0, x1, y1) = (
            k * step,
            w.saturating_sub(1 + k * step),
            h.saturating_sub(1 + k * step),
        );
        if x0 >= x1 || y1 == 0 {
            return m;
        }
        for y in 0..=y1 {
            m[y * w + x0] = true;
            m[y * w + x1] = true;
        }
        for x in x0..=x1 {
            m[y1 * w + x] = true;
        }
        k += 1;
    }
}

/// A comb: teeth in every `pitch`-th column, joined only in the last row (`down`), or
/// only in the first row (`!down`).
pub fn comb_mask(w: usize, h: usize, pitch: usize, down: bool) -> Vec<bool> {
    let mut m = vec![false; w * h];
    for y in 0..h {
        for x in (0..w).step_by(pitch) {
            m[y * w + x] = true;
        }
    }
    let join = if down { h - 1 } else { 0 };
    for x in 0..w {
        m[join * w + x] = true;
    }
    m
}

/// Vertical stripes in every other column: the most components a row can keep alive.
pub fn stripes_mask(w: usize, h: usize) -> Vec<bool> {
    (0..w * h).map(|i| (i % w) % 2 == 0).collect()
}

/// Isolated pixels on a 2-pixel lattice: the most components in a frame.
pub fn dots_mask(w: usize, h: usize) -> Vec<bool> {
    (0..w * h)
        .map(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0)
        .collect()
}

/// A structured or random mask, chosen at random.
pub fn any_mask(rng: &mut Rng, w: usize, h: usize) -> Vec<bool> {
    match rng.below(10) {
        0..=3 => {
            let p = [0.02, 0.1, 0.3, 0.45, 0.5, 0.55, 0.7, 0.9, 0.98][rng.below(9) as usize];
            random_mask(rng, w, h, p)
        }
        4 => {
            let n = rng.urange(1, 6);
            rects_mask(rng, w, h, n)
        }
        5 => checkerboard_mask(w, h, rng.urange(1, 3)),
        6 => spiral_mask(w, h),
        7 => nested_u_mask(w, h, rng.urange(1, 3)),
        8 => comb_mask(w, h, rng.urange(2, 4), rng.chance(0.5)),
        _ => {
            if rng.chance(0.5) {
                stripes_mask(w, h)
            } else {
                dots_mask(w, h)
            }
        }
    }
}

// ---------------------------------------------------------------------------------
// Brute-force references
// ---------------------------------------------------------------------------------

/// Otsu by exhaustive search: over every threshold `t` in `0..max_dn` for which both
/// classes `v ≤ t` and `v > t` are non-empty, the largest between-class variance
/// `(M·n₀ − N·m₀)² / (n₀·(N − n₀))`; ties go to the smallest `t`. DN above `max_dn`
/// count as `max_dn`. `None` when no threshold splits the frame (a single DN value).
///
/// Exactness: with `n₁ = N − n₀`, `M·n₀ − N·m₀ = n₀·n₁·(μ₁ − μ₀)`, so its magnitude is
/// at most `(N²/4)·max_dn ≤ 1.66e9 · 65 535 < 1.1e14`; squared `< 1.2e28`, times a
/// denominator `≤ N²/4 < 1.7e9` stays `< 2.1e37 < u128::MAX ≈ 3.4e38`. The
/// cross-multiplied comparison is exact (`checked_mul` asserts the bound).
pub fn otsu_exhaustive(pixels: &[u16], bits: u8) -> Option<u32> {
    let max = usize::from(max_dn(bits));
    let mut hist = vec![0u64; max + 1];
    for &v in pixels {
        hist[usize::from(v).min(max)] += 1;
    }
    let n = pixels.len() as u64;
    let m: u64 = hist.iter().enumerate().map(|(v, &c)| v as u64 * c).sum();
    let mut best: Option<(u32, u128, u128)> = None;
    let (mut n0, mut m0) = (0u64, 0u64);
    for (t, &c) in hist.iter().enumerate().take(max) {
        n0 += c;
        m0 += t as u64 * c;
        if n0 == 0 || n0 == n {
            continue;
        }
        let d = i128::from(m) * i128::from(n0) - i128::from(n) * i128::from(m0);
        let d2 = d.unsigned_abs() * d.unsigned_abs();
        let den = u128::from(n0) * u128::from(n - n0);
        let better = match best {
            None => true,
            Some((_, bd2, bden)) => match (d2.checked_mul(bden), bd2.checked_mul(den)) {
                (Some(a), Some(b)) => a > b,
                // Frames above the reference size: quotients, then remainders
                // cross-multiplied (each below its denominator ≤ N²/4 < 2^38 for
                // N ≤ 1024·768, so products < 2^76).
                _ => {
                    let (q1, r1) = (d2 / den, d2 % den);
                    let (q2, r2) = (bd2 / bden, bd2 % bden);
                    q1 > q2 || (q1 == q2 && r1 * bden > r2 * den)
                }
            },
        };
        if better {
            best = Some((t as u32, d2, den));
        }
    }
    best.map(|(t, _, _)| t)
}

/// The threshold the Otsu detector must report: the exhaustive optimum, or the single
/// DN value (clamped) of a frame that cannot be split.
pub fn otsu_expected_threshold(img: &Img) -> u32 {
    otsu_exhaustive(&img.px, img.bits).unwrap_or_else(|| u32::from(img.px[0].min(img.max_dn())))
}

/// Otsu's mask for threshold `t`: `min(v, max_dn) > t`.
pub fn mask_above(img: &Img, t: u32) -> Vec<bool> {
    let max = img.max_dn();
    img.px.iter().map(|&v| u32::from(v.min(max)) > t).collect()
}

/// Adaptive thresholding by the definition: for every pixel, the sum and count of
/// the `block × block` window centred on it, clipped to the frame (DN clamped to
/// `max_dn`); foreground iff `v·count > sum + offset·count` (i64). Window sums come
/// from a summed-area table (an independent method from the detector's column sums);
/// [`adaptive_bruteforce`] is the literal per-pixel loop for small frames.
pub fn adaptive_naive(
    pixels: &[u16],
    w: usize,
    h: usize,
    bits: u8,
    block: u16,
    offset: i32,
) -> Vec<bool> {
    let max = max_dn(bits);
    let r = usize::from(block / 2);
    let sw = w + 1;
    let mut sat = vec![0i64; sw * (h + 1)];
    for y in 0..h {
        for x in 0..w {
            let v = i64::from(pixels[y * w + x].min(max));
            sat[(y + 1) * sw + x + 1] =
                v + sat[y * sw + x + 1] + sat[(y + 1) * sw + x] - sat[y * sw + x];
        }
    }
    let offset = i64::from(offset);
    let mut mask = Vec::with_capacity(w * h);
    for y in 0..h {
        let (ya, yb) = (y.saturating_sub(r), (y + r).min(h - 1) + 1);
        for x in 0..w {
            let (xa, xb) = (x.saturating_sub(r), (x + r).min(w - 1) + 1);
            let sum = sat[yb * sw + xb] - sat[ya * sw + xb] - sat[yb * sw + xa] + sat[ya * sw + xa];
            let count = ((yb - ya) * (xb - xa)) as i64;
            let v = i64::from(pixels[y * w + x].min(max));
            mask.push(v * count > sum + offset * count);
        }
    }
    mask
}

/// [`adaptive_naive`] as the literal double loop over every window (small frames).
pub fn adaptive_bruteforce(
    pixels: &[u16],
    w: usize,
    h: usize,
    bits: u8,
    block: u16,
    offset: i32,
) -> Vec<bool> {
    let max = max_dn(bits);
    let r = i64::from(block / 2);
    let mut mask = Vec::with_capacity(w * h);
    for y in 0..h as i64 {
        for x in 0..w as i64 {
            let (mut sum, mut count) = (0i64, 0i64);
            for yy in y - r..=y + r {
                for xx in x - r..=x + r {
                    if yy >= 0 && xx >= 0 && (yy as usize) < h && (xx as usize) < w {
                        sum += i64::from(pixels[yy as usize * w + xx as usize].min(max));
                        count += 1;
                    }
                }
            }
            let v = i64::from(pixels[y as usize * w + x as usize].min(max));
            mask.push(v * count > sum + i64::from(offset) * count);
        }
    }
    mask
}

/// Prewitt L1 gradient `|g_x| + |g_y|` of every pixel (0 on the one-pixel border),
/// DN clamped to `max_dn`.
pub fn prewitt_naive(pixels: &[u16], w: usize, h: usize, bits: u8) -> Vec<u32> {
    let max = max_dn(bits);
    let p = |x: usize, y: usize| i64::from(pixels[y * w + x].min(max));
    let mut g = vec![0u32; w * h];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let mut gx = 0i64;
            let mut gy = 0i64;
            for d in 0..3 {
                gx += p(x + 1, y + d - 1) - p(x - 1, y + d - 1);
                gy += p(x + d - 1, y + 1) - p(x + d - 1, y - 1);
            }
            g[y * w + x] = (gx.abs() + gy.abs()) as u32;
        }
    }
    g
}

/// WGE by the definition, on the whole gradient image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WgeReference {
    /// Foreground mask.
    pub mask: Vec<bool>,
    /// The threshold, or `u32::MAX` when every gradient is eliminated.
    pub threshold: u32,
}

/// WGE reference: sort the interior gradients, `k = ⌊drop_fraction·N⌋` (computed as the
/// module documents, in f32), threshold = the `k`-th smallest (0-based) raised to
/// `min_gradient`, nothing kept when `k == N`; foreground = interior and `g ≥ threshold`.
pub fn wge_naive(
    pixels: &[u16],
    w: usize,
    h: usize,
    bits: u8,
    drop_fraction: f32,
    min_gradient: u32,
) -> WgeReference {
    let g = prewitt_naive(pixels, w, h, bits);
    let interior = |i: usize| {
        let (x, y) = (i % w, i / w);
        x >= 1 && y >= 1 && x + 1 < w && y + 1 < h
    };
    let mut sorted: Vec<u32> = (0..w * h).filter(|&i| interior(i)).map(|i| g[i]).collect();
    sorted.sort_unstable();
    let n = sorted.len() as u32;
    let k = ((drop_fraction * n as f32) as u32).min(n);
    let threshold = if k == n {
        u32::MAX
    } else {
        sorted[k as usize].max(min_gradient)
    };
    let mask = (0..w * h)
        .map(|i| threshold != u32::MAX && interior(i) && g[i] >= threshold)
        .collect();
    WgeReference { mask, threshold }
}

/// Box of every foreground pixel, `None` for an empty mask.
pub fn hull_of_mask(mask: &[bool], w: usize, h: usize) -> Option<Roi> {
    assert_eq!(mask.len(), w * h);
    let mut r: Option<(usize, usize, usize, usize)> = None;
    for y in 0..h {
        for x in 0..w {
            if mask[y * w + x] {
                r = Some(match r {
                    None => (x, y, x + 1, y + 1),
                    Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1)),
                });
            }
        }
    }
    r.map(|(x0, y0, x1, y1)| Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16))
}

/// Box of the largest 8-connected component by flood fill (most pixels; ties go to the
/// component whose first pixel in raster order comes first), `None` for an empty mask.
pub fn largest_component_naive(mask: &[bool], w: usize, h: usize) -> Option<Roi> {
    assert_eq!(mask.len(), w * h);
    let mut seen = vec![false; w * h];
    let mut best: Option<(usize, Roi)> = None;
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !mask[start] || seen[start] {
            continue;
        }
        // Components are discovered in raster order of their first pixel, so a strict
        // comparison keeps the earliest of equally large ones.
        seen[start] = true;
        stack.push(start);
        let (mut area, mut x0, mut y0, mut x1, mut y1) = (0usize, w, h, 0usize, 0usize);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            area += 1;
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            for ny in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                    let j = ny * w + nx;
                    if mask[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        let roi = Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16);
        if best.is_none_or(|(a, _)| area > a) {
            best = Some((area, roi));
        }
    }
    best.map(|(_, r)| r)
}

/// The box `rule` makes of `mask`, by the references above.
pub fn box_by_rule(rule: BoxRule, mask: &[bool], w: usize, h: usize) -> Option<Roi> {
    match rule {
        BoxRule::AllForeground => hull_of_mask(mask, w, h),
        BoxRule::LargestComponent => largest_component_naive(mask, w, h),
    }
}

// ---------------------------------------------------------------------------------
// Running detectors and recording their masks
// ---------------------------------------------------------------------------------

/// Detectors whose scratch the tests can build.
pub trait TestDetector: Detector + Copy {
    /// Fresh scratch memory, boxed (DoG's is 70 KiB).
    fn scratch() -> Box<Scratch<Self::Work<Reference>>>;
    /// The same detector with another box rule.
    fn with_rule(self, rule: BoxRule) -> Self;
}

impl TestDetector for Otsu {
    fn scratch() -> Box<Scratch<Self::Work<Reference>>> {
        Box::new(OtsuScratch::new())
    }
    fn with_rule(self, box_rule: BoxRule) -> Self {
        Otsu { box_rule }
    }
}

impl TestDetector for Adaptive {
    fn scratch() -> Box<Scratch<Self::Work<Reference>>> {
        Box::new(AdaptiveScratch::new())
    }
    fn with_rule(self, box_rule: BoxRule) -> Self {
        Adaptive { box_rule, ..self }
    }
}

impl TestDetector for Wge {
    fn scratch() -> Box<Scratch<Self::Work<Reference>>> {
        Box::new(WgeScratch::new())
    }
    fn with_rule(self, box_rule: BoxRule) -> Self {
        Wge { box_rule, ..self }
    }
}

impl TestDetector for Dog {
    fn scratch() -> Box<Scratch<Self::Work<Reference>>> {
        Box::new(DogScratch::new())
    }
    fn with_rule(self, box_rule: BoxRule) -> Self {
        Dog { box_rule, ..self }
    }
}

/// Wraps a detector and records every mask row its `foreground` hands out, while
/// `detect` (the trait's own method, run in the wrapped detector's scratch) turns the
/// same rows into the detection. This is the public way to see a detector's mask.
pub struct Spy<D> {
    inner: D,
    rows: RefCell<Vec<(usize, Vec<bool>)>>,
}

impl<D: Detector> Detector for Spy<D> {
    type Work<C: FrameCapacity> = D::Work<C>;
    const NAME: &'static str = "spy";

    fn validate(&self) -> Result<(), DetectError> {
        self.inner.validate()
    }

    fn box_rule(&self) -> BoxRule {
        self.inner.box_rule()
    }

    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut Self::Work<C>,
        mut sink: F,
    ) -> u32 {
        self.inner.foreground(frame, work, |y, mask| {
            self.rows.borrow_mut().push((y, mask.to_vec()));
            sink(y, mask);
        })
    }
}

/// What one detector run produced.
#[derive(Debug, Clone)]
pub struct Observed {
    /// The detection `detect` returned.
    pub detection: Detection,
    /// The full mask handed to the box rule, row-major.
    pub mask: Vec<bool>,
}

/// Runs `det` on `img` in `scratch` through `detect`, recording the mask. Asserts the
/// row protocol of [`Detector::foreground`] (rows 0..h in order, each exactly once,
/// each `w` long) and that `foreground_px` counts the mask.
#[track_caller]
pub fn observe_in<D: Detector, C: FrameCapacity>(
    det: D,
    img: &Img,
    scratch: &mut Scratch<D::Work<C>, C>,
) -> Observed {
    let spy = Spy {
        inner: det,
        rows: RefCell::new(Vec::new()),
    };
    let detection = spy
        .detect(&img.frame(), scratch)
        .expect("parameters are valid");
    let rows = spy.rows.into_inner();
    let order: Vec<usize> = rows.iter().map(|(y, _)| *y).collect();
    assert_eq!(
        order,
        (0..img.h).collect::<Vec<_>>(),
        "foreground must hand rows 0..h once each, in order"
    );
    let mut mask = Vec::with_capacity(img.w * img.h);
    for (y, row) in &rows {
        assert_eq!(row.len(), img.w, "row {y} has the wrong length");
        mask.extend_from_slice(row);
    }
    let count = mask.iter().filter(|&&m| m).count() as u32;
    assert_eq!(
        detection.foreground_px, count,
        "foreground_px counts the mask"
    );
    Observed { detection, mask }
}

/// [`observe_in`] with fresh scratch memory.
#[track_caller]
pub fn observe<D: TestDetector>(det: D, img: &Img) -> Observed {
    observe_in(det, img, &mut D::scratch())
}

/// Runs `det` through its plain `detect` in fresh scratch memory.
pub fn detect<D: TestDetector>(det: D, img: &Img) -> Result<Detection, DetectError> {
    det.detect(&img.frame(), &mut D::scratch())
}

/// Asserts that the detection's box is what `det`'s rule makes of its own mask, by
/// the brute-force references.
#[track_caller]
pub fn assert_box_rule<D: Detector>(det: &D, obs: &Observed, img: &Img, what: &str) {
    let want = box_by_rule(det.box_rule(), &obs.mask, img.w, img.h);
    assert_eq!(
        obs.detection.roi,
        want,
        "{what}: {:?} box of the detector's own mask",
        det.box_rule()
    );
}

/// The distinct values of a slice (for diagnostics).
pub fn distinct(px: &[u16]) -> usize {
    px.iter().collect::<HashSet<_>>().len()
}

/// Both box rules.
pub const RULES: [BoxRule; 2] = [BoxRule::AllForeground, BoxRule::LargestComponent];

/// The committed fixture frames, in the order of `truth.csv`: `(name, file)`.
pub const FIXTURES: [(&str, &str); 4] = [
    ("deep-space", "deep-space.png"),
    ("earth", "earth.png"),
    ("earth-close", "earth-close.png"),
    ("earth-far", "earth-far.png"),
];

/// The folder of the committed fixture frames (see its README).
pub fn fixtures_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixtures")
}

/// The committed `truth.csv`: every fixture file with the exact box of its target.
pub fn fixture_truth() -> Vec<(String, Roi)> {
    let path = fixtures_dir().join("truth.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: cannot read: {e}", path.display()));
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("file,x0,y0,x1,y1"), "truth.csv header");
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 5, "truth.csv line {line:?}");
            let n = |i: usize| -> u16 { f[i].parse().expect("truth.csv coordinate") };
            (f[0].to_string(), Roi::new(n(1), n(2), n(3), n(4)))
        })
        .collect()
}

/// Reads a committed 16-bit grayscale PNG as a 14-bit test image (the fixtures are
/// 14-bit DN stored unscaled in 16-bit samples).
pub fn read_png14(path: &std::path::Path) -> Img {
    let file = std::fs::File::open(path)
        .unwrap_or_else(|e| panic!("{}: cannot open: {e}", path.display()));
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder
        .read_info()
        .unwrap_or_else(|e| panic!("{}: not a PNG: {e}", path.display()));
    let mut buf = vec![0u8; reader.output_buffer_size().expect("small frame")];
    let info = reader
        .next_frame(&mut buf)
        .unwrap_or_else(|e| panic!("{}: cannot decode: {e}", path.display()));
    assert_eq!(
        (info.color_type, info.bit_depth),
        (png::ColorType::Grayscale, png::BitDepth::Sixteen),
        "{}: fixtures are 16-bit grayscale",
        path.display()
    );
    let (w, h) = (info.width as usize, info.height as usize);
    let px: Vec<u16> = buf[..w * h * 2]
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect();
    let img = Img { px, w, h, bits: 14 };
    assert!(
        img.px.iter().all(|&v| v <= img.max_dn()),
        "{}: DN above 14 bits",
        path.display()
    );
    img
}

/// The host's procedural fixture frames (`tirroi fixtures`, committed in
/// `core/tests/data/fixtures/`) as test images, with their names. The root test
/// `tests/fixture_data.rs` checks that the host's generator still makes exactly these.
pub fn fixture_imgs() -> Vec<(&'static str, Img)> {
    let dir = fixtures_dir();
    let listed: Vec<String> = fixture_truth().into_iter().map(|(f, _)| f).collect();
    let want: Vec<&str> = FIXTURES.iter().map(|&(_, file)| file).collect();
    assert_eq!(listed, want, "truth.csv lists the fixture files");
    FIXTURES
        .iter()
        .map(|&(name, file)| (name, read_png14(&dir.join(file))))
        .collect()
}

/// A `w`×`h` dark frame (300 DN) with a bright soft-edged disc (9 300 DN inside, a
/// logistic edge 1.5 px wide); returns it and the disc's box (pixels within `radius`
/// of the centre).
pub fn disc_frame(w: usize, h: usize, cx: f64, cy: f64, radius: f64) -> (Img, Roi) {
    let mut img = Img::constant(w, h, 14, 300);
    for y in 0..h {
        for x in 0..w {
            let d = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
            let v = 300.0 + 9_000.0 / (1.0 + ((d - radius) / 1.5).exp());
            *img.at(x, y) = v.round() as u16;
        }
    }
    let r = Roi::new(
        (cx - radius).ceil() as u16,
        (cy - radius).ceil() as u16,
        (cx + radius).floor() as u16 + 1,
        (cy + radius).floor() as u16 + 1,
    );
    (img, r)
}
