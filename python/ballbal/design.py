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
from ._progress import Progress, ProgressArg
from ._style import Summarised
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
    progress: ProgressArg = False,
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
    :class:`DesignChart` (a table and its ``.plot()``).

    ``progress``: True for a progress bar over the values (tqdm, notebook-aware), or a
    callable ``f(done, total)``."""
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
    with Progress(progress, len(vals), "ballbal critical speeds", "value") as bar:
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
            bar.update()
    schema = {vary: pl.Float64, "eta": pl.Float64, "natural_frequency_rpm": pl.Float64,
              "critical_speed_rpm": pl.Float64, "critical_ratio": pl.Float64,
              "status": pl.String}
    return DesignChart(pl.DataFrame(rows, schema=schema), vary)


# --- charts from a model: where a sweep up ends balanced, and how often a start does --

#: What :func:`balancing_chart` varies, with the unit its values are given in.
BALANCING_AXES = {"zeta_b": "", "oil_viscosity": "cP", "imbalance": "g mm"}
#: Most random starts per speed in :func:`balanced_fraction`.
MAX_STARTS_PER_SPEED = 100_000


@dataclass(frozen=True, repr=False)
class BalancingChart(Summarised):
    """The result of :func:`balancing_chart`. ``table``: one row per design value: the
    varied quantity (``zeta_b``; ``oil_viscosity`` [cP]; or ``imbalance``, the rotor's
    ``m_d e`` [g mm]), the model's ``zeta_b`` and each ball's ``eta`` there,
    ``eta_margin`` (``sum eta - 1``: the capacity left over the imbalance; balancing
    needs it > 0), ``chasing_end_rpm`` (the largest speed with a stable chasing motion
    of ``pattern``, :func:`ballbal.calibration.stable_band_end`; null without one),
    ``perfect_balance_from_rpm`` (the lowest speed of the range from which the perfect
    balance is stable to its top; null where it is not), ``balanced_from_rpm`` (the
    larger of the two: a sweep up ends balanced past it) and ``status`` (as
    :class:`DesignChart`'s). ``vary``: the varied column; ``natural_frequency_rpm``."""

    table: pl.DataFrame
    vary: str
    natural_frequency_rpm: float

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        t = self.table
        ok = t["balanced_from_rpm"].drop_nulls().to_numpy()
        span = (f"{ok.min():.0f}-{ok.max():.0f} rpm" if ok.size else "none")
        head = (f"BalancingChart({self.vary}: {t.height} values, balanced from {span}; "
                f"f_n {self.natural_frequency_rpm:g} rpm)")
        rows: list[tuple[str, Any]] = [("natural frequency (rpm)", self.natural_frequency_rpm)]
        for r in t.iter_rows(named=True):
            rows.append((f"{self.vary} = {r[self.vary]:g}: balanced from (rpm)",
                         r["balanced_from_rpm"]))
        return head, rows

    def plot(self, ax: Any = None) -> Any:
        """The chasing band's end and the perfect balance's onset [rpm] against the
        varied quantity; a sweep up ends balanced above both. Returns the axes."""
        from ._style import new_axes

        ax = new_axes(ax)
        t = self.table
        x = t[self.vary].to_numpy()
        for col, style, label in (
                ("chasing_end_rpm", "o-", "chasing band ends"),
                ("perfect_balance_from_rpm", "s--", "perfect balance stable from")):
            ax.plot(x, t[col].to_numpy().astype(float), style, ms=4, label=label)
        top = t["balanced_from_rpm"].to_numpy().astype(float)
        if np.any(np.isfinite(top)):
            ax.fill_between(x, top, 1.2 * np.nanmax(top), color="tab:green", alpha=0.15,
                            label="balanced")
        ax.axhline(self.natural_frequency_rpm, color="0.5", lw=0.8, ls=":")
        unit = BALANCING_AXES[self.vary]
        ax.set_xlabel(self.vary.replace("_", " ") + (f" [{unit}]" if unit else ""))
        ax.set_ylabel("speed [rpm]")
        ax.legend(frameon=False, fontsize=8)
        return ax


def balancing_chart(
    model: Balancer,
    *,
    vary: str,
    values: Sequence[float] | np.ndarray,
    natural_frequency_rpm: float,
    ball_mass: float | None = None,
    ball_radius: float | None = None,
    track_radius: float | None = None,
    channel_radius: float | None = None,
    geometric_factor: float = 1.0,
    pattern: str = "R-R",
    Omega: Any = (1.0, 2.5, 0.01),  # noqa: N803 - the model's symbol
    progress: ProgressArg = False,
) -> BalancingChart:
    """From which speed [rpm] a sweep up ends balanced, against ``vary``:

    - ``"zeta_b"``: the model's track damping, directly;
    - ``"oil_viscosity"`` [cP]: ``zeta_b`` from the oil law
      (:func:`ballbal.oil.track_damping` with ``ball_radius``, ``ball_mass`` [m, kg],
      ``channel_radius`` and the calibrated ``geometric_factor``, e.g. from
      :func:`ballbal.calibration.transfer_oils`);
    - ``"imbalance"``: the rotor's ``m_d e`` [g mm], each ball's ``eta = m_b r / (m_d
      e)`` from ``ball_mass`` [kg] and ``track_radius`` [m] (the margin of ``eta``).

    Everything else is ``model``'s; ``natural_frequency_rpm`` turns the model's speed
    ``Omega`` into rpm. Per value: the chasing band's end
    (:func:`ballbal.calibration.stable_band_end` of ``pattern`` over the ``Omega``
    grid ``(start, stop, step)``) and the perfect balance's onset on that grid,
    refined by bisection. At most :data:`MAX_DESIGN_VALUES` values.

    ``progress``: True for a progress bar over the values (tqdm, notebook-aware), or a
    callable ``f(done, total)``."""
    from .calibration import _balancer, stable_band_end
    from .oil import CENTIPOISE, track_damping

    _balancer(model)
    if not isinstance(vary, str) or vary not in BALANCING_AXES:
        raise ParameterError("vary", f"must be one of {', '.join(BALANCING_AXES)}, got "
                             f"{vary!r:.60}", allowed=", ".join(BALANCING_AXES))
    vals = _check.vector("values", values, MAX_DESIGN_VALUES)
    if np.any(vals <= 0):
        raise ParameterError("values", f"every value of {vary} must be > 0",
                             allowed="(0, inf)", value=values)
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                     lo_open=True, hi_open=True)
    if vary == "oil_viscosity" and (ball_mass is None or ball_radius is None):
        raise ParameterError("ball_radius", "the oil law needs ball_radius and ball_mass")
    if vary == "imbalance":
        if ball_mass is None or track_radius is None:
            raise ParameterError("track_radius", "eta from the imbalance needs track_radius "
                                 "and ball_mass")
        mb = _check.real("ball_mass", ball_mass, 0.0, math.inf, lo_open=True, hi_open=True)
        rt = _check.real("track_radius", track_radius, 0.0, math.inf, lo_open=True,
                         hi_open=True)
    if not (isinstance(Omega, tuple) and len(Omega) == 3):
        raise ParameterError("Omega", "must be a (start, stop, step) tuple of the model's "
                             f"speed, got {Omega!r:.60}")
    o0, o1, step = (_check.real("Omega", v, 0.0, math.inf, lo_open=True, hi_open=True)
                    for v in Omega)
    if not (o0 < o1 and step < o1 - o0):
        raise ParameterError("Omega", f"must have start < stop and step < stop - start, got "
                             f"{Omega}")
    count = int(math.floor((o1 - o0) / step + 1e-9)) + 1
    if count > MAX_SPINS:
        raise ParameterError("Omega", f"the grid has {count} speeds, more than {MAX_SPINS}")
    grid = o0 + step * np.arange(count)
    rows = []
    with Progress(progress, len(vals), "ballbal balancing chart", "value") as bar:
        for v in vals:
            b = model
            if vary == "zeta_b":
                b = model.replace(zeta_b=float(v))
            elif vary == "oil_viscosity":
                assert ball_radius is not None and ball_mass is not None
                b = model.replace(zeta_b=track_damping(
                    float(v) * CENTIPOISE, ball_radius=ball_radius, ball_mass=ball_mass,
                    natural_frequency_rpm=fn, channel_radius=channel_radius,
                    geometric_factor=geometric_factor))
            else:
                b = model.replace(eta=tuple([mb * rt * 1e6 / float(v)] * model.n_balls))
            end = stable_band_end(b, pattern, Omega=Omega)
            status, om = _lowest_stable_speed(b, grid)
            onset = om * fn if status in ("ok", "stable_from_lowest") and om is not None else None
            chase = None if end is None else end * fn
            known = [s for s in (chase, onset) if s is not None]
            top = max(known) if onset is not None else None
            rows.append({vary: float(v), "zeta_b": float(np.mean(b.zeta_b)),
                         "eta": float(np.mean(b.eta)), "eta_margin": float(np.sum(b.eta)) - 1.0,
                         "chasing_end_rpm": chase, "perfect_balance_from_rpm": onset,
                         "balanced_from_rpm": top, "status": status})
            bar.update()
    schema = {vary: pl.Float64, "zeta_b": pl.Float64, "eta": pl.Float64,
              "eta_margin": pl.Float64, "chasing_end_rpm": pl.Float64,
              "perfect_balance_from_rpm": pl.Float64, "balanced_from_rpm": pl.Float64,
              "status": pl.String}
    return BalancingChart(pl.DataFrame(rows, schema=schema), vary, fn)


@dataclass(frozen=True, repr=False)
class BalancedFraction(Summarised):
    """The result of :func:`balanced_fraction`. ``table``: one row per speed:
    ``speed_rpm``, ``Omega``, ``starts``, ``balanced`` (starts that ended at the perfect
    balance), ``fraction`` and its binomial ``std_error`` ``sqrt(p (1 - p) / n)``, and
    ``rotating`` (starts that ended with a ball rotating)."""

    table: pl.DataFrame
    natural_frequency_rpm: float

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        t = self.table
        head = (f"BalancedFraction({t.height} speeds x {t['starts'][0]} starts, fraction "
                f"{float(np.min(t['fraction'].to_numpy())):.2f}-"
                f"{float(np.max(t['fraction'].to_numpy())):.2f})")
        rows = [(f"{r['speed_rpm']:.0f} rpm", f"{r['fraction']:.3f} ± {r['std_error']:.3f}")
                for r in t.iter_rows(named=True)]
        return head, rows

    def plot(self, ax: Any = None) -> Any:
        """The fraction with one-standard-error bars against the speed; returns the
        axes."""
        from ._style import new_axes

        ax = new_axes(ax)
        t = self.table
        ax.errorbar(t["speed_rpm"], t["fraction"], yerr=t["std_error"], fmt="o-", ms=4,
                    capsize=2)
        ax.set_ylim(-0.02, 1.02)
        ax.set_xlabel("speed [rpm]")
        ax.set_ylabel("starts from rest ending balanced")
        return ax


def balanced_fraction(
    model: Balancer,
    *,
    speeds_rpm: Sequence[float] | np.ndarray,
    natural_frequency_rpm: float,
    starts: int = 200,
    seed: int = 0,
    t_end: float = 1000.0,
    progress: ProgressArg = False,
) -> BalancedFraction:
    """The fraction of starts from rest (the rotor at rest in the ground frame, the two
    balls at uniformly random angles, :func:`ballbal.basins.basins` with ``samples``)
    that end at the perfect balance, per speed in ``speeds_rpm`` (at most
    :data:`MAX_DESIGN_VALUES`), with its binomial standard error. ``starts`` per speed
    (1 to :data:`MAX_STARTS_PER_SPEED`) drawn from ``seed`` (the same angles at every
    speed); ``t_end``: time simulated per start (model units).

    ``progress``: True for a progress bar over the speeds (tqdm, notebook-aware), or a
    callable ``f(done, total)``."""
    from .basins import ROTATING, basins
    from .calibration import _balancer

    _balancer(model)
    sp = _check.vector("speeds_rpm", speeds_rpm, MAX_DESIGN_VALUES)
    if np.any(sp <= 0):
        raise ParameterError("speeds_rpm", "every speed must be > 0", allowed="(0, inf)",
                             value=speeds_rpm)
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                     lo_open=True, hi_open=True)
    n = _check.integer("starts", starts, 1, MAX_STARTS_PER_SPEED)
    s = _check.integer("seed", seed, 0, 2**63 - 1)
    rows = []
    with Progress(progress, len(sp), "ballbal balanced fraction", "speed") as bar:
        for v in sp:
            res = basins(model.replace(Omega=float(v) / fn), samples=n, seed=s, t_end=t_end,
                         orbits=False)
            labels = res.table["label"]
            k = int((labels == "perfect_balance").sum())
            p = k / n
            rows.append({"speed_rpm": float(v), "Omega": float(v) / fn, "starts": n,
                         "balanced": k, "fraction": p, "std_error": math.sqrt(p * (1 - p) / n),
                         "rotating": int(labels.is_in(list(ROTATING)).sum())})
            bar.update()
    schema = {"speed_rpm": pl.Float64, "Omega": pl.Float64, "starts": pl.Int64,
              "balanced": pl.Int64, "fraction": pl.Float64, "std_error": pl.Float64,
              "rotating": pl.Int64}
    return BalancedFraction(pl.DataFrame(rows, schema=schema), fn)
