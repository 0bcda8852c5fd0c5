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
machine are noisy.

Side by side (harmonic balance at N = 24, the truncation whose periods match AUTO NTST
20's at Omega 0.93; CPU seconds of one thread, medians of ``--repeat``, the tools
interleaved run by run):

* (a) the matched branch, 1.2 -> BP -> LP -> back to 1.3 and 1.2 -> 0.93, with
  multipliers at every point (ballbal's defaults, ``BRANCH_DEFAULTS``; AUTO ISP 2) and
  without (Floquet off; AUTO ISP 0, which also drops its BP detection), and ballbal with
  ``periodic()``'s multipliers (RK45, Hill at every point: the branch default before),
  AUTO at each ``--ntst``; ballbal's steps capped (``ds_max`` 0.3) to about AUTO's number
  of points;
* (b) the downward run to each tool's own end: reach (distance to Omega*), time, and the
  period error at 0.93 against a collocation orbit on ``REF_NTST`` intervals;
* (c) the BP and fold curves in (Omega, eta) from eta 1 to 1.5: time and where each
  reaches eta 1.5 (AUTO: ISW 2 from the BP or LP at the smallest ``--ntst``, restarted
  once from the starting data it generates, the anchor's ISP 2: its time is the same
  with ISP 0; ballbal: ``periodic_curve`` without multipliers).

Each ratio is to AUTO's time at the smallest ``--ntst`` (with ISP 2 in (a)).

AUTO's side runs when ``AUTO_DIR`` names a built AUTO-07p source tree (``./configure &&
make``; nothing of AUTO is part of this project): the benchmark compiles the anchor's
``bal.f90`` with AUTO's flags into a temporary directory, writes its starting orbit
(``bal.dat``, the anchor's ``make_start.py`` recipe) there, and runs the executable on the
anchor's constants ``c.bal.up`` / ``c.bal.down`` with one OpenMP thread. The anchor is
``$BALLBAL_AUTO_ANCHOR``, or ``--anchor``, or ``../shared/anchors/auto07p`` beside the
repository.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import ballbal
from ballbal import _native
from ballbal.continuation import Branch, Continuation, periodic_branch, periodic_curve
from ballbal.options import PERIODIC_DEFAULTS

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


# ---- side by side with AUTO-07p ----------------------------------------------------

HB_N = 24
REF_NTST = 400
ETA_END = 1.5
AUTO_TYPES = {5: "LP", 6: "BP", 7: "PD", 8: "TR", -4: "UZ", 9: "EP", -9: "MX"}


class Auto:
    """The anchor's AUTO-07p set-up, compiled into ``work`` (a temporary directory)."""

    def __init__(self, auto_dir: Path, anchor: Path, work: Path) -> None:
        self.anchor, self.work = anchor, work
        shutil.copy(anchor / "bal.f90", work / "bal.f90")
        start = ballbal.periodic(balancer(1.2), "R-R", N=16)
        h = start.time_history(np.linspace(0.0, start.period, 401))
        cols = ["t", "x", "y", "b1", "b2", "dx", "dy", "db1", "db2"]
        np.savetxt(work / "bal.dat", np.column_stack([h[c].to_numpy() for c in cols]),
                   fmt="%24.16e")
        # the compile and link lines of AUTO's cmds/cmds.make (FFLAGS -g -fopenmp, OPT -O)
        flags = ["-g", "-fopenmp", "-O"]
        subprocess.run(["gfortran", *flags, "-c", "bal.f90", "-o", "bal.o"], cwd=work,
                       check=True)
        objs = sorted(str(o) for o in (auto_dir / "lib").glob("*.o"))
        subprocess.run(["gfortran", *flags, "bal.o", *objs, "-o", "bal.exe"], cwd=work,
                       check=True)

    def run(self, constants: str, extra: list[str], restart: str | None = None) -> dict:
        """One run: ``constants`` (an anchor file) with ``extra`` lines; ``restart``: the
        solution file (fort.8 text) to start from. CPU seconds of the child, the fort.7
        rows and the fort.8 text."""
        w = self.work
        lines = (self.anchor / constants).read_text().splitlines()
        if restart is not None:
            # a PAR line would override the restart point's parameters
            lines = [x for x in lines if not x.startswith("PAR ")]
        (w / "fort.2").write_text("\n".join([*lines, *extra]) + "\n")
        for f in ("fort.3", "fort.7", "fort.8", "fort.9"):
            (w / f).unlink(missing_ok=True)
        if restart is not None:
            (w / "fort.3").write_text(restart)
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([str(w / "bal.exe")], cwd=w, env=dict(os.environ, OMP_NUM_THREADS="1"),
                       capture_output=True, check=False)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime
        return {"cpu": cpu, "rows": auto_rows(w / "fort.7"),
                "fort8": (w / "fort.8").read_text() if (w / "fort.8").exists() else ""}


def auto_rows(path: Path) -> list[dict]:
    rows = []
    for line in path.read_text().splitlines() if path.exists() else []:
        f = line.split()
        if len(f) < 6 or f[0] == "0":
            continue
        try:
            vals = [float(v) for v in f[4:]]
        except ValueError:
            continue
        ty = int(f[2])  # on curves of special points AUTO adds 10 x the curve's type
        base = ty if abs(ty) < 10 else (abs(ty) % 10) * (1 if ty > 0 else -1)
        # columns: Omega, L2 norm, max x, max y, max b1, max b2, [eta on curves], T
        rows.append({"pt": abs(int(f[1])), "type": AUTO_TYPES.get(base, ""), "label": int(f[3]),
                     "Omega": vals[0], "T": vals[-1], "eta": vals[-2],
                     "split": abs(vals[4] - vals[5])})
    return rows


def interleaved(fs: dict[str, Callable[[], object]],
                repeat: int) -> dict[str, tuple[float, object]]:
    """Median CPU seconds of each callable (a callable returning a dict with ``cpu``, an
    AUTO run, is timed by that) and its last result, the callables taking turns."""
    times: dict[str, list[float]] = {k: [] for k in fs}
    last: dict[str, object] = {}
    for _ in range(repeat):
        for k, f in fs.items():
            t = time.process_time()
            out = f()
            dt = time.process_time() - t
            times[k].append(out["cpu"] if isinstance(out, dict) and "cpu" in out else dt)
            last[k] = out
    return {k: (statistics.median(v), last[k]) for k, v in times.items()}


def hb_matched(start: ballbal.PeriodicSolution, popts: ballbal.PeriodicOptions | None,
               steps: Continuation) -> dict:
    """ballbal's matched branch: 1.2 -> 1.3, on from there through BP and LP back to 1.3
    (the same stretch as AUTO's ``UZ2`` stop), and 1.2 -> 0.93."""
    a = periodic_branch(start, "Omega", range=(1.2, 1.3), options=steps,
                        periodic_options=popts)
    up = periodic_branch(a.solutions[-1], "Omega", range=(1.3, 1.5), options=steps,
                         periodic_options=popts)
    down = periodic_branch(start, "Omega", range=(0.93, 1.2), direction="backward",
                           options=steps, periodic_options=popts)
    ev = up.events
    first = {t: ev.filter(ev["type"] == t)["Omega"].to_list()[:1] for t in ("branch_point", "fold")}
    rows = [br.table for br in (a, up, down)]
    return {"points": sum(t.height for t in rows),
            "BP": (first["branch_point"] or [None])[0], "LP": (first["fold"] or [None])[0],
            "verdicts": [v for t in rows for v in t["stability"].to_list()],
            "T093": down.table["period"][-1]}


def reference_periods() -> dict[float, float]:
    """Periods at 0.95 and 0.93 on ``REF_NTST`` collocation intervals, each solved from the
    NTST 100 orbit there."""
    out = {}
    for om in (0.95, 0.93):
        g = ballbal.periodic(balancer(om), "R-R", method="collocation",
                             collocation=ballbal.Collocation(ntst=100))
        out[om] = ballbal.periodic(balancer(om), "R-R", guess=g, method="collocation",
                                   collocation=ballbal.Collocation(ntst=REF_NTST)).period
    return out


def auto_curve(auto: Auto, up: dict, kind: str, extra: list[str]) -> dict:
    """AUTO's locus of the branch's first ``kind`` (BP or LP) in (Omega, eta), to eta
    ``ETA_END``; where AUTO first only generates starting data (it then stops at an EP at
    the start), it is restarted from that."""
    label = next(r["label"] for r in up["rows"] if r["type"] == kind)
    cont = [f"IRS = {label}", "ISW = 2", "ICP = [5, 6, 11]", f"UZSTOP = {{6: {ETA_END}}}",
            "NMX = 300", "STOP = []", *extra]
    r = auto.run("c.bal.up", cont, restart=up["fort8"])
    cpu = r["cpu"]
    if r["rows"] and max(x["eta"] for x in r["rows"]) < 1.0 + 1e-6:
        label = r["rows"][-1]["label"]
        r = auto.run("c.bal.up", [*cont, f"IRS = {label}"], restart=r["fort8"])
        cpu += r["cpu"]
    end = r["rows"][-1] if r["rows"] else None
    return {"cpu": cpu, "points": len(r["rows"]),
            "Omega_end": end["Omega"] if end and abs(end["eta"] - ETA_END) < 1e-6 else None}


def side_by_side(ntsts: list[int], repeat: int, anchor: Path) -> None:
    auto_dir = os.environ.get("AUTO_DIR")
    start = ballbal.periodic(balancer(1.2), "R-R", N=HB_N)
    ref = reference_periods()
    bare = ballbal.PeriodicOptions(floquet=ballbal.Floquet(monodromy=False, hill=False))
    # AUTO's DSMAX 0.1 in its norm gives 91 points on the matched branch; this step cap
    # gives ballbal a comparable count (its default, ds_max 0.05 in the series' norm,
    # about 270).
    steps = Continuation(ds=0.01, ds_max=0.3)
    fs: dict[str, Callable[[], object]] = {
        "ballbal multipliers": lambda: hb_matched(start, None, steps),
        "ballbal bare": lambda: hb_matched(start, bare, steps),
        # multipliers as periodic() computes them (RK45, Hill everywhere): the branch
        # default before BRANCH_DEFAULTS
        "ballbal RK45 + Hill": lambda: hb_matched(start, PERIODIC_DEFAULTS, steps),
    }
    auto = None
    work = tempfile.TemporaryDirectory(prefix="bench_auto_")
    if auto_dir is None:
        print("AUTO-07p: not run (set AUTO_DIR to a built AUTO-07p source tree)")
    else:
        auto = Auto(Path(auto_dir), anchor, Path(work.name))
        for ntst in ntsts:
            for isp in (2, 0):
                ex = [f"NTST = {ntst}", f"ISP = {isp}"]
                fs[f"AUTO {ntst} ISP {isp}"] = (
                    lambda ex=ex: both_runs(auto, ex))
    print(f"(a) matched branch 1.2 -> BP -> LP -> 1.3 and 1.2 -> 0.93 (ballbal N = {HB_N}, "
          f"steps ds_max {steps.ds_max}; period at 0.93 against NTST {REF_NTST}: "
          f"{ref[0.93]:.10f})", flush=True)
    res = interleaved(fs, repeat)
    t_auto = res.get(f"AUTO {min(ntsts)} ISP 2", (None,))[0]
    for k, (t, out) in res.items():
        assert isinstance(out, dict)
        ratio = f", {t / t_auto:5.2f} x AUTO NTST {min(ntsts)} ISP 2" if t_auto else ""
        bp, lp = out.get("BP"), out.get("LP")
        print(f"  {k:22s} {t:6.3f} s{ratio}; {out['points']:4d} points, BP "
              f"{bp if bp is None else f'{bp:.10f}'}, LP {lp if lp is None else f'{lp:.10f}'}, "
              f"period error 0.93 {out['T093'] / ref[0.93] - 1:+.1e}"
              + ("" if out.get("merged_end", True) else " (left the merged branch at the BP)"),
              flush=True)
    if auto is None:
        return
    print(f"(b) down to each tool's end (reach = distance to Omega* {OMEGA_STAR}; ballbal: "
          f"the HB branch with its defaults, at=[0.95, 0.93])", flush=True)
    fs = {f"AUTO {n}": (lambda n=n: auto_down(auto.run("c.bal.down", [f"NTST = {n}"])))
          for n in ntsts}
    fs[f"ballbal HB N {HB_N}"] = lambda: hb_down(start)
    res = interleaved(fs, repeat)
    t_auto = res[f"AUTO {min(ntsts)}"][0]
    for k, (t, out) in res.items():
        assert isinstance(out, dict)
        print(f"  {k:22s} {t:6.3f} s ({t / t_auto:5.2f} x AUTO {min(ntsts)}), {out['points']} "
              f"points, reach {out['Omega'] - OMEGA_STAR:.1e} (T {out['T']:.3e}), period "
              f"error 0.95 {out[0.95] / ref[0.95] - 1:+.1e}, 0.93 {out[0.93] / ref[0.93] - 1:+.1e}",
              flush=True)
    print(f"(c) BP and fold curves in (Omega, eta), eta 1 -> {ETA_END}", flush=True)
    up = auto.run("c.bal.up", [f"NTST = {min(ntsts)}", "SP = ['BP0']"])
    up_bp = auto.run("c.bal.up", [f"NTST = {min(ntsts)}"])
    br = periodic_branch(start, "Omega", range=(1.2, 1.5), periodic_options=bare,
                         options=Continuation(ds=0.01, ds_max=0.3, max_points=60))
    fs = {}
    for kind, name, src in (("BP", "branch_point", up_bp), ("LP", "fold", up)):
        fs[f"AUTO {min(ntsts)} {kind} curve"] = (
            lambda kind=kind, src=src: auto_curve(auto, src, kind, [f"NTST = {min(ntsts)}"]))
        fs[f"ballbal {kind} curve"] = (lambda name=name: hb_curve(br, name, bare))
    res = interleaved(fs, repeat)
    for k, (t, out) in res.items():
        assert isinstance(out, dict)
        end = out["Omega_end"]
        kind = k.split()[-2]
        ratio = t / res[f"AUTO {min(ntsts)} {kind} curve"][0]
        print(f"  {k:22s} {t:6.3f} s ({ratio:5.2f} x AUTO), {out['points']} points, Omega at "
              f"eta {ETA_END}: {end if end is None else f'{end:.10f}'}", flush=True)
    work.cleanup()


def hb_down(start: ballbal.PeriodicSolution) -> dict:
    """ballbal's HB branch from 1.2 down to where it stops by itself, with its defaults."""
    br = periodic_branch(start, "Omega", range=(0.9, 1.2), direction="backward",
                         at=[0.95, 0.93])
    ev = br.events.filter(br.events["type"] == "user")
    at = dict(zip(ev["Omega"].to_list(), ev["period"].to_list(), strict=True))
    t = br.table
    return {"points": t.height, "Omega": t["Omega"][-1], "T": t["period"][-1],
            **{om: next((v for o, v in at.items() if abs(o - om) < 1e-9), float("nan"))
               for om in (0.95, 0.93)}}


def auto_down(out: dict) -> dict:
    """AUTO's downward run: reach, last period, periods at its UZ points."""
    rows = out["rows"]
    lo = min(rows, key=lambda r: r["Omega"])
    uz = [r for r in rows if r["type"] == "UZ"]
    return {"cpu": out["cpu"], "points": len(rows), "Omega": lo["Omega"], "T": lo["T"],
            **{om: next((r["T"] for r in uz if abs(r["Omega"] - om) < 1e-6), float("nan"))
               for om in (0.95, 0.93)}}


def both_runs(auto: Auto, extra: list[str]) -> dict:
    """AUTO's matched branch: ``c.bal.up`` (to the second UZ at 1.3) and ``c.bal.down``
    stopped at 0.93; the BP and LP are the up run's first."""
    up = auto.run("c.bal.up", extra)
    down = auto.run("c.bal.down", [*extra, "UZR = {5: 0.95}", "UZSTOP = {5: 0.93}"])
    first = {t: next((r["Omega"] for r in up["rows"] if r["type"] == t), None)
             for t in ("BP", "LP")}
    merged = bool(up["rows"]) and up["rows"][-1]["split"] < 1e-6
    return {"cpu": up["cpu"] + down["cpu"],
            "points": len(up["rows"]) + len(down["rows"]), **first,
            "T093": down["rows"][-1]["T"] if down["rows"] else float("nan"),
            "merged_end": merged}


def hb_curve(br: Branch, name: str, popts: ballbal.PeriodicOptions) -> dict:
    c = periodic_curve(br, name, "eta", range=(1.0, ETA_END), range1=(0.5, 3.0),
                       periodic_options=popts, options=Continuation(ds=0.02, ds_max=0.1))
    t = c.table
    hit = t.filter((t["eta"] - ETA_END).abs() < 1e-9)
    return {"points": t.height, "Omega_end": hit["Omega"][0] if hit.height else None}


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
    ap.add_argument("--anchor", default=os.environ.get(
        "BALLBAL_AUTO_ANCHOR",
        str(Path(__file__).resolve().parents[2] / "shared" / "anchors" / "auto07p")))
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
    side_by_side(a.ntst, a.repeat, Path(a.anchor))


if __name__ == "__main__":
    main()
