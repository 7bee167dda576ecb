//! The Earth model, dataset settings and one scene kind ([`SceneSpec`]) of a scene file,
//! with their serde defaults and checks.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use tirroi_core::sensor::DetectionScale;

use super::camera::{Camera, RadiometryReadout, is_false};
use super::kinds::{
    Illumination, Mode, MoonSpec, OneOrMany, Param, SequenceSpec, TargetModel, ThermalModel,
};
use crate::world::constants::{EARTH_DISTANCE_M, EARTH_RADIUS_M};
use crate::world::earth::clouds::{LOW_TOP_TEXTURE_K, MAX_REGIONAL_RADIUS_CELLS};
use crate::world::earth::{ECLIPSE_FLUX_FACTOR, EarthMap};
use crate::world::spacecraft::MaterialCase;

/// Largest `earth_model.cloud_top_texture_k`, K per σ: clipped at 2 σ, 20 K of
/// texture, as much as a low cloud is deep.
pub const MAX_CLOUD_TOP_TEXTURE_K: f64 = 10.0;

/// Where the Earth's longwave flux map comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EarthSource {
    /// The built-in synthetic daily field ([`crate::world::earth::OlrGrid::builtin`]).
    Builtin,
    /// A CERES SYN1deg NetCDF file (`path`, `variable`, `time_index`); needs the
    /// `netcdf` cargo feature.
    Netcdf,
}

/// How the Earth looks below the 1° flux grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EarthTexture {
    /// The paper's: the 1° Eq. 10 temperatures interpolated to the `mesh_deg` mesh,
    /// flat per mesh cell, the view factor's cos of the emission angle at the limb.
    #[default]
    Paper,
    /// Sub-grid cloud texture ([`crate::world::earth::CloudField`]): sharp-edged cloud
    /// fields conserving each 1° cell's flux, limb darkening and a thin atmospheric
    /// edge beyond the limb.
    Clouds,
}

/// The Earth model shared by every scene of a file (Section 3.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EarthModel {
    /// Source of the 1° TOA longwave flux map.
    pub source: EarthSource,
    /// NetCDF file (relative paths are taken from the config file's directory).
    pub path: Option<PathBuf>,
    /// NetCDF variable (CERES SYN1deg daily all-sky TOA LW: `toa_lw_all_daily`).
    pub variable: String,
    /// Index along the file's time dimension (day).
    pub time_index: usize,
    /// Built-in source: how many different daily maps the images draw from (1..=16).
    pub days: usize,
    /// Cell size of the refined mesh, degrees (0.1 as the paper's Fig. 3b; 1.0 gives 3a).
    pub mesh_deg: f64,
    /// Eclipse: factor on the sunlit flux map (Section 3.2.2).
    pub eclipse_factor: f32,
    /// Earth radius, km.
    pub radius_km: f64,
    /// Sub-grid texture: "paper" (default) or "clouds".
    pub texture: EarthTexture,
    /// With `texture = "clouds"`: texture of the cloud tops outside deep convection, K
    /// per σ of the field's finer octaves, 0..=10 (default 0: flat tops; the `realistic`
    /// presets set 5, about the real 4 km image's median cloud-top spread,
    /// docs/scenes.md § Cloud-top texture). Not written by `--print-config` when 0.
    #[serde(skip_serializing_if = "is_zero")]
    pub cloud_top_texture_k: f64,
    /// With `texture = "clouds"`: radius, cells, of the regional cloud balance
    /// ([`crate::world::earth::CloudField::with_regional_balance`]: each 1° cell's
    /// cloud threshold the mean of the (2r + 1)² cells' around it, so clouds gather
    /// into masses across cells), 0..=4 (default 0: each cell balanced on its own; the
    /// `realistic` presets set 1, docs/scenes.md § Cloud masses). Not written by
    /// `--print-config` when 0.
    #[serde(skip_serializing_if = "is_zero_cells")]
    pub regional_balance_cells: usize,
    /// With `texture = "clouds"`: the small cold fragments bound to the clouds
    /// ([`crate::world::earth::CloudField::with_cloud_fragments`]: more among clouds,
    /// fewer in clear air, their tops 18–28 K below the cloud under them; default false:
    /// anywhere, 18–40 K below the clear sky; the `realistic` presets set true,
    /// docs/scenes.md § Cloud-bound fragments). Not written by `--print-config` when
    /// false.
    #[serde(skip_serializing_if = "is_false")]
    pub cloud_fragments: bool,
}

fn is_zero_cells(v: &usize) -> bool {
    *v == 0
}

impl Default for EarthModel {
    fn default() -> Self {
        EarthModel {
            source: EarthSource::Builtin,
            path: None,
            variable: "toa_lw_all_daily".into(),
            time_index: 0,
            days: 2,
            mesh_deg: EarthMap::DEFAULT_MESH_DEG,
            eclipse_factor: ECLIPSE_FLUX_FACTOR,
            radius_km: EARTH_RADIUS_M / 1e3,
            texture: EarthTexture::Paper,
            cloud_top_texture_k: LOW_TOP_TEXTURE_K,
            regional_balance_cells: 0,
            cloud_fragments: false,
        }
    }
}

impl EarthModel {
    pub(super) fn validate(&self) -> Result<(), String> {
        if self.source == EarthSource::Netcdf && self.path.is_none() {
            return Err(
                "earth_model.path is missing: source = \"netcdf\" needs path = \"FILE.nc\"".into(),
            );
        }
        if !(1..=16).contains(&self.days) {
            return Err(format!("earth_model.days = {}: expected 1..=16", self.days));
        }
        if !(self.mesh_deg.is_finite() && self.mesh_deg > 0.0 && self.mesh_deg <= 1.0) {
            return Err(format!(
                "earth_model.mesh_deg = {}: expected a cell size in (0, 1] degrees that divides 1",
                self.mesh_deg
            ));
        }
        if !(self.eclipse_factor.is_finite()
            && self.eclipse_factor > 0.0
            && self.eclipse_factor <= 1.0)
        {
            return Err(format!(
                "earth_model.eclipse_factor = {}: expected (0, 1]",
                self.eclipse_factor
            ));
        }
        if !(self.radius_km.is_finite() && self.radius_km > 0.0) {
            return Err(format!(
                "earth_model.radius_km = {}: expected a number > 0",
                self.radius_km
            ));
        }
        if !(0.0..=MAX_CLOUD_TOP_TEXTURE_K).contains(&self.cloud_top_texture_k) {
            return Err(format!(
                "earth_model.cloud_top_texture_k = {}: expected 0..={MAX_CLOUD_TOP_TEXTURE_K} K",
                self.cloud_top_texture_k
            ));
        }
        if self.regional_balance_cells > MAX_REGIONAL_RADIUS_CELLS {
            return Err(format!(
                "earth_model.regional_balance_cells = {}: expected 0..={MAX_REGIONAL_RADIUS_CELLS} cells",
                self.regional_balance_cells
            ));
        }
        // The cloud texture's own settings, set away from their defaults: (set, the
        // setting as written, what only the cloud texture has).
        let cloud_settings = [
            (
                self.cloud_top_texture_k > 0.0,
                format!("cloud_top_texture_k = {}", self.cloud_top_texture_k),
                "cloud tops",
            ),
            (
                self.regional_balance_cells > 0,
                format!("regional_balance_cells = {}", self.regional_balance_cells),
                "a cloud balance",
            ),
            (
                self.cloud_fragments,
                "cloud_fragments = true".to_string(),
                "cloud fragments",
            ),
        ];
        if self.texture != EarthTexture::Clouds {
            if let Some((_, setting, what)) = cloud_settings.iter().find(|(set, ..)| *set) {
                return Err(format!(
                    "earth_model.{setting}: only the cloud texture has {what} (set texture = \"clouds\")"
                ));
            }
        }
        Ok(())
    }
}

/// Dataset-wide settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DatasetSettings {
    /// Name written into the labels.
    pub name: String,
    /// Master seed: every image's pose, Earth and noise derive from it and its index.
    pub seed: u64,
    /// Thermal states per (target, material, illumination): random-attitude images
    /// pick one of these solutions (steady states, or times along the orbit with
    /// `thermal = "transient"`) and a camera view consistent with it.
    pub thermal_states: usize,
    /// Target temperatures: `"steady"` (default) or `"transient"` (the periodic
    /// state on the orbit, sampled at times along it; random-attitude scenes only,
    /// fixed attitudes keep the steady state).
    pub thermal: ThermalModel,
    /// Target coverage at or above which a pixel belongs to the truth box `x0,y0,x1,y1`
    /// of `truth.csv` (0 < value ≤ 1; default [`DEFAULT_TRUTH_COVERAGE`]). The box of the pixels
    /// covered more than ¼ is written beside it whatever this is.
    #[serde(skip_serializing_if = "is_half")]
    pub truth_coverage: f64,
}

/// The default truth-box coverage: a pixel at least half covered by the target (the
/// renderer's mask, `imaging::render::MASK_COVERAGE`, the paper's convention).
pub const DEFAULT_TRUTH_COVERAGE: f64 = 0.5;

fn is_half(v: &f64) -> bool {
    *v == DEFAULT_TRUTH_COVERAGE
}

impl Default for DatasetSettings {
    fn default() -> Self {
        DatasetSettings {
            name: "custom".into(),
            seed: 1,
            thermal_states: 12,
            thermal: ThermalModel::Steady,
            truth_coverage: DEFAULT_TRUTH_COVERAGE,
        }
    }
}

/// Largest `max_offset_fraction`: 1.5 half-frames (the target's centre up to a quarter
/// frame outside the edge, then pulled back to keep part of it in view).
pub const MAX_OFFSET_FRACTION: f64 = 1.5;

/// One kind of scene: `count` images sharing these settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Label of this kind (default "scene-N").
    #[serde(default)]
    pub name: Option<String>,
    /// Images of this kind (0 turns the kind off; the file's total must be at least 1).
    /// Detection renders each pose at every scale, in order; when `count` is not a
    /// multiple of the scales, the last pose is rendered at the first `count mod
    /// scales` of them only (so `--count N` gives exactly N images).
    #[serde(default = "one")]
    pub count: usize,
    /// Camera mode.
    #[serde(default = "radiometry")]
    pub mode: Mode,
    /// Detection scales of Table 5 (1, 2 or 3); each pose is rendered at every scale
    /// listed, as in the paper. Ignored in radiometry mode.
    #[serde(default = "scale_one")]
    pub scale: OneOrMany<u8>,
    /// Target spacecraft.
    #[serde(default = "cube_cylinder")]
    pub target: TargetModel,
    /// Table 3 material case (cube + cylinder only).
    #[serde(default = "mono")]
    pub material: OneOrMany<MaterialCase>,
    /// Facet edge length of the target mesh, m (default per target).
    #[serde(default)]
    pub resolution_m: Option<f64>,
    /// Camera–target centre distance, m (0.5..=100 000).
    pub range_m: Param,
    /// Target attitude as Z-Y-X Euler angles, degrees, body → camera frame; omitted: a
    /// random attitude consistent with one of the dataset's thermal states.
    #[serde(default)]
    pub attitude_deg: Option<[f64; 3]>,
    /// Where the target's centre projects, pixels from the frame centre (x right, y
    /// down); omitted: uniform within the central `max_offset_fraction` of the frame.
    #[serde(default)]
    pub offset_px: Option<[f64; 2]>,
    /// Random offsets stay within this fraction of the half-frame (0..=1.5, default
    /// 0.6). Above 1 the target's centre can leave the frame and the target is cut by
    /// its edge; the centre is then pulled back so that a disc of the target's inner
    /// half-size ([`TargetModel::inner_half_size_m`]) still reaches 2 px into the frame
    /// (the dataset's `EDGE_CUT_KEEP_PX`): never a frame without the target.
    #[serde(default = "max_offset")]
    pub max_offset_fraction: f64,
    /// Sunlit or eclipse (one, or a list the poses cycle through).
    #[serde(default = "sunlit")]
    pub illumination: OneOrMany<Illumination>,
    /// Direction to the Sun in the camera frame (with a fixed attitude only; default
    /// from behind the camera's upper left).
    #[serde(default)]
    pub sun_dir: Option<[f64; 3]>,
    /// Add the camera noise (Eq. 18).
    #[serde(default = "yes")]
    pub noise: bool,
    /// Render the Earth (false: deep space behind the target; the Earth still heats it).
    #[serde(default = "yes")]
    pub earth: bool,
    /// Camera–Earth centre distance, km (10 871: 4 500 km altitude, Section 4.1).
    #[serde(default = "earth_distance")]
    pub earth_distance_km: f64,
    /// Angle between the boresight and the direction to the Earth's centre, degrees
    /// (below ~26° the Earth fills the frame, above ~46° it is out of view).
    #[serde(default = "off_boresight")]
    pub earth_off_boresight_deg: Param,
    /// Image-plane direction towards the Earth's centre, degrees from +x towards +y.
    #[serde(default = "full_circle")]
    pub earth_azimuth_deg: Param,
    /// Factor on the DN map's gain a (0.05..=20, default 1). Detection: the Table 5
    /// scale's gain × factor (offset 0): the Earth's warmest cell (2.07e-17 W m⁻², 69 %
    /// of Scale 1) sits at 0.69 × factor of full scale on Scale 1 (clipped above factor
    /// 1.45), and a hot target saturates sooner. Radiometry: the auto range
    /// (Eq. 17) is computed, then its gain is multiplied about the frame's minimum F
    /// (which stays at DN 0): above 1 the brightest pure pixels clip at 2ⁿ − 1, below 1
    /// the scene spans only `factor` of the DN range.
    #[serde(default = "unit")]
    pub gain: Param,
    /// Factor on the camera's NETD the noise is scaled to (0..=100, default 1): the
    /// frame's NETD is `camera.netd_k × factor`.
    #[serde(default = "unit")]
    pub noise_netd_factor: Param,
    /// Bit depth of the DN map per pose (1..=16; a list is cycled through by the poses);
    /// omitted: `camera.bits`. The PNG stays 16-bit; `truth.csv` has a `bits` column.
    #[serde(default)]
    pub bits: Option<OneOrMany<u8>>,
    /// The Moon in the field of view with some probability (omitted: never).
    #[serde(default)]
    pub moon: Option<MoonSpec>,
    /// Radiometry DN map per pose: `"auto"` (Eq. 17), `"fixed-gain"`, or a list the
    /// poses cycle through (e.g. both, so the kind is read out both ways); omitted:
    /// `[camera] readout`. Recorded per frame as `readout` in `metadata.jsonl`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readout: Option<OneOrMany<RadiometryReadout>>,
    /// Share of this kind's poses rendered without the target (0..=1, default 0): the
    /// same camera, Earth and noise, nothing to detect (`target = "none"` in the labels,
    /// empty truth box). ⌈share × poses⌉ poses, picked by a permutation seeded from the
    /// dataset seed and the kind's index, so they mix with every material and
    /// illumination the poses cycle through; the other poses are unchanged. 1: a kind of
    /// target-less frames only.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub no_target_fraction: f64,
    /// Approach sequences ([`SequenceSpec`]): each pose becomes `frames` consecutive
    /// images of one encounter (per scale: pose, then scale, then frame), labelled with
    /// `sequence` and `frame` in `truth.csv` and `metadata.jsonl`. `count` still counts
    /// images. Omitted: every image is its own pose (today's datasets, unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sequence: Option<SequenceSpec>,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn one() -> usize {
    1
}
fn radiometry() -> Mode {
    Mode::Radiometry
}
fn scale_one() -> OneOrMany<u8> {
    OneOrMany::One(1)
}
fn cube_cylinder() -> TargetModel {
    TargetModel::CubeCylinder
}
fn mono() -> OneOrMany<MaterialCase> {
    OneOrMany::One(MaterialCase::Mono)
}
fn max_offset() -> f64 {
    0.6
}
fn sunlit() -> OneOrMany<Illumination> {
    OneOrMany::One(Illumination::Sunlit)
}
fn yes() -> bool {
    true
}
fn earth_distance() -> f64 {
    EARTH_DISTANCE_M / 1e3
}
fn unit() -> Param {
    Param::Fixed(1.0)
}
fn off_boresight() -> Param {
    Param::Range {
        min: 0.0,
        max: 60.0,
    }
}
fn full_circle() -> Param {
    Param::Range {
        min: 0.0,
        max: 360.0,
    }
}

impl SceneSpec {
    /// The radiometry readouts the poses of this kind cycle through: the scene's
    /// `readout`, else the camera's.
    pub fn readouts(&self, camera: &Camera) -> Vec<RadiometryReadout> {
        self.readout
            .as_ref()
            .map_or_else(|| vec![camera.readout], OneOrMany::values)
    }

    /// The detection scales of this kind (one entry, unused, for radiometry).
    pub fn scales(&self) -> Vec<DetectionScale> {
        match self.mode {
            Mode::Radiometry => vec![DetectionScale::Scale1],
            Mode::Detection => self
                .scale
                .values()
                .into_iter()
                .map(|s| match s {
                    2 => DetectionScale::Scale2,
                    3 => DetectionScale::Scale3,
                    _ => DetectionScale::Scale1,
                })
                .collect(),
        }
    }

    /// Mesh facet size, m.
    pub fn resolution(&self) -> f64 {
        self.resolution_m
            .unwrap_or_else(|| self.target.default_resolution_m())
    }

    pub(super) fn validate(&self, at: &str, earth_radius_km: f64) -> Result<(), String> {
        if self.count > 1_000_000 {
            return Err(format!(
                "{at}.count = {}: expected at most 1 000 000",
                self.count
            ));
        }
        let scales = self.scale.values();
        if scales.is_empty() || scales.iter().any(|s| !(1..=3).contains(s)) {
            return Err(format!(
                "{at}.scale = {scales:?}: expected 1, 2 or 3 (Table 5), or a non-empty list of them"
            ));
        }
        if self.material.values().is_empty() {
            return Err(format!(
                "{at}.material: expected at least one material case"
            ));
        }
        if self.illumination.values().is_empty() {
            return Err(format!(
                "{at}.illumination: expected at least one of \"sunlit\", \"eclipse\""
            ));
        }
        if let Some(r) = self.resolution_m {
            if !(r.is_finite() && (0.005..=1.0).contains(&r)) {
                return Err(format!(
                    "{at}.resolution_m = {r}: expected a facet size in [0.005, 1] m"
                ));
            }
        }
        self.range_m.validate(&format!("{at}.range_m"), 0.5, 1e5)?;
        if let Some(a) = self.attitude_deg {
            if a.iter().any(|v| !v.is_finite()) {
                return Err(format!(
                    "{at}.attitude_deg = {a:?}: expected three finite angles"
                ));
            }
        }
        if let Some(o) = self.offset_px {
            if o.iter().any(|v| !v.is_finite() || v.abs() > 1e4) {
                return Err(format!(
                    "{at}.offset_px = {o:?}: expected two finite pixel offsets"
                ));
            }
        }
        if !(0.0..=MAX_OFFSET_FRACTION).contains(&self.max_offset_fraction) {
            return Err(format!(
                "{at}.max_offset_fraction = {}: expected 0..={MAX_OFFSET_FRACTION} (above 1 the target is cut by the frame edge)",
                self.max_offset_fraction
            ));
        }
        if let Some(s) = self.sun_dir {
            if s.iter().any(|v| !v.is_finite()) || s.iter().all(|v| *v == 0.0) {
                return Err(format!(
                    "{at}.sun_dir = {s:?}: expected a finite non-zero vector"
                ));
            }
            if self.attitude_deg.is_none() {
                return Err(format!(
                    "{at}.sun_dir needs attitude_deg: a random attitude takes the Sun from its thermal state"
                ));
            }
        }
        if !(self.earth_distance_km.is_finite()
            && self.earth_distance_km > earth_radius_km * 1.0001)
        {
            return Err(format!(
                "{at}.earth_distance_km = {}: expected more than the Earth's radius ({earth_radius_km} km)",
                self.earth_distance_km
            ));
        }
        self.earth_off_boresight_deg.validate(
            &format!("{at}.earth_off_boresight_deg"),
            0.0,
            180.0,
        )?;
        self.earth_azimuth_deg
            .validate(&format!("{at}.earth_azimuth_deg"), -360.0, 720.0)?;
        self.gain.validate(&format!("{at}.gain"), 0.05, 20.0)?;
        self.noise_netd_factor
            .validate(&format!("{at}.noise_netd_factor"), 0.0, 100.0)?;
        if let Some(bits) = &self.bits {
            let b = bits.values();
            if b.is_empty() || b.iter().any(|v| !(1..=16).contains(v)) {
                return Err(format!(
                    "{at}.bits = {b:?}: expected a bit depth 1..=16 (e.g. 12, 14, 16) or a non-empty list of them"
                ));
            }
        }
        if self.readout.as_ref().is_some_and(|r| r.values().is_empty()) {
            return Err(format!(
                "{at}.readout = []: expected \"auto\", \"fixed-gain\" or a non-empty list of them"
            ));
        }
        if let Some(m) = self.moon {
            if !(0.0..=1.0).contains(&m.probability) {
                return Err(format!(
                    "{at}.moon.probability = {}: expected 0..=1",
                    m.probability
                ));
            }
        }
        if let Some(q) = &self.sequence {
            q.validate(at)?;
        }
        if !(0.0..=1.0).contains(&self.no_target_fraction) {
            return Err(format!(
                "{at}.no_target_fraction = {}: expected a share in 0..=1",
                self.no_target_fraction
            ));
        }
        Ok(())
    }
}
