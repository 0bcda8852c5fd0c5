"""Periodic-branch continuation against a grid scan of the same points (issue 15):
the thesis' standard merged R-R orbit (mu 0.2, zeta 0.05, zeta_b 0.05, delta 50, eta 1)
continued in Omega with N = 8 by pseudo-arclength, 200 points with their certificates,
Floquet multipliers and located events, against `ballbal.scan` (natural-parameter
continuation on the scan's lattice, one thread) over 200 Omega values spanning the same
range with the same harmonics and Floquet options. The requirement: the branch costs no
more than 2x the scan.

    python benchmarks/bench_po_continuation.py
"""

from __future__ import annotations

import time

import numpy as np

import ballbal
from ballbal.continuation import Continuation, periodic_branch


def main() -> None:
    base = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, eta=(1.0, 1.0))
    b = ballbal.Balancer(**base, Omega=1.2)
    opts = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=8))
    start = ballbal.periodic(b, "R-R", options=opts)
    t = time.perf_counter()
    br = periodic_branch(start, "Omega", range=(1.2, 3.0), periodic_options=opts,
                         options=Continuation(ds=0.01, ds_max=0.01, max_points=200))
    t_branch = time.perf_counter() - t
    n = br.table.height
    lo, hi = float(br.table["Omega"].min()), float(br.table["Omega"].max())
    print(f"branch: {n} points over Omega {lo:.4f}..{hi:.4f} in {t_branch:.2f} s, "
          f"stop {br.stop}, events {br.events['type'].to_list()}")
    grid = np.linspace(lo, hi, n)
    so = ballbal.ScanOptions(harmonic_balance=ballbal.HarmonicBalance(N=8),
                             floquet=opts.floquet)
    t = time.perf_counter()
    df = ballbal.scan(b, Omega=grid, patterns=("R-R",), options=so, threads=1)
    t_scan = time.perf_counter() - t
    found = df.filter(df["status"] == "converged").height
    print(f"scan:   {n} points ({found} converged R-R rows) in {t_scan:.2f} s")
    print(f"points per second: natural-parameter (scan lattice) {n / t_scan:.1f}, "
          f"pseudo-arclength {n / t_branch:.1f}; branch / scan = {t_branch / t_scan:.2f} "
          f"(required <= 2)")


if __name__ == "__main__":
    main()
