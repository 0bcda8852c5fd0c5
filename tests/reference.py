"""Independent NumPy implementation of the spec's equations (model.md section 2) for
cross-checks with scipy. Written from the symmetric Lagrangian form, not from the core."""

from __future__ import annotations

import numpy as np


def rhs(b, t, s):
    """First-order right-hand side of the planar balancer, ball rows multiplied by m_i."""
    n = len(b.eta)
    zb = np.broadcast_to(np.asarray(b.zeta_b, dtype=float), (n,))
    q, v = s[: n + 2], s[n + 2 :]
    x, y, beta = q[0], q[1], q[2:]
    vx, vy, vb = v[0], v[1], v[2:]
    m = b.mu * np.asarray(b.eta)
    S, C = np.sin(beta), np.cos(beta)
    Om, z, dl = b.Omega, b.zeta, b.delta
    M = np.eye(n + 2)
    M[0, 2:] = M[2:, 0] = -m * S
    M[1, 2:] = M[2:, 1] = m * C
    M[2:, 2:] = np.diag(m * dl)
    w2 = (Om + vb) ** 2
    g = np.empty(n + 2)
    g[0] = (2 * z * vx - 2 * Om * vy + (1 - Om**2) * x - 2 * z * Om * y - np.sum(m * w2 * C)
            - b.mu * Om**2)
    g[1] = 2 * z * vy + 2 * Om * vx + (1 - Om**2) * y + 2 * z * Om * x - np.sum(m * w2 * S)
    g[2:] = m * (2 * Om * (C * vx + S * vy) + 2 * zb * dl * vb + Om**2 * (x * S - y * C))
    return np.concatenate([v, np.linalg.solve(M, -g)])


def rhs_many(b, t, s):
    """:func:`rhs` for a batch of states (the columns of ``s``): the same equations, the
    mass matrices solved as a stack (perturbed flows integrated together, sampled
    records)."""
    n = len(b.eta)
    k = s.shape[1]
    zb = np.broadcast_to(np.asarray(b.zeta_b, dtype=float), (n,))[:, None]
    x, y, beta = s[0], s[1], s[2 : n + 2]
    vx, vy, vb = s[n + 2], s[n + 3], s[n + 4 :]
    m = (b.mu * np.asarray(b.eta))[:, None]
    S, C = np.sin(beta), np.cos(beta)
    Om, z, dl = b.Omega, b.zeta, b.delta
    M = np.zeros((k, n + 2, n + 2))
    M[:, 0, 0] = M[:, 1, 1] = 1.0
    M[:, 0, 2:] = M[:, 2:, 0] = (-m * S).T
    M[:, 1, 2:] = M[:, 2:, 1] = (m * C).T
    idx = np.arange(2, n + 2)
    M[:, idx, idx] = (m * dl).T
    w2 = (Om + vb) ** 2
    g = np.empty((n + 2, k))
    g[0] = (2 * z * vx - 2 * Om * vy + (1 - Om**2) * x - 2 * z * Om * y
            - np.sum(m * w2 * C, axis=0) - b.mu * Om**2)
    g[1] = (2 * z * vy + 2 * Om * vx + (1 - Om**2) * y + 2 * z * Om * x
            - np.sum(m * w2 * S, axis=0))
    g[2:] = m * (2 * Om * (C * vx + S * vy) + 2 * zb * dl * vb + Om**2 * (x * S - y * C))
    acc = np.linalg.solve(M, -g.T[:, :, None])[:, :, 0].T
    return np.concatenate([s[n + 2 :], acc])


def jacobi_integral(b, s):
    """Jacobi integral T2 - T0 + V of the undamped system in the rotating frame, from the
    kinetic energy of rotor, eccentric disk and balls (fractions of the total mass)."""
    s = np.atleast_2d(s)
    n = len(b.eta)
    Om, dl, mu = b.Omega, b.delta, b.mu
    eta = np.asarray(b.eta)
    x, y, beta = s[:, 0], s[:, 1], s[:, 2 : 2 + n]
    vx, vy, vb = s[:, n + 2], s[:, n + 3], s[:, n + 4 :]
    fr_b = mu * eta / dl
    fr_r = 1.0 - mu - fr_b.sum()

    def parts(X, Y, dX, dY, frac):
        # inertial velocity (dX - Om Y, dY + Om X): T2 = |d|^2/2, T0 = Om^2 |r|^2 / 2
        return frac * 0.5 * (dX**2 + dY**2), frac * 0.5 * Om**2 * (X**2 + Y**2)

    t2, t0 = parts(x, y, vx, vy, fr_r)
    a2, a0 = parts(x + 1.0, y, vx, vy, mu)
    t2, t0 = t2 + a2, t0 + a0
    for i in range(n):
        X = x + dl * np.cos(beta[:, i])
        Y = y + dl * np.sin(beta[:, i])
        dX = vx - dl * np.sin(beta[:, i]) * vb[:, i]
        dY = vy + dl * np.cos(beta[:, i]) * vb[:, i]
        a2, a0 = parts(X, Y, dX, dY, fr_b[i])
        t2, t0 = t2 + a2, t0 + a0
    V = 0.5 * (x**2 + y**2)
    return t2 - t0 + V
