"""Where periodic()'s automatic choice switches from harmonic balance to collocation,
down the merged R-R branch of issue 33 (mu 0.2, zeta 0.05, zeta_b 0.1, delta 50, eta
(1, 1)) from Omega 1.2 towards its infinite-period end (Omega* ~ 0.91714), and what each
point costs.

    python benchmarks/bench_collocation.py

Each Omega is solved without a guess (periodic()'s own simulated start), once with the
defaults (``N = 3``, ``method="auto"``) and once with ``N="auto"``; the columns are the
method chosen, the status, the period, harmonic balance's status alone, and the wall
time. With ``--check`` every collocation period is also compared with a second solve on
a mesh twice as fine (its relative difference).
"""

from __future__ import annotations

import sys
import time

import ballbal

PARAMS = dict(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, eta=(1.0, 1.0))
OMEGAS = (1.2, 1.1, 1.0, 0.97, 0.96, 0.95, 0.945, 0.94, 0.935, 0.93, 0.925, 0.92, 0.918)


def main() -> None:
    check = "--check" in sys.argv
    print(f"{'Omega':>6} {'N':>5} {'method':>11} {'status':>10} {'period':>14} "
          f"{'hb alone':>10} {'seconds':>8}" + ("  fine-mesh period diff" if check else ""))
    first: dict[str, float] = {}
    for om in OMEGAS:
        b = ballbal.Balancer(**PARAMS, Omega=om)
        for N in (3, "auto"):
            t = time.perf_counter()
            r = ballbal.periodic(b, "R-R", N=N)
            dt = time.perf_counter() - t
            hb = ballbal.periodic(b, "R-R", N=N, method="hb")
            period = f"{r.period:14.8f}" if r.omega is not None else f"{'-':>14}"
            extra = ""
            if check and r.method == "collocation" and r.converged:
                fine = ballbal.periodic(b, "R-R", guess=r, method="collocation",
                                        collocation=ballbal.Collocation(ntst=100))
                extra = f"  {fine.period / r.period - 1:+.1e}"
            if r.method == "collocation":
                first.setdefault(str(N), om)
            print(f"{om:6.3f} {N!s:>5} {r.method:>11} {r.status:>10} {period} "
                  f"{hb.status:>10} {dt:8.2f}{extra}", flush=True)
    for N, om in first.items():
        print(f"N = {N}: auto switches to collocation first at Omega {om}")


if __name__ == "__main__":
    main()
