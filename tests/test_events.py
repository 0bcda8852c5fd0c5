"""One event vocabulary for every branch, events selected by name, the same keywords on
every branch function, and step control that does not step over a close pair of Hopf
points. Values are checked against computations written here: the perfect balance's
eigenvalues from its linearised equations (test_eq_continuation's matrices), bisected in
Omega, and the together branch's closed-form fold."""

from __future__ import annotations

from functools import cache

import numpy as np
import polars as pl
import pytest
from scipy.optimize import brentq
from test_eq_continuation import _pb_matrices, eta_fold

import ballbal
from ballbal.continuation import (
    Branch,
    Continuation,
    equilibrium_branch,
    equilibrium_curve,
    event_name,
    event_vocabulary,
    periodic_branch,
    periodic_curve,
    switch,
    switch_equilibrium,
)
from ballbal.exceptions import ParameterError

CANONICAL = ["fold", "branch_point", "hopf", "period_doubling", "neimark_sacker",
             "infinite_period", "user"]
OPTS = Continuation(ds=0.01, ds_max=0.05, max_points=400, tol=1e-12)


def test_one_vocabulary_with_autos_abbreviations_as_aliases() -> None:
    names = [n for n, _, _ in event_vocabulary()]
    assert names == CANONICAL
    for alias, name in [("LP", "fold"), ("lp", "fold"), ("BP", "branch_point"),
                        ("HB", "hopf"), ("Hopf", "hopf"), ("PD", "period_doubling"),
                        ("NS", "neimark_sacker"), ("TR", "neimark_sacker"),
                        ("Neimark-Sacker", "neimark_sacker"), ("IP", "infinite_period"),
                        ("UZ", "user")]:
        assert event_name(alias) == name, alias
    with pytest.raises(ParameterError) as e:
        event_name("cusp", "kind")
    assert e.value.parameter == "kind" and e.value.allowed == ", ".join(CANONICAL)


@cache
def together_branch() -> Branch:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.05, eta=(0.3, 0.3))
    return equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS)


@cache
def merged_rr() -> Branch:
    """The merged R-R branch in Omega whose branch point (~1.7993) and fold (~1.8084)
    (test_po_continuation's, at N = 4) lie close together."""
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2, eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", N=4)
    return periodic_branch(start, "Omega", range=(1.2, 3.0),
                           options=Continuation(ds=0.02, ds_max=0.05, max_points=140))


def test_every_branch_table_writes_the_canonical_names() -> None:
    eq = together_branch()
    po = merged_rr()
    for br in (eq, po):
        types = br.events["type"].to_list()
        assert types and set(types) <= set(CANONICAL), types
        marks = {m for cell in br.table["event"].drop_nulls().to_list()
                 for m in cell.split(",") if m}
        assert marks == set(types), (marks, types)
    assert set(po.events["type"]) == {"branch_point", "fold"}
    for col in ("test_fold", "test_branch_point", "test_period_doubling",
                "test_neimark_sacker"):
        assert col in po.table.columns, po.table.columns


def test_a_curve_is_chosen_by_its_event_name() -> None:
    br = together_branch()
    # by name, the fold's saddle-node curve: the closed form, whatever the fold's row
    c = equilibrium_curve(br, "fold", "Omega", range=(0.9, 1.2), options=OPTS)
    om = c.table["Omega"].to_numpy()
    assert c.table.height > 10 and om.min() < 1.0 < om.max()
    err = np.abs(c.table["eta"].to_numpy() - eta_fold(om, 0.05)).max()
    assert err < 1e-9, err
    # an alias reads the same; a kind the branch lacks lists its events
    c2 = equilibrium_curve(br, "LP", "Omega", range=(0.9, 1.2), options=OPTS)
    assert c2.table.height == c.table.height
    with pytest.raises(ParameterError) as e:
        equilibrium_curve(br, "period_doubling", "Omega", range=(0.9, 1.2))
    assert e.value.parameter == "event" and "its events:" in str(e.value)
    assert "fold" in str(e.value) and "branch_point" in str(e.value)
    # switching at a branch point by name, and refusing a fold by name
    pb = switch_equilibrium(br, "branch_point")
    assert "perfect_balance" in pb.table["kind"].to_list()
    with pytest.raises(ParameterError) as e:
        switch_equilibrium(br, "fold")
    assert e.value.parameter == "event"


def test_a_periodic_curve_is_chosen_by_its_event_name() -> None:
    br = merged_rr()
    with pytest.raises(ParameterError) as e:
        periodic_curve(br, "period_doubling", "eta", range=(0.9, 1.1))
    assert e.value.parameter == "event" and "its events:" in str(e.value)
    c = periodic_curve(br, "BP", "eta", range=(0.98, 1.02),
                       options=Continuation(ds=0.01, ds_max=0.02, max_points=6))
    assert c.kind == "branch_point"
    i = br.events["type"].to_list().index("branch_point")
    at = int(np.argmin(np.abs(c.table["eta"].to_numpy() - 1.0)))
    assert c.table["Omega"][at] == pytest.approx(br.events["Omega"][i], abs=1e-6)


def _pb_max_real(om: float, eta: float) -> float:
    M, C, K = _pb_matrices(om, eta, 0.2, 0.05, 0.1, 50.0)
    A = np.block([[np.zeros((4, 4)), np.eye(4)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return float(np.linalg.eigvals(A).real.max())


def _pb_hopf_points(eta: float, lo: float, hi: float) -> list[float]:
    """The Omega where the perfect balance's largest real part changes sign, bracketed
    on a fine grid and bisected (its eigenvalues from the linearised equations)."""
    grid = np.linspace(lo, hi, 2001)
    r = np.array([_pb_max_real(o, eta) for o in grid])
    out = []
    for k in np.nonzero(np.sign(r[1:]) != np.sign(r[:-1]))[0]:
        out.append(brentq(_pb_max_real, grid[k], grid[k + 1], args=(eta,), xtol=1e-13))
    return out


def test_default_step_finds_the_close_pair_of_hopf_points() -> None:
    # eta 0.505: the perfect balance loses stability on (1.0543, 1.0758) only, between
    # two Hopf points 0.0215 apart; with the default ds_max 0.05 a step used to span them.
    eta = 0.505
    exact = _pb_hopf_points(eta, 0.95, 1.2)
    assert len(exact) == 3, exact
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=0.9, eta=(eta, eta))
    br = equilibrium_branch(b, "Omega", start="perfect_balance", range=(0.8, 1.5))
    h = br.events.filter(br.events["type"] == "hopf")
    assert h.height == 3, br.events
    np.testing.assert_allclose(h["Omega"].to_numpy(), exact, atol=1e-7)
    # the unstable window has rows, and they say so
    om = br.table["Omega"].to_numpy()
    inside = (om > exact[1]) & (om < exact[2])
    assert inside.any()
    assert (br.table.filter(pl.Series(inside))["stability"] == "unstable").all()
    # the other directions see them too
    both = equilibrium_branch(b.replace(Omega=1.2), "Omega", start="perfect_balance",
                              range=(0.8, 1.5), direction="both")
    hb = both.events.filter(both.events["type"] == "hopf")["Omega"].to_numpy()
    np.testing.assert_allclose(np.sort(hb), exact, atol=1e-7)


def test_a_zero_eigenvalue_at_the_start_is_named() -> None:
    # eta = 1/2: the balls meet opposite the imbalance, a zero eigenvalue of the
    # perfect balance at every speed.
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.2, eta=(0.5, 0.5))
    with pytest.raises(ParameterError) as e:
        equilibrium_branch(b, "Omega", start="perfect_balance", range=(1.0, 1.5))
    assert e.value.parameter == "start" and "singular" in str(e.value), e.value


def test_switch_takes_an_equilibrium_branchs_own_hopf_point() -> None:
    eta = 0.505
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=0.9, eta=(eta, eta))
    br = equilibrium_branch(b, "Omega", start="perfect_balance", range=(0.8, 1.2))
    by_name = switch(br, event="hopf", amplitude=0.02, N=4)
    by_row = switch(br, event=0, amplitude=0.02, N=4)
    first = _pb_hopf_points(eta, 0.95, 1.2)[0]
    for r in (by_name, by_row):
        assert r.info["switched_from"] == "hopf" and r.info["parameter"] == "Omega"
        # born at the Hopf point: near it, at the critical pair's frequency
        assert abs(r.info["value"] - first) < 0.01
        M, C, K = _pb_matrices(first, eta, 0.2, 0.05, 0.1, 50.0)
        A = np.block([[np.zeros((4, 4)), np.eye(4)],
                      [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
        ev = np.linalg.eigvals(A)
        crit = abs(ev[np.argmin(np.abs(ev.real))].imag)
        assert abs(r.omega - crit) < 0.05 * crit, (r.omega, crit)
    with pytest.raises(ParameterError) as e:
        switch(br, event="period_doubling")
    assert e.value.parameter == "event" and "hopf" in str(e.value)
    with pytest.raises(ParameterError) as e:
        switch(br)
    assert e.value.parameter == "event" and "its events:" in str(e.value)


def test_periodic_branch_both_ways_covers_both_sides() -> None:
    ref = merged_rr()
    t = ref.table
    bp, fold = (float(ref.events.filter(ref.events["type"] == k)["Omega"][0])
                for k in ("branch_point", "fold"))
    # a start between the branch point (below) and the fold (above)
    k = next(i for i, om in enumerate(t["Omega"].to_list()) if bp < om < fold)
    start, om0 = ref.solutions[k], float(t["Omega"][k])
    opts = Continuation(ds=0.02, ds_max=0.05, max_points=30)
    up = periodic_branch(start, "Omega", range=(1.6, 2.0), options=opts, direction="forward")
    down = periodic_branch(start, "Omega", range=(1.6, 2.0), options=opts,
                           direction="backward")
    both = periodic_branch(start, "Omega", range=(1.6, 2.0), options=opts, direction="both")
    assert "branch_point" not in up.events["type"].to_list()
    assert "fold" not in down.events["type"].to_list()
    assert both.stop.count("/") == 1
    om = both.table["Omega"].to_numpy()
    assert om.min() < bp < om0 < fold and (om == om0).sum() == 1
    assert both.table.height == up.table.height + down.table.height - 1
    j = int(np.nonzero(om == om0)[0][0])
    np.testing.assert_allclose(om[j::-1], down.table["Omega"].to_numpy(), atol=0)
    np.testing.assert_allclose(om[j:], up.table["Omega"].to_numpy(), atol=0)
    ev = both.events
    assert ev["type"].to_list()[:2] == ["branch_point", "fold"], ev
    assert abs(ev["Omega"][0] - bp) < 1e-6 and abs(ev["Omega"][1] - fold) < 1e-6
    # every event is named in its row's event column and lies between the row before
    # it and its row (a fold, where Omega turns back, beyond both)
    for typ, p, i in ev.select("type", "Omega", "index").rows():
        lo, hi = sorted((om[i - 1], om[i]))
        assert typ in both.table["event"][i]
        assert lo - 1e-9 <= p <= hi + 1e-9 if typ != "fold" else p >= hi
    # oriented along the rows: Omega grows from the lower end up to the fold
    i_fold = int(ev["index"][1])
    assert (both.table["dp_ds"].to_numpy()[:i_fold] > 0).all()
    with pytest.raises(ParameterError) as e:
        periodic_branch(start, "Omega", range=(1.6, 2.0), direction="up")  # type: ignore[arg-type]
    assert e.value.parameter == "direction"
