"""Sweeps over grids of lobe's library calls, on a laptop or a cluster, with
Dask (``dask.distributed``): :func:`sweep` (also ``lobe.sweep``).

A sweep is a list of tasks, each one call that lobe already has (an
estimate, a chi-square test, a fit of a measured file, a white-furnace
albedo cell) with its parameters. The tasks run on a ``dask.distributed``
client (a ``LocalCluster`` of worker processes unless a scheduler is given)
and come back as a pandas DataFrame, one row per task, the parameters as
columns. With ``out=`` the finished rows are written as they arrive to a
Parquet dataset (a directory of part files); a sweep that was stopped, or
lost workers, resumes from it: the tasks already written are not run again.

Each task's seed comes from its parameters (a hash of them, with the
grid's ``seed`` if it has one), so the numbers are the same whatever the
number of workers, the order tasks finish in, and whether the run was
resumed (columns of wall time, ``time_s`` and ``efficiency``, excepted).

Dask, pandas and pyarrow are an optional extra (``pip install
'lobe[dask]'``); the rest of lobe does not import them.

>>> import lobe.sweeps
>>> tasks = lobe.sweeps.tasks("estimate", {"material": ["phong"], "theta": [10, 80], "strategy": ["uniform", "brdf"]})
>>> len(tasks), sorted(tasks[0])
(4, ['material', 'strategy', 'theta'])
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import sys
import time
import uuid
from typing import Any, Callable, Iterable, Mapping, Sequence

__all__ = ["sweep", "tasks", "TASKS", "task_seed", "run_task", "main"]


def _estimate(p: Mapping[str, Any], seed: int) -> dict[str, Any]:
    import lobe

    t = lobe.estimate(
        p["material"],
        theta=float(p.get("theta", 30.0)),
        light=str(p.get("light", "constant")),
        strategies=[str(p["strategy"])],
        samples=int(p.get("samples", 65536)),
        sequence=str(p.get("sequence", "independent")),
        seed=seed,
    )
    (row,) = t["strategies"]
    out: dict[str, Any] = {}
    for k, v in row.items():
        if k in ("name", "samples"):
            continue
        _put(out, k, v)
    _put(out, "reference", t["reference"])
    _put(out, "uniform_variance", (t.get("uniform_variance") or {}).get("variance"))
    return out


def _chi2(p: Mapping[str, Any], seed: int) -> dict[str, Any]:
    import numpy as np

    import lobe
    from lobe import chi2

    m = p["material"] if isinstance(p["material"], lobe.Material) else lobe.load_dict(p["material"])
    theta = np.radians(float(p.get("theta", 30.0)))
    wo = [float(np.sin(theta)), 0.0, float(np.cos(theta))]
    ad = chi2.BSDFAdapter(m, str(p["strategy"]), wo=wo)
    domain = chi2.SphericalDomain()
    t = chi2.ChiSquareTest(
        domain, ad.sample, ad.pdf, sample_count=int(p.get("samples", 100_000)), res=int(p.get("res", 40)), seed=seed
    )
    passed = t.run(significance_level=float(p.get("significance", 0.01)))
    return {"p_value": float(t.p_value) if t.p_value is not None else None, "passed": bool(passed)}


def _fit(p: Mapping[str, Any], seed: int) -> dict[str, Any]:
    import lobe

    r = lobe.fit(
        {"type": "measured", "path": os.fspath(p["file"])},
        distribution=str(p.get("distribution", "ggx")),
        fresnel=str(p.get("fresnel", "schlick")),
        anisotropic=bool(p.get("anisotropic", False)),
    )
    return {"fit": _canonical(r["material"]), "fit_error": r["error"], "pairs": r["pairs"]}


def _albedo(p: Mapping[str, Any], seed: int) -> dict[str, Any]:
    import lobe

    t = lobe.furnace(
        p["material"], theta=[float(p.get("theta", 0.0))], alpha=[float(p["alpha"])],
        walks=int(p.get("walks", 0)), seed=seed,
    )
    (row,) = t["rows"]
    out: dict[str, Any] = {}
    for k in ("none", "kulla-conty", "turquin", "walk", "walk_std_error"):
        _put(out, k.replace("-", "_"), row[k])
    return out


#: The tasks a sweep can run: name -> (function, parameters it requires,
#: parameters it accepts besides them). Every task also accepts ``seed``
#: (mixed into the seed each task derives from its parameters).
TASKS: dict[str, tuple[Callable[[Mapping[str, Any], int], dict[str, Any]], tuple[str, ...], tuple[str, ...]]] = {
    "estimate": (_estimate, ("material", "strategy"), ("theta", "light", "samples", "sequence")),
    "chi2": (_chi2, ("material", "strategy"), ("theta", "samples", "res", "significance")),
    "fit": (_fit, ("file",), ("distribution", "fresnel", "anisotropic")),
    "albedo": (_albedo, ("material", "alpha"), ("theta", "walks")),
}


def _put(out: dict[str, Any], key: str, v: Any) -> None:
    """A value as flat columns: an RGB triple as ``key_r``, ``key_g``, ``key_b``."""
    if isinstance(v, (list, tuple)) and len(v) == 3:
        for c, x in zip("rgb", v):
            out[f"{key}_{c}"] = x
    else:
        out[key] = v


def _canonical(v: Any) -> str:
    """A parameter value as canonical JSON text (dicts with sorted keys)."""
    return json.dumps(v, sort_keys=True, separators=(",", ":"), default=str)


def task_seed(task: str, params: Mapping[str, Any]) -> int:
    """The seed of one task: 63 bits of SHA-256 of the task's name and its
    parameters (canonical JSON, ``seed`` among them if given)."""
    h = hashlib.sha256((task + "\0" + _canonical(dict(params))).encode()).digest()
    return int.from_bytes(h[:8], "little") >> 1


def _key(task: str, params: Mapping[str, Any]) -> str:
    return hashlib.sha256((task + "\0" + _canonical(dict(params))).encode()).hexdigest()[:24]


def tasks(task: str, grid: Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The tasks of ``grid``: the product of a dict of lists (in the order
    of its keys, the last fastest), or a list of dicts as they are. Raises
    ``ValueError`` before any work for an unknown task, an unknown or
    missing parameter, an empty grid, or a duplicate task."""
    if task not in TASKS:
        raise ValueError(f"task {task!r}: unknown; expected one of {', '.join(TASKS)}")
    _, required, optional = TASKS[task]
    if isinstance(grid, Mapping):
        if not grid:
            raise ValueError("grid: empty (no parameters)")
        names = list(grid)
        values = []
        for n in names:
            v = grid[n]
            if isinstance(v, (str, bytes, Mapping)) or not isinstance(v, Iterable):
                v = [v]
            v = list(v)
            if not v:
                raise ValueError(f"grid: parameter {n!r} has no values (the grid would be empty)")
            values.append(v)
        out = [dict(zip(names, combo)) for combo in itertools.product(*values)]
    else:
        out = [dict(p) for p in grid]
        if not out:
            raise ValueError("grid: empty (no tasks)")
    allowed = set(required) | set(optional) | {"seed"}
    seen: dict[str, int] = {}
    for i, p in enumerate(out):
        unknown = sorted(set(p) - allowed)
        if unknown:
            raise ValueError(
                f"task {i}: unknown parameter {unknown[0]!r} for {task!r}; "
                f"it takes {', '.join(required)} and optionally {', '.join((*optional, 'seed'))}"
            )
        missing = [n for n in required if n not in p]
        if missing:
            raise ValueError(f"task {i}: {task!r} needs the parameter {missing[0]!r}")
        k = _key(task, p)
        if k in seen:
            raise ValueError(f"tasks {seen[k]} and {i} are the same task: {_canonical(p)}")
        seen[k] = i
    return out


def _params_row(task: str, params: Mapping[str, Any]) -> dict[str, Any]:
    """The start of a task's row: its key and its parameters as columns
    (each as given, a dict or list as canonical JSON)."""
    row: dict[str, Any] = {"task_key": _key(task, params)}
    for k, v in params.items():
        row[k] = _canonical(v) if isinstance(v, (Mapping, list, tuple)) else v
    return row


def run_task(task: str, params: Mapping[str, Any]) -> dict[str, Any]:
    """Run one task where this process is (a Dask worker, or here): its row,
    the parameters (each as given, a dict as canonical JSON) and the
    results, with ``error`` set (and no results) if it failed."""
    import lobe

    # One thread per task: the parallelism is the sweep's, across workers.
    lobe.set_threads(1)
    fn, _, _ = TASKS[task]
    row = _params_row(task, params)
    t0 = time.perf_counter()
    try:
        row.update(fn(params, task_seed(task, params)))
        row["error"] = None
    except Exception as e:  # noqa: BLE001 - a failed task is a row, not the end of the sweep
        row["error"] = f"{type(e).__name__}: {e}"
    row["wall_s"] = time.perf_counter() - t0
    return row


def _need_dask() -> Any:
    try:
        import dask  # noqa: F401
        import distributed
        import pandas  # type: ignore[import-untyped]  # noqa: F401
        import pyarrow  # type: ignore[import-untyped]  # noqa: F401
    except ImportError as e:
        raise ImportError(
            f"lobe.sweep needs Dask, pandas and pyarrow ({e.name} is missing): pip install 'lobe[dask]'"
        ) from e
    return distributed


def _client(workers: int | None, scheduler: Any) -> tuple[Any, Callable[[], None]]:
    """A client and how to close what was opened for it."""
    distributed = _need_dask()
    if scheduler is not None:
        if isinstance(scheduler, distributed.Client):
            return scheduler, lambda: None
        try:
            c = distributed.Client(str(scheduler), timeout="5s")
        except Exception as e:  # noqa: BLE001 - an unreachable scheduler, said before any work
            raise ConnectionError(f"scheduler {scheduler!r}: cannot connect ({type(e).__name__}: {e})") from e
        return c, c.close
    n = 2 if workers is None else int(workers)
    if n < 1:
        raise ValueError(f"workers {workers}: must be >= 1")
    # One thread per worker process, lobe's own pool included (the worker
    # processes inherit the environment): the parallelism is the workers'.
    saved = os.environ.get("RAYON_NUM_THREADS")
    os.environ["RAYON_NUM_THREADS"] = "1"
    try:
        cluster = distributed.LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=40
        )
    finally:
        if saved is None:
            del os.environ["RAYON_NUM_THREADS"]
        else:
            os.environ["RAYON_NUM_THREADS"] = saved
    c = distributed.Client(cluster)

    def close() -> None:
        c.close()
        cluster.close()

    return c, close


def _read_done(out: str) -> Any:
    import pandas as pd  # type: ignore[import-untyped]

    parts = sorted(
        os.path.join(out, f) for f in os.listdir(out) if f.endswith(".parquet") and not f.startswith(("_", "."))
    )
    if not parts:
        return None
    df = pd.concat([pd.read_parquet(p) for p in parts], ignore_index=True)
    return df.drop_duplicates("task_key", keep="first")


class _Writer:
    """Finished rows to part files of the dataset, each written whole under
    a temporary name and renamed (a part is there entirely or not at all),
    at most every ``every`` seconds or ``rows`` rows."""

    def __init__(self, out: str | None, every: float = 2.0, rows: int = 64):
        self.out, self.every, self.rows = out, every, rows
        self.pending: list[dict[str, Any]] = []
        self.last = time.monotonic()

    def add(self, row: dict[str, Any]) -> None:
        if self.out is None or row.get("error") is not None:
            return
        self.pending.append(row)
        if len(self.pending) >= self.rows or time.monotonic() - self.last >= self.every:
            self.flush()

    def flush(self) -> None:
        if self.out is None or not self.pending:
            return
        import pandas as pd  # type: ignore[import-untyped]

        name = f"part-{time.time_ns():020d}-{uuid.uuid4().hex[:8]}.parquet"
        tmp = os.path.join(self.out, f".{name}.tmp")
        pd.DataFrame(self.pending).to_parquet(tmp, index=False)
        os.replace(tmp, os.path.join(self.out, name))
        self.pending = []
        self.last = time.monotonic()


class _Progress:
    """A bar on a terminal (tqdm when it is installed, else a line redrawn),
    and a line per finished task in the log."""

    def __init__(self, total: int, done: int, log: str | None, quiet: bool):
        self.total, self.n, self.quiet = total, done, quiet
        self.log = open(log, "a", encoding="utf-8") if log else None
        self.bar = None
        if not quiet:
            try:
                from tqdm import tqdm  # type: ignore[import-untyped]

                self.bar = tqdm(total=total, initial=done, desc="sweep", unit="task", file=sys.stderr)
            except ImportError:
                pass

    def note(self, text: str) -> None:
        if self.log:
            self.log.write(f"{time.strftime('%Y-%m-%dT%H:%M:%S')} {text}\n")
            self.log.flush()

    def advance(self, row: dict[str, Any]) -> None:
        self.n += 1
        status = "failed: " + row["error"] if row.get("error") else f"done in {row['wall_s']:.3f} s"
        self.note(f"task {row['task_key']} {status}")
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.update(1)
        else:
            sys.stderr.write(f"\rsweep: {self.n}/{self.total} tasks")
            sys.stderr.flush()

    def close(self, summary: str) -> None:
        if self.bar is not None:
            self.bar.close()
        elif not self.quiet:
            sys.stderr.write("\n")
        sys.stderr.write(summary + "\n")
        self.note(summary)
        if self.log:
            self.log.close()


def sweep(
    task: str,
    grid: Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]],
    *,
    out: str | os.PathLike[str] | None = None,
    workers: int | None = None,
    scheduler: Any = None,
    quiet: bool = False,
    flush_seconds: float = 2.0,
) -> Any:
    """Run ``task`` (``"estimate"``, ``"chi2"``, ``"fit"``, ``"albedo"``)
    over ``grid`` and return a pandas DataFrame, one row per task in the
    grid's order: the parameters as columns (a material dict as canonical
    JSON text), ``task_key``, the task's results, ``error`` (None, or the
    exception of a failed task, which does not stop the sweep) and
    ``wall_s``.

    ``grid``: a dict of lists (their product) or a list of dicts.
    Parameters: ``estimate``: ``material``, ``strategy``, and ``theta``
    (degrees), ``light``, ``samples``, ``sequence`` (the columns of ``lobe
    estimate --json``, RGB triples as ``_r``, ``_g``, ``_b``); ``chi2``:
    ``material``, ``strategy``, ``theta``, ``samples``, ``res``,
    ``significance`` (``p_value``, ``passed``); ``fit``: ``file`` (a
    measured MERL or RGL file's path), ``distribution``, ``fresnel``,
    ``anisotropic`` (``fit``, the fitted material as JSON, ``fit_error``,
    ``pairs``); ``albedo``: ``material``, ``alpha``,
    ``theta``, ``walks`` (``none``, ``kulla_conty``, ``turquin``, ``walk``
    RGB, as ``lobe.furnace``). Any task takes ``seed``.

    ``out``: a Parquet dataset (a directory) the rows are written to as they
    finish; the tasks already in it are not run again, and
    ``df.attrs["computed"]`` says how many this call ran. Rows are written
    in part files at most every ``flush_seconds`` (and every 64 rows); a
    failed task is not written (a rerun tries it again). A log of every task is kept in
    ``out/_sweep.log``; the progress bar goes to stderr (none with
    ``quiet``), and the summary line at the end either way. ``workers``: worker processes of the
    ``LocalCluster`` (default 2); ``scheduler``: an address
    (``"tcp://host:8786"``) or a ``distributed.Client`` instead. Bad input
    (an unknown task or parameter, an empty grid, an unreachable scheduler)
    raises before any work starts."""
    todo = tasks(task, grid)
    _need_dask()
    import pandas as pd  # type: ignore[import-untyped]

    keys = [_key(task, p) for p in todo]
    out_dir = None if out is None else os.fspath(out)
    done = None
    if out_dir is not None:
        os.makedirs(out_dir, exist_ok=True)
        done = _read_done(out_dir)
    done_keys = set() if done is None else set(done["task_key"]) & set(keys)
    pending = [(k, p) for k, p in zip(keys, todo) if k not in done_keys]
    progress = _Progress(len(todo), len(done_keys), None if out_dir is None else os.path.join(out_dir, "_sweep.log"), quiet)
    progress.note(f"sweep {task}: {len(todo)} tasks, {len(done_keys)} already in {out_dir}")
    rows: dict[str, dict[str, Any]] = {}
    writer = _Writer(out_dir, every=float(flush_seconds))
    t0 = time.perf_counter()
    if pending:
        client, close = _client(workers, scheduler)
        try:
            from distributed import as_completed

            params = {f"lobe-{task}-{k}": p for k, p in pending}
            futures = [client.submit(run_task, task, p, key=key, pure=False) for key, p in params.items()]
            for fut in as_completed(futures):
                try:
                    row = fut.result()
                except Exception as e:  # noqa: BLE001 - a task that killed its workers
                    row = _params_row(task, params[fut.key])
                    row["error"] = f"{type(e).__name__}: {e}"
                    row["wall_s"] = None
                rows[row["task_key"]] = row
                writer.add(row)
                progress.advance(row)
        finally:
            writer.flush()
            close()
    failed = sum(1 for r in rows.values() if r.get("error"))
    summary = (
        f"sweep {task}: {len(todo)} tasks, {len(pending)} computed ({failed} failed), "
        f"{len(done_keys)} already done, {time.perf_counter() - t0:.1f} s"
    )
    progress.close(summary)
    frames = []
    if done is not None and done_keys:
        frames.append(done[done["task_key"].isin(done_keys)])
    if rows:
        frames.append(pd.DataFrame(list(rows.values())))
    df = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0]
    order = {k: i for i, k in enumerate(keys)}
    df = df.iloc[df["task_key"].map(order).argsort(kind="stable")].reset_index(drop=True)
    df.attrs["computed"] = len(pending)
    df.attrs["failed"] = failed
    return df


def _load_spec(path: str) -> dict[str, Any]:
    try:
        import tomllib
    except ImportError as e:  # Python < 3.11
        raise ImportError("lobe sweep SPEC.toml needs Python 3.11 or later (tomllib)") from e
    try:
        with open(path, "rb") as f:
            spec = tomllib.load(f)
    except OSError as e:
        raise ValueError(f"{path}: cannot read ({e.strerror})") from e
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{path}: {e}") from e
    unknown = sorted(set(spec) - {"task", "grid", "tasks", "out", "workers", "scheduler"})
    if unknown:
        raise ValueError(f"{path}: unknown key {unknown[0]!r} (keys: task, grid or tasks, out, workers, scheduler)")
    if "task" not in spec:
        raise ValueError(f"{path}: missing key 'task' (one of {', '.join(TASKS)})")
    if ("grid" in spec) == ("tasks" in spec):
        raise ValueError(f"{path}: give either [grid] (a table of lists) or [[tasks]] (a list of tables)")
    return spec


def main(argv: Sequence[str] | None = None) -> int:
    """``lobe sweep SPEC.toml [--out DIR] [--workers N] [--scheduler ADDR]``
    (also ``python -m lobe.sweeps``): run the sweep a TOML file describes
    (``task``, ``[grid]`` or ``[[tasks]]``, ``out``, ``workers``,
    ``scheduler``) and print its summary and table."""
    import argparse

    ap = argparse.ArgumentParser(prog="lobe sweep", description=main.__doc__)
    ap.add_argument("spec", help="the sweep (TOML)")
    ap.add_argument("--out", help="Parquet dataset to write and resume from (overrides the spec's)")
    ap.add_argument("--workers", type=int, help="local worker processes (overrides the spec's)")
    ap.add_argument("--scheduler", help="a Dask scheduler's address instead of a local cluster")
    ap.add_argument("--csv", help="also write the table as CSV")
    ap.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    a = ap.parse_args(argv)
    try:
        spec = _load_spec(a.spec)
        df = sweep(
            spec["task"],
            spec["grid"] if "grid" in spec else spec["tasks"],
            out=a.out or spec.get("out"),
            workers=a.workers or spec.get("workers"),
            scheduler=a.scheduler or spec.get("scheduler"),
            quiet=a.quiet,
        )
    except (ValueError, ImportError, ConnectionError) as e:
        print(f"lobe sweep: {e}", file=sys.stderr)
        return 2
    if a.csv:
        df.to_csv(a.csv, index=False)
    import pandas as pd  # type: ignore[import-untyped]

    with pd.option_context("display.max_rows", 50, "display.width", 160):
        print(df.drop(columns=["task_key"]).to_string(max_rows=50))
    return 1 if df.attrs.get("failed") else 0


if __name__ == "__main__":
    sys.exit(main())
