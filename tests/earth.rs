//! The Earth model (`tirroi::host::world::earth`, paper Section 3.2): Eq. 10 against hand
//! values, the 1° grid's validation, the Catmull-Rom refinement (exact at the nodes,
//! no overshoot, periodic in longitude, clamped at the poles), eclipse scaling, and the
//! statistics and determinism of the built-in synthetic OLR field.

use tirroi::core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi::core::sensor::rng::Xoshiro128pp;
use tirroi::core::sensor::{BandLut, BandRadiance};
use tirroi::host::world::earth::{
    BUILTIN_ZONAL_OLR_W_M2, ECLIPSE_FLUX_FACTOR, EarthError, EarthMap, OlrGrid,
    flux_to_temperature_k, interpolate_temperature_k,
};

const N: usize = OlrGrid::ROWS * OlrGrid::COLS;

fn lut() -> BandLut {
    BandLut::new(&BandRadiance::hayabusa2_tir())
}

/// A grid of independent uniform fluxes in [lo, hi) W m⁻²: rough data, the hardest
/// case for overshoot.
fn random_grid(seed: u64, lo: f32, hi: f32) -> OlrGrid {
    let mut rng = Xoshiro128pp::seed_from_u64(seed);
    let values = (0..N)
        .map(|_| lo + (hi - lo) * (rng.next_u32() >> 8) as f32 / 16_777_216.0)
        .collect();
    OlrGrid::from_values(values).expect("valid grid")
}

/// A smooth grid, periodic in longitude: 240 + 40 cos(lon) + 30 sin(2 lat) W m⁻².
fn smooth_grid() -> OlrGrid {
    let values = (0..N)
        .map(|i| {
            let lat = OlrGrid::node_lat_deg(i / OlrGrid::COLS).to_radians();
            let lon = OlrGrid::node_lon_deg(i % OlrGrid::COLS).to_radians();
            (240.0 + 40.0 * lon.cos() + 30.0 * (2.0 * lat).sin()) as f32
        })
        .collect();
    OlrGrid::from_values(values).expect("valid grid")
}

// --- Eq. 10 ------------------------------------------------------------------------

#[test]
fn eq10_hand_values_and_round_trip() {
    // 240 W/m² (the global mean OLR) is the classic 255 K effective temperature.
    let t = flux_to_temperature_k(240.0);
    assert!((t - 255.0).abs() < 0.1, "240 W/m² -> {t} K");
    // By hand: (240 / 5.670374419e-8)^(1/4) = 255.0644 K.
    assert!((t - 255.0644).abs() < 1e-4, "{t}");
    // σ T⁴ round trip over the whole Earth range and beyond.
    for t in [3.0, 100.0, 150.0, 200.0, 255.0, 288.0, 300.0, 1000.0] {
        let f = STEFAN_BOLTZMANN_W_M2_K4 * t * t * t * t;
        let back = flux_to_temperature_k(f);
        assert!(
            (back - t).abs() < 1e-12 * t,
            "{t} K -> {f} W/m² -> {back} K"
        );
    }
    assert_eq!(flux_to_temperature_k(0.0), 0.0);
    assert!(flux_to_temperature_k(-1.0).is_nan());
    assert!(flux_to_temperature_k(f64::NAN).is_nan());
    // The CERES valid_range ends (0, 500) map to 0 K and 306.436 K.
    assert!((flux_to_temperature_k(500.0) - 306.4358).abs() < 1e-3);
}

// --- the 1° grid -------------------------------------------------------------------

#[test]
fn from_values_accepts_the_valid_range_and_refuses_the_rest() {
    let mut v = vec![0.0f32; N];
    v[N - 1] = 500.0;
    let g = OlrGrid::from_values(v).expect("0 and 500 are valid");
    assert_eq!(g.at_node(179, 359), 500.0);
    assert_eq!(g.values().len(), N);

    for len in [0, N - 1, N + 1, 180] {
        assert_eq!(
            OlrGrid::from_values(vec![240.0; len]),
            Err(EarthError::WrongLength { actual: len })
        );
    }
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.5, 500.5] {
        let mut v = vec![240.0f32; N];
        let i = 37 * OlrGrid::COLS + 123;
        v[i] = bad;
        match OlrGrid::from_values(v) {
            Err(EarthError::BadFlux { row, col, value }) => {
                assert_eq!((row, col), (37, 123));
                assert!(value.to_bits() == bad.to_bits());
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    // The message names the node and the expected range.
    let mut v = vec![240.0f32; N];
    v[0] = -3.0;
    let msg = OlrGrid::from_values(v).unwrap_err().to_string();
    assert!(
        msg.contains("row 0") && msg.contains("-89.5") && msg.contains("0..=500"),
        "{msg}"
    );
    let msg = OlrGrid::from_values(vec![1.0; 5]).unwrap_err().to_string();
    assert!(msg.contains("64800") && msg.contains('5'), "{msg}");
}

#[test]
fn at_node_clamps_rows_and_wraps_columns() {
    let g = random_grid(1, 100.0, 330.0);
    assert_eq!(g.at_node(3, 5), g.values()[3 * 360 + 5]);
    assert_eq!(g.at_node(500, 5), g.at_node(179, 5));
    assert_eq!(g.at_node(3, 365), g.at_node(3, 5));
    assert_eq!(
        g.at_node(usize::MAX, usize::MAX),
        g.at_node(179, usize::MAX % 360)
    );
}

#[test]
fn area_weighted_mean_uses_cell_areas() {
    let g = OlrGrid::from_values(vec![240.0; N]).unwrap();
    assert!((g.area_weighted_mean_w_m2() - 240.0).abs() < 1e-9);
    // 300 in the northern hemisphere, 100 in the southern: equal areas, mean 200.
    let v = (0..N)
        .map(|i| if i / 360 >= 90 { 300.0 } else { 100.0 })
        .collect();
    let g = OlrGrid::from_values(v).unwrap();
    assert!((g.area_weighted_mean_w_m2() - 200.0).abs() < 1e-9);
    // 300 within 30° of the equator (half the sphere's area: sin 30° = ½), 100 elsewhere.
    let v = (0..N)
        .map(|i| {
            if OlrGrid::node_lat_deg(i / 360).abs() < 30.0 {
                300.0
            } else {
                100.0
            }
        })
        .collect();
    let g = OlrGrid::from_values(v).unwrap();
    assert!(
        (g.area_weighted_mean_w_m2() - 200.0).abs() < 1e-9,
        "{}",
        g.area_weighted_mean_w_m2()
    );
}

// --- eclipse -----------------------------------------------------------------------

#[test]
fn eclipse_scaling_is_uniform_and_stays_valid() {
    assert!((0.9..=0.95).contains(&ECLIPSE_FLUX_FACTOR));
    let g = OlrGrid::builtin(3);
    let e = g.scaled(ECLIPSE_FLUX_FACTOR);
    for (a, b) in g.values().iter().zip(e.values()) {
        assert_eq!(*b, a * ECLIPSE_FLUX_FACTOR);
    }
    let ratio = e.area_weighted_mean_w_m2() / g.area_weighted_mean_w_m2();
    assert!(
        (ratio - f64::from(ECLIPSE_FLUX_FACTOR)).abs() < 1e-6,
        "{ratio}"
    );
    // Temperatures scale by factor^¼ everywhere.
    let k = f64::from(ECLIPSE_FLUX_FACTOR).powf(0.25);
    for (a, b) in g.temperatures_k().iter().zip(e.temperatures_k()) {
        assert!((f64::from(b) / f64::from(*a) - k).abs() < 1e-6);
    }
    // The eclipse Earth is dimmer in band on every cell.
    let lut = lut();
    let (day, night) = (
        EarthMap::refine(&g, 1.0, &lut).unwrap(),
        EarthMap::refine(&e, 1.0, &lut).unwrap(),
    );
    for (d, n) in day
        .radiances_w_m2_sr()
        .iter()
        .zip(night.radiances_w_m2_sr())
    {
        assert!(n < d);
    }
    // Out-of-domain factors still give a valid grid.
    assert!(g.scaled(10.0).values().iter().all(|&v| v == 500.0));
    assert!(g.scaled(-1.0).values().iter().all(|&v| v == 0.0));
    assert!(g.scaled(f32::NAN).values().iter().all(|&v| v == 0.0));
    assert_eq!(g.scaled(1.0), g);
}

// --- interpolation and the refined mesh -------------------------------------------

#[test]
fn interpolant_is_exact_at_every_node() {
    let g = random_grid(7, 100.0, 330.0);
    let temps = g.temperatures_k();
    for row in 0..OlrGrid::ROWS {
        for col in 0..OlrGrid::COLS {
            let (lat, lon) = (OlrGrid::node_lat_deg(row), OlrGrid::node_lon_deg(col));
            let t = interpolate_temperature_k(&temps, lat, lon).unwrap();
            assert_eq!(t, temps[row * 360 + col], "node ({row}, {col})");
            // The same node one turn east or west.
            let t = interpolate_temperature_k(&temps, lat, lon - 360.0).unwrap();
            assert_eq!(t, temps[row * 360 + col], "node ({row}, {col}) - 360°");
        }
    }
    assert_eq!(
        interpolate_temperature_k(&temps[1..], 0.0, 0.0),
        Err(EarthError::WrongLength { actual: N - 1 })
    );
    assert!(
        interpolate_temperature_k(&temps, f64::NAN, 0.0)
            .unwrap()
            .is_nan()
    );
}

#[test]
fn one_degree_map_reproduces_the_grid() {
    let g = random_grid(8, 100.0, 330.0);
    let lut = lut();
    let map = EarthMap::refine(&g, 1.0, &lut).unwrap();
    assert_eq!(map.shape(), (180, 360));
    assert_eq!(map.mesh_deg(), 1.0);
    let temps = g.temperatures_k();
    for row in 0..OlrGrid::ROWS {
        for col in 0..OlrGrid::COLS {
            let (lat, lon) = (OlrGrid::node_lat_deg(row), OlrGrid::node_lon_deg(col));
            let t = temps[row * 360 + col];
            assert_eq!(map.temperature_k(lat, lon), t);
            assert_eq!(map.interpolated_temperature_k(lat, lon), t);
            // Radiance is the band radiance of that temperature (blackbody Earth).
            assert_eq!(
                map.radiance_w_m2_sr(lat, lon),
                lut.radiance_f32(t, 1.0).unwrap()
            );
            // Anywhere inside the 1° cell is the same flat element.
            assert_eq!(map.temperature_k(lat + 0.49, lon - 0.49), t);
        }
    }
    let (lo, hi) = map.min_max_radiance_w_m2_sr();
    let tmin = temps.iter().copied().fold(f32::INFINITY, f32::min);
    let tmax = temps.iter().copied().fold(0.0, f32::max);
    assert_eq!(lo, lut.radiance_f32(tmin, 1.0).unwrap());
    assert_eq!(hi, lut.radiance_f32(tmax, 1.0).unwrap());
}

#[test]
fn odd_refinement_keeps_the_node_in_the_cell_centred_on_it() {
    // 0.2°: five cells per degree, so the cell centred on every node holds the node.
    let g = random_grid(9, 100.0, 330.0);
    let map = EarthMap::refine(&g, 0.2, &lut()).unwrap();
    assert_eq!(map.shape(), (900, 1800));
    let temps = g.temperatures_k();
    for row in (0..OlrGrid::ROWS).step_by(7) {
        for col in 0..OlrGrid::COLS {
            let (lat, lon) = (OlrGrid::node_lat_deg(row), OlrGrid::node_lon_deg(col));
            assert_eq!(map.temperature_k(lat, lon), temps[row * 360 + col]);
        }
    }
}

#[test]
fn no_overshoot_beyond_the_data() {
    // A step grid (cold band 150 W/m², warm elsewhere 320): Catmull-Rom alone would
    // ring around the steps; the 4×4 clamp keeps every cell within [T(150), T(320)].
    let v = (0..N)
        .map(|i| {
            let (r, c) = (i / 360, i % 360);
            if (80..100).contains(&r) || (c / 10) % 2 == 0 {
                150.0
            } else {
                320.0
            }
        })
        .collect();
    let g = OlrGrid::from_values(v).unwrap();
    let map = EarthMap::refine(&g, 0.25, &lut()).unwrap();
    let (tlo, thi) = (
        flux_to_temperature_k(150.0) as f32,
        flux_to_temperature_k(320.0) as f32,
    );
    for &t in map.temperatures_k() {
        assert!((tlo..=thi).contains(&t), "{t} outside [{tlo}, {thi}]");
    }
    // And on random data every cell stays within the range of the whole grid.
    let g = random_grid(10, 100.0, 330.0);
    let temps = g.temperatures_k();
    let (lo, hi) = temps
        .iter()
        .fold((f32::INFINITY, 0.0f32), |a, &t| (a.0.min(t), a.1.max(t)));
    let map = EarthMap::refine(&g, 0.5, &lut()).unwrap();
    assert!(map.temperatures_k().iter().all(|t| (lo..=hi).contains(t)));
}

#[test]
fn refined_cells_sample_the_interpolant_at_their_centres() {
    let g = random_grid(11, 150.0, 300.0);
    let map = EarthMap::refine(&g, 0.25, &lut()).unwrap();
    let (rows, cols) = map.shape();
    let mut rng = Xoshiro128pp::seed_from_u64(5);
    for _ in 0..2000 {
        let (r, c) = (
            rng.next_u32() as usize % rows,
            rng.next_u32() as usize % cols,
        );
        let (lat, lon) = ((r as f64 + 0.5) * 0.25 - 90.0, (c as f64 + 0.5) * 0.25);
        assert_eq!(
            map.temperature_k(lat, lon),
            map.interpolated_temperature_k(lat, lon)
        );
        assert_eq!(
            map.temperatures_k()[r * cols + c],
            map.temperature_k(lat, lon)
        );
    }
}

#[test]
fn longitude_seam_is_continuous() {
    let g = smooth_grid();
    let temps = g.temperatures_k();
    // The interpolant at 360° − ε and 0° + ε meets the same value.
    for lat in [-89.9, -60.0, -0.3, 0.0, 33.3, 89.5, 90.0] {
        let west = interpolate_temperature_k(&temps, lat, 359.999_999).unwrap();
        let east = interpolate_temperature_k(&temps, lat, 0.000_001).unwrap();
        let zero = interpolate_temperature_k(&temps, lat, 0.0).unwrap();
        let turn = interpolate_temperature_k(&temps, lat, 360.0).unwrap();
        assert_eq!(zero, turn);
        assert!((west - east).abs() < 1e-3, "lat {lat}: {west} vs {east}");
    }
    // On the refined mesh the two cells either side of the seam (359.9°, 0.05°) differ
    // no more than neighbours elsewhere on the row.
    let map = EarthMap::refine(&g, 0.1, &lut()).unwrap();
    let (rows, cols) = map.shape();
    assert_eq!((rows, cols), (1800, 3600));
    for lat in [-45.05, 0.05, 60.05] {
        let seam = (map.temperature_k(lat, 359.95) - map.temperature_k(lat, 0.05)).abs();
        let max_step = (1..cols)
            .map(|c| {
                let lon = (c as f64 + 0.5) * 0.1;
                (map.temperature_k(lat, lon) - map.temperature_k(lat, lon - 0.1)).abs()
            })
            .fold(0.0f32, f32::max);
        assert!(
            seam <= max_step * 1.01 && seam < 0.05,
            "lat {lat}: seam {seam}, max step {max_step}"
        );
        // Wrapped longitudes look up the same cells.
        assert_eq!(
            map.temperature_k(lat, -0.05),
            map.temperature_k(lat, 359.95)
        );
        assert_eq!(
            map.radiance_w_m2_sr(lat, 720.05),
            map.radiance_w_m2_sr(lat, 0.05)
        );
    }
    // Memory: 8 bytes per cell plus the 1° nodes.
    assert_eq!(map.memory_bytes(), (1800 * 3600 * 2 + N) * 4);
}

#[test]
fn poles_are_clamped_and_lookups_never_panic() {
    let g = random_grid(12, 100.0, 330.0);
    let temps = g.temperatures_k();
    for col in [0, 100, 359] {
        let lon = OlrGrid::node_lon_deg(col);
        // Beyond ±89.5° the edge rows hold.
        assert_eq!(
            interpolate_temperature_k(&temps, 90.0, lon).unwrap(),
            temps[179 * 360 + col]
        );
        assert_eq!(
            interpolate_temperature_k(&temps, -90.0, lon).unwrap(),
            temps[col]
        );
    }
    let map = EarthMap::refine(&g, 0.5, &lut()).unwrap();
    for (lat, lon) in [
        (90.0, 0.0),
        (-90.0, 0.0),
        (1e9, 1e9),
        (-1e9, -1e9),
        (f64::NAN, 10.0),
        (10.0, f64::NAN),
        (f64::INFINITY, f64::NEG_INFINITY),
        (0.0, -720.3),
    ] {
        let l = map.radiance_w_m2_sr(lat, lon);
        let t = map.temperature_k(lat, lon);
        assert!(l.is_finite() && t.is_finite(), "({lat}, {lon})");
    }
    assert_eq!(map.temperature_k(90.0, 10.0), map.temperature_k(89.9, 10.0));
    assert_eq!(
        map.temperature_k(-90.0, 10.0),
        map.temperature_k(-89.9, 10.0)
    );
}

#[test]
fn refine_refuses_meshes_that_do_not_divide_a_degree() {
    let g = smooth_grid();
    let lut = lut();
    for bad in [
        0.0,
        -0.1,
        0.3,
        0.15,
        2.0,
        1.5,
        0.01,
        f64::NAN,
        f64::INFINITY,
    ] {
        match EarthMap::refine(&g, bad, &lut) {
            Err(EarthError::BadMesh { mesh_deg }) => {
                assert!(mesh_deg.to_bits() == bad.to_bits());
            }
            other => panic!("{bad}: {:?}", other.map(|m| m.shape())),
        }
    }
    let msg = EarthMap::refine(&g, 0.3, &lut).unwrap_err().to_string();
    assert!(msg.contains("0.3") && msg.contains("0.1"), "{msg}");
    for (mesh, shape) in [
        (1.0, (180, 360)),
        (0.5, (360, 720)),
        (1.0 / 3.0, (540, 1080)),
    ] {
        let map = EarthMap::refine(&g, mesh, &lut).unwrap();
        assert_eq!(map.shape(), shape);
        assert!((map.mesh_deg() - mesh).abs() < 1e-12);
    }
}

// --- the built-in field ------------------------------------------------------------

#[test]
fn builtin_field_has_ceres_like_statistics() {
    for seed in [0, 1, 2024] {
        let g = OlrGrid::builtin(seed);
        let v = g.values();
        assert_eq!(v.len(), N);
        assert!(
            v.iter().all(|x| (100.0..=330.0).contains(x)),
            "seed {seed}: range"
        );
        let mean = g.area_weighted_mean_w_m2();
        assert!(
            (235.0..=245.0).contains(&mean),
            "seed {seed}: global mean {mean}"
        );
        // Deep convective cloud tops and hot clear deserts both occur.
        let deep = v.iter().filter(|&&x| x < 140.0).count();
        let hot = v.iter().filter(|&&x| x > 300.0).count();
        assert!(deep > 100, "seed {seed}: {deep} cells below 140 W/m²");
        assert!(hot > 100, "seed {seed}: {hot} cells above 300 W/m²");
        // Deep cloud sits mostly in the tropics (|lat| < 30°).
        let tropical_deep = (0..N)
            .filter(|&i| v[i] < 140.0 && OlrGrid::node_lat_deg(i / 360).abs() < 30.0)
            .count();
        assert!(
            tropical_deep * 10 > deep * 7,
            "seed {seed}: {tropical_deep} of {deep}"
        );

        // Zonal means: the anchor profile to a few W/m², tropics and subtropics far
        // above the poles, Antarctica colder than the Arctic.
        let zonal: Vec<f64> = (0..180).map(|r| g.zonal_mean_w_m2(r)).collect();
        let anchor = |lat: f64| {
            let t = &BUILTIN_ZONAL_OLR_W_M2;
            let j = t.windows(2).position(|w| lat <= w[1].0).unwrap();
            let ((a, va), (b, vb)) = (t[j], t[j + 1]);
            va + (vb - va) * (lat - a) / (b - a)
        };
        for (r, z) in zonal.iter().enumerate() {
            let want = anchor(OlrGrid::node_lat_deg(r));
            assert!((z - want).abs() < 8.0, "seed {seed} row {r}: {z} vs {want}");
        }
        let band = |lo: f64, hi: f64| {
            let rows: Vec<usize> = (0..180)
                .filter(|&r| (lo..hi).contains(&OlrGrid::node_lat_deg(r).abs()))
                .collect();
            rows.iter().map(|&r| zonal[r]).sum::<f64>() / rows.len() as f64
        };
        assert!(band(0.0, 30.0) > band(60.0, 90.0) + 50.0);
        assert!(band(15.0, 30.0) > 260.0 && band(15.0, 30.0) < 290.0);
        assert!(
            zonal[0] < zonal[179],
            "Antarctic {} vs Arctic {}",
            zonal[0],
            zonal[179]
        );
        assert!((150.0..=185.0).contains(&zonal[0]) && (150.0..=185.0).contains(&zonal[179]));
        // Clear subtropical deserts: the Sahara (20–28° N, 0–30° E) is warm.
        let sahara: f64 = (110..118)
            .flat_map(|r| (0..30).map(move |c| (r, c)))
            .map(|(r, c)| f64::from(g.at_node(r, c)))
            .sum::<f64>()
            / 240.0;
        assert!(sahara > 285.0, "seed {seed}: Sahara {sahara}");
    }
}

#[test]
fn builtin_field_is_deterministic_per_seed() {
    let bytes = |g: &OlrGrid| {
        g.values()
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect::<Vec<u8>>()
    };
    let a = OlrGrid::builtin(42);
    let b = OlrGrid::builtin(42);
    assert_eq!(bytes(&a), bytes(&b));
    let c = OlrGrid::builtin(43);
    let differing = a
        .values()
        .iter()
        .zip(c.values())
        .filter(|(x, y)| x != y)
        .count();
    assert!(
        differing > N / 2,
        "seeds 42 and 43 differ at only {differing} nodes"
    );
    // A fingerprint of seed 42 (FNV-1a of the little-endian bytes), so that a change
    // of the field, or a platform that computes it differently, is noticed. The field
    // uses only IEEE-exact operations and `libm`, and per-node work in parallel.
    let fnv = bytes(&a).iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
    });
    assert_eq!(fnv, BUILTIN_SEED_42_FNV, "fingerprint {fnv:#018x}");
}

/// FNV-1a of `OlrGrid::builtin(42)`'s bytes (update on purpose when the field changes).
const BUILTIN_SEED_42_FNV: u64 = 0x22af_fb8f_ec73_4886;
