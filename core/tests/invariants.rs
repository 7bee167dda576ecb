//! Property tests (proptest) of invariants every detector must keep on any frame: no
//! panic, boxes inside the frame, no ROI on flat frames, IoU's algebra, Otsu's
//! invariance under positive affine maps of the DN, and boxes that follow a moving
//! target.
//!
//! Runs are deterministic (a fixed seed) unless `PROPTEST_RNG_SEED` says otherwise;
//! `PROPTEST_CASES` does not override the per-test case counts, which keep a debug
//! `cargo test` quick.

mod common;

use common::Rng;
use common::*;
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::RngSeed;
use tirroi_core::frame::{FRAME_HEIGHT, FRAME_WIDTH};
use tirroi_core::roi::adaptive::Adaptive;
use tirroi_core::roi::dog::Dog;
use tirroi_core::roi::otsu::Otsu;
use tirroi_core::roi::wge::Wge;
use tirroi_core::{BoxRule, DetectError, Detection, Roi};

const W: usize = FRAME_WIDTH;
const H: usize = FRAME_HEIGHT;

/// `cases` cases from a fixed seed (unless `PROPTEST_RNG_SEED` is set).
fn config(cases: u32) -> ProptestConfig {
    let mut c = ProptestConfig::with_cases(cases);
    if c.rng_seed == RngSeed::Random {
        c.rng_seed = RngSeed::Fixed(0x7155_0C0F_FEE5);
    }
    // Runs are reproducible from the seed; no regression files next to the tests.
    c.failure_persistence = None;
    c
}

// ---------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------

fn bits() -> impl Strategy<Value = u8> {
    prop_oneof![Just(8u8), Just(12), Just(14), Just(16), 1u8..=16]
}

fn rule() -> impl Strategy<Value = BoxRule> {
    prop_oneof![
        Just(BoxRule::AllForeground),
        Just(BoxRule::LargestComponent)
    ]
}

/// DN for `n` pixels of a `bits`-bit frame: arbitrary `u16` (many above `max_dn`),
/// in range, a few levels, or one hot pixel on a flat background.
fn pixels(n: usize, bits: u8) -> impl Strategy<Value = Vec<u16>> {
    let max = max_dn(bits);
    prop_oneof![
        vec(any::<u16>(), n),
        vec(0..=max, n),
        vec(0..=max, 1..4).prop_flat_map(move |levels| vec(select(levels), n)),
        (0..=max, 0..n, any::<u16>()).prop_map(move |(bg, at, hot)| {
            let mut px = vec![bg; n];
            px[at] = hot;
            px
        }),
    ]
}

/// Frames of 1..=40 × 1..=40 pixels.
fn small_img() -> impl Strategy<Value = Img> {
    (1usize..=40, 1usize..=40, bits()).prop_flat_map(|(w, h, bits)| {
        pixels(w * h, bits).prop_map(move |px| Img { px, w, h, bits })
    })
}

/// Full 328×248 frames: constant, all-zero, all-saturated, above `max_dn`, one hot
/// pixel, uniform noise (in range or not), or a bimodal scene.
fn full_img() -> impl Strategy<Value = Img> {
    (0u8..8, bits(), any::<u64>()).prop_map(|(kind, bits, seed)| {
        let mut rng = Rng::new(seed);
        let max = max_dn(bits);
        match kind {
            0 => Img::constant(W, H, bits, rng.below(u64::from(max) + 1) as u16),
            1 => Img::constant(W, H, bits, 0),
            2 => Img::constant(W, H, bits, max),
            3 => Img::constant(W, H, bits, u16::MAX),
            4 => {
                let mut img = Img::constant(W, H, bits, rng.below(u64::from(max) + 1) as u16);
                let (x, y) = (rng.urange(0, W - 1), rng.urange(0, H - 1));
                *img.at(x, y) = rng.below(1 << 16) as u16;
                img
            }
            5 => uniform_frame(&mut rng, W, H, bits, max),
            6 => uniform_frame(&mut rng, W, H, bits, u16::MAX),
            _ => bimodal_frame(&mut rng, W, H, bits, 0.01),
        }
    })
}

/// Parameters of all four detectors (DoG's may be out of bounds on purpose).
#[derive(Debug, Clone, Copy)]
struct Params {
    rule: BoxRule,
    adaptive: Adaptive,
    wge: Wge,
    dog: Dog,
}

fn params() -> impl Strategy<Value = Params> {
    let block = prop_oneof![1u16..=4, 1u16..=124].prop_map(|k| 2 * k + 1);
    let min_gradient = prop_oneof![0u32..=2_000, Just(u32::MAX)];
    (
        rule(),
        (block, -3_000i32..=3_000),
        (0.0f32..=1.0, min_gradient),
        (0.5f32..10.0, 1.0f32..2.5, 2u8..=9, 0u32..=2_000),
    )
        .prop_map(
            |(
                rule,
                (block, offset_dn),
                (drop_fraction, min_gradient),
                (s0, ratio, levels, resp),
            )| {
                Params {
                    rule,
                    adaptive: Adaptive {
                        block,
                        offset_dn,
                        box_rule: rule,
                    },
                    wge: Wge {
                        drop_fraction,
                        min_gradient,
                        box_rule: rule,
                    },
                    dog: Dog {
                        sigma0_px: s0,
                        sigma_ratio: ratio,
                        levels,
                        min_response_dn: resp,
                        box_rule: rule,
                    },
                }
            },
        )
}

/// Checks one detection of `img`: a box, if any, is non-empty and inside the frame, and
/// there is a box exactly when some pixel is foreground.
fn check_detection(
    what: &str,
    img: &Img,
    rule: BoxRule,
    d: Detection,
) -> Result<(), TestCaseError> {
    prop_assert!(d.foreground_px as usize <= img.w * img.h, "{what}: {d:?}");
    prop_assert_eq!(d.roi.is_some(), d.foreground_px > 0, "{}: {:?}", what, d);
    if let Some(r) = d.roi {
        prop_assert!(!r.is_empty(), "{what}: empty box {r:?}");
        prop_assert!(
            usize::from(r.x1) <= img.w && usize::from(r.y1) <= img.h,
            "{what}: box {r:?} outside the {}x{} frame",
            img.w,
            img.h
        );
        if rule == BoxRule::AllForeground {
            prop_assert!(r.area() >= d.foreground_px, "{what}: {d:?}");
        }
    }
    Ok(())
}

/// Runs every detector on `img` with `p` and checks each detection.
fn check_all_detectors(img: &Img, p: &Params) -> Result<(), TestCaseError> {
    let o = detect(Otsu { box_rule: p.rule }, img).expect("Otsu has no parameters");
    check_detection("otsu", img, p.rule, o)?;
    let a = detect(p.adaptive, img).expect("valid adaptive parameters");
    check_detection("adaptive", img, p.rule, a)?;
    let g = detect(p.wge, img).expect("valid WGE parameters");
    check_detection("wge", img, p.rule, g)?;
    match detect(p.dog, img) {
        Ok(d) => check_detection("dog", img, p.rule, d)?,
        Err(DetectError::InvalidParameter { .. }) => {
            // Out-of-bounds DoG parameters are an error value, never a panic.
            let dog = p.dog;
            let in_bounds = dog.sigma0_px >= 1.0 && dog.sigma_ratio >= 1.001;
            prop_assert!(
                !in_bounds || !(3..=8).contains(&dog.levels) || dog.sigma_px(dog.levels - 1) > 80.0,
                "DoG refused plausible parameters {dog:?}"
            );
        }
        Err(e @ DetectError::FrameTooLarge { .. }) => {
            prop_assert!(false, "frames here fit the reference capacity: {e}")
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------
// No panic, boxes inside the frame
// ---------------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(192))]

    #[test]
    fn small_frames_never_panic_and_boxes_fit(img in small_img(), p in params()) {
        check_all_detectors(&img, &p)?;
    }
}

proptest! {
    #![proptest_config(config(8))]

    #[test]
    fn full_frames_never_panic_and_boxes_fit(img in full_img(), p in params()) {
        check_all_detectors(&img, &p)?;
    }

    /// Any size the core accepts, 1×1 to 328×248 (thin strips, odd sizes, blocks wider
    /// than the frame), with random content and parameters.
    #[test]
    fn frames_of_any_size_never_panic_and_boxes_fit(
        w in 1usize..=FRAME_WIDTH,
        h in 1usize..=FRAME_HEIGHT,
        bits in bits(),
        seed in any::<u64>(),
        p in params(),
    ) {
        let img = any_frame(&mut Rng::new(seed), w, h, bits);
        check_all_detectors(&img, &p)?;
    }
}

// ---------------------------------------------------------------------------------
// Flat frames
// ---------------------------------------------------------------------------------

/// Checks that Otsu and WGE (which keeps flat frames empty when `min_gradient ≥ 1`)
/// find nothing in the flat frame `img` of DN `v`.
fn check_flat(img: &Img, v: u16, rule: BoxRule, wge: Wge) -> Result<(), TestCaseError> {
    let o = detect(Otsu { box_rule: rule }, img).unwrap();
    prop_assert_eq!(o.roi, None);
    prop_assert_eq!(o.foreground_px, 0);
    prop_assert_eq!(o.threshold, u32::from(v.min(img.max_dn())));
    let g = detect(wge, img).unwrap();
    prop_assert_eq!(g.roi, None);
    prop_assert_eq!(g.foreground_px, 0);
    Ok(())
}

fn flat_value(bits: u8) -> impl Strategy<Value = u16> {
    let max = max_dn(bits);
    prop_oneof![Just(0u16), Just(max), Just(u16::MAX), any::<u16>()]
}

fn flat_wge(rule: BoxRule) -> impl Strategy<Value = Wge> {
    (0.0f32..=1.0, 1u32..=5_000).prop_map(move |(drop_fraction, min_gradient)| Wge {
        drop_fraction,
        min_gradient,
        box_rule: rule,
    })
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn small_flat_frames_have_no_roi(
        (w, h, bits, v) in (1usize..=40, 1usize..=40, bits())
            .prop_flat_map(|(w, h, b)| (Just(w), Just(h), Just(b), flat_value(b))),
        (rule, wge) in rule().prop_flat_map(|r| (Just(r), flat_wge(r))),
    ) {
        check_flat(&Img::constant(w, h, bits, v), v, rule, wge)?;
    }
}

proptest! {
    #![proptest_config(config(8))]

    #[test]
    fn full_flat_frames_have_no_roi(
        (bits, v) in bits().prop_flat_map(|b| (Just(b), flat_value(b))),
        (rule, wge) in rule().prop_flat_map(|r| (Just(r), flat_wge(r))),
    ) {
        check_flat(&Img::constant(W, H, bits, v), v, rule, wge)?;
    }
}

// ---------------------------------------------------------------------------------
// IoU
// ---------------------------------------------------------------------------------

fn any_roi() -> impl Strategy<Value = Roi> {
    (0u16..=24, 0u16..=24, 0u16..=24, 0u16..=24).prop_map(|(a, b, c, d)| Roi::new(a, b, c, d))
}

/// IoU by counting pixels on a 25×25 grid.
fn iou_by_pixels(a: &Roi, b: &Roi) -> f64 {
    let (mut inter, mut union) = (0u32, 0u32);
    for y in 0..25 {
        for x in 0..25 {
            let (ia, ib) = (a.contains(x, y), b.contains(x, y));
            inter += u32::from(ia && ib);
            union += u32::from(ia || ib);
        }
    }
    if union == 0 {
        0.0
    } else {
        f64::from(inter) / f64::from(union)
    }
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn iou_algebra(a in any_roi(), b in any_roi()) {
        let (ab, ba) = (a.iou(&b), b.iou(&a));
        prop_assert_eq!(ab, ba);
        prop_assert!((0.0..=1.0).contains(&ab), "IoU {}", ab);
        prop_assert!((f64::from(ab) - iou_by_pixels(&a, &b)).abs() < 1e-6);
        prop_assert_eq!(a.iou(&a), if a.is_empty() { 0.0 } else { 1.0 });
        prop_assert_eq!(a.iou(&Roi::EMPTY), 0.0);
        prop_assert_eq!(Roi::EMPTY.iou(&Roi::EMPTY), 0.0);
        // Two different empty boxes.
        prop_assert_eq!(Roi::new(a.x0, a.y0, a.x0, a.y1).iou(&Roi::new(b.x0, b.y0, b.x1, b.y0)), 0.0);
        // Hull and intersection agree with containment.
        let hull = a.hull(&b);
        prop_assert!(hull.contains_roi(&a) && hull.contains_roi(&b));
        let inter = a.intersection(&b);
        prop_assert!(a.contains_roi(&inter) && b.contains_roi(&inter));
        if ab > 0.0 {
            prop_assert!(!inter.is_empty());
        }
    }
}

// ---------------------------------------------------------------------------------
// Otsu under positive affine maps
// ---------------------------------------------------------------------------------

/// A frame whose DN fit `max_dn / 8`, a gain in 1..=8 and an offset that keep
/// `a·v + b ≤ max_dn`.
fn affine_case() -> impl Strategy<Value = (Img, u16, u16)> {
    (1usize..=40, 1usize..=40, 8u8..=16, 1u16..=8, any::<u16>()).prop_flat_map(
        |(w, h, bits, a, b_raw)| {
            let top = max_dn(bits) / 8;
            let px = prop_oneof![
                vec(0..=top, w * h),
                vec(0..=top, 1..5).prop_flat_map(move |levels| vec(select(levels), w * h)),
            ];
            px.prop_map(move |px| {
                let vmax = px.iter().copied().max().unwrap_or(0);
                let room = max_dn(bits) - a * vmax;
                let b = b_raw % (room + 1);
                (Img { px, w, h, bits }, a, b)
            })
        },
    )
}

proptest! {
    #![proptest_config(config(160))]

    #[test]
    fn otsu_is_invariant_under_positive_affine_maps((img, a, b) in affine_case(), rule in rule()) {
        let mapped = Img {
            px: img.px.iter().map(|&v| a * v + b).collect(),
            ..img.clone()
        };
        let det = Otsu { box_rule: rule };
        let before = observe(det, &img);
        let after = observe(det, &mapped);
        prop_assert!(before.mask == after.mask, "mask changed under {}·v + {}", a, b);
        prop_assert_eq!(before.detection.roi, after.detection.roi);
        prop_assert_eq!(before.detection.foreground_px, after.detection.foreground_px);
        prop_assert_eq!(
            after.detection.threshold,
            u32::from(a) * before.detection.threshold + u32::from(b)
        );
    }
}

// ---------------------------------------------------------------------------------
// Boxes follow a translated target
// ---------------------------------------------------------------------------------

/// A frame size, a rectangle size and two placements of it, each at least 2 pixels
/// from the frame's edges.
fn translation_case(full: bool) -> impl Strategy<Value = (usize, usize, Roi, Roi)> {
    let size = if full {
        (Just(W), Just(H)).boxed()
    } else {
        (8usize..=40, 8usize..=40).boxed()
    };
    size.prop_flat_map(|(w, h)| (Just(w), Just(h), 1..=w - 4, 1..=h - 4))
        .prop_flat_map(|(w, h, rw, rh)| {
            let place = (2..=w - 2 - rw, 2..=h - 2 - rh);
            (Just(w), Just(h), Just(rw), Just(rh), place.clone(), place)
        })
        .prop_map(|(w, h, rw, rh, (x0, y0), (x1, y1))| {
            let r =
                |x: usize, y: usize| Roi::new(x as u16, y as u16, (x + rw) as u16, (y + rh) as u16);
            (w, h, r(x0, y0), r(x1, y1))
        })
}

fn target_frame(w: usize, h: usize, rect: Roi) -> Img {
    let mut img = Img::constant(w, h, 14, 500);
    img.fill(rect, 12_500);
    img
}

fn shift(r: Roi, from: Roi, to: Roi) -> Roi {
    let dx = i32::from(to.x0) - i32::from(from.x0);
    let dy = i32::from(to.y0) - i32::from(from.y0);
    let m = |v: u16, d: i32| (i32::from(v) + d) as u16;
    Roi::new(m(r.x0, dx), m(r.y0, dy), m(r.x1, dx), m(r.y1, dy))
}

fn grown(r: Roi) -> Roi {
    Roi::new(r.x0 - 1, r.y0 - 1, r.x1 + 1, r.y1 + 1)
}

fn check_translation(
    w: usize,
    h: usize,
    a: Roi,
    b: Roi,
    rule: BoxRule,
    block: u16,
) -> Result<(), TestCaseError> {
    let (fa, fb) = (target_frame(w, h, a), target_frame(w, h, b));
    let moved = |d: &Detection| d.roi.map(|r| shift(r, a, b));

    let otsu = Otsu { box_rule: rule };
    let (da, db) = (detect(otsu, &fa).unwrap(), detect(otsu, &fb).unwrap());
    prop_assert_eq!(da.roi, Some(a));
    prop_assert_eq!(db.roi, moved(&da));

    // Blocks up to 41 see a dark strip beside every edge pixel of the target.
    let adaptive = Adaptive {
        block,
        box_rule: rule,
        ..Adaptive::default()
    };
    let (da, db) = (
        detect(adaptive, &fa).unwrap(),
        detect(adaptive, &fb).unwrap(),
    );
    prop_assert_eq!(da.roi, Some(a), "{:?}", adaptive);
    prop_assert_eq!(db.roi, moved(&da), "{:?}", adaptive);

    // Default WGE: the interior gradients are the same multiset, so the boxes move.
    let wge = Wge::default().with_rule(rule);
    let (da, db) = (detect(wge, &fa).unwrap(), detect(wge, &fb).unwrap());
    prop_assert_eq!(db.roi, moved(&da));
    // Keeping every non-zero gradient: the ring around the target.
    let keep_all = Wge {
        drop_fraction: 0.0,
        min_gradient: 1,
        box_rule: rule,
    };
    let (da, db) = (
        detect(keep_all, &fa).unwrap(),
        detect(keep_all, &fb).unwrap(),
    );
    prop_assert_eq!(da.roi, Some(grown(a)));
    prop_assert_eq!(db.roi, Some(grown(b)));
    Ok(())
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn small_boxes_follow_the_target(
        (w, h, a, b) in translation_case(false),
        rule in rule(),
        k in 1u16..=20,
    ) {
        check_translation(w, h, a, b, rule, 2 * k + 1)?;
    }
}

proptest! {
    #![proptest_config(config(8))]

    #[test]
    fn full_frame_boxes_follow_the_target(
        (w, h, a, b) in translation_case(true),
        rule in rule(),
        k in 1u16..=20,
    ) {
        check_translation(w, h, a, b, rule, 2 * k + 1)?;
    }
}
