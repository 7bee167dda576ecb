//! `tirroi demo`: every detector on the built-in procedural frames.

use std::path::Path;
use std::process::ExitCode;

use tirroi_core::{BoxRule, Method};

use super::EXIT_BAD_INPUT;
use crate::eval::bank::DetectorBank;
use crate::imaging::{fixture, overlay};

/// Runs `tirroi demo`: every detector on the procedural frames, IoU and median time.
pub fn run(repeat: usize, figures: Option<&Path>) -> ExitCode {
    if let Some(dir) = figures {
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("tirroi: error: {}: cannot create: {e}", dir.display());
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    }
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    println!(
        "tirroi demo: every detector ({}) on procedural 328x248 14-bit frames",
        names.join(", ")
    );
    println!(
        "(procedural test input, not physically rendered: `tirroi render` makes rendered frames)\n"
    );
    let mut bank = DetectorBank::default();
    println!(
        "| frame | method | box, all foreground | IoU | box, largest component | IoU | truth | median time [us] |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, spec) in fixture::standard_set() {
        let fx = fixture::render(&spec);
        let Ok(view) = fx.frame.view() else {
            eprintln!("tirroi: error: fixture {name} does not fit the core");
            return ExitCode::from(EXIT_BAD_INPUT);
        };
        let mut drawn = vec![(fx.truth, overlay::TRUTH_COLOUR)];
        for (method, colour) in Method::ALL.map(|m| (m, overlay::method_colour(m))) {
            let mut cells = Vec::new();
            let mut time_us = 0.0;
            for rule in [BoxRule::AllForeground, BoxRule::LargestComponent] {
                bank.set_box_rule(rule);
                match bank.detect_timed(method, &view, repeat) {
                    Ok((d, t)) => {
                        let iou = d.roi.map_or(0.0, |r| r.iou(&fx.truth));
                        let bbox = d
                            .roi
                            .map_or("none".into(), |r| format!("{:?}", r.to_array()));
                        cells.push(format!("{bbox} | {iou:.3}"));
                        if rule == BoxRule::AllForeground {
                            time_us = t;
                        } else if let Some(r) = d.roi {
                            drawn.push((r, colour));
                        }
                    }
                    Err(e) => {
                        eprintln!("tirroi: error: {method}: {e}");
                        return ExitCode::from(EXIT_BAD_INPUT);
                    }
                }
            }
            println!(
                "| {name} | {method} | {} | {:?} | {time_us:.1} |",
                cells.join(" | "),
                fx.truth.to_array()
            );
        }
        if let Some(dir) = figures {
            let img = overlay::frame_with_boxes(&fx.frame, &drawn, 1);
            if let Err(e) = overlay::save(&img, &dir.join(format!("demo-{name}.png"))) {
                eprintln!("tirroi: error: {e}");
                return ExitCode::from(EXIT_BAD_INPUT);
            }
        }
    }
    if let Some(dir) = figures {
        println!(
            "\nFigures: {}/demo-*.png (green: truth; largest-component boxes: red Otsu, blue adaptive, yellow WGE, magenta DoG, cyan auto).",
            dir.display()
        );
    }
    println!(
        "\nTimes are for the all-foreground rule (auto has no box rule: both columns are the same). Scratch memory per detector: `tirroi memory`."
    );
    ExitCode::SUCCESS
}
