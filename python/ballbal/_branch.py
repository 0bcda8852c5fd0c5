"""What continuation returns: a branch of solutions in one parameter, with its located
events, and a curve of bifurcation points in two parameters. The options of the
pseudo-arclength engine (``rust/core/src/continuation/arclength.rs``) are
:class:`Continuation`; the binding reads its fields by name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import polars as pl

from ballbal import _check, _native
from ballbal._style import Summarised, value_range
from ballbal.exceptions import ParameterError, ParameterTypeError


def parameter_range(v: Any) -> tuple[float, float]:
    """The ``range=(lo, hi)`` argument of a continuation: finite, ``lo < hi``."""
    try:
        lo, hi = v
    except (TypeError, ValueError):
        raise ParameterTypeError("range", f"must be a pair (lo, hi), got {v!r}") from None
    lo = _check.real("range", lo)
    hi = _check.real("range", hi)
    if not lo < hi or not (math.isfinite(lo) and math.isfinite(hi)):
        raise ParameterError("range", f"needs finite lo < hi, got ({lo}, {hi})")
    return lo, hi


def event_vocabulary() -> list[tuple[str, list[str], str]]:
    """The events every branch, curve and switch names, from the core: ``(name, aliases,
    meaning)`` for each, the canonical lower-case ``name`` being what every ``events``
    table's ``type`` column and every :class:`Curve`'s ``kind`` write. A function that
    takes an event reads the name or any alias (AUTO's ``LP``, ``BP``, ``HB``, ``PD``,
    ``NS`` / ``TR``, ...), in any case."""
    return [(n, list(a), m) for n, a, m in _native.event_vocabulary()]


def event_name(text: Any, parameter: str = "event") -> str:
    """The canonical name of the event ``text`` (a name or an alias, any case); an unknown
    one raises :class:`~ballbal.exceptions.ParameterError` naming ``parameter``."""
    if not isinstance(text, str):
        raise ParameterTypeError(parameter, f"must be an event name, got {type(text).__name__}",
                                 value=text)
    return _native.event_name(text, parameter)


def _listing(branch: Branch) -> str:
    ev = branch.events
    if ev.height == 0:
        return "it has no located events"
    rows = [f"{i} {t} at {branch.parameter}={p:.6g}"
            for i, (t, p) in enumerate(zip(ev["type"], ev[branch.parameter], strict=True))]
    return "its events: " + "; ".join(rows)


def event_row(branch: Branch, event: Any, parameter: str = "event") -> int:
    """The row of ``branch.events`` that ``event`` selects: an integer is the row itself;
    a name (or alias, see :func:`event_vocabulary`) the first event of that kind along
    the branch. A row the branch does not have, or a kind it did not locate, raises
    :class:`~ballbal.exceptions.ParameterError` naming ``parameter`` and listing the
    branch's events."""
    n = branch.events.height
    if isinstance(event, str):
        name = event_name(event, parameter)
        rows = [i for i, t in enumerate(branch.events["type"]) if t == name]
        if not rows:
            raise ParameterError(parameter, f"the branch has no {name} event; "
                                 f"{_listing(branch)}", value=event)
        return rows[0]
    i = _check.integer(parameter, event, 0)
    if i >= n:
        raise ParameterError(parameter, f"the branch has {n} events; {_listing(branch)}",
                             value=i)
    return i


def directed(options: Continuation, direction: Any) -> tuple[Continuation, bool]:
    """``options`` turned by a branch function's ``direction`` (``"forward"``: towards
    increasing parameter, ``"backward"``, ``"both"``, or None: ``options.forward``), and
    whether both ways were asked for."""
    if direction is None:
        return options, False
    if not isinstance(direction, str) or direction not in ("forward", "backward", "both"):
        raise ParameterError("direction", f"must be 'forward', 'backward' or 'both', got "
                             f"{direction!r:.60}", allowed="forward, backward, both")
    if direction == "both":
        return options, True
    return replace(options, forward=direction == "forward"), False


def branch_controls(at: Any, stop: Any) -> tuple[list[float] | None, list[str] | None]:
    """A branch function's ``at=`` (parameter values: a number or a list of at most
    :data:`~ballbal._check.MAX_USER_POINTS` finite ones) and ``stop=`` (an event name or
    alias, or a list of them) as the binding takes them; the core checks the values
    against the branch's range and the events against the branch's kind."""
    values = None if at is None else [
        float(v) for v in _check.vector("at", at, _check.MAX_USER_POINTS, empty=True)]
    if stop is None:
        return values, None
    names = [stop] if isinstance(stop, str) else _check.sequence("stop", stop, empty=True)
    if len(names) > _check.MAX_STOP_EVENTS:
        raise ParameterError("stop", f"{len(names)} event names, at most "
                             f"{_check.MAX_STOP_EVENTS}",
                             allowed=f"at most {_check.MAX_STOP_EVENTS} names")
    return values, [event_name(n, "stop") for n in names]


@dataclass(frozen=True)
class Continuation:
    """Step control of pseudo-arclength continuation.

    ``ds`` is the first step, between ``ds_min`` and ``ds_max``, measured in the unknowns
    and the parameter together (the harmonic coefficients, omega, the parameter);
    ``max_points`` bounds the branch (at most :data:`~ballbal._check.MAX_BRANCH_POINTS`);
    Newton's corrector converges when the residual is at most ``tol`` within
    ``max_newton`` iterations (at most :data:`~ballbal._check.MAX_NEWTON`); the step
    grows by ``grow`` after an easy correction and halves after a failed one or a turn
    sharper than ``acos(min_cos)`` between successive tangents. ``forward`` starts
    towards increasing parameter.
    """

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = 0.05
    max_points: int = 500
    tol: float = 1e-10
    max_newton: int = 8
    grow: float = 1.5
    min_cos: float = 0.9
    forward: bool = True

    def __post_init__(self) -> None:
        for name in ("ds", "ds_min", "ds_max", "tol", "grow", "min_cos"):
            object.__setattr__(self, name, _check.real(name, getattr(self, name)))
        for name, most in (("max_points", _check.MAX_BRANCH_POINTS),
                           ("max_newton", _check.MAX_NEWTON)):
            object.__setattr__(self, name, _check.integer(name, getattr(self, name), 1, most))
        object.__setattr__(self, "forward", _check.boolean("forward", self.forward))
        _native.validate_continuation(self)


@dataclass(frozen=True, repr=False)
class Branch(Summarised):
    """A branch of equilibria or periodic solutions continued in ``parameter``.

    ``table`` has one row per point, in order along the branch (the parameter, the
    solution's summary, its stability with the evidence, the test functions, and an
    ``event`` column naming the event located between this point and the previous one);
    ``events`` has one row per located event (type, parameter value, the located
    solution's summary, the test function's value there). ``stop`` says why the branch
    ended (``"boundary"``, ``"max_points"``, ``"step_too_small"``,
    ``"infinite_period"``, or ``"failed: ..."``). ``solutions`` holds the solution
    objects (:class:`~ballbal.Equilibrium` / :class:`~ballbal.PeriodicSolution`, each
    with its model at that parameter value) row for row, ``event_solutions`` one per
    event row: what branch switching starts from.
    """

    kind: str
    parameter: str
    table: pl.DataFrame
    events: pl.DataFrame
    stop: str
    solutions: tuple[Any, ...] = ()
    event_solutions: tuple[Any, ...] = ()
    meta: dict[str, Any] = field(default_factory=dict)

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        span = (" " + value_range(self.table[self.parameter])
                if self.parameter in self.table.columns and self.table.height else "")
        kinds = self.events["type"].to_list() if self.events.height else []
        stable = (self.table.filter(pl.col("stability") == "stable").height
                  if "stability" in self.table.columns else None)
        head = (f"Branch {self.kind} in {self.parameter}{span}: {self.table.height} points "
                f"({stable} stable), events [{_counts(kinds)}], stop {self.stop}")
        return head, [("kind", self.kind), ("parameter", self.parameter),
                      ("range", span.strip() or "-"), ("points", self.table.height),
                      ("stable points", stable), ("events", _counts(kinds) or "none"),
                      ("stop", self.stop)]

    def plot(self, y: str | None = None, ax: Any = None) -> Any:
        """Bifurcation diagram: ``y`` (a column of ``table``; default ``omega`` for
        periodic solutions, ``r``, the disk centre's offset, for equilibria) against the
        parameter, stable parts solid and unstable dashed, events marked with their
        short names (LP, BP, HB, PD, NS); returns the axes."""
        from ._figures import branch

        return branch(self, y, ax)


@dataclass(frozen=True, repr=False)
class Curve(Summarised):
    """A curve of bifurcation points of type ``kind`` in ``parameters`` (two names),
    one row per point in ``table``; ``points`` lists the codimension-two points found on
    it (e.g. Bogdanov–Takens, cusp); ``stop`` as for :class:`Branch`."""

    kind: str
    parameters: tuple[str, str]
    table: pl.DataFrame
    points: pl.DataFrame
    stop: str
    meta: dict[str, Any] = field(default_factory=dict)

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        kinds = self.points["type"].to_list() if self.points.height else []
        head = (f"Curve {self.kind} in ({', '.join(self.parameters)}): {self.table.height} "
                f"points, codimension-two [{_counts(kinds)}], stop {self.stop}")
        rows: list[tuple[str, Any]] = [("kind", self.kind),
                                       ("parameters", ", ".join(self.parameters))]
        for name in self.parameters:
            if name in self.table.columns and self.table.height:
                rows.append((f"{name} range", value_range(self.table[name])))
        rows += [("points", self.table.height), ("codimension-two", _counts(kinds) or "none"),
                 ("stop", self.stop)]
        return head, rows

    def plot(self, ax: Any = None) -> Any:
        """The curve in its two parameters, stable parts solid and unstable dashed, its
        codimension-two points starred and labelled; returns the axes."""
        from ._figures import curve

        return curve(self, ax)


def _counts(kinds: list[str]) -> str:
    """``"fold 2, hopf 1"``: how many of each kind, in order of first appearance."""
    seen: dict[str, int] = {}
    for k in kinds:
        seen[k] = seen.get(k, 0) + 1
    return ", ".join(f"{k} {n}" if n > 1 else k for k, n in seen.items())
