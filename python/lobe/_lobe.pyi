"""Type stubs of the compiled module (re-exported by ``lobe``).

Conventions: local shading frame, +z the normal; wo toward the viewer, wi
toward the light, unit, away from the surface; eval WITHOUT the cosine;
pdfs in solid angle; weight = f·cos θi / pdf.
"""

from typing import Any, Optional, Sequence, Tuple, final

import numpy as np
import numpy.typing as npt

_ArrayLike = npt.ArrayLike
_F32 = npt.NDArray[np.float32]
_Floats = npt.NDArray[np.floating[Any]]
_F64 = npt.NDArray[np.float64]

__all__ = [
    "BLOCK", "Material", "SampleResult", "_albedo_curve", "_chi2_test", "_chi2_uniforms", "_estimate_json", "_fit_json", "_furnace_json",
    "_json_to_toml", "_load_json", "_lobe_grid", "_polar", "_render", "_warp_test", "_weight_map", "cache_info", "clear_cache",
    "get_threads", "set_cache_limit", "set_threads", "sidak", "simd_level", "__version__",
]

BLOCK: int
"""Rows per block of the array calls (the unit of the thread split)."""
__version__: str
"""The package's version: the Rust workspace's."""

@final
class SampleResult:
    """The result of ``Material.sample``. Conventions: local frame (+z the
    normal), wo toward the viewer, wi toward the light; weight = f·cos θi /
    pdf (the cosine included); pdf in solid angle. A failed sample (below
    the horizon) has valid False and zeros elsewhere, and still counts in an
    estimator's N."""

    @property
    def wi(self) -> _Floats:
        """(N, 3) unit directions toward the light, local frame; zero where not valid."""
    @property
    def weight(self) -> _Floats:
        """(N, 3) f·cos θi / pdf (the cosine included); zero where not valid."""
    @property
    def pdf(self) -> _Floats:
        """(N,) the density in solid angle with which wi was drawn; zero where not valid."""
    @property
    def valid(self) -> npt.NDArray[np.bool_]:
        """(N,) bool: False for a failed sample (below the horizon)."""

@final
class Material:
    """A material (see ``lobe.load_dict``). Conventions: local frame (+z
    the normal), wo toward the viewer, wi toward the light, both unit and
    away from the surface; eval WITHOUT the cosine; pdfs in solid angle;
    weight = f·cos θi / pdf. Float32 results come from the batch SIMD
    kernels, float64 from ``reference=True`` (the scalar f64 path)."""

    def eval(self, wo: _ArrayLike, wi: _ArrayLike, *, reference: bool = False) -> _Floats:
        """f_r(wo, wi) WITHOUT the cosine, (N, 3); zero unless both are above the horizon."""
    def pdf(self, wo: _ArrayLike, wi: _ArrayLike, strategy: Optional[str] = None, *, reference: bool = False) -> _Floats:
        """The solid-angle density (N,) with which ``sample(wo, ..., strategy)`` draws wi."""
    def eval_pdf(
        self,
        wo: _ArrayLike,
        wi: _ArrayLike,
        strategy: Optional[str] = None,
        *,
        reference: bool = False,
        out: Optional[Tuple[_F32, _F32]] = None,
    ) -> Tuple[_Floats, _Floats]:
        """(f WITHOUT the cosine (N, 3), pdf in solid angle (N,)) in one pass."""
    def sample(
        self,
        wo: _ArrayLike,
        u: _ArrayLike,
        uc: Optional[_ArrayLike] = None,
        strategy: Optional[str] = None,
        *,
        reference: bool = False,
        out: Optional[SampleResult] = None,
    ) -> SampleResult:
        """Draw wi toward the light for each wo from u (N, 2); uc (N,) chooses
        the lobe where the material has two. weight = f·cos θi / pdf."""
    @property
    def strategies(self) -> list[str]:
        """The strategies that apply (names for ``strategy=``)."""
    def batched(self, strategy: Optional[str] = None) -> bool:
        """Whether ``strategy`` runs on the batch SIMD kernels (else the scalar f64 path)."""
    def chooses_lobe(self, strategy: Optional[str] = None) -> bool:
        """A method (call it: ``m.chooses_lobe("vndf")``): whether ``strategy``
        (default: vndf where it applies, else brdf) chooses between the
        material's two lobes with ``uc``, which ``sample`` then requires."""
    @property
    def model(self) -> str:
        """The model's short name (lambert, phong, blinn-phong, cook-torrance, measured, conductor, dielectric, thindielectric, roughdielectric, plastic, roughplastic). Mitsuba's names (diffuse, roughconductor, twosided) give lambert, cook-torrance and the wrapped material's model."""
    @property
    def description(self) -> str:
        """lobe's description of the material: JSON text with the keys of ``--material``."""
    def to_toml(self) -> str:
        """The description as TOML text (``MaterialDesc::to_toml``)."""
    def to_python(self) -> str:
        """The description as a Python dict literal, for ``lobe.load_dict`` (``MaterialDesc::to_python``)."""

def _load_json(text: str) -> Material: ...
def set_threads(n: Optional[int] = None) -> None:
    """Threads of the array calls (None: one per core); results do not depend on it."""
def get_threads() -> int:
    """Threads of the array calls."""
def simd_level() -> str:
    """The dispatch level of the batch kernels: avx512, avx2 or scalar (LOBE_SIMD forces one)."""
def set_cache_limit(nbytes: int) -> None:
    """Most bytes of dead result arrays kept for reuse (default 1 GiB, 0 none)."""
def cache_info() -> Tuple[int, int]:
    """(limit, kept) bytes of the reuse cache."""
def clear_cache() -> None:
    """Free the memory kept for reuse."""
def sidak(alpha: float, tests: int) -> float:
    """Šidák's per-test significance level for ``tests`` tests at family level ``alpha``."""
def _estimate_json(
    material: Material, wo: Optional[Sequence[float]], theta: Optional[float], light: str, normal: Sequence[float], tangent: Sequence[float],
    strategies: list[str], samples: int, sequence: str, seed: int, replicas: int,
    mis_bsdf: Optional[str], mis_samples: Tuple[int, int],
) -> str: ...
def _fit_json(material: Material, distribution: str, fresnel: str, anisotropic: bool) -> str: ...
def _furnace_json(
    material: Material, thetas: Optional[list[float]], alphas: Optional[list[float]], walks: int, seed: int,
) -> str: ...
def _render(
    text: str, path: str, spp: Optional[int], strategy: Optional[str], seed: Optional[int],
    max_depth: Optional[int], threads: Optional[int], spp_allocation: Optional[str],
) -> _F32: ...
def _json_to_toml(text: str) -> str: ...
def _chi2_uniforms(seed: int, samples: int) -> npt.NDArray[np.float64]: ...
def _chi2_test(
    n_z: int, n_phi: int, min_expected: float, dirs: npt.NDArray[np.float64], valid: npt.NDArray[np.bool_],
    probs: npt.NDArray[np.float64], errors: npt.NDArray[np.float64],
) -> dict[str, Any]: ...
def _polar(
    material: Material, theta_o: float, phi_o: float, steps: int,
) -> Tuple[_F64, _F64, dict[str, _F64], bool]: ...
def _lobe_grid(
    material: Material, theta_o: float, phi_o: float, n_theta: int, n_phi: int,
) -> Tuple[_F64, _F64, _F64, bool]: ...
def _albedo_curve(material: Material, thetas_deg: Sequence[float], phi_deg: float, n: int) -> _F64: ...
def _warp_test(
    material: Material, strategy: str, theta_o: float, phi_o: float, samples: int, res: int, seed: Optional[int],
) -> dict[str, Any]: ...
def _weight_map(material: Material, strategy: str, theta_o: float, phi_o: float, res: int) -> _F64: ...
