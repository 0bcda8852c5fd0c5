"""Scan throughput, including Floquet, on 1 and 2 threads, side by side:

* the thesis grid (Omega 1.0-2.0, eta 0.4-1.5, step 0.1; mu 0.2, delta 50), all three
  two-ball types, at the standard point (zeta = zeta_b = 0.05) and at zeta_b = 0.1;
* the fine grid (101 x 111, step 0.01) for R-R.

Each at N = 3 and N = 8. Targets (issue 4): thesis grid, all three types, under 1 s;
fine grid R-R under 30 s; 1-to-2-thread speed-up at least 1.8.

    python benchmarks/bench_scan.py            # everything (about 3 minutes)
    python benchmarks/bench_scan.py --quick    # thesis grid only
"""

from __future__ import annotations

import sys
import time

import ballbal

THESIS = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
FINE = {"Omega": (1.0, 2.0, 0.01), "eta": (0.4, 1.5, 0.01)}
ALL = ("R-R", "O-O", "R-O")


def run(label: str, b: ballbal.Balancer, grid: dict, pats: tuple[str, ...], N: int) -> None:
    times = {}
    for threads in (1, 2):
        t = time.perf_counter()
        df = ballbal.scan(b, patterns=pats, N=N, threads=threads, **grid)
        times[threads] = time.perf_counter() - t
    pts = df.select(list(grid)).unique().height
    sols = df.filter(df["status"] == "converged")
    stable = int((sols["stability"] == "stable").sum())
    print(f"{label:<24} {'/'.join(pats):<12} {N:>2} {pts:>6} {sols.height:>6} {stable:>6} "
          f"{times[1]:>8.2f} {times[2]:>8.2f} {pts / times[2]:>9.0f} "
          f"{times[1] / times[2]:>8.2f}")


def main() -> None:
    quick = "--quick" in sys.argv
    std = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
    zb1 = std.replace(zeta_b=0.1)
    print(f"{'grid':<24} {'types':<12} {'N':>2} {'points':>6} {'sols':>6} {'stable':>6} "
          f"{'1 thr s':>8} {'2 thr s':>8} {'pts/s(2)':>9} {'speed-up':>8}")
    for N in (3, 8):
        run("thesis, zeta_b 0.05", std, THESIS, ALL, N)
        run("thesis, zeta_b 0.1", zb1, THESIS, ALL, N)
    if not quick:
        for N in (3, 8):
            run("fine 101x111, zb 0.05", std, FINE, ("R-R",), N)


if __name__ == "__main__":
    main()
