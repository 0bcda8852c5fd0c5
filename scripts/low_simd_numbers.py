"""Key numbers of the standard case as ``name hex`` lines, and their comparison between
runs, for scripts/test_low_simd.sh.

``python low_simd_numbers.py [--large] > run.txt`` prints ``float.hex`` of the periodic
solutions' frequency, residual, coefficients and multipliers (monodromy and Hill) at
N = 3, 10 (and 24 with ``--large``) and of a small scan, plus a checksum of glibc's libm
on fixed arguments. ``python low_simd_numbers.py --compare native.txt libm.txt emu.txt``
counts, per group of numbers, the lines that differ between a native run, a native run
with glibc's libm held to its SSE code (``GLIBC_TUNABLES``) and an emulated run without
AVX2/FMA: the first pair's differences come from libm's FMA variants, the second's from
the code that reads the CPU's features itself (faer's kernels, through pulp).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import hashlib
import random
import struct
import sys
from collections import defaultdict
from typing import Any

import numpy as np

STANDARD_PARAMS = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0}


def emit(name: str, values: Any) -> None:
    """One line per value: ``name[i] hex``; complex values as their real and imaginary
    parts."""
    arr = np.atleast_1d(np.asarray(values, dtype=complex if np.iscomplexobj(values)
                                   else float))
    if np.iscomplexobj(arr):
        arr = np.stack([arr.real, arr.imag], axis=-1)
    for i, v in enumerate(arr.ravel()):
        print(f"{name}[{i}] {float(v).hex()}")


def sorted_multipliers(m: np.ndarray | None) -> np.ndarray:
    """Multipliers ordered by modulus, then argument, so that the eigensolver's output
    order is not counted as a difference."""
    if m is None:
        return np.array([np.nan])
    m = np.asarray(m)
    return m[np.lexsort((np.angle(m), -np.abs(m)))]


def libm_checksums() -> None:
    """glibc picks FMA variants of these functions at load time where the CPU has FMA;
    the core calls them (Rust's f64::sin, exp, ... are libm's)."""
    libm = ctypes.CDLL(ctypes.util.find_library("m") or "libm.so.6")
    rnd = random.Random(1)
    xs = [rnd.uniform(-50.0, 50.0) for _ in range(20000)]
    for name in ("sin", "cos", "atan", "exp", "log", "pow", "atan2"):
        f = getattr(libm, name)
        f.restype = ctypes.c_double
        two = name in ("pow", "atan2")
        f.argtypes = [ctypes.c_double] * (2 if two else 1)
        if name in ("log", "pow"):
            args: list[tuple[float, ...]] = [(abs(x), x / 7) if two else (abs(x),) for x in xs]
        else:
            args = [(x, 0.3 * x + 1.0) if two else (x,) for x in xs]
        vals = [f(*a) for a in args]
        digest = hashlib.sha256(struct.pack(f"{len(vals)}d", *vals)).hexdigest()[:16]
        print(f"libm.{name} {digest}")


def periodic_numbers(b: Any, tag: str, N: int, guess: Any) -> Any:
    import ballbal

    sol = ballbal.periodic(b, "R-R", N=N, guess=guess,
                           options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=True)))
    print(f"# {tag}: status {sol.status}, iterations {sol.iterations}, "
          f"start {sol.info.get('guess_source')}")
    emit(f"{tag}.omega", sol.omega if sol.omega is not None else np.nan)
    emit(f"{tag}.residual", sol.residual)
    emit(f"{tag}.pivot_ratio", sol.pivot_ratio)
    emit(f"{tag}.coeffs_x", sol.coeffs[0, :3])
    emit(f"{tag}.coeffs_b1", sol.coeffs[2, :3])
    emit(f"{tag}.trivial_error", sol.trivial_error if sol.trivial_error is not None
         else np.nan)
    emit(f"{tag}.multipliers", sorted_multipliers(sol.multipliers))
    emit(f"{tag}.hill_multipliers", sorted_multipliers(sol.hill_multipliers))
    return sol


def numbers(large: bool) -> None:
    import ballbal

    libm_checksums()
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.2, eta=(1.0, 1.0))
    s3 = periodic_numbers(b, "N3", 3, None)
    periodic_numbers(b, "N10", 10, s3)
    if large:
        # Larger Newton and Hill matrices, where faer's blocked dense kernels run.
        periodic_numbers(b, "N24", 24, s3)
    table = ballbal.scan(b, Omega=[1.15, 1.2, 1.25], eta=[0.9, 1.0], N=6, threads=1)
    print(f"# scan: {table.height} rows")
    table = table.sort([c for c in ("Omega", "eta", "omega") if c in table.columns])
    for col in ("omega", "residual", "max_modulus"):
        if col in table.columns:
            emit(f"scan.{col}", table[col].to_numpy())


def _load(path: str) -> dict[str, str]:
    with open(path) as f:
        return dict(line.split(None, 1) for line in f if line.strip()
                    and not line.startswith("#"))


def compare(native_path: str, libm_path: str, emulated_path: str) -> None:
    """Per group: lines, and how many differ native vs libm-held-to-SSE (libm's share),
    libm-held vs emulated (the core's own SIMD share), native vs emulated; then the
    largest relative differences native vs emulated."""
    n, s, e = _load(native_path), _load(libm_path), _load(emulated_path)
    if n.keys() != e.keys() or n.keys() != s.keys():
        print("the runs printed different numbers: compare the files by hand")
        return
    counts: dict[str, list[int]] = defaultdict(lambda: [0, 0, 0, 0])
    for k in n:
        c = counts[k.split("[")[0]]
        c[0] += 1
        c[1] += n[k] != s[k]
        c[2] += s[k] != e[k]
        c[3] += n[k] != e[k]
    print(f"{'numbers':24s} {'lines':>5s} {'libm':>6s} {'core':>6s} {'total':>6s}")
    for k, c in counts.items():
        print(f"{k:24s} {c[0]:5d} {c[1]:6d} {c[2]:6d} {c[3]:6d}")
    tot = [sum(c[i] for c in counts.values()) for i in range(4)]
    print(f"{'all':24s} {tot[0]:5d} {tot[1]:6d} {tot[2]:6d} {tot[3]:6d}")
    print("(libm: native vs native with GLIBC_TUNABLES masking AVX/AVX2/FMA; core: that vs "
          "emulated; total: native vs emulated)")
    rel = {}
    for k in n:
        if k.startswith("libm.") or n[k] == e[k]:
            continue
        a, b = float.fromhex(n[k].strip()), float.fromhex(e[k].strip())
        rel[k] = abs(a - b) / max(abs(a), abs(b), 1e-300)
    print("largest relative differences native vs emulated, residuals and values below "
          "1e-6 left out:")
    keep = {k: v for k, v in rel.items() if "residual" not in k
            and abs(float.fromhex(n[k].strip())) > 1e-6}
    for k in sorted(keep, key=keep.__getitem__, reverse=True)[:5]:
        print(f"  {k:28s} {n[k].strip():>24s} {e[k].strip():>24s} {keep[k]:.1e}")


def main() -> None:
    if len(sys.argv) == 5 and sys.argv[1] == "--compare":
        compare(*sys.argv[2:5])
    else:
        numbers("--large" in sys.argv[1:])


if __name__ == "__main__":
    main()
