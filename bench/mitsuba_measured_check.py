#!/usr/bin/env python3
"""Cross-check lobe's RGL files against Mitsuba 3's `measured` plugin (off CI).

Writes RGL files of analytic materials with `lobe tabulate`, loads them in
Mitsuba 3 (`scalar_rgb`), and compares Mitsuba's `eval` (f·cos θ of the
light direction) with lobe's reading of the same file (`lobe eval`, f
without the cosine, times cos θi) over random pairs of directions, and with
the analytic material itself; and Mitsuba's sampling `pdf` (the file's
luminance and visible-normal warps) with the pdf of lobe's `vndf` strategy
of the same file. Each file is also checked with `jacobian` set to 1 and
non-constant `ndf` and `sigma` tables, as measured files have them (lobe
writes `jacobian` 0), against Mitsuba only.

Usage: /work/venv-mitsuba/bin/python bench/mitsuba_measured_check.py [LOBE]
(LOBE: the lobe binary, default target/release/lobe or target/debug/lobe).
"""
import json
import math
import os
import random
import subprocess
import sys
import tempfile

import mitsuba as mi

mi.set_variant("scalar_rgb")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MATERIALS = {
    "ggx-0.2": '{"type":"cook-torrance","distribution":"ggx","alpha":0.2,"kd":0.1,'
               '"fresnel":{"type":"schlick","f0":[0.9,0.6,0.3]}}',
    "beckmann-0.4": '{"type":"cook-torrance","distribution":"beckmann","alpha":0.4,'
                    '"kd":[0.3,0.2,0.1]}',
    "lambert": '{"type":"lambert","albedo":[0.8,0.5,0.2]}',
}


def read_tensor(path):
    """The fields of a tensor file: {name: (dtype, shape, bytes)}, in order."""
    import struct
    b = open(path, "rb").read()
    assert b[:12] == b"tensor_file\0" and b[12:14] == b"\x01\x00", path
    (n,) = struct.unpack_from("<I", b, 14)
    at, fields = 18, {}
    sizes = {1: 1, 2: 1, 3: 2, 4: 2, 5: 4, 6: 4, 7: 8, 8: 8, 9: 2, 10: 4, 11: 8}
    for _ in range(n):
        (ln,) = struct.unpack_from("<H", b, at)
        name = b[at + 2:at + 2 + ln].decode()
        at += 2 + ln
        ndim, dtype, offset = struct.unpack_from("<HBQ", b, at)
        at += 11
        shape = struct.unpack_from(f"<{ndim}Q", b, at)
        at += 8 * ndim
        count = sizes[dtype]
        for s in shape:
            count *= s
        fields[name] = (dtype, list(shape), b[offset:offset + count])
    return fields


def write_tensor(path, fields):
    """Write {name: (dtype, shape, bytes)} as a tensor file."""
    import struct
    header = 18 + sum(2 + len(n) + 2 + 1 + 8 + 8 * len(s) for n, (_, s, _) in fields.items())
    out, data, offset = bytearray(b"tensor_file\0\x01\x00"), bytearray(), header
    out += struct.pack("<I", len(fields))
    for name, (dtype, shape, raw) in fields.items():
        out += struct.pack("<H", len(name)) + name.encode()
        out += struct.pack(f"<HBQ{len(shape)}Q", len(shape), dtype, offset, *shape)
        offset += len(raw)
        data += raw
    open(path, "wb").write(bytes(out + data))


def with_jacobian(src, dst):
    """`src` with `jacobian` 1 and non-constant 8 × 8 `ndf` and `sigma`
    tables (as Dupuy and Jakob's measured files have): exercises the
    `ndf(u_m) / (4 sigma(u_wo))` factor of both readers."""
    import struct
    f = read_tensor(src)
    n = 8
    ndf = [1.0 + 3.0 * (x / (n - 1)) ** 2 + 0.5 * (y / (n - 1)) for y in range(n) for x in range(n)]
    # sigma varies with θo only: for an isotropic file Mitsuba 3.9.1 folds
    # a view with y > 0 to the opposite azimuth (φo + π) before reading
    # sigma at (θo, φo), which changes nothing for an isotropic material's
    # sigma (constant in φo) but would for a table varying with φo (lobe
    # reads it at φo itself).
    sigma = [2.0 + (x / (n - 1)) + 0.7 * (x / (n - 1)) ** 2 for y in range(n) for x in range(n)]
    f["jacobian"] = (1, [1], b"\x01")
    f["ndf"] = (10, [n, n], struct.pack(f"<{n * n}f", *ndf))
    f["sigma"] = (10, [n, n], struct.pack(f"<{n * n}f", *sigma))
    write_tensor(dst, f)


def lobe_binary():
    if len(sys.argv) > 1:
        return sys.argv[1]
    for p in ("target/release/lobe", "target/debug/lobe"):
        if os.path.exists(os.path.join(ROOT, p)):
            return os.path.join(ROOT, p)
    sys.exit("build lobe first (cargo build -p lobe-cli)")


def unit(theta, phi):
    return [math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), math.cos(theta)]


def lobe_eval(lobe, material, pairs, key="f"):
    text = "".join(json.dumps({"wo": wo, "wi": wi}) + "\n" for wo, wi in pairs)
    out = subprocess.run([lobe, "eval", "--material", material], input=text,
                         capture_output=True, text=True, check=True).stdout
    return [json.loads(line)[key] for line in out.splitlines() if line.strip()]


def main():
    lobe = lobe_binary()
    rng = random.Random(1)
    # Views below 80° (the file's last view is 89°), lights above 5° elevation.
    pairs = [(unit(math.radians(rng.uniform(0, 80)), rng.uniform(0, 2 * math.pi)),
              unit(math.radians(rng.uniform(0, 85)), rng.uniform(0, 2 * math.pi)))
             for _ in range(2000)]
    tmp = tempfile.mkdtemp(prefix="lobe-mitsuba-")
    worst_all = 0.0
    print(f"Mitsuba {mi.__version__}, variant scalar_rgb; {len(pairs)} random pairs per material")
    cases = []
    for name, material in MATERIALS.items():
        path = os.path.join(tmp, name + ".bsdf")
        subprocess.run([lobe, "tabulate", "--material", material, "--format", "rgl", "--out", path],
                       check=True, capture_output=True)
        cases.append((name, material, path, True))
        # The same file with jacobian = 1 (no longer the analytic model).
        jpath = os.path.join(tmp, name + "-jacobian.bsdf")
        with_jacobian(path, jpath)
        cases.append((name + "+jac", material, jpath, False))
    for name, material, path, is_model in cases:
        bsdf = mi.load_dict({"type": "measured", "filename": path})
        measured = json.dumps({"type": "measured", "path": path})
        f_lobe = lobe_eval(lobe, measured, pairs)
        f_model = lobe_eval(lobe, material, pairs)
        # The pdf of lobe's `vndf` strategy of an RGL file is the file's own
        # scheme (luminance and visible-normal warps), Mitsuba's `pdf`.
        pdf_lobe = [p["vndf"] for p in lobe_eval(lobe, measured, pairs, "pdf")]
        ctx = mi.BSDFContext()
        worst_abs = worst_rel = worst_pdf = 0.0
        model_err = []
        for (wo, wi), fl, fm, pl in zip(pairs, f_lobe, f_model, pdf_lobe):
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(*wo)  # Mitsuba's wi is the viewer (lobe's wo)
            si.n = mi.Normal3f(0, 0, 1)
            si.sh_frame = mi.Frame3f(si.n)
            v = bsdf.eval(ctx, si, mi.Vector3f(*wi))  # f cos θ of the light
            mits = [v[0], v[1], v[2]]
            pm = bsdf.pdf(ctx, si, mi.Vector3f(*wi))
            worst_pdf = max(worst_pdf, abs(pm - pl) / max(abs(pl), 1e-3))
            lob = [c * wi[2] for c in fl]
            mod = [c * wi[2] for c in fm]
            for a, b, m in zip(mits, lob, mod):
                worst_abs = max(worst_abs, abs(a - b))
                worst_rel = max(worst_rel, abs(a - b) / max(abs(b), 1e-3))
                model_err.append(abs(a - m) / max(abs(m), 1e-3))
        model_err.sort()
        if not is_model:
            print(f"{name:>13}: Mitsuba vs lobe (same file): worst |Δ(f cos)| {worst_abs:.3e}, "
                  f"worst relative {worst_rel:.3e}, sampling pdf (lobe's vndf) worst relative "
                  f"{worst_pdf:.3e}")
            worst_all = max(worst_all, worst_rel, worst_pdf)
            continue
        worst_all = max(worst_all, worst_rel, worst_pdf)
        print(f"{name:>13}: Mitsuba vs lobe (same file): worst |Δ(f cos)| {worst_abs:.3e}, "
              f"worst relative {worst_rel:.3e}, sampling pdf (lobe's vndf) worst relative "
              f"{worst_pdf:.3e}; file vs analytic model: median relative "
              f"{model_err[len(model_err) // 2]:.3e}, 99th percentile "
              f"{model_err[int(0.99 * len(model_err))]:.3e}")
    print(f"worst relative difference Mitsuba vs lobe over all materials (f cos and pdf): {worst_all:.3e}")
    return 0 if worst_all < 1e-3 else 1


if __name__ == "__main__":
    sys.exit(main())
