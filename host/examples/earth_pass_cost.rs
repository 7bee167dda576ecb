//! The textured Earth pass's cost per frame, for instruction counts without the
//! dataset library's minute of cloud set-up: a `texture = "clouds"` Earth whose cells
//! are built lazily, the camera's pixels behind an 8× longer lens (a 2° field, so a
//! few hundred cells; no limb, whose rays cross so many cells that building them would
//! take minutes under callgrind), three poses (nadir, 12° and 24° off boresight)
//! rendered once to build the cells they see, then `--frames N` (default
//! 3) more renders of the same poses in [`measured`], the only
//! function to count:
//!
//! ```text
//! cargo build --release -p tirroi-host --example earth_pass_cost
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*measured*' \
//!     target/release/examples/earth_pass_cost --frames 3
//! ```
//!
//! It prints the Earth rays cast and a hash of the frames' signal bits (so any change
//! of the pass's arithmetic shows as a changed hash).

use tirroi_core::sensor::{BandLut, BandRadiance};
use tirroi_host::imaging::render::{
    EarthView, Readout, RenderInput, Rendered, SensorEffects, render,
};
use tirroi_host::world::earth::{CloudField, EarthMap, OlrGrid};
use tirroi_host::world::geom::Rotation;
use tirroi_host::world::scene::Camera;

/// Camera–Earth-centre distance, m (the paper's 4 500 km altitude).
const DISTANCE_M: f64 = 10_871e3;
/// Earth radius, m.
const RADIUS_M: f64 = 6_371e3;
/// The poses' Earth-centre angles off the boresight, degrees.
const OFF_BORESIGHT_DEG: [f64; 3] = [0.0, 12.0, 24.0];
/// Focal length over the default camera's.
const FOCAL_LENGTH_FACTOR: f64 = 8.0;

fn input<'a>(
    camera: &'a Camera,
    earth: EarthView<'a>,
    band: &'a BandRadiance,
    lut: &'a BandLut,
) -> RenderInput<'a> {
    RenderInput {
        camera,
        readout: Readout::Radiometry,
        target: None,
        earth: Some(earth),
        earth_distance_m: DISTANCE_M,
        noise_seed: None,
        band,
        lut,
        gain_factor: 1.0,
        moon: None,
        sensor: SensorEffects::NONE,
    }
}

fn view(map: &EarthMap, off_deg: f64) -> EarthView<'_> {
    EarthView {
        map,
        centre_m: [
            0.0,
            DISTANCE_M * off_deg.to_radians().sin(),
            DISTANCE_M * off_deg.to_radians().cos(),
        ],
        radius_m: RADIUS_M,
        // Looking at the warm pool and its deep convection (longitude ~140°).
        camera_to_earth: Rotation::from_quaternion([0.766, 0.0, 0.0, 0.643]),
    }
}

/// The counted renders: `frames` frames cycling through the poses.
#[inline(never)]
fn measured(
    camera: &Camera,
    map: &EarthMap,
    band: &BandRadiance,
    lut: &BandLut,
    frames: usize,
) -> Result<Vec<Rendered>, String> {
    (0..frames)
        .map(|k| {
            let off = OFF_BORESIGHT_DEG[k % OFF_BORESIGHT_DEG.len()];
            render(&input(camera, view(map, off), band, lut)).map_err(|e| e.to_string())
        })
        .collect()
}

fn main() {
    let mut frames = 3usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match (a.as_str(), args.next().map(|v| v.parse::<usize>())) {
            ("--frames", Some(Ok(n))) => frames = n,
            _ => {
                eprintln!("usage: earth_pass_cost [--frames N]");
                std::process::exit(2);
            }
        }
    }
    let band = BandRadiance::hayabusa2_tir();
    let lut = BandLut::new(&band);
    let grid = OlrGrid::builtin(7);
    let map = EarthMap::refine(&grid, EarthMap::DEFAULT_MESH_DEG, &lut)
        .expect("built-in grid")
        // Shared, not `with_clouds`: that would fill every cell of the globe (a minute).
        .with_shared_clouds(std::sync::Arc::new(CloudField::new(&grid, 0, 7)), 1.0);
    // The camera's pixels with an 8× longer focal length (a 2° field): the per-ray work
    // is the same, and only a few hundred cells need building.
    let default = Camera::default();
    let camera = Camera {
        focal_length_mm: default.focal_length_mm * FOCAL_LENGTH_FACTOR,
        ..default
    };
    // Warm-up: builds every cell the poses see.
    if let Err(e) = measured(&camera, &map, &band, &lut, OFF_BORESIGHT_DEG.len()) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
    match measured(&camera, &map, &band, &lut, frames) {
        Ok(out) => {
            let rays: usize = out.iter().map(|r| r.stats.earth_rays).sum();
            // FNV-1a over the signals' bits: equal iff the frames are bit-identical
            // (up to a hash collision).
            let hash = out
                .iter()
                .flat_map(|r| r.signal.iter())
                .fold(0xcbf2_9ce4_8422_2325u64, |h, s| {
                    (h ^ u64::from(s.to_bits())).wrapping_mul(0x0100_0000_01b3)
                });
            println!("{frames} frames, {rays} Earth rays, signal hash {hash:016x}");
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
