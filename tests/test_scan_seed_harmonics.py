"""A seed whose orbit three harmonics cannot write is solved with more (issue 31).

Slow R-R orbits near a rotating branch's infinite-period end spend most of their period
creeping and then turn quickly; at N = 3 their series is truncated or fails the closure
certificate. On the fine R-R reference grid (mu 0.2, zeta 0.05, zeta_b 0.05, delta 50)
such orbits were the only attractor at three points, and the scan listed none there: at
Omega 1.1, eta 0.49 every one of 16 random starts (DOP853, outside ballbal) settled on an
R-R orbit of omega 0.057099.

The orbit is shot here by ``tests/shooting.py`` (DOP853 on ``tests/reference.py``), from
a state ballbal's own simulation reaches (only the start of the shooting comes from
ballbal).
"""

from __future__ import annotations

import numpy as np
import polars as pl

import ballbal

from shooting import monodromy_multipliers, shoot


def test_a_slow_orbit_is_listed_with_more_harmonics() -> None:
    om = 1.1
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=om,
                         eta=(0.49, 0.49))
    t = np.array([0.0, 3000.0])
    y = ballbal.simulate(b, [0, 0, 0.3, 0.5, 0, 0, -om, -om], t, rtol=1e-10, atol=1e-12)
    start = y.select("x", "y", "b1", "b2", "dx", "dy", "db1", "db2").to_numpy()[-1]
    y0, T = shoot(b, start, 2 * np.pi / 0.0571, [0, 0, -1, -1], 2)
    ev = monodromy_multipliers(b, y0, T)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, trivial))))
    assert abs(ev[trivial] - 1.0) < 1e-4 and lead < 0.5

    df = ballbal.scan(b, Omega=[om], eta=[0.49], N=3)
    rows = df.filter((pl.col("status") == "converged")
                     & ((pl.col("omega") - 2 * np.pi / T).abs() < 1e-3))
    assert rows.height == 1, df.select("omega", "stability", "N")
    row = rows.row(0, named=True)
    assert row["N"] > 3
    assert abs(row["omega"] - 2 * np.pi / T) <= row["omega_error"] + 1e-8
    assert row["stability"] == "stable"
    assert abs(row["max_modulus"] - lead) <= row["modulus_error"] + 1e-4


def test_a_rotation_slower_than_the_seed_window_is_listed() -> None:
    """Census point random-22: every random start settles on an R-R orbit of period
    about 3 530, which turns less than once in a seed's 2 000-unit window. The period is
    measured here from scipy's DOP853 on ``tests/reference.py`` (the times ball 1
    crosses whole turns after the transient), and the scan must list that orbit as
    stable, with its frequency within the row's own error bound. That simulation from
    a plain start settles on it (successive turns agree to 1e-4 by the third, the
    transient shrinking by about 1e-5 per turn) is the independent evidence that it
    attracts."""
    from scipy.integrate import solve_ivp

    from reference import rhs

    om = 0.7997
    b = ballbal.Balancer(mu=0.0715, zeta=0.1936, zeta_b=0.1706, delta=93.41, Omega=om,
                         eta=(1.057, 1.057))

    def turn(t: float, s: np.ndarray) -> float:
        return float(np.sin(s[2] / 2))

    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, 12000), [0, 0, 0.3, 1.0, 0, 0, -om, -om],
                  rtol=1e-7, atol=1e-9, method="DOP853", events=turn)
    turns = np.diff(r.t_events[0])
    assert turns.size >= 3 and abs(turns[-1] - turns[-2]) < 1e-4 * turns[-1], turns
    omega = 2 * np.pi / turns[-1]

    df = ballbal.scan(b, Omega=[om], eta=[1.057])
    rows = df.filter((pl.col("type") == "R-R") & (pl.col("status") == "converged"))
    assert rows.height == 1, df.select("type", "status", "omega")
    row = rows.row(0, named=True)
    assert abs(row["omega"] - omega) <= row["omega_error"] + 1e-9 * omega
    assert row["stability"] == "stable"
