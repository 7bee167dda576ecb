//! Scenes and datasets as data: the TOML description `tirroi render --config FILE` reads
//! and the built-in presets are written in.
//!
//! A file holds a camera (Table 4 by default), the Earth model, dataset settings and one
//! or more `[[scene]]` kinds. Each scene kind renders `count` images; a numeric field is
//! a fixed value (`range_m = 30.0`) or a uniform range (`range_m = { min = 15.0, max =
//! 50.0 }`), a categorical field is one value or a list the images cycle through
//! (`material = ["mono", "multi-1", "multi-2"]`). Unknown keys are errors, and every
//! error names the file, line, field and the expected form.
//!
//! ```toml
//! [dataset]
//! name = "example"
//! seed = 7
//!
//! [[scene]]
//! count = 6
//! mode = "detection"            # or "radiometry"
//! scale = [1, 2, 3]             # Table 5; every pose is rendered at each scale
//! target = "cube-cylinder"      # or "tango"
//! material = "mono"             # Table 3: "mono", "multi-1", "multi-2"
//! range_m = { min = 15.0, max = 50.0 }
//! illumination = ["sunlit", "eclipse"]
//! earth_off_boresight_deg = 30.0
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};
use tirroi_core::sensor::DetectionScale;
use tirroi_core::sensor::noise::{DEFAULT_FLICKER_CORRELATION_PX, TIR_NETD_K};

use crate::world::constants::{EARTH_DISTANCE_M, EARTH_RADIUS_M};
use crate::world::earth::{ECLIPSE_FLUX_FACTOR, EarthMap};
use crate::world::spacecraft::MaterialCase;

/// The camera of Table 4 (Hayabusa2 TIR) and its read-out.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Camera {
    /// Focal length, mm (Table 4: 42.2).
    pub focal_length_mm: f64,
    /// Pixel pitch, µm (Table 4: 37).
    pub pixel_pitch_um: f64,
    /// Columns, 1..=328 (Table 4: 328).
    pub width: usize,
    /// Rows, 1..=248 (Table 4: 248).
    pub height: usize,
    /// Bits per DN, 1..=16 (default 14).
    pub bits: u8,
    /// Noise-equivalent temperature difference the noise is scaled to, K (0.4, the TIR's).
    pub netd_k: f64,
    /// Scene temperature at which the NETD holds, K (300).
    pub netd_reference_k: f64,
    /// Correlation length of the 1/f noise map, pixels (4).
    pub flicker_correlation_px: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            focal_length_mm: 42.2,
            pixel_pitch_um: 37.0,
            width: FRAME_WIDTH,
            height: FRAME_HEIGHT,
            bits: 14,
            netd_k: TIR_NETD_K,
            netd_reference_k: 300.0,
            flicker_correlation_px: DEFAULT_FLICKER_CORRELATION_PX,
        }
    }
}

impl Camera {
    /// Focal length in pixels (42.2 mm / 37 µm = 1 140.5 px).
    pub fn focal_px(&self) -> f64 {
        self.focal_length_mm * 1e3 / self.pixel_pitch_um
    }

    /// Full field of view (horizontal, vertical), degrees (16.4 × 12.4 for Table 4, which
    /// rounds them to 16 × 12).
    pub fn fov_deg(&self) -> (f64, f64) {
        let f = self.focal_px();
        let full = |n: usize| 2.0 * (n as f64 / 2.0 / f).atan().to_degrees();
        (full(self.width), full(self.height))
    }

    /// Instantaneous field of view of one pixel, rad (0.877 mrad).
    pub fn ifov_rad(&self) -> f64 {
        1.0 / self.focal_px()
    }

    fn validate(&self) -> Result<(), String> {
        let positive = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("camera.{name} = {v}: expected a finite number > 0"))
            }
        };
        positive("focal_length_mm", self.focal_length_mm)?;
        positive("pixel_pitch_um", self.pixel_pitch_um)?;
        positive("netd_reference_k", self.netd_reference_k)?;
        if !(self.netd_k.is_finite() && self.netd_k >= 0.0) {
            return Err(format!(
                "camera.netd_k = {}: expected a number >= 0",
                self.netd_k
            ));
        }
        if !(self.flicker_correlation_px.is_finite() && self.flicker_correlation_px >= 0.0) {
            return Err(format!(
                "camera.flicker_correlation_px = {}: expected a number >= 0",
                self.flicker_correlation_px
            ));
        }
        if !(1..=FRAME_WIDTH).contains(&self.width) || !(1..=FRAME_HEIGHT).contains(&self.height) {
            return Err(format!(
                "camera.width × height = {} × {}: expected at most {FRAME_WIDTH} × {FRAME_HEIGHT} (the core's frame)",
                self.width, self.height
            ));
        }
        if !(1..=16).contains(&self.bits) {
            return Err(format!("camera.bits = {}: expected 1..=16", self.bits));
        }
        Ok(())
    }
}

/// Camera mode (Section 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// Radiometry: DN = a·F + b with F = D·q_fc (Eqs. 5–7), auto-ranged per frame (Eq. 17).
    Radiometry,
    /// Detection: DN = a·q_fc + b on a fixed scale of Table 5 (Eq. 9).
    Detection,
}

impl Mode {
    /// "radiometry" or "detection".
    pub fn label(&self) -> &'static str {
        match self {
            Mode::Radiometry => "radiometry",
            Mode::Detection => "detection",
        }
    }
}

/// Which spacecraft is the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TargetModel {
    /// The paper's simplified target: a cube with a cylinder (Section 4.1).
    CubeCylinder,
    /// A Tango-like satellite (PRISMA, Section 5).
    Tango,
}

impl TargetModel {
    /// "cube-cylinder" or "tango".
    pub fn label(&self) -> &'static str {
        match self {
            TargetModel::CubeCylinder => "cube-cylinder",
            TargetModel::Tango => "tango",
        }
    }

    /// Default facet edge length of the mesh, m: fine enough that a facet spans a few
    /// pixels at the closest range (a pixel is 13 mm at 15 m).
    pub fn default_resolution_m(&self) -> f64 {
        match self {
            TargetModel::CubeCylinder => 0.05,
            TargetModel::Tango => 0.05,
        }
    }
}

/// Whether the Sun lights the target and the Earth (Section 3.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Illumination {
    /// Sunlit: solar, albedo and Earth IR heat the target; the Earth map as measured.
    Sunlit,
    /// Eclipse: Earth IR only; the Earth's flux scaled by the diurnal factor.
    Eclipse,
}

impl Illumination {
    /// "sunlit" or "eclipse".
    pub fn label(&self) -> &'static str {
        match self {
            Illumination::Sunlit => "sunlit",
            Illumination::Eclipse => "eclipse",
        }
    }
}

/// A number fixed, or drawn uniformly from `[min, max]` per image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a number, or a table { min = <number>, max = <number> }"
)]
pub enum Param {
    /// The same value for every image.
    Fixed(f64),
    /// Uniform in `[min, max]`.
    Range {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
}

impl Param {
    /// The value for a uniform variate `u` in [0, 1).
    pub fn sample(&self, u: f64) -> f64 {
        match *self {
            Param::Fixed(v) => v,
            Param::Range { min, max } => min + (max - min) * u,
        }
    }

    /// The smallest and largest value it can take.
    pub fn bounds(&self) -> (f64, f64) {
        match *self {
            Param::Fixed(v) => (v, v),
            Param::Range { min, max } => (min, max),
        }
    }

    fn validate(&self, field: &str, lo: f64, hi: f64) -> Result<(), String> {
        let (a, b) = self.bounds();
        if !(a.is_finite() && b.is_finite() && a <= b && a >= lo && b <= hi) {
            return Err(format!(
                "{field} = {self}: expected a value (or min <= max) within [{lo}, {hi}]"
            ));
        }
        Ok(())
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Param::Fixed(v) => write!(f, "{v}"),
            Param::Range { min, max } => write!(f, "{{ min = {min}, max = {max} }}"),
        }
    }
}

/// One value, or a list that consecutive poses cycle through.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged, expecting = "not an accepted value")]
pub enum OneOrMany<T> {
    /// One value.
    One(T),
    /// Values taken in turn.
    Many(Vec<T>),
}

impl<T: Copy> OneOrMany<T> {
    /// The values as a slice-like list.
    pub fn values(&self) -> Vec<T> {
        match self {
            OneOrMany::One(v) => vec![*v],
            OneOrMany::Many(v) => v.clone(),
        }
    }
}

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
        }
    }
}

impl EarthModel {
    fn validate(&self) -> Result<(), String> {
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
    /// pick one of these steady-state solutions and a camera view consistent with it.
    pub thermal_states: usize,
}

impl Default for DatasetSettings {
    fn default() -> Self {
        DatasetSettings {
            name: "custom".into(),
            seed: 1,
            thermal_states: 12,
        }
    }
}

/// One kind of scene: `count` images sharing these settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Label of this kind (default "scene-N").
    #[serde(default)]
    pub name: Option<String>,
    /// Images of this kind (detection: a multiple of the number of scales).
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
    /// Random offsets stay within this fraction of the half-frame (0..=1, default 0.6).
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

    fn validate(&self, at: &str, earth_radius_km: f64) -> Result<(), String> {
        if self.count == 0 {
            return Err(format!("{at}.count = 0: expected at least 1 image"));
        }
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
        if self.mode == Mode::Detection && self.count % scales.len() != 0 {
            return Err(format!(
                "{at}.count = {}: expected a multiple of the {} scales (each pose is rendered at every scale)",
                self.count,
                scales.len()
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
        if !(0.0..=1.0).contains(&self.max_offset_fraction) {
            return Err(format!(
                "{at}.max_offset_fraction = {}: expected 0..=1",
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
        Ok(())
    }
}

/// A scene/dataset description: what a TOML file or a preset holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Dataset-wide settings.
    #[serde(default)]
    pub dataset: DatasetSettings,
    /// The camera.
    #[serde(default)]
    pub camera: Camera,
    /// The Earth model.
    #[serde(default)]
    pub earth_model: EarthModel,
    /// The scene kinds, `[[scene]]` tables.
    #[serde(rename = "scene")]
    pub scenes: Vec<SceneSpec>,
}

/// A scene file that could not be used: the file, the line (when known) and what was
/// expected. `Display` is one line.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file (or `preset:NAME`).
    pub source: String,
    /// 1-based line and column, when the parser knows them.
    pub line_col: Option<(usize, usize)>,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line_col {
            Some((l, c)) => write!(f, "{}:{l}:{c}: {}", self.source, self.message),
            None => write!(f, "{}: {}", self.source, self.message),
        }
    }
}

impl std::error::Error for SceneError {}

/// The built-in presets: name, description, TOML.
pub const PRESETS: [(&str, &str, &str); 3] = [
    (
        "paper",
        "Section 4.1: 12 000 cube+cylinder images, radiometry (3 material cases) and detection (Scales 1-3), close 15-50 m and far 340-440 m, sunlit and eclipse",
        include_str!("../../presets/paper.toml"),
    ),
    (
        "tango",
        "Section 5: 1 000 radiometry images of a Tango-like satellite at close range, sunlit and eclipse",
        include_str!("../../presets/tango.toml"),
    ),
    (
        "quick",
        "24 images across every scene kind (both modes, all material cases and scales, both targets) for a first look",
        include_str!("../../presets/quick.toml"),
    ),
];

impl SceneFile {
    /// Parses and validates a TOML description; `source` names it in errors.
    ///
    /// # Errors
    /// [`SceneError`] with the line and field for syntax errors, unknown keys, wrong
    /// types and out-of-range values.
    pub fn parse(text: &str, source: &str) -> Result<SceneFile, SceneError> {
        let file: SceneFile = toml::from_str(text).map_err(|e| {
            let at = e.span().map(|s| s.start);
            SceneError {
                source: source.to_string(),
                line_col: at.map(|a| line_col(text, a)),
                message: explain(e.message().trim(), at.and_then(|a| key_at(text, a))),
            }
        })?;
        file.validate().map_err(|message| SceneError {
            source: source.to_string(),
            line_col: None,
            message,
        })?;
        Ok(file)
    }

    /// Reads and parses a TOML file; a relative NetCDF path is resolved against the
    /// file's directory.
    ///
    /// # Errors
    /// [`SceneError`] when the file cannot be read or is invalid.
    pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
        let source = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            source: source.clone(),
            line_col: None,
            message: format!("cannot read: {e}"),
        })?;
        let mut file = SceneFile::parse(&text, &source)?;
        if let (Some(p), Some(dir)) = (file.earth_model.path.as_mut(), path.parent()) {
            if p.is_relative() {
                *p = dir.join(&*p);
            }
        }
        Ok(file)
    }

    /// A built-in preset by name.
    ///
    /// # Errors
    /// [`SceneError`] naming the presets when `name` is not one.
    pub fn preset(name: &str) -> Result<SceneFile, SceneError> {
        let (_, _, text) =
            PRESETS
                .iter()
                .find(|(n, _, _)| *n == name)
                .ok_or_else(|| SceneError {
                    source: format!("preset {name}"),
                    line_col: None,
                    message: format!(
                        "no such preset; expected one of {}",
                        PRESETS.map(|p| p.0).join(", ")
                    ),
                })?;
        SceneFile::parse(text, &format!("preset:{name}"))
    }

    /// Spreads `total` images over the scene kinds in proportion to their counts, each
    /// rounded to whole poses (detection: multiples of its scales) and at least one
    /// pose; the result can differ from `total` by the rounding.
    ///
    /// # Errors
    /// [`SceneError`] for a total of 0.
    pub fn rescale_count(&mut self, total: usize) -> Result<(), SceneError> {
        if total == 0 {
            return Err(SceneError {
                source: "--count".into(),
                line_col: None,
                message: "0 images: expected at least 1".into(),
            });
        }
        let old = self.image_count().max(1) as f64;
        for s in &mut self.scenes {
            let per_pose = match s.mode {
                Mode::Radiometry => 1,
                Mode::Detection => s.scale.values().len().max(1),
            };
            let share = total as f64 * s.count as f64 / old;
            let poses = ((share / per_pose as f64).round() as usize).max(1);
            s.count = poses * per_pose;
        }
        Ok(())
    }

    /// Total images over all scene kinds.
    pub fn image_count(&self) -> usize {
        self.scenes.iter().map(|s| s.count).sum()
    }

    fn validate(&self) -> Result<(), String> {
        self.camera.validate()?;
        self.earth_model.validate()?;
        if self.scenes.is_empty() {
            return Err("no [[scene]] table: expected at least one scene kind".into());
        }
        if !(1..=1024).contains(&self.dataset.thermal_states) {
            return Err(format!(
                "dataset.thermal_states = {}: expected 1..=1024",
                self.dataset.thermal_states
            ));
        }
        for (i, s) in self.scenes.iter().enumerate() {
            s.validate(&format!("scene[{i}]"), self.earth_model.radius_km)?;
        }
        if self.image_count() > 10_000_000 {
            return Err(format!(
                "{} images in total: expected at most 10 000 000",
                self.image_count()
            ));
        }
        Ok(())
    }
}

/// The key of the `key = value` line holding byte `offset`, if any.
fn key_at(text: &str, offset: usize) -> Option<&str> {
    let start = text[..offset.min(text.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?;
    let (key, _) = line.split_once('=')?;
    let key = key.trim();
    (!key.is_empty() && !key.starts_with('[')).then_some(key)
}

/// The parser's message, with the field named and the accepted values spelled out.
fn explain(message: &str, key: Option<&str>) -> String {
    let message = message.replace('\n', " ");
    let Some(key) = key else {
        return message;
    };
    let accepted = match key {
        "mode" => Some("\"radiometry\" or \"detection\""),
        "target" => Some("\"cube-cylinder\" or \"tango\""),
        "material" => Some("\"mono\", \"multi-1\", \"multi-2\", or a list of them"),
        "illumination" => Some("\"sunlit\", \"eclipse\", or a list of them"),
        "scale" => Some("1, 2, 3, or a list of them"),
        "source" => Some("\"builtin\" or \"netcdf\""),
        _ => None,
    };
    match accepted {
        Some(a) if !message.contains(a) => format!("`{key}`: {message}; expected {a}"),
        _ if message.contains(&format!("`{key}`")) => message,
        _ => format!("`{key}`: {message}"),
    }
}

/// 1-based line and column of byte `offset` in `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table4_camera() {
        let c = Camera::default();
        assert!((c.focal_px() - 1140.54).abs() < 0.01);
        let (h, v) = c.fov_deg();
        assert!(
            (h - 16.36).abs() < 0.01 && (v - 12.41).abs() < 0.01,
            "{h} {v}"
        );
        assert!((c.ifov_rad() - 8.768e-4).abs() < 1e-6);
    }

    #[test]
    fn presets_parse() {
        for (name, _, _) in PRESETS {
            let f = SceneFile::preset(name).unwrap();
            assert!(f.image_count() > 0);
        }
        assert_eq!(SceneFile::preset("paper").unwrap().image_count(), 12_000);
        assert_eq!(SceneFile::preset("tango").unwrap().image_count(), 1_000);
        assert!(SceneFile::preset("nope").is_err());
        let mut paper = SceneFile::preset("paper").unwrap();
        paper.rescale_count(120).unwrap();
        assert_eq!(paper.image_count(), 120);
        assert!(paper.scenes.iter().all(|s| s.count == 30));
        paper.rescale_count(1).unwrap();
        assert_eq!(paper.image_count(), 1 + 1 + 3 + 3);
    }

    #[test]
    fn errors_name_line_and_field() {
        let e = SceneFile::parse("[[scene]]\nrange_m = 20.0\nrnage = 3\n", "x.toml").unwrap_err();
        assert_eq!(e.line_col.map(|l| l.0), Some(3), "{e}");
        assert!(e.to_string().contains("rnage"), "{e}");
        let e = SceneFile::parse("[[scene]]\nrange_m = \"far\"\n", "x.toml").unwrap_err();
        assert!(e.to_string().contains("x.toml:2:"), "{e}");
        assert!(e.to_string().contains("a number, or a table"), "{e}");
        assert!(e.to_string().contains("`range_m`"), "{e}");
        let e =
            SceneFile::parse("[[scene]]\nrange_m = { min = 50.0, max = 15.0 }\n", "x").unwrap_err();
        assert!(e.to_string().contains("scene[0].range_m"), "{e}");
        let e =
            SceneFile::parse("[[scene]]\nrange_m = 20.0\nmaterial = \"gold\"\n", "x").unwrap_err();
        assert!(e.to_string().contains("x:3:"), "{e}");
        assert!(e.to_string().contains("`material`"), "{e}");
        assert!(e.to_string().contains("\"multi-1\""), "{e}");
        let e = SceneFile::parse(
            "[[scene]]\nrange_m = 20.0\nmode = \"detection\"\nscale = [1, 2]\ncount = 3\n",
            "x",
        )
        .unwrap_err();
        assert!(e.to_string().contains("multiple of the 2 scales"), "{e}");
        let e = SceneFile::parse("[camera]\nwidth = 640\n[[scene]]\nrange_m = 20.0\n", "x")
            .unwrap_err();
        assert!(e.to_string().contains("camera.width"), "{e}");
        assert!(SceneFile::parse("", "x").is_err());
    }
}
