"""Plots of scan tables (matplotlib, installed with the ``plot`` extra), in the style of
:mod:`ballbal._style`: mathtext symbols with units on the axes, the fixed parameters
over the map, markers sized to the grid."""

from __future__ import annotations

from typing import Any

import numpy as np
import polars as pl

from . import _style as style

_MARK = {"stable": ("o", "tab:blue"), "unstable": ("x", "tab:red"),
         "undetermined": ("^", "tab:gray")}


def _pyplot() -> Any:
    """matplotlib's pyplot, or an ImportError naming the extra (:func:`_style.pyplot`)."""
    return style.pyplot()


def scan_map(df: pl.DataFrame, *, x: str = "Omega", y: str = "eta", type: str = "R-R",
             ax: Any = None, title: str | None = None,
             shade: str = "perfect balance stable", curves: Any = ()) -> Any:
    """Tien's (2011) map (figures 3-6 to 3-16): solutions of ``type`` over the (x, y) plane,
    stable and unstable markers, and the perfect balance's stable region shaded (for a
    scene with springs, its balanced state's: name it with ``shade``). ``curves``:
    :class:`~ballbal.continuation` curves (``Curve`` objects whose tables have the columns
    ``x`` and ``y``) drawn over the map, with their codimension-two points (black stars
    for the confirmed ones; points whose multipliers reject or cannot decide the label,
    ``status`` other than ``"confirmed"``, as hollow grey circles). The parameters the
    table holds fixed are written over the map; markers fill a share of one grid cell."""
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    for col in (x, y):
        if col not in df.columns:
            raise ValueError(f"{col}: not a column of this scan (columns: {df.columns})")
    pts = df.unique(subset=[x, y], keep="first").sort([y, x])
    xs, ys = np.unique(pts[x].to_numpy()), np.unique(pts[y].to_numpy())
    stable = np.full((ys.size, xs.size), np.nan)
    for row in pts.select(x, y, "pb_stable").iter_rows():
        stable[np.searchsorted(ys, row[1]), np.searchsorted(xs, row[0])] = float(row[2])
    if xs.size > 1 and ys.size > 1:
        ax.contourf(xs, ys, stable, levels=[0.5, 1.5], colors=["#cfe8cf"])
    ax.plot([], [], "s", color="#cfe8cf", label=shade)
    sols = df.filter((pl.col("type") == type) & (pl.col("status") == "converged"))
    size = style.grid_marker_size(ax, xs.size, ys.size)
    for verdict, (m, c) in _MARK.items():
        s = sols.filter(pl.col("stability") == verdict)
        if s.height:
            ax.scatter(s[x], s[y], marker=m, color=c, s=size, label=f"{type} {verdict}",
                       facecolors="none" if m == "o" and verdict != "stable" else None)
    style.pad_to_grid(ax, xs, ys)
    for cv in curves:
        t = cv.table
        for col in (x, y):
            if col not in t.columns:
                raise ValueError(f"curves: a {cv.kind} curve has no column {col!r}")
        ax.plot(t[x], t[y], "-" if cv.kind != "hopf" else "--", lw=1.5, label=cv.kind)
        pts = cv.points
        if pts.height and "status" in pts.columns:
            # only confirmed points are bifurcations: the others hollow, grey
            ok = pts.filter(pl.col("status") == "confirmed")
            other = pts.filter(pl.col("status") != "confirmed")
            if ok.height:
                ax.plot(ok[x], ok[y], "k*", ms=9)
            if other.height:
                ax.plot(other[x], other[y], "o", ms=6, mfc="none", color="tab:gray")
        elif pts.height:
            ax.plot(pts[x], pts[y], "k*", ms=9)
    style.axes_labels(ax, x, y)
    ax.set_title(title or f"{type} solutions", pad=14)
    style.caption(ax, style.fixed_caption(df, (x, y)))
    ax.legend(loc="best", fontsize=8)
    return ax


def omega_curves(df: pl.DataFrame, *, x: str = "eta", by: str = "Omega",
                 type: str = "R-R", stable_only: bool = True, ax: Any = None) -> Any:
    """omega against ``x`` for each value of ``by`` (Tien's (2011) figure 3-7)."""
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    s = df.filter((pl.col("type") == type) & (pl.col("status") == "converged"))
    if stable_only:
        s = s.filter(pl.col("stability") == "stable")
    for v in sorted(s[by].unique().to_list()):
        part = s.filter(pl.col(by) == v).sort(x)
        ax.plot(part[x], part["omega"], "o-", ms=3, label=f"{style.symbol(by)} = {v:g}")
    style.axes_labels(ax, x, "omega")
    ax.set_title(f"{type}: frequency of the ball motion", pad=14)
    style.caption(ax, style.fixed_caption(df, (x, by)))
    ax.legend(fontsize=7, ncol=2)
    return ax
