//! `tirroi eval --predictions` (detect JSON lines, CSV, COCO results), truth and
//! prediction validation, the confidence figures, and the frame formats of `detect`/
//! `eval` (FITS with its DN rule and crop, sizes from the header, multi-page TIFF,
//! `--bits` below the data's depth), each checked against a computation of its own.

mod cli_common;

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use cli_common::{STAGE_NAMES, run, tirroi};
use tirroi::core::Method;
use tirroi::host::imaging::fits::read_fits;
use tirroi::host::imaging::image_io::{HAYABUSA2_TIR_CROP, ReadOptions, read_frame_with};

/// A box `[x0, y0, x1, y1)`, or none.
type Bbox = Option<[u16; 4]>;

/// A frame as the brute-force count sees it: truth, predicted box, its score.
type Frame = (Bbox, Bbox, f64);

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[track_caller]
fn ok(out: &Output) -> String {
    assert!(out.status.success(), "{}", stderr(out));
    stdout(out)
}

/// A failed run: exit code 2, no panic, the message holds every `needle`.
#[track_caller]
fn refused(out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// CSV as (header, rows of fields).
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
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// The fixture frames with a truth where the first frame is declared without a target
/// (a box on it is a false alarm); returns the directory and the truth boxes.
fn fixtures_with_an_empty_frame() -> (tempfile::TempDir, Vec<(String, Bbox)>) {
    let dir = tempfile::tempdir().unwrap();
    ok(&run(&["fixtures", "--out", s(dir.path())]));
    let (_, rows) = csv(&dir.path().join("truth.csv"));
    let mut truth = Vec::new();
    let mut text = String::from("file,x0,y0,x1,y1\n");
    for (i, r) in rows.iter().enumerate() {
        if i == 0 {
            text.push_str(&format!("{},,,,\n", r[0]));
            truth.push((r[0].clone(), None));
        } else {
            text.push_str(&format!("{}\n", r[..5].join(",")));
            truth.push((
                r[0].clone(),
                Some([1, 2, 3, 4].map(|k| r[k].parse().unwrap())),
            ));
        }
    }
    fs::write(dir.path().join("truth.csv"), text).unwrap();
    (dir, truth)
}

fn iou(a: [u16; 4], b: [u16; 4]) -> f64 {
    let ix = f64::from(a[2].min(b[2]).saturating_sub(a[0].max(b[0])));
    let iy = f64::from(a[3].min(b[3]).saturating_sub(a[1].max(b[1])));
    let area = |r: [u16; 4]| f64::from(r[2] - r[0]) * f64::from(r[3] - r[1]);
    ix * iy / (area(a) + area(b) - ix * iy)
}

/// Mean IoU, hit rate, false-alarm rate and AUC of (truth, box, score) frames, by the
/// definitions counted pair by pair (docs/results.md § Confidence).
fn brute(frames: &[Frame]) -> (f64, f64, f64, Option<f64>) {
    let mut ious = Vec::new();
    let (mut empty, mut alarms) = (0, 0);
    let mut pos = Vec::new();
    let mut neg = Vec::new();
    for &(t, b, sc) in frames {
        match t {
            Some(t) => {
                let v = b.map_or(0.0, |b| iou(b, t));
                ious.push(v);
                pos.push((v >= 0.5).then_some(sc));
                if b.is_some() && v < 0.5 {
                    neg.push(Some(sc));
                }
            }
            None => {
                empty += 1;
                alarms += usize::from(b.is_some());
                neg.push(b.map(|_| sc));
            }
        }
    }
    let mean = ious.iter().sum::<f64>() / ious.len() as f64;
    let hits = ious.iter().filter(|&&v| v >= 0.5).count() as f64 / ious.len() as f64;
    let far = if empty == 0 {
        0.0
    } else {
        alarms as f64 / empty as f64
    };
    let auc = (!pos.is_empty() && !neg.is_empty()).then(|| {
        let mut sum = 0.0;
        for p in &pos {
            for n in &neg {
                sum += match (p, n) {
                    (None, _) => 0.0,
                    (Some(_), None) => 1.0,
                    (Some(a), Some(b)) if a > b => 1.0,
                    (Some(a), Some(b)) if a == b => 0.5,
                    _ => 0.0,
                };
            }
        }
        sum / (pos.len() * neg.len()) as f64
    });
    (mean, hits, far, auc)
}

/// summary.csv's `all` row of `method` as name → value.
fn summary_all(report: &Path, method: &str) -> BTreeMap<String, String> {
    let (h, rows) = csv(&report.join("summary.csv"));
    let r = rows
        .iter()
        .find(|r| r[col(&h, "method")] == method && r[col(&h, "group")] == "all")
        .unwrap_or_else(|| panic!("no `all` row of {method}"));
    h.iter().cloned().zip(r.iter().cloned()).collect()
}

#[test]
fn detect_json_predictions_score_like_the_built_in_methods() {
    let (dir, _) = fixtures_with_an_empty_frame();
    let d = dir.path();
    let pngs: Vec<PathBuf> = {
        let mut v: Vec<PathBuf> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "png"))
            .collect();
        v.sort();
        v
    };
    // eval's default box rule is largest-component; detect's, each detector's own.
    // The fixtures have no manifest: eval cuts auto-v2's saturated blobs by 0 px (no
    // optics blur), detect by the flight camera's default unless told.
    let mut args = vec![
        "detect",
        "--method",
        "all",
        "--json",
        "--box-rule",
        "largest-component",
        "--saturated-erode-px",
        "0",
    ];
    args.extend(pngs.iter().map(|p| s(p)));
    let lines = ok(&run(&args));
    fs::write(d.join("det.jsonl"), &lines).unwrap();
    let report = d.join("report");
    let curve = d.join("curve.csv");
    ok(&run(&[
        "eval",
        "--images",
        s(d),
        "--method",
        "all",
        "--repeat",
        "1",
        "--predictions",
        &format!("det={}", s(&d.join("det.jsonl"))),
        "--curve",
        s(&curve),
        "--out",
        s(&report),
    ]));
    for m in Method::ALL.map(Method::name) {
        let a = summary_all(&report, m);
        let b = summary_all(&report, &format!("det:{m}"));
        for k in [
            "frames",
            "target_frames",
            "mean_iou",
            "median_iou",
            "hit_rate",
            "false_alarm_rate",
            "auc",
            "calibration_gap",
        ] {
            assert_eq!(a[k], b[k], "{m} {k}");
        }
    }
    // Per frame: the same boxes and scores.
    let (h, rows) = csv(&report.join("scores.csv"));
    let key = |r: &Vec<String>| (r[0].clone(), r[col(&h, "method")].replace("det:", ""));
    let mut seen: BTreeMap<(String, String), Vec<String>> = BTreeMap::new();
    for r in &rows {
        let boxed: Vec<String> = ["x0", "y0", "x1", "y1", "iou", "score"]
            .iter()
            .map(|c| r[col(&h, c)].clone())
            .collect();
        if let Some(prev) = seen.insert(key(r), boxed.clone()) {
            assert_eq!(prev, boxed, "{r:?}");
        }
    }
    assert_eq!(rows.len(), 2 * seen.len());
    // The curve: every set, the first point at +∞ is (0, 0).
    let (ch, points) = csv(&curve);
    let firsts: Vec<&Vec<String>> = points
        .iter()
        .filter(|p| p[col(&ch, "threshold")] == "inf")
        .collect();
    assert_eq!(
        firsts.len(),
        2 * Method::ALL.len(),
        "every method and its det: copy, one truth convention (no quarter columns)"
    );
    assert!(firsts.iter().all(|p| p[col(&ch, "hit_rate")] == "0.000000"));
}

#[test]
fn csv_and_coco_predictions_against_a_brute_force_count() {
    let (dir, truth) = fixtures_with_an_empty_frame();
    let d = dir.path();
    // Frame 0 (no target): a false alarm at 0.3; frame 1: its truth box at 0.9 (a hit);
    // frame 2: a box shifted by half its width at 0.6 (IoU 1/3, a miss and a false
    // positive); frame 3: no line (null).
    let t1 = truth[1].1.unwrap();
    let t2 = truth[2].1.unwrap();
    let half = (t2[2] - t2[0]) / 2;
    let shifted = [t2[0] + half, t2[1], t2[2] + half, t2[3]];
    let boxes: Vec<(Option<[u16; 4]>, f64)> = vec![
        (Some([10, 10, 40, 30]), 0.3),
        (Some(t1), 0.9),
        (Some(shifted), 0.6),
        (None, 0.0),
    ];
    let mut text = String::from("file,x0,y0,x1,y1,score\n");
    for (i, (b, sc)) in boxes.iter().enumerate().take(3) {
        let b = b.unwrap();
        text.push_str(&format!(
            "{},{},{},{},{},{sc}\n",
            truth[i].0, b[0], b[1], b[2], b[3]
        ));
    }
    fs::write(d.join("mine.csv"), &text).unwrap();
    // COCO: the same boxes as [x, y, w, h], plus a weaker second result on frame 1 that
    // the best-score rule drops; image ids from a coco.json beside the frames.
    let images: Vec<String> = truth
        .iter()
        .enumerate()
        .map(|(i, (f, _))| format!("{{\"id\":{},\"file_name\":\"{f}\"}}", i + 10))
        .collect();
    fs::write(
        d.join("coco.json"),
        format!("{{\"images\":[{}],\"annotations\":[]}}", images.join(",")),
    )
    .unwrap();
    let mut results: Vec<String> = boxes
        .iter()
        .enumerate()
        .take(3)
        .map(|(i, (b, sc))| {
            let b = b.unwrap();
            format!(
                "{{\"image_id\":{},\"category_id\":1,\"bbox\":[{},{},{},{}],\"score\":{sc}}}",
                i + 10,
                b[0],
                b[1],
                b[2] - b[0],
                b[3] - b[1]
            )
        })
        .collect();
    results.push("{\"image_id\":11,\"category_id\":1,\"bbox\":[0,0,5,5],\"score\":0.2}".into());
    fs::write(
        d.join("coco-results.json"),
        format!("[{}]", results.join(",\n")),
    )
    .unwrap();
    let report = d.join("report");
    let out = ok(&run(&[
        "eval",
        "--images",
        s(d),
        "--method",
        "none",
        "--predictions",
        s(&d.join("mine.csv")),
        "--predictions",
        &format!("coco={}", s(&d.join("coco-results.json"))),
        "--out",
        s(&report),
    ]));
    assert!(
        out.contains("| mine | all |") && out.contains("| coco | all |"),
        "{out}"
    );
    let frames: Vec<Frame> = truth
        .iter()
        .zip(&boxes)
        .map(|((_, t), (b, sc))| (*t, *b, *sc))
        .collect();
    let (mean, hits, far, auc) = brute(&frames);
    // By hand too: positives {hit@0.9, miss, miss}, negatives {alarm@0.3, wrong@0.6}:
    // the hit beats both → 2 of 6 pairs.
    assert!((auc.unwrap() - 2.0 / 6.0).abs() < 1e-12);
    for name in ["mine", "coco"] {
        let r = summary_all(&report, name);
        let f = |k: &str| r[k].parse::<f64>().unwrap();
        assert!(
            (f("mean_iou") - mean).abs() < 1e-4,
            "{name} {r:?} vs {mean}"
        );
        assert!((f("hit_rate") - hits).abs() < 1e-4, "{name}");
        assert!((f("false_alarm_rate") - far).abs() < 1e-4, "{name}");
        assert!((f("auc") - auc.unwrap()).abs() < 1e-4, "{name}");
        // Deciles: 0.3 (no hit), 0.6 (no hit), 0.9 (hit): gaps 0.3, 0.6, 0.1.
        assert!((f("calibration_gap") - 0.6).abs() < 1e-4, "{name}");
    }
    let (h, rows) = csv(&report.join("calibration.csv"));
    let d9 = rows
        .iter()
        .find(|r| r[0] == "coco" && r[col(&h, "lower")] == "0.9")
        .unwrap();
    assert_eq!(
        (
            d9[col(&h, "boxes")].as_str(),
            d9[col(&h, "hit_rate")].as_str()
        ),
        ("1", "1.0000")
    );
    // The confidence table holds both conventions only with quarter columns: here one.
    let (h, rows) = csv(&report.join("confidence.csv"));
    assert!(rows.iter().all(|r| r[col(&h, "truth")] == "half"));
}

#[test]
fn bad_truth_and_predictions_name_file_and_line() {
    let (dir, truth) = fixtures_with_an_empty_frame();
    let d = dir.path();
    let f0 = &truth[0].0;
    let f1 = &truth[1].0;
    let eval = |truth_file: &Path, extra: &[&str]| {
        let mut a = vec![
            "eval",
            "--images",
            s(d),
            "--truth",
            s(truth_file),
            "--repeat",
            "1",
        ];
        if !extra.contains(&"--method") {
            a.extend_from_slice(&["--method", "otsu"]);
        }
        a.extend_from_slice(extra);
        run(&a)
    };
    let t = d.join("bad.csv");
    // Duplicate rows, zero area, outside the frame, header only.
    for (text, needles) in [
        (
            format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\n{f1},1,1,5,5\n{f0},2,2,6,6\n"),
            vec!["bad.csv:4", "lines 2 and 4"],
        ),
        (
            format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\n{f1},3,1,3,5\n"),
            vec!["bad.csv:3", "zero area"],
        ),
        (
            format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\n\n{f1},300,200,329,249\n"),
            vec!["bad.csv:4", "outside the 328x248"],
        ),
        (
            "file,x0,y0,x1,y1\n".to_string(),
            vec!["bad.csv:1", "only a header"],
        ),
    ] {
        fs::write(&t, text).unwrap();
        refused(&eval(&t, &[]), &needles);
    }
    // Predictions: a file not in the truth, a bad box, a score out of range, a frame
    // twice, a COCO image id the annotations do not hold, a bad JSON line.
    let good = d.join("truth.csv");
    let p = d.join("p.csv");
    for (text, needles) in [
        (
            format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\nnot-here.png,1,1,5,5\n"),
            vec!["p.csv:3", "not-here.png"],
        ),
        (
            format!("file,x0,y0,x1,y1\n{f0},5,1,5,5\n"),
            vec!["p.csv:2", "x0 < x1"],
        ),
        (
            format!("file,x0,y0,x1,y1,score\n{f0},1,1,5,5,1.5\n"),
            vec!["p.csv:2", "score 1.5"],
        ),
        (
            format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\n{f0},,,,\n"),
            vec!["p.csv:3", "twice", "p.csv:2"],
        ),
        (
            format!("file,x0,y0,x1,y1\n{f0},a,1,5,5\n"),
            vec!["p.csv:2", "x0 = `a`"],
        ),
        ("x,y\n".to_string(), vec!["p.csv:1", "file,x0,y0,x1,y1"]),
    ] {
        fs::write(&p, text).unwrap();
        refused(&eval(&good, &["--predictions", s(&p)]), &needles);
    }
    let j = d.join("p.jsonl");
    fs::write(
        &j,
        format!("{{\"file\":\"{f0}\",\"bbox\":null}}\n{{\"file\":\"{f1}\",\"bbox\":[1,2]}}\n"),
    )
    .unwrap();
    refused(
        &eval(&good, &["--predictions", s(&j)]),
        &["p.jsonl:2", "bbox"],
    );
    let c = d.join("r.json");
    fs::write(
        d.join("coco.json"),
        format!("{{\"images\":[{{\"id\":1,\"file_name\":\"{f0}\"}}]}}"),
    )
    .unwrap();
    fs::write(&c, "[{\"image_id\":1,\"bbox\":[1,1,4,4],\"score\":0.5},{\"image_id\":7,\"bbox\":[1,1,4,4],\"score\":0.5}]").unwrap();
    refused(
        &eval(&good, &["--predictions", s(&c)]),
        &["r.json: entry 2", "image_id 7"],
    );
    // Nothing to score; a name taken twice.
    refused(&eval(&good, &["--method", "none"]), &["nothing to score"]);
    fs::write(&p, format!("file,x0,y0,x1,y1\n{f0},1,1,5,5\n")).unwrap();
    refused(
        &eval(&good, &["--predictions", &format!("otsu={}", s(&p))]),
        &["otsu", "taken"],
    );
}

/// A FITS file by hand: 80-character cards padded to 2880 bytes, then big-endian f32
/// data padded to 2880 bytes (FITS 4.0 §3).
fn write_fits_f32(path: &Path, w: usize, h: usize, values: &[f32]) {
    let mut out = Vec::new();
    let card = |k: &str, v: &str| format!("{k:<8}= {v:>20}");
    for c in [
        card("SIMPLE", "T"),
        card("BITPIX", "-32"),
        card("NAXIS", "2"),
        card("NAXIS1", &w.to_string()),
        card("NAXIS2", &h.to_string()),
        "END".to_string(),
    ] {
        out.extend_from_slice(format!("{c:<80}").as_bytes());
    }
    out.resize(out.len().div_ceil(2880) * 2880, b' ');
    for v in values {
        out.extend_from_slice(&v.to_be_bytes());
    }
    out.resize(out.len().div_ceil(2880) * 2880, 0);
    fs::write(path, out).unwrap();
}

#[test]
fn a_float_fits_frame_is_read_by_the_stated_rule_and_detected() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A 96 × 72 differenced frame: −380 DN of deep space with a ±3 DN ripple, a target
    // at +2000 DN above it in [30, 20, 54, 40), one pixel of −30 000 (clamped to 0).
    let (w, h) = (96, 72);
    let mut v = vec![0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let ripple = ((x * 7 + y * 3) % 7) as f32 - 3.0;
            let target = (30..54).contains(&x) && (20..40).contains(&y);
            v[y * w + x] = -380.25 + ripple + if target { 2000.0 } else { 0.0 };
        }
    }
    v[5] = -30_000.0;
    let fits = d.join("frame.fits");
    write_fits_f32(&fits, w, h, &v);
    // The rule: clamp(round(v + 1024), 0, 2^14 − 1) by default; the offset and depth
    // from the options.
    let (frame, warnings) = read_frame_with(&fits, &ReadOptions::default()).unwrap();
    assert_eq!((frame.width, frame.height, frame.bits), (w, h, 14));
    for (i, &x) in v.iter().enumerate() {
        let want = (f64::from(x) + 1024.0).round().clamp(0.0, 16383.0) as u16;
        assert_eq!(frame.pixels[i], want, "pixel {i}");
    }
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("1 of 6912 values clamped"),
        "{warnings:?}"
    );
    let opts = ReadOptions {
        bits: Some(16),
        fits_offset_dn: Some(500.0),
        crop: Some([10, 5, 60, 45]),
    };
    let (crop, warnings) = read_frame_with(&fits, &opts).unwrap();
    assert!(warnings.is_empty());
    assert_eq!((crop.width, crop.height, crop.bits), (50, 40, 16));
    assert_eq!(
        crop.pixels[0],
        (f64::from(v[5 * w + 10]) + 500.0).round() as u16
    );
    // detect finds the target; the clamp is a warning line, not an error.
    let out = run(&["detect", "--method", "otsu", "--json", s(&fits)]);
    let line = ok(&out);
    let j: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(j["bbox"], serde_json::json!([30, 20, 54, 40]), "{line}");
    assert!(stderr(&out).contains("warning") && stderr(&out).contains("clamped"));
    // eval on FITS frames with a truth.csv; the crop moves the box.
    fs::write(
        d.join("truth.csv"),
        "file,x0,y0,x1,y1\nframe.fits,20,15,44,35\n",
    )
    .unwrap();
    let report = d.join("report");
    ok(&run(&[
        "eval",
        "--images",
        s(d),
        "--method",
        "otsu",
        "--repeat",
        "1",
        "--crop",
        "10,5,96,72",
        "--out",
        s(&report),
    ]));
    assert_eq!(summary_all(&report, "otsu")["mean_iou"], "1.0000");
    // A bad --crop value and one larger than the frame.
    refused(
        &run(&["detect", "--crop", "1,2,3", s(&fits)]),
        &["x0,y0,x1,y1"],
    );
    refused(
        &run(&["detect", "--crop", "0,0,200,10", s(&fits)]),
        &["frame.fits", "crop"],
    );
}

fn reference_dark_frame() -> Option<PathBuf> {
    let dir = std::env::var_os("TIRROI_REFERENCE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference"));
    let p = dir.join("hayabusa2-tir/dark_20180629_083003.fit");
    if p.exists() {
        Some(p)
    } else {
        eprintln!(
            "SKIPPED: {} not found (set TIRROI_REFERENCE_DIR)",
            p.display()
        );
        None
    }
}

#[test]
fn the_real_dark_frame_reads_by_the_rule_and_its_effective_area() {
    let Some(fits) = reference_dark_frame() else {
        return;
    };
    let raw = read_fits(&fits).unwrap();
    assert_eq!((raw.width, raw.height, raw.bitpix), (384, 256, -32));
    let (frame, warnings) = read_frame_with(&fits, &ReadOptions::default()).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    for (i, &x) in raw.pixels.iter().enumerate() {
        assert_eq!(
            f64::from(frame.pixels[i]),
            (x + 1024.0).round(),
            "pixel {i}"
        );
    }
    let opts = ReadOptions {
        crop: Some(HAYABUSA2_TIR_CROP),
        ..ReadOptions::default()
    };
    let (area, _) = read_frame_with(&fits, &opts).unwrap();
    assert_eq!((area.width, area.height), (328, 248));
    // The README's statistics of the effective area: mean −373 DN, range −434…−131.
    let n = area.pixels.len() as f64;
    let mean = area.pixels.iter().map(|&p| f64::from(p)).sum::<f64>() / n - 1024.0;
    assert!((mean + 373.0).abs() < 1.0, "{mean}");
    let (lo, hi) = area
        .pixels
        .iter()
        .fold((u16::MAX, 0), |(a, b), &p| (a.min(p), b.max(p)));
    // (The README gives whole DN; the values are rounded here.)
    assert!((i32::from(lo) - 1024 + 434).abs() <= 1, "{lo}");
    assert!((i32::from(hi) - 1024 + 131).abs() <= 1, "{hi}");
    for y in 0..248 {
        for x in 0..328 {
            assert_eq!(
                area.pixels[y * 328 + x],
                frame.pixels[(y + 6) * 384 + x + 16]
            );
        }
    }
    let line = ok(&run(&[
        "detect",
        "--method",
        "auto",
        "--json",
        "--crop",
        "hayabusa2-tir",
        s(&fits),
    ]));
    let j: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert!(
        j["bbox"].is_null() || j["bbox"].as_array().unwrap()[2].as_u64().unwrap() <= 328,
        "{line}"
    );
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn an_oversized_png_is_refused_from_its_header() {
    // Signature and IHDR of a 20 000 × 20 000 16-bit grayscale PNG, no pixel data: a
    // reader that allocated before checking would ask for 800 MB, beyond the 256 MB of
    // address space the run is given.
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("huge.png");
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend_from_slice(&20_000u32.to_be_bytes());
    ihdr.extend_from_slice(&20_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[16, 0, 0, 0, 0]);
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    bytes.extend_from_slice(&13u32.to_be_bytes());
    bytes.extend_from_slice(&ihdr);
    bytes.extend_from_slice(&crc32(&ihdr).to_be_bytes());
    // A first IDAT chunk (the header reader stops at it), then the end.
    let idat = b"IDAT\x78\x9c".to_vec();
    bytes.extend_from_slice(&2u32.to_be_bytes());
    bytes.extend_from_slice(&idat);
    bytes.extend_from_slice(&crc32(&idat).to_be_bytes());
    bytes.extend_from_slice(&[0, 0, 0, 0]);
    bytes.extend_from_slice(b"IEND");
    bytes.extend_from_slice(&crc32(b"IEND").to_be_bytes());
    fs::write(&png, bytes).unwrap();
    let out = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 262144; exec {} detect --method otsu {}",
            tirroi().display(),
            s(&png)
        ))
        .output()
        .unwrap();
    refused(&out, &["huge.png", "20000x20000"]);
}

#[test]
fn multi_page_tiff_and_bits_below_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Two pages: page 1 has a bright block, page 2 is flat.
    let (w, h) = (64u32, 48u32);
    let mut page1 = vec![1000u16; (w * h) as usize];
    for y in 10..20 {
        for x in 20..36 {
            page1[(y * w + x) as usize] = 9000;
        }
    }
    let tif = d.join("two.tif");
    {
        let f = fs::File::create(&tif).unwrap();
        let mut enc = tiff::encoder::TiffEncoder::new(f).unwrap();
        enc.write_image::<tiff::encoder::colortype::Gray16>(w, h, &page1)
            .unwrap();
        enc.write_image::<tiff::encoder::colortype::Gray16>(w, h, &vec![1000u16; (w * h) as usize])
            .unwrap();
    }
    let out = run(&["detect", "--method", "otsu", "--json", s(&tif)]);
    let line = ok(&out);
    let j: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
    assert_eq!(
        j["bbox"],
        serde_json::json!([20, 10, 36, 20]),
        "page 1 is read: {line}"
    );
    assert!(
        stderr(&out).contains("multi-page TIFF: reading page 1 only"),
        "{}",
        stderr(&out)
    );
    // A DN of 9000 needs 14 bits: --bits 13 is refused, 14 is fine.
    refused(
        &run(&["detect", "--bits", "13", s(&tif)]),
        &["two.tif", "--bits 13", "needs 14 bits"],
    );
    ok(&run(&["detect", "--bits", "14", s(&tif)]));
    // 8-bit PNG of 255 with --bits 7.
    let png = d.join("eight.png");
    image::GrayImage::from_pixel(16, 8, image::Luma([255]))
        .save(&png)
        .unwrap();
    refused(
        &run(&["detect", "--bits", "7", s(&png)]),
        &["eight.png", "needs 8 bits"],
    );
}

/// `tirroi eval --method all --track MODE` of the frames in `images` into `out`, which
/// must succeed.
fn eval_tracked(images: &Path, mode: &str, out: &Path) {
    ok(&run(&[
        "eval",
        "--images",
        s(images),
        "--method",
        "all",
        "--track",
        mode,
        "--out",
        s(out),
    ]));
}

/// The stronger of [`blocks_frame`]'s two targets in the tracking tests, px.
const STRONG_BLOCK: [u32; 4] = [60, 60, 120, 110];

/// A 328 × 248 frame of 2 000 DN with noise (σ ≈ 9 DN, a fixed xorshift sequence) and
/// each block `([x0, y0, x1, y1), DN)` raised by its DN (the first block that holds a
/// pixel wins).
fn blocks_frame(blocks: &[([u32; 4], u32)]) -> image::ImageBuffer<image::Luma<u16>, Vec<u16>> {
    let mut state = 0x2545_f491u32;
    image::ImageBuffer::from_fn(328, 248, |x, y| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let noise =
            (state & 15) + ((state >> 8) & 15) + ((state >> 16) & 15) + ((state >> 24) & 15);
        let inside = |b: &[u32; 4]| (b[0]..b[2]).contains(&x) && (b[1]..b[3]).contains(&y);
        let lift = blocks
            .iter()
            .find(|(b, _)| inside(b))
            .map_or(0, |&(_, dn)| dn);
        image::Luma([(2000 + noise + lift) as u16])
    })
}

/// A `sequence` column (rendered approach sequences, `render --preset
/// realistic-approach`) makes `eval --track sequence` start each sequence without a
/// prior: a tracker that boxed the weaker of two targets on a frame where it was alone
/// carries that box into the next frame of the same sequence and boxes the weaker
/// target there too, but on the first frame of a new sequence it searches the whole
/// frame and boxes the stronger one.
#[test]
fn eval_track_sequence_starts_each_sequence_without_a_prior() {
    let dir = tempfile::tempdir().unwrap();
    let weak = [230u32, 150, 270, 190];
    blocks_frame(&[(weak, 1500)])
        .save(dir.path().join("a-weak-alone.png"))
        .unwrap();
    blocks_frame(&[(STRONG_BLOCK, 3000), (weak, 1500)])
        .save(dir.path().join("b-both.png"))
        .unwrap();
    let iou = |b: &[String], t: [u32; 4]| {
        let b: [u32; 4] = [0, 1, 2, 3].map(|k| b[k].parse().unwrap());
        let ix = b[2].min(t[2]).saturating_sub(b[0].max(t[0]));
        let iy = b[3].min(t[3]).saturating_sub(b[1].max(t[1]));
        let area = |r: [u32; 4]| (r[2] - r[0]) * (r[3] - r[1]);
        f64::from(ix * iy) / f64::from(area(b) + area(t) - ix * iy)
    };
    for (second, carried) in [("0,1", true), ("1,0", false)] {
        let w = weak.map(|v| v.to_string()).join(",");
        fs::write(
            dir.path().join("truth.csv"),
            format!("file,x0,y0,x1,y1,sequence,frame\na-weak-alone.png,{w},0,0\nb-both.png,{w},{second}\n"),
        )
        .unwrap();
        let out = dir.path().join(format!("eval-{carried}"));
        eval_tracked(dir.path(), "sequence", &out);
        let (h, rows) = csv(&out.join("scores.csv"));
        let (fc, mc, x0, y1) = (
            col(&h, "file"),
            col(&h, "method"),
            col(&h, "x0"),
            col(&h, "y1"),
        );
        // summary.csv: each tracker's frames grouped by whether it came in with a box.
        let (sh, summary) = csv(&out.join("summary.csv"));
        let (m, g, v, n) = (
            col(&sh, "method"),
            col(&sh, "group"),
            col(&sh, "value"),
            col(&sh, "frames"),
        );
        for method in ["auto", "auto-v2"] {
            let boxed = |file: &str| {
                let r = rows
                    .iter()
                    .find(|r| r[fc] == file && r[mc] == method)
                    .unwrap_or_else(|| panic!("{file} {method} in scores.csv"));
                r[x0..=y1].to_vec()
            };
            assert!(iou(&boxed("a-weak-alone.png"), weak) > 0.9, "{method}");
            let b = boxed("b-both.png");
            let (on_weak, on_strong) = (iou(&b, weak), iou(&b, STRONG_BLOCK));
            if carried {
                assert!(on_weak > 0.9, "{method} carried: {b:?}");
            } else {
                assert!(on_strong > 0.9, "{method} new sequence: {b:?}");
            }
            // The first frame of a sequence never comes in with a box, the second of
            // one does.
            let frames = |value: &str| {
                summary
                    .iter()
                    .find(|r| r[m] == method && r[g] == "prior" && r[v] == value)
                    .map_or(0, |r| r[n].parse::<usize>().unwrap())
            };
            let tracked = usize::from(carried);
            assert_eq!(
                (frames("yes"), frames("no")),
                (tracked, 2 - tracked),
                "{method}"
            );
        }
        // Methods that take no prior get no such group.
        assert!(
            summary
                .iter()
                .all(|r| r[g] != "prior" || r[m].starts_with("auto"))
        );
        // `auto-v2`'s boxes name the stage that gave them (a column and a group);
        // no other method's do.
        let sc = col(&h, "stage");
        let mut staged = 0;
        for r in &rows {
            let boxed = !r[x0].is_empty();
            if r[mc] == "auto-v2" && boxed {
                assert!(STAGE_NAMES.contains(&r[sc].as_str()), "{r:?}");
                staged += 1;
            } else {
                assert_eq!(r[sc], "", "{r:?}");
            }
        }
        let grouped: usize = summary
            .iter()
            .filter(|r| r[g] == "stage")
            .inspect(|r| assert_eq!(r[m], "auto-v2", "{r:?}"))
            .map(|r| r[n].parse::<usize>().unwrap())
            .sum();
        assert_eq!((staged, grouped), (2, 2));
    }
}

/// `eval --track jitter` and `--track sequence` give both trackers (`auto`, `auto-v2`)
/// their prior: each box in `scores.csv` is the library tracker's with the prior the
/// mode defines (jitter: `jittered_prior` of the truth, and for `auto-v2` its look on
/// the frame; sequence: the tracker's own box on the file before, by file name, and its
/// look there), and a frame without a target has none; on a
/// frame with two targets the jittered prior on the weaker one makes both box it.
#[test]
fn eval_track_hands_both_trackers_their_priors() {
    use tirroi::core::Detector;
    use tirroi::core::Roi;
    use tirroi::core::roi::auto::Auto;
    use tirroi::core::roi::auto::AutoScratch;
    use tirroi::core::roi::auto::learned::look::Look;
    use tirroi::core::roi::auto::learned::{AutoV2, AutoV2Scratch};
    use tirroi::host::eval::scoring::jittered_prior;
    use tirroi::host::imaging::image_io::read_frame;
    let (dir, mut truth) = fixtures_with_an_empty_frame();
    // A frame with two targets, the truth the weaker one: only a tracker handed a prior
    // near it boxes it (noise σ ≈ 9 DN on 2 000 DN; blocks 3 000 and 1 500 DN above).
    let weak = [230u16, 150, 270, 190];
    blocks_frame(&[(STRONG_BLOCK, 3000), (weak.map(u32::from), 1500)])
        .save(dir.path().join("two-targets.png"))
        .unwrap();
    let mut text = fs::read_to_string(dir.path().join("truth.csv")).unwrap();
    text.push_str(&format!(
        "two-targets.png,{},{},{},{}\n",
        weak[0], weak[1], weak[2], weak[3]
    ));
    fs::write(dir.path().join("truth.csv"), text).unwrap();
    truth.push(("two-targets.png".to_string(), Some(weak)));
    let boxed = |r: Option<Roi>| r.map(|r| r.to_array());
    // The library's answer of `method` with `prior` on `file` (no manifest: auto-v2's
    // saturated cut is 0, as `eval` takes it).
    // The look `auto-v2` gets with `prior` on `file`: jitter's, the prior's on the
    // frame itself.
    let look_on = |file: &str, r: Option<Roi>| {
        let buf = read_frame(&dir.path().join(file), None).unwrap();
        let frame = buf.view().unwrap();
        r.and_then(|r| Look::measure(&frame, r))
    };
    let library = |method: &str, file: &str, prior: Option<Roi>, look: Option<Look>| {
        let buf = read_frame(&dir.path().join(file), None).unwrap();
        let frame = buf.view().unwrap();
        match method {
            "auto" => {
                Auto::default()
                    .with_prior(prior)
                    .detect(&frame, &mut Box::new(AutoScratch::new()))
                    .unwrap()
                    .roi
            }
            _ => {
                AutoV2 {
                    saturated_erode_px: 0,
                    ..AutoV2::default()
                }
                .with_prior(prior)
                .with_look(look)
                .detect(&frame, &mut Box::new(AutoV2Scratch::new()))
                .unwrap()
                .roi
            }
        }
    };
    // `x0..y1` of a scores.csv row: four empty fields for no box.
    let parse = |f: &[String]| -> Bbox {
        (!f[0].is_empty()).then(|| [0, 1, 2, 3].map(|k| f[k].parse().unwrap()))
    };
    for mode in ["jitter", "sequence"] {
        let out = dir.path().join(format!("eval-{mode}"));
        eval_tracked(dir.path(), mode, &out);
        let (h, rows) = csv(&out.join("scores.csv"));
        let (fc, mc) = (col(&h, "file"), col(&h, "method"));
        let (x0, y1) = (col(&h, "x0"), col(&h, "y1"));
        // Each tracker's box on the file before, and its look there.
        let mut previous: BTreeMap<String, (Option<Roi>, Option<Look>)> = BTreeMap::new();
        let mut files: Vec<&(String, Bbox)> = truth.iter().collect();
        files.sort_by(|a, b| a.0.cmp(&b.0));
        for (file, t) in files {
            for method in ["auto", "auto-v2"] {
                let row = rows
                    .iter()
                    .find(|r| r[fc] == *file && r[mc] == method)
                    .unwrap_or_else(|| panic!("{file} {method} in scores.csv"));
                let got = parse(&row[x0..=y1]);
                let (prior, look) = match mode {
                    "jitter" => {
                        let p = t.map(|b| jittered_prior(Roi::new(b[0], b[1], b[2], b[3]), file));
                        (p, look_on(file, p))
                    }
                    _ => previous.get(method).copied().unwrap_or((None, None)),
                };
                let want = library(method, file, prior, look);
                assert_eq!(got, boxed(want), "{mode} {file} {method} prior {prior:?}");
                if mode == "jitter" && file == "two-targets.png" {
                    // The prior is what makes the answer: the weaker target's box, not
                    // the stronger one's found without a prior.
                    assert_ne!(want, library(method, file, None, None), "{method}");
                }
                previous.insert(method.to_string(), (want, look_on(file, want)));
            }
        }
    }
}
