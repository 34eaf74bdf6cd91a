#!/usr/bin/env python3
"""lobe's path tracer against Mitsuba 3's on glass and plastic (issue 42).

Setup (not run by CI): the Mitsuba venv and libLLVM of bench/README.md, and
a release build of lobe; then, from the repository root:

    cargo build --release --locked -p lobe-cli
    venv-mitsuba/bin/python bench/mitsuba_glass_render.py            # 4096 spp each
    venv-mitsuba/bin/python bench/mitsuba_glass_render.py --spp 256  # a quick look

The scene is bench/glass_spheres.toml (lobe's scene file, with Mitsuba's
plugin names; this script builds the same Mitsuba scene from it): smooth
glass (`dielectric`, BK7 in air), rough glass (`roughdielectric`, GGX,
alpha 0.2) and rough plastic (`roughplastic`, GGX, alpha 0.2, a red-orange
base) on a diffuse ground of reflectance 0.5 under the procedural sky with
a sun of bench/mitsuba_render.py (the same analytic function sampled on
each renderer's texel lattice). lobe's ground is an infinite plane,
Mitsuba's a 200 x 200 rectangle; lobe's `max_depth` counts scattering
events, Mitsuba's path segments, so lobe's `max_depth = d` is Mitsuba's
`path` integrator with `max_depth = d + 1`. Both use Russian roulette
(lobe after the third bounce, Mitsuba from depth 5: `rr_depth` 5), which
leaves the expected image unchanged. lobe renders with `--strategy mis`,
Mitsuba's `path` with its MIS of BSDF and emitter samples.

Each renderer renders --spp samples per pixel in --passes passes of
different seeds. For each sphere (the pixels whose four corners and centre
all see it) the script prints the mean of each image over its pixels and
channels, the relative difference of lobe's from Mitsuba's, and that
difference's standard error from the spread of the passes; and, as a
yardstick, Mitsuba's first half of passes against its second half. It
writes bench/out/glass-lobe.exr, glass-mitsuba.exr and glass-compare.png
(lobe, Mitsuba, and their difference), and with --json-out the numbers.

The aim (issue 42): each sphere within 1.5% (smooth glass 3%, whose
caustics are heavy-tailed) at 4096 spp.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)

import mitsuba_render as mr  # noqa: E402  (the sky, its maps, the camera rays)
import numpy as np  # noqa: E402

dr, mi = mr.dr, mr.mi
SCENE = os.path.join(HERE, "glass_spheres.toml")
AIMS = {"dielectric": 0.03}  # the rest: 0.015


def die(msg):
    sys.exit(f"mitsuba_glass_render.py: {msg}")


def load_desc():
    with open(SCENE, "rb") as f:
        desc = mr.tomllib.load(f)
    spheres, planes = [], []
    for i, o in enumerate(desc.get("object", [])):
        if o["type"] == "sphere":
            spheres.append((np.array(o["center"], float), float(o["radius"]), o["material"]))
        elif o["type"] == "plane":
            planes.append((np.array(o["point"], float), np.array(o["normal"], float), o["material"]))
        else:
            die(f"{SCENE}: object[{i}]: only spheres and planes are mapped to Mitsuba")
    return desc, spheres, planes


def mitsuba_bsdf(m):
    """lobe's material table, Mitsuba's names already: colours as RGB."""
    d = {}
    for k, v in m.items():
        if isinstance(v, list):
            v = {"type": "rgb", "value": [float(x) for x in v]}
        elif k in ("reflectance", "diffuse_reflectance") and isinstance(v, (int, float)):
            v = {"type": "rgb", "value": [float(v)] * 3}
        d[k] = v
    return d


def build_mitsuba(desc, spheres, planes, env, spp, max_depth):
    cam = desc["camera"]
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1},
        "sensor": {
            "type": "perspective", "fov": float(cam["fov_y"]), "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["origin"], target=cam["target"], up=cam.get("up", [0, 1, 0])),
            "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"],
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "env": {"type": "envmap", "filename": env},
    }
    for i, (c, r, m) in enumerate(spheres):
        d[f"sphere{i}"] = {"type": "sphere", "center": c.tolist(), "radius": r, "bsdf": mitsuba_bsdf(m)}
    for i, (p, n, m) in enumerate(planes):
        if not np.allclose(n, [0, 1, 0]):
            die(f"{SCENE}: only planes with normal +Y are mapped")
        d[f"ground{i}"] = {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().translate(p.tolist())
            @ mi.ScalarTransform4f().rotate([1, 0, 0], -90)
            @ mi.ScalarTransform4f().scale([100, 100, 1]),
            "bsdf": mitsuba_bsdf(m),
        }
    return mi.load_dict(d)


def read_exr(path):
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def main():
    p = argparse.ArgumentParser(description="lobe's path tracer against Mitsuba 3's on glass (see the header)")
    p.add_argument("--lobe", default=os.path.join(ROOT, "target", "release", "lobe"))
    p.add_argument("--spp", type=int, default=4096, help="samples per pixel of each renderer (default 4096)")
    p.add_argument("--passes", type=int, default=8, help="passes of different seeds (default 8)")
    p.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    p.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (default llvm_ad_rgb)")
    p.add_argument("--out", default=os.path.join(HERE, "out"))
    p.add_argument("--max-depth", type=int,
                   help="lobe's max_depth (default: the scene file's; Mitsuba's is one more)")
    p.add_argument("--json-out")
    args = p.parse_args()
    if args.spp < args.passes or args.passes < 2:
        die("--passes must be at least 2 and at most --spp")
    if not os.path.exists(args.lobe):
        die(f"no lobe binary at {args.lobe}: cargo build --release --locked -p lobe-cli")
    mi.set_variant(args.variant)
    dr.set_thread_count(args.threads)
    desc, spheres, planes = load_desc()
    cam = desc["camera"]
    max_depth = args.max_depth or int(desc["render"]["max_depth"])
    if args.max_depth:
        text_depth = f"max_depth = {max_depth}"
    else:
        text_depth = None
    maps = mr.write_maps(args.out)
    with open(SCENE) as f:
        text = f.read()
    text, n = re.subn(r'(?m)^path\s*=\s*".*"', f"path = {json.dumps(os.path.abspath(maps['lobe']))}", text)
    if n != 1:
        die(f"{SCENE}: expected one `path = ...` line (the environment's)")
    if text_depth:
        text = re.sub(r"(?m)^max_depth\s*=.*$", text_depth, text)
    lobe_scene = os.path.join(args.out, "glass_spheres.toml")
    with open(lobe_scene, "w") as f:
        f.write(text)

    per = args.spp // args.passes
    print(f"{cam['width']}x{cam['height']}, {args.passes} passes of {per} spp each, "
          f"lobe max_depth {max_depth} (Mitsuba {max_depth + 1})", file=sys.stderr)
    lobe_passes, lobe_t = [], 0.0
    for k in range(args.passes):
        out = os.path.join(args.out, f"glass-lobe-{k}")
        t0 = time.perf_counter()
        subprocess.run([args.lobe, "render", lobe_scene, "--spp", str(per), "--seed", str(1000 + k),
                        "--threads", str(args.threads), "--spp-allocation", "uniform", "--quiet",
                        "--out", out], check=True, stdout=subprocess.DEVNULL)
        lobe_t += time.perf_counter() - t0
        lobe_passes.append(read_exr(out + ".exr"))
        print(f"  lobe pass {k + 1}/{args.passes}: {lobe_t:.1f} s so far", file=sys.stderr, flush=True)
    scene = build_mitsuba(desc, spheres, planes, maps["mitsuba"], per, max_depth)
    mi_passes, mi_t = [], 0.0
    for k in range(args.passes):
        t0 = time.perf_counter()
        img = np.array(mi.render(scene, spp=per, seed=2000 + k), dtype=np.float64)[..., :3]
        mi_t += time.perf_counter() - t0
        mi_passes.append(img)
        print(f"  Mitsuba pass {k + 1}/{args.passes}: {mi_t:.1f} s so far", file=sys.stderr, flush=True)

    lobe_img, mi_img = np.mean(lobe_passes, 0), np.mean(mi_passes, 0)
    mi.Bitmap(lobe_img.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(os.path.join(args.out, "glass-lobe.exr"))
    mi.Bitmap(mi_img.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(os.path.join(args.out, "glass-mitsuba.exr"))
    diff = np.abs(lobe_img - mi_img)
    strip = np.concatenate([lobe_img, mi_img, 4.0 * diff], axis=1)
    mr.save_png(os.path.join(args.out, "glass-compare.png"), strip)

    rows = []
    half = args.passes // 2
    print(f"\n{args.spp} spp each; lobe {lobe_t:.1f} s, Mitsuba {args.variant} {mi_t:.1f} s "
          f"({args.threads} threads)")
    print(f"{'sphere':<18}{'pixels':>7}{'lobe':>10}{'Mitsuba':>10}{'rel. diff':>11}{'± s.e.':>9}"
          f"{'aim':>7}{'Mi vs Mi':>10}")
    for i, (c, r, m) in enumerate(spheres):
        mask = mr.sphere_mask(cam, [(c, r, m)])
        lm = np.array([x[mask].mean() for x in lobe_passes])
        mm = np.array([x[mask].mean() for x in mi_passes])
        a, b = lm.mean(), mm.mean()
        rel = (a - b) / b
        se = np.sqrt(lm.var(ddof=1) / len(lm) + mm.var(ddof=1) / len(mm)) / b
        yard = (mm[:half].mean() - mm[half:].mean()) / b
        aim = AIMS.get(m["type"], 0.015)
        rows.append({"sphere": m["type"], "pixels": int(mask.sum()), "lobe": a, "mitsuba": b,
                     "rel_diff": rel, "se": se, "aim": aim, "mitsuba_halves": yard})
        print(f"{m['type']:<18}{int(mask.sum()):>7}{a:>10.4f}{b:>10.4f}{100 * rel:>10.2f}%"
              f"{100 * se:>8.2f}%{100 * aim:>6.1f}%{100 * yard:>9.2f}%")
    print("rel. diff: lobe's mean over the sphere's pixels and channels against Mitsuba's; s.e. from the\n"
          "spread of the passes; Mi vs Mi: Mitsuba's first half of passes against its second half.")
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump({"spp": args.spp, "passes": args.passes, "variant": args.variant,
                       "threads": args.threads, "lobe_seconds": lobe_t, "mitsuba_seconds": mi_t,
                       "spheres": rows}, f, indent=1)


if __name__ == "__main__":
    main()
