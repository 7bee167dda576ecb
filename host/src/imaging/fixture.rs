//! Procedural test frames: a bright two-part target over deep space or a textured,
//! Earth-like background, with Gaussian noise, and its exact box.
//!
//! These are *not* physically based (that is the renderer's job); they exist so that
//! benches, tests and the demo have realistic-looking 328×248 14-bit frames with known
//! labels: smooth multi-octave texture with a curved limb, a cube-and-cylinder-like
//! silhouette with shaded faces, and sensor-like noise. Deterministic for a seed.

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64;
use tirroi_core::Roi;
use tirroi_core::frame::{DEFAULT_BIT_DEPTH, FRAME_HEIGHT, FRAME_WIDTH};

use crate::imaging::image_io::FrameBuf;

/// What lies behind the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Background {
    /// Deep space: a flat, dark level.
    DeepSpace,
    /// An Earth-like disc filling the lower part of the frame, with cloud-like
    /// multi-octave texture, above deep space.
    Earth,
}

/// A procedural scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FixtureSpec {
    /// Background kind.
    pub background: Background,
    /// Box of the target's body (the cube); a narrower cylinder is attached to its
    /// right side, and the truth box covers both. An empty box renders a frame
    /// without a target (empty truth).
    pub body: Roi,
    /// Mean DN of the target's brightest face.
    pub target_dn: u16,
    /// Mean DN of the Earth texture.
    pub earth_dn: u16,
    /// Peak-to-peak amplitude of the Earth texture, in DN.
    pub texture_dn: u16,
    /// Standard deviation of the additive noise, in DN.
    pub noise_dn: f64,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for FixtureSpec {
    fn default() -> Self {
        FixtureSpec {
            background: Background::Earth,
            body: Roi::new(120, 80, 190, 150),
            target_dn: 11_000,
            earth_dn: 7_000,
            texture_dn: 5_000,
            noise_dn: 20.0,
            seed: 1,
        }
    }
}

/// A rendered fixture: the frame and the exact box of the target's pixels.
#[derive(Debug, Clone)]
pub struct Fixture {
    /// 328×248 frame of 14-bit DN.
    pub frame: FrameBuf,
    /// Tight box of all target pixels.
    pub truth: Roi,
}

/// Deep space level, DN.
pub const SPACE_DN: f64 = 300.0;

/// The Earth's limb: a circle (centre x, centre y, radius), px, whose centre lies below
/// the frame; pixels inside it see the Earth when the background is [`Background::Earth`].
pub const EARTH_LIMB_PX: (f64, f64, f64) = (140.0, 900.0, 780.0);

/// Whether pixel (x, y) lies on the Earth's disc ([`EARTH_LIMB_PX`]).
pub fn on_earth_disc(x: usize, y: usize) -> bool {
    let (cx, cy, r) = EARTH_LIMB_PX;
    let (dx, dy) = (x as f64 - cx, y as f64 - cy);
    (dx * dx + dy * dy).sqrt() < r
}

/// Smooth value noise in [0, 1): bilinear interpolation of a random lattice.
struct ValueNoise {
    cell: usize,
    cols: usize,
    lattice: Vec<f64>,
}

impl ValueNoise {
    fn new(rng: &mut Pcg64, cell: usize) -> Self {
        let cols = FRAME_WIDTH / cell + 2;
        let rows = FRAME_HEIGHT / cell + 2;
        let lattice = (0..cols * rows).map(|_| rng.r#gen::<f64>()).collect();
        ValueNoise {
            cell,
            cols,
            lattice,
        }
    }

    fn at(&self, x: usize, y: usize) -> f64 {
        let (cx, cy) = (x / self.cell, y / self.cell);
        let fx = (x % self.cell) as f64 / self.cell as f64;
        let fy = (y % self.cell) as f64 / self.cell as f64;
        let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
        let v = |i: usize, j: usize| self.lattice[j * self.cols + i];
        let top = v(cx, cy) * (1.0 - sx) + v(cx + 1, cy) * sx;
        let bottom = v(cx, cy + 1) * (1.0 - sx) + v(cx + 1, cy + 1) * sx;
        top * (1.0 - sy) + bottom * sy
    }
}

/// Renders `spec`.
pub fn render(spec: &FixtureSpec) -> Fixture {
    let mut rng = Pcg64::seed_from_u64(spec.seed);
    let octaves =
        [(48, 0.5), (16, 0.3), (6, 0.2)].map(|(cell, w)| (ValueNoise::new(&mut rng, cell), w));
    // `Normal::new` only fails for a non-finite σ: such a spec renders without noise.
    let noise = Normal::new(0.0, spec.noise_dn.max(0.0)).ok();
    let max_dn = f64::from((1u32 << DEFAULT_BIT_DEPTH) - 1);
    let space_dn = SPACE_DN;

    let body = if spec.body.is_empty() {
        Roi::EMPTY
    } else {
        spec.body
    };
    let (cyl, truth) = if body.is_empty() {
        (Roi::EMPTY, Roi::EMPTY)
    } else {
        let cyl_h = (body.height() / 2).max(1);
        let cyl = Roi::new(
            body.x1,
            body.y0 + (body.height() - cyl_h) / 2,
            body.x1
                .saturating_add(body.width() / 2)
                .min(FRAME_WIDTH as u16),
            body.y0 + (body.height() - cyl_h) / 2 + cyl_h,
        );
        let truth = body
            .clip(FRAME_WIDTH as u16, FRAME_HEIGHT as u16)
            .hull(&cyl);
        (cyl, truth)
    };

    let mut pixels = Vec::with_capacity(FRAME_WIDTH * FRAME_HEIGHT);
    for y in 0..FRAME_HEIGHT {
        for x in 0..FRAME_WIDTH {
            let (xu, yu) = (x as u16, y as u16);
            let mut v = if body.contains(xu, yu) {
                // Two shaded faces of the cube: the left 60 % brighter.
                let split = body.x0 + body.width() * 3 / 5;
                if xu < split {
                    spec.target_dn as f64
                } else {
                    spec.target_dn as f64 * 0.85
                }
            } else if cyl.contains(xu, yu) {
                // Cylinder: brightness falls off with the angle to the camera.
                let t = (f64::from(yu - cyl.y0) + 0.5) / f64::from(cyl.height()) * 2.0 - 1.0;
                spec.target_dn as f64 * (0.7 + 0.3 * (1.0 - t * t).sqrt())
            } else {
                let on_earth = spec.background == Background::Earth && on_earth_disc(x, y);
                if on_earth {
                    let t: f64 = octaves.iter().map(|(n, w)| w * n.at(x, y)).sum();
                    spec.earth_dn as f64 + (t - 0.5) * spec.texture_dn as f64
                } else {
                    space_dn
                }
            };
            if let Some(n) = &noise {
                v += n.sample(&mut rng);
            }
            pixels.push(v.round().clamp(0.0, max_dn) as u16);
        }
    }
    Fixture {
        frame: FrameBuf {
            pixels,
            width: FRAME_WIDTH,
            height: FRAME_HEIGHT,
            bits: DEFAULT_BIT_DEPTH,
        },
        truth,
    }
}

/// A small, fixed set of fixtures covering the scene kinds: deep space, textured
/// Earth, a large close target and a small far one. Deterministic.
pub fn standard_set() -> Vec<(&'static str, FixtureSpec)> {
    let base = FixtureSpec::default();
    vec![
        (
            "deep-space",
            FixtureSpec {
                background: Background::DeepSpace,
                seed: 11,
                ..base
            },
        ),
        ("earth", FixtureSpec { seed: 12, ..base }),
        (
            "earth-close",
            FixtureSpec {
                body: Roi::new(60, 40, 200, 190),
                seed: 13,
                ..base
            },
        ),
        (
            "earth-far",
            FixtureSpec {
                body: Roi::new(200, 150, 206, 156),
                seed: 14,
                ..base
            },
        ),
    ]
}
