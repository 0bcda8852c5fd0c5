"""Equilibria of scenes with ball springs against a search written in the test on the
ground-frame Lagrangian, and their stability against time simulation."""

import itertools
import math

import numpy as np
import pytest
from ground_frame import canonical, ground_rhs
from scipy.optimize import root

import ballbal


def steady_residual(scene, q):
    """An equilibrium in the rotating frame is the configuration q turning rigidly at
    Omega in the ground frame: ground_rhs must give the centripetal accelerations."""
    n, w = scene.n_balls, scene.Omega
    x, y = q[0], q[1]
    s = np.concatenate([[x, y], q[2:], [-w * y, w * x], np.full(n, w)])
    acc = ground_rhs(scene, 0.0, s)[n + 2 :]
    return acc - np.concatenate([[-w * w * x, -w * w * y], np.zeros(n)])


def reference_spring_equilibria(scene, per):
    """The test's own search: scipy's root on steady_residual from starts in track order,
    keeping solutions still in track order."""
    n = scene.n_balls
    equal = len(set(scene.balancer.eta)) == 1
    grid = 2 * math.pi * (np.arange(per) + 0.23) / per
    found = set()
    for b1 in grid[::2]:
        for offs in itertools.combinations(grid, n - 1):
            q0 = np.concatenate([[0.0, 0.0, b1], b1 + np.array(offs)])
            r = root(lambda q: steady_residual(scene, q), q0, tol=1e-13)
            if not r.success or np.max(np.abs(steady_residual(scene, r.x))) > 1e-10:
                continue
            b = r.x[2:]
            if np.all(np.diff(np.append(b, b[0] + 2 * math.pi)) >= -1e-9):
                found.add(canonical(r.x, equal))
    return found


@pytest.mark.parametrize(("eta", "Omega", "springs", "per", "count"), [
    ((1.0, 1.0), 1.2, 1e-5, 16, 2), ((1.0, 1.0), 1.2, 2e-2, 16, 2),
    ((0.9, 1.1, 0.7), 1.2, 3e-2, 12, 2), ((0.9, 1.1, 0.7), 0.8, 1e-5, 12, 6),
    ((0.9, 1.1, 0.7), 0.95, 1e-5, 12, 6),
])
def test_equilibria_with_springs_are_those_of_the_ground_frame_formulation(
        eta, Omega, springs, per, count):
    sc = ballbal.Scene(balancer=ballbal.Balancer(eta=eta, Omega=Omega), springs=springs)
    eqs = ballbal.equilibria(sc)
    ref = reference_spring_equilibria(sc, per)
    got = [canonical(e.q, len(set(eta)) == 1) for e in eqs]
    assert len(set(got)) == len(got) == len(ref) == count
    for g in got:
        assert any(np.max(np.abs(np.subtract(g, r))) < 1e-4 for r in ref), g
    balanced = [e for e in eqs if e.kind == "balanced"]
    expected = ballbal.balanced_state(sc)
    assert len(balanced) == (expected is not None)
    if expected is not None:
        assert np.allclose(balanced[0].q, expected.q, atol=1e-9)


@pytest.mark.parametrize(("Omega", "springs"), [(1.2, 1e-3), (0.8, 1e-5)])
def test_stability_of_equilibria_with_springs_agrees_with_time_simulation(Omega, springs):
    b = ballbal.Balancer(eta=(0.9, 1.1, 0.7), Omega=Omega)
    sc = ballbal.Scene(balancer=b, springs=springs)
    eqs = ballbal.equilibria(sc)
    assert {e.stability for e in eqs} == {"stable", "unstable"}
    d = len(sc.coordinates)
    kick = 1e-6 * np.array([1.0, -0.7, 0.5, -0.3, 0.8])
    for e in eqs:
        y0 = np.concatenate([e.q + kick, np.zeros(d)])
        t = np.linspace(0.0, 1500.0, 3)
        df = ballbal.simulate(sc, y0, t, rtol=1e-11, atol=1e-14)
        dev = np.max(np.abs(df[len(t) - 1].select(sc.coordinates).to_numpy()[0] - e.q))
        if e.stability == "stable":
            assert dev < 0.2 * 1e-6, (e.kind, dev)
        else:
            assert dev > 5 * 1e-6, (e.kind, dev)
