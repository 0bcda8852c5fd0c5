"""Hard parameter points (issue 5): each asserts the right answer from an independent
method (time simulation of the orbit, Hill's method, closed forms) or a clean status."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ballbal

STD = ballbal.Balancer()
HARD = ballbal.Balancer(Omega=1.0, eta=(0.7, 0.7))


def genuine(s, closure=1e-6):
    """A converged solution that time simulation confirms closes after one period."""
    return s.converged and s.verify() < closure


def test_hard_rr_case_auto_N_meets_its_target():
    s = ballbal.periodic(HARD, "R-R", N="auto",
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(target=1e-7)))
    assert s.target_met and s.N >= 8
    assert s.trivial_error < 1e-7
    # Tien's (2011) period and an independent closure check by time simulation
    assert abs(2 * math.pi / s.omega - 106.5) < 0.1
    assert genuine(s, 1e-7)
    low = ballbal.periodic(HARD, "R-R", N=3, guess=s,
                           options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(refine=False)))
    assert abs(abs(low.multipliers[0]) - 1.1808) < 2e-3  # Tien (2011) table 3-1, N = 3


def test_auto_N_stays_low_where_the_point_is_easy():
    s = ballbal.periodic(STD, "R-R", N="auto",
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(target=1e-5)))
    h = ballbal.periodic(HARD, "R-R", N="auto",
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(target=1e-5)))
    assert s.target_met and h.target_met and s.N < h.N


def test_scan_with_auto_N_adapts_point_by_point():
    df = ballbal.scan(STD.replace(eta=(0.7, 0.7)), Omega=[1.0, 1.05, 1.2], N="auto",
                      options=ballbal.ScanOptions(harmonic_balance=dataclasses.replace(
                          ballbal.options.SCAN_DEFAULTS.harmonic_balance, target=1e-6)))
    n = dict(zip(df["Omega"], df["N"], strict=True))
    assert df["target_met"].all()
    assert n[1.0] > n[1.2]


@pytest.mark.parametrize(("Omega", "eta"), [(1.0, 1.0), (1.0, 0.7), (1.2, 3.0)])
def test_omega_exactly_one_and_large_eta(Omega, eta):
    b = STD.replace(Omega=Omega, eta=(eta, eta))
    s = ballbal.periodic(b, "R-R", N="auto",
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(target=1e-6)))
    # the tail measures coefficients; the state's error is a few times larger
    assert genuine(s, 1e-5), (s.status, s.omega)
    assert not s.verdicts_disagree


@pytest.mark.parametrize("Omega", [4.0, 6.0])
def test_far_above_resonance(Omega):
    """Perfect balance is the attractor: simulation from rest ends there, the
    equilibrium analysis says it is stable, and no R-R solution is claimed."""
    b = STD.replace(Omega=Omega)
    pb = next(e for e in ballbal.equilibria(b) if e.kind == "perfect_balance")
    assert pb.stability == "stable" and pb.routh_hurwitz
    sim = ballbal.simulate(b, t_span=(0, 600), y0=[0.1, 0, 0.3, -0.3, 0, 0, 0, 0])
    end = sim.row(-1, named=True)
    assert math.hypot(end["x"], end["y"]) < 1e-4
    # the balls sit at +-arccos(-1/(2 eta)), in either order, modulo whole turns
    ends = sorted(abs(math.remainder(end[k], 2 * math.pi)) for k in ("b1", "b2"))
    assert np.allclose(ends, abs(pb.q[2]), atol=1e-3), (ends, pb.q)
    s = ballbal.periodic(b, "R-R",
                         options=ballbal.PeriodicOptions(
                             guess=ballbal.GuessSearch(settle=500, window=800)))
    assert s.status == "no_guess" or genuine(s)


def test_eta_just_above_one_half():
    eta = 0.5 + 1e-6
    b = STD.replace(Omega=1.5, eta=(eta, eta))
    pb = next(e for e in ballbal.equilibria(b) if e.kind == "perfect_balance")
    angle = math.acos(-1 / (2 * eta))  # closed form
    assert abs(abs(pb.q[2]) - angle) < 1e-9 and abs(pb.q[2] + pb.q[3]) < 1e-9
    assert pb.routh_hurwitz == (pb.stability == "stable")
    below = STD.replace(Omega=1.5, eta=(0.5 - 1e-6, 0.5 - 1e-6))
    assert not any(e.kind == "perfect_balance" for e in ballbal.equilibria(below))


def test_very_light_damping_verdict_is_right_or_undetermined():
    # reached by continuation in the damping, as a user would: from rest a simulation
    # with this little damping takes tens of thousands of time units to settle
    s = ballbal.periodic(STD, "R-R", N=8)
    for z in (0.02, 0.01, 0.005, 0.002, 0.001):
        b = STD.replace(zeta=z, zeta_b=z)
        s = ballbal.periodic(b, "R-R", N=12, guess=s)
        assert s.converged, (z, s.status)
    # strongly unstable here (a multiplier near 19), so the closure check over one
    # period amplifies truncation error: solve with enough harmonics for it
    s = ballbal.periodic(b, "R-R", N=24, guess=s)
    assert genuine(s)
    mods = np.sort(np.abs(s.multipliers))[::-1]
    assert mods[2] > 0.95  # the non-trivial ones crowd the unit circle
    hill = s.hill_stability
    assert not s.verdicts_disagree
    if s.stability != "undetermined":
        assert s.stability == hill or hill == "undetermined"
    tight = ballbal.periodic(b, "R-R", N=24, guess=s,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=1e-11, atol=1e-13)))
    assert {s.stability, tight.stability} != {"stable", "unstable"}


def test_past_a_fold_newton_stops_or_finds_a_real_orbit():
    """zeta_b 0.1, eta 1.0: the R-R branch ends between Omega 1.4 and 1.5. Newton
    from the last solution must not return garbage flagged converged."""
    b = STD.replace(zeta_b=0.1)
    df = ballbal.scan(b, Omega=(1.0, 1.6, 0.1), eta=[1.0])
    found = df.filter(df["status"] == "converged")["Omega"].to_list()
    assert 1.3 in found and 1.6 not in found
    last = ballbal.periodic(b.replace(Omega=1.0), "R-R", N=3)
    for om in np.arange(1.05, max(found) + 0.01, 0.05):
        last = ballbal.periodic(b.replace(Omega=round(om, 2)), "R-R", N=3, guess=last)
        assert last.converged
    for om in (max(found) + 0.05, max(found) + 0.1, 1.6):
        s = ballbal.periodic(b.replace(Omega=om), "R-R", N=3, guess=last)
        assert s.status in {"diverged", "singular", "max_iterations"} or genuine(s), s.status
        if not s.converged:
            assert s.omega is None


def test_many_harmonics_stay_well_conditioned():
    s16 = ballbal.periodic(HARD, "R-R", N=16)
    s32 = ballbal.periodic(HARD, "R-R", N=32, guess=s16)
    assert s32.converged and np.isfinite(s32.pivot_ratio) and s32.pivot_ratio < 1e8
    assert abs(s32.omega - s16.omega) < 1e-9
    assert s32.trivial_error < 1e-9 and s32.residual < 1e-10
    assert genuine(s32, 1e-8)


def test_long_period_monodromy_keeps_its_accuracy():
    """Below resonance the R-R branch slows down (period ~190 at Omega 0.9715)."""
    b = HARD
    s = ballbal.periodic(b, "R-R", N=16)
    for om in (0.99, 0.98, 0.976, 0.9715):
        s = ballbal.periodic(b.replace(Omega=om), "R-R", N=48, guess=s,
                             options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
        assert s.converged, (om, s.status)
    assert s.omega < 0.035 and s.period > 175
    assert s.floquet_steps is not None and s.floquet_steps < 20_000
    assert s.trivial_error < 1e-9
    assert genuine(s, 1e-7)
    # a step budget too small ends in a message and an undetermined verdict, not a hang
    cut = ballbal.periodic(b.replace(Omega=0.9715), "R-R", N=48, guess=s,
                           options=ballbal.PeriodicOptions(
                               floquet=ballbal.Floquet(max_steps=100, hill=False)))
    assert cut.converged and cut.stability == "undetermined"
    assert "max_steps" in cut.info["floquet_error"]


@pytest.mark.parametrize(("delta", "mu"), [(0.5, 0.2), (500.0, 0.2), (50.0, 0.01),
                                           (50.0, 0.9)])
def test_extreme_but_valid_parameters(delta, mu):
    b = ballbal.Balancer(mu=mu, delta=delta, Omega=1.2, eta=(1.0, 1.0))
    s = ballbal.periodic(b, "R-R", N="auto",
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(target=1e-6),
                             guess=ballbal.GuessSearch(settle=800, window=1500)))
    assert s.status in {"converged", "no_guess", "diverged", "max_iterations", "singular"}
    if s.converged:
        assert genuine(s, 1e-5)
        assert not s.verdicts_disagree
    else:
        assert s.omega is None


params = st.fixed_dictionaries({
    "mu": st.floats(0.05, 0.5), "zeta": st.floats(0.01, 0.2), "zeta_b": st.floats(0.01, 0.2),
    "delta": st.floats(5.0, 200.0), "Omega": st.floats(0.8, 2.5), "eta": st.floats(0.5, 1.5),
})


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(params)
def test_random_points_never_lie(p):
    b = ballbal.Balancer(**{**p, "eta": (p["eta"], p["eta"])})
    df = ballbal.scan(b, Omega=[p["Omega"]], eta=[p["eta"]], patterns=["R-R", "O-O"],
                      N="auto", options=ballbal.ScanOptions(
                          harmonic_balance=dataclasses.replace(
                              ballbal.options.SCAN_DEFAULTS.harmonic_balance, target=1e-6),
                          floquet=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.floquet,
                                                      hill=True, hill_band=None)))
    ok = df.filter(df["status"] == "converged")
    for c in ("omega", "residual", "max_modulus", "trivial_error"):
        assert ok[c].null_count() == 0 and not ok[c].is_nan().any(), c
    assert (ok["residual"] <= 1e-10).all()
    assert (~ok["verdicts_disagree"]).all()
    for row in ok.iter_rows(named=True):
        if row["target_met"]:
            assert row["trivial_error"] <= 1e-4  # max(target, 100 rtol) with rtol 1e-6
        # the verdict survives much tighter tolerances
        s = ballbal.periodic(b, row["type"], N=row["N"],
                             guess=None if row["type"] != "R-R" else None,
                             options=ballbal.PeriodicOptions(
                                 floquet=ballbal.Floquet(rtol=1e-10, atol=1e-12, hill=False),
                                 guess=ballbal.GuessSearch(settle=800, window=1500)))
        if s.converged and abs(s.omega - row["omega"]) < 1e-6:
            assert {s.stability, row["stability"]} != {"stable", "unstable"}
