"""The lecture's models x 8 roughness values x 5 angles x every BSDF
strategy, as a lobe.sweep on a local Dask cluster of 2 worker processes
(docs/sweeps.md). Prints each strategy's variance and efficiency against
uniform sampling, and draws the variances (--out FILE.png, needs matplotlib).

    pip install '.[dask]' matplotlib
    python examples/sweep_lecture.py --out runs/sweep_lecture.png

A stopped run resumes from runs/sweep_lecture.parquet.
"""

import argparse

import numpy as np

import lobe

#: The microfacet width α; the lecture's exponents are matched to it as
#: Blinn-Phong's n = 2/α² − 2 (Walter et al. 2007's equivalence with
#: Beckmann), and Phong's n/4 (the reflected vector turns twice as fast as
#: the half vector).
ALPHAS = [0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.7, 1.0]
THETAS = [0, 20, 40, 60, 80]
#: The figure's floor: variance ratios below it are drawn on it.
FLOOR = 1e-8


def materials():
    for a in ALPHAS:
        n = 2.0 / a**2 - 2.0
        yield "phong", a, {"type": "phong", "exponent": round(n / 4, 3)}
        yield "blinn-phong", a, {"type": "blinn-phong", "exponent": round(n, 3)}
        yield "ggx", a, {"type": "cook-torrance", "distribution": "ggx", "alpha": a}
        yield "beckmann", a, {"type": "cook-torrance", "distribution": "beckmann", "alpha": a}


def grid(samples):
    tasks = []
    for _, _, m in materials():
        for s in lobe.load_dict(m).strategies:
            for t in THETAS:
                tasks.append({"material": m, "theta": t, "strategy": s, "samples": samples})
    return tasks


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="figure (PNG)")
    ap.add_argument("--data", default="runs/sweep_lecture.parquet", help="the Parquet dataset")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--samples", type=int, default=16384)
    a = ap.parse_args()
    df = lobe.sweep("estimate", grid(a.samples), out=a.data, workers=a.workers)
    names = {lobe.sweeps._canonical(m): (name, al) for name, al, m in materials()}
    df["model"] = [names[m][0] for m in df["material"]]
    df["alpha"] = [names[m][1] for m in df["material"]]
    ok = df[df["error"].isna() & (df["variance"] > 0)].copy()
    # Against uniform sampling's exact variance (by quadrature: at 16k
    # samples uniform sampling can miss a narrow lobe and underestimate its
    # own), and for efficiency its time per sample.
    uni = ok[ok.strategy == "uniform"].set_index(["material", "theta"])
    ok["var_vs_uniform"] = ok["variance"] / ok["uniform_variance"]
    ok["eff_vs_uniform"] = [
        uv * uni.loc[(m, t), "time_s"] / (v * ts)
        for v, ts, uv, m, t in zip(ok["variance"], ok["time_s"], ok["uniform_variance"], ok["material"], ok["theta"])
    ]
    # Geometric means over the 5 angles.
    g = ok.groupby(["model", "alpha", "strategy"])[["var_vs_uniform", "eff_vs_uniform"]].agg(
        lambda x: float(np.exp(np.log(x).mean()))
    )
    import pandas as pd

    with pd.option_context("display.max_rows", 500, "display.max_columns", 20, "display.width", 200, "display.float_format", "{:.3g}".format):
        print("variance / uniform sampling's (geometric mean over θo = 0, 20, 40, 60, 80°; lower is better)")
        print(g.unstack("strategy")["var_vs_uniform"])
        print()
        print("efficiency / uniform sampling's (1 / (variance x time); higher is better)")
        print(g.unstack("strategy")["eff_vs_uniform"])
    if a.out:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 4, figsize=(16, 4.2), sharey=True)
        for ax, model in zip(axes, ["phong", "blinn-phong", "ggx", "beckmann"]):
            sub = g.loc[model]["var_vs_uniform"].unstack("strategy")
            for s in sub.columns:
                ax.loglog(sub.index, sub[s].clip(lower=FLOOR), marker="o", label=s)
            ax.set_ylim(FLOOR / 3, 30)
            ax.set_title(model)
            ax.set_xlabel("α (roughness², the lobe's width)")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
        axes[0].set_ylabel("variance / uniform sampling's")
        fig.suptitle(
            f"lobe.sweep: {len(df)} estimates ({a.samples} samples each), geometric mean over 5 angles; "
            f"lower is better; below {FLOOR:g} (a sampler matching the lobe exactly) drawn at {FLOOR:g}"
        )
        fig.tight_layout()
        fig.savefig(a.out, dpi=110)
        print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
