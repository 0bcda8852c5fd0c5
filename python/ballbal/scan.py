"""Parallel parameter scans returning polars tables."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import polars as pl

from . import _native
from .model import Balancer

SCANNABLE = ("mu", "zeta", "zeta_b", "delta", "Omega", "eta")


def _grid(name: str, spec: Sequence[float] | np.ndarray | tuple[float, float, float]) -> np.ndarray:
    if name not in SCANNABLE:
        raise ValueError(f"{name}: not a scannable parameter (choose from {', '.join(SCANNABLE)})")
    if isinstance(spec, tuple) and len(spec) == 3 and isinstance(spec[2], (int, float)) and \
            not isinstance(spec, np.ndarray) and spec[2] > 0 and spec[1] > spec[0]:
        start, stop, step = (float(v) for v in spec)
        vals = start + step * np.arange(int(np.floor((stop - start) / step + 1e-9)) + 1)
    else:
        vals = np.asarray(spec, dtype=float).ravel()
    if vals.size == 0:
        raise ValueError(f"{name}: the grid is empty")
    if not np.all(np.isfinite(vals)):
        raise ValueError(f"{name}: grid values must be finite")
    return vals


def scan(
    balancer: Balancer,
    *,
    patterns: Sequence[str] = ("R-R",),
    N: int = 3,
    samples: int | None = None,
    tol: float = 1e-10,
    step_tol: float = 1e-8,
    max_iter: int = 50,
    floquet: bool = True,
    rtol: float = 1e-6,
    atol: float = 1e-9,
    margin: float = 1e-6,
    settle: float = 1500.0,
    window: float = 2500.0,
    threads: int | None = None,
    **grid: Sequence[float] | np.ndarray | tuple[float, float, float],
) -> pl.DataFrame:
    """Scan two parameters of ``balancer`` over grids, e.g.
    ``scan(b, Omega=(1.0, 2.0, 0.1), eta=np.arange(0.4, 1.51, 0.1))``: each grid is a
    sequence of values or ``(start, stop, step)``.

    Runs on ``threads`` cores (default: all) in the Rust core with the GIL released. Each
    line along the first parameter is continued point to point, with fresh simulated
    starts where continuation fails and a backward sweep into gaps; the table is the same
    for any thread count. One row per grid point and solution type, with ``status``
    ("converged" or why not), ``omega``, ``stability``, ``max_modulus``,
    ``trivial_error``, ``multipliers`` (list of ``{re, im}``), ``residual``,
    ``iterations``, ``N``, ``seconds``, ``origin``, and the perfect balance's existence and
    stability (``pb_exists``, ``pb_stable``). Values of unconverged rows are null.
    """
    if len(grid) != 2:
        raise ValueError(f"grid: give exactly two parameters to scan, got {sorted(grid)}")
    (n0, g0), (n1, g1) = grid.items()
    v0, v1 = _grid(n0, g0), _grid(n1, g1)
    if threads is None:
        threads = os.cpu_count() or 1
    if int(threads) < 1:
        raise ValueError(f"threads: must be >= 1, got {threads}")
    d = _native.scan(
        *balancer.native_args(), (n0, n1), v0.tolist(), v1.tolist(), list(patterns), int(N),
        samples, float(tol), float(step_tol), int(max_iter), bool(floquet), float(rtol),
        float(atol), float(margin), float(settle), float(window), int(threads),
    )
    mult = [
        [{"re": r, "im": i} for r, i in zip(re, im, strict=True)]
        for re, im in zip(d["mult_re"], d["mult_im"], strict=True)
    ]
    df = pl.DataFrame({
        n0: d[n0], n1: d[n1], "type": d["type"], "status": d["status"],
        "omega": d["omega"], "stability": d["stability"], "max_modulus": d["max_modulus"],
        "trivial_error": d["trivial_error"],
        "multipliers": pl.Series(mult, dtype=pl.List(pl.Struct({"re": pl.Float64,
                                                                "im": pl.Float64}))),
        "residual": d["residual"], "iterations": d["iterations"],
        "N": [d["N"]] * d["rows"], "seconds": d["seconds"], "origin": d["origin"],
        "pb_exists": d["pb_exists"], "pb_stable": d["pb_stable"],
    })
    floats = ["omega", "max_modulus", "trivial_error", "residual", "iterations"]
    df = df.with_columns([pl.col(c).fill_nan(None) for c in floats])
    return df.with_columns(pl.col("iterations").cast(pl.Int64))
