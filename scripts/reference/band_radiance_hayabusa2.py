#!/usr/bin/env python3
"""High-precision band radiance of the measured Hayabusa2 TIR response: the reference
table the core's tests compare against (core/tests/data/band_radiance_hayabusa2_reference.csv).

Run once, with mpmath only (no numpy; gmpy2 makes it about 5x faster):

    python3 -m pip install mpmath gmpy2    # tested with mpmath 1.4.1, gmpy2 2.2
    python3 scripts/reference/band_radiance_hayabusa2.py > core/tests/data/band_radiance_hayabusa2_reference.csv

Method:

- R(lambda) is the data file core/data/hayabusa2-tir/response.txt (columns lambda in um,
  R; see the NOTICE there), read here as exact decimals: linear between the 0.01 um
  samples, 0 outside the file (the same rule as `TabulatedResponse::at` in the core).
- L(T) = sum over the sample intervals of int R(l) B(l, T) dl, B per um
  (W m^-2 sr^-1 um^-1), SI-2019 exact h, c, k_B, mpmath at 40 digits. On each 0.01 um
  interval R is linear and B is smooth, so a Gauss-Legendre rule converges fast: the
  table uses 24 points per interval, and an independent 12-point evaluation must
  agree to 1e-25 relative or the script stops (it agrees far better above 3 K).
- Temperatures are those of band_radiance.py (multiples of 1/256 K, exact in f32 and
  f64) plus 273.15 K, computed at the f64 nearest 273.15 and printed as "273.15",
  which parses back to that f64.

Output: CSV `t_k,band_radiance_w_m2_sr` with 30 significant digits, '#' comment lines first.
Takes a few minutes.
"""
import sys
from pathlib import Path

import mpmath as mp
from mpmath.calculus.quadrature import GaussLegendre

mp.mp.dps = 40

H = mp.mpf('6.62607015e-34')            # J s (exact, SI 2019)
C = mp.mpf(299792458)                   # m/s (exact)
KB = mp.mpf('1.380649e-23')             # J/K (exact)
C1_UM = 2 * H * C**2 * mp.mpf(10)**24   # 2hc^2, W um^4 m^-2 sr^-1 (B per um)
C2_UM = H * C / KB * mp.mpf(10)**6      # hc/k_B, um K

DATA = Path(__file__).resolve().parents[2] / 'core' / 'data' / 'hayabusa2-tir' / 'response.txt'


def read_table():
    rows = [tuple(mp.mpf(v) for v in line.split()[:2]) for line in DATA.read_text().splitlines()]
    return rows


def rule(degree):
    """Gauss-Legendre nodes and weights on [0, 1]: 3*2^(degree-1) points."""
    nodes = GaussLegendre(mp.mp).calc_nodes(degree, mp.mp.prec)
    return [((x + 1) / 2, w / 2) for x, w in nodes]


def prepare(rows, degree):
    """(c2/lambda, weight*R(lambda)*c1/lambda^5) of every quadrature point of every
    interval where R is not 0 at both ends."""
    pts = []
    nodes = rule(degree)
    for (la, ra), (lb, rb) in zip(rows, rows[1:]):
        if ra == 0 and rb == 0:
            continue
        h = lb - la
        for t, w in nodes:
            lam = la + h * t
            pts.append((C2_UM / lam, w * h * (ra + (rb - ra) * t) * C1_UM / lam**5))
    return pts


def band_radiance(pts, t):
    inv_t = 1 / t
    return mp.fsum(a / mp.expm1(x * inv_t) for x, a in pts)


def temperatures():
    """The temperatures of band_radiance.py, and 273.15 K (as its f64)."""
    picked = [1, 1.25, 1.5, 2, 2.5, 2.75, 3, 4, 5, 7, 10, 11, 12, 13, 14, 15, 17, 20, 25, 30, 40,
              50, 70, 100, 150, 200, 250, 273.25, 300, 350, 400, 460, 500, 700, 1000, 1500,
              2000, 3000, 4000, 5000]
    n = 48
    sweep = [3 * (2000 / 3) ** (i / (n - 1)) for i in range(n)]
    ts = {round(t * 256) / 256 for t in picked + sweep} | {273.15}
    return sorted(ts)


def main():
    rows = read_table()
    fine, check = prepare(rows, 4), prepare(rows, 3)
    out = sys.stdout
    out.write('# Band radiance L(T) = int R(l) B(l,T) dl of the measured Hayabusa2 TIR response\n')
    out.write('# (core/data/hayabusa2-tir/response.txt, linear between samples, 0 outside)\n')
    out.write('# [W m^-2 sr^-1], mpmath %s at %d digits; written by scripts/reference/band_radiance_hayabusa2.py\n'
              % (mp.__version__, mp.mp.dps))
    out.write('t_k,band_radiance_w_m2_sr\n')
    worst = mp.mpf(0)
    for t in temperatures():
        tm = mp.mpf(t)  # the exact value of the f64
        a = band_radiance(fine, tm)
        b = band_radiance(check, tm)
        rel = abs(a / b - 1)
        worst = max(worst, rel)
        if rel > mp.mpf('1e-25'):
            sys.exit('24- and 12-point rules disagree at T = %r K: %s' % (t, mp.nstr(rel, 5)))
        out.write('%r,%s\n' % (t, mp.nstr(a, 30)))
        out.flush()
    sys.stderr.write('worst disagreement between the 24- and 12-point rules: %s\n' % mp.nstr(worst, 3))


if __name__ == '__main__':
    main()
