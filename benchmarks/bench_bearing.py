"""Journal-bearing film forces: cost per force evaluation on one core, beside ROSS.

    python benchmarks/bench_bearing.py

1. ballbal's per-evaluation costs (short closed form, plain finite 128 x 32 by the sine
   transform, herringbone 256 x 32 by sparse Cholesky cold and along a trajectory with the
   old factor as CG preconditioner) come from the core's timing test
   (``cargo test --release -p ballbal-core --features studies bearing_bench --
   --ignored``), run here if
   ``cargo`` is on the path; they are wall clock on a shared machine (callgrind counts are
   in ``rust/core/src/model/bearing/finite.rs``).
2. ROSS (``ross-rotordynamics``, optional, skipped with a message when missing): its
   finite-difference pressure (``FluidFlow.calculate_pressure_matrix_numerical``, a
   first-order annular-flow scheme assembled as a dense matrix) and force
   (``calculate_oil_film_force(..., force_type="numerical")``) on the same plain bearing and
   grid, timed, and compared with ballbal's plain finite film (second-order conservative
   finite volumes) read through the groove study at depth 0.
3. The groove study's throughput (points per second) on 1 and 2 threads.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from ballbal._groove_study import groove_study
from ballbal.bearing import Bearing

ROOT = Path(__file__).resolve().parent.parent
GRID = (128, 32)


def core_timings() -> dict[str, float]:
    """Microseconds per force evaluation from the core's timing test."""
    if shutil.which("cargo") is None:
        print("cargo not found: skipping the core's per-evaluation timings")
        return {}
    out = subprocess.run(
        ["cargo", "test", "--release", "-q", "-p", "ballbal-core", "--features", "studies",
         "bearing_bench", "--",
         "--ignored", "--nocapture"],
        cwd=ROOT, capture_output=True, text=True, check=False).stdout
    found = {}
    for m in re.finditer(r"^(.*?): ([0-9.]+) us per force evaluation", out, re.M):
        found[m.group(1)] = float(m.group(2))
    return found


def ballbal_plain(lam: float, eps: float) -> tuple[float, float]:
    """(|F| / F_S, attitude in degrees) of the plain finite film on GRID."""
    df = groove_study(Bearing(length_ratio=lam, grid=GRID), depth_ratio=[0.0],
                      eccentricity=eps, threads=1)
    row = df.row(0, named=True)
    return row["load"], row["attitude"]


def ross_plain(lam: float, eps: float, repeat: int = 2) -> tuple[float, float, float] | None:
    """(|F| / F_S, attitude in degrees, seconds per evaluation) of ROSS's numerical film."""
    try:
        from ross.bearings.fluid_flow import FluidFlow
        from ross.bearings.fluid_flow_coefficients import calculate_oil_film_force
    except ImportError:
        print("ROSS (ross-rotordynamics) is not installed: skipping the comparison")
        return None
    radius, clearance, mu, omega = 0.05, 50e-6, 0.02, 300.0
    length = 2 * lam * radius
    ff = FluidFlow(GRID[1], GRID[0], length, omega, 0.0, 0.0, radius, radius + clearance,
                   mu, 860.0, eccentricity=eps * clearance, attitude_angle=math.pi / 4,
                   immediately_calculate_pressure_matrix_numerically=False)
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        ff.calculate_pressure_matrix_numerical()
        fr, ft, *_ = calculate_oil_film_force(ff, force_type="numerical")
        best = min(best, time.perf_counter() - t0)
    f_s = mu * omega * length * radius**3 / clearance**2
    return math.hypot(fr, ft) / f_s, math.degrees(math.atan2(abs(ft), abs(fr))), best


def study_rate(threads: int) -> float:
    kw = dict(angle=[20.0, 30.0, 40.0, 50.0], depth_ratio=[0.5, 1.0], width_ratio=[0.5],
              count=[8], eccentricity=0.5)
    bearing = Bearing(grid=(128, 32))
    groove_study(bearing, threads=threads, angle=[30.0], depth_ratio=[1.0])  # warm up
    t0 = time.perf_counter()
    df = groove_study(bearing, threads=threads, **kw)  # type: ignore[arg-type]
    return df.height / (time.perf_counter() - t0)


def main() -> int:
    print("ballbal per force evaluation (core timing test, one core, wall clock):")
    core = core_timings()
    for k, v in core.items():
        print(f"  {k:45s} {v:10.1f} us")
    plain_us = core.get("plain finite 128 x 32")
    print(f"\nROSS vs ballbal, plain bearing, half-Sommerfeld, grid {GRID[0]} x {GRID[1]}:")
    for lam, eps in [(0.5, 0.6), (1.0, 0.3), (1.0, 0.6)]:
        bb = ballbal_plain(lam, eps)
        ro = ross_plain(lam, eps)
        if ro is None:
            break
        diff = (ro[0] - bb[0]) / bb[0]
        line = (f"  L/D {lam:3.1f} eps {eps:3.1f}: |F|/F_S ballbal {bb[0]:8.5f} ROSS {ro[0]:8.5f}"
                f" ({diff:+.2%}), attitude ballbal {bb[1]:6.2f} ROSS {ro[1]:6.2f} deg;"
                f" ROSS {ro[2] * 1e3:8.1f} ms per force")
        if plain_us:
            line += f" = {ro[2] * 1e6 / plain_us:,.0f} x ballbal's"
        print(line)
    print("\ngroove study (herringbone 128 x 32, 3 factorisations per point):")
    for t in (1, 2):
        print(f"  {t} thread(s): {study_rate(t):6.1f} points/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
