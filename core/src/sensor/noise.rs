//! Microbolometer noise (paper Section 3.3): Johnson (Eq. 11), 1/f (Eqs. 12–13) and
//! temperature-fluctuation noise (Eq. 14) from the Table 1 parameters, the noise voltage
//! density of Eq. 15, the conversion to ADU (Eq. 16), three noise levels, and a seeded
//! noise field generated row by row.
//!
//! # Table 2, and what the code uses
//!
//! | source | equation as printed | reading that reproduces Table 2 | Table 2 |
//! |---|---|---|---|
//! | Johnson | Eq. 11, Δf_J = 1/(2τ): 1.175e-7 V | none found; Δf_J = 1/(2t_int) gives 5.255e-6 (−2.6 %) | 5.394e-6 |
//! | 1/f | Eq. 13, f_H = 1/(2t_int), f_L = 1 Hz: 5.322e-6 V | the same | 5.322e-6 |
//! | thermal | Eq. 14 as printed: 2.747e-8 V | √(k_B T_B² v_b β²/(4 G_th t_int)) = 2.617e-6 (dimensionally inconsistent; equals 10 × the standard v_b β √(4k_B T_B² Δf_th/G_th) = 2.617e-7) | 2.617e-6 |
//!
//! [`RmsReading`] selects the set: `Table2` (the default) uses the published values, as
//! the paper's noise maps did; `AsPrinted` and `Physical` compute them. The searches
//! behind the table are in `shared/reference/REFERENCE.md` §1; core/tests/sensor_noise.rs
//! asserts every number above to four significant digits.
//!
//! # Noise levels, and why `netd` is the default
//!
//! Eq. 16 turns Table 2 into σ = 2470 ADU/V × 8.017e-6 V = 0.0198 ADU, a fiftieth of one
//! DN step: quantisation erases it, yet the paper's Fig. 5 shows visible grain and the
//! real TIR has a NETD of 0.4 K. [`NoiseLevel`] offers:
//!
//! - `PaperLiteral`: σ_src = G_A/D · v_src in DN, as Eq. 16 reads (invisible).
//! - `PaperVisible`: σ_src = G_A/D · v_src · (2ⁿ − 1): the Eq. 16 noise map taken as a
//!   fraction of full scale, i.e. added to the render while its intensities were
//!   normalised to [0, 1] and then scaled to n bits, which is what the paper's normalised
//!   Blender renders imply. 0.0198 of full scale = 324 DN at 14 bits.
//! - `Netd`: the same three maps scaled together so that the total σ equals NETD × ∂DN/∂T
//!   at a reference scene temperature ([`crate::sensor::DnMapping::dn_per_kelvin`]).
//!
//! `Netd` (0.4 K, Okada et al. 2017) is the default because it is the only level tied to
//! a measured property of the instrument, and the only one that scales correctly with
//! the DN map: the noise of a real bolometer is fixed in kelvin, not in ADU (literal) or
//! in fractions of whatever full scale a render picked (visible).
//!
//! # The noise field
//!
//! Johnson and thermal noise are white Gaussian; their sum is drawn as one white
//! Gaussian of σ = √(σ_J² + σ_th²) (identical in distribution, half the draws). The 1/f
//! map is white Gaussian noise low-pass filtered by a separable first-order recursive
//! filter, x then y, with correlation coefficient α = e^(−1/ℓ) per pixel (ℓ the
//! correlation length) and innovations scaled by √(1 − α²), started in its stationary
//! state, so its per-pixel σ is exactly σ_1/f from the first pixel on and its spectrum
//! falls as 1/(1 + α² − 2α cos ω) along each axis. It needs one f32 of state per column
//! (1 312 bytes), never a full-frame buffer.
//!
//! Every Gaussian draw (two per pixel, one per row) comes from the ziggurat of
//! [`super::gaussian`] (Marsaglia & Tsang 2000; 128 strips, 2 052 bytes of `const`
//! tables, 97 % of draws by one table compare and one multiply, exact up to 24-bit
//! resolution) on the xoshiro128++ stream of [`super::rng`]: no libm on the common path,
//! the same values on the host and on the flight target for a seed.

use super::dn::DnMapping;
use super::gaussian::standard_normal;
use super::rng::Xoshiro128pp;
use super::{SensorError, check_positive, check_range};
use crate::capacity::{ConstInit, FrameCapacity, Reference};

/// Boltzmann constant k_B, J K⁻¹ (SI 2019 exact).
pub const BOLTZMANN_J_K: f64 = 1.380_649e-23;
/// A/D gain G_A/D of Eq. 16, ADU per volt (paper ref. \[46\]).
pub const ADC_GAIN_ADU_PER_V: f64 = 2470.0;
/// NETD of the Hayabusa2 TIR, K: ≤ 0.4 K per pixel in the calibrated range (Okada et
/// al. 2017, Space Sci. Rev. 208:255).
pub const TIR_NETD_K: f64 = 0.4;
/// Default correlation length of the 1/f map, pixels (the paper's ref. \[11\] filter is
/// not specified; 4 px gives the blotchy texture of Fig. 5's flicker panel).
pub const DEFAULT_FLICKER_CORRELATION_PX: f32 = 4.0;

/// The microbolometer parameters of paper Table 1 (refs. \[41, 42\]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BolometerParams {
    /// Bolometer temperature T_B, K: 300.
    pub t_bolometer_k: f64,
    /// Bolometer resistance R_B, Ω: 20 kΩ.
    pub r_bolometer_ohm: f64,
    /// Detector heat conductance G_th, W K⁻¹: 20 µW/K.
    pub g_th_w_k: f64,
    /// Thermal coefficient of resistance β, K⁻¹: 0.023.
    pub beta_per_k: f64,
    /// Time constant τ, s: 12 ms.
    pub tau_s: f64,
    /// Integration time t_int, s: 6 µs.
    pub t_int_s: f64,
    /// Bias voltage v_bias, V: 5.
    pub v_bias_v: f64,
    /// Lower frequency at frame rate f_L, Hz: 1.
    pub f_low_hz: f64,
    /// Material (Hooge) constant 𝒩, dimensionless: 1e-13.
    pub hooge_n: f64,
}

impl BolometerParams {
    /// Paper Table 1.
    pub const TABLE1: BolometerParams = BolometerParams {
        t_bolometer_k: 300.0,
        r_bolometer_ohm: 20e3,
        g_th_w_k: 20e-6,
        beta_per_k: 0.023,
        tau_s: 12e-3,
        t_int_s: 6e-6,
        v_bias_v: 5.0,
        f_low_hz: 1.0,
        hooge_n: 1e-13,
    };

    /// Checks that every parameter is finite and > 0, and f_H = 1/(2t_int) > f_L.
    ///
    /// # Errors
    /// [`SensorError`] naming the first bad field.
    pub fn validate(&self) -> Result<(), SensorError> {
        check_positive("t_bolometer_k", self.t_bolometer_k)?;
        check_positive("r_bolometer_ohm", self.r_bolometer_ohm)?;
        check_positive("g_th_w_k", self.g_th_w_k)?;
        check_positive("beta_per_k", self.beta_per_k)?;
        check_positive("tau_s", self.tau_s)?;
        check_positive("t_int_s", self.t_int_s)?;
        check_positive("v_bias_v", self.v_bias_v)?;
        check_positive("f_low_hz", self.f_low_hz)?;
        check_positive("hooge_n", self.hooge_n)?;
        check_range(
            "f_low_hz",
            self.f_low_hz,
            0.0,
            self.high_frequency_hz(),
            "f_low_hz < 1/(2 t_int_s)",
        )?;
        Ok(())
    }

    /// High-frequency bound f_H = 1/(2t_int), Hz (83 333 Hz for Table 1).
    pub fn high_frequency_hz(&self) -> f64 {
        1.0 / (2.0 * self.t_int_s)
    }

    /// Johnson RMS voltage √(4 k_B T_B R_B Δf) over `bandwidth_hz` (Eq. 11), V.
    pub fn johnson_rms_v(&self, bandwidth_hz: f64) -> f64 {
        libm::sqrt(4.0 * BOLTZMANN_J_K * self.t_bolometer_k * self.r_bolometer_ohm * bandwidth_hz)
    }

    /// Flicker RMS voltage v_bias·√(𝒩 ln(f_H/f_L)) (Eq. 13), V.
    pub fn flicker_rms_v(&self) -> f64 {
        self.v_bias_v
            * libm::sqrt(self.hooge_n * libm::log(self.high_frequency_hz() / self.f_low_hz))
    }

    /// Temperature-fluctuation bandwidth Δf_th = 1/(4τ), Hz.
    pub fn thermal_bandwidth_hz(&self) -> f64 {
        1.0 / (4.0 * self.tau_s)
    }

    /// Eq. 14 exactly as printed: √(4 k_B T_B²/G_th) · v_bias · β² · Δf_th, V (not a
    /// voltage dimensionally; 2.747e-8 for Table 1).
    pub fn thermal_rms_as_printed_v(&self) -> f64 {
        libm::sqrt(4.0 * BOLTZMANN_J_K * self.t_bolometer_k * self.t_bolometer_k / self.g_th_w_k)
            * self.v_bias_v
            * self.beta_per_k
            * self.beta_per_k
            * self.thermal_bandwidth_hz()
    }

    /// Temperature-fluctuation RMS voltage in its standard form
    /// v_bias·β·√(4 k_B T_B² Δf_th/G_th), V (2.617e-7 for Table 1).
    pub fn thermal_rms_v(&self) -> f64 {
        self.v_bias_v
            * self.beta_per_k
            * libm::sqrt(
                4.0 * BOLTZMANN_J_K
                    * self.t_bolometer_k
                    * self.t_bolometer_k
                    * self.thermal_bandwidth_hz()
                    / self.g_th_w_k,
            )
    }

    /// The three RMS voltages under `reading`.
    pub fn rms(&self, reading: RmsReading) -> NoiseRms {
        match reading {
            RmsReading::Table2 => NoiseRms::TABLE2,
            RmsReading::AsPrinted => NoiseRms {
                johnson_v: self.johnson_rms_v(1.0 / (2.0 * self.tau_s)),
                flicker_v: self.flicker_rms_v(),
                thermal_v: self.thermal_rms_as_printed_v(),
            },
            RmsReading::Physical => NoiseRms {
                johnson_v: self.johnson_rms_v(self.high_frequency_hz()),
                flicker_v: self.flicker_rms_v(),
                thermal_v: self.thermal_rms_v(),
            },
        }
    }

    /// Noise voltage density of Eq. 15 over a measurement bandwidth Δf starting at f_L,
    /// V Hz^-½: √(v_J² + v_1/f² + v_th²)/√Δf with
    /// v_J² = 4k_B T_B R_B Δf, v_1/f² = v_bias² 𝒩 ln(1 + Δf/f_L) (Eq. 12 integrated) and
    /// v_th² = (v_bias β)² (4k_B T_B²/G_th) ∫ df/(1 + (2πfτ)²), whose integral to ∞ is
    /// 1/(4τ) = Δf_th of Eq. 14. These are the data of Fig. 4: the flicker term falls
    /// with Δf and the density settles at the Johnson floor √(4k_B T_B R_B) = 1.8e-8 V
    /// Hz^-½ ("in the order of 10⁻⁸"). The paper's Eq. 15 divides by Δf, not √Δf; its
    /// Fig. 4 axis (V Hz^-0.5) and level fit the square root, which is used here.
    /// Returns 0 for a bandwidth that is not finite and > 0.
    pub fn nvd_v_per_sqrt_hz(&self, bandwidth_hz: f64) -> f64 {
        if !(bandwidth_hz > 0.0 && bandwidth_hz.is_finite()) {
            return 0.0;
        }
        let kb = BOLTZMANN_J_K;
        let johnson2 = 4.0 * kb * self.t_bolometer_k * self.r_bolometer_ohm * bandwidth_hz;
        let flicker2 = self.v_bias_v
            * self.v_bias_v
            * self.hooge_n
            * libm::log1p(bandwidth_hz / self.f_low_hz);
        let w = core::f64::consts::TAU * self.tau_s;
        let vb_beta = self.v_bias_v * self.beta_per_k;
        let thermal_density2 =
            vb_beta * vb_beta * 4.0 * kb * self.t_bolometer_k * self.t_bolometer_k / self.g_th_w_k;
        let thermal2 = thermal_density2 / w
            * (libm::atan(w * (self.f_low_hz + bandwidth_hz)) - libm::atan(w * self.f_low_hz));
        libm::sqrt((johnson2 + flicker2 + thermal2) / bandwidth_hz)
    }
}

impl Default for BolometerParams {
    fn default() -> Self {
        Self::TABLE1
    }
}

/// Which set of RMS voltages feeds the noise maps (see the module docs' table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RmsReading {
    /// The published Table 2 values (5.394e-6, 5.322e-6, 2.617e-6 V): what the paper's
    /// noise maps used. The default.
    #[default]
    Table2,
    /// Eqs. 11, 13, 14 exactly as printed (Δf_J = 1/(2τ)): 1.175e-7, 5.322e-6, 2.747e-8 V.
    AsPrinted,
    /// Physically consistent: Δf_J = f_H = 1/(2t_int), the standard thermal formula:
    /// 5.255e-6, 5.322e-6, 2.617e-7 V.
    Physical,
}

/// RMS voltages of the three noise sources, V.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseRms {
    /// Johnson noise v_J, V.
    pub johnson_v: f64,
    /// 1/f (flicker) noise v_1/f, V.
    pub flicker_v: f64,
    /// Temperature-fluctuation noise v_th, V.
    pub thermal_v: f64,
}

impl NoiseRms {
    /// Paper Table 2.
    pub const TABLE2: NoiseRms = NoiseRms {
        johnson_v: 5.394e-6,
        flicker_v: 5.322e-6,
        thermal_v: 2.617e-6,
    };

    /// RMS of the sum of the three independent sources, √(v_J² + v_1/f² + v_th²), V.
    pub fn total_v(&self) -> f64 {
        libm::sqrt(
            self.johnson_v * self.johnson_v
                + self.flicker_v * self.flicker_v
                + self.thermal_v * self.thermal_v,
        )
    }
}

/// How loud the noise added to a frame is (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoiseLevel {
    /// Eq. 16 as written: σ = G_A/D · v, in DN (about 0.02 DN: invisible).
    PaperLiteral,
    /// Eq. 16's map as a fraction of full scale: σ = G_A/D · v · (2ⁿ − 1) DN.
    PaperVisible,
    /// Total σ = `netd_k` × `dn_per_k` DN, shared among the sources as their RMS
    /// voltages are.
    Netd {
        /// Noise-equivalent temperature difference, K (default 0.4).
        netd_k: f64,
        /// ∂DN/∂T of the frame's DN map at the reference scene temperature, DN K⁻¹
        /// ([`DnMapping::dn_per_kelvin`]).
        dn_per_k: f64,
    },
}

impl NoiseLevel {
    /// The σ of each source in DN for this level, `rms` voltages and the bit depth of
    /// `mapping`.
    ///
    /// # Errors
    /// [`SensorError`] for a NETD or ∂DN/∂T that is not finite and ≥ 0, or RMS voltages
    /// that are not finite and ≥ 0.
    pub fn sigmas(&self, rms: &NoiseRms, mapping: &DnMapping) -> Result<NoiseSigmas, SensorError> {
        for (name, v) in [
            ("johnson_v", rms.johnson_v),
            ("flicker_v", rms.flicker_v),
            ("thermal_v", rms.thermal_v),
        ] {
            check_range(name, v, 0.0, 1e3, "a finite RMS voltage >= 0")?;
        }
        let scale = match *self {
            NoiseLevel::PaperLiteral => ADC_GAIN_ADU_PER_V,
            NoiseLevel::PaperVisible => ADC_GAIN_ADU_PER_V * f64::from(mapping.max_dn()),
            NoiseLevel::Netd { netd_k, dn_per_k } => {
                check_range("netd_k", netd_k, 0.0, 1e3, "0 <= netd_k <= 1000 K")?;
                check_range("dn_per_k", dn_per_k, 0.0, 1e9, "0 <= dn_per_k <= 1e9 DN/K")?;
                let total = rms.total_v();
                if total > 0.0 {
                    netd_k * dn_per_k / total
                } else {
                    0.0
                }
            }
        };
        Ok(NoiseSigmas {
            johnson_dn: (rms.johnson_v * scale) as f32,
            flicker_dn: (rms.flicker_v * scale) as f32,
            thermal_dn: (rms.thermal_v * scale) as f32,
        })
    }
}

/// Standard deviation of each noise source in DN, as added to a frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NoiseSigmas {
    /// Johnson noise σ, DN.
    pub johnson_dn: f32,
    /// 1/f noise σ, DN.
    pub flicker_dn: f32,
    /// Temperature-fluctuation noise σ, DN.
    pub thermal_dn: f32,
}

impl NoiseSigmas {
    /// σ of the white part, √(σ_J² + σ_th²), DN.
    pub fn white_dn(&self) -> f32 {
        libm::sqrtf(self.johnson_dn * self.johnson_dn + self.thermal_dn * self.thermal_dn)
    }

    /// σ of the total noise, √(σ_J² + σ_1/f² + σ_th²), DN.
    pub fn total_dn(&self) -> f32 {
        libm::sqrtf(
            self.johnson_dn * self.johnson_dn
                + self.flicker_dn * self.flicker_dn
                + self.thermal_dn * self.thermal_dn,
        )
    }
}

/// A seeded noise map in DN, produced one row at a time (module docs), for rows up to
/// capacity `C`'s width (default the reference 328: 1 360 bytes).
#[derive(Debug, Clone)]
pub struct NoiseField<C: FrameCapacity = Reference> {
    rng: Xoshiro128pp,
    white_dn: f32,
    flicker_dn: f32,
    /// α = e^(−1/ℓ) of the 1/f filter.
    alpha: f32,
    /// √(1 − α²): keeps the filtered map at unit variance.
    innovation: f32,
    width: usize,
    rows: usize,
    /// The 1/f map's previous row (the vertical filter's state), unit variance.
    column: C::Row<f32>,
}

impl NoiseField {
    /// A field of `width` columns (1..=328, the reference capacity) with the given σ
    /// per source, 1/f correlation length `flicker_correlation_px` (≥ 0; 0 makes the
    /// 1/f map white), and `seed`.
    ///
    /// # Errors
    /// [`SensorError`] for a width outside 1..=328, or σ or ℓ not finite and ≥ 0.
    pub fn new(
        sigmas: NoiseSigmas,
        flicker_correlation_px: f32,
        width: usize,
        seed: u64,
    ) -> Result<Self, SensorError> {
        Self::for_capacity(sigmas, flicker_correlation_px, width, seed)
    }
}

impl<C: FrameCapacity> NoiseField<C> {
    /// As [`NoiseField::new`], for rows up to capacity `C`'s width (the same noise: the
    /// capacity only sizes the filter's row of state).
    ///
    /// # Errors
    /// [`SensorError`] for a width outside 1..=`C::WIDTH`, or σ or ℓ not finite and ≥ 0.
    pub fn for_capacity(
        sigmas: NoiseSigmas,
        flicker_correlation_px: f32,
        width: usize,
        seed: u64,
    ) -> Result<Self, SensorError> {
        if width == 0 || width > C::WIDTH {
            return Err(SensorError::BadSize {
                name: "width",
                actual: width,
                expected: C::WIDTH,
            });
        }
        for (name, v) in [
            ("johnson_dn", sigmas.johnson_dn),
            ("flicker_dn", sigmas.flicker_dn),
            ("thermal_dn", sigmas.thermal_dn),
            ("flicker_correlation_px", flicker_correlation_px),
        ] {
            check_range(name, f64::from(v), 0.0, 1e9, "a finite value >= 0")?;
        }
        let alpha = if flicker_correlation_px > 0.0 {
            libm::expf(-1.0 / flicker_correlation_px)
        } else {
            0.0
        };
        Ok(NoiseField {
            rng: Xoshiro128pp::seed_from_u64(seed),
            white_dn: sigmas.white_dn(),
            flicker_dn: sigmas.flicker_dn,
            alpha,
            innovation: libm::sqrtf(1.0 - alpha * alpha),
            width,
            rows: 0,
            column: ConstInit::INIT,
        })
    }

    /// True when every σ is 0: the frame pass then skips the noise stage.
    pub fn is_silent(&self) -> bool {
        self.white_dn == 0.0 && self.flicker_dn == 0.0
    }

    /// Columns per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// The next row of noise, `width` values in DN, left to right. Consume each row to
    /// its end before asking for the next (the 1/f filter's state advances per pixel).
    pub fn next_row(&mut self) -> NoiseRow<'_, C> {
        let first = self.rows == 0;
        self.rows += 1;
        // Stationary start of the horizontal filter: h₋₁ ~ N(0, 1).
        let h = standard_normal(&mut self.rng);
        NoiseRow {
            field: self,
            x: 0,
            h,
            first,
        }
    }
}

impl<C: FrameCapacity> NoiseField<C> {
    /// Combines the next row of noise with a row of `signal` into `out`, left to
    /// right: `out[x] = combine(signal[x], noise[x])`, the noise in DN being the same
    /// values, draws and filter state as [`NoiseField::next_row`] consumed to its end,
    /// bit for bit. The row is drawn in full (`width` values) even when `signal` or
    /// `out` is shorter, so the stream stays aligned; values past the shorter of the
    /// two are dropped. The flight path's fast loop: the generator's 16 bytes of state
    /// in registers, the first-row test once per row, the filter's state row, the
    /// signal and the output walked together by one zip (no per-pixel index check).
    #[inline]
    pub fn combine_row<T>(
        &mut self,
        signal: &[f32],
        out: &mut [T],
        mut combine: impl FnMut(f32, f32) -> T,
    ) {
        let first = self.rows == 0;
        self.rows += 1;
        let (alpha, innovation) = (self.alpha, self.innovation);
        let (white_dn, flicker_dn) = (self.white_dn, self.flicker_dn);
        let mut rng = self.rng.clone();
        // Stationary start of the horizontal filter: h₋₁ ~ N(0, 1).
        let mut h = standard_normal(&mut rng);
        // The filter's state: `width` columns, those with a signal and an output, then
        // the rest (checked-once splits: no panic path).
        let column = self.column.as_mut();
        let (column, _) = column.split_at_mut_checked(self.width).unwrap_or_default();
        let paired = signal.len().min(out.len());
        let (head, rest) = match column.split_at_mut_checked(paired) {
            Some(split) => split,
            None => (column, &mut [][..]),
        };
        let pixels = head.iter_mut().zip(signal).zip(out.iter_mut());
        if first {
            for ((c, &s), o) in pixels {
                let white = standard_normal(&mut rng);
                let g = standard_normal(&mut rng);
                h = alpha * h + innovation * g;
                *c = h;
                *o = combine(s, white_dn * white + flicker_dn * h);
            }
            for c in rest {
                let _white = standard_normal(&mut rng);
                let g = standard_normal(&mut rng);
                h = alpha * h + innovation * g;
                *c = h;
            }
        } else {
            for ((c, &s), o) in pixels {
                let white = standard_normal(&mut rng);
                let g = standard_normal(&mut rng);
                // x filter, then y filter; unit variance throughout.
                h = alpha * h + innovation * g;
                let z = alpha * *c + innovation * h;
                *c = z;
                *o = combine(s, white_dn * white + flicker_dn * z);
            }
            for c in rest {
                let _white = standard_normal(&mut rng);
                let g = standard_normal(&mut rng);
                h = alpha * h + innovation * g;
                *c = alpha * *c + innovation * h;
            }
        }
        self.rng = rng;
    }
}

/// One row of a [`NoiseField`]: an iterator of `width` noise values in DN.
#[derive(Debug)]
pub struct NoiseRow<'a, C: FrameCapacity = Reference> {
    field: &'a mut NoiseField<C>,
    x: usize,
    h: f32,
    first: bool,
}

impl<C: FrameCapacity> Iterator for NoiseRow<'_, C> {
    type Item = f32;

    fn next(&mut self) -> Option<f32> {
        let f = &mut *self.field;
        let x = self.x;
        if x >= f.width {
            return None;
        }
        self.x += 1;
        let white = standard_normal(&mut f.rng);
        let g = standard_normal(&mut f.rng);
        // x filter, then y filter; unit variance throughout.
        self.h = f.alpha * self.h + f.innovation * g;
        let z = if self.first {
            self.h
        } else {
            f.alpha * f.column.as_ref()[x] + f.innovation * self.h
        };
        f.column.as_mut()[x] = z;
        Some(f.white_dn * white + f.flicker_dn * z)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.field.width - self.x;
        (n, Some(n))
    }
}

impl<C: FrameCapacity> ExactSizeIterator for NoiseRow<'_, C> {}
