"""Python against lobe's Rust paths: the batch kernels bit for bit (through
`lobe eval --batch`, the same f32 inputs), and the scalar f64 reference
within 1e-4 relative, where the f32 inputs determine the value to that."""

import json
import subprocess

import numpy as np
import pytest

import lobe

MATERIALS = [
    {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2},
    {"type": "cook-torrance", "distribution": "ggx", "alpha_u": 0.05, "alpha_v": 0.5, "kd": 0.2,
     "fresnel": {"type": "conductor"}},
    {"type": "cook-torrance", "distribution": "beckmann", "alpha": 0.3, "kd": 0.1, "fresnel": {"type": "dielectric"}},
    {"type": "phong", "exponent": 30, "kd": 0.2},
    {"type": "blinn-phong", "exponent": 200},
    {"type": "lambert"},
]
IDS = ["ggx", "ggx-aniso-kd", "beckmann-kd", "phong-kd", "blinn-phong", "lambert"]


def inputs(n, seed):
    """f32 views over the hemisphere (a tenth of them grazing, down to
    cos θ = 1e-7), not renormalized after rounding; f32 uniforms."""
    rng = np.random.default_rng(seed)
    c = 1.0 - rng.random(n)
    c[: n // 10] = 10.0 ** rng.uniform(-7, -2, n // 10)
    s = np.sqrt(1 - c * c)
    p = 2 * np.pi * rng.random(n)
    wo = np.stack([s * np.cos(p), s * np.sin(p), c], axis=1).astype(np.float32)
    u = rng.random((n, 2)).astype(np.float32)
    uc = rng.random(n).astype(np.float32)
    return wo, u, uc


def run_cli(exe, desc, lines):
    out = subprocess.run([exe, "eval", "--material", json.dumps(desc), "--batch"], input="\n".join(lines) + "\n",
                         check=True, capture_output=True, text=True).stdout
    return [json.loads(x) for x in out.splitlines()]


def f32(x):
    return np.asarray(x, dtype=np.float64).astype(np.float32)


def same_bits(a, b):
    a, b = np.asarray(a, np.float32), np.asarray(b, np.float32)
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


@pytest.mark.parametrize("desc", MATERIALS, ids=IDS)
def test_the_same_bits_as_the_rust_batch_path(desc, lobe_exe):
    m = lobe.load_dict(desc)
    n = 3000
    wo, u, uc = inputs(n, 11)
    for st in m.strategies:
        assert m.batched(st), st
        lines = [json.dumps({"wo": wo[i].tolist(), "u": u[i].tolist(), "uc": float(uc[i]), "strategy": st})
                 for i in range(n)]
        cli = run_cli(lobe_exe, desc, lines)
        valid = np.array([r["wi"] is not None for r in cli])
        wi = f32([r["wi"] if r["wi"] is not None else [0, 0, 0] for r in cli])
        pdf, weight = f32([r["pdf"] for r in cli]), f32([r["weight"] for r in cli])
        # f32 arrays, and the same values as f64 arrays: both are the rows the CLI read.
        for w, uu, c in ((wo, u, uc), (wo.astype(np.float64), u.astype(np.float64), uc.astype(np.float64))):
            s = m.sample(w, uu, c, strategy=st)
            assert np.array_equal(s.valid, valid), st
            assert same_bits(s.wi, wi), st
            assert same_bits(s.pdf, pdf), st
            assert same_bits(s.weight, weight), st
    # eval lines: wi drawn by the last strategy (where valid), else from
    # the hemisphere.
    s = m.sample(wo, u, uc, strategy=m.strategies[-1])
    wi = np.where(s.valid[:, None], s.wi, inputs(n, 12)[0])
    wi[: n // 2] = inputs(n // 2, 13)[0]
    lines = [json.dumps({"wo": wo[i].tolist(), "wi": wi[i].tolist()}) for i in range(n)]
    cli = run_cli(lobe_exe, desc, lines)
    assert same_bits(m.eval(wo, wi), f32([r["f"] for r in cli]))
    wo64, wi64 = wo.astype(np.float64), np.asfortranarray(wi.astype(np.float64))
    assert same_bits(m.eval(wo64, wi64), f32([r["f"] for r in cli]))
    for st in m.strategies:
        f, p = m.eval_pdf(wo, wi, strategy=st)
        assert same_bits(p, f32([r["pdf"][st] for r in cli])), st
        f64, p64 = m.eval_pdf(wo64, wi64, strategy=st)
        assert same_bits(f64, f) and same_bits(p64, p), st
        assert same_bits(m.pdf(wo, wi, strategy=st), p), st
        # GGX's vndf and brdf kernels compute f another way (as their
        # samples' f): equal to f32 rounding, not always to the bit.
        assert np.allclose(f, m.eval(wo, wi), rtol=2e-6, atol=0), st


def jitter(rng, a, rel):
    """`a` with each entry moved by `rel` relative, up or down at random."""
    return a * (1 + rel * rng.choice([-1.0, 1.0], a.shape))


def spread(moved, base):
    """How far the reference moves (`moved`: its values at inputs moved by
    their f32 rounding) from `base`: what the f32 inputs leave open."""
    return np.max([np.abs(v - base) for v in moved], axis=0)


@pytest.mark.parametrize("desc", MATERIALS, ids=IDS)
def test_within_1e_4_of_the_scalar_reference(desc):
    """Every row, no quantile: f, pdf and weight within 1e-4 relative of the
    f64 path given the same (f32) inputs, wi within 1e-5, and the same
    validity (but within 1e-5 of the horizon), except by what moving the
    inputs by an f32 rounding (directions 2^-23 relative, uniforms 2^-24)
    moves the reference itself: twice that is allowed, as lobe's Rust tests
    of the batch kernels do."""
    m = lobe.load_dict(desc)
    n = 20000
    wo, u, uc = inputs(n, 3)
    rng = np.random.default_rng(4)
    e = 2.0**-23
    wo64, u64, uc64 = wo.astype(np.float64), u.astype(np.float64), uc.astype(np.float64)
    # Uniforms move by 2^-24 absolute: the f32 grid near 1, where the
    # kernels map u to 2u - 1 (cosine, caps) or 1 - u (brdf).
    moves = [(jitter(rng, wo64, e), np.clip(u64 + 2.0**-24 * rng.choice([-1.0, 1.0], u64.shape), 0, 1 - 2**-53), uc64)
             for _ in range(4)]
    for st in m.strategies:
        s = m.sample(wo, u, uc, strategy=st)
        r = m.sample(wo64, u64, uc64, strategy=st, reference=True)
        near = [m.sample(*mv, strategy=st, reference=True) for mv in moves]
        open_valid = np.any([x.valid != r.valid for x in near], axis=0)
        horizon = np.minimum(np.abs(s.wi[:, 2]), np.abs(r.wi[:, 2])) < 1e-5
        differ = s.valid != r.valid
        assert not np.any(differ & ~open_valid & ~horizon), (st, np.flatnonzero(differ & ~open_valid & ~horizon)[:5])
        both = s.valid & r.valid & ~np.any([~x.valid for x in near], axis=0)
        dwi = spread([x.wi for x in near], r.wi).max(axis=1)
        err = np.abs(s.wi - r.wi).max(axis=1)
        assert np.all((err <= 1e-5 + 2 * dwi)[both]), (st, err[both].max())
        for a in ("pdf", "weight"):
            got, want = getattr(s, a), getattr(r, a)
            d = spread([getattr(x, a) for x in near], want)
            ok = np.abs(got - want) <= 1e-4 * np.abs(want) + 2 * d + 1e-30
            assert np.all(ok[both]), (st, a, np.flatnonzero(~ok & both)[:5])
    # eval and pdf at (wo, wi) pairs: wi drawn by the last strategy (where
    # valid) and from the hemisphere.
    wi = np.where(s.valid[:, None], s.wi, inputs(n, 5)[0])
    wi[: n // 2] = inputs(n // 2, 6)[0]
    wi64 = wi.astype(np.float64)
    pairs = [(jitter(rng, wo64, e), jitter(rng, wi64, e)) for _ in range(4)]
    f, fr = m.eval(wo, wi), m.eval(wo64, wi64, reference=True)
    df = spread([m.eval(a, b, reference=True) for a, b in pairs], fr)
    assert np.all(np.abs(f - fr) <= 1e-4 * fr + 2 * df + 1e-30), np.abs(f - fr).max()
    for st in m.strategies:
        p, pr = m.pdf(wo, wi, strategy=st), m.pdf(wo64, wi64, strategy=st, reference=True)
        dp = spread([m.pdf(a, b, strategy=st, reference=True) for a, b in pairs], pr)
        bad = np.abs(p - pr) > 1e-4 * pr + 2 * dp + 1e-30
        assert not np.any(bad), (st, np.flatnonzero(bad)[:5], p[bad][:3], pr[bad][:3])
        print(f"{desc['type']} {st}: pdf beyond 1e-4 at {np.sum(np.abs(p - pr) > 1e-4 * pr)} of {n} pairs, "
              f"each within what the f32 inputs leave open")
