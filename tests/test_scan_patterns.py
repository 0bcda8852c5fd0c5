"""A pattern's rows in a scan do not depend on which other patterns were asked for.

Issue 31: ``scan(Balancer(mu=0.2, zeta=0.02, zeta_b=0.1, delta=50), Omega=(0.8, 2.0, 0.1),
eta=(0.4, 1.6, 0.2))`` listed 4 stable R-R rows with ``patterns=["R-R"]`` and 58 with
``["R-R", "O-O"]``: only the second seeded the perfect balance's stability boundary, and
starts there settle on R-R orbits too. Each pattern's rows are compared here between a
scan that asks for it alone and one that asks for every pattern of the ball count.
"""

from __future__ import annotations

import itertools

import numpy as np
import polars as pl
import pytest

import ballbal


def _rows(df: pl.DataFrame, pattern: str, axes: list[str]) -> list[tuple]:
    """The pattern's converged rows as (point, omega, verdict), in a fixed order."""
    sub = df.filter((pl.col("type") == pattern) & (pl.col("status") == "converged"))
    return sorted(
        (tuple(round(r[a], 9) for a in axes), round(r["omega"], 9), r["stability"])
        for r in sub.iter_rows(named=True)
    )


def _all_patterns(balls: int) -> list[str]:
    return ["-".join(p) for p in itertools.product("RO", repeat=balls)]


def _random_settings(count: int) -> list[ballbal.Balancer]:
    rng = np.random.default_rng(31)
    return [ballbal.Balancer(mu=float(rng.uniform(0.05, 0.4)),
                             zeta=float(rng.uniform(0.01, 0.2)),
                             zeta_b=float(rng.uniform(0.01, 0.2)),
                             delta=float(rng.uniform(10, 100)))
            for _ in range(count)]


SETTINGS = [ballbal.Balancer(mu=0.2, zeta=0.02, zeta_b=0.1, delta=50), *_random_settings(3)]


@pytest.mark.parametrize("k", range(len(SETTINGS)))
def test_each_patterns_rows_are_those_of_its_own_scan(k: int) -> None:
    b = SETTINGS[k]
    axes = {"Omega": (0.8, 2.0, 0.1), "eta": (0.4, 1.6, 0.2)}
    every = ballbal.scan(b, patterns=_all_patterns(2), **axes)
    for pattern in ("R-R", "O-O", "R-O"):
        alone = ballbal.scan(b, patterns=[pattern], **axes)
        assert _rows(alone, pattern, list(axes)) == _rows(every, pattern, list(axes)), pattern
    if k == 0:
        # The example: the stable R-R rows the two-pattern scan found.
        rr = every.filter((pl.col("type") == "R-R") & (pl.col("stability") == "stable"))
        assert rr.height >= 58


def test_unequal_balls_rows_do_not_depend_on_the_patterns_asked_for() -> None:
    b = ballbal.Balancer(mu=0.25, zeta=0.08, zeta_b=0.02, delta=20, eta=(1.0, 0.8))
    every = ballbal.scan(b, patterns=_all_patterns(2), Omega=(1.2, 2.2, 0.05))
    for pattern in ("R-O", "O-R"):
        alone = ballbal.scan(b, patterns=[pattern], Omega=(1.2, 2.2, 0.05))
        assert _rows(alone, pattern, ["Omega"]) == _rows(every, pattern, ["Omega"]), pattern
