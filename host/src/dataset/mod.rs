//! Labelled datasets: a [`SceneFile`] becomes a plan of images (poses, Earth geometry,
//! thermal state, seeds), the shared pieces (meshes, thermal solutions, Earth maps) are
//! computed once, and the images render in parallel into a directory:
//!
//! - `NNNNNN.png`: 16-bit grayscale DN (the core's sensor model);
//! - `truth.csv`: `file,x0,y0,x1,y1` then metadata columns (DESIGN convention; the box is
//!   the tight box of the pixels whose target coverage is ≥ 0.5);
//! - `coco.json`: COCO detection labels (one category, `spacecraft`);
//! - `metadata.jsonl`: one JSON object per image (pose, mode, scale, material,
//!   illumination, Earth fraction, seeds, DN map, noise σ, target temperatures);
//! - `masks/NNNNNN.png` (optional): 8-bit target coverage, 255 = fully covered;
//! - `preview/NNNNNN.png` (optional): contrast-stretched 8-bit RGB with the truth box.
//!
//! Determinism: every image's parameters derive from the dataset seed and its index
//! alone, so the bytes do not depend on the thread count. Safety: each file is written
//! to a temporary name and renamed; finished images are journalled in `progress.jsonl`,
//! and the label files are written (atomically) only when all images are done, so a
//! stopped run leaves no label file describing missing images, and `--resume` continues
//! where it stopped.

use std::collections::{BTreeMap, HashMap};
use std::fs::{self, File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use indicatif::ProgressBar;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use tirroi_core::Roi;
use tirroi_core::sensor::{BandLut, BandRadiance, DetectionScale};

use crate::imaging::image_io::{self, FrameBuf};
use crate::imaging::overlay;
use crate::imaging::render::{
    self, EarthView, Readout, RenderInput, RenderStats, Rendered, TargetView,
};
use crate::progress;
use crate::seed::splitmix64;
use crate::world::constants::EARTH_DISTANCE_M;
use crate::world::earth::{EarthMap, OlrGrid};
use crate::world::geom::{Rotation, Vec3, normalize, scale};
use crate::world::scene::{EarthSource, Illumination, Mode, SceneFile, TargetModel};
use crate::world::spacecraft::{
    MaterialCase, Mesh, ThermalEnvironment, cube_cylinder, solve_steady_state, tango,
};

/// Everything that fixes one image.
#[derive(Debug, Clone, PartialEq)]
pub struct ImagePlan {
    /// Index in the dataset (file `NNNNNN.png`).
    pub index: usize,
    /// Index of the scene kind in the file.
    pub scene: usize,
    /// Pose index within the scene kind (detection: shared by its scales).
    pub pose: usize,
    /// Mode.
    pub mode: Mode,
    /// Detection scale (1..=3), `None` in radiometry.
    pub scale: Option<u8>,
    /// Target and its mesh resolution.
    pub thermal: ThermalKey,
    /// Camera–target centre distance, m.
    pub range_m: f64,
    /// Target centre's image offset from the frame centre, px.
    pub offset_px: [f64; 2],
    /// Body → camera rotation.
    pub body_to_camera: Rotation,
    /// Direction to the Sun in the camera frame (`None` in eclipse).
    pub sun_dir_camera: Option<Vec3>,
    /// Direction to the Earth's centre in the camera frame.
    pub earth_dir_camera: Vec3,
    /// Camera–Earth-centre distance, m.
    pub earth_distance_m: f64,
    /// Whether the Earth is rendered.
    pub earth_rendered: bool,
    /// Camera frame → Earth-fixed frame.
    pub camera_to_earth: Rotation,
    /// Which daily Earth map.
    pub earth_day: usize,
    /// Noise seed (`None`: noise off).
    pub noise_seed: Option<u64>,
}

/// Identifies a thermal solution: target, material, resolution, illumination and the
/// Sun and Earth directions in the body frame (f64 bit patterns, so it hashes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ThermalKey {
    /// Target model.
    pub target: TargetModel,
    /// Table 3 case (Tango: `Mono`, unused).
    pub material: MaterialCase,
    /// Facet size, m (bits of the f64).
    pub resolution_bits: u64,
    /// Sunlit or eclipse.
    pub illumination: Illumination,
    /// Sun direction in the body frame (bits), zero in eclipse.
    pub sun_body_bits: [u64; 3],
    /// Earth direction in the body frame (bits).
    pub earth_body_bits: [u64; 3],
}

impl ThermalKey {
    fn mesh_key(&self) -> (TargetModel, MaterialCase, u64) {
        (self.target, self.material, self.resolution_bits)
    }

    /// Facet size, m.
    pub fn resolution_m(&self) -> f64 {
        f64::from_bits(self.resolution_bits)
    }

    fn sun_body(&self) -> Option<Vec3> {
        (self.illumination == Illumination::Sunlit).then(|| self.sun_body_bits.map(f64::from_bits))
    }

    fn earth_body(&self) -> Vec3 {
        self.earth_body_bits.map(f64::from_bits)
    }
}

fn rng_for(seed: u64, stream: u64, index: u64) -> Pcg64 {
    Pcg64::seed_from_u64(splitmix64(splitmix64(seed ^ splitmix64(stream)) ^ index))
}

/// A direction uniform on the unit sphere.
fn random_direction(rng: &mut Pcg64) -> Vec3 {
    let z: f64 = rng.gen_range(-1.0..1.0);
    let phi: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    let s = (1.0 - z * z).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

/// The Sun and Earth directions (body frame) of thermal state `k`: the Earth anywhere,
/// the Sun anywhere it is not hidden by the Earth's disc (sunlit).
fn pool_state(
    seed: u64,
    illumination: Illumination,
    k: usize,
    disc_cos: f64,
) -> (Option<Vec3>, Vec3) {
    let mut rng = rng_for(seed, 0x7E57, k as u64);
    let earth = random_direction(&mut rng);
    let sun = match illumination {
        Illumination::Eclipse => None,
        Illumination::Sunlit => loop {
            let s = random_direction(&mut rng);
            if crate::world::geom::dot(s, earth) < disc_cos {
                break Some(s);
            }
        },
    };
    (sun, earth)
}

/// The plan of every image of `file`, in index order.
pub fn plan(file: &SceneFile) -> Vec<ImagePlan> {
    let seed = file.dataset.seed;
    let radius_m = file.earth_model.radius_km * 1e3;
    let mut plans = Vec::with_capacity(file.image_count());
    for (si, spec) in file.scenes.iter().enumerate() {
        let scales: Vec<Option<u8>> = match spec.mode {
            Mode::Radiometry => vec![None],
            Mode::Detection => spec.scale.values().into_iter().map(Some).collect(),
        };
        let materials = match spec.target {
            TargetModel::CubeCylinder => spec.material.values(),
            TargetModel::Tango => vec![MaterialCase::Mono],
        };
        let lights = spec.illumination.values();
        let poses = spec.count / scales.len();
        let earth_distance_m = spec.earth_distance_km * 1e3;
        let disc_cos = (1.0 - (radius_m / earth_distance_m).powi(2)).sqrt();
        for pose in 0..poses {
            let mut rng = rng_for(seed, si as u64 + 1, pose as u64);
            let combo = pose % (materials.len() * lights.len());
            let material = materials[combo % materials.len()];
            let illumination = lights[(combo / materials.len()) % lights.len()];
            let range_m = spec.range_m.sample(rng.r#gen());
            let fov_half = [
                file.camera.width as f64 / 2.0 * spec.max_offset_fraction,
                file.camera.height as f64 / 2.0 * spec.max_offset_fraction,
            ];
            let offset_px = spec.offset_px.unwrap_or_else(|| {
                [
                    rng.gen_range(-1.0..=1.0) * fov_half[0],
                    rng.gen_range(-1.0..=1.0) * fov_half[1],
                ]
            });
            let off = spec
                .earth_off_boresight_deg
                .sample(rng.r#gen())
                .to_radians();
            let az = spec.earth_azimuth_deg.sample(rng.r#gen()).to_radians();
            let earth_dir_camera = [off.sin() * az.cos(), off.sin() * az.sin(), off.cos()];
            let (body_to_camera, sun_body, earth_body) = match spec.attitude_deg {
                Some([yaw, pitch, roll]) => {
                    let r = Rotation::from_euler_zyx_deg(yaw, pitch, roll);
                    let sun_cam = normalize(spec.sun_dir.unwrap_or([-0.4, -0.5, -0.75]));
                    let sun =
                        (illumination == Illumination::Sunlit).then(|| r.apply_inverse(sun_cam));
                    (r, sun, r.apply_inverse(earth_dir_camera))
                }
                None => {
                    let k = rng.gen_range(0..file.dataset.thermal_states);
                    let (sun, earth) = pool_state(seed, illumination, k, disc_cos);
                    // Map the state's Earth direction onto the camera's, then turn freely
                    // about it: any such attitude shares the thermal state.
                    let spin = rng.gen_range(0.0..std::f64::consts::TAU);
                    let r = Rotation::about_axis(earth_dir_camera, spin)
                        .then(&Rotation::between(earth, earth_dir_camera));
                    (r, sun, earth)
                }
            };
            // The Earth's orientation: the sub-camera point and heading are random.
            let lat0 = rng.gen_range(-1.0f64..1.0).asin();
            let lon0 = rng.gen_range(0.0..std::f64::consts::TAU);
            let heading = rng.gen_range(0.0..std::f64::consts::TAU);
            let up = [lat0.cos() * lon0.cos(), lat0.cos() * lon0.sin(), lat0.sin()];
            let camera_to_earth = Rotation::about_axis(up, heading)
                .then(&Rotation::between(scale(earth_dir_camera, -1.0), up));
            let earth_day = rng.gen_range(0..file.earth_model.days);
            let thermal = ThermalKey {
                target: spec.target,
                material,
                resolution_bits: spec.resolution().to_bits(),
                illumination,
                sun_body_bits: sun_body.unwrap_or([0.0; 3]).map(f64::to_bits),
                earth_body_bits: earth_body.map(f64::to_bits),
            };
            for (k, &scale) in scales.iter().enumerate() {
                let index = plans.len();
                plans.push(ImagePlan {
                    index,
                    scene: si,
                    pose,
                    mode: spec.mode,
                    scale,
                    thermal,
                    range_m,
                    offset_px,
                    body_to_camera,
                    sun_dir_camera: sun_body.map(|s| body_to_camera.apply(s)),
                    earth_dir_camera,
                    earth_distance_m,
                    earth_rendered: spec.earth,
                    camera_to_earth,
                    earth_day,
                    noise_seed: spec.noise.then(|| {
                        splitmix64(splitmix64(seed ^ 0xA0A0) ^ (index as u64) ^ ((k as u64) << 48))
                    }),
                });
            }
        }
    }
    plans
}

/// A thermal solution with the numbers the labels report.
#[derive(Debug, Clone)]
pub struct ThermalState {
    /// Temperature per facet, K.
    pub temperature_k: Vec<f64>,
    /// Coldest and hottest facet, K.
    pub min_max_k: (f64, f64),
}

/// Shared, precomputed pieces of a dataset.
pub struct Library {
    /// Band radiance of the camera.
    pub band: BandRadiance,
    /// Its fast table.
    pub lut: BandLut,
    meshes: HashMap<(TargetModel, MaterialCase, u64), Arc<Mesh>>,
    thermal: HashMap<ThermalKey, Arc<ThermalState>>,
    earth: HashMap<(Illumination, usize), Arc<EarthMap>>,
    /// Seconds spent building the library: meshes, thermal solutions, Earth maps.
    pub build_s: [f64; 3],
}

/// Why a dataset could not be made.
#[derive(Debug)]
pub struct DatasetError(pub String);

impl std::fmt::Display for DatasetError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DatasetError {}

fn olr_grid(file: &SceneFile, day: usize) -> Result<OlrGrid, DatasetError> {
    match file.earth_model.source {
        EarthSource::Builtin => Ok(OlrGrid::builtin(
            splitmix64(file.dataset.seed ^ 0xEA27) ^ day as u64,
        )),
        EarthSource::Netcdf => load_netcdf(file),
    }
}

#[cfg(feature = "netcdf")]
fn load_netcdf(file: &SceneFile) -> Result<OlrGrid, DatasetError> {
    let m = &file.earth_model;
    let path = m.path.as_deref().unwrap_or(Path::new(""));
    OlrGrid::load_netcdf(path, &m.variable, m.time_index).map_err(|e| DatasetError(e.to_string()))
}

#[cfg(not(feature = "netcdf"))]
fn load_netcdf(_file: &SceneFile) -> Result<OlrGrid, DatasetError> {
    Err(DatasetError(
        "earth_model.source = \"netcdf\" needs tirroi built with `--features netcdf` (and the system libnetcdf); use source = \"builtin\" otherwise".into(),
    ))
}

impl Library {
    /// Builds the meshes, thermal solutions and Earth maps `plans` use, in parallel.
    ///
    /// # Errors
    /// [`DatasetError`] when an Earth source cannot be read or a thermal solve fails.
    pub fn build(file: &SceneFile, plans: &[ImagePlan]) -> Result<Library, DatasetError> {
        let band = BandRadiance::hayabusa2_tir();
        let lut = BandLut::new(&band);
        let t0 = Instant::now();
        let mut mesh_keys: Vec<_> = plans.iter().map(|p| p.thermal.mesh_key()).collect();
        mesh_keys.sort_by_key(|k| (k.0.label(), k.1.label(), k.2));
        mesh_keys.dedup();
        let meshes: HashMap<_, _> = mesh_keys
            .par_iter()
            .map(|&(t, m, res)| {
                let r = f64::from_bits(res);
                let mesh = match t {
                    TargetModel::CubeCylinder => cube_cylinder(m, r),
                    TargetModel::Tango => tango(r),
                };
                ((t, m, res), Arc::new(mesh))
            })
            .collect();
        let t1 = Instant::now();

        // Earth maps: one per (illumination, day); eclipse is the sunlit map scaled.
        let mut earth_keys: Vec<(Illumination, usize)> = plans
            .iter()
            .filter(|p| p.earth_rendered)
            .map(|p| (p.thermal.illumination, p.earth_day))
            .collect();
        earth_keys.sort_by_key(|k| (k.0.label(), k.1));
        earth_keys.dedup();
        let mut days: Vec<usize> = plans.iter().map(|p| p.earth_day).collect();
        days.sort_unstable();
        days.dedup();
        // Ordered by day: the thermal network below takes the first day's mean flux, and
        // a HashMap's per-process order would make that choice (and the bytes) vary.
        let grids: BTreeMap<usize, OlrGrid> = days
            .iter()
            .map(|&d| Ok((d, olr_grid(file, d)?)))
            .collect::<Result<_, DatasetError>>()?;
        let factor = file.earth_model.eclipse_factor;
        let earth: HashMap<_, _> = earth_keys
            .par_iter()
            .map(|&(ill, day)| {
                let grid = &grids[&day];
                let map = match ill {
                    Illumination::Sunlit => EarthMap::refine(grid, file.earth_model.mesh_deg, &lut),
                    Illumination::Eclipse => {
                        EarthMap::refine(&grid.scaled(factor), file.earth_model.mesh_deg, &lut)
                    }
                };
                map.map(|m| ((ill, day), Arc::new(m)))
                    .map_err(|e| DatasetError(format!("Earth map: {e}")))
            })
            .collect::<Result<_, _>>()?;
        let t2 = Instant::now();

        // Thermal solutions: the mean flux of the first day used heats the target.
        let olr_mean = grids
            .values()
            .next()
            .map_or(240.0, |g| g.area_weighted_mean_w_m2());
        let mut thermal_keys: Vec<ThermalKey> = plans.iter().map(|p| p.thermal).collect();
        thermal_keys.sort_by_key(|k| {
            (
                k.target.label(),
                k.material.label(),
                k.resolution_bits,
                k.illumination.label(),
                k.sun_body_bits,
                k.earth_body_bits,
            )
        });
        thermal_keys.dedup();
        let radius_m = file.earth_model.radius_km * 1e3;
        let distance_m = plans
            .first()
            .map_or(EARTH_DISTANCE_M, |p| p.earth_distance_m);
        let thermal: HashMap<_, _> = thermal_keys
            .par_iter()
            .map(|key| {
                let mesh = &meshes[&key.mesh_key()];
                let mut env = match key.sun_body() {
                    Some(s) => ThermalEnvironment::sunlit(s, key.earth_body()),
                    None => ThermalEnvironment::eclipse(key.earth_body()),
                };
                env.earth_radius_m = radius_m;
                env.earth_distance_m = distance_m;
                env.earth_olr_w_m2 = match key.illumination {
                    Illumination::Sunlit => olr_mean,
                    Illumination::Eclipse => olr_mean * f64::from(factor),
                };
                if let Some(s) = key.sun_body() {
                    env.sun_earth_cos = (-crate::world::geom::dot(s, key.earth_body())).max(0.0);
                }
                let sol = solve_steady_state(mesh, &env).map_err(|e| {
                    DatasetError(format!(
                        "thermal solution of {} ({}, {}): {e}",
                        key.target.label(),
                        key.material.label(),
                        key.illumination.label()
                    ))
                })?;
                let min_max_k = sol.min_max_k();
                Ok((
                    *key,
                    Arc::new(ThermalState {
                        temperature_k: sol.temperature_k,
                        min_max_k,
                    }),
                ))
            })
            .collect::<Result<_, DatasetError>>()?;
        let t3 = Instant::now();
        Ok(Library {
            band,
            lut,
            meshes,
            thermal,
            earth,
            build_s: [
                (t1 - t0).as_secs_f64(),
                (t3 - t2).as_secs_f64(),
                (t2 - t1).as_secs_f64(),
            ],
        })
    }

    /// Number of distinct meshes, thermal solutions and Earth maps.
    pub fn counts(&self) -> (usize, usize, usize) {
        (self.meshes.len(), self.thermal.len(), self.earth.len())
    }

    /// Renders one planned image.
    ///
    /// # Errors
    /// [`DatasetError`] naming the image when the renderer refuses it.
    pub fn render(
        &self,
        file: &SceneFile,
        plan: &ImagePlan,
    ) -> Result<(Rendered, Arc<ThermalState>), DatasetError> {
        let mesh = &self.meshes[&plan.thermal.mesh_key()];
        let thermal = self.thermal[&plan.thermal].clone();
        let f = file.camera.focal_px();
        let dir = normalize([plan.offset_px[0] / f, plan.offset_px[1] / f, 1.0]);
        let earth = if plan.earth_rendered {
            Some(EarthView {
                map: &self.earth[&(plan.thermal.illumination, plan.earth_day)],
                centre_m: scale(plan.earth_dir_camera, plan.earth_distance_m),
                radius_m: file.earth_model.radius_km * 1e3,
                camera_to_earth: plan.camera_to_earth,
            })
        } else {
            None
        };
        let input = RenderInput {
            camera: &file.camera,
            readout: match plan.scale {
                None => Readout::Radiometry,
                Some(2) => Readout::Detection(DetectionScale::Scale2),
                Some(3) => Readout::Detection(DetectionScale::Scale3),
                Some(_) => Readout::Detection(DetectionScale::Scale1),
            },
            target: Some(TargetView {
                mesh,
                temperature_k: &thermal.temperature_k,
                body_to_camera: plan.body_to_camera,
                centre_m: scale(dir, plan.range_m),
            }),
            earth,
            earth_distance_m: plan.earth_distance_m,
            noise_seed: plan.noise_seed,
            band: &self.band,
            lut: &self.lut,
        };
        let frame = render::render(&input)
            .map_err(|e| DatasetError(format!("image {}: {e}", plan.index)))?;
        Ok((frame, thermal))
    }
}

/// The labels and metadata of one image (a line of `metadata.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageRecord {
    /// Index.
    pub index: usize,
    /// PNG file name, relative to the dataset directory.
    pub file: String,
    /// Scene kind name.
    pub scene: String,
    /// Truth box [x0, y0, x1, y1) (all 0 when the target is not in the frame).
    pub bbox: [u16; 4],
    /// Pixels in the target mask (coverage ≥ 0.5).
    pub mask_px: usize,
    /// "radiometry" or "detection".
    pub mode: String,
    /// Table 5 scale (detection).
    pub scale: Option<u8>,
    /// Target model.
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
    /// Noise seed.
    pub noise_seed: Option<u64>,
    /// Coldest and hottest target facet, K.
    pub target_temperature_k: [f64; 2],
    /// Dataset seed.
    pub dataset_seed: u64,
}

/// Options of a dataset run.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// Also write `masks/`.
    pub masks: bool,
    /// Also write `preview/`.
    pub preview: bool,
    /// Skip images already journalled in `progress.jsonl`.
    pub resume: bool,
    /// Show a progress bar.
    pub progress: bool,
}

/// Totals of a dataset run.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Images rendered in this run.
    pub rendered: usize,
    /// Images skipped (resumed).
    pub skipped: usize,
    /// Wall-clock seconds: library build, rendering + writing, labels.
    pub wall_s: [f64; 3],
    /// Library build seconds per part: meshes, thermal, Earth maps.
    pub library_s: [f64; 3],
    /// Distinct meshes, thermal solutions and Earth maps.
    pub library_counts: (usize, usize, usize),
    /// Summed per-image CPU time per stage, s: target, Earth, expose, PNG encode + write.
    pub stage_cpu_s: [f64; 4],
}

fn atomic_write(path: &Path, bytes: &[u8]) -> Result<(), DatasetError> {
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

fn record(
    file: &SceneFile,
    plan: &ImagePlan,
    frame: &Rendered,
    thermal: &ThermalState,
) -> ImageRecord {
    let spec = &file.scenes[plan.scene];
    ImageRecord {
        index: plan.index,
        file: format!("{:06}.png", plan.index),
        scene: spec
            .name
            .clone()
            .unwrap_or_else(|| format!("scene-{}", plan.scene)),
        bbox: frame.truth.to_array(),
        mask_px: frame
            .coverage
            .iter()
            .filter(|&&c| c >= render::MASK_COVERAGE)
            .count(),
        mode: plan.mode.label().into(),
        scale: plan.scale,
        target: plan.thermal.target.label().into(),
        material: (plan.thermal.target == TargetModel::CubeCylinder)
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
        noise_seed: plan.noise_seed,
        target_temperature_k: [thermal.min_max_k.0, thermal.min_max_k.1],
        dataset_seed: file.dataset.seed,
    }
}

/// Writes one image's files; returns its record and the encode/write seconds.
fn write_image(
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
    let png = encode_png(
        &image_io::native_bytes(&frame.dn),
        w,
        h,
        image::ExtendedColorType::L16,
        &path,
    )?;
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
            bits: file.camera.bits,
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

/// Renders every image of `file` into `dir` with labels (module docs).
///
/// # Errors
/// [`DatasetError`] for unwritable outputs, bad Earth sources, or an image that cannot
/// be rendered (named).
pub fn write_dataset(
    file: &SceneFile,
    dir: &Path,
    options: &WriteOptions,
) -> Result<RunSummary, DatasetError> {
    let t0 = Instant::now();
    let io = |p: &Path, e: std::io::Error| DatasetError(format!("{}: {e}", p.display()));
    fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    for (on, sub) in [(options.masks, "masks"), (options.preview, "preview")] {
        if on {
            let p = dir.join(sub);
            fs::create_dir_all(&p).map_err(|e| io(&p, e))?;
        }
    }
    let plans = plan(file);
    let journal_path = dir.join("progress.jsonl");
    let mut done: BTreeMap<usize, ImageRecord> = BTreeMap::new();
    if options.resume && journal_path.exists() {
        let f = File::open(&journal_path).map_err(|e| io(&journal_path, e))?;
        for line in BufReader::new(f).lines().map_while(Result::ok) {
            if let Ok(rec) = serde_json::from_str::<ImageRecord>(&line) {
                if dir.join(&rec.file).exists() {
                    done.insert(rec.index, rec);
                }
            }
        }
    }
    let todo: Vec<&ImagePlan> = plans
        .iter()
        .filter(|p| !done.contains_key(&p.index))
        .collect();
    let library = Library::build(file, &plans)?;
    let t1 = Instant::now();

    let journal = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&journal_path)
        .map_err(|e| io(&journal_path, e))?;
    let journal = Mutex::new(journal);
    let bar = if options.progress {
        progress::bar(todo.len(), "images")
    } else {
        ProgressBar::hidden()
    };
    let results: Vec<Result<(ImageRecord, RenderStats, f64), DatasetError>> = todo
        .par_iter()
        .map(|plan| {
            let (frame, thermal) = library.render(file, plan)?;
            let (rec, write_s) = write_image(dir, file, plan, &frame, &thermal, options)?;
            let line = serde_json::to_string(&rec).map_err(|e| DatasetError(e.to_string()))?;
            {
                let mut j = journal
                    .lock()
                    .map_err(|_| DatasetError("journal lock".into()))?;
                writeln!(j, "{line}").map_err(|e| io(&journal_path, e))?;
            }
            bar.inc(1);
            Ok((rec, frame.stats, write_s))
        })
        .collect();
    bar.finish_and_clear();
    let mut summary = RunSummary {
        skipped: done.len(),
        library_s: library.build_s,
        library_counts: library.counts(),
        ..RunSummary::default()
    };
    for r in results {
        let (rec, stats, write_s) = r?;
        summary.rendered += 1;
        summary.stage_cpu_s[0] += stats.target_ns as f64 * 1e-9;
        summary.stage_cpu_s[1] += stats.earth_ns as f64 * 1e-9;
        summary.stage_cpu_s[2] += stats.expose_ns as f64 * 1e-9;
        summary.stage_cpu_s[3] += write_s;
        done.insert(rec.index, rec);
    }
    let t2 = Instant::now();
    write_labels(file, dir, done.values())?;
    fs::remove_file(&journal_path).map_err(|e| io(&journal_path, e))?;
    summary.wall_s = [
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        t2.elapsed().as_secs_f64(),
    ];
    Ok(summary)
}

/// Writes `truth.csv`, `coco.json` and `metadata.jsonl` (each atomically).
fn write_labels<'a>(
    file: &SceneFile,
    dir: &Path,
    records: impl Iterator<Item = &'a ImageRecord>,
) -> Result<(), DatasetError> {
    let mut csv = String::from(
        "file,x0,y0,x1,y1,mode,scale,target,material,illumination,range_m,earth_fraction,noise_seed\n",
    );
    let mut jsonl = String::new();
    let mut images = Vec::new();
    let mut annotations = Vec::new();
    for r in records {
        let [x0, y0, x1, y1] = r.bbox;
        csv.push_str(&format!(
            "{},{x0},{y0},{x1},{y1},{},{},{},{},{},{:.3},{:.4},{}\n",
            r.file,
            r.mode,
            r.scale.map_or(String::new(), |s| s.to_string()),
            r.target,
            r.material.as_deref().unwrap_or(""),
            r.illumination,
            r.range_m,
            r.earth_fraction,
            r.noise_seed.map_or(String::new(), |s| s.to_string()),
        ));
        jsonl.push_str(&serde_json::to_string(r).map_err(|e| DatasetError(e.to_string()))?);
        jsonl.push('\n');
        images.push(serde_json::json!({
            "id": r.index + 1,
            "file_name": r.file,
            "width": file.camera.width,
            "height": file.camera.height,
        }));
        let roi = Roi::new(x0, y0, x1, y1);
        if !roi.is_empty() {
            annotations.push(serde_json::json!({
                "id": r.index + 1,
                "image_id": r.index + 1,
                "category_id": 1,
                "bbox": [x0, y0, roi.width(), roi.height()],
                "area": r.mask_px,
                "iscrowd": 0,
            }));
        }
    }
    let coco = serde_json::json!({
        "info": {
            "description": format!("tirroi synthetic thermal-infrared dataset `{}`", file.dataset.name),
            "version": env!("CARGO_PKG_VERSION"),
        },
        "images": images,
        "annotations": annotations,
        "categories": [{"id": 1, "name": "spacecraft", "supercategory": "target"}],
    });
    let coco = serde_json::to_string(&coco).map_err(|e| DatasetError(e.to_string()))?;
    atomic_write(&dir.join("truth.csv"), csv.as_bytes())?;
    atomic_write(&dir.join("coco.json"), coco.as_bytes())?;
    atomic_write(&dir.join("metadata.jsonl"), jsonl.as_bytes())?;
    Ok(())
}

/// The output directory's label file, for callers that report it.
pub fn truth_path(dir: &Path) -> PathBuf {
    dir.join("truth.csv")
}
