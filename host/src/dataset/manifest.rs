//! A run's identity and the ownership of its directory: the manifest `tirroi-run.json`
//! written before the first image, and the checks that keep a user's files safe.
//!
//! - A new or empty directory is free to use.
//! - A directory holding a manifest is a tirroi run: replaced only when asked
//!   ([`clear_run`], `render --force`), continued only with the same resolved
//!   configuration ([`Manifest::differences`], `render --resume`).
//! - Any other non-empty directory, the file-system root and the home directory are
//!   refused ([`inspect`]): nothing is written.
//!
//! The manifest records the resolved configuration (preset name, or scene file path and
//! SHA-256 of its bytes; the scene description as TOML after `--seed`/`--count`; seed;
//! image count; outputs; shard), the tirroi version and the renderer's fingerprint
//! ([`RENDERER_FINGERPRINT`]), and whether the run is complete. Its bytes are
//! deterministic (no time stamps).

use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::DatasetError;
use super::images::atomic_write;

/// File name of the manifest in a run's directory.
pub const MANIFEST_FILE: &str = "tirroi-run.json";

/// Version of the manifest's layout (bumped when a field changes meaning).
pub const MANIFEST_FORMAT: u32 = 1;

/// The fingerprint of this build's renderer: 16 hex digits of a SHA-256 over the code that
/// decides a frame's bytes and labels (scene, world, imaging and dataset stages, presets,
/// sensor assets, the core's camera model, `Cargo.lock`; comment lines left out),
/// computed by `host/build.rs`. Two builds with the same fingerprint render the same
/// frames for the same configuration; a different one means the frames may differ.
pub const RENDERER_FINGERPRINT: &str = env!("TIRROI_RENDERER_FINGERPRINT");

/// The label files a run writes beside its images.
pub const LABEL_FILES: [&str; 3] = ["truth.csv", "coco.json", "metadata.jsonl"];

/// The files every run writes: 16-bit PNG frames of DN and the label files (the
/// manifest's `formats`; `outputs` adds masks and previews).
pub const FORMATS: [&str; 4] = ["png-16bit-dn", "truth.csv", "coco.json", "metadata.jsonl"];

/// The journal of finished images of an unfinished run.
pub const JOURNAL_FILE: &str = "progress.jsonl";

/// Where a run's scene description came from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunSource {
    /// A built-in preset, by name.
    Preset(String),
    /// A TOML scene file: its path as given and the SHA-256 (hex) of its bytes.
    File {
        /// The path as given on the command line.
        path: String,
        /// SHA-256 of the file's bytes, lower-case hex (`sha256sum` prints the same).
        sha256: String,
    },
}

/// Part `index` of `of` of a dataset: the images whose index `i` has `i mod of ==
/// index` (interleaved, so every part gets its share of every scene kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This part, 0-based (`0..of`).
    pub index: usize,
    /// Number of parts (≥ 1).
    pub of: usize,
}

/// Largest number of shards `--shard I/N` accepts.
pub const MAX_SHARDS: usize = 100_000;

impl Shard {
    /// Parses `I/N` (0 ≤ I < N ≤ [`MAX_SHARDS`]).
    ///
    /// # Errors
    /// One line naming the expected form.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || {
            format!(
                "--shard {text:?}: expected I/N with 0 <= I < N <= {MAX_SHARDS}, e.g. 0/8 (part I of N: images i with i mod N = I)"
            )
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let of: usize = n.trim().parse().map_err(|_| bad())?;
        if of == 0 || of > MAX_SHARDS || index >= of {
            return Err(bad());
        }
        Ok(Shard { index, of })
    }

    /// Whether image `index` of the dataset belongs to this part.
    pub fn contains(&self, index: usize) -> bool {
        index % self.of == self.index
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.of)
    }
}

/// Which files a run writes besides the 16-bit PNG frames and the label files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Outputs {
    /// `masks/NNNNNN.png`.
    pub masks: bool,
    /// `preview/NNNNNN.png`.
    pub preview: bool,
}

/// The manifest of a run (`tirroi-run.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// [`MANIFEST_FORMAT`] of the writer.
    pub format: u32,
    /// Version of the tirroi that rendered the run (`CARGO_PKG_VERSION`).
    pub tirroi_version: String,
    /// [`RENDERER_FINGERPRINT`] of the build that rendered the run (empty in manifests
    /// written before it was recorded: such a run never matches a current build).
    #[serde(default)]
    pub renderer: String,
    /// Preset or scene file.
    pub source: RunSource,
    /// Dataset name (`[dataset] name`).
    pub name: String,
    /// Dataset seed (after `--seed`).
    pub seed: u64,
    /// Images of the whole dataset (after `--count`; all shards together).
    pub count: usize,
    /// The files every image and the run get ([`FORMATS`]).
    pub formats: Vec<String>,
    /// Optional outputs.
    pub outputs: Outputs,
    /// The part of the dataset this directory holds (`None`: all of it).
    pub shard: Option<Shard>,
    /// The resolved scene description, TOML (what `render --print-config` prints).
    pub scene: String,
    /// Whether every image and the label files are written.
    pub complete: bool,
}

impl Manifest {
    /// The manifest of a run about to start (`complete` false).
    pub fn new(
        source: RunSource,
        file: &crate::world::scene::SceneFile,
        outputs: Outputs,
        shard: Option<Shard>,
    ) -> Result<Manifest, DatasetError> {
        Ok(Manifest {
            format: MANIFEST_FORMAT,
            tirroi_version: env!("CARGO_PKG_VERSION").into(),
            renderer: RENDERER_FINGERPRINT.into(),
            source,
            name: file.dataset.name.clone(),
            seed: file.dataset.seed,
            count: file.image_count(),
            formats: FORMATS.iter().map(|f| f.to_string()).collect(),
            outputs,
            shard,
            scene: toml::to_string(file).map_err(|e| DatasetError(e.to_string()))?,
            complete: false,
        })
    }

    /// What differs between this (stored) run and `other` (the one asked for), one
    /// phrase per field, empty when they are the same run. A scene file's path may
    /// differ as long as its content does not.
    pub fn differences(&self, other: &Manifest) -> Vec<String> {
        let mut d = Vec::new();
        if self.tirroi_version != other.tirroi_version {
            d.push(format!(
                "it was rendered by tirroi {}, this is {}",
                self.tirroi_version, other.tirroi_version
            ));
        }
        if self.renderer != other.renderer {
            let of = |r: &str| {
                if r.is_empty() {
                    "a renderer without a recorded fingerprint".to_string()
                } else {
                    format!("renderer {r}")
                }
            };
            d.push(format!(
                "it was rendered by {}, this build's is {}",
                of(&self.renderer),
                of(&other.renderer)
            ));
        }
        match (&self.source, &other.source) {
            (RunSource::Preset(a), RunSource::Preset(b)) if a == b => {}
            (RunSource::File { sha256: a, .. }, RunSource::File { sha256: b, .. }) if a == b => {}
            (a, b) => d.push(format!(
                "its scenes are {}, not {}",
                describe(a),
                describe(b)
            )),
        }
        if self.seed != other.seed {
            d.push(format!("its seed is {}, not {}", self.seed, other.seed));
        }
        if self.count != other.count {
            d.push(format!("its count is {}, not {}", self.count, other.count));
        }
        if self.formats != other.formats {
            d.push(format!(
                "its files are {}, not {}",
                self.formats.join(", "),
                other.formats.join(", ")
            ));
        }
        let on = |b: bool| if b { "on" } else { "off" };
        if self.outputs.masks != other.outputs.masks {
            d.push(format!("--masks was {}", on(self.outputs.masks)));
        }
        if self.outputs.preview != other.outputs.preview {
            d.push(format!("--preview was {}", on(self.outputs.preview)));
        }
        if self.shard != other.shard {
            let s = |s: Option<Shard>| s.map_or("none".to_string(), |s| s.to_string());
            d.push(format!(
                "its shard is {}, not {}",
                s(self.shard),
                s(other.shard)
            ));
        }
        if d.is_empty() && self.scene != other.scene {
            d.push("its resolved scene description differs".into());
        }
        d
    }

    /// The command that renders (or resumes, with `resume`) this run into `out`.
    pub fn command(&self, out: &Path, resume: bool) -> String {
        let mut c = vec!["tirroi".to_string(), "render".into()];
        match &self.source {
            RunSource::Preset(p) => c.extend(["--preset".into(), quote(p)]),
            RunSource::File { path, .. } => c.extend(["--config".into(), quote(path)]),
        }
        c.extend([
            "--out".into(),
            quote(&out.display().to_string()),
            "--count".into(),
            self.count.to_string(),
            "--seed".into(),
            self.seed.to_string(),
        ]);
        if self.outputs.masks {
            c.push("--masks".into());
        }
        if self.outputs.preview {
            c.push("--preview".into());
        }
        if let Some(s) = self.shard {
            c.extend(["--shard".into(), s.to_string()]);
        }
        if resume {
            c.push("--resume".into());
        }
        c.join(" ")
    }

    /// A short description for messages: source, seed, count, shard.
    pub fn summary(&self) -> String {
        let shard = self.shard.map_or(String::new(), |s| format!(", shard {s}"));
        format!(
            "{}, seed {}, {} images{shard}, {}",
            describe(&self.source),
            self.seed,
            self.count,
            if self.complete {
                "complete"
            } else {
                "unfinished"
            }
        )
    }

    /// Reads `dir`'s manifest (`None` when there is none).
    ///
    /// # Errors
    /// [`DatasetError`] when it exists but cannot be read or parsed.
    pub fn read(dir: &Path) -> Result<Option<Manifest>, DatasetError> {
        let path = dir.join(MANIFEST_FILE);
        if !path.exists() {
            return Ok(None);
        }
        let text = fs::read_to_string(&path)
            .map_err(|e| DatasetError(format!("{}: cannot read: {e}", path.display())))?;
        serde_json::from_str(&text).map(Some).map_err(|e| {
            DatasetError(format!(
                "{}: not a tirroi run manifest ({e}); move it away or choose another --out",
                path.display()
            ))
        })
    }

    /// Writes the manifest into `dir` (atomically).
    ///
    /// # Errors
    /// [`DatasetError`] naming the file.
    pub fn write(&self, dir: &Path) -> Result<(), DatasetError> {
        let mut text =
            serde_json::to_string_pretty(self).map_err(|e| DatasetError(e.to_string()))?;
        text.push('\n');
        atomic_write(&dir.join(MANIFEST_FILE), text.as_bytes())
    }
}

fn describe(s: &RunSource) -> String {
    match s {
        RunSource::Preset(p) => format!("preset {p}"),
        RunSource::File { path, sha256 } => {
            format!("file {path} (sha256 {})", &sha256[..sha256.len().min(12)])
        }
    }
}

/// `s` as one shell word (single-quoted when it holds anything but safe characters).
pub fn quote(s: &str) -> String {
    let safe = |c: char| c.is_ascii_alphanumeric() || "_-./=:,+@%".contains(c);
    if !s.is_empty() && s.chars().all(safe) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// SHA-256 of `bytes`, lower-case hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// What an output directory holds.
#[derive(Debug, Clone, PartialEq)]
pub enum OutState {
    /// Missing, or an empty directory: free to use.
    Free,
    /// A tirroi run, with its manifest.
    Run(Box<Manifest>),
}

/// Checks an output directory before anything is written to it.
///
/// # Errors
/// One actionable line, nothing touched: `dir` is the file-system root or the home
/// directory, not a directory, unreadable, or a non-empty directory without a
/// manifest (not a tirroi run).
pub fn inspect(dir: &Path) -> Result<OutState, DatasetError> {
    let shown = dir.display();
    if let Ok(canon) = dir.canonicalize() {
        if canon.parent().is_none() {
            return Err(DatasetError(format!(
                "--out {shown}: the file-system root is never an output directory; give a new directory, e.g. --out {}",
                Path::new("dataset").display()
            )));
        }
        let home = std::env::var_os("HOME").map(PathBuf::from);
        if let Some(home) = home.and_then(|h| h.canonicalize().ok()) {
            if canon == home {
                return Err(DatasetError(format!(
                    "--out {shown}: the home directory is never an output directory; give a new directory inside it, e.g. --out {}",
                    home.join("dataset").display()
                )));
            }
        }
    }
    if !dir.exists() {
        return Ok(OutState::Free);
    }
    if !dir.is_dir() {
        return Err(DatasetError(format!(
            "--out {shown}: exists and is not a directory; give a directory"
        )));
    }
    if let Some(m) = Manifest::read(dir)? {
        return Ok(OutState::Run(Box::new(m)));
    }
    let mut entries =
        fs::read_dir(dir).map_err(|e| DatasetError(format!("--out {shown}: cannot read: {e}")))?;
    if entries.next().is_some() {
        return Err(DatasetError(format!(
            "--out {shown}: not empty and not a tirroi run (no {MANIFEST_FILE}); nothing was written: give a new or empty directory"
        )));
    }
    Ok(OutState::Free)
}

/// Whether `name` is a frame file a run writes: six or more digits and `.png`
/// (or its temporary `.png.part`).
fn is_frame_name(name: &str) -> bool {
    let stem = name
        .strip_suffix(".png")
        .or_else(|| name.strip_suffix(".png.part"));
    stem.is_some_and(|s| s.len() >= 6 && s.bytes().all(|b| b.is_ascii_digit()))
}

/// Removes the files a tirroi run writes from `dir` (frames, masks, previews, label
/// files and their temporaries, the journal, the manifest), and nothing else: a file
/// of the user's that happens to be in the directory stays, as do empty `masks/` and
/// `preview/` directories holding such files.
///
/// # Errors
/// [`DatasetError`] naming the file that could not be removed.
pub fn clear_run(dir: &Path) -> Result<usize, DatasetError> {
    let mut removed = 0;
    let remove = |p: &Path, removed: &mut usize| -> Result<(), DatasetError> {
        fs::remove_file(p)
            .map_err(|e| DatasetError(format!("{}: cannot remove: {e}", p.display())))?;
        *removed += 1;
        Ok(())
    };
    let own = |name: &str| {
        is_frame_name(name)
            || LABEL_FILES
                .iter()
                .chain([&JOURNAL_FILE, &MANIFEST_FILE])
                .any(|f| name == *f || name.strip_suffix(".part") == Some(f))
    };
    for sub in ["masks", "preview"] {
        let d = dir.join(sub);
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if e.path().is_file() && is_frame_name(&name) {
                remove(&e.path(), &mut removed)?;
            }
        }
        // Only when nothing of the user's is left in it.
        let _ = fs::remove_dir(&d);
    }
    let entries = fs::read_dir(dir)
        .map_err(|e| DatasetError(format!("{}: cannot read: {e}", dir.display())))?;
    // The manifest last: a stopped clean-up still leaves the directory a tirroi run.
    let mut manifest = None;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if e.path().is_file() && own(&name) {
            if name == MANIFEST_FILE {
                manifest = Some(e.path());
            } else {
                remove(&e.path(), &mut removed)?;
            }
        }
    }
    if let Some(m) = manifest {
        remove(&m, &mut removed)?;
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_partition() {
        assert_eq!(Shard::parse("2/8"), Ok(Shard { index: 2, of: 8 }));
        for bad in ["8/8", "1/0", "x/2", "3", "-1/4", "1/100001"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let parts: Vec<Shard> = (0..3).map(|index| Shard { index, of: 3 }).collect();
        for i in 0..30 {
            assert_eq!(parts.iter().filter(|s| s.contains(i)).count(), 1);
        }
    }

    /// A manifest of a preset run, as this build writes it.
    fn this_build() -> Manifest {
        let file = crate::world::scene::SceneFile::preset("quick").unwrap();
        let outputs = Outputs {
            masks: false,
            preview: false,
        };
        Manifest::new(RunSource::Preset("quick".into()), &file, outputs, None).unwrap()
    }

    #[test]
    fn a_run_of_other_renderer_code_is_another_run() {
        let now = this_build();
        assert_eq!(now.renderer, RENDERER_FINGERPRINT);
        assert_eq!(RENDERER_FINGERPRINT.len(), 16);
        assert!(RENDERER_FINGERPRINT.bytes().all(|b| b.is_ascii_hexdigit()));
        assert!(now.differences(&now).is_empty());
        let other = Manifest {
            renderer: "0123456789abcdef".into(),
            ..now.clone()
        };
        assert_eq!(
            other.differences(&now),
            [format!(
                "it was rendered by renderer 0123456789abcdef, this build's is renderer {RENDERER_FINGERPRINT}"
            )]
        );
        // A manifest written before the fingerprint was recorded still reads, and is
        // never taken for this build's run.
        let mut json: serde_json::Value = serde_json::to_value(&now).unwrap();
        json.as_object_mut().unwrap().remove("renderer");
        let old: Manifest = serde_json::from_value(json).unwrap();
        assert_eq!(old.renderer, "");
        assert_eq!(
            old.differences(&now),
            [format!(
                "it was rendered by a renderer without a recorded fingerprint, this build's is renderer {RENDERER_FINGERPRINT}"
            )]
        );
    }

    #[test]
    fn frame_names_and_quoting() {
        assert!(is_frame_name("000012.png") && is_frame_name("1234567.png.part"));
        assert!(!is_frame_name("holiday.png") && !is_frame_name("12.png"));
        assert_eq!(quote("runs/a-1"), "runs/a-1");
        assert_eq!(quote("my runs/it's"), "'my runs/it'\\''s'");
        // The digest `sha256sum` prints for "abc".
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
