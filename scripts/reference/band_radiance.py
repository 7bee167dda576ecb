#!/usr/bin/env python3
"""High-precision band radiance of the TIR response model: the reference table the
core's band-radiance tests compare against (core/tests/data/band_radiance_reference.csv).

Run once, with mpmath only (pure Python, no numpy):

    python3 -m pip install mpmath          # tested with mpmath 1.3.0 and 1.4.1
    python3 scripts/reference/band_radiance.py > core/tests/data/band_radiance_reference.csv

Takes about 3-5 minutes. Method (adopted from the project's shared reference,
shared/reference/reference.py, section 3, and checked against its 30-digit table):

- Response model R(lambda) = eta * S(lambda)/S_max on 6..16 um, 0 outside, eta = 1,
  S(l) = sig((l - 8.15)/0.075) * sig((12.0 - l)/0.10) * exp(-0.075 (l - 10)), sig(z) = 1/(1+e^-z).
  These are the numbers of `tirroi_core::sensor::response::SkewedBell::HAYABUSA2_TIR`.
- L(T) = int_6^16 R(l) B(l, T) dl, B per um (W m^-2 sr^-1 um^-1), SI-2019 exact h, c, k_B.
- mpmath at 40 digits, tanh-sinh quadrature on panels split at the response's edges and
  on a grid uniform in x = c2/(l T) (step <= 2), integrand rescaled to O(1) because
  mp.quad's stopping test is absolute; a second, independent Gauss-Legendre evaluation on
  another partition must agree to 1e-30 relative or the script stops.
- Temperatures are multiples of 1/256 K, so each is exact in both f32 and f64 and the
  f32 paths are tested at exactly the temperature the reference used.

Output: CSV `t_k,band_radiance_w_m2_sr` with 30 significant digits, '#' comment lines first.
"""
import sys

import mpmath as mp

mp.mp.dps = 40

H = mp.mpf('6.62607015e-34')            # J s (exact, SI 2019)
C = mp.mpf(299792458)                   # m/s (exact)
KB = mp.mpf('1.380649e-23')             # J/K (exact)
C1_UM = 2 * H * C**2 * mp.mpf(10)**24   # 2hc^2, W um^4 m^-2 sr^-1 (B per um)
C2_UM = H * C / KB * mp.mpf(10)**6      # hc/k_B, um K

L1, W1, L2, W2, KT = mp.mpf('8.15'), mp.mpf('0.075'), mp.mpf('12.0'), mp.mpf('0.10'), mp.mpf('0.075')
LAM_A, LAM_B = mp.mpf(6), mp.mpf(16)


def sig(z):
    return 1 / (1 + mp.exp(-z))


def shape(lam):
    return sig((lam - L1) / W1) * sig((L2 - lam) / W2) * mp.exp(-KT * (lam - 10))


def dln_shape(lam):
    return (1 - sig((lam - L1) / W1)) / W1 - (1 - sig((L2 - lam) / W2)) / W2 - KT


LAM_PEAK = mp.findroot(dln_shape, mp.mpf('8.55'))
S_MAX = shape(LAM_PEAK)


def planck_um(lam, t):
    return C1_UM / lam**5 / mp.expm1(C2_UM / (lam * t))


BREAKS = [mp.mpf(x) for x in ['6', '7', '7.6', '7.9', '8.05', '8.15', '8.25', '8.4', '8.7', '9.2', '10',
                              '11', '11.6', '11.85', '12', '12.15', '12.4', '12.8', '13.5', '14.5', '15.3', '16']]


def panels(t, dx):
    xa, xb = C2_UM / (LAM_B * t), C2_UM / (LAM_A * t)
    n = max(1, int(mp.ceil((xb - xa) / dx)))
    pts = {C2_UM / (t * x) for x in mp.linspace(xa, xb, n + 1)}
    pts |= set(BREAKS)
    return sorted(pts)


def quad_scaled(f, pts, method):
    grid = sorted(set(pts) | set(mp.linspace(pts[0], pts[-1], 2001)))
    m = max(mp.log(v) for v in (f(l) for l in grid) if v > 0)
    sc = mp.exp(-m)
    return mp.quad(lambda l: f(l) * sc, pts, method=method) / sc


def band_radiance(t):
    t = mp.mpf(t)
    return quad_scaled(lambda l: shape(l) * planck_um(l, t), panels(t, 2), 'tanh-sinh') / S_MAX


def band_radiance_check(t):
    t = mp.mpf(t)
    pts = sorted(set(panels(t, mp.mpf('1.5'))) | set(mp.linspace(LAM_A, LAM_B, 81)))
    return quad_scaled(lambda l: shape(l) * planck_um(l, t), pts, 'gauss-legendre') / S_MAX


def temperatures():
    """1 K .. 5000 K: hand-picked points (the shared table's integers, the f32 and f64
    underflow edges) plus a geometric sweep, each rounded to a multiple of 1/256 K."""
    picked = [1, 1.25, 1.5, 2, 2.5, 2.75, 3, 4, 5, 7, 10, 11, 12, 13, 14, 15, 17, 20, 25, 30, 40,
              50, 70, 100, 150, 200, 250, 273.25, 300, 350, 400, 460, 500, 700, 1000, 1500,
              2000, 3000, 4000, 5000]
    n = 48
    sweep = [3 * (2000 / 3) ** (i / (n - 1)) for i in range(n)]
    ts = {mp.mpf(round(t * 256)) / 256 for t in picked + sweep}
    return sorted(ts)


def main():
    out = sys.stdout
    out.write('# Band radiance L(T) = int_6^16 R(l) B(l,T) dl of the skewed-bell TIR response, eta = 1\n')
    out.write('# [W m^-2 sr^-1], mpmath %s at %d digits; written by scripts/reference/band_radiance.py\n'
              % (mp.__version__, mp.mp.dps))
    out.write('# S_max = %s at lambda_peak = %s um\n' % (mp.nstr(S_MAX, 30), mp.nstr(LAM_PEAK, 30)))
    out.write('t_k,band_radiance_w_m2_sr\n')
    worst = mp.mpf(0)
    for t in temperatures():
        a = band_radiance(t)
        b = band_radiance_check(t)
        rel = abs(a / b - 1)
        worst = max(worst, rel)
        if rel > mp.mpf('1e-30'):
            sys.exit('independent quadratures disagree at T = %s K: %s' % (t, mp.nstr(rel, 5)))
        out.write('%s,%s\n' % (mp.nstr(t, 20), mp.nstr(a, 30)))
        out.flush()
    sys.stderr.write('worst disagreement between the two quadratures: %s\n' % mp.nstr(worst, 3))


if __name__ == '__main__':
    main()
