//! `tirroi fixtures`: writes the procedural fixture frames with their labels.

use std::path::Path;

use crate::imaging::fixture;
use crate::imaging::image_io::write_png16;

/// Runs `tirroi fixtures`: the procedural frames as 16-bit PNG and a `truth.csv` in `out`.
///
/// # Errors
/// One line: a directory or file that cannot be written.
pub fn run(out: &Path) -> Result<(), String> {
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
