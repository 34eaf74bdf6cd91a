"""The explorer's views from Python (issue 45: everything a page of ``lobe
explore`` shows is a library call): ``lobe.polar``, ``lobe.lobe_grid``,
``lobe.albedo_curve``, ``lobe.warp_test``, ``lobe.weight_map`` and
``Material.to_toml`` / ``to_python``."""

import ast
import json

import numpy as np
import pytest

import lobe

ROUGH = {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3}
WHITE = {"type": "diffuse", "reflectance": 1.0}
GLASS = {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.2}


def test_polar_shapes_and_the_mirror_peak():
    m = lobe.load_dict(ROUGH)
    p = lobe.polar(m, 40.0)
    assert isinstance(p, lobe.views.Polar) and p.full_circle is False
    assert p.theta.shape == p.fcos.shape == (362,) and p.theta.dtype == np.float64
    assert p.theta[0] == pytest.approx(-np.pi / 2) and p.theta[-1] == pytest.approx(np.pi / 2)
    assert list(p.pdfs) == m.strategies
    assert all(v.shape == (362,) for v in p.pdfs.values())
    # f·|cos θi| of a rough conductor peaks at the mirror direction, θi = −θo.
    peak = np.degrees(p.theta[np.argmax(p.fcos)])
    assert abs(peak + 40.0) < 1.0, peak
    # vndf's pdf follows the lobe: its peak is there too.
    assert abs(np.degrees(p.theta[np.argmax(p.pdfs["vndf"])]) + 40.0) < 2.0
    # A transmitting material goes round the circle: 2·steps + 1 angles.
    g = lobe.polar(GLASS, 30.0, phi_o=20.0, steps=90)
    assert g.full_circle and g.theta.shape == (181,)
    assert g.theta[0] == pytest.approx(-np.pi) and g.theta[-1] == pytest.approx(np.pi)
    # Seen from below (θo in (90, 180]).
    assert lobe.polar(GLASS, 150.0, steps=8).full_circle


def test_a_white_lambertian_lobe_is_cos_over_pi():
    g = lobe.lobe_grid(WHITE, 30.0, n_theta=9, n_phi=12)
    assert isinstance(g, lobe.views.LobeGrid) and not g.sphere
    assert g.theta.shape == (10,) and g.phi.shape == (13,) and g.values.shape == (10, 13)
    assert g.theta[-1] == pytest.approx(np.pi / 2) and g.phi[-1] == pytest.approx(2 * np.pi)
    want = np.broadcast_to((np.cos(g.theta) / np.pi)[:, None], g.values.shape)
    np.testing.assert_allclose(g.values, want, rtol=0, atol=1e-12)
    d = lobe.lobe_grid(lobe.load_dict(ROUGH), 40.0)
    assert d.values.shape == (46, 91)
    s = lobe.lobe_grid(GLASS, 40.0, n_theta=10, n_phi=8)
    assert s.sphere and s.theta[-1] == pytest.approx(np.pi) and s.values.shape == (11, 9)


def test_albedo_curve():
    a = lobe.albedo_curve(WHITE, [0, 30, 60, 85])
    assert a.shape == (4, 3) and a.dtype == np.float64
    np.testing.assert_allclose(a, 1.0, rtol=0, atol=1e-4)
    assert lobe.albedo_curve(WHITE, np.arange(0, 90, 10), phi_deg=45, n=16).shape == (9, 3)
    assert lobe.albedo_curve(WHITE, []).shape == (0, 3)
    # A white rough conductor loses energy between microfacets; a glass
    # (importance carried) keeps R + T ≈ 1 from either side.
    r = lobe.albedo_curve(ROUGH, [0, 60])
    assert np.all((r > 0.8) & (r < 1.0))
    glass = lobe.albedo_curve(GLASS, [30, 150])
    assert np.all((glass > 0.9) & (glass <= 1.0 + 1e-6))


def test_warp_test_of_vndf_passes():
    w = lobe.warp_test(ROUGH, "vndf", 40.0)
    assert isinstance(w, lobe.views.WarpTest) and not w.sphere
    assert w.observed.shape == w.expected.shape == (1, 24, 24)
    assert w.p_value > 1e-3, w
    assert w.dof > 0 and np.isfinite(w.statistic) and w.message is None
    assert w.observed.sum() <= 20000 and abs(w.expected.sum() - w.observed.sum()) < 500
    # Pixels outside the disk hold nothing.
    assert w.observed[0, 0, 0] == 0 and w.expected[0, 0, 0] == 0
    g = lobe.warp_test(GLASS, "vndf", 30.0, samples=5000, res=8, seed=3)
    assert g.sphere and g.observed.shape == (2, 8, 8) and g.p_value > 1e-3
    # The seed is the draws'.
    a = lobe.warp_test(ROUGH, "brdf", 40.0, samples=2000, res=8, seed=1)
    b = lobe.warp_test(ROUGH, "brdf", 40.0, samples=2000, res=8, seed=2)
    assert not np.array_equal(a.observed, b.observed)
    np.testing.assert_array_equal(a.expected, b.expected)


def test_weight_map():
    w = lobe.weight_map({"type": "diffuse", "reflectance": 0.5}, "cosine", 30.0, res=16)
    assert w.shape == (1, 16, 16)
    inside = ~np.isnan(w)
    # NaN exactly at the pixels whose centre is outside the unit disk.
    c = -1 + (np.arange(16) + 0.5) * 2 / 16
    assert np.array_equal(inside[0], (c[None, :] ** 2 + c[:, None] ** 2) < 1)
    np.testing.assert_allclose(w[inside], 0.5, rtol=1e-12)
    # Uniform sampling of a rough conductor: weights vary; vndf's are at most 1 (G1 ≤ 1).
    u = lobe.weight_map(ROUGH, "uniform", 40.0)
    v = lobe.weight_map(ROUGH, "vndf", 40.0)
    assert u.shape == v.shape == (1, 48, 48)
    assert np.nanmax(u) > 1.0 and np.nanmax(v) <= 1.0 + 1e-9
    assert lobe.weight_map(GLASS, "vndf", 40.0, res=8).shape == (2, 8, 8)
    # f = 0 is 0, not NaN: a Phong lobe far from the mirror direction.
    p = lobe.weight_map({"type": "phong", "exponent": 5, "ks": 1.0, "kd": 0.0}, "cosine", 60.0, res=16)
    assert np.any(p[~np.isnan(p)] == 0.0)


def test_the_same_numbers_on_any_number_of_threads():
    m = lobe.load_dict(ROUGH)
    try:
        runs = []
        for n in (1, 2, 3):
            lobe.set_threads(n)
            runs.append(
                (
                    lobe.lobe_grid(m, 40.0, n_theta=20, n_phi=30).values,
                    lobe.albedo_curve(m, [0, 40, 80], n=16),
                    lobe.warp_test(m, "vndf", 40.0, samples=3000, res=8).expected,
                    lobe.weight_map(m, "vndf", 40.0, res=16),
                )
            )
    finally:
        lobe.set_threads(None)
    for r in runs[1:]:
        for a, b in zip(runs[0], r):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("theta", [90, 95, 180, -1, float("nan"), float("inf")])
def test_bad_view_angles_raise(theta):
    for call in (
        lambda: lobe.polar(ROUGH, theta),
        lambda: lobe.lobe_grid(ROUGH, theta),
        lambda: lobe.warp_test(ROUGH, "vndf", theta),
        lambda: lobe.weight_map(ROUGH, "vndf", theta),
    ):
        with pytest.raises(ValueError, match=r"^theta_o .*\[0, 90\)"):
            call()
    with pytest.raises(ValueError, match=r"^thetas_deg\[1\] "):
        lobe.albedo_curve(ROUGH, [10, theta])


def test_view_angles_below_the_surface():
    # Glass and two-sided materials are seen from below, but never edge-on.
    for desc in (GLASS, {"type": "twosided", "bsdf": {"type": "diffuse"}}):
        lobe.polar(desc, 135.0, steps=8)
        lobe.lobe_grid(desc, 180.0, n_theta=2, n_phi=3)
        for bad in (90.0, 180.5, -0.5):
            with pytest.raises(ValueError, match=r"^theta_o .*\(90, 180\]"):
                lobe.polar(desc, bad)
    with pytest.raises(ValueError, match=r"^phi_o "):
        lobe.polar(ROUGH, 30.0, phi_o=float("nan"))
    with pytest.raises(ValueError, match=r"^phi_deg "):
        lobe.albedo_curve(ROUGH, [30.0], phi_deg=float("inf"))


def test_bad_strategies_and_counts_raise():
    with pytest.raises(ValueError, match=r"^strategy `nope`: .*vndf"):
        lobe.warp_test(ROUGH, "nope", 30.0)
    with pytest.raises(ValueError, match=r"^strategy `vndf` does not apply"):
        lobe.weight_map(WHITE, "vndf", 30.0)
    with pytest.raises(ValueError, match=r"^strategy "):
        lobe.warp_test(ROUGH, None, 30.0)
    for call, name in (
        (lambda: lobe.polar(ROUGH, 30.0, steps=0), "steps"),
        (lambda: lobe.lobe_grid(ROUGH, 30.0, n_theta=0), "n_theta"),
        (lambda: lobe.lobe_grid(ROUGH, 30.0, n_phi=-1), "n_phi"),
        (lambda: lobe.albedo_curve(ROUGH, [30.0], n=0), "n"),
        (lambda: lobe.warp_test(ROUGH, "vndf", 30.0, samples=0), "samples"),
        (lambda: lobe.warp_test(ROUGH, "vndf", 30.0, res=0), "res"),
        (lambda: lobe.warp_test(ROUGH, "vndf", 30.0, seed=-1), "seed"),
        (lambda: lobe.weight_map(ROUGH, "vndf", 30.0, res=0), "res"),
        (lambda: lobe.albedo_curve(ROUGH, [[30.0]]), "thetas_deg"),
    ):
        with pytest.raises(ValueError, match=rf"^{name}[ :]"):
            call()


DESCRIPTIONS = [
    ROUGH,
    {"type": "twosided", "bsdf": {"type": "roughconductor", "alpha": 0.3, "material": "Au"}},
    {"type": "cook-torrance", "alpha": 0.2, "kd": [0.1, 0.2, 0.3], "fresnel": {"type": "schlick", "f0": 0.9}},
    {"type": "roughdielectric", "int_ior": "bk7", "ext_ior": 1, "alpha": 0.2},
    {"type": "phong", "exponent": 100, "normalized": True},
]


@pytest.mark.parametrize("desc", DESCRIPTIONS)
def test_to_python_and_to_toml_read_back(desc):
    m = lobe.load_dict(desc)
    want = json.loads(m.description)
    py = m.to_python()
    assert ast.literal_eval(py) == want
    assert lobe.load_dict(ast.literal_eval(py)).to_python() == py
    tomllib = pytest.importorskip("tomllib")
    assert tomllib.loads(m.to_toml()) == want


def test_to_python_writes_python_literals():
    py = lobe.load_dict({"type": "phong", "exponent": 10, "normalized": False}).to_python()
    assert "False" in py and "false" not in py
    assert py.startswith('{"type": "phong"')
