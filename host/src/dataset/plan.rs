//! The plan of a dataset: every image's pose, scene kind, Earth geometry, thermal
//! state and seeds, derived from the dataset seed and the image index alone.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use crate::seed::splitmix64;
use crate::world::geom::{Rotation, Vec3, normalize, scale};
use crate::world::scene::{Illumination, Mode, SceneFile, TargetModel};
use crate::world::spacecraft::MaterialCase;

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
    /// Whether the target is rendered (false: a no-target frame,
    /// [`SceneSpec::no_target_fraction`](crate::world::scene::SceneSpec::no_target_fraction)).
    pub has_target: bool,
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
    pub(super) fn mesh_key(&self) -> (TargetModel, MaterialCase, u64) {
        (self.target, self.material, self.resolution_bits)
    }

    /// Facet size, m.
    pub fn resolution_m(&self) -> f64 {
        f64::from_bits(self.resolution_bits)
    }

    pub(super) fn sun_body(&self) -> Option<Vec3> {
        (self.illumination == Illumination::Sunlit).then(|| self.sun_body_bits.map(f64::from_bits))
    }

    pub(super) fn earth_body(&self) -> Vec3 {
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

/// Which of a kind's `poses` have no target: the first ⌈`share` × `poses`⌉ of a
/// permutation of the pose indices drawn from the dataset seed and the kind's index
/// (its own stream, so the poses' other draws do not move).
fn no_target_poses(seed: u64, scene: usize, poses: usize, share: f64) -> Vec<bool> {
    let mut empty = vec![false; poses];
    if share <= 0.0 || poses == 0 {
        return empty;
    }
    let n = ((share * poses as f64).ceil() as usize).min(poses);
    let mut order: Vec<usize> = (0..poses).collect();
    let mut rng = rng_for(seed, 0x0E0E_0000 + scene as u64, 0);
    // Partial Fisher–Yates: the first n places are a uniform n-subset.
    for i in 0..n {
        let j = rng.gen_range(i..poses);
        order.swap(i, j);
    }
    for &p in &order[..n] {
        empty[p] = true;
    }
    empty
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
        let no_target = no_target_poses(seed, si, poses, spec.no_target_fraction);
        for (pose, &empty) in no_target.iter().enumerate() {
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
                    has_target: !empty,
                });
            }
        }
    }
    plans
}
