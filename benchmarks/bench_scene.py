"""What the effect system costs: the planar balancer's time per simulation and per
harmonic-balance solve (which evaluate the residual and its Jacobians), and a scene
with effects switched on, side by side.

    python benchmarks/bench_scene.py

To compare with a build from before the effect system, run this script under both
installs; the figures are the best of repeated runs.
"""

from __future__ import annotations

import time

import numpy as np

import ballbal


def best_time(f, repeats: int = 15) -> float:
    # The minimum: on a shared machine the noise only ever adds time.
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    b = ballbal.Balancer()
    y0 = np.array([0.1, 0.0, 0.3, 2.0, 0.0, 0.0, -1.2, -1.2])
    t = np.linspace(0, 1000, 2001)
    sim = best_time(lambda: ballbal.simulate(b, y0, t, rtol=1e-8, atol=1e-10))
    seed = ballbal.periodic(b.replace(Omega=1.19), "R-R", N=12,
                            options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    hb = {N: best_time(lambda N=N: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                    options=ballbal.PeriodicOptions(
                                                        floquet=ballbal.Floquet(
                                                            monodromy=False, hill=False))), 40)
          for N in (3, 8)}
    # right-hand sides the integrator evaluated: time per evaluation, all else included
    evals = ballbal.simulate(b, y0, t, rtol=1e-8, atol=1e-10, stats=True)[1]["nfev"]
    print(f"ballbal {ballbal.__version__}: planar balancer")
    print(f"  simulate 1000 time units (rtol 1e-8):  {sim * 1e3:8.3f} ms "
          f"({evals} right-hand sides, {sim / evals * 1e9:.0f} ns each)")
    for N, v in hb.items():
        print(f"  harmonic balance, N = {N:2d}, warm start: {v * 1e6:8.1f} us")
    if hasattr(ballbal, "Scene"):
        sc = ballbal.Scene(balancer=b, springs=1e-5)
        ssim = best_time(lambda: ballbal.simulate(sc, y0, t, rtol=1e-8, atol=1e-10))
        near = ballbal.Scene(balancer=b.replace(Omega=1.19), springs=1e-5)
        sseed = ballbal.periodic(near, "R-R", N=12, guess=seed,
                                 options=ballbal.PeriodicOptions(
                                     floquet=ballbal.Floquet(hill=False)))
        shb = best_time(lambda: ballbal.periodic(sc, "R-R", N=8, guess=sseed,
                                                 options=ballbal.PeriodicOptions(
                                                     floquet=ballbal.Floquet(monodromy=False,
                                                                             hill=False))), 40)
        print("scene with ball springs (k_d / k = 1e-5):")
        print(f"  simulate 1000 time units (rtol 1e-8):  {ssim * 1e3:8.3f} ms "
              f"({ssim / sim:.2f} x planar)")
        print(f"  harmonic balance, N =  8, warm start: {shb * 1e6:8.1f} us "
              f"({shb / hb[8]:.2f} x planar)")
    if hasattr(ballbal, "Tilt"):
        # generated Lagrangian terms and a dense LU of the mass matrix per evaluation
        tl = ballbal.Tilt(a=1.8, b=2.2, j_t=0.35, j_z=0.55, zeta_r=0.04)
        ts = ballbal.Scene(balancer=b, tilt=tl)
        ty0 = np.concatenate([y0[:2], [0.0, 0.0], y0[2:6], [0.0, 0.0], y0[6:]])
        tsim = best_time(lambda: ballbal.simulate(ts, ty0, t, rtol=1e-8, atol=1e-10))
        tseed = ballbal.periodic(ts.replace(Omega=1.19), "R-R", N=12,
                                 options=ballbal.PeriodicOptions(
                                     floquet=ballbal.Floquet(hill=False)))
        thb = best_time(lambda: ballbal.periodic(ts, "R-R", N=8, guess=tseed,
                                                 options=ballbal.PeriodicOptions(
                                                     floquet=ballbal.Floquet(monodromy=False,
                                                                             hill=False))), 40)
        grid = np.linspace(0.5, 3.0, 200)
        tmap = best_time(lambda: ballbal.balance_map(ts, Omega=grid), 5)
        print("tilting disk on a flexible shaft (Rezaee et al. 2017):")
        print(f"  simulate 1000 time units (rtol 1e-8):  {tsim * 1e3:8.3f} ms "
              f"({tsim / sim:.2f} x planar)")
        print(f"  harmonic balance, N =  8, warm start: {thb * 1e6:8.1f} us "
              f"({thb / hb[8]:.2f} x planar)")
        print(f"  balanced state + eigenvalues:         {tmap / grid.size * 1e6:8.1f} us "
              f"a point (balance_map of {grid.size} points)")
    if hasattr(ballbal, "Scene"):
        # R-R scans (seeds, continuation, Floquet) over one grid, 2 threads, best of 3
        axes = {"Omega": (1.0, 2.0, 0.05), "eta": (0.4, 1.5, 0.1)}
        tl = ballbal.Tilt(a=1.8, b=2.2, j_t=0.35, j_z=0.55, zeta_r=0.04)
        print("R-R scan, Omega 1.0-2.0 x eta 0.4-1.5 (21 x 12), N = 3, 2 threads:")
        base = None
        for label, m in [("planar", b), ("ball springs 1e-5", ballbal.Scene(balancer=b,
                                                                              springs=1e-5)),
                         ("tilting disk", ballbal.Scene(balancer=b, tilt=tl))]:
            try:
                secs = best_time(lambda m=m: ballbal.scan(m, threads=2, **axes), 3)
            except ValueError as e:  # builds before scene scans
                print(f"  {label:<18} not available ({e})")
                continue
            df = ballbal.scan(m, threads=2, **axes)
            pts = df.select(list(axes)).unique().height
            found = int((df["status"] == "converged").sum())
            base = base or secs
            print(f"  {label:<18} {secs:7.2f} s  {secs / pts * 1e3:6.2f} ms a point  "
                  f"{found:4d} solutions  ({secs / base:.2f} x planar)")


if __name__ == "__main__":
    main()
