"""Transients of scenes: speed disturbances, track-damping studies ([TwoBallStrength])."""

import math

import numpy as np
import polars as pl
import pytest
from ground_frame import canonical

import ballbal


def test_speed_disturbance_ends_in_the_closed_form_perfect_balance():
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, zeta_b=0.1, eta=(0.8, 0.8))
    res = ballbal.disturbance_response(b, to=2.5, t_end=1500)
    assert res.final_r < 1e-6 and res.settle_time is not None
    end = res.trajectory.row(-1, named=True)
    angle = math.acos(-1 / (2 * 0.8))  # perfect balance, closed form
    got = sorted(abs(math.remainder(end[k], 2 * math.pi)) for k in ("b1", "b2"))
    assert np.allclose(got, angle, atol=1e-6)
    assert res.peak > 10 * 0.01  # the disturbance really throws the rotor out


def test_track_damping_trade_off_of_seed_001():
    """More track damping: a smaller peak; past a point, a longer settling; the combined
    index has an interior optimum."""
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, eta=(1.0, 1.0))
    zb = [0.01, 0.05, 0.1, 0.2, 0.4, 0.8]
    df = ballbal.track_damping_study(b, zb, to=2.5, t_end=2000)
    peak = df["peak"].to_list()
    settle = df["settle_time"].to_list()
    assert all(p1 > p2 for p1, p2 in zip(peak, peak[1:], strict=False)), peak
    assert settle[5] > settle[4] > settle[2] and settle[0] > settle[2], settle
    best = df.filter(pl.col("optimal"))["zeta_b"][0]
    assert zb[0] < best < zb[-1], df


def test_disturbance_needs_a_stable_balanced_state_and_an_autonomous_scene():
    with pytest.raises(ballbal.exceptions.ParameterError) as info:
        ballbal.disturbance_response(ballbal.Balancer(Omega=1.2), to=1.5)
    assert info.value.parameter == "model"
    with pytest.raises(ballbal.exceptions.NotAutonomousError) as e:
        ballbal.disturbance_response(ballbal.Scene(gravity=0.1), to=1.5)
    assert e.value.effect == "gravity"


@pytest.mark.parametrize("tilt", [None, ballbal.Tilt(a=1.8, b=2.2, j_t=0.15, j_z=0.25,
                                                     zeta_r=0.05)])
def test_speed_disturbance_of_a_spring_balancer_settles_in_its_balanced_state(tilt):
    """Springs leave a residual whirl; after the disturbance the simulation must come to
    rest in the balanced state at the new speed, computed as an equilibrium."""
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, zeta_b=0.1)
    sc = ballbal.Scene(balancer=b, springs=1e-4, tilt=tilt)
    res = ballbal.disturbance_response(sc, to=2.5, t_end=1500)
    target = ballbal.balanced_state(sc.replace(Omega=2.5))
    assert target.stability == "stable"
    end = res.trajectory.row(-1, named=True)
    q = np.array([end[c] for c in sc.coordinates])
    # identical balls: the same state whichever ball is where (they may swap places)
    o = len(sc.coordinates) - sc.n_balls
    assert np.allclose(canonical(q, True, o), canonical(target.q, True, o), atol=1e-5)
    assert res.final_r == pytest.approx(math.hypot(*target.q[:2]), abs=1e-6)
    assert res.final_r > 0.1  # the springs' residual whirl, not a perfect balance
    start = math.hypot(*ballbal.balanced_state(sc).q[:2])
    assert res.peak > max(start, res.final_r) + 0.05  # thrown out by the disturbance
