"""The single-ball balancer (n = 1): its named equilibria against the static equations
written here, the residual imbalance against its closed form and Tien's (2011) section
4-3, rotating (R) and oscillating (O) motions against a scipy shooting method on
variational equations derived here with sympy and against long simulations, and the
Tien's (2011) single-ball comparison (figures 4-7 and 4-8) on the model."""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import cache
from typing import Any

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import ballbal
from ballbal import continuation as cont
from ballbal import data

MU, ZETA, ZETA_B, DELTA = 0.2, 0.05, 0.05, 50.0


def _one(Omega: float, eta: float, zeta_b: float = ZETA_B) -> ballbal.Balancer:  # noqa: N803
    return ballbal.Balancer(mu=MU, zeta=ZETA, zeta_b=zeta_b, delta=DELTA, Omega=Omega,
                            eta=(eta,))


Fn = Callable[[np.ndarray], Any]


@cache
def _system(zeta_b: float, Omega: float, eta: float) -> tuple[Fn, Fn]:  # noqa: N803
    """First-order right-hand side and its Jacobian (the variational equations' matrix)
    of one ball, from the spec's equations of motion, by sympy."""
    x, y, b, dx, dy, db = sp.symbols("x y b dx dy db", real=True)
    m = MU * eta
    s, c = sp.sin(b), sp.cos(b)
    mass = sp.Matrix([[1, 0, -m * s], [0, 1, m * c], [-s, c, DELTA]])
    g = sp.Matrix([
        2 * ZETA * dx - 2 * Omega * dy + (1 - Omega**2) * x - 2 * ZETA * Omega * y
        - m * (Omega + db) ** 2 * c - MU * Omega**2,
        2 * ZETA * dy + 2 * Omega * dx + (1 - Omega**2) * y + 2 * ZETA * Omega * x
        - m * (Omega + db) ** 2 * s,
        2 * Omega * (c * dx + s * dy) + 2 * zeta_b * DELTA * db
        + Omega**2 * (x * s - y * c),
    ])
    state = [x, y, b, dx, dy, db]
    f = sp.Matrix([dx, dy, db, *mass.LUsolve(-g)])
    jac = f.jacobian(state)
    return (sp.lambdify([state], f, "numpy", cse=True),
            sp.lambdify([state], jac, "numpy", cse=True))


def _flow(sys_: tuple[Fn, Fn], y0: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """State and monodromy (fundamental matrix) after time T."""
    f, jac = sys_

    def rhs(_t: float, z: np.ndarray) -> np.ndarray:
        phi = z[6:].reshape(6, 6)
        return np.concatenate([np.asarray(f(z[:6]), float).ravel(),
                               (np.asarray(jac(z[:6]), float) @ phi).ravel()])

    r = solve_ivp(rhs, (0.0, T), np.concatenate([y0, np.eye(6).ravel()]), method="DOP853",
                  rtol=1e-11, atol=1e-12)
    return r.y[:6, -1], r.y[6:, -1].reshape(6, 6)


def _shoot(sys_: tuple[Fn, Fn], y0: np.ndarray, T: float, winding: int,  # noqa: N803
           phase: int) -> tuple[float, np.ndarray]:
    """Newton on (state, period) with the monodromy from the variational equations:
    the period and the multipliers (largest modulus first)."""
    y = y0.copy()
    shift = np.zeros(6)
    shift[2] = 2 * np.pi * winding
    free = [i for i in range(6) if i != phase]
    for _ in range(12):
        yT, phi = _flow(sys_, y, T)
        res = yT - y - shift
        if np.abs(res).max() < 1e-10:
            break
        a = np.column_stack([(phi - np.eye(6))[:, free],
                             np.asarray(sys_[0](yT), float).ravel()])
        dz = np.linalg.solve(a, -res)
        y[free] += dz[:-1]
        T += dz[-1]
    else:
        raise AssertionError(f"shooting did not converge: {np.abs(res).max()}")
    ev = np.linalg.eigvals(phi)
    return T, ev[np.argsort(-np.abs(ev))]


# ------------------------------------------------------------------ equilibria


@pytest.mark.parametrize(("Omega", "eta"), [(0.8, 0.54), (1.2, 0.99), (1.5, 0.54),
                                            (1.5, 1.85), (1.05, 0.99), (1.5, 1.0)])
def test_equilibria_solve_the_static_equations_and_are_named_by_side(
        Omega: float, eta: float) -> None:  # noqa: N803
    eqs = ballbal.equilibria(_one(Omega, eta))
    f, jac = _system(ZETA_B, Omega, eta)
    a = (1 - Omega**2) / (2 * ZETA)
    assert len(eqs) == 2
    for e in eqs:
        x, y, b = e.q
        y0 = np.array([x, y, b, 0.0, 0.0, 0.0])
        assert np.abs(np.asarray(f(y0), float)).max() < 1e-12
        # the disk centre on the ball's line at r = -mu Omega sin b / (2 zeta)
        r = -MU * Omega * math.sin(b) / (2 * ZETA)
        assert x == pytest.approx(r * math.cos(b), abs=1e-12)
        assert y == pytest.approx(r * math.sin(b), abs=1e-12)
        assert a * math.sin(b) + Omega * math.cos(b) == pytest.approx(-eta * Omega, abs=1e-12)
        # stability from the eigenvalues of the Jacobian derived here
        lead = np.linalg.eigvals(np.asarray(jac(y0), float)).real.max()
        assert (lead < 0) == (e.stability == "stable")
        assert e.stability_index == pytest.approx(lead, abs=1e-9)
        if eta == 1.0 and math.cos(b) == -1.0:
            assert e.kind == "perfect_balance" and x == y == 0.0
        else:
            assert e.kind == ("partial_balance" if math.cos(b) < 0 else "imbalance_side")
    kinds = {e.kind for e in eqs}
    if eta == 1.0:
        assert "perfect_balance" in kinds
    if abs(Omega - 1) > 0.2:
        # away from the resonance one state on each side of the track
        assert len(kinds) == 2


def test_a_heavy_ball_near_the_resonance_has_no_equilibrium() -> None:
    """eta Omega > sqrt(A^2 + Omega^2): no rest; the ball rotates from every start."""
    b = _one(1.0, 1.85)
    assert ballbal.equilibria(b) == []
    sol = ballbal.periodic(b, "R", N=8)
    assert sol.converged and sol.stability == "stable"


def test_partial_balance_branch_starts_by_name() -> None:
    br = cont.equilibrium_branch(_one(1.5, 0.99), "Omega", start="partial_balance",
                                 range=(1.3, 1.7))
    assert br.table.height > 3
    assert set(br.table["kind"].to_list()) == {"partial_balance"}
    # along an Omega branch the capacity is fixed: the residual follows the ball angle
    for s in br.solutions:
        assert s.residual_imbalance == pytest.approx(abs(1 + 0.99 * np.exp(1j * s.q[2])),
                                                     rel=1e-12)


# ------------------------------------------------------------ residual imbalance


def test_residual_imbalance_closed_form_and_the_disk_whirl() -> None:
    for Omega, eta in [(1.5, 0.54), (1.2, 1.85), (0.8, 0.99)]:  # noqa: N806
        for e in ballbal.equilibria(_one(Omega, eta)):
            ri = abs(1 + eta * np.exp(1j * e.q[2]))
            assert e.residual_imbalance == pytest.approx(ri, rel=1e-12)
            # the whirl is the support's response to the imbalance left
            z = MU * Omega**2 * ri / abs(1 - Omega**2 + 2j * ZETA * Omega)
            assert math.hypot(e.q[0], e.q[1]) == pytest.approx(z, rel=1e-10)
            assert data.residual_imbalance(33.12, e) == pytest.approx(33.12 * ri, rel=1e-12)
    # two balls at the perfect balance leave none
    pb = ballbal.equilibria(ballbal.Balancer(eta=(0.8, 0.8), Omega=1.5))[0]
    assert pb.kind == "perfect_balance" and pb.residual_imbalance < 1e-14


def test_residual_imbalance_of_the_single_ball_experiment() -> None:
    sb = data.single_ball()
    stated = dict(zip(sb["eta_stated"], sb["residual_imbalance"], strict=True))
    # Tien's (2011) numbers: (1 - eta) and (eta - 1) times 33.12 g mm, eta as printed
    assert data.residual_imbalance(33.12, 0.54) == pytest.approx(stated[0.54], abs=0.005)
    assert data.residual_imbalance(33.12, 1.85) == pytest.approx(stated[1.85], abs=0.005)
    assert data.residual_imbalance(33.12, [0.5, 0.5], [2.0, -2.0]) == pytest.approx(
        33.12 * abs(1 + np.exp(2j) / 2 + np.exp(-2j) / 2))
    # on the model (Tien's (2011) parameters, eta from the masses and radii) the stable
    # equilibrium's residual falls towards m_d e |1 - eta| as the speed rises; at
    # 1000 rpm it is within 1 % of the stated values
    for row in sb.iter_rows(named=True):
        prev = math.inf
        for rpm in (625.0, 800.0, 1000.0):
            b = ballbal.Balancer(**data.MODEL_PARAMETERS, Omega=data.rpm_to_ratio(rpm),
                                 eta=(row["eta"],))
            (e,) = [e for e in ballbal.equilibria(b) if e.stability == "stable"]
            assert e.kind == "partial_balance"
            g = data.residual_imbalance(33.12, e)
            assert 33.12 * abs(1 - row["eta"]) < g < prev
            prev = g
        if row["residual_imbalance"] is not None:
            assert prev == pytest.approx(row["residual_imbalance"], rel=0.01)


# --------------------------------------------------------------- R and O motions


@pytest.mark.parametrize(("Omega", "eta", "zeta_b"), [
    (1.2, 0.99, 0.05),
    # stable but reached from no start at rest in the ground frame: whirl starts
    (1.6, 1.85, 0.05),
    (1.35, 0.99, 0.05),
])
def test_rotating_motion_against_shooting_and_simulation(Omega: float, eta: float,  # noqa: N803
                                                         zeta_b: float) -> None:
    b = _one(Omega, eta, zeta_b)
    sol = ballbal.periodic(b, "R", N=10)
    assert sol.converged and sol.stability == "stable", sol.status
    assert sol.type == "R"
    T, mult = _shoot(_system(zeta_b, Omega, eta), sol.state(0.0), sol.period, -1, 2)
    assert sol.period == pytest.approx(T, rel=1e-8)
    assert abs(mult[0] - 1) < 1e-6
    assert sol.max_modulus == pytest.approx(abs(mult[1]), abs=1e-6)
    # a long simulation from a disturbed state settles back onto it: over k periods the
    # ball loses k turns on the disk
    y0 = sol.state(0.0) + np.array([0.05, -0.05, 0.5, 0.0, 0.0, 0.02])
    k = 20
    t1 = 1500.0
    df = ballbal.simulate(b, y0, [0.0, t1, t1 + k * sol.period], rtol=1e-10, atol=1e-12)
    bb = df["b1"].to_numpy()
    rate = (bb[2] - bb[1]) / (k * sol.period)
    assert rate == pytest.approx(-sol.omega, rel=1e-6)


def test_oscillating_motion_against_shooting_and_simulation() -> None:
    b = _one(1.2, 1.85)
    sol = ballbal.periodic(b, "O", N=10)
    assert sol.converged and sol.stability == "stable", sol.status
    T, mult = _shoot(_system(ZETA_B, 1.2, 1.85), sol.state(0.0), sol.period, 0, 3)
    assert sol.period == pytest.approx(T, rel=1e-8)
    assert sol.max_modulus == pytest.approx(abs(mult[1]), abs=1e-6)
    # disturbed, it comes back: no net turns, and x returns after a whole number of periods
    y0 = sol.state(0.0) + np.array([0.01, 0.0, 0.05, 0.0, 0.0, 0.0])
    t1 = 1500.0
    k = 10
    df = ballbal.simulate(b, y0, [0.0, t1, t1 + k * sol.period], rtol=1e-10, atol=1e-12)
    bb = df["b1"].to_numpy()
    assert abs(bb[2] - bb[1]) < 1e-5
    assert abs(df["x"][2] - df["x"][1]) < 1e-5


def test_no_rotating_or_oscillating_motion_where_none_exists() -> None:
    """eta 0.99 at Omega 1.5: every start comes to rest, and periodic() says no_guess
    rather than return something else."""
    b = _one(1.5, 0.99)
    for pattern in ("R", "O"):
        assert ballbal.periodic(b, pattern, N=8).status == "no_guess"
    rng = np.random.default_rng(7)
    for _ in range(6):
        y0 = np.zeros(6)
        y0[:2] = rng.uniform(-2, 2, 2)
        y0[2] = rng.uniform(-np.pi, np.pi)
        y0[3:5] = rng.uniform(-2, 2, 2)
        y0[5] = rng.uniform(-1.5, 0.5)
        df = ballbal.simulate(b, y0, [0.0, 2000.0, 2100.0])
        assert abs(df["db1"][2]) < 1e-6 and abs(df["b1"][2] - df["b1"][1]) < 1e-4


# --------------------------------------------------- Tien's (2011) comparison (4-3)

SPEEDS = [550.0, 625.0, 700.0, 775.0, 850.0, 925.0, 1000.0]


def _rig(rpm: float, eta: float, **change: float) -> ballbal.Balancer:
    return ballbal.Balancer(**{**data.MODEL_PARAMETERS, **change},
                            Omega=data.rpm_to_ratio(rpm), eta=(eta,))


def _no_balls(Omega: float) -> float:  # noqa: N803
    """Mean |Z''| of the disk without balls: Omega^2 mu Omega^2 / |1 - Omega^2 + 2 i zeta
    Omega|."""
    z = data.MODEL_PARAMETERS["zeta"]
    return Omega**4 * data.MODEL_PARAMETERS["mu"] / abs(1 - Omega**2 + 2j * z * Omega)


def test_balanced_vibration_orders_as_figure_4_7() -> None:
    """At the stable equilibrium: eta 1.85 > 0.54 > 0.99, all below no balls, at every
    speed where all three are stable (from 625 rpm)."""
    etas = data.single_ball().sort("rank_balanced")["eta"].to_list()  # 1.85, 0.54, 0.99
    compared = 0
    for rpm in SPEEDS:
        om = data.rpm_to_ratio(rpm)
        v = []
        for eta in etas:
            stable = [e for e in ballbal.equilibria(_rig(rpm, eta)) if e.stability == "stable"]
            if not stable:
                break
            amp = ballbal.vibration(stable[0], Omega=om).mean
            # Omega^2 |Z| with |Z| the support's response to the residual imbalance
            z = data.MODEL_PARAMETERS["zeta"]
            assert amp == pytest.approx(
                om**4 * 0.2 * stable[0].residual_imbalance / abs(1 - om**2 + 2j * z * om),
                rel=1e-10)
            v.append(amp)
        else:
            assert _no_balls(om) > v[0] > v[1] > v[2], (rpm, v)
            compared += 1
    assert compared >= len(SPEEDS) - 1


def _rotating(rpm: float, eta: float, **change: float) -> float | None:
    sol = ballbal.periodic(_rig(rpm, eta, **change), "R", N=8)
    return sol.vibration().mean if sol.converged and sol.stability == "stable" else None


def test_rotating_vibration_figure_4_8() -> None:
    """In the rotating motion. At Tien's (2011) model parameters (zeta_b 0.05) only the
    two heavier balls rotate: 1.85 > 0.99 where both do, both above no balls; the
    0.54 ball has no rotating motion at all there. With the lighter track damping of a
    dry track (zeta_b 0.01; the single-ball experiment used no oil) all three rotate and
    the whole order of figure 4-8 holds, 1.85 > 0.99 > 0.54 > no balls."""
    etas = data.single_ball().sort("rank_rotating")["eta"].to_list()  # 1.85, 0.99, 0.54
    both = 0
    for rpm in (625.0, 700.0):
        v = [_rotating(rpm, eta) for eta in etas]
        assert v[0] is not None and v[1] is not None and v[2] is None
        assert v[0] > v[1] > _no_balls(data.rpm_to_ratio(rpm))
        both += 1
    assert _rotating(1000.0, etas[0]) is None  # the heavy ball settles by 1000 rpm
    full = 0
    for rpm in SPEEDS[1:]:
        v = [_rotating(rpm, eta, zeta_b=0.01) for eta in etas]
        assert all(a is not None for a in v), (rpm, v)
        assert v[0] > v[1] > v[2] > _no_balls(data.rpm_to_ratio(rpm)), (rpm, v)  # type: ignore[operator]
        full += 1
    assert both == 2 and full == len(SPEEDS) - 1
