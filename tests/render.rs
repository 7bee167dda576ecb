//! The renderer against independent references: the projected box of a known pose, the
//! DN of a uniform plate from the f64 camera model by hand, the Earth's DN at nadir,
//! frame-level culling of the Earth, and the radiometry auto-range (Eq. 17).

use tirroi::core::Roi;
use tirroi::core::sensor::flux::SENSOR_AREA_M2;
use tirroi::core::sensor::{BandLut, BandRadiance, DetectionScale, DnMapping};
use tirroi::host::imaging::render::{
    EarthView, Readout, RenderInput, SensorEffects, TargetView, render,
};
use tirroi::host::world::earth::{EarthMap, OlrGrid, flux_to_temperature_k};
use tirroi::host::world::geom::{Rotation, Vec3};
use tirroi::host::world::scene::Camera;
use tirroi::host::world::spacecraft::models::{closed_box, grey_aluminium_skin};
use tirroi::host::world::spacecraft::{Material, MaterialCase, Mesh, Part, cube_cylinder};

fn band() -> (BandRadiance, BandLut) {
    let band = BandRadiance::hayabusa2_tir();
    let lut = BandLut::new(&band);
    (band, lut)
}

fn input<'a>(
    camera: &'a Camera,
    readout: Readout,
    target: Option<TargetView<'a>>,
    earth: Option<EarthView<'a>>,
    band: &'a (BandRadiance, BandLut),
) -> RenderInput<'a> {
    RenderInput {
        camera,
        readout,
        target,
        earth,
        earth_distance_m: 10_871e3,
        noise_seed: None,
        band: &band.0,
        lut: &band.1,
        gain_factor: 1.0,
        moon: None,
        sensor: SensorEffects::NONE,
    }
}

/// The box the coverage ≥ 1/2 rule gives for a silhouette whose projected extremes are
/// `lo`..`hi` along one axis (pixel x is in when its covered part is at least half).
fn rule_box(lo: f64, hi: f64) -> (u16, u16) {
    ((lo - 0.5).ceil() as u16, ((hi - 0.5).floor() + 1.0) as u16)
}

/// Projected extremes (u0, u1, v0, v1) of a mesh's vertices under a pose.
fn projected_extent(mesh: &Mesh, r: &Rotation, centre: Vec3, f: f64) -> [f64; 4] {
    let (mut u0, mut u1, mut v0, mut v1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for v in &mesh.vertices {
        let p = r.apply(*v);
        let (x, y, z) = (p[0] + centre[0], p[1] + centre[1], p[2] + centre[2]);
        let (u, w) = (164.0 + f * x / z, 124.0 + f * y / z);
        u0 = u0.min(u);
        u1 = u1.max(u);
        v0 = v0.min(w);
        v1 = v1.max(w);
    }
    [u0, u1, v0, v1]
}

fn detect_frame(mesh: &Mesh, r: Rotation, centre: Vec3) -> tirroi::host::imaging::render::Rendered {
    let camera = Camera::default();
    let b = band();
    let temps = vec![290.0; mesh.facet_count()];
    let target = TargetView {
        mesh,
        temperature_k: &temps,
        body_to_camera: r,
        centre_m: centre,
    };
    render(&input(
        &camera,
        Readout::Detection(DetectionScale::Scale1),
        Some(target),
        None,
        &b,
    ))
    .unwrap()
}

#[test]
fn known_cube_pose_gives_the_known_box() {
    // A 1 m cube, axis-aligned with the camera: whatever its offset, its silhouette's
    // extremes are straight image-axis edges (front or back face), so the coverage rule
    // gives the box exactly from the projected vertices.
    let f = Camera::default().focal_px();
    let cube = closed_box(
        [1.0, 1.0, 1.0],
        Part {
            name: "cube",
            material: grey_aluminium_skin("cube", 0.86),
            dissipation_w: 0.0,
        },
        0.1,
    );
    let mut checked = 0;
    for k in 0..40 {
        let range = 15.0 + 0.9 * f64::from(k);
        let centre: Vec3 = [0.3 * range / 15.0, -0.2 * range / 15.0, range];
        let [u0, u1, v0, v1] = projected_extent(&cube, &Rotation::IDENTITY, centre, f);
        // Skip poses whose edges fall within 1/8 px of the rule's threshold (4 × 4
        // samples estimate coverage in steps of 1/16).
        let near_tie = [u0, u1, v0, v1]
            .iter()
            .any(|e| ((e - 0.5) - (e - 0.5).round()).abs() < 0.125);
        if near_tie {
            continue;
        }
        let out = detect_frame(&cube, Rotation::IDENTITY, centre);
        let (x0, x1) = rule_box(u0, u1);
        let (y0, y1) = rule_box(v0, v1);
        assert_eq!(out.truth, Roi::new(x0, y0, x1, y1), "range {range} m");
        checked += 1;
    }
    assert!(
        checked >= 5,
        "only {checked} poses away from a rounding tie"
    );
    // At 20 m face-on and centred, the 1 m face spans f·1/19.5 = 58.5 px.
    let out = detect_frame(&cube, Rotation::IDENTITY, [0.0, 0.0, 20.0]);
    assert_eq!(out.truth, Roi::new(135, 95, 193, 153));
}

#[test]
fn rotated_cube_cylinder_box_lies_within_a_pixel_of_its_projection() {
    // Tilted, the extremes are corners, where a pixel is less than half covered even
    // outside the vertex's own column: the box is inside the projected vertices' box and
    // within one pixel of it.
    let f = Camera::default().focal_px();
    let mesh = cube_cylinder(MaterialCase::Mono, 0.1);
    let r = Rotation::from_euler_zyx_deg(20.0, -15.0, 5.0);
    for range in [17.3, 23.9, 31.7, 44.1, 380.0] {
        let centre: Vec3 = [0.4, -0.3, range];
        let [u0, u1, v0, v1] = projected_extent(&mesh, &r, centre, f);
        let out = detect_frame(&mesh, r, centre);
        let t = out.truth;
        let outer = [u0.floor(), v0.floor(), u1.ceil(), v1.ceil()];
        let got = [t.x0, t.y0, t.x1, t.y1].map(f64::from);
        for k in 0..2 {
            assert!(
                got[k] >= outer[k] && got[k] <= outer[k] + 1.0,
                "{range}: {got:?} {outer:?}"
            );
            assert!(
                got[k + 2] <= outer[k + 2] && got[k + 2] >= outer[k + 2] - 1.0,
                "{range}: {got:?} {outer:?}"
            );
        }
        // Detection mode: the target saturates every Table 5 scale (Section 4.1).
        let (cx, cy) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
        assert_eq!(out.dn[cy as usize * 328 + cx as usize], 16383);
    }
}

/// A flat square plate of side `side_m` facing the camera (normal −z), two triangles.
fn plate(side_m: f64, emissivity: f64) -> Mesh {
    let h = side_m / 2.0;
    Mesh {
        vertices: vec![[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]],
        // Counter-clockwise seen from −z (the camera side): outward normal −z.
        triangles: vec![[0, 2, 1], [0, 3, 2]],
        part_of: vec![0, 0],
        parts: vec![Part {
            name: "plate",
            material: Material {
                name: "test gray",
                solar_absorptivity: 0.5,
                ir_emissivity: emissivity,
                conductivity_w_m_k: 100.0,
                thickness_m: 0.002,
                core_conductance_w_m2_k: 0.0,
            },
            dissipation_w: 0.0,
        }],
    }
}

#[test]
fn uniform_300k_plate_gives_the_sensor_models_dn() {
    let camera = Camera::default();
    let b = band();
    let mesh = plate(2.0, 0.86);
    assert!(mesh.normal(0)[2] < -0.99, "plate must face the camera");
    let temps = vec![300.0; 2];
    let range = 20.0;
    // Independent reference: f64 band radiance, Eq. 4 by hand at each facet centroid.
    let radiance = b.0.radiance_w_m2_sr(300.0, 0.86).unwrap();
    let q: Vec<f64> = (0..2)
        .map(|t| {
            let c = mesh.centroid(t);
            let r = [c[0], c[1], c[2] + range];
            let d2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let cos = range / d2.sqrt(); // both cosines: plate ⟂ boresight
            radiance * cos * cos / d2 * SENSOR_AREA_M2
        })
        .collect();
    let q_max = q[0] * 1.3;
    let mapping = DnMapping::detection(DetectionScale::Custom(q_max), 14).unwrap();
    let expected: Vec<f64> = q.iter().map(|&q| q / q_max * 16383.0).collect();
    let target = TargetView {
        mesh: &mesh,
        temperature_k: &temps,
        body_to_camera: Rotation::IDENTITY,
        centre_m: [0.0, 0.0, range],
    };
    let out = render(&input(
        &camera,
        Readout::Detection(DetectionScale::Custom(q_max)),
        Some(target),
        None,
        &b,
    ))
    .unwrap();
    assert_eq!(out.mapping, mapping);
    // 2 m at 20 m is 114 px: check the interior, away from the diagonal and the edges.
    let mut interior = 0;
    for y in 80..168 {
        for x in 120..208 {
            let i = y * 328 + x;
            assert_eq!(out.coverage[i], 1.0);
            let dn = f64::from(out.dn[i]);
            let near = expected.iter().any(|e| (dn - e).abs() <= 0.5 + 1e-3);
            assert!(
                near,
                "pixel ({x}, {y}): DN {dn}, expected one of {expected:?}"
            );
            interior += 1;
        }
    }
    assert!(interior > 7000);
    // Deep space around it: DN 0, and the box is the plate's.
    assert_eq!(out.dn[0], 0);
    let half = camera.focal_px() * 1.0 / range;
    let (x0, x1) = rule_box(164.0 - half, 164.0 + half);
    let (y0, y1) = rule_box(124.0 - half, 124.0 + half);
    assert_eq!(out.truth, Roi::new(x0, y0, x1, y1));
    // Edge pixels are mixed: coverage strictly between 0 and 1 along the border.
    let edge = (y0 as usize + 20) * 328 + x0 as usize - 1;
    assert!(out.coverage[edge] < 1.0 && out.coverage[edge + 1] > 0.0);
}

#[test]
fn radiometry_auto_range_maps_the_coldest_and_hottest_pure_pixels_to_0_and_full_scale() {
    let camera = Camera::default();
    let b = band();
    let mesh = plate(1.0, 0.9);
    // Left triangle hotter than the right one.
    let temps = vec![320.0, 250.0];
    let target = TargetView {
        mesh: &mesh,
        temperature_k: &temps,
        body_to_camera: Rotation::IDENTITY,
        centre_m: [0.0, 0.0, 10.0],
    };
    let out = render(&input(&camera, Readout::Radiometry, Some(target), None, &b)).unwrap();
    let dn: Vec<u16> = out
        .dn
        .iter()
        .zip(&out.coverage)
        .filter(|(_, c)| **c == 1.0)
        .map(|(d, _)| *d)
        .collect();
    assert_eq!(dn.iter().max(), Some(&16383));
    assert_eq!(dn.iter().min(), Some(&0));
    // F = D·q of the hot facet maps to the top: the DN map's signal of full scale is it.
    let f_top = out.mapping.signal(16383.0);
    let l_hot = b.0.radiance_w_m2_sr(320.0, 0.9).unwrap();
    // F = π·L·cos θ_f·cos θ_s·(d/r)² ≤ π·L, and within 1 % of it near the boresight.
    let ratio = f_top / (std::f64::consts::PI * l_hot);
    assert!(ratio > 0.99 && ratio <= 1.0 + 1e-4, "{ratio}");
}

fn uniform_earth(olr: f32, mesh_deg: f64, lut: &BandLut) -> EarthMap {
    let grid = OlrGrid::from_values(vec![olr; OlrGrid::ROWS * OlrGrid::COLS]).unwrap();
    EarthMap::refine(&grid, mesh_deg, lut).unwrap()
}

#[test]
fn earth_at_nadir_gives_the_table5_dn_and_is_culled_out_of_view() {
    let camera = Camera::default();
    let b = band();
    let map = uniform_earth(240.0, 1.0, &b.1);
    let distance = 10_871e3;
    let view = |off_deg: f64| EarthView {
        map: &map,
        centre_m: [
            0.0,
            distance * off_deg.to_radians().sin(),
            distance * off_deg.to_radians().cos(),
        ],
        radius_m: 6_371e3,
        camera_to_earth: Rotation::IDENTITY,
    };
    let out = render(&input(
        &camera,
        Readout::Detection(DetectionScale::Scale1),
        None,
        Some(view(0.0)),
        &b,
    ))
    .unwrap();
    assert_eq!(out.earth_fraction, 1.0);
    // Reference: Eq. 10 then the f64 band radiance, Eq. 4 face-on at |r| = 10 871 km.
    let t = flux_to_temperature_k(240.0);
    let l = b.0.radiance_w_m2_sr(t, 1.0).unwrap();
    let q = l * SENSOR_AREA_M2 / distance / distance;
    let expected = q / 3e-17 * 16383.0;
    let centre = f64::from(out.dn[124 * 328 + 164]);
    assert!((centre - expected).abs() <= 1.0, "{centre} vs {expected}");
    // Off-centre pixels see the surface obliquely: darker towards the frame's edge.
    assert!(out.dn[124 * 328] < out.dn[124 * 328 + 164]);

    // Earth 80° off the boresight: no pixel can see it, and no ray is cast.
    let out = render(&input(
        &camera,
        Readout::Detection(DetectionScale::Scale1),
        None,
        Some(view(80.0)),
        &b,
    ))
    .unwrap();
    assert_eq!(out.earth_fraction, 0.0);
    assert_eq!(out.stats.earth_rays, 0);
    assert!(out.dn.iter().all(|&d| d == 0));

    // Limb across the frame: part Earth, part space, limb pixels supersampled.
    let limb = 36.0 + 3.0;
    let out = render(&input(
        &camera,
        Readout::Detection(DetectionScale::Scale1),
        None,
        Some(view(limb)),
        &b,
    ))
    .unwrap();
    assert!(
        out.earth_fraction > 0.05 && out.earth_fraction < 0.95,
        "{}",
        out.earth_fraction
    );
    assert!(out.stats.earth_rays > 328 * 248);
}

#[test]
fn target_pixels_skip_the_earth() {
    let camera = Camera::default();
    let b = band();
    let map = uniform_earth(240.0, 1.0, &b.1);
    let mesh = plate(4.0, 0.86);
    let temps = vec![300.0; 2];
    let target = TargetView {
        mesh: &mesh,
        temperature_k: &temps,
        body_to_camera: Rotation::IDENTITY,
        centre_m: [0.0, 0.0, 15.0],
    };
    let earth = EarthView {
        map: &map,
        centre_m: [0.0, 0.0, 10_871e3],
        radius_m: 6_371e3,
        camera_to_earth: Rotation::IDENTITY,
    };
    let out = render(&input(
        &camera,
        Readout::Detection(DetectionScale::Scale1),
        Some(target),
        Some(earth),
        &b,
    ))
    .unwrap();
    let full = out.coverage.iter().filter(|&&c| c == 1.0).count();
    assert!(full > 10_000);
    assert_eq!(out.stats.earth_rays, 328 * 248 - full);
    assert!(out.earth_fraction < 1.0 - full as f64 / (328.0 * 248.0) + 0.01);
}

#[test]
fn a_uniform_radiometry_scene_keeps_a_usable_range_and_noise() {
    // One temperature: Eq. 17 alone has no range; the renderer keeps 10 NETDs of span so
    // the noise (NETD-scaled) stays finite and the plate sits mid-scale.
    let camera = Camera::default();
    let b = band();
    let mesh = plate(1.0, 0.9);
    let temps = vec![300.0, 300.0];
    let target = TargetView {
        mesh: &mesh,
        temperature_k: &temps,
        body_to_camera: Rotation::IDENTITY,
        centre_m: [0.0, 0.0, 400.0],
    };
    let mut i = input(&camera, Readout::Radiometry, Some(target), None, &b);
    i.noise_seed = Some(5);
    let out = render(&i).unwrap();
    let expected_sigma = 16383.0 / tirroi::host::imaging::render::MIN_RANGE_NETD as f32;
    assert!(
        (out.noise_sigma_dn - expected_sigma).abs() < 0.02 * expected_sigma,
        "{}",
        out.noise_sigma_dn
    );
}

/// Deep space with the real camera's signature and the fixed-gain readout: the frame
/// carries the calibration frame's shading and column pattern (within 10 %, measured by
/// the same fit), sits on the pedestal, and the PSF costs nothing to a uniform scene.
#[test]
fn deep_space_carries_the_real_camera_signature_on_the_pedestal() {
    use tirroi::host::imaging::psf::OpticsPsf;
    use tirroi::host::imaging::signature::fit::fit_frame;
    use tirroi::host::imaging::signature::{Calibration, FIXED_GAIN_PEDESTAL_DN};
    let camera = Camera::default();
    let b = band();
    let cal = Calibration::hayabusa2_tir().unwrap();
    let psf = OpticsPsf::hayabusa2_tir(camera.pixel_pitch_um).unwrap();
    let fixed = cal.fixed_gain();
    for seed in [1u64, 2, 3] {
        let sig = cal.realise(camera.width, camera.height, seed);
        let mut inp = input(&camera, Readout::Radiometry, None, None, &b);
        inp.sensor = SensorEffects {
            psf: Some(&psf),
            signature: Some(&sig),
            fixed_gain: Some(fixed),
        };
        let out = render(&inp).unwrap();
        let dn: Vec<f64> = out.dn.iter().map(|&d| f64::from(d)).collect();
        let (fit, _) = fit_frame(&dn, camera.width, camera.height).unwrap();
        let amp = fit.shading.amplitude_dn / cal.fit.shading.amplitude_dn - 1.0;
        let col = fit.columns.sigma_dn / cal.fit.columns.sigma_dn - 1.0;
        assert!(
            amp.abs() < 0.1 && col.abs() < 0.1,
            "seed {seed}: {amp} {col}"
        );
        // Deep space about the pedestal: the mean within a few DN, nothing near 0.
        assert!((fit.shading.mean_dn - FIXED_GAIN_PEDESTAL_DN).abs() < 5.0);
        assert!(
            *out.dn.iter().min().unwrap() > 900,
            "{:?}",
            out.dn.iter().min()
        );
    }
    // Without sensor effects the frame is the flat auto-ranged deep space it was.
    let plain = render(&input(&camera, Readout::Radiometry, None, None, &b)).unwrap();
    assert!(plain.dn.iter().all(|&d| d == plain.dn[0]));
}
