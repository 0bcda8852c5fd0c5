"""Periodic continuation speed (issue 15), printed side by side:

* a 200-point branch of Tien's (2011) standard merged R-R orbit (mu 0.2, zeta 0.05,
  zeta_b 0.05, delta 50, eta 1, N = 8) continued in Omega by pseudo-arclength, every
  point with its certificates, Floquet multipliers and located events, against
  ``ballbal.scan`` (natural-parameter continuation on the scan's lattice, one thread)
  over the same Omega values with the same harmonics and Floquet options (required:
  branch <= 2x scan);
* points per second of natural-parameter (scan) and pseudo-arclength (branch)
  continuation, with and without the per-point Floquet analysis;
* a 100-point two-parameter curve (the branch point of the band's upper end in
  (Omega, eta)), with and without Floquet multipliers per point (required: seconds);
* the slow end of a branch: the merged R-R orbit at zeta_b 0.1 continued down in Omega to
  its infinite-period end (periods up to ~400, where the multipliers dominate a point's
  cost, and with them the finer series that bounds each verdict's error).

    python benchmarks/bench_po_continuation.py
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

import ballbal
from ballbal.continuation import Continuation, periodic_branch, periodic_curve

BASE = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, eta=(1.0, 1.0))


def branch_vs_scan(opts: ballbal.PeriodicOptions, label: str) -> ballbal.continuation.Branch:
    b = ballbal.Balancer(**BASE, Omega=1.2)
    start = ballbal.periodic(b, "R-R", options=opts)
    t = time.perf_counter()
    br = periodic_branch(start, "Omega", range=(1.2, 3.0), periodic_options=opts,
                         options=Continuation(ds=0.06, ds_max=0.06, max_points=200))
    t_branch = time.perf_counter() - t
    n = br.table.height
    grid = np.sort(br.table["Omega"].to_numpy())
    so = ballbal.ScanOptions(harmonic_balance=ballbal.HarmonicBalance(N=8),
                             floquet=opts.floquet)
    t = time.perf_counter()
    df = ballbal.scan(b, Omega=grid, patterns=("R-R",), options=so, threads=1)
    t_scan = time.perf_counter() - t
    found = df.filter(df["status"] == "converged").height
    print(f"[{label}] pseudo-arclength branch: {n} points over Omega "
          f"{grid[0]:.4f}..{grid[-1]:.4f} in {t_branch:.2f} s ({n / t_branch:.1f} points/s), "
          f"stop {br.stop}, events {br.events['type'].to_list()}")
    print(f"[{label}] natural-parameter scan:  {len(grid)} points ({found} converged) in "
          f"{t_scan:.2f} s ({len(grid) / t_scan:.1f} points/s)")
    print(f"[{label}] branch / scan = {t_branch / t_scan:.2f} (required <= 2)")
    return br


def curve(br: ballbal.continuation.Branch, opts: ballbal.PeriodicOptions, label: str) -> None:
    i = br.events["type"].to_list().index("branch_point")
    t = time.perf_counter()
    c = periodic_curve(br, i, "eta", range=(0.3, 3.0), range1=(0.5, 5.0),
                       periodic_options=opts,
                       options=Continuation(ds=0.02, ds_max=0.02, max_points=51, grow=1.0))
    dt = time.perf_counter() - t
    n = c.table.height
    print(f"[{label}] BP curve in (Omega, eta): {n} points in {dt:.2f} s "
          f"({n / dt:.1f} points/s), eta {c.table['eta'].min():.3f}..{c.table['eta'].max():.3f},"
          f" stop {c.stop}, codim-2 {c.points['type'].to_list()}")


def infinite_period_end(opts: ballbal.PeriodicOptions) -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0, eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=opts)
    t = time.perf_counter()
    br = periodic_branch(start, "Omega", range=(0.5, 1.0), periodic_options=opts,
                         options=Continuation(ds=0.01, ds_max=0.03, forward=False,
                                              max_points=200))
    dt = time.perf_counter() - t
    n = br.table.height
    decided = br.table.filter(br.table["stability"] != "undetermined").height
    print(f"[Floquet] branch to the infinite-period end: {n} points in {dt:.2f} s "
          f"({n / dt:.1f} points/s), {decided} with a verdict, stop {br.stop}, "
          f"events {br.events['type'].to_list()}")


def main() -> None:
    with_floquet = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))
    bare = replace(with_floquet, floquet=ballbal.Floquet(monodromy=False, hill=False))
    br = branch_vs_scan(with_floquet, "Floquet")
    branch_vs_scan(bare, "no Floquet")
    curve(br, bare, "no Floquet")
    curve(br, with_floquet, "Floquet")
    infinite_period_end(with_floquet)


if __name__ == "__main__":
    main()
