#!/usr/bin/env python3
"""Time to 1% relative RMSE: Mitsuba 3's samplers against `lobe render`, on
one scene, in one run on one machine (issue 10).

Setup (not run by CI): the Mitsuba venv and libLLVM of
`bench/mitsuba_kernels.py` (see its header), and a release build of lobe;
then, from the repository root:

    cargo build --release --locked -p lobe-cli
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
    venv-mitsuba/bin/python bench/mitsuba_render.py                  # everything
    venv-mitsuba/bin/python bench/mitsuba_render.py --samplers multijitter --skip-lobe

(If DRJIT_LIBLLVM_PATH is not set and the Debian path exists, the script sets
it itself.)

The scene is `bench/two_spheres.toml` (lobe's scene file; this script reads
its camera and spheres and builds the same Mitsuba scene from them): a GGX
alpha = 0.2 conductor with F = 1 and a white Lambert sphere (albedo 0.8),
160 x 120, under a procedural HDR sky with a sun that the script generates
from one analytic function into two equirectangular maps in bench/out/:

* `sky-sun-lobe.exr` for lobe, sampled at lobe's texel centres
  (u, v) = ((i + 1/2) / W, (j + 1/2) / H): lobe's texels are constant
  (nearest) over [i, i+1) / W x [j, j+1) / H;
* `sky-sun-mitsuba.exr` for Mitsuba's `envmap`, sampled at its lattice
  (u, v) = ((i + 1/2) / W, j / (H - 1)): Mitsuba interpolates bilinearly
  between texel centres, its first and last rows lying on the poles.

Both use u = atan2(x, -z) / 2pi, v = acos(y) / pi, +Y up (lobe's envmap is in
Mitsuba's convention). The sun is a disc of 2 degrees radius with a smooth
edge (1.5 to 2.5 degrees; 14 texels across at 1024 x 512) so that nearest and
bilinear lookups integrate to the same light up to O(texel^2); the script
prints the mean of lobe's image over the sphere pixels against the
reference's to show how well the two scenes agree.

Materials: lobe `cook-torrance` GGX alpha 0.2, `shadowing = smith-separable`,
`fresnel = none` is Mitsuba's `roughconductor` (GGX, alpha 0.2,
`material = none`: eta = 0, k = 1, F = 1; Mitsuba's Smith term is the
separable one); lobe `lambert` albedo 0.8 is Mitsuba's `diffuse` 0.8. Camera:
lobe's pinhole (vertical fov) is Mitsuba's `perspective` (fov_axis = y,
look_at) with a `box` pixel filter (each sample counts for the pixel it falls
in, as in lobe).

Mitsuba: `direct` with emitter_samples = 1, bsdf_samples = 1 (MIS between
the two), for each sampler of --samplers (independent, stratified,
multijitter, orthogonal, ldsampler: all exist in 3.9.1; stratified and
orthogonal round the spp up to a square / the square of a prime, ldsampler
to a power of two, and the table gives the count they used), each without
and with the envmap's `mis_compensation` (Karlik et al. 2019: light samples
from max(0, luminance - mean), which lobe's `mis` also does; --mis-compensation
picks off, on or both). lobe: `lobe render --strategy mis` (one
BSDF and one light sample per spp, MIS) as one process per render, timed from
spawn to exit (loading the map, rendering, writing EXR + PNG); --lobe-sequence
and --lobe-loop add rows for other sample patterns and for the scalar
reference loop (`--loop scalar`) beside the default batch loop.

Error: relative RMSE over the sphere pixels = sqrt(mean over those pixels and
the three channels of (image - reference)^2) / (mean of the reference over
the same), where the sphere pixels are those whose four corners and centre
all see a sphere (computed from the camera). The reference is Mitsuba's
multijitter at --ref-spp (default 16384) spp, in --ref-passes renders with
different seeds, averaged; its own error (from the spread of the passes) is
printed and adds in quadrature to every measured error.

Time to 1%: for each renderer, spp doubles from --start-spp until the error is
at most --target (default 0.01); "spp" and "time" are the first ladder step
that reaches it (its warm render time: Mitsuba renders every spp twice, a
warm-up that compiles the kernels unless Dr.Jit's cache has them, then the
timed render with a fixed seed per step, so that its error does not depend on
the cache; stratified samplers compile one kernel per spp), the fastest of
--repeat timings of the same render (lobe: of the same process), and with
--rounds R of R - 1 more, one per step per round, taken renderer after
renderer once every ladder is built (so that a host busier for a while
slows one timing of each step rather than every timing of a few). The
"interp." columns interpolate between the last two steps (error as a power of
spp, time linear in spp), since doubling alone can overstate the time by up
to 2x. A ladder stops early when one render takes more than --max-seconds.
"""

import argparse
import json
import math
import os
import re
import resource
import subprocess
import sys
import time

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(_LLVM):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM

import numpy as np  # noqa: E402
from machine import cpu_model  # noqa: E402  (bench/machine.py, beside this script)

try:
    import drjit as dr  # noqa: E402
    import mitsuba as mi  # noqa: E402
except ImportError as e:
    sys.exit(f"mitsuba_render.py: {e}; install with `pip install mitsuba numpy` (see the header)")

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENE = os.path.join(HERE, "two_spheres.toml")
SAMPLERS = ["independent", "stratified", "multijitter", "orthogonal", "ldsampler"]

# The analytic sky (linear RGB radiance), world +Y up.
SUN_ELEVATION, SUN_AZIMUTH = 40.0, 140.0  # degrees; azimuth 0 is -Z, 90 is +X
SUN_R0, SUN_R1 = 1.5, 2.5  # degrees: full radiance inside R0, 0 beyond R1
SUN_RADIANCE = np.array([1500.0, 1420.0, 1270.0])
ZENITH = np.array([0.25, 0.45, 1.0])
HORIZON = np.array([1.0, 1.05, 1.1])
GLOW = np.array([1.5, 1.2, 0.8])  # a broad glow around the sun, 1/e at 0.3 rad
GROUND = np.array([0.25, 0.22, 0.18])
MAP_W, MAP_H = 1024, 512


def die(msg):
    sys.exit(f"mitsuba_render.py: {msg}")


def sun_dir():
    el, az = math.radians(SUN_ELEVATION), math.radians(SUN_AZIMUTH)
    return np.array([math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az)])


def smoothstep(a, b, x):
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def sky(d):
    """Radiance of unit directions d (..., 3)."""
    y = d[..., 1]
    s = sun_dir()
    gamma = np.arccos(np.clip(d @ s, -1.0, 1.0))
    t = np.sqrt(np.clip(y, 0.0, 1.0))[..., None]
    above = HORIZON * (1.0 - t) + ZENITH * t + GLOW * np.exp(-gamma / 0.3)[..., None]
    h = smoothstep(-0.02, 0.02, y)[..., None]
    base = GROUND * (1.0 - h) + above * h
    disc = (1.0 - smoothstep(SUN_R0, SUN_R1, np.degrees(gamma)))[..., None]
    return base + SUN_RADIANCE * disc


def latlong(u, v):
    """Directions of map coordinates (Mitsuba's and lobe's convention)."""
    phi, theta = 2.0 * np.pi * u, np.pi * v
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1)


def write_exr_uncompressed(path, img):
    """`img` (H, W, 3) as a scanline OpenEXR file without compression, float
    channels B, G, R (the OpenEXR file layout: magic, version, header
    attributes, the offset table, one scanline per block)."""
    import struct

    h, w, _ = img.shape

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (attr("channels", "chlist", chlist) + attr("compression", "compression", b"\0")
              + attr("dataWindow", "box2i", box) + attr("displayWindow", "box2i", box)
              + attr("lineOrder", "lineOrder", b"\0") + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    start = 8 + len(header) + 8 * h
    line = 8 + 3 * 4 * w
    offsets = np.arange(h, dtype="<u8") * line + start
    planes = np.ascontiguousarray(img[..., ::-1].transpose(0, 2, 1), dtype="<f4")  # (H, B/G/R, W)
    with open(path, "wb") as f:
        f.write(b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header + offsets.tobytes())
        for y in range(h):
            f.write(struct.pack("<ii", y, 3 * 4 * w) + planes[y].tobytes())


def write_maps(out, lobe_compression="none"):
    os.makedirs(out, exist_ok=True)
    u = (np.arange(MAP_W) + 0.5) / MAP_W
    v_lobe = (np.arange(MAP_H) + 0.5) / MAP_H
    v_mi = np.arange(MAP_H) / (MAP_H - 1)
    paths = {}
    for name, v in (("lobe", v_lobe), ("mitsuba", v_mi)):
        uu, vv = np.meshgrid(u, v)
        img = sky(latlong(uu, vv)).astype(np.float32)
        p = os.path.join(out, f"sky-sun-{name}.exr")
        if name == "lobe" and lobe_compression == "none":
            # lobe reads its map inside its timed process, Mitsuba before
            # its timer starts: lobe's copy without compression (the PIZ
            # that Mitsuba writes took half of lobe's fixed cost to decode).
            write_exr_uncompressed(p, img)
        else:
            mi.Bitmap(img, mi.Bitmap.PixelFormat.RGB).write(p)
        paths[name] = p
        if name == "lobe":
            save_png(os.path.join(out, "sky-sun-preview.png"), img)
    return paths


def load_scene_desc():
    if tomllib is None:
        die("needs Python >= 3.11 (tomllib) to read bench/two_spheres.toml")
    with open(SCENE, "rb") as f:
        desc = tomllib.load(f)
    cam = desc["camera"]
    spheres = []
    for i, o in enumerate(desc.get("object", [])):
        if o.get("type") != "sphere":
            die(f"{SCENE}: object[{i}]: only spheres are mapped to Mitsuba")
        spheres.append((np.array(o["center"], float), float(o["radius"]), o["material"]))
    return desc, cam, spheres


def mitsuba_bsdf(m, where):
    t = m.get("type")
    if t == "lambert":
        a = m.get("albedo", 0.8)
        a = [a] * 3 if isinstance(a, (int, float)) else a
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": a}}
    if t == "cook-torrance":
        if m.get("distribution", "ggx") not in ("ggx", "beckmann"):
            die(f"{where}: distribution {m.get('distribution')!r} has no Mitsuba roughconductor match")
        if m.get("shadowing") != "smith-separable":
            die(f"{where}: Mitsuba's roughconductor has separable Smith shadowing; "
                "set shadowing = \"smith-separable\"")
        if m.get("fresnel", {"type": "none"}).get("type") != "none" or m.get("kd", 0) not in (0, 0.0):
            die(f"{where}: only fresnel none and kd = 0 are mapped (roughconductor, material none)")
        if "alpha_u" in m or m.get("ks", 1) not in (1, 1.0):
            die(f"{where}: only isotropic alpha and ks = 1 are mapped")
        return {"type": "roughconductor", "material": "none",
                "distribution": m.get("distribution", "ggx"), "alpha": float(m["alpha"])}
    die(f"{where}: material type {t!r} is not mapped to Mitsuba")


def camera_rays(cam, x, y):
    """lobe's pinhole camera (crates/lobe-render/src/camera.rs): directions
    through film points (x, y) in pixels, (0, 0) the top-left corner."""
    o, tgt = np.array(cam["origin"], float), np.array(cam["target"], float)
    up = np.array(cam.get("up", [0, 1, 0]), float)
    w, h = cam.get("width", 320), cam.get("height", 240)
    fwd = (tgt - o) / np.linalg.norm(tgt - o)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    up2 = np.cross(right, fwd)
    th = math.tan(0.5 * math.radians(cam.get("fov_y", 40)))
    sy = (1.0 - 2.0 * y / h) * th
    sx = (2.0 * x / w - 1.0) * th * (w / h)
    d = fwd + right * sx[..., None] + up2 * sy[..., None]
    return o, d / np.linalg.norm(d, axis=-1, keepdims=True)


def sphere_mask(cam, spheres):
    w, h = cam.get("width", 320), cam.get("height", 240)
    jj, ii = np.meshgrid(np.arange(h, dtype=float), np.arange(w, dtype=float), indexing="ij")
    mask = np.ones((h, w), bool)
    for dx, dy in ((0, 0), (1, 0), (0, 1), (1, 1), (0.5, 0.5)):
        o, d = camera_rays(cam, ii + dx, jj + dy)
        hit = np.zeros((h, w), bool)
        for c, r, _ in spheres:
            oc = o - c
            b = d @ oc
            disc = b * b - (oc @ oc - r * r)
            hit |= (disc > 0) & (-b - np.sqrt(np.maximum(disc, 0)) > 0)
        mask &= hit
    return mask


def build_mitsuba_scene(cam, spheres, env_path, sampler, spp, compensation=False):
    d = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 1},
        "sensor": {
            "type": "perspective", "fov": float(cam.get("fov_y", 40)), "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=list(map(float, cam["origin"])), target=list(map(float, cam["target"])),
                up=list(map(float, cam.get("up", [0, 1, 0])))),
            "film": {"type": "hdrfilm", "width": int(cam.get("width", 320)),
                     "height": int(cam.get("height", 240)), "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": sampler, "sample_count": spp},
        },
        "env": {"type": "envmap", "filename": env_path, "mis_compensation": compensation},
    }
    for i, (c, r, m) in enumerate(spheres):
        d[f"sphere{i}"] = {"type": "sphere", "center": c.tolist(), "radius": r,
                           "bsdf": mitsuba_bsdf(m, f"{SCENE}: object[{i}].material")}
    return mi.load_dict(d)


def cpu_time(who):
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


CPU_SHARE = []  # CPU time / (wall time x threads) of the last render


def mi_render(scene, spp, seed):
    """One render; returns (image, seconds, compiled, spp the sampler used)."""
    dr.kernel_history()
    c0 = cpu_time(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    t = time.perf_counter() - t0
    CPU_SHARE.append((cpu_time(resource.RUSAGE_SELF) - c0) / (t * dr.thread_count()))
    hist = dr.kernel_history()
    compiled = any(k["type"] == dr.KernelType.JIT
                   and (not k.get("cache_hit", 1) or k.get("backend_time", 0) > 0) for k in hist)
    used = scene.sensors()[0].sampler().sample_count()
    return np.array(img, dtype=np.float64)[..., :3], t, compiled, used


def rel_rmse(img, ref, mask):
    diff = (img - ref)[mask]
    return float(np.sqrt(np.mean(diff * diff)) / np.mean(ref[mask]))


def save_png(path, img):
    """sRGB PNG of a linear image, one stop darker (the Lambert sphere is
    above 1), clipped."""
    mi.util.write_bitmap(path, (0.5 * img).astype(np.float32))


def interpolate(steps, target):
    """(spp, seconds) where the error crosses `target`, between the last
    step above it and the first at or below it."""
    for a, b in zip(steps, steps[1:]):
        if a["err"] > target >= b["err"] and b["spp"] > a["spp"]:
            s = math.log(a["err"] / b["err"]) / math.log(b["spp"] / a["spp"])
            if s <= 0:
                return b["spp"], b["seconds"]
            n = a["spp"] * (a["err"] / target) ** (1.0 / s)
            t = a["seconds"] + (b["seconds"] - a["seconds"]) * (n - a["spp"]) / (b["spp"] - a["spp"])
            return n, t
    if steps and steps[0]["err"] <= target:
        return steps[0]["spp"], steps[0]["seconds"]
    return None, None


def ladder(name, render, start, target, max_seconds, max_spp, log):
    steps = []
    spp = start
    while spp <= max_spp:
        img, t, used = render(spp, len(steps))
        if steps and used <= steps[-1]["spp"]:  # the sampler rounded up to the same count
            spp *= 2
            continue
        e = rel_rmse(img, *log["ref"])
        share = CPU_SHARE[-1] if CPU_SHARE else float("nan")
        steps.append({"spp": used, "seconds": t, "err": e, "cpu_share": share,
                      "requested": spp, "k": len(steps)})
        print(f"  {name}: {used} spp, {t:.3f} s, rel. RMSE {100 * e:.3f}%, CPU share {100 * share:.0f}%",
              file=sys.stderr, flush=True)
        log["last_img"][name] = img
        if e <= target or t > max_seconds:
            break
        spp *= 2
    return steps


def main():
    p = argparse.ArgumentParser(description="time to 1%% relative RMSE: Mitsuba 3's samplers "
                                            "against lobe render (see this file's header)")
    p.add_argument("--lobe", default=os.path.join(ROOT, "target", "release", "lobe"))
    p.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                   help="threads of both renderers (default: every CPU)")
    p.add_argument("--samplers", default=",".join(SAMPLERS))
    p.add_argument("--lobe-strategy", default="mis",
                   help="lobe render --strategy, or several separated by commas, a row each (default mis)")
    p.add_argument("--lobe-sequence", default="",
                   help="comma-separated `lobe render --sequence` values (sobol, stratified, independent), "
                        "one lobe row each (default: lobe's default, sobol)")
    p.add_argument("--lobe-loop", default="",
                   help="comma-separated `lobe render --loop` values (batch, scalar), one lobe row each "
                        "per --lobe-sequence (default: lobe's default loop, batch)")
    p.add_argument("--lobe-spp-allocation", default="",
                   help="comma-separated `lobe render --spp-allocation` values (uniform, variance), one "
                        "lobe row each per strategy, sequence and loop (default: lobe's default, uniform)")
    p.add_argument("--mis-compensation", choices=["off", "on", "both"], default="both",
                   help="Mitsuba envmap mis_compensation (Karlik et al. 2019; default: both, one row each)")
    p.add_argument("--ref-spp", type=int, default=16384)
    p.add_argument("--ref-passes", type=int, default=4)
    p.add_argument("--ref-sampler", default="multijitter")
    p.add_argument("--target", type=float, default=0.01, help="relative RMSE to reach (default 0.01)")
    p.add_argument("--start-spp", type=int, default=4, help="first Mitsuba spp (default 4)")
    p.add_argument("--lobe-start-spp", type=int, default=64, help="first lobe spp (default 64)")
    p.add_argument("--max-spp", type=int, default=1 << 17)
    p.add_argument("--max-seconds", type=float, default=150.0,
                   help="stop a ladder after a render that took longer (default 150)")
    p.add_argument("--repeat", type=int, default=3,
                   help="time each step this many times (the same seed) and keep the fastest "
                        "(default 3; a shared machine's noise only ever adds time)")
    p.add_argument("--rounds", type=int, default=1,
                   help="after every ladder is built, time each of its steps once more this many "
                        "times minus one, renderer after renderer, and keep the fastest of all "
                        "(default 1: none; a host that gets busier for a while then slows one "
                        "timing of each step instead of every timing of a few)")
    p.add_argument("--skip-lobe", action="store_true")
    p.add_argument("--skip-mitsuba", action="store_true", help="only the reference and lobe")
    p.add_argument("--out", default=os.path.join(HERE, "out"), help="images and maps (default bench/out)")
    p.add_argument("--json-out", help="write the ladders as JSON here")
    p.add_argument("--lobe-map-compression", choices=["none", "piz"], default="none",
                   help="lobe's copy of the map: uncompressed EXR (default; lobe reads it in its timed "
                        "process, Mitsuba its own before the timer) or PIZ as Mitsuba writes it")
    args = p.parse_args()
    if (args.threads < 1 or args.ref_spp < 1 or args.ref_passes < 1 or args.rounds < 1
            or args.repeat < 1 or not 0 < args.target < 1):
        die("--threads, --ref-spp, --ref-passes, --rounds, --repeat must be >= 1 and --target in (0, 1)")
    samplers = [] if args.skip_mitsuba else [s.strip() for s in args.samplers.split(",") if s.strip()]
    for s in samplers + [args.ref_sampler]:
        if s not in SAMPLERS:
            die(f"unknown sampler {s!r} (known: {', '.join(SAMPLERS)})")
    if not args.skip_lobe and not os.path.exists(args.lobe):
        die(f"no lobe binary at {args.lobe}: cargo build --release --locked -p lobe-cli")

    mi.set_variant("llvm_ad_rgb")
    mi.set_log_level(mi.LogLevel.Error)  # orthogonal warns when it rounds the spp
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    dr.set_thread_count(args.threads)

    desc, cam, spheres = load_scene_desc()
    maps = write_maps(args.out, args.lobe_map_compression)
    # lobe renders a copy of the scene file whose environment is the map
    # just written (the committed file names bench/out/sky-sun-lobe.exr).
    with open(SCENE) as f:
        text = f.read()
    text, n = re.subn(r'(?m)^path\s*=\s*".*"', f"path = {json.dumps(os.path.abspath(maps['lobe']))}", text)
    if n != 1:
        die(f"{SCENE}: expected one `path = ...` line (the environment's)")
    lobe_scene = os.path.join(args.out, "two_spheres.toml")
    with open(lobe_scene, "w") as f:
        f.write(text)
    mask = sphere_mask(cam, spheres)
    print(f"{int(mask.sum())} sphere pixels of {mask.size}", file=sys.stderr)

    # The reference.
    print(f"reference: Mitsuba {args.ref_sampler}, {args.ref_passes} x {args.ref_spp // args.ref_passes} spp",
          file=sys.stderr, flush=True)
    per = max(1, args.ref_spp // args.ref_passes)
    rs = build_mitsuba_scene(cam, spheres, maps["mitsuba"], args.ref_sampler, per)
    passes = []
    for k in range(args.ref_passes):
        img, t, _, _ = mi_render(rs, per, 1_000_003 + k)
        passes.append(img)
        print(f"  pass {k + 1}: {t:.1f} s", file=sys.stderr, flush=True)
    ref = np.mean(passes, axis=0)
    if len(passes) > 1:
        spread = np.std(passes, axis=0, ddof=1)[mask]
        ref_err = float(np.sqrt(np.mean(spread ** 2) / len(passes)) / np.mean(ref[mask]))
    else:
        ref_err = float("nan")
    mi.Bitmap(ref.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(os.path.join(args.out, "reference.exr"))
    save_png(os.path.join(args.out, "reference.png"), ref)
    log = {"ref": (ref, mask), "last_img": {}}
    results = {}
    retimers = {}  # name -> (requested spp, step index) -> (seconds, CPU share), one timing

    comps = {"off": [False], "on": [True], "both": [False, True]}[args.mis_compensation]
    for s, comp in [(s, c) for c in comps for s in samplers]:
        name = f"Mitsuba {s}" + (" + mis_compensation" if comp else "")
        print(name, file=sys.stderr, flush=True)
        scene = build_mitsuba_scene(cam, spheres, maps["mitsuba"], s, args.start_spp, comp)

        def retime(spp, k, scene=scene):
            """One more timed render of step `k`: (seconds, CPU share)."""
            t = mi_render(scene, spp, 2 * k + 2)[1]
            return t, CPU_SHARE[-1]

        def render(spp, k, scene=scene, retime=retime):
            # Always a warm-up render first (it compiles the kernels unless
            # Dr.Jit's cache has them), then the timed one: warm, and with
            # the same seed whatever the cache held, so that the error of a
            # step is the same in every run of the script.
            mi_render(scene, spp, 2 * k + 1)
            img, t, compiled, used = mi_render(scene, spp, 2 * k + 2)
            if compiled:
                print(f"  (spp {spp}: the timed render compiled a kernel too)", file=sys.stderr)
            t, share = min([(t, CPU_SHARE[-1])] + [retime(spp, k) for _ in range(args.repeat - 1)])
            CPU_SHARE.append(share)
            return img, t, used

        retimers[name] = retime
        results[name] = ladder(name, render, args.start_spp, args.target,
                               args.max_seconds, args.max_spp, log)

    seqs = [q.strip() for q in args.lobe_sequence.split(",") if q.strip()] or [None]
    loops = [q.strip() for q in args.lobe_loop.split(",") if q.strip()] or [None]
    strats = [q.strip() for q in args.lobe_strategy.split(",") if q.strip()] or ["mis"]
    allocs = [q.strip() for q in args.lobe_spp_allocation.split(",") if q.strip()] or [None]
    for st, seq, lp, al in [] if args.skip_lobe else [(a, q, l, c) for a in strats for q in seqs
                                                      for l in loops for c in allocs]:
        name = (f"lobe {st}" + (f" --sequence {seq}" if seq else "")
                + (f" --loop {lp}" if lp else "") + (f" --spp-allocation {al}" if al else ""))
        print(name, file=sys.stderr, flush=True)

        def lobe_cmd(spp, k, st=st, seq=seq, lp=lp, al=al):
            tag = ((st + "-" if st != "mis" else "") + (seq + "-" if seq else "") + (lp + "-" if lp else "")
                   + (al + "-" if al else ""))
            out = os.path.join(args.out, f"lobe-{tag}{spp}")
            cmd = ([args.lobe, "render", lobe_scene, "--spp", str(spp), "--seed", str(k + 1),
                    "--threads", str(args.threads), "--strategy", st, "--out", out, "-q"]
                   + (["--sequence", seq] if seq else []) + (["--loop", lp] if lp else [])
                   + (["--spp-allocation", al] if al else []))
            return cmd, out

        def lobe_once(cmd):
            """One timed process: (seconds, CPU share)."""
            c0 = cpu_time(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            r = subprocess.run(cmd, capture_output=True, text=True)
            dt = time.perf_counter() - t0
            if r.returncode != 0:
                die(f"{' '.join(cmd)} failed: {r.stderr.strip()}")
            return dt, (cpu_time(resource.RUSAGE_CHILDREN) - c0) / (dt * args.threads)

        def render_lobe(spp, k, lobe_cmd=lobe_cmd):
            cmd, out = lobe_cmd(spp, k)
            t, share = min(lobe_once(cmd) for _ in range(args.repeat))
            CPU_SHARE.append(share)
            img = np.array(mi.Bitmap(out + ".exr"), dtype=np.float64)[..., :3]
            return img, t, spp

        retimers[name] = lambda spp, k, lobe_cmd=lobe_cmd: lobe_once(lobe_cmd(spp, k)[0])
        results[name] = ladder(name, render_lobe, args.lobe_start_spp, args.target,
                               args.max_seconds, args.max_spp, log)

    # More rounds: every step of every ladder timed once more per round,
    # renderer after renderer, the fastest kept.
    for r in range(1, args.rounds):
        print(f"round {r + 1} of {args.rounds}", file=sys.stderr, flush=True)
        for name, steps in results.items():
            for step in steps:
                t, share = retimers[name](step["requested"], step["k"])
                if t < step["seconds"]:
                    step["seconds"], step["cpu_share"] = t, share

    # The table.
    lobe_ver = "?"
    if os.path.exists(args.lobe):
        lobe_ver = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                  capture_output=True, text=True).stdout.strip() or "?"
    cpu = cpu_model()
    load = " ".join(open("/proc/loadavg").read().split()[:3]) if os.path.exists("/proc/loadavg") else "?"
    print(f"Scene bench/two_spheres.toml, {cam.get('width')}x{cam.get('height')}, {int(mask.sum())} sphere "
          f"pixels; CPU {cpu}, {args.threads} threads; Mitsuba {mi.__version__} llvm_ad_rgb `direct` "
          f"(1 emitter + 1 BSDF sample per spp); lobe commit {lobe_ver}, `lobe render --strategy "
          f"{' / '.join(strats)}`.  ")
    print(f"Reference: Mitsuba {args.ref_sampler}, {args.ref_passes} x {per} spp, its own rel. RMSE "
          f"{100 * ref_err:.3f}%. Load average at the end {load}. Target: rel. RMSE "
          f"{100 * args.target:g}% over the sphere pixels.")
    print()
    rows = []
    for name, steps in results.items():
        hit = next((s for s in steps if s["err"] <= args.target), None)
        n_i, t_i = interpolate(steps, args.target)
        mean_ratio = None
        if name in log["last_img"]:
            mean_ratio = float(np.mean(log["last_img"][name][mask]) / np.mean(ref[mask]))
        rows.append((name, hit, n_i, t_i, steps[-1], mean_ratio))
    best = [r for r in rows if r[0].startswith("Mitsuba") and r[3] is not None]
    best_t = min((r[3] for r in best), default=None)
    best_name = next((r[0] for r in best if r[3] == best_t), None)
    tgt = f"{100 * args.target:g}%"
    print(f"| renderer / sampler | spp to {tgt} | rel. RMSE there | time to {tgt} (s) | interp. spp "
          f"| interp. time (s) | time / Mitsuba's best | mean / reference | CPU share |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, hit, n_i, t_i, last, mr in rows:
        if hit:
            a, b, c = str(hit["spp"]), f"{100 * hit['err']:.3f}%", f"{hit['seconds']:.2f}"
        else:
            a, b, c = f"> {last['spp']}", f"{100 * last['err']:.3f}%", f"> {last['seconds']:.2f}"
        ni = "—" if n_i is None else f"{n_i:.0f}"
        # (Three decimals: the goal's 0.5× is within a run's noise of it.)
        ti = "—" if t_i is None else f"{t_i:.3f}"
        ratio = "—" if t_i is None or best_t is None else f"{t_i / best_t:.3f}×"
        cs = (hit or last)["cpu_share"]
        print(f"| {name} | {a} | {b} | {c} | {ni} | {ti} | {ratio} | "
              f"{'—' if mr is None else f'{mr:.4f}'} | {100 * cs:.0f}% |")
    print("\nCPU share: CPU time / (wall time × threads) of the render at the step shown; about 100% "
          "on an idle machine, less when other work competes for the cores.")
    if best_name:
        print(f"\nMitsuba's best here: {best_name} (interpolated time). Goal of issue 10: lobe at most 0.5×.")
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump({"reference_err": ref_err, "ladders": results}, f, indent=2)
    for name in log["last_img"]:
        save_png(os.path.join(args.out, name.replace(" + ", "+").replace(" --sequence ", "-")
                              .replace(" --loop ", "-").replace(" --spp-allocation ", "-")
                              .replace(" ", "-") + ".png"),
                 log["last_img"][name])


if __name__ == "__main__":
    main()
