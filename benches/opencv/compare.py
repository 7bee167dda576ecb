#!/usr/bin/env python3
"""Times OpenCV equivalents of tirroi's four ROI detectors (single thread).

Usage: python3 benches/opencv/compare.py FRAME.png [...]
Prints the median time per call in microseconds (Python call overhead included: this
is the cost a user of OpenCV's Python API pays), and the box each equivalent finds.
Needs `pip install opencv-python-headless numpy`.
"""
import sys
import time

import cv2
import numpy as np

cv2.setNumThreads(1)
REPEAT = 200


def median_us(f):
    times = []
    for _ in range(REPEAT):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return float(np.median(times)) * 1e6


def box(mask):
    x, y, w, h = cv2.boundingRect(mask)
    return [x, y, x + w, y + h] if w and h else None


def otsu16(img):
    _, m = cv2.threshold(img, 0, 1, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    return box(m.astype(np.uint8))


def otsu8(img):
    _, m = cv2.threshold((img >> 6).astype(np.uint8), 0, 1, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    return box(m)


def adaptive16(img, block=41, offset=64):
    # adaptiveThreshold is 8-bit only: the same local-mean test on 16-bit data.
    mean = cv2.boxFilter(img.astype(np.float32), -1, (block, block), borderType=cv2.BORDER_REPLICATE)
    return box((img > mean + offset).astype(np.uint8))


def adaptive8(img, block=41, offset=1):
    m = cv2.adaptiveThreshold((img >> 6).astype(np.uint8), 1, cv2.ADAPTIVE_THRESH_MEAN_C,
                              cv2.THRESH_BINARY, block, -offset)
    return box(m)


KX = np.array([[-1, 0, 1]] * 3, np.float32)


def wge(img, drop=0.97):
    f = img.astype(np.float32)
    g = np.abs(cv2.filter2D(f, -1, KX)) + np.abs(cv2.filter2D(f, -1, KX.T))
    inner = g[1:-1, 1:-1]
    k = int(drop * inner.size)
    t = max(np.partition(inner.ravel(), k)[k], 48) if k < inner.size else np.inf
    m = np.zeros(img.shape, np.uint8)
    m[1:-1, 1:-1] = inner >= t
    return box(m)


def dog(img, sigma0=4.0, ratio=1.6, levels=7, thr=256):
    small = cv2.resize(img.astype(np.float32), (82, 62), interpolation=cv2.INTER_AREA)
    gs = [cv2.GaussianBlur(small, (0, 0), sigma0 / 4 * ratio ** i, borderType=cv2.BORDER_REPLICATE)
          for i in range(levels)]
    d = np.stack([(gs[i] - gs[i + 1]) / (ratio - 1) for i in range(levels - 1)])
    mx = np.stack([cv2.dilate(x, np.ones((3, 3), np.uint8)) for x in d])
    mx = np.maximum(mx, np.concatenate([mx[1:], mx[-1:]]))
    mx = np.maximum(mx, np.concatenate([mx[:1], mx[:-1]]))
    peaks = np.argwhere((d >= mx) & (d >= thr))
    m = np.zeros(img.shape, np.uint8)
    for i, y, x in peaks:
        r = int(np.ceil(np.sqrt(2) * sigma0 * ratio ** i))
        cx, cy = x * 4 + 2, y * 4 + 2
        m[max(cy - r, 0):cy + r + 1, max(cx - r, 0):cx + r + 1] = 1
    return box(m)


METHODS = [("otsu", otsu16), ("otsu-8bit", otsu8), ("adaptive", adaptive16),
           ("adaptive-8bit", adaptive8), ("wge", wge), ("dog", dog)]

for path in sys.argv[1:]:
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    for name, f in METHODS:
        print(f"{path}\t{name}\t{median_us(lambda: f(img)):.1f} us\t{f(img)}")
