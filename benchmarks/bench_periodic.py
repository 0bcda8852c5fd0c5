"""Per-point cost of a periodic solution at the thesis' standard case (Omega 1.2, eta 1.0,
balls merged, R-R) and its hard case (Omega 1.0, eta 0.7, period ~106): Newton-IHB from
a neighbour's warm start against N, and the Floquet multipliers by both monodromy
methods side by side (``Floquet(method="rk45")``, today's, and ``"magnus"``) with their
errors against a tight reference; Hill's-method cross-check; scipy shooting for scale.

    python benchmarks/bench_periodic.py

Wall clock on a shared machine is noisy (medians of many repeats); the Rust core's
instruction counts under callgrind are steadier:

    cargo test --release -p ballbal-core --lib --no-run
    valgrind --tool=callgrind target/release/deps/ballbal_core-* --ignored --exact \\
        numerics::floquet::tests::magnus_profile        # RK45, Magnus, Hill
    BALLBAL_HB_N=8 valgrind --tool=callgrind target/release/deps/ballbal_core-* \\
        --ignored --exact numerics::hb::tests::hb_profile  # 20 warm HB solves at N
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


def match_error(a, ref) -> float:
    left = list(a)
    worst = 0.0
    for r in sorted(ref, key=lambda z: -abs(z)):
        k = int(np.argmin([abs(z - r) for z in left]))
        worst = max(worst, abs(left.pop(k) - r) / max(1.0, abs(r)))
    return worst


def harmonic_balance(b, seed) -> None:
    print("\nharmonic balance, warm start from the fine-grid neighbour (no Floquet):")
    print(f"{'N':>3} {'HB solve [us]':>14} {'iters':>6} {'ratio to N=3':>13}")
    base = None
    for N in (3, 6, 8, 12):
        t_hb, sol = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                         floquet=False, hill=False), 50)
        base = base or t_hb
        print(f"{N:3d} {t_hb * 1e6:14.0f} {sol.iterations:6d} {t_hb / base:13.2f}")


def floquet_methods(name, b, seed, N) -> None:
    """Both monodromies on the same series: Floquet time = (HB + Floquet) - HB."""
    t_hb, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed,
                                                   floquet=False, hill=False))
    ref = ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-12, atol=1e-14,
                           max_steps=10_000_000, hill=False)
    print(f"\n{name}, N = {N} (period {ref.period:.1f}); Floquet cost and the multipliers' "
          "error against RK45 at rtol 1e-12")
    print(f"{'method':>7} {'rtol':>6} {'Floquet [us]':>13} {'steps':>6} {'error':>9}")
    rows = {}
    for method in ("rk45", "magnus"):
        for rtol in (1e-5, 1e-6, 1e-7, 1e-8):
            t_all, s = median_time(lambda: ballbal.periodic(
                b, "R-R", N=N, guess=seed, rtol=rtol, atol=rtol * 1e-3, hill=False,
                floquet_method=method))
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
    print("thesis standard case, warm start from the fine-grid neighbour Omega = 1.19")
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
        t_h, h = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-6,
                                                      atol=1e-9), 10)
        t_n, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=N, guess=seed, rtol=1e-6,
                                                      atol=1e-9, hill=False), 10)
        d = np.max(np.abs(np.sort(np.abs(h.multipliers)) - np.sort(np.abs(h.hill_multipliers))))
        print(f"N = {N:2d}: Hill's-method check adds {(t_h - t_n) * 1e3:.1f} ms "
              f"(HB + RK45 Floquet {t_n * 1e3:.2f} ms); moduli agree to {d:.1e}")
    t0 = time.perf_counter()
    mult = scipy_point()
    t_sp = time.perf_counter() - t0
    t6, _ = median_time(lambda: ballbal.periodic(b, "R-R", N=6, guess=seed, rtol=1e-6,
                                                 hill=False, floquet_method="magnus"), 30)
    print(f"scipy shooting + finite-difference monodromy: {t_sp * 1e3:.0f} ms "
          f"(max modulus {np.sort(np.abs(mult))[-2]:.4f}); ballbal N = 6 (Magnus): "
          f"{t6 * 1e6:.0f} us; ratio {t_sp / t6:.0f}")


if __name__ == "__main__":
    main()
