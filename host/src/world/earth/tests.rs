//! Unit tests of the Earth model (private helpers included).

use super::builtin::{CLEAR_SKY_OLR_W_M2, CLOUD_DEPTH_W_M2, profile};
use super::grid::{catmull_rom_weights, dot4, lat_stencil, lon_stencil};
use super::refine::cells_per_degree;
use super::*;

#[test]
fn catmull_rom_weights_sum_to_one_and_hit_the_nodes() {
    assert_eq!(catmull_rom_weights(0.0), [0.0, 1.0, 0.0, 0.0]);
    assert_eq!(catmull_rom_weights(1.0), [0.0, 0.0, 1.0, 0.0]);
    for i in 0..=100 {
        let w = catmull_rom_weights(f64::from(i) / 100.0);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
    // Linear data are reproduced exactly (Catmull-Rom is exact for degree 1).
    let w = catmull_rom_weights(0.3);
    assert!((dot4(&w, [-1.0, 0.0, 1.0, 2.0]) - 0.3).abs() < 1e-15);
}

#[test]
fn stencils_wrap_in_longitude_and_clamp_at_the_poles() {
    assert_eq!(lon_stencil(0.5).0, [359, 0, 1, 2]);
    assert_eq!(lon_stencil(0.0).0, [358, 359, 0, 1]);
    assert_eq!(lon_stencil(359.9).0, [358, 359, 0, 1]);
    assert_eq!(lon_stencil(-0.1).0, lon_stencil(359.9).0);
    assert_eq!(lat_stencil(-90.0).0, [0, 0, 1, 2]);
    assert_eq!(lat_stencil(90.0).0, [177, 178, 179, 179]);
    assert_eq!(lat_stencil(90.0).1, [0.0, 0.0, 1.0, 0.0]);
}

#[test]
fn mesh_sizes_must_be_a_degree_over_an_integer() {
    assert_eq!(cells_per_degree(1.0), Some(1));
    assert_eq!(cells_per_degree(0.1), Some(10));
    assert_eq!(cells_per_degree(1.0 / 3.0), Some(3));
    assert_eq!(cells_per_degree(0.05), Some(20));
    for bad in [0.0, -1.0, 0.3, 0.04, 2.0, f64::NAN, f64::INFINITY] {
        assert_eq!(cells_per_degree(bad), None, "{bad}");
    }
}

#[test]
fn profiles_interpolate_their_anchors() {
    assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, -90.0), 158.0);
    assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 22.0), 278.0);
    assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 26.0), 273.0);
    assert_eq!(profile(&BUILTIN_ZONAL_OLR_W_M2, 95.0), 176.0);
    // Every cloud can only lower the flux, and the thickest tropical cloud reaches
    // deep-convective cloud-top values (~105 W m⁻²).
    for lat in -90..=90 {
        let lat = f64::from(lat);
        assert!(profile(&CLOUD_DEPTH_W_M2, lat) > 0.0);
        assert!(profile(&CLEAR_SKY_OLR_W_M2, lat) > profile(&BUILTIN_ZONAL_OLR_W_M2, lat));
    }
    let core = profile(&CLEAR_SKY_OLR_W_M2, 5.0) - profile(&CLOUD_DEPTH_W_M2, 5.0);
    assert!((100.0..=110.0).contains(&core), "{core}");
}

#[test]
fn errors_say_what_to_do() {
    let e = EarthError::BadMesh { mesh_deg: 0.3 };
    assert!(e.to_string().contains("0.1"));
    let e = EarthError::MissingVariable {
        path: "a.nc".into(),
        variable: "olr".into(),
        available: vec!["lat".into(), "lon".into()],
    };
    let msg = e.to_string();
    assert!(msg.contains("a.nc") && msg.contains("`olr`") && msg.contains("toa_lw_all_daily"));
}
