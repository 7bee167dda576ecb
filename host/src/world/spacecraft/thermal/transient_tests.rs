//! Tests of the transient solver and the orbit: closed forms for a plate's radiative
//! cooling and heating, the per-step energy balance, the shadow geometry by brute
//! force, and the periodic orbit of the cube + cylinder.

use super::*;

use crate::world::geom::{dot, norm, sub};
use crate::world::spacecraft::mesh::{Material, MeshBuilder, Part};
use crate::world::spacecraft::models::{
    ALUMINIUM_DENSITY_KG_M3, ALUMINIUM_SPECIFIC_HEAT_J_KG_K, MaterialCase, cube_cylinder,
};

/// Sink temperature of the closed-form tests, K: its T⁴ (1e-12 K⁴) is negligible
/// against the plate's (> 1e8 K⁴), so the plate radiates to 0 K.
const COLD_SINK_K: f64 = 1e-3;

/// A 1 m × 1 m plate in the z = 0 plane (normal +z), two facets, grey α = ε.
fn plate(emissivity: f64) -> Mesh {
    let mut b = MeshBuilder::new();
    let p = b.part(Part {
        name: "plate",
        material: Material {
            name: "plate",
            solar_absorptivity: emissivity,
            ir_emissivity: emissivity,
            conductivity_w_m_k: 167.0,
            thickness_m: 2e-3,
            core_conductance_w_m2_k: 0.0,
        },
        dissipation_w: 0.0,
    });
    b.grid(p, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 1.0);
    b.finish()
}

/// An environment with only the Sun along `sun` (no Earth infrared, no albedo).
fn sun_only(sun: Option<[f64; 3]>) -> ThermalEnvironment {
    let mut env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
    env.sun_dir_body = sun;
    env.earth_olr_w_m2 = 0.0;
    env.albedo = 0.0;
    env.deep_space_k = COLD_SINK_K;
    env
}

/// T(t) = (T0⁻³ + 3εσ t / c)^(−1/3): an isolated plate (areal capacity c) radiating
/// to 0 K.
fn cooling_closed_form(t0_k: f64, emissivity: f64, areal_j_m2_k: f64, t_s: f64) -> f64 {
    (t0_k.powi(-3) + 3.0 * emissivity * SIGMA * t_s / areal_j_m2_k).powf(-1.0 / 3.0)
}

/// Integrates `plate` from `t0_k` with step `dt_s` and returns the mean temperature
/// at each of `times_s` (multiples of `dt_s`).
fn integrate(
    mesh: &Mesh,
    env: &ThermalEnvironment,
    t0_k: f64,
    dt_s: f64,
    times_s: &[f64],
) -> Vec<f64> {
    let net = ThermalNetwork::new(mesh).unwrap();
    let cap = facet_heat_capacities_j_k(mesh);
    let q = net.absorbed_w(env).unwrap();
    let mut temp = vec![t0_k; mesh.facet_count()];
    let mut t = 0.0;
    let mut out = Vec::new();
    for &target in times_s {
        while t < target - 1e-9 {
            net.step(&mut temp, &cap, &q, env.deep_space_k, dt_s)
                .unwrap();
            t += dt_s;
        }
        out.push(temp.iter().sum::<f64>() / temp.len() as f64);
    }
    out
}

/// The plate's capacity is the aluminium skin: ρ c t of 2 mm 6061.
#[test]
fn plate_capacity_is_the_skin() {
    let mesh = plate(0.8);
    let c: f64 = facet_heat_capacities_j_k(&mesh).iter().sum();
    let expected = ALUMINIUM_DENSITY_KG_M3 * ALUMINIUM_SPECIFIC_HEAT_J_KG_K * 2e-3 * 1.0;
    assert!((c - expected).abs() < 1e-9 * expected, "{c} vs {expected}");
}

/// Radiative cooling of an isolated plate against the closed form: with Δt = 1 s the
/// error stays below 0.05 K over two hours (300 K → 160 K); with Δt = 10 s it is
/// about ten times larger (first order).
#[test]
fn plate_cooling_matches_closed_form() {
    let (eps, t0) = (0.8, 300.0);
    let mesh = plate(eps);
    let areal = ALUMINIUM_DENSITY_KG_M3 * ALUMINIUM_SPECIFIC_HEAT_J_KG_K * 2e-3;
    let env = sun_only(None);
    let times = [600.0, 1800.0, 3600.0, 7200.0];
    let fine = integrate(&mesh, &env, t0, 1.0, &times);
    let coarse = integrate(&mesh, &env, t0, 10.0, &times);
    let mut max_fine = 0.0_f64;
    let mut max_coarse = 0.0_f64;
    for (k, &t) in times.iter().enumerate() {
        let exact = cooling_closed_form(t0, eps, areal, t);
        max_fine = max_fine.max((fine[k] - exact).abs());
        max_coarse = max_coarse.max((coarse[k] - exact).abs());
        assert!(
            (fine[k] - exact).abs() < 0.05,
            "t = {t} s: {} K vs closed form {exact} K",
            fine[k]
        );
    }
    let order = max_coarse / max_fine;
    assert!(
        (7.0..14.0).contains(&order),
        "error ratio {order} (Δt 10 s vs 1 s)"
    );
}

/// Time for a sunlit plate to heat from T0 to T towards its equilibrium Te:
/// t = c/(εσ) · [F(T) − F(T0)], F(T) = (ln((Te+T)/(Te−T)) + 2 atan(T/Te)) / (4Te³).
fn heating_time_s(te: f64, t0: f64, t: f64, eps: f64, areal: f64) -> f64 {
    let f = |x: f64| (((te + x) / (te - x)).ln() + 2.0 * (x / te).atan()) / (4.0 * te.powi(3));
    areal / (eps * SIGMA) * (f(t) - f(t0))
}

/// A plate facing the Sun heats from 150 K along the closed form (inverted by
/// bisection) within 0.1 K at Δt = 2 s, and ends at the steady solution.
#[test]
fn plate_heating_matches_closed_form_and_steady_state() {
    let (eps, t0) = (0.6, 150.0);
    let mesh = plate(eps);
    let areal = ALUMINIUM_DENSITY_KG_M3 * ALUMINIUM_SPECIFIC_HEAT_J_KG_K * 2e-3;
    let env = sun_only(Some([0.0, 0.0, 1.0]));
    // α = ε: Te⁴ = S/σ (+ sink⁴, negligible).
    let te = (SOLAR_CONSTANT_W_M2 / SIGMA).powf(0.25);
    let times = [300.0, 900.0, 1800.0, 3600.0, 40_000.0];
    let got = integrate(&mesh, &env, t0, 2.0, &times);
    for (k, &t) in times[..4].iter().enumerate() {
        let (mut lo, mut hi) = (t0, te);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if heating_time_s(te, t0, mid, eps, areal) < t {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let exact = 0.5 * (lo + hi);
        assert!(
            (got[k] - exact).abs() < 0.1,
            "t = {t} s: {} K vs closed form {exact} K",
            got[k]
        );
    }
    let steady = solve_steady_state(&mesh, &env).unwrap();
    let (lo, hi) = steady.min_max_k();
    assert!((lo - te).abs() < 1e-6 && (hi - te).abs() < 1e-6);
    assert!(
        (got[4] - te).abs() < 1e-3,
        "{} K after 40 000 s vs {te} K",
        got[4]
    );
}

/// Every step conserves energy: Σ C ΔT = Δt·(absorbed − emitted) to 1e-8 of the
/// gross flow (the Newton tolerance is 1e-10 of it per node, summed over nodes), for the conducting cube + cylinder in and out of the Sun, long steps.
#[test]
fn step_conserves_energy() {
    let mesh = cube_cylinder(MaterialCase::Multi1, 0.2);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let cap = facet_heat_capacities_j_k(&mesh);
    let mut temp = vec![250.0; mesh.facet_count()];
    for (k, sun) in [Some([0.3, -0.5, 0.8]), None, Some([-1.0, 0.0, 0.0])]
        .into_iter()
        .enumerate()
    {
        let env = match sun {
            Some(s) => ThermalEnvironment::sunlit(s, [0.0, 0.0, -1.0]),
            None => ThermalEnvironment::eclipse([0.0, 0.0, -1.0]),
        };
        let q = net.absorbed_w(&env).unwrap();
        for dt in [1.0, 60.0, 600.0] {
            let before = temp.clone();
            let bal = net.step(&mut temp, &cap, &q, env.deep_space_k, dt).unwrap();
            let moved = temp
                .iter()
                .zip(&before)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(moved > 1e-4, "case {k}, Δt {dt}: nothing moved");
            assert!(bal.error_rel() < 1e-8, "case {k}, Δt {dt}: {bal:?}");
            assert!(bal.newton_iterations <= 8, "{bal:?}");
        }
    }
}

/// Bad transient inputs are errors, not panics.
#[test]
fn step_rejects_bad_input() {
    let mesh = plate(0.5);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let q = vec![0.0; 2];
    let mut t = vec![200.0; 2];
    for (cap, dt) in [
        (vec![1.0; 2], 0.0),
        (vec![0.0; 2], 1.0),
        (vec![1.0; 3], 1.0),
    ] {
        assert!(matches!(
            net.step(&mut t, &cap, &q, 3.0, dt),
            Err(ThermalError::BadTransient { .. })
        ));
    }
    let mut bad = Orbit::reference();
    bad.radius_m = 1.0;
    assert!(bad.checked().is_err());
}

/// Period and eclipse fraction of the reference orbit, the shadow tested by brute
/// force: position on the circle, Sun at β, inside the Earth's shadow cylinder.
#[test]
fn orbit_period_and_shadow_by_brute_force() {
    let reference = Orbit::reference();
    assert!(
        (reference.period_s() - 11_280.0).abs() < 5.0,
        "{}",
        reference.period_s()
    );
    for beta_deg in [0.0_f64, 20.0, 30.0, 40.0] {
        let orbit = Orbit {
            beta_rad: beta_deg.to_radians(),
            ..reference
        };
        let p = orbit.period_s();
        let (a, r) = (orbit.radius_m, orbit.earth_radius_m);
        let sun = [
            beta_deg.to_radians().cos(),
            0.0,
            beta_deg.to_radians().sin(),
        ];
        let samples = 100_000;
        let mut shadow = 0;
        for k in 0..samples {
            let th = std::f64::consts::TAU * (k as f64 + 0.5) / samples as f64;
            let pos = [a * th.cos(), a * th.sin(), 0.0];
            let along = dot(pos, sun);
            let perp = norm(sub(pos, [sun[0] * along, 0.0, sun[2] * along]));
            if along < 0.0 && perp < r {
                shadow += 1;
            }
        }
        let brute = shadow as f64 / samples as f64;
        let model = orbit.eclipse_duration_s() / p;
        assert!(
            (brute - model).abs() < 1e-4,
            "β {beta_deg}°: {brute} vs {model}"
        );
        // Times: shadowed exactly in [0, duration).
        let d = orbit.eclipse_duration_s();
        for t in [0.0, 0.5 * d, 0.999 * d, 1.001 * d, 0.5 * p, 0.999 * p] {
            let g = orbit.geometry(t);
            let expect_shadow = d > 0.0 && t < d;
            assert_eq!(
                g.sun_dir_body.is_none(),
                expect_shadow,
                "β {beta_deg}°, t {t}"
            );
            if let Some(s) = g.sun_dir_body {
                assert!((norm(s) - 1.0).abs() < 1e-12);
                assert!((g.sun_earth_cos - (-dot(s, g.earth_dir_body)).max(0.0)).abs() < 1e-12);
            }
        }
    }
    let d = reference.eclipse_duration_s();
    assert!((d / reference.period_s() - 0.1994).abs() < 1e-3, "{d}");
}

/// The cube + cylinder's periodic orbit: periodic within the tolerance, the energy
/// balanced, the eclipse cooling monotonic, every eclipse state warmer than the
/// steady eclipse state, and a step four times smaller changing no facet by more
/// than 1 K.
#[test]
fn cube_cylinder_orbit_is_periodic_and_cools_in_eclipse() {
    let mesh = cube_cylinder(MaterialCase::Mono, 0.2);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let cap = facet_heat_capacities_j_k(&mesh);
    let orbit = Orbit::reference();
    let env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
    let times = [0.0, 600.0, 1200.0, 2100.0, orbit.period_s()];
    let run = |step| {
        net.periodic_orbit(&cap, &orbit, &env, EARTH_OLR_W_M2, step, &times)
            .unwrap()
    };
    let sol = run(TRANSIENT_STEP_S);
    assert!(sol.change_k < PERIODIC_TOLERANCE_K);
    assert!(
        sol.max_balance_error_rel < 1e-8,
        "{}",
        sol.max_balance_error_rel
    );
    let mean = |t: &[f64]| t.iter().sum::<f64>() / t.len() as f64;
    let means: Vec<f64> = sol.states.iter().map(|s| mean(&s.temperature_k)).collect();
    for w in means[..4].windows(2) {
        assert!(w[1] < w[0], "eclipse means {means:?}");
    }
    // t = 0 and t = P are the same state (periodic).
    let wrap = sol.states[0]
        .temperature_k
        .iter()
        .zip(&sol.states[4].temperature_k)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(wrap < 1e-9, "{wrap}");
    let steady = net.solve(&env).unwrap();
    let steady_max = steady.min_max_k().1;
    for s in &sol.states[..4] {
        assert!(s.geometry.sun_dir_body.is_none());
        let lo = s.temperature_k.iter().fold(f64::INFINITY, |m, &v| m.min(v));
        assert!(
            lo > steady.min_max_k().0,
            "{lo} vs steady {:?}",
            steady.min_max_k()
        );
    }
    assert!(mean(&sol.states[0].temperature_k) > steady_max);
    let fine = run(TRANSIENT_STEP_S / 4.0);
    for (a, b) in sol.states.iter().zip(&fine.states) {
        let d = a
            .temperature_k
            .iter()
            .zip(&b.temperature_k)
            .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(
            d < 1.0,
            "t = {} s: Δt 30 s vs 7.5 s differ by {d} K",
            a.geometry.time_s
        );
    }
}

/// The figures of the report (run with `cargo test --release -p tirroi-host --lib
/// transient_report -- --ignored --nocapture`): facet temperature ranges of the
/// cube + cylinder (Table 3 cases) and Tango at 0.05 m in eclipse at 0, 10, 20, 35 min
/// after entry and along the sunlit arc, the steady eclipse state for comparison
/// (Earth at body −z, as on the orbit), and the cost of one periodic orbit.
#[test]
#[ignore = "prints the report's figures; slow in debug"]
fn transient_report() {
    use crate::world::earth::ECLIPSE_FLUX_FACTOR;
    use crate::world::spacecraft::models::tango;
    let orbit = Orbit::reference();
    let (p, e) = (orbit.period_s(), orbit.eclipse_duration_s());
    println!("period {p:.1} s, eclipse {e:.1} s ({:.1} %)", 100.0 * e / p);
    let mut times = vec![0.0, 600.0, 1200.0, 2100.0];
    let sunlit: Vec<f64> = (0..4)
        .map(|k| e + (k as f64 + 0.5) / 4.0 * (p - e))
        .collect();
    times.extend(&sunlit);
    let eclipse_olr = EARTH_OLR_W_M2 * f64::from(ECLIPSE_FLUX_FACTOR);
    let cases: Vec<(String, Mesh)> = MaterialCase::ALL
        .iter()
        .map(|&c| {
            (
                format!("cube-cylinder {}", c.label()),
                cube_cylinder(c, 0.05),
            )
        })
        .chain([("tango".to_string(), tango(0.05))])
        .collect();
    for (name, mesh) in &cases {
        let t0 = std::time::Instant::now();
        let net = ThermalNetwork::new(mesh).unwrap();
        let cap = facet_heat_capacities_j_k(mesh);
        let env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
        let sol = net
            .periodic_orbit(&cap, &orbit, &env, eclipse_olr, TRANSIENT_STEP_S, &times)
            .unwrap();
        let secs = t0.elapsed().as_secs_f64();
        let mut steady_env = env;
        steady_env.earth_olr_w_m2 = eclipse_olr;
        let steady = net.solve(&steady_env).unwrap().min_max_k();
        println!(
            "{name}: {} facets, {} orbits, {} steps/orbit, {} Newton steps in the last, last change {:.3} K, balance {:.1e}, {secs:.2} s; steady eclipse {:.1}–{:.1} K",
            mesh.facet_count(),
            sol.orbits,
            sol.steps_per_orbit,
            sol.newton_iterations,
            sol.change_k,
            sol.max_balance_error_rel,
            steady.0,
            steady.1
        );
        for s in &sol.states {
            let (lo, hi) = s
                .temperature_k
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
                    (a.min(t), b.max(t))
                });
            let mean = s.temperature_k.iter().sum::<f64>() / s.temperature_k.len() as f64;
            let t = s.geometry.time_s;
            let label = if s.geometry.sun_dir_body.is_some() {
                format!("sunlit, {:.0} min after sunrise", (t - e) / 60.0)
            } else {
                format!("eclipse, {:.0} min after entry", t / 60.0)
            };
            println!("  {label:32} {lo:6.1}–{hi:6.1} K (mean {mean:.1} K)");
        }
    }
}
