"""Basin grids: starts per second on 1 and 2 threads at Tien's (2011) 1000 time units
(figures 4-15 / 4-16: mu 0.2, zeta 0.05, zeta_b 0.05, delta 50, eta 0.7), and the time a
200 x 200 map would take, extrapolated from a smaller grid (targets: at most 10 ms per
start on one core, a 200 x 200 map in under 3 minutes on 2 cores). The starts are
classified only (``orbits=False``); ``extended`` counts the starts simulated beyond
``t_end``, and the last column is the time of linking the periodic starts to their
orbits (one call with ``orbits=True`` minus the classification).

    python benchmarks/bench_basins.py [n]      # n x n starts per run (default 16)
"""

from __future__ import annotations

import sys
import time

import ballbal
from ballbal.basins import BasinOptions, basins


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 16
    print(f"basins: {n} x {n} starts, t_end 1000; best of 2 runs")
    print(f"{'Omega':>6} {'early':>6} {'threads':>8} {'starts/s':>9} {'ms/start':>9} "
          f"{'200x200 [s]':>12} {'rotating':>9} {'t_stop':>7} {'extended':>9} "
          f"{'link [s]':>9}")
    for om in (1.2, 1.35):
        m = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=om,
                             eta=(0.7, 0.7))
        # Side by side in one run: with and without the early stop (the labels agree).
        for threads in (1, 2):
            for early in (False, True):
                best = float("inf")
                for _ in range(2):
                    t = time.perf_counter()
                    r = basins(m, n=n, options=BasinOptions(early_stop=early),
                               threads=threads, orbits=False)
                    best = min(best, time.perf_counter() - t)
                t = time.perf_counter()
                basins(m, n=n, options=BasinOptions(early_stop=early),
                       threads=threads)
                link = time.perf_counter() - t - best
                rate = n * n / best
                print(f"{om:>6} {early!s:>6} {threads:>8} {rate:>9.0f} {1e3 / rate:>9.2f} "
                      f"{40_000 / rate:>12.0f} {r.rotating_fraction()[0]:>9.2f} "
                      f"{r.table['t_stop'].mean():>7.0f} "
                      f"{(r.table['extensions'] > 0).sum():>9} {link:>9.2f}")


if __name__ == "__main__":
    main()
