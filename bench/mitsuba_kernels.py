#!/usr/bin/env python3
"""Throughput of Mitsuba 3's rough-conductor BSDF kernels, measured the way
`lobe bench` measures lobe's batch kernels (issue 9), so that the two can be
put side by side (`bench/side_by_side.py` does that in one run).

Setup (not run by CI):

    python3 -m venv venv-mitsuba
    venv-mitsuba/bin/pip install mitsuba==3.9.1 numpy   # Dr.Jit 1.5.0 comes with it
    sudo apt-get install libllvm19                      # Debian/Ubuntu: Dr.Jit's LLVM backend
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
    venv-mitsuba/bin/python bench/mitsuba_kernels.py            # 1 and 2 threads, a table
    venv-mitsuba/bin/python bench/mitsuba_kernels.py --threads 1 --json

If DRJIT_LIBLLVM_PATH is not set and the Debian path above exists, the script
sets it itself.

What one figure is:
* Variant `llvm_ad_rgb` (Dr.Jit's LLVM JIT: f32 lanes as wide as the host CPU
  allows, AVX-512 gives 16; the width is read from the generated kernel's IR
  and printed as "simd").
* Plugin `roughconductor` with `material = none` (eta = 0, k = 1: the
  conductor Fresnel term evaluates to exactly 1, lobe's Fresnel `none`),
  `alpha = 0.2`, `distribution = ggx|beckmann`, `sample_visible = true`
  (lobe's `vndf`) or `false` (lobe's `brdf`, sampling D(m) cos θm).
* Inputs: N = 2^22 lanes (by default) of precomputed wo (lobe's wo, Mitsuba's
  `si.wi`) uniform over the upper hemisphere (uniform cos θ, uniform azimuth:
  the same distribution as `lobe bench`, from numpy's PCG64 instead of
  rand_pcg), sample2 = (u1, u2) uniform, sample1 uniform (lobe's uc: the lobe choice
  of plastics and dielectrics; roughconductor ignores it).
* `msps`: `bsdf.sample` + `bsdf.eval` + `bsdf.pdf` at the sampled direction,
  the three channels of weight and f plus pdf summed per lane and reduced with
  `dr.sum`, `dr.eval` + `dr.sync_thread()`: one fused kernel plus the
  reduction. `eval_pdf_msps`: the same with the combined `bsdf.eval_pdf`
  (what lobe's `msps` does: sample + eval_pdf). `sample_msps`: `bsdf.sample`
  alone (every output: weight, pdf, wo summed, so that nothing is dead code).
  `kernel_msps`: the same as `msps` but from Dr.Jit's own kernel timer
  (kernel history: the fused kernel and the reduction, no Python, no tracing).
* Each figure is the median wall time of --reps timed runs (default 10) after
  --warmup untimed runs (default 2) that compile the kernel. Every timed run
  gets fresh input arrays (copied from numpy outside the timed region, with
  u1 shifted by a per-run offset so that the results differ) so that it really
  recomputes; the script checks in Dr.Jit's kernel history that every timed
  run hit the kernel cache (no compilation timed) and warns otherwise.
* Threads: `dr.set_thread_count(T)` for each T of --threads.

Differences from lobe's material, which the figures do not hide:
* Shadowing: Mitsuba's roughconductor uses the separable Smith term
  G1(wi) G1(wo); lobe's default and the only one its batch path has is the
  height-correlated one, 1 / (1 + Λ(wi) + Λ(wo)). About the same arithmetic
  (two Λ, one division), slightly different values.
* Fresnel: Mitsuba computes the complex conductor formula (eta = 0, k = 1) and
  gets 1; lobe's Fresnel `none` computes nothing. Mitsuba's RGB channels
  are identical constants, and Dr.Jit merges them (the kernel has 345 IR
  operations with three channels summed, 341 with one).
* lobe's `sample` also returns f (`f_r`, no cosine); Mitsuba's returns the
  weight and pdf only.

Output: a table, or with --json one object per thread count in the shape of
`lobe bench --json` (a list when several thread counts are given), plus a
"material" field per result holding the lobe material JSON that matches.
"""

import argparse
import json
import os
import re
import statistics
import sys
import time

_LLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(_LLVM):
    os.environ["DRJIT_LIBLLVM_PATH"] = _LLVM

import numpy as np  # noqa: E402
from machine import cpu_model  # noqa: E402  (bench/machine.py, beside this script)

try:
    import drjit as dr  # noqa: E402
    import mitsuba as mi  # noqa: E402
except ImportError as e:
    sys.exit(f"mitsuba_kernels.py: {e}; install with `pip install mitsuba numpy` (see the header)")

VARIANT = "llvm_ad_rgb"

# name -> (lobe strategy, lobe material JSON, Mitsuba BSDF dict)
CASES = {
    "ggx-vndf": (
        "vndf",
        '{"type":"cook-torrance","distribution":"ggx","alpha":0.2}',
        {"type": "roughconductor", "material": "none", "distribution": "ggx",
         "alpha": 0.2, "sample_visible": True},
    ),
    "ggx-brdf": (
        "brdf",
        '{"type":"cook-torrance","distribution":"ggx","alpha":0.2}',
        {"type": "roughconductor", "material": "none", "distribution": "ggx",
         "alpha": 0.2, "sample_visible": False},
    ),
    "beckmann-vndf": (
        "vndf",
        '{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}',
        {"type": "roughconductor", "material": "none", "distribution": "beckmann",
         "alpha": 0.2, "sample_visible": True},
    ),
    "beckmann-brdf": (
        "brdf",
        '{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}',
        {"type": "roughconductor", "material": "none", "distribution": "beckmann",
         "alpha": 0.2, "sample_visible": False},
    ),
}
DEFAULT_CASES = "ggx-vndf,ggx-brdf,beckmann-vndf"

# Mitsuba 3 plugins whose names and parameters lobe's material descriptions
# share (`lobe bench --all` uses them wherever Mitsuba has the model).
MITSUBA_PLUGINS = {"diffuse", "roughconductor", "roughdielectric", "roughplastic", "conductor",
                   "dielectric", "thindielectric", "plastic", "twosided"}


def mitsuba_dict(material, strategy):
    """The Mitsuba BSDF dict doing the work of lobe's `material` (JSON text)
    sampled by `strategy`, or None where Mitsuba has no such model or
    sampler: the same dict (lobe reads Mitsuba's names and defaults), with
    `sample_visible` from the strategy (vndf: true, brdf: false) for the
    rough plugins; the diffuse plugins sample the cosine (lobe's `cosine`
    and `brdf`), the smooth ones their delta (lobe's `brdf`, their only
    strategy). lobe-only keys (`multiscatter`) have no Mitsuba equivalent."""
    d = json.loads(material)
    t = d.get("type")
    if t not in MITSUBA_PLUGINS or "multiscatter" in json.dumps(d):
        return None
    inner = d.get("material", {}) if t == "twosided" else d
    it = inner.get("type") if isinstance(inner, dict) else None
    if t == "twosided" and it not in MITSUBA_PLUGINS:
        return None
    kind = it if t == "twosided" else t
    if kind in ("roughconductor", "roughdielectric", "roughplastic"):
        if strategy not in ("vndf", "brdf"):
            return None
        inner["sample_visible"] = strategy == "vndf"
    elif kind == "diffuse":
        if strategy not in ("cosine", "brdf"):
            return None
    elif strategy != "brdf":
        return None
    return d


def cases_from(path):
    """(name, (strategy, lobe material, Mitsuba dict)) for each distinct
    (material, strategy) of a `lobe bench --all --json` file that Mitsuba
    can run."""
    with open(path) as f:
        rows = json.load(f)["results"]
    out, seen = [], set()
    for r in rows:
        k = (r["material"], r["strategy"])
        if k in seen:
            continue
        seen.add(k)
        d = mitsuba_dict(*k)
        if d is not None:
            out.append((f"{r['case']} {r['strategy']}", (r["strategy"], r["material"], d)))
    return out


class Inputs:
    """Precomputed inputs (numpy, f32), the distribution of `lobe bench`."""

    def __init__(self, n, seed):
        rng = np.random.default_rng(seed)
        cos_t = 1.0 - rng.random(n)
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        phi = 2.0 * np.pi * rng.random(n)
        self.wo = [(sin_t * np.cos(phi)).astype(np.float32),
                   (sin_t * np.sin(phi)).astype(np.float32),
                   cos_t.astype(np.float32)]
        # 24 random bits each: uniform f32 in [0, 1), as lobe bench draws them.
        self.u1 = rng.integers(0, 1 << 24, n, dtype=np.int64)
        self.u2 = (rng.integers(0, 1 << 24, n) / float(1 << 24)).astype(np.float32)
        # sample1 (lobe's uc): which lobe a plastic or a dielectric samples.
        self.uc = (rng.integers(0, 1 << 24, n) / float(1 << 24)).astype(np.float32)

    def fresh(self, run):
        """New Dr.Jit arrays (evaluated, outside any timing); u1 shifted by a
        per-run offset (modulo 1, on the 24-bit grid) so that each run
        computes different results."""
        shift = (run * 10368889) % (1 << 24)  # about 0.618 of the grid per run
        u1 = (((self.u1 + shift) % (1 << 24)) / float(1 << 24)).astype(np.float32)
        si = dr.zeros(mi.SurfaceInteraction3f)
        si.wi = mi.Vector3f(mi.Float(self.wo[0]), mi.Float(self.wo[1]), mi.Float(self.wo[2]))
        s2 = mi.Point2f(mi.Float(u1), mi.Float(self.u2))
        s1 = mi.Float(self.uc)
        dr.eval(si.wi, s2, s1)
        dr.sync_thread()
        return si, (s1, s2)


def kernel(bsdf, mode, si, samples):
    """Trace one run; returns the reduced sum (not yet evaluated)."""
    s1, s2 = samples
    ctx = mi.BSDFContext()
    bs, w = bsdf.sample(ctx, si, s1, s2)
    if mode == "sample":
        s = w.x + w.y + w.z + bs.pdf + bs.wo.x + bs.wo.y + bs.wo.z
    else:
        if mode == "eval_pdf":
            f, p = bsdf.eval_pdf(ctx, si, bs.wo)
        else:
            f = bsdf.eval(ctx, si, bs.wo)
            p = bsdf.pdf(ctx, si, bs.wo)
        s = w.x + w.y + w.z + f.x + f.y + f.z + p
    return dr.sum(s)


def time_mode(bsdf, mode, inputs, warmup, reps, info):
    """Median wall time and median kernel time (s) of `reps` warm runs."""
    walls, kernels = [], []
    for run in range(warmup + reps):
        si, s2 = inputs.fresh(run)
        dr.kernel_history()  # clears the history
        t0 = time.perf_counter()
        total = kernel(bsdf, mode, si, s2)
        dr.eval(total)
        dr.sync_thread()
        wall = time.perf_counter() - t0
        hist = dr.kernel_history()
        if not np.isfinite(float(total[0])):
            info["not_finite"].add(mode)
        jit = [k for k in hist if k["type"] == dr.KernelType.JIT]
        if run >= warmup:
            walls.append(wall)
            kernels.append(sum(k["execution_time"] for k in hist) / 1e3)
            if any(not k.get("cache_hit", 1) for k in jit):
                info["cache_misses"] += 1
        if "lanes" not in info:
            for k in jit:
                m = re.findall(r"<(\d+) x float>", k["ir"].getvalue())
                if m:
                    info["lanes"] = max(int(x) for x in m)
                    info["ops"] = k.get("operation_count")
                    break
    return statistics.median(walls), statistics.median(kernels)


def simd_name(lanes):
    if lanes is None:
        return "llvm (unknown width)"
    isa = {16: "avx512", 8: "avx2", 4: "sse4.2/neon"}.get(lanes, "?")
    return f"llvm {isa} ({lanes} f32 lanes)"


def run(args):
    mi.set_variant(VARIANT)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    if args.cases_from:
        try:
            chosen = cases_from(args.cases_from)
        except (OSError, KeyError, ValueError) as e:
            sys.exit(f"mitsuba_kernels.py: --cases-from {args.cases_from}: {e}")
    else:
        names = [c.strip() for c in args.cases.split(",") if c.strip()]
        for c in names:
            if c not in CASES:
                sys.exit(f"mitsuba_kernels.py: --cases: unknown case {c!r} (known: {', '.join(CASES)})")
        chosen = [(c, CASES[c]) for c in names]
    try:
        threads = [int(t) for t in args.threads.split(",")]
    except ValueError:
        sys.exit(f"mitsuba_kernels.py: --threads: not a list of integers: {args.threads!r}")
    if any(t < 1 for t in threads) or args.samples < 1 or args.reps < 1 or args.warmup < 1:
        sys.exit("mitsuba_kernels.py: --threads, --samples, --reps and --warmup must be >= 1")
    inputs = Inputs(args.samples, args.seed)
    n = args.samples
    msps = lambda t: n / t / 1e6 if t > 0 else None  # noqa: E731
    out = []
    info = {"cache_misses": 0}
    for t in threads:
        dr.set_thread_count(t)
        results = []
        for c, (strategy, lobe_material, d) in chosen:
            info["not_finite"] = set()
            bsdf = mi.load_dict(d)
            full, full_k = time_mode(bsdf, "sep", inputs, args.warmup, args.reps, info)
            ep, _ = time_mode(bsdf, "eval_pdf", inputs, args.warmup, args.reps, info)
            smp, _ = time_mode(bsdf, "sample", inputs, args.warmup, args.reps, info)
            if info["not_finite"]:
                # Mitsuba's own outputs (a NaN or an infinity among 2^22
                # lanes): timed all the same, flagged.
                print(f"warning: {c}, {t} threads: the sum of Mitsuba's outputs is not finite "
                      f"({', '.join(sorted(info['not_finite']))})", file=sys.stderr)
            results.append({
                "not_finite": sorted(info["not_finite"]),
                "case": c,
                "strategy": strategy,
                "material": lobe_material,
                "mitsuba_bsdf": d,
                "msps": msps(full),
                "sample_msps": msps(smp),
                "eval_pdf_msps": msps(ep),
                "kernel_msps": msps(full_k),
            })
        out.append({
            "renderer": "mitsuba",
            "mitsuba": mi.__version__,
            "drjit": dr.__version__,
            "variant": VARIANT,
            "simd": simd_name(info.get("lanes")),
            "cpu": cpu_model(),
            "threads": t,
            "samples": n,
            "reps": args.reps,
            "warmup": args.warmup,
            "results": results,
        })
    if info["cache_misses"]:
        print(f"warning: {info['cache_misses']} timed runs compiled a kernel (kernel cache miss)",
              file=sys.stderr)
    if args.json:
        print(json.dumps(out[0] if len(out) == 1 else out, indent=2))
        return
    o = out[0]
    print(f"Mitsuba {o['mitsuba']} {VARIANT}, Dr.Jit {o['drjit']}; cpu {o['cpu']}; simd {o['simd']}")
    print(f"{n} samples, median of {args.reps} warm runs; M samples/s")
    print(f"{'case':<40} {'threads':>7} {'s+eval+pdf':>11} {'s+eval_pdf':>11} {'sample':>9} {'kernel':>9}")
    for o in out:
        for r in o["results"]:
            k = "—" if r["kernel_msps"] is None else f"{r['kernel_msps']:.1f}"
            print(f"{r['case']:<40} {o['threads']:>7} {r['msps']:>11.1f} {r['eval_pdf_msps']:>11.1f} "
                  f"{r['sample_msps']:>9.1f} {k:>9}")


def main():
    p = argparse.ArgumentParser(
        description="Mitsuba 3 rough-conductor BSDF throughput, measured like `lobe bench` "
                    "(see the header of this file for the setup and what each figure is)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts (default 1,2)")
    p.add_argument("--samples", "-n", type=int, default=1 << 22, help="lanes (default 2^22)")
    p.add_argument("--reps", type=int, default=10, help="timed runs; the median is reported (default 10)")
    p.add_argument("--warmup", type=int, default=2, help="untimed runs first (default 2)")
    p.add_argument("--cases", default=DEFAULT_CASES,
                   help=f"comma-separated, from {', '.join(CASES)} (default {DEFAULT_CASES})")
    p.add_argument("--cases-from", metavar="FILE",
                   help="instead of --cases: every (material, strategy) of a `lobe bench --all --json` "
                        "output that Mitsuba has (see mitsuba_dict)")
    p.add_argument("--seed", type=int, default=0x6C6F6265, help="numpy seed of the inputs")
    p.add_argument("--json", action="store_true", help="print JSON (the shape of `lobe bench --json`)")
    run(p.parse_args())


if __name__ == "__main__":
    main()
