//! Worst-case instruction counts on the emulated Cortex-M7 (issue 18, part 2; run by
//! scripts/worst-case.sh): every detector of the core on every adversarial frame of
//! [`tirroi_firmware::adversarial`], and `auto` tracking each of its priors, one line
//! per call over semihosting:
//!
//! ```text
//! worst case=checker-7 method=otsu instructions=5712040 box=0,0,328,248
//! worst case=checker-7 method=auto+prior prior=0,0,16,16 instructions=612400 box=none
//! ```
//!
//! then `worst done calls=N` and exit 0 (1 if a detector refused its input).
//! Instructions are counted as in `src/main.rs`: the SysTick under `qemu-system-arm
//! -icount shift=0` (one instruction per ns, SysTick at 25 MHz: 40 instructions per
//! tick), the cost of an empty measurement subtracted; exact to ± 40.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::hint::black_box;
    use core::sync::atomic::{AtomicU32, Ordering};

    use cortex_m::peripheral::SYST;
    use cortex_m::peripheral::syst::SystClkSource;
    use cortex_m_rt::{entry, exception};
    use cortex_m_semihosting::{debug, hprintln};
    use panic_semihosting as _;
    use tirroi_core::frame::{FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};
    use tirroi_core::{DetectError, Detection, Frame, Method};
    use tirroi_firmware::adversarial::{self, PRIORS};
    use tirroi_firmware::{BITS, DEMO_METHODS, Detectors};

    /// Instructions per SysTick tick under `-icount shift=0` (as in src/main.rs).
    const INSTRUCTIONS_PER_TICK: u64 = 40;
    /// The SysTick reload value: the full 24 bits.
    const RELOAD: u32 = 0x00FF_FFFF;

    /// SysTick wraps since start-up (written by the SysTick handler only).
    static WRAPS: AtomicU32 = AtomicU32::new(0);

    #[exception]
    fn SysTick() {
        WRAPS.store(
            WRAPS.load(Ordering::Relaxed).wrapping_add(1),
            Ordering::Relaxed,
        );
    }

    /// SysTick ticks since start-up, 64-bit.
    #[inline(never)]
    fn ticks() -> u64 {
        loop {
            let before = WRAPS.load(Ordering::SeqCst);
            let current = SYST::get_current();
            let after = WRAPS.load(Ordering::SeqCst);
            if before == after {
                return u64::from(before) * (u64::from(RELOAD) + 1) + u64::from(RELOAD - current);
            }
        }
    }

    /// Instructions of `f`, less `overhead` (an empty measurement's).
    #[inline(always)]
    fn count<R>(overhead: u64, f: impl FnOnce() -> R) -> (R, u64) {
        let start = ticks();
        let r = black_box(f());
        let end = ticks();
        (
            r,
            ((end - start) * INSTRUCTIONS_PER_TICK).saturating_sub(overhead),
        )
    }

    /// A detection's box as `x0,y0,x1,y1`, `none`, or `error` (so runs can be
    /// compared box for box).
    struct BoxOf<'a>(&'a Result<Detection, DetectError>);

    impl core::fmt::Display for BoxOf<'_> {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            match self.0 {
                Ok(Detection { roi: Some(r), .. }) => {
                    write!(f, "{},{},{},{}", r.x0, r.y0, r.x1, r.y1)
                }
                Ok(_) => f.write_str("none"),
                Err(_) => f.write_str("error"),
            }
        }
    }

    #[entry]
    fn main() -> ! {
        // Statics via cortex-m-rt's `static mut` in the entry function (safe references).
        static mut FRAME: [u16; FRAME_PIXELS] = [0; FRAME_PIXELS];
        static mut DETECTORS: Detectors = Detectors::new();

        let mut core = cortex_m::Peripherals::take().expect("first and only take");
        core.SYST.set_clock_source(SystClkSource::Core);
        core.SYST.set_reload(RELOAD);
        core.SYST.clear_current();
        core.SYST.enable_interrupt();
        core.SYST.enable_counter();

        let overhead = (0..8).map(|_| count(0, || ()).1).min().unwrap_or(0);
        hprintln!("worst overhead={overhead} cases={}", adversarial::COUNT);
        let mut calls = 0u32;
        let mut failed = false;
        for index in 0..adversarial::COUNT {
            let Some(case) = adversarial::case(index) else {
                continue;
            };
            adversarial::fill(case, FRAME);
            let Ok(frame) = Frame::new(&FRAME[..], FRAME_WIDTH, FRAME_HEIGHT, BITS) else {
                hprintln!("worst error case={case} frame refused");
                failed = true;
                continue;
            };
            for &method in DEMO_METHODS {
                let (result, n) = count(overhead, || DETECTORS.run(method, &frame));
                failed |= result.is_err();
                calls += 1;
                hprintln!(
                    "worst case={case} method={method} instructions={n} box={}",
                    BoxOf(&result)
                );
            }
            if DEMO_METHODS.contains(&Method::Auto) {
                for prior in PRIORS {
                    let (result, n) = count(overhead, || DETECTORS.track(prior, &frame));
                    failed |= result.is_err();
                    calls += 1;
                    hprintln!(
                        "worst case={case} method=auto+prior prior={},{},{},{} instructions={n} box={}",
                        prior.x0,
                        prior.y0,
                        prior.x1,
                        prior.y1,
                        BoxOf(&result)
                    );
                }
            }
        }
        hprintln!("worst done calls={calls}");
        debug::exit(if failed {
            debug::EXIT_FAILURE
        } else {
            debug::EXIT_SUCCESS
        });
        loop {
            cortex_m::asm::wfi();
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("worst-case is a Cortex-M binary: build and run it with scripts/worst-case.sh");
    std::process::exit(2);
}
