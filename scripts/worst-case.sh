#!/usr/bin/env bash
# Worst-case instruction bounds (issue 18, part 2): builds the firmware's `worst-case`
# binary (firmware/src/worst_case.rs; release, thumbv7em-none-eabihf, Debian's cargo with
# -Zbuild-std=core, as scripts/flight.sh), runs it on QEMU's Cortex-M7 (mps2-an500,
# -icount shift=0: the SysTick counts instructions), which calls every detector on every
# adversarial frame of firmware/src/adversarial.rs (made on board, deterministic) and
# `auto` with each border prior, and compares the counts with firmware/worst-case-bounds.txt.
#
# Fails when a count exceeds its method's bound, when a method has no bound, or when a
# bound exceeds 1.25x its largest count (too loose: lower it); and, for `auto` within a
# work budget (a ladder of budgets on every frame and prior), when a call counts more
# instructions than it charged or charges more than its budget. Writes the table (bound,
# max, mean, ms at 100 MHz) to $CARGO_TARGET_DIR/worst-case/table.md, and Otsu's
# refinement passes per frame to $CARGO_TARGET_DIR/worst-case/otsu-passes.txt; fails when
# a frame takes more passes than Otsu's proven bound (core/src/roi/otsu.rs, "Worst case").
#
# Usage: scripts/worst-case.sh
# Needs: apt-get install rustc-web cargo-web rust-web-src lld qemu-system-arm
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"

target=thumbv7em-none-eabihf
cross_cargo="${CROSS_CARGO:-/usr/bin/cargo}"
cross_rustc="${CROSS_RUSTC:-/usr/bin/rustc}"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
fw_target_dir="$target_dir/firmware"
out="$target_dir/worst-case"
bounds=firmware/worst-case-bounds.txt
# A bound may be at most this many times the largest measured count.
max_slack=1.25
mkdir -p "$out"

die() { echo "worst-case: error: $*" >&2; exit 1; }
for tool in "$cross_cargo" "$cross_rustc" qemu-system-arm ld.lld; do
    command -v "$tool" >/dev/null || die "$tool not found (see the usage above for the packages)"
done

start=$SECONDS
(cd firmware && RUSTC="$cross_rustc" RUSTC_BOOTSTRAP=1 "$cross_cargo" build --release --quiet \
    --bin worst-case --target "$target" --target-dir "$fw_target_dir" \
    -Zbuild-std=core -Zbuild-std-features=compiler-builtins-mem)
echo "worst-case: built in $((SECONDS - start)) s"
elf="$fw_target_dir/$target/release/worst-case"
run_start=$SECONDS
rc=0
timeout 1800 qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -monitor none \
    -serial none -semihosting-config enable=on,target=native \
    -icount shift=0,align=off,sleep=off -kernel "$elf" >"$out/run.log" || rc=$?
[[ $rc -eq 0 ]] || die "the worst-case run failed (exit $rc): see $out/run.log"
grep -q '^worst done' "$out/run.log" || die "the worst-case run did not finish: see $out/run.log"
echo "worst-case: $(awk '/^worst done/ { sub("calls=", "", $3); print $3 }' "$out/run.log") calls on QEMU in $((SECONDS - run_start)) s"

# auto's fixed charge per call (core/src/roi/auto/budget.rs, CALL_INSTR).
call_instr=$(sed -n 's/^pub const CALL_INSTR: u32 = \([0-9_]*\);.*/\1/p' core/src/roi/auto/budget.rs | tr -d _)
[[ -n $call_instr ]] || die "CALL_INSTR not found in core/src/roi/auto/budget.rs"
awk -v slack="$max_slack" -v table="$out/table.md" -v passes_file="$out/otsu-passes.txt" -v call_instr="$call_instr" '
    FNR == NR {
        if ($0 ~ /^[ \t]*(#|$)/) next
        bound[$1] = $2; order[++n] = $1; next
    }
    $1 == "worst" && $2 ~ /^otsu-pass-bound=/ { split($2, kv, "="); pass_bound = kv[2] + 0; next }
    $1 == "worst" && /instructions=/ {
        delete v
        for (i = 2; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
        m = v["method"]; x = v["instructions"] + 0
        if (m == "auto-budget") {
            # A budgeted call: counted <= charged (+ the counter'"'"'s 40-instruction
            # resolution) and charged <= max(budget, the call'"'"'s fixed cost).
            c = v["charged"] + 0; b = v["budget"] + 0
            budget_calls++; stops[v["stopped"]]++
            if (x > c + 40) { printf "worst-case: error: auto-budget on %s prior %s: %d instructions > %d charged (budget %d)\n", v["case"], v["prior"], x, c, b; budget_bad = 1 }
            if (c > b && c > call_instr) { printf "worst-case: error: auto-budget on %s prior %s: charged %d > budget %d\n", v["case"], v["prior"], c, b; budget_bad = 1 }
            if (c > 0 && x / c > worst_share) { worst_share = x / c; worst_at = v["case"] " prior " v["prior"] " budget " b }
            next
        }
        calls[m]++; sum[m] += x
        if ("passes" in v) {
            p = v["passes"] + 0; pass_calls++
            printf "%s passes=%d instructions=%d\n", v["case"], p, x > passes_file
            if (pass_calls == 1 || p > max_passes) { max_passes = p; max_passes_at = v["case"] }
            pass_hist[p]++
        }
        if (!(m in max) || x > max[m]) { max[m] = x; at[m] = v["case"] (("prior" in v) ? " prior " v["prior"] : "") (("look" in v) ? " look " v["look"] : "") (("step" in v) ? " step " v["step"] : "") }
        if (!(m in seen)) { seen[m] = 1; extra[++k] = m }
    }
    END {
        bad = 0
        print "| detector | bound | max measured | at | mean | bound / max | ms at 100 MHz (max) | calls |" > table
        print "|---|---|---|---|---|---|---|---|" > table
        for (j = 1; j <= k; j++) {
            m = extra[j]
            if (!(m in bound)) { printf "worst-case: error: %s has no bound in the bounds file\n", m; bad = 1; continue }
            ratio = bound[m] / max[m]
            printf "| %s | %.2f M | %.2f M | %s | %.2f M | %.3f | %.1f | %d |\n", m, bound[m] / 1e6, max[m] / 1e6, at[m], sum[m] / calls[m] / 1e6, ratio, max[m] / 1e5, calls[m] > table
            printf "worst-case: %-10s bound %6.2f M  max %6.2f M (%s)  mean %6.2f M  bound/max %.3f\n", m, bound[m] / 1e6, max[m] / 1e6, at[m], sum[m] / calls[m] / 1e6, ratio
            if (max[m] > bound[m]) { printf "worst-case: error: %s: %d instructions on %s exceed the bound %d\n", m, max[m], at[m], bound[m]; bad = 1 }
            if (ratio > slack) { printf "worst-case: error: %s: bound %d is more than %.2fx the largest count %d: lower it\n", m, bound[m], slack, max[m]; bad = 1 }
        }
        for (j = 1; j <= n; j++) if (!(order[j] in seen)) printf "worst-case: note: %s has a bound but was not run\n", order[j]
        if (pass_calls == 0 || pass_bound == 0) { print "worst-case: error: no Otsu pass counts (passes=, otsu-pass-bound=) in the run"; bad = 1 }
        else {
            line = ""
            for (p = 0; p <= pass_bound + 1; p++) if (p in pass_hist) line = line " " p ":" pass_hist[p]
            printf "worst-case: otsu refinement passes: max %d (%s), proven bound %d; frames per pass count:%s\n", max_passes, max_passes_at, pass_bound, line
            printf "\nOtsu refinement passes: max %d (%s), proven bound %d; frames per pass count (passes:frames):%s.\n", max_passes, max_passes_at, pass_bound, line > table
            if (max_passes > pass_bound) { printf "worst-case: error: otsu: %d refinement passes on %s exceed the proven bound %d\n", max_passes, max_passes_at, pass_bound; bad = 1 }
        }
        if (budget_calls > 0) {
            line = ""
            for (st in stops) line = line " " st "=" stops[st]
            printf "worst-case: auto-budget: %d budgeted calls, counted <= charged on all: %s; largest counted/charged %.3f (%s); stops:%s\n", budget_calls, budget_bad ? "NO" : "yes", worst_share, worst_at, line
            printf "\n`auto` within a work budget: %d calls (every adversarial frame, no prior and each prior, budgets of 0/8..7/8 of the full charge and unlimited): instructions counted <= charged on all: %s; largest counted / charged %.3f (%s).\n", budget_calls, budget_bad ? "NO" : "yes", worst_share, worst_at > table
        } else { print "worst-case: error: no auto-budget lines in the run"; bad = 1 }
        exit bad || budget_bad
    }' "$bounds" "$out/run.log" || die "a worst-case bound failed (table: $out/table.md)"
echo "worst-case: all counts within their bounds ($((SECONDS - start)) s)"
