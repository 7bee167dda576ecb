//! The Earth pass: every pixel's ray against the Earth sphere, its signal looked up in
//! the [`EarthMap`].

use tirroi_core::sensor::flux::{distance_compensation, view_factor_per_m2};
use tirroi_core::sensor::{SENSOR_AREA_M2, SensorError};

use super::target::Range;
use super::{
    EarthView, MASK_COVERAGE, Pinhole, Readout, RenderError, RenderStats, SAMPLES, sample_point,
};
use crate::world::geom::{Vec3, dot, norm, scale, sub};

/// Earth signal along the unit ray `d`, or `None` when it misses.
#[derive(Debug, Clone, Copy)]
struct EarthRays<'a> {
    pub(super) view: &'a EarthView<'a>,
    pub(super) centre_distance_m: f64,
    /// |c|² − R².
    pub(super) c2_minus_r2: f64,
    pub(super) compensation: f64,
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
}

/// Adds the Earth's signal behind the target; returns how many pixel centres see it.
pub(super) fn render_earth(
    cam: &Pinhole,
    earth: &EarthView<'_>,
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
            if let Some(s) = rays.signal(cam.ray(x as f64 + 0.5, y as f64 + 0.5))? {
                hit[i] = 1;
                earth_signal[i] = s;
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
                    sum += rays.signal(cam.ray(u, v))?.unwrap_or(0.0);
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
