"""``Balancer.replace`` with one ``eta`` keeps the number of balls, and ``simulate``
reports the integrator's step statistics, checked against scipy's RK45."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.exceptions import ParameterError

from reference import rhs


def test_replace_with_one_eta_sets_every_ball():
    b = ballbal.Balancer(eta=(0.5, 0.7, 0.9))
    c = b.replace(eta=1.0)
    assert c.n_balls == 3
    assert c.eta == (1.0, 1.0, 1.0)
    # The same rule as Scene.replace, so a balancer and its scene agree.
    assert ballbal.Scene(balancer=b).replace(eta=1.0).balancer == c
    # A sequence still sets the balls outright, its length their number.
    assert b.replace(eta=(0.4, 0.6)).eta == (0.4, 0.6)
    assert b.replace(eta=[2.0]).n_balls == 1
    assert b.replace(eta=np.float64(0.8)).eta == (0.8, 0.8, 0.8)
    # Other fields leave eta alone.
    assert b.replace(Omega=2.0).eta == b.eta


def test_simulate_stats_count_as_dormand_prince_with_fsal():
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.3, eta=(0.9, 1.1))
    y0 = np.array([0.1, -0.2, 0.4, 2.5, 0.0, 0.0, -1.3, -1.3])
    t = np.linspace(0.0, 40.0, 41)
    rtol, atol = 1e-6, 1e-9
    df, st = ballbal.simulate(b, y0, t, rtol=rtol, atol=atol, stats=True)
    assert set(st) == {"nfev", "naccept", "nreject"}
    assert df.equals(ballbal.simulate(b, y0, t, rtol=rtol, atol=atol))
    # Seven stages, the seventh (f at the new state) reused as the next step's first:
    # six new evaluations per attempted step, accepted or not, plus f(t0, y0) and the
    # one trial evaluation of the initial step selection (Hairer's, as in scipy).
    assert st["nfev"] == 6 * (st["naccept"] + st["nreject"]) + 2
    # The same method, error norm, initial step and step control as scipy's RK45: the
    # step counts agree (exactly, here; a little slack for rounding in the step sizes).
    ref = solve_ivp(lambda tt, s: rhs(b, tt, s), (0.0, 40.0), y0, rtol=rtol, atol=atol,
                    method="RK45")
    ref_steps = len(ref.t) - 1
    assert abs(st["naccept"] - ref_steps) <= 0.01 * ref_steps + 1
    ref_attempts = (ref.nfev - 2) // 6
    assert ref.nfev == 6 * ref_attempts + 2  # scipy counts the same way
    assert abs(st["nreject"] - (ref_attempts - ref_steps)) <= 0.01 * ref_steps + 1
    # Tighter tolerances need more steps (DP5: about rtol^(-1/5) times as many).
    _, tight = ballbal.simulate(b, y0, t, rtol=rtol * 1e-5, atol=atol * 1e-5, stats=True)
    assert 5 < tight["naccept"] / st["naccept"] < 20


def test_simulate_stats_must_be_a_bool():
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as e:
        ballbal.simulate(b, t_span=(0.0, 1.0), stats="yes")  # type: ignore[call-overload]
    assert e.value.parameter == "stats"
