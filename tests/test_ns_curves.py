"""Neimark–Sacker (NS) events and curves of periodic solutions (ballbal.continuation):
the oil-whirl orbit of a balancer on Ocvirk's short bearing (L/D 1/2, rho = e/c 0.5,
Omega 2, an external damper zeta; the balls rock, O-O) has a complex pair of multipliers
that leaves the unit circle between zeta 0.100 and 0.136. Checked against shooting
written here (flows over one period by ballbal.simulate, the monodromy by central
differences of the flows, Newton on the closure: no harmonic balance, Hill matrix or
variational equations of the package), and against one-parameter branches run at a curve
point's second parameter (event location on the monodromy's multipliers, a different
computation from the curve's Hill matrix)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import ballbal
from ballbal.bearing import Bearing
from ballbal.continuation import Continuation, periodic_branch, periodic_curve
from ballbal.exceptions import ParameterError

N = 6
SHORT = Bearing(length_ratio=0.5, model="short")


def scene(zeta: float, rho: float = 0.5) -> ballbal.Scene:
    b = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=0.1, delta=50, Omega=2.0, eta=(1.0, 1.0))
    return ballbal.Scene(balancer=b, support=ballbal.BearingSupport(SHORT, rho=rho))


# --- shooting ------------------------------------------------------------------------

STATE = ["x", "y", "b1", "b2", "dx", "dy", "db1", "db2"]
PHASE = 4  # x'(0) kept at the guess's value: the free time shift fixed


def _flow(sc: ballbal.Scene, y0: np.ndarray, T: float) -> np.ndarray:
    df = ballbal.simulate(sc, y0, np.array([0.0, T]), rtol=1e-11, atol=1e-13)
    return df.select(STATE).to_numpy()[-1]


def _monodromy(sc: ballbal.Scene, y0: np.ndarray, T: float, h: float = 1e-4) -> np.ndarray:
    M = np.empty((8, 8))
    for j in range(8):
        e = np.zeros(8)
        e[j] = h
        M[:, j] = (_flow(sc, y0 + e, T) - _flow(sc, y0 - e, T)) / (2 * h)
    return M


def shoot(sc: ballbal.Scene, y_guess: np.ndarray, T_guess: float
          ) -> tuple[np.ndarray, float, np.ndarray]:
    """The orbit through the phase section near ``y_guess`` by Newton on
    ``phi_T(y0) - y0 = 0`` (unknowns: the state but ``x'``, and ``T``; the Jacobian from
    the monodromy and the flow's velocity, both differenced): initial state, period and
    the monodromy's eigenvalues there."""
    y0, T = y_guess.copy(), T_guess
    free = [i for i in range(8) if i != PHASE]
    for _ in range(6):
        M = _monodromy(sc, y0, T)
        r = _flow(sc, y0, T) - y0
        if np.max(np.abs(r)) < 1e-10:
            return y0, T, np.linalg.eigvals(M)
        dt = 1e-4
        f = (_flow(sc, y0, T + dt) - _flow(sc, y0, T - dt)) / (2 * dt)
        J = np.column_stack([(M - np.eye(8))[:, free], f])
        step = np.linalg.solve(J, -r)
        y0[free] += step[:-1]
        T += step[-1]
    raise AssertionError(f"shooting did not converge: {np.max(np.abs(r))}")


def critical_pair(m: np.ndarray) -> complex:
    """The complex multiplier (upper half plane) closest to the unit circle."""
    pairs = [z for z in m if z.imag > 1e-7]
    return min(pairs, key=lambda z: abs(abs(z) - 1.0))


@cache
def shot(zeta: float, rho: float, guess: tuple[float, ...], T: float) -> tuple[complex, float]:
    _, T, m = shoot(scene(zeta, rho), np.array(guess), T)
    return critical_pair(m), T


def shot_at(sol: ballbal.PeriodicSolution, zeta: float, rho: float) -> tuple[complex, float]:
    return shot(zeta, rho, tuple(sol.state(0.0)), 2 * np.pi / sol.omega)


# --- the branch and the curve ------------------------------------------------------

@cache
def whirl_branch() -> ballbal.continuation.Branch:
    # zeta 0.3: the whirl attracts strongly (pair 0.95), a short simulation finds it
    start = ballbal.periodic(scene(0.3), "O-O", N=N,
                             options=ballbal.PeriodicOptions(
                                 guess=ballbal.GuessSearch(settle=200.0, window=100.0)))
    assert start.status == "converged" and start.stability == "stable"
    return periodic_branch(start, "zeta", range=(0.115, 0.3),
                           options=Continuation(ds=0.02, ds_max=0.05, max_points=40,
                                                forward=False))


def ns_event() -> int:
    ev = whirl_branch().events
    rows = [i for i, t in enumerate(ev["type"]) if t == "neimark_sacker"]
    assert len(rows) == 1, ev
    return rows[0]


@cache
def ns_curve() -> ballbal.continuation.Curve:
    return periodic_curve(whirl_branch(), ns_event(), "rho", range=(0.47, 0.53),
                          range1=(0.05, 0.3),
                          options=Continuation(ds=0.02, ds_max=0.05, max_points=3))


def test_ns_event_is_where_shooting_multipliers_leave_the_unit_circle():
    br = whirl_branch()
    i = ns_event()
    z_ns = br.events["zeta"][i]
    sol = br.event_solutions[i]
    assert 0.13 < z_ns < 0.14
    # |lambda| - 1 of the shooting's complex pair on both sides and at the event; the
    # zero of the quadratic through the three is the NS point of the exact orbit
    zs = np.array([z_ns - 0.004, z_ns, z_ns + 0.004])
    d = np.array([abs(shot_at(sol, z, 0.5)[0]) - 1.0 for z in zs])
    assert d[0] > 0 > d[2]
    c = np.polyfit(zs - z_ns, d, 2)
    r = np.roots(c)
    z0 = z_ns + r[np.argmin(np.abs(r))].real
    # N = 6 series: their truncation moves the multipliers by ~2e-6 (measured 1.6e-6 at
    # the event), i.e. ~3e-5 in zeta at the slope d|lambda|/dzeta ~ -0.058
    assert abs(d[1]) < 5e-6, d
    assert abs(z0 - z_ns) < 5e-5, (z0, z_ns, d)


def test_ns_curve_points_have_a_shooting_pair_on_the_unit_circle_at_theta():
    c = ns_curve()
    t = c.table
    assert c.kind == "neimark_sacker" and "theta" in t.columns
    assert t.height >= 5, c.stop
    assert t["rho"].min() < 0.495 and t["rho"].max() > 0.505
    sols = c.meta["solutions"]
    for row in (0, t.height - 1):
        zeta, rho, theta = t["zeta"][row], t["rho"][row], t["theta"][row]
        lam, T = shot_at(sols[row], zeta, rho)
        assert abs(abs(lam) - 1.0) < 2e-6, (row, lam)
        assert abs(np.angle(lam) - theta) < 1e-5, (row, lam, theta)
        assert T == pytest.approx(2 * np.pi / t["omega"][row], rel=1e-7)


def test_ns_curve_meets_the_branch_event_at_another_rho():
    c = ns_curve()
    t = c.table
    row = t.height - 1
    zeta, rho = t["zeta"][row], t["rho"][row]
    # a branch in zeta at the curve point's rho, started off the point on the stable side
    sol = c.meta["solutions"][row]
    start = ballbal.periodic(scene(zeta + 0.008, rho), "O-O", guess=sol, N=N)
    br = periodic_branch(start, "zeta", range=(zeta - 0.01, zeta + 0.01),
                         options=Continuation(ds=0.004, ds_max=0.005, max_points=20,
                                              forward=False))
    ns = br.events.filter(br.events["type"] == "neimark_sacker")
    assert ns.height == 1, br.events
    assert ns["zeta"][0] == pytest.approx(zeta, abs=1e-6)


def test_bad_ns_curve_input_names_the_parameter():
    br = whirl_branch()
    i = ns_event()
    with pytest.raises(ParameterError) as e:
        periodic_curve(br, i, "nope", range=(0.4, 0.6))
    assert e.value.parameter == "parameter2"
    with pytest.raises(ParameterError) as e:
        periodic_curve(br, i, "zeta", range=(0.4, 0.6))
    assert e.value.parameter == "parameter2"
    with pytest.raises(ParameterError) as e:
        periodic_curve(br, i, "rho", range=(0.6, 0.7))
    assert e.value.parameter == "range"
    with pytest.raises(ParameterError) as e:
        periodic_curve(br, i, "rho", range=(0.4, 0.6), range1=(0.2, 0.3))
    assert e.value.parameter == "range1"
