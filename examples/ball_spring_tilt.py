"""Ball-spring balancer on a tilting rotor
=======================================

Rezaee et al. (2017): the ball-spring balancer on a tilting rotor with gyroscopic coupling.

1. The balanced state's stable region from the eigenvalues of the linearised system, in
   the (track damping, speed) and (ball mass, speed) planes, classic balancer against
   ball springs (Rezaee et al.'s (2017) figures 4 and 5).
2. The run-up through the critical speed of both (its figures 8 to 10): peak whirl and
   peak tilt.

Run: python examples/ball_spring_tilt.py [OUT_DIR]   (about 5 s)
"""

import argparse
import os
import tempfile
import time

import matplotlib.pyplot as plt
import numpy as np

import ballbal

TILT = ballbal.Tilt(a=1.5, b=2.5, j_t=0.3, j_z=0.5, zeta_r=0.1)
BASE = ballbal.Scene(
    balancer=ballbal.Balancer(mu=0.2, zeta=0.1, zeta_b=0.1, delta=50.0, Omega=1.5,
                              eta=(1.0, 1.0)),
    tilt=TILT,
)
SPRINGS = 2e-5
MAX_WHIRL = 0.1  # residual whirl (units of e) still counted as balanced
# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): maps of 9 x 5 points and a short
# run-up, written into a temporary directory unless an output directory is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
SPEEDS, PLANE_POINTS = (9, 5) if SMALL else (77, None)
RUN_UP, SETTLE = (100.0, 200.0) if SMALL else (300.0, 600.0)


def maps(ax):
    speeds = np.linspace(0.2, 4.0, SPEEDS)
    planes = [("zeta_b", np.linspace(0.0, 0.4, PLANE_POINTS or 41)),
              ("eta", np.linspace(0.3, 2.0, PLANE_POINTS or 35))]
    for col, (name, values) in enumerate(planes):
        for row, (springs, label) in enumerate(((0.0, "classic"), (SPRINGS, "ball springs"))):
            t = time.perf_counter()
            df = ballbal.balance_map(BASE.replace(springs=springs), Omega=speeds,
                                     **{name: values})
            sec = time.perf_counter() - t
            stable = df.filter(df["stability"] == "stable")
            balanced = stable.filter(stable["whirl"] <= MAX_WHIRL)
            print(f"{label:12s} ({name}, Omega): {df.height} points in {sec:.2f} s; "
                  f"stable {stable.height}, of which whirl <= {MAX_WHIRL} e: "
                  f"{balanced.height} (lowest speed {balanced['Omega'].min():.2f})")
            a = ax[row][col]
            ballbal.plot_balance_map(df, "Omega", name, ax=a, max_whirl=MAX_WHIRL,
                                     label=f"{label}: green balanced, grey whirl > {MAX_WHIRL}")


def run_up(ax):
    start = BASE.replace(Omega=0.3, zeta=0.05, zeta_b=0.05,
                         tilt=ballbal.Tilt(a=1.5, b=2.5, j_t=0.3, j_z=0.5, zeta_r=0.05))
    for springs, label in ((0.0, "classic"), (SPRINGS, f"ball springs k_d/k = {SPRINGS:g}")):
        r = ballbal.run_up(start.replace(springs=springs), 2.0, RUN_UP, settle=SETTLE)
        tr = r.trajectory
        print(f"run-up 0.3 -> 2.0, {label}: peak whirl {r.peak_whirl:.2f} e at Omega "
              f"{r.peak_Omega:.2f}, peak tilt {r.peak_tilt / 50:.4f} rad; final whirl "
              f"{r.final_whirl:.3f} e")
        ax[0].plot(tr["t"], np.hypot(tr["x"], tr["y"]), lw=0.8, label=label)
        ax[1].plot(tr["t"], np.hypot(tr["A"], tr["B"]) / 50, lw=0.8, label=label)
    ax[0].set_ylabel("whirl hypot(x, y) / e")
    ax[1].set_ylabel("tilt (rad)")
    for a in ax:
        a.set_xlabel(f"t w_n (spin ramps 0.3 -> 2.0 until {RUN_UP:g})")
        a.legend()


def main() -> None:
    ap = argparse.ArgumentParser()
    default = tempfile.mkdtemp(prefix="ball_spring_tilt-") if SMALL else "ball_spring_tilt"
    ap.add_argument("out", nargs="?", default=default, help="output directory")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    png = os.path.join(args.out, "ball_spring_tilt.png")
    fig, ax = plt.subplots(3, 2, figsize=(10, 12))
    maps(ax)
    run_up(ax[2])
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
