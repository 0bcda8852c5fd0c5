"""Seed 002's impulse (Yen 2005, fig. 9-15) on refined bearing grids: which outcome converges.

The gallery's ``examples/grooved_bearing_rotor.py`` runs the impulse ``5 W exp(-2 (tau -
3)^2)`` on the herringbone-grooved sleeve (8 grooves, depth ratio 1, width ratio 0.5,
L/D 1, ``m = 2``, ``g_n = 0.6``) on a 96 x 12 finite-volume grid; its small version used
64 x 8, where a run touched the sleeve. Here every groove angle of the seed's figure 9 runs
on 64 x 8, 96 x 12, 128 x 16 and 192 x 24 cells (8, 12, 16, 24 cells per groove pitch), and
the outcome, the largest eccentricity and the time are printed: the outcome the finer grids
agree on is the converged one.

    python benchmarks/bearing_impulse_grid.py [--grids 64x8,96x12,128x16,192x24]
        [--angles 20,40,60,80] [--span 40]
"""

from __future__ import annotations

import argparse
import time

from ballbal.bearing import Bearing, Grooves, RotorImpulse, RotorOnBearing, simulate_rotor

MASS, GRAVITY = 2.0, 0.6


def run(grid: tuple[int, int], angle: float, span: float) -> tuple[str, float, float, float]:
    b = Bearing(length_ratio=1.0, model="finite", grid=grid,
                grooves=Grooves(8, angle, 1.0, 0.5))
    r = RotorOnBearing(b, MASS, gravity=GRAVITY, impulse=RotorImpulse(5.0, 3.0, 2.0))
    t0 = time.perf_counter()
    tr = simulate_rotor(r, "equilibrium", (0.0, span), samples=401)
    peak = float(tr.table["eccentricity"].max())  # type: ignore[arg-type]
    return tr.outcome, peak, tr.t_end, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", default="64x8,96x12,128x16,192x24")
    ap.add_argument("--angles", default="20,40,60,80")
    ap.add_argument("--span", type=float, default=40.0)
    args = ap.parse_args()
    grids = [tuple(int(v) for v in g.split("x")) for g in args.grids.split(",")]
    angles = [float(a) for a in args.angles.split(",")]
    print(f"impulse 5 W on the grooved sleeve, m {MASS}, g_n {GRAVITY}, tau 0..{args.span:g}")
    print(f"{'angle':>6s} {'grid':>8s} {'outcome':>10s} {'max eps':>8s} {'tau end':>8s} "
          f"{'seconds':>8s}")
    for a in angles:
        for g in grids:
            out, peak, t_end, sec = run((g[0], g[1]), a, args.span)
            print(f"{a:6.0f} {g[0]:>4d}x{g[1]:<3d} {out:>10s} {peak:8.4f} {t_end:8.2f} "
                  f"{sec:8.1f}", flush=True)


if __name__ == "__main__":
    main()
