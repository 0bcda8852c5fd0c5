"""What the certificates cost in a scan.

The core adds up the time it spends in the certificate checks (the integrated ODE defect
of every accepted series, and the merged balls' separation product after each Floquet
analysis) in a process-wide counter, `_native.certificate_seconds()`. This runs the
Tien (2011) grid (zeta 0.05, zeta_b 0.1; Omega 1.0-2.0 step 0.1, eta 0.4-1.5 step 0.1; R-R,
O-O, R-O; N = 3) and prints that time against the scan's CPU time (wall time x
threads), per point and as a fraction: the same build, the same run, the checks timed
where they run.

    python benchmarks/bench_certificates.py [repeats]
"""

from __future__ import annotations

import sys
import time

import ballbal
from ballbal import _native


def main(repeats: int = 3, threads: int = 2) -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.2, eta=(1.0, 1.0))
    grid = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
    fractions = []
    for r in range(repeats):
        c0 = _native.certificate_seconds()
        t0 = time.perf_counter()
        df = ballbal.scan(b, patterns=["R-R", "O-O", "R-O"], threads=threads, **grid)
        wall = time.perf_counter() - t0
        c1 = _native.certificate_seconds()
        cert = c1 - c0
        points = df.select("Omega", "eta").unique().height
        found = df.filter(df["status"] == "converged").height
        frac = cert / (wall * threads)
        fractions.append(frac)
        print(f"run {r}: {points} points, {found} solutions, scan {wall:.3f} s wall "
              f"({1e3 * wall * threads / points:.2f} ms CPU a point), certificates "
              f"{1e3 * cert:.2f} ms ({1e6 * cert / points:.1f} us a point) = "
              f"{100 * frac:.2f} % of the scan's CPU time")
    print(f"certificates: {100 * min(fractions):.2f} - {100 * max(fractions):.2f} % of the "
          f"scan (budget 10 %)")
    d = df.filter(df["status"] == "converged")
    print(f"converged rows: closure {d['closure'].min():.2e} .. {d['closure'].max():.2e}, "
          f"trivial error up to {d['trivial_error'].max():.2e}, separation error up to "
          f"{d['separation_error'].max()}")


def separation() -> None:
    """The closure certificate against the simulated closure (verify()) on the issue's
    reproduction, certificates off, so that both sides of the threshold show."""
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0, eta=(1.0, 1.0))
    for n in (8, 3):
        prev = ballbal.periodic(b, "R-R", N=n,
                                options=ballbal.PeriodicOptions(max_closure=1e300, max_tail=1e300))
        for k in range(1, 20):
            w = round(1.0 - 0.02 * k, 3)
            s = ballbal.periodic(b.replace(Omega=w), "R-R", N=n, guess=prev,
                                 options=ballbal.PeriodicOptions(
                                     floquet=ballbal.Floquet(hill=False), max_closure=1e300,
                                     max_tail=1e300))
            if s.omega is None:
                break
            print(f"N={n} Omega={w:.2f}: omega {s.omega:.2e}, closure certificate "
                  f"{s.closure:.2e}, simulated closure {s.verify():.2e}, tail {s.tail:.2f}")
            prev = s


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
    separation()
