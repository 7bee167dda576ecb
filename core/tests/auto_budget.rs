//! `auto` within a work budget (`Auto::detect_within`): the full answer when the budget
//! covers the charges, never more charged than the budget, stops in stage order as the
//! budget shrinks, and the best box so far (the tracking pass's box, the winner's cells)
//! when it stops.

use proptest::prelude::*;
use tirroi_core::roi::auto::{
    Auto, AutoScratch, AutoStage, BudgetReport, CALL_INSTR, WorkBudget, largest_charge,
};
use tirroi_core::{Detection, Detector, Frame, Roi};

const W: usize = 328;
const H: usize = 248;

fn frame_of(f: impl Fn(usize, usize) -> u16) -> Vec<u16> {
    (0..W * H).map(|i| f(i % W, i / W)).collect()
}

/// Deterministic noise in `-amp..=amp` (a hash of the position).
fn noise(x: usize, y: usize, amp: i32) -> i32 {
    let mut h = (x as u32).wrapping_mul(0x9E37_79B1) ^ (y as u32).wrapping_mul(0x85EB_CA77);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    (h % (2 * amp as u32 + 1)) as i32 - amp
}

/// A dark target (150..230 × 60..110, two boxes) on a smooth noisy Earth below a limb
/// at row 30 (as in tests/auto.rs).
fn earth_scene(x: usize, y: usize) -> u16 {
    let target = (150..190).contains(&x) && (60..110).contains(&y)
        || (190..230).contains(&x) && (75..95).contains(&y);
    let v = if target {
        500
    } else if y >= 30 {
        4000 + 8 * x as i32 + 6 * y as i32 + ((x as f64 / 9.0).sin() * 300.0) as i32
    } else {
        40
    };
    (v + noise(x, y, 20)).clamp(0, 16383) as u16
}

fn run(auto: Auto, px: &[u16], budget: WorkBudget) -> (Detection, BudgetReport) {
    let frame = Frame::reference(px).unwrap();
    let mut s = Box::<AutoScratch>::default();
    auto.detect_within(&frame, &mut s, budget).unwrap()
}

fn detect(auto: Auto, px: &[u16]) -> Detection {
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
    // candidates 5 084 x 64 x 4, refinement 84 x 64 x 24 + 81 344 x 40.
    let pass = 17 * 328 * 60
        + 4_000
        + 124 * 328 * 48
        + 5_084 * 40
        + 5_084 * 256
        + 84 * 64 * 24
        + 81_344 * 40;
    assert_eq!(largest_charge(W, H, false), 2_000 + pass);
    assert_eq!(largest_charge(W, H, true), 2_000 + 2 * pass);
    assert_eq!(largest_charge(W, H, false), 7_180_464);
}

#[test]
fn an_unlimited_budget_gives_detects_answer() {
    let scenes: [Vec<u16>; 3] = [
        frame_of(earth_scene),
        frame_of(|x, y| {
            if (120..225).contains(&x) && (80..150).contains(&y) {
                9000
            } else {
                0
            }
        }),
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
            assert_eq!(d, detect(a, px), "{prior:?}");
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
    let px = frame_of(|x, y| {
        if (120..225).contains(&x) && (80..150).contains(&y) {
            9000
        } else {
            0
        }
    });
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
            prop_assert_eq!(d, detect(a, &px));
        }
        // The largest charge of the frame size covers any frame: never a stop.
        let most = largest_charge(W, H, a.prior.is_some());
        let (d_most, r_most) = run(a, &px, WorkBudget::instructions(most));
        prop_assert_eq!(r_most.stopped, None);
        prop_assert!(r_most.charged <= most);
        prop_assert_eq!(d_most, detect(a, &px));
        // Deterministic: the same budget, the same answer.
        prop_assert_eq!(run(a, &px, WorkBudget::instructions(budget)), (d, r));
    }
}
