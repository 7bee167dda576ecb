//! Compositing a rendered target over a real background and reading the frame out
//! through the renderer's readout stage.

use tirroi_core::sensor::{BandLut, BandRadiance};

use super::targets::TargetRender;
use crate::dataset::DatasetError;
use crate::imaging::render::{
    FixedGain, PurePixels, ReadOut, Readout, RenderInput, RenderStats, SensorEffects, read_out,
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

/// The composite's pure pixels (coverage 0 or 1), which bound the auto range of
/// Eq. 17 as in the renderer.
pub fn pure_pixels(signal: &[f32], target: Option<&TargetRender>) -> PurePixels {
    let mut pure = PurePixels::default();
    for (i, &s) in signal.iter().enumerate() {
        let c = target.map_or(0.0, |t| t.coverage.get(i).copied().unwrap_or(0.0));
        if c <= 0.0 || c >= 1.0 {
            pure.add(i, s);
        }
    }
    pure
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
    pure: &PurePixels,
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

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use tirroi_core::roi::Roi;

    use super::*;

    /// A camera ranges on what it measures: a cold target over deep space read out with
    /// Eq. 17's auto range and a signature whose offset is negative under the target
    /// (the real frame's dark centre) keeps the target's faces apart inside the DN
    /// range. Ranged on the scene alone (the renderer before session 31: F 0–1.6 W m⁻²)
    /// the offset put every target pixel below the range's low end, at DN 0.
    #[test]
    fn auto_range_is_taken_over_the_measured_signal_of_the_pure_pixels() {
        let camera = Camera {
            width: 8,
            height: 4,
            ..Camera::default()
        };
        let band = BandRadiance::new(&camera.response.to_core()).expect("band");
        let lut = BandLut::new(&band);
        let n = camera.width * camera.height;
        let on_target = |i: usize| (2..6).contains(&(i % 8));
        // The target: columns 2..6 of every row, faces of F 1.0, 1.2, 1.4, 1.6 W m⁻²;
        // deep space elsewhere (F 0).
        let coverage: Vec<f32> = (0..n).map(|i| f32::from(u8::from(on_target(i)))).collect();
        let face_f = |i: usize| 1.0 + 0.2 * (i % 8 - 2) as f32;
        let signal: Vec<f32> = (0..n)
            .map(|i| if on_target(i) { face_f(i) } else { 0.0 })
            .collect();
        let target = TargetRender {
            signal,
            coverage,
            truth: Roi {
                x0: 2,
                y0: 0,
                x1: 6,
                y1: 4,
            },
            truth_quarter: Roi {
                x0: 2,
                y0: 0,
                x1: 6,
                y1: 4,
            },
            target: "test".into(),
            material: None,
            illumination: "eclipse".into(),
            range_m: 10.0,
            mask_px: 16,
        };
        let f = composite(Some(&target), &vec![0.0; n]).expect("composite");
        let pure = pure_pixels(&f, Some(&target));
        assert_eq!(pure.bounds(), Some((0.0, f64::from(1.6f32))));
        // An offset of −2 W m⁻² sr⁻¹ (−2π in F) under the target, +1 (π) elsewhere.
        let signature = SensorSignature {
            width: 8,
            height: 4,
            offset_w_m2_sr: (0..n)
                .map(|i| if on_target(i) { -2.0 } else { 1.0 })
                .collect(),
            gain: vec![1.0; n],
        };
        let choice = ReadoutChoice {
            camera: &camera,
            fixed_gain: None,
            gain_factor: 1.0,
            noise_seed: None,
            signature: Some(&signature),
        };
        let out = read(f, &pure, &choice, &band, &lut).expect("read");
        let max_dn = f64::from(out.mapping.max_dn());
        // Measured: the faces 1.0–1.6 − 2π (below 0), deep space π: Eq. 17 over the
        // measured pure pixels maps the coldest face to 0 and deep space to full scale,
        // each face exactly in between.
        let (lo, hi) = (f64::from(1.0f32) - 2.0 * PI, PI);
        for (i, &dn) in out.dn.iter().enumerate() {
            let measured = if on_target(i) {
                f64::from(face_f(i)) - 2.0 * PI
            } else {
                PI
            };
            let want = (measured - lo) / (hi - lo) * max_dn;
            assert!(
                (f64::from(dn) - want).abs() <= 0.51,
                "pixel {i}: {dn} DN vs {want:.2}"
            );
        }
        let row = &out.dn[..8];
        assert!(
            row[2] < row[3] && row[3] < row[4] && row[4] < row[5],
            "{row:?}"
        );
    }
}
