//! The firmware demo's workload on the host: the reference the firmware's report is
//! compared with (boxes and the on-board sensor checksum, bit for bit), and the program
//! callgrind counts x86 instructions in.
//!
//! ```text
//! cargo run --release --example host                       # the whole demo, one line per event
//! cargo run --release --example host -- FRAME METHOD       # one detector on one frame, once
//! cargo run --release --example host -- FRAME auto+prior   # auto, then auto tracking its box
//! cargo run --release --example host -- FRAME auto-v2+prior   # the same for auto-v2
//! cargo run --release --example host -- on-board-sensor -  # only the sensor model
//! ```
//!
//! The second form is what scripts/flight.sh runs under `valgrind --tool=callgrind
//! --toggle-collect=...Detectors::run...` (`...Detectors::track...` for `auto+prior`
//! and `auto-v2+prior`)
//! to count one call.

use std::process::ExitCode;

use tirroi_core::frame::{FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::{Frame, Method};
use tirroi_firmware::frames::FRAMES;
use tirroi_firmware::synth::Tables;
use tirroi_firmware::{BITS, Detectors, NoMeter, Workspace, run_demo, synth};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut frame = Box::new([0u16; FRAME_PIXELS]);
    let mut detectors = Box::new(Detectors::new());
    let mut tables = Box::new(Tables::new());
    let mut ws = Workspace {
        frame: &mut frame,
        detectors: &mut detectors,
        tables: &mut tables,
    };
    match args.as_slice() {
        [] => {
            let mut failed = false;
            run_demo(&mut ws, &mut NoMeter, &mut |event| {
                failed |= event.is_error();
                println!("{event}");
            });
            if failed {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            }
        }
        [frame, method] => match one(&mut ws, frame, method) {
            Ok(line) => {
                println!("{line}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("host: {e}");
                ExitCode::from(2)
            }
        },
        _ => {
            eprintln!("usage: host [FRAME METHOD]   (METHOD `-` with FRAME on-board-sensor)");
            ExitCode::from(2)
        }
    }
}

/// Loads `frame` into the workspace and runs `method` on it once.
fn one(ws: &mut Workspace<'_>, frame: &str, method: &str) -> Result<String, String> {
    if frame == synth::NAME {
        synth::setup(ws);
        synth::expose_scene(ws).map_err(|e| e.to_string())?;
        if method == "-" {
            return Ok(format!(
                "sensor checksum={:016x}",
                synth::checksum(&ws.frame[..])
            ));
        }
    } else {
        let embedded = FRAMES
            .iter()
            .find(|f| f.name == frame)
            .ok_or_else(|| format!("no embedded frame `{frame}`"))?;
        for (dn, be) in ws.frame.iter_mut().zip(embedded.be_bytes.chunks_exact(2)) {
            *dn = u16::from_be_bytes([be[0], be[1]]);
        }
    }
    let (name, tracking) = match method.strip_suffix("+prior") {
        Some(name) => (name, true),
        None => (method, false),
    };
    let method = Method::from_name(name).ok_or_else(|| format!("no method `{name}`"))?;
    let Workspace {
        frame: pixels,
        detectors,
        ..
    } = ws;
    let view =
        Frame::new(&pixels[..], FRAME_WIDTH, FRAME_HEIGHT, BITS).map_err(|e| e.to_string())?;
    let mut detection = detectors.run(method, &view).map_err(|e| e.to_string())?;
    if tracking {
        // As the firmware: the tracker again with its own box as the prior.
        let prior = detection
            .roi
            .ok_or_else(|| format!("{method} found nothing to track"))?;
        detection = detectors
            .track(method, prior, Look::measure(&view, prior), &view)
            .map_err(|e| e.to_string())?;
    }
    Ok(format!("{frame} {method} {:?}", detection.roi))
}
