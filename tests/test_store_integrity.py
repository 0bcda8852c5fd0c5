"""Checksummed chunk stores (issue 30): a scan or basin directory whose chunk files were
changed after they were written -- a bit flipped anywhere, header, rows or footer
metadata, or one chunk copied over another -- resumes to the uninterrupted table, with
every changed file set aside and named in a ``ScanStoreWarning``.

The grids are tiny (4 chunks each) so that every flipped copy can be resumed on its own."""

import dataclasses
import random
import shutil
import warnings
from pathlib import Path

import polars as pl
import pytest

import ballbal
from ballbal.basins import basins
from ballbal.exceptions import ScanStoreError, ScanStoreWarning

# 3 x 4 points, 4 chunks of one block each; both kinds of row (solutions with
# multipliers, not_found) are in it.
KW = dict(Omega=[1.0, 1.3, 1.6], eta=[0.5, 0.9, 1.3, 1.5], threads=1,
          options=ballbal.ScanOptions(block=1, guess=dataclasses.replace(
              ballbal.options.SCAN_DEFAULTS.guess, starts=8)))
# Flipped copies per chunk file, half of the flips in the footer: 24 copies of the scan
# (each resume recomputes a chunk of a few solves), 48 of the basins (a few starts).
SCAN_FLIPS, BASIN_FLIPS = 6, 12


def standard() -> ballbal.Balancer:
    # The basins of tests/test_basins.py (figure 4-16): 16 starts in 4 chunks of 4.
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.35,
                            eta=(0.7, 0.7))


BASINS = dict(n=4)


def basin_execution(out=None):
    return {"threads": 1, "chunk": 4, "out": out}


@pytest.fixture(scope="module")
def scan_reference():
    ref = ballbal.scan(ballbal.Balancer(), **KW).drop("seconds")
    assert ref.filter(pl.col("status") == "converged").height > 0
    assert ref.filter(pl.col("status") == "not_found").height > 0
    return ref


@pytest.fixture(scope="module")
def scan_written(tmp_path_factory):
    out = tmp_path_factory.mktemp("scan") / "s"
    ballbal.scan(ballbal.Balancer(), out=out, **KW)
    return out


@pytest.fixture(scope="module")
def basin_reference():
    return basins(standard(), **BASINS, **basin_execution()).table


@pytest.fixture(scope="module")
def basin_written(tmp_path_factory):
    out = tmp_path_factory.mktemp("basins") / "b"
    basins(standard(), **BASINS, **basin_execution(out))
    return out


def chunk_files(d):
    return sorted(Path(d).glob("chunk-*.parquet"))


def aside(f):
    """Where a damaged file of a store directory is set aside: ``<dir>.damaged/<name>``,
    beside the directory, so that the directory stays one Parquet dataset."""
    d = Path(f).parent.resolve()
    return d.with_name(d.name + ".damaged") / Path(f).name


def store_warnings(w):
    return [str(x.message) for x in w if issubclass(x.category, ScanStoreWarning)]


def resume_scan(out):
    computed = []
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        df = ballbal.scan(ballbal.Balancer(), out=out,
                          progress=lambda d, t: computed.append(d), **KW)
    return df.drop("seconds"), store_warnings(w), computed


def resume_basins(out):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = basins(standard(), **BASINS, **basin_execution(out))
    return r.table, store_warnings(w)


def flips(files, rng, per_file):
    """(file index, bit) pairs: per file, half anywhere in it and half in its footer
    (the Thrift metadata, key-value entries included, and the length and magic after
    it), where a checksum of the decoded rows would not look."""
    out = []
    for i, f in enumerate(files):
        data = f.read_bytes()
        assert data[-4:] == b"PAR1"
        footer = int.from_bytes(data[-8:-4], "little") + 8
        for k in range(per_file):
            lo = 0 if k % 2 else len(data) - footer
            out.append((i, rng.randrange(8 * lo, 8 * len(data))))
    return out


def flip(f, bit):
    data = bytearray(f.read_bytes())
    data[bit // 8] ^= 1 << (bit % 8)
    f.write_bytes(bytes(data))


def test_scan_resumes_past_flipped_bits(tmp_path, scan_reference, scan_written):
    # Before checksums: most flips in the rows changed the resumed table silently (a
    # multiplier in its 9th digit), and flips in the footer went unnoticed.
    files = chunk_files(scan_written)
    assert len(files) == 4
    clean = tmp_path / "clean"
    shutil.copytree(scan_written, clean)
    df, said, computed = resume_scan(clean)
    assert said == [] and computed == []  # no false alarm: nothing recomputed
    assert df.equals(scan_reference)
    for k, (i, bit) in enumerate(flips(files, random.Random(30), SCAN_FLIPS)):
        out = tmp_path / f"flip{k}"
        shutil.copytree(scan_written, out)
        f = chunk_files(out)[i]
        flip(f, bit)
        # Every byte is covered by the checksum: every flip is caught, by read_scan
        # (lazy too: it checks checksums, not only footers) and on resuming.
        for lazy in (False, True):
            with pytest.raises(ScanStoreError, match=f.name):
                ballbal.read_scan(out, lazy=lazy)
        df, said, computed = resume_scan(out)
        assert len(said) == 1 and str(f) in said[0], (k, i, bit, said)
        assert aside(f).exists()
        assert len(computed) == 1  # only the flipped chunk was recomputed
        assert df.equals(scan_reference), (k, i, bit)


def test_scan_chunk_copied_over_another_is_set_aside(tmp_path, scan_reference, scan_written):
    out = tmp_path / "s"
    shutil.copytree(scan_written, out)
    files = chunk_files(out)
    shutil.copyfile(files[3], files[2])
    with pytest.raises(ScanStoreError, match=files[2].name):
        ballbal.read_scan(out, lazy=True)
    df, said, computed = resume_scan(out)
    # Told by the chunk number it records, not only by its rows' values.
    assert len(said) == 1 and str(files[2]) in said[0]
    assert "holds chunk 3" in said[0] and "not chunk 2" in said[0], said
    assert len(computed) == 1
    assert df.equals(scan_reference)


def test_scan_chunk_without_checksum_is_recomputed(tmp_path, scan_reference, scan_written):
    # A chunk as written before chunks had checksums (the scan's fingerprint only):
    # set aside with the reason and recomputed.
    out = tmp_path / "s"
    shutil.copytree(scan_written, out)
    f = chunk_files(out)[1]
    fingerprint = pl.read_parquet_metadata(f)["ballbal_scan"]
    pl.read_parquet(f).write_parquet(f, metadata={"ballbal_scan": fingerprint})
    df, said, computed = resume_scan(out)
    assert len(said) == 1 and str(f) in said[0] and "no checksum" in said[0], said
    assert len(computed) == 1
    assert df.equals(scan_reference)
    _, said, computed = resume_scan(out)  # rewritten with one: trusted from now on
    assert said == [] and computed == []


def test_basins_resume_past_flipped_bits(tmp_path, basin_reference, basin_written):
    # Before checksums: a flip that left a chunk readable with its row count was
    # trusted, whatever it changed.
    files = chunk_files(basin_written)
    assert len(files) == 4
    clean = tmp_path / "clean"
    shutil.copytree(basin_written, clean)
    before = {f.name: f.stat().st_mtime_ns for f in chunk_files(clean)}
    table, said = resume_basins(clean)
    assert said == [] and table.equals(basin_reference)
    assert {f.name: f.stat().st_mtime_ns for f in chunk_files(clean)} == before
    for k, (i, bit) in enumerate(flips(files, random.Random(31), BASIN_FLIPS)):
        out = tmp_path / f"flip{k}"
        shutil.copytree(basin_written, out)
        f = chunk_files(out)[i]
        flip(f, bit)
        others = {g.name: g.stat().st_mtime_ns for g in chunk_files(out) if g != f}
        table, said = resume_basins(out)
        assert len(said) == 1 and str(f) in said[0], (k, i, bit, said)
        assert aside(f).exists()
        assert {g: (out / g).stat().st_mtime_ns for g in others} == others
        assert table.equals(basin_reference), (k, i, bit)


def test_basins_chunk_copied_over_another_is_set_aside(tmp_path, basin_reference,
                                                       basin_written):
    # Same grid, same row count: before, the copy was trusted and the table held
    # chunk 2's starts twice.
    out = tmp_path / "b"
    shutil.copytree(basin_written, out)
    files = chunk_files(out)
    shutil.copyfile(files[2], files[1])
    table, said = resume_basins(out)
    assert len(said) == 1 and str(files[1]) in said[0], said
    assert "holds chunk 2" in said[0] and "not chunk 1" in said[0], said
    assert aside(files[1]).exists()
    assert table.equals(basin_reference)
    assert table.select("b1", "b2").unique().height == 16
