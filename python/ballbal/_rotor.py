"""A rigid rotor on one journal bearing, in the fixed frame, without balls ([Yen2005]).

Nondimensional equations (the core's ``analysis/journal.rs``; positions over the radial
clearance ``c``, time ``tau = w t``, film forces over ``F_S = mu w L R^3 / c^2``)::

    q'' = f(q, q', tau) / m + g_n e_g + rho_u (cos(tau + phi_u), sin(tau + phi_u))
          + a g_n exp(-s (tau - tau_c)^2) e_i

* ``mass_parameter`` ``m = M c w^2 / F_S = M c^3 w / (mu L R^3)``, the classical bearing
  mass parameter (also the critical mass of the whirl threshold);
* ``gravity`` ``g_n = W / (M c w^2) = g / (c w^2)`` along ``gravity_direction`` (degrees,
  0 = Yen's (2005) ``x``, pointing down); the film's static load is ``m g_n`` in ``F_S``,
  i.e. the Sommerfeld number is ``1 / (pi m g_n)``;
* ``unbalance`` ``rho_u = e_u / c``: the unbalance force ``M e_u w^2`` is ``rho_u / g_n``
  times the weight;
* :class:`RotorImpulse`: ``amplitude`` times the weight, ``exp(-sharpness (tau - center)^2)``,
  along ``direction`` (degrees); Yen's (2005) ``5 W exp(-5e5 (t - 0.006)^2)`` at 500 rad/s
  is ``RotorImpulse(5, 3, 2)``.

The journal turns at the reference speed ``w`` from ``tau = 0`` (Yen's (2005) sudden
start) unless the rotor has a :class:`SpinUp`: a linear run-up from ``start w`` to ``w``
over ``duration`` (in ``tau``). The film at speed ``s w`` is ``s f(q, q' / s)`` (Reynolds'
right-hand side scales with the speed, and half-Sommerfeld and Swift–Stieber cavitation
commute with a positive factor), the unbalance's mass centre at the journal's angle
``theta = int s dtau`` adds ``rho_u (s^2 u - s' J u)``, ``u = (cos, sin)(theta + phi_u)``;
gravity, ``m`` and ``g_n`` keep their values at ``w``. A prescribed speed makes the rotor
non-autonomous during the run-up: it is for :func:`simulate_rotor` only.

Runs end ``"completed"``, ``"contact"`` (eccentricity reached ``eps_contact``, the time
found on the step's dense output), ``"stiff"`` (the explicit integrator's steps held down
by the squeeze film near the wall: use ``method="implicit"``, a Rosenbrock 2(3) method) or
``"failed"``; the trajectory up to then is kept.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import polars as pl

from . import _check
from ._geometry import Bearing
from ._style import Summarised
from .exceptions import ParameterError, ParameterTypeError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

OUTCOMES = ("completed", "contact", "stiff", "failed")
METHODS = ("explicit", "implicit")


@dataclass(frozen=True)
class RotorImpulse:
    """Force ``amplitude * W * exp(-sharpness (tau - center)^2)`` along ``direction``
    (degrees in the fixed frame; 0 is Yen's (2005) gravity direction ``x``)."""

    amplitude: float = 5.0
    center: float = 3.0
    sharpness: float = 2.0
    direction: float = 0.0

    def __post_init__(self) -> None:
        for name in ("amplitude", "center", "sharpness", "direction"):
            object.__setattr__(self, name, _check.real(f"impulse.{name}", getattr(self, name),
                                                      finite=True))
        # its ranges are the core's, checked on a rotor under gravity (an impulse is a
        # multiple of the weight; that it needs gravity is the rotor's check)
        RotorOnBearing(Bearing(), 1.0, gravity=1.0, impulse=self)


@dataclass(frozen=True)
class SpinUp:
    """A linear run-up of the journal's speed: ``s = start + (1 - start) tau / duration``
    times the reference speed ``w`` on ``0 <= tau <= duration``, ``start`` before and 1
    after (the journal's angle is its integral). ``start`` in ``[0, 1)``, ``duration`` in
    ``(0, 1e12]`` (units ``1 / w``). [Yen2005] contrasts its sudden start with
    a start from rest, after Li et al. (1999)."""

    start: float = 0.0
    duration: float = 100.0

    def __post_init__(self) -> None:
        for name in ("start", "duration"):
            object.__setattr__(self, name, _check.real(f"spin_up.{name}", getattr(self, name),
                                                      finite=True))
        # its ranges are the core's
        RotorOnBearing(Bearing(), 1.0, spin_up=self)


@dataclass(frozen=True)
class RotorOnBearing:
    """A rigid rotor of bearing mass parameter ``mass_parameter`` on ``bearing`` under
    ``gravity`` (``g / (c w^2)``), ``unbalance`` (``e_u / c``), an optional
    :class:`RotorImpulse` and an optional :class:`SpinUp` (``None``: at ``w`` from the
    start) (module docstring). Angles in degrees."""

    bearing: Bearing
    mass_parameter: float
    gravity: float = 0.0
    unbalance: float = 0.0
    impulse: RotorImpulse | None = None
    gravity_direction: float = 0.0
    unbalance_phase: float = 0.0
    spin_up: SpinUp | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.bearing, Bearing):
            raise ParameterTypeError(
                "bearing", f"bearing must be ballbal.bearing.Bearing, got "
                f"{type(self.bearing).__name__}", allowed="Bearing")
        if self.impulse is not None and not isinstance(self.impulse, RotorImpulse):
            raise ParameterTypeError(
                "impulse",
                f"impulse must be RotorImpulse or None, got {type(self.impulse).__name__}",
                allowed="RotorImpulse or None")
        if self.spin_up is not None and not isinstance(self.spin_up, SpinUp):
            raise ParameterTypeError(
                "spin_up",
                f"spin_up must be SpinUp or None, got {type(self.spin_up).__name__}",
                allowed="SpinUp or None")
        for name in ("mass_parameter", "gravity", "unbalance", "gravity_direction",
                     "unbalance_phase"):
            object.__setattr__(self, name, _check.real(name, getattr(self, name)))
        from . import _native

        _native.validate_rotor(self)

    @classmethod
    def from_dimensions(cls, bearing: Bearing, *, radius: float, length: float,
                        clearance: float, viscosity: float, mass: float, speed: float,
                        unbalance: float = 0.0, g: float = 9.81,
                        impulse: RotorImpulse | None = None) -> RotorOnBearing:
        """From SI quantities: journal ``radius``, bearing ``length``, radial ``clearance``
        (m), ``viscosity`` (Pa s), rotor ``mass`` carried by the bearing (kg), ``speed``
        (rad/s), unbalance eccentricity ``unbalance`` ``e_u`` (m), gravity ``g`` (m/s^2,
        along Yen's (2005) ``x``). ``m = M c^3 w / (mu L R^3)``, ``g_n = g / (c w^2)``,
        ``rho_u = e_u / c``; ``length / (2 radius)`` must be the bearing's
        ``length_ratio``. Time: ``t = tau / speed``."""
        from . import _native

        if not isinstance(bearing, Bearing):
            raise ParameterTypeError("bearing", f"bearing must be ballbal.bearing.Bearing, got "
                                     f"{type(bearing).__name__}", allowed="Bearing")
        args = {k: _check.real(k, v) for k, v in dict(
            radius=radius, length=length, clearance=clearance, viscosity=viscosity,
            mass=mass, speed=speed, unbalance=unbalance, g=g).items()}
        m, gn, rho = _native.rotor_from_dimensions(bearing, **args)
        return cls(bearing, m, gravity=gn, unbalance=rho, impulse=impulse)

    @property
    def static_load(self) -> float:
        """The weight on the film in ``F_S`` (``m g_n``)."""
        return self.mass_parameter * self.gravity


@dataclass(frozen=True, repr=False)
class RotorTrajectory(Summarised):
    """A simulated trajectory: ``table`` (polars) with columns ``tau, x, y, vx, vy,
    eccentricity, attitude`` (degrees, the journal's direction from ``x``), ``fx, fy,
    radial, tangential`` (film force in ``F_S``; radial positive towards the centre,
    tangential along the rotation), the ``outcome`` (one of :data:`OUTCOMES`), the time
    ``t_end`` reached, ``contact_time`` (contact only), where the steps collapsed
    (``stiff_eccentricity``, stiff only), step and force-evaluation counts and a message."""

    table: pl.DataFrame
    outcome: str
    t_end: float
    contact_time: float | None
    stiff_eccentricity: float | None
    accepted_steps: int
    rejected_steps: int
    force_evals: int
    message: str
    rotor: RotorOnBearing = field(repr=False)

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        ecc = self.table["eccentricity"]
        top = float(ecc.max()) if ecc.len() else math.nan  # type: ignore[arg-type]
        head = (f"RotorTrajectory {self.outcome} τ to {self.t_end:.4g}: {self.table.height} "
                f"rows, ε max={top:.4g}, {self.accepted_steps} steps")
        return head, [("outcome", self.outcome), ("τ reached", self.t_end),
                      ("rows", self.table.height), ("largest eccentricity", top),
                      ("contact at τ", self.contact_time),
                      ("steps accepted / rejected",
                       f"{self.accepted_steps} / {self.rejected_steps}"),
                      ("force evaluations", self.force_evals), ("message", self.message)]

    def plot(self, axes: Any = None) -> Any:
        """The journal orbit in the clearance circle and the eccentricity against time
        (two panels; :func:`plot_trajectory` compares several runs); returns the figure."""
        from ._figures import rotor_trajectory

        return rotor_trajectory(self, axes)


def rotor_equilibrium(rotor: RotorOnBearing) -> tuple[float, float]:
    """The journal's static equilibrium ``(x, y)`` under the rotor's weight (Newton on the
    film; the centre without gravity)."""
    from . import _native

    return _native.rotor_equilibrium(rotor)


def simulate_rotor(rotor: RotorOnBearing, x0: Any, t_span: Any, *, samples: int = 2001,
                   t_eval: Any = None, rtol: float = 1e-6, atol: float = 1e-9,
                   max_steps: int = 2_000_000, eps_contact: float = 0.98,
                   stiff_steps: int = 100_000, method: str = "explicit",
                   factor_reuse: float | None = 1e-10) -> RotorTrajectory:
    """Simulates ``rotor`` from ``x0`` = ``(x, y)``, ``(x, y, x', y')`` (units ``c`` and
    ``c w``) or ``"equilibrium"`` (at rest at :func:`rotor_equilibrium`) over
    ``t_span = (tau0, tau1)`` (``tau0 < tau1``), with ``samples`` evenly spaced rows (or
    the rows at ``t_eval``; at most :data:`~ballbal._check.MAX_SAMPLES` either way).
    ``method`` ``"explicit"`` (Dormand–Prince 5(4); a run whose steps are held so small by
    stability that finishing would take more than ``stiff_steps`` steps ends ``"stiff"``,
    with ``stiff_eccentricity`` where they collapsed) or ``"implicit"`` (Rosenbrock
    2(3)). ``factor_reuse``: relative residual of the preconditioned solves of
    finite grooved films (``None``: a fresh factorisation per evaluation)."""
    from . import _native

    if not isinstance(rotor, RotorOnBearing):
        raise ParameterTypeError("rotor", f"rotor must be RotorOnBearing, got "
                                 f"{type(rotor).__name__}", allowed="RotorOnBearing")
    if isinstance(x0, str) and x0 == "equilibrium":
        x0 = rotor_equilibrium(rotor)
    x = _check.reals("x0", x0)
    if len(x) == 2:
        x = [*x, 0.0, 0.0]
    if len(x) != 4:
        raise ParameterError("x0", f"x0 must be (x, y) or (x, y, vx, vy), got {len(x)} values",
                             allowed="2 or 4 numbers")
    span = _check.reals("t_span", t_span)
    if len(span) != 2:
        raise ParameterError("t_span", "t_span must be (tau0, tau1)", allowed="2 numbers")
    # Checked here, where the caller named them: the core sees only the output times made
    # from them and would name those (t_eval).
    tau0 = _check.real("t_span[0]", span[0], finite=True)
    if not (math.isfinite(span[1]) and span[1] > tau0 and math.isfinite(span[1] - tau0)):
        raise ParameterError("t_span", f"must be (tau0, tau1) with tau1 > tau0, both finite, "
                             f"got {tuple(span)}", allowed="tau0 < tau1, finite",
                             value=t_span)
    if t_eval is None:
        n = _check.integer("samples", samples, 2, _check.MAX_SAMPLES)
        te = np.linspace(span[0], span[1], n)
    else:
        te = np.ascontiguousarray(_check.array("t_eval", t_eval), dtype=float)
        if te.size > _check.MAX_SAMPLES:
            raise ParameterError("t_eval", f"{te.size} output times, at most "
                                 f"{_check.MAX_SAMPLES:.0e}",
                                 allowed=f"at most {_check.MAX_SAMPLES:.0e} times")
    d = _native.simulate_rotor(
        rotor, (x[0], x[1], x[2], x[3]), span[0], te, _check.real("rtol", rtol),
        _check.real("atol", atol),
        _check.integer("max_steps", max_steps), _check.real("eps_contact", eps_contact),
        _check.integer("stiff_steps", stiff_steps), _check.string("method", method),
        None if factor_reuse is None else _check.real("factor_reuse", factor_reuse))
    s, f = d["state"], d["force"]
    table = pl.DataFrame({
        "tau": d["tau"], "x": s[:, 0], "y": s[:, 1], "vx": s[:, 2], "vy": s[:, 3],
        "eccentricity": np.hypot(s[:, 0], s[:, 1]),
        "attitude": np.degrees(np.arctan2(s[:, 1], s[:, 0])),
        "fx": f[:, 0], "fy": f[:, 1], "radial": f[:, 2], "tangential": f[:, 3],
    })
    return RotorTrajectory(
        table=table, outcome=d["outcome"], t_end=d["t_end"], contact_time=d["contact_time"],
        stiff_eccentricity=d["stiff_eccentricity"], accepted_steps=d["accepted_steps"],
        rejected_steps=d["rejected_steps"], force_evals=d["force_evals"],
        message=d["message"], rotor=rotor)


def plot_trajectory(trajectories: RotorTrajectory | dict[str, RotorTrajectory], *,
                    title: str | None = None) -> tuple[Figure, Figure]:
    """Yen's (2005) two views of one or more labelled trajectories: the journal orbit inside
    the clearance circle (``x`` down, as the seed draws it), and the tangential film
    force against time. Returns ``(orbit_figure, force_figure)``."""
    from .plot import _pyplot

    runs = trajectories if isinstance(trajectories, dict) else {"": trajectories}
    for label, tr in runs.items():
        if not isinstance(label, str) or not isinstance(tr, RotorTrajectory):
            raise ParameterTypeError(
                "trajectories", f"must be a RotorTrajectory or a dict of them by label (str), "
                f"got {type(label).__name__}: {type(tr).__name__}", value=trajectories)
    if title is not None:
        _check.string("title", title)
    plt = _pyplot()
    orbit, ax = plt.subplots(figsize=(4.6, 4.6))
    th = np.linspace(0, 2 * math.pi, 361)
    ax.plot(np.sin(th), np.cos(th), color="0.3", lw=1)
    force, axf = plt.subplots(figsize=(6.0, 3.4))
    for label, tr in runs.items():
        t = tr.table
        # x points down: plot (y, -x) so that gravity is down on the page.
        line, = ax.plot(t["y"], -t["x"], lw=0.9, label=label or None)
        if tr.outcome == "contact":
            ax.plot(t["y"][-1], -t["x"][-1], "x", color=line.get_color())
        axf.plot(t["tau"], t["tangential"], lw=0.9, label=label or None)
    ax.set_aspect("equal")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xlabel(r"$y/c$")
    ax.set_ylabel(r"$-x/c$ ($x$ down)")
    axf.set_xlabel(r"$\tau = \omega t$ (rad)")
    axf.set_ylabel(r"tangential film force $F_t$ ($F_S$)")
    for a in (ax, axf):
        if any(runs):
            a.legend(fontsize=7)
        if title:
            a.set_title(title, fontsize=9)
    orbit.tight_layout()
    force.tight_layout()
    return orbit, force
