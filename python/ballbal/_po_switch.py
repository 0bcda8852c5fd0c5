"""Branch switching: the first solution of the branch that leaves a known solution at
a bifurcation, from the critical eigenvector (no simulation). The numerics are the
core's ``bifurcation/switch.rs``."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from . import _check, _native
from ._branch import Branch, _listing, event_name, event_row
from .analysis import Equilibrium, PeriodicSolution, _solution
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer, DiskUnits
from .options import PERIODIC_DEFAULTS, PeriodicOptions, refuses_keywords, with_harmonics
from .scene import Scene, model_argument, model_at


def _from_branch(branch: Branch, event: Any, kind: str | None, parameter: str | None,
                 model: Balancer | Scene | None
                 ) -> tuple[PeriodicSolution | Equilibrium, str, str, Balancer | Scene | None]:
    """The solution, event name, parameter and (for an equilibrium) model that switching
    at ``branch``'s event ``event`` starts from: all the branch's own."""
    if event is None:
        raise ParameterError("event", f"name the event to switch at; {_listing(branch)}")
    i = event_row(branch, event)
    etype = str(branch.events["type"][i])
    if kind is not None and event_name(kind, "kind") != etype:
        raise ParameterError("kind", f"event {i} of the branch is a {etype}, not "
                             f"{kind!r:.40}", allowed=etype)
    if parameter is not None and parameter != branch.parameter:
        raise ParameterError("parameter", f"the branch is continued in "
                             f"{branch.parameter!r}, got {parameter!r:.40}",
                             allowed=branch.parameter)
    solution = branch.event_solutions[i]
    if branch.kind == "equilibrium" and model is None:
        own = branch.meta["model"]
        if isinstance(own, DiskUnits):
            raise ParameterError("branch", "a branch continued in the disk's units has no "
                                 "ballbal model at its events: continue the Balancer "
                                 "(ballbal.continuation.from_disk_units) to switch")
        model = model_at(own, branch.parameter, float(branch.events[branch.parameter][i]))
    return solution, etype, branch.parameter, model


@refuses_keywords(PeriodicOptions)
def switch(
    solution: PeriodicSolution | Equilibrium | Branch,
    *,
    parameter: str | None = None,
    kind: str | None = None,
    event: int | str | None = None,
    model: Balancer | Scene | None = None,
    amplitude: float = 0.05,
    N: int | Literal["auto"] | None = None,  # noqa: N803
    options: PeriodicOptions | None = None,
) -> PeriodicSolution:
    """The first periodic solution on the branch that leaves ``solution`` at a
    bifurcation in ``parameter``, ``kind`` naming it (the names of
    :func:`~ballbal.continuation.event_vocabulary`, or an alias such as AUTO's ``PD``,
    ``BP``, ``HB``, in any case):

    * ``kind="period_doubling"`` (a multiplier at -1) from a
      :class:`~ballbal.PeriodicSolution` near the event: the doubled orbit, period ``2 T``
      and every winding doubled (an R-R orbit becomes ``windings (-2, -2)``);
    * ``kind="branch_point"`` (a real multiplier at +1 other than the trivial one)
      from a periodic solution: for merged balls the unmerged orbit, along the balls'
      antisymmetric separation mode;
    * ``kind="hopf"`` from an :class:`~ballbal.Equilibrium` (give its ``model=``) near a
      Hopf point: the small all-``O`` orbit it gives birth to, from the critical
      eigenvector of the equilibrium's Jacobian, at its frequency.

    ``solution`` may also be a :class:`~ballbal._branch.Branch` (of periodic solutions or
    of equilibria) with ``event`` one of its events: a row of its ``events`` table, or an
    event name (the first event of that kind along the branch, e.g. ``event="hopf"``).
    The event's type, solution, parameter and (for equilibria) model at the event are the
    branch's own: ``kind``, ``parameter`` and ``model`` need not be given (a ``kind`` or
    ``parameter`` given must agree with the event's).

    The new branch's point lies at distance ``amplitude`` from the given one along the
    critical direction (in the series' coefficients), the parameter left free: near a
    pitchfork, period doubling or Hopf point ``|p - p*|`` grows like the amplitude
    squared. The result is an ordinary :class:`~ballbal.PeriodicSolution` (certificates,
    multipliers) of the model at the parameter value found, at the harmonics it was found
    with: its verdict's ``modulus_error`` comes from a series with more harmonics, as on
    a branch, but a verdict that bound leaves open stays undetermined (``N`` is not
    raised); ``info`` holds
    ``switched_from`` (the event's canonical name), ``parameter``, ``value`` and
    ``critical`` (the multiplier, or at a Hopf point the eigenvalue, switched along).
    ``options`` and ``N`` as in :func:`~ballbal.periodic` (``N`` sets the harmonics of a
    Hopf orbit; a doubled orbit has twice the solution's). When no solution of the new branch is
    found within ``amplitude`` (halved up to four times), raises
    :class:`~ballbal.exceptions.ParameterError` naming ``amplitude``.
    """
    if isinstance(solution, Branch):
        solution, kind, parameter, model = _from_branch(solution, event, kind, parameter,
                                                        model)
    if parameter is None:
        raise ParameterError("parameter", "name the parameter the branch is continued in")
    _check.string("parameter", parameter)
    if kind is not None:
        kind = event_name(kind, "kind")
    amp = _check.real("amplitude", amplitude, 0.0, 10.0, lo_open=True)
    options = _check.option("options", options, PeriodicOptions, PERIODIC_DEFAULTS,
                            "ballbal.PeriodicOptions")
    options = with_harmonics(options, N)
    if isinstance(solution, PeriodicSolution):
        if kind is None:
            raise ParameterError("kind", "name the event a periodic solution is switched "
                                 "at", allowed="period_doubling, branch_point")
        if solution.omega is None:
            raise ParameterError("solution", f"did not converge (status {solution.status})")
        base = solution.balancer
        d, p, crit = _native.switch_periodic(
            base, parameter, float(solution.omega),
            np.ascontiguousarray(solution.coeffs, dtype=np.float64).ravel(),
            [float(w) for w in solution.winding], kind, amp, options)
    elif isinstance(solution, Equilibrium):
        if kind not in (None, "hopf"):
            raise ParameterError("kind", f"an equilibrium is switched at a hopf event, not "
                                 f"a {kind}" + (" (switch_equilibrium switches at a branch "
                                                "point)" if kind == "branch_point" else ""),
                                 allowed="hopf")
        kind = "hopf"
        if model is None:
            raise ParameterError("model", "give the model the equilibrium belongs to")
        base = model_argument("model", model)
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
