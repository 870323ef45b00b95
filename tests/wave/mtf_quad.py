#!/usr/bin/python3
# mtf_quad.py -- an independent MTF for tests/t_94_wave.sh: reads a --wave record of
# a one-wavelength run, takes each field's Zernike table (j, n, m, waves: Fringe,
# peak-normalised) and the cutoff, and computes the MTF as the pupil's
# autocorrelation by two-dimensional Gauss-Legendre quadrature over the two circles'
# overlap (numpy's nodes), W rebuilt from the table with R_n^m written out here; no
# FFT, no grid.  Prints "field k freq T S" for each row of the record's MTF table,
# beside the record's own T and S.
import math, re, sys
import numpy as np

def radial(n, m, r):
    s = 0.0
    for k in range((n - m) // 2 + 1):
        s = s + (-1) ** k * math.factorial(n - k) / (math.factorial(k) * math.factorial((n + m) // 2 - k) * math.factorial((n - m) // 2 - k)) * r ** (n - 2 * k)
    return s

def wave(terms, x, y):
    r = np.hypot(x, y); t = np.arctan2(y, x); w = np.zeros_like(x)
    for (n, m, c) in terms:
        z = radial(n, abs(m), r)
        if m > 0: z = z * np.cos(m * t)
        elif m < 0: z = z * np.sin(-m * t)
        w = w + c * z
    return w

G = 96
gx, gw = np.polynomial.legendre.leggauss(G)

def mtf(terms, s, axis):
    """|OTF| for a shift s (normalised pupil, 2 = cutoff) along y (axis 1) or x (0)."""
    if s >= 2: return 0.0
    # overlap of the unit circles centred at -s/2 and +s/2 along the shift: in (u, v)
    # with u along the shift, |v| <= sqrt(1 - (s/2)^2), |u| <= sqrt(1 - v^2) - s/2
    vm = math.sqrt(1 - (s / 2) ** 2)
    tot = 0j
    for vi, vw in zip(gx * vm, gw * vm):
        um = math.sqrt(max(0.0, 1 - vi * vi)) - s / 2
        if um <= 0: continue
        u = gx * um; wu = gw * um
        if axis == 1: xa, ya, xb, yb = vi + 0 * u, u + s / 2, vi + 0 * u, u - s / 2
        else: xa, ya, xb, yb = u + s / 2, vi + 0 * u, u - s / 2, vi + 0 * u
        ph = 2 * math.pi * (wave(terms, xa, ya) - wave(terms, xb, yb))
        tot += np.sum(wu * np.exp(-1j * ph)) * vw
    return abs(tot) / math.pi

rec = open(sys.argv[1]).read().splitlines()
field = 0; terms = []; cut = None; intable = False
for line in rec:
    if line.startswith('Field '):
        field = int(line.split()[1].rstrip(':')); terms = []; intable = False
    m = re.match(r'^\s+(\d+)\s+(\d+)\s+(-?\d+)\s+(-?\d+\.\d+)\s', line)
    if m and not intable:
        terms.append((int(m.group(2)), int(m.group(3)), float(m.group(4))))
        continue
    m = re.match(r'^\s+MTF \(cutoff ([0-9.e+]+) cycles/mm', line)
    if m: cut = float(m.group(1)); intable = True; continue
    if intable:
        m = re.match(r'^\s+([0-9.e+]+)\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)\s*$', line)
        if m:
            f = float(m.group(1))
            print(field, f, mtf(terms, 2 * f / cut, 1), mtf(terms, 2 * f / cut, 0), m.group(2), m.group(3))
        elif not ('tangential' in line and 'diffraction' in line):
            intable = False
