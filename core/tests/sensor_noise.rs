//! Noise model: Table 2 from Table 1 (paper Eqs. 11–14), Eq. 16's ADU figure, the NVD of
//! Eq. 15, the three noise levels, and the statistics of the seeded noise field.

use tirroi_core::sensor::expose_frame;
use tirroi_core::sensor::noise::{
    ADC_GAIN_ADU_PER_V, BOLTZMANN_J_K, DEFAULT_FLICKER_CORRELATION_PX, NoiseRms,
};
use tirroi_core::sensor::{
    BandRadiance, BolometerParams, DnMapping, NoiseField, NoiseLevel, NoiseSigmas, RmsReading,
};

const W: usize = 328;
const H: usize = 248;

/// `x` rounded to four significant digits, as Table 2 prints them.
fn sig4(x: f64) -> f64 {
    let e = x.abs().log10().floor();
    let s = 10f64.powf(3.0 - e);
    (x * s).round() / s
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn table2_from_table1() {
    let p = BolometerParams::TABLE1;
    // v_1/f: Eq. 13 as printed reproduces Table 2.
    assert_eq!(sig4(p.flicker_rms_v()), 5.322e-6);
    // v_th: the standard formula gives Table 2's digits a decade lower; the reading
    // √(k T² v_b β²/(4 G t_int)) gives the printed value.
    assert_eq!(sig4(p.thermal_rms_v()), 2.617e-7);
    let v_th_table2 = (BOLTZMANN_J_K * p.t_bolometer_k.powi(2) * p.v_bias_v * p.beta_per_k.powi(2)
        / (4.0 * p.g_th_w_k * p.t_int_s))
        .sqrt();
    assert_eq!(sig4(v_th_table2), 2.617e-6);
    // Eq. 14 exactly as printed.
    assert_eq!(sig4(p.thermal_rms_as_printed_v()), 2.747e-8);
    // v_J: Eq. 11 as printed (Δf_J = 1/(2τ)) and with Δf_J = 1/(2 t_int); neither is
    // Table 2's 5.394e-6 (no reading found, REFERENCE.md §1).
    assert_eq!(sig4(p.johnson_rms_v(1.0 / (2.0 * p.tau_s))), 1.175e-7);
    assert_eq!(sig4(p.johnson_rms_v(p.high_frequency_hz())), 5.255e-6);
    assert!(rel(p.johnson_rms_v(p.high_frequency_hz()), 5.394e-6) > 0.02);

    let t2 = p.rms(RmsReading::Table2);
    assert_eq!(t2, NoiseRms::TABLE2);
    let printed = p.rms(RmsReading::AsPrinted);
    assert_eq!(sig4(printed.johnson_v), 1.175e-7);
    assert_eq!(sig4(printed.thermal_v), 2.747e-8);
    let phys = p.rms(RmsReading::Physical);
    assert_eq!(sig4(phys.johnson_v), 5.255e-6);
    assert_eq!(sig4(phys.flicker_v), 5.322e-6);
    assert_eq!(sig4(phys.thermal_v), 2.617e-7);

    // Eq. 16: Table 2 in ADU is 0.0198, far below one DN.
    assert!(rel(t2.total_v(), 8.01671e-6) < 1e-5);
    assert!(rel(ADC_GAIN_ADU_PER_V * t2.total_v(), 0.019801) < 1e-4);
    assert!(p.validate().is_ok());
}

#[test]
fn nvd_falls_to_the_johnson_floor() {
    let p = BolometerParams::TABLE1;
    let floor = (4.0 * BOLTZMANN_J_K * p.t_bolometer_k * p.r_bolometer_ohm).sqrt();
    assert!(rel(floor, 1.82e-8) < 0.01);
    let mut last = f64::INFINITY;
    for k in 0..=80 {
        let bw = 10f64.powf(k as f64 / 10.0); // 1 Hz .. 100 MHz
        let nvd = p.nvd_v_per_sqrt_hz(bw);
        assert!(nvd.is_finite() && nvd > 0.0);
        assert!(nvd < last, "NVD must fall with bandwidth: {bw} Hz");
        assert!(nvd >= floor);
        last = nvd;
    }
    // Slope: flicker-dominated at low Δf, "order of 1e-8" at high Δf.
    assert!(p.nvd_v_per_sqrt_hz(1.0) > 50.0 * floor);
    assert!(rel(p.nvd_v_per_sqrt_hz(1e8), floor) < 0.01);
    // Over the readout band [f_L, f_H] the NVD integrates back to Eqs. 11, 13 and the
    // standard thermal formula (whose Lorentzian integrates to 1/(4τ)).
    let band = p.high_frequency_hz() - p.f_low_hz;
    let v2 = p.nvd_v_per_sqrt_hz(band).powi(2) * band;
    let want =
        p.johnson_rms_v(band).powi(2) + p.flicker_rms_v().powi(2) + p.thermal_rms_v().powi(2);
    assert!(rel(v2, want) < 1e-3, "{v2} vs {want}");
    assert_eq!(p.nvd_v_per_sqrt_hz(0.0), 0.0);
    assert_eq!(p.nvd_v_per_sqrt_hz(f64::NAN), 0.0);
}

fn tir_mapping(bits: u8) -> (BandRadiance, DnMapping) {
    let band = BandRadiance::hayabusa2_tir();
    let f = |t: f64| band.emissive_power_w_m2(t, 1.0).unwrap();
    let m = DnMapping::radiometry_auto(f(150.0), f(460.0), bits).unwrap();
    (band, m)
}

#[test]
fn noise_levels() {
    let (band, m) = tir_mapping(14);
    let rms = NoiseRms::TABLE2;
    let lit = NoiseLevel::PaperLiteral.sigmas(&rms, &m).unwrap();
    assert!(rel(f64::from(lit.total_dn()), 0.019801) < 1e-4);
    let vis = NoiseLevel::PaperVisible.sigmas(&rms, &m).unwrap();
    assert!(rel(f64::from(vis.total_dn()), 0.019801 * 16383.0) < 1e-4);
    let dn_per_k = m.dn_per_kelvin(&band, 300.0, std::f64::consts::PI).unwrap();
    let netd = NoiseLevel::Netd {
        netd_k: 0.4,
        dn_per_k,
    }
    .sigmas(&rms, &m)
    .unwrap();
    assert!(rel(f64::from(netd.total_dn()), 0.4 * dn_per_k) < 1e-6);
    // The sources keep Table 2's proportions.
    assert!(rel(f64::from(netd.johnson_dn / netd.flicker_dn), 5.394 / 5.322) < 1e-6);
    assert!(
        NoiseLevel::Netd {
            netd_k: f64::NAN,
            dn_per_k
        }
        .sigmas(&rms, &m)
        .is_err()
    );
}

fn field_frame(sigmas: NoiseSigmas, corr: f32, seed: u64) -> Vec<f32> {
    let mut f = NoiseField::new(sigmas, corr, W, seed).unwrap();
    let mut out = Vec::with_capacity(W * H);
    for _ in 0..H {
        out.extend(f.next_row());
    }
    out
}

fn mean_std(v: &[f32]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let var = v
        .iter()
        .map(|&x| (f64::from(x) - mean).powi(2))
        .sum::<f64>()
        / (n - 1.0);
    (mean, var.sqrt())
}

/// Mean power of the row spectra in the lowest (k = 1..=16) and highest (k = 100..=164)
/// frequency bins, by a direct DFT of every row.
fn low_high_power(v: &[f32]) -> (f64, f64) {
    let mut power = vec![0.0f64; W / 2 + 1];
    for row in v.chunks_exact(W) {
        for (k, p) in power.iter_mut().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            for (x, &s) in row.iter().enumerate() {
                let a = std::f64::consts::TAU * (k * x) as f64 / W as f64;
                re += f64::from(s) * a.cos();
                im -= f64::from(s) * a.sin();
            }
            *p += re * re + im * im;
        }
    }
    let low = power[1..=16].iter().sum::<f64>() / 16.0;
    let high = power[100..=164].iter().sum::<f64>() / 65.0;
    (low, high)
}

#[test]
fn each_source_has_its_sigma_and_spectrum() {
    let one = |j: f32, f: f32, t: f32| NoiseSigmas {
        johnson_dn: j,
        flicker_dn: f,
        thermal_dn: t,
    };
    let n = (W * H) as f64;
    for (name, s, corr_tol) in [
        ("johnson", one(12.0, 0.0, 0.0), 1.0),
        ("thermal", one(0.0, 0.0, 5.0), 1.0),
        (
            "flicker",
            one(0.0, 9.0, 0.0),
            2.0 * f64::from(DEFAULT_FLICKER_CORRELATION_PX),
        ),
    ] {
        let v = field_frame(s, DEFAULT_FLICKER_CORRELATION_PX, 42);
        let sigma = f64::from(s.total_dn());
        let (mean, std) = mean_std(&v);
        // Standard error of the mean, widened by the correlation length for 1/f.
        let se = sigma * corr_tol / n.sqrt();
        assert!(mean.abs() < 5.0 * se, "{name}: mean {mean}, se {se}");
        let tol = if name == "flicker" { 0.06 } else { 0.015 };
        assert!(rel(std, sigma) < tol, "{name}: std {std} vs {sigma}");
        let (low, high) = low_high_power(&v);
        if name == "flicker" {
            assert!(
                low > 10.0 * high,
                "{name}: spectrum must fall: {low} vs {high}"
            );
        } else {
            let r = low / high;
            assert!((0.8..1.25).contains(&r), "{name}: white spectrum ratio {r}");
        }
    }
}

#[test]
fn field_is_deterministic_for_a_seed() {
    let s = NoiseSigmas {
        johnson_dn: 3.0,
        flicker_dn: 2.0,
        thermal_dn: 1.0,
    };
    let a = field_frame(s, 4.0, 7);
    assert_eq!(a, field_frame(s, 4.0, 7));
    assert_ne!(a, field_frame(s, 4.0, 8));
    let silent = NoiseField::new(NoiseSigmas::default(), 4.0, W, 1).unwrap();
    assert!(silent.is_silent());
    assert!(NoiseField::new(s, 4.0, 0, 1).is_err());
    assert!(NoiseField::new(s, 4.0, 329, 1).is_err());
    assert!(NoiseField::new(s, f32::NAN, W, 1).is_err());
}

#[test]
fn netd_level_gives_0_4_k_of_temperature_noise() {
    // A uniform 300 K scene through radiometry mode with the netd level: the
    // temperatures read back from the DN scatter by 0.4 K.
    let (band, m) = tir_mapping(14);
    let dn_per_k = m.dn_per_kelvin(&band, 300.0, std::f64::consts::PI).unwrap();
    let s = NoiseLevel::Netd {
        netd_k: 0.4,
        dn_per_k,
    }
    .sigmas(&NoiseRms::TABLE2, &m)
    .unwrap();
    let f300 = band.emissive_power_w_m2(300.0, 1.0).unwrap() as f32;
    let signal = vec![f300; W * H];
    let mut out = vec![0u16; W * H];
    let mut field = NoiseField::new(s, 4.0, W, 3).unwrap();
    expose_frame(&signal, W, &m, Some(&mut field), &mut out).unwrap();
    // Invert each distinct DN once.
    let mut t_of_dn = std::collections::HashMap::new();
    let temps: Vec<f32> = out
        .iter()
        .map(|&dn| {
            *t_of_dn.entry(dn).or_insert_with(|| {
                m.radiometric_temperature_k(f64::from(dn), &band, 1.0)
                    .unwrap() as f32
            })
        })
        .collect();
    let (mean, std) = mean_std(&temps);
    assert!((mean - 300.0).abs() < 0.05, "mean {mean}");
    assert!(rel(std, 0.4) < 0.05, "NETD {std} K");
}

#[test]
fn literal_noise_vanishes_in_quantisation_and_frames_saturate() {
    let m = DnMapping::new(1.0, 0.0, 14).unwrap();
    let lit = NoiseLevel::PaperLiteral
        .sigmas(&NoiseRms::TABLE2, &m)
        .unwrap();
    let mut field = NoiseField::new(lit, 4.0, W, 9).unwrap();
    let mut out = vec![0u16; W * H];
    expose_frame(&vec![100.3f32; W * H], W, &m, Some(&mut field), &mut out).unwrap();
    assert!(
        out.iter().all(|&d| d == 100),
        "0.02 DN of noise never moves 100.3 DN"
    );

    // Saturation at both ends with loud noise: never wraps.
    let loud = NoiseSigmas {
        johnson_dn: 500.0,
        flicker_dn: 500.0,
        thermal_dn: 0.0,
    };
    let mut field = NoiseField::new(loud, 4.0, W, 9).unwrap();
    let mut signal = vec![16383.0f32; W * H];
    signal[..W * H / 2].fill(0.0);
    signal[0] = f32::NAN;
    signal[1] = f32::INFINITY;
    signal[2] = f32::NEG_INFINITY;
    expose_frame(&signal, W, &m, Some(&mut field), &mut out).unwrap();
    assert!(out.iter().all(|&d| d <= 16383));
    assert_eq!(out[1], 16383);
    assert_eq!(out[2], 0);
    assert!(out[W * H / 2..].contains(&16383) && out[..W * H / 2].contains(&0));

    // Sizes are checked.
    let mut short = vec![0u16; 10];
    assert!(expose_frame(&signal, W, &m, None::<&mut NoiseField>, &mut short).is_err());
    assert!(expose_frame(&signal, 0, &m, None::<&mut NoiseField>, &mut out).is_err());
    assert!(
        expose_frame(
            &signal[..W * H - 1],
            W,
            &m,
            None::<&mut NoiseField>,
            &mut out[..W * H - 1]
        )
        .is_err()
    );
    let mut narrow = NoiseField::new(loud, 4.0, 100, 9).unwrap();
    assert!(expose_frame(&signal, W, &m, Some(&mut narrow), &mut out).is_err());
}

/// The frame of [`field_frame`] through the flight path's loop
/// ([`NoiseField::combine_row`], combining with a zero signal) instead of the row
/// iterator.
fn field_frame_fast(sigmas: NoiseSigmas, corr: f32, seed: u64) -> Vec<f32> {
    let mut f = NoiseField::new(sigmas, corr, W, seed).unwrap();
    let zero = [0.0f32; W];
    let mut out = vec![f32::NAN; W * H];
    for row in out.chunks_exact_mut(W) {
        f.combine_row(&zero, row, |s, n| s + n);
    }
    out
}

#[test]
fn flight_loop_is_the_row_iterator_bit_for_bit_with_normal_statistics() {
    let s = NoiseSigmas {
        johnson_dn: 3.0,
        flicker_dn: 2.0,
        thermal_dn: 1.0,
    };
    for (corr, seed) in [(DEFAULT_FLICKER_CORRELATION_PX, 7), (0.0, 8), (1.5, 2026)] {
        let slow = field_frame(s, corr, seed);
        let fast = field_frame_fast(s, corr, seed);
        assert_eq!(fast.len(), W * H);
        let same = slow
            .iter()
            .zip(&fast)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same,
            "ℓ = {corr}, seed {seed}: the fast loop differs from next_row"
        );
        // Shorter signal rows: the dropped values are still drawn, so the next rows
        // stay on the stream (row 2 of a field fed a 100-pixel row 1 equals next_row's).
        let mut f = NoiseField::new(s, corr, W, seed).unwrap();
        let mut short = vec![0.0f32; 100];
        f.combine_row(&[0.0; 100], &mut short, |_, n| n);
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&short), bits(&slow[..100]));
        let mut row = vec![0.0f32; W];
        f.combine_row(&[0.0; W], &mut row, |_, n| n);
        assert_eq!(bits(&row), bits(&slow[W..2 * W]));
    }
    // White noise alone: mean 0, σ = √(σ_J² + σ_th²), and the share within 1, 2, 3 σ
    // against the normal law's closed form erf(k/√2) = 0.682 689, 0.954 500, 0.997 300.
    let white = NoiseSigmas {
        johnson_dn: 4.0,
        flicker_dn: 0.0,
        thermal_dn: 3.0,
    };
    let v = field_frame_fast(white, DEFAULT_FLICKER_CORRELATION_PX, 11);
    let n = v.len() as f64;
    let sigma = 5.0;
    let (mean, std) = mean_std(&v);
    assert!(mean.abs() < 5.0 * sigma / n.sqrt(), "mean {mean}");
    assert!(rel(std, sigma) < 0.015, "std {std} vs {sigma}");
    for (k, p) in [(1.0, 0.682_689), (2.0, 0.954_500), (3.0, 0.997_300)] {
        let inside = v
            .iter()
            .filter(|&&x| f64::from(x).abs() < k * sigma)
            .count() as f64
            / n;
        // Binomial standard error √(p(1−p)/n), 5 of them.
        let tol = 5.0 * (p * (1.0 - p) / n).sqrt();
        assert!((inside - p).abs() < tol, "within {k} σ: {inside} vs {p}");
    }
}
