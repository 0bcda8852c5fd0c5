"""One convention for ball-indexed names everywhere: balls are named from 1, in parameter
names (``"eta1"``, ``"zeta_b2"``) as in the coordinates ``b1``, ``b2``, the rates and the
windings, so that ``eta1`` is the ball whose angle is ``b1`` (``Balancer.eta[0]`` in
Python's own indexing). The bracketed form ``eta[0]`` is refused with the name it meant.
Once, the core continued the first ball while the rows' models were built as if it were
the second: a row at eta (1.5, 1.1) carried the model (0.9, 1.5)."""

from __future__ import annotations

import numpy as np
import pytest

import ballbal
from ballbal import continuation as cont
from ballbal.exceptions import ParameterError


def _imbalance(eta: tuple[float, ...], balls: np.ndarray) -> float:
    """|1 + sum eta_i e^(i b_i)|: zero at a perfect balance (written here, not read)."""
    return float(abs(1 + np.sum(np.asarray(eta) * np.exp(1j * balls))))


@pytest.fixture(scope="module")
def branch() -> cont.Branch:
    sol = ballbal.periodic(ballbal.Balancer(eta=(0.9, 1.1)), "R-R", N=6)
    assert sol.converged
    return cont.periodic_branch(sol, "eta1", range=(0.5, 1.5),
                                options=cont.Continuation(max_points=25))


def test_periodic_rows_carry_the_model_they_were_computed_for(branch: cont.Branch) -> None:
    assert len(branch.solutions) >= 5
    values = branch.table[branch.parameter].to_list()
    for p, s in zip(values, branch.solutions, strict=True):
        assert s.balancer.eta[0] == pytest.approx(p, abs=1e-14)
        assert s.balancer.eta[1] == 1.1
        # The row is an orbit of the model it carries: a simulated period closes.
        assert s.verify() < 1e-4


def test_equilibrium_rows_carry_the_model_they_were_computed_for() -> None:
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    br = cont.equilibrium_branch(b, "eta1", start="perfect_balance", range=(0.6, 1.4),
                                 options=cont.Continuation(max_points=20))
    assert len(br.solutions) >= 5
    values = br.table[br.parameter].to_list()
    moved = 0
    for p, e in zip(values, br.solutions, strict=True):
        eta = (p, 1.1)  # the row's model: the first ball's eta is the parameter
        moved += abs(p - 0.9) > 1e-3
        # A perfect balance of that model (the imbalance written in this test), and the
        # imbalance the row reports is that model's.
        assert _imbalance(eta, np.asarray(e.q[2:])) < 1e-8
        assert e.residual_imbalance == pytest.approx(_imbalance(eta, np.asarray(e.q[2:])),
                                                     abs=1e-9)
    assert moved >= 3


def test_a_ball_index_past_the_last_ball_names_the_parameter() -> None:
    sol = ballbal.periodic(ballbal.Balancer(eta=(0.9, 1.1)), "R-R", N=3)
    with pytest.raises(ParameterError) as e:
        cont.periodic_branch(sol, "eta3", range=(0.5, 1.5),
                             options=cont.Continuation(max_points=5))
    assert "eta3" in f"{e.value.parameter} {e.value}"


@pytest.mark.parametrize("call", [
    lambda b: ballbal.scan(b, grid={"eta[0]": [0.9]}, threads=1),
    lambda b: cont.equilibrium_branch(b, "eta[0]", start="perfect_balance", range=(0.6, 1.4)),
    lambda b: ballbal.balance_map(b, **{"eta[0]": [0.9]}),
])
def test_the_bracketed_form_is_refused_with_the_name_it_meant(call: object) -> None:
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    with pytest.raises(ParameterError) as e:
        call(b)  # type: ignore[operator]
    assert e.value.parameter == "eta[0]"
    assert "eta1 is the ball at index 0" in str(e.value)


def test_one_ball_is_an_axis_by_keyword_in_scan_and_balance_map() -> None:
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    table = ballbal.scan(b, eta2=[0.8, 1.2], threads=1, patterns=["R-R"])
    assert sorted(set(table["eta2"].to_list())) == [0.8, 1.2]
    assert set(table["eta1"].to_list()) == {0.9}
    balance = ballbal.balance_map(b, eta2=[0.8, 1.2])
    assert sorted(set(balance["eta2"].to_list())) == [0.8, 1.2]


def test_names_count_balls_as_the_coordinates_do() -> None:
    """``eta1`` varies the ball whose angle is ``b1``: along an equilibrium branch in
    ``eta1`` at a perfect balance, 1 + eta1 e^(i b1) + eta2 e^(i b2) = 0 with eta2 fixed."""
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    br = cont.equilibrium_branch(b, "eta1", start="perfect_balance", range=(0.6, 1.4),
                                 options=cont.Continuation(max_points=10))
    assert len(br.solutions) >= 5
    for p, e in zip(br.table["eta1"], br.solutions, strict=True):
        b1, b2 = e.q[2], e.q[3]  # x, y, then the balls' angles b1, b2
        assert abs(1 + p * np.exp(1j * b1) + 1.1 * np.exp(1j * b2)) < 1e-8
