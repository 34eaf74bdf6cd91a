#!/usr/bin/env python3
"""Cross-check `lobe.load_dict` on Mitsuba 3 plugin dicts against Mitsuba 3
itself (off CI): for each dict, Mitsuba's `bsdf.eval` (f·|cos θi|,
scalar_rgb) against lobe's `Material.eval` (f without the cosine) times
|cos θi|, over random pairs of directions (in the upper hemisphere for the
opaque plugins, over the whole sphere for glass and two-sided ones); and
Mitsuba's `pdf` (visible-normal sampling) against lobe's `vndf` pdf, or
`brdf` where the plugin has no visible normals (plastic). For the smooth
plugins (whose eval is zero) `sample` is compared instead: the sampled
direction, the weight and the probability, at the same `uc`. Prints the
largest relative differences.

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
    # Issue 42: glass, plastic, two-sided (eval and pdf over the whole sphere).
    {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3},
    {"type": "roughdielectric", "distribution": "ggx", "alpha_u": 0.1, "alpha_v": 0.4, "int_ior": "water"},
    {"type": "roughdielectric", "distribution": "beckmann", "alpha": 0.2, "int_ior": 1.0, "ext_ior": 1.5},
    {"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.5, 0.8]}},
    {"type": "roughplastic", "alpha": 0.1, "nonlinear": True},
    {"type": "plastic", "diffuse_reflectance": 0.3},
    {"type": "twosided", "material": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.2, "material": "Cu"}},
]

SMOOTH = [
    {"type": "conductor", "material": "Au"},
    {"type": "dielectric"},
    {"type": "dielectric", "int_ior": "water", "ext_ior": "bk7"},
    {"type": "thindielectric"},
    {"type": "plastic", "diffuse_reflectance": 0.3},
]

# Plugins whose lobe transmits or is seen from both sides: pairs over the sphere.
SPHERE = ("roughdielectric", "twosided")


def directions(n, rng):
    c = 0.02 + 0.98 * rng.random(n)
    s = np.sqrt(1 - c * c)
    p = 2 * np.pi * rng.random(n)
    return np.stack([s * np.cos(p), s * np.sin(p), c], axis=1)


def sphere_directions(n, rng):
    w = directions(n, rng)
    w[:, 2] *= np.where(rng.random(n) < 0.5, -1.0, 1.0)
    return w


def check_smooth(rng, n=200):
    """Smooth plugins: at the same `uc`, the same lobe, direction and weight."""
    for d in SMOOTH:
        m = lobe.load_dict(d)
        b = mi.load_dict(d)
        ctx = mi.BSDFContext()
        wo = sphere_directions(n, rng) if d["type"] != "plastic" and d["type"] != "conductor" else directions(n, rng)
        uc = rng.random(n)
        u = rng.random((n, 2))
        s = m.sample(wo, u, uc if m.chooses_lobe() else None, reference=True)
        worst_dir, worst_w, mismatch = 0.0, 0.0, 0
        for i in range(n):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*wo[i])
            bs, w = b.sample(ctx, si, float(uc[i]), mi.Point2f(*u[i]))
            w = np.array(w)
            if not s.valid[i] or np.max(w) == 0:
                mismatch += int(bool(s.valid[i]) != bool(np.max(w) > 0))
                continue
            worst_dir = max(worst_dir, np.max(np.abs(np.array(bs.wo) - s.wi[i])))
            worst_w = max(worst_w, np.max(np.abs(w - s.weight[i]) / np.maximum(w, 1e-12)))
        print(f"{str(d):110s} sample: direction max abs {worst_dir:.2e}, weight max rel {worst_w:.2e}, {mismatch} valid/invalid mismatches")


def main():
    rng = np.random.default_rng(1)
    n = 2000
    print(f"Mitsuba {mi.__version__} scalar_rgb against lobe {lobe.simd_level()} ({n} pairs each)")
    for d in DICTS:
        if d["type"] in SPHERE:
            wo, wi = sphere_directions(n, rng), sphere_directions(n, rng)
        else:
            wo, wi = directions(n, rng), directions(n, rng)
        m = lobe.load_dict(d)
        b = mi.load_dict(d)
        ctx = mi.BSDFContext()
        ours = m.eval(wo, wi, reference=True) * np.abs(wi[:, 2:3])
        strategy = "vndf" if "vndf" in m.strategies else "brdf"
        pdf_ours = m.pdf(wo, wi, strategy=strategy, reference=True)
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
            line += f", {strategy} pdf: max rel {np.max(np.abs(pdf_ours[ok] - pdf_theirs[ok]) / pdf_theirs[ok]):.2e}"
        print(line)
    check_smooth(rng)


if __name__ == "__main__":
    main()
