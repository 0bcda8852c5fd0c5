"""Scans of orbits that wind more than once per period (issue 31).

A scan type may carry the balls' windings, ``"R-R[-2,-2]"``: each ball makes two turns
per period, as Tien's (2011) "balls rotating separately" do at Omega 1.2 (their turns
alternate between two durations). Scans never listed these; a seed whose turns did not
repeat one by one gave nothing.

The checks are independent of ballbal's integrator and harmonic balance: the orbit is
shot by ``tests/shooting.py`` (DOP853 on ``tests/reference.py``), its multipliers from
finite differences of that flow.
"""

from __future__ import annotations

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ParameterError

from shooting import flow, monodromy_multipliers, shoot

#: Figure 4-15's point: balls started apart rotate separately, two turns per period.
SEPARATED = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2,
                             eta=(0.7, 0.7))


def _rows(df: pl.DataFrame, kind: str) -> pl.DataFrame:
    return df.filter((pl.col("type") == kind) & (pl.col("status") == "converged"))


@pytest.fixture(scope="module")
def shot() -> tuple[np.ndarray, float, np.ndarray]:
    """The separated orbit shot independently, from periodic()'s (-2, -2) orbit."""
    b = SEPARATED
    sol = ballbal.periodic(b, "R-R", windings=(-2, -2))
    assert sol.converged
    y0, T = shoot(b, sol.state(0.0), sol.period, [0, 0, -2, -2], 2)
    return y0, T, monodromy_multipliers(b, y0, T)


def test_a_scan_lists_the_separated_rotation_with_a_bounded_verdict(shot) -> None:
    y0, T, ev = shot
    b = SEPARATED
    # A genuine two-turn orbit, not the single-turn one written twice: half a period
    # later the state is far from its start (angles modulo a turn).
    half = flow(b, y0, T / 2)
    diff = half - y0
    diff[2:4] = (diff[2:4] + np.pi) % (2 * np.pi) - np.pi
    assert np.max(np.abs(diff)) > 0.1
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, trivial))))
    assert abs(ev[trivial] - 1.0) < 1e-4 and lead < 0.7

    df = ballbal.scan(b, Omega=[b.Omega], patterns=["R-R", "R-R[-2,-2]"])
    rows = _rows(df, "R-R[-2,-2]")
    assert rows.height == 1, df.select("type", "omega", "stability")
    row = rows.row(0, named=True)
    omega = 2 * np.pi / T
    assert abs(row["omega"] - omega) <= row["omega_error"] + 1e-8
    assert row["stability"] == "stable"
    assert abs(row["max_modulus"] - lead) <= row["modulus_error"] + 1e-4
    # Its frequency is not half the single-turn R-R orbit's at the point.
    for r in _rows(df, "R-R").iter_rows(named=True):
        assert abs(r["omega"] / 2 - row["omega"]) > 1e-3


def test_wound_types_add_rows_of_their_own_only() -> None:
    grid = {"Omega": (1.1, 1.3, 0.05), "eta": (0.6, 0.8, 0.1)}
    m = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50)
    plain = ballbal.scan(m, patterns=["R-R"], **grid)
    both = ballbal.scan(m, patterns=["R-R", "R-R[-2,-2]"], **grid)
    key = ["Omega", "eta", "solution"]
    a = plain.sort(key).select(*key, "status", "omega", "stability")
    b = both.filter(pl.col("type") == "R-R").sort(key).select(*key, "status", "omega",
                                                              "stability")
    assert a.select(*key, "status", "stability").equals(b.select(*key, "status",
                                                                  "stability"))
    assert np.allclose(a["omega"].fill_null(0).to_numpy(), b["omega"].fill_null(0).to_numpy(),
                       rtol=1e-9, atol=0)
    wound = _rows(both, "R-R[-2,-2]")
    # Figure 4-15's orbit is there, and every wound row is one (never the single orbit
    # twice over): no wound frequency is half a single-turn one at its point.
    assert wound.filter((pl.col("Omega") == 1.2) & (pl.col("eta") == 0.7)).height >= 1
    single = _rows(both, "R-R").select("Omega", "eta", pl.col("omega").alias("single"))
    joined = wound.join(single, on=["Omega", "eta"])
    assert (abs(joined["single"] / 2 - joined["omega"]) > 1e-4).all()


@pytest.mark.parametrize(("kind", "needle"), [
    ("R-R[-1,-1]", '"R-R"'),
    ("R-R[-2]", "one winding per ball"),
    ("R-R[-2,-2", "must end with ']'"),
    ("R-R[a,b]", "integers"),
    ("R-O[-2,-2]", "ball 2 is O"),
    ("R-R[-17,-17]", "16"),
    ("R-R[-3,-3]", "at most 2 turns"),
])
def test_bad_wound_types_are_refused(kind: str, needle: str) -> None:
    with pytest.raises(ParameterError, match="pattern|windings") as e:
        ballbal.scan(SEPARATED, Omega=[1.2], patterns=[kind])
    assert needle in f"{e.value} {e.value.allowed}"


def test_periodic_names_the_single_orbit_written_twice() -> None:
    # The single-turn R-R orbit at the point, written over two of its periods (harmonic
    # k becomes 2k, half the frequency): a solution of the (-2, -2) equations that is
    # not a period-doubled orbit. Newton started on it stays there, and periodic() says
    # so instead of calling it converged.
    b = SEPARATED
    single = ballbal.periodic(b, "R-R", N=3)
    assert single.converged
    c = single.coeffs
    doubled = np.zeros((c.shape[0], 2 * (c.shape[1] - 1) + 1))
    doubled[:, 0] = c[:, 0]
    for k in range(1, (c.shape[1] - 1) // 2 + 1):
        doubled[:, 4 * k - 1] = c[:, 2 * k - 1]
        doubled[:, 4 * k] = c[:, 2 * k]
    out = ballbal.periodic(b, "R-R", windings=(-2, -2), guess=(single.omega / 2, doubled),
                           N=6)
    assert out.status == "repeated"
    assert out.stability == "undetermined"


#: The census' random point 32 (seed 31): one start of 16 settled on a stable
#: period-doubled O-R orbit (O ball 1, ball 2 two turns per period) that no scan listed.
CENSUS_PD = ballbal.Balancer(mu=0.243, zeta=0.0497, zeta_b=0.1378, delta=15.927,
                             Omega=1.4647, eta=(0.9629, 1.3147))
#: That start's state after 8000 time units of the census' DOP853 simulation (rtol
#: 1e-10), at the section where it was judged settled; period about 2 pi / 0.243414.
CENSUS_PD_STATE = [1.33056099, -2.75394134, -10.4973164, -1200.08839, -1.18997956,
                   -0.760057006, -0.169119643, -0.515343085]


def test_period_doubled_orbits_are_seeded_from_the_orbits_they_double() -> None:
    b = CENSUS_PD
    y0, T = shoot(b, np.array(CENSUS_PD_STATE), 2 * np.pi / 0.243414, [0, 0, 0, -2], 3)
    ev = monodromy_multipliers(b, y0, T)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    lead = float(np.max(np.abs(np.delete(ev, trivial))))
    assert abs(ev[trivial] - 1.0) < 1e-4 and 0.85 < lead < 0.95
    grid = {"Omega": [b.Omega + d * 0.05 for d in (-2, -1, 0, 1, 2)],
            "eta1": [0.8629, 0.9629, 1.0629]}
    alone = ballbal.scan(b, grid=grid, patterns=["O-R[0,-2]"])
    both = ballbal.scan(b, grid=grid, patterns=["O-R", "O-R[0,-2]"])
    # The single-turn O-R orbits are solved either way (unreported when not asked
    # for), so the doubled type's rows are the same.
    key = ["Omega", "eta1", "solution"]
    a = alone.sort(key).select(*key, "status", "stability", "origin")
    c = both.filter(pl.col("type") == "O-R[0,-2]").sort(key).select(*key, "status",
                                                                    "stability", "origin")
    assert a.equals(c)
    at = _rows(alone, "O-R[0,-2]").filter((pl.col("Omega") == b.Omega)
                                           & (pl.col("eta1") == 0.9629))
    assert at.height == 1, alone.filter(pl.col("status") == "converged")
    row = at.row(0, named=True)
    assert row["origin"] == "period_doubling" and row["N"] == 6
    assert abs(row["omega"] - 2 * np.pi / T) <= row["omega_error"] + 1e-8
    assert row["stability"] == "stable"
    assert abs(row["max_modulus"] - lead) <= row["modulus_error"] + 1e-4
