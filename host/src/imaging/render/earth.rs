//! The Earth pass: every pixel's ray against the Earth sphere, its signal looked up in
//! the [`EarthMap`].

use tirroi_core::sensor::flux::{distance_compensation, view_factor_per_m2};
use tirroi_core::sensor::{BandLut, SENSOR_AREA_M2, SensorError};

use super::pure::PurePixels;
use super::{
    EarthView, MASK_COVERAGE, Pinhole, Readout, RenderError, RenderStats, SAMPLES, sample_point,
};
use crate::world::geom::{Vec3, dot, norm, scale, sub};

/// Limb darkening of the cloud texture: the TOA longwave radiance at emission angle θ
/// is I(μ) = I(1)·μ^q with μ = cos θ and q = 0.1, i.e. 7 % darker at θ = 60° and 10 %
/// at 70°: about the mean broadband longwave limb darkening of the ERBE angular
/// distribution models (Suttles et al., "Angular radiation models for Earth-atmosphere
/// system, Vol. II: Longwave radiation", NASA RP-1184, 1989: the LW anisotropic factor
/// falls by roughly 5–10 % from nadir to 60–70°). An approximation: the real window
/// channel darkens more over moist tropics and less over dry poles.
pub const LIMB_DARKENING_EXPONENT: f64 = 0.1;
/// Brightness temperature of the atmosphere's limb emission at zero tangent height
/// (the 8–12 µm limb path is opaque in the lower troposphere, so it shows the air
/// temperature there), K.
pub const LIMB_EDGE_T_K: f32 = 250.0;
/// E-folding height of the limb emission above the hard limb, m: the edge is about
/// one pixel (≈ 9.5 km at the limb from 10 871 km) wide.
pub const LIMB_EDGE_SCALE_HEIGHT_M: f64 = 6.0e3;
/// Tangent heights above which the limb emission counts as 0, m.
pub const LIMB_EDGE_TOP_M: f64 = 60.0e3;

/// Lowest brightness temperature of the dense cloud-texture radiance table, K (below
/// the texture's cloud tops but for the deepest cores, clear surface − [`MAX_LOCAL_COLD_K`],
/// which fall back to the [`BandLut`]).
///
/// [`MAX_LOCAL_COLD_K`]: crate::world::earth::clouds::MAX_LOCAL_COLD_K
pub const DENSE_RADIANCE_T_MIN_K: f32 = 150.0;
/// Highest temperature of the dense table, K (above the warmest clear surface, ~320 K).
pub const DENSE_RADIANCE_T_MAX_K: f32 = 350.0;
/// Step of the dense table, K: linear interpolation of the band radiance between
/// nodes 0.05 K apart errs by L''·h²/8 ≈ 3·10⁻⁷ of L at 150 K and less above (L ∝ Tⁿ
/// with n ≲ 12 there), far below the [`BandLut`]'s own 4·10⁻⁶.
pub const DENSE_RADIANCE_STEP_K: f32 = 0.05;

/// Intervals of the limb-darkening table [`limb_darkening`] in √μ.
const LIMB_TABLE_INTERVALS: usize = 1024;

/// μ^[`LIMB_DARKENING_EXPONENT`] for μ = cos θ ∈ [0, 1], read by linear interpolation
/// from a table on a uniform grid in √μ (1 025 nodes, built once): one square root and
/// a multiply-add instead of a `powf` per Earth ray. On √μ, f = (√μ)^0.2 has
/// |f''/f| = 0.16/μ, so the linear interpolation errs by at most h²·0.16/(8μ) with
/// h = 1/1024: ≤ 2·10⁻⁴ relative for μ ≥ 10⁻⁴ (emission angles up to 89.994°) and
/// ≤ 2·10⁻⁸ for μ ≥ 0.1 (the test bounds it against `powf`); below μ = 10⁻⁴ (rays
/// grazing the hard limb within ~60 m of tangency at 10 871 km) the error grows, on a
/// radiance that is averaged with 15 other sub-samples of a limb pixel.
#[inline]
fn limb_darkening(mu: f32) -> f32 {
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=LIMB_TABLE_INTERVALS)
            .map(|i| {
                let root = i as f64 / LIMB_TABLE_INTERVALS as f64;
                (root * root).powf(LIMB_DARKENING_EXPONENT) as f32
            })
            .collect()
    });
    let x = mu.clamp(0.0, 1.0).sqrt() * LIMB_TABLE_INTERVALS as f32;
    let i = (x as usize).min(LIMB_TABLE_INTERVALS - 1);
    let f = x - i as f32;
    table[i] + f * (table[i + 1] - table[i])
}

/// tan(π/12) = 2 − √3: the arctangent's argument is reduced below it.
const TAN_PI_12: f64 = 0.267_949_192_431_122_7;

/// arctan(t) for t ∈ [0, 1], radians: above tan(π/12), atan t = π/6 + atan u with
/// u = (√3·t − 1)/(√3 + t), |u| ≤ tan(π/12); then the Taylor series to u¹⁵, whose
/// truncation error is below |u|¹⁷/17 ≈ 1.1·10⁻¹¹ rad (no table, no fitted
/// coefficients).
#[inline]
fn atan_unit(t: f64) -> f64 {
    let sqrt3 = 1.732_050_807_568_877_2;
    let (base, u) = if t > TAN_PI_12 {
        (std::f64::consts::FRAC_PI_6, (sqrt3 * t - 1.0) / (sqrt3 + t))
    } else {
        (0.0, t)
    };
    let u2 = u * u;
    let series = 1.0
        + u2 * (-1.0 / 3.0
            + u2 * (1.0 / 5.0
                + u2 * (-1.0 / 7.0
                    + u2 * (1.0 / 9.0
                        + u2 * (-1.0 / 11.0 + u2 * (1.0 / 13.0 + u2 * (-1.0 / 15.0)))))));
    base + u * series
}

/// atan2(y, x), radians in −π…π, to ~10⁻¹¹ rad ([`atan_unit`] after the octant
/// reduction): the cloud texture's latitude and longitude of a ray without libm's
/// asin and atan2 (a third of a ray's cost before).
#[inline]
fn fast_atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (mn, mx) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if mx == 0.0 {
        return 0.0;
    }
    let mut a = atan_unit(mn / mx);
    if ay > ax {
        a = std::f64::consts::FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = std::f64::consts::PI - a;
    }
    if y < 0.0 { -a } else { a }
}

/// The band radiance of the cloud texture's temperatures on a uniform 0.05 K grid,
/// read by linear interpolation: one multiply-add per ray instead of the [`BandLut`]'s
/// cubic in ln L and an `expf` (the Earth pass casts ~70 000 rays per frame). Built
/// per frame from the frame's [`BandLut`] (4 000 evaluations, ~50 µs);
/// temperatures outside the grid fall back to the [`BandLut`].
#[derive(Debug, Clone)]
struct DenseRadiance {
    /// L(T) at T = [`DENSE_RADIANCE_T_MIN_K`] + i·[`DENSE_RADIANCE_STEP_K`], W m⁻² sr⁻¹.
    l_w_m2_sr: Vec<f32>,
}

impl DenseRadiance {
    fn new(lut: &BandLut) -> Result<Self, SensorError> {
        let intervals = ((DENSE_RADIANCE_T_MAX_K - DENSE_RADIANCE_T_MIN_K) / DENSE_RADIANCE_STEP_K)
            .round() as usize;
        let l_w_m2_sr = (0..=intervals)
            .map(|i| {
                lut.radiance_f32(
                    DENSE_RADIANCE_T_MIN_K + i as f32 * DENSE_RADIANCE_STEP_K,
                    1.0,
                )
            })
            .collect::<Result<Vec<f32>, SensorError>>()?;
        Ok(DenseRadiance { l_w_m2_sr })
    }

    /// The table of `lut`, built once and shared: every frame of a dataset (and its
    /// signal-to-clutter twin) uses the same camera table, and rebuilding its 4 001
    /// nodes twice per frame was ~15 % of the textured Earth pass. The last table built
    /// is kept with the [`BandLut`] it came from and reused when the frame's table is
    /// equal to it (compared in full, ~11 kB: far cheaper than the build), so the
    /// values are exactly those a fresh build gives.
    fn shared(lut: &BandLut) -> Result<std::sync::Arc<DenseRadiance>, SensorError> {
        use std::sync::{Arc, Mutex};
        type Cached = Option<(Box<BandLut>, Arc<DenseRadiance>)>;
        static LAST: Mutex<Cached> = Mutex::new(None);
        // A poisoned lock only means another thread panicked while holding it: the
        // cached pair is still consistent (it is replaced whole).
        let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((cached_lut, table)) = last.as_ref()
            && **cached_lut == *lut
        {
            return Ok(Arc::clone(table));
        }
        let table = Arc::new(DenseRadiance::new(lut)?);
        *last = Some((Box::new(lut.clone()), Arc::clone(&table)));
        Ok(table)
    }

    /// Blackbody band radiance at `t_k`, W m⁻² sr⁻¹.
    #[inline]
    fn radiance(&self, lut: &BandLut, t_k: f32) -> Result<f32, SensorError> {
        let x = (t_k - DENSE_RADIANCE_T_MIN_K) / DENSE_RADIANCE_STEP_K;
        let i = x as usize;
        if x >= 0.0 && i + 1 < self.l_w_m2_sr.len() {
            let f = x - i as f32;
            let (a, b) = (self.l_w_m2_sr[i], self.l_w_m2_sr[i + 1]);
            Ok(a + f * (b - a))
        } else {
            lut.radiance_f32(t_k, 1.0)
        }
    }
}

/// Earth signal along the unit ray `d`, or `None` when it misses.
#[derive(Debug, Clone)]
struct EarthRays<'a> {
    pub(super) view: &'a EarthView<'a>,
    pub(super) centre_distance_m: f64,
    /// |c|² − R².
    pub(super) c2_minus_r2: f64,
    pub(super) compensation: f64,
    /// Band radiance table (the cloud texture's temperatures).
    pub(super) lut: &'a BandLut,
    /// The same on a dense grid (cloud texture only).
    dense: Option<std::sync::Arc<DenseRadiance>>,
    /// Limb-edge radiance at zero tangent height (cloud texture only).
    pub(super) limb_edge_w_m2_sr: f32,
    /// The map's factor on the cloud texture's temperatures (eclipse).
    cloud_t_scale: f64,
}

impl EarthRays<'_> {
    pub(super) fn signal(&self, d: Vec3) -> Result<Option<f32>, SensorError> {
        let c = self.view.centre_m;
        let b = dot(d, c);
        let disc = b * b - self.c2_minus_r2;
        if b <= 0.0 || disc < 0.0 {
            return Ok(None);
        }
        let t = b - disc.sqrt();
        let hit = scale(d, t);
        let normal = scale(sub(hit, c), 1.0 / self.view.radius_m);
        let e = self.view.camera_to_earth.apply(normal);
        if let Some(clouds) = self.view.map.clouds() {
            // A resolved surface: radiance × limb darkening, no cos of the emission
            // angle in the view factor (module docs of `render`). Latitude and
            // longitude by `fast_atan2` (≤ 10⁻⁹°, far below a tile node's 1/32°).
            let lat = fast_atan2(e[2], (e[0] * e[0] + e[1] * e[1]).sqrt()).to_degrees();
            let lon = fast_atan2(e[1], e[0]).to_degrees();
            let t = (clouds.temperature_k(lat, lon) * self.cloud_t_scale) as f32;
            let radiance = match &self.dense {
                Some(dense) => dense.radiance(self.lut, t)?,
                None => self.lut.radiance_f32(t, 1.0)?,
            };
            let mu = (-dot(normal, d)).clamp(0.0, 1.0) as f32;
            let g = f64::from(limb_darkening(mu)) * d[2].max(0.0)
                / self.centre_distance_m
                / self.centre_distance_m;
            return Ok(Some(
                (f64::from(radiance) * g * SENSOR_AREA_M2 * self.compensation) as f32,
            ));
        }
        let lat = e[2].clamp(-1.0, 1.0).asin().to_degrees();
        let lon = e[1].atan2(e[0]).to_degrees();
        let radiance = self.view.map.radiance_w_m2_sr(lat, lon);
        // Eq. 4 with |r| = the camera–Earth-centre distance (module docs).
        let g = view_factor_per_m2(
            &normal,
            &[0.0, 0.0, 1.0],
            &scale(d, -self.centre_distance_m),
        )?;
        Ok(Some(
            (f64::from(radiance) * g * SENSOR_AREA_M2 * self.compensation) as f32,
        ))
    }

    /// Signal of the atmosphere's limb emission along a ray `d` that misses the hard
    /// sphere: L_edge·exp(−z/H) at tangent height z (cloud texture only; 0 otherwise).
    pub(super) fn atmosphere(&self, d: Vec3) -> f32 {
        if self.limb_edge_w_m2_sr <= 0.0 {
            return 0.0;
        }
        let b = dot(d, self.view.centre_m);
        if b <= 0.0 {
            return 0.0;
        }
        // Closest approach to the centre: p² = |c|² − b².
        let p2 = self.c2_minus_r2 + self.view.radius_m * self.view.radius_m - b * b;
        let z = p2.max(0.0).sqrt() - self.view.radius_m;
        if !(0.0..LIMB_EDGE_TOP_M).contains(&z) {
            return 0.0;
        }
        let l = f64::from(self.limb_edge_w_m2_sr) * (-z / LIMB_EDGE_SCALE_HEIGHT_M).exp();
        let g = d[2].max(0.0) / self.centre_distance_m / self.centre_distance_m;
        (l * g * SENSOR_AREA_M2 * self.compensation) as f32
    }
}

/// Adds the Earth's signal behind the target; returns how many pixel centres see it.
// The frame's buffers and settings, passed apart so the caller keeps its borrows.
#[allow(clippy::too_many_arguments)]
pub(super) fn render_earth(
    cam: &Pinhole,
    earth: &EarthView<'_>,
    lut: &BandLut,
    readout: Readout,
    coverage: &[f32],
    signal: &mut [f32],
    pure: &mut PurePixels,
    stats: &mut RenderStats,
) -> Result<usize, RenderError> {
    let dist = norm(earth.centre_m);
    if dist.is_nan() || dist <= earth.radius_m {
        return Err(RenderError::Input(format!(
            "the camera is {dist} m from the Earth's centre, inside its {} m radius",
            earth.radius_m
        )));
    }
    // Frame-level cull: the boresight's angle to the centre minus the disc's angular
    // radius must be within the half diagonal of the field of view.
    let off_boresight = (earth.centre_m[2] / dist).clamp(-1.0, 1.0).acos();
    let disc_radius = (earth.radius_m / dist).asin();
    if off_boresight - disc_radius > cam.half_diagonal_rad() {
        return Ok(0);
    }
    let rays = EarthRays {
        view: earth,
        centre_distance_m: dist,
        c2_minus_r2: (dist - earth.radius_m) * (dist + earth.radius_m),
        compensation: match readout {
            Readout::Radiometry => distance_compensation(dist, SENSOR_AREA_M2)?,
            Readout::Detection(_) => 1.0,
        },
        lut,
        dense: match earth.map.clouds() {
            Some(_) => Some(DenseRadiance::shared(lut)?),
            None => None,
        },
        limb_edge_w_m2_sr: if earth.map.clouds().is_some() {
            lut.radiance_f32(LIMB_EDGE_T_K, 1.0)?
        } else {
            0.0
        },
        cloud_t_scale: earth.map.cloud_temperature_scale(),
    };
    let (w, h) = (cam.w, cam.h);
    // Centre rays for every pixel not fully on the target: 1 hit, 0 miss, −1 not cast.
    let mut hit = vec![-1i8; w * h];
    let mut earth_signal = vec![0f32; w * h];
    let mut seen = 0usize;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if coverage[i] >= 1.0 {
                continue;
            }
            stats.earth_rays += 1;
            hit[i] = 0;
            let d = cam.ray(x as f64 + 0.5, y as f64 + 0.5);
            if let Some(s) = rays.signal(d)? {
                hit[i] = 1;
                earth_signal[i] = s;
            } else {
                earth_signal[i] = rays.atmosphere(d);
            }
        }
    }
    // Limb pixels (a cast 4-neighbour differs in hit) are supersampled.
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let here = hit[i];
            if here < 0 {
                continue;
            }
            let other = |j: usize| hit[j] >= 0 && hit[j] != here;
            let differs = (x > 0 && other(i - 1))
                || (x + 1 < w && other(i + 1))
                || (y > 0 && other(i - w))
                || (y + 1 < h && other(i + w));
            let s = if differs {
                let mut sum = 0f32;
                for s in 0..SAMPLES {
                    let (u, v) = sample_point(x, y, s);
                    stats.earth_rays += 1;
                    let d = cam.ray(u, v);
                    sum += match rays.signal(d)? {
                        Some(s) => s,
                        None => rays.atmosphere(d),
                    };
                }
                sum / SAMPLES as f32
            } else {
                earth_signal[i]
            };
            let c = coverage[i];
            signal[i] += (1.0 - c) * s;
            if here == 1 && c < MASK_COVERAGE {
                seen += 1;
            }
            if here == 1 && !differs && c == 0.0 {
                pure.add(i, s);
            }
        }
    }
    Ok(seen)
}

#[cfg(test)]
mod tests {
    use super::{LIMB_DARKENING_EXPONENT, fast_atan2, limb_darkening};

    /// The table against `powf` in f64 on a dense sweep of μ: within 2·10⁻⁴ relative
    /// for μ ≥ 10⁻⁴ and 10⁻⁶ for μ ≥ 0.1 (the f32 rounding of the table and of √μ
    /// dominates there), exact at 0 and 1.
    #[test]
    fn limb_darkening_table_matches_powf() {
        let (mut worst_grazing, mut worst_disc) = (0.0f64, 0.0f64);
        for k in 0..=200_000 {
            let mu = 1e-4 + (1.0 - 1e-4) * f64::from(k) / 200_000.0;
            let exact = mu.powf(LIMB_DARKENING_EXPONENT);
            let rel = (f64::from(limb_darkening(mu as f32)) / exact - 1.0).abs();
            if mu >= 0.1 {
                worst_disc = worst_disc.max(rel);
            } else {
                worst_grazing = worst_grazing.max(rel);
            }
        }
        assert!(
            worst_grazing < 2e-4,
            "worst relative error {worst_grazing} below μ = 0.1"
        );
        assert!(
            worst_disc < 1e-6,
            "worst relative error {worst_disc} above μ = 0.1"
        );
        assert_eq!(limb_darkening(0.0), 0.0);
        assert_eq!(limb_darkening(1.0), 1.0);
    }

    /// Against libm's f64 atan2 on a dense sweep of directions (every octant, the
    /// reduction's break points, the axes): within 10⁻¹⁰ rad.
    #[test]
    fn fast_atan2_matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..=20_000 {
            let a = -std::f64::consts::PI + k as f64 * std::f64::consts::TAU / 20_000.0;
            for r in [1e-3, 0.7, 1.0, 6.4e6] {
                let (y, x) = (r * a.sin(), r * a.cos());
                worst = worst.max((fast_atan2(y, x) - y.atan2(x)).abs());
            }
        }
        for (y, x) in [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0), (1.0, 1.0)] {
            worst = worst.max((fast_atan2(y, x) - f64::atan2(y, x)).abs());
        }
        assert!(worst < 1e-10, "worst error {worst} rad");
        assert_eq!(fast_atan2(0.0, 0.0), 0.0);
    }
}
