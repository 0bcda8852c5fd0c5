"""Maps of ball-spring balancers
=============================

R-R motions of ball-spring balancers (scans of scenes): where balls that chase round
the track exist and are stable, over spin speed and spring stiffness, for a planar disk
and for an off-centre disk that tilts on its shaft (Rezaee et al.'s (2017) rotor).

    python examples/scene_maps.py [output-directory]      # about 10 s on 2 cores

Writes scene_maps.png (one panel per rotor) and the tables as Parquet, and prints how
the stable R-R range shrinks as the springs stiffen.
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
from ballbal.plot import scan_map  # noqa: E402

# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): 3 x 3 points a rotor, written into a
# temporary directory unless one is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"

GRID = {"Omega": (1.0, 2.0, 0.025), "springs": (0.0, 4e-5, 5e-6)}
if SMALL:
    GRID = {"Omega": (1.1, 1.3, 0.1), "springs": (0.0, 2e-5, 1e-5)}
BALANCER = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0)
ROTORS = {
    "planar disk": ballbal.Scene(balancer=BALANCER),
    "tilting disk, a = 1.8, b = 2.2": ballbal.Scene(
        balancer=BALANCER, tilt=ballbal.Tilt(a=1.8, b=2.2, j_t=0.35, j_z=0.55, zeta_r=0.04)),
}


def main() -> None:
    default = tempfile.mkdtemp(prefix="scene_maps-") if SMALL else "."
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8), sharey=True)
    for ax, (label, scene) in zip(axes, ROTORS.items(), strict=True):
        df = ballbal.scan(scene, **GRID)
        df.write_parquet(out / f"scene_map_{'tilt' if scene.tilt else 'planar'}.parquet")
        scan_map(df, x="Omega", y="springs", ax=ax, title=f"R-R, {label}",
                 shade="balanced state stable")
        stable = df.filter(pl.col("stability") == "stable")
        print(f"{label}: {df.select('Omega', 'springs').unique().height} points, "
              f"{(df['status'] == 'converged').sum()} R-R solutions, {stable.height} stable")
        for k in sorted(stable["springs"].unique().to_list())[::2]:
            om = stable.filter(pl.col("springs") == k)["Omega"]
            print(f"  springs {k:7.1e}: stable R-R for Omega {om.min():.3f} .. {om.max():.3f}"
                  f" ({om.len()} of {len(df['Omega'].unique())} speeds)")
    fig.tight_layout()
    fig.savefig(out / "scene_maps.png", dpi=110)
    print(f"wrote {out / 'scene_maps.png'}")


if __name__ == "__main__":
    main()
