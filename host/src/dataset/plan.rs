//! The plan of a dataset: every image's pose, scene kind, Earth geometry, thermal
//! state and seeds, derived from the dataset seed and the image index alone.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use crate::seed::splitmix64;
use crate::world::constants::EARTH_DISTANCE_M;
use crate::world::geom::{Rotation, Vec3, norm, normalize, scale};
use crate::world::scene::{
    Illumination, Mode, RadiometryReadout, SceneFile, SequenceSpec, TargetModel, ThermalModel,
};
use crate::world::spacecraft::MaterialCase;
use crate::world::spacecraft::thermal::Orbit;

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
    /// Factor on the DN map's gain (scene `gain`, 1 by default).
    pub gain_factor: f64,
    /// Factor on the camera's NETD for the noise (scene `noise_netd_factor`, 1 by default).
    pub netd_factor: f64,
    /// Bit depth of the DN map (scene `bits`, else the camera's).
    pub bits: u8,
    /// Radiometry DN map of this pose (scene `readout`, else the camera's; cycled by
    /// pose); unused in detection mode.
    pub readout: RadiometryReadout,
    /// The Moon, when it is in the field of view.
    pub moon: Option<MoonPlan>,
    /// Whether the target is rendered (false: a no-target frame,
    /// [`SceneSpec::no_target_fraction`](crate::world::scene::SceneSpec::no_target_fraction)).
    pub has_target: bool,
    /// The image's place in an approach sequence (scene `sequence`), `None` outside one.
    pub sequence: Option<SequenceFrame>,
}

/// Where an image sits in an approach sequence
/// ([`SequenceSpec`](crate::world::scene::SequenceSpec)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SequenceFrame {
    /// The sequence: 0, 1, … over the dataset in image order.
    pub id: usize,
    /// The frame within it: 0 (the first) to `frames` − 1.
    pub frame: usize,
}

/// How one pose of a sequence moves over it: each quantity reached linearly at the
/// last frame (drawn once per sequence, [`sequence_motion`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct SequenceMotion {
    /// Frames in the sequence (≥ 2).
    frames: usize,
    /// Range at the last frame, m.
    range_end_m: f64,
    /// The target centre's image motion over the sequence, px.
    drift_px: [f64; 2],
    /// The target's turn over the sequence: axis (camera frame) and angle, rad.
    spin: (Vec3, f64),
    /// The ground's motion over the sequence: axis (Earth-fixed) and angle, rad.
    earth_turn: (Vec3, f64),
}

/// What moves over a sequence: range, m; the target centre's offset, px; body → camera;
/// camera → Earth-fixed.
type MovingPose = (f64, [f64; 2], Rotation, Rotation);

impl SequenceMotion {
    /// Frame `k`'s pose from the first frame's `first`: range and offset moved and the
    /// target's and the ground's turns applied by `k / (frames − 1)` of the way (the
    /// offset before any pull back into view).
    fn pose_at(&self, k: usize, first: MovingPose) -> MovingPose {
        let f = k as f64 / (self.frames - 1).max(1) as f64;
        let (range_m, offset_px, body_to_camera, camera_to_earth) = first;
        let turn = Rotation::about_axis(self.spin.0, self.spin.1 * f);
        let ground = Rotation::about_axis(self.earth_turn.0, self.earth_turn.1 * f);
        (
            range_m + (self.range_end_m - range_m) * f,
            [
                offset_px[0] + self.drift_px[0] * f,
                offset_px[1] + self.drift_px[1] * f,
            ],
            turn.then(&body_to_camera),
            ground.then(&camera_to_earth),
        )
    }
}

/// The motion of one sequence, drawn from `rng` after the pose's own draws: the range
/// at its end, the drift (its direction turned back on an axis where the end would lie
/// beyond `limit_px` of the frame centre), the spin axis and the ground's direction
/// (perpendicular to the sub-camera point).
fn sequence_motion(
    rng: &mut Pcg64,
    q: &SequenceSpec,
    range_m: f64,
    offset_px: [f64; 2],
    limit_px: [f64; 2],
    up_earth: Vec3,
) -> SequenceMotion {
    let range_end_m = q.range_end_m.map_or(range_m, |r| r.sample(rng.r#gen()));
    let length = q.drift_px.sample(rng.r#gen());
    let heading: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    let mut drift_px = [length * heading.cos(), length * heading.sin()];
    for ((d, &o), &lim) in drift_px.iter_mut().zip(&offset_px).zip(&limit_px) {
        if (o + *d).abs() > lim {
            *d = -*d;
        }
    }
    let spin = (
        random_direction(rng),
        q.spin_deg.sample(rng.r#gen()).to_radians(),
    );
    let side = random_direction(rng);
    let mut axis = crate::world::geom::cross(up_earth, side);
    if norm(axis) < 1e-9 {
        // `side` along the sub-camera point: any axis perpendicular to it.
        let helper = if up_earth[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        axis = crate::world::geom::cross(up_earth, helper);
    }
    let earth_turn = (
        normalize(axis),
        q.earth_drift_deg.sample(rng.r#gen()).to_radians(),
    );
    SequenceMotion {
        frames: q.frames,
        range_end_m,
        drift_px,
        spin,
        earth_turn,
    }
}

/// Where the Moon is and where its Sun is, camera frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoonPlan {
    /// Unit direction to the Moon's centre.
    pub dir_camera: Vec3,
    /// Unit direction to the Sun (the same from the camera and the Moon): the scene's
    /// Sun when sunlit; in eclipse the Sun is behind the Earth, so the direction to the
    /// Earth's centre.
    pub sun_dir_camera: Vec3,
}

/// How far into the frame an edge-cut target still reaches, px: random offsets beyond
/// the frame (`max_offset_fraction` > 1) are pulled back until a disc of the target's
/// inner half-size reaches this far in (or, when that disc is smaller, until the
/// centre is this far minus the disc radius inside the edge).
pub const EDGE_CUT_KEEP_PX: f64 = 2.0;

/// `offset` (px from the frame centre) pulled back so that the disc of radius
/// `inner_px` about it reaches [`EDGE_CUT_KEEP_PX`] into the frame of half-size
/// `half` (the nearest such point; unchanged when it already does).
pub fn keep_in_view(offset: [f64; 2], half: [f64; 2], inner_px: f64) -> [f64; 2] {
    let limit = inner_px - EDGE_CUT_KEEP_PX;
    if limit < 0.0 {
        // The centre itself must be -limit inside the edges.
        let c = |v: f64, h: f64| {
            let m = (h + limit).max(0.0);
            v.clamp(-m, m)
        };
        return [c(offset[0], half[0]), c(offset[1], half[1])];
    }
    let p = [
        offset[0].clamp(-half[0], half[0]),
        offset[1].clamp(-half[1], half[1]),
    ];
    let v = [offset[0] - p[0], offset[1] - p[1]];
    let d = v[0].hypot(v[1]);
    if d <= limit {
        offset
    } else {
        [p[0] + v[0] * limit / d, p[1] + v[1] * limit / d]
    }
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
    /// Transient state: time since eclipse entry on the dataset's orbit, s (bits);
    /// `None`: the steady state.
    pub orbit_time_bits: Option<u64>,
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

    /// Time since eclipse entry of a transient state, s (`None`: steady state).
    pub fn orbit_time_s(&self) -> Option<f64> {
        self.orbit_time_bits.map(f64::from_bits)
    }
}

/// The orbit of a file's transient thermal states: circular at the first scene's
/// camera–Earth distance (the distance the library's view factors use, 10 871 km by
/// default), the file's Earth radius, the Sun in the orbit plane (β = 0).
pub fn thermal_orbit(file: &SceneFile) -> Orbit {
    Orbit {
        radius_m: file
            .scenes
            .first()
            .map_or(EARTH_DISTANCE_M, |s| s.earth_distance_km * 1e3),
        earth_radius_m: file.earth_model.radius_km * 1e3,
        beta_rad: 0.0,
    }
}

/// Time since eclipse entry of transient state `k` of `states`: eclipse states spread
/// evenly over the shadow, (k + ½)/states × its duration; sunlit ones over the sunlit
/// arc after it.
fn orbit_state_time_s(orbit: &Orbit, illumination: Illumination, k: usize, states: usize) -> f64 {
    let (p, e) = (orbit.period_s(), orbit.eclipse_duration_s());
    let f = (k as f64 + 0.5) / states.max(1) as f64;
    match illumination {
        Illumination::Eclipse => f * e,
        Illumination::Sunlit => e + f * (p - e),
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
    let orbit = thermal_orbit(file);
    let transient = file.dataset.thermal == ThermalModel::Transient;
    let mut plans = Vec::with_capacity(file.image_count());
    // Sequences planned so far (the next one's id).
    let mut sequences = 0usize;
    for (si, spec) in file.scenes.iter().enumerate() {
        let scales: Vec<Option<u8>> = match spec.mode {
            Mode::Radiometry => vec![None],
            Mode::Detection => spec.scale.values().into_iter().map(Some).collect(),
        };
        let materials = match spec.target {
            TargetModel::CubeCylinder => spec.material.values(),
            // Their own materials: one case, not the Table 3 ones.
            TargetModel::Tango | TargetModel::WingedSat => vec![MaterialCase::Mono],
        };
        let lights = spec.illumination.values();
        // Whole poses, and a last partial one (its first `count mod scales` scales, or
        // frames of a sequence) when the count is not a multiple of them.
        let frames = spec.sequence.map_or(1, |q| q.frames);
        let poses = spec.count.div_ceil(scales.len() * frames);
        let kind_start = plans.len();
        let earth_distance_m = spec.earth_distance_km * 1e3;
        let disc_cos = (1.0 - (radius_m / earth_distance_m).powi(2)).sqrt();
        let focal_px = file.camera.focal_px();
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
            // An edge-cut target's centre pulled back so that part of it stays in view.
            let in_view = |o: [f64; 2], range_m: f64| {
                if spec.max_offset_fraction > 1.0 {
                    let half = [
                        file.camera.width as f64 / 2.0,
                        file.camera.height as f64 / 2.0,
                    ];
                    let inner_px = spec.target.inner_half_size_m() / range_m * focal_px;
                    keep_in_view(o, half, inner_px)
                } else {
                    o
                }
            };
            let offset_px = spec.offset_px.unwrap_or_else(|| {
                let o = [
                    rng.gen_range(-1.0..=1.0) * fov_half[0],
                    rng.gen_range(-1.0..=1.0) * fov_half[1],
                ];
                in_view(o, range_m)
            });
            let off = spec
                .earth_off_boresight_deg
                .sample(rng.r#gen())
                .to_radians();
            let az = spec.earth_azimuth_deg.sample(rng.r#gen()).to_radians();
            let earth_dir_camera = [off.sin() * az.cos(), off.sin() * az.sin(), off.cos()];
            let mut orbit_time_s = None;
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
                    let (sun, earth) = if transient {
                        let t = orbit_state_time_s(
                            &orbit,
                            illumination,
                            k,
                            file.dataset.thermal_states,
                        );
                        let g = orbit.geometry(t);
                        orbit_time_s = Some(g.time_s);
                        // The shadow's ends are grid times: a state sits strictly inside
                        // its arc, so its geometry agrees with its illumination.
                        (g.sun_dir_body, g.earth_dir_body)
                    } else {
                        pool_state(seed, illumination, k, disc_cos)
                    };
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
            // The variety knobs draw after every draw above, so those keep their values.
            let gain_factor = spec.gain.sample(rng.r#gen());
            let netd_factor = spec.noise_netd_factor.sample(rng.r#gen());
            let bits = spec.bits.as_ref().map_or(file.camera.bits, |b| {
                let b = b.values();
                b[pose % b.len()]
            });
            let readout = {
                let r = spec.readouts(&file.camera);
                r[pose % r.len()]
            };
            let moon = spec.moon.and_then(|m| {
                let u: f64 = rng.r#gen();
                let x = rng.gen_range(0.0..file.camera.width as f64);
                let y = rng.gen_range(0.0..file.camera.height as f64);
                (u < m.probability).then(|| MoonPlan {
                    dir_camera: normalize([
                        (x - file.camera.width as f64 / 2.0) / focal_px,
                        (y - file.camera.height as f64 / 2.0) / focal_px,
                        1.0,
                    ]),
                    sun_dir_camera: match sun_body {
                        Some(s) => normalize(body_to_camera.apply(s)),
                        None => earth_dir_camera,
                    },
                })
            });
            // A sequence's motion draws last: the other draws keep their values.
            let motion = spec
                .sequence
                .map(|q| sequence_motion(&mut rng, &q, range_m, offset_px, fov_half, up));
            let thermal = ThermalKey {
                target: spec.target,
                material,
                resolution_bits: spec.resolution().to_bits(),
                illumination,
                sun_body_bits: sun_body.unwrap_or([0.0; 3]).map(f64::to_bits),
                earth_body_bits: earth_body.map(f64::to_bits),
                orbit_time_bits: orbit_time_s.map(f64::to_bits),
            };
            let sun_dir_camera = sun_body.map(|s| body_to_camera.apply(s));
            for (k, &scale) in scales.iter().enumerate() {
                let sequence_start = plans.len();
                for frame in 0..frames {
                    if plans.len() - kind_start == spec.count {
                        break;
                    }
                    let index = plans.len();
                    // Frame `frame` of the sequence (the pose itself outside one); the Sun
                    // stays where it is in the camera frame (the target turns, not the
                    // chaser) and the temperatures stay the first frame's.
                    let first = (range_m, offset_px, body_to_camera, camera_to_earth);
                    let (range_m, offset_px, body_to_camera, camera_to_earth) = match motion {
                        None => first,
                        Some(m) => {
                            let (r, o, body, ground) = m.pose_at(frame, first);
                            (r, in_view(o, r), body, ground)
                        }
                    };
                    let sequence = motion.map(|_| SequenceFrame {
                        id: sequences,
                        frame,
                    });
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
                        sun_dir_camera,
                        earth_dir_camera,
                        earth_distance_m,
                        earth_rendered: spec.earth,
                        camera_to_earth,
                        earth_day,
                        noise_seed: spec.noise.then(|| {
                            splitmix64(
                                splitmix64(seed ^ 0xA0A0) ^ (index as u64) ^ ((k as u64) << 48),
                            )
                        }),
                        gain_factor,
                        netd_factor,
                        bits,
                        readout,
                        moon,
                        has_target: !empty,
                        sequence,
                    });
                }
                // A sequence cut to nothing by the count takes no id.
                if motion.is_some() && plans.len() > sequence_start {
                    sequences += 1;
                }
            }
        }
    }
    plans
}

#[cfg(test)]
mod tests {
    use super::*;

    const TRANSIENT: &str = r#"
[dataset]
thermal_states = 4
thermal = "transient"

[[scene]]
count = 8
illumination = ["sunlit", "eclipse"]
range_m = 30.0
"#;

    const SEQUENCES: &str = r#"
[dataset]
seed = 11

[[scene]]
count = 12
range_m = 40.0
earth = false
sequence = { frames = 5, range_end_m = 20.0, drift_px = 40.0, spin_deg = 60.0, earth_drift_deg = 4.0 }
"#;

    /// The angle of a rotation, rad.
    fn angle(r: &Rotation) -> f64 {
        let m = &r.0;
        ((m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0)
            .clamp(-1.0, 1.0)
            .acos()
    }

    /// Sequences: `count` images in runs of `frames` (the last cut by the count), each
    /// frame numbered in its sequence; within one, the pose's draws are shared and range,
    /// place, the target's turn and the ground's move linearly to the drawn ends; each
    /// frame has its own noise. A file without `sequence` plans no sequence.
    #[test]
    fn sequences_share_the_pose_and_move_linearly() {
        let file = SceneFile::parse(SEQUENCES, "sequences.toml").unwrap();
        let plans = plan(&file);
        assert_eq!(plans.len(), 12);
        let ids: Vec<(usize, usize)> = plans
            .iter()
            .map(|p| p.sequence.map(|q| (q.id, q.frame)).unwrap())
            .collect();
        let want: Vec<(usize, usize)> = (0..12).map(|i| (i / 5, i % 5)).collect();
        assert_eq!(ids, want);
        for run in plans.chunks(5) {
            let first = &run[0];
            for (k, p) in run.iter().enumerate() {
                let f = k as f64 / 4.0;
                assert_eq!(p.thermal, first.thermal);
                assert_eq!(
                    (p.pose, p.earth_day, p.bits, p.gain_factor, p.has_target),
                    (
                        first.pose,
                        first.earth_day,
                        first.bits,
                        first.gain_factor,
                        first.has_target
                    )
                );
                assert_eq!(p.sun_dir_camera, first.sun_dir_camera);
                assert_eq!(p.earth_dir_camera, first.earth_dir_camera);
                assert!(
                    (p.range_m - (40.0 - 20.0 * f)).abs() < 1e-9,
                    "{}",
                    p.range_m
                );
                let d = [
                    p.offset_px[0] - first.offset_px[0],
                    p.offset_px[1] - first.offset_px[1],
                ];
                assert!((d[0].hypot(d[1]) - 40.0 * f).abs() < 1e-9, "{d:?}");
                let turn = p.body_to_camera.then(&first.body_to_camera.inverse());
                assert!((angle(&turn) - 60f64.to_radians() * f).abs() < 1e-9);
                // The sub-camera point moves along a great circle by the ground's turn.
                let below =
                    |q: &ImagePlan| q.camera_to_earth.apply(scale(q.earth_dir_camera, -1.0));
                let cos = crate::world::geom::dot(below(p), below(first));
                assert!((cos.clamp(-1.0, 1.0).acos() - 4f64.to_radians() * f).abs() < 1e-9);
                if k > 0 {
                    assert_ne!(p.noise_seed, run[k - 1].noise_seed);
                }
            }
        }
        // Edge-cut targets drifting further than the frame is wide: every frame keeps
        // its target in view (each offset is its own `keep_in_view`).
        let far = SceneFile::parse(
            &SEQUENCES
                .replace("drift_px = 40.0", "drift_px = 400.0")
                .replace("earth = false", "earth = false\nmax_offset_fraction = 1.5"),
            "far.toml",
        )
        .unwrap();
        let focal_px = far.camera.focal_px();
        let half = [
            far.camera.width as f64 / 2.0,
            far.camera.height as f64 / 2.0,
        ];
        for p in plan(&far) {
            let inner = TargetModel::CubeCylinder.inner_half_size_m() / p.range_m * focal_px;
            assert_eq!(keep_in_view(p.offset_px, half, inner), p.offset_px, "{p:?}");
        }
        let single = SceneFile::parse(
            &SEQUENCES.replace(
                "sequence = { frames = 5, range_end_m = 20.0, drift_px = 40.0, spin_deg = 60.0, earth_drift_deg = 4.0 }",
                "",
            ),
            "single.toml",
        )
        .unwrap();
        assert!(plan(&single).iter().all(|p| p.sequence.is_none()));
        for (bad, field) in [
            ("frames = 1", "sequence.frames"),
            ("frames = 3, drift_px = -1.0", "sequence.drift_px"),
            (
                "frames = 3, earth_drift_deg = 200.0",
                "sequence.earth_drift_deg",
            ),
            ("frames = 3, range_end_m = 0.1", "sequence.range_end_m"),
        ] {
            let text = SEQUENCES.replace(
                "frames = 5, range_end_m = 20.0, drift_px = 40.0, spin_deg = 60.0, earth_drift_deg = 4.0",
                bad,
            );
            let e = SceneFile::parse(&text, "bad.toml").unwrap_err().to_string();
            assert!(e.contains(field), "{bad}: {e}");
        }
        let e = SceneFile::parse(
            &SEQUENCES.replace("frames = 5,", "frames = 5, speed = 1.0,"),
            "k.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("speed"), "{e}");
    }

    /// Transient states sit on the orbit: eclipse states inside the shadow (no Sun),
    /// sunlit ones after it, their Sun and Earth directions the orbit's at their time;
    /// steady files keep no orbit time.
    #[test]
    fn transient_states_follow_the_orbit() {
        let file = SceneFile::parse(TRANSIENT, "transient.toml").unwrap();
        assert_eq!(file.dataset.thermal, ThermalModel::Transient);
        let orbit = thermal_orbit(&file);
        let (p, e) = (orbit.period_s(), orbit.eclipse_duration_s());
        let plans = plan(&file);
        assert_eq!(plans.len(), 8);
        for pl in &plans {
            let t = pl.thermal.orbit_time_s().unwrap();
            let g = orbit.geometry(t);
            match pl.thermal.illumination {
                Illumination::Eclipse => {
                    assert!(t > 0.0 && t < e, "{t}");
                    assert!(pl.thermal.sun_body().is_none() && pl.sun_dir_camera.is_none());
                }
                Illumination::Sunlit => {
                    assert!(t > e && t < p, "{t}");
                    assert_eq!(pl.thermal.sun_body(), g.sun_dir_body);
                }
            }
            assert_eq!(pl.thermal.earth_body(), g.earth_dir_body);
            // The camera sees the Earth where the state has it.
            let e_cam = pl.body_to_camera.apply(g.earth_dir_body);
            let d = crate::world::geom::sub(e_cam, pl.earth_dir_camera);
            assert!(crate::world::geom::norm(d) < 1e-9);
        }
        let steady = SceneFile::parse(&TRANSIENT.replace("transient", "steady"), "s.toml").unwrap();
        assert!(
            plan(&steady)
                .iter()
                .all(|p| p.thermal.orbit_time_s().is_none())
        );
        let bad = SceneFile::parse(
            &TRANSIENT.replace("\"transient\"", "\"periodic\""),
            "b.toml",
        );
        let msg = bad.unwrap_err().to_string();
        assert!(msg.contains("\"steady\" or \"transient\""), "{msg}");
    }
}
