//! Hands the linker script (`leon3.ld`, by absolute path) to the link.
use std::env;
use std::path::PathBuf;

fn main() {
    let manifest =
        PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let script = manifest.join("leon3.ld");
    if env::var("CARGO_CFG_TARGET_ARCH").as_deref() == Ok("sparc") {
        println!("cargo:rustc-link-arg=-T{}", script.display());
    }
    println!("cargo:rerun-if-changed={}", script.display());
    println!("cargo:rerun-if-changed=src/start.s");
}
