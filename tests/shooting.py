"""Independent shooting method with scipy for periodic solutions of the balancer:
unknowns are the initial state and the period, with the same phase condition as the
spec (b_r(0) = 0 for a rotating ball r, else x'(0) = 0); the monodromy matrix comes from
finite differences of the flow over one period."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from reference import rhs


def flow(b, y0, T, rtol=1e-11, atol=1e-13):
    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0, rtol=rtol, atol=atol, method="DOP853")
    return r.y[:, -1]


def shoot(b, y_guess, T_guess, winding, phase_index):
    """Periodic orbit: y(T) = y(0) + 2 pi winding (on the angles). Returns (y0, T)."""
    n2 = len(y_guess)
    shift = np.zeros(n2)
    shift[: len(winding)] = 2 * np.pi * np.asarray(winding)
    fixed = y_guess[phase_index]
    free = [i for i in range(n2) if i != phase_index]

    def F(z):
        y0 = y_guess.copy()
        y0[free] = z[:-1]
        y0[phase_index] = fixed
        return flow(b, y0, z[-1]) - y0 - shift

    z0 = np.append(y_guess[free], T_guess)
    z, info, ok, msg = fsolve(F, z0, full_output=True, xtol=1e-12)
    assert ok == 1, msg
    y0 = y_guess.copy()
    y0[free] = z[:-1]
    return y0, z[-1]


def match_error(a, ref) -> float:
    """Largest distance between paired multipliers (each reference one with the nearest
    unused one), relative to the larger of 1 and the reference's modulus."""
    left = list(a)
    worst = 0.0
    for r in sorted(ref, key=lambda z: -abs(z)):
        k = int(np.argmin([abs(z - r) for z in left]))
        worst = max(worst, abs(left.pop(k) - r) / max(1.0, abs(r)))
    return worst


def monodromy_multipliers(b, y0, T, h=1e-6):
    n2 = len(y0)
    M = np.empty((n2, n2))
    for j in range(n2):
        e = np.zeros(n2)
        e[j] = h
        M[:, j] = (flow(b, y0 + e, T) - flow(b, y0 - e, T)) / (2 * h)
    ev = np.linalg.eigvals(M)
    return ev[np.argsort(-np.abs(ev))]
