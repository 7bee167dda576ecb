//! The target pass: facets projected and rasterised with super-sampling on partial
//! pixels (coverage, signal, the range of pure pixels).

use tirroi_core::sensor::SENSOR_AREA_M2;
use tirroi_core::sensor::flux::{distance_compensation, facet_flux_w_m2};

use super::pure::PurePixels;
use super::{
    NO_FACET, Pinhole, Readout, RenderError, RenderInput, RenderStats, SAMPLES, TargetView,
    sample_point,
};
use crate::world::geom::{Vec3, dot, norm, scale};

/// A facet projected to the image: vertices (u, v) and 1/z.
#[derive(Debug, Clone, Copy)]
struct Edge {
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) c: f64,
}

impl Edge {
    /// Edge function of the directed edge p → q: ≥ 0 on its inner side.
    pub(super) fn new(p: [f64; 2], q: [f64; 2]) -> Edge {
        let a = -(q[1] - p[1]);
        let b = q[0] - p[0];
        Edge {
            a,
            b,
            c: -(a * p[0] + b * p[1]),
        }
    }

    pub(super) fn at(&self, u: f64, v: f64) -> f64 {
        self.a * u + self.b * v + self.c
    }

    /// The largest value over a pixel square whose centre gives `centre_value`.
    pub(super) fn conservative(&self, centre_value: f64) -> f64 {
        centre_value + 0.5 * (self.a.abs() + self.b.abs())
    }
}

/// A front-facing facet ready for rasterisation.
struct ScreenTriangle {
    pub(super) edges: [Edge; 3],
    pub(super) inv_area2: f64,
    pub(super) inv_z: [f64; 3],
    /// Pixel bounds, inclusive-exclusive, in frame coordinates.
    pub(super) x: (usize, usize),
    pub(super) y: (usize, usize),
    pub(super) facet: u32,
}

impl ScreenTriangle {
    /// Barycentric-interpolated 1/z at (u, v) when the point is inside.
    pub(super) fn inside(&self, u: f64, v: f64) -> Option<f32> {
        self.inside_from([
            self.edges[0].at(u, v),
            self.edges[1].at(u, v),
            self.edges[2].at(u, v),
        ])
    }

    /// As [`ScreenTriangle::inside`], from the three edge values already evaluated.
    pub(super) fn inside_from(&self, [e0, e1, e2]: [f64; 3]) -> Option<f32> {
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

pub(super) fn render_target(
    cam: &Pinhole,
    target: &TargetView<'_>,
    input: &RenderInput<'_>,
    coverage: &mut [f32],
    signal: &mut [f32],
    pure: &mut PurePixels,
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
                if let Some(iz) = tri.inside_from(e) {
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
                pure.add(o, s);
            }
        }
    }
    Ok(())
}
