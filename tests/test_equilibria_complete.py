"""Every equilibrium listed. Without disk damping (zeta = 0) the search found only the
perfect balance (zeta = 1e-9 gave four); with unequal balls it missed most states with
the balls on the disk's line at any damping. Checked against the equations of motion
written in the tests (``reference.rhs``: at rest every acceleration vanishes), against
an independent search (scipy's root from random starts), and, for the branch, against
the closed form of the together state derived here: with the balls at ``b`` on the
disk's line, ``(1 - Omega^2) x = mu Omega^2 (1 + 2 eta cos b)`` and ``sin b = 0``."""

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


def _independent_search(b: ballbal.Balancer, starts: int, seed: int) -> list[np.ndarray]:
    """Equilibria found by scipy's root on the test's own equations from random starts
    over the disk offset and every ball angle, kept where the residual is at round-off,
    one per state (angles modulo 2 pi)."""
    from scipy.optimize import root

    n = len(b.eta)
    rng = np.random.default_rng(seed)
    found: list[np.ndarray] = []

    def residual(q: np.ndarray) -> np.ndarray:
        return rhs(b, 0.0, np.concatenate([q, np.zeros(n + 2)]))[n + 2:]

    for _ in range(starts):
        q0 = np.concatenate([rng.uniform(-3, 3, 2), rng.uniform(-np.pi, np.pi, n)])
        r = root(residual, q0, method="hybr")
        if np.max(np.abs(residual(r.x))) > 1e-11:
            continue
        q = r.x.copy()
        q[2:] = np.angle(np.exp(1j * q[2:]))
        if not any(_same(q, f) for f in found):
            found.append(q)
    return found


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.max(np.abs(a[:2] - b[:2])) < 1e-6
                and np.max(np.abs(np.angle(np.exp(1j * (a[2:] - b[2:]))))) < 1e-6)


@pytest.mark.parametrize(("eta", "zeta", "Omega"), [
    ((0.8, 1.0), 0.05, 1.2), ((0.8, 1.0), 0.05, 0.8), ((0.8, 1.0), 0.0, 2.0),
    ((0.6, 1.3), 0.1, 1.5)])
def test_unequal_balls_every_equilibrium_is_listed(eta, zeta, Omega) -> None:
    """Two unequal balls: the search listed none of the four states with the balls on the
    disk's line at Omega 1.2, zeta 0.05. An independent search (scipy's root on the
    test's equations from 400 random starts) finds the reference set; ballbal must list
    exactly those states."""
    b = ballbal.Balancer(zeta=zeta, Omega=Omega, eta=eta)
    ref = _independent_search(b, 400, seed=7)
    got = [np.asarray(e.q, dtype=float) for e in ballbal.equilibria(b)]
    for q in got:
        q[2:] = np.angle(np.exp(1j * q[2:]))
        assert _at_rest(b, q) < 1e-12
    missing = [r for r in ref if not any(_same(r, g) for g in got)]
    extra = [g for g in got if not any(_same(r, g) for r in ref)]
    assert not missing, missing
    assert not extra, extra
