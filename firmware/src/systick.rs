//! Instruction counting on the emulated Cortex-M7 (the flight demo's `src/main.rs` and
//! the worst-case harness `src/worst_case.rs`): the SysTick counts the processor clock;
//! under `qemu-system-arm -icount shift=0` every guest instruction advances the virtual
//! clock by 1 ns and the mps2 boards clock the SysTick at 25 MHz, so a tick is
//! [`INSTRUCTIONS_PER_TICK`] instructions (checked by the demo at start-up against a
//! loop of known length). Wraps of the 24-bit counter are counted by the SysTick
//! exception, so [`ticks`] is a 64-bit count since [`start`].

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::exception;

/// Instructions per SysTick tick under `-icount shift=0` (1 ns per instruction,
/// SysTick at the 25 MHz system clock of the mps2 boards).
pub const INSTRUCTIONS_PER_TICK: u64 = 40;
/// The SysTick reload value: the full 24 bits.
const RELOAD: u32 = 0x00FF_FFFF;

/// SysTick wraps since start-up (written by the SysTick handler only).
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    // Single writer: a load and a store are enough, and ARMv6-M has no RMW atomics.
    WRAPS.store(
        WRAPS.load(Ordering::Relaxed).wrapping_add(1),
        Ordering::Relaxed,
    );
}

/// Starts the SysTick on the core clock, full reload, wrap interrupt on.
pub fn start(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// SysTick ticks since [`start`], 64-bit.
#[inline(never)]
pub fn ticks() -> u64 {
    loop {
        let before = WRAPS.load(Ordering::SeqCst);
        let current = SYST::get_current();
        let after = WRAPS.load(Ordering::SeqCst);
        if before == after {
            return u64::from(before) * (u64::from(RELOAD) + 1) + u64::from(RELOAD - current);
        }
    }
}

/// Instructions between two [`ticks`] readings, less `overhead` (an empty
/// measurement's).
pub fn instructions(start: u64, end: u64, overhead: u64) -> u64 {
    ((end - start) * INSTRUCTIONS_PER_TICK).saturating_sub(overhead)
}
