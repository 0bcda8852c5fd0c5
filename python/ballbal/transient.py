"""Transients after a spin-speed disturbance ([TwoBallStrength]): the peak radial amplitude, the
time to settle inside a band, and the track damping that trades the two off."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, cast

import numpy as np
import polars as pl

from . import _check
from ._progress import Progress, ProgressArg
from ._style import Summarised
from .analysis import capacities, equilibria, simulate
from .balance import balanced_state
from .exceptions import NotAutonomousError, ParameterError
from .model import Balancer
from .scene import Ramp, Scene, model_argument


@dataclass(frozen=True, repr=False)
class DisturbanceResponse(Summarised):
    """``peak``: largest radial amplitude ``r = sqrt(x^2 + y^2)`` after the disturbance
    starts; ``settle_time``: time from the start of the disturbance after which ``r``
    stays within ``band`` of its final value (None if it never does before ``t_end``);
    ``final_r``; ``trajectory``: the simulation (polars)."""

    peak: float
    settle_time: float | None
    final_r: float
    trajectory: pl.DataFrame

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        settle = "never" if self.settle_time is None else f"{self.settle_time:.4g}"
        head = (f"DisturbanceResponse peak |Z|={self.peak:.4g} settles after {settle} "
                f"final |Z|={self.final_r:.3g} ({self.trajectory.height} samples)")
        return head, [("peak |Z| (e)", self.peak), ("settling time (1/ω_n)", self.settle_time),
                      ("final |Z| (e)", self.final_r), ("samples", self.trajectory.height)]

    def plot(self, ax: Any = None, *, start: float | None = None,
             band: float | None = None) -> Any:
        """``|Z|`` against time; given the disturbance's ``start`` and the ``band`` it was
        measured with (:func:`disturbance_response`'s; the result does not keep them),
        the settling band and the settling time marked too. Returns the axes."""
        from ._figures import trajectory_radius

        at = (None if self.settle_time is None or start is None
              else _check.real("start", start) + self.settle_time)
        return trajectory_radius(self.trajectory, ax, final=self.final_r, settle_at=at,
                                 band=None if band is None else _check.real("band", band))


def _balanced_start(model: Balancer | Scene) -> np.ndarray:
    """The steady state at the starting speed, where the disturbance begins: the stable
    balanced state; or, when the balls cannot cancel the imbalance (total capacity
    ``sum eta_i <= 1``, [TwoBallStrength]'s light-ball cases), the stable equilibrium in which they
    settle against it (of several, the one leaving the least imbalance), or at exactly
    the capacity the perfect balance, marginal as it is."""
    if isinstance(model, Scene) and model.time_dependence is not None:
        raise NotAutonomousError(
            model.time_dependence,
            f"disturbance_response: the disturbance brings its own spin change, so the "
            f"scene must be autonomous, but it has '{model.time_dependence}'")
    e = balanced_state(model)
    if e is not None and e.stability == "stable":
        return np.asarray(e.q, dtype=float)
    if float(np.sum(capacities(model))) <= 1.0 + 1e-12:
        found = equilibria(model)
        stable = [q for q in found if q.stability == "stable"]
        if stable:
            return np.asarray(min(stable, key=lambda q: q.residual_imbalance).q, dtype=float)
        if e is not None and e.stability == "marginal":
            return np.asarray(e.q, dtype=float)
        raise ParameterError(
            "model", f"the balls are under capacity (sum eta = {np.sum(capacities(model))}"
            f" <= 1) and no equilibrium is stable at the starting speed Omega = "
            f"{model.Omega}, so the disturbance cannot start from rest")
    raise ParameterError(
        "model", f"the balanced state must be stable at the starting speed "
        f"Omega = {model.Omega} (above the resonance), so that the "
        "disturbance starts from rest (with sum eta <= 1 it starts where the balls "
        "settle against the imbalance)")


def disturbance_response(
    model: Balancer | Scene,
    to: float,
    *,
    start: float = 10.0,
    duration: float = 5.0,
    t_end: float = 3000.0,
    band: float = 0.01,
    dt: float = 0.1,
    rtol: float = 1e-8,
) -> DisturbanceResponse:
    """Start at the stable perfect balance at ``model.Omega`` (balls under capacity,
    ``sum eta_i <= 1``: at the stable equilibrium where they settle against the
    imbalance, [TwoBallStrength]'s light-ball cases), change the spin to
    ``to`` linearly over ``duration`` from ``start`` ([TwoBallStrength]: 100 rad/s in 0.11 s), and
    measure the radial vibration. ``band`` is in units of the eccentricity ``e``.

    ``model`` may be an autonomous scene (ball springs, a tilting disk): it starts at
    its stable balanced state (:func:`balanced_state`), and ``final_r`` is then that of
    the balanced state at ``to``, not 0, where springs leave a residual whirl.

    ``dt`` (the output step) must be at most ``t_end - start``, so that some samples
    follow the change; ``rtol`` (the integrator's) must be in (0, 1)."""
    model_argument("model", model)
    to = _check.real("to", to, 0.0, lo_open=True)
    start = _check.real("start", start, 0.0)
    duration = _check.real("duration", duration, 0.0, lo_open=True)
    t_end = _check.real("t_end", t_end, start + duration, lo_open=True)
    band = _check.real("band", band, 0.0, lo_open=True)
    # At least one sample after the change starts: the peak is read from those.
    dt = _check.real("dt", dt, 0.0, t_end - start, lo_open=True)
    rtol = _check.real("rtol", rtol, 0.0, 1.0, lo_open=True, hi_open=True)
    _check.samples_count(t_end, dt, duration_name="t_end")
    q = _balanced_start(model)
    y0 = np.concatenate([q, np.zeros(q.size)])
    ramp = Ramp(to=to, start=start, duration=duration)
    scene = (replace(model, ramp=ramp) if isinstance(model, Scene)
             else Scene(balancer=model, ramp=ramp))
    t = np.arange(0.0, t_end + dt / 2, dt)
    df = simulate(scene, y0, t, rtol=rtol, atol=rtol * 1e-2)
    r = np.hypot(df["x"].to_numpy(), df["y"].to_numpy())
    after = t >= start
    final = float(r[-1])
    outside = np.nonzero(after & (np.abs(r - final) > band))[0]
    settle = None
    if outside.size == 0:
        settle = 0.0
    elif outside[-1] < t.size - 1:
        settle = float(t[outside[-1] + 1] - start)
    if settle is not None and t_end - start - settle < 0.1 * (t_end - start):
        settle = None  # settled only at the very end: not enough evidence it stays
    return DisturbanceResponse(peak=float(r[after].max()), settle_time=settle, final_r=final,
                               trajectory=df)


def track_damping_study(
    model: Balancer | Scene,
    zeta_b: Sequence[float],
    to: float,
    *,
    progress: ProgressArg = False,
    **kw: Any,
) -> pl.DataFrame:
    """Peak amplitude and settling time after the disturbance for each track damping,
    and [TwoBallStrength]'s combined index ``peak * s + settle_time`` with the scale ``s`` = mean
    settling time / mean peak (so both terms count alike); ``optimal`` marks its
    minimum. At most :data:`~ballbal._check.MAX_STUDY_VALUES` dampings (each a
    simulation of ``t_end``). ``progress``: True for a progress bar over the dampings
    (tqdm, notebook-aware), or a callable ``f(done, total)``."""
    rows = []
    model_argument("model", model)
    values = [zeta_b] if _check.is_real(zeta_b) else zeta_b
    dampings = _check.vector("zeta_b", values, _check.MAX_STUDY_VALUES)
    with Progress(progress, dampings.size, "ballbal damping study") as bar:
        for zb in dampings:
            res = disturbance_response(model.replace(zeta_b=zb), to, **kw)
            rows.append({"zeta_b": float(zb), "peak": res.peak, "settle_time": res.settle_time,
                         "final_r": res.final_r})
            bar.update()
    df = pl.DataFrame(rows, schema={"zeta_b": pl.Float64, "peak": pl.Float64,
                                    "settle_time": pl.Float64, "final_r": pl.Float64})
    ok = df.filter(pl.col("settle_time").is_not_null())
    if ok.height == 0:
        return df.with_columns(index=pl.lit(None, dtype=pl.Float64), optimal=pl.lit(False))
    # polars types a mean as any literal; of a non-empty Float64 column it is a float
    scale = cast(float, ok["settle_time"].mean()) / cast(float, ok["peak"].mean())
    df = df.with_columns(index=pl.col("peak") * scale + pl.col("settle_time"))
    best = df["index"].arg_min()
    return df.with_columns(optimal=pl.Series([i == best for i in range(df.height)]))


@dataclass(frozen=True, repr=False)
class RunUp(Summarised):
    """A run-up transient: peak and final whirl ``hypot(x, y)`` (units of ``e``) and, for
    a tilting disk, peak and final tilt ``hypot(A, B)`` (units of ``e / r_t``; radians
    are these over ``delta``); ``peak_Omega`` is the spin at the peak whirl."""

    peak_whirl: float
    peak_Omega: float
    final_whirl: float
    peak_tilt: float
    final_tilt: float
    trajectory: pl.DataFrame

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        head = (f"RunUp peak whirl={self.peak_whirl:.4g} at Ω={self.peak_Omega:.4g}, final "
                f"{self.final_whirl:.3g}; tilt peak {self.peak_tilt:.4g} final "
                f"{self.final_tilt:.3g}")
        return head, [("peak whirl (e)", self.peak_whirl), ("at Ω", self.peak_Omega),
                      ("final whirl (e)", self.final_whirl), ("peak tilt", self.peak_tilt),
                      ("final tilt", self.final_tilt), ("samples", self.trajectory.height)]

    def plot(self, ax: Any = None) -> Any:
        """The whirl ``|Z|`` against time; returns the axes."""
        from ._figures import trajectory_radius

        return trajectory_radius(self.trajectory, ax)


def run_up(
    model: Scene | Balancer,
    to: float,
    duration: float,
    *,
    balls: Sequence[float] | None = None,
    settle: float = 600.0,
    dt: float = 0.5,
    rtol: float = 1e-8,
) -> RunUp:
    """Spin the scene's rotor up from ``model.Omega`` to ``to`` over ``duration`` (seed
    004's run-up) and measure the whirl and tilt. The rotor starts centred and flat, the
    balls at rest relative to the disk at angles ``balls``, in track order (default:
    spread over +-1 rad about the unbalance, where a classic balancer's balls make the
    resonance worst). A plain :class:`Balancer` runs up as a scene without effects."""
    model_argument("model", model)
    scene = Scene(balancer=model) if isinstance(model, Balancer) else model
    to = _check.real("to", to, 0.0, lo_open=True)
    duration = _check.real("duration", duration, 0.0, lo_open=True)
    settle = _check.real("settle", settle, 0.0)
    dt = _check.real("dt", dt, 0.0, lo_open=True)
    rtol = _check.real("rtol", rtol)
    _check.samples_count(duration + settle, dt,
                         duration_name="duration" if duration >= settle else "settle")
    n = scene.n_balls
    if balls is None:
        balls = list(np.linspace(-1.0, 1.0, n)) if n > 1 else [1.0]
    balls = [_check.real("balls", x, finite=True) for x in _check.reals("balls", balls)]
    if len(balls) != n:
        raise ParameterError("balls", f"needs {n} angles, got {len(balls)}")
    sc = replace(scene, ramp=Ramp(to=to, start=0.0, duration=duration))
    d = len(sc.coordinates)
    y0 = np.zeros(2 * d)
    y0[d - n : d] = balls
    t = np.arange(0.0, duration + settle + dt / 2, dt)
    df = simulate(sc, y0, t, rtol=rtol, atol=rtol * 1e-2)
    r = np.hypot(df["x"].to_numpy(), df["y"].to_numpy())
    if "A" in df.columns:
        tilt = np.hypot(df["A"].to_numpy(), df["B"].to_numpy())
    else:
        tilt = np.zeros_like(r)
    k = int(r.argmax())
    om = scene.Omega + (to - scene.Omega) * min(t[k] / duration, 1.0)
    return RunUp(peak_whirl=float(r[k]), peak_Omega=float(om), final_whirl=float(r[-1]),
                 peak_tilt=float(tilt.max()), final_tilt=float(tilt[-1]), trajectory=df)
