//! `tirroi sensor-fit` end to end: on the real TIR frame it writes the committed
//! calibration byte for byte; bad input is one clean error line naming the file.

mod cli_common;

use std::path::PathBuf;

use cli_common::run;
use tirroi::host::imaging::signature::HAYABUSA2_TIR_DARK_TOML;

fn real_frame() -> Option<PathBuf> {
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
fn sensor_fit_writes_the_committed_calibration() {
    let Some(fits) = real_frame() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cal.toml");
    let o = run(&[
        "sensor-fit",
        "--fits",
        fits.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        HAYABUSA2_TIR_DARK_TOML
    );
    // The summary line carries the headline numbers.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("hot 34") && err.contains("gain 14.2"), "{err}");
}

#[test]
fn bad_fits_input_is_one_error_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("not.fit");
    std::fs::write(&bad, b"hello").unwrap();
    for path in [bad.clone(), dir.path().join("missing.fit")] {
        let o = run(&["sensor-fit", "--fits", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.starts_with("tirroi: error: ") && err.contains(path.to_str().unwrap()),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}
