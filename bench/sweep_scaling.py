"""Wall time of lobe.sweep on 1 and 2 local worker processes, the same grid
(examples/sweep_lecture.py's 640 estimates), each from a cold start of its
cluster (BENCHMARKS.md "Sweeps on Dask"). Needs pip install '.[dask]'.

    python bench/sweep_scaling.py [--samples N] [--repeat R]
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "examples"))

import lobe  # noqa: E402
from machine import cpu_model  # noqa: E402  (bench/machine.py, beside this script)
from sweep_lecture import grid  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=16384)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    tasks = grid(a.samples)
    print(f"{cpu_model()}, {os.cpu_count()} cores; {len(tasks)} estimates of {a.samples} samples; lobe {lobe.__version__}")
    times = {}
    for w in (1, 2) * a.repeat:
        t0 = time.perf_counter()
        df = lobe.sweep("estimate", tasks, workers=w, quiet=True)
        dt = time.perf_counter() - t0
        assert df["error"].isna().all()
        times.setdefault(w, []).append(dt)
        work = df["wall_s"].sum()
        print(f"{w} worker(s): {dt:.1f} s wall (tasks' own time {work:.1f} s)")
    best = {w: min(t) for w, t in times.items()}
    print(f"best: 1 worker {best[1]:.1f} s, 2 workers {best[2]:.1f} s: speed-up {best[1] / best[2]:.2f}x")


if __name__ == "__main__":
    main()
