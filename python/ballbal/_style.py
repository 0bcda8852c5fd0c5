"""One style for every figure and notebook summary: the symbols and units of the
quantities on the axes, marker sizes that follow a grid, the fixed parameters of a map,
and the short text and HTML tables the result objects show in a notebook.

The parameter names come from the core's registry (:func:`ballbal._native.parameters`);
this module only says how to *write* them (mathtext symbol and unit), never what they
are. Times are in units of ``1 / omega_n``, frequencies in units of ``omega_n`` and the
disk's displacement in units of the eccentricity ``e`` (the model's scales)."""

from __future__ import annotations

import dataclasses
import html
import math
import re
from collections.abc import Iterable, Sequence
from functools import cache
from typing import Any

import numpy as np

from . import _native

#: How a quantity is written: mathtext symbol and unit ("" for a pure number). Keys are
#: the registry's parameter names, the disk units' parameters, and the columns of the
#: result tables. A per-ball name ``eta1`` is written with its ball as a subscript
#: (``eta_1``), as the coordinates ``b1, b2`` are.
QUANTITIES: dict[str, tuple[str, str]] = {
    # the planar balancer (registry)
    "mu": (r"$\mu$", ""),
    "zeta": (r"$\zeta$", ""),
    "zeta_b": (r"$\zeta_b$", ""),
    "delta": (r"$\delta$", ""),
    "Omega": (r"$\Omega$", r"$\omega_n$"),
    "eta": (r"$\eta$", ""),
    # effects (registry): lengths over e, time over 1/omega_n, forces over M e omega_n^2
    "springs": (r"$k_d$", r"$k$"),
    "gravity": (r"$g$", r"$e\,\omega_n^2$"),
    "tilt.a": (r"$a$", r"$r_t$"),
    "tilt.b": (r"$b$", r"$r_t$"),
    "tilt.j_t": (r"$J_t$", r"$M r_t^2$"),
    "tilt.j_z": (r"$J_z$", r"$M r_t^2$"),
    "tilt.zeta_r": (r"$\zeta_r$", ""),
    "ramp.to": (r"$\Omega_{end}$", r"$\omega_n$"),
    "ramp.start": (r"$t_{ramp}$", r"$1/\omega_n$"),
    "ramp.duration": (r"$T_{ramp}$", r"$1/\omega_n$"),
    "impulse.amplitude": (r"$F_0$", r"$M e\,\omega_n^2$"),
    "impulse.t0": (r"$t_0$", r"$1/\omega_n$"),
    "impulse.sharpness": (r"$s$", r"$\omega_n^2$"),
    "impulse.angle": (r"$\phi_0$", "rad"),
    # the journal bearing (registry)
    "rho": (r"$\rho$", ""),
    "grooves.depth_ratio": (r"$h_g/c$", ""),
    "grooves.angle": (r"$\beta_g$", "deg"),
    # the disk's own units (ballbal.continuation.DiskUnits)
    "omega0": (r"$\omega_0$", ""),
    "m0": (r"$m_0$", ""),
    "e": (r"$e$", ""),
    "C0": (r"$C_0$", ""),
    "D0": (r"$D_0$", ""),
    # results
    "omega": (r"$\omega$", r"$\omega_n$"),
    "period": (r"$T$", r"$1/\omega_n$"),
    "t": (r"$t$", r"$1/\omega_n$"),
    "tau": (r"$\tau = \omega t$", "rad"),
    "x": (r"$x$", r"$e$"),
    "y": (r"$y$", r"$e$"),
    "X": (r"$X$", r"$e$"),
    "Y": (r"$Y$", r"$e$"),
    "r": (r"$|Z|$", r"$e$"),
    "theta": (r"$\theta$", "rad"),
    "b": (r"$b$", "rad"),
    "max_modulus": (r"$|\mu_F|_{max}$", ""),
    "max_real": (r"$\max \mathrm{Re}\,\lambda$", r"$\omega_n$"),
    "vibration": (r"$\overline{|Z''|}$", r"$e\,\omega_n^2$"),
    "peak": (r"$|Z|_{max}$", r"$e$"),
    "settle_time": (r"$t_s$", r"$1/\omega_n$"),
    "frequency": (r"$f$", r"$\omega_n$"),
    "amplitude": (r"$A$", ""),
    "eccentricity": (r"$\varepsilon = e_j/c$", ""),
    "attitude": (r"$\phi$", "deg"),
    "tangential": (r"$F_t$", r"$F_S$"),
    "radial": (r"$F_r$", r"$F_S$"),
    "speed_rpm": (r"$n$", "rpm"),
}

_BALL = re.compile(r"^d?b(\d+)$")


@cache
def registry_names() -> tuple[str, ...]:
    """The core's parameter names (every model parameter a scan or branch can vary)."""
    return tuple(p["name"] for p in _native.parameters())


@cache
def _ball_parameter(name: str) -> tuple[str, int | None]:
    """The core's reading of a per-ball name (``"eta2"`` -> ``("eta", 1)``); ``(name,
    None)`` for any other name or column."""
    try:
        return _native.parse_parameter(name)
    except ValueError:
        return name, None


def symbol(name: str) -> str:
    """The mathtext symbol of a parameter or column (``"Omega"`` -> ``$\\Omega$``,
    ``"eta1"`` -> ``$\\eta_{1}$``, ``"b2"`` -> ``$b_{2}$``); the name itself when
    it has none."""
    return _written(name)[0]


def unit(name: str) -> str:
    """The unit of a parameter or column, ``""`` for a pure number."""
    return _written(name)[1]


def _written(name: str) -> tuple[str, str]:
    if name in QUANTITIES:
        return QUANTITIES[name]
    key, index = _ball_parameter(name)
    if index is not None and key in QUANTITIES:
        sym, u = QUANTITIES[key]
        ball = str(index + 1)
        sub = re.match(r"^\$(.*)_\{?([^{}$]*)\}?\$$", sym)
        if sub:  # zeta_b of ball 1: zeta_{b,1}, not a double subscript
            return f"${sub.group(1)}_{{{sub.group(2)},{ball}}}$", u
        return f"{sym[:-1]}_{{{ball}}}$", u
    m = _BALL.match(name)
    if m:
        rate = name.startswith("d")
        return (r"$\dot b_{" if rate else r"$b_{") + m.group(1) + "}$", (
            r"rad $\omega_n$" if rate else "rad")
    return name, ""


def label(name: str) -> str:
    """An axis label: symbol and, where it has one, the unit in parentheses
    (``"Omega"`` -> ``$\\Omega$ ($\\omega_n$)``)."""
    sym, u = _written(name)
    return f"{sym} ({u})" if u else sym


def value_text(name: str, value: Any) -> str:
    """``symbol = value`` for a caption, 4 significant digits."""
    if isinstance(value, (tuple, list, np.ndarray)):
        vals = [float(v) for v in value]
        if len(set(vals)) == 1:
            return f"{symbol(name)} = {vals[0]:.4g}"
        return f"{symbol(name)} = (" + ", ".join(f"{v:.4g}" for v in vals) + ")"
    if isinstance(value, (int, float, np.floating, np.integer)):
        return f"{symbol(name)} = {float(value):.4g}"
    return f"{symbol(name)} = {value}"


def _numeric(v: Any) -> bool:
    items = v if isinstance(v, (tuple, list)) else (v,)
    return bool(items) and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                               for x in items)


def fixed_caption(source: Any, varying: Iterable[str] = ()) -> str:
    """The fixed parameters of a map or a branch, ``"$\\mu$ = 0.2, $\\zeta$ = 0.05,
    ..."``: from a model (a ``Balancer``, a ``Scene``'s balancer, the disk units of
    :class:`~ballbal.continuation.DiskUnits`) or from a result
    table's model columns (the registry's names; a column constant over the table is
    fixed, the balls' values of one name shown together). ``varying``: names left out
    (the axes; ``"eta"`` also leaves out ``eta1``...)."""
    skip = set(varying)
    skip |= {_ball_parameter(v)[0] for v in skip}
    parts: list[str] = []
    # a Scene holds its balancer as a field (DiskUnits derives one: its own are shown)
    holds = dataclasses.is_dataclass(source) and any(
        f.name == "balancer" for f in dataclasses.fields(source))
    bal = source.balancer if holds else source
    if dataclasses.is_dataclass(bal) and not isinstance(bal, type):
        for f in dataclasses.fields(bal):
            v = getattr(bal, f.name)
            if f.name in QUANTITIES and f.name not in skip and _numeric(v):
                parts.append(value_text(f.name, v))
        return ", ".join(parts)
    columns = getattr(source, "columns", None)
    if columns is None:
        return ""
    groups: dict[str, list[float]] = {}
    for col in columns:
        base = _ball_parameter(col)[0]
        if base not in registry_names() or col in skip or base in skip:
            continue
        values = source[col].unique()
        if values.len() != 1 or values.dtype.is_numeric() is False:
            continue
        groups.setdefault(base, []).append(float(values[0]))
    return ", ".join(value_text(k, v if len(v) > 1 else v[0]) for k, v in groups.items())


def caption(ax: Any, text: str) -> None:
    """Writes ``text`` (the fixed parameters) under the axes' title, small."""
    if text:
        ax.text(0.0, 1.01, text, transform=ax.transAxes, fontsize=7, va="bottom",
                ha="left", color="0.25")


def grid_marker_size(ax: Any, nx: int, ny: int, fill: float = 0.6,
                     largest: float = 60.0) -> float:
    """A scatter marker's area (points squared) that fills ``fill`` of one cell of an
    ``nx`` by ``ny`` grid over the axes, so that markers of a 61 x 61 map do not merge
    and those of a 5 x 5 map are not specks; at most ``largest``."""
    bbox = ax.get_window_extent()
    dpi = ax.figure.dpi
    w, h = bbox.width * 72.0 / dpi, bbox.height * 72.0 / dpi
    cell = min(w / max(nx, 1), h / max(ny, 1))
    return float(min(largest, max(1.0, (fill * cell) ** 2)))


def pad_to_grid(ax: Any, xs: Any, ys: Any) -> None:
    """Limits half a grid cell beyond the outer points, so that the edge markers are not
    cut by the axes."""
    for values, setter in ((np.asarray(xs, float), ax.set_xlim),
                           (np.asarray(ys, float), ax.set_ylim)):
        if values.size > 1:
            half = 0.5 * float(np.min(np.diff(np.unique(values)))) if np.unique(
                values).size > 1 else 0.5
            setter(float(values.min()) - half, float(values.max()) + half)


def value_range(series: Any) -> str:
    """``"lo…hi"`` of a numeric polars column, ``"-"`` when empty."""
    if series.len() == 0:
        return "-"
    return f"{float(series.min()):.4g}…{float(series.max()):.4g}"


def axes_labels(ax: Any, x: str, y: str) -> None:
    """Both axes labelled by :func:`label`."""
    ax.set_xlabel(label(x))
    ax.set_ylabel(label(y))


# -- notebook summaries ------------------------------------------------------------------


def number(v: Any, digits: int = 4) -> str:
    """A value as the summaries write it: ``-`` for None and NaN, ``digits`` significant
    digits for a float."""
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (float, np.floating)):
        return "-" if math.isnan(v) else f"{float(v):.{digits}g}"
    return str(v)


def html_table(title: str, rows: Sequence[tuple[str, Any]]) -> str:
    """A notebook's summary: a bold title and a two-column table of (quantity, value)."""
    body = "".join(f"<tr><th style='text-align:left'>{html.escape(str(k))}</th>"
                   f"<td style='text-align:left'>{html.escape(number(v))}</td></tr>"
                   for k, v in rows)
    return f"<b>{html.escape(title)}</b><table>{body}</table>"


class Summarised:
    """Short text and an HTML table for a notebook from one method, :meth:`_summary`,
    which returns the one-line headline and the (quantity, value) rows of the table.
    A dataclass using it is declared with ``repr=False`` so that this ``__repr__`` is
    kept (its fields and equality are the dataclass's)."""

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        raise NotImplementedError

    def __repr__(self) -> str:
        return self._summary()[0]

    def _repr_html_(self) -> str:
        head, rows = self._summary()
        return html_table(head, rows)


def pyplot() -> Any:
    """matplotlib's pyplot, or an ImportError naming the extra that installs it."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the install
        raise ImportError("plotting needs matplotlib: pip install 'ballbal[plot]'") from e
    return plt


def new_axes(ax: Any = None, figsize: tuple[float, float] = (5.5, 4.0)) -> Any:
    """``ax`` or the axes of a new figure."""
    if ax is not None:
        return ax
    _, ax = pyplot().subplots(figsize=figsize, constrained_layout=True)
    return ax


#: One look for stability everywhere: solid stable, dashed unstable, dotted undecided.
LINESTYLE = {"stable": "-", "unstable": "--", "marginal": ":", "undetermined": ":"}


def stability_runs(values: Sequence[str | None]) -> list[tuple[int, int, str]]:
    """Runs ``(first, last, verdict)`` of equal verdicts along a branch, each run
    sharing its end point with the next so that the drawn line has no gaps."""
    runs: list[tuple[int, int, str]] = []
    start = 0
    for i in range(1, len(values) + 1):
        if i == len(values) or values[i] != values[start]:
            runs.append((start, min(i, len(values) - 1), str(values[start])))
            start = i
    return runs
