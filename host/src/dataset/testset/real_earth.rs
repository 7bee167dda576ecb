//! Rendered targets over windows of a real longwave image of the Earth.
//!
//! The source (`earth-lwir/hi-regional_10p7um_20050919_1315_tb50.png`, GOES-10 10.7 µm
//! at 4 km per pixel, close to the TIR's 3.9 km footprint from 4 500 km) is a 16-bit
//! PNG whose value is the brightness temperature × [`TB_SCALE`], 0 = no data. A window
//! is the camera's 328 × 248 px placed where every pixel holds data, flipped one of
//! four ways. Each pixel's brightness temperature T becomes the camera's band radiance
//! L(T) (`tirroi_core::sensor::BandRadiance` with the camera's spectral response),
//! F = π·L; a rendered target is composited over it by coverage
//! ([`super::composite::composite`]) and the frame read out by the renderer: the auto
//! range of Eq. 17 or the fixed gain ([`READOUT_FIXED_SHARE`]), a bit depth of
//! [`BITS`], and noise at the camera's NETD.

use std::collections::HashSet;
use std::path::Path;

use indicatif::ProgressBar;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use tirroi_core::Roi;
use tirroi_core::sensor::BandRadiance;

use super::composite::{ReadoutChoice, composite, pure_pixels, read};
use super::targets::{TargetRender, TargetRenders};
use super::{Kind, TestFrame, TestRecord, box_array, file_name, reference_file};
use crate::dataset::DatasetError;
use crate::imaging::image_io::{FrameBuf, read_frame};
use crate::imaging::render::MASK_COVERAGE;
use crate::imaging::signature::Calibration;
use crate::seed::splitmix64;
use crate::world::scene::Camera;

/// The real image, relative to the reference folder.
pub const EARTH_IMAGE: &str = "earth-lwir/hi-regional_10p7um_20050919_1315_tb50.png";
/// Counts per kelvin of the source's encoding (value = T × 50).
pub const TB_SCALE: f64 = 50.0;
/// Bit depths the frames draw from (the realistic world's).
pub const BITS: [u8; 3] = [12, 14, 16];
/// Share of frames read out with the fixed gain (the rest auto-ranged, Eq. 17).
pub const READOUT_FIXED_SHARE: f64 = 0.5;
/// Salt of the per-frame seed.
const EARTH_SALT: u64 = 0xEA27_0000_0000_0016;

/// The real image and where the camera's windows fit inside its data.
#[derive(Debug, Clone)]
pub struct RealEarth {
    /// Source width, px.
    pub width: usize,
    /// Source height, px.
    pub height: usize,
    /// Source values (T × 50, 0 = no data), row-major.
    pub tb50: Vec<u16>,
    /// Window size, px.
    pub window: (usize, usize),
    /// Top-left corners of every window with no pixel lacking data.
    pub corners: Vec<(usize, usize)>,
    /// F = π·L(T), W m⁻², per source value (index = the value; 0 where unused).
    f_of_value: Vec<f32>,
}

impl RealEarth {
    /// Reads the image under `reference` and finds the windows of `window` px fully
    /// inside its data; radiances by the camera's `band`.
    ///
    /// # Errors
    /// [`DatasetError`] naming the file when it is missing or unreadable, or holds no
    /// such window, or a temperature the band model refuses.
    pub fn load(
        reference: &Path,
        window: (usize, usize),
        band: &BandRadiance,
    ) -> Result<RealEarth, DatasetError> {
        let path = reference_file(reference, EARTH_IMAGE)?;
        let img = read_frame(&path, Some(16)).map_err(|e| DatasetError(e.to_string()))?;
        let (w, h) = (img.width, img.height);
        let (ww, wh) = window;
        // Summed-area table of no-data pixels.
        let mut sat = vec![0u32; (w + 1) * (h + 1)];
        for y in 0..h {
            let mut row = 0u32;
            for x in 0..w {
                row += u32::from(img.pixels[y * w + x] == 0);
                sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + row;
            }
        }
        let mut corners = Vec::new();
        for y0 in 0..=h.saturating_sub(wh) {
            for x0 in 0..=w.saturating_sub(ww) {
                if ww > w || wh > h {
                    break;
                }
                let (x1, y1) = (x0 + ww, y0 + wh);
                let s = |x: usize, y: usize| sat[y * (w + 1) + x];
                if s(x1, y1) + s(x0, y0) - s(x0, y1) - s(x1, y0) == 0 {
                    corners.push((x0, y0));
                }
            }
        }
        if corners.is_empty() {
            return Err(DatasetError(format!(
                "{}: {w} × {h} px: no {ww} × {wh} window lies fully inside its data (value > 0)",
                path.display()
            )));
        }
        let max = img.pixels.iter().copied().max().unwrap_or(0) as usize;
        let mut used = vec![false; max + 1];
        for &v in &img.pixels {
            used[v as usize] = true;
        }
        let mut f_of_value = vec![0f32; max + 1];
        for (v, f) in f_of_value.iter_mut().enumerate().skip(1) {
            if used[v] {
                let t_k = v as f64 / TB_SCALE;
                let l = band.radiance_w_m2_sr(t_k, 1.0).map_err(|e| {
                    DatasetError(format!("{}: value {v} ({t_k} K): {e}", path.display()))
                })?;
                *f = (std::f64::consts::PI * l) as f32;
            }
        }
        Ok(RealEarth {
            width: w,
            height: h,
            tb50: img.pixels,
            window,
            corners,
            f_of_value,
        })
    }

    /// The source value under window pixel (x, y) of the window at `corner`, flipped
    /// by `flip` (bit 0: left-right, bit 1: up-down).
    pub fn value(&self, corner: (usize, usize), flip: u8, x: usize, y: usize) -> u16 {
        let (ww, wh) = self.window;
        let sx = if flip & 1 == 1 { ww - 1 - x } else { x };
        let sy = if flip & 2 == 2 { wh - 1 - y } else { y };
        self.tb50[(corner.1 + sy) * self.width + corner.0 + sx]
    }

    /// F = π·L(T), W m⁻², of the window, row-major.
    pub fn window_f(&self, corner: (usize, usize), flip: u8) -> Vec<f32> {
        let (ww, wh) = self.window;
        (0..wh)
            .flat_map(|y| (0..ww).map(move |x| (x, y)))
            .map(|(x, y)| self.f_of_value[self.value(corner, flip, x, y) as usize])
            .collect()
    }
}

/// Largest slide of the real ground per frame and axis, px: the renderer's approach
/// sequences slide their ground by up to about 5 px per frame; at least 1 px on one
/// axis, so every sequence moves.
pub const SEQUENCE_MAX_SLIDE_PX: isize = 5;

/// Salt of a sequence's seed.
const SEQUENCE_SALT: u64 = 0xEA27_5E00_0000_0043;

/// A sequence's path over the real image: the first window's corner, the slide per
/// frame (px, x and y in the source), and the readout shared by its frames.
struct SequencePath {
    corner: (usize, usize),
    slide: (isize, isize),
    flip: u8,
    fixed: bool,
    bits: u8,
}

/// The path of sequence `s` (`frames` frames): a slide drawn in ±[`SEQUENCE_MAX_SLIDE_PX`]
/// and a first corner whose every window along it lies inside the data.
///
/// # Errors
/// No such corner in 10 000 draws (an image with too little data for the slide).
fn sequence_path(
    earth: &RealEarth,
    valid: &HashSet<(usize, usize)>,
    seed: u64,
    s: usize,
    frames: usize,
) -> Result<SequencePath, DatasetError> {
    let mut rng = Pcg64::seed_from_u64(splitmix64(seed ^ SEQUENCE_SALT ^ s as u64));
    let m = SEQUENCE_MAX_SLIDE_PX;
    let mut slide = (0, 0);
    while slide == (0, 0) {
        slide = (rng.gen_range(-m..=m), rng.gen_range(-m..=m));
    }
    let flip: u8 = rng.gen_range(0..4);
    let fixed = rng.gen_bool(READOUT_FIXED_SHARE);
    let bits = BITS[rng.gen_range(0..BITS.len())];
    for _ in 0..10_000 {
        let corner = earth.corners[rng.gen_range(0..earth.corners.len())];
        let inside = (0..frames).all(|k| {
            let x = corner.0.checked_add_signed(slide.0 * k as isize);
            let y = corner.1.checked_add_signed(slide.1 * k as isize);
            x.zip(y).is_some_and(|c| valid.contains(&c))
        });
        if inside {
            return Ok(SequencePath {
                corner,
                slide,
                flip,
                fixed,
                bits,
            });
        }
    }
    Err(DatasetError(format!(
        "real-earth sequence {s}: no path of {frames} windows sliding {slide:?} px per frame \
         lies inside the image's data"
    )))
}

/// The frames of the real-Earth set (`none[i]`: frame i without a target). With
/// `sequence_frames` = n, frames come in sequences of n (frame i is frame i mod n of
/// sequence i / n): the camera's window slides over the real image by a fixed step
/// per frame (the ground moving, [`SEQUENCE_MAX_SLIDE_PX`]), the target composited
/// where it is in every frame (the camera following it), readout shared, noise per
/// frame; `none` of a sequence's first frame holds for all of it.
///
/// # Errors
/// [`DatasetError`] for missing reference data or a frame the renderer refuses.
pub fn frames(
    reference: &Path,
    seed: u64,
    none: &[bool],
    sequence_frames: Option<usize>,
    bar: &ProgressBar,
) -> Result<Vec<TestFrame>, DatasetError> {
    // A sequence's frames share one target (the first frame's `none` decides).
    let per = sequence_frames.unwrap_or(1).max(1);
    let leads: Vec<bool> = none.iter().step_by(per).copied().collect();
    let with_target = leads.iter().filter(|&&n| !n).count();
    let targets = TargetRenders::new(with_target, seed)?;
    let camera0 = targets.scene_file().camera;
    let lib = targets.library();
    let earth = RealEarth::load(reference, (camera0.width, camera0.height), &lib.band)?;
    let cal = Calibration::hayabusa2_tir().map_err(DatasetError)?;
    let mut rank = vec![None; leads.len()];
    let mut k = 0;
    for (i, &n) in leads.iter().enumerate() {
        if !n {
            rank[i] = Some(k);
            k += 1;
        }
    }
    let valid: HashSet<(usize, usize)> = earth.corners.iter().copied().collect();
    none.par_iter()
        .enumerate()
        .map(|(i, _)| {
            let mut rng = Pcg64::seed_from_u64(splitmix64(seed ^ EARTH_SALT ^ i as u64));
            let (s, frame) = (i / per, i % per);
            let (corner, flip, fixed, bits, place) = match sequence_frames {
                None => {
                    let corner = earth.corners[rng.gen_range(0..earth.corners.len())];
                    let flip: u8 = rng.gen_range(0..4);
                    let fixed = rng.gen_bool(READOUT_FIXED_SHARE);
                    let bits = BITS[rng.gen_range(0..BITS.len())];
                    (corner, flip, fixed, bits, None)
                }
                Some(_) => {
                    let q = sequence_path(&earth, &valid, seed, s, per)?;
                    let at = (
                        q.corner.0.wrapping_add_signed(q.slide.0 * frame as isize),
                        q.corner.1.wrapping_add_signed(q.slide.1 * frame as isize),
                    );
                    (at, q.flip, q.fixed, q.bits, Some((s, frame)))
                }
            };
            let noise_seed = Some(rng.r#gen::<u64>());
            let target: Option<TargetRender> = match rank[s] {
                Some(k) => Some(targets.render(k)?),
                None => None,
            };
            let background = earth.window_f(corner, flip);
            let signal = composite(target.as_ref(), &background)?;
            let pure = pure_pixels(&signal, target.as_ref());
            let camera = Camera { bits, ..camera0 };
            let out = read(
                signal,
                &pure,
                &ReadoutChoice {
                    camera: &camera,
                    fixed_gain: fixed.then(|| cal.fixed_gain()),
                    gain_factor: 1.0,
                    noise_seed,
                    signature: None,
                },
                &lib.band,
                &lib.lut,
            )?;
            let n = camera0.width * camera0.height;
            let on_target = target.as_ref().map_or(0, |t| {
                t.coverage.iter().filter(|&&c| c >= MASK_COVERAGE).count()
            });
            let (mut lo, mut hi) = (u16::MAX, 0u16);
            for y in 0..camera0.height {
                for x in 0..camera0.width {
                    let v = earth.value(corner, flip, x, y);
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            let max_dn = out.mapping.max_dn();
            let truth = target.as_ref().map_or(Roi::EMPTY, |t| t.truth);
            let truth_quarter = target.as_ref().map_or(Roi::EMPTY, |t| t.truth_quarter);
            let record = TestRecord {
                index: i,
                file: file_name(i),
                kind: Kind::RealEarth.name().into(),
                background: "real-earth".into(),
                bbox: box_array(truth),
                bbox_quarter: box_array(truth_quarter),
                target: target.as_ref().map_or("none".into(), |t| t.target.clone()),
                material: target.as_ref().and_then(|t| t.material.clone()),
                illumination: target.as_ref().map(|t| t.illumination.clone()),
                range_m: target.as_ref().map(|t| t.range_m),
                mode: Some("radiometry".into()),
                readout: if fixed { "fixed-gain" } else { "auto" }.into(),
                bits,
                gain_factor: 1.0,
                noise_seed,
                noise_sigma_dn: f64::from(out.noise_sigma_dn),
                earth_fraction: (n - on_target) as f64 / n as f64,
                saturated_px: out.dn.iter().filter(|&&v| v >= max_dn).count(),
                mask_px: on_target,
                window: Some([corner.0, corner.1, usize::from(flip)]),
                window_bt_k: Some([f64::from(lo) / TB_SCALE, f64::from(hi) / TB_SCALE]),
                sequence: place.map(|(s, _)| s),
                frame: place.map(|(_, k)| k),
                ..TestRecord::default()
            };
            bar.inc(1);
            Ok(TestFrame {
                frame: FrameBuf {
                    pixels: out.dn,
                    width: camera0.width,
                    height: camera0.height,
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

    fn reference() -> Option<PathBuf> {
        crate::dataset::testset::test_reference(EARTH_IMAGE)
    }

    #[test]
    fn window_radiance_is_the_band_radiance_of_the_real_temperature() {
        let Some(r) = reference() else { return };
        let band = BandRadiance::hayabusa2_tir();
        let earth = RealEarth::load(&r, (328, 248), &band).expect("load");
        // The source read independently, with the `image` crate.
        let img = image::open(r.join(EARTH_IMAGE)).expect("png").into_luma16();
        println!("{} windows fully inside the data", earth.corners.len());
        assert!(earth.corners.len() > 100, "{} windows", earth.corners.len());
        for (k, flip) in [
            (0usize, 0u8),
            (earth.corners.len() / 2, 1),
            (earth.corners.len() - 1, 3),
        ] {
            let c = earth.corners[k];
            let f = earth.window_f(c, flip);
            for (x, y) in [(0usize, 0usize), (327, 247), (100, 50), (200, 200)] {
                let sx = if flip & 1 == 1 { 327 - x } else { x };
                let sy = if flip & 2 == 2 { 247 - y } else { y };
                let v = img.get_pixel((c.0 + sx) as u32, (c.1 + sy) as u32)[0];
                assert!(v > 0, "window {c:?} holds no-data pixel ({sx}, {sy})");
                let t_k = f64::from(v) / 50.0;
                assert!((224.0..=297.0).contains(&t_k), "{t_k} K");
                let l = band.radiance_w_m2_sr(t_k, 1.0).expect("L");
                let want = std::f64::consts::PI * l;
                let got = f64::from(f[y * 328 + x]);
                assert!(
                    (got - want).abs() <= 1e-6 * want,
                    "{got} vs π·L({t_k} K) = {want}"
                );
            }
        }
    }

    /// `--sequence-frames`: frames come in sequences whose window slides by one fixed
    /// step per frame (at most `SEQUENCE_MAX_SLIDE_PX` per axis, never none) inside the
    /// data, with one readout and one target each; `truth.csv` gains `sequence,frame`;
    /// the share without a target counts sequences; other kinds and lengths are refused.
    #[test]
    fn sequences_slide_the_real_ground() {
        let Some(r) = reference() else { return };
        let opts = TestsetOptions {
            kind: Kind::RealEarth,
            count: 12,
            seed: 5,
            reference: r,
            no_target_fraction: Some(0.4),
            preview: false,
            progress: false,
            sequence_frames: Some(4),
        };
        let bar = ProgressBar::hidden();
        let frames = make_frames(&opts, &bar).expect("frames");
        for (a, b) in frames
            .iter()
            .zip(&make_frames(&opts, &bar).expect("frames"))
        {
            assert_eq!((&a.frame, &a.record), (&b.frame, &b.record), "seeded");
        }
        let mut without = 0;
        for seq in frames.chunks(4) {
            let first = &seq[0].record;
            let [x0, y0, flip] = first.window.expect("a window");
            let [x1, y1, _] = seq[1].record.window.expect("a window");
            let step = (x1 as isize - x0 as isize, y1 as isize - y0 as isize);
            assert_ne!(step, (0, 0));
            assert!(step.0.abs() <= SEQUENCE_MAX_SLIDE_PX && step.1.abs() <= SEQUENCE_MAX_SLIDE_PX);
            without += usize::from(first.target == "none");
            for (k, f) in seq.iter().enumerate() {
                let rec = &f.record;
                assert_eq!((rec.sequence, rec.frame), (Some(first.index / 4), Some(k)));
                let w = rec.window.expect("a window");
                let at = (
                    x0 as isize + step.0 * k as isize,
                    y0 as isize + step.1 * k as isize,
                );
                assert_eq!((w[0] as isize, w[1] as isize, w[2]), (at.0, at.1, flip));
                assert_eq!((rec.bits, &rec.readout), (first.bits, &first.readout));
                assert_eq!((&rec.target, rec.bbox), (&first.target, first.bbox));
            }
        }
        // 40 % of three sequences, rounded up: two without a target.
        assert_eq!(without, 2);
        let (csv, _) = crate::dataset::testset::labels(&frames).expect("labels");
        let header = csv.lines().next().unwrap_or_default();
        assert!(header.ends_with(",sequence,frame"), "{header}");
        assert!(
            csv.lines().nth(6).unwrap_or_default().ends_with(",1,1"),
            "{csv}"
        );
        for (kind, n) in [(Kind::Dark, Some(4)), (Kind::RealEarth, Some(1))] {
            let bad = TestsetOptions {
                kind,
                sequence_frames: n,
                ..opts.clone()
            };
            let e = make_frames(&bad, &bar).expect_err("refused");
            assert!(e.to_string().contains("--sequence-frames"), "{e}");
        }
    }

    #[test]
    fn frames_are_seeded_physical_and_labelled() {
        let Some(r) = reference() else { return };
        let opts = TestsetOptions {
            kind: Kind::RealEarth,
            count: 4,
            seed: 5,
            reference: r,
            no_target_fraction: Some(0.5),
            preview: false,
            progress: false,
            sequence_frames: None,
        };
        let bar = ProgressBar::hidden();
        let a = make_frames(&opts, &bar).expect("frames");
        let b = make_frames(&opts, &bar).expect("frames");
        assert_eq!(a.len(), 4);
        let none = a.iter().filter(|f| f.record.target == "none").count();
        assert_eq!(none, 2);
        for (fa, fb) in a.iter().zip(&b) {
            assert_eq!(fa.frame, fb.frame, "{}: same seed, same DN", fa.record.file);
            assert_eq!(fa.record, fb.record);
            let [x0, y0, x1, y1] = fa.record.bbox;
            let [q0, r0, q1, r1] = fa.record.bbox_quarter;
            if fa.record.target == "none" {
                assert_eq!([x0, y0, x1, y1, q0, r0, q1, r1], [0; 8]);
            } else {
                assert!(
                    x0 < x1 && y0 < y1 && x1 <= 328 && y1 <= 248,
                    "{:?}",
                    fa.record.bbox
                );
                // The quarter box holds the half box.
                assert!(q0 <= x0 && r0 <= y0 && q1 >= x1 && r1 >= y1);
            }
            let max = (1u32 << fa.frame.bits) - 1;
            assert!(fa.frame.pixels.iter().all(|&v| u32::from(v) <= max));
        }
    }
}
