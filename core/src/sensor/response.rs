//! The camera response R(λ) = η·R_L(λ)·R_F(λ) of paper Eq. 3.
//!
//! The default is the real one: [`TabulatedResponse::HAYABUSA2_TIR`], the response of
//! JAXA's Hayabusa2 TIR as its team measured it (lens, filter and detector together, so
//! η is inside the numbers), on a 0.01 µm grid from 5.01 to 17.91 µm, linear between the
//! samples and 0 outside. The table is generated from `core/data/hayabusa2-tir/response.txt`
//! (provenance in the NOTICE beside it) into [`response_table`](super::response_table);
//! its 30-digit band integrals are in `core/tests/data/band_radiance_hayabusa2_reference.csv`,
//! made by `scripts/reference/band_radiance_hayabusa2.py`.
//!
//! The analytic model stays selectable (`CameraResponse::Band`). The paper fits "skewed bell-shaped curves" to the Hayabusa2 TIR data of its ref. \[33\]
//! (Fig. 1) without printing the numbers. [`SkewedBell::HAYABUSA2_TIR`] adopts the model
//! of the project's shared reference (`shared/reference/REFERENCE.md`, §3), a rounded
//! least-squares fit to the measured TIR curve: a logistic rise (the lens and filter
//! cut-on), a logistic fall (the filter cut-off), and an exponential tilt for the
//! plateau that falls towards long wavelengths. Its 30-digit band integrals are in
//! `core/tests/data/band_radiance_reference.csv`, made by
//! `scripts/reference/band_radiance.py`.

use super::response_table;
use super::{SensorError, check_positive, check_range};

/// Analytic skewed-bell band model (λ in µm, σ(z) = 1/(1 + e^(−z))):
///
/// S(λ) = σ((λ − λ_rise)/w_rise) · σ((λ_fall − λ)/w_fall) · exp(−k·(λ − λ_pivot)),
/// R(λ) = η·S(λ)/S_max on [λ_min, λ_max], 0 outside,
///
/// so that R peaks at exactly η. The two logistic factors stand for R_L·R_F, η for the
/// detection efficiency of Eq. 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkewedBell {
    /// Peak response η (dimensionless, 0 < η ≤ 1). Default 1, so that the tests compare
    /// against the reference table directly; the measured TIR curve behaves like
    /// η ≈ 0.887 (REFERENCE.md §3 cross-check against HEAT's `tir_response.txt`).
    pub eta: f64,
    /// 50 % point of the rising edge, µm: 8.15 (measured: 8.14 µm; REFERENCE.md §2).
    pub rise_um: f64,
    /// Logistic width of the rising edge, µm: 0.075 (fit; free fit 0.0757).
    pub rise_width_um: f64,
    /// 50 % point of the falling edge, µm: 12.0 (measured: 11.96 µm).
    pub fall_um: f64,
    /// Logistic width of the falling edge, µm: 0.10 (fit; free fit 0.0994).
    pub fall_width_um: f64,
    /// Exponential tilt of the plateau, 1/µm: 0.075 (fit; free fit 0.0742). Positive
    /// values make the response fall towards long wavelengths, as measured (0.85 at
    /// 9 µm to 0.60 at 11.8 µm).
    pub tilt_per_um: f64,
    /// Wavelength where the tilt factor is 1, µm: 10 (a convention; it cancels in S/S_max).
    pub tilt_pivot_um: f64,
    /// Shortest wavelength with a response, µm: 6 (R(6) = 4.3e-13).
    pub band_min_um: f64,
    /// Longest wavelength with a response, µm: 16 (R(16) = 2.4e-18; the cut matters only
    /// below about 10 K, where the out-of-band tail dominates).
    pub band_max_um: f64,
}

impl SkewedBell {
    /// The Hayabusa2 TIR model of the shared reference (η = 1): R(8 µm) = 0.1248,
    /// R(10 µm) = 0.9012, R(12 µm) = 0.3878, peak 1 at 8.538 µm, ∫R dλ = 3.4620 µm.
    pub const HAYABUSA2_TIR: SkewedBell = SkewedBell {
        eta: 1.0,
        rise_um: 8.15,
        rise_width_um: 0.075,
        fall_um: 12.0,
        fall_width_um: 0.10,
        tilt_per_um: 0.075,
        tilt_pivot_um: 10.0,
        band_min_um: 6.0,
        band_max_um: 16.0,
    };

    /// Checks every parameter: η in (0, 1], widths > 0, 0 < λ_min < λ_rise < λ_fall <
    /// λ_max ≤ 1000 µm, finite tilt.
    ///
    /// # Errors
    /// [`SensorError`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_range("eta", self.eta, f64::MIN_POSITIVE, 1.0, "0 < eta <= 1")?;
        check_positive("rise_width_um", self.rise_width_um)?;
        check_positive("fall_width_um", self.fall_width_um)?;
        check_range(
            "tilt_per_um",
            self.tilt_per_um,
            -10.0,
            10.0,
            "-10..=10 per um",
        )?;
        check_range(
            "tilt_pivot_um",
            self.tilt_pivot_um,
            0.0,
            1000.0,
            "0..=1000 um",
        )?;
        check_range(
            "band_min_um",
            self.band_min_um,
            0.1,
            1000.0,
            "0.1..=1000 um",
        )?;
        check_range(
            "rise_um",
            self.rise_um,
            self.band_min_um,
            1000.0,
            "band_min_um <= rise_um",
        )?;
        check_range(
            "fall_um",
            self.fall_um,
            self.rise_um,
            1000.0,
            "rise_um <= fall_um",
        )?;
        check_range(
            "band_max_um",
            self.band_max_um,
            self.fall_um,
            1000.0,
            "fall_um <= band_max_um <= 1000 um",
        )?;
        if self.band_max_um <= self.band_min_um {
            return Err(SensorError::OutOfRange {
                name: "band_max_um",
                value: self.band_max_um,
                expected: "band_max_um > band_min_um",
            });
        }
        Ok(())
    }

    /// The unnormalised shape S(λ), λ in µm (no band cut).
    pub fn shape(&self, lambda_um: f64) -> f64 {
        logistic((lambda_um - self.rise_um) / self.rise_width_um)
            * logistic((self.fall_um - lambda_um) / self.fall_width_um)
            * libm::exp(-self.tilt_per_um * (lambda_um - self.tilt_pivot_um))
    }

    /// d ln S / dλ, 1/µm: strictly decreasing in λ, so S has one maximum.
    fn dln_shape(&self, lambda_um: f64) -> f64 {
        (1.0 - logistic((lambda_um - self.rise_um) / self.rise_width_um)) / self.rise_width_um
            - (1.0 - logistic((self.fall_um - lambda_um) / self.fall_width_um)) / self.fall_width_um
            - self.tilt_per_um
    }

    /// The wavelength of the peak of S within the band, µm, and S there. Bisection on
    /// d ln S/dλ (decreasing), to the last bit.
    pub fn peak(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (self.band_min_um, self.band_max_um);
        if self.dln_shape(hi) >= 0.0 {
            lo = hi;
        } else if self.dln_shape(lo) <= 0.0 {
            hi = lo;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.dln_shape(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let lambda = 0.5 * (lo + hi);
        (lambda, self.shape(lambda))
    }
}

impl Default for SkewedBell {
    fn default() -> Self {
        Self::HAYABUSA2_TIR
    }
}

/// The logistic function 1/(1 + e^(−z)), without overflow for any z.
fn logistic(z: f64) -> f64 {
    if z >= 0.0 {
        1.0 / (1.0 + libm::exp(-z))
    } else {
        let e = libm::exp(z);
        e / (1.0 + e)
    }
}

/// A response tabulated on a uniform wavelength grid: sample i is R at
/// λ_i = `first_um` + i·`step_um`, in millionths (exact for data given to 6 decimals).
///
/// Interpolation rule: R is linear in λ between neighbouring samples and 0 outside
/// [λ_0, λ_last] (a measured response ends in zero samples, so this is continuous).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TabulatedResponse {
    /// Wavelength of the first sample, µm (≥ 0.1).
    pub first_um: f64,
    /// Spacing of the samples, µm (> 0).
    pub step_um: f64,
    /// R at each sample, in units of 1e-6 (dimensionless; |R| ≤ 1). At least 2 samples.
    pub samples_micro: &'static [i32],
}

/// Millionths per unit of response: the scale of [`TabulatedResponse::samples_micro`].
const MICRO_PER_UNIT: f64 = 1_000_000.0;

impl TabulatedResponse {
    /// The measured response of the Hayabusa2 TIR (η included): 1291 samples from
    /// 5.01 µm to 17.91 µm, step 0.01 µm, peak 0.908740 at 8.85 µm, ∫R dλ = 3.06913 µm.
    /// Outside the stored span the source file is 0 everywhere, so nothing is cut.
    pub const HAYABUSA2_TIR: TabulatedResponse = TabulatedResponse {
        first_um: response_table::FIRST_CENTI_UM as f64 / 100.0,
        step_um: 0.01,
        samples_micro: &response_table::RESPONSE_MICRO,
    };

    /// Checks the grid: `first_um` in [0.1, 1000] µm, `step_um` in (0, 1000] µm, the
    /// last sample at most 1000 µm, at least 2 samples, every |R| ≤ 1.
    ///
    /// # Errors
    /// [`SensorError`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_range("first_um", self.first_um, 0.1, 1000.0, "0.1..=1000 um")?;
        check_range(
            "step_um",
            self.step_um,
            f64::MIN_POSITIVE,
            1000.0,
            "0 < step_um <= 1000 um",
        )?;
        if self.samples_micro.len() < 2 {
            return Err(SensorError::BadSize {
                name: "samples_micro",
                actual: self.samples_micro.len(),
                expected: 2,
            });
        }
        check_range(
            "samples_micro (last wavelength)",
            self.last_um(),
            self.first_um,
            1000.0,
            "a last sample at most 1000 um",
        )?;
        for &r in self.samples_micro {
            check_range(
                "samples_micro",
                f64::from(r),
                -MICRO_PER_UNIT,
                MICRO_PER_UNIT,
                "|R| <= 1 (1 000 000 millionths)",
            )?;
        }
        Ok(())
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples_micro.len()
    }

    /// True for a table without samples (never valid).
    pub fn is_empty(&self) -> bool {
        self.samples_micro.is_empty()
    }

    /// R at sample `i`, dimensionless (0 past the end).
    pub fn sample(&self, i: usize) -> f64 {
        // An integer over a power of ten: correctly rounded, the same f64 as the
        // data file's decimal.
        self.samples_micro
            .get(i)
            .map_or(0.0, |&r| f64::from(r) / MICRO_PER_UNIT)
    }

    /// Wavelength of sample `i`, µm.
    pub fn wavelength_um(&self, i: usize) -> f64 {
        self.first_um + i as f64 * self.step_um
    }

    /// Wavelength of the last sample, µm.
    pub fn last_um(&self) -> f64 {
        self.wavelength_um(self.samples_micro.len().saturating_sub(1))
    }

    /// R(λ), dimensionless, λ in µm: linear between samples, 0 outside the table (and
    /// for NaN).
    pub fn at(&self, lambda_um: f64) -> f64 {
        let n = self.samples_micro.len();
        let u = (lambda_um - self.first_um) / self.step_um;
        if n < 2 || !(u >= 0.0 && u <= (n - 1) as f64) {
            return 0.0;
        }
        let i = (u as usize).min(n - 2);
        let t = u - i as f64;
        self.sample(i) * (1.0 - t) + self.sample(i + 1) * t
    }
}

/// Which spectral response the camera model integrates over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CameraResponse {
    /// A measured response on a wavelength grid (the default: the Hayabusa2 TIR's,
    /// [`TabulatedResponse::HAYABUSA2_TIR`]; `tirroi sensor --response hayabusa2`).
    Tabulated(TabulatedResponse),
    /// The analytic band model ([`SkewedBell::HAYABUSA2_TIR`]: `--response tir`).
    Band(SkewedBell),
    /// R(λ) = 1 at every wavelength: the band radiance becomes ε·σT⁴/π, a check anyone
    /// can do by hand (`tirroi sensor --response flat`).
    Flat,
}

impl Default for CameraResponse {
    /// The measured Hayabusa2 TIR response.
    fn default() -> Self {
        CameraResponse::Tabulated(TabulatedResponse::HAYABUSA2_TIR)
    }
}

impl CameraResponse {
    /// R(λ), dimensionless, λ in µm: 0 outside the band (and for NaN); η at the peak of
    /// the bell, 0.90874 at the peak of the measured table.
    pub fn at(&self, lambda_um: f64) -> f64 {
        match self {
            CameraResponse::Flat => 1.0,
            CameraResponse::Tabulated(t) => t.at(lambda_um),
            CameraResponse::Band(b) => {
                if !(lambda_um >= b.band_min_um && lambda_um <= b.band_max_um) {
                    return 0.0;
                }
                b.eta * b.shape(lambda_um) / b.peak().1
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tir_model_matches_the_reference_points() {
        let b = SkewedBell::HAYABUSA2_TIR;
        let (l_pk, s_max) = b.peak();
        assert!((l_pk - 8.538_117_008_825_108).abs() < 1e-12, "{l_pk}");
        assert!((s_max - 1.109_600_837_115_338_6).abs() < 1e-14, "{s_max}");
        let r = CameraResponse::Band(b);
        for (l, want) in [(8.0, 0.124814), (10.0, 0.901225), (12.0, 0.387846)] {
            assert!((r.at(l) - want).abs() < 1e-6, "R({l}) = {}", r.at(l));
        }
        assert!((r.at(6.0) - 4.32e-13).abs() < 1e-14);
        assert_eq!(r.at(5.99), 0.0);
        assert_eq!(r.at(16.01), 0.0);
        assert_eq!(r.at(f64::NAN), 0.0);
        assert!((r.at(l_pk) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn measured_table_interpolates_linearly_and_is_zero_outside() {
        let t = TabulatedResponse::HAYABUSA2_TIR;
        assert!(t.validate().is_ok());
        assert_eq!(t.len(), 1291);
        let r = CameraResponse::default();
        // Samples of the data file: 8.85 um 0.908740 (the peak), 8.86 um 0.907822.
        assert!((r.at(8.85) - 0.90874).abs() < 1e-12);
        assert!((r.at(8.855) - 0.5 * (0.90874 + 0.907822)).abs() < 1e-12);
        assert_eq!(r.at(5.0), 0.0);
        assert_eq!(r.at(17.92), 0.0);
        assert_eq!(r.at(f64::NAN), 0.0);
        let peak = (0..t.len()).map(|i| t.sample(i)).fold(0.0, f64::max);
        assert_eq!(peak, 0.90874);
        let bad = TabulatedResponse {
            samples_micro: &[0],
            ..t
        };
        assert!(matches!(
            bad.validate(),
            Err(SensorError::BadSize {
                name: "samples_micro",
                ..
            })
        ));
        let bad = TabulatedResponse { step_um: 0.0, ..t };
        assert!(bad.validate().is_err());
    }

    #[test]
    fn validation_names_the_field() {
        let mut b = SkewedBell::HAYABUSA2_TIR;
        b.eta = 0.0;
        assert!(matches!(
            b.validate(),
            Err(SensorError::OutOfRange { name: "eta", .. })
        ));
        let mut b = SkewedBell::HAYABUSA2_TIR;
        b.fall_um = 7.0;
        assert!(b.validate().is_err());
        let mut b = SkewedBell::HAYABUSA2_TIR;
        b.rise_width_um = f64::NAN;
        assert_eq!(
            b.validate(),
            Err(SensorError::NotFinite {
                name: "rise_width_um"
            })
        );
        assert!(SkewedBell::HAYABUSA2_TIR.validate().is_ok());
    }
}
