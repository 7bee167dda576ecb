//! The Moon as a background object: its size, distance and surface temperature.
//!
//! **Geometry.** Mean radius 1 737.4 km at the mean Earth–Moon distance 384 400 km: an
//! angular radius of asin(1 737.4 / 384 400) = 4.52 mrad (0.259°, a 0.518° disc), i.e.
//! a disc of radius 5.15 px (diameter 10.3 px) at the Table 4 IFOV of 0.877 mrad. From
//! a 4 500 km orbit the camera–Moon distance differs from the Earth–Moon one by at most
//! 1.7 %, which we neglect.
//!
//! **Temperature.** A surface in radiative equilibrium with the Sun (no thermal
//! inertia on the day side): T = T_ss · cos(i)^¼ with i the solar incidence angle,
//! floored at the night-side temperature. T_ss = 390 K and T_night = 100 K are rounded
//! from LRO Diviner's equatorial measurements (Vasavada et al. 2012, *J. Geophys. Res.*
//! 117, E00H18: noon maxima 387–397 K, pre-dawn minima 95–100 K at the equator);
//! emissivity 0.95 (the value Diviner's temperatures assume). The floor makes the
//! terminator an abrupt step from ~ 175 K (cos i = 0.04) to 100 K; the real morning
//! terminator warms within hours, the afternoon one cools slower: a simplification
//! that is not resolved in a 10 px disc anyway.

/// Mean radius of the Moon, m (IAU).
pub const MOON_RADIUS_M: f64 = 1_737.4e3;

/// Mean Earth–Moon distance, m, taken as the camera–Moon distance.
pub const MOON_DISTANCE_M: f64 = 384_400e3;

/// Subsolar surface temperature, K (Diviner equatorial noon, Vasavada et al. 2012).
pub const MOON_SUBSOLAR_K: f64 = 390.0;

/// Night-side surface temperature, K (Diviner equatorial pre-dawn, Vasavada et al. 2012).
pub const MOON_NIGHT_K: f64 = 100.0;

/// Thermal-infrared emissivity of the regolith (Diviner's assumed value).
pub const MOON_EMISSIVITY: f64 = 0.95;

/// Surface temperature, K, at a point whose normal makes cosine `cos_incidence` with
/// the direction to the Sun: `MOON_SUBSOLAR_K · cos^¼`, at least `MOON_NIGHT_K` (night
/// side and NaN included).
pub fn surface_temperature_k(cos_incidence: f64) -> f64 {
    if cos_incidence > 0.0 {
        (MOON_SUBSOLAR_K * cos_incidence.min(1.0).sqrt().sqrt()).max(MOON_NIGHT_K)
    } else {
        MOON_NIGHT_K
    }
}

/// Angular radius of the Moon's disc seen from the camera, rad (4.52 mrad).
pub fn angular_radius_rad() -> f64 {
    (MOON_RADIUS_M / MOON_DISTANCE_M).asin()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subsolar_night_and_equilibrium_law() {
        assert_eq!(surface_temperature_k(1.0), MOON_SUBSOLAR_K);
        assert_eq!(surface_temperature_k(-0.3), MOON_NIGHT_K);
        assert_eq!(surface_temperature_k(f64::NAN), MOON_NIGHT_K);
        // Radiative equilibrium: σT⁴ ∝ cos i, so T(60°)⁴ = T_ss⁴ / 2.
        let t60 = surface_temperature_k(0.5);
        assert!((t60.powi(4) - MOON_SUBSOLAR_K.powi(4) / 2.0).abs() < 1e-3 * t60.powi(4));
        // Disc of ~10 px at the Table 4 IFOV (37 µm / 42.2 mm).
        let ifov = 37e-6 / 42.2e-3;
        let diameter_px = 2.0 * angular_radius_rad() / ifov;
        assert!((diameter_px - 10.3).abs() < 0.05, "{diameter_px}");
    }
}
