#!/usr/bin/env python3
"""lobe's batch kernels against Mitsuba 3's, in one run on one machine
(issue 9): a Markdown table of M samples/s and their ratio.

Setup (not run by CI): the Mitsuba venv and libLLVM of
`bench/mitsuba_kernels.py` (see its header), then from the repository root:

    python3 bench/side_by_side.py --mitsuba-python venv-mitsuba/bin/python
    python3 bench/side_by_side.py --rounds 5 --threads 1,2 --build

This script needs only the Python standard library; it runs Mitsuba in the
interpreter given by --mitsuba-python (default: $MITSUBA_PYTHON, else
/work/venv-mitsuba/bin/python if it exists, else this interpreter).

What it does: it builds `target/release/lobe` if it is missing (or with
--build: `cargo build --release --locked -p lobe-cli`), then for each of
--rounds rounds and each thread count T it runs, alternately (the order of
lobe and Mitsuba flips every round, so that a slow spell of the shared
machine does not fall on one side only):

* `lobe bench --json --threads T --samples N --reps R` (its default table:
  GGX alpha = 0.2, vndf and brdf), and
  `lobe bench --json --threads T ... --material <beckmann alpha 0.2> --strategy vndf`
  (reported as unsupported if lobe's batch path does not have it);
* `mitsuba_kernels.py --json --threads T --samples N --reps R` (the same
  materials in Mitsuba's `roughconductor`, see that script's header for what
  matches and what differs).

Each figure in the table is the median over the rounds of each round's median
of R warm runs. "s+e+p" is lobe's `msps` (batch sample, then batch eval_pdf
at the sampled direction) against Mitsuba's `msps` (`bsdf.sample` +
`bsdf.eval` + `bsdf.pdf`, as issue 9 measured it) and, in its own column,
Mitsuba's sample + `eval_pdf`; the ratio is lobe over the faster of Mitsuba's
two. "sample" is `sample` alone on both sides. The header names the CPU,
lobe's SIMD level, Mitsuba's LLVM vector width, the machine's load average
and the lobe commit.
"""

import argparse
import datetime
import json
import os
import resource
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

BECKMANN = '{"type":"cook-torrance","distribution":"beckmann","alpha":0.2}'
GGX = '{"type":"cook-torrance","distribution":"ggx","alpha":0.2}'


def die(msg):
    sys.exit(f"side_by_side.py: {msg}")


def default_mitsuba_python():
    if os.environ.get("MITSUBA_PYTHON"):
        return os.environ["MITSUBA_PYTHON"]
    if os.path.exists("/work/venv-mitsuba/bin/python"):
        return "/work/venv-mitsuba/bin/python"
    return sys.executable


SHARE = {"lobe": [], "mitsuba": []}


def run_context():
    """(lobe's short commit, the load average now), for a table's header."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip() or "?"
    try:
        load = " ".join(open("/proc/loadavg").read().split()[:3])
    except OSError:
        load = "?"
    return commit, load


def run_json(cmd, env=None, side=None, threads=1):
    """Runs `cmd`; returns (parsed JSON, None) or (None, first error line).
    Records the share of `threads` cores the process got (CPU time over
    wall time): far below 100% means the machine was busy with other work."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = datetime.datetime.now()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    wall = (datetime.datetime.now() - t0).total_seconds()
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if side and wall > 0:
        SHARE[side].append(cpu / (wall * threads))
    run_json.last_stderr = p.stderr
    if p.returncode != 0:
        lines = [x for x in p.stderr.strip().splitlines() if x.strip()]
        return None, (" ".join(lines[-3:]) if lines else f"exit {p.returncode}")
    try:
        return json.loads(p.stdout), None
    except json.JSONDecodeError as e:
        return None, f"not JSON ({e}): {p.stdout[:200]!r}"


def key(material, strategy):
    """Canonical (material, strategy) key: the material JSON with sorted keys,
    without lobe's `shadowing` (Mitsuba's results name lobe's default
    material; `--shadowing` says which term lobe ran)."""
    m = json.loads(material)
    m.pop("shadowing", None)
    return (json.dumps(m, sort_keys=True), strategy)


def with_shadowing(material, shadowing):
    """`material` with lobe's `shadowing` key set (None: lobe's default)."""
    if shadowing is None:
        return material
    m = json.loads(material)
    m["shadowing"] = shadowing
    return json.dumps(m, separators=(",", ":"))


def label(material):
    m = json.loads(material)
    return f"{m.get('distribution', 'ggx')} α = {m.get('alpha')}"


def main():
    p = argparse.ArgumentParser(description="lobe bench against bench/mitsuba_kernels.py in one run")
    p.add_argument("--lobe", default=os.path.join(ROOT, "target", "release", "lobe"),
                   help="the lobe binary (default target/release/lobe)")
    p.add_argument("--build", action="store_true", help="run cargo build --release first")
    p.add_argument("--mitsuba-python", default=default_mitsuba_python(),
                   help="Python with mitsuba + numpy (default $MITSUBA_PYTHON or /work/venv-mitsuba)")
    p.add_argument("--rounds", type=int, help="alternating rounds (default 3; with --all, 1)")
    p.add_argument("--threads", default="1,2", help="comma-separated thread counts (default 1,2)")
    p.add_argument("--samples", "-n", type=int, default=1 << 22, help="samples per run (default 2^22)")
    p.add_argument("--reps", type=int, default=10, help="warm runs per figure, median (default 10)")
    p.add_argument("--json-out", help="also write every raw JSON result to this file")
    p.add_argument("--all", action="store_true",
                   help="the whole table: `lobe bench --all` (every model x strategy x SIMD level x "
                        "thread count) beside mitsuba_kernels.py on every case Mitsuba has, "
                        "alternating per round (default 1 round)")
    p.add_argument("--shadowing", choices=["smith-correlated", "smith-separable"],
                   help="lobe's Smith term (default: lobe's default, smith-correlated); "
                        "smith-separable is the term Mitsuba's roughconductor evaluates")
    args = p.parse_args()
    if args.rounds is None:
        args.rounds = 1 if args.all else 3
    try:
        threads = [int(t) for t in args.threads.split(",")]
    except ValueError:
        die(f"--threads: not a list of integers: {args.threads!r}")
    if args.rounds < 1 or args.samples < 1 or args.reps < 1 or any(t < 1 for t in threads):
        die("--rounds, --samples, --reps and --threads must be >= 1")

    if args.build or not os.path.exists(args.lobe):
        print("building lobe: cargo build --release --locked -p lobe-cli", file=sys.stderr)
        r = subprocess.run(["cargo", "build", "--release", "--locked", "-p", "lobe-cli"], cwd=ROOT)
        if r.returncode != 0:
            die("cargo build failed")
    if not os.path.exists(args.lobe):
        die(f"no lobe binary at {args.lobe}")

    env = dict(os.environ)
    llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
    if "DRJIT_LIBLLVM_PATH" not in env and os.path.exists(llvm):
        env["DRJIT_LIBLLVM_PATH"] = llvm
    common = ["--samples", str(args.samples), "--reps", str(args.reps)]
    if args.all:
        return run_all(args, threads, env)
    mitsuba_cmd = [args.mitsuba_python, os.path.join(HERE, "mitsuba_kernels.py"), "--json"] + common

    # (key, threads) -> {"lobe": [...], "lobe_sample": [...], ...}
    figures = {}
    notes = {}
    meta = {"lobe": None, "mitsuba": None}
    raw = []

    def add(k, t, name, x):
        figures.setdefault((k, t), {}).setdefault(name, []).append(x)

    def lobe_runs(t):
        base = [args.lobe, "bench", "--json", "--threads", str(t)] + common
        # (key of the run's results if it fails, extra arguments)
        if args.shadowing is None:
            runs = ((("lobe default table", ""), []),
                    (key(BECKMANN, "vndf"), ["--material", BECKMANN, "--strategy", "vndf"]))
        else:
            runs = ((("lobe GGX runs", ""),
                     ["--material", with_shadowing(GGX, args.shadowing), "--strategy", "vndf,brdf"]),
                    (key(BECKMANN, "vndf"),
                     ["--material", with_shadowing(BECKMANN, args.shadowing), "--strategy", "vndf"]))
        for fail_key, extra in runs:
            out, err = run_json(base + extra, side="lobe", threads=t)
            if out is None:
                k = fail_key
                notes[(k, t)] = err if err.startswith("lobe") else f"lobe: {err}"
                figures.setdefault((k, t), {})
                continue
            raw.append({"side": "lobe", "cmd": base + extra, "out": out})
            meta["lobe"] = out
            for r in out["results"]:
                k = key(r.get("material", out.get("material")), r["strategy"])
                add(k, t, "lobe", r["msps"])
                add(k, t, "lobe_sample", r["sample_msps"])
                if "scalar_msps" in r:
                    add(k, t, "lobe_scalar", r["scalar_msps"])

    def mitsuba_runs(t):
        out, err = run_json(mitsuba_cmd + ["--threads", str(t)], env=env, side="mitsuba", threads=t)
        if out is None:
            die(f"mitsuba_kernels.py failed: {err}")
        raw.append({"side": "mitsuba", "cmd": mitsuba_cmd + ["--threads", str(t)], "out": out})
        meta["mitsuba"] = out
        for r in out["results"]:
            k = key(r["material"], r["strategy"])
            add(k, t, "mi", r["msps"])
            add(k, t, "mi_ep", r["eval_pdf_msps"])
            add(k, t, "mi_sample", r["sample_msps"])

    for rnd in range(args.rounds):
        for t in threads:
            order = (lobe_runs, mitsuba_runs) if (rnd + t) % 2 == 0 else (mitsuba_runs, lobe_runs)
            for f in order:
                print(f"round {rnd + 1}/{args.rounds}, {t} thread(s): {f.__name__}", file=sys.stderr)
                f(t)

    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump(raw, f, indent=2)

    lo, mt = meta["lobe"] or {}, meta["mitsuba"] or {}
    commit, load = run_context()
    med = lambda v: statistics.median(v) if v else None  # noqa: E731
    fmt = lambda x: "—" if x is None else f"{x:.1f}"  # noqa: E731
    ratio = lambda a, b: "—" if a is None or b is None else f"{a / b:.2f}×"  # noqa: E731

    print(f"CPU: {lo.get('cpu') or mt.get('cpu', '?')}, {os.cpu_count()} logical CPUs; "
          f"lobe SIMD level: {lo.get('simd', '?')}; "
          f"Mitsuba {mt.get('mitsuba', '?')} {mt.get('variant', '?')} (Dr.Jit {mt.get('drjit', '?')}, "
          f"{mt.get('simd', '?')}).  ")
    print(f"lobe commit {commit}; {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
          f"load average at the end {load}; {args.samples} samples, median of {args.reps} warm runs "
          f"per round, median of {args.rounds} alternating rounds; M samples/s; lobe's shadowing: "
          f"{args.shadowing or 'smith-correlated (its default)'}, Mitsuba's: separable Smith.  ")
    share = {k: f"{100 * statistics.median(v):.0f}%" if v else "?" for k, v in SHARE.items()}
    print(f"Share of its T cores each process got (CPU time / (wall time × T), median over the runs; "
          f"about 100% on an idle machine, less when other work competes): lobe {share['lobe']}, "
          f"Mitsuba {share['mitsuba']}.")
    print()
    print("| material | strategy | threads | lobe s+e+p | Mitsuba s+eval+pdf | Mitsuba s+eval_pdf "
          "| ratio | lobe sample | Mitsuba sample | ratio | lobe scalar f64 s+e+p |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    order = []
    for (k, t) in figures:
        if k not in order and k[1]:
            order.append(k)
    for k in order:
        for t in threads:
            f = figures.get((k, t), {})
            lobe, mi_, mi_ep = med(f.get("lobe")), med(f.get("mi")), med(f.get("mi_ep"))
            mi_best = max(x for x in (mi_, mi_ep) if x is not None) if (mi_ or mi_ep) else None
            ls, ms = med(f.get("lobe_sample")), med(f.get("mi_sample"))
            print(f"| {label(k[0])} | {k[1]} | {t} | {fmt(lobe)} | {fmt(mi_)} | {fmt(mi_ep)} | "
                  f"{ratio(lobe, mi_best)} | {fmt(ls)} | {fmt(ms)} | {ratio(ls, ms)} | "
                  f"{fmt(med(f.get('lobe_scalar')))} |")
    shown = set()
    for (k, t), n in sorted(notes.items(), key=lambda x: str(x)):
        if n not in shown:
            print(f"\n* {label(k[0]) if k[1] else k[0]} {k[1]}: {n}")
            shown.add(n)
    print("\nratio = lobe / the faster of Mitsuba's two ways; — = not measured (see the notes).")


def run_all(args, threads, env):
    """--all: rounds of `lobe bench --all --json` and mitsuba_kernels.py
    --cases-from (its output), alternating; the median per cell; one
    Markdown table: lobe's f64 path and every SIMD level, Mitsuba's faster
    way of sample + eval + pdf, and lobe's best level over Mitsuba."""
    import tempfile
    lobe_runs, mi_runs = [], []
    tlist = ",".join(str(t) for t in threads)
    # lobe --all's own reps: the f64 path is slow; 3 is its default.
    lobe_cmd = [args.lobe, "bench", "--all", "--json", "--threads", tlist,
                "--samples", str(args.samples)]
    with tempfile.TemporaryDirectory() as tmp:
        for rnd in range(args.rounds):
            def lobe_side():
                print(f"round {rnd + 1}/{args.rounds}: lobe bench --all", file=sys.stderr)
                out, err = run_json(lobe_cmd, side="lobe", threads=max(threads))
                if out is None:
                    die(f"lobe bench --all failed: {err}")
                lobe_runs.append(out)
                with open(os.path.join(tmp, "cases.json"), "w") as f:
                    json.dump(out, f)
                if args.json_out:  # kept as it comes: a later failure loses nothing
                    with open(args.json_out, "w") as f:
                        json.dump({"lobe": lobe_runs, "mitsuba": mi_runs}, f, indent=2)

            def mitsuba_side():
                path = os.path.join(tmp, "cases.json")
                if not os.path.exists(path):
                    lobe_side()
                print(f"round {rnd + 1}/{args.rounds}: mitsuba_kernels.py", file=sys.stderr)
                cmd = [args.mitsuba_python, os.path.join(HERE, "mitsuba_kernels.py"), "--json",
                       "--cases-from", path, "--threads", tlist,
                       "--samples", str(args.samples), "--reps", str(args.reps)]
                out, err = run_json(cmd, env=env, side="mitsuba", threads=max(threads))
                if out is None:
                    die(f"mitsuba_kernels.py failed: {err}")
                sys.stderr.write(run_json.last_stderr)
                mi_runs.append(out if isinstance(out, list) else [out])

            for f in ((lobe_side, mitsuba_side) if rnd % 2 == 0 else (mitsuba_side, lobe_side)):
                f()
    if args.json_out:
        with open(args.json_out, "w") as f:
            json.dump({"lobe": lobe_runs, "mitsuba": mi_runs}, f, indent=2)
    med = lambda v: statistics.median(v) if v else None  # noqa: E731
    levels = lobe_runs[0]["levels"]
    cells = {}  # (case, strategy, threads) -> {column: [values]}
    order = []
    for run in lobe_runs:
        for r in run["results"]:
            k = (r["case"], r["strategy"], r["threads"])
            if k not in cells:
                order.append(k)
                cells[k] = {"material": r["material"]}
            cells[k].setdefault("f64", []).append(r["f64"]["msps"])
            for lv in levels:
                if "msps" in r[lv]:
                    cells[k].setdefault(lv, []).append(r[lv]["msps"])
    by_material = {}
    notes = set()
    for run in mi_runs:
        for o in run:
            for r in o["results"]:
                best = max(x for x in (r["msps"], r["eval_pdf_msps"]) if x is not None)
                if r.get("not_finite"):
                    notes.add(f"{r['case']}: the sum of Mitsuba's outputs is not finite "
                              f"({', '.join(r['not_finite'])}), timed all the same")
                by_material.setdefault((r["material"], r["strategy"], o["threads"]), []).append(best)
    mt = mi_runs[0][0] if mi_runs and mi_runs[0] else {}
    lo = lobe_runs[0]
    commit, load = run_context()
    heads = {"scalar": "f32 portable", "avx2": "AVX2", "avx512": "AVX-512"}
    print(f"CPU: {lo['cpu']}; lobe levels {', '.join(levels)}; Mitsuba {mt.get('mitsuba', '?')} "
          f"{mt.get('variant', '?')} (Dr.Jit {mt.get('drjit', '?')}, {mt.get('simd', '?')}).  ")
    print(f"lobe commit {commit}; {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC; "
          f"load average at the end {load}; {args.samples} inputs ({lo['scalar_samples']} for lobe's "
          f"f64 path), lobe median of {lo['reps']} reps, Mitsuba median of {args.reps} warm runs, "
          f"median of {args.rounds} alternating round(s); sample + eval + pdf per sample, "
          f"M samples/s · ns per sample (wall).\n")
    cols = ["f64 path"] + [heads.get(lv, lv) for lv in levels] + ["Mitsuba 3", "lobe best / Mitsuba"]
    print("| model | strategy | threads | " + " | ".join(cols) + " |")
    print("|---|---|---:|" + "---:|" * len(cols))
    fmt = lambda x: "—" if x is None else f"{x:.1f} · {1e3 / x:.1f} ns"  # noqa: E731
    for k in order:
        c = cells[k]
        row = [med(c.get("f64"))] + [med(c.get(lv)) for lv in levels]
        mi_ = med(by_material.get((c["material"], k[1], k[2])))
        best = max((x for x in row[1:] if x is not None), default=None)
        ratio = "—" if best is None or mi_ is None else f"{best / mi_:.2f}×"
        print(f"| {k[0]} | {k[1]} | {k[2]} | " + " | ".join(fmt(x) for x in row + [mi_])
              + f" | {ratio} |")
    for n in sorted(notes):
        print(f"\n* {n}")
    print("\n— = not measured: no batch kernel at that level (lobe's f64 path serves it), or no "
          "Mitsuba plugin or sampler for the case (bench/mitsuba_kernels.py, mitsuba_dict).")


if __name__ == "__main__":
    main()
