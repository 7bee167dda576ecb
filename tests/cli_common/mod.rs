//! Shared by the CLI tests: the `tirroi` binary of this build and a way to run it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The `tirroi` binary of this build (the root package cannot use
/// `CARGO_BIN_EXE_tirroi`: the binary belongs to `tirroi-host`). It lives next to
/// this test's `deps/` directory; cargo is asked once to bring it up to date (a no-op
/// when it is), so a stale binary is never tested.
pub fn tirroi() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let exe = std::env::current_exe().expect("test executable path");
        let profile_dir = exe
            .parent()
            .and_then(Path::parent)
            .expect("test executables live in <target>/<profile>/deps");
        let bin = profile_dir.join(format!("tirroi{}", std::env::consts::EXE_SUFFIX));
        let target_dir = profile_dir.parent().expect("<target>/<profile>");
        let profile = profile_dir
            .file_name()
            .and_then(|p| p.to_str())
            .unwrap_or("debug");
        let mut build = Command::new(env!("CARGO"));
        build
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["build", "-q", "-p", "tirroi-host", "--bin", "tirroi"])
            .arg("--target-dir")
            .arg(target_dir);
        match profile {
            "debug" => {}
            "release" => {
                build.arg("--release");
            }
            other => {
                build.args(["--profile", other]);
            }
        }
        let status = build.status().expect("run cargo build");
        assert!(status.success(), "cargo build of the tirroi binary failed");
        assert!(bin.is_file(), "no binary at {}", bin.display());
        bin
    })
}

/// Runs `tirroi` with `args` and collects its output.
pub fn run(args: &[&str]) -> Output {
    Command::new(tirroi())
        .args(args)
        .output()
        .expect("run tirroi")
}

/// The values `auto-v2`'s stage takes in `tirroi detect --json` (`"stage"`) and in
/// `eval`'s `scores.csv` (`stage`): the interface, written out here and checked against
/// `learned::Stage::name` in `tests/cli.rs`. (Not every test crate that includes this
/// module uses it.)
#[allow(dead_code)]
pub const STAGE_NAMES: [&str; 6] = [
    "tracked",
    "blob",
    "deep-space",
    "classifier",
    "spot",
    "outline",
];
