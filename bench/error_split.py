#!/usr/bin/env python3
"""Where the error of a render of bench/two_spheres.toml comes from (issue 10).

For each image given, against a reference EXR: the relative RMSE over the
sphere pixels (as bench/mitsuba_render.py measures it), each region's share
of the squared error, and each region's own relative RMSE (the RMS over its
pixels of |image - reference| / reference luminance). The regions: the
left sphere (GGX) split by the reference's luminance (its sun highlight is
the brightest part), and the right sphere (Lambert).

Setup as bench/mitsuba_render.py (its venv reads the EXR files); run that
script once first (it writes bench/out/reference.exr and the maps). Then,
from the repository root:

    venv-mitsuba/bin/python bench/error_split.py bench/out/reference.exr bench/out/lobe-256.exr

A reference can be any converged render, for example lobe's own at 8192
spp, which separates lobe's noise from any difference between the two
renderers' scenes.
"""

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists("/usr/lib/x86_64-linux-gnu/libLLVM-19.so"):
    os.environ["DRJIT_LIBLLVM_PATH"] = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"

import mitsuba as mi  # noqa: E402

mi.set_variant("scalar_rgb")
import mitsuba_render as mr  # noqa: E402


def read(path):
    if not os.path.exists(path):
        sys.exit(f"error_split.py: {path}: no such file")
    img = np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]
    return img


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("reference")
    p.add_argument("images", nargs="+")
    args = p.parse_args()
    _, cam, spheres = mr.load_scene_desc()
    mask = mr.sphere_mask(cam, spheres)
    ref = read(args.reference)
    if ref.shape[:2] != mask.shape:
        sys.exit(f"error_split.py: {args.reference}: {ref.shape[1]}x{ref.shape[0]}, "
                 f"the scene is {mask.shape[1]}x{mask.shape[0]}")
    lum = ref.mean(-1)
    w = mask.shape[1]
    left, right = mask.copy(), mask.copy()
    left[:, w // 2:] = False
    right[:, :w // 2] = False
    regions = [
        ("GGX, luminance > 8", left & (lum > 8)),
        ("GGX, 4 to 8", left & (lum > 4) & (lum <= 8)),
        ("GGX, 1 to 4", left & (lum > 1) & (lum <= 4)),
        ("GGX, below 1", left & (lum <= 1)),
        ("Lambert", right),
    ]
    for path in args.images:
        img = read(path)
        if img.shape != ref.shape:
            sys.exit(f"error_split.py: {path}: {img.shape[1]}x{img.shape[0]}, the reference is "
                     f"{ref.shape[1]}x{ref.shape[0]}")
        d2 = ((img - ref) ** 2).mean(-1)
        total = d2[mask].sum()
        print(f"{path}: rel. RMSE {100 * mr.rel_rmse(img, ref, mask):.3f}% over {int(mask.sum())} sphere pixels")
        print("| region | pixels | share of the squared error | its rel. RMSE | mean luminance |")
        print("|---|---:|---:|---:|---:|")
        for name, sel in regions:
            rel = np.sqrt(d2[sel] / np.maximum(lum[sel], 1e-12) ** 2)
            print(f"| {name} | {int(sel.sum())} | {d2[sel].sum() / total:.2f} | "
                  f"{100 * np.sqrt(np.mean(rel ** 2)):.2f}% | {lum[sel].mean():.2f} |")


if __name__ == "__main__":
    main()
