"""Bifurcation curves in units of the disk alone
=============================================

Bifurcation diagrams of the two-ball balancer in units of the disk alone, after
[EccentricRotorABB]: its equilibria continued with ballbal's own continuation (the paper
used AUTO), drawn in the disk's units.

Figure 4: the (omega0, m0) plane at e = 2, C0 = D0 = 0.35, continued in these units' own
parameters (a ``DiskUnits`` model: m0 moves mu, eta, Omega, zeta and zeta_b at once):
the saddle-node curve SN_2+ of the balls-together state, the pitchfork PF (m0 = e/2)
and the perfect balance's Hopf curve H_1, meeting at (omega0, m0) = (0.5773, 1).
Figure 5: saddle-node curves of the balls-together equilibria and the Hopf curve of the
perfect balance in the (omega0, C0) and (omega0, D0) planes at its defaults (table 2:
m0 = 2, e = 2, C0 = D0 = 0.35), converted by ``from_disk_units``.

Run: python examples/disk_units_bifurcations.py [OUTDIR]   (a few seconds)
"""

import math
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import ballbal
from ballbal._branch import Continuation
from ballbal.continuation import DiskUnits, equilibrium_branch, equilibrium_curve, from_disk_units

M0 = 2.0
S = math.sqrt(1 + 2 * M0)  # Omega = omega0 S, zeta = C0 / S, zeta_b = D0 S / 2
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
OPTS = Continuation(ds=0.01, ds_max=0.1 if SMALL else 0.05, max_points=150 if SMALL else 400)


def curves(second: str, lo: float, hi: float) -> list:
    # from low speed upwards: branches are continued forwards from their start
    b = from_disk_units(0.3, M0, 2.0, C0=0.35, D0=0.35)
    out = []
    for start in ("together", "perfect_balance"):
        br = equilibrium_branch(b, "Omega", start=start, range=(0.25 * S, 2.2 * S), options=OPTS)
        for i, t in enumerate(br.events["type"].to_list()):
            if t in ("fold", "hopf"):
                c = equilibrium_curve(br, i, second, range=(lo, hi), options=OPTS)
                print(f"{start} {t} at omega0 = {br.events['Omega'][i] / S:.4f}: "
                      f"{c.kind} curve of {c.table.height} points, stop {c.stop}")
                out.append(c)
    return out


def figure4(ax: plt.Axes) -> None:
    """SN_2+, PF and H_1 in (omega0, m0), continued in the disk's units."""
    units = DiskUnits(omega0=0.3, m0=M0, e=2.0, C0=0.35, D0=0.35)
    tog = equilibrium_branch(units, "omega0", start="together", range=(0.25, 2.2), options=OPTS)
    sn = equilibrium_curve(tog, "fold", "m0", range=(0.05, 5.0), options=OPTS)
    at = units.replace(omega0=1.5, m0=0.5)  # the state 2+ (balls opposite the imbalance)
    start = next(e for e in ballbal.equilibria(at.balancer)
                 if e.kind == "together" and np.cos(e.q[2]) < 0)
    up = equilibrium_branch(at, "m0", start=start, range=(0.05, 5.0), options=OPTS)
    pf = equilibrium_curve(up, "branch_point", "omega0", range=(0.01, 2.2), options=OPTS)
    pb = equilibrium_branch(units.replace(omega0=0.8), "omega0", start="perfect_balance",
                            range=(0.6, 2.2), options=OPTS)
    h1 = equilibrium_curve(pb, "hopf", "m0", range=(1.0 + 1e-4, 5.0), options=OPTS)
    for c, name, style in ((sn, "SN_2+", "-"), (pf, "PF", "-."), (h1, "H_1", "--")):
        ax.plot(c.table["omega0"], c.table["m0"], style, label=name)
        print(f"figure 4: {name} of {c.table.height} points, stop {c.stop}")
    for row in sn.points.iter_rows(named=True):
        print(f"figure 4: {row['type']} at (omega0, m0) = ({row['omega0']:.4f}, "
              f"{row['m0']:.4f})")
        if row["type"] == "pitchfork":
            ax.plot(row["omega0"], row["m0"], "ko", ms=5)
    ax.set_xlim(0, 2.2)
    ax.set_ylim(0, 5)
    ax.set_xlabel("omega0")
    ax.set_ylabel("m0")
    ax.set_title("disk units, figure 4: (omega0, m0) at e = 2")
    ax.legend(fontsize=8)


def main() -> None:
    outdir = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(outdir, exist_ok=True)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.5))
    figure4(axes[0])
    for ax, second, scale, label, hi in (
        (axes[1], "zeta", S, "C0", 1.2 / S),
        (axes[2], "zeta_b", 2 / S, "D0", 0.6 * S / 2),
    ):
        for c in curves(second, 1e-3, hi):
            x = c.table["Omega"].to_numpy() / S
            y = c.table[second].to_numpy() * scale
            ax.plot(x, y, "--" if c.kind == "hopf" else "-",
                    label=f"{c.kind} ({'perfect balance' if c.kind == 'hopf' else 'together'})")
        ax.set_xlim(0, 2.2)
        ax.set_xlabel("omega0")
        ax.set_ylabel(label)
        ax.set_title(f"disk units, figure 5: (omega0, {label}) at m0 = {M0}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(outdir, "disk_units_bifurcations.png")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
