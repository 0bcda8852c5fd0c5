"""Calibration: the model parameters a rig has, fitted to what it measured.

:func:`calibrate` fits chosen parameters of a :class:`~ballbal.Balancer` (``zeta_b``,
``zeta``, ``mu``, ``delta``, ``eta``, and the rig's natural frequency
``natural_frequency_rpm``) to the per-step features of a measured stepped sweep
(:meth:`ballbal.rig.Record.features`), with the model as the forward model and
nonlinear least squares (scipy's trust-region reflective ``least_squares``).

What is fitted:

- ``main_frequency`` (:func:`calibrate`): at every step whose motion was
  non-synchronous (the balls chasing round the track), the frequency of the model's
  largest ground-frame acceleration line of its periodic solution of ``pattern``
  (default ``"R-R"``) at that speed, against
  the measured main frequency. Each step's solution starts from the same step's
  solution at the previous parameters, so that the fit follows one branch.
- a transition speed (:func:`calibrate_transition`): the speed at which the balls
  stopped chasing round the track in a sweep up, against the model's
  :func:`stable_band_end`, the largest speed at which the model has a stable chasing
  motion; one parameter is solved for, and the interval is the speeds' uncertainty
  carried through the model.

The uncertainty is the classical one of nonlinear least squares: the residuals' scale
``s^2 = RSS / (m - p)`` (``m`` measurements, ``p`` parameters), the covariance ``s^2
(J^T J)^-1`` at the optimum, and Student's ``t`` with ``m - p`` degrees of freedom for
the interval. A parameter is *undetermined* by the data where its column of ``J`` is
(nearly) a combination of the others' (its singular direction, relative to the
largest, below 1e-8) or where the interval is wider than the parameter's value: the
estimate is then reported with ``determined = False``.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import polars as pl

from . import _check
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer
from .options import Floquet, HarmonicBalance, PeriodicOptions
from .rig import Record

__all__ = ["Calibration", "calibrate", "CALIBRATABLE", "stable_band_end", "Transition",
           "calibrate_transition"]

#: Parameters :func:`calibrate` can fit, with the range each is kept in.
CALIBRATABLE: dict[str, tuple[float, float]] = {
    "zeta_b": (1e-6, 10.0), "zeta": (1e-6, 10.0), "mu": (1e-6, 0.99),
    "delta": (1.0, 1e4), "eta": (1e-3, 100.0), "natural_frequency_rpm": (1.0, 1e6),
}
# The main frequency needs the orbit, not its multipliers.
_DEFAULT_OPTIONS = PeriodicOptions(harmonic_balance=HarmonicBalance(N=8),
                                   floquet=Floquet(monodromy=False, hill=False))


@dataclass(frozen=True, repr=False, eq=False)
class Calibration:
    """What :func:`calibrate` found.

    ``model``: the balancer with the fitted values; ``natural_frequency_rpm``: the
    natural frequency used (fitted when asked). ``estimates``: one row per free
    parameter (``parameter``, ``value``, ``std_error``, ``ci_low``, ``ci_high`` at
    ``level``, ``determined``). ``residuals``: one row per measured value used
    (``step``, ``speed_rpm``, ``quantity``, ``measured``, ``model``, ``residual``).
    ``dof``: degrees of freedom ``m - p``; ``scale``: the residuals' standard deviation
    ``s``; ``evaluations``: forward-model evaluations; ``message``: the optimiser's.
    """

    model: Balancer
    natural_frequency_rpm: float
    estimates: pl.DataFrame
    residuals: pl.DataFrame
    level: float
    dof: int
    scale: float
    evaluations: int
    message: str
    extra: dict[str, Any] = field(default_factory=dict)

    def __repr__(self) -> str:
        parts = []
        for r in self.estimates.iter_rows(named=True):
            flag = "" if r["determined"] else " (undetermined)"
            parts.append(f"{r['parameter']}={r['value']:.5g}±{r['std_error']:.2g}{flag}")
        return (f"Calibration({', '.join(parts)}; {self.residuals.height} points, "
                f"residual s={self.scale:.3g})")

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{html.escape(r['parameter'])}</td><td>{r['value']:.6g}</td>"
            f"<td>{r['std_error']:.3g}</td><td>[{r['ci_low']:.6g}, {r['ci_high']:.6g}]</td>"
            f"<td>{'yes' if r['determined'] else 'no'}</td></tr>"
            for r in self.estimates.iter_rows(named=True))
        return (f"<b>Calibration</b> on {self.residuals.height} measured values, "
                f"{self.dof} degrees of freedom, residual s = {self.scale:.4g}"
                f"<table><tr><th>parameter</th><th>estimate</th><th>std. error</th>"
                f"<th>{100 * self.level:.0f} % interval</th><th>determined</th></tr>"
                f"{rows}</table>")

    def plot(self, ax: Any = None) -> Any:
        """Measured against model, quantity by quantity, over the speed; returns the
        figure."""
        from .plot import _pyplot

        plt = _pyplot()
        if ax is None:
            fig, ax = plt.subplots(figsize=(5.5, 3.5), constrained_layout=True)
        else:
            fig = ax.figure
        r = self.residuals.sort("speed_rpm")
        ax.plot(r["speed_rpm"], r["measured"], "o", ms=4, label="measured")
        ax.plot(r["speed_rpm"], r["model"], "-", lw=1.2, label="model (fitted)")
        ax.set_xlabel("speed (rpm)")
        ax.set_ylabel("main frequency (rpm)")
        text = ", ".join(f"{p} = {v:.4g} ± {e:.2g}" for p, v, e in zip(
            self.estimates["parameter"], self.estimates["value"],
            self.estimates["std_error"], strict=True))
        ax.set_title(text, fontsize=9)
        ax.legend(frameon=False)
        return fig


def _balancer(model: Any) -> None:
    if not isinstance(model, Balancer):
        raise ParameterTypeError("model", "calibration works on a ballbal.Balancer, got "
                                 f"{type(model).__name__}", value=model)


def _features(source: Any) -> pl.DataFrame:
    if isinstance(source, Record):
        return source.features()
    if not isinstance(source, pl.DataFrame):
        raise ParameterTypeError("features", "must be a ballbal.rig.Record or the table of "
                                 f"Record.features(), got {type(source).__name__}",
                                 value=source)
    need = {"speed_rpm", "status", "main_frequency_rpm", "synchronous"}
    missing = need - set(source.columns)
    if missing:
        raise ParameterError("features", f"the table lacks the columns {sorted(missing)} "
                             "(give Record.features()'s table)")
    return source


def calibrate(
    model: Balancer,
    features: Any,
    free: Sequence[str],
    *,
    natural_frequency_rpm: float,
    pattern: str = "R-R",
    start: dict[str, float] | None = None,
    level: float = 0.95,
    options: PeriodicOptions | None = None,
) -> Calibration:
    """Fit the parameters ``free`` of ``model`` to a measured sweep's ``features`` (a
    :class:`~ballbal.rig.Record` or its :meth:`~ballbal.rig.Record.features` table).

    ``free``: names from :data:`CALIBRATABLE`; ``eta`` moves every ball's ``eta``
    together. ``natural_frequency_rpm``: the rig's natural frequency (the speed scale
    ``Omega = speed / f_n``; its starting value when it is free). ``start``: starting
    values (default: the model's). ``pattern``: the motion the non-synchronous steps are
    fitted with. ``options``: the :class:`~ballbal.PeriodicOptions` of the forward model
    (default ``N = 8`` harmonics, no multipliers). ``level``: the intervals' confidence level.

    Raises :class:`~ballbal.exceptions.ParameterError` for an unknown or repeated free
    parameter, fewer usable steps than free parameters plus one, and a forward model
    that finds no solution at a step (naming the step).
    """
    from scipy import optimize, stats

    from .analysis import periodic
    from .spectrum import line_spectrum

    _balancer(model)
    ft = _features(features)
    names = [_check.string("free", f) for f in _check.sequence("free", free)]
    for f in names:
        if f not in CALIBRATABLE:
            raise ParameterError("free", f"{f!r:.40} cannot be calibrated; choose from "
                                 f"{', '.join(CALIBRATABLE)}", allowed=", ".join(CALIBRATABLE))
    if len(set(names)) != len(names):
        raise ParameterError("free", f"a parameter is named twice: {names}")
    fn0 = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                      lo_open=True, hi_open=True)
    lvl = _check.real("level", level, 0.5, 1.0, hi_open=True)
    opts = _check.option("options", options, PeriodicOptions, _DEFAULT_OPTIONS,
                         "ballbal.PeriodicOptions")
    starts = dict(start or {})
    for k in starts:
        if k not in names:
            raise ParameterError("start", f"{k!r:.40} is not a free parameter ({names})")

    use = ft.filter((pl.col("status") == "ok") & pl.col("synchronous").not_())
    if use.height < len(names) + 1:
        raise ParameterError("features", f"{use.height} non-synchronous steps measured; "
                             f"fitting {len(names)} parameters needs at least {len(names) + 1}")
    speeds = use["speed_rpm"].to_numpy()
    measured = use["main_frequency_rpm"].to_numpy()
    steps = use["step"].to_list() if "step" in use.columns else list(range(use.height))

    def value0(name: str) -> float:
        if name in starts:
            return float(starts[name])
        if name == "natural_frequency_rpm":
            return fn0
        if name == "eta":
            return float(np.mean(model.eta))
        return float(np.mean(getattr(model, name)))

    x0 = np.array([value0(n) for n in names])
    lo = np.array([CALIBRATABLE[n][0] for n in names])
    hi = np.array([CALIBRATABLE[n][1] for n in names])
    for n, v, a, b in zip(names, x0, lo, hi, strict=True):
        if not a <= v <= b:
            raise ParameterError(n, f"start value {v} outside [{a}, {b}]", allowed=f"[{a}, {b}]")
    guesses: dict[int, Any] = {}
    count = [0]

    def at(x: np.ndarray) -> tuple[Balancer, float]:
        changes: dict[str, Any] = {}
        fn = fn0
        for n, v in zip(names, x, strict=True):
            if n == "natural_frequency_rpm":
                fn = float(v)
            else:
                changes[n] = float(v)
        return model.replace(**changes), fn

    def forward(x: np.ndarray) -> np.ndarray:
        count[0] += 1
        b, fn = at(x)
        out = np.empty(speeds.size)
        for i, sp in enumerate(speeds):
            sol = periodic(b.replace(Omega=float(sp / fn)), pattern, options=opts,
                           guess=guesses.get(i))
            if sol.status != "converged":
                sol = periodic(b.replace(Omega=float(sp / fn)), pattern, options=opts)
            if sol.status != "converged":
                raise ParameterError("features", f"the model has no {pattern} solution at "
                                     f"step {steps[i]} ({sp:.1f} rpm, Omega "
                                     f"{sp / fn:.4f}): {sol.status}")
            guesses[i] = sol
            lines = line_spectrum(sol, "acceleration")
            out[i] = abs(float(lines.sort("amplitude", descending=True)["frequency"][0])) * fn
        return out

    res = optimize.least_squares(lambda x: forward(x) - measured, x0, bounds=(lo, hi),
                                 x_scale=np.abs(x0), diff_step=1e-6, method="trf")
    m, p = speeds.size, len(names)
    dof = m - p
    rss = float(np.sum(res.fun**2))
    s = math.sqrt(rss / dof)
    J = res.jac
    sv = np.linalg.svd(J * np.abs(res.x), compute_uv=False)
    rank_ok = sv.size and sv[-1] > 1e-8 * sv[0]
    if rank_ok:
        cov = s**2 * np.linalg.inv(J.T @ J)
        se = np.sqrt(np.diag(cov))
    else:
        se = np.full(p, np.inf)
    tq = float(stats.t.ppf(0.5 + lvl / 2, dof))
    rows = []
    for n, v, e in zip(names, res.x, se, strict=True):
        rows.append({"parameter": n, "value": float(v), "std_error": float(e),
                     "ci_low": float(v - tq * e), "ci_high": float(v + tq * e),
                     "determined": bool(rank_ok and math.isfinite(e) and tq * e < abs(v))})
    fitted, fn = at(res.x)
    model_values = res.fun + measured
    resid = pl.DataFrame({"step": pl.Series(steps, dtype=pl.Int64), "speed_rpm": speeds,
                          "quantity": ["main_frequency_rpm"] * m, "measured": measured,
                          "model": model_values, "residual": res.fun})
    return Calibration(model=fitted, natural_frequency_rpm=fn,
                       estimates=pl.DataFrame(rows), residuals=resid, level=lvl, dof=dof,
                       scale=s, evaluations=count[0], message=str(res.message))


def stable_band_end(model: Balancer, pattern: str = "R-R", *,
                    Omega: Any = (1.0, 2.5, 0.01), refine: int = 12) -> float | None:
    """The largest speed ``Omega`` (the model's, a ratio to the natural frequency) in the
    grid ``Omega`` at which ``model`` has a stable motion of ``pattern``, from a speed
    scan (:func:`ballbal.scan`), refined between that grid point and the next by
    ``refine`` bisections of :func:`ballbal.periodic` continued from the stable side.
    ``None`` when no grid point has one. The end of the chasing band in a sweep up: past
    it the balls leave the chasing motion (for the perfect balance where it is
    stable)."""
    from .analysis import periodic
    from .scan import scan

    _balancer(model)
    n_refine = _check.integer("refine", refine, 0, 60)
    df = scan(model, Omega=Omega, patterns=[pattern])
    st = df.filter(pl.col("stability") == "stable")
    if st.height == 0:
        return None
    grid = np.unique(df["Omega"].to_numpy())
    hi_k = int(np.searchsorted(grid, st["Omega"].to_numpy().max()))
    lo = float(grid[hi_k])
    if hi_k + 1 >= grid.size or n_refine == 0:
        return lo
    hi = float(grid[hi_k + 1])
    opts = PeriodicOptions(harmonic_balance=HarmonicBalance(N=8))
    last = periodic(model.replace(Omega=lo), pattern, options=opts)
    if last.stability != "stable":
        return lo
    for _ in range(n_refine):
        mid = 0.5 * (lo + hi)
        s = periodic(model.replace(Omega=mid), pattern, options=opts, guess=last)
        if s.status == "converged" and s.stability == "stable":
            lo, last = mid, s
        else:
            hi = mid
    return lo


@dataclass(frozen=True, repr=False)
class Transition:
    """What :func:`calibrate_transition` found: ``value`` of ``parameter`` at which the
    model's stable band ends at the measured ``speed_rpm``, and ``low``/``high`` at the
    speeds ``speed_rpm -+ uncertainty_rpm`` (``None`` where the band cannot end there
    for any value in ``bracket``); ``status`` is ``"ok"`` or ``"unreachable"`` (then
    ``value`` is None and ``reach_rpm`` gives the band ends at the bracket's ends). No
    ``plot``: one value and its interval, all in its summary."""

    parameter: str
    speed_rpm: float
    uncertainty_rpm: float
    value: float | None
    low: float | None
    high: float | None
    status: str
    reach_rpm: tuple[float | None, float | None]

    def __repr__(self) -> str:
        if self.value is None:
            return (f"Transition({self.parameter}: {self.speed_rpm:.0f} rpm {self.status}; "
                    f"the band ends at {self.reach_rpm} rpm over the bracket)")
        return (f"Transition({self.parameter}={self.value:.4g} "
                f"[{self.low if self.low is not None else float('nan'):.4g}, "
                f"{self.high if self.high is not None else float('nan'):.4g}] "
                f"for {self.speed_rpm:.0f} ± {self.uncertainty_rpm:g} rpm)")

    def _repr_html_(self) -> str:
        from ._style import html_table

        return html_table(f"Transition of {self.parameter}", [
            ("speed (rpm)", f"{self.speed_rpm:.0f} ± {self.uncertainty_rpm:g}"),
            ("status", self.status), (self.parameter, self.value), ("low", self.low),
            ("high", self.high)])


def calibrate_transition(
    model: Balancer,
    speed_rpm: float,
    *,
    parameter: str = "zeta_b",
    natural_frequency_rpm: float,
    uncertainty_rpm: float = 0.0,
    bracket: tuple[float, float] = (0.005, 0.5),
    pattern: str = "R-R",
    Omega: Any = (1.0, 2.5, 0.01),  # noqa: N803 - the model's symbol
) -> Transition:
    """The value of ``parameter`` at which ``model``'s stable ``pattern`` band ends
    (:func:`stable_band_end`) at the measured transition speed ``speed_rpm``, solved by
    Brent's method over ``bracket``; with ``uncertainty_rpm``, the values at the speeds
    either side too (the interval). The band's end must change monotonically over the
    bracket for the answer to be unique: the function checks the ends' order."""
    from scipy import optimize

    _balancer(model)
    _check.string("parameter", parameter)
    if parameter not in CALIBRATABLE or parameter == "natural_frequency_rpm":
        allowed = ", ".join(k for k in CALIBRATABLE if k != "natural_frequency_rpm")
        raise ParameterError("parameter", f"{parameter!r:.40} cannot be solved for; choose "
                             f"from {allowed}", allowed=allowed)
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                     lo_open=True, hi_open=True)
    sp = _check.real("speed_rpm", speed_rpm, 0.0, math.inf, lo_open=True, hi_open=True)
    du = _check.real("uncertainty_rpm", uncertainty_rpm, 0.0, sp, hi_open=True)
    a, b = (_check.real("bracket", v, *CALIBRATABLE[parameter]) for v in bracket)
    if not a < b:
        raise ParameterError("bracket", f"must be (low, high) with low < high, got {bracket}")
    cache: dict[float, float] = {}

    def end_rpm(v: float) -> float:
        if v not in cache:
            e = stable_band_end(model.replace(**{parameter: v}), pattern, Omega=Omega)
            cache[v] = -math.inf if e is None else e * fn
        return cache[v]

    ea, eb = end_rpm(a), end_rpm(b)
    reach = (None if ea == -math.inf else ea, None if eb == -math.inf else eb)

    def solve(target: float) -> float | None:
        if not min(ea, eb) <= target <= max(ea, eb):
            return None
        return float(optimize.brentq(lambda v: end_rpm(v) - target, a, b, xtol=1e-5))

    value = solve(sp)
    if value is None:
        return Transition(parameter, sp, du, None, None, None, "unreachable", reach)
    ends = [solve(sp - du), solve(sp + du)] if du > 0 else [value, value]
    known = [e for e in ends if e is not None]
    low = min(known) if len(known) == 2 else None
    high = max(known) if len(known) == 2 else None
    return Transition(parameter, sp, du, value, low, high, "ok", reach)
