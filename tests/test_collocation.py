"""periodic() by collocation (issue 33): the orbit against this file's own references
(the independent shooting of tests/shooting.py, a long DOP853 integration's return
times), the automatic choice between harmonic balance and collocation, and the options'
checks.

The case is the issue's merged R-R branch (mu 0.2, zeta 0.05, zeta_b 0.1, delta 50, eta
(1, 1)): smooth at Omega 1.2 (period ~27), long and slow near its infinite-period end at
Omega* ~ 0.9171 (period ~370 at 0.93), where harmonic balance's N = 3 series is refused
as truncated.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.exceptions import ParameterError, ParameterTypeError

from reference import rhs
from shooting import flow, monodromy_multipliers, shoot

PARAMS = dict(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, eta=(1.0, 1.0))


def balancer(omega: float) -> ballbal.Balancer:
    return ballbal.Balancer(**PARAMS, Omega=omega)


@pytest.fixture(scope="module")
def smooth() -> tuple[ballbal.Balancer, ballbal.PeriodicSolution]:
    b = balancer(1.2)
    return b, ballbal.periodic(b, "R-R", method="collocation")


@pytest.fixture(scope="module")
def slow() -> tuple[ballbal.Balancer, ballbal.PeriodicSolution]:
    b = balancer(0.93)
    return b, ballbal.periodic(b, "R-R")


def test_smooth_orbit_against_shooting_and_harmonic_balance(smooth):
    b, c = smooth
    assert c.method == "collocation" and c.converged
    y_c = c.state(0.0)
    # Shooting from a start moved off the orbit (1e-4 on every free state, the period
    # 1e-4 relative), so that it converges by itself rather than accept the start.
    off = np.full(8, 1e-4)
    off[2] = 0.0
    y0, T = shoot(b, y_c + off, c.period * (1 + 1e-4), [0, 0, -1, -1], phase_index=2)
    # Shooting's residual 1e-9 fixes its period to ~1e-9 relative.
    assert abs(T / c.period - 1) < 1e-8
    assert np.max(np.abs(y0 - y_c)) < 1e-6
    # A third of a period on: the collocation polynomials against the flow.
    y3 = flow(b, y0, T / 3)
    assert np.max(np.abs(c.state(c.period / 3) - y3)) < 1e-6
    # The leading non-trivial multiplier (shooting's monodromy by central differences of
    # the flow, ~1e-5 accurate), and the verdict's bound covers the difference.
    mult = monodromy_multipliers(b, y0, T)
    moduli = np.sort(np.abs(mult))[::-1]
    trivial = int(np.argmin(np.abs(mult - 1)))
    lead = max(abs(m) for k, m in enumerate(mult) if k != trivial)
    assert abs(c.max_modulus - lead) < 1e-4, (c.max_modulus, moduli)
    assert c.modulus_error is not None and c.modulus_error < 1e-3
    assert c.stability == ("stable" if lead < 1 - 1e-3 else "unstable")
    assert c.modulus_error_source is not None and "collocation" in c.modulus_error_source
    # Harmonic balance where both are resolved (N = 24 at tight tolerance).
    hb = ballbal.periodic(b, "R-R", N=24, method="hb", guess=c,
                          options=ballbal.PeriodicOptions(
                              harmonic_balance=ballbal.HarmonicBalance(tol=1e-12)))
    assert hb.method == "hb"
    assert abs(hb.period / c.period - 1) < 1e-9
    assert c.closure is not None and c.closure < 1e-6


def test_collocation_time_history_is_the_orbit(smooth):
    _, c = smooth
    h = c.time_history([0.0, c.period])
    a, e = h.row(0), h.row(1)
    # One period on: the balls a turn back (winding -1), everything else returned.
    jump = np.zeros(len(a) - 1)
    jump[: len(c.winding)] = 2 * np.pi * c.winding
    assert np.max(np.abs(np.asarray(e[1:]) - np.asarray(a[1:]) - jump)) < 1e-9
    assert c.mesh is not None and c.mesh_states is not None
    assert c.mesh[0] == 0.0 and c.mesh[-1] == 1.0 and np.all(np.diff(c.mesh) > 0)
    assert c.mesh_states.shape == ((len(c.mesh) - 1) * 4 + 1, 8)
    # verify() simulates from the collocation state itself.
    assert c.verify() < 1e-6


def test_auto_keeps_harmonic_balance_where_it_is_certified():
    b = balancer(1.2)
    auto = ballbal.periodic(b, "R-R")
    hb = ballbal.periodic(b, "R-R", method="hb")
    assert auto.method == "hb" and auto.mesh is None
    assert auto.status == hb.status == "converged"
    assert abs(auto.omega - hb.omega) < 1e-12
    assert np.max(np.abs(auto.coeffs - hb.coeffs)) < 1e-12


def _return_times(b, y0, turns, period):
    """Times at which the first ball's angle first passes its start value less k whole
    turns downwards (it winds backwards), k = 1 .. ``turns``: DOP853 at rtol 1e-12 from
    ``y0``, turn by turn (each turn ends on its event)."""
    times: list[float] = []
    t, y = 0.0, np.asarray(y0, dtype=float)
    for k in range(1, turns + 1):
        level = y0[2] - 2 * np.pi * k

        def section(_t, s, level=level):
            return s[2] - level

        section.terminal = True  # type: ignore[attr-defined]
        section.direction = -1  # type: ignore[attr-defined]
        r = solve_ivp(lambda tt, s: rhs(b, tt, s), (t, t + 2 * period), y,
                      method="DOP853", rtol=1e-12, atol=1e-13, events=section)
        assert r.t_events[0].size, f"no return in turn {k}"
        t, y = float(r.t_events[0][0]), r.y_events[0][0]
        times.append(t)
    return np.asarray(times)


def test_slow_orbit_by_auto_collocation_against_a_long_integration(slow):
    b, c = slow
    # Harmonic balance's N = 3 series is truncated there, so "auto" went to collocation.
    hb = ballbal.periodic(b, "R-R", method="hb")
    assert hb.status in ("truncated", "not_closed")
    assert c.method == "collocation" and c.converged
    assert c.period > 300
    # Four turns from the orbit's state: any error in the start decays by the leading
    # multiplier (~1e-8) per turn, so the last turn's duration is the model's period to
    # the integration's accuracy.
    times = _return_times(b, c.state(0.0), 4, c.period)
    t_int = times[3] - times[2]
    assert abs(c.period / t_int - 1) < 1e-6, (c.period, t_int)
    # Strongly attracting (the turns' durations converge at once): a bounded verdict.
    assert abs(times[1] - times[0] - t_int) < 1e-6 * t_int
    assert c.stability == "stable"
    assert c.modulus_error is not None and c.max_modulus + c.modulus_error < 1


def test_auto_switches_between_omega_1_2_and_the_slow_end():
    """Down the branch, the first Omega at which "auto" solves by collocation is where
    harmonic balance's own certificate first refuses its N = 3 series."""
    methods = {}
    for om in (1.2, 1.0, 0.95, 0.94, 0.92):
        b = balancer(om)
        auto = ballbal.periodic(b, "R-R")
        hb = ballbal.periodic(b, "R-R", method="hb")
        methods[om] = auto.method
        assert auto.method == ("hb" if hb.converged else "collocation"), (om, hb.status)
    assert methods[1.2] == "hb" and methods[0.92] == "collocation"


def test_a_guess_carries_auto_collocation_past_the_simulated_search():
    """Below Omega ~0.918 the simulated search sees no whole period; from the orbit at
    0.92 as guess, "auto" continues by collocation (harmonic balance's solve from the
    guess is refused or diverges). The periods follow the saddle-node-on-invariant-circle
    law T ~ C (Omega - Omega*)^(-1/2): two of them put the end within 3e-4 of AUTO-07p's
    Omega* = 0.917140455 (issue 33; the law's next term is what is left)."""
    p92 = ballbal.periodic(balancer(0.92), "R-R")
    assert p92.method == "collocation" and p92.converged
    p918 = ballbal.periodic(balancer(0.918), "R-R", guess=p92)
    assert p918.method == "collocation" and p918.converged
    p9175 = ballbal.periodic(balancer(0.9175), "R-R", guess=p918)
    assert p9175.method == "collocation" and p9175.converged
    assert p92.period < p918.period < p9175.period
    (w1, t1), (w2, t2) = (0.918, p918.period), (0.9175, p9175.period)
    end = (t2**2 * w2 - t1**2 * w1) / (t2**2 - t1**2)
    assert abs(end - 0.917140455) < 3e-4, end


def test_bad_collocation_options_are_refused_by_name():
    for kw, name in [({"ntst": 1}, "ntst"), ({"ntst": 10_001}, "ntst"), ({"ncol": 0}, "ncol"),
                     ({"ncol": 8}, "ncol"), ({"tol": float("nan")}, "tol"),
                     ({"step_tol": -1.0}, "step_tol"), ({"max_iter": 0}, "max_iter"),
                     ({"adapt": 101}, "adapt")]:
        with pytest.raises(ParameterError) as e:
            ballbal.Collocation(**kw)
        assert e.value.parameter == name, (kw, e.value)
    with pytest.raises(ParameterTypeError) as e:
        ballbal.Collocation(ntst=2.5)
    assert e.value.parameter == "ntst"
    b = balancer(1.2)
    with pytest.raises(ParameterError) as e:
        ballbal.periodic(b, "R-R", method="shooting")
    assert e.value.parameter == "method"
    with pytest.raises(ParameterTypeError) as e:
        ballbal.periodic(b, "R-R", collocation={"ntst": 20})
    assert e.value.parameter == "collocation"
