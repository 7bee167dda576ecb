//! The target's orbit for transient temperatures: a circular orbit, the Sun at a fixed
//! angle β from the orbit plane, a cylindrical Earth shadow and an Earth-pointing
//! (LVLH) attitude.
//!
//! Orbit frame: e₁ the Sun's projection on the orbit plane, h the orbit normal,
//! e₂ = h × e₁; the Sun is S = cos β e₁ + sin β h. At the orbit angle θ (from the
//! noon point) the target is at r̂ = cos θ e₁ + sin θ e₂ and moves along
//! v̂ = −sin θ e₁ + cos θ e₂.
//!
//! Attitude (body frame = local vertical, local horizontal): body +x along the
//! velocity v̂, +z the zenith r̂, +y the orbit normal h. The Earth's centre is
//! always at body −z; the Sun turns once per orbit in the body x–z plane (β = 0):
//! s_body = (−cos β sin θ, sin β, cos β cos θ). For the cube + cylinder the cylinder
//! points along-track; Tango's solar panel (+z) faces the zenith.
//!
//! Shadow: the cylinder of the Earth's radius R behind it. With ρ = R/a, the target is
//! in shadow when r̂·S < 0 and its distance from the Sun line is below R, i.e. for
//! |θ − π| < φ with cos φ = √(1 − ρ²)/cos β (no eclipse when |β| ≥ asin ρ). At β = 0,
//! φ = asin ρ. The reference orbit (a = 6 371 + 4 500 km) has period
//! 2π√(a³/μ) = 11 280 s and φ = 35.9°: 19.9 % of the orbit, 2 249 s, in shadow.
//!
//! Time: t is the time since eclipse entry (θ = π − φ at t = 0), in [0, P); the
//! eclipse lasts t < [`Orbit::eclipse_duration_s`]. Without eclipse t counts from the
//! midnight point θ = π.

use super::ThermalError;
use crate::world::constants::{EARTH_DISTANCE_M, EARTH_RADIUS_M};
use crate::world::geom::Vec3;

/// Earth's gravitational parameter μ = GM, m³ s⁻² (WGS 84 / IERS value
/// 3.986004418 × 10¹⁴).
pub const EARTH_MU_M3_S2: f64 = 3.986_004_418e14;

/// A circular orbit around the Earth with the Sun at β from its plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Orbit radius (distance from the Earth's centre), m (> `earth_radius_m`).
    pub radius_m: f64,
    /// Earth radius, m (> 0).
    pub earth_radius_m: f64,
    /// Angle β between the Sun direction and the orbit plane, rad (−π/2..=π/2).
    pub beta_rad: f64,
}

/// The Sun and Earth as seen from the target's body frame at one time on the orbit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitGeometry {
    /// Time since eclipse entry, s (0..period).
    pub time_s: f64,
    /// Unit vector to the Sun, body frame (`None`: in the Earth's shadow).
    pub sun_dir_body: Option<Vec3>,
    /// Unit vector to the Earth's centre, body frame (always −z).
    pub earth_dir_body: Vec3,
    /// Cosine of the Sun's elevation at the sub-target point (max(0, r̂·S)): scales the
    /// albedo; 0 in eclipse.
    pub sun_earth_cos: f64,
}

impl Orbit {
    /// The reference orbit: radius [`EARTH_DISTANCE_M`] (altitude 4 500 km), Earth
    /// radius [`EARTH_RADIUS_M`], Sun in the orbit plane (β = 0).
    pub fn reference() -> Orbit {
        Orbit {
            radius_m: EARTH_DISTANCE_M,
            earth_radius_m: EARTH_RADIUS_M,
            beta_rad: 0.0,
        }
    }

    /// The orbit, or why not (radius not above the Earth radius, β out of range).
    pub fn checked(&self) -> Result<Orbit, ThermalError> {
        let bad = |reason: &str| {
            Err(ThermalError::BadTransient {
                reason: format!("orbit {self:?}: {reason}"),
            })
        };
        if !(self.earth_radius_m.is_finite() && self.earth_radius_m > 0.0) {
            return bad("Earth radius not positive and finite");
        }
        if !(self.radius_m.is_finite() && self.radius_m > self.earth_radius_m) {
            return bad("radius not finite or not above the Earth radius");
        }
        if !(-std::f64::consts::FRAC_PI_2..=std::f64::consts::FRAC_PI_2).contains(&self.beta_rad) {
            return bad("beta outside −π/2..=π/2");
        }
        Ok(*self)
    }

    /// Orbital period 2π√(a³/μ), s (11 280 s for the reference orbit).
    pub fn period_s(&self) -> f64 {
        std::f64::consts::TAU * (self.radius_m.powi(3) / EARTH_MU_M3_S2).sqrt()
    }

    /// Shadow half-angle φ about the midnight point, rad (0: no eclipse).
    pub fn eclipse_half_angle_rad(&self) -> f64 {
        let rho = (self.earth_radius_m / self.radius_m).clamp(0.0, 1.0);
        let c = (1.0 - rho * rho).sqrt() / self.beta_rad.cos();
        if c.is_finite() && c < 1.0 {
            c.acos()
        } else {
            0.0
        }
    }

    /// Time in the Earth's shadow per orbit, s (cylindrical shadow).
    pub fn eclipse_duration_s(&self) -> f64 {
        self.eclipse_half_angle_rad() / std::f64::consts::PI * self.period_s()
    }

    /// The Sun and Earth in the body frame at `time_s` since eclipse entry (taken
    /// modulo the period).
    pub fn geometry(&self, time_s: f64) -> OrbitGeometry {
        let p = self.period_s();
        let t = time_s.rem_euclid(p);
        let phi = self.eclipse_half_angle_rad();
        let theta = std::f64::consts::PI - phi + std::f64::consts::TAU * t / p;
        let (cb, sb) = (self.beta_rad.cos(), self.beta_rad.sin());
        let s = [-cb * theta.sin(), sb, cb * theta.cos()];
        let shadow = phi > 0.0 && t < self.eclipse_duration_s();
        OrbitGeometry {
            time_s: t,
            sun_dir_body: (!shadow).then_some(s),
            earth_dir_body: [0.0, 0.0, -1.0],
            sun_earth_cos: if shadow { 0.0 } else { s[2].max(0.0) },
        }
    }
}
