"""Tables that say what they are (issue 32): a scan directory is a Parquet dataset polars
reads by itself, with no lock left however the scan ended; every scan table carries the
model it was computed for (columns in memory and in every chunk; the whole description
in the directory's ``_scan.parquet``); nested columns have a flat export that
``write_csv`` takes."""

import dataclasses
import json
import math
import os
import shutil
import warnings
from pathlib import Path

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ScanInterrupted, ScanStoreError, ScanStoreWarning

# 2 x 3 points in three chunks of one block (block=1): about a second on one thread.
GRID = dict(Omega=[1.2, 1.3], eta=[0.9, 1.0, 1.1])
KW = dict(threads=1, options=ballbal.ScanOptions(
    block=1, guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess, starts=4)))


def names_in(d: Path) -> list[str]:
    return sorted(p.name for p in d.iterdir())


def only_chunks(d: Path) -> bool:
    """Only the table's Parquet files: the chunks and the description (no rows)."""
    return all((n.startswith("chunk-") and n.endswith(".parquet")) or n == "_scan.parquet"
               for n in names_in(d))


def same_rows(a: pl.DataFrame, b: pl.DataFrame) -> bool:
    return a.drop("seconds").equals(b.drop("seconds"))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "fine.parquet"
    df = ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)
    return out, df


# --- 1. the directory is a Parquet dataset ------------------------------------------------


def test_polars_reads_the_scan_directory_itself(written):
    out, df = written
    assert only_chunks(out), names_in(out)  # no meta.json, no .lock
    assert len(names_in(out)) == 3 + 1
    for got in (pl.read_parquet(out), pl.scan_parquet(out).collect(),
                pl.read_parquet(f"{out}/*.parquet")):
        assert got.height == 2 * 3
        assert same_rows(got, df)
        assert same_rows(got, ballbal.read_scan(out))


def test_no_lock_is_left_after_an_error(tmp_path):
    out = tmp_path / "s"

    def fail(done, total):
        raise RuntimeError("a progress callback that fails")

    with pytest.raises(RuntimeError, match="progress callback"):
        ballbal.scan(ballbal.Balancer(), out=out, progress=fail, **GRID, **KW)
    assert only_chunks(out), names_in(out)
    # A different scan into the directory is refused, and leaves no lock either.
    ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)
    with pytest.raises(ScanStoreError, match="differs in balancer.zeta"):
        ballbal.scan(ballbal.Balancer(zeta=0.06), out=out, **GRID, **KW)
    assert only_chunks(out), names_in(out)
    assert pl.read_parquet(out).height == 6


def test_no_lock_is_left_after_ctrl_c(tmp_path):
    out = tmp_path / "s"
    calls = []

    def ctrl_c(done, total):
        calls.append(done)
        if len(calls) == 1:
            raise KeyboardInterrupt

    with pytest.warns(ScanInterrupted):
        part = ballbal.scan(ballbal.Balancer(), out=out, progress=ctrl_c, **GRID, **KW)
    assert part.height >= 2  # the chunks finished before the interrupt took effect
    assert only_chunks(out), names_in(out)
    assert same_rows(pl.read_parquet(out), part)
    # ... and resuming finishes it.
    full = ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)
    assert full.height == 6 and same_rows(pl.read_parquet(out), full)


def test_the_directory_is_locked_while_a_scan_uses_it(tmp_path):
    out = tmp_path / "s"
    refused = []

    def second_scan(done, total):
        if not refused:
            with pytest.raises(ScanStoreError, match=f"in use by another scan "
                               f"\\(process {os.getpid()}\\)") as e:
                ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)
            refused.append(e.value)

    ballbal.scan(ballbal.Balancer(), out=out, progress=second_scan, **GRID, **KW)
    assert refused
    assert only_chunks(out)
    # Released: the next scan opens it (and resumes everything).
    ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)


def test_damaged_files_are_set_aside_outside_the_dataset(tmp_path, written):
    src, df = written
    out = tmp_path / "fine.parquet"
    shutil.copytree(src, out)
    f = out / "chunk-00001.parquet"
    f.write_bytes(f.read_bytes()[:100])
    (out / "meta.json").write_text("{}")  # the description of ballbal before 0.2
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        again = ballbal.scan(ballbal.Balancer(), out=out, **GRID, **KW)
    said = [str(x.message) for x in w if issubclass(x.category, ScanStoreWarning)]
    assert len(said) == 2 and any("meta.json" in m for m in said)
    aside = tmp_path / "fine.parquet.damaged"
    assert sorted(p.name for p in aside.iterdir()) == ["chunk-00001.parquet", "meta.json"]
    assert only_chunks(out)
    assert same_rows(again, df) and same_rows(pl.read_parquet(out), df)


# --- 2. every table says its model ----------------------------------------------------------

MODEL = dict(mu=0.15, zeta=0.07, zeta_b=(0.1, 0.2), delta=40.0, Omega=1.25, eta=(0.9, 1.1))


def test_in_memory_table_carries_every_fixed_parameter(tmp_path):
    b = ballbal.Balancer(**MODEL)
    df = ballbal.scan(b, Omega=[1.2, 1.3], threads=1,
                      options=ballbal.ScanOptions(
                          guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess, starts=4)))
    expect = {"mu": 0.15, "zeta": 0.07, "zeta_b1": 0.1, "zeta_b2": 0.2, "delta": 40.0,
              "eta1": 0.9, "eta2": 1.1}
    for c, v in expect.items():
        assert df[c].to_list() == [v] * df.height, c
    assert df["Omega"].to_list() == [1.2, 1.3]  # the axis, not the model's 1.25
    # Saved in a format without metadata and read back: still the same model.
    df.drop("multipliers").write_csv(tmp_path / "t.csv")
    back = pl.read_csv(tmp_path / "t.csv")
    for c, v in expect.items():
        assert back[c].to_list() == [v] * df.height, c


def test_a_ball_under_an_axis_of_every_ball_takes_the_axis_value():
    b = ballbal.Balancer(**MODEL)
    df = ballbal.scan(b, eta=[0.8, 1.2], threads=1,
                      options=ballbal.ScanOptions(
                          guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess, starts=4)))
    assert df["eta1"].to_list() == df["eta"].to_list() == df["eta2"].to_list()
    assert sorted(set(df["eta"].to_list())) == [0.8, 1.2]
    one = ballbal.scan(b, grid={"eta2": [0.8, 1.2]}, threads=1,
                       options=ballbal.ScanOptions(
                           guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess,
                                                     starts=4)))
    assert one["eta1"].to_list() == [0.9] * one.height
    assert sorted(set(one["eta2"].to_list())) == [0.8, 1.2]
    assert one.columns.count("eta2") == 1


def test_stored_scan_says_model_options_and_scene(tmp_path):
    b = ballbal.Balancer(**MODEL)
    out = tmp_path / "s"
    ballbal.scan(b, out=out, Omega=[1.2, 1.3], threads=1,
                 options=ballbal.ScanOptions(
                     guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess, starts=4,
                                               seeds=3)))
    meta = ballbal.scan_meta(out)
    bal = meta["balancer"]
    assert (bal["mu"], bal["zeta"], bal["delta"], bal["Omega"]) == (0.15, 0.07, 40.0, 1.25)
    assert list(bal["zeta_b"]) == [0.1, 0.2] and list(bal["eta"]) == [0.9, 1.1]
    assert meta["options"]["seeds"] == 3 and meta["options"]["starts"] == 4
    assert meta["grid"] == {"Omega": [1.2, 1.3]}
    # The description file carries it, readable by polars alone, and adds no rows.
    kv = pl.read_parquet_metadata(out / "_scan.parquet")
    assert json.loads(kv["ballbal_scan_description"]) == meta
    assert pl.read_parquet(out / "_scan.parquet").height == 0
    # The table read back from the directory by polars has the model's columns too.
    back = pl.read_parquet(out)
    assert back["mu"].to_list() == [0.15] * back.height

    # A scene: its effects too (here springs in a chain; the axis is stored beside).
    s = ballbal.Scene(balancer=b, springs=0.05, spring_layout="chain")
    out2 = tmp_path / "scene"
    got = ballbal.scan(s, out=out2, springs=[0.05, 0.06], threads=1,
                       options=ballbal.ScanOptions(
                           guess=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.guess,
                                                     starts=4)))
    m2 = ballbal.scan_meta(out2)
    assert m2["scene"]["springs"] == {"stiffness": 0.05, "layout": "chain"}
    assert m2["scene"]["balancer"]["mu"] == 0.15 and m2["grid"] == {"springs": [0.05, 0.06]}
    assert got["zeta_b2"].to_list() == [0.2] * got.height


def test_a_description_without_a_description_is_damaged(tmp_path, written):
    src, _ = written
    out = tmp_path / "s"
    shutil.copytree(src, out)
    # A readable Parquet file with the right columns but no description in it.
    pl.read_parquet(out / "_scan.parquet").write_parquet(out / "_scan.parquet")
    for call in (ballbal.read_scan, ballbal.scan_meta):
        with pytest.raises(ScanStoreError, match="_scan.parquet"):
            call(out)


# --- 3. flat export -----------------------------------------------------------------------


def test_flat_table_writes_csv_and_keeps_the_multipliers(tmp_path):
    df = ballbal.scan(ballbal.Balancer(zeta_b=0.1), Omega=[1.1, 1.2, 1.3, 1.5], eta=[0.6, 1.0, 1.2],
                      patterns=["R-R", "O-O"], threads=1,
                      options=ballbal.ScanOptions(guess=dataclasses.replace(
                          ballbal.options.SCAN_DEFAULTS.guess, starts=4)))
    with pytest.raises(Exception, match="(?i)nested|list|struct"):  # why flat() exists
        df.write_csv(tmp_path / "nested.csv")
    flat = ballbal.flat(df)
    path = tmp_path / "t.csv"
    flat.write_csv(path)
    back = pl.read_csv(path, infer_schema_length=None)
    assert back.height == df.height
    have = df.filter(pl.col("multipliers").is_not_null())
    assert have.height >= 3
    k = max(len(m) for m in have["multipliers"].to_list())
    assert {f"multipliers_re_{k - 1}", f"multipliers_im_{k - 1}"} <= set(back.columns)
    for i, row in enumerate(df.iter_rows(named=True)):
        mult = row["multipliers"]
        if mult is None:
            assert back["multipliers_re_0"][i] is None
            continue
        want = np.abs([complex(m["re"], m["im"]) for m in mult])
        got = np.hypot([back[f"multipliers_re_{j}"][i] for j in range(len(mult))],
                       [back[f"multipliers_im_{j}"][i] for j in range(len(mult))])
        assert np.allclose(got, want, rtol=1e-12, atol=0), (i, got, want)
    # The other columns are kept as they were.
    for a, b in zip(back["omega"].to_list(), df["omega"].to_list(), strict=True):
        assert (a is None and b is None) or math.isclose(a, b, rel_tol=1e-14)


def test_flat_refuses_a_lazy_frame():
    with pytest.raises(ballbal.exceptions.ParameterTypeError, match="table"):
        ballbal.flat(pl.LazyFrame({"a": [1]}))  # type: ignore[arg-type]


# --- 4. axis indices in the other gridded tables ------------------------------------------


def test_basin_table_has_each_starts_axis_positions():
    from ballbal.basins import BasinOptions, basins

    m = ballbal.Balancer(zeta_b=0.05, Omega=1.35, eta=(0.7, 0.7))
    ax1, ax2 = [0.3, 1.1, 2.0], [0.6, 2.5]
    t = basins(m, b1=ax1, b2=ax2, t_end=60, options=BasinOptions(window=30)).table
    assert t.height == 6 and t.schema["b1_index"] == pl.Int64
    assert sorted(zip(t["b1_index"], t["b2_index"], strict=True)) == [
        (i, j) for i in range(3) for j in range(2)]
    for r in t.iter_rows(named=True):
        assert math.isclose(ax1[r["b1_index"]], r["b1"], rel_tol=1e-15)
        assert math.isclose(ax2[r["b2_index"]], r["b2"], rel_tol=1e-15)
    rnd = basins(m, samples=3, seed=1, t_end=60, options=BasinOptions(window=30)).table
    assert rnd["b1_index"].null_count() == rnd["b2_index"].null_count() == 3


def test_speed_sweep_table_has_the_speeds_positions():
    speeds = [1.0, 1.2, 1.4]
    from ballbal.sweep import speed_sweep

    s = speed_sweep(ballbal.Balancer(), speeds, dwell=40.0, record=None)
    assert s.table["Omega_index"].to_list() == [0, 1, 2, 1, 0]  # up, then down
    for om, i in zip(s.table["Omega"], s.table["Omega_index"], strict=True):
        assert math.isclose(speeds[i], om, rel_tol=1e-15)
    down = speed_sweep(ballbal.Balancer(), speeds, dwell=40.0, record=None,
                       direction="down")
    assert down.table["Omega_index"].to_list() == [2, 1, 0]
