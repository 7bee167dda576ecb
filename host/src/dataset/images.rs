//! Rendering and writing one image: the PNG (written atomically), its optional mask
//! and preview, and its [`ImageRecord`].

use std::fs::{self};
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::library::ThermalState;
use super::plan::ImagePlan;
use super::{DatasetError, WriteOptions};
use crate::imaging::image_io::{self, FrameBuf};
use crate::imaging::overlay;
use crate::imaging::render::{self, Rendered};
use crate::world::geom::Vec3;
use crate::world::scene::{RadiometryReadout, SceneFile, TargetModel};

/// The `target` label of a frame rendered without the target.
pub const NO_TARGET: &str = "none";

/// The labels and metadata of one image (a line of `metadata.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageRecord {
    /// Index.
    pub index: usize,
    /// PNG file name, relative to the dataset directory.
    pub file: String,
    /// Scene kind name.
    pub scene: String,
    /// Truth box [x0, y0, x1, y1) of the pixels covered at least `truth_coverage` (all
    /// 0 when no target is in the frame).
    pub bbox: [u16; 4],
    /// The coverage threshold of `bbox` (the scene file's `dataset.truth_coverage`).
    #[serde(default = "half")]
    pub truth_coverage: f64,
    /// Truth box of the pixels covered more than ¼ (⊇ `bbox` at the default ½; all 0
    /// when none).
    #[serde(default)]
    pub bbox_quarter: [u16; 4],
    /// Pixels in the target mask (coverage ≥ 0.5).
    pub mask_px: usize,
    /// "radiometry" or "detection".
    pub mode: String,
    /// Table 5 scale (detection).
    pub scale: Option<u8>,
    /// Target model, or "none" for a frame rendered without the target.
    pub target: String,
    /// Table 3 case (cube + cylinder).
    pub material: Option<String>,
    /// "sunlit" or "eclipse".
    pub illumination: String,
    /// Camera–target centre distance, m.
    pub range_m: f64,
    /// Target centre offset from the frame centre, px.
    pub offset_px: [f64; 2],
    /// Body → camera rotation, row-major.
    pub body_to_camera: [[f64; 3]; 3],
    /// Sun direction in the camera frame (sunlit).
    pub sun_dir_camera: Option<Vec3>,
    /// Earth centre direction in the camera frame.
    pub earth_dir_camera: Vec3,
    /// Fraction of the frame whose pixel centres see the Earth.
    pub earth_fraction: f64,
    /// DN map: gain a (DN per W m⁻²) and offset b (DN).
    pub dn_gain: f64,
    /// DN map offset b, DN.
    pub dn_offset: f64,
    /// Noise σ, DN (0: noise off).
    pub noise_sigma_dn: f32,
    /// |Mean target − background| over the mask, noise-free, DN (`None`: no target
    /// pixel at coverage ≥ ½); `imaging::render::clutter`.
    #[serde(default)]
    pub target_contrast_dn: Option<f64>,
    /// Standard deviation of the target-less background in a ring around the truth
    /// box, noise-free, DN (`None` as above).
    #[serde(default)]
    pub clutter_sigma_dn: Option<f64>,
    /// Contrast / max(clutter σ, noise σ, 1/√12 DN) (`None` as above).
    #[serde(default)]
    pub signal_to_clutter: Option<f64>,
    /// Tight box `[x0, y0, x1, y1]` of the target pixels whose noise-free contrast
    /// against the background, as the camera sees both, is ≥ 3 noise σ (all 0 when none
    /// is, or no target); inside `bbox`. `imaging::render::clutter`.
    #[serde(default)]
    pub visible_bbox: [u16; 4],
    /// Area of `visible_bbox` / area of `bbox`, 0..=1: the IoU of a detector that boxes
    /// exactly the pixels the target changes beyond the noise (an optimistic ceiling;
    /// `None` as above).
    #[serde(default)]
    pub visible_share: Option<f64>,
    /// Noise seed.
    pub noise_seed: Option<u64>,
    /// Bit depth of the DN map (scene `bits`, else the camera's): the PNG is 16-bit,
    /// saturation is at 2^bits − 1.
    #[serde(default = "default_bits")]
    pub bits: u8,
    /// Radiometry DN map: `auto` (Eq. 17) or `fixed-gain`; `table-5` in detection mode.
    #[serde(default)]
    pub readout: String,
    /// Factor on the mode's DN gain (scene `gain`).
    #[serde(default = "unit")]
    pub gain_factor: f64,
    /// NETD the noise is scaled to, K (camera NETD × scene `noise_netd_factor`).
    #[serde(default)]
    pub netd_k: f64,
    /// Whether the Moon is in the field of view (scene `moon`).
    #[serde(default)]
    pub moon_in_view: bool,
    /// Pixels whose centre sees the Moon (0 when it is not in view or hidden by the
    /// Earth).
    #[serde(default)]
    pub moon_px: usize,
    /// Direction to the Moon's centre in the camera frame (when in view).
    #[serde(default)]
    pub moon_dir_camera: Option<Vec3>,
    /// Coldest and hottest target facet, K.
    pub target_temperature_k: [f64; 2],
    /// Transient thermal state (`dataset.thermal = "transient"`): time since the
    /// target entered the Earth's shadow, s (0..orbital period; in eclipse while below
    /// `eclipse_duration_s`, sunlit after it); absent for steady states.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orbit_time_s: Option<f64>,
    /// Transient thermal state: the orbit's time in shadow, s (2 249 s on the reference
    /// orbit); absent for steady states.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eclipse_duration_s: Option<f64>,
    /// Dataset seed.
    pub dataset_seed: u64,
    /// The approach sequence the image belongs to (scene `sequence`; 0, 1, … in image
    /// order); absent outside one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<usize>,
    /// The image's frame within its sequence, 0 = the first; absent outside one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<usize>,
}

fn default_bits() -> u8 {
    tirroi_core::frame::DEFAULT_BIT_DEPTH
}

fn unit() -> f64 {
    1.0
}

fn half() -> f64 {
    crate::world::scene::DEFAULT_TRUTH_COVERAGE
}

pub(super) fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
    let tmp = path.with_extension(format!(
        "{}.part",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    fs::write(&tmp, bytes)
        .and_then(|()| fs::rename(&tmp, path))
        .map_err(|e| DatasetError(format!("{}: cannot write: {e}", path.display())))
}

/// PNG bytes through [`image_io::encode_png`], errors naming the file.
fn encode_png(
    bytes: &[u8],
    width: u32,
    height: u32,
    colour: image::ExtendedColorType,
    path: &Path,
) -> Result<Vec<u8>, DatasetError> {
    image_io::encode_png(bytes, width, height, colour)
        .map_err(|e| DatasetError(format!("{}: cannot encode PNG: {e}", path.display())))
}

pub(super) fn record(
    file: &SceneFile,
    plan: &ImagePlan,
    frame: &Rendered,
    thermal: &ThermalState,
) -> ImageRecord {
    let spec = &file.scenes[plan.scene];
    let threshold = file.dataset.truth_coverage as f32;
    let bbox = if threshold == render::MASK_COVERAGE {
        frame.truth
    } else {
        render::coverage_box(&frame.coverage, frame.width, |c| c >= threshold)
    };
    ImageRecord {
        index: plan.index,
        file: format!("{:06}.png", plan.index),
        scene: spec
            .name
            .clone()
            .unwrap_or_else(|| format!("scene-{}", plan.scene)),
        bbox: bbox.to_array(),
        truth_coverage: file.dataset.truth_coverage,
        bbox_quarter: frame.truth_quarter.to_array(),
        mask_px: frame
            .coverage
            .iter()
            .filter(|&&c| c >= render::MASK_COVERAGE)
            .count(),
        mode: plan.mode.label().into(),
        scale: plan.scale,
        target: if plan.has_target {
            plan.thermal.target.label().into()
        } else {
            NO_TARGET.into()
        },
        material: (plan.has_target && plan.thermal.target == TargetModel::CubeCylinder)
            .then(|| plan.thermal.material.label().to_string()),
        illumination: plan.thermal.illumination.label().into(),
        range_m: plan.range_m,
        offset_px: plan.offset_px,
        body_to_camera: plan.body_to_camera.0,
        sun_dir_camera: plan.sun_dir_camera,
        earth_dir_camera: plan.earth_dir_camera,
        earth_fraction: frame.earth_fraction,
        dn_gain: frame.mapping.gain_dn(),
        dn_offset: frame.mapping.offset_dn(),
        noise_sigma_dn: frame.noise_sigma_dn,
        target_contrast_dn: frame.clutter.map(|c| c.target_contrast_dn),
        clutter_sigma_dn: frame.clutter.map(|c| c.clutter_sigma_dn),
        signal_to_clutter: frame.clutter.map(|c| c.signal_to_clutter),
        visible_bbox: frame.clutter.map_or([0; 4], |c| {
            let v = c.visible;
            [v.x0, v.y0, v.x1, v.y1]
        }),
        visible_share: frame.clutter.map(|c| c.visible_share(frame.truth)),
        noise_seed: plan.noise_seed,
        bits: frame.mapping.bits(),
        readout: match (plan.scale, plan.readout) {
            (Some(_), _) => "table-5".into(),
            (None, RadiometryReadout::Auto) => "auto".into(),
            (None, RadiometryReadout::FixedGain) => "fixed-gain".into(),
        },
        gain_factor: plan.gain_factor,
        netd_k: file.camera.netd_k * plan.netd_factor,
        moon_in_view: plan.moon.is_some(),
        moon_px: frame.moon_px,
        moon_dir_camera: plan.moon.map(|m| m.dir_camera),
        target_temperature_k: [thermal.min_max_k.0, thermal.min_max_k.1],
        orbit_time_s: thermal.orbit_time_s,
        eclipse_duration_s: thermal.eclipse_duration_s,
        dataset_seed: file.dataset.seed,
        sequence: plan.sequence.map(|q| q.id),
        frame: plan.sequence.map(|q| q.frame),
    }
}

/// Writes one image's files; returns its record and the encode/write seconds.
pub(super) fn write_image(
    dir: &Path,
    file: &SceneFile,
    plan: &ImagePlan,
    frame: &Rendered,
    thermal: &ThermalState,
    options: &WriteOptions,
) -> Result<(ImageRecord, f64), DatasetError> {
    let t0 = Instant::now();
    let rec = record(file, plan, frame, thermal);
    let (w, h) = (frame.width as u32, frame.height as u32);
    let path = dir.join(&rec.file);
    let png = image_io::encode_dn_png(&frame.dn, w, h, frame.mapping.bits())
        .map_err(|e| DatasetError(format!("{}: cannot encode PNG: {e}", path.display())))?;
    atomic_write(&path, &png)?;
    if options.masks {
        let mask: Vec<u8> = frame
            .coverage
            .iter()
            .map(|c| (c * 255.0).round() as u8)
            .collect();
        let path = dir.join("masks").join(&rec.file);
        let png = encode_png(&mask, w, h, image::ExtendedColorType::L8, &path)?;
        atomic_write(&path, &png)?;
    }
    if options.preview {
        let buf = FrameBuf {
            pixels: frame.dn.clone(),
            width: frame.width,
            height: frame.height,
            bits: frame.mapping.bits(),
        };
        let img = overlay::frame_with_boxes(&buf, &[(frame.truth, overlay::TRUTH_COLOUR)], 2);
        let path = dir.join("preview").join(&rec.file);
        let png = encode_png(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
            &path,
        )?;
        atomic_write(&path, &png)?;
    }
    Ok((rec, t0.elapsed().as_secs_f64()))
}
