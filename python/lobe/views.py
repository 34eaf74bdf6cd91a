"""The explorer's views as library calls (``lobe explore``, docs/explore.md):
the polar plot, the 3D lobe, the albedo curve, the warp test and the weight
heat map of a page are these functions' numbers (the same Rust calls of
``lobe::experiment``), re-exported by ``lobe``.

The view is given by ``theta_o`` and ``phi_o`` in degrees, checked as the
explorer checks them: θo in [0, 90), or in (90, 180] (seen from below) for a
material that transmits or is two-sided; a bad angle, count or strategy
raises ``ValueError`` naming the argument. Conventions: the local shading
frame, +z the normal; ``wo = (sin θo cos φo, sin θo sin φo, cos θo)`` toward
the viewer; f without the cosine, the values shown ``f·|cos θi|`` (its
luminance) and pdfs in solid angle. The work runs with the GIL released;
the numbers do not depend on the thread count (``lobe.set_threads``).

>>> import lobe
>>> m = lobe.load_dict({"type": "roughconductor", "distribution": "ggx", "alpha": 0.3})
>>> p = lobe.polar(m, 40.0)
>>> p.theta.shape, sorted(p.pdfs) == sorted(m.strategies), p.full_circle
((362,), True, False)
>>> lobe.warp_test(m, "vndf", 40.0).p_value > 1e-3
True
"""

from __future__ import annotations

import typing as _typing
from typing import NamedTuple, Optional

import numpy as np
import numpy.typing as npt

from . import _lobe

if _typing.TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any

__all__ = ["Polar", "LobeGrid", "WarpTest", "polar", "lobe_grid", "albedo_curve", "warp_test", "weight_map"]

_F64 = npt.NDArray[np.float64]


class Polar(NamedTuple):
    """``lobe.polar``'s curves in the plane of incidence (the plane of the
    normal and wo)."""

    theta: _F64
    """Signed angles θi in radians from the normal, positive on the viewer's
    side (the mirror direction at −θo): ``steps + 1`` from −π/2 to π/2, or
    ``2·steps + 1`` from −π to π with ``full_circle``."""
    fcos: _F64
    """The luminance of f·|cos θi| at each angle (the cosine included)."""
    pdfs: dict[str, _F64]
    """Each strategy of the material (``Material.strategies``) and its pdf in
    solid angle at each angle."""
    full_circle: bool
    """The curves go round the whole circle (the material transmits, or is
    seen from below): |θi| > π/2 are directions below the surface."""


class LobeGrid(NamedTuple):
    """``lobe.lobe_grid``'s values: the 3D lobe's surface is
    ``values[i, j] × (sin θ cos φ, sin θ sin φ, cos θ)``."""

    theta: _F64
    """``n_theta + 1`` polar angles in radians from 0 to π/2 (to π with
    ``sphere``)."""
    phi: _F64
    """``n_phi + 1`` azimuths in radians from 0 to 2π (the last closes the
    surface)."""
    values: _F64
    """(n_theta + 1, n_phi + 1): the luminance of f·|cos θ| at
    ``theta[i]``, ``phi[j]``; delta parts (no density) are left out."""
    sphere: bool
    """Over the whole sphere: the material transmits, or is seen from below."""


class WarpTest(NamedTuple):
    """``lobe.warp_test``'s result: Nori's warp test of one strategy at one
    view."""

    observed: _F64
    """(grids, res, res): draws in each pixel of the projected hemisphere
    (the unit disk of wi's (x, y)), ``observed[k, j, i]`` at x in pixel
    column i and y in row j from −1 (row 0 at y = −1); grid 0 the upper
    hemisphere, grid 1 (with ``sphere``) the lower one."""
    expected: _F64
    """(grids, res, res): the counts the pdf expects there."""
    sphere: bool
    """Two grids: the material transmits, or is seen from below."""
    statistic: float
    """The chi-square statistic over the sphere (16 × 16 bins in cos θ and
    φ, small ones pooled; infinite on a hard failure)."""
    dof: int
    """Its degrees of freedom."""
    p_value: float
    """Its p-value (0 on a hard failure, see ``message``)."""
    message: Optional[str]
    """Why the test failed outright, and notes; None when there is nothing
    to say."""


def _material(m: Any) -> _lobe.Material:
    from . import load_dict

    return m if isinstance(m, _lobe.Material) else load_dict(m)


def _count(name: str, v: int, least: int = 1) -> int:
    n = int(v)
    if n < least:
        raise ValueError(f"{name} {v}: must be at least {least}")
    return n


def polar(
    material: _lobe.Material | Mapping[str, Any], theta_o: float, phi_o: float = 0.0, steps: int = 361
) -> Polar:
    """f·|cos θi| (luminance) and the pdf of every strategy of the material
    in the plane of incidence at the view ``theta_o``, ``phi_o`` (degrees),
    at ``steps`` steps over the half circle: the explorer's polar plot
    (``lobe::experiment::polar``'s ``integrand`` with albedo 1 and ``pdf``).
    ``material``: a ``Material`` or a dict for ``load_dict``.

    >>> import lobe, numpy as np
    >>> p = lobe.polar({"type": "diffuse", "reflectance": 1.0}, 30.0, steps=180)
    >>> bool(np.allclose(p.fcos, np.cos(p.theta) / np.pi)), list(p.pdfs)
    (True, ['uniform', 'cosine', 'brdf'])
    """
    m = _material(material)
    theta, fcos, pdfs, full = _lobe._polar(m, float(theta_o), float(phi_o), _count("steps", steps))
    return Polar(theta, fcos, pdfs, full)


def lobe_grid(
    material: _lobe.Material | Mapping[str, Any],
    theta_o: float,
    phi_o: float = 0.0,
    n_theta: int = 45,
    n_phi: int = 90,
) -> LobeGrid:
    """The luminance of f·|cos θ| over a grid of directions (θ from the
    normal, φ around it) at the view ``theta_o``, ``phi_o`` (degrees): the
    explorer's 3D lobe (``lobe::experiment::lobe_grid::grid``).

    >>> import lobe
    >>> g = lobe.lobe_grid({"type": "diffuse"}, 30.0, n_theta=9, n_phi=12)
    >>> g.theta.shape, g.phi.shape, g.values.shape, g.sphere
    ((10,), (13,), (10, 13), False)
    """
    m = _material(material)
    theta, phi, values, sphere = _lobe._lobe_grid(
        m, float(theta_o), float(phi_o), _count("n_theta", n_theta), _count("n_phi", n_phi)
    )
    return LobeGrid(theta, phi, values, sphere)


def albedo_curve(
    material: _lobe.Material | Mapping[str, Any],
    thetas_deg: npt.ArrayLike,
    phi_deg: float = 0.0,
    n: int = 64,
) -> _F64:
    """The directional albedo ∫ f |cos θi| dωi (RGB, delta parts included,
    over the sphere where the material transmits; a glass carries importance)
    at each view angle of ``thetas_deg`` (degrees, each checked as
    ``theta_o``) and azimuth ``phi_deg``: an (len(thetas_deg), 3) array, the
    mean weight of the best strategy over an ``n × n`` midpoint grid of its
    uniforms (about three digits at 64): the explorer's albedo plot
    (``lobe::experiment::albedo::albedo_curve``).

    >>> import lobe
    >>> lobe.albedo_curve({"type": "diffuse", "reflectance": 0.5}, [0, 45, 80]).round(6).tolist()
    [[0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5, 0.5, 0.5]]
    """
    m = _material(material)
    t = np.asarray(thetas_deg, dtype=np.float64)
    if t.ndim != 1:
        raise ValueError(f"thetas_deg: shape {t.shape} where (N,) is expected")
    return _lobe._albedo_curve(m, t.tolist(), float(phi_deg), _count("n", n))


def _seed(seed: int | None) -> int | None:
    if seed is None:
        return None
    s = int(seed)
    if not 0 <= s < 1 << 64:
        raise ValueError(f"seed {seed}: must be in [0, 2**64)")
    return s


def warp_test(
    material: _lobe.Material | Mapping[str, Any],
    strategy: str,
    theta_o: float,
    phi_o: float = 0.0,
    samples: int = 20000,
    res: int = 24,
    seed: int | None = None,
) -> WarpTest:
    """Nori's warp test of ``strategy`` at the view ``theta_o``, ``phi_o``
    (degrees): ``samples`` draws into a ``res × res`` histogram over the
    projected hemisphere beside the counts its pdf expects, and the
    chi-square test of the draws against the pdf over the sphere (16 × 16
    bins, the material's settings otherwise): the explorer's warp test
    (``lobe::experiment::warp_test::warp_test`` with ``interactive_config``).
    ``seed``: None for the chi-square harness's default (the explorer's).
    A strategy that does not apply raises ``ValueError`` naming it.

    >>> import lobe
    >>> w = lobe.warp_test({"type": "diffuse"}, "cosine", 30.0, samples=5000, res=8)
    >>> w.observed.shape, w.expected.shape, w.p_value > 1e-3
    ((1, 8, 8), (1, 8, 8), True)
    """
    m = _material(material)
    if not isinstance(strategy, str):
        raise ValueError(f"strategy {strategy!r}: expected a name (a string)")
    d = _lobe._warp_test(
        m, strategy, float(theta_o), float(phi_o), _count("samples", samples), _count("res", res), _seed(seed)
    )
    return WarpTest(
        d["observed"], d["expected"], d["sphere"], d["statistic"], d["dof"], d["p_value"], d["message"]
    )


def weight_map(
    material: _lobe.Material | Mapping[str, Any],
    strategy: str,
    theta_o: float,
    phi_o: float = 0.0,
    res: int = 48,
) -> _F64:
    """The sample weight f·|cos θi| / pdf (f the luminance of ``eval``) of
    ``strategy`` at the centre of each pixel of a ``res × res`` grid over the
    projected hemisphere at the view ``theta_o``, ``phi_o`` (degrees): a
    (grids, res, res) array laid out as ``WarpTest.observed`` (two grids
    where the material transmits or is seen from below), NaN where the pixel
    is outside the disk or the strategy never samples its direction, 0 where
    f = 0: the explorer's weight heat map
    (``lobe::experiment::histogram::weight_pixels``).

    >>> import lobe, numpy as np
    >>> w = lobe.weight_map({"type": "diffuse", "reflectance": 0.5}, "cosine", 30.0, res=8)
    >>> w.shape, bool(np.isnan(w[0, 0, 0])), bool(np.allclose(w[~np.isnan(w)], 0.5))
    ((1, 8, 8), True, True)
    """
    m = _material(material)
    if not isinstance(strategy, str):
        raise ValueError(f"strategy {strategy!r}: expected a name (a string)")
    return _lobe._weight_map(m, strategy, float(theta_o), float(phi_o), _count("res", res))
