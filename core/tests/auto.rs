//! The `auto` detector: exact boxes on hand-built frames, tracking, memory budget,
//! parameter errors, and no-panic / box-inside-frame invariants (proptest); within a
//! work budget (`Auto::detect_within`): the full answer when the budget covers the
//! charges, never more charged than the budget, stops in stage order as the budget
//! shrinks, and the best box so far (the tracking pass's box, the winner's cells).

use proptest::prelude::*;
use tirroi_core::roi::auto::{
    self, Auto, AutoScratch, AutoStage, BudgetReport, CALL_INSTR, WorkBudget, largest_charge,
};
use tirroi_core::{DetectError, Detection, Detector, Frame, Method, Roi};

const W: usize = 328;
const H: usize = 248;

/// A 328×248 frame from `f(x, y)`.
fn frame_of(f: impl Fn(usize, usize) -> u16) -> Vec<u16> {
    (0..W * H).map(|i| f(i % W, i / W)).collect()
}

/// A 105 × 70 px box at 9000 DN on deep space (0 DN): x 120..225, y 80..150.
fn bright_box_scene(x: usize, y: usize) -> u16 {
    if (120..225).contains(&x) && (80..150).contains(&y) {
        9000
    } else {
        0
    }
}

fn detect(auto: Auto, px: &[u16]) -> Option<Roi> {
    let frame = Frame::reference(px).unwrap();
    let mut s = Box::<AutoScratch>::default();
    auto.detect(&frame, &mut s).unwrap().roi
}

/// Deterministic noise in `-amp..=amp` (a hash of the position).
fn noise(x: usize, y: usize, amp: i32) -> i32 {
    let mut h = (x as u32).wrapping_mul(0x9E37_79B1) ^ (y as u32).wrapping_mul(0x85EB_CA77);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    (h % (2 * amp as u32 + 1)) as i32 - amp
}

#[test]
fn scratch_fits_32_kib_and_is_static() {
    static SCRATCH: AutoScratch = AutoScratch::new();
    // The budget of lib.rs's memory table, at compile time and as `Method` reports it.
    const { assert!(auto::SCRATCH_BYTES <= 32 * 1024) };
    assert!(Method::Auto.scratch_bytes() <= 32 * 1024);
    assert!(size_of_val(&SCRATCH) <= 32 * 1024);
    // The exact figure of lib.rs's table, the README and `tirroi memory` (x86-64; 32-bit
    // targets save a few bytes of `usize` fields).
    #[cfg(target_pointer_width = "64")]
    {
        assert_eq!(auto::SCRATCH_BYTES, 25_456);
        assert_eq!(Method::Auto.scratch_bytes(), 25_456);
        assert_eq!(size_of_val(&SCRATCH), 25_456);
    }
    assert_eq!(Method::from_name("auto"), Some(Method::Auto));
}

#[test]
fn bright_box_on_deep_space_is_exact() {
    let px = frame_of(bright_box_scene);
    assert_eq!(
        detect(Auto::default(), &px),
        Some(Roi::new(120, 80, 225, 150))
    );
}

#[test]
fn partial_pixels_go_to_the_side_they_resemble() {
    // Target 5000 on 1000 over columns 40..80, rows 30..60; column 39 is 60 % covered
    // (in the truth box), column 80 is 30 % covered (not), row 29 is 50 % covered (in),
    // row 60 is 40 % covered (not).
    let px = frame_of(|x, y| {
        let cov_x = match x {
            39 => 0.6,
            40..=79 => 1.0,
            80 => 0.3,
            _ => 0.0,
        };
        let cov_y = match y {
            29 => 0.5,
            30..=59 => 1.0,
            60 => 0.4,
            _ => 0.0,
        };
        (1000.0 + 4000.0 * cov_x * cov_y) as u16
    });
    assert_eq!(detect(Auto::default(), &px), Some(Roi::new(39, 29, 80, 60)));
}

/// The smooth, noisy Earth below a straight limb at row 30 (deep space above it).
fn earth_only(x: usize, y: usize) -> u16 {
    let v = if y >= 30 {
        4000 + 8 * x as i32 + 6 * y as i32 + ((x as f64 / 9.0).sin() * 300.0) as i32
    } else {
        40
    };
    (v + noise(x, y, 20)).clamp(0, 16383) as u16
}

/// A dark target (500 DN) in front of [`earth_only`].
fn earth_scene(x: usize, y: usize) -> u16 {
    let target = (150..190).contains(&x) && (60..110).contains(&y)
        || (190..230).contains(&x) && (75..95).contains(&y);
    if target {
        (500 + noise(x, y, 20)) as u16
    } else {
        earth_only(x, y)
    }
}

#[test]
fn dark_target_on_textured_earth_beats_the_limb() {
    let px = frame_of(earth_scene);
    assert_eq!(
        detect(Auto::default(), &px),
        Some(Roi::new(150, 60, 230, 110))
    );
}

#[test]
fn saturated_target_drops_single_pixel_ears() {
    // Detection mode: target saturates; two partly covered pixels saturate too and
    // stick out of the truth box by one pixel (top and right).
    let px = frame_of(|x, y| {
        let body = (100..106).contains(&x) && (50..55).contains(&y);
        let ear = (x, y) == (102, 49) || (x, y) == (106, 52);
        if body || ear {
            16383
        } else {
            (300 + noise(x, y, 10)) as u16
        }
    });
    assert_eq!(
        detect(Auto::default(), &px),
        Some(Roi::new(100, 50, 106, 55))
    );
}

#[test]
fn tracking_window_gives_the_full_frame_box() {
    let px = frame_of(earth_scene);
    let full = detect(Auto::default(), &px);
    for prior in [
        Roi::new(150, 60, 230, 110),
        Roi::new(145, 58, 226, 112),
        Roi::new(155, 64, 232, 104),
    ] {
        assert_eq!(
            detect(Auto::default().with_prior(Some(prior)), &px),
            full,
            "{prior:?}"
        );
    }
}

#[test]
fn wrong_prior_falls_back_to_the_full_frame() {
    let px = frame_of(earth_scene);
    let full = detect(Auto::default(), &px);
    for prior in [
        Roi::new(10, 150, 40, 180),   // Earth only
        Roi::new(0, 0, 20, 10),       // deep space only
        Roi::new(160, 70, 180, 90),   // inside the target: it leaves the window
        Roi::new(400, 300, 500, 400), // outside the frame
        Roi::new(200, 100, 100, 50),  // empty
    ] {
        assert_eq!(
            detect(Auto::default().with_prior(Some(prior)), &px),
            full,
            "{prior:?}"
        );
    }
}

/// Frame `i` of a sequence: a dark box moving 3 px right and 1 px down per frame and
/// growing, over the textured Earth of `earth_scene`; frame 12 jumps elsewhere.
fn sequence_frame(i: usize) -> (Vec<u16>, Roi) {
    let (x0, y0) = if i == 12 {
        (40, 150)
    } else {
        (60 + 3 * i, 50 + i)
    };
    let (w, h) = (30 + i, 20 + i / 2);
    let truth = Roi::new(x0 as u16, y0 as u16, (x0 + w) as u16, (y0 + h) as u16);
    let px = frame_of(|x, y| {
        if truth.contains(x as u16, y as u16) {
            (600 + noise(x, y, 20)) as u16
        } else {
            earth_only(x, y)
        }
    });
    (px, truth)
}

#[test]
fn sequence_tracks_with_its_own_boxes_and_reacquires_after_a_jump() {
    let mut s = Box::<AutoScratch>::default();
    let mut prior = None;
    for i in 0..20 {
        let (px, truth) = sequence_frame(i);
        let frame = Frame::reference(&px).unwrap();
        let tracked = Auto::default()
            .with_prior(prior)
            .detect(&frame, &mut s)
            .unwrap()
            .roi;
        let full = Auto::default().detect(&frame, &mut s).unwrap().roi;
        assert_eq!(tracked, full, "frame {i}");
        assert_eq!(tracked, Some(truth), "frame {i}");
        prior = tracked;
    }
}

#[test]
fn flat_and_extreme_frames_find_nothing_and_do_not_panic() {
    for v in [0u16, 1, 8000, 16383, 65535] {
        let px = vec![v; W * H];
        assert_eq!(detect(Auto::default(), &px), None, "constant {v}");
    }
    let mut hot = vec![100u16; W * H];
    hot[120 * W + 200] = 16383;
    let r = detect(Auto::default(), &hot).expect("one hot pixel is a step");
    assert!(r.contains(200, 120), "{r:?}");
}

#[test]
fn bad_parameters_are_errors() {
    let frame_px = vec![0u16; W * H];
    let frame = Frame::reference(&frame_px).unwrap();
    let mut s = Box::<AutoScratch>::default();
    let bad = [
        (
            Auto {
                coarse_sigma: 0,
                ..Auto::default()
            },
            "coarse_sigma",
        ),
        (
            Auto {
                fine_sigma: 1001,
                ..Auto::default()
            },
            "fine_sigma",
        ),
        (
            Auto {
                margin_px: 329,
                ..Auto::default()
            },
            "margin_px",
        ),
    ];
    for (a, name) in bad {
        match a.detect(&frame, &mut s) {
            Err(DetectError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn small_and_odd_frames() {
    let mut s = Box::<AutoScratch>::default();
    for (w, h) in [(1, 1), (2, 3), (5, 1), (7, 9), (328, 1), (1, 248), (13, 17)] {
        let px: Vec<u16> = (0..w * h).map(|i| ((i * 7919) % 16384) as u16).collect();
        let f = Frame::new(&px, w, h, 14).unwrap();
        let d = Auto::default().detect(&f, &mut s).unwrap();
        if let Some(r) = d.roi {
            assert!(Roi::new(0, 0, w as u16, h as u16).contains_roi(&r), "{r:?}");
            assert!(!r.is_empty());
        }
    }
}

fn arb_frame() -> impl Strategy<Value = (usize, usize, u8, Vec<u16>)> {
    (1usize..=48, 1usize..=40, 1u8..=16).prop_flat_map(|(w, h, bits)| {
        (
            Just(w),
            Just(h),
            Just(bits),
            prop::collection::vec(
                prop_oneof![any::<u16>(), Just(0u16), Just(u16::MAX), 0u16..64],
                w * h,
            ),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn any_frame_and_prior_gives_a_box_inside_the_frame(
        (w, h, bits, px) in arb_frame(),
        prior in prop::option::of((0u16..400, 0u16..300, 0u16..400, 0u16..300)),
        coarse_sigma in 1u16..=40,
        fine_sigma in 1u16..=40,
    ) {
        let f = Frame::new(&px, w, h, bits).unwrap();
        let mut s = AutoScratch::new();
        let a = Auto {
            prior: prior.map(|(a, b, c, d)| Roi::new(a, b, c, d)),
            coarse_sigma,
            fine_sigma,
            ..Auto::default()
        };
        let d = a.detect(&f, &mut s).unwrap();
        if let Some(r) = d.roi {
            prop_assert!(!r.is_empty());
            prop_assert!(Roi::new(0, 0, w as u16, h as u16).contains_roi(&r), "{:?}", r);
        }
        // The same scratch again gives the same answer (no state leaks between frames).
        prop_assert_eq!(a.detect(&f, &mut s).unwrap(), d);
    }

    #[test]
    fn full_size_random_scenes_never_panic(
        seed in any::<u32>(),
        x0 in 0usize..320, y0 in 0usize..240, tw in 1usize..200, th in 1usize..200,
        bg in 0u16..16384, fg in 0u16..16384, amp in 0i32..2000,
        prior in prop::option::of((0u16..330, 0u16..250, 0u16..330, 0u16..250)),
    ) {
        let px = frame_of(|x, y| {
            let v = if (x0..x0 + tw).contains(&x) && (y0..y0 + th).contains(&y) { fg } else { bg };
            (i32::from(v) + noise(x ^ seed as usize, y, amp)).clamp(0, 16383) as u16
        });
        let f = Frame::reference(&px).unwrap();
        let mut s = Box::<AutoScratch>::default();
        let a = Auto::default().with_prior(prior.map(|(a, b, c, d)| Roi::new(a, b, c, d)));
        if let Some(r) = a.detect(&f, &mut s).unwrap().roi {
            prop_assert!(Roi::new(0, 0, 328, 248).contains_roi(&r), "{:?}", r);
        }
    }
}

// ---- within a work budget ----

fn run(auto: Auto, px: &[u16], budget: WorkBudget) -> (Detection, BudgetReport) {
    let frame = Frame::reference(px).unwrap();
    let mut s = Box::<AutoScratch>::default();
    auto.detect_within(&frame, &mut s, budget).unwrap()
}

fn detection(auto: Auto, px: &[u16]) -> Detection {
    let frame = Frame::reference(px).unwrap();
    let mut s = Box::<AutoScratch>::default();
    auto.detect(&frame, &mut s).unwrap()
}

fn stage_index(r: &BudgetReport) -> usize {
    match r.stopped {
        None => 4,
        Some(s) => s.stage as usize,
    }
}

#[test]
fn the_largest_charge_of_the_reference_frame() {
    // Worked by hand from the coefficients (core/src/roi/auto/budget.rs): call 2 000;
    // a pass: noise 17 rows x 328 x 60 + 4 000, step plane 124 x 328 x 48 + 5 084 x 40,
    // candidates 5 084 x 64 x 4, refinement 84 x 64 x 24 + 81 344 x 86.
    let pass = 17 * 328 * 60
        + 4_000
        + 124 * 328 * 48
        + 5_084 * 40
        + 5_084 * 256
        + 84 * 64 * 24
        + 81_344 * 86;
    assert_eq!(largest_charge(W, H, false), 2_000 + pass);
    assert_eq!(largest_charge(W, H, true), 2_000 + 2 * pass);
    assert_eq!(largest_charge(W, H, false), 10_922_288);
}

#[test]
fn an_unlimited_budget_gives_detects_answer() {
    let scenes: [Vec<u16>; 3] = [
        frame_of(earth_scene),
        frame_of(bright_box_scene),
        frame_of(|_, _| 700),
    ];
    for px in &scenes {
        for prior in [
            None,
            Some(Roi::new(150, 60, 230, 110)),
            Some(Roi::new(160, 70, 180, 90)),
        ] {
            let a = Auto::default().with_prior(prior);
            let (d, r) = run(a, px, WorkBudget::UNLIMITED);
            assert_eq!(d, detection(a, px), "{prior:?}");
            assert_eq!(r.stopped, None);
            assert!(r.charged > CALL_INSTR);
        }
    }
}

#[test]
fn a_ladder_of_budgets_never_overspends_and_stops_in_stage_order() {
    let px = frame_of(earth_scene);
    let a = Auto::default();
    let (full, all) = run(a, &px, WorkBudget::UNLIMITED);
    let need = all.charged;
    // Exactly the charges: the whole pipeline; one instruction less: stopped.
    let (d, r) = run(a, &px, WorkBudget::instructions(need));
    assert_eq!((d, r.stopped), (full, None));
    assert_eq!(r.charged, need);
    let (_, r) = run(a, &px, WorkBudget::instructions(need - 1));
    assert_eq!(r.stopped.map(|s| s.stage), Some(AutoStage::Refinement));
    let mut last_stage = 0;
    let mut seen = [false; 5];
    for i in 0..=200u32 {
        let b = (u64::from(need) * u64::from(i) / 200) as u32;
        let (d, r) = run(a, &px, WorkBudget::instructions(b));
        assert!(
            r.charged <= b.max(CALL_INSTR),
            "budget {b}: charged {}",
            r.charged
        );
        let stage = stage_index(&r);
        assert!(
            stage >= last_stage,
            "budget {b}: stopped earlier than a smaller budget"
        );
        last_stage = stage;
        seen[stage] = true;
        match r.stopped {
            None => assert_eq!(d, full),
            Some(s) => {
                assert!(!s.after_tracking);
                // Before the candidates there is nothing to box.
                if s.stage != AutoStage::Refinement {
                    assert_eq!(d.roi, None, "budget {b}");
                }
            }
        }
    }
    assert_eq!(
        seen, [true; 5],
        "every stop point is reached by some budget"
    );
}

#[test]
fn a_refinement_that_does_not_fit_gives_the_winners_cells() {
    let px = frame_of(earth_scene);
    let a = Auto::default();
    let (full, all) = run(a, &px, WorkBudget::UNLIMITED);
    let (d, r) = run(a, &px, WorkBudget::instructions(all.charged - 1));
    assert_eq!(r.stopped.map(|s| s.stage), Some(AutoStage::Refinement));
    let coarse = d.roi.expect("the winner's cell box");
    // 4-pixel cells of the window (the full frame here): aligned, and where the target is.
    assert_eq!((coarse.x0 % 4, coarse.y0 % 4), (0, 0), "{coarse:?}");
    let truth = full.roi.unwrap();
    assert_eq!(truth, Roi::new(150, 60, 230, 110));
    assert!(coarse.iou(&truth) >= 0.8, "{coarse:?} vs {truth:?}");
}

#[test]
fn the_tracking_pass_box_stands_when_the_full_pass_does_not_fit() {
    // A bright box on deep space, the prior over its left edge: the box found in the
    // prior's window (grown by 16 + 50 / 8 = 22 px: 88..162 × 68..162) is cut by the
    // window's right border, so the full frame is searched after it.
    let px = frame_of(bright_box_scene);
    let prior = Roi::new(110, 90, 140, 140);
    let a = Auto::default().with_prior(Some(prior));
    let (full, all) = run(a, &px, WorkBudget::UNLIMITED);
    assert_eq!(full.roi, Some(Roi::new(120, 80, 225, 150)));
    let mut found = false;
    for i in 0..=400u32 {
        let b = (u64::from(all.charged) * u64::from(i) / 400) as u32;
        let (d, r) = run(a, &px, WorkBudget::instructions(b));
        let Some(s) = r.stopped else { continue };
        if !s.after_tracking {
            continue;
        }
        found = true;
        // The tracking pass's box: over the prior, inside its window, not the full
        // frame's.
        let roi = d.roi.expect("the tracking pass's box");
        assert!(!roi.intersection(&prior).is_empty(), "{roi:?}");
        assert!(Roi::new(88, 68, 162, 162).contains_roi(&roi), "{roi:?}");
        assert_ne!(d.roi, full.roi);
    }
    assert!(
        found,
        "some budget fits the tracking pass but not the full one"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]


    #[test]
    fn any_frame_prior_and_budget_stays_within_the_budget(
        seed in any::<u32>(),
        x0 in 0usize..320, y0 in 0usize..240, tw in 1usize..200, th in 1usize..200,
        bg in 0u16..16384, fg in 0u16..16384, amp in 0i32..2000,
        prior in prop::option::of((0u16..330, 0u16..250, 0u16..330, 0u16..250)),
        budget in prop_oneof![0u32..10_000, 0u32..3_000_000, Just(u32::MAX)],
    ) {
        let px = frame_of(|x, y| {
            let v = if (x0..x0 + tw).contains(&x) && (y0..y0 + th).contains(&y) { fg } else { bg };
            (i32::from(v) + noise(x ^ seed as usize, y, amp)).clamp(0, 16383) as u16
        });
        let a = Auto::default().with_prior(prior.map(|(a, b, c, d)| Roi::new(a, b, c, d)));
        let (d, r) = run(a, &px, WorkBudget::instructions(budget));
        prop_assert!(r.charged <= budget.max(CALL_INSTR));
        if let Some(roi) = d.roi {
            prop_assert!(!roi.is_empty());
            prop_assert!(Roi::new(0, 0, 328, 248).contains_roi(&roi), "{:?}", roi);
        }
        if r.stopped.is_none() {
            prop_assert_eq!(d, detection(a, &px));
        }
        // The largest charge of the frame size covers any frame: never a stop.
        let most = largest_charge(W, H, a.prior.is_some());
        let (d_most, r_most) = run(a, &px, WorkBudget::instructions(most));
        prop_assert_eq!(r_most.stopped, None);
        prop_assert!(r_most.charged <= most);
        prop_assert_eq!(d_most, detection(a, &px));
        // Deterministic: the same budget, the same answer.
        prop_assert_eq!(run(a, &px, WorkBudget::instructions(budget)), (d, r));
    }
}
