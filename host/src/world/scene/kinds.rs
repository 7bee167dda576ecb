//! The choices a scene kind makes: camera mode, target model, illumination, and
//! parameters drawn from a range or fixed.

use std::fmt;

use serde::{Deserialize, Serialize};

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
    /// A generic small satellite with two solar wings (2.9 m span; not in the paper):
    /// a shape the learned detector never saw in training
    /// ([`crate::world::spacecraft::models::winged_sat`]).
    WingedSat,
}

impl TargetModel {
    /// "cube-cylinder", "tango" or "winged-sat".
    pub fn label(&self) -> &'static str {
        match self {
            TargetModel::CubeCylinder => "cube-cylinder",
            TargetModel::Tango => "tango",
            TargetModel::WingedSat => "winged-sat",
        }
    }

    /// Default facet edge length of the mesh, m: fine enough that a facet spans a few
    /// pixels at the closest range (a pixel is 13 mm at 15 m).
    pub fn default_resolution_m(&self) -> f64 {
        match self {
            TargetModel::CubeCylinder => 0.05,
            TargetModel::Tango => 0.05,
            TargetModel::WingedSat => 0.05,
        }
    }

    /// Radius of a ball about the body origin (the target's centre) that lies inside
    /// the target, m: its projection lies inside the silhouette at any attitude, which
    /// is what keeps an edge-cut target in view. Cube + cylinder: 0.25 m (the origin is
    /// the centre of the joint face; the Ø 0.5 m cylinder and the 1 m cube hold the
    /// ball). Tango: 0.14 m (the 0.295 m bus, the origin within 3 mm of its mid-plane).
    /// Winged satellite: 0.29 m (the 0.6 × 0.6 × 0.7 m bus, the origin 40 mm below its
    /// centre, 0.30 m from its walls).
    pub fn inner_half_size_m(&self) -> f64 {
        match self {
            TargetModel::CubeCylinder => 0.25,
            TargetModel::Tango => 0.14,
            TargetModel::WingedSat => 0.29,
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

/// How the dataset's target temperatures are computed (`dataset.thermal`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThermalModel {
    /// Steady state for a random Sun and Earth direction (eclipse: the Earth's
    /// infrared alone, the coldest possible state).
    #[default]
    Steady,
    /// The periodic state on the reference orbit (Earth-pointing attitude, Sun in the
    /// orbit plane), sampled at times along it: eclipse states at times since eclipse
    /// entry, sunlit states along the sunlit arc (see
    /// [`crate::world::spacecraft::thermal`]).
    Transient,
}

impl ThermalModel {
    /// "steady" or "transient".
    pub fn label(&self) -> &'static str {
        match self {
            ThermalModel::Steady => "steady",
            ThermalModel::Transient => "transient",
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

    pub(super) fn validate(&self, field: &str, lo: f64, hi: f64) -> Result<(), String> {
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

/// Whether the Moon may appear in the field of view (a background disc, [`crate::world::moon`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MoonSpec {
    /// Probability that a pose has the Moon in its field, 0..=1.
    pub probability: f64,
}

/// An approach sequence: each pose of the kind becomes `frames` consecutive images
/// (per detection scale) of one encounter, the chaser closing in on the target while it
/// drifts across the image, turns, and the Earth slides below. Every frame of a sequence
/// shares the pose's target, material, illumination, thermal state, Earth day, gain,
/// bit depth, readout and Moon; its own noise. Each quantity below is drawn once per
/// sequence and reached linearly over it (frame `k` of `n` at `k / (n − 1)`). The
/// temperatures stay the first frame's: a sequence spans seconds to minutes, far below
/// a spacecraft's thermal time constants (hours), so a turning target keeps its
/// temperature map while its faces turn (`docs/scenes.md` § Sequences).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceSpec {
    /// Frames per sequence, 2..=10 000.
    pub frames: usize,
    /// Camera–target distance at the last frame, m (0.5..=100 000); the first frame's is
    /// the scene's `range_m`. Omitted: the range stays.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_end_m: Option<Param>,
    /// How far the target's centre moves across the image over the sequence, px
    /// (0..=10 000), in a direction drawn per sequence (turned back on an axis where it
    /// would leave the scene's `max_offset_fraction` of the frame). Default 0.
    #[serde(default = "zero_param")]
    pub drift_px: Param,
    /// How far the target turns over the sequence, degrees (0..=3 600), about an axis
    /// drawn per sequence. Default 0.
    #[serde(default = "zero_param")]
    pub spin_deg: Param,
    /// How far the ground below moves over the sequence, degrees of the Earth's central
    /// angle (0..=180; an orbit at 500 km covers about 0.064° per second), in a direction
    /// drawn per sequence. Default 0.
    #[serde(default = "zero_param")]
    pub earth_drift_deg: Param,
}

fn zero_param() -> Param {
    Param::Fixed(0.0)
}

/// Most frames in one sequence.
pub const MAX_SEQUENCE_FRAMES: usize = 10_000;

impl SequenceSpec {
    pub(super) fn validate(&self, at: &str) -> Result<(), String> {
        if !(2..=MAX_SEQUENCE_FRAMES).contains(&self.frames) {
            return Err(format!(
                "{at}.sequence.frames = {}: expected 2..={MAX_SEQUENCE_FRAMES} frames per sequence",
                self.frames
            ));
        }
        if let Some(r) = self.range_end_m {
            r.validate(&format!("{at}.sequence.range_end_m"), 0.5, 1e5)?;
        }
        self.drift_px
            .validate(&format!("{at}.sequence.drift_px"), 0.0, 1e4)?;
        self.spin_deg
            .validate(&format!("{at}.sequence.spin_deg"), 0.0, 3600.0)?;
        self.earth_drift_deg
            .validate(&format!("{at}.sequence.earth_drift_deg"), 0.0, 180.0)
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
