//! One frame: the detected flux of Eq. 4 per pixel from whichever surface the pixel sees
//! (a target facet, the Earth, or deep space), then the core's DN conversion and noise.
//!
//! The camera is a pinhole at the origin looking along +z, x right and y down (the pixel
//! grid's axes); pixel (i, j) spans [i, i+1) × [j, j+1) in image coordinates and the
//! principal point is the frame centre.
//!
//! **Target.** Each facet's band radiance comes from the core's table
//! ([`BandLut::radiance_f32`], T and ε of the facet) and its flux from the core's Eq. 4
//! ([`facet_flux_w_m2`]) at the facet centroid, as the paper's per-mesh-element flux.
//! Facets are rasterised (back faces culled, nearest wins by 1/z) inside the target's
//! projected bounds only. A pixel is *partial* when a facet touches its square
//! (conservative test) but its centre or one of its 8 neighbours' centres is not
//! covered; only partial pixels are supersampled (4 × 4 stratified samples) for their
//! target coverage and mixed signal. Coverage is the fraction of samples on the target
//! (1 for interior pixels).
//!
//! **Earth.** A sphere of radius R at the scene's centre position. A pixel's ray that
//! hits it takes the band radiance of the Earth mesh cell there ([`EarthMap`]) and the
//! flux of Eq. 4 with the local surface normal, the pixel's ray and |r| = the
//! camera–Earth-centre distance (the paper's 10 871 km; this reading reproduces
//! Table 5's q_max, `shared/reference/REFERENCE.md` §4). No Earth work is done for a
//! frame whose field of view cannot reach the Earth's disc, nor for pixels fully on the
//! target; pixels at the limb are supersampled like the target's edges.
//!
//! **Readout.** Radiometry mode turns q into F = D·q (Eq. 7) with D = π|r|²/ΔA_c per
//! object (target: distance to its centre; Earth: to its centre) and auto-ranges the DN
//! map over the frame's pure (unmixed) pixels (Eq. 17); detection mode uses the fixed
//! Table 5 scale (Eq. 9). The core's [`expose_frame`] then adds the noise (Eq. 18,
//! scaled to the NETD) and quantises.

use std::time::Instant;

use tirroi_core::Roi;
use tirroi_core::sensor::flux::{distance_compensation, facet_flux_w_m2, view_factor_per_m2};
use tirroi_core::sensor::noise::NoiseRms;
use tirroi_core::sensor::{
    BandLut, BandRadiance, DetectionScale, DnMapping, NoiseField, NoiseLevel, SENSOR_AREA_M2,
    SensorError, expose_frame,
};

use crate::world::earth::EarthMap;
use crate::world::geom::{Rotation, Vec3, dot, norm, scale, sub};
use crate::world::scene::Camera;
use crate::world::spacecraft::Mesh;

/// Sub-samples per axis on a partial pixel (4 × 4 = 16 per pixel).
pub const SUPERSAMPLES_PER_AXIS: usize = 4;
const SAMPLES: usize = SUPERSAMPLES_PER_AXIS * SUPERSAMPLES_PER_AXIS;
const NO_FACET: u32 = u32::MAX;
/// Narrowest radiometry range (Eq. 17), in NETDs of F at the reference temperature
/// (10 × 0.4 K: 4 K at 300 K): a scene of (nearly) one temperature keeps a usable DN map.
pub const MIN_RANGE_NETD: f64 = 10.0;
/// Coverage at or above which a pixel belongs to the target's mask and truth box.
pub const MASK_COVERAGE: f32 = 0.5;

/// The target as the camera sees it.
#[derive(Debug, Clone, Copy)]
pub struct TargetView<'a> {
    /// The mesh in the body frame, m.
    pub mesh: &'a Mesh,
    /// Temperature per facet, K (the thermal solution).
    pub temperature_k: &'a [f64],
    /// Body frame → camera frame.
    pub body_to_camera: Rotation,
    /// The body origin (the target's centre) in the camera frame, m.
    pub centre_m: Vec3,
}

/// The Earth as the camera sees it.
#[derive(Debug, Clone, Copy)]
pub struct EarthView<'a> {
    /// Band radiance per mesh cell.
    pub map: &'a EarthMap,
    /// The Earth's centre in the camera frame, m.
    pub centre_m: Vec3,
    /// Radius, m.
    pub radius_m: f64,
    /// Camera-frame directions → Earth-fixed frame (z north, x at longitude 0).
    pub camera_to_earth: Rotation,
}

/// The camera mode and its DN map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Readout {
    /// Radiometry, auto-ranged per frame (Eq. 17).
    Radiometry,
    /// Detection on a Table 5 scale.
    Detection(DetectionScale),
}

/// Everything one frame needs.
#[derive(Debug, Clone, Copy)]
pub struct RenderInput<'a> {
    /// Camera geometry and read-out.
    pub camera: &'a Camera,
    /// Mode.
    pub readout: Readout,
    /// The target, if any.
    pub target: Option<TargetView<'a>>,
    /// The Earth, if rendered.
    pub earth: Option<EarthView<'a>>,
    /// Camera–Earth-centre distance, m: the detection-mode noise is scaled to the NETD
    /// of a face-on blackbody at this distance (the scene the Table 5 scales are built on).
    pub earth_distance_m: f64,
    /// Noise seed; `None` renders without noise (and skips the noise stage).
    pub noise_seed: Option<u64>,
    /// Band radiance (f64, for ∂L/∂T of the noise scale).
    pub band: &'a BandRadiance,
    /// Band radiance table (per facet and Earth cell radiances).
    pub lut: &'a BandLut,
}

/// Time spent and work done per stage of one frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RenderStats {
    /// Facet fluxes, rasterisation and supersampling, ns.
    pub target_ns: u64,
    /// Earth rays, lookups and limb supersampling, ns.
    pub earth_ns: u64,
    /// DN map, noise and quantisation (the core's `expose_frame`), ns.
    pub expose_ns: u64,
    /// Pixels inside the target's projected bounds.
    pub target_region_px: usize,
    /// Pixels supersampled at the target's edges.
    pub target_partial_px: usize,
    /// Earth rays cast (centre rays plus limb sub-samples); 0 when the Earth is out of view.
    pub earth_rays: usize,
}

/// One rendered frame with its labels.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// DN, row-major.
    pub dn: Vec<u16>,
    /// Signal before the DN map: F (W m⁻², radiometry) or q_fc (W m⁻², detection).
    pub signal: Vec<f32>,
    /// Target coverage per pixel, 0..=1.
    pub coverage: Vec<f32>,
    /// Tight box of the pixels with coverage ≥ [`MASK_COVERAGE`] (empty when none).
    pub truth: Roi,
    /// Fraction of the frame's pixels whose centre sees the Earth (not the target).
    pub earth_fraction: f64,
    /// The DN map used.
    pub mapping: DnMapping,
    /// Total noise σ, DN (0 without noise).
    pub noise_sigma_dn: f32,
    /// Stage times and counts.
    pub stats: RenderStats,
}

/// Why a frame could not be rendered.
#[derive(Debug, Clone, PartialEq)]
pub enum RenderError {
    /// The core refused a value (message names it).
    Sensor(SensorError),
    /// The target reaches the camera plane (too close for its size).
    TargetTooClose {
        /// The nearest vertex depth, m.
        nearest_z_m: f64,
    },
    /// Inconsistent input (message says what).
    Input(String),
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Sensor(e) => write!(f, "camera model: {e}"),
            RenderError::TargetTooClose { nearest_z_m } => write!(
                f,
                "the target reaches {nearest_z_m:.3} m in front of the camera: expected the whole target > 0.1 m ahead (increase range_m)"
            ),
            RenderError::Input(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for RenderError {}

impl From<SensorError> for RenderError {
    fn from(e: SensorError) -> Self {
        RenderError::Sensor(e)
    }
}

/// Pinhole projection of the camera.
#[derive(Debug, Clone, Copy)]
struct Pinhole {
    f: f64,
    cx: f64,
    cy: f64,
    w: usize,
    h: usize,
}

impl Pinhole {
    fn new(c: &Camera) -> Self {
        Pinhole {
            f: c.focal_px(),
            cx: c.width as f64 / 2.0,
            cy: c.height as f64 / 2.0,
            w: c.width,
            h: c.height,
        }
    }

    /// Unit ray through image point (u, v).
    fn ray(&self, u: f64, v: f64) -> Vec3 {
        let d = [(u - self.cx) / self.f, (v - self.cy) / self.f, 1.0];
        scale(d, 1.0 / norm(d))
    }

    /// Half the diagonal field of view, rad.
    fn half_diagonal_rad(&self) -> f64 {
        (self.cx.hypot(self.cy) / self.f).atan()
    }
}

/// Renders one frame.
///
/// # Errors
/// [`RenderError`] for a target too close to the camera, temperatures that do not match
/// the mesh, or values the core's camera model refuses.
pub fn render(input: &RenderInput<'_>) -> Result<Rendered, RenderError> {
    let cam = Pinhole::new(input.camera);
    let n = cam.w * cam.h;
    let mut stats = RenderStats::default();
    // Per pixel: target coverage and the target's share of the signal.
    let mut coverage = vec![0f32; n];
    let mut signal = vec![0f32; n];
    // Pure pixels (all target or all Earth) bound the radiometry range (Eq. 17).
    let mut pure = Range::default();

    let t0 = Instant::now();
    if let Some(target) = &input.target {
        render_target(
            &cam,
            target,
            input,
            &mut coverage,
            &mut signal,
            &mut pure,
            &mut stats,
        )?;
    }
    stats.target_ns = t0.elapsed().as_nanos() as u64;

    let t1 = Instant::now();
    let mut earth_px = 0usize;
    if let Some(earth) = &input.earth {
        earth_px = render_earth(
            &cam,
            earth,
            input.readout,
            &coverage,
            &mut signal,
            &mut pure,
            &mut stats,
        )?;
    }
    stats.earth_ns = t1.elapsed().as_nanos() as u64;

    let t2 = Instant::now();
    let bits = input.camera.bits;
    let mapping = match input.readout {
        Readout::Detection(scale) => DnMapping::detection(scale, bits)?,
        Readout::Radiometry => {
            // Eq. 17 over the pure pixels, with the span kept at least
            // MIN_RANGE_NETD NETDs wide (in F at the reference temperature), so a
            // near-uniform scene is not stretched until its noise fills the frame.
            let (lo, hi) = pure.bounds().unwrap_or((0.0, 0.0));
            let min_span = MIN_RANGE_NETD
                * input.camera.netd_k
                * std::f64::consts::PI
                * input
                    .band
                    .radiance_derivative_w_m2_sr_k(input.camera.netd_reference_k, 1.0)?;
            let (lo, hi) = if hi - lo >= min_span && hi > lo {
                (lo, hi)
            } else {
                let lo = (0.5 * (lo + hi) - 0.5 * min_span).max(0.0);
                (lo, lo + min_span.max(f64::MIN_POSITIVE))
            };
            DnMapping::radiometry_auto(lo, hi, bits)?
        }
    };
    let mut noise_sigma_dn = 0.0;
    let mut field = match input.noise_seed {
        None => None,
        Some(seed) => {
            let signal_per_radiance_sr = match input.readout {
                Readout::Radiometry => std::f64::consts::PI,
                Readout::Detection(_) => {
                    SENSOR_AREA_M2 / input.earth_distance_m / input.earth_distance_m
                }
            };
            let dn_per_k = mapping.dn_per_kelvin(
                input.band,
                input.camera.netd_reference_k,
                signal_per_radiance_sr,
            )?;
            let level = NoiseLevel::Netd {
                netd_k: input.camera.netd_k,
                dn_per_k,
            };
            let sigmas = level.sigmas(&NoiseRms::TABLE2, &mapping)?;
            noise_sigma_dn = sigmas.total_dn();
            Some(NoiseField::new(
                sigmas,
                input.camera.flicker_correlation_px,
                cam.w,
                seed,
            )?)
        }
    };
    let mut dn = vec![0u16; n];
    expose_frame(&signal, cam.w, &mapping, field.as_mut(), &mut dn)?;
    stats.expose_ns = t2.elapsed().as_nanos() as u64;

    let truth = mask_box(&coverage, cam.w);
    Ok(Rendered {
        width: cam.w,
        height: cam.h,
        dn,
        signal,
        coverage,
        truth,
        earth_fraction: earth_px as f64 / n as f64,
        mapping,
        noise_sigma_dn,
        stats,
    })
}

/// Image point of sub-sample `s` (0..16, row-major) of pixel (x, y): the centres of a
/// 4 × 4 grid of equal cells.
fn sample_point(x: usize, y: usize, s: usize) -> (f64, f64) {
    let step = 1.0 / SUPERSAMPLES_PER_AXIS as f64;
    (
        x as f64 + ((s % SUPERSAMPLES_PER_AXIS) as f64 + 0.5) * step,
        y as f64 + ((s / SUPERSAMPLES_PER_AXIS) as f64 + 0.5) * step,
    )
}

/// Tight box of the pixels whose coverage is at least [`MASK_COVERAGE`].
pub fn mask_box(coverage: &[f32], width: usize) -> Roi {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (y, row) in coverage.chunks_exact(width).enumerate() {
        for (x, &c) in row.iter().enumerate() {
            if c >= MASK_COVERAGE {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x + 1);
                y1 = y1.max(y + 1);
            }
        }
    }
    if x0 == usize::MAX {
        Roi::EMPTY
    } else {
        Roi::new(x0 as u16, y0 as u16, x1 as u16, y1 as u16)
    }
}

/// Running min/max of the pure pixels' signal.
#[derive(Debug, Default, Clone, Copy)]
struct Range {
    lo: f32,
    hi: f32,
    any: bool,
}

impl Range {
    fn add(&mut self, v: f32) {
        if !self.any {
            *self = Range {
                lo: v,
                hi: v,
                any: true,
            };
        } else {
            self.lo = self.lo.min(v);
            self.hi = self.hi.max(v);
        }
    }

    fn bounds(&self) -> Option<(f64, f64)> {
        self.any.then_some((f64::from(self.lo), f64::from(self.hi)))
    }
}

/// A facet projected to the image: vertices (u, v) and 1/z.
#[derive(Debug, Clone, Copy)]
struct Edge {
    a: f64,
    b: f64,
    c: f64,
}

impl Edge {
    /// Edge function of the directed edge p → q: ≥ 0 on its inner side.
    fn new(p: [f64; 2], q: [f64; 2]) -> Edge {
        let a = -(q[1] - p[1]);
        let b = q[0] - p[0];
        Edge {
            a,
            b,
            c: -(a * p[0] + b * p[1]),
        }
    }

    fn at(&self, u: f64, v: f64) -> f64 {
        self.a * u + self.b * v + self.c
    }

    /// The largest value over a pixel square whose centre gives `centre_value`.
    fn conservative(&self, centre_value: f64) -> f64 {
        centre_value + 0.5 * (self.a.abs() + self.b.abs())
    }
}

/// A front-facing facet ready for rasterisation.
struct ScreenTriangle {
    edges: [Edge; 3],
    inv_area2: f64,
    inv_z: [f64; 3],
    /// Pixel bounds, inclusive-exclusive, in frame coordinates.
    x: (usize, usize),
    y: (usize, usize),
    facet: u32,
}

impl ScreenTriangle {
    /// Barycentric-interpolated 1/z at (u, v) when the point is inside.
    fn inside(&self, u: f64, v: f64) -> Option<f32> {
        let e0 = self.edges[0].at(u, v);
        let e1 = self.edges[1].at(u, v);
        let e2 = self.edges[2].at(u, v);
        if e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0 {
            // e0 is opposite vertex 2 (edge 0→1), e1 opposite 0, e2 opposite 1.
            let iz =
                (e1 * self.inv_z[0] + e2 * self.inv_z[1] + e0 * self.inv_z[2]) * self.inv_area2;
            Some(iz as f32)
        } else {
            None
        }
    }
}

fn render_target(
    cam: &Pinhole,
    target: &TargetView<'_>,
    input: &RenderInput<'_>,
    coverage: &mut [f32],
    signal: &mut [f32],
    pure: &mut Range,
    stats: &mut RenderStats,
) -> Result<(), RenderError> {
    let mesh = target.mesh;
    let facets = mesh.facet_count();
    if target.temperature_k.len() != facets {
        return Err(RenderError::Input(format!(
            "{} temperatures for a mesh of {facets} facets",
            target.temperature_k.len()
        )));
    }
    let r = &target.body_to_camera;
    let verts: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| crate::world::geom::add(r.apply(*v), target.centre_m))
        .collect();
    let nearest = verts.iter().map(|v| v[2]).fold(f64::INFINITY, f64::min);
    if nearest.is_nan() || nearest <= 0.1 {
        return Err(RenderError::TargetTooClose {
            nearest_z_m: nearest,
        });
    }
    let proj: Vec<[f64; 2]> = verts
        .iter()
        .map(|v| [cam.cx + cam.f * v[0] / v[2], cam.cy + cam.f * v[1] / v[2]])
        .collect();

    // Signal per facet: the core's Eq. 4 at the centroid (radiometry: × D, Eq. 7).
    let compensation = match input.readout {
        Readout::Radiometry => distance_compensation(norm(target.centre_m), SENSOR_AREA_M2)?,
        Readout::Detection(_) => 1.0,
    };
    let mut facet_signal = vec![0f32; facets];
    let mut tris = Vec::with_capacity(facets / 2);
    let (w, h) = (cam.w as f64, cam.h as f64);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let n_cam = r.apply(mesh.normal(t));
        let c_cam = crate::world::geom::add(r.apply(mesh.centroid(t)), target.centre_m);
        if dot(n_cam, c_cam) >= 0.0 {
            continue; // back face
        }
        let [i0, i1, i2] = tri.map(|i| i as usize);
        let (p0, mut p1, mut p2) = (proj[i0], proj[i1], proj[i2]);
        let (z0, mut z1, mut z2) = (verts[i0][2], verts[i1][2], verts[i2][2]);
        let umin = p0[0].min(p1[0]).min(p2[0]);
        let umax = p0[0].max(p1[0]).max(p2[0]);
        let vmin = p0[1].min(p1[1]).min(p2[1]);
        let vmax = p0[1].max(p1[1]).max(p2[1]);
        if umax < 0.0 || vmax < 0.0 || umin > w || vmin > h {
            continue; // outside the frame
        }
        let mut area2 = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
        if area2.abs() < 1e-12 {
            continue; // edge-on
        }
        if area2 < 0.0 {
            std::mem::swap(&mut p1, &mut p2);
            std::mem::swap(&mut z1, &mut z2);
            area2 = -area2;
        }
        let radiance = input.lut.radiance_f32(
            target.temperature_k[t] as f32,
            mesh.material(t).ir_emissivity as f32,
        )?;
        let q = facet_flux_w_m2(
            f64::from(radiance),
            &n_cam,
            &[0.0, 0.0, 1.0],
            &scale(c_cam, -1.0),
            SENSOR_AREA_M2,
        )?;
        facet_signal[t] = (q * compensation) as f32;
        let clamp = |v: f64, hi: usize| (v.max(0.0) as usize).min(hi);
        tris.push(ScreenTriangle {
            edges: [Edge::new(p0, p1), Edge::new(p1, p2), Edge::new(p2, p0)],
            inv_area2: 1.0 / area2,
            inv_z: [1.0 / z0, 1.0 / z1, 1.0 / z2],
            x: (
                clamp((umin - 0.5).floor(), cam.w),
                clamp((umax + 0.5).ceil() + 1.0, cam.w),
            ),
            y: (
                clamp((vmin - 0.5).floor(), cam.h),
                clamp((vmax + 0.5).ceil() + 1.0, cam.h),
            ),
            facet: t as u32,
        });
    }
    if tris.is_empty() {
        return Ok(());
    }
    // The target's projected bounds: all per-pixel work stays inside them.
    let rx0 = tris.iter().map(|t| t.x.0).min().unwrap_or(0);
    let rx1 = tris.iter().map(|t| t.x.1).max().unwrap_or(0);
    let ry0 = tris.iter().map(|t| t.y.0).min().unwrap_or(0);
    let ry1 = tris.iter().map(|t| t.y.1).max().unwrap_or(0);
    let rw = rx1 - rx0;
    let region = rw * (ry1 - ry0);
    stats.target_region_px = region;
    let local = |x: usize, y: usize| (y - ry0) * rw + (x - rx0);

    // Pass 1: the facet at each pixel centre (nearest by 1/z) and which pixels any
    // facet touches.
    let mut centre_facet = vec![NO_FACET; region];
    let mut centre_inv_z = vec![0f32; region];
    let mut touched = vec![false; region];
    for tri in &tris {
        for y in tri.y.0..tri.y.1 {
            let v = y as f64 + 0.5;
            for x in tri.x.0..tri.x.1 {
                let u = x as f64 + 0.5;
                let e = [
                    tri.edges[0].at(u, v),
                    tri.edges[1].at(u, v),
                    tri.edges[2].at(u, v),
                ];
                let i = local(x, y);
                if (0..3).all(|k| tri.edges[k].conservative(e[k]) >= 0.0) {
                    touched[i] = true;
                }
                if let Some(iz) = tri.inside(u, v) {
                    if iz > centre_inv_z[i] {
                        centre_inv_z[i] = iz;
                        centre_facet[i] = tri.facet;
                    }
                }
            }
        }
    }

    // Partial pixels: touched, but the centre or a neighbour's centre is off the target.
    let covered = |x: isize, y: isize| -> bool {
        if x < rx0 as isize || y < ry0 as isize || x >= rx1 as isize || y >= ry1 as isize {
            return false;
        }
        centre_facet[local(x as usize, y as usize)] != NO_FACET
    };
    let mut partial_index = vec![u32::MAX; region];
    let mut partial_px: Vec<(usize, usize)> = Vec::new();
    for y in ry0..ry1 {
        for x in rx0..rx1 {
            let i = local(x, y);
            if !touched[i] {
                continue;
            }
            let (xi, yi) = (x as isize, y as isize);
            let interior = (-1..=1).all(|dy| (-1..=1).all(|dx| covered(xi + dx, yi + dy)));
            if !interior {
                partial_index[i] = partial_px.len() as u32;
                partial_px.push((x, y));
            }
        }
    }
    stats.target_partial_px = partial_px.len();

    // Pass 2: 4 × 4 samples on partial pixels only.
    let mut sample_facet = vec![NO_FACET; partial_px.len() * SAMPLES];
    let mut sample_inv_z = vec![0f32; partial_px.len() * SAMPLES];
    if !partial_px.is_empty() {
        for tri in &tris {
            for y in tri.y.0..tri.y.1 {
                for x in tri.x.0..tri.x.1 {
                    let p = partial_index[local(x, y)];
                    if p == u32::MAX {
                        continue;
                    }
                    let base = p as usize * SAMPLES;
                    for s in 0..SAMPLES {
                        let (u, v) = sample_point(x, y, s);
                        if let Some(iz) = tri.inside(u, v) {
                            if iz > sample_inv_z[base + s] {
                                sample_inv_z[base + s] = iz;
                                sample_facet[base + s] = tri.facet;
                            }
                        }
                    }
                }
            }
        }
    }

    // Resolve coverage and the target's signal.
    for y in ry0..ry1 {
        for x in rx0..rx1 {
            let i = local(x, y);
            let o = y * cam.w + x;
            let p = partial_index[i];
            if p != u32::MAX {
                let samples = &sample_facet[p as usize * SAMPLES..(p as usize + 1) * SAMPLES];
                let mut hits = 0u32;
                let mut sum = 0f32;
                for &f in samples {
                    if f != NO_FACET {
                        hits += 1;
                        sum += facet_signal[f as usize];
                    }
                }
                coverage[o] = hits as f32 / SAMPLES as f32;
                signal[o] = sum / SAMPLES as f32;
            } else if centre_facet[i] != NO_FACET {
                coverage[o] = 1.0;
                let s = facet_signal[centre_facet[i] as usize];
                signal[o] = s;
                pure.add(s);
            }
        }
    }
    Ok(())
}

/// Earth signal along the unit ray `d`, or `None` when it misses.
#[derive(Debug, Clone, Copy)]
struct EarthRays<'a> {
    view: &'a EarthView<'a>,
    centre_distance_m: f64,
    /// |c|² − R².
    c2_minus_r2: f64,
    compensation: f64,
}

impl EarthRays<'_> {
    fn signal(&self, d: Vec3) -> Result<Option<f32>, SensorError> {
        let c = self.view.centre_m;
        let b = dot(d, c);
        let disc = b * b - self.c2_minus_r2;
        if b <= 0.0 || disc < 0.0 {
            return Ok(None);
        }
        let t = b - disc.sqrt();
        let hit = scale(d, t);
        let normal = scale(sub(hit, c), 1.0 / self.view.radius_m);
        let e = self.view.camera_to_earth.apply(normal);
        let lat = e[2].clamp(-1.0, 1.0).asin().to_degrees();
        let lon = e[1].atan2(e[0]).to_degrees();
        let radiance = self.view.map.radiance_w_m2_sr(lat, lon);
        // Eq. 4 with |r| = the camera–Earth-centre distance (module docs).
        let g = view_factor_per_m2(
            &normal,
            &[0.0, 0.0, 1.0],
            &scale(d, -self.centre_distance_m),
        )?;
        Ok(Some(
            (f64::from(radiance) * g * SENSOR_AREA_M2 * self.compensation) as f32,
        ))
    }
}

/// Adds the Earth's signal behind the target; returns how many pixel centres see it.
fn render_earth(
    cam: &Pinhole,
    earth: &EarthView<'_>,
    readout: Readout,
    coverage: &[f32],
    signal: &mut [f32],
    pure: &mut Range,
    stats: &mut RenderStats,
) -> Result<usize, RenderError> {
    let dist = norm(earth.centre_m);
    if dist.is_nan() || dist <= earth.radius_m {
        return Err(RenderError::Input(format!(
            "the camera is {dist} m from the Earth's centre, inside its {} m radius",
            earth.radius_m
        )));
    }
    // Frame-level cull: the boresight's angle to the centre minus the disc's angular
    // radius must be within the half diagonal of the field of view.
    let off_boresight = (earth.centre_m[2] / dist).clamp(-1.0, 1.0).acos();
    let disc_radius = (earth.radius_m / dist).asin();
    if off_boresight - disc_radius > cam.half_diagonal_rad() {
        return Ok(0);
    }
    let rays = EarthRays {
        view: earth,
        centre_distance_m: dist,
        c2_minus_r2: (dist - earth.radius_m) * (dist + earth.radius_m),
        compensation: match readout {
            Readout::Radiometry => distance_compensation(dist, SENSOR_AREA_M2)?,
            Readout::Detection(_) => 1.0,
        },
    };
    let (w, h) = (cam.w, cam.h);
    // Centre rays for every pixel not fully on the target: 1 hit, 0 miss, −1 not cast.
    let mut hit = vec![-1i8; w * h];
    let mut earth_signal = vec![0f32; w * h];
    let mut seen = 0usize;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if coverage[i] >= 1.0 {
                continue;
            }
            stats.earth_rays += 1;
            hit[i] = 0;
            if let Some(s) = rays.signal(cam.ray(x as f64 + 0.5, y as f64 + 0.5))? {
                hit[i] = 1;
                earth_signal[i] = s;
            }
        }
    }
    // Limb pixels (a cast 4-neighbour differs in hit) are supersampled.
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let here = hit[i];
            if here < 0 {
                continue;
            }
            let other = |j: usize| hit[j] >= 0 && hit[j] != here;
            let differs = (x > 0 && other(i - 1))
                || (x + 1 < w && other(i + 1))
                || (y > 0 && other(i - w))
                || (y + 1 < h && other(i + w));
            let s = if differs {
                let mut sum = 0f32;
                for s in 0..SAMPLES {
                    let (u, v) = sample_point(x, y, s);
                    stats.earth_rays += 1;
                    sum += rays.signal(cam.ray(u, v))?.unwrap_or(0.0);
                }
                sum / SAMPLES as f32
            } else {
                earth_signal[i]
            };
            let c = coverage[i];
            signal[i] += (1.0 - c) * s;
            if here == 1 && c < MASK_COVERAGE {
                seen += 1;
            }
            if here == 1 && !differs && c == 0.0 {
                pure.add(s);
            }
        }
    }
    Ok(seen)
}
