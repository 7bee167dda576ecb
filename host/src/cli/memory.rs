//! `tirroi memory`: the scratch memory of each detector.

use std::process::ExitCode;

use tirroi_core::Method;

/// Runs `tirroi memory`: one markdown row per detector, its scratch size in bytes.
pub fn run() -> ExitCode {
    println!("| detector | scratch bytes |");
    println!("|---|---|");
    for m in Method::ALL {
        println!("| {m} | {} |", m.scratch_bytes());
    }
    ExitCode::SUCCESS
}
