"""Stability regions of a tilting rotor in its own units
=====================================================

Rezaee et al.'s (2017) stability maps in its own axes: fig. 3 (the classic
balancer on a Jeffcott rotor, lam against omega_bar), fig. 4 (the tilting disk on its
shaft, lam against omega_bar, m_bar = eps_bar = 0.01, zeta_t = zeta_r = 0.1) and fig. 5
(m_bar against omega_bar, lam = 0.1). The paper does not print its shaft geometry or
inertias: here the disk sits at a = 4 R, b = 6 R from the bearings with J_t = 0.3 M R^2,
J_z = 0.5 M R^2, and no ball springs (the paper's k_d is not printed either), so the maps
show the shape of its figures, not their exact boundaries.

    python examples/shaft_units_maps.py [output-directory]      # about 5 s
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
import polars as pl  # noqa: E402

from ballbal import plot_balance_map  # noqa: E402
from ballbal.shaft import ShaftUnits  # noqa: E402

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
STEPS = 21 if SMALL else 81
OMEGA_BAR = np.linspace(0.2, 4.0, STEPS)
LAM = np.linspace(0.0, 0.4, 9 if SMALL else 41)  # 0.1 on the grid
TILT = dict(a=4.0, b=6.0, j_t=0.3, j_z=0.5)


def lowest_stable(df: pl.DataFrame, at_lam: float) -> float | None:
    rows = df.filter(((pl.col("lam") - at_lam).abs() < 1e-9)
                     & (pl.col("stability") == "stable"))
    return None if rows.height == 0 else float(rows["omega_bar"].min())


def main() -> None:
    default = tempfile.mkdtemp(prefix="shaft-") if SMALL else "shaft_units_maps"
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.3))
    base = dict(m_bar=0.01, eps_bar=0.01, lam=0.1, zeta_t=0.1)
    jeffcott = ShaftUnits(omega_bar=1.0, **base)  # flat disk at mid-span
    tilting = ShaftUnits(omega_bar=1.0, zeta_r=0.1, **base, **TILT)
    for k, (units, title) in enumerate(((jeffcott, "fig. 3: Jeffcott rotor"),
                                        (tilting, "fig. 4: tilting disk"))):
        df = units.balance_map(OMEGA_BAR, LAM)
        plot_balance_map(df, "omega_bar", "lam", ax=ax[k], label=title)
        for lam in (0.0, 0.1):
            print(f"{title}: lam {lam}: stable balance from omega_bar "
                  f"{lowest_stable(df, lam)}")
    rows = []
    for m_bar in np.linspace(0.002, 0.05, STEPS // 4 + 1):
        units = ShaftUnits(omega_bar=1.0, m_bar=float(m_bar), eps_bar=0.01, lam=0.1,
                           zeta_t=0.1, zeta_r=0.1, **TILT)
        rows.append(units.balance_map(OMEGA_BAR).with_columns(pl.lit(float(m_bar))
                                                              .alias("m_bar")))
    fig5 = pl.concat(rows)
    print("fig. 5: no balance for m_bar < eps_bar / 2:",
          sorted(set(fig5.filter(pl.col("status") == "no_balance")["m_bar"].round(4))))
    plot_balance_map(fig5.filter(pl.col("status") == "ok"), "omega_bar", "m_bar", ax=ax[2],
                     label="fig. 5: tilting disk, lam 0.1")
    fig.suptitle("Stable balanced regions in Rezaee et al.'s (2017) axes (green: stable)")
    fig.savefig(out / "shaft_units_maps.png", dpi=110, bbox_inches="tight")
    print(f"wrote {out / 'shaft_units_maps.png'}")


if __name__ == "__main__":
    main()
