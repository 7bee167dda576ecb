//! No-target frames, the two truth-coverage boxes, the signal-to-clutter ratio and the
//! scoring definition (`docs/results.md` § Scoring), end to end through `tirroi render`
//! and `tirroi eval`, each checked against a computation of its own.

mod cli_common;

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;

use cli_common::run;
use serde_json::Value;
use tirroi::core::Method;
use tirroi::host::dataset::{Library, plan};
use tirroi::host::eval::scoring::read_truth;
use tirroi::host::world::scene::SceneFile;

/// Two kinds on a small frame and a coarse Earth: deep space without noise, on the
/// fixed detection scale (half its poses without a target) and the Earth behind (a quarter without).
const TINY: &str = r#"
[dataset]
name = "tiny"
seed = 3
thermal_states = 1

[camera]
width = 96
height = 72

[earth_model]
days = 1
mesh_deg = 1.0

[[scene]]
name = "space"
count = 4
mode = "detection"
scale = 3
range_m = 60.0
offset_px = [0.0, 0.0]
earth = false
noise = false
no_target_fraction = 0.5

[[scene]]
name = "earth"
count = 4
range_m = { min = 40.0, max = 60.0 }
max_offset_fraction = 0.3
earth_off_boresight_deg = 10.0
no_target_fraction = 0.25
"#;

fn render(dir: &Path, toml: &str) {
    let scene = dir.join("scene.toml");
    fs::write(&scene, toml).unwrap();
    let out = run(&[
        "render",
        "--config",
        scene.to_str().unwrap(),
        "--out",
        dir.join("ds").to_str().unwrap(),
        "--masks",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `truth.csv` as (header, rows of fields).
fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

fn metadata(dir: &Path) -> Vec<Value> {
    fs::read_to_string(dir.join("metadata.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// 8-bit coverage mask (255 = fully covered) of one frame, and its width.
fn mask(dir: &Path, file: &str) -> (Vec<u8>, usize) {
    let mask = image::open(dir.join("masks").join(file))
        .unwrap()
        .to_luma8();
    let w = mask.width() as usize;
    (mask.into_raw(), w)
}

/// Tight box [x0, y0, x1, y1) of the mask pixels `keep` accepts, by brute force.
fn brute_box(mask: &[u8], w: usize, keep: impl Fn(u8) -> bool) -> Option<[u16; 4]> {
    let mut b: Option<[usize; 4]> = None;
    for (i, &m) in mask.iter().enumerate() {
        if keep(m) {
            let (x, y) = (i % w, i / w);
            let v = b.get_or_insert([x, y, x + 1, y + 1]);
            *v = [v[0].min(x), v[1].min(y), v[2].max(x + 1), v[3].max(y + 1)];
        }
    }
    b.map(|v| v.map(|c| c as u16))
}

fn parse_box(fields: &[String]) -> Option<[u16; 4]> {
    if fields.iter().all(String::is_empty) {
        return None;
    }
    Some([0, 1, 2, 3].map(|k| fields[k].parse().unwrap()))
}

#[test]
fn no_target_frames_boxes_and_signal_to_clutter() {
    let tmp = tempfile::tempdir().unwrap();
    render(tmp.path(), TINY);
    let ds = tmp.path().join("ds");
    let (h, rows) = csv(&ds.join("truth.csv"));
    let meta = metadata(&ds);
    assert_eq!(rows.len(), 8);
    let (target, x0, x0q, scr, vis) = (
        col(&h, "target"),
        col(&h, "x0"),
        col(&h, "x0_quarter"),
        col(&h, "signal_to_clutter"),
        col(&h, "visible_share"),
    );
    // ⌈0.5 × 4⌉ = 2 of the space kind, ⌈0.25 × 4⌉ = 1 of the Earth kind.
    let none: Vec<usize> = (0..8).filter(|&i| rows[i][target] == "none").collect();
    assert_eq!(none.iter().filter(|&&i| i < 4).count(), 2, "{none:?}");
    assert_eq!(none.iter().filter(|&&i| i >= 4).count(), 1, "{none:?}");
    let coco: Value = serde_json::from_str(&fs::read_to_string(ds.join("coco.json")).unwrap())
        .expect("coco.json");
    assert_eq!(coco["images"].as_array().unwrap().len(), 8);
    let annotated: Vec<u64> = coco["annotations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["image_id"].as_u64().unwrap())
        .collect();
    let mut quarter_larger = false;
    for (i, row) in rows.iter().enumerate() {
        let (mask, w) = mask(&ds, &row[0]);
        let half = parse_box(&row[x0..x0 + 4]);
        let quarter = parse_box(&row[x0q..x0q + 4]);
        let m = &meta[i];
        if none.contains(&i) {
            // Nothing rendered: no coverage, empty boxes, no annotation, no SCR.
            assert!(mask.iter().all(|&v| v == 0), "{}", row[0]);
            assert_eq!((half, quarter), (None, None));
            assert!(!annotated.contains(&(i as u64 + 1)));
            assert!(row[scr].is_empty() && m["signal_to_clutter"].is_null());
            assert!(row[vis].is_empty() && m["visible_share"].is_null());
            assert_eq!(m["target"], "none");
            continue;
        }
        assert!(annotated.contains(&(i as u64 + 1)));
        // The ½ box: coverage ≥ ½ (mask ≥ 128); the ¼ box: coverage > ¼. Coverage is a
        // multiple of 1/16, and ¼ = 4/16 is written as round(63.75) = 64, 5/16 as 80.
        assert_eq!(half, brute_box(&mask, w, |v| v >= 128), "{}", row[0]);
        assert_eq!(quarter, brute_box(&mask, w, |v| v > 64), "{}", row[0]);
        let (h2, q) = (half.unwrap(), quarter.unwrap());
        assert!(q[0] <= h2[0] && q[1] <= h2[1] && q[2] >= h2[2] && q[3] >= h2[3]);
        quarter_larger |= q != h2;
        // Metadata: the noise σ and the Earth's share, both boxes, the SCR's parts.
        assert!(m["noise_sigma_dn"].as_f64().unwrap() >= 0.0);
        let ef = m["earth_fraction"].as_f64().unwrap();
        assert!((0.0..=1.0).contains(&ef));
        assert_eq!(m["bbox"].as_array().unwrap().len(), 4);
        assert_eq!(m["bbox_quarter"].as_array().unwrap().len(), 4);
        let contrast = m["target_contrast_dn"].as_f64().unwrap();
        let clutter = m["clutter_sigma_dn"].as_f64().unwrap();
        let ratio = m["signal_to_clutter"].as_f64().unwrap();
        let noise = m["noise_sigma_dn"].as_f64().unwrap();
        let floor = clutter.max(noise).max(1.0 / 12f64.sqrt());
        // (The noise σ is an f32 written in its shortest decimal form.)
        assert!((ratio - contrast / floor).abs() <= 1e-6 * ratio.max(1.0));
        // The visible box: inside the truth box, its share the area ratio.
        let v: Vec<u16> = m["visible_bbox"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap() as u16)
            .collect();
        let share = m["visible_share"].as_f64().unwrap();
        let area = |b: &[u16]| f64::from(b[2] - b[0]) * f64::from(b[3] - b[1]);
        if v[2] > v[0] {
            assert!(v[0] >= h2[0] && v[1] >= h2[1] && v[2] <= h2[2] && v[3] <= h2[3]);
        }
        assert!((share - area(&v) / area(&h2)).abs() < 1e-12, "{}", row[0]);
        assert_eq!(row[vis], format!("{share:.4}"));
        if i < 4 {
            // Deep space, noise-free: nothing behind the target; a detection-mode
            // target at 60 m lifts every pixel it half covers far above the 3 × 1/√12
            // DN threshold, so all of it is visible.
            assert_eq!((clutter, noise), (0.0, 0.0));
            assert_eq!(v, h2.to_vec(), "{}", row[0]);
        } else {
            // The Earth behind: a background that varies.
            assert!(clutter > 0.0, "{}", row[0]);
        }
    }
    assert!(quarter_larger, "the ¼ box grows past the ½ box somewhere");

    // eval's reader: the ratio from truth.csv, and from metadata.jsonl beside a
    // truth file without the column; none for the target-less frames.
    let full = read_truth(&ds.join("truth.csv")).unwrap();
    let bare: String = fs::read_to_string(ds.join("truth.csv"))
        .unwrap()
        .lines()
        .map(|l| l.split(',').take(13).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    fs::write(ds.join("bare.csv"), bare).unwrap();
    let from_meta = read_truth(&ds.join("bare.csv")).unwrap();
    for (i, (a, b)) in full.iter().zip(&from_meta).enumerate() {
        assert_eq!(a.has_target(), !none.contains(&i));
        let want = meta[i]["signal_to_clutter"].as_f64();
        assert_eq!(b.signal_to_clutter, want);
        let csv_value = a.signal_to_clutter.map(|v| format!("{v:.4}"));
        assert_eq!(csv_value, want.map(|v| format!("{v:.4}")));
        // The bare file has no `visible_share` column, so no `visible` group.
        let bare_groups: Vec<_> = a.groups.iter().filter(|(k, _)| k != "visible").collect();
        assert_eq!(bare_groups, b.groups.iter().collect::<Vec<_>>());
        assert_eq!(
            a.groups.iter().any(|(k, _)| k == "visible"),
            a.has_target(),
            "the visible bin for every frame with a target"
        );
    }
}

#[test]
fn eval_scores_target_frames_and_false_alarms() {
    let tmp = tempfile::tempdir().unwrap();
    render(tmp.path(), TINY);
    let ds = tmp.path().join("ds");
    let report = tmp.path().join("report");
    let args = |cov: &str, out: &Path| {
        run(&[
            "eval",
            "--images",
            ds.to_str().unwrap(),
            "--method",
            "all",
            "--repeat",
            "1",
            "--truth-coverage",
            cov,
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let out = args("half", &report);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Recompute every method's numbers from the per-frame boxes of scores.csv and the
    // truth of truth.csv, by the definition: IoU over frames with a target (no box
    // scores 0), hit = IoU ≥ ½, false alarm = any box on a frame without a target.
    let (th, truth) = csv(&ds.join("truth.csv"));
    let x0 = col(&th, "x0");
    let truth: BTreeMap<String, Option<[u16; 4]>> = truth
        .iter()
        .map(|r| (r[0].clone(), parse_box(&r[x0..x0 + 4])))
        .collect();
    let (sh, scores) = csv(&report.join("scores.csv"));
    let (sx0, mcol) = (col(&sh, "x0"), col(&sh, "method"));
    let iou = |a: [u16; 4], b: [u16; 4]| {
        let ix = f64::from(a[2].min(b[2]).saturating_sub(a[0].max(b[0])));
        let iy = f64::from(a[3].min(b[3]).saturating_sub(a[1].max(b[1])));
        let area = |r: [u16; 4]| f64::from(r[2] - r[0]) * f64::from(r[3] - r[1]);
        ix * iy / (area(a) + area(b) - ix * iy)
    };
    let mut by_method: BTreeMap<String, (Vec<f64>, usize, usize)> = BTreeMap::new();
    for r in &scores {
        let e = by_method.entry(r[mcol].clone()).or_default();
        let found = parse_box(&r[sx0..sx0 + 4]);
        match truth[&r[0]] {
            Some(t) => e.0.push(found.map_or(0.0, |f| iou(f, t))),
            None => {
                e.1 += 1;
                e.2 += usize::from(found.is_some());
            }
        }
    }
    let (gh, summary) = csv(&report.join("summary.csv"));
    let g = |r: &Vec<String>, name: &str| r[col(&gh, name)].clone();
    let mut checked = 0;
    for r in summary.iter().filter(|r| g(r, "group") == "all") {
        let (ious, empty, alarms) = &by_method[&g(r, "method")];
        assert_eq!((ious.len(), *empty), (5, 3));
        let f = |name: &str| g(r, name).parse::<f64>().unwrap();
        let mean = ious.iter().sum::<f64>() / ious.len() as f64;
        let hits = ious.iter().filter(|&&v| v >= 0.5).count() as f64 / ious.len() as f64;
        assert_eq!(g(r, "frames"), "8");
        assert_eq!(g(r, "target_frames"), "5");
        assert!((f("mean_iou") - mean).abs() <= 1e-4, "{r:?} vs {mean}");
        assert!((f("hit_rate") - hits).abs() <= 1e-4, "{r:?} vs {hits}");
        assert!((f("false_alarm_rate") - *alarms as f64 / 3.0).abs() <= 1e-4);
        checked += 1;
    }
    assert_eq!(checked, Method::ALL.len(), "every registered method");
    // The `target = none` group: no target frame, only false alarms.
    for r in summary
        .iter()
        .filter(|r| g(r, "group") == "target" && g(r, "value") == "none")
    {
        assert_eq!(
            (g(r, "frames"), g(r, "target_frames")),
            ("3".into(), "0".into())
        );
        let (_, _, alarms) = &by_method[&g(r, "method")];
        let rate = g(r, "false_alarm_rate").parse::<f64>().unwrap();
        assert!((rate - *alarms as f64 / 3.0).abs() <= 1e-4);
    }
    // Signal-to-clutter bins over the target frames: as many frames as have an SCR.
    let scr_frames: usize = summary
        .iter()
        .filter(|r| g(r, "group") == "scr" && g(r, "method") == "otsu")
        .map(|r| g(r, "frames").parse::<usize>().unwrap())
        .sum();
    assert_eq!(scr_frames, 5);

    // The ¼ box: scores.csv's truth columns are truth.csv's quarter columns.
    let quarter_report = tmp.path().join("quarter");
    let out = args("quarter", &quarter_report);
    assert!(out.status.success());
    let x0q = col(&th, "x0_quarter");
    let (_, rows) = csv(&ds.join("truth.csv"));
    let quarter: BTreeMap<String, Option<[u16; 4]>> = rows
        .iter()
        .map(|r| (r[0].clone(), parse_box(&r[x0q..x0q + 4])))
        .collect();
    let (qh, qscores) = csv(&quarter_report.join("scores.csv"));
    let tx0 = col(&qh, "truth_x0");
    for r in &qscores {
        assert_eq!(parse_box(&r[tx0..tx0 + 4]), quarter[&r[0]], "{r:?}");
    }
}

#[test]
fn eval_reads_empty_truth_fields_and_refuses_half_empty_boxes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let out = run(&["fixtures", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success());
    let (_, rows) = csv(&dir.join("truth.csv"));
    // Declare the first fixture (a frame with a target the detectors find) target-less:
    // a box on it is a false alarm.
    let mut text = String::from("file,x0,y0,x1,y1\n");
    text.push_str(&format!("{},,,,\n", rows[0][0]));
    for r in &rows[1..] {
        text.push_str(&format!("{}\n", r[..5].join(",")));
    }
    let truth = dir.join("mine.csv");
    fs::write(&truth, &text).unwrap();
    let report = dir.join("report");
    let out = run(&[
        "eval",
        "--images",
        dir.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
        "--method",
        "otsu",
        "--repeat",
        "1",
        "--out",
        report.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (sh, scores) = csv(&report.join("scores.csv"));
    let sx0 = col(&sh, "x0");
    let found = parse_box(&scores.iter().find(|r| r[0] == rows[0][0]).unwrap()[sx0..sx0 + 4]);
    let (gh, summary) = csv(&report.join("summary.csv"));
    let all = &summary[0];
    assert_eq!(all[col(&gh, "group")], "all");
    assert_eq!(all[col(&gh, "target_frames")], (rows.len() - 1).to_string());
    let rate: f64 = all[col(&gh, "false_alarm_rate")].parse().unwrap();
    assert_eq!(rate, if found.is_some() { 1.0 } else { 0.0 });

    // Three empty fields and one number: an error naming the line.
    fs::write(&truth, format!("file,x0,y0,x1,y1\n{},1,,,\n", rows[0][0])).unwrap();
    let out = run(&[
        "eval",
        "--images",
        dir.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
        "--method",
        "otsu",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("mine.csv:2") && err.contains("y0"), "{err}");
    // The quarter box of a file without its columns: an error naming them.
    let out = run(&[
        "eval",
        "--images",
        dir.to_str().unwrap(),
        "--truth",
        truth.to_str().unwrap(),
        "--truth-coverage",
        "quarter",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("x0_quarter"));
}

#[test]
fn no_target_poses_leave_the_other_frames_unchanged() {
    // The same kinds without target-less poses: every frame that keeps its target is
    // the same bytes, the target-less ones differ.
    let with = tempfile::tempdir().unwrap();
    let without = tempfile::tempdir().unwrap();
    render(with.path(), TINY);
    render(
        without.path(),
        &TINY
            .replace("no_target_fraction = 0.5", "")
            .replace("no_target_fraction = 0.25", ""),
    );
    let (h, rows) = csv(&with.path().join("ds/truth.csv"));
    let target = col(&h, "target");
    for r in &rows {
        let a = fs::read(with.path().join("ds").join(&r[0])).unwrap();
        let b = fs::read(without.path().join("ds").join(&r[0])).unwrap();
        assert_eq!(a == b, r[target] != "none", "{}", r[0]);
    }
}

#[test]
fn signal_to_clutter_against_a_full_frame_twin() {
    // The windowed twin of the renderer against a brute-force one: the same plan
    // rendered whole without its target and without noise; the ring enumerated by
    // Chebyshev distance to the truth box; every signal compared as the DN the camera
    // shows (unquantised, clipped to its range: a saturated target over a saturated
    // Earth stands out by nothing).
    let file = SceneFile::parse(TINY, "TINY").unwrap();
    let plans = plan(&file);
    let library = Library::build(&file, &plans).unwrap();
    let mut checked = [0usize; 2];
    for p in plans.iter().filter(|p| p.has_target) {
        let (frame, _) = library.render(&file, p).unwrap();
        let mut bare = p.clone();
        bare.has_target = false;
        bare.noise_seed = None;
        let (twin, _) = library.render(&file, &bare).unwrap();
        assert!(twin.coverage.iter().all(|&c| c == 0.0) && twin.clutter.is_none());
        let got = frame.clutter.expect("a target in view");
        let (w, h) = (frame.width, frame.height);
        let t = frame.truth;
        let max_dn = f64::from(frame.mapping.max_dn());
        let dn = |v: f32| frame.mapping.dn(f64::from(v)).clamp(0.0, max_dn);
        let (mut diff, mut n) = (0.0, 0usize);
        let mut ring = Vec::new();
        let band = 4usize.max(usize::from(t.width().max(t.height())).div_ceil(2)) as i64;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if frame.coverage[i] >= 0.5 {
                    diff += dn(frame.signal[i]) - dn(twin.signal[i]);
                    n += 1;
                }
                let dx = (i64::from(t.x0) - x as i64).max(x as i64 - (i64::from(t.x1) - 1));
                let dy = (i64::from(t.y0) - y as i64).max(y as i64 - (i64::from(t.y1) - 1));
                let d = dx.max(dy);
                if (1..=band).contains(&d) {
                    ring.push(dn(twin.signal[i]));
                }
            }
        }
        let contrast = (diff / n as f64).abs();
        let mean = ring.iter().sum::<f64>() / ring.len() as f64;
        let var = ring.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / ring.len() as f64;
        let sigma = var.sqrt();
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-12);
        // The window's limb pixels on its edge may miss their supersampling (the
        // module's docs): a per-mille difference at most on these frames.
        assert!(
            rel(got.target_contrast_dn, contrast) < 1e-3,
            "{got:?} vs {contrast}"
        );
        if p.earth_rendered {
            assert!(
                rel(got.clutter_sigma_dn, sigma) < 1e-2,
                "{got:?} vs {sigma}"
            );
            checked[1] += 1;
        } else {
            assert_eq!((got.clutter_sigma_dn, sigma), (0.0, 0.0));
            assert!(rel(got.signal_to_clutter, contrast * 12f64.sqrt()) < 1e-9);
            checked[0] += 1;
        }
    }
    assert_eq!(checked, [2, 3]);
}

#[test]
fn truth_coverage_sets_the_main_box() {
    // ¾: the pixels covered at least 12/16, written as round(191.25) = 191 in the mask
    // (11/16 as 175); the ¼ box stays as it was.
    let tmp = tempfile::tempdir().unwrap();
    render(
        tmp.path(),
        &TINY.replace(
            "thermal_states = 1",
            "thermal_states = 1\ntruth_coverage = 0.75",
        ),
    );
    let ds = tmp.path().join("ds");
    let (h, rows) = csv(&ds.join("truth.csv"));
    let (x0, x0q) = (col(&h, "x0"), col(&h, "x0_quarter"));
    let meta = metadata(&ds);
    let mut smaller = false;
    for (i, row) in rows.iter().enumerate() {
        let (mask, w) = mask(&ds, &row[0]);
        let main = parse_box(&row[x0..x0 + 4]);
        assert_eq!(main, brute_box(&mask, w, |v| v >= 191), "{}", row[0]);
        assert_eq!(
            parse_box(&row[x0q..x0q + 4]),
            brute_box(&mask, w, |v| v > 64)
        );
        smaller |= main != brute_box(&mask, w, |v| v >= 128);
        assert_eq!(meta[i]["truth_coverage"], 0.75);
    }
    assert!(smaller, "a ¾ box inside the ½ box somewhere");
}
