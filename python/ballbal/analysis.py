"""Analyses of a balancer: time simulation, equilibria, periodic solutions."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import polars as pl

from . import _native
from .model import Balancer
from .scene import Scene

Stability = Literal["stable", "unstable", "undetermined"]


def _atol(atol: float | Sequence[float]) -> list[float]:
    return [float(atol)] if np.isscalar(atol) else [float(a) for a in atol]  # type: ignore[arg-type]


def _state_names(model: Balancer | Scene) -> list[str]:
    q = model.coordinates
    return q + [f"d{c}" for c in q]


def simulate(
    balancer: Balancer | Scene,
    y0: Sequence[float] | np.ndarray | None = None,
    t_eval: Sequence[float] | np.ndarray | None = None,
    *,
    t_span: tuple[float, float] | None = None,
    t0: float | None = None,
    rtol: float = 1e-8,
    atol: float | Sequence[float] = 1e-10,
) -> pl.DataFrame:
    """Integrate the equations of motion with the core's Dormand–Prince 5(4).

    ``y0 = (q, q')`` in the rotating frame, ``q = (x, y, b_1..b_n)`` (with a tilting disk
    ``(x, y, A, B, b_1..b_n)``: ``balancer.coordinates``); default: the thesis' start, at
    rest in the ground frame, balls spread over half the track. The
    state is given at ``t0`` (default ``t_span[0]``, else 0). Give output times ``t_eval``
    (strictly monotone, not before ``t0``) or ``t_span`` for 1001 evenly spaced outputs.
    Returns columns ``t``, the state, ``theta`` (the disk's angle, 0 at t = 0) and ``X,
    Y``: the disk centre in the fixed frame.
    """
    n = balancer.n_balls
    d = len(balancer.coordinates)
    if y0 is None:
        y0 = np.zeros(2 * d)
        y0[d - n : d] = np.linspace(0.0, np.pi, n, endpoint=False) + 0.3
        y0[2 * d - n :] = -balancer.Omega
    y0 = np.ascontiguousarray(y0, dtype=np.float64).ravel()
    if y0.size != 2 * d:
        raise ValueError(f"y0: needs 2 x {d} values ({', '.join(balancer.coordinates)} and "
                         f"their rates), got {y0.size}")
    if t_eval is None:
        if t_span is None:
            raise ValueError("t_eval: give output times, or t_span=(t0, t1)")
        t_eval = np.linspace(float(t_span[0]), float(t_span[1]), 1001)
    t = np.ascontiguousarray(t_eval, dtype=np.float64).ravel()
    if t.size == 0:
        raise ValueError("t_eval: must hold at least one time")
    if t0 is None:
        t0 = float(t_span[0]) if t_span is not None else 0.0
    y, theta, *_ = _native.simulate(*balancer.native_args(), y0, float(t0), t, float(rtol),
                                    _atol(atol), balancer.native_effects())
    cols: dict[str, Any] = {"t": t}
    for name, col in zip(_state_names(balancer), np.asarray(y).T, strict=True):
        cols[name] = col
    cols["theta"] = theta
    cols["X"] = cols["x"] * np.cos(theta) - cols["y"] * np.sin(theta)
    cols["Y"] = cols["x"] * np.sin(theta) + cols["y"] * np.cos(theta)
    return pl.DataFrame(cols)


@dataclass(frozen=True)
class Equilibrium:
    """One equilibrium: balls at rest relative to the disk."""

    kind: str
    q: np.ndarray
    residual: float
    eigenvalues: np.ndarray
    stability_index: float
    stability: str
    neutral: int
    routh_hurwitz: bool | None
    char_poly: np.ndarray
    #: False when the search's start budget (``max(600, 25 n)`` starts from 5 balls on)
    #: cut it short: other equilibria may exist.
    exhaustive: bool = True


def equilibria(balancer: Balancer | Scene) -> list[Equilibrium]:
    """All equilibria (perfect balance first), with eigenvalues, the relative-stability
    index (largest real part) and, where defined, the Routh–Hurwitz verdict.

    With ball springs, ball angles count turns: the equilibria reported have the balls in
    track order (``b_1 <= ... <= b_n <= b_1 + 2 pi``: balls cannot pass each other),
    ``b_1`` in ``(-pi, pi]``, and identical balls relabelled round the ring count once;
    the one that continues the perfect balance (:func:`balanced_state`) is ``"balanced"``.
    Scenes with a ramp, gravity or an impulse have none (an error naming the effect).

    From three balls on the perfect balances form a family (``neutral > 0``), reported
    once by one of its points. Up to four balls every start of a lattice is tried; from
    five on the search tries ``max(600, 25 n)`` starts (balls together, then a
    low-discrepancy sequence) and says so with ``exhaustive=False``."""
    return [_equilibrium(d)
            for d in _native.equilibria(*balancer.native_args(), balancer.native_effects())]


def _equilibrium(d: dict[str, Any]) -> Equilibrium:
    return Equilibrium(
        kind=d["kind"], q=d["q"], residual=d["residual"],
        eigenvalues=d["eig_re"] + 1j * d["eig_im"], stability_index=d["index"],
        stability=d["stability"], neutral=d["neutral"], routh_hurwitz=d["routh_hurwitz"],
        char_poly=d["char_poly"], exhaustive=d.get("exhaustive", True),
    )


@dataclass(frozen=True)
class PeriodicSolution:
    """A periodic solution from harmonic balance (or a failed attempt: see ``status``).

    ``coeffs[j] = [a_0, a_1, b_1, ..., a_N, b_N]`` for coordinate ``j`` of
    ``(x, y, b_1..b_n)``; ``q_j(tau) = a_0 + sum a_m cos(m tau) + b_m sin(m tau) + w_j tau``,
    ``tau = omega t``, with ``winding[j] = -1`` for a rotating ball.
    """

    balancer: Balancer | Scene
    status: str
    type: str
    omega: float | None
    coeffs: np.ndarray
    winding: np.ndarray
    N: int
    samples: int
    residual: float
    iterations: int
    multipliers: np.ndarray | None
    stability: Stability
    max_modulus: float | None
    trivial_error: float | None
    floquet_steps: int | None
    condition: float
    tail: float = float("nan")
    target_met: bool | None = None
    hill_multipliers: np.ndarray | None = None
    hill_stability: Stability | None = None
    verdicts_disagree: bool | None = None
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def period(self) -> float:
        if self.omega is None:
            raise ValueError(f"no period: the solve did not converge (status {self.status})")
        return 2 * np.pi / self.omega

    def harmonics(self) -> np.ndarray:
        """Amplitude of each harmonic, shape ``(n + 2, N + 1)``."""
        c = self.coeffs
        amp = np.empty((c.shape[0], self.N + 1))
        amp[:, 0] = np.abs(c[:, 0])
        amp[:, 1:] = np.hypot(c[:, 1::2], c[:, 2::2])
        return amp

    def time_history(self, t: Sequence[float] | np.ndarray | None = None) -> pl.DataFrame:
        """The orbit sampled at times ``t`` (default: 201 points over one period)."""
        if self.omega is None:
            raise ValueError(f"no orbit: the solve did not converge (status {self.status})")
        tt = np.linspace(0, self.period, 201) if t is None else np.asarray(t, dtype=float)
        tau = self.omega * tt
        m = np.arange(1, self.N + 1)
        cos, sin = np.cos(np.outer(tau, m)), np.sin(np.outer(tau, m))
        cols: dict[str, Any] = {"t": tt}
        names = _state_names(self.balancer)
        d = len(self.winding)
        a, b = self.coeffs[:, 1::2], self.coeffs[:, 2::2]
        q = self.coeffs[:, 0] + cos @ a.T + sin @ b.T + np.outer(tau, self.winding)
        dq = self.omega * (-(sin * m) @ a.T + (cos * m) @ b.T + self.winding)
        for j in range(d):
            cols[names[j]] = q[:, j]
        for j in range(d):
            cols[names[d + j]] = dq[:, j]
        return pl.DataFrame(cols)

    def state(self, t: float = 0.0) -> np.ndarray:
        """First-order state ``(q, q')`` on the orbit at time ``t``."""
        row = self.time_history([t]).drop("t").row(0)
        return np.asarray(row)

    def verify(self, rtol: float = 1e-10, atol: float = 1e-12) -> float:
        """Simulate one period from the orbit's state (the thesis' "NI" check) and return
        the largest distance from where the orbit says the motion should be."""
        if self.omega is None:
            raise ValueError(f"nothing to verify: status {self.status}")
        return _native.orbit_closure(
            *self.balancer.native_args(), self.omega, np.ascontiguousarray(self.coeffs.ravel()),
            [float(w) for w in self.winding], float(rtol), float(atol),
            self.balancer.native_effects(),
        )


def harmonics(N: int | str, target: float) -> tuple[int, float | None]:
    """``(starting N, target or None)`` from ``N`` = an integer or ``"auto"``."""
    if isinstance(N, str):
        if N != "auto":
            raise ValueError(f"N: must be an integer in [1, 256] or 'auto', got {N!r}")
        return 3, float(target)
    if isinstance(N, bool) or not isinstance(N, (int, np.integer)):
        raise ValueError(f"N: must be an integer in [1, 256] or 'auto', got {N!r}")
    return int(N), None


def periodic(
    balancer: Balancer | Scene,
    pattern: str = "R-R",
    *,
    N: int | str = 3,
    target: float = 1e-6,
    N_max: int = 32,
    hill: bool = True,
    samples: int | None = None,
    tol: float = 1e-10,
    step_tol: float = 1e-8,
    max_iter: int = 50,
    guess: PeriodicSolution | tuple[float, np.ndarray] | None = None,
    floquet: bool = True,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    margin: float = 1e-6,
    max_steps: int = 200_000,
    settle: float = 1500.0,
    window: float = 2500.0,
) -> PeriodicSolution:
    """Periodic solution of a ball pattern (``"R-R"``, ``"O-O"``, ``"R-O"``, ... one letter
    per ball) by Newton–IHB with ``N`` harmonics, and its Floquet multipliers.

    Without ``guess`` the start comes from a time simulation (``settle`` time units for
    transients, then up to ``window`` to measure the period). ``guess`` may be a previous
    solution (any N; it is truncated or padded) or ``(omega, coeffs)``. ``rtol, atol`` are
    the RK45 tolerances of the monodromy integration, ``max_steps`` its step budget (a
    longer integration ends in ``floquet_error`` and an undetermined verdict); a verdict
    needs the largest non-trivial modulus further than ``max(margin, trivial_error)``
    from 1.

    ``N="auto"`` starts at 3 and raises the harmonics (solving from the last) until the
    highest harmonic relative to the motion (``tail``) and the trivial multiplier's
    distance from 1 are below ``target`` (or ``N_max`` is reached: ``target_met`` says
    which). ``hill`` adds a second stability estimate by Hill's method (eigenvalues of
    the Hill matrix, no time integration): ``hill_multipliers``, ``hill_stability``, and
    ``verdicts_disagree`` when one says stable and the other unstable.

    A solve that fails is returned with its ``status`` (``diverged``, ``singular``,
    ``max_iterations``, ``no_guess``) and ``omega = None``; it never raises for that.
    """
    go: float | None = None
    gc: np.ndarray | None = None
    if guess is not None:
        if isinstance(guess, PeriodicSolution):
            if guess.omega is None:
                raise ValueError("guess: a solution that did not converge cannot seed a solve")
            go, gc = guess.omega, guess.coeffs
        else:
            go, gc = float(guess[0]), np.asarray(guess[1], dtype=float)
        gc = np.ascontiguousarray(gc, dtype=np.float64).ravel()
    n0, auto = harmonics(N, target)
    d = _native.periodic(
        *balancer.native_args(), pattern, n0, samples, float(tol), float(step_tol),
        int(max_iter), go, gc, bool(floquet), float(rtol), float(atol), float(margin),
        int(max_steps), float(settle), float(window), 1e-9, auto, int(N_max), bool(hill),
        balancer.native_effects(),
    )
    mult = d["mult_re"] + 1j * d["mult_im"] if "mult_re" in d else None
    hill_m = d["hill_re"] + 1j * d["hill_im"] if "hill_re" in d else None
    return PeriodicSolution(
        tail=d["tail"], target_met=d["target_met"], hill_multipliers=hill_m,
        hill_stability=d.get("hill_stability"), verdicts_disagree=d["verdicts_disagree"],
        balancer=balancer, status=d["status"], type=d["type"], omega=d["omega"],
        coeffs=d["coeffs"], winding=d["winding"], N=d["N"], samples=d["samples"],
        residual=d["residual"], iterations=d["iterations"], multipliers=mult,
        stability=d["stability"], max_modulus=d.get("max_modulus"),
        trivial_error=d.get("trivial_error"), floquet_steps=d.get("floquet_steps"),
        condition=d["pivot_ratio"],
        info={"floquet_error": d["floquet_error"], "last_omega": d["last_omega"]},
    )
