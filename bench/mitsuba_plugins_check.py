#!/usr/bin/env python3
"""Cross-check `lobe.load_dict` on Mitsuba 3 plugin dicts against Mitsuba 3
itself (off CI): for each dict, Mitsuba's `bsdf.eval` (f·cos θi, scalar_rgb)
against lobe's `Material.eval` (f without the cosine) times cos θi, over
random pairs of directions in the upper hemisphere; and Mitsuba's `pdf`
(visible-normal sampling) against lobe's `vndf` pdf. Prints the largest
relative differences.

Needs both packages in one environment:
    python3 -m venv /tmp/mi && /tmp/mi/bin/pip install mitsuba numpy . && /tmp/mi/bin/python bench/mitsuba_plugins_check.py
"""
import mitsuba as mi
import numpy as np

import lobe

mi.set_variant("scalar_rgb")
mi.set_log_level(mi.LogLevel.Error)

DICTS = [
    {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2},
    {"type": "roughconductor", "distribution": "beckmann", "alpha": 0.3, "material": "Au"},
    {"type": "roughconductor", "distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.4, "material": "Cr"},
    {"type": "roughconductor", "distribution": "ggx", "alpha": 0.15, "material": "TiN"},
    {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3, "material": "CsI"},
    {"type": "roughconductor", "distribution": "beckmann", "alpha": 0.25, "eta": {"type": "rgb", "value": [0.2, 0.9, 1.1]},
     "k": {"type": "rgb", "value": [3.9, 2.4, 2.1]}},
    {"type": "roughplastic", "distribution": "ggx", "alpha": 0.2, "int_ior": "bk7", "diffuse_reflectance": 0.0},
    {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.2, 0.4, 0.6]}},
]


def directions(n, rng):
    c = 0.02 + 0.98 * rng.random(n)
    s = np.sqrt(1 - c * c)
    p = 2 * np.pi * rng.random(n)
    return np.stack([s * np.cos(p), s * np.sin(p), c], axis=1)


def main():
    rng = np.random.default_rng(1)
    n = 2000
    wo, wi = directions(n, rng), directions(n, rng)
    print(f"Mitsuba {mi.__version__} scalar_rgb against lobe {lobe.simd_level()} ({n} pairs each)")
    for d in DICTS:
        m = lobe.load_dict(d)
        b = mi.load_dict(d)
        ctx = mi.BSDFContext()
        ours = m.eval(wo, wi, reference=True) * wi[:, 2:3]
        pdf_ours = m.pdf(wo, wi, strategy="vndf", reference=True) if "vndf" in m.strategies else None
        theirs = np.zeros((n, 3))
        pdf_theirs = np.zeros(n)
        for i in range(n):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*wo[i])  # Mitsuba's si.wi points toward the viewer: lobe's wo
            theirs[i] = np.array(b.eval(ctx, si, mi.Vector3f(*wi[i])))
            pdf_theirs[i] = b.pdf(ctx, si, mi.Vector3f(*wi[i]))
        big = theirs.max(axis=1) > 1e-3 * theirs.max()
        rel = np.abs(ours - theirs)[big] / np.maximum(theirs[big], 1e-12)
        line = f"{str(d):110s} eval: max rel {rel.max():.2e}"
        if pdf_ours is not None:
            ok = pdf_theirs > 1e-3 * pdf_theirs.max()
            line += f", vndf pdf: max rel {np.max(np.abs(pdf_ours[ok] - pdf_theirs[ok]) / pdf_theirs[ok]):.2e}"
        print(line)


if __name__ == "__main__":
    main()
