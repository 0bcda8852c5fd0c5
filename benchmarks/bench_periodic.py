"""Per-point cost of a periodic solution at Tien's (2011) standard case (Omega 1.2, eta 1.0,
balls merged, R-R) and its hard case (Omega 1.0, eta 0.7, period ~106): Newton-IHB from
a neighbour's warm start against N, and the Floquet multipliers by both monodromy
methods side by side (``Floquet(method="rk45")``, today's, and ``"magnus"``) with their
errors against a tight reference; Hill's-method cross-check; scipy shooting for scale.

    python benchmarks/bench_periodic.py

Wall clock on a shared machine is noisy (medians of many repeats); the Rust core's
instruction counts under callgrind are steadier:

    cargo test --release -p ballbal-core --features studies --lib --no-run
    valgrind --tool=callgrind target/release/deps/ballbal_core-* --ignored --exact \\
        numerics::floquet::studies::magnus_profile        # RK45, Magnus, Hill
    BALLBAL_HB_N=8 valgrind --tool=callgrind --toggle-collect='*warm_solve*' \\
        target/release/deps/ballbal_core-* --ignored --exact \\
        numerics::hb::studies::hb_profile  # 20 warm HB solves at N (total / 20 per solve)

Instructions per warm solve (certificates included), 2026-11-23, before -> after the
product-to-sum Jacobian (N > 3) and the reuse of the accepted trial's residual:
N = 3: 2.41 M -> 1.87 M, N = 6: 6.71 M -> 3.01 M, N = 8: 11.46 M -> 4.47 M,
N = 12: 26.7 M -> 8.36 M; N = 8 / N = 3: 4.75 -> 2.39.
Then (same harness, 2026-11-23 night): the basis and DFT tables kept per thread, sampling
vectorised along the samples and faer factoring the row-major view (every result the
same to the bit): N = 3: 1.87 M -> 1.82 M, N = 6: 3.00 M -> 2.76 M, N = 8: 4.45 M ->
4.06 M, N = 12: 8.32 M -> 7.45 M; N = 8 / N = 3: 2.38 -> 2.23. Chord steps ending the
N > 3 solves (reusing the last LU) measured N = 8 / N = 3 = 2.01 but made one Omega-eta
map N = 8 scan gain a solution, unexplained, and were taken out again (commit e6f873a has
them).
Then (2026-11-24) the sample count above N = 3 grows as 4 (N + 5) instead of 8 (N + 1)
(N = 8: 52 samples, not 72; aliasing measured at round-off, see ``hb::default_samples``;
N <= 3 unchanged): N = 3: 1.66 M, N = 6: 2.76 M -> 2.15 M, N = 8: 3.65 M -> 3.09 M,
N = 12: 6.94 M -> 5.59 M; N = 8 / N = 3: 2.20 -> 1.86 (this script's wall clock, the
Python facade included: 1.87).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import ballbal

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from shooting import match_error, monodromy_multipliers, shoot  # noqa: E402


def median_time(f, repeats=30):
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts)), out


STAGES = ("residual (AFT)", "model K,C,M", "Jacobian projection", "LU")


def harmonic_balance(b, seed) -> None:
    """Warm solves against N, then the same solves' time per stage (the core's stage
    timers, ``_native.hb_stage_profile``): the residual (sampling, the model at the
    samples, the Galerkin projection), the model's K, C, M at the samples, their
    projection into the Jacobian (sample by sample at N <= 3, product-to-sum above),
    the LU solve; the certificates (integrated ODE defect, tail) are the rest of a
    solve's time."""
    from ballbal import _native

    print("\nharmonic balance, warm start from the fine-grid neighbour (no Floquet; LUs: "
          "factorisations per solve, one per Newton iteration):")
    print(f"{'N':>3} {'S':>4} {'unknowns':>8} {'HB solve [us]':>14} {'LUs':>6} "
          f"{'residuals':>9} {'ratio to N=3':>13}")
    base = None
    rows = []
    for N in (3, 6, 8, 12):
        def solve(N=N):
            return ballbal.periodic(b, "R-R", N=N, guess=seed,
                                    options=ballbal.PeriodicOptions(
                                        floquet=ballbal.Floquet(monodromy=False, hill=False)))
        t_hb, sol = median_time(solve, 50)
        _native.hb_stage_profile(True)
        c0 = _native.certificate_seconds()
        reps = 50
        t0 = time.perf_counter()
        for _ in range(reps):
            solve()
        t_all = (time.perf_counter() - t0) / reps
        cert = (_native.certificate_seconds() - c0) / reps
        st = _native.hb_stage_seconds()
        _native.hb_stage_profile(False)
        stages = [v / reps for v in st[:4]]
        solves, iters, residuals = st[4] / reps, st[5] / reps, st[6] / reps
        base = base or t_hb
        samples = sol.samples
        print(f"{N:3d} {samples:4d} {4 * (2 * N + 1) + 1:8d} {t_hb * 1e6:14.0f} "
              f"{iters / solves:6.2f} {residuals / solves:9.2f} {t_hb / base:13.2f}")
        rows.append((N, stages, cert, t_all))
    print("per stage [us per solve] (timed run; rest: tail check, the Python facade and its "
          "conversions)")
    print(f"{'N':>3} " + " ".join(f"{s:>20}" for s in STAGES)
          + f" {'certificates':>13} {'rest':>6} {'total':>7}")
    for N, stages, cert, t_all in rows:
        rest = t_all - sum(stages) - cert
        print(f"{N:3d} " + " ".join(f"{v * 1e6:20.1f}" for v in stages)
              + f" {cert * 1e6:13.1f} {rest * 1e6:6.1f} {t_all * 1e6:7.1f}")


def floquet_methods(name, b, seed, N) -> None:
    """Both monodromies on the same series: Floquet time = (HB + Floquet) - HB."""
    t_hb, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                   options=ballbal.PeriodicOptions(
                                                       floquet=ballbal.Floquet(monodromy=False,
                                                                               hill=False))))
    ref = ballbal.periodic(b, "R-R", N=N, guess=seed,
                           options=ballbal.PeriodicOptions(
                               floquet=ballbal.Floquet(rtol=1e-12, atol=1e-14, max_steps=10_000_000,
                                                       hill=False)))
    print(f"\n{name}, N = {N} (period {ref.period:.1f}); Floquet cost and the multipliers' "
          "error against RK45 at rtol 1e-12")
    print(f"{'method':>7} {'rtol':>6} {'Floquet [us]':>13} {'steps':>6} {'error':>9}")
    rows = {}
    for method in ("rk45", "magnus"):
        for rtol in (1e-5, 1e-6, 1e-7, 1e-8):
            fl = ballbal.Floquet(rtol=rtol, atol=rtol * 1e-3, hill=False, method=method)
            t_all, s = median_time(lambda: ballbal.periodic(
                b, "R-R", N=N, guess=seed, options=ballbal.PeriodicOptions(floquet=fl)))
            err = match_error(s.multipliers, ref.multipliers)
            rows[method, rtol] = (t_all - t_hb, err)
            print(f"{method:>7} {rtol:6.0e} {(t_all - t_hb) * 1e6:13.0f} "
                  f"{s.floquet_steps:6d} {err:9.1e}")
    # matched accuracy: the cheapest setting of each method with error <= 1e-5
    best = {}
    for method in ("rk45", "magnus"):
        ok = [t for (m, _), (t, e) in rows.items() if m == method and e <= 1e-5]
        best[method] = min(ok) if ok else float("nan")
    print(f"  multipliers to 1e-5: RK45 {best['rk45'] * 1e6:.0f} us, Magnus "
          f"{best['magnus'] * 1e6:.0f} us, ratio {best['rk45'] / best['magnus']:.1f}; "
          f"scan setting (rtol 1e-6): ratio "
          f"{rows['rk45', 1e-6][0] / rows['magnus', 1e-6][0]:.1f}")


def main() -> None:
    base = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, eta=(1.0, 1.0))
    b = ballbal.Balancer(**base, Omega=1.2)
    neighbour = ballbal.Balancer(**base, Omega=1.19)  # fine-grid neighbour, step 0.01
    seed = ballbal.periodic(neighbour, "R-R", N=12)
    print("Tien (2011) standard case, warm start from the fine-grid neighbour Omega = 1.19")
    harmonic_balance(b, seed)
    for N in (3, 8):
        floquet_methods("standard case", b, seed, N)
    hard = ballbal.Balancer(**{**base, "eta": (0.7, 0.7)}, Omega=1.0)
    hard_seed = ballbal.periodic(hard.replace(Omega=0.99), "R-R", N=8)
    hard_seed = ballbal.periodic(hard.replace(Omega=0.99), "R-R", N=12, guess=hard_seed)
    for N in (3, 8):
        floquet_methods("hard case", hard, hard_seed, N)

    # scipy shooting of the same point, same warm start, to ~1e-6
    def scipy_point():
        y0, T = shoot(b, seed.state(0.0), seed.period, [0, 0, -1, -1], phase_index=2)
        return monodromy_multipliers(b, y0, T)

    print()
    for N in (3, 8):
        t_h, h = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                      options=ballbal.PeriodicOptions(
                                                          floquet=ballbal.Floquet(rtol=1e-6,
                                                                                  atol=1e-9))), 10)
        t_n, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                      options=ballbal.PeriodicOptions(
                                                          floquet=ballbal.Floquet(
                                                              rtol=1e-6, atol=1e-9,
                                                              hill=False))), 10)
        d = np.max(np.abs(np.sort(np.abs(h.multipliers)) - np.sort(np.abs(h.hill_multipliers))))
        print(f"N = {N:2d}: Hill's-method check adds {(t_h - t_n) * 1e3:.1f} ms "
              f"(HB + RK45 Floquet {t_n * 1e3:.2f} ms); moduli agree to {d:.1e}")
    t0 = time.perf_counter()
    mult = scipy_point()
    t_sp = time.perf_counter() - t0
    t6, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=6, guess=seed,
                                                 options=ballbal.PeriodicOptions(
                                                     floquet=ballbal.Floquet(rtol=1e-6, hill=False,
                                                                             method="magnus"))), 30)
    print(f"scipy shooting + finite-difference monodromy: {t_sp * 1e3:.0f} ms "
          f"(max modulus {np.sort(np.abs(mult))[-2]:.4f}); ballbal N = 6 (Magnus): "
          f"{t6 * 1e6:.0f} us; ratio {t_sp / t6:.0f}")


if __name__ == "__main__":
    main()
