import dataclasses
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ParameterError, ScanStoreError

BASE = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2, eta=(1.0, 1.0))
MAP_GRID = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}


def stable_rr(df):
    return df.filter((pl.col("type") == "R-R") & (pl.col("stability") == "stable"))


@pytest.fixture(scope="module")
def small():
    return ballbal.scan(BASE, Omega=[1.15, 1.2, 1.25, 1.3], eta=[0.9, 1.0], threads=1)


@pytest.fixture(scope="module")
def omega_eta_maps():
    """Tien's (2011) R-R map (zeta 0.05, zeta_b 0.1) and its neighbours in zeta, zeta_b."""
    maps = {}
    for zeta, zeta_b in [(0.05, 0.1), (0.05, 0.05), (0.05, 0.2), (0.02, 0.1), (0.1, 0.1)]:
        b = BASE.replace(zeta=zeta, zeta_b=zeta_b)
        maps[zeta, zeta_b] = ballbal.scan(b, **MAP_GRID)
    return maps


def test_standard_point_equals_single_point_solver(small):
    row = small.filter((pl.col("Omega") == 1.2) & (pl.col("eta") == 1.0)).row(0, named=True)
    # the scan's Floquet settings (Magnus at rtol 1e-6)
    single = ballbal.periodic(BASE, "R-R", N=3,
                              options=ballbal.PeriodicOptions(
                                  floquet=ballbal.Floquet(rtol=1e-6, atol=1e-9, method="magnus")))
    assert row["status"] == "converged" and row["type"] == "R-R"
    assert abs(row["omega"] - single.omega) < 1e-9
    assert abs(row["max_modulus"] - single.max_modulus) < 1e-6
    mods = sorted((abs(complex(m["re"], m["im"])) for m in row["multipliers"]), reverse=True)
    assert np.allclose(mods, np.sort(np.abs(single.multipliers))[::-1], atol=1e-6)
    # and both equal the independent shooting value in the spec
    assert abs(row["omega"] - 0.25141) < 1e-4


def test_same_table_for_one_and_two_threads(small):
    two = ballbal.scan(BASE, Omega=[1.15, 1.2, 1.25, 1.3], eta=[0.9, 1.0], threads=2)
    assert small.drop("seconds").equals(two.drop("seconds"))


def test_omega_grows_with_Omega(omega_eta_maps):
    df = stable_rr(omega_eta_maps[0.05, 0.1])
    for eta in (0.7, 1.0, 1.3):
        w = df.filter(pl.col("eta") == eta).sort("Omega")["omega"].to_numpy()
        assert w.size >= 3 and np.all(np.diff(w) > 0), (eta, w)


def test_stable_rr_region_of_the_standard_map(omega_eta_maps):
    """Tien (2011), zeta 0.05, zeta_b 0.1: stable R-R needs eta >= about 0.5 and lives near
    Omega 1.0 to 1.6."""
    s = stable_rr(omega_eta_maps[0.05, 0.1])
    assert s.filter(pl.col("eta") < 0.45).height == 0
    assert s.filter(pl.col("Omega") > 1.75).height == 0
    for eta in (0.7, 1.0, 1.3):
        om = s.filter(pl.col("eta") == eta)["Omega"].to_list()
        assert min(om) == 1.0 and 1.15 < max(om) < 1.75, (eta, om)


def test_stable_range_widens_with_eta(omega_eta_maps):
    s = stable_rr(omega_eta_maps[0.05, 0.1])
    width = [s.filter(pl.col("eta") == e).height for e in (0.6, 0.8, 1.0, 1.2, 1.4)]
    assert width == sorted(width) and width[-1] > width[0], width


def test_stable_region_shrinks_as_damping_grows(omega_eta_maps):
    area = {k: stable_rr(v).height for k, v in omega_eta_maps.items()}
    assert area[0.05, 0.05] > area[0.05, 0.1] > area[0.05, 0.2], area
    assert area[0.02, 0.1] > area[0.05, 0.1] > area[0.1, 0.1], area


def test_perfect_balance_region_comes_with_the_scan(omega_eta_maps):
    df = omega_eta_maps[0.05, 0.1]
    pb = df.unique(subset=["Omega", "eta"])
    # closed form: the perfect balance exists for eta >= 1/2
    assert pb.filter(pl.col("pb_exists") != (pl.col("eta") >= 0.5)).height == 0
    # and it is stable somewhere above the resonance and never where it does not exist
    assert pb.filter(pl.col("pb_stable")).height > 10
    assert pb.filter(pl.col("pb_stable") & ~pl.col("pb_exists")).height == 0
    eqs = ballbal.equilibria(BASE.replace(zeta_b=0.1, Omega=1.8, eta=(1.2, 1.2)))
    verdict = next(e for e in eqs if e.kind == "perfect_balance").stability == "stable"
    row = pb.filter((pl.col("Omega") == 1.8) & (pl.col("eta") == 1.2))
    assert row["pb_stable"][0] == verdict


def test_coexisting_solutions_are_distinct_orbits():
    """Where the scan reports two R-R solutions at one point, each is a real orbit: the
    single-point solver started from a time simulation finds the stable one, and the
    other one has a different frequency."""
    df = ballbal.scan(BASE, Omega=(1.3, 1.6, 0.1), eta=[0.9, 1.0, 1.1])
    two = df.filter(pl.col("solution") == 1)
    assert two.height > 0
    row = two.row(0, named=True)
    both = df.filter((pl.col("Omega") == row["Omega"]) & (pl.col("eta") == row["eta"]))
    assert both.height == 2
    assert abs(both["omega"][0] - both["omega"][1]) > 1e-3
    b = BASE.replace(Omega=row["Omega"], eta=(row["eta"], row["eta"]))
    single = ballbal.periodic(b, "R-R", N=3)
    stable = both.filter(pl.col("stability") == "stable")
    assert stable.height == 1 and single.stability == "stable"
    assert abs(stable["omega"][0] - single.omega) < 1e-7


def test_not_found_rows_are_null_not_nan():
    # the perfect balance attracts every start here: no R-R found, a row with a status
    b = ballbal.Balancer(mu=0.2, zeta=0.1, zeta_b=0.1, delta=50, Omega=3.0, eta=(1.0, 1.0))
    df = ballbal.scan(b, Omega=[3.0], eta=[1.0], threads=1)
    assert df["status"].to_list() == ["not_found"]
    for c in ("omega", "max_modulus", "residual", "stability", "solution"):
        assert df[c].null_count() == 1, c
    assert df["omega"].is_nan().sum() == 0


def test_three_parameter_grid_and_progress():
    seen = []
    df = ballbal.scan(BASE, Omega=[1.2, 1.3], eta=[1.0], zeta_b=[0.05, 0.1],
                      progress=lambda d, t: seen.append((d, t)))
    assert df.columns[:3] == ["Omega", "eta", "zeta_b"]
    assert df.unique(subset=["Omega", "eta", "zeta_b"]).height == 4
    assert seen[-1] == (4, 4)
    # each row's parameters are the ones it was solved at
    row = df.filter((pl.col("Omega") == 1.2) & (pl.col("zeta_b") == 0.1)).row(0, named=True)
    single = ballbal.periodic(BASE.replace(Omega=1.2, zeta_b=0.1), "R-R", N=3)
    assert abs(row["omega"] - single.omega) < 1e-7


def test_executor_gives_the_same_table():
    kw = dict(Omega=[1.1, 1.2, 1.3], eta=[0.8, 0.9, 1.0, 1.1], chunk=2)
    local = ballbal.scan(BASE, **kw)
    with ProcessPoolExecutor(2) as ex:
        remote = ballbal.scan(BASE, executor=ex, **kw)
    assert local.drop("seconds").equals(remote.drop("seconds"))


def test_dask_local_cluster_gives_the_same_table():
    distributed = pytest.importorskip("distributed")
    kw = dict(Omega=[1.1, 1.2, 1.3], eta=[0.8, 0.9, 1.0, 1.1], chunk=2)
    local = ballbal.scan(BASE, **kw)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = ballbal.scan(BASE, executor=client, **kw)
    assert local.drop("seconds").equals(remote.drop("seconds"))


SCRIPT = """
import dataclasses, sys, warnings, ballbal
b = ballbal.Balancer()
opts = ballbal.ScanOptions(block=1, guess=dataclasses.replace(
    ballbal.options.SCAN_DEFAULTS.guess, starts=8))
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    df = ballbal.scan(b, Omega=(1.0, 1.6, 0.1), eta=(0.5, 1.5, 0.05), threads=1,
                      options=opts, out=sys.argv[1])
print("ROWS", df.height, "WARNED", sum(issubclass(x.category, ballbal.ScanInterrupted) for x in w))
"""


def test_interrupt_keeps_finished_chunks_and_resume_completes(tmp_path):
    out = tmp_path / "scan.parquet"
    kw = dict(Omega=(1.0, 1.6, 0.1), eta=(0.5, 1.5, 0.05), threads=1,
              options=ballbal.ScanOptions(block=1, guess=dataclasses.replace(
                  ballbal.options.SCAN_DEFAULTS.guess, starts=8)))
    p = subprocess.Popen([sys.executable, "-c", SCRIPT, str(out)], stdout=subprocess.PIPE,
                         text=True)
    deadline = time.time() + 120
    while len(list(out.glob("chunk-*.parquet"))) < 3 and time.time() < deadline:
        time.sleep(0.01)
    p.send_signal(signal.SIGINT)
    stdout, _ = p.communicate(timeout=60)
    assert p.returncode == 0, stdout
    kept = len(list(out.glob("chunk-*.parquet")))
    assert 3 <= kept < 21, kept
    rows, warned = int(stdout.split()[1]), int(stdout.split()[3])
    # 7 Omega values per chunk, one type: a row each, or more where orbits coexist
    on_disk = ballbal.read_scan(out)
    assert warned == 1 and rows == on_disk.height >= 7 * kept
    assert on_disk.select("Omega", "eta").unique().height == 7 * kept
    resumed = ballbal.scan(ballbal.Balancer(), out=out, **kw)
    whole = ballbal.scan(ballbal.Balancer(), **kw)
    assert resumed.drop("seconds").equals(whole.drop("seconds"))
    assert ballbal.read_scan(out).drop("seconds").equals(whole.drop("seconds"))
    # resuming recomputed nothing that was on disk: the kept files are unchanged
    assert len(list(out.glob("chunk-*.parquet"))) == 21


def test_resume_refuses_a_different_scan(tmp_path):
    ballbal.scan(BASE, Omega=[1.2], eta=[1.0], out=tmp_path / "s")
    with pytest.raises(ballbal.exceptions.ScanStoreError, match="^out: .* differs in grid"):
        ballbal.scan(BASE, Omega=[1.3], eta=[1.0], out=tmp_path / "s")
    meta = ballbal.scan_meta(tmp_path / "s")
    assert meta["grid"] == {"Omega": [1.2], "eta": [1.0]}


def test_resume_refuses_another_floquet_method(tmp_path):
    # The multipliers of the two methods differ in their last digits: a directory must
    # not end up holding rows of both.
    ballbal.scan(BASE, Omega=[1.2], eta=[1.0], out=tmp_path / "s")
    with pytest.raises(ScanStoreError, match="differs in options.floquet_method"):
        ballbal.scan(BASE, Omega=[1.2], eta=[1.0], out=tmp_path / "s",
                     options=ballbal.ScanOptions(
                         floquet=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.floquet,
                                                     method="rk45")))


@pytest.mark.parametrize(
    ("grid", "name"),
    [
        ({"Omega": [], "eta": [1.0]}, "Omega"),
        ({"Omega": [1.0, float("nan")], "eta": [1.0]}, "Omega"),
        ({"gravity": [1.0], "eta": [1.0]}, "gravity"),
        ({}, "grid"),
        ({"Omega": [-1.0], "eta": [1.0]}, "Omega"),
        ({"Omega": (2.0, 1.0, 0.1)}, "Omega"),
        ({"Omega": "1:2"}, "Omega"),
        ({"eta6": [1.0]}, "eta6"),
        ({"eta": [0.0]}, "eta1"),
    ],
)
def test_bad_grids_raise_before_work(grid, name):
    with pytest.raises(ParameterError) as err:
        ballbal.scan(BASE, grid=grid)
    assert err.value.parameter == name


@pytest.mark.parametrize(
    ("kw", "name"),
    [({"patterns": []}, "patterns"), ({"patterns": ["R-X"]}, "pattern"),
     ({"threads": 0}, "threads"), ({"chunk": 0}, "chunk"), ({"N": 0}, "N")],
)
def test_bad_options_raise_before_work(kw, name):
    with pytest.raises(ParameterError) as err:
        ballbal.scan(BASE, Omega=[1.2], eta=[1.0], **kw)
    assert err.value.parameter == name


def test_a_scans_own_bounds_are_checked_before_work():
    # No start at all: a bound of scans (periodic() ignores starts), so refused by scan.
    none = ballbal.ScanOptions(guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess,
                                                         starts=0))
    with pytest.raises(ParameterError) as err:
        ballbal.scan(BASE, Omega=[1.2], eta=[1.0], options=none)
    assert err.value.parameter == "starts"


@pytest.mark.parametrize(("make", "name"), [
    (lambda: ballbal.Floquet(rtol=-1.0), "rtol"),
    (lambda: ballbal.ScanOptions(max_tail=0.0), "max_tail")])
def test_bad_scan_options_raise_when_made(make, name):
    with pytest.raises(ParameterError) as err:
        make()
    assert err.value.parameter == name


def test_command_line_scan_and_plot(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text("mu = 0.2\nzeta = 0.05\nzeta_b = 0.1\ndelta = 50.0\neta = 1.0\nballs = 2\n")
    out = tmp_path / "out.parquet"
    exe = [sys.executable, "-m", "ballbal.cli"]
    r = subprocess.run(exe + ["scan", str(scene), "--Omega", "1.1:1.3:0.1", "--eta",
                              "0.9:1.0:0.1", "-o", str(out), "--no-progress"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    df = ballbal.read_scan(out)
    assert df.height == 6 and set(df["type"]) == {"R-R"}
    assert ballbal.scan_meta(out)["balancer"]["zeta_b"] == 0.1
    png = tmp_path / "map.png"
    r = subprocess.run(exe + ["plot", str(out), "-o", str(png)], capture_output=True,
                       text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 0, r.stderr
    assert png.stat().st_size > 10_000
    bad = tmp_path / "bad.toml"
    bad.write_text("mu = 0.2\nzetta = 0.1\n")
    r = subprocess.run(exe + ["scan", str(bad), "--Omega", "1:2:0.5", "-o", str(tmp_path / "x")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "unknown key(s) zetta" in r.stderr


@pytest.mark.parametrize("rows", [
    [[0.5, -0.25], None, [1.0, 2.0]],          # one length, a row without multipliers
    [[0.5], None, [1.0, 2.0, 3.0]],            # mixed lengths
    [None, None],                              # none at all
    [],                                        # an empty chunk
])
def test_multiplier_column_matches_a_list_of_structs(rows: list[list[float] | None]) -> None:
    from ballbal.scan import MULTIPLIER, _multipliers
    im = [None if r is None else [-2.0 * v for v in r] for r in rows]
    expected = pl.Series("multipliers", [
        None if r is None else [{"re": a, "im": b} for a, b in zip(r, i, strict=True)]
        for r, i in zip(rows, im, strict=True)
    ], dtype=MULTIPLIER)
    got = _multipliers(rows, im)
    assert got.name == "multipliers" and got.dtype == MULTIPLIER
    assert got.to_list() == expected.to_list()
