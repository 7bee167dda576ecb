//! The host's procedural fixtures (`tirroi::host::imaging::fixture`) are committed as data in
//! `core/tests/data/fixtures/` so that the core's tests read them without the host.
//! This test keeps data and generator from drifting apart: the generator must still
//! make exactly the committed frames and truth boxes.
//!
//! After an intended change of the generator, regenerate the data with
//! `cargo run --release -- fixtures --out core/tests/data/fixtures`.

use std::path::{Path, PathBuf};

use tirroi::host::imaging::fixture::{render, standard_set};

const REGENERATE: &str =
    "regenerate with `cargo run --release -- fixtures --out core/tests/data/fixtures`";

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("core/tests/data/fixtures")
}

/// The committed truth.csv rows: (file, [x0, y0, x1, y1]).
fn committed_truth() -> Vec<(String, [u16; 4])> {
    let text = std::fs::read_to_string(fixtures_dir().join("truth.csv")).expect("truth.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("file,x0,y0,x1,y1"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            assert_eq!(f.len(), 5, "truth.csv line {line:?}");
            let n = |i: usize| -> u16 { f[i].parse().expect("coordinate") };
            (f[0].to_string(), [n(1), n(2), n(3), n(4)])
        })
        .collect()
}

#[test]
fn committed_fixtures_are_what_the_generator_makes() {
    let set = standard_set();
    let truth = committed_truth();
    let files: Vec<String> = set.iter().map(|(name, _)| format!("{name}.png")).collect();
    let listed: Vec<String> = truth.iter().map(|(f, _)| f.clone()).collect();
    assert_eq!(
        listed, files,
        "truth.csv lists the standard set; {REGENERATE}"
    );

    for ((name, spec), (file, want_box)) in set.iter().zip(&truth) {
        let fx = render(spec);
        assert_eq!(
            fx.truth.to_array(),
            *want_box,
            "{name}: truth box; {REGENERATE}"
        );
        let png = image::open(fixtures_dir().join(file))
            .unwrap_or_else(|e| panic!("{file}: {e}"))
            .into_luma16();
        assert_eq!(
            (png.width() as usize, png.height() as usize),
            (fx.frame.width, fx.frame.height),
            "{name}: size; {REGENERATE}"
        );
        assert_eq!(fx.frame.bits, 14, "{name}: the committed frames are 14-bit");
        let committed = png.into_raw();
        let differing = committed
            .iter()
            .zip(&fx.frame.pixels)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differing, 0,
            "{name}: {differing} pixels differ from the committed frame; {REGENERATE}"
        );
    }
}

#[test]
fn fixture_folder_holds_only_the_standard_set() {
    let mut want: Vec<String> = standard_set()
        .into_iter()
        .map(|(name, _)| format!("{name}.png"))
        .chain(["truth.csv".to_string(), "README.md".to_string()])
        .collect();
    want.sort();
    let mut got: Vec<String> = std::fs::read_dir(fixtures_dir())
        .expect("fixture folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    got.sort();
    assert_eq!(got, want, "stale or missing files; {REGENERATE}");
}
