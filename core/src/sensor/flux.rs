//! The view-factor flux of paper Eqs. 2 and 4 and the distance compensation of Eq. 7.
//!
//! q_fc = i · (n̂_f · r_fs)(n̂_s · r_sf) / |r_fs|⁴ · ΔA_c,  W m⁻²,
//!
//! with i the band radiance of the facet (W m⁻² sr⁻¹), n̂_f its normal, n̂_s the sensor's
//! normal (the boresight, pointing out of the camera towards the scene), r_fs the vector
//! from the facet to the sensor in metres and r_sf = −r_fs. It is evaluated as
//! i·cos θ_f·cos θ_s/|r|²·ΔA_c, so |r|⁴ is never formed (at 10 871 km it is 1.4·10²⁸ m⁴;
//! fine in f64, but 1.4·10⁴⁰ in mm would overflow f32). A facet facing away from the
//! camera, or behind the sensor plane, gets 0 (both cosines are clamped at 0).
//!
//! # Which ΔA_c
//!
//! The paper calls ΔA_c "the sensor area intercepting the radiation" without a number.
//! [`SENSOR_AREA_M2`], the whole active area of the Table 4 array (328 × 248 pixels of
//! 37 µm = 1.1136·10⁻⁴ m²), is the reading that reproduces Table 5: the warmest Earth
//! cell (OLR 330 W m⁻² → 276.2 K by Eq. 10) at the paper's camera–Earth distance of
//! 10 871 km gives q_fc = 2.07·10⁻¹⁷ W m⁻² with the TIR band model (2.38·10⁻¹⁷ for a box
//! 8–12 µm band), the order of Table 5's 3·10⁻¹⁷. A pixel's area would give 10⁻²², an
//! aperture 10⁻¹⁶ (`shared/reference/REFERENCE.md` §4; asserted in
//! core/tests/sensor_scales.rs).

use super::{SensorError, check_positive, check_range};
use crate::frame::{FRAME_HEIGHT, FRAME_WIDTH};

/// Pixel pitch of the Table 4 camera (Hayabusa2 TIR), m.
pub const PIXEL_PITCH_M: f64 = 37e-6;
/// Sensing area ΔA_c used in Eqs. 2, 4 and 7: the active array, 328 × 248 pixels of
/// 37 µm, = 1.113 6·10⁻⁴ m².
pub const SENSOR_AREA_M2: f64 =
    (FRAME_WIDTH as f64 * PIXEL_PITCH_M) * (FRAME_HEIGHT as f64 * PIXEL_PITCH_M);

/// A 3-vector in metres (or a direction), x, y, z.
pub type Vec3 = [f64; 3];

fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Euclidean norm, scaled so that no square overflows or underflows.
fn norm(a: &Vec3) -> f64 {
    let m = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let (x, y, z) = (a[0] / m, a[1] / m, a[2] / m);
    m * libm::sqrt(x * x + y * y + z * z)
}

fn check_vec(name: &'static str, v: &Vec3) -> Result<f64, SensorError> {
    for c in v {
        check_range(name, *c, f64::MIN, f64::MAX, "finite components")?;
    }
    let n = norm(v);
    if n.is_nan() || n <= 0.0 {
        return Err(SensorError::OutOfRange {
            name,
            value: n,
            expected: "a non-zero vector",
        });
    }
    Ok(n)
}

/// The geometric factor (n̂_f·r̂)(n̂_s·(−r̂))/|r|² of Eq. 2, m⁻² (per steradian of
/// radiance and square metre of sensing area): cos θ_f · cos θ_s / |r|².
///
/// `facet_normal` and `sensor_normal` need not be unit vectors; `facet_to_sensor_m` is
/// r_fs in metres. Both cosines are clamped at 0 (no flux from behind).
///
/// # Errors
/// [`SensorError`] for a zero or non-finite vector.
pub fn view_factor_per_m2(
    facet_normal: &Vec3,
    sensor_normal: &Vec3,
    facet_to_sensor_m: &Vec3,
) -> Result<f64, SensorError> {
    let nf = check_vec("facet_normal", facet_normal)?;
    let ns = check_vec("sensor_normal", sensor_normal)?;
    let r = check_vec("facet_to_sensor_m", facet_to_sensor_m)?;
    let cos_f = (dot(facet_normal, facet_to_sensor_m) / (nf * r)).clamp(0.0, 1.0);
    // r_sf = −r_fs points from the sensor to the facet.
    let cos_s = (-dot(sensor_normal, facet_to_sensor_m) / (ns * r)).clamp(0.0, 1.0);
    // cos/r then /r: no r² overflow even at 1e200 m.
    Ok(cos_f * cos_s / r / r)
}

/// The flux q_fc (Eq. 4) a facet of band radiance `radiance_w_m2_sr` (W m⁻² sr⁻¹,
/// including ε) sends onto a sensing area of `sensing_area_m2` (normally
/// [`SENSOR_AREA_M2`]), W m⁻².
///
/// # Errors
/// [`SensorError`] for a negative or non-finite radiance or area, or bad vectors.
pub fn facet_flux_w_m2(
    radiance_w_m2_sr: f64,
    facet_normal: &Vec3,
    sensor_normal: &Vec3,
    facet_to_sensor_m: &Vec3,
    sensing_area_m2: f64,
) -> Result<f64, SensorError> {
    check_range(
        "radiance_w_m2_sr",
        radiance_w_m2_sr,
        0.0,
        f64::MAX,
        "a finite radiance >= 0",
    )?;
    check_positive("sensing_area_m2", sensing_area_m2)?;
    let g = view_factor_per_m2(facet_normal, sensor_normal, facet_to_sensor_m)?;
    Ok(radiance_w_m2_sr * g * sensing_area_m2)
}

/// Distance compensation D = π|r|²/ΔA_c of Eq. 7 (dimensionless, sr), so that
/// F(T) = D·q_fc for a facet seen face-on at `distance_m`.
///
/// # Errors
/// [`SensorError`] for a distance or area that is not finite and > 0.
pub fn distance_compensation(distance_m: f64, sensing_area_m2: f64) -> Result<f64, SensorError> {
    let r = check_positive("distance_m", distance_m)?;
    let a = check_positive("sensing_area_m2", sensing_area_m2)?;
    Ok(core::f64::consts::PI * (r / a) * r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensor_area_is_the_active_array() {
        assert!((SENSOR_AREA_M2 - 1.113_599_36e-4).abs() < 1e-15);
    }

    #[test]
    fn face_on_flux_and_compensation_invert() {
        let q = facet_flux_w_m2(
            33.4,
            &[0.0, 0.0, 1.0],
            &[0.0, 0.0, -1.0],
            &[0.0, 0.0, 50.0],
            SENSOR_AREA_M2,
        )
        .unwrap();
        assert!((q - 33.4 * SENSOR_AREA_M2 / 2500.0).abs() < 1e-18);
        let d = distance_compensation(50.0, SENSOR_AREA_M2).unwrap();
        assert!((d * q / (core::f64::consts::PI * 33.4) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn backfacing_and_behind_give_zero() {
        let z = [0.0, 0.0, 1.0];
        assert_eq!(
            view_factor_per_m2(&[0.0, 0.0, -1.0], &[0.0, 0.0, -1.0], &[0.0, 0.0, 5.0]),
            Ok(0.0)
        );
        assert_eq!(view_factor_per_m2(&z, &z, &[0.0, 0.0, 5.0]), Ok(0.0));
        assert!(view_factor_per_m2(&[0.0; 3], &z, &z).is_err());
        assert!(view_factor_per_m2(&z, &z, &[f64::NAN, 0.0, 1.0]).is_err());
    }
}
