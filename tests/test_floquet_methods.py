"""The Magnus monodromy (``Floquet(method="magnus")``) against independent estimates of
the same multipliers: RK45 at tight tolerances on the same series, and the monodromy of
tests/shooting.py (central differences of scipy flows) on the orbit, which the series
closes to 1e-8 by simulation, Tien's (2011) long-period hard case included."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.exceptions import ParameterError, ParameterTypeError

from reference import rhs, rhs_many
from shooting import flow, match_error

STANDARD_PARAMS = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0}
# (Omega, eta, pattern): the standard R-R case (balls merged), the hard R-R case
# (period ~106), an unstable O-O and a stable R-O orbit of the zeta_b = 0.05 map.
POINTS = [(1.2, 1.0, "R-R"), (1.0, 0.7, "R-R"), (1.1, 0.4, "O-O"), (1.3, 0.7, "R-O")]


@pytest.fixture(scope="module")
def solutions():
    out = {}
    for om, eta, pattern in POINTS:
        b = ballbal.Balancer(**STANDARD_PARAMS, Omega=om, eta=(eta, eta))
        s = ballbal.periodic(b, pattern, N=3,
                             options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
        assert s.converged, (om, eta, pattern, s.status)
        out[om, eta, pattern] = (b, s)
    return out


@pytest.mark.parametrize("N", [3, 8])
@pytest.mark.parametrize("point", POINTS)
def test_magnus_matches_tight_rk45(solutions, point, N):
    b, s3 = solutions[point]
    pattern = point[2]
    tight = ballbal.periodic(b, pattern, N=N, guess=s3,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=1e-11, atol=1e-13, hill=False)))
    assert tight.converged
    for rtol in (1e-6, 1e-8):
        m = ballbal.periodic(b, pattern, N=N, guess=s3,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=rtol, hill=False, method="magnus")))
        # the same series: Newton does not see the Floquet method
        assert m.omega == tight.omega
        assert m.multipliers is not None and m.info["floquet_error"] is None
        err = match_error(m.multipliers, tight.multipliers)
        assert err < 10 * rtol, (point, N, rtol, err)
        assert m.stability == tight.stability or "undetermined" in (
            m.stability, tight.stability)
        # and the scan's RK45 setting needs several times the steps for less accuracy
        if rtol == 1e-6:
            rk = ballbal.periodic(b, pattern, N=N, guess=s3,
                                  options=ballbal.PeriodicOptions(
                                      floquet=ballbal.Floquet(rtol=1e-6, atol=1e-9, hill=False)))
            assert match_error(rk.multipliers, tight.multipliers) > err
            assert rk.floquet_steps > 2 * m.floquet_steps


def shooting_multipliers(b, y0, T, h=1e-6):
    """tests/shooting.py's central-difference monodromy, its flows integrated together."""
    n2 = len(y0)
    # the batched equations are the reference's
    probe = y0 + 0.1 * np.arange(n2)
    assert np.allclose(rhs_many(b, 0.0, probe[:, None])[:, 0], rhs(b, 0.0, probe),
                       rtol=1e-13, atol=1e-13)
    starts = np.concatenate([y0[:, None] + h * np.eye(n2), y0[:, None] - h * np.eye(n2)],
                            axis=1)
    r = solve_ivp(lambda t, v: rhs_many(b, t, v.reshape(n2, 2 * n2)).ravel(), (0, T),
                  starts.ravel(), rtol=1e-11, atol=1e-13, method="DOP853")
    end = r.y[:, -1].reshape(n2, 2 * n2)
    ev = np.linalg.eigvals((end[:, :n2] - end[:, n2:]) / (2 * h))
    return ev[np.argsort(-np.abs(ev))]


def test_magnus_against_shooting_on_the_standard_case(solutions):
    b, s3 = solutions[1.2, 1.0, "R-R"]
    s = ballbal.periodic(b, "R-R", N=12, guess=s3,
                         options=ballbal.PeriodicOptions(
                             floquet=ballbal.Floquet(rtol=1e-9, method="magnus", hill=False)))
    y0, T = s.state(0.0), s.period
    shift = np.zeros(8)
    shift[2:4] = -2 * np.pi
    assert np.max(np.abs(flow(b, y0, T) - y0 - shift)) < 1e-8
    assert match_error(s.multipliers, shooting_multipliers(b, y0, T)) < 1e-5


def test_magnus_against_shooting_on_the_hard_case(solutions):
    """Period ~106: the slow orbit where RK45 takes the most steps. The series at N = 24
    closes to 1e-8 after a period of simulation, so it is the shooting's orbit."""
    b, s3 = solutions[1.0, 0.7, "R-R"]
    s = s3
    for N in (8, 16, 24):
        s = ballbal.periodic(b, "R-R", N=N, guess=s,
                             options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    m = ballbal.periodic(b, "R-R", N=24, guess=s,
                         options=ballbal.PeriodicOptions(
                             floquet=ballbal.Floquet(rtol=1e-8, method="magnus", hill=False)))
    assert 106 < m.period < 107 and m.trivial_error < 1e-5
    y0, T = m.state(0.0), m.period
    shift = np.zeros(8)
    shift[2:4] = -2 * np.pi
    assert np.max(np.abs(flow(b, y0, T) - y0 - shift)) < 1e-7
    assert match_error(m.multipliers, shooting_multipliers(b, y0, T)) < 2e-5
    assert m.stability == "stable"


def test_magnus_step_budget_gives_no_verdict(solutions):
    b, s3 = solutions[1.0, 0.7, "R-R"]
    s = ballbal.periodic(b, "R-R", N=8, guess=s3,
                         options=ballbal.PeriodicOptions(
                             floquet=ballbal.Floquet(method="magnus", max_steps=20, hill=False)))
    assert s.converged and s.multipliers is None
    assert "max_steps" in s.info["floquet_error"]
    assert s.stability == "undetermined"


@pytest.mark.parametrize("point", POINTS)
def test_loose_magnus_never_gives_the_opposite_verdict(solutions, point):
    """At rtol 0.3 the grids are coarse and the estimated error large: it widens the
    margin, so the verdict is the tight one or undetermined, never the opposite."""
    b, s3 = solutions[point]
    tight = ballbal.periodic(b, point[2], N=8, guess=s3,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=1e-11, atol=1e-13, hill=False)))
    loose = ballbal.periodic(b, point[2], N=8, guess=s3,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=0.3, method="magnus", hill=False)))
    assert loose.stability in (tight.stability, "undetermined")


def test_method_option_is_checked():
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as e:
        ballbal.periodic(b, "R-R", N=3,
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(method="euler")))
    # the field of the option that holds it
    assert e.value.parameter == "method"
    with pytest.raises(ParameterTypeError) as e:
        ballbal.Floquet(method=3)  # type: ignore[arg-type]
    assert e.value.parameter == "method"
    with pytest.raises(ParameterError) as e:  # refused when the options are made
        ballbal.Floquet(method="rk4")  # type: ignore[arg-type]
    assert e.value.parameter == "method"
