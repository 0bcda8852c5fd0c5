"""Scan directories that lose nothing and never corrupt, and tables that do not depend on
``chunk``: damaged files, resuming with another axis order, two processes on one
directory, interrupted command-line scans, SIGKILL and SIGINT at any time."""

import dataclasses
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ScanStoreError, ScanStoreWarning

# 7 x 21 points in 21 chunks of one block each (block=1: a few seconds on one thread).
KW = dict(Omega=(1.0, 1.6, 0.1), eta=(0.5, 1.5, 0.05), threads=1,
          options=ballbal.ScanOptions(block=1, guess=dataclasses.replace(
              ballbal.options.SCAN_DEFAULTS.guess, starts=8)))


@pytest.fixture(scope="module")
def reference():
    """The table of the uninterrupted scan in memory, without a directory."""
    return ballbal.scan(ballbal.Balancer(), **KW).drop("seconds")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A finished scan directory of KW; tests damage copies of it."""
    out = tmp_path_factory.mktemp("written") / "s"
    ballbal.scan(ballbal.Balancer(), out=out, **KW)
    return out


def copy_of(written, tmp_path):
    out = tmp_path / "s"
    shutil.copytree(written, out)
    return out


def same(df, ref):
    return df.drop("seconds").equals(ref)


def chunk_files(d):
    return sorted(Path(d).glob("chunk-*.parquet"))


def aside(f):
    """Where a damaged file of a store directory is set aside: ``<dir>.damaged/<name>``,
    beside the directory, so that the directory stays one Parquet dataset."""
    d = Path(f).parent.resolve()
    return d.with_name(d.name + ".damaged") / Path(f).name


def store_warnings(w):
    return [str(x.message) for x in w if issubclass(x.category, ScanStoreWarning)]


# --- chunk no longer changes the science -----------------------------------------------


def test_table_is_the_same_for_any_chunk_length():
    # 2 x 2 x 9 points with 9 blocks of one value: chunk 1, 3, 4 (rounded to whole
    # blocks) and the default cut the grid differently; the table must not change.
    b = ballbal.Balancer(zeta_b=0.1)
    grid = dict(Omega=[1.2, 1.3], eta=[0.9, 1.1], mu=(0.1, 0.26, 0.02), patterns=["R-R", "O-O"])
    ref = ballbal.scan(b, options=ballbal.ScanOptions(block=1), threads=1, **grid)
    ok = ref.filter(pl.col("status") == "converged")
    assert ok.height >= 20
    for chunk, threads in [(1, 2), (3, 1), (4, 2), (None, 2)]:
        df = ballbal.scan(b, options=ballbal.ScanOptions(block=1), chunk=chunk, threads=threads,
                          **grid)
        keys = ["Omega", "eta", "mu", "type", "solution", "status", "stability"]
        assert df.select(keys).equals(ref.select(keys)), chunk
        assert (df["omega"] - ref["omega"]).abs().max() <= 1e-10


def test_default_chunk_does_not_cut_continuation():
    # The defect: chunk=1 stopped continuation at every eta value, losing the solutions
    # that only continuation reaches. Now chunk=1 gives the default table, and the
    # numerical unit is `block` (documented), whose default is ~1024 points.
    b = ballbal.Balancer(zeta_b=0.1)
    grid = dict(Omega=(1.0, 2.0, 0.05), eta=(0.4, 1.5, 0.1))
    default = ballbal.scan(b, threads=2, **grid)
    for chunk in (1, 3):
        assert same(ballbal.scan(b, chunk=chunk, threads=1, **grid), default.drop("seconds"))
    lines = ballbal.scan(b, options=ballbal.ScanOptions(block=1), threads=2,
                         **grid)  # the old chunk=1
    found = default.filter(pl.col("status") == "converged").height
    assert lines.filter(pl.col("status") == "converged").height < found


def test_block_and_chunk_are_validated():
    for kw, name in [({"chunk": 0}, "chunk"), ({"lazy": True}, "lazy"), ({"out": ""}, "out")]:
        with pytest.raises(ballbal.exceptions.ParameterError) as e:
            ballbal.scan(ballbal.Balancer(), Omega=[1.2], **kw)
        assert e.value.parameter == name
    with pytest.raises(ballbal.exceptions.ParameterError) as e:
        ballbal.ScanOptions(block=0)
    assert e.value.parameter == "block"


# --- damaged directories ----------------------------------------------------------------


def test_damaged_chunks_are_reported_set_aside_and_recomputed(tmp_path, reference, written):
    out = copy_of(written, tmp_path)
    files = chunk_files(out)
    assert len(files) == 21
    truncated, empty, foreign = files[3], files[7], files[12]
    truncated.write_bytes(truncated.read_bytes()[: truncated.stat().st_size // 2])
    empty.write_bytes(b"")
    # A complete, readable chunk of another scan (other zeta): not this scan's rows.
    other = tmp_path / "other"
    ballbal.scan(ballbal.Balancer(zeta=0.06), out=other, **KW)
    foreign.write_bytes(chunk_files(other)[12].read_bytes())

    with pytest.raises(ScanStoreError, match=truncated.name) as e:
        ballbal.read_scan(out)
    assert empty.name in str(e.value) and foreign.name in str(e.value)
    with pytest.raises(ScanStoreError, match=empty.name):
        ballbal.read_scan(out, lazy=True)

    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out, **KW)
    said = store_warnings(w)
    assert len(said) == 3
    for f in (truncated, empty, foreign):
        assert any(str(f) in m for m in said), (f, said)
        assert aside(f).exists()
    assert same(df, reference)
    assert same(ballbal.read_scan(out), reference)


def test_chunk_missing_rows_is_damaged(tmp_path, reference, written):
    out = copy_of(written, tmp_path)
    f = chunk_files(out)[5]
    # Rewritten by another tool: readable, right columns, but rows are missing.
    pl.read_parquet(f).head(3).write_parquet(
        f, metadata=pl.read_parquet_metadata(f))
    with pytest.raises(ScanStoreError, match=f.name):
        ballbal.read_scan(out)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out, **KW)
    assert [m for m in store_warnings(w) if f.name in m]
    assert same(df, reference)


@pytest.mark.parametrize("content", [b"", b"PAR1", b"\xff\xfe\x00garbage", b"[1, 2]"])
def test_damaged_description_is_reported_and_rewritten_and_chunks_kept(tmp_path, reference,
                                                                      written, content):
    out = copy_of(written, tmp_path)
    before = {f.name: f.stat().st_mtime_ns for f in chunk_files(out)}
    (out / "_scan.parquet").write_bytes(content)
    with pytest.raises(ScanStoreError, match="_scan.parquet"):
        ballbal.read_scan(out)
    with pytest.raises(ScanStoreError, match="_scan.parquet"):
        ballbal.scan_meta(out)
    progress = []
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out,
                          progress=lambda d, t: progress.append(d), **KW)
    said = store_warnings(w)
    assert len(said) == 1 and "_scan.parquet" in said[0]
    assert same(df, reference)
    # The chunks carry the scan's fingerprint: all were trusted, none recomputed.
    assert progress == []
    assert {f.name: f.stat().st_mtime_ns for f in chunk_files(out)} == before
    assert ballbal.scan_meta(out)["grid"]["Omega"][0] == 1.0
    assert same(pl.read_parquet(out), reference)


def test_meta_json_of_before_0_2_is_set_aside(tmp_path, reference, written):
    out = copy_of(written, tmp_path)
    (out / "meta.json").write_text(json.dumps({"grid": {"Omega": [1.0]}}))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out, **KW)
    said = store_warnings(w)
    assert len(said) == 1 and "meta.json" in said[0] and "ballbal 0.1" in said[0]
    assert aside(out / "meta.json").exists() and not (out / "meta.json").exists()
    assert same(df, reference)
    assert same(pl.read_parquet(out), reference)


def test_resume_with_axes_in_another_order_is_refused(tmp_path):
    out = tmp_path / "s"
    kw = dict(options=ballbal.ScanOptions(block=1), threads=1)
    ballbal.scan(ballbal.Balancer(), out=out, Omega=[1.2, 1.3], eta=[0.9, 1.0, 1.1], **kw)
    before = {f.name: f.read_bytes() for f in chunk_files(out)}
    with pytest.raises(ScanStoreError, match="order Omega, eta"):
        ballbal.scan(ballbal.Balancer(), out=out, eta=[0.9, 1.0, 1.1], Omega=[1.2, 1.3], **kw)
    assert {f.name: f.read_bytes() for f in chunk_files(out)} == before
    assert ballbal.read_scan(out).height == 6


def test_chunk_layout_of_the_directory_is_kept_on_resume(tmp_path):
    out = tmp_path / "s"
    grid = dict(Omega=[1.2, 1.3], eta=[0.9, 1.0, 1.1], options=ballbal.ScanOptions(block=1),
                threads=1)
    ballbal.scan(ballbal.Balancer(), out=out, chunk=2, **grid)
    assert len(chunk_files(out)) == 2
    again = ballbal.scan(ballbal.Balancer(), out=out, **grid)  # no chunk: the directory's
    assert again.height == 6 and len(chunk_files(out)) == 2
    with pytest.raises(ScanStoreError, match="differs in chunk"):
        ballbal.scan(ballbal.Balancer(), out=out, chunk=3, **grid)


# --- processes and signals -----------------------------------------------------------

RUN = """
import dataclasses, sys, warnings, ballbal
kw = dict(Omega=(1.0, 1.6, 0.1), eta=(0.5, 1.5, 0.05), threads=1,
          options=ballbal.ScanOptions(block=1, guess=dataclasses.replace(
              ballbal.options.SCAN_DEFAULTS.guess, starts=8)))
print("READY", flush=True)
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    df = ballbal.scan(ballbal.Balancer(), out=sys.argv[1], **kw)
print("DONE" if not w else "PARTIAL", df.height, flush=True)
"""


def child(out, script=RUN):
    return subprocess.Popen([sys.executable, "-c", script, str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def wait_for(pred, timeout=120.0):
    deadline = time.time() + timeout
    while not pred():
        assert time.time() < deadline, "timed out"
        time.sleep(0.01)


def test_two_processes_cannot_share_a_directory(tmp_path, reference):
    out = tmp_path / "s"
    p = child(out)
    try:
        assert p.stdout.readline().strip() == "READY"
        wait_for(lambda: len(chunk_files(out)) >= 1)
        with pytest.raises(ScanStoreError, match=f"in use by another scan \\(process {p.pid}\\)"):
            ballbal.scan(ballbal.Balancer(), out=out, **KW)
        p.send_signal(signal.SIGKILL)  # a crash: the kernel drops the lock
        p.wait(timeout=30)
    finally:
        p.kill()
    assert 1 <= len(chunk_files(out)) < 21
    assert same(ballbal.scan(ballbal.Balancer(), out=out, **KW), reference)


KILL_IN_WRITE = """
import dataclasses, io, os, signal, sys, polars as pl, ballbal
orig = pl.DataFrame.write_parquet
calls = []
def torn(self, file, **kw):
    calls.append(1)
    if len(calls) < 5:  # the description (a file of no rows), then three chunks
        return orig(self, file, **kw)
    buf = io.BytesIO()
    orig(self, buf, **kw)
    data = buf.getvalue()
    file.write(data[: len(data) // 2])  # half the file is on disk, then the process dies
    file.flush()
    os.kill(os.getpid(), signal.SIGKILL)
pl.DataFrame.write_parquet = torn
kw = dict(Omega=(1.0, 1.6, 0.1), eta=(0.5, 1.5, 0.05), threads=1,
          options=ballbal.ScanOptions(block=1, guess=dataclasses.replace(
              ballbal.options.SCAN_DEFAULTS.guess, starts=8)))
ballbal.scan(ballbal.Balancer(), out=sys.argv[1], **kw)
"""


def test_sigkill_during_a_chunk_write_loses_nothing(tmp_path, reference):
    out = tmp_path / "s"
    p = child(out, KILL_IN_WRITE)
    p.communicate(timeout=300)
    assert p.returncode == -signal.SIGKILL
    assert len(chunk_files(out)) == 3
    assert list(out.glob(".*.tmp"))  # the torn temporary file is there...
    # ...and never read: the first three chunks' rows (7 Omega values each)
    first = reference.filter(pl.col("eta_index") < 3)
    assert same(ballbal.read_scan(out), first)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out, **KW)
    assert not store_warnings(w)
    assert same(df, reference)
    assert not list(out.glob(".*.tmp"))


def test_sigint_and_sigkill_at_random_times_then_resume(tmp_path, reference):
    out = tmp_path / "s"
    rng = random.Random(13)
    runs = 0
    while True:
        runs += 1
        assert runs <= 12, "the scan never finished"
        p = child(out)
        assert p.stdout.readline().strip() == "READY"
        if runs <= 6:
            time.sleep(rng.uniform(0.0, 2.0))
            p.send_signal(signal.SIGINT if runs % 2 else signal.SIGKILL)
        stdout, stderr = p.communicate(timeout=300)
        # Ctrl-C while the table is read back may end the script with KeyboardInterrupt,
        # never with anything else (no panic, no store error).
        if "Traceback" in stderr:
            assert stderr.strip().splitlines()[-1] == "KeyboardInterrupt", stderr
        if stdout.startswith("DONE"):
            break
        # An uncaught KeyboardInterrupt ends Python by SIGINT (returncode -2).
        assert p.returncode in (0, 1, -signal.SIGINT, -signal.SIGKILL), (p.returncode, stderr)
    assert same(ballbal.read_scan(out), reference)
    assert same(ballbal.scan(ballbal.Balancer(), out=out, **KW), reference)


def test_interrupted_command_line_scan_exits_130(tmp_path):
    out = tmp_path / "cli"
    p = subprocess.Popen(
        [sys.executable, "-m", "ballbal.cli", "scan", "--Omega", "1.0:2.0:0.01", "--eta",
         "0.4:1.5:0.01", "--threads", "1", "-o", str(out), "--no-progress"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_for(lambda: len(chunk_files(out)) >= 1)
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=60)
    assert p.returncode == 130, (stdout, stderr)
    assert "interrupted" in stderr and "Traceback" not in stderr
    assert "ballbal scan:" not in stdout  # no normal summary line
    assert ballbal.scan_meta(out)["grid"]["Omega"][0] == 1.0
    assert not (out / ".lock").exists()  # however the scan ended, no lock is left


# --- memory: lazy tables over the files --------------------------------------------------


def test_lazy_table_over_the_files(tmp_path, reference):
    out = tmp_path / "s"
    lf = ballbal.scan(ballbal.Balancer(), out=out, lazy=True, **KW)
    assert isinstance(lf, pl.LazyFrame)
    assert same(lf.collect(), reference)
    lf2 = ballbal.read_scan(out, lazy=True)
    assert isinstance(lf2, pl.LazyFrame) and same(lf2.collect(), reference)
    # The directory holds the table's files only: polars reads it as a dataset.
    assert not os.path.exists(out / ".lock")
    assert same(pl.read_parquet(out), reference)


def test_command_line_scan_into_another_scans_directory_is_a_clear_error(tmp_path):
    out = tmp_path / "cli"
    exe = [sys.executable, "-m", "ballbal.cli", "scan", "--eta", "1:1:1", "-o", str(out),
           "--no-progress"]
    r = subprocess.run(exe + ["--Omega", "1.2:1.2:0.1"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    r = subprocess.run(exe + ["--Omega", "1.3:1.3:0.1"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.startswith("ballbal: error: out:") and "differs in grid" in r.stderr
