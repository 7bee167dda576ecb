//! Unit tests of scene files and presets.

use super::*;

#[test]
fn table4_camera() {
    let c = Camera::default();
    assert!((c.focal_px() - 1140.54).abs() < 0.01);
    let (h, v) = c.fov_deg();
    assert!(
        (h - 16.36).abs() < 0.01 && (v - 12.41).abs() < 0.01,
        "{h} {v}"
    );
    assert!((c.ifov_rad() - 8.768e-4).abs() < 1e-6);
}

#[test]
fn presets_parse() {
    for (name, _, _) in PRESETS {
        let f = SceneFile::preset(name).unwrap();
        assert!(f.image_count() > 0);
    }
    assert_eq!(SceneFile::preset("paper").unwrap().image_count(), 12_000);
    assert_eq!(SceneFile::preset("tango").unwrap().image_count(), 1_000);
    assert!(SceneFile::preset("nope").is_err());
    let mut paper = SceneFile::preset("paper").unwrap();
    paper.rescale_count(120).unwrap();
    assert_eq!(paper.image_count(), 120);
    assert!(paper.scenes.iter().all(|s| s.count == 30));
    // Exactly the count asked for (before the largest-remainder split, 1 gave 8, as
    // every kind kept at least one whole pose).
    for n in [1, 2, 5, 7, 398, 400, 401, 1200, 11_999] {
        let mut paper = SceneFile::preset("paper").unwrap();
        paper.rescale_count(n).unwrap();
        assert_eq!(paper.image_count(), n);
        // No kind is off its exact share (n / 4) by a whole image.
        for s in &paper.scenes {
            assert!(
                (s.count as f64 - n as f64 / 4.0).abs() < 1.0,
                "{n}: {}",
                s.count
            );
        }
    }
    let mut quick = SceneFile::preset("quick").unwrap();
    quick.rescale_count(3).unwrap();
    assert_eq!(quick.image_count(), 3);
}

#[test]
fn apportion_is_exact_and_proportional() {
    assert_eq!(apportion(1, &[6, 3, 6, 3, 6]), vec![1, 0, 0, 0, 0]);
    assert_eq!(apportion(3, &[6, 3, 6, 3, 6]), vec![1, 0, 1, 0, 1]);
    assert_eq!(apportion(10, &[1, 1, 1]), vec![4, 3, 3]);
    assert_eq!(apportion(5, &[0, 0]), vec![3, 2]);
    // Brute force: the parts sum to the total and each is floor or ceil of its share.
    for total in 1..60usize {
        for w in [[1usize, 2, 3], [5, 0, 7], [3000, 3000, 1000]] {
            let p = apportion(total, &w);
            assert_eq!(p.iter().sum::<usize>(), total);
            let sum: usize = w.iter().sum();
            for (pi, wi) in p.iter().zip(w) {
                let share = total * wi;
                assert!(pi * sum + sum > share && pi * sum < share + sum);
            }
        }
    }
}

#[test]
fn errors_name_line_and_field() {
    let e = SceneFile::parse("[[scene]]\nrange_m = 20.0\nrnage = 3\n", "x.toml").unwrap_err();
    assert_eq!(e.line_col.map(|l| l.0), Some(3), "{e}");
    assert!(e.to_string().contains("rnage"), "{e}");
    let e = SceneFile::parse("[[scene]]\nrange_m = \"far\"\n", "x.toml").unwrap_err();
    assert!(e.to_string().contains("x.toml:2:"), "{e}");
    assert!(e.to_string().contains("a number, or a table"), "{e}");
    assert!(e.to_string().contains("`range_m`"), "{e}");
    let e = SceneFile::parse("[[scene]]\nrange_m = { min = 50.0, max = 15.0 }\n", "x").unwrap_err();
    assert!(e.to_string().contains("scene[0].range_m"), "{e}");
    let e = SceneFile::parse("[[scene]]\nrange_m = 20.0\nmaterial = \"gold\"\n", "x").unwrap_err();
    assert!(e.to_string().contains("x:3:"), "{e}");
    assert!(e.to_string().contains("`material`"), "{e}");
    assert!(e.to_string().contains("\"multi-1\""), "{e}");
    // A detection count that is not a multiple of the scales ends on a partial pose
    // (it was an error before `--count N` had to give exactly N images).
    let f = SceneFile::parse(
        "[[scene]]\nrange_m = 20.0\nmode = \"detection\"\nscale = [1, 2]\ncount = 3\n",
        "x",
    )
    .unwrap();
    assert_eq!(f.image_count(), 3);
    let e = SceneFile::parse("[[scene]]\nrange_m = 20.0\ncount = 0\n", "x").unwrap_err();
    assert!(e.to_string().contains("at least 1 image in total"), "{e}");
    let e =
        SceneFile::parse("[camera]\nwidth = 1025\n[[scene]]\nrange_m = 20.0\n", "x").unwrap_err();
    assert!(e.to_string().contains("camera.width"), "{e}");
    // Up to the core's largest capacity.
    assert!(
        SceneFile::parse(
            "[camera]\nwidth = 1024\nheight = 768\n[[scene]]\nrange_m = 20.0\n",
            "x"
        )
        .is_ok()
    );
    assert!(SceneFile::parse("", "x").is_err());
    // Cloud-top texture: only on the cloud texture, within 0..=10 K per σ.
    let earth = |fields: &str| format!("[earth_model]\n{fields}\n[[scene]]\nrange_m = 20.0\n");
    let e = SceneFile::parse(&earth("cloud_top_texture_k = 2.0"), "x").unwrap_err();
    assert!(e.to_string().contains("texture = \"clouds\""), "{e}");
    let e = SceneFile::parse(
        &earth("texture = \"clouds\"\ncloud_top_texture_k = -1.0"),
        "x",
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("earth_model.cloud_top_texture_k"),
        "{e}"
    );
    let f = SceneFile::parse(
        &earth("texture = \"clouds\"\ncloud_top_texture_k = 2.0"),
        "x",
    )
    .unwrap();
    assert_eq!(f.earth_model.cloud_top_texture_k, 2.0);
    // The regional cloud balance: only on the cloud texture, within 0..=4 cells.
    let e = SceneFile::parse(&earth("regional_balance_cells = 1"), "x").unwrap_err();
    assert!(e.to_string().contains("texture = \"clouds\""), "{e}");
    let e = SceneFile::parse(
        &earth("texture = \"clouds\"\nregional_balance_cells = 5"),
        "x",
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("earth_model.regional_balance_cells = 5"),
        "{e}"
    );
    let f = SceneFile::parse(
        &earth("texture = \"clouds\"\nregional_balance_cells = 1"),
        "x",
    )
    .unwrap();
    assert_eq!(f.earth_model.regional_balance_cells, 1);
    // Cloud-bound fragments: only on the cloud texture.
    let e = SceneFile::parse(&earth("cloud_fragments = true"), "x").unwrap_err();
    assert!(
        e.to_string().contains("earth_model.cloud_fragments = true")
            && e.to_string().contains("texture = \"clouds\""),
        "{e}"
    );
    let f = SceneFile::parse(&earth("texture = \"clouds\"\ncloud_fragments = true"), "x").unwrap();
    assert!(f.earth_model.cloud_fragments);
}

#[test]
fn camera_response_is_hayabusa2_by_default_and_selectable() {
    use tirroi_core::sensor::{CameraResponse, SkewedBell};
    let scene = "[[scene]]\nrange_m = 20.0\n";
    let f = SceneFile::parse(scene, "x").unwrap();
    assert_eq!(f.camera.response, ResponseName::Hayabusa2);
    assert_eq!(f.camera.response.to_core(), CameraResponse::default());
    for (name, want) in [
        ("hayabusa2", CameraResponse::default()),
        ("tir", CameraResponse::Band(SkewedBell::HAYABUSA2_TIR)),
        ("flat", CameraResponse::Flat),
    ] {
        let text = format!("[camera]\nresponse = \"{name}\"\n{scene}");
        let f = SceneFile::parse(&text, "x").unwrap();
        assert_eq!(f.camera.response.name(), name);
        assert_eq!(f.camera.response.to_core(), want);
    }
    let e =
        SceneFile::parse(&format!("[camera]\nresponse = \"box\"\n{scene}"), "x.toml").unwrap_err();
    assert!(e.to_string().contains("x.toml:2:"), "{e}");
    assert!(e.to_string().contains("hayabusa2"), "{e}");
}

#[test]
fn no_target_share_and_truth_coverage_are_checked() {
    let f = SceneFile::parse("[[scene]]\nrange_m = 20.0\nno_target_fraction = 0.1\n", "x").unwrap();
    assert_eq!(f.scenes[0].no_target_fraction, 0.1);
    assert_eq!(f.dataset.truth_coverage, DEFAULT_TRUTH_COVERAGE);
    let e =
        SceneFile::parse("[[scene]]\nrange_m = 20.0\nno_target_fraction = 1.5\n", "x").unwrap_err();
    assert!(e.to_string().contains("scene[0].no_target_fraction"), "{e}");
    let e = SceneFile::parse(
        "[dataset]\ntruth_coverage = 0.0\n[[scene]]\nrange_m = 20.0\n",
        "x",
    )
    .unwrap_err();
    assert!(e.to_string().contains("dataset.truth_coverage"), "{e}");
    // Off by default, and not printed then: the paper world's presets stay as they
    // were (their tables comparable); every kind of the realistic world has >= 10 %.
    for (name, _, _) in PRESETS {
        let p = SceneFile::preset(name).unwrap();
        let text = toml::to_string(&p).unwrap();
        if name.starts_with("realistic") {
            assert!(
                p.scenes.iter().all(|s| s.no_target_fraction >= 0.1),
                "{name}"
            );
        } else {
            assert!(p.scenes.iter().all(|s| s.no_target_fraction == 0.0));
            assert!(!text.contains("no_target_fraction"));
        }
        assert!(!text.contains("truth_coverage"));
    }
}

#[test]
fn camera_sensor_keys_are_opt_in_and_checked() {
    use super::{RadiometryReadout, SignatureKind};
    let c: super::Camera = toml::from_str(
        "signature = \"hayabusa2-dark\"\noptics_psf = true\nreadout = \"fixed-gain\"\n",
    )
    .unwrap();
    assert_eq!(c.signature, SignatureKind::Hayabusa2Dark);
    assert!(c.optics_psf);
    assert_eq!(c.readout, RadiometryReadout::FixedGain);
    // The defaults are not written, so printed presets are unchanged.
    let d = toml::to_string(&super::Camera::default()).unwrap();
    assert!(!d.contains("signature") && !d.contains("optics_psf") && !d.contains("readout"));
    let e = toml::from_str::<super::Camera>("signature = \"real\"\n").unwrap_err();
    assert!(e.to_string().contains("hayabusa2-dark"), "{e}");
}
