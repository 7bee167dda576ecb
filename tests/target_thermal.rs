//! Target meshes and their thermal network: geometry (closure, outward normals,
//! volume, area, bounding radius, facet counts), Table 3 materials, energy balance,
//! analytic checks (isolated plate, isothermal box) and the temperature field's
//! gradients, plus refusal of degenerate input.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::time::Instant;

use tirroi::host::world::spacecraft::models::{DEFAULT_RESOLUTION_M, closed_box};
use tirroi::host::world::spacecraft::thermal::{ThermalNetwork, earth_view_factor};
use tirroi::host::world::spacecraft::{
    Material, MaterialCase, Mesh, Part, ThermalEnvironment, ThermalError, cube_cylinder,
    solve_steady_state, tango,
};

const SIGMA: f64 = 5.670_374_419e-8;

/// Coarse facets keep the debug-build tests fast.
const COARSE_M: f64 = 0.2;

fn edge_uses(mesh: &Mesh, part: Option<u16>) -> HashMap<(u32, u32), usize> {
    let mut uses = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if part.is_some_and(|p| mesh.part_of[t] != p) {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    uses
}

/// Segments of the cylinder polygon at a resolution (as the model builds it).
fn cylinder_segments(mesh: &Mesh) -> usize {
    edge_uses(mesh, Some(1))
        .values()
        .filter(|&&n| n == 1)
        .count()
}

fn sun_earth() -> ThermalEnvironment {
    ThermalEnvironment::sunlit([0.6, 0.64, 0.48], [-0.48, 0.0, -0.877])
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    s / n as f64
}

#[test]
fn cube_is_closed_and_the_cylinder_open_only_at_the_joint() {
    for res in [DEFAULT_RESOLUTION_M, 0.1, COARSE_M] {
        let mesh = cube_cylinder(MaterialCase::Mono, res);
        // Every cube edge is shared by exactly two cube triangles.
        assert!(edge_uses(&mesh, Some(0)).values().all(|&n| n == 2));
        // The cylinder's open edges form the joint ring on the cube face (x = 0).
        let cyl = edge_uses(&mesh, Some(1));
        let open: Vec<_> = cyl
            .iter()
            .filter(|&(_, &n)| n == 1)
            .map(|(&e, _)| e)
            .collect();
        assert!(open.len() >= 16 && open.len() % 4 == 0);
        for (a, b) in open {
            assert!(mesh.vertices[a as usize][0].abs() < 1e-12);
            assert!(mesh.vertices[b as usize][0].abs() < 1e-12);
        }
        assert!(cyl.values().all(|&n| n <= 2));
        assert!(edge_uses(&mesh, None).values().all(|&n| n <= 2));
    }
}

#[test]
fn cube_cylinder_volume_area_and_extent() {
    for res in [DEFAULT_RESOLUTION_M, COARSE_M] {
        let mesh = cube_cylinder(MaterialCase::Mono, res);
        let n = cylinder_segments(&mesh) as f64;
        let r: f64 = 0.25;
        let polygon_area = 0.5 * n * r * r * (2.0 * PI / n).sin();
        let polygon_side = n * 2.0 * r * (PI / n).sin() * 1.0;
        // Outward normals: positive volume, exact for the polygonal cylinder (the
        // open end lies in the plane x = 0 through the origin).
        let volume = mesh.signed_volume_m3();
        assert!(
            (volume - (1.0 + polygon_area)).abs() < 1e-9,
            "volume {volume}"
        );
        let circle = 1.0 + PI * r * r;
        assert!((volume - circle).abs() < 0.02 * circle);
        // Area: the closed cube (6 m², covered face included), side and free cap.
        let area = mesh.total_area_m2();
        assert!(
            (area - (6.0 + polygon_side + polygon_area)).abs() < 1e-9,
            "area {area}"
        );
        let analytic = 6.0 + PI * 0.5 + PI * r * r;
        assert!((area - analytic).abs() < 0.01 * analytic);
        // Each facet's normal is a unit vector, the bounding box centred.
        for t in 0..mesh.facet_count() {
            let nrm = mesh.normal(t);
            assert!((nrm.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-12);
        }
        let (lo, hi) = mesh.bounding_box();
        assert!(lo.iter().zip(&hi).all(|(a, b)| (a + b).abs() < 1e-12));
        assert!((lo[0] + 1.0).abs() < 1e-12 && (hi[0] - 1.0).abs() < 1e-12);
        // The farthest vertices are the cube's outer corners (−1, ±0.5, ±0.5).
        assert!((mesh.bounding_radius_m() - 1.5_f64.sqrt()).abs() < 1e-12);
    }
}

#[test]
fn facet_counts_at_the_default_resolution() {
    assert_eq!(DEFAULT_RESOLUTION_M, 0.05);
    let cc = cube_cylinder(MaterialCase::Mono, DEFAULT_RESOLUTION_M);
    // Cube 6 × 20 × 20 × 2, side 20 rings × 32 segments × 2, cap 32 + 4 × 64.
    assert_eq!(cc.facet_count(), 4800 + 1280 + 288);
    assert_eq!(cc.triangles.len(), cc.part_of.len());
    let tg = tango(DEFAULT_RESOLUTION_M);
    assert_eq!(tg.facet_count(), 2092);
    assert_eq!(tango(0.1).facet_count(), 676);
    assert_eq!(cube_cylinder(MaterialCase::Mono, 0.1).facet_count(), 1600);
    assert_eq!(
        cube_cylinder(MaterialCase::Mono, COARSE_M).facet_count(),
        508
    );
    // Invalid resolutions fall back to the default instead of failing.
    assert_eq!(
        cube_cylinder(MaterialCase::Mono, f64::NAN).facet_count(),
        6368
    );
    assert_eq!(cube_cylinder(MaterialCase::Mono, -1.0).facet_count(), 6368);
}

#[test]
fn table3_emissivities_per_part_and_grey_absorptivity() {
    let expected = [
        (MaterialCase::Mono, 0.86, 0.86),
        (MaterialCase::Multi1, 0.90, 0.10),
        (MaterialCase::Multi2, 0.10, 0.90),
    ];
    for (case, cube, cyl) in expected {
        let mesh = cube_cylinder(case, COARSE_M);
        assert_eq!(mesh.parts.len(), 2);
        assert_eq!(mesh.parts[0].name, "cube");
        assert_eq!(mesh.parts[1].name, "cylinder");
        for t in 0..mesh.facet_count() {
            let want = if mesh.part_of[t] == 0 { cube } else { cyl };
            let m = mesh.material(t);
            assert_eq!(m.ir_emissivity, want);
            assert_eq!(m.solar_absorptivity, want, "grey body: α = ε");
        }
    }
    assert_eq!(
        MaterialCase::ALL.map(|c| c.label()),
        ["mono", "multi-1", "multi-2"]
    );
}

#[test]
fn tango_parts_sizes_and_closure() {
    let mesh = tango(0.1);
    let names: Vec<&str> = mesh.parts.iter().map(|p| p.name).collect();
    assert_eq!(
        names,
        [
            "bus-radiator",
            "bus-mli",
            "solar-cells",
            "panel-back",
            "whip-antennas",
            "patch-antennas"
        ]
    );
    for (p, name) in names.iter().enumerate() {
        assert!(mesh.facets_of_part(p).count() > 0, "{name}");
    }
    let cells = &mesh.parts[2].material;
    assert_eq!(
        (cells.solar_absorptivity, cells.ir_emissivity),
        (0.91, 0.85)
    );
    let whip = &mesh.parts[4].material;
    assert!(whip.ir_emissivity <= 0.1 && whip.solar_absorptivity / whip.ir_emissivity > 3.0);
    let watts: f64 = mesh.parts.iter().map(|p| p.dissipation_w).sum();
    assert!((watts - 10.0).abs() < 1e-12);
    // Envelope: 0.02 m patches + 0.295 m bus + 0.025 m panel high; whips reach ±0.54 m.
    let (lo, hi) = mesh.bounding_box();
    assert!((hi[2] - lo[2] - 0.34).abs() < 1e-12);
    assert!((hi[0] - lo[0] - 1.08).abs() < 0.02);
    assert!(lo.iter().zip(&hi).all(|(a, b)| (a + b).abs() < 1e-12));
    // Solar cells face +z; nothing is used by more than two facets.
    assert!(mesh.facets_of_part(2).all(|t| mesh.normal(t)[2] > 0.999));
    assert!(edge_uses(&mesh, None).values().all(|&n| n <= 2));
    let net = ThermalNetwork::new(&mesh).unwrap();
    assert_eq!(net.free_edge_count(), 0);
    assert!(mesh.signed_volume_m3() > 0.0);
}

#[test]
fn energy_balance_sunlit_and_eclipse() {
    let earth = [-0.48, 0.0, -0.877];
    let mut meshes: Vec<(String, Mesh)> = MaterialCase::ALL
        .into_iter()
        .map(|c| (c.label().to_string(), cube_cylinder(c, COARSE_M)))
        .collect();
    meshes.push(("tango".into(), tango(0.1)));
    for (name, mesh) in &meshes {
        let net = ThermalNetwork::new(mesh).unwrap();
        for env in [sun_earth(), ThermalEnvironment::eclipse(earth)] {
            let sol = net.solve(&env).unwrap();
            let input = sol.absorbed_w + sol.dissipated_w;
            assert!(
                sol.energy_balance_rel() < 1e-6,
                "{name}: {}",
                sol.energy_balance_rel()
            );
            assert!(
                sol.max_residual_w <= 1e-9 * input,
                "{name}: residual {}",
                sol.max_residual_w
            );
            assert!(sol.iterations >= 1 && sol.iterations < 20);
            assert_eq!(sol.temperature_k.len(), mesh.facet_count());
            assert!(sol.temperature_k.iter().all(|t| t.is_finite() && *t >= 3.0));
        }
    }
}

fn plate(material: Material) -> Mesh {
    Mesh {
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        part_of: vec![0, 0],
        parts: vec![Part {
            name: "plate",
            material,
            dissipation_w: 0.0,
        }],
    }
}

/// A plate facing the Sun, without conduction, Earth or albedo:
/// εσ(T⁴ − Ts⁴) = αS cos θ.
#[test]
fn isolated_plate_matches_radiative_equilibrium() {
    let mesh = plate(Material {
        name: "plate",
        solar_absorptivity: 0.8,
        ir_emissivity: 0.6,
        conductivity_w_m_k: 0.0,
        thickness_m: 0.0,
        core_conductance_w_m2_k: 0.0,
    });
    for sun_deg in [0.0_f64, 60.0] {
        let sun = [sun_deg.to_radians().sin(), 0.0, sun_deg.to_radians().cos()];
        let mut env = ThermalEnvironment::sunlit(sun, [0.0, 0.0, -1.0]);
        env.earth_olr_w_m2 = 0.0;
        env.albedo = 0.0;
        let sol = solve_steady_state(&mesh, &env).unwrap();
        let q = 0.8 * 1361.0 * sun_deg.to_radians().cos();
        let analytic = (q / (0.6 * SIGMA) + 3.0_f64.powi(4)).powf(0.25);
        for &t in &sol.temperature_k {
            assert!((t - analytic).abs() < 1e-9 * analytic, "{t} vs {analytic}");
        }
    }
    // Earth infrared alone, plate facing the Earth: εσ(T⁴ − Ts⁴) = ε·OLR/H².
    let env = ThermalEnvironment::eclipse([0.0, 0.0, 1.0]);
    let sol = solve_steady_state(&mesh, &env).unwrap();
    let h = env.earth_distance_m / env.earth_radius_m;
    assert!((earth_view_factor(h, 1.0) - 1.0 / (h * h)).abs() < 1e-15);
    let analytic = (240.0 / (h * h * SIGMA) + 81.0).powf(0.25);
    assert!((sol.temperature_k[0] - analytic).abs() < 1e-9 * analytic);
}

/// A conductive closed box heated inside through one face only, no Sun, no Earth:
/// nearly uniform, at P = εσA(T⁴ − Ts⁴).
#[test]
fn isothermal_box_with_dissipation_only() {
    let copper_slab = Material {
        name: "slab",
        solar_absorptivity: 0.5,
        ir_emissivity: 0.8,
        conductivity_w_m_k: 400.0,
        thickness_m: 0.25,
        core_conductance_w_m2_k: 0.0,
    };
    let part = Part {
        name: "walls",
        material: copper_slab,
        dissipation_w: 0.0,
    };
    let mut mesh = closed_box([1.0, 1.0, 1.0], part, COARSE_M);
    mesh.parts.push(Part {
        name: "heated",
        dissipation_w: 1000.0,
        ..part
    });
    for t in 0..mesh.facet_count() {
        if mesh.normal(t)[2] > 0.5 {
            mesh.part_of[t] = 1;
        }
    }
    let mut env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
    env.earth_olr_w_m2 = 0.0;
    let sol = solve_steady_state(&mesh, &env).unwrap();
    assert_eq!(sol.absorbed_w, 0.0);
    assert!((sol.dissipated_w - 1000.0).abs() < 1e-9);
    let uniform = (1000.0 / (0.8 * SIGMA * 6.0) + 81.0).powf(0.25);
    let (lo, hi) = sol.min_max_k();
    // 1000 W through k·t = 100 W/K sheets: about 2 K from the heated face to the far one.
    assert!(hi - lo < 0.01 * uniform, "spread {lo}..{hi}");
    assert!(lo < uniform && hi > uniform, "{lo}..{hi} around {uniform}");
    assert!(sol.energy_balance_rel() < 1e-9);
    // Vertex temperatures (smooth shading) stay within the facet range.
    let vt = sol.vertex_temperatures_k(&mesh).unwrap();
    assert_eq!(vt.len(), mesh.vertices.len());
    assert!(vt.iter().all(|&t| t >= lo && t <= hi));
}

#[test]
fn sunlit_side_is_hotter_and_edges_are_graded() {
    let owned = cube_cylinder(MaterialCase::Mono, 0.1);
    let mesh = &owned;
    let env = ThermalEnvironment::sunlit([0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    let sol = solve_steady_state(mesh, &env).unwrap();
    let t = &sol.temperature_k;
    let face = |axis: usize, sign: f64| {
        (0..mesh.facet_count())
            .filter(move |&f| mesh.part_of[f] == 0 && mesh.normal(f)[axis] * sign > 0.99)
    };
    let top = mean(face(2, 1.0).map(|f| t[f]));
    let bottom = mean(face(2, -1.0).map(|f| t[f]));
    assert!(top > 300.0 && top < 380.0, "sunlit face {top} K");
    assert!(top > bottom + 50.0, "sunlit {top} K, anti-Sun {bottom} K");
    // The −y side face (unlit, edge-on to the Earth) is graded from the hot top edge
    // down to the cold bottom edge by conduction.
    let band = |z0: f64, z1: f64| {
        mean(
            face(1, -1.0)
                .filter(|&f| (z0..z1).contains(&mesh.centroid(f)[2]))
                .map(|f| t[f]),
        )
    };
    let (upper, middle, lower) = (band(0.3, 0.5), band(-0.1, 0.1), band(-0.5, -0.3));
    assert!(
        upper > middle + 5.0 && middle > lower + 5.0,
        "{upper} > {middle} > {lower}"
    );
    assert!(upper < top && lower > bottom.min(lower - 1.0));
}

#[test]
fn eclipse_is_colder_everywhere() {
    let earth = [-0.48, 0.0, -0.877];
    for mesh in [cube_cylinder(MaterialCase::Multi1, COARSE_M), tango(0.1)] {
        let net = ThermalNetwork::new(&mesh).unwrap();
        let sunlit = net.solve(&sun_earth()).unwrap();
        let eclipse = net.solve(&ThermalEnvironment::eclipse(earth)).unwrap();
        // The network is monotone: less absorbed power everywhere, lower T everywhere.
        for (s, e) in sunlit.temperature_k.iter().zip(&eclipse.temperature_k) {
            assert!(e < s, "{e} !< {s}");
        }
        let (_, hi) = eclipse.min_max_k();
        assert!(hi < 260.0 && hi > 100.0, "eclipse max {hi} K");
        assert!(sunlit.min_max_k().1 > 300.0);
    }
}

/// Heat crosses the cube–cylinder joint: dissipation in the cylinder alone warms
/// the cube (without the joint the cube would sit at the 3 K sink).
#[test]
fn heat_crosses_the_joint() {
    let mut mesh = cube_cylinder(MaterialCase::Mono, COARSE_M);
    mesh.parts[1].dissipation_w = 200.0;
    let mut env = ThermalEnvironment::eclipse([0.0, 0.0, -1.0]);
    env.earth_olr_w_m2 = 0.0;
    let sol = solve_steady_state(&mesh, &env).unwrap();
    let (cube_lo, _) = sol.part_min_max_k(&mesh, 0).unwrap();
    let (_, cyl_hi) = sol.part_min_max_k(&mesh, 1).unwrap();
    assert!(cube_lo > 60.0, "cube {cube_lo} K");
    assert!(cyl_hi > cube_lo);
    assert!(sol.energy_balance_rel() < 1e-9);
}

/// The cylinder shadows the cube's +x face below it when the Sun is above +x.
#[test]
fn cylinder_casts_a_shadow_on_the_cube() {
    let mesh = cube_cylinder(MaterialCase::Mono, 0.1);
    let net = ThermalNetwork::new(&mesh).unwrap();
    let mut env = ThermalEnvironment::sunlit([1.0, 0.0, 0.3], [0.0, 1.0, 0.0]);
    env.earth_olr_w_m2 = 0.0;
    env.albedo = 0.0;
    let q = net.absorbed_w(&env).unwrap();
    let on_face = |z0: f64, z1: f64| {
        (0..mesh.facet_count())
            .filter(|&f| {
                let c = mesh.centroid(f);
                mesh.part_of[f] == 0
                    && mesh.normal(f)[0] > 0.99
                    && c[1].abs() < 0.1
                    && (z0..z1).contains(&c[2])
            })
            .map(|f| q[f] / mesh.area_m2(f))
            .collect::<Vec<_>>()
    };
    let full = 0.86 * 1361.0 / 1.09_f64.sqrt();
    assert!(on_face(-0.45, -0.3).iter().all(|&f| f == 0.0));
    assert!(
        on_face(0.3, 0.5)
            .iter()
            .all(|&f| (f - full).abs() < 1e-9 * full)
    );
}

#[test]
fn low_emissivity_parts_differ() {
    // Multi-2: the ε = 0.10 cube is coupled to the sky 9× more weakly than the
    // ε = 0.90 cylinder: it runs warmer in eclipse than the mono-material cube.
    let earth = [0.0, 0.0, -1.0];
    let mono = solve_steady_state(
        &cube_cylinder(MaterialCase::Mono, COARSE_M),
        &ThermalEnvironment::eclipse(earth),
    )
    .unwrap();
    let multi = solve_steady_state(
        &cube_cylinder(MaterialCase::Multi2, COARSE_M),
        &ThermalEnvironment::eclipse(earth),
    )
    .unwrap();
    assert!(
        multi
            .temperature_k
            .iter()
            .zip(&mono.temperature_k)
            .any(|(m, o)| (m - o).abs() > 2.0)
    );
    // Tango in sunlight: polished-metal whips, white radiators and solar cells differ.
    let mesh = tango(0.1);
    let sol = solve_steady_state(
        &mesh,
        &ThermalEnvironment::sunlit([0.3, 0.2, 0.93], [0.0, 0.0, -1.0]),
    )
    .unwrap();
    let part_mean = |p: usize| mean(mesh.facets_of_part(p).map(|t| sol.temperature_k[t]));
    let cells = part_mean(2);
    assert!(cells > 320.0 && cells < 400.0, "cells {cells} K");
    assert!(
        part_mean(0) < cells - 30.0,
        "white radiators colder than the cells"
    );
    assert!(
        part_mean(5) < part_mean(0),
        "shaded patches colder than the radiators"
    );
}

#[test]
fn degenerate_input_is_an_error_not_a_panic() {
    let good = Material {
        name: "m",
        solar_absorptivity: 0.5,
        ir_emissivity: 0.5,
        conductivity_w_m_k: 1.0,
        thickness_m: 1e-3,
        core_conductance_w_m2_k: 0.0,
    };
    let env = sun_earth();
    let mut zero_area = plate(good);
    zero_area.vertices[2] = zero_area.vertices[0];
    assert!(matches!(
        solve_steady_state(&zero_area, &env),
        Err(ThermalError::DegenerateFacet { facet: 0, .. })
    ));
    let mut nan_vertex = plate(good);
    nan_vertex.vertices[1][0] = f64::NAN;
    assert_eq!(
        solve_steady_state(&nan_vertex, &env),
        Err(ThermalError::BadVertex { vertex: 1 })
    );
    let mut bad_index = plate(good);
    bad_index.triangles[1][2] = 99;
    assert_eq!(
        solve_steady_state(&bad_index, &env),
        Err(ThermalError::BadIndex { facet: 1 })
    );
    let mut bad_part = plate(good);
    bad_part.part_of[0] = 5;
    assert_eq!(
        solve_steady_state(&bad_part, &env),
        Err(ThermalError::BadIndex { facet: 0 })
    );
    let mut short = plate(good);
    short.part_of.pop();
    assert!(matches!(
        solve_steady_state(&short, &env),
        Err(ThermalError::BadIndex { .. })
    ));
    let empty = Mesh {
        vertices: vec![],
        triangles: vec![],
        part_of: vec![],
        parts: vec![],
    };
    assert_eq!(
        solve_steady_state(&empty, &env),
        Err(ThermalError::EmptyMesh)
    );
    for material in [
        Material {
            ir_emissivity: 0.0,
            ..good
        },
        Material {
            ir_emissivity: f64::NAN,
            ..good
        },
        Material {
            solar_absorptivity: 1.5,
            ..good
        },
        Material {
            conductivity_w_m_k: -1.0,
            ..good
        },
        Material {
            thickness_m: f64::INFINITY,
            ..good
        },
        Material {
            core_conductance_w_m2_k: -1.0,
            ..good
        },
        Material {
            core_conductance_w_m2_k: f64::NAN,
            ..good
        },
    ] {
        assert!(matches!(
            solve_steady_state(&plate(material), &env),
            Err(ThermalError::BadMaterial { .. })
        ));
    }
    let mut hot = plate(good);
    hot.parts[0].dissipation_w = f64::NAN;
    assert!(matches!(
        solve_steady_state(&hot, &env),
        Err(ThermalError::BadMaterial { .. })
    ));

    let mesh = plate(good);
    let mut envs = Vec::new();
    let mut e = env;
    e.sun_dir_body = Some([f64::NAN, 0.0, 1.0]);
    envs.push(e);
    envs.push(ThermalEnvironment::sunlit([0.0; 3], [0.0, 0.0, -1.0]));
    envs.push(ThermalEnvironment::eclipse([f64::NAN; 3]));
    let mut e = env;
    e.earth_distance_m = 1e6;
    envs.push(e);
    let mut e = env;
    e.albedo = -0.1;
    envs.push(e);
    let mut e = env;
    e.deep_space_k = 0.0;
    envs.push(e);
    let mut e = env;
    e.solar_constant_w_m2 = f64::INFINITY;
    envs.push(e);
    for e in envs {
        let err = solve_steady_state(&mesh, &e).unwrap_err();
        assert!(
            matches!(err, ThermalError::BadEnvironment { .. }),
            "{err:?}"
        );
        assert!(err.to_string().starts_with("thermal environment: "));
    }
}

/// A heated box sealed inside another box, not touching it, has no way to lose its
/// heat in this model: refused, not iterated forever.
#[test]
fn enclosed_dissipation_has_no_steady_state() {
    let m = Material {
        name: "m",
        solar_absorptivity: 0.5,
        ir_emissivity: 0.5,
        conductivity_w_m_k: 100.0,
        thickness_m: 1e-3,
        core_conductance_w_m2_k: 0.0,
    };
    let outer = closed_box(
        [2.0, 2.0, 2.0],
        Part {
            name: "outer",
            material: m,
            dissipation_w: 0.0,
        },
        0.5,
    );
    let inner = closed_box(
        [0.5, 0.5, 0.5],
        Part {
            name: "inner",
            material: m,
            dissipation_w: 5.0,
        },
        0.5,
    );
    let offset = outer.vertices.len() as u32;
    let mesh = Mesh {
        vertices: outer
            .vertices
            .iter()
            .chain(&inner.vertices)
            .copied()
            .collect(),
        triangles: outer
            .triangles
            .iter()
            .copied()
            .chain(inner.triangles.iter().map(|t| t.map(|v| v + offset)))
            .collect(),
        part_of: outer
            .part_of
            .iter()
            .copied()
            .chain(inner.part_of.iter().map(|_| 1))
            .collect(),
        parts: vec![outer.parts[0], inner.parts[0]],
    };
    let err = solve_steady_state(&mesh, &sun_earth()).unwrap_err();
    assert!(matches!(err, ThermalError::NoSteadyState { .. }), "{err}");
    // Without the dissipation the sealed box is pinned at the sink and the rest solves.
    let mut quiet = mesh.clone();
    quiet.parts[1].dissipation_w = 0.0;
    let sol = solve_steady_state(&quiet, &sun_earth()).unwrap();
    assert!(sol.energy_balance_rel() < 1e-6);
}

/// Timings and temperature ranges for the report: run with
/// `cargo test --release --test target_thermal -- --ignored --nocapture`.
#[test]
#[ignore]
fn report() {
    let earth = [-0.48, 0.0, -0.877];
    let run = |name: &str, mesh: &Mesh, env: &ThermalEnvironment| {
        let t0 = Instant::now();
        let net = ThermalNetwork::new(mesh).unwrap();
        let build = t0.elapsed();
        let mut best = f64::INFINITY;
        let mut sol = None;
        for _ in 0..5 {
            let t1 = Instant::now();
            sol = Some(net.solve(env).unwrap());
            best = best.min(t1.elapsed().as_secs_f64());
        }
        let sol = sol.unwrap();
        println!(
            "{name}: {} facets, {} links, {} joints, build {:.1} ms, solve {:.1} ms, {} Newton, balance {:.1e}, absorbed {:.0} W",
            mesh.facet_count(),
            net.link_count(),
            net.joint_count(),
            build.as_secs_f64() * 1e3,
            best * 1e3,
            sol.iterations,
            sol.energy_balance_rel(),
            sol.absorbed_w
        );
        for (p, part) in mesh.parts.iter().enumerate() {
            let (lo, hi) = sol.part_min_max_k(mesh, p).unwrap();
            println!("    {:>16}: {lo:6.1} .. {hi:6.1} K", part.name);
        }
    };
    for res in [0.05, 0.1, 0.2] {
        for case in MaterialCase::ALL {
            let mesh = cube_cylinder(case, res);
            run(
                &format!("cube+cyl {} res {res} sunlit", case.label()),
                &mesh,
                &sun_earth(),
            );
            run(
                &format!("cube+cyl {} res {res} eclipse", case.label()),
                &mesh,
                &ThermalEnvironment::eclipse(earth),
            );
        }
        let mesh = tango(res);
        run(
            &format!("tango res {res} sunlit"),
            &mesh,
            &ThermalEnvironment::sunlit([0.3, 0.2, 0.93], [0.0, 0.0, -1.0]),
        );
        run(
            &format!("tango res {res} eclipse"),
            &mesh,
            &ThermalEnvironment::eclipse([0.0, 0.0, -1.0]),
        );
    }
    let mesh = cube_cylinder(MaterialCase::Mono, 0.025);
    run("cube+cyl mono res 0.025 sunlit", &mesh, &sun_earth());
    let mesh = tango(0.025);
    run(
        "tango res 0.025 sunlit",
        &mesh,
        &ThermalEnvironment::sunlit([0.3, 0.2, 0.93], [0.0, 0.0, -1.0]),
    );
}

/// Random triangle soups (overlapping, open, intersecting, some degenerate) never
/// panic; when they solve, the energy balances.
#[test]
fn random_soups_solve_or_refuse() {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut solved, mut refused) = (0, 0);
    for case in 0..200 {
        let nt = 1 + (rnd() * 40.0) as usize;
        let nv = 3 + (rnd() * 30.0) as usize;
        let vertices: Vec<[f64; 3]> = (0..nv)
            .map(|_| [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5])
            .collect();
        let triangles: Vec<[u32; 3]> = (0..nt)
            .map(|_| [0, 1, 2].map(|_| (rnd() * nv as f64) as u32 % nv as u32))
            .collect();
        let parts = vec![
            Part {
                name: "a",
                material: Material {
                    name: "a",
                    solar_absorptivity: rnd(),
                    ir_emissivity: 0.01 + 0.99 * rnd(),
                    conductivity_w_m_k: 200.0 * rnd(),
                    thickness_m: 0.01 * rnd(),
                    core_conductance_w_m2_k: 0.0,
                },
                dissipation_w: if case % 3 == 0 { 10.0 * rnd() } else { 0.0 },
            },
            Part {
                name: "b",
                material: Material {
                    name: "b",
                    solar_absorptivity: rnd(),
                    ir_emissivity: 0.01 + 0.99 * rnd(),
                    conductivity_w_m_k: 0.0,
                    thickness_m: 0.0,
                    core_conductance_w_m2_k: 0.0,
                },
                dissipation_w: 0.0,
            },
        ];
        let part_of = (0..nt).map(|_| (rnd() * 2.0) as u16 % 2).collect();
        let mesh = Mesh {
            vertices,
            triangles,
            part_of,
            parts,
        };
        let sun = [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5];
        let env = if case % 2 == 0 {
            ThermalEnvironment::sunlit(sun, [0.0, 0.0, -1.0])
        } else {
            ThermalEnvironment::eclipse(sun)
        };
        match solve_steady_state(&mesh, &env) {
            Ok(sol) => {
                solved += 1;
                assert!(
                    sol.energy_balance_rel() < 1e-6,
                    "case {case}: {}",
                    sol.energy_balance_rel()
                );
                assert!(sol.temperature_k.iter().all(|t| t.is_finite() && *t >= 3.0));
            }
            Err(e) => {
                refused += 1;
                assert!(
                    matches!(
                        e,
                        ThermalError::DegenerateFacet { .. } | ThermalError::NoSteadyState { .. }
                    ),
                    "case {case}: {e}"
                );
            }
        }
    }
    assert!(
        solved > 20 && refused > 20,
        "{solved} solved, {refused} refused"
    );
}
