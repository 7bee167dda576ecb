//! How target-like a dataset's background is to `auto-v2`'s cell classifier, by the
//! strength of its edges: on the frames without a target, each 8×8 cell's largest
//! two-pixel step in units of the frame's pixel noise σ (the classifier's feature 3,
//! `learned::features`: the log code of 4 · step / σ, binned back to σ) and whether the
//! flight forest scores the cell as a target (score ≥ the default cell threshold).
//!
//! A realism check of a rendered background against a real one (issue 16, session 37):
//! the real satellite image's windows (`tirroi testset --kind real-earth`) against the
//! `realistic` world's Earth-filled frames without a target; where the real Earth's
//! strong steps are rare and a third of them score as targets, ours are many and rarely
//! do (`docs/detectors.md` § Session 37).
//!
//! `cargo run --release -p tirroi-host --example clutter_steps -- DIR [DIR ...]
//! [--earth-min F] [--mode radiometry|detection]` prints one Markdown table per
//! dataset (frames without a target; with `--earth-min`, only those whose metadata's
//! `earth_fraction` reaches F; with `--mode`, only that readout mode), and the median
//! ratio of the detector's noise σ to the renderer's noise at the camera's NETD.
mod common;

use std::path::PathBuf;

use rayon::prelude::*;
use tirroi_core::capacity::ConstInit;
use tirroi_core::roi::auto::learned::features::log_code;
use tirroi_core::roi::auto::learned::{AutoV2, AutoV2Work, for_each_cell_features, forest};
use tirroi_host::imaging::image_io::read_frame;

/// Upper ends of the step bins, σ (the last bin is open).
const BIN_ENDS_SIGMA: [u32; 4] = [10, 20, 40, 80];

/// The classifier's feature holding the cell's largest two-pixel step (log code of
/// 4 · step / σ).
const STEP_FEATURE: usize = 3;

fn main() {
    let mut dirs = Vec::new();
    let mut earth_min: Option<f64> = None;
    let mut mode: Option<String> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--earth-min" => {
                earth_min = args.next().and_then(|v| v.parse().ok());
                if earth_min.is_none() {
                    eprintln!("--earth-min: a number 0..=1");
                    std::process::exit(2)
                }
            }
            "--mode" => mode = args.next(),
            _ => dirs.push(PathBuf::from(a)),
        }
    }
    if dirs.is_empty() {
        eprintln!(
            "usage: clutter_steps DIR [DIR ...] [--earth-min F] [--mode radiometry|detection]"
        );
        std::process::exit(2)
    }
    // A step of S σ has the code log_code(4 · S); a cell falls in the first bin whose
    // end code it stays below.
    let ends: Vec<i32> = BIN_ENDS_SIGMA.iter().map(|&s| log_code(4 * s)).collect();
    let floor = i32::from(AutoV2::default().cell_score);
    for dir in dirs {
        let meta = common::metadata(&dir);
        let list = common::frames(&dir);
        // Each kept frame with its rendered noise σ at the NETD (`noise_sigma_dn`).
        let kept: Vec<_> = list
            .iter()
            .zip(&meta)
            .filter(|((_, _, bbox), m)| {
                bbox.is_none()
                    && earth_min.is_none_or(|e| m["earth_fraction"].as_f64().unwrap_or(0.0) >= e)
                    && mode
                        .as_deref()
                        .is_none_or(|md| m["mode"].as_str() == Some(md))
            })
            .map(|(e, m)| (e.clone(), m["noise_sigma_dn"].as_f64().filter(|&v| v > 0.0)))
            .collect();
        let per_frame: Vec<_> = kept
            .par_iter()
            .map(|((file, bits, _), netd_sigma)| {
                let f = read_frame(&dir.join(file), Some(*bits)).unwrap_or_else(|e| {
                    eprintln!("{}: {e}", dir.join(file).display());
                    std::process::exit(2)
                });
                let frame = f.view().expect("a frame within the capacity");
                let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
                let mut c = [[0u64; 2]; BIN_ENDS_SIGMA.len() + 1];
                let sigma = for_each_cell_features(&frame, &mut work, |_, _, feats| {
                    let bin = ends
                        .iter()
                        .position(|&e| feats[STEP_FEATURE] < e)
                        .unwrap_or(ends.len());
                    c[bin][0] += 1;
                    c[bin][1] += u64::from(forest::FLIGHT.score(feats) >= floor);
                });
                (c, netd_sigma.map(|n| f64::from(sigma) / n))
            })
            .collect();
        let mut counts = [[0u64; 2]; BIN_ENDS_SIGMA.len() + 1];
        for (c, _) in &per_frame {
            for (x, y) in counts.iter_mut().zip(c) {
                x[0] += y[0];
                x[1] += y[1];
            }
        }
        // The detector's noise σ over the renderer's noise σ at the camera's NETD (the
        // metadata's `noise_sigma_dn`): above 1 where the camera's signature or the
        // scene's texture raise the estimate.
        let mut ratios: Vec<f64> = per_frame.iter().filter_map(|(_, r)| *r).collect();
        ratios.sort_by(f64::total_cmp);
        let median_ratio = ratios.get(ratios.len() / 2).copied();
        let cells: u64 = counts.iter().map(|c| c[0]).sum();
        let targets: u64 = counts.iter().map(|c| c[1]).sum();
        println!(
            "\n{} ({} frames without a target, {cells} cells, {targets} scored as target)\n",
            dir.display(),
            kept.len()
        );
        if let Some(r) = median_ratio {
            println!("the detector's noise σ / the NETD noise σ: {r:.2} (median)\n");
        }
        println!("| largest 2-px step | cells | of them scored as target |");
        println!("|---|---|---|");
        for (k, c) in counts.iter().enumerate() {
            let from = if k == 0 { 0 } else { BIN_ENDS_SIGMA[k - 1] };
            let label = BIN_ENDS_SIGMA
                .get(k)
                .map_or(format!("≥ {from} σ"), |to| format!("{from}–{to} σ"));
            let share = |n: u64, d: u64| 100.0 * n as f64 / d.max(1) as f64;
            println!(
                "| {label} | {:.2} % | {:.2} % ({} of {}) |",
                share(c[0], cells),
                share(c[1], c[0]),
                c[1],
                c[0]
            );
        }
    }
}
