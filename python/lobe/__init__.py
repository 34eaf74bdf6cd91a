"""lobe: BRDFs and their importance samplers, from NumPy.

Conventions (everywhere in this package): the local shading frame, +z the
surface normal; ``wo`` points toward the viewer and ``wi`` toward the light,
both unit vectors pointing away from the surface; ``eval`` is f_r WITHOUT the
cosine; pdfs are densities in solid angle; ``weight = f·cos θi / pdf`` (the
cosine included). Directions are (N, 3) arrays, uniforms (N, 2), scalars
(N,); float32 or float64, C- or F-ordered, or any array-like.

The array calls run on lobe's batch SIMD kernels where they cover the
material and strategy (``Material.batched``) and on the scalar f64 path
otherwise, with the GIL released and the work split over threads in fixed
blocks (the results do not depend on the thread count, ``set_threads``).
The memory of large result arrays that died is kept for the next call of
the same size (``set_cache_limit``, ``cache_info``, ``clear_cache``), so
that fresh results cost no page faults.

>>> import lobe, numpy as np
>>> m = lobe.load_dict({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2})
>>> m.strategies
['uniform', 'cosine', 'brdf', 'vndf', 'spherical-caps', 'bounded-vndf']
>>> s = m.sample([0.6, 0.0, 0.8], np.random.default_rng(0).random((4, 2)), strategy="vndf")
>>> f, pdf = m.eval_pdf([0.6, 0.0, 0.8], s.wi, strategy="vndf")
>>> bool(np.allclose(pdf, s.pdf, rtol=1e-4))
True
"""

from __future__ import annotations

# The modules lobe uses under private names, and the typing names for the
# annotations (strings here) only where a type checker reads them: ``dir(lobe)``
# shows lobe's own names (``__dir__`` below).
import json as _json
import os as _os
from collections.abc import Mapping as _Mapping
import typing as _typing

import numpy as _np

from . import _lobe

if _typing.TYPE_CHECKING:
    import os
    from collections.abc import Mapping
    from typing import Any, Sequence

    import numpy as np
from ._lobe import (
    Material,
    SampleResult,
    cache_info,
    clear_cache,
    get_threads,
    set_cache_limit,
    set_threads,
    sidak,
    simd_level,
)

__all__ = [
    "Material",
    "SampleResult",
    "load_dict",
    "estimate",
    "furnace",
    "fit",
    "sweep",
    "render",
    "polar",
    "lobe_grid",
    "albedo_curve",
    "warp_test",
    "weight_map",
    "set_threads",
    "get_threads",
    "simd_level",
    "set_cache_limit",
    "cache_info",
    "clear_cache",
    "sidak",
    "chi2",
]

#: The package's version: the Rust crates' (the workspace's ``version``),
#: as the compiled module was built with it.
__version__: str = _lobe.__version__


def __dir__() -> list[str]:
    """lobe's own names: ``__all__`` and the module's dunders (not the
    modules it imports)."""
    return sorted(set(__all__) | {n for n in globals() if n.startswith("__") and n.endswith("__")})


def _jsonable(x: Any) -> Any:
    if isinstance(x, _np.generic):
        return x.item()
    if isinstance(x, _np.ndarray):
        return x.tolist()
    raise ValueError(f"material: {x!r} ({type(x).__name__}) is not a number, string, list or dict")


def _check_finite(v: Any, path: str) -> None:
    """Non-finite numbers are not JSON: name the field instead."""
    if isinstance(v, _Mapping):
        for k, x in v.items():
            _check_finite(x, f"{path}.{k}" if path else str(k))
    elif isinstance(v, (list, tuple, _np.ndarray)):
        for x in (v.tolist() if isinstance(v, _np.ndarray) else v):
            _check_finite(x, path)
    elif isinstance(v, (float, _np.floating)) and not _np.isfinite(v):
        raise ValueError(f"material: field `{path}`: {v} is not a finite number")


def load_dict(desc: Mapping[str, Any]) -> Material:
    """A material from a dict with the keys of ``lobe --material``.

    lobe's models (``lambert``, ``phong``, ``blinn-phong``,
    ``cook-torrance``, ``measured``) and the dicts a Mitsuba 3 user writes
    for ``mi.load_dict``, with Mitsuba's parameter names and defaults:
    ``diffuse``, ``conductor``, ``roughconductor``, ``dielectric``,
    ``thindielectric``, ``roughdielectric``, ``plastic``, ``roughplastic``
    and ``twosided`` (one nested material under ``bsdf`` or ``material``).
    Colours are a number, ``[r, g, b]`` or ``{"type": "rgb", "value": ...}``;
    ``int_ior``/``ext_ior`` a number or one of Mitsuba's names (``bk7``,
    ``water``, ``air``, ``diamond``, ...); a conductor's ``material`` one of
    Mitsuba's names (``Au``, ``Ag``, ``Cu``, ``Al``, ``Cr``, ...) with the
    RGB (eta, k) of its RGB variants. ``lobe eval --help`` lists every key,
    range and default.

    A bad key or value raises ``ValueError`` naming the field, with the CLI's
    message. The material's conventions: local frame, +z the normal, wo
    toward the viewer, eval without the cosine.

    >>> import lobe
    >>> lobe.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha": 0.2}).model
    'cook-torrance'
    >>> lobe.load_dict({"type": "phong", "exponnt": 3})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: material: field `exponnt`: unknown field `exponnt`, expected one of `type`, ...
    """
    if not isinstance(desc, _Mapping):
        raise TypeError(f"load_dict: expected a dict, got {type(desc).__name__}")
    _check_finite(desc, "")
    return _lobe._load_json(_json.dumps(dict(desc), default=_jsonable))


def _material(m: Material | Mapping[str, Any]) -> Material:
    return m if isinstance(m, Material) else load_dict(m)


def estimate(
    material: Material | Mapping[str, Any],
    wo: Sequence[float] | None = None,
    light: str = "constant",
    strategies: Sequence[str] | str = "all",
    samples: int = 65536,
    sequence: str = "independent",
    seed: int = 1,
    *,
    theta: float | None = None,
    replicas: int = 16,
    mis_bsdf: str | None = None,
    mis_samples: tuple[int, int] = (1, 1),
    normal: Sequence[float] = (0.0, 1.0, 0.0),
    tangent: Sequence[float] = (1.0, 0.0, 0.0),
) -> dict[str, Any]:
    """Estimate L_o(wo) = ∫ f_r(wo, wi) L_i(wi) cos θi dωi at one shading point
    with each strategy against a quadrature reference: what ``lobe estimate
    --json`` prints, as Python objects (the same library call).

    ``wo``: the view direction in the local frame (+z the normal, toward the
    viewer; normalized), or ``theta`` in degrees (default 30°). ``light`` in
    the CLI's syntax: ``constant[:V]``, ``beam[:K[:X,Y,Z[:V]]]`` (a world
    direction; ``normal``/``tangent`` give the frame, default normal +Y),
    ``sky[:ELEVATION[:AZIMUTH]]``, or an ``.hdr``/``.exr`` map.
    ``strategies``: ``"all"`` or names (BSDF strategies, ``light``, ``mis``
    (adaptive: a pilot gives each sample's draws to BSDF sampling, the
    balance heuristic or light sampling), ``mis-balance``, ``mis-power``,
    ``mis-one``, ``mis-power-one``). ``sequence``:
    ``independent``, ``stratified`` or ``sobol``. Each row's ``mean`` is the
    estimate with the cosine included; its ``stderr_reliable`` is false when
    the sample's own tail says the standard error is not to be trusted
    (``variance_rel_stderr``, the variance's estimated relative standard
    error from the sample kurtosis, above 0.15: heavy-tailed weights, as
    BSDF sampling under a sun; docs/statistics.md).

    >>> import lobe
    >>> t = lobe.estimate({"type": "phong", "exponent": 100}, theta=30, strategies=["uniform", "brdf"], samples=4096)
    >>> [r["name"] for r in t["strategies"]]
    ['uniform', 'brdf']
    >>> abs(t["strategies"][1]["mean"][0] - t["reference"][0]) < 0.01
    True
    """
    m = _material(material)
    for name, v in (("samples", samples), ("seed", seed), ("replicas", replicas)):
        if int(v) < 0:
            raise ValueError(f"{name} {v}: must be >= 0")
    if len(mis_samples) != 2:
        raise ValueError(f"mis_samples {mis_samples!r}: expected (BSDF samples, light samples)")
    ms = (int(mis_samples[0]), int(mis_samples[1]))
    names = [strategies] if isinstance(strategies, str) else list(strategies)
    if not all(isinstance(s, str) for s in names):
        raise ValueError("strategies: expected names (strings)")
    text = _lobe._estimate_json(
        m, None if wo is None else [float(x) for x in wo], None if theta is None else float(theta), str(light), list(normal), list(tangent), names, int(samples),
        str(sequence), int(seed), int(replicas), mis_bsdf, ms,
    )
    return _json.loads(text)


def furnace(
    material: Material | Mapping[str, Any],
    theta: Sequence[float] | None = None,
    alpha: Sequence[float] | None = None,
    walks: int = 100_000,
    seed: int = 1,
) -> dict[str, Any]:
    """The white furnace of a microfacet material (``cook-torrance``,
    ``roughconductor``, ``roughdielectric``: R + T in importance mode, or
    ``roughplastic``): its directional albedo ∫ f |cos θi| dωi under light 1
    from every direction, per RGB channel, for each ``theta`` (degrees, θo;
    default 0 to 85 by 5, and 89) and ``alpha`` (default 0.05 to 1), without
    energy compensation (``"none"``, Mitsuba's lobe), with each kind
    (``"kulla-conty"``, ``"turquin"``), and
    by Heitz et al.'s random walk on the microsurface (``"walk"`` and
    ``"walk_std_error"``, the mean of ``walks`` walks per cell; None with
    ``walks=0`` or for a plastic). The material's ``alpha`` and
    ``multiscatter`` are replaced by each cell's. What ``lobe furnace
    --json`` prints, as Python objects (the same library call); the numbers
    do not depend on the thread count.

    >>> import lobe
    >>> t = lobe.furnace({"type": "roughconductor", "distribution": "ggx"}, theta=[0], alpha=[1.0], walks=0)
    >>> row = t["rows"][0]
    >>> round(row["none"][0], 3), round(row["turquin"][0], 2)
    (0.307, 1.0)
    """
    m = _material(material)
    for name, v in (("walks", walks), ("seed", seed)):
        if int(v) < 0:
            raise ValueError(f"{name} {v}: must be >= 0")
    grid = lambda xs: None if xs is None else [float(x) for x in xs]  # noqa: E731
    return _json.loads(_lobe._furnace_json(m, grid(theta), grid(alpha), int(walks), int(seed)))


def fit(
    material: Material | Mapping[str, Any],
    distribution: str = "ggx",
    fresnel: str = "schlick",
    anisotropic: bool = False,
) -> dict[str, Any]:
    """Fit Cook-Torrance (``distribution`` ``"ggx"`` or ``"beckmann"``,
    ``fresnel`` ``"schlick"`` or ``"conductor"``, one ``alpha`` or, with
    ``anisotropic``, ``alpha_u`` and ``alpha_v``, and a diffuse ``kd``) to a
    material, typically a measured one (``{"type": "measured", "path":
    ...}``), by the cosine-weighted log-space L2 error over its table: what
    ``lobe fit --json`` prints, as Python objects (the same library call):
    ``material`` (the fitted description, for ``load_dict``), ``error``,
    ``pairs``, ``evaluations``.

    >>> import lobe
    >>> r = lobe.fit({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3})
    >>> round(r["material"]["alpha"], 2), r["error"] < 1e-6
    (0.3, True)
    """
    m = _material(material)
    return _json.loads(_lobe._fit_json(m, str(distribution), str(fresnel), bool(anisotropic)))


def render(
    scene: str | os.PathLike[str] | Mapping[str, Any],
    spp: int | None = None,
    strategy: str | None = None,
    seed: int | None = None,
    *,
    max_depth: int | None = None,
    threads: int | None = None,
    spp_allocation: str | None = None,
) -> np.ndarray:
    """Render a scene (a TOML file path, or a dict of the same tables:
    ``camera``, ``environment``, ``object``, ``render``; see ``lobe render
    --help``) and return the linear image, an (H, W, 3) float32 array, row 0
    at the top. ``spp``, ``strategy`` (``mis``, ``light``, a BSDF strategy,
    ...), ``seed``, ``max_depth`` and ``spp_allocation`` (``variance``, the
    default: the ``width × height × spp`` samples shared out in proportion to
    each pixel's noise, as a pilot estimates it; ``uniform``: ``spp`` in every
    pixel) override the scene's
    ``[render]`` table; the image does not depend on ``threads``. Relative paths in a dict are
    taken from the current directory. The scene is in world space (y up);
    each object's material is evaluated in its local shading frame (+z the
    surface normal, wo toward the camera, wi toward the light, f without the
    cosine, pdfs in solid angle), as ``Material`` is.

    >>> import lobe
    >>> scene = {"camera": {"origin": [0, 0, 4], "target": [0, 0, 0], "width": 8, "height": 6},
    ...          "environment": {"path": "sky"},
    ...          "object": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
    ...                      "material": {"type": "lambert"}}]}
    >>> img = lobe.render(scene, spp=4, strategy="mis", seed=1)
    >>> img.shape, str(img.dtype)
    ((6, 8, 3), 'float32')
    """
    if isinstance(scene, _Mapping):
        text = _lobe._json_to_toml(_json.dumps(dict(scene), default=_jsonable))
        path = _os.path.join(_os.getcwd(), "<dict>.toml")
    else:
        path = _os.fspath(scene)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise ValueError(f"scene {path}: cannot read it: {e}") from e
    return _lobe._render(text, path, spp, strategy, seed, max_depth, threads, spp_allocation)


from . import chi2  # noqa: E402
from . import views  # noqa: E402
from .views import albedo_curve, lobe_grid, polar, warp_test, weight_map  # noqa: E402
from . import sweeps  # noqa: E402  (imports Dask only when a sweep runs)
from .sweeps import sweep  # noqa: E402
