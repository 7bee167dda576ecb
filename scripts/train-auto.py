#!/usr/bin/env python3
"""Train auto-v2's cell classifier and write core/src/roi/auto/learned/forest_trees.rs.

Input: cell CSVs written by
  cargo run --release -p tirroi-host --example auto_v2_cells -- features DIR OUT.csv
for datasets rendered with --masks (the development family: seed 7001). A cell is a
target cell when at least 6 of its 64 pixels' worth are covered (coverage >= 24 of
255), or when it is its frame's most covered cell (a 3-12 px far target may cover
6 px of no cell); background when nothing of it is; cells touched less are left out.

A CELLS argument may name its dataset, `CELLS.csv@DATASET` (the rendered folder the
CSV was dumped from): then a target cell whose pixels do not differ from the
background next to it is left out (label noise, `indistinguishable` below).

Model: scikit-learn HistGradientBoostingClassifier (DEPTH, TREES below, fixed
random_state), leaf values and the bias scaled by 256 (SCORE_ONE) and rounded,
thresholds floored (the features are integers, so `x <= t` is `x <= floor(t)`).

Usage: scripts/train-auto.py OUT.rs CELLS.csv [CELLS.csv ...]
"""
import sys
import numpy as np
from sklearn.ensemble import HistGradientBoostingClassifier

SCORE_ONE = 256
# Depth 4, 100 trees (with the fixtures family in the training set): on family B (seed
# 9001) the cell AUC rises 0.925 → 0.942 over depth 3 / 60 trees without it, and the
# test fixtures' (seed 16) false cells at even odds fall 12 % → 0.5 %; 400 node visits
# per 8×8 cell (≈ 6 per pixel).
DEPTH, TREES = 4, 100
# A cell is a target cell from 24/255 of it covered (6 of its 64 pixels): a far
# target of 3-12 px never fills half a cell, and must still be learned.
POSITIVE_COVERAGE = 24


# The label rule (`CELLS.csv@DATASET`): a target cell is label noise when both its
# hottest and its coldest 4x4-pixel window (2-px stride, as the core's
# `sub_window_extremes`) stay within CLEAN_SPREADS spreads of the median cell mean of
# the background cells (coverage 0) within CLEAN_RING_CELLS cells (Chebyshev; widened
# to CLEAN_RING_WIDE_CELLS when fewer than CLEAN_RING_MIN are there); spread = the
# larger of 1.4826 x their median absolute deviation and sigma / 4 (a 16-px window's
# noise, sigma from the frame's metadata `noise_sigma_dn`). Without any background cell
# nearby the cell stays a target cell. On family A (famA25) the rule leaves out 1 872
# of 12 439 target cells (25 % of radiometry-close ones: faces at the Earth's level).
CLEAN_SPREADS = 3.0
CLEAN_RING_CELLS, CLEAN_RING_WIDE_CELLS, CLEAN_RING_MIN = 3, 8, 4


def indistinguishable(a, dataset):
    """Boolean per row of the cell table `a`: a target cell at the background's level."""
    import json
    from PIL import Image
    meta = [json.loads(line) for line in open(f"{dataset}/metadata.jsonl")]
    out = np.zeros(len(a), dtype=bool)
    starts = np.r_[0, np.nonzero(np.diff(a[:, 0]))[0] + 1, len(a)]
    for s0, s1 in zip(starts[:-1], starts[1:]):
        rows = a[s0:s1]
        if not (rows[:, 3] >= POSITIVE_COVERAGE).any():
            continue
        m = meta[rows[0, 0]]
        img = np.asarray(Image.open(f"{dataset}/{m['file']}")).astype(np.float64)
        ph, pw = img.shape[0] // 8, img.shape[1] // 8
        img = img[:ph * 8, :pw * 8]
        means = img.reshape(ph, 8, pw, 8).mean(axis=(1, 3))
        b = img.reshape(ph * 4, 2, pw * 4, 2).sum(axis=(1, 3))
        win = (b[:-1, :-1] + b[1:, :-1] + b[:-1, 1:] + b[1:, 1:]) / 16
        cov = np.full((ph, pw), -1)
        cov[rows[:, 2], rows[:, 1]] = rows[:, 3]
        sigma = float(m.get("noise_sigma_dn") or 1.0)
        for k in np.nonzero(rows[:, 3] >= POSITIVE_COVERAGE)[0]:
            cx, cy = rows[k, 1], rows[k, 2]
            for r in (CLEAN_RING_CELLS, CLEAN_RING_WIDE_CELLS):
                y0, y1, x0, x1 = max(0, cy - r), min(ph, cy + r + 1), max(0, cx - r), min(pw, cx + r + 1)
                bg = means[y0:y1, x0:x1][cov[y0:y1, x0:x1] == 0]
                if len(bg) >= CLEAN_RING_MIN:
                    break
            if len(bg) < CLEAN_RING_MIN:
                continue
            med = np.median(bg)
            spread = max(1.4826 * np.median(np.abs(bg - med)), sigma / 4)
            w = win[4 * cy:4 * cy + 3, 4 * cx:4 * cx + 3]
            out[s0 + k] = np.abs(w - med).max() < CLEAN_SPREADS * spread
    return out


def load(paths):
    xs, ys = [], []
    for spec in paths:
        p, _, dataset = spec.partition("@")
        a = np.loadtxt(p, delimiter=",", skiprows=1, dtype=np.int64)
        cov = a[:, 3]
        pos = cov >= POSITIVE_COVERAGE
        # Each frame's most covered cell (first in scan order on ties), when covered.
        frame = a[:, 0]
        order = np.lexsort((-cov, frame))
        first = order[np.r_[True, frame[order][1:] != frame[order][:-1]]]
        pos[first[cov[first] > 0]] = True
        keep = pos | (cov == 0)
        if dataset:
            noise = indistinguishable(a, dataset)
            keep &= ~noise
            print(f"{p}: {int(noise.sum())} of {int((cov >= POSITIVE_COVERAGE).sum())} target cells left out")
        xs.append(a[keep, 4:])
        ys.append(pos[keep])
    return np.concatenate(xs), np.concatenate(ys)


def fit_forest(x, y, depth, trees):
    """Boosted trees of `depth` (`trees` of them) fitted to hits `y` of features `x`:
    learning rate 0.1, no early stopping, a fixed random state (reproducible tables)."""
    clf = HistGradientBoostingClassifier(max_depth=depth, max_iter=trees, learning_rate=0.1,
                                         early_stopping=False, random_state=0)
    return clf.fit(x, y)


def write_forest(out, clf, generator, about, bias_doc):
    """Writes the fitted HistGradientBoostingClassifier `clf` as a node table
    (`forest::Node`): leaf values and the bias × SCORE_ONE rounded, thresholds floored."""
    nodes, roots = [], []
    for (pred,) in clf._predictors:
        base = len(nodes)
        roots.append(base)
        for n in pred.nodes:
            if n["is_leaf"]:
                nodes.append((255, 0, 0, 0, int(round(float(n["value"]) * SCORE_ONE))))
            else:
                nodes.append((int(n["feature_idx"]), int(np.floor(n["num_threshold"])),
                              base + int(n["left"]), base + int(n["right"]), 0))
    bias = int(round(float(np.ravel(clf._baseline_prediction)[0]) * SCORE_ONE))
    with open(out, "w") as f:
        f.write(f"//! Generated by `{generator}`: do not edit.\n")
        f.write(f"//! {about}\n")
        f.write("use super::forest::Node;\n")
        f.write(f"/// {bias_doc}\n")
        f.write(f"pub const BIAS: i32 = {bias};\n")
        f.write("/// Roots of the trees (indices into [`NODES`]).\n")
        f.write(f"pub const ROOTS: [u16; {len(roots)}] = [{', '.join(map(str, roots))}];\n")
        f.write("/// The trees' nodes (a `static`: one copy in flash).\n")
        f.write(f"pub static NODES: [Node; {len(nodes)}] = [\n")
        for (fe, th, l, r, v) in nodes:
            f.write(f"    Node {{ feature: {fe}, threshold: {th}, left: {l}, right: {r}, value: {v} }},\n")
        f.write("];\n")
    return nodes, roots, bias


def main():
    out, paths = sys.argv[1], sys.argv[2:]
    x, y = load(paths)
    clf = fit_forest(x, y, DEPTH, TREES)
    nodes, roots, bias = write_forest(
        out, clf, "scripts/train-auto.py",
        f"{TREES} trees of depth {DEPTH}; trained on {len(y)} cells ({int(y.sum())} target) of: "
        + ", ".join(p.split('@')[0].split('/')[-1] for p in paths) + ".",
        "Bias (the log-odds of a target cell before any tree), score units.")
    print(f"wrote {out}: {len(roots)} trees, {len(nodes)} nodes, bias {bias}, cells {len(y)}")


if __name__ == "__main__" and sys.argv[1:2] not in (["--confidence"], ["--blob"], ["--spots"]):
    main()


# --- the confidence model --------------------------------------------------------
# `scripts/train-auto.py --confidence OUT.rs PRED.csv DATASET [PRED.csv DATASET ...]`:
# PRED.csv from `auto_v2_cells predict` (gate off: every winner, with its statistics),
# DATASET the rendered folder (metadata.jsonl with the truth). A winner is a hit when
# its box has IoU >= 0.5 with the truth (0.5-coverage convention); a logistic
# regression of hit on the integer winner features below, as the core computes them
# (`learned::confidence_features`), gives integer weights (4096 per unit).

CONF_FEATURES = ["log_cells", "log_box", "fill_permille", "sides", "mean_code16",
                 "code_max", "log_components", "runner_up_permille", "compact_permille",
                 "contrast_code", "clutter_code",
                 # Session 26 (`shape.rs`): how the winner meets the frame's edge, how flat
                 # its cells are, and terms per size class (small: 1-2 cells, far targets).
                 "log_edge_sides", "log_reach", "spans", "spread_code", "spread_minus_contrast",
                 "step_mean_code", "interior_permille", "interior_step_code", "straight_permille",
                 "small", "small_clutter", "small_mean_code16", "touch_mean_code16",
                 # Session 33 (`shape::roughness_permille`): rough pixels inside, per mille.
                 "rough_permille"]
CONF_ONE = 4096
# Features the model uses (the others get weight 0): statistics of the winner itself
# that do not count the background (issue 16: on real GOES texture the forest finds ~5
# components per frame, and a weight on their number gated the hits), so the component
# count and the runner-up are left out. Chosen on family A (famA25, paperAm, fixA) by
# backward elimination of the leave-one-set-out AUC of hits (fit on two sets, score the
# third): the 9 candidates give 0.851; without the border contrast in σ, the best cell
# code, the fill, the compactness and the box 0.872 (0.876 / 0.805 / 0.934); dropping
# the sides too lowers it (0.870). (The previous 5 with the component count: 0.871.)
# Session 26: the new winner statistics (edge stretch, reach, spans, spread, steps,
# interior, straightness, size-class terms) added one at a time by a 10-fold
# cross-validated objective on family A (every winner's out-of-fold score; the lowest
# gate in steps of 0.05 with false alarms <= 2 % on every kind's no-target frames; the
# summed gated mean IoU of the three sets, 1/2 convention): the 4 above 1.950 (gate
# 0.60), + the interior cells' step code 1.986, + the small-winner term 1.989 (gate
# 0.55); nothing else adds 0.002. See docs/detectors.md § auto-v2.
# Session 33: the roughness added, trained with 300 more realistic frames without a
# target (famAE, scripts/training/realistic-no-target.toml): family A's summed gated IoU
# 2.078 = 2.078 with false alarms 15 -> 11 of 440 (the famAE set alone, without the
# roughness: 2.046, 9; the roughness alone: 2.100, 17). docs/detectors.md § Session 33.
CONF_KEEP = ["log_cells", "sides", "mean_code16", "clutter_code", "interior_step_code", "small",
             "rough_permille"]


def log_code(v):
    x = int(v) + 1
    l = x.bit_length() - 1
    return 16 * l + ((x << 4) >> l) - 16


def conf_features(r):
    c, w, h = int(r["cells"]), int(r["box_w"]), int(r["box_h"])
    sides, mean16, clutter = int(r["sides"]), int(r["code_sum"]) * 16 // max(c, 1), int(r["clutter_code"])
    small = int(c <= SMALL_CELLS)
    return [log_code(c - 1), log_code(w * h - 1), c * 1000 // (w * h), sides,
            mean16, int(r["code_max"]), log_code(int(r["components"])),
            int(r["runner_up"]), compact_permille(c, int(r["perimeter"])), int(r["contrast_code"]),
            clutter,
            log_code(int(r["edge_sides"])), log_code(int(r["reach"])), int(r["spans"]),
            int(r["spread_code"]), int(r["spread_code"]) - int(r["contrast_code"]),
            int(r["step_mean_code"]), int(r["interior_cells"]) * 1000 // max(c, 1),
            int(r["interior_step_code"]), straight_permille(w, h, int(r["perimeter"])),
            small, small * clutter, small * mean16, int(sides > 0) * mean16,
            int(r.get("rough") or 0)]


# A winner of at most this many cells is "small" (a far target, 3-12 px: one or two
# 8x8 cells), `learned::SMALL_WINNER_CELLS`.
SMALL_CELLS = 2


def straight_permille(w, h, perimeter):
    """The cell box's outline over the component's, in per mille, capped at 1000 (a
    component that fills its box, or any orthogonally convex one, 1000)."""
    return min(1000, 2 * (w + h) * 1000 // max(perimeter, 1))


def compact_permille(cells, perimeter):
    """16 · cells / perimeter² in ‰, capped at a square's 1000 (`Winner::confidence_features`)."""
    p = max(perimeter, 1)
    return min(1000, 16 * max(cells, 1) * 1000 // (p * p))


def iou(a, b):
    ix = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    i = ix * iy
    u = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - i
    return i / u if u > 0 else 0.0


def truth_boxes(dataset):
    """File -> truth box (x0, y0, x1, y1; the 0.5-coverage convention) of the rendered
    folder DATASET's metadata.jsonl, None for a frame without a target."""
    import json
    truth = {}
    for line in open(f"{dataset}/metadata.jsonl"):
        m = json.loads(line)
        truth[m["file"]] = m["bbox"] if m.get("target") != "none" else None
    return truth


def confidence(out, pairs):
    import csv
    from sklearn.linear_model import LogisticRegression
    xs, ys = [], []
    for pred, dataset in pairs:
        truth = truth_boxes(dataset)
        for r in csv.DictReader(open(pred)):
            if not r["cells"]:
                continue
            t = truth[r["file"]]
            hit = t is not None and r["x0"] != "" and iou([int(r[k]) for k in ("x0", "y0", "x1", "y1")], t) >= 0.5
            xs.append(conf_features(r))
            ys.append(hit)
    x, y = np.array(xs, dtype=float), np.array(ys)
    keep = [CONF_FEATURES.index(k) for k in CONF_KEEP]
    scale = x[:, keep].std(axis=0) + 1e-9
    lr = LogisticRegression(max_iter=5000, C=1.0).fit(x[:, keep] / scale, y)
    weights = [0] * len(CONF_FEATURES)
    for i, c, s in zip(keep, lr.coef_[0], scale):
        weights[i] = int(round(c / s * CONF_ONE))
    bias = int(round(lr.intercept_[0] * CONF_ONE))
    with open(out, "w") as f:
        f.write("//! Generated by `scripts/train-auto.py --confidence`: do not edit.\n")
        f.write(f"//! Logistic regression of a hit on the winner's features; {len(y)} winners "
                f"({int(y.sum())} hits) of: " + ", ".join(p.split("/")[-1] for p, _ in pairs) + ".\n")
        f.write("/// Weights per feature of `confidence_features`, 4096 per unit of log-odds.\n")
        f.write(f"pub const WEIGHTS: [i32; {len(weights)}] = [{', '.join(map(str, weights))}];\n")
        f.write("/// Bias, 4096 per unit of log-odds.\n")
        f.write(f"pub const BIAS: i32 = {bias};\n")
    print(f"wrote {out}: weights {weights}, bias {bias}, winners {len(y)}, hits {int(y.sum())}")


# --- the saturated blob's model ----------------------------------------------------
# `scripts/train-auto.py --blob OUT.rs PRED.csv DATASET [PRED.csv DATASET ...]`:
# PRED.csv from `auto_v2_cells predict-all DIR PRED.csv 0 ERODE 3 2 5 250 100 always`
# (`BlobRule::Always`: every frame's largest saturated blob is the winner, with its
# statistics, `learned::blob::BlobStats`). A blob is a hit when that box has IoU >= 0.5 with the
# truth (0.5-coverage convention); a logistic regression of hit on the blob's integer
# features (`BlobStats::features`) gives integer weights (4096 per unit).

BLOB_FEATURES = ["log_px", "solid_permille", "ring_depth_permille", "log_other_permille", "sides",
                 "many_sides"]
MANY_SIDES = 3  # `learned::blob::MANY_SIDES`


def blob_features(r):
    sides = int(r["blob_sides"])
    return [log_code(int(r["blob_px"]) - 1), int(r["blob_solid"]), int(r["blob_ring"]),
            log_code(int(r["blob_other"])), sides, int(sides >= MANY_SIDES)]


def blob_rows(pred, dataset):
    """(file, features, hit) of every frame of PRED.csv with a saturated blob."""
    import csv
    truth = truth_boxes(dataset)
    out = []
    for r in csv.DictReader(open(pred)):
        if not r["blob_px"]:
            continue
        t = truth[r["file"]]
        hit = t is not None and r["x0"] != "" and iou([int(r[k]) for k in ("x0", "y0", "x1", "y1")], t) >= 0.5
        out.append((r["file"], blob_features(r), hit))
    return out


def blob(out, pairs):
    from sklearn.linear_model import LogisticRegression
    rows = [row for pred, dataset in pairs for row in blob_rows(pred, dataset)]
    x = np.array([f for _, f, _ in rows], dtype=float)
    y = np.array([h for _, _, h in rows])
    scale = x.std(axis=0) + 1e-9
    lr = LogisticRegression(max_iter=5000, C=1.0).fit(x / scale, y)
    weights = [int(round(c / s * CONF_ONE)) for c, s in zip(lr.coef_[0], scale)]
    bias = int(round(lr.intercept_[0] * CONF_ONE))
    with open(out, "w") as f:
        f.write("//! Generated by `scripts/train-auto.py --blob`: do not edit.\n")
        f.write(f"//! Logistic regression of a hit on the largest saturated blob's features; {len(y)} "
                f"blobs ({int(y.sum())} hits) of: " + ", ".join(p.split("/")[-1] for p, _ in pairs) + ".\n")
        f.write("/// Weights per feature of `BlobStats::features` (" + ", ".join(BLOB_FEATURES)
                + "), 4096 per unit of log-odds.\n")
        f.write(f"pub const WEIGHTS: [i32; {len(weights)}] = [{', '.join(map(str, weights))}];\n")
        f.write("/// Bias, 4096 per unit of log-odds.\n")
        f.write(f"pub const BIAS: i32 = {bias};\n")
    print(f"wrote {out}: weights {weights}, bias {bias}, blobs {len(y)}, hits {int(y.sum())}")


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "--blob":
    rest = sys.argv[3:]
    blob(sys.argv[2], list(zip(rest[0::2], rest[1::2])))


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "--confidence":
    rest = sys.argv[3:]
    confidence(sys.argv[2], list(zip(rest[0::2], rest[1::2])))


# --- stage 5e's spot forest --------------------------------------------------------
# `scripts/train-auto.py --spots OUT.rs SPOTS.csv DATASET [SPOTS.csv DATASET ...]`:
# SPOTS.csv from `auto_v2_cells spots DATASET SPOTS.csv` (every frame's rated spots, with
# their regions' boxes and the features `learned::spot` computes), DATASET the rendered
# folder (metadata.jsonl with the truth). A spot is a hit when its region's box has
# IoU >= 0.5 with the truth (0.5-coverage convention); frames without a target give
# misses only. Model: HistGradientBoostingClassifier, SPOT_DEPTH / SPOT_TREES, fixed
# random_state, written as `spot_trees.rs` (the cell forest's format).
#
# Depth 3, 100 trees: chosen on family A in a numpy prototype of the stage (scikit-learn
# GradientBoostingClassifier, family A's frames): 40 trees gave radiometry far 0.23 of
# 0.27 at 100; a logistic regression of the same features 0.06 (z, the level and the
# region's size interact: a spot over deep space has z in the thousands).
SPOT_DEPTH, SPOT_TREES = 3, 100


def spot_rows(spots, dataset):
    """(features, hit) of every spot of SPOTS.csv."""
    import csv
    truth = truth_boxes(dataset)
    out = []
    for r in csv.DictReader(open(spots)):
        t = truth[r["file"]]
        box = [int(r[k]) for k in ("x0", "y0", "x1", "y1")]
        feats = [int(v) for c, v in r.items() if c[:1] == "f" and c[1:].isdigit()]
        out.append((feats, t is not None and iou(box, t) >= 0.5))
    return out


def spots(out, pairs):
    rows = [row for sp, dataset in pairs for row in spot_rows(sp, dataset)]
    x = np.array([f for f, _ in rows], dtype=np.int64)
    y = np.array([h for _, h in rows])
    clf = fit_forest(x, y, SPOT_DEPTH, SPOT_TREES)
    nodes, roots, bias = write_forest(
        out, clf, "scripts/train-auto.py --spots",
        f"{SPOT_TREES} trees of depth {SPOT_DEPTH}; trained on {len(y)} spots ({int(y.sum())} hits) of: "
        + ", ".join(p.split("/")[-1] for p, _ in pairs) + ".",
        "Bias (the log-odds of a hit before any tree), score units.")
    print(f"wrote {out}: {len(roots)} trees, {len(nodes)} nodes, bias {bias}, spots {len(y)}, hits {int(y.sum())}")


if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] == "--spots":
    rest = sys.argv[3:]
    spots(sys.argv[2], list(zip(rest[0::2], rest[1::2])))
