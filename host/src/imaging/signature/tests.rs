//! The signature against the real frame: the committed numbers are what the fit gives,
//! and realisations carry the fitted statistics without being the frame.

use std::path::PathBuf;

use rayon::prelude::*;

use super::fit::fit_frame;
use super::*;
use crate::imaging::fits::read_fits;

/// The real frame: `$TIRROI_REFERENCE_DIR/hayabusa2-tir/dark_20180629_083003.fit`, by
/// default `shared/reference/` beside the repository (read-only data, not in the repo).
fn real_frame() -> Option<(crate::imaging::fits::FitsImage, PathBuf)> {
    let dir = std::env::var_os("TIRROI_REFERENCE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference")
        });
    let path = dir.join("hayabusa2-tir/dark_20180629_083003.fit");
    if !path.exists() {
        eprintln!(
            "SKIPPED: {} not found (set TIRROI_REFERENCE_DIR to the reference data)",
            path.display()
        );
        return None;
    }
    Some((read_fits(&path).unwrap(), path))
}

fn area_of(img: &crate::imaging::fits::FitsImage) -> Vec<f64> {
    let [x0, y0, w, h] = TIR_EFFECTIVE_AREA_PX;
    (y0..y0 + h)
        .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
        .map(|(x, y)| img.at(x, y))
        .collect()
}

fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// A realisation as the camera would read it: the calibration frame's mean level plus
/// the signature.
fn synthetic_frame(cal: &Calibration, seed: u64) -> Vec<f64> {
    let [_, _, w, h] = cal.source.area_px;
    let r = cal.realise_dn(w, h, seed);
    r.offset
        .iter()
        .map(|o| cal.fit.shading.mean_dn + o)
        .collect()
}

#[test]
fn committed_calibration_is_what_the_fit_command_gives() {
    let Some((img, path)) = real_frame() else {
        return;
    };
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let fitted = Calibration::from_fits(&img, &name, TIR_EFFECTIVE_AREA_PX).unwrap();
    // Through TOML as the command writes it.
    let written = Calibration::from_toml(&fitted.to_toml().unwrap()).unwrap();
    let committed = Calibration::hayabusa2_tir().unwrap();
    assert_eq!(
        written, committed,
        "rerun `tirroi sensor-fit` and commit the file"
    );
    // And the file is exactly the command's output.
    assert_eq!(fitted.to_toml().unwrap(), HAYABUSA2_TIR_DARK_TOML);
    // The README's independent summary of the same area: mean −373 DN.
    assert!((committed.fit.shading.mean_dn + 373.0).abs() < 0.5);
}

#[test]
fn realisations_are_not_the_frame() {
    let Some((img, _)) = real_frame() else {
        return;
    };
    let cal = Calibration::hayabusa2_tir().unwrap();
    let [_, _, w, h] = TIR_EFFECTIVE_AREA_PX;
    let (_, real) = fit_frame(&area_of(&img), w, h).unwrap();
    let mut worst: f64 = 0.0;
    for seed in 1..=5 {
        let (_, syn) = fit_frame(&synthetic_frame(&cal, seed), w, h).unwrap();
        let r = pearson(&syn.residual_dn, &real.residual_dn);
        worst = worst.max(r.abs());
    }
    eprintln!("largest |correlation| of a realisation's residual with the real one: {worst:.4}");
    assert!(worst < 0.2, "{worst}");
}

#[test]
fn realisations_keep_the_shading_and_column_pattern_within_10_percent() {
    let cal = Calibration::hayabusa2_tir().unwrap();
    let [_, _, w, h] = cal.source.area_px;
    let (mut worst_amp, mut worst_col): (f64, f64) = (0.0, 0.0);
    for seed in 0..10 {
        let (fit, _) = fit_frame(&synthetic_frame(&cal, seed), w, h).unwrap();
        let amp = fit.shading.amplitude_dn / cal.fit.shading.amplitude_dn - 1.0;
        let col = fit.columns.sigma_dn / cal.fit.columns.sigma_dn - 1.0;
        worst_amp = worst_amp.max(amp.abs());
        worst_col = worst_col.max(col.abs());
        // The correlation along x is the fitted one (a loose check: 328 columns).
        assert!(
            (fit.columns.lag1_correlation - cal.fit.columns.lag1_correlation).abs() < 0.2,
            "{:?}",
            fit.columns
        );
    }
    eprintln!(
        "largest deviation over 10 realisations: shading amplitude {:.2} %, column sigma {:.2} %",
        100.0 * worst_amp,
        100.0 * worst_col
    );
    assert!(worst_amp < 0.10, "{worst_amp}");
    assert!(worst_col < 0.10, "{worst_col}");
}

/// Spread of the `cell`×`cell` block means of what the fit leaves (shading and lines
/// out, outliers clipped at 5 robust σ), DN: the texture a detector's cells see.
fn cell_mean_spread_dn(frame: &[f64], w: usize, h: usize, cell: usize) -> f64 {
    let (fit, maps) = fit_frame(frame, w, h).unwrap();
    let mut e = maps.residual_dn.clone();
    let (col, row) = fit::line_medians(&e, w, h);
    let clip = fit.pixels.outlier_k_sigma * fit.pixels.sigma_dn;
    for (i, v) in e.iter_mut().enumerate() {
        *v = (*v - col[i % w] - row[i / w]).clamp(-clip, clip);
    }
    let means: Vec<f64> = (0..h / cell)
        .flat_map(|cy| (0..w / cell).map(move |cx| (cx, cy)))
        .map(|(cx, cy)| {
            let s: f64 = (0..cell)
                .flat_map(|y| (0..cell).map(move |x| (x, y)))
                .map(|(x, y)| e[(cy * cell + y) * w + cx * cell + x])
                .sum();
            s / (cell * cell) as f64
        })
        .collect();
    let m = means.iter().sum::<f64>() / means.len() as f64;
    (means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / means.len() as f64).sqrt()
}

/// The cell-scale field: realisations, fitted as the real frame is, show its σ and
/// correlation length, and 8-px (and 16-px) cell means scatter as the real frame's do
/// (2.2 DN; white pixels alone would give 0.4 DN, the signature without the field did).
#[test]
fn realisations_keep_the_cell_scale_field_within_10_percent() {
    let cal = Calibration::hayabusa2_tir().unwrap();
    let [_, _, w, h] = cal.source.area_px;
    let want = &cal.fit.field;
    assert!(
        want.sigma_dn > 1.0 && want.correlation_length_px > 8.0,
        "{want:?}"
    );
    let runs = 8;
    let (mut sigma, mut length, mut cell8, mut cell16) = (0.0, 0.0, 0.0, 0.0);
    for seed in 0..runs {
        let frame = synthetic_frame(&cal, 500 + seed);
        let (fit, _) = fit_frame(&frame, w, h).unwrap();
        sigma += fit.field.sigma_dn / runs as f64;
        length += fit.field.correlation_length_px / runs as f64;
        cell8 += cell_mean_spread_dn(&frame, w, h, 8) / runs as f64;
        cell16 += cell_mean_spread_dn(&frame, w, h, 16) / runs as f64;
    }
    let Some((img, _)) = real_frame() else {
        // Without the real frame: the fitted numbers in the committed file.
        assert!(
            (sigma / want.sigma_dn - 1.0).abs() < 0.10,
            "{sigma} vs {want:?}"
        );
        return;
    };
    let real = area_of(&img);
    let (real8, real16) = (
        cell_mean_spread_dn(&real, w, h, 8),
        cell_mean_spread_dn(&real, w, h, 16),
    );
    eprintln!(
        "field: sigma {sigma:.3} DN (real {:.3}), length {length:.1} px (real {:.1}); \
         8-px cell means {cell8:.3} DN (real {real8:.3}), 16-px {cell16:.3} DN (real {real16:.3})",
        want.sigma_dn, want.correlation_length_px
    );
    assert!(
        (sigma / want.sigma_dn - 1.0).abs() < 0.10,
        "{sigma} vs {want:?}"
    );
    assert!(
        (length / want.correlation_length_px - 1.0).abs() < 0.10,
        "{length} vs {want:?}"
    );
    assert!((cell8 / real8 - 1.0).abs() < 0.10, "{cell8} vs {real8}");
    assert!((cell16 / real16 - 1.0).abs() < 0.10, "{cell16} vs {real16}");
}

/// The field fit against a known answer: a field made with a known Gaussian
/// autocorrelation and no fitting in the way is found back.
#[test]
fn field_fit_recovers_a_known_gaussian_field() {
    let (w, h) = (256, 256);
    let mut sigma = 0.0;
    let mut length = 0.0;
    for seed in 0..4 {
        // σ 3 DN, ℓ 6 px: short against the frame, so no fit shortens it.
        let v: Vec<f64> = gaussian_blur(
            &{
                let mut rng = Pcg64Mcg::seed_from_u64(seed);
                (0..w * h)
                    .map(|_| rng.sample::<f64, _>(StandardNormal))
                    .collect::<Vec<_>>()
            },
            w,
            h,
            3.0,
        );
        let sd = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        let v: Vec<f64> = v.iter().map(|x| 3.0 * x / sd).collect();
        let f = fit::fit_field(&v, w, h, f64::INFINITY);
        sigma += f.sigma_dn / 4.0;
        length += f.correlation_length_px / 4.0;
    }
    assert!((sigma / 3.0 - 1.0).abs() < 0.05, "{sigma}");
    assert!((length / 6.0 - 1.0).abs() < 0.05, "{length}");
}

#[test]
fn hot_pixel_count_within_10_percent_over_100_realisations() {
    let cal = Calibration::hayabusa2_tir().unwrap();
    let [_, _, w, h] = cal.source.area_px;
    let total: usize = (0..100u64)
        .into_par_iter()
        .map(|seed| {
            fit_frame(&synthetic_frame(&cal, 1000 + seed), w, h)
                .unwrap()
                .0
                .pixels
                .hot_count
        })
        .sum();
    let mean = total as f64 / 100.0;
    let want = cal.fit.pixels.hot_count as f64;
    eprintln!("hot pixels: {mean:.2} per realisation (calibration frame {want})");
    assert!((mean / want - 1.0).abs() < 0.10, "{mean} vs {want}");
}

#[test]
fn radiance_maps_follow_the_gain_and_other_sizes_work() {
    let cal = Calibration::hayabusa2_tir().unwrap();
    let dn = cal.realise_dn(328, 248, 7);
    let sig = cal.realise(328, 248, 7);
    let g = cal.gain.dn_per_w_m2_sr;
    for i in [0, 1000, 40_000, 81_343] {
        assert!((f64::from(sig.offset_w_m2_sr[i]) * g - dn.offset[i]).abs() < 1e-3);
    }
    // The gain map: 1 + p/S̄, σ = fixed pixel σ / |S̄| (about 0.8 %).
    let n = sig.gain.len() as f64;
    let m = sig.gain.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let sd = (sig
        .gain
        .iter()
        .map(|&x| (f64::from(x) - m).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let want = cal.fixed_pixel_sigma_dn() / cal.fit.shading.mean_dn.abs();
    assert!(
        (m - 1.0).abs() < 1e-3 && (sd / want - 1.0).abs() < 0.05,
        "{m} {sd} {want}"
    );
    // Same seed, same maps; another seed, another.
    assert_eq!(cal.realise(328, 248, 7), sig);
    assert_ne!(cal.realise(328, 248, 8), sig);
    // A 640 × 512 frame: hot pixels scale with the area (4.03×).
    let (w, h) = (640, 512);
    let big = cal.realise_dn(w, h, 3);
    let frame: Vec<f64> = big
        .offset
        .iter()
        .map(|o| cal.fit.shading.mean_dn + o)
        .collect();
    let (fit, _) = fit_frame(&frame, w, h).unwrap();
    let want = cal.fit.pixels.hot_count as f64 * (w * h) as f64 / (328.0 * 248.0);
    assert!(
        (fit.pixels.hot_count as f64 - want).abs() < 4.0 * want.sqrt(),
        "{}",
        fit.pixels.hot_count
    );
    assert!((fit.shading.amplitude_dn / cal.fit.shading.amplitude_dn - 1.0).abs() < 0.1);
}

#[test]
fn apply_adds_the_offset_in_signal_units_and_multiplies_the_gain() {
    let sig = SensorSignature {
        width: 2,
        height: 1,
        offset_w_m2_sr: vec![1.0, -2.0],
        gain: vec![1.0, 1.01],
    };
    let mut s = vec![10.0f32, 10.0];
    sig.apply(&mut s, std::f64::consts::PI).unwrap();
    assert!((s[0] - (10.0 + std::f32::consts::PI)).abs() < 1e-5);
    assert!((s[1] - (10.1 - 2.0 * std::f32::consts::PI)).abs() < 1e-5);
    assert!(sig.apply(&mut [0.0; 3], 1.0).is_err());
}
