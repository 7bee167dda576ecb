//! The detectors through the public API, against brute-force references of the
//! semantics their module documentation states (see `common`).

mod common;

use common::*;
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH, FrameError};
use tirroi_core::roi::adaptive::{self, Adaptive};
use tirroi_core::roi::dog::{self, Dog};
use tirroi_core::roi::otsu::{self, Otsu};
use tirroi_core::roi::wge::{self, Wge};
use tirroi_core::roi::{RoiBuilder, Scratch};
use tirroi_core::{BoxRule, DetectError, Detector, Frame, Method, Roi};

const W: usize = FRAME_WIDTH;
const H: usize = FRAME_HEIGHT;

/// Asserts two masks are equal, reporting how many pixels differ and the first one.
#[track_caller]
fn assert_same_mask(got: &[bool], want: &[bool], w: usize, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: mask length");
    let diff: Vec<usize> = (0..got.len()).filter(|&i| got[i] != want[i]).collect();
    if let Some(&i) = diff.first() {
        panic!(
            "{what}: {} of {} mask pixels differ; first at (x {}, y {}): got {}, want {}",
            diff.len(),
            got.len(),
            i % w,
            i / w,
            got[i],
            want[i]
        );
    }
}

// =================================================================================
// Otsu
// =================================================================================

/// Checks Otsu on `img` with both box rules: threshold = exhaustive search, mask =
/// `DN > t`, box = the rule applied to that mask.
#[track_caller]
fn check_otsu(img: &Img, what: &str) {
    let want_t = otsu_expected_threshold(img);
    let want_mask = mask_above(img, want_t);
    for rule in RULES {
        let det = Otsu { box_rule: rule };
        let mut scratch = Otsu::scratch();
        let obs = observe_in(det, img, &mut scratch);
        // The proven worst case (otsu.rs, "Worst case") holds on every frame.
        let passes = usize::from(scratch.work().refinement_passes());
        assert!(
            passes <= otsu::max_refinement_passes(img.bits),
            "{what}: {passes} refinement passes, more than the proven {} at {} bits",
            otsu::max_refinement_passes(img.bits),
            img.bits
        );
        assert_eq!(
            obs.detection.threshold,
            want_t,
            "{what} ({}x{} {}-bit, {} distinct DN): Otsu threshold",
            img.w,
            img.h,
            img.bits,
            distinct(&img.px)
        );
        assert_same_mask(&obs.mask, &want_mask, img.w, what);
        assert_box_rule(&det, &obs, img, what);
        let want_box = box_by_rule(rule, &want_mask, img.w, img.h);
        assert_eq!(obs.detection.roi, want_box, "{what}: {rule:?} box");
    }
}

#[test]
fn otsu_reference_agrees_with_a_hand_computation() {
    // 0,0,0,10,10,12: t = 0 separates {0,0,0} from {10,10,12} (the largest gap).
    assert_eq!(otsu_exhaustive(&[0, 0, 0, 10, 10, 12], 8), Some(0));
    // Symmetric two-value frame: every t in 3..7 gives the same split; smallest wins.
    assert_eq!(otsu_exhaustive(&[3, 7, 3, 7], 8), Some(3));
    // {0, 1, 2} equally often: t = 0 and t = 1 tie exactly; the smallest wins.
    assert_eq!(otsu_exhaustive(&[0, 1, 2], 8), Some(0));
    // One value: no split.
    assert_eq!(otsu_exhaustive(&[5, 5, 5], 8), None);
    // Above max_dn clamps: 300 is 255 in 8 bits, so {255, 255}: no split.
    assert_eq!(otsu_exhaustive(&[255, 300], 8), None);
}

#[test]
fn otsu_matches_exhaustive_search_on_small_random_frames() {
    let mut rng = Rng::new(1);
    for case in 0..400 {
        let bits = [1, 2, 5, 8, 9, 10, 12, 14, 14, 16][rng.below(10) as usize];
        let w = rng.urange(1, 48);
        let h = rng.urange(1, 48);
        let img = any_frame(&mut rng, w, h, bits);
        check_otsu(&img, &format!("case {case}"));
    }
}

#[test]
fn otsu_matches_exhaustive_search_on_full_frames() {
    let mut rng = Rng::new(2);
    for (case, bits) in [8u8, 12, 14, 16].into_iter().cycle().take(16).enumerate() {
        let img = match case / 4 {
            0 => bimodal_frame(&mut rng, W, H, bits, 0.001),
            1 => textured_frame(&mut rng, W, H, bits),
            2 => uniform_frame(&mut rng, W, H, bits, u16::MAX),
            _ => few_levels_frame(&mut rng, W, H, bits),
        };
        check_otsu(&img, &format!("full frame {case}, {bits} bits"));
    }
}

/// Otsu's worst case: frames whose between-class variance is flat over the whole
/// interval where the optimal split may lie (`otsu::fill_flat_variance`) keep the
/// branch and bound refining until the proven pass bound, within one pass (the bound
/// allows 65 bins, these frames fill 62-64 of them), and still match the exhaustive
/// search.
#[test]
fn otsu_flat_variance_frames_reach_the_proven_pass_bound() {
    for (w, h, bits, spike_px) in [
        (W, H, 14, 100),
        (W, H, 14, 1000),
        (W, H, 12, 100),
        (W, H, 16, 100),
        (64, 48, 14, 100),
    ] {
        let what = format!("flat variance {w}x{h} {bits}-bit, spikes of {spike_px} px");
        let mut img = Img::constant(w, h, bits, 0);
        otsu::fill_flat_variance(&mut img.px, max_dn(bits), spike_px);
        assert!(
            img.px.iter().all(|&v| v <= max_dn(bits)),
            "{what}: DN within the bit depth"
        );
        check_otsu(&img, &what);
        let mut scratch = Otsu::scratch();
        Otsu::default()
            .detect(&img.frame(), &mut scratch)
            .expect("valid parameters");
        let passes = usize::from(scratch.work().refinement_passes());
        let bound = otsu::max_refinement_passes(bits);
        assert!(
            passes <= bound && passes + 1 >= bound,
            "{what}: {passes} refinement passes, the proven bound is {bound}"
        );
    }
    // The bound's arithmetic: ⌈65 bins / (512 DN per pass / bin width)⌉.
    assert_eq!(otsu::MAX_REFINED_BINS, 65);
    for (bits, per_pass) in [
        (7u8, 0usize),
        (8, 255),
        (9, 128),
        (12, 16),
        (14, 4),
        (16, 1),
    ] {
        assert_eq!(otsu::bins_per_pass(bits), per_pass, "{bits} bits");
        let want = if per_pass == 0 {
            0
        } else {
            65usize.div_ceil(per_pass)
        };
        assert_eq!(otsu::max_refinement_passes(bits), want, "{bits} bits");
    }
}

#[test]
fn otsu_matches_exhaustive_search_on_fixture_frames() {
    for (name, img) in fixture_imgs() {
        check_otsu(&img, name);
    }
}

/// Low-contrast frames (every DN within a few counts), most of them within one coarse
/// bin of the detector's histogram.
fn low_contrast_frames() -> Vec<(String, Img)> {
    let mut rng = Rng::new(3);
    (0..120)
        .map(|case| {
            let bits = [10, 12, 14, 16][case % 4];
            let (w, h) = if case < 8 {
                (W, H)
            } else {
                (rng.urange(2, 40), rng.urange(1, 40))
            };
            let span = rng.range(1, 40) as u16;
            let img = narrow_frame(&mut rng, w, h, bits, span);
            (format!("low-contrast case {case}, span {span}"), img)
        })
        .collect()
}

#[test]
fn otsu_matches_exhaustive_search_on_low_contrast_frames_with_both_rules() {
    // Narrow DN spans: inside one coarse bin or across a boundary.
    for (what, img) in low_contrast_frames() {
        check_otsu(&img, &what);
    }
    // Two values either side of a coarse-bin boundary (128 DN at 14 bits), and inside.
    for (lo, hi) in [(127u16, 128u16), (255, 256), (63, 64), (16_319, 16_320)] {
        let img = frame_from_pattern(&["#..", ".#.", "..#"], lo, hi);
        check_otsu(&img, &format!("{lo}/{hi}"));
    }
}

#[test]
fn otsu_matches_exhaustive_search_on_low_contrast_frames() {
    for (what, img) in low_contrast_frames() {
        let want_t = otsu_expected_threshold(&img);
        let d = detect(Otsu::default(), &img).unwrap();
        assert_eq!(d.threshold, want_t, "{what}: threshold");
        assert_eq!(
            d.roi,
            hull_of_mask(&mask_above(&img, want_t), img.w, img.h),
            "{what}: box"
        );
    }
}

#[test]
fn otsu_two_close_values_are_split() {
    // 14-bit frame holding only DN 100 and 101: the only split is t = 100.
    let img = frame_from_pattern(&["..#.", ".##.", "...."], 100, 101);
    assert_eq!(otsu_exhaustive(&img.px, 14), Some(100));
    let d = detect(Otsu::default(), &img).unwrap();
    assert_eq!(d.threshold, 100);
    assert_eq!(d.foreground_px, 3);
    assert_roi_pattern(d.roi, img.w, &[".##.", ".##.", "...."]);
}

#[test]
fn otsu_single_value_frames_have_no_roi() {
    for (bits, v, want) in [
        (14u8, 0u16, 0u32),
        (14, 7_000, 7_000),
        (14, 16_383, 16_383),
        (14, 40_000, 16_383), // above max_dn: saturated
        (8, 255, 255),
        (16, 65_535, 65_535),
        (1, 1, 1),
    ] {
        for (w, h) in [(1, 1), (3, 2), (W, H)] {
            let img = Img::constant(w, h, bits, v);
            assert_eq!(otsu_exhaustive(&img.px, bits), None);
            for rule in RULES {
                let obs = observe(Otsu { box_rule: rule }, &img);
                let d = obs.detection;
                assert_eq!(d.roi, None, "{w}x{h} constant {v} at {bits} bits");
                assert_eq!(d.threshold, want, "{w}x{h} constant {v} at {bits} bits");
                assert_eq!(d.foreground_px, 0);
            }
        }
    }
}

#[test]
fn otsu_pattern_frames() {
    let img = frame_from_pattern(
        &[
            "..........",
            ".###......",
            ".###...#..",
            ".......##.",
            "..........",
        ],
        500,
        9_000,
    );
    let all = detect(Otsu::default(), &img).unwrap();
    assert_eq!(all.threshold, 500);
    assert_eq!(all.foreground_px, 9);
    assert_roi_pattern(
        all.roi,
        img.w,
        &[
            "..........",
            ".########.",
            ".########.",
            ".########.",
            "..........",
        ],
    );
    let largest = detect(
        Otsu {
            box_rule: BoxRule::LargestComponent,
        },
        &img,
    )
    .unwrap();
    assert_roi_pattern(
        largest.roi,
        img.w,
        &[
            "..........",
            ".###......",
            ".###......",
            "..........",
            "..........",
        ],
    );
}

// =================================================================================
// Adaptive
// =================================================================================

/// Checks adaptive on `img` with both box rules against the reference.
#[track_caller]
fn check_adaptive(img: &Img, block: u16, offset: i32, what: &str) {
    let want = adaptive_naive(&img.px, img.w, img.h, img.bits, block, offset);
    for rule in RULES {
        let det = Adaptive {
            block,
            offset_dn: offset,
            box_rule: rule,
        };
        let obs = observe(det, img);
        let what = format!(
            "{what} ({}x{} {}-bit, block {block}, offset {offset})",
            img.w, img.h, img.bits
        );
        assert_same_mask(&obs.mask, &want, img.w, &what);
        assert_eq!(obs.detection.threshold, offset.max(0) as u32, "{what}");
        assert_box_rule(&det, &obs, img, &what);
    }
}

#[test]
fn adaptive_reference_summed_area_table_equals_literal_loops() {
    let mut rng = Rng::new(10);
    for _ in 0..60 {
        let (w, h) = (rng.urange(1, 20), rng.urange(1, 20));
        let bits = [8, 14, 16][rng.below(3) as usize];
        let img = any_frame(&mut rng, w, h, bits);
        let block = [3u16, 5, 7, 41][rng.below(4) as usize];
        let offset = rng.range(-300, 300) as i32;
        assert_eq!(
            adaptive_naive(&img.px, w, h, bits, block, offset),
            adaptive_bruteforce(&img.px, w, h, bits, block, offset)
        );
    }
}

#[test]
fn adaptive_matches_reference_on_small_frames() {
    let mut rng = Rng::new(11);
    let sizes = [
        (1, 1),
        (3, 2),
        (2, 3),
        (1, 17),
        (17, 1),
        (2, 2),
        (5, 5),
        (40, 3),
    ];
    for (case, &(w, h)) in sizes.iter().cycle().take(80).enumerate() {
        let bits = [8, 12, 14, 16][case % 4];
        let img = any_frame(&mut rng, w, h, bits);
        for block in [3, 5, 41, 249] {
            for offset in [-200, -1, 0, 1, 64] {
                check_adaptive(&img, block, offset, &format!("case {case}"));
            }
        }
    }
    for case in 0..200 {
        let (w, h) = (rng.urange(1, 60), rng.urange(1, 60));
        let bits = [8, 12, 14, 16][case % 4];
        let img = any_frame(&mut rng, w, h, bits);
        let block = if case % 2 == 0 {
            2 * rng.range(1, 124) as u16 + 1
        } else {
            2 * rng.range(1, w.div_ceil(2) as i64) as u16 + 1
        };
        let offset = rng.range(-2_000, 2_000) as i32;
        check_adaptive(&img, block, offset, &format!("random case {case}"));
    }
}

#[test]
fn adaptive_matches_reference_on_full_frames() {
    let mut rng = Rng::new(12);
    let blocks = [3u16, 5, 41, 249, 41, 3];
    let offsets = [-64, 0, 64, 1, -1, 500];
    for case in 0..6 {
        let bits = [14, 16, 12, 8, 14, 14][case];
        let img = match case % 3 {
            0 => textured_frame(&mut rng, W, H, bits),
            1 => bimodal_frame(&mut rng, W, H, bits, 0.001),
            _ => uniform_frame(&mut rng, W, H, bits, u16::MAX),
        };
        check_adaptive(
            &img,
            blocks[case],
            offsets[case],
            &format!("full case {case}"),
        );
    }
}

#[test]
fn adaptive_matches_reference_on_fixture_frames() {
    for (name, img) in fixture_imgs() {
        let d = Adaptive::default();
        check_adaptive(&img, d.block, d.offset_dn, name);
    }
}

#[test]
fn adaptive_frames_narrower_than_the_block_do_not_panic() {
    let mut rng = Rng::new(13);
    for (w, h) in [(1, 1), (1, 40), (15, 15), (39, 20), (100, 3), (247, 10)] {
        let img = any_frame(&mut rng, w, h, 14);
        for block in [41u16, 249] {
            let want = adaptive_naive(&img.px, w, h, 14, block, 64);
            let det = Adaptive {
                block,
                ..Adaptive::default()
            };
            let d = detect(det, &img).unwrap();
            assert_eq!(d.roi, hull_of_mask(&want, w, h), "{w}x{h}, block {block}");
        }
    }
}

#[test]
fn adaptive_pattern_frame() {
    // Block 3: an isolated bright pixel exceeds its 3x3 mean; its dark neighbours do
    // not. At the corner the window is clipped to 2x2.
    let img = frame_from_pattern(&["#....", "..#..", "....."], 100, 1_000);
    let det = Adaptive {
        block: 3,
        offset_dn: 0,
        box_rule: BoxRule::AllForeground,
    };
    let obs = observe(det, &img);
    assert_mask_pattern(&obs.mask, img.w, &["#....", "..#..", "....."]);
    assert_roi_pattern(obs.detection.roi, img.w, &["###..", "###..", "....."]);
    // An offset above the excess over the mean removes both: excess of the centre
    // pixel is 900 - 900/9 = 800, of the corner 900 - 900/4 = 675.
    for (offset, want) in [
        (674, ["#....", "..#..", "....."]),
        (675, [".....", "..#..", "....."]),
        (799, [".....", "..#..", "....."]),
        (800, [".....", ".....", "....."]),
    ] {
        let obs = observe(
            Adaptive {
                offset_dn: offset,
                ..det
            },
            &img,
        );
        assert_mask_pattern(&obs.mask, img.w, &want);
    }
}

#[test]
fn adaptive_rejects_invalid_blocks() {
    let img = Img::constant(8, 8, 14, 100);
    for block in [0u16, 1, 2, 4, 40, 250, 251, 1_000, u16::MAX - 1, u16::MAX] {
        let det = Adaptive {
            block,
            ..Adaptive::default()
        };
        let err = det.validate().unwrap_err();
        assert!(
            matches!(err, DetectError::InvalidParameter { name: "block", .. }),
            "block {block}: {err:?}"
        );
        assert_eq!(detect(det, &img).unwrap_err(), err, "block {block}");
    }
    for block in [3u16, 5, 41, 247, 249, adaptive::MAX_BLOCK] {
        let det = Adaptive {
            block,
            ..Adaptive::default()
        };
        assert_eq!(det.validate(), Ok(()), "block {block}");
    }
}

// =================================================================================
// WGE
// =================================================================================

#[track_caller]
fn check_wge(img: &Img, drop_fraction: f32, min_gradient: u32, what: &str) {
    let want = wge_naive(&img.px, img.w, img.h, img.bits, drop_fraction, min_gradient);
    for rule in RULES {
        let det = Wge {
            drop_fraction,
            min_gradient,
            box_rule: rule,
        };
        let obs = observe(det, img);
        let what = format!(
            "{what} ({}x{} {}-bit, drop {drop_fraction}, min {min_gradient})",
            img.w, img.h, img.bits
        );
        assert_eq!(obs.detection.threshold, want.threshold, "{what}: threshold");
        assert_same_mask(&obs.mask, &want.mask, img.w, &what);
        assert_box_rule(&det, &obs, img, &what);
    }
}

#[test]
fn wge_reference_prewitt_by_hand() {
    // A vertical step of 10 DN between columns 1 and 2: g_x = 3·10 at x = 1 and 2.
    let img = frame_from_pattern(&["..##", "..##", "..##", "..##"], 0, 10);
    let g = prewitt_naive(&img.px, 4, 4, 14);
    assert_eq!(g, vec![0, 0, 0, 0, 0, 30, 30, 0, 0, 30, 30, 0, 0, 0, 0, 0]);
    // A single hot pixel: every neighbour sees it in one tap of g_x and one of g_y
    // (or two of one at the side centres).
    let img = frame_from_pattern(&[".....", ".....", "..#..", ".....", "....."], 0, 10);
    let g = prewitt_naive(&img.px, 5, 5, 14);
    assert_eq!(
        g,
        vec![
            0, 0, 0, 0, 0, //
            0, 20, 10, 20, 0, //
            0, 10, 0, 10, 0, //
            0, 20, 10, 20, 0, //
            0, 0, 0, 0, 0,
        ]
    );
}

#[test]
fn wge_matches_reference_on_small_frames() {
    let mut rng = Rng::new(20);
    let drops = [0.0f32, 0.25, 0.5, 0.9, 0.97, 0.999, 1.0];
    let mins = [0u32, 1, 48, 1_000];
    for case in 0..300 {
        let (w, h) = (rng.urange(2, 48), rng.urange(3, 48));
        let bits = [8, 12, 14, 16][case % 4];
        let img = any_frame(&mut rng, w, h, bits);
        let drop = if case % 5 == 4 {
            rng.unit() as f32
        } else {
            drops[rng.below(drops.len() as u64) as usize]
        };
        let min = mins[rng.below(mins.len() as u64) as usize];
        check_wge(&img, drop, min, &format!("case {case}"));
    }
}

#[test]
fn wge_matches_reference_on_full_frames() {
    let mut rng = Rng::new(21);
    for case in 0..8 {
        let bits = [14, 16, 12, 8][case % 4];
        let img = match case % 4 {
            0 => textured_frame(&mut rng, W, H, bits),
            1 => bimodal_frame(&mut rng, W, H, bits, 0.001),
            2 => uniform_frame(&mut rng, W, H, bits, u16::MAX),
            _ => few_levels_frame(&mut rng, W, H, bits),
        };
        let (drop, min) = [(0.97, 48), (0.5, 0), (0.999, 10), (0.0, 1_000)][case % 4];
        check_wge(&img, drop, min, &format!("full case {case}"));
    }
}

#[test]
fn wge_matches_reference_on_fixture_frames() {
    for (name, img) in fixture_imgs() {
        let d = Wge::default();
        check_wge(&img, d.drop_fraction, d.min_gradient, name);
    }
}

#[test]
fn wge_frames_without_interior_have_no_roi() {
    let mut rng = Rng::new(22);
    for (w, h) in [
        (1, 1),
        (2, 1),
        (1, 2),
        (2, 2),
        (3, 2),
        (2, 3),
        (W, 2),
        (2, H),
        (W, 1),
    ] {
        let img = uniform_frame(&mut rng, w, h, 14, u16::MAX);
        for drop in [0.0, 0.5, 1.0] {
            let want = wge_naive(&img.px, w, h, 14, drop, 0);
            assert_eq!(want.threshold, u32::MAX);
            check_wge(&img, drop, 0, &format!("{w}x{h}"));
            let d = detect(
                Wge {
                    drop_fraction: drop,
                    min_gradient: 0,
                    box_rule: BoxRule::AllForeground,
                },
                &img,
            )
            .unwrap();
            assert_eq!(d.roi, None, "{w}x{h}");
            assert_eq!(d.foreground_px, 0, "{w}x{h}");
        }
    }
}

#[test]
fn wge_one_pixel_wide_frames_do_not_panic() {
    // Width 1 with a height of 3 or more: no interior pixel, so no ROI.
    for h in [3usize, 4, 17, H] {
        let img = Img {
            px: (0..h as u16).map(|v| v * 37).collect(),
            w: 1,
            h,
            bits: 14,
        };
        let d = detect(Wge::default(), &img).unwrap();
        assert_eq!(d.roi, None, "1x{h}");
        assert_eq!(d.foreground_px, 0, "1x{h}");
        assert_eq!(d.threshold, u32::MAX, "1x{h}");
    }
}

#[test]
fn wge_pattern_frame() {
    // A 2x2 bright square: the pixels whose 3x3 neighbourhood sees its edge.
    let img = frame_from_pattern(
        &[
            "........", //
            "........", "...##...", "...##...", "........", "........",
        ],
        0,
        1_000,
    );
    let det = Wge {
        drop_fraction: 0.0,
        min_gradient: 1,
        box_rule: BoxRule::AllForeground,
    };
    let obs = observe(det, &img);
    assert_mask_pattern(
        &obs.mask,
        img.w,
        &[
            "........", //
            "..####..", "..####..", "..####..", "..####..", "........",
        ],
    );
    assert_eq!(obs.detection.threshold, 1);
    // Dropping everything keeps nothing.
    let none = detect(
        Wge {
            drop_fraction: 1.0,
            ..det
        },
        &img,
    )
    .unwrap();
    assert_eq!(none.roi, None);
    assert_eq!(none.threshold, u32::MAX);
}

#[test]
fn wge_rejects_invalid_drop_fractions() {
    let img = Img::constant(8, 8, 14, 100);
    for drop in [
        -0.01f32,
        -1.0,
        1.000_001,
        2.0,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ] {
        let det = Wge {
            drop_fraction: drop,
            ..Wge::default()
        };
        let err = det.validate().unwrap_err();
        assert!(
            matches!(
                err,
                DetectError::InvalidParameter {
                    name: "drop_fraction",
                    ..
                }
            ),
            "drop {drop}: {err:?}"
        );
        assert_eq!(detect(det, &img).unwrap_err(), err, "drop {drop}");
    }
    for drop in [0.0f32, -0.0, 0.5, 1.0] {
        let det = Wge {
            drop_fraction: drop,
            ..Wge::default()
        };
        assert_eq!(det.validate(), Ok(()), "drop {drop}");
    }
}

// =================================================================================
// DoG
// =================================================================================

#[test]
fn dog_finds_a_bright_disc() {
    for (cx, cy, radius) in [(150.0, 110.0, 24.0), (60.0, 200.0, 12.0)] {
        let (img, disc) = disc_frame(W, H, cx, cy, radius);
        for rule in RULES {
            let det = Dog {
                box_rule: rule,
                ..Dog::default()
            };
            let obs = observe(det, &img);
            assert_box_rule(&det, &obs, &img, "disc");
            let roi = obs
                .detection
                .roi
                .unwrap_or_else(|| panic!("disc at ({cx}, {cy}) r {radius}: no ROI"));
            assert!(
                roi.contains(cx as u16, cy as u16),
                "disc at ({cx}, {cy}) r {radius}, {rule:?}: box {roi:?} misses the centre"
            );
            let iou = roi.iou(&disc);
            assert!(
                iou > 0.5,
                "disc at ({cx}, {cy}) r {radius}, {rule:?}: box {roi:?} vs disc {disc:?}, IoU {iou}"
            );
        }
    }
}

#[test]
fn dog_box_matches_the_scale_of_the_target() {
    // Discs of other radii than in `dog_finds_a_bright_disc`, and a rectangle: the box
    // should match the target's size. Today the selected scale is one level too coarse
    // (box half-side ≈ 1.5 × radius): R_i = (G_i − G_{i+1})·σ_i/σ_0 multiplies a DoG that
    // already approximates the scale-normalised (k−1)·σ²·∇²G by σ once more.
    for (cx, cy, radius) in [
        (164.0, 124.0, 10.0),
        (164.0, 124.0, 16.0),
        (250.0, 70.0, 40.0),
    ] {
        let (img, disc) = disc_frame(W, H, cx, cy, radius);
        let d = detect(Dog::default(), &img).unwrap();
        let roi = d.roi.expect("DoG finds the disc");
        let iou = roi.iou(&disc);
        assert!(
            iou > 0.5,
            "r {radius}: box {roi:?} vs disc {disc:?}, IoU {iou}"
        );
    }
    let rect = Roi::new(100, 70, 180, 130);
    let mut img = Img::constant(W, H, 14, 400);
    img.fill(rect, 12_000);
    let roi = detect(Dog::default(), &img)
        .unwrap()
        .roi
        .expect("DoG finds it");
    let iou = roi.iou(&rect);
    assert!(iou > 0.5, "box {roi:?} vs rectangle {rect:?}, IoU {iou}");
}

#[test]
fn dog_constant_frames_have_no_roi() {
    for v in [0u16, 300, 9_000, 16_383, 65_535] {
        for (w, h) in [(1, 1), (5, 3), (W, H)] {
            let img = Img::constant(w, h, 14, v);
            for rule in RULES {
                let d = detect(
                    Dog {
                        box_rule: rule,
                        ..Dog::default()
                    },
                    &img,
                )
                .unwrap();
                assert_eq!(d.roi, None, "{w}x{h} constant {v}");
                assert_eq!(d.foreground_px, 0, "{w}x{h} constant {v}");
            }
        }
    }
}

#[test]
fn dog_box_rules_hold_on_its_own_mask() {
    let mut rng = Rng::new(30);
    for case in 0..12 {
        let (w, h) = if case < 4 {
            (W, H)
        } else {
            (rng.urange(1, 120), rng.urange(1, 120))
        };
        let img = if case % 2 == 0 {
            bimodal_frame(&mut rng, w, h, 14, 0.0)
        } else {
            textured_frame(&mut rng, w, h, 14)
        };
        for rule in RULES {
            let det = Dog {
                box_rule: rule,
                min_response_dn: [0, 64, 256][case % 3],
                ..Dog::default()
            };
            let obs = observe(det, &img);
            assert_box_rule(&det, &obs, &img, &format!("DoG case {case}"));
        }
    }
}

#[test]
fn dog_rejects_invalid_parameters() {
    let img = Img::constant(16, 16, 14, 100);
    let base = Dog::default();
    let cases: [(Dog, &str); 14] = [
        (
            Dog {
                sigma0_px: 0.99,
                ..base
            },
            "sigma0_px",
        ),
        (
            Dog {
                sigma0_px: 0.0,
                ..base
            },
            "sigma0_px",
        ),
        (
            Dog {
                sigma0_px: -4.0,
                ..base
            },
            "sigma0_px",
        ),
        (
            Dog {
                sigma0_px: f32::NAN,
                ..base
            },
            "sigma0_px",
        ),
        (
            Dog {
                sigma0_px: f32::INFINITY,
                ..base
            },
            "sigma0_px",
        ),
        (
            Dog {
                sigma_ratio: 1.0,
                ..base
            },
            "sigma_ratio",
        ),
        (
            Dog {
                sigma_ratio: 0.5,
                ..base
            },
            "sigma_ratio",
        ),
        (
            Dog {
                sigma_ratio: f32::NAN,
                ..base
            },
            "sigma_ratio",
        ),
        (
            Dog {
                sigma_ratio: f32::INFINITY,
                ..base
            },
            "sigma_ratio",
        ),
        (Dog { levels: 0, ..base }, "levels"),
        (Dog { levels: 2, ..base }, "levels"),
        (Dog { levels: 9, ..base }, "levels"),
        // 4 · 1.6^7 ≈ 107 px: beyond the largest kernel.
        (Dog { levels: 8, ..base }, "sigma0_px"),
        (
            Dog {
                sigma0_px: 100.0,
                ..base
            },
            "sigma0_px",
        ),
    ];
    for (det, field) in cases {
        let err = det.validate().unwrap_err();
        assert!(
            matches!(err, DetectError::InvalidParameter { name, .. } if name == field),
            "{det:?}: {err:?}, expected {field}"
        );
        assert_eq!(detect(det, &img).unwrap_err(), err, "{det:?}");
    }
    // In bounds: the extremes that still fit.
    for det in [
        base,
        Dog {
            sigma0_px: 1.0,
            levels: 3,
            ..base
        },
        Dog {
            sigma0_px: 1.0,
            sigma_ratio: 1.01,
            levels: 8,
            ..base
        },
        Dog {
            sigma0_px: 80.0,
            sigma_ratio: 1.01,
            levels: 3,
            ..base
        },
    ] {
        assert_eq!(det.validate(), Ok(()), "{det:?}");
        let d = detect(det, &img).unwrap();
        assert_eq!(d.roi, None, "{det:?} on a constant frame");
    }
}

// =================================================================================
// Box rules
// =================================================================================

/// Runs a `RoiBuilder` over `mask` row by row.
fn build(b: &mut RoiBuilder, rule: BoxRule, mask: &[bool], w: usize) -> (Option<Roi>, u32) {
    b.start(rule, w);
    for (y, row) in mask.chunks(w).enumerate() {
        b.push_row(y, row);
    }
    b.finish()
}

#[track_caller]
fn check_builder(b: &mut RoiBuilder, mask: &[bool], w: usize, h: usize, what: &str) {
    let count = mask.iter().filter(|&&m| m).count() as u32;
    for rule in RULES {
        let got = build(b, rule, mask, w);
        let want = box_by_rule(rule, mask, w, h);
        assert_eq!(got, (want, count), "{what} ({w}x{h}), {rule:?}");
    }
}

#[test]
fn roi_builder_matches_flood_fill_on_random_masks() {
    let mut rng = Rng::new(40);
    let mut b = Box::new(RoiBuilder::new());
    for case in 0..1_500 {
        let (w, h) = (rng.urange(1, 40), rng.urange(1, 40));
        let mask = any_mask(&mut rng, w, h);
        check_builder(&mut b, &mask, w, h, &format!("case {case}"));
    }
    for case in 0..60 {
        let (w, h) = if case < 30 {
            (W, H)
        } else {
            (rng.urange(1, W), rng.urange(1, H))
        };
        let mask = any_mask(&mut rng, w, h);
        check_builder(&mut b, &mask, w, h, &format!("large case {case}"));
    }
}

#[test]
fn roi_builder_density_sweep() {
    let mut rng = Rng::new(41);
    let mut b = Box::new(RoiBuilder::new());
    for step in 0..=40 {
        let p = f64::from(step) / 40.0;
        for (w, h) in [(W, H), (64, 48), (7, 200)] {
            let mask = random_mask(&mut rng, w, h, p);
            check_builder(&mut b, &mask, w, h, &format!("density {p}"));
        }
    }
}

#[test]
fn roi_builder_structured_masks() {
    let mut b = Box::new(RoiBuilder::new());
    for (w, h) in [(W, H), (W, 3), (3, H), (1, 1), (2, 2), (33, 17), (101, 77)] {
        let masks: Vec<(&str, Vec<bool>)> = vec![
            ("checkerboard 1", checkerboard_mask(w, h, 1)),
            ("checkerboard 2", checkerboard_mask(w, h, 2)),
            ("checkerboard 5", checkerboard_mask(w, h, 5)),
            ("spiral", spiral_mask(w, h)),
            ("nested U gap 1", nested_u_mask(w, h, 1)),
            ("nested U gap 3", nested_u_mask(w, h, 3)),
            ("comb down", comb_mask(w, h, 2, true)),
            ("comb up", comb_mask(w, h, 2, false)),
            ("comb 3 down", comb_mask(w, h, 3, true)),
            ("stripes", stripes_mask(w, h)),
            ("dots", dots_mask(w, h)),
            ("full", vec![true; w * h]),
            ("empty", vec![false; w * h]),
            ("full rows", (0..w * h).map(|i| (i / w) % 3 == 1).collect()),
            (
                "one pixel",
                (0..w * h).map(|i| i == (h / 2) * w + w / 2).collect(),
            ),
            ("last pixel", (0..w * h).map(|i| i == w * h - 1).collect()),
            (
                "diagonal",
                (0..w * h).map(|i| i % w == (i / w) % w).collect(),
            ),
            (
                "anti-diagonal",
                (0..w * h).map(|i| w - 1 - i % w == (i / w) % w).collect(),
            ),
        ];
        for (name, mask) in masks {
            check_builder(&mut b, &mask, w, h, name);
        }
    }
}

#[test]
fn roi_builder_spiral_and_comb_are_one_component() {
    let (w, h) = (41, 31);
    let mut b = Box::new(RoiBuilder::new());
    for mask in [
        spiral_mask(w, h),
        comb_mask(w, h, 2, true),
        nested_u_mask(w, h, 1),
    ] {
        let (roi, _) = build(&mut b, BoxRule::LargestComponent, &mask, w);
        assert_eq!(
            largest_component_naive(&mask, w, h),
            hull_of_mask(&mask, w, h)
        );
        assert_eq!(roi, hull_of_mask(&mask, w, h));
    }
    // Nested U shapes with gap 1 are separate components; the outermost is largest.
    let mask = nested_u_mask(9, 6, 1);
    assert_mask_pattern(
        &mask,
        9,
        &[
            "#.#...#.#",
            "#.#...#.#",
            "#.#...#.#",
            "#.#####.#",
            "#.......#",
            "#########",
        ],
    );
    assert_eq!(
        build(&mut b, BoxRule::LargestComponent, &mask, 9).0,
        Some(Roi::new(0, 0, 9, 6))
    );
}

#[test]
fn roi_builder_ties_go_to_the_first_component_in_raster_order() {
    let mut b = Box::new(RoiBuilder::new());
    // Two 4-pixel components; the right one starts in an earlier row.
    let (mask, w, h) = mask_from_pattern(&[
        "......##", //
        "##....##", "##......",
    ]);
    assert_eq!(
        build(&mut b, BoxRule::LargestComponent, &mask, w).0,
        Some(Roi::new(6, 0, 8, 2))
    );
    assert_eq!(
        largest_component_naive(&mask, w, h),
        Some(Roi::new(6, 0, 8, 2))
    );
    // Same row: the left one comes first. A U whose arms join late keeps the first
    // pixel of its left arm.
    let (mask, w, h) = mask_from_pattern(&[
        "#.#..#.#", //
        "#.#..#.#", "###..###",
    ]);
    check_builder(&mut b, &mask, w, h, "two Us");
    assert_eq!(
        build(&mut b, BoxRule::LargestComponent, &mask, w).0,
        Some(Roi::new(0, 0, 3, 3))
    );
    // A late merge makes the right shape larger: 1 + 1 + ... joined at the bottom.
    let (mask, w, h) = mask_from_pattern(&[
        "###.#...#", //
        "###.#...#",
        "....#...#",
        "....#####",
    ]);
    check_builder(&mut b, &mask, w, h, "late merge");
    assert_eq!(
        build(&mut b, BoxRule::LargestComponent, &mask, w).0,
        Some(Roi::new(4, 0, 9, 4))
    );
}

#[test]
fn roi_builder_row_protocol() {
    let mut b = Box::new(RoiBuilder::new());
    let row = [false, true, true, false];
    // Skipped rows count as background: rows 0 and 3 do not connect.
    b.start(BoxRule::LargestComponent, 4);
    b.push_row(0, &row);
    b.push_row(3, &[true, true, true, true]);
    assert_eq!(b.finish(), (Some(Roi::new(0, 3, 4, 4)), 6));
    // A repeated or earlier row is ignored.
    b.start(BoxRule::AllForeground, 4);
    b.push_row(1, &row);
    b.push_row(1, &[true; 4]);
    b.push_row(0, &[true; 4]);
    assert_eq!(b.finish(), (Some(Roi::new(1, 1, 3, 2)), 2));
    // Pixels beyond the width are cut.
    b.start(BoxRule::AllForeground, 2);
    b.push_row(0, &[false, false, true, true]);
    assert_eq!(b.finish(), (None, 0));
    // No rows at all.
    for rule in RULES {
        b.start(rule, 10);
        assert_eq!(b.finish(), (None, 0));
    }
}

#[test]
fn box_rules_hold_on_every_detectors_own_mask() {
    let mut rng = Rng::new(42);
    for case in 0..24 {
        let (w, h) = if case < 4 {
            (W, H)
        } else {
            (rng.urange(1, 80), rng.urange(1, 80))
        };
        let img = any_frame(&mut rng, w, h, 14);
        let what = format!("case {case}");
        for rule in RULES {
            let o = Otsu::default().with_rule(rule);
            assert_box_rule(&o, &observe(o, &img), &img, &what);
            let a = Adaptive {
                block: 5,
                offset_dn: 10,
                box_rule: rule,
            };
            assert_box_rule(&a, &observe(a, &img), &img, &what);
            let g = Wge {
                drop_fraction: 0.8,
                ..Wge::default()
            }
            .with_rule(rule);
            assert_box_rule(&g, &observe(g, &img), &img, &what);
            let d = Dog::default().with_rule(rule);
            assert_box_rule(&d, &observe(d, &img), &img, &what);
        }
    }
}

/// One scratch reused for many frames gives what fresh scratch gives.
fn check_reuse<D: TestDetector + std::fmt::Debug>(
    dets: &[D],
    frames: &[Img],
    skip: impl Fn(&Img) -> bool,
) {
    let mut shared = D::scratch();
    for (i, img) in frames.iter().enumerate() {
        for det in dets {
            if skip(img) {
                continue;
            }
            let reused = det.detect(&img.frame(), &mut shared);
            let fresh = detect(*det, img);
            assert_eq!(reused, fresh, "frame {i}, {det:?}");
        }
    }
}

#[test]
fn scratch_reuse_gives_the_same_detections() {
    let mut rng = Rng::new(43);
    let mut frames = Vec::new();
    for i in 0..10 {
        let (w, h) = if i % 4 == 0 {
            (W, H)
        } else {
            (rng.urange(1, 90), rng.urange(1, 90))
        };
        frames.push(any_frame(&mut rng, w, h, [14, 8, 16][i % 3]));
    }
    let never = |_: &Img| false;
    check_reuse(&RULES.map(|r| Otsu::default().with_rule(r)), &frames, never);
    let a = Adaptive::default();
    check_reuse(&RULES.map(|r| a.with_rule(r)), &frames, never);
    let g = Wge::default();
    check_reuse(&RULES.map(|r| g.with_rule(r)), &frames, never);
    check_reuse(&RULES.map(|r| Dog::default().with_rule(r)), &frames, never);
}

// =================================================================================
// Hand-made frames with known boxes
// =================================================================================

#[test]
fn bright_rectangle_on_dark_frame() {
    let rect = Roi::new(100, 70, 180, 130);
    let mut img = Img::constant(W, H, 14, 400);
    img.fill(rect, 12_000);
    let grown = Roi::new(rect.x0 - 1, rect.y0 - 1, rect.x1 + 1, rect.y1 + 1);
    for rule in RULES {
        let o = detect(Otsu::default().with_rule(rule), &img).unwrap();
        assert_eq!(o.roi, Some(rect), "otsu {rule:?}");
        assert_eq!(o.threshold, 400);
        assert_eq!(o.foreground_px, rect.area());
        let a = detect(Adaptive::default().with_rule(rule), &img).unwrap();
        assert_eq!(a.roi, Some(rect), "adaptive {rule:?}");
        // WGE keeps the pixels whose 3x3 neighbourhood straddles the edge.
        let g = detect(Wge::default().with_rule(rule), &img).unwrap();
        assert_eq!(g.roi, Some(grown), "wge {rule:?}");
        // DoG: a box around the rectangle (its size: `dog_box_matches_the_scale_of_the_target`).
        let d = detect(Dog::default().with_rule(rule), &img).unwrap();
        let droi = d.roi.expect("DoG finds the rectangle");
        assert!(droi.contains(140, 100), "dog {rule:?}: {droi:?}");
        assert!(droi.contains_roi(&rect), "dog {rule:?}: {droi:?}");
    }
}

#[test]
fn rectangle_on_a_linear_ramp() {
    // Background rises 4 DN per column (1 312 DN across); the target is 8 000 DN above.
    let rect = Roi::new(200, 60, 260, 110);
    let mut img = Img::constant(W, H, 14, 0);
    for y in 0..H {
        for x in 0..W {
            let ramp = 1_000 + 4 * x as u16;
            let on = rect.contains(x as u16, y as u16);
            *img.at(x, y) = ramp + if on { 8_000 } else { 0 };
        }
    }
    let grown = Roi::new(rect.x0 - 1, rect.y0 - 1, rect.x1 + 1, rect.y1 + 1);
    for rule in RULES {
        let o = observe(Otsu::default().with_rule(rule), &img);
        assert_eq!(o.detection.roi, Some(rect), "otsu {rule:?}");
        // Adaptive: the ramp's excess over a clipped block mean is at most 10·4 DN,
        // below the 64 DN offset.
        let a = observe(Adaptive::default().with_rule(rule), &img);
        assert_eq!(a.detection.roi, Some(rect), "adaptive {rule:?}");
        // WGE: the ramp's gradient is 6·4 = 24 < 48.
        let g = observe(Wge::default().with_rule(rule), &img);
        assert_eq!(g.detection.roi, Some(grown), "wge {rule:?}");
        assert_eq!(g.detection.threshold, 48);
    }
}

#[test]
fn two_blobs_hull_versus_largest() {
    let img = frame_from_pattern(
        &[
            "............",
            ".##.........",
            ".##.........",
            "......####..",
            "......####..",
            "......####..",
            "............",
        ],
        200,
        5_000,
    );
    let hull = [
        "............",
        ".#########..",
        ".#########..",
        ".#########..",
        ".#########..",
        ".#########..",
        "............",
    ];
    let big = [
        "............",
        "............",
        "............",
        "......####..",
        "......####..",
        "......####..",
        "............",
    ];
    let o = detect(Otsu::default(), &img).unwrap();
    assert_roi_pattern(o.roi, img.w, &hull);
    let o = detect(Otsu::default().with_rule(BoxRule::LargestComponent), &img).unwrap();
    assert_roi_pattern(o.roi, img.w, &big);
    let a = Adaptive {
        block: 5,
        offset_dn: 0,
        box_rule: BoxRule::AllForeground,
    };
    assert_roi_pattern(detect(a, &img).unwrap().roi, img.w, &hull);
    let a = a.with_rule(BoxRule::LargestComponent);
    assert_roi_pattern(detect(a, &img).unwrap().roi, img.w, &big);
}

#[test]
fn two_blobs_on_a_full_frame() {
    let small = Roi::new(20, 20, 40, 35);
    let large = Roi::new(200, 120, 260, 180);
    let mut img = Img::constant(W, H, 14, 500);
    img.fill(small, 10_000);
    img.fill(large, 10_000);
    let hull = small.hull(&large);
    for (rule, want) in [
        (BoxRule::AllForeground, hull),
        (BoxRule::LargestComponent, large),
    ] {
        assert_eq!(
            detect(Otsu::default().with_rule(rule), &img).unwrap().roi,
            Some(want)
        );
        assert_eq!(
            detect(Adaptive::default().with_rule(rule), &img)
                .unwrap()
                .roi,
            Some(want)
        );
        let grow = |r: Roi| Roi::new(r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1);
        let wge_want = match rule {
            BoxRule::AllForeground => grow(small).hull(&grow(large)),
            BoxRule::LargestComponent => grow(large),
        };
        assert_eq!(
            detect(Wge::default().with_rule(rule), &img).unwrap().roi,
            Some(wge_want)
        );
    }
}

// =================================================================================
// Memory budgets and frames
// =================================================================================

/// lib.rs's memory table: (detector, its `SCRATCH_BYTES`, what `Method` reports, the
/// budget, the exact bytes on x86-64). Stated numbers, not recomputed from the types.
const MEMORY_TABLE: [(&str, usize, Method, usize, usize); 5] = [
    ("otsu", otsu::SCRATCH_BYTES, Method::Otsu, 16 * 1024, 15_224),
    (
        "adaptive",
        adaptive::SCRATCH_BYTES,
        Method::Adaptive,
        16 * 1024,
        11_576,
    ),
    ("wge", wge::SCRATCH_BYTES, Method::Wge, 16 * 1024, 14_352),
    ("dog", dog::SCRATCH_BYTES, Method::Dog, 96 * 1024, 74_296),
    (
        "auto-v2",
        tirroi_core::roi::auto::learned::SCRATCH_BYTES,
        Method::AutoV2,
        48 * 1024,
        48_784,
    ),
];

#[test]
fn scratch_memory_budgets() {
    for (name, bytes, method, budget, _) in MEMORY_TABLE {
        assert!(
            bytes <= budget,
            "{name}: {bytes} B of scratch, budget {budget} B"
        );
        assert!(
            method.scratch_bytes() <= budget,
            "{name}: Method::{method:?} reports {} B, budget {budget} B",
            method.scratch_bytes()
        );
        // The mask-to-box state is part of every scratch.
        assert!(bytes > size_of::<RoiBuilder>());
    }
    assert_eq!(
        size_of::<Scratch<()>>(),
        size_of::<RoiBuilder>(),
        "Scratch<W> is W plus the RoiBuilder"
    );
}

/// The exact figures of lib.rs's memory table (and the README, `tirroi memory`) hold
/// on 64-bit targets (32-bit ones save a few bytes of `usize` fields).
#[cfg(target_pointer_width = "64")]
#[test]
fn scratch_memory_is_as_documented_on_64_bit() {
    for (name, bytes, method, _, documented) in MEMORY_TABLE {
        assert_eq!(bytes, documented, "{name}: SCRATCH_BYTES vs lib.rs's table");
        assert_eq!(
            method.scratch_bytes(),
            documented,
            "{name}: Method::{method:?}.scratch_bytes() vs lib.rs's table"
        );
    }
    // The sequence tracker's own state (lib.rs, docs/detectors.md).
    assert_eq!(
        tirroi_core::roi::track::TRACKER_BYTES,
        8_408,
        "lib.rs: TRACKER_BYTES"
    );
}

#[test]
fn method_names_round_trip() {
    assert_eq!(Method::ALL.len(), 6);
    assert_eq!(
        Method::PAPER,
        [Method::Otsu, Method::Adaptive, Method::Wge, Method::Dog]
    );
    for (m, name) in Method::ALL
        .into_iter()
        .zip(["otsu", "adaptive", "wge", "dog", "auto", "auto-v2"])
    {
        assert_eq!(m.name(), name);
        assert_eq!(m.to_string(), name);
        assert_eq!(Method::from_name(name), Some(m));
    }
    assert_eq!(Method::from_name("Otsu"), None);
    assert_eq!(Method::from_name("all"), None);
    assert_eq!(Method::from_name(""), None);
}

#[test]
fn frame_new_validates_once() {
    let px = vec![0u16; 329 * 249];
    assert_eq!(
        Frame::new(&px[..0], 0, 5, 14).unwrap_err(),
        FrameError::ZeroSize
    );
    assert_eq!(
        Frame::new(&px[..0], 5, 0, 14).unwrap_err(),
        FrameError::ZeroSize
    );
    assert_eq!(
        Frame::new(&px[..0], 0, 0, 14).unwrap_err(),
        FrameError::ZeroSize
    );
    // Above the reference capacity is a valid frame; the detectors refuse it
    // (tests/capacity.rs).
    assert!(Frame::new(&px[..329 * 248], 329, 248, 14).is_ok());
    assert!(Frame::new(&px[..328 * 249], 328, 249, 14).is_ok());
    assert_eq!(
        Frame::new(&px[..0], 65_535, 1, 14).unwrap_err(),
        FrameError::TooLarge {
            width: 65_535,
            height: 1
        }
    );
    assert_eq!(
        Frame::new(&px, usize::MAX, usize::MAX, 14).unwrap_err(),
        FrameError::TooLarge {
            width: usize::MAX,
            height: usize::MAX
        }
    );
    for bits in [0u8, 17, 255] {
        assert_eq!(
            Frame::new(&px[..4], 2, 2, bits).unwrap_err(),
            FrameError::BadBitDepth(bits)
        );
    }
    for len in [0usize, 3, 5, 100] {
        assert_eq!(
            Frame::new(&px[..len], 2, 2, 14).unwrap_err(),
            FrameError::WrongLength {
                expected: 4,
                actual: len
            }
        );
    }
    assert_eq!(
        Frame::reference(&px[..FRAME_PIXELS + 1]).unwrap_err(),
        FrameError::WrongLength {
            expected: FRAME_PIXELS,
            actual: FRAME_PIXELS + 1
        }
    );
    // Accepted: the extremes.
    let f = Frame::reference(&px[..FRAME_PIXELS]).unwrap();
    assert_eq!(
        (f.width(), f.height(), f.bits(), f.max_dn()),
        (W, H, 14, 16_383)
    );
    assert_eq!(f.rows().count(), H);
    assert_eq!(f.row(H - 1).map(<[u16]>::len), Some(W));
    assert_eq!(f.row(H), None);
    let f = Frame::new(&px[..1], 1, 1, 1).unwrap();
    assert_eq!(f.max_dn(), 1);
    let f = Frame::new(&px[..1], 1, 1, 16).unwrap();
    assert_eq!(f.max_dn(), 65_535);
    // Errors print one line naming the numbers.
    let msg = FrameError::WrongLength {
        expected: 4,
        actual: 3,
    }
    .to_string();
    assert!(
        msg.contains('4') && msg.contains('3') && !msg.contains('\n'),
        "{msg}"
    );
}
