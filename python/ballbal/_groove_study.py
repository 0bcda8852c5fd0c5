"""Groove study: a parallel scan over herringbone groove parameters ([Yen2005], ``bearing.md``
section 3). Re-exported from :mod:`ballbal.bearing`.

Every point is the given bearing with one groove geometry and ``L / D``, solved on its own
in the Rust core (rayon over the points), so the table does not depend on ``threads``.
The journal is held at ``eccentricity`` along ``+x``: the table gives the **load capacity
at that eccentricity** (not the equilibrium under a given load), in units ``F_S = mu w L
R^3 / c^2``, with its Sommerfeld number and attitude angle (degrees), the linearised
stiffness ``kxx, kxy, kyx, kyy`` (``F_S / c``) and damping ``cxx, ...`` (``F_S / (c w)``)
there, the rigid-rotor whirl threshold for that load (``critical_mass`` = ``M c w^2 /
F_S`` at the threshold, ``whirl_ratio``, ``threshold_speed`` in ``sqrt(W / (M c))``;
``inf`` where the rotor is stable at every speed), and the concentric journal's direct
and cross stiffness ``k_centre``, ``k_centre_cross`` (grooves give a centred journal
direct stiffness; a plain bearing has none).

The groove side and grooved length come from the bearing's grooves (sleeve, whole length
if it has none); a finite model's ``n_theta`` is rounded up to a multiple of each
point's groove count (at least 8 cells per pitch). A point that fails (a groove width
that grid cannot resolve) has its error text in ``status`` and NaN values.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import polars as pl

from . import _check
from ._geometry import Bearing
from ._progress import Progress, ProgressArg
from .exceptions import ParameterError, ParameterTypeError

COLUMNS = (
    "angle", "depth_ratio", "width_ratio", "length_ratio", "count", "status", "load",
    "sommerfeld", "attitude", "kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy",
    "critical_mass", "whirl_ratio", "threshold_speed", "k_centre", "k_centre_cross",
)

_AXES = ("angle", "depth_ratio", "width_ratio", "length_ratio", "count")


def _reals(name: str, v: Any) -> list[float]:
    return [_check.real(name, x) for x in _axis(name, v)]


def _axis(name: str, v: Any) -> list[Any]:
    """An axis's values: a non-empty list, no longer than a whole study may be."""
    if isinstance(v, (str, bytes)) or not isinstance(v, (Sequence, np.ndarray)):
        raise ParameterTypeError(name, f"must be a list of values, got {type(v).__name__}",
                                 value=v)
    if len(v) > _check.MAX_GROOVE_POINTS:
        raise ParameterError(name, f"{len(v)} values, at most {_check.MAX_GROOVE_POINTS}",
                             allowed=f"at most {_check.MAX_GROOVE_POINTS} values")
    return _check.sequence(name, v)


def _point_cells(bearing: Bearing, count: int) -> int:
    """Cells of a point's grid: the core rounds a finite model's ``n_theta`` up to a
    multiple of the groove count with at least 8 cells per pitch."""
    if bearing.model != "finite":
        return 0 if bearing.model in ("short", "long") else math.prod(bearing.grid or (0, 0))
    assert bearing.grid is not None
    n_theta, n_zeta = bearing.grid
    return max(-(-n_theta // count), 8) * count * n_zeta


def groove_study(bearing: Bearing, *, angle: Sequence[float] = (30.0,),
                 depth_ratio: Sequence[float] = (1.0,), width_ratio: Sequence[float] = (0.5,),
                 length_ratio: Sequence[float] | None = None, count: Sequence[int] = (8,),
                 eccentricity: float = 0.5, threads: int | None = None,
                 progress: ProgressArg = False) -> pl.DataFrame:
    """The cartesian product of the axes (``angle`` in degrees from the circumferential
    direction, slowest; then ``depth_ratio``, ``width_ratio``, ``length_ratio`` (default:
    the bearing's), ``count``), one row per point; see the module documentation for the
    columns. ``threads``: rayon threads (``None``: all cores), at most
    :data:`~ballbal._check.MAX_THREADS`; each holds one point's film, and all of them
    together at most :data:`~ballbal._check.MAX_STUDY_CELLS` cells. At most
    :data:`~ballbal._check.MAX_GROOVE_POINTS` points. Bad axis values raise
    :class:`~ballbal.exceptions.ParameterError` naming the axis.

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)``."""
    from . import _native

    if not isinstance(bearing, Bearing):
        raise ParameterTypeError(
            "bearing", f"must be ballbal.bearing.Bearing, got {type(bearing).__name__}",
            allowed="Bearing",
        )
    lengths = [bearing.length_ratio] if length_ratio is None else length_ratio
    reals = {name: _reals(name, v) for name, v in (
        ("angle", angle), ("depth_ratio", depth_ratio), ("width_ratio", width_ratio),
        ("length_ratio", lengths))}
    counts = [_check.integer("count", n, 1, _check.MAX_GROOVES) for n in _axis("count", count)]
    ecc = _check.real("eccentricity", eccentricity)
    n_threads = _check.optional_integer("threads", threads, 1, _check.MAX_THREADS)
    sizes = {**{k: len(v) for k, v in reals.items()}, "count": len(counts)}
    points = math.prod(sizes.values())
    if points > _check.MAX_GROOVE_POINTS:
        longest = max(sizes, key=lambda k: sizes[k])
        raise ParameterError(
            longest, f"the study has {points} points ({' x '.join(map(str, sizes.values()))}),"
            f" at most {_check.MAX_GROOVE_POINTS}",
            allowed=f"at most {_check.MAX_GROOVE_POINTS} points", value=points)
    # Each point's finite grid is the bearing's rounded to its groove count: check the
    # largest, alone and times the points solved at once.
    n_max = max(counts, key=lambda n: _point_cells(bearing, n))
    cells = _point_cells(bearing, n_max)
    if cells > _check.MAX_BEARING_CELLS:
        raise ParameterError(
            "count", f"{n_max} grooves need a grid of {cells} cells (the bearing's n_theta "
            f"rounded up to at least 8 cells per groove pitch), at most "
            f"{_check.MAX_BEARING_CELLS}", allowed=f"at most {_check.MAX_BEARING_CELLS} cells",
            value=n_max)
    at_once = min(points, n_threads or os.cpu_count() or 1)
    if at_once * cells > _check.MAX_STUDY_CELLS:
        raise ParameterError(
            "threads", f"{at_once} threads would each hold a film of up to {cells} cells, "
            f"at most {_check.MAX_STUDY_CELLS} cells in all: use fewer threads or a coarser "
            "grid", allowed=f"threads * cells <= {_check.MAX_STUDY_CELLS}", value=threads)
    with Progress(progress, points, "ballbal groove study", "point") as bar:
        cols = _native.groove_study(bearing, reals["angle"], reals["depth_ratio"],
                                    reals["width_ratio"], reals["length_ratio"], counts, ecc,
                                    n_threads, bar.reporter())
    schema = {c: (pl.Int64 if c == "count" else pl.Utf8 if c == "status" else pl.Float64)
              for c in COLUMNS}
    return pl.DataFrame({c: cols[c] for c in COLUMNS}, schema=schema)


def plot_groove_study(df: pl.DataFrame, x: str = "angle", y: str = "k_centre",
                      ax: Any = None, by: str | None = None) -> Any:
    """``y`` against ``x`` from a :func:`groove_study` table (rows with status ``"ok"``),
    one line per value of ``by`` (default: the first other axis that varies). Returns the
    matplotlib Figure."""
    from . import _style
    from .plot import _pyplot

    if not isinstance(df, pl.DataFrame):
        raise ParameterTypeError("df", f"must be a groove_study table (polars DataFrame), "
                                 f"got {type(df).__name__}", value=df)
    _check.axes("ax", ax)
    for pname, name in (("x", x), ("y", y), ("by", by)):
        if pname == "by" and name is None:
            continue
        if not isinstance(name, str) or name not in df.columns:
            raise ParameterError(pname, f"no column {name!r:.60}", allowed=", ".join(df.columns))
    missing = [c for c in ("status", *_AXES) if c not in df.columns]
    if missing:
        raise ParameterError("df", f"not a groove_study table: no column {missing[0]!r}")
    plt = _pyplot()
    ok = df.filter(pl.col("status") == "ok")
    if by is None:
        by = next((a for a in _AXES if a != x and ok[a].n_unique() > 1), None)
    if ax is None:
        fig, ax = plt.subplots(figsize=(5, 4))
    else:
        fig = ax.figure
    groups = [(None, ok)] if by is None else [
        (k, ok.filter(pl.col(by) == k)) for k in sorted(ok[by].unique().to_list())]
    for key, g in groups:
        g = g.sort(x)
        ax.plot(g[x].to_numpy(), g[y].to_numpy(), marker="o",
                label=None if key is None else f"{by} = {key:g}")
    ax.set_xlabel(_style.label(x))
    ax.set_ylabel(_style.label(y))
    if by is not None and ok.height:
        ax.legend()
    return fig
