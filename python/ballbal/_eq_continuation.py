"""Continuation of equilibria: one-parameter branches with their stability and located
events (fold, Hopf, branch point / pitchfork), branch switching at a branch point, and
two-parameter curves of those bifurcations (the core's
``rust/core/src/bifurcation/equilibria.rs``); and the balancer in the disk's units.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
import polars as pl

from ballbal import _check, _native
from ballbal._branch import (
    Branch,
    Continuation,
    Curve,
    branch_controls,
    directed,
    event_row,
    parameter_range,
)
from ballbal._progress import Progress, ProgressArg
from ballbal.analysis import Equilibrium, _equilibrium, capacities, equilibria
from ballbal.exceptions import ParameterError, ParameterTypeError
from ballbal.model import Balancer, DiskUnits
from ballbal.scene import Scene, model_argument, model_at

__all__ = ["equilibrium_branch", "equilibrium_curve", "switch_equilibrium"]

#: The default step control (a module-level value: a frozen dataclass).
_DEFAULT = Continuation()

def _options(options: Any) -> Continuation:
    if not isinstance(options, Continuation):
        raise ParameterTypeError("options", f"must be a Continuation, got {type(options).__name__}")
    return options


def _native_model(model: Any) -> tuple[Balancer | Scene, DiskUnits | None]:
    """What the binding takes: the model, and the disk's units when continued in them."""
    if isinstance(model, DiskUnits):
        return model.balancer, model
    return model, None


def _seed_at(seed: DiskUnits, names: tuple[str, ...], values: tuple[float, ...]) -> DiskUnits:
    return seed.replace(**dict(zip(names, values, strict=True)))


def _eta_at(model: Any, parameter: str, value: float) -> np.ndarray:
    """The balls' capacities at a branch point (they vary only along an ``eta`` branch, or
    ``m0`` / ``e`` in the disk's units)."""
    if isinstance(model, DiskUnits):
        return capacities(_seed_at(model, (parameter,), (value,)).balancer)
    if parameter.startswith("eta"):
        return capacities(model_at(model, parameter, value))
    return capacities(model)


def _to_seed(rows: list[dict[str, Any]], seed: DiskUnits, names: tuple[str, ...],
             keys: tuple[str, ...]) -> list[dict[str, Any]]:
    """Rows in the disk's units: ``x, y`` times ``e`` (lengths by the track radius), rates
    (eigenvalues, ``max_real``, ``omega``) over ``S = sqrt(1 + n m0)`` (its time unit)."""
    out = []
    for r in rows:
        at = _seed_at(seed, names, tuple(float(r[k]) for k in keys))
        s, e = at.scale, at.e
        r = dict(r)
        q = np.array(r["q"], dtype=float)
        q[:2] *= e
        r["q"] = q
        for k in ("eig_re", "eig_im"):
            r[k] = np.asarray(r[k], dtype=float) / s
        r["index"] = r["index"] / s
        if "omega" in r:
            r["omega"] = r["omega"] / s
        out.append(r)
    return out


def _branch(d: dict[str, Any], parameter: str, model: Any, rng: tuple[float, float],
            options: Continuation) -> Branch:
    pts = d["points"]
    evs = d["events"]
    solutions = tuple(_equilibrium(p, _eta_at(model, parameter, p["p"])) for p in pts)
    event_solutions = tuple(_equilibrium(e, _eta_at(model, parameter, e["p"])) for e in evs)
    meta = {"model": model, "range": rng, "options": options,
            "event_x": [list(e["x"]) for e in evs],
            "event_tangent": [list(e["tangent"]) for e in evs]}
    if isinstance(model, DiskUnits):
        pts = _to_seed(pts, model, (parameter,), ("p",))
        evs = _to_seed(evs, model, (parameter,), ("p",))
    marks: list[str | None] = [None] * len(pts)
    for e in evs:
        r = e["row"]
        marks[r] = e["type"] if marks[r] is None else f"{marks[r]},{e['type']}"
    table = pl.DataFrame({
        parameter: [p["p"] for p in pts],
        "q": [list(map(float, p["q"])) for p in pts],
        "kind": [p["kind"] for p in pts],
        "stability": [p["stability"] for p in pts],
        "max_real": [p["index"] for p in pts],
        "eig_re": [list(map(float, p["eig_re"])) for p in pts],
        "eig_im": [list(map(float, p["eig_im"])) for p in pts],
        "test_fold": [p["test_fold"] for p in pts],
        "test_branch_point": [p["test_branch_point"] for p in pts],
        "test_hopf": [p["test_hopf"] for p in pts],
        "event": pl.Series(marks, dtype=pl.String),
    }, schema_overrides={"q": pl.List(pl.Float64), "eig_re": pl.List(pl.Float64),
                         "eig_im": pl.List(pl.Float64)})
    events = pl.DataFrame({
        "type": [e["type"] for e in evs],
        parameter: [e["p"] for e in evs],
        "q": [list(map(float, e["q"])) for e in evs],
        "kind": [e["kind"] for e in evs],
        "stability": [e["stability"] for e in evs],
        "max_real": [e["index"] for e in evs],
        "omega": [e["omega"] for e in evs],
        "test": [e["test"] for e in evs],
        "row": [e["row"] for e in evs],
    }, schema={"type": pl.String, parameter: pl.Float64, "q": pl.List(pl.Float64),
               "kind": pl.String, "stability": pl.String, "max_real": pl.Float64,
               "omega": pl.Float64, "test": pl.Float64, "row": pl.Int64})
    return Branch(
        kind="equilibrium", parameter=parameter, table=table, events=events, stop=d["stop"],
        solutions=solutions, event_solutions=event_solutions, meta=meta,
    )


def equilibrium_branch(model: Any, parameter: str, *, start: Equilibrium | str = "perfect_balance",
                       range: tuple[float, float], options: Continuation = _DEFAULT,
                       direction: Literal["forward", "backward", "both"] | None = None,
                       at: float | Sequence[float] | None = None,
                       stop: str | Sequence[str] | None = None,
                       progress: ProgressArg = False) -> Branch:
    """The branch of equilibria through ``start`` (an :class:`~ballbal.Equilibrium` of
    ``model``, or a kind name: the first equilibrium of that kind) continued in
    ``parameter`` (any name ``with_param`` takes: ``"Omega"``, ``"eta"`` (all balls),
    ``"eta2"`` (the second ball's; balls are named from 1), ``"zeta"``, ``"zeta_b"``,
    ``"mu"``, ``"delta"``, scene parameters) by pseudo-arclength over ``range``, through
    folds.

    ``model`` may also be a :class:`~ballbal.model.DiskUnits`: then ``parameter`` is one
    of its (``"omega0"``, ``"m0"``, ``"e"``, ``"C0"``, ``"D0"``), ``start`` an
    equilibrium of ``model.balancer`` or a kind name, and the tables are in the disk's
    units: its parameter, ``q`` with ``x, y`` over the track radius, eigenvalues,
    ``max_real`` and ``omega`` in its time unit (ballbal's over ``S = sqrt(1 + n m0)``);
    ``solutions`` stay ballbal's :class:`~ballbal.Equilibrium` objects.

    ``direction``: ``"forward"`` (towards increasing ``parameter``), ``"backward"``, or
    ``"both"``: both ways from the start, the rows running from the end reached
    downwards to the end reached upwards (the start once; tangents and ``test_fold``
    oriented along the rows), ``stop`` then ``"<lower end>/<upper end>"``. Default:
    ``options.forward``.

    ``at``: parameter values inside ``range`` (AUTO's ``UZ``): each time a step crosses
    one (or ends on it; not at the start), the equilibrium there is solved with the
    parameter fixed at the value and listed in ``events`` as a ``"user"`` event (test
    0), its ``row`` the row after it; the rows are those of the branch without ``at``.
    ``stop``: an event name (or alias: ``"LP"``, ``"BP"``, ``"HB"``, ``"UZ"``) or a list
    of them: the branch ends at the first such event, its last row that event's point,
    ``stop`` (the attribute) the event's name. The branch also stops on ``range``'s
    edges (``"boundary"``, a row on the edge): that is its stop at a parameter value.

    ``table``: one row per point (the parameter, ``q``, ``kind``, ``stability``,
    ``max_real``, the eigenvalues, the test functions ``test_fold`` (dp/ds),
    ``test_branch_point`` (the bordered determinant, or on the balls-together branch the
    antisymmetric ball mode's stiffness), ``test_hopf`` (the bialternate-product
    determinant) and ``event``, the events located since the previous row). ``events``:
    fold, Hopf (with its frequency ``omega``) and branch points, located to ~1e-11 in
    arclength.

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)`` called as points are added (``total`` the most the call
    can make: ``max_points`` per direction)."""
    native, seed = _native_model(model)
    model_argument("model", native)
    parameter = _check.string("parameter", parameter)
    rng = parameter_range(range)
    options = _options(options)
    options, both = directed(options, direction)
    at_values, stop_events = branch_controls(at, stop)
    if isinstance(start, str):
        found = [e for e in equilibria(native) if e.kind == start]
        if not found:
            raise ParameterError("start", f"the model has no {start!r} equilibrium",
                                 allowed="perfect_balance, balanced, together, opposite, "
                                         "unbalanced, partial_balance, imbalance_side")
        start = found[0]
    if not isinstance(start, Equilibrium):
        raise ParameterTypeError("start", "must be an Equilibrium or a kind name")
    with Progress(progress, options.max_points * (2 if both else 1), "ballbal branch",
                  "point") as bar:
        d = _native.equilibrium_branch(native, parameter, [float(v) for v in start.q],
                                       start.kind, rng, options, both, seed, at_values,
                                       stop_events, bar.reporter())
    return _branch(d, parameter, model, rng, options)


def _event(branch: Any, event: Any) -> int:
    if not isinstance(branch, Branch) or branch.kind != "equilibrium":
        raise ParameterTypeError("branch", "must be a Branch of equilibria")
    return event_row(branch, event)


def switch_equilibrium(branch: Branch, event: int | str = "branch_point", *,
                       progress: ProgressArg = False) -> Branch:
    """The other branch through the branch point ``event`` of ``branch`` (a row of
    ``branch.events``, or an event name: the first event of that kind; default the first
    branch point), e.g. the perfect balance born at the pitchfork of the balls-together
    branch, eta = 1/2 for two balls, started along the null vector of ``[F_q, F_p]``
    orthogonal to the branch's tangent, over the same range with the same options.

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)`` called as points are added (``total`` the most the call
    can make: ``max_points`` per direction)."""
    i = _event(branch, event)
    if branch.events["type"][i] != "branch_point":
        raise ParameterError("event", f"event {i} is a {branch.events['type'][i]}, "
                             "not a branch point", allowed="branch_point")
    m = branch.meta
    native, seed = _native_model(m["model"])
    with Progress(progress, m["options"].max_points, "ballbal branch", "point") as bar:
        d = _native.equilibrium_switch(native, branch.parameter, m["event_x"][i],
                                       float(branch.events[branch.parameter][i]),
                                       m["event_tangent"][i], m["range"], m["options"], seed,
                                       bar.reporter())
    return _branch(d, branch.parameter, m["model"], m["range"], m["options"])


def equilibrium_curve(branch: Branch, event: int | str, parameter2: str, *,
                      range: tuple[float, float], options: Continuation = _DEFAULT,
                      progress: ProgressArg = False) -> Curve:
    """The curve of the bifurcation ``event`` of ``branch`` (an event name, e.g.
    ``"fold"``: the first event of that kind along the branch, or a row of
    ``branch.events``) in (the branch's parameter, ``parameter2``), ``range`` bounding
    ``parameter2``, continued both ways:
    a fold gives the saddle-node curve, a Hopf point the Hopf curve (with ``omega``), a
    branch point of the balls-together branch the pitchfork curve (folds and pitchforks
    of that branch are continued on its invariant subspace, all ``b_i`` equal).

    With a branch continued in the disk's units (a :class:`~ballbal.model.DiskUnits`
    model), ``parameter2`` is one of its parameters and the tables are in those
    units, as for :func:`equilibrium_branch`.

    ``points`` lists the codimension-two points found, each once: ``"BT"`` (a double
    zero eigenvalue with a Jordan block: Bogdanov–Takens), ``"ZH"`` (zero-Hopf),
    ``"cusp"`` (the curve reverses in the parameter plane), ``"pitchfork"`` (a
    saddle-node curve meets the pitchfork; for two balls at (Omega, eta) = (1, 1/2),
    in the disk's units (omega0, m0) = (1/sqrt(1 + 2 m0), e/2), where the second zero
    eigenvalue is the antisymmetric ball mode's), ``"saddle_node"`` (a pitchfork curve
    meets the saddle-node curve).

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)`` called as points are added (``total`` the most the call
    can make: ``max_points`` per direction)."""
    i = _event(branch, event)
    parameter2 = _check.string("parameter2", parameter2)
    rng = parameter_range(range)
    options = _options(options)
    etype = branch.events["type"][i]
    ekind = branch.events["kind"][i]
    together = ekind == "together" and etype in ("fold", "branch_point")
    if etype == "branch_point" and not together:
        raise ParameterError("event", "curves of branch points are continued for the "
                             "pitchfork of the balls-together branch only",
                             allowed="fold, hopf, or a together branch point")
    m = branch.meta
    native, seed = _native_model(m["model"])
    with Progress(progress, 2 * options.max_points, "ballbal curve", "point") as bar:
        d = _native.equilibrium_curve(native, etype, branch.parameter, parameter2,
                                      m["event_x"][i],
                                      float(branch.events[branch.parameter][i]),
                                      together, rng, options, seed, bar.reporter())
    p1, p2 = branch.parameter, parameter2
    pts = d["points"]
    sp = d["special"]
    if seed is not None:
        pts = _to_seed(pts, seed, (p1, p2), ("p1", "p2"))
        sp = [{**s, "q": _to_seed([{**s, "eig_re": [], "eig_im": [], "index": 0.0}], seed,
                                  (p1, p2), ("p1", "p2"))[0]["q"]} for s in sp]
    table = pl.DataFrame({
        p1: [p["p1"] for p in pts],
        p2: [p["p2"] for p in pts],
        "q": [list(map(float, p["q"])) for p in pts],
        "kind": [p["kind"] for p in pts],
        "stability": [p["stability"] for p in pts],
        "max_real": [p["index"] for p in pts],
        "omega": [p["omega"] for p in pts],
        "test": [p["test"] for p in pts],
    }, schema_overrides={"q": pl.List(pl.Float64)})
    points = pl.DataFrame({
        "type": [s["type"] for s in sp],
        p1: [s["p1"] for s in sp],
        p2: [s["p2"] for s in sp],
        "q": [list(map(float, s["q"])) for s in sp],
        "row": [s["row"] for s in sp],
    }, schema={"type": pl.String, p1: pl.Float64, p2: pl.Float64, "q": pl.List(pl.Float64),
               "row": pl.Int64})
    return Curve(kind=d["kind"], parameters=(p1, p2), table=table, points=points,
                 stop=d["stop"], meta={"model": m["model"], "range": rng, "options": options})
