"""Periodic branches by collocation (issue 33): ``periodic_branch(method=...)`` on the
merged R-R branch (mu 0.2, zeta 0.05, zeta_b 0.1, delta 50, eta (1, 1)).

Independent numbers: periods from tests/shooting.py's scipy shooting (DOP853 at rtol
1e-11, residual 1e-9); harmonic balance at N = 24 where the orbit is smooth; the end of
the branch, the saddle-node on the invariant circle where the balls-together equilibria
appear, in closed form (1 - W^2)^2 = 4 zeta^2 W^2 (4 eta^2 - 1), i.e. Omega* =
sqrt(1 + 3 zeta^2) - sqrt(3) zeta = 0.91714045 at zeta 0.05, eta 1 (AUTO-07p's NTST 100:
0.917140455, ../shared/anchors/auto07p/README.md); the period law T ~ C |Omega -
Omega*|^(-1/2) of that bifurcation.
"""

from __future__ import annotations

import numpy as np
import pytest

import ballbal
from ballbal.continuation import Continuation, periodic_branch
from ballbal.exceptions import ParameterError

from shooting import monodromy_multipliers, shoot

ZETA = 0.05
OMEGA_STAR = float(np.sqrt(1 + 3 * ZETA**2) - np.sqrt(3) * ZETA)


def test_closed_form_end_agrees_with_auto() -> None:
    w = OMEGA_STAR
    assert abs((1 - w**2) ** 2 - 4 * ZETA**2 * w**2 * 3) < 1e-14
    assert abs(w - 0.917140455) < 1e-9


def balancer(om: float) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=ZETA, zeta_b=0.1, delta=50.0, eta=(1.0, 1.0),
                            Omega=om)


@pytest.fixture(scope="module")
def start() -> ballbal.PeriodicSolution:
    s = ballbal.periodic(balancer(1.2), "R-R")
    assert s.converged and s.method == "hb"
    return s


@pytest.fixture(scope="module")
def down(start):
    """The downward branch with every default, and user points at 0.95 and 0.93."""
    return periodic_branch(start, "Omega", range=(0.9, 1.2), direction="backward",
                           at=[0.95, 0.93])


def test_default_downward_branch_reaches_the_infinite_period_end(down):
    t = down.table
    assert down.stop == "infinite_period", down.stop
    last = t["Omega"][-1]
    assert 0 < last - OMEGA_STAR < 1e-6, last - OMEGA_STAR
    assert t["period"][-1] > 1e4
    # Harmonic balance first, then collocation, switching once.
    methods = t["method"].to_list()
    k = methods.index("collocation")
    assert k > 0 and set(methods[:k]) == {"hb"} and set(methods[k:]) == {"collocation"}
    # Every collocation row certified, with multipliers and their bound: strongly stable.
    col = t.filter(t["method"] == "collocation")
    assert (col["status"] == "converged").all()
    assert col["closure"].max() <= 1e-4
    assert col["modulus_error"].null_count() == 0
    # Stable where the bound is below the distance to 1 (which it is far from the end).
    judged = col.filter(col["max_modulus"] + col["modulus_error"] < 1)
    assert judged.height > 0 and (judged["stability"] == "stable").all()


def test_user_points_periods_against_shooting(down):
    ev = down.events.filter(down.events["type"] == "user")
    assert ev["Omega"].to_list() == [0.95, 0.93]  # exact: solved at the values
    for i, row in enumerate(ev.iter_rows(named=True)):
        sol = down.event_solutions[int(np.flatnonzero(down.events["type"] == "user")[i])]
        y0 = np.asarray(sol.state(0.0), dtype=float)
        _, t_shoot = shoot(balancer(row["Omega"]), y0, row["period"], [0, 0, -1, -1],
                           phase_index=2)
        assert abs(row["period"] / t_shoot - 1) < 1e-6, (row["Omega"], row["period"], t_shoot)


def test_infinite_period_event_from_the_orbit(down):
    ip = down.events.filter(down.events["type"] == "infinite_period")
    assert ip.height == 1
    # Located from the slowest speed along the orbit (test_infinite_period), which falls
    # to zero linearly at the saddle-node.
    # To event_tol (1e-7 by default; ~1e-8 measured).
    assert abs(ip["Omega"][0] - OMEGA_STAR) < 5e-8, ip["Omega"][0] - OMEGA_STAR
    col = down.table.filter(down.table["method"] == "collocation")
    # Speed / distance to the end is nearly constant near the end (the linear law), down
    # to where the orbit's discretisation error (~5e-9 in the speed) takes over.
    near = col.filter((col["Omega"] - OMEGA_STAR > 2e-7) & (col["Omega"] - OMEGA_STAR < 2e-5))
    assert near.height >= 5
    speed = near["test_infinite_period"].to_numpy()
    assert np.all(np.diff(speed) < 0)
    ratio = speed / (near["Omega"].to_numpy() - OMEGA_STAR)
    assert np.ptp(ratio) < 0.1 * ratio.mean(), ratio


def test_period_law_on_the_last_points(down):
    t = down.table.filter(down.table["Omega"] - OMEGA_STAR < 1e-4)
    assert t.height >= 5
    x = np.log(t["Omega"].to_numpy() - OMEGA_STAR)
    y = np.log(t["period"].to_numpy())
    slope = np.polyfit(x, y, 1)[0]
    assert abs(slope + 0.5) < 0.05, slope


def test_auto_keeps_harmonic_balance_rows(start, down):
    hb = periodic_branch(start, "Omega", range=(0.9, 1.2), direction="backward",
                         method="hb")
    k = down.table["method"].to_list().index("collocation")
    a, b = down.table.head(k), hb.table.head(k)
    for c in ("Omega", "period", "max_modulus", "closure"):
        assert np.allclose(a[c].to_numpy(), b[c].to_numpy(), rtol=1e-12, atol=0), c
    # Upwards the period falls: no switch, the rows are harmonic balance's.
    up = periodic_branch(start, "Omega", range=(1.2, 1.3), direction="forward")
    up_hb = periodic_branch(start, "Omega", range=(1.2, 1.3), direction="forward",
                            method="hb")
    assert set(up.table["method"].to_list()) == {"hb"}
    assert up.table.height == up_hb.table.height
    assert np.allclose(up.table["period"].to_numpy(), up_hb.table["period"].to_numpy(),
                       rtol=1e-12, atol=0)


def test_forced_collocation_agrees_with_resolved_harmonic_balance(start):
    """On smooth orbits (Omega 1.2 to 1.25) the collocation branch's periods and
    multipliers agree with harmonic balance at N = 24 (resolved to round-off) at the
    same user points."""
    col = periodic_branch(start, "Omega", range=(1.2, 1.25), direction="forward",
                          method="collocation", at=[1.22, 1.24])
    assert set(col.table["method"].to_list()) == {"collocation"}
    assert col.stop == "boundary"
    hb = periodic_branch(start, "Omega", range=(1.2, 1.25), direction="forward", N=24,
                         method="hb", at=[1.22, 1.24])
    ec = col.events.filter(col.events["type"] == "user")
    eh = hb.events.filter(hb.events["type"] == "user")
    assert ec["Omega"].to_list() == eh["Omega"].to_list() == [1.22, 1.24]
    assert np.allclose(ec["period"].to_numpy(), eh["period"].to_numpy(), rtol=1e-9, atol=0)
    bound = ec["modulus_error"].to_numpy() + eh["modulus_error"].to_numpy()
    assert np.all(np.abs(ec["max_modulus"].to_numpy() - eh["max_modulus"].to_numpy())
                  <= bound + 1e-9)


def test_bad_method_is_refused(start):
    with pytest.raises(ParameterError, match="method"):
        periodic_branch(start, "Omega", range=(0.9, 1.2), method="fourier")  # type: ignore[arg-type]


def test_period_doubling_located_on_a_collocation_branch():
    """The merged R-R branch in eta (Omega 1.2, zeta_b 0.05) doubles its period near eta
    0.8676: located on collocation rows (bisection on the discretised multipliers), the
    orbit there has a real multiplier at -1 by tests/shooting.py's finite-difference
    monodromy, and the harmonic-balance branch (N = 8) puts it at the same eta."""
    b = ballbal.Balancer(mu=0.2, zeta=0.05, delta=50.0, zeta_b=0.05, Omega=1.2,
                         eta=(0.9, 0.9))
    opts = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8),
                                   floquet=ballbal.Floquet(hill=False))
    s = ballbal.periodic(b, "R-R", options=opts)
    cont = Continuation(ds=0.01, ds_max=0.02, forward=False, max_points=60)
    col = periodic_branch(s, "eta", range=(0.8, 0.9), periodic_options=opts, options=cont,
                          method="collocation")
    hb = periodic_branch(s, "eta", range=(0.8, 0.9), periodic_options=opts, options=cont,
                         method="hb")
    pd_c = col.events.filter(col.events["type"] == "period_doubling")
    pd_h = hb.events.filter(hb.events["type"] == "period_doubling")
    assert pd_c.height == pd_h.height == 1
    eta = float(pd_c["eta"][0])
    assert abs(eta - float(pd_h["eta"][0])) < 1e-6, (eta, pd_h["eta"][0])
    k = int(np.flatnonzero(col.events["type"] == "period_doubling")[0])
    sol = col.event_solutions[k]
    q = sol.balancer
    y0, T = shoot(q, np.asarray(sol.state(0.0), dtype=float), sol.period, [0, 0, -1, -1],
                  phase_index=2)
    ev = monodromy_multipliers(q, y0, T)
    assert np.min(np.abs(ev + 1)) < 1e-4, ev


def test_stop_conditions_on_collocation_rows(start):
    """stop_period and a stop at a user point, both met past the hand-over."""
    b = periodic_branch(start, "Omega", range=(0.9, 1.2), direction="backward",
                        stop_period=1000.0)
    assert b.stop == "period"
    last = b.table.row(-1, named=True)
    assert last["method"] == "collocation"
    assert abs(last["period"] / 1000.0 - 1) < 1e-9
    u = periodic_branch(start, "Omega", range=(0.9, 1.2), direction="backward", at=[0.95],
                        stop="UZ")
    assert u.stop == "user"
    assert u.table["Omega"][-1] == 0.95 and u.table["method"][-1] == "collocation"
