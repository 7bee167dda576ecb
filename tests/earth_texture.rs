//! The Earth's cloud texture (`earth_model.texture = "clouds"`): energy conservation
//! per 1° cell, continuity across cell borders, determinism, the statistics tool
//! against the real image's README numbers, and the acceptance ranges.

use tirroi_core::sensor::planck::STEFAN_BOLTZMANN_W_M2_K4;
use tirroi_host::cli::earth_texture::{PATCH_CENTRES, builtin_field};
use tirroi_host::world::earth::CloudField;
use tirroi_host::world::earth::texture_stats::{
    PATCH_PX_KM, REAL_QUANTUM_K, TextureStats, sample_patch,
};

/// The statistics of the `size`-px square patch of `f` centred at (`lat`, `lon`) at the
/// real image's 4 km pixels and 0.5 K quantum.
fn patch_stats(f: &CloudField, lat: f64, lon: f64, size: usize) -> TextureStats {
    let t = sample_patch(f, lat, lon, size, size, PATCH_PX_KM, REAL_QUANTUM_K);
    TextureStats::of(&t, size, size, PATCH_PX_KM).unwrap()
}

/// Relative error of the 1° cell (`row`, `col`)'s flux against its mean σT⁴ by an
/// independent 40 × 40 sampling (cos-latitude weighted, offset from the 16 × 16 balance
/// points).
fn cell_flux_error(f: &CloudField, row: usize, col: usize) -> f64 {
    let n = 40;
    let (mut sum, mut wsum) = (0.0, 0.0);
    for i in 0..n {
        let lat = row as f64 - 90.0 + (i as f64 + 0.37) / n as f64;
        let w = lat.to_radians().cos();
        for j in 0..n {
            let lon = col as f64 + (j as f64 + 0.61) / n as f64;
            let t = f.temperature_at_k(lat, lon);
            sum += w * STEFAN_BOLTZMANN_W_M2_K4 * t.powi(4);
            wsum += w;
        }
    }
    let target = f64::from(f.cell_flux_w_m2(row, col));
    (sum / wsum / target - 1.0).abs()
}

/// Each cell's mean σT⁴ by an independent 40 × 40 sampling (offset from the 16 × 16
/// balance points) is within 0.5 % of its flux.
#[test]

fn every_cell_keeps_its_flux_within_half_a_percent() {
    let f = builtin_field(1, 0);
    let mut worst = 0.0f64;
    // A mild trade-wind block and a convective warm-pool block.
    for (r0, c0) in [(108usize, 200usize), (90, 138)] {
        for row in r0..r0 + 3 {
            for col in c0..c0 + 3 {
                worst = worst.max(cell_flux_error(&f, row, col));
            }
        }
    }
    eprintln!("worst cell flux error {:.3} %", 100.0 * worst);
    assert!(worst < 0.005, "worst cell flux error {worst}");
}

/// Textured cloud tops (`earth_model.cloud_top_texture_k`, here 5 K per σ) keep each
/// cell's flux as the flat ones do (within 0.5 %, the same independent sampling), and
/// they do texture the tops: the cloud-top 5 × 5 σ of a 256-px patch rises.
#[test]
fn textured_cloud_tops_keep_the_flux() {
    use tirroi_host::world::earth::texture_stats::cloud_top_sd;
    let flat = builtin_field(1, 0);
    let f = builtin_field(1, 0).with_cloud_top_texture(5.0);
    let worst = [(108usize, 200usize), (109, 201), (90, 138), (91, 139)]
        .into_iter()
        .map(|(row, col)| cell_flux_error(&f, row, col))
        .fold(0.0f64, f64::max);
    assert!(worst < 0.005, "worst cell flux error {worst}");
    let sd = |field: &CloudField| {
        let t = sample_patch(field, 20.0, 202.0, 256, 256, PATCH_PX_KM, 0.0);
        let mut sorted = t.clone();
        sorted.sort_by(f64::total_cmp);
        let warm = sorted[(sorted.len() - 1) * 9 / 10];
        cloud_top_sd(&t, 256, 256, warm)
    };
    let (a, b) = (sd(&flat), sd(&f));
    assert!(
        b[0] > a[0] + 0.5 && b[1] > a[1],
        "flat {a:?}, textured {b:?}"
    );
}

/// Steps between neighbouring samples that cross a 1° border are no larger than those
/// inside cells (no seams).
#[test]
fn no_seams_at_cell_borders() {
    let f = builtin_field(1, 1);
    let (mut border, mut interior) = (Vec::new(), Vec::new());
    let dx = 0.02; // ≈ 2 km
    for k in 0..40 {
        let lat = 15.0 + 0.137 * k as f64;
        let mut prev = f.temperature_at_k(lat, 200.0);
        for i in 1..1000 {
            let lon = 200.0 + i as f64 * dx;
            let t = f.temperature_at_k(lat, lon);
            let crosses = (lon - dx).floor() != lon.floor();
            let near = (lon - lon.round()).abs() < 0.3;
            if crosses {
                border.push((t - prev).abs());
            } else if !near {
                interior.push((t - prev).abs());
            }
            prev = t;
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (b, i) = (mean(&border), mean(&interior));
    eprintln!("mean step across borders {b:.3} K, inside cells {i:.3} K");
    assert!(b < 2.0 * i + 0.1, "border steps {b} K vs interior {i} K");
}

/// No seams in deep-convective decks either: along every 1° border with a cell below
/// 150 W m⁻² on either side (the warm pool of field (1, 1): 0–10° N, 130–160° E), the
/// coherent step across the border (the signed mean over 40 points along the border of
/// T(+0.03°) − T(−0.03°)) is no larger than across lines inside the cells (0.3, 0.5 and
/// 0.7 of a cell): 90th percentile within 1.25 × the interior's and maximum within the
/// interior's maximum. Session 24: fails on the field before (borders p90 5.93 K and
/// max 10.0 K against 2.40 K and 9.15 K inside: cells whose threshold shift saturated
/// took 3–7 % off their temperature by the scale s, blended over only 0.05°, so they
/// showed as 1° blocks in rendered frames), passes after (1.74 K and 3.11 K against
/// 2.64 K and 11.93 K).
#[test]
fn no_seams_at_deep_convective_cell_borders() {
    let f = builtin_field(1, 1);
    let (h, n) = (0.03, 40);
    let step = |lat: f64, lon: f64, along_lat: bool| -> f64 {
        let mut s = 0.0;
        for k in 0..n {
            let t = (f64::from(k) + 0.5) / f64::from(n);
            s += if along_lat {
                f.temperature_k(lat + t, lon + h) - f.temperature_k(lat + t, lon - h)
            } else {
                f.temperature_k(lat + h, lon + t) - f.temperature_k(lat - h, lon + t)
            };
        }
        (s / f64::from(n)).abs()
    };
    let (mut border, mut interior) = (Vec::new(), Vec::new());
    for row in 90..100usize {
        for col in 130..160usize {
            let (lat, lon) = (row as f64 - 90.0, col as f64);
            // West border (a line of constant longitude), then south border.
            for (along_lat, other) in [(true, (row, col - 1)), (false, (row - 1, col))] {
                let flux = f
                    .cell_flux_w_m2(row, col)
                    .min(f.cell_flux_w_m2(other.0, other.1));
                if flux > 150.0 {
                    continue;
                }
                border.push(step(lat, lon, along_lat));
                for off in [0.3, 0.5, 0.7] {
                    interior.push(if along_lat {
                        step(lat, lon + off, true)
                    } else {
                        step(lat + off, lon, false)
                    });
                }
            }
        }
    }
    assert!(border.len() >= 20, "only {} deep borders", border.len());
    border.sort_by(f64::total_cmp);
    interior.sort_by(f64::total_cmp);
    let p90 = |v: &[f64]| v[(v.len() - 1) * 9 / 10];
    let (bp, ip) = (p90(&border), p90(&interior));
    let (bm, im) = (border[border.len() - 1], interior[interior.len() - 1]);
    eprintln!(
        "{} deep borders: coherent step p90 {bp:.2} K, max {bm:.2} K; interior lines p90 {ip:.2} K, max {im:.2} K",
        border.len()
    );
    assert!(bp <= 1.25 * ip, "border p90 {bp} K vs interior {ip} K");
    assert!(bm <= im, "border max {bm} K vs interior {im} K");
}

#[test]
fn same_inputs_same_bits_other_seed_or_day_other_clouds() {
    let (a, b) = (builtin_field(7, 3), builtin_field(7, 3));
    let (other_seed, other_day) = (builtin_field(8, 3), builtin_field(7, 4));
    let mut diff_seed = 0;
    let mut diff_day = 0;
    // 400 points: 20 in each of 20 cells spread over the globe (−60…54° N, every
    // 13.7 × 20° E). Each lazily built cell needs its 7 × 7 neighbourhood, so 400
    // points in 400 different cells cost 20 times the set-up for the same check
    // (session 24: this test took most of the file's 269 s in a debug build).
    for k in 0..400 {
        let (cell, point) = (k / 20, k % 20);
        let (lat, lon) = (
            -60.0 + 6.0 * cell as f64 + 0.047 * point as f64,
            274.0 * cell as f64 + 0.043 * (point * 7 % 20) as f64,
        );
        let t = a.temperature_at_k(lat, lon);
        assert_eq!(t.to_bits(), b.temperature_at_k(lat, lon).to_bits());
        diff_seed += usize::from((t - other_seed.temperature_at_k(lat, lon)).abs() > 0.5);
        diff_day += usize::from((t - other_day.temperature_at_k(lat, lon)).abs() > 0.5);
    }
    assert!(diff_seed > 40 && diff_day > 40, "{diff_seed} {diff_day}");
}

/// The tool reproduces the README's numbers of the real image.
#[test]
fn stats_tool_reproduces_the_real_image_readme() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/reference/earth-lwir/hi-regional_10p7um_20050919_1315_tb50.png"
    );
    let path = std::path::Path::new(path);
    let path = if path.exists() {
        path.to_path_buf()
    } else {
        std::path::PathBuf::from(
            "/work/shared/reference/earth-lwir/hi-regional_10p7um_20050919_1315_tb50.png",
        )
    };
    let frame = tirroi_host::imaging::image_io::read_frame(&path, Some(16)).expect("real PNG");
    let t: Vec<f64> = frame
        .pixels
        .iter()
        .map(|&v| {
            if v == 0 {
                f64::NAN
            } else {
                f64::from(v) / 50.0
            }
        })
        .collect();
    let s = TextureStats::of(&t, frame.width, frame.height, PATCH_PX_KM).expect("stats");
    assert_eq!(s.step2_k, [0.5, 4.0, 11.0, 44.0]);
    assert!((s.step2_share_over[2] - 0.063).abs() < 0.001);
    assert!((s.step2_share_over[3] - 0.012).abs() < 0.0005);
    assert!((s.step2_share_over[4] - 0.0012).abs() < 0.0001);
    // The fine steps (session 38), measured independently with numpy on the same
    // pixels: 36.2 % over 1 K, 22.9 % over 2 K.
    assert!((s.step2_share_over[0] - 0.362).abs() < 0.001);
    assert!((s.step2_share_over[1] - 0.229).abs() < 0.001);
    assert!(
        (s.spectral_slope + 2.7).abs() < 0.05,
        "{}",
        s.spectral_slope
    );
    assert_eq!(s.bt_k, [259.5, 292.0, 296.0]);
    // Small cold elements (session 38): measured independently with scipy
    // (`ndimage.median_filter` 11 × 11, `ndimage.label` 8-connected): 2.7 small and
    // 0.5 mid-sized per 10⁴ px (scipy's median fills the no-data pixels, ours skips them).
    let [small, mid] = s.cold_features_per_10k_px;
    assert!((2.3..=2.9).contains(&small), "small cold features {small}");
    assert!((0.3..=0.7).contains(&mid), "mid cold features {mid}");
    // Cold structures (session 50), measured independently with scipy / numpy
    // (`ndimage.label` 8-connected on BT ≤ p90 − 10 K, `np.cov` of each group's pixel
    // coordinates): 20 groups of at least 200 px, 0.875 per 10⁴ valid px, 5 of them bands.
    let [per_10k, bands] = s.cold_structures;
    assert!((per_10k - 0.875).abs() < 0.005, "cold structures {per_10k}");
    assert!((bands - 0.25).abs() < 1e-9, "bands {bands}");
}

/// Sets the `bw × bh` block at (`x0`, `y0`) of the row-major image `t` (`w` wide) to
/// `t_k`.
fn paint(t: &mut [f64], w: usize, (x0, y0, bw, bh): (usize, usize, usize, usize), t_k: f64) {
    for y in y0..y0 + bh {
        t[y * w + x0..y * w + x0 + bw].fill(t_k);
    }
}

/// The cold-structure count and band share against a drawn image: a 300 K field of
/// 200 × 200 px (the warm reference given) with, 30 K colder, a 10 × 80 band (elongation
/// about 8), a 25 × 10 block (2.5: no band), a disc of radius 12 (about 1) and a
/// 10 × 10 square (100 px: too small), and a 20 × 20 square only 5 K colder (no cloud
/// top).
#[test]
fn cold_structures_count_masses_and_bands() {
    use tirroi_host::world::earth::texture_stats::cold_structures;
    let (w, h) = (200, 200);
    let mut t = vec![300.0; w * h];
    paint(&mut t, w, (10, 10, 10, 80), 270.0);
    paint(&mut t, w, (40, 10, 25, 10), 270.0);
    paint(&mut t, w, (150, 150, 10, 10), 270.0);
    paint(&mut t, w, (100, 20, 20, 20), 295.0);
    for y in 0..h {
        for x in 0..w {
            if (x as f64 - 100.0).hypot(y as f64 - 120.0) <= 12.0 {
                t[y * w + x] = 270.0;
            }
        }
    }
    let [per_10k, bands] = cold_structures(&t, w, h, 300.0);
    assert!(
        (per_10k - 3.0 * 1e4 / (w * h) as f64).abs() < 1e-9,
        "{per_10k}"
    );
    assert!((bands - 1.0 / 3.0).abs() < 1e-9, "{bands}");
    // No data is not cold: a row of NaN across the band splits it into two
    // groups of 10 × 40 and 10 × 39 px (each a band), and leaves the count's base.
    let mut cut = t.clone();
    cut[50 * w + 10..50 * w + 20].fill(f64::NAN);
    let [per_10k, bands] = cold_structures(&cut, w, h, 300.0);
    assert!(
        (per_10k - 4.0 * 1e4 / (w * h - 10) as f64).abs() < 1e-9,
        "{per_10k}"
    );
    assert!((bands - 0.5).abs() < 1e-9, "{bands}");
    // Without any structure the share is undefined.
    let flat = vec![300.0; w * h];
    let [n, share] = cold_structures(&flat, w, h, 300.0);
    assert_eq!(n, 0.0);
    assert!(share.is_nan());
}

/// The cold-feature count against a brute-force reference on a drawn image: a flat
/// 280 K field (the warm reference) with three cold elements of 1, 9 and 30 px (−25 K
/// below their background), the 30-px one inside a 20 × 20 px cloud at 265 K, and one
/// 9-px element only −10 K deep (not counted), on 64 × 64 px.
#[test]
fn cold_features_count_small_and_mid_elements() {
    use tirroi_host::world::earth::texture_stats::cold_features;
    let (w, h) = (64, 64);
    let mut t = vec![280.0; w * h];
    paint(&mut t, w, (5, 5, 1, 1), 255.0);
    paint(&mut t, w, (20, 5, 3, 3), 255.0);
    paint(&mut t, w, (36, 25, 20, 20), 265.0);
    paint(&mut t, w, (43, 32, 6, 5), 240.0);
    paint(&mut t, w, (10, 40, 3, 3), 270.0);
    let f = cold_features(&t, w, h, 280.0);
    let per = 1e4 / (w * h) as f64;
    assert!((f.per_10k_px[0] - 2.0 * per).abs() < 1e-9, "{f:?}");
    assert!((f.per_10k_px[1] - per).abs() < 1e-9, "{f:?}");
    // Each is 25 K below its local median; one of three lies in the cloud (its median
    // 15 K below the warm reference, over the 5 K of a cloudy background).
    assert_eq!(f.depth_k, [25.0, 25.0], "{f:?}");
    assert!((f.cloudy_share - 1.0 / 3.0).abs() < 1e-9, "{f:?}");
    // No data is neither counted nor a neighbour.
    let mut holes = t.clone();
    holes[5 * w + 5] = f64::NAN;
    let f = cold_features(&holes, w, h, 280.0);
    let per = 1e4 / (w * h - 1) as f64;
    assert!((f.per_10k_px[0] - per).abs() < 1e-9, "{f:?}");
    // Without a feature the share and the depths are undefined.
    let f = cold_features(&vec![280.0; w * h], w, h, 280.0);
    assert_eq!(f.per_10k_px, [0.0, 0.0]);
    assert!(f.cloudy_share.is_nan() && f.depth_k.iter().all(|d| d.is_nan()));
}

/// The cloud-top texture against its definition on a drawn image: a 290 K field (the
/// warm p90) with a 20 × 20 px cloud 30 K colder carrying a ±a K checkerboard, so
/// every 5 × 5 window inside it (13 pixels of one sign, 12 of the other: mean offset
/// a/25) has σ = √(a² − (a/25)²); the windows touching the clear field do not count,
/// nor those over a pixel without data; a scene without cloud tops gives NaN.
#[test]
fn cloud_top_spread_is_measured_inside_the_cloud_only() {
    use tirroi_host::world::earth::texture_stats::cloud_top_sd;
    let (w, h, a) = (64usize, 64usize, 3.0);
    let mut t = vec![290.0; w * h];
    for y in 20..40 {
        for x in 20..40 {
            t[y * w + x] = 260.0 + if (x + y) % 2 == 0 { a } else { -a };
        }
    }
    // A 5×5 window of the checkerboard holds 13 of one sign and 12 of the other.
    let m: f64 = a / 25.0;
    let sd = (a * a - m * m).sqrt();
    let [p50, p90] = cloud_top_sd(&t, w, h, 290.0);
    assert!(
        (p50 - sd).abs() < 1e-9 && (p90 - sd).abs() < 1e-9,
        "{p50} {p90} vs {sd}"
    );
    // A colder pixel inside with no data: the windows over it are left out, the rest
    // unchanged.
    let mut holes = t.clone();
    holes[30 * w + 30] = f64::NAN;
    let [p50, _] = cloud_top_sd(&holes, w, h, 290.0);
    assert!((p50 - sd).abs() < 1e-9, "{p50}");
    // Only 10 K colder than the warm reference counts: a 285 K cloud does not.
    let [p50, p90] = cloud_top_sd(&vec![285.0; w * h], w, h, 290.0);
    assert!(p50.is_nan() && p90.is_nan());
}

/// Acceptance of the issue on noise-free BT at 4 km, quantised to 0.5 K, over 8 patches
/// (2 days × 4 places, 256 × 256 px), ranges unchanged: 2-px step p99 in 9–17 K for
/// every patch; share of steps > 10 K in 0.8–3.5 % for the median and at least 7 of 8
/// patches; spectral slope (8–200 km) in −2.5…−3.3 for the median and at least 7 of 8
/// patches (session 23, with the deep-convective regime and its cloud-top texture:
/// p99 10–14.5 K, share 0.77–3.24 %, slope −2.44…−3.15; the two misses are mild
/// patches at the ranges' edges: share 0.77 % at (20°, 202°) and slope −2.44 at
/// (45°, 330°) on day 0). Session 38 adds the small cold features (`TextureStats::
/// cold_features_per_10k_px`): median within ½–2× the real mild scene's 2.6 per 10⁴ px,
/// present on at least 7 of 8 patches (with the cold fragments and the clear grain at
/// its stated amplitude: 0.3–6.6, median 2.65; slope −2.31…−3.19 (7 of 8 in range), share
/// 1.1–2.7 % (8 of 8), p99 10.5–14 K).
#[test]
fn texture_statistics_within_the_acceptance_ranges() {
    let (mut p99, mut share, mut slope) = (Vec::new(), Vec::new(), Vec::new());
    let mut small_cold = Vec::new();
    for day in 0..2 {
        let f = builtin_field(1, day);
        for &(lat, lon) in &PATCH_CENTRES {
            let s = patch_stats(&f, lat, lon, 256);
            eprintln!(
                "day {day} ({lat}, {lon}): p99 {} K, share > 10 K {:.2} %, slope {:.2}",
                s.step2_k[2],
                100.0 * s.step2_share_over[3],
                s.spectral_slope
            );
            eprintln!(
                "  cold features small / mid per 10⁴ px: {:.1} / {:.1}",
                s.cold_features_per_10k_px[0], s.cold_features_per_10k_px[1]
            );
            small_cold.push(s.cold_features_per_10k_px[0]);
            p99.push(s.step2_k[2]);
            share.push(s.step2_share_over[3]);
            slope.push(s.spectral_slope);
        }
    }
    for p in &p99 {
        assert!((9.0..=17.0).contains(p), "p99 {p} K");
    }
    let shares_in = share
        .iter()
        .filter(|s| (0.008..=0.035).contains(*s))
        .count();
    share.sort_by(f64::total_cmp);
    let s_med = 0.5 * (share[share.len() / 2 - 1] + share[share.len() / 2]);
    eprintln!(
        "median share > 10 K {:.2} %, {shares_in} of 8 patches in range",
        100.0 * s_med
    );
    assert!((0.008..=0.035).contains(&s_med), "median share {s_med}");
    assert!(
        shares_in >= 7,
        "{shares_in} patches with the share in range"
    );
    // Small cold elements (session 38): the real mild scene has 2.6 per 10⁴ px, the
    // texture without its cold fragments had 0.0–0.8 (median 0.0) on these patches.
    small_cold.sort_by(f64::total_cmp);
    let c_med = 0.5 * (small_cold[3] + small_cold[4]);
    eprintln!("median small cold features {c_med:.1} per 10⁴ px");
    assert!(
        (1.3..=5.2).contains(&c_med),
        "median small cold features {c_med}"
    );
    assert!(
        small_cold.iter().filter(|&&c| c > 0.0).count() >= 7,
        "cold fragments missing on patches: {small_cold:?}"
    );
    let slopes_in = slope.iter().filter(|k| (-3.3..=-2.5).contains(*k)).count();
    slope.sort_by(f64::total_cmp);
    let k = 0.5 * (slope[slope.len() / 2 - 1] + slope[slope.len() / 2]);
    eprintln!("median slope {k:.2}, {slopes_in} of 8 patches in range");
    assert!((-3.3..=-2.5).contains(&k), "median slope {k}");
    assert!(
        slopes_in >= 7,
        "{slopes_in} patches with the slope in range"
    );
}

/// No cell's cloud-threshold shift sits at its bound (session 38): a cell whose flux
/// the shift cannot reach used to go to ±12 σ (2.2 % of the cells of field (7201, 0)),
/// 12 σ from its neighbours' shifts, and the blended threshold cut the neighbours'
/// clouds along the border (straight-edged blocks). Now it stops just short of the
/// reachable end; on 300 cells of field (1, 0) none is within 0.5 σ of the bound
/// (at a 2.2 % rate the old solver puts none there with probability 0.1 %).
#[test]
fn threshold_shifts_stay_off_their_bound() {
    use tirroi_host::world::earth::clouds::MAX_THRESHOLD_SHIFT_SIGMA;
    let f = builtin_field(1, 0);
    let mut worst = 0.0f64;
    for r in (35..145).step_by(11) {
        for c in (0..360).step_by(12) {
            let (shift_sigma, s) = f.cell_balance(r, c);
            assert!(s.is_finite() && s > 0.0);
            worst = worst.max(shift_sigma.abs());
        }
    }
    eprintln!("largest |shift| {worst:.2} σ of {MAX_THRESHOLD_SHIFT_SIGMA}");
    assert!(
        worst < MAX_THRESHOLD_SHIFT_SIGMA - 0.5,
        "a cell's shift at {worst} σ"
    );
}

/// The regional cloud balance (`earth_model.regional_balance_cells`, here 1, with the
/// cloud-bound fragments, as the `realistic` presets render): each cell keeps the flux it is given (what its regional shift
/// renders, within 0.5 % by the same independent sampling), single cells move from the
/// grid's as the masses do, and a region's mean stays near the grid's: over 6 × 6
/// cells at 40 places (latitudes −60…60°) and two days, the signed mean departure
/// under 0.5 % and the largest under 4 % (measured +0.17 % and 2.4 %; the built-in
/// grid's zonal profiles are themselves stated to about ±4 %; the mean of the shifts
/// alone, without the window's Newton step, gave −0.96 % and 4.5 %).
#[test]
fn regional_balance_keeps_the_cells_and_the_regions_flux() {
    let mut worst_cell = 0.0f64;
    let mut region_errors = Vec::new();
    let mut largest_cell_move = 0.0f64;
    for day in 0..2 {
        let f = builtin_field(1, day)
            .with_regional_balance(1)
            .with_cloud_fragments(true);
        for k in 0..20usize {
            let (row, col) = (30 + (k * 37) % 120, (k * 97) % 354);
            let (mut kept, mut grid) = (0.0, 0.0);
            for r in row..row + 6 {
                for c in col..col + 6 {
                    let (kf, gf) = (
                        f64::from(f.cell_flux_w_m2(r, c)),
                        f64::from(f.grid_flux_w_m2(r, c)),
                    );
                    kept += kf;
                    grid += gf;
                    largest_cell_move = largest_cell_move.max((kf / gf - 1.0).abs());
                }
            }
            region_errors.push(kept / grid - 1.0);
            if k % 5 == 0 {
                worst_cell = worst_cell.max(cell_flux_error(&f, row + 2, col + 3));
            }
        }
    }
    let mean = region_errors.iter().sum::<f64>() / region_errors.len() as f64;
    let worst = region_errors.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    eprintln!(
        "regional balance: worst cell {:.3} %, 6x6 regions mean {:+.3} %, worst {:.3} %, largest cell move {:.1} %",
        100.0 * worst_cell,
        100.0 * mean,
        100.0 * worst,
        100.0 * largest_cell_move
    );
    assert!(worst_cell < 0.005, "worst cell flux error {worst_cell}");
    assert!(mean.abs() < 0.005, "regions' mean departure {mean}");
    assert!(worst < 0.04, "worst region departure {worst}");
    assert!(
        largest_cell_move > 0.01,
        "cells did not move: {largest_cell_move}"
    );
}

/// The `realistic` presets' Earth (cloud tops at 5 K per σ, the regional balance over
/// 3 × 3 cells, cloud-bound fragments) gathers its cold cover into masses as the real
/// image does (session 51): cold structures (≥ 200 px at least 10 K below the warm p90)
/// on the 512-px patches of `tirroi earth-texture --stats` (4 places, days 0–1), median
/// within ½–2× the real mild scene's 0.88 per 10⁴ px (measured 0.94, range 0.19–1.53;
/// each cell balanced on its own gave a median of 0.27), and the edge statistics stay
/// in the acceptance ranges of `texture_statistics_within_the_acceptance_ranges` (2-px
/// p99 9–17 K on every patch, the spectral slope within −3.3…−2.5 on at least 7 of 8).
/// Its small cold elements lie among clouds as the real ones (session 52): the median
/// patch's share of compact cold features on a background ≥ 5 K below the warm
/// reference at least 0.75 (real 0.96; measured 43–98 %, median 87 %; the session-38
/// fragments anywhere: 4–73 %, median 14 %), their depth below the local median p50
/// within 3 K of the real 20.5 K (measured 20–23.5 K), and their number's median
/// within ½–2× the real 2.6 per 10⁴ px (3.85).
#[test]
fn realistic_earth_has_cloud_masses_with_cold_fragments_among_them() {
    let (mut masses, mut slopes_in) = (Vec::new(), 0);
    let (mut cloudy, mut depth, mut small) = (Vec::new(), Vec::new(), Vec::new());
    for day in 0..2 {
        let f = builtin_field(1, day)
            .with_cloud_top_texture(5.0)
            .with_regional_balance(1)
            .with_cloud_fragments(true);
        for &(lat, lon) in &PATCH_CENTRES {
            let s = patch_stats(&f, lat, lon, 512);
            eprintln!(
                "day {day} ({lat}, {lon}): cold structures {:.2} per 10⁴ px, bands {:.0} %, p99 {} K, slope {:.2}; cold features {:.1} per 10⁴ px, {:.0} % among clouds, depth p50 {:.1} K",
                s.cold_structures[0],
                100.0 * s.cold_structures[1],
                s.step2_k[2],
                s.spectral_slope,
                s.cold_features_per_10k_px[0],
                100.0 * s.cold_feature_cloudy_share,
                s.cold_feature_depth_k[0]
            );
            masses.push(s.cold_structures[0]);
            cloudy.push(s.cold_feature_cloudy_share);
            depth.push(s.cold_feature_depth_k[0]);
            small.push(s.cold_features_per_10k_px[0]);
            assert!(
                (9.0..=17.0).contains(&s.step2_k[2]),
                "p99 {} K",
                s.step2_k[2]
            );
            slopes_in += usize::from((-3.3..=-2.5).contains(&s.spectral_slope));
        }
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        0.5 * (v[3] + v[4])
    };
    let cloudy_median = median(&mut cloudy);
    assert!(
        cloudy_median >= 0.75,
        "cold features among clouds {cloudy:?}"
    );
    let depth_median = median(&mut depth);
    assert!(
        (depth_median - 20.5).abs() <= 3.0,
        "cold features' depth {depth:?}"
    );
    let small_median = median(&mut small);
    assert!(
        (1.3..=5.2).contains(&small_median),
        "small cold features {small:?}"
    );
    let masses_median = median(&mut masses);
    assert!(
        (0.44..=1.76).contains(&masses_median),
        "median cold structures {masses:?}"
    );
    assert!(
        slopes_in >= 7,
        "{slopes_in} patches with the slope in range"
    );
}
