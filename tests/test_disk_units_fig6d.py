"""Seed 003's figure 6(d) (omega0 0.6, m0 4, e 2): the perfect balance is stable.

The seed draws a radial vibration that never settles; its own equations (as eq. (3)
gives them, ``tests/disk_units_equations.py``) make the perfect balance stable there. The
characteristic polynomial is built here from those equations (central differences, a
determinant sampled on a circle), judged by Routh–Hurwitz, and its roots compared with
ballbal's eigenvalues in the seed's time unit; a DOP853 run from the seed's start settles
on the balance. The printed eq. (8)'s phi2-row sign (``-2 Omega x'``) instead makes the
balance unstable, but breaks fig. 6(c), which the derived equations reproduce to the
printed digits (docs/source_documents.md weighs the readings).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

import ballbal
from ballbal.model import from_disk_units

import disk_units_equations as s3

W0, M0, E, C0, D0 = 0.6, 4.0, 2.0, 0.35, 0.35


def test_perfect_balance_is_stable_by_routh_hurwitz_and_matches_ballbal() -> None:
    q0 = s3.perfect_balance(M0, E)
    p = s3.char_poly(*s3.linearised(q0, W0, M0, E, C0, D0))
    assert s3.hurwitz_stable(p)
    roots = np.sort_complex(np.roots(p))
    # a margin far above round-off: the slowest pair decays at about -0.0187
    assert -0.03 < roots.real.max() < -0.01, roots
    eq = next(q for q in ballbal.equilibria(from_disk_units(W0, M0, E, C0, D0))
              if q.kind == "perfect_balance")
    assert eq.stability == "stable" and eq.routh_hurwitz is True
    # ballbal's time unit is omega_n of disk and balls, sqrt(1 + 2 m0) times slower
    theirs = np.sort_complex(np.asarray(eq.eigenvalues) / math.sqrt(1 + 2 * M0))
    assert theirs.shape == roots.shape
    assert np.abs(theirs - roots).max() < 1e-6 * np.abs(roots).max()


def test_the_printed_phi2_row_makes_it_unstable() -> None:
    q0 = s3.perfect_balance(M0, E)
    p = s3.char_poly(*s3.linearised(q0, W0, M0, E, C0, D0, sign_phi2=-1.0))
    assert not s3.hurwitz_stable(p)
    assert np.roots(p).real.max() > 0.005


def test_run_from_the_seeds_start_settles_on_the_balance() -> None:
    z0 = [0.0, 0.0, math.pi / 2, -math.pi / 2, 0, 0, 0, 0]
    sol = solve_ivp(s3.rotating_rhs(W0, M0, E, C0, D0), (0.0, 500.0), z0, method="DOP853",
                    rtol=1e-9, atol=1e-11, t_eval=[0.0, 250.0, 500.0])
    assert sol.status == 0
    q = sol.y[:4, -1]
    bal = s3.perfect_balance(M0, E)
    # the slowest mode decays like exp(-0.0187 t): 1e-4 of the start's 2 by t = 500
    assert math.hypot(q[0], q[1]) < 1e-3
    assert abs(abs(q[2]) - bal[2]) < 1e-2 and abs(q[2] + q[3]) < 1e-2


def test_fig6c_settles_at_the_printed_radius() -> None:
    """Fig. 6(c) (omega0 4, m0 0.5): the balls together, radial vibration 0.02577 as
    printed, which is metres: r in units of R = 0.05 m (table 1). The radius from the
    seed's closed form eq. (11), from ballbal's stable 'together' state and from a run of
    the seed's equations agree, and with the printed value to its four digits."""
    w, m0, e, c0 = 4.0, 0.5, 2.0, 0.35
    a = 1 - w * w * (1 + 2 * m0)
    d = a * a + (2 * c0 * w) ** 2
    p = math.acos(-4 * m0 * w * c0 / (e * math.sqrt(d))) - math.atan(a / (2 * c0 * w))
    x = (a * w * w * (2 * m0 * math.cos(p) + e) + 4 * m0 * w**3 * c0 * math.sin(p)) / d
    y = (2 * a * m0 * w * w * math.sin(p) - 2 * w**3 * c0 * (2 * m0 * math.cos(p) + e)) / d
    r = math.hypot(x, y)
    assert abs(r * 0.05 - 0.02577) < 1e-3 * 0.02577
    stable = [q for q in ballbal.equilibria(from_disk_units(w, m0, e, c0, D0))
              if q.stability == "stable"]
    assert len(stable) == 1 and stable[0].kind == "together"
    # ballbal's lengths are over the eccentricity eps = e R
    assert abs(math.hypot(*stable[0].q[:2]) * e - r) < 1e-8
    z0 = [0.0, 0.0, math.pi / 2, -math.pi / 2, 0, 0, 0, 0]
    sol = solve_ivp(s3.rotating_rhs(w, m0, e, c0, D0), (0.0, 300.0), z0, method="DOP853",
                    rtol=1e-9, atol=1e-11, t_eval=[300.0])
    assert abs(math.hypot(sol.y[0, -1], sol.y[1, -1]) - r) < 1e-6
