//! The shared pieces of a dataset, computed once: meshes, thermal solutions, OLR grids
//! and Earth maps.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;
use tirroi_core::sensor::{BandLut, BandRadiance, DetectionScale};

use super::DatasetError;
use super::plan::{ImagePlan, ThermalKey, thermal_orbit};
use crate::imaging::psf::OpticsPsf;
use crate::imaging::render::{
    self, EarthView, FixedGain, MoonView, Readout, RenderInput, Rendered, SensorEffects, TargetView,
};
use crate::imaging::signature::{Calibration, SensorSignature};
use crate::seed::splitmix64;
use crate::world::constants::EARTH_DISTANCE_M;
use crate::world::earth::{CloudField, EarthMap, OlrGrid};
use crate::world::geom::{normalize, scale};
use crate::world::scene::{
    Camera, EarthSource, EarthTexture, Illumination, RadiometryReadout, SceneFile, SignatureKind,
    TargetModel,
};
use crate::world::spacecraft::thermal::{TRANSIENT_STEP_S, facet_heat_capacities_j_k};
use crate::world::spacecraft::{
    MaterialCase, Mesh, ThermalEnvironment, ThermalNetwork, cube_cylinder, solve_steady_state,
    tango, winged_sat,
};

/// A thermal solution with the numbers the labels report.
#[derive(Debug, Clone)]
pub struct ThermalState {
    /// Temperature per facet, K.
    pub temperature_k: Vec<f64>,
    /// Coldest and hottest facet, K.
    pub min_max_k: (f64, f64),
    /// Transient state: time since eclipse entry on the orbit, s (`None`: steady).
    pub orbit_time_s: Option<f64>,
    /// Transient state: the orbit's time in shadow, s (`None`: steady).
    pub eclipse_duration_s: Option<f64>,
}

/// Shared, precomputed pieces of a dataset.
pub struct Library {
    /// Band radiance of the camera.
    pub band: BandRadiance,
    /// Its fast table.
    pub lut: BandLut,
    pub(super) meshes: HashMap<(TargetModel, MaterialCase, u64), Arc<Mesh>>,
    pub(super) thermal: HashMap<ThermalKey, Arc<ThermalState>>,
    pub(super) earth: HashMap<(Illumination, usize), Arc<EarthMap>>,
    /// Seconds spent building the library: meshes, thermal solutions, Earth maps.
    pub build_s: [f64; 3],
    /// The optics PSF when `[camera] optics_psf` is on.
    pub psf: Option<OpticsPsf>,
    /// A pool of [`SIGNATURE_POOL`] signature realisations when `[camera] signature`
    /// is not "none"; each image takes one by a hash of the dataset seed and its index.
    pub signature: Vec<SensorSignature>,
    /// The fixed-gain radiometry readout when a scene kind (or `[camera] readout`)
    /// reads out with it; each radiometry frame planned with
    /// [`RadiometryReadout::FixedGain`] uses it at its own bit depth.
    pub fixed_gain: Option<FixedGain>,
}

/// Salt of the per-image signature seed (so it is independent of the noise seed).
const SIGNATURE_SEED_SALT: u64 = 0x5167_0000_0000_0015;

/// Signature realisations made per dataset: one costs about 7 ms (328 × 248, release),
/// too slow per image at 150 frames/s, so images draw from a pool (64 realisations,
/// 21 MB at 328 × 248) made once in parallel.
pub const SIGNATURE_POOL: usize = 64;

/// The sensor-effect pieces of a camera: PSF, signature calibration, fixed-gain map.
type SensorPieces = (Option<OpticsPsf>, Vec<SensorSignature>, Option<FixedGain>);

fn sensor_pieces(file: &SceneFile) -> Result<SensorPieces, DatasetError> {
    let cam = &file.camera;
    let err = |e: String| DatasetError(format!("camera: {e}"));
    let psf = if cam.optics_psf {
        Some(OpticsPsf::hayabusa2_tir(cam.pixel_pitch_um).map_err(err)?)
    } else {
        None
    };
    let fixed_readout = file
        .scenes
        .iter()
        .any(|s| s.readouts(cam).contains(&RadiometryReadout::FixedGain));
    let needs_cal = cam.signature != SignatureKind::None || fixed_readout;
    let cal = if needs_cal {
        Some(Calibration::hayabusa2_tir().map_err(err)?)
    } else {
        None
    };
    let fixed = cal
        .as_ref()
        .filter(|_| fixed_readout)
        .map(Calibration::fixed_gain);
    let signature = match (&cal, cam.signature) {
        (Some(c), SignatureKind::Hayabusa2Dark) => (0..SIGNATURE_POOL as u64)
            .into_par_iter()
            .map(|k| {
                let seed = splitmix64(file.dataset.seed ^ SIGNATURE_SEED_SALT ^ k);
                c.realise(cam.width, cam.height, seed)
            })
            .collect(),
        _ => Vec::new(),
    };
    Ok((psf, signature, fixed))
}

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
    let path = m.path.as_deref().unwrap_or(std::path::Path::new(""));
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
        let response = file.camera.response;
        let band = BandRadiance::new(&response.to_core())
            .map_err(|e| DatasetError(format!("camera.response = \"{}\": {e}", response.name())))?;
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
                    TargetModel::WingedSat => winged_sat(r),
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
        // The cloud texture once per day, from the sunlit grid (filled in parallel
        // inside); the eclipse map of the day shares it with its temperatures ×
        // factor^¼ (the same clouds, each cell's flux × factor).
        let clouds: BTreeMap<usize, Arc<CloudField>> = match file.earth_model.texture {
            EarthTexture::Paper => BTreeMap::new(),
            EarthTexture::Clouds => {
                let mut cloud_days: Vec<usize> = earth_keys.iter().map(|k| k.1).collect();
                cloud_days.sort_unstable();
                cloud_days.dedup();
                cloud_days
                    .iter()
                    .map(|&day| {
                        let field = CloudField::new(&grids[&day], day as u64, file.dataset.seed)
                            .with_cloud_top_texture(file.earth_model.cloud_top_texture_k)
                            .with_regional_balance(file.earth_model.regional_balance_cells)
                            .with_cloud_fragments(file.earth_model.cloud_fragments);
                        field.fill();
                        (day, Arc::new(field))
                    })
                    .collect()
            }
        };
        let eclipse_t_scale = f64::from(factor).sqrt().sqrt();
        let earth: HashMap<_, _> = earth_keys
            .par_iter()
            .map(|&(ill, day)| {
                let grid = &grids[&day];
                let scaled;
                let grid = match ill {
                    Illumination::Sunlit => grid,
                    Illumination::Eclipse => {
                        scaled = grid.scaled(factor);
                        &scaled
                    }
                };
                let map = EarthMap::refine(grid, file.earth_model.mesh_deg, &lut).map(|m| {
                    match file.earth_model.texture {
                        EarthTexture::Paper => m,
                        // The same clouds by day and seed, whatever the illumination.
                        EarthTexture::Clouds => m.with_shared_clouds(
                            Arc::clone(&clouds[&day]),
                            match ill {
                                Illumination::Sunlit => 1.0,
                                Illumination::Eclipse => eclipse_t_scale,
                            },
                        ),
                    }
                });
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
                k.orbit_time_bits,
            )
        });
        thermal_keys.dedup();
        let (transient_keys, thermal_keys): (Vec<ThermalKey>, Vec<ThermalKey>) = thermal_keys
            .into_iter()
            .partition(|k| k.orbit_time_bits.is_some());
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
                        orbit_time_s: None,
                        eclipse_duration_s: None,
                    }),
                ))
            })
            .collect::<Result<_, DatasetError>>()?;
        let mut thermal = thermal;
        // Transient states: one periodic orbit per mesh, sampled at every time asked.
        let mut groups: BTreeMap<(&'static str, &'static str, u64), Vec<ThermalKey>> =
            BTreeMap::new();
        for key in transient_keys {
            groups
                .entry((
                    key.target.label(),
                    key.material.label(),
                    key.resolution_bits,
                ))
                .or_default()
                .push(key);
        }
        let orbit = thermal_orbit(file);
        let transient: Vec<Vec<(ThermalKey, Arc<ThermalState>)>> = groups
            .into_values()
            .collect::<Vec<_>>()
            .par_iter()
            .map(|keys| {
                let key0 = keys[0];
                let mesh = &meshes[&key0.mesh_key()];
                let what = || {
                    format!(
                        "transient thermal state of {} ({})",
                        key0.target.label(),
                        key0.material.label()
                    )
                };
                let net = ThermalNetwork::new(mesh)
                    .map_err(|e| DatasetError(format!("{}: {e}", what())))?;
                let capacity = facet_heat_capacities_j_k(mesh);
                let mut env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
                env.earth_radius_m = radius_m;
                env.earth_distance_m = distance_m;
                env.earth_olr_w_m2 = olr_mean;
                let times: Vec<f64> = keys.iter().filter_map(|k| k.orbit_time_s()).collect();
                let sol = net
                    .periodic_orbit(
                        &capacity,
                        &orbit,
                        &env,
                        olr_mean * f64::from(factor),
                        TRANSIENT_STEP_S,
                        &times,
                    )
                    .map_err(|e| DatasetError(format!("{}: {e}", what())))?;
                Ok(keys
                    .iter()
                    .zip(sol.states)
                    .map(|(k, state)| {
                        let min_max_k = state
                            .temperature_k
                            .iter()
                            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &t| {
                                (lo.min(t), hi.max(t))
                            });
                        (
                            *k,
                            Arc::new(ThermalState {
                                temperature_k: state.temperature_k,
                                min_max_k,
                                orbit_time_s: Some(state.geometry.time_s),
                                eclipse_duration_s: Some(sol.eclipse_duration_s),
                            }),
                        )
                    })
                    .collect())
            })
            .collect::<Result<_, DatasetError>>()?;
        thermal.extend(transient.into_iter().flatten());
        let t3 = Instant::now();
        let (psf, signature, fixed_gain) = sensor_pieces(file)?;
        Ok(Library {
            band,
            lut,
            psf,
            signature,
            fixed_gain,
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
        // The pose's bit depth and NETD (scene `bits`, `noise_netd_factor`).
        let camera = Camera {
            bits: plan.bits,
            netd_k: file.camera.netd_k * plan.netd_factor,
            ..file.camera
        };
        let realisation = (!self.signature.is_empty()).then(|| {
            let k = splitmix64(file.dataset.seed ^ SIGNATURE_SEED_SALT ^ plan.index as u64);
            &self.signature[(k % self.signature.len() as u64) as usize]
        });
        let input = RenderInput {
            camera: &camera,
            readout: match plan.scale {
                None => Readout::Radiometry,
                Some(2) => Readout::Detection(DetectionScale::Scale2),
                Some(3) => Readout::Detection(DetectionScale::Scale3),
                Some(_) => Readout::Detection(DetectionScale::Scale1),
            },
            target: plan.has_target.then(|| TargetView {
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
            gain_factor: plan.gain_factor,
            moon: plan.moon.map(|m| MoonView {
                dir_camera: m.dir_camera,
                sun_dir_camera: m.sun_dir_camera,
            }),
            sensor: SensorEffects {
                psf: self.psf.as_ref(),
                signature: realisation,
                fixed_gain: self
                    .fixed_gain
                    .filter(|_| plan.readout == RadiometryReadout::FixedGain),
            },
        };
        let err = |e: render::RenderError| DatasetError(format!("image {}: {e}", plan.index));
        let mut frame = render::render(&input).map_err(err)?;
        let t = std::time::Instant::now();
        frame.clutter = render::signal_to_clutter(&input, &frame).map_err(err)?;
        frame.stats.clutter_ns = t.elapsed().as_nanos() as u64;
        Ok((frame, thermal))
    }
}
