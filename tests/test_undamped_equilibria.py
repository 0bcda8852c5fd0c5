"""Equilibria without disk damping (zeta = 0): all of them, not only the perfect balance
(which was all the search found at zeta = 0, while zeta = 1e-9 gave four). Checked
against the equations of motion written in the test (``reference.rhs``: at rest every
acceleration vanishes) and, for the branch, against the closed form of the together
state derived here: with the balls at ``b`` on the disk's line, ``(1 - Omega^2) x =
mu Omega^2 (1 + 2 eta cos b)`` and ``sin b = 0``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import ballbal
from ballbal import continuation as cont

from reference import rhs


def _at_rest(b: ballbal.Balancer, q: np.ndarray) -> float:
    s = np.concatenate([q, np.zeros(len(q))])
    return float(np.max(np.abs(rhs(b, 0.0, s))))


@pytest.mark.parametrize(("Omega", "eta"), [(0.7, (1.0, 1.0)), (1.2, (1.0, 1.0)),
                                            (2.0, (0.8, 0.8)), (1.5, (0.54,)), (0.6, (1.0,))])
def test_undamped_equilibria_are_all_found(Omega: float, eta: tuple[float, ...]) -> None:
    b = ballbal.Balancer(zeta=0.0, Omega=Omega, eta=eta)
    eqs = ballbal.equilibria(b)
    kinds = sorted(e.kind for e in eqs)
    if len(eta) == 2:
        # the perfect balance, the balls together on either side, the balls opposite
        assert kinds == ["opposite", "perfect_balance", "together", "together"]
    else:
        assert len(eqs) == 2
    for e in eqs:
        assert _at_rest(b, np.asarray(e.q)) < 1e-12, e.kind
    # The same states as with a trace of damping (the search's other path there).
    damped = ballbal.equilibria(b.replace(zeta=1e-9))
    assert sorted(e.kind for e in damped) == kinds


def test_together_branch_without_damping_follows_the_closed_form() -> None:
    b = ballbal.Balancer(zeta=0.0, Omega=0.5)
    br = cont.equilibrium_branch(b, "Omega", start="together", range=(0.3, 0.95),
                                 options=cont.Continuation(max_points=200))
    assert br.stop == "boundary"
    om = br.table["Omega"].to_numpy()
    q = np.array(br.table["q"].to_list())
    assert om.min() == pytest.approx(0.3) or om.max() == pytest.approx(0.95)
    assert np.all(np.abs(np.sin(q[:, 2])) < 1e-9) and np.allclose(q[:, 2], q[:, 3])
    x = b.mu * om**2 * (1 + 2 * np.cos(q[:, 2])) / (1 - om**2)
    assert np.max(np.abs(q[:, 0] - x)) < 1e-9


def test_command_line_lists_every_undamped_equilibrium() -> None:
    out = subprocess.run([sys.executable, "-m", "ballbal.cli", "equilibria", "--zeta", "0"],
                         capture_output=True, text=True, check=True).stdout
    rows = [ln.split()[0] for ln in out.splitlines() if ln.startswith("  ")]
    assert sorted(rows) == ["opposite", "perfect_balance", "together", "together"]
