//! Stage 2c: deep space recognised by its statistics, not by DN 0. Behind a target in
//! deep space a real camera shows only its own signal: a pedestal and a shading that
//! is smooth across the frame (the Hayabusa2 TIR's dark frame: a dark centre, brighter
//! edges, 30–100 DN), noise, fixed pattern and a few hot pixels. The Earth's clouds,
//! limb and decks are not smooth at the 8-px scale. So the cell means are fitted by a
//! smooth surface (a polynomial of degree [`DEGREE`] in the frame's coordinates, by
//! least squares on 16×16-pixel blocks, trimmed of outliers over [`FIT_ROUNDS`]
//! rounds); when the cells' residuals around it are within noise
//! ([`MAX_SPREAD_PERMILLE`] of the pixel σ: the window is deep space), the cells that
//! depart from it ([`OUTLIER_K`] × that spread, at least one σ) are the target's, and
//! the classifier (trained on our renders, which miss most low-contrast targets over a
//! shaded sky) is not asked.
//!
//! Chosen on family A (realistic seed 7001: of its 36 radiometry frames at close range
//! over deep space, the classifier's mean IoU is 0.19; `docs/detectors.md` § Session
//! 29): the degree, the spread limit (re-chosen in session 30 on family A rendered
//! with the real camera's cell-scale field: Earth frames' spread 0.9–6.3 σ, 5th–95th
//! percentile, deep space's 0.4–0.7 σ) and [`WEAK_K`]. Set by
//! their reason and not varied: [`TRIM_K`], [`OUTLIER_K`], [`FIT_ROUNDS`],
//! [`BLOCK_CELLS`], [`MAX_OUTLIER_PERMILLE`], [`MIN_VALID_PERMILLE`].
//!
//! Memory: the residuals (one `f32` per cell, then per block) in a plane the caller
//! lends (`auto-v2`'s integrals, made after this stage); on the stack two 15×15 `f32`
//! systems and the solver's copy (about 2.2 KB measured on the M7). Cost: one pass
//! over ≤ 336 blocks for every block's normal equations (120 products each), then per
//! round the trimmed blocks' less and a residual pass, ≤ [`FIT_ROUNDS`] rounds; three
//! passes over the cells; medians by 64-bin histogram passes: 1.06 M instructions on
//! the Cortex-M7 where it runs in full (docs/flight.md § Session 29).

use super::order::select_binned;

/// Degree of the background surface: 4 fits the real dark frame's shading, whose
/// corners rise faster than a paraboloid (family A: degree 2 leaves the corners as
/// false components, 4 does not; 15 terms).
pub const DEGREE: usize = 4;

/// Terms of the polynomial of degree [`DEGREE`] in two variables.
const TERMS: usize = (DEGREE + 1) * (DEGREE + 2) / 2;

/// The powers `(i, j)` of each term, `P_i(across) · P_j(down)`, in the basis's order.
const TERM_POWERS: [(usize, usize); TERMS] = {
    let mut powers = [(0, 0); TERMS];
    let (mut i, mut k) = (0, 0);
    while i <= DEGREE {
        let mut j = 0;
        while j <= DEGREE - i {
            powers[k] = (i, j);
            k += 1;
            j += 1;
        }
        i += 1;
    }
    powers
};

/// Cells per side of a fit block: the fit works on 2×2-cell (16×16-pixel) blocks,
/// a quarter of the cells' products, as smooth as the shading it models.
pub const BLOCK_CELLS: usize = 2;

/// Least-squares rounds; after each, blocks beyond [`TRIM_K`] robust σ of the
/// residuals leave the fit (a target covering up to a third of the frame is trimmed
/// away in 2–3 rounds).
pub const FIT_ROUNDS: usize = 4;

/// Trimming threshold, robust σ of the block residuals (3: a Gaussian keeps 99.7 %).
pub const TRIM_K: f32 = 3.0;

/// A round whose blocks' spread is beyond this many times the deep-space limit ends the
/// stage (cloud texture: later rounds trim outliers, they do not halve the texture's
/// spread); the answers on family A are those without the early end.
const EARLY_EXIT_FACTOR: f32 = 8.0;

/// The cells' robust residual spread must be at most this share of the pixel noise
/// σ, ‰, for the window to be deep space. Re-chosen on family A (seed 7001) once the
/// renderer's camera carried the real dark frame's cell-scale field (session 30): its
/// deep-space frames then spread 400–700 ‰ (5th–95th percentile; the real dark frame's
/// test set 340–680 ‰), its Earth frames 920 ‰ and more. Family A's realistic mean IoU
/// rises with the limit to a plateau at 1000 ‰ (600: 0.508, 800: 0.514, 1000–1200:
/// 0.519); at 1500 ‰ Earth frames start to be taken for deep space (radiometry at far
/// range 0.078 → 0.069), so the smallest limit on the plateau.
pub const MAX_SPREAD_PERMILLE: u32 = 1000;

/// A cell departs from the surface (a target cell) beyond this many spreads (and at
/// least one pixel σ).
pub const OUTLIER_K: f32 = 6.0;

/// A cell departing beyond this many spreads (and half a pixel σ) but not beyond
/// [`OUTLIER_K`] joins a target's cells it touches (a fainter face of the target):
/// code [`WEAK_CODE`]; a component of such cells alone is no target.
pub const WEAK_K: f32 = 3.0;

/// The code of a weakly departing cell; target cells' codes are above it.
pub const WEAK_CODE: u8 = 1;

/// More than this share of departing cells, ‰, and the surface is no background model
/// (a target over a third of the frame leaves too few cells to fit).
pub const MAX_OUTLIER_PERMILLE: usize = 350;

/// At least this share of the cells must be usable (not clipped at 0 nor at the top
/// DN), ‰: a frame read out with its centre clipped has no shading to fit.
pub const MIN_VALID_PERMILLE: usize = 500;

/// The MAD of a Gaussian times this is its σ.
const MAD_TO_SIGMA: f32 = 1.4826;

/// Residuals in 1/16 DN for their median (an integer order statistic).
const RESIDUAL_SCALE: f32 = 16.0;

/// Legendre polynomials `P0..=P4` at `t` (−1..=1): an orthogonal basis keeps the
/// normal equations well conditioned in `f32`.
fn legendre(t: f32) -> [f32; DEGREE + 1] {
    let t2 = t * t;
    [
        1.0,
        t,
        1.5 * t2 - 0.5,
        (2.5 * t2 - 1.5) * t,
        (4.375 * t2 - 3.75) * t2 + 0.375,
    ]
}

/// The basis at cell coordinates `(x, y)` of a `pw × ph` plane (cell units, centres at
/// `c + 0.5`).
fn basis(x: f32, y: f32, (pw, ph): (usize, usize)) -> [f32; TERMS] {
    let pu = legendre(2.0 * x / pw as f32 - 1.0);
    let pv = legendre(2.0 * y / ph as f32 - 1.0);
    let mut out = [0.0f32; TERMS];
    let mut k = 0;
    for (i, a) in pu.iter().enumerate() {
        for b in pv.iter().take(DEGREE + 1 - i) {
            if let Some(o) = out.get_mut(k) {
                *o = a * b;
            }
            k += 1;
        }
    }
    out
}

/// Solves `m · x = rhs` (symmetric positive definite) by Cholesky in place; `None` for
/// a singular system. Index loops: the textbook triangular recurrences read rows and
/// columns of the same matrix.
#[allow(clippy::needless_range_loop)]
fn solve(m: &mut [[f32; TERMS]; TERMS], rhs: &[f32; TERMS]) -> Option<[f32; TERMS]> {
    for j in 0..TERMS {
        let mut d = m[j][j];
        for k in 0..j {
            d -= m[j][k] * m[j][k];
        }
        if d.is_nan() || d <= 1e-6 * (1.0 + m[j][j].abs()) {
            return None;
        }
        let d = libm::sqrtf(d);
        m[j][j] = d;
        for i in j + 1..TERMS {
            let mut s = m[i][j];
            for k in 0..j {
                s -= m[i][k] * m[j][k];
            }
            m[i][j] = s / d;
        }
    }
    let mut y = [0.0f32; TERMS];
    for i in 0..TERMS {
        let mut s = rhs[i];
        for k in 0..i {
            s -= m[i][k] * y[k];
        }
        y[i] = s / m[i][i];
    }
    let mut x = [0.0f32; TERMS];
    for i in (0..TERMS).rev() {
        let mut s = y[i];
        for k in i + 1..TERMS {
            s -= m[k][i] * x[k];
        }
        x[i] = s / m[i][i];
    }
    Some(x)
}

/// The robust spread (MAD × 1.4826, from the median in 1/16 DN) of the residuals
/// (`f32` bits; NaN: none) within `trim` of 0, DN; infinite for none.
fn trimmed_spread(residuals: &[u32], trim: f32) -> f32 {
    let within = |r: &u32| {
        let r = f32::from_bits(*r);
        (!r.is_nan() && libm::fabsf(r) <= trim).then_some(r)
    };
    let n = residuals.iter().filter_map(within).count();
    if n == 0 {
        return f32::INFINITY;
    }
    let code = |r: f32| (libm::fabsf(r) * RESIDUAL_SCALE).min(u32::MAX as f32 / 2.0) as u32;
    let values = || residuals.iter().filter_map(within).map(code);
    let hi = values().max().unwrap_or(0);
    let mad = select_binned(values, n / 2, hi);
    MAD_TO_SIGMA * (mad as f32 + 0.5) / RESIDUAL_SCALE
}

/// Whether a cell can be fitted: not clipped at the top DN (no saturated pixel) nor at
/// 0 (a mean of 0 is a cell clipped whole).
fn usable(mean: u16, saturated: u8) -> bool {
    saturated == 0 && mean > 0
}

/// What stage 2c saw: the surface's spread and its departing cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeepSpace {
    /// Robust spread of the usable cells' residuals, DN.
    pub spread_dn: f32,
    /// Cells departing from the surface (target cells).
    pub outliers: usize,
}

/// Stage 2c on the cell plane `(pw, ph)` (`mean_dn` and, in `saturated_then_codes`,
/// the saturated counts as the cell pass left them; pixel noise `sigma_dn`): when the
/// window is deep space, overwrites the counts with the target cells' codes (above
/// [`WEAK_CODE`]: 1 + the departure in thresholds; [`WEAK_CODE`] for a weak departure;
/// 0 elsewhere) and returns what it saw; `None` (the counts untouched) when it is not
/// deep space or the fit fails. `scratch` (≥ one entry per cell) holds the residuals
/// (`f32` bits) so each is computed once. Slices shorter than the plane: `None`.
pub fn deep_space_codes(
    mean_dn: &[u16],
    saturated_then_codes: &mut [u8],
    plane: (usize, usize),
    sigma_dn: u32,
    scratch: &mut [u32],
) -> Option<DeepSpace> {
    fit_codes(
        mean_dn,
        saturated_then_codes,
        plane,
        sigma_dn,
        scratch,
        (None, MIN_VALID_PERMILLE),
    )
}

/// Stage 2e: [`deep_space_codes`] on the sky beside the Earth, the cells whose
/// `distance` (to the Earth, one per cell) exceeds `excluded` (the other cells are
/// left out of the fit and coded 0, as unusable ones are), of which at least
/// `min_sky_permille` of the plane's cells must be usable; `None` for a short
/// `distance` too.
#[allow(clippy::too_many_arguments)]
pub fn sky_codes(
    mean_dn: &[u16],
    saturated_then_codes: &mut [u8],
    plane: (usize, usize),
    sigma_dn: u32,
    scratch: &mut [u32],
    distance: &[u8],
    excluded: u8,
    min_sky_permille: usize,
) -> Option<DeepSpace> {
    let distance = distance.get(..plane.0 * plane.1)?;
    fit_codes(
        mean_dn,
        saturated_then_codes,
        plane,
        sigma_dn,
        scratch,
        (Some((distance, excluded)), min_sky_permille),
    )
}

/// [`deep_space_codes`] on the cells beyond `fitted.0`'s distance (all without it),
/// at least `fitted.1` ‰ of the plane's cells usable. One function for both stages,
/// not a generic one: a second copy of the fit cost the M7's flash 6 KB.
fn fit_codes(
    mean_dn: &[u16],
    saturated_then_codes: &mut [u8],
    (pw, ph): (usize, usize),
    sigma_dn: u32,
    scratch: &mut [u32],
    (fitted, min_valid_permille): (Option<(&[u8], u8)>, usize),
) -> Option<DeepSpace> {
    let n = pw * ph;
    let mean_dn = mean_dn.get(..n)?;
    let plane_codes = saturated_then_codes.get_mut(..n)?;
    let scratch = scratch.get_mut(..n)?;
    if n == 0 {
        return None;
    }
    let saturated_px: &[u8] = plane_codes;
    let usable_at = |i: usize| {
        fitted.is_none_or(|(distance, excluded)| distance.get(i).is_some_and(|&d| d > excluded))
            && usable(
                mean_dn.get(i).copied().unwrap_or(0),
                saturated_px.get(i).copied().unwrap_or(1),
            )
    };
    let valid = (0..n).filter(|&i| usable_at(i)).count();
    if valid * 1000 < min_valid_permille * n {
        return None;
    }
    // Residuals around the frame's median level keep the sums small in `f32`.
    let level = select_binned(|| mean_dn.iter().map(|&m| u32::from(m)), n / 2, 65_535) as f32;
    let plane = (pw, ph);
    let sigma = sigma_dn.max(1) as f32;
    let limit = MAX_SPREAD_PERMILLE as f32 * sigma / 1000.0;
    let (bw, bh) = (pw.div_ceil(BLOCK_CELLS), ph.div_ceil(BLOCK_CELLS));
    let nb = bw * bh;
    // The blocks: their mean (NaN when a cell is not usable) in `scratch[..nb]`, their
    // residual around the last surface in `scratch[nb..2nb]` (2 nb ≤ n + 2 pw: the
    // last row of blocks may be half a row of cells; `get`: no panic path).
    let centre = |b: usize, cells: usize| {
        let c0 = b * BLOCK_CELLS;
        let k = (c0 + BLOCK_CELLS).min(cells).saturating_sub(c0).max(1);
        c0 as f32 + k as f32 / 2.0
    };
    for by in 0..bh {
        for bx in 0..bw {
            let (mut sum, mut k, mut ok) = (0.0f32, 0u32, true);
            for cy in by * BLOCK_CELLS..((by + 1) * BLOCK_CELLS).min(ph) {
                for cx in bx * BLOCK_CELLS..((bx + 1) * BLOCK_CELLS).min(pw) {
                    let i = cy * pw + cx;
                    ok &= usable_at(i);
                    sum += f32::from(mean_dn.get(i).copied().unwrap_or(0)) - level;
                    k += 1;
                }
            }
            let m = if ok { sum / k.max(1) as f32 } else { f32::NAN };
            if let Some(slot) = scratch.get_mut(by * bw + bx) {
                *slot = m.to_bits();
            }
        }
    }
    if 2 * nb > n {
        // A plane of one row or column of cells: too small to fit.
        return None;
    }
    // `split_at_mut_checked`: no panic path (2 nb ≤ n = the scratch's length here).
    let (blocks, rest) = scratch.split_at_mut_checked(nb)?;
    let residuals = rest.get_mut(..nb)?;
    residuals.fill(0f32.to_bits());
    let mut coef = [0.0f32; TERMS];
    // Blocks within `trim` of the last surface are fitted (all usable ones at first).
    let mut trim = f32::INFINITY;
    // `max(1)`: no division by zero (a plane has a block per row).
    let bw = bw.max(1);
    let basis_of = |b: usize| basis(centre(b % bw, pw), centre(b / bw, ph), plane);
    // The normal equations of every usable block (the lower triangle): those of the
    // whole grid of blocks, a product of one-dimensional sums (the basis is a product
    // of a polynomial across and one down), less the unusable blocks'; the right-hand
    // side over the usable blocks.
    let grid_sums = |count: usize, cells: usize, side: usize| {
        let mut sums = [[0.0f32; DEGREE + 1]; DEGREE + 1];
        for c in 0..count {
            let p = legendre(2.0 * centre(c, cells) / side as f32 - 1.0);
            for (row, &pi) in sums.iter_mut().zip(&p) {
                for (a, &pk) in row.iter_mut().zip(&p) {
                    *a += pi * pk;
                }
            }
        }
        sums
    };
    let (across, down) = (grid_sums(bw, pw, pw), grid_sums(bh, ph, ph));
    let mut ata_all = [[0.0f32; TERMS]; TERMS];
    // (`get`: the powers are at most `DEGREE`; no panic path.)
    let at = |sums: &[[f32; DEGREE + 1]; DEGREE + 1], a: usize, b: usize| {
        sums.get(a).and_then(|r| r.get(b)).copied().unwrap_or(0.0)
    };
    for (row, &(i, j)) in ata_all.iter_mut().zip(&TERM_POWERS) {
        for (a, &(k, l)) in row.iter_mut().zip(&TERM_POWERS) {
            *a = at(&across, i, k) * at(&down, j, l);
        }
    }
    let (mut atb_all, mut used_all) = ([0.0f32; TERMS], 0usize);
    for (b, &m) in blocks.iter().enumerate() {
        let m = f32::from_bits(m);
        let basis = basis_of(b);
        if m.is_nan() {
            accumulate(&mut ata_all, &mut atb_all, &basis, 0.0, -1.0);
        } else {
            for (a, &bt) in atb_all.iter_mut().zip(&basis) {
                *a += bt * m;
            }
            used_all += 1;
        }
    }
    // The trimmed blocks' count and index sums of the last round: the same set again
    // gives the same surface (the rounds have converged).
    let mut last_trimmed = None;
    for _ in 0..FIT_ROUNDS {
        // The normal equations of this round's blocks: all usable blocks' less the
        // trimmed ones' (few: the target's), not a sum over the kept ones again.
        let (mut ata, mut atb) = (ata_all, atb_all);
        let mut trimmed = (0usize, 0u64, 0u64);
        for (b, (&m, &r)) in blocks.iter().zip(residuals.iter()).enumerate() {
            let (m, r) = (f32::from_bits(m), f32::from_bits(r));
            if m.is_nan() || libm::fabsf(r) <= trim {
                continue;
            }
            accumulate(&mut ata, &mut atb, &basis_of(b), -m, -1.0);
            trimmed = (
                trimmed.0 + 1,
                trimmed.1 + b as u64,
                trimmed.2 + (b * b) as u64,
            );
        }
        if last_trimmed == Some(trimmed) {
            break;
        }
        last_trimmed = Some(trimmed);
        if used_all.saturating_sub(trimmed.0) < 3 * TERMS {
            return None;
        }
        // The upper triangle mirrors the lower one (index loops: a transpose).
        #[allow(clippy::needless_range_loop)]
        for i in 0..TERMS {
            for j in i + 1..TERMS {
                ata[i][j] = ata[j][i];
            }
        }
        coef = solve(&mut ata, &atb)?;
        for (b, (&m, r)) in blocks.iter().zip(residuals.iter_mut()).enumerate() {
            let fit: f32 = basis_of(b).iter().zip(&coef).map(|(u, c)| u * c).sum();
            *r = (f32::from_bits(m) - fit).to_bits();
        }
        let spread = trimmed_spread(residuals, trim);
        // Far beyond the limit after a round (clouds): no later round comes back.
        if spread > EARLY_EXIT_FACTOR * limit {
            return None;
        }
        trim = TRIM_K * spread;
    }
    // The cells' residuals (NaN where not usable); their spread within the trim decides.
    // Row by row: the surface along a row is a polynomial across, its coefficients
    // the terms' summed down the row's `P_j`.
    for (cy, row) in scratch.chunks_mut(pw.max(1)).enumerate() {
        let pv = legendre(2.0 * (cy as f32 + 0.5) / ph as f32 - 1.0);
        let mut along = [0.0f32; DEGREE + 1];
        for (&c, &(i, j)) in coef.iter().zip(&TERM_POWERS) {
            if let (Some(a), Some(&v)) = (along.get_mut(i), pv.get(j)) {
                *a += c * v;
            }
        }
        for (cx, slot) in row.iter_mut().enumerate() {
            let i = cy * pw + cx;
            let r = if usable_at(i) {
                let pu = legendre(2.0 * (cx as f32 + 0.5) / pw as f32 - 1.0);
                let fit: f32 = along.iter().zip(&pu).map(|(a, u)| a * u).sum();
                f32::from(mean_dn.get(i).copied().unwrap_or(0)) - level - fit
            } else {
                f32::NAN
            };
            *slot = r.to_bits();
        }
    }
    let spread_dn = trimmed_spread(scratch, trim);
    // A NaN spread (no cell left) is no deep space either.
    if spread_dn.is_nan() || spread_dn > limit {
        return None;
    }
    let threshold = (OUTLIER_K * spread_dn).max(sigma);
    let weak = (WEAK_K * spread_dn).max(0.5 * sigma).min(threshold);
    // A cell's code from its residual (NaN: not usable, 0).
    let code_of = |r: u32| -> u8 {
        let r = libm::fabsf(f32::from_bits(r));
        if r.is_nan() {
            0
        } else if r > threshold {
            (1.0 + r / threshold).clamp(2.0, 255.0) as u8
        } else if r > weak {
            WEAK_CODE
        } else {
            0
        }
    };
    let outliers = scratch.iter().filter(|&&r| code_of(r) > WEAK_CODE).count();
    if outliers * 1000 > MAX_OUTLIER_PERMILLE * n {
        return None;
    }
    for (c, &r) in plane_codes.iter_mut().zip(scratch.iter()) {
        *c = code_of(r);
    }
    Some(DeepSpace {
        spread_dn,
        outliers,
    })
}

/// Adds `sign` · basis basisᵀ to the lower triangle of `ata` and `m` · basis to `atb`
/// (`m` carries the sign too).
fn accumulate(
    ata: &mut [[f32; TERMS]; TERMS],
    atb: &mut [f32; TERMS],
    basis: &[f32; TERMS],
    m: f32,
    sign: f32,
) {
    for (i, (row, t)) in ata.iter_mut().zip(atb.iter_mut()).enumerate() {
        let bi = sign * basis[i];
        for (a, &bj) in row.iter_mut().zip(basis).take(i + 1) {
            *a += bi * bj;
        }
        *t += basis[i] * m;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// xorshift32 noise, uniform in ±`amp` DN.
    fn noise(seed: &mut u32, amp: f32) -> f32 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 17;
        *seed ^= *seed << 5;
        (*seed % 10_000) as f32 / 10_000.0 * 2.0 * amp - amp
    }

    /// A 41×31 cell plane: a radial shading (dark centre, +80 DN at the corners) on a
    /// 1 000 DN pedestal with cell noise, and optionally a 6×5-cell target +40 DN.
    fn plane(target: bool, clouds: bool) -> (Vec<u16>, Vec<u8>) {
        let (pw, ph) = (41usize, 31usize);
        let mut seed = 0x1234_5678u32;
        let mut mean = Vec::new();
        for cy in 0..ph {
            for cx in 0..pw {
                let (u, v) = (
                    cx as f32 / pw as f32 * 2.0 - 1.0,
                    cy as f32 / ph as f32 * 2.0 - 1.0,
                );
                let mut m = 1000.0 + 40.0 * (u * u + v * v) + noise(&mut seed, 0.4);
                if target && (10..16).contains(&cx) && (8..13).contains(&cy) {
                    m += 40.0;
                }
                if clouds {
                    // Cloud cells: ±60 DN patches every few cells.
                    m += 60.0 * libm::sinf(cx as f32 * 1.3) * libm::cosf(cy as f32 * 0.9);
                }
                mean.push(m.round() as u16);
            }
        }
        let sat = std::vec![0u8; pw * ph];
        (mean, sat)
    }

    /// Deep space with a target: the surface takes the shading, exactly the target's
    /// 30 cells depart.
    #[test]
    fn the_target_departs_from_a_shaded_sky() {
        let (mean, sat) = plane(true, false);
        let mut scratch = std::vec![0u32; mean.len()];
        let mut codes = sat.clone();
        let seen =
            deep_space_codes(&mean, &mut codes, (41, 31), 4, &mut scratch).expect("deep space");
        assert_eq!(seen.outliers, 30);
        for cy in 0..31 {
            for cx in 0..41 {
                let target = (10..16).contains(&cx) && (8..13).contains(&cy);
                let code = codes[cy * 41 + cx];
                // Target cells above the weak code, every other cell 0 (no weak ones
                // in this noise).
                assert_eq!(code > WEAK_CODE, target, "cell ({cx}, {cy})");
                assert!(target || code == 0, "cell ({cx}, {cy}): {code}");
            }
        }
        assert!(seen.spread_dn < 0.6 * 4.0, "{seen:?}");
    }

    /// Without a target nothing departs; clouds are not deep space; a frame clipped
    /// at 0 has nothing to fit; short planes are no answer.
    #[test]
    fn no_target_clouds_and_clipped_frames() {
        let (mean, sat) = plane(false, false);
        let mut scratch = std::vec![0u32; mean.len()];
        let mut codes = sat.clone();
        let seen =
            deep_space_codes(&mean, &mut codes, (41, 31), 4, &mut scratch).expect("deep space");
        assert_eq!(seen.outliers, 0);
        assert!(codes.iter().all(|&c| c == 0));
        // Not deep space: the saturated counts stay (here 7 in every cell).
        let (mean, _) = plane(true, true);
        let mut counts = std::vec![7u8; mean.len()];
        assert_eq!(
            deep_space_codes(&mean, &mut counts, (41, 31), 4, &mut scratch),
            None
        );
        assert!(counts.iter().all(|&c| c == 7));
        let mut counts = std::vec![0u8; mean.len()];
        assert_eq!(
            deep_space_codes(&mean, &mut counts, (41, 31), 4, &mut scratch),
            None
        );
        let clipped = std::vec![0u16; mean.len()];
        assert_eq!(
            deep_space_codes(&clipped, &mut counts, (41, 31), 4, &mut scratch),
            None
        );
        assert_eq!(
            deep_space_codes(&mean[..10], &mut counts, (41, 31), 4, &mut scratch),
            None
        );
    }

    /// The Cholesky solve against a system with a known answer.
    #[test]
    fn solve_recovers_a_known_answer() {
        let mut m = [[0.0f32; TERMS]; TERMS];
        let want: [f32; TERMS] = core::array::from_fn(|i| i as f32 - 7.0);
        for (i, row) in m.iter_mut().enumerate() {
            for (j, a) in row.iter_mut().enumerate() {
                *a = if i == j {
                    4.0
                } else {
                    1.0 / (1.0 + (i + j) as f32)
                };
            }
        }
        let rhs: [f32; TERMS] =
            core::array::from_fn(|i| (0..TERMS).map(|j| m[i][j] * want[j]).sum());
        let x = solve(&mut m, &rhs).expect("positive definite");
        for (a, b) in x.iter().zip(&want) {
            assert!((a - b).abs() < 1e-4, "{x:?}");
        }
    }
}
