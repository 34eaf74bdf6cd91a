"""The lecture's comparison from NumPy: uniform sampling against importance
sampling for Phong, Blinn-Phong and GGX, at equal sample counts, under the
furnace (L_i = 1), so the estimate of ∫ f cos dω is the mean of the Monte
Carlo weights f·cos/pdf. The reference is lobe's quadrature (lobe.estimate).

    pip install . matplotlib        # from the repository root
    python examples/lecture_comparison.py [--out comparison.png]
"""

import argparse

import numpy as np

import lobe

MATERIALS = {
    "Phong n=100": {"type": "phong", "exponent": 100},
    "Blinn-Phong n=100": {"type": "blinn-phong", "exponent": 100},
    "GGX α=0.2": {"type": "cook-torrance", "distribution": "ggx", "alpha": 0.2},
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", help="write a convergence plot (needs matplotlib)")
    ap.add_argument("--samples", type=int, default=1 << 16)
    a = ap.parse_args()
    rng = np.random.default_rng(1)
    wo = np.array([np.sin(np.radians(30)), 0.0, np.cos(np.radians(30))])
    u = rng.random((a.samples, 2))
    curves = {}
    for name, desc in MATERIALS.items():
        m = lobe.load_dict(desc)
        ref = lobe.estimate(m, wo=wo, strategies=["uniform"], samples=2)["reference"][0]
        print(f"{name}: reference {ref:.5f}")
        for strategy in ["uniform", "brdf"] + (["vndf"] if "vndf" in m.strategies else []):
            w = m.sample(wo, u, strategy=strategy).weight[:, 0].astype(np.float64)  # 0 where failed
            est, var = w.mean(), w.var()
            print(f"  {strategy:<8} estimate {est:.5f}  rel. err {abs(est - ref) / ref:.2e}  variance {var:.3e}")
            n = np.arange(1, len(w) + 1)
            curves[(name, strategy)] = np.abs(np.cumsum(w) / n - ref) / ref
    if a.out:
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(12, 3.5), sharey=True)
        for ax, name in zip(axes, MATERIALS):
            for (mat, strategy), err in curves.items():
                if mat == name:
                    ax.loglog(np.arange(1, len(err) + 1), np.maximum(err, 1e-6), label=strategy)
            ax.set_title(name)
            ax.set_xlabel("samples")
            ax.legend(loc="lower left")
        axes[0].set_ylabel("relative error of the running estimate")
        fig.tight_layout()
        fig.savefig(a.out, dpi=120)
        print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
