//! Fuzz target: `auto` on arbitrary frames and priors never panics, and its box lies
//! inside the frame.
//!
//! Input layout: byte 0 width − 1 (mod 328), byte 1 height − 1 (mod 248), byte 2 bit
//! depth − 1 (mod 16), byte 3 flags (bit 0: a prior is given), bytes 4..12 the prior
//! `x0, y0, x1, y1` (little-endian u16), bytes 12 and 13 `coarse_sigma` and `fine_sigma`
//! (mod 40, + 1), the rest the DN (little-endian u16, repeated to fill the frame; none:
//! a black frame).
#![no_main]

use libfuzzer_sys::fuzz_target;
use tirroi_core::roi::auto::{Auto, AutoScratch};
use tirroi_core::{Detector, Frame, Roi};

fuzz_target!(|data: &[u8]| {
    if data.len() < 14 {
        return;
    }
    let w = 1 + usize::from(data[0]) % 328;
    let h = 1 + usize::from(data[1]) % 248;
    let bits = 1 + data[2] % 16;
    let word = |i: usize| u16::from_le_bytes([data[i], data[i + 1]]);
    let prior = (data[3] & 1 == 1).then(|| Roi::new(word(4), word(6), word(8), word(10)));
    let auto = Auto {
        prior,
        coarse_sigma: 1 + u16::from(data[12] % 40),
        fine_sigma: 1 + u16::from(data[13] % 40),
        ..Auto::default()
    };
    let dn: Vec<u16> = data[14..]
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    let pixels: Vec<u16> = (0..w * h)
        .map(|i| if dn.is_empty() { 0 } else { dn[i % dn.len()] })
        .collect();
    let frame = Frame::new(&pixels, w, h, bits).expect("valid dimensions");
    let mut scratch = Box::new(AutoScratch::new());
    let d = auto.detect(&frame, &mut scratch).expect("valid parameters");
    if let Some(r) = d.roi {
        assert!(!r.is_empty(), "{r:?}");
        assert!(
            usize::from(r.x1) <= w && usize::from(r.y1) <= h,
            "{r:?} in {w}x{h}"
        );
    }
    // The same frame again in the same scratch gives the same detection.
    assert_eq!(auto.detect(&frame, &mut scratch).unwrap(), d);
});
