//! Triangle meshes of target spacecraft with per-part materials.
//!
//! A [`Mesh`] lives in the target body frame: metres, origin at the centre of its
//! bounding box, outward normals (counter-clockwise winding seen from outside). Each
//! triangle (facet) belongs to one [`Part`], which carries its [`Material`] and an
//! optional internal dissipation.

use std::collections::HashMap;

use crate::world::geom::{Vec3, add, cross, dot, norm, normalize, scale, sub};

/// Surface optical and conduction properties of a part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Short name, e.g. `"white-paint"`.
    pub name: &'static str,
    /// Solar absorptivity α, 0..=1 (fraction of the incident solar and albedo flux
    /// that is absorbed).
    pub solar_absorptivity: f64,
    /// Hemispherical infrared emissivity ε, 0..=1 (the thermal solver needs ε > 0);
    /// the grey-body emissivity the TIR camera sees.
    pub ir_emissivity: f64,
    /// Thermal conductivity of the conducting skin or panel, W m⁻¹ K⁻¹ (≥ 0).
    pub conductivity_w_m_k: f64,
    /// In-plane conducting thickness of the skin or panel, m (≥ 0): the facet network
    /// conducts k·t W K⁻¹ per square.
    pub thickness_m: f64,
    /// Conductance through a sandwich panel's core from this face to the opposite one,
    /// W m⁻² K⁻¹ (≥ 0): the thermal network links a facet to the facet its inward ray
    /// meets within [`crate::world::spacecraft::thermal::CORE_MAX_DEPTH_M`] (the panel's
    /// other face). 0: a skin whose faces meet only along the panel's edges.
    pub core_conductance_w_m2_k: f64,
}

/// A named group of facets with one material (and optional internal dissipation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Part {
    /// Short name, e.g. `"cube"`, `"solar-cells"`.
    pub name: &'static str,
    /// Surface and conduction properties of every facet of the part.
    pub material: Material,
    /// Internal power dissipated in the part, W (≥ 0), spread over its facets in
    /// proportion to their area.
    pub dissipation_w: f64,
}

/// A closed-ish triangle mesh in the target body frame (metres, origin at the target's
/// geometric centre — the centre of its bounding box), outward normals
/// (counter-clockwise winding seen from outside).
///
/// Parts attached to another part's face (the cylinder on the cube, antennas on the
/// bus) are open where they touch it; the covered facets of the face below stay in
/// the mesh (the renderer never sees them, the thermal network finds them enclosed).
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertex positions, m, body frame.
    pub vertices: Vec<Vec3>,
    /// Vertex indices of each triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Index into `parts` of each triangle (same length as `triangles`).
    pub part_of: Vec<u16>,
    /// The parts.
    pub parts: Vec<Part>,
}

impl Mesh {
    /// Number of triangles (facets).
    pub fn facet_count(&self) -> usize {
        self.triangles.len()
    }

    fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [
            self.vertices[a as usize],
            self.vertices[b as usize],
            self.vertices[c as usize],
        ]
    }

    /// Unit outward normal of facet `t` (the zero vector for a zero-area facet).
    /// Panics if `t` or its vertex indices are out of range.
    pub fn normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        normalize(cross(sub(b, a), sub(c, a)))
    }

    /// Area of facet `t`, m². Panics if `t` or its vertex indices are out of range.
    pub fn area_m2(&self, t: usize) -> f64 {
        let [a, b, c] = self.corners(t);
        0.5 * norm(cross(sub(b, a), sub(c, a)))
    }

    /// Centroid of facet `t`, m, body frame. Panics if `t` or its vertex indices are
    /// out of range.
    pub fn centroid(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        scale(add(add(a, b), c), 1.0 / 3.0)
    }

    /// Material of facet `t`. Panics if `t` or its part index is out of range.
    pub fn material(&self, t: usize) -> &Material {
        &self.parts[self.part_of[t] as usize].material
    }

    /// Largest distance of a vertex from the body origin, m (for culling: the whole
    /// mesh lies in the sphere of this radius about the origin).
    pub fn bounding_radius_m(&self) -> f64 {
        self.vertices.iter().map(|&v| norm(v)).fold(0.0, f64::max)
    }

    /// Sum of the facet areas, m² (covered facets under attached parts included).
    pub fn total_area_m2(&self) -> f64 {
        (0..self.facet_count()).map(|t| self.area_m2(t)).sum()
    }

    /// Axis-aligned bounding box `(min, max)` of the vertices, m (both zero for an
    /// empty mesh).
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        bounding_box(&self.vertices)
    }

    /// Signed volume enclosed by the facets, m³ (divergence theorem about the
    /// origin): positive for outward normals. Exact for a closed mesh; for a part
    /// left open where it is attached, exact when the opening lies in a plane
    /// through the origin (the cube + cylinder joint does).
    pub fn signed_volume_m3(&self) -> f64 {
        (0..self.facet_count())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// Index of the part called `name`, if any.
    pub fn part_index(&self, name: &str) -> Option<usize> {
        self.parts.iter().position(|p| p.name == name)
    }

    /// Facets of part `part`, in mesh order.
    pub fn facets_of_part(&self, part: usize) -> impl Iterator<Item = usize> + '_ {
        self.part_of
            .iter()
            .enumerate()
            .filter(move |&(_, &p)| p as usize == part)
            .map(|(t, _)| t)
    }

    /// Total facet area of part `part`, m².
    pub fn part_area_m2(&self, part: usize) -> f64 {
        self.facets_of_part(part).map(|t| self.area_m2(t)).sum()
    }
}

fn bounding_box(vertices: &[Vec3]) -> (Vec3, Vec3) {
    if vertices.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

/// Number of subdivisions of a length at a facet size (at least `min`).
pub(crate) fn divisions(length_m: f64, resolution_m: f64, min: usize) -> usize {
    let n = (length_m / resolution_m - 1e-9).ceil();
    if n.is_finite() && n >= min as f64 {
        (n as usize).min(100_000)
    } else {
        min
    }
}

/// Incremental mesh construction: grids, boxes and cylinders, then vertex welding and
/// centring on the bounding box.
#[derive(Debug, Default)]
pub(crate) struct MeshBuilder {
    vertices: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    part_of: Vec<u16>,
    parts: Vec<Part>,
}

/// A cylinder to add with [`MeshBuilder::cylinder`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct CylinderSpec {
    /// Centre of the base (attached) end, m.
    pub base: Vec3,
    /// Axis direction, base → free end (any non-zero length).
    pub axis: Vec3,
    /// Radius, m.
    pub radius_m: f64,
    /// Length along the axis from the base centre to the free end, m.
    pub length_m: f64,
    /// Normal of the plane the base ring lies in (the face it is attached to); the
    /// axis itself for a square cut.
    pub base_plane_normal: Vec3,
    /// Segments around the circumference.
    pub segments: usize,
    /// Rings along the length.
    pub rings: usize,
    /// Concentric rings of the free-end cap.
    pub cap_rings: usize,
}

impl MeshBuilder {
    pub(crate) fn new() -> Self {
        Self::default()
    }

    /// Adds a part and returns its index.
    pub(crate) fn part(&mut self, part: Part) -> u16 {
        self.parts.push(part);
        (self.parts.len() - 1) as u16
    }

    fn vertex(&mut self, p: Vec3) -> u32 {
        self.vertices.push(p);
        (self.vertices.len() - 1) as u32
    }

    fn tri(&mut self, part: u16, a: u32, b: u32, c: u32) {
        self.triangles.push([a, b, c]);
        self.part_of.push(part);
    }

    /// Two triangles of the quad `[a, b, c, d]` (counter-clockwise from outside), split
    /// along a–c, or along b–d when `flip`. Grids alternate the split in a
    /// checkerboard: with one diagonal direction everywhere, the facet network would
    /// conduct about twice as well along the diagonals as across them.
    fn quad(&mut self, part: u16, flip: bool, [a, b, c, d]: [u32; 4]) {
        if flip {
            self.tri(part, a, b, d);
            self.tri(part, b, c, d);
        } else {
            self.tri(part, a, b, c);
            self.tri(part, a, c, d);
        }
    }

    /// A planar parallelogram `origin + s·u + r·v`, s, r ∈ [0, 1], at facet size
    /// `resolution_m`: ⌈|u|/res⌉ × ⌈|v|/res⌉ cells of two triangles; the outward
    /// normal is along u × v.
    pub(crate) fn grid(&mut self, part: u16, origin: Vec3, u: Vec3, v: Vec3, resolution_m: f64) {
        let nu = divisions(norm(u), resolution_m, 1);
        let nv = divisions(norm(v), resolution_m, 1);
        let base = self.vertices.len() as u32;
        for j in 0..=nv {
            for i in 0..=nu {
                let p = add(
                    origin,
                    add(
                        scale(u, i as f64 / nu as f64),
                        scale(v, j as f64 / nv as f64),
                    ),
                );
                self.vertex(p);
            }
        }
        let id = |i: usize, j: usize| base + (j * (nu + 1) + i) as u32;
        for j in 0..nv {
            for i in 0..nu {
                self.quad(
                    part,
                    (i + j) % 2 == 1,
                    [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                );
            }
        }
    }

    /// The faces of the axis-aligned box `[lo, hi]` whose entry in `faces` is
    /// `Some(part)`, in the order −x, +x, −y, +y, −z, +z.
    pub(crate) fn box_faces(
        &mut self,
        lo: Vec3,
        hi: Vec3,
        faces: [Option<u16>; 6],
        resolution_m: f64,
    ) {
        for (f, part) in faces.iter().enumerate() {
            let Some(part) = *part else { continue };
            let axis = f / 2;
            let positive = f % 2 == 1;
            let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut origin = lo;
            origin[axis] = if positive { hi[axis] } else { lo[axis] };
            let mut e1 = [0.0; 3];
            e1[a1] = hi[a1] - lo[a1];
            let mut e2 = [0.0; 3];
            e2[a2] = hi[a2] - lo[a2];
            // e1 × e2 points along +axis (cyclic order); swap for the negative face.
            let (u, v) = if positive { (e1, e2) } else { (e2, e1) };
            self.grid(part, origin, u, v, resolution_m);
        }
    }

    /// A cylinder side and its free-end cap, open at the base (the base ring lies in
    /// the plane through `base` with normal `base_plane_normal`).
    pub(crate) fn cylinder(&mut self, part: u16, c: CylinderSpec) {
        let a = normalize(c.axis);
        // e1, e2, a right-handed: e1 × e2 = a.
        let helper = if a[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = normalize(cross(helper, a));
        let e2 = cross(a, e1);
        let n = c.segments.max(3);
        let rings = c.rings.max(1);
        let plane = normalize(c.base_plane_normal);
        let radial = |j: usize| {
            let phi = std::f64::consts::TAU * j as f64 / n as f64;
            add(scale(e1, phi.cos()), scale(e2, phi.sin()))
        };
        let base = self.vertices.len() as u32;
        for k in 0..=rings {
            let f = k as f64 / rings as f64;
            for j in 0..n {
                let r = scale(radial(j), c.radius_m);
                // Axial position of the base ring point in the attachment plane.
                let d = dot(plane, a);
                let t0 = if d.abs() > 1e-9 {
                    -dot(plane, r) / d
                } else {
                    0.0
                };
                let t = t0 + (c.length_m - t0) * f;
                let p = add(add(c.base, r), scale(a, t));
                self.vertex(p);
            }
        }
        let id = |j: usize, k: usize| base + (k * n + j % n) as u32;
        for k in 0..rings {
            for j in 0..n {
                self.quad(
                    part,
                    (j + k) % 2 == 1,
                    [id(j, k), id(j + 1, k), id(j + 1, k + 1), id(j, k + 1)],
                );
            }
        }
        // Free-end cap, normal +a: concentric rings, a fan at the centre.
        let end = add(c.base, scale(a, c.length_m));
        let m = c.cap_rings.max(1);
        let centre = self.vertex(end);
        let cap_base = self.vertices.len() as u32;
        for ring in 1..=m {
            let rr = c.radius_m * ring as f64 / m as f64;
            for j in 0..n {
                self.vertex(add(end, scale(radial(j), rr)));
            }
        }
        let q = |ring: usize, j: usize| cap_base + ((ring - 1) * n + j % n) as u32;
        for j in 0..n {
            self.tri(part, centre, q(1, j), q(1, j + 1));
        }
        for ring in 1..m {
            for j in 0..n {
                self.quad(
                    part,
                    (ring + j) % 2 == 1,
                    [
                        q(ring, j),
                        q(ring + 1, j),
                        q(ring + 1, j + 1),
                        q(ring, j + 1),
                    ],
                );
            }
        }
    }

    /// Welds coincident vertices (within 1e-7 m), drops unused ones and moves the
    /// origin to the centre of the bounding box.
    pub(crate) fn finish(self) -> Mesh {
        const TOL: f64 = 1e-7;
        let key = |p: Vec3| -> [i64; 3] { p.map(|x| (x / TOL).floor() as i64) };
        let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
        let mut vertices: Vec<Vec3> = Vec::new();
        let mut remap = vec![u32::MAX; self.vertices.len()];
        let mut used = vec![false; self.vertices.len()];
        for tri in &self.triangles {
            for &v in tri {
                used[v as usize] = true;
            }
        }
        for (old, &p) in self.vertices.iter().enumerate() {
            if !used[old] {
                continue;
            }
            let k = key(p);
            let mut found = None;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(list) = cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &cand in list {
                                if norm(sub(vertices[cand as usize], p)) <= TOL {
                                    found = Some(cand);
                                    break 'search;
                                }
                            }
                        }
                    }
                }
            }
            remap[old] = match found {
                Some(v) => v,
                None => {
                    vertices.push(p);
                    let v = (vertices.len() - 1) as u32;
                    cells.entry(k).or_default().push(v);
                    v
                }
            };
        }
        let triangles: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|v| remap[v as usize]))
            .collect();
        let (lo, hi) = bounding_box(&vertices);
        let centre = scale(add(lo, hi), 0.5);
        for v in &mut vertices {
            *v = sub(*v, centre);
        }
        Mesh {
            vertices,
            triangles,
            part_of: self.part_of,
            parts: self.parts,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const AL: Material = Material {
        name: "al",
        solar_absorptivity: 0.5,
        ir_emissivity: 0.5,
        conductivity_w_m_k: 167.0,
        thickness_m: 1e-3,
        core_conductance_w_m2_k: 0.0,
    };

    fn edge_uses(mesh: &Mesh) -> HashMap<(u32, u32), usize> {
        let mut uses = HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        uses
    }

    #[test]
    fn welded_box_is_closed_and_outward() {
        let mut b = MeshBuilder::new();
        let p = b.part(Part {
            name: "box",
            material: AL,
            dissipation_w: 0.0,
        });
        b.box_faces([0.0, 0.0, 0.0], [2.0, 1.0, 0.5], [Some(p); 6], 0.25);
        let mesh = b.finish();
        assert!(edge_uses(&mesh).values().all(|&n| n == 2));
        assert!((mesh.signed_volume_m3() - 1.0).abs() < 1e-12);
        assert!((mesh.total_area_m2() - 7.0).abs() < 1e-12);
        let (lo, hi) = mesh.bounding_box();
        assert_eq!(lo, [-1.0, -0.5, -0.25]);
        assert_eq!(hi, [1.0, 0.5, 0.25]);
        // Every normal points away from the centre.
        for t in 0..mesh.facet_count() {
            assert!(dot(mesh.normal(t), mesh.centroid(t)) > 0.0);
        }
    }

    #[test]
    fn oblique_cylinder_base_lies_in_its_plane() {
        let mut b = MeshBuilder::new();
        let p = b.part(Part {
            name: "rod",
            material: AL,
            dissipation_w: 0.0,
        });
        b.cylinder(
            p,
            CylinderSpec {
                base: [0.0, 0.0, 0.0],
                axis: [1.0, 1.0, 0.0],
                radius_m: 0.1,
                length_m: 1.0,
                base_plane_normal: [0.0, 1.0, 0.0],
                segments: 12,
                rings: 4,
                cap_rings: 2,
            },
        );
        let mesh = b.finish();
        let uses = edge_uses(&mesh);
        let open: Vec<(u32, u32)> = uses
            .iter()
            .filter(|&(_, &n)| n == 1)
            .map(|(&e, _)| e)
            .collect();
        // Only the base ring is open, and it lies in the plane y = const.
        assert_eq!(open.len(), 12);
        let y0 = mesh.vertices[open[0].0 as usize][1];
        for (a, b) in open {
            assert!((mesh.vertices[a as usize][1] - y0).abs() < 1e-12);
            assert!((mesh.vertices[b as usize][1] - y0).abs() < 1e-12);
        }
        assert!(uses.values().all(|&n| n <= 2));
    }

    #[test]
    fn divisions_round_up_and_floor_at_min() {
        assert_eq!(divisions(1.0, 0.05, 1), 20);
        assert_eq!(divisions(1.0, 0.3, 1), 4);
        assert_eq!(divisions(0.01, 0.05, 1), 1);
        assert_eq!(divisions(1.0, f64::NAN, 3), 3);
        assert_eq!(divisions(1.0, 0.0, 3), 3);
    }
}
