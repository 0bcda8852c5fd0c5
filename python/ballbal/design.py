"""Design charts in lab units: from which spin (rpm) the balls balance the rotor stably,
against the ball mass or the track radius, for a machine given in SI quantities
(:meth:`ballbal.Balancer.from_lab`).

For each design value the machine is nondimensionalised once (its ``w_n = sqrt(k /
M_tot)`` includes the balls), the perfect balance's stability is mapped over the spins
(:func:`ballbal.balance_map`), and the lowest speed from which it stays stable up to the
top of the range is refined by bisection on :func:`ballbal.balanced_state`'s verdict.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import polars as pl

from . import _check
from .balance import balance_map, balanced_state
from .exceptions import ParameterError
from .model import Balancer

#: Most design values in one chart (each a stability map over the spins).
MAX_DESIGN_VALUES = 1000
#: Most spins mapped per design value.
MAX_SPINS = 10_000
_RPM = 60.0 / (2.0 * math.pi)  # rad/s -> rpm


@dataclass(frozen=True)
class DesignChart:
    """The result of :func:`critical_speed_chart`. ``table``: one row per design value:
    the varied quantity (``ball_mass`` [kg] or ``track_radius`` [m]), ``eta`` (each
    ball's capacity), ``natural_frequency_rpm`` (``sqrt(k / M_tot)``, balls included),
    ``critical_speed_rpm`` (the lowest spin from which the perfect balance is stable up
    to ``max_rpm``; null unless ``status`` is ``"ok"``), ``critical_ratio`` (over the
    natural frequency), ``status``: ``"ok"``, ``"no_balance"`` (the balls cannot cancel
    the imbalance: ``sum eta <= 1``), ``"never_stable"`` (not stable at ``max_rpm``),
    ``"stable_from_lowest"`` (already stable at the lowest spin of the range, so the
    boundary lies below it). ``vary``: the varied column's name."""

    table: pl.DataFrame
    vary: str

    def plot(self, ax: Any = None) -> Any:
        """Critical speed and natural frequency [rpm] against the varied quantity; the
        balls balance above the critical-speed line."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(6, 4))
        t = self.table
        x = t[self.vary].to_numpy()
        crit = t["critical_speed_rpm"].to_numpy().astype(float)
        ax.plot(x, crit, "o-", color="tab:green", label="stable balancing from")
        ax.plot(x, t["natural_frequency_rpm"].to_numpy(), "--", color="0.4",
                label="natural frequency")
        top = np.nanmax(crit) if np.any(np.isfinite(crit)) else 1.0
        ax.fill_between(x, np.where(np.isfinite(crit), crit, np.nan), 1.3 * top,
                        color="tab:green", alpha=0.15)
        unit = "kg" if self.vary == "ball_mass" else "m"
        ax.set_xlabel(f"{self.vary.replace('_', ' ')} [{unit}]")
        ax.set_ylabel("spin [rpm]")
        ax.legend()
        return ax


def _lowest_stable_speed(b: Balancer, omegas: np.ndarray) -> tuple[str, float | None]:
    """``(status, Omega)``: the lowest Omega of the map from which every point up to the
    top is stable, refined by bisection against the first unstable point below it."""
    df = balance_map(b, Omega=omegas)
    if (df["status"] == "no_balance").any():
        return "no_balance", None
    stable = (df["stability"] == "stable").to_numpy()
    if not stable[-1]:
        return "never_stable", None
    below = np.nonzero(~stable)[0]
    if below.size == 0:
        return "stable_from_lowest", float(omegas[0])
    lo, hi = float(omegas[below[-1]]), float(omegas[below[-1] + 1])
    for _ in range(40):  # to 1e-12 of the grid step
        mid = 0.5 * (lo + hi)
        e = balanced_state(b.replace(Omega=mid))
        if e is not None and e.stability == "stable":
            hi = mid
        else:
            lo = mid
    return "ok", hi


def critical_speed_chart(
    *,
    vary: str,
    values: Sequence[float] | np.ndarray,
    disk_mass: float,
    eccentricity: float,
    ball_mass: float,
    track_radius: float,
    stiffness: float,
    damping: float,
    track_damping: float,
    n_balls: int = 2,
    other_mass: float = 0.0,
    max_rpm: float,
    spins: int = 400,
) -> DesignChart:
    """The spin [rpm] from which the balls balance stably, against ``vary`` =
    ``"ball_mass"`` (each ball's mass [kg]) or ``"track_radius"`` [m] over ``values``
    (the other one fixed at ``ball_mass`` / ``track_radius``).

    The machine, in SI units as :meth:`ballbal.Balancer.from_lab` takes it:
    ``disk_mass`` [kg] carrying the imbalance at ``eccentricity`` [m], ``n_balls`` equal
    balls (1 to :data:`~ballbal._check.MAX_BALLS`), the support's ``stiffness`` [N/m] and
    ``damping`` [N s/m], ``track_damping`` ``c_b`` [N s/m] on each ball's speed relative
    to the track, ``other_mass`` [kg] (rotor and motor base). The stability is mapped on
    ``spins`` equally spaced speeds (2 to :data:`MAX_SPINS`) from ``max_rpm / spins`` to
    ``max_rpm``; at most :data:`MAX_DESIGN_VALUES` values. Returns a
    :class:`DesignChart` (a table and its ``.plot()``)."""
    if not isinstance(vary, str) or vary not in ("ball_mass", "track_radius"):
        raise ParameterError("vary", f"must be 'ball_mass' or 'track_radius', got {vary!r:.60}",
                             allowed="ball_mass, track_radius")
    vals = _check.vector("values", values, MAX_DESIGN_VALUES)
    if np.any(vals <= 0):
        raise ParameterError("values", f"every value of {vary} must be > 0",
                             allowed="(0, inf)", value=values)
    n = _check.integer("n_balls", n_balls, 1, _check.MAX_BALLS)
    max_rpm = _check.real("max_rpm", max_rpm, 0.0, lo_open=True, finite=True)
    count = _check.integer("spins", spins, 2, MAX_SPINS)
    spin_grid = np.linspace(max_rpm / count, max_rpm, count) / _RPM  # rad/s
    rows = []
    for v in vals:
        mb = float(v) if vary == "ball_mass" else ball_mass
        rt = float(v) if vary == "track_radius" else track_radius
        b = Balancer.from_lab(disk_mass=disk_mass, eccentricity=eccentricity,
                              ball_masses=[mb] * n, track_radius=rt, stiffness=stiffness,
                              damping=damping, track_damping=track_damping, spin=1.0,
                              other_mass=other_mass)
        wn = 1.0 / b.Omega  # spin 1 rad/s is Omega = 1 / w_n
        status, om = _lowest_stable_speed(b, spin_grid / wn)
        crit = om * wn * _RPM if status == "ok" and om is not None else None
        rows.append({vary: float(v), "eta": b.eta[0], "natural_frequency_rpm": wn * _RPM,
                     "critical_speed_rpm": crit,
                     "critical_ratio": None if crit is None else crit / (wn * _RPM),
                     "status": status})
    schema = {vary: pl.Float64, "eta": pl.Float64, "natural_frequency_rpm": pl.Float64,
              "critical_speed_rpm": pl.Float64, "critical_ratio": pl.Float64,
              "status": pl.String}
    return DesignChart(pl.DataFrame(rows, schema=schema), vary)
