"""Groove study: a parallel scan over herringbone groove parameters (seed 002, ``bearing.md``
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

from collections.abc import Sequence
from typing import Any

import polars as pl

from . import _check
from .bearing import Bearing

COLUMNS = (
    "angle", "depth_ratio", "width_ratio", "length_ratio", "count", "status", "load",
    "sommerfeld", "attitude", "kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy",
    "critical_mass", "whirl_ratio", "threshold_speed", "k_centre", "k_centre_cross",
)


def _reals(name: str, v: Any) -> list[float]:
    return [_check.real(name, x) for x in _check.sequence(name, v)]


def groove_study(bearing: Bearing, *, angle: Sequence[float] = (30.0,),
                 depth_ratio: Sequence[float] = (1.0,), width_ratio: Sequence[float] = (0.5,),
                 length_ratio: Sequence[float] | None = None, count: Sequence[int] = (8,),
                 eccentricity: float = 0.5, threads: int | None = None) -> pl.DataFrame:
    """The cartesian product of the axes (``angle`` in degrees from the circumferential
    direction, slowest; then ``depth_ratio``, ``width_ratio``, ``length_ratio`` (default:
    the bearing's), ``count``), one row per point; see the module documentation for the
    columns. ``threads``: rayon threads (``None``: all cores). Bad axis values raise
    :class:`~ballbal.exceptions.ParameterError` naming the axis."""
    from . import _native

    if not isinstance(bearing, Bearing):
        from .exceptions import ParameterTypeError

        raise ParameterTypeError(
            "bearing", f"must be ballbal.bearing.Bearing, got {type(bearing).__name__}",
            allowed="Bearing",
        )
    lengths = [bearing.length_ratio] if length_ratio is None else length_ratio
    cols = _native.groove_study(
        bearing,
        _reals("angle", angle),
        _reals("depth_ratio", depth_ratio),
        _reals("width_ratio", width_ratio),
        _reals("length_ratio", lengths),
        [_check.integer("count", n, 1) for n in _check.sequence("count", count)],
        _check.real("eccentricity", eccentricity),
        _check.optional_integer("threads", threads, 1),
    )
    schema = {c: (pl.Int64 if c == "count" else pl.Utf8 if c == "status" else pl.Float64)
              for c in COLUMNS}
    return pl.DataFrame({c: cols[c] for c in COLUMNS}, schema=schema)


def plot_groove_study(df: pl.DataFrame, x: str = "angle", y: str = "k_centre",
                      ax: Any = None, by: str | None = None) -> Any:
    """``y`` against ``x`` from a :func:`groove_study` table (rows with status ``"ok"``),
    one line per value of ``by`` (default: the first other axis that varies). Returns the
    matplotlib Figure."""
    import matplotlib.pyplot as plt

    for name in (x, y) + (() if by is None else (by,)):
        if name not in df.columns:
            from .exceptions import ParameterError

            raise ParameterError("x" if name == x else "y" if name == y else "by",
                                 f"no column {name!r}", allowed=", ".join(df.columns))
    ok = df.filter(pl.col("status") == "ok")
    if by is None:
        axes = ("angle", "depth_ratio", "width_ratio", "length_ratio", "count")
        by = next((a for a in axes if a != x and ok[a].n_unique() > 1), None)
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
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    if by is not None:
        ax.legend()
    return fig
