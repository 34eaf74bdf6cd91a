#!/usr/bin/env python3
"""Fit the polynomial coefficients of `lobe::batch::math` (exp, log, erf, erfc).

Cephes-style reductions, discrete minimax fits (Lawson's iteratively
reweighted least squares, `lawson` from fit_sincos.py) on Chebyshev points,
in f64; standard library only. Run it to reproduce the constants in math.rs:
    exp r  ~ 1 + r + r^2 P(r)           r in [-ln2/2, ln2/2]   (relative)
    log1p f ~ f - f^2/2 + f^3 P(f)      f in [sqrt(1/2)-1, sqrt(2)-1] (relative)
    erf x  ~ x P(x^2)                   x in [0, 1]             (relative)
    erfc z ~ exp(-z^2) t P(t), t = 1/(1 + z/2), z in [1, 10]   (relative)
"""
import math
import sys
import os
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib.util
spec = importlib.util.spec_from_file_location("fs", os.path.join(os.path.dirname(os.path.abspath(__file__)), "fit_sincos.py"))


def solve(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(m[i][k]))
        m[k], m[p] = m[p], m[k]
        for i in range(k + 1, n):
            f = m[i][k] / m[k][k]
            for j in range(k, n + 1):
                m[i][j] -= f * m[k][j]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))) / m[i][i]
    return x


def lawson(xs, basis, target, weight, iters=150):
    w = [1.0 / len(xs)] * len(xs)
    phis = [basis(x) for x in xs]
    ts = [target(x) for x in xs]
    ws = [weight(x) for x in xs]
    n = len(phis[0])
    for _ in range(iters):
        a = [[0.0] * n for _ in range(n)]
        b = [0.0] * n
        for phi, t, wt, wx in zip(phis, ts, ws, w):
            s = wt * wt * wx
            for i in range(n):
                b[i] += s * phi[i] * t
                for j in range(n):
                    a[i][j] += s * phi[i] * phi[j]
        c = solve(a, b)
        err = [abs(wt * (t - sum(ci * p for ci, p in zip(c, phi)))) for phi, t, wt in zip(phis, ts, ws)]
        tot = sum(wx * e for wx, e in zip(w, err))
        w = [wx * e / tot for wx, e in zip(w, err)]
    return c, max(err)


def cheb(a, b, n=1500):
    return [a + (b - a) * 0.5 * (1 - math.cos(math.pi * (i + 0.5) / n)) for i in range(n)]


which = sys.argv[1:] or ["exp", "log", "erf", "erfc"]
if "exp" in which:
    h = math.log(2) / 2
    xs = [x for x in cheb(-h, h) if abs(x) > 1e-9]
    c, e = lawson(xs, lambda r: [r**k for k in range(2, 8)], lambda r: math.exp(r) - 1 - r,
                  lambda r: math.exp(-r))
    print("exp", [repr(x) for x in c], "max rel err", e)
if "log" in which:
    xs = [x for x in cheb(math.sqrt(0.5) - 1, math.sqrt(2) - 1) if abs(x) > 1e-9]
    c, e = lawson(xs, lambda f: [f**k for k in range(3, 11)], lambda f: math.log1p(f) - f + f * f / 2,
                  lambda f: 1 / abs(math.log1p(f)))
    print("log", [repr(x) for x in c], "max rel err", e)
if "erf" in which:
    xs = cheb(1e-6, 1.0)
    c, e = lawson(xs, lambda x: [x * x**(2 * k) for k in range(0, 7)], lambda x: math.erf(x),
                  lambda x: 1 / math.erf(x))
    print("erf", [repr(x) for x in c], "max rel err", e)
if "erfc" in which:
    xs = cheb(1.0, 10.0, 2000)
    deg = int(os.environ.get("DEG", "10"))
    t = lambda z: 1 / (1 + 0.5 * z)
    c, e = lawson(xs, lambda z: [t(z)**(k + 1) for k in range(deg)],
                  lambda z: math.erfc(z) * math.exp(z * z), lambda z: 1 / (math.erfc(z) * math.exp(z * z)))
    print("erfc", [repr(x) for x in c], "max rel err", e)
