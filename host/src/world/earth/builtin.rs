//! The built-in synthetic daily OLR field, [`OlrGrid::builtin`]: zonal profiles,
//! fixed weather patches and seeded fractal gradient noise for clouds.

use rayon::prelude::*;

use super::OlrGrid;

/// Piecewise-linear interpolation in a table of (latitude°, value) anchors sorted by
/// latitude; flat beyond the ends.
pub(super) fn profile(table: &[(f64, f64)], lat_deg: f64) -> f64 {
    let (first, last) = (table[0], table[table.len() - 1]);
    if lat_deg <= first.0 {
        return first.1;
    }
    for pair in table.windows(2) {
        let ((la, va), (lb, vb)) = (pair[0], pair[1]);
        if lat_deg <= lb {
            return va + (vb - va) * (lat_deg - la) / (lb - la);
        }
    }
    last.1
}

/// All-sky zonal-mean OLR anchors (latitude°, W m⁻²) the built-in field reproduces row
/// by row: the shape of the annual-mean zonal all-sky OLR of CERES EBAF-TOA Ed4
/// (Loeb et al., J. Climate 31:895, 2018) and ERBE (Harrison et al., J. Geophys. Res.
/// 95:18687, 1990): the ITCZ dip at 5° N, subtropical maxima at 20–25°, the
/// mid-latitude decline and a colder Antarctic than Arctic. Approximate values (about
/// ±10 W m⁻²), written from those published profiles, not digitised from the data.
/// Area-weighted mean 239.6 W m⁻² (asserted in the tests).
pub const BUILTIN_ZONAL_OLR_W_M2: [(f64, f64); 25] = [
    (-90.0, 158.0),
    (-80.0, 165.0),
    (-70.0, 185.0),
    (-60.0, 200.0),
    (-50.0, 213.0),
    (-45.0, 222.0),
    (-40.0, 234.0),
    (-30.0, 258.0),
    (-20.0, 272.0),
    (-15.0, 268.0),
    (-10.0, 258.0),
    (-5.0, 250.0),
    (0.0, 250.0),
    (5.0, 238.0),
    (10.0, 245.0),
    (15.0, 262.0),
    (22.0, 278.0),
    (30.0, 268.0),
    (40.0, 244.0),
    (45.0, 232.0),
    (50.0, 220.0),
    (60.0, 200.0),
    (70.0, 187.0),
    (80.0, 178.0),
    (90.0, 176.0),
];

/// Clear-sky zonal OLR anchors (latitude°, W m⁻²) from the same CERES EBAF clear-sky
/// climatology: the flux of the cloud-free parts of the built-in field before the
/// surface anomalies (deserts, plateaus) are added.
pub(super) const CLEAR_SKY_OLR_W_M2: [(f64, f64); 19] = [
    (-90.0, 166.0),
    (-80.0, 172.0),
    (-70.0, 197.0),
    (-60.0, 220.0),
    (-50.0, 238.0),
    (-40.0, 257.0),
    (-30.0, 279.0),
    (-20.0, 290.0),
    (-10.0, 290.0),
    (0.0, 289.0),
    (10.0, 290.0),
    (20.0, 296.0),
    (30.0, 289.0),
    (40.0, 266.0),
    (50.0, 246.0),
    (60.0, 226.0),
    (70.0, 205.0),
    (80.0, 190.0),
    (90.0, 186.0),
];

/// OLR lost under the thickest, highest cloud of each latitude (latitude°, W m⁻²):
/// clear-sky OLR minus the emission of cloud tops at about 200 K (≈105 W m⁻²) in deep
/// tropical convection, about 230 K (≈140 W m⁻²) in mid-latitude fronts, and small over
/// the polar ice, where cloud tops are barely colder than the surface.
pub(super) const CLOUD_DEPTH_W_M2: [(f64, f64); 15] = [
    (-90.0, 18.0),
    (-75.0, 30.0),
    (-60.0, 70.0),
    (-45.0, 112.0),
    (-30.0, 120.0),
    (-20.0, 150.0),
    (-10.0, 180.0),
    (0.0, 185.0),
    (10.0, 185.0),
    (20.0, 150.0),
    (30.0, 120.0),
    (45.0, 112.0),
    (60.0, 70.0),
    (75.0, 40.0),
    (90.0, 25.0),
];

/// A surface feature of the built-in field: a Gaussian patch (centre latitude° and
/// longitude° E, half-widths in degrees) that adds `clear_w_m2` to the clear-sky flux
/// and `convection` to the cloud propensity (negative: suppresses cloud).
struct Patch {
    lat: f64,
    lon: f64,
    sigma_lat: f64,
    sigma_lon: f64,
    clear_w_m2: f64,
    convection: f64,
}

/// Hot deserts (warm, cloud-free), high cold plateaus and ice sheets, and the three
/// tropical convection centres (maritime continent/warm pool, Amazon, Congo), placed
/// at their real positions so the disc looks like the Earth's.
const PATCHES: [Patch; 13] = [
    // Sahara, Arabia, Thar; Australian and southern African deserts; Sonoran.
    patch(23.0, 10.0, 7.0, 22.0, 26.0, -1.2),
    patch(22.0, 47.0, 6.0, 9.0, 24.0, -1.0),
    patch(27.0, 70.0, 4.0, 5.0, 12.0, -0.4),
    patch(-25.0, 132.0, 6.0, 12.0, 18.0, -0.8),
    patch(-24.0, 20.0, 5.0, 6.0, 12.0, -0.6),
    patch(30.0, 248.0, 5.0, 7.0, 12.0, -0.5),
    // Tibetan plateau, Greenland, East Antarctic plateau, Andes altiplano.
    patch(33.0, 88.0, 4.0, 10.0, -18.0, 0.0),
    patch(73.0, 318.0, 7.0, 12.0, -14.0, 0.0),
    patch(-82.0, 90.0, 6.0, 60.0, -10.0, 0.0),
    patch(-17.0, 292.0, 4.0, 3.0, -10.0, 0.0),
    // Convection centres: warm pool, Amazon, Congo.
    patch(0.0, 130.0, 12.0, 35.0, 0.0, 0.9),
    patch(-5.0, 298.0, 10.0, 14.0, 0.0, 0.7),
    patch(0.0, 22.0, 8.0, 10.0, 0.0, 0.6),
];

const fn patch(
    lat: f64,
    lon: f64,
    sigma_lat: f64,
    sigma_lon: f64,
    clear_w_m2: f64,
    convection: f64,
) -> Patch {
    Patch {
        lat,
        lon,
        sigma_lat,
        sigma_lon,
        clear_w_m2,
        convection,
    }
}

impl Patch {
    /// Gaussian weight of the patch at (lat, lon), longitude distance wrapped.
    fn weight(&self, lat: f64, lon: f64) -> f64 {
        let dlon = (lon - self.lon + 540.0).rem_euclid(360.0) - 180.0;
        let u = (lat - self.lat) / self.sigma_lat;
        let v = dlon / self.sigma_lon;
        libm::exp(-0.5 * (u * u + v * v))
    }
}

/// Integer hash (the 32-bit finaliser of MurmurHash3 over a mixed key): the gradient
/// index of a lattice point, the same on every platform.
fn hash3(seed: u32, x: i32, y: i32, z: i32) -> u32 {
    let mut h = seed
        ^ (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ (z as u32).wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// Gradient of a lattice point: one of the 12 cube-edge directions of improved Perlin
/// noise, dotted with the offset (dx, dy, dz).
fn grad(h: u32, dx: f64, dy: f64, dz: f64) -> f64 {
    match h % 12 {
        0 => dx + dy,
        1 => -dx + dy,
        2 => dx - dy,
        3 => -dx - dy,
        4 => dx + dz,
        5 => -dx + dz,
        6 => dx - dz,
        7 => -dx - dz,
        8 => dy + dz,
        9 => -dy + dz,
        10 => dy - dz,
        _ => -dy - dz,
    }
}

/// Perlin's quintic fade 6t⁵ − 15t⁴ + 10t³.
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// 3-D gradient noise (K. Perlin, "Improving noise", SIGGRAPH 2002) with hashed
/// gradients; about −1…1, 0 at lattice points.
fn gradient_noise(seed: u32, p: [f64; 3]) -> f64 {
    let f = p.map(f64::floor);
    let [ix, iy, iz] = f.map(|v| v as i32);
    let [dx, dy, dz] = [p[0] - f[0], p[1] - f[1], p[2] - f[2]];
    let [u, v, w] = [fade(dx), fade(dy), fade(dz)];
    let corner = |a: i32, b: i32, c: i32| {
        grad(
            hash3(seed, ix + a, iy + b, iz + c),
            dx - f64::from(a),
            dy - f64::from(b),
            dz - f64::from(c),
        )
    };
    let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
    let x00 = lerp(u, corner(0, 0, 0), corner(1, 0, 0));
    let x10 = lerp(u, corner(0, 1, 0), corner(1, 1, 0));
    let x01 = lerp(u, corner(0, 0, 1), corner(1, 0, 1));
    let x11 = lerp(u, corner(0, 1, 1), corner(1, 1, 1));
    lerp(w, lerp(v, x00, x10), lerp(v, x01, x11))
}

/// Fractal sum of `seeds.len()` octaves (frequency ×2, amplitude ×0.5 per octave),
/// each octave with its own lattice (seed) and offset.
fn fractal_noise(seeds: &[(u32, [f64; 3])], p: [f64; 3], first_freq: f64) -> f64 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 1.0, 0.0, first_freq);
    for (seed, offset) in seeds {
        let q = [
            p[0] * freq + offset[0],
            p[1] * freq + offset[1],
            p[2] * freq + offset[2],
        ];
        sum += amp * gradient_noise(*seed, q);
        norm += amp;
        amp *= 0.62;
        freq *= 2.0;
    }
    sum / norm
}

/// Octaves of the cloud texture: lattice cells of 30°, 15°, … 0.94° of latitude, so
/// the last one gives 1° detail.
const CLOUD_OCTAVES: usize = 6;
/// Amplitude of the domain warp, radians of great circle (~1000 km).
const WARP: f64 = 0.15;
/// Octaves of the domain warp (swirls, tilted frontal bands).
const WARP_OCTAVES: usize = 3;
/// Degrees of latitude per lattice cell of the first cloud octave (~3300 km).
const CLOUD_SCALE_DEG: f64 = 30.0;
/// Width of the cloud ramp, in standard deviations of the cloud texture: from clear
/// (texture below the row threshold) to full cloud depth over this much texture.
const CLOUD_RAMP: f64 = 1.6;

impl OlrGrid {
    /// A synthetic daily all-sky OLR map, deterministic for `seed` (the same bytes on
    /// every platform and thread count). **Not real data**: it is built to have the
    /// statistics of a CERES SYN1deg daily field, for scenes and tests without a CERES
    /// file.
    ///
    /// Construction, per 1° node:
    /// - clear-sky flux: the zonal clear-sky profile of the CERES EBAF climatology plus
    ///   warm deserts (Sahara, Arabia, Australia, …) and cold plateaus and ice sheets
    ///   (Tibet, Greenland, East Antarctica) at their real places, plus a ±5 W m⁻²
    ///   seeded texture;
    /// - cloud: a seeded fractal gradient noise (6 octaves, 3300 km down to 100 km)
    ///   on the sphere, domain-warped (swirls) and stretched 2.6× zonally at 50° of
    ///   latitude (frontal bands), biased up over the tropical convection centres
    ///   and down over the deserts; cloud depth c ∈ [0, 1] is a ramp of that texture,
    ///   and OLR = clear − c·D(φ) with D the loss under the highest cloud of that
    ///   latitude (≈185 W m⁻² in deep tropical convection, so cores reach ~105 W m⁻²);
    /// - per latitude row the cloud threshold is solved (bisection) so that the zonal
    ///   mean matches [`BUILTIN_ZONAL_OLR_W_M2`] (then smoothed over ±3 rows), so the
    ///   global mean is about 240 W m⁻²; values are clamped to 100–330 W m⁻².
    pub fn builtin(seed: u64) -> OlrGrid {
        let mut rng = tirroi_core::sensor::rng::Xoshiro128pp::seed_from_u64(seed);
        let octaves = |n: usize, rng: &mut tirroi_core::sensor::rng::Xoshiro128pp| {
            (0..n)
                .map(|_| {
                    let s = rng.next_u32();
                    // Offsets in [0, 256) lattice cells, so no two octaves share a lattice.
                    let o = [0; 3].map(|_: i32| f64::from(rng.next_u32() >> 8) / 65_536.0);
                    (s, o)
                })
                .collect::<Vec<_>>()
        };
        let cloud = octaves(CLOUD_OCTAVES, &mut rng);
        let warp: Vec<Vec<(u32, [f64; 3])>> =
            (0..3).map(|_| octaves(WARP_OCTAVES, &mut rng)).collect();
        let clear_tex = octaves(3, &mut rng);

        let n = Self::ROWS * Self::COLS;
        let deg = std::f64::consts::PI / 180.0;
        // Per node: (cloud texture, clear-sky flux, convective propensity). Every node
        // is computed on its own, so the parallel, order-preserving collect gives the
        // same bytes for any thread count.
        let node = |i: usize| {
            let (lat, lon) = (
                Self::node_lat_deg(i / Self::COLS),
                Self::node_lon_deg(i % Self::COLS),
            );
            let (s_lat, c_lat) = (libm::sin(lat * deg), libm::cos(lat * deg));
            let (s_lon, c_lon) = (libm::sin(lon * deg), libm::cos(lon * deg));
            // Zonal stretch: 2.6 at 50° of latitude, 1 in the tropics and at the poles.
            let z = (lat.abs() - 50.0) / 18.0;
            let stretch = 1.0 + 1.6 * libm::exp(-z * z);
            // The unit sphere (distances in radians of great circle) for isotropic
            // fields.
            let unit = [c_lat * c_lon, c_lat * s_lon, s_lat];
            let w = [0, 1, 2].map(|a| fractal_noise(&warp[a], unit, 1.2));
            // A cylinder around the polar axis: height = latitude (radians), radius
            // = cos φ / stretch, so a step east covers 1/stretch of the texture
            // distance of the same step north (zonal stretching); then warped.
            let r = c_lat / stretch;
            let p = [
                r * c_lon + WARP * w[0],
                r * s_lon + WARP * w[1],
                lat * deg + WARP * w[2],
            ];
            let texture = fractal_noise(&cloud, p, 180.0 / CLOUD_SCALE_DEG / std::f64::consts::PI);
            let mut surface = 5.0 * fractal_noise(&clear_tex, unit, 3.0);
            let mut convect = 0.0;
            for patch in &PATCHES {
                let wgt = patch.weight(lat, lon);
                surface += wgt * patch.clear_w_m2;
                convect += wgt * patch.convection;
            }
            (
                texture,
                profile(&CLEAR_SKY_OLR_W_M2, lat) + surface,
                convect,
            )
        };
        let nodes: Vec<(f64, f64, f64)> = (0..n).into_par_iter().map(node).collect();
        let mut texture: Vec<f64> = nodes.iter().map(|v| v.0).collect();
        let clear: Vec<f64> = nodes.iter().map(|v| v.1).collect();
        let propensity: Vec<f64> = nodes.iter().map(|v| v.2).collect();
        // Standardise the texture (mean 0, sd 1) in a fixed summation order.
        let mean = texture.iter().sum::<f64>() / n as f64;
        let var = texture.iter().map(|t| (t - mean) * (t - mean)).sum::<f64>() / n as f64;
        let sd = var.sqrt().max(1e-12);
        for (t, p) in texture.iter_mut().zip(&propensity) {
            *t = (*t - mean) / sd + p;
        }

        // Per row: the threshold that gives the target zonal mean.
        let olr_at = |i: usize, depth: f64, thr: f64| {
            let c = ((texture[i] - thr) / CLOUD_RAMP).clamp(0.0, 1.0);
            clear[i] - depth * c
        };
        let thresholds: Vec<f64> = (0..Self::ROWS)
            .into_par_iter()
            .map(|row| {
                let lat = Self::node_lat_deg(row);
                let target = profile(&BUILTIN_ZONAL_OLR_W_M2, lat);
                let depth = profile(&CLOUD_DEPTH_W_M2, lat);
                let row_mean = |thr: f64| {
                    (0..Self::COLS)
                        .map(|col| olr_at(row * Self::COLS + col, depth, thr))
                        .sum::<f64>()
                        / Self::COLS as f64
                };
                let (mut lo, mut hi) = (-8.0, 8.0);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if row_mean(mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                0.5 * (lo + hi)
            })
            .collect();
        let values = (0..n)
            .map(|i| {
                let row = i / Self::COLS;
                let lat = Self::node_lat_deg(row);
                // Triangle-smoothed threshold over ±3 rows (clamped at the poles).
                let (mut sum, mut wsum) = (0.0, 0.0);
                for d in -3i32..=3 {
                    let r = (row as i32 + d).clamp(0, Self::ROWS as i32 - 1) as usize;
                    let w = f64::from(4 - d.abs());
                    sum += w * thresholds[r];
                    wsum += w;
                }
                let v = olr_at(i, profile(&CLOUD_DEPTH_W_M2, lat), sum / wsum);
                v.clamp(100.0, 330.0) as f32
            })
            .collect();
        OlrGrid { values }
    }
}
