//! Build script: the renderer's fingerprint, `TIRROI_RENDERER_FINGERPRINT`.
//!
//! A run's manifest (`tirroi-run.json`) records it so that a dataset rendered by other
//! renderer code is not reused or resumed as if it were this build's
//! (`dataset::Manifest::differences`). It is the first 16 hex digits of the SHA-256 of
//! every source file that decides a frame's bytes or labels — the scene, world and
//! imaging stages, the dataset writer, the seeds, the built-in presets and sensor
//! assets, the core's camera model — and of `Cargo.lock` (a dependency's version can
//! change a random stream). Lines that are only a `//` comment are left out, so a
//! documentation edit does not invalidate datasets; any code change does, even one that
//! happens to leave the frames identical (a re-render is the safe answer).

use std::fs;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// Folders and files, relative to this crate's directory, whose content is the renderer.
const RENDERER_SOURCES: [&str; 8] = [
    "src/world",
    "src/imaging",
    "src/dataset",
    "src/seed.rs",
    "presets",
    "assets/sensor",
    "../core/src/sensor",
    "../Cargo.lock",
];

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let mut files = Vec::new();
    for source in RENDERER_SOURCES {
        let path = root.join(source);
        println!("cargo:rerun-if-changed={}", path.display());
        collect(&path, &mut files);
    }
    files.sort();
    let mut hash = Sha256::new();
    for file in &files {
        let Ok(text) = fs::read(file) else { continue };
        // The path relative to the crate, so the fingerprint does not depend on where
        // the checkout lives.
        let name = file.strip_prefix(&root).unwrap_or(file);
        hash.update(name.to_string_lossy().replace('\\', "/").as_bytes());
        hash.update([0]);
        for line in text.split(|&b| b == b'\n') {
            if !line.trim_ascii_start().starts_with(b"//") {
                hash.update(line.trim_ascii_end());
                hash.update([b'\n']);
            }
        }
    }
    let digest = hash.finalize();
    let hex: String = digest.iter().take(8).map(|b| format!("{b:02x}")).collect();
    println!("cargo:rustc-env=TIRROI_RENDERER_FINGERPRINT={hex}");
}

/// Every regular file under `path` (or `path` itself), any depth.
fn collect(path: &Path, files: &mut Vec<PathBuf>) {
    if path.is_file() {
        files.push(path.to_path_buf());
    } else if let Ok(entries) = fs::read_dir(path) {
        for entry in entries.flatten() {
            collect(&entry.path(), files);
        }
    }
}
