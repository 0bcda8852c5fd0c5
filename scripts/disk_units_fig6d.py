"""Figure 6(d) of [EccentricRotorABB] (omega0 0.6, m0 4, e 2): the evidence for
docs/source_documents.md.

For each candidate reading of the paper, from its own equations
(``tests/disk_units_equations.py``, written independently of ballbal): the perfect
balance's eigenvalues (roots of the
characteristic polynomial ``det(lambda^2 M + lambda C + K)``), the Routh–Hurwitz verdict,
and a scipy DOP853 run from the seed's start (``x = y = 0``, ``phi1 = pi/2``,
``phi2 = -pi/2``, at rest) reporting the radial vibration ``r = sqrt(x^2 + y^2)`` late in the
run (its mean and peak-to-peak: a figure like 6(d) needs ``r`` to keep oscillating).
Then ballbal's own verdict (``equilibria(from_disk_units(...))``).

Run: ``python scripts/disk_units_fig6d.py [--t-end 3000]``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import disk_units_equations as s3  # noqa: E402

W0, M0, E = 0.6, 4.0, 2.0
#: Table 2's defaults; table 1's dimensional values give D0 = D / (m R^2 omega_n) = 1.414.
C0, D0 = 0.35, 0.35
D0_TABLE1 = 0.01 / (0.2 * 0.05**2 * math.sqrt(20 / 0.1))
C0_TABLE1 = 1.0 / (2 * math.sqrt(20 * 0.1))

#: name: (omega0, m0, e, C0, D0, sign of phi2 row's 2 Omega x', sign of eq. (6)'s Y'' cos)
READINGS = {
    "as derived (eq. 3), table 2": (W0, M0, E, C0, D0, 1.0, 1.0),
    "D0 from table 1 (1.414)": (W0, M0, E, C0, D0_TABLE1, 1.0, 1.0),
    "C0, D0 from table 1": (W0, M0, E, C0_TABLE1, D0_TABLE1, 1.0, 1.0),
    "eq. (8)'s phi2 row as printed": (W0, M0, E, C0, D0, -1.0, 1.0),
    "eq. (6) as printed (fixed frame)": (W0, M0, E, C0, D0, 1.0, -1.0),
    "m0 = 0.4 (decimal slip)": (W0, 0.4, E, C0, D0, 1.0, 1.0),
    "omega0 = 0.06": (0.06, M0, E, C0, D0, 1.0, 1.0),
    "C0 = 0.035": (W0, M0, E, 0.035, D0, 1.0, 1.0),
    "D0 = 0.035": (W0, M0, E, C0, 0.035, 1.0, 1.0),
}


def verdict(w0: float, m0: float, e: float, c0: float, d0: float,
            sign_phi2: float) -> tuple[np.ndarray, bool] | None:
    """Eigenvalues and Routh–Hurwitz verdict of the perfect balance (None: none exists)."""
    if e > 2 * m0:
        return None
    q0 = s3.perfect_balance(m0, e)
    p = s3.char_poly(*s3.linearised(q0, w0, m0, e, c0, d0, sign_phi2))
    return np.roots(p), s3.hurwitz_stable(p)


def run(w0: float, m0: float, e: float, c0: float, d0: float, sign_phi2: float,
        sign_eq6: float, t_end: float) -> tuple[float, float, float]:
    """``(mean r, peak-to-peak r)`` over the last fifth of a run from the seed's start,
    and the largest ``r`` seen."""
    z0 = np.array([0.0, 0.0, math.pi / 2, -math.pi / 2, 0, 0, 0, 0])
    t = np.linspace(0.0, t_end, int(t_end * 20) + 1)
    if sign_eq6 == 1.0:
        sol = solve_ivp(s3.rotating_rhs(w0, m0, e, c0, d0, sign_phi2), (0, t_end), z0,
                        t_eval=t, method="DOP853", rtol=1e-9, atol=1e-11)
        r = np.hypot(sol.y[0], sol.y[1])
    else:
        # the fixed frame: at t = 0 it coincides with the rotating one, velocities differ
        # by omega0 x J (x, y) = 0 at the centre
        sol = solve_ivp(s3.inertial_rhs(w0, m0, e, c0, d0, sign_eq6), (0, t_end), z0,
                        t_eval=t, method="DOP853", rtol=1e-9, atol=1e-11)
        r = np.hypot(sol.y[0], sol.y[1])
    assert sol.status == 0, sol.message
    tail = r[t >= 0.8 * t_end]
    return float(tail.mean()), float(np.ptp(tail)), float(r.max())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--t-end", type=float, default=3000.0)
    args = ap.parse_args()
    print(f"seed 003 fig. 6(d): omega0 {W0}, m0 {M0}, e {E}, table 2: C0 {C0}, D0 {D0}; "
          f"table 1 gives C0 {C0_TABLE1:.4f}, D0 {D0_TABLE1:.4f}; run to t0 = {args.t_end:g}")
    print(f"{'reading':36s} {'max Re lambda':>14s} {'R-H':>5s} {'mean r':>9s} "
          f"{'p-p r':>9s} {'max r':>7s}")
    for name, (w0, m0, e, c0, d0, sp2, se6) in READINGS.items():
        v = verdict(w0, m0, e, c0, d0, sp2) if se6 == 1.0 else None
        if v is None:
            idx, rh = "n/a", "n/a"
        else:
            idx, rh = f"{v[0].real.max():.3e}", "yes" if v[1] else "no"
        mean, pp, top = run(w0, m0, e, c0, d0, sp2, se6, args.t_end)
        print(f"{name:36s} {idx:>14s} {rh:>5s} {mean:9.3e} {pp:9.3e} {top:7.3f}")

    # how long the derived reading's transient looks like "no balance"
    z0 = np.array([0.0, 0.0, math.pi / 2, -math.pi / 2, 0, 0, 0, 0])
    t = np.linspace(0.0, 400.0, 8001)
    sol = solve_ivp(s3.rotating_rhs(W0, M0, E, C0, D0), (0, 400.0), z0, t_eval=t,
                    method="DOP853", rtol=1e-9, atol=1e-11)
    r = np.hypot(sol.y[0], sol.y[1])
    wn = math.sqrt(20 / 0.1)
    for a, b in ((0, 25), (25, 50), (50, 100), (100, 200), (200, 400)):
        w = r[(t >= a) & (t <= b)]
        print(f"as derived, t0 {a}-{b} ({a / wn:.1f}-{b / wn:.1f} s): r {w.min():.4f} to "
              f"{w.max():.4f} R")
    # the readings that reproduce 6(d), on the paper's other panels
    print("panels: balance's max Re lambda at 6(a) (20, 2), 6(b) (0.3, 2), 6(d) (0.6, 4); "
          "6(c) (4, 0.5) run to t0 300: mean r, p-p r (units R)")
    for name, c0, d0, sp2 in (("as derived", C0, D0, 1.0), ("phi2 row as printed", C0, D0, -1.0),
                              ("D0 = 0.035", C0, 0.035, 1.0), ("C0 = 0.035", 0.035, D0, 1.0)):
        idx = []
        for w0, m0 in ((20.0, 2.0), (0.3, 2.0), (0.6, 4.0)):
            v = verdict(w0, m0, E, c0, d0, sp2)
            assert v is not None
            idx.append(f"{v[0].real.max():+.4f}")
        mean, pp, _ = run(4.0, 0.5, E, c0, d0, sp2, 1.0, 300.0)
        print(f"  {name:22s} 6(a) {idx[0]} 6(b) {idx[1]} 6(d) {idx[2]}  6(c) r {mean:.5f} "
              f"(x 0.05 m = {0.05 * mean:.6f} m), p-p {pp:.2e}")

    import ballbal
    from ballbal.model import from_disk_units

    b = from_disk_units(W0, M0, E, C0, D0)
    eq = next(q for q in ballbal.equilibria(b) if q.kind == "perfect_balance")
    scale = math.sqrt(1 + 2 * M0)  # ballbal's time unit: omega_n of disk and balls
    print(f"ballbal: perfect balance {eq.stability}, max Re lambda {eq.stability_index:.4e} "
          f"in its units = {eq.stability_index / scale:.4e} in the seed's; Routh–Hurwitz "
          f"{eq.routh_hurwitz}")
    ref = verdict(W0, M0, E, C0, D0, 1.0)
    assert ref is not None
    mine = np.sort_complex(ref[0])
    theirs = np.sort_complex(np.asarray(eq.eigenvalues) / scale)
    if mine.shape == theirs.shape:
        print(f"largest difference of the eigenvalues (seed units): "
              f"{np.abs(mine - theirs).max():.2e}")
    print("eigenvalues (seed units):", np.array2string(mine, precision=4))


if __name__ == "__main__":
    main()
