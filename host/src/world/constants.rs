//! Physical constants of the world shared by the scene, the Earth and the spacecraft
//! models: each appears once, in metres; derived values are computed from them.

/// Mean Earth radius, m.
pub const EARTH_RADIUS_M: f64 = 6_371e3;

/// Altitude of the reference orbit above the mean Earth radius, m.
pub const ORBIT_ALTITUDE_M: f64 = 4_500e3;

/// Distance from the Earth's centre to the spacecraft on the reference orbit, m
/// ([`EARTH_RADIUS_M`] + [`ORBIT_ALTITUDE_M`]).
pub const EARTH_DISTANCE_M: f64 = EARTH_RADIUS_M + ORBIT_ALTITUDE_M;
