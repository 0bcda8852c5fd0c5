"""Two-parameter curves of bifurcations of periodic solutions (``fold``,
``branch_point`` of merged balls, ``period_doubling``, ``neimark_sacker``): a
minimally augmented harmonic-balance system continued by pseudo-arclength
(``rust/core/src/bifurcation/po_curves/``), from an event of a periodic branch.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import polars as pl

from . import _check, _native
from ._branch import Branch, Continuation, Curve, event_row, parameter_range
from ._po_continuation import _multipliers
from ._progress import Progress, ProgressArg
from .analysis import _solution
from .exceptions import ParameterError, ParameterTypeError
from .options import BRANCH_DEFAULTS, PeriodicOptions
from .scene import model_at

__all__ = ["periodic_curve"]

def _flag_label(kind: str, status: str) -> str:
    """A codimension-two label as the ``flag`` column shows it: only a confirmed point
    carries the bare label of a bifurcation."""
    if status == "confirmed":
        return kind
    return f"{kind}?" if status == "undetermined" else f"not {kind}"


def periodic_curve(
    branch: Branch,
    event: int | str,
    parameter2: str,
    *,
    range: tuple[float, float],  # noqa: A002 - the documented keyword
    range1: tuple[float, float] | None = None,
    options: Continuation | None = None,
    periodic_options: PeriodicOptions | None = None,
    locate_tol: float = 1e-8,
    progress: ProgressArg = False,
) -> Curve:
    """The curve of the bifurcation ``event`` of a periodic branch (an event name, e.g.
    ``"period_doubling"``: the first event of that kind along the branch, or a row of
    ``branch.events``; a ``fold``, ``branch_point``, ``period_doubling`` or
    ``neimark_sacker``) in (``branch.parameter``, ``parameter2``), continued
    both ways from the event over ``range`` in ``parameter2`` and ``range1`` in the
    branch's parameter (default: the branch's range), with the branch's harmonics.

    The curve solves the harmonic-balance equations together with one scalar test
    function from a bordered matrix that is singular on it: the harmonic-balance
    Jacobian (``fold``), the separating mode's Galerkin block of merged balls (``branch_point``: the
    separation multiplier at +1), the linearisation's Galerkin matrix on half harmonics
    (``period_doubling``: a multiplier at -1), Hill's matrix on the harmonics ``k + theta / 2 pi``
    (``neimark_sacker``: a complex pair ``e^{+-i theta}`` on the unit circle; the test function is
    complex, and ``theta`` is an unknown of the curve next to the branch's parameter,
    started where Hill's matrix at the event is closest to singular). A merged start is
    continued with its balls merged.

    ``table``: one row per point (the two parameters, ``omega``, ``period``, status,
    stability and multipliers with ``periodic_options`` (default
    :data:`ballbal.options.BRANCH_DEFAULTS`), ``modulus_error`` and
    ``modulus_error_source`` (the bound on the leading non-trivial modulus' error that the
    verdict was judged against, from a series with more harmonics, as on a
    :func:`~ballbal.continuation.periodic_branch`; the point keeps its ``N``, and a
    verdict the bound leaves open is undetermined; ``omega_error`` from the same pair),
    ``test`` (the curve's own test
    function, ~0), ``test_*`` (the other kinds' determinants, whose sign changes are the
    codimension-two points), ``flag`` (the codimension-two points located since the
    previous row: the bare label when its multipliers confirm it, ``"LPPD?"`` when they
    cannot decide, ``"not LPPD"`` when they reject it)); a ``neimark_sacker`` curve also has
    ``theta``, the critical pair's angle in ``(0, pi)``. ``points``: the sign changes of
    the test functions located on the curve (codimension-two points keep AUTO's labels:
    ``CP`` cusp of a fold curve,
    ``BP`` / ``LP`` / ``PD`` where the curve meets that curve, ``LPPD`` fold–flip; on a
    ``neimark_sacker`` curve ``LPNS`` fold–Neimark–Sacker, ``PDNS`` flip–Neimark–Sacker,
    ``BPNS`` and
    the strong resonances ``R4`` (``theta = pi/2``) and ``R3`` (``theta = 2 pi/3``)). A
    ``neimark_sacker`` curve ends with ``"resonance_1:1"`` / ``"resonance_1:2"`` where ``theta``
    reaches 0 or pi (the pair meets the real axis). Each point carries its multiplier
    certificate: ``status`` (``"confirmed"``, ``"rejected"``, ``"undetermined"``; only a
    confirmed point is a codimension-two bifurcation, a truncated Galerkin determinant can
    change sign with no multiplier crossing), ``gap`` (distance of the nearest multiplier
    to the value the label adds: -1 for ``LPPD`` on a fold curve, ``PD``, ``PDNS``; the
    separation multiplier's +1 for ``BP``, ``BPNS``; a second +1 for ``LP``, ``LPNS``,
    ``LPPD`` on a PD curve; for ``CP``, ``R3``, ``R4`` the curve's own), ``residual`` /
    ``own_residual`` (the smallest perturbation of the monodromy that puts a multiplier at
    the added / the curve's own value) and ``error`` (the monodromy's estimated error);
    see docs/howto/errors.md, "Certificates of codimension-two points".
    ``meta["solutions"]``: the :class:`~ballbal.PeriodicSolution` of every row.

    ``progress``: True for a progress bar over the points (tqdm, notebook-aware), or a
    callable ``f(done, total)`` called as points are added (``total`` the most the call
    can make: ``max_points`` per direction)."""
    if not isinstance(branch, Branch) or branch.kind != "periodic":
        raise ParameterTypeError("branch", "must be a periodic Branch (from periodic_branch)",
                                 value=branch)
    i = event_row(branch, event)
    kind = branch.events["type"][i]
    p1 = branch.parameter
    p2 = _check.string("parameter2", parameter2)
    if p2 == p1:
        raise ParameterError("parameter2", f"must differ from the branch's parameter {p1!r}")
    lo, hi = parameter_range(range)
    if range1 is None:
        lo1, hi1 = branch.meta.get("range", (-np.inf, np.inf))
    else:
        try:
            lo1, hi1 = parameter_range(range1)
        except ParameterError as e:
            raise type(e)("range1", e.message, value=range1) from None
    options = _check.option("options", options, Continuation,
                            Continuation(ds=0.01, ds_max=0.05, max_points=200),
                            "ballbal.continuation.Continuation")
    popts = _check.option("periodic_options", periodic_options, PeriodicOptions,
                          BRANCH_DEFAULTS, "ballbal.PeriodicOptions")
    n = int(branch.meta.get("N", branch.event_solutions[i].N))
    popts = replace(popts, harmonic_balance=replace(popts.harmonic_balance, N=n))
    locate_tol = _check.real("locate_tol", locate_tol)
    start = branch.event_solutions[i]
    model = start.balancer
    coeffs = np.ascontiguousarray(start.coeffs, dtype=np.float64).ravel()
    winding = [float(w) for w in start.winding]
    with Progress(progress, 2 * options.max_points, "ballbal curve", "point") as bar:
        d = _native.periodic_curve(model, kind, p1, p2, (float(start.omega), coeffs, winding),
                                   (lo, hi), (lo1, hi1), options, popts, locate_tol,
                                   bar.reporter())
    pts = d["points"]
    flags: list[str | None] = [None] * len(pts)
    for s in d["special"]:
        r = min(int(s["row"]), len(pts) - 1)
        label = _flag_label(s["type"], s["status"])
        flags[r] = label if flags[r] is None else f"{flags[r]},{label}"
    tests = sorted({k for p in pts for k in p if k.startswith("test_")})
    ns = kind == "neimark_sacker"
    rows = []
    for p, flag in zip(pts, flags, strict=True):
        re_, im = _multipliers(p)
        om = p["omega"]
        rows.append({
            p1: p["p1"], p2: p["p2"], "omega": om,
            "period": None if om is None else 2 * np.pi / om,
            "status": p["status"], "stability": p["stability"],
            "max_modulus": p["max_modulus"], "modulus_error": p["modulus_error"],
            "modulus_error_source": p["modulus_error_source"], "omega_error": p["omega_error"],
            "mult_re": re_, "mult_im": im,
            "trivial_error": p["trivial_error"], "closure": p["closure"],
            "test": p["test"], **({"theta": p["theta"]} if ns else {}),
            **{t: p.get(t) for t in tests}, "flag": flag,
        })
    f, s_, lf = pl.Float64, pl.Utf8, pl.List(pl.Float64)
    schema: dict[str, Any] = {p1: f, p2: f, "omega": f, "period": f, "status": s_,
                              "stability": s_, "max_modulus": f, "modulus_error": f,
                              "modulus_error_source": s_, "omega_error": f, "mult_re": lf,
                              "mult_im": lf, "trivial_error": f, "closure": f, "test": f,
                              **({"theta": f} if ns else {}), **{t: f for t in tests},
                              "flag": s_}
    table = pl.DataFrame(rows, schema=schema, orient="row")
    sp = d["special"]
    points = pl.DataFrame({
        "type": [s["type"] for s in sp], p1: [s["p1"] for s in sp],
        p2: [s["p2"] for s in sp], "omega": [s["omega"] for s in sp],
        "row": [s["row"] for s in sp], "status": [s["status"] for s in sp],
        "gap": [s["gap"] for s in sp], "residual": [s["residual"] for s in sp],
        "own_residual": [s["own_residual"] for s in sp], "error": [s["error"] for s in sp],
    }, schema={"type": pl.Utf8, p1: f, p2: f, "omega": f, "row": pl.Int64,
               "status": pl.Utf8, "gap": f, "residual": f, "own_residual": f, "error": f})
    solutions = tuple(_solution(model_at(model_at(model, p1, p["p1"]), p2, p["p2"]), p)
                      for p in pts)
    return Curve(kind=d["kind"], parameters=(p1, p2), table=table, points=points,
                 stop=d["stop"],
                 meta={"model": model, "range": (lo, hi), "range1": (lo1, hi1),
                       "options": options, "together": d["together"], "N": n,
                       "solutions": solutions})
