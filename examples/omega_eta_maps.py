"""Omega-eta maps of R-R, O-O and R-O motions
==========================================

Tien's (2011) Omega-eta maps (its figures 3-6 to 3-16): where R-R, O-O and R-O motions
exist and are stable, for zeta in {0.02, 0.05, 0.1} and zeta_b in {0.05, 0.1, 0.2}
(mu 0.2, delta 50, N 3), and omega against eta for several Omega (figure 3-7).

    python examples/omega_eta_maps.py [output-directory]      # about 10 s on 2 cores

Writes one PNG per (zeta, zeta_b) with a panel per solution type, a 3 x 3 overview of
the R-R maps, the omega curves, and the tables as Parquet.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402

import ballbal  # noqa: E402
from ballbal.plot import omega_curves, scan_map  # noqa: E402

# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): two maps of 3 x 3 points, written into
# a temporary directory unless one is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"

GRID = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
ZETAS, ZETA_BS = (0.02, 0.05, 0.1), (0.05, 0.1, 0.2)
if SMALL:
    GRID = {"Omega": (1.1, 1.3, 0.1), "eta": (0.4, 1.0, 0.3)}
    ZETAS, ZETA_BS = (0.05,), (0.05, 0.1)
TYPES = ("R-R", "O-O", "R-O")


def main() -> None:
    default = tempfile.mkdtemp(prefix="omega_eta_maps-") if SMALL else "omega_eta_maps"
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    overview, axes = plt.subplots(3, 3, figsize=(15, 12), sharex=True, sharey=True)
    summary = []
    for i, zeta in enumerate(ZETAS):
        for j, zeta_b in enumerate(ZETA_BS):
            b = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=zeta_b, delta=50.0)
            df = ballbal.scan(b, patterns=TYPES, **GRID)
            df.write_parquet(out / f"map_zeta{zeta}_zetab{zeta_b}.parquet")
            fig, ax = plt.subplots(1, 3, figsize=(16, 4.5))
            for k, ty in enumerate(TYPES):
                scan_map(df, type=ty, ax=ax[k], title=f"{ty}, zeta {zeta}, zeta_b {zeta_b}")
            fig.tight_layout()
            fig.savefig(out / f"map_zeta{zeta}_zetab{zeta_b}.png", dpi=110)
            plt.close(fig)
            scan_map(df, type="R-R", ax=axes[i, j], title=f"R-R, zeta {zeta}, zeta_b {zeta_b}")
            counts = (df.filter(pl.col("status") == "converged")
                      .group_by("type", "stability").len().sort("type", "stability"))
            summary.append((zeta, zeta_b, counts))
            if (zeta, zeta_b) == (0.05, 0.1):
                fig, ax = plt.subplots(figsize=(6, 4.5))
                omega_curves(df, ax=ax)
                fig.tight_layout()
                fig.savefig(out / "omega_vs_eta.png", dpi=110)
                plt.close(fig)
    overview.tight_layout()
    overview.savefig(out / "rr_maps.png", dpi=90)
    for zeta, zeta_b, counts in summary:
        parts = ", ".join(f"{t} {s}: {n}" for t, s, n in counts.iter_rows())
        print(f"zeta {zeta:<4} zeta_b {zeta_b:<4}  {parts}")
    print(f"figures and tables in {out}/")


if __name__ == "__main__":
    main()
