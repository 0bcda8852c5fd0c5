"""One convention for ball-indexed parameter names everywhere: balls count from 0, as
Python indexes ``Balancer.eta`` (``"eta[0]"`` is the first ball's). The core continued
``"eta[0]"`` as the first ball while the rows' models were built as if it were the
second: a row at eta (1.5, 1.1) carried the model (0.9, 1.5)."""

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
    return cont.periodic_branch(sol, "eta[0]", range=(0.5, 1.5),
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
    br = cont.equilibrium_branch(b, "eta[0]", start="perfect_balance", range=(0.6, 1.4),
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
        cont.periodic_branch(sol, "eta[2]", range=(0.5, 1.5),
                             options=cont.Continuation(max_points=5))
    assert "eta[2]" in f"{e.value.parameter} {e.value}"
