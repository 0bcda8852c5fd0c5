"""Continuation of periodic solutions in one parameter (pseudo-arclength on the
harmonic-balance equations, ``rust/core/src/bifurcation/po_branch.rs``), every point
certified and judged as :func:`ballbal.periodic` does, with its bifurcations located.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Any, Literal

import numpy as np
import polars as pl

from . import _check, _native
from ._branch import (
    Branch,
    Continuation,
    branch_controls,
    directed,
    parameter_range,
)
from ._progress import Progress, ProgressArg
from .analysis import PeriodicSolution, _solution
from .exceptions import ParameterError, ParameterTypeError
from .options import BRANCH_DEFAULTS, COLLOCATION_DEFAULTS, Collocation, PeriodicOptions
from .scene import model_at

__all__ = ["Branch", "Continuation", "periodic_branch"]

def _multipliers(d: dict[str, Any]) -> tuple[list[float] | None, list[float] | None]:
    if d["mult_re"] is not None:
        return list(d["mult_re"]), list(d["mult_im"])
    if "hill_re" in d:
        return list(d["hill_re"]), list(d["hill_im"])
    return None, None


def _row(parameter: str, d: dict[str, Any]) -> dict[str, Any]:
    re_, im = _multipliers(d)
    omega = d["omega"]
    mod = None if re_ is None or im is None else np.hypot(re_, im)
    return {
        parameter: d["p"], "omega": omega,
        "period": None if omega is None else 2 * np.pi / omega,
        "status": d["status"], "stability": d["stability"],
        "max_modulus": d["max_modulus"] if d["max_modulus"] is not None or mod is None
        else float(np.sort(mod)[-2] if len(mod) > 1 else mod[0]),
        "modulus_error": d["modulus_error"], "modulus_error_source": d["modulus_error_source"],
        "omega_error": d["omega_error"],
        "mult_re": re_, "mult_im": im,
        "trivial_error": d["trivial_error"], "closure": d["closure"], "tail": d["tail"],
        "separation_error": d["separation_error"], "residual": d["residual"],
        "dp_ds": d["dp_ds"], "det_sign": d["det_sign"],
        "test_fold": d["test_fold"], "test_branch_point": d["test_branch_point"],
        "test_branch_point_multipliers": d["test_branch_point_multipliers"],
        "test_period_doubling": d["test_period_doubling"],
        "test_neimark_sacker": d["test_neimark_sacker"],
        "test_infinite_period": d["test_infinite_period"], "method": d["method"],
        "event": d["event"],
    }


def _schema(parameter: str) -> dict[str, Any]:
    f, s, lf = pl.Float64, pl.Utf8, pl.List(pl.Float64)
    return {parameter: f, "omega": f, "period": f, "status": s, "stability": s,
            "max_modulus": f, "modulus_error": f, "modulus_error_source": s, "omega_error": f,
            "mult_re": lf, "mult_im": lf, "trivial_error": f,
            "closure": f, "tail": f, "separation_error": f, "residual": f, "dp_ds": f,
            "det_sign": f, "test_fold": f, "test_branch_point": f,
            "test_branch_point_multipliers": f, "test_period_doubling": f,
            "test_neimark_sacker": f, "test_infinite_period": f, "method": s, "event": s}


def periodic_branch(
    start: PeriodicSolution,
    parameter: str,
    *,
    range: tuple[float, float],  # noqa: A002 - the documented keyword
    options: Continuation | None = None,
    N: int | None = None,
    periodic_options: PeriodicOptions | None = None,
    min_omega: float = 1e-3,
    event_tol: float = 1e-7,
    direction: Literal["forward", "backward", "both"] | None = None,
    at: float | Sequence[float] | None = None,
    stop: str | Sequence[str] | None = None,
    stop_period: float | None = None,
    method: Literal["hb", "collocation", "auto"] = "auto",
    collocation: Collocation | None = None,
    progress: ProgressArg = False,
) -> Branch:
    """Continue the periodic solution ``start`` (converged, from :func:`ballbal.periodic`)
    in the model parameter ``parameter`` (``"Omega"``, ``"eta"``, ``"zeta_b"``,
    ``"eta2"`` (the second ball's; balls are named from 1), a scene's ``"springs"``, ...)
    over ``range = (lo, hi)`` by
    pseudo-arclength continuation of the harmonic-balance equations (through folds),
    with ``N`` harmonics (default: the start's).

    ``direction``: ``"forward"`` (towards increasing ``parameter``), ``"backward"``, or
    ``"both"``: both ways from the start, the rows running from the end reached
    downwards to the end reached upwards (the start once; tangents, ``dp_ds``,
    ``det_sign``, ``test_fold`` and ``test_branch_point`` oriented along the rows),
    ``stop`` then ``"<lower end>/<upper end>"``. Default: ``options.forward``, as for
    :func:`~ballbal.continuation.equilibrium_branch`.

    ``at``: parameter values inside ``range`` (AUTO's ``UZ``): each time a step crosses
    one (or ends on it; not at the start), the orbit there is solved with the parameter
    fixed at the value, judged as a row is, and listed in ``events`` as a ``"user"``
    event (test 0), its ``index`` the row after it; the rows are those of the branch
    without ``at``. Stop conditions: ``stop``, an event name (or alias: ``"LP"``,
    ``"BP"``, ``"PD"``, ``"NS"``, ``"UZ"``) or a list of them: the branch ends at the first
    such event, its last row that event's point, ``stop`` (the attribute) the event's
    name; ``stop_period`` (above the start's period): the branch ends where the period
    reaches it, its last row solved with that period, ``stop`` ``"period"``. It also
    stops on ``range``'s edges (``"boundary"``, a row on the edge: its stop at a
    parameter value) and at an infinite period.

    Every point gets the certificates and Floquet multipliers of :func:`ballbal.periodic`
    with ``periodic_options`` (default :data:`ballbal.options.BRANCH_DEFAULTS`: Magnus'
    monodromy, Hill's method where the verdict is in doubt;
    ``Floquet(monodromy=False, hill=True)`` uses Hill's multipliers instead): a point
    whose certificate fails has status ``not_closed`` / ``truncated`` and is never
    called stable. Events (named as on every branch, see
    :func:`~ballbal.continuation.event_vocabulary`), located to ``event_tol`` in the
    parameter between two points: ``fold`` (``dp/ds`` changes sign), ``branch_point``
    (the bordered determinant changes sign, i.e. a real multiplier passes +1 other than
    the trivial one; for merged balls the ball-separation multiplier),
    ``period_doubling`` (a real multiplier through -1), ``neimark_sacker`` (a complex
    pair through the unit circle) and ``infinite_period`` (omega falls below
    ``min_omega``, or a point fails its certificate while
    omega falls; that point is not kept, the branch stops with ``"infinite_period"`` and
    the event's parameter ``p*`` is fitted on the last three points as
    ``T = C / sqrt|p - p*| + D``, the period law near a saddle-node on the invariant
    circle).

    ``method``: the discretisation. ``"hb"``: harmonic balance with ``N`` harmonics,
    pseudo-arclength through folds (every row as before). ``"collocation"``: orthogonal
    collocation on an adaptive mesh (``collocation``, a :class:`~ballbal.Collocation`,
    default :data:`ballbal.options.COLLOCATION_DEFAULTS`; the mesh adapted at every
    point), continued naturally in the parameter (a fold ends it with
    ``"step_too_small"``), every row certified as ``periodic(method="collocation")``
    certifies its orbit (closure; the discretised monodromy's multipliers with
    ``modulus_error``). ``"auto"`` (default): harmonic balance, handing over to
    collocation at the first point where, with omega falling, harmonic balance's omega
    bound exceeds 1e-6 of omega, its certificates fail, or omega falls below
    ``min_omega`` (the rows up to there are those of ``"hb"``; without Floquet
    multipliers there is no omega bound, and only the last two hand over). The ``method`` column
    says which discretisation each row used. On collocation rows ``dp_ds``,
    ``det_sign``, ``test_fold`` and ``test_branch_point`` are NaN (no arclength tangent);
    the multiplier events are located between rows by bisection in the parameter on the
    discretised multipliers; ``test_infinite_period`` is the slowest speed along the
    orbit, which falls to zero linearly at a saddle-node on the invariant circle: the
    ``infinite_period`` event is its zero extrapolated from the last two rows, the branch
    approaching it in steps that halve the remaining distance and ending when the last
    row is within ``event_tol`` of it, or when a row's speed leaves the line through the
    two before it by half (the orbit no longer resolves it; the end is then where those
    two put it). ``min_omega`` does not end collocation rows.

    Every verdict is bounded as :func:`ballbal.periodic`'s is, but at the branch's own
    ``N`` (a branch keeps one truncation): the point's series is solved again from itself
    with more harmonics (``N 3 vs 5``, ``N 8 vs 12``), and ``modulus_error`` (twice the
    difference of the leading non-trivial moduli, plus the finer series' own integration
    error) must be smaller than the modulus' distance to 1 for a verdict; otherwise, or
    where that finer series fails (the reason is in ``floquet_error`` of the point's
    solution), the point is ``undetermined`` (its harmonics are not raised along a
    branch). A point the trivial multiplier's error already leaves undetermined gets no
    finer series (``modulus_error`` None). The bifurcations are located on the
    multipliers at ``N``, with or without the bound.

    Returns a :class:`~ballbal._branch.Branch` of kind ``"periodic"``: ``table`` (one row
    per point: the parameter, omega, period, status, stability, max modulus,
    ``modulus_error`` and ``modulus_error_source`` (the bound on the leading non-trivial
    modulus' error the verdict was judged against, and the two series it compares, as in
    :func:`ballbal.scan`; None without a Floquet verdict), ``omega_error`` (the bound on
    omega's error from the same pair), multipliers, certificates, test functions,
    ``event``: the events located between the previous row and this one),
    ``events`` (type, parameter, the located solution's summary, the test function's
    value, ``index``: the row after it), ``solutions`` and
    ``event_solutions`` (:class:`~ballbal.PeriodicSolution` objects with the model at
    their parameter value, row for row and event for event).

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)`` called as points are added (``total`` the most the call
    can make: ``max_points`` per direction)."""
    if not isinstance(start, PeriodicSolution):
        raise ParameterTypeError("start", "must be a PeriodicSolution (from ballbal.periodic)",
                                 value=start)
    if start.omega is None or start.status != "converged":
        raise ParameterError("start", f"must be a converged solution, got status {start.status!r}")
    _check.string("parameter", parameter)
    lo, hi = parameter_range(range)
    options = _check.option("options", options, Continuation, Continuation(),
                            "ballbal.continuation.Continuation")
    options, both = directed(options, direction)
    popts = _check.option("periodic_options", periodic_options, PeriodicOptions,
                          BRANCH_DEFAULTS, "ballbal.PeriodicOptions")
    n = start.N if N is None else _check.integer("N", N, 1, 256)
    popts = replace(popts, harmonic_balance=replace(popts.harmonic_balance, N=n))
    min_omega = _check.real("min_omega", min_omega)
    event_tol = _check.real("event_tol", event_tol)
    at_values, stop_events = branch_controls(at, stop)
    if stop_period is not None:
        stop_period = _check.real("stop_period", stop_period)
    if method not in ("hb", "collocation", "auto"):
        raise ParameterError("method", f'must be "hb", "collocation" or "auto", got {method!r}')
    colloc = _check.option("collocation", collocation, Collocation, COLLOCATION_DEFAULTS,
                           "ballbal.Collocation")
    model = start.balancer
    coeffs = np.ascontiguousarray(start.coeffs, dtype=np.float64).ravel()
    winding = [float(w) for w in start.winding]
    with Progress(progress, options.max_points * (2 if both else 1), "ballbal branch",
                  "point") as bar:
        d = _native.periodic_branch(model, parameter, (float(start.omega), coeffs, winding),
                                    (lo, hi), options, popts, min_omega, event_tol, both,
                                    at_values, stop_events, stop_period, method, colloc,
                                    bar.reporter())
    table = pl.DataFrame([_row(parameter, p) for p in d["points"]], schema=_schema(parameter),
                         orient="row") if d["points"] else pl.DataFrame(schema=_schema(parameter))
    ev_rows = []
    for e in d["events"]:
        r = _row(parameter, e)
        r.pop("event")
        r[parameter] = e["event_p"]
        ev_rows.append({"type": e["event_type"], **r, "test": e["test"], "index": e["index"]})
    ev_schema = {"type": pl.Utf8, **{k: v for k, v in _schema(parameter).items() if k != "event"},
                 "test": pl.Float64, "index": pl.Int64}
    events = (pl.DataFrame(ev_rows, schema=ev_schema, orient="row") if ev_rows
              else pl.DataFrame(schema=ev_schema))
    solutions = tuple(_solution(model_at(model, parameter, p["p"]), p) for p in d["points"])
    event_solutions = tuple(_solution(model_at(model, parameter, e["p"]), e)
                            for e in d["events"])
    return Branch(kind="periodic", parameter=parameter, table=table, events=events,
                  stop=d["stop"], solutions=solutions, event_solutions=event_solutions,
                  meta={"N": n, "pattern": start.type, "range": (lo, hi),
                        "min_omega": min_omega, "event_tol": event_tol, "method": method,
                        "options": options})
