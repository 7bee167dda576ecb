//! Building the network of a mesh ([`ThermalNetwork::new`]): facet geometry, shared
//! edges and their conductances, joints between attached parts, sandwich cores between
//! a panel's two faces, exposure of every
//! facet (enclosed facets neither absorb nor emit).

use super::ThermalNetwork;
use std::collections::HashMap;

use super::error::ThermalError;
use super::illumination::{Bvh, point_line_distance, point_segment_distance};
use super::{CONTACT_TOLERANCE_M, CORE_MAX_DEPTH_M, JOINT_CONDUCTANCE_W_M_K};
use crate::world::geom::{add, cross, dot, norm, scale, sub};
use crate::world::spacecraft::mesh::Mesh;

impl ThermalNetwork {
    /// Builds the network of `mesh` (checks indices, vertices, areas, materials).
    pub fn new(mesh: &Mesh) -> Result<ThermalNetwork, ThermalError> {
        let n = mesh.facet_count();
        if n == 0 {
            return Err(ThermalError::EmptyMesh);
        }
        if mesh.part_of.len() != n {
            return Err(ThermalError::BadIndex {
                facet: mesh.part_of.len().min(n),
            });
        }
        if let Some(v) = mesh
            .vertices
            .iter()
            .position(|v| v.iter().any(|x| !x.is_finite()))
        {
            return Err(ThermalError::BadVertex { vertex: v });
        }
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if tri.iter().any(|&v| v as usize >= mesh.vertices.len())
                || mesh.part_of[t] as usize >= mesh.parts.len()
            {
                return Err(ThermalError::BadIndex { facet: t });
            }
        }
        for part in &mesh.parts {
            let m = &part.material;
            let bad = |reason| {
                Err(ThermalError::BadMaterial {
                    part: part.name,
                    reason,
                })
            };
            if !(0.0..=1.0).contains(&m.solar_absorptivity) {
                return bad("solar absorptivity outside 0..=1");
            }
            if !(m.ir_emissivity > 0.0 && m.ir_emissivity <= 1.0) {
                return bad("infrared emissivity outside (0, 1]");
            }
            if !(m.conductivity_w_m_k.is_finite() && m.conductivity_w_m_k >= 0.0) {
                return bad("conductivity negative or not finite");
            }
            if !(m.thickness_m.is_finite() && m.thickness_m >= 0.0) {
                return bad("thickness negative or not finite");
            }
            if !(m.core_conductance_w_m2_k.is_finite() && m.core_conductance_w_m2_k >= 0.0) {
                return bad("core conductance negative or not finite");
            }
            if !(part.dissipation_w.is_finite() && part.dissipation_w >= 0.0) {
                return bad("dissipation negative or not finite");
            }
        }
        let mut area = Vec::with_capacity(n);
        let mut normal = Vec::with_capacity(n);
        let mut centroid = Vec::with_capacity(n);
        let mut tris = Vec::with_capacity(n);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let p = tri.map(|v| mesh.vertices[v as usize]);
            let c = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            let a = 0.5 * norm(c);
            if !(a.is_finite() && a > 0.0) {
                return Err(ThermalError::DegenerateFacet {
                    facet: t,
                    area_m2: a,
                });
            }
            area.push(a);
            normal.push(scale(c, 0.5 / a));
            centroid.push(scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0));
            tris.push(p);
        }
        let mat = |t: usize| mesh.material(t);
        let alpha: Vec<f64> = (0..n).map(|t| mat(t).solar_absorptivity).collect();
        let eps: Vec<f64> = (0..n).map(|t| mat(t).ir_emissivity).collect();
        let kt: Vec<f64> = (0..n)
            .map(|t| mat(t).conductivity_w_m_k * mat(t).thickness_m)
            .collect();
        let mut part_area = vec![0.0; mesh.parts.len()];
        for t in 0..n {
            part_area[mesh.part_of[t] as usize] += area[t];
        }
        let dissipation: Vec<f64> = (0..n)
            .map(|t| {
                let p = mesh.part_of[t] as usize;
                mesh.parts[p].dissipation_w * area[t] / part_area[p]
            })
            .collect();

        let radius = mesh.bounding_radius_m().max(1e-3);
        let ray_eps = 1e-7 * radius;
        let bvh = Bvh::new(tris);

        // Edges: vertex pair → facets using it.
        let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(3 * n / 2);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(t as u32);
            }
        }
        let vtx = |v: u32| mesh.vertices[v as usize];
        let series = |i: usize, di: f64, j: usize, dj: f64, len: f64, extra: f64| -> f64 {
            if kt[i] <= 0.0 || kt[j] <= 0.0 || len <= 0.0 {
                return 0.0;
            }
            let r = di / (kt[i] * len) + dj / (kt[j] * len) + extra;
            if r > 0.0 && r.is_finite() {
                1.0 / r
            } else {
                0.0
            }
        };
        let mut links: HashMap<(u32, u32), f64> = HashMap::with_capacity(3 * n / 2);
        let mut open_edges: Vec<(usize, u32, u32)> = Vec::new();
        let mut open_by_facet: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
        for (&(a, b), facets) in &edges {
            if facets.len() == 1 {
                open_edges.push((facets[0] as usize, a, b));
                open_by_facet.entry(facets[0]).or_default().push((a, b));
                continue;
            }
            let (pa, pb) = (vtx(a), vtx(b));
            let len = norm(sub(pb, pa));
            for x in 0..facets.len() {
                for y in x + 1..facets.len() {
                    let (i, j) = (facets[x] as usize, facets[y] as usize);
                    let di = point_line_distance(centroid[i], pa, pb);
                    let dj = point_line_distance(centroid[j], pa, pb);
                    let g = series(i, di, j, dj, len, 0.0);
                    if g > 0.0 && i != j {
                        *links
                            .entry((i.min(j) as u32, i.max(j) as u32))
                            .or_insert(0.0) += g;
                    }
                }
            }
        }
        // Joints: open edges whose midpoint lies on another facet.
        open_edges.sort_unstable();
        let mut joints = 0;
        let mut free_edges = 0;
        for &(i, a, b) in &open_edges {
            let (pa, pb) = (vtx(a), vtx(b));
            let mid = scale(add(pa, pb), 0.5);
            let mut best: Option<(usize, f64)> = None;
            bvh.near(mid, CONTACT_TOLERANCE_M, |j, d| {
                if j != i && best.is_none_or(|(bj, bd)| d < bd || (d == bd && j < bj)) {
                    best = Some((j, d));
                }
            });
            let Some((j, _)) = best else {
                free_edges += 1;
                continue;
            };
            let seam = open_by_facet.get(&(j as u32)).is_some_and(|list| {
                list.iter().any(|&(c, d)| {
                    point_segment_distance(mid, vtx(c), vtx(d)) <= CONTACT_TOLERANCE_M
                })
            });
            let same_part = mesh.part_of[i] == mesh.part_of[j];
            if seam && (mesh.part_of[i], i) > (mesh.part_of[j], j) {
                continue; // counted from the other side
            }
            let len = norm(sub(pb, pa));
            let extra = if seam && same_part {
                0.0
            } else {
                1.0 / (JOINT_CONDUCTANCE_W_M_K * len)
            };
            let di = point_line_distance(centroid[i], pa, pb);
            let dj = norm(sub(centroid[j], mid));
            let g = series(i, di, j, dj, len, extra);
            if g > 0.0 {
                *links
                    .entry((i.min(j) as u32, i.max(j) as u32))
                    .or_insert(0.0) += g;
                joints += 1;
            }
        }

        // Sandwich cores: a facet of a cored material to the facet its inward ray meets
        // first, when that faces the other way (the panel's other face) within
        // CORE_MAX_DEPTH_M; h·A/2 from each side, so a pair of aligned faces links h·A.
        for i in 0..n {
            let h = mat(i).core_conductance_w_m2_k;
            if h <= 0.0 {
                continue;
            }
            let inward = scale(normal[i], -1.0);
            let o = add(centroid[i], scale(inward, ray_eps));
            if let Some((j, depth)) = bvh.closest_hit(o, inward, i)
                && depth <= CORE_MAX_DEPTH_M
                && dot(normal[j], normal[i]) < 0.0
            {
                *links
                    .entry((i.min(j) as u32, i.max(j) as u32))
                    .or_insert(0.0) += 0.5 * h * area[i];
            }
        }

        // CSR, symmetric.
        let mut degree = vec![0u32; n];
        for &(i, j) in links.keys() {
            degree[i as usize] += 1;
            degree[j as usize] += 1;
        }
        let mut row = vec![0u32; n + 1];
        for i in 0..n {
            row[i + 1] = row[i] + degree[i];
        }
        let mut fill = row.clone();
        let mut col = vec![0u32; row[n] as usize];
        let mut g = vec![0.0; row[n] as usize];
        let mut sorted: Vec<((u32, u32), f64)> = links.into_iter().collect();
        sorted.sort_unstable_by_key(|&(k, _)| k);
        for ((i, j), v) in sorted {
            for (p, q) in [(i, j), (j, i)] {
                let at = fill[p as usize] as usize;
                col[at] = q;
                g[at] = v;
                fill[p as usize] += 1;
            }
        }
        let g_sum: Vec<f64> = (0..n)
            .map(|i| g[row[i] as usize..row[i + 1] as usize].iter().sum())
            .collect();

        // Enclosed facets: the outward ray first meets the inner side of a facet.
        let exposed: Vec<bool> = (0..n)
            .map(|i| {
                let o = add(centroid[i], scale(normal[i], ray_eps));
                match bvh.closest_hit(o, normal[i], i) {
                    Some((j, _)) => dot(normal[j], normal[i]) <= 0.0,
                    None => true,
                }
            })
            .collect();

        // Conduction components; enclosed groups without a radiating facet.
        let mut component = vec![u32::MAX; n];
        let mut components = 0u32;
        let mut pinned = vec![false; n];
        let mut stack = Vec::new();
        let mut members = Vec::new();
        for s in 0..n {
            if component[s] != u32::MAX {
                continue;
            }
            members.clear();
            component[s] = components;
            stack.push(s);
            while let Some(i) = stack.pop() {
                members.push(i);
                for &j in &col[row[i] as usize..row[i + 1] as usize] {
                    if component[j as usize] == u32::MAX {
                        component[j as usize] = components;
                        stack.push(j as usize);
                    }
                }
            }
            if !members.iter().any(|&i| exposed[i]) {
                if let Some(&i) = members.iter().find(|&&i| dissipation[i] > 0.0) {
                    return Err(ThermalError::NoSteadyState { facet: i });
                }
                for &i in &members {
                    pinned[i] = true;
                }
            }
            components += 1;
        }

        Ok(ThermalNetwork {
            area,
            normal,
            centroid,
            alpha,
            eps,
            dissipation,
            exposed,
            pinned,
            component,
            components: components as usize,
            row,
            col,
            g,
            g_sum,
            joints,
            free_edges,
            bvh,
            ray_eps,
        })
    }

    /// Number of nodes (facets).
    pub fn facet_count(&self) -> usize {
        self.area.len()
    }

    /// Whether facet `t` exchanges radiation with the environment (false for facets
    /// enclosed by an attached part). Panics if `t` is out of range.
    pub fn is_exposed(&self, t: usize) -> bool {
        self.exposed[t]
    }

    /// Number of conductive links between facets (each pair once).
    pub fn link_count(&self) -> usize {
        self.col.len() / 2
    }

    /// Number of joint conductances added from open edges (an open edge on another
    /// facet, through [`JOINT_CONDUCTANCE_W_M_K`], or a seam of two open edges,
    /// counted once).
    pub fn joint_count(&self) -> usize {
        self.joints
    }

    /// Number of open edges that touch no other facet: free edges of the mesh (0 for
    /// a closed target; heat does not cross them).
    pub fn free_edge_count(&self) -> usize {
        self.free_edges
    }

    /// Number of conductively connected groups of facets.
    pub fn component_count(&self) -> usize {
        self.components
    }

    /// Conductance between facets `i` and `j`, W K⁻¹ (0 when not linked or out of
    /// range).
    pub fn conductance_w_k(&self, i: usize, j: usize) -> f64 {
        if i >= self.facet_count() || j >= self.facet_count() {
            return 0.0;
        }
        let (s, e) = (self.row[i] as usize, self.row[i + 1] as usize);
        self.col[s..e]
            .iter()
            .zip(&self.g[s..e])
            .filter(|&(&c, _)| c as usize == j)
            .map(|(_, &g)| g)
            .sum()
    }
}
