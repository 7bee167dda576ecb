#!/usr/bin/env bash
# Where the flight firmware's instructions go on the emulated Cortex-M7, by source line:
# runs the demo ELF that scripts/flight.sh built (thumbv7em-none-eabihf, release) on
# QEMU's mps2-an500 with its execution trace (`-d in_asm,exec,nochain`: every translated
# block's instructions once, every execution of a block), counts executions per block
# through a FIFO (mawk; the trace itself is gigabytes), and attributes each block's
# count x its instructions to its inline chain (arm-none-eabi-addr2line -i). Prints the
# whole run's top functions and, for `auto-v2`, the stages (cell plane, forest,
# features, ...) per call and its hottest source lines.
#
# The counts are QEMU's guest instructions (as the demo's SysTick counts them with
# -icount): an IT block counts as an instruction, so do the skipped ones. A block's
# count is attributed to its first instruction's line; inlined code goes to the
# innermost frame of the chain that matches a stage (scripts/m7_profile.py). Helpers
# shared with `auto` and kept out of line (the noise estimate, the edge labelling) are
# in the function table only.
#
# Usage: scripts/m7-profile.sh [CALLS]   (CALLS: whole-frame auto-v2 calls in the demo,
#        12.6 by default: 7 frames, 7 tracked calls of which 2 keep a small window)
# Needs: scripts/flight.sh run first (the ELF), qemu-system-arm, mawk, binutils-arm-none-eabi
#        (arm-none-eabi-addr2line), python3.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
elf="$target_dir/firmware/thumbv7em-none-eabihf/release/tirroi-firmware"
out="$target_dir/m7-profile"
calls="${1:-12.6}"

die() { echo "m7-profile: error: $*" >&2; exit 1; }
[[ -f $elf ]] || die "no firmware ELF at $elf: run scripts/flight.sh first"
for tool in qemu-system-arm mawk arm-none-eabi-addr2line python3; do
    command -v "$tool" >/dev/null || die "$tool not found"
done

mkdir -p "$out"
fifo="$(mktemp -u)"
mkfifo "$fifo"
trap 'rm -f "$fifo"' EXIT
# Block start -> executions and instructions (a block translated twice keeps its
# last length: the same code).
mawk '
/^IN:/ { intb = 1; start = ""; n = 0; next }
intb && /^0x/ { if (start == "") start = substr($1, 3, 8); n++; next }
intb && /^$/ { if (start != "") len[start] = n; intb = 0; next }
/^Trace/ { split($4, a, "/"); c[a[2]]++ }
END { for (k in c) print k, c[k], len[k] }' "$fifo" >"$out/blocks.txt" &
qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0,align=off,sleep=off \
    -d in_asm,exec,nochain -D "$fifo" -kernel "$elf" >"$out/run.log"
wait
grep -q '^done' "$out/run.log" || die "the demo did not finish (see $out/run.log)"
python3 scripts/m7_profile.py "$elf" "$out/blocks.txt" "$calls" | tee "$out/profile.txt"
