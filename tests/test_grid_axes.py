"""One meaning of a grid axis (issue 32): ``(start, stop, step)`` is a range with ``stop``
included and the same floats in every gridded function; a list or array is explicit
values; every gridded table has an integer index per axis, so joins are exact."""

from __future__ import annotations

import sys

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ParameterError

B = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.2, eta=(1.0, 1.0))
scan_module = sys.modules["ballbal.scan"]


def test_a_range_is_the_same_in_balance_map_and_scan() -> None:
    # 0.8 to 2.0 by 0.02, stop included: 61 speeds (balance_map computed three before)
    m = ballbal.balance_map(B, Omega=(0.8, 2.0, 0.02))
    assert m.height == 61
    expected = [round(0.8 + 0.02 * i, 12) for i in range(61)]
    assert m["Omega"].to_list() == expected
    assert m["Omega_index"].to_list() == list(range(61))
    assert scan_module.grid_values("Omega", (0.8, 2.0, 0.02)).tolist() == expected
    # the same written as a string
    assert ballbal.balance_map(B, Omega="0.8:2.0:0.02")["Omega"].to_list() == expected


def test_a_join_of_balance_map_and_scan_keeps_every_row() -> None:
    axes = {"Omega": np.arange(1.0, 2.01, 0.1), "eta": (0.4, 0.8, 0.1)}
    m = ballbal.balance_map(B, **axes)
    s = ballbal.scan(B, **axes, patterns=["O-O"], N=3)
    assert m.height == 11 * 5
    points = s.select("Omega", "eta", "Omega_index", "eta_index").unique()
    assert points.height == 11 * 5
    # explicit values are kept as given (1.0 + 2 * 0.1 is 1.2000000000000002 in both)
    assert sorted(points["Omega"].unique().to_list()) == axes["Omega"].tolist()
    for keys in (["Omega", "eta"], ["Omega_index", "eta_index"]):
        joined = points.join(m, on=keys, how="inner")
        assert joined.height == 11 * 5, keys
    # the index is the value's position on the axis
    ok = points.with_columns(
        (pl.col("Omega") - (1.0 + 0.1 * pl.col("Omega_index"))).abs().alias("d"))
    assert ok["d"].max() < 1e-9


def test_speed_sweep_takes_a_range() -> None:
    from ballbal.sweep import speed_sweep

    r = speed_sweep(B, (1.0, 1.2, 0.1), dwell=50.0, direction="up", record=None)
    assert sorted({round(x, 12) for x in r.table["Omega"].to_list()}) == [1.0, 1.1, 1.2]


def test_a_value_given_twice_is_refused() -> None:
    with pytest.raises(ParameterError) as e:
        ballbal.balance_map(B, Omega=[1.0, 1.2, 1.0])
    assert e.value.parameter == "Omega"
