//! The detector registry: adding a detector is its module plus one registry entry.
//!
//! A toy detector (`peak`: pixels within `band_dn` of the frame's brightest DN) is
//! registered beside the core's six in a registry of this test's own; everything that
//! dispatches on a method (names, parsing, scratch bytes, defaults, validation, the
//! scratch bank) comes from that one entry, and the toy's box is checked against a
//! brute-force box of the same rule.

use core::fmt;

use tirroi_core::capacity::{Cap640x512, ConstInit};
use tirroi_core::roi::{self, BoxRule, DetectError, Detector, Scratch};
use tirroi_core::{Frame, FrameCapacity, Reference, Roi};

/// The toy: foreground = DN ≥ (brightest DN − `band_dn`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Peak {
    /// Width of the band below the brightest DN, in DN: 0..=1000.
    pub band_dn: u16,
    /// Mask-to-box rule.
    pub box_rule: BoxRule,
}

impl Default for Peak {
    fn default() -> Self {
        Peak {
            band_dn: 10,
            box_rule: BoxRule::AllForeground,
        }
    }
}

impl fmt::Display for Peak {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "band_dn={} box={}", self.band_dn, self.box_rule)
    }
}

/// The toy's buffers at capacity `C`: one mask row (`C::Row<bool>`, `[bool; W]`).
#[derive(Debug, Clone)]
pub struct PeakWork<C: FrameCapacity> {
    mask: C::Row<bool>,
}

impl<C: FrameCapacity> ConstInit for PeakWork<C> {
    const INIT: Self = PeakWork {
        mask: ConstInit::INIT,
    };
}

impl Detector for Peak {
    type Work<C: FrameCapacity> = PeakWork<C>;
    const NAME: &'static str = "peak";

    fn validate(&self) -> Result<(), DetectError> {
        if self.band_dn > 1000 {
            return Err(DetectError::InvalidParameter {
                name: "band_dn",
                expected: "0..=1000 DN",
            });
        }
        Ok(())
    }

    fn box_rule(&self) -> BoxRule {
        self.box_rule
    }

    fn set_box_rule(&mut self, rule: BoxRule) {
        self.box_rule = rule;
    }

    fn foreground<C: FrameCapacity, F: FnMut(usize, &[bool])>(
        &self,
        frame: &Frame<'_>,
        work: &mut PeakWork<C>,
        mut sink: F,
    ) -> u32 {
        let peak = frame.pixels().iter().copied().max().unwrap_or(0);
        let threshold = peak.saturating_sub(self.band_dn);
        for (y, row) in frame.rows().enumerate() {
            let mask = &mut work.mask.as_mut()[..row.len()];
            for (m, &v) in mask.iter_mut().zip(row) {
                *m = v >= threshold;
            }
            sink(y, mask);
        }
        u32::from(threshold)
    }
}

tirroi_core::detector_registry! {
    /// The core's six and the toy.
    pub enum Method;
    /// Their parameters.
    pub enum Params;
    /// Their scratch.
    pub struct Detectors;
    /// Otsu.
    Otsu(otsu) => roi::otsu::Otsu,
    /// Adaptive.
    Adaptive(adaptive) => roi::adaptive::Adaptive,
    /// WGE.
    Wge(wge) => roi::wge::Wge,
    /// DoG.
    Dog(dog) => roi::dog::Dog,
    /// auto.
    Auto(auto) => roi::auto::Auto,
    /// auto-v2.
    AutoV2(auto_v2) => roi::auto::learned::AutoV2,
    /// The toy: the one line that adds it.
    Peak(peak) => Peak,
}

/// A 40×30 frame: background 100 DN with a gentle ramp, a 500 DN block at
/// x 5..12, y 4..9 and a 495 DN pixel at (30, 20).
fn scene() -> Vec<u16> {
    let (w, h) = (40, 30);
    let mut px: Vec<u16> = (0..w * h).map(|i| 100 + (i % w) as u16 / 8).collect();
    for y in 4..9 {
        for x in 5..12 {
            px[y * w + x] = 500;
        }
    }
    px[20 * w + 30] = 495;
    px
}

/// The box of all pixels ≥ `t` and of the largest 8-connected group of them, by brute
/// force (flood fill).
fn brute_force(px: &[u16], w: usize, h: usize, t: u16) -> (Option<Roi>, Option<Roi>) {
    let on = |x: usize, y: usize| px[y * w + x] >= t;
    let mut hull: Option<Roi> = None;
    let mut seen = vec![false; w * h];
    let mut best: Option<(usize, Roi)> = None;
    for y in 0..h {
        for x in 0..w {
            if !on(x, y) {
                continue;
            }
            let cell = Roi::new(x as u16, y as u16, x as u16 + 1, y as u16 + 1);
            hull = Some(hull.map_or(cell, |r| r.hull(&cell)));
            if seen[y * w + x] {
                continue;
            }
            let (mut stack, mut area, mut roi) = (vec![(x, y)], 0, cell);
            seen[y * w + x] = true;
            while let Some((cx, cy)) = stack.pop() {
                area += 1;
                roi = roi.hull(&Roi::new(
                    cx as u16,
                    cy as u16,
                    cx as u16 + 1,
                    cy as u16 + 1,
                ));
                for (dx, dy) in (-1i32..=1).flat_map(|dx| (-1i32..=1).map(move |dy| (dx, dy))) {
                    let (nx, ny) = (cx as i32 + dx, cy as i32 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i32 || ny >= h as i32 {
                        continue;
                    }
                    let (nx, ny) = (nx as usize, ny as usize);
                    if on(nx, ny) && !seen[ny * w + nx] {
                        seen[ny * w + nx] = true;
                        stack.push((nx, ny));
                    }
                }
            }
            if best.is_none_or(|(a, _)| area > a) {
                best = Some((area, roi));
            }
        }
    }
    (hull, best.map(|(_, r)| r))
}

#[test]
fn one_entry_gives_names_parsing_defaults_and_scratch_bytes() {
    assert_eq!(Method::ALL.len(), 7);
    assert_eq!(Method::ALL[6], Method::Peak);
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(
        names,
        ["otsu", "adaptive", "wge", "dog", "auto", "auto-v2", "peak"]
    );
    for m in Method::ALL {
        assert_eq!(Method::from_name(m.name()), Some(m));
        assert_eq!(m.to_string(), m.name());
        assert_eq!(m.default_params().method(), m);
        assert!(m.default_params().validate().is_ok(), "{m}");
    }
    assert_eq!(Method::from_name("Peak"), None);
    // The core's six keep their registry's sizes; the toy's is its scratch type's.
    for (mine, core) in Method::ALL.iter().zip(tirroi_core::Method::ALL) {
        assert_eq!(mine.name(), core.name());
        assert_eq!(mine.scratch_bytes(), core.scratch_bytes());
    }
    assert_eq!(
        Method::Peak.scratch_bytes(),
        core::mem::size_of::<Scratch<PeakWork<Reference>>>()
    );
    assert_eq!(
        Method::Peak.default_params().to_string(),
        "band_dn=10 box=all-foreground"
    );
}

#[test]
fn the_bank_runs_the_toy_like_a_brute_force_reference() {
    let (w, h) = (40, 30);
    let px = scene();
    let frame = Frame::new(&px, w, h, 14).unwrap();
    let mut bank = Box::new(Detectors::new());
    for band_dn in [0u16, 5, 10, 400, 1000] {
        for rule in BoxRule::ALL {
            let mut params = Params::Peak(Peak {
                band_dn,
                ..Peak::default()
            });
            params.set_box_rule(rule);
            assert_eq!(params.box_rule(), rule);
            let found = bank.detect(&params, &frame).unwrap();
            let t = 500u16.saturating_sub(band_dn);
            let (hull, largest) = brute_force(&px, w, h, t);
            let expected = match rule {
                BoxRule::AllForeground => hull,
                BoxRule::LargestComponent => largest,
            };
            assert_eq!(found.roi, expected, "band {band_dn} {rule}");
            assert_eq!(found.threshold, u32::from(t));
            let count = px.iter().filter(|&&v| v >= t).count();
            assert_eq!(found.foreground_px as usize, count);
        }
    }
    // The toy's bounds are checked through the registry like any detector's.
    let bad = Params::Peak(Peak {
        band_dn: 1001,
        ..Peak::default()
    });
    assert_eq!(
        bank.detect(&bad, &frame),
        Err(DetectError::InvalidParameter {
            name: "band_dn",
            expected: "0..=1000 DN"
        })
    );
    // The core's detectors run from the same bank, with the same boxes as the core's
    // own registry.
    let mut core_bank = Box::new(tirroi_core::roi::Detectors::new());
    for (mine, core) in Method::ALL.iter().zip(tirroi_core::Method::ALL) {
        let a = bank.detect(&mine.default_params(), &frame).unwrap();
        let b = core_bank.detect(&core.default_params(), &frame).unwrap();
        assert_eq!(a, b, "{core}");
    }
    // A bank of a larger capacity: the same boxes; the toy's row grows with it.
    let mut big = Box::new(Detectors::<Cap640x512>::for_capacity());
    for m in Method::ALL {
        let a = bank.detect(&m.default_params(), &frame).unwrap();
        assert_eq!(big.detect(&m.default_params(), &frame).unwrap(), a, "{m}");
    }
    assert_eq!(
        Method::Peak.scratch_bytes_for::<Cap640x512>() - Method::Peak.scratch_bytes(),
        core::mem::size_of::<Scratch<PeakWork<Cap640x512>, Cap640x512>>()
            - core::mem::size_of::<Scratch<PeakWork<Reference>>>()
    );
}
