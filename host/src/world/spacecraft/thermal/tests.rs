//! Unit tests of the thermal network (private helpers included).

use super::illumination::{
    point_line_distance, point_segment_distance, point_triangle_distance, ray_triangle,
};
use super::solver::CgWork;
use super::*;

use crate::world::spacecraft::mesh::{Material, MeshBuilder, Part};
use crate::world::spacecraft::models::{MaterialCase, cube_cylinder, tango, winged_sat};

fn sheet(kt_w_k: f64) -> Material {
    Material {
        name: "sheet",
        solar_absorptivity: 0.5,
        ir_emissivity: 0.5,
        conductivity_w_m_k: kt_w_k / 1e-3,
        thickness_m: 1e-3,
        core_conductance_w_m2_k: 0.0,
    }
}

fn plate_mesh(len: f64, width: f64, res: f64) -> Mesh {
    let mut b = MeshBuilder::new();
    let p = b.part(Part {
        name: "strip",
        material: sheet(1.0),
        dissipation_w: 0.0,
    });
    b.grid(p, [0.0, 0.0, 0.0], [len, 0.0, 0.0], [0.0, width, 0.0], res);
    b.finish()
}

/// Solves L·T = src (singular Laplacian, consistent right-hand side).
fn conduct(net: &ThermalNetwork, src: &[f64]) -> Vec<f64> {
    let n = src.len();
    let diag: Vec<f64> = (0..n).map(|i| net.g_sum[i] + 1e-12).collect();
    let mut t = vec![0.0; n];
    let mut w = CgWork::new(n);
    net.pcg(&diag, src, 1e-13, &mut t, &mut w);
    t
}

/// The facet network conducts like the continuum sheet: effective k·t of a strip
/// between two heated/cooled end zones.
#[test]
fn strip_conductance_matches_continuum() {
    for res in [0.1, 0.05] {
        let (len, width) = (2.0, 0.4);
        let mesh = plate_mesh(len, width, res);
        let net = ThermalNetwork::new(&mesh).unwrap();
        let n = mesh.facet_count();
        let x = |t: usize| mesh.centroid(t)[0];
        let src: Vec<f64> = (0..n)
            .map(|t| {
                let a = mesh.area_m2(t);
                if x(t) < -0.4 * len {
                    a
                } else if x(t) > 0.4 * len {
                    -a
                } else {
                    0.0
                }
            })
            .collect();
        let temp = conduct(&net, &src);
        let mean_at = |x0: f64| {
            let sel: Vec<usize> = (0..n).filter(|&i| (x(i) - x0).abs() < res).collect();
            sel.iter().map(|&i| temp[i]).sum::<f64>() / sel.len() as f64
        };
        let grad = (mean_at(-0.25 * len) - mean_at(0.25 * len)) / (0.5 * len);
        let power: f64 = src.iter().filter(|&&s| s > 0.0).sum();
        let k_eff = power / (grad * width);
        assert!((k_eff - 1.0).abs() < 0.01, "res {res}: k·t {k_eff}");
    }
}

/// The checkerboard split makes the network isotropic: heat crossing a square
/// plate along either diagonal sees the same resistance.
#[test]
fn grid_network_is_isotropic() {
    let mesh = plate_mesh(2.0, 2.0, 0.05);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let n = mesh.facet_count();
    let mut drops = Vec::new();
    for (sx, sy) in [(1.0, 1.0), (1.0, -1.0)] {
        let f = |t: usize| {
            let c = mesh.centroid(t);
            sx * c[0] + sy * c[1]
        };
        let src: Vec<f64> = (0..n)
            .map(|t| {
                let a = mesh.area_m2(t);
                if f(t) < -1.5 {
                    a
                } else if f(t) > 1.5 {
                    -a
                } else {
                    0.0
                }
            })
            .collect();
        let temp = conduct(&net, &src);
        let mean = |lo: f64, hi: f64| {
            let s: Vec<usize> = (0..n).filter(|&i| f(i) > lo && f(i) < hi).collect();
            s.iter().map(|&i| temp[i]).sum::<f64>() / s.len() as f64
        };
        drops.push(mean(-0.55, -0.45) - mean(0.45, 0.55));
    }
    assert!((drops[0] / drops[1] - 1.0).abs() < 0.01, "{drops:?}");
}

/// The view factor formula against a direct quadrature of cos θ/π over the
/// directions that meet the sphere.
#[test]
fn earth_view_factor_matches_quadrature() {
    let pi = std::f64::consts::PI;
    for h in [1.05_f64, 1.706, 3.0, 10.0] {
        let half_angle = (1.0 / h).asin();
        for lambda_deg in [0.0_f64, 30.0, 60.0, 80.0, 90.0, 100.0, 120.0, 150.0, 180.0] {
            let lam = lambda_deg.to_radians();
            let normal = [lam.sin(), 0.0, lam.cos()];
            // Directions in the cone towards the centre (+z): polar ψ, azimuth β.
            let (np, nb) = (400, 400);
            let mut f = 0.0;
            for ip in 0..np {
                let psi = (ip as f64 + 0.5) / np as f64 * half_angle;
                let dpsi = half_angle / np as f64;
                for ib in 0..nb {
                    let beta = (ib as f64 + 0.5) / nb as f64 * 2.0 * pi;
                    let d = [psi.sin() * beta.cos(), psi.sin() * beta.sin(), psi.cos()];
                    let c = dot(d, normal);
                    if c > 0.0 {
                        f += c / pi * psi.sin() * dpsi * (2.0 * pi / nb as f64);
                    }
                }
            }
            let formula = earth_view_factor(h, lam.cos());
            assert!(
                (formula - f).abs() < 2e-4,
                "H {h} λ {lambda_deg}: formula {formula} quadrature {f}"
            );
        }
    }
    assert_eq!(earth_view_factor(2.0, f64::NAN), 0.0);
    assert!((earth_view_factor(1.0, 0.0) - 0.5).abs() < 1e-15);
    assert!((earth_view_factor(0.5, 1.0) - 1.0).abs() < 1e-15);
}

/// BVH closest hits agree with a brute-force scan.
#[test]
fn bvh_matches_brute_force() {
    let mesh = cube_cylinder(MaterialCase::Mono, 0.25);
    let tris: Vec<[Vec3; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| mesh.vertices[v as usize]))
        .collect();
    let bvh = Bvh::new(tris.clone());
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for _ in 0..500 {
        let o = [3.0 * rnd(), 3.0 * rnd(), 3.0 * rnd()];
        let d = normalize([rnd(), rnd(), rnd()]);
        let brute = tris
            .iter()
            .enumerate()
            .filter_map(|(t, tri)| ray_triangle(o, d, tri).map(|h| (t, h)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let fast = bvh.closest_hit(o, d, usize::MAX);
        assert_eq!(brute.map(|b| b.0), fast.map(|f| f.0));
        assert_eq!(brute.is_some(), bvh.any_hit(o, d, usize::MAX));
    }
}

#[test]
fn point_distances() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(point_triangle_distance([0.2, 0.2, 0.5], &tri), 0.5);
    assert_eq!(point_triangle_distance([-1.0, 0.0, 0.0], &tri), 1.0);
    assert!((point_triangle_distance([1.0, 1.0, 0.0], &tri) - 0.5_f64.sqrt()).abs() < 1e-15);
    assert_eq!(
        point_segment_distance([0.5, 1.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]),
        1.0
    );
    assert_eq!(
        point_line_distance([5.0, 2.0, 0.0], [0.0; 3], [1.0, 0.0, 0.0]),
        2.0
    );
}

/// The cylinder's open end is joined to the cube face edge by edge; the cube
/// facets under it are enclosed, about the cylinder's cross-section.
#[test]
fn joints_and_enclosed_facets_of_the_cube_cylinder() {
    let mesh = cube_cylinder(MaterialCase::Mono, 0.1);
    let net = ThermalNetwork::new(&mesh).unwrap();
    assert_eq!(net.joint_count(), 16);
    assert_eq!(net.free_edge_count(), 0);
    assert_eq!(net.component_count(), 1);
    let enclosed: f64 = (0..mesh.facet_count())
        .filter(|&t| !net.is_exposed(t))
        .map(|t| {
            assert_eq!(mesh.part_of[t], 0);
            assert!((mesh.centroid(t)[0]).abs() < 1e-12);
            mesh.area_m2(t)
        })
        .sum();
    let disc = std::f64::consts::PI * 0.25 * 0.25;
    assert!(
        (enclosed - disc).abs() < 0.1 * disc,
        "enclosed {enclosed} m²"
    );
    // Symmetric conductances.
    for i in (0..mesh.facet_count()).step_by(37) {
        for &j in &net.col[net.row[i] as usize..net.row[i + 1] as usize] {
            let j = j as usize;
            assert_eq!(net.conductance_w_k(i, j), net.conductance_w_k(j, i));
            assert!(net.conductance_w_k(i, j) > 0.0);
        }
    }
}

#[test]
fn tango_is_joined_without_free_edges() {
    let mesh = tango(0.1);
    let net = ThermalNetwork::new(&mesh).unwrap();
    assert_eq!(net.free_edge_count(), 0);
    assert_eq!(net.component_count(), 1);
    // Only the bus face under the two patch antennas (2 × 0.01 m²) is enclosed.
    let enclosed: f64 = (0..mesh.facet_count())
        .filter(|&t| !net.is_exposed(t))
        .map(|t| {
            assert_eq!(mesh.parts[mesh.part_of[t] as usize].name, "bus-mli");
            assert!(mesh.normal(t)[2] < -1.0 + 1e-12);
            mesh.area_m2(t)
        })
        .sum();
    assert!(enclosed > 0.01 && enclosed < 0.04, "enclosed {enclosed} m²");
}

/// The winged satellite: bus, radome and yokes one conducting body; each wing its own
/// (joined to nothing but its yoke's cap, against which it only touches); no free
/// edges; enclosed only the bus top under the radome, and the yokes' caps and the wings'
/// inner edges where the two touch.
#[test]
fn winged_sat_wings_are_decoupled_from_the_bus() {
    let mesh = winged_sat(0.05);
    let net = ThermalNetwork::new(&mesh).unwrap();
    assert_eq!(net.free_edge_count(), 0);
    assert_eq!(net.component_count(), 3);
    let mut enclosed = 0.0;
    for t in (0..mesh.facet_count()).filter(|&t| !net.is_exposed(t)) {
        let (part, n) = (mesh.parts[mesh.part_of[t] as usize].name, mesh.normal(t));
        match part {
            "bus-mli" => assert!(n[2] > 1.0 - 1e-12, "{t}: {n:?}"),
            "panel-back" | "yokes" => assert!(n[1].abs() > 1.0 - 1e-12, "{t}: {n:?}"),
            _ => panic!("{t}: enclosed facet of {part}"),
        }
        enclosed += mesh.area_m2(t);
    }
    // The radome's 0.12 × 0.12 m footprint, as whole 0.05 m facets under it.
    assert!((0.005..0.02).contains(&enclosed), "enclosed {enclosed} m²");
}

/// A wing square to the Sun, nothing else around (no Earth): its two faces against a
/// one-dimensional sandwich in closed form, αS = ε_f σ T_f⁴ + h (T_f − T_b) and
/// h (T_f − T_b) = ε_b σ T_b⁴ (1 + e), the black edges radiating at the back's
/// temperature (e: their area over a face's, 0.08 / 0.6 m²; solved by bisection), and
/// each wing's energy balance: the sunlight its cells absorb is what it emits.
#[test]
fn winged_sat_sunlit_wing_matches_a_sandwich_in_closed_form() {
    use crate::world::spacecraft::models::{
        HONEYCOMB_THROUGH_W_M2_K, PANEL_BACK, SOLAR_CELLS, WINGED_BUS_M, WINGED_WING_M,
    };
    let mesh = winged_sat(0.05);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let mut env = ThermalEnvironment::sunlit([1.0, 0.0, 0.0], [0.0, 0.0, -1.0]);
    env.earth_olr_w_m2 = 0.0;
    env.albedo = 0.0;
    let sol = net.solve(&env).unwrap();
    let (h, s) = (HONEYCOMB_THROUGH_W_M2_K, SOLAR_CONSTANT_W_M2);
    let [wx, wy, wz] = WINGED_WING_M;
    let edges = 2.0 * (wy + wz) * wx / (wy * wz);
    let (a, ef, eb) = (
        SOLAR_CELLS.solar_absorptivity,
        SOLAR_CELLS.ir_emissivity,
        PANEL_BACK.ir_emissivity,
    );
    // T_b from the back face's balance given T_f, then T_f by bisection on the front's.
    let back = |tf: f64| {
        let (mut lo, mut hi) = (0.0f64, tf);
        for _ in 0..200 {
            let tb = 0.5 * (lo + hi);
            if h * (tf - tb) > (1.0 + edges) * eb * STEFAN_BOLTZMANN_W_M2_K4 * tb.powi(4) {
                lo = tb;
            } else {
                hi = tb;
            }
        }
        0.5 * (lo + hi)
    };
    let (mut lo, mut hi) = (100.0f64, 500.0f64);
    for _ in 0..200 {
        let tf = 0.5 * (lo + hi);
        let out = ef * STEFAN_BOLTZMANN_W_M2_K4 * tf.powi(4) + h * (tf - back(tf));
        if out < a * s {
            lo = tf;
        } else {
            hi = tf;
        }
    }
    let (tf, tb) = (0.5 * (lo + hi), back(0.5 * (lo + hi)));
    assert!(tf - tb > 3.0 && tf - tb < 6.0, "closed form {tf} / {tb}");
    let hy = WINGED_BUS_M[1] / 2.0;
    for side in [-1.0, 1.0] {
        let wing: Vec<usize> = (0..mesh.facet_count())
            .filter(|&t| {
                let name = mesh.parts[mesh.part_of[t] as usize].name;
                (name == "solar-cells" || name == "panel-back")
                    && mesh.centroid(t)[1] * side > hy + 0.1
            })
            .collect();
        let mean = |sign: f64| {
            let (mut at, mut area) = (0.0, 0.0);
            for &t in wing.iter().filter(|&&t| mesh.normal(t)[0] * sign > 0.99) {
                at += sol.temperature_k[t] * mesh.area_m2(t);
                area += mesh.area_m2(t);
            }
            at / area
        };
        let (front, rear) = (mean(1.0), mean(-1.0));
        assert!(
            (front - tf).abs() < 1.0 && (rear - tb).abs() < 1.0,
            "wing {side}: faces {front:.2} / {rear:.2} K, closed form {tf:.2} / {tb:.2} K"
        );
        let absorbed: f64 = wing
            .iter()
            .filter(|&&t| mesh.normal(t)[0] > 0.99)
            .map(|&t| a * s * mesh.area_m2(t))
            .sum();
        let emitted: f64 = wing
            .iter()
            .filter(|&&t| net.is_exposed(t))
            .map(|&t| {
                mesh.material(t).ir_emissivity
                    * STEFAN_BOLTZMANN_W_M2_K4
                    * mesh.area_m2(t)
                    * (sol.temperature_k[t].powi(4) - env.deep_space_k.powi(4))
            })
            .sum();
        assert!(
            (emitted - absorbed).abs() < 1e-3 * absorbed,
            "wing {side}: absorbs {absorbed:.2} W, emits {emitted:.2} W"
        );
    }
}
