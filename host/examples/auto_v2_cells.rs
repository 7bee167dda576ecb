//! Training data and predictions for `auto-v2`'s cell classifier
//! (`scripts/train-auto.py` drives it).
//!
//! `cargo run --release -p tirroi-host --example auto_v2_cells -- features DIR OUT.csv`
//! writes, for every frame of a dataset rendered with `--masks`, one line per 8×8 cell:
//! `frame,cx,cy,coverage,f0..f32` (coverage: the mean of the cell's mask values,
//! 0–255, i.e. the share of the cell covered by the target × 255; for a dataset without
//! `masks/`, e.g. `tirroi fixtures --count N --seed S`, the truth box stands for the mask).
//!
//! `... -- track-self DIR OUT.csv` is `predict` with each box then tracked: `auto-v2`
//! again with its own box as the prior (what tracking alone changes on a target that
//! does not move).
//!
//! `... -- predict DIR OUT.csv` runs `auto-v2` on every frame and writes
//! `file,x0,y0,x1,y1,score` (then the winner's statistics) for `tirroi eval
//! --predictions`; `predict-all` the same with the confidence gate off (every winner
//! boxed: the confidence model's training data; the winner's statistics end with its
//! shape, `learned::shape::WinnerShape`). Optional further arguments set
//! the cell threshold (`AutoV2::cell_score`, score units), the saturated blob's
//! cut (`AutoV2::saturated_erode_px`, px per side) and the body stage's parameters
//! (`BodyParams`: k_sigma, ring_from_cells, ring_to_cells, max_share_permille,
//! trim_permille; `k_sigma` 0 turns the stage off) and the saturated blob's rule
//! (`AutoV2::blob`: `off`, `compete` (the default) or `always`, the blob model's
//! training data; run the confidence model's `predict-all` with `off`: its winner
//! statistics are the classifier's) and the components stage 4b rates
//! (`AutoV2::candidates`, 1..=4; the confidence model's training data is the strongest
//! alone: 1) and stage 4's link between target cells (`AutoV2::link_cells`, 1..=3).
//! Every line ends with
//! the frame's largest saturated blob (`learned::blob::BlobStats`: saturated pixels,
//! solidity ‰, ring depth ‰, others ‰, sides, its confidence ‰; empty without one),
//! the blob model's training data (`scripts/train-auto.py --blob`).
//!
//! `... -- segments DIR OUT.csv` writes the straight edges of every frame
//! (`learned::frame_segments`): `file,k,x0_q,y0_q,x1_q,y1_q,dir_x,dir_y,length_q,blocks`
//! (ends in quarter pixels, the mean gradient direction × 1024, length in quarter
//! pixels, the region's 2×2 blocks).
//!
//! `... -- spots DIR OUT.csv` writes stage 5e's rated spots of every frame (whatever
//! the other stages answer; `learned::rated_spots`): one line per spot,
//! `file,k,x,y,x0,y0,x1,y1,score,f0..f16` (the spot's centre, its region's box, the
//! current forest's confidence ‰ and the features), the spot forest's training data
//! (`scripts/train-auto.py --spots`).
mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use rayon::prelude::*;
use tirroi_core::Detector;
use tirroi_core::capacity::ConstInit;
use tirroi_core::roi::auto::learned::{
    AutoV2, AutoV2Scratch, AutoV2Work, BlobRule, Stage, for_each_cell_features, frame_segments,
    rated_spots,
    segments::{self, Segment},
};
use tirroi_host::imaging::image_io::read_frame;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mode, dir, out) = (&args[1], PathBuf::from(&args[2]), PathBuf::from(&args[3]));
    // Optional: the cell threshold, score units (default: `AutoV2::default()`'s).
    let cell_score = args
        .get(4)
        .map(|v| {
            v.parse::<i16>()
                .expect("cell_score: an integer, score units")
        })
        .unwrap_or(AutoV2::default().cell_score);
    // Optional: the saturated blob's cut per side, px (default: `AutoV2::default()`'s).
    let erode = args
        .get(5)
        .map(|v| v.parse::<u8>().expect("saturated_erode_px: 0..=8"))
        .unwrap_or(AutoV2::default().saturated_erode_px);
    // Optional: the body stage's parameters (`BodyParams`): k_sigma, ring_from_cells,
    // ring_to_cells, max_share_permille, trim_permille (default: `AutoV2::default()`'s).
    let mut body = AutoV2::default().body;
    let num = |k: usize| {
        args.get(k)
            .map(|v| v.parse::<u16>().expect("body: integers"))
    };
    if let Some(v) = num(6) {
        body.k_sigma = v;
    }
    if let Some(v) = num(7) {
        body.ring_from_cells = u8::try_from(v).expect("ring_from_cells: 1..=8");
    }
    if let Some(v) = num(8) {
        body.ring_to_cells = u8::try_from(v).expect("ring_to_cells: ..=16");
    }
    if let Some(v) = num(9) {
        body.max_share_permille = v;
    }
    if let Some(v) = num(10) {
        body.trim_permille = v;
    }
    // Optional: the saturated blob's rule (default: `AutoV2::default()`'s).
    let blob = match args.get(11).map(String::as_str) {
        None => AutoV2::default().blob,
        Some("off") => BlobRule::Off,
        Some("compete") => BlobRule::Compete,
        Some("always") => BlobRule::Always,
        Some(v) => {
            eprintln!("blob rule: off, compete or always, not {v:?}");
            std::process::exit(2)
        }
    };
    // Optional: the components stage 4b rates (default: `AutoV2::default()`'s).
    let candidates = args
        .get(12)
        .map(|v| v.parse::<u8>().expect("candidates: 1..=4"))
        .unwrap_or(AutoV2::default().candidates);
    // Optional: stage 4's link between target cells, cells (default: `AutoV2::default()`'s).
    let link_cells = args
        .get(13)
        .map(|v| v.parse::<u8>().expect("link_cells: 1..=3"))
        .unwrap_or(AutoV2::default().link_cells);
    // Optional (experiments): `noscreen` classifies every cell (`AutoV2::prescreen` off).
    let prescreen = args.get(14).map(String::as_str) != Some("noscreen");
    let list = common::frames(&dir);
    let lines: Vec<String> = list
        .par_iter()
        .enumerate()
        .map(|(i, (file, bits, bbox))| {
            let f = read_frame(&dir.join(file), Some(*bits)).expect("frame");
            let frame = f.view().expect("view");
            let mut s = String::new();
            if mode == "segments" {
                let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
                let mut segs = [Segment::default(); segments::MAX_SEGMENTS];
                let n = frame_segments(&frame, &mut work, &mut segs);
                for (k, g) in segs[..n].iter().enumerate() {
                    let _ = writeln!(
                        s,
                        "{file},{k},{},{},{},{},{},{},{},{}",
                        g.x0_q, g.y0_q, g.x1_q, g.y1_q, g.dir_x, g.dir_y, g.length_q, g.blocks
                    );
                }
            } else if mode == "spots" {
                let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
                for (k, r) in rated_spots(&frame, &mut work).iter().enumerate() {
                    let Some(r) = r else { break };
                    let b = r.roi;
                    let _ = write!(
                        s,
                        "{file},{k},{},{},{},{},{},{},{}",
                        r.spot.x, r.spot.y, b.x0, b.y0, b.x1, b.y1, r.score_permille
                    );
                    for v in r.features {
                        let _ = write!(s, ",{v}");
                    }
                    s.push('\n');
                }
            } else if mode == "features" {
                let mask = read_frame(&dir.join("masks").join(file), Some(8)).ok();
                let mut work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
                for_each_cell_features(&frame, &mut work, |cx, cy, feats| {
                    let mut cov = 0u32;
                    let mut n = 0u32;
                    if let Some(m) = &mask {
                        for y in cy * 8..(cy * 8 + 8).min(m.height) {
                            for x in cx * 8..(cx * 8 + 8).min(m.width) {
                                cov += u32::from(m.pixels[y * m.width + x]);
                                n += 1;
                            }
                        }
                    } else if let Some(b) = bbox {
                        // Without masks (the test-set kinds): the truth box as the mask.
                        let xs = usize::from(b.x0)..usize::from(b.x1);
                        let ys = usize::from(b.y0)..usize::from(b.y1);
                        for y in cy * 8..cy * 8 + 8 {
                            for x in cx * 8..cx * 8 + 8 {
                                cov += if xs.contains(&x) && ys.contains(&y) {
                                    255
                                } else {
                                    0
                                };
                                n += 1;
                            }
                        }
                    }
                    let _ = write!(s, "{i},{cx},{cy},{}", cov / n.max(1));
                    for v in feats {
                        let _ = write!(s, ",{v}");
                    }
                    s.push('\n');
                });
            } else {
                let mut scratch = Box::new(AutoV2Scratch::new());
                // `predict-all`: every winner (the confidence model's training data).
                let gate_off = AutoV2 {
                    min_score_permille: if mode == "predict-all" {
                        0
                    } else {
                        AutoV2::default().min_score_permille
                    },
                    cell_score,
                    saturated_erode_px: erode,
                    body,
                    blob,
                    candidates,
                    link_cells,
                    prescreen,
                    // `predict-all`: the winner's own box (the spots do not compete), so
                    // that each row's box is the one its statistics rate.
                    spot_competes_below_permille: if mode == "predict-all" {
                        0
                    } else {
                        AutoV2::default().spot_competes_below_permille
                    },
                    // `predict-all`: nor does stage 5f's outline.
                    outline: mode != "predict-all",
                    ..AutoV2::default()
                };
                let mut d = gate_off.detect(&frame, &mut scratch).expect("detect");
                // `track-self`: the tracker given its own box as the last frame's (a
                // target that does not move: what tracking alone changes).
                if mode == "track-self" && d.roi.is_some() {
                    d = gate_off
                        .with_prior(d.roi)
                        .detect(&frame, &mut scratch)
                        .expect("detect");
                }
                match d.roi {
                    Some(r) => {
                        let _ = write!(
                            s,
                            "{file},{},{},{},{},{:.3}",
                            r.x0,
                            r.y0,
                            r.x1,
                            r.y1,
                            d.score()
                        );
                    }
                    None => {
                        let _ = write!(s, "{file},,,,,");
                    }
                }
                match scratch.work().winner() {
                    Some(w) => {
                        let _ = write!(
                            s,
                            ",{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                            w.cells,
                            w.box_w_cells,
                            w.box_h_cells,
                            w.sides,
                            w.code_sum,
                            w.code_max,
                            w.components,
                            w.runner_up_permille,
                            w.shape.perimeter_cells,
                            w.shape.contrast_code,
                            w.shape.clutter_code,
                            w.shape.edge_sides,
                            w.shape.reach_cells,
                            w.shape.spans,
                            w.shape.spread_code,
                            w.shape.step_mean_code,
                            w.shape.interior_cells,
                            w.shape.interior_step_code,
                            w.rough_permille
                        );
                    }
                    None => s.push_str(",,,,,,,,,,,,,,,,,,,"),
                }
                match scratch.work().blob() {
                    Some(b) => {
                        let _ = write!(
                            s,
                            ",{},{},{},{},{},{}",
                            b.saturated_px,
                            b.solid_permille,
                            b.ring_depth_permille,
                            b.other_permille,
                            b.sides,
                            b.score_permille()
                        );
                    }
                    None => s.push_str(",,,,,,"),
                }
                // The stage whose box this is (what the score's scale is), "none"
                // without a box.
                let stage = scratch.work().stage(d.roi).map_or("none", Stage::name);
                let _ = writeln!(s, ",{stage}");
            }
            s
        })
        .collect();
    let header = if mode == "segments" {
        "file,k,x0_q,y0_q,x1_q,y1_q,dir_x,dir_y,length_q,blocks".to_string()
    } else if mode == "spots" {
        let mut h = "file,k,x,y,x0,y0,x1,y1,score".to_string();
        for k in 0..tirroi_core::roi::auto::learned::spot::SPOT_FEATURES {
            let _ = write!(h, ",f{k}");
        }
        h
    } else if mode == "features" {
        let mut h = "frame,cx,cy,coverage".to_string();
        for k in 0..tirroi_core::roi::auto::learned::features::FEATURES {
            let _ = write!(h, ",f{k}");
        }
        h
    } else {
        "file,x0,y0,x1,y1,score,cells,box_w,box_h,sides,code_sum,code_max,components,runner_up,\
             perimeter,contrast_code,clutter_code,edge_sides,reach,spans,spread_code,step_mean_code,\
             interior_cells,interior_step_code,rough,blob_px,blob_solid,blob_ring,blob_other,blob_sides,blob_score,stage"
            .to_string()
    };
    std::fs::write(&out, format!("{header}\n{}", lines.concat())).expect("write");
}
