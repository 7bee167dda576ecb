//! The noise field's Gaussian generator (`sensor::gaussian`, a 128-strip ziggurat):
//! its tables against their defining equations in f64, and 4 × 10⁶ draws against the
//! standard normal law (moments to the 4th, Kolmogorov–Smirnov, binned χ², 3 σ and
//! 4 σ tails, serial correlation).

use tirroi_core::sensor::gaussian::{
    LAYER_DENSITY, LAYER_UNIFORM_BOUND, LAYER_WIDTH_PER_UNIT, LAYERS, SIGNED_WIDTH_PER_UNIT,
    TAIL_START_F64, standard_normal,
};
use tirroi_core::sensor::rng::Xoshiro128pp;

const DRAWS: usize = 4_000_000;
const TWO_POW_24: f64 = 16_777_216.0;

fn density(x: f64) -> f64 {
    (-0.5 * x * x).exp()
}

/// Φ(x), the standard normal CDF (libm's erfc, relative error ~1e-16).
fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / core::f64::consts::SQRT_2)
}

fn draws(seed: u64) -> Vec<f64> {
    let mut rng = Xoshiro128pp::seed_from_u64(seed);
    (0..DRAWS)
        .map(|_| f64::from(standard_normal(&mut rng)))
        .collect()
}

/// Every strip's abscissa from the f32 tables.
fn edges() -> Vec<f64> {
    let mut x: Vec<f64> = LAYER_WIDTH_PER_UNIT
        .iter()
        .map(|&w| f64::from(w) * TWO_POW_24)
        .collect();
    x.push(0.0);
    x
}

#[test]
fn tables_satisfy_the_ziggurat_equations() {
    let r = TAIL_START_F64;
    // v = r f(r) + ∫_r^∞ f: the base strip's rectangle plus the tail, closed form.
    let v = r * density(r)
        + (core::f64::consts::PI / 2.0).sqrt() * libm::erfc(r / core::f64::consts::SQRT_2);
    let x = edges();
    assert!((x[1] / r - 1.0).abs() < 1e-7, "x1 {} vs r {r}", x[1]);
    // Base strip: x₀ f(r) = v.
    assert!((x[0] * density(r) / v - 1.0).abs() < 1e-6);
    // Strip i ≥ 1: xᵢ (f(xᵢ₊₁) − f(xᵢ)) = v, each strip the same area.
    for i in 1..LAYERS {
        let area = x[i] * (density(x[i + 1]) - density(x[i]));
        assert!(
            (area / v - 1.0).abs() < 2e-5,
            "strip {i}: area {area} vs {v}"
        );
    }
    // The top strip closes at the peak: v/x₁₂₇ + f(x₁₂₇) = 1.
    assert!((v / x[LAYERS - 1] + density(x[LAYERS - 1]) - 1.0).abs() < 1e-6);
    // Densities: 0 below strip 0, f(xᵢ) within f32 rounding, 1 at the peak.
    assert_eq!(LAYER_DENSITY[0], 0.0);
    assert_eq!(LAYER_DENSITY[LAYERS], 1.0);
    for i in 1..LAYERS {
        let f = f64::from(LAYER_DENSITY[i]);
        assert!((f / density(x[i]) - 1.0).abs() < 3e-7, "density {i}");
    }
    // Fast-accept bounds: ⌊2²⁴ xᵢ₊₁/xᵢ⌋ from the f64 abscissae (within 3 of the ratio of
    // the f32-rounded ones: 2 ulps of rounding + the floor), and the largest point the
    // fast path returns, computed as the generator does in f32, is not beyond xᵢ₊₁.
    for i in 0..LAYERS {
        let exact = TWO_POW_24 * x[i + 1] / x[i];
        let k = LAYER_UNIFORM_BOUND[i];
        assert!(
            (f64::from(k) - exact).abs() <= 3.0,
            "bound {i}: {k} vs {exact}"
        );
        if k > 0 {
            let last = f64::from((k - 1) as f32 * LAYER_WIDTH_PER_UNIT[i]);
            assert!(
                last <= x[i + 1] * (1.0 + 2.0 / TWO_POW_24),
                "strip {i}: {last}"
            );
        }
    }
    // The signed table the fast path reads: +width, then −width.
    for i in 0..LAYERS {
        assert_eq!(SIGNED_WIDTH_PER_UNIT[i], LAYER_WIDTH_PER_UNIT[i]);
        assert_eq!(SIGNED_WIDTH_PER_UNIT[LAYERS + i], -LAYER_WIDTH_PER_UNIT[i]);
    }
    // The fast path's share: the mean of the bounds, 97.2 % for 128 strips.
    let fast: f64 = LAYER_UNIFORM_BOUND
        .iter()
        .map(|&k| f64::from(k) / TWO_POW_24)
        .sum::<f64>()
        / LAYERS as f64;
    assert!(fast > 0.97, "fast path {fast}");
}

#[test]
fn moments_match_the_normal_law_to_the_fourth() {
    let z = draws(1);
    let n = z.len() as f64;
    let mean = z.iter().sum::<f64>() / n;
    let m = |p: i32| z.iter().map(|v| (v - mean).powi(p)).sum::<f64>() / n;
    let (var, m3, m4) = (m(2), m(3), m(4));
    let skew = m3 / var.powf(1.5);
    let excess = m4 / (var * var) - 3.0;
    // Standard errors of the sample moments of N(0, 1): 1/√n, √(2/n), √(6/n), √(24/n);
    // 5 of them is a 6e-7 two-sided chance for a correct generator.
    let k = 5.0;
    assert!(mean.abs() < k / n.sqrt(), "mean {mean}");
    assert!((var - 1.0).abs() < k * (2.0 / n).sqrt(), "variance {var}");
    assert!(skew.abs() < k * (6.0 / n).sqrt(), "skewness {skew}");
    assert!(
        excess.abs() < k * (24.0 / n).sqrt(),
        "excess kurtosis {excess}"
    );
}

#[test]
fn kolmogorov_smirnov_and_chi_square_accept_the_normal_law() {
    let mut z = draws(2);
    let n = z.len() as f64;
    z.sort_by(f64::total_cmp);
    let d = z
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let f = normal_cdf(v);
            (f - i as f64 / n).abs().max(((i + 1) as f64 / n - f).abs())
        })
        .fold(0.0, f64::max);
    // Kolmogorov's limit law: P(√n D > 1.95) = 0.001.
    assert!(d * n.sqrt() < 1.95, "KS statistic √n D = {}", d * n.sqrt());

    // χ² over 0.1 σ bins on [−5, 5] plus the two tails: 102 bins, 101 degrees of freedom.
    let bins = 100;
    let lo = -5.0;
    let width = 0.1;
    let mut counts = vec![0u64; bins + 2];
    for &v in &z {
        let b = if v < lo {
            0
        } else {
            (((v - lo) / width) as usize + 1).min(bins + 1)
        };
        counts[b] += 1;
    }
    let edge = |b: usize| lo + width * b as f64;
    let chi2: f64 = (0..bins + 2)
        .map(|b| {
            let p = match b {
                0 => normal_cdf(lo),
                b if b == bins + 1 => 1.0 - normal_cdf(edge(bins)),
                b => normal_cdf(edge(b)) - normal_cdf(edge(b - 1)),
            };
            let e = p * n;
            (counts[b] as f64 - e).powi(2) / e
        })
        .sum();
    let dof = (bins + 1) as f64;
    // 99.9th percentile of χ²(101) by Wilson–Hilferty: 149.
    let q = dof * (1.0 - 2.0 / (9.0 * dof) + 3.09 * (2.0 / (9.0 * dof)).sqrt()).powi(3);
    assert!(chi2 < q, "χ² {chi2} over {dof} dof (99.9 % point {q})");
}

#[test]
fn tails_at_3_and_4_sigma_have_the_normal_probability() {
    let z = draws(3);
    let n = z.len() as f64;
    for k in [3.0, 4.0, 4.5] {
        let p = libm::erfc(k / core::f64::consts::SQRT_2);
        let count = z.iter().filter(|v| v.abs() > k).count() as f64;
        let expected = p * n;
        // Binomial σ = √(n p (1 − p)); 5 σ apart is a 6e-7 chance.
        let sd = (n * p * (1.0 - p)).sqrt();
        assert!(
            (count - expected).abs() < 5.0 * sd,
            "P(|z| > {k}): {count} draws vs {expected:.1} ± {sd:.1}"
        );
    }
    // The tail sampler reaches beyond the last strip (Box–Muller's 24-bit cut was 5.77).
    assert!(z.iter().any(|v| v.abs() > 4.5));
}

#[test]
fn draws_are_uncorrelated_and_seeded() {
    let z = draws(4);
    let n = z.len() as f64;
    for lag in [1, 2, 328] {
        let c = z.iter().zip(&z[lag..]).map(|(a, b)| a * b).sum::<f64>() / (n - lag as f64);
        assert!(c.abs() < 5.0 / n.sqrt(), "lag {lag} correlation {c}");
    }
    // Sign against magnitude (the same 32-bit draw): independent.
    let c = z
        .iter()
        .map(|v| v.signum() * (v.abs() - 0.797_884_6))
        .sum::<f64>()
        / n;
    assert!(c.abs() < 5.0 * 0.6028 / n.sqrt(), "sign-magnitude {c}");
    let mut a = Xoshiro128pp::seed_from_u64(9);
    let mut b = Xoshiro128pp::seed_from_u64(9);
    let mut c2 = Xoshiro128pp::seed_from_u64(10);
    let (mut same, mut differ) = (true, false);
    for _ in 0..10_000 {
        let (x, y, w) = (
            standard_normal(&mut a),
            standard_normal(&mut b),
            standard_normal(&mut c2),
        );
        same &= x.to_bits() == y.to_bits();
        differ |= x != w;
    }
    assert!(same && differ);
}
