#!/usr/bin/env python3
"""Per-group breakdown of `tirroi eval` scores on a `tirroi testset` directory.

Usage: scripts/testset-breakdown.py TESTSET_DIR EVAL_OUT_DIR [KEY ...]

Joins EVAL_OUT_DIR/scores.csv (per frame and method) with TESTSET_DIR/metadata.jsonl
and prints, per method and value of each KEY of the metadata (default: background,
target, readout), the mean IoU and hit rate (IoU >= 0.5) over frames with a target and
the false-alarm rate (any box) over frames without one, as Markdown. The scoring is
eval's (docs/results.md, Scoring); this only regroups its per-frame rows. Stdlib only.
"""
import csv
import json
import sys
from collections import defaultdict


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    testset, evald = sys.argv[1], sys.argv[2]
    keys = sys.argv[3:] or ["background", "target", "readout"]
    meta = {}
    with open(f"{testset}/metadata.jsonl") as f:
        for line in f:
            r = json.loads(line)
            if r.get("saturated_px", 0) > 0 and r["target"] != "none":
                r["saturated"] = "yes"
            else:
                r["saturated"] = "no"
            meta[r["file"]] = r
    groups = defaultdict(lambda: {"iou": [], "fa": []})
    methods = []
    with open(f"{evald}/scores.csv") as f:
        for row in csv.DictReader(f):
            m = row["method"]
            if m not in methods:
                methods.append(m)
            r = meta[row["file"]]
            has_box = row["x0"] != "" and row["x1"] != row["x0"]
            for key in keys:
                g = groups[(m, key, str(r.get(key)))]
                if r["target"] == "none":
                    g["fa"].append(1.0 if has_box else 0.0)
                else:
                    g["iou"].append(float(row["iou"] or 0.0))
    print("| method | group | target frames | mean IoU | hit rate | no-target frames | false alarms |")
    print("|---|---|---|---|---|---|---|")
    for (m, key, value), g in sorted(groups.items(), key=lambda kv: (methods.index(kv[0][0]), kv[0][1], kv[0][2])):
        iou, fa = g["iou"], g["fa"]
        mean = f"{sum(iou) / len(iou):.3f}" if iou else "–"
        hit = f"{sum(1 for v in iou if v >= 0.5) / len(iou):.3f}" if iou else "–"
        far = f"{sum(fa) / len(fa):.3f}" if fa else "–"
        print(f"| {m} | {key} = {value} | {len(iou)} | {mean} | {hit} | {len(fa)} | {far} |")


if __name__ == "__main__":
    main()
