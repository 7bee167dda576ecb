//! The `tirroi` binary: see `tirroi --help`.
fn main() -> std::process::ExitCode {
    tirroi_host::cli::main()
}
