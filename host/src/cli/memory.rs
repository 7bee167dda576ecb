//! `tirroi memory`: the scratch memory of each detector.

use std::process::ExitCode;

use tirroi_core::Method;
use tirroi_core::capacity::{Cap640x512, Cap1024x768};

/// Runs `tirroi memory`: one markdown row per detector, its scratch size in bytes at
/// the reference capacity 328×248 (the flight build's), then per larger capacity;
/// last the sequence tracker's own state.
pub fn run() -> ExitCode {
    println!("| detector | scratch bytes |");
    println!("|---|---|");
    for m in Method::ALL {
        println!("| {m} | {} |", m.scratch_bytes());
    }
    println!();
    println!("| detector | 328x248 | 640x512 | 1024x768 |");
    println!("|---|---|---|---|");
    for m in Method::ALL {
        println!(
            "| {m} | {} | {} | {} |",
            m.scratch_bytes(),
            m.scratch_bytes_for::<Cap640x512>(),
            m.scratch_bytes_for::<Cap1024x768>()
        );
    }
    // Not a detector's scratch: the state a sequence tracker keeps beside `auto-v2`'s
    // (the ground's patches, the last box and look, the run of candidates).
    println!();
    println!("| state | bytes |");
    println!("|---|---|");
    println!(
        "| auto-v2's sequence tracker (`roi::track::Tracker`) | {} |",
        tirroi_core::roi::track::TRACKER_BYTES
    );
    ExitCode::SUCCESS
}
