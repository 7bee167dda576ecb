//! The flight demo's workload ([`tirroi_firmware::run_demo`]) on a LEON3 (big-endian
//! SPARC V8; QEMU `leon3_generic`, see scripts/leon3.sh): every embedded frame through
//! the SPI link and every detector, then the on-board camera model, each event printed
//! as one text line on the APBUART. The host compares the boxes and the sensor
//! checksum with its own run of the same workload, bit for bit. No instruction counts
//! (no cycle counter is read here): the point is that a big-endian target gets the
//! same answers.
#![no_std]
#![no_main]
// global_asm! on SPARC (the build already needs RUSTC_BOOTSTRAP=1 for -Zbuild-std).
#![feature(asm_experimental_arch)]

use core::fmt::{self, Write};

use tirroi_core::frame::FRAME_PIXELS;
use tirroi_firmware::synth::Tables;
use tirroi_firmware::{Detectors, NoMeter, Workspace, run_demo};

core::arch::global_asm!(include_str!("start.s"));

/// Data register of the APBUART on QEMU's leon3_generic (and GRLIB parts).
const UART_DATA: usize = 0x8000_0100;

/// Writes text to the APBUART, one byte per store.
struct Uart;

impl Write for Uart {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for b in s.bytes() {
            // SAFETY: UART_DATA is the APBUART's data register on this machine; a
            // 32-bit store of one byte sends it. Needed: the only output there is.
            unsafe { core::ptr::write_volatile(UART_DATA as *mut u32, u32::from(b)) };
        }
        Ok(())
    }
}

static mut FRAME: [u16; FRAME_PIXELS] = [0; FRAME_PIXELS];
static mut DETECTORS: Detectors = Detectors::new();
static mut TABLES: Tables = Tables::new();

unsafe extern "C" {
    /// Stops the machine (start.s: `ta 0` with traps off; QEMU exits).
    fn leon3_shutdown() -> !;
}

/// Stops the machine after the last line.
fn shutdown() -> ! {
    // SAFETY: leon3_shutdown (start.s) takes no arguments, touches only %g1 and the
    // PSR, and never returns. Needed: the only way to end the emulator's run.
    unsafe { leon3_shutdown() }
}

/// Called once by `_start` (start.s) with the stack set up and `.bss` zeroed.
#[unsafe(no_mangle)]
extern "C" fn rust_main() -> ! {
    // SAFETY: rust_main runs once and nothing else (no interrupts are enabled) names
    // these statics, so these are the only references ever made to them.
    let mut ws = unsafe {
        Workspace {
            frame: &mut *(&raw mut FRAME),
            detectors: &mut *(&raw mut DETECTORS),
            tables: &mut *(&raw mut TABLES),
        }
    };
    let _ = writeln!(Uart, "leon3 big-endian={}", cfg!(target_endian = "big"));
    run_demo(&mut ws, &mut NoMeter, &mut |event| {
        let _ = writeln!(Uart, "{event}");
    });
    shutdown()
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    let _ = writeln!(Uart, "error what=\"panic\"");
    shutdown()
}
