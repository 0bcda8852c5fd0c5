"""Basins of attraction (Tien's (2011) figures 4-15 and 4-16: mu 0.2, zeta 0.05, zeta_b
0.05, delta 50, eta 0.7, Omega 1.2 and 1.35, starts at rest in the ground frame).

Grids are small (a few dozen starts) and the physics lets t_end stay at Tien's (2011)
1000: the perfect balance's slowest decay rate there is 0.004 (Omega 1.2) to 0.04, and
the R-R orbit's largest nontrivial multiplier 0.58 (Omega 1.35) per period of 17, so
both are settled well within 1000; every start costs a few milliseconds."""

from typing import Any

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.basins import BasinOptions, basins
from ballbal.exceptions import ParameterError


def standard(omega: float) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=omega,
                            eta=(0.7, 0.7))


@pytest.fixture(scope="module")
def maps() -> dict[float, ballbal.basins.Basins]:
    return {om: basins(standard(om), n=8) for om in (1.2, 1.35)}


def test_rotating_fraction_falls_with_speed(maps):
    # Figure 4-15: "most" starts rotate at 1.2; figure 4-16: only a band about the
    # diagonal at 1.35, the rest settle on the perfect balance.
    p12, se12 = maps[1.2].rotating_fraction()
    p135, se135 = maps[1.35].rotating_fraction()
    assert p12 > 0.5
    assert p135 < 0.25
    assert p12 - p135 > 3 * np.hypot(se12, se135)
    rot = maps[1.35].table.filter(pl.col("label").is_in(ballbal.basins.ROTATING))
    gap = np.abs(np.angle(np.exp(1j * (rot["b1"] - rot["b2"]).to_numpy())))
    assert rot.height > 0 and gap.max() < 1.0
    rest = maps[1.35].table.filter(pl.col("label") == "perfect_balance")
    assert rest.height > 0.7 * maps[1.35].table.height


def test_labels_agree_with_an_independent_long_simulation(maps):
    # ballbal.simulate at tight tolerances for 3000 time units: rotating labels turn,
    # perfect balance ends at x = y = 0 with the balls at rest on the disk.
    for om, res in maps.items():
        rows = res.table.unique(subset=["label"], keep="first", maintain_order=True)
        for r in rows.iter_rows(named=True):
            m = standard(om)
            y0 = [0, 0, r["b1"], r["b2"], 0, 0, -om, -om]
            df = ballbal.simulate(m, y0, t_eval=np.linspace(2700, 3000, 601), t0=0.0,
                                  rtol=1e-10, atol=1e-12)
            turns = abs(df["b1"][-1] - df["b1"][0]) / (2 * np.pi)
            if r["label"] in ballbal.basins.ROTATING:
                assert turns > 5, (om, r)
                rate = -(df["b1"][-1] - df["b1"][0]) / 300
                # A torus (separated R-R) has no single rate: its mean over a window
                # moves by a few per cent with the window (the early stop reads it
                # from an earlier one); a periodic class's is exact.
                tol = 0.03 if r["label"] == "separated_R-R" else 0.02
                assert abs(rate - r["rate1"]) < tol * abs(rate)
            else:
                assert r["label"] == "perfect_balance", (om, r)
                assert turns < 0.01
                assert np.hypot(df["x"][-1], df["y"][-1]) < 1e-3


def test_no_label_changes_between_1000_and_3000():
    for om in (1.2, 1.35):
        r = basins(standard(om), n=5, settle_check=True)
        assert r.table["settled"].all(), r.table.filter(~pl.col("settled"))
        assert set(r.table["label"]) <= {"perfect_balance", "merged_R-R", "separated_R-R"}


def test_exchange_symmetry():
    # Identical balls: swapping them swaps the motion, so the label must not change.
    ax = np.array([0.4, 1.3, 2.5, 3.6, 4.9])
    t = basins(standard(1.35), b1=ax, b2=ax).table
    lab = {(round(a, 9), round(b, 9)): lab for a, b, lab in
           zip(t["b1"], t["b2"], t["label"], strict=True)}
    for (a, b), v in lab.items():
        assert lab[(b, a)] == v, (a, b)


def test_classes_link_to_the_solutions_they_converge_to(maps):
    link = maps[1.35].link()
    rr = link.filter(pl.col("label") == "merged_R-R").row(0, named=True)
    # Mean ball rate of the simulated starts against the harmonic-balance orbit's omega
    # (an independent computation: Newton on Fourier coefficients).
    assert rr["kind"] == "R-R" and rr["status"] == "converged"
    assert rr["stability"] == "stable"
    assert abs(rr["mean_rate"] - rr["omega"]) < 1e-4 * rr["omega"]
    pb = link.filter(pl.col("label") == "perfect_balance").row(0, named=True)
    assert pb["mean_rate"] == 0.0 and pb["stability"] == "stable"


def test_same_table_on_one_and_two_threads():
    m = standard(1.2)
    a = basins(m, samples=12, seed=3, threads=1, chunk=5)
    b = basins(m, samples=12, seed=3, threads=2, chunk=4)
    assert a.table.equals(b.table)
    assert a.random and a.table["b1"].min() >= 0 and a.table["b1"].max() < 2 * np.pi


def test_default_grid_avoids_the_diagonal():
    t = basins(standard(1.35), n=4, t_end=60, options=BasinOptions(window=30)).table
    assert t.height == 16
    gap = np.abs(np.angle(np.exp(1j * (t["b1"] - t["b2"]).to_numpy())))
    assert gap.min() > 0.5


def test_errors_name_the_parameter():
    m = standard(1.2)
    with pytest.raises(ParameterError) as e:
        basins(m, n=2, t_end=-1.0)
    assert e.value.parameter == "t_end"
    with pytest.raises(ParameterError) as e:
        basins(m, n=2, options=BasinOptions(merge_tol=4.0))
    assert e.value.parameter == "merge_tol"
    with pytest.raises(ParameterError) as e:
        basins(m, b1=[0.1])
    assert e.value.parameter == "b2"
    with pytest.raises(ParameterError) as e:
        basins(ballbal.Balancer(eta=(0.7, 0.7, 0.7)), n=2)
    assert e.value.parameter == "model"


def test_plot(tmp_path, maps):
    import matplotlib

    matplotlib.use("Agg")
    ax = ballbal.basins.plot_basins(maps[1.35], title="Omega 1.35")
    ax.figure.savefig(tmp_path / "b.png")
    assert (tmp_path / "b.png").stat().st_size > 1000


INTERRUPTED = """
import sys, time, warnings, ballbal
from ballbal.basins import basins
m = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2, eta=(0.7, 0.7))
out = sys.argv[2] if len(sys.argv) > 2 else None
print("ready", flush=True)
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    r = basins(m, n=int(sys.argv[1]), threads=2, chunk=16, out=out)
print("ROWS", r.table.height, "WARNED",
      sum(issubclass(x.category, ballbal.ScanInterrupted) for x in w),
      "INTERRUPTED", r.interrupted, "AT", time.monotonic(), flush=True)
"""


def _sigint(args: list[str], ready) -> tuple[str, str, float]:
    """Runs INTERRUPTED with `args`, sends SIGINT once `ready()` holds; returns (stdout,
    stderr, seconds from the signal to the returned table)."""
    import signal
    import subprocess
    import sys
    import time

    p = subprocess.Popen([sys.executable, "-c", INTERRUPTED, *args], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    deadline = time.time() + 120
    while not ready() and time.time() < deadline:
        time.sleep(0.005)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 0, (out, err)
    assert "PanicException" not in err and "panicked" not in err, err
    return out, err, float(out.split()[-1]) - sent


def test_ctrl_c_returns_the_finished_starts_within_a_second():
    # A real SIGINT to a child computing a grid that takes far longer than the delay:
    # the call returns the finished chunks (whole chunks of 16 starts, in order) with a
    # ScanInterrupted warning, as scans do, instead of raising KeyboardInterrupt.
    import time

    t0 = time.time()
    out, err, lag = _sigint(["100"], lambda: time.time() - t0 > 3.0)
    words = out.split()
    rows, warned, flag = int(words[1]), int(words[3]), words[5]
    assert warned == 1 and flag == "True", out
    assert rows % 16 == 0 and rows < 100 * 100, rows
    assert lag < 1.0, lag


def test_ctrl_c_keeps_chunks_on_disk_and_a_rerun_resumes(tmp_path):
    d = tmp_path / "b"
    out, err, _ = _sigint(["16", str(d)], lambda: len(list(d.glob("chunk-*.parquet"))) >= 3)
    words = out.split()
    kept = len(list(d.glob("chunk-*.parquet")))
    assert int(words[3]) == 1 and words[5] == "True", out
    assert 3 <= kept < 16, kept
    assert int(words[1]) == 16 * kept  # the table returned is what is on disk
    m = standard(1.2)
    before = {f: f.stat().st_mtime_ns for f in d.glob("chunk-*.parquet")}
    resumed = basins(m, n=16, threads=2, chunk=16, out=d)
    assert not resumed.interrupted
    # the kept chunks were not recomputed, and the table is the uninterrupted one
    assert {f: f.stat().st_mtime_ns for f in before} == before
    whole = basins(m, n=16, threads=2, chunk=16)
    assert resumed.table.equals(whole.table)


def test_resume_from_a_directory_redoes_only_a_damaged_chunk(tmp_path):
    import os
    import warnings

    from ballbal.exceptions import ScanStoreError, ScanStoreWarning

    m = standard(1.35)
    ex: dict[str, Any] = {"threads": 2, "chunk": 4, "out": tmp_path / "b"}
    full = basins(m, n=4, **ex)
    files = sorted((tmp_path / "b").glob("chunk-*.parquet"))
    assert len(files) == 4
    files[1].write_bytes(files[1].read_bytes()[:40])  # a crash mid-write, say
    before = {f: os.stat(f).st_mtime_ns for f in files if f != files[1]}
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        again = basins(m, n=4, **ex)
    assert any(issubclass(x.category, ScanStoreWarning) for x in w)
    assert again.table.equals(full.table)
    assert {f: os.stat(f).st_mtime_ns for f in before} == before
    with pytest.raises(ScanStoreError):
        basins(m, n=5, **ex)


def test_an_executor_gives_the_same_table():
    from concurrent.futures import ThreadPoolExecutor

    m = standard(1.2)
    here = basins(m, samples=6, seed=5, threads=1)
    with ThreadPoolExecutor(2) as ex:
        there = basins(m, samples=6, seed=5,
                       chunk=2, executor=ex)
    assert there.table.equals(here.table)


def _label_by_simulation(m: ballbal.Balancer, b1: float, b2: float) -> str:
    """The label of a start read from ballbal.simulate run to the full 1000 time
    units at tight tolerances, over its last 300: both balls turning (at least once
    per half) with their gap below merge_tol 0.5 = merged R-R, apart = separated R-R;
    none turning = rest, the perfect balance if |x + i y| ends below rest_tol 0.05."""
    om = m.Omega
    df = ballbal.simulate(m, [0, 0, b1, b2, 0, 0, -om, -om], t_eval=np.arange(700, 1000.01, 0.1),
                          t0=0.0, rtol=1e-9, atol=1e-11)
    b = df.select("b1", "b2").to_numpy()
    h = len(b) // 2
    turning = [min(abs(b[h, i] - b[0, i]), abs(b[-1, i] - b[h, i])) >= 2 * np.pi
               for i in range(2)]
    if all(turning):
        gap = np.abs(np.angle(np.exp(1j * (b[:, 0] - b[:, 1])))).max()
        return "merged_R-R" if gap < 0.5 else "separated_R-R"
    if not any(turning):
        return "perfect_balance" if np.hypot(df["x"][-1], df["y"][-1]) < 0.05 else \
            "other_equilibrium"
    return "R-O"


@pytest.mark.parametrize("omega", [1.2, 1.35])
def test_early_stop_keeps_the_labels_of_full_runs(omega):
    # The early stop ends most starts well before t_end (a converged Poincare section,
    # a torus, a clean decay to rest) and must give the label the full 1000 time units
    # give: against the classifier without early stopping on a 12 x 12 grid, and
    # against fixed-horizon simulations read in this test on random starts.
    m = standard(omega)
    early = basins(m, n=12).table
    full = basins(m, n=12, options=BasinOptions(early_stop=False)).table
    assert early["label"].to_list() == full["label"].to_list()
    assert early["t_stop"].mean() < 0.7 * full["t_stop"].mean()
    # full runs stop at t_end, or after whole extensions of it
    stops = full.filter(pl.col("label").is_in(ballbal.basins.ROTATING))["t_stop"]
    assert ((stops / 1000) % 1 == 0).all() and (stops >= 1000).all()
    assert early["motion"].to_list() == full["motion"].to_list()
    rot = early.filter(pl.col("label").is_in(ballbal.basins.ROTATING))
    # a torus' windowed mean rate moves by a few per cent with the window
    assert np.allclose(rot["rate1"], full.filter(
        pl.col("label").is_in(ballbal.basins.ROTATING))["rate1"], rtol=0.03)
    sample = basins(m, samples=24, seed=7).table
    for r in sample.iter_rows(named=True):
        assert r["label"] == _label_by_simulation(m, r["b1"], r["b2"]), r
    assert sample["t_stop"].min() < 1000


def _simulated_period(m: ballbal.Balancer, b1: float, b2: float, t0: float = 2000.0,
                      t1: float = 3000.0) -> tuple[int, float]:
    """(whole turns per period, period) of ball 1 from ballbal.simulate at tight
    tolerances, started at rest in the ground frame: the times ball 1 crosses whole
    turns over [t0, t1] (linear interpolation between samples 0.01 apart), the fewest
    turns m after which the turn durations repeat to 1e-6, and the mean period over the
    whole periods seen."""
    om = m.Omega
    t = np.arange(t0, t1, 0.01)
    df = ballbal.simulate(m, [0, 0, b1, b2, 0, 0, -om, -om], t_eval=t, t0=0.0,
                          rtol=1e-11, atol=1e-13)
    b = df["b1"].to_numpy()
    k = np.floor(b / (2 * np.pi))
    i = np.nonzero(np.diff(k))[0]
    level = 2 * np.pi * np.maximum(k[i], k[i + 1])
    c = t[i] + (level - b[i]) / (b[i + 1] - b[i]) * 0.01
    tau = np.diff(c)
    turns = next(mm for mm in range(1, 5) if np.allclose(tau[mm:], tau[:-mm], rtol=1e-6))
    periods = (len(c) - 1) // turns
    return turns, (c[periods * turns] - c[0]) / periods


@pytest.mark.parametrize("omega", [1.2, 1.35])
def test_periodic_starts_link_to_the_orbit_they_settle_on(omega, maps):
    # (a) Every periodic start points at an orbit whose harmonic-balance period is the
    # period measured here from an independent simulation of that start (ball turn
    # crossings); at 1.2 the balls rotate separately, two turns per period (the old
    # table gave these starts no period and linked nothing).
    res = maps[omega]
    t = res.table
    per = t.filter(pl.col("motion") == "periodic")
    assert per.height > 0
    assert per["orbit"].null_count() == 0
    assert t.filter(pl.col("motion") != "periodic")["orbit"].null_count() == \
        t.filter(pl.col("motion") != "periodic").height
    m = standard(omega)
    for o in res.orbits.iter_rows(named=True):
        assert o["status"] == "converged" and o["stability"] == "stable", o
        assert o["max_modulus"] < 1
        assert o["count"] == per.filter(pl.col("orbit") == o["orbit"]).height
        start = per.filter(pl.col("orbit") == o["orbit"]).row(-1, named=True)
        turns, period = _simulated_period(m, start["b1"], start["b2"])
        assert (o["winding1"], o["winding2"]) == (-turns, -turns), (o, turns)
        assert abs(o["period"] - period) < 1e-5 * period, (o, period)
    if omega == 1.2:
        sep = res.orbits.filter(pl.col("label") == "separated_R-R")
        assert sep.height >= 1
        assert (sep["winding1"] == -2).all() and (sep["winding2"] == -2).all()
    else:
        assert set(res.orbits["label"]) == {"merged_R-R"}
        assert (res.orbits["winding1"] == -1).all()


def test_a_start_unsettled_at_t_end_is_extended_and_linked():
    # (b) At Omega 1.2 a separated start is still in its transient at t_end = 400 (its
    # turn durations converge to their alternation over about a thousand time units):
    # with no extension it has no regular period and is not linked; with extensions it
    # is simulated on, 400 at a time, until its two-turn period repeats, and is linked
    # to the (-2, -2) orbit, whose period the independent simulation gives.
    m = standard(1.2)
    b1, b2 = [0.1309], [0.392699]
    short = basins(m, b1=b1, b2=b2, t_end=400,
                   options=BasinOptions(extend_factor=1)).table.row(0, named=True)
    assert short["label"] == "separated_R-R" and short["motion"] == "quasi_periodic"
    assert short["orbit"] is None and short["period"] is None
    assert short["extensions"] == 0 and short["t_stop"] <= 400
    r = basins(m, b1=b1, b2=b2, t_end=400)
    row = r.table.row(0, named=True)
    assert row["extensions"] >= 1 and row["t_stop"] <= 8 * 400
    assert row["t_stop"] == pytest.approx(400 * (row["extensions"] + 1), abs=400)
    assert row["label"] == "separated_R-R" and row["motion"] == "periodic"
    assert (row["winding1"], row["winding2"]) == (-2, -2)
    orbit = r.orbits.row(row["orbit"], named=True)
    assert (orbit["winding1"], orbit["winding2"]) == (-2, -2)
    turns, period = _simulated_period(m, b1[0], b2[0])
    assert turns == 2
    assert abs(orbit["period"] - period) < 1e-5 * period
    assert abs(row["period"] - period) < 1e-3 * period


def test_link_and_extension_options_are_checked():
    # (c)
    m = standard(1.2)
    for bad in (0.5, 65.0, float("nan")):
        with pytest.raises(ParameterError) as e:
            basins(m, n=2, options=BasinOptions(extend_factor=bad))
        assert e.value.parameter == "extend_factor"
    with pytest.raises(ParameterError) as e:
        basins(m, n=2, N=0)
    assert e.value.parameter == "N"
    with pytest.raises(ParameterError) as e:
        basins(m, n=2, orbits="yes")  # type: ignore[arg-type]
    assert e.value.parameter == "orbits"


def test_repr_names_the_orbits(maps):
    text = repr(maps[1.2])
    assert "orbit 0: separated_R-R windings (-2, -2)" in text
    assert "<table" in maps[1.2]._repr_html_()


def test_starts_of_one_class_link_to_distinct_orbits_by_period_and_rates(monkeypatch):
    # The matching alone (no solve: each new orbit's period is its representative's):
    # R-O starts whose periods agree to within LINK_TOL share an orbit, one 2 % off or
    # with the other ball rotating gets its own; rests and quasi-periodic motions none.
    from ballbal import basins as bmod

    solved = []

    def fake(model, r, state, options, N, periodic):  # noqa: N803
        solved.append((r["b1"], r["b2"]))
        return {k: None for k in bmod.ORBIT_SCHEMA} | {
            "label": r["label"], "winding1": r["winding1"], "winding2": r["winding2"],
            "count": 0}, r["period"]

    monkeypatch.setattr(bmod, "_solve_orbit", fake)
    rows = [  # (label, motion, period, rate1, rate2, winding1, winding2)
        ("R-O", "periodic", 10.0, 2 * np.pi / 10.0, 0.0, -1, 0),
        ("R-O", "periodic", 10.05, 2 * np.pi / 10.05, 0.001, -1, 0),  # 0.5 %: the same
        ("R-O", "periodic", 10.2, 2 * np.pi / 10.2, 0.0, -1, 0),  # 2 %: another
        ("R-O", "periodic", 10.0, 0.0, 2 * np.pi / 10.0, 0, -1),  # the other ball
        ("perfect_balance", "rest", None, 0.0, 0.0, None, None),
        ("separated_R-R", "quasi_periodic", None, 0.23, 0.23, None, None),
        ("R-O", "periodic", 10.19, 2 * np.pi / 10.19, 0.0, -1, 0),
    ]
    t = pl.DataFrame(
        [dict(zip(("label", "motion", "period", "rate1", "rate2", "winding1", "winding2"),
                  r, strict=True)) | {"b1": float(i), "b2": 0.0} for i, r in enumerate(rows)])
    col, orbits = bmod._link_orbits(standard(1.2), t, [[0.0] * 8] * len(rows),
                                    BasinOptions(), 8)
    assert col == [0, 0, 1, 2, None, None, 1]
    assert orbits["count"].to_list() == [2, 2, 1]
    assert solved == [(0.0, 0.0), (2.0, 0.0), (3.0, 0.0)]
