"""Table 3-1: Floquet multipliers of R-R orbits
============================================

Tien's (2011) table 3-1 lists the moduli of the Floquet multipliers of two R-R orbits
(mu 0.2, zeta 0.05, zeta_b 0.05, delta 50): the standard case (Omega 1.2, eta 1.0, N 3)
and a hard case (Omega 1.0, eta 0.7: slow rotation, period about 106, near resonance) at
N 3 and 4. This script computes them with ballbal and prints them beside the published
values and, for the standard case, beside an independent shooting computation (omega
0.25141, moduli 1.0000, 0.8637, 0.2859, 0.2859, 0.2345, 0.2345, 0.1185, 0.0951). The
figure shows the moduli, and how far the trivial multiplier (exactly 1 for an exact
orbit) lies from 1 as the hard case's harmonics N grow: its distance measures the
orbit's truncation error.

Run: python examples/table_3_1.py [output-directory]   (a few seconds)
"""

import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import polars as pl

import ballbal

PUBLISHED = {
    "standard N=3": [1.0000, 0.8641, 0.2859, 0.2859, 0.2346, 0.2346, 0.1185, 0.0951],
    "hard N=3": [1.1808, 0.0453, 0.0048, 0.0048, 0.0021, 0.0021, 0.0005, 0.0001],
    "hard N=4": [1.0379, 0.0449, 0.0048, 0.0048, 0.0020, 0.0020, 0.0005, 0.0001],
}
SHOOTING = [1.0000, 0.8637, 0.2859, 0.2859, 0.2345, 0.2345, 0.1185, 0.0951]


def moduli(sol) -> np.ndarray:
    """The trivial multiplier's modulus first, then the others, largest first."""
    m = np.abs(np.asarray(sol.multipliers))
    trivial = int(np.argmin(np.abs(np.asarray(sol.multipliers) - 1.0)))
    rest = np.sort(np.delete(m, trivial))[::-1]
    return np.concatenate([[m[trivial]], rest])


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    standard = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2,
                                eta=(1.0, 1.0))
    hard = standard.replace(Omega=1.0, eta=(0.7, 0.7))
    rows = []
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, model, N in (("standard N=3", standard, 3), ("hard N=3", hard, 3),
                           ("hard N=4", hard, 4)):
        sol = ballbal.periodic(model, "R-R", N=N)
        ours = moduli(sol)
        print(f"{name}: omega {sol.omega:.5f}")
        print("  published " + " ".join(f"{v:.4f}" for v in PUBLISHED[name]))
        print("  ballbal   " + " ".join(f"{v:.4f}" for v in ours))
        if name.startswith("standard"):
            print("  shooting  " + " ".join(f"{v:.4f}" for v in SHOOTING))
        for k, (v, p) in enumerate(zip(ours, PUBLISHED[name], strict=True)):
            rows.append({"case": name, "N": N, "rank": k, "modulus": float(v), "published": p})
        ax1.plot(range(8), PUBLISHED[name], "o", mfc="none", ms=8,
                 label=f"{name}, published")
        ax1.plot(range(8), ours, "x", label=f"{name}, ballbal")
    ax1.set_yscale("log")
    ax1.set_xlabel("multiplier (trivial first, then by modulus)")
    ax1.set_ylabel(r"$|\rho|$")
    ax1.set_title("table 3-1: moduli of the Floquet multipliers")
    ax1.legend(fontsize=7)
    # The hard case's trivial multiplier against N: the truncation error of the orbit.
    ns = [3, 4, 5, 6, 8, 10, 12]
    errs = []
    guess = None
    for N in ns:
        sol = ballbal.periodic(hard, "R-R", N=N, guess=guess)
        guess = sol
        errs.append(abs(moduli(sol)[0] - 1.0))
        rows.append({"case": "hard trivial", "N": N, "rank": 0, "modulus": float(moduli(sol)[0]),
                     "published": None})
    print("hard case, |trivial multiplier - 1| against N: "
          + ", ".join(f"N={n}: {e:.1e}" for n, e in zip(ns, errs, strict=True)))
    ax2.semilogy(ns, errs, "o-", label="ballbal")
    ax2.semilogy([3, 4], [0.1808, 0.0379], "s", mfc="none", ms=8, label="published")
    ax2.set_xlabel("harmonics N")
    ax2.set_ylabel(r"$||\rho_{trivial}| - 1|$")
    ax2.set_title(r"hard case ($\Omega$ 1.0, $\eta$ 0.7): truncation error")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    pl.DataFrame(rows).write_parquet(out / "table_3_1.parquet")
    fig.savefig(out / "table_3_1.png", dpi=100)
    print(f"wrote {out / 'table_3_1.png'} and {out / 'table_3_1.parquet'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("."))
