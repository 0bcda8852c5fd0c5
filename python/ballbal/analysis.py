"""Analyses of a balancer: time simulation, equilibria, periodic solutions."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, overload

import numpy as np
import polars as pl

from . import _check, _native
from ._style import Summarised
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer
from .options import (
    COLLOCATION_DEFAULTS,
    PERIODIC_DEFAULTS,
    Collocation,
    PeriodicOptions,
    refuses_keywords,
    with_harmonics,
)
from .scene import Scene, model_argument
from .spectrum import LineSource, Vibration, line_spectrum, vibration

Stability = Literal["stable", "unstable", "undetermined"]

#: Times per block of :meth:`PeriodicSolution.time_history` (its cos and sin tables are
#: this by N: 2 x 130 MB at N = 256).
_HISTORY_BLOCK = 1 << 16


def _atol(atol: float | Sequence[float]) -> list[float]:
    return _check.reals("atol", atol)


def _state_names(model: Balancer | Scene) -> list[str]:
    q = model.coordinates
    return q + [f"d{c}" for c in q]


@overload
def simulate(
    model: Balancer | Scene,
    y0: Sequence[float] | np.ndarray | None = None,
    t_eval: Sequence[float] | np.ndarray | None = None,
    *,
    t_span: tuple[float, float] | None = None,
    t0: float | None = None,
    rtol: float = 1e-8,
    atol: float | Sequence[float] = 1e-10,
    max_steps: int = 10_000_000,
    stats: Literal[False] = False,
) -> pl.DataFrame: ...
@overload
def simulate(
    model: Balancer | Scene,
    y0: Sequence[float] | np.ndarray | None = None,
    t_eval: Sequence[float] | np.ndarray | None = None,
    *,
    t_span: tuple[float, float] | None = None,
    t0: float | None = None,
    rtol: float = 1e-8,
    atol: float | Sequence[float] = 1e-10,
    max_steps: int = 10_000_000,
    stats: Literal[True],
) -> tuple[pl.DataFrame, dict[str, int]]: ...
def simulate(
    model: Balancer | Scene,
    y0: Sequence[float] | np.ndarray | None = None,
    t_eval: Sequence[float] | np.ndarray | None = None,
    *,
    t_span: tuple[float, float] | None = None,
    t0: float | None = None,
    rtol: float = 1e-8,
    atol: float | Sequence[float] = 1e-10,
    max_steps: int = 10_000_000,
    stats: bool = False,
) -> pl.DataFrame | tuple[pl.DataFrame, dict[str, int]]:
    """Integrate the equations of motion with the core's Dormand–Prince 5(4).

    ``y0 = (q, q')`` in the rotating frame, ``q = (x, y, b_1..b_n)`` (with a tilting disk
    ``(x, y, A, B, b_1..b_n)``: ``model.coordinates``); default: Tien's (2011) start, at
    rest in the ground frame, balls spread over half the track. The
    state is given at ``t0`` (default ``t_span[0]``, else 0). Give output times ``t_eval``
    (strictly monotone, not before ``t0``) or ``t_span`` for 1001 evenly spaced outputs.
    Returns columns ``t``, the state, ``theta`` (the disk's angle, 0 at t = 0) and ``X,
    Y``: the disk centre in the fixed frame.

    ``max_steps`` bounds the integrator's steps (accepted and rejected); a simulation
    that needs more stops with an :class:`~ballbal.exceptions.IntegrationError` saying
    how far it got. At most ``1e7`` output times.

    With ``stats=True`` returns ``(df, stats)``, ``stats`` the integrator's counts under
    scipy's names: ``nfev`` (right-hand-side evaluations), ``naccept`` and ``nreject``
    (accepted and rejected steps). The method has seven stages, the last of a step being
    the first of the next (FSAL), so ``nfev = 6 (naccept + nreject) + 2``: one evaluation
    at the start and one to choose the first step, as scipy's ``RK45`` counts.
    """
    if not isinstance(stats, (bool, np.bool_)):
        raise ParameterTypeError("stats", f"must be True or False, got {stats!r:.60}",
                                 value=stats)
    model_argument("model", model)
    n = model.n_balls
    d = len(model.coordinates)
    if y0 is None:
        y0 = np.zeros(2 * d)
        y0[d - n : d] = np.linspace(0.0, np.pi, n, endpoint=False) + 0.3
        y0[2 * d - n :] = -model.Omega
    y0 = _check.array("y0", y0)
    if y0.size != 2 * d:
        raise ParameterError("y0", f"needs 2 x {d} values ({', '.join(model.coordinates)} "
                             f"and their rates), got {y0.size}")
    span = None if t_span is None else _span(t_span)
    if t_eval is None:
        if span is None:
            raise ParameterError("t_eval", "give output times, or t_span=(t0, t1)")
        t_eval = np.linspace(span[0], span[1], 1001)
    t = _check.array("t_eval", t_eval)
    if t.size == 0:
        raise ParameterError("t_eval", "must hold at least one time")
    if t.size > _check.MAX_SAMPLES:
        raise ParameterError("t_eval", f"at most {_check.MAX_SAMPLES:.0e} output times, got "
                             f"{t.size}", allowed=f"at most {_check.MAX_SAMPLES:.0e} times")
    if t0 is None:
        t0 = span[0] if span is not None else 0.0
    t0 = _check.real("t0", t0, finite=True)
    steps = _check.integer("max_steps", max_steps, 1)
    y, theta, naccept, nreject, nfev = _native.simulate(
        model, y0, t0, t, _check.real("rtol", rtol), _atol(atol), steps)
    cols: dict[str, Any] = {"t": t}
    for name, col in zip(_state_names(model), np.asarray(y).T, strict=True):
        cols[name] = col
    cols["theta"] = theta
    cols["X"] = cols["x"] * np.cos(theta) - cols["y"] * np.sin(theta)
    cols["Y"] = cols["x"] * np.sin(theta) + cols["y"] * np.cos(theta)
    df = pl.DataFrame(cols)
    if stats:
        return df, {"nfev": nfev, "naccept": naccept, "nreject": nreject}
    return df


def _span(t_span: Any) -> tuple[float, float]:
    """``(t0, t1)``: two finite, different times."""
    if isinstance(t_span, (str, bytes)) or not isinstance(t_span, (Sequence, np.ndarray)):
        raise ParameterTypeError("t_span", f"must be a pair (t0, t1), got {t_span!r:.60}",
                                 value=t_span)
    if len(t_span) != 2:
        raise ParameterError("t_span", f"must be a pair (t0, t1), got {len(t_span)} values",
                             value=t_span)
    a = _check.real("t_span", t_span[0], finite=True)
    b = _check.real("t_span", t_span[1], finite=True)
    if a == b:
        raise ParameterError("t_span", f"t1 must differ from t0, got ({a}, {b})", value=t_span)
    return a, b


@dataclass(frozen=True, repr=False)
class Equilibrium(Summarised, LineSource):
    """One equilibrium: balls at rest relative to the disk. In a notebook: a one-line
    summary, an HTML table, and :meth:`plot` (its eigenvalues)."""

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
    #: ``|1 + sum eta_i exp(i b_i)|``: the imbalance the disk and its balls leave
    #: together, in units of the disk's ``m_d e`` (0 at a perfect balance; ``|1 - eta|``
    #: for one ball straight opposite the imbalance). ``ballbal.data.residual_imbalance``
    #: gives it in mass x length. NaN only where the balls' capacities were not known.
    residual_imbalance: float = float("nan")

    def _displacement_lines(self, Omega: float | None,  # noqa: N803
                            name: str) -> tuple[np.ndarray, np.ndarray, float, float]:
        # One line at the spin: the disk centre's offset, constant in the rotating frame.
        if Omega is None:
            raise ParameterError("Omega", "an Equilibrium does not carry its model: give "
                                 "Omega (the spin speed ratio it was computed at)")
        spin = _check.real("Omega", Omega, finite=True)
        return (np.zeros(1, dtype=int), np.array([self.q[0] + 1j * self.q[1]]),
                spin, float("nan"))

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        r = float(np.hypot(self.q[0], self.q[1]))
        head = (f"Equilibrium {self.kind} {self.stability} max Re λ={self.stability_index:.4g} "
                f"|Z|={r:.4g} residual imbalance={self.residual_imbalance:.4g}")
        return head, [("kind", self.kind), ("stability", self.stability),
                      ("max Re λ", self.stability_index), ("|Z| (e)", r),
                      ("residual imbalance", self.residual_imbalance),
                      ("neutral eigenvalues", self.neutral),
                      ("Routh-Hurwitz stable", self.routh_hurwitz),
                      ("residual", self.residual), ("exhaustive search", self.exhaustive)]

    def plot(self, ax: Any = None) -> Any:
        """The eigenvalues in the complex plane (returns the axes)."""
        from ._figures import equilibrium

        return equilibrium(self, ax)


def equilibria(model: Balancer | Scene) -> list[Equilibrium]:
    """All equilibria (perfect balance first), with eigenvalues, the relative-stability
    index (largest real part) and, where defined, the Routh–Hurwitz verdict.

    With ball springs, ball angles count turns: the equilibria reported have the balls in
    track order (``b_1 <= ... <= b_n <= b_1 + 2 pi``: balls cannot pass each other),
    ``b_1`` in ``(-pi, pi]``, and identical balls relabelled round the ring count once;
    the one that continues the perfect balance (:func:`balanced_state`) is ``"balanced"``.

    Kinds: ``perfect_balance`` (the disk at rest on the axis), ``together``, ``opposite``
    (two balls), ``unbalanced``; for one ball (closed forms, as for two equal balls):
    ``partial_balance`` (the ball on the far side of the track from the imbalance,
    ``cos b < 0``: it cancels part of it; near ``Omega = 1`` both states can be on that
    side), ``imbalance_side`` (``cos b >= 0``: it adds to it) and, with ``eta = 1``
    exactly, ``perfect_balance`` at ``b = pi``. A ball heavier than the imbalance has no
    equilibrium near the resonance (``eta Omega > sqrt(A^2 + Omega^2)``, ``A = (1 -
    Omega^2) / (2 zeta)``): the list is empty and the ball keeps moving. Every
    equilibrium carries its ``residual_imbalance``.
    Scenes with a ramp, gravity or an impulse have none (an error naming the effect).

    Of the planar balancer, every state off the axis is listed in closed form, for any
    damping (``zeta = 0`` included) and up to ten balls: at rest each ball needs the disk
    centre on its line, so every ball sits at ``b`` or ``b + pi`` and the balls act as
    one mass ``sum s_i eta_i`` (``s_i = +-1``), which leaves at most two ``b`` per sign
    pattern. From three balls on the perfect balances form a family (``neutral > 0``),
    reported once by one of its points. Up to four balls every start of a lattice is
    tried; from five on the search tries ``max(600, 25 n)`` starts (balls together, then
    a low-discrepancy sequence) and says so with ``exhaustive=False``."""
    model_argument("model", model)
    eta = capacities(model)
    return [_equilibrium(d, eta) for d in _native.equilibria(model)]


def capacities(model: Balancer | Scene) -> np.ndarray:
    """The balls' balancing capacities ``eta_i`` of a balancer or a scene."""
    bal = model.balancer if isinstance(model, Scene) else model
    return np.asarray(bal.eta, dtype=float)


def residual_imbalance(eta: Sequence[float] | np.ndarray,
                       angles: Sequence[float] | np.ndarray) -> float:
    """``|1 + sum eta_i exp(i b_i)|``: the disk's and balls' imbalance together, in units
    of the disk's ``m_d e``, for balls at angles ``b_i`` from the disk's mass centre
    (one finite value each, at most :data:`~ballbal._check.MAX_BALLS`)."""
    e = _check.vector("eta", eta, _check.MAX_BALLS)
    b = _check.vector("angles", angles, _check.MAX_BALLS)
    if b.size != e.size:
        raise ParameterError("angles", f"needs one angle per ball ({e.size}), got {b.size}",
                             allowed=f"{e.size} values", value=b.size)
    return float(abs(1.0 + np.sum(e * np.exp(1j * b))))


def _equilibrium(d: dict[str, Any], eta: np.ndarray | None = None) -> Equilibrium:
    q = d["q"]
    ri = float("nan") if eta is None else residual_imbalance(eta, q[len(q) - len(eta):])
    return Equilibrium(
        kind=d["kind"], q=q, residual=d["residual"],
        eigenvalues=d["eig_re"] + 1j * d["eig_im"], stability_index=d["index"],
        stability=d["stability"], neutral=d["neutral"], routh_hurwitz=d["routh_hurwitz"],
        char_poly=d["char_poly"], exhaustive=d.get("exhaustive", True),
        residual_imbalance=ri,
    )


@dataclass(frozen=True, repr=False)
class PeriodicSolution(Summarised, LineSource):
    """A periodic solution from harmonic balance or collocation (or a failed attempt: see
    ``status``); ``method`` says which (``"hb"``, ``"collocation"``).

    ``coeffs[j] = [a_0, a_1, b_1, ..., a_N, b_N]`` for coordinate ``j`` of
    ``(x, y, b_1..b_n)``; ``q_j(tau) = a_0 + sum a_m cos(m tau) + b_m sin(m tau) + w_j tau``,
    ``tau = omega t``, with ``winding[j] = -1`` for a rotating ball. For a collocation
    orbit the series is fitted to the orbit (``N = 32`` harmonics, from 148 samples per
    period; its ``tail`` says how well it holds the orbit) and serves the spectrum, the
    vibration measures and as a start for other solves; ``time_history`` and ``state``
    evaluate the collocation polynomials themselves (``mesh``, ``mesh_states``).

    Certificates (see :func:`periodic`): ``closure`` (the series' ODE defect integrated
    over one period), ``tail`` (highest harmonic relative to the motion),
    ``trivial_error`` and, for merged balls, ``separation_error``.
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
    #: The last Newton matrix's largest over smallest LU pivot, a lower bound of its
    #: condition number (the scan tables' column of the same name).
    pivot_ratio: float
    tail: float = float("nan")
    target_met: bool | None = None
    hill_multipliers: np.ndarray | None = None
    hill_stability: Stability | None = None
    verdicts_disagree: bool | None = None
    closure: float | None = None
    separation_error: float | None = None
    #: Bound on the error of ``max_modulus`` that ``stability`` was judged against: twice
    #: its difference to the same multiplier of a series with more harmonics, plus that
    #: series' own error measures (see :func:`periodic`). ``None`` without a monodromy,
    #: and on a branch, curve or switched orbit (which keep their ``N``) where the trivial
    #: multiplier's error already leaves the verdict undetermined.
    modulus_error: float | None = None
    #: Which series the bound compares: ``"N 3 vs 5"``.
    modulus_error_source: str | None = None
    #: Bound on the error of ``omega`` from the same comparison (twice the two series'
    #: frequencies' difference); ``None`` without it (as ``modulus_error``). Near the
    #: infinite-period end of a rotating branch the trivial multiplier's error says little
    #: about the frequency's.
    omega_error: float | None = None
    info: dict[str, Any] = field(default_factory=dict)
    #: ``"hb"`` (harmonic balance) or ``"collocation"``.
    method: str = "hb"
    #: Collocation only: the mesh points in scaled time ``t / T`` (``NTST + 1``, 0 to 1).
    mesh: np.ndarray | None = None
    #: Collocation only: the first-order states ``(q, q')`` at the ``NCOL`` equally spaced
    #: points of every mesh interval and the last mesh point, shape
    #: ``(NTST NCOL + 1, 2 d)`` (rotating angles unwrapped).
    mesh_states: np.ndarray | None = None

    def _displacement_lines(self, Omega: float | None,  # noqa: N803
                            name: str) -> tuple[np.ndarray, np.ndarray, float, float]:
        if self.omega is None:
            raise ParameterError(name, f"has no spectrum: the solve did not converge (status "
                                 f"{self.status})", allowed="a converged PeriodicSolution")
        spin = self.balancer.Omega
        if Omega is not None and _check.real("Omega", Omega) != spin:
            raise ParameterError("Omega", f"a periodic solution spins at its model's Omega "
                                 f"({spin}), got {Omega}", value=Omega)
        n = self.N
        ax, ay = self.coeffs[0], self.coeffs[1]
        a_x, b_x = ax[1::2], ax[2::2]
        a_y, b_y = ay[1::2], ay[2::2]
        k = np.arange(-n, n + 1)
        c = np.empty(2 * n + 1, dtype=complex)
        c[n] = ax[0] + 1j * ay[0]
        c[n + 1:] = 0.5 * ((a_x + b_y) + 1j * (a_y - b_x))
        c[:n] = (0.5 * ((a_x - b_y) + 1j * (a_y + b_x)))[::-1]
        return k, c, float(spin), float(self.omega)

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        spin = f"Ω={self.balancer.Omega:.4g}"
        if self.method == "collocation" and self.mesh is not None:
            how = f"collocation, {len(self.mesh) - 1} intervals"
        else:
            how = f"N={self.N}"
        if self.omega is None:
            head = f"PeriodicSolution {self.type} {spin} {self.status} ({how})"
        else:
            mod = "-" if self.max_modulus is None else f"{self.max_modulus:.3g}"
            head = (f"PeriodicSolution {self.type} {spin} ω={self.omega:.5g} {self.stability} "
                    f"|μ|max={mod} ({how})")
            if self.status != "converged":
                head += f" {self.status}"
        return head, [("type", self.type), ("status", self.status),
                      ("Ω (spin)", self.balancer.Omega), ("ω (balls)", self.omega),
                      ("stability", self.stability), ("|μ|max", self.max_modulus),
                      ("|μ|max error", self.modulus_error), ("method", self.method),
                      ("harmonics N", self.N),
                      ("closure", self.closure), ("tail", self.tail),
                      ("residual", self.residual), ("iterations", self.iterations)]

    def plot(self, axes: Any = None) -> Any:
        """Time series of the disk centre, its orbit in the ground frame and the ball
        angles (three panels; ``axes``: three matplotlib axes, default a new figure;
        returns the figure)."""
        from ._figures import periodic_solution

        return periodic_solution(self, axes)

    @property
    def converged(self) -> bool:
        """Newton converged *and* every certificate passed."""
        return self.status == "converged"

    @property
    def period(self) -> float:
        """The orbit's period ``2 pi / omega`` in units of ``1 / omega_n``; a
        :class:`ValueError` if the solve did not converge."""
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
        """The orbit sampled at times ``t`` (default: 201 points over one period; at
        most :data:`~ballbal._check.MAX_SAMPLES` finite times)."""
        if self.omega is None:
            raise ValueError(f"no orbit: the solve did not converge (status {self.status})")
        tt = (np.linspace(0, self.period, 201) if t is None
              else _check.vector("t", t, _check.MAX_SAMPLES))
        if self.method == "collocation" and self.mesh is not None and self.mesh_states is not None:
            y = _native.collocation_states(
                self.mesh, np.ascontiguousarray(self.mesh_states.ravel()), self.period,
                [float(w) for w in self.winding], np.ascontiguousarray(tt, dtype=np.float64))
            names = _state_names(self.balancer)
            return pl.DataFrame({"t": tt, **{names[j]: y[:, j] for j in range(y.shape[1])}})
        tau = self.omega * tt
        m = np.arange(1, self.N + 1)
        cols: dict[str, Any] = {"t": tt}
        names = _state_names(self.balancer)
        d = len(self.winding)
        a, b = self.coeffs[:, 1::2], self.coeffs[:, 2::2]
        q = np.empty((tt.size, d))
        dq = np.empty((tt.size, d))
        # In blocks of times: the cos and sin tables are (times x N), which for 1e7
        # times and N = 256 would be 40 GB at once.
        for lo in range(0, tt.size, _HISTORY_BLOCK):
            tb = tau[lo:lo + _HISTORY_BLOCK]
            cos, sin = np.cos(np.outer(tb, m)), np.sin(np.outer(tb, m))
            q[lo:lo + tb.size] = (self.coeffs[:, 0] + cos @ a.T + sin @ b.T
                                  + np.outer(tb, self.winding))
            dq[lo:lo + tb.size] = self.omega * (-(sin * m) @ a.T + (cos * m) @ b.T
                                                + self.winding)
        for j in range(d):
            cols[names[j]] = q[:, j]
        for j in range(d):
            cols[names[d + j]] = dq[:, j]
        return pl.DataFrame(cols)

    def spectrum(self, quantity: Literal["displacement", "velocity", "acceleration"]
                 = "acceleration", **keywords: Any) -> pl.DataFrame:
        """The exact ground-frame spectrum: lines at ``Omega + k omega`` from the
        coefficients (:func:`ballbal.spectrum.line_spectrum`, which takes the keywords:
        ``natural_frequency_hz`` / ``_rpm``, ``eccentricity``, ``min_relative``)."""
        return line_spectrum(self, quantity, **keywords)

    def vibration(self, quantity: Literal["displacement", "velocity", "acceleration"]
                  = "acceleration") -> Vibration:
        """Mean, min, max and rms of ``|Z''|`` (or ``|Z|``, ``|Z'|``) over the orbit,
        exact from the coefficients (:func:`ballbal.spectrum.vibration`)."""
        return vibration(self, quantity)

    def state(self, t: float = 0.0) -> np.ndarray:
        """First-order state ``(q, q')`` on the orbit at time ``t``."""
        row = self.time_history([_check.real("t", t, finite=True)]).drop("t").row(0)
        return np.asarray(row)

    def verify(self, rtol: float = 1e-10, atol: float = 1e-12) -> float:
        """Simulate one period from the orbit's state (Tien's (2011) "NI" check) and return
        the largest distance from where the orbit says the motion should be."""
        if self.omega is None:
            raise ValueError(f"nothing to verify: status {self.status}")
        if self.method == "collocation":
            # From the collocation orbit's own state (the fitted series is not the orbit).
            y0 = np.ascontiguousarray(self.state(0.0), dtype=np.float64)
            y, *_ = _native.simulate(self.balancer, y0, 0.0, np.array([self.period]),
                                     _check.real("rtol", rtol), [_check.real("atol", atol)],
                                     10_000_000)
            d = len(self.winding)
            target = y0.copy()
            target[:d] += 2 * np.pi * np.asarray(self.winding)
            return float(np.max(np.abs(np.asarray(y)[0] - target)))
        return _native.orbit_closure(
            self.balancer, self.omega, np.ascontiguousarray(self.coeffs.ravel()),
            [float(w) for w in self.winding], _check.real("rtol", rtol),
            _check.real("atol", atol))


def _search_range(model: Balancer | Scene) -> None:
    """Refuses a model whose start search by simulation would run for minutes: ``Omega``
    above :data:`~ballbal._check.MAX_SEARCH_OMEGA`, ``zeta`` or ``zeta_b`` above
    :data:`~ballbal._check.MAX_SEARCH_DAMPING` (see there for the measured cost)."""
    bal = model.balancer if isinstance(model, Scene) else model
    zb = bal.zeta_b if isinstance(bal.zeta_b, tuple) else (bal.zeta_b,)
    for name, value, most in (("Omega", bal.Omega, _check.MAX_SEARCH_OMEGA),
                              ("zeta", bal.zeta, _check.MAX_SEARCH_DAMPING),
                              ("zeta_b", max(zb), _check.MAX_SEARCH_DAMPING)):
        if value > most:
            raise ParameterError(
                name, f"{value:g} is above {most:g}, the largest for which periodic() "
                "searches its start by simulation (the search's cost grows with it: "
                f"minutes at 100); pass guess= (e.g. a solution continued from {most:g} "
                "or below) to solve here", allowed=f"[0, {most:g}] without guess",
                value=value)


def _windings(windings: Any) -> list[int]:
    items = _check.sequence("windings", windings)
    return [_check.integer("windings", w, -16, 16) for w in items]


#: The ``Omega`` offsets ``periodic(homotopy=True)`` (and by default, last) starts from, in
#: order. The nearest come first; the far ones reach orbits that simulation finds only near
#: the perfect balance's stability boundary: the stable R-R orbit of the Tien (2011) map
#: ``zeta = 0.02, zeta_b = 0.2`` at ``Omega = 1.6, eta = 1.4`` is reached from 1.2 only,
#: that of ``zeta_b = 0.05`` at ``Omega = 1.75, eta = 1`` (N = 8) from 1.2 too.
HOMOTOPY_OMEGA_STEPS = (-0.1, 0.1, -0.2, 0.2, -0.4, 0.4, -0.6, 0.6)


def _homotopy(model: Balancer | Scene, homotopy: Any) -> list[tuple[str, float]]:
    """The ``(parameter, value)`` starts of ``periodic(homotopy=...)``."""
    if homotopy is True:
        om = model.Omega if isinstance(model, Balancer) else model.balancer.Omega
        starts = [("Omega", round(om + d, 12)) for d in HOMOTOPY_OMEGA_STEPS if om + d > 0]
        return starts + [("eta", 1.0)]
    items = list(homotopy.items()) if isinstance(homotopy, dict) else _check.sequence(
        "homotopy", homotopy)
    out = []
    for item in items:
        if not (isinstance(item, (tuple, list)) and len(item) == 2):
            raise ParameterTypeError("homotopy", "must be True, {name: value} or pairs "
                                     f"(name, value), got {item!r:.60}", value=homotopy)
        out.append((_check.string("homotopy", item[0]),
                    _check.real("homotopy", item[1], finite=True)))
    return out


@refuses_keywords(PeriodicOptions)
def periodic(
    model: Balancer | Scene,
    pattern: str = "R-R",
    *,
    N: int | Literal["auto"] | None = None,  # noqa: N803
    options: PeriodicOptions | None = None,
    guess: PeriodicSolution | tuple[float, np.ndarray] | None = None,
    windings: Sequence[int] | None = None,
    homotopy: bool | dict[str, float] | Sequence[tuple[str, float]] | None = None,
    method: Literal["hb", "collocation", "auto"] = "auto",
    collocation: Collocation | None = None,
) -> PeriodicSolution:
    """Periodic solution of a ball pattern (``"R-R"``, ``"O-O"``, ``"R-O"``, ... one letter
    per ball) by Newton–IHB with ``N`` harmonics (or by collocation, see ``method``), and
    its Floquet multipliers.

    ``method``: the discretisation. ``"hb"``: harmonic balance only. ``"collocation"``:
    orthogonal collocation on an adaptive mesh (``collocation``, a
    :class:`~ballbal.Collocation`; default :data:`ballbal.options.COLLOCATION_DEFAULTS`),
    started from harmonic balance's series (the search below, or ``guess``) and, where
    that solve fails, from simulated starts. ``"auto"`` (default): harmonic balance, and
    collocation where harmonic balance's own certificates refuse its series (``truncated``,
    ``not_closed``, or ``N="auto"`` short of its target) or, from a ``guess``, where its
    Newton solve fails (collocation then starts from the guess): near the infinite-period end of a
    rotating branch, whose orbits linger in a slow phase and jump through the rest, a
    series needs ever more harmonics, a mesh that crowds into the jump does not. A result
    harmonic balance certified is returned as before; a collocation solve that fails its
    certificates leaves harmonic balance's result. ``result.method`` says which.
    A collocation orbit is certified as a series is: ``closure`` is the largest distance
    between the orbit and the model integrated (Dormand–Prince, rtol 1e-10) over each mesh
    interval from the orbit's state at its start (above 1e-4: ``not_closed``); its
    multipliers are the discretised monodromy's (AUTO-07p's), ``modulus_error`` twice the
    leading non-trivial modulus' difference to the monodromy integrated along the orbit at
    ``Floquet.rtol`` plus that one's trivial error, and the verdict needs ``max_modulus``
    farther than it from 1 (otherwise ``undetermined``). Hill's method and the merged
    balls' ``separation_error`` are harmonic balance's only; ``omega_error`` is None.

    ``options``: a :class:`~ballbal.PeriodicOptions` (harmonic balance, Floquet, guess
    search, certificates; default :data:`ballbal.options.PERIODIC_DEFAULTS`); the option
    names below are its fields' (``hill`` is ``options.floquet.hill``, ``settle``
    ``options.guess.settle``, ``max_closure`` ``options.max_closure``; ``hill_band``
    limits Hill to verdicts in doubt, as in scans, and ``hill_stability`` is then None
    elsewhere). ``N``: the harmonics (``options.harmonic_balance.N`` when given). The
    flat option keywords of before (``hill=``, ``rtol=``, ...) are refused with a
    :class:`~ballbal.exceptions.ParameterTypeError` naming the field that replaces each.

    Without ``guess`` the start comes from a time simulation (``settle`` time units for
    transients, then up to ``window`` to measure the period). One ball, when no start at
    rest in the ground frame finds the pattern, is also started whirling with the support
    at its natural frequency (its rotating motion past a few tenths above the resonance
    is reached from rest only from a sliver of ball angles); so are the rotating balls of
    a pattern in which others rest on the disk (R-O, O-R: their stable orbits turn at
    about the natural frequency in the ground frame, omega close to ``Omega - 1``).
    ``guess`` may be a previous solution (any N; it is truncated or padded) or
    ``(omega, coeffs)``. ``rtol, atol`` are
    the RK45 tolerances of the monodromy integration, ``max_steps`` its step budget (a
    longer integration ends in ``floquet_error`` and an undetermined verdict); a verdict
    needs the largest non-trivial modulus further than ``max(margin, trivial_error)``
    from 1.

    ``windings``: the balls' whole turns per period, one integer per ball, non-zero for
    each ``R`` ball and 0 for each ``O`` ball (``|w| <= 16``; default -1 per ``R``: a ball
    lagging the disk by one turn per period). ``periodic(b, "R-R", windings=(-2, -2))``
    asks for a period-doubled R-R orbit, each ball winding twice per (doubled) period;
    without ``guess`` its simulated starts are observed over two turns of the first
    ball, whose durations may differ, and a series that only repeats a period-``T``
    orbit twice is returned only if no start gives a genuine one. A ``guess`` that is a
    :class:`PeriodicSolution` lends its windings when ``windings`` is not given. Wrong
    lengths, zeros on ``R`` balls or non-integers raise
    :class:`~ballbal.exceptions.ParameterError` naming ``windings``.

    ``homotopy``: where no simulated start reaches the pattern although a stable orbit
    exists (every start settling to the perfect balance, as at Tien's (2011) R-R point of
    its table 4-7), find the orbit at a nearby parameter point instead and follow it
    here by natural-parameter continuation (secant predictor, each step certified, the
    step halved on failure). ``True`` tries ``Omega`` 0.1, 0.2, 0.4 and 0.6 below and
    above the model's (:data:`HOMOTOPY_OMEGA_STEPS`), then ``eta = 1``; a dict
    ``{"Omega": 1.2}`` or pairs ``[("Omega", 1.2)]`` give the starts to try, in order.
    Only used without ``guess`` and only when simulation here finds nothing. By default
    (``None``) the ``True`` starts are tried last, after the constructed starts;
    ``False`` never tries them.
    ``info["guess_source"]`` says how every result was found: ``"simulation"``,
    ``"guess"``, ``"constructed (...)"`` or ``"homotopy from Omega=1.2"``.

    ``N="auto"`` starts at 3 and raises the harmonics (solving from the last) until the
    highest harmonic relative to the motion (``tail``) and the trivial multiplier's
    distance from 1 are below ``target`` (or ``N_max`` is reached: ``target_met`` says
    which). ``hill`` adds a second stability estimate by Hill's method (eigenvalues of
    the Hill matrix, no time integration): ``hill_multipliers``, ``hill_stability``, and
    ``verdicts_disagree`` when one says stable and the other unstable.

    Every converged series is certified before it is called ``converged``:

    * ``closure``: the series' ODE defect (acceleration error, ``M^-1 F``) at twice the
      collocation samples, between them, integrated over one period. It estimates the
      velocity error one simulated period from the series' state would show before the
      linearised flow amplifies or damps it, so unlike a simulated closure (``verify()``)
      it does not grow with the multipliers of a strongly unstable orbit. Above
      ``max_closure`` (default 6; genuine orbits of the Tien (2011) grid at N = 3 give at
      most 4.9, the series near a rotating branch's infinite-period end that are no
      orbits 23 and more) the status is ``not_closed``.
    * ``tail`` above ``max_tail``: status ``truncated`` (N does not resolve the orbit).
    * A series without winding whose harmonics are at round-off (below 1e-9 of its
      size) is an equilibrium, which solves the equations at any ``omega``: status
      ``equilibrium`` (no orbit, no frequency).
    * With ``windings`` of several turns, a series whose only non-zero harmonics are
      multiples of the balls' common winding is the orbit of a shorter period written
      several times (a period-doubled orbit's solve can fall back to the orbit it
      doubled): status ``repeated``, no verdict.
    * ``trivial_error``: no stability verdict (``undetermined``) unless the trivial
      multiplier is within ``max_trivial`` of 1; the same for ``hill_stability``.
    * ``separation_error`` (merged balls, i.e. identical balls on the same motion, only):
      the product of the two ball-separation multipliers against its exact value
      ``exp(-2 zeta_b T)`` (Liouville's formula on the separation mode); above
      ``max_trivial`` the verdict is ``undetermined`` too.
    * ``modulus_error``: every verdict is judged against a bound on the error of the
      leading non-trivial modulus ``max_modulus``, not only the trivial multiplier's
      (which does not bound it: at N = 3 the leading modulus' real error exceeded the
      trivial one's in a quarter of the Tien (2011) rows, by up to 195 times). The series is
      solved again with half as many harmonics more (at least two) and its multipliers
      computed with the same options; the bound is twice the two leading moduli's
      difference plus the finer series' own error measures, and the verdict needs
      ``max_modulus`` farther than it (and than ``margin``, ``trivial_error``) from 1.
      Where it is not, the finer series becomes the result (``N`` says so) and is
      checked the same way, up to ``N = 27``; then, or where no finer series converges,
      the verdict is ``undetermined``. ``modulus_error_source`` names the two series
      (``"N 5 vs 8"``). The same comparison bounds the frequency: ``omega_error`` is
      twice the two series' frequencies' difference.

    A ``not_closed``, ``truncated``, ``equilibrium`` or ``repeated`` result keeps ``coeffs`` (and,
    but for an equilibrium, ``omega``) for inspection but has no multipliers and no
    verdict. A solve that fails is returned with
    its ``status`` (``diverged``, ``singular``, ``max_iterations``, ``no_guess``) and
    ``omega = None``; it never raises for that. Tolerances and margins outside their
    ranges (``rtol`` and ``atol`` in (0, 1), ``margin`` in [0, 1), ``settle`` and
    ``window`` up to 1e5, ...) raise :class:`~ballbal.exceptions.ParameterError` naming
    them. Without ``guess`` the model's ``Omega`` is at most
    :data:`~ballbal._check.MAX_SEARCH_OMEGA` and its ``zeta`` and ``zeta_b`` at most
    :data:`~ballbal._check.MAX_SEARCH_DAMPING` (30): beyond, the simulated search for a
    start takes minutes; a ``guess`` (a solution continued there) lifts the bound.
    """
    model_argument("model", model)
    _check.string("pattern", pattern)
    options = _check.option("options", options, PeriodicOptions, PERIODIC_DEFAULTS,
                            "ballbal.PeriodicOptions")
    options = with_harmonics(options, N)
    _check.string("method", method)
    copts = _check.option("collocation", collocation, Collocation, COLLOCATION_DEFAULTS,
                          "ballbal.Collocation")
    wind = None if windings is None else _windings(windings)
    go: float | None = None
    gc: np.ndarray | None = None
    if guess is not None:
        if isinstance(guess, PeriodicSolution):
            if guess.omega is None:
                raise ParameterError("guess", "a solution that did not converge cannot seed "
                                     "a solve")
            go, gc = guess.omega, guess.coeffs
            if wind is None and guess.type == pattern:
                lent = [int(w) for w in guess.winding[-model.n_balls:]]
                if any(abs(w) > 1 for w in lent):
                    wind = lent
        elif isinstance(guess, (tuple, list)) and len(guess) == 2:
            go, gc = _check.real("guess", guess[0]), _check.array("guess", guess[1])
        else:
            raise ParameterTypeError("guess", "must be a PeriodicSolution or (omega, coeffs), "
                                     f"got {type(guess).__name__}", value=guess)
        gc = np.ascontiguousarray(gc, dtype=np.float64).ravel()
    if go is None:
        _search_range(model)
    # (starts, before the constructed starts): by default the nearby points come last.
    starts: tuple[list[tuple[str, float]], bool] | None = None
    if homotopy is None:
        starts = (_homotopy(model, True), False)
    elif homotopy is not False:
        starts = (_homotopy(model, homotopy), True)
    d = _native.periodic(model, pattern, options,
                         None if go is None or gc is None else (go, gc), wind, starts,
                         method, copts)
    out = _solution(model, d)
    out.info["guess_source"] = d["guess_source"]
    return out


def _solution(model: Balancer | Scene, d: dict[str, Any]) -> PeriodicSolution:
    """A :class:`PeriodicSolution` from the binding's dict."""
    mult = d["mult_re"] + 1j * d["mult_im"] if d["mult_re"] is not None else None
    hill_m = d["hill_re"] + 1j * d["hill_im"] if "hill_re" in d else None
    return PeriodicSolution(
        tail=d["tail"], target_met=d["target_met"], hill_multipliers=hill_m,
        hill_stability=d["hill_stability"], verdicts_disagree=d["verdicts_disagree"],
        modulus_error=d["modulus_error"], modulus_error_source=d["modulus_error_source"],
        omega_error=d["omega_error"], balancer=model, status=d["status"], type=d["type"],
        omega=d["omega"],
        coeffs=d["coeffs"], winding=d["winding"], N=d["N"], samples=d["samples"],
        residual=d["residual"], iterations=d["iterations"], multipliers=mult,
        stability=d["stability"], max_modulus=d["max_modulus"],
        trivial_error=d["trivial_error"], floquet_steps=d["floquet_steps"],
        pivot_ratio=d["pivot_ratio"], closure=d["closure"],
        separation_error=d["separation_error"],
        info={"floquet_error": d["floquet_error"], "last_omega": d["last_omega"]},
        method=d.get("method", "hb"), mesh=d.get("mesh"), mesh_states=d.get("mesh_states"),
    )
