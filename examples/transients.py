"""Transients: disturbances and run-up
===================================

Transient studies with scenes (time simulation of non-autonomous scenes).

1. [TwoBallStrength]: a spin-speed disturbance (Omega 2.0 -> 2.5 in 5 time units) from the
   perfect balance; peak radial amplitude and settling time into a +-0.01 e band against
   the track damping, and the damping that minimises their combined index.
2. A run-up through the resonance (Omega 0.3 -> 2.0) of the classic balancer and of a
   ball-spring balancer (the planar part of Rezaee et al.'s (2017) comparison).

    python examples/transients.py [output-directory]      # about 3 s
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ballbal  # noqa: E402

# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): fewer dampings and shorter times,
# written into a temporary directory unless one is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
ZETA_B = [0.05, 0.4] if SMALL else [0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8]
STUDY_END, RESPONSE_END, RUN_UP_END = (400.0, 200.0, 500.0) if SMALL else (2000, 600, 800)


def main() -> None:
    default = tempfile.mkdtemp(prefix="transients-") if SMALL else "transients"
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.5))

    b = ballbal.Balancer(Omega=2.0, zeta=0.05, eta=(1.0, 1.0))
    df = ballbal.track_damping_study(b, ZETA_B, to=2.5, t_end=STUDY_END)
    print(df)
    best = df.filter(df["optimal"])["zeta_b"][0]
    print(f"track damping with the best combined index: zeta_b = {best}")
    ax[0].plot(df["zeta_b"], df["peak"], "o-", label="peak radial amplitude (e)")
    ax0b = ax[0].twinx()
    ax0b.plot(df["zeta_b"], df["settle_time"], "s-", color="tab:red", label="settling time")
    ax[0].set_xscale("log")
    ax[0].set_xlabel("zeta_b")
    ax[0].set_ylabel("peak radial amplitude / e")
    ax0b.set_ylabel("settling time (1/w_n)")
    ax[0].set_title(f"speed disturbance 2.0 -> 2.5: best zeta_b = {best}")
    for z in (ZETA_B[0], best) if SMALL else (0.02, best, 0.8):
        r = ballbal.disturbance_response(b.replace(zeta_b=z), 2.5, t_end=RESPONSE_END)
        tr = r.trajectory
        ax[1].plot(tr["t"], np.hypot(tr["x"], tr["y"]), lw=0.8, label=f"zeta_b = {z}")
    ax[1].set_xlabel("t (1/w_n)")
    ax[1].set_ylabel("r / e")
    ax[1].set_title("radial vibration after the disturbance")
    ax[1].legend(fontsize=8)

    base = ballbal.Balancer(Omega=0.3, zeta=0.05, zeta_b=0.05, eta=(1.0, 1.0))
    ramp = ballbal.Ramp(to=2.0, start=0.0, duration=300.0)
    y0 = [0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0]
    t = np.linspace(0, RUN_UP_END, int(10 * RUN_UP_END) + 1)
    for springs, label in ((0.0, "classic"), (2e-5, "ball springs k_d/k = 2e-5")):
        sc = ballbal.Scene(balancer=base, springs=springs, ramp=ramp)
        tr = ballbal.simulate(sc, y0, t)
        r = np.hypot(tr["x"], tr["y"])
        print(f"run-up, {label}: peak r = {r.max():.3f} e, final r = {r[-1]:.2e} e")
        ax[2].plot(t, r, lw=0.8, label=f"{label} (peak {r.max():.2f})")
    ax[2].set_xlabel("t (1/w_n); Omega 0.3 -> 2.0 over 300")
    ax[2].set_ylabel("r / e")
    ax[2].set_title("run-up through the resonance")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "transients.png", dpi=110)
    print(f"figure in {out}/")


if __name__ == "__main__":
    main()
