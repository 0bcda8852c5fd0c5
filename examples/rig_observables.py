"""Spectra, basins and a speed sweep on the rig
============================================

Tien's (2011) chapter 4 in the model: fixed-frame spectra of its figures
4-12 (R-R), 4-27 (O-O) and 4-28 (R-O), the main vibration frequency against speed of
figure 4-13 against the measured band (``ballbal.data``), the basins of attraction of
figures 4-15 / 4-16 and a speed sweep up and down with its hysteresis.

Run: python examples/rig_observables.py [out_dir]   (about 5 s; small mode less)
"""

import os
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import polars as pl

import ballbal
from ballbal.basins import basins, plot_basins
from ballbal.spectrum import plot_spectrum
from ballbal.sweep import speed_sweep

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"
GRID = 6 if SMALL else 40
FN_RPM = ballbal.data.NATURAL_FREQUENCY_RPM


def balancer(zeta, zeta_b, omega, eta):
    return ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=zeta_b, delta=50, Omega=omega,
                            eta=(eta, eta))


def follow(m, pattern, steps, N=3):
    """A solution reached by continuation from where a simulation finds it (at the
    figures' own parameters a simulation from rest lands on another attractor)."""
    sol = ballbal.periodic(m, pattern, N=N)
    for ch in steps:
        m = m.replace(**ch)
        sol = ballbal.periodic(m, pattern, N=N, guess=sol)
    return m, sol


def main(out: Path) -> None:
    fig, axes = plt.subplots(2, 4, figsize=(20, 9))
    cases = [("4-12 R-R", "R-R", balancer(0.05, 0.05, 1.2, 1.0),
              [dict(zeta_b=0.1, zeta=0.02), dict(Omega=1.3), dict(eta=(0.7, 0.7))]),
             ("4-27 O-O", "O-O", balancer(0.1, 0.1, 1.1, 1.3), []),
             ("4-28 R-O", "R-O", balancer(0.02, 0.05, 1.4, 0.8),
              [dict(zeta_b=0.075), dict(zeta_b=0.1), dict(Omega=1.35), dict(Omega=1.3),
               dict(eta=(0.7, 0.7))])]
    for ax, (name, pattern, m0, steps) in zip(axes[0, :3], cases, strict=True):
        m, sol = follow(m0, pattern, steps)
        spec = sol.spectrum()
        top = spec.sort("amplitude", descending=True).row(0, named=True)
        print(f"fig. {name}: omega {sol.omega:.3f}, largest line k = {top['k']} at "
              f"{top['frequency']:.3f} (Omega - omega = {m.Omega - sol.omega:.3f})")
        plot_spectrum(spec, ax=ax, title=f"fig. {name}, omega {sol.omega:.2f}")
    # Figure 4-13: main frequency (Omega - omega) f_n of the stable R-R against speed.
    b = balancer(0.05, 0.05, 1.2, 1.3)
    step = 0.1 if SMALL else 0.025
    rr = ballbal.scan(b, Omega=(1.0, 1.95, step), eta=[1.3], patterns=["R-R"])
    rr = rr.filter(pl.col("stability") == "stable").sort("Omega")
    main_rpm = ((rr["Omega"] - rr["omega"]) * FN_RPM).to_numpy()
    t = ballbal.data.experiments()
    lo = t.filter(pl.col("quantity") == "main_frequency_min")["value"][0]
    hi = t.filter(pl.col("quantity") == "main_frequency_max")["value"][0]
    print(f"fig. 4-13: model main frequency {main_rpm.min():.0f} to {main_rpm.max():.0f} "
          f"rpm over {rr['Omega'].min() * FN_RPM:.0f} to {rr['Omega'].max() * FN_RPM:.0f} "
          f"rpm; measured {lo:.0f} to {hi:.0f} rpm")
    ax = axes[0, 3]
    ax.plot(rr["Omega"].to_numpy() * FN_RPM, main_rpm, "o-", label="model (Omega - omega) f_n")
    ax.axhspan(lo, hi, color="tab:orange", alpha=0.3, label="measured")
    ax.set_xlabel("speed (rpm)")
    ax.set_ylabel("main frequency (rpm)")
    ax.set_title("fig. 4-13")
    ax.legend()
    # Figures 4-15 / 4-16.
    for ax, om in zip(axes[1, :2], (1.2, 1.35), strict=True):
        r = basins(balancer(0.05, 0.05, om, 0.7), n=GRID)
        p, se = r.rotating_fraction()
        print(f"fig. 4-1{5 if om == 1.2 else 6}: Omega {om}: rotating fraction {p:.3f} "
              f"+- {se:.3f}")
        plot_basins(r, ax=ax, title=f"Omega {om}: rotating {p:.2f}")
    # A speed sweep up and down (section 4-2's procedure).
    speeds = np.round(np.arange(1.0, 1.8 + 1e-9, 0.05), 3)
    sw = speed_sweep(balancer(0.05, 0.05, 1.0, 0.7), speeds, dwell=1000.0)
    print(f"sweep: up-transition Omega {sw.up}, down-transition Omega {sw.down}, "
          f"hysteresis {sw.hysteresis}")
    ax = axes[1, 2]
    for d, mk in (("up", "o-"), ("down", "s--")):
        s = sw.table.filter(pl.col("direction") == d)
        ax.plot(s["Omega"], s["vibration"], mk, label=d)
    ax.set_xlabel("Omega")
    ax.set_ylabel("mean |Z''|")
    ax.set_title("speed sweep (eta 0.7)")
    ax.legend()
    axes[1, 3].axis("off")
    fig.tight_layout()
    fig.savefig(out / "rig_observables.png", dpi=80)
    print(f"wrote {out / 'rig_observables.png'}")


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else None
    if target is None and SMALL:
        target = Path(tempfile.mkdtemp())
    target = target or Path(__file__).parent
    target.mkdir(parents=True, exist_ok=True)
    main(target)
