from typing import Any

import numpy as np
import pytest

import ballbal
from ballbal.exceptions import ParameterError

from shooting import monodromy_multipliers, shoot

STANDARD_PARAMS = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0}
PUBLISHED_N3 = [1.0000, 0.8641, 0.2859, 0.2859, 0.2346, 0.2346, 0.1185, 0.0951]
SHOOTING = [1.0000, 0.8637, 0.2859, 0.2859, 0.2345, 0.2345, 0.1185, 0.0951]


@pytest.fixture(scope="module")
def standard():
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.2, eta=(1.0, 1.0))
    return b, ballbal.periodic(b, "R-R", N=3)


def _moduli(sol):
    return np.sort(np.abs(sol.multipliers))[::-1]


def test_table_3_1_first_case_at_N3(standard):
    _, sol = standard
    assert sol.converged and sol.type == "R-R" and sol.stability == "stable"
    assert np.allclose(_moduli(sol), PUBLISHED_N3, atol=1.5e-3)
    # balls merged: both ball series identical
    assert np.allclose(sol.coeffs[2], sol.coeffs[3], atol=1e-10)


def test_table_3_1_converges_to_shooting_values(standard):
    b, sol3 = standard
    prev = sol3
    for N in (6, 10):
        sol = ballbal.periodic(b, "R-R", N=N, guess=prev,
                               options=ballbal.PeriodicOptions(
                                   floquet=ballbal.Floquet(rtol=1e-10, atol=1e-12)))
        prev = sol
    assert abs(sol.omega - 0.25141) < 1e-5
    assert np.allclose(_moduli(sol), SHOOTING, atol=1e-4)
    assert sol.trivial_error < 1e-6
    assert sol.verify() < 1e-6


def test_standard_case_against_shooting_in_this_test(standard):
    b, sol3 = standard
    sol = ballbal.periodic(b, "R-R", N=10, guess=sol3)
    y0, T = shoot(b, sol.state(0.0), sol.period, [0, 0, -1, -1], phase_index=2)
    assert abs(2 * np.pi / T - sol.omega) < 1e-8
    assert np.max(np.abs(y0 - sol.state(0.0))) < 1e-6
    mult = monodromy_multipliers(b, y0, T)
    assert np.allclose(np.abs(mult), _moduli(sol), atol=1e-5)


def test_hard_case_needs_more_harmonics():
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.0, eta=(0.7, 0.7))
    # The N = 3 series itself (refine=False: the verdict's bound would raise N here).
    s3 = ballbal.periodic(b, "R-R", N=3,
                          options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(refine=False)))
    assert s3.converged and s3.N == 3 and s3.stability == "undetermined"
    # Tien (2011) table 3-1: trivial multiplier 1.1808 at N = 3, 1.0379 at N = 4
    assert s3.trivial_error > 0.1
    assert abs((1 + s3.trivial_error) - 1.1808) < 0.01
    s4 = ballbal.periodic(b, "R-R", N=4, guess=s3,
                          options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(refine=False)))
    assert 0.02 < s4.trivial_error < 0.05
    s = s4
    for N in (8, 16):  # N = 16 is what the test relies on
        s = ballbal.periodic(b, "R-R", N=N, guess=s)
    assert s.trivial_error < 1e-4
    assert abs(s.omega - 0.059) < 5e-4 and s.period > 100
    assert s.verify() < 1e-5
    assert s.stability == "stable"


def test_oo_solution_cross_checked_by_simulation_and_shooting():
    # Tien (2011) table 4-7: O-O at zeta = zeta_b = 0.1, Omega = 1.1, eta = 1.3, omega ~ 0.09
    b = ballbal.Balancer(mu=0.2, zeta=0.1, zeta_b=0.1, delta=50, Omega=1.1, eta=(1.3, 1.3))
    sol = ballbal.periodic(b, "O-O", N=8)
    assert sol.converged and sol.type == "O-O"
    assert abs(sol.omega - 0.09) < 0.005
    assert sol.verify() < 1e-6
    y = sol.state(0.0)
    # phase condition of the shooting: keep x(0) fixed (the orbit crosses it transversally)
    y0, T = shoot(b, y, sol.period, [0, 0, 0, 0], phase_index=0)
    assert abs(2 * np.pi / T - sol.omega) < 1e-7
    mult = monodromy_multipliers(b, y0, T)
    assert np.allclose(np.abs(mult), _moduli(sol), atol=1e-5)


def test_round_trip_solution_stays_on_orbit(standard):
    b, sol = standard
    sol8 = ballbal.periodic(b, "R-R", N=8, guess=sol)
    t = np.linspace(0, 3 * sol8.period, 7)
    sim = ballbal.simulate(b, sol8.state(0.0), t, rtol=1e-11, atol=1e-13)
    orbit = sol8.time_history(t)
    for c in ("x", "y", "b1", "b2", "db1"):
        assert np.max(np.abs(sim[c].to_numpy() - orbit[c].to_numpy())) < 1e-4


def test_failure_is_data_not_exception():
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.2, eta=(1.0, 1.0))
    junk = np.full((4, 7), 50.0)
    sol = ballbal.periodic(b, "R-R", N=3, guess=(5.0, junk),
                           options=ballbal.PeriodicOptions(
                               harmonic_balance=ballbal.HarmonicBalance(max_iter=20)))
    assert not sol.converged
    assert sol.status in ("diverged", "singular", "max_iterations")
    assert sol.omega is None and sol.multipliers is None
    assert sol.stability == "undetermined"
    # no periodic motion of this type: perfect balance attracts everything here
    stable_pb = ballbal.Balancer(mu=0.2, zeta=0.1, zeta_b=0.1, delta=50, Omega=3.0, eta=(1.0, 1.0))
    s = ballbal.periodic(stable_pb, "O-O", N=3,
                         options=ballbal.PeriodicOptions(
                             guess=ballbal.GuessSearch(settle=300, window=500)))
    assert s.status == "no_guess" and s.omega is None


def test_bad_periodic_input():
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as err:
        ballbal.periodic(b, "R-X")
    assert err.value.parameter == "pattern"
    with pytest.raises(ParameterError) as err:
        ballbal.periodic(b, "R-R-R")
    assert err.value.parameter == "pattern"
    with pytest.raises(ParameterError) as err:
        ballbal.periodic(b, N=0)
    assert err.value.parameter == "N"
    with pytest.raises(ParameterError) as err:
        ballbal.periodic(b, N=5,
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(samples=4)))
    assert err.value.parameter == "samples"
    with pytest.raises(ParameterError) as err:
        ballbal.periodic(b,
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(tol=float("nan"))))
    assert err.value.parameter == "tol"
    # The binding's guess-shape check (not yet a ParameterError) names the guess.
    with pytest.raises(ValueError, match="guess"):
        ballbal.periodic(b, guess=(0.2, np.zeros(5)))


def test_ro_solution_by_continuation_cross_checked():
    """Tien (2011) section 3-2: R-O at zeta 0.02, zeta_b 0.1, Omega 1.3, eta 0.8. There the
    perfect balance attracts every simulated start, so (as in Tien (2011)) the orbit is
    reached by continuation from a point where time simulation lands on it."""
    b = ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.05, delta=50, Omega=1.4, eta=(0.8, 0.8))
    sol = ballbal.periodic(b, "R-O", N=8)
    assert sol.converged and sol.type == "R-O"
    for zb in np.linspace(0.05, 0.1, 6)[1:]:
        b = b.replace(zeta_b=float(zb))
        sol = ballbal.periodic(b, "R-O", N=8, guess=sol)
        assert sol.converged
    for Om in (1.375, 1.35, 1.325, 1.3):
        b = b.replace(Omega=Om)
        sol = ballbal.periodic(b, "R-O", N=8, guess=sol)
        assert sol.converged, Om
    assert sol.type == "R-O"
    assert sol.verify() < 1e-5
    y0, T = shoot(b, sol.state(0.0), sol.period, [0, 0, -1, 0], phase_index=2)
    assert abs(2 * np.pi / T - sol.omega) < 1e-7
    mult = monodromy_multipliers(b, y0, T)
    assert np.allclose(np.abs(mult), _moduli(sol), atol=1e-4)
    # Not attracting from rest at this point: the Floquet verdict must say unstable
    # or (if it is stable with a small basin) agree with the shooting multipliers.
    nontrivial = np.delete(mult, np.argmin(np.abs(mult - 1)))
    assert sol.stability == ("unstable" if np.max(np.abs(nontrivial)) > 1 else "stable")


def test_hb_stage_counters_count_what_a_warm_solve_does(standard):
    """The stage timers behind bench_periodic's per-stage printout: one solve, its LU
    factorisations (at most one per Newton iteration), one residual per iteration plus
    the first, and nothing counted while they are off."""
    from ballbal import _native

    standard, _ = standard
    seed = ballbal.periodic(standard.replace(Omega=1.19), "R-R", N=8)

    def profiled(n: int) -> tuple[Any, list[float]]:
        _native.hb_stage_profile(True)
        try:
            sol = ballbal.periodic(standard, "R-R", N=n, guess=seed,
                                   options=ballbal.PeriodicOptions(
                                       floquet=ballbal.Floquet(monodromy=False, hill=False)))
            return sol, _native.hb_stage_seconds()
        finally:
            _native.hb_stage_profile(False)

    sol, st = profiled(8)
    assert sol.status == "converged"
    assert st[4] == 1 and 0 < st[5] <= sol.iterations
    # the first residual, then one per line-search trial (a full step each here)
    assert st[6] == sol.iterations + 1
    assert all(v > 0 for v in st[:4])
    sol3, st3 = profiled(3)
    assert sol3.status == "converged" and st3[5] == sol3.iterations
    ballbal.periodic(standard, "R-R", N=8, guess=seed,
                     options=ballbal.PeriodicOptions(
                         floquet=ballbal.Floquet(monodromy=False, hill=False)))
    assert _native.hb_stage_seconds() == [0.0] * 7
