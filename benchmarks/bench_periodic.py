"""Per-point cost of a periodic solution at the thesis' standard case (Omega 1.2, eta 1.0,
balls merged, R-R): Newton-IHB from a neighbour's warm start, and the Floquet multipliers,
for N = 3, 6, 12; and scipy shooting of the same point for the ratio.

    python benchmarks/bench_periodic.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import ballbal

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from shooting import monodromy_multipliers, shoot  # noqa: E402


def median_time(f, repeats=30):
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), out


def main() -> None:
    base = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, eta=(1.0, 1.0))
    b = ballbal.Balancer(**base, Omega=1.2)
    neighbour = ballbal.Balancer(**base, Omega=1.19)  # fine-grid neighbour, step 0.01
    seed = ballbal.periodic(neighbour, "R-R", N=12)
    print("thesis standard case, warm start from the fine-grid neighbour Omega = 1.19")
    print("Floquet error = max |modulus - modulus at rtol 1e-11| (integration error only)")
    print(f"{'N':>3} {'HB solve [us]':>14} {'iters':>6} {'rtol':>6} {'Floquet [us]':>13} "
          f"{'steps':>6} {'HB+Floquet [us]':>16} {'Floquet error':>14} {'|omega-0.251413|':>17}")
    for N in (3, 6, 12):
        t_hb, sol = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                         floquet=False, hill=False))
        tight = ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-11, atol=1e-14,
                                 hill=False)
        ref = np.sort(np.abs(tight.multipliers))
        for rtol in (1e-5, 1e-6):
            t_all, full = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                               rtol=rtol, atol=rtol * 1e-3,
                                                               hill=False))
            err = np.max(np.abs(np.sort(np.abs(full.multipliers)) - ref))
            print(f"{N:3d} {t_hb * 1e6:14.0f} {sol.iterations:6d} {rtol:6.0e} "
                  f"{(t_all - t_hb) * 1e6:13.0f} {full.floquet_steps:6d} {t_all * 1e6:16.0f} "
                  f"{err:14.1e} {abs(sol.omega - 0.251413):17.1e}")
    # scipy shooting of the same point, same warm start, to ~1e-6

    def scipy_point():
        y0, T = shoot(b, seed.state(0.0), seed.period, [0, 0, -1, -1], phase_index=2)
        return monodromy_multipliers(b, y0, T)

    t0 = time.perf_counter()
    mult = scipy_point()
    t_sp = time.perf_counter() - t0
    t6, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=6, guess=seed, rtol=1e-6,
                                                 atol=1e-9, hill=False), 30)
    for N in (3, 6, 12):
        t_h, h = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-6,
                                                      atol=1e-9), 10)
        t_n, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-6,
                                                      atol=1e-9, hill=False), 10)
        d = np.max(np.abs(np.sort(np.abs(h.multipliers)) - np.sort(np.abs(h.hill_multipliers))))
        print(f"N = {N:2d}: Hill's-method check adds {(t_h - t_n) * 1e3:.1f} ms "
              f"(HB + Floquet {t_n * 1e3:.2f} ms); moduli agree to {d:.1e}")
    print(f"scipy shooting + finite-difference monodromy: {t_sp * 1e3:.0f} ms "
          f"(max modulus {np.sort(np.abs(mult))[-2]:.4f}); ballbal N = 6: {t6 * 1e6:.0f} us; "
          f"ratio {t_sp / t6:.0f}")


if __name__ == "__main__":
    main()
