#!/usr/bin/env python3
"""Offline study of confirming `auto-v2`'s candidates over an approach sequence
(docs/detectors.md § Session 42, items 3 and 4): a box below the confidence gate is
accepted once it followed itself (`follows_prior`, the fast path's rule) on M
consecutive frames with a confidence of at least F, and, with --ground, only when over
those frames its centre moved against the ground's motion by at least D px per frame
on the net. The ground's shift between consecutive frames: `--ground fft`, the peak of
the phase correlation of the whole frames (high-passed by a 15-px box, Hann window),
taken as zero where the peak is under --peak (deep space: the camera's own pattern
stays put); `--ground patches`, block matching of 16 patches (a flight-sized
registration), taken as zero where fewer than --peak of them agree.

Needs numpy, scipy and Pillow. Inputs: a set rendered with `sequence` (truth.csv with
`sequence,frame`) and each frame's winner with the gate off:

    cargo run --release -p tirroi-host --example auto_v2_cells -- predict-all DIR W.csv
    python3 scripts/sequence-confirmation.py DIR W.csv [--ground fft|patches] [--peak P]

Prints the gate alone's mean IoU and false alarms (frames without a target given a
box), then the same for each M, D (with --ground) and F. A study, not the detector:
the gate-off winners are not what `auto-v2` answers at its default gate.
"""
import argparse
import csv

import numpy as np
from PIL import Image
from scipy import ndimage


def iou(a, b):
    if a is None or b is None:
        return 0.0
    ix = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union else 0.0


def follows(p, r):
    """`follows_prior` of core/src/roi/auto/learned/mod.rs: IoU >= 0.3 and every side
    within 4 px + 10 % of the prior's size."""
    ix = max(0, min(p[2], r[2]) - max(p[0], r[0]))
    iy = max(0, min(p[3], r[3]) - max(p[1], r[1]))
    inter = ix * iy
    union = (p[2] - p[0]) * (p[3] - p[1]) + (r[2] - r[0]) * (r[3] - r[1]) - inter
    sx = 4 + (p[2] - p[0]) * 100 // 1000
    sy = 4 + (p[3] - p[1]) * 100 // 1000
    near = lambda a, b, s: abs(a - b) <= s
    return (inter * 1000 >= union * 300 and near(r[0], p[0], sx) and near(r[2], p[2], sx)
            and near(r[1], p[1], sy) and near(r[3], p[3], sy))


def ground_shift(a, b):
    """Displacement (dx, dy) of frame b against frame a, px, and the correlation peak."""
    def high_pass(x):
        x = x - ndimage.uniform_filter(x, 15)
        lo, hi = np.percentile(x, [1, 99])
        x = np.clip(x, lo, hi)
        return (x - x.mean()) * np.outer(np.hanning(x.shape[0]), np.hanning(x.shape[1]))
    fa, fb = np.fft.fft2(high_pass(a)), np.fft.fft2(high_pass(b))
    cross = fb * np.conj(fa)
    cross /= np.abs(cross) + 1e-9
    r = np.fft.ifft2(cross).real
    iy, ix = np.unravel_index(np.argmax(r), r.shape)
    h, w = r.shape
    return (ix if ix < w // 2 else ix - w), (iy if iy < h // 2 else iy - h), float(r.max())


PATCH_GRID, PATCH_PX, SEARCH_PX = 4, 16, 12


def patch_shift(a, b):
    """The ground's shift by block matching, a flight-sized registration: in each cell of
    a 4 x 4 grid the 16 x 16 patch of frame a with the most gradient (on a 4-px lattice),
    found in frame b by the least sum of absolute differences (patch means removed) over
    +-12 px; the median displacement, and the share of patches within 1 px of it (its
    confidence)."""
    h, w = a.shape
    grad = np.abs(np.diff(a, axis=0))[:, :-1] + np.abs(np.diff(a, axis=1))[:-1, :]
    moves = []
    span = lambda n, k: (SEARCH_PX + k * (n - 2 * SEARCH_PX - PATCH_PX) // PATCH_GRID)
    for gy in range(PATCH_GRID):
        for gx in range(PATCH_GRID):
            best = max(((grad[y:y + PATCH_PX, x:x + PATCH_PX].sum(), y, x)
                        for y in range(span(h, gy), max(span(h, gy) + 1, span(h, gy + 1)), 4)
                        for x in range(span(w, gx), max(span(w, gx) + 1, span(w, gx + 1)), 4)))
            _, y, x = best
            p = a[y:y + PATCH_PX, x:x + PATCH_PX]
            p = p - p.mean()
            cost = {}
            for dy in range(-SEARCH_PX, SEARCH_PX + 1):
                for dx in range(-SEARCH_PX, SEARCH_PX + 1):
                    q = b[y + dy:y + dy + PATCH_PX, x + dx:x + dx + PATCH_PX]
                    cost[(dx, dy)] = np.abs(p - (q - q.mean())).sum()
            moves.append(min(cost, key=cost.get))
    moves = np.array(moves)
    m = np.median(moves, axis=0)
    agree = float(np.mean(np.all(np.abs(moves - m) <= 1, axis=1)))
    return int(m[0]), int(m[1]), agree


def load(images, winners, ground, peak):
    truth = list(csv.DictReader(open(f"{images}/truth.csv")))
    if not truth or "sequence" not in truth[0]:
        raise SystemExit(f"{images}/truth.csv: no `sequence` column (render with `sequence`)")
    won = {r["file"]: r for r in csv.DictReader(open(winners))}
    box = lambda r, k: tuple(int(r[c]) for c in k) if r[k[0]] else None
    sequences, last, last_seq = {}, None, None
    for t in sorted(truth, key=lambda r: r["file"]):
        w = won[t["file"]]
        g = (0, 0)
        if ground:
            frame = np.asarray(Image.open(f"{images}/{t['file']}"), dtype=np.float64)
            if last is not None and t["sequence"] == last_seq:
                dx, dy, p = (patch_shift if ground == "patches" else ground_shift)(last, frame)
                if p >= peak:
                    g = (dx, dy)
            last, last_seq = frame, t["sequence"]
        sequences.setdefault(t["sequence"], []).append((
            box(t, ("x0", "y0", "x1", "y1")), box(w, ("x0", "y0", "x1", "y1")),
            float(w["score"]) if w["score"] else 0.0, g))
    return sequences


def score(sequences, m, floor, d, gate=0.55):
    total = n = alarms = empty = 0
    for frames in sequences.values():
        run, prev, rx, ry = 0, None, 0.0, 0.0
        for truth, got, conf, g in frames:
            ok = got is not None and conf >= floor
            if ok and prev is not None and follows(prev, got):
                run += 1
                rx += (got[0] + got[2] - prev[0] - prev[2]) / 2 - g[0]
                ry += (got[1] + got[3] - prev[1] - prev[3]) / 2 - g[1]
            elif ok:
                run, rx, ry = 1, 0.0, 0.0
            else:
                run, rx, ry = 0, 0.0, 0.0
            prev = got if ok else None
            confirmed = run >= m and np.hypot(rx, ry) / max(run - 1, 1) >= d
            out = got if got is not None and (conf >= gate or confirmed) else None
            if truth is None:
                empty += 1
                alarms += out is not None
            else:
                n += 1
                total += iou(out, truth)
    return (total / n if n else 0.0), alarms, empty


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("images")
    ap.add_argument("winners")
    ap.add_argument("--ground", choices=["fft", "patches"],
                    help="take the ground's motion out: by phase correlation, or by block matching")
    ap.add_argument("--peak", type=float, default=None,
                    help="the registration's least confidence, else no motion (default: "
                         "correlation peak 0.15 for fft, half the patches agreeing for patches)")
    a = ap.parse_args()
    peak = a.peak if a.peak is not None else (0.5 if a.ground == "patches" else 0.15)
    seqs = load(a.images, a.winners, a.ground, peak)
    print("gate alone: mean IoU %.4f, false alarms %d / %d" % score(seqs, 10**9, 0.55, 0))
    for m in (2, 3, 4):
        for d in ((0.5, 1.0, 1.5, 2.0) if a.ground else (0.0,)):
            cells = ["F %.2f: %.4f %d/%d" % ((f,) + score(seqs, m, f, d))
                     for f in (0.05, 0.1, 0.2, 0.3)]
            print(f"M {m} D {d}: " + " | ".join(cells))


if __name__ == "__main__":
    main()
