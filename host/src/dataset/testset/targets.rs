//! The rendered targets composited into the real-data test sets: the renderer's own
//! spacecraft, thermal solutions and poses ([`TARGETS_TOML`], planned and built as a
//! dataset is, [`crate::dataset::plan`] and [`Library`]), rendered noise-free over deep
//! space in radiometry mode, so the frame's signal is the target's F (W m⁻²), coverage-
//! weighted on partial pixels, and zero elsewhere.

use tirroi_core::Roi;

use crate::dataset::{DatasetError, ImagePlan, Library, plan};
use crate::world::scene::{SceneFile, TargetModel};

/// The target family: the paper's cube + cylinder (three material cases) at close
/// range (15–50 m, cut by the frame edge sometimes) and far (130–525 m, 3–12 px), and
/// the Tango-like satellite at close range; sunlit and eclipse, steady thermal
/// states (4 per target, material and illumination), random attitudes; no Earth in view, no noise. The counts are
/// set per run ([`TargetRenders::new`]).
pub const TARGETS_TOML: &str = r#"
[dataset]
name = "testset-targets"
seed = 1
thermal_states = 4

[[scene]]
name = "close"
count = 1
mode = "radiometry"
target = "cube-cylinder"
material = ["mono", "multi-1", "multi-2"]
illumination = ["sunlit", "eclipse"]
range_m = { min = 15.0, max = 50.0 }
max_offset_fraction = 1.2
earth = false
noise = false

[[scene]]
name = "far"
count = 1
mode = "radiometry"
target = "cube-cylinder"
material = ["mono", "multi-1", "multi-2"]
illumination = ["sunlit", "eclipse"]
range_m = { min = 130.0, max = 525.0 }
resolution_m = 0.2
max_offset_fraction = 0.9
earth = false
noise = false

[[scene]]
name = "tango"
count = 1
mode = "radiometry"
target = "tango"
illumination = ["sunlit", "eclipse"]
range_m = { min = 15.0, max = 50.0 }
max_offset_fraction = 0.9
earth = false
noise = false
"#;

/// Shares of the target family's scene kinds (close, far, Tango), of the frames with a
/// target: close range is the paper's headline, far the hard small-target case.
pub const SCENE_SHARES: [f64; 3] = [0.45, 0.35, 0.2];

/// Salt of the target family's dataset seed (independent of the frames' other draws).
const TARGET_SEED_SALT: u64 = 0x7A26_0000_0000_0016;

/// One rendered target: its signal, coverage and labels.
#[derive(Debug, Clone)]
pub struct TargetRender {
    /// Target F per pixel, W m⁻² (coverage-weighted on partial pixels; 0 off the target).
    pub signal: Vec<f32>,
    /// Target coverage per pixel, 0..=1.
    pub coverage: Vec<f32>,
    /// Box of the pixels covered ≥ ½.
    pub truth: Roi,
    /// Box of the pixels covered > ¼.
    pub truth_quarter: Roi,
    /// Target model label.
    pub target: String,
    /// Material case (cube + cylinder).
    pub material: Option<String>,
    /// `sunlit` or `eclipse`.
    pub illumination: String,
    /// Camera–target distance, m.
    pub range_m: f64,
    /// Pixels covered ≥ ½.
    pub mask_px: usize,
}

/// The planned targets and the library that renders them.
pub struct TargetRenders {
    file: SceneFile,
    plans: Vec<ImagePlan>,
    library: Library,
}

impl TargetRenders {
    /// Plans `count` targets for the set of `seed` and builds their meshes and thermal
    /// solutions.
    ///
    /// # Errors
    /// [`DatasetError`] when the library cannot be built (a thermal solve fails).
    pub fn new(count: usize, seed: u64) -> Result<TargetRenders, DatasetError> {
        let mut file = SceneFile::parse(TARGETS_TOML, "testset targets")
            .map_err(|e| DatasetError(e.to_string()))?;
        file.dataset.seed = crate::seed::splitmix64(seed ^ TARGET_SEED_SALT);
        let n = count.max(1);
        let mut left = n;
        for (k, (scene, share)) in file.scenes.iter_mut().zip(SCENE_SHARES).enumerate() {
            let c = if k + 1 == SCENE_SHARES.len() {
                left
            } else {
                ((n as f64 * share).round() as usize).min(left)
            };
            scene.count = c.max(1);
            left -= c.min(left);
        }
        // Poses interleaved across the kinds, so any prefix mixes them.
        let mut by_kind: Vec<Vec<ImagePlan>> = vec![Vec::new(); file.scenes.len()];
        for p in plan(&file) {
            by_kind[p.scene].push(p);
        }
        let mut plans = Vec::with_capacity(n);
        let mut cursor = vec![0usize; by_kind.len()];
        let mut weights = [0.0f64; 3];
        while plans.len() < n {
            // The kind furthest below its share goes next.
            let k = (0..by_kind.len())
                .filter(|&k| cursor[k] < by_kind[k].len())
                .min_by(|&a, &b| {
                    let da = weights[a] / SCENE_SHARES[a];
                    let db = weights[b] / SCENE_SHARES[b];
                    da.total_cmp(&db)
                });
            let Some(k) = k else { break };
            plans.push(by_kind[k][cursor[k]].clone());
            cursor[k] += 1;
            weights[k] += 1.0;
        }
        let library = Library::build(&file, &plans)?;
        Ok(TargetRenders {
            file,
            plans,
            library,
        })
    }

    /// The camera's band radiance (the library's).
    pub fn library(&self) -> &Library {
        &self.library
    }

    /// The scene file the targets are planned from (camera and readouts).
    pub fn scene_file(&self) -> &SceneFile {
        &self.file
    }

    /// Renders target `k` (0..count).
    ///
    /// # Errors
    /// [`DatasetError`] naming the pose when the renderer refuses it, or `k` out of range.
    pub fn render(&self, k: usize) -> Result<TargetRender, DatasetError> {
        let plan = self.plans.get(k).ok_or_else(|| {
            DatasetError(format!("target {k}: only {} planned", self.plans.len()))
        })?;
        let (frame, _) = self.library.render(&self.file, plan)?;
        let mask_px = frame
            .coverage
            .iter()
            .filter(|&&c| c >= crate::imaging::render::MASK_COVERAGE)
            .count();
        Ok(TargetRender {
            signal: frame.signal,
            coverage: frame.coverage,
            truth: frame.truth,
            truth_quarter: frame.truth_quarter,
            target: plan.thermal.target.label().into(),
            material: (plan.thermal.target == TargetModel::CubeCylinder)
                .then(|| plan.thermal.material.label().to_string()),
            illumination: plan.thermal.illumination.label().into(),
            range_m: plan.range_m,
            mask_px,
        })
    }
}
