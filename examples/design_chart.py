"""Design charts in lab units
==========================

Design charts in lab units: from which spin the balls balance stably, against the ball
mass and the track radius, for a rig like Tien's (2011) (m_d e = 33.12 g mm, 2.05 g balls
on a 16 mm track, the support's resonance near 513 rpm, zeta 0.05, zeta_b about 0.1);
then, from the model of that rig (design_balancing.png), the speed from which a sweep up
ends balanced against the oil's viscosity (through the oil law, ballbal.oil) and the
rotor's imbalance, and the fraction of starts from rest that end balanced.

    python examples/design_chart.py [output-directory]      # about 3 s (+ 1 min)
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
from ballbal.design import (  # noqa: E402
    balanced_fraction,
    balancing_chart,
    critical_speed_chart,
)

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
LAB = dict(disk_mass=0.3, eccentricity=33.12e-6 / 0.3, ball_mass=2.05e-3, track_radius=0.016,
           stiffness=1443.0, damping=2.7, track_damping=0.022, other_mass=0.2,
           max_rpm=2000.0, spins=100 if SMALL else 400)


def main() -> None:
    default = tempfile.mkdtemp(prefix="design-") if SMALL else "design_chart"
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    count = 5 if SMALL else 15
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    for i, (vary, values) in enumerate((("ball_mass", np.linspace(0.5e-3, 4e-3, count)),
                                        ("track_radius", np.linspace(0.006, 0.03, count)))):
        chart = critical_speed_chart(vary=vary, values=values, **LAB)
        print(f"critical speed against {vary}:")
        print(chart.table)
        chart.plot(ax=ax[i])
    fig.suptitle("Stable balancing above the green line (Tien 2011-like rig)")
    fig.savefig(out / "design_chart.png", dpi=110, bbox_inches="tight")
    print(f"wrote {out / 'design_chart.png'}")
    balancing(out)


# Tien's (2011) rig as the model sees it (eta 0.66, f_n 513 rpm, the support's zeta 0.01
# without pads), and the oil law's geometric factor calibrated on fig. 4-14's 36.9 cP
# oil (ballbal.calibration.transfer_oils; see docs/guide's oil section).
KAPPA = 19.0
RIG = ballbal.Balancer(mu=0.2, zeta=0.01, zeta_b=0.1, delta=50.0, Omega=1.2, eta=(0.66, 0.66))
FN = 513.0
OIL = dict(ball_radius=4e-3, ball_mass=2.05e-3, geometric_factor=KAPPA)


def balancing(out: Path) -> None:
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    oils = [15.0, 40.0, 80.0] if SMALL else list(np.linspace(10.0, 100.0, 10))
    chart = balancing_chart(RIG, vary="oil_viscosity", values=oils, natural_frequency_rpm=FN,
                            **OIL)
    print("sweep up ends balanced, against the oil (cP):")
    for r in chart.table.iter_rows(named=True):
        print(f"oil {r['oil_viscosity']:.1f} cP: zeta_b {r['zeta_b']:.4f}, chasing ends "
              f"{r['chasing_end_rpm']} rpm")
    chart.plot(ax=ax[0])
    imb = [20.0, 40.0, 80.0] if SMALL else list(np.linspace(15.0, 80.0, 10))
    chart = balancing_chart(RIG.replace(zeta_b=0.24), vary="imbalance", values=imb,
                            natural_frequency_rpm=FN, ball_mass=2.05e-3, track_radius=0.016)
    print("against the imbalance (g mm):")
    for r in chart.table.iter_rows(named=True):
        print(f"imbalance {r['imbalance']:.1f} g mm: eta margin {r['eta_margin']:.3f}, "
              f"balanced from {r['balanced_from_rpm']} rpm, {r['status']}")
    chart.plot(ax=ax[1])
    speeds = [630.0, 660.0] if SMALL else list(np.linspace(580.0, 720.0, 15))
    frac = balanced_fraction(RIG.replace(zeta_b=0.24), speeds_rpm=speeds,
                             natural_frequency_rpm=FN, starts=20 if SMALL else 200)
    for r in frac.table.iter_rows(named=True):
        print(f"balanced fraction at {r['speed_rpm']:.0f} rpm: {r['fraction']:.4f} ± "
              f"{r['std_error']:.4f} ({r['balanced']}/{r['starts']})")
    frac.plot(ax=ax[2])
    fig.suptitle("Tien (2011) rig: where a sweep up ends balanced, and how often a start "
                 "from rest does (zeta_b 0.24: the 36.9 cP oil)")
    fig.savefig(out / "design_balancing.png", dpi=110, bbox_inches="tight")
    print(f"wrote {out / 'design_balancing.png'}")


if __name__ == "__main__":
    main()
