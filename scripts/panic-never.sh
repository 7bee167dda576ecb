#!/usr/bin/env bash
# Can the flight code panic? (issue 18, part 1). Builds flight-checks/panic-never (release,
# fat LTO, panic = "abort", thumbv7em-none-eabihf with Debian's cargo and -Zbuild-std=core,
# as scripts/cross-build.sh and scripts/flight.sh do): a binary that links each flight call
# (a detector through the firmware's registry call, `auto` with a prior, the on-board
# camera model) with a panic handler that calls a symbol defined nowhere. A panic branch
# the optimiser could not remove keeps that reference, and the link fails.
#
#  1. REQUIRED components, linked together: must link (else exit 1).
#  2. On failure, each REQUIRED component alone, and each PENDING one: linked again with
#     undefined symbols allowed, and flight-checks/panic-never/panic_sites.py names the
#     functions and source lines that still branch into a panic.
# PENDING components are reported, never fail the step: they are the ones still being
# rewritten (auto v2, the table-driven sensor). Making one required is moving its name
# from PENDING to REQUIRED below.
#
# Usage: scripts/panic-never.sh [--all-pending-fail] [COMPONENT...]
#   with COMPONENTs: check only these, all required (e.g. `scripts/panic-never.sh auto`).
#   components: otsu adaptive wge dog auto auto-prior sensor auto-v2 auto-v2-prior tracker (cargo
#   features of the check)
# Needs: apt-get install rustc-web cargo-web rust-web-src lld binutils-arm-none-eabi
#        (arm-none-eabi-objdump/addr2line, from gcc-arm-none-eabi) python3.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

REQUIRED=(otsu adaptive wge dog auto auto-prior sensor auto-v2 auto-v2-prior tracker)
PENDING=()

if [[ $# -gt 0 ]]; then
    REQUIRED=("$@")
    PENDING=()
fi

target=thumbv7em-none-eabihf
cross_cargo="${CROSS_CARGO:-/usr/bin/cargo}"
cross_rustc="${CROSS_RUSTC:-/usr/bin/rustc}"
target_dir="${CARGO_TARGET_DIR:-$root/target}/panic-never"
elf="$target_dir/$target/release/tirroi-panic-never"
crate=flight-checks/panic-never

die() { echo "panic-never: error: $*" >&2; exit 1; }
for tool in "$cross_cargo" "$cross_rustc" ld.lld arm-none-eabi-objdump arm-none-eabi-addr2line python3; do
    command -v "$tool" >/dev/null || die "$tool not found (see the usage above for the packages)"
done

# build FEATURES [EXTRA_RUSTC_ARGS...]: links the check with these features; the output
# (the linker's error on a panic path) goes to $log.
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
build() {
    local features=$1
    shift
    (cd "$crate" && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" rustc --release --quiet \
        --target "$target" --target-dir "$target_dir" --features "$features" \
        --bin tirroi-panic-never \
        -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem -- "$@") >"$log" 2>&1
}

# sites COMPONENT: links it alone with undefined symbols allowed and names its panic sites.
sites() {
    local component=$1
    if build "$component"; then
        echo "panic-never: $component: no panic path"
        return 0
    fi
    grep -q 'undefined symbol: tirroi_panic_path_found' "$log" \
        || { cat "$log" >&2; die "$component: the build failed for another reason than a panic path"; }
    build "$component" -C link-arg=--unresolved-symbols=ignore-all \
        || { cat "$log" >&2; die "$component: the diagnostic link failed"; }
    echo "panic-never: $component: panic paths left (file:line, function [panic], inlined into):"
    python3 "$crate/panic_sites.py" "$elf" | sed 's/^/    /'
    return 1
}

start=$SECONDS
required=$(IFS=,; echo "${REQUIRED[*]}")
failed=()
required_ok=1
echo "::: panic-never: required: ${REQUIRED[*]}"
if build "$required"; then
    echo "panic-never: ${REQUIRED[*]}: linked with the unlinkable panic handler: no panic path ($((SECONDS - start)) s)"
else
    required_ok=0
    grep -q 'undefined symbol: tirroi_panic_path_found' "$log" \
        || { cat "$log" >&2; die "the build failed for another reason than a panic path"; }
    echo "panic-never: a panic path is left; each component alone:"
    for component in "${REQUIRED[@]}"; do
        sites "$component" || failed+=("$component")
    done
fi

if [[ ${#PENDING[@]} -gt 0 ]]; then
    echo "::: panic-never: pending (reported, not failing): ${PENDING[*]}"
    for component in "${PENDING[@]}"; do
        sites "$component" || true
    done
fi
echo "panic-never: done in $((SECONDS - start)) s"
if [[ ${#failed[@]} -gt 0 ]]; then
    die "panic paths in required components: ${failed[*]}"
fi
if [[ $required_ok -eq 0 ]] && ! build "$required"; then
    sites "$required" || true
    die "the required set (${REQUIRED[*]}) has a panic path no single component has (see above)"
fi
