//! What a facet receives: the Earth view factor of a plate, shadows by ray casting
//! through a bounding-volume hierarchy, and the absorbed power of every facet
//! ([`ThermalNetwork::absorbed_w`]); plus the point–triangle distances joints use.

use super::ThermalNetwork;

use super::ThermalEnvironment;
use super::error::ThermalError;
use super::solver::checked;
use crate::world::geom::{Vec3, add, cross, dot, norm, scale, sub};

/// View factor from a differential plate to a sphere (the Earth), 0..=1.
///
/// `distance_over_radius` H = d/R ≥ 1 (d from the sphere's centre; values below 1
/// count as 1), `cos_lambda` = cosine of the angle λ between the plate's normal and
/// the direction to the sphere's centre. With x = √(H² − 1):
///
/// - cos λ ≥ 1/H (the whole sphere above the plate's horizon): F = cos λ / H²;
/// - cos λ ≤ −1/H (the sphere below the horizon): F = 0;
/// - otherwise F = ½ − (1/π)·asin(x/(H sin λ)) + (1/(πH²))·[cos λ·acos(−x cot λ)
///   − x·√(1 − H² cos² λ)].
///
/// Source: J. R. Howell, *A Catalog of Radiation Heat Transfer Configuration
/// Factors* (differential planar element to a sphere, element tilted), the form used
/// for planetary view factors in Gilmore, *Spacecraft Thermal Control Handbook*, Vol. I,
/// ch. 2. At H = 1 it gives (1 + cos λ)/2, the plate on the ground.
pub fn earth_view_factor(distance_over_radius: f64, cos_lambda: f64) -> f64 {
    if distance_over_radius.is_nan() || cos_lambda.is_nan() {
        return 0.0;
    }
    let h = distance_over_radius.max(1.0);
    let c = cos_lambda.clamp(-1.0, 1.0);
    if c >= 1.0 / h {
        return c / (h * h);
    }
    if c <= -1.0 / h {
        return 0.0;
    }
    let s = (1.0 - c * c).sqrt();
    let x = (h * h - 1.0).sqrt();
    let pi = std::f64::consts::PI;
    let f = 0.5 - (x / (h * s)).clamp(-1.0, 1.0).asin() / pi
        + (c * (-x * c / s).clamp(-1.0, 1.0).acos() - x * (1.0 - h * h * c * c).max(0.0).sqrt())
            / (pi * h * h);
    f.clamp(0.0, 1.0)
}

/// A bounding-volume hierarchy over the facets, for shadow and enclosure rays and the
/// joint search.
#[derive(Debug, Clone)]
pub(super) struct Bvh {
    nodes: Vec<BvhNode>,
    order: Vec<u32>,
    tris: Vec<[Vec3; 3]>,
}

#[derive(Debug, Clone, Copy)]
struct BvhNode {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first index into `order`; inner: index of the right child (left = next).
    start: u32,
    /// Leaf: number of facets (> 0); inner: 0.
    count: u32,
}

impl Bvh {
    pub(super) fn new(tris: Vec<[Vec3; 3]>) -> Bvh {
        let mut order: Vec<u32> = (0..tris.len() as u32).collect();
        let centroids: Vec<Vec3> = tris
            .iter()
            .map(|t| scale(add(add(t[0], t[1]), t[2]), 1.0 / 3.0))
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(tris.len() / 2 + 1),
            order: Vec::new(),
            tris,
        };
        if !order.is_empty() {
            let n = order.len();
            bvh.build(&mut order, 0, n, &centroids);
        }
        bvh.order = order;
        bvh
    }

    pub(super) fn build(
        &mut self,
        order: &mut [u32],
        start: usize,
        end: usize,
        centroids: &[Vec3],
    ) -> usize {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let mut clo = [f64::INFINITY; 3];
        let mut chi = [f64::NEG_INFINITY; 3];
        for &t in &order[start..end] {
            for p in self.tris[t as usize] {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            let c = centroids[t as usize];
            for k in 0..3 {
                clo[k] = clo[k].min(c[k]);
                chi[k] = chi[k].max(c[k]);
            }
        }
        let index = self.nodes.len();
        self.nodes.push(BvhNode {
            lo,
            hi,
            start: start as u32,
            count: (end - start) as u32,
        });
        if end - start <= 4 {
            return index;
        }
        let axis = (0..3)
            .max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b])))
            .unwrap_or(0);
        let mid = (start + end) / 2;
        order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        self.build(order, start, mid, centroids);
        let right = self.build(order, mid, end, centroids);
        self.nodes[index].start = right as u32;
        self.nodes[index].count = 0;
        index
    }

    /// Nearest facet hit by the ray `origin + t·dir`, t > 0, other than `skip`.
    pub(super) fn closest_hit(&self, origin: Vec3, dir: Vec3, skip: usize) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        self.traverse_ray(origin, dir, |t, dist| {
            if t != skip && best.is_none_or(|(_, d)| dist < d) {
                best = Some((t, dist));
            }
            best.map_or(f64::INFINITY, |(_, d)| d)
        });
        best
    }

    /// Whether the ray `origin + t·dir`, t > 0, hits any facet other than `skip`.
    pub(super) fn any_hit(&self, origin: Vec3, dir: Vec3, skip: usize) -> bool {
        let mut hit = false;
        self.traverse_ray(origin, dir, |t, _| {
            hit |= t != skip;
            if hit {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            }
        });
        hit
    }

    /// Calls `on_hit(facet, t)` for the facets hit, in boxes entered before the limit
    /// it returns (−∞ stops the traversal).
    fn traverse_ray(&self, origin: Vec3, dir: Vec3, mut on_hit: impl FnMut(usize, f64) -> f64) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = dir.map(|d| 1.0 / d);
        let mut limit = f64::INFINITY;
        let mut stack = Vec::with_capacity(64);
        stack.push(0usize);
        while let Some(i) = stack.pop() {
            let node = self.nodes[i];
            let Some(entry) = slab(origin, inv, node.lo, node.hi) else {
                continue;
            };
            if entry > limit {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                for &t in &self.order[s..s + node.count as usize] {
                    if let Some(dist) = ray_triangle(origin, dir, &self.tris[t as usize]) {
                        limit = on_hit(t as usize, dist);
                        if limit == f64::NEG_INFINITY {
                            return;
                        }
                    }
                }
            } else {
                stack.push(node.start as usize);
                stack.push(i + 1);
            }
        }
    }

    /// Facets within `tol` of `p`, with their distances.
    pub(super) fn near(&self, p: Vec3, tol: f64, mut f: impl FnMut(usize, f64)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let node = self.nodes[i];
            if (0..3).any(|k| p[k] < node.lo[k] - tol || p[k] > node.hi[k] + tol) {
                continue;
            }
            if node.count > 0 {
                let s = node.start as usize;
                for &t in &self.order[s..s + node.count as usize] {
                    let d = point_triangle_distance(p, &self.tris[t as usize]);
                    if d <= tol {
                        f(t as usize, d);
                    }
                }
            } else {
                stack.push(node.start as usize);
                stack.push(i + 1);
            }
        }
    }
}

/// Entry distance of a ray into a box, if it meets it at t ≥ 0.
fn slab(origin: Vec3, inv: Vec3, lo: Vec3, hi: Vec3) -> Option<f64> {
    let mut t0 = 0.0_f64;
    let mut t1 = f64::INFINITY;
    for k in 0..3 {
        let a = (lo[k] - origin[k]) * inv[k];
        let b = (hi[k] - origin[k]) * inv[k];
        // NaN (0·∞ for a ray in the slab's plane) is ignored by min/max.
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t0 <= t1).then_some(t0)
}

/// Möller–Trumbore, two-sided: distance t > 0 along `dir` (unit) to the triangle.
pub(super) fn ray_triangle(origin: Vec3, dir: Vec3, tri: &[Vec3; 3]) -> Option<f64> {
    let e1 = sub(tri[1], tri[0]);
    let e2 = sub(tri[2], tri[0]);
    let p = cross(dir, e2);
    let det = dot(e1, p);
    let scale_ref = norm(e1) * norm(e2);
    if det.abs() <= 1e-14 * scale_ref {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(origin, tri[0]);
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, e1);
    let v = dot(dir, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = dot(e2, q) * inv;
    (t > 0.0).then_some(t)
}

/// Distance from `p` to the closest point of the triangle (Ericson, *Real-Time
/// Collision Detection*, 5.1.5).
pub(super) fn point_triangle_distance(p: Vec3, tri: &[Vec3; 3]) -> f64 {
    let [a, b, c] = *tri;
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return norm(ap);
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return norm(bp);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return norm(sub(p, add(a, scale(ab, v))));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return norm(cp);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return norm(sub(p, add(a, scale(ac, w))));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return norm(sub(p, add(b, scale(sub(c, b), w))));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    norm(sub(p, add(a, add(scale(ab, v), scale(ac, w)))))
}

/// Distance from `p` to the segment [a, b].
pub(super) fn point_segment_distance(p: Vec3, a: Vec3, b: Vec3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, add(a, scale(ab, t))))
}

/// Distance from `p` to the line through a and b.
pub(super) fn point_line_distance(p: Vec3, a: Vec3, b: Vec3) -> f64 {
    let ab = sub(b, a);
    let l = norm(ab);
    if l > 0.0 {
        norm(cross(sub(p, a), ab)) / l
    } else {
        norm(sub(p, a))
    }
}

impl ThermalNetwork {
    /// Absorbed environmental power of every facet, W (Sun with shadows, Earth
    /// infrared, albedo; zero for enclosed facets).
    pub fn absorbed_w(&self, env: &ThermalEnvironment) -> Result<Vec<f64>, ThermalError> {
        let env = checked(env)?;
        let n = self.facet_count();
        let h = env.earth_distance_m / env.earth_radius_m;
        let e = env.earth_dir_body;
        let albedo_scale = env.albedo * env.solar_constant_w_m2 * env.sun_earth_cos.clamp(0.0, 1.0);
        let q = (0..n)
            .map(|i| {
                if !self.exposed[i] {
                    return 0.0;
                }
                let nrm = self.normal[i];
                let f = earth_view_factor(h, dot(nrm, e));
                let mut q = self.eps[i] * env.earth_olr_w_m2 * f;
                if let Some(s) = env.sun_dir_body {
                    q += self.alpha[i] * albedo_scale * f;
                    let c = dot(nrm, s);
                    if c > 0.0 {
                        let o = add(self.centroid[i], scale(nrm, self.ray_eps));
                        if !self.bvh.any_hit(o, s, i) {
                            q += self.alpha[i] * env.solar_constant_w_m2 * c;
                        }
                    }
                }
                q * self.area[i]
            })
            .collect();
        Ok(q)
    }
}
