"""Peak memory of scans streamed to Parquet against grid size (issue 13).

Each size runs in its own process (peak RSS from ``resource.getrusage`` is a process's
high-water mark): an Omega x eta square grid of 10^4, 10^5 and 10^6 points scanned with
``out=`` and ``lazy=True`` (one chunk per thread in memory; the table stays on disk),
and, for contrast, the same grid held in memory without ``out=`` (up to 10^5 points).

Grid Omega 1.0-2.0 x eta 0.4-1.5 (mu 0.2, delta 50, zeta_b 0.1), R-R only,
``floquet=False`` (multipliers are null: rows a little smaller than with Floquet), two
settings:

* ``solved`` (``seeds=2, starts=2``): most points get a solution (about 0.6 ms a point
  on 2 threads), up to 10^5 points;
* ``cheap`` (``seeds=1, starts=1``): the one start per block finds no R-R, so every
  point is a ``not_found`` row after its perfect-balance check (about 0.15 ms a point):
  the setting that lets 10^6 points run in minutes. A row's size on disk and in memory
  hardly depends on the setting; the time does.

* ``floquet`` (the scan's defaults, N = 3, Floquet on; zeta_b 0.05): the issue-17 case,
  a 10^6-point R-R scan with multipliers, streamed; target under 5 minutes on 2
  cores and under 1 GiB. Only with ``--full`` at 10^6 (it occupies the machine for
  minutes); without it, 10^4 and 10^5 points and the 10^6 time extrapolated from 10^5.

The target is under 1 GiB at 10^6 points.

    python benchmarks/bench_scan_memory.py            # 10^4, 10^5 (cheap also 10^6)
    python benchmarks/bench_scan_memory.py --quick    # 10^4, 10^5
    python benchmarks/bench_scan_memory.py --floquet  # only the floquet setting, to 10^5
    python benchmarks/bench_scan_memory.py --floquet --full   # ... and the 10^6 run
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile

CHILD = r"""
import dataclasses, json, resource, sys, time
import numpy as np, polars as pl, ballbal
side, mode, setting, out = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
grid = dict(Omega=np.linspace(1.0, 2.0, side), eta=np.linspace(0.4, 1.5, side))
seeds = 2 if setting == "solved" else 1
d = ballbal.options.SCAN_DEFAULTS
options = ballbal.ScanOptions(floquet=dataclasses.replace(d.floquet, monodromy=False),
                              guess=dataclasses.replace(d.guess, seeds=seeds, starts=seeds))
kw = dict(patterns=["R-R"], options=options, threads=2, **grid)
model = ballbal.Balancer(zeta_b=0.1)
if setting == "floquet":
    kw = dict(patterns=["R-R"], N=3, threads=2, **grid)
    model = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
counts = getattr(ballbal._native, "scan_work_counts", lambda: [0] * 5)
w0 = counts()
t = time.perf_counter()
if mode == "streamed":
    lf = ballbal.scan(model, out=out, lazy=True, **kw)
    n = lf.select(pl.len()).collect().item()
    found = lf.filter(pl.col("status") == "converged").select(pl.len()).collect().item()
else:
    df = ballbal.scan(model, **kw)
    n, found = df.height, df.filter(pl.col("status") == "converged").height
dt = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
work = [b - a for a, b in zip(w0, counts())]
print(json.dumps(dict(points=side * side, rows=n, found=found, seconds=dt,
                      peak_mib=peak / 1024, import_mib=base / 1024, work=work)))
"""


def run(side: int, mode: str, setting: str) -> dict:
    with tempfile.TemporaryDirectory() as d:
        r = subprocess.run([sys.executable, "-c", CHILD, str(side), mode, setting,
                            f"{d}/scan"],
                           capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def main() -> None:
    quick = "--quick" in sys.argv
    if "--floquet" in sys.argv:
        floquet("--full" in sys.argv)
        return
    print(f"{'setting':<8} {'mode':<10} {'points':>9} {'rows':>9} {'found':>9} "
          f"{'seconds':>8} {'peak MiB':>9} {'after import':>12}")
    runs = [("solved", 100, "streamed"), ("solved", 100, "memory"),
            ("solved", 316, "streamed"), ("solved", 316, "memory"),
            ("cheap", 100, "streamed"), ("cheap", 316, "streamed")]
    if not quick:
        runs.append(("cheap", 1000, "streamed"))
    for setting, side, mode in runs:
        r = run(side, mode, setting)
        print(f"{setting:<8} {mode:<10} {r['points']:>9} {r['rows']:>9} {r['found']:>9} "
              f"{r['seconds']:>8.1f} {r['peak_mib']:>9.0f} {r['import_mib']:>12.0f}",
              flush=True)


def floquet(full: bool) -> None:
    """Also the work per row (``_native.scan_work_counts``): harmonic-balance solves
    (seeds' and continuation attempts'), certificates, Floquet analyses (solutions
    finished), and certificates spared on attempts that reached a known orbit."""
    print(f"{'points':>9} {'rows':>9} {'found':>9} {'seconds':>8} {'us/point':>9} "
          f"{'peak MiB':>9} {'after import':>12} {'solves/row':>10} {'certs/row':>9} "
          f"{'Floquet/row':>11} {'spared/row':>10}")
    sides = [100, 316] + ([1000] if full else [])
    last = None
    for side in sides:
        r = run(side, "streamed", "floquet")
        last = r
        seed, wave, cert, fin, spared = (c / r["rows"] for c in r["work"])
        print(f"{r['points']:>9} {r['rows']:>9} {r['found']:>9} {r['seconds']:>8.1f} "
              f"{1e6 * r['seconds'] / r['points']:>9.0f} {r['peak_mib']:>9.0f} "
              f"{r['import_mib']:>12.0f} {seed + wave:>10.2f} {cert:>9.2f} {fin:>11.2f} "
              f"{spared:>10.2f}", flush=True)
    if not full and last is not None:
        print(f"10^6 points at the 10^5 rate: about "
              f"{1e6 * last['seconds'] / last['points'] / 60:.1f} minutes")


if __name__ == "__main__":
    main()
