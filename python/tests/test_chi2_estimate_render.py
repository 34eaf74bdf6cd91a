"""lobe.chi2, lobe.estimate and lobe.render."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import lobe
import lobe.chi2 as chi2

GGX = {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2}


@pytest.mark.parametrize("strategy", lobe.load_dict(GGX).strategies)
def test_every_ggx_strategy_passes(strategy):
    m = lobe.load_dict(GGX)
    wo = [np.sin(0.8), 0.0, np.cos(0.8)]
    ad = chi2.BSDFAdapter(m, strategy, wo)
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_count=200_000, res=(40, 80))
    assert t.run(0.01, test_count=6), t.messages
    assert t.histogram.shape == (40, 80) and t.pdf.shape == (40, 80)
    assert abs(t.histogram.sum() + t.result["lost_observed"] - 200_000) < 1e-9


def test_two_lobes_with_uc():
    m = lobe.load_dict({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3, "kd": 0.4})
    ad = chi2.BSDFAdapter(m, "vndf", [0.3, 0.0, np.sqrt(1 - 0.09)])
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_dim=3, sample_count=200_000, res=30)
    assert t.run(), t.messages
    # Two uniforms cannot choose the lobe: an error that says what to do,
    # not a wrongly failed test.
    t2 = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_count=1000, res=30)
    with pytest.raises(ValueError, match="sample_dim=3"):
        t2.run()


def test_a_wrong_pdf_fails():
    m = lobe.load_dict(GGX)
    ad = chi2.BSDFAdapter(m, "vndf", [0.6, 0.0, 0.8])
    # The pdf of the brdf strategy against vndf's samples.
    wrong = chi2.BSDFAdapter(m, "brdf", [0.6, 0.0, 0.8])
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, wrong.pdf, sample_count=200_000, res=30)
    assert not t.run(), t.messages
    # A pdf 3% too narrow in a cosine sampler.
    def cos_sample(u):
        r, phi = np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
        return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u[:, 0])], axis=1)
    def pdf(w, k=1.0):
        return np.where(w[:, 2] > 0, (k + 1) / (2 * np.pi) * np.maximum(w[:, 2], 0) ** k, 0.0)
    ok = chi2.ChiSquareTest(chi2.SphericalDomain(), cos_sample, pdf, sample_count=1_000_000, res=50)
    assert ok.run(), ok.messages
    bad = chi2.ChiSquareTest(chi2.SphericalDomain(), cos_sample, lambda w: pdf(w, 1.03), sample_count=1_000_000, res=50)
    assert not bad.run(), bad.messages


def test_planar_domain():
    def sample(u):
        return np.stack([u[:, 0] ** 0.5, u[:, 1]], axis=1) * 2 - 1  # x density ∝ (x + 1)
    def pdf(p):
        return np.where(np.all(np.abs(p) <= 1, axis=1), (p[:, 0] + 1) / 4, 0.0)
    t = chi2.ChiSquareTest(chi2.PlanarDomain(), sample, pdf, sample_count=300_000, res=30)
    assert t.run(), t.messages
    u = chi2.ChiSquareTest(chi2.PlanarDomain(), sample, lambda p: np.full(len(p), 0.25), sample_count=300_000, res=30)
    assert not u.run()


def test_the_rust_harness_runs_the_statistics():
    assert lobe.sidak(0.01, 1) == pytest.approx(0.01)
    assert lobe.sidak(0.01, 10) == pytest.approx(1 - 0.99 ** 0.1)
    bad = chi2.ChiSquareTest(chi2.SphericalDomain(), lambda u: np.tile([0.0, 0.0, 2.0], (len(u), 1)),
                             lambda w: np.full(len(w), 1 / (4 * np.pi)), sample_count=1000, res=10)
    assert not bad.run()
    assert "not finite unit vectors" in bad.messages


def test_chi2_is_fast_enough_for_ci():
    import time
    m = lobe.load_dict(GGX)
    ad = chi2.BSDFAdapter(m, "vndf", [0.6, 0.0, 0.8])
    t0 = time.perf_counter()
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_count=1_000_000, res=(100, 100))
    assert t.run(), t.messages
    # Informational: the issue asks for a few seconds (timed tests are no speed claims).
    print(f"chi2 1e6 samples at 100x100: {time.perf_counter() - t0:.2f} s")


def test_estimate_returns_the_cli_table(lobe_exe):
    t = lobe.estimate({"type": "phong", "exponent": 50}, theta=40, light="beam:16:1,1,0",
                      strategies=["uniform", "brdf", "mis"], samples=20000, seed=3)
    assert [r["name"] for r in t["strategies"]] == ["uniform", "brdf", "mis"]
    for key in ("reference", "reference_method", "sequence", "stderr_method", "uniform_variance"):
        assert key in t
    ref = t["reference"][0]
    for r in t["strategies"]:
        assert abs(r["mean"][0] - ref) < 6 * r["stderr"][0] + 1e-12
        assert r["stderr_reliable"] == (r["variance_rel_stderr"] <= 0.15)
    # Phong's lobe misses most of the beam, so brdf sampling's weights are
    # heavy-tailed here and its standard error is flagged; uniform's is not.
    flags = {r["name"]: r["stderr_reliable"] for r in t["strategies"]}
    assert flags["uniform"] is True and flags["brdf"] is False
    with pytest.raises(ValueError, match="does not apply"):
        lobe.estimate({"type": "phong"}, strategies=["vndf"], samples=100)
    with pytest.raises(ValueError, match="unknown light"):
        lobe.estimate({"type": "phong"}, light="lamp", samples=100)
    # The same numbers as `lobe estimate --json` where the binary is built.
    out = subprocess.run([lobe_exe, "estimate", "--material", '{"type":"phong","exponent":50}', "--theta", "40",
                          "--light", "beam:16:1,1,0", "--strategy", "uniform,brdf,mis", "--samples", "20000",
                          "--seed", "3", "--json", "--quiet"], check=True, capture_output=True, text=True).stdout
    cli = json.loads(out)
    assert cli["reference"] == t["reference"]
    for a, b in zip(cli["strategies"], t["strategies"]):
        assert a["mean"] == b["mean"] and a["variance"] == b["variance"]
        assert a["stderr_reliable"] == b["stderr_reliable"]


def test_render_a_tiny_scene():
    scene = {
        "camera": {"origin": [0, 0, 4], "target": [0, 0, 0], "width": 8, "height": 6},
        "environment": {"path": "sky"},
        "object": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                    "material": {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3}}],
    }
    img = lobe.render(scene, spp=4, strategy="mis", seed=1)
    assert img.shape == (6, 8, 3) and img.dtype == np.float32
    assert np.all(np.isfinite(img)) and img.max() > 0
    again = lobe.render(scene, spp=4, strategy="mis", seed=1, threads=1)
    assert np.array_equal(img, again)
    with pytest.raises(ValueError, match="strategy"):
        lobe.render(scene, strategy="nope")
    with pytest.raises(ValueError):
        lobe.render({"camera": {"width": 0}})
    with pytest.raises(ValueError, match="cannot read"):
        lobe.render("/nonexistent/scene.toml")
    # Samples allocated by each pixel's noise (the default): the same shape,
    # finite, the same for any thread count; uniform spp differs; the
    # scene's [render] table can ask too.
    v = lobe.render(scene, spp=16, seed=1, spp_allocation="variance")
    assert v.shape == (6, 8, 3) and np.all(np.isfinite(v))
    assert np.array_equal(v, lobe.render(scene, spp=16, seed=1, threads=1))
    u = lobe.render(scene, spp=16, seed=1, spp_allocation="uniform")
    assert np.all(np.isfinite(u)) and not np.array_equal(v, u)
    in_table = lobe.render({**scene, "render": {"spp_allocation": "uniform"}}, spp=16, seed=1)
    assert np.array_equal(u, in_table)
    with pytest.raises(ValueError, match="spp_allocation: unknown spp allocation `even`"):
        lobe.render(scene, spp_allocation="even")


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to oneself is POSIX")
def test_ctrl_c_stops_a_render():
    """Ctrl-C (SIGINT) during lobe.render raises KeyboardInterrupt within a
    second or so, instead of after the whole render (about a minute here)."""
    import signal
    import threading
    import time

    scene = {
        "camera": {"origin": [0, 0, 4], "target": [0, 0, 0], "width": 64, "height": 48},
        "environment": {"path": "sky"},
        "object": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                    "material": {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3}}],
    }
    # Python's own Ctrl-C handler, whatever this process inherited: a
    # process started in the background by a non-interactive shell (a CI
    # runner's `cmd &`) begins with SIGINT ignored, and Python then installs
    # no handler, so the signal would never arrive.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            lobe.render(scene, spp=1 << 18, seed=1)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    elapsed = time.monotonic() - t0
    assert elapsed < 10, f"the render went on for {elapsed:.1f} s after Ctrl-C"
    # The package works afterwards.
    assert lobe.render(scene, spp=1, seed=1).shape == (48, 64, 3)


def test_the_lecture_example_runs():
    """examples/lecture_comparison.py (without its matplotlib plot): every
    strategy's estimate prints, and importance sampling has less variance
    than uniform sampling for each model."""
    root = os.path.join(os.path.dirname(__file__), "..", "..")
    script = os.path.join(root, "examples", "lecture_comparison.py")
    r = subprocess.run([sys.executable, script, "--samples", "20000"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    blocks = r.stdout.split("reference")
    assert len(blocks) == 4, r.stdout
    for block in blocks[1:]:
        var = {
            line.split()[0]: float(line.split("variance")[1])
            for line in block.splitlines()
            if "variance" in line
        }
        assert var["brdf"] < var["uniform"], r.stdout
