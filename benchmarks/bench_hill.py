"""Cost of Hill's-method cross-check (``periodic(..., hill=True)``, and at the scan's
``hill_target="verdict"``) against the monodromy
it cross-checks (RK45 at the scan's rtol 1e-6, and Magnus), at Tien's (2011) standard case
(Omega 1.2, eta 1.0, balls merged, R-R) and its hard case (Omega 1.0, eta 0.7, period
~106), N = 3 and 8, with the Hill multipliers' error against RK45 at rtol 1e-12.

    python benchmarks/bench_hill.py            # wall clock, medians (a few seconds)
    python benchmarks/bench_hill.py --rust     # also the core's old-vs-new side by side
    python benchmarks/bench_hill.py --scan     # also the fine-grid scan's Hill settings

``--scan``: the fine grid (101 x 111, R-R, N = 3, zeta = zeta_b = 0.05), one thread,
CPU time, with ``hill=False``, the default (Hill where the verdict is in doubt,
``hill_band`` 0.2) and ``hill=True`` (beside every monodromy), twice in turn, with the
solutions each cross-checks and the extra over ``hill=False``.

The former Hill's method (complex Hill matrix, full eigen-decomposition, truncation
clamp(N + 4, 8, 24)) is reachable only in the core (``hill_multipliers_dense``); its cost
is printed beside today's from the callgrind counts below, and ``--rust`` runs the
core's ``hill_profile`` test, which times both on the same series:

    cargo test --release -p ballbal-core --features studies --lib --no-run
    valgrind --tool=callgrind target/release/deps/ballbal_core-* --ignored --exact \\
        numerics::floquet::studies::hill_profile
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import time
from pathlib import Path

import polars as pl
from bench_periodic import match_error, median_time  # the script's own directory

import ballbal

# Instructions per Hill's-method call, standard case, measured with callgrind on
# 2026-11-23 (hill_profile, one run): (N, balls) -> (former dense, today's). Today's
# splits every merged group's separation modes off (three merged balls cost about what
# two do) and uses a smaller deflation window in the Schur iteration; before that:
# 16.6, 16.6, 26.3, 26.9 M.
CALLGRIND = {(3, 2): (146.9e6, 14.1e6), (8, 2): (347.7e6, 14.2e6),
             (3, 3): (234.4e6, 15.1e6), (8, 3): (610.1e6, 15.1e6)}

# The scan's verdict target (hill_target="verdict"), callgrind on 2026-11-23: the
# standard case N = 3 at H = 3 (42 + 14 rows) 4.3 M per call (the multipliers target
# 14.1 M at H = 6); over Tien (2011) grid (zeta = zeta_b = 0.05, N = 3, all three types,
# one thread, 190 solutions) Hill 1.19 G = 6.3 M per solution against the Magnus
# monodromy's 0.57 G = 3.0 M, 15 % of the scan's 7.85 G. 146 of the 190 solutions
# settle at H = 3, all at the first truncation tried. The fine grid (101 x 111, R-R,
# N = 3, 11 261 solutions; one thread, CPU time on a loaded machine): 10.0-12.0 s
# without Hill, 20.6 s with it, +70 to 100 %: a continuation-bound scan spends about
# as much per solution on everything else (warm solve, certificate, Magnus) as faer's
# real Schur of the 42-row Hill block costs, which is why scans run Hill only where the
# verdict is in doubt (hill_band; --scan prints the three settings).
# 2026-11-24: the verdict starts at H = 2 where 1.5 / sqrt(omega) allows it (omega >=
# 0.5625; hill_verdict_profile: about 2.3 M per Hill matrix at H = 2 against 4.2 M at
# H = 3): on a 26 x 28 R-R grid (840 solutions, callgrind) hill_verdict 5.49 M -> 4.80 M
# per solution; the fine grid's Hill extra 90-91 % -> 80 % of CPU time (one thread,
# alternating runs). faer's Schur iteration is 84 % of what remains.
SCAN_CALLGRIND = {"standard N=3, per call": 4.3e6, "Tien (2011) grid, per solution": 6.3e6,
                  "Magnus, Tien (2011) grid, per solution": 3.0e6}


def case(name: str, b: ballbal.Balancer, seed: ballbal.PeriodicSolution, N: int) -> None:
    sol = ballbal.periodic(b, "R-R", N=N, guess=seed,
                           options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    ref = ballbal.periodic(b, "R-R", N=N, guess=sol,
                           options=ballbal.PeriodicOptions(
                               floquet=ballbal.Floquet(rtol=1e-12, atol=1e-14, max_steps=10_000_000,
                                                       hill=False)))

    def run(**floquet):
        options = ballbal.PeriodicOptions(floquet=ballbal.Floquet(**floquet))
        return ballbal.periodic(b, "R-R", N=N, guess=sol, options=options)

    t_hb, _ = median_time(lambda: run(monodromy=False, hill=False), 15)
    t_rk, _ = median_time(lambda: run(rtol=1e-6, atol=1e-9, hill=False), 15)
    t_mg, _ = median_time(lambda: run(rtol=1e-6, hill=False, method="magnus"), 15)
    t_hill, h = median_time(lambda: run(monodromy=False, hill=True), 15)
    t_hv, hv = median_time(lambda: run(monodromy=False, hill=True, hill_target="verdict"), 15)
    rk, mg, hl, hvl = t_rk - t_hb, t_mg - t_hb, t_hill - t_hb, t_hv - t_hb
    err = match_error(h.hill_multipliers, ref.multipliers)
    err_v = match_error(hv.hill_multipliers, ref.multipliers)
    print(f"{name:>9} N = {N}: Hill {hl * 1e3:6.2f} ms (error {err:.1e}, "
          f"{h.hill_stability}); RK45 {rk * 1e3:5.2f} ms; Magnus {mg * 1e3:5.2f} ms; "
          f"Hill / RK45 {hl / rk:4.1f}, Hill / Magnus {hl / mg:4.1f}")
    print(f"{'':>9}        scan's verdict target: Hill {hvl * 1e3:6.2f} ms (error "
          f"{err_v:.1e}, {hv.hill_stability}); Hill / Magnus {hvl / mg:4.1f}")


def scan_settings() -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
    grid = {"Omega": (1.0, 2.0, 0.01), "eta": (0.4, 1.5, 0.01)}
    ballbal.scan(b, patterns=["R-R"], threads=1, Omega=[1.2], eta=[1.0])
    fl = ballbal.options.SCAN_DEFAULTS.floquet
    settings = {"hill=False": dataclasses.replace(fl, hill=False), "default (band)": fl,
                "hill=True": dataclasses.replace(fl, hill=True, hill_band=None)}
    cpu: dict[str, list[float]] = {k: [] for k in settings}
    checked: dict[str, int] = {}
    for _ in range(2):
        for k, floquet in settings.items():
            t = time.process_time()
            df = ballbal.scan(b, patterns=["R-R"], N=3, threads=1, **grid,
                              options=ballbal.ScanOptions(floquet=floquet))
            cpu[k].append(time.process_time() - t)
            ok = df.filter(pl.col("status") == "converged")
            checked[k] = int(ok["hill_stability"].is_not_null().sum())
            checked["solutions"] = ok.height
    base = min(cpu["hill=False"])
    print(f"\nfine grid, R-R, N = 3, one thread, CPU s (best of 2), "
          f"{checked['solutions']} solutions:")
    for k in settings:
        print(f"  {k:<15} {min(cpu[k]):6.2f} s  (+{100 * (min(cpu[k]) / base - 1):4.1f} %), "
              f"Hill on {checked[k]} solutions")


def main() -> None:
    base = dict(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, eta=(1.0, 1.0))
    b = ballbal.Balancer(**base, Omega=1.2)
    seed = ballbal.periodic(b, "R-R", N=8,
                            options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    hard = ballbal.Balancer(**{**base, "eta": (0.7, 0.7)}, Omega=1.0)
    hard_seed = ballbal.periodic(hard.replace(Omega=0.99), "R-R", N=8,
                                 options=ballbal.PeriodicOptions(
                                     floquet=ballbal.Floquet(hill=False)))
    print("Hill's method beside the monodromy it cross-checks (wall clock, medians):")
    for N in (3, 8):
        case("standard", b, seed, N)
        case("hard", hard, hard_seed, N)
    print("\ncallgrind instructions per Hill call, standard case (former dense -> today):")
    for (N, balls), (old, new) in CALLGRIND.items():
        print(f"  N = {N}, {balls} balls: {old / 1e6:6.1f} M -> {new / 1e6:5.1f} M "
              f"({old / new:4.1f} x)")
    print("\ncallgrind instructions, the scan's verdict target (see SCAN_CALLGRIND):")
    for k, v in SCAN_CALLGRIND.items():
        print(f"  {k}: {v / 1e6:4.1f} M")
    if "--scan" in sys.argv:
        scan_settings()
    if "--rust" in sys.argv:
        root = Path(__file__).resolve().parent.parent
        out = subprocess.run(
            ["cargo", "test", "--release", "-q", "-p", "ballbal-core", "--features",
             "studies", "--lib", "hill_profile", "--", "--ignored", "--nocapture"],
            cwd=root, capture_output=True, text=True, check=True).stdout
        print("\ncore, same series, one call each (today's hill vs hill_multipliers_dense):")
        print("\n".join("  " + ln for ln in out.splitlines() if ln.startswith("N=")))


if __name__ == "__main__":
    main()
