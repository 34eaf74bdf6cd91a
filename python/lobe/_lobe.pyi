"""Type stubs of the compiled module (re-exported by ``lobe``).

Conventions: local shading frame, +z the normal; wo toward the viewer, wi
toward the light, unit, away from the surface; eval WITHOUT the cosine;
pdfs in solid angle; weight = f·cos θi / pdf.
"""

from typing import Any, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F32 = npt.NDArray[np.float32]
Floats = npt.NDArray[np.floating[Any]]

BLOCK: int

class SampleResult:
    """wi (N, 3), weight (N, 3) = f·cos θi / pdf, pdf (N,) solid angle, valid (N,) bool."""

    @property
    def wi(self) -> Floats: ...
    @property
    def weight(self) -> Floats: ...
    @property
    def pdf(self) -> Floats: ...
    @property
    def valid(self) -> npt.NDArray[np.bool_]: ...

class Material:
    """A material (see lobe.load_dict). Local frame, +z the normal, wo toward the viewer."""

    def eval(self, wo: ArrayLike, wi: ArrayLike, *, reference: bool = False) -> Floats:
        """f_r(wo, wi) WITHOUT the cosine, (N, 3)."""
    def pdf(self, wo: ArrayLike, wi: ArrayLike, strategy: Optional[str] = None, *, reference: bool = False) -> Floats:
        """Solid-angle pdf of `strategy` at wi, (N,)."""
    def eval_pdf(
        self,
        wo: ArrayLike,
        wi: ArrayLike,
        strategy: Optional[str] = None,
        *,
        reference: bool = False,
        out: Optional[Tuple[F32, F32]] = None,
    ) -> Tuple[Floats, Floats]:
        """(f without the cosine (N, 3), pdf (N,))."""
    def sample(
        self,
        wo: ArrayLike,
        u: ArrayLike,
        uc: Optional[ArrayLike] = None,
        strategy: Optional[str] = None,
        *,
        reference: bool = False,
        out: Optional[SampleResult] = None,
    ) -> SampleResult:
        """Draw wi for each wo from u (N, 2); uc (N,) where the material has two lobes."""
    @property
    def strategies(self) -> list[str]: ...
    def batched(self, strategy: Optional[str] = None) -> bool: ...
    def chooses_lobe(self, strategy: Optional[str] = None) -> bool: ...
    @property
    def model(self) -> str: ...
    @property
    def description(self) -> str: ...

def _load_json(text: str) -> Material: ...
def set_threads(n: Optional[int] = None) -> None: ...
def get_threads() -> int: ...
def simd_level() -> str: ...
def set_cache_limit(nbytes: int) -> None: ...
def cache_info() -> Tuple[int, int]: ...
def clear_cache() -> None: ...
def sidak(alpha: float, tests: int) -> float: ...
def _estimate_json(
    material: Material, wo: Optional[Sequence[float]], theta: Optional[float], light: str, normal: Sequence[float], tangent: Sequence[float],
    strategies: list[str], samples: int, sequence: str, seed: int, replicas: int,
    mis_bsdf: Optional[str], mis_samples: Tuple[int, int],
) -> str: ...
def _render(
    text: str, path: str, spp: Optional[int], strategy: Optional[str], seed: Optional[int],
    max_depth: Optional[int], threads: Optional[int],
) -> F32: ...
def _json_to_toml(text: str) -> str: ...
def _chi2_uniforms(seed: int, samples: int) -> npt.NDArray[np.float64]: ...
def _chi2_test(
    n_z: int, n_phi: int, min_expected: float, dirs: npt.NDArray[np.float64], valid: npt.NDArray[np.bool_],
    probs: npt.NDArray[np.float64], errors: npt.NDArray[np.float64],
) -> dict[str, Any]: ...
