"""Scan throughput, including Floquet, on 1 and 2 threads, side by side:

* Tien (2011) grid (Omega 1.0-2.0, eta 0.4-1.5, step 0.1; mu 0.2, delta 50), all three
  two-ball types, at the standard point (zeta = zeta_b = 0.05) and at zeta_b = 0.1;
* the fine grid (101 x 111, step 0.01) for R-R.

Each at N = 3 and N = 8 (the fine grid at N = 3 with ``--quick``). Targets (issue 17):
Tien (2011) grid, all three types, at most 0.35 s on 1 thread and 0.2 s on 2; 1-to-2-thread
speed-up at least 1.85.

Per-stage costs (one thread, from ``_native.scan_stage_seconds``): perfect-balance
checks, seed simulations with their solves, continuation waves (harmonic balance and
Floquet of every continued solution), row building, and table building (columns and
Python per chunk); Floquet's share is the difference to a run with ``floquet=False``,
of which Hill's cross-check of the doubtful verdicts (the default ``hill_band``) is the
difference to ``hill=False``; beside it, what ``hill=True`` (Hill beside every monodromy)
would add instead.

``--old PATH``: also run every row with an older build (a directory holding the
``ballbal`` package, put first on ``PYTHONPATH`` in a subprocess), printed beside.

    python benchmarks/bench_scan.py                       # everything (minutes)
    python benchmarks/bench_scan.py --quick               # Omega-eta map grids, N = 3
    python benchmarks/bench_scan.py --fine                # fine grid, profiled runs only
    python benchmarks/bench_scan.py --quick --old /work/ref/before_pkg

The hardware's own ceiling for the 1-to-2 speed-up is printed beside it: the same
one-thread scan run alone, then in two processes at once (no shared work, no
synchronisation). Two processes that each slow down by a factor s when they share the
machine give a throughput ratio 2 / s: a threaded scan cannot beat that, whatever its
load balance, so the speed-up's shortfall splits into the machine's part (2 - ceiling)
and the scan's own (ceiling - speed-up).

Parallel efficiency per stage (from ``_native.scan_profile``): on 2 threads, the busy
time (summed durations of the stage's tasks on both pool threads) over 2 x the stage's
wall time, beside the one-thread wall and the two-thread bound the stage's steps allow
(per barrier step max(busy / 2, longest task), from the one-thread run's task times):
the one-thread total over the summed bounds is the speed-up the scan's structure
allows, apart from the machine. The waves are also run with
their target points started in point order (``_native.scan_wave_order(False)``), as
before longest-first ordering.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

MAP_GRID = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
FINE = {"Omega": (1.0, 2.0, 0.01), "eta": (0.4, 1.5, 0.01)}
ALL = ("R-R", "O-O", "R-O")

CHILD = r"""
import dataclasses, json, sys, time
import ballbal
from ballbal import _native
grid, pats, N, zb, repeat = json.loads(sys.argv[1])
grid = {k: tuple(v) for k, v in grid.items()}
b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=zb, delta=50.0)
out = {}
ballbal.scan(b, patterns=pats, N=N, threads=1, Omega=(1.0, 1.1, 0.1), eta=(1.0, 1.1, 0.1))
# repeat 0: only the profiled runs, once each (the fine grid within a minute)
light = repeat == 0
repeat = max(repeat, 1)
for threads in () if light else (1, 2):
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        df = ballbal.scan(b, patterns=pats, N=N, threads=threads, **grid)
        best = min(best, time.perf_counter() - t)
    out[threads] = best
stages = getattr(_native, "scan_stage_seconds", None)
if stages is not None and not light:
    s0 = stages()
    t = time.perf_counter()
    ballbal.scan(b, patterns=pats, N=N, threads=1, **grid)
    total = time.perf_counter() - t
    s1 = stages()
    out["stages"] = [y - x for x, y in zip(s0, s1)] + [total]
    t = time.perf_counter()
    fl = ballbal.options.SCAN_DEFAULTS.floquet
    def floquet(**changes):
        return ballbal.ScanOptions(floquet=dataclasses.replace(fl, **changes))
    ballbal.scan(b, patterns=pats, N=N, threads=1, options=floquet(monodromy=False), **grid)
    out["no_floquet"] = time.perf_counter() - t
    t = time.perf_counter()
    ballbal.scan(b, patterns=pats, N=N, threads=1, options=floquet(hill=True, hill_band=None),
                 **grid)
    out["hill"] = time.perf_counter() - t
    t = time.perf_counter()
    ballbal.scan(b, patterns=pats, N=N, threads=1, options=floquet(hill=False), **grid)
    out["no_hill"] = time.perf_counter() - t
prof = getattr(_native, "scan_profile", None)
if prof is not None:
    order = _native.scan_wave_order
    out["profile"] = {}
    for key, threads, longest in (("1", 1, True), ("2", 2, True), ("2 plain", 2, False)):
        order(longest)
        best = None
        for _ in range(repeat):
            p0, s0 = prof(), _native.scan_stage_seconds()
            t = time.perf_counter()
            df = ballbal.scan(b, patterns=pats, N=N, threads=threads, **grid)
            total = time.perf_counter() - t
            p1, s1 = prof(), _native.scan_stage_seconds()
            run = {"stages": [[y - x for x, y in zip(a, c)] for a, c in zip(p0, p1)],
                   "table": s1[4] - s0[4], "total": total}
            if best is None or total < best["total"]:
                best = run
        out["profile"][key] = best
    order(True)
    if light:
        out[1], out[2] = out["profile"]["1"]["total"], out["profile"]["2"]["total"]
sols = df.filter(df["status"] == "converged")
out["points"] = df.select(list(grid)).unique().height
out["sols"] = sols.height
out["stable"] = int((sols["stability"] == "stable").sum())
print(json.dumps(out))
"""


SOLO = r"""
import json, sys, time
import ballbal
grid, pats, N, zb, repeat = json.loads(sys.argv[1])
grid = {k: tuple(v) for k, v in grid.items()}
b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=zb, delta=50.0)
ballbal.scan(b, patterns=pats, N=N, threads=1, Omega=(1.0, 1.1, 0.1), eta=(1.0, 1.1, 0.1))
repeat = max(repeat, 1)
best = float("inf")
for _ in range(repeat):
    t = time.perf_counter()
    ballbal.scan(b, patterns=pats, N=N, threads=1, **grid)
    best = min(best, time.perf_counter() - t)
print(best)
"""


def ceiling(grid: dict, pats: tuple[str, ...], N: int, zb: float, repeat: int) -> float:
    """Throughput of two one-thread scans in two processes at once, over one alone."""
    arg = json.dumps([grid, list(pats), N, zb, repeat])

    def run(k: int) -> list[float]:
        ps = [subprocess.Popen([sys.executable, "-c", SOLO, arg], stdout=subprocess.PIPE,
                               text=True) for _ in range(k)]
        return [float(p.communicate()[0]) for p in ps]

    alone = run(1)[0]
    pair = max(run(2))
    return 2 * alone / pair


def measure(grid: dict, pats: tuple[str, ...], N: int, zb: float, repeat: int,
            path: str | None = None) -> dict:
    env = dict(os.environ)
    if path is not None:
        env["PYTHONPATH"] = path + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run([sys.executable, "-c", CHILD,
                        json.dumps([grid, list(pats), N, zb, repeat])],
                       capture_output=True, text=True, check=True, env=env)
    return json.loads(r.stdout)


STAGES = ("balance", "seeds", "waves", "glue", "rows")


def efficiency(label: str, N: int, prof: dict) -> list[str]:
    """Per stage on 2 threads: wall, busy (summed task durations of both threads),
    parallel efficiency busy / (2 wall); beside it the one-thread wall and the two-thread
    bound from the one-thread run's tasks (max(busy / 2, longest task) per step, summed),
    and the same waves with their target points started in point order ("plain")."""
    one, two, plain = prof["1"], prof["2"], prof["2 plain"]
    lines = [f"{label}, N {N}: stage       1 thr s  2 thr s  busy 2 s  efficiency  "
             f"bound 2 s  (waves in point order: 2 thr s, efficiency)"]
    bound = 0.0
    busy1 = busy2 = 0.0
    for i, name in enumerate(STAGES):
        w1, b1_bound = one["stages"][i][0], one["stages"][i][1]
        w2 = two["stages"][i][0]
        busy = sum(two["stages"][i][5:])
        busy1 += sum(one["stages"][i][5:])
        busy2 += busy
        bound += b1_bound
        eff = f"{busy / (2 * w2):>10.2f}" if w2 > 0 else f"{'-':>10}"
        pw = plain["stages"][i][0]
        pe = sum(plain["stages"][i][5:]) / (2 * pw) if pw > 0 else float("nan")
        lines.append(f"{'':>24}{name:<10} {w1:>8.3f} {w2:>8.3f} {busy:>9.3f} {eff} "
                     f"{b1_bound:>10.3f}   ({pw:.3f}, {pe:.2f})")
    t1, t2 = one["table"], two["table"]
    # The calling thread builds a chunk's table while the pool computes the next ones:
    # on one thread it uses the otherwise idle core, on two it takes a share of them.
    compute1 = sum(one["stages"][i][0] for i in range(len(STAGES)))
    bound = max(bound, (compute1 + t1) / 2)
    lines.append(f"{'':>24}{'table':<10} {t1:>8.3f} {t2:>8.3f}   (serial, on the calling thread)")
    T1, T2 = one["total"], two["total"]
    slow = busy2 / busy1 if busy1 > 0 else float("nan")
    lines.append(f"{'':>24}total      {T1:>8.3f} {T2:>8.3f}  speed-up {T1 / T2:.2f} "
                 f"(waves in point order {T1 / plain['total']:.2f}); allowed by the scan's "
                 f"steps {T1 / bound:.2f} (the table sharing the cores); timed tasks take "
                 f"{slow:.2f} x as long on 2 threads as on 1 (the machine's share); "
                 f"whole run: timed busy / (2 x wall) "
                 f"{busy2 / (2 * T2):.2f} (blocks that run at once make per-stage walls "
                 f"overlap: then only this one counts)")
    return lines


def main() -> None:
    quick = "--quick" in sys.argv
    old = sys.argv[sys.argv.index("--old") + 1] if "--old" in sys.argv else None
    rows: list[tuple[str, dict, tuple[str, ...], int, float, int]] = [
        ("thesis, zeta_b 0.05", MAP_GRID, ALL, 3, 0.05, 3),
        ("thesis, zeta_b 0.1", MAP_GRID, ALL, 3, 0.1, 3)]
    if "--fine" in sys.argv:
        rows = [("fine 101x111, zb 0.05", FINE, ("R-R",), 3, 0.05, 0)]
    elif not quick:
        rows += [("thesis, zeta_b 0.05", MAP_GRID, ALL, 8, 0.05, 3),
                 ("thesis, zeta_b 0.1", MAP_GRID, ALL, 8, 0.1, 3),
                 ("fine 101x111, zb 0.05", FINE, ("R-R",), 3, 0.05, 1)]
    print(f"{'grid':<24} {'types':<12} {'N':>2} {'points':>6} {'sols':>5} {'stable':>6} "
          f"{'1 thr s':>8} {'2 thr s':>8} {'speed-up':>8} {'ceiling':>7}"
          + (f" {'old 1 thr':>9} {'old 2 thr':>9} {'old s-up':>8} {'new/old 1':>9}"
             if old else ""))
    stage_lines = []
    eff_lines: list[str] = []
    for label, grid, pats, N, zb, repeat in rows:
        t0 = time.perf_counter()
        new = measure(grid, pats, N, zb, repeat)
        line = (f"{label:<24} {'/'.join(pats):<12} {N:>2} {new['points']:>6} "
                f"{new['sols']:>5} {new['stable']:>6} {new['1']:>8.3f} {new['2']:>8.3f} "
                f"{new['1'] / new['2']:>8.2f} {ceiling(grid, pats, N, zb, repeat):>7.2f}")
        if old:
            o = measure(grid, pats, N, zb, repeat, old)
            line += (f" {o['1']:>9.3f} {o['2']:>9.3f} {o['1'] / o['2']:>8.2f} "
                     f"{new['1'] / o['1']:>9.2f}")
            if (o["sols"], o["stable"]) != (new["sols"], new["stable"]):
                line += f"  (old: {o['sols']} sols, {o['stable']} stable)"
        print(line, flush=True)
        if "stages" in new:
            pb, seeds, waves, rows_, table, total = new["stages"]
            stage_lines.append(
                f"{label:<24} N {N}: total {total:.3f} s = balance {pb:.3f} + seeds "
                f"{seeds:.3f} + continuation {waves:.3f} + rows {rows_:.3f} + table "
                f"{table:.3f} + rest {total - pb - seeds - waves - rows_ - table:.3f}; "
                f"Floquet ~{total - new['no_floquet']:.3f}, of it Hill in the band "
                f"~{total - new['no_hill']:.3f}; Hill beside every monodromy would add "
                f"{new['hill'] - new['no_hill']:.3f} instead")
        if "profile" in new:
            eff_lines += efficiency(label, N, new["profile"])
        del t0
    if eff_lines:
        print("\nparallel efficiency per stage:")
        print("\n".join(eff_lines))
    if stage_lines:
        print("\nper stage, one thread (seconds):")
        print("\n".join(stage_lines))


if __name__ == "__main__":
    main()
