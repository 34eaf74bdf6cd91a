"""Throughput of lobe's Python bindings against `lobe bench`, same machine,
same run: sample + eval_pdf at the sampled directions (what `lobe bench`
calls msps) for GGX alpha = 0.2 by vndf at N = 2^22, one thread; `sample`
alone against `lobe bench`'s sample_msps; and two Python threads calling
sample + eval_pdf at once against the same calls one after the other.

    cargo build --release -p lobe-cli
    python python/bench_python.py [--lobe target/release/lobe] [--threads 1] [--reps 7]

Inputs: wo uniform over the hemisphere and u uniform, float32,
Fortran-ordered (read without a copy); the median of --reps timed calls
after one warm-up, with fresh output arrays (`python_msps`) and writing
into a previous call's arrays with `out=` (`python_out_msps`). Python runs
before and after `lobe bench`; the better of the two is compared. Prints
JSON with the figures and the ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

# Import the installed package, not the sources beside this script.
_here = os.path.dirname(os.path.abspath(__file__))
sys.path = [p for p in sys.path if os.path.abspath(p or ".") != _here]

import numpy as np  # noqa: E402

import lobe  # noqa: E402

MATERIAL = '{"type":"cook-torrance","distribution":"ggx","alpha":0.2}'


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--lobe", default="target/release/lobe")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--samples", type=int, default=1 << 22)
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--strategy", default="vndf")
    a = ap.parse_args()
    lobe.set_threads(a.threads)
    m = lobe.load_dict(json.loads(MATERIAL))
    assert m.batched(a.strategy), "the batch kernels should cover this material"
    rng = np.random.default_rng(1)
    n = a.samples
    cos_t = 1.0 - rng.random(n)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = 2 * np.pi * rng.random(n)
    wo = np.asfortranarray(np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=1), dtype=np.float32)
    u = np.asfortranarray(rng.random((n, 2)), dtype=np.float32)

    def once() -> float:
        t0 = time.perf_counter()
        s = m.sample(wo, u, strategy=a.strategy)
        f, pdf = m.eval_pdf(wo, s.wi, strategy=a.strategy)
        dt = time.perf_counter() - t0
        assert s.valid.any() and f.shape == (n, 3) and pdf.shape == (n,)
        return dt

    s0 = m.sample(wo, u, strategy=a.strategy)
    fp0 = m.eval_pdf(wo, s0.wi, strategy=a.strategy)

    def reused() -> float:
        # The same calls writing into the arrays of a previous call (out=):
        # no new memory, so no page faults.
        t0 = time.perf_counter()
        s = m.sample(wo, u, strategy=a.strategy, out=s0)
        m.eval_pdf(wo, s.wi, strategy=a.strategy, out=fp0)
        return time.perf_counter() - t0

    def python_msps(call=once) -> float:
        call()
        times = sorted(call() for _ in range(a.reps))
        return n / times[len(times) // 2] / 1e6

    def bench_msps() -> dict:
        out = subprocess.run(
            [a.lobe, "bench", "--material", MATERIAL, "--strategy", a.strategy, "--threads", str(a.threads),
             "--samples", str(n), "--reps", str(a.reps), "--json"],
            check=True, capture_output=True, text=True,
        ).stdout
        return json.loads(out)

    def sample_only() -> float:
        t0 = time.perf_counter()
        s = m.sample(wo, u, strategy=a.strategy)
        dt = time.perf_counter() - t0
        assert s.valid.any()
        return dt

    # Two Python threads, each on its own copy of the inputs, calling
    # sample + eval_pdf at once; against the same two calls in a row.
    wo2, u2 = wo.copy(order="F"), u.copy(order="F")

    def pair(w, uu):
        s = m.sample(w, uu, strategy=a.strategy)
        m.eval_pdf(w, s.wi, strategy=a.strategy)

    def serial() -> float:
        t0 = time.perf_counter()
        pair(wo, u)
        pair(wo2, u2)
        return time.perf_counter() - t0

    def concurrent() -> float:
        import threading
        ts = [threading.Thread(target=pair, args=x) for x in ((wo, u), (wo2, u2))]
        t0 = time.perf_counter()
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        return time.perf_counter() - t0

    def median_time(call) -> float:
        call()
        times = sorted(call() for _ in range(a.reps))
        return times[len(times) // 2]

    # Interleaved: Python, lobe bench, Python, so that a change of load shows.
    p1, q1, s1 = python_msps(), python_msps(reused), python_msps(sample_only)
    b = bench_msps()
    p2, q2, s2 = python_msps(), python_msps(reused), python_msps(sample_only)
    t_serial, t_conc = median_time(serial), median_time(concurrent)
    r = b["results"][0]
    py, pq = max(p1, p2), max(q1, q2)
    print(json.dumps({
        "cpu": b["cpu"], "simd": b["simd"], "lobe_simd_python": lobe.simd_level(), "threads": a.threads,
        "samples": n, "strategy": a.strategy, "material": MATERIAL,
        "python_msps": [p1, p2], "python_out_msps": [q1, q2],
        "lobe_bench_msps": r["msps"], "lobe_bench_scalar_msps": r["scalar_msps"],
        "ratio_python_over_bench": py / r["msps"], "ratio_python_out_over_bench": pq / r["msps"],
        "python_sample_msps": [s1, s2], "lobe_bench_sample_msps": r["sample_msps"],
        "ratio_python_sample_over_bench": max(s1, s2) / r["sample_msps"],
        "two_calls_serial_s": t_serial, "two_calls_concurrent_s": t_conc,
        "concurrent_speed_over_serial": t_serial / t_conc,
    }, indent=2))


if __name__ == "__main__":
    main()
