//! The camera's own signature, calibrated on a real frame: what a detector meets on
//! every frame of the Hayabusa2 TIR after its on-board shutter correction.
//!
//! - [`fit`]: the measurement (smooth shading, column and row patterns, the cell-scale
//!   field, hot and dead pixels, per-pixel residual) of one frame;
//! - [`Calibration`]: the fitted numbers of the real deep-space frame
//!   `dark_20180629_083003.fit` with the camera gain that turns them into radiance,
//!   committed as `host/assets/sensor/hayabusa2-tir-dark.toml` (written by
//!   `tirroi sensor-fit`) and built into the binary;
//! - [`SensorSignature`]: a new seeded realisation with the fitted statistics, as a
//!   scene-equivalent radiance offset map (W m⁻² sr⁻¹) and a per-pixel gain map, which
//!   the renderer adds to any readout.
//!
//! **Model** (DN of the real camera's L1 product, per pixel i at column x, row y):
//! `DN_i = α·(S(x − dx, y − dy) − S̄) + c_x + r_y + f_i + p_i + o_i`, with S the fitted
//! polynomial shading, α and (dx, dy) a modest per-realisation variation
//! ([`SHADING_AMPLITUDE_VARIATION`], [`SHADING_SHIFT_PX`]), c and r AR(1) processes with
//! the fitted σ and lag-1 correlation (their degree-4 polynomial part removed, as the
//! shading fit absorbs it), f a Gaussian-correlated field (below), p a white per-pixel
//! residual and o the hot/dead outliers
//! (a Poisson count with the fitted mean at random places, amplitudes drawn from the
//! fitted ones).
//!
//! **Field.** What the shading and line fits leave on the real frame is not white: its
//! autocorrelation holds 0.37 of its variance at lags 1–8 px and falls to 0 near 48 px
//! (`fit::FieldPattern`: σ 2.3 DN, ℓ 32 px as measured), so 8-px cell means scatter
//! by 2.2 DN where white pixels would give 0.4. f is white noise blurred by a Gaussian
//! of σ = ℓ_p/2 (autocorrelation exp(−(L/ℓ_p)²)), less what the fit would take out as
//! shading and lines ([`fit::remove_fitted_parts`]), scaled to the fitted σ. The fits
//! shorten a long field's apparent length, so ℓ_p is found by simulation when the
//! calibration is made ([`FieldProcess`]). f is put in the offset, not the gain: one
//! frame cannot tell which, and as an offset it is there over deep space, where a
//! detector must not take it for a target.
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
    /// The cell-scale field's generating process, found by simulation.
    pub field_process: FieldProcess,
}

/// The generating length of the signature's field (module docs, "Field"): the
/// correlation length ℓ_p of the Gaussian-correlated field whose realisations on the
/// fitted area, after the shading and line fits, show the measured length
/// `fit.field.correlation_length_px` (mean over [`FIELD_PROCESS_SEEDS`] fixed seeds,
/// bisection on ln ℓ_p).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldProcess {
    /// ℓ_p, px (0 without a field).
    pub length_px: f64,
}

/// Fixed seeds the field's generating length is matched over: two realisations halve
/// the scatter of one (about 5 % in the measured length) at twice the cost.
const FIELD_PROCESS_SEEDS: u64 = 2;

/// Bisection steps on ln ℓ_p over [0.5 px, the area's larger side]: 12 halvings of
/// 6.5 octaves leave 0.1 % (far below the 5 % scatter of the measurement itself).
const FIELD_PROCESS_STEPS: usize = 12;

/// Salt of the field's random stream (its own, so that a seed's other parts are those
/// of a signature without the field).
const FIELD_SEED_SALT: u64 = 0x6669_656c_6453_6967;

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

    /// Fixed per-pixel (white) residual σ, DN: the fitted σ less the field's and the
    /// temporal noise in quadrature (0 if the fit is below them).
    pub fn fixed_pixel_sigma_dn(&self) -> f64 {
        let s = self.fit.pixels.sigma_dn;
        let f = self.fit.field.sigma_dn;
        (s * s - f * f - TEMPORAL_NOISE_DN * TEMPORAL_NOISE_DN)
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
            field_process: FieldProcess {
                length_px: field_process_length(&fit).map_err(|e| format!("{file}: field: {e}"))?,
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
        let field = scaled_field(
            width,
            height,
            self.field_process.length_px,
            f.field.sigma_dn,
            seed ^ FIELD_SEED_SALT,
        );
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
                offset[i] = alpha * (s - mean) + col_x + row_y + field[i] + p;
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

/// A realisation of the field: white noise blurred by a Gaussian of σ = `length_px`/2,
/// less what the fit takes out as shading and lines, scaled to σ `sigma_dn` (all zero
/// for a length or σ of 0, or a shading fit that fails on a degenerate size).
fn scaled_field(width: usize, height: usize, length_px: f64, sigma_dn: f64, seed: u64) -> Vec<f64> {
    let n = width * height;
    if !(length_px > 0.0 && sigma_dn > 0.0) {
        return vec![0.0; n];
    }
    let mut v = processed_field(width, height, length_px, seed);
    let sd = (v.iter().map(|x| x * x).sum::<f64>() / n.max(1) as f64).sqrt();
    let k = if sd > 0.0 { sigma_dn / sd } else { 0.0 };
    v.iter_mut().for_each(|x| *x *= k);
    v
}

/// Unit white noise for `seed` blurred by a Gaussian of σ = `length_px`/2 and passed
/// through [`fit::remove_fitted_parts`] (zeros if that fails).
fn processed_field(width: usize, height: usize, length_px: f64, seed: u64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let white: Vec<f64> = (0..width * height)
        .map(|_| rng.sample(StandardNormal))
        .collect();
    let mut v = gaussian_blur(&white, width, height, 0.5 * length_px);
    if fit::remove_fitted_parts(&mut v, width, height).is_err() {
        v.iter_mut().for_each(|x| *x = 0.0);
    }
    v
}

/// Separable Gaussian blur of σ `sigma_px` (kernel to 3σ, mirrored at the edges).
fn gaussian_blur(v: &[f64], width: usize, height: usize, sigma_px: f64) -> Vec<f64> {
    let r = (3.0 * sigma_px).ceil().max(1.0) as usize;
    let kernel: Vec<f64> = (0..=2 * r)
        .map(|k| (-0.5 * ((k as f64 - r as f64) / sigma_px).powi(2)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let kernel: Vec<f64> = kernel.iter().map(|k| k / total).collect();
    // Index i − r of a line of n, mirrored at both ends (any distance).
    let mirror = |i: usize, n: usize| -> usize {
        let p = (i + 2 * n * (r / n + 1) - r) % (2 * n);
        if p >= n { 2 * n - 1 - p } else { p }
    };
    let mut rows = vec![0.0; v.len()];
    let mut padded = vec![0.0; width + 2 * r];
    for (line, out) in v.chunks_exact(width).zip(rows.chunks_exact_mut(width)) {
        for (i, p) in padded.iter_mut().enumerate() {
            *p = line[mirror(i, width)];
        }
        for (o, win) in out.iter_mut().zip(padded.windows(kernel.len())) {
            *o = win.iter().zip(&kernel).map(|(a, k)| a * k).sum();
        }
    }
    let mut out = vec![0.0; v.len()];
    for (y, dst) in out.chunks_exact_mut(width).enumerate() {
        for (k, &w) in kernel.iter().enumerate() {
            let src = mirror(y + k, height) * width;
            let line = &rows[src..src + width];
            dst.iter_mut().zip(line).for_each(|(o, &s)| *o += w * s);
        }
    }
    out
}

/// The field's generating length ℓ_p for a fit ([`FieldProcess`]): the ℓ_p whose
/// processed realisations on the fit's area show, on average over
/// [`FIELD_PROCESS_SEEDS`], the fitted correlation length. 0 without a field.
///
/// # Errors
/// A message when the area is too small for a field fit (under 16 px a side).
fn field_process_length(f: &FrameFit) -> Result<f64, String> {
    let target = f.field.correlation_length_px;
    if !(target > 0.0 && f.field.sigma_dn > 0.0) {
        return Ok(0.0);
    }
    let (w, h) = (f.width, f.height);
    if w < 16 || h < 16 {
        return Err(format!("{w} × {h} area: expected at least 16 × 16"));
    }
    let measured = |length_px: f64| {
        (0..FIELD_PROCESS_SEEDS)
            .map(|k| {
                let v = processed_field(w, h, length_px, FIELD_SEED_SALT ^ k);
                fit::fit_field(&v, w, h, f64::INFINITY).correlation_length_px
            })
            .sum::<f64>()
            / FIELD_PROCESS_SEEDS as f64
    };
    let (mut lo, mut hi) = (0.5f64.ln(), (w.max(h) as f64).ln());
    for _ in 0..FIELD_PROCESS_STEPS {
        let mid = 0.5 * (lo + hi);
        if measured(mid.exp()) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok((0.5 * (lo + hi)).exp())
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
