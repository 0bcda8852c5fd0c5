"""Bounded work: many balls, cheap validation, stiff or hopeless parameters fail fast."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import ballbal
from ballbal import Balancer, balanced_state, equilibria, load_scene, periodic, simulate
from ballbal.exceptions import IntegrationError, ParameterError, StiffError


def _unbalance(q: np.ndarray, eta: float) -> complex:
    return complex(sum(eta * np.cos(q[2:])), sum(eta * np.sin(q[2:])))


@pytest.mark.parametrize("n", [3, 4, 32])
def test_equal_balls_find_the_perfect_balance_and_the_together_states(n: int) -> None:
    """4^32 starts overflowed to none: equilibria() was [] from 32 balls on; the lattice
    of 3 and 4 balls missed the together states."""
    eta, Om, zeta, mu = 2 / n, 1.2, 0.05, 0.2
    b = Balancer(mu=mu, zeta=zeta, Omega=Om, eta=(eta,) * n)
    eqs = equilibria(b)
    assert eqs and all(e.exhaustive == (n <= 4) for e in eqs)
    pb = [e for e in eqs if e.kind == "perfect_balance"]
    assert len(pb) == 1 and pb[0].neutral == n - 2
    # The family's closed form: disk centre at rest on the axis, sum eta e^(i b) = -1.
    q = pb[0].q
    assert abs(q[0]) < 1e-10 and abs(q[1]) < 1e-10
    assert abs(_unbalance(q, eta) + 1) < 1e-10
    bs = balanced_state(b)
    assert bs is not None and bs.kind == "perfect_balance"
    assert abs(bs.q[0]) < 1e-10 and abs(_unbalance(bs.q, eta) + 1) < 1e-10

    # All balls together at b act on the disk as one ball of mass n eta and each obeys
    # one ball's equation, so the two-ball closed form holds with 2 eta -> n eta:
    # A sin b + Omega cos b = -n eta Omega, A = (1 - Omega^2) / (2 zeta), disk centre
    # on the balls' ray at r = -mu Omega sin b / (2 zeta).
    A = (1 - Om**2) / (2 * zeta)
    amp, phi = math.hypot(A, Om), math.atan2(Om, A)
    s = math.asin(-n * eta * Om / amp)
    expected = []
    for bb in (s - phi, math.pi - s - phi):
        r = -mu * Om * math.sin(bb) / (2 * zeta)
        expected.append((r * math.cos(bb), r * math.sin(bb), bb))
    together = [e for e in eqs if e.kind == "together"]
    assert len(together) == 2
    for x, y, bb in expected:
        assert any(
            abs(e.q[0] - x) < 1e-9 and abs(e.q[1] - y) < 1e-9
            and all(abs(math.remainder(v - bb, 2 * math.pi)) < 1e-9 for v in e.q[2:])
            for e in together
        ), (x, y, bb)


@pytest.mark.parametrize("n", [16, 18, 20, 22, 24])
def test_many_balls_finish_in_bounded_time(n: int) -> None:
    """They took 17 s (16 balls), 42 s (20), 59 s (22) and over a minute (24)."""
    t = time.perf_counter()
    eqs = equilibria(Balancer(eta=(2 / n,) * n))
    took = time.perf_counter() - t
    print(f"equilibria, {n} balls: {took:.2f} s, {len(eqs)} found")
    assert took < 30
    assert sum(e.kind == "perfect_balance" for e in eqs) == 1


def test_small_ball_counts_stay_exhaustive() -> None:
    for n in (2, 3, 4):
        assert all(e.exhaustive for e in equilibria(Balancer(eta=(0.7,) * n)))


def test_validate_checks_parameters_without_analysing(tmp_path) -> None:
    with pytest.raises(ParameterError) as e:
        Balancer(eta=(0.5, -0.5)).validate()
    assert e.value.parameter == "eta2"
    with pytest.raises(ParameterError) as e:
        Balancer(mu=1.5).validate()
    assert e.value.parameter == "mu"
    # 22 balls: validation used to run the whole equilibrium search (about a minute).
    t = time.perf_counter()
    Balancer(eta=(0.1,) * 22).validate()
    f = tmp_path / "balls22.toml"
    f.write_text("[balancer]\neta = [" + ", ".join(["0.1"] * 22) + "]\n\n[springs]\n"
                 "stiffness = 0.5\n")
    sc = load_scene(f)
    assert sc.n_balls == 22
    assert time.perf_counter() - t < 1.0


def test_stiff_parameters_raise_stiff_error_quickly() -> None:
    stiff = Balancer(zeta=1e6, zeta_b=1e6)
    t = time.perf_counter()
    with pytest.raises(StiffError):
        simulate(stiff, t_span=(0, 100))
    assert time.perf_counter() - t < 5
    # periodic() refuses such damping before its simulated start search (issue 30)
    with pytest.raises(ParameterError) as e:
        periodic(stiff, "R-R")
    assert e.value.parameter == "zeta"


def test_hopeless_step_budget_fails_quickly() -> None:
    """Omega = 1e6 is not stiff — the balls really turn a million radians per time unit,
    and accuracy, not stability, holds the step at ~1e-7 — but a run of 100 time units
    needs ~1e9 steps: an IntegrationError within seconds instead of after the whole
    budget (20 s); periodic() refuses it before its guess simulations (they took 325 s)."""
    t = time.perf_counter()
    with pytest.raises(IntegrationError):
        simulate(Balancer(Omega=1e6), t_span=(0, 100))
    with pytest.raises(IntegrationError):
        simulate(Balancer(), t_eval=[0.0, 1e300])
    assert time.perf_counter() - t < 5
    # periodic() refuses such a speed before its simulated start search (issue 30)
    with pytest.raises(ParameterError) as e:
        periodic(Balancer(Omega=1e6), "R-R")
    assert e.value.parameter == "Omega"


def test_normal_cases_are_not_called_stiff() -> None:
    """Hairer's test must not fire on ordinary runs: a long simulation of the Tien (2011) case
    and a highly damped but not stiff one integrate to the end."""
    df = simulate(Balancer(), t_span=(0, 2000))
    assert df.height == 1001 and np.isfinite(df["x"].to_numpy()).all()
    df = simulate(Balancer(zeta=5.0, zeta_b=5.0, delta=200), t_span=(0, 200))
    assert np.isfinite(df["x"].to_numpy()).all()
    assert ballbal.periodic(Balancer(), "R-R").status == "converged"
