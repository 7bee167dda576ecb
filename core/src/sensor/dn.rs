//! From signal to digital numbers (DN): the linear camera response of radiometry mode
//! (Eq. 5, auto-ranged by Eq. 17) and detection mode (Eq. 9 with the fixed scales of
//! Table 5), quantisation to the bit depth with saturation, and the way back to a
//! radiometric temperature (Eq. 8).
//!
//! Both modes are one linear map DN = a·s + b of a per-pixel signal s: the emissive
//! power F(T) in W m⁻² (radiometry) or the view-factor flux q_fc in W m⁻² (detection).
//! [`DnMapping`] holds a, b and the bit depth; [`DnMapping::quantise`] rounds to the
//! nearest DN and saturates at 0 and 2ⁿ − 1, never wrapping (NaN gives 0).

use super::planck::{BandRadiance, STEFAN_BOLTZMANN_W_M2_K4};
use super::{SensorError, check_positive, check_range};
use crate::frame::MAX_BIT_DEPTH;

/// The Earth's maximum detected flux of Table 5, q_fc,max^Earth = 3·10⁻¹⁷ W m⁻².
///
/// Under the reading of [`crate::sensor::flux`] (ΔA_c = the whole sensor area, Earth at
/// 10 871 km, band radiance of the TIR model) the warmest Earth cell (OLR 330 W m⁻²,
/// 276.2 K) gives 2.07·10⁻¹⁷ W m⁻²: the same order (core/tests/sensor_scales.rs).
pub const EARTH_MAX_FLUX_TABLE5_W_M2: f64 = 3e-17;

/// Bit depth at which a fixed radiometry gain is given (the frames' default, 14 bits).
pub const FIXED_GAIN_REFERENCE_BITS: u8 = 14;

/// The fixed radiance scales of detection mode (paper Table 5): q_min = 0 and q_max a
/// multiple of the Earth's maximum detected flux.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DetectionScale {
    /// Scale 1: q_max = q_Earth,max = 3·10⁻¹⁷ W m⁻².
    Scale1,
    /// Scale 2: q_max = 2·q_Earth,max = 6·10⁻¹⁷ W m⁻².
    Scale2,
    /// Scale 3: q_max = 10·q_Earth,max = 3·10⁻¹⁶ W m⁻².
    Scale3,
    /// Any other full scale q_max, W m⁻² (finite, > 0).
    Custom(f64),
}

impl DetectionScale {
    /// The three scales of Table 5.
    pub const TABLE5: [DetectionScale; 3] = [Self::Scale1, Self::Scale2, Self::Scale3];

    /// The full-scale flux q_max, W m⁻².
    pub fn q_max_w_m2(&self) -> f64 {
        match *self {
            Self::Scale1 => EARTH_MAX_FLUX_TABLE5_W_M2,
            Self::Scale2 => 2.0 * EARTH_MAX_FLUX_TABLE5_W_M2,
            Self::Scale3 => 10.0 * EARTH_MAX_FLUX_TABLE5_W_M2,
            Self::Custom(q) => q,
        }
    }
}

/// The linear map DN = a·s + b from a signal s to DN, and the bit depth that bounds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DnMapping {
    gain_dn: f64,
    offset_dn: f64,
    bits: u8,
}

impl DnMapping {
    /// A map with camera gain `gain_dn` (a, DN per unit of signal, > 0) and offset
    /// `offset_dn` (b, DN), quantised to `bits` (1..=16).
    ///
    /// # Errors
    /// [`SensorError`] for a gain that is not finite and ≥ 2.2e-308 (a normal f64, so
    /// that 1/a is finite), a non-finite offset, or a
    /// bit depth outside 1..=16.
    pub fn new(gain_dn: f64, offset_dn: f64, bits: u8) -> Result<Self, SensorError> {
        check_positive("gain_dn", gain_dn)?;
        check_range("offset_dn", offset_dn, f64::MIN, f64::MAX, "a finite DN")?;
        check_range(
            "bits",
            f64::from(bits),
            1.0,
            f64::from(MAX_BIT_DEPTH),
            "1..=16",
        )?;
        Ok(DnMapping {
            gain_dn,
            offset_dn,
            bits,
        })
    }

    /// Radiometry mode auto-ranged as in Eq. 17: F_min ↦ DN 0 and F_max ↦ 2ⁿ − 1, for
    /// the smallest and largest emissive power in the scene (target and Earth), W m⁻².
    ///
    /// # Errors
    /// [`SensorError`] unless 0 ≤ F_min < F_max are finite, or for a bad bit depth.
    pub fn radiometry_auto(
        f_min_w_m2: f64,
        f_max_w_m2: f64,
        bits: u8,
    ) -> Result<Self, SensorError> {
        check_range("f_min_w_m2", f_min_w_m2, 0.0, f64::MAX, "a finite F >= 0")?;
        check_range(
            "f_max_w_m2",
            f_max_w_m2,
            f_min_w_m2,
            f64::MAX,
            "a finite F > f_min_w_m2",
        )?;
        Self::range_map(
            (f_min_w_m2, f_max_w_m2),
            bits,
            "f_max_w_m2",
            "F_max > F_min (a scene of one temperature has no range)",
        )
    }

    /// Eq. 17 on a camera's measured signal: `lo` ↦ DN 0 and `hi` ↦ 2ⁿ − 1 for any
    /// finite `lo` < `hi` (the signal's unit, W m⁻² for F). A camera ranges on what it
    /// measures, the scene's F plus its own offset (shading, fixed pattern), which can
    /// put the low end below 0 where the scene's F cannot be ([`Self::radiometry_auto`]).
    ///
    /// # Errors
    /// [`SensorError`] unless `lo` < `hi` are finite with a span whose gain is normal,
    /// or for a bad bit depth.
    pub fn radiometry_auto_measured(lo: f64, hi: f64, bits: u8) -> Result<Self, SensorError> {
        check_range("lo", lo, f64::MIN, f64::MAX, "a finite signal")?;
        check_range("hi", hi, lo, f64::MAX, "a finite signal > lo")?;
        Self::range_map(
            (lo, hi),
            bits,
            "hi",
            "hi > lo (a signal of one level has no range)",
        )
    }

    /// `lo` ↦ DN 0 and `hi` ↦ 2ⁿ − 1 (both Eq. 17 maps, their ends checked by the
    /// caller); an empty span is refused as `hi_name` with `one_level`.
    fn range_map(
        (lo, hi): (f64, f64),
        bits: u8,
        hi_name: &'static str,
        one_level: &'static str,
    ) -> Result<Self, SensorError> {
        let span = hi - lo;
        if span.is_nan() || span <= 0.0 {
            return Err(SensorError::OutOfRange {
                name: hi_name,
                value: hi,
                expected: one_level,
            });
        }
        let gain = full_scale(bits) / span;
        Self::new(gain, -gain * lo, bits)
    }

    /// Radiometry mode with a fixed gain instead of Eq. 17's auto range: a real
    /// camera's read-out, DN = a·F + b with a = `dn_per_w_m2_sr`/π (F = π·L, Eq. 6) at
    /// [`FIXED_GAIN_REFERENCE_BITS`] bits, scaled by 2^(bits − 14) for another depth,
    /// and the pedestal b = `pedestal_dn` (DN of F = 0, likewise scaled) that keeps
    /// deep space above 0 DN.
    ///
    /// # Errors
    /// [`SensorError`] for a gain that is not finite and > 0, a pedestal that is not
    /// finite, or a bit depth outside 1..=16.
    pub fn radiometry_fixed_gain(
        dn_per_w_m2_sr: f64,
        pedestal_dn: f64,
        bits: u8,
    ) -> Result<Self, SensorError> {
        check_positive("dn_per_w_m2_sr", dn_per_w_m2_sr)?;
        check_range(
            "pedestal_dn",
            pedestal_dn,
            f64::MIN,
            f64::MAX,
            "a finite DN",
        )?;
        let depth = full_scale(bits);
        if depth == 0.0 {
            return Self::new(1.0, 0.0, bits);
        }
        let k = libm::exp2(f64::from(bits) - f64::from(FIXED_GAIN_REFERENCE_BITS));
        Self::new(
            k * dn_per_w_m2_sr / core::f64::consts::PI,
            k * pedestal_dn,
            bits,
        )
    }

    /// Detection mode (Eq. 9) with a fixed scale of Table 5: q = 0 ↦ DN 0 and
    /// q_max ↦ 2ⁿ − 1 (a = (2ⁿ − 1)/q_max, b = 0).
    ///
    /// # Errors
    /// [`SensorError`] for a custom q_max that is not finite and > 0, or a bad bit depth.
    pub fn detection(scale: DetectionScale, bits: u8) -> Result<Self, SensorError> {
        let q_max = check_positive("q_max_w_m2", scale.q_max_w_m2())?;
        Self::new(full_scale(bits) / q_max, 0.0, bits)
    }

    /// Camera gain a, DN per unit of signal.
    pub fn gain_dn(&self) -> f64 {
        self.gain_dn
    }

    /// Camera offset b, DN.
    pub fn offset_dn(&self) -> f64 {
        self.offset_dn
    }

    /// Bit depth n.
    pub fn bits(&self) -> u8 {
        self.bits
    }

    /// Largest DN, 2ⁿ − 1 (saturation).
    pub fn max_dn(&self) -> u16 {
        ((1u32 << self.bits) - 1) as u16
    }

    /// The unquantised DN a·s + b (Eqs. 5, 9) of a signal.
    pub fn dn(&self, signal: f64) -> f64 {
        self.gain_dn * signal + self.offset_dn
    }

    /// Rounds `dn` to the nearest integer and saturates to 0..=2ⁿ − 1; NaN gives 0.
    pub fn quantise(&self, dn: f64) -> u16 {
        // `as` saturates (and maps NaN to 0); the clamp adds the bit depth's ceiling.
        ((dn + 0.5) as u32).min(u32::from(self.max_dn())) as u16
    }

    /// The signal a DN stands for, (DN − b)/a: the inverse of [`DnMapping::dn`].
    pub fn signal(&self, dn: f64) -> f64 {
        (dn - self.offset_dn) / self.gain_dn
    }

    /// ∂DN/∂T at `t_ref_k` for a blackbody (ε = 1), DN K⁻¹: a · s_L · ∂L/∂T, where
    /// `signal_per_radiance_sr` s_L turns band radiance into this map's signal: π for
    /// radiometry mode (F = π·L, Eq. 6), ΔA_c·cos θ_f·cos θ_s/r² for detection mode
    /// ([`crate::sensor::flux::view_factor_per_m2`] × ΔA_c). The scale of the `netd`
    /// noise level.
    ///
    /// # Errors
    /// [`SensorError`] for a temperature outside [0, 10 000] K or a factor that is not
    /// finite and ≥ 0.
    pub fn dn_per_kelvin(
        &self,
        band: &BandRadiance,
        t_ref_k: f64,
        signal_per_radiance_sr: f64,
    ) -> Result<f64, SensorError> {
        check_range(
            "signal_per_radiance_sr",
            signal_per_radiance_sr,
            0.0,
            f64::MAX,
            "a finite factor >= 0",
        )?;
        Ok(self.gain_dn
            * signal_per_radiance_sr
            * band.radiance_derivative_w_m2_sr_k(t_ref_k, 1.0)?)
    }

    /// Radiometric temperature of a radiometry-mode DN by Eq. 8 exactly as printed,
    /// T_rad = ((DN − b)/(a·σ))^(1/4), K: the inverse of F = σT⁴, which is the emissive
    /// power of the flat response. For the band response use
    /// [`DnMapping::radiometric_temperature_k`]. 0 for DN at or below b.
    pub fn t_rad_eq8_k(&self, dn: f64) -> f64 {
        let f = self.signal(dn);
        if f.is_nan() || f <= 0.0 {
            return 0.0;
        }
        libm::sqrt(libm::sqrt(f / STEFAN_BOLTZMANN_W_M2_K4))
    }

    /// Radiometric temperature of a radiometry-mode DN, K: the T whose band emissive
    /// power π·ε·L(T) (Eq. 6) maps to `dn`. This is Eq. 8 with σT⁴ replaced by the
    /// camera's own F(T), so that T → DN → T round-trips within one quantisation step.
    /// 0 for DN at or below b.
    ///
    /// # Errors
    /// [`SensorError`] for ε outside (0, 1] or a DN above what 10 000 K gives.
    pub fn radiometric_temperature_k(
        &self,
        dn: f64,
        band: &BandRadiance,
        emissivity: f64,
    ) -> Result<f64, SensorError> {
        let f = self.signal(dn);
        if f.is_nan() || f <= 0.0 {
            return Ok(0.0);
        }
        band.temperature_k(f / core::f64::consts::PI, emissivity)
    }
}

/// 2ⁿ − 1 as f64 (0 for a bad depth, which the constructors then refuse).
fn full_scale(bits: u8) -> f64 {
    if (1..=MAX_BIT_DEPTH).contains(&bits) {
        f64::from((1u32 << bits) - 1)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_gain_is_the_affine_map_of_radiance_scaled_by_bit_depth() {
        let m = DnMapping::radiometry_fixed_gain(12.0, 1024.0, 14).unwrap();
        // F = π·L: L = 10 W m⁻² sr⁻¹ gives 120 DN above the pedestal.
        let f = core::f64::consts::PI * 10.0;
        assert!((m.dn(f) - 1144.0).abs() < 1e-9);
        assert!((m.dn(0.0) - 1024.0).abs() < 1e-12);
        let m12 = DnMapping::radiometry_fixed_gain(12.0, 1024.0, 12).unwrap();
        assert!((m12.dn(f) - 1144.0 / 4.0).abs() < 1e-9);
        assert!(DnMapping::radiometry_fixed_gain(0.0, 0.0, 14).is_err());
        assert!(DnMapping::radiometry_fixed_gain(1.0, f64::NAN, 14).is_err());
        assert!(DnMapping::radiometry_fixed_gain(1.0, 0.0, 17).is_err());
    }

    #[test]
    fn quantise_saturates_and_never_wraps() {
        let m = DnMapping::new(1.0, 0.0, 14).unwrap();
        assert_eq!(m.quantise(-5.0), 0);
        assert_eq!(m.quantise(f64::NAN), 0);
        assert_eq!(m.quantise(1e30), 16383);
        assert_eq!(m.quantise(f64::INFINITY), 16383);
        assert_eq!(m.quantise(16382.6), 16383);
        assert_eq!(m.quantise(2.49), 2);
        assert_eq!(m.quantise(2.5), 3);
        let m16 = DnMapping::new(1.0, 0.0, 16).unwrap();
        assert_eq!(m16.quantise(70_000.0), 65535);
    }

    #[test]
    fn scales_follow_table5() {
        let m = DnMapping::detection(DetectionScale::Scale1, 14).unwrap();
        assert_eq!(m.quantise(m.dn(3e-17)), 16383);
        assert_eq!(m.quantise(m.dn(0.0)), 0);
        let m3 = DnMapping::detection(DetectionScale::Scale3, 14).unwrap();
        assert_eq!(m3.quantise(m3.dn(3e-17)), 1638);
        let m2 = DnMapping::detection(DetectionScale::Scale2, 12).unwrap();
        assert_eq!(m2.quantise(m2.dn(3e-17)), 2048);
        assert!(DnMapping::detection(DetectionScale::Custom(0.0), 14).is_err());
        assert!(DnMapping::detection(DetectionScale::Custom(f64::NAN), 14).is_err());
        assert!(DnMapping::detection(DetectionScale::Scale1, 0).is_err());
        assert!(DnMapping::detection(DetectionScale::Scale1, 17).is_err());
    }

    #[test]
    fn radiometry_range_maps_ends_to_0_and_full_scale() {
        let m = DnMapping::radiometry_auto(10.0, 500.0, 14).unwrap();
        assert_eq!(m.quantise(m.dn(10.0)), 0);
        assert_eq!(m.quantise(m.dn(500.0)), 16383);
        assert!(DnMapping::radiometry_auto(5.0, 5.0, 14).is_err());
        assert!(DnMapping::radiometry_auto(5.0, 1.0, 14).is_err());
        assert!(DnMapping::radiometry_auto(-1.0, 1.0, 14).is_err());
    }

    #[test]
    fn measured_range_maps_ends_below_zero_too() {
        // A measured low end below 0 (the camera's own offset): still DN 0 to full scale.
        let m = DnMapping::radiometry_auto_measured(-4.5, 12.0, 12).unwrap();
        assert_eq!(m.quantise(m.dn(-4.5)), 0);
        assert_eq!(m.quantise(m.dn(12.0)), 4095);
        assert_eq!(m.quantise(m.dn(3.75)), 2048);
        // Where both are allowed it is Eq. 17's map.
        let (a, b) = (
            DnMapping::radiometry_auto(10.0, 500.0, 14).unwrap(),
            DnMapping::radiometry_auto_measured(10.0, 500.0, 14).unwrap(),
        );
        assert_eq!(a, b);
        assert!(DnMapping::radiometry_auto_measured(1.0, 1.0, 14).is_err());
        assert!(DnMapping::radiometry_auto_measured(2.0, 1.0, 14).is_err());
        assert!(DnMapping::radiometry_auto_measured(f64::NAN, 1.0, 14).is_err());
        assert!(DnMapping::radiometry_auto_measured(0.0, f64::INFINITY, 14).is_err());
        assert!(DnMapping::radiometry_auto_measured(0.0, 1.0, 0).is_err());
    }

    #[test]
    fn eq8_inverts_sigma_t4() {
        let m =
            DnMapping::radiometry_auto(0.0, STEFAN_BOLTZMANN_W_M2_K4 * 500f64.powi(4), 16).unwrap();
        let dn = m.dn(STEFAN_BOLTZMANN_W_M2_K4 * 300f64.powi(4));
        assert!((m.t_rad_eq8_k(dn) - 300.0).abs() < 1e-9);
        assert_eq!(m.t_rad_eq8_k(-3.0), 0.0);
    }
}
