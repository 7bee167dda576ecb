//! The scale of the paper's detection mode (Eq. 4, Table 5) under the chosen sensing
//! area ΔA_c, against `shared/reference/REFERENCE.md` §4, whose numbers are made with
//! the analytic bell response (η = 1), so these tests use it too.

use tirroi_core::sensor::dn::EARTH_MAX_FLUX_TABLE5_W_M2;
use tirroi_core::sensor::flux::{distance_compensation, facet_flux_w_m2};
use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi_core::sensor::{BandRadiance, DetectionScale, DnMapping, SENSOR_AREA_M2};

/// Camera–Earth distance of the paper's dataset, m (4 500 km altitude).
const EARTH_DISTANCE_M: f64 = 10_871e3;

fn face_on_flux(radiance: f64, distance_m: f64) -> f64 {
    facet_flux_w_m2(
        radiance,
        &[0.0, 0.0, 1.0],
        &[0.0, 0.0, -1.0],
        &[0.0, 0.0, distance_m],
        SENSOR_AREA_M2,
    )
    .unwrap()
}

#[test]
fn earth_maximum_flux_is_of_table5_order() {
    let band = BandRadiance::hayabusa2_tir_bell();
    // Warmest CERES cell: OLR 330 W m⁻² → Eq. 10.
    let t_earth = (330.0 / STEFAN_BOLTZMANN_W_M2_K4).powf(0.25);
    assert!((t_earth - 276.201).abs() < 1e-3);
    let l = band.radiance_w_m2_sr(t_earth, 1.0).unwrap();
    assert!((l / 21.913 - 1.0).abs() < 1e-4, "L = {l}");
    let q = face_on_flux(l, EARTH_DISTANCE_M);
    eprintln!("Earth maximum detected flux: {q:.4e} W/m^2 (Table 5: 3e-17)");
    assert!((q / 2.065e-17 - 1.0).abs() < 1e-3, "q = {q:e}");
    // Same order as Table 5: within a factor 1.5 of 3e-17.
    let ratio = EARTH_MAX_FLUX_TABLE5_W_M2 / q;
    assert!((1.0..1.5).contains(&ratio), "3e-17 / q = {ratio}");
    // On Scale 1 at 14 bits the warmest Earth cell uses 69 % of the range:
    // 2.065e-17 / 3e-17 × 16383 = 11 277 ± 5 from REFERENCE.md's four digits.
    let m = DnMapping::detection(DetectionScale::Scale1, 14).unwrap();
    let dn = m.quantise(m.dn(q));
    assert!((11_272..=11_282).contains(&dn), "{dn}");
}

#[test]
fn target_saturates_every_scale() {
    // ε = 0.86 face at 300 K (REFERENCE.md §4 table): 15 m and 440 m.
    let band = BandRadiance::hayabusa2_tir_bell();
    let l = band.radiance_w_m2_sr(300.0, 0.86).unwrap();
    for (d, want) in [
        (15.0, 1.4218e-5),
        (50.0, 1.2796e-6),
        (340.0, 2.7673e-8),
        (440.0, 1.6524e-8),
    ] {
        let q = face_on_flux(l, d);
        assert!((q / want - 1.0).abs() < 1e-4, "{d} m: {q:e}");
        for s in DetectionScale::TABLE5 {
            let m = DnMapping::detection(s, 14).unwrap();
            assert_eq!(
                m.quantise(m.dn(q)),
                16383,
                "the target is white on every scale"
            );
        }
    }
}

#[test]
fn distance_compensation_recovers_emissive_power() {
    // Eq. 7: F(T) = π|r|²/ΔA_c · q_fc for a facet seen face-on.
    let band = BandRadiance::hayabusa2_tir();
    for (t, d) in [(300.0, 15.0), (250.0, 440.0), (276.2, EARTH_DISTANCE_M)] {
        let q = face_on_flux(band.radiance_w_m2_sr(t, 1.0).unwrap(), d);
        let f = distance_compensation(d, SENSOR_AREA_M2).unwrap() * q;
        let want = band.emissive_power_w_m2(t, 1.0).unwrap();
        assert!((f / want - 1.0).abs() < 1e-12);
    }
}
