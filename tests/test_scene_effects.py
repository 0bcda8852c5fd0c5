"""Scene effects (springs, ramp, gravity, impulse) against the ground-frame Lagrangian
written in the test, their limits, and the refusals of time-dependent scenes."""


import numpy as np
import pytest
from ground_frame import FULL, NOT_STATE, ground_gap

import ballbal

from reference import jacobi_integral


def test_every_effect_against_the_ground_frame_lagrangian():
    y0 = np.array([0.2, -0.1, 0.3, 2.0, 4.5, 0.05, 0.1, -0.2, 0.1, 0.3])
    t = np.linspace(0.0, 40.0, 81)
    gap, df = ground_gap(FULL, y0, t)
    assert gap < 1e-7
    # and the effects do something: without them the motion differs
    plain = ballbal.simulate(FULL.balancer, y0, t, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(plain["x"].to_numpy() - df["x"].to_numpy())) > 1e-2


def test_spring_chain_against_the_ground_frame_lagrangian():
    y0 = np.array([0.2, -0.1, 0.3, 2.0, 4.5, 0.05, 0.1, -0.2, 0.1, 0.3])
    t = np.linspace(0.0, 40.0, 81)
    chain = FULL.replace(spring_layout="chain")
    gap, df = ground_gap(chain, y0, t)
    assert gap < 1e-7
    ring = ballbal.simulate(FULL, y0, t, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(ring["b1"].to_numpy() - df["b1"].to_numpy())) > 1e-2


def test_two_ball_ring_is_a_chain_of_twice_the_stiffness():
    b = ballbal.Balancer(Omega=1.3, zeta_b=0.05)
    y0 = np.array([0.1, 0.0, 0.4, 2.9, 0.0, 0.1, -1.3, -1.0])
    t = np.linspace(0.0, 60.0, 61)
    ring = ballbal.simulate(ballbal.Scene(balancer=b, springs=1e-3), y0, t, rtol=1e-11,
                            atol=1e-13)
    chain = ballbal.simulate(ballbal.Scene(balancer=b, springs=2e-3, spring_layout="chain"),
                             y0, t, rtol=1e-11, atol=1e-13)
    half = ballbal.simulate(ballbal.Scene(balancer=b, springs=1e-3, spring_layout="chain"),
                            y0, t, rtol=1e-11, atol=1e-13)
    cols = ["x", "y", "b1", "b2"]
    assert np.max(np.abs(ring.select(cols).to_numpy() - chain.select(cols).to_numpy())) < 1e-9
    assert np.max(np.abs(ring.select(cols).to_numpy() - half.select(cols).to_numpy())) > 1e-3
    eq_r = ballbal.equilibria(ballbal.Scene(balancer=b, springs=1e-3))
    eq_c = ballbal.equilibria(ballbal.Scene(balancer=b, springs=2e-3, spring_layout="chain"))
    assert [e.kind for e in eq_r] == [e.kind for e in eq_c]
    for u, v in zip(eq_r, eq_c, strict=True):
        assert np.allclose(u.q, v.q, atol=1e-9)


@pytest.mark.parametrize("effect", ["springs", "ramp", "gravity", "impulse"])
def test_each_effect_alone_against_the_ground_frame(effect):
    kw = {"springs": 0.0, "ramp": None, "gravity": 0.0, "impulse": None}
    kw[effect] = getattr(FULL, effect)
    sc = ballbal.Scene(balancer=FULL.balancer, **kw)
    y0 = np.array([0.1, 0.1, 0.0, 2.1, 4.2, 0.0, 0.0, -1.2, -1.2, -1.2])
    gap, _ = ground_gap(sc, y0, np.linspace(0.0, 30.0, 31))
    assert gap < 1e-7


def test_effects_at_zero_equal_the_planar_model():
    b = FULL.balancer
    off = ballbal.Scene(balancer=b, ramp=ballbal.Ramp(to=b.Omega, start=0.0, duration=3.0),
                        impulse=ballbal.Impulse(amplitude=0.0, t0=1.0, sharpness=1.0))
    assert off._effects_on()  # the scene path really runs
    t = np.linspace(0, 50, 101)
    a = ballbal.simulate(b, t_span=(0, 50))
    c = ballbal.simulate(off, t_span=(0, 50))
    assert np.max(np.abs(a.drop("t").to_numpy() - c.drop("t").to_numpy())) < 1e-12
    assert t.size == 101


def test_spring_potential_joins_the_jacobi_integral():
    """Undamped, constant spin: T2 - T0 + V_support + V_springs is conserved; without the
    spring term it is not (so the spring force is the gradient of that potential)."""
    b = ballbal.Balancer(mu=0.3, zeta=0.0, zeta_b=0.0, delta=20, Omega=1.4, eta=(0.8, 1.2, 0.5))
    k = 3e-3
    sc = ballbal.Scene(balancer=b, springs=k)
    y0 = np.array([0.2, -0.1, 0.0, 2.0, 4.0, 0.05, 0.1, -0.3, 0.2, 0.1])
    t = np.linspace(0, 200, 401)
    s = ballbal.simulate(sc, y0, t, rtol=1e-10, atol=1e-12).drop(NOT_STATE).to_numpy()
    beta = s[:, 2:5]
    sp = np.stack([beta[:, 1] - beta[:, 0], beta[:, 2] - beta[:, 1],
                   beta[:, 0] + 2 * np.pi - beta[:, 2]], axis=1) - 2 * np.pi / 3
    v_springs = 0.5 * k * b.delta**2 * np.sum(sp**2, axis=1)
    h = jacobi_integral(b, s) + v_springs
    assert np.max(np.abs(h - h[0])) < 1e-7
    h_wrong = jacobi_integral(b, s)
    assert np.max(np.abs(h_wrong - h_wrong[0])) > 1e-3


def test_periodic_solution_with_springs_is_a_real_orbit():
    base = ballbal.periodic(ballbal.Balancer(), "R-R", N=8)
    s = ballbal.periodic(ballbal.Scene(springs=1e-5), "R-R", N=12, guess=base)
    assert s.converged and abs(s.omega - base.omega) > 1e-3  # the springs matter
    assert s.verify() < 1e-6  # time simulation of the same scene closes the orbit
    assert not s.verdicts_disagree and s.stability == s.hill_stability


@pytest.mark.parametrize(("kw", "effect"), [
    ({"ramp": ballbal.Ramp(to=2.0)}, "ramp"), ({"gravity": 0.1}, "gravity"),
    ({"impulse": ballbal.Impulse(amplitude=1.0, t0=1.0, sharpness=1.0)}, "impulse"),
])
def test_time_dependent_scenes_refuse_harmonic_balance(kw, effect):
    sc = ballbal.Scene(**kw)
    assert sc.time_dependence == effect
    with pytest.raises(ValueError, match=f"^periodic: .*'{effect}'"):
        ballbal.periodic(sc, "R-R")
    with pytest.raises(ValueError, match=f"^equilibria: .*'{effect}'"):
        ballbal.equilibria(sc)
    with pytest.raises(ValueError, match=f"^scan: .*'{effect}'"):
        ballbal.scan(sc, Omega=[1.2], eta=[1.0])
    ballbal.simulate(sc, t_span=(0, 5))  # simulation always works


def test_scene_without_effects_is_the_balancer():
    sc = ballbal.Scene(balancer=ballbal.Balancer(Omega=1.3))
    a = ballbal.scan(sc, Omega=[1.2], eta=[1.0])
    b = ballbal.scan(sc.balancer, Omega=[1.2], eta=[1.0])
    assert a.drop("seconds").equals(b.drop("seconds"))
