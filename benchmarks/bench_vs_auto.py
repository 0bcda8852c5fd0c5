"""ballbal's collocation against AUTO-07p on the merged R-R branch of issue 33 (mu 0.2,
zeta 0.05, zeta_b 0.1, delta 50, eta (1, 1)), continued down in Omega from 1.2 towards
its infinite-period end (the saddle-node on the invariant circle, Omega* = 0.917140455 by
AUTO-07p; the reach below is measured from it).

    python benchmarks/bench_vs_auto.py                  # ballbal's side
    AUTO_DIR=... python benchmarks/bench_vs_auto.py     # and AUTO's, same run

ballbal's side, per NTST (one thread, medians of ``--repeat`` runs, default 3): the
matched run 1.2 -> 0.93 (natural continuation of the collocation orbit, no multipliers)
and its periods at 0.95 and 0.93 against the same orbits re-solved on a mesh four times
as fine; the downward run to the end (steps halved until below 1e-13): its reach and
time (and the last orbit's mesh error indicator, the largest ``h^(NCOL+1)
|y^(NCOL+1)|``: above ~0.1 that orbit is no longer resolved). Wall times on a shared
machine are noisy. AUTO's side runs the anchor's ``run_auto.py`` (``../shared/anchors/auto07p`` or
``--anchor``) and prints its summary as it comes.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import ballbal
from ballbal import _native

PARAMS = dict(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, eta=(1.0, 1.0))
OMEGA_STAR = 0.917140455


def balancer(om: float) -> ballbal.Balancer:
    return ballbal.Balancer(**PARAMS, Omega=om)


def follow(start: ballbal.PeriodicSolution, target: float, step: float, min_step: float,
           ntst: int) -> dict:
    assert start.mesh is not None and start.mesh_states is not None
    return _native.collocation_follow(
        start.balancer, "Omega", start.mesh, np.ascontiguousarray(start.mesh_states.ravel()),
        start.period, [float(w) for w in start.winding], target, step, min_step,
        ballbal.Collocation(ntst=ntst))


def median_time(f, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def period_error(om: float, period: float, start: ballbal.PeriodicSolution,
                 ntst: int) -> float:
    """Relative difference to the orbit at ``om`` on a mesh four times as fine."""
    fine = ballbal.periodic(balancer(om), "R-R", guess=start, method="collocation",
                            collocation=ballbal.Collocation(ntst=4 * ntst))
    return period / fine.period - 1


def branch_runs(repeat: int) -> None:
    """``periodic_branch`` itself (multipliers and certificates at every row): the
    downward run to the end with every default (``method="auto"``: harmonic balance,
    then collocation), and the matched branch (1.2 -> 1.3, and 1.2 -> 0.93) by harmonic
    balance (N = 24, the N that matches AUTO NTST 20's period accuracy at 0.93) and by
    collocation (NTST 50)."""
    from ballbal.continuation import periodic_branch

    start = ballbal.periodic(balancer(1.2), "R-R")
    t_down, down = median_time(lambda: periodic_branch(
        start, "Omega", range=(0.9, 1.2), direction="backward", at=[0.95, 0.93]), repeat)
    tb = down.table
    methods = tb["method"].to_list()
    k = methods.index("collocation") if "collocation" in methods else len(methods)
    switch = tb["Omega"][k] if k < len(methods) else float("nan")
    ip = down.events.filter(down.events["type"] == "infinite_period")
    user = down.events.filter(down.events["type"] == "user")
    print(f"periodic_branch defaults, 1.2 -> end: {t_down:6.3f} s, {tb.height} rows "
          f"({k} hb, {tb.height - k} collocation; switch at Omega {switch:.6f}), stop "
          f"{down.stop!r}, reach {tb['Omega'][-1] - OMEGA_STAR:.1e} (T {tb['period'][-1]:.3e}),"
          f" end event {ip['Omega'][0] - OMEGA_STAR if ip.height else float('nan'):+.1e} "
          f"from Omega*; periods at {user['Omega'].to_list()}: {user['period'].to_list()}",
          flush=True)
    times = {}
    for name, kw in (("hb N=24", {"N": 24, "method": "hb"}),
                     ("collocation NTST 50", {"method": "collocation"})):
        def matched(kw=kw):
            up = periodic_branch(start, "Omega", range=(1.2, 1.3), direction="forward",
                                 **kw)
            dn = periodic_branch(start, "Omega", range=(0.93, 1.2), direction="backward",
                                 **kw)
            return up, dn
        t, (up, dn) = median_time(matched, repeat)
        times[name] = t
        rows = up.table.height + dn.table.height
        print(f"matched branch with multipliers, {name}: {t:6.3f} s, {rows} rows "
              f"({1e3 * t / rows:.1f} ms per row), stops {up.stop!r} / {dn.stop!r}, "
              f"T(0.93) {dn.table['period'][-1]:.9f}", flush=True)
    h, c = times["hb N=24"], times["collocation NTST 50"]
    print(f"ratio collocation / hb on the matched branch: {c / h:.2f}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--ntst", type=int, nargs="+", default=[20, 50, 100])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--anchor", default=str(Path(__file__).resolve().parents[2]
                                            / "shared" / "anchors" / "auto07p"))
    a = ap.parse_args()
    print("ballbal (collocation, natural continuation in Omega; one thread)")
    for ntst in a.ntst:
        start = ballbal.periodic(balancer(1.2), "R-R", method="collocation",
                                 collocation=ballbal.Collocation(ntst=ntst))
        t_matched, br = median_time(lambda s=start, n=ntst: follow(s, 0.93, 0.05, 1e-6, n),
                                    a.repeat)
        assert isinstance(br, dict)
        errs = []
        for om in (0.95, 0.93):
            part = follow(start, om, 0.05, 1e-6, ntst)
            guess = ballbal.periodic(balancer(om), "R-R", method="collocation",
                                     collocation=ballbal.Collocation(ntst=ntst))
            errs.append(period_error(om, part["period"][-1], guess, ntst))
        t_down, down = median_time(
            lambda s=start, n=ntst: follow(s, 0.9, 0.05, 1e-13, n), a.repeat)
        assert isinstance(down, dict)
        reach = down["param"][-1] - OMEGA_STAR
        print(f"NTST {ntst:4d}: 1.2 -> 0.93 {t_matched:6.3f} s ({len(br['param'])} points), "
              f"period error 0.95 {errs[0]:+.1e}, 0.93 {errs[1]:+.1e}; down to the end "
              f"{t_down:6.3f} s ({len(down['param'])} points), reach {reach:.1e} "
              f"(T {down['period'][-1]:.3e}, mesh indicator {down['mesh_error'][-1]:.1e})",
              flush=True)
    branch_runs(a.repeat)
    if "AUTO_DIR" not in os.environ:
        print("AUTO-07p: not run (set AUTO_DIR to a built AUTO-07p source tree)")
        return
    print("AUTO-07p (the anchor's run_auto.py)", flush=True)
    subprocess.run([sys.executable, "run_auto.py", "--ntst", *map(str, a.ntst), "--repeat",
                    str(a.repeat)], cwd=a.anchor, check=True)


if __name__ == "__main__":
    main()
