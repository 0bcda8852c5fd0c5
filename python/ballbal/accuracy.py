"""What accuracy costs in time: harmonics, samples and tolerances against error and
seconds at one parameter point."""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import polars as pl

from . import _check
from ._progress import Progress, ProgressArg, checked
from .analysis import PeriodicSolution, periodic
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer
from .options import Floquet, HarmonicBalance, PeriodicOptions
from .scene import Scene, model_argument


def _match_error(a: np.ndarray, ref: np.ndarray) -> float:
    """Largest distance between multipliers after pairing each reference multiplier with
    the nearest unused one (pairing by sorted modulus mixes up near-equal moduli)."""
    left = list(a)
    worst = 0.0
    for r in sorted(ref, key=lambda z: -abs(z)):
        k = int(np.argmin([abs(z - r) for z in left]))
        worst = max(worst, abs(left.pop(k) - r))
    return worst


def _study_options(kw: dict[str, Any]) -> PeriodicOptions:
    """One setting of the study (its ``N``, ``samples``, ``tol``, ``rtol``, ``atol`` and
    where given ``step_tol`` and the Floquet method) without Hill, at the truncation
    under study (``refine=False``: not one the verdict's bound refined)."""
    hb = HarmonicBalance(N=kw["N"], samples=kw["samples"], tol=kw["tol"],
                         step_tol=kw.get("step_tol", HarmonicBalance.step_tol))
    fl = Floquet(rtol=kw["rtol"], atol=kw["atol"], method=kw.get("floquet_method", "rk45"),
                 hill=False, refine=False)
    return PeriodicOptions(harmonic_balance=hb, floquet=fl)


def _coeff_error(c: np.ndarray, ref: np.ndarray) -> float:
    n = max(c.shape[1], ref.shape[1])
    pad = np.zeros((c.shape[0], n))
    padr = np.zeros((ref.shape[0], n))
    pad[:, : c.shape[1]] = c
    padr[:, : ref.shape[1]] = ref
    return float(np.max(np.abs(pad - padr)) / max(1.0, float(np.max(np.abs(ref)))))


def _knob(name: str, v: Any) -> list[Any]:
    """The values of one knob: a list (empty skips the knob), at most
    :data:`~ballbal._check.MAX_STUDY_VALUES` (each is ``repeats`` solves)."""
    items = _check.sequence(name, v, empty=True)
    _check.at_most(name, len(items), _check.MAX_STUDY_VALUES, "values")
    return items


def accuracy_cost(
    model: Balancer | Scene,
    pattern: str = "R-R",
    *,
    N: Sequence[int] = (1, 2, 3, 4, 5, 6, 8, 10, 12, 16),
    samples: Sequence[int] = (4, 6, 8, 16, 32),
    tol: Sequence[float] = (1e-3, 1e-5, 1e-7, 1e-9, 1e-11),
    rtol: Sequence[float] = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
    magnus_rtol: Sequence[float] = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10),
    base_N: int = 12,
    reference_N: int = 32,
    neighbour: float = 0.01,
    repeats: int = 5,
    guess: PeriodicSolution | None = None,
    progress: ProgressArg = False,
) -> pl.DataFrame:
    """Error against time for each accuracy knob at one point, as a polars table
    (``model`` may be an autonomous scene).

    Knobs, each varied with the others at a high-accuracy baseline (``base_N``
    harmonics, default samples, Newton tol 1e-10, RK45 rtol 1e-9): ``N``; ``samples``
    per period as a multiple of N (at ``base_N``); the Newton ``tol``; the RK45 ``rtol``
    of the monodromy (atol = rtol / 100); ``magnus_rtol``, the multiplier accuracy asked
    of the Magnus monodromy (``Floquet(method="magnus")``), the curve beside RK45's.
    Every setting is solved from the same warm start, the solution at
    ``Omega - neighbour`` (what a scan does), ``repeats`` times; ``seconds`` is the
    median wall time of harmonic balance plus Floquet.

    Errors are against a reference with ``reference_N`` harmonics and tight tolerances
    (rtol 1e-11), whose own orbit closure after one period of time simulation is in the
    column ``reference_closure``: ``omega_error`` (relative), ``coeff_error`` (largest
    coefficient difference relative to the largest coefficient), ``multiplier_error``
    (largest distance between paired multipliers), ``trivial_error`` (the computed
    trivial multiplier's distance from 1) and whether the verdict matches the
    reference's. The same certificates as :func:`~ballbal.periodic` apply: a setting whose
    series fails one (``status`` ``not_closed`` or ``truncated``) has no errors, and
    ``verdict_ok`` is null where either verdict is ``undetermined`` (no verdict is not a
    wrong verdict); ``closure``, ``separation_error`` and ``stability`` are columns.

    Checked before any solve, each error naming its argument: ``reference_N`` above
    ``base_N`` and at least every ``N`` (at most 256), at most
    :data:`~ballbal._check.MAX_STUDY_VALUES` values per knob, ``samples`` multiples
    giving at most 65536 samples, ``tol > 0``, ``rtol`` and ``magnus_rtol`` in (0, 1),
    ``neighbour <= Omega``. ``progress``: True for a progress bar over the settings
    (tqdm, notebook-aware), or a callable ``f(done, total)``.
    """
    model_argument("model", model)
    progress = checked(progress)
    _check.string("pattern", pattern)
    N = [_check.integer("N", n, 1, 256) for n in _knob("N", N)]
    base_N = _check.integer("base_N", base_N, 1, 255)
    # The core's largest sample count: a multiple of base_N above it is refused here,
    # before the reference solves, rather than at its setting's solve.
    multiples = [_check.real("samples", m, 0.0, (1 << 16) / base_N, lo_open=True)
                 for m in _knob("samples", samples)]
    # The core's ranges, checked before the reference solves: Newton's tolerance is
    # positive, an integration's relative tolerance in (0, 1).
    tol = [_check.real("tol", t, 0.0, lo_open=True, finite=True) for t in _knob("tol", tol)]
    rtol = [_check.real("rtol", r, 0.0, 1.0, lo_open=True, hi_open=True)
            for r in _knob("rtol", rtol)]
    magnus_rtol = [_check.real("magnus_rtol", r, 0.0, 1.0, lo_open=True, hi_open=True)
                   for r in _knob("magnus_rtol", magnus_rtol)]
    # The errors are measured against the reference: it must resolve more harmonics
    # than the baseline and at least as many as every N tried.
    top = max([base_N + 1, *N])
    reference_N = _check.integer("reference_N", reference_N, top, 256)
    # the warm start's point, Omega - neighbour, is a speed: not below 0
    neighbour = _check.real("neighbour", neighbour, -math.inf, model.Omega, finite=True)
    repeats = _check.integer("repeats", repeats, 1, 1000)
    if guess is not None and not isinstance(guess, PeriodicSolution):
        raise ParameterTypeError("guess", "must be a PeriodicSolution or None, got "
                                 f"{type(guess).__name__}", value=guess)
    no_hill = PeriodicOptions(floquet=Floquet(hill=False))
    tight = PeriodicOptions(harmonic_balance=HarmonicBalance(tol=1e-12, step_tol=1e-10),
                            floquet=Floquet(rtol=1e-11, atol=1e-13, hill=False))
    if guess is None:
        start = periodic(model, pattern, N=8, options=no_hill, method="hb")
        if not start.converged:
            raise ParameterError("pattern", f"no {pattern} solution found at this point by "
                             f"simulation (status {start.status}); pass guess=")
        guess = start
    ref = periodic(model, pattern, N=reference_N, guess=guess, options=tight, method="hb")
    if not ref.converged or ref.multipliers is None:
        raise ParameterError("reference_N", f"the N = {reference_N} solve did not converge "
                         f"(status {ref.status})")
    closure = ref.verify(rtol=1e-11, atol=1e-13)
    near_b = model.replace(Omega=model.Omega - neighbour)
    near = periodic(near_b, pattern, N=reference_N, guess=ref, options=no_hill,
                    method="hb")
    warm = near if near.converged else ref

    settings: list[tuple[str, float, dict[str, Any]]] = []
    base: dict[str, Any] = dict(N=base_N, samples=None, tol=1e-10, rtol=1e-9, atol=1e-11)
    for n in N:
        settings.append(("N", n, {**base, "N": int(n)}))
    for m in multiples:
        per = max(int(m * base_N), 2 * base_N + 2)
        settings.append(("samples", per, {**base, "samples": per}))
    for t in tol:
        settings.append(("tol", t, {**base, "tol": t, "step_tol": max(t * 100, 1e-8)}))
    for r in rtol:
        settings.append(("rtol", r, {**base, "rtol": r, "atol": r / 100}))
    for r in magnus_rtol:
        settings.append(("magnus", r, {**base, "rtol": r, "atol": r / 100,
                                       "floquet_method": "magnus"}))

    rows = []
    with Progress(progress, len(settings), "ballbal accuracy study") as bar:
        for knob, value, kw in settings:
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                # The truncation under study, not one the verdict's bound refined, nor
                # collocation where the series is refused.
                s = periodic(model, pattern, guess=warm, options=_study_options(kw),
                             method="hb")
                times.append(time.perf_counter() - t0)
            ok = s.converged and s.multipliers is not None
            errors: dict[str, float | None] = dict.fromkeys(
                ("omega_error", "coeff_error", "multiplier_error"))
            if (s.converged and s.omega is not None and s.multipliers is not None
                    and ref.omega is not None and ref.multipliers is not None):
                errors = {
                    "omega_error": abs(s.omega - ref.omega) / ref.omega,
                    "coeff_error": _coeff_error(s.coeffs, ref.coeffs),
                    "multiplier_error": _match_error(s.multipliers, ref.multipliers),
                }
            rows.append({
                "knob": knob, "value": float(value), "N": int(kw["N"]),
                "samples": s.samples, "tol": float(kw["tol"]), "rtol": float(kw["rtol"]),
                "status": s.status, "iterations": s.iterations,
                "floquet_steps": s.floquet_steps, "seconds": statistics.median(times),
                **errors,
                "trivial_error": s.trivial_error, "tail": s.tail if ok else None,
                "closure": s.closure, "separation_error": s.separation_error,
                "stability": s.stability,
                "verdict_ok": (s.stability == ref.stability)
                if ok and "undetermined" not in (s.stability, ref.stability) else None,
                "reference_closure": closure,
            })
            bar.update()
    return pl.DataFrame(rows)


def plot_accuracy_cost(df: pl.DataFrame, *, error: str = "multiplier_error", ax: Any = None,
                       title: str | None = None) -> Any:
    """Error against time, one curve per knob, with the Pareto front of all settings."""
    from ._style import pyplot

    if ax is None:
        _, ax = pyplot().subplots(figsize=(6.5, 4.5))
    ok = df.filter(pl.col(error).is_not_null() & (pl.col(error) > 0))
    for knob, mark in (("N", "o-"), ("samples", "s-"), ("tol", "^-"), ("rtol", "v-"),
                       ("magnus", "D-")):
        part = ok.filter(pl.col("knob") == knob).sort("value")
        if part.height:
            label = {"rtol": "rtol (RK45)", "magnus": "rtol (Magnus)"}.get(knob, knob)
            ax.loglog(part["seconds"] * 1e3, part[error], mark, ms=4, label=label)
            if knob == "N":
                for n, sx, e in part.select("N", "seconds", error).iter_rows():
                    ax.annotate(f"N={n}", (sx * 1e3, e), fontsize=6, xytext=(3, 3),
                                textcoords="offset points")
    front = ok.sort("seconds").with_columns(pl.col(error).cum_min().alias("_front"))
    front = front.filter(pl.col(error) == pl.col("_front"))
    ax.loglog(front["seconds"] * 1e3, front[error], "k:", lw=1, label="Pareto front")
    ax.set_xlabel("time per point (ms): harmonic balance + Floquet")
    ax.set_ylabel(error.replace("_", " "))
    ax.set_title(title or "accuracy against cost")
    ax.legend(fontsize=7)
    return ax
