//! `tirroi render`: labelled datasets that are the same bytes for a seed (whatever the
//! thread count), resumable, with errors that name the file, line and field.

mod cli_common;

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;
use std::process::Command;

use cli_common::{run, tirroi};

/// Every scene kind in a few images, on a coarse Earth mesh to keep debug builds quick.
const SMALL: &str = r#"
[dataset]
name = "small"
seed = 3
thermal_states = 2

[earth_model]
mesh_deg = 0.5
days = 2

[[scene]]
name = "det"
count = 3
mode = "detection"
scale = [1, 2, 3]
range_m = { min = 15.0, max = 50.0 }
earth_off_boresight_deg = 30.0

[[scene]]
name = "rad-far"
count = 2
mode = "radiometry"
material = ["multi-1", "multi-2"]
illumination = ["sunlit", "eclipse"]
range_m = { min = 340.0, max = 440.0 }
resolution_m = 0.1

[[scene]]
name = "tango-fixed"
count = 1
target = "tango"
range_m = 20.0
attitude_deg = [10.0, 20.0, 30.0]
offset_px = [10.0, -5.0]
noise = false
earth = false

[[scene]]
name = "winged-fixed"
count = 1
target = "winged-sat"
range_m = 20.0
attitude_deg = [10.0, 20.0, 30.0]
offset_px = [10.0, -5.0]
noise = false
earth = false
"#;

fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    for sub in ["", "masks", "preview"] {
        let d = dir.join(sub);
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            if e.path().is_file() {
                let name = format!("{sub}/{}", e.file_name().to_string_lossy());
                out.insert(name, fs::read(e.path()).unwrap());
            }
        }
    }
    out
}

fn render_into(config: &Path, out: &Path, threads: &str, extra: &[&str]) -> String {
    let o = Command::new(tirroi())
        .env("RAYON_NUM_THREADS", threads)
        .args(["render", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn small_dataset_is_labelled_and_deterministic_across_thread_counts() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("small.toml");
    fs::write(&config, SMALL).unwrap();
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    let report = render_into(&config, &a, "1", &["--masks", "--preview"]);
    assert!(report.contains("7 images rendered"), "{report}");
    assert!(report.contains("per-image CPU time by stage"), "{report}");
    render_into(&config, &b, "2", &["--masks", "--preview"]);
    let fa = files(&a);
    let fb = files(&b);
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{name} differs between 1 and 2 threads");
    }
    // 7 PNG + 7 masks + 7 previews + truth.csv + coco.json + metadata.jsonl + the run
    // manifest tirroi-run.json, nothing else.
    assert_eq!(fa.len(), 25, "{:?}", fa.keys().collect::<Vec<_>>());
    assert!(fa.contains_key("/tirroi-run.json"));
    assert!(
        !fa.keys()
            .any(|k| k.ends_with(".part") || k.contains("progress"))
    );

    let truth = String::from_utf8(fa["/truth.csv"].clone()).unwrap();
    let mut lines = truth.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with("file,x0,y0,x1,y1,"));
    // No sequence in the file, no sequence columns.
    assert!(header.ends_with(",visible_share"), "{header}");
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 7);
    for r in &rows {
        let b: Vec<u16> = r[1..5].iter().map(|v| v.parse().unwrap()).collect();
        assert!(
            b[0] < b[2] && b[1] < b[3] && b[2] <= 328 && b[3] <= 248,
            "{r:?}"
        );
    }
    // Detection: one pose at the three scales shares its box; modes and scales labelled.
    assert_eq!(rows[0][1..5], rows[1][1..5]);
    assert_eq!(rows[0][1..5], rows[2][1..5]);
    assert_eq!((rows[0][5], rows[0][6]), ("detection", "1"));
    assert_eq!((rows[2][5], rows[2][6]), ("detection", "3"));
    assert_eq!(
        (rows[3][5], rows[3][8], rows[3][9]),
        ("radiometry", "multi-1", "sunlit")
    );
    // Poses enumerate material × illumination: the second pose is multi-2, sunlit.
    assert_eq!((rows[4][8], rows[4][9]), ("multi-2", "sunlit"));
    assert_eq!(rows[5][7], "tango");
    // The winged satellite, no Table 3 material case; its wings stretch the box (2.9 m
    // span against a 0.6 m bus, 0.78 m with its radome).
    assert_eq!((rows[6][7], rows[6][8]), ("winged-sat", ""));
    let w: Vec<f64> = rows[6][1..5].iter().map(|v| v.parse().unwrap()).collect();
    let (bw, bh) = (w[2] - w[0], w[3] - w[1]);
    assert!(bw.max(bh) >= 2.5 * bw.min(bh), "{:?}", rows[6]);

    // The PNG is the DN the metadata describes: 16-bit, 328 × 248, inside 14 bits.
    let img = image::load_from_memory(&fa["/000000.png"])
        .unwrap()
        .into_luma16();
    assert_eq!(img.dimensions(), (328, 248));
    assert!(img.pixels().all(|p| p.0[0] <= 16383));
    // Detection mode: the target saturates (Section 4.1).
    assert!(img.pixels().any(|p| p.0[0] == 16383));
    // The mask's ≥ 50 % pixels span exactly the truth box.
    let mask = image::load_from_memory(&fa["masks/000000.png"])
        .unwrap()
        .into_luma8();
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, p) in mask.enumerate_pixels() {
        if p.0[0] >= 128 {
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
        }
    }
    let b: Vec<u32> = rows[0][1..5].iter().map(|v| v.parse().unwrap()).collect();
    assert_eq!(vec![x0, y0, x1, y1], b);

    let coco: serde_json::Value = serde_json::from_slice(&fa["/coco.json"]).unwrap();
    assert_eq!(coco["images"].as_array().unwrap().len(), 7);
    assert_eq!(coco["annotations"].as_array().unwrap().len(), 7);
    let ann = &coco["annotations"][0];
    assert_eq!(ann["bbox"][0].as_u64().unwrap() as u32, b[0]);
    assert_eq!(ann["bbox"][2].as_u64().unwrap() as u32, b[2] - b[0]);
    let meta: Vec<serde_json::Value> = String::from_utf8(fa["/metadata.jsonl"].clone())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(meta.len(), 7);
    assert!(meta[0]["earth_fraction"].as_f64().unwrap() > 0.0);
    assert_eq!(meta[5]["earth_fraction"].as_f64().unwrap(), 0.0);
    assert_eq!(meta[5]["noise_sigma_dn"].as_f64().unwrap(), 0.0);
    assert!(meta[0]["noise_sigma_dn"].as_f64().unwrap() > 0.0);
    let t = &meta[3]["target_temperature_k"];
    assert!(t[0].as_f64().unwrap() < t[1].as_f64().unwrap());
}

/// Approach sequences (scene `sequence`): `truth.csv` ends with `sequence,frame`, the
/// images of a sequence are numbered in it, the range closes frame by frame as the
/// scene says (so the target's box grows), and `metadata.jsonl` carries both numbers.
#[test]
fn a_sequence_is_labelled_frame_by_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("approach.toml");
    fs::write(
        &config,
        r#"
[dataset]
seed = 5
thermal_states = 2

[[scene]]
count = 6
range_m = 40.0
earth = false
offset_px = [0.0, 0.0]
sequence = { frames = 3, range_end_m = 20.0, drift_px = 30.0, spin_deg = 20.0 }
"#,
    )
    .unwrap();
    let out = tmp.path().join("out");
    let report = render_into(&config, &out, "2", &[]);
    assert!(report.contains("6 images rendered"), "{report}");
    let truth = fs::read_to_string(out.join("truth.csv")).unwrap();
    let mut lines = truth.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[header.len() - 2..], ["sequence", "frame"]);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (seq, frame, range) = (at("sequence"), at("frame"), at("range_m"));
    let numbered: Vec<(&str, &str)> = rows.iter().map(|r| (r[seq], r[frame])).collect();
    assert_eq!(
        numbered,
        [
            ("0", "0"),
            ("0", "1"),
            ("0", "2"),
            ("1", "0"),
            ("1", "1"),
            ("1", "2")
        ]
    );
    for run in rows.chunks(3) {
        let ranges: Vec<f64> = run.iter().map(|r| r[range].parse().unwrap()).collect();
        assert_eq!(ranges, [40.0, 30.0, 20.0]);
        let width = |r: &Vec<&str>| r[3].parse::<u32>().unwrap() - r[1].parse::<u32>().unwrap();
        assert!(width(&run[0]) < width(&run[1]) && width(&run[1]) < width(&run[2]));
    }
    let meta: Vec<serde_json::Value> = fs::read_to_string(out.join("metadata.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(
        (meta[4]["sequence"].as_u64(), meta[4]["frame"].as_u64()),
        (Some(1), Some(1))
    );
    // The target's centre drifts the scene's 30 px from the first frame to the last.
    let centre = |m: &serde_json::Value| [0, 1].map(|k| m["offset_px"][k].as_f64().unwrap());
    let (a, b) = (centre(&meta[0]), centre(&meta[2]));
    assert!(
        ((b[0] - a[0]).hypot(b[1] - a[1]) - 30.0).abs() < 1e-6,
        "{a:?} {b:?}"
    );
}

#[test]
fn a_stopped_run_resumes_to_the_same_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("small.toml");
    fs::write(&config, SMALL).unwrap();
    let full = tmp.path().join("full");
    render_into(&config, &full, "2", &[]);
    // Simulate a stop after 4 images: the manifest of an unfinished run, the journal
    // lists them, no label files yet.
    let part = tmp.path().join("part");
    fs::create_dir(&part).unwrap();
    let manifest = fs::read_to_string(full.join("tirroi-run.json")).unwrap();
    assert!(manifest.contains("\"complete\": true"), "{manifest}");
    fs::write(
        part.join("tirroi-run.json"),
        manifest.replace("\"complete\": true", "\"complete\": false"),
    )
    .unwrap();
    let meta = fs::read_to_string(full.join("metadata.jsonl")).unwrap();
    let journal: String = meta.lines().take(4).map(|l| format!("{l}\n")).collect();
    fs::write(part.join("progress.jsonl"), journal).unwrap();
    for i in 0..4 {
        let name = format!("{i:06}.png");
        fs::copy(full.join(&name), part.join(&name)).unwrap();
    }
    let report = render_into(&config, &part, "2", &["--resume"]);
    assert!(report.contains("3 images rendered (4 resumed)"), "{report}");
    let (a, b) = (files(&full), files(&part));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    for (name, bytes) in &a {
        assert!(bytes == &b[name], "{name} differs after resuming");
    }
}

#[test]
fn renders_a_640x512_camera() {
    let tmp = tempfile::tempdir().unwrap();
    let config = tmp.path().join("big.toml");
    fs::write(
        &config,
        "[dataset]\nname = \"big\"\nseed = 5\n[camera]\nwidth = 640\nheight = 512\n\
         [[scene]]\nname = \"rad\"\ncount = 1\nmode = \"radiometry\"\nrange_m = 20.0\n",
    )
    .unwrap();
    let out = tmp.path().join("out");
    let report = render_into(&config, &out, "1", &[]);
    assert!(report.contains("1 images rendered"), "{report}");
    let png = fs::read_dir(&out)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|e| e == "png"))
        .expect("a PNG");
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (640, 512));
    // And the detectors take it.
    let o = run(&["detect", "--method", "all", "--json", png.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_scene_files_name_the_file_line_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.toml");
    fs::write(&bad, "[[scene]]\nrange_m = 20.0\nmaterial = \"gold\"\n").unwrap();
    let o = run(&[
        "render",
        "--config",
        bad.to_str().unwrap(),
        "--out",
        "/nonexistent/x",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.toml:3:"), "{err}");
    assert!(err.starts_with("tirroi: error:"), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    fs::write(&bad, "[[scene]]\nrange_m = { min = 0.0, max = 10.0 }\n").unwrap();
    let o = run(&["render", "--config", bad.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(err.contains("scene[0].range_m"), "{err}");

    let o = run(&["render", "--config", "/no/such/file.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read"));

    let o = run(&["render", "--preset", "nope"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("paper, tango, quick"));
}

#[test]
fn presets_list_and_print_as_toml_that_parses_back() {
    let o = run(&["render", "--list-presets"]);
    assert!(o.status.success());
    let list = String::from_utf8_lossy(&o.stdout);
    for p in ["paper", "tango", "quick", "realistic-winged"] {
        assert!(list.contains(p), "{list}");
    }
    let o = run(&[
        "render",
        "--preset",
        "paper",
        "--count",
        "120",
        "--print-config",
    ]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("paper120.toml");
    fs::write(&path, &text).unwrap();
    let o = run(&[
        "render",
        "--config",
        path.to_str().unwrap(),
        "--print-config",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(String::from_utf8_lossy(&o.stdout), text);
    assert_eq!(text.matches("count = 30").count(), 4, "{text}");
}

#[test]
fn eval_scores_a_directory_of_frames_per_method_and_group() {
    let tmp = tempfile::tempdir().unwrap();
    let fixtures = tmp.path().join("fx");
    let o = run(&["fixtures", "--out", fixtures.to_str().unwrap()]);
    assert!(o.status.success());
    let out = tmp.path().join("eval");
    let o = run(&[
        "eval",
        "--images",
        fixtures.to_str().unwrap(),
        "--method",
        "otsu",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.starts_with("| method | group | frames | mean IoU"),
        "{table}"
    );
    // Otsu finds the target over deep space exactly (a bimodal histogram).
    let scores = fs::read_to_string(out.join("scores.csv")).unwrap();
    let deep = scores
        .lines()
        .find(|l| l.starts_with("deep-space.png,otsu"))
        .unwrap();
    let cols: Vec<&str> = deep.split(',').collect();
    assert_eq!(cols[10], "1.0000", "{deep}");
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary[0]["method"], "otsu");
    assert_eq!(summary[0]["frames"], 4);

    // A bad truth file names the file and the line.
    let bad = tmp.path().join("bad.csv");
    fs::write(&bad, "file,x0,y0,x1,y1\nearth.png,1,2,x,4\n").unwrap();
    let o = run(&[
        "eval",
        "--images",
        fixtures.to_str().unwrap(),
        "--truth",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("bad.csv:2: x1 = `x`"), "{err}");
}
