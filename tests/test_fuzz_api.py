"""Fuzzing the public Python API (issue 13): whatever the arguments, a call returns or
raises a ``ballbal.exceptions`` class (bad input: a ValueError/TypeError subclass whose
``.parameter`` names a real parameter); no other exception type, no panic, no hang.

Arguments mix valid values with wrong types, non-finite numbers, negative and huge
counts and malformed strings and files. Valid settings are kept cheap (short times,
few harmonics, tiny grids): the property is the boundary's behaviour, not the
numerics; limits on costly valid inputs have tests of their own (test_errors.py).
Each case runs under a wall-clock guard: an alarm for Python-level loops and a check
of the elapsed time after native calls (which run to the end before a signal is seen).
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import math
import re
import signal
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ballbal as bb
from ballbal.exceptions import BallbalError, ParameterError

#: Every name a ParameterError may carry: the public functions' parameters, the model's
#: fields and effect keys, scan axes (also one ball's: ``eta2``).
NAMES = {
    # models
    "mu", "zeta", "zeta_b", "delta", "Omega", "eta", "balancer", "model", "scene",
    "springs", "spring_layout", "ramp", "gravity", "impulse", "tilt", "balls",
    "ramp.to", "ramp.start", "ramp.duration", "impulse.amplitude", "impulse.t0",
    "impulse.sharpness", "impulse.angle", "tilt.a", "tilt.b", "tilt.j_t", "tilt.j_z",
    "tilt.zeta_r", "a", "b", "j_t", "j_z", "zeta_r", "path",
    "disk_mass", "eccentricity", "ball_masses", "track_radius", "stiffness", "damping",
    "track_damping", "spin", "other_mass",
    # analyses
    "y0", "t_eval", "t_span", "t0", "rtol", "atol", "max_steps", "pattern", "N", "target",
    "N_max", "hill", "samples", "tol", "step_tol", "max_iter", "guess", "floquet", "margin",
    "settle", "window", "coeffs",
    # scans and maps
    "patterns", "guess_rtol", "seeds", "starts", "max_tail", "chunk", "threads", "out",
    "grid", "axes", "chunks", "block",
    # the option classes (ballbal.options) and the names the core gives their fields
    "options", "execution", "monodromy", "guess_atol", "lazy", "executor", "progress",
    # transients and accuracy
    "to", "start", "duration", "t_end", "band", "dt", "base_N", "reference_N", "neighbour",
    "repeats",
    # command line
    "scan_dir", "type", "cmd",
    # basins, speed sweeps and their helpers
    "b1", "b2", "n", "seed", "settle_check", "rest_tol", "merge_tol", "settle_factor",
    "early_stop", "speeds", "dwell", "direction", "kick", "record", "angles", "t",
    "magnus_rtol", "result", "title", "y", "d", "n_balls", "omega_from", "omega_to",
    # continuation
    "range", "range1", "parameter", "parameter2", "event", "kind",
    "amplitude", "solution", "branch", "min_omega", "event_tol", "periodic_options",
    "locate_tol", "ds", "ds_min", "ds_max", "max_points", "max_newton", "grow", "min_cos",
    "forward", "omega0", "m0", "e", "C0", "D0",
}


def known_parameter(name: str) -> bool:
    base = re.sub(r"^(eta|zeta_b)[1-9]\d*$", r"\1", name)  # one ball's: eta1, zeta_b2
    if base in NAMES:
        return True
    # An unknown key or axis the caller typed is named as typed.
    return name in TYPED


#: Names the fuzzer itself made up (unknown keys, axes): errors may name them.
TYPED: set[str] = set()

LIMIT = 20.0  # seconds per case; the cheap settings here take well under one


class Hang(Exception):
    pass


@contextlib.contextmanager
def guard(seconds: float = LIMIT) -> Iterator[None]:
    def alarm(_sig: int, _frame: Any) -> None:
        raise Hang(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    t = time.monotonic()
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert time.monotonic() - t < seconds, f"took {time.monotonic() - t:.1f} s"


#: Outcomes per function (returned, or the parameter named), to see what a run reached.
OUTCOMES: collections.Counter[tuple[str, str]] = collections.Counter()


def check(f: Callable[..., Any], *args: Any, **kw: Any) -> Any:
    """Calls ``f``; a failure must be a ballbal exception naming a known parameter."""
    name = getattr(f, "__name__", str(f))
    with guard():
        try:
            r = f(*args, **kw)
            OUTCOMES[(name, "ok")] += 1
            return r
        except Hang:
            raise
        except BallbalError as e:
            OUTCOMES[(name, getattr(e, "parameter", type(e).__name__))] += 1
            if isinstance(e, ParameterError):
                assert known_parameter(e.parameter), (e.parameter, str(e))
                assert str(e).startswith(f"{e.parameter}:") or e.parameter in str(e), str(e)
            elif isinstance(e, (ValueError, TypeError)):
                assert isinstance(e, bb.exceptions.NotAutonomousError), repr(e)
            return e
        except BaseException as e:  # noqa: BLE001 - the property under test
            pytest.fail(f"{type(e).__module__}.{type(e).__name__} (not a ballbal exception): "
                        f"{e!r:.300}")


FUZZ = settings(max_examples=80, derandomize=True, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
FEW = settings(FUZZ, max_examples=25)

# --- values ---------------------------------------------------------------------

BAD = st.sampled_from([None, "x", "1.0", True, False, math.nan, math.inf, -math.inf, -1, 0,
                       [1.0], (), {}, b"1", 2**70, -(2**70), 1e308 * 10, object()])


def sometimes(valid: st.SearchStrategy[Any],
              bad: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    """``valid`` three times in four: most calls then carry one bad value or none, so
    that the checks after the first one and the valid paths are reached too."""
    return st.integers(0, 3).flatmap(lambda i: bad if i == 0 else valid)


def num(lo: float, hi: float) -> st.SearchStrategy[Any]:
    """A valid number in [lo, hi], or something that is not."""
    return sometimes(st.floats(lo, hi, allow_nan=False), BAD)


def count(lo: int, hi: int) -> st.SearchStrategy[Any]:
    return sometimes(st.integers(lo, hi), st.one_of(
        BAD, st.floats(-3, 3).map(lambda x: x + 0.5), st.integers(-(2**65), -1)))


def maybe(strategy: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    """A keyword's value or (three times in four) ``...`` for leaving it out."""
    return sometimes(st.just(...), strategy)


def kwargs(**strategies: st.SearchStrategy[Any]) -> st.SearchStrategy[dict[str, Any]]:
    return st.fixed_dictionaries({k: maybe(v) for k, v in strategies.items()}).map(
        lambda d: {k: v for k, v in d.items() if v is not ...})


PATTERN = sometimes(
    st.sampled_from(["R-R", "O-O", "R-O", "O-R", "R", "O", "R-R-R"]),
    st.one_of(st.sampled_from(["RR", "r-r", " R-R ", "", "X-X", "R_R", "R--R"]),
              st.text(alphabet="RrOo-_ x", max_size=6), BAD))

BALANCER_FIELDS = dict(
    mu=num(0.01, 0.9), zeta=num(0.0, 0.3), delta=num(5.0, 100.0), Omega=num(0.3, 3.0),
    zeta_b=st.one_of(num(0.01, 0.3), st.lists(num(0.01, 0.3), min_size=0, max_size=4)),
    eta=st.one_of(num(0.3, 2.0), st.lists(num(0.3, 2.0), min_size=0, max_size=4)),
)
GOOD_BALANCER = st.builds(
    bb.Balancer, mu=st.floats(0.05, 0.5), zeta=st.floats(0.01, 0.2),
    zeta_b=st.floats(0.02, 0.2), delta=st.floats(10, 80), Omega=st.floats(0.5, 2.5),
    eta=st.lists(st.floats(0.4, 1.6), min_size=1, max_size=3).map(tuple))
MODEL = sometimes(st.one_of(GOOD_BALANCER, GOOD_BALANCER.map(lambda b: bb.Scene(balancer=b)),
                            GOOD_BALANCER.filter(lambda b: b.n_balls > 1).map(
                                lambda b: bb.Scene(balancer=b, springs=0.1))),
                  st.one_of(GOOD_BALANCER.map(lambda b: bb.Scene(balancer=b, gravity=0.1)),
                            BAD))


# --- models -----------------------------------------------------------------------

@FUZZ
@given(kwargs(**BALANCER_FIELDS))
def test_balancer(kw: dict[str, Any]) -> None:
    b = check(bb.Balancer, **kw)
    if isinstance(b, bb.Balancer) and b.n_balls <= 4:
        check(b.validate)
        check(b.replace, **{"Omega": kw.get("Omega", 1.0)})


@FUZZ
@given(GOOD_BALANCER, kwargs(springs=num(0, 2), gravity=num(0, 1),
                             spring_layout=st.one_of(st.sampled_from(["ring", "chain"]), BAD),
                             ramp=st.one_of(st.none(), BAD), tilt=st.one_of(st.none(), BAD)),
       kwargs(start=num(0, 5), duration=num(0.1, 5)).flatmap(
           lambda d: num(0.1, 3).map(lambda to: {**d, "to": to})),
       kwargs(zeta_r=num(0, 1)).flatmap(lambda d: st.fixed_dictionaries(dict(
           a=num(0.5, 3), b=num(0.5, 3), j_t=num(0.05, 1), j_z=num(0, 2))).map(
               lambda r: {**d, **r})),
       kwargs(angle=num(-3, 3)).flatmap(lambda d: st.fixed_dictionaries(dict(
           amplitude=num(-1, 1), t0=num(0, 5), sharpness=num(0.1, 10))).map(
               lambda r: {**d, **r})))
def test_scene(b: bb.Balancer, kw: dict[str, Any], ramp: dict[str, Any],
               tilt: dict[str, Any], impulse: dict[str, Any]) -> None:
    for cls, d in ((bb.Ramp, ramp), (bb.Tilt, tilt), (bb.Impulse, impulse)):
        check(cls, **d)
    sc = check(bb.Scene, balancer=b, **kw)
    if isinstance(sc, bb.Scene):
        check(sc.replace, **{k: v for k, v in tilt.items()})
        check(sc.replace, Omega=kw.get("springs", 1.0))


TOML_KEYS = st.sampled_from(["mu", "zeta", "zeta_b", "delta", "Omega", "eta", "balls",
                             "Omgea", "x", "to", "g", "stiffness", "layout", "a", "j_z"])
TOML_TABLES = st.sampled_from(["balancer", "springs", "ramp", "gravity", "impulse", "tilt",
                               "spring", "Balancer"])
TOML_VALUES = st.one_of(
    st.floats(-2, 3).map(lambda x: f"{x!r}"), st.integers(-3, 100).map(str),
    st.sampled_from(['"x"', "true", "nan", "inf", "-inf", "[]", "[1.0, 2.0]", "[1, 'a']",
                     "{a = 1}", '"ring"', '"chain"', "1e400", "[[1.0]]", "0", "2"]))


@st.composite
def toml_text(draw: st.DrawFn) -> str:
    # Mostly valid TOML (distinct keys and tables), so that the scene checks are reached.
    top = draw(st.dictionaries(TOML_KEYS, TOML_VALUES, max_size=3))
    lines = [f"{k} = {v}" for k, v in top.items()]
    for t in draw(st.lists(TOML_TABLES, max_size=3, unique=True)):
        lines.append(f"[{t}]")
        lines += [f"{k} = {v}" for k, v in
                  draw(st.dictionaries(TOML_KEYS, TOML_VALUES, max_size=4)).items()]
    return "\n".join(lines) + "\n"


@FUZZ
@given(st.one_of(toml_text().map(str.encode), st.binary(max_size=64),
                 st.text(max_size=40).map(lambda s: s.encode("utf-16")),
                 st.integers(1, 4000).map(lambda n: b"a = " + b"[" * n + b"]" * n)))
def test_load_scene(tmp_path_factory: pytest.TempPathFactory, data: bytes) -> None:
    TYPED.update(["Omgea", "x", "to", "g", "stiffness", "layout", "a", "j_z", "spring",
                  "Balancer", "springs.x", "ramp.x", "gravity.x", "impulse.x", "tilt.x"])
    TYPED.update(f"{t}.{k}" for t in ("springs", "ramp", "gravity", "impulse", "tilt")
                 for k in ("mu", "zeta", "zeta_b", "delta", "Omega", "eta", "balls", "Omgea",
                           "to", "g", "stiffness", "layout", "a", "j_z"))
    p = tmp_path_factory.mktemp("scene") / "s.toml"
    p.write_bytes(data)
    sc = check(bb.load_scene, p)
    if isinstance(sc, bb.Scene):
        assert sc.n_balls >= 1


def test_load_scene_paths(tmp_path: Path) -> None:
    for p in (tmp_path, tmp_path / "none.toml", "", None, 3, b"x", tmp_path / "a\0b"):
        e = check(bb.load_scene, p)
        assert isinstance(e, ParameterError), e


# --- analyses ---------------------------------------------------------------------

TIMES = st.one_of(
    st.lists(st.floats(0, 5, allow_nan=False), min_size=0, max_size=5).map(sorted),
    st.lists(st.floats(allow_nan=True), max_size=3), BAD)
SPAN = st.one_of(st.tuples(st.floats(-1, 1), st.floats(0, 5)),
                 st.tuples(num(-1, 1), num(0, 5)), st.lists(st.floats(0, 5), max_size=4),
                 BAD)


@FUZZ
@given(MODEL, kwargs(y0=st.one_of(st.lists(num(-1, 1), max_size=10), BAD), t_eval=TIMES,
                     t_span=SPAN, t0=num(-1, 1), rtol=num(1e-10, 1e-3),
                     atol=st.one_of(num(1e-12, 1e-6), st.lists(num(1e-12, 1e-6), max_size=9)),
                     max_steps=count(1, 20_000)))
def test_simulate(model: Any, kw: dict[str, Any]) -> None:
    if "t_eval" not in kw and "t_span" not in kw:
        kw["t_span"] = (0.0, 1.0)
    check(bb.simulate, model, **kw)


@FEW
@given(MODEL)
def test_equilibria_and_balanced_state(model: Any) -> None:
    check(bb.equilibria, model)
    check(bb.balanced_state, model)


@FUZZ
@given(MODEL, PATTERN, kwargs(
    N=st.one_of(st.integers(-2, 6), st.sampled_from(["auto", "Auto", 300, 2.0]), BAD),
    target=num(1e-6, 0.5), N_max=count(1, 6), hill=st.one_of(st.booleans(), BAD),
    samples=st.one_of(st.none(), count(1, 40)), tol=num(1e-12, 1e-3), step_tol=num(1e-10, 1e-3),
    max_iter=count(1, 5), floquet=st.one_of(st.booleans(), BAD), rtol=num(1e-8, 1e-3),
    atol=num(1e-10, 1e-5), margin=num(0, 1e-3), max_steps=count(1, 2000),
    settle=num(1, 30), window=num(1, 30),
    guess=st.one_of(st.none(), BAD, st.tuples(num(0.1, 2), st.lists(num(-1, 1), max_size=9))),
))
def test_periodic(model: Any, pattern: Any, kw: dict[str, Any]) -> None:
    kw.setdefault("settle", 5.0)
    kw.setdefault("window", 20.0)
    kw.setdefault("max_steps", 2000)
    kw.setdefault("max_iter", 5)
    options = built_options(bb.PeriodicOptions(), kw)
    if isinstance(options, BallbalError):
        return
    s = check(bb.periodic, model, pattern, options=options, **kw)
    if isinstance(s, bb.PeriodicSolution):
        assert s.status in ("converged",) or s.omega is None


#: Where each fuzzed option keyword goes in the option classes.
OPTION_FIELDS = {
    "harmonic_balance": ("target", "N_max", "samples", "tol", "step_tol", "max_iter"),
    "floquet": ("hill", "rtol", "atol", "margin", "max_steps", "monodromy"),
    "guess": ("settle", "window", "seeds", "starts"),
}


def built_options(base: Any, kw: dict[str, Any]) -> Any:
    """``base`` with the option keywords taken out of ``kw`` set in its parts (``floquet``
    is ``Floquet.monodromy``), built under ``check`` (their own checks are part of what
    is fuzzed): the options, or the ballbal error that refused them."""
    if "floquet" in kw:
        kw["monodromy"] = kw.pop("floquet")
    parts = {part: {k: kw.pop(k) for k in names if k in kw}
             for part, names in OPTION_FIELDS.items()}
    top = {k: kw.pop(k) for k in ("max_tail",) if k in kw}
    for part, changes in parts.items():
        if changes:
            top[part] = check(dataclasses.replace, getattr(base, part), **changes)
            if isinstance(top[part], BallbalError):
                return top[part]
    return check(dataclasses.replace, base, **top)


GRID_VALUES = st.one_of(
    st.lists(st.floats(0.5, 2.0), min_size=1, max_size=2),
    st.sampled_from(["1.0:1.2:0.1", "1:2", "a:b:c", "2:1:0.1", "1:1:0", "0:1e300:1e-300", ""]),
    st.tuples(num(0.5, 2), num(0.5, 2), num(0.05, 1)), BAD, st.just([]))
GRID_NAMES = st.sampled_from(["Omega", "eta", "zeta", "mu", "eta1", "eta8", "zeta_b2",
                              "springs", "j_t", "Omgea", "delta"])


@FUZZ
@given(MODEL, st.dictionaries(GRID_NAMES, GRID_VALUES, min_size=0, max_size=2), kwargs(
    patterns=st.one_of(st.lists(PATTERN, max_size=3), PATTERN),
    N=st.one_of(st.integers(-1, 4), st.just("auto"), BAD), N_max=count(1, 5),
    seeds=count(1, 2), starts=count(1, 2), threads=count(1, 1), chunk=st.one_of(st.none(),
                                                                               count(1, 3)),
    max_iter=count(1, 5), max_steps=count(1, 1000), tol=num(1e-12, 1e-4),
    max_tail=num(0.01, 1), hill=st.one_of(st.booleans(), BAD),
    out=st.one_of(st.none(), st.sampled_from(["", 3, b"x"]))))
def test_scan(model: Any, axes: dict[str, Any], kw: dict[str, Any]) -> None:
    TYPED.update(["Omgea", "eta8", "zeta_b2", "springs", "j_t"])
    kw.setdefault("threads", 1)
    kw.update(settle=3.0, window=10.0)
    kw.setdefault("max_steps", 1000)
    kw.setdefault("seeds", 1)
    kw.setdefault("starts", 1)
    options = built_options(bb.options.SCAN_DEFAULTS, kw)
    if isinstance(options, BallbalError):
        return
    check(bb.scan, model, grid=axes, options=options, **kw)


@FEW
@given(MODEL, st.dictionaries(GRID_NAMES, st.one_of(
    st.lists(st.floats(0.5, 2.0), min_size=1, max_size=2), BAD, st.just([])), max_size=2))
def test_balance_map(model: Any, axes: dict[str, Any]) -> None:
    TYPED.update(["Omgea", "eta1", "eta8", "zeta_b2", "j_t"])
    check(bb.balance_map, model, **axes)


@FUZZ
@given(MODEL, num(0.5, 2.5), num(0.1, 5), kwargs(
    balls=st.one_of(st.none(), st.lists(num(-3, 3), max_size=4), BAD), settle=num(0, 5),
    dt=num(0.1, 1), rtol=num(1e-8, 1e-4)))
def test_run_up(model: Any, to: Any, duration: Any, kw: dict[str, Any]) -> None:
    kw.setdefault("settle", 2.0)
    check(bb.run_up, model, to, duration, **kw)


@FUZZ
@given(MODEL, num(0.5, 2.5), kwargs(
    start=num(0, 2), duration=num(0.1, 2), t_end=num(0, 20), band=num(1e-3, 0.1),
    dt=num(0.1, 1), rtol=num(1e-8, 1e-4)))
def test_disturbance_response(model: Any, to: Any, kw: dict[str, Any]) -> None:
    kw.setdefault("t_end", 15.0)
    check(bb.disturbance_response, model, to, **kw)


@settings(FUZZ, max_examples=8)
@given(MODEL, PATTERN, kwargs(
    N=st.one_of(st.lists(count(1, 3), min_size=0, max_size=2), BAD),
    samples=st.one_of(st.lists(num(2, 4), min_size=1, max_size=1), BAD),
    tol=st.one_of(st.lists(num(1e-8, 1e-4), min_size=1, max_size=1), BAD),
    rtol=st.one_of(st.lists(num(1e-6, 1e-4), min_size=1, max_size=1), BAD),
    base_N=count(1, 3), reference_N=count(1, 4), neighbour=num(-0.1, 0.1),
    repeats=count(1, 1), guess=st.one_of(st.none(), BAD)))
def test_accuracy_cost(model: Any, pattern: Any, kw: dict[str, Any]) -> None:
    # The valid settings are cheap; a call with every argument valid still runs the
    # start from simulation: most cases carry one bad argument at least.
    kw.setdefault("N", [2])
    kw.setdefault("samples", [4])
    kw.setdefault("tol", [1e-6])
    kw.setdefault("rtol", [1e-5])
    kw.setdefault("base_N", 3)
    kw.setdefault("reference_N", 4)
    kw.setdefault("repeats", 1)
    check(bb.accuracy_cost, model, pattern, **kw)


def test_read_scan(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    (tmp_path / "empty").mkdir()
    for p in (tmp_path / "none", tmp_path / "file", tmp_path / "empty", "", None, 3):
        e = check(bb.read_scan, p)
        assert isinstance(e, ParameterError), e


def test_every_exception_is_picklable_with_its_fields() -> None:
    import pickle

    e = check(bb.periodic, bb.Balancer(), "rr")
    assert isinstance(e, ParameterError)
    back = pickle.loads(pickle.dumps(e))
    assert (type(back), back.parameter, back.allowed) == (type(e), e.parameter, e.allowed)


def test_no_panic_on_extreme_arrays() -> None:
    # Non-contiguous and exotic arrays are copied, never handed to the core as is.
    y0 = np.zeros(16)[::2]
    check(bb.simulate, bb.Balancer(), y0, np.array([0.0, 0.5]))
    check(bb.simulate, bb.Balancer(), np.zeros(8, dtype=complex), [0.0])
    check(bb.simulate, bb.Balancer(), np.zeros((2, 4)), [[0.0, 1.0]])


SCAN_OPTIONS = dict(
    N=st.one_of(st.integers(1, 4), st.just("auto"), BAD), N_max=count(3, 5),
    seeds=count(1, 2), starts=count(1, 2), chunk=st.one_of(st.none(), count(1, 3)),
    max_iter=count(1, 8), max_steps=count(1, 2000), tol=num(1e-12, 1e-4),
    max_tail=num(0.01, 1), hill=st.one_of(st.booleans(), BAD), rtol=num(1e-8, 1e-4),
    patterns=st.one_of(st.just(["R-R", "O-O"]), st.just(["R-R", "R-R"]), PATTERN),
)


@settings(FUZZ, max_examples=20)
@given(GOOD_BALANCER.map(lambda b: b.replace(eta=(1.0, 1.0), zeta_b=0.1)),
       st.lists(st.floats(1.1, 1.6), min_size=1, max_size=2),
       st.sampled_from(sorted(SCAN_OPTIONS)).flatmap(
           lambda k: SCAN_OPTIONS[k].map(lambda v: {k: v})))
def test_scan_one_option(model: bb.Balancer, omegas: list[float], kw: dict[str, Any]) -> None:
    """A tiny valid scan with one option fuzzed: the valid paths are reached too."""
    kw = {"settle": 3.0, "window": 10.0, "max_steps": 2000, **kw}
    options = built_options(bb.options.SCAN_DEFAULTS, kw)
    if isinstance(options, BallbalError):
        return
    r = check(bb.scan, model, Omega=omegas, threads=1, options=options, **kw)
    if not isinstance(r, BaseException):
        assert set(r["Omega"].to_list()) <= set(omegas)


def test_outcomes_report() -> None:
    """Runs last: with ``-s``, shows which outcomes the fuzz cases reached."""
    for (f, what), n in sorted(OUTCOMES.items()):
        print(f"{f:24s} {what:16s} {n}")
