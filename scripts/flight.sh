#!/usr/bin/env bash
# The flight demo (firmware/) end to end, as CI runs it:
#  1. host reference: `tirroi detect --method all --json` on the embedded frames, and the
#     firmware's own workload on the host (firmware/examples/host.rs);
#  2. for each Arm target: build the firmware (release, -Zbuild-std=core, Debian's cargo),
#     take its section sizes, run it on QEMU's Cortex-M7 (mps2-an500, semihosting,
#     -icount shift=0 so the SysTick counts instructions);
#  3. x86-64 instruction counts of the same calls under valgrind's callgrind;
#  4. firmware/examples/flight_report.rs compares boxes (bit for bit against the host),
#     the on-board sensor checksums (every target against the host), checks the memory
#     budgets of memory.x, and writes the tables to $out/report.md.
# Exits non-zero when a build, a run, a comparison or a budget fails.
#
# Usage: scripts/flight.sh [--no-callgrind] [TARGET...]
#   default targets: thumbv7em-none-eabihf (FPU, the flight target) thumbv7m-none-eabi
#   thumbv6m-none-eabi (no FPU; both run on the Cortex-M7, a superset of their ISAs)
# Needs: apt-get install rustc-web cargo-web rust-web-src lld qemu-system-arm
#        gcc-arm-none-eabi (arm-none-eabi-size) valgrind; rustup's cargo first in PATH.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

callgrind=1
targets=()
for arg in "$@"; do
    case $arg in
        --no-callgrind) callgrind=0 ;;
        -*) echo "flight: unknown option $arg" >&2; exit 2 ;;
        *) targets+=("$arg") ;;
    esac
done
[[ ${#targets[@]} -gt 0 ]] || targets=(thumbv7em-none-eabihf thumbv7m-none-eabi thumbv6m-none-eabi)

cross_cargo="${CROSS_CARGO:-/usr/bin/cargo}"
cross_rustc="${CROSS_RUSTC:-/usr/bin/rustc}"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
out="$target_dir/flight"
fw_target_dir="$target_dir/firmware"
mkdir -p "$out"
rm -f "$out"/*.log "$out"/*.size "$out"/*.rc "$out"/callgrind.txt

die() { echo "flight: error: $*" >&2; exit 1; }
for tool in "$cross_cargo" "$cross_rustc" qemu-system-arm arm-none-eabi-size ld.lld; do
    command -v "$tool" >/dev/null || die "$tool not found (see the usage above for the packages)"
done

echo "::: flight: rustfmt and clippy (firmware crate, host side)"
(cd firmware && cargo fmt --check && cargo clippy --release --quiet --lib --examples --bins \
    --target-dir "$fw_target_dir/host" -- -D warnings)

echo "::: flight: the embedded frames are what the renderer makes now"
fresh="$(mktemp -d)"
trap 'rm -rf "$fresh"' EXIT
scripts/flight-frames.sh "$fresh/frames" >/dev/null
diff -r "$fresh/frames" firmware/frames >/dev/null \
    || die "firmware/frames differ from a fresh render: run scripts/flight-frames.sh and commit"

echo "::: flight: host reference"
cargo build --release --quiet --bin tirroi
"$target_dir/release/tirroi" detect --method all --json firmware/frames/*.png >"$out/host-detect.jsonl"
(cd firmware && cargo build --release --quiet --example host --example flight_report --target-dir "$fw_target_dir/host")
host_bin="$fw_target_dir/host/release/examples/host"
"$host_bin" >"$out/host-demo.log"

for target in "${targets[@]}"; do
    echo "::: flight: $target"
    start=$SECONDS
    (cd firmware && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build --release --quiet \
        --target "$target" --target-dir "$fw_target_dir" \
        -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem)
    elf="$fw_target_dir/$target/release/tirroi-firmware"
    arm-none-eabi-size -A "$elf" >"$out/$target.size"
    rc=0
    timeout 900 qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -monitor none \
        -serial none -semihosting-config enable=on,target=native \
        -icount shift=0,align=off,sleep=off -kernel "$elf" >"$out/$target.log" || rc=$?
    echo "$rc" >"$out/$target.rc"
    echo "flight: $target: built and ran in $((SECONDS - start)) s (exit $rc)"
done

# Nothing wasted at start-up, on every target: no scratch initial values in flash
# (.data at most DATA_BUDGET bytes: the statics are zero bytes in .bss) and no table
# built on board (the camera model's set-up at most SETUP_BUDGET instructions: the band
# tables are build-time consts).
DATA_BUDGET=4096
SETUP_BUDGET=10000
for target in "${targets[@]}"; do
    data=$(awk '$1 == ".data" { print $2 }' "$out/$target.size")
    [[ ${data:-0} -le $DATA_BUDGET ]] \
        || die "$target: .data is $data B > $DATA_BUDGET B (initial values in flash: make the static zero bytes)"
    setup=$(awk '$1 == "sensor" { for (i = 2; i <= NF; i++) if ($i ~ /^setup_insns=/) { sub("setup_insns=", "", $i); print $i } }' "$out/$target.log")
    [[ -n $setup && $setup -le $SETUP_BUDGET ]] \
        || die "$target: camera-model set-up took ${setup:-?} instructions > $SETUP_BUDGET (tables built at start-up?)"
done
echo "flight: start-up budgets met (.data <= $DATA_BUDGET B, set-up <= $SETUP_BUDGET instructions)"
# The on-board DN + noise pass (table-driven: ziggurat draws, no libm on the common
# path) at most DN_NOISE_BUDGET instructions per pixel on the flight target (the FPU
# build; thumbv7m/thumbv6m do f32 in software and are only reported).
DN_NOISE_BUDGET=100
dn_noise=$(awk '$1 == "sensor" { for (i = 2; i <= NF; i++) if ($i ~ /^dn_noise_insns=/) { sub("dn_noise_insns=", "", $i); print $i } }' "$out/${targets[0]}.log")
[[ -n $dn_noise && $dn_noise -le $((DN_NOISE_BUDGET * 328 * 248)) ]] \
    || die "${targets[0]}: DN + noise took ${dn_noise:-?} instructions > $DN_NOISE_BUDGET per pixel"
echo "flight: ${targets[0]}: DN + noise $dn_noise instructions, $((dn_noise / (328 * 248))) per pixel (budget $DN_NOISE_BUDGET)"

# The STM32H7-class map (`--features dtcm`, firmware/memory-dtcm.x): statics (the one
# shared scratch area) and stack in a 128 KiB DTCM, the frame in AXI SRAM. Built for
# the flight target, run, its boxes and sensor checksum compared with the SAMV71
# build's, and its DTCM and AXI SRAM budgets checked.
DTCM_BUDGET=$((128 * 1024))
AXISRAM_BUDGET=$((512 * 1024))
echo "::: flight: ${targets[0]} --features dtcm (128 KiB DTCM map)"
# Same target dir as the builds above (the core, its dependencies and build-std are
# reused: only the firmware crate and the link run again); the ELF replaces the
# ${targets[0]} one, whose run is done, so it is copied aside first.
cp "$fw_target_dir/${targets[0]}/release/tirroi-firmware" "$out/${targets[0]}.elf"
(cd firmware && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build --release --quiet \
    --features dtcm --bin tirroi-firmware --target "${targets[0]}" --target-dir "$fw_target_dir" \
    -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem)
dtcm_elf="$out/${targets[0]}-dtcm.elf"
cp "$fw_target_dir/${targets[0]}/release/tirroi-firmware" "$dtcm_elf"
arm-none-eabi-size -A "$dtcm_elf" >"$out/dtcm.size"
rc=0
timeout 900 qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -monitor none \
    -serial none -semihosting-config enable=on,target=native \
    -icount shift=0,align=off,sleep=off -kernel "$dtcm_elf" >"$out/dtcm.log" || rc=$?
[[ $rc -eq 0 ]] && grep -q '^done' "$out/dtcm.log" \
    || die "the DTCM build failed on QEMU (exit $rc, see $out/dtcm.log)"
strip_counts() { grep -E '^(detect|sensor)' "$1" | sed -E 's/ (insns|stack|[a-z_]+_insns|[a-z_]+_stack)=[^ ]*//g'; }
diff <(strip_counts "$out/${targets[0]}.log") <(strip_counts "$out/dtcm.log") >/dev/null \
    || die "the DTCM build's boxes or sensor checksum differ from the ${targets[0]} build's"
dtcm_statics=$(awk '$1 == ".data" || $1 == ".bss" || $1 == ".uninit" { s += $2 } END { print s + 0 }' "$out/dtcm.size")
dtcm_stack=$(awk '$1 == "ram" { for (i = 2; i <= NF; i++) if ($i ~ /^stack_peak=/) { sub("stack_peak=", "", $i); print $i } }' "$out/dtcm.log")
axisram=$(awk '$1 == ".axisram" { print $2 }' "$out/dtcm.size")
echo "flight: DTCM map: statics $dtcm_statics B + stack peak ${dtcm_stack:-?} B of $DTCM_BUDGET B DTCM; frame ${axisram:-0} B of $AXISRAM_BUDGET B AXI SRAM"
[[ -n $dtcm_stack && $((dtcm_statics + dtcm_stack)) -le $DTCM_BUDGET ]] \
    || die "DTCM budget exceeded: statics $dtcm_statics B + stack ${dtcm_stack:-?} B > $DTCM_BUDGET B"
[[ ${axisram:-0} -gt 0 && $axisram -le $AXISRAM_BUDGET ]] \
    || die "AXI SRAM: the frame section is ${axisram:-missing} B (budget $AXISRAM_BUDGET B)"

# The defmt variant (`--features defmt`): built for the flight target, so the feature
# cannot rot; its output is binary (decode with `defmt-print -e ELF`).
echo "::: flight: ${targets[0]} --features defmt (build only)"
(cd firmware && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build --release --quiet \
    --features defmt --target "${targets[0]}" --target-dir "$fw_target_dir/defmt" \
    -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem)

if command -v defmt-print >/dev/null; then
    # Optional (cargo install defmt-print): run the defmt build and decode its frames.
    defmt_elf="$fw_target_dir/defmt/${targets[0]}/release/tirroi-firmware"
    timeout 900 qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -monitor none \
        -serial none -semihosting-config enable=on,target=native \
        -icount shift=0,align=off,sleep=off -kernel "$defmt_elf" >"$out/defmt.bin"
    defmt-print -e "$defmt_elf" <"$out/defmt.bin" >"$out/defmt.log"
    grep -q '^done' "$out/defmt.log" || die "the defmt build did not finish (see $out/defmt.log)"
    echo "flight: defmt build ran: $(stat -c %s "$out/defmt.bin") bytes of defmt frames, $(wc -l <"$out/defmt.log") lines decoded"
fi

if [[ $callgrind -eq 1 ]]; then
    command -v valgrind >/dev/null || die "valgrind not found (apt-get install valgrind), or pass --no-callgrind"
    echo "::: flight: callgrind (x86-64)"
    frames=$(awk '$1 == "link" { sub("frame=", "", $2); print $2 }' "$out/host-demo.log")
    methods=$(awk '$1 == "memory" { sub("method=", "", $2); print $2 }' "$out/host-demo.log")
    for frame in $frames on-board-sensor; do
        for method in $methods auto+prior auto-v2+prior; do
            # A tracker tracks only what it found (as the demo: no `+prior` line then).
            [[ $method == *+prior ]] && ! grep -q "^detect frame=$frame method=$method " "$out/host-demo.log" \
                && continue
            cg="$out/callgrind.$frame.$method.out"
            toggle='*Detectors*run*'
            [[ $method == *+prior ]] && toggle='*Detectors*track*'
            valgrind --tool=callgrind --toggle-collect="$toggle" \
                --callgrind-out-file="$cg" "$host_bin" "$frame" "$method" >"$out/callgrind.log" 2>&1 \
                || die "callgrind of $frame $method failed: see $out/callgrind.log"
            echo "$frame $method $(awk '/^totals:/ { print $2 }' "$cg")" >>"$out/callgrind.txt"
            rm -f "$cg"
        done
    done
fi

echo "::: flight: report"
"$fw_target_dir/host/release/examples/flight_report" "$out" "${targets[@]}"
