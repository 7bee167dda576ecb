//! The thermal camera model of the paper (Sections 3.1 and 3.3): what the Hayabusa2-like
//! microbolometer does between the scene's radiance and the frame of DN.
//!
//! Data flows one way through these modules:
//!
//! 1. [`response`]: the camera response R(λ) = η·R_L(λ)·R_F(λ) (Eq. 3): by default the
//!    Hayabusa2 TIR's measured curve (the const table of [`response_table`], linear
//!    between its 0.01 µm samples, 0 outside 5.01–17.91 µm), or the analytic
//!    skewed-bell band model (8–12 µm), or a flat R = 1 for hand checks.
//! 2. [`planck`]: band radiance i(T, ε) = ∫ ε B(λ,T) R(λ) dλ (Eqs. 1, 6) and emissive
//!    power F(T) = π·i, exact in f64, in f32, and by the fast table of [`band_lut`].
//! 3. [`flux`]: the view-factor flux q_fc a facet sends onto the sensor (Eqs. 2, 4) and
//!    the distance compensation D (Eq. 7).
//! 4. [`dn`]: the linear DN map of radiometry mode (Eqs. 5, 17) and detection mode
//!    (Eq. 9, Table 5), quantisation with saturation, and the inverse T_rad (Eq. 8).
//! 5. [`noise`]: Johnson, 1/f and temperature-fluctuation noise (Eqs. 11–16, Tables 1,
//!    2), the noise levels, and a seeded noise field generated row by row.
//! 6. [`expose`]: one pass from a frame of signal (F or q_fc per pixel) to the noisy
//!    camera frame of DN (Eq. 18), row by row.
//!
//! Units are SI unless a name says otherwise (`_um` micrometres, `_k` kelvin,
//! `_w_m2_sr` W m⁻² sr⁻¹). Every function that takes physical input validates it and
//! returns [`SensorError`] for NaN, infinite, negative or out-of-domain values; none
//! panics.

pub mod band_lut;
// Generated tables (the `const` band radiance and fast table); not reformatted, so the
// test in `band_tables_check` can compare the file with its generator's text.
#[rustfmt::skip]
mod band_tables;
#[cfg(test)]
mod band_tables_check;
pub mod dn;
pub mod expose;
pub mod flux;
pub mod gaussian;
pub mod noise;
pub mod planck;
pub mod response;
pub mod response_table;
pub mod rng;

use core::fmt;

pub use band_lut::BandLut;
pub use dn::{DetectionScale, DnMapping};
pub use expose::expose_frame;
pub use flux::SENSOR_AREA_M2;
pub use noise::{BolometerParams, NoiseField, NoiseLevel, NoiseSigmas, RmsReading};
pub use planck::BandRadiance;
pub use response::{CameraResponse, SkewedBell, TabulatedResponse};

/// Why a camera-model function refused its input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SensorError {
    /// An input is NaN or infinite.
    NotFinite {
        /// The parameter's name.
        name: &'static str,
    },
    /// An input lies outside its documented domain.
    OutOfRange {
        /// The parameter's name.
        name: &'static str,
        /// The value that was given.
        value: f64,
        /// What the domain is.
        expected: &'static str,
    },
    /// A buffer has the wrong length or a frame is larger than the core holds.
    BadSize {
        /// The buffer's name.
        name: &'static str,
        /// The length that was given.
        actual: usize,
        /// The length that was expected (or the largest allowed).
        expected: usize,
    },
}

impl fmt::Display for SensorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            SensorError::NotFinite { name } => write!(f, "`{name}` is NaN or infinite"),
            SensorError::OutOfRange {
                name,
                value,
                expected,
            } => write!(f, "`{name}` = {value} is out of range: expected {expected}"),
            SensorError::BadSize {
                name,
                actual,
                expected,
            } => write!(f, "`{name}` has length {actual}, expected {expected}"),
        }
    }
}

/// Checks that `value` is finite and within `[min, max]`.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    min: f64,
    max: f64,
    expected: &'static str,
) -> Result<f64, SensorError> {
    if !value.is_finite() {
        return Err(SensorError::NotFinite { name });
    }
    if value < min || value > max {
        return Err(SensorError::OutOfRange {
            name,
            value,
            expected,
        });
    }
    Ok(value)
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<f64, SensorError> {
    check_range(
        name,
        value,
        f64::MIN_POSITIVE,
        f64::MAX,
        "a finite value > 0",
    )
}
