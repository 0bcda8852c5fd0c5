"""Save, or compare, reference outputs of the continuation and bifurcation functions:
what a behaviour-preserving change to branches, events, switching and curves must leave
as it was.

    python scripts/branch_reference.py save DIR      # with the build before the change
    python scripts/branch_reference.py compare DIR   # with the build after it

Saved, as Parquet (each object's ``table`` and ``events`` or ``points``): equilibrium
branches (the balls-together branch in eta with its pitchfork and fold; the perfect
balance in Omega at eta 0.505 with its close Hopf pair), the switch from the pitchfork to
the perfect balance, the saddle-node and Hopf curves, the merged R-R branch in Omega at
zeta_b 0.05 (its branch point and fold) and both ways from Omega 1.2, the period doubling
of the merged R-R branch in eta, and the periodic curves of the branch point, the fold and
the period doubling. ``compare`` requires identical tables (timings aside) and otherwise
prints the largest numeric difference of each table, so that round-off can be named.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import polars as pl
from reference_outputs import _max_diff  # same folder: the scripts' shared comparison

import ballbal
from ballbal.continuation import (
    Continuation,
    equilibrium_branch,
    equilibrium_curve,
    periodic_branch,
    periodic_curve,
    switch_equilibrium,
)

N = 8
OPTS = Continuation(ds=0.01, ds_max=0.05, max_points=400, tol=1e-12)
HB = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N))
NO_FLOQUET = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N),
                                     floquet=ballbal.Floquet(monodromy=False, hill=False))
MONODROMY = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N),
                                    floquet=ballbal.Floquet(hill=False))
DROP = {"seconds"}


def _thesis(Omega: float, eta: float, zeta_b: float = 0.05) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, delta=50.0, zeta_b=zeta_b, Omega=Omega,
                            eta=(eta, eta))


def _first(br: Any, kind: str) -> int:
    return int(br.events["type"].to_list().index(kind))


def _together() -> Any:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.05, eta=(0.3, 0.3))
    return equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0), options=OPTS)


def _hopf_pair() -> Any:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=0.8,
                         eta=(0.505, 0.505))
    return equilibrium_branch(b, "Omega", start="perfect_balance", range=(0.8, 1.5))


def _band_end() -> Any:
    start = ballbal.periodic(_thesis(1.2, 1.0), "R-R", options=HB)
    return periodic_branch(start, "Omega", range=(1.2, 1.9), periodic_options=NO_FLOQUET,
                           options=Continuation(ds=0.05, ds_max=0.2, max_points=80))


def _both_ways() -> Any:
    start = ballbal.periodic(_thesis(1.2, 1.0, zeta_b=0.1), "R-R", options=HB)
    return periodic_branch(start, "Omega", range=(0.95, 1.4), periodic_options=HB,
                           options=Continuation(ds=0.02, ds_max=0.1, max_points=120),
                           direction="both")


def _doubling() -> Any:
    start = ballbal.periodic(_thesis(1.2, 0.9), "R-R", options=HB)
    return periodic_branch(start, "eta", range=(0.8, 0.9), periodic_options=MONODROMY,
                           options=Continuation(ds=0.01, ds_max=0.02, forward=False,
                                                max_points=60))


def objects() -> dict[str, Callable[[], Any]]:
    cache: dict[str, Any] = {}

    def once(name: str, make: Callable[[], Any]) -> Callable[[], Any]:
        def get() -> Any:
            if name not in cache:
                cache[name] = make()
            return cache[name]
        return get

    together = once("together", _together)
    band = once("band", _band_end)
    doubling = once("doubling", _doubling)
    return {
        "eq_together": together,
        "eq_hopf_pair": _hopf_pair,
        "eq_switch_pitchfork": lambda: switch_equilibrium(together(),
                                                          _first(together(), "branch_point")),
        "eq_curve_fold": lambda: equilibrium_curve(together(), "fold", "Omega",
                                                   range=(0.6, 1.6), options=OPTS),
        "eq_curve_hopf": lambda: equilibrium_curve(_hopf_pair(), "hopf", "eta",
                                                   range=(0.45, 0.6), options=OPTS),
        "po_band_end": band,
        "po_both_ways": _both_ways,
        "po_doubling": doubling,
        "po_curve_branch_point": lambda: periodic_curve(
            band(), "branch_point", "eta", range=(0.9, 1.1),
            options=Continuation(ds=0.02, ds_max=0.05, max_points=30)),
        "po_curve_fold": lambda: periodic_curve(
            band(), "fold", "eta", range=(0.9, 1.1),
            options=Continuation(ds=0.02, ds_max=0.05, max_points=30)),
        "po_curve_period_doubling": lambda: periodic_curve(
            doubling(), "period_doubling", "Omega", range=(1.15, 1.3),
            options=Continuation(ds=0.01, ds_max=0.02, max_points=20)),
    }


def _tables(obj: Any) -> dict[str, pl.DataFrame]:
    second = "events" if hasattr(obj, "events") else "points"
    out = {"table": obj.table, second: getattr(obj, second)}
    return {k: v.drop([c for c in v.columns if c in DROP]) for k, v in out.items()}


def main(argv: list[str]) -> int:
    mode, d = argv[1], Path(argv[2])
    d.mkdir(parents=True, exist_ok=True)
    bad = 0
    for name, make in objects().items():
        for part, df in _tables(make()).items():
            f = d / f"{name}.{part}.parquet"
            if mode == "save":
                df.write_parquet(f)
                print(f"saved {name}.{part}: {df.height} rows x {df.width} columns")
                continue
            ref = pl.read_parquet(f)
            if ref.columns == df.columns and ref.equals(df):
                print(f"same {name}.{part}: {df.height} rows")
                continue
            bad += 1
            worst = _max_diff(ref, df, set())
            how = (f"largest difference {worst:.2e}" if worst is not None else
                   f"shape or labels differ: {df.height}x{df.width} against "
                   f"{ref.height}x{ref.width}, columns {set(ref.columns) ^ set(df.columns)}")
            print(f"DIFFERENT {name}.{part}: {how}")
    if mode == "compare":
        print("all identical" if not bad else f"{bad} tables differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
