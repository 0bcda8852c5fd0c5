"""Speed sweeps as an experiment is run (Tien's (2011) section 4-2): the speed is stepped
up, then down, with a dwell at each step, the state carried over from step to step, and
the motion at each step labelled by the basins' classifier
(:func:`ballbal.basins.basins`' labels).

Carrying the state over a speed step
------------------------------------
The state lives in the frame rotating with the disk at ``Omega``. A step changes the
disk's speed from ``Omega_a`` to ``Omega_b`` at an instant; what is continuous there is
the ground-frame state: the disk centre ``Z = (x + i y) e^(i theta)`` and its velocity
``Z' = (x' + i y' + i Omega (x + i y)) e^(i theta)``, and each ball's absolute angle
``theta + b_i`` and rate ``Omega + b_i'`` (the disk's angle ``theta`` is continuous;
only its rate jumps). Hence, with ``D = Omega_a - Omega_b``::

    x, y, b_i  unchanged
    x' -> x' - D y,    y' -> y' + D x,    b_i' -> b_i' + D

(at the perfect balance, ``x = y = 0`` and the balls at rest on the disk, the balls
keep their absolute speed and so slip by ``D`` relative to the new disk speed).

A tilting disk (:class:`ballbal.Tilt`) also keeps the ground-frame motion of its axis:
its Euler tilts ``alpha = A / delta``, ``beta = B / delta`` are continuous, and of the
disk's angular velocity the two components across the axis (body ``x, y``:
``alpha' cos beta - Omega cos alpha sin beta`` and ``beta' + Omega sin alpha``), so::

    A' -> A' - D delta cos(alpha) tan(beta),    B' -> B' + D delta sin(alpha)

(to first order ``A' - D B`` and ``B' + D A``, as for ``x, y``).

The symmetry-breaking kick
--------------------------
Merged balls (``b1 = b2``) stay merged for ever in a simulation of identical balls (the
diagonal is invariant), which no rig does. ``kick`` (default 1e-3 rad) moves ball 1 by
``+kick`` and ball 2 by ``-kick`` at the start of every step, as a tap on the rig
would (two balls or more; one ball is not kicked); ``kick=0`` switches it off.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np
import polars as pl

from . import _check, _native
from ._progress import Progress, ProgressArg
from ._style import Summarised, value_range
from .basins import REST, ROTATING, BasinOptions
from .exceptions import NotAutonomousError, ParameterError, ParameterTypeError
from .model import Balancer
from .scene import Scene, model_argument

#: Longest ``dwell`` (and ``record``): the basins' classifier's longest ``t_end``
#: (``BasinOptions``, checked in the core), which a step's dwell is.
MAX_DWELL = 1e6


def carry_over(y: np.ndarray, omega_from: float, omega_to: float, n_balls: int,
               d: int, *, delta: float | None = None) -> np.ndarray:
    """The rotating-frame state after a speed step from ``omega_from`` to ``omega_to``
    with the ground-frame state continuous (see the module's description); ``y`` has
    ``2 d`` values (``d`` coordinates, the last ``n_balls`` of them the balls'). A
    tilting disk's state (``x, y, A, B``, then the balls) needs its ``delta`` (the
    tilts' scale), which carries ``A', B'`` over too."""
    d = _check.integer("d", d, 3, _check.MAX_BALLS + 4)
    n_balls = _check.integer("n_balls", n_balls, 1, d - 2)
    y = _check.vector("y", y, 2 * d).copy()
    if y.size != 2 * d:
        raise ParameterError("y", f"needs 2 d = {2 * d} values, got {y.size}",
                             allowed=f"{2 * d} values", value=y.size)
    omega_from = _check.real("omega_from", omega_from, finite=True)
    omega_to = _check.real("omega_to", omega_to, finite=True)
    dd = omega_from - omega_to
    x, yy = y[0], y[1]
    y[d] -= dd * yy
    y[d + 1] += dd * x
    y[2 * d - n_balls:] += dd
    if delta is not None:
        delta = _check.real("delta", delta, 0.0, lo_open=True, finite=True)
        if d != n_balls + 4:
            raise ParameterError("d", f"a tilting disk has d = n_balls + 4 = {n_balls + 4} "
                                 f"coordinates, got {d}")
        alpha, beta = y[2] / delta, y[3] / delta
        y[d + 2] -= dd * delta * np.cos(alpha) * np.tan(beta)
        y[d + 3] += dd * delta * np.sin(alpha)
    return y


@dataclass(frozen=True, repr=False)
class Sweep(Summarised):
    """The result of :func:`speed_sweep`: ``table`` (one row per step: ``step,
    direction, Omega, Omega_index`` (the speed's position on the ``speeds`` axis, for
    exact joins), ``label, omega`` (mean ball rate), ``period``, ``rotating``, and
    ``vibration`` (mean ``|Z''|`` over the last ``record`` time units of the dwell) when
    recorded); ``up`` and ``down``: the transition speeds (Tien's (2011) critical speeds:
    the first speed going up at which the motion is at rest on an equilibrium after
    moving, the first speed going down at which it moves again; ``None`` if none)."""

    table: pl.DataFrame
    up: float | None
    down: float | None
    #: One windowed ground-frame acceleration spectrum per step (flat-top, two-sided over
    #: ``X + iY``, :func:`ballbal.spectrum.signal_spectrum`) of the recorded stretch; empty
    #: when ``record`` was ``None``. Its resolution is ``1 / record`` cycles per time unit.
    spectra: tuple[pl.DataFrame, ...] = ()

    def waterfall(self) -> pl.DataFrame:
        """The steps' spectra as one long table (:func:`ballbal.spectrum.waterfall`),
        each row tagged with its ``step``, ``direction`` and ``Omega``: Tien's (2011)
        spectra over a speed sweep, forward and backward whirl apart."""
        from .spectrum import waterfall

        if not self.spectra:
            raise ParameterError("record", "the sweep recorded no signal (record=None)",
                                 allowed="record > 0")
        steps = self.table.select("step", "direction", "Omega").rows()
        parts = [(om, sp.with_columns(pl.lit(k).alias("step"), pl.lit(dirn).alias("direction")))
                 for (k, dirn, om), sp in zip(steps, self.spectra, strict=True)]
        return waterfall(parts)

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        span = value_range(self.table["Omega"])
        dirs = "/".join(dict.fromkeys(self.table["direction"].to_list()))
        hy = self.hysteresis
        head = (f"Sweep Ω {span} {dirs}: {self.table.height} steps, up {_fmt(self.up)}, "
                f"down {_fmt(self.down)}, hysteresis {_fmt(hy)}")
        labels = self.table["label"].unique(maintain_order=True).to_list()
        return head, [("speeds Ω", span), ("directions", dirs), ("steps", self.table.height),
                      ("up (critical speed)", self.up), ("down (critical speed)", self.down),
                      ("hysteresis up - down", hy), ("motions seen", ", ".join(labels)),
                      ("spectra recorded", len(self.spectra))]

    def plot(self, axes: Any = None) -> Any:
        """The balls' mean rate and (when recorded) the vibration against the speed, up
        and down, the transition speeds marked (the hysteresis); returns the figure."""
        from ._figures import sweep

        return sweep(self, axes)

    @property
    def hysteresis(self) -> float | None:
        """``up - down``: the width of the speed range where both motions are seen."""
        if self.up is None or self.down is None:
            return None
        return self.up - self.down


def _fmt(v: float | None) -> str:
    return "-" if v is None else f"{v:.4g}"


def speed_sweep(
    model: Balancer | Scene,
    speeds: Sequence[float] | np.ndarray | tuple[float, float, float] | str,
    *,
    dwell: float = 1000.0,
    direction: Literal["up-down", "up", "down"] = "up-down",
    kick: float = 1e-3,
    record: float | None = 100.0,
    y0: Sequence[float] | np.ndarray | None = None,
    options: BasinOptions | None = None,
    progress: ProgressArg = False,
) -> Sweep:
    """Step the speed through ``speeds`` (ascending; ``(start, stop, step)`` with
    ``stop`` included, or explicit values, as every gridded function takes an axis) up,
    then back down (``"up-down"``: the top speed is not repeated), dwelling ``dwell``
    time units at each step, and label the motion at each (the basins' classifier over
    the last ``options.window`` of the dwell).

    ``model``: a balancer or an autonomous scene (ball springs, a tilting disk, a bearing
    or an anisotropic support with equal axes; a ramp, gravity, an impulse or unequal
    support axes are an error naming the effect: the sweep is its own speed change).

    ``y0``: the state at the first step (default: at rest in the ground frame, the disk
    flat, the balls together at angle 0.3 of the disk, as a rig is started). ``kick``:
    see the module's description. ``record``: simulate that long more after each step's
    dwell, without changing the state carried on, for the vibration indicator
    (:func:`ballbal.spectrum.vibration`); ``None`` skips it.

    Bounds (a :class:`~ballbal.exceptions.ParameterError` naming the argument, before
    any step runs): at most :data:`~ballbal._check.MAX_SWEEP_STEPS` steps, ``dwell``
    and ``record`` in ``(0, 1e6]``, ``|kick| <= pi``, and at most
    :data:`~ballbal._check.MAX_SAMPLES` recorded samples over the sweep.

    ``progress``: True for a progress bar over the steps (tqdm, notebook-aware), or a
    callable ``f(done_steps, total_steps)``.
    """
    from .analysis import simulate
    from .spectrum import ground_signal, signal_spectrum, vibration

    model_argument("model", model)
    if not isinstance(model, (Balancer, Scene)):
        raise ParameterTypeError("model", "speed sweeps take a Balancer or a Scene",
                                 value=model)
    if isinstance(model, Scene) and model.time_dependence is not None:
        raise NotAutonomousError(
            model.time_dependence,
            f"speed_sweep: the sweep sets the speed of each step, so the scene must be "
            f"autonomous, but it has '{model.time_dependence}'")
    tilt_delta = (model.balancer.delta if isinstance(model, Scene) and model.tilt is not None
                  else None)
    if not isinstance(direction, str) or direction not in ("up-down", "up", "down"):
        raise ParameterError("direction", f"must be 'up-down', 'up' or 'down', got "
                             f"{direction!r:.60}", allowed="up-down, up, down")
    # an axis as every gridded function reads it: (start, stop, step) is a range
    sp = _check.axis("speeds", speeds, _check.MAX_SWEEP_STEPS)
    if np.any(sp < 0) or np.any(np.diff(sp) <= 0):
        raise ParameterError("speeds", "give ascending speeds >= 0 (values of Omega)",
                             allowed="ascending values in [0, inf)", value=speeds)
    steps = 2 * sp.size - 1 if direction == "up-down" else sp.size
    _check.at_most("speeds", steps, _check.MAX_SWEEP_STEPS, f"steps going {direction}")
    # The dwell is the classifier's t_end: its range, named as the caller wrote it.
    dwell = _check.real("dwell", dwell, 0.0, MAX_DWELL, lo_open=True)
    kick = _check.real("kick", kick, -np.pi, np.pi)
    if record is not None:
        record = _check.real("record", record, 0.0, MAX_DWELL, lo_open=True)
        # every step keeps the spectrum of its 20 samples per time unit
        _check.at_most("record", steps * (int(record * 20) + 1), _check.MAX_SAMPLES,
                       "recorded samples over the sweep (20 per time unit and step)")
    o = _check.option("options", options, BasinOptions, BasinOptions(),
                      "ballbal.basins.BasinOptions")
    o = replace(o, t_end=dwell, window=min(o.window, dwell), settle_factor=None)
    # (position on the speeds axis, direction): the index column makes joins exact
    if direction == "up":
        path = [(i, "up") for i in range(sp.size)]
    elif direction == "down":
        path = [(i, "down") for i in range(sp.size)[::-1]]
    else:
        path = ([(i, "up") for i in range(sp.size)]
                + [(i, "down") for i in range(sp.size - 1)[::-1]])
    n = model.n_balls
    d = len(model.coordinates)
    if y0 is None:
        y = np.zeros(2 * d)
        y[d - n:d] = 0.3
        y[2 * d - n:] = -float(sp[path[0][0]])
    else:
        y = _check.vector("y0", y0, 2 * d).copy()
        if y.size != 2 * d:
            raise ParameterError("y0", f"needs {2 * d} values ({', '.join(model.coordinates)} "
                                 f"and their rates), got {y.size}",
                                 allowed=f"{2 * d} values", value=y.size)
    prev = float(sp[path[0][0]])
    rows: list[dict[str, Any]] = []
    spectra: list[pl.DataFrame] = []
    with Progress(progress, len(path), "ballbal speed sweep") as bar:
        for k, (i, dirn) in enumerate(path):
            om = float(sp[i])
            y = carry_over(y, prev, om, n, d, delta=tilt_delta)
            if kick and n >= 2:
                y[d - n] += kick
                y[d - n + 1] -= kick
            m = model.replace(Omega=om)
            cols, y = _native.classify_state(m, np.ascontiguousarray(y), o)
            row: dict[str, Any] = {"step": k, "direction": dirn, "Omega": om, "Omega_index": i,
                                   "label": cols["label"][0], "omega": cols["omega"][0],
                                   "period": cols["period"][0]}
            row["rotating"] = row["label"] in ROTATING
            row["at_rest"] = row["label"] in REST
            if record is not None:
                rec = simulate(m, y, t_eval=np.linspace(0.0, record, int(record * 20) + 1),
                               rtol=o.rtol, atol=o.atol)
                row["vibration"] = vibration(rec).mean
                spectra.append(signal_spectrum(ground_signal(rec), window="flattop"))
            rows.append(row)
            prev = om
            bar.update()
    table = pl.DataFrame(rows)
    return Sweep(table, *_transitions(table, direction), spectra=tuple(spectra))


def _transitions(table: pl.DataFrame, direction: str) -> tuple[float | None, float | None]:
    """Going up, the first speed at rest (an equilibrium) after a moving step; going
    down, the first moving step after rest (a transient, ``not_settled``, counts as
    moving: the balls have left the equilibrium)."""
    up = down = None
    was: bool | None = None
    for r in table.filter(pl.col("direction") == "up").iter_rows(named=True):
        if was is False and r["at_rest"]:
            up = r["Omega"]
            break
        was = r["at_rest"]
    ups = table.filter(pl.col("direction") == "up")
    was = bool(ups["at_rest"][-1]) if direction == "up-down" and ups.height else None
    for r in table.filter(pl.col("direction") == "down").iter_rows(named=True):
        if was is True and not r["at_rest"]:
            down = r["Omega"]
            break
        was = r["at_rest"]
    return up, down
