//! `tirroi render` keeps a user's files: the run manifest, refusals (exit 2, one line,
//! nothing touched), `--force`, `--resume` against the manifest, exact `--count`,
//! Ctrl-C's resume command, and `--shard` + `tirroi merge` giving the single run's bytes;
//! `tirroi earth-texture --export` refusing to replace a patch.

mod cli_common;

use std::collections::BTreeMap;
use std::fs;
use std::path::Path;
use std::process::{Command, Output};

use cli_common::{run, tirroi};

/// Two kinds, no Earth, fixed attitudes and a coarse mesh: seconds in a debug build.
/// The detection kind's 4 images end on a partial pose (1 of its 3 scales).
const TINY: &str = r#"
[dataset]
name = "tiny"
seed = 5
thermal_states = 1

[[scene]]
name = "det"
count = 4
mode = "detection"
scale = [1, 2, 3]
target = "tango"
resolution_m = 0.3
range_m = { min = 15.0, max = 30.0 }
attitude_deg = [10.0, 20.0, 30.0]
illumination = "sunlit"
earth = false

[[scene]]
name = "rad"
count = 3
target = "tango"
resolution_m = 0.3
range_m = 20.0
attitude_deg = [40.0, 10.0, 0.0]
illumination = "sunlit"
earth = false
"#;

/// Every file under `dir` (recursively), relative path → bytes.
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, d: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        let Ok(entries) = fs::read_dir(d) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().display().to_string();
                out.insert(rel, fs::read(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn tirroi_in(cwd: &Path, args: &[&str]) -> Output {
    Command::new(tirroi())
        .current_dir(cwd)
        .env("RAYON_NUM_THREADS", "2")
        .args(args)
        .output()
        .unwrap()
}

fn ok(o: &Output) -> String {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Exit code 2 and one line `tirroi: error: ...` containing `needle`.
fn refused(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].starts_with("tirroi: error: "), "{err}");
    assert!(lines[0].contains(needle), "{needle:?} not in {err}");
}

fn setup() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    fs::write(tmp.path().join("tiny.toml"), TINY).unwrap();
    tmp
}

fn frames(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png"))
        .collect();
    v.sort();
    v
}

#[test]
fn foreign_directories_root_and_home_are_refused_untouched() {
    let tmp = setup();
    let cwd = tmp.path();
    let user = cwd.join("photos");
    fs::create_dir(&user).unwrap();
    fs::write(user.join("truth.csv"), "my own labels\n").unwrap();
    fs::write(user.join("000000.png"), b"not a frame of ours").unwrap();
    let before = tree(&user);
    for extra in [&[][..], &["--force"], &["--resume"]] {
        let mut args = vec!["render", "--config", "tiny.toml", "--out", "photos"];
        args.extend_from_slice(extra);
        refused(&tirroi_in(cwd, &args), "not a tirroi run");
        assert_eq!(tree(&user), before, "{extra:?} touched the user's files");
    }
    refused(
        &run(&["render", "--preset", "quick", "--out", "/"]),
        "file-system root",
    );
    // The home directory, even empty and even with --force.
    let home = cwd.join("home");
    fs::create_dir(&home).unwrap();
    let o = Command::new(tirroi())
        .current_dir(cwd)
        .env("HOME", &home)
        .args(["render", "--config", "tiny.toml", "--force", "--out"])
        .arg(&home)
        .output()
        .unwrap();
    refused(&o, "home directory");
    assert!(tree(&home).is_empty());
    // A file where the directory should be.
    fs::write(cwd.join("afile"), "x").unwrap();
    refused(
        &tirroi_in(cwd, &["render", "--config", "tiny.toml", "--out", "afile"]),
        "not a directory",
    );
    // merge follows the same rules for its output.
    refused(
        &tirroi_in(cwd, &["merge", "--out", "out", "photos"]),
        "not a tirroi run",
    );
}

#[test]
fn a_previous_run_is_replaced_only_with_force_and_resumed_only_when_identical() {
    let tmp = setup();
    let cwd = tmp.path();
    ok(&tirroi_in(
        cwd,
        &["render", "--config", "tiny.toml", "--out", "run", "--masks"],
    ));
    let run = cwd.join("run");
    let manifest: serde_json::Value =
        serde_json::from_slice(&fs::read(run.join("tirroi-run.json")).unwrap()).unwrap();
    assert_eq!(manifest["seed"], 5);
    assert_eq!(manifest["count"], 7);
    assert_eq!(manifest["complete"], true);
    assert_eq!(manifest["outputs"]["masks"], true);
    assert_eq!(manifest["outputs"]["preview"], false);
    assert_eq!(manifest["tirroi_version"], env!("CARGO_PKG_VERSION"));
    // The renderer's fingerprint: 16 hex digits (host/build.rs).
    let renderer = manifest["renderer"].as_str().unwrap();
    assert!(renderer.len() == 16 && renderer.bytes().all(|b| b.is_ascii_hexdigit()));
    assert_eq!(
        manifest["source"]["file"]["sha256"].as_str().unwrap().len(),
        64
    );
    let before = tree(&run);

    // Again without --force or --resume: refused, nothing touched.
    refused(
        &tirroi_in(
            cwd,
            &["render", "--config", "tiny.toml", "--out", "run", "--masks"],
        ),
        "--force",
    );
    // --resume with any other resolved configuration: refused, naming what differs.
    for (extra, needle) in [
        (&["--masks", "--seed", "99"][..], "its seed is 5, not 99"),
        (&["--masks", "--count", "5"], "its count is 7, not 5"),
        (&[][..], "--masks was on"),
        (&["--masks", "--preview"], "--preview was off"),
        (&["--masks", "--shard", "0/2"], "shard"),
    ] {
        let mut args = vec![
            "render",
            "--config",
            "tiny.toml",
            "--out",
            "run",
            "--resume",
        ];
        args.extend_from_slice(extra);
        refused(&tirroi_in(cwd, &args), needle);
        assert_eq!(tree(&run), before, "{extra:?}");
    }
    let o = tirroi_in(
        cwd,
        &[
            "render", "--preset", "quick", "--out", "run", "--resume", "--masks",
        ],
    );
    refused(&o, "not preset quick");
    // Another scene file content under the same name: refused.
    fs::write(
        cwd.join("tiny.toml"),
        TINY.replace("seed = 5", "seed = 5 # edited"),
    )
    .unwrap();
    refused(
        &tirroi_in(
            cwd,
            &[
                "render",
                "--config",
                "tiny.toml",
                "--out",
                "run",
                "--resume",
                "--masks",
            ],
        ),
        "its scenes are file",
    );
    fs::write(cwd.join("tiny.toml"), TINY).unwrap();
    assert_eq!(tree(&run), before);
    // The same configuration on a complete run: says so, renders nothing.
    let text = ok(&tirroi_in(
        cwd,
        &[
            "render",
            "--config",
            "tiny.toml",
            "--out",
            "run",
            "--resume",
            "--masks",
        ],
    ));
    assert!(text.contains("complete"), "{text}");
    assert_eq!(tree(&run), before);

    // --force with fewer images and no masks: no stale frame or mask of the old run
    // stays beside the new labels; a file of the user's stays.
    fs::write(run.join("notes.txt"), "mine").unwrap();
    ok(&tirroi_in(
        cwd,
        &[
            "render",
            "--config",
            "tiny.toml",
            "--out",
            "run",
            "--force",
            "--count",
            "2",
        ],
    ));
    assert_eq!(frames(&run), ["000000.png", "000001.png"]);
    assert!(!run.join("masks").exists());
    assert_eq!(fs::read_to_string(run.join("notes.txt")).unwrap(), "mine");
    let truth = fs::read_to_string(run.join("truth.csv")).unwrap();
    assert_eq!(truth.lines().count(), 1 + 2, "{truth}");
}

#[test]
fn count_gives_exactly_that_many_images() {
    let tmp = setup();
    let cwd = tmp.path();
    // The resolved configurations (no rendering): the kinds' counts sum to N.
    for (preset, n) in [
        ("quick", 1),
        ("quick", 3),
        ("paper", 400),
        ("paper", 1),
        ("tango", 7),
    ] {
        let text = ok(&tirroi_in(
            cwd,
            &[
                "render",
                "--preset",
                preset,
                "--count",
                &n.to_string(),
                "--print-config",
            ],
        ));
        // `count = N` lines are the scene kinds' (the [dataset] table has none).
        let total: i64 = text
            .lines()
            .filter_map(|l| l.strip_prefix("count = "))
            .map(|v| v.parse::<i64>().unwrap())
            .sum();
        assert_eq!(total, n, "{preset} --count {n}");
    }
    // Rendered: 5 of the 7 images, in proportion 4 : 3 → 3 detection, 2 radiometry.
    ok(&tirroi_in(
        cwd,
        &[
            "render",
            "--config",
            "tiny.toml",
            "--out",
            "five",
            "--count",
            "5",
        ],
    ));
    let five = cwd.join("five");
    assert_eq!(frames(&five).len(), 5);
    let truth = fs::read_to_string(five.join("truth.csv")).unwrap();
    let modes: Vec<&str> = truth
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(5).unwrap())
        .collect();
    assert_eq!(
        modes,
        ["detection"; 3]
            .iter()
            .chain(&["radiometry"; 2])
            .copied()
            .collect::<Vec<_>>()
    );
}

#[test]
fn shards_merge_to_the_single_run_bytes() {
    let tmp = setup();
    let cwd = tmp.path();
    let base = [
        "render",
        "--config",
        "tiny.toml",
        "--masks",
        "--preview",
        "--out",
    ];
    let mut args = base.to_vec();
    args.push("whole");
    ok(&tirroi_in(cwd, &args));
    for i in 0..3 {
        let mut args = base.to_vec();
        let (out, shard) = (format!("part{i}"), format!("{i}/3"));
        args.extend([out.as_str(), "--shard", shard.as_str()]);
        ok(&tirroi_in(cwd, &args));
        // Each part holds its own frames (i mod 3 = I) with their labels.
        let f = frames(&cwd.join(&out));
        assert!(!f.is_empty());
        for name in &f {
            let index: usize = name[..6].parse().unwrap();
            assert_eq!(index % 3, i, "{name} in {out}");
        }
    }
    // A part missing, or given twice: refused, nothing written.
    refused(
        &tirroi_in(cwd, &["merge", "--out", "m", "part0", "part2"]),
        "missing shard 1/3",
    );
    refused(
        &tirroi_in(
            cwd,
            &["merge", "--out", "m", "part0", "part1", "part1", "part2"],
        ),
        "given twice",
    );
    refused(
        &tirroi_in(cwd, &["merge", "--out", "m", "whole"]),
        "not a part",
    );
    assert!(!cwd.join("m").exists());
    let text = ok(&tirroi_in(
        cwd,
        &["merge", "--out", "m", "part2", "part0", "part1"],
    ));
    assert!(text.contains("7 images"), "{text}");
    let (whole, merged) = (tree(&cwd.join("whole")), tree(&cwd.join("m")));
    // 7 frames, 7 masks, 7 previews, truth.csv, coco.json, metadata.jsonl, manifest.
    assert_eq!(whole.len(), 25, "{:?}", whole.keys().collect::<Vec<_>>());
    assert_eq!(
        whole.keys().collect::<Vec<_>>(),
        merged.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in &whole {
        assert!(bytes == &merged[name], "{name} differs after merging");
    }
    // The merged directory is a run like the whole one: merging again needs --force.
    refused(
        &tirroi_in(cwd, &["merge", "--out", "m", "part0", "part1", "part2"]),
        "--force",
    );
    ok(&tirroi_in(
        cwd,
        &["merge", "--force", "--out", "m", "part0", "part1", "part2"],
    ));
}

#[cfg(unix)]
#[test]
fn ctrl_c_prints_the_command_that_resumes() {
    let tmp = setup();
    let cwd = tmp.path();
    let out = cwd.join("big");
    let child = Command::new(tirroi())
        .current_dir(cwd)
        .env("RAYON_NUM_THREADS", "1")
        .args([
            "render",
            "--config",
            "tiny.toml",
            "--out",
            "big",
            "--count",
            "400",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The manifest is written before the first image; interrupt once it is there.
    let t0 = std::time::Instant::now();
    while !out.join("tirroi-run.json").exists() {
        assert!(t0.elapsed().as_secs() < 120, "no manifest after 120 s");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    std::thread::sleep(std::time::Duration::from_millis(500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    let expected = "tirroi render --config tiny.toml --out big --count 400 --seed 5 --resume";
    assert!(err.contains(expected), "{err}");
    // The printed command is accepted: the run is unfinished and of this configuration
    // (checked with a different seed: refused for the seed alone).
    let manifest: serde_json::Value =
        serde_json::from_slice(&fs::read(out.join("tirroi-run.json")).unwrap()).unwrap();
    assert_eq!(manifest["complete"], false);
    refused(
        &tirroi_in(
            cwd,
            &[
                "render",
                "--config",
                "tiny.toml",
                "--out",
                "big",
                "--count",
                "400",
                "--seed",
                "6",
                "--resume",
            ],
        ),
        "its seed is 5, not 6",
    );
}

/// `tirroi earth-texture --export DIR` writes each sampled patch in the real image's
/// encoding (16-bit PNG, value = brightness temperature × 50) and never replaces a file:
/// a second run into the same directory is refused with the file named, nothing touched.
#[test]
fn earth_texture_export_writes_the_real_encoding_and_keeps_existing_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("patches");
    let dir_arg = dir.to_str().unwrap();
    let args = [
        "earth-texture",
        "--stats",
        "--days",
        "1",
        "--size",
        "64",
        "--cloud-fragments",
        "--export",
        dir_arg,
    ];
    ok(&tirroi_in(tmp.path(), &args));
    let written = frames(&dir);
    assert_eq!(written.len(), 4, "{written:?}");
    assert!(
        written.contains(&"ours-seed1-day0-20N-202E.png".to_string()),
        "{written:?}"
    );
    for name in &written {
        let img = image::open(dir.join(name)).unwrap().into_luma16();
        assert_eq!(img.dimensions(), (64, 64), "{name}");
        // Brightness temperatures of the Earth's longwave window, K.
        for &v in img.as_raw() {
            let t_k = f64::from(v) / 50.0;
            assert!((150.0..=340.0).contains(&t_k), "{name}: {t_k} K");
        }
    }
    let before = tree(&dir);
    refused(&tirroi_in(tmp.path(), &args), "already exists");
    assert_eq!(tree(&dir), before, "an existing patch was touched");
}
