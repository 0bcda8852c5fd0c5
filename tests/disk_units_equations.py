"""Seed 003's two-ball balancer in its own equations, written independently of ballbal.

The seed ([EccentricRotorABB]) writes the disk of mass M on a spring K and damper C with an
imbalance M eps and two balls of mass m on a track of radius R with damping D, in units of
the disk alone: lengths over R, time over 1 / omega_n = sqrt(M / K), and the parameters
``m0 = m / M``, ``omega0 = omega / omega_n``, ``e = eps / R``, ``C0 = C / (2 sqrt(K M))``,
``D0 = D / (m R^2 omega_n)``. Its eq. (8) is the rotating-frame form, state
``q = (x, y, phi1, phi2)``:

    M(q) q'' + f(q, q') = 0,
    M = [[1 + 2 m0, 0, -m0 s1, -m0 s2], [0, 1 + 2 m0, m0 c1, m0 c2],
         [-m0 s1, m0 c1, m0, 0], [-m0 s2, m0 c2, 0, m0]]     (si, ci of phi_i)

with the rows of ``f`` as printed, except that the seed prints the phi2 row with
``-2 Omega x'`` where the phi1 row (and the Lagrangian, eq. (3)) has ``+2 Omega x'``:
``sign_phi2`` chooses (+1: as eq. (3) gives, -1: as printed).

:func:`inertial_rhs` integrates eqs. (4)-(6) in the fixed frame instead, with the sign of
the ``Y0'' cos`` term of eq. (6) as a choice (+1: from eq. (3); -1: as eq. (6) prints it).
"""

from __future__ import annotations

import math

import numpy as np


def residual_terms(q: np.ndarray, v: np.ndarray, w0: float, m0: float, e: float, c0: float,
                   d0: float, sign_phi2: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``(M(q), f(q, q'))`` of the seed's eq. (8)."""
    x, y, p1, p2 = q
    dx, dy, dp1, dp2 = v
    s1, c1, s2, c2 = math.sin(p1), math.cos(p1), math.sin(p2), math.cos(p2)
    a = 1 + 2 * m0
    mass = np.array([[a, 0, -m0 * s1, -m0 * s2], [0, a, m0 * c1, m0 * c2],
                     [-m0 * s1, m0 * c1, m0, 0], [-m0 * s2, m0 * c2, 0, m0]])
    k = w0 * w0 * a - 1
    f = np.array([
        -e * w0 * w0 + 2 * c0 * dx - 2 * w0 * a * dy - k * x - 2 * c0 * w0 * y
        - m0 * ((w0 + dp1) ** 2 * c1 + (w0 + dp2) ** 2 * c2),
        2 * w0 * a * dx + 2 * c0 * dy + 2 * c0 * w0 * x - k * y
        - m0 * ((w0 + dp1) ** 2 * s1 + (w0 + dp2) ** 2 * s2),
        m0 * d0 * dp1 + m0 * (w0 * w0 * x + 2 * w0 * dy) * s1
        + m0 * (2 * w0 * dx - w0 * w0 * y) * c1,
        m0 * d0 * dp2 + m0 * (w0 * w0 * x + 2 * w0 * dy) * s2
        + m0 * (sign_phi2 * 2 * w0 * dx - w0 * w0 * y) * c2,
    ])
    return mass, f


def rotating_rhs(w0: float, m0: float, e: float, c0: float, d0: float,
                 sign_phi2: float = 1.0):  # type: ignore[no-untyped-def]
    """``dz/dt`` of eq. (8), ``z = (q, q')``, for scipy's ``solve_ivp``."""

    def rhs(_t: float, z: np.ndarray) -> np.ndarray:
        mass, f = residual_terms(z[:4], z[4:], w0, m0, e, c0, d0, sign_phi2)
        return np.concatenate([z[4:], np.linalg.solve(mass, -f)])

    return rhs


def inertial_rhs(w0: float, m0: float, e: float, c0: float, d0: float,
                 sign_eq6: float = 1.0):  # type: ignore[no-untyped-def]
    """``dz/dt`` of eqs. (4)-(6) in the fixed frame, ``z = (X0, Y0, phi1, phi2, ...')``:
    with ``th_i = omega0 t + phi_i``,

    (1 + 2 m0) X'' - m0 sum phi_i'' sin th_i = e w0^2 cos w0 t - 2 C0 X' - X
                                               + m0 sum (w0 + phi_i')^2 cos th_i,
    (1 + 2 m0) Y'' + m0 sum phi_i'' cos th_i = e w0^2 sin w0 t - 2 C0 Y' - Y
                                               + m0 sum (w0 + phi_i')^2 sin th_i,
    -X'' sin th_i + sign_eq6 Y'' cos th_i + phi_i'' = -D0 phi_i'.
    """
    a = 1 + 2 * m0

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        X, Y, _, _, dX, dY, dp1, dp2 = z
        th = w0 * t + z[2:4]
        s, c = np.sin(th), np.cos(th)
        dp = np.array([dp1, dp2])
        mass = np.array([[a, 0, -m0 * s[0], -m0 * s[1]], [0, a, m0 * c[0], m0 * c[1]],
                         [-s[0], sign_eq6 * c[0], 1, 0], [-s[1], sign_eq6 * c[1], 0, 1]])
        b = np.array([
            e * w0 * w0 * math.cos(w0 * t) - 2 * c0 * dX - X + m0 * np.sum((w0 + dp) ** 2 * c),
            e * w0 * w0 * math.sin(w0 * t) - 2 * c0 * dY - Y + m0 * np.sum((w0 + dp) ** 2 * s),
            -d0 * dp1, -d0 * dp2])
        return np.concatenate([z[4:], np.linalg.solve(mass, b)])

    return rhs


def perfect_balance(m0: float, e: float) -> np.ndarray:
    """Eq. (9): ``x = y = 0``, ``phi1 = arccos(-e / (2 m0)) = -phi2``."""
    p = math.acos(-e / (2 * m0))
    return np.array([0.0, 0.0, p, -p])


def linearised(q0: np.ndarray, w0: float, m0: float, e: float, c0: float, d0: float,
               sign_phi2: float = 1.0, h: float = 1e-6) -> tuple[np.ndarray, ...]:
    """``(M, C, K)`` at the equilibrium ``q0``: central differences of ``f``."""
    z = np.zeros(4)
    mass, _ = residual_terms(q0, z, w0, m0, e, c0, d0, sign_phi2)
    cmat, kmat = np.zeros((4, 4)), np.zeros((4, 4))
    for j in range(4):
        d = np.zeros(4)
        d[j] = h
        kmat[:, j] = (residual_terms(q0 + d, z, w0, m0, e, c0, d0, sign_phi2)[1]
                      - residual_terms(q0 - d, z, w0, m0, e, c0, d0, sign_phi2)[1]) / (2 * h)
        cmat[:, j] = (residual_terms(q0, d, w0, m0, e, c0, d0, sign_phi2)[1]
                      - residual_terms(q0, -d, w0, m0, e, c0, d0, sign_phi2)[1]) / (2 * h)
    return mass, cmat, kmat


def char_poly(mass: np.ndarray, cmat: np.ndarray, kmat: np.ndarray) -> np.ndarray:
    """Coefficients (highest power first) of ``det(lambda^2 M + lambda C + K)``, degree 8:
    the determinant sampled on a circle of 16 points and transformed back (a DFT)."""
    n, r = 16, 1.0
    lam = r * np.exp(2j * np.pi * np.arange(n) / n)
    vals = np.array([np.linalg.det(x * x * mass + x * cmat + kmat) for x in lam])
    c = np.fft.fft(vals) / n / r ** np.arange(n)
    assert np.abs(c[9:]).max() < 1e-9 * np.abs(c).max()
    return np.real(c[:9])[::-1]


def hurwitz_stable(coeffs: np.ndarray) -> bool:
    """Routh–Hurwitz: all leading principal minors of the Hurwitz matrix of
    ``a0 s^n + ... + an`` (``a0 > 0``) positive."""
    a = np.asarray(coeffs, dtype=float)
    if a[0] < 0:
        a = -a
    n = len(a) - 1
    hm = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            k = 2 * j - i + 1
            if 0 <= k <= n:
                hm[i, j] = a[k]
    return bool(np.all(a > 0) and all(np.linalg.det(hm[:k, :k]) > 0 for k in range(1, n + 1)))
