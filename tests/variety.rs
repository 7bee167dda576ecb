//! The variety knobs of a scene kind against independent expectations: the gain factor
//! (DN scale about the DN-0 signal, clipping), the NETD factor (noise σ in DN and the
//! measured spread), the bit depth (saturation level, the `bits` column eval reads),
//! edge-cut targets (truth clipped to the frame, never empty) and the Moon (disc radius
//! from its angular size, day-side and night-side temperature back through the band
//! radiance).

use std::path::PathBuf;

use tirroi::core::Roi;
use tirroi::core::sensor::flux::SENSOR_AREA_M2;
use tirroi::core::sensor::{BandLut, BandRadiance, DetectionScale};
use tirroi::host::dataset::{WriteOptions, keep_in_view, plan, write_dataset};
use tirroi::host::eval::scoring::{read_row_frame, read_truth};
use tirroi::host::imaging::image_io::read_frame;
use tirroi::host::imaging::render::{
    EarthView, MoonView, Readout, RenderInput, Rendered, SensorEffects, TargetView, render,
};
use tirroi::host::world::earth::{EarthMap, OlrGrid};
use tirroi::host::world::geom::{Rotation, Vec3, normalize};
use tirroi::host::world::moon::{
    MOON_EMISSIVITY, MOON_NIGHT_K, MOON_SUBSOLAR_K, angular_radius_rad,
};
use tirroi::host::world::scene::{Camera, SceneFile};
use tirroi::host::world::spacecraft::{Material, Mesh, Part};

fn band() -> (BandRadiance, BandLut) {
    let band = BandRadiance::hayabusa2_tir();
    let lut = BandLut::new(&band);
    (band, lut)
}

/// A flat square plate of side `side_m` facing the camera, one temperature per triangle.
fn plate(side_m: f64) -> Mesh {
    let h = side_m / 2.0;
    Mesh {
        vertices: vec![[-h, -h, 0.0], [h, -h, 0.0], [h, h, 0.0], [-h, h, 0.0]],
        triangles: vec![[0, 2, 1], [0, 3, 2]],
        part_of: vec![0, 0],
        parts: vec![Part {
            name: "plate",
            material: Material {
                name: "test gray",
                solar_absorptivity: 0.5,
                ir_emissivity: 0.9,
                conductivity_w_m_k: 100.0,
                thickness_m: 0.002,
                core_conductance_w_m2_k: 0.0,
            },
            dissipation_w: 0.0,
        }],
    }
}

struct Scene<'a> {
    camera: Camera,
    readout: Readout,
    mesh: &'a Mesh,
    temps: Vec<f64>,
    centre: Vec3,
    gain: f64,
    noise: Option<u64>,
    moon: Option<MoonView>,
    target: bool,
}

impl<'a> Scene<'a> {
    fn new(mesh: &'a Mesh, readout: Readout) -> Self {
        Scene {
            camera: Camera::default(),
            readout,
            mesh,
            temps: vec![300.0; mesh.facet_count()],
            centre: [0.0, 0.0, 20.0],
            gain: 1.0,
            noise: None,
            moon: None,
            target: true,
        }
    }

    fn render(&self, b: &(BandRadiance, BandLut), earth: Option<EarthView<'_>>) -> Rendered {
        let target = TargetView {
            mesh: self.mesh,
            temperature_k: &self.temps,
            body_to_camera: Rotation::IDENTITY,
            centre_m: self.centre,
        };
        render(&RenderInput {
            camera: &self.camera,
            readout: self.readout,
            target: self.target.then_some(target),
            earth,
            earth_distance_m: 10_871e3,
            noise_seed: self.noise,
            band: &b.0,
            lut: &b.1,
            gain_factor: self.gain,
            moon: self.moon,
            sensor: SensorEffects::NONE,
        })
        .unwrap()
    }
}

#[test]
fn gain_factor_scales_dn_about_the_zero_signal_and_clips() {
    let b = band();
    let mesh = plate(2.0);
    // Detection: DN = g·a·q, so every pixel's DN doubles (to rounding) until 2¹⁴ − 1;
    // q_max is 3 × the plate's q (Eq. 4 face-on at 20 m), so the plate sits at 1/3.
    let q_plate = b.0.radiance_w_m2_sr(300.0, 0.9).unwrap() * SENSOR_AREA_M2 / 400.0;
    let scale = Readout::Detection(DetectionScale::Custom(3.0 * q_plate));
    let mut s = Scene::new(&mesh, scale);
    let one = s.render(&b, None);
    s.gain = 2.0;
    let two = s.render(&b, None);
    assert_eq!(two.mapping.gain_dn(), 2.0 * one.mapping.gain_dn());
    let mut checked = 0;
    for (d1, d2) in one.dn.iter().zip(&two.dn) {
        let want = (2.0 * f64::from(*d1)).min(16383.0);
        assert!((f64::from(*d2) - want).abs() <= 1.0, "{d1} -> {d2}");
        checked += usize::from(*d1 > 1000);
    }
    assert!(checked > 7000, "{checked} plate pixels");
    let plate_dn = one.dn[124 * 328 + 164];
    assert!(
        (f64::from(plate_dn) - 16383.0 / 3.0).abs() < 10.0,
        "{plate_dn}"
    );

    // Radiometry: two temperatures auto-range to 0 and full scale; a factor of 0.5
    // puts the hot one at half scale, 2 keeps the cold one at 0 and clips the hot one.
    let mut s = Scene::new(&mesh, Readout::Radiometry);
    s.temps = vec![280.0, 320.0];
    let base = s.render(&b, None);
    for g in [0.5, 2.0] {
        s.gain = g;
        let out = s.render(&b, None);
        let mut hot_clipped = 0;
        for (i, (d1, d2)) in base.dn.iter().zip(&out.dn).enumerate() {
            if base.coverage[i] < 1.0 {
                continue;
            }
            let want = (g * f64::from(*d1)).min(16383.0);
            assert!((f64::from(*d2) - want).abs() <= 1.0, "g {g}: {d1} -> {d2}");
            hot_clipped += usize::from(*d1 == 16383 && *d2 == 16383);
        }
        assert_eq!(hot_clipped > 0, g > 1.0);
        assert_eq!(out.mapping.signal(0.0), base.mapping.signal(0.0));
    }
}

#[test]
fn noise_sigma_follows_the_netd_factor_and_the_measured_spread() {
    let b = band();
    let mesh = plate(2.0);
    // Radiometry over 280 K and 320 K halves, the gain halved so the hot half sits
    // mid-scale (no clipping of its noise); the range (40 K) is far above 10 NETDs.
    let mut sigmas = Vec::new();
    for factor in [0.5, 1.0, 3.0] {
        let mut s = Scene::new(&mesh, Readout::Radiometry);
        s.temps = vec![280.0, 320.0];
        s.gain = 0.5;
        s.camera.netd_k *= factor;
        s.noise = Some(11);
        let noisy = s.render(&b, None);
        s.noise = None;
        let clean = s.render(&b, None);
        // Spread of noisy − clean over the hot half's interior.
        let d: Vec<f64> = (80..168)
            .flat_map(|y| (120..208).map(move |x| y * 328 + x))
            .filter(|&i| clean.dn[i] > 4000)
            .map(|i| f64::from(noisy.dn[i]) - f64::from(clean.dn[i]))
            .collect();
        assert!(d.len() > 3000, "{}", d.len());
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt();
        let sigma = f64::from(noisy.noise_sigma_dn);
        eprintln!("NETD factor {factor}: noise_sigma_dn {sigma:.2}, measured {sd:.2}");
        assert!((sd - sigma).abs() < 0.15 * sigma, "{sd} vs {sigma}");
        sigmas.push(sigma);
    }
    assert!((sigmas[0] / sigmas[1] - 0.5).abs() < 1e-4);
    assert!((sigmas[2] / sigmas[1] - 3.0).abs() < 1e-4);
}

#[test]
fn bit_depth_sets_the_saturation_level() {
    let b = band();
    let mesh = plate(2.0);
    for bits in [12u8, 14, 16] {
        let mut s = Scene::new(&mesh, Readout::Detection(DetectionScale::Custom(1e-12)));
        s.camera.bits = bits;
        let out = s.render(&b, None);
        let full = (1u32 << bits) - 1;
        // The plate's q is above q_max: saturated at 2ⁿ − 1, not beyond.
        assert_eq!(u32::from(out.dn[124 * 328 + 164]), full, "{bits} bits");
        assert_eq!(u32::from(*out.dn.iter().max().unwrap()), full);
        assert_eq!(out.mapping.bits(), bits);
    }
}

#[test]
fn keep_in_view_pulls_an_outside_centre_back_to_the_edge_band() {
    let half = [164.0, 124.0];
    // Inside: unchanged.
    assert_eq!(keep_in_view([100.0, -50.0], half, 30.0), [100.0, -50.0]);
    // Beyond the right edge by 40 px, inner disc 30 px: back to 28 px beyond (30 − 2).
    assert_eq!(keep_in_view([204.0, 0.0], half, 30.0), [192.0, 0.0]);
    // Beyond a corner: to 28 px from the corner along the same direction.
    let p = keep_in_view([164.0 + 30.0, 124.0 + 40.0], half, 30.0);
    assert!(((p[0] - 164.0).hypot(p[1] - 124.0) - 28.0).abs() < 1e-9);
    assert!(((p[1] - 124.0) / (p[0] - 164.0) - 40.0 / 30.0).abs() < 1e-9);
    // A sub-pixel inner disc: the centre itself 2 − 0.5 px inside the edge.
    assert_eq!(keep_in_view([300.0, -300.0], half, 0.5), [162.5, -122.5]);
}

#[test]
fn a_target_half_outside_the_frame_has_its_truth_clipped_to_the_frame() {
    let b = band();
    let mesh = plate(2.0);
    let mut s = Scene::new(&mesh, Readout::Detection(DetectionScale::Scale3));
    // Centre on the right edge (u = 328): half the 114 px plate is outside.
    let f = s.camera.focal_px();
    s.centre = [164.0 / f * 20.0, 0.0, 20.0];
    let out = s.render(&b, None);
    let half = f * 1.0 / 20.0;
    let x0 = (328.0 - half - 0.5).ceil() as u16;
    let (y0, y1) = (
        (124.0 - half - 0.5).ceil() as u16,
        ((124.0 + half - 0.5).floor() + 1.0) as u16,
    );
    assert_eq!(out.truth, Roi::new(x0, y0, 328, y1));
}

/// A small dataset of far cube-cylinders in detection frames.
fn small_scene(extra: &str, count: usize) -> SceneFile {
    let text = format!(
        "[dataset]\nseed = 3\nthermal_states = 1\n[[scene]]\ncount = {count}\nmode = \"detection\"\nscale = 3\nresolution_m = 0.2\nearth = false\nrange_m = {{ min = 15.0, max = 60.0 }}\n{extra}\n"
    );
    SceneFile::parse(&text, "test").unwrap()
}

#[test]
fn the_knobs_draw_after_every_existing_draw() {
    let plain = plan(&small_scene("", 8));
    let varied = plan(&small_scene(
        "gain = { min = 0.5, max = 2.0 }\nnoise_netd_factor = { min = 0.5, max = 3.0 }\nbits = [12, 14, 16]\nmoon = { probability = 0.5 }",
        8,
    ));
    for (a, b) in plain.iter().zip(&varied) {
        assert_eq!(
            (
                a.range_m,
                a.offset_px,
                a.body_to_camera,
                a.earth_dir_camera,
                a.noise_seed
            ),
            (
                b.range_m,
                b.offset_px,
                b.body_to_camera,
                b.earth_dir_camera,
                b.noise_seed
            )
        );
        assert_eq!(
            (a.gain_factor, a.netd_factor, a.bits, a.moon),
            (1.0, 1.0, 14, None)
        );
        assert!((0.5..=2.0).contains(&b.gain_factor) && (0.5..=3.0).contains(&b.netd_factor));
    }
    let bits: Vec<u8> = varied.iter().map(|p| p.bits).collect();
    assert_eq!(bits, [12, 14, 16, 12, 14, 16, 12, 14]);
    assert!(varied.iter().any(|p| p.moon.is_some()) && varied.iter().any(|p| p.moon.is_none()));
}

#[test]
fn edge_cut_datasets_never_lose_the_target_and_record_the_bit_depth_eval_reads() {
    let file = small_scene("max_offset_fraction = 1.5\nbits = [12, 16]", 16);
    let dir: PathBuf = std::env::temp_dir().join(format!("tirroi-variety-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_dataset(&file, &dir, &WriteOptions::default()).unwrap();
    let rows = read_truth(&dir.join("truth.csv")).unwrap();
    assert_eq!(rows.len(), 16);
    let mut at_edge = 0;
    for (k, row) in rows.iter().enumerate() {
        assert!(!row.roi.is_empty(), "{}: target lost", row.file);
        assert!(row.roi.x1 <= 328 && row.roi.y1 <= 248);
        at_edge += usize::from(
            row.roi.x0 == 0 || row.roi.y0 == 0 || row.roi.x1 == 328 || row.roi.y1 == 248,
        );
        let bits = [12, 16][k % 2];
        assert_eq!(row.bits, Some(bits));
        // What eval and tune read: the row's depth, even against an explicit --bits 14.
        let frame = read_row_frame(&dir, row, Some(14)).unwrap();
        assert_eq!(frame.bits, bits);
        // Without the column (`tirroi detect` on the file alone) the PNG's sBIT chunk
        // tells the depth; before the renderer wrote it, a 12-bit frame was taken for
        // 14-bit here.
        let from_file = read_frame(&dir.join(&row.file), None).unwrap();
        assert_eq!(from_file.bits, bits);
        assert!(u32::from(*frame.pixels.iter().max().unwrap()) < 1 << bits);
    }
    eprintln!("{at_edge} of 16 truth boxes touch the frame edge");
    assert!(at_edge >= 4, "{at_edge}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Moon alone (no target) in radiometry at frame pixel (u, v), lit from `sun`.
fn moon_frame(
    b: &(BandRadiance, BandLut),
    u: f64,
    v: f64,
    sun: Vec3,
    earth: Option<EarthView<'_>>,
) -> Rendered {
    let mesh = plate(1.0);
    let mut s = Scene::new(&mesh, Readout::Radiometry);
    s.target = false;
    let f = s.camera.focal_px();
    let dir = normalize([(u - 164.0) / f, (v - 124.0) / f, 1.0]);
    s.moon = Some(MoonView {
        dir_camera: dir,
        sun_dir_camera: sun,
    });
    s.render(b, earth)
}

/// Radiometric temperature of a pixel's F (= π·ε·L·cos θ_f·cos θ_s) for ε = 0.95.
fn t_of(b: &(BandRadiance, BandLut), f_w_m2: f32, cos: f64) -> f64 {
    b.0.temperature_k(
        f64::from(f_w_m2) / std::f64::consts::PI / cos,
        MOON_EMISSIVITY,
    )
    .unwrap()
}

#[test]
fn the_moon_is_a_10_px_disc_at_390_k_by_day_and_100_k_by_night() {
    let b = band();
    let f = Camera::default().focal_px();
    let (u, v) = (100.5, 80.5);
    let dir = normalize([(u - 164.0) / f, (v - 124.0) / f, 1.0]);
    // Full Moon: the Sun behind the camera, along the line of sight to the Moon.
    let full = moon_frame(&b, u, v, [-dir[0], -dir[1], -dir[2]], None);
    let r_px = angular_radius_rad() * f;
    let area = std::f64::consts::PI * r_px * r_px;
    eprintln!(
        "Moon radius {r_px:.2} px: {} centres on the disc, π r² = {area:.1}",
        full.moon_px
    );
    assert!((full.moon_px as f64 - area).abs() < 0.08 * area);
    // Every lit pixel within r + 1 px of the centre, none beyond.
    for (i, s) in full.signal.iter().enumerate() {
        let (x, y) = ((i % 328) as f64 + 0.5, (i / 328) as f64 + 0.5);
        let d = (x - u).hypot(y - v);
        if d > r_px + 1.0 {
            assert_eq!(*s, 0.0);
        }
        if d < r_px - 1.0 {
            assert!(*s > 0.0);
        }
    }
    // The centre pixel sees the subsolar point: T_ss within the spread of cos(i)^¼
    // over the pixel (±0.7 px of 5.15 px: cos i ≥ 0.99, T ≥ 389 K).
    let i = 80 * 328 + 100;
    let t = t_of(&b, full.signal[i], 1.0);
    eprintln!("full Moon centre: {t:.2} K");
    assert!(
        t <= MOON_SUBSOLAR_K + 0.05 && t > MOON_SUBSOLAR_K - 1.0,
        "{t}"
    );
    // New Moon: the night side, 100 K.
    let new = moon_frame(&b, u, v, dir, None);
    let t = t_of(&b, new.signal[i], 1.0);
    eprintln!("new Moon centre: {t:.2} K");
    assert!((t - MOON_NIGHT_K).abs() < 0.05, "{t}");
    // Quarter: the Sun along +x of the frame; the +x half is the warm one.
    let quarter = moon_frame(&b, u, v, [1.0, 0.0, 0.0], None);
    let (east, west) = (quarter.signal[i + 3], quarter.signal[i - 3]);
    let (te, tw) = (t_of(&b, east, 0.8), t_of(&b, west, 0.8));
    eprintln!("quarter Moon: {te:.1} K lit side, {tw:.1} K dark side");
    assert!(te > 300.0 && tw < MOON_NIGHT_K + 2.0);
    // Behind the Earth: hidden.
    let grid = OlrGrid::from_values(vec![240.0; OlrGrid::ROWS * OlrGrid::COLS]).unwrap();
    let map = EarthMap::refine(&grid, 1.0, &b.1).unwrap();
    let earth = EarthView {
        map: &map,
        centre_m: [dir[0] * 10_871e3, dir[1] * 10_871e3, dir[2] * 10_871e3],
        radius_m: 6_371e3,
        camera_to_earth: Rotation::IDENTITY,
    };
    let hidden = moon_frame(&b, u, v, dir, Some(earth));
    assert_eq!(hidden.moon_px, 0);
}

#[test]
fn a_bad_bits_column_is_named_with_its_line() {
    let dir = std::env::temp_dir().join(format!("tirroi-variety-bits-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("truth.csv");
    std::fs::write(
        &path,
        "file,x0,y0,x1,y1,bits\na.png,1,2,3,4,12\nb.png,1,2,3,4,20\n",
    )
    .unwrap();
    let e = read_truth(&path).unwrap_err().to_string();
    assert!(
        e.contains("truth.csv:3") && e.contains("bits = `20`"),
        "{e}"
    );
    std::fs::write(
        &path,
        "file,x0,y0,x1,y1,bits\na.png,1,2,3,4,12\nb.png,1,2,3,4,\n",
    )
    .unwrap();
    let rows = read_truth(&path).unwrap();
    assert_eq!((rows[0].bits, rows[1].bits), (Some(12), None));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sub_pixel_boom_covers_its_projected_area() {
    // A Tango whip seen side-on: 10 mm × 0.29 m at 20 m, 0.57 px wide and 16.5 px long,
    // turned 30° in the image so no pixel row lines up with it. Its partial pixels are
    // supersampled: the summed coverage is its projected area (to the 4 × 4 grid's
    // sampling error along 16 px of edge).
    let b = band();
    let (w, l) = (0.01, 0.29);
    let mut mesh = plate(1.0);
    mesh.vertices = vec![
        [-l / 2.0, -w / 2.0, 0.0],
        [l / 2.0, -w / 2.0, 0.0],
        [l / 2.0, w / 2.0, 0.0],
        [-l / 2.0, w / 2.0, 0.0],
    ];
    let camera = Camera::default();
    let temps = vec![300.0; 2];
    for (angle_deg, centre_x) in [(30.0, 0.0), (17.0, 0.0123), (60.0, -0.031)] {
        let target = TargetView {
            mesh: &mesh,
            temperature_k: &temps,
            body_to_camera: Rotation::about_axis([0.0, 0.0, 1.0], f64::to_radians(angle_deg)),
            centre_m: [centre_x, 0.004, 20.0],
        };
        let out = render(&RenderInput {
            camera: &camera,
            readout: Readout::Detection(DetectionScale::Scale3),
            target: Some(target),
            earth: None,
            earth_distance_m: 10_871e3,
            noise_seed: None,
            band: &b.0,
            lut: &b.1,
            gain_factor: 1.0,
            moon: None,
            sensor: SensorEffects::NONE,
        })
        .unwrap();
        let f = camera.focal_px();
        let area_px = (w * f / 20.0) * (l * f / 20.0);
        let covered: f64 = out.coverage.iter().map(|&c| f64::from(c)).sum();
        let max = out.coverage.iter().copied().fold(0f32, f32::max);
        eprintln!(
            "boom at {angle_deg}°: {covered:.2} px² covered, {area_px:.2} expected, max coverage {max}"
        );
        assert!(
            (covered - area_px).abs() < 0.05 * area_px,
            "{covered} vs {area_px}"
        );
        assert!(max < 1.0);
    }
}

#[test]
fn variety_fields_parse_and_bad_values_name_the_field() {
    let base = "[[scene]]\nrange_m = 20.0\n";
    let ok = SceneFile::parse(
        &format!("{base}gain = {{ min = 0.5, max = 2.0 }}\nnoise_netd_factor = 3.0\nbits = [12, 16]\nmax_offset_fraction = 1.3\nmoon = {{ probability = 0.1 }}\n"),
        "t",
    )
    .unwrap();
    assert_eq!(ok.scenes[0].moon.unwrap().probability, 0.1);
    for (line, expect) in [
        ("gain = 0.0", "scene[0].gain = 0"),
        ("gain = { min = 0.5, max = 40.0 }", "scene[0].gain"),
        ("noise_netd_factor = -1.0", "scene[0].noise_netd_factor"),
        ("bits = [12, 20]", "scene[0].bits = [12, 20]"),
        ("bits = []", "scene[0].bits = []"),
        (
            "max_offset_fraction = 1.6",
            "scene[0].max_offset_fraction = 1.6",
        ),
        (
            "moon = { probability = 1.5 }",
            "scene[0].moon.probability = 1.5",
        ),
        ("moon = { chance = 0.1 }", "chance"),
    ] {
        let e = SceneFile::parse(&format!("{base}{line}\n"), "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains(expect) && !e.contains('\n'), "{line}: {e}");
    }
}
