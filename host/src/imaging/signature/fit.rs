//! The fit of a sensor signature on one frame: smooth shading (a 2-D polynomial),
//! column and row patterns, a cell-scale field, outlier (hot and dead) pixels, and the
//! per-pixel residual.
//!
//! The same code measures the calibration frame and the synthetic realisations, so the
//! tests compare like with like.

use serde::{Deserialize, Serialize};

/// Degree of the smooth shading polynomial Σ c_ij·xⁱ·yʲ (i + j ≤ 4, 15 terms) in the
/// coordinates x, y ∈ (−1, 1) of the area: enough for the radial bowl of the TIR's own
/// optics/shutter emission (r² and r⁴ terms) and a tilt, too few to follow the column
/// pattern (328 columns against 5 powers of x).
pub const SHADING_DEGREE: usize = 4;

/// Terms of the shading polynomial, (D + 1)(D + 2)/2.
pub const SHADING_TERMS: usize = (SHADING_DEGREE + 1) * (SHADING_DEGREE + 2) / 2;

/// Threshold of an outlier pixel, in robust σ of the pixel residual (1.4826·MAD). For
/// a Gaussian residual the one-sided tail beyond 5σ is 2.9·10⁻⁷, i.e. 0.02 false hot
/// pixels in the 81 344 pixels of a frame: every pixel counted is a real defect.
pub const OUTLIER_K_SIGMA: f64 = 5.0;

/// Pixels farther than this many robust σ from the first shading fit are left out of
/// the second (so that hot pixels do not pull the smooth surface).
const SHADING_CLIP_K_SIGMA: f64 = 5.0;

/// Largest lag of the residual's autocorrelation the field is fitted on, px. On the
/// real dark frame the autocorrelation of what the shading and line fits leave falls to
/// 0 near 48 px (lag 48: 0.0 of lag 1's; lag 32: 0.40), so 1..=48 spans the whole
/// correlated part without fitting the negative lobe the polynomial leaves beyond.
pub const FIELD_MAX_LAG_PX: usize = 48;

/// Candidate correlation lengths of the field's fit, log-spaced from 0.5 px to the
/// frame's larger side: 400 steps are 1.5 % apart on a 328-px frame (finer than the
/// fit's scatter between realisations, about 5 %).
const FIELD_LENGTH_STEPS: usize = 400;

/// MAD → σ of a Gaussian.
const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// What [`fit_frame`] measures, DN of the frame it was given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameFit {
    /// Width of the fitted area, px.
    pub width: usize,
    /// Height of the fitted area, px.
    pub height: usize,
    /// The smooth shading.
    pub shading: Shading,
    /// Column pattern: the median of each column of the residual.
    pub columns: LinePattern,
    /// Row pattern: the median of each row of the residual less the column pattern.
    pub rows: LinePattern,
    /// The spatially correlated part of what is left (cell-scale structure).
    pub field: FieldPattern,
    /// The per-pixel residual and its outliers.
    pub pixels: PixelResidual,
}

/// The smooth shading: a polynomial of degree [`SHADING_DEGREE`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shading {
    /// Coefficients c_ij of xⁱyʲ, DN, ordered by total degree then by the power of y
    /// (1, x, y, x², xy, y², x³, ...), x = (2·col + 1)/width − 1, y likewise with rows.
    pub coefficients_dn: Vec<f64>,
    /// Mean of the frame over the area, DN.
    pub mean_dn: f64,
    /// Amplitude: 99th minus 1st percentile of the smooth surface over the area, DN.
    pub amplitude_dn: f64,
    /// Largest minus smallest value of the smooth surface, DN.
    pub range_dn: f64,
    /// Smallest value of the smooth surface, DN.
    pub min_dn: f64,
    /// Largest value of the smooth surface, DN.
    pub max_dn: f64,
    /// Where the smallest value is, [column, row] of the area, px.
    pub min_at_px: [usize; 2],
    /// Where the largest value is, [column, row] of the area, px.
    pub max_at_px: [usize; 2],
}

/// A pattern along one axis (a value per column or per row).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinePattern {
    /// Standard deviation of the per-line values, DN.
    pub sigma_dn: f64,
    /// Lag-1 autocorrelation of the per-line values (neighbouring columns or rows).
    pub lag1_correlation: f64,
}

/// The correlated part of the residual after shading, column and row patterns: a
/// Gaussian autocorrelation C(L) = σ²·exp(−(L/ℓ)²) fitted by least squares to the
/// residual's autocorrelation at lags 1..=[`FIELD_MAX_LAG_PX`] along rows and columns
/// (lag 0 holds the white per-pixel part as well, so it is left out). On the real dark
/// frame this is structure at 10–50 px that a detector's 8-px cells see as a 1-σ
/// texture over deep space.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldPattern {
    /// σ of the field, DN (0 when the residual is uncorrelated).
    pub sigma_dn: f64,
    /// Correlation length ℓ, px (the lag at which the correlation is 1/e), as measured
    /// after the shading and line fits (which take the field's longest scales out).
    pub correlation_length_px: f64,
}

/// The residual after shading, column and row patterns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PixelResidual {
    /// Robust σ of the residual (1.4826·MAD), DN.
    pub sigma_dn: f64,
    /// Outlier threshold, in `sigma_dn` ([`OUTLIER_K_SIGMA`]).
    pub outlier_k_sigma: f64,
    /// Pixels above +k·σ.
    pub hot_count: usize,
    /// Their residuals, DN, descending.
    pub hot_amplitudes_dn: Vec<f64>,
    /// Pixels below −k·σ.
    pub dead_count: usize,
    /// Their residuals, DN, ascending (most negative first).
    pub dead_amplitudes_dn: Vec<f64>,
}

/// The fit's per-pixel products (for the correlation check and the previews).
#[derive(Debug, Clone, PartialEq)]
pub struct FitMaps {
    /// The smooth shading, DN, row-major.
    pub smooth_dn: Vec<f64>,
    /// Frame minus the smooth shading, DN, row-major.
    pub residual_dn: Vec<f64>,
}

/// Normalised coordinate of pixel `i` of `n`: the pixel centre in (−1, 1).
pub fn norm_coord(i: f64, n: usize) -> f64 {
    (2.0 * i + 1.0) / n as f64 - 1.0
}

/// The monomials xⁱyʲ of the shading polynomial at (x, y), in the order of
/// [`Shading::coefficients_dn`].
pub fn shading_basis(x: f64, y: f64) -> [f64; SHADING_TERMS] {
    let mut out = [0.0; SHADING_TERMS];
    let mut k = 0;
    for d in 0..=SHADING_DEGREE {
        for j in 0..=d {
            out[k] = x.powi((d - j) as i32) * y.powi(j as i32);
            k += 1;
        }
    }
    out
}

/// Evaluates a shading polynomial at (x, y).
pub fn shading_at(c: &[f64], x: f64, y: f64) -> f64 {
    shading_basis(x, y).iter().zip(c).map(|(b, c)| b * c).sum()
}

/// Fits the signature model to a `width × height` frame (row-major DN).
///
/// # Errors
/// A message when the frame is smaller than 16 × 16, its length is not
/// `width × height`, a value is not finite, or the shading fit is singular.
pub fn fit_frame(
    frame: &[f64],
    width: usize,
    height: usize,
) -> Result<(FrameFit, FitMaps), String> {
    if width < 16 || height < 16 || frame.len() != width * height {
        return Err(format!(
            "signature fit: a {width} × {height} area of {} values: expected at least 16 × 16 and width × height values",
            frame.len()
        ));
    }
    if let Some(i) = frame.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "signature fit: pixel ({}, {}) = {}: expected finite values",
            i % width,
            i / width,
            frame[i]
        ));
    }
    let n = frame.len();
    let mean_dn = frame.iter().sum::<f64>() / n as f64;
    // Shading: least squares, then again without the pixels beyond 5 robust σ.
    let mut keep = vec![true; n];
    let mut coeffs = fit_poly(frame, width, height, &keep)?;
    let smooth0 = eval_poly(&coeffs, width, height);
    let r0: Vec<f64> = frame.iter().zip(&smooth0).map(|(v, s)| v - s).collect();
    let s0 = robust_sigma(&r0);
    for (k, r) in keep.iter_mut().zip(&r0) {
        *k = r.abs() <= SHADING_CLIP_K_SIGMA * s0;
    }
    coeffs = fit_poly(frame, width, height, &keep)?;
    let smooth = eval_poly(&coeffs, width, height);
    let residual: Vec<f64> = frame.iter().zip(&smooth).map(|(v, s)| v - s).collect();

    let (col, row) = line_medians(&residual, width, height);
    let e: Vec<f64> = (0..n)
        .map(|i| residual[i] - col[i % width] - row[i / width])
        .collect();
    let sigma = robust_sigma(&e);
    let thr = OUTLIER_K_SIGMA * sigma;
    let field = fit_field(&e, width, height, thr);
    let mut hot: Vec<f64> = e.iter().copied().filter(|&v| v > thr).collect();
    let mut dead: Vec<f64> = e.iter().copied().filter(|&v| v < -thr).collect();
    hot.sort_by(|a, b| b.total_cmp(a));
    dead.sort_by(f64::total_cmp);

    let (min_i, max_i) = smooth.iter().enumerate().fold((0, 0), |(lo, hi), (i, &v)| {
        (
            if v < smooth[lo] { i } else { lo },
            if v > smooth[hi] { i } else { hi },
        )
    });
    let mut sorted = smooth.clone();
    sorted.sort_by(f64::total_cmp);
    let pct = |p: f64| sorted[((p * (n - 1) as f64).round() as usize).min(n - 1)];
    let fit = FrameFit {
        width,
        height,
        shading: Shading {
            coefficients_dn: coeffs,
            mean_dn,
            amplitude_dn: pct(0.99) - pct(0.01),
            range_dn: smooth[max_i] - smooth[min_i],
            min_dn: smooth[min_i],
            max_dn: smooth[max_i],
            min_at_px: [min_i % width, min_i / width],
            max_at_px: [max_i % width, max_i / width],
        },
        columns: line_pattern(&col),
        rows: line_pattern(&row),
        field,
        pixels: PixelResidual {
            sigma_dn: sigma,
            outlier_k_sigma: OUTLIER_K_SIGMA,
            hot_count: hot.len(),
            hot_amplitudes_dn: hot,
            dead_count: dead.len(),
            dead_amplitudes_dn: dead,
        },
    };
    Ok((
        fit,
        FitMaps {
            smooth_dn: smooth,
            residual_dn: residual,
        },
    ))
}

/// The residual's field: autocorrelation of `e` clipped at ±`clip_dn` (so outliers do not
/// weigh), averaged over the row and column directions at each lag, and the Gaussian
/// [`FieldPattern`] that fits it best (σ² in closed form for each candidate ℓ).
pub fn fit_field(e: &[f64], width: usize, height: usize, clip_dn: f64) -> FieldPattern {
    let acf = autocorrelation(e, width, height, clip_dn);
    let none = FieldPattern {
        sigma_dn: 0.0,
        correlation_length_px: 0.0,
    };
    let top = width.max(height) as f64;
    let mut best: Option<(f64, f64, f64)> = None;
    for k in 0..=FIELD_LENGTH_STEPS {
        let l = 0.5 * (top / 0.5).powf(k as f64 / FIELD_LENGTH_STEPS as f64);
        let (mut cg, mut gg) = (0.0, 0.0);
        for (lag, &c) in acf.iter().enumerate().skip(1) {
            let g = (-(lag as f64 / l).powi(2)).exp();
            cg += c * g;
            gg += g * g;
        }
        if gg <= 0.0 {
            continue;
        }
        let s2 = cg / gg;
        let sse: f64 = acf
            .iter()
            .enumerate()
            .skip(1)
            .map(|(lag, &c)| (c - s2 * (-(lag as f64 / l).powi(2)).exp()).powi(2))
            .sum();
        if best.is_none_or(|(b, _, _)| sse < b) {
            best = Some((sse, s2, l));
        }
    }
    match best {
        Some((_, s2, l)) if s2 > 0.0 => FieldPattern {
            sigma_dn: s2.sqrt(),
            correlation_length_px: l,
        },
        _ => none,
    }
}

/// Autocorrelation (covariance, DN²) of the mean-removed `e` clipped at ±`clip_dn`, at
/// lags 0..=min([`FIELD_MAX_LAG_PX`], side − 1), the mean of the row and column
/// directions.
pub fn autocorrelation(e: &[f64], width: usize, height: usize, clip_dn: f64) -> Vec<f64> {
    let c: Vec<f64> = e.iter().map(|v| v.clamp(-clip_dn, clip_dn)).collect();
    let m = c.iter().sum::<f64>() / c.len().max(1) as f64;
    let c: Vec<f64> = c.iter().map(|v| v - m).collect();
    let lags = FIELD_MAX_LAG_PX.min(width.min(height).saturating_sub(1));
    (0..=lags)
        .map(|lag| {
            let (mut sx, mut sy) = (0.0, 0.0);
            for y in 0..height {
                let row = &c[y * width..(y + 1) * width];
                sx += row.iter().zip(&row[lag..]).map(|(a, b)| a * b).sum::<f64>();
                if y + lag < height {
                    let below = &c[(y + lag) * width..(y + lag + 1) * width];
                    sy += row.iter().zip(below).map(|(a, b)| a * b).sum::<f64>();
                }
            }
            let nx = (height * (width - lag)) as f64;
            let ny = (width * (height - lag)) as f64;
            0.5 * (sx / nx + sy / ny)
        })
        .collect()
}

/// The column pattern (the median of each column of `residual`) and the row pattern
/// (the median of each row less the column pattern), as [`fit_frame`] takes them out.
pub fn line_medians(residual: &[f64], width: usize, height: usize) -> (Vec<f64>, Vec<f64>) {
    let col: Vec<f64> = (0..width)
        .map(|x| median((0..height).map(|y| residual[y * width + x]).collect()))
        .collect();
    let row: Vec<f64> = (0..height)
        .map(|y| {
            median(
                (0..width)
                    .map(|x| residual[y * width + x] - col[x])
                    .collect(),
            )
        })
        .collect();
    (col, row)
}

/// Takes out of `v` (a `width × height` map, row-major) what [`fit_frame`] would fit
/// as shading and line patterns (one least-squares pass: the map has no outliers), so
/// that a synthetic field is left as the fit sees a real one.
///
/// # Errors
/// A message when the shading fit is singular.
pub fn remove_fitted_parts(v: &mut [f64], width: usize, height: usize) -> Result<(), String> {
    let coeffs = fit_poly(v, width, height, &vec![true; v.len()])?;
    for (x, s) in v.iter_mut().zip(eval_poly(&coeffs, width, height)) {
        *x -= s;
    }
    let (col, row) = line_medians(v, width, height);
    for (i, x) in v.iter_mut().enumerate() {
        *x -= col[i % width] + row[i / width];
    }
    Ok(())
}

/// σ and lag-1 autocorrelation of a sequence.
fn line_pattern(v: &[f64]) -> LinePattern {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64;
    let cov = v.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum::<f64>() / v.len() as f64;
    LinePattern {
        sigma_dn: var.sqrt(),
        lag1_correlation: if var > 0.0 { cov / var } else { 0.0 },
    }
}

/// The median (mean of the middle two for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    let n = v.len();
    if n == 0 {
        return 0.0;
    }
    let (lo, &mut mid, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    if n % 2 == 1 {
        mid
    } else {
        0.5 * (lo.iter().copied().fold(f64::NEG_INFINITY, f64::max) + mid)
    }
}

/// 1.4826 × the median absolute deviation from the median.
pub fn robust_sigma(v: &[f64]) -> f64 {
    let m = median(v.to_vec());
    MAD_TO_SIGMA * median(v.iter().map(|x| (x - m).abs()).collect())
}

/// Least-squares shading coefficients over the kept pixels (normal equations, solved
/// with partial pivoting; the monomials on (−1, 1) are well conditioned at degree 4).
///
/// The normal matrix is built from the moments Σ xᵖyᵠ (p, q ≤ 2D) accumulated row by
/// row, about 14 operations per pixel instead of the 120 of the outer products.
pub fn fit_poly(frame: &[f64], w: usize, h: usize, keep: &[bool]) -> Result<Vec<f64>, String> {
    const P: usize = 2 * SHADING_DEGREE + 1;
    let xp: Vec<[f64; P]> = (0..w).map(|x| powers(norm_coord(x as f64, w))).collect();
    // m[p][q] = Σ xᵖyᵠ; v[p][q] = Σ xᵖyᵠ·frame (p + q ≤ D).
    let mut m = [[0.0f64; P]; P];
    let mut v = [[0.0f64; P]; P];
    for y in 0..h {
        let yp = powers(norm_coord(y as f64, h));
        let (mut sx, mut bx) = ([0.0f64; P], [0.0f64; P]);
        let rows = xp
            .iter()
            .zip(&keep[y * w..(y + 1) * w])
            .zip(&frame[y * w..(y + 1) * w]);
        for ((px, &kept), &v) in rows {
            if !kept {
                continue;
            }
            for (s, &t) in sx.iter_mut().zip(px) {
                *s += t;
            }
            for (b, &t) in bx.iter_mut().zip(px).take(SHADING_DEGREE + 1) {
                *b += t * v;
            }
        }
        for p in 0..P {
            for q in 0..P {
                m[p][q] += sx[p] * yp[q];
            }
        }
        for p in 0..=SHADING_DEGREE {
            for q in 0..=SHADING_DEGREE - p {
                v[p][q] += bx[p] * yp[q];
            }
        }
    }
    // Term k ↔ (power of x, power of y), in the order of `shading_basis`.
    let mut terms = [(0usize, 0usize); SHADING_TERMS];
    let mut k = 0;
    for d in 0..=SHADING_DEGREE {
        for j in 0..=d {
            terms[k] = (d - j, j);
            k += 1;
        }
    }
    let mut a = [[0.0f64; SHADING_TERMS]; SHADING_TERMS];
    let mut b = [0.0f64; SHADING_TERMS];
    for (r, &(pr, qr)) in terms.iter().enumerate() {
        b[r] = v[pr][qr];
        for (c, &(pc, qc)) in terms.iter().enumerate() {
            a[r][c] = m[pr + pc][qr + qc];
        }
    }
    solve(a, b).ok_or_else(|| "signature fit: the shading fit is singular".to_string())
}

/// 1, t, t², ..., t^(2D).
fn powers(t: f64) -> [f64; 2 * SHADING_DEGREE + 1] {
    let mut out = [1.0; 2 * SHADING_DEGREE + 1];
    for k in 1..out.len() {
        out[k] = out[k - 1] * t;
    }
    out
}

/// The shading polynomial over a `w × h` grid, row-major.
pub fn eval_poly(c: &[f64], w: usize, h: usize) -> Vec<f64> {
    let xs: Vec<f64> = (0..w).map(|x| norm_coord(x as f64, w)).collect();
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let rc = row_coefficients(c, norm_coord(y as f64, h));
        out.extend(
            xs.iter()
                .map(|&x| rc.iter().rev().fold(0.0, |s, &k| s * x + k)),
        );
    }
    out
}

/// Coefficients of x⁰..x^D of the shading polynomial `c` on the row at `y`.
pub fn row_coefficients(c: &[f64], y: f64) -> [f64; SHADING_DEGREE + 1] {
    let mut rc = [0.0; SHADING_DEGREE + 1];
    let mut k = 0;
    for d in 0..=SHADING_DEGREE {
        for j in 0..=d {
            rc[d - j] += c[k] * y.powi(j as i32);
            k += 1;
        }
    }
    rc
}

/// Gaussian elimination with partial pivoting; `None` when singular.
fn solve(
    mut a: [[f64; SHADING_TERMS]; SHADING_TERMS],
    mut b: [f64; SHADING_TERMS],
) -> Option<Vec<f64>> {
    let n = SHADING_TERMS;
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..n {
            let f = a[r][col] / a[col][col];
            let pivot_row = a[col];
            for (x, &p) in a[r].iter_mut().zip(&pivot_row).skip(col) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|c| a[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame built from known parts: the fit must find them back.
    #[test]
    fn fit_recovers_a_known_polynomial_columns_and_hot_pixels() {
        let (w, h) = (120, 90);
        let c: Vec<f64> = (0..SHADING_TERMS)
            .map(|k| (k as f64 * 0.7).sin() * 40.0)
            .collect();
        let smooth = eval_poly(&c, w, h);
        // Alternating column offsets ±2 DN (σ 2, lag-1 correlation −1 less the edge).
        let mut f: Vec<f64> = (0..w * h)
            .map(|i| smooth[i] + if (i % w) % 2 == 0 { 2.0 } else { -2.0 })
            .collect();
        // A deterministic ±0.3 DN pixel texture (so the MAD is not 0).
        for (i, v) in f.iter_mut().enumerate() {
            *v += 0.3 * ((i as f64 * 12.9898).sin() * 43758.5453).fract();
        }
        f[10 * w + 7] += 500.0;
        f[50 * w + 99] += 300.0;
        f[70 * w + 30] -= 400.0;
        let (fit, maps) = fit_frame(&f, w, h).unwrap();
        assert_eq!(fit.pixels.hot_count, 2);
        assert_eq!(fit.pixels.dead_count, 1);
        assert!((fit.pixels.hot_amplitudes_dn[0] - 500.0).abs() < 2.0);
        assert!(
            (fit.columns.sigma_dn - 2.0).abs() < 0.1,
            "{:?}",
            fit.columns
        );
        assert!(fit.columns.lag1_correlation < -0.9);
        assert!(fit.rows.sigma_dn < 0.2, "{:?}", fit.rows);
        // The smooth part: within 0.5 DN of the truth everywhere.
        let worst = maps
            .smooth_dn
            .iter()
            .zip(&smooth)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.5, "{worst}");
    }
}
