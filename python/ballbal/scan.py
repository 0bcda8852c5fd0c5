"""Parallel parameter scans returning polars tables.

The grid is cut into chunks along its last parameter. A chunk's rows depend only on the
grid, the options and the chunk's bounds, so the table is the same whether the chunks
run here on any number of threads, on an executor's workers (``concurrent.futures`` or
a Dask ``Client``), or partly now and partly after an interruption (``out=``).
"""

from __future__ import annotations

import json
import math
import os
import sys
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import polars as pl

from . import _check, _native
from .analysis import harmonics
from .exceptions import ParameterError, ParameterTypeError, ScanInterrupted
from .model import Balancer
from .scene import Scene

SCANNABLE = ("mu", "zeta", "zeta_b", "delta", "Omega", "eta")
#: Scene parameters a scan can vary besides the balancer's (tilt fields need a tilt).
SCENE_SCANNABLE = ("springs", "a", "b", "j_t", "j_z", "zeta_r")
_INDEXED = ("eta[", "zeta_b[")

GridSpec = Sequence[float] | np.ndarray | tuple[float, float, float] | str

MULTIPLIER = pl.List(pl.Struct({"re": pl.Float64, "im": pl.Float64}))
_SCHEMA: dict[str, Any] = {
    "type": pl.Utf8, "solution": pl.Int64, "status": pl.Utf8, "omega": pl.Float64,
    "stability": pl.Utf8, "max_modulus": pl.Float64, "trivial_error": pl.Float64,
    "multipliers": MULTIPLIER, "residual": pl.Float64, "tail": pl.Float64,
    "pivot_ratio": pl.Float64, "iterations": pl.Int64, "floquet_steps": pl.Int64,
    "floquet_error": pl.Utf8, "N": pl.Int64, "attempts": pl.Int64, "seconds": pl.Float64,
    "origin": pl.Utf8, "pb_exists": pl.Boolean, "pb_stable": pl.Boolean,
    "target_met": pl.Boolean, "hill_stability": pl.Utf8, "verdicts_disagree": pl.Boolean,
}


def grid_values(name: str, spec: GridSpec) -> np.ndarray:
    """The values of one grid axis: a sequence, an array, ``(start, stop, step)`` or
    ``"start:stop:step"`` (both ends included)."""
    if not (name in SCANNABLE or name in SCENE_SCANNABLE
            or (name.startswith(_INDEXED) and name.endswith("]"))):
        raise ParameterError(
            name, f"not a scannable parameter (choose from {', '.join(SCANNABLE)}, "
            f"eta[i], zeta_b[i]; for scenes also {', '.join(SCENE_SCANNABLE)})"
        )
    if isinstance(spec, str):
        try:
            parts = [float(p) for p in spec.split(":")]
        except ValueError as e:
            raise ParameterError(name, f"give start:stop:step, got {spec!r}") from e
        if len(parts) != 3:
            raise ParameterError(name, f"give start:stop:step, got {spec!r}")
        spec = (parts[0], parts[1], parts[2])
    if isinstance(spec, tuple) and len(spec) == 3 and not isinstance(spec, np.ndarray):
        start, stop, step = (_check.real(name, v) for v in spec)
        if not all(math.isfinite(v) for v in (start, stop, step)):
            raise ParameterError(name, f"(start, stop, step) must be finite, got {spec}")
        if step <= 0 or stop < start:
            raise ParameterError(
                name, f"(start, stop, step) needs step > 0 and stop >= start, got {spec}"
            )
        count = _check.axis_count(name, (stop - start) / step)
        vals = np.round(start + step * np.arange(count), 12)
    else:
        if spec is None or isinstance(spec, (bool, np.bool_)):
            raise ParameterTypeError(name, f"grid values must be numbers, got {spec!r}")
        try:
            vals = np.asarray(spec, dtype=float).ravel()
        except (TypeError, ValueError) as e:
            raise ParameterError(name, f"grid values must be numbers, got {spec!r}") from e
    if vals.size == 0:
        raise ParameterError(name, "the grid is empty")
    if not np.all(np.isfinite(vals)):
        raise ParameterError(name, "grid values must be finite (no NaN or inf)")
    return vals


@dataclass(frozen=True)
class _Job:
    """Everything one chunk needs: picklable, so it can travel to other processes."""

    model: Balancer | Scene
    names: tuple[str, ...]
    values: tuple[tuple[float, ...], ...]
    patterns: tuple[str, ...]
    options: tuple[tuple[str, Any], ...]
    chunk: int

    def native(self, chunks: list[int], threads: int,
               on_chunk: Callable[[int, dict[str, Any]], None]) -> None:
        o = dict(self.options)
        effects = self.model.effects_tuple() if isinstance(self.model, Scene) else None
        _native.scan(
            *self.model.native_args(), list(self.names), [list(v) for v in self.values],
            list(self.patterns), o["N"], o["samples"], o["tol"], o["step_tol"],
            o["max_iter"], o["floquet"], o["rtol"], o["atol"], o["margin"], o["max_steps"],
            o["settle"], o["window"], o["guess_rtol"], o["auto"], o["N_max"], o["hill"],
            o["seeds"], o["starts"], self.chunk,
            o["max_tail"], threads, chunks, on_chunk, effects,
        )

    def n_chunks(self) -> int:
        return math.ceil(len(self.values[-1]) / self.chunk)

    def points(self, c: int) -> int:
        outer = len(self.values[-1])
        inner = math.prod(len(v) for v in self.values[:-1])
        return inner * (min(outer, (c + 1) * self.chunk) - c * self.chunk)

    def meta(self) -> dict[str, Any]:
        return {
            "ballbal": _native.__version__,
            **({"scene": self.model.to_dict()} if isinstance(self.model, Scene)
               else {"balancer": asdict(self.model)}),
            "grid": {n: list(v) for n, v in zip(self.names, self.values, strict=True)},
            "patterns": list(self.patterns), "options": dict(self.options),
            "chunk": self.chunk,
        }


def _frame(names: Sequence[str], d: dict[str, Any]) -> pl.DataFrame:
    mult = [
        None if re is None else [{"re": r, "im": i} for r, i in zip(re, im, strict=True)]
        for re, im in zip(d["mult_re"], d["mult_im"], strict=True)
    ]
    cols: dict[str, pl.Series] = {n: pl.Series(n, d[n], dtype=pl.Float64) for n in names}
    for c, dtype in _SCHEMA.items():
        cols[c] = pl.Series(c, mult if c == "multipliers" else d[c], dtype=dtype)
    return pl.DataFrame(cols)


def _empty(names: Sequence[str]) -> pl.DataFrame:
    return pl.DataFrame(schema={**{n: pl.Float64 for n in names}, **_SCHEMA})


def run_chunk(job: _Job, c: int, threads: int = 1) -> pl.DataFrame:
    """One chunk of a scan as a DataFrame: what executors run on their workers."""
    out: list[pl.DataFrame] = []
    job.native([c], threads, lambda _c, d: out.append(_frame(job.names, d)))
    return out[0]


class _Store:
    """Finished chunks as Parquet files in a directory, with the scan's description."""

    def __init__(self, path: str | os.PathLike[str], job: _Job) -> None:
        self.dir = Path(path)
        # As it reads back from JSON (tuples become lists), to compare with the file.
        meta = json.loads(json.dumps(job.meta()))
        mfile = self.dir / "meta.json"
        if mfile.exists():
            old = json.loads(mfile.read_text())
            if old != meta:
                diff = sorted(k for k in meta if old.get(k) != meta[k])
                raise ValueError(
                    f"out: {self.dir} holds a different scan (it differs in "
                    f"{', '.join(diff)}); choose another directory or delete it"
                )
        else:
            self.dir.mkdir(parents=True, exist_ok=True)
            mfile.write_text(json.dumps(meta, indent=1))

    def file(self, c: int) -> Path:
        return self.dir / f"chunk-{c:05d}.parquet"

    def done(self) -> set[int]:
        return {int(p.stem.split("-")[1]) for p in self.dir.glob("chunk-*.parquet")}

    def write(self, c: int, df: pl.DataFrame) -> None:
        tmp = self.dir / f".chunk-{c:05d}.tmp"
        df.write_parquet(tmp)
        os.replace(tmp, self.file(c))  # a chunk file is complete or absent

    def read(self, c: int) -> pl.DataFrame:
        return pl.read_parquet(self.file(c))


class _Progress:
    def __init__(self, progress: bool | Callable[[int, int], Any], total: int,
                 done: int) -> None:
        self.total, self.done, self.bar, self.fn = total, done, None, None
        if callable(progress):
            self.fn = progress
        elif progress:
            try:
                from tqdm.auto import tqdm

                self.bar = tqdm(total=total, initial=done, unit="pt", desc="ballbal scan")
            except ImportError:
                self.fn = lambda d, t: print(f"\rballbal scan: {d}/{t} points", end="",
                                             file=sys.stderr, flush=True)

    def update(self, n: int) -> None:
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        if self.fn is not None:
            self.fn(self.done, self.total)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _as_completed(futures: list[Any]) -> Iterable[Any]:
    if futures and type(futures[0]).__module__.startswith("distributed"):
        from distributed import as_completed

        return as_completed(futures)
    from concurrent.futures import as_completed as cf_as_completed

    return cf_as_completed(futures)


def scan(
    balancer: Balancer | Scene,
    *,
    patterns: Sequence[str] = ("R-R",),
    N: int | str = 3,
    target: float = 1e-4,
    N_max: int = 32,
    hill: bool = False,
    samples: int | None = None,
    tol: float = 1e-10,
    step_tol: float = 1e-8,
    max_iter: int = 50,
    floquet: bool = True,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    margin: float = 1e-6,
    max_steps: int = 20_000,
    settle: float = 1000.0,
    window: float = 2000.0,
    guess_rtol: float = 1e-5,
    seeds: int = 4,
    starts: int = 4,
    max_tail: float = 0.25,
    chunk: int | None = None,
    threads: int | None = None,
    progress: bool | Callable[[int, int], Any] = False,
    out: str | os.PathLike[str] | None = None,
    executor: Any = None,
    grid: Mapping[str, GridSpec] | None = None,
    **axes: GridSpec,
) -> pl.DataFrame:
    """Scan parameters of ``balancer`` over a grid and return one row per solution found.

    Axes are keywords (``Omega=(1.0, 2.0, 0.1), eta=np.arange(0.4, 1.51, 0.1)``) or a
    ``grid`` mapping (needed for ``"eta[0]"``); each is a sequence, ``(start, stop, step)``
    or ``"start:stop:step"``. Any number of axes; the first varies fastest in the table.

    ``balancer`` may be an autonomous :class:`Scene` (ball springs, a tilting disk): its
    ``springs`` and tilt fields ``a``, ``b``, ``j_t``, ``j_z``, ``zeta_r`` can be axes
    too, and ``pb_exists``, ``pb_stable`` then describe its balanced state (see
    :func:`balanced_state`). A scene with a ramp, gravity or an impulse is time
    dependent and has no periodic solutions to scan: that is an error naming the effect.

    Each chunk of the grid (``chunk`` values of the last axis; default about 1024
    points) is solved in the Rust core on ``threads`` cores with the GIL released:
    simulated starts at ``seeds`` points per axis (and, for O-types, along the perfect
    balance's stability boundary) are classified by rotation pattern, then every
    solution is continued to its grid neighbours until nothing new appears. Coexisting
    solutions of one type get separate rows (``solution`` 0, 1, ...); a point and type
    with none gets one row with ``status="not_found"`` and nulls. ``max_tail`` refuses
    series whose last harmonic is that large relative to the motion (``N`` too small).

    ``N="auto"``: continuation runs at N = 3 and each solution found is refined until
    its highest harmonic and trivial multiplier error are below ``target`` (at most
    ``N_max``): easy points stay cheap; ``N`` and ``target_met`` say what each row got.
    ``hill=True`` adds Hill's-method verdicts (``hill_stability``) and flags rows where
    they contradict the monodromy's (``verdicts_disagree``).

    ``out``: a directory; each finished chunk is written there as Parquet at once, and a
    later call with the same arguments and ``out`` skips the chunks on disk (resume).
    ``executor``: a ``concurrent.futures`` executor or Dask ``Client``; the chunks run
    as its tasks (``threads`` per task, default 1) and the table is the same as here.
    ``progress``: ``True`` for a progress bar (tqdm if installed), or a callable
    ``f(done_points, total_points)``. Ctrl-C stops the scan and returns the finished
    chunks with a :class:`ScanInterrupted` warning.

    Limits (checked before any work): at most 1e6 values per axis, 5e6 grid points for a
    table held in memory and 1e9 for one streamed to ``out=``.
    """
    patterns = _check.scan_arguments(
        balancer, patterns=patterns, N_max=N_max, samples=samples, max_iter=max_iter,
        max_steps=max_steps, seeds=seeds, starts=starts, chunk=chunk, threads=threads, out=out,
        hill=hill, floquet=floquet, reals=dict(
            target=target, tol=tol, step_tol=step_tol, rtol=rtol, atol=atol, margin=margin,
            settle=settle, window=window, guess_rtol=guess_rtol, max_tail=max_tail))
    axes_all: dict[str, GridSpec] = dict(grid or {})
    for k, v in axes.items():
        if k in axes_all:
            raise ParameterError(k, "given twice (keyword and grid)")
        axes_all[k] = v
    if not axes_all:
        raise ParameterError("grid", "give at least one parameter to scan, e.g. "
                             "Omega=(1, 2, 0.1)")
    names = tuple(axes_all)
    model: Balancer | Scene = balancer
    if (isinstance(model, Scene) and model.native_effects() is None
            and not set(names) & set(SCENE_SCANNABLE)):
        model = model.balancer  # the same table, and a scan directory it can resume
    values = tuple(tuple(grid_values(n, s).tolist()) for n, s in axes_all.items())
    _check.grid_points([len(v) for v in values], names, streamed=out is not None)
    if isinstance(patterns, str):
        patterns = (patterns,)
    if not patterns:
        raise ParameterError("patterns", "give at least one solution type, e.g. ['R-R']")
    if chunk is None:
        chunk = _native.default_chunk([len(v) for v in values])
    if int(chunk) < 1:
        raise ParameterError("chunk", f"must be >= 1, got {chunk}")
    local_threads = (os.cpu_count() or 1) if threads is None else int(threads)
    if local_threads < 1:
        raise ParameterError("threads", f"must be >= 1, got {threads}")
    n0, auto = harmonics(N, target)
    options = (
        ("N", n0), ("auto", auto), ("N_max", int(N_max)), ("hill", bool(hill)),
        ("samples", None if samples is None else int(samples)),
        ("tol", float(tol)), ("step_tol", float(step_tol)), ("max_iter", int(max_iter)),
        ("floquet", bool(floquet)), ("rtol", float(rtol)), ("atol", float(atol)),
        ("margin", float(margin)), ("max_steps", int(max_steps)), ("settle", float(settle)),
        ("window", float(window)), ("guess_rtol", float(guess_rtol)), ("seeds", int(seeds)),
        ("starts", int(starts)), ("max_tail", float(max_tail)),
    )
    job = _Job(model, names, values, tuple(str(p) for p in patterns), options, int(chunk))
    # Validates everything (grid values, combinations, options) before any work.
    job.native([], 1, lambda _c, _d: None)

    store = _Store(out, job) if out is not None else None
    n = job.n_chunks()
    frames: dict[int, pl.DataFrame] = {}
    if store is not None:
        for c in sorted(store.done()):
            if c < n:
                frames[c] = store.read(c)
    todo = [c for c in range(n) if c not in frames]
    total = sum(job.points(c) for c in range(n))
    bar = _Progress(progress, total, sum(job.points(c) for c in frames))

    def keep(c: int, df: pl.DataFrame) -> None:
        frames[c] = df
        if store is not None:
            store.write(c, df)
        bar.update(job.points(c))

    try:
        if todo and executor is not None:
            per_task = 1 if threads is None else local_threads
            futures = [executor.submit(run_chunk, job, c, per_task) for c in todo]
            index = dict(zip(futures, todo, strict=True))
            try:
                for f in _as_completed(futures):
                    keep(index[f], f.result())
            except KeyboardInterrupt:
                for f in futures:
                    f.cancel()
                raise
        elif todo:
            job.native(todo, local_threads, lambda c, d: keep(c, _frame(names, d)))
    except KeyboardInterrupt:
        warnings.warn(
            ScanInterrupted(
                f"scan interrupted: {len(frames)} of {n} chunks finished"
                + (f" and kept in {store.dir}; run the same scan again to resume"
                   if store is not None else "; pass out= to keep chunks on disk")
            ),
            stacklevel=2,
        )
    finally:
        bar.close()
    if not frames:
        return _empty(names)
    return pl.concat([frames[c] for c in sorted(frames)], how="vertical")


def read_scan(path: str | os.PathLike[str]) -> pl.DataFrame:
    """The table of a scan written with ``out=path`` (the finished chunks, in order)."""
    d = Path(_check.path("path", path))
    files = sorted(d.glob("chunk-*.parquet"))
    if not files:
        raise ParameterError("path", f"no scan chunks (chunk-*.parquet) in {d}")
    return pl.concat([pl.read_parquet(f) for f in files], how="vertical")


def scan_meta(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The description (balancer, grid, options) stored with a scan written with ``out=``."""
    return dict(json.loads((Path(path) / "meta.json").read_text()))
