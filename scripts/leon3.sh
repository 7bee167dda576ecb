#!/usr/bin/env bash
# The flight demo's workload on an emulated LEON3 (big-endian SPARC V8, GR712RC class):
#  1. builds firmware/leon3 (the firmware's platform-neutral workload, run_demo, with a
#     SPARC start-up and register-window trap handlers in start.s and output on the
#     APBUART) for sparc-unknown-none-elf (Debian's cargo, -Zbuild-std=core), linked by
#     Debian's sparc binutils (sparc64-linux-gnu-ld -melf32_sparc);
#  2. runs it on QEMU's leon3_generic (it stops QEMU itself with `ta 0`);
#  3. compares every line of boxes, link statistics and the on-board sensor checksum
#     with the same workload on the host (firmware/examples/host.rs), bit for bit.
# Exits non-zero when the build, the run or a comparison fails.
#
# Usage: scripts/leon3.sh
# Needs: apt-get install rustc-web cargo-web rust-web-src qemu-system-sparc
#        binutils-sparc64-linux-gnu; rustup's cargo first in PATH (host reference).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

cross_cargo="${CROSS_CARGO:-/usr/bin/cargo}"
cross_rustc="${CROSS_RUSTC:-/usr/bin/rustc}"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
out="$target_dir/leon3-run"
mkdir -p "$out"

die() { echo "leon3: error: $*" >&2; exit 1; }
for tool in "$cross_cargo" "$cross_rustc" qemu-system-sparc sparc64-linux-gnu-ld; do
    command -v "$tool" >/dev/null || die "$tool not found (see the usage above for the packages)"
done

echo "::: leon3: rustfmt (firmware/leon3)"
(cd firmware/leon3 && cargo fmt --check)

echo "::: leon3: build (sparc-unknown-none-elf, target-cpu=leon3)"
start=$SECONDS
(cd firmware/leon3 && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build --release --quiet \
    --target sparc-unknown-none-elf --target-dir "$target_dir/leon3" \
    -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem)
elf="$target_dir/leon3/sparc-unknown-none-elf/release/tirroi-leon3"
echo "leon3: built in $((SECONDS - start)) s"

echo "::: leon3: host reference"
(cd firmware && cargo build --release --quiet --example host --target-dir "$target_dir/firmware/host")
"$target_dir/firmware/host/release/examples/host" >"$out/host-demo.log"

echo "::: leon3: run (QEMU leon3_generic)"
start=$SECONDS
rc=0
timeout 600 qemu-system-sparc -M leon3_generic -m 64M -nographic -monitor none \
    -kernel "$elf" >"$out/leon3.log" 2>&1 || rc=$?
echo "leon3: ran in $((SECONDS - start)) s (exit $rc)"
[[ $rc -eq 0 ]] || die "QEMU exited with status $rc (see $out/leon3.log)"
grep -q '^leon3 big-endian=true' "$out/leon3.log" || die "not a big-endian run (see $out/leon3.log)"
grep -q '^done' "$out/leon3.log" || die "the demo did not finish (see $out/leon3.log)"
if grep -q '^error' "$out/leon3.log"; then
    die "errors on the LEON3: $(grep '^error' "$out/leon3.log" | head -3)"
fi
# The boxes, foreground counts, IoU, link statistics and sensor checksum, without the
# measurements (the host and this run measure nothing; the fields are `-`).
strip_counts() { grep -E '^(link|detect|sensor)' "$1" | sed -E 's/ (insns|stack|[a-z_]+_insns|[a-z_]+_stack)=[^ ]*//g'; }
lines=$(strip_counts "$out/host-demo.log" | wc -l)
[[ $lines -gt 0 ]] || die "the host reference printed nothing to compare"
diff <(strip_counts "$out/host-demo.log") <(strip_counts "$out/leon3.log") >"$out/diff.txt" \
    || die "the LEON3 run differs from the host's (see $out/diff.txt)"
echo "leon3: all $lines lines (boxes, link statistics, sensor checksum $(awk '$1 == "sensor" { print $2 }' "$out/leon3.log")) equal the host's, bit for bit"
