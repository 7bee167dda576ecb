//! Band radiance of the three paths (exact f64, f32, table) against the 30-digit
//! reference tables: `tests/data/band_radiance_reference.csv` of the analytic bell,
//! written once by `scripts/reference/band_radiance.py` (mpmath, two independent
//! quadratures), and `tests/data/band_radiance_hayabusa2_reference.csv` of the measured
//! Hayabusa2 TIR response, written by `scripts/reference/band_radiance_hayabusa2.py`
//! (mpmath, 24- and 12-point rules per 0.01 µm sample interval); and the flat response
//! against σT⁴/π.

use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi_core::sensor::{BandLut, BandRadiance, CameraResponse, DnMapping};

/// (T in K, L in W m⁻² sr⁻¹) from the bell's reference table, parsed as f64 (the 30
/// digits round to the nearest f64, 1e-16 relative: far below every bound tested here).
fn reference() -> Vec<(f64, f64)> {
    parse_reference(include_str!("data/band_radiance_reference.csv"))
}

/// The same for the measured Hayabusa2 TIR response.
fn reference_measured() -> Vec<(f64, f64)> {
    parse_reference(include_str!("data/band_radiance_hayabusa2_reference.csv"))
}

fn parse_reference(text: &str) -> Vec<(f64, f64)> {
    let rows: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("t_k"))
        .map(|l| {
            let (t, v) = l.split_once(',').expect("two columns");
            // Values below f64's range (1e-408 at 1 K) parse to 0.
            (t.parse().expect("T"), v.trim().parse().unwrap_or(0.0))
        })
        .collect();
    assert!(rows.len() > 80, "reference table has {} rows", rows.len());
    rows
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn f64_path_within_1e9_from_1_5_k_to_5000_k() {
    let band = BandRadiance::hayabusa2_tir_bell();
    let mut worst = (0.0, 0.0);
    for (t, want) in reference() {
        let got = band.radiance_w_m2_sr(t, 1.0).unwrap();
        if t >= 1.5 {
            let e = rel(got, want);
            if e > worst.0 {
                worst = (e, t);
            }
        } else {
            // Below 1.34 K the radiance is below the smallest normal f64.
            assert!((got - want).abs() < 2.3e-308, "T = {t}: {got} vs {want}");
        }
    }
    eprintln!(
        "f64 path: worst relative error {:.2e} at {} K",
        worst.0, worst.1
    );
    assert!(worst.0 <= 1e-9, "worst {:.3e} at {} K", worst.0, worst.1);
}

#[test]
fn f32_paths_within_1e5_where_l_is_a_normal_f32() {
    let band = BandRadiance::hayabusa2_tir_bell();
    check_f32_paths(&band, &reference());
}

#[test]
fn measured_response_f32_paths_within_1e5_where_l_is_a_normal_f32() {
    check_f32_paths(&BandRadiance::hayabusa2_tir(), &reference_measured());
}

/// The f32 quadrature and the table within 1e-5 relative wherever L is a normal f32,
/// ln L within 1e-4 absolute from 3 K, at every f32-exact reference temperature.
fn check_f32_paths(band: &BandRadiance, reference: &[(f64, f64)]) {
    let lut = BandLut::new(band);
    let (mut worst_quad, mut worst_lut, mut worst_ln) = ((0.0, 0.0), (0.0, 0.0), (0.0, 0.0));
    for &(t, want) in reference {
        let t32 = t as f32;
        if f64::from(t32) != t {
            // 273.15 K of the measured table: not an f32.
            continue;
        }
        let quad = f64::from(band.radiance_f32(t32, 1.0).unwrap());
        let table = f64::from(lut.radiance_f32(t32, 1.0).unwrap());
        if want >= f64::from(f32::MIN_POSITIVE) {
            let (eq, el) = (rel(quad, want), rel(table, want));
            if eq > worst_quad.0 {
                worst_quad = (eq, t);
            }
            if el > worst_lut.0 {
                worst_lut = (el, t);
            }
        } else {
            // Below 13 K: subnormal or 0, absolute error below the f32 normal minimum.
            assert!(
                (quad - want).abs() < f64::from(f32::MIN_POSITIVE),
                "T = {t}"
            );
            assert!(
                (table - want).abs() < f64::from(f32::MIN_POSITIVE),
                "T = {t}"
            );
        }
        if t >= 3.0 {
            let e = (f64::from(band.ln_radiance_f32(t32).unwrap()) - want.ln()).abs();
            if e > worst_ln.0 {
                worst_ln = (e, t);
            }
        }
    }
    eprintln!(
        "f32 quadrature: worst {:.2e} at {} K; table: worst {:.2e} at {} K; ln L f32: worst abs {:.2e} at {} K",
        worst_quad.0, worst_quad.1, worst_lut.0, worst_lut.1, worst_ln.0, worst_ln.1
    );
    assert!(worst_quad.0 <= 1e-5, "f32 quadrature {worst_quad:?}");
    assert!(worst_lut.0 <= 1e-5, "table {worst_lut:?}");
    assert!(worst_ln.0 <= 1e-4, "ln L f32 {worst_ln:?}");
}

#[test]
#[allow(clippy::excessive_precision)] // the digits as REFERENCE.md prints them
fn shared_reference_rows_match() {
    // Independent check against shared/reference/REFERENCE.md §3 (same model, made
    // with another script run), including the two temperatures that are not f32-exact.
    let band = BandRadiance::hayabusa2_tir_bell();
    for (t, want) in [
        (2.7, 5.928_670_475_583_473_5e-162),
        (10.0, 2.428_133_328_200_529_7e-50),
        (273.15, 20.655_540_180_591_427),
        (300.0, 33.402_715_873_345_489),
        (2000.0, 4_356.613_753_870_746),
    ] {
        let got = band.radiance_w_m2_sr(t, 1.0).unwrap();
        assert!(rel(got, want) < 1e-9, "T = {t}: {got} vs {want}");
    }
}

#[test]
fn measured_response_f64_within_1e6_from_50_k_to_2000_k_and_1e9_from_3_k() {
    let band = BandRadiance::hayabusa2_tir();
    let (mut worst_band, mut worst_all) = ((0.0, 0.0), (0.0, 0.0));
    let rows = reference_measured();
    assert!(rows.len() > 80, "reference table has {} rows", rows.len());
    for (t, want) in rows {
        let got = band.radiance_w_m2_sr(t, 1.0).unwrap();
        if t >= 3.0 {
            let e = rel(got, want);
            if e > worst_all.0 {
                worst_all = (e, t);
            }
            if (50.0..=2000.0).contains(&t) && e > worst_band.0 {
                worst_band = (e, t);
            }
        } else if want >= f64::MIN_POSITIVE {
            // 1.25–3 K: the pile-up against 17.91 um, where the tail panels end
            // (1.25 K: 4.5e-285 W m^-2 sr^-1, 1.3e-7 relative).
            assert!(rel(got, want) <= 1e-6, "T = {t}: {got} vs {want}");
        } else {
            // 1 K: 6e-354, below the f64 range.
            assert!((got - want).abs() < 2.3e-308, "T = {t}: {got} vs {want}");
        }
    }
    eprintln!(
        "measured response, f64: worst relative error {:.2e} at {} K over 50-2000 K, {:.2e} at {} K over 3-5000 K",
        worst_band.0, worst_band.1, worst_all.0, worst_all.1
    );
    // The bound over the camera's temperatures, and a tighter one everywhere.
    assert!(worst_band.0 <= 1e-6, "worst {worst_band:?}");
    assert!(worst_all.0 <= 1e-9, "worst {worst_all:?}");
}

#[test]
fn measured_response_matches_the_shared_reference_cross_check() {
    // REFERENCE.md §3: L_meas(300 K) = 29.6172 (5 digits, from the sample sum of the
    // same file, which differs from the piecewise-linear integral by 4e-7).
    let l = BandRadiance::hayabusa2_tir()
        .radiance_w_m2_sr(300.0, 1.0)
        .unwrap();
    assert!((l - 29.6172).abs() <= 0.00005 + 29.6172 * 4e-7, "{l}");
    // … and L_meas/L_model(η = 1) = 0.8867 at 300 K, 0.8895 at 150 K, 0.8849 at 500 K.
    let bell = BandRadiance::hayabusa2_tir_bell();
    for (t, want) in [(150.0, 0.8895), (300.0, 0.8867), (500.0, 0.8849)] {
        let ratio = BandRadiance::hayabusa2_tir()
            .radiance_w_m2_sr(t, 1.0)
            .unwrap()
            / bell.radiance_w_m2_sr(t, 1.0).unwrap();
        assert!((ratio - want).abs() <= 0.00005 + 1e-6, "T = {t}: {ratio}");
    }
}

#[test]
fn flat_response_is_sigma_t4_over_pi() {
    let flat = BandRadiance::new(&CameraResponse::Flat).unwrap();
    let lut = BandLut::new(&flat);
    for t in [3.0, 77.0, 300.0, 1000.0, 5000.0] {
        let want = STEFAN_BOLTZMANN_W_M2_K4 * t * t * t * t / std::f64::consts::PI;
        assert!(rel(flat.radiance_w_m2_sr(t, 1.0).unwrap(), want) < 1e-13);
        assert!(rel(flat.radiance_w_m2_sr(t, 0.5).unwrap(), 0.5 * want) < 1e-13);
        assert!(
            rel(
                flat.emissive_power_w_m2(t, 1.0).unwrap(),
                STEFAN_BOLTZMANN_W_M2_K4 * t.powi(4)
            ) < 1e-13
        );
        assert!(rel(f64::from(flat.radiance_f32(t as f32, 1.0).unwrap()), want) < 1e-6);
        assert!(rel(f64::from(lut.radiance_f32(t as f32, 1.0).unwrap()), want) < 1e-5);
    }
}

#[test]
fn derivative_matches_central_differences() {
    for band in [
        BandRadiance::hayabusa2_tir(),
        BandRadiance::hayabusa2_tir_bell(),
    ] {
        for t in [20.0, 100.0, 300.0, 1500.0] {
            let h = t * 1e-5;
            let fd = (band.radiance_w_m2_sr(t + h, 1.0).unwrap()
                - band.radiance_w_m2_sr(t - h, 1.0).unwrap())
                / (2.0 * h);
            let d = band.radiance_derivative_w_m2_sr_k(t, 1.0).unwrap();
            assert!(rel(d, fd) < 1e-7, "T = {t}: {d} vs {fd}");
        }
    }
}

#[test]
fn inverse_recovers_the_temperature() {
    for band in [
        BandRadiance::hayabusa2_tir(),
        BandRadiance::hayabusa2_tir_bell(),
    ] {
        for t in [5.0, 13.0, 50.0, 150.0, 276.2, 300.0, 460.0, 2000.0, 9000.0] {
            for eps in [1.0, 0.86, 0.05] {
                let l = band.radiance_w_m2_sr(t, eps).unwrap();
                let back = band.temperature_k(l, eps).unwrap();
                assert!(rel(back, t) < 1e-10, "T = {t}, eps = {eps}: {back}");
            }
        }
        assert_eq!(band.temperature_k(0.0, 1.0), Ok(0.0));
        assert!(band.temperature_k(f64::NAN, 1.0).is_err());
        assert!(band.temperature_k(1e30, 1.0).is_err());
    }
}

#[test]
fn radiometry_round_trip_within_one_quantisation_step() {
    // T → F(T) → DN (14 bit, range of the TIR: 150–460 K) → T_rad: within the
    // temperature width of one DN at that T.
    let band = BandRadiance::hayabusa2_tir();
    let f = |t: f64| band.emissive_power_w_m2(t, 1.0).unwrap();
    for bits in [12u8, 14, 16] {
        let m = DnMapping::radiometry_auto(f(150.0), f(460.0), bits).unwrap();
        let mut t = 150.0;
        while t <= 460.0 {
            let dn = m.quantise(m.dn(f(t)));
            let back = m
                .radiometric_temperature_k(f64::from(dn), &band, 1.0)
                .unwrap();
            let step_k = 1.0
                / (m.gain_dn()
                    * std::f64::consts::PI
                    * band
                        .radiance_derivative_w_m2_sr_k(back.max(150.0), 1.0)
                        .unwrap());
            assert!(
                (back - t).abs() <= 0.5 * step_k * 1.01 + 1e-9,
                "{bits} bit, T = {t}: {back}, step {step_k}"
            );
            t += 1.37;
        }
    }
}
