//! Transient temperatures: heat capacity per facet, one implicit time step
//! ([`ThermalNetwork::step`]) and the periodic state on an orbit
//! ([`ThermalNetwork::periodic_orbit`]).
//!
//! Every facet i stores Cᵢ = cᵢ Aᵢ (cᵢ the areal heat capacity of its part's material,
//! [`areal_heat_capacity_j_m2_k`]) and follows
//!
//! ```text
//! Cᵢ dTᵢ/dt = Qᵢ(t) + Pᵢ − εᵢσAᵢ(Tᵢ⁴ − T_space⁴) − Σⱼ Gᵢⱼ(Tᵢ − Tⱼ)
//! ```
//!
//! Time stepping: backward Euler, Cᵢ(Tᵢⁿ⁺¹ − Tᵢⁿ)/Δt = right-hand side at Tⁿ⁺¹ with
//! the absorbed power at the step's midpoint time, solved by Newton's method; every
//! Newton step is the steady solver's preconditioned conjugate gradient solve with
//! C/Δt added to the Jacobian's diagonal (it stays symmetric positive definite and is
//! better conditioned than the steady one). The scheme is unconditionally stable and
//! conserves energy exactly per step: Σ C ΔT = Δt·(absorbed + dissipated − emitted at
//! Tⁿ⁺¹), conduction cancelling (checked by [`StepBalance`]). Its error is first order
//! in Δt: with [`TRANSIENT_STEP_S`] = 30 s and the shortest time constant of the
//! targets' skins (a sunlit 2 mm aluminium face at 350 K, C/(4εσT³) ≈ 600 s) the lag
//! behind the exact solution after a sunrise is about Δt/2 = 15 s.
//!
//! Orbit: [`ThermalNetwork::periodic_orbit`] steps the grid of the orbit (eclipse and
//! sunlit arcs each cut into equal steps of at most `step_s`, so the shadow's entry and
//! exit are grid times), starting from the steady state of the orbit-averaged absorbed
//! power, until one orbit changes no facet by more than [`PERIODIC_TOLERANCE_K`]
//! (max |T(t + P) − T(t)|). The slowest mode (the whole body's mean temperature,
//! time constants up to several orbits for the low-emissivity cases) is accelerated:
//! after each orbit the change d is extrapolated with the observed contraction ρ =
//! d·d_prev / d_prev·d_prev of the orbit map, T += ρ/(1 − ρ)·d (0 < ρ < 0.9); the
//! convergence test always uses an un-extrapolated orbit.

use rayon::prelude::*;

use super::ThermalError;
use super::orbit::{Orbit, OrbitGeometry};
use super::solver::{CgWork, checked};
use super::{MAX_NEWTON_ITERATIONS, RESIDUAL_TOLERANCE, ThermalEnvironment, ThermalNetwork};
use crate::world::spacecraft::mesh::Mesh;
use crate::world::spacecraft::models::areal_heat_capacity_j_m2_k;

/// Default largest time step on an orbit, s: 376 steps per reference orbit; small
/// against the shortest skin time constant (≈ 600 s, module docs).
pub const TRANSIENT_STEP_S: f64 = 30.0;

/// An orbit counts as periodic when no facet changes by more than this over one
/// orbit, K.
pub const PERIODIC_TOLERANCE_K: f64 = 0.1;

/// Orbits integrated before [`ThermalError::NotPeriodic`].
pub const MAX_ORBITS: usize = 60;

/// Largest contraction ratio of the orbit map used to extrapolate (the jump is
/// ρ/(1 − ρ) = 9 orbit changes at most).
const MAX_EXTRAPOLATION_RATIO: f64 = 0.9;

/// Heat capacity of every facet of `mesh`, J K⁻¹: the areal capacity of its part's
/// material ([`areal_heat_capacity_j_m2_k`]) × its area.
pub fn facet_heat_capacities_j_k(mesh: &Mesh) -> Vec<f64> {
    (0..mesh.facet_count())
        .map(|t| areal_heat_capacity_j_m2_k(mesh.material(t)) * mesh.area_m2(t))
        .collect()
}

/// The energy balance of one time step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepBalance {
    /// Change of the stored energy Σ Cᵢ(Tᵢⁿ⁺¹ − Tᵢⁿ), J.
    pub stored_j: f64,
    /// Net input Δt·Σ(Qᵢ + Pᵢ − εᵢσAᵢ(Tᵢⁿ⁺¹⁴ − T_space⁴)), J.
    pub net_input_j: f64,
    /// Gross energy flow Δt·Σ(Qᵢ + Pᵢ + εᵢσAᵢTᵢⁿ⁺¹⁴), J (the scale of the balance).
    pub gross_j: f64,
    /// Newton steps taken.
    pub newton_iterations: usize,
}

impl StepBalance {
    /// |stored − net input| / gross flow (0 when nothing flows).
    pub fn error_rel(&self) -> f64 {
        let d = (self.stored_j - self.net_input_j).abs();
        if self.gross_j > 0.0 {
            d / self.gross_j
        } else {
            d
        }
    }
}

/// One sampled state of the periodic orbit.
#[derive(Debug, Clone, PartialEq)]
pub struct OrbitState {
    /// Where the target is: time since eclipse entry, Sun and Earth in the body frame.
    pub geometry: OrbitGeometry,
    /// Temperature of every facet, K (linear between the two grid times around it).
    pub temperature_k: Vec<f64>,
}

/// The periodic temperatures of a target on an orbit, at the asked times.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicOrbit {
    /// Orbital period, s.
    pub period_s: f64,
    /// Time in shadow per orbit, s.
    pub eclipse_duration_s: f64,
    /// Time steps per orbit.
    pub steps_per_orbit: usize,
    /// Orbits integrated.
    pub orbits: usize,
    /// Largest |T(t + P) − T(t)| over the facets in the last orbit, K.
    pub change_k: f64,
    /// Largest [`StepBalance::error_rel`] of the last orbit.
    pub max_balance_error_rel: f64,
    /// Newton steps of the last orbit (all its time steps).
    pub newton_iterations: usize,
    /// The states at the asked times, in their order.
    pub states: Vec<OrbitState>,
}

impl ThermalNetwork {
    /// One backward-Euler step of `dt_s` seconds: `temp` (K per facet) moves from Tⁿ
    /// to Tⁿ⁺¹ under absorbed powers `absorbed_w` (W per facet, e.g. from
    /// [`ThermalNetwork::absorbed_w`]), heat capacities `capacity_j_k` (J K⁻¹ per
    /// facet, > 0 for every facet not pinned at the sink) and the sink `deep_space_k`.
    ///
    /// # Errors
    /// [`ThermalError::BadTransient`] for lengths that differ from the facet count, a
    /// non-positive step or capacity, non-finite inputs; [`ThermalError::NoConvergence`]
    /// when Newton's method stalls.
    pub fn step(
        &self,
        temp: &mut [f64],
        capacity_j_k: &[f64],
        absorbed_w: &[f64],
        deep_space_k: f64,
        dt_s: f64,
    ) -> Result<StepBalance, ThermalError> {
        self.step_from(temp, None, capacity_j_k, absorbed_w, deep_space_k, dt_s)
    }

    /// [`ThermalNetwork::step`] with Newton's method started at `guess` (e.g. the
    /// linear extrapolation of the last two steps) instead of Tⁿ.
    fn step_from(
        &self,
        temp: &mut [f64],
        guess: Option<&[f64]>,
        capacity_j_k: &[f64],
        absorbed_w: &[f64],
        deep_space_k: f64,
        dt_s: f64,
    ) -> Result<StepBalance, ThermalError> {
        let n = self.facet_count();
        let bad = |reason: String| Err(ThermalError::BadTransient { reason });
        if temp.len() != n || capacity_j_k.len() != n || absorbed_w.len() != n {
            return bad(format!(
                "{} temperatures, {} capacities, {} absorbed powers for {n} facets",
                temp.len(),
                capacity_j_k.len(),
                absorbed_w.len()
            ));
        }
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return bad(format!("time step {dt_s} s: expected > 0"));
        }
        if !(deep_space_k.is_finite() && deep_space_k > 0.0) {
            return bad(format!("sink temperature {deep_space_k} K: expected > 0"));
        }
        for i in 0..n {
            if self.pinned[i] {
                continue;
            }
            if !(capacity_j_k[i].is_finite() && capacity_j_k[i] > 0.0) {
                return bad(format!(
                    "facet {i}: heat capacity {} J/K, expected > 0",
                    capacity_j_k[i]
                ));
            }
            if !(temp[i].is_finite() && temp[i] > 0.0 && absorbed_w[i].is_finite()) {
                return bad(format!(
                    "facet {i}: temperature {} K or absorbed power {} W not finite and positive",
                    temp[i], absorbed_w[i]
                ));
            }
        }
        let ts = deep_space_k;
        let ts4 = ts.powi(4);
        let rad = self.radiative_coupling();
        let input: Vec<f64> = (0..n)
            .map(|i| absorbed_w[i] + self.dissipation[i])
            .collect();
        let c_dt: Vec<f64> = capacity_j_k.iter().map(|c| c / dt_s).collect();
        let old = temp.to_vec();
        if let Some(g) = guess.filter(|g| g.len() == n) {
            for i in (0..n).filter(|&i| !self.pinned[i]) {
                if g[i].is_finite() {
                    temp[i] = g[i].max(ts);
                }
            }
        }
        let scale: f64 = (0..n)
            .filter(|&i| !self.pinned[i])
            .map(|i| input[i].abs() + rad[i] * old[i].powi(4))
            .sum();
        let tolerance = RESIDUAL_TOLERANCE * scale;
        let mut residual = vec![0.0; n];
        let mut diag = vec![0.0; n];
        let mut delta = vec![0.0; n];
        let mut work = CgWork::new(n);
        let mut iterations = 0;
        loop {
            self.residual(temp, &input, &rad, ts4, &mut residual);
            let mut max_r = 0.0_f64;
            for i in 0..n {
                if !self.pinned[i] {
                    residual[i] -= c_dt[i] * (temp[i] - old[i]);
                    max_r = max_r.max(residual[i].abs());
                }
            }
            if max_r.is_nan() || (iterations >= MAX_NEWTON_ITERATIONS && max_r > tolerance) {
                return Err(ThermalError::NoConvergence {
                    iterations,
                    residual_w: max_r,
                    tolerance_w: tolerance,
                });
            }
            if max_r <= tolerance {
                break;
            }
            for i in 0..n {
                diag[i] = if self.pinned[i] {
                    1.0
                } else {
                    c_dt[i] + self.g_sum[i] + 4.0 * rad[i] * temp[i].powi(3)
                };
            }
            let lin_tol = (1e-3 * max_r).max(0.25 * tolerance);
            self.pcg(&diag, &residual, lin_tol, &mut delta, &mut work);
            for i in 0..n {
                if !self.pinned[i] {
                    temp[i] = (temp[i] + delta[i]).max(ts);
                }
            }
            iterations += 1;
        }
        let (mut stored, mut net, mut gross) = (0.0, 0.0, 0.0);
        for i in (0..n).filter(|&i| !self.pinned[i]) {
            let emitted = rad[i] * (temp[i].powi(4) - ts4);
            stored += capacity_j_k[i] * (temp[i] - old[i]);
            net += dt_s * (input[i] - emitted);
            gross += dt_s * (input[i].abs() + rad[i] * temp[i].powi(4));
        }
        Ok(StepBalance {
            stored_j: stored,
            net_input_j: net,
            gross_j: gross,
            newton_iterations: iterations,
        })
    }

    /// The periodic temperatures on `orbit` (module docs), sampled at
    /// `sample_times_s` (time since eclipse entry, taken modulo the period).
    ///
    /// `env` gives the solar constant, the sunlit Earth OLR, albedo, Earth distance and
    /// radius for the view factors, and the sink (its Sun and Earth directions are
    /// replaced by the orbit's); in shadow the Earth's OLR is `eclipse_olr_w_m2`.
    /// Time steps are at most `step_s` ([`TRANSIENT_STEP_S`] by default).
    ///
    /// # Errors
    /// Bad inputs ([`ThermalError::BadTransient`], [`ThermalError::BadEnvironment`]),
    /// a failed step, or [`ThermalError::NotPeriodic`] after [`MAX_ORBITS`].
    pub fn periodic_orbit(
        &self,
        capacity_j_k: &[f64],
        orbit: &Orbit,
        env: &ThermalEnvironment,
        eclipse_olr_w_m2: f64,
        step_s: f64,
        sample_times_s: &[f64],
    ) -> Result<PeriodicOrbit, ThermalError> {
        let orbit = orbit.checked()?;
        let env = checked(env)?;
        if !(eclipse_olr_w_m2.is_finite() && eclipse_olr_w_m2 >= 0.0) {
            return Err(ThermalError::BadTransient {
                reason: format!("eclipse OLR {eclipse_olr_w_m2} W/m²: expected ≥ 0"),
            });
        }
        if !(step_s.is_finite() && step_s > 0.0) {
            return Err(ThermalError::BadTransient {
                reason: format!("time step {step_s} s: expected > 0"),
            });
        }
        if let Some(t) = sample_times_s.iter().find(|t| !t.is_finite()) {
            return Err(ThermalError::BadTransient {
                reason: format!("sample time {t} s is not finite"),
            });
        }
        let period = orbit.period_s();
        let eclipse = orbit.eclipse_duration_s();
        // The grid: eclipse and sunlit arcs in equal steps of at most step_s.
        let mut grid = vec![0.0];
        for (start, len) in [(0.0, eclipse), (eclipse, period - eclipse)] {
            if len > 0.0 {
                let m = (len / step_s).ceil().max(1.0) as usize;
                grid.extend((1..=m).map(|k| start + len * k as f64 / m as f64));
            }
        }
        let steps = grid.len() - 1;
        let geometry_env = |t: f64| {
            let g = orbit.geometry(t);
            let mut e = env;
            e.sun_dir_body = g.sun_dir_body;
            e.earth_dir_body = g.earth_dir_body;
            e.sun_earth_cos = g.sun_earth_cos;
            if g.sun_dir_body.is_none() {
                e.earth_olr_w_m2 = eclipse_olr_w_m2;
            }
            e
        };
        // Eclipse steps all see the same Earth (fixed in the body frame) and no Sun:
        // one absorbed vector serves them all.
        let dark = self.absorbed_w(&geometry_env(0.0))?;
        let absorbed: Vec<Vec<f64>> = (0..steps)
            .into_par_iter()
            .map(|j| {
                let env_j = geometry_env(0.5 * (grid[j] + grid[j + 1]));
                if env_j.sun_dir_body.is_none() {
                    Ok(dark.clone())
                } else {
                    self.absorbed_w(&env_j)
                }
            })
            .collect::<Result<_, _>>()?;
        let n = self.facet_count();
        let mut mean = vec![0.0; n];
        for (j, q) in absorbed.iter().enumerate() {
            let w = (grid[j + 1] - grid[j]) / period;
            for (m, v) in mean.iter_mut().zip(q) {
                *m += w * v;
            }
        }
        let ts = env.deep_space_k;
        let mut temp = self.solve_absorbed(&mean, ts)?.temperature_k;

        // Each sample: its step and its weight within it.
        let placed: Vec<(usize, f64, f64)> = sample_times_s
            .iter()
            .map(|&t| {
                let t = t.rem_euclid(period);
                let j = grid.partition_point(|&g| g <= t).clamp(1, steps) - 1;
                let w = ((t - grid[j]) / (grid[j + 1] - grid[j])).clamp(0.0, 1.0);
                (j, w, t)
            })
            .collect();
        let mut sampled: Vec<Vec<f64>> = vec![Vec::new(); placed.len()];
        let mut prev_change: Option<Vec<f64>> = None;
        let mut guess = vec![0.0; n];
        let mut last = temp.clone();
        let mut last_dt = 1.0;
        let mut newton_iterations;
        let mut orbit_count = 0;
        loop {
            orbit_count += 1;
            let start = temp.clone();
            // No predictor across the extrapolation jump.
            last.copy_from_slice(&temp);
            let mut max_err = 0.0_f64;
            newton_iterations = 0;
            for j in 0..steps {
                let before = temp.clone();
                let dt = grid[j + 1] - grid[j];
                // Predictor: the last step's change, scaled to this step.
                for i in 0..n {
                    guess[i] = temp[i] + (temp[i] - last[i]) * dt / last_dt;
                }
                let bal =
                    self.step_from(&mut temp, Some(&guess), capacity_j_k, &absorbed[j], ts, dt)?;
                newton_iterations += bal.newton_iterations;
                max_err = max_err.max(bal.error_rel());
                last.copy_from_slice(&before);
                last_dt = dt;
                let before = placed.iter().any(|p| p.0 == j).then_some(before);
                if let Some(before) = before {
                    for (k, &(pj, w, _)) in placed.iter().enumerate() {
                        if pj == j {
                            sampled[k] = before
                                .iter()
                                .zip(&temp)
                                .map(|(a, b)| a + w * (b - a))
                                .collect();
                        }
                    }
                }
            }
            let change: Vec<f64> = temp.iter().zip(&start).map(|(a, b)| a - b).collect();
            let change_k = change.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            if change_k < PERIODIC_TOLERANCE_K {
                return Ok(PeriodicOrbit {
                    period_s: period,
                    eclipse_duration_s: eclipse,
                    steps_per_orbit: steps,
                    orbits: orbit_count,
                    change_k,
                    max_balance_error_rel: max_err,
                    newton_iterations,
                    states: placed
                        .iter()
                        .zip(sampled)
                        .map(|(&(_, _, t), temperature_k)| OrbitState {
                            geometry: orbit.geometry(t),
                            temperature_k,
                        })
                        .collect(),
                });
            }
            if orbit_count >= MAX_ORBITS {
                return Err(ThermalError::NotPeriodic {
                    orbits: orbit_count,
                    change_k,
                });
            }
            if let Some(prev) = &prev_change {
                let dd: f64 = change.iter().zip(prev).map(|(a, b)| a * b).sum();
                let pp: f64 = prev.iter().map(|b| b * b).sum();
                let rho = dd / pp;
                if rho > 0.0 && rho < MAX_EXTRAPOLATION_RATIO {
                    let k = rho / (1.0 - rho);
                    for i in 0..n {
                        if !self.pinned[i] {
                            temp[i] = (temp[i] + k * change[i]).max(ts);
                        }
                    }
                }
            }
            prev_change = Some(change);
        }
    }
}
