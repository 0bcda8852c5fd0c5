"""Parallel parameter scans returning polars tables.

The grid is cut into blocks along its last parameter (seeding and continuation stay
inside a block), and blocks are grouped into chunks (files, progress, tasks). A block's
rows depend only on the grid, the options and the block's bounds, so the table is the
same for any chunk length, whether the chunks run here on any number of threads, on an
executor's workers (``concurrent.futures`` or a Dask ``Client``), or partly now and
partly after an interruption or a crash (``out=``).
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from types import FrameType
from typing import Any, Literal, overload

import numpy as np
import polars as pl

from . import _check, _native
from ._progress import Progress
from .exceptions import (
    InternalError,
    ParameterError,
    ParameterTypeError,
    ScanInterrupted,
    ScanStoreError,
    ScanStoreWarning,
)
from .model import Balancer
from .options import (
    REMOVED_KEYWORDS,
    SCAN_DEFAULTS,
    ScanOptions,
    _Execution,
    refuse_keywords,
    with_harmonics,
)
from .scene import Scene, model_argument

try:
    import fcntl
except ImportError:  # pragma: no cover - not on POSIX: scan directories are not locked
    fcntl = None  # type: ignore[assignment]

#: The parameter registry as the core serves it (``_native.parameters()``): the names,
#: owners and ranges every model's parameters are checked with.
PARAMETERS: tuple[dict[str, Any], ...] = tuple(_native.parameters())
#: The planar balancer's parameters a scan can vary (per-ball ones also one ball at a
#: time, ``eta2`` for the second ball).
SCANNABLE: tuple[str, ...] = tuple(p["key"] for p in PARAMETERS if p["key"] and p["planar"])
#: Scene parameters a scan can vary besides the balancer's: the core takes each only from
#: a scene that has its component (the tilt's with a tilting disk, ``rho``,
#: ``depth_ratio`` and ``groove_angle`` on a bearing support) and refuses a value that
#: makes the scene time-dependent (gravity above 0).
SCENE_SCANNABLE: tuple[str, ...] = tuple(p["key"] for p in PARAMETERS
                                         if p["key"] and not p["planar"])

GridSpec = Sequence[float] | np.ndarray | tuple[float, float, float] | str

MULTIPLIER = pl.List(pl.Struct({"re": pl.Float64, "im": pl.Float64}))
#: polars' dtype for each column type of the core's schema.
_DTYPES: dict[str, Any] = {"float": pl.Float64, "count": pl.Int64, "flag": pl.Boolean,
                           "label": pl.Utf8, "multipliers": MULTIPLIER}
#: A scan table's columns after the axes and their index columns, as the core serves
#: them (``_native.scan_schema()``), with their polars dtypes.
SCHEMA: dict[str, Any] = {name: _DTYPES[kind] for name, kind in _native.scan_schema()}


def grid_values(name: str, spec: GridSpec) -> np.ndarray:
    """The values of one grid axis (:func:`ballbal._check.axis`, shared by every gridded
    function): ``(start, stop, step)`` or ``"start:stop:step"`` (both ends included),
    or a sequence or array of explicit values. Whether a model has the parameter
    ``name`` is the core's to say (:func:`scan` asks it before any work)."""
    if spec is None or isinstance(spec, (bool, np.bool_)):
        raise ParameterTypeError(name, f"grid values must be numbers, got {spec!r}")
    return _check.axis(name, spec)


@dataclass(frozen=True)
class _Job:
    """Everything one chunk needs: picklable, so it can travel to other processes."""

    model: Balancer | Scene
    names: tuple[str, ...]
    values: tuple[tuple[float, ...], ...]
    patterns: tuple[str, ...]
    #: With ``block`` set: values of the last axis per continuation block (the
    #: numerical unit).
    options: ScanOptions
    #: Values of the last axis per chunk (whole blocks: the unit of files, progress and
    #: interruption).
    chunk: int

    @property
    def block(self) -> int:
        assert self.options.block is not None
        return self.options.block

    def native(self, chunks: list[int], threads: int,
               on_chunk: Callable[[int, dict[str, Any]], None]) -> None:
        _native.scan(self.model, list(self.names), [list(v) for v in self.values],
                     list(self.patterns), self.options, self.chunk, threads, chunks, on_chunk)

    def n_chunks(self) -> int:
        return math.ceil(len(self.values[-1]) / self.chunk)

    def points(self, c: int) -> int:
        outer = len(self.values[-1])
        inner = math.prod(len(v) for v in self.values[:-1])
        return inner * (min(outer, (c + 1) * self.chunk) - c * self.chunk)

    def meta(self) -> dict[str, Any]:
        return {
            "ballbal": _native.__version__,
            **({"scene": self.model.to_dict()} if isinstance(self.model, Scene)
               else {"balancer": asdict(self.model)}),
            "grid": {n: list(v) for n, v in zip(self.names, self.values, strict=True)},
            "patterns": list(self.patterns), "options": _meta_options(self.options),
            "block": self.block, "chunk": self.chunk,
            # A store written with other columns is not resumed into this table.
            # (the axes' index columns named generically: the axes are compared apart)
            "columns": [_index_name("<axis>"), *SCHEMA],
            "model_columns": list(self.model_values()),
        }

    def model_values(self) -> dict[str, float]:
        """The model's parameters that are not axes, as the table's columns carry them."""
        return {k: v for k, v in _model_values(self.model).items() if k not in self.names}


def _differences(old: Mapping[str, Any], new: Mapping[str, Any], prefix: str = "") -> list[str]:
    """The keys whose values differ, nested dictionaries' as ``outer.inner``, so that the
    error says which option differs rather than "options"."""
    out: list[str] = []
    for k in sorted(old.keys() | new.keys()):
        a, b = old.get(k), new.get(k)
        if isinstance(a, dict) and isinstance(b, dict):
            out += _differences(a, b, f"{prefix}{k}.")
        elif a != b:
            out.append(prefix + k)
    return out


def _meta_options(o: ScanOptions) -> dict[str, Any]:
    """The options as the scan's description records them (its fingerprint): the flat
    keywords of before the option classes, in their order, so that directories written
    then resume; ``guess_atol`` only where it is not ``guess_rtol / 1000`` (what those
    keywords implied). The Floquet method only where it is not RK45: directories written
    before it was an option hold RK45 multipliers; they resume with
    ``floquet_method="rk45"`` and are refused with any other method. Hill's target only
    where Hill runs and it is not ``"multipliers"`` (what every earlier Hill verdict
    used), likewise; Hill's band only where Hill runs with one (earlier Hill verdicts
    were given beside every monodromy). A band without a monodromy runs no Hill and is
    recorded as Hill off, as ``floquet=False`` scans were."""
    h, f, g = o.harmonic_balance, o.floquet, o.guess
    # A band without a monodromy runs no Hill: the same table as Hill off.
    hill = f.hill and (f.monodromy or f.hill_band is None)
    d: dict[str, Any] = {
        "N": h._start, "auto": h._auto_target, "N_max": h.N_max, "hill": hill,
        "samples": h.samples, "tol": h.tol, "step_tol": h.step_tol, "max_iter": h.max_iter,
        "floquet": f.monodromy, "rtol": f.rtol, "atol": f.atol, "margin": f.margin,
        "max_steps": f.max_steps, "settle": g.settle, "window": g.window,
        "guess_rtol": g.rtol, "seeds": g.seeds, "starts": g.starts, "max_tail": o.max_tail,
        "max_closure": o.max_closure, "max_trivial": f.max_trivial,
    }
    if f.method != "rk45":
        d["floquet_method"] = f.method
    if hill and f.hill_target != "multipliers":
        d["hill_target"] = f.hill_target
    if hill and f.hill_band is not None:
        d["hill_band"] = f.hill_band
    if g.atol != g.rtol * 1e-3:
        d["guess_atol"] = g.atol
    return d


def _multipliers(re_rows: Sequence[Any], im_rows: Sequence[Any]) -> pl.Series:
    """The ``multipliers`` column (null where a row has none) from per-row lists of real
    and imaginary parts."""
    lens = {len(r) for r in re_rows if r is not None}
    if len(lens) == 1 and 0 not in lens:
        # One length (the usual case): from flat arrays, since a list of dicts per row
        # made polars build one struct per row, a quarter of a fine-grid scan's time.
        k = lens.pop()
        zero = [0.0] * k
        flat = pl.DataFrame({
            "re": np.array([zero if r is None else r for r in re_rows], dtype=np.float64).ravel(),
            "im": np.array([zero if r is None else r for r in im_rows], dtype=np.float64).ravel(),
        }).to_struct("multipliers")
        lists = flat.reshape((len(re_rows), k)).arr.to_list()
        present = pl.Series([r is not None for r in re_rows], dtype=pl.Boolean)
        return pl.select(pl.when(present).then(lists).otherwise(None)
                         .alias("multipliers")).to_series().cast(MULTIPLIER)
    mult = [
        None if re is None else [{"re": r, "im": i} for r, i in zip(re, im, strict=True)]
        for re, im in zip(re_rows, im_rows, strict=True)
    ]
    return pl.Series("multipliers", mult, dtype=MULTIPLIER)


def _model_values(model: Balancer | Scene) -> dict[str, float]:
    """Every balancer parameter of ``model``, ball-indexed ones per ball (``eta1``,
    ``zeta_b2``, the grid axes' spelling), so that a table says what model its rows
    are of wherever it goes (a CSV file, a join of two scans)."""
    b = model.balancer if isinstance(model, Scene) else model
    n = b.n_balls
    zeta_b = b.zeta_b if isinstance(b.zeta_b, tuple) else (b.zeta_b,) * n
    ball = _native.ball_parameter_name
    return {"mu": b.mu, "zeta": b.zeta, **{ball("zeta_b", i): z for i, z in enumerate(zeta_b)},
            "delta": b.delta, "Omega": b.Omega, **{ball("eta", i): e for i, e in enumerate(b.eta)}}


def _index_name(axis: str) -> str:
    """The column of an axis value's position on its axis (``Omega_index``)."""
    return f"{axis}_index"


def _frame(job: _Job, d: dict[str, Any]) -> pl.DataFrame:
    mult = _multipliers(d["mult_re"], d["mult_im"])
    names = job.names
    cols: dict[str, pl.Series] = {n: pl.Series(n, d[n], dtype=pl.Float64) for n in names}
    for n, vals in zip(names, job.values, strict=True):
        # The rows carry the grid's own floats, so each maps to its position exactly.
        # With numpy, not a polars expression: executors run this in forked workers,
        # where polars' thread pool (started in the parent) never answers.
        grid = np.asarray(vals, dtype=np.float64)
        order = np.argsort(grid, kind="stable")
        at = order[np.searchsorted(grid[order], np.asarray(d[n], dtype=np.float64))]
        cols[_index_name(n)] = pl.Series(_index_name(n), at, dtype=pl.Int64)
    for c, dtype in SCHEMA.items():
        cols[c] = mult if c == "multipliers" else pl.Series(c, d[c], dtype=dtype)
    rows = len(d["type"])
    for k, v in job.model_values().items():
        family = _native.parse_parameter(k)[0]
        # A ball's value under an axis that sets every ball's is that axis' value.
        cols[k] = (cols[family].alias(k) if family in names
                   else pl.Series(k, [v], dtype=pl.Float64).new_from_index(0, rows))
    return pl.DataFrame(cols)


def _empty(names: Sequence[str], model_columns: Sequence[str]) -> pl.DataFrame:
    return pl.DataFrame(schema={**{n: pl.Float64 for n in names},
                                **{_index_name(n): pl.Int64 for n in names}, **SCHEMA,
                                **{k: pl.Float64 for k in model_columns}})


def run_chunk(job: _Job, c: int, threads: int = 1) -> pl.DataFrame:
    """One chunk of a scan as a DataFrame: what executors run on their workers."""
    out: list[pl.DataFrame] = []
    job.native([c], threads, lambda _c, d: out.append(_frame(job, d)))
    return out[0]


#: Parquet key-value metadata entry holding the fingerprint of the scan a chunk belongs
#: to, so that a chunk is trusted only for the scan that wrote it (even when the
#: description file itself was damaged and had to be rewritten).
_FINGERPRINT = "ballbal_scan"
_CHUNK_FILE = re.compile(r"chunk-(\d{5,})\.parquet")
#: Parquet key-value entry holding the scan's description (:meth:`_Job.meta` as JSON:
#: model, grid, patterns, options, layout) in the directory's description file.
_DESCRIPTION = "ballbal_scan_description"
#: The description file: a Parquet file of no rows with the table's columns, the
#: description, the scan's fingerprint and a checksum (as a chunk's) in its key-value
#: metadata. Not a ``meta.json``: polars reads a directory only when every file in it is
#: Parquet (it skips no name by default, not even a leading ``.`` or ``_``, only empty
#: files), and a file of no rows with the same columns adds nothing to the table. The
#: leading ``_`` is what pyarrow and Spark datasets skip (as their ``_common_metadata``,
#: the same idea). One file, not a copy in every chunk: the description holds every
#: axis value, which in every chunk would grow as the square of a long axis.
_DESCRIPTION_FILE = "_scan.parquet"
#: Parquet key-value entry holding the chunk's number, so that a chunk copied or renamed
#: to another position of the same grid is not taken for that position's: the basin
#: store's rows are checked only by their count, and a checksum travels with its file.
_CHUNK_KEY = "ballbal_chunk"
#: Parquet key-value entry holding a SHA-256 of the chunk file's own bytes.
#:
#: Why the file's bytes and not the decoded table: a flip in the footer can leave the
#: rows as they were and still change what is read, e.g. a column's min/max statistics,
#: which polars' lazy scans use to skip row groups (``lazy=True`` tables), so a hash
#: of the content would pass a file that filters wrong. Hashing the bytes needs no
#: canonical serialisation, costs one pass of SHA-256 over what was just written, and
#: is checked before polars parses anything (a damaged file never reaches its decoder).
#:
#: Why inside the file and not in a sidecar or a manifest: a chunk stays one file
#: written by one atomic rename, so no crash can leave a chunk and its checksum out of
#: step (a sidecar needs an order of two renames, and a manifest a rewrite per chunk),
#: and a chunk copied elsewhere carries its own checksum.
#:
#: A checksum cannot cover itself: the file is written with ``_UNSEALED`` as the value,
#: hashed, and the value is overwritten with the digest (the same length, so no offset
#: in the file moves); the check puts ``_UNSEALED`` back and hashes again. Any changed
#: byte elsewhere changes the hash, and a changed digest no longer matches it.
_CHECKSUM = "ballbal_sha256"
_UNSEALED = b"0" * 64
#: The key's bytes as the footer holds them (Thrift compact protocol, as every Parquet
#: footer): the key, the value's field header and length (1 byte each for a 64-byte
#: string), then the value.
_CHECKSUM_KEY = _CHECKSUM.encode()
_CHECKSUM_AT = len(_CHECKSUM_KEY) + 2
_HEX = re.compile(rb"[0-9a-f]{64}")


def _fingerprint(meta: Mapping[str, Any]) -> str:
    return hashlib.sha256(json.dumps(meta).encode()).hexdigest()


def _sealed(df: pl.DataFrame, metadata: Mapping[str, str]) -> bytes:
    """``df`` as the bytes of a Parquet file with ``metadata`` and its checksum (see
    ``_CHECKSUM``)."""
    buf = io.BytesIO()
    df.write_parquet(buf, metadata={**metadata, _CHECKSUM: _UNSEALED.decode()})
    data = bytearray(buf.getvalue())
    at = data.find(_CHECKSUM_KEY)
    if (at < 0 or data.find(_CHECKSUM_KEY, at + 1) >= 0
            or data[at + _CHECKSUM_AT:at + _CHECKSUM_AT + 64] != _UNSEALED):
        # The writer laid out its footer otherwise: no chunk is written that the check
        # would refuse.
        raise InternalError("the Parquet writer did not store the chunk checksum where "
                            "expected")
    data[at + _CHECKSUM_AT:at + _CHECKSUM_AT + 64] = \
        hashlib.sha256(data).hexdigest().encode()
    return bytes(data)


def _checksum_problem(data: bytes) -> str | None:
    """Why the bytes of a chunk file are not the ones written (see ``_CHECKSUM``), or
    ``None``."""
    at = data.rfind(_CHECKSUM_KEY)
    if at < 0:
        return "it carries no checksum (written before chunks had one, or its footer is damaged)"
    digest = data[at + _CHECKSUM_AT:at + _CHECKSUM_AT + 64]
    if data.find(_CHECKSUM_KEY) != at or not _HEX.fullmatch(digest):
        return "its checksum is damaged"
    h = hashlib.sha256(data[:at + _CHECKSUM_AT])
    h.update(_UNSEALED)
    h.update(data[at + _CHECKSUM_AT + 64:])
    if h.hexdigest().encode() != digest:
        return "its bytes do not match its checksum"
    return None


def _sealed_problem(f: Path, fingerprint: str, c: int,
                    what: str = "scan") -> tuple[str | None, bytes]:
    """Why chunk file ``f`` is not chunk ``c`` as this ``fingerprint``'s store wrote it,
    or ``None``; and the file's bytes."""
    try:
        data = f.read_bytes()
    except OSError as e:
        return f"unreadable: {type(e).__name__}: {e}", b""
    why = _checksum_problem(data)
    if why is not None:
        return why, data
    try:
        # Past the checksum the bytes are the ones written: polars reads its own file.
        kv = pl.read_parquet_metadata(io.BytesIO(data))
    except Exception as e:  # noqa: BLE001 - any failure to read means a damaged file
        return f"unreadable: {type(e).__name__}", data
    if kv.get(_FINGERPRINT) != fingerprint:
        return f"it was not written by this {what}", data
    if kv.get(_CHUNK_KEY) != str(c):
        return f"it holds chunk {kv.get(_CHUNK_KEY)} of this {what}, not chunk {c}", data
    return None, data


def _chunk_index(f: Path) -> int | None:
    m = _CHUNK_FILE.fullmatch(f.name)
    return int(m.group(1)) if m else None


def _caller() -> int:
    """The ``stacklevel`` of the first frame outside ballbal, seen from the function
    that calls this one: warnings then point at the user's line."""
    here = str(Path(__file__).parent)
    f: FrameType | None = sys._getframe(1)
    level = 1
    while f is not None and f.f_code.co_filename.startswith(here):
        f, level = f.f_back, level + 1
    return level


def _sync_dir(d: Path) -> None:
    # The rename itself must reach the disk, or a crash can bring back the old name.
    try:
        fd = os.open(d, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _write_atomic(path: Path, write: Callable[[Any], None]) -> None:
    """Write through ``write(file)`` to a temporary file, flush it to disk, then rename:
    ``path`` is always either the old complete file or the new complete one."""
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "wb") as fh:
        write(fh)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    _sync_dir(path.parent)


def _chunk_problem(f: Path, meta: Mapping[str, Any], c: int | None) -> str | None:
    """Why chunk file ``f`` (number ``c``) cannot be trusted for the scan ``meta``, or
    ``None``; reads the whole file."""
    if c is None:
        return "not a chunk file name"
    names = list(meta["grid"])
    values = [meta["grid"][n] for n in names]
    patterns = meta["patterns"]
    chunk = int(meta["chunk"])
    lo, hi = c * chunk, min(len(values[-1]), (c + 1) * chunk)
    if lo >= hi:
        return f"chunk {c} is outside the grid"
    why, data = _sealed_problem(f, _fingerprint(meta), c)
    if why is not None:
        return why
    try:
        df = pl.read_parquet(io.BytesIO(data))
    except Exception as e:  # noqa: BLE001 - any failure to read means a damaged file
        return f"unreadable: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"
    if df.schema != _empty(names, meta.get("model_columns", [])).schema:
        return "its columns are not a scan table's"
    wanted = [set(v) for v in values[:-1]] + [set(values[-1][lo:hi])]
    for n, w in zip(names, wanted, strict=True):
        if not set(df[n].to_list()) <= w:
            return f"it holds {n} values outside chunk {c}"
    if not set(df["type"].to_list()) <= set(patterns):
        return "it holds other solution types"
    # Values within the chunk's, and as many distinct (point, type) pairs as the chunk
    # has: every point and type is there.
    expected = math.prod(len(w) for w in wanted) * len(set(patterns))
    if df.select([*names, "type"]).unique().height != expected:
        return "it misses points of the chunk"
    return None


_LEGACY_META = "meta.json"


def _chunk_order(f: Path) -> tuple[int, str]:
    # In chunk order, also past chunk 99999 (where names stop sorting as numbers).
    c = _chunk_index(f)
    return (-1 if c is None else c, f.name)


def _chunk_files(d: Path) -> list[Path]:
    return sorted(d.glob("chunk-*.parquet"), key=_chunk_order)


def _description_problem(f: Path, kind: str = "grid") -> tuple[dict[str, Any] | None,
                                                             str | None]:
    """The description in the description file ``f`` (see ``_DESCRIPTION_FILE``), or why it
    cannot be trusted: its bytes changed since written (checksum), no description in its
    metadata, or not one of ``kind`` (``grid`` for a scan, ``basins`` for a basin grid)."""
    try:
        data = f.read_bytes()
    except FileNotFoundError:
        return None, "missing: not a scan directory"
    except OSError as e:
        return None, f"unreadable: {type(e).__name__}: {e}"
    why = _checksum_problem(data)
    if why is not None:
        return None, why
    try:
        meta = json.loads(pl.read_parquet_metadata(io.BytesIO(data))[_DESCRIPTION])
    except Exception as e:  # noqa: BLE001 - no description, or not JSON: damaged
        return None, f"unreadable: {type(e).__name__}"
    if not isinstance(meta, dict) or not isinstance(meta.get(kind), dict):
        return None, "not a scan description"
    return meta, None


def _read_description(d: Path) -> dict[str, Any]:
    """The description of the scan in ``d``; ScanStoreError naming its file when it is
    damaged."""
    f = d / _DESCRIPTION_FILE
    meta, why = _description_problem(f)
    if meta is None:
        raise ScanStoreError(f"path: {f} is damaged ({why}); run the same scan with "
                             "out= again to rewrite it")
    return meta


class _Store:
    """Finished chunks as Parquet files in a directory, with the scan's description in a
    Parquet file of no rows (``_DESCRIPTION_FILE``), so that the directory holds nothing
    but the table: ``polars.read_parquet(dir)`` reads it.

    The directory itself is locked (``fcntl.flock`` on its descriptor) while a scan uses
    it: the kernel drops the lock when the process ends, even when killed, and no lock
    file is needed that polars would have to skip. ``.lock`` only tells another scan
    which process holds the lock; it is removed when the scan ends, however it ends (a
    killed process leaves it until the directory's next scan). Every file is written
    atomically, and every chunk carries the scan's fingerprint, its chunk number and a
    checksum of its bytes (``_CHECKSUM``); on opening, a file that cannot be trusted
    (unreadable, truncated, changed, of another scan or position, missing points) is set
    aside (``_set_aside``) with a :class:`ScanStoreWarning` and recomputed.
    """

    def __init__(self, path: str | os.PathLike[str], job: _Job, chunk_given: bool) -> None:
        self.dir = Path(path)
        try:
            self.dir.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise ScanStoreError(f"out: cannot create the directory {self.dir}: {e}") from e
        self._lock: int | None = self._acquire()
        try:
            self.job = self._open(job, chunk_given)
        except BaseException:
            self.close()
            raise

    @property
    def _holder(self) -> Path:
        return self.dir / ".lock"

    def _acquire(self) -> int | None:
        if fcntl is None:
            return None
        try:
            fd = os.open(self.dir, os.O_RDONLY)
        except OSError as e:
            raise ScanStoreError(f"out: cannot use the directory {self.dir}: {e}") from e
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            try:
                who = self._holder.read_text().strip()
            except (OSError, UnicodeDecodeError):
                who = ""
            raise ScanStoreError(
                f"out: {self.dir} is in use by another scan"
                + (f" (process {who})" if who.isdigit() else "")
                + "; wait for it to finish or choose another directory") from None
        try:
            self._holder.write_text(f"{os.getpid()}\n")
        except OSError:
            pass  # only the message of a refused second scan loses the process number
        return fd

    def close(self) -> None:
        if self._lock is None:
            return
        # The holder file goes first, while the lock is still held: a scan that opens
        # the directory next writes its own.
        self._holder.unlink(missing_ok=True)
        fcntl.flock(self._lock, fcntl.LOCK_UN)
        os.close(self._lock)
        self._lock = None

    @property
    def set_aside_dir(self) -> Path:
        """Where damaged files go: beside the directory, not in it, so that what is in
        it stays one Parquet dataset (``<out>.damaged``)."""
        d = self.dir.resolve()
        return d.with_name(d.name + ".damaged")

    def _set_aside(self, f: Path, why: str, then: str) -> None:
        dest = self.set_aside_dir / f.name
        try:
            dest.parent.mkdir(exist_ok=True)
            os.replace(f, dest)
        except OSError:
            # Not beside it (another file system, no permission): in place, as before.
            dest = f.with_name(f.name + ".damaged")
            os.replace(f, dest)
        warnings.warn(ScanStoreWarning(f"out: {f} is damaged ({why}); set aside as "
                                       f"{dest} and {then}"), stacklevel=_caller())

    def _old_description(self, kind: str) -> dict[str, Any] | None:
        """The description the directory holds, if it can be trusted; a damaged one is
        set aside (the chunks are still checked by their fingerprints), and so is a
        ``meta.json`` of ballbal 0.1, which would stop polars reading the directory."""
        legacy = self.dir / _LEGACY_META
        if legacy.exists():
            self._set_aside(legacy, "the description of ballbal 0.1, which polars cannot "
                            "read among the chunks", "replaced by "
                            f"{_DESCRIPTION_FILE}; the chunks are checked by their "
                            "fingerprints")
        f = self.dir / _DESCRIPTION_FILE
        if not f.exists():
            return None
        old, why = _description_problem(f, kind)
        if old is None:
            self._set_aside(f, why or "", "rewritten; the chunks are checked by their "
                            "fingerprints")
        return old

    def _describe(self, meta: dict[str, Any], empty: pl.DataFrame) -> None:
        """Record ``meta`` as the directory's description, in a file of no rows with the
        table's columns ``empty``."""
        self.meta = meta
        self.fingerprint = _fingerprint(meta)
        f = self.dir / _DESCRIPTION_FILE
        if not f.exists():
            _write_atomic(f, lambda fh: fh.write(_sealed(empty, {
                _FINGERPRINT: self.fingerprint, _DESCRIPTION: json.dumps(meta)})))
        for tmp in self.dir.glob(".*.tmp"):  # left by a crash; the lock says nobody writes
            tmp.unlink(missing_ok=True)

    def _open(self, job: _Job, chunk_given: bool) -> _Job:
        # As it reads back from JSON (tuples become lists), to compare with the file's.
        meta = json.loads(json.dumps(job.meta()))
        old = self._old_description("grid")
        if old is not None:
            same = {k: v for k, v in old.items() if k != "chunk"} == {
                k: v for k, v in meta.items() if k != "chunk"}
            stored = old.get("chunk")
            if (same and not chunk_given and isinstance(stored, int) and stored > 0
                    and stored % job.block == 0):
                # The table does not depend on the chunk length: keep the directory's.
                job = replace(job, chunk=stored)
                meta["chunk"] = stored
            if old != meta:
                diff = _differences(old, meta)
                hint = ""
                if old.get("options", {}).get("hill") is False and "options.hill" in diff:
                    hint = (" (scans written before 2026-11-24 ran without Hill's "
                            "cross-check by default: Floquet(hill=False) resumes them)")
                raise ScanStoreError(
                    f"out: {self.dir} holds a different scan (it differs in "
                    f"{', '.join(diff)}){hint}; choose another directory or delete it")
            if list(old["grid"]) != list(meta["grid"]):
                # Same axes, other order: the chunks would be cut along another axis.
                raise ScanStoreError(
                    f"out: {self.dir} holds this scan with its axes in the order "
                    f"{', '.join(old['grid'])}; give them in that order to resume it")
        self._describe(meta, _empty(job.names, list(job.model_values())))
        return job

    def file(self, c: int) -> Path:
        return self.dir / f"chunk-{c:05d}.parquet"

    def done(self) -> set[int]:
        """The chunks on disk that can be trusted; the others are set aside."""
        ok = set()
        for f in _chunk_files(self.dir):
            c = _chunk_index(f)
            why = _chunk_problem(f, self.meta, c)
            if why is None and c is not None:
                ok.add(c)
            else:
                self._set_aside(f, why or "", "recomputed")
        return ok

    def write(self, c: int, df: pl.DataFrame) -> None:
        _write_atomic(self.file(c), lambda fh: fh.write(
            _sealed(df, {_FINGERPRINT: self.fingerprint, _CHUNK_KEY: str(c)})))

    def files(self, chunks: Iterable[int]) -> list[Path]:
        return [self.file(c) for c in sorted(chunks)]


def _interrupted(work: Callable[[], None]) -> bool:
    """Runs ``work()``; True if Ctrl-C stopped it. One Ctrl-C can arrive twice: when it
    lands while polars writes a chunk, polars raises a KeyboardInterrupt of its own and
    Python's handler, still pending, raises another at the next opportunity (entering
    the handler below, or the call in it). Both are this one interrupt."""
    try:
        try:
            work()
        except KeyboardInterrupt:
            _pending()
            return True
    except KeyboardInterrupt:
        return True
    return False


def _pending() -> None:
    """Nothing: calling it is where a pending Ctrl-C is raised."""


def _as_completed(futures: list[Any]) -> Iterable[Any]:
    if futures and type(futures[0]).__module__.startswith("distributed"):
        from distributed import as_completed

        return as_completed(futures)
    from concurrent.futures import as_completed as cf_as_completed

    return cf_as_completed(futures)


@overload
def scan(model: Balancer | Scene, *, lazy: Literal[False] = ...,
         **kwargs: Any) -> pl.DataFrame: ...
@overload
def scan(model: Balancer | Scene, *, lazy: Literal[True], **kwargs: Any) -> pl.LazyFrame: ...
def scan(  # noqa: E302 - overloads above
    model: Balancer | Scene,
    *,
    patterns: Sequence[str] = ("R-R",),
    N: int | Literal["auto"] | None = None,  # noqa: N803
    options: ScanOptions | None = None,
    chunk: int | None = None,
    threads: int | None = None,
    progress: bool | Callable[[int, int], Any] = False,
    out: str | os.PathLike[str] | None = None,
    lazy: bool = False,
    executor: Any = None,
    grid: Mapping[str, GridSpec] | None = None,
    **axes: GridSpec,
) -> pl.DataFrame | pl.LazyFrame:
    """Scan parameters of ``model`` over a grid and return one row per solution found.

    Axes are keywords (``Omega=(1.0, 2.0, 0.1), eta=np.arange(0.4, 1.51, 0.1)``) or a
    ``grid`` mapping; a per-ball name sets one ball (``eta1=...``, balls named from 1).
    Each is a sequence, ``(start, stop, step)`` or ``"start:stop:step"``. Any number of
    axes; the first varies fastest in the table.

    ``patterns``: the solution types, each a rotation pattern (one letter per ball, ``R``
    turning round the track, ``O`` oscillating, joined by ``-``: ``"R-R"``, ``"R-O"``) or
    a pattern followed by the balls' whole turns per period in brackets, for orbits that
    wind more than once per period: ``"R-R[-2,-2]"`` (each ball makes two turns per
    period, as balls rotating separately do when their turns alternate in length),
    ``"O-R[0,-2]"`` (a period-doubled O-R orbit). The ``type`` column holds the name as
    given. A type's rows do not depend on which other types are asked for. A wound
    type's series has ``N`` harmonics per turn (``N`` column: 6 for ``"R-R[-2,-2]"`` at
    ``N=3``). Seeds are observed over as many turns as the most wound type asks for; a
    period-doubled type is also started from every orbit of the type it doubles that has
    a real multiplier below -1 (past a period doubling), displaced along that
    multiplier's mode (``origin`` ``period_doubling``), and that type is solved,
    unreported, where it was not asked for. A series that is a shorter orbit written
    several times (a doubled branch at its period doubling) is neither reported nor
    continued.

    ``options``: a :class:`~ballbal.ScanOptions` (what is computed; default
    :data:`ballbal.options.SCAN_DEFAULTS`, whose tolerances and guess search differ from
    :func:`~ballbal.periodic`'s on purpose: see :mod:`ballbal.options`); ``N``: the
    harmonics (``options.harmonic_balance.N`` when given). The flat option keywords of
    before (``hill=``, ``seeds=``, ``block=``, ...) are refused with a
    :class:`~ballbal.exceptions.ParameterTypeError` naming the field that replaces each
    (they are no parameters, so never axes).

    Where it runs, which never changes the table: ``threads`` (cores for the core's
    parallel loop; default all here, 1 per task on an ``executor``), ``chunk`` (values
    of the last axis per chunk, rounded up to whole blocks; default one block: the unit
    of progress, interruption, resumption, files and executor tasks), ``executor`` (a
    ``concurrent.futures`` executor or Dask ``Client`` running the chunks as tasks),
    ``progress`` (True for a progress bar, or a callable ``f(done_points,
    total_points)``), ``out`` (a directory the chunks are written to and resumed from)
    and ``lazy`` (a ``polars.LazyFrame`` over its files).

    ``model`` may be an autonomous :class:`Scene` (ball springs, a tilting disk): its
    ``springs`` and tilt fields ``a``, ``b``, ``j_t``, ``j_z``, ``zeta_r`` can be axes
    too, and ``pb_exists``, ``pb_stable`` then describe its balanced state (see
    :func:`balanced_state`). A scene with a ramp, gravity or an impulse is time
    dependent and has no periodic solutions to scan: that is an error naming the effect.

    The grid is cut along its last axis into blocks of ``block`` values (default: about
    1024 points, fixed by the grid's shape). Each block is solved in the Rust core on
    ``threads`` cores with the GIL released: simulated starts at ``seeds`` points per
    axis (and along the perfect balance's stability boundary) are classified by
    rotation pattern; for types in which some balls rotate and others rest on the disk
    (R-O, O-R), the ``seeds`` points are also simulated from whirl starts (rotating
    balls turning at the natural frequency in the ground frame, the disk on its resonant
    response to them), since such stable orbits are reached from rest only from a
    sliver of starts; then every solution is continued to its grid neighbours until
    nothing new appears. Then every point where the perfect balance is not stable and a
    type has no stable row yet is simulated from a start at rest (a *gap seed*: a
    narrow stable band between seed points would otherwise be missed; on grids of two
    or more axes, the points of even index along every axis), and what it finds is
    continued in turn. ``origin`` says how a row's solution was reached:
    ``seed`` (simulated start at that point), ``gap_seed`` (a gap seed at that point),
    ``continuation`` (from a neighbour),
    ``period_doubling`` (from the orbit it doubles, see ``patterns``), ``none`` (no
    solution). Continuation does not cross block edges, so
    ``block`` is a numerical option (smaller blocks find fewer continued solutions);
    the table depends on it and on nothing else of the layout. Coexisting solutions of
    one type get separate rows (``solution`` 0, 1, ...); a point and type with none gets
    one row with ``status="not_found"`` and nulls. ``max_tail`` refuses series whose
    last harmonic is that large relative to the motion (``N`` too small). Every solution
    is certified as in :func:`~ballbal.periodic` (``max_closure``, ``max_trivial``, the
    same defaults): a series that fails is neither reported nor continued (a seed's
    series refused by ``max_tail`` or by its closure is first solved again with twice
    and four times ``N`` harmonics, as slow orbits near a rotating branch's
    infinite-period end need; the row's ``N`` says how many it got), and a row
    gets a stability verdict only with an accurate trivial multiplier and a bound on its
    leading modulus' error (``modulus_error``; a row whose verdict the bound leaves open
    is refined to more harmonics first, see :func:`~ballbal.periodic`). The solution
    columns have the names and meaning of :class:`~ballbal.PeriodicSolution`'s fields
    (``pivot_ratio``, ...); the multipliers are a list of ``{re, im}`` (a nested column,
    which ``write_csv`` cannot hold: :func:`ballbal.flat` spreads it into
    ``multipliers_re_0, multipliers_im_0, ...``). After them, the table says what model
    its rows are of: a column for every balancer parameter that is not an axis (``mu``,
    ``zeta``, ``zeta_b1``, ..., ``delta``, ``Omega``, ``eta1``, ..., one per ball; a ball's
    column repeats an axis that sets every ball, such as ``eta``). Columns rather than
    metadata, since a polars DataFrame carries none: they survive every format, filter
    and join. What columns cannot hold (options, a scene's effects) is in the stored
    scan's description, :func:`scan_meta`.

    ``chunk``: values of the last axis per chunk, rounded up to whole blocks (default
    one block): the unit of progress, interruption, resumption, files and executor
    tasks. It never changes the table.

    ``N="auto"``: continuation runs at N = 3 and each solution found is refined until
    its highest harmonic and trivial multiplier error are below ``target`` (at most
    ``N_max``): easy points stay cheap; ``N`` and ``target_met`` say what each row got.
    Hill's method cross-checks the verdicts where they are in doubt: a row whose
    monodromy gives no verdict, or whose leading non-trivial multiplier lies within
    ``floquet.hill_band`` (default 0.2) of the unit circle or within ten times the
    monodromy's own error estimate, gets Hill's verdict (``hill_stability``) and a flag
    where the two contradict each other (``verdicts_disagree``); elsewhere both are null.
    ``hill_band=None`` cross-checks every solution, ``hill=False`` none (both fields of
    ``options.floquet``).

    ``out``: a directory; each finished chunk is written there as Parquet at once
    (atomically), and a later call with the same arguments and ``out`` skips the chunks
    on disk (resume; the axes must be given in the same order). The directory is a
    Parquet dataset: once the scan ends (finished, failed or interrupted) it holds only
    Parquet files, so ``polars.read_parquet(out)`` and ``polars.scan_parquet(out)`` read
    the table: the chunks, and ``_scan.parquet`` (no rows, the table's columns), which
    carries the scan's description in its Parquet metadata (:func:`scan_meta`). Only
    one scan at a time may use a directory (another gets
    :class:`~ballbal.exceptions.ScanStoreError`). A damaged file found on resuming
    (truncated, unreadable, changed since it was written -- every chunk carries a
    SHA-256 of its bytes --, another scan's or another chunk's) is set aside in
    ``<out>.damaged`` beside the directory with a
    :class:`~ballbal.exceptions.ScanStoreWarning` naming it, and recomputed. With
    ``out``, only one chunk per thread is held in memory while the scan runs;
    ``lazy=True`` returns a ``polars.LazyFrame`` over the files instead of reading them
    back, for grids whose table does not fit in memory.
    ``executor``: a ``concurrent.futures`` executor or Dask ``Client``; the chunks run
    as its tasks (``threads`` per task, default 1) and the table is the same as here.
    ``progress``: ``True`` for a progress bar (tqdm if installed), or a callable
    ``f(done_points, total_points)``. Ctrl-C stops the scan and returns the finished
    chunks with a :class:`ScanInterrupted` warning.

    Limits (checked before any work): at most 1e6 values per axis, 5e6 grid points for a
    table held in memory and 1e9 for one streamed to ``out=``.
    """
    model_argument("model", model)
    options = _check.option("options", options, ScanOptions, SCAN_DEFAULTS,
                            "ballbal.ScanOptions")
    execution = _Execution(threads=threads, chunk=chunk, executor=executor,
                           progress=progress, out=out, lazy=lazy)
    if "execution" in axes:
        raise ParameterTypeError("execution", "is no option: where a scan runs is given by "
                                 "its keywords threads=, chunk=, executor=, progress=, out=, "
                                 "lazy=")
    refuse_keywords("scan", ScanOptions, [k for k in axes if k in REMOVED_KEYWORDS])
    options = with_harmonics(options, N)
    p = _check.patterns("patterns", patterns)
    if not p:
        raise ParameterError("patterns", "give at least one solution type, e.g. ['R-R']")
    axes_all: dict[str, GridSpec] = dict(grid or {})
    for k, v in axes.items():
        if k in axes_all:
            raise ParameterError(k, "given twice (keyword and grid)")
        axes_all[k] = v
    if not axes_all:
        raise ParameterError("grid", "give at least one parameter to scan, e.g. "
                             "Omega=(1, 2, 0.1)")
    names = tuple(axes_all)
    if (isinstance(model, Scene) and not model._effects_on()
            and not set(names) & set(SCENE_SCANNABLE)):
        model = model.balancer  # the same table, and a scan directory it can resume
    # The core's own refusal of a name, before any value is read or file written.
    _native.check_axes(model, list(names))
    values = tuple(tuple(grid_values(n, s).tolist()) for n, s in axes_all.items())
    ex = execution
    _check.grid_points([len(v) for v in values], names, streamed=ex.out is not None)
    if ex.lazy and ex.out is None:
        raise ParameterError("lazy", "a lazy table needs out= (it reads the chunk files)",
                             allowed="False without out", value=ex.lazy)
    block = options.block
    if block is None:
        block = _native.default_chunk([len(v) for v in values])
    if block < 1:
        raise ParameterError("block", f"must be >= 1, got {block}", allowed=">= 1",
                             value=block)
    chunk_given = ex.chunk is not None
    n_chunk = block if ex.chunk is None else ex.chunk
    if n_chunk < 1:
        raise ParameterError("chunk", f"must be >= 1, got {n_chunk}", allowed=">= 1",
                             value=n_chunk)
    # Whole blocks per chunk: a split block would continue less (see the Rust core).
    n_chunk = -(-n_chunk // block) * block
    local_threads = (os.cpu_count() or 1) if ex.threads is None else ex.threads
    job = _Job(model, names, values, tuple(str(x) for x in p),
               replace(options, block=block), n_chunk)
    # Validates everything (grid values, combinations, options) before any work.
    job.native([], 1, lambda _c, _d: None)

    store = _Store(ex.out, job, chunk_given) if ex.out is not None else None
    try:
        return _run(job, store, ex.executor, ex.threads, local_threads, ex.progress, ex.lazy)
    finally:
        if store is not None:
            store.close()


def _run(job: _Job, store: _Store | None, executor: Any, threads: int | None,
         local_threads: int, progress: bool | Callable[[int, int], Any],
         lazy: bool) -> pl.DataFrame | pl.LazyFrame:
    if store is not None:
        job = store.job
    n = job.n_chunks()
    # In memory without out=; with out= only the chunk numbers, the rows are on disk.
    frames: dict[int, pl.DataFrame] = {}
    finished: set[int] = store.done() if store is not None else set()
    finished &= set(range(n))
    todo = [c for c in range(n) if c not in finished]
    total = sum(job.points(c) for c in range(n))
    bar = Progress(progress, total, "ballbal scan", unit="pt",
                   done=sum(job.points(c) for c in finished))

    def keep(c: int, df: pl.DataFrame) -> None:
        if store is not None:
            store.write(c, df)
        else:
            frames[c] = df
        finished.add(c)
        bar.update(job.points(c))

    def work() -> None:
        if todo and executor is not None:
            per_task = 1 if threads is None else local_threads
            futures = [executor.submit(run_chunk, job, c, per_task) for c in todo]
            index = dict(zip(futures, todo, strict=True))
            try:
                for f in _as_completed(futures):
                    keep(index[f], f.result())
            except KeyboardInterrupt:
                for f in futures:
                    f.cancel()
                raise
        elif todo:
            job.native(todo, local_threads, lambda c, d: keep(c, _frame(job, d)))

    try:
        if _interrupted(work):
            if store is not None:
                # Ctrl-C can land between a chunk's atomic rename and `finished.add`: a
                # file that exists is whole, so it belongs to the table returned now.
                finished |= {c for c in todo if store.file(c).exists()}
            warnings.warn(
                ScanInterrupted(
                    f"scan interrupted: {len(finished)} of {n} chunks finished"
                    + (f" and kept in {store.dir}; run the same scan again to resume"
                       if store is not None else "; pass out= to keep chunks on disk")
                ),
                stacklevel=3,
            )
    finally:
        bar.close()
    if store is not None:
        files = store.files(finished)
        if lazy:
            return (pl.scan_parquet(files) if files
                    else _empty(job.names, list(job.model_values())).lazy())
        frames = {c: pl.read_parquet(f) for c, f in zip(sorted(finished), files, strict=True)}
    if not frames:
        return _empty(job.names, list(job.model_values()))
    return pl.concat([frames[c] for c in sorted(frames)], how="vertical")


@overload
def read_scan(path: str | os.PathLike[str], *, lazy: Literal[False] = ...) -> pl.DataFrame: ...
@overload
def read_scan(path: str | os.PathLike[str], *, lazy: Literal[True]) -> pl.LazyFrame: ...
def read_scan(  # noqa: E302 - overloads above
    path: str | os.PathLike[str], *, lazy: bool = False,
) -> pl.DataFrame | pl.LazyFrame:
    """The table of a scan written with ``out=path`` (the finished chunks, in order).

    The directory is also a Parquet dataset: ``polars.read_parquet(path)`` and
    ``polars.scan_parquet(path)`` read the same table, unchecked. Every chunk file is
    checked against the scan's description (:func:`scan_meta`) before its rows are
    used; a damaged one (truncated, unreadable, changed since it
    was written, another scan's or another chunk's, missing points) raises
    :class:`~ballbal.exceptions.ScanStoreError` naming it; running the same scan with
    ``out=path`` again sets it aside and recomputes it. ``lazy=True`` returns a
    ``polars.LazyFrame`` over the files (checked by their checksums and footers, one
    file in memory at a time; the rows are decoded when the frame is collected).
    """
    d = Path(_check.path("path", path))
    files = _chunk_files(d)
    if not files:
        raise ParameterError("path", f"no scan chunks (chunk-*.parquet) in {d}", value=path)
    meta = _read_description(d)
    damaged = []
    for f in files:
        c = _chunk_index(f)
        if lazy:
            why: str | None
            if c is None:
                why, data = "not a chunk file name", b""
            else:
                why, data = _sealed_problem(f, _fingerprint(meta), c)
            if why is None:
                try:
                    ok = (pl.read_parquet_schema(io.BytesIO(data))
                          == dict(_empty(list(meta["grid"]), meta.get("model_columns", [])).schema))
                except Exception:  # noqa: BLE001 - any failure to read: a damaged file
                    ok = False
                why = None if ok else "its columns are not a scan table's"
        else:
            why = _chunk_problem(f, meta, c)
        if why is not None:
            damaged.append(f"{f} ({why})")
    if damaged:
        raise ScanStoreError(
            f"path: damaged chunk file(s): {'; '.join(damaged)}; run the same scan with "
            f"out={str(d)!r} again to recompute them")
    if lazy:
        return pl.scan_parquet(files)
    return pl.concat([pl.read_parquet(f) for f in files], how="vertical")


def scan_meta(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The description of the scan written with ``out=path``: what its table was computed
    for, as the directory's description file ``_scan.parquet`` (no rows, the table's
    columns) carries it in its Parquet key-value metadata (key
    ``ballbal_scan_description``, JSON: ``polars.read_parquet_metadata`` reads it too).

    Keys: ``balancer`` (every field: ``mu``, ``zeta``, ``zeta_b``, ``delta``, ``Omega``,
    ``eta`` with one value per ball) or, for a :class:`~ballbal.Scene`, ``scene`` (its
    :meth:`~ballbal.Scene.to_dict`: the balancer and every effect); ``grid`` (each
    axis' values, in the order given), ``patterns``, ``options`` (what the scan
    computed with), ``block`` and ``chunk``, ``columns`` and ``model_columns`` (the
    table's), ``ballbal`` (the version that wrote it). A grid axis replaces the model's
    value of that parameter. :class:`~ballbal.exceptions.ScanStoreError` naming the file
    if it is damaged (running the same scan with ``out=path`` again rewrites it)."""
    return _read_description(Path(_check.path("path", path)))


def flat(table: pl.DataFrame) -> pl.DataFrame:
    """``table`` with its nested columns spread into plain ones, for formats that hold
    only those (``write_csv``): a list of structs ``x`` (a scan's ``multipliers``, a
    list of ``{re, im}``) becomes ``x_re_0, x_im_0, x_re_1, ...``, a list of numbers
    ``x_0, x_1, ...``, a struct ``x_<field>``. Lists are padded with nulls to the longest
    row's length; a row without the list (null) gets nulls. Other columns keep their
    place and values."""
    if not isinstance(table, pl.DataFrame):
        raise ParameterTypeError("table", "must be a polars DataFrame (collect a LazyFrame "
                                 f"first), got {type(table).__name__}")
    out: list[pl.Expr] = []
    for name, dtype in table.schema.items():
        col = pl.col(name)
        if isinstance(dtype, (pl.List, pl.Array)):
            inner = dtype.inner
            longest = table.select(col.list.len().max() if isinstance(dtype, pl.List)
                                   else pl.lit(dtype.size)).item() or 0
            for i in range(longest):
                item = col.list.get(i, null_on_oob=True) if isinstance(dtype, pl.List) \
                    else col.arr.get(i, null_on_oob=True)
                if isinstance(inner, pl.Struct):
                    out += [item.struct.field(f.name).alias(f"{name}_{f.name}_{i}")
                            for f in inner.fields]
                else:
                    out.append(item.alias(f"{name}_{i}"))
        elif isinstance(dtype, pl.Struct):
            out += [col.struct.field(f.name).alias(f"{name}_{f.name}") for f in dtype.fields]
        else:
            out.append(col)
    return table.select(out)
