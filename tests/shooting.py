"""Independent shooting method with scipy for periodic solutions of the balancer:
unknowns are the initial state and the period, with the same phase condition as the
spec (b_r(0) = 0 for a rotating ball r, else x'(0) = 0); the monodromy matrix comes from
finite differences of the flow over one period.

The root finder is :func:`newton`, which stops on the residual, not on the step: a
solver that stops on its step (``fsolve(xtol=...)``, ``root(tol=...)``) asks for a
relative step that the flow's integration error can make unreachable, and whether it
gets there then depends on the round-off of the start, which the core computes and which
differs between CPUs (faer picks its SIMD kernels at run time). A residual bound above
the integration error is reached from any start close enough, on any machine.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.integrate import solve_ivp

from reference import rhs

#: The flow's tolerances: DOP853 at rtol 1e-11 closes a standard-map orbit (period ~25, states
#: of order 1 and angles of order 2 pi) to about 1e-10 after one period.
FLOW_RTOL, FLOW_ATOL = 1e-11, 1e-13
#: The shooting residual a converged orbit must reach: ten times the flow's error above,
#: so that it is reachable whatever the start's round-off, and small enough that the
#: period it fixes is right to ~1e-9 relative (the tests compare frequencies to 1e-8).
SHOOT_TOL = 1e-9


def flow(b, y0, T, rtol=FLOW_RTOL, atol=FLOW_ATOL):
    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0, rtol=rtol, atol=atol, method="DOP853")
    return r.y[:, -1]


def central_jacobian(F: Callable[[np.ndarray], np.ndarray], z: np.ndarray,
                     h: float) -> np.ndarray:
    """The Jacobian of ``F`` at ``z`` by central differences, column ``j`` with the step
    ``h * max(1, |z_j|)``."""
    cols = []
    for j in range(len(z)):
        e = np.zeros(len(z))
        e[j] = h * max(1.0, abs(z[j]))
        cols.append((F(z + e) - F(z - e)) / (2 * e[j]))
    return np.column_stack(cols)


def newton(F: Callable[[np.ndarray], np.ndarray], z0: Sequence[float] | np.ndarray,
           tol: float = SHOOT_TOL, h: float = 1e-6, max_iter: int = 12) -> np.ndarray:
    """A zero of ``F`` near ``z0``: Newton with a central-difference Jacobian (step ``h``:
    the differences' error is the flow's noise over ``h``, ~1e-5 relative, which keeps
    Newton's contraction near 1e-5 per step), a step halved while it does not lower the
    residual, and convergence when ``max |F| <= tol``. Raises AssertionError, with the
    residual reached, when ``max_iter`` steps do not get there."""
    z = np.array(z0, dtype=float)
    r = F(z)
    best = float(np.max(np.abs(r)))
    for _ in range(max_iter):
        if best <= tol:
            return z
        J = central_jacobian(F, z, h)
        step = np.linalg.lstsq(J, -r, rcond=None)[0]
        lam = 1.0
        while True:
            trial = z + lam * step
            rt = F(trial)
            nt = float(np.max(np.abs(rt)))
            if nt < best or lam < 1e-3:
                break
            lam /= 2
        if not nt < best:
            break
        z, r, best = trial, rt, nt
    if best <= tol:
        return z
    raise AssertionError(f"shooting did not reach its residual {tol:g}: {best:.3g}")


def shoot(b, y_guess, T_guess, winding, phase_index, tol=SHOOT_TOL):
    """Periodic orbit: y(T) = y(0) + 2 pi winding (on the angles). Returns (y0, T)."""
    n2 = len(y_guess)
    shift = np.zeros(n2)
    shift[: len(winding)] = 2 * np.pi * np.asarray(winding)
    fixed = y_guess[phase_index]
    free = [i for i in range(n2) if i != phase_index]

    def state(z):
        y0 = np.array(y_guess, dtype=float)
        y0[free] = z[:-1]
        y0[phase_index] = fixed
        return y0

    def F(z):
        y0 = state(z)
        return flow(b, y0, z[-1]) - y0 - shift

    z = newton(F, np.append(np.asarray(y_guess, dtype=float)[free], T_guess), tol=tol)
    return state(z), float(z[-1])


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
