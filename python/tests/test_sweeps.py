"""lobe.sweep on Dask (issue 46): the grid, determinism across worker
counts, resuming from the Parquet dataset, a worker killed in the middle,
failed tasks, the command line, and bad input."""

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

import lobe
import lobe.sweeps as sw

PHONG = {"type": "phong", "exponent": 40}
GGX = {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3}
#: The columns that are wall time, not numbers the seed fixes.
TIMING = ["time_s", "efficiency", "wall_s"]


def test_the_grid_is_the_product_in_order_and_bad_input_is_refused():
    t = sw.tasks("estimate", {"material": [PHONG, GGX], "theta": [10, 80], "strategy": ["brdf"]})
    assert [(p["material"]["type"], p["theta"]) for p in t] == [
        ("phong", 10), ("phong", 80), ("cook-torrance", 10), ("cook-torrance", 80)
    ]
    assert sw.tasks("albedo", [{"material": GGX, "alpha": 0.5}]) == [{"material": GGX, "alpha": 0.5}]
    # The seed comes from the parameters, not from the order.
    a, b = sw.tasks("estimate", {"material": [PHONG], "theta": [10, 80], "strategy": ["brdf"]})
    assert sw.task_seed("estimate", a) != sw.task_seed("estimate", b)
    assert sw.task_seed("estimate", dict(reversed(list(a.items())))) == sw.task_seed("estimate", a)
    for task, grid, words in [
        ("estimate", {"material": [PHONG], "strategy": ["brdf"], "thetaa": [1]}, ["thetaa", "theta"]),
        ("estimate", {}, ["empty"]),
        ("estimate", {"material": [PHONG], "strategy": []}, ["strategy", "no values"]),
        ("estimate", [], ["empty"]),
        ("estimate", {"material": [PHONG]}, ["strategy"]),
        ("render", {"material": [PHONG]}, ["render", "estimate"]),
        ("estimate", [{"material": PHONG, "strategy": "brdf"}] * 2, ["same task"]),
    ]:
        with pytest.raises(ValueError) as e:
            lobe.sweep(task, grid)
        assert all(w in str(e.value) for w in words), str(e.value)


def test_the_package_works_without_dask_and_sweep_says_what_to_install():
    code = (
        "import sys\n"
        "for m in ('dask', 'distributed', 'pandas', 'pyarrow'): sys.modules[m] = None\n"
        "import lobe\n"
        "t = lobe.estimate({'type': 'phong', 'exponent': 10}, theta=30, strategies=['brdf'], samples=256)\n"
        "assert t['strategies'][0]['name'] == 'brdf'\n"
        "try:\n"
        "    lobe.sweep('estimate', {'material': [{'type': 'phong'}], 'strategy': ['brdf']})\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert "lobe[dask]" in out, out


pd = pytest.importorskip("pandas")
pytest.importorskip("distributed")


def _grid():
    return {
        "material": [PHONG, GGX],
        "theta": [20, 70],
        "strategy": ["uniform", "brdf"],
        "samples": [2048],
    }


def _numbers(df):
    return df.drop(columns=[c for c in TIMING if c in df.columns]).reset_index(drop=True)


def test_one_worker_and_two_give_the_same_numbers_bit_for_bit(tmp_path):
    one = lobe.sweep("estimate", _grid(), workers=1, quiet=True)
    two = lobe.sweep("estimate", _grid(), workers=2, quiet=True, out=tmp_path / "two.parquet")
    assert len(one) == 8 and one.attrs["computed"] == 8 and one["error"].isna().all()
    pd.testing.assert_frame_equal(_numbers(one), _numbers(two), check_exact=True)
    # The parameters are columns, a material as canonical JSON.
    assert set(one["theta"]) == {20, 70} and one["material"][0] == '{"exponent":40,"type":"phong"}'
    # The estimate's own columns, RGB as _r, _g, _b.
    for c in ("mean_r", "stderr_b", "variance", "variance_reduction", "reference_g", "relative_error"):
        assert c in one.columns, c
    # Importance sampling beats uniform sampling on the Phong lobe.
    ph = one[one["material"].str.contains("phong")]
    assert (ph[ph.strategy == "brdf"]["variance"].values < ph[ph.strategy == "uniform"]["variance"].values).all()
    # Same as a direct call with the task's seed.
    p = sw.tasks("estimate", _grid())[0]
    t = lobe.estimate(PHONG, theta=20, strategies=["uniform"], samples=2048, seed=sw.task_seed("estimate", p))
    assert one["mean_r"][0] == t["strategies"][0]["mean"][0]


def test_a_stopped_sweep_resumes_without_redoing_what_was_written(tmp_path):
    out = tmp_path / "run.parquet"
    full = lobe.sweep("estimate", _grid(), workers=2, quiet=True)
    # A process killed after its first rows were written.
    code = (
        "import lobe\n"
        f"lobe.sweep('estimate', {_grid()!r} | {{'samples': [2048, 2049, 2050, 2051, 2052, 2053, 2054, 2055]}}, "
        f"out={str(out)!r}, workers=1, quiet=True, flush_seconds=0)\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", code], start_new_session=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not (out.exists() and any(f.endswith(".parquet") for f in os.listdir(out))):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    written = len(sw._read_done(str(out)))
    assert 0 < written < 64, written
    grid = _grid() | {"samples": [2048, 2049, 2050, 2051, 2052, 2053, 2054, 2055]}
    again = lobe.sweep("estimate", grid, out=out, workers=2, quiet=True)
    assert len(again) == 64 and again.attrs["computed"] == 64 - written
    assert again["task_key"].is_unique
    # A third call has nothing left to do, and the numbers are those of an uninterrupted run.
    third = lobe.sweep("estimate", grid, out=out, workers=2, quiet=True)
    assert third.attrs["computed"] == 0
    pd.testing.assert_frame_equal(_numbers(third), _numbers(again), check_exact=True)
    first = third[third["samples"] == 2048].reset_index(drop=True)
    pd.testing.assert_frame_equal(_numbers(first), _numbers(full), check_exact=True)
    assert "already" in (out / "_sweep.log").read_text()


def test_a_worker_killed_in_the_middle_loses_nothing(tmp_path):
    from distributed import Client, LocalCluster

    grid = {"material": [GGX], "theta": [10, 30, 50, 70], "strategy": ["uniform", "brdf", "vndf"],
            "samples": [20000, 20001, 20002]}
    out = tmp_path / "killed.parquet"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        result = {}
        t = threading.Thread(target=lambda: result.update(df=lobe.sweep(
            "estimate", grid, out=out, scheduler=client, quiet=True, flush_seconds=0)))
        t.start()
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not (out.exists() and any(f.endswith(".parquet") for f in os.listdir(out))):
            time.sleep(0.02)
        pids = client.run(os.getpid)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)
        t.join(300)
    df = result["df"]
    assert len(df) == 36 and df["task_key"].is_unique and df["error"].isna().all()
    assert len(sw._read_done(str(out))) == 36
    alone = lobe.sweep("estimate", grid, workers=2, quiet=True)
    pd.testing.assert_frame_equal(_numbers(df), _numbers(alone), check_exact=True)


def test_a_failed_task_is_a_row_and_the_sweep_goes_on(tmp_path):
    df = lobe.sweep("estimate", {"material": [PHONG], "strategy": ["brdf", "vndf"], "samples": [512]},
                    workers=1, quiet=True, out=tmp_path / "f.parquet")
    ok, bad = df.iloc[0], df.iloc[1]
    assert ok["error"] is None or pd.isna(ok["error"])
    assert "vndf" in bad["error"] and df.attrs["failed"] == 1
    # The failure is not written: a rerun tries it again.
    assert len(sw._read_done(str(tmp_path / "f.parquet"))) == 1


def test_other_tasks_albedo_chi2_and_fit(tmp_path):
    a = lobe.sweep("albedo", {"material": [{"type": "roughconductor", "distribution": "ggx"}], "alpha": [0.5, 1.0],
                              "theta": [0]}, workers=1, quiet=True)
    assert (abs(a["turquin_r"] - 1) < 5e-3).all() and (a["none_r"] < 0.9).all()
    c = lobe.sweep("chi2", {"material": [GGX], "strategy": ["uniform", "vndf"], "theta": [45],
                            "samples": [20000], "seed": [1, 2]}, workers=1, quiet=True)
    # A correct sampler's p-values are uniform: each task passes when its p-value is above the level.
    assert len(c) == 4 and ((0 < c["p_value"]) & (c["p_value"] <= 1)).all()
    assert (c["passed"] == (c["p_value"] > 0.01)).all() and c["passed"].sum() >= 2
    # A fit of a measured file: a MERL table of a glossy lobe in θh (as test_measured.py writes).
    import json

    import numpy as np

    merl = tmp_path / "glossy.binary"
    theta_h = (np.arange(90) / 90.0) ** 2 * np.pi / 2
    table = np.broadcast_to((0.05 + 3.0 * np.cos(theta_h) ** 40)[:, None, None], (90, 90, 180)).ravel()
    with open(merl, "wb") as fh:
        np.array([90, 90, 180], "<i4").tofile(fh)
        np.concatenate([table / s for s in (1 / 1500, 1.15 / 1500, 1.66 / 1500)]).astype("<f8").tofile(fh)
    f = lobe.sweep("fit", {"file": [str(merl)], "distribution": ["ggx", "beckmann"]}, workers=1, quiet=True)
    assert f["error"].isna().all(), f["error"][0]
    fitted = [json.loads(x) for x in f["fit"]]
    assert [x["type"] for x in fitted] == ["cook-torrance"] * 2 and (f["fit_error"] > 0).all()
    assert f["file"][0] == str(merl)


def test_the_command_runs_a_spec_and_refuses_a_bad_one(tmp_path, lobe_exe):
    spec = tmp_path / "s.toml"
    spec.write_text(
        'task = "estimate"\nworkers = 1\n'
        '[grid]\nmaterial = [{type = "phong", exponent = 20}]\ntheta = [30]\nstrategy = ["uniform", "brdf"]\n'
        "samples = [1024]\n"
    )
    env = dict(os.environ, LOBE_PYTHON=sys.executable)
    r = subprocess.run([lobe_exe, "sweep", str(spec), "--out", str(tmp_path / "o.parquet"), "-q"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert "brdf" in r.stdout and "2 tasks, 2 computed" in r.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text('task = "estimate"\nworkerz = 2\n[grid]\nmaterial = ["phong"]\n')
    r = subprocess.run([lobe_exe, "sweep", str(bad)], capture_output=True, text=True, env=env)
    assert r.returncode == 2 and "workerz" in r.stderr, r.stderr


def test_an_unreachable_scheduler_is_an_error_before_any_work():
    t0 = time.monotonic()
    with pytest.raises(ConnectionError) as e:
        lobe.sweep("estimate", {"material": [PHONG], "strategy": ["brdf"]}, scheduler="tcp://127.0.0.1:9", quiet=True)
    assert "tcp://127.0.0.1:9" in str(e.value) and time.monotonic() - t0 < 30
