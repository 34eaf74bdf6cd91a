#!/usr/bin/env python3
"""Fit the polynomial coefficients of `lobe::batch::math::sincos_turns`.

Cephes-style reduction: the argument is reduced to x in [-pi/4, pi/4]; there
    sin x ~ x + x^3 (s0 + s1 x^2 + s2 x^4)          (relative error)
    cos x ~ 1 - x^2/2 + x^4 (c0 + c1 x^2 + c2 x^4)  (absolute error)
The coefficients are a discrete minimax fit (Lawson's iteratively reweighted
least squares) on 4000 Chebyshev points of [0, pi/4], in f64. Standard
library only; run it to reproduce the constants in math.rs.
"""
import math


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


def lawson(xs, basis, target, weight, iters=400):
    """min over c of max_x |weight(x) (target(x) - sum c_k basis_k(x))|."""
    w = [1.0 / len(xs)] * len(xs)
    n = len(basis(xs[0]))
    for _ in range(iters):
        a = [[0.0] * n for _ in range(n)]
        b = [0.0] * n
        for x, wx in zip(xs, w):
            phi = basis(x)
            s = weight(x) ** 2 * wx
            for i in range(n):
                b[i] += s * phi[i] * target(x)
                for j in range(n):
                    a[i][j] += s * phi[i] * phi[j]
        c = solve(a, b)
        err = [abs(weight(x) * (target(x) - sum(ci * p for ci, p in zip(c, basis(x))))) for x in xs]
        tot = sum(wx * e for wx, e in zip(w, err))
        w = [wx * e / tot for wx, e in zip(w, err)]
    return c, max(err)


N = 4000
xs = [math.pi / 8 * (1 - math.cos(math.pi * (i + 0.5) / N)) for i in range(N)]
# sin: fit (sin x - x) with x^3, x^5, x^7, error relative to sin x.
cs, es = lawson(xs, lambda x: [x**3, x**5, x**7], lambda x: math.sin(x) - x,
                lambda x: 1.0 / math.sin(x))
# cos: fit (cos x - 1 + x^2/2) with x^4, x^6, x^8, absolute error.
cc, ec = lawson(xs, lambda x: [x**4, x**6, x**8], lambda x: math.cos(x) - 1 + x * x / 2,
                lambda x: 1.0)
print("sin", [repr(c) for c in cs], "max rel err", es)
print("cos", [repr(c) for c in cc], "max abs err", ec)
