//! # tirroi-panic-never
//!
//! A link-time proof that the flight calls cannot panic (issue 18, part 1): this
//! bare-metal binary calls what the firmware calls — each detector through the
//! firmware's registry calls ([`Detectors::run`] for the paper's four and `auto`,
//! [`Detectors::track`] for `auto` and `auto-v2` with a prior) and the on-board camera model
//! ([`synth::setup`], [`synth::expose_scene`]) — on inputs the optimiser cannot see
//! ([`black_box`]), and its panic handler calls a function that exists nowhere. The
//! release build (fat LTO, `panic = "abort"`, as the firmware's) drops every panic
//! branch the compiler proves unreachable; if one is left, the panic handler is still
//! referenced and the link fails with `undefined symbol: tirroi_panic_path_found`.
//!
//! Which components are linked is chosen by cargo features (`otsu`, `adaptive`, `wge`,
//! `dog`, `auto`, `auto-prior`, `sensor`, `auto-v2`, the development detector, called
//! from the core directly, `auto-v2-prior`, it tracking through the firmware, and
//! `tracker`, `auto-v2`'s sequence tracker through the firmware); `scripts/panic-never.sh` builds the required
//! set, and on a failure or for components not yet required, each one alone, and names
//! the functions and source lines that still reach a panic.
//!
//! The binary is never run: it has no start-up code and no memory map.
#![no_std]
#![no_main]
#![deny(missing_docs)]

use core::hint::black_box;

#[allow(unused_imports)]
use tirroi_core::frame::{DEFAULT_BIT_DEPTH, FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};
#[allow(unused_imports)]
use tirroi_core::roi::auto::learned::look::Look;
#[allow(unused_imports)]
use tirroi_core::{Frame, Method, Roi};
#[allow(unused_imports)]
use tirroi_firmware::{Detectors, Workspace, synth};

unsafe extern "C" {
    /// Defined nowhere: any reference to it left after optimisation is a link error,
    /// and only the panic handler references it. `safe`: calling it needs no `unsafe`
    /// block (it is never called; the link fails first).
    safe fn tirroi_panic_path_found() -> !;
}

/// The panic handler: reachable only through a panic branch the optimiser kept.
#[panic_handler]
fn panic(_info: &core::panic::PanicInfo<'_>) -> ! {
    tirroi_panic_path_found()
}

/// Runs one method through the firmware's registry call on an opaque frame.
#[allow(dead_code)]
#[inline(never)]
fn detect(detectors: &mut Detectors, method: Method, pixels: &[u16]) {
    // Any frame size and bit depth the caller could pass, not only the reference one.
    let width = black_box(FRAME_WIDTH);
    let height = black_box(FRAME_HEIGHT);
    let bits = black_box(DEFAULT_BIT_DEPTH);
    if let Ok(frame) = Frame::new(black_box(pixels), width, height, bits) {
        let _ = black_box(detectors.run(method, &frame));
    }
}

/// Runs a tracker (`auto`, `auto-v2`) through the firmware's tracking call on an
/// opaque frame with an opaque prior (any box, also one outside the frame) and an
/// opaque look of the last box (any, or none: `auto-v2`'s fast path and its search).
#[allow(dead_code)]
#[inline(never)]
fn track(detectors: &mut Detectors, method: Method, pixels: &[u16]) {
    let width = black_box(FRAME_WIDTH);
    let height = black_box(FRAME_HEIGHT);
    if let Ok(frame) = Frame::new(black_box(pixels), width, height, DEFAULT_BIT_DEPTH) {
        let prior = black_box(Roi::new(
            black_box(0),
            black_box(0),
            black_box(0),
            black_box(0),
        ));
        let look = black_box(Some(Look {
            level_dn: black_box(0),
            ring_dn: black_box(0),
            side_dn: black_box([None; 4]),
        }));
        let _ = black_box(detectors.track(method, prior, black_box(look), &frame));
    }
}

/// The entry point the linker keeps (`ld.lld`'s default entry symbol): every checked
/// call is reachable from here. `no_mangle` is the only way to name it for the linker.
#[unsafe(no_mangle)]
pub extern "C" fn _start() -> ! {
    let mut pixels = [0u16; FRAME_PIXELS];
    let pixels = black_box(&mut pixels);
    let mut detectors = Detectors::new();
    // Unused when only `auto-v2` (called from the core directly) is checked.
    #[allow(unused_variables)]
    let detectors = black_box(&mut detectors);
    #[cfg(feature = "otsu")]
    detect(detectors, Method::Otsu, pixels);
    #[cfg(feature = "adaptive")]
    detect(detectors, Method::Adaptive, pixels);
    #[cfg(feature = "wge")]
    detect(detectors, Method::Wge, pixels);
    #[cfg(feature = "dog")]
    detect(detectors, Method::Dog, pixels);
    #[cfg(feature = "auto")]
    detect(detectors, Method::Auto, pixels);
    #[cfg(feature = "auto-prior")]
    track(detectors, Method::Auto, pixels);
    #[cfg(feature = "auto-v2-prior")]
    track(detectors, Method::AutoV2, pixels);
    #[cfg(feature = "auto-v2")]
    {
        // The development detector `auto-v2` (issue 16) is not in the firmware's
        // registry yet: called straight from the core, with its own scratch.
        use tirroi_core::roi::Detector;
        use tirroi_core::roi::auto::learned::{AutoV2, AutoV2Scratch};
        let mut scratch = AutoV2Scratch::new();
        let width = black_box(FRAME_WIDTH);
        let height = black_box(FRAME_HEIGHT);
        let bits = black_box(DEFAULT_BIT_DEPTH);
        if let Ok(frame) = Frame::new(black_box(&pixels[..]), width, height, bits) {
            let detector = black_box(AutoV2::default());
            let _ = black_box(detector.detect(&frame, black_box(&mut scratch)));
        }
    }
    #[cfg(feature = "tracker")]
    {
        // `auto-v2`'s sequence tracker through the firmware's call (`roi::track`): two
        // opaque frames in a row, so the first step's capture, the second's registration
        // against it and the confirmation are all linked.
        let width = black_box(FRAME_WIDTH);
        let height = black_box(FRAME_HEIGHT);
        let bits = black_box(DEFAULT_BIT_DEPTH);
        for _ in 0..black_box(2) {
            if let Ok(frame) = Frame::new(black_box(&pixels[..]), width, height, bits) {
                let _ = black_box(detectors.sequence_step(&frame));
            }
        }
    }
    #[cfg(feature = "sensor")]
    {
        let mut tables = synth::Tables::new();
        let mut ws = Workspace {
            frame: pixels,
            detectors,
            tables: black_box(&mut tables),
        };
        synth::setup(&mut ws);
        let _ = black_box(synth::expose_scene(&mut ws));
    }
    loop {
        core::hint::spin_loop();
    }
}
