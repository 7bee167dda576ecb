//! The flight demo on a Cortex-M7 (QEMU `mps2-an500`; see scripts/flight.sh): runs
//! [`tirroi_firmware::run_demo`] and prints every event over semihosting (text, or
//! defmt frames with `--features defmt`), with the instructions and the stack depth
//! of each step, then exits through semihosting with status 0, or 1 if a step failed.
//!
//! Instructions: counted with the SysTick ([`tirroi_firmware::systick`]: 40
//! instructions per tick under `qemu-system-arm -icount shift=0`, checked at start-up
//! against a loop of known length). The counter's own cost is measured and subtracted.
//! Counts are exact to ± 40.
//!
//! Stack: before each step the free RAM between the end of the statics and the stack
//! pointer is painted with a pattern; after it, the lowest overwritten word gives the
//! step's deepest stack use.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use cortex_m_rt::entry;
    #[cfg(feature = "defmt")]
    use defmt_semihosting as _;
    use panic_semihosting as _;
    use tirroi_core::frame::FRAME_PIXELS;
    use tirroi_firmware::synth::Tables;
    use tirroi_firmware::systick::{self, ticks};
    use tirroi_firmware::{Detectors, Event, Meter, MeterReading, Workspace, run_demo};

    /// The stack paint pattern.
    const PAINT: u32 = 0xC5AC_CE55;
    /// Bytes below the stack pointer left unpainted when a measurement starts (the
    /// painting function's own frame).
    const PAINT_MARGIN: usize = 64;

    unsafe extern "C" {
        /// End of the statics (.bss / .uninit), from cortex-m-rt's link.x: the bottom
        /// of the free RAM the stack grows into.
        static mut __sheap: u32;
        /// The initial stack pointer: ORIGIN(RAM) + LENGTH(RAM) by default.
        static mut _stack_start: u32;
    }

    fn free_ram_bottom() -> usize {
        (&raw const __sheap) as usize
    }

    /// The initial stack pointer (top of RAM in memory.x), from cortex-m-rt's link.x.
    fn stack_top() -> usize {
        (&raw const _stack_start) as usize
    }

    /// Counts instructions with the SysTick and measures stack depth by painting.
    struct QemuMeter {
        start_ticks: u64,
        sp_at_start: usize,
        /// Lowest address the stack reached since the first measurement.
        lowest: usize,
        /// Instructions a `start`/`stop` pair costs with nothing between them.
        overhead: u64,
    }

    impl QemuMeter {
        fn new() -> Self {
            let mut meter = QemuMeter {
                start_ticks: 0,
                sp_at_start: 0,
                lowest: usize::MAX,
                overhead: 0,
            };
            // The overhead, the least of a few empty measurements.
            let mut least = u64::MAX;
            for _ in 0..8 {
                meter.start();
                let r = meter.stop();
                least = least.min(r.instructions.unwrap_or(0));
            }
            meter.overhead = least;
            meter
        }

        fn paint(&mut self) {
            // What ran since the last measurement (reporting) used the painted stack too.
            if self.sp_at_start != 0 {
                self.lowest = self.lowest.min(self.lowest_touched());
            }
            let sp = cortex_m::register::msp::read() as usize;
            self.sp_at_start = sp;
            let bottom = free_ram_bottom();
            let top = sp.saturating_sub(PAINT_MARGIN) & !3;
            let mut addr = (bottom + 3) & !3;
            while addr < top {
                // SAFETY: [bottom, sp − margin) is RAM that neither the statics (below
                // `__sheap`) nor any live stack frame (at or above `sp`, the margin
                // covering this function's own frame) uses; the pattern is only read
                // back by `stack_used`. Needed to measure stack depth, which is the
                // point of this demo.
                unsafe { core::ptr::write_volatile(addr as *mut u32, PAINT) };
                addr += 4;
            }
        }

        /// The lowest word of the painted region that is no longer the pattern.
        fn lowest_touched(&self) -> usize {
            let mut addr = (free_ram_bottom() + 3) & !3;
            let top = self.sp_at_start.saturating_sub(PAINT_MARGIN) & !3;
            while addr < top {
                // SAFETY: reads back the words `paint` wrote, in the same free RAM.
                if unsafe { core::ptr::read_volatile(addr as *const u32) } != PAINT {
                    break;
                }
                addr += 4;
            }
            addr
        }

        fn stack_used(&mut self) -> u32 {
            let lowest = self.lowest_touched();
            self.lowest = self.lowest.min(lowest);
            (self.sp_at_start - lowest) as u32
        }
    }

    impl Meter for QemuMeter {
        #[inline(never)]
        fn start(&mut self) {
            self.paint();
            self.start_ticks = ticks();
        }

        #[inline(never)]
        fn stop(&mut self) -> MeterReading {
            let end = ticks();
            let instructions = systick::instructions(self.start_ticks, end, self.overhead);
            MeterReading {
                instructions: Some(instructions),
                stack_bytes: Some(self.stack_used()),
            }
        }
    }

    /// Checks [`systick::INSTRUCTIONS_PER_TICK`]: counts a loop of 2 instructions × N.
    fn calibrate(meter: &mut QemuMeter) -> (u64, u64) {
        const ITERATIONS: u32 = 1_000_000;
        meter.start();
        // SAFETY: a register-only countdown loop (subs + bne per iteration): no memory,
        // no stack. Needed because only a loop of known length checks the counter.
        unsafe {
            core::arch::asm!(
                "2:",
                "subs {n}, {n}, #1",
                "bne 2b",
                n = inout(reg) ITERATIONS => _,
                options(nomem, nostack),
            );
        }
        let counted = meter.stop().instructions.unwrap_or(0);
        (2 * u64::from(ITERATIONS), counted)
    }

    #[cfg(not(feature = "defmt"))]
    fn emit(event: &Event) {
        cortex_m_semihosting::hprintln!("{}", event);
    }

    #[cfg(feature = "defmt")]
    fn emit(event: &Event) {
        defmt::println!("{}", event);
    }

    #[cfg(not(feature = "defmt"))]
    fn report_calibration(expected: u64, counted: u64, overhead: u64) {
        cortex_m_semihosting::hprintln!(
            "calibration loop_insns={expected} counted={counted} overhead={overhead}"
        );
    }

    #[cfg(feature = "defmt")]
    fn report_calibration(expected: u64, counted: u64, overhead: u64) {
        defmt::println!(
            "calibration loop_insns={=u64} counted={=u64} overhead={=u64}",
            expected,
            counted,
            overhead
        );
    }

    #[cfg(not(feature = "defmt"))]
    fn report_ram(statics_end: usize, stack_top: usize, peak: usize, never_used: usize) {
        cortex_m_semihosting::hprintln!(
            "ram statics_end={statics_end:#x} stack_top={stack_top:#x} stack_peak={peak} free_never_used={never_used}"
        );
    }

    #[cfg(feature = "defmt")]
    fn report_ram(statics_end: usize, stack_top: usize, peak: usize, never_used: usize) {
        defmt::println!(
            "ram statics_end={=usize:x} stack_top={=usize:x} stack_peak={=usize} free_never_used={=usize}",
            statics_end,
            stack_top,
            peak,
            never_used
        );
    }

    /// The one frame buffer (162 688 B), zero bytes in `.bss`; with `--features dtcm`
    /// in AXI SRAM (memory-dtcm.x's `.axisram`, NOLOAD: not cleared at start-up; the
    /// SPI link writes every pixel before anything reads one, and the emulator's RAM
    /// starts zeroed). A module-level static because the entry function's `static mut`
    /// items (turned into parameters by cortex-m-rt) cannot take `#[link_section]`.
    #[cfg_attr(feature = "dtcm", unsafe(link_section = ".axisram.frame"))]
    static mut FRAME: [u16; FRAME_PIXELS] = [0; FRAME_PIXELS];

    /// The frame buffer, borrowed once for the whole program.
    fn frame_buffer() -> &'static mut [u16; FRAME_PIXELS] {
        // SAFETY: called exactly once, from `main` before the demo starts (nothing else
        // names FRAME), so this is the only reference to the buffer ever made; no
        // interrupt handler touches it. Needed because a section attribute (the DTCM
        // map's frame in AXI SRAM) needs a module-level static.
        unsafe { &mut *(&raw mut FRAME) }
    }

    #[entry]
    fn main() -> ! {
        // cortex-m-rt turns `static mut` items of the entry function into safe
        // `&'static mut` references: the buffers are statics, not on the stack. The
        // detectors' one shared scratch area and the tables are zero bytes (.bss: no
        // initial values in flash); the frame is the module-level `FRAME` below.
        static mut DETECTORS: Detectors = Detectors::new();
        static mut TABLES: Tables = Tables::new();

        let mut core = cortex_m::Peripherals::take().expect("first and only take");
        systick::start(&mut core.SYST);

        let mut meter = QemuMeter::new();
        let (expected, counted) = calibrate(&mut meter);
        report_calibration(expected, counted, meter.overhead);

        let mut failed = false;
        let mut workspace = Workspace {
            frame: frame_buffer(),
            detectors: DETECTORS,
            tables: TABLES,
        };
        run_demo(&mut workspace, &mut meter, &mut |event| {
            failed |= event.is_error();
            emit(event);
        });
        // One more paint/scan pair closes the last reporting interval.
        meter.start();
        meter.stop();
        let top = stack_top();
        report_ram(
            free_ram_bottom(),
            top,
            top - meter.lowest,
            meter.lowest - free_ram_bottom(),
        );
        let status = if failed {
            cortex_m_semihosting::debug::EXIT_FAILURE
        } else {
            cortex_m_semihosting::debug::EXIT_SUCCESS
        };
        cortex_m_semihosting::debug::exit(status);
        loop {
            cortex_m::asm::wfi();
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "tirroi-firmware is a Cortex-M binary: build and run it with scripts/flight.sh; \
         on the host, run `cargo run --release --example host` in firmware/"
    );
    std::process::exit(2);
}
