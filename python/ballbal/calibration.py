"""Calibration: the model parameters a rig has, fitted to what it measured.

:func:`calibrate` fits chosen parameters of a :class:`~ballbal.Balancer` (``zeta_b``,
``zeta``, ``mu``, ``delta``, ``eta``, the rig's natural frequency
``natural_frequency_rpm`` and the sensor's scale ``sensor_scale``) to the per-step
features of a measured stepped sweep (:meth:`ballbal.rig.Record.features`), with the
model as the forward model and nonlinear least squares (scipy's trust-region reflective
``least_squares``).

What is fitted:

- ``main_frequency`` (:func:`calibrate`): at every step whose motion was
  non-synchronous (the balls chasing round the track), the frequency of the model's
  largest ground-frame acceleration line of its periodic solution of ``pattern``
  (default ``"R-R"``) at that speed, against
  the measured main frequency. Each step's solution starts from the same step's
  solution at the previous parameters, so that the fit follows one branch.
- ``main_amplitude`` (:func:`calibrate` with ``fit`` holding it): at the same steps,
  the amplitude of that largest line, the model's (in ``e w_n^2``) times the sensor
  scale (``sensor_scale``: given, or free), against the measured main line's amplitude
  in the sensor's unit (:meth:`ballbal.rig.Record.features`' ``main_amplitude``). The
  scale multiplies every model amplitude alike, so a parameter that does too (a
  capacity ``eta`` that scales the chasing balls' force, say) cannot be told apart
  from it by amplitudes alone: ``confounded_with`` in the estimates says so.
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
from ._style import Summarised
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer
from .options import Floquet, HarmonicBalance, PeriodicOptions
from .rig import Record

__all__ = ["Calibration", "calibrate", "CALIBRATABLE", "stable_band_end", "Transition",
           "calibrate_transition", "OilTransfer", "transfer_oils"]

#: Parameters :func:`calibrate` can fit, with the range each is kept in.
CALIBRATABLE: dict[str, tuple[float, float]] = {
    "zeta_b": (1e-6, 10.0), "zeta": (1e-6, 10.0), "mu": (1e-6, 0.99),
    "delta": (1.0, 1e4), "eta": (1e-3, 100.0), "natural_frequency_rpm": (1.0, 1e6),
    "sensor_scale": (1e-12, 1e12),
}
#: What :func:`calibrate` fits at the non-synchronous steps.
_FITTED = ("main_frequency", "main_amplitude")
#: Correlation of two estimates beyond which the data cannot tell them apart.
_CONFOUNDED = 0.99
# The main frequency needs the orbit, not its multipliers.
_DEFAULT_OPTIONS = PeriodicOptions(harmonic_balance=HarmonicBalance(N=8),
                                   floquet=Floquet(monodromy=False, hill=False))


@dataclass(frozen=True, repr=False, eq=False)
class Calibration:
    """What :func:`calibrate` found.

    ``model``: the balancer with the fitted values; ``natural_frequency_rpm``: the
    natural frequency used (fitted when asked). ``estimates``: one row per free
    parameter (``parameter``, ``value``, ``std_error``, ``ci_low``, ``ci_high`` at
    ``level``, ``determined``, ``confounded_with``: the free parameters whose estimates
    correlate with this one's beyond 0.99, which the data cannot tell apart from it,
    or null). ``residuals``: one row per measured value used
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

    def plot(self, ax: Any = None, quantity: str | None = None) -> Any:
        """Measured against model over the speed for ``quantity`` (a value of the
        residuals' ``quantity`` column; default the first fitted); returns the
        figure."""
        from .plot import _pyplot

        plt = _pyplot()
        if ax is None:
            fig, ax = plt.subplots(figsize=(5.5, 3.5), constrained_layout=True)
        else:
            fig = ax.figure
        known = list(dict.fromkeys(self.residuals["quantity"].to_list()))
        q = known[0] if quantity is None else quantity
        if q not in known:
            raise ParameterError("quantity", f"{q!r:.40} was not fitted; choose from "
                                 f"{', '.join(known)}", allowed=", ".join(known))
        r = self.residuals.filter(pl.col("quantity") == q).sort("speed_rpm")
        ax.plot(r["speed_rpm"], r["measured"], "o", ms=4, label="measured")
        ax.plot(r["speed_rpm"], r["model"], "-", lw=1.2, label="model (fitted)")
        ax.set_xlabel("speed (rpm)")
        ax.set_ylabel("main frequency (rpm)" if q == "main_frequency_rpm"
                      else "main line amplitude (sensor unit)")
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
    fit: Sequence[str] = ("main_frequency",),
    sensor_scale: float | None = None,
    pattern: str = "R-R",
    start: dict[str, float] | None = None,
    level: float = 0.95,
    options: PeriodicOptions | None = None,
) -> Calibration:
    """Fit the parameters ``free`` of ``model`` to a measured sweep's ``features`` (a
    :class:`~ballbal.rig.Record` or its :meth:`~ballbal.rig.Record.features` table).

    ``free``: names from :data:`CALIBRATABLE`; ``eta`` moves every ball's ``eta``
    together; ``sensor_scale`` is the measured amplitude (in the features' ``unit``)
    per model unit (``e``, ``e w_n`` or ``e w_n^2``). ``fit``: what is fitted at the
    non-synchronous steps: ``"main_frequency"`` and/or ``"main_amplitude"`` (the
    largest line's amplitude, model times the sensor scale: ``sensor_scale`` given, or
    free). With both, each quantity's residuals are weighted by their own scatter
    (estimated from a first fit, then the fit repeated). ``natural_frequency_rpm``: the
    rig's natural frequency (the speed scale ``Omega = speed / f_n``; its starting
    value when it is free). ``start``: starting values (default: the model's; a free
    ``sensor_scale`` starts at the least-squares scale of the starting model).
    ``pattern``: the motion the non-synchronous steps are fitted with. ``options``: the
    :class:`~ballbal.PeriodicOptions` of the forward model (default ``N = 8``
    harmonics, no multipliers). ``level``: the intervals' confidence level.

    Raises :class:`~ballbal.exceptions.ParameterError` for an unknown or repeated free
    parameter or fitted quantity, a sensor scale neither given nor free where the
    amplitude is fitted, fewer usable values than free parameters plus one, and a
    forward model that finds no solution at a step (naming the step).
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
    quantities = [_check.string("fit", q) for q in _check.sequence("fit", fit)]
    if not quantities or len(set(quantities)) != len(quantities) or any(
            q not in _FITTED for q in quantities):
        raise ParameterError("fit", f"must name each of {', '.join(_FITTED)} at most once "
                             f"(at least one), got {quantities}", allowed=", ".join(_FITTED))
    fits_amp = "main_amplitude" in quantities
    if "sensor_scale" in names and not fits_amp:
        raise ParameterError("free", "sensor_scale is free but only the main frequency is "
                             "fitted, which it does not change: add 'main_amplitude' to fit")
    scale0: float | None = None
    if sensor_scale is not None:
        scale0 = _check.real("sensor_scale", sensor_scale, *CALIBRATABLE["sensor_scale"])
    elif fits_amp and "sensor_scale" not in names:
        raise ParameterError("sensor_scale", "fitting main_amplitude needs the sensor scale: "
                             "give it, or free it (free=[..., 'sensor_scale'])")
    fn0 = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                      lo_open=True, hi_open=True)
    lvl = _check.real("level", level, 0.5, 1.0, hi_open=True)
    opts = _check.option("options", options, PeriodicOptions, _DEFAULT_OPTIONS,
                         "ballbal.PeriodicOptions")
    starts = dict(start or {})
    for k in starts:
        if k not in names:
            raise ParameterError("start", f"{k!r:.40} is not a free parameter ({names})")
    if fits_amp and "main_amplitude" not in ft.columns:
        raise ParameterError("features", "the table lacks the column 'main_amplitude' "
                             "(give Record.features()'s table)")

    use = ft.filter((pl.col("status") == "ok") & pl.col("synchronous").not_())
    n_values = use.height * len(quantities)
    if n_values < len(names) + 1:
        raise ParameterError("features", f"{use.height} non-synchronous steps measured "
                             f"({n_values} values); fitting {len(names)} parameters needs "
                             f"at least {len(names) + 1} values")
    speeds = use["speed_rpm"].to_numpy()
    measured_q = {"main_frequency": use["main_frequency_rpm"].to_numpy()}
    if fits_amp:
        measured_q["main_amplitude"] = use["main_amplitude"].to_numpy()
    measured = np.concatenate([measured_q[q] for q in quantities])
    steps = use["step"].to_list() if "step" in use.columns else list(range(use.height))
    guesses: dict[int, Any] = {}
    count = [0]

    def at(x: np.ndarray) -> tuple[Balancer, float, float | None]:
        changes: dict[str, Any] = {}
        fn, scale = fn0, scale0
        for n, v in zip(names, x, strict=True):
            if n == "natural_frequency_rpm":
                fn = float(v)
            elif n == "sensor_scale":
                scale = float(v)
            else:
                changes[n] = float(v)
        return model.replace(**changes), fn, scale

    def lines_at(b: Balancer, fn: float) -> tuple[np.ndarray, np.ndarray]:
        """The main line's frequency (rpm) and amplitude (model units) per step."""
        count[0] += 1
        freq, amp = np.empty(speeds.size), np.empty(speeds.size)
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
            top = line_spectrum(sol, "acceleration").sort("amplitude", descending=True)
            freq[i] = abs(float(top["frequency"][0])) * fn
            amp[i] = float(top["amplitude"][0])
        return freq, amp

    def forward(x: np.ndarray) -> np.ndarray:
        b, fn, scale = at(x)
        freq, amp = lines_at(b, fn)
        got = {"main_frequency": freq}
        if fits_amp:
            got["main_amplitude"] = amp * (1.0 if scale is None else scale)
        return np.concatenate([got[q] for q in quantities])

    def value0(name: str) -> float:
        if name in starts:
            return float(starts[name])
        if name == "natural_frequency_rpm":
            return fn0
        if name == "sensor_scale":
            # the starting model's least-squares scale: measured ~ scale * model
            _, amp = lines_at(*at_start()[:2])
            m_amp = measured_q["main_amplitude"]
            return float(np.dot(amp, m_amp) / np.dot(amp, amp))
        if name == "eta":
            return float(np.mean(model.eta))
        return float(np.mean(getattr(model, name)))

    def at_start() -> tuple[Balancer, float, float | None]:
        others = {n: v for n, v in starts.items() if n != "sensor_scale"}
        b = model.replace(**{k: v for k, v in others.items()
                             if k != "natural_frequency_rpm"})
        return b, float(others.get("natural_frequency_rpm", fn0)), None

    x0 = np.array([value0(n) for n in names])
    lo = np.array([CALIBRATABLE[n][0] for n in names])
    hi = np.array([CALIBRATABLE[n][1] for n in names])
    for n, v, a, b in zip(names, x0, lo, hi, strict=True):
        if not a <= v <= b:
            raise ParameterError(n, f"start value {v} outside [{a}, {b}]", allowed=f"[{a}, {b}]")
    weight = np.ones(measured.size)

    def solve(x_start: np.ndarray) -> Any:
        return optimize.least_squares(lambda x: (forward(x) - measured) * weight, x_start,
                                      bounds=(lo, hi), x_scale=np.abs(x_start),
                                      diff_step=1e-6, method="trf")

    res = solve(x0)
    m, p = measured.size, len(names)
    dof = m - p
    if len(quantities) > 1:
        # Each quantity in its own unit: weigh it by its scatter about the first fit
        # (its share of the degrees of freedom), and fit again from there.
        parts = np.split(res.fun, len(quantities))
        for qi, part in enumerate(parts):
            share = max(part.size * dof / m, 1.0)
            sd = math.sqrt(float(np.sum(part**2)) / share)
            weight[qi * speeds.size:(qi + 1) * speeds.size] = 1.0 / sd if sd > 0 else 1.0
        res = solve(res.x)
    rss = float(np.sum(res.fun**2))
    s = math.sqrt(rss / dof)
    J = res.jac
    sv = np.linalg.svd(J * np.abs(res.x), compute_uv=False)
    rank_ok = bool(sv.size and sv[-1] > 1e-8 * sv[0])
    corr = np.full((p, p), np.nan)
    if rank_ok:
        cov = s**2 * np.linalg.inv(J.T @ J)
        se = np.sqrt(np.diag(cov))
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(se, se)
    else:
        se = np.full(p, np.inf)
    tq = float(stats.t.ppf(0.5 + lvl / 2, dof))
    rows = []
    for j, (n, v, e) in enumerate(zip(names, res.x, se, strict=True)):
        # the data tell the two apart only through the difference of their effects
        twins = [names[k] for k in range(p) if k != j and
                 (not rank_ok or abs(corr[j, k]) > _CONFOUNDED)]
        rows.append({"parameter": n, "value": float(v), "std_error": float(e),
                     "ci_low": float(v - tq * e), "ci_high": float(v + tq * e),
                     "determined": bool(rank_ok and math.isfinite(e) and tq * e < abs(v)),
                     "confounded_with": ", ".join(twins) or None})
    fitted, fn, _ = at(res.x)
    model_values = res.fun / weight + measured
    labels = {"main_frequency": "main_frequency_rpm", "main_amplitude": "main_amplitude"}
    resid = pl.DataFrame({"step": pl.Series(steps * len(quantities), dtype=pl.Int64),
                          "speed_rpm": np.tile(speeds, len(quantities)),
                          "quantity": [labels[q] for q in quantities for _ in speeds],
                          "measured": measured, "model": model_values,
                          "residual": model_values - measured})
    schema = {"parameter": pl.String, "value": pl.Float64, "std_error": pl.Float64,
              "ci_low": pl.Float64, "ci_high": pl.Float64, "determined": pl.Boolean,
              "confounded_with": pl.String}
    return Calibration(model=fitted, natural_frequency_rpm=fn,
                       estimates=pl.DataFrame(rows, schema=schema), residuals=resid,
                       level=lvl, dof=dof, scale=s, evaluations=count[0],
                       message=str(res.message))


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


# --- one calibration, many oils: the viscosity -> zeta_b law put to the test -----------

#: Most cases (oils, pads) :func:`transfer_oils` takes (each a few band-end searches).
MAX_OIL_CASES = 50


@dataclass(frozen=True, repr=False)
class OilTransfer(Summarised):
    """What :func:`transfer_oils` found. ``geometric_factor``: ``kappa`` of
    :func:`ballbal.oil.track_damping`, from the reference case's calibrated ``zeta_b``;
    ``reference``: that case's row. ``table``: one row per case: ``case``,
    ``viscosity_cP``, ``natural_frequency_rpm``, ``zeta``, ``measured_rpm``,
    ``calibrated_zeta_b`` (the ``zeta_b`` that puts the model's band end at the measured
    speed, :func:`calibrate_transition`; null where no ``zeta_b`` in the bracket does),
    ``calibrated_low`` / ``calibrated_high`` (at the measured speed -+ its uncertainty),
    ``status`` (``"ok"`` or ``"unreachable"``), ``law_zeta_b`` (the law's prediction
    with the reference's ``kappa``), ``ratio`` (calibrated over predicted, 1 where the
    law transfers), ``predicted_rpm`` (the model's band end at the law's ``zeta_b``;
    null where the model has no stable chasing band) and ``residual_rpm`` (predicted
    minus measured)."""

    table: pl.DataFrame
    geometric_factor: float
    reference: int

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        t = self.table
        res = [r for r in t["residual_rpm"].to_list() if r is not None]
        worst = max((abs(r) for r in res), default=float("nan"))
        head = (f"OilTransfer(kappa={self.geometric_factor:.4g} from "
                f"{t['case'][self.reference]!r}; {t.height} cases, worst residual "
                f"{worst:.0f} rpm)")
        rows: list[tuple[str, Any]] = [("geometric factor kappa", self.geometric_factor)]
        for r in t.iter_rows(named=True):
            pred = "-" if r["predicted_rpm"] is None else f"{r['predicted_rpm']:.0f}"
            rows.append((f"{r['case']}: measured / predicted rpm",
                         f"{r['measured_rpm']:.0f} / {pred}"))
        return head, rows

    def plot(self, ax: Any = None) -> Any:
        """Calibrated and predicted ``zeta_b`` against the viscosity (left axis), case by
        case; returns the axes."""
        from ._style import new_axes

        ax = new_axes(ax)
        t = self.table
        ax.plot(t["viscosity_cP"], t["law_zeta_b"], "s", mfc="none", label="law (predicted)")
        ok = t.filter(pl.col("calibrated_zeta_b").is_not_null())
        lo = (ok["calibrated_zeta_b"] - ok["calibrated_low"].fill_null(ok["calibrated_zeta_b"]))
        hi = (ok["calibrated_high"].fill_null(ok["calibrated_zeta_b"]) - ok["calibrated_zeta_b"])
        ax.errorbar(ok["viscosity_cP"], ok["calibrated_zeta_b"],
                    yerr=[lo.abs().to_numpy(), hi.abs().to_numpy()], fmt="o",
                    label="calibrated from the transition")
        for r in t.iter_rows(named=True):
            ax.annotate(r["case"], (r["viscosity_cP"], r["law_zeta_b"]), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel("oil viscosity (cP)")
        ax.set_ylabel("zeta_b")
        ax.legend(frameon=False)
        return ax


def transfer_oils(
    model: Balancer,
    cases: pl.DataFrame,
    *,
    reference: int,
    ball_radius: float,
    ball_mass: float,
    channel_radius: float | None = None,
    bracket: tuple[float, float] = (0.01, 1.0),
    pattern: str = "R-R",
    Omega: Any = (1.0, 2.5, 0.01),  # noqa: N803 - the model's symbol
) -> OilTransfer:
    """Calibrate the viscosity -> ``zeta_b`` law (:mod:`ballbal.oil`) on one measured
    transition and transfer it to the others.

    ``cases``: one row per experiment, with columns ``case`` (a name),
    ``viscosity_cP``, ``speed_rpm`` (where a sweep up left the chasing motion),
    ``natural_frequency_rpm`` (the rig's, which the law's ``zeta_b`` depends on), and
    optionally ``zeta`` (the support's damping in that experiment, default the
    model's) and ``uncertainty_rpm`` (default 0). ``reference``: the row whose
    calibrated ``zeta_b`` fixes the geometric factor. Per case, ``zeta_b`` is calibrated
    (:func:`calibrate_transition` over ``bracket``) and predicted by the law, and the
    model's band end at the predicted ``zeta_b`` (:func:`stable_band_end`) is compared
    with the measured speed. The ball's ``ball_radius`` [m], ``ball_mass`` [kg] and the
    track's ``channel_radius`` [m] (half its width; None: no wall factor) go to
    :func:`ballbal.oil.track_damping`. At most :data:`MAX_OIL_CASES` cases."""
    from .oil import CENTIPOISE, geometric_factor, track_damping

    _balancer(model)
    if not isinstance(cases, pl.DataFrame):
        raise ParameterTypeError("cases", f"must be a polars DataFrame, got "
                                 f"{type(cases).__name__}", value=cases)
    need = {"case", "viscosity_cP", "speed_rpm", "natural_frequency_rpm"}
    missing = need - set(cases.columns)
    if missing:
        raise ParameterError("cases", f"the table lacks the columns {sorted(missing)}")
    if not 1 <= cases.height <= MAX_OIL_CASES:
        raise ParameterError("cases", f"must hold 1 to {MAX_OIL_CASES} rows, got "
                             f"{cases.height}", allowed=f"[1, {MAX_OIL_CASES}] rows")
    ref = _check.integer("reference", reference, 0, cases.height - 1)
    rows_in = list(cases.iter_rows(named=True))

    def calibrated(r: dict[str, Any]) -> tuple[Balancer, Transition]:
        zeta = r.get("zeta")
        b = model if zeta is None else model.replace(zeta=float(zeta))
        tr = calibrate_transition(
            b, r["speed_rpm"], natural_frequency_rpm=r["natural_frequency_rpm"],
            uncertainty_rpm=float(r.get("uncertainty_rpm") or 0.0), bracket=bracket,
            pattern=pattern, Omega=Omega)
        return b, tr

    fits = [calibrated(r) for r in rows_in]
    ref_tr = fits[ref][1]
    if ref_tr.value is None:
        raise ParameterError("reference", f"the reference case {rows_in[ref]['case']!r} "
                             f"cannot be calibrated: its transition is {ref_tr.status} "
                             f"(band ends {ref_tr.reach_rpm} rpm over the bracket)")
    kappa = geometric_factor(ref_tr.value, rows_in[ref]["viscosity_cP"] * CENTIPOISE,
                             natural_frequency_rpm=rows_in[ref]["natural_frequency_rpm"],
                             ball_radius=ball_radius, ball_mass=ball_mass,
                             channel_radius=channel_radius)
    out = []
    for r, (b, tr) in zip(rows_in, fits, strict=True):
        fn = float(r["natural_frequency_rpm"])
        law = track_damping(r["viscosity_cP"] * CENTIPOISE, natural_frequency_rpm=fn,
                            geometric_factor=kappa, ball_radius=ball_radius,
                            ball_mass=ball_mass, channel_radius=channel_radius)
        end = stable_band_end(b.replace(zeta_b=law), pattern, Omega=Omega)
        pred = None if end is None else end * fn
        out.append({"case": str(r["case"]), "viscosity_cP": float(r["viscosity_cP"]),
                    "natural_frequency_rpm": fn, "zeta": float(np.mean(b.zeta)),
                    "measured_rpm": float(r["speed_rpm"]), "calibrated_zeta_b": tr.value,
                    "calibrated_low": tr.low, "calibrated_high": tr.high,
                    "status": tr.status, "law_zeta_b": law,
                    "ratio": None if tr.value is None else tr.value / law,
                    "predicted_rpm": pred,
                    "residual_rpm": None if pred is None else pred - float(r["speed_rpm"])})
    schema = {"case": pl.String, "viscosity_cP": pl.Float64,
              "natural_frequency_rpm": pl.Float64, "zeta": pl.Float64,
              "measured_rpm": pl.Float64, "calibrated_zeta_b": pl.Float64,
              "calibrated_low": pl.Float64, "calibrated_high": pl.Float64,
              "status": pl.String, "law_zeta_b": pl.Float64, "ratio": pl.Float64,
              "predicted_rpm": pl.Float64, "residual_rpm": pl.Float64}
    return OilTransfer(pl.DataFrame(out, schema=schema), kappa, ref)
