"""A measured material from Python: a MERL table written here with NumPy
(a glossy lobe in θh, the same in every channel), loaded by path, its
strategies chi-square tested, the batch path against the reference, and
bad files refused with the file named."""

import numpy as np
import pytest

import lobe
import lobe.chi2 as chi2

SCALE = (1 / 1500, 1.15 / 1500, 1.66 / 1500)  # MERL's channel scales
THETA_H = (np.arange(90) / 90.0) ** 2 * np.pi / 2  # each θh entry's start


def lobe_value(theta_h):
    return 0.05 + 3.0 * np.cos(theta_h) ** 40


@pytest.fixture(scope="module")
def merl(tmp_path_factory):
    path = tmp_path_factory.mktemp("merl") / "glossy.binary"
    table = np.broadcast_to(lobe_value(THETA_H)[:, None, None], (90, 90, 180)).ravel()
    with open(path, "wb") as f:
        np.array([90, 90, 180], "<i4").tofile(f)
        np.concatenate([table / s for s in SCALE]).astype("<f8").tofile(f)
    return str(path)


def test_loads_and_evaluates_the_table(merl):
    m = lobe.load_dict({"type": "measured", "path": merl})
    assert m.model == "measured" and m.strategies == ["uniform", "cosine", "brdf"]
    assert all(m.batched(s) for s in m.strategies)
    # At normal incidence and reflection θh = θd = 0: the first entry, in
    # every channel (the scales undone). Nearest lookup: the entry each
    # half vector falls in.
    assert np.array_equal(m.eval([0, 0, 1], [[0, 0, 1]]), np.float32(lobe_value(0.0)) * np.ones((1, 3), np.float32))
    wo = np.array([[np.sin(0.5), 0, np.cos(0.5)]] * 3)
    wi = np.array([[-np.sin(0.5), 0, np.cos(0.5)], [np.sin(0.2), 0, np.cos(0.2)], [0, 0.6, 0.8]])
    h = (wo + wi) / np.linalg.norm(wo + wi, axis=1, keepdims=True)
    idx = np.minimum((np.sqrt(np.arccos(h[:, 2]) / (np.pi / 2)) * 90).astype(int), 89)
    f = m.eval(wo, wi)
    assert np.allclose(f[:, 0], lobe_value(THETA_H[idx]), rtol=1e-6), (f[:, 0], lobe_value(THETA_H[idx]))


@pytest.mark.parametrize("strategy", ["uniform", "cosine", "brdf"])
def test_every_strategy_passes_chi2(merl, strategy):
    m = lobe.load_dict({"type": "measured", "path": merl})
    ad = chi2.BSDFAdapter(m, strategy, [np.sin(0.7), 0.0, np.cos(0.7)])
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_count=200_000, res=(30, 60))
    assert t.run(0.01, test_count=3), t.messages


def test_linear_interpolation_and_the_batch_path(merl):
    m = lobe.load_dict({"type": "measured", "path": merl, "interpolation": "linear"})
    rng = np.random.default_rng(2)
    wo = np.tile([0.6, 0.0, 0.8], (50_000, 1))
    u = rng.random((50_000, 2)).astype(np.float32)
    s = m.sample(wo, u, strategy="brdf")
    r = m.sample(wo, u.astype(np.float64), strategy="brdf", reference=True)
    assert np.array_equal(s.valid, r.valid)
    assert np.allclose(s.wi, r.wi, atol=1e-5) and np.allclose(s.pdf, r.pdf, rtol=1e-4)
    f = m.eval(wo, s.wi)[s.valid]
    assert f.min() >= 0.05 * (1 - 1e-6) and f.max() <= 3.05 * (1 + 1e-6)


def test_bad_files_are_named(tmp_path, merl):
    missing = str(tmp_path / "none.binary")
    with pytest.raises(ValueError, match="none.binary"):
        lobe.load_dict({"type": "measured", "path": missing})
    short = tmp_path / "short.binary"
    with open(merl, "rb") as f:
        short.write_bytes(f.read(1000))
    with pytest.raises(ValueError, match="short.binary"):
        lobe.load_dict({"type": "measured", "path": str(short)})
    with pytest.raises(ValueError, match="interpolation"):
        lobe.load_dict({"type": "measured", "path": merl, "interpolation": "cubic"})
