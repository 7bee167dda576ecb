#!/usr/bin/env bash
# The seed families `auto-v2` is chosen and judged on (issue 16: "tune only on your own
# seed family, evaluate on another, and report the drop"), rendered and scored the same
# way every session. Family A (seeds 7001, 7101, 7201) chooses parameters and trains the
# models (docs/detectors.md, training block); the held-out sets (seed 9001 and the test
# sets of `tirroi testset`, seed 16) only report.
#
#   family A:  famA   realistic, 600 frames, seed 7001 (masks: the forest's cell labels)
#              paperA paper, 300, seed 7001
#              fixA   `tirroi fixtures`, 400, seed 7001
#              famAF  scripts/training/realistic-far-radiometry.toml, 600, seed 7201
#              famAE  scripts/training/realistic-no-target.toml, 300, seed 7101 (no target)
#              famAT  realistic-tango, 300, seed 7001
#              paperAT tango (the paper world's Tango), 300, seed 7001 (session 57: the
#                     paper's Table 8 had no family-A set to choose on)
#              (famAT and paperAT are reported beside family A's sum, not in it)
#   held out:  famB   realistic, 600, seed 9001      famBT  realistic-tango, 300, seed 9001
#              paperB paper, 300, seed 9001          paperBT tango, 300, seed 9001
#              famBW  realistic-winged, 1 200, seed 9001: a target shape (a small satellite
#                     with two solar wings) no model was trained or tuned on
#              ts-fixtures, ts-dark, ts-real-earth: `tirroi testset --kind ...`, 200, seed 16
#              (the real dark frame and the real Earth image; they never choose)
#   approach sequences (`track`; `eval` and `compare` leave them out):
#              famAS  realistic-approach, 960 frames (40 sequences), seed 7001 (family A)
#              famASE scripts/training/realistic-approach-no-target.toml, 480, seed 7101
#                     (family A, no target)
#              famBS  realistic-approach, 960, seed 9001; famBSE the no-target file, 480,
#                     seed 9101 (held out)
#              ts-real-earth-seq `tirroi testset --kind real-earth --sequence-frames 24`,
#                     480 (20 sequences, half without a target), seed 16: the real
#                     Earth image sliding under a fixed target (held out, never chooses)
#
# Usage: scripts/families.sh render DIR          render every set into DIR (skips a set
#                                                 whose folder exists; ~3 min on 2 cores)
#        scripts/families.sh eval DIR [TIRROI]   `tirroi eval --method auto-v2` on each set,
#                                                 both truth conventions: one row per set
#                                                 and family A's summed mean IoU (½), then
#                                                 each set's table rows (mode × range)
#        scripts/families.sh track DIR [TIRROI]  tracking on the approach sequences (famAS,
#                                                 famASE, famBS, famBSE): `auto-v2` with
#                                                 --track off and sequence, mean IoU, false
#                                                 alarms and median time against adaptive's
#                                                 (all frames, and the frames it tracked:
#                                                 those after one where it had a box)
#        scripts/families.sh compare DIR A B     two binaries side by side (½ convention):
#                                                 each set's mean IoU and false alarms under
#                                                 A and B with the change, family A's and
#                                                 the held-out sets' summed change, and the
#                                                 table rows that moved (a candidate is
#                                                 chosen by family A; the held-out sum and
#                                                 false alarms are the drop to report);
#                                                 further arguments go to every eval
#                                                 (e.g. --track jitter)
# TIRROI: the binary to score (default target/release/tirroi, built if missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
die() { echo "families: $*" >&2; exit 2; }
[[ $# -ge 2 ]] || die "usage: scripts/families.sh render|eval|track DIR [TIRROI] | compare DIR A B"
cmd=$1
dir=$2
if [[ $cmd == compare ]]; then
    [[ $# -ge 4 ]] || die "usage: scripts/families.sh compare DIR A B [EVAL ARGS] (two tirroi binaries)"
    for bin in "$3" "$4"; do
        [[ -x $bin ]] || die "$bin is not an executable"
    done
    tirroi=$3
else
    tirroi=${3:-$root/target/release/tirroi}
    if [[ ! -x $tirroi ]]; then
        [[ $# -ge 3 ]] && die "$tirroi is not an executable"
        (cd "$root" && cargo build --release --quiet --bin tirroi)
    fi
fi

family_a=(famA paperA fixA famAF famAE famAT paperAT)
held_out=(famB famBT paperB paperBT famBW ts-fixtures ts-dark ts-real-earth)

# "family A" or "held out": the set's role in a choice.
role_of() {
    if [[ " ${family_a[*]} " == *" $1 "* ]]; then echo "family A"; else echo "held out"; fi
}

# `tirroi eval --method auto-v2` of binary BIN on every set into OUT/<set>; further
# arguments go to eval (e.g. --truth-coverage quarter).
score_sets() {
    local bin=$1 into=$2 name
    shift 2
    [[ -d $dir ]] || die "no folder $dir (run: scripts/families.sh render $dir)"
    for name in "${family_a[@]}" "${held_out[@]}"; do
        [[ -d $dir/$name ]] || die "no set $dir/$name (run: scripts/families.sh render $dir)"
        "$bin" eval --images "$dir/$name" --method auto-v2 --repeat 1 \
            --out "$into/$name" "$@" >/dev/null
    done
}

# Of group GROUP = VALUE in eval's SUMMARY.csv (method,group,value,frames,mean_iou,
# median_iou,hit_rate,mean_time_ms,median_time_ms,target_frames,false_alarm_rate,auc,
# calibration_gap): frames with a target, mean IoU, false alarms, frames without a
# target, AUC and calibration gap ("–" when empty), space-separated.
fields() {
    awk -F, -v g="$2" -v v="$3" '$2 == g && $3 == v {
        empty = $4 - $10
        printf "%s %s %d %d %s %s", $10, $5, $11 * empty + 0.5, empty,
            ($12 == "" ? "–" : $12), ($13 == "" ? "–" : $13)
    }' "$1"
}

# "FALSE_ALARMS / FRAMES_WITHOUT_TARGET", or "–" without such frames.
fa_text() {
    if [[ $2 -gt 0 ]]; then echo "$1 / $2"; else echo "–"; fi
}

render_set() {
    local name=$1
    shift
    if [[ -e $dir/$name ]]; then
        echo "families: $dir/$name exists, kept" >&2
        return
    fi
    echo "families: rendering $name" >&2
    "$tirroi" "$@" --out "$dir/$name" >/dev/null
}

case $cmd in
    render)
        mkdir -p "$dir"
        training="$root/scripts/training"
        render_set famA render --preset realistic --count 600 --seed 7001 --masks
        render_set paperA render --preset paper --count 300 --seed 7001 --masks
        render_set fixA fixtures --count 400 --seed 7001
        render_set famAF render --config "$training/realistic-far-radiometry.toml" \
            --count 600 --seed 7201 --masks
        render_set famAE render --config "$training/realistic-no-target.toml" \
            --count 300 --seed 7101
        render_set famAT render --preset realistic-tango --count 300 --seed 7001 --masks
        render_set paperAT render --preset tango --count 300 --seed 7001 --masks
        render_set famB render --preset realistic --count 600 --seed 9001 --masks
        render_set famBT render --preset realistic-tango --count 300 --seed 9001 --masks
        render_set paperB render --preset paper --count 300 --seed 9001 --masks
        render_set paperBT render --preset tango --count 300 --seed 9001 --masks
        render_set famBW render --preset realistic-winged --count 1200 --seed 9001
        for kind in fixtures dark real-earth; do
            render_set "ts-$kind" testset --kind "$kind" --count 200 --seed 16
        done
        render_set famAS render --preset realistic-approach --count 960 --seed 7001
        render_set famASE render --config "$training/realistic-approach-no-target.toml" \
            --count 480 --seed 7101
        render_set famBS render --preset realistic-approach --count 960 --seed 9001
        render_set famBSE render --config "$training/realistic-approach-no-target.toml" \
            --count 480 --seed 9101
        render_set ts-real-earth-seq testset --kind real-earth --sequence-frames 24 \
            --count 480 --seed 16 --no-target-fraction 0.5
        ;;
    track)
        # The median core time (ms) of method $2 in eval's SUMMARY.csv $1.
        median() { awk -F, -v m="$2" '$1 == m && $2 == "all" { print $9 }' "$1"; }
        out="$(mktemp -d)"
        trap 'rm -rf "$out"' EXIT
        printf '| set | role | frames with a target | mean IoU ½ off → sequence | false alarms off → sequence | median ms off → sequence (adaptive) | tracked frames | their median / adaptive |\n'
        printf '|---|---|---|---|---|---|---|---|\n'
        for name in famAS famASE famBS famBSE ts-real-earth-seq; do
            [[ -d $dir/$name ]] || die "no set $dir/$name (run: scripts/families.sh render $dir)"
            role="held out"
            [[ $name == famA* ]] && role="family A"
            for mode in off sequence; do
                "$tirroi" eval --images "$dir/$name" --method all --repeat 3 --track "$mode" \
                    --out "$out/$name-$mode" >/dev/null
                # `auto-v2`'s rows alone (`fields` reads a group's first row).
                grep '^auto-v2,' "$out/$name-$mode/summary.csv" >"$out/$name-$mode/auto-v2.csv"
            done
            read -r targets iou_off fa_off empty _ <<<"$(fields "$out/$name-off/auto-v2.csv" all all)"
            read -r _ iou_seq fa_seq _ <<<"$(fields "$out/$name-sequence/auto-v2.csv" all all)"
            t_off=$(median "$out/$name-off/summary.csv" auto-v2)
            t_seq=$(median "$out/$name-sequence/summary.csv" auto-v2)
            t_ad=$(median "$out/$name-sequence/summary.csv" adaptive)
            # The frames after one where auto-v2 had a box in the same sequence (eval's
            # group `prior = yes`): their count and median time over adaptive's median.
            read -r tracked ratio <<<"$(awk -F, -v ad="$t_ad" '
                $1 == "auto-v2" && $2 == "prior" && $3 == "yes" { printf "%d %.2f\n", $4, $9 / ad }
            ' "$out/$name-sequence/summary.csv")"
            [[ -n $tracked ]] || { tracked=0; ratio="–"; }
            [[ $targets -gt 0 ]] || { iou_off="–"; iou_seq="–"; }
            printf '| %s | %s | %s | %s → %s | %s → %s | %.3f → %.3f (%.3f) | %s | %s |\n' "$name" "$role" \
                "$targets" "$iou_off" "$iou_seq" "$(fa_text "$fa_off" "$empty")" \
                "$(fa_text "$fa_seq" "$empty")" "$t_off" "$t_seq" "$t_ad" "$tracked" "$ratio"
        done
        ;;
    eval)
        out="$(mktemp -d)"
        trap 'rm -rf "$out"' EXIT
        score_sets "$tirroi" "$out/half"
        score_sets "$tirroi" "$out/quarter" --truth-coverage quarter
        printf '| set | role | frames with a target | mean IoU ½ / ¼ | false alarms | AUC | calibration gap |\n'
        printf '|---|---|---|---|---|---|---|\n'
        sum=0
        for name in "${family_a[@]}" "${held_out[@]}"; do
            role=$(role_of "$name")
            read -r targets iou fa empty auc gap <<<"$(fields "$out/half/$name/summary.csv" all all)"
            read -r _ quarter _ <<<"$(fields "$out/quarter/$name/summary.csv" all all)"
            if [[ $targets -gt 0 ]]; then
                if [[ $role == "family A" && $name != famAT && $name != paperAT ]]; then
                    sum=$(awk -v a="$sum" -v b="$iou" 'BEGIN { printf "%.4f", a + b }')
                fi
            else
                iou="–" quarter="–"
            fi
            printf '| %s | %s | %s | %s / %s | %s | %s | %s |\n' \
                "$name" "$role" "$targets" "$iou" "$quarter" "$(fa_text "$fa" "$empty")" "$auc" "$gap"
        done
        printf '\nfamily A sum (famA + paperA + fixA + famAF, mean IoU ½): %s\n' "$sum"
        # The paper's table rows (mode × range, eval's `row` group) of the sets that
        # have them: where a change moved a set's figure.
        printf '\n| set | row | frames with a target | mean IoU ½ | false alarms |\n'
        printf '|---|---|---|---|---|\n'
        for name in "${family_a[@]}" "${held_out[@]}"; do
            summary="$out/half/$name/summary.csv"
            awk -F, '$2 == "row" { print $3 }' "$summary" | while read -r row; do
                read -r targets iou fa empty _ <<<"$(fields "$summary" row "$row")"
                [[ $targets -gt 0 ]] || iou="–"
                printf '| %s | %s | %s | %s | %s |\n' \
                    "$name" "$row" "$targets" "$iou" "$(fa_text "$fa" "$empty")"
            done
        done
        ;;
    compare)
        out="$(mktemp -d)"
        trap 'rm -rf "$out"' EXIT
        score_sets "$3" "$out/a" "${@:5}"
        score_sets "$4" "$out/b" "${@:5}"
        printf '| set | role | frames with a target | A mean IoU ½ | B mean IoU ½ | change | A false alarms | B false alarms |\n'
        printf '|---|---|---|---|---|---|---|---|\n'
        sum_a=0 sum_h=0
        for name in "${family_a[@]}" "${held_out[@]}"; do
            role=$(role_of "$name")
            read -r targets iou_a fa_a empty _ <<<"$(fields "$out/a/$name/summary.csv" all all)"
            read -r _ iou_b fa_b _ <<<"$(fields "$out/b/$name/summary.csv" all all)"
            if [[ $targets -gt 0 ]]; then
                delta=$(awk -v a="$iou_a" -v b="$iou_b" 'BEGIN { printf "%+.4f", b - a }')
                if [[ $role == "family A" && $name != famAT && $name != paperAT ]]; then
                    sum_a=$(awk -v s="$sum_a" -v d="$delta" 'BEGIN { printf "%+.4f", s + d }')
                elif [[ $role == "held out" ]]; then
                    sum_h=$(awk -v s="$sum_h" -v d="$delta" 'BEGIN { printf "%+.4f", s + d }')
                fi
            else
                iou_a="–" iou_b="–" delta="–"
            fi
            printf '| %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$role" "$targets" \
                "$iou_a" "$iou_b" "$delta" "$(fa_text "$fa_a" "$empty")" "$(fa_text "$fa_b" "$empty")"
        done
        printf '\nchange of family A sum (famA + paperA + fixA + famAF): %s\n' "$sum_a"
        printf 'change summed over the held-out sets: %s\n' "$sum_h"
        printf '\n| set | row | A mean IoU ½ | B mean IoU ½ | A false alarms | B false alarms |\n'
        printf '|---|---|---|---|---|---|\n'
        for name in "${family_a[@]}" "${held_out[@]}"; do
            summary="$out/a/$name/summary.csv"
            awk -F, '$2 == "row" { print $3 }' "$summary" | while read -r row; do
                read -r targets iou_a fa_a empty _ <<<"$(fields "$summary" row "$row")"
                read -r _ iou_b fa_b _ <<<"$(fields "$out/b/$name/summary.csv" row "$row")"
                [[ $iou_a == "$iou_b" && $fa_a == "$fa_b" ]] && continue
                [[ $targets -gt 0 ]] || { iou_a="–"; iou_b="–"; }
                printf '| %s | %s | %s | %s | %s | %s |\n' "$name" "$row" \
                    "$iou_a" "$iou_b" "$(fa_text "$fa_a" "$empty")" "$(fa_text "$fa_b" "$empty")"
            done
        done
        ;;
    *) die "unknown command $cmd (render, eval, track or compare)" ;;
esac
