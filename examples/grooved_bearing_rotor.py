"""A rotor on a herringbone-grooved journal bearing
================================================

Yen's (2005) scenarios: a rigid rotor in a herringbone-grooved journal bearing.

The seed (an NSC report, 2004) gives no geometry, so the numbers here are ours, chosen so
that its qualitative regimes appear (the choice is printed):

* the bearing: L/D = 1, grooves on the stationary sleeve (8 grooves, 40 deg from the
  circumferential direction, depth ratio 1, width ratio 0.5), half-Sommerfeld cavitation,
  the finite-volume film on a 96 x 12 grid (12 cells per groove pitch);
* the rotor: gravity ``g_n = g / (c w^2)`` and the mass parameter ``m = M c w^2 / F_S`` are
  picked so that the weight puts the grooved journal at a moderate eccentricity (the
  static load ``m g_n`` in ``F_S``), with ``m`` below the whirl threshold; the unbalance
  ratios of the seed, 2.55 W, 0.255 W and 0.0255 W, are then ``e_u / c = (2.55, 0.255,
  0.0255) g_n``;
* Yen's (2005) impulse ``5 W exp(-5e5 (t - 0.006)^2)`` at 500 rad/s, i.e.
  ``5 W exp(-2 (tau - 3)^2)`` along gravity, applied at the static equilibrium.

Panels (the paper's figures 2-19): two starts converging to one equilibrium (plain bearing, as the
Yen's (2005) smooth one), the impulse response against groove angle, L/D, depth and width ratio
(orbit and tangential film force), and the three unbalance regimes.

Run: ``python examples/grooved_bearing_rotor.py [OUT_DIR]``;
``BALLBAL_EXAMPLE_SMALL=1`` runs a shortened version (fewer values, shorter times) for the tests.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ballbal.bearing import (  # noqa: E402
    Bearing,
    Grooves,
    RotorImpulse,
    RotorOnBearing,
    RotorTrajectory,
    rotor_equilibrium,
    simulate_rotor,
)

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
GRID = (64, 8) if SMALL else (96, 12)
COUNT = 8
IMPULSE_SPAN = 20.0 if SMALL else 40.0
UNBALANCE_SPAN = 30.0 if SMALL else 60.0
#: Gravity and mass parameter (see the module docstring and the printed rationale).
GRAVITY = 0.6
MASS = 2.0
ANGLES = (20.0, 80.0) if SMALL else (20.0, 40.0, 60.0, 80.0)
LENGTHS = (1.0,) if SMALL else (0.5, 1.0, 1.5, 2.0)
DEPTHS = (1.0,) if SMALL else (0.5, 1.0, 1.4)
WIDTHS = (0.5,) if SMALL else (0.3, 0.5, 0.8)
UNBALANCES = (2.55, 0.255, 0.0255)


def grooved(angle: float = 40.0, lam: float = 1.0, depth: float = 1.0,
            width: float = 0.5) -> Bearing:
    return Bearing(length_ratio=lam, model="finite", grid=GRID,
                   grooves=Grooves(COUNT, angle, depth, width))


_cache: dict[tuple[float, ...], RotorTrajectory] = {}


def impulse_run(angle: float = 40.0, lam: float = 1.0, depth: float = 1.0,
                width: float = 0.5) -> RotorTrajectory:
    key = (angle, lam, depth, width)
    if key not in _cache:
        r = RotorOnBearing(grooved(*key), MASS, gravity=GRAVITY,
                           impulse=RotorImpulse(5.0, 3.0, 2.0))
        _cache[key] = simulate_rotor(r, "equilibrium", (0.0, IMPULSE_SPAN), samples=401)
    return _cache[key]


def orbit(ax: plt.Axes, runs: dict[str, RotorTrajectory], title: str) -> None:
    th = np.linspace(0, 2 * math.pi, 361)
    ax.plot(np.sin(th), np.cos(th), color="0.4", lw=0.8)
    for label, tr in runs.items():
        t = tr.table
        line, = ax.plot(t["y"], -t["x"], lw=0.8, label=label)
        if tr.outcome == "contact":
            ax.plot(t["y"][-1], -t["x"][-1], "x", color=line.get_color())
    ax.set_aspect("equal")
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    # the journal centre in the clearance circle, the load (x) pointing down
    ax.set_xlabel("$y/c$", fontsize=9)
    ax.set_ylabel("$-x/c$", fontsize=9)
    ax.set_title(title, fontsize=10)
    ax.tick_params(labelsize=8)
    ax.legend(fontsize=7, loc="upper right")


def tangential(ax: plt.Axes, runs: dict[str, RotorTrajectory], title: str) -> None:
    for label, tr in runs.items():
        ax.plot(tr.table["tau"], tr.table["tangential"], lw=0.8, label=label)
    ax.set_xlabel(r"$\tau = \omega t$", fontsize=9)
    ax.set_ylabel("$F_t / F_S$ (tangential film force)", fontsize=9)
    ax.set_title(title, fontsize=10)
    ax.tick_params(labelsize=8)
    ax.legend(fontsize=7)


def describe(label: str, tr: RotorTrajectory, seconds: float) -> None:
    t = tr.table
    last = t.row(-1, named=True)
    peak = float(t["eccentricity"].max())  # type: ignore[arg-type]
    print(f"{label}: {tr.outcome} at tau {tr.t_end:.2f}, max eps {peak:.3f}, "
          f"final eps {last['eccentricity']:.3f}, {tr.accepted_steps} steps, "
          f"{tr.force_evals} film solves, {seconds:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?", default=None, help="output directory")
    args = ap.parse_args()
    if args.out is None:  # made only when needed (a temporary directory in small mode)
        args.out = (tempfile.mkdtemp(prefix="grooved_bearing_rotor-") if SMALL
                    else "grooved_bearing_rotor")
    os.makedirs(args.out, exist_ok=True)
    png = os.path.join(args.out, "grooved_bearing_rotor.png")
    t_all = time.perf_counter()
    base = RotorOnBearing(grooved(), MASS, gravity=GRAVITY)
    xe, ye = rotor_equilibrium(base)
    att = math.degrees(math.atan2(ye, xe))
    print(f"choice: g_n = {GRAVITY}, m = {MASS}: weight {MASS * GRAVITY} F_S puts the grooved "
          f"journal at eps {math.hypot(xe, ye):.3f}, attitude {att:.1f} deg; unbalance "
          f"e_u/c = {', '.join(f'{u * GRAVITY:g}' for u in UNBALANCES)}")
    # three orbits a row, then the forces: readable where the README shows it
    fig, ax = plt.subplots(4, 3, figsize=(13.0, 16.0))
    ax[3, 1].remove()
    ax[3, 2].remove()

    # The paper's figure 2: two starts, one equilibrium (plain bearing).
    plain = RotorOnBearing(Bearing(length_ratio=1.0, model="finite", grid=(64, 16)), MASS,
                           gravity=GRAVITY)
    starts = {"eps0 0.75 at 90 deg": (0.0, 0.75), "eps0 0.3 at 90 deg": (0.0, 0.3),
              "eps0 0.4 at -135 deg": (0.4 * math.cos(math.radians(-135)),
                                       0.4 * math.sin(math.radians(-135)))}
    runs = {}
    for label, x0 in starts.items():
        t0 = time.perf_counter()
        runs[label] = simulate_rotor(plain, x0, (0.0, 80.0 if SMALL else 150.0), samples=801)
        describe(f"start {label}", runs[label], time.perf_counter() - t0)
    ends = [tr.table.row(-1, named=True) for tr in runs.values()]
    spread = max(math.hypot(a["x"] - b["x"], a["y"] - b["y"]) for a in ends for b in ends)
    print(f"two starts: final positions agree to {spread:.2e} c")
    orbit(ax[0, 0], runs, "plain bearing: starts converge (fig. 2-3)")

    # The paper's figures 9-15: impulse response against the groove parameters.
    orbit_at = {"angle": (0, 1), "lam": (0, 2), "depth": (1, 0), "width": (1, 1)}
    force_at = {"angle": (2, 0), "depth": (2, 1), "width": (2, 2)}
    figs = {"angle": (9, 10), "lam": (11, 11), "depth": (12, 13), "width": (14, 15)}
    for name, values, kw in (("groove angle", ANGLES, "angle"), ("L/D", LENGTHS, "lam"),
                             ("depth ratio", DEPTHS, "depth"), ("width ratio", WIDTHS, "width")):
        runs = {}
        for v in values:
            t0 = time.perf_counter()
            tr = impulse_run(**{kw: v})
            runs[f"{name} {v:g}"] = tr
            describe(f"impulse, {name} {v:g}", tr, time.perf_counter() - t0)
        orbit(ax[orbit_at[kw]], runs, f"impulse 5 W: {name} (fig. {figs[kw][0]})")
        if kw in force_at:
            tangential(ax[force_at[kw]], runs,
                       f"impulse: tangential force, {name} (fig. {figs[kw][1]})")

    # The paper's figures 16-19: unbalance 2.55 W, 0.255 W, 0.0255 W.
    runs = {}
    for u in UNBALANCES:
        r = RotorOnBearing(grooved(), MASS, gravity=GRAVITY, unbalance=u * GRAVITY)
        t0 = time.perf_counter()
        tr = simulate_rotor(r, "equilibrium", (0.0, UNBALANCE_SPAN), samples=601)
        runs[f"unbalance {u:g} W"] = tr
        describe(f"unbalance {u:g} W", tr, time.perf_counter() - t0)
        if tr.outcome == "completed":
            # the orbit's dominant frequency over the second half, over the spin frequency
            t = tr.table.filter(tr.table["tau"] >= UNBALANCE_SPAN / 2)
            x = t["x"].to_numpy() - t["x"].mean()
            tau = t["tau"].to_numpy()
            up = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
            tc = tau[up] - x[up] * (tau[up + 1] - tau[up]) / (x[up + 1] - x[up])
            print(f"  unbalance {u:g} W: orbit radius {0.5 * np.ptp(x):.4f} c, whirl/spin "
                  f"{2 * math.pi / np.mean(np.diff(tc)):.3f}")
    orbit(ax[1, 2], runs, "mass unbalance (fig. 16-18)")
    tangential(ax[3, 0], runs, "mass unbalance: tangential force (fig. 19)")
    fig.tight_layout()
    fig.savefig(png, dpi=80)
    print(f"total {time.perf_counter() - t_all:.1f} s; wrote {png}")


if __name__ == "__main__":
    main()
