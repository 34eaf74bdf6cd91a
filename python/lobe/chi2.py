"""Chi-square goodness-of-fit tests of samplers against their pdfs, after
Mitsuba 3's ``mi.chi2``, on lobe's own Rust harness (``lobe::stats::chi2``):
the same histogram, lost bin for failed samples, pooling of cells expecting
fewer than ``min_expected`` counts, hard failures (a sample where the pdf is
zero, a non-unit direction) and p-value; Šidák correction over
``test_count`` tests.

The sampler is called once with all the uniforms (an (N, sample_dim) array,
the harness's stream: per sample ``uc, u.x, u.y`` from ``Pcg64(seed)``; with
``sample_dim=2`` the last two) and returns the points, (N, 3) directions for
``SphericalDomain`` (local frame, +z the normal) or (N, 2) points for
``PlanarDomain``, optionally with a bool mask of valid samples; an all-zero
row is a failed (lost) sample. The pdf is called once with all the
integration points and returns their densities (solid angle on the sphere):
each cell's probability is a Gauss-Legendre rule with ``ires × ires`` points
per cell (exact for the sphere's equal-area cells in ``(cos θ, φ)``).

>>> import lobe, lobe.chi2 as chi2
>>> m = lobe.load_dict({"type": "cook-torrance", "distribution": "ggx", "alpha": 0.3})
>>> ad = chi2.BSDFAdapter(m, "vndf", wo=[0.6, 0.0, 0.8])
>>> t = chi2.ChiSquareTest(chi2.SphericalDomain(), ad.sample, ad.pdf, sample_count=100_000, res=40)
>>> t.run()
True
>>> t.histogram.shape, t.pdf.shape
((40, 80), (40, 80))
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from . import _lobe

__all__ = ["ChiSquareTest", "SphericalDomain", "PlanarDomain", "BSDFAdapter"]


class SphericalDomain:
    """The unit sphere, binned equal-area: ``res`` bins in z = cos θ over
    [-1, 1] times ``2·res`` bins in φ over [0, 2π) (the layout of lobe's
    Rust harness). Points are unit (N, 3) directions in the local frame
    (+z the normal, the hemisphere of wo above); the pdf is a density in
    solid angle, as lobe's ``Material.pdf`` gives it (f without the cosine
    plays no part here)."""

    dim = 3

    def bins(self, res: int | tuple[int, int]) -> tuple[int, int]:
        if isinstance(res, tuple):
            return int(res[0]), int(res[1])
        return int(res), 2 * int(res)

    def nodes(self, nz: int, nphi: int, ires: int) -> tuple[np.ndarray, np.ndarray]:
        """Integration points (M, 3) and weights (M,) in cell-major order."""
        x, w = np.polynomial.legendre.leggauss(ires)
        dz, dphi = 2.0 / nz, 2.0 * np.pi / nphi
        z = (-1.0 + dz * (np.arange(nz)[:, None] + 0.5 * (x[None, :] + 1.0))).ravel()  # nz*ires
        phi = (dphi * (np.arange(nphi)[:, None] + 0.5 * (x[None, :] + 1.0))).ravel()
        zz = np.repeat(z, nphi * ires)
        pp = np.tile(phi, nz * ires)
        r = np.sqrt(np.maximum(0.0, 1.0 - zz * zz))
        pts = np.stack([r * np.cos(pp), r * np.sin(pp), zz], axis=1)
        wz = np.tile(w, nz) * (0.5 * dz)
        wp = np.tile(w, nphi) * (0.5 * dphi)
        weights = np.repeat(wz, nphi * ires) * np.tile(wp, nz * ires)
        return pts, weights

    def to_sphere(self, pts: np.ndarray, nz: int, nphi: int) -> np.ndarray:
        return pts

    def cell_sum(self, v: np.ndarray, nz: int, nphi: int, ires: int) -> np.ndarray:
        return v.reshape(nz, ires, nphi, ires).sum(axis=(1, 3))


class PlanarDomain:
    """A rectangle ``bounds = ((x0, x1), (y0, y1))`` (default [-1, 1]²),
    binned in ``res × res`` cells (or ``res = (nx, ny)``). Points are (N, 2);
    a point outside the bounds counts as lost; the pdf is a density in area
    (for a warp of the unit square or a disk, not a direction: a
    direction sampler takes ``SphericalDomain``, whose pdf is in solid
    angle)."""

    dim = 2

    def __init__(self, bounds: Sequence[Sequence[float]] = ((-1.0, 1.0), (-1.0, 1.0))):
        (self.x0, self.x1), (self.y0, self.y1) = [(float(a), float(b)) for a, b in bounds]
        if not (self.x1 > self.x0 and self.y1 > self.y0):
            raise ValueError(f"PlanarDomain: empty bounds {bounds}")

    def bins(self, res: int | tuple[int, int]) -> tuple[int, int]:
        if isinstance(res, tuple):
            return int(res[0]), int(res[1])
        return int(res), int(res)

    def nodes(self, nx: int, ny: int, ires: int) -> tuple[np.ndarray, np.ndarray]:
        x, w = np.polynomial.legendre.leggauss(ires)
        dx, dy = (self.x1 - self.x0) / nx, (self.y1 - self.y0) / ny
        xs = (self.x0 + dx * (np.arange(nx)[:, None] + 0.5 * (x[None, :] + 1.0))).ravel()
        ys = (self.y0 + dy * (np.arange(ny)[:, None] + 0.5 * (x[None, :] + 1.0))).ravel()
        xx = np.repeat(xs, ny * ires)
        yy = np.tile(ys, nx * ires)
        wx = np.tile(w, nx) * (0.5 * dx)
        wy = np.tile(w, ny) * (0.5 * dy)
        return np.stack([xx, yy], axis=1), np.repeat(wx, ny * ires) * np.tile(wy, nx * ires)

    def to_sphere(self, pts: np.ndarray, nx: int, ny: int) -> np.ndarray:
        """Each point as the centre direction of the harness's sphere cell
        with the same indices (ix, iy); NaN for a point outside (lost)."""
        fx = (pts[:, 0] - self.x0) / (self.x1 - self.x0)
        fy = (pts[:, 1] - self.y0) / (self.y1 - self.y0)
        ix = np.clip(np.floor(fx * nx), 0, nx - 1)
        iy = np.clip(np.floor(fy * ny), 0, ny - 1)
        z = -1.0 + 2.0 * (ix + 0.5) / nx
        phi = 2.0 * np.pi * (iy + 0.5) / ny
        r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        out = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
        bad = ~(np.isfinite(fx) & np.isfinite(fy))
        out[bad] = np.nan
        return out

    def inside(self, pts: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            return (pts[:, 0] >= self.x0) & (pts[:, 0] <= self.x1) & (pts[:, 1] >= self.y0) & (pts[:, 1] <= self.y1)

    def cell_sum(self, v: np.ndarray, nx: int, ny: int, ires: int) -> np.ndarray:
        return v.reshape(nx, ires, ny, ires).sum(axis=(1, 3))


class ChiSquareTest:
    """A chi-square test of ``sample_func`` against ``pdf_func`` on ``domain``.

    ``sample_func(u)``: ``u`` is (N, sample_dim) uniforms; returns the points,
    or ``(points, valid)``. ``pdf_func(points)``: (M,) densities. ``res``: bins
    (see the domains); ``ires``: Gauss-Legendre points per cell side;
    ``seed``: the uniforms' stream; ``min_expected``: cells expecting fewer
    counts are pooled. After ``run``: ``histogram`` (observed counts) and
    ``pdf`` (expected counts), arrays of the bins' shape; ``p_value``,
    ``statistic``, ``dof``, ``messages``.

    For a BSDF sampler (see ``BSDFAdapter``): directions in the local frame
    (+z the normal, wo toward the viewer, wi toward the light), the pdf in
    solid angle; a sample below the horizon is lost, as the sampler's
    failure, and counts against the total.
    """

    def __init__(
        self,
        domain: SphericalDomain | PlanarDomain,
        sample_func: Callable[[np.ndarray], Any],
        pdf_func: Callable[[np.ndarray], Any],
        sample_dim: int = 2,
        sample_count: int = 1_000_000,
        res: int | tuple[int, int] = 50,
        ires: int = 6,
        seed: int = 0,
        min_expected: float = 5.0,
    ):
        if sample_dim not in (1, 2, 3):
            raise ValueError(f"sample_dim {sample_dim}: expected 1, 2 or 3")
        if int(sample_count) < 1:
            raise ValueError("sample_count: at least 1")
        if int(ires) < 1:
            raise ValueError("ires: at least 1")
        self.domain = domain
        self.sample_func = sample_func
        self.pdf_func = pdf_func
        self.sample_dim = int(sample_dim)
        self.sample_count = int(sample_count)
        self.res = domain.bins(res)
        if min(self.res) < 1:
            raise ValueError(f"res {res}: at least one bin per axis")
        self.ires = int(ires)
        self.seed = int(seed)
        self.min_expected = float(min_expected)
        self.messages = ""
        self.histogram: np.ndarray | None = None
        self.pdf: np.ndarray | None = None
        self.p_value: float | None = None
        self.statistic: float | None = None
        self.dof: int | None = None
        self.result: dict[str, Any] | None = None

    def _points(self) -> tuple[np.ndarray, np.ndarray]:
        u = _lobe._chi2_uniforms(self.seed, self.sample_count)
        u = u[:, 3 - self.sample_dim:]
        r = self.sample_func(u)
        if isinstance(r, tuple):
            pts, valid = r
            valid = np.asarray(valid, dtype=bool).reshape(-1)
        else:
            pts, valid = r, None
        pts = np.asarray(pts, dtype=np.float64)
        d = self.domain.dim
        if pts.shape != (self.sample_count, d):
            raise ValueError(f"sample_func returned shape {pts.shape}, expected ({self.sample_count}, {d})")
        if valid is None:
            valid = np.any(pts != 0.0, axis=1)
        elif valid.shape != (self.sample_count,):
            raise ValueError(f"sample_func's valid mask has shape {valid.shape}, expected ({self.sample_count},)")
        if isinstance(self.domain, PlanarDomain):
            valid = valid & self.domain.inside(pts) | (valid & ~np.all(np.isfinite(pts), axis=1))
        return pts, valid

    def run(self, significance_level: float = 0.01, test_count: int = 1, quiet: bool = True) -> bool:
        """Run the test; True when the sampler is accepted at
        ``significance_level`` after Šidák's correction for ``test_count``
        tests (p-value > 1 − (1 − level)^(1/test_count)). ``messages``
        tells why a test failed (and the pooled cells, the statistic, the
        degrees of freedom); ``histogram`` and ``pdf`` are then the observed
        and expected counts per bin, to plot side by side. Directions in the
        local frame (+z the normal); pdfs in solid angle (area for
        ``PlanarDomain``)."""
        nz, nphi = self.res
        pts, valid = self._points()
        dirs = np.ascontiguousarray(self.domain.to_sphere(pts, nz, nphi), dtype=np.float64)
        nodes, weights = self.domain.nodes(nz, nphi, self.ires)
        p = np.asarray(self.pdf_func(nodes), dtype=np.float64).reshape(-1)
        if p.shape != (nodes.shape[0],):
            raise ValueError(f"pdf_func returned {p.shape[0]} values for {nodes.shape[0]} points")
        notes = []
        badp = ~(np.isfinite(p) & (p >= 0))
        if badp.any():
            i = int(np.argmax(badp))
            notes.append(f"pdf({nodes[i].tolist()}) = {p[i]} is not a finite non-negative number")
            p = np.where(badp, 0.0, p)
        probs = np.ascontiguousarray(self.domain.cell_sum(p * weights, nz, nphi, self.ires).ravel())
        errors = np.zeros_like(probs)
        r = _lobe._chi2_test(nz, nphi, self.min_expected, dirs, np.ascontiguousarray(valid), probs, errors)
        if notes:
            r["p_value"], r["statistic"] = 0.0, float("inf")
            r["message"] = "; ".join(notes + ([r["message"]] if r["message"] else []))
        self.result = r
        self.histogram = r["observed"]
        self.pdf = r["expected"]
        self.p_value = r["p_value"]
        self.statistic = r["statistic"]
        self.dof = r["dof"]
        level = _lobe.sidak(float(significance_level), int(test_count))
        ok = self.p_value > level
        self.messages = (
            f"chi2 {'passed' if ok else 'FAILED'}: statistic {self.statistic:.6g}, dof {self.dof}, "
            f"p-value {self.p_value:.6g} against the Šidák-corrected level {level:.6g} "
            f"({test_count} tests at {significance_level}); pdf integral {r['pdf_integral']:.9g}, "
            f"lost {r['lost_observed']:.0f} observed / {r['lost_expected']:.3f} expected"
            + (f"; {r['message']}" if r["message"] else "")
        )
        if not quiet:
            print(self.messages)
        return ok


class BSDFAdapter:
    """A lobe material's sampler and pdf for ``strategy`` at a fixed ``wo``
    (local frame, +z the normal, toward the viewer), as ``sample_func`` and
    ``pdf_func`` of ``ChiSquareTest`` (with ``sample_dim=3`` the first
    uniform chooses the lobe of a two-lobe material). ``reference=True``
    tests the scalar f64 path, else the path ``Material.batched`` names.
    The drawn wi are toward the light in the same frame; the pdf is the
    strategy's, in solid angle (no cosine: that is in the weight,
    f·cos θi / pdf, which the test does not use)."""

    def __init__(self, material: Any, strategy: str | None, wo: Sequence[float] = (0.0, 0.0, 1.0), reference: bool = False):
        from . import Material, load_dict

        self.material = material if isinstance(material, Material) else load_dict(material)
        self.strategy = strategy
        w = np.asarray(wo, dtype=np.float64).reshape(3)
        n = np.linalg.norm(w)
        if not (np.isfinite(n) and n > 0):
            raise ValueError(f"wo {w.tolist()}: not a direction")
        self.wo = w / n
        self.reference = bool(reference)

    def sample(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        u = np.asarray(u, dtype=np.float64)
        uc = u[:, 0] if u.shape[1] == 3 else None
        if uc is None and self.material.chooses_lobe(self.strategy):
            # A fixed uc would draw one lobe's share of the mixture, not
            # the mixture the pdf describes: the test would fail wrongly.
            raise ValueError(
                f"strategy {self.strategy!r} of this material chooses between two lobes: "
                "use ChiSquareTest(..., sample_dim=3), whose first uniform chooses the lobe"
            )
        s = self.material.sample(self.wo, u[:, -2:], uc, self.strategy, reference=self.reference)
        return s.wi, s.valid

    def pdf(self, wi: np.ndarray) -> np.ndarray:
        wi = np.asarray(wi, dtype=np.float64)
        out = np.zeros(wi.shape[0])
        up = wi[:, 2] > 0
        out[up] = self.material.pdf(self.wo, wi[up], self.strategy, reference=self.reference)
        return out
