"""Equilibrium continuation in units of the disk alone (omega0, m0, e, C0, D0) and
[EccentricRotorABB]'s figure 4: the saddle-node curve SN_2+ against the closed form of its
condition (14) taken as an equality, the pitchfork at m0 = e/2, the perfect balance's Hopf
curve H_1 against a Routh–Hurwitz computation (the characteristic polynomial built in
test_eq_continuation.py from model.md's equations, with the conversion to the model's
units written out here), and the point where they meet, (omega0, m0) =
(1/sqrt(1 + 2 m0), e/2) = (0.5773, 1)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.optimize import brentq
from test_eq_continuation import _char_poly, _hurwitz_last, _pb_matrices

from ballbal import equilibria
from ballbal._branch import Branch, Continuation, Curve
from ballbal.continuation import DiskUnits, equilibrium_branch, equilibrium_curve
from ballbal.exceptions import ParameterError

E, C0, D0 = 2.0, 0.35, 0.35  # the paper's table 2
OPTS = Continuation(ds=0.01, ds_max=0.05, max_points=400, tol=1e-12)


def units(omega0: float, m0: float) -> DiskUnits:
    return DiskUnits(omega0=omega0, m0=m0, e=E, C0=C0, D0=D0)


def m0_on_sn(omega0: float, near: float) -> float:
    """Condition (14) as an equality, (2 w C0)^2 ((2 m0 / e)^2 - 1) = (1 - w^2 (1 + 2 m0))^2,
    is quadratic in m0: its root nearest ``near``."""
    w = omega0
    a = (2 * w * C0) ** 2 * 4 / E**2 - 4 * w**4
    b = 4 * w**2 * (1 - w**2)
    c = -(2 * w * C0) ** 2 - (1 - w**2) ** 2
    r = np.roots([a, b, c])
    r = r[np.abs(r.imag) < 1e-12].real
    return float(r[np.argmin(np.abs(r - near))])


@cache
def together_in_omega0() -> Branch:
    # m0 = 2: the balls-together state 2+ exists from low speed up to omega01 (its fold)
    return equilibrium_branch(units(0.3, 2.0), "omega0", start="together", range=(0.25, 2.2),
                              options=OPTS)


@cache
def sn_curve() -> Curve:
    br = together_in_omega0()
    i = br.events["type"].to_list().index("fold")
    return equilibrium_curve(br, i, "m0", range=(0.5, 5.0), options=OPTS)


def test_tables_are_in_the_disks_units() -> None:
    br = together_in_omega0()
    assert br.parameter == "omega0" and "omega0" in br.table.columns
    k = br.table.height // 3
    s = np.sqrt(1 + 2 * 2.0)
    sol = br.solutions[k]  # ballbal's own equilibrium, in its units
    assert sol.eigenvalues.size == len(br.table["eig_re"][k])
    np.testing.assert_allclose(np.sort(np.asarray(br.table["eig_re"][k])),
                               np.sort(sol.eigenvalues.real / s), atol=1e-14)
    q = np.asarray(br.table["q"][k])
    np.testing.assert_allclose(q[:2], sol.q[:2] * E, atol=1e-14)
    # the statics of [EccentricRotorABB]'s eq. (8) (rotating frame, its units), every row
    m0 = 2.0
    for w, (x, y, p1, p2) in zip(br.table["omega0"], br.table["q"].to_list(), strict=True):
        g = w**2 * (1 + 2 * m0) - 1
        r1 = -E * w**2 - g * x - 2 * C0 * w * y - m0 * w**2 * (np.cos(p1) + np.cos(p2))
        r2 = 2 * C0 * w * x - g * y - m0 * w**2 * (np.sin(p1) + np.sin(p2))
        r3 = x * np.sin(p1) - y * np.cos(p1)
        assert max(abs(r1), abs(r2), abs(r3)) < 1e-9, (w, r1, r2, r3)


def test_saddle_node_curve_against_condition_14() -> None:
    c = sn_curve()
    assert c.parameters == ("omega0", "m0")
    w = c.table["omega0"].to_numpy()
    m0 = c.table["m0"].to_numpy()
    assert c.table.height > 30 and m0.min() < 1.01 and m0.max() > 4.0
    err = max(abs(m - m0_on_sn(x, m)) for x, m in zip(w, m0, strict=True))
    assert err < 1e-9, err
    # its two sides (omega01 and omega02 of the paper's text) meet at the tip m0 = e/2
    assert m0[0] > 4.0 and m0[-1] > 4.0 and m0.min() < E / 2 + 1e-4


def test_the_codimension_two_point_is_flagged_once() -> None:
    p = sn_curve().points
    near = p.filter((abs(p["omega0"] - 1 / np.sqrt(3)) < 1e-6) & (abs(p["m0"] - 1.0) < 1e-6))
    assert near["type"].to_list() == ["pitchfork"], p


def test_pitchfork_at_half_e() -> None:
    # At omega0 = 1.5 the together state with the balls opposite the imbalance (cos b < 0)
    # meets the perfect balance at m0 = e/2, where the balanced pair is born
    s = units(1.5, 0.5)
    start = next(e for e in equilibria(s.balancer)
                 if e.kind == "together" and np.cos(e.q[2]) < 0)
    br = equilibrium_branch(s, "m0", start=start, range=(0.3, 3.0), options=OPTS)
    bp = br.events.filter(br.events["type"] == "branch_point")
    assert bp.height >= 1 and abs(bp["m0"][0] - E / 2) < 1e-9, br.events
    i = br.events["type"].to_list().index("branch_point")
    pf = equilibrium_curve(br, i, "omega0", range=(0.3, 2.2), options=OPTS)
    assert pf.kind == "pitchfork" and pf.table.height > 10
    assert float(pf.table["omega0"].min()) < 0.6 and float(pf.table["omega0"].max()) > 2.1
    assert np.abs(pf.table["m0"].to_numpy() - E / 2).max() < 1e-9


def _hurwitz(omega0: float, m0: float) -> float:
    s = np.sqrt(1 + 2 * m0)  # [EccentricRotorABB] -> model.md
    M, C, K = _pb_matrices(omega0 * s, m0 / E, 1 / s**2, C0 / s, D0 * s / 2, 1 / E)
    return _hurwitz_last(_char_poly(M, C, K))


def test_hopf_curve_of_the_perfect_balance_against_routh_hurwitz() -> None:
    br = equilibrium_branch(units(0.8, 2.0), "omega0", start="perfect_balance",
                            range=(0.6, 2.2), options=OPTS)
    h = br.events.filter(br.events["type"] == "hopf")
    assert h.height >= 1, br.events
    w0 = float(h["omega0"][0])
    assert abs(brentq(lambda w: _hurwitz(w, 2.0), w0 - 1e-3, w0 + 1e-3, xtol=1e-14) - w0) < 1e-7
    # the paper's figure 4: right of H_1 the perfect balance is stable
    after = br.table.filter(br.table["omega0"] > w0 + 0.05)
    assert after.height > 0 and (after["stability"] == "stable").all()
    i = br.events["type"].to_list().index("hopf")
    c = equilibrium_curve(br, i, "m0", range=(1.0 + 1e-4, 5.0), options=OPTS)
    assert c.table.height > 10 and float(c.table["m0"].max()) > 4.0
    worst = 0.0
    for w, m0 in zip(c.table["omega0"].to_list()[::5], c.table["m0"].to_list()[::5],
                     strict=True):
        root = brentq(lambda x, m0=m0: _hurwitz(x, m0), w - 1e-3, w + 1e-3, xtol=1e-14)
        worst = max(worst, abs(root - w))
    assert worst < 1e-7, worst
    # the Hopf frequency, in the disk's time unit, from the eigenvalues (ballbal's / S)
    k = c.table.height // 2
    s = np.sqrt(1 + 2 * float(c.table["m0"][k]))
    lam = np.asarray(c.table["omega"][k]) * s
    M, C, K = _pb_matrices(float(c.table["omega0"][k]) * s, float(c.table["m0"][k]) / E,
                           1 / s**2, C0 / s, D0 * s / 2, 1 / E)
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ev = np.linalg.eigvals(A)
    assert abs(np.abs(ev[np.argmin(np.abs(ev.real))].imag) - lam) < 1e-7


def test_disk_unit_parameters_are_named() -> None:
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(units(0.3, 2.0), "Omega", start="together", range=(0.2, 2.0))
    assert e.value.parameter == "Omega"
    with pytest.raises(ParameterError) as e:
        DiskUnits(omega0=0.3, m0=0.0, e=2.0)
    assert e.value.parameter == "m0"
    with pytest.raises(ParameterError) as e:
        units(0.3, 2.0).replace(Omega=1.0)
    assert e.value.parameter == "Omega"
