//! The Earth pass: every pixel's ray against the Earth sphere, its signal looked up in
//! the [`EarthMap`].

use tirroi_core::sensor::flux::{distance_compensation, view_factor_per_m2};
use tirroi_core::sensor::{BandLut, SENSOR_AREA_M2, SensorError};

use super::target::Range;
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

/// Earth signal along the unit ray `d`, or `None` when it misses.
#[derive(Debug, Clone, Copy)]
struct EarthRays<'a> {
    pub(super) view: &'a EarthView<'a>,
    pub(super) centre_distance_m: f64,
    /// |c|² − R².
    pub(super) c2_minus_r2: f64,
    pub(super) compensation: f64,
    /// Band radiance table (the cloud texture's temperatures).
    pub(super) lut: &'a BandLut,
    /// Limb-edge radiance at zero tangent height (cloud texture only).
    pub(super) limb_edge_w_m2_sr: f32,
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
        let lat = e[2].clamp(-1.0, 1.0).asin().to_degrees();
        let lon = e[1].atan2(e[0]).to_degrees();
        if let Some(clouds) = self.view.map.clouds() {
            // A resolved surface: radiance × limb darkening, no cos of the emission
            // angle in the view factor (module docs of `render`).
            let t = clouds.temperature_k(lat, lon) as f32;
            let radiance = self.lut.radiance_f32(t, 1.0)?;
            let mu = (-dot(normal, d)).clamp(0.0, 1.0);
            let g = mu.powf(LIMB_DARKENING_EXPONENT) * d[2].max(0.0)
                / self.centre_distance_m
                / self.centre_distance_m;
            return Ok(Some(
                (f64::from(radiance) * g * SENSOR_AREA_M2 * self.compensation) as f32,
            ));
        }
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
    pure: &mut Range,
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
        limb_edge_w_m2_sr: if earth.map.clouds().is_some() {
            lut.radiance_f32(LIMB_EDGE_T_K, 1.0)?
        } else {
            0.0
        },
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
                pure.add(s);
            }
        }
    }
    Ok(seen)
}
