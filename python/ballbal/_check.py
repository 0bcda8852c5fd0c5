"""Type checks of the public functions' arguments, before anything reaches the core.

Python's own conversions fail with messages that do not name the parameter (``float("a")``:
"could not convert string to float"), turn ``True`` into 1 and ``2.5`` into 2 without a
word, and pyo3 raises ``OverflowError`` for a negative count. These helpers refuse such
values with a :class:`ParameterTypeError` / :class:`ParameterError` that names the
parameter and its allowed range. Value ranges that the core checks where it consumes the
value stay in the core (the option classes of :mod:`ballbal.options` check types only);
a count is refused here only when negative or huge, so that it never reaches the
conversion to ``usize``.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Sequence
from typing import Any, ParamSpec, TypeVar

import numpy as np

from .exceptions import ParameterError, ParameterTypeError

#: Most points of a scan grid whose table is held in memory (a row of about 25 columns
#: takes some 300 bytes: about 1.5 GB at this size); a scan streamed to ``out=`` holds
#: one chunk at a time.
MAX_GRID_POINTS = 5 * 10**6
#: Most points of a scan grid streamed to a directory with ``out=``.
MAX_STREAMED_POINTS = 10**9
#: Most values of one scan axis (every axis's values are held, checked and stored in
#: the scan directory's ``meta.json``).
MAX_AXIS_VALUES = 10**6
#: Most output times of one simulation (each a row of the returned table).
MAX_SAMPLES = 10**7
#: Most threads a scan may start.
MAX_THREADS = 1024
#: Largest integer a count may be (the core's counts are 64-bit).
_MAX_COUNT = 2**62

# --- Sizes of the bearing modules: bearing grids and grooves, the groove study, the
# rotor's output times and the spectra (kept in one block). Measured on the project's
# 2-core machine while other work ran. ---

#: Most finite-volume cells of one bearing grid (``n_theta * n_zeta``), set by Ctrl-C:
#: faer's sparse factorisations are single calls that cannot be interrupted, and the film
#: solvers poll between them. The longest stretch between two polls measured 0.25-0.9 s
#: (grooved finite film) up to 2^19 cells on the project's loaded 2-core machine, and
#: the plain film's sine sweep took 1.3 s at 2^20. An equilibrium or a trajectory solves
#: the film many times. (8000 x 2000 took 42 s and 8.4 GB per solve.)
MAX_BEARING_CELLS = 2**18
#: Most cells of a narrow-groove grid: its 9-point factorisation is the slower one, about
#: 1 s between polls at 2^18 cells and 0.3-0.7 s at this bound.
MAX_NARROW_GROOVE_CELLS = 2**17
#: Most cells around the bearing (``n_theta``): 32 cells per groove pitch of
#: :data:`MAX_GROOVES` grooves, and a cell of 1e-4 rad, far finer than any film needs.
MAX_BEARING_THETA = 2**16
#: Most cells along the bearing (``n_zeta``). The plain finite film solves one periodic
#: tridiagonal system per sine mode and holds ``n_zeta^2 / 4`` mode values: an ``8 x
#: 131072`` grid asked for some 34 GB and was killed; at 1024 the modes take 2 MB.
MAX_BEARING_ZETA = 1024
#: Most grooves of a bearing: the default grid of this many (16 cells per pitch, 32
#: along the length) is the largest allowed, :data:`MAX_BEARING_CELLS`. Herringbone
#: bearings have tens of grooves; narrow-groove theory stands for many more.
MAX_GROOVES = MAX_BEARING_CELLS // (16 * 32)
#: Most points of one groove study (the product of its axes). Each point is a film
#: solve, its linearised coefficients and the concentric stiffness: 0.04 s on the
#: default 256 x 32 grid of 8 grooves, so 1e5 points are over an hour on one thread.
MAX_GROOVE_POINTS = 10**5
#: Most film cells a groove study holds at once: each thread solves one point's grid at
#: a time, so threads times the largest point's cells (four grids of
#: :data:`MAX_BEARING_CELLS`, about a gigabyte with narrow-groove films).
MAX_STUDY_CELLS = 4 * MAX_BEARING_CELLS
#: Most frequencies :func:`ballbal.spectrum.label_lines` labels (and most peaks
#: :func:`~ballbal.spectrum.label_peaks` keeps): the line spacing is estimated by trying
#: every peak's offset against every peak, ``n^2`` work (1e8 at this bound).
MAX_LINES = 10**4


def axes(name: str, v: Any) -> Any:
    """A matplotlib ``Axes`` to draw into, or None (a new figure)."""
    if v is None:
        return None
    from matplotlib.axes import Axes

    if not isinstance(v, Axes):
        raise ParameterTypeError(name, f"must be a matplotlib Axes or None, got "
                                 f"{type(v).__name__}", allowed="Axes or None", value=v)
    return v


def _range_text(lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> str:
    def fmt(v: float) -> str:
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:g}" if isinstance(v, float) else str(v)
    return f"{'(' if lo_open else '['}{fmt(lo)}, {fmt(hi)}{')' if hi_open else ']'}"


def is_real(v: Any) -> bool:
    """A real number (numpy scalars included); a bool is not a parameter value."""
    return isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_))


def real(name: str, v: Any, lo: float = -math.inf, hi: float = math.inf, *,
         lo_open: bool = False, hi_open: bool = False, finite: bool = False) -> float:
    """``v`` as a float. Without bounds only the type is checked (the core checks the
    value); with bounds (or ``finite``) the value must be finite and inside them."""
    if not is_real(v):
        raise ParameterTypeError(name, f"must be a number, got {type(v).__name__} {v!r:.60}",
                                 value=v)
    try:
        x = float(v)
    except OverflowError as e:  # an int beyond the float range
        raise ParameterError(name, "is too large for a float", value=v) from e
    bounded = finite or lo > -math.inf or hi < math.inf
    if bounded:
        ok = (math.isfinite(x) and (x > lo if lo_open else x >= lo)
              and (x < hi if hi_open else x <= hi))
        if not ok:
            allowed = _range_text(lo, hi, lo_open, hi_open)
            raise ParameterError(name, f"must be a finite number in {allowed}, got {x}",
                                 allowed=allowed, value=v)
    return x


def integer(name: str, v: Any, lo: int = 0, hi: int = _MAX_COUNT) -> int:
    """``v`` as an int in ``[lo, hi]``; floats (even 2.0), bools and strings are refused."""
    if not isinstance(v, (numbers.Integral, np.integer)) or isinstance(v, (bool, np.bool_)):
        raise ParameterTypeError(
            name, f"must be an integer in {_range_text(lo, hi)}, got {type(v).__name__} "
            f"{v!r:.60}", allowed=_range_text(lo, hi), value=v)
    i = int(v)
    if not lo <= i <= hi:
        raise ParameterError(name, f"must be an integer in {_range_text(lo, hi)}, got {i}",
                             allowed=_range_text(lo, hi), value=v)
    return i


def optional_integer(name: str, v: Any, lo: int = 0, hi: int = _MAX_COUNT) -> int | None:
    return None if v is None else integer(name, v, lo, hi)


def boolean(name: str, v: Any) -> bool:
    """A bool (numpy's too); ``"no"`` or ``0`` are refused rather than read as truth values."""
    if not isinstance(v, (bool, np.bool_)):
        raise ParameterTypeError(name, f"must be True or False, got {v!r:.60}", value=v)
    return bool(v)


def string(name: str, v: Any) -> str:
    if not isinstance(v, str):
        raise ParameterTypeError(name, f"must be a string, got {type(v).__name__} {v!r:.60}",
                                 value=v)
    return v


def option(name: str, v: Any, kind: type[_T], default: _T, shown: str) -> _T:
    """An options object of type ``kind`` (``shown`` is its public name), or ``default``
    for ``None``."""
    if v is None:
        return default
    if not isinstance(v, kind):
        raise ParameterTypeError(name, f"must be a {shown}, got {type(v).__name__}", value=v)
    return v


def array(name: str, v: Any) -> np.ndarray:
    """A flat float64 array of finite or non-finite numbers (the core checks values)."""
    if isinstance(v, (str, bytes)) or v is None:
        raise ParameterTypeError(name, f"must be a sequence of numbers, got {v!r:.60}",
                                 value=v)
    try:
        a = np.asarray(v)
        if a.dtype == object or a.dtype.kind not in "iuf":
            raise TypeError(a.dtype)
        return np.ascontiguousarray(a, dtype=np.float64).ravel()
    except (TypeError, ValueError, OverflowError) as e:
        raise ParameterTypeError(name, f"must be a sequence of numbers, got {v!r:.60}",
                                 value=v) from e


def reals(name: str, v: Any) -> list[float]:
    """One number or a sequence of numbers, as a list."""
    if is_real(v):
        return [real(name, v)]
    return [float(x) for x in array(name, v)]


def path(name: str, v: Any) -> str | os.PathLike[str]:
    """A file or directory name: a non-empty string or path object. An empty name would
    mean the current directory, which is never what was meant."""
    if not isinstance(v, (str, os.PathLike)):
        raise ParameterTypeError(name, f"must be a path (str or os.PathLike), got "
                                 f"{type(v).__name__}", value=v)
    s = os.fspath(v)
    if not isinstance(s, str) or not s.strip():
        raise ParameterError(name, "must be a non-empty path", value=v)
    if "\0" in s:
        raise ParameterError(name, "must not contain a NUL character", value=v)
    return v


def patterns(name: str, v: Any) -> tuple[str, ...]:
    """Solution types for a scan: one string or a sequence of strings, no repeats (a
    repeated type would give two rows, converged and not_found, for one point)."""
    if isinstance(v, str):
        v = (v,)
    if not isinstance(v, Sequence) and not isinstance(v, (set, frozenset, np.ndarray)):
        raise ParameterTypeError(name, f"must be a list of solution types such as ['R-R'], "
                                 f"got {type(v).__name__}", value=v)
    out = tuple(v)
    for p in out:
        string(name, p)
    seen: set[str] = set()
    for p in out:
        if p in seen:
            raise ParameterError(name, f"{p!r} is given twice", value=v)
        seen.add(p)
    return out


def samples_count(duration: float, dt: float, *, duration_name: str, dt_name: str = "dt") -> int:
    """Number of output times of ``arange(0, duration, dt)``, refused before it is
    allocated when above :data:`MAX_SAMPLES`."""
    count = math.floor(duration / dt) + 1
    if count > MAX_SAMPLES:
        raise ParameterError(
            duration_name, f"{duration:g} time units at {dt_name} = {dt:g} would give "
            f"{count:.3g} output times, at most {MAX_SAMPLES:.0e}: shorten it or raise {dt_name}",
            allowed=f"at most {MAX_SAMPLES:.0e} output times", value=duration)
    return count


def grid_points(counts: Sequence[int], names: Sequence[str], streamed: bool) -> int:
    """The number of grid points, refused when above the limit for a table held in
    memory (:data:`MAX_GRID_POINTS`) or streamed to ``out=`` (:data:`MAX_STREAMED_POINTS`)."""
    for name, c in zip(names, counts, strict=True):
        if c > MAX_AXIS_VALUES:
            raise ParameterError(name, f"{c} values, at most {MAX_AXIS_VALUES:.0e} per axis",
                                 allowed=f"at most {MAX_AXIS_VALUES:.0e} values", value=c)
    limit = MAX_STREAMED_POINTS if streamed else MAX_GRID_POINTS
    total = math.prod(counts)
    if total > limit:
        # Name the longest axis: the one to cut.
        k = max(range(len(counts)), key=lambda i: counts[i])
        where = "streamed to out=" if streamed else "held in memory (without out=)"
        raise ParameterError(
            names[k], f"the grid has {total:.3g} points, at most {limit:.0e} for a scan "
            f"{where}", allowed=f"at most {limit:.0e} grid points", value=total)
    return total


def axis_count(name: str, steps: float) -> int:
    """The number of values ``floor(steps) + 1`` of a ``(start, stop, step)`` axis with
    ``steps = (stop - start) / step``, refused before they are made when this axis alone
    exceeds :data:`MAX_AXIS_VALUES`."""
    if not steps < MAX_AXIS_VALUES:  # also inf and NaN
        raise ParameterError(
            name, f"(start, stop, step) gives {steps + 1:.3g} values, at most "
            f"{MAX_AXIS_VALUES:.0e} per axis", value=steps,
            allowed=f"at most {MAX_AXIS_VALUES:.0e} values")
    return int(math.floor(steps + 1e-9)) + 1




def sequence(name: str, v: Any, *, empty: bool = False) -> list[Any]:
    """The items of a list or tuple (or array); a string or a scalar is refused, and so
    is an empty one unless ``empty`` (where an empty list means "none of these")."""
    if isinstance(v, (str, bytes)) or not isinstance(v, (Sequence, np.ndarray)):
        raise ParameterTypeError(name, f"must be a list of values, got {type(v).__name__}",
                                 value=v)
    items = list(v)
    if not items and not empty:
        raise ParameterError(name, "must hold at least one value", value=v)
    return items


_T = TypeVar("_T")
_P = ParamSpec("_P")
_R = TypeVar("_R")


# --- Sizes of the analyses: sweeps, basins, balance maps, accuracy_cost, continuation
# and the models (kept in one block; other bounds are above). ---

#: Most balls a model may have (a balancer's ``eta``, a scene file's ``balls``, the
#: command line's ``--balls``): one bound everywhere. The equilibrium search tries
#: ``max(600, 25 n)`` starts of an ``n + 2`` unknown Newton solve, so its work grows
#: about as ``n^4``: at 64 balls it takes 9 s (23 s with ball springs; 0.8 s at 32) on a
#: loaded 2-core machine, at 1000 it would take days.
MAX_BALLS = 64
#: Most starts of one basin map (grid points ``len(b1) * len(b2)`` or ``n^2``, or
#: ``samples``). Each start is a simulation of ``t_end`` time units (milliseconds to a
#: second), and the starts and their table are held in memory: a million is a
#: thousand-by-thousand map, hours of work at the default ``t_end``.
MAX_BASIN_STARTS = 10**6
#: Most speed steps of one sweep (``"up-down"`` makes ``2 len(speeds) - 1`` of them).
#: Each step is a simulation of ``dwell`` time units, run one after the other since
#: every step starts from the state the last one left; ten thousand steps at the
#: default dwell are hours.
MAX_SWEEP_STEPS = 10**4
#: Most points of a balance map (the product of its axes). The core holds one scene and
#: one equilibrium with its eigenvalues per point, all at once: measured 3.7 kB a point
#: with 2 balls, 12 kB with 64, so 0.4 to 1.2 GB at this bound (and 20 s of work with 2
#: balls, over an hour with 64).
MAX_MAP_POINTS = 10**5
#: Most points of one continuation (``Continuation.max_points``). Every point keeps
#: its solution (up to ``(n + 2)(2 N + 1)`` coefficients, multipliers, a Python
#: solution object): at a hundred thousand points a branch is already hundreds of MB.
MAX_BRANCH_POINTS = 10**5
#: Most Newton iterations per continuation step (``Continuation.max_newton``): a
#: corrector that has not converged in a hundred iterations halves the step instead.
MAX_NEWTON = 100
#: Largest ``Omega`` for which :func:`ballbal.periodic` searches its start by
#: simulation (without ``guess``). The balls turn ``Omega`` radians per time unit, so the
#: integrator's steps per time unit grow with it (about 20 at Tien's (2011) 1.2, 2000 at
#: 100); a pattern that no start reaches is simulated some 100 times for ``settle +
#: window`` time units: 4 s at 1.2, 12 s at 10, 22 s at 30, 106 s at 100, many minutes at
#: 1e3 (one loaded 2-core machine). Balancers run at a few times the support's natural
#: frequency (Tien (2011) below 3): 30 leaves a wide margin.
MAX_SEARCH_OMEGA = 30.0
#: Largest damping ratio ``zeta`` and ``zeta_b`` for the same search: past a few times
#: critical damping the explicit integrator's step is held by stability, and the search
#: that finds nothing takes 15 s at 30 but 85 to 92 s at 100. No rig's support or track
#: is damped more than a few times critically.
MAX_SEARCH_DAMPING = 30.0
#: Most values of one knob of :func:`ballbal.accuracy_cost` (``N``, ``samples``,
#: ``tol``, ``rtol``, ``magnus_rtol``) and of a :func:`ballbal.track_damping_study`:
#: each value is a full solve (``repeats`` times) or simulation.
MAX_STUDY_VALUES = 1000
#: Most parameter values of one branch's ``at=`` (the core's ``MAX_USER_POINTS``,
#: checked there too): each is a solve, and a judged point, wherever the branch crosses it.
MAX_USER_POINTS = 1000
#: Most event names in one branch's ``stop=`` (there are fewer events than this; a
#: longer list is a mistake).
MAX_STOP_EVENTS = 32


def vector(name: str, v: Any, max_size: int, *, empty: bool = False) -> np.ndarray:
    """One number or a one-dimensional list of them (a numpy array, a polars or pandas
    series) as a float64 array of finite numbers, at most ``max_size`` of them, refused
    before it is converted when longer. Unlike :func:`array`, a nested list or 2-D array
    is refused (flattening it would hide the mistake), and so are NaN and inf; an empty
    one too unless ``empty``."""
    if is_real(v) or (isinstance(v, np.ndarray) and v.ndim == 0):
        v = np.reshape(v, 1)
    if isinstance(v, (str, bytes)) or not (isinstance(v, (Sequence, np.ndarray))
                                           or hasattr(v, "__array__")):
        raise ParameterTypeError(name, f"must be a list of numbers, got "
                                 f"{type(v).__name__} {v!r:.60}", value=v)
    size = len(v)
    if size > max_size:
        raise ParameterError(name, f"{size} values, at most {max_size}",
                             allowed=f"at most {max_size} values", value=size)
    try:
        shape = np.shape(v)
    except ValueError:  # ragged: nested lists of different lengths
        shape = (size, -1)
    if len(shape) != 1:
        got = f"an array of shape {shape}" if min(shape) >= 0 else "nested lists"
        raise ParameterError(name, f"must be a flat list of numbers, got {got}", value=v)
    a = array(name, v)
    if a.size == 0 and not empty:
        raise ParameterError(name, "must hold at least one value", value=v)
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise ParameterError(name, f"value {bad[0]} is {a[bad[0]]}: every value must be "
                             "finite", allowed="finite numbers", value=v)
    return a


def axis(name: str, spec: Any, max_size: int = MAX_AXIS_VALUES) -> np.ndarray:
    """One grid axis, read the same way by every gridded function (scan, balance_map,
    basins, speed_sweep, the command line), so that the same axis gives the same floats
    everywhere. ``(start, stop, step)`` (a tuple) or ``"start:stop:step"``: a range with
    ``stop`` included, ``round(start + step * i, 12)`` for ``i = 0, 1, ...`` (rounded so
    that ``(1.0, 2.0, 0.1)`` gives 1.2, not 1.2000000000000002); anything else (a list,
    an array, one number): explicit values, kept as given. At most ``max_size`` values,
    all finite, none given twice (each value has one index in a gridded table)."""
    if isinstance(spec, str):
        try:
            parts = [float(p) for p in spec.split(":")]
        except ValueError as e:
            raise ParameterError(name, f"give start:stop:step, got {spec!r}") from e
        if len(parts) != 3:
            raise ParameterError(name, f"give start:stop:step, got {spec!r}")
        spec = (parts[0], parts[1], parts[2])
    if isinstance(spec, tuple) and len(spec) == 3:
        start, stop, step = (real(name, v) for v in spec)
        if not all(math.isfinite(v) for v in (start, stop, step)):
            raise ParameterError(name, f"(start, stop, step) must be finite, got {spec}")
        if step <= 0 or stop < start:
            raise ParameterError(
                name, f"(start, stop, step) needs step > 0 and stop >= start, got {spec}"
            )
        count = axis_count(name, (stop - start) / step)
        at_most(name, count, max_size, "values")
        vals = np.round(start + step * np.arange(count), 12)
    else:
        vals = vector(name, spec, max_size)
    if not np.all(np.isfinite(vals)):
        raise ParameterError(name, "grid values must be finite (no NaN or inf)")
    if np.unique(vals).size != vals.size:
        u, counts = np.unique(vals, return_counts=True)
        raise ParameterError(name, f"value {u[counts > 1][0]} is given twice: each grid "
                             "value once", value=spec)
    return vals


def at_most(name: str, size: int, limit: int, what: str) -> int:
    """``size`` (a count the arguments imply: grid points, steps), refused above
    ``limit`` with an error naming ``name``, the argument to cut."""
    if size > limit:
        raise ParameterError(name, f"gives {size:.3g} {what}, at most {limit:.3g}",
                             allowed=f"at most {limit:.3g} {what}", value=size)
    return size
