//! Pixel-scale statistics of a brightness-temperature image ([`TextureStats`]): the
//! numbers `shared/reference/earth-lwir/README.md` gives for real longwave imagery at
//! 4 km per pixel, so the cloud texture can be checked against them
//! (`tirroi earth-texture --stats`).

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use super::clouds::{CloudField, KM_PER_DEG};

/// Quantisation step of the real 10.7 µm data above 242 K (GINI counts), K.
pub const REAL_QUANTUM_K: f64 = 0.5;
/// Pixel spacing of the real imagery and of our camera from 4 500 km, km.
pub const PATCH_PX_KM: f64 = 4.0;
/// Wavelength band of the spectral slope fit, km.
pub const SLOPE_BAND_KM: (f64, f64) = (8.0, 200.0);
/// Logarithmic frequency bins over [`SLOPE_BAND_KM`] for the ring average.
const SLOPE_BINS: usize = 12;
/// The 2-px steps whose shares [`TextureStats::step2_share_over`] counts, K: 1 and 2 K
/// (the grain of trade cumulus and clear-sky texture, session 38), 5, 10 and 20 K (the
/// README's cloud edges).
pub const STEP2_SHARE_K: [f64; 5] = [1.0, 2.0, 5.0, 10.0, 20.0];
/// A pixel is part of a cold feature when it is this much colder than the median of
/// its [`LOCAL_MEDIAN_PX`]² neighbourhood, K: deeper than a low cloud's edge step (the
/// real mild scene's 2-px p99 is 11 K), as deep as a small cold cloud element that a
/// detector can take for a target's outline.
pub const COLD_FEATURE_DEPTH_K: f64 = 16.0;
/// Side of the neighbourhood whose median is the local background, px (44 km at 4 km:
/// wider than a small cloud element, narrower than a cloud deck).
pub const LOCAL_MEDIAN_PX: usize = 11;
/// Largest small cold feature, px (≤ 12 px: one to a few pixels across); larger ones
/// up to [`MID_FEATURE_MAX_PX`] count as mid-sized.
pub const SMALL_FEATURE_MAX_PX: usize = 12;
/// Largest mid-sized cold feature, px.
pub const MID_FEATURE_MAX_PX: usize = 60;
/// A cold feature whose local median lies this far below the warm reference sits among
/// clouds, K: half the low clouds' shallowest depth ([`super::clouds::MIN_CLOUD_COLD_K`]
/// is 15.5 K) and 10 real quantisation steps above the clear sea's own spread.
pub const CLOUDY_BACKGROUND_K: f64 = 5.0;
/// The image's warm reference, its clear sky: the brightness temperature at this
/// quantile of its valid pixels (p90: cloud-free surface in any scene with less than
/// 90 % cloud cover).
pub const WARM_QUANTILE: f64 = 0.9;
/// A pixel is under cloud top when it is at least this much colder than the warm
/// reference, K (the shallowest low cloud, `clouds::MIN_CLOUD_COLD_K`, is 15.5 K).
pub const CLOUD_TOP_DEPTH_K: f64 = 10.0;
/// Side of the windows whose spread is a cloud top's texture, px (20 km at 4 km).
pub const CLOUD_TOP_WINDOW_PX: usize = 5;
/// The band of intermediate levels below the warm reference, K: thin cloud, cloud
/// fringes and mixed pixels, neither clear surface nor cloud top.
pub const INTERMEDIATE_BAND_K: (f64, f64) = (2.0, 15.0);
/// Least size of a cold structure, px (200 px at 4 km: 3 200 km², about 14 px across):
/// a cloud mass or band at the scale of the camera's frame, large enough to fill
/// several of `auto-v2`'s 8-px cells beside a target and to be cut by the frame's
/// side as a body is (session 50: such masses were a retrained cell forest's false
/// alarms on the real Earth).
pub const COLD_STRUCTURE_MIN_PX: usize = 200;
/// A cold structure is a band when its pixels' spread along their main axis is at
/// least this many times the spread across (the square root of the ratio of the
/// coordinates' covariance eigenvalues; a uniform L × W rectangle gives about L / W).
pub const BAND_ELONGATION: f64 = 3.0;

/// Statistics of one image (see the README's table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureStats {
    /// |T(x+2) − T(x)| along rows: p50, p90, p99 and max, K.
    pub step2_k: [f64; 4],
    /// Share of those steps above each of [`STEP2_SHARE_K`] (fractions, 0..=1).
    pub step2_share_over: [f64; STEP2_SHARE_K.len()],
    /// Slope of the 2-D ring-averaged power spectrum over [`SLOPE_BAND_KM`].
    pub spectral_slope: f64,
    /// Brightness temperature p1, p50, p99, K.
    pub bt_k: [f64; 3],
    /// Cold features per 10⁴ valid pixels: 8-connected groups of pixels more than
    /// [`COLD_FEATURE_DEPTH_K`] below their local median, small (≤
    /// [`SMALL_FEATURE_MAX_PX`] px) and mid-sized (≤ [`MID_FEATURE_MAX_PX`] px).
    pub cold_features_per_10k_px: [f64; 2],
    /// Share of those features (both sizes) whose local median at their deepest pixel
    /// lies at least [`CLOUDY_BACKGROUND_K`] below the warm reference: cold elements
    /// among clouds rather than over the clear surface (0..=1, NaN without a feature).
    pub cold_feature_cloudy_share: f64,
    /// Depth of those features' deepest pixel below its local median, p50 and p90, K
    /// (NaN without a feature).
    pub cold_feature_depth_k: [f64; 2],
    /// Texture of cloud tops: the standard deviation of the brightness temperature in
    /// the [`CLOUD_TOP_WINDOW_PX`]² windows whose pixels are all valid and at least
    /// [`CLOUD_TOP_DEPTH_K`] below the warm reference ([`WARM_QUANTILE`]), p50 and p90,
    /// K (NaN without such a window).
    pub cloud_top_sd_k: [f64; 2],
    /// Share of the valid pixels in [`INTERMEDIATE_BAND_K`] below the warm reference
    /// (0..=1): how much of the scene lies between the clear surface and the cloud tops.
    pub intermediate_share: f64,
    /// Cold structures: 8-connected groups of at least [`COLD_STRUCTURE_MIN_PX`] valid
    /// pixels each at least [`CLOUD_TOP_DEPTH_K`] below the warm reference, per 10⁴
    /// valid pixels, and the share of them that are bands ([`BAND_ELONGATION`];
    /// 0..=1, NaN without a structure).
    pub cold_structures: [f64; 2],
    /// Number of 2-px steps measured.
    pub steps: usize,
}

/// The value at quantile `q` (0..=1) of sorted `v` (nearest rank).
fn pct(v: &[f64], q: f64) -> f64 {
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i]
}

impl TextureStats {
    /// Statistics of the row-major `w` × `h` image `t_k` (K, NaN = no data) with
    /// pixels `px_km` apart: steps between valid pixel pairs only, percentiles over the
    /// valid pixels, the spectrum on the largest all-valid rectangle (as the README's
    /// numbers were measured). `None` when that rectangle is smaller than 16 × 16.
    pub fn of(t_k: &[f64], w: usize, h: usize, px_km: f64) -> Option<TextureStats> {
        if w < 16 || h < 16 || t_k.len() != w * h {
            return None;
        }
        let mut steps: Vec<f64> = Vec::with_capacity((w - 2) * h);
        for row in t_k.chunks_exact(w) {
            for x in 0..w - 2 {
                let d = (row[x + 2] - row[x]).abs();
                if d.is_finite() {
                    steps.push(d);
                }
            }
        }
        let valid: Vec<bool> = t_k.iter().map(|v| v.is_finite()).collect();
        let (x0, y0, rw, rh) = largest_valid_rectangle(&valid, w, h);
        if rw < 16 || rh < 16 || steps.is_empty() {
            return None;
        }
        let rect: Vec<f64> = (y0..y0 + rh)
            .flat_map(|y| t_k[y * w + x0..y * w + x0 + rw].iter().copied())
            .collect();
        steps.sort_by(f64::total_cmp);
        let over =
            |lim: f64| steps.iter().filter(|&&s| s > lim).count() as f64 / steps.len() as f64;
        let mut bt: Vec<f64> = t_k.iter().copied().filter(|v| v.is_finite()).collect();
        bt.sort_by(f64::total_cmp);
        // The clear surface: the reference of the cloud-top statistics.
        let warm_k = pct(&bt, WARM_QUANTILE);
        let features = cold_features(t_k, w, h, warm_k);
        Some(TextureStats {
            step2_k: [
                pct(&steps, 0.5),
                pct(&steps, 0.9),
                pct(&steps, 0.99),
                steps[steps.len() - 1],
            ],
            step2_share_over: STEP2_SHARE_K.map(over),
            spectral_slope: spectral_slope(&rect, rw, rh, px_km),
            bt_k: [pct(&bt, 0.01), pct(&bt, 0.5), pct(&bt, 0.99)],
            cold_features_per_10k_px: features.per_10k_px,
            cold_feature_cloudy_share: features.cloudy_share,
            cold_feature_depth_k: features.depth_k,
            cloud_top_sd_k: cloud_top_sd(t_k, w, h, warm_k),
            intermediate_share: bt
                .iter()
                .filter(|&&t| {
                    (INTERMEDIATE_BAND_K.0..=INTERMEDIATE_BAND_K.1).contains(&(warm_k - t))
                })
                .count() as f64
                / bt.len() as f64,
            cold_structures: cold_structures(t_k, w, h, warm_k),
            steps: steps.len(),
        })
    }
}

/// p50 and p90 of the brightness temperature's standard deviation over the
/// [`CLOUD_TOP_WINDOW_PX`]² windows (every position) of the row-major `w` × `h` image
/// `t_k` whose pixels are all valid and at least [`CLOUD_TOP_DEPTH_K`] below `warm_k`,
/// K; NaN for both without one (see [`TextureStats::cloud_top_sd_k`]).
pub fn cloud_top_sd(t_k: &[f64], w: usize, h: usize, warm_k: f64) -> [f64; 2] {
    let n = CLOUD_TOP_WINDOW_PX;
    let top = warm_k - CLOUD_TOP_DEPTH_K;
    let mut sds = Vec::new();
    for y in 0..h.saturating_sub(n - 1) {
        'window: for x in 0..w.saturating_sub(n - 1) {
            let (mut s, mut s2) = (0.0, 0.0);
            for yy in y..y + n {
                for &t in &t_k[yy * w + x..yy * w + x + n] {
                    // No data (NaN) leaves the window out too.
                    if t.is_nan() || t > top {
                        continue 'window;
                    }
                    s += t;
                    s2 += t * t;
                }
            }
            let m = (n * n) as f64;
            sds.push((s2 / m - (s / m).powi(2)).max(0.0).sqrt());
        }
    }
    if sds.is_empty() {
        return [f64::NAN; 2];
    }
    sds.sort_by(f64::total_cmp);
    [pct(&sds, 0.5), pct(&sds, 0.9)]
}

/// The small and mid-sized cold features of an image ([`cold_features`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColdFeatures {
    /// Per 10⁴ valid pixels, small and mid-sized ([`TextureStats::cold_features_per_10k_px`]).
    pub per_10k_px: [f64; 2],
    /// Share among clouds ([`TextureStats::cold_feature_cloudy_share`]).
    pub cloudy_share: f64,
    /// Depth below the local median, p50 and p90, K ([`TextureStats::cold_feature_depth_k`]).
    pub depth_k: [f64; 2],
}

/// Small and mid-sized cold features of the row-major `w` × `h` image `t_k` (K, NaN =
/// no data) with warm reference `warm_k` (see [`TextureStats::cold_features_per_10k_px`]):
/// the local median over the valid pixels of each window, then 8-connected groups of
/// the pixels below it by more than [`COLD_FEATURE_DEPTH_K`], sized by flood fill;
/// each group's deepest pixel gives its depth and its background (the local median
/// there).
pub fn cold_features(t_k: &[f64], w: usize, h: usize, warm_k: f64) -> ColdFeatures {
    let r = LOCAL_MEDIAN_PX / 2;
    let mut cold = vec![false; w * h];
    let mut median_k = vec![f64::NAN; w * h];
    let mut window: Vec<f64> = Vec::with_capacity(LOCAL_MEDIAN_PX * LOCAL_MEDIAN_PX);
    let mut valid = 0usize;
    for y in 0..h {
        for x in 0..w {
            let t = t_k[y * w + x];
            if !t.is_finite() {
                continue;
            }
            valid += 1;
            window.clear();
            for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
                let line = &t_k[yy * w..yy * w + w];
                window.extend(
                    line[x.saturating_sub(r)..(x + r + 1).min(w)]
                        .iter()
                        .filter(|v| v.is_finite()),
                );
            }
            let mid = window.len() / 2;
            let (_, median, _) = window.select_nth_unstable_by(mid, f64::total_cmp);
            median_k[y * w + x] = *median;
            cold[y * w + x] = t < *median - COLD_FEATURE_DEPTH_K;
        }
    }
    let mut counts = [0usize; 2];
    let mut cloudy = 0usize;
    let mut depths = Vec::new();
    for_each_group(&mut cold, w, h, |group| {
        if group.len() > MID_FEATURE_MAX_PX {
            return;
        }
        counts[usize::from(group.len() > SMALL_FEATURE_MAX_PX)] += 1;
        let (depth, background) = group
            .iter()
            .map(|&i| (median_k[i] - t_k[i], median_k[i]))
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f64::NAN, f64::NAN));
        depths.push(depth);
        cloudy += usize::from(warm_k - background >= CLOUDY_BACKGROUND_K);
    });
    let per = 1e4 / valid.max(1) as f64;
    depths.sort_by(f64::total_cmp);
    let (cloudy_share, depth_k) = if depths.is_empty() {
        (f64::NAN, [f64::NAN; 2])
    } else {
        (
            cloudy as f64 / depths.len() as f64,
            [pct(&depths, 0.5), pct(&depths, 0.9)],
        )
    };
    ColdFeatures {
        per_10k_px: [counts[0] as f64 * per, counts[1] as f64 * per],
        cloudy_share,
        depth_k,
    }
}

/// Each 8-connected group of the `true` pixels of the row-major `w` × `h` `mask`, as
/// its pixel indices (flood fill; the mask is cleared as the groups are taken). The
/// callers build `mask` with `w × h` entries.
fn for_each_group(mask: &mut [bool], w: usize, h: usize, mut each: impl FnMut(&[usize])) {
    debug_assert_eq!(mask.len(), w * h);
    let mut stack = Vec::new();
    let mut group = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] {
            continue;
        }
        mask[start] = false;
        stack.push(start);
        group.clear();
        while let Some(i) = stack.pop() {
            group.push(i);
            let (x, y) = (i % w, i / w);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    let j = yy * w + xx;
                    if mask[j] {
                        mask[j] = false;
                        stack.push(j);
                    }
                }
            }
        }
        each(&group);
    }
}

/// Cold structures of the row-major `w` × `h` image `t_k` (K, NaN = no data) with
/// warm reference `warm_k`: per 10⁴ valid pixels, and the share of bands (see
/// [`TextureStats::cold_structures`]).
pub fn cold_structures(t_k: &[f64], w: usize, h: usize, warm_k: f64) -> [f64; 2] {
    let top = warm_k - CLOUD_TOP_DEPTH_K;
    let valid = t_k.iter().filter(|t| t.is_finite()).count();
    // NaN compares false: no data is never cold.
    let mut cold: Vec<bool> = t_k.iter().map(|&t| t <= top).collect();
    let (mut structures, mut bands) = (0usize, 0usize);
    for_each_group(&mut cold, w, h, |group| {
        if group.len() < COLD_STRUCTURE_MIN_PX {
            return;
        }
        structures += 1;
        // The coordinates' covariance and its eigenvalues (a symmetric 2 × 2).
        let n = group.len() as f64;
        let (mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &i in group {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            (sx, sy) = (sx + x, sy + y);
            (sxx, syy, sxy) = (sxx + x * x, syy + y * y, sxy + x * y);
        }
        let (mx, my) = (sx / n, sy / n);
        let (cxx, cyy, cxy) = (sxx / n - mx * mx, syy / n - my * my, sxy / n - mx * my);
        let half_trace = 0.5 * (cxx + cyy);
        let root = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
        let (major, minor) = (half_trace + root, (half_trace - root).max(1e-12));
        if (major / minor).sqrt() >= BAND_ELONGATION {
            bands += 1;
        }
    });
    let share = if structures == 0 {
        f64::NAN
    } else {
        bands as f64 / structures as f64
    };
    [structures as f64 * 1e4 / valid.max(1) as f64, share]
}

/// Slope of log power vs log frequency of the 2-D ring-averaged power spectrum of the
/// image (mean removed, Hann window on both axes) over wavelengths [`SLOPE_BAND_KM`]:
/// the power of all 2-D frequencies is averaged in 12 logarithmic bins of |f| and a
/// least-squares line fitted through the bins' (log mean |f|, log mean power).
pub fn spectral_slope(t_k: &[f64], w: usize, h: usize, px_km: f64) -> f64 {
    let mean = t_k.iter().sum::<f64>() / t_k.len() as f64;
    let hann = |i: usize, n: usize| {
        0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / n as f64).cos()
    };
    let mut data: Vec<Complex<f64>> = t_k
        .iter()
        .enumerate()
        .map(|(i, &t)| Complex::new((t - mean) * hann(i % w, w) * hann(i / w, h), 0.0))
        .collect();
    let mut planner = FftPlanner::new();
    let fw = planner.plan_fft_forward(w);
    for row in data.chunks_exact_mut(w) {
        fw.process(row);
    }
    let fh = planner.plan_fft_forward(h);
    let mut col = vec![Complex::new(0.0, 0.0); h];
    for x in 0..w {
        for y in 0..h {
            col[y] = data[y * w + x];
        }
        fh.process(&mut col);
        for y in 0..h {
            data[y * w + x] = col[y];
        }
    }
    let (f_lo, f_hi) = (1.0 / SLOPE_BAND_KM.1, 1.0 / SLOPE_BAND_KM.0);
    let (l_lo, l_hi) = (f_lo.ln(), f_hi.ln());
    let mut bins = [(0.0f64, 0.0f64, 0usize); SLOPE_BINS];
    for y in 0..h {
        let ky = if y <= h / 2 {
            y as f64
        } else {
            y as f64 - h as f64
        };
        for x in 0..w {
            let kx = if x <= w / 2 {
                x as f64
            } else {
                x as f64 - w as f64
            };
            let f = ((kx / (w as f64 * px_km)).powi(2) + (ky / (h as f64 * px_km)).powi(2)).sqrt();
            if f < f_lo || f > f_hi {
                continue;
            }
            let b = (((f.ln() - l_lo) / (l_hi - l_lo)) * SLOPE_BINS as f64) as usize;
            let b = b.min(SLOPE_BINS - 1);
            bins[b].0 += f;
            bins[b].1 += data[y * w + x].norm_sqr();
            bins[b].2 += 1;
        }
    }
    let pts: Vec<(f64, f64)> = bins
        .iter()
        .filter(|b| b.2 > 0 && b.1 > 0.0)
        .map(|b| ((b.0 / b.2 as f64).ln(), (b.1 / b.2 as f64).ln()))
        .collect();
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx) * (p.0 - mx))
    });
    sxy / sxx
}

/// The largest axis-aligned rectangle of valid pixels (`valid[y * w + x]`) as
/// (x0, y0, width, height): the classic histogram-stack method, O(w·h).
pub fn largest_valid_rectangle(valid: &[bool], w: usize, h: usize) -> (usize, usize, usize, usize) {
    let mut heights = vec![0usize; w];
    let mut best = (0, 0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            heights[x] = if valid[y * w + x] { heights[x] + 1 } else { 0 };
        }
        let mut stack: Vec<usize> = Vec::new();
        for x in 0..=w {
            let cur = if x < w { heights[x] } else { 0 };
            while let Some(&top) = stack.last() {
                if heights[top] <= cur {
                    break;
                }
                stack.pop();
                let hgt = heights[top];
                let left = stack.last().map_or(0, |&l| l + 1);
                let width = x - left;
                if width * hgt > best.2 * best.3 {
                    best = (left, y + 1 - hgt, width, hgt);
                }
            }
            stack.push(x);
        }
    }
    best
}

/// The cloud texture on a `w` × `h` patch of `px_km` pixels centred on (`lat0`,
/// `lon0`) (a local equirectangular grid: x east, y south like an image), brightness
/// temperature quantised to `quantum_k` (0: not quantised), K, row-major.
pub fn sample_patch(
    field: &CloudField,
    lat0: f64,
    lon0: f64,
    w: usize,
    h: usize,
    px_km: f64,
    quantum_k: f64,
) -> Vec<f64> {
    let cos0 = libm::cos(lat0.to_radians()).max(0.05);
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let lat = lat0 - (y as f64 - h as f64 / 2.0) * px_km / KM_PER_DEG;
        for x in 0..w {
            let lon = lon0 + (x as f64 - w as f64 / 2.0) * px_km / (KM_PER_DEG * cos0);
            let t = field.temperature_at_k(lat, lon);
            out.push(if quantum_k > 0.0 {
                (t / quantum_k).round() * quantum_k
            } else {
                t
            });
        }
    }
    out
}
