"""Stable R-O motions in scans, and scans whose stable rows do not depend on the grid step.

Issue 31: simulation from random starts reached stable R-O orbits that the scans did not
list (5 of 16 periodic attractors in one census, all R-O), and whether R-O appeared
depended on the grid step (23 stable R-O rows at Omega step 0.1, none at 0.05, or the
reverse). Starts at rest reach these orbits only from a sliver of states: the rotating
ball turns in the ground frame just below the natural frequency, the disk whirling with
it at resonant amplitude. Scans now also simulate whirl starts of that shape.

The checks here are independent of ballbal's integrator and harmonic balance: the
shooting code of ``tests/shooting.py`` (DOP853 on ``tests/reference.py``) and, for the
grid-step test, the rows of two scans compared at their common points (the continuation
used to lose a branch where a step jumped to a neighbouring one at one grid step and
not at the other).
"""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest

import ballbal

from shooting import monodromy_multipliers, shoot

#: The census' point (seed 31, random point 32): a stable R-O with |mu| 0.757 (omega
#: 0.4721) that simulation from random starts reached and the three-pattern scans missed.
CENSUS_RO = ballbal.Balancer(mu=0.243, zeta=0.0497, zeta_b=0.1378, delta=15.927,
                             Omega=1.4647, eta=(0.9629, 1.3147))


def _stable(df: pl.DataFrame, pattern: str) -> pl.DataFrame:
    return df.filter((pl.col("type") == pattern) & (pl.col("stability") == "stable"))


def test_a_one_point_scan_lists_the_census_r_o_orbit() -> None:
    b = CENSUS_RO
    df = ballbal.scan(b, Omega=[b.Omega], patterns=["R-R", "O-O", "R-O", "O-R"])
    rows = _stable(df, "R-O")
    assert rows.height == 1, df.select("type", "omega", "stability")
    row = rows.row(0, named=True)
    # The orbit shot independently from periodic()'s orbit of that frequency.
    sol = ballbal.periodic(b, "R-O", N=8)
    assert sol.converged and abs(sol.omega - row["omega"]) < 1e-4
    y0, T = shoot(b, sol.state(0.0), sol.period, [0, 0, -1, 0], 2)
    omega = 2 * np.pi / T
    ev = monodromy_multipliers(b, y0, T)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, trivial))))
    assert abs(ev[trivial] - 1.0) < 1e-4
    # Stable by a wide margin, as the census measured (0.757), and the row's verdict
    # bound and frequency bound hold.
    assert lead < 0.8
    assert abs(row["max_modulus"] - lead) <= row["modulus_error"] + 1e-4
    assert abs(row["omega"] - omega) <= row["omega_error"] + 1e-8


def test_periodic_finds_the_stable_r_o_that_no_start_at_rest_reaches() -> None:
    # mu 0.2, zeta 0.02, zeta_b 0.1, delta 50 (the first map), Omega 1.4, eta 1.4:
    # every start at rest settles on the perfect balance or an R-R; periodic() used to
    # answer no_guess. Its orbit is checked by shooting, which must close on it.
    b = ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.1, delta=50, Omega=1.4, eta=(1.4, 1.4))
    sol = ballbal.periodic(b, "R-O")
    assert sol.converged and sol.stability == "stable", (sol.status, sol.stability)
    y0, T = shoot(b, sol.state(0.0), sol.period, [0, 0, -1, 0], 2)
    assert abs(2 * np.pi / T - sol.omega) <= sol.omega_error + 1e-8
    # The ball whirls at the natural frequency in the ground frame: Omega - omega near 1.
    assert abs(b.Omega - sol.omega - 1.0) < 0.02


GRIDS = {
    # The first map: at Omega step 0.1 no R-O at all, at 0.05 a stable region.
    "issue_map": (ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.1, delta=50),
                  (0.8, 2.0), (0.4, 1.6, 0.2)),
    # Tien's (2011) map with the most R-O (zeta 0.02, zeta_b 0.05).
    "omega_eta_map": (ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.05, delta=50),
                   (1.0, 2.0), (0.4, 1.5, 0.1)),
    # Unequal balls, Omega only: at step 0.05 the continuation from 1.8 down to 1.75
    # jumped to the stable R-R branch and never came back up it, so that the stable
    # R-R rows at 1.8-2.0 were listed at step 0.1 only.
    "unequal_line": (ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.05, delta=50,
                                      eta=(0.9, 1.1)), (1.0, 2.0), None),
}


@pytest.mark.parametrize("name", sorted(GRIDS))
def test_stable_rows_do_not_depend_on_the_grid_step(name: str) -> None:
    b, (lo, hi), eta = GRIDS[name]
    pats = ["R-R", "O-O", "R-O"] if eta is not None else ["R-R", "O-O", "R-O", "O-R"]
    axes = {} if eta is None else {"eta": eta}
    coarse = ballbal.scan(b, patterns=pats, Omega=(lo, hi, 0.1), **axes)
    fine = ballbal.scan(b, patterns=pats, Omega=(lo, hi, 0.05), **axes)

    def stable_sets(df: pl.DataFrame) -> dict[tuple, list[tuple[str, float]]]:
        out: dict[tuple, list[tuple[str, float]]] = {}
        for r in df.filter(pl.col("stability") == "stable").iter_rows(named=True):
            key = (round(r["Omega"], 6), round(r.get("eta", 0.0), 6))
            out.setdefault(key, []).append((r["type"], r["omega"]))
        return out

    a = stable_sets(coarse)
    c = {k: v for k, v in stable_sets(fine).items()
         if k[0] in {round(x, 6) for x in coarse["Omega"].to_list()}}

    def same(x: list, y: list) -> bool:
        return len(x) == len(y) and all(
            any(t == u and abs(w - v) < 1e-6 * max(1.0, w) for u, v in y) for t, w in x)

    differ = [k for k in set(a) | set(c) if not same(a.get(k, []), c.get(k, []))]
    assert not differ, [(k, a.get(k), c.get(k)) for k in sorted(differ)[:5]]
    if eta is None:
        # The stable R-R rows the finer grid lost.
        for om in (1.8, 1.9, 2.0):
            assert any(t == "R-R" for t, _ in c.get((om, 0.0), [])), om
        return
    # Both grids list a stable R-O region (the map had none at step 0.1), which
    # holds the orbit shot above at Omega 1.4, eta 1.4 in the map.
    assert sum(t == "R-O" for v in a.values() for t, _ in v) >= 10
    if name == "issue_map":
        assert any(t == "R-O" for t, _ in a.get((1.4, 1.4), []))


#: A narrow stable R-R band in a 1-D speed scan: from below Omega 1.0 up to about 1.149,
#: where the merged orbit's separation multiplier reaches +1. The perfect balance is
#: unstable below Omega about 1.09. At step 0.01 no seed point lay in the band and the
#: scan listed no stable R-R; at step 0.02 a seed point did and it listed eight.
NARROW = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.16, delta=50.0, Omega=1.05,
                          eta=(0.66, 0.66))


def test_a_narrow_band_is_listed_at_every_grid_step() -> None:
    hb8 = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))
    sol = ballbal.periodic(NARROW, "R-R", options=hb8)
    assert sol.converged
    # The orbit at Omega 1.05 shot independently: a real orbit, stable by a wide margin.
    y0, T = shoot(NARROW, sol.state(0.0), sol.period, [0, 0, -1, -1], 2)
    ev = monodromy_multipliers(NARROW, y0, T)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    assert abs(ev[trivial] - 1.0) < 1e-4
    assert float(np.max(np.abs(np.delete(ev, trivial)))) < 0.5
    for step in (0.01, 0.02, 0.05):
        df = ballbal.scan(NARROW, Omega=(1.0, 2.2, step), patterns=["R-R"])
        rows = _stable(df, "R-R")
        listed = set(np.round(rows["Omega"].to_numpy(), 9))
        band = set(np.round(np.arange(1.0, 1.14 + 1e-9, step), 9))
        assert band <= listed, (step, sorted(band - listed))
        at = rows.filter((pl.col("Omega") - 1.05).abs() < 1e-9)
        if at.height:
            assert abs(float(at["omega"][0]) - 2 * np.pi / T) < 1e-3


def test_stable_rows_do_not_depend_on_the_block() -> None:
    """Continuation does not cross block edges, so a block's rows come only from its own
    seeds and gap seeds. In blocks of 3 eta values this map listed 13 fewer stable R-O
    rows (a band at Omega 1.3-1.5, eta 0.4-0.6) and one more stable R-R (a slow orbit at
    Omega 0.95, eta 1.6, one grid step from the end of the R-R rows) than in one block.
    The R-O band's orbit at Omega 1.4, eta 0.5 is shot independently: its frequency
    within the row's bound, stable by the shot monodromy."""
    b = ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.05, delta=50)
    grid = {"Omega": (0.8, 2.0, 0.05), "eta": (0.4, 1.6, 0.1)}
    pats = ["R-R", "R-O", "O-O"]
    whole = ballbal.scan(b, patterns=pats, **grid)
    blocks = ballbal.scan(b, patterns=pats, options=ballbal.ScanOptions(block=3), **grid)

    def stable(df: pl.DataFrame) -> list[tuple[float, float, str, float]]:
        return sorted((round(r["Omega"], 6), round(r["eta"], 6), r["type"], r["omega"])
                      for r in df.filter(pl.col("stability") == "stable").iter_rows(named=True))

    a, c = stable(whole), stable(blocks)
    keys_a, keys_c = [x[:3] for x in a], [x[:3] for x in c]
    assert keys_a == keys_c, (sorted(set(keys_a) - set(keys_c))[:5],
                              sorted(set(keys_c) - set(keys_a))[:5])
    assert all(abs(x[3] - y[3]) < 1e-6 for x, y in zip(a, c, strict=True))

    row = _stable(whole, "R-O").filter(((pl.col("Omega") - 1.4).abs() < 1e-9)
                                       & ((pl.col("eta") - 0.5).abs() < 1e-9))
    assert row.height == 1
    r = row.row(0, named=True)
    m = b.replace(Omega=1.4, eta=(0.5, 0.5))
    sol = ballbal.periodic(m, "R-O", N=8)
    assert sol.converged and abs(sol.omega - r["omega"]) < 1e-3
    y0, T = shoot(m, sol.state(0.0), sol.period, [0, 0, -1, 0], 2)
    ev = monodromy_multipliers(m, y0, T)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, trivial))))
    assert abs(ev[trivial] - 1.0) < 1e-4 and lead < 1.0
    assert abs(r["max_modulus"] - lead) <= r["modulus_error"] + 1e-4
    assert abs(r["omega"] - 2 * np.pi / T) <= r["omega_error"] + 1e-8
