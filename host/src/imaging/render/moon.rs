//! The Moon pass: a background disc ([`crate::world::moon`]) behind the target and the
//! Earth, its signal through the same band radiance and Eq. 4 path as the Earth.
//!
//! Every pixel of the disc's bounding box that is not fully on the target is sampled on
//! the 4 × 4 grid (the disc is ~ 10 px across, so the whole disc costs ~ 2 000 rays):
//! a sample sees the Moon when its ray hits the Moon's sphere and misses the Earth's
//! (the Earth, at 10 871 km, is in front of the Moon at 384 400 km). A sample's signal
//! is the band radiance of the regolith at its temperature
//! ([`surface_temperature_k`]) and emissivity 0.95, times the view factor of Eq. 4 with
//! |r| = the camera–Moon distance and the local surface normal, times ΔA_c: in
//! radiometry, with D = π|r|²/ΔA_c (Eq. 7), F = π·L·cos θ_f·cos θ_s, a radiometric
//! temperature near the surface's; in detection, q_fc at the real 384 400 km, which is
//! (10 871 / 384 400)² = 8.0·10⁻⁴ of what the same radiance gives at the Earth's
//! distance: under the paper's per-element reading of Eq. 4 the Moon is a faint disc
//! of a few DN in detection frames (module docs of [`super`], Table 5).
//!
//! Pixels whose 16 samples all see the Moon (and no target) join the pure pixels that
//! bound the radiometry auto range (Eq. 17), as the camera's auto range would see it.

use tirroi_core::sensor::flux::{distance_compensation, view_factor_per_m2};
use tirroi_core::sensor::{BandLut, SENSOR_AREA_M2};

use super::pure::PurePixels;
use super::{EarthView, Pinhole, Readout, RenderError, SAMPLES, sample_point};
use crate::world::geom::{Vec3, dot, norm, normalize, scale, sub};
use crate::world::moon::{
    MOON_DISTANCE_M, MOON_EMISSIVITY, MOON_RADIUS_M, angular_radius_rad, surface_temperature_k,
};

/// The Moon as the camera sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoonView {
    /// Unit direction to the Moon's centre, camera frame.
    pub dir_camera: Vec3,
    /// Unit direction to the Sun, camera frame (the Moon's phase).
    pub sun_dir_camera: Vec3,
}

/// Whether the unit ray `d` hits the sphere of `centre` and `radius_m` in front of the camera.
fn hits_sphere(d: Vec3, centre: Vec3, radius_m: f64) -> Option<f64> {
    let dist = norm(centre);
    let b = dot(d, centre);
    let disc = b * b - (dist - radius_m) * (dist + radius_m);
    (b > 0.0 && disc >= 0.0).then(|| b - disc.sqrt())
}

/// Adds the Moon's signal behind the target and the Earth; returns how many pixel
/// centres see it (not the target, not the Earth).
#[allow(clippy::too_many_arguments)]
pub(super) fn render_moon(
    cam: &Pinhole,
    moon: &MoonView,
    earth: Option<&EarthView<'_>>,
    readout: Readout,
    lut: &BandLut,
    coverage: &[f32],
    signal: &mut [f32],
    pure: &mut PurePixels,
) -> Result<usize, RenderError> {
    let dir = normalize(moon.dir_camera);
    let sun = normalize(moon.sun_dir_camera);
    if dir[2].is_nan() || dir[2] <= 0.0 || sun.iter().any(|v| !v.is_finite()) {
        return Err(RenderError::Input(format!(
            "the Moon's direction {:?} is not in front of the camera (or its Sun {:?} is not a direction)",
            moon.dir_camera, moon.sun_dir_camera
        )));
    }
    let centre = scale(dir, MOON_DISTANCE_M);
    let compensation = match readout {
        Readout::Radiometry => distance_compensation(MOON_DISTANCE_M, SENSOR_AREA_M2)?,
        Readout::Detection(_) => 1.0,
    };
    let emissivity = MOON_EMISSIVITY as f32;
    let sample = |d: Vec3| -> Result<Option<f32>, RenderError> {
        if let Some(e) = earth {
            if hits_sphere(d, e.centre_m, e.radius_m).is_some() {
                return Ok(None);
            }
        }
        let Some(t) = hits_sphere(d, centre, MOON_RADIUS_M) else {
            return Ok(None);
        };
        let normal = scale(sub(scale(d, t), centre), 1.0 / MOON_RADIUS_M);
        let t_k = surface_temperature_k(dot(normal, sun));
        let radiance = lut.radiance_f32(t_k as f32, emissivity)?;
        let g = view_factor_per_m2(&normal, &[0.0, 0.0, 1.0], &scale(d, -MOON_DISTANCE_M))?;
        Ok(Some(
            (f64::from(radiance) * g * SENSOR_AREA_M2 * compensation) as f32,
        ))
    };
    // The disc's bounding box, with a pixel of margin for the perspective stretch.
    let u = cam.cx + cam.f * dir[0] / dir[2];
    let v = cam.cy + cam.f * dir[1] / dir[2];
    let r_px = cam.f * angular_radius_rad().tan() / (dir[2] * dir[2]) + 2.0;
    let x0 = (u - r_px).floor().max(0.0) as usize;
    let y0 = (v - r_px).floor().max(0.0) as usize;
    let x1 = ((u + r_px).ceil().max(0.0) as usize).min(cam.w);
    let y1 = ((v + r_px).ceil().max(0.0) as usize).min(cam.h);
    let mut seen = 0usize;
    for y in y0..y1 {
        for x in x0..x1 {
            let i = y * cam.w + x;
            let c = coverage[i];
            if c >= 1.0 {
                continue;
            }
            let (mut sum, mut hits) = (0f32, 0usize);
            for s in 0..SAMPLES {
                let (su, sv) = sample_point(x, y, s);
                if let Some(q) = sample(cam.ray(su, sv))? {
                    sum += q;
                    hits += 1;
                }
            }
            if hits == 0 {
                continue;
            }
            let mean = sum / SAMPLES as f32;
            signal[i] += (1.0 - c) * mean;
            if hits == SAMPLES && c == 0.0 {
                pure.add(i, mean);
            }
            if c < super::MASK_COVERAGE
                && sample(cam.ray(x as f64 + 0.5, y as f64 + 0.5))?.is_some()
            {
                seen += 1;
            }
        }
    }
    Ok(seen)
}
