"""ballbal.simulate against scipy.integrate.solve_ivp(method="RK45") on the same two-ball
problem, tolerances and output times; prints both times and the ratio.

    python benchmarks/bench_simulate.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import ballbal

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from reference import rhs  # noqa: E402


def best_of(f, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return min(times), out


def main() -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2, eta=(1.0, 1.0))
    y0 = np.array([0.0, 0.0, 0.3, 1.9, 0.0, 0.0, -1.2, -1.2])
    T = 1000.0
    t_eval = np.linspace(0, T, 2001)
    print(f"two-ball simulation over {T:g} time units, 2001 outputs")
    print(f"{'rtol':>8} {'ballbal [ms]':>13} {'scipy RK45 [ms]':>16} {'ratio':>8} "
          f"{'max |diff|':>11}")
    for rtol in (1e-6, 1e-8):
        atol = rtol * 1e-3
        t_us, df = best_of(lambda: ballbal.simulate(b, y0, t_eval, rtol=rtol, atol=atol), 5)
        t_sp, sp = best_of(lambda: solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0,
                                             t_eval=t_eval, rtol=rtol, atol=atol,
                                             method="RK45"), 1)
        diff = np.max(np.abs(df.select(["x", "y"]).to_numpy() - sp.y[:2].T))
        print(f"{rtol:8.0e} {t_us * 1e3:13.2f} {t_sp * 1e3:16.1f} {t_sp / t_us:8.0f} {diff:11.1e}")


if __name__ == "__main__":
    main()
