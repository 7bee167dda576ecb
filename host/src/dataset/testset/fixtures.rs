//! The procedural family: [`crate::imaging::fixture`] frames with every parameter the
//! generator has drawn from a seed.
//!
//! Per frame (index i, seed S; a PCG stream seeded from both): background Earth
//! ([`EARTH_SHARE`]) or deep space; the body's width log-uniform in
//! [`BODY_WIDTH_PX`] and its height 0.6–1.2 × the width, placed uniformly so the
//! body and its cylinder stay in the frame; Earth mean DN and texture amplitude uniform
//! in [`EARTH_DN`] and [`TEXTURE_DN`]; the target's DN from a contrast drawn relative
//! to the texture (warm, or cold with [`COLD_SHARE`]) or saturated ([`SATURATED_SHARE`],
//! above full scale so the faces clip); noise σ uniform in [`NOISE_DN`]. Frames marked
//! without a target keep their background and noise and drop the body.

use indicatif::ProgressBar;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use tirroi_core::Roi;
use tirroi_core::frame::{DEFAULT_BIT_DEPTH, FRAME_HEIGHT, FRAME_WIDTH};

use super::{FixtureParams, Kind, TestFrame, TestRecord, box_array, file_name};
use crate::imaging::fixture::{self, Background, FixtureSpec};
use crate::seed::splitmix64;

/// Share of frames over the Earth (the rest over deep space): the Earth is the hard
/// case, so it gets the larger share.
pub const EARTH_SHARE: f64 = 0.6;
/// Body (cube) width, px, log-uniform: a 4 px far target to a 140 px close one (the
/// generator's own standard set spans 6–140 px).
pub const BODY_WIDTH_PX: (f64, f64) = (4.0, 140.0);
/// Mean DN of the Earth texture (14-bit), uniform.
pub const EARTH_DN: (f64, f64) = (3_000.0, 10_000.0);
/// Peak-to-peak texture amplitude, DN, uniform (the standard set uses 5 000).
pub const TEXTURE_DN: (f64, f64) = (1_000.0, 8_000.0);
/// Warm target: (target − Earth mean) / (texture peak-to-peak / 2), uniform: from just
/// above the texture's mean (0.5) to well above its brightest cells (3).
pub const WARM_CONTRAST: (f64, f64) = (0.5, 3.0);
/// Cold target (an eclipsed spacecraft over a warm Earth): the same ratio, negative.
pub const COLD_CONTRAST: (f64, f64) = (-2.0, -1.0);
/// Share of targets colder than the Earth.
pub const COLD_SHARE: f64 = 0.1;
/// Share of saturated targets: their brightest face at 1.0–1.4 × full scale.
pub const SATURATED_SHARE: f64 = 0.15;
/// Deep-space frames: the target's DN, uniform (the space level is 300 DN).
pub const SPACE_TARGET_DN: (f64, f64) = (1_000.0, 15_000.0);
/// Additive noise σ, DN, uniform (the standard set uses 20).
pub const NOISE_DN: (f64, f64) = (5.0, 60.0);
/// Salt of the per-frame seed.
const FIXTURE_SALT: u64 = 0xF1C5_0000_0000_0016;

/// The spec of frame `index` of the family of `seed` (`no_target`: the body left out).
pub fn spec(seed: u64, index: usize, no_target: bool) -> FixtureSpec {
    let frame_seed = splitmix64(seed ^ FIXTURE_SALT ^ (index as u64).wrapping_mul(0x9E37));
    let mut rng = Pcg64::seed_from_u64(frame_seed);
    let max_dn = f64::from((1u32 << DEFAULT_BIT_DEPTH) - 1);
    let background = if rng.gen_bool(EARTH_SHARE) {
        Background::Earth
    } else {
        Background::DeepSpace
    };
    let w = (rng.gen_range(BODY_WIDTH_PX.0.ln()..BODY_WIDTH_PX.1.ln())).exp();
    let h = (w * rng.gen_range(0.6..1.2)).max(2.0);
    let (w, h) = (w.round() as u16, h.round() as u16);
    // Body plus its cylinder (half the body's width) inside the frame.
    let span_x = FRAME_WIDTH as u16 - (w + w / 2) - 1;
    let span_y = FRAME_HEIGHT as u16 - h - 1;
    let x0 = rng.gen_range(1..=span_x);
    let y0 = rng.gen_range(1..=span_y);
    let earth_dn = rng.gen_range(EARTH_DN.0..EARTH_DN.1);
    let texture_dn = rng.gen_range(TEXTURE_DN.0..TEXTURE_DN.1);
    let u: f64 = rng.r#gen();
    let target_dn = if u < SATURATED_SHARE {
        max_dn * rng.gen_range(1.0..1.4)
    } else if background == Background::DeepSpace {
        rng.gen_range(SPACE_TARGET_DN.0..SPACE_TARGET_DN.1)
    } else if u < SATURATED_SHARE + COLD_SHARE {
        earth_dn + rng.gen_range(COLD_CONTRAST.0..COLD_CONTRAST.1) * texture_dn / 2.0
    } else {
        earth_dn + rng.gen_range(WARM_CONTRAST.0..WARM_CONTRAST.1) * texture_dn / 2.0
    };
    let noise_dn = rng.gen_range(NOISE_DN.0..NOISE_DN.1);
    FixtureSpec {
        background,
        body: if no_target {
            Roi::EMPTY
        } else {
            Roi::new(x0, y0, x0 + w, y0 + h)
        },
        target_dn: target_dn.clamp(fixture::SPACE_DN + 200.0, f64::from(u16::MAX)) as u16,
        earth_dn: earth_dn as u16,
        texture_dn: texture_dn as u16,
        noise_dn,
        seed: rng.r#gen(),
    }
}

/// The frames of the family (`none[i]`: frame i without a target).
pub fn frames(seed: u64, none: &[bool], bar: &ProgressBar) -> Vec<TestFrame> {
    none.par_iter()
        .enumerate()
        .map(|(i, &no_target)| {
            let s = spec(seed, i, no_target);
            let fx = fixture::render(&s);
            let max_dn = (1u16 << DEFAULT_BIT_DEPTH) - 1;
            let on_earth = |x: usize, y: usize| {
                s.background == Background::Earth
                    && fixture::on_earth_disc(x, y)
                    && !fx.truth.contains(x as u16, y as u16)
            };
            let earth_px = (0..FRAME_HEIGHT)
                .flat_map(|y| (0..FRAME_WIDTH).map(move |x| (x, y)))
                .filter(|&(x, y)| on_earth(x, y))
                .count();
            let mask_px = fx.truth.area() as usize;
            let record = TestRecord {
                index: i,
                file: file_name(i),
                kind: Kind::Fixtures.name().into(),
                background: match s.background {
                    Background::Earth => "earth",
                    Background::DeepSpace => "space",
                }
                .into(),
                bbox: box_array(fx.truth),
                bbox_quarter: box_array(fx.truth),
                target: if no_target { "none" } else { "fixture" }.into(),
                readout: "fixture".into(),
                bits: fx.frame.bits,
                gain_factor: 1.0,
                noise_seed: Some(s.seed),
                noise_sigma_dn: s.noise_dn,
                earth_fraction: earth_px as f64 / (FRAME_WIDTH * FRAME_HEIGHT) as f64,
                saturated_px: fx.frame.pixels.iter().filter(|&&v| v >= max_dn).count(),
                mask_px,
                fixture: Some(FixtureParams {
                    target_dn: s.target_dn,
                    earth_dn: s.earth_dn,
                    texture_dn: s.texture_dn,
                    noise_dn: s.noise_dn,
                    seed: s.seed,
                }),
                ..TestRecord::default()
            };
            bar.inc(1);
            TestFrame {
                frame: fx.frame,
                record,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_are_seeded_and_vary() {
        let a: Vec<FixtureSpec> = (0..50).map(|i| spec(7, i, false)).collect();
        let b: Vec<FixtureSpec> = (0..50).map(|i| spec(7, i, false)).collect();
        assert_eq!(a, b);
        assert_ne!(a, (0..50).map(|i| spec(8, i, false)).collect::<Vec<_>>());
        let earth = a
            .iter()
            .filter(|s| s.background == Background::Earth)
            .count();
        assert!((15..=45).contains(&earth), "{earth} of 50 over the Earth");
        let widths: Vec<u16> = a.iter().map(|s| s.body.width()).collect();
        assert!(widths.iter().any(|&w| w <= 10) && widths.iter().any(|&w| w >= 60));
        let saturated = a.iter().filter(|s| s.target_dn > 16_383).count();
        assert!(saturated >= 2, "{saturated} saturated of 50");
        for s in &a {
            // Body and cylinder inside the frame.
            assert!(s.body.x1 + s.body.width() / 2 < FRAME_WIDTH as u16);
            assert!(s.body.y1 < FRAME_HEIGHT as u16 && !s.body.is_empty());
        }
        assert!(spec(7, 3, true).body.is_empty());
    }
}
