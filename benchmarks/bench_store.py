"""What the chunk checksums cost a streamed scan (issue 30; target under 2 %).

One run, side by side: a streamed R-R scan (``out=``, ``lazy=True``; the floquet
setting of ``bench_scan_memory.py``: the scan's defaults, N = 3, Floquet on, mu 0.2,
delta 50, zeta_b 0.05) of ``side^2`` points (default 316^2, about 10^5) is timed; then,
over the chunk files it wrote, each chunk is written to memory the way it was before
checksums (Parquet with the fingerprint) and the way it is now (``_sealed``: the same
plus a SHA-256 of the bytes put into the footer), the steps ``_sealed`` adds (copy,
locate, hash) are timed alone, and each file is checked the way a resume now checks it
first (read and hashed: ``_checksum_problem``). Each of those is the best of
``repeats`` interleaved passes (the machine is shared; the difference of the two
writes is within the Parquet writer's noise, hence the added steps timed alone).
Printed: the scan's wall and CPU time, the write-time cost, the resume-time check, and
each as a fraction of the scan.

    python benchmarks/bench_store.py            # 316 x 316 points
    python benchmarks/bench_store.py 100        # 100 x 100 (quick)
"""

from __future__ import annotations

import hashlib
import io
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import polars as pl

import ballbal
from ballbal.scan import (
    _CHECKSUM_AT,
    _CHECKSUM_KEY,
    _CHUNK_KEY,
    _FINGERPRINT,
    _checksum_problem,
    _sealed,
)


def best(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    side = int(sys.argv[1]) if len(sys.argv) > 1 else 316
    repeats = 7
    grid = dict(Omega=np.linspace(1.0, 2.0, side), eta=np.linspace(0.4, 1.5, side))
    model = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "scan"
        t, cpu = time.perf_counter(), time.process_time()
        lf = ballbal.scan(model, out=out, lazy=True, patterns=["R-R"], N=3, threads=2,
                          **grid)
        rows = lf.select(pl.len()).collect().item()
        scan_s = time.perf_counter() - t
        # Both threads' CPU seconds: on a loaded machine the wall time grows and would
        # flatter the ratio; the checksum work is CPU work on one thread.
        cpu_s = time.process_time() - cpu
        files = sorted(out.glob("chunk-*.parquet"))
        frames = [pl.read_parquet(f) for f in files]
        fp = pl.read_parquet_metadata(files[0])[_FINGERPRINT]
        size = sum(f.stat().st_size for f in files)
        # Every check passes on a clean directory (no false alarm).
        assert all(_checksum_problem(f.read_bytes()) is None for f in files)

        def write_before() -> None:
            for df in frames:
                df.write_parquet(io.BytesIO(), metadata={_FINGERPRINT: fp})

        def write_now() -> None:
            for c, df in enumerate(frames):
                _sealed(df, {_FINGERPRINT: fp, _CHUNK_KEY: str(c)})

        def check() -> None:
            for f in files:
                _checksum_problem(f.read_bytes())

        written = [f.read_bytes() for f in files]

        def seal_steps() -> None:
            # What _sealed adds to a write, alone: copy, locate, hash, copy back.
            for data in written:
                buf = bytearray(data)
                at = buf.find(_CHECKSUM_KEY)
                buf[at + _CHECKSUM_AT:at + _CHECKSUM_AT + 64] = \
                    hashlib.sha256(buf).hexdigest().encode()
                bytes(buf)

        # Interleaved, best of each: the machine's load drifts during a run.
        runs: dict[str, list[float]] = {"before": [], "now": [], "seal": [], "check": []}
        for _ in range(repeats):
            for name, fn in (("before", write_before), ("now", write_now),
                             ("seal", seal_steps), ("check", check)):
                runs[name].append(best(fn, 1))
        before_s, now_s, seal_s, check_s = (min(runs[k]) for k in runs)
    print(f"scan: {side}^2 = {side * side} points, {rows} rows, {len(files)} chunks, "
          f"{size / 2**20:.1f} MiB of Parquet, {scan_s:.1f} s wall, {cpu_s:.1f} s CPU "
          f"(2 threads)")
    print(f"write chunks, before (fingerprint only): {1e3 * before_s:8.1f} ms")
    print(f"write chunks, now (sealed with SHA-256): {1e3 * now_s:8.1f} ms")
    print(f"  difference (noise of the Parquet write included): "
          f"{1e3 * (now_s - before_s):+.1f} ms")
    print(f"  checksum cost at write:  {1e3 * seal_s:8.1f} ms = "
          f"{100 * seal_s / scan_s:.3f} % of the scan (the added steps alone)")
    print(f"  checksum check on resume: {1e3 * check_s:7.1f} ms = "
          f"{100 * check_s / scan_s:.3f} % of the scan")
    # The larger of the two write-time figures, so that noise cannot flatter the total.
    total = max(seal_s, now_s - before_s) + check_s
    print(f"  both (larger write figure): {1e3 * total:5.1f} ms = "
          f"{100 * total / scan_s:.3f} % of the scan's wall time, "
          f"{100 * total / cpu_s:.3f} % of its CPU time (target < 2 %)")


if __name__ == "__main__":
    main()
