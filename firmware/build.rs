//! Build script of the firmware demo:
//! - puts the repository's `memory.x` (the flight target's memory map; with
//!   `--features dtcm` this crate's `memory-dtcm.x`) where cortex-m-rt's `link.x`
//!   finds it;
//! - decodes the frames of `frames/` (16-bit PNG, listed in `frames/truth.csv`) into
//!   big-endian DN files in OUT_DIR and writes `frames.rs`, which embeds them in flash
//!   with `include_bytes!`, in the order of `truth.csv`, with their truth boxes.

use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};

/// The core's frame size (the frames are embedded for its detectors).
const WIDTH: u32 = FRAME_WIDTH as u32;
const HEIGHT: u32 = FRAME_HEIGHT as u32;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));

    // `--features dtcm`: the STM32H7-class map (128 KB DTCM for statics and stack, the
    // frame in AXI SRAM), else the reference flight part's (SAMV71Q21RT).
    let memory_x = if env::var_os("CARGO_FEATURE_DTCM").is_some() {
        manifest.join("memory-dtcm.x")
    } else {
        manifest.join("../memory.x")
    };
    fs::copy(&memory_x, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("cannot copy {}: {e}", memory_x.display()));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());

    let bare_arm = env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none")
        && env::var("CARGO_CFG_TARGET_ARCH").as_deref() == Ok("arm");
    if bare_arm && env::var_os("CARGO_FEATURE_DEFMT").is_some() {
        println!("cargo:rustc-link-arg=-Tdefmt.x");
    }

    let frames_dir = manifest.join("frames");
    println!("cargo:rerun-if-changed={}", frames_dir.display());
    let code = embed_frames(&frames_dir, &out).unwrap_or_else(|e| {
        panic!(
            "{e}\nThe frames are rendered by the host: run scripts/flight-frames.sh from the repository root."
        )
    });
    fs::write(out.join("frames.rs"), code).expect("write frames.rs");
}

/// Decodes every frame listed in `dir/truth.csv`, writes `<n>.be` files to `out` and
/// returns the Rust source of the `FRAMES` table.
fn embed_frames(dir: &Path, out: &Path) -> Result<String, String> {
    let truth_path = dir.join("truth.csv");
    let truth =
        fs::read_to_string(&truth_path).map_err(|e| format!("{}: {e}", truth_path.display()))?;
    println!("cargo:rerun-if-changed={}", truth_path.display());
    let mut entries = String::new();
    let mut count = 0usize;
    for (line_no, line) in truth.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        let at = || format!("{}:{}", truth_path.display(), line_no + 1);
        if fields.len() < 5 {
            return Err(format!(
                "{}: expected file,x0,y0,x1,y1,..., got {line:?}",
                at()
            ));
        }
        let file = fields[0];
        let name = file
            .strip_suffix(".png")
            .ok_or_else(|| format!("{}: {file} is not a .png", at()))?;
        let mut truth_box = [0u16; 4];
        for (v, f) in truth_box.iter_mut().zip(&fields[1..5]) {
            *v = f
                .parse()
                .map_err(|_| format!("{}: box value {f:?} is not an integer", at()))?;
        }
        let png_path = dir.join(file);
        println!("cargo:rerun-if-changed={}", png_path.display());
        let be = decode_be(&png_path)?;
        let be_path = out.join(format!("{count}.be"));
        fs::write(&be_path, be).map_err(|e| format!("{}: {e}", be_path.display()))?;
        writeln!(
            entries,
            "    EmbeddedFrame {{ name: {name:?}, truth: Roi::new({}, {}, {}, {}), be_bytes: include_bytes!({:?}) }},",
            truth_box[0],
            truth_box[1],
            truth_box[2],
            truth_box[3],
            be_path.display().to_string()
        )
        .unwrap();
        count += 1;
    }
    if count == 0 {
        return Err(format!("{}: no frames listed", truth_path.display()));
    }
    Ok(format!(
        "/// The embedded frames, in the order of `frames/truth.csv`.\n\
         pub static FRAMES: [EmbeddedFrame; {count}] = [\n{entries}];\n"
    ))
}

/// A 328×248 16-bit grayscale PNG as big-endian DN bytes, row-major.
fn decode_be(path: &Path) -> Result<Vec<u8>, String> {
    let file = fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let info = reader.info();
    if info.width != WIDTH || info.height != HEIGHT {
        return Err(format!(
            "{}: {}x{} pixels, expected {WIDTH}x{HEIGHT}",
            path.display(),
            info.width,
            info.height
        ));
    }
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(format!(
            "{}: {:?} {:?}, expected 16-bit grayscale",
            path.display(),
            info.color_type,
            info.bit_depth
        ));
    }
    let mut buf = vec![0u8; reader.output_buffer_size().ok_or("PNG too large")?];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    buf.truncate(frame.buffer_size());
    // PNG stores 16-bit samples big-endian: the bytes are already the link's order.
    Ok(buf)
}
