"""A balancer on a grooved journal bearing
=======================================

Where a ball balancer on a herringbone-grooved journal bearing balances stably.

    python examples/bearing_balancer.py [output-directory] [--model finite]
    # about 6 s on 2 cores with the default film (measured 2026-11-28)

The disk centre is carried by a hydrodynamic journal bearing instead of a spring
(``ballbal.BearingSupport``). Speeds are ``Omega = w / w_ref`` with ``w_ref = C_S / M``,
``C_S = mu_oil L R^3 / c^3`` (the classical mass parameter ``M c^3 w / (mu_oil L R^3)``).
The map is the stability of the perfect balance (journal centred, balls cancelling the
unbalance) from the eigenvalues of its linearisation (``ballbal.balance_map``), over

* speed against groove depth ratio (angle 30 deg), and
* speed against groove angle (depth ratio 1),

beside the plain bearing, on which the centred rotor is unstable at every speed: a plain
film at the centre has only cross-coupled stiffness, so nothing holds the centred journal
(the largest real part of the eigenvalues is drawn against speed, plain and grooved).

Parameters and why: Tien (2011) balancer (``mu = 0.2``, ``delta = 50``, two balls of ``eta =
1``, ``zeta_b = 0.05``) with ``zeta = 0`` (the film's damping only); a short bearing, ``L/D
= 0.5``; 8 grooves on the journal (so the scene stays autonomous: grooves on the sleeve
with the resolved finite model make it time-periodic, simulation only), width ratio 0.5
over the full length, half-Sommerfeld cavitation; the finite film on 128 x 16 cells (16
cells per groove pitch: forces within about 1 % of a 256 x 32 grid at the centre, and
each point costs a few film solves). ``rho = e / c`` does not enter: at the centre the
linearised film force ``Omega (D_X + D_V J) q + D_V q'`` does not depend on it. The film
model is a parameter (``--model finite`` or ``narrow_groove`` once the engine has it);
the plain comparison also runs Ocvirk's short bearing.

Writes bearing_balancer.png and the tables as Parquet; prints the stable speed range
at each groove depth.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import polars as pl  # noqa: E402

import ballbal  # noqa: E402
from ballbal.bearing import Bearing, Grooves  # noqa: E402

# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): a few points, written into a temporary
# directory unless one is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"

OMEGA = np.geomspace(0.2, 10.0, 6 if SMALL else 36)
DEPTHS = np.linspace(0.0, 2.0, 3 if SMALL else 21)
ANGLES = np.linspace(10.0, 85.0, 3 if SMALL else 16)
BALANCER = ballbal.Balancer(mu=0.2, zeta=0.0, zeta_b=0.05, delta=50.0, Omega=1.0,
                            eta=(1.0, 1.0))
LD = 0.5
GROOVES = Grooves(count=8, angle=30.0, depth_ratio=1.0, width_ratio=0.5, side="journal")
GRID = (128, 16)


def scene(bearing: Bearing) -> ballbal.Scene:
    return ballbal.Scene(balancer=BALANCER, support=ballbal.BearingSupport(bearing, rho=0.3))


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    model = "finite"
    if "--model" in sys.argv:
        model = sys.argv[sys.argv.index("--model") + 1]
        args = [a for a in args if a != model]
    default = tempfile.mkdtemp(prefix="bearing_balancer-") if SMALL else "."
    out = Path(args[0] if args else default)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    grooved = scene(Bearing(length_ratio=LD, grooves=GROOVES, model=model, grid=GRID))
    by_depth = ballbal.balance_map(grooved, Omega=OMEGA, depth_ratio=DEPTHS)
    by_angle = ballbal.balance_map(grooved, Omega=OMEGA, groove_angle=ANGLES)
    plain = {
        "plain, finite": scene(Bearing(length_ratio=LD, model="finite", grid=GRID)),
        "plain, short (Ocvirk)": scene(Bearing(length_ratio=LD, model="short")),
    }
    lines = {label: ballbal.balance_map(sc, Omega=OMEGA) for label, sc in plain.items()}
    lines["grooved journal, depth 1, 30 deg"] = by_depth.filter(
        pl.col("depth_ratio") == 1.0).drop("depth_ratio")
    elapsed = time.perf_counter() - start
    by_depth.write_parquet(out / "bearing_balancer_depth.parquet")
    by_angle.write_parquet(out / "bearing_balancer_angle.parquet")

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ballbal.plot_balance_map(by_depth, x="Omega", y="depth_ratio", ax=axes[0],
                             label=f"grooved journal ({model}), angle 30 deg: stable shaded")
    ballbal.plot_balance_map(by_angle, x="Omega", y="groove_angle", ax=axes[1],
                             label=f"grooved journal ({model}), depth 1: stable shaded")
    axes[1].set_ylabel("groove angle (deg from circumferential)")
    for ax in axes[:2]:
        ax.set_xscale("log")
        ax.set_xlabel("Omega = w / w_ref")
    ax = axes[2]
    for label, df in lines.items():
        ax.plot(df["Omega"], df["index"], marker=".", label=label)
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_xlabel("Omega = w / w_ref")
    ax.set_ylabel("largest real part (perfect balance)")
    ax.set_title("plain bearings: unstable at every speed")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "bearing_balancer.png", dpi=110)

    print(f"{by_depth.height + by_angle.height + sum(d.height for d in lines.values())} "
          f"points in {elapsed:.1f} s ({model} film, {GRID[0]} x {GRID[1]} cells)")
    for label, df in lines.items():
        if label.startswith("plain"):
            print(f"{label}: largest real part {df['index'].min():.2e} .. "
                  f"{df['index'].max():.2e} (unstable at all {df.height} speeds: "
                  f"{(df['stability'] == 'unstable').all()})")
    for d in DEPTHS:
        om = by_depth.filter((pl.col("depth_ratio") == d)
                             & (pl.col("stability") == "stable"))["Omega"]
        span = f"Omega {om.min():.3g} .. {om.max():.3g}" if om.len() else "nowhere"
        print(f"  depth ratio {d:4.2f}: stable for {span} ({om.len()} of {len(OMEGA)} speeds)")


if __name__ == "__main__":
    main()
