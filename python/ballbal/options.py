"""The analyses' options as frozen dataclasses, mirroring the core's option structs.

The native module reads these objects by attribute. Each is checked when it is made:
types here, values by the core's own checks (errors name the option and its range);
the only checks left to an analysis are those that need its model (the largest
harmonic-balance system a model of that size allows). One vocabulary:
``rtol``/``atol`` are always integration tolerances (relative, absolute) of the
Dormand–Prince integrator that uses them: :class:`Floquet`'s of the monodromy,
:class:`GuessSearch`'s of the simulations that find starts. Mathematics (what is
computed) is apart from execution: where and how a scan or a basin grid runs
(``threads=``, ``chunk=``, ``executor=``, ``progress=``, ``out=``), which never changes
a result and is given as keywords of the call.

``periodic()`` and ``scan()`` mean the same by every option but differ in some
defaults, on purpose: a scan solves thousands of points, continues each solution to
its neighbours (so its starts only need to land in Newton's basin) and keeps the
verdicts that are certain at its looser tolerances. :data:`PERIODIC_DEFAULTS` and
:data:`SCAN_DEFAULTS` are the two sets; the differences:

====================================  =================  ===============
option                                ``periodic()``     ``scan()``
====================================  =================  ===============
``HarmonicBalance.target`` (auto)     1e-6               1e-4
``Floquet.rtol``, ``atol``            1e-8, 1e-10        1e-6, 1e-9
``Floquet.max_steps``                 200 000            20 000
``Floquet.hill``                      True               True
``Floquet.hill_band``                 None               0.2
``Floquet.hill_target``               ``"multipliers"``  ``"verdict"``
``Floquet.method``                    ``"rk45"``         ``"magnus"``
``GuessSearch.settle``, ``window``    1500, 2500         1000, 2000
``GuessSearch.rtol``, ``atol``        1e-9, 1e-11        1e-5, 1e-8
====================================  =================  ===============

Branches and curves of periodic solutions (:data:`BRANCH_DEFAULTS`) take
``periodic()``'s defaults but the scan's way to multipliers at every point: Magnus'
monodromy (at ``periodic()``'s ``rtol`` 1e-8) and Hill's method only where the verdict is
in doubt (``hill_band`` 0.2, ``hill_target`` ``"verdict"``).
"""

from __future__ import annotations

import functools
import inspect
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, fields, replace
from typing import Any, ClassVar, Literal, TypeVar, cast

from . import _check, _native
from .exceptions import ParameterError, ParameterTypeError

_F = TypeVar("_F", bound=Callable[..., Any])

#: Harmonics ``N = "auto"`` starts from.
AUTO_START = 3

#: A scan's default ``Floquet.hill_band``: Hill cross-checks the solutions whose
#: leading non-trivial multiplier lies within it of the unit circle (and those without a
#: monodromy verdict). Hill beside every monodromy, on the nine Tien (2011) maps at N = 3 and
#: 8 and two fine grids (all three types, 21 879 solutions), contradicted no verdict and
#: gave the monodromy's own everywhere outside it but once (a modulus-55 orbit it left
#: undetermined); 7 % of those solutions lie inside, and a fine-grid scan costs 4 to 8 %
#: more with the default than without Hill, against 80 to 86 % with Hill everywhere.
SCAN_HILL_BAND = 0.2


def _reals(obj: Any, *names: str) -> None:
    for n in names:
        object.__setattr__(obj, n, _check.real(n, getattr(obj, n)))


def _counts(obj: Any, *names: str) -> None:
    # Non-negative only: the range is the core's; a negative count cannot reach it.
    for n in names:
        object.__setattr__(obj, n, _check.integer(n, getattr(obj, n)))


def _flags(obj: Any, *names: str) -> None:
    for n in names:
        object.__setattr__(obj, n, _check.boolean(n, getattr(obj, n)))


def _nested(obj: Any, name: str, kind: type) -> None:
    v = getattr(obj, name)
    if not isinstance(v, kind):
        raise ParameterTypeError(name, f"must be a ballbal.{kind.__name__}, got "
                                 f"{type(v).__name__}", value=v)


@dataclass(frozen=True)
class HarmonicBalance:
    """Newton–IHB (the core's ``HbOptions`` and ``AutoHarmonics``).

    ``N``: harmonics, or ``"auto"``: start at :data:`AUTO_START` and raise N (solving
    from the last) until the highest harmonic relative to the motion (``tail``) and the
    trivial multiplier's distance from 1 are below ``target``, at most ``N_max``
    (``target`` and ``N_max`` apply to ``"auto"`` only). ``samples``: time samples per
    period (None: the core's default for N). Newton stops when the residual's max-norm
    is below ``tol`` and the last step's below ``step_tol``, or after ``max_iter``
    iterations.
    """

    N: int | Literal["auto"] = 3
    target: float = 1e-6
    N_max: int = 32
    samples: int | None = None
    tol: float = 1e-10
    step_tol: float = 1e-8
    max_iter: int = 50

    def __post_init__(self) -> None:
        if isinstance(self.N, str):
            if self.N != "auto":
                raise ParameterError("N", f"must be an integer in [1, 256] or 'auto', got "
                                     f"{self.N!r:.60}", allowed="[1, 256] or 'auto'",
                                     value=self.N)
        else:
            object.__setattr__(self, "N", _check.integer("N", self.N))
        _reals(self, "target", "tol", "step_tol")
        _counts(self, "N_max", "max_iter")
        object.__setattr__(self, "samples", _check.optional_integer("samples", self.samples))
        # What the binding reads, stored rather than computed by properties: reading a
        # property runs Python code, where a Ctrl-C raised during the binding's argument
        # extraction surfaced as a TypeError instead of KeyboardInterrupt.
        auto = self.N == "auto"
        object.__setattr__(self, "_start", AUTO_START if auto else int(self.N))
        object.__setattr__(self, "_auto_target", self.target if auto else None)
        _native.validate_harmonic_balance(self)

    # Instance attributes set above; declared as ClassVar so that they stay out of the
    # dataclass' fields (its equality, asdict and the scan files' metadata).
    _start: ClassVar[int]
    _auto_target: ClassVar[float | None]


@dataclass(frozen=True)
class Floquet:
    """Stability of a periodic solution (the core's ``FloquetOptions``, and Hill's
    method).

    ``monodromy``: integrate the monodromy matrix over one period (Dormand–Prince at
    ``rtol``, ``atol``, at most ``max_steps`` steps; a longer integration ends in
    ``floquet_error`` and an undetermined verdict). A verdict needs the largest
    non-trivial modulus further than ``max(margin, trivial_error)`` from 1, and no
    verdict is given unless the trivial multiplier is within ``max_trivial`` of 1.
    ``hill``: a second estimate by Hill's method (eigenvalues of the Hill matrix, no
    integration), judged with the same ``margin`` and ``max_trivial`` (with
    ``monodromy=False`` the core judges it with its defaults, 1e-6 and 0.1). The values
    are checked even with ``monodromy=False``. ``hill_target``: how far Hill's truncation
    is enlarged. ``"multipliers"``: until its error estimate is below 1e-7 (the
    multipliers to that). ``"verdict"`` (a scan's, whose table keeps Hill's verdict but not
    its multipliers): only until the verdict is settled, i.e. the leading non-trivial
    modulus is ten estimates or more from 1, or the estimate is below the larger of 1e-6
    and the trivial multiplier's error (a verdict still open then is undetermined); a
    third to a tenth of the cost, with multipliers only as good as the estimate (1e-2 at
    worst).

    ``hill_band``: None runs Hill on every solution. A number makes Hill a cross-check
    of the monodromy where it leaves the verdict in some doubt: the monodromy failed or
    gave no verdict, or its leading non-trivial modulus is within ``hill_band`` of 1, or
    within ten times its own error (the trivial multiplier's, or Magnus' estimate) of 1.
    Elsewhere ``hill_stability`` is null: a verdict that far from the unit circle would
    need an error many times what the monodromy's certificates measured to change. With
    ``monodromy=False`` a band leaves nothing to cross-check, and Hill does not run.

    ``method``: how the monodromy is computed. ``"rk45"``: the adaptive
    Dormand–Prince integration described above. ``"magnus"``: sixth-order Magnus steps
    on a fixed grid along the series (the linearisation is known in closed form there),
    the grid doubled until two successive grids' multipliers agree; ``rtol`` is then the
    multipliers' accuracy asked for (relative to the larger of 1 and their modulus;
    ``atol`` unused), the estimated error widens the margin like ``trivial_error``, and
    ``max_steps`` bounds the steps of all grids together.

    ``refine``: every verdict is judged against a bound on the leading modulus' error
    (``modulus_error``, from a solve with more harmonics; see :func:`~ballbal.periodic`).
    Where the bound leaves the verdict open, ``True`` (the default) raises the harmonics
    of that solution, up to 27, before calling it undetermined, so a result's ``N`` may
    exceed the one asked for; ``False`` keeps the truncation asked for (a study of one
    ``N``) and leaves such a verdict undetermined.
    """

    rtol: float = 1e-8
    atol: float = 1e-10
    margin: float = 1e-6
    max_steps: int = 200_000
    max_trivial: float = 0.1
    monodromy: bool = True
    hill: bool = True
    method: Literal["rk45", "magnus"] = "rk45"
    hill_target: Literal["multipliers", "verdict"] = "multipliers"
    hill_band: float | None = None
    refine: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "method", _check.string("method", self.method))
        object.__setattr__(self, "hill_target", _check.string("hill_target", self.hill_target))
        if self.hill_band is not None:
            object.__setattr__(self, "hill_band", _check.real("hill_band", self.hill_band))
        _reals(self, "rtol", "atol", "margin", "max_trivial")
        _counts(self, "max_steps")
        _flags(self, "monodromy", "hill", "refine")
        _native.validate_floquet(self)


@dataclass(frozen=True)
class GuessSearch:
    """Starts for Newton from time simulations (the core's ``GuessOptions``).

    Each start is simulated for ``settle`` time units (transients), then up to
    ``window`` more to measure the period, at integration tolerances ``rtol``,
    ``atol``. A scan simulates ``starts`` initial states at ``seeds`` points per axis
    (``periodic()`` tries the core's fixed set of starts and ignores both).
    """

    settle: float = 1500.0
    window: float = 2500.0
    rtol: float = 1e-9
    # rtol / 100 computed as periodic() always did (1e-11 itself is one ulp away).
    atol: float = 1e-9 * 1e-2
    seeds: int = 4
    starts: int = 4

    def __post_init__(self) -> None:
        _reals(self, "settle", "window", "rtol", "atol")
        _counts(self, "seeds", "starts")
        _native.validate_guess(self)


@dataclass(frozen=True)
class PeriodicOptions:
    """Everything :func:`ballbal.periodic` computes with (the core's
    ``PeriodicOptions``). ``max_closure``: largest integrated ODE defect of a converged
    series (above: ``not_closed``); ``max_tail``: largest highest-harmonic ratio (above:
    ``truncated``). See :func:`ballbal.periodic` for the certificates."""

    harmonic_balance: HarmonicBalance = field(default_factory=HarmonicBalance)
    floquet: Floquet = field(default_factory=Floquet)
    guess: GuessSearch = field(default_factory=GuessSearch)
    max_closure: float = 6.0
    max_tail: float = 0.25

    def __post_init__(self) -> None:
        _nested(self, "harmonic_balance", HarmonicBalance)
        _nested(self, "floquet", Floquet)
        _nested(self, "guess", GuessSearch)
        _reals(self, "max_closure", "max_tail")
        _native.validate_periodic_options(self)


@dataclass(frozen=True)
class Collocation:
    """Orthogonal collocation on an adaptive mesh (the core's ``CollocOptions``), the
    discretisation :func:`ballbal.periodic` uses with ``method="collocation"``, and with
    ``method="auto"`` where harmonic balance's certificates refuse its series.

    ``ntst`` mesh intervals (2 to 10 000) with ``ncol`` Gauss points each (1 to 7): the
    orbit is a piecewise polynomial of degree ``ncol`` in time. Newton stops when the
    residual's max-norm is below ``tol`` and the last step's (relative) below
    ``step_tol``, or after ``max_iter`` iterations (1 to 1000). ``adapt``: mesh
    adaptations after the first convergence (0 to 100), each moving the mesh points so
    that they equidistribute the error estimate (they crowd into the fast jump of a
    long-period orbit), then Newton again.

    ``ntst = 50`` by default: at 20 (AUTO's usual) the discretised monodromy's leading
    multiplier near the slow end of the merged R-R branch (Omega 0.93) is 0.41 where the
    integrated one is 1e-8, too far for its bound to give a verdict; at 50 it is 0.009.
    """

    ntst: int = 50
    ncol: int = 4
    tol: float = 1e-10
    step_tol: float = 1e-10
    max_iter: int = 30
    adapt: int = 3

    def __post_init__(self) -> None:
        _counts(self, "ntst", "ncol", "max_iter", "adapt")
        _reals(self, "tol", "step_tol")
        _native.validate_collocation(self)


def _scan_floquet() -> Floquet:
    # Magnus at rtol 1e-6 gives the multipliers to ~2e-7 for a third to a sixth of
    # RK45's cost at rtol 1e-6 (multipliers to ~4e-6); see bench_periodic.py. Hill's
    # cross-check only as far as its verdict needs, and only where the monodromy leaves
    # the verdict in doubt (SCAN_HILL_BAND): beside every monodromy it costs 1.5 to 2
    # Magnus monodromies and adds 70 to 100 % to a continuation-bound scan.
    return Floquet(rtol=1e-6, atol=1e-9, max_steps=20_000, hill=True, method="magnus",
                   hill_target="verdict", hill_band=SCAN_HILL_BAND)


def _branch_floquet() -> Floquet:
    # Multipliers at every point of a branch: RK45 at rtol 1e-8 and Hill's multipliers
    # everywhere made issue 33's matched branch (HB N = 24, the merged R-R orbit at zeta_b
    # 0.1, 1.2 -> BP -> LP -> 1.3 and 1.2 -> 0.93, 67 points) 2.6 times as slow as without
    # multipliers; Magnus at the same rtol with Hill in the band 1.5 times, with the same
    # verdicts and events on four branches (N = 8 and 24, 790 points; a branch's time
    # x0.27 to x0.74). RK45's stable leading moduli there were off by 4e-8 against
    # modulus_error ~6e-14 (the trivial multiplier does not see that error); Magnus' are
    # within 4e-11 of an rtol-1e-12 integration and carry their own error estimate.
    return Floquet(method="magnus", hill=True, hill_target="verdict", hill_band=SCAN_HILL_BAND)


def _scan_guess() -> GuessSearch:
    return GuessSearch(settle=1000.0, window=2000.0, rtol=1e-5, atol=1e-5 * 1e-3)


@dataclass(frozen=True)
class ScanOptions:
    """Everything :func:`ballbal.scan` computes with: a periodic solve's options (with
    the scan's defaults, see the module's table) and ``block``, the values of the last
    axis per continuation block (None: about 1024 points, fixed by the grid's shape).
    ``block`` is mathematics, not execution: continuation does not cross block edges,
    so smaller blocks find fewer *unstable* solutions (which only continuation reaches).
    The stable ones are also sought at every block's own points by gap seeds, and on
    the maps measured (Tien's map at zeta 0.02, zeta_b 0.05, three types, blocks of 3
    and 7 against one) the stable rows do not depend on it."""

    harmonic_balance: HarmonicBalance = field(
        default_factory=lambda: HarmonicBalance(target=1e-4))
    floquet: Floquet = field(default_factory=_scan_floquet)
    guess: GuessSearch = field(default_factory=_scan_guess)
    max_closure: float = 6.0
    max_tail: float = 0.25
    block: int | None = None

    def __post_init__(self) -> None:
        _nested(self, "harmonic_balance", HarmonicBalance)
        _nested(self, "floquet", Floquet)
        _nested(self, "guess", GuessSearch)
        _reals(self, "max_closure", "max_tail")
        if self.block is not None:
            object.__setattr__(self, "block", _check.integer("block", self.block, 1))
        _native.validate_periodic_options(self)


@dataclass(frozen=True)
class _Execution:
    """Where and how a scan or a basin grid runs (their keywords, checked together);
    none of it changes the table.

    ``threads``: cores for the core's parallel loop (default: all here; 1 per task on
    an ``executor``). ``chunk``: values of the last axis per chunk, rounded up to whole
    blocks (default one block): the unit of progress, interruption, resumption, files
    and executor tasks. ``executor``: a ``concurrent.futures`` executor or Dask
    ``Client`` running the chunks as tasks. ``progress``: True for a progress bar, or a
    callable ``f(done_points, total_points)``. ``out``: a directory the chunks are
    written to (and resumed from); ``lazy``: return a ``polars.LazyFrame`` over its
    files.
    """

    threads: int | None = None
    chunk: int | None = None
    executor: Any = None
    progress: bool | Callable[[int, int], Any] = False
    out: str | os.PathLike[str] | None = None
    lazy: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "threads", _check.optional_integer(
            "threads", self.threads, 1, _check.MAX_THREADS))
        object.__setattr__(self, "chunk", _check.optional_integer("chunk", self.chunk, 1))
        if self.out is not None:
            _check.path("out", self.out)
        _flags(self, "lazy")


PERIODIC_DEFAULTS = PeriodicOptions()
#: The periodic options of :func:`~ballbal.continuation.periodic_branch` and
#: :func:`~ballbal.continuation.periodic_curve` by default: :data:`PERIODIC_DEFAULTS`
#: with Magnus' monodromy and Hill's method only where the verdict is in doubt (the
#: module's note).
BRANCH_DEFAULTS = PeriodicOptions(floquet=_branch_floquet())
COLLOCATION_DEFAULTS = Collocation()
SCAN_DEFAULTS = ScanOptions()

#: The flat keywords ``periodic()``, ``scan()`` and ``switch()`` took beside the option
#: classes, removed: the field of the options that replaces each (``floquet.hill``:
#: ``options=PeriodicOptions(floquet=Floquet(hill=...))``), for the error that a caller
#: of the old keyword gets. ``N=`` stays a keyword: the harmonics are the usual call.
REMOVED_KEYWORDS: dict[str, str] = {
    "target": "harmonic_balance.target", "N_max": "harmonic_balance.N_max",
    "samples": "harmonic_balance.samples", "tol": "harmonic_balance.tol",
    "step_tol": "harmonic_balance.step_tol", "max_iter": "harmonic_balance.max_iter",
    "floquet": "floquet.monodromy", "hill": "floquet.hill", "rtol": "floquet.rtol",
    "atol": "floquet.atol", "margin": "floquet.margin", "max_steps": "floquet.max_steps",
    "max_trivial": "floquet.max_trivial", "floquet_method": "floquet.method",
    "hill_target": "floquet.hill_target", "hill_band": "floquet.hill_band",
    "refine": "floquet.refine",
    "settle": "guess.settle", "window": "guess.window", "guess_rtol": "guess.rtol",
    "guess_atol": "guess.atol", "seeds": "guess.seeds", "starts": "guess.starts",
    "max_closure": "max_closure", "max_tail": "max_tail", "block": "block",
}
#: What a flat keyword set besides its field, said in its error.
_ALSO = {"hill": "; hill=True also set floquet.hill_band=None (Hill on every solution)",
         "guess_rtol": "; it also set guess.atol to rtol / 100 (periodic) or rtol / 1000 "
                       "(scan)"}
#: The option classes the parts of a field's path name.
_PARTS = {"harmonic_balance": "HarmonicBalance", "floquet": "Floquet",
          "guess": "GuessSearch"}


def refuse_keywords(where: str, options_class: type, keywords: Iterable[str]) -> None:
    """Raises for the first of ``keywords`` (ones ``where()`` does not take): a removed
    flat option keyword that ``options_class`` has a field for as
    :class:`~ballbal.exceptions.ParameterTypeError` naming that field, any other as
    Python's ``TypeError``."""
    cls = options_class.__name__
    for k in keywords:
        path = REMOVED_KEYWORDS.get(k)
        part, _, name = (path or "").rpartition(".")
        if path is None or (part or name) not in option_names(options_class):
            raise TypeError(f"{where}() got an unexpected keyword argument {k!r}")
        if not part:
            how = f"options={cls}({name}=...)"
        elif options_class is ScanOptions:
            # A scan's parts have defaults of their own: changed from them, not rebuilt.
            how = f"options={cls}({part}=replace(SCAN_DEFAULTS.{part}, {name}=...))"
        else:
            how = f"options={cls}({part}={_PARTS[part]}({name}=...))"
        raise ParameterTypeError(
            k, f"{where}() takes no {k}= keyword: options are dataclasses, set "
            f"{cls}.{path} instead ({how}){_ALSO.get(k, '')}", allowed=f"{cls}.{path}")


def refuses_keywords(options_class: type) -> Callable[[_F], _F]:
    """Makes a function without ``**keywords`` refuse a removed flat option keyword with
    :func:`refuse_keywords`' error (naming its replacement) instead of Python's."""
    def wrap(f: _F) -> _F:
        takes = frozenset(inspect.signature(f).parameters)

        @functools.wraps(f)
        def checked(*args: Any, **kwargs: Any) -> Any:
            if not takes.issuperset(kwargs):
                refuse_keywords(f.__name__, options_class, sorted(kwargs.keys() - takes))
            return f(*args, **kwargs)
        return cast(_F, checked)
    return wrap


#: Options with ``N`` set, by (options, type of N, N): building them (their checks call
#: the core) costs about 80 us, an eighth of a warm N = 3 solve, so a loop of small
#: solves at ``N=8`` pays for it once. The type is part of the key: 3, 3.0 and True are
#: equal and hash alike, and only 3 is a valid N.
_WITH_N: dict[tuple[Any, type, Any], Any] = {}


def with_harmonics(options: Any, N: int | Literal["auto"] | None) -> Any:  # noqa: N803
    """``options`` with ``harmonic_balance.N`` set to ``N`` (unchanged for None)."""
    if N is None:
        return options
    key: tuple[Any, type, Any] | None = (options, type(N), N)
    try:
        built = _WITH_N.get(key)  # type: ignore[arg-type]
    except TypeError:  # an unhashable N (a list): built, and refused, every time
        key, built = None, None
    if built is None:
        built = replace(options, harmonic_balance=replace(options.harmonic_balance, N=N))
        if key is not None:
            if len(_WITH_N) >= 64:
                _WITH_N.clear()
            _WITH_N[key] = built
    return built


def option_names(cls: type) -> list[str]:
    return [f.name for f in fields(cls)]
