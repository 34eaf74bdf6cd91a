"""lobe.furnace: the white furnace from Python, the same library call as
``lobe furnace --json`` (issue 43)."""

import json
import subprocess

import pytest

import lobe


def test_compensation_fills_the_furnace_and_the_walk_agrees():
    t = lobe.furnace(
        {"type": "roughconductor", "distribution": "ggx"}, theta=[0, 60], alpha=[0.5, 1.0], walks=4000, seed=3
    )
    assert t["model"] == "roughconductor" and t["walks"] == 4000
    assert [(r["alpha"], r["theta"]) for r in t["rows"]] == [(0.5, 0), (0.5, 60), (1.0, 0), (1.0, 60)]
    for r in t["rows"]:
        for kind in ("kulla-conty", "turquin"):
            assert all(abs(v - 1.0) < 5e-3 for v in r[kind]), (kind, r)
        # A white conductor's walk loses nothing.
        assert r["walk"] == [1.0, 1.0, 1.0] and r["walk_std_error"] == [0.0, 0.0, 0.0]
        assert r["none"][0] < 0.9
    # At α 1, θo 0 half the visible normals reflect below the horizon: 1 − ln 2.
    assert abs(t["rows"][2]["none"][0] - 0.3069) < 1e-3


def test_glass_and_plastic_are_compensated_both_ways():
    for desc in (
        {"type": "roughdielectric", "distribution": "ggx"},
        {"type": "roughplastic", "distribution": "ggx", "diffuse_reflectance": 1.0},
    ):
        t = lobe.furnace(desc, theta=[45], alpha=[0.5], walks=0)
        (r,) = t["rows"]
        assert r["walk"] is None and r["none"][0] < 0.95
        for kind in ("kulla-conty", "turquin"):
            assert abs(r[kind][0] - 1.0) < 1e-2, (desc, kind, r)


def test_the_same_numbers_as_the_command(lobe_exe):
    desc = {"type": "cook-torrance", "alpha": 0.3, "fresnel": {"type": "conductor"}}
    t = lobe.furnace(desc, theta=[30], alpha=[0.3, 0.8], walks=500, seed=7)
    out = subprocess.run(
        [lobe_exe, "furnace", "-q", "--json", "-m", json.dumps(desc), "--theta", "30", "--alpha", "0.3,0.8",
         "--walks", "500", "--seed", "7"],
        check=True, capture_output=True, text=True,
    ).stdout
    assert json.loads(out) == t


@pytest.mark.parametrize(
    "desc, kwargs, words",
    [
        ({"type": "phong"}, {}, ["type"]),
        ({"type": "roughconductor"}, {"theta": [95]}, ["theta", "89.9"]),
        ({"type": "roughconductor"}, {"alpha": [5.0]}, ["alpha"]),
        ({"type": "roughconductor"}, {"walks": -1}, ["walks"]),
        ({"type": "roughplastic", "int_ior": 1.0, "ext_ior": 1.33}, {}, ["multiscatter", "int_ior"]),
    ],
)
def test_bad_input_raises_naming_the_field(desc, kwargs, words):
    with pytest.raises(ValueError) as e:
        lobe.furnace(desc, walks=kwargs.pop("walks", 0), **kwargs)
    assert all(w in str(e.value) for w in words), str(e.value)
