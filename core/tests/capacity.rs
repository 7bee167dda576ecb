//! Capacities above the reference 328×248: every detector at 640×512 (and 1024×768)
//! against the brute-force references of `common`, counters that would overflow
//! 16 bits, identical results whatever the capacity, and `FrameTooLarge` above it.

mod common;

use common::*;
use tirroi_core::capacity::{Cap640x512, Cap1024x768};
use tirroi_core::roi::adaptive::{Adaptive, AdaptiveScratch};
use tirroi_core::roi::auto::{Auto, AutoScratch};
use tirroi_core::roi::dog::{Dog, DogScratch};
use tirroi_core::roi::otsu::{Otsu, OtsuScratch};
use tirroi_core::roi::wge::{Wge, WgeScratch};
use tirroi_core::roi::{Detectors, Scratch};
use tirroi_core::{BoxRule, DetectError, Detector, Frame, FrameCapacity, Method, Roi};

const RULES: [BoxRule; 2] = BoxRule::ALL;

fn otsu_at<C: FrameCapacity>(img: &Img, what: &str) {
    let want_t = otsu_expected_threshold(img);
    let want_mask = mask_above(img, want_t);
    let mut s = Box::new(OtsuScratch::<C>::for_capacity());
    for rule in RULES {
        let det = Otsu { box_rule: rule };
        let obs = observe_in(det, img, &mut s);
        assert_eq!(obs.detection.threshold, want_t, "{what}: threshold");
        assert!(obs.mask == want_mask, "{what}: mask");
        assert_eq!(
            obs.detection.roi,
            box_by_rule(rule, &want_mask, img.w, img.h),
            "{what}: {rule} box"
        );
    }
}

#[test]
fn otsu_at_640x512_matches_exhaustive_search() {
    let (w, h) = (640, 512);
    let mut rng = Rng::new(640);
    otsu_at::<Cap640x512>(&bimodal_frame(&mut rng, w, h, 14, 0.2), "bimodal");
    otsu_at::<Cap640x512>(&textured_frame(&mut rng, w, h, 14), "textured");
    // Nearly flat: 3/4 of the pixels at one DN, the rest a few DN above it in the same
    // coarse bin, so the refinement pass counts > 2^16 pixels of one DN per lane.
    let mut img = Img::constant(w, h, 14, 1000);
    for i in 0..w * h {
        if i % 4 == 3 {
            img.px[i] = 1001 + (i % 7) as u16;
        }
    }
    img.fill(Roi::new(200, 150, 300, 260), 1003);
    otsu_at::<Cap640x512>(&img, "near-flat");
    let mut img = Img::constant(w, h, 16, 40_000);
    for i in (0..w * h).step_by(3) {
        img.px[i] = 40_001;
    }
    otsu_at::<Cap640x512>(&img, "two adjacent DN, 16-bit");
}

#[test]
fn otsu_at_1024x768_matches_exhaustive_search() {
    let mut rng = Rng::new(1024);
    let img = bimodal_frame(&mut rng, 1024, 768, 14, 0.1);
    otsu_at::<Cap1024x768>(&img, "bimodal 1024x768");
}

#[test]
fn adaptive_at_640x512_matches_the_naive_reference() {
    let mut rng = Rng::new(41);
    let img = textured_frame(&mut rng, 640, 512, 14);
    let mut s = Box::new(AdaptiveScratch::<Cap640x512>::for_capacity());
    for (block, offset) in [(41u16, 64), (249, 0), (3, -5)] {
        let want = adaptive_naive(&img.px, img.w, img.h, img.bits, block, offset);
        for rule in RULES {
            let det = Adaptive {
                block,
                offset_dn: offset,
                box_rule: rule,
            };
            let obs = observe_in(det, &img, &mut s);
            assert!(obs.mask == want, "block {block} offset {offset}: mask");
            assert_box_rule(&det, &obs, &img, "adaptive 640x512");
        }
    }
    // Saturated 16-bit frame with the largest block: window sums near 2^32.
    let mut img = Img::constant(640, 512, 16, u16::MAX);
    img.fill(Roi::new(10, 10, 400, 300), 1);
    let want = adaptive_naive(&img.px, img.w, img.h, 16, 249, 0);
    let obs = observe_in(
        Adaptive {
            block: 249,
            offset_dn: 0,
            box_rule: BoxRule::AllForeground,
        },
        &img,
        &mut s,
    );
    assert!(obs.mask == want, "saturated 16-bit: mask");
}

#[test]
fn wge_at_640x512_matches_the_naive_reference() {
    let mut rng = Rng::new(97);
    let mut s = Box::new(WgeScratch::<Cap640x512>::for_capacity());
    for img in [
        textured_frame(&mut rng, 640, 512, 14),
        bimodal_frame(&mut rng, 640, 512, 14, 0.3),
        Img::constant(640, 512, 14, 77),
    ] {
        for (drop, min) in [(0.97f32, 48u32), (0.5, 0)] {
            let want = wge_naive(&img.px, img.w, img.h, img.bits, drop, min);
            for rule in RULES {
                let det = Wge {
                    drop_fraction: drop,
                    min_gradient: min,
                    box_rule: rule,
                };
                let obs = observe_in(det, &img, &mut s);
                assert_eq!(obs.detection.threshold, want.threshold);
                assert!(obs.mask == want.mask, "drop {drop}: mask");
                assert_box_rule(&det, &obs, &img, "wge 640x512");
            }
        }
    }
}

#[test]
fn dog_at_640x512_finds_a_disc_and_boxes_its_own_mask() {
    let mut s = Box::new(DogScratch::<Cap640x512>::for_capacity());
    for (cx, cy, r) in [(500.0, 400.0, 30.0), (120.0, 90.0, 16.0)] {
        let (img, truth) = disc_frame(640, 512, cx, cy, r);
        for rule in RULES {
            let det = Dog {
                box_rule: rule,
                ..Dog::default()
            };
            let obs = observe_in(det, &img, &mut s);
            assert_box_rule(&det, &obs, &img, "dog 640x512");
            let roi = obs.detection.roi.expect("a box");
            assert!(roi.iou(&truth) > 0.5, "{roi:?} vs {truth:?}");
        }
    }
}

/// A bright rectangle with ±3 DN noise on a 100 DN sky: `auto` boxes it exactly.
fn auto_rect<C: FrameCapacity>(w: usize, h: usize, rect: Roi) {
    let px: Vec<u16> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let n = ((x * 7 + y * 13) % 7) as u16;
            if rect.contains(x as u16, y as u16) {
                5000 + n
            } else {
                100 + n
            }
        })
        .collect();
    let frame = Frame::new(&px, w, h, 14).unwrap();
    let mut s = Box::new(AutoScratch::<C>::for_capacity());
    let d = Auto::default().detect(&frame, &mut s).unwrap();
    assert_eq!(d.roi, Some(rect), "{w}x{h}");
    // Tracking from the box finds it again.
    let t = Auto::default()
        .with_prior(Some(rect))
        .detect(&frame, &mut s)
        .unwrap();
    assert_eq!(t.roi, Some(rect), "{w}x{h} tracking");
}

#[test]
fn auto_at_640x512_and_1024x768_boxes_a_rectangle_exactly() {
    auto_rect::<Cap640x512>(640, 512, Roi::new(400, 300, 520, 420));
    // Touching the right part of a 256-cell-wide plane (cell coordinates up to 255).
    auto_rect::<Cap1024x768>(1024, 768, Roi::new(900, 600, 1000, 700));
    auto_rect::<Cap1024x768>(1024, 768, Roi::new(100, 80, 700, 500));
}

#[test]
fn every_detector_refuses_a_frame_above_its_capacity() {
    let px = vec![100u16; 329 * 248];
    let frame = Frame::new(&px, 329, 248, 14).unwrap();
    let mut bank = Box::new(Detectors::new());
    for m in Method::ALL {
        assert_eq!(
            bank.detect(&m.default_params(), &frame),
            Err(DetectError::FrameTooLarge {
                width: 329,
                height: 248,
                capacity_width: 328,
                capacity_height: 248
            }),
            "{m}"
        );
    }
    let px = vec![100u16; 640 * 513];
    let frame = Frame::new(&px, 640, 513, 14).unwrap();
    let mut big = Box::new(Detectors::<Cap640x512>::for_capacity());
    for m in Method::ALL {
        assert!(matches!(
            big.detect(&m.default_params(), &frame),
            Err(DetectError::FrameTooLarge {
                capacity_height: 512,
                ..
            })
        ));
    }
}

#[test]
fn a_larger_capacity_gives_the_same_results_on_reference_frames() {
    let mut rng = Rng::new(7);
    let mut small = Box::new(Detectors::new());
    let mut big = Box::new(Detectors::<Cap640x512>::for_capacity());
    for img in [
        textured_frame(&mut rng, 328, 248, 14),
        bimodal_frame(&mut rng, 328, 248, 14, 0.1),
        disc_frame(328, 248, 150.0, 110.0, 24.0).0,
    ] {
        for m in Method::ALL {
            let mut p = m.default_params();
            for rule in RULES {
                p.set_box_rule(rule);
                let a = small.detect(&p, &img.frame()).unwrap();
                assert_eq!(big.detect(&p, &img.frame()).unwrap(), a, "{m} {rule}");
            }
        }
    }
}

#[test]
fn scratch_bytes_per_capacity() {
    // The reference keeps its bytes (x86-64 figures in lib.rs); larger capacities grow.
    for m in Method::ALL {
        let r = m.scratch_bytes();
        assert_eq!(r, m.scratch_bytes_for::<tirroi_core::Reference>());
        assert!(m.scratch_bytes_for::<Cap640x512>() > r, "{m}");
        assert!(m.scratch_bytes_for::<Cap1024x768>() > m.scratch_bytes_for::<Cap640x512>());
    }
    assert_eq!(
        core::mem::size_of::<Scratch<<Otsu as Detector>::Work<Cap640x512>, Cap640x512>>(),
        Method::Otsu.scratch_bytes_for::<Cap640x512>()
    );
}
