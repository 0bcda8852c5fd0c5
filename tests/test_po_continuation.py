"""Continuation of periodic solutions in one parameter (ballbal.continuation.
periodic_branch), checked against scipy shooting written here, simulation, and the
scan's verdicts."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

import ballbal
from ballbal.continuation import Continuation, periodic_branch
from ballbal.exceptions import ParameterError

from reference import rhs

STD = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
OPTS = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))


# --- shooting with variational equations (independent of the harmonic balance) ---------

def _flow_var(b: ballbal.Balancer, y0: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
    """State and monodromy after T: the variational equations integrated with the flow
    (the Jacobian of the right-hand side by central differences of `reference.rhs`)."""
    n2 = len(y0)

    def jac(t: float, y: np.ndarray) -> np.ndarray:
        J = np.empty((n2, n2))
        for j in range(n2):
            h = 1e-7 * max(1.0, abs(y[j]))
            e = np.zeros(n2)
            e[j] = h
            J[:, j] = (rhs(b, t, y + e) - rhs(b, t, y - e)) / (2 * h)
        return J

    def f(t: float, z: np.ndarray) -> np.ndarray:
        y, P = z[:n2], z[n2:].reshape(n2, n2)
        return np.concatenate([rhs(b, t, y), (jac(t, y) @ P).ravel()])

    z0 = np.concatenate([y0, np.eye(n2).ravel()])
    r = solve_ivp(f, (0, T), z0, rtol=1e-10, atol=1e-12, method="DOP853")
    z = r.y[:, -1]
    return z[:n2], z[n2:].reshape(n2, n2)


def shoot(b: ballbal.Balancer, y_guess: np.ndarray, T_guess: float,
          winding: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Periodic orbit by shooting (phase: the first ball's angle fixed): initial state,
    period and the monodromy's eigenvalues, largest modulus first."""
    n2 = len(y_guess)
    d = n2 // 2
    shift = np.zeros(n2)
    shift[:d] = 2 * np.pi * winding
    k = 2  # first ball's angle
    free = [i for i in range(n2) if i != k]

    def F(z: np.ndarray) -> np.ndarray:
        y0 = y_guess.copy()
        y0[free] = z[:-1]
        return _flow(b, y0, z[-1]) - y0 - shift

    z, _, ok, msg = fsolve(F, np.append(y_guess[free], T_guess), full_output=True,
                           xtol=1e-12)
    assert ok == 1, msg
    y0 = y_guess.copy()
    y0[free] = z[:-1]
    _, M = _flow_var(b, y0, z[-1])
    ev = np.linalg.eigvals(M)
    return y0, float(z[-1]), ev[np.argsort(-np.abs(ev))]


def _flow(b: ballbal.Balancer, y0: np.ndarray, T: float) -> np.ndarray:
    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0, rtol=1e-11, atol=1e-13,
                  method="DOP853")
    return r.y[:, -1]


def _nontrivial(ev: np.ndarray) -> np.ndarray:
    i = int(np.argmin(np.abs(ev - 1)))
    return np.delete(ev, i)


# --- the branches -------------------------------------------------------------------------

@cache
def standard_up() -> ballbal.continuation.Branch:
    b = ballbal.Balancer(**STD, Omega=1.2, eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=OPTS)
    return periodic_branch(start, "Omega", range=(1.2, 3.0),
                           options=Continuation(ds=0.02, ds_max=0.05, max_points=140))


def test_table_and_solutions_describe_the_branch() -> None:
    br = standard_up()
    assert br.kind == "periodic" and br.parameter == "Omega"
    t = br.table
    assert len(br.solutions) == t.height and len(br.event_solutions) == br.events.height
    for k in (0, t.height // 2, t.height - 1):
        s = br.solutions[k]
        assert s.balancer.Omega == t["Omega"][k]
        # The row is an orbit of its model: periodic() from it at its Omega agrees.
        r = ballbal.periodic(s.balancer, "R-R", options=OPTS, guess=s)
        assert abs(r.omega - t["omega"][k]) < 1e-8
    for e, s in zip(br.events.iter_rows(named=True), br.event_solutions, strict=True):
        assert s.balancer.Omega == pytest.approx(e["Omega"], abs=0)
    # A point whose certificate fails is never called stable.
    bad = t.filter(t["status"] != "converged")
    assert (bad["stability"] != "stable").all()


def test_bad_inputs_name_the_parameter() -> None:
    b = ballbal.Balancer(**STD, Omega=1.2, eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", N=4)
    cases = [
        (dict(parameter="nope", range=(1.0, 2.0)), "parameter"),
        (dict(parameter="Omega", range=(1.3, 2.0)), "range"),
        (dict(parameter="Omega", range=(2.0, 1.0)), "range"),
        (dict(parameter="Omega", range=(1.0, 2.0), min_omega=-1.0), "min_omega"),
        (dict(parameter="Omega", range=(1.0, 2.0), options=Continuation(ds=-1.0)), "ds"),
        (dict(parameter="Omega", range=(1.0, 2.0), N=0), "N"),
    ]
    for kw, name in cases:
        p = kw.pop("parameter")
        with pytest.raises(ParameterError) as e:
            periodic_branch(start, p, **kw)
        assert e.value.parameter == name, (kw, e.value)
    with pytest.raises(ParameterError) as e:
        periodic_branch("x", "Omega", range=(1.0, 2.0))  # type: ignore[arg-type]
    assert e.value.parameter == "start"


def _row_near(br: ballbal.continuation.Branch, om: float) -> int:
    return int(np.argmin(np.abs(br.table["Omega"].to_numpy() - om)))


def _shoot_from(br: ballbal.continuation.Branch, k: int, om: float) -> tuple[float, np.ndarray]:
    """Shooting at Omega `om` from branch row `k`'s orbit: period and multipliers."""
    s = br.solutions[k]
    b = s.balancer.replace(Omega=om)
    _, T, ev = shoot(b, s.state(0.0), s.period, np.asarray(s.winding))
    return T, ev


def test_branch_point_against_shooting() -> None:
    """At the branch point a real multiplier other than the trivial one passes +1
    (the merged balls' separation multiplier): shooting on both sides of the located
    point brackets it, and its secant zero is the located parameter."""
    br = standard_up()
    bp = br.events.filter(br.events["type"] == "BP")
    assert bp.height >= 1, br.events
    om = float(bp["Omega"][0])
    k = _row_near(br, om)
    g = []
    h = 2e-3
    for o in (om - h, om + h):
        _, ev = _shoot_from(br, k, o)
        real = [z.real for z in _nontrivial(ev) if abs(z.imag) < 1e-8]
        g.append(min(real, key=lambda r: abs(r - 1)) - 1)
    assert g[0] * g[1] < 0, g
    zero = (om - h) - g[0] * (2 * h) / (g[1] - g[0])
    assert abs(zero - om) < 2e-4, (zero, om)


@cache
def rr_zeta_b_01_down() -> ballbal.continuation.Branch:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0,
                         eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=OPTS)
    return periodic_branch(start, "Omega", range=(0.5, 1.0),
                           options=Continuation(ds=0.02, ds_max=0.05, forward=False))


def test_monodromy_and_hill_give_the_same_events() -> None:
    br = standard_up()
    b = br.solutions[0].balancer
    start = ballbal.periodic(b, "R-R", options=OPTS)
    hill = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8),
                                   floquet=ballbal.Floquet(monodromy=False, hill=True))
    bh = periodic_branch(start, "Omega", range=(1.2, 3.0), periodic_options=hill,
                         options=Continuation(ds=0.02, ds_max=0.05, max_points=140))
    assert bh.events["type"].to_list() == br.events["type"].to_list()
    assert np.allclose(bh.events["Omega"].to_numpy(), br.events["Omega"].to_numpy(),
                       atol=1e-3)


def test_scan_verdicts_agree_with_the_events() -> None:
    """Every converged merged R-R row of a fine scan has the verdict of the branch on
    its side of the located events (the branch row nearest in (Omega, omega)), except
    within one grid step of an event."""
    br = standard_up()
    step = 0.01
    hi = float(br.table["Omega"].max())
    b = ballbal.Balancer(**STD, Omega=1.2, eta=(1.0, 1.0))
    df = ballbal.scan(b, Omega=np.arange(1.2, hi + 1e-9, step), patterns=("R-R",), N=8)
    df = df.filter((df["status"] == "converged") & df["separation_error"].is_not_null()
                   & df["stability"].is_in(["stable", "unstable"]))
    assert df.height > 10
    ev = br.events.filter(br.events["type"] != "IP")["Omega"].to_numpy()
    t = br.table.filter(br.table["stability"].is_in(["stable", "unstable"]))
    checked = 0
    for r in df.iter_rows(named=True):
        if np.any(np.abs(ev - r["Omega"]) <= step):
            continue
        near = t.filter((t["Omega"] - r["Omega"]).abs() < 0.02)
        if near.height == 0:
            continue
        dist = (np.abs(near["Omega"].to_numpy() - r["Omega"])
                + np.abs(near["omega"].to_numpy() - r["omega"]))
        j = int(np.argmin(dist))
        lo, hi_ = sorted((float(near["Omega"][j]), float(r["Omega"])))
        if dist[j] > 2e-2 or np.any((ev > lo) & (ev < hi_)):
            continue
        assert near["stability"][j] == r["stability"], (r["Omega"], r["omega"], near)
        checked += 1
    assert checked > 10
