//! The steady-state solve ([`ThermalNetwork::solve`]): Newton steps, each a
//! preconditioned conjugate-gradient solve of the Jacobian, and the
//! [`ThermalSolution`] it returns.

use super::ThermalNetwork;

use super::error::ThermalError;
use super::{MAX_NEWTON_ITERATIONS, RESIDUAL_TOLERANCE, SIGMA, ThermalEnvironment};
use crate::world::geom::{Vec3, norm, scale};
use crate::world::spacecraft::mesh::Mesh;

/// Steady-state facet temperatures and the power balance.
#[derive(Debug, Clone, PartialEq)]
pub struct ThermalSolution {
    /// Temperature of every facet, K (mesh order).
    pub temperature_k: Vec<f64>,
    /// Absorbed solar, albedo and Earth infrared power, W.
    pub absorbed_w: f64,
    /// Power emitted to space, Σ εσA(T⁴ − T_space⁴) over exposed facets, W.
    pub emitted_w: f64,
    /// Internal dissipation, W.
    pub dissipated_w: f64,
    /// Newton steps taken.
    pub iterations: usize,
    /// Largest nodal residual at the solution, W.
    pub max_residual_w: f64,
}

impl ThermalSolution {
    /// |absorbed + dissipated − emitted| / (absorbed + dissipated): below 1e-6 at a
    /// converged solution (the absolute difference in W when no power enters).
    pub fn energy_balance_rel(&self) -> f64 {
        let input = self.absorbed_w + self.dissipated_w;
        let diff = (input - self.emitted_w).abs();
        if input > 0.0 { diff / input } else { diff }
    }

    /// Lowest and highest facet temperature, K ((NaN, NaN) for no facets).
    pub fn min_max_k(&self) -> (f64, f64) {
        min_max(self.temperature_k.iter().copied())
    }

    /// Lowest and highest temperature of the facets of part `part` of `mesh`, K
    /// (`None` when the part has no facets or `mesh` is not the solved one).
    pub fn part_min_max_k(&self, mesh: &Mesh, part: usize) -> Option<(f64, f64)> {
        if mesh.facet_count() != self.temperature_k.len() {
            return None;
        }
        let mut it = mesh.facets_of_part(part).peekable();
        it.peek()?;
        Some(min_max(it.map(|t| self.temperature_k[t])))
    }

    /// Temperature at every vertex of `mesh`, K: the area-weighted mean of the facets
    /// that use it (facets of different parts sharing a vertex included), for smooth
    /// shading; NaN for a vertex no facet uses. `None` when `mesh` is not the solved
    /// one (facet counts differ) or a vertex index is out of range.
    pub fn vertex_temperatures_k(&self, mesh: &Mesh) -> Option<Vec<f64>> {
        if mesh.facet_count() != self.temperature_k.len() {
            return None;
        }
        let nv = mesh.vertices.len();
        let mut sum = vec![0.0; nv];
        let mut weight = vec![0.0; nv];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if tri.iter().any(|&v| v as usize >= nv) {
                return None;
            }
            let a = mesh.area_m2(t);
            for &v in tri {
                sum[v as usize] += a * self.temperature_k[t];
                weight[v as usize] += a;
            }
        }
        Some(
            sum.iter()
                .zip(&weight)
                .map(|(s, w)| if *w > 0.0 { s / w } else { f64::NAN })
                .collect(),
        )
    }
}

fn min_max(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let mut lo = f64::NAN;
    let mut hi = f64::NAN;
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (lo, hi)
}

impl ThermalNetwork {
    /// Steady-state temperatures in `env`.
    pub fn solve(&self, env: &ThermalEnvironment) -> Result<ThermalSolution, ThermalError> {
        let env = checked(env)?;
        let q = self.absorbed_w(&env)?;
        self.solve_absorbed(&q, env.deep_space_k)
    }

    /// Steady-state temperatures for given absorbed powers `q` (W per facet, as
    /// [`ThermalNetwork::absorbed_w`] returns) and sink temperature `ts` (K).
    pub(super) fn solve_absorbed(
        &self,
        q: &[f64],
        ts: f64,
    ) -> Result<ThermalSolution, ThermalError> {
        let n = self.facet_count();
        let ts4 = ts.powi(4);
        let absorbed: f64 = q.iter().sum();
        let dissipated: f64 = self.dissipation.iter().sum();
        let input: Vec<f64> = (0..n).map(|i| q[i] + self.dissipation[i]).collect();
        let rad = self.radiative_coupling();

        // Start: the larger of the facet's own radiative equilibrium and its
        // component's uniform equilibrium.
        let mut comp_in = vec![0.0; self.components];
        let mut comp_rad = vec![0.0; self.components];
        for i in 0..n {
            comp_in[self.component[i] as usize] += input[i];
            comp_rad[self.component[i] as usize] += rad[i];
        }
        let mut temp: Vec<f64> = (0..n)
            .map(|i| {
                if self.pinned[i] {
                    return ts;
                }
                let c = self.component[i] as usize;
                let uniform = (comp_in[c] / comp_rad[c] + ts4).sqrt().sqrt();
                let own = if rad[i] > 0.0 {
                    (input[i] / rad[i] + ts4).sqrt().sqrt()
                } else {
                    uniform
                };
                own.max(uniform)
            })
            .collect();

        let tolerance = RESIDUAL_TOLERANCE * (absorbed + dissipated);
        let mut residual = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut step = vec![0.0; n];
        let mut work = CgWork::new(n);
        let mut iterations = 0;
        loop {
            let max_r = self.residual(&temp, &input, &rad, ts4, &mut residual);
            if !max_r.is_finite() {
                return Err(ThermalError::NoConvergence {
                    iterations,
                    residual_w: max_r,
                    tolerance_w: tolerance,
                });
            }
            if max_r <= tolerance {
                let emitted = (0..n).map(|i| rad[i] * (temp[i].powi(4) - ts4)).sum();
                return Ok(ThermalSolution {
                    temperature_k: temp,
                    absorbed_w: absorbed,
                    emitted_w: emitted,
                    dissipated_w: dissipated,
                    iterations,
                    max_residual_w: max_r,
                });
            }
            if iterations >= MAX_NEWTON_ITERATIONS {
                return Err(ThermalError::NoConvergence {
                    iterations,
                    residual_w: max_r,
                    tolerance_w: tolerance,
                });
            }
            for i in 0..n {
                diag[i] = if self.pinned[i] {
                    1.0
                } else {
                    self.g_sum[i] + 4.0 * rad[i] * temp[i].powi(3)
                };
            }
            let lin_tol = (1e-3 * max_r).max(0.25 * tolerance);
            self.pcg(&diag, &residual, lin_tol, &mut step, &mut work);
            for i in 0..n {
                if !self.pinned[i] {
                    // The solution is ≥ the sink temperature (maximum principle):
                    // projecting onto T ≥ T_space only moves towards it.
                    temp[i] = (temp[i] + step[i]).max(ts);
                }
            }
            iterations += 1;
        }
    }

    /// Radiative coupling εσA of every exposed facet (0 for enclosed ones), W K⁻⁴.
    pub(super) fn radiative_coupling(&self) -> Vec<f64> {
        (0..self.facet_count())
            .map(|i| {
                if self.exposed[i] {
                    self.eps[i] * SIGMA * self.area[i]
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// Nodal residuals R = input − εσA(T⁴ − Ts⁴) − Σ G (Tᵢ − Tⱼ); returns max |R|.
    pub(super) fn residual(
        &self,
        temp: &[f64],
        input: &[f64],
        rad: &[f64],
        ts4: f64,
        out: &mut [f64],
    ) -> f64 {
        let mut max_r = 0.0_f64;
        for i in 0..temp.len() {
            if self.pinned[i] {
                out[i] = 0.0;
                continue;
            }
            let (s, e) = (self.row[i] as usize, self.row[i + 1] as usize);
            let mut cond = 0.0;
            for (&j, &g) in self.col[s..e].iter().zip(&self.g[s..e]) {
                cond += g * (temp[i] - temp[j as usize]);
            }
            let r = input[i] - rad[i] * (temp[i].powi(4) - ts4) - cond;
            out[i] = r;
            if r.is_nan() {
                return f64::NAN;
            }
            max_r = max_r.max(r.abs());
        }
        max_r
    }

    /// y = (diag − offdiag G)·x.
    pub(super) fn apply(&self, diag: &[f64], x: &[f64], y: &mut [f64]) {
        for i in 0..x.len() {
            let (s, e) = (self.row[i] as usize, self.row[i + 1] as usize);
            let mut acc = diag[i] * x[i];
            if !self.pinned[i] {
                for (&j, &g) in self.col[s..e].iter().zip(&self.g[s..e]) {
                    acc -= g * x[j as usize];
                }
            }
            y[i] = acc;
        }
    }

    /// Jacobi-preconditioned conjugate gradients for (L + diag)·x = b, until
    /// max |residual| ≤ `tol` (or 4n + 100 iterations).
    pub(super) fn pcg(&self, diag: &[f64], b: &[f64], tol: f64, x: &mut [f64], w: &mut CgWork) {
        let n = b.len();
        x.fill(0.0);
        w.r.copy_from_slice(b);
        for ((z, r), d) in w.z.iter_mut().zip(&w.r).zip(diag) {
            *z = r / d;
        }
        w.p.copy_from_slice(&w.z);
        let mut rz: f64 = w.r.iter().zip(&w.z).map(|(a, b)| a * b).sum();
        for _ in 0..4 * n + 100 {
            if w.r.iter().fold(0.0_f64, |m, v| m.max(v.abs())) <= tol || rz == 0.0 {
                break;
            }
            self.apply(diag, &w.p, &mut w.ap);
            let pap: f64 = w.p.iter().zip(&w.ap).map(|(a, b)| a * b).sum();
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let a = rz / pap;
            for i in 0..n {
                x[i] += a * w.p[i];
                w.r[i] -= a * w.ap[i];
                w.z[i] = w.r[i] / diag[i];
            }
            let rz_new: f64 = w.r.iter().zip(&w.z).map(|(a, b)| a * b).sum();
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                w.p[i] = w.z[i] + beta * w.p[i];
            }
        }
    }
}
#[derive(Debug)]
pub(super) struct CgWork {
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    ap: Vec<f64>,
}

impl CgWork {
    pub(super) fn new(n: usize) -> Self {
        CgWork {
            r: vec![0.0; n],
            z: vec![0.0; n],
            p: vec![0.0; n],
            ap: vec![0.0; n],
        }
    }
}

/// The environment with unit directions, or the first field out of bounds.
pub(super) fn checked(env: &ThermalEnvironment) -> Result<ThermalEnvironment, ThermalError> {
    let bad = |reason| Err(ThermalError::BadEnvironment { reason });
    let unit = |v: Vec3| {
        let l = norm(v);
        (l.is_finite() && l > 0.0).then(|| scale(v, 1.0 / l))
    };
    let mut env = *env;
    if let Some(s) = env.sun_dir_body {
        match unit(s) {
            Some(u) => env.sun_dir_body = Some(u),
            None => return bad("sun direction is zero or not finite"),
        }
    }
    match unit(env.earth_dir_body) {
        Some(u) => env.earth_dir_body = u,
        None => return bad("Earth direction is zero or not finite"),
    }
    if !(env.solar_constant_w_m2.is_finite() && env.solar_constant_w_m2 >= 0.0) {
        return bad("solar constant negative or not finite");
    }
    if !(env.earth_radius_m.is_finite() && env.earth_radius_m > 0.0) {
        return bad("Earth radius not positive and finite");
    }
    if !(env.earth_distance_m.is_finite() && env.earth_distance_m > env.earth_radius_m) {
        return bad("Earth distance not finite or not above the Earth radius");
    }
    if !(env.earth_olr_w_m2.is_finite() && env.earth_olr_w_m2 >= 0.0) {
        return bad("Earth OLR negative or not finite");
    }
    if !(0.0..=1.0).contains(&env.albedo) {
        return bad("albedo outside 0..=1");
    }
    if env.sun_earth_cos.is_nan() {
        return bad("sun_earth_cos is NaN");
    }
    if !(env.deep_space_k.is_finite() && env.deep_space_k > 0.0) {
        return bad("deep-space temperature not positive and finite");
    }
    Ok(env)
}
