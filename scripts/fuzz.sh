#!/usr/bin/env bash
# The core's fuzz targets (fuzz/, cargo-fuzz + libFuzzer), each run for a fixed time:
# `auto` (arbitrary frames, sizes, bit depths, tracking priors) and `auto-v2` (arbitrary
# frames and parameters, its tracking paths and the sequence tracker: confidence in
# range, `null` below the threshold, the same answer twice; fuzz/fuzz_targets/*.rs say
# what each asserts). Fails when an input panics, breaks an assertion or runs longer
# than TIMEOUT seconds (a hang, or a frame far off the detector's known timing); the
# input is then in fuzz/artifacts/TARGET/ and the run prints how to replay it.
#
# Usage: scripts/fuzz.sh [TARGET...]          (default: every target, auto auto_v2)
#   FUZZ_SECONDS  time per target (default 60)
#   FUZZ_TIMEOUT  longest run of one input, s (default 10; a 328x248 frame takes ~1 ms)
# Needs: a C++ compiler (libFuzzer is built from source by libfuzzer-sys: Debian g++) and
# cargo-fuzz (installed from crates.io into ~/.cargo/bin when missing). Runs on the stable
# toolchain: RUSTC_BOOTSTRAP=1 lets it take cargo-fuzz's nightly flags; --sanitizer none
# because the core's host build has no `unsafe` for AddressSanitizer to watch (it is
# forbidden there; only the Cortex-M4/M7 build has inline assembly; fuzz/Cargo.toml).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root/fuzz"

seconds="${FUZZ_SECONDS:-60}"
timeout="${FUZZ_TIMEOUT:-10}"
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(auto auto_v2)

die() { echo "fuzz: $*" >&2; exit 1; }
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || die "FUZZ_SECONDS must be a positive integer, not '$seconds'"
[[ $timeout =~ ^[0-9]+$ && $timeout -gt 0 ]] || die "FUZZ_TIMEOUT must be a positive integer, not '$timeout'"
command -v c++ >/dev/null || die "no C++ compiler (c++) in PATH: libFuzzer needs one (Debian: apt-get install g++)"
if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "cargo-fuzz missing: cargo install cargo-fuzz --locked"
    cargo install cargo-fuzz --locked --quiet
fi
cargo fuzz --version

log="$(mktemp)"
trap 'rm -f "$log"' EXIT
for target in "${targets[@]}"; do
    [[ -f fuzz_targets/$target.rs ]] || die "no fuzz target '$target' (fuzz/fuzz_targets/$target.rs)"
    echo "fuzz: $target for $seconds s"
    # -seed: the same sequence of inputs on every machine (up to the time limit); the
    # corpus (fuzz/corpus/TARGET, not in git) grows across local runs.
    status=0
    RUSTC_BOOTSTRAP=1 cargo fuzz run "$target" --sanitizer none -- \
        -max_total_time="$seconds" -timeout="$timeout" -seed=1 -print_final_stats=1 \
        >"$log" 2>&1 || status=$?
    # libFuzzer's start, end and final statistics.
    grep -E '^#[0-9]+[[:space:]]+(INITED|DONE)|^stat::(number_of_executed_units|average_exec_per_sec|slowest_unit_time_sec|peak_rss_mb)' "$log" || true
    if [[ $status -ne 0 ]]; then
        tail -n 40 "$log"
        die "$target failed (exit $status; the input is in fuzz/artifacts/$target/, replay it with: cd fuzz && RUSTC_BOOTSTRAP=1 cargo fuzz run $target --sanitizer none artifacts/$target/FILE)"
    fi
done
echo "fuzz: ${targets[*]} ok"
