#!/usr/bin/env bash
# Cross-build the flight core `tirroi-core` (release, default features) for bare-metal
# targets. This is the no_std proof: only `core` is built for the target
# (-Zbuild-std=core, no `alloc`, no `std`), so any use of std or of the heap by
# tirroi-core or by one of its dependencies fails the build.
#
# Usage: scripts/cross-build.sh [TARGET...]      (default: thumbv7em-none-eabihf)
#   e.g. scripts/cross-build.sh thumbv7em-none-eabihf thumbv7m-none-eabi \
#          thumbv6m-none-eabi armv7r-none-eabihf aarch64-unknown-none \
#          sparc-unknown-none-elf riscv32imac-unknown-none-elf
#
# Toolchain: Debian's packaged Rust (rustup cannot download targets here), installed
# by CI, not by this script:
#   apt-get install rustc-web cargo-web rust-web-src lld gcc-arm-none-eabi
# It is called by absolute path, with RUSTC_BOOTSTRAP=1 for the unstable -Zbuild-std.
# Override with CROSS_CARGO / CROSS_RUSTC if it lives elsewhere.
#
# Output goes to $CARGO_TARGET_DIR/cross (default target/cross), away from the host
# build so the two never invalidate or lock each other.
# Every target is attempted; the script exits non-zero if any failed.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

cross_cargo="${CROSS_CARGO:-/usr/bin/cargo}"
cross_rustc="${CROSS_RUSTC:-/usr/bin/rustc}"
target_dir="${CARGO_TARGET_DIR:-$root/target}/cross"

if [[ $# -eq 0 ]]; then
    set -- thumbv7em-none-eabihf
fi

die() { echo "cross-build: error: $*" >&2; exit 1; }

[[ -x "$cross_cargo" ]] || die "$cross_cargo not found (apt-get install cargo-web)"
[[ -x "$cross_rustc" ]] || die "$cross_rustc not found (apt-get install rustc-web)"
sysroot="$("$cross_rustc" --print sysroot)"
[[ -f "$sysroot/lib/rustlib/src/rust/library/core/Cargo.toml" ]] \
    || die "Rust library source missing under $sysroot/lib/rustlib/src (apt-get install rust-web-src)"

echo "cross-build: $("$cross_cargo" --version), $("$cross_rustc" --version)"
echo "cross-build: target dir $target_dir"

# Print code size (.text + .rodata, Berkeley "text") of the rlib's object files. This
# is what the crate compiles on its own; generic and #[inline] code is instantiated in
# the final firmware and counted there, not here.
print_size() {
    local target=$1 rlib=$2 size_tool=""
    echo "cross-build: $target: rlib $(stat -c %s "$rlib") bytes ($rlib)"
    if command -v llvm-size >/dev/null; then
        size_tool=llvm-size
    elif [[ $target == thumb* || $target == armv7r* ]] && command -v arm-none-eabi-size >/dev/null; then
        size_tool=arm-none-eabi-size
    fi
    if [[ -n $size_tool ]]; then
        "$size_tool" -t "$rlib" 2>/dev/null \
            | awk -v t="$target" '/\(TOTALS\)/ { printf "cross-build: %s: code+rodata %d bytes\n", t, $1 }' \
            || true
    fi
}

failed=()
for target in "$@"; do
    echo "::: cross-build $target"
    start=$SECONDS
    if RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build \
        --release \
        -p tirroi-core \
        --target "$target" \
        --target-dir "$target_dir" \
        -Zbuild-std=core \
        -Zbuild-std-features=compiler-builtins-mem; then
        print_size "$target" "$target_dir/$target/release/libtirroi_core.rlib"
        echo "cross-build: $target: OK in $((SECONDS - start)) s"
    else
        echo "cross-build: $target: FAILED after $((SECONDS - start)) s" >&2
        failed+=("$target")
    fi
done

if [[ ${#failed[@]} -gt 0 ]]; then
    die "failed targets: ${failed[*]}"
fi
echo "cross-build: all targets built: $*"
