//! `tirroi fixtures`: writes the procedural fixture frames with their labels.

use std::path::Path;

use crate::imaging::fixture;
use crate::imaging::image_io::write_png16;

/// Runs `tirroi fixtures`: the procedural frames as 16-bit PNG and a `truth.csv` in `out`
/// (the four standard fixtures; with `count`, the seeded family of
/// [`crate::dataset::testset`], as `tirroi testset --kind fixtures`).
///
/// # Errors
/// One line: a bad count, a directory or file that cannot be written.
pub fn run(out: &Path, count: Option<usize>, seed: u64) -> Result<(), String> {
    if let Some(count) = count {
        return super::testset::run(&super::testset::TestsetArgs {
            kind: crate::dataset::testset::Kind::Fixtures,
            count,
            seed,
            out: out.to_path_buf(),
            reference: crate::dataset::testset::DEFAULT_REFERENCE_DIR.into(),
            no_target_fraction: None,
            preview: false,
            sequence_frames: None,
        });
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let mut csv = String::from("file,x0,y0,x1,y1\n");
    for (name, spec) in fixture::standard_set() {
        let fx = fixture::render(&spec);
        let file = format!("{name}.png");
        write_png16(&out.join(&file), &fx.frame).map_err(|e| e.to_string())?;
        let [x0, y0, x1, y1] = fx.truth.to_array();
        csv.push_str(&format!("{file},{x0},{y0},{x1},{y1}\n"));
    }
    let truth = out.join("truth.csv");
    std::fs::write(&truth, csv).map_err(|e| format!("{}: cannot write: {e}", truth.display()))?;
    println!(
        "wrote {} frames and truth.csv to {}",
        fixture::standard_set().len(),
        out.display()
    );
    Ok(())
}
