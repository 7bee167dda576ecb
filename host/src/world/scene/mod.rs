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
//! target = "cube-cylinder"      # or "tango", "winged-sat"
//! material = "mono"             # Table 3: "mono", "multi-1", "multi-2"
//! range_m = { min = 15.0, max = 50.0 }
//! illumination = ["sunlit", "eclipse"]
//! earth_off_boresight_deg = 30.0
//! # Variety (optional; omitted they change nothing): docs/scenes.md
//! gain = { min = 0.5, max = 2.0 }   # factor on the DN map's gain
//! noise_netd_factor = { min = 0.5, max = 3.0 }
//! bits = [12, 14, 16]
//! max_offset_fraction = 1.3         # > 1: targets cut by the frame edge
//! moon = { probability = 0.1 }
//! ```
//!
//! Opt-in camera realism (all off by default, which keeps today's frames):
//!
//! ```toml
//! [camera]
//! signature = "hayabusa2-dark"  # the real TIR's shading, column/row pattern, hot pixels
//! optics_psf = true             # Airy (F/1.4) over the pixel footprint, before the DN map
//! readout = "fixed-gain"        # radiometry: DN = a·F + b (real gain, 1024 DN pedestal)
//! ```

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

mod camera;
mod kinds;
mod spec;
#[cfg(test)]
mod tests;

pub use camera::{Camera, RadiometryReadout, ResponseName, SignatureKind};
pub use kinds::{
    Illumination, MAX_SEQUENCE_FRAMES, Mode, MoonSpec, OneOrMany, Param, SequenceSpec, TargetModel,
    ThermalModel,
};
pub use spec::{
    DEFAULT_TRUTH_COVERAGE, DatasetSettings, EarthModel, EarthSource, EarthTexture,
    MAX_CLOUD_TOP_TEXTURE_K, MAX_OFFSET_FRACTION, SceneSpec,
};

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
pub const PRESETS: [(&str, &str, &str); 7] = [
    (
        "paper",
        "Section 4.1: 12 000 cube+cylinder images, radiometry (3 material cases) and detection (Scales 1-3), close 15-50 m and far 340-440 m, sunlit and eclipse",
        include_str!("../../../presets/paper.toml"),
    ),
    (
        "tango",
        "Section 5: 1 000 radiometry images of a Tango-like satellite at close range, sunlit and eclipse",
        include_str!("../../../presets/tango.toml"),
    ),
    (
        "quick",
        "24 images across every scene kind (both modes, all material cases and scales, both targets) for a first look",
        include_str!("../../../presets/quick.toml"),
    ),
    (
        "realistic",
        "the paper's scene kinds in the world a flight detector meets: the real camera's signature, PSF and fixed-gain readout, a cloud-textured Earth, gain/noise/bit-depth variety, edge-cut and 3-12 px targets, the Moon, 10 % frames without a target",
        include_str!("../../../presets/realistic.toml"),
    ),
    (
        "realistic-tango",
        "the Tango case study in the realistic world (1 000 radiometry images, close range, 10 % without a target)",
        include_str!("../../../presets/realistic-tango.toml"),
    ),
    (
        "realistic-approach",
        "approach sequences in the realistic world (2 448 images: 102 sequences of 24 frames, range closing, the target drifting and turning, the ground sliding; 10 % without a target): a tracker's test",
        include_str!("../../../presets/realistic-approach.toml"),
    ),
    (
        "realistic-winged",
        "the realistic world's four scene kinds (1 200 images) with a target no detector was trained on: a small satellite with two solar wings",
        include_str!("../../../presets/realistic-winged.toml"),
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

    /// Spreads exactly `total` images over the scene kinds in proportion to their
    /// counts: each kind gets the floor of its share, and the images left over go one
    /// each to the kinds with the largest remainders (ties: the earlier kind) — the
    /// largest-remainder (Hamilton) apportionment, so no kind is off its share by a
    /// whole image. A kind may get 0 images (when `total` is below the number of
    /// kinds), and a detection kind may end on a partial pose ([`SceneSpec::count`]).
    /// A file whose counts already are `total` in proportion keeps them unchanged.
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
        let counts: Vec<usize> = self.scenes.iter().map(|s| s.count).collect();
        for (s, n) in self.scenes.iter_mut().zip(apportion(total, &counts)) {
            s.count = n;
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
        let t = self.dataset.truth_coverage;
        if !(t > 0.0 && t <= 1.0) {
            return Err(format!(
                "dataset.truth_coverage = {t}: expected a pixel coverage in (0, 1] (0.5: half covered)"
            ));
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
        if self.image_count() == 0 {
            return Err("every [[scene]] has count = 0: expected at least 1 image in total".into());
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

/// `total` split in proportion to `weights` by the largest-remainder method: the
/// parts sum to `total` exactly (all weights 0: equal weights).
pub fn apportion(total: usize, weights: &[usize]) -> Vec<usize> {
    let all_zero = weights.iter().all(|&w| w == 0);
    let w: Vec<u128> = weights
        .iter()
        .map(|&w| if all_zero { 1 } else { w as u128 })
        .collect();
    let sum: u128 = w.iter().sum::<u128>().max(1);
    // Integer arithmetic: share_i = total·w_i / sum, exact floor and remainder.
    let mut parts: Vec<usize> = w
        .iter()
        .map(|&wi| (total as u128 * wi / sum) as usize)
        .collect();
    let rem: Vec<u128> = w.iter().map(|&wi| total as u128 * wi % sum).collect();
    let left = total - parts.iter().sum::<usize>();
    let mut order: Vec<usize> = (0..w.len()).collect();
    order.sort_by(|&a, &b| rem[b].cmp(&rem[a]).then(a.cmp(&b)));
    for &i in order.iter().take(left) {
        parts[i] += 1;
    }
    parts
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
        "bits" => Some("a bit depth 1..=16, or a list of them"),
        "moon" => Some("a table { probability = <0..1> }"),
        "thermal" => Some("\"steady\" or \"transient\""),
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
