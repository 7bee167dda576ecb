//! Compositing a rendered target over a real background and reading the frame out
//! through the renderer's readout stage.

use tirroi_core::sensor::{BandLut, BandRadiance};

use super::targets::TargetRender;
use crate::dataset::DatasetError;
use crate::imaging::render::{
    FixedGain, ReadOut, Readout, RenderInput, RenderStats, SensorEffects, read_out,
};
use crate::imaging::signature::SensorSignature;
use crate::world::constants::EARTH_DISTANCE_M;
use crate::world::scene::Camera;

/// The physical composite, F = F_target + (1 − c)·F_background per pixel: a pixel
/// fully on the target (c = 1) shows the target alone, one off it (c = 0) the
/// background alone, a partial pixel both by its coverage (the target's F is already
/// coverage-weighted, [`TargetRender::signal`]). Without a target, the background.
///
/// # Errors
/// A message when the sizes differ.
pub fn composite(
    target: Option<&TargetRender>,
    background_f: &[f32],
) -> Result<Vec<f32>, DatasetError> {
    let Some(t) = target else {
        return Ok(background_f.to_vec());
    };
    if t.signal.len() != background_f.len() || t.coverage.len() != background_f.len() {
        return Err(DatasetError(format!(
            "composite: target of {} px over a background of {} px: expected the same size",
            t.signal.len(),
            background_f.len()
        )));
    }
    Ok(t.signal
        .iter()
        .zip(&t.coverage)
        .zip(background_f)
        .map(|((&s, &c), &b)| s + (1.0 - c.clamp(0.0, 1.0)) * b)
        .collect())
}

/// (min, max) of the composite's pure pixels (coverage 0 or 1), which bound the auto
/// range of Eq. 17 as in the renderer; `None` when there are none.
pub fn pure_bounds(signal: &[f32], target: Option<&TargetRender>) -> Option<(f64, f64)> {
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    for (i, &s) in signal.iter().enumerate() {
        let c = target.map_or(0.0, |t| t.coverage[i]);
        if c <= 0.0 || c >= 1.0 {
            lo = lo.min(s);
            hi = hi.max(s);
        }
    }
    (lo <= hi).then_some((f64::from(lo), f64::from(hi)))
}

/// How a composite is read out.
#[derive(Debug, Clone, Copy)]
pub struct ReadoutChoice<'a> {
    /// Camera (size, bits, NETD).
    pub camera: &'a Camera,
    /// Fixed gain (`None`: the auto range of Eq. 17).
    pub fixed_gain: Option<FixedGain>,
    /// Factor on the map's gain.
    pub gain_factor: f64,
    /// Noise seed (`None`: no noise).
    pub noise_seed: Option<u64>,
    /// A signature added to the signal (the real dark frame as radiance).
    pub signature: Option<&'a SensorSignature>,
}

/// Reads `signal` (F, W m⁻²) out as the renderer does in radiometry mode
/// ([`read_out`]).
///
/// # Errors
/// [`DatasetError`] with the renderer's message.
pub fn read(
    signal: Vec<f32>,
    pure: Option<(f64, f64)>,
    choice: &ReadoutChoice<'_>,
    band: &BandRadiance,
    lut: &BandLut,
) -> Result<ReadOut, DatasetError> {
    let input = RenderInput {
        camera: choice.camera,
        readout: Readout::Radiometry,
        target: None,
        earth: None,
        earth_distance_m: EARTH_DISTANCE_M,
        noise_seed: choice.noise_seed,
        band,
        lut,
        gain_factor: choice.gain_factor,
        moon: None,
        sensor: SensorEffects {
            psf: None,
            signature: choice.signature,
            fixed_gain: choice.fixed_gain,
        },
    };
    let mut stats = RenderStats::default();
    read_out(&input, signal, pure, &mut stats).map_err(|e| DatasetError(format!("readout: {e}")))
}
