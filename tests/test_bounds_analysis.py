"""Bounded sizes and the right errors in the analyses (issue 30): every size has a stated
bound checked before any work, and bad input raises a ``ballbal.exceptions`` class that
names the argument the caller wrote. Each test here failed before its fix: the call ran
(for hours, or returned rows), or raised numpy's or Python's own error, or named another
parameter."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballbal
from ballbal import Balancer, _check
from ballbal.basins import BasinOptions, basins, default_grid
from ballbal.continuation import Continuation, DiskUnits, from_disk_units
from ballbal.exceptions import ParameterError, ParameterTypeError
from ballbal.sweep import speed_sweep


def refused(call, parameter: str, kind: type[ParameterError] = ParameterError) -> str:
    """Runs ``call``; it must raise ``kind`` naming ``parameter``. Returns the message."""
    with pytest.raises(kind) as e:
        call()
    assert e.value.parameter == parameter, (e.value.parameter, str(e.value))
    return str(e.value)


# --- balls ------------------------------------------------------------------------

def test_one_bound_on_balls_everywhere():
    """1000 balls were accepted by Python (equilibria() then ran for hours) while scene
    files and the command line stopped at 64: the one constant now bounds them all."""
    assert ballbal.scene.MAX_BALLS == _check.MAX_BALLS == 64
    msg = refused(lambda: Balancer(eta=(0.01,) * 1000), "eta")
    assert "64" in msg
    refused(lambda: Balancer(eta=np.full(65, 0.1)), "eta")
    refused(lambda: Balancer(eta=(0.5, 0.5), zeta_b=(0.1,) * 65), "zeta_b")
    refused(lambda: Balancer().replace(eta=(0.1,) * 65), "eta")
    refused(lambda: from_disk_units(0.5, 0.1, 2.0, n=65), "n")
    refused(lambda: DiskUnits(0.5, 0.1, 2.0, n=65), "n")
    refused(lambda: Balancer.from_lab(
        disk_mass=1.0, eccentricity=1e-3, ball_masses=[1e-3] * 65, track_radius=0.05,
        stiffness=1e4, damping=1.0, track_damping=1e-3, spin=100.0), "ball_masses")
    assert Balancer(eta=(1 / 32,) * 64).n_balls == 64


# --- periodic's simulated start search ----------------------------------------------

def test_periodic_bounds_the_parameters_of_its_start_search():
    """``zeta=100`` took 85 s and ``Omega=1e3`` many minutes in the search by
    simulation for a start that finds nothing; now refused before it, naming the
    parameter and the bound."""
    for kw, name in ((dict(zeta=100.0), "zeta"), (dict(Omega=1e3), "Omega"),
                     (dict(zeta_b=(0.1, 31.0)), "zeta_b")):
        msg = refused(lambda kw=kw: ballbal.periodic(Balancer(**kw), "R-R"), name)
        assert "30" in msg and "guess" in msg
    scene = ballbal.Scene(balancer=Balancer(Omega=31.0), springs=0.1)
    refused(lambda: ballbal.periodic(scene, "R-R"), "Omega")
    # accuracy_cost finds its start with periodic()
    refused(lambda: ballbal.accuracy_cost(Balancer(Omega=40.0), N=[], samples=[], tol=[],
                                          rtol=[], magnus_rtol=[], base_N=3,
                                          reference_N=4), "Omega")
    # with a guess there is no search, and no bound: Newton runs (whatever it finds)
    opts = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(max_iter=5),
                                   floquet=ballbal.Floquet(monodromy=False, hill=False))
    s = ballbal.periodic(Balancer(), "R-R", N=3, options=opts)
    r = ballbal.periodic(Balancer(Omega=31.0), "R-R", N=3, guess=s, options=opts)
    assert isinstance(r, ballbal.PeriodicSolution) and r.info["guess_source"] == "guess"


# --- balance_map -------------------------------------------------------------------

def test_balance_map_refuses_values_outside_the_parameters_ranges():
    """``Omega=[-1.0], zeta_b=[-1.0]`` gave a row with status "ok" and a verdict: the
    core set the values on each point without checking them."""
    b = Balancer()
    refused(lambda: ballbal.balance_map(b, Omega=[-1.0], zeta_b=[-1.0]), "Omega")
    refused(lambda: ballbal.balance_map(b, zeta_b=[0.1, -1.0]), "zeta_b")
    refused(lambda: ballbal.balance_map(b, Omega=[1.2], eta=[0.5, 0.0]), "eta")
    refused(lambda: ballbal.balance_map(b, mu=[0.5, 1.0]), "mu")
    refused(lambda: ballbal.balance_map(ballbal.Scene(balancer=b, springs=0.1),
                                        delta=[-3.0]), "delta")


def test_balance_map_refuses_nested_axes_and_a_grid_too_large():
    b = Balancer()
    refused(lambda: ballbal.balance_map(b, Omega=[[1.1, 1.2], [1.3, 1.4]]), "Omega")
    refused(lambda: ballbal.balance_map(b, Omega=[1.2, math.nan]), "Omega")
    # two axes of 400 values: 160 000 points, more than MAX_MAP_POINTS, before any is built
    big = np.linspace(1.1, 2.0, 400)
    refused(lambda: ballbal.balance_map(b, Omega=big, eta=big), "Omega")


# --- accuracy_cost ----------------------------------------------------------------

def test_accuracy_cost_needs_a_reference_finer_than_the_baseline():
    """A reference with fewer harmonics than the baseline (or than an N tried) was
    accepted: the "errors" were then the reference's own."""
    b = Balancer()
    no_knobs = dict(N=[], samples=[], tol=[], rtol=[], magnus_rtol=[], repeats=1)
    refused(lambda: ballbal.accuracy_cost(b, base_N=3, reference_N=2, **no_knobs),
            "reference_N")
    refused(lambda: ballbal.accuracy_cost(b, base_N=3, reference_N=3, **no_knobs),
            "reference_N")
    refused(lambda: ballbal.accuracy_cost(b, base_N=3, reference_N=8,
                                          **{**no_knobs, "N": [2, 12]}), "reference_N")


def test_accuracy_cost_checks_every_knob_before_solving():
    b = Balancer()
    kw = dict(N=[2], samples=[4], tol=[1e-6], rtol=[1e-5], magnus_rtol=[], base_N=3,
              reference_N=4, repeats=1)
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "tol": [0.0]}), "tol")
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "rtol": [1.5]}), "rtol")
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "magnus_rtol": [-1e-6]}),
            "magnus_rtol")
    # 3 harmonics x 30000 = 90000 samples per period, over the core's 65536
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "samples": [30000]}), "samples")
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "N": [1] * 1001}), "N")
    refused(lambda: ballbal.accuracy_cost(b, **{**kw, "neighbour": 2.0}), "neighbour")


# --- speed_sweep -----------------------------------------------------------------

SPEEDS = [1.2, 1.3]


def test_speed_sweep_errors_name_its_own_arguments():
    """``dwell`` was reported as ``t_end``, ``kick=nan`` as ``y0``, ``record=0`` as
    ``t``; ``record < 0`` raised numpy's ValueError and ``options=3`` an
    AttributeError."""
    b = Balancer(eta=(0.7, 0.7))
    for dwell in (-1.0, 0.0, math.inf, 2e6):
        refused(lambda dwell=dwell: speed_sweep(b, SPEEDS, dwell=dwell), "dwell")
    refused(lambda: speed_sweep(b, SPEEDS, dwell=10.0, kick=math.nan), "kick")
    refused(lambda: speed_sweep(b, SPEEDS, dwell=10.0, record=0.0), "record")
    refused(lambda: speed_sweep(b, SPEEDS, dwell=10.0, record=-5.0), "record")
    refused(lambda: speed_sweep(b, SPEEDS, dwell=10.0, options=3), "options",
            ParameterTypeError)
    refused(lambda: speed_sweep(b, [1.2, math.nan], dwell=10.0), "speeds")
    refused(lambda: speed_sweep(b, [[1.2, 1.3]], dwell=10.0), "speeds")
    refused(lambda: speed_sweep(b, [-1.0, 1.2], dwell=10.0), "speeds")
    refused(lambda: speed_sweep(b, SPEEDS, dwell=10.0, direction=np.array([1, 2])),
            "direction")


def test_speed_sweep_sizes_are_bounded():
    b = Balancer(eta=(0.7, 0.7))
    # 6000 speeds up and down are 11999 steps
    many = np.linspace(1.0, 2.0, 6000)
    refused(lambda: speed_sweep(b, many, dwell=10.0), "speeds")
    # 100 steps recording 1e4 time units: 2e7 samples kept
    refused(lambda: speed_sweep(b, np.linspace(1.0, 2.0, 100), dwell=10.0,
                                direction="up", record=1e4), "record")


# --- basins ----------------------------------------------------------------------

def m2() -> Balancer:
    return Balancer(eta=(0.7, 0.7), Omega=1.35)


def test_basins_errors_name_its_own_arguments():
    """A bad ``seed`` raised numpy's errors, NaN angles were reported as ``starts``
    (the core's name), and 2-D axes were flattened without a word."""
    o = BasinOptions(window=5.0)
    for seed in (-1, "x", 1.5, 2**70):
        refused(lambda seed=seed: basins(m2(), samples=4, seed=seed, t_end=10.0,
                                         options=o), "seed")
    refused(lambda: basins(m2(), b1=[0.1, math.nan], b2=[1.0], t_end=10.0, options=o),
            "b1")
    refused(lambda: basins(m2(), b1=[0.1], b2=[[1.0, 2.0], [3.0, 4.0]], t_end=10.0,
                           options=o), "b2")
    refused(lambda: basins(m2(), n=2, seed=3, t_end=10.0, options=o), "seed")


def test_basins_sizes_are_bounded():
    o = BasinOptions(window=5.0)
    refused(lambda: basins(m2(), n=1001, t_end=10.0, options=o), "n")
    refused(lambda: basins(m2(), samples=10**6 + 1, t_end=10.0, options=o), "samples")
    axis = np.linspace(0.0, 6.0, 1001)
    refused(lambda: basins(m2(), b1=axis, b2=axis, t_end=10.0, options=o), "b1")
    refused(lambda: default_grid(10**9), "n")


def test_basins_checks_its_options_before_writing_out(tmp_path):
    """A t_end out of range was refused only after the directory and its meta.json
    were written."""
    out = tmp_path / "b"
    refused(lambda: basins(m2(), n=2, t_end=2e6,
                           out=out), "t_end")
    assert not out.exists()


# --- continuation ----------------------------------------------------------------

def test_continuation_sizes_are_bounded():
    refused(lambda: Continuation(max_points=10**9), "max_points")
    refused(lambda: Continuation(max_newton=10**6), "max_newton")
    assert Continuation(max_points=_check.MAX_BRANCH_POINTS).max_points == 10**5


def test_harmonic_balance_size_is_bounded_before_allocation() -> None:
    """64 balls at N = 256 make 66 x 513 + 1 = 33 859 unknowns, a 9.2 GB Jacobian whose
    allocation aborted the process; the bound (8192 unknowns) allows N <= 61 there."""
    from ballbal.exceptions import ParameterError

    b = ballbal.Balancer(eta=(1.0 / 32,) * 64)
    pattern = "-".join(["R"] * 64)
    with pytest.raises(ParameterError) as e:
        ballbal.periodic(b, pattern, N=256)
    assert e.value.parameter == "N" and e.value.allowed == "[1, 61]"
    with pytest.raises(ParameterError) as e:
        ballbal.scan(b, Omega=[1.2], patterns=[pattern], N=62)
    assert e.value.parameter == "N"
