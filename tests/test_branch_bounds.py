"""Verdicts along periodic branches bounded as ``periodic()``'s are (issue 31), at the
branch's own N, against the independent shooting and variational equations of
tests/test_verdict_bound.py.

The family is the issue's (mu 0.25, zeta 0.08, zeta_b 0.02, delta 20, eta 1 and 1): its
merged R-R orbit continued in Omega at N = 3 loses a multiplier through -1 (period
doubling) near Omega 1.3584. At the issue's Omega 1.3584277344, N = 3 gives the leading
modulus 0.99998 where the orbit is unstable (1.0000036 by shooting): a branch point there
used to be called stable, judged by the trivial multiplier's error (5e-6) alone.
"""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
from test_verdict_bound import _multipliers, _truth

import ballbal
from ballbal.continuation import Continuation, periodic_branch, switch

from shooting import shoot

ISSUE = ballbal.Balancer(mu=0.25, zeta=0.08, zeta_b=0.02, delta=20, eta=(1.0, 1.0),
                         Omega=1.3584277344)
DECIDED = ("stable", "unstable")


def _truth_at(sol: ballbal.PeriodicSolution) -> float:
    """The leading non-trivial modulus of the orbit at the row's parameters, by shooting
    from the N = 12 series there; its own error (the trivial multiplier's) must be far
    below the modulus' distance from 1. Where the row has a frequency bound, the shot
    frequency lies within it."""
    ref = ballbal.periodic(sol.balancer, "R-R", N=12, guess=sol)
    assert ref.converged
    lead, accuracy, omega = _truth(sol.balancer, "R-R", ref, 2, with_omega=True)
    assert accuracy < 0.05 * abs(lead - 1.0), (sol.balancer.Omega, lead, accuracy)
    if sol.omega_error is not None:
        assert abs(sol.omega - omega) <= sol.omega_error, (sol.omega, omega, sol.omega_error)
    return lead


def _check_rows(br: ballbal.continuation.Branch) -> None:
    """Every verdict has a finite bound smaller than its modulus' distance from 1, from
    the series with 5 harmonics; every row stays at N = 3."""
    t = br.table
    for k, r in enumerate(t.iter_rows(named=True)):
        assert br.solutions[k].N == 3
        if r["stability"] in DECIDED:
            e = r["modulus_error"]
            assert e is not None and np.isfinite(e), r
            assert e < abs(r["max_modulus"] - 1.0), r
            assert r["modulus_error_source"] == "N 3 vs 5", r
            assert br.solutions[k].modulus_error == e
            assert r["omega_error"] is not None and np.isfinite(r["omega_error"]), r


@cache
def across_the_period_doubling() -> ballbal.continuation.Branch:
    s = ballbal.periodic(replace(ISSUE, Omega=1.30), "R-R", N=3,
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(refine=False)))
    return periodic_branch(s, "Omega", range=(1.30, 1.42),
                           options=Continuation(ds=0.02, ds_max=0.02, max_points=80))


def test_verdicts_across_a_period_doubling_are_bounded_and_right() -> None:
    br = across_the_period_doubling()
    t = br.table
    assert br.events["type"].to_list() == ["period_doubling"], br.events
    assert set(t["stability"].to_list()) >= set(DECIDED)
    _check_rows(br)
    # The decided rows on either side of the event, and the branch's two ends.
    k = int(br.events["index"][0])
    rows = sorted({0, k - 1, k, t.height - 1})
    for i in rows:
        r = t.row(i, named=True)
        assert r["stability"] in DECIDED, r
        lead = _truth_at(br.solutions[i])
        assert r["stability"] == ("stable" if lead < 1.0 else "unstable"), (r, lead)
        assert abs(r["max_modulus"] - lead) <= r["modulus_error"], (r, lead)


def test_the_issues_point_on_a_branch_is_unstable_or_undetermined() -> None:
    """A branch started at the issue's Omega and continued down into the unstable side,
    its points within 1e-4 of the crossing: each verdict is the shooting's or
    undetermined, and where a bound was computed it holds."""
    s = ballbal.periodic(ISSUE, "R-R", N=3,
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(refine=False)))
    br = periodic_branch(s, "Omega", range=(1.3584, ISSUE.Omega),
                         options=Continuation(ds=1e-5, ds_max=1e-5, forward=False,
                                              max_points=4))
    t = br.table
    assert t.height == 4 and t["Omega"][0] == ISSUE.Omega
    _check_rows(br)
    for i, r in enumerate(t.iter_rows(named=True)):
        lead = _truth_at(br.solutions[i])
        assert abs(lead - 1.0) < 1e-3, (r, lead)
        truth = "stable" if lead < 1.0 else "unstable"
        assert r["stability"] in (truth, "undetermined"), (r, lead)
        if r["modulus_error"] is not None:
            assert abs(r["max_modulus"] - lead) <= r["modulus_error"], (r, lead)
    # The issue's point itself: unstable by shooting, 0.99998 at N = 3.
    first = t.row(0, named=True)
    assert first["max_modulus"] < 1.0 and first["stability"] == "undetermined", first


def test_a_switched_orbit_keeps_its_harmonics_and_bounds_its_verdict() -> None:
    """The doubled orbit switched to from the branch's period doubling has twice the
    branch's harmonics, not more, and a verdict judged against a bound from a finer
    series: the shooting's (the orbit is unstable, |mu| - 1 about 8e-3 at N = 6)."""
    br = across_the_period_doubling()
    d2 = switch(br, event=0, amplitude=0.1)
    assert d2.converged and list(d2.winding[2:]) == [-2, -2]
    assert d2.N == 6
    assert d2.modulus_error is not None and d2.modulus_error_source == "N 6 vs 9"
    assert d2.modulus_error < abs(d2.max_modulus - 1.0)
    y0, T = shoot(d2.balancer, d2.state(0.0), d2.period, [0, 0, -2, -2], 2)
    ev = _multipliers(d2.balancer, y0, T)
    k = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, k))))
    assert abs(ev[k] - 1.0) < 0.05 * abs(lead - 1.0), (ev[k], lead)
    assert d2.stability == ("stable" if lead < 1.0 else "unstable"), (d2.stability, lead)
    assert abs(d2.max_modulus - lead) <= d2.modulus_error, (d2.max_modulus, lead)
