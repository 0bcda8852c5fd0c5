"""Basins of attraction (the thesis' figures 4-15 and 4-16: mu 0.2, zeta 0.05, zeta_b
0.05, delta 50, eta 0.7, Omega 1.2 and 1.35, starts at rest in the ground frame).

Grids are small (a few dozen starts) and the physics lets t_end stay at the thesis'
1000: the perfect balance's slowest decay rate there is 0.004 (Omega 1.2) to 0.04, and
the R-R orbit's largest nontrivial multiplier 0.58 (Omega 1.35) per period of 17, so
both are settled well within 1000; every start costs a few milliseconds."""

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.basins import BasinOptions, basins
from ballbal.exceptions import ParameterError


def thesis(omega: float) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=omega,
                            eta=(0.7, 0.7))


@pytest.fixture(scope="module")
def maps() -> dict[float, ballbal.basins.Basins]:
    return {om: basins(thesis(om), n=8) for om in (1.2, 1.35)}


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
            m = thesis(om)
            y0 = [0, 0, r["b1"], r["b2"], 0, 0, -om, -om]
            df = ballbal.simulate(m, y0, t_eval=np.linspace(2700, 3000, 601), t0=0.0,
                                  rtol=1e-10, atol=1e-12)
            turns = abs(df["b1"][-1] - df["b1"][0]) / (2 * np.pi)
            if r["label"] in ballbal.basins.ROTATING:
                assert turns > 5, (om, r)
                rate = -(df["b1"][-1] - df["b1"][0]) / 300
                assert abs(rate - r["rate1"]) < 0.02 * abs(rate)
            else:
                assert r["label"] == "perfect_balance", (om, r)
                assert turns < 0.01
                assert np.hypot(df["x"][-1], df["y"][-1]) < 1e-3


def test_no_label_changes_between_1000_and_3000():
    for om in (1.2, 1.35):
        r = basins(thesis(om), n=5, settle_check=True)
        assert r.table["settled"].all(), r.table.filter(~pl.col("settled"))
        assert set(r.table["label"]) <= {"perfect_balance", "merged_R-R", "separated_R-R"}


def test_exchange_symmetry():
    # Identical balls: swapping them swaps the motion, so the label must not change.
    ax = np.array([0.4, 1.3, 2.5, 3.6, 4.9])
    t = basins(thesis(1.35), b1=ax, b2=ax).table
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
    m = thesis(1.2)
    a = basins(m, samples=12, seed=3, execution=ballbal.Execution(threads=1, chunk=5))
    b = basins(m, samples=12, seed=3, execution=ballbal.Execution(threads=2, chunk=4))
    assert a.table.equals(b.table)
    assert a.random and a.table["b1"].min() >= 0 and a.table["b1"].max() < 2 * np.pi


def test_default_grid_avoids_the_diagonal():
    t = basins(thesis(1.35), n=4, t_end=60, options=BasinOptions(window=30)).table
    assert t.height == 16
    gap = np.abs(np.angle(np.exp(1j * (t["b1"] - t["b2"]).to_numpy())))
    assert gap.min() > 0.5


def test_errors_name_the_parameter():
    m = thesis(1.2)
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


def test_ctrl_c_stops_a_grid_within_a_second():
    # A real SIGINT to a child computing a grid that takes about a minute.
    import signal
    import subprocess
    import sys
    import time

    code = ("import sys, time, ballbal\nfrom ballbal.basins import basins\n"
            "m = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2, "
            "eta=(0.7, 0.7))\nprint('ready', flush=True)\n"
            "try:\n    basins(m, n=100, execution=ballbal.Execution(threads=2))\n"
            "except KeyboardInterrupt:\n    print('interrupted', time.monotonic(), "
            "flush=True)\n    sys.exit(7)\n")
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 7, (out, err)
    assert float(out.split()[1]) - sent < 1.0


def test_resume_from_a_directory_redoes_only_a_damaged_chunk(tmp_path):
    import os
    import warnings

    from ballbal.exceptions import ScanStoreError, ScanStoreWarning

    m = thesis(1.35)
    ex = ballbal.Execution(threads=2, chunk=4, out=tmp_path / "b")
    full = basins(m, n=4, execution=ex)
    files = sorted((tmp_path / "b").glob("chunk-*.parquet"))
    assert len(files) == 4
    files[1].write_bytes(files[1].read_bytes()[:40])  # a crash mid-write, say
    before = {f: os.stat(f).st_mtime_ns for f in files if f != files[1]}
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        again = basins(m, n=4, execution=ex)
    assert any(issubclass(x.category, ScanStoreWarning) for x in w)
    assert again.table.equals(full.table)
    assert {f: os.stat(f).st_mtime_ns for f in before} == before
    with pytest.raises(ScanStoreError):
        basins(m, n=5, execution=ex)


def test_an_executor_gives_the_same_table():
    from concurrent.futures import ThreadPoolExecutor

    m = thesis(1.2)
    here = basins(m, samples=6, seed=5, execution=ballbal.Execution(threads=1))
    with ThreadPoolExecutor(2) as ex:
        there = basins(m, samples=6, seed=5,
                       execution=ballbal.Execution(chunk=2, executor=ex))
    assert there.table.equals(here.table)
