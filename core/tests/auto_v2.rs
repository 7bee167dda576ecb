//! `auto-v2` (issue 16 part 4) under proptest: on random frames of every size and bit
//! depth and random parameters within bounds it never panics and answers `Ok`; its box
//! is non-empty and inside the frame; its confidence is in 0..=1000 ‰, at least the
//! threshold for a box and 0 for `null`; the threshold cuts exactly at the confidence
//! (`null` from one ‰ above it without a tracking prior, the same box at it); the same
//! frame gives the same answer twice, with or without a prior (and the look of the last
//! box, any or measured on the frame), in the same scratch and in a fresh one; a box of
//! the fast tracking path only with a prior and a look; a tracker's candidate only
//! under the gate and at its floor, and the same answer with the floor off; and
//! through the registry
//! (`Method::AutoV2`) it answers as called directly; the sequence tracker
//! (`roi::track::Tracker`) keeps the same invariants over three frames and answers the
//! same after a reset. Parameters out of bounds are an error, never a panic. Stage 4d's
//! limb test answers any box of any frame the same twice, `true` only for a box on the
//! frame's border, inside it and at most a quarter of it; stage 7's half-maximum cut
//! keeps any box or cuts it to one inside it holding its peak, over the Earth and over
//! deep space.
//!
//! Runs are deterministic (a fixed seed) unless `PROPTEST_RNG_SEED` says otherwise.
//! Debug builds run `auto-v2` at some 10–20 ms per full frame: the case counts keep
//! this file at a few seconds.

mod common;

use common::Rng;
use common::*;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use tirroi_core::capacity::ConstInit;
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};
use tirroi_core::roi::auto::learned::body::BodyParams;
use tirroi_core::roi::auto::learned::look::Look;
use tirroi_core::roi::auto::learned::{
    AutoV2, AutoV2Scratch, AutoV2Work, BORDER_PIECE_SCORE_PERMILLE, BlobRule,
    DEEP_SPACE_SCORE_PERMILLE, SMALL_TARGET_SCORE_PERMILLE, Stage, TRACKED_SCORE_PERMILLE,
    frame_segments, polygon, rated_spots,
    segments::{self, Segment},
};
use tirroi_core::roi::track::Tracker;
use tirroi_core::roi::{Detectors, Params};
use tirroi_core::{DetectError, Detector, Frame, Method, Roi, SCORE_FULL_PERMILLE};

/// `cases` cases from a fixed seed (unless `PROPTEST_RNG_SEED` is set).
fn config(cases: u32) -> ProptestConfig {
    let mut c = ProptestConfig::with_cases(cases);
    if c.rng_seed == RngSeed::Random {
        c.rng_seed = RngSeed::Fixed(0xA070_0002_5EED);
    }
    c.failure_persistence = None;
    c
}

/// Parameters within their documented bounds (`AutoV2::validate`), the defaults
/// weighted in.
fn params() -> impl Strategy<Value = AutoV2> {
    (
        prop_oneof![Just(8u16), 1u16..=1000],
        prop_oneof![Just(0i16), -4096i16..=4096],
        prop_oneof![Just(550u16), Just(0u16), 0u16..=1000],
        0u8..=8,
        body_params(),
        any::<bool>(),
        prop_oneof![
            Just(BlobRule::Compete),
            Just(BlobRule::Off),
            Just(BlobRule::Always)
        ],
        prior(),
        // (deep_space, sky_beside_earth)
        (any::<bool>(), any::<bool>()),
        any::<bool>(),
        prop_oneof![Just(3u8), 1u8..=4],
        // (spot, link_cells, look, candidate floor, spots compete below, outline):
        // proptest's tuples end at 12.
        (
            any::<bool>(),
            prop_oneof![Just(2u8), 1u8..=3],
            look(),
            prop_oneof![Just(None), (0u16..=1000).prop_map(Some)],
            prop_oneof![Just(800u16), 0u16..=1000],
            any::<bool>(),
        ),
    )
        .prop_map(
            |(
                fine_sigma,
                cell_score,
                min_score_permille,
                saturated_erode_px,
                body,
                prescreen,
                blob,
                prior,
                (deep_space, sky_beside_earth),
                small_target,
                candidates,
                (
                    spot,
                    link_cells,
                    look,
                    candidate_floor_permille,
                    spot_competes_below_permille,
                    outline,
                ),
            )| {
                AutoV2 {
                    prior,
                    look,
                    fine_sigma,
                    cell_score,
                    min_score_permille,
                    saturated_erode_px,
                    body,
                    prescreen,
                    blob,
                    deep_space,
                    sky_beside_earth,
                    small_target,
                    candidates,
                    spot,
                    spot_competes_below_permille,
                    outline,
                    link_cells,
                    candidate_floor_permille,
                }
            },
        )
}

/// A tracking prior: none (weighted in), or any box, also empty, reversed or off the
/// frame (it is cut to the frame; an empty result is no prior).
fn prior() -> impl Strategy<Value = Option<Roi>> {
    let any = (0u16..400, 0u16..300, 0u16..400, 0u16..300)
        .prop_map(|(x0, y0, x1, y1)| Some(Roi { x0, y0, x1, y1 }));
    prop_oneof![2 => Just(None), 1 => any]
}

/// The last frame's look of the tracked target: none (weighted in), or any, also one
/// no box could match (a departure above the bit depth) or one that tells nothing (no
/// departure). [`with_measured_look`] adds the look a tracker would carry.
fn look() -> impl Strategy<Value = Option<Look>> {
    let side = prop_oneof![Just(None), any::<u16>().prop_map(Some)];
    let any = (
        any::<u16>(),
        any::<u16>(),
        [side.clone(), side.clone(), side.clone(), side],
    )
        .prop_map(|(level_dn, ring_dn, side_dn)| {
            Some(Look {
                level_dn,
                ring_dn,
                side_dn,
            })
        });
    prop_oneof![2 => Just(None), 1 => any]
}

/// `det` with the look of its prior's box on `img` (what a tracker that found that box
/// on this frame would carry), when it has a prior.
fn with_measured_look(det: AutoV2, img: &Img) -> Option<AutoV2> {
    let look = Look::measure(&img.frame(), det.prior?)?;
    Some(det.with_look(Some(look)))
}

/// The body stage's parameters within their documented bounds (`BodyParams::is_valid`),
/// the default and the stage switched off weighted in.
fn body_params() -> impl Strategy<Value = BodyParams> {
    let any = (0u16..=100, 1u8..=8, 0u8..=16, 1u16..=1000, 0u16..=1000).prop_map(
        |(k_sigma, ring_from_cells, extra, max_share_permille, trim_permille)| BodyParams {
            k_sigma,
            ring_from_cells,
            ring_to_cells: (ring_from_cells + extra).min(16),
            max_share_permille,
            trim_permille,
        },
    );
    prop_oneof![Just(BodyParams::DEFAULT), Just(BodyParams::OFF), any]
}

/// A frame of `w × h` from `seed`: the shared generators (noise in and out of range,
/// bimodal, textured, few levels, smooth), or a bright block on a textured ramp (what
/// the classifier is meant to find).
fn frame(seed: u64, w: usize, h: usize, bits: u8) -> Img {
    let mut rng = Rng::new(seed);
    match rng.below(4) {
        0 => return shaded_sky(&mut rng, w, h, bits),
        1 | 2 => return any_frame(&mut rng, w, h, bits),
        _ => {}
    }
    let max = u64::from(max_dn(bits));
    let (bx, by) = (rng.urange(0, w - 1), rng.urange(0, h - 1));
    let (bw, bh) = (rng.urange(1, 60), rng.urange(1, 60));
    let hot = rng.below(max + 1) as u16;
    let mut img = Img::constant(w, h, bits, 0);
    for y in 0..h {
        for x in 0..w {
            let ramp = (max / 4) * (x + y) as u64 / (w + h) as u64;
            let v = if (bx..bx + bw).contains(&x) && (by..by + bh).contains(&y) {
                hot
            } else {
                (ramp + rng.below(max / 64 + 1)).min(max) as u16
            };
            *img.at(x, y) = v;
        }
    }
    img
}

/// Deep space as a camera shows it (what stage 2c takes for deep space): a pedestal,
/// a radial shading of random depth, noise, a few hot pixels and a block of random
/// contrast (none, hotter or colder than the sky), any of it clipped to the bit depth.
fn shaded_sky(rng: &mut Rng, w: usize, h: usize, bits: u8) -> Img {
    let max = u64::from(max_dn(bits));
    let pedestal = rng.below(max / 2 + 1);
    let shading = rng.below(max / 32 + 2) as f64;
    let noise = rng.below(max / 256 + 2);
    let (bx, by) = (rng.urange(0, w - 1), rng.urange(0, h - 1));
    let (bw, bh) = (rng.urange(1, 80), rng.urange(1, 80));
    let contrast = rng.below(64 * noise + 2) as i64 * if rng.below(2) == 0 { 1 } else { -1 };
    let mut img = Img::constant(w, h, bits, 0);
    for y in 0..h {
        for x in 0..w {
            let u = 2.0 * x as f64 / w as f64 - 1.0;
            let v = 2.0 * y as f64 / h as f64 - 1.0;
            let mut dn =
                pedestal as i64 + (shading * (u * u + v * v)) as i64 + rng.below(noise + 1) as i64;
            if (bx..bx + bw).contains(&x) && (by..by + bh).contains(&y) {
                dn += contrast;
            }
            if rng.below(2000) == 0 {
                dn += (max / 4) as i64;
            }
            *img.at(x, y) = dn.clamp(0, max as i64) as u16;
        }
    }
    img
}

/// Every invariant of one frame and parameter set (see the file's documentation).
fn check(img: &Img, det: AutoV2) -> Result<(), TestCaseError> {
    let f = img.frame();
    let mut scratch = Box::new(AutoV2Scratch::new());
    let d = det
        .detect(&f, &mut scratch)
        .expect("parameters within bounds");
    let candidate = scratch.work().candidate();
    prop_assert!(d.score_permille <= SCORE_FULL_PERMILLE, "{d:?}");
    match d.roi {
        Some(r) => {
            prop_assert!(!r.is_empty(), "{d:?}");
            prop_assert!(
                usize::from(r.x1) <= img.w && usize::from(r.y1) <= img.h,
                "{r:?} outside the {}x{} frame",
                img.w,
                img.h
            );
            prop_assert!(d.score_permille >= det.min_score_permille, "{d:?}");
            // The confidence is the winner's (what telemetry reads): the saturated
            // blob's when it won, else the classifier's.
            let work = scratch.work();
            let (score, stage) = if work.tracked() {
                // The fast tracking path's box: only with a prior and a look, and no
                // other stage ran.
                prop_assert!(det.prior.is_some() && det.look.is_some(), "{d:?}");
                prop_assert!(work.winner().is_none() && work.spot().is_none(), "{d:?}");
                (TRACKED_SCORE_PERMILLE, Stage::Tracked)
            } else if let Some(o) = work.outline() {
                // Stage 5f's box: the other stages' answer was none or rated lower, on
                // a whole-frame search; no other stage's telemetry.
                prop_assert!(det.outline, "{d:?}");
                prop_assert_eq!(Some(o.roi), d.roi);
                prop_assert!(work.winner().is_none() && work.spot().is_none(), "{d:?}");
                prop_assert!(!work.blob_won() && work.deep_space().is_none(), "{d:?}");
                (o.score_permille(), Stage::Outline)
            } else if let Some((roi, score)) = work.spot() {
                // Stage 5e's box: the other stages answered no target, or their box was
                // rated below `spot_competes_below_permille` and lower than the spot.
                prop_assert!(det.spot, "{d:?}");
                prop_assert_eq!(Some(roi), d.roi);
                (score, Stage::Spot)
            } else if work.blob_won() {
                prop_assert!(det.blob != BlobRule::Off, "{d:?}");
                (
                    work.blob().expect("a blob won").score_permille(),
                    Stage::Blob,
                )
            } else if work.deep_space().is_some() {
                // Stage 2c's or 2d's box (deep space): its constant confidence, no blob.
                prop_assert!(det.deep_space && work.blob().is_none(), "{d:?}");
                let score = if d.score_permille == SMALL_TARGET_SCORE_PERMILLE {
                    prop_assert!(det.small_target, "{d:?}");
                    SMALL_TARGET_SCORE_PERMILLE
                } else if d.score_permille == BORDER_PIECE_SCORE_PERMILLE {
                    // A component cut by one side of the window.
                    BORDER_PIECE_SCORE_PERMILLE
                } else {
                    DEEP_SPACE_SCORE_PERMILLE
                };
                (score, Stage::DeepSpace)
            } else {
                (
                    work.winner().expect("a box has a winner").score_permille(),
                    Stage::Classifier,
                )
            };
            prop_assert_eq!(score, d.score_permille);
            // The stage the telemetry names is the branch's.
            prop_assert_eq!(work.stage(d.roi), Some(stage), "{:?}", d);
            // The threshold at the confidence keeps the same box; one ‰ above, `null`.
            let at = AutoV2 {
                min_score_permille: d.score_permille,
                ..det
            };
            prop_assert_eq!(at.detect(&f, &mut scratch).unwrap(), d);
            // Without a prior: with one, a box gated in the tracking window sends the
            // search to the whole frame, whose winner may pass the stricter gate.
            if d.score_permille < SCORE_FULL_PERMILLE && det.prior.is_none() {
                let above = AutoV2 {
                    min_score_permille: d.score_permille + 1,
                    ..det
                };
                let n = above.detect(&f, &mut scratch).unwrap();
                prop_assert_eq!((n.roi, n.score_permille), (None, 0));
            }
        }
        None => {
            prop_assert_eq!(d.score_permille, 0, "{:?}", d);
            prop_assert_eq!(scratch.work().stage(d.roi), None);
            // Below the threshold: the winner's confidence, when there was one.
            if let Some(w) = scratch.work().winner() {
                prop_assert!(w.score_permille() < det.min_score_permille, "{w:?}");
            }
        }
    }
    // The winner's shape statistics are consistent with its cells and the frame
    // (`learned::shape`): cell sides on the frame's edge are outline, the reach stays
    // inside half the cell plane, a span joins two touched sides, interior cells are
    // cells, and without one their step code is 0.
    if let Some(w) = scratch.work().winner() {
        let sh = w.shape;
        let (pw, ph) = (img.w.div_ceil(8), img.h.div_ceil(8));
        prop_assert!(sh.edge_sides <= sh.perimeter_cells, "{w:?}");
        prop_assert_eq!(sh.edge_sides == 0, w.sides == 0, "{:?}", w);
        prop_assert!(
            usize::from(sh.reach_cells) < pw.max(ph).div_ceil(2),
            "{w:?}"
        );
        prop_assert!(
            sh.spans <= 2 && u8::from(sh.spans > 0) * 2 <= w.sides,
            "{w:?}"
        );
        prop_assert!(sh.interior_cells <= w.cells, "{w:?}");
        if sh.interior_cells == 0 {
            prop_assert_eq!(sh.interior_step_code, 0);
        }
        let feats = w.confidence_features();
        prop_assert!(feats.iter().all(|&v| v > -2000 && v <= 16_000), "{feats:?}");
    }
    // A tracker's candidate under the gate: only with a floor, without a box, in
    // [floor, gate), inside the frame; and the floor does not change the answer.
    if let Some((r, score)) = candidate {
        let floor = det.candidate_floor_permille;
        prop_assert!(
            d.roi.is_none() && floor.is_some_and(|f| score >= f),
            "{d:?} {r:?} {score}"
        );
        prop_assert!(score < det.min_score_permille, "{r:?} {score}");
        prop_assert!(!r.is_empty() && usize::from(r.x1) <= img.w && usize::from(r.y1) <= img.h);
    }
    let no_floor = AutoV2 {
        candidate_floor_permille: None,
        ..det
    };
    prop_assert_eq!(no_floor.detect(&f, &mut scratch).unwrap(), d);
    prop_assert_eq!(scratch.work().candidate(), None);
    // Same answer twice: the same scratch, a fresh one, and through the registry.
    prop_assert_eq!(det.detect(&f, &mut scratch).unwrap(), d);
    prop_assert_eq!(det.detect(&f, &mut AutoV2Scratch::new()).unwrap(), d);
    let mut bank = Box::new(Detectors::new());
    prop_assert_eq!(bank.detect(&Params::AutoV2(det), &f).unwrap(), d);
    Ok(())
}

proptest! {
    #![proptest_config(config(64))]

    /// Shaded skies of about the full size (stage 2c's ground: many blocks to fit).
    #[test]
    fn shaded_skies_keep_every_invariant(
        w in 200usize..=FRAME_WIDTH,
        h in 150usize..=FRAME_HEIGHT,
        bits in prop_oneof![Just(14u8), 8u8..=16],
        seed in any::<u64>(),
        det in params(),
    ) {
        let img = shaded_sky(&mut Rng::new(seed), w, h, bits);
        check(&img, det)?;
        if let Some(tracked) = with_measured_look(det, &img) {
            check(&img, tracked)?;
        }
    }
}

proptest! {
    #![proptest_config(config(96))]

    /// Small frames (1..=40 a side: fewer cells than any window of the features).
    #[test]
    fn small_frames_keep_every_invariant(
        w in 1usize..=40,
        h in 1usize..=40,
        bits in 1u8..=16,
        seed in any::<u64>(),
        det in params(),
    ) {
        let img = frame(seed, w, h, bits);
        check(&img, det)?;
        if let Some(tracked) = with_measured_look(det, &img) {
            check(&img, tracked)?;
        }
    }
}

proptest! {
    #![proptest_config(config(24))]

    /// Any size the core accepts, up to the full 328×248.
    #[test]
    fn frames_of_any_size_keep_every_invariant(
        w in 1usize..=FRAME_WIDTH,
        h in 1usize..=FRAME_HEIGHT,
        bits in prop_oneof![Just(14u8), 1u8..=16],
        seed in any::<u64>(),
        det in params(),
    ) {
        let img = frame(seed, w, h, bits);
        check(&img, det)?;
        if let Some(tracked) = with_measured_look(det, &img) {
            check(&img, tracked)?;
        }
    }

    /// Parameters out of bounds: an error naming the field, never a panic, on any frame.
    #[test]
    fn parameters_out_of_bounds_are_errors(
        which in 0u8..10,
        seed in any::<u64>(),
    ) {
        let img = frame(seed, 64, 48, 14);
        let bad = match which {
            8 => AutoV2 { spot_competes_below_permille: 1001, ..AutoV2::default() },
            0 => AutoV2 { fine_sigma: 0, ..AutoV2::default() },
            1 => AutoV2 { cell_score: 4097, ..AutoV2::default() },
            2 => AutoV2 { min_score_permille: 1001, ..AutoV2::default() },
            3 => AutoV2 { candidates: 0, ..AutoV2::default() },
            4 => AutoV2 { candidates: 5, ..AutoV2::default() },
            5 => AutoV2 { link_cells: 0, ..AutoV2::default() },
            6 => AutoV2 { link_cells: 4, ..AutoV2::default() },
            7 => AutoV2 { candidate_floor_permille: Some(1001), ..AutoV2::default() },
            _ => AutoV2 { saturated_erode_px: 9, ..AutoV2::default() },
        };
        let got = bad.detect(&img.frame(), &mut Box::new(AutoV2Scratch::new()));
        let is_invalid = matches!(got, Err(DetectError::InvalidParameter { .. }));
        prop_assert!(is_invalid, "{:?}", got);
    }
}

/// The registry entry: name, defaults, and the full-frame box of a bright block on a
/// dark textured background found with a confidence above the default threshold.
#[test]
fn registry_entry_is_auto_v2_with_its_defaults() {
    assert_eq!(Method::from_name("auto-v2"), Some(Method::AutoV2));
    assert_eq!(
        Method::AutoV2.default_params(),
        Params::AutoV2(AutoV2::default())
    );
    assert_eq!(
        Method::AutoV2.scratch_bytes(),
        tirroi_core::roi::auto::learned::SCRATCH_BYTES
    );
    let px: Vec<u16> = (0..FRAME_WIDTH * FRAME_HEIGHT)
        .map(|i| {
            let (x, y) = (i % FRAME_WIDTH, i / FRAME_WIDTH);
            if (140..180).contains(&x) && (100..130).contains(&y) {
                9000
            } else {
                1000 + ((x * 7 + y * 13) % 11) as u16
            }
        })
        .collect();
    let f = Frame::new(&px, FRAME_WIDTH, FRAME_HEIGHT, 14).unwrap();
    let mut bank = Box::new(Detectors::new());
    let d = bank.detect_default(Method::AutoV2, &f).unwrap();
    let want = tirroi_core::Roi::new(140, 100, 180, 130);
    let r = d.roi.expect("a bright block on a dark background");
    assert!(r.iou(&want) >= 0.9, "{r:?} vs {want:?}");
    assert!(
        d.score_permille >= AutoV2::default().min_score_permille,
        "{d:?}"
    );
}

/// The core's sequence tracker (`roi::track::Tracker`) over `img` and two copies of it
/// moved by `step` px along x per frame (the ground's registration and the candidate's
/// run see motion): every step answers `Ok`; a box lies inside the frame with a
/// confidence in range and at the gate, `null` scores 0; the tracker's prior is its
/// last answer; the same sequence again after `reset` gives the same answers.
fn check_tracker(img: &Img, det: AutoV2, step: usize) -> Result<(), TestCaseError> {
    let frames: Vec<Vec<u16>> = (0..3)
        .map(|k| {
            (0..img.w * img.h)
                .map(|i| {
                    let (x, y) = (i % img.w, i / img.w);
                    img.px[y * img.w + (x + k * step) % img.w]
                })
                .collect()
        })
        .collect();
    let mut scratch = Box::new(AutoV2Scratch::new());
    let mut tracker = Tracker::new(det);
    let mut answers = Vec::new();
    for px in &frames {
        let f = Frame::new(px, img.w, img.h, img.bits).unwrap();
        let d = tracker
            .step(&f, &mut scratch)
            .expect("parameters within bounds");
        prop_assert!(d.score_permille <= SCORE_FULL_PERMILLE, "{d:?}");
        match d.roi {
            Some(r) => {
                prop_assert!(!r.is_empty(), "{d:?}");
                prop_assert!(
                    usize::from(r.x1) <= img.w && usize::from(r.y1) <= img.h,
                    "{d:?}"
                );
                prop_assert!(d.score_permille >= det.min_score_permille, "{d:?}");
            }
            None => prop_assert_eq!(d.score_permille, 0),
        }
        prop_assert_eq!(tracker.prior(), d.roi);
        answers.push(d);
    }
    tracker.reset();
    for (px, d) in frames.iter().zip(&answers) {
        let f = Frame::new(px, img.w, img.h, img.bits).unwrap();
        prop_assert_eq!(tracker.step(&f, &mut scratch).unwrap(), *d);
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(24))]

    /// The tracker on random frames of about the full size and on shaded skies.
    #[test]
    fn tracker_steps_keep_every_invariant(
        w in 100usize..=FRAME_WIDTH,
        h in 80usize..=FRAME_HEIGHT,
        bits in prop_oneof![Just(14u8), 8u8..=16],
        seed in any::<u64>(),
        sky in any::<bool>(),
        step in 0usize..6,
        det in params(),
    ) {
        let img = if sky {
            shaded_sky(&mut Rng::new(seed), w, h, bits)
        } else {
            frame(seed, w, h, bits)
        };
        check_tracker(&img, det, step)?;
    }
}

proptest! {
    #![proptest_config(config(64))]

    /// Stage 4d's limb test (`learned::limb::is_limb`) on any frame and any box, inside
    /// the frame or not: no panic, the same answer twice, and `false` for a box off the
    /// frame's border, over a quarter of the frame or reaching beyond it.
    #[test]
    fn limb_test_answers_for_any_box(
        seed in any::<u64>(),
        w in 8usize..=FRAME_WIDTH,
        h in 8usize..=FRAME_HEIGHT,
        bits in 1u8..=16,
        corners in (0u16..400, 0u16..300, 0u16..400, 0u16..300),
    ) {
        use tirroi_core::roi::auto::learned::limb::is_limb;
        let img = frame(seed, w, h, bits);
        let f = img.frame();
        let (a, b, c, d) = corners;
        let r = Roi { x0: a.min(c), y0: b.min(d), x1: a.max(c), y1: b.max(d) };
        let answer = is_limb(&f, r);
        prop_assert_eq!(answer, is_limb(&f, r));
        let (x0, y0, x1, y1) =
            (usize::from(r.x0), usize::from(r.y0), usize::from(r.x1), usize::from(r.y1));
        let on_border = x0 == 0 || y0 == 0 || x1 == w || y1 == h;
        let inside = x1 <= w && y1 <= h;
        let small = (x1 - x0) * (y1 - y0) * 4 <= w * h;
        if answer {
            prop_assert!(on_border && inside && small, "{r:?} in {w}x{h}");
        }
    }
}

proptest! {
    #![proptest_config(config(256))]

    /// Stage 7's half-maximum cut (`learned::half_max::half_max_box`) on any frame and
    /// any box, over the Earth and over deep space: no panic, the same answer twice, the
    /// box unchanged or cut to a box inside it that holds the pixel departing most from
    /// the ring's median (the ring collected and sorted here, by brute force). The boxes
    /// lie around the frame's brightest pixel, some beyond the frame; about a third are
    /// cut.
    #[test]
    fn half_max_cuts_inside_the_box_around_its_peak(
        seed in any::<u64>(),
        w in 8usize..=FRAME_WIDTH,
        h in 8usize..=FRAME_HEIGHT,
        bits in 1u8..=16,
        before in (0u16..24, 0u16..24),
        after in (0u16..24, 0u16..24),
        sigma in 1u32..8,
        deep_space in any::<bool>(),
    ) {
        use tirroi_core::roi::auto::learned::half_max::{Background, half_max_box};
        let img = frame(seed, w, h, bits);
        let f = img.frame();
        // A box around the frame's brightest pixel (its block, or a hot pixel), so
        // that most boxes are cut.
        let top = (0..w * h).max_by_key(|&i| img.px[i]).unwrap_or(0);
        let (mx, my) = ((top % w) as u16, (top / w) as u16);
        let r = Roi {
            x0: mx.saturating_sub(before.0),
            y0: my.saturating_sub(before.1),
            x1: mx + 1 + after.0,
            y1: my + 1 + after.1,
        };
        let background = if deep_space { Background::DeepSpace } else { Background::Cluttered };
        let dn = |x: i64, y: i64| i64::from(img.px[y as usize * w + x as usize]);
        let cut = half_max_box(&f, r, sigma, background);
        prop_assert_eq!(cut, half_max_box(&f, r, sigma, background));
        if cut == r {
            return Ok(());
        }
        prop_assert!(
            cut.x0 >= r.x0 && cut.y0 >= r.y0 && cut.x1 <= r.x1 && cut.y1 <= r.y1
                && cut.x0 < cut.x1 && cut.y0 < cut.y1,
            "{cut:?} from {r:?}"
        );
        // The ring: the pixels of the frame just around `r`, outside it.
        let (x0, y0, x1, y1) =
            (i64::from(r.x0), i64::from(r.y0), i64::from(r.x1), i64::from(r.y1));
        let mut ring = Vec::new();
        for y in y0 - 1..=y1 {
            for x in x0 - 1..=x1 {
                let inside = x >= x0 && x < x1 && y >= y0 && y < y1;
                let in_frame = x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h;
                if !inside && in_frame {
                    ring.push(dn(x, y));
                }
            }
        }
        ring.sort_unstable();
        let bg = ring[ring.len() / 2];
        let peak = (r.y0..r.y1.min(h as u16))
            .flat_map(|y| (r.x0..r.x1.min(w as u16)).map(move |x| (x, y)))
            .map(|(x, y)| (dn(i64::from(x), i64::from(y)) - bg).abs())
            .max()
            .unwrap_or(0);
        let held = (cut.y0..cut.y1).any(|y| {
            (cut.x0..cut.x1)
                .any(|x| (dn(i64::from(x), i64::from(y)) - bg).abs() == peak)
        });
        prop_assert!(held, "{cut:?} from {r:?}: no pixel of the peak departure {peak}");
    }
}

/// Stage 5e competing with a weak answer (`AutoV2::spot_competes_below_permille`),
/// against its rule built from parts: the answer without competition (0), and the
/// frame's rated spots from `learned::rated_spots` (the stage's own rating, called on
/// its own). With competition at 1000 the answer is the most confident spot (its box
/// and P) where that is rated above the other stages' box, else that box unchanged; a
/// frame without a box keeps stage 5e's usual answer. Both branches occur on the
/// frames drawn.
#[test]
fn spots_replace_a_weaker_answer_and_only_that() {
    let mut scratch = Box::new(AutoV2Scratch::new());
    let mut spot_work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
    let (mut replaced, mut kept) = (0, 0);
    for seed in 0..160u64 {
        let (w, h) = (96 + (seed as usize % 5) * 40, 72 + (seed as usize % 3) * 40);
        let mut img = frame(seed, w, h, 14);
        // A small target, a 3×3 block a quarter of the 14-bit range above what lies
        // there, where a box of the other stages may or may not be.
        let (sx, sy) = (
            8 + (seed as usize * 37) % (w - 16),
            8 + (seed as usize * 53) % (h - 16),
        );
        for y in sy..sy + 3 {
            for x in sx..sx + 3 {
                let v = img.at(x, y);
                *v = v.saturating_add(4096).min(16_383);
            }
        }
        let f = img.frame();
        // The gate open (the rule holds at any gate; synthetic frames' spots are rated
        // low by a forest trained on renders, so open it is where both branches occur).
        let alone = AutoV2 {
            spot_competes_below_permille: 0,
            min_score_permille: 0,
            outline: false,
            ..AutoV2::default()
        };
        let competing = AutoV2 {
            spot_competes_below_permille: 1000,
            ..alone
        };
        let before = alone.detect(&f, &mut scratch).unwrap();
        let after = competing.detect(&f, &mut scratch).unwrap();
        let best = rated_spots(&f, &mut spot_work).into_iter().flatten().fold(
            None::<(Roi, u16)>,
            |b, r| match b {
                Some((_, s)) if s >= r.score_permille => b,
                _ => Some((r.roi, r.score_permille)),
            },
        );
        match (before.roi, best) {
            (Some(_), Some((roi, score))) if score > before.score_permille => {
                assert_eq!(
                    (after.roi, after.score_permille),
                    (Some(roi), score),
                    "seed {seed}"
                );
                replaced += 1;
            }
            _ => {
                assert_eq!(after, before, "seed {seed}");
                kept += usize::from(before.roi.is_some());
            }
        }
    }
    assert!(replaced > 0 && kept > 0, "replaced {replaced}, kept {kept}");
}

/// A region answer rated at or above `spot_competes_below_permille` stands against the
/// spots under the gate too, so a gate one ‰ above it gives "no target", never a spot:
/// the gate decides whether the answer is given, not which. The fuzz target's input
/// `crash-389043c4` (session 60): a 256 × 89 frame of a 4-pixel period (3, 0, 0, 16 384
/// DN at 9 bits), the saturated blob always rated (`BlobRule::Always`) at 0 ‰ with
/// competition off (0); before the fix a gate of 1 ‰ gave stage 5e's spot at 46 ‰.
#[test]
fn a_stricter_gate_never_brings_up_a_spot() {
    let (w, h) = (256, 89);
    let period = [3u16, 0, 0, 16_384];
    let img = Img {
        px: (0..w * h).map(|i| period[i % period.len()]).collect(),
        w,
        h,
        bits: 9,
    };
    let det = AutoV2 {
        fine_sigma: 39,
        cell_score: 2903,
        min_score_permille: 0,
        saturated_erode_px: 2,
        body: BodyParams::OFF,
        prescreen: false,
        deep_space: false,
        sky_beside_earth: false,
        small_target: true,
        blob: BlobRule::Always,
        candidates: 2,
        spot: true,
        spot_competes_below_permille: 0,
        outline: false,
        link_cells: 1,
        ..AutoV2::default()
    };
    let mut scratch = Box::new(AutoV2Scratch::new());
    let d = det.detect(&img.frame(), &mut scratch).unwrap();
    assert!(d.roi.is_some() && scratch.work().blob_won(), "{d:?}");
    assert_eq!(d.score_permille, 0, "{d:?}");
    check(&img, det).unwrap();
    // Every gate above the blob's rating: "no target" (the spots do not compete).
    for gate in [1, 46, 550] {
        let stricter = AutoV2 {
            min_score_permille: gate,
            ..det
        };
        let n = stricter.detect(&img.frame(), &mut scratch).unwrap();
        assert_eq!((n.roi, n.score_permille), (None, 0), "gate {gate}");
        assert_eq!(scratch.work().spot(), None, "gate {gate}");
    }
}

/// Stage 5f, the straight outline (`AutoV2::outline`), against its rule built from
/// parts: the answer without it (`outline: false`), and the frame's outline from
/// `learned::frame_segments` and `polygon::strongest` (the stage's own parts, called
/// on their own). On a whole-frame search the outline's box and its confidence are the
/// answer exactly when there is an outline and the other stages' answer is "no target"
/// or rated below it (the default gate is under both of its ratings) and is not stage
/// 2c's box over deep space; else their answer stands.
/// A dark quadrilateral drawn on half the frames gives both branches.
#[test]
fn an_outline_replaces_a_weaker_answer_and_only_that() {
    let mut scratch = Box::new(AutoV2Scratch::new());
    let mut part_work: Box<AutoV2Work> = Box::new(ConstInit::INIT);
    let (mut replaced, mut kept) = (0, 0);
    for seed in 0..120u64 {
        let (w, h) = (
            120 + (seed as usize % 4) * 40,
            96 + (seed as usize % 3) * 32,
        );
        let mut img = frame(seed, w, h, 14);
        if seed % 2 == 0 {
            // A dark parallelogram (sides 40 and 26 px, slanted 1 px in 4) at a tenth of
            // the range: straight edges meeting at corners.
            let (ox, oy) = (
                10 + (seed as usize * 7) % (w - 70),
                10 + (seed as usize * 5) % (h - 40),
            );
            for y in 0..26 {
                for x in 0..40 {
                    let v = img.at(ox + x + y / 4, oy + y);
                    *v = 1600;
                }
            }
        }
        let f = img.frame();
        let without = AutoV2 {
            outline: false,
            ..AutoV2::default()
        };
        let before = without.detect(&f, &mut scratch).unwrap();
        // Where stage 2c boxed a target over deep space (above the gate or not), its
        // answer stands.
        let deep_space_box = scratch.work().deep_space().is_some();
        let after = AutoV2::default().detect(&f, &mut scratch).unwrap();
        let mut segs = [Segment::default(); segments::MAX_SEGMENTS];
        let n = frame_segments(&f, &mut part_work, &mut segs);
        let outline = polygon::strongest(&segs[..n], w, h);
        let weaker = |o: polygon::Outline| {
            before.roi.is_none() || before.score_permille < o.score_permille()
        };
        match outline {
            Some(o) if weaker(o) && !deep_space_box => {
                assert_eq!(
                    (after.roi, after.score_permille),
                    (Some(o.roi), o.score_permille()),
                    "seed {seed}"
                );
                assert_eq!(scratch.work().outline(), Some(o), "seed {seed}");
                assert_eq!(
                    scratch.work().stage(after.roi),
                    Some(Stage::Outline),
                    "seed {seed}"
                );
                replaced += 1;
            }
            _ => {
                assert_eq!(after, before, "seed {seed}");
                assert_eq!(scratch.work().outline(), None, "seed {seed}");
                assert_ne!(
                    scratch.work().stage(after.roi),
                    Some(Stage::Outline),
                    "seed {seed}"
                );
                kept += 1;
            }
        }
    }
    assert!(replaced > 0 && kept > 0, "replaced {replaced}, kept {kept}");
}
