"""Basins of attraction in the plane of the initial ball angles (Tien's (2011) figures
4-15 and 4-16).

Every start is at rest in the ground frame (``x = x' = y = y' = 0``, ``b_i' = -Omega``
in the rotating frame) with given ball angles, simulated in the Rust core for ``t_end``
time units (Tien (2011): 1000) and labelled by the motion over the last ``window``
(:mod:`ballbal_core::analysis::basins`): ``perfect_balance`` (rest with ``|x + i y|``
below ``rest_tol``), ``other_equilibrium``, ``merged_R-R`` (both balls rotate with
their gap below ``merge_tol``), ``separated_R-R`` (both rotate apart: the gap
oscillates or they pass each other), ``R-O``, ``O-O``, ``other`` (not two balls),
``not_settled`` and ``failed``. A start is at rest early once every velocity is below
1e-7 (the simulation stops there: ``t_stop``). Starts run in parallel, each on its own,
so the table does not depend on the thread count.

A start whose motion is not settled after ``t_end`` (``not_settled``, or a moving class
whose period does not repeat over its last three periods to 1e-3: a torus too, whose
steady look at 1000 time units was, on Tien's (2011) Omega 1.2 grid, separated rotations
still converging) is simulated further, ``t_end`` at a time, up to ``extend_factor *
t_end`` in all (``extensions`` counts the extensions); what is still unsettled then
keeps its label (``motion``: ``not_settled`` or ``quasi_periodic``). Every periodic
class is then linked to its orbit: the harmonic balance solved from the series fitted to
a representative start's own motion (:func:`ballbal.analysis.periodic`, with its
windings: Tien's (2011) balls rotating separately take two turns per period, windings
``(-2, -2)``), each start pointing at it by the ``orbit`` column (see :func:`basins`).

The default grid avoids the diagonal ``b1 = b2``: merged balls stay merged in
simulation (the diagonal is invariant for identical balls), so a start on it says
nothing about its neighbourhood.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import polars as pl

from . import _check, _native
from ._progress import Progress
from .exceptions import ParameterError, ParameterTypeError, ScanInterrupted, ScanStoreError
from .model import Balancer
from .options import _Execution
from .scan import SCHEMA
from .scene import Scene, model_argument

LABELS = ("perfect_balance", "other_equilibrium", "merged_R-R", "separated_R-R", "R-O",
          "O-O", "other", "not_settled", "failed")
#: Labels of rest (an equilibrium).
REST = ("perfect_balance", "other_equilibrium")
#: Labels of motions in which a ball rotates.
ROTATING = ("merged_R-R", "separated_R-R", "R-O")
#: Relative tolerance of linking a start to an orbit: its simulated period and the mean
#: rates of its rotating balls within this fraction of the orbit's (the simulated
#: periods repeat to 1e-3 and agree with the orbits' to about 1e-5; distinct orbits of
#: one class and winding differ by more). Over it, a new orbit is solved.
LINK_TOL = 0.01
#: The columns a chunk's native call returns, none of them filled: a table of no rows.
_NO_ROWS: dict[str, list[Any]] = {k: [] for k in (
    "label", "pattern", "omega", "period", "rate1", "rate2", "t_stop", "motion",
    "winding1", "winding2", "extensions", "long_label", "state")}
#: Columns of :attr:`Basins.orbits`: the basin's own, and the periodic solution's
#: fields with the types of a scan's table (:data:`ballbal.scan.SCHEMA`), which the core
#: declares.
ORBIT_SCHEMA = {
    "orbit": pl.Int64, "label": pl.Utf8, "pattern": pl.Utf8, "winding1": pl.Int64,
    "winding2": pl.Int64, "count": pl.Int64, "period_simulated": pl.Float64,
    "omega": SCHEMA["omega"], "period": pl.Float64, "period_difference": pl.Float64,
    **{k: SCHEMA[k] for k in ("status", "stability", "max_modulus", "modulus_error", "N")},
    "b1": pl.Float64, "b2": pl.Float64,
}


@dataclass(frozen=True)
class BasinOptions:
    """How each start is simulated and judged (see the module's description).

    ``t_end``: time simulated; ``window``: the final part of it the label is read from
    (a rotating ball must turn at least once per half of it, so ``window`` bounds the
    slowest rotation recognised: ``omega >= 4 pi / window``); ``rtol, atol``: the
    integrator's tolerances; ``settle_factor``: with the settle check, the longer run's
    length in units of ``t_end``; ``early_stop``: end a start's simulation before
    ``t_end`` once its attractor is clear — a periodic orbit whose Poincare section
    (the whole turns of a rotating ball) has converged, or a clean decay to rest —
    with the label the full run gives (``t_stop`` says where it stopped; the settle
    check's longer run and speed sweeps always run to the end); ``extend_factor``:
    the longest total time a start is simulated, in units of ``t_end`` (a start not
    settled after ``t_end`` is extended by ``t_end`` at a time until it is; 1: never;
    in ``[1, 64]``; speed sweeps never extend).
    """

    t_end: float = 1000.0
    window: float = 300.0
    rtol: float = 1e-6
    atol: float = 1e-8
    rest_tol: float = 0.05
    merge_tol: float = 0.5
    settle_factor: float | None = None
    early_stop: bool = True
    extend_factor: float = 8.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "early_stop", _check.boolean("early_stop", self.early_stop))
        for n in ("t_end", "window", "rtol", "atol", "rest_tol", "merge_tol", "extend_factor"):
            object.__setattr__(self, n, _check.real(n, getattr(self, n)))
        if self.settle_factor is not None:
            object.__setattr__(self, "settle_factor",
                               _check.real("settle_factor", self.settle_factor))
        _native.validate_basin_options(self)


@dataclass(frozen=True)
class Basins:
    """The result of :func:`basins`.

    ``table``: one row per start (``b1, b2, b1_index, b2_index`` (the start's position
    on each axis, for exact joins; null for random starts), ``label, pattern, omega``
    (mean ball rate of
    the rotating balls), ``period`` (null unless regular), ``rate1, rate2`` (each
    ball's mean rate), ``t_stop`` (time simulated in all), ``motion`` (``rest``,
    ``periodic``: a period that repeats over the last three periods to 1e-3,
    ``quasi_periodic``: moving without one, a torus or a motion that did not repeat
    within ``extend_factor * t_end``, ``not_settled``, ``failed``), ``winding1,
    winding2`` (each ball's whole turns per period, negative lagging the disk; null
    without a period), ``extensions`` (times the start was simulated ``t_end``
    further), ``orbit`` (the row of :attr:`orbits` a periodic start is linked to, null
    for every other motion), and with the settle check ``long_label`` and
    ``settled``).

    ``orbits``: one row per distinct periodic orbit the starts reached (columns
    :data:`ORBIT_SCHEMA`: its class ``label``, ``pattern`` and windings, ``count`` of
    starts, ``period_simulated`` (its representative start's period), the harmonic
    balance's ``omega`` and ``period = 2 pi / omega``, ``period_difference`` (the
    relative difference of that period from the simulated one), ``status``, ``stability``,
    ``max_modulus``, ``modulus_error`` and ``N`` of :func:`ballbal.analysis.periodic`,
    and ``b1, b2``: the representative start). ``status`` ``mismatch``: the solve
    converged to another orbit (its period more than :data:`LINK_TOL` from the
    simulated one; no verdict given); empty when linking was not asked for or the call
    was interrupted.
    """

    model: Balancer | Scene
    table: pl.DataFrame
    options: BasinOptions
    random: bool = False
    #: Ctrl-C stopped the call: ``table`` holds only the finished chunks' starts.
    interrupted: bool = False
    _links: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    orbits: pl.DataFrame = field(default_factory=lambda: pl.DataFrame(schema=ORBIT_SCHEMA))

    def _summary(self) -> list[str]:
        """Lines of the short description: the classes' counts and the orbits."""
        lines = [f"Basins: {self.table.height} starts"
                 + (" (interrupted)" if self.interrupted else "")]
        counts = self.table.group_by("label").agg(pl.len()).sort("len", descending=True)
        lines.append("  " + ", ".join(f"{r[0]} {r[1]}" for r in counts.iter_rows()))
        if "motion" in self.table.columns:
            q = self.table.filter(pl.col("motion") == "quasi_periodic").height
            if q:
                lines.append(f"  {q} quasi-periodic (no regular period): not linked")
        for o in self.orbits.iter_rows(named=True):
            om = "-" if o["omega"] is None else f"{o['omega']:.6g}"
            lines.append(f"  orbit {o['orbit']}: {o['label']} windings "
                         f"({o['winding1']}, {o['winding2']}), {o['count']} starts, "
                         f"omega {om}, {o['status']}, {o['stability']}")
        return lines

    def __repr__(self) -> str:
        lines = self._summary()
        if len(lines) > 6:  # a notebook's summary stays short: the orbits are in .orbits
            lines = [*lines[:5], f"  ... {len(lines) - 5} more lines: see .orbits"]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        from ._style import html_table

        rows: list[tuple[str, Any]] = [
            (r["label"], f"{r['count']} ({r['fraction']:.1%} ± {r['standard_error']:.1%})")
            for r in self.fractions.iter_rows(named=True)]
        for o in self.orbits.head(10).iter_rows(named=True):
            om = "-" if o["omega"] is None else f"{o['omega']:.6g}"
            rows.append((f"orbit {o['orbit']}", f"{o['label']} windings ({o['winding1']}, "
                         f"{o['winding2']}), {o['count']} starts, omega {om}, "
                         f"{o['status']}, {o['stability']}"))
        return html_table(self._summary()[0], rows)

    def plot(self, ax: Any = None) -> Any:
        """The basin map (:func:`plot_basins`); returns the axes."""
        return plot_basins(self, ax=ax)

    @property
    def fractions(self) -> pl.DataFrame:
        """Fraction of the starts in each class with its standard error
        ``sqrt(p (1 - p) / n)`` (binomial; for random starts it is the sampling error of
        the basin's area fraction, for a grid an estimate of it)."""
        n = self.table.height
        return (self.table.group_by("label").agg(pl.len().alias("count"))
                .with_columns((pl.col("count") / n).alias("fraction"))
                .with_columns((pl.col("fraction") * (1 - pl.col("fraction")) / n)
                              .sqrt().alias("standard_error"))
                .sort("count", descending=True))

    def rotating_fraction(self) -> tuple[float, float]:
        """Fraction (and its standard error) of starts that end with a rotating ball."""
        n = self.table.height
        if n == 0:
            return math.nan, math.nan
        p = self.table.filter(pl.col("label").is_in(ROTATING)).height / n
        return p, math.sqrt(p * (1 - p) / n)

    def link(self, *, N: int = 8) -> pl.DataFrame:  # noqa: N803
        """Each class found, linked to the solution it converges to: the perfect balance
        to the ``equilibria()`` entry (omega 0 and its stability), every class with a
        regular period (merged R-R, separated R-R, R-O, O-O, ...) to ``periodic()`` of
        its pattern and windings, solved from the series fitted to its first start's own
        simulated attractor (each start's own orbit: :attr:`orbits`).
        Columns ``label, count, mean_rate`` (the class's mean ball rate), ``kind``,
        ``omega``, ``stability``, ``status`` (null where nothing is linked). ``N``:
        the harmonics of the fitted series and of the solves, in ``[1, 256]``."""
        from .analysis import equilibria, periodic

        N = _check.integer("N", N, 1, 256)  # noqa: N806 - the harmonics' symbol
        rows = []
        for label in self.table["label"].unique(maintain_order=True).to_list():
            cls = self.table.filter(pl.col("label") == label)
            row: dict[str, Any] = {"label": label, "count": cls.height,
                                   "mean_rate": float(np.mean(cls["omega"].to_numpy())),
                                   "kind": None, "omega": None, "stability": None,
                                   "status": None}
            if label == "perfect_balance":
                eq = [e for e in equilibria(self.model) if e.kind == "perfect_balance"]
                if eq:
                    row.update(kind="equilibrium", omega=0.0, stability=eq[0].stability,
                               status="converged")
            elif cls["period"].null_count() < cls.height and label != "not_settled":
                first = cls.filter(pl.col("period").is_not_null()).sort(
                    pl.col("motion") != "periodic" if "motion" in cls.columns else pl.lit(0),
                    maintain_order=True).row(0, named=True)
                sol = self._periodic_of(first, N, periodic)
                if sol is not None:
                    row.update(kind=sol.type, omega=sol.omega, stability=sol.stability,
                               status=sol.status)
            rows.append(row)
        return pl.DataFrame(rows, schema={
            "label": pl.Utf8, "count": pl.Int64, "mean_rate": pl.Float64, "kind": pl.Utf8,
            "omega": pl.Float64, "stability": pl.Utf8, "status": pl.Utf8})

    def _periodic_of(self, row: dict[str, Any], N: int, periodic: Any) -> Any:  # noqa: N803
        m = self.model
        d = len(m.coordinates)
        n = m.n_balls
        y0 = np.zeros(2 * d)
        balls = [row[f"b{i + 1}"] for i in range(n)]
        y0[d - n:d] = balls
        y0[2 * d - n:] = -m.Omega
        o = self.options
        # After as long as the start was simulated.
        wind = [row.get(f"winding{i + 1}") for i in range(n)]
        return _fitted_orbit(m, y0, None if None in wind else wind,
                             min(max(o.t_end, row.get("t_stop") or 0), 1e5),
                             max(o.window, 20 * row["period"]), o, N, periodic)


def _fitted_orbit(model: Balancer | Scene, y0: Any, wind: Sequence[Any] | None, settle: float,
                  window: float, options: BasinOptions, N: int,  # noqa: N803
                  periodic: Any) -> Any:
    """:func:`ballbal.analysis.periodic` of the attractor reached from ``y0``: the series
    fitted to it after ``settle`` time units, observed for ``window`` at a thousandth of
    the basin run's tolerances over as many whole turns per period as the windings
    ``wind`` say (two for Tien's (2011) separated rotations; any pattern without them),
    solved with its pattern and those windings. ``None`` when no series is fitted."""
    d = len(model.coordinates)
    rot = None if wind is None else [w != 0 for w in wind]
    turns = next((abs(w) for w in wind if w), 1) if wind is not None else 1
    got = _native.attractor_series(model, np.asarray(y0, dtype=np.float64), N, settle,
                                   window, options.rtol * 1e-3, options.atol * 1e-3, rot,
                                   turns)
    if got is None:
        return None
    omega, coeffs, rotating = got
    pattern = "-".join("R" if r else "O" for r in rotating)
    return periodic(model, pattern, guess=(omega, coeffs.reshape(d, -1)), N=N,
                    windings=wind if rot is not None and any(rot) else None)


class _BasinStore:
    """Finished chunks of a basin grid as Parquet files in a directory (``basins(...,
    out=...)``), with the scan store's guarantees (:class:`ballbal.scan._Store`, whose
    locking, atomic writes and setting aside of damaged files it reuses): a later call
    with the same arguments skips the chunks on disk; a chunk file that is unreadable,
    changed since it was written (its checksum), of another grid or another chunk's
    position, or short is set aside in ``<out>.damaged`` beside the directory with a
    :class:`~ballbal.exceptions.ScanStoreWarning` and recomputed. The grid's description
    is a Parquet file of no rows (``_scan.parquet``), so the directory holds only the
    table's files (``polars.read_parquet(out)`` reads them)."""

    def __init__(self, path: str | os.PathLike[str], meta: dict[str, Any],
                 empty: pl.DataFrame) -> None:
        from .scan import _Store

        class Store(_Store):
            def _open(self, job: Any, chunk_given: bool) -> Any:
                want = json.loads(json.dumps(meta))
                old = self._old_description("basins")
                if old is not None and old != want:
                    raise ScanStoreError(f"out: {self.dir} holds a different basin grid; "
                                         "choose another directory or delete it")
                self._describe(want, empty)
                return job

        self.store = Store(path, None, False)  # type: ignore[arg-type]

    def done(self, sizes: dict[int, int]) -> set[int]:
        """The chunks on disk that can be trusted (this grid's, at their position, with
        their checksum and every start); the others are set aside."""
        from .scan import _chunk_index, _sealed_problem

        st = self.store
        ok = set()
        for f in sorted(st.dir.glob("chunk-*.parquet")):
            c = _chunk_index(f)
            why: str | None
            if c is None:
                why = "not a chunk file name"
            elif c not in sizes:
                why = f"chunk {c} is outside the grid"
            else:
                why, data = _sealed_problem(f, st.fingerprint, c, "grid")
                if why is None:
                    try:
                        if pl.read_parquet(io.BytesIO(data)).height != sizes[c]:
                            why = "it misses starts of its chunk"
                    except Exception as e:  # noqa: BLE001 - any failure to read: damaged
                        why = f"unreadable: {type(e).__name__}"
            if why is None and c is not None:
                ok.add(c)
            else:
                st._set_aside(f, why or "", "recomputed")
        return ok

    def write(self, c: int, df: pl.DataFrame) -> None:
        self.store.write(c, df)

    def read(self, c: int) -> pl.DataFrame:
        return pl.read_parquet(self.store.file(c))

    def close(self) -> None:
        self.store.close()


def _run_chunk(model: Balancer | Scene, starts: list[list[float]], options: BasinOptions,
               threads: int) -> dict[str, Any]:
    """One chunk's columns: what an executor's workers run."""
    out: list[dict[str, Any]] = []
    _native.basins(model, starts, options, threads, len(starts), [0],
                   lambda _c, cols: out.append(cols))
    return out[0]


def _axis(name: str, v: Any) -> np.ndarray:
    """A grid axis of angles, written as every gridded function's
    (:func:`ballbal._check.axis`: ``(start, stop, step)`` with ``stop`` included, or
    explicit values; a 2-D array is refused, not flattened; NaN is named here rather
    than as the core's ``starts``)."""
    return _check.axis(name, v, _check.MAX_BASIN_STARTS)


def _seed(v: Any) -> int | None:
    """``seed``: None (fresh entropy) or a non-negative integer, as numpy's
    ``default_rng`` takes it, checked here so that its errors name ``seed``."""
    return _check.optional_integer("seed", v, 0, 2**64 - 1)


def default_grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` values per axis over ``[0, 2 pi)``: ``b1`` at ``(i + 1/4) h``, ``b2`` at
    ``(j + 3/4) h`` (``h = 2 pi / n``), so that no start lies on the diagonal. ``n`` is
    at most ``sqrt(MAX_BASIN_STARTS)`` (1000)."""
    n = _check.integer("n", n, 1, math.isqrt(_check.MAX_BASIN_STARTS))
    h = 2 * np.pi / n
    return (np.arange(n) + 0.25) * h, (np.arange(n) + 0.75) * h


def basins(
    model: Balancer | Scene,
    *,
    b1: Sequence[float] | np.ndarray | None = None,
    b2: Sequence[float] | np.ndarray | None = None,
    n: int | None = None,
    samples: int | None = None,
    seed: int | None = None,
    t_end: float = 1000.0,
    settle_check: bool = False,
    options: BasinOptions | None = None,
    orbits: bool = True,
    N: int = 8,  # noqa: N803 - the harmonics' symbol
    threads: int | None = None,
    chunk: int | None = None,
    executor: Any = None,
    progress: bool | Callable[[int, int], Any] = False,
    out: str | os.PathLike[str] | None = None,
) -> Basins:
    """Label the starts of a grid (or random sample) of initial ball angles by the
    attractor they reach; two balls.

    Starts: ``b1`` and ``b2`` axis values (every pair of the product), or ``n`` per
    axis on the default grid (:func:`default_grid`, offset from the diagonal; default
    ``n = 20``), or ``samples`` uniform random starts in ``[0, 2 pi)^2`` from ``seed``.
    ``t_end``: time simulated per start (Tien (2011): 1000; overrides ``options``).
    ``settle_check``: simulate every start again for ``3 t_end`` (``options.
    settle_factor``) and report ``long_label`` and ``settled`` (the labels agree).
    Where it runs, as for :func:`ballbal.scan` (none of it changes the table):
    ``threads`` (default all cores), ``chunk`` (starts per task,
    default 256) and ``out`` (a directory the finished chunks are written to as
    Parquet and resumed from, with the scan store's checks: see :class:`_BasinStore`);
    Ctrl-C stops the work and returns the finished chunks' starts (in chunk order) with
    a :class:`~ballbal.exceptions.ScanInterrupted` warning, as :func:`ballbal.scan`
    does (with ``out`` they are also on disk, and the same call resumes);
    ``executor``: a ``concurrent.futures`` executor or Dask ``Client`` running the
    chunks as tasks (``threads`` per task, default 1); ``progress``: True for a
    progress bar over the starts (tqdm, notebook-aware) or a callable ``f(done,
    total)``. None of it changes the table.

    ``orbits``: link every periodic start to its orbit (:attr:`Basins.orbits`, the
    table's ``orbit`` column; see :func:`_link_orbits`), solved with ``N`` harmonics
    (in ``[1, 256]``); not done for an interrupted call.

    At most :data:`~ballbal._check.MAX_BASIN_STARTS` starts (``n <= 1000``); ``b1`` and
    ``b2`` are flat lists of finite angles; ``seed`` (a non-negative integer) goes with
    ``samples`` only. Bad arguments raise a
    :class:`~ballbal.exceptions.ParameterError` naming them before any start is made.
    """
    model_argument("model", model)
    if model.n_balls != 2:
        raise ParameterError("model", f"basins are drawn for two balls, got {model.n_balls}")
    options = _check.option("options", options, BasinOptions, BasinOptions(),
                            "ballbal.basins.BasinOptions")
    execution = _Execution(threads=threads, chunk=chunk, executor=executor,
                           progress=progress, out=out)
    t_end = _check.real("t_end", t_end)
    window = min(options.window, t_end)
    factor = options.settle_factor
    if _check.boolean("settle_check", settle_check) and factor is None:
        factor = 3.0
    options = BasinOptions(t_end, window, options.rtol, options.atol, options.rest_tol,
                           options.merge_tol, factor if settle_check else None,
                           options.early_stop, options.extend_factor)
    link = _check.boolean("orbits", orbits)
    N = _check.integer("N", N, 1, 256)  # noqa: N806 - the harmonics' symbol
    chunk = 256 if execution.chunk is None else execution.chunk
    if chunk < 1:
        raise ParameterError("chunk", f"must be >= 1, got {chunk}", allowed=">= 1",
                             value=chunk)
    # The core's checks of the model and the options, on no starts: before the starts
    # are made and before ``out`` is written to.
    _native.basins(model, [], options, 1, 1, [], lambda _c, _cols: None)
    random = samples is not None
    if random:
        if b1 is not None or b2 is not None or n is not None:
            raise ParameterError("samples", "give either samples (with seed) or a grid")
        k = _check.integer("samples", samples, 1, _check.MAX_BASIN_STARTS)
        rng = np.random.default_rng(_seed(seed))
        pts = rng.uniform(0.0, 2 * np.pi, size=(k, 2))
        s1, s2 = pts[:, 0], pts[:, 1]
        # random starts lie on no axis
        i1 = i2 = np.full(k, None, dtype=object)
    else:
        if seed is not None:
            raise ParameterError("seed", "draws random starts: give it with samples, not "
                                 "with a grid", value=seed)
        if (b1 is None) != (b2 is None):
            raise ParameterError("b1" if b1 is None else "b2", "give both axes, or n")
        if b1 is not None and b2 is not None:
            if n is not None:
                raise ParameterError("n", "give either n or the axes b1, b2")
            a1, a2 = _axis("b1", b1), _axis("b2", b2)
            # the longer axis is the one to cut
            _check.at_most("b1" if a1.size >= a2.size else "b2", a1.size * a2.size,
                           _check.MAX_BASIN_STARTS, "starts (len(b1) * len(b2))")
        else:
            a1, a2 = default_grid(20 if n is None else n)
        g1, g2 = np.meshgrid(a1, a2, indexing="xy")
        s1, s2 = g1.ravel(), g2.ravel()
        # each start's position on its axes: joins on these are exact
        j1, j2 = np.meshgrid(np.arange(a1.size), np.arange(a2.size), indexing="xy")
        i1, i2 = j1.ravel(), j2.ravel()
    starts = [[float(x), float(y)] for x, y in zip(s1, s2, strict=True)]
    threads = (os.cpu_count() or 1) if execution.threads is None else execution.threads
    n_chunks = -(-len(starts) // chunk)
    sizes = {c: min(len(starts), (c + 1) * chunk) - c * chunk for c in range(n_chunks)}
    parts: dict[int, pl.DataFrame] = {}

    def frame(c: int, cols: dict[str, Any], size: int | None = None) -> pl.DataFrame:
        lo = c * chunk
        hi = lo + (sizes[c] if size is None else size)
        return pl.DataFrame({
            "b1": s1[lo:hi], "b2": s2[lo:hi],
            "b1_index": pl.Series(i1[lo:hi].tolist(), dtype=pl.Int64),
            "b2_index": pl.Series(i2[lo:hi].tolist(), dtype=pl.Int64),
            "label": pl.Series(cols["label"], dtype=pl.Utf8),
            "pattern": pl.Series(cols["pattern"], dtype=pl.Utf8),
            "omega": pl.Series(cols["omega"], dtype=pl.Float64),
            "period": pl.Series(cols["period"], dtype=pl.Float64),
            "rate1": pl.Series(cols["rate1"], dtype=pl.Float64),
            "rate2": pl.Series(cols["rate2"], dtype=pl.Float64),
            "t_stop": pl.Series(cols["t_stop"], dtype=pl.Float64),
            "motion": pl.Series(cols["motion"], dtype=pl.Utf8),
            "winding1": pl.Series(cols["winding1"], dtype=pl.Int64),
            "winding2": pl.Series(cols["winding2"], dtype=pl.Int64),
            "extensions": pl.Series(cols["extensions"], dtype=pl.Int64),
            "long_label": pl.Series(cols["long_label"], dtype=pl.Utf8),
            "state": pl.Series(cols["state"], dtype=pl.List(pl.Float64)),
        })

    store = None
    if execution.out is not None:
        meta = {"ballbal": _native.__version__, "basins": {
            "model": model.to_dict() if isinstance(model, Scene) else asdict(model),
            "starts": hashlib.sha256(np.stack([s1, s2]).tobytes()).hexdigest(),
            "count": len(starts), "options": asdict(options), "chunk": chunk,
            # chunks written before the index columns hold other columns
            "columns": ["b1", "b2", "b1_index", "b2_index"]}}
        store = _BasinStore(execution.out, meta, frame(0, _NO_ROWS, 0))
    done: set[int] = set()
    todo: list[int] = []
    interrupted = False
    from .scan import _as_completed, _interrupted

    meter: list[Progress] = []  # made once the finished chunks on disk are known

    def keep(c: int, cols: dict[str, Any]) -> None:
        df = frame(c, cols)
        if store is not None:
            store.write(c, df)
        parts[c] = df
        for m in meter:
            m.update(sizes[c])

    def work() -> None:
        nonlocal done, todo
        done = store.done(sizes) if store is not None else set()
        todo = [c for c in range(n_chunks) if c not in done]
        meter.append(Progress(execution.progress, len(starts), "ballbal basins", "start",
                              done=sum(sizes[c] for c in done)))
        if todo and execution.executor is not None:
            per_task = 1 if execution.threads is None else threads
            futures = {execution.executor.submit(
                _run_chunk, model, starts[c * chunk:c * chunk + sizes[c]], options,
                per_task): c for c in todo}
            try:
                for f in _as_completed(list(futures)):
                    keep(futures[f], f.result())
            except KeyboardInterrupt:
                for f in futures:
                    f.cancel()
                raise
        elif todo:
            _native.basins(model, starts, options, threads, chunk, todo, keep)
        for c in done:
            assert store is not None
            parts[c] = store.read(c)

    try:
        interrupted = _interrupted(work)
        if interrupted:
            if store is not None:
                # Ctrl-C can land between a chunk's atomic rename and `parts[c] = ...`:
                # a file that exists is whole, so it belongs to the table returned now.
                for c in todo:
                    if c not in parts and store.store.file(c).exists():
                        parts[c] = store.read(c)
                for c in done:
                    parts.setdefault(c, store.read(c))
            warnings.warn(
                ScanInterrupted(
                    f"basins interrupted: {len(parts)} of {n_chunks} chunks finished"
                    + (f" and kept in {execution.out}; run the same call again to resume"
                       if store is not None
                       else "; pass out= to keep chunks on disk")
                ),
                stacklevel=2,
            )
    finally:
        for m in meter:
            m.close()
        if store is not None:
            store.close()
    df = (pl.concat([parts[c] for c in sorted(parts)], how="vertical") if parts
          else frame(0, _NO_ROWS, 0))
    states = df["state"].to_list()
    df = df.drop("state")
    if settle_check:
        df = df.with_columns((pl.col("label") == pl.col("long_label")).alias("settled"))
    else:
        df = df.drop("long_label")
    orbit_col: list[int | None] = [None] * df.height
    orbit_table = pl.DataFrame(schema=ORBIT_SCHEMA)
    if link and not interrupted:
        orbit_col, orbit_table = _link_orbits(model, df, states, options, N)
    df = df.with_columns(pl.Series("orbit", orbit_col, dtype=pl.Int64))
    return Basins(model, df, options, random, interrupted, orbits=orbit_table)


def _link_orbits(model: Balancer | Scene, table: pl.DataFrame, states: list[list[float]],
                 options: BasinOptions, N: int,  # noqa: N803
                 ) -> tuple[list[int | None], pl.DataFrame]:
    """Links every ``periodic`` start of ``table`` to an orbit: the first orbit (in the
    order they were found) of its label and windings whose period and rotating balls'
    mean rates are within :data:`LINK_TOL` of its own; when none is, a new orbit is
    solved from this start (it becomes the orbit's representative): the series fitted
    to its motion from ``states`` (the state it ended in, on its attractor: settled for
    ten periods more, observed for twenty at a thousandth of the basin run's
    tolerances, over as many whole turns per period as its windings say), then
    :func:`ballbal.analysis.periodic` of its pattern and windings from that series.
    An orbit's reference period is the solved one where it matches the simulated one,
    else the representative's. Rows in table order, so the result is that of the
    table. The balls' exchange maps an orbit of identical balls onto one of the same
    period and rates, which shares its index. Returns the ``orbit`` column and the
    orbits' table."""
    from .analysis import periodic

    col: list[int | None] = [None] * table.height
    found: list[dict[str, Any]] = []
    refs: list[tuple[float, list[float]]] = []  # (period, rates) matched against
    for k, r in enumerate(table.iter_rows(named=True)):
        if r["motion"] != "periodic" or r["period"] is None:
            continue
        wind = (r["winding1"], r["winding2"])
        rates = [r["rate1"], r["rate2"]]
        hit = None
        for j, o in enumerate(found):
            per, ref_rates = refs[j]
            if (o["label"] == r["label"] and (o["winding1"], o["winding2"]) == wind
                    and abs(r["period"] - per) <= LINK_TOL * per
                    and all(abs(a - b) <= LINK_TOL * abs(b)
                            for a, b, w in zip(rates, ref_rates, wind, strict=True) if w)):
                hit = j
                break
        if hit is None:
            row, ref = _solve_orbit(model, r, states[k], options, N, periodic)
            row["orbit"] = len(found)
            found.append(row)
            refs.append((ref, rates))
            hit = row["orbit"]
        found[hit]["count"] += 1
        col[k] = hit
    return col, pl.DataFrame(found, schema=ORBIT_SCHEMA)


def _solve_orbit(model: Balancer | Scene, r: dict[str, Any], state: list[float],
                 options: BasinOptions, N: int,  # noqa: N803
                 periodic: Any) -> tuple[dict[str, Any], float]:
    """The orbits-table row of the orbit reached by the start ``r`` (ending in
    ``state``) and the period later starts are matched against."""
    wind = [int(r["winding1"]), int(r["winding2"])]
    rotating = [w != 0 for w in wind]
    per = float(r["period"])
    row: dict[str, Any] = {
        "label": r["label"], "pattern": "-".join("R" if x else "O" for x in rotating),
        "winding1": wind[0], "winding2": wind[1], "count": 0, "period_simulated": per,
        "omega": None, "period": None, "period_difference": None, "status": "no_guess",
        "stability": None, "max_modulus": None, "modulus_error": None, "N": None,
        "b1": r["b1"], "b2": r["b2"]}
    cap = 1e5  # GuessOptions' longest settle and window
    sol = _fitted_orbit(model, state, wind, min(10 * per, cap),
                        min(max(options.window, 20 * per), cap), options, N, periodic)
    if sol is None:
        return row, per
    row.update(status=sol.status, omega=sol.omega, N=sol.N)
    if sol.omega is None:
        return row, per
    period = 2 * math.pi / sol.omega
    err = abs(period - per) / per
    row.update(period=period, period_difference=err)
    if err > LINK_TOL:
        row.update(status="mismatch")
        return row, per
    row.update(stability=sol.stability, max_modulus=sol.max_modulus,
               modulus_error=sol.modulus_error)
    return row, period if sol.status == "converged" else per


def plot_basins(result: Basins, *, ax: Any = None, title: str | None = None) -> Any:
    """A categorical map of the labels over the starts (matplotlib, imported here); the
    legend names the orbits each class is linked to (:attr:`Basins.orbits`)."""
    from matplotlib.lines import Line2D

    from . import _style as style

    plt = style.pyplot()
    if not isinstance(result, Basins):
        raise ParameterTypeError("result", "must be a Basins (from ballbal.basins.basins), "
                                 f"got {type(result).__name__}", value=result)
    if title is not None:
        _check.string("title", title)
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    colours = {"perfect_balance": "white", "other_equilibrium": "tab:green",
               "merged_R-R": "black", "separated_R-R": "0.45", "R-O": "tab:orange",
               "O-O": "tab:blue", "other": "tab:purple", "not_settled": "tab:red",
               "failed": "magenta"}
    t = result.table
    present = [lab for lab in LABELS if lab in set(t["label"].to_list())]
    # squares that tile the map: a cell of the grid each (random starts: of the grid of
    # as many points)
    side = max(1, round(math.sqrt(t.height)))
    nx, ny = ((side, side) if result.random or t.height == 0
              else (t["b1"].n_unique(), t["b2"].n_unique()))
    ax.set_aspect("equal")
    size = style.grid_marker_size(ax, nx, ny, fill=0.95, largest=math.inf)
    for lab in present:
        s = t.filter(pl.col("label") == lab)
        ax.scatter(s["b1"], s["b2"], s=size, c=colours[lab], edgecolors="0.6",
                   linewidths=0.2, marker="s")
    ax.set_xlabel(style.label("b1"))
    ax.set_ylabel(style.label("b2"))
    if not result.random and t.height:
        style.pad_to_grid(ax, t["b1"].to_numpy(), t["b2"].to_numpy())
    style.caption(ax, style.fixed_caption(result.model))

    def name(lab: str) -> str:
        # the orbits a class is linked to, with their windings
        o = result.orbits.filter(pl.col("label") == lab)
        return lab + "".join(f"\norbit {r['orbit']}: ({r['winding1']}, {r['winding2']}), "
                             f"{r['stability']}" for r in o.iter_rows(named=True))

    ax.legend(handles=[Line2D([], [], marker="s", ls="", mfc=colours[lab], mec="0.6",
                              label=name(lab)) for lab in present],
              loc="upper left", fontsize="small", framealpha=0.8)
    if title is not None:
        ax.set_title(title, pad=14)
    return ax
