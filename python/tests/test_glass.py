"""Glass, metal and plastic from Python (issue 42): Mitsuba 3's plugin
dicts load as they are, evaluate and sample over the whole sphere, and bad
input raises ValueError naming the field."""

import numpy as np
import pytest

import lobe


def sphere(n, seed=3):
    rng = np.random.default_rng(seed)
    z = 2 * rng.random(n) - 1
    s = np.sqrt(1 - z * z)
    p = 2 * np.pi * rng.random(n)
    return np.stack([s * np.cos(p), s * np.sin(p), z], axis=1)


def test_mitsuba_dicts_load_with_their_defaults():
    assert lobe.load_dict({"type": "dielectric"}).model == "dielectric"
    assert lobe.load_dict({"type": "diffuse"}).model == "lambert"
    assert lobe.load_dict({"type": "roughconductor", "material": "Au"}).model == "cook-torrance"
    m = lobe.load_dict({"type": "twosided", "material": {"type": "roughplastic", "distribution": "ggx"}})
    assert m.model == "roughplastic"
    rgb = lobe.load_dict({"type": "plastic", "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.4, 0.6]}})
    assert rgb.strategies == ["brdf"]


def test_rough_glass_transmits_and_samples_below():
    m = lobe.load_dict({"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3})
    n = 4000
    wo = np.tile([0.6, 0.0, 0.8], (n, 1))
    rng = np.random.default_rng(5)
    s = m.sample(wo, rng.random((n, 2)), rng.random(n), strategy="vndf")
    below = s.valid & (s.wi[:, 2] < 0)
    assert below.mean() > 0.8  # about 1 − F of the light is refracted
    f, p = m.eval_pdf(wo[below], s.wi[below], strategy="vndf")
    # The SIMD kernels (f32): the pdf recomputed from the f32 direction
    # agrees with the sample's to f32's precision, as the batch tests ask.
    assert np.all(f[:, 0] > 0) and np.allclose(p, s.pdf[below], rtol=1e-4)
    r = m.eval_pdf(wo[below], s.wi[below], strategy="vndf", reference=True)[1]
    assert np.allclose(r, s.pdf[below], rtol=1e-4)
    # Seen from inside too.
    inside = np.tile([0.3, 0.0, -np.sqrt(1 - 0.09)], (n, 1))
    assert np.any(m.eval(inside, sphere(n))[:, 0] > 0)


def test_smooth_glass_has_only_its_deltas():
    m = lobe.load_dict({"type": "dielectric", "int_ior": "water"})
    wo = np.tile([0.0, 0.6, 0.8], (1000, 1))
    rng = np.random.default_rng(2)
    s = m.sample(wo, rng.random((1000, 2)), rng.random(1000))
    assert np.all(s.valid)
    assert np.allclose(m.eval(wo, s.wi), 0) and np.allclose(m.pdf(wo, s.wi), 0)
    with pytest.raises(ValueError, match="delta"):
        m.sample(wo, rng.random((1000, 2)), strategy="uniform")


@pytest.mark.parametrize(
    "desc, field",
    [
        ({"type": "dielectric", "int_ior": -1.0}, "int_ior"),
        ({"type": "dielectric", "int_ior": "glass"}, "int_ior"),
        ({"type": "conductor", "material": "Gold"}, "material"),
        ({"type": "roughdielectric", "sample_visible": False}, "sample_visible"),
        ({"type": "twosided", "bsdf": {"type": "dielectric"}}, "bsdf"),
        ({"type": "roughplastic", "alpha_u": 0.1, "alpha_v": 0.2}, "alpha_u"),
    ],
)
def test_bad_input_names_the_field(desc, field):
    with pytest.raises(ValueError, match=field):
        lobe.load_dict(desc)


def test_rough_glass_runs_on_the_simd_kernels_and_matches_the_f64_path():
    m = lobe.load_dict({"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3})
    assert all(m.batched(s) for s in m.strategies), m.strategies
    beckmann = lobe.load_dict({"type": "roughdielectric", "alpha": 0.3})
    assert all(beckmann.batched(s) for s in beckmann.strategies), beckmann.strategies
    wo = sphere(2000, seed=9)
    wo = wo[np.abs(wo[:, 2]) > 0.05]
    n = len(wo)
    rng = np.random.default_rng(11)
    u, uc = rng.random((n, 2)), rng.random(n)
    fast = m.sample(wo, u, uc, strategy="vndf")
    ref = m.sample(wo, u, uc, strategy="vndf", reference=True)
    both = fast.valid & ref.valid
    assert both.mean() > 0.85 and (fast.valid != ref.valid).mean() < 0.01
    assert np.abs(fast.wi[both] - ref.wi[both]).max() < 1e-4
    assert (fast.wi[both, 2] * wo[both, 2] < 0).mean() > 0.5  # mostly refracted, from both sides
    close = np.isclose(fast.weight[both], ref.weight[both], rtol=1e-3).all(axis=1)
    assert close.mean() > 0.99


@pytest.mark.parametrize(
    "desc",
    [
        {"type": "roughplastic", "distribution": "ggx", "alpha": 0.3, "diffuse_reflectance": [0.8, 0.3, 0.1]},
        {"type": "roughplastic", "distribution": "beckmann", "alpha": 0.2, "multiscatter": "turquin"},
        {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.5, "multiscatter": "turquin", "kd": 0.2},
    ],
)
def test_rough_plastic_and_turquin_run_on_the_simd_kernels_and_match_the_f64_path(desc):
    m = lobe.load_dict(desc)
    assert all(m.batched(s) for s in m.strategies), m.strategies
    wo = sphere(4000, seed=5)
    wo = wo[wo[:, 2] > 0.05]
    n = len(wo)
    rng = np.random.default_rng(12)
    u, uc = rng.random((n, 2)), rng.random(n)
    for strategy in ("brdf", "vndf"):
        fast = m.sample(wo, u, uc, strategy=strategy)
        ref = m.sample(wo, u, uc, strategy=strategy, reference=True)
        both = fast.valid & ref.valid
        assert both.mean() > 0.5 and (fast.valid != ref.valid).mean() < 0.01
        assert np.abs(fast.wi[both] - ref.wi[both]).max() < 1e-4
        assert np.isclose(fast.pdf[both], ref.pdf[both], rtol=1e-3).mean() > 0.99
        close = np.isclose(fast.weight[both], ref.weight[both], rtol=1e-3).all(axis=1)
        assert close.mean() > 0.99
        f, pdf = m.eval_pdf(wo, ref.wi, strategy=strategy)
        f_ref, pdf_ref = m.eval_pdf(wo, ref.wi, strategy=strategy, reference=True)
        assert np.isclose(f, f_ref, rtol=1e-3, atol=1e-6).all(axis=1).mean() > 0.99
        assert np.isclose(pdf, pdf_ref, rtol=1e-3, atol=1e-6).mean() > 0.99
