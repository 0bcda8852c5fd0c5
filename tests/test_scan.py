import numpy as np
import polars as pl
import pytest

import ballbal

BASE = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2, eta=(1.0, 1.0))


@pytest.fixture(scope="module")
def small():
    return ballbal.scan(BASE, Omega=[1.15, 1.2, 1.25, 1.3], eta=[0.9, 1.0], threads=1)


def test_standard_point_equals_single_point_solver(small):
    row = small.filter((pl.col("Omega") == 1.2) & (pl.col("eta") == 1.0)).row(0, named=True)
    single = ballbal.periodic(BASE, "R-R", N=3, rtol=1e-6, atol=1e-9)
    assert row["status"] == "converged" and row["type"] == "R-R"
    assert abs(row["omega"] - single.omega) < 1e-10
    assert abs(row["max_modulus"] - single.max_modulus) < 1e-6
    mods = sorted((abs(complex(m["re"], m["im"])) for m in row["multipliers"]), reverse=True)
    assert np.allclose(mods, np.sort(np.abs(single.multipliers))[::-1], atol=1e-6)
    # and both equal the independent shooting value in the spec
    assert abs(row["omega"] - 0.25141) < 1e-4


def test_same_table_for_one_and_two_threads(small):
    two = ballbal.scan(BASE, Omega=[1.15, 1.2, 1.25, 1.3], eta=[0.9, 1.0], threads=2)
    assert small.drop("seconds").equals(two.drop("seconds"))


def test_omega_grows_with_Omega(small):
    for eta in (0.9, 1.0):
        w = small.filter(pl.col("eta") == eta).sort("Omega")["omega"].to_numpy()
        assert np.all(np.diff(w) > 0), w


def test_perfect_balance_columns():
    df = ballbal.scan(BASE, Omega=[1.5], eta=[0.45, 1.0], floquet=False, threads=1)
    pb = dict(zip(df["eta"], df["pb_exists"], strict=True))
    assert pb[0.45] is False and pb[1.0] is True


def test_unconverged_rows_are_null_not_nan():
    # perfect balance attracts every start here: no R-R found, a row with a status
    b = ballbal.Balancer(mu=0.2, zeta=0.1, zeta_b=0.1, delta=50, Omega=3.0, eta=(1.0, 1.0))
    df = ballbal.scan(b, Omega=[3.0], eta=[1.0], settle=300, window=500, threads=1)
    assert df["status"][0] == "no_solution"
    assert df["omega"].null_count() == 1 and df["omega"].is_nan().sum() == 0


@pytest.mark.parametrize(
    ("grid", "name"),
    [
        ({"Omega": [], "eta": [1.0]}, "Omega"),
        ({"Omega": [1.0, float("nan")], "eta": [1.0]}, "Omega"),
        ({"gravity": [1.0], "eta": [1.0]}, "gravity"),
        ({"Omega": [1.0]}, "grid"),
        ({"Omega": [-1.0], "eta": [1.0]}, "Omega"),
    ],
)
def test_bad_grids_raise_before_work(grid, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        ballbal.scan(BASE, **grid)
