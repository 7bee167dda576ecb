//! `tirroi memory`: the scratch memory of each detector.

use std::process::ExitCode;

use tirroi_core::Method;
use tirroi_core::capacity::{Cap640x512, Cap1024x768};

/// Runs `tirroi memory`: one markdown row per detector, its scratch size in bytes at
/// the reference capacity 328×248 (the flight build's), then per larger capacity.
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
    ExitCode::SUCCESS
}
