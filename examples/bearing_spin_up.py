"""A rotor's start-up on a journal bearing
========================================

Run: ``python examples/bearing_spin_up.py [OUT_DIR]`` (about 20 s on 2 cores).

Yen's (2005) start-up study (fig. 3 and conclusion 1): a sudden start can whirl.

The paper starts a rotor on a plain journal bearing suddenly at 500 rad/s from rest at
eccentricity 0.4, attitude -135 deg, and watches it converge; from 0.4005 it whirls into
the sleeve. Its conclusion 1: a sudden start may touch the sleeve, while a start at a
suitable speed reaches the same equilibrium from any position (after Li et al. 1999).
It gives no geometry, so the numbers here are ours, chosen so that the regime appears:

* plain finite-volume film, L/D 1, 64 x 16 cells, half-Sommerfeld;
* static load ``m g_n = 0.3 F_S`` (eccentricity about 0.13) and the mass parameter at
  0.95 of the whirl threshold's (``ballbal.bearing.stability``): stable, but the film's
  whirl threshold is subcritical here, so a large enough start lands on the large whirl
  orbit instead of the equilibrium;
* sudden starts (the journal at ``w`` from ``tau = 0``) from rest along -135 deg: the
  start eccentricity ``eps0*`` that separates the two outcomes is found by bisection (the
  paper's 0.4 / 0.4005 is its value for its rotor);
* the same starts with a run-up from rest (``SpinUp(0, 100)``: linear to ``w`` over
  ``tau = 100``), which all converge on the one equilibrium.

Run: ``python examples/bearing_spin_up.py [OUT_DIR]``; ``BALLBAL_EXAMPLE_SMALL=1`` runs a
shorter version for the tests.
"""

from __future__ import annotations

import math
import os
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ballbal.bearing import (  # noqa: E402
    Bearing,
    RotorOnBearing,
    RotorTrajectory,
    SpinUp,
    rotor_equilibrium,
    simulate_rotor,
    stability,
)

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
SPAN = 800.0
BISECTIONS = 8 if SMALL else 16
LOAD, FRACTION, ATTITUDE = 0.3, 0.95, -135.0
BEARING = Bearing(length_ratio=1.0, model="finite", grid=(64, 16))


def start(eps0: float) -> tuple[float, float]:
    a = math.radians(ATTITUDE)
    return eps0 * math.cos(a), eps0 * math.sin(a)


def late_eps(tr: RotorTrajectory) -> float:
    """The largest eccentricity over the last fifth of the run (the whirl's size)."""
    t = tr.table.filter(tr.table["tau"] >= 0.8 * tr.t_end)
    return float(t["eccentricity"].max())  # type: ignore[arg-type]


def main() -> None:
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out_dir, exist_ok=True)
    t_all = time.perf_counter()
    m = FRACTION * stability(BEARING, (LOAD, 0.0)).critical_mass
    sudden = RotorOnBearing(BEARING, m, gravity=LOAD / m)
    ramped = RotorOnBearing(BEARING, m, gravity=LOAD / m, spin_up=SpinUp(0.0, 100.0))
    xe, ye = rotor_equilibrium(sudden)
    eps_s = math.hypot(xe, ye)
    print(f"choice: load {LOAD} F_S, m = {m:.4f} ({FRACTION} of the threshold's), "
          f"g_n = {LOAD / m:.5f}; equilibrium eps {eps_s:.4f}")

    def converges(tr: RotorTrajectory) -> bool:
        # near the threshold the decay is slow: what separates the outcomes is the large
        # whirl orbit (eps ~ 0.86) against a shrinking orbit about eps_s
        return tr.outcome == "completed" and late_eps(tr) < 0.5

    lo, hi = 0.2, 0.7
    runs = {e: simulate_rotor(sudden, start(e), (0.0, SPAN), samples=2001) for e in (lo, hi)}
    assert converges(runs[lo]) and not converges(runs[hi]), "no threshold in [0.2, 0.7]"
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if converges(simulate_rotor(sudden, start(mid), (0.0, SPAN), samples=201)):
            lo = mid
        else:
            hi = mid
    print(f"sudden start threshold: eps0* in [{lo:.5f}, {hi:.5f}]")
    pair = (round(lo - 0.01, 4), round(hi + 0.01, 4))
    fig, ax = plt.subplots(1, 3, figsize=(12.0, 4.2))
    th = np.linspace(0, 2 * math.pi, 361)
    for a in ax[:2]:
        a.plot(np.sin(th), np.cos(th), color="0.4", lw=0.8)
        a.set_aspect("equal")
        a.set_xlim(-1.05, 1.05)
        a.set_ylim(-1.05, 1.05)
        a.set_xlabel("y / c")
    ax[0].set_ylabel("-x / c (gravity down)")
    finals = []
    for col, (how, rotor) in enumerate((("sudden start", sudden), ("spin-up from rest",
                                                                    ramped))):
        for e0 in pair:
            tr = simulate_rotor(rotor, start(e0), (0.0, SPAN), samples=4001)
            t = tr.table
            verdict = "converges" if converges(tr) else "whirls"
            last = t.row(-1, named=True)
            if how != "sudden start":
                finals.append((last["x"], last["y"]))
            print(f"{how} from eps0 {e0}: {verdict} ({tr.outcome}), late max eps "
                  f"{late_eps(tr):.4f}, final eps {last['eccentricity']:.4f}")
            ax[col].plot(t["y"], -t["x"], lw=0.6, label=f"eps0 {e0}: {verdict}")
            ax[2].plot(t["tau"], t["eccentricity"], lw=0.7, label=f"{how}, eps0 {e0}")
        ax[col].set_title(f"{how} at -135 deg", fontsize=9)
        ax[col].legend(fontsize=7, loc="upper right")
    spread = math.hypot(finals[0][0] - finals[1][0], finals[0][1] - finals[1][1])
    print(f"spin-up: the two starts end {spread:.2e} c apart, {math.hypot(*finals[0]) - eps_s:+.2e}"
          f" from the equilibrium's eccentricity")
    ax[2].axhline(eps_s, color="0.5", lw=0.6, ls="--")
    ax[2].set_xlabel("tau = w t")
    ax[2].set_ylabel("eccentricity")
    ax[2].legend(fontsize=7)
    fig.suptitle("Yen (2005) fig. 3: sudden start against spin-up (plain bearing, L/D 1)",
                 fontsize=10)
    fig.tight_layout()
    path = os.path.join(out_dir, "bearing_spin_up.png")
    fig.savefig(path, dpi=70)
    print(f"total {time.perf_counter() - t_all:.1f} s; wrote {path}")


if __name__ == "__main__":
    main()
