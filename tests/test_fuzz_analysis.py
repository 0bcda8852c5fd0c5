"""Fuzzing the analyses test_fuzz_api.py does not reach (issue 30): basins, speed sweeps,
continuation (branches, curves, branch switching) and their small helpers. As there,
whatever the arguments a call returns or raises a ``ballbal.exceptions`` class whose
``.parameter`` names a real parameter; no numpy or Python error, no panic, no hang.

Valid settings are kept cheap (a few starts of a few time units, branches of a few
points): the property is the boundary's behaviour, not the numerics.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_api import (
    BAD,
    FEW,
    FUZZ,
    GOOD_BALANCER,
    MODEL,
    PATTERN,
    TYPED,
    check,
    count,
    kwargs,
    num,
    sometimes,
)

import ballbal as bb
from ballbal.analysis import residual_imbalance
from ballbal.basins import BasinOptions, basins, default_grid
from ballbal.continuation import (
    Branch,
    Continuation,
    DiskUnits,
    equilibrium_branch,
    equilibrium_curve,
    periodic_branch,
    periodic_curve,
    switch,
    switch_equilibrium,
)
from ballbal.exceptions import ParameterError
from ballbal.sweep import carry_over, speed_sweep

#: Two balls (what basins and most sweeps need), three times in four.
TWO = GOOD_BALANCER.map(lambda b: b.replace(eta=(b.eta[0], b.eta[0])))
MODEL2 = sometimes(st.one_of(TWO, TWO.map(lambda b: bb.Scene(balancer=b))), MODEL)
#: A sweep takes a Balancer.
BALANCER2 = sometimes(TWO, MODEL)

#: Lists of numbers and the ways they go wrong: NaN and inf inside, nested, 2-D arrays,
#: empty, not lists at all.
ANGLES = st.lists(st.floats(0.0, 6.3), min_size=1, max_size=3)
LISTS = st.one_of(
    ANGLES, ANGLES.map(np.asarray),
    st.lists(st.sampled_from([0.5, math.nan, math.inf, -math.inf]), min_size=1, max_size=2),
    st.just([[0.1, 0.2], [0.3, 0.4]]), st.just(np.zeros((2, 2))), st.just([[0.1], 0.2]),
    st.just([]), st.just(np.array(0.5)), st.just([1.0, "a"]), BAD)
SEED = st.one_of(st.integers(0, 2**64 - 1), st.integers(-5, -1), st.just(2**64),
                 st.just(np.int64(3)), BAD)
#: Basin options as keywords (built under ``check`` in the test: their own checks are
#: part of what is fuzzed), None, or not options at all.
OPTIONS = st.one_of(st.none(), kwargs(
    window=num(0.5, 3), rtol=num(1e-8, 1e-3), atol=num(1e-10, 1e-5),
    rest_tol=num(0.01, 0.1), merge_tol=num(0.1, 3), settle_factor=st.one_of(
        st.none(), num(1, 2)), early_stop=st.one_of(st.booleans(), BAD)), BAD)


def built(cls: Any, v: Any) -> Any:
    """``cls(**v)`` when ``v`` is a dict of keywords (a failure to build is then the
    result, checked like any other), else ``v`` itself."""
    return check(cls, **v) if isinstance(v, dict) else v
CHUNK = st.one_of(st.none(), st.just(2), count(1, 3), BAD)


@FUZZ
@given(MODEL2, kwargs(b1=LISTS, b2=LISTS, n=count(1, 3), samples=count(1, 4), seed=SEED,
                      t_end=num(1, 6), settle_check=st.one_of(st.booleans(), BAD),
                      options=OPTIONS, chunk=CHUNK, threads=st.one_of(st.just(1), BAD)))
def test_basins(model: Any, kw: dict[str, Any]) -> None:
    kw.setdefault("t_end", 4.0)
    kw.setdefault("threads", 1)
    kw["options"] = built(BasinOptions, kw.get("options") or {"window": 2.0})
    r = check(basins, model, **kw)
    if isinstance(r, bb.basins.Basins):
        assert r.table.height >= 1
        assert np.isfinite(r.table["b1"].to_numpy()).all()
        # nested axes are refused, not flattened into starts nobody asked for
        assert all(np.ndim(kw[a]) == 1 for a in ("b1", "b2") if a in kw)
    elif isinstance(r, ParameterError):
        assert r.parameter != "starts", r  # the core's name for what the caller gave


@FEW
@given(SEED, st.integers(1, 3))
def test_basins_seed(seed: Any, samples: Any) -> None:
    r = check(basins, bb.Balancer(eta=(0.7, 0.7)), samples=samples, seed=seed, t_end=2.0,
              options=BasinOptions(window=1.0), threads=1)
    if isinstance(r, bb.basins.Basins):
        assert r.random and r.table.height == samples


@cache
def small_basins() -> bb.basins.Basins:
    return basins(bb.Balancer(eta=(0.7, 0.7), Omega=1.35), n=2, t_end=4.0,
                  options=BasinOptions(window=2.0), threads=1)


@FEW
@given(st.one_of(count(1, 4), st.integers(10**3 + 1, 10**12)),
       st.one_of(count(1, 4), st.sampled_from(["auto", 300])))
def test_basin_helpers(n: Any, N: Any) -> None:  # noqa: N803
    check(default_grid, n)
    check(small_basins().link, N=N)


SPEEDS = st.one_of(
    st.lists(st.floats(0.5, 2.0), min_size=1, max_size=3, unique=True).map(sorted),
    st.lists(st.floats(0.5, 2.0), min_size=2, max_size=3), LISTS,
    st.just([-1.0, 1.0]), st.just(np.linspace(1.0, 2.0, 6000)))


@FUZZ
@given(BALANCER2, SPEEDS, kwargs(
    dwell=num(1, 6), direction=st.one_of(st.sampled_from(["up-down", "up", "down", "Up"]),
                                         BAD, st.just(np.array([1, 2]))),
    kick=num(-0.01, 0.01), record=st.one_of(st.none(), num(0.5, 2)),
    y0=st.one_of(st.none(), st.lists(num(-1, 1), max_size=9), LISTS), options=OPTIONS))
def test_speed_sweep(model: Any, speeds: Any, kw: dict[str, Any]) -> None:
    kw.setdefault("dwell", 4.0)
    kw.setdefault("record", None)
    if "options" in kw:
        kw["options"] = built(BasinOptions, kw["options"])
    r = check(speed_sweep, model, speeds, **kw)
    if isinstance(r, bb.sweep.Sweep):
        assert r.table.height >= 1
        if kw["record"] is None:
            check(r.waterfall)


@FEW
@given(st.one_of(st.lists(num(-1, 1), max_size=9), LISTS), num(0, 3), num(0, 3),
       count(1, 3), count(3, 6))
def test_carry_over(y: Any, a: Any, b: Any, n: Any, d: Any) -> None:
    check(carry_over, y, a, b, n, d)


@FEW
@given(st.one_of(LISTS, st.lists(num(0.1, 2), max_size=3)), LISTS)
def test_residual_imbalance(eta: Any, angles: Any) -> None:
    r = check(residual_imbalance, eta, angles)
    if isinstance(r, float):
        assert r >= 0


# --- continuation ---------------------------------------------------------------------

DISK_UNITS = st.builds(DiskUnits, st.floats(0.3, 1.5), st.floats(0.05, 0.5), st.floats(1.0, 3.0))
PARAMETERS = sometimes(
    st.sampled_from(["Omega", "eta", "eta2", "zeta", "zeta_b", "mu", "delta"]),
    st.one_of(st.sampled_from(["eta10", "springs", "m0", "omega0", "nope", ""]), BAD))
#: Valid ranges hold the models' values of the parameters above (0.05 to 1.2).
RANGE = sometimes(st.tuples(st.floats(0.01, 0.04), num(1.3, 2.0)),
                  st.one_of(st.just((2.0, 1.0)), st.just((1.0, 1.0, 2.0)), st.just("ab"),
                            LISTS, BAD))
#: Step control as keywords (built under ``check``), or not step control at all.
CONTINUATION = sometimes(kwargs(
    ds=num(1e-3, 0.05), ds_min=num(1e-7, 1e-3), ds_max=num(0.05, 0.2),
    max_points=st.one_of(count(1, 6), st.just(10**9)), tol=num(1e-12, 1e-6),
    max_newton=st.one_of(count(1, 8), st.just(10**6)), grow=num(1, 2),
    min_cos=num(-1, 1), forward=st.one_of(st.booleans(), BAD)).map(
        lambda d: {"max_points": 6, **d}), BAD)


@FUZZ
@given(st.one_of(MODEL2, DISK_UNITS), PARAMETERS, kwargs(
    start=sometimes(st.sampled_from(["perfect_balance", "together"]),
                    st.one_of(st.sampled_from(["opposite", "x"]), BAD)),
    range=RANGE, options=CONTINUATION,
    direction=st.one_of(st.sampled_from(["forward", "backward", "both", "up"]), BAD,
                        st.just(np.array([1, 2])))))
def test_equilibrium_branch(model: Any, parameter: Any, kw: dict[str, Any]) -> None:
    TYPED.update(["eta10", "nope", "", "springs", "m0", "omega0"])
    kw.setdefault("range", (0.01, 1.8))
    kw["options"] = built(Continuation, kw.get("options", {}))
    check(equilibrium_branch, model, parameter, **kw)


@cache
def together_branch() -> Branch:
    """The balls-together branch in eta with its branch point (eta = 1/2) and fold."""
    b = bb.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.05, eta=(0.3, 0.3))
    return equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0),
                              options=Continuation(ds=0.01, ds_max=0.05, max_points=400))


#: An event row: one of the three of the branches below, or not.
EVENT = sometimes(st.integers(0, 2), st.one_of(st.integers(-2, -1), st.integers(3, 5),
                                               st.just(10**30), BAD))
BRANCH = sometimes(st.just("branch"), BAD)


@FEW
@given(BRANCH, EVENT, PARAMETERS, RANGE, CONTINUATION)
def test_equilibrium_switch_and_curve(branch: Any, event: Any, parameter2: Any, rng: Any,
                                      options: Any) -> None:
    TYPED.update(["eta10", "nope", "", "springs", "m0", "omega0"])
    br = together_branch() if branch == "branch" else branch
    assert br is branch or br.events.height >= 2
    check(switch_equilibrium, br, event)
    check(equilibrium_curve, br, event, parameter2, range=rng,
          options=built(Continuation, options))


POPTS = bb.PeriodicOptions(harmonic_balance=bb.HarmonicBalance(N=3),
                           floquet=bb.Floquet(monodromy=False, hill=False))


@cache
def rr_solution() -> bb.PeriodicSolution:
    return bb.periodic(bb.Balancer(eta=(1.0, 1.0), zeta_b=0.1), "R-R", options=POPTS)


@cache
def snake() -> Branch:
    """The merged R-R branch in Omega that snakes through folds (LP events) before its
    infinite-period end (test_codim2.py's, at N = 3 and a few points)."""
    b = bb.Balancer(mu=0.2, zeta=0.05, delta=50.0, zeta_b=0.1, Omega=1.2, eta=(1.0, 1.0))
    start = bb.periodic(b, "R-R", options=POPTS)
    return periodic_branch(start, "Omega", range=(1.1, 1.5), periodic_options=POPTS,
                           options=Continuation(ds=0.05, ds_max=0.2, max_points=60))


PERIODIC_OPTIONS = st.one_of(st.none(), st.just(POPTS), BAD)


@FUZZ
@given(sometimes(st.just("solution"), st.one_of(st.just("failed"), BAD)), PARAMETERS, kwargs(
    range=RANGE, options=CONTINUATION, N=st.one_of(count(1, 4), st.just(300)),
    periodic_options=PERIODIC_OPTIONS, min_omega=num(1e-4, 0.1), event_tol=num(1e-9, 1e-3)))
def test_periodic_branch(start: Any, parameter: Any, kw: dict[str, Any]) -> None:
    TYPED.update(["eta10", "nope", "", "springs", "m0", "omega0"])
    if start == "solution":
        start = rr_solution()
    elif start == "failed":
        start = bb.periodic(bb.Balancer(), "R-R", guess=(1.0, np.zeros((4, 7))),
                            options=POPTS)
    kw.setdefault("range", (0.01, 1.8))
    kw["options"] = built(Continuation, kw.get("options", {}))
    kw.setdefault("periodic_options", POPTS)
    check(periodic_branch, start, parameter, **kw)


@FEW
@given(BRANCH, EVENT, PARAMETERS, kwargs(
    range=RANGE, range1=st.one_of(st.none(), RANGE), options=CONTINUATION,
    periodic_options=PERIODIC_OPTIONS, locate_tol=num(1e-10, 1e-4)))
def test_periodic_curve(branch: Any, event: Any, parameter2: Any, kw: dict[str, Any]) -> None:
    TYPED.update(["eta10", "nope", "", "springs", "m0", "omega0"])
    br = snake() if branch == "branch" else branch
    kw.setdefault("range", (0.8, 1.2))
    kw["options"] = built(Continuation, kw.get("options", {"max_points": 4}))
    kw.setdefault("periodic_options", POPTS)
    check(periodic_curve, br, event, parameter2, **kw)


@FEW
@given(st.sampled_from(["periodic", "equilibrium", "branch", "bad"]), BAD, kwargs(
    parameter=PARAMETERS, kind=st.one_of(st.sampled_from(["PD", "BP", "Hopf", "LP"]), BAD,
                                         st.just(np.array([1]))),
    event=EVENT, model=MODEL, amplitude=num(1e-3, 0.1), N=st.one_of(count(1, 4), BAD)))
def test_switch(what: str, bad: Any, kw: dict[str, Any]) -> None:
    TYPED.update(["eta10", "nope", "", "springs", "m0", "omega0"])
    solution = {"periodic": rr_solution, "equilibrium": lambda: bb.equilibria(
        bb.Balancer())[0], "branch": together_branch, "bad": lambda: bad}[what]()
    kw.setdefault("options", POPTS)
    kw.setdefault("parameter", "Omega")
    check(switch, solution, **kw)


@FEW
@given(st.one_of(st.just(None), st.lists(num(0, 10), max_size=3), LISTS,
                 # more times than MAX_SAMPLES, without allocating them
                 st.just(np.broadcast_to(0.0, (10**7 + 1,)))), num(-3, 3))
def test_time_history_and_state(t: Any, t0: Any) -> None:
    s = rr_solution()
    check(s.time_history, t)
    check(s.state, t0)


@settings(FEW, max_examples=10)
@given(st.sampled_from(["eta", "zeta_b"]), st.one_of(
    st.integers(0, 3), st.integers(63, 66), st.just(1000)))
def test_ball_counts(name: str, n: int) -> None:
    kw = {"eta": (0.5,) * n} if name == "eta" else {"eta": (0.5,) * min(n, 64),
                                                    "zeta_b": (0.1,) * n}
    b = check(bb.Balancer, **kw)
    if isinstance(b, bb.Balancer):
        assert b.n_balls <= 64
    check(bb.from_disk_units, 0.5, 0.1, 2.0, n=n)


@FEW
@given(MODEL, PATTERN)
def test_accuracy_cost_checks_before_solving(model: Any, pattern: Any) -> None:
    """Every knob empty: nothing but the start and the reference would be solved, and
    with a reference no finer than the baseline not even those."""
    check(bb.accuracy_cost, model, pattern, N=[], samples=[], tol=[], rtol=[],
          magnus_rtol=[], base_N=3, reference_N=3, repeats=1)
