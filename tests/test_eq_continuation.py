"""Equilibrium continuation against values computed independently here: the closed-form
saddle-node curve (scripts/derive_saddle_node.py), the pitchfork at eta = 1/2, the
perfect balance's Hopf curve from a Routh–Hurwitz (Hurwitz determinant) computation on
its characteristic polynomial built in this file, and the Hopf frequency from numpy's
eigenvalues."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.optimize import brentq

import ballbal
from ballbal._branch import Branch, Continuation
from ballbal.continuation import (
    equilibrium_branch,
    equilibrium_curve,
    from_disk_units,
    switch_equilibrium,
)
from ballbal.exceptions import ParameterError

OPTS = Continuation(ds=0.01, ds_max=0.05, max_points=400, tol=1e-12)


def eta_fold(om: np.ndarray, zeta: float) -> np.ndarray:
    return np.sqrt(0.25 + (1 - om**2) ** 2 / (16 * zeta**2 * om**2))


def together_branch(om: float = 1.05, zeta: float = 0.05) -> Branch:
    b = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=0.1, delta=50, Omega=om, eta=(0.3, 0.3))
    return equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS)


def test_pitchfork_and_fold_of_the_together_branch() -> None:
    br = together_branch()
    ev = br.events
    bp = ev.filter(ev["type"] == "branch_point")
    fold = ev.filter(ev["type"] == "fold")
    assert bp.height >= 1 and fold.height >= 1
    assert abs(bp["eta"][0] - 0.5) < 1e-9
    assert abs(fold["eta"][0] - eta_fold(np.array(1.05), 0.05)) < 1e-9
    # every row's event column agrees with the events table
    assert br.table["event"].drop_nulls().len() == len(set(ev["row"].to_list()))


def test_switch_to_the_perfect_balance() -> None:
    br = together_branch()
    i = br.events["type"].to_list().index("branch_point")
    pb = switch_equilibrium(br, i)
    rows = pb.table.filter(pb.table["kind"] == "perfect_balance")
    assert rows.height > 10
    eta = rows["eta"].to_numpy()
    b1 = np.array([abs(q[2]) for q in rows["q"].to_list()])
    np.testing.assert_allclose(b1, np.arccos(-1 / (2 * eta)), atol=1e-8)
    with pytest.raises(ParameterError) as e:
        switch_equilibrium(br, br.events["type"].to_list().index("fold"))
    assert e.value.parameter == "event"


def test_saddle_node_curve_against_the_closed_form() -> None:
    br = together_branch()
    i = br.events["type"].to_list().index("fold")
    c = equilibrium_curve(br, i, "Omega", range=(0.6, 1.6), options=OPTS)
    om = c.table["Omega"].to_numpy()
    err = np.abs(c.table["eta"].to_numpy() - eta_fold(om, 0.05)).max()
    assert c.table.height > 30 and om.min() < 0.9 and om.max() > 1.3
    assert err < 1e-9, err
    # where it meets the pitchfork: one point, not a Bogdanov–Takens one (the second zero
    # eigenvalue is the antisymmetric ball mode's, outside the together subspace)
    p = c.points
    at = p.filter((abs(p["Omega"] - 1.0) < 1e-6) & (abs(p["eta"] - 0.5) < 1e-6))
    assert at["type"].to_list() == ["pitchfork"], p


def _pb_matrices(om: float, eta: float, mu: float, zeta: float, zeta_b: float,
                 delta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """M, C, K of the two-ball perfect balance linearised from model.md's equations."""
    b = np.arccos(-1 / (2 * eta))
    s = np.array([np.sin(b), np.sin(-b)])
    c = np.array([np.cos(b), np.cos(-b)])
    m = mu * eta
    M = np.eye(4)
    M[0, 2:] = M[2:, 0] = -m * s
    M[1, 2:] = M[2:, 1] = m * c
    M[2, 2] = M[3, 3] = m * delta
    C = np.zeros((4, 4))
    C[0, :2] = [2 * zeta, -2 * om]
    C[1, :2] = [2 * om, 2 * zeta]
    C[0, 2:] = -2 * om * m * c
    C[1, 2:] = -2 * om * m * s
    for i in range(2):
        C[2 + i, :2] = [2 * om * m * c[i], 2 * om * m * s[i]]
        C[2 + i, 2 + i] = 2 * zeta_b * delta * m
    K = np.zeros((4, 4))
    K[0, :2] = [1 - om**2, -2 * zeta * om]
    K[1, :2] = [2 * zeta * om, 1 - om**2]
    K[0, 2:] = m * om**2 * s
    K[1, 2:] = -m * om**2 * c
    for i in range(2):
        K[2 + i, :2] = [m * om**2 * s[i], -m * om**2 * c[i]]
    return M, C, K


def _char_poly(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """det(s^2 M + s C + K), monic, highest power first, by interpolation at the 9th
    roots of unity (exact for a degree-8 polynomial)."""
    z = np.exp(2j * np.pi * np.arange(9) / 9)
    vals = np.array([np.linalg.det(s * s * M + s * C + K) for s in z])
    coef = np.real(np.fft.fft(vals) / 9)  # ascending
    return coef[::-1] / coef[-1]


def _hurwitz_last(a: np.ndarray) -> float:
    """Delta_{n-1}, the Hurwitz determinant that vanishes on the Hopf boundary."""
    n = len(a) - 1
    H = np.zeros((n - 1, n - 1))
    for i in range(n - 1):
        for j in range(n - 1):
            k = 2 * j - i + 1
            if 0 <= k <= n:
                H[i, j] = a[k]
    return float(np.linalg.det(H))


def test_hopf_curve_of_the_perfect_balance_against_routh_hurwitz() -> None:
    mu, zeta, zeta_b, delta = 0.2, 0.1, 0.1, 50.0
    b = ballbal.Balancer(mu=mu, zeta=zeta, zeta_b=zeta_b, delta=delta, Omega=1.1,
                         eta=(1.3, 1.3))
    br = equilibrium_branch(b, "Omega", start="perfect_balance", range=(1.0, 1.5), options=OPTS)
    h = br.events.filter(br.events["type"] == "hopf")
    assert h.height >= 1
    om_h = h["Omega"][0]
    M, C, K = _pb_matrices(om_h, 1.3, mu, zeta, zeta_b, delta)
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ev = np.linalg.eigvals(A)
    crit = ev[np.argmin(np.abs(ev.real))]
    assert abs(crit.real) < 1e-7
    assert abs(abs(crit.imag) - h["omega"][0]) < 1e-7
    i = br.events["type"].to_list().index("hopf")
    c = equilibrium_curve(br, i, "eta", range=(0.55, 1.5), options=OPTS)
    assert c.table.height > 10
    worst = 0.0
    for om, eta in zip(c.table["Omega"].to_list()[::5], c.table["eta"].to_list()[::5], strict=True):
        def g(o: float, eta: float = eta) -> float:
            return _hurwitz_last(_char_poly(*_pb_matrices(o, eta, mu, zeta, zeta_b, delta)))
        root = brentq(g, om - 1e-3, om + 1e-3, xtol=1e-14)
        worst = max(worst, abs(root - om))
    assert worst < 1e-7, worst


def test_bad_input_names_the_parameter() -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.2, eta=(1.0, 1.0))
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(b, "nonsense", range=(0.5, 2.0))
    assert e.value.parameter == "nonsense"
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(b, "Omega", range=(1.5, 2.0))
    assert e.value.parameter == "range"
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(b, "Omega", start="opposite_kind", range=(0.5, 2.0))
    assert e.value.parameter == "start"


def test_from_disk_units_meets_at_the_double_zero_point() -> None:
    # the paper's curves meet at (omega0, m0) = (1/sqrt(1 + 2 m0), e/2)
    b = from_disk_units(m0=1.0, omega0=1 / np.sqrt(3.0), e=2.0)
    assert abs(b.Omega - 1.0) < 1e-15 and abs(b.eta[0] - 0.5) < 1e-15
    d = from_disk_units(1.5, 2.0, 2.0, C0=0.35, D0=0.35)  # the paper's table 2
    assert abs(d.mu - 0.2) < 1e-15 and abs(d.delta - 0.5) < 1e-15


# --- codimension-two points on the saddle-node curve, and branches both ways ----------

def _spec_residual(q: np.ndarray, v: np.ndarray, a: np.ndarray, om: float, eta: float,
                   mu: float, zeta: float, zeta_b: float, delta: float) -> np.ndarray:
    """model.md's equations of motion for two balls."""
    x, y, b = q[0], q[1], q[2:]
    s, c, m = np.sin(b), np.cos(b), mu * eta
    r = np.zeros(4)
    r[0] = (a[0] - np.sum(m * s * a[2:]) + 2 * zeta * v[0] - 2 * om * v[1] + (1 - om**2) * x
            - 2 * zeta * om * y - np.sum(m * (om + v[2:]) ** 2 * c) - mu * om**2)
    r[1] = (a[1] + np.sum(m * c * a[2:]) + 2 * zeta * v[1] + 2 * om * v[0] + (1 - om**2) * y
            + 2 * zeta * om * x - np.sum(m * (om + v[2:]) ** 2 * s))
    r[2:] = m * (delta * a[2:] - s * a[0] + c * a[1] + 2 * om * (c * v[0] + s * v[1])
                 + 2 * zeta_b * delta * v[2:] + om**2 * (x * s - y * c))
    return r


def _together(om: float, b: float, mu: float, zeta: float) -> tuple[float, float, float]:
    """The balls-together equilibrium with both balls at angle b: (x, y, eta), from the
    statics, which are linear in (x, y, mu eta) for given b."""
    A = np.array([[1 - om**2, -2 * zeta * om, -2 * om**2 * np.cos(b)],
                  [2 * zeta * om, 1 - om**2, -2 * om**2 * np.sin(b)],
                  [np.sin(b), -np.cos(b), 0.0]])
    x, y, m = np.linalg.solve(A, [mu * om**2, 0.0, 0.0])
    return x, y, m / mu


def _together_pair_sum(om: float, b_near: float, mu: float, zeta: float, zeta_b: float,
                       delta: float) -> float:
    """On the saddle-node curve at om (the fold of eta along the together states, found
    here by d eta / d b = 0 near b_near): the sum of the together subspace's two
    eigenvalues nearest zero (the fold's zero and the next one; real even where they pair
    up), whose zero is a double zero within the subspace."""
    def deta(b: float, h: float = 1e-6) -> float:
        return (_together(om, b + h, mu, zeta)[2] - _together(om, b - h, mu, zeta)[2]) / (2 * h)
    b = brentq(deta, b_near - 0.3, b_near + 0.3, xtol=1e-14)
    x, y, eta = _together(om, b, mu, zeta)
    q, z = np.array([x, y, b, b]), np.zeros(4)

    def jac(f: Any, u0: np.ndarray, h: float = 1e-6) -> np.ndarray:
        return np.array([(f(u0 + h * e) - f(u0 - h * e)) / (2 * h) for e in np.eye(4)]).T
    args = (om, eta, mu, zeta, zeta_b, delta)
    K = jac(lambda u: _spec_residual(u, z, z, *args), q)
    C = jac(lambda u: _spec_residual(q, u, z, *args), z)
    M = jac(lambda u: _spec_residual(q, z, u, *args), z)
    P = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1]], dtype=float)  # b1 = b2
    R = P.T.copy()  # x, y rows and the balls' sum
    Mr, Cr, Kr = R @ M @ P, R @ C @ P, R @ K @ P
    A = np.block([[np.zeros((3, 3)), np.eye(3)],
                  [-np.linalg.solve(Mr, Kr), -np.linalg.solve(Mr, Cr)]])
    ev = np.linalg.eigvals(A)
    two = ev[np.argsort(np.abs(ev))[:2]]
    return float(np.sum(two).real)


def test_each_codimension_two_point_of_the_saddle_node_curve_is_flagged_once() -> None:
    # README's example: the fold meets the pitchfork at (Omega, eta) = (1, 1/2), and
    # nearby the together states have a true double zero (a Bogdanov–Takens point).
    mu, zeta, zeta_b, delta = 0.2, 0.05, 0.05, 50.0
    b = ballbal.Balancer(mu=mu, zeta=zeta, zeta_b=zeta_b, delta=delta, Omega=0.5,
                         eta=(1.0, 1.0))
    br = equilibrium_branch(b, "Omega", start="together", range=(0.3, 2.5))
    i = br.events["type"].to_list().index("fold")
    c = equilibrium_curve(br, i, "eta", range=(0.3, 2.0))
    p = c.points
    for j in range(p.height):  # no two flags at one point
        d = np.hypot(p["Omega"] - p["Omega"][j], p["eta"] - p["eta"][j]).to_numpy()
        assert np.sum(d < 1e-4) == 1, p
    at = p.filter((abs(p["Omega"] - 1.0) < 1e-6) & (abs(p["eta"] - 0.5) < 1e-6))
    assert at["type"].to_list() == ["pitchfork"], p
    bt = p.filter(p["type"] == "BT")
    assert bt.height == 1, p
    om = float(bt["Omega"][0])
    b_near = float(bt["q"][0][2])
    star = brentq(lambda o: _together_pair_sum(o, b_near, mu, zeta, zeta_b, delta),
                  om - 3e-3, om + 3e-3, xtol=1e-13)
    assert abs(star - om) < 1e-6, (star, om)
    assert abs(bt["eta"][0] - eta_fold(np.array(star), zeta)) < 1e-6


def test_a_branch_both_ways_meets_the_pitchfork_and_the_fold() -> None:
    # From eta 0.6 on the together branch: the pitchfork (eta = 1/2) lies below, the
    # fold above; one way finds only one of them.
    om, zeta = 1.05, 0.05
    b = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=0.1, delta=50, Omega=om, eta=(0.6, 0.6))
    up = equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS)
    both = equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS,
                              direction="both")
    down = equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS,
                              direction="backward")
    assert "branch_point" not in up.events["type"].to_list()
    assert "fold" not in down.events["type"].to_list()
    ev = both.events
    bp = ev.filter(ev["type"] == "branch_point")
    fold = ev.filter(ev["type"] == "fold")
    assert bp.height == 1 and abs(bp["eta"][0] - 0.5) < 1e-9
    assert abs(fold["eta"][0] - eta_fold(np.array(om), zeta)) < 1e-9
    assert both.stop.count("/") == 1
    # one branch: the backward half reversed, then the forward half, the start once
    assert both.table.height == up.table.height + down.table.height - 1
    eta = both.table["eta"].to_numpy()
    k = int(np.argmin(np.abs(eta - 0.6)))
    np.testing.assert_allclose(eta[k::-1], down.table["eta"].to_numpy(), atol=0)
    np.testing.assert_allclose(eta[k:], up.table["eta"].to_numpy(), atol=0)
    # rows and events agree; dp/ds keeps its sign along the rows up to the fold
    for t, r in zip(ev["type"].to_list(), ev["row"].to_list(), strict=True):
        assert t in both.table["event"][r]
    assert (both.table["test_fold"].to_numpy()[: k + 1] > 0).all()
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0),
                           direction="sideways")  # type: ignore[arg-type]
    assert e.value.parameter == "direction"
