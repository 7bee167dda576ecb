//! `auto-v2`'s stage-3 cascade ([`tirroi_core::roi::auto::learned::prescreen`]): what it
//! keeps of the full cell pass, reproducibly (re-run it after the forest is retrained).
//!
//! ```text
//! cargo build --release -p tirroi-host --example auto_v2_prescreen
//! target/release/examples/auto_v2_prescreen check DIR [DIR ...]
//! target/release/examples/auto_v2_prescreen dump DIR OUT.csv
//! ```
//!
//! `check` prints, per dataset directory (a `tirroi render`/`fixtures`/`testset`
//! output; the saturated cut from its manifest, as `tirroi eval`): the share of cells
//! the cascade classifies (seeds, and all), the recall of the forest's target cells
//! (cells with the full pass's code, cascade vs full), the components of target cells
//! lost (no seed), and, running the detector both ways (`AutoV2::prescreen` on and
//! off), the frames whose winner ([`AutoV2Work::winner`]) or box and confidence differ,
//! gate off and gate on, and the mean IoU against the metadata's truth box (½
//! convention; a frame without a box scores 0) and the false alarms (a box on a frame
//! without a target), off → on. `dump` writes one line per cell of every frame:
//! `frame,cx,cy,score,seed,f0..f26` (the forest's score, score units; whether the cell
//! is a seed; the features).
mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use tirroi_core::Detector;
use tirroi_core::capacity::ConstInit;
use tirroi_core::roi::auto::learned::features::FEATURES;
use tirroi_core::roi::auto::learned::{
    AutoV2, AutoV2Scratch, AutoV2Work, for_each_cell_features, forest, prescreen,
};
use tirroi_host::eval::bank::saturated_erode_px_of_dataset;
use tirroi_host::imaging::image_io::read_frame;

/// The detector's code of a cell score (`AutoV2::run`'s stage 3 at the default cell
/// threshold): 0 below it, else 1 + the quarter units of log-odds above it.
fn code_of(score: i32) -> u8 {
    let above = score - i32::from(AutoV2::default().cell_score);
    if above >= 0 {
        (1 + above / (forest::SCORE_ONE / 4)).clamp(1, 255) as u8
    } else {
        0
    }
}

/// One frame's figures.
#[derive(Default, Clone, Copy)]
struct Tally {
    frames: u32,
    cells: u64,
    seeds: u64,
    classified: u64,
    positive: u64,
    positive_kept: u64,
    components: u64,
    components_lost: u64,
    winner_changed_gate_off: u32,
    box_changed_gate_off: u32,
    box_changed_gated: u32,
    targets: u32,
    iou_off: f64,
    iou_on: f64,
    no_target: u32,
    fa_off: u32,
    fa_on: u32,
}

impl Tally {
    fn add(mut self, o: Tally) -> Tally {
        self.frames += o.frames;
        self.cells += o.cells;
        self.seeds += o.seeds;
        self.classified += o.classified;
        self.positive += o.positive;
        self.positive_kept += o.positive_kept;
        self.components += o.components;
        self.components_lost += o.components_lost;
        self.winner_changed_gate_off += o.winner_changed_gate_off;
        self.box_changed_gate_off += o.box_changed_gate_off;
        self.box_changed_gated += o.box_changed_gated;
        self.targets += o.targets;
        self.iou_off += o.iou_off;
        self.iou_on += o.iou_on;
        self.no_target += o.no_target;
        self.fa_off += o.fa_off;
        self.fa_on += o.fa_on;
        self
    }
}

/// 8-connected components of the nonzero cells of `codes` (`pw` wide): a label per
/// cell (0: none) and the count, by flood fill.
fn components(codes: &[u8], pw: usize) -> (Vec<u32>, u32) {
    let ph = codes.len() / pw;
    let mut label = vec![0u32; codes.len()];
    let mut n = 0;
    for start in 0..codes.len() {
        if codes[start] == 0 || label[start] != 0 {
            continue;
        }
        n += 1;
        label[start] = n;
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            let (x, y) = (i % pw, i / pw);
            for ny in y.saturating_sub(1)..=(y + 1).min(ph - 1) {
                for nx in x.saturating_sub(1)..=(x + 1).min(pw - 1) {
                    let j = ny * pw + nx;
                    if codes[j] != 0 && label[j] == 0 {
                        label[j] = n;
                        stack.push(j);
                    }
                }
            }
        }
    }
    (label, n)
}

fn check(dir: &Path) -> Tally {
    let erode = saturated_erode_px_of_dataset(dir).unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let list = common::frames(dir);
    list.par_iter()
        .map(|(file, bits, truth)| {
            let f = read_frame(&dir.join(file), Some(*bits)).unwrap_or_else(|e| {
                eprintln!("{}: {e}", dir.join(file).display());
                std::process::exit(2)
            });
            let frame = f.view().expect("a frame read is a valid view");
            let mut t = Tally {
                frames: 1,
                ..Tally::default()
            };
            // The full pass's codes and the seeds, from the features.
            let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
            let (mut full, mut seeds, mut pw) = (Vec::new(), Vec::new(), 0);
            for_each_cell_features(&frame, &mut work, |cx, _, feats: &[i32; FEATURES]| {
                pw = pw.max(cx + 1);
                full.push(code_of(forest::FLIGHT.score(feats)));
                seeds.push(prescreen::is_seed_features(feats));
            });
            let ph = full.len() / pw.max(1);
            let (mut codes, mut marks, mut stack) = (
                vec![0u8; full.len()],
                vec![0u8; full.len()],
                vec![0u8; 2 * full.len()],
            );
            let classified = prescreen::cascade(
                (pw, ph),
                &mut codes,
                &mut marks,
                &mut stack,
                |cx, cy| seeds[cy * pw + cx],
                |cx, cy| full[cy * pw + cx],
            );
            t.cells = full.len() as u64;
            t.seeds = seeds.iter().filter(|&&s| s).count() as u64;
            t.classified = classified as u64;
            t.positive = full.iter().filter(|&&c| c != 0).count() as u64;
            t.positive_kept = full
                .iter()
                .zip(&codes)
                .filter(|&(&a, &b)| a != 0 && a == b)
                .count() as u64;
            let (label, n) = components(&full, pw);
            t.components = u64::from(n);
            let mut kept = vec![false; n as usize + 1];
            for (i, &l) in label.iter().enumerate() {
                if l != 0 && codes[i] != 0 {
                    kept[l as usize] = true;
                }
            }
            t.components_lost = kept[1..].iter().filter(|&&k| !k).count() as u64;
            // The detector both ways, gate off and on.
            let mut scratch = Box::new(AutoV2Scratch::new());
            let mut run = |prescreen: bool, gate: bool| {
                let det = AutoV2 {
                    prescreen,
                    saturated_erode_px: erode,
                    min_score_permille: if gate {
                        AutoV2::default().min_score_permille
                    } else {
                        0
                    },
                    ..AutoV2::default()
                };
                let d = det.detect(&frame, &mut scratch).expect("valid parameters");
                (d.roi, d.score_permille, scratch.work().winner())
            };
            let (off_all, on_all) = (run(false, false), run(true, false));
            let (off, on) = (run(false, true), run(true, true));
            t.winner_changed_gate_off = u32::from(off_all.2 != on_all.2);
            t.box_changed_gate_off = u32::from(off_all.0 != on_all.0 || off_all.1 != on_all.1);
            t.box_changed_gated = u32::from(off.0 != on.0 || off.1 != on.1);
            match truth {
                Some(tr) => {
                    t.targets = 1;
                    t.iou_off = f64::from(off.0.map_or(0.0, |r| r.iou(tr)));
                    t.iou_on = f64::from(on.0.map_or(0.0, |r| r.iou(tr)));
                }
                None => {
                    t.no_target = 1;
                    t.fa_off = u32::from(off.0.is_some());
                    t.fa_on = u32::from(on.0.is_some());
                }
            }
            t
        })
        .reduce(Tally::default, Tally::add)
}

fn dump(dir: &Path, out: &Path) {
    let list = common::frames(dir);
    let lines: Vec<String> = list
        .par_iter()
        .enumerate()
        .map(|(i, (file, bits, _))| {
            let f = read_frame(&dir.join(file), Some(*bits)).unwrap_or_else(|e| {
                eprintln!("{}: {e}", dir.join(file).display());
                std::process::exit(2)
            });
            let frame = f.view().expect("a frame read is a valid view");
            let mut s = String::new();
            let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
            for_each_cell_features(&frame, &mut work, |cx, cy, feats| {
                let score = forest::FLIGHT.score(feats);
                let seed = u8::from(prescreen::is_seed_features(feats));
                let _ = write!(s, "{i},{cx},{cy},{score},{seed}");
                for v in feats {
                    let _ = write!(s, ",{v}");
                }
                s.push('\n');
            });
            s
        })
        .collect();
    let mut h = "frame,cx,cy,score,seed".to_string();
    for k in 0..FEATURES {
        let _ = write!(h, ",f{k}");
    }
    if let Err(e) = std::fs::write(out, format!("{h}\n{}", lines.concat())) {
        eprintln!("{}: {e}", out.display());
        std::process::exit(2)
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    match (args.get(1).map(String::as_str), args.len()) {
        (Some("dump"), 4) => dump(Path::new(&args[2]), Path::new(&args[3])),
        (Some("check"), n) if n >= 3 => {
            println!(
                "| dataset | frames | seeds | classified | target cells kept | components lost \
                 | winner changed (gate off) | box or confidence changed (gate off / on) \
                 | mean IoU off → on | false alarms off → on |"
            );
            println!("|---|---|---|---|---|---|---|---|---|---|");
            for d in &args[2..] {
                let dir = PathBuf::from(d);
                let t = check(&dir);
                let pct = |a: u64, b: u64| 100.0 * a as f64 / b.max(1) as f64;
                println!(
                    "| {} | {} | {:.1} % | {:.1} % | {} / {} ({:.2} %) | {} / {} | {} | {} / {} \
                     | {:.4} → {:.4} | {} → {} of {} |",
                    dir.display(),
                    t.frames,
                    pct(t.seeds, t.cells),
                    pct(t.classified, t.cells),
                    t.positive_kept,
                    t.positive,
                    pct(t.positive_kept, t.positive),
                    t.components_lost,
                    t.components,
                    t.winner_changed_gate_off,
                    t.box_changed_gate_off,
                    t.box_changed_gated,
                    t.iou_off / f64::from(t.targets.max(1)),
                    t.iou_on / f64::from(t.targets.max(1)),
                    t.fa_off,
                    t.fa_on,
                    t.no_target
                );
            }
        }
        _ => {
            eprintln!(
                "usage: auto_v2_prescreen check DIR [DIR ...] | auto_v2_prescreen dump DIR OUT.csv"
            );
            std::process::exit(2)
        }
    }
}
