"""Seed 003: the two-ball balancer's equilibria continued with ballbal's own
continuation (the seed used AUTO), drawn in the seed's units (its figure 5):
saddle-node curves of the balls-together equilibria and the Hopf curve of the perfect
balance in the (omega0, C0) and (omega0, D0) planes at its defaults (table 2: m0 = 2,
e = 2, C0 = D0 = 0.35), converted by ``from_seed003``.

Run: python examples/seed003.py [OUTDIR]   (a few seconds)
"""

import math
import os
import sys

import matplotlib.pyplot as plt

from ballbal._branch import Continuation
from ballbal.continuation import equilibrium_branch, equilibrium_curve, from_seed003

M0 = 2.0
S = math.sqrt(1 + 2 * M0)  # Omega = omega0 S, zeta = C0 / S, zeta_b = D0 S / 2
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
OPTS = Continuation(ds=0.01, ds_max=0.1 if SMALL else 0.05, max_points=150 if SMALL else 400)


def curves(second: str, lo: float, hi: float) -> list:
    # from low speed upwards: branches are continued forwards from their start
    b = from_seed003(0.3, M0, 2.0, C0=0.35, D0=0.35)
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


def main() -> None:
    outdir = sys.argv[1] if len(sys.argv) > 1 else "."
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, second, scale, label, hi in (
        (axes[0], "zeta", S, "C0", 1.2 / S),
        (axes[1], "zeta_b", 2 / S, "D0", 0.6 * S / 2),
    ):
        for c in curves(second, 1e-3, hi):
            x = c.table["Omega"].to_numpy() / S
            y = c.table[second].to_numpy() * scale
            ax.plot(x, y, "--" if c.kind == "hopf" else "-",
                    label=f"{c.kind} ({'perfect balance' if c.kind == 'hopf' else 'together'})")
        ax.set_xlim(0, 2.2)
        ax.set_xlabel("omega0")
        ax.set_ylabel(label)
        ax.set_title(f"seed 003, (omega0, {label}) at m0 = {M0}")
        ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(outdir, "seed003.png")
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
