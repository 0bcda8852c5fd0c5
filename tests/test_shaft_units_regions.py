"""Seed 004's (Rezaee et al. 2017) fig. 3 boundary in its own axes, found independently.

Fig. 3 is the classic two-ball balancer on a Jeffcott rotor (flat disk at mid-span),
which the paper says equals its reference [6]'s map; it prints no boundary values, so
the boundary is computed here from [6]'s equations in the disk's units
(``tests/disk_units_equations.py``, written without ballbal: ``m0 = m_bar``,
``e = eps_bar``, ``C0 = zeta_t / 2``,
``D0 = lam``, time over ``omega0``): the lowest ``omega_bar`` where Routh–Hurwitz calls
the perfect balance stable, by bisection. ``ShaftUnits``' scene must change its verdict
there, and ``balance_map``'s lowest stable grid point must be the first one above it.
"""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.shaft import ShaftUnits

import disk_units_equations as s3

M_BAR = EPS_BAR = 0.01
ZETA_T = 0.1


def rh_stable(omega_bar: float, lam: float) -> bool:
    q0 = s3.perfect_balance(M_BAR, EPS_BAR)
    return s3.hurwitz_stable(s3.char_poly(*s3.linearised(
        q0, omega_bar, M_BAR, EPS_BAR, ZETA_T / 2, lam)))


def lower_boundary(lam: float, lo: float = 1.0, hi: float = 1.5) -> float:
    assert not rh_stable(lo, lam) and rh_stable(hi, lam)
    while hi - lo > 1e-7:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if rh_stable(mid, lam) else (mid, hi)
    return 0.5 * (lo + hi)


def ballbal_stable(omega_bar: float, lam: float) -> bool:
    u = ShaftUnits(omega_bar=omega_bar, m_bar=M_BAR, eps_bar=EPS_BAR, lam=lam, zeta_t=ZETA_T)
    pb = [q for q in ballbal.equilibria(u.scene) if q.kind == "perfect_balance"]
    assert len(pb) == 1
    return pb[0].stability == "stable"


@pytest.mark.parametrize("lam", [0.05, 0.1, 0.2])
def test_fig3_lower_boundary_matches_routh_hurwitz(lam: float) -> None:
    w = lower_boundary(lam)
    # above the critical speed of disk and balls, 1 / sqrt(1 + 2 m_bar) = 0.990
    assert 1.0 < w < 1.5
    assert not ballbal_stable(w * (1 - 1e-3), lam)
    assert ballbal_stable(w * (1 + 1e-3), lam)


def test_fig3_balance_map_starts_at_the_boundary() -> None:
    lam = 0.1
    w = lower_boundary(lam)
    grid = np.linspace(0.2, 4.0, 77)  # steps of 0.05
    u = ShaftUnits(omega_bar=1.0, m_bar=M_BAR, eps_bar=EPS_BAR, lam=lam, zeta_t=ZETA_T)
    df = u.balance_map(grid, [lam])
    stable = df.filter(pl.col("stability") == "stable")["omega_bar"].to_numpy()
    first_above = grid[grid > w].min()
    assert abs(stable.min() - first_above) < 1e-9, (stable.min(), w)
    # and every grid point above it up to 4 is stable here, as in the paper's fig. 3
    assert np.allclose(np.sort(stable), grid[grid > w])
