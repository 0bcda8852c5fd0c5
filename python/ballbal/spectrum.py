"""What the balancer does to the machine: ground-frame spectra and the vibration indicator.

The model lives in a frame rotating with the disk at ``Omega`` (nondimensional time
``t* = w_n t``). A periodic solution has rotating-frame coordinates ``x, y`` of period
``2 pi / omega``, so the disk centre in the ground frame,

    Z(t) = X + i Y = exp(i Omega t) (x(t) + i y(t)) = sum_k c_k exp(i (Omega + k omega) t),

has lines only at ``f_k = Omega + k omega`` (``k = -N..N``; a negative ``f_k`` is a
backward whirl). From ``x = a_0 + sum a_m cos(m tau) + b_m sin(m tau)`` (``tau = omega
t``, the same for ``y``), ``c_0 = a_0x + i a_0y``,
``c_m = ((a_mx + b_my) + i (a_my - b_mx)) / 2`` and
``c_-m = ((a_mx - b_my) + i (a_my + b_mx)) / 2``; velocity and acceleration lines are
``(i f_k) c_k`` and ``-f_k^2 c_k``. These lines are exact (no FFT, no leakage); the
functions below also give the windowed spectrum of a sampled signal (a simulation or a
measured record), label its peaks as ``Omega + k omega``, and Tien's (2011) vibration
indicator: the mean, least and largest support acceleration magnitude ``|Z''|``.

Units. Frequencies are ratios to ``w_n`` (the model's angular frequencies), optionally
also in Hz and rpm given the natural frequency. Amplitudes are in the eccentricity ``e``
(displacement), ``e w_n`` (velocity) and ``e w_n^2`` (acceleration), optionally in SI
units given ``e`` in metres and the natural frequency.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import polars as pl

from . import _check
from ._style import Summarised
from ._style import label as label_of
from .exceptions import ParameterError, ParameterTypeError

if TYPE_CHECKING:
    from .analysis import Equilibrium, PeriodicSolution

Quantity = Literal["displacement", "velocity", "acceleration"]
Window = Literal["flattop", "hann", "rect"]

_POWER = {"displacement": 0, "velocity": 1, "acceleration": 2}

__all__ = [
    "Vibration",
    "ground_signal",
    "label_lines",
    "label_peaks",
    "line_spectrum",
    "plot_spectrum",
    "plot_waterfall",
    "signal_spectrum",
    "vibration",
    "waterfall",
]


def _quantity(q: Any) -> int:
    _check.string("quantity", q)
    if q not in _POWER:
        raise ParameterError("quantity", f"must be one of {', '.join(_POWER)}, got {q!r}",
                             allowed=", ".join(_POWER), value=q)
    return _POWER[q]


def _natural_hz(hz: Any, rpm: Any) -> float | None:
    """The natural frequency ``f_n`` in Hz from whichever of the two keywords is given."""
    if hz is not None and rpm is not None:
        raise ParameterError("natural_frequency_rpm", "give natural_frequency_hz or "
                             "natural_frequency_rpm, not both")
    if hz is not None:
        return _check.real("natural_frequency_hz", hz, 0.0, math.inf, lo_open=True,
                           finite=True)
    if rpm is not None:
        return _check.real("natural_frequency_rpm", rpm, 0.0, math.inf, lo_open=True,
                           finite=True) / 60.0
    return None


# --------------------------------------------------------------------------------------
# Exact lines of a periodic solution or an equilibrium


class LineSource:
    """A result with displacement lines: :class:`~ballbal.PeriodicSolution` and
    :class:`~ballbal.Equilibrium` derive from it, each saying how its lines follow from
    its values, so that this module reads them without knowing the classes."""

    def _displacement_lines(self, Omega: float | None,  # noqa: N803
                            name: str) -> tuple[np.ndarray, np.ndarray, float, float]:
        """``(k, c_k, Omega, omega)``: the lines ``Z = sum c_k e^{i (Omega + k omega) t}``
        (``omega`` NaN for a single line); ``name`` is the caller's for the result."""
        raise NotImplementedError


def _lines(source: PeriodicSolution | Equilibrium, Omega: float | None,  # noqa: N803
           name: str = "solution") -> tuple[np.ndarray, np.ndarray, float, float]:
    """``(k, c_k, Omega, omega)``: the displacement lines ``Z = sum c_k e^{i f_k t}``
    (``name``: the caller's name for ``source``)."""
    if isinstance(source, LineSource):
        return source._displacement_lines(Omega, name)
    raise ParameterTypeError(name, f"must be a ballbal.PeriodicSolution or "
                             f"ballbal.Equilibrium, got {type(source).__name__}",
                             value=source)


def _scaled_lines(source: PeriodicSolution | Equilibrium, quantity: str,
                  Omega: float | None, name: str = "solution",  # noqa: N803
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    p = _quantity(quantity)
    k, c, spin, omega = _lines(source, Omega, name)
    f = spin + k * (0.0 if math.isnan(omega) else omega)
    return k, f, (1j * f) ** p * c, spin, omega


def _wrap(phi: np.ndarray) -> np.ndarray:
    return np.angle(np.exp(1j * phi))


def line_spectrum(
    solution: PeriodicSolution | Equilibrium,
    quantity: Quantity = "acceleration",
    *,
    Omega: float | None = None,  # noqa: N803 - Tien's (2011) symbol
    natural_frequency_hz: float | None = None,
    natural_frequency_rpm: float | None = None,
    eccentricity: float | None = None,
    min_relative: float = 0.0,
) -> pl.DataFrame:
    """The exact ground-frame spectrum of a periodic solution (or of an equilibrium).

    One row per line ``Z = sum_k C_k exp(i f_k t)`` of the disk centre's ``quantity``
    (``Z``, ``Z'`` or ``Z''``, ``Z = X + i Y``), ``f_k = Omega + k omega``, ``k = -N..N``:

    * ``k``; ``frequency``: ``f_k`` as a ratio to ``w_n`` (negative: backward whirl);
      ``frequency_hz``, ``frequency_rpm`` (signed likewise) when the natural frequency is
      given;
    * ``direction``: ``"forward"`` (``f_k > 0``), ``"backward"`` (``f_k < 0``) or
      ``"static"``;
    * ``amplitude``: ``|C_k|``, the radius of the line's circular whirl, which is also the
      amplitude of its ``X`` and of its ``Y`` oscillation; in ``e``, ``e w_n`` or
      ``e w_n^2`` (``x, y`` are scaled by the eccentricity ``e``); ``amplitude_si`` in
      m, m/s or m/s^2 when ``eccentricity`` (``e`` in metres) and the natural frequency
      are given;
    * ``relative_amplitude``: ``amplitude`` over the largest line's;
    * ``phase_x``, ``phase_y``: the line's ``X = amplitude cos(|f_k| t + phase_x)`` and
      ``Y = amplitude cos(|f_k| t + phase_y)`` (radians); ``phase_y = phase_x - pi/2``
      for a forward line, ``+ pi/2`` for a backward one. ``t = 0`` is the solution's
      ``t = 0`` (:meth:`PeriodicSolution.time_history`), where the disk angle is 0.

    Lines of equal ``|f_k|`` and opposite sign add in a spectrum of ``X`` alone (see
    :func:`signal_spectrum`); in the two-sided spectrum of ``X + i Y`` they stay apart.

    ``Omega`` is the solution's model's (giving another is an error); an
    :class:`~ballbal.Equilibrium` needs it (it does not carry its model) and has the
    single line ``k = 0`` at ``Omega``: the disk centre's offset ``x + i y``, which the
    perfect balance makes zero. Lines below ``min_relative`` times the largest are left
    out.
    """
    fn = _natural_hz(natural_frequency_hz, natural_frequency_rpm)
    k, f, C, spin, omega = _scaled_lines(solution, quantity, Omega)
    amp = np.abs(C)
    top = float(amp.max())
    rel = amp / top if top > 0 else np.full(amp.shape, np.nan)
    arg = np.angle(C)
    fwd = f >= 0
    phase_x = np.where(fwd, arg, -arg)
    phase_y = _wrap(np.where(fwd, arg - np.pi / 2, -arg + np.pi / 2))
    cols: dict[str, Any] = {"k": k.astype(np.int64), "frequency": f}
    if fn is not None:
        cols["frequency_hz"] = f * fn
        cols["frequency_rpm"] = f * fn * 60.0
    cols["direction"] = np.where(f > 0, "forward", np.where(f < 0, "backward", "static"))
    cols["amplitude"] = amp
    if eccentricity is not None:
        e = _check.real("eccentricity", eccentricity, 0.0, math.inf, lo_open=True,
                        finite=True)
        if fn is None:
            raise ParameterError("eccentricity", "physical amplitudes need the natural "
                                 "frequency too (natural_frequency_hz or _rpm)")
        cols["amplitude_si"] = amp * e * (2 * np.pi * fn) ** _POWER[quantity]
    cols["relative_amplitude"] = rel
    cols["phase_x"] = phase_x
    cols["phase_y"] = phase_y
    df = pl.DataFrame(cols)
    lo = _check.real("min_relative", min_relative, 0.0, 1.0)
    if lo > 0:
        df = df.filter(pl.col("relative_amplitude") >= lo)
    return df


# --------------------------------------------------------------------------------------
# The vibration indicator


@dataclass(frozen=True, repr=False)
class Vibration(Summarised):
    """Statistics of ``|Z|``, ``|Z'|`` or ``|Z''|`` (``quantity``) over the motion.

    ``mean``, ``min``, ``max`` and ``rms`` in the units of :func:`line_spectrum`
    (``e w_n^2`` for the acceleration: Tien's (2011) "amplitude" is ``|Z''|``, the root of
    the two accelerometers' squares, its mean the vibration level of its tables).
    ``exact``: from a periodic solution's coefficients (see :func:`vibration`), else from
    samples of a simulation; ``mean_error``: the last change of the mean as the samples
    were doubled (exact case) or ``nan``; ``samples``: how many values the statistics
    took. No ``plot``: four numbers, all in its summary (the orbit's own
    :meth:`~ballbal.PeriodicSolution.plot` draws the motion).
    """

    quantity: str
    mean: float
    min: float
    max: float
    rms: float
    exact: bool
    samples: int
    mean_error: float = float("nan")

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        how = "exact" if self.exact else "sampled"
        head = (f"Vibration {self.quantity} mean={self.mean:.4g} min={self.min:.4g} "
                f"max={self.max:.4g} rms={self.rms:.4g} ({how}, {self.samples} samples)")
        return head, [("quantity", self.quantity), ("mean", self.mean), ("min", self.min),
                      ("max", self.max), ("rms", self.rms), ("exact", self.exact),
                      ("samples", self.samples), ("mean error", self.mean_error)]


def _trig(C: np.ndarray, k: np.ndarray, s: float, d: int) -> complex:
    """``d``-th derivative in ``s`` of ``sum C_k exp(i k s)``."""
    return complex(np.sum(C * (1j * k) ** d * np.exp(1j * k * s)))


def _refine(C: np.ndarray, k: np.ndarray, s0: float, h: float, sign: float) -> float:
    """``|g|`` at the extremum of ``|g|^2`` next to ``s0`` (Newton on its derivative
    ``2 Re(conj(g) g')``, steps held within one sample spacing ``h``)."""
    s = s0
    for _ in range(60):
        g, g1, g2 = (_trig(C, k, s, d) for d in (0, 1, 2))
        h1 = (g.conjugate() * g1).real
        h2 = abs(g1) ** 2 + (g.conjugate() * g2).real
        if sign * h2 >= 0:  # wrong curvature: not at this extremum's basin, keep the sample
            return abs(_trig(C, k, s0, 0))
        step = max(-h, min(h, -h1 / h2))
        s += step
        if abs(step) < 1e-15 * (1 + abs(s)):
            break
    if abs(s - s0) > 2 * h:
        return abs(_trig(C, k, s0, 0))
    return abs(_trig(C, k, s, 0))


def _exact_vibration(C: np.ndarray, k: np.ndarray, quantity: str) -> Vibration:
    n = int(np.max(np.abs(k)))
    rms = math.sqrt(float(np.sum(np.abs(C) ** 2)))
    if n == 0:
        a = float(abs(C[0]))
        return Vibration(quantity, a, a, a, a, True, 1, 0.0)
    m = 256
    while m < 64 * (n + 1):
        m *= 2
    last = math.nan
    while True:
        spec = np.zeros(m, dtype=complex)
        spec[k % m] = C
        g = np.abs(np.fft.ifft(spec) * m)
        mean = float(g.mean())
        err = abs(mean - last)
        if err <= 1e-14 * max(mean, 1e-300) or m >= 2**20:
            break
        last, m = mean, 2 * m
    h = 2 * np.pi / m
    s = np.arange(m) * h
    # |g|^2 has degree 2 N, hence at most 4 N extrema: refine that many candidates (ties
    # on a flat stretch would otherwise make every sample one)
    lo_i = np.flatnonzero((g <= np.roll(g, 1)) & (g <= np.roll(g, -1)))
    hi_i = np.flatnonzero((g >= np.roll(g, 1)) & (g >= np.roll(g, -1)))
    lo_i = lo_i[np.argsort(g[lo_i], kind="stable")][: 4 * n]
    hi_i = hi_i[np.argsort(-g[hi_i], kind="stable")][: 4 * n]
    gmax = max([float(g.max())] + [_refine(C, k, s[i], h, 1.0) for i in hi_i])
    gmin = min([float(g.min())] + [_refine(C, k, s[i], h, -1.0) for i in lo_i])
    return Vibration(quantity, mean, gmin, gmax, rms, True, m, err)


def _column(df: pl.DataFrame, c: str, name: str = "df") -> np.ndarray:
    """Column ``c`` of a table as a float array; a column of anything but numbers is an
    error naming the table's parameter."""
    if not df.schema[c].is_numeric():
        raise ParameterTypeError(name, f"column {c!r} must hold numbers, not {df.schema[c]}",
                                 value=None)
    return df[c].cast(pl.Float64).to_numpy()


def _uniform_step(t: np.ndarray, name: str = "t") -> float:
    if t.size < 8:
        raise ParameterError(name, f"needs at least 8 samples, got {t.size}")
    dt = np.diff(t)
    h = float(dt.mean())
    if not (h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h)):
        raise ParameterError(name, "sample times must be evenly spaced and increasing")
    return h


def _d5(v: np.ndarray, h: float) -> np.ndarray:
    """Fourth-order central first derivative at samples 2..n-3."""
    return (v[:-4] - 8 * v[1:-3] + 8 * v[3:-1] - v[4:]) / (12 * h)


def ground_signal(df: pl.DataFrame, quantity: Quantity = "acceleration", *,
                  t_min: float | None = None) -> pl.DataFrame:
    """The disk centre's ground-frame ``X, Y`` (``quantity``: displacement, velocity or
    acceleration) from a :func:`ballbal.simulate` table (columns ``t, x, y, dx, dy,
    theta``, evenly spaced times), as columns ``t, X, Y``.

    The displacement is ``exp(i theta)(x + i y)`` and the velocity ``exp(i theta)((x' + i
    y') + i theta' (x + i y))``, both exact to the integration's tolerance; the
    acceleration is the fourth-order central difference of that velocity (relative
    error about ``(f h)^4 / 30`` for a line at ``f`` and output step ``h``: 6e-6 at
    ``h = 0.05, f = 2.3``), which drops two samples at each end (``theta'`` likewise).
    Samples before ``t_min`` are dropped first.
    """
    p = _quantity(quantity)
    if not isinstance(df, pl.DataFrame):
        raise ParameterTypeError("df", f"must be a polars DataFrame from ballbal.simulate, "
                                 f"got {type(df).__name__}", value=df)
    need = ["t", "x", "y", "dx", "dy", "theta"]
    missing = [c for c in need if c not in df.columns]
    if missing:
        raise ParameterError("df", f"needs the columns of ballbal.simulate; missing "
                             f"{', '.join(missing)}")
    if t_min is not None:
        lo = _check.real("t_min", t_min, finite=True)
        df = df.filter(pl.col("t") >= lo) if df.schema["t"].is_numeric() else df
    col = {c: _column(df, c) for c in need}
    t = col["t"]
    h = _uniform_step(t, "df")
    th = col["theta"]
    rot = np.exp(1j * th)
    z = col["x"] + 1j * col["y"]
    if p == 0:
        Z = rot * z
    else:
        dth = _d5(th, h)
        sl = slice(2, -2)
        dz = col["dx"] + 1j * col["dy"]
        V = rot[sl] * (dz[sl] + 1j * dth * z[sl])
        t = t[sl]
        if p == 1:
            Z = V
        else:
            Z = _d5(V, h)
            t = t[2:-2]
    return pl.DataFrame({"t": t, "X": Z.real, "Y": Z.imag})


def vibration(
    source: PeriodicSolution | Equilibrium | pl.DataFrame,
    quantity: Quantity = "acceleration",
    *,
    Omega: float | None = None,  # noqa: N803
    t_min: float | None = None,
) -> Vibration:
    """The vibration indicator: mean, least, largest and rms value of ``|Z''|`` (the
    support acceleration magnitude, Tien's (2011) "amplitude"), or of ``|Z|`` / ``|Z'|``.

    * A :class:`~ballbal.PeriodicSolution`: exact from its coefficients. ``|Z^(p)(t)| =
      |g(omega t)|`` with ``g(s) = sum_k C_k exp(i k s)`` (the factor ``exp(i Omega t)``
      has modulus 1), a trigonometric polynomial of degree ``N``. The rms is exact by
      Parseval (``sum |C_k|^2``); the mean is the periodic trapezoid rule on ``M``
      samples of ``|g|`` (from one inverse FFT), which converges geometrically for this
      analytic periodic function: ``M`` starts at ``64 (N + 1)`` (at least 256) and
      doubles until the mean changes by less than ``1e-14`` relative (``mean_error``;
      where ``|g|`` touches zero it has a kink and converges algebraically: at most
      ``2^20`` samples, ``mean_error`` then says how far it got); min and max: the
      samples' local extrema refined by Newton on ``d|g|^2/ds`` to round-off.
    * An :class:`~ballbal.Equilibrium` (give ``Omega``): the constant ``Omega^p |x + i y|``.
    * A :func:`ballbal.simulate` table: from :func:`ground_signal`'s samples after
      ``t_min`` (leave out transients; over a whole number of periods or a long record
      the mean is that of the motion).
    """
    _quantity(quantity)
    if isinstance(source, LineSource):
        k, _, C, _, _ = _scaled_lines(source, quantity, Omega, "source")
        return _exact_vibration(C, k, quantity)
    if isinstance(source, pl.DataFrame):
        sig = ground_signal(source, quantity, t_min=t_min)
        a = np.hypot(sig["X"].to_numpy(), sig["Y"].to_numpy())
        return Vibration(quantity, float(a.mean()), float(a.min()), float(a.max()),
                         float(np.sqrt(np.mean(a**2))), False, int(a.size))
    raise ParameterTypeError("source", f"must be a PeriodicSolution, Equilibrium or a "
                             f"ballbal.simulate table, got {type(source).__name__}",
                             value=source)


# --------------------------------------------------------------------------------------
# Spectrum of a sampled signal

#: Coefficients of the windows ``w[n] = sum_j (-1)^j a_j cos(2 pi j n / M)`` (periodic
#: form, as for spectral analysis): Hann; the flat-top window of scipy / Matlab's
#: ``flattopwin`` (scalloping loss below 0.02 dB, main lobe +-5 bins wide, side lobes
#: below -93 dB).
_WINDOWS = {
    "rect": (1.0,),
    "hann": (0.5, 0.5),
    "flattop": (0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368),
}


def _window(name: str, m: int) -> np.ndarray:
    _check.string("window", name)
    if name not in _WINDOWS:
        raise ParameterError("window", f"must be one of {', '.join(_WINDOWS)}, got {name!r}",
                             allowed=", ".join(_WINDOWS), value=name)
    n = np.arange(m)
    w = np.zeros(m)
    for j, a in enumerate(_WINDOWS[name]):
        w += (-1) ** j * a * np.cos(2 * np.pi * j * n / m)
    return w


def signal_spectrum(
    t: Sequence[float] | np.ndarray | pl.DataFrame,
    X: Sequence[float] | np.ndarray | None = None,
    Y: Sequence[float] | np.ndarray | None = None,
    *,
    window: Window = "flattop",
    scaling: Literal["amplitude", "psd"] = "amplitude",
    two_sided: bool | None = None,
    detrend: bool = False,
    time_unit: Literal["nondimensional", "s"] = "nondimensional",
    natural_frequency_hz: float | None = None,
    natural_frequency_rpm: float | None = None,
) -> pl.DataFrame:
    """Windowed spectrum of a sampled signal (a simulation or a measured record).

    ``t`` evenly spaced; ``X`` and optionally ``Y`` the two ground-frame components (or
    pass one DataFrame with columns ``t, X, Y``, e.g. :func:`ground_signal`'s). With ``Y``
    the spectrum is by default two-sided, of ``Z = X + i Y``: a line at negative
    frequency is a backward whirl (column ``direction``); ``two_sided=False`` gives the
    one-sided spectra of ``X`` and ``Y`` (``amplitude_x``, ``amplitude_y``). Without
    ``Y``, the one-sided spectrum of ``X`` (``amplitude``).

    Scaling ``"amplitude"``: a component ``A cos(f t + phi)`` of ``X`` gives a one-sided
    peak ``A``, a whirl ``A exp(i (f t + phi))`` of ``Z`` a two-sided peak ``A`` at
    ``f`` (the same numbers as :func:`line_spectrum`'s ``amplitude``), exactly with the
    flat-top window (default; within its scalloping loss, below 0.25 %) and up to 15 %
    low between bins with Hann (``-1.42 dB``), 36 % with ``"rect"``. Scaling ``"psd"``:
    power spectral density per unit of the first frequency column (mean square =
    sum of psd times the bin width).

    Frequencies: with ``time_unit="nondimensional"`` (``t* = w_n t``, as
    :func:`ballbal.simulate` returns) ``frequency`` is the angular frequency in units of
    ``w_n``, the ratio of :func:`line_spectrum`; with ``time_unit="s"`` (a measured
    record) ``frequency_hz`` and ``frequency_rpm``. The other set is added when the
    natural frequency is given. ``detrend`` removes the mean first. The bins are
    ``2 pi / (m h)`` apart (``m`` samples ``h`` apart; no zero padding, so that
    :func:`label_peaks`' separation in bins is one in resolution).
    """
    if isinstance(t, pl.DataFrame):
        if X is not None or Y is not None:
            raise ParameterError("X", "give a DataFrame (columns t, X, Y) or arrays, not both")
        df = t
        for c in ("t", "X"):
            if c not in df.columns:
                raise ParameterError("t", f"the DataFrame needs columns t, X (and Y); "
                                     f"missing {c}")
        t, X = df["t"].to_numpy(), df["X"].to_numpy()
        Y = df["Y"].to_numpy() if "Y" in df.columns else None
    tt = _check.array("t", t)
    if X is None:
        raise ParameterError("X", "give the signal X (and Y)")
    xs = _check.array("X", X)
    if xs.size != tt.size:
        raise ParameterError("X", f"needs one value per time ({tt.size}), got {xs.size}")
    ys = None
    if Y is not None:
        ys = _check.array("Y", Y)
        if ys.size != tt.size:
            raise ParameterError("Y", f"needs one value per time ({tt.size}), got {ys.size}")
    if not (np.all(np.isfinite(xs)) and (ys is None or np.all(np.isfinite(ys)))):
        raise ParameterError("X", "the signal must be finite")
    h = _uniform_step(tt)
    _check.string("scaling", scaling)
    if scaling not in ("amplitude", "psd"):
        raise ParameterError("scaling", f"must be amplitude or psd, got {scaling!r}",
                             allowed="amplitude, psd", value=scaling)
    _check.string("time_unit", time_unit)
    if time_unit not in ("nondimensional", "s"):
        raise ParameterError("time_unit", f"must be nondimensional or s, got {time_unit!r}",
                             allowed="nondimensional, s", value=time_unit)
    fn = _natural_hz(natural_frequency_hz, natural_frequency_rpm)
    if two_sided is None:
        two_sided = ys is not None
    two_sided = _check.boolean("two_sided", two_sided)
    if two_sided and ys is None:
        raise ParameterError("two_sided", "a two-sided spectrum needs Y (the whirl X + i Y)")
    detrend = _check.boolean("detrend", detrend)
    m = tt.size
    w = _window(window, m)
    nfft = m
    # unit of the first frequency column per cycle per time unit of t
    per_cycle = 2 * np.pi if time_unit == "nondimensional" else 1.0
    fs = per_cycle / h  # sampling rate in that unit

    def transform(v: np.ndarray) -> np.ndarray:
        if detrend:
            v = v - v.mean()
        return np.fft.fft(v * w, nfft)

    def scale(F: np.ndarray, one_sided: bool) -> np.ndarray:
        if scaling == "amplitude":
            a = np.abs(F) / w.sum()
            if one_sided:
                a[1:] *= 2
                if nfft % 2 == 0:
                    a[-1] /= 2
            return a
        p = np.abs(F) ** 2 / (fs * np.sum(w**2))
        if one_sided:
            p[1:] *= 2
            if nfft % 2 == 0:
                p[-1] /= 2
        return p

    cols: dict[str, Any] = {}
    if two_sided:
        assert ys is not None
        F = np.fft.fftshift(transform(xs + 1j * ys))
        cyc = np.fft.fftshift(np.fft.fftfreq(nfft, h))
        amp = {"amplitude": scale(F, False)}
    else:
        half = nfft // 2 + 1
        cyc = np.fft.rfftfreq(nfft, h)
        if ys is None:
            amp = {"amplitude": scale(transform(xs)[:half], True)}
        else:
            amp = {"amplitude_x": scale(transform(xs)[:half], True),
                   "amplitude_y": scale(transform(ys)[:half], True)}
    if time_unit == "nondimensional":
        cols["frequency"] = 2 * np.pi * cyc
        if fn is not None:
            cols["frequency_hz"] = 2 * np.pi * cyc * fn
            cols["frequency_rpm"] = 2 * np.pi * cyc * fn * 60.0
    else:
        cols["frequency_hz"] = cyc
        cols["frequency_rpm"] = cyc * 60.0
        if fn is not None:
            cols["frequency"] = cyc / fn
    if two_sided:
        f0 = cols[next(iter(cols))]
        cols["direction"] = np.where(f0 > 0, "forward", np.where(f0 < 0, "backward",
                                                                 "static"))
    cols.update(amp)
    return pl.DataFrame(cols)


# --------------------------------------------------------------------------------------
# Peak labelling


def _family_fit(d: np.ndarray, om: float, tol: float, k_max: int,
                ) -> tuple[np.ndarray, np.ndarray]:
    r = d / om
    k = np.rint(r)
    ok = (np.abs(r - k) <= tol) & (np.abs(k) <= k_max)
    return k, ok


def label_lines(
    frequencies: Sequence[float] | np.ndarray,
    Omega: float,  # noqa: N803
    *,
    omega: float | None = None,
    amplitudes: Sequence[float] | np.ndarray | None = None,
    tol: float = 0.1,
    k_max: int = 6,
) -> pl.DataFrame:
    """Label peaks at ``frequencies`` (any unit, ``Omega`` in the same) as ``Omega + k
    omega`` and flag those that are not.

    Without ``omega`` it is estimated from the line spacing: each peak's offset from
    ``Omega`` is a candidate; a candidate's family is the peaks within ``tol * omega`` of
    ``Omega + k omega``, ``|k| <= k_max``; the candidate whose family holds the most
    ``amplitudes`` (or peaks, without amplitudes) wins, the larger on a tie, and is
    refined by least squares over its family (``sum k d / sum k^2``, ``d`` the offsets).
    A sub-multiple of the true spacing wins only where peaks sit between the family's
    lines; pass ``omega`` when it is known.

    Columns: ``frequency``, ``amplitude`` (when given), ``k = round((f - Omega) /
    omega)``, ``residual = f - Omega - k omega`` (frequency unit), ``relative_residual``
    (over ``omega``), ``in_family`` (``|relative_residual| <= tol`` and ``|k| <=
    k_max``) and ``omega`` (the one used, the same on every row).
    """
    f = _check.array("frequencies", frequencies)
    if f.size > _check.MAX_LINES:
        raise ParameterError("frequencies", f"{f.size} peaks, at most {_check.MAX_LINES}",
                             allowed=f"at most {_check.MAX_LINES} peaks")
    if not np.all(np.isfinite(f)):
        raise ParameterError("frequencies", "must be finite", allowed="finite numbers")
    spin = _check.real("Omega", Omega, finite=True)
    tol = _check.real("tol", tol, 0.0, 0.5, lo_open=True)
    k_max = _check.integer("k_max", k_max, 1, 10**6)
    wgt = np.ones(f.size) if amplitudes is None else _check.array("amplitudes", amplitudes)
    if wgt.size != f.size:
        raise ParameterError("amplitudes", f"needs one per frequency ({f.size}), got "
                             f"{wgt.size}")
    if not np.all(np.isfinite(wgt)):
        raise ParameterError("amplitudes", "must be finite", allowed="finite numbers")
    d = f - spin
    if omega is not None:
        om = _check.real("omega", omega, 0.0, math.inf, lo_open=True, finite=True)
    else:
        scale_ = float(np.max(np.abs(d))) if d.size else 0.0
        cands = np.abs(d[np.abs(d) > 1e-9 * max(scale_, abs(spin), 1e-300)])
        om = math.nan
        best = -math.inf
        for c in np.unique(cands)[::-1]:  # larger first: keeps the larger on a tie
            _, ok = _family_fit(d, c, tol, k_max)
            score = float(wgt[ok].sum())
            if score > best * (1 + 1e-12):
                best, om = score, float(c)
        if not math.isnan(om):
            k, ok = _family_fit(d, om, tol, k_max)
            use = ok & (k != 0)
            om = float(np.sum(k[use] * d[use]) / np.sum(k[use] ** 2))
    cols: dict[str, Any] = {"frequency": f}
    if amplitudes is not None:
        cols["amplitude"] = wgt
    if math.isnan(om):
        k = np.zeros(f.size)
        res = d
        rel = np.full(f.size, np.nan)
        ok = np.abs(d) <= 1e-9 * max(abs(spin), 1e-300)
    else:
        k, ok = _family_fit(d, om, tol, k_max)
        res = d - k * om
        rel = res / om
    cols.update({"k": k.astype(np.int64), "residual": res, "relative_residual": rel,
                 "in_family": ok, "omega": np.full(f.size, om)})
    return pl.DataFrame(cols)


def label_peaks(
    spectrum: pl.DataFrame,
    Omega: float,  # noqa: N803
    *,
    omega: float | None = None,
    column: str = "frequency",
    amplitude: str = "amplitude",
    threshold: float = 0.01,
    min_separation: float | None = None,
    max_peaks: int = 40,
    tol: float = 0.1,
    k_max: int = 6,
) -> pl.DataFrame:
    """Find the peaks of a :func:`signal_spectrum` and label them (:func:`label_lines`).

    A peak is a local maximum of ``amplitude`` of at least ``threshold`` times the
    largest, at least ``min_separation`` (in ``column``'s unit; default 4 bins, beyond
    the Hann window's first side lobes and within the flat-top's main lobe) from every
    larger peak; at most ``max_peaks``, largest first. Its frequency is refined by a
    parabola through the logarithms of the three bins around it (error below 0.02 bin
    with Hann, 0.15 bin with the flat-top window, whose top is flatter than a parabola).
    ``Omega`` and ``omega`` are in ``column``'s unit (``"frequency"``: ratio to ``w_n``;
    ``"frequency_rpm"``, ``"frequency_hz"``). Returns :func:`label_lines`' columns,
    sorted by frequency, with ``amplitude`` the peak bin's value. Use the flat-top or
    Hann window: the rectangular window's side lobes pass a 1 % threshold.
    """
    sp = _spectrum_table(spectrum, column, amplitude)
    f = _column(sp, column, "column")
    a = _column(sp, amplitude, "amplitude")
    if f.size < 3:
        raise ParameterError("spectrum", "needs at least 3 bins")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(a))):
        raise ParameterError("spectrum", f"{column!r} and {amplitude!r} must be finite")
    bin_ = float(np.median(np.diff(f)))
    sep = 4 * bin_ if min_separation is None else _check.real(
        "min_separation", min_separation, 0.0, math.inf, finite=True)
    thr = _check.real("threshold", threshold, 0.0, 1.0) * float(a.max())
    max_peaks = _check.integer("max_peaks", max_peaks, 1, _check.MAX_LINES)
    i = np.arange(1, f.size - 1)
    loc = i[(a[i] >= a[i - 1]) & (a[i] > a[i + 1]) & (a[i] >= thr)]
    loc = loc[np.argsort(-a[loc], kind="stable")]
    # Largest first, each kept unless within sep of a kept one: the kept frequencies are
    # held sorted, so that only the two neighbours need a look (a spectrum can have
    # hundreds of thousands of local maxima).
    kept: list[int] = []
    kept_f: list[float] = []
    for j in loc:
        fj = float(f[j])
        pos = bisect.bisect_left(kept_f, fj)
        if ((pos == 0 or fj - kept_f[pos - 1] > sep)
                and (pos == len(kept_f) or kept_f[pos] - fj > sep)):
            kept_f.insert(pos, fj)
            kept.append(int(j))
            if len(kept) == max_peaks:
                break
    kept.sort()
    idx = np.asarray(kept, dtype=int)
    fr = f[idx].copy()
    for n, j in enumerate(idx):
        if min(a[j - 1], a[j + 1]) <= 0:
            continue
        y0, y1, y2 = np.log(a[j - 1 : j + 2])
        den = y0 - 2 * y1 + y2
        if den < 0:
            fr[n] = f[j] + 0.5 * (y0 - y2) / den * (f[j + 1] - f[j])
    return label_lines(fr, Omega, omega=omega, amplitudes=a[idx], tol=tol, k_max=k_max)


def _spectrum_table(spectrum: Any, column: Any, amplitude: Any,
                    name: str = "spectrum") -> pl.DataFrame:
    """A spectrum table (the caller's parameter ``name``) sorted by ``column``, both
    columns present."""
    if not isinstance(spectrum, pl.DataFrame):
        raise ParameterTypeError(name, f"must be a polars DataFrame, got "
                                 f"{type(spectrum).__name__}", value=spectrum)
    for c, name in ((column, "column"), (amplitude, "amplitude")):
        if not isinstance(c, str) or c not in spectrum.columns:
            raise ParameterError(name, f"{c!r:.60} is not a column of the spectrum "
                                 f"({', '.join(spectrum.columns)})",
                                 allowed=", ".join(spectrum.columns))
    return spectrum.sort(column)


# --------------------------------------------------------------------------------------
# Waterfall and plots


def waterfall(items: Iterable[tuple[float, pl.DataFrame]], *, name: str = "Omega",
              ) -> pl.DataFrame:
    """A long table of spectra over a speed sweep: ``(speed, spectrum)`` pairs (line or
    signal spectra of the same kind), each row tagged with its speed in column ``name``."""
    _check.string("name", name)
    if isinstance(items, (str, bytes, pl.DataFrame)) or not isinstance(items, Iterable):
        raise ParameterTypeError("items", f"must be (speed, spectrum) pairs, got "
                                 f"{type(items).__name__}", value=items)
    parts = []
    for n, item in enumerate(items):
        if not (isinstance(item, tuple) and len(item) == 2
                and isinstance(item[1], pl.DataFrame)):
            raise ParameterTypeError("items", f"item {n} must be a pair (speed, spectrum "
                                     f"DataFrame)", value=item)
        speed = _check.real("items", item[0], finite=True)
        if name in item[1].columns:
            raise ParameterError("name", f"{name!r} is already a column of spectrum {n}",
                                 value=name)
        parts.append(item[1].with_columns(pl.lit(speed).alias(name)).select(
            [name, *item[1].columns]))
    if not parts:
        raise ParameterError("items", "give at least one (speed, spectrum) pair")
    if any(p.schema != parts[0].schema for p in parts):
        raise ParameterError("items", "the spectra must be of one kind (the same columns)")
    return pl.concat(parts, how="vertical")


def plot_spectrum(spectrum: pl.DataFrame, *, column: str = "frequency",
                  amplitude: str = "amplitude", ax: Any = None, label: float = 0.05,
                  min_relative: float = 1e-4, title: str | None = None) -> Any:
    """Plot a spectrum: stems for :func:`line_spectrum` (Tien's (2011) figures 4-12, 4-27,
    4-28; lines below ``min_relative`` of the largest omitted, lines above ``label``
    annotated with their ``k``), a curve for :func:`signal_spectrum`. Returns the axes."""
    from .plot import _pyplot

    spectrum = _spectrum_table(spectrum, column, amplitude)
    f = _column(spectrum, column, "column")
    a = _column(spectrum, amplitude, "amplitude")
    label = _check.real("label", label, 0.0, 1.0)
    min_relative = _check.real("min_relative", min_relative, 0.0, 1.0)
    if title is not None:
        _check.string("title", title)
    _check.axes("ax", ax)
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3.5))
    if "k" in spectrum.columns:
        top = float(a.max()) if a.size else 0.0
        keep = a >= min_relative * top
        ax.vlines(f[keep], 0, a[keep], color="tab:blue")
        ax.plot(f[keep], a[keep], "o", color="tab:blue", ms=4)
        for fk, ak, k in zip(f[keep], a[keep], spectrum["k"].to_numpy()[keep], strict=True):
            if ak >= label * top:
                txt = "Ω" if k == 0 else f"Ω{'+' if k > 0 else '−'}{abs(k) if abs(k) > 1 else ''}ω"
                ax.annotate(txt, (fk, ak), textcoords="offset points", xytext=(0, 4),
                            ha="center", fontsize=8)
        ax.set_ylim(0, 1.15 * top if top > 0 else 1)
    else:
        ax.plot(f, a, lw=0.9)
    ax.axvline(0, color="0.8", lw=0.6)
    ax.set_xlabel({"frequency": label_of("frequency"), "frequency_rpm": "frequency (rpm)",
                   "frequency_hz": "frequency (Hz)"}.get(column, column))
    ax.set_ylabel(amplitude)
    if title:
        ax.set_title(title)
    return ax


def plot_waterfall(table: pl.DataFrame, *, name: str = "Omega", column: str = "frequency",
                   amplitude: str = "amplitude", ax: Any = None, height: float = 0.8,
                   ) -> Any:
    """A waterfall of :func:`waterfall`'s table: each spectrum drawn at its speed
    (vertical axis), amplitudes scaled so the largest spans ``height`` speed steps."""
    from .plot import _pyplot

    _spectrum_table(table, column, amplitude, "table")
    _check.string("name", name)
    if name not in table.columns:
        raise ParameterError("name", f"{name!r} is not a column of the table",
                             allowed=", ".join(table.columns))
    for c, pname in ((name, "name"), (column, "column"), (amplitude, "amplitude")):
        _column(table, c, pname)
    height = _check.real("height", height, 0.0, math.inf, lo_open=True, finite=True)
    _check.axes("ax", ax)
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 4.5))
    speeds = sorted(table[name].unique().to_list())
    step = float(np.min(np.diff(speeds))) if len(speeds) > 1 else 1.0
    top = float(np.max(table[amplitude].to_numpy()))
    gain = height * step / top if top > 0 else 0.0
    lines = "k" in table.columns
    for sp in speeds:
        part = table.filter(pl.col(name) == sp).sort(column)
        f, a = part[column].to_numpy(), part[amplitude].to_numpy()
        if lines:
            ax.vlines(f, sp, sp + gain * a, color="tab:blue", lw=1.2)
        else:
            ax.plot(f, sp + gain * a, color="tab:blue", lw=0.8)
    ax.set_xlabel({"frequency": label_of("frequency"), "frequency_rpm": "frequency (rpm)",
                   "frequency_hz": "frequency (Hz)"}.get(column, column))
    ax.set_ylabel(label_of(name))
    return ax
