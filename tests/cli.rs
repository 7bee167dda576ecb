//! The `tirroi` binary end to end: fixtures on disk, `detect --json` lines that agree
//! with the library, and one clean error line (exit code 2, no panic) per bad file.

mod cli_common;

use cli_common::{STAGE_NAMES, run};
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;
use tirroi::core::roi::Detectors;
use tirroi::core::roi::auto::learned::Stage;
use tirroi::core::{Detection, Method, Roi};
use tirroi::host::imaging::fixture;
use tirroi::host::imaging::image_io::read_frame;

fn stdout_lines(out: &Output) -> Vec<String> {
    String::from_utf8(out.stdout.clone())
        .expect("UTF-8 stdout")
        .lines()
        .map(str::to_owned)
        .collect()
}

fn stderr_text(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Writes the fixture frames into a fresh temporary directory.
fn fixtures() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = run(&["fixtures", "--out", dir.path().to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    dir
}

/// What the library's default detector for `method` finds in the frame file `path`
/// (read as the CLI reads it).
fn library_detection(method: Method, path: &Path) -> Detection {
    let buf = read_frame(path, None).expect("readable frame");
    let frame = buf.view().expect("valid frame");
    let mut bank = Box::new(Detectors::new());
    bank.detect(&method.default_params(), &frame)
        .expect("default parameters are valid")
}

/// Parses one `detect --json` line and checks its shape; returns (file, method, bbox).
/// An `auto-v2` line with a box carries a `"stage"` too (checked by [`stage_of_line`]).
fn parse_line(line: &str) -> (String, String, Option<[u16; 4]>) {
    let v: Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"));
    let obj = v.as_object().expect("a JSON object per line");
    let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
    keys.sort_unstable();
    let staged = obj["method"] == "auto-v2" && !obj["bbox"].is_null();
    let want: &[&str] = if staged {
        &["bbox", "file", "method", "score", "stage", "time_us"]
    } else {
        &["bbox", "file", "method", "score", "time_us"]
    };
    assert_eq!(keys, want, "{line}");
    let time = obj["time_us"].as_f64().expect("time_us is a number");
    assert!(time.is_finite() && time >= 0.0, "{line}");
    let score = obj["score"].as_f64().expect("score is a number");
    assert!((0.0..=1.0).contains(&score), "score in 0–1: {line}");
    assert_eq!(
        obj["bbox"].is_null(),
        score == 0.0,
        "score 0 exactly when no box: {line}"
    );
    let bbox = match &obj["bbox"] {
        Value::Null => None,
        Value::Array(a) => {
            assert_eq!(a.len(), 4, "{line}");
            let c: Vec<u16> = a
                .iter()
                .map(|n| {
                    let n = n.as_u64().expect("integer coordinates");
                    u16::try_from(n).expect("coordinate fits the frame")
                })
                .collect();
            assert!(c[0] < c[2] && c[1] < c[3], "non-empty box: {line}");
            Some([c[0], c[1], c[2], c[3]])
        }
        other => panic!("bbox is neither an array nor null: {other}"),
    };
    (
        obj["file"].as_str().expect("file is a string").to_owned(),
        obj["method"]
            .as_str()
            .expect("method is a string")
            .to_owned(),
        bbox,
    )
}

/// The `"stage"` of a `detect --json` line (`None` without one), one of [`STAGE_NAMES`].
fn stage_of_line(line: &str) -> Option<String> {
    let v: Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"));
    let stage = v
        .get("stage")?
        .as_str()
        .expect("stage is a string")
        .to_owned();
    assert!(STAGE_NAMES.contains(&stage.as_str()), "{line}");
    Some(stage)
}

/// The stage names of the interface are the library's, in its order.
#[test]
fn stage_names_are_the_librarys() {
    let names = Stage::ALL.map(Stage::name);
    assert_eq!(names, STAGE_NAMES);
}

/// The stage of `auto-v2`'s box on `path` by the library (its default parameters, the
/// telemetry of its scratch).
fn library_stage(path: &Path) -> Option<&'static str> {
    let buf = read_frame(path, None).expect("readable frame");
    let frame = buf.view().expect("valid frame");
    let mut bank = Box::new(Detectors::new());
    let d = bank
        .detect(&Method::AutoV2.default_params(), &frame)
        .expect("default parameters are valid");
    bank.auto_v2().work().stage(d.roi).map(|s| s.name())
}

#[test]
fn fixtures_writes_pngs_and_truth() {
    let dir = fixtures();
    let csv = std::fs::read_to_string(dir.path().join("truth.csv")).expect("truth.csv");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("file,x0,y0,x1,y1"));
    let rows: Vec<&str> = lines.collect();
    let set = fixture::standard_set();
    assert_eq!(rows.len(), set.len());
    for (row, (name, spec)) in rows.iter().zip(&set) {
        let fx = fixture::render(spec);
        let [x0, y0, x1, y1] = fx.truth.to_array();
        assert_eq!(*row, format!("{name}.png,{x0},{y0},{x1},{y1}"));
        // The PNG holds exactly the fixture's DN as 16-bit grayscale.
        let path = dir.path().join(format!("{name}.png"));
        let img = image::open(&path).expect("decodable PNG");
        assert_eq!(img.color(), image::ColorType::L16, "{name}");
        assert_eq!((img.width(), img.height()), (328, 248), "{name}");
        assert_eq!(img.into_luma16().into_raw(), fx.frame.pixels, "{name}");
        // And reads back as the 14-bit frame it was.
        let buf = read_frame(&path, None).expect("readable frame");
        assert_eq!(buf, fx.frame, "{name}");
    }
}

#[test]
fn detect_json_one_method() {
    let dir = fixtures();
    let file = dir.path().join("earth.png");
    let file_arg = file.to_str().unwrap();
    let out = run(&["detect", "--method", "otsu", "--json", file_arg]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    assert!(out.stderr.is_empty(), "{}", stderr_text(&out));
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), 1, "{lines:?}");
    let (f, m, bbox) = parse_line(&lines[0]);
    assert_eq!(f, file_arg);
    assert_eq!(m, "otsu");
    let want = library_detection(Method::Otsu, &file);
    assert_eq!(bbox, want.roi.map(|r| r.to_array()));
}

#[test]
fn detect_json_all_methods_and_files() {
    let dir = fixtures();
    let files: Vec<PathBuf> = ["deep-space", "earth-far"]
        .iter()
        .map(|n| dir.path().join(format!("{n}.png")))
        .collect();
    let mut args = vec!["detect", "--method", "all", "--json"];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    let out = run(&args);
    assert!(out.status.success(), "{}", stderr_text(&out));
    let lines = stdout_lines(&out);
    let n = Method::ALL.len();
    assert_eq!(lines.len(), n * files.len(), "{lines:?}");
    let mut staged = 0;
    for (i, line) in lines.iter().enumerate() {
        let (f, m, bbox) = parse_line(line);
        let file = &files[i / n];
        let method = Method::ALL[i % n];
        assert_eq!(f, file.to_str().unwrap());
        assert_eq!(m, method.name());
        let want = library_detection(method, file);
        assert_eq!(bbox, want.roi.map(|r| r.to_array()), "{line}");
        // `auto-v2` names the stage that gave its box, as the library's telemetry.
        let want_stage = (method == Method::AutoV2)
            .then(|| library_stage(file))
            .flatten();
        assert_eq!(stage_of_line(line).as_deref(), want_stage, "{line}");
        staged += usize::from(want_stage.is_some());
    }
    assert!(staged > 0, "an auto-v2 box with its stage");
    // The default method is all of them.
    let out = run(&["detect", "--json", files[0].to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    assert_eq!(stdout_lines(&out).len(), n);
}

#[test]
fn detect_small_8_bit_png_with_known_box() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("square.png");
    let mut img = image::GrayImage::from_pixel(20, 12, image::Luma([10]));
    for y in 3..7 {
        for x in 5..9 {
            img.put_pixel(x, y, image::Luma([200]));
        }
    }
    img.save(&path).unwrap();
    let out = run(&[
        "detect",
        "--method",
        "otsu",
        "--json",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), 1);
    let (_, _, bbox) = parse_line(&lines[0]);
    assert_eq!(bbox, Some(Roi::new(5, 3, 9, 7).to_array()));
}

#[test]
fn detect_a_640x512_png_with_every_method() {
    // Larger than the reference 328×248: the bank runs it at the 640×512 capacity.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.png");
    let mut img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(640, 512, |x, y| {
        image::Luma([100 + ((x * 7 + y * 13) % 7) as u16])
    });
    for y in 300..420 {
        for x in 400..520 {
            img.put_pixel(x, y, image::Luma([5000 + ((x * 7 + y * 13) % 7) as u16]));
        }
    }
    img.save(&path).unwrap();
    let out = run(&[
        "detect",
        "--method",
        "all",
        "--json",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), Method::ALL.len());
    for line in &lines {
        let (_, method, bbox) = parse_line(line);
        if method == "otsu" || method == "auto" {
            assert_eq!(
                bbox,
                Some(Roi::new(400, 300, 520, 420).to_array()),
                "{line}"
            );
        }
    }
}

/// Asserts a failed run: exit code 2, exactly one stderr line naming `file`, no panic.
#[track_caller]
fn assert_one_clean_error(out: &Output, file: &Path) {
    let err = stderr_text(out);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "exactly one error line: {err}");
    assert!(
        lines[0].contains(file.to_str().unwrap()),
        "the error names {}: {err}",
        file.display()
    );
}

#[test]
fn bad_files_give_one_error_line_and_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.png");
    let text_png = dir.path().join("notes.png");
    std::fs::write(&text_png, "this is not a PNG\n").unwrap();
    let text_txt = dir.path().join("notes.txt");
    std::fs::write(&text_txt, "neither is this\n").unwrap();
    let empty = dir.path().join("empty.png");
    std::fs::write(&empty, b"").unwrap();
    let rgb = dir.path().join("colour.png");
    image::RgbImage::from_pixel(16, 8, image::Rgb([10, 200, 30]))
        .save(&rgb)
        .unwrap();
    let large = dir.path().join("large.png");
    image::GrayImage::from_pixel(1025, 300, image::Luma([7]))
        .save(&large)
        .unwrap();
    let large16 = dir.path().join("large16.png");
    image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_pixel(10, 769, image::Luma([7]))
        .save(&large16)
        .unwrap();
    for file in [
        &missing, &text_png, &text_txt, &empty, &rgb, &large, &large16,
    ] {
        for method in ["otsu", "all"] {
            let out = run(&[
                "detect",
                "--method",
                method,
                "--json",
                file.to_str().unwrap(),
            ]);
            assert_one_clean_error(&out, file);
            assert!(
                out.stdout.is_empty(),
                "{}",
                String::from_utf8_lossy(&out.stdout)
            );
        }
    }
}

#[test]
fn a_bad_file_does_not_stop_the_good_ones() {
    let dir = fixtures();
    let good = dir.path().join("earth-close.png");
    let bad = dir.path().join("missing.png");
    let out = run(&[
        "detect",
        "--method",
        "wge",
        "--json",
        bad.to_str().unwrap(),
        good.to_str().unwrap(),
    ]);
    assert_one_clean_error(&out, &bad);
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), 1, "{lines:?}");
    let (f, m, bbox) = parse_line(&lines[0]);
    assert_eq!((f.as_str(), m.as_str()), (good.to_str().unwrap(), "wge"));
    let want = library_detection(Method::Wge, &good);
    assert_eq!(bbox, want.roi.map(|r| r.to_array()));
}

#[test]
fn memory_lists_every_detectors_scratch_bytes() {
    let out = run(&["memory"]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    for m in Method::ALL {
        let row = format!("| {} | {} |", m.name(), m.scratch_bytes());
        assert!(text.contains(&row), "missing {row:?} in:\n{text}");
    }
}

#[test]
fn detect_budget_stops_auto_and_says_where() {
    use tirroi::core::roi::auto::{CALL_INSTR, largest_charge};
    let dir = fixtures();
    let file = dir.path().join("earth.png");
    let file_arg = file.to_str().unwrap();
    let json_of = |budget: u32, method: &str| -> Value {
        let b = budget.to_string();
        let out = run(&[
            "detect", "--method", method, "--budget", &b, "--json", file_arg,
        ]);
        assert!(out.status.success(), "{}", stderr_text(&out));
        serde_json::from_str(&stdout_lines(&out)[0]).expect("one JSON line")
    };
    // Nothing fits: the call's fixed cost only, no box, stopped before the noise stage.
    let v = json_of(100, "auto");
    assert_eq!(v["bbox"], Value::Null);
    assert_eq!(v["budget"]["instructions"], 100);
    assert_eq!(v["budget"]["charged"], CALL_INSTR);
    assert_eq!(v["budget"]["stopped"], "noise");
    // The largest charge of the frame size: the library's box, not stopped.
    let most = largest_charge(328, 248, false);
    let v = json_of(most, "auto");
    let want = library_detection(Method::Auto, &file)
        .roi
        .map(|r| r.to_array());
    let got: Option<[u16; 4]> = serde_json::from_value(v["bbox"].clone()).unwrap();
    assert_eq!(got, want);
    assert_eq!(v["budget"]["stopped"], Value::Null);
    let charged = v["budget"]["charged"].as_u64().unwrap();
    assert!(charged > u64::from(CALL_INSTR) && charged <= u64::from(most));
    // Other methods run as without a budget, and say nothing of it.
    let v = json_of(100, "otsu");
    assert!(v.get("budget").is_none(), "{v}");
    let want = library_detection(Method::Otsu, &file)
        .roi
        .map(|r| r.to_array());
    let got: Option<[u16; 4]> = serde_json::from_value(v["bbox"].clone()).unwrap();
    assert_eq!(got, want);
}

/// `detect --prior` hands the trackers (`auto`, `auto-v2`) the box of the frame
/// before, and `--track` chains each tracker's own box (and `auto-v2`'s look of it)
/// from file to file: the boxes
/// are the library's with those priors; the other methods ignore them; a reversed
/// prior is one error line and exit code 2.
#[test]
fn detect_prior_and_track_are_the_library_trackers() {
    use tirroi::core::Detector;
    use tirroi::core::roi::auto::Auto;
    use tirroi::core::roi::auto::learned::look::Look;
    use tirroi::core::roi::auto::learned::{AutoV2, AutoV2Scratch};
    let dir = fixtures();
    let file = dir.path().join("earth.png");
    let f = file.to_str().unwrap();
    let prior = Roi::new(118, 78, 228, 152);
    let buf = read_frame(&file, None).expect("readable frame");
    let frame = buf.view().expect("valid frame");
    let v2 = AutoV2 {
        saturated_erode_px: 0,
        ..AutoV2::default()
    };
    let with = |p: Option<Roi>, look: Option<Look>| {
        v2.with_prior(p)
            .with_look(look)
            .detect(&frame, &mut Box::new(AutoV2Scratch::new()))
            .expect("valid parameters")
            .roi
            .map(|r| r.to_array())
    };
    let mut bank = Box::new(Detectors::new());
    let v1 = |p: Option<Roi>, bank: &mut Detectors| {
        bank.detect(
            &tirroi::core::roi::Params::Auto(Auto::default().with_prior(p)),
            &frame,
        )
        .expect("valid parameters")
        .roi
        .map(|r| r.to_array())
    };
    let out = run(&[
        "detect",
        "--method",
        "auto-v2",
        "--json",
        "--saturated-erode-px",
        "0",
        "--prior",
        "118,78,228,152",
        "--track",
        f,
        f,
    ]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    let lines = stdout_lines(&out);
    assert_eq!(lines.len(), 2, "{lines:?}");
    let first = parse_line(&lines[0]).2;
    assert!(first.is_some(), "the target is found: {lines:?}");
    // The first file: the window around `--prior` (no look: no frame before).
    assert_eq!(first, with(Some(prior), None));
    // The second: the first box and its look on the first file (the same frame).
    let first_roi = first.map(|[x0, y0, x1, y1]| Roi::new(x0, y0, x1, y1));
    let look = first_roi.and_then(|r| Look::measure(&frame, r));
    assert!(look.is_some(), "the first box has a look");
    assert_eq!(parse_line(&lines[1]).2, with(first_roi, look));
    // `auto` the same way; a method that does not track gives its own box.
    let out = run(&[
        "detect",
        "--method",
        "auto",
        "--json",
        "--prior",
        "118,78,228,152",
        f,
    ]);
    assert!(out.status.success(), "{}", stderr_text(&out));
    assert_eq!(
        parse_line(&stdout_lines(&out)[0]).2,
        v1(Some(prior), &mut bank)
    );
    let out = run(&[
        "detect",
        "--method",
        "otsu",
        "--json",
        "--prior",
        "118,78,228,152",
        f,
    ]);
    assert_eq!(
        parse_line(&stdout_lines(&out)[0]).2,
        library_detection(Method::Otsu, &file)
            .roi
            .map(|r| r.to_array())
    );
    // A reversed box: an error naming the option, exit code 2.
    let out = run(&["detect", "--prior", "5,5,3,3", f]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr_text(&out).contains("--prior"),
        "{}",
        stderr_text(&out)
    );
}
