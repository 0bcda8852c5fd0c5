"""Branch controls (AUTO's UZ and stop conditions): points at chosen parameter values
(``at=``), stops at an event, at a period and at a parameter value, and periodic
branches both ways from one start. Each ``at=`` point is checked as a solution by a
method written here (an independent Newton on the equations of motion for an
equilibrium, scipy shooting for an orbit), never against ballbal's own numbers.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import ballbal
from ballbal.continuation import Continuation, equilibrium_branch, periodic_branch
from ballbal.exceptions import ParameterError

from reference import rhs
from shooting import newton, shoot

N8 = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))
STEPS = Continuation(ds=0.02, ds_max=0.05, max_points=200)


# --- equilibria ---------------------------------------------------------------------------

def _together_model(eta: float = 0.3) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.05,
                            eta=(eta, eta))


@cache
def together(at: tuple[float, ...] | None = None, stop: str | None = None
             ) -> ballbal.continuation.Branch:
    """The balls-together branch in eta (a pitchfork at eta 1/2, then a fold)."""
    return equilibrium_branch(_together_model(), "eta", start="together", range=(0.2, 1.0),
                              options=STEPS, at=None if at is None else list(at), stop=stop)


def _equilibrium_residual(b: ballbal.Balancer, q: np.ndarray) -> np.ndarray:
    """The accelerations at rest at ``q``: zero at an equilibrium."""
    return rhs(b, 0.0, np.concatenate([q, np.zeros_like(q)]))[len(q):]


def test_equilibrium_at_points_are_solutions_at_their_values() -> None:
    """The branch turns back at a fold near eta 0.699: it crosses 0.45 and 0.65 on the
    way up and again on the way down, and never reaches 0.75."""
    at = (0.45, 0.65, 0.75)
    br = together(at)
    users = br.events.filter(br.events["type"] == "user")
    assert users["eta"].to_list() == pytest.approx([0.45, 0.65, 0.65, 0.45], abs=1e-12)
    fold = br.events.filter(br.events["type"] == "fold")
    assert fold.height == 1 and 0.65 < fold["eta"][0] < 0.75
    for e in users.iter_rows(named=True):
        b = _together_model(e["eta"])
        q = np.asarray(e["q"])
        # Newton on the equations of motion (finite-difference Jacobian), from 1e-3 off
        q_ref = newton(lambda z, b=b: _equilibrium_residual(b, z), q + 1e-3, tol=1e-13)
        assert np.abs(q - q_ref).max() < 1e-9, (q, q_ref)
        # the event's row is the first row past it
        row = int(e["row"])
        eta = br.table["eta"].to_numpy()
        assert min(eta[row - 1], eta[row]) <= e["eta"] <= max(eta[row - 1], eta[row])
        assert "user" in br.table["event"][row]
    # the rows and the other events are those of the branch without at=
    plain = together()
    assert br.table.height == plain.table.height
    assert np.abs(br.table["eta"].to_numpy() - plain.table["eta"].to_numpy()).max() < 1e-12
    others = br.events.filter(br.events["type"] != "user")
    assert others["type"].to_list() == plain.events["type"].to_list()
    assert np.abs(others["eta"].to_numpy() - plain.events["eta"].to_numpy()).max() < 1e-12


def test_equilibrium_branch_stops_at_an_event() -> None:
    plain = together()
    assert plain.events["type"].to_list() == ["branch_point", "hopf", "fold"], plain.events
    for name, alias in (("branch_point", "BP"), ("hopf", "HB"), ("fold", "LP")):
        br = together(stop=alias)
        assert br.stop == name
        assert br.events["type"][-1] == name and br.events["type"].to_list().count(name) == 1
        # the last row is the event's point, where the full branch located it
        k = plain.events["type"].to_list().index(name)
        assert br.table["eta"][-1] == pytest.approx(plain.events["eta"][k], abs=1e-9)
        assert br.events["eta"][-1] == br.table["eta"][-1]
        assert int(br.events["row"][-1]) == br.table.height - 1


def test_equilibrium_branch_stops_at_a_value() -> None:
    """The stop at a parameter value is the range's edge, reached exactly (both ways), or
    the first of the at= values with stop="user" (AUTO's negative UZ)."""
    br = equilibrium_branch(_together_model(), "eta", start="together", range=(0.25, 0.4),
                            options=STEPS, direction="both")
    assert br.stop == "boundary/boundary"
    assert br.table["eta"][0] == 0.25 and br.table["eta"][-1] == 0.4
    br = together(at=(0.45, 0.7), stop="UZ")
    assert br.stop == "user"
    assert br.table["eta"][-1] == pytest.approx(0.45, abs=1e-12)
    assert (br.table["eta"].to_numpy() <= 0.45 + 1e-12).all()


# --- periodic orbits ----------------------------------------------------------------------

def _rr(Omega: float, zeta_b: float) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=zeta_b, delta=50.0, Omega=Omega,
                            eta=(1.0, 1.0))


@cache
def rr_start(Omega: float = 1.2, zeta_b: float = 0.05) -> ballbal.PeriodicSolution:
    return ballbal.periodic(_rr(Omega, zeta_b), "R-R", options=N8)


@cache
def rr_up(at: tuple[float, ...] | None = None, stop: str | None = None
          ) -> ballbal.continuation.Branch:
    """The merged R-R branch up from Omega 1.2 (a branch point near 1.80, then a fold
    near 1.81)."""
    return periodic_branch(rr_start(), "Omega", range=(1.2, 1.9), options=STEPS,
                           at=None if at is None else list(at), stop=stop)


def test_periodic_at_points_against_shooting() -> None:
    at = (1.25, 1.3)
    br = rr_up(at)
    users = br.events.filter(br.events["type"] == "user")
    sols = [s for s, t in zip(br.event_solutions, br.events["type"], strict=True)
            if t == "user"]
    assert users["Omega"].to_list() == pytest.approx(list(at), abs=1e-12)
    for e, s in zip(users.iter_rows(named=True), sols, strict=True):
        assert s.balancer.Omega == pytest.approx(e["Omega"], abs=1e-12)
        assert e["test"] == 0.0
        # scipy shooting at that Omega (phase: the first ball's angle), from the orbit
        y0, T = shoot(s.balancer, s.state(0.0), s.period, s.winding, 2)
        assert abs(s.period / T - 1) < 1e-8, (s.period, T)
        assert np.abs(s.state(0.0) - y0).max() < 1e-6, np.abs(s.state(0.0) - y0).max()
    plain = rr_up()
    assert br.table.height == plain.table.height
    assert np.abs(br.table["Omega"].to_numpy() - plain.table["Omega"].to_numpy()).max() < 1e-12


def test_the_slow_orbit_at_omega_095_against_shooting() -> None:
    """The issue's case: down the R-R branch at zeta_b 0.1 towards its infinite-period
    end, the orbit at Omega 0.95 (period ~196, twice the start's), stopping there. With
    N = 16 the series is resolved: its period agrees with shooting to 1e-9 (measured
    3e-11), and the orbit's own row is that point."""
    opts = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=16))
    start = ballbal.periodic(_rr(1.0, 0.1), "R-R", options=opts)
    br = periodic_branch(start, "Omega", range=(0.5, 1.0), options=STEPS, direction="backward",
                         at=0.95, stop="user")
    assert br.stop == "user"
    assert br.table["Omega"][-1] == pytest.approx(0.95, abs=1e-12)
    s = br.solutions[-1]
    assert s.period > 1.9 * start.period
    y0, T = shoot(s.balancer, s.state(0.0), s.period, s.winding, 2)
    assert abs(s.period / T - 1) < 1e-9, (s.period, T)
    assert np.abs(s.state(0.0) - y0).max() < 1e-4


def test_periodic_branch_stops_at_an_event() -> None:
    plain = rr_up()
    kinds = plain.events["type"].to_list()
    assert "branch_point" in kinds and "fold" in kinds, kinds
    for name in ("branch_point", "fold"):
        br = rr_up(stop=name)
        assert br.stop == name
        assert br.events["type"][-1] == name
        k = kinds.index(name)
        assert br.table["Omega"][-1] == pytest.approx(plain.events["Omega"][k], abs=1e-9)
        assert br.table.height <= int(plain.events["index"][k]) + 1
    with pytest.raises(ParameterError) as e:
        rr_up(stop="hopf")
    assert e.value.parameter == "stop"


def test_periodic_branch_stops_at_a_period() -> None:
    """Down the R-R branch at zeta_b 0.1 the period grows towards the infinite-period end
    (Omega* = 0.91714): the branch stops where it reaches the period asked for, and that
    last row is an orbit of that period (scipy shooting at its Omega)."""
    start = rr_start(1.0, 0.1)
    T_stop = 2.0 * start.period
    br = periodic_branch(start, "Omega", range=(0.5, 1.0), options=STEPS, direction="backward",
                         stop_period=T_stop)
    assert br.stop == "period"
    T = br.table["period"].to_numpy()
    assert abs(T[-1] / T_stop - 1) < 1e-12
    assert (T[:-1] < T_stop).all()
    # The row before is well below the period asked for (the stop was not a row the
    # branch reached anyway); the last row is an orbit of that period at its Omega, to the
    # N = 8 series' truncation this close to the end (measured 3.6e-6).
    assert T[-2] / T_stop < 0.99, T[-2] / T_stop
    s = br.solutions[-1]
    _, T_shoot = shoot(s.balancer, s.state(0.0), s.period, s.winding, 2)
    assert abs(T_shoot / T_stop - 1) < 2e-5, (T_shoot, T_stop)
    for bad in (0.5 * start.period, -1.0, float("nan")):
        with pytest.raises(ParameterError) as e:
            periodic_branch(start, "Omega", range=(0.5, 1.0), stop_period=bad)
        assert e.value.parameter == "stop_period"


def test_periodic_both_ways_is_the_two_one_sided_runs() -> None:
    """From a row of the merged R-R branch at Omega ~1.7: upwards it meets the branch
    point and the fold and turns back; downwards it runs to the range's edge."""
    up_branch = rr_up()
    k = int(np.argmin(np.abs(up_branch.table["Omega"].to_numpy() - 1.7)))
    start = up_branch.solutions[k]
    kw = dict(range=(1.6, 1.9), options=STEPS)
    both = periodic_branch(start, "Omega", direction="both", **kw)  # type: ignore[arg-type]
    down = periodic_branch(start, "Omega", direction="backward", **kw)  # type: ignore[arg-type]
    up = periodic_branch(start, "Omega", direction="forward", **kw)  # type: ignore[arg-type]
    om = both.table["Omega"].to_numpy()
    assert om[0] == 1.6 and om.max() > 1.8 and om.min() == 1.6
    assert {"branch_point", "fold"} <= set(both.events["type"])
    assert both.table.height == down.table.height + up.table.height - 1
    assert both.stop == f"{down.stop}/{up.stop}"
    # the events: the backward run's in reverse, then the forward run's
    want = list(reversed(list(zip(down.events["type"], down.events["Omega"], strict=True))))
    want += list(zip(up.events["type"], up.events["Omega"], strict=True))
    got = list(zip(both.events["type"], both.events["Omega"], strict=True))
    assert [g[0] for g in got] == [w[0] for w in want]
    assert np.allclose([g[1] for g in got], [w[1] for w in want], atol=1e-9, rtol=0)
    # every event but a fold (the parameter's extremum) lies between its neighbouring rows
    for e in both.events.filter(both.events["type"] != "fold").iter_rows(named=True):
        i = int(e["index"])
        assert min(om[i - 1], om[i]) - 1e-12 <= e["Omega"] <= max(om[i - 1], om[i]) + 1e-12


def test_bad_controls_name_the_parameter() -> None:
    start = rr_start()
    cases = [
        (dict(at=[float("nan")]), "at"),
        (dict(at=[2.0]), "at"),  # outside the range
        (dict(at=[1.3] * 1001), "at"),
        (dict(at=[[1.3]]), "at"),
        (dict(stop="cusp"), "stop"),
        (dict(stop=["fold"] * 33), "stop"),
        (dict(stop=3), "stop"),
    ]
    for kw, name in cases:
        with pytest.raises((ParameterError, ballbal.exceptions.ParameterTypeError)) as e:
            periodic_branch(start, "Omega", range=(1.2, 1.9), **kw)  # type: ignore[arg-type]
        assert e.value.parameter == name, (kw, e.value)
        with pytest.raises((ParameterError, ballbal.exceptions.ParameterTypeError)) as e:
            equilibrium_branch(_together_model(), "eta", start="together", range=(0.2, 1.0),
                               **kw)  # type: ignore[arg-type]
        assert e.value.parameter == name, (kw, e.value)
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(_together_model(), "eta", start="together", range=(0.2, 1.0),
                           stop="period_doubling")
    assert e.value.parameter == "stop"
