"""Continuation of periodic solutions in one parameter (ballbal.continuation.
periodic_branch), checked against scipy shooting written here, simulation, and the
scan's verdicts."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, curve_fit

import ballbal
from ballbal.continuation import Continuation, periodic_branch, switch
from ballbal.exceptions import ParameterError

from reference import rhs
from shooting import newton

STD = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
OPTS = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))


# --- shooting (independent of the harmonic balance) -------------------------------------

def _flow_tol(b: ballbal.Balancer, y0: np.ndarray, T: float, rtol: float) -> np.ndarray:
    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0, rtol=rtol, atol=rtol * 1e-2,
                  method="DOP853")
    return r.y[:, -1]


def shoot_newton(b: ballbal.Balancer, y: np.ndarray, T: float,
                 winding: np.ndarray) -> tuple[float, np.ndarray]:
    """Shooting by Newton with the monodromy from forward differences of the flow
    (phase: the first ball's angle fixed), from a close start: period and multipliers at
    the closed orbit."""
    n = len(y)
    shift = np.zeros(n)
    shift[: len(winding)] = 2 * np.pi * np.asarray(winding)
    free = [i for i in range(n) if i != 2]
    h = 1e-6
    for _ in range(6):
        end = _flow_tol(b, y, T, 1e-10)
        M = np.empty((n, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = h
            M[:, j] = (_flow_tol(b, y + e, T, 1e-10) - end) / h
        r = end - y - shift
        if np.abs(r).max() < 1e-9:
            return T, np.linalg.eigvals(M)
        J = np.column_stack([(M - np.eye(n))[:, free], rhs(b, T, end)])
        d = np.linalg.solve(J, -r)
        y = y.copy()
        y[free] += d[:-1]
        T += d[-1]
    raise AssertionError(f"shooting did not close: {np.abs(r).max()}")


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
        (dict(parameter="Omega", range=(1.0, 2.0), N=0), "N"),
    ]
    for kw, name in cases:
        p = kw.pop("parameter")
        with pytest.raises(ParameterError) as e:
            periodic_branch(start, p, **kw)
        assert e.value.parameter == name, (kw, e.value)
    # A bad step is refused when the options are made, before any branch.
    with pytest.raises(ParameterError) as e:
        Continuation(ds=-1.0)
    assert e.value.parameter == "ds"
    with pytest.raises(ParameterError) as e:
        periodic_branch("x", "Omega", range=(1.0, 2.0))  # type: ignore[arg-type]
    assert e.value.parameter == "start"


def _row_near(br: ballbal.continuation.Branch, om: float) -> int:
    return int(np.argmin(np.abs(br.table["Omega"].to_numpy() - om)))


def _shoot_from(br: ballbal.continuation.Branch, k: int, om: float) -> tuple[float, np.ndarray]:
    """Shooting at Omega `om`, started from the series re-solved there from branch row
    `k` (the start only): period and multipliers."""
    s = br.solutions[k]
    b = s.balancer.replace(Omega=om)
    start = ballbal.periodic(b, "R-R", options=OPTS, guess=s)
    assert start.converged
    return shoot_newton(b, start.state(0.0), start.period, np.asarray(start.winding))


def test_branch_point_against_shooting() -> None:
    """At the branch point a real multiplier other than the trivial one passes +1
    (the merged balls' separation multiplier): shooting on both sides of the located
    point brackets it, and its secant zero is the located parameter."""
    br = standard_up()
    bp = br.events.filter(br.events["type"] == "branch_point")
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
    # Measured 7e-6 (the secant over the +-2e-3 bracket; the series closes to 1e-11).
    assert abs(zero - om) < 5e-5, (zero, om)


# The merged balls' subspace (b1 = b2, b1' = b2') is invariant: shooting in it sees the
# fold's multiplier without the balls' separation multiplier, which is also near +1 there
# (it passed +1 at the branch point just below the fold).
_MERGED = [0, 1, 2, 4, 5, 6]  # x, y, b1, x', y', b1'


def _unmerge(z: np.ndarray) -> np.ndarray:
    return np.array([z[0], z[1], z[2], z[2], z[3], z[4], z[5], z[5]])


def _merged_flow(b: ballbal.Balancer, z: np.ndarray, T: float) -> np.ndarray:
    return _flow_tol(b, _unmerge(z), T, 1e-10)[_MERGED]


def merged_fold_multiplier(b: ballbal.Balancer, y_guess: np.ndarray, T_guess: float,
                           winding: float) -> float:
    """Merged orbit by shooting in the merged subspace (phase: b1(0) fixed), and the real
    multiplier closest to +1 after the trivial one (monodromy by forward differences)."""
    zg = y_guess[_MERGED]
    shift = np.zeros(6)
    shift[2] = 2 * np.pi * winding
    free = [0, 1, 3, 4, 5]

    def F(u: np.ndarray) -> np.ndarray:
        z = zg.copy()
        z[free] = u[:-1]
        return _merged_flow(b, z, u[-1]) - z - shift

    # The merged flow runs at rtol 1e-10: its residual floor is ~1e-9.
    u = newton(F, np.append(zg[free], T_guess), tol=1e-8)
    z = zg.copy()
    z[free] = u[:-1]
    T = float(u[-1])
    h = 1e-6
    end = _merged_flow(b, z, T)
    M = np.empty((6, 6))
    for j in range(6):
        e = np.zeros(6)
        e[j] = h
        M[:, j] = (_merged_flow(b, z + e, T) - end) / h
    rest = _nontrivial(np.linalg.eigvals(M))
    real = rest[np.abs(rest.imag) < 1e-6].real
    return float(real[np.argmin(np.abs(real - 1))])


def test_fold_against_shooting() -> None:
    """At the fold a second multiplier of the merged orbit reaches +1: along the branch
    it passes 1 transversally while Omega turns back, so Omega is a smooth function of
    g = lambda - 1 with no linear term at g = 0: Omega = Omega_LP + a g^2 + b g^3.
    Shooting at Omega_LP - h, h = 3e-4 and 1e-3, on both sides of the fold (g < 0 before
    it, g > 0 after) and that law fitted by least squares give the fold. N = 8 truncation
    is negligible here (the series' closure at Omega 1.8 is 1e-11); the fits' spread
    (a quadratic with a linear term, or the three-point law without the h = 1e-3 point
    after the fold) is 1e-5, hence the 3e-5 allowed. Each shooting starts from the
    series re-solved at its Omega from the branch row on its side (the start only)."""
    br = standard_up()
    lp = br.events.filter(br.events["type"] == "fold")
    assert lp.height == 1, br.events
    om = float(lp["Omega"][0])
    i = int(lp["index"][0])
    t = br.table
    pts = []
    for rows in (range(0, i), range(i, t.height)):
        for h in (3e-4, 1e-3):
            k = min(rows, key=lambda k: abs(float(t["Omega"][k]) - (om - h)))
            b = br.solutions[k].balancer.replace(Omega=om - h)
            s = ballbal.periodic(b, "R-R", options=OPTS, guess=br.solutions[k])
            assert s.converged
            lam = merged_fold_multiplier(b, s.state(0.0), s.period, float(s.winding[2]))
            pts.append((om - h, lam - 1))
    g = np.array([p[1] for p in pts])
    assert np.all(g[:2] < 0) and np.all(g[2:] > 0) and g[1] < g[0] and g[3] > g[2], pts
    A = np.stack([np.ones(4), g**2, g**3], axis=1)
    (om_lp, a, _), *_ = np.linalg.lstsq(A, np.array([p[0] for p in pts]), rcond=None)
    assert a < 0
    assert abs(om_lp - om) < 3e-5, (om_lp, om, pts)


def _separation_and_balance(b: ballbal.Balancer, s: ballbal.PeriodicSolution,
                            t_end: float) -> tuple[float, float, float]:
    """Simulation from the merged orbit with the balls nudged 2e-3 apart: the balls'
    final separation (mod 2 pi, in [0, pi]), rotor displacement and largest rate."""
    y0 = s.state(0.0)
    y0[2] += 1e-3
    y0[3] -= 1e-3
    sim = ballbal.simulate(b, y0, np.linspace(0.0, t_end, 201))
    last = sim.tail(20)
    sep = float(np.abs(np.angle(np.exp(1j * (last["b1"][-1] - last["b2"][-1])))))
    disp = float(np.hypot(last["x"], last["y"]).max())
    rate = float(np.abs(last.select("dx", "dy", "db1", "db2").to_numpy()).max())
    return sep, disp, rate


def test_simulation_past_the_branch_point_separates_the_balls() -> None:
    """Beyond the branch point the merged orbit is unstable in the separation direction:
    a simulation from it with the balls nudged apart ends at the perfect balance (closed
    form for two equal balls: rotor centred, balls at rest, cos b1 + cos b2 = -1, i.e.
    2 pi / 3 apart). Before it the nudge dies out and the balls stay merged. (The branch
    folds back 0.009 above the branch point: the point past it is taken between the two.)"""
    br = standard_up()
    bp = float(br.events.filter(br.events["type"] == "branch_point")["Omega"][0])
    lp = float(br.events.filter(br.events["type"] == "fold")["Omega"][0])
    assert bp + 3e-3 < lp
    guess = br.solutions[_row_near(br, bp)]
    for om, past in ((bp - 5e-3, False), (bp + 3e-3, True)):
        b = guess.balancer.replace(Omega=om)
        s = ballbal.periodic(b, "R-R", options=OPTS, guess=guess)
        assert s.converged
        sep, disp, rate = _separation_and_balance(b, s, 3000.0)
        if past:
            assert abs(sep - 2 * np.pi / 3) < 1e-6 and disp < 1e-6 and rate < 1e-6, \
                (om, sep, disp, rate)
        else:
            # Merged (the nudge, 2e-3, decays) and still on the orbit (moving).
            assert sep < 1e-6 and disp > 1.0, (om, sep, disp)


@cache
def rr_zeta_b_01_down() -> ballbal.continuation.Branch:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0,
                         eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=OPTS)
    # Harmonic balance's own end (method="auto" would hand over to collocation).
    return periodic_branch(start, "Omega", range=(0.5, 1.0),
                           options=Continuation(ds=0.02, ds_max=0.05, forward=False),
                           method="hb")


def _simulated_period(b: ballbal.Balancer, y0: np.ndarray, t_end: float) -> float:
    """Period of the attracting R-R orbit from a simulation (the core's RK45, no harmonic
    balance): the time between the first ball's last two whole turns, counted from its
    start (near the infinite-period end a turn takes most of ``t_end``; counting turns of
    the absolute angle would make whether the start is one depend on the sign of a
    round-off in ``b1(0) = 0``)."""
    t = np.arange(0.0, t_end, 0.05)
    b1 = ballbal.simulate(b, y0, t)["b1"].to_numpy()
    b1 = b1 - b1[0]
    k = np.floor(b1 / (2 * np.pi))
    idx = np.nonzero(np.diff(k))[0]
    level = 2 * np.pi * np.maximum(k[idx], k[idx + 1])
    c = t[idx] + (level - b1[idx]) / (b1[idx + 1] - b1[idx]) * (t[idx + 1] - t[idx])
    return float(c[-1] - c[-2])


def _period_law_end(om: np.ndarray, T: np.ndarray) -> float:
    """Omega* with T = C / sqrt|Omega - Omega*| + D through three points (equal slopes of
    T against 1 / sqrt|Omega - Omega*|), Omega* beyond the third."""
    def g(ps: float) -> float:
        u = 1 / np.sqrt(np.abs(om - ps))
        return float((T[2] - T[1]) / (u[2] - u[1]) - (T[1] - T[0]) / (u[1] - u[0]))
    return float(brentq(g, om[2] - 1e-9 * np.sign(om[2] - om[1]),
                        om[2] + 0.05 * np.sign(om[2] - om[1])))


def test_continuation_down_stops_at_the_infinite_period_end() -> None:
    """Down the R-R branch (zeta_b 0.1, eta 1) omega falls to 0 where the balls-together
    equilibria appear in a saddle-node on the orbit's circle: (1 - W^2)^2 =
    4 zeta^2 W^2 (4 eta^2 - 1), Omega* = 0.917140 at zeta 0.05. The branch stops there and
    says so, with no row past it; the period follows C / sqrt|Omega - Omega*| (+ D)."""
    z = 0.05
    om_star = -z * np.sqrt(3) + np.sqrt(1 + 3 * z**2)
    assert abs((1 - om_star**2) ** 2 - 4 * z**2 * om_star**2 * 3) < 1e-12
    br = rr_zeta_b_01_down()
    t = br.table
    assert br.stop == "infinite_period", br.stop
    types = br.events["type"].to_list()
    assert types[-1] == "infinite_period" and types.count("infinite_period") == 1
    ip = br.events.filter(br.events["type"] == "infinite_period")
    assert int(ip["index"][0]) == t.height
    om_ip = float(ip["Omega"][0])
    assert (t["Omega"] > om_ip).all()
    # The law itself, from simulation at Omega* + eps: exponent -1/2 (a free-exponent fit
    # gives -0.497: D and C trade off a little), and its end on the closed form (1e-6;
    # 2e-5 allowed for the law's next term at eps 2.5e-3).
    last = br.solutions[-1]
    eps = np.array([4e-4, 1e-3, 2.5e-3, 6e-3])
    Ts = np.array([_simulated_period(last.balancer.replace(Omega=om_star + e),
                                     last.state(0.0), 3000.0) for e in eps])
    (_, a, _), _ = curve_fit(lambda e, C, a, D: C * e**a + D, eps, Ts, p0=(50.0, -0.5, 0.0))
    assert abs(a + 0.5) < 0.01, a
    assert abs(_period_law_end(om_star + eps[2::-1], Ts[2::-1]) - om_star) < 2e-5
    # The branch's last rows: N = 8 periods within 2e-3 of simulation (measured 1.2e-3;
    # their closure is near the certificate's limit, which is what ended the branch).
    rows = [t.height - 3, t.height - 2, t.height - 1]
    om = t["Omega"].to_numpy()[rows]
    T_hb = t["period"].to_numpy()[rows]
    T_sim = np.array([_simulated_period(br.solutions[k].balancer, br.solutions[k].state(0.0),
                                        4 * float(T_hb[i])) for i, k in enumerate(rows)])
    assert np.all(np.abs(T_hb / T_sim - 1) < 2e-3), (T_hb, T_sim)
    # The located end: the law through those rows. On the simulated periods it ends
    # 8.5e-5 from the closed form (the law's next term at eps 9e-3); the rows' 1.2e-3
    # period error adds 1.4e-4 (measured 2.3e-4 in all), hence 4e-4.
    assert abs(_period_law_end(om, T_sim) - om_star) < 2e-4
    assert abs(om_ip - om_star) < 4e-4, (om_ip, om_star)


def _standard(eta: float) -> ballbal.Balancer:
    return ballbal.Balancer(**STD, Omega=1.2, eta=(eta, eta))


def _turns(b: ballbal.Balancer, y0: np.ndarray, t_end: float) -> np.ndarray:
    """Durations of the first ball's successive whole turns in a simulation."""
    t = np.arange(0.0, t_end, 0.02)
    b1 = ballbal.simulate(b, y0, t)["b1"].to_numpy()
    k = np.floor(b1 / (2 * np.pi))
    idx = np.nonzero(np.diff(k))[0]
    level = 2 * np.pi * np.maximum(k[idx], k[idx + 1])
    return np.diff(t[idx] + (level - b1[idx]) / (b1[idx + 1] - b1[idx]) * (t[idx + 1] - t[idx]))


def test_period_doubling_against_shooting_and_simulation() -> None:
    """The merged R-R orbit at zeta_b 0.05, Omega 1.2 continued down in eta: a real
    multiplier passes -1 (Tien's (2011) tongue of balls rotating separately). Shooting at
    eta_PD +- 3e-3 brackets it and its secant zero is the located eta (measured 2e-6:
    the N = 8 series closes to 1e-6 under scipy there; 2e-5 allowed for the secant's
    curvature error over the bracket). Inside the tongue, simulation from the merged
    orbit, nudged, settles on alternating turns whose sum is the period of the doubled
    orbit switched to from the event; above it the turns stay equal, one period each."""
    s = ballbal.periodic(_standard(0.9), "R-R", options=OPTS)
    br = periodic_branch(s, "eta", range=(0.8, 0.9),
                         options=Continuation(ds=0.01, ds_max=0.02, forward=False))
    pd = br.events.filter(br.events["type"] == "period_doubling")
    assert pd.height == 1, br.events
    e_pd = float(pd["eta"][0])
    k = int(pd["index"][0])
    h = 3e-3
    g = []
    for e in (e_pd + h, e_pd - h):
        sol = ballbal.periodic(_standard(e), "R-R", options=OPTS, guess=br.solutions[k])
        assert sol.converged
        T, ev = shoot_newton(_standard(e), sol.state(0.0), sol.period, np.asarray(sol.winding))
        assert abs(T - sol.period) < 1e-6 * T
        real = ev[np.abs(ev.imag) < 1e-8].real
        g.append(real[np.argmin(np.abs(real + 1))] + 1)
    assert g[0] > 0 > g[1], g
    zero = (e_pd + h) - g[0] * (-2 * h) / (g[1] - g[0])
    assert abs(zero - e_pd) < 2e-5, (zero, e_pd)
    # The doubled orbit from the event, followed into the tongue.
    i_pd = br.events["type"].to_list().index("period_doubling")
    d2 = switch(br, event=i_pd, amplitude=0.2)
    assert d2.converged and list(d2.winding[2:]) == [-2, -2] and d2.info["value"] < e_pd
    for e in (0.84, 0.82):
        d2 = ballbal.periodic(_standard(e), "R-R", N=16, guess=d2)
        assert d2.converged and list(d2.winding[2:]) == [-2, -2]
    kick = 1e-3 * np.array([1, 0, 1, -1, 0, 0, 0, 0])
    for e, inside in ((0.82, True), (0.88, False)):
        merged = ballbal.periodic(_standard(e), "R-R", options=OPTS, guess=br.solutions[0])
        assert merged.converged
        d = _turns(_standard(e), merged.state(0.0) + kick, 6000.0)
        if inside:
            assert abs(d[-1] - d[-2]) > 0.1 * d[-1]
            assert abs(d[-1] - d[-3]) < 1e-4 * d[-1]
            assert abs((d[-1] + d[-2]) / d2.period - 1) < 1e-5, (d[-2:], d2.period)
        else:
            assert abs(d[-1] - d[-2]) < 1e-2 * d[-1]
            assert abs(d[-1] / merged.period - 1) < 1e-3, (d[-2:], merged.period)


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
    ev = br.events.filter(br.events["type"] != "infinite_period")["Omega"].to_numpy()
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
