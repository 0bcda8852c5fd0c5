"""The figures of the result objects' ``.plot()`` methods, drawn in one style
(:mod:`ballbal._style`): each takes the result and optional axes and returns the axes
(one panel) or the figure (several)."""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
import polars as pl

from . import _style as st


@cache
def _event_short() -> dict[str, str]:
    """Each event's short name (its first alias in the core's vocabulary: LP, BP...)."""
    from . import _native

    return {name: (aliases[0] if aliases else name)
            for name, aliases, _ in _native.event_vocabulary()}


def _panels(n: int, axes: Any, figsize: tuple[float, float]) -> tuple[Any, list[Any]]:
    if axes is None:
        fig, made = st.pyplot().subplots(1, n, figsize=figsize, constrained_layout=True)
        return fig, list(np.atleast_1d(made))
    axes = list(np.atleast_1d(axes))
    if len(axes) != n:
        from .exceptions import ParameterError

        raise ParameterError("ax", f"needs {n} axes, got {len(axes)}", allowed=f"{n} axes")
    return axes[0].figure, axes


# -- solutions ------------------------------------------------------------------------


def equilibrium(eq: Any, ax: Any = None) -> Any:
    """The eigenvalues in the complex plane, stable half shaded: what decides the
    equilibrium's stability."""
    ax = st.new_axes(ax, (4.5, 3.8))
    lam = np.asarray(eq.eigenvalues)
    ax.axvspan(min(-1.0, float(lam.real.min()) * 1.1), 0.0, color="#e8f3e8", zorder=0)
    ax.axvline(0.0, color="0.4", lw=0.8)
    ax.plot(lam.real, lam.imag, "x", color="tab:red" if eq.stability == "unstable"
            else "tab:blue", ms=7)
    ax.set_xlabel(r"Re $\lambda$ ($\omega_n$)")
    ax.set_ylabel(r"Im $\lambda$ ($\omega_n$)")
    ax.set_title(f"{eq.kind}: {eq.stability}", fontsize=9)
    return ax


def periodic_solution(sol: Any, axes: Any = None) -> Any:
    """Three panels: the disk centre ``x, y`` (rotating frame) over one period, the
    orbit of the disk centre in the ground frame ``X, Y`` over at least three turns of
    the disk, and the ball angles over one period."""
    from .exceptions import ParameterError

    if sol.omega is None:
        raise ParameterError("solution", f"has no orbit to draw: status {sol.status}",
                             allowed="a solution with a frequency")
    fig, (a0, a1, a2) = _panels(3, axes, (11.0, 3.4))
    h = sol.time_history(np.linspace(0.0, sol.period, 401))
    t = h["t"].to_numpy()
    a0.plot(t, h["x"], label=st.symbol("x"))
    a0.plot(t, h["y"], label=st.symbol("y"))
    a0.set_xlabel(st.label("t"))
    a0.set_ylabel(r"$x, y$ ($e$)")
    a0.legend(fontsize=8)
    spin = sol.balancer.Omega
    t_end = max(sol.period, 3 * 2 * math.pi / spin) if spin > 0 else sol.period
    g = sol.time_history(np.linspace(0.0, t_end, 2001))
    z = (g["x"].to_numpy() + 1j * g["y"].to_numpy()) * np.exp(1j * spin * g["t"].to_numpy())
    a1.plot(z.real, z.imag, lw=0.9)
    a1.plot(0.0, 0.0, "+", color="0.4")
    a1.set_aspect("equal", adjustable="datalim")
    st.axes_labels(a1, "X", "Y")
    a1.set_title("ground frame", fontsize=9)
    balls = [c for c in sol.balancer.coordinates if c.startswith("b")]
    for b in balls:
        a2.plot(t, h[b], label=st.symbol(b))
    a2.set_xlabel(st.label("t"))
    a2.set_ylabel(st.label("b"))
    a2.legend(fontsize=8)
    fig.suptitle(repr(sol), fontsize=9)
    return fig


# -- branches and curves ----------------------------------------------------------------


def _column(table: pl.DataFrame, y: str) -> np.ndarray:
    """A numeric column, or ``r``: the disk centre's offset ``hypot(q_x, q_y)`` read from
    an equilibrium's coordinates ``q``."""
    if y == "r" and "q" in table.columns and "r" not in table.columns:
        q = table["q"].to_list()
        return np.array([math.hypot(v[0], v[1]) if v else math.nan for v in q])
    if y not in table.columns:
        from .exceptions import ParameterError

        raise ParameterError("y", f"{y!r} is not a column of the table (columns: "
                             f"{', '.join(table.columns)})", value=y)
    return table[y].cast(pl.Float64).to_numpy()


def branch(br: Any, y: str | None = None, ax: Any = None) -> Any:
    """Bifurcation diagram: ``y`` against the branch's parameter, stable parts solid,
    unstable dashed, each event marked and labelled with its short name."""
    ax = st.new_axes(ax)
    y = y or ("omega" if br.kind == "periodic" else "r")
    x = br.table[br.parameter].to_numpy()
    yy = _column(br.table, y)
    verdicts = br.table["stability"].to_list() if "stability" in br.table.columns else \
        ["stable"] * br.table.height
    drawn: set[str] = set()
    for lo, hi, v in st.stability_runs(verdicts):
        ax.plot(x[lo:hi + 1], yy[lo:hi + 1], st.LINESTYLE.get(v, "-."), color="tab:blue",
                lw=1.4, label=None if v in drawn else v)
        drawn.add(v)
    ev = br.events
    if ev.height:
        ex = ev[br.parameter].to_numpy()
        ey = _column(ev, y) if (y in ev.columns or y == "r") else np.interp(ex, x, yy)
        short = _event_short()
        ax.plot(ex, ey, "o", color="k", ms=5, ls="none")
        for (xi, yi), names in _near_groups(ex, ey, [short.get(k, k) for k in
                                                     ev["type"].to_list()], x, yy):
            ax.annotate("+".join(names), (xi, yi), textcoords="offset points",
                        xytext=(4, 4), fontsize=8)
    st.axes_labels(ax, br.parameter, y)
    model = _model_of(br)
    if model is not None:
        st.caption(ax, st.fixed_caption(model, (br.parameter,)))
    if drawn:
        ax.legend(fontsize=8, loc="best")
    return ax


def _near_groups(ex: np.ndarray, ey: np.ndarray, names: list[str], x: np.ndarray,
                 y: np.ndarray) -> list[tuple[tuple[float, float], list[str]]]:
    """Events within 4 % of the plotted ranges of one another, labelled once (``BP+LP``)
    so that the labels of events located close together do not overprint."""
    span_x = float(np.nanmax(x) - np.nanmin(x)) or 1.0 if x.size else 1.0
    span_y = float(np.nanmax(y) - np.nanmin(y)) or 1.0 if y.size else 1.0
    groups: list[tuple[tuple[float, float], list[str]]] = []
    for xi, yi, name in zip(ex, ey, names, strict=True):
        for (gx, gy), members in groups:
            if abs(xi - gx) < 0.04 * span_x and abs(yi - gy) < 0.04 * span_y:
                if name not in members:
                    members.append(name)
                break
        else:
            groups.append(((float(xi), float(yi)), [name]))
    return groups


def _model_of(result: Any) -> Any:
    model = result.meta.get("model") if isinstance(result.meta, dict) else None
    solutions = getattr(result, "solutions", None)
    if model is None and solutions:
        model = getattr(solutions[0], "balancer", None)
    return model


def curve(cv: Any, ax: Any = None) -> Any:
    """A two-parameter bifurcation curve, stable parts solid and unstable dashed (the
    stability of the solution at the bifurcation, where the table has it), its
    codimension-two points as stars (confirmed) or hollow circles, labelled."""
    ax = st.new_axes(ax)
    p1, p2 = cv.parameters
    x, y = cv.table[p1].to_numpy(), cv.table[p2].to_numpy()
    verdicts = (cv.table["stability"].to_list() if "stability" in cv.table.columns
                else ["stable"] * cv.table.height)
    drawn: set[str] = set()
    for lo, hi, v in st.stability_runs(verdicts):
        ax.plot(x[lo:hi + 1], y[lo:hi + 1], st.LINESTYLE.get(v, "-."), color="tab:purple",
                lw=1.4, label=None if v in drawn else f"{cv.kind} ({v})")
        drawn.add(v)
    pts = cv.points
    for r in pts.iter_rows(named=True):
        ok = r.get("status", "confirmed") == "confirmed"
        ax.plot(r[p1], r[p2], "*" if ok else "o", color="k" if ok else "tab:gray",
                ms=10 if ok else 6, mfc=None if ok else "none")
        ax.annotate(str(r["type"]), (r[p1], r[p2]), textcoords="offset points",
                    xytext=(5, 4), fontsize=8)
    st.axes_labels(ax, p1, p2)
    model = _model_of(cv)
    if model is not None:
        st.caption(ax, st.fixed_caption(model, (p1, p2)))
    if drawn:
        ax.legend(fontsize=8, loc="best")
    return ax


# -- transients ---------------------------------------------------------------------------


def sweep(sw: Any, axes: Any = None) -> Any:
    """The speed sweep up and down: the balls' mean rate and (when recorded) the
    vibration against the speed, up (triangles up) and down (triangles down), the
    transition speeds marked: the hysteresis."""
    cols = ["omega"] + (["vibration"] if "vibration" in sw.table.columns else [])
    fig, panels = _panels(len(cols), axes, (5.0 * len(cols), 3.6))
    for ax, col in zip(panels, cols, strict=True):
        for direction, marker, color in (("up", "^-", "tab:red"), ("down", "v--", "tab:blue")):
            part = sw.table.filter(pl.col("direction") == direction)
            if part.height:
                ax.plot(part["Omega"], part[col], marker, color=color, ms=5, lw=1.0,
                        label=direction)
        for speed, name in ((sw.up, "up"), (sw.down, "down")):
            if speed is not None:
                ax.axvline(speed, color="0.5", lw=0.8, ls=":")
                ax.annotate(f"{name} {speed:.4g}", (speed, 1.0), xycoords=("data", "axes fraction"),
                            fontsize=7, va="top", rotation=90)
        st.axes_labels(ax, "Omega", col)
        ax.legend(fontsize=8)
    return fig


def trajectory_radius(df: pl.DataFrame, ax: Any = None, *, band: float | None = None,
                      final: float | None = None, settle_at: float | None = None) -> Any:
    """The disk centre's distance from the axis ``|Z| = hypot(x, y)`` against time."""
    ax = st.new_axes(ax, (6.0, 3.4))
    t = df["t"].to_numpy()
    ax.plot(t, np.hypot(df["x"].to_numpy(), df["y"].to_numpy()), lw=0.9)
    if band is not None and final is not None:
        ax.axhspan(final - band, final + band, color="0.9", zorder=0, label="settling band")
    if settle_at is not None:
        ax.axvline(settle_at, color="tab:green", ls="--", lw=1.0, label="settled")
    st.axes_labels(ax, "t", "r")
    if band is not None or settle_at is not None:
        ax.legend(fontsize=8)
    return ax


def rotor_trajectory(tr: Any, axes: Any = None) -> Any:
    """The journal orbit inside the clearance circle (``x`` down, gravity down on the
    page) and the eccentricity against time."""
    fig, (a0, a1) = _panels(2, axes, (9.0, 3.8))
    th = np.linspace(0, 2 * math.pi, 361)
    a0.plot(np.sin(th), np.cos(th), color="0.3", lw=1)
    t = tr.table
    a0.plot(t["y"], -t["x"], lw=0.9)
    a0.set_aspect("equal")
    a0.set_xlim(-1.05, 1.05)
    a0.set_ylim(-1.05, 1.05)
    a0.set_xlabel(r"$y/c$")
    a0.set_ylabel(r"$-x/c$ ($x$ down)")
    a1.plot(t["tau"], t["eccentricity"], lw=0.9)
    a1.set_xlabel(r"$\tau = \omega t$ (rad)")
    a1.set_ylabel(st.label("eccentricity"))
    fig.suptitle(f"{tr.outcome}", fontsize=9)
    return fig


def log_decrement(ld: Any, ax: Any = None) -> Any:
    """The peaks' logarithms against the peak number and the fitted line of slope
    ``-delta``."""
    ax = st.new_axes(ax, (4.5, 3.4))
    i = np.arange(len(ld.peak_value))
    lnx = np.log(np.asarray(ld.peak_value, float))
    ax.plot(i, lnx, "o", label="peaks")
    ax.plot(i, lnx.mean() - ld.delta * (i - i.mean()), "-",
            label=rf"fit, $\delta$ = {ld.delta:.4g}")
    ax.set_xlabel("peak number $i$")
    ax.set_ylabel(r"$\ln x_i$ (x in the record's unit)")
    ax.legend(fontsize=8)
    return ax


def bearing_equilibrium(eq: Any, ax: Any = None) -> Any:
    """The journal's static position inside the clearance circle and the load's
    direction."""
    ax = st.new_axes(ax, (4.0, 4.0))
    th = np.linspace(0, 2 * math.pi, 361)
    ax.plot(np.cos(th), np.sin(th), color="0.3", lw=1)
    ax.plot([0.0, eq.position[0]], [0.0, eq.position[1]], "-o", color="tab:blue",
            ms=4, label="journal centre")
    w = math.hypot(*eq.load)
    if w > 0:
        ax.annotate("", xy=(0.5 * eq.load[0] / w, 0.5 * eq.load[1] / w), xytext=(0, 0),
                    arrowprops={"arrowstyle": "->", "color": "tab:red"})
    ax.set_aspect("equal")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xlabel(r"$x/c$")
    ax.set_ylabel(r"$y/c$")
    ax.set_title(rf"$\varepsilon$ = {eq.eccentricity:.3g}, load arrow in red", fontsize=9)
    return ax
