//! Frames made from the real Hayabusa2 TIR deep-space frame.
//!
//! **The frame as DN.** The real frame (its 328 × 248 effective area, read by the one
//! FITS reader [`crate::imaging::fits`]) is the camera's own signature over deep space
//! in DN of the instrument. The renderer's fixed-gain readout reads deep space as
//! DN = a·(F + π·o) + b with a = g/π, g the real camera's gain (DN per W m⁻² sr⁻¹), b
//! the pedestal and o the signature as a scene-equivalent radiance about the frame's
//! mean ([`crate::imaging::signature`]). The real frame is put in as that signature,
//! o_i = (D_i − mean D)/g, with a per-pixel gain of 1, so a noise-free read-out at 14
//! bits and gain factor 1 gives DN_i = D_i − mean D + b, the frame itself on the
//! pedestal ([`DARK_SIGNATURE_PLAIN`]).
//!
//! **Variants**, per frame from the seed: bit depth ([`BITS`]), gain factor
//! (log-uniform in [`GAIN_FACTOR`], the realistic world's range), a new temporal noise
//! realisation at the camera's NETD (the renderer's noise); the first frame without a
//! target is the frame itself (14 bits, gain 1, no added noise). Frames with a target
//! add a rendered target's F ([`super::targets`]) before the readout.

use std::path::Path;

use indicatif::ProgressBar;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

use super::composite::{ReadoutChoice, composite, read};
use super::targets::{TargetRender, TargetRenders};
use super::{Kind, TestFrame, TestRecord, box_array, file_name, reference_file};
use crate::dataset::DatasetError;
use crate::imaging::fits::read_fits;
use crate::imaging::image_io::FrameBuf;
use crate::imaging::render::PurePixels;
use crate::imaging::signature::{Calibration, SensorSignature, TIR_EFFECTIVE_AREA_PX};
use crate::seed::splitmix64;
use crate::world::scene::Camera;

/// The dark frame, relative to the reference folder.
pub const DARK_FRAME: &str = "hayabusa2-tir/dark_20180629_083003.fit";
/// Bit depths the variants cycle through (the realistic world's).
pub const BITS: [u8; 3] = [12, 14, 16];
/// Gain factor range, log-uniform (the realistic world's ×0.5–×2).
pub const GAIN_FACTOR: (f64, f64) = (0.5, 2.0);
/// Name of the plain variant in `metadata.jsonl`'s `readout` (the frame itself).
pub const DARK_SIGNATURE_PLAIN: &str = "fixed-gain";
/// Salt of the per-frame seed.
const DARK_SALT: u64 = 0xDA2C_0000_0000_0016;

/// The real dark frame's effective area, DN, and its mean.
#[derive(Debug, Clone)]
pub struct DarkFrame {
    /// Width, px (328).
    pub width: usize,
    /// Height, px (248).
    pub height: usize,
    /// DN of the real frame (space minus shutter), row-major.
    pub dn: Vec<f64>,
    /// Its mean, DN.
    pub mean_dn: f64,
}

impl DarkFrame {
    /// Reads the effective area of the dark frame under `reference`.
    ///
    /// # Errors
    /// [`DatasetError`] naming the missing or unreadable file, or an image smaller than
    /// the effective area.
    pub fn load(reference: &Path) -> Result<DarkFrame, DatasetError> {
        let path = reference_file(reference, DARK_FRAME)?;
        let image = read_fits(&path).map_err(DatasetError)?;
        let [x0, y0, w, h] = TIR_EFFECTIVE_AREA_PX;
        if image.width < x0 + w || image.height < y0 + h {
            return Err(DatasetError(format!(
                "{}: {} × {} px: expected at least {} × {} (the effective area {x0},{y0},{w},{h})",
                path.display(),
                image.width,
                image.height,
                x0 + w,
                y0 + h
            )));
        }
        let dn: Vec<f64> = (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .map(|(x, y)| image.at(x, y))
            .collect();
        if let Some(bad) = dn.iter().position(|v| !v.is_finite()) {
            return Err(DatasetError(format!(
                "{}: pixel {} of the effective area is not finite: expected DN",
                path.display(),
                bad
            )));
        }
        let mean_dn = dn.iter().sum::<f64>() / dn.len() as f64;
        Ok(DarkFrame {
            width: w,
            height: h,
            dn,
            mean_dn,
        })
    }

    /// The frame as the renderer's signature: offset (D − mean)/g, W m⁻² sr⁻¹, gain 1.
    pub fn signature(&self, dn_per_w_m2_sr: f64) -> SensorSignature {
        SensorSignature {
            width: self.width,
            height: self.height,
            offset_w_m2_sr: self
                .dn
                .iter()
                .map(|&d| ((d - self.mean_dn) / dn_per_w_m2_sr) as f32)
                .collect(),
            gain: vec![1.0; self.dn.len()],
        }
    }
}

/// The frames of the dark set (`none[i]`: frame i without a target).
///
/// # Errors
/// [`DatasetError`] for missing reference data or a frame the renderer refuses.
pub fn frames(
    reference: &Path,
    seed: u64,
    none: &[bool],
    bar: &ProgressBar,
) -> Result<Vec<TestFrame>, DatasetError> {
    let dark = DarkFrame::load(reference)?;
    let cal = Calibration::hayabusa2_tir().map_err(DatasetError)?;
    let signature = dark.signature(cal.gain.dn_per_w_m2_sr);
    let with_target = none.iter().filter(|&&n| !n).count();
    let targets = TargetRenders::new(with_target, seed)?;
    let camera0 = targets.scene_file().camera;
    if (camera0.width, camera0.height) != (dark.width, dark.height) {
        return Err(DatasetError(format!(
            "camera of {} × {} px: expected the dark frame's {} × {}",
            camera0.width, camera0.height, dark.width, dark.height
        )));
    }
    let plain = none.iter().position(|&n| n);
    // Frame i with a target takes target k = its rank among the frames with one.
    let mut rank = vec![None; none.len()];
    let mut k = 0;
    for (i, &n) in none.iter().enumerate() {
        if !n {
            rank[i] = Some(k);
            k += 1;
        }
    }
    let lib = targets.library();
    none.par_iter()
        .enumerate()
        .map(|(i, _)| {
            let mut rng = Pcg64::seed_from_u64(splitmix64(seed ^ DARK_SALT ^ i as u64));
            let is_plain = plain == Some(i);
            let bits = if is_plain {
                14
            } else {
                BITS[rng.gen_range(0..BITS.len())]
            };
            let gain_factor = if is_plain {
                1.0
            } else {
                rng.gen_range(GAIN_FACTOR.0.ln()..GAIN_FACTOR.1.ln()).exp()
            };
            let noise_seed = (!is_plain).then(|| rng.r#gen::<u64>());
            let target: Option<TargetRender> = match rank[i] {
                Some(k) => Some(targets.render(k)?),
                None => None,
            };
            let background = vec![0.0f32; dark.width * dark.height];
            let signal = composite(target.as_ref(), &background)?;
            let camera = Camera { bits, ..camera0 };
            let out = read(
                signal,
                &PurePixels::default(),
                &ReadoutChoice {
                    camera: &camera,
                    fixed_gain: Some(cal.fixed_gain()),
                    gain_factor,
                    noise_seed,
                    signature: Some(&signature),
                },
                &lib.band,
                &lib.lut,
            )?;
            let max_dn = out.mapping.max_dn();
            let record = TestRecord {
                index: i,
                file: file_name(i),
                kind: Kind::Dark.name().into(),
                background: "dark-frame".into(),
                bbox: box_array(target.as_ref().map_or(tirroi_core::Roi::EMPTY, |t| t.truth)),
                bbox_quarter: box_array(
                    target
                        .as_ref()
                        .map_or(tirroi_core::Roi::EMPTY, |t| t.truth_quarter),
                ),
                target: target.as_ref().map_or("none".into(), |t| t.target.clone()),
                material: target.as_ref().and_then(|t| t.material.clone()),
                illumination: target.as_ref().map(|t| t.illumination.clone()),
                range_m: target.as_ref().map(|t| t.range_m),
                mode: Some("radiometry".into()),
                readout: DARK_SIGNATURE_PLAIN.into(),
                bits,
                gain_factor,
                noise_seed,
                noise_sigma_dn: f64::from(out.noise_sigma_dn),
                earth_fraction: 0.0,
                saturated_px: out.dn.iter().filter(|&&v| v >= max_dn).count(),
                mask_px: target.as_ref().map_or(0, |t| t.mask_px),
                ..TestRecord::default()
            };
            bar.inc(1);
            Ok(TestFrame {
                frame: FrameBuf {
                    pixels: out.dn,
                    width: dark.width,
                    height: dark.height,
                    bits,
                },
                record,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;
    use crate::dataset::testset::{TestsetOptions, make_frames};
    use crate::imaging::signature::FIXED_GAIN_PEDESTAL_DN;

    fn reference() -> Option<PathBuf> {
        crate::dataset::testset::test_reference(DARK_FRAME)
    }

    #[test]
    fn plain_frame_is_the_real_frame_on_the_pedestal_and_variants_are_seeded() {
        let Some(r) = reference() else { return };
        let dark = DarkFrame::load(&r).expect("dark frame");
        // The reference README: mean −373 DN, σ 32 DN over the effective area.
        assert!((dark.mean_dn + 373.0).abs() < 1.0, "mean {}", dark.mean_dn);
        let opts = TestsetOptions {
            kind: Kind::Dark,
            count: 4,
            seed: 9,
            reference: r,
            no_target_fraction: Some(0.75),
            preview: false,
            progress: false,
            sequence_frames: None,
        };
        let bar = ProgressBar::hidden();
        let a = make_frames(&opts, &bar).expect("frames");
        let b = make_frames(&opts, &bar).expect("frames");
        assert_eq!(a.len(), 4);
        assert_eq!(a.iter().filter(|f| f.record.target == "none").count(), 3);
        for (fa, fb) in a.iter().zip(&b) {
            assert_eq!(fa.frame, fb.frame);
        }
        let plain = a
            .iter()
            .find(|f| f.record.noise_seed.is_none())
            .expect("the plain frame");
        assert_eq!(plain.record.target, "none");
        assert_eq!(plain.frame.bits, 14);
        // DN = D − mean D + pedestal, within the f32 radiance round trip and rounding.
        for (i, (&dn, &d)) in plain.frame.pixels.iter().zip(&dark.dn).enumerate() {
            let want = d - dark.mean_dn + FIXED_GAIN_PEDESTAL_DN;
            assert!(
                (f64::from(dn) - want).abs() <= 0.51,
                "pixel {i}: {dn} DN vs {want:.2}"
            );
        }
        // The noisy variants differ from each other and carry σ > 0.
        let noisy: Vec<_> = a.iter().filter(|f| f.record.noise_seed.is_some()).collect();
        assert!(noisy.iter().all(|f| f.record.noise_sigma_dn > 0.0));
        assert_ne!(noisy[0].frame.pixels, noisy[1].frame.pixels);
        let with = a
            .iter()
            .find(|f| f.record.target != "none")
            .expect("target");
        let [x0, y0, x1, y1] = with.record.bbox;
        assert!(x0 < x1 && y0 < y1 && x1 <= 328 && y1 <= 248);
    }
}
