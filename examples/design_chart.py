"""Design charts in lab units
==========================

Design charts in lab units: from which spin the balls balance stably, against the ball
mass and the track radius, for a rig like Tien's (2011) (m_d e = 33.12 g mm, 2.05 g balls
on a 16 mm track, the support's resonance near 513 rpm, zeta 0.05, zeta_b about 0.1).

    python examples/design_chart.py [output-directory]      # about 3 s
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

from ballbal.design import critical_speed_chart  # noqa: E402

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


if __name__ == "__main__":
    main()
