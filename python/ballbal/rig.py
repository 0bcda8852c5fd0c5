"""Measured records from a balancer rig: read them, split a stepped speed sweep into its
steps, and reduce each step to what the model predicts (main frequency, labelled
spectral lines, vibration level), and find where the motion changes.

A *record* is a set of time series sampled together: a time column (seconds), the
rotor's speed (a column in rpm, Hz or rad/s, or a tachometer's pulses), and any number
of sensor channels. A :class:`Sensor` says how a channel's recorded numbers (volts,
millivolts, counts) become a physical quantity: the recorded value divided by the
sensitivity is the quantity in the sensor's unit (``m/s^2``, ``g``, ``mm/s``, ``um``,
...). With the rotor's mass eccentricity ``e`` (metres) and the rig's natural frequency
``w_n`` the quantity is also given in the model's units: a displacement in ``e``, a
velocity in ``e w_n``, an acceleration in ``e w_n^2``.

A *stepped sweep* holds the speed at a sequence of values, each for a while, with short
ramps between. :meth:`Record.steps` finds the plateaus from the speed alone; each step's
*settled segment* is its later part (``settle``: the fraction at the plateau's start
left out, where the balls are still moving to their steady motion). Per step,
:meth:`Record.features` gives:

- ``main_frequency_rpm``: the largest line of the settled segment's spectrum;
- ``synchronous``: whether that line is at the rotor speed. With the balls at rest in
  the track (balanced or not) the disk whirls with the rotor; when the balls chase round
  the track slower than the rotor, the largest line moves off the speed (the model's
  ``Omega + k omega`` lines with ``k != 0``);
- the vibration level (RMS and peak of the settled segment) in the sensor's unit and,
  given ``eccentricity`` and the natural frequency, in the model's units.

:meth:`Record.transitions` lists the speeds at which consecutive steps change from
synchronous to non-synchronous motion or back, sweeping up or down: the measured
counterpart of the speeds where the model's balanced state loses or regains stability.
"""

from __future__ import annotations

import html
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import polars as pl

from . import _check
from .exceptions import ParameterError, ParameterTypeError
from .spectrum import label_peaks, signal_spectrum

__all__ = ["Record", "Sensor", "read_record"]

Quantity = Literal["acceleration", "velocity", "displacement"]

#: Physical units a sensor may report, with their factor to SI and their quantity.
UNITS: dict[str, tuple[float, Quantity]] = {
    "m/s^2": (1.0, "acceleration"), "mm/s^2": (1e-3, "acceleration"),
    "g": (9.80665, "acceleration"),
    "m/s": (1.0, "velocity"), "mm/s": (1e-3, "velocity"), "um/s": (1e-6, "velocity"),
    "m": (1.0, "displacement"), "mm": (1e-3, "displacement"), "um": (1e-6, "displacement"),
}
_SPEED_UNITS = {"rpm": 1.0, "Hz": 60.0, "rad/s": 60.0 / (2 * math.pi)}
#: Longest record accepted, in samples per channel.
MAX_RECORD_SAMPLES = _check.MAX_SAMPLES
MAX_CHANNELS = 64


@dataclass(frozen=True)
class Sensor:
    """How a channel's recorded numbers become a physical quantity.

    ``unit``: the physical unit the sensor measures in (one of :data:`UNITS`' keys:
    ``m/s^2``, ``mm/s^2``, ``g``, ``m/s``, ``mm/s``, ``um/s``, ``m``, ``mm``, ``um``);
    the unit says whether it is an acceleration, a velocity or a displacement.
    ``sensitivity``: recorded units per physical unit (e.g. 100 for an accelerometer
    giving 100 mV per ``g`` recorded in mV; 1 when the record holds the quantity
    itself). ``recorded_unit``: what the record holds (``"mV"``, ``"V"``, ...), for
    labels only.
    """

    unit: str = "m/s^2"
    sensitivity: float = 1.0
    recorded_unit: str = ""

    def __post_init__(self) -> None:
        _check.string("unit", self.unit)
        if self.unit not in UNITS:
            allowed = ", ".join(UNITS)
            raise ParameterError("unit", f"must be one of {allowed}, got {self.unit!r:.40}",
                                 allowed=allowed, value=self.unit)
        object.__setattr__(self, "sensitivity", _check.real(
            "sensitivity", self.sensitivity, 0.0, math.inf, lo_open=True, hi_open=True))
        _check.string("recorded_unit", self.recorded_unit)

    @property
    def quantity(self) -> Quantity:
        """``"acceleration"``, ``"velocity"`` or ``"displacement"``, from the unit."""
        return UNITS[self.unit][1]


def _columns_of(source: Any) -> tuple[dict[str, Any], str]:
    """The record's columns as float arrays, and a short description of the source."""
    if isinstance(source, (str, os.PathLike)):
        path = os.fspath(source)
        if not os.path.isfile(path):
            raise ParameterError("source", f"no such file: {path}")
        low = path.lower()
        if low.endswith(".csv"):
            df = pl.read_csv(path, infer_schema_length=10000)
            return {c: df[c] for c in df.columns}, os.path.basename(path)
        if low.endswith(".npz"):
            with np.load(path, allow_pickle=False) as z:
                return {k: z[k] for k in z.files}, os.path.basename(path)
        if low.endswith(".mat"):
            return _read_mat(path), os.path.basename(path)
        if low.endswith((".h5", ".hdf5")):
            return _read_hdf5(path), os.path.basename(path)
        if low.endswith(".tdms"):
            return _read_tdms(path), os.path.basename(path)
        raise ParameterError("source", "reads .csv, .npz, .mat, .h5/.hdf5 and .tdms files "
                             "(or a polars DataFrame or a mapping of arrays), got "
                             f"{os.path.basename(path)!r}",
                             allowed=".csv, .npz, .mat, .h5, .hdf5, .tdms")
    if isinstance(source, pl.DataFrame):
        return {c: source[c] for c in source.columns}, "DataFrame"
    if isinstance(source, Mapping):
        return dict(source), "mapping"
    raise ParameterTypeError("source", "must be a .csv or .npz path, a polars DataFrame or "
                             f"a mapping of column names to arrays, got {type(source).__name__}",
                             value=source)


def _read_mat(path: str) -> dict[str, Any]:
    """A MATLAB (v4 to v7.2) file's numeric vectors, by variable name (scipy.io)."""
    from scipy import io

    try:
        raw = io.loadmat(path, squeeze_me=True)
    except (ValueError, NotImplementedError) as e:  # v7.3 is HDF5: read it as .h5
        raise ParameterError("source", f"cannot read {os.path.basename(path)!r} as a "
                             f"MATLAB file ({e}); a v7.3 file is HDF5: rename it .h5") from e
    return {k: v for k, v in raw.items() if not k.startswith("__")
            and isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind in "iuf"}


def _read_hdf5(path: str) -> dict[str, Any]:
    """An HDF5 file's one-dimensional numeric datasets, by path without the leading
    slash (``group/name``), through h5py (the ``hdf5`` extra)."""
    try:
        import h5py
    except ImportError as e:
        raise ImportError("reading HDF5 needs h5py: pip install 'ballbal[hdf5]'") from e
    out: dict[str, Any] = {}
    with h5py.File(path, "r") as f:
        def take(name: str, obj: Any) -> None:
            if (isinstance(obj, h5py.Dataset) and obj.ndim == 1
                    and obj.dtype.kind in "iuf" and obj.size <= MAX_RECORD_SAMPLES):
                out[name] = obj[()]
        f.visititems(take)
    return out


def _read_tdms(path: str) -> dict[str, Any]:
    """A TDMS file's numeric channels as ``group/channel`` (and the bare channel name
    where it is unique), through npTDMS (the ``tdms`` extra)."""
    try:
        import nptdms
    except ImportError as e:
        raise ImportError("reading TDMS needs npTDMS: pip install 'ballbal[tdms]'") from e
    out: dict[str, Any] = {}
    names: dict[str, int] = {}
    with nptdms.TdmsFile.open(path) as f:
        for g in f.groups():
            for c in g.channels():
                data = c[:]
                if data.dtype.kind in "iuf":
                    out[f"{g.name}/{c.name}"] = data
                    names[c.name] = names.get(c.name, 0) + 1
    for key in list(out):
        bare = key.split("/", 1)[1]
        if names[bare] == 1:
            out.setdefault(bare, out[key])
    return out


def _column(cols: dict[str, Any], name: str, what: str, n: int | None) -> np.ndarray:
    if name not in cols:
        raise ParameterError(what, f"{name!r} is not a column of the record "
                             f"({', '.join(map(str, cols))[:200]})",
                             allowed=", ".join(map(str, cols))[:200], value=name)
    v = cols[name]
    if isinstance(v, pl.Series):
        if not v.dtype.is_numeric():
            raise ParameterTypeError(name, f"column {name!r} must hold numbers, "
                                     f"got {v.dtype}")
        if v.null_count():
            raise ParameterError(name, f"column {name!r} has {v.null_count()} missing values")
        v = v.to_numpy()
    a = _check.array(name, v)
    if a.size > MAX_RECORD_SAMPLES:
        raise ParameterError(name, f"at most {MAX_RECORD_SAMPLES} samples per column, "
                             f"got {a.size}", allowed=f"<= {MAX_RECORD_SAMPLES}")
    if n is not None and a.size != n:
        raise ParameterError(name, f"column {name!r} has {a.size} samples, the time column "
                             f"{n}")
    bad = ~np.isfinite(a)
    if bad.any():
        raise ParameterError(name, f"column {name!r} has {int(bad.sum())} values that are "
                             f"not finite (first at sample {int(np.argmax(bad))})")
    return a


def speed_from_tacho(t: np.ndarray, pulses: np.ndarray, pulses_per_revolution: int) -> np.ndarray:
    """The speed (rpm) at every sample from a tachometer's pulse train: rising edges
    through the level midway between the signal's least and largest values, one
    revolution per ``pulses_per_revolution`` edges; the speed between two edges is
    placed at their midpoint and interpolated linearly (held outside)."""
    lo, hi = float(pulses.min()), float(pulses.max())
    if not hi > lo:
        raise ParameterError("tacho", "the tachometer signal has no pulses (it is constant)")
    up = pulses > 0.5 * (lo + hi)
    i = np.flatnonzero(~up[:-1] & up[1:]) + 1
    if i.size < 3:
        raise ParameterError("tacho", f"found {i.size} pulses; at least 3 are needed")
    # the crossing time by linear interpolation between the two samples around it
    level = 0.5 * (lo + hi)
    frac = (level - pulses[i - 1]) / (pulses[i] - pulses[i - 1])
    edges = t[i - 1] + frac * (t[i] - t[i - 1])
    dt = np.diff(edges)
    rpm = 60.0 / (dt * pulses_per_revolution)
    mid = 0.5 * (edges[1:] + edges[:-1])
    return np.interp(t, mid, rpm)


def _refine_peak(t: np.ndarray, x: np.ndarray, f0: float, width: float) -> float:
    """The frequency (Hz) within ``width`` of ``f0`` where the Hann-windowed discrete
    time Fourier transform of ``x`` peaks (for one line in white noise, the
    maximum-likelihood estimate, without the bias of an interpolation between bins):
    Newton's method on ``|S(f)|^2`` from ``f0``, with its first and second derivatives
    summed alongside ``S``; ``f0`` when a step would leave the interval."""
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(t.size) / t.size)
    wx = w * x
    tc = t - t.mean()  # centred time keeps the derivative sums well scaled
    f = f0
    for _ in range(8):
        e = wx * np.exp(-2j * np.pi * f * tc)
        s0, s1, s2 = e.sum(), np.dot(tc, e), np.dot(tc * tc, e)
        # S' = -2 pi i S1, S'' = -(2 pi)^2 S2 (derivatives in f)
        d1, d2 = -2j * np.pi * s1, -((2 * np.pi) ** 2) * s2
        p1 = 2.0 * (np.conj(s0) * d1).real
        p2 = 2.0 * ((np.conj(d1) * d1).real + (np.conj(s0) * d2).real)
        if not p2 < 0:
            return f
        step = -p1 / p2
        f_new = f + step
        if abs(f_new - f0) > width:
            return f
        f = f_new
        if abs(step) < 1e-10 * width:
            break
    return float(f)


def _line_amplitude(t: np.ndarray, x: np.ndarray, f: float) -> float:
    """The amplitude of a line at ``f`` (Hz) in ``x``: the Hann-windowed transform at
    ``f`` over half the window's sum (exact for a pure cosine at ``f``, up to the
    window's leakage from other lines). Noise adds to it only in quadrature, at the
    level of one bin, unlike the RMS, which holds all the noise."""
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(t.size) / t.size)
    return float(2.0 * abs(np.sum(w * x * np.exp(-2j * np.pi * f * (t - t.mean()))))
                 / w.sum())


def read_record(
    source: Any,
    *,
    time: str = "t",
    speed: str | None = None,
    speed_unit: Literal["rpm", "Hz", "rad/s"] = "rpm",
    tacho: str | None = None,
    pulses_per_revolution: int = 1,
    channels: Mapping[str, Sensor] | None = None,
) -> Record:
    """Read a measured record: a ``.csv`` or ``.npz`` file, a MATLAB ``.mat`` file (its
    one-dimensional numeric variables), an HDF5 ``.h5``/``.hdf5`` file (its
    one-dimensional numeric datasets as ``group/name``; needs h5py, the ``hdf5``
    extra), a TDMS ``.tdms`` file (its channels as ``group/channel`` and by the
    channel's name where unique; needs npTDMS, the ``tdms`` extra), a polars DataFrame
    or a mapping of column names to arrays.

    ``time``: the time column, in seconds, strictly increasing (sampling may be
    uneven: steps are found on the samples as they are; spectra need an even step
    within 1 %). The speed: a ``speed`` column in ``speed_unit``, or a ``tacho``
    column of pulses (``pulses_per_revolution`` per turn of the rotor). ``channels``:
    the sensor channels to keep, each with its :class:`Sensor` (default: every other
    numeric column, read as ``m/s^2`` with sensitivity 1).

    Raises :class:`~ballbal.exceptions.ParameterError` naming the column for a missing
    column, a column of another length, missing or non-finite values, a time that does
    not increase, and a record without a speed.
    """
    cols, what = _columns_of(source)
    _check.string("time", time)
    t = _column(cols, time, "time", None)
    if t.size < 16:
        raise ParameterError(time, f"a record needs at least 16 samples, got {t.size}")
    d = np.diff(t)
    if not np.all(d > 0):
        k = int(np.argmax(~(d > 0)))
        raise ParameterError(time, f"time must increase from sample to sample; it does not "
                             f"between samples {k} and {k + 1} ({t[k]!r} -> {t[k + 1]!r})")
    n = t.size
    if (speed is None) == (tacho is None):
        raise ParameterError("speed", "give the rotor's speed: a speed column (speed=) or a "
                             "tachometer column (tacho=), one of the two")
    if speed is not None:
        _check.string("speed", speed)
        _check.string("speed_unit", speed_unit)
        if speed_unit not in _SPEED_UNITS:
            raise ParameterError("speed_unit", f"must be one of {', '.join(_SPEED_UNITS)}, "
                                 f"got {speed_unit!r:.40}", allowed=", ".join(_SPEED_UNITS))
        rpm = _column(cols, speed, "speed", n) * _SPEED_UNITS[speed_unit]
        speed_source = f"column {speed!r} ({speed_unit})"
    else:
        assert tacho is not None
        _check.string("tacho", tacho)
        ppr = _check.integer("pulses_per_revolution", pulses_per_revolution, 1, 10**4)
        rpm = speed_from_tacho(t, _column(cols, tacho, "tacho", n), ppr)
        speed_source = f"tachometer {tacho!r} ({ppr} per revolution)"
    if channels is None:
        used = {time, speed, tacho}
        channels = {str(c): Sensor() for c in cols if c not in used}
    if not isinstance(channels, Mapping):
        raise ParameterTypeError("channels", "must be a mapping of column names to Sensor, "
                                 f"got {type(channels).__name__}", value=channels)
    if not channels:
        raise ParameterError("channels", "the record has no sensor channel")
    if len(channels) > MAX_CHANNELS:
        raise ParameterError("channels", f"at most {MAX_CHANNELS} channels, got {len(channels)}",
                             allowed=f"<= {MAX_CHANNELS}")
    data: dict[str, np.ndarray] = {}
    sensors: dict[str, Sensor] = {}
    for name, sensor in channels.items():
        if not isinstance(sensor, Sensor):
            raise ParameterTypeError(f"channels[{name!r}]", "must be a ballbal.rig.Sensor, "
                                     f"got {type(sensor).__name__}", value=sensor)
        data[name] = _column(cols, name, "channels", n) / sensor.sensitivity
        sensors[name] = sensor
    return Record(t=t, speed_rpm=rpm, channels=data, sensors=sensors,
                  source=f"{what}; speed from {speed_source}")


@dataclass(frozen=True, repr=False, eq=False)
class Record:
    """A measured record (see the module's description); made by :func:`read_record`.

    ``t``: seconds; ``speed_rpm``: the rotor's speed at every sample; ``channels``: each
    sensor's signal in its physical unit (``sensors[name].unit``); ``source``: where it
    came from."""

    t: np.ndarray
    speed_rpm: np.ndarray
    channels: dict[str, np.ndarray]
    sensors: dict[str, Sensor]
    source: str = ""
    _cache: dict[Any, Any] = field(default_factory=dict, compare=False)

    def __repr__(self) -> str:
        dur = float(self.t[-1] - self.t[0])
        return (f"Record({self.t.size} samples, {dur:.4g} s, speed "
                f"{self.speed_rpm.min():.0f}-{self.speed_rpm.max():.0f} rpm, channels "
                f"{', '.join(self.channels)})")

    def _repr_html_(self) -> str:
        rows = "".join(
            f"<tr><td>{html.escape(k)}</td><td>{html.escape(s.unit)}</td>"
            f"<td>{s.sensitivity:g} {html.escape(s.recorded_unit)}</td>"
            f"<td>{np.sqrt(np.mean(self.channels[k] ** 2)):.4g}</td></tr>"
            for k, s in self.sensors.items())
        return (f"<b>Record</b>: {self.t.size} samples over {self.t[-1] - self.t[0]:.4g} s, "
                f"speed {self.speed_rpm.min():.0f}&ndash;{self.speed_rpm.max():.0f} rpm "
                f"<br><small>{html.escape(self.source)}</small>"
                "<table><tr><th>channel</th><th>unit</th><th>sensitivity</th>"
                f"<th>RMS</th></tr>{rows}</table>")

    # -- steps --------------------------------------------------------------------------

    def steps(self, *, tolerance: float = 0.01, min_duration: float = 2.0,
              settle: float = 0.5, resolution: float = 0.05) -> pl.DataFrame:
        """The plateaus of a stepped sweep, in time order.

        The speed is averaged over windows of ``resolution`` seconds; a plateau is a run
        of windows within ``tolerance`` (relative) of the run's first window, lasting at
        least ``min_duration`` seconds (ramps between plateaus are left out). The settled
        segment leaves out the first ``settle`` fraction of each plateau.

        Columns: ``step`` (0, 1, ...), ``speed_rpm`` (mean over the settled segment),
        ``start``, ``stop``, ``settled_start`` (seconds), ``samples`` (in the settled
        segment), ``direction`` (``"up"``/``"down"`` from the previous step; ``"first"``).
        """
        tol = _check.real("tolerance", tolerance, 0.0, 0.5, lo_open=True)
        dur = _check.real("min_duration", min_duration, 0.0, math.inf, lo_open=True,
                          hi_open=True)
        frac = _check.real("settle", settle, 0.0, 1.0, hi_open=True)
        res = _check.real("resolution", resolution, 0.0, math.inf, lo_open=True,
                          hi_open=True)
        key = ("steps", tol, dur, frac, res)
        if key in self._cache:
            cached: pl.DataFrame = self._cache[key]
            return cached
        t, v = self.t, self.speed_rpm
        # window index of every sample; mean speed per window by bincount (one pass)
        w = ((t - t[0]) / res).astype(np.int64)
        nw = int(w[-1]) + 1
        counts = np.bincount(w, minlength=nw)
        mean = np.bincount(w, weights=v, minlength=nw) / np.maximum(counts, 1)
        filled = counts > 0
        rows: list[dict[str, Any]] = []
        i = 0
        while i < nw:
            if not filled[i]:
                i += 1
                continue
            ref = mean[i]
            j = i + 1
            while j < nw and (not filled[j] or abs(mean[j] - ref) <= tol * abs(ref)):
                j += 1
            # Trim the ends of the run back to the plateau: a run starts and ends on the
            # ramps' last and first windows that fall within the tolerance.
            run = np.flatnonzero(filled[i:j]) + i
            m = float(np.median(mean[run]))
            spread = float(np.median(np.abs(mean[run] - m)))
            close = np.abs(mean[run] - m) <= max(0.25 * tol * abs(m), 4.0 * spread)
            if close.any():
                lo_w, hi_w = run[np.argmax(close)], run[len(run) - 1 - np.argmax(close[::-1])]
            else:
                lo_w, hi_w = i, j - 1
            # The first and last windows may hold a few samples of the ramp or of the
            # next step (a window is close when its mean is): leave them out.
            if hi_w - lo_w >= 3:
                lo_w, hi_w = lo_w + 1, hi_w - 1
            t0, t1 = t[0] + lo_w * res, min(t[0] + (hi_w + 1) * res, t[-1])
            if t1 - t0 >= dur:
                ts = t0 + frac * (t1 - t0)
                a, b = np.searchsorted(t, [ts, t1])
                rows.append({"speed_rpm": float(v[a:b].mean()) if b > a else float(ref),
                             "start": float(t0), "stop": float(t1),
                             "settled_start": float(ts), "samples": int(b - a)})
                i = j
            else:
                i += 1
        prev = None
        for k, r in enumerate(rows):
            r["step"] = k
            r["direction"] = ("first" if prev is None else
                              "up" if r["speed_rpm"] > prev else "down")
            prev = r["speed_rpm"]
        schema = {"step": pl.Int64, "speed_rpm": pl.Float64, "start": pl.Float64,
                  "stop": pl.Float64, "settled_start": pl.Float64, "samples": pl.Int64,
                  "direction": pl.Utf8}
        df = pl.DataFrame(rows, schema=schema).select(list(schema))
        self._cache[key] = df
        return df

    def segment(self, step: int, channel: str | None = None, **step_options: Any
                ) -> tuple[np.ndarray, np.ndarray]:
        """The settled segment of ``step`` (a row of :meth:`steps`): times and the
        channel's signal (default: the first channel)."""
        st = self.steps(**step_options)
        k = _check.integer("step", step, 0, max(st.height - 1, 0))
        if st.height == 0:
            raise ParameterError("step", "the record has no step (see Record.steps)")
        name = self._channel(channel)
        a, b = np.searchsorted(self.t, [st["settled_start"][k], st["stop"][k]])
        return self.t[a:b], self.channels[name][a:b]

    def _channel(self, channel: str | None) -> str:
        if channel is None:
            return next(iter(self.channels))
        _check.string("channel", channel)
        if channel not in self.channels:
            raise ParameterError("channel", f"{channel!r:.40} is not a channel "
                                 f"({', '.join(self.channels)})",
                                 allowed=", ".join(self.channels), value=channel)
        return channel

    # -- per-step features ----------------------------------------------------------------

    def features(self, *, channel: str | None = None, eccentricity: float | None = None,
                 natural_frequency_rpm: float | None = None, sync_tolerance: float = 0.03,
                 min_revolutions: int = 8, **step_options: Any) -> pl.DataFrame:
        """One row per step (:meth:`steps`, whose options pass through): the settled
        segment of ``channel`` (default the first) reduced to

        - ``status``: ``"ok"``, or ``"too_short"`` where the settled segment holds fewer
          than ``min_revolutions`` turns of the rotor or its sampling is uneven (the
          features are then null);
        - ``main_frequency_rpm`` (the largest spectral line of the Hann-windowed
          spectrum, refined to the maximum of its continuous transform) and
          ``main_order`` (it over the speed);
        - ``synchronous``: the main line within ``sync_tolerance`` (relative) or 1.5
          bins of the speed;
        - ``rms`` and ``peak`` in the sensor's unit (column ``unit``), and with
          ``eccentricity`` (metres) and ``natural_frequency_rpm`` also ``rms_model`` and
          ``peak_model`` in the model's units (``e``, ``e w_n`` or ``e w_n^2``);
        - ``main_amplitude``: the main line's amplitude (the settled segment's Hann
          transform at ``main_frequency_rpm``), in the sensor's unit, and
          ``main_amplitude_model`` in the model's units as ``rms_model``; unlike the
          RMS it holds the noise of one spectral bin only;
        - ``resolution_rpm``: the spectrum's bin width.
        """
        name = self._channel(channel)
        sensor = self.sensors[name]
        sync = _check.real("sync_tolerance", sync_tolerance, 0.0, 0.5, lo_open=True)
        nrev = _check.integer("min_revolutions", min_revolutions, 1, 10**6)
        scale = None
        if (eccentricity is None) != (natural_frequency_rpm is None):
            raise ParameterError("eccentricity", "the model's units need both eccentricity "
                                 "and natural_frequency_rpm")
        if eccentricity is not None and natural_frequency_rpm is not None:
            e = _check.real("eccentricity", eccentricity, 0.0, math.inf, lo_open=True,
                            hi_open=True)
            fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                             lo_open=True, hi_open=True)
            wn = fn * 2 * math.pi / 60.0
            power = {"displacement": 0, "velocity": 1, "acceleration": 2}[sensor.quantity]
            scale = UNITS[sensor.unit][0] / (e * wn**power)
        st = self.steps(**step_options)
        rows = []
        for k in range(st.height):
            a, b = np.searchsorted(self.t, [st["settled_start"][k], st["stop"][k]])
            ts, xs = self.t[a:b], self.channels[name][a:b]
            sp = float(st["speed_rpm"][k])
            row: dict[str, Any] = {"step": k, "speed_rpm": sp, "status": "too_short",
                                   "main_frequency_rpm": None, "main_order": None,
                                   "synchronous": None, "rms": None, "peak": None,
                                   "rms_model": None, "peak_model": None,
                                   "resolution_rpm": None, "main_amplitude": None,
                                   "main_amplitude_model": None}
            turns = sp / 60.0 * (ts[-1] - ts[0]) if ts.size > 1 else 0.0
            even = ts.size > 16 and np.ptp(np.diff(ts)) <= 0.01 * np.mean(np.diff(ts))
            if turns >= nrev and even:
                x = xs - xs.mean()
                # Hann: a narrow main lobe, so that the peak's refinement between bins
                # holds (the flat-top's flat lobe would not locate it)
                spec = signal_spectrum(ts - ts[0], x, window="hann", time_unit="s")
                lines = label_peaks(spec, sp, column="frequency_rpm", max_peaks=8)
                top = lines.sort("amplitude", descending=True).row(0, named=True)
                bin_rpm = 60.0 / (ts[-1] - ts[0] + (ts[1] - ts[0]))
                f = 60.0 * _refine_peak(ts - ts[0], x, float(top["frequency"]) / 60.0,
                                        bin_rpm / 60.0)
                rms, peak = float(np.sqrt(np.mean(x**2))), float(np.max(np.abs(x)))
                row.update(status="ok", main_frequency_rpm=f, main_order=f / sp,
                           synchronous=bool(abs(f - sp) <= max(sync * sp, 1.5 * bin_rpm)),
                           rms=rms, peak=peak, resolution_rpm=bin_rpm)
                amp = _line_amplitude(ts - ts[0], x, f / 60.0)
                row.update(main_amplitude=amp)
                if scale is not None:
                    row.update(rms_model=rms * scale, peak_model=peak * scale,
                               main_amplitude_model=amp * scale)
            rows.append(row)
        schema = {"step": pl.Int64, "speed_rpm": pl.Float64, "status": pl.Utf8,
                  "main_frequency_rpm": pl.Float64, "main_order": pl.Float64,
                  "synchronous": pl.Boolean, "rms": pl.Float64, "peak": pl.Float64,
                  "rms_model": pl.Float64, "peak_model": pl.Float64,
                  "resolution_rpm": pl.Float64, "main_amplitude": pl.Float64,
                  "main_amplitude_model": pl.Float64}
        out = pl.DataFrame(rows, schema=schema)
        return out.with_columns(pl.lit(sensor.unit).alias("unit"),
                                st["direction"].alias("direction"))

    def transitions(self, **feature_options: Any) -> pl.DataFrame:
        """Where consecutive steps change between synchronous and non-synchronous
        motion (:meth:`features`, whose options pass through; steps whose status is not
        ``"ok"`` are skipped): ``from_speed_rpm``, ``to_speed_rpm``, ``speed_rpm`` (their
        midpoint) and ``uncertainty_rpm`` (half their distance), ``direction``
        (``"up"``/``"down"``), ``from_state`` and ``to_state`` (``"synchronous"`` or
        ``"non_synchronous"``)."""
        ft = self.features(**feature_options).filter(pl.col("status") == "ok")
        rows = []
        sp, sy = ft["speed_rpm"].to_list(), ft["synchronous"].to_list()
        for k in range(1, ft.height):
            if sy[k] != sy[k - 1]:
                state = {True: "synchronous", False: "non_synchronous"}
                rows.append({"from_speed_rpm": sp[k - 1], "to_speed_rpm": sp[k],
                             "speed_rpm": 0.5 * (sp[k - 1] + sp[k]),
                             "uncertainty_rpm": 0.5 * abs(sp[k] - sp[k - 1]),
                             "direction": "up" if sp[k] > sp[k - 1] else "down",
                             "from_state": state[sy[k - 1]], "to_state": state[sy[k]]})
        schema = {"from_speed_rpm": pl.Float64, "to_speed_rpm": pl.Float64,
                  "speed_rpm": pl.Float64, "uncertainty_rpm": pl.Float64,
                  "direction": pl.Utf8, "from_state": pl.Utf8, "to_state": pl.Utf8}
        return pl.DataFrame(rows, schema=schema)

    def plot(self, channel: str | None = None, ax: Any = None, **step_options: Any) -> Any:
        """The speed and a channel against time, the settled segments of the steps
        shaded; returns the figure."""
        from .plot import _pyplot

        plt = _pyplot()
        name = self._channel(channel)
        if ax is None:
            fig, (ax0, ax1) = plt.subplots(2, 1, sharex=True, figsize=(7, 4.5),
                                           constrained_layout=True)
        else:
            ax0, ax1 = ax
            fig = ax0.figure
        ax0.plot(self.t, self.speed_rpm, lw=1.0)
        ax0.set_ylabel("speed (rpm)")
        stride = max(1, self.t.size // 200_000)
        ax1.plot(self.t[::stride], self.channels[name][::stride], lw=0.4)
        ax1.set_ylabel(f"{name} ({self.sensors[name].unit})")
        ax1.set_xlabel("time (s)")
        for r in self.steps(**step_options).iter_rows(named=True):
            for a in (ax0, ax1):
                a.axvspan(r["settled_start"], r["stop"], color="0.9", zorder=0)
        return fig
