"""The balanced state of a scene and where it is stable (the stability maps of [Rezaee2017])."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import polars as pl

from . import _check, _native
from .analysis import Equilibrium, _equilibrium, capacities
from .exceptions import ParameterError
from .model import Balancer
from .scene import Scene, model_argument, model_at


def balanced_state(model: Balancer | Scene) -> Equilibrium | None:
    """The equilibrium that continues the planar perfect balance to ``model``, with its
    eigenvalues and stability; ``None`` if the balls cannot balance the disk.

    Without springs it is the perfect balance (``x = y = 0``, a flat disk). Springs whose
    rest spacing is not the balancing spacing leave a nearly balanced state whose
    residual whirl is ``hypot(x, y)`` (in units of ``e``); it is followed from zero
    spring stiffness. Needs an autonomous scene."""
    model_argument("model", model)
    d = _native.balanced_states([model])[0]
    return None if d is None else _equilibrium(d, capacities(model))


def balance_map(
    model: Balancer | Scene,
    **axes: Sequence[float] | np.ndarray | tuple[float, float, float] | str,
) -> pl.DataFrame:
    """The balanced state's stability over a grid: one row per point of the product of
    ``axes`` (parameter name = values; the names the scene takes, as the core lists them
    in ``_native.parameter_keys``: balancer fields such as ``Omega``, ``eta``,
    ``zeta_b``, ``zeta``, the scene's ``springs`` and tilt fields ``j_t``, ``j_z``,
    ``zeta_r``, ``a``, ``b``; on a bearing ``rho``, ``depth_ratio``, ``groove_angle``;
    ``gravity`` only at 0, where the scene stays autonomous).
    Points are solved in parallel in the core, each on its own, so the table does not
    depend on the thread count.

    Columns: the axes, ``<axis>_index`` (the value's position on its axis, counted from
    0: the key that joins maps and scans over the same axes exactly), ``status``
    (``"ok"``; ``"no_balance"`` where the balls cannot balance the disk;
    ``"not_converged"`` where the continuation from the planar balancer's perfect
    balance failed, e.g. springs near the critical speed), ``stability``,
    ``index`` (largest real part of the eigenvalues, [TwoBallStrength]'s relative-stability
    index), ``whirl`` (residual ``hypot(x, y)``), ``tilt`` (residual ``hypot(A, B)``,
    0 for a planar disk), ``residual`` (of the equilibrium equations).

    Each axis is written as in :func:`ballbal.scan` (:func:`ballbal._check.axis`):
    ``(start, stop, step)`` or ``"start:stop:step"`` a range with ``stop`` included,
    a list or array explicit values; finite, inside the parameter's range (a value
    outside it raises :class:`~ballbal.exceptions.ParameterError` naming the axis); the
    grid has at most :data:`~ballbal._check.MAX_MAP_POINTS` points."""
    model_argument("model", model)
    if not axes:
        raise ParameterError("axes", "give at least one parameter to vary, e.g. Omega=[...]")
    scene = model if isinstance(model, Scene) else Scene(balancer=model)
    names = list(axes)
    # the core's check, as a scan's: a name the scene cannot vary is refused with the
    # names it can (a per-ball one, ``eta2``, included) before any work
    _native.check_axes(scene, names)
    values: list[list[float]] = []
    for name in names:
        v = _check.axis(name, axes[name], _check.MAX_MAP_POINTS)
        _planar_range(scene.balancer, name, v)
        values.append([float(x) for x in v])
    k = max(range(len(values)), key=lambda i: len(values[i]))  # the longest: the one to cut
    _check.at_most(names[k], math.prod(len(v) for v in values), _check.MAX_MAP_POINTS,
                   "points (the product of the axes)")
    grid = list(itertools.product(*values))
    at = list(itertools.product(*(range(len(v)) for v in values)))
    # The points are built and solved in the core (parameters set by name there), so a
    # map costs the solves and not one Python scene per point.
    results = _native.balance_map(scene, names, [list(c) for c in grid])
    cols: dict[str, list[Any]] = {n: [] for n in names}
    cols |= {f"{n}_index": [] for n in names}
    for key in ("status", "stability", "index", "whirl", "tilt", "residual"):
        cols[key] = []
    for combo, where, (status, d) in zip(grid, at, results, strict=True):
        for n, x, i in zip(names, combo, where, strict=True):
            cols[n].append(x)
            cols[f"{n}_index"].append(i)
        cols["status"].append(status)
        if d is None:
            for key in ("stability", "index", "whirl", "tilt", "residual"):
                cols[key].append(None)
            continue
        q = d["q"]
        cols["stability"].append(d["stability"])
        cols["index"].append(float(d["index"]))
        cols["whirl"].append(float(np.hypot(q[0], q[1])))
        cols["tilt"].append(float(np.hypot(q[2], q[3])) if scene.tilt is not None else 0.0)
        cols["residual"].append(float(d["residual"]))
    schema = {n: pl.Float64 for n in names} | {f"{n}_index": pl.Int64 for n in names} | {
        "status": pl.String, "stability": pl.String, "index": pl.Float64,
        "whirl": pl.Float64, "tilt": pl.Float64, "residual": pl.Float64}
    return pl.DataFrame(cols, schema=schema)


#: The planar balancer's axes: the core sets them on each point's scene without checking
#: them (issue 30: ``Omega=[-1.0]`` gave rows with verdicts), so they are checked here.
_PLANAR_AXES = {p["key"] for p in _native.parameters() if p["key"] and p["planar"]}


def _planar_range(balancer: Balancer, name: str, values: np.ndarray) -> None:
    """Refuses an axis of a balancer parameter with a value outside its range (the
    core's, through :meth:`Balancer.validate`). The ranges are intervals, so the
    smallest and the largest value decide; the error names the axis (``eta``, not the
    ball ``eta2`` the core names)."""
    if _native.parse_parameter(name)[0] not in _PLANAR_AXES:
        return
    for x in (float(values.min()), float(values.max())):
        try:
            model_at(balancer, name, x)  # a Balancer is validated as it is made
        except ParameterError as e:
            raise ParameterError(name, f"{x:g} is outside its range: {e.message}",
                                 allowed=e.allowed, value=x) from None


def plot_balance_map(df: pl.DataFrame, x: str, y: str, ax: Any = None, label: str = "",
                     max_whirl: float | None = None) -> Any:
    """Stable balanced region of a :func:`balance_map` in the ``(x, y)`` plane, filled.
    With ``max_whirl``, a stable state whose residual whirl exceeds it (springs at low
    speed hold the balls apart without balancing) is drawn apart, in grey."""
    from . import _style as style

    if ax is None:
        _, ax = style.pyplot().subplots(figsize=(5, 4))
    xs = np.unique(df[x].to_numpy())
    ys = np.unique(df[y].to_numpy())
    grid = np.full((ys.size, xs.size), np.nan)
    for row in df.iter_rows(named=True):
        i, j = np.searchsorted(ys, row[y]), np.searchsorted(xs, row[x])
        v = {"stable": 1.0, "unstable": 0.0}.get(row["stability"] or "", np.nan)
        if v == 1.0 and max_whirl is not None and row["whirl"] > max_whirl:
            v = 2.0
        grid[i, j] = v
    ax.contourf(xs, ys, grid, levels=[0.5, 1.5, 2.5], colors=["tab:green", "0.6"],
                alpha=0.35)
    ax.contour(xs, ys, np.where(grid == 1.0, 1.0, 0.0), levels=[0.5], colors=["tab:green"])
    style.axes_labels(ax, x, y)
    style.caption(ax, style.fixed_caption(df, (x, y)))
    if label:
        ax.set_title(label, pad=14)
    return ax
