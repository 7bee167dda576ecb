//! The camera's own signature, calibrated on a real frame: what a detector meets on
//! every frame of the Hayabusa2 TIR after its on-board shutter correction.
//!
//! - [`fit`]: the measurement (smooth shading, column and row patterns, hot and dead
//!   pixels, per-pixel residual) of one frame;
//! - [`Calibration`]: the fitted numbers of the real deep-space frame
//!   `dark_20180629_083003.fit` with the camera gain that turns them into radiance,
//!   committed as `host/assets/sensor/hayabusa2-tir-dark.toml` (written by
//!   `tirroi sensor-fit`) and built into the binary;
//! - [`SensorSignature`]: a new seeded realisation with the fitted statistics, as a
//!   scene-equivalent radiance offset map (W m⁻² sr⁻¹) and a per-pixel gain map, which
//!   the renderer adds to any readout.
//!
//! **Model** (DN of the real camera's L1 product, per pixel i at column x, row y):
//! `DN_i = α·(S(x − dx, y − dy) − S̄) + c_x + r_y + p_i + o_i`, with S the fitted
//! polynomial shading, α and (dx, dy) a modest per-realisation variation
//! ([`SHADING_AMPLITUDE_VARIATION`], [`SHADING_SHIFT_PX`]), c and r AR(1) processes with
//! the fitted σ and lag-1 correlation (their degree-4 polynomial part removed, as the
//! shading fit absorbs it), p a white per-pixel residual and o the hot/dead outliers
//! (a Poisson count with the fitted mean at random places, amplitudes drawn from the
//! fitted ones).
//!
//! **Gain residual.** One shutter-differenced frame cannot separate a pixel's gain from
//! its offset: its value is g_i·(L_space − L_shutter). Writing g_i = g·(1 + δ_i), the
//! residual of pixel i about the smooth level S is δ_i·S, so the fixed per-pixel
//! residual p_i is read as a gain error δ_i = p_i / S̄ (S̄ the frame's mean, −373 DN);
//! the same δ_i then multiplies the scene's signal ([`SensorSignature::gain`]). The
//! per-frame noise (about 1 DN after the on-board sum of 32 frames, the reference
//! README) is taken out of p's σ in quadrature ([`TEMPORAL_NOISE_DN`]), since the
//! renderer adds its own noise.

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Poisson, StandardNormal};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::imaging::render::FixedGain;

pub mod fit;

use fit::{FrameFit, SHADING_DEGREE, norm_coord, row_coefficients};

/// The committed calibration of the Hayabusa2 TIR dark frame (`tirroi sensor-fit`).
pub const HAYABUSA2_TIR_DARK_TOML: &str =
    include_str!("../../../assets/sensor/hayabusa2-tir-dark.toml");

/// Per-frame (temporal) noise in the calibration frame, DN: about 1 DN after the
/// on-board sum of 32 frames (`shared/reference/hayabusa2-tir/README.md`); taken out of
/// the per-pixel residual in quadrature, since the renderer adds its own noise.
pub const TEMPORAL_NOISE_DN: f64 = 1.0;

/// Half-width of the uniform variation of the shading amplitude between realisations,
/// as a fraction (±5 %): the shading is the lens/shutter's own emission contrast, whose
/// band radiance changes by about 1.4 % per K near 300 K, so ±5 % is ±3.5 K of
/// instrument temperature, within the TIR's operating drift.
pub const SHADING_AMPLITUDE_VARIATION: f64 = 0.05;

/// Half-width of the uniform shift of the shading pattern between realisations, px
/// (±3 px, 0.9 % of the width): the lens-to-array alignment tolerance of a different
/// unit of the same design. Small enough that the amplitude stays the fitted one.
pub const SHADING_SHIFT_PX: f64 = 3.0;

/// 0 °C in K (the TIR's FITS headers give temperatures in °C).
pub const CELSIUS_TO_KELVIN: f64 = 273.15;

/// The effective (active) area of a TIR L1 frame, [x0, y0, width, height], px: columns
/// 16–343 and rows 6–253, 0-based (the reference README, HEAT's `image[y+6][x+16]`).
pub const TIR_EFFECTIVE_AREA_PX: [usize; 4] = [16, 6, 328, 248];

/// Pedestal of the fixed-gain radiometry readout, DN at 14 bits: the DN of F = 0 (deep
/// space). The signature spans −56…+150 DN about it on the calibration frame (smooth
/// shading −56…+90, hot pixels up to +272 DN, dead down to −17 DN about the local
/// level), so deep space's lowest pixel sits near 960 DN: 30 σ of the frame's spatial
/// σ (32 DN) and about 380 σ of the rendered noise (2.5 DN) above 0 DN, leaving
/// 15 359 DN (1 217 W m⁻² sr⁻¹, far above a 460 K scene's 190) of headroom.
pub const FIXED_GAIN_PEDESTAL_DN: f64 = 1024.0;

/// Standard error of a median over that of a mean for Gaussian data, √(π/2).
const MEDIAN_EFFICIENCY: f64 = 1.253_314_137_315_500_3;

/// The fitted signature of a real frame and the gain that makes it radiance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Where the numbers come from.
    pub source: Source,
    /// The camera gain used to turn DN into scene-equivalent radiance.
    pub gain: GainCalibration,
    /// The fitted numbers, DN of the source frame.
    pub fit: FrameFit,
}

/// Provenance of a calibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Source {
    /// The FITS file's name.
    pub file: String,
    /// The fitted area of the file, [x0, y0, width, height], px, 0-based.
    pub area_px: [usize; 4],
    /// Shutter temperature of the frame (FITS `SHT_TEMP`), K.
    pub shutter_temperature_k: f64,
    /// Lens temperature of the frame (FITS `LEN_TEMP`), K.
    pub lens_temperature_k: f64,
    /// Bolometer temperature of the frame (FITS `BOL_TEMP`), K.
    pub bolometer_temperature_k: f64,
}

/// The real camera's gain g, DN per W m⁻² sr⁻¹ of band radiance.
///
/// Derivation: the frame is space minus shutter, DN = g·(L_space + L_inst − L_shutter),
/// with L_space ≈ 0 (3 K) and L_inst ≥ 0 the lens and barrel emission the pixel sees
/// with the shutter open. Where L_inst is smallest (the most negative point of the
/// smooth shading) the frame is closest to −g·L_shutter, so
/// g ≈ −min(S)/L_band(T_shutter): a lower bound (any instrument emission left there
/// makes the true g larger).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GainCalibration {
    /// Band radiance of a blackbody at the shutter temperature (the core's TIR band
    /// model), W m⁻² sr⁻¹.
    pub shutter_radiance_w_m2_sr: f64,
    /// g = −min(S)/L_shutter, DN per W m⁻² sr⁻¹.
    pub dn_per_w_m2_sr: f64,
}

impl Calibration {
    /// The built-in Hayabusa2 TIR calibration ([`HAYABUSA2_TIR_DARK_TOML`]).
    ///
    /// # Errors
    /// A message when the built-in file does not parse (a broken build).
    pub fn hayabusa2_tir() -> Result<Self, String> {
        Self::from_toml(HAYABUSA2_TIR_DARK_TOML)
    }

    /// Parses a calibration written by [`Calibration::to_toml`].
    ///
    /// # Errors
    /// The TOML error (line and column) or a gain that is not finite and > 0.
    pub fn from_toml(text: &str) -> Result<Self, String> {
        let c: Calibration =
            toml::from_str(text).map_err(|e| format!("sensor calibration: {e}"))?;
        if !(c.gain.dn_per_w_m2_sr.is_finite() && c.gain.dn_per_w_m2_sr > 0.0) {
            return Err(format!(
                "sensor calibration: gain.dn_per_w_m2_sr = {}: expected a finite number > 0",
                c.gain.dn_per_w_m2_sr
            ));
        }
        Ok(c)
    }

    /// The calibration as TOML with a provenance comment.
    ///
    /// # Errors
    /// A serialisation error (not expected).
    pub fn to_toml(&self) -> Result<String, String> {
        let body = toml::to_string(self).map_err(|e| e.to_string())?;
        Ok(format!(
            "# The Hayabusa2 TIR's own signature, fitted on a real deep-space frame.\n\
             # Written by `tirroi sensor-fit --fits {} --out <this file>`: do not edit by hand.\n\
             # Data: JAXA Hayabusa2 TIR L1 dark frame (space minus shutter), as published in\n\
             # HEAT-Develop/HEAT olds/src/; see shared/reference/hayabusa2-tir/README.md.\n\
             # Units: DN of that frame; gain in DN per W m-2 sr-1 of 8-12 um band radiance.\n\
             # Model and derivations: docs/camera-model.md (\"The sensor's own signature\").\n\n{body}",
            self.source.file
        ))
    }

    /// The fixed-gain radiometry readout of this camera: DN = a·F + b with
    /// a = g/π (g = [`GainCalibration::dn_per_w_m2_sr`], the real camera's DN per band
    /// radiance, taken as the 14-bit DN) and b = [`FIXED_GAIN_PEDESTAL_DN`], both scaled
    /// by 2^(bits − 14) when a frame's map is made
    /// ([`tirroi_core::sensor::DnMapping::radiometry_fixed_gain`]).
    pub fn fixed_gain(&self) -> FixedGain {
        FixedGain {
            dn_per_w_m2_sr: self.gain.dn_per_w_m2_sr,
            pedestal_dn: FIXED_GAIN_PEDESTAL_DN,
        }
    }

    /// Fixed per-pixel residual σ, DN: the fitted σ less the temporal noise in
    /// quadrature (0 if the fit is below it).
    pub fn fixed_pixel_sigma_dn(&self) -> f64 {
        let s = self.fit.pixels.sigma_dn;
        (s * s - TEMPORAL_NOISE_DN * TEMPORAL_NOISE_DN)
            .max(0.0)
            .sqrt()
    }

    /// Fits a calibration on the `area_px` = [x0, y0, width, height] of a FITS frame
    /// (space minus shutter), with the gain from the shutter temperature `SHT_TEMP`
    /// (°C in the TIR's headers) and the core's TIR band radiance.
    ///
    /// # Errors
    /// A message for an area outside the image, a missing or non-numeric `SHT_TEMP`,
    /// a fit that fails, or a smooth shading that is not negative somewhere (no
    /// space-minus-shutter frame).
    pub fn from_fits(
        image: &crate::imaging::fits::FitsImage,
        file: &str,
        area_px: [usize; 4],
    ) -> Result<Self, String> {
        let [x0, y0, w, h] = area_px;
        if x0 + w > image.width || y0 + h > image.height {
            return Err(format!(
                "{file}: area {x0},{y0},{w},{h}: expected inside the {} × {} image",
                image.width, image.height
            ));
        }
        let area: Vec<f64> = (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .map(|(x, y)| image.at(x, y))
            .collect();
        let (fit, _) = fit::fit_frame(&area, w, h).map_err(|e| format!("{file}: {e}"))?;
        let celsius = |key: &str| {
            image
                .keyword_f64(key)
                .map(|c| c + CELSIUS_TO_KELVIN)
                .ok_or_else(|| {
                    format!("{file}: header keyword {key}: expected a temperature in °C")
                })
        };
        let t_sh = celsius("SHT_TEMP")?;
        let band = tirroi_core::sensor::BandRadiance::hayabusa2_tir();
        let l_sh = band
            .radiance_w_m2_sr(t_sh, 1.0)
            .map_err(|e| format!("{file}: SHT_TEMP: {e}"))?;
        if fit.shading.min_dn >= 0.0 {
            return Err(format!(
                "{file}: the smooth shading's minimum is {} DN: expected a space-minus-shutter frame (negative)",
                fit.shading.min_dn
            ));
        }
        Ok(Calibration {
            source: Source {
                file: file.to_string(),
                area_px,
                shutter_temperature_k: t_sh,
                lens_temperature_k: celsius("LEN_TEMP")?,
                bolometer_temperature_k: celsius("BOL_TEMP")?,
            },
            gain: GainCalibration {
                shutter_radiance_w_m2_sr: l_sh,
                dn_per_w_m2_sr: -fit.shading.min_dn / l_sh,
            },
            fit,
        })
    }

    /// A new realisation of the signature on a `width × height` frame for `seed`
    /// (same seed, same maps). The fitted statistics are per pixel and per line, so a
    /// frame of another size keeps them (hot pixels scale with the area).
    pub fn realise(&self, width: usize, height: usize, seed: u64) -> SensorSignature {
        let dn = self.realise_dn(width, height, seed);
        let g = self.gain.dn_per_w_m2_sr;
        let mean = self.fit.shading.mean_dn;
        SensorSignature {
            width,
            height,
            offset_w_m2_sr: dn.offset.iter().map(|&d| (d / g) as f32).collect(),
            gain: dn.pixel.iter().map(|&p| (1.0 + p / mean) as f32).collect(),
        }
    }

    /// A realisation in DN of the real camera, about the frame's mean (0 = the mean
    /// level of the calibration frame): the offset map and its per-pixel part alone.
    pub fn realise_dn(&self, width: usize, height: usize, seed: u64) -> SignatureDn {
        let f = &self.fit;
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x5167_4e41_7475_7265);
        let n = width * height;
        let alpha = 1.0 + rng.gen_range(-1.0..=1.0) * SHADING_AMPLITUDE_VARIATION;
        let dx = rng.gen_range(-1.0..=1.0) * SHADING_SHIFT_PX;
        let dy = rng.gen_range(-1.0..=1.0) * SHADING_SHIFT_PX;
        // A line's median over m pixels of residual σ carries 1.2533·σ/√m of pixel
        // noise, which the fitted line σ includes: the process gets the rest.
        let line_sigma = |p: &fit::LinePattern, m: usize| {
            let noise = MEDIAN_EFFICIENCY * f.pixels.sigma_dn / (m as f64).sqrt();
            (p.sigma_dn * p.sigma_dn - noise * noise).max(0.0).sqrt()
        };
        let col = line_process(
            &mut rng,
            width,
            line_sigma(&f.columns, f.height),
            f.columns.lag1_correlation,
        );
        let row = line_process(
            &mut rng,
            height,
            line_sigma(&f.rows, f.width),
            f.rows.lag1_correlation,
        );
        let sp = self.fixed_pixel_sigma_dn();
        let c = &f.shading.coefficients_dn;
        let mean = f.shading.mean_dn;
        let mut offset = vec![0.0f64; n];
        let mut pixel = vec![0.0f64; n];
        // Row-wise evaluation: the polynomial in x with y folded in per row.
        let xs: Vec<f64> = (0..width)
            .map(|x| norm_coord(x as f64 - dx, width))
            .collect();
        for (y, &row_y) in row.iter().enumerate() {
            let yn = norm_coord(y as f64 - dy, height);
            let rc = row_coefficients(c, yn);
            for (x, (&xn, &col_x)) in xs.iter().zip(&col).enumerate() {
                let s = rc.iter().rev().fold(0.0, |s, &k| s * xn + k);
                let p: f64 = sp * rng.sample::<f64, _>(StandardNormal);
                let i = y * width + x;
                pixel[i] = p;
                offset[i] = alpha * (s - mean) + col_x + row_y + p;
            }
        }
        // Outliers: a Poisson count per kind with the fitted mean scaled to the area.
        let area = n as f64 / (f.width * f.height) as f64;
        for amps in [&f.pixels.hot_amplitudes_dn, &f.pixels.dead_amplitudes_dn] {
            if amps.is_empty() {
                continue;
            }
            let mean_count = amps.len() as f64 * area;
            let count = Poisson::new(mean_count)
                .map(|p| p.sample(&mut rng) as usize)
                .unwrap_or(0);
            for _ in 0..count {
                let i = rng.gen_range(0..n);
                let a = amps[rng.gen_range(0..amps.len())];
                // The fitted amplitude is the pixel's whole residual: it replaces the
                // per-pixel part (and an outlier's gain is left at 1).
                offset[i] += a - pixel[i];
                pixel[i] = 0.0;
            }
        }
        SignatureDn {
            width,
            height,
            offset,
            pixel,
        }
    }
}

/// A realisation in DN of the calibration frame's camera.
#[derive(Debug, Clone, PartialEq)]
pub struct SignatureDn {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// The whole signature about the calibration frame's mean, DN, row-major.
    pub offset: Vec<f64>,
    /// Its per-pixel (gain residual) part, DN, row-major.
    pub pixel: Vec<f64>,
}

/// One realisation of the camera's signature, in units the renderer adds to any
/// readout.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorSignature {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// Scene-equivalent band radiance added to every pixel, W m⁻² sr⁻¹, row-major
    /// (zero-mean over the calibration frame: shading, column and row patterns,
    /// outliers, per-pixel residual).
    pub offset_w_m2_sr: Vec<f32>,
    /// Per-pixel gain 1 + δ_i multiplying the scene's signal (≈ 1 ± 1 %).
    pub gain: Vec<f32>,
}

impl SensorSignature {
    /// Applies the signature to a signal frame in place: s_i ← gain_i·s_i +
    /// `signal_per_radiance_sr`·offset_i, where `signal_per_radiance_sr` turns band
    /// radiance into the signal's unit (π for F, ΔA_c/r² for the detection flux q_fc).
    ///
    /// # Errors
    /// A message when the frame's size differs from the signature's.
    pub fn apply(&self, signal: &mut [f32], signal_per_radiance_sr: f64) -> Result<(), String> {
        if signal.len() != self.offset_w_m2_sr.len() {
            return Err(format!(
                "sensor signature: {} × {} px, frame of {} px: expected the same size",
                self.width,
                self.height,
                signal.len()
            ));
        }
        let k = signal_per_radiance_sr as f32;
        for ((s, &o), &g) in signal.iter_mut().zip(&self.offset_w_m2_sr).zip(&self.gain) {
            *s = g * *s + k * o;
        }
        Ok(())
    }
}

/// An AR(1) sequence with lag-1 correlation `lag1`, less its least-squares polynomial
/// of degree [`SHADING_DEGREE`] (the part the shading fit absorbs), scaled to `sigma_dn`.
fn line_process(rng: &mut Pcg64Mcg, n: usize, sigma_dn: f64, lag1: f64) -> Vec<f64> {
    let rho = lag1.clamp(-0.99, 0.99);
    let innov = (1.0 - rho * rho).sqrt();
    let mut v = Vec::with_capacity(n);
    let mut prev: f64 = rng.sample(StandardNormal);
    for _ in 0..n {
        v.push(prev);
        let z: f64 = rng.sample(StandardNormal);
        prev = rho * prev + innov * z;
    }
    remove_poly(&mut v);
    let m = v.iter().sum::<f64>() / n as f64;
    let sd = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n as f64).sqrt();
    let k = if sd > 0.0 { sigma_dn / sd } else { 0.0 };
    v.iter().map(|x| (x - m) * k).collect()
}

/// Removes the least-squares polynomial of degree [`SHADING_DEGREE`] in the normalised
/// coordinate (Gram–Schmidt on the sampled monomials).
fn remove_poly(v: &mut [f64]) {
    let n = v.len();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    for d in 0..=SHADING_DEGREE {
        let mut b: Vec<f64> = (0..n)
            .map(|i| norm_coord(i as f64, n).powi(d as i32))
            .collect();
        for q in &basis {
            let dot: f64 = b.iter().zip(q).map(|(a, c)| a * c).sum();
            b.iter_mut().zip(q).for_each(|(a, c)| *a -= dot * c);
        }
        let norm = b.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm > 1e-12 {
            b.iter_mut().for_each(|a| *a /= norm);
            basis.push(b);
        }
    }
    for q in &basis {
        let dot: f64 = v.iter().zip(q).map(|(a, c)| a * c).sum();
        v.iter_mut().zip(q).for_each(|(a, c)| *a -= dot * c);
    }
}

#[cfg(test)]
mod tests;
