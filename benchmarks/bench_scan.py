"""Scan throughput: the thesis grid (Omega 1.0-2.0, eta 0.4-1.5, step 0.1; mu 0.2,
delta 50, zeta 0.05, zeta_b 0.1) with all three two-ball types, on 1 and 2 threads.

    python benchmarks/bench_scan.py
"""

from __future__ import annotations

import time

import numpy as np

import ballbal


def main() -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0, eta=(1.0, 1.0))
    Om = np.round(np.arange(1.0, 2.0001, 0.1), 10)
    eta = np.round(np.arange(0.4, 1.5001, 0.1), 10)
    print(f"thesis grid {Om.size} x {eta.size}, N = 3, Floquet rtol 1e-6")
    print(f"{'types':>12} {'threads':>8} {'seconds':>8} {'points/s':>9} {'converged':>10}")
    base = {}
    for pats in (("R-R",), ("R-R", "O-O", "R-O")):
        for threads in (1, 2):
            t = time.perf_counter()
            df = ballbal.scan(b, Omega=Om, eta=eta, patterns=pats, threads=threads)
            dt = time.perf_counter() - t
            base.setdefault(pats, dt)
            conv = int((df["status"] == "converged").sum())
            print(f"{'/'.join(pats):>12} {threads:8d} {dt:8.2f} {Om.size * eta.size / dt:9.1f} "
                  f"{conv:10d}  speed-up {base[pats] / dt:.2f}")


if __name__ == "__main__":
    main()
