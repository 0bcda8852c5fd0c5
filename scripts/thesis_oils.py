"""The oil law (ballbal.oil) calibrated on one of Tien's (2011) measured transitions and
transferred to the others: fig. 4-14's three oils (the sweep up leaves the chasing
motion at 675 / 800 / 950 rpm for 76.0 / 36.9 / 26.3 cP, 25 rpm steps) and fig. 4-22's
rubber pads (oil (4), 12.3 cP; the chasing band ends at Omega 1.4 (pads C) and 1.5
(pads B); pads A still chase at the rig's top speed, 1000 rpm: a lower bound, given here
as 1000 rpm).

The rig as the model sees it: mu 0.2, delta 50, eta 0.66 (2.05 g balls of radius 4 mm on
the 16 mm track, 1.38 g at 36 mm), f_n 513 rpm without pads and the pads' own f_n and
zeta (table 4-5). The support's damping without pads was not measured; ``zeta`` is the
first argument (default 0.01: below the softest pads' 0.020, as a bare steel leaf
spring's is). The law's geometric factor is calibrated on the 36.9 cP oil.

    python scripts/thesis_oils.py [zeta]       # some minutes: a band-end search per try
"""

from __future__ import annotations

import sys
import time

import polars as pl

import ballbal
from ballbal.calibration import transfer_oils


def main() -> None:
    zeta = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
    rig = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=0.1, delta=50.0, Omega=1.2,
                           eta=(0.66, 0.66))
    cases = pl.DataFrame({
        "case": ["oil 76.0 cP", "oil 36.9 cP", "oil 26.3 cP", "pads C", "pads B",
                 "pads A (>)"],
        "viscosity_cP": [76.0, 36.9, 26.3, 12.3, 12.3, 12.3],
        "speed_rpm": [675.0, 800.0, 950.0, 1.4 * 557, 1.5 * 543, 1000.0],
        "natural_frequency_rpm": [513.0, 513.0, 513.0, 557.0, 543.0, 521.0],
        "zeta": [zeta, zeta, zeta, 0.039, 0.030, 0.020],
        # half a step of the sweep either side (25 rpm; 0.05 Omega with the pads)
        "uncertainty_rpm": [12.5, 12.5, 12.5, 0.025 * 557, 0.025 * 543, 0.0],
    })
    t = time.perf_counter()
    res = transfer_oils(rig, cases, reference=1, ball_radius=4e-3, ball_mass=2.05e-3)
    pl.Config.set_tbl_cols(20)
    pl.Config.set_tbl_width_chars(250)
    print(res)
    print(res.table.drop("natural_frequency_rpm"))
    print(f"{time.perf_counter() - t:.0f} s")


if __name__ == "__main__":
    main()
