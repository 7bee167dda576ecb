//! Worst-case instruction counts on the emulated Cortex-M7 (issue 18, part 2; run by
//! scripts/worst-case.sh): every detector of the core on every adversarial frame of
//! [`tirroi_firmware::adversarial`], `auto` tracking each of its priors and `auto-v2`
//! each of them and the largest windows it searches, and `auto-v2`'s sequence tracker
//! stepping through the cases as one sequence, one line per call over semihosting:
//!
//! ```text
//! worst case=checker-7 method=otsu instructions=5712040 box=0,0,328,248 passes=1
//! worst case=checker-7 method=auto+prior prior=0,0,16,16 instructions=612400 box=none
//! worst case=checker-7 method=auto-budget prior=none budget=1310720 instructions=1012440 charged=1290232 stopped=refinement box=40,8,72,40
//! ```
//!
//! (`passes`: Otsu's refinement passes, against its proven bound, printed once as
//! `worst otsu-pass-bound=17`), then `worst done calls=N` and exit 0 (1 if a detector
//! refused its input).
//! Instructions are counted as in `src/main.rs`: the SysTick under `qemu-system-arm
//! -icount shift=0` (one instruction per ns, SysTick at 25 MHz: 40 instructions per
//! tick), the cost of an empty measurement subtracted; exact to ± 40.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::hint::black_box;

    use cortex_m_rt::entry;
    use cortex_m_semihosting::{debug, hprintln};
    use panic_semihosting as _;
    use tirroi_core::frame::{FRAME_HEIGHT, FRAME_PIXELS, FRAME_WIDTH};
    use tirroi_core::roi::auto::learned::AutoV2;
    use tirroi_core::roi::auto::learned::look::Look;
    use tirroi_core::roi::auto::{BudgetReport, WorkBudget};
    use tirroi_core::{DetectError, Detection, Frame, Method, Roi};
    use tirroi_firmware::adversarial::{self, AUTO_V2_PRIORS, PRIORS};
    use tirroi_firmware::systick::{self, ticks};
    use tirroi_firmware::{BITS, DEMO_METHODS, Detectors};

    /// Instructions of `f`, less `overhead` (an empty measurement's).
    #[inline(always)]
    fn count<R>(overhead: u64, f: impl FnOnce() -> R) -> (R, u64) {
        let start = ticks();
        let r = black_box(f());
        let end = ticks();
        (r, systick::instructions(start, end, overhead))
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

    /// The budget ladder of `auto-budget` lines: 0/8 .. 7/8 of the full charge.
    const BUDGET_STEPS: u32 = 8;

    /// A prior as `x0,y0,x1,y1`, or `none`.
    struct PriorOf(Option<tirroi_core::Roi>);

    impl core::fmt::Display for PriorOf {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            match self.0 {
                Some(r) => write!(f, "{},{},{},{}", r.x0, r.y0, r.x1, r.y1),
                None => f.write_str("none"),
            }
        }
    }

    /// Where a budgeted call stopped: `no` (it ran to the end) or the stage that did
    /// not fit, `+tracking` when after a tracking pass.
    struct StopOf<'a>(&'a BudgetReport);

    impl core::fmt::Display for StopOf<'_> {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            match self.0.stopped {
                None => f.write_str("no"),
                Some(s) if s.after_tracking => write!(f, "{}+tracking", s.stage.name()),
                Some(s) => f.write_str(s.stage.name()),
            }
        }
    }

    #[entry]
    fn main() -> ! {
        // Statics via cortex-m-rt's `static mut` in the entry function (safe references).
        static mut FRAME: [u16; FRAME_PIXELS] = [0; FRAME_PIXELS];
        static mut DETECTORS: Detectors = Detectors::new();

        let mut core = cortex_m::Peripherals::take().expect("first and only take");
        systick::start(&mut core.SYST);

        let overhead = (0..8).map(|_| count(0, || ()).1).min().unwrap_or(0);
        hprintln!("worst overhead={overhead} cases={}", adversarial::COUNT);
        hprintln!(
            "worst otsu-pass-bound={}",
            tirroi_core::roi::otsu::max_refinement_passes(BITS)
        );
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
                // The weak blob exists to make `auto-v2` run its whole-frame regions and
                // then the spots: its rating must lie between the gate and the spots'
                // threshold, or the case no longer reaches that path (a retrained model
                // moves it; adversarial::WEAK_BLOB_MARGIN_PX).
                if let (adversarial::Case::WeakBlob(_), Method::AutoV2, Ok(d)) =
                    (case, method, &result)
                {
                    let v2 = AutoV2::DEFAULT;
                    if !(v2.min_score_permille..v2.spot_competes_below_permille)
                        .contains(&d.score_permille)
                    {
                        hprintln!(
                            "worst error case={case} method={method} rated {} permille: outside {}..{}, the case misses its path",
                            d.score_permille,
                            v2.min_score_permille,
                            v2.spot_competes_below_permille
                        );
                        failed = true;
                    }
                }
                match DETECTORS.otsu_passes().filter(|_| method == Method::Otsu) {
                    Some(passes) => hprintln!(
                        "worst case={case} method={method} instructions={n} box={} passes={passes}",
                        BoxOf(&result)
                    ),
                    None => hprintln!(
                        "worst case={case} method={method} instructions={n} box={}",
                        BoxOf(&result)
                    ),
                }
            }
            // The trackers with each of their priors: `auto` the border ones,
            // `auto-v2` those and the largest windows it still searches.
            let trackers: [(Method, &[Roi]); 2] =
                [(Method::Auto, &PRIORS), (Method::AutoV2, &AUTO_V2_PRIORS)];
            for (method, priors) in trackers {
                if !DEMO_METHODS.contains(&method) {
                    continue;
                }
                for &prior in priors {
                    // `auto-v2` also with the prior's own look on the frame: its
                    // place matches, so the fast path refines (the blob, then the
                    // prior's cells) and its box stands or is refused, and then the
                    // window and the frame are searched (the most a call with a prior
                    // can cost).
                    let own = Look::measure(&frame, prior);
                    // (`auto` has no look: its lines name none.)
                    let looks: &[(Option<Look>, &str)] = if method == Method::AutoV2 {
                        &[(None, " look=none"), (own, " look=own")]
                    } else {
                        &[(None, "")]
                    };
                    for &(look, look_name) in looks {
                        let (result, n) =
                            count(overhead, || DETECTORS.track(method, prior, look, &frame));
                        failed |= result.is_err();
                        calls += 1;
                        hprintln!(
                            "worst case={case} method={method}+prior prior={},{},{},{}{look_name} instructions={n} box={}",
                            prior.x0,
                            prior.y0,
                            prior.x1,
                            prior.y1,
                            BoxOf(&result)
                        );
                    }
                }
            }
            // `auto-v2`'s sequence tracker: this frame as the next of one sequence of all
            // the cases (the ground registered against the last step's frame, the prior
            // and look its last answer), then the same frame again (a still ground, its
            // own box as the prior), then once per `auto-v2` prior with that prior's own
            // look handed over (the fast path refines and may refuse, then the window,
            // the frame, the registration and the candidate's refinement are paid).
            if DEMO_METHODS.contains(&Method::AutoV2) {
                let handed = AUTO_V2_PRIORS.iter().map(|&p| Some(p));
                for prior in [None, None].into_iter().chain(handed) {
                    if let Some(p) = prior {
                        DETECTORS.set_sequence_prior(Some(p), Look::measure(&frame, p));
                    }
                    let (result, n) = count(overhead, || DETECTORS.sequence_step(&frame));
                    failed |= result.is_err();
                    calls += 1;
                    hprintln!(
                        "worst case={case} method=auto-v2+sequence prior={} instructions={n} box={}",
                        PriorOf(prior),
                        BoxOf(&result)
                    );
                }
            }
            // `auto` within a work budget: without a prior and with each prior, the
            // whole pipeline's charge, then budgets of 0/8 .. 7/8 of it. Each line has
            // the budget, the instructions counted and charged (scripts/worst-case.sh
            // checks counted <= charged <= budget) and where the call stopped.
            if DEMO_METHODS.contains(&Method::Auto) {
                for prior in core::iter::once(None).chain(PRIORS.iter().copied().map(Some)) {
                    let full = DETECTORS.auto_within(prior, &frame, WorkBudget::UNLIMITED);
                    let Ok((_, all)) = full else {
                        failed = true;
                        continue;
                    };
                    for eighth in (0..=BUDGET_STEPS).rev() {
                        let budget = if eighth == BUDGET_STEPS {
                            WorkBudget::UNLIMITED
                        } else {
                            let b = u64::from(all.charged) * u64::from(eighth)
                                / u64::from(BUDGET_STEPS);
                            WorkBudget::instructions(b as u32)
                        };
                        let (result, n) =
                            count(overhead, || DETECTORS.auto_within(prior, &frame, budget));
                        calls += 1;
                        let Ok((d, report)) = result else {
                            failed = true;
                            continue;
                        };
                        hprintln!(
                            "worst case={case} method=auto-budget prior={} budget={} instructions={n} charged={} stopped={} box={}",
                            PriorOf(prior),
                            budget.instructions,
                            report.charged,
                            StopOf(&report),
                            BoxOf(&Ok(d))
                        );
                    }
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
