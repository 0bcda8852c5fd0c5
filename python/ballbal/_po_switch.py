"""Branch switching: the first solution of the branch that leaves a known solution at
a bifurcation, from the critical eigenvector (no simulation). The numerics are the
core's ``analysis/switch.rs``."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from . import _check, _native
from ._branch import Branch, model_at
from .analysis import Equilibrium, PeriodicSolution, _solution
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer
from .options import PERIODIC_DEFAULTS, PERIODIC_KEYWORDS, PeriodicOptions, with_keywords
from .scene import Scene

SwitchKind = Literal["PD", "BP", "Hopf"]
_KINDS = ("PD", "BP", "Hopf")


def switch(
    solution: PeriodicSolution | Equilibrium | Branch,
    *,
    parameter: str | None = None,
    kind: SwitchKind | None = None,
    event: int | None = None,
    model: Balancer | Scene | None = None,
    amplitude: float = 0.05,
    options: PeriodicOptions | None = None,
    **keywords: Any,
) -> PeriodicSolution:
    """The first periodic solution on the branch that leaves ``solution`` at a
    bifurcation in ``parameter``:

    * ``kind="PD"`` (period doubling, a multiplier at -1) from a
      :class:`~ballbal.PeriodicSolution` near the event: the doubled orbit, period ``2 T``
      and every winding doubled (an R-R orbit becomes ``windings (-2, -2)``);
    * ``kind="BP"`` (branch point, a real multiplier at +1 other than the trivial one)
      from a periodic solution: for merged balls the unmerged orbit, along the balls'
      antisymmetric separation mode;
    * ``kind="Hopf"`` from an :class:`~ballbal.Equilibrium` (give its ``model=``) near a
      Hopf point: the small all-``O`` orbit it gives birth to, from the critical
      eigenvector of the equilibrium's Jacobian, at its frequency.

    ``solution`` may also be a :class:`~ballbal._branch.Branch` with ``event`` the row of
    its ``events`` table (its type, solution and parameter are used).

    The new branch's point lies at distance ``amplitude`` from the given one along the
    critical direction (in the series' coefficients), the parameter left free: near a
    pitchfork, period doubling or Hopf point ``|p - p*|`` grows like the amplitude
    squared. The result is an ordinary :class:`~ballbal.PeriodicSolution` (certificates,
    multipliers) of the model at the parameter value found, at the harmonics it was found
    with: its verdict's ``modulus_error`` comes from a series with more harmonics, as on
    a branch, but a verdict that bound leaves open stays undetermined (``N`` is not
    raised); ``info`` holds
    ``switched_from`` (the kind), ``parameter``, ``value`` and ``critical`` (the
    multiplier, or at a Hopf point the eigenvalue, switched along). ``options`` and the
    keywords as in :func:`~ballbal.periodic` (``N`` sets the harmonics of a Hopf orbit;
    a doubled orbit has twice the solution's). When no solution of the new branch is
    found within ``amplitude`` (halved up to four times), raises
    :class:`~ballbal.exceptions.ParameterError` naming ``amplitude``.
    """
    if isinstance(solution, Branch):
        if event is None:
            raise ParameterError("event", "give the row of the branch's events table to "
                                 "switch at")
        n = len(solution.event_solutions)
        i = _check.integer("event", event, 0, max(n - 1, 0))
        if i >= n:
            raise ParameterError("event", "the branch has no located events")
        if kind is None:
            kind = str(solution.events["type"][i])  # type: ignore[assignment]
        parameter = solution.parameter if parameter is None else parameter
        solution = solution.event_solutions[i]
    if parameter is None:
        raise ParameterError("parameter", "name the parameter the branch is continued in")
    _check.string("parameter", parameter)
    if kind is not None:
        _check.string("kind", kind)
    amp = _check.real("amplitude", amplitude, 0.0, 10.0, lo_open=True)
    options = _check.option("options", options, PeriodicOptions, PERIODIC_DEFAULTS,
                            "ballbal.PeriodicOptions")
    options = with_keywords(options, "switch", keywords, PERIODIC_KEYWORDS)
    if isinstance(solution, PeriodicSolution):
        if kind is None or kind not in ("PD", "BP"):
            raise ParameterError("kind", f"must be 'PD' or 'BP' for a periodic solution, got "
                                 f"{kind!r}", allowed="PD, BP")
        if solution.omega is None:
            raise ParameterError("solution", f"did not converge (status {solution.status})")
        base = solution.balancer
        d, p, crit = _native.switch_periodic(
            base, parameter, float(solution.omega),
            np.ascontiguousarray(solution.coeffs, dtype=np.float64).ravel(),
            [float(w) for w in solution.winding], kind, amp, options)
    elif isinstance(solution, Equilibrium):
        if kind not in (None, "Hopf"):
            raise ParameterError("kind", f"must be 'Hopf' for an equilibrium, got {kind!r}",
                                 allowed="Hopf")
        kind = "Hopf"
        if model is None:
            raise ParameterError("model", "give the model the equilibrium belongs to")
        base = _check.model("model", model)
        d, p, crit = _native.switch_hopf(base, parameter, [float(v) for v in solution.q],
                                         amp, options)
    else:
        raise ParameterTypeError("solution", "must be a PeriodicSolution, an Equilibrium or "
                                 f"a Branch, got {type(solution).__name__}", value=solution)
    out = _solution(_at(base, parameter, p), d)
    out.info.update({"switched_from": kind, "parameter": parameter, "value": p,
                     "critical": complex(*crit)})
    return out


def _at(model: Balancer | Scene, parameter: str, value: float) -> Balancer | Scene:
    """The model with ``parameter`` set to ``value`` (its ``replace``; a name it does not
    have leaves the Python model as it was, the core having used its own registry)."""
    try:
        return model_at(model, parameter, value)
    except (TypeError, ValueError):
        return model
