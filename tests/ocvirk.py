"""Ocvirk's short-bearing film, written here independently of ballbal: the reference the
rotor-on-bearing tests integrate Newton's law with (a plain journal of L/D ``LAM`` in the
units where the film's scale ``F0 = mu w R L^3 / c^2 = (2 lambda)^2 F_S`` is ``F_S``)."""

from __future__ import annotations

import math

import numpy as np

LAM = 0.5  # L/D
GL_X, GL_W = np.polynomial.legendre.leggauss(200)


def film_force(x: float, y: float, vx: float, vy: float, s: float = 1.0) -> np.ndarray:
    """The half-Sommerfeld film force in F_S at journal speed ``s w``: the mean over zeta
    of P = g (zeta^2 - lambda^2) / (2 H^3), g = 6 s dH/dtheta + 12 dH/dtau, positive
    where g < 0, i.e. on theta + chi in (pi, 2 pi) for g = R sin(theta + chi)."""
    a, b = 6 * s * x - 12 * vy, -6 * s * y - 12 * vx
    if a == 0.0 and b == 0.0:
        return np.zeros(2)
    chi = math.atan2(b, a)
    lo, hi = math.pi - chi, 2 * math.pi - chi
    th = 0.5 * (lo + hi) + 0.5 * (hi - lo) * GL_X
    w = 0.5 * (hi - lo) * GL_W
    h = 1 - x * np.cos(th) - y * np.sin(th)
    g = a * np.sin(th) + b * np.cos(th)
    pbar = LAM**2 * np.maximum(-g, 0.0) / (3 * h**3)
    return -np.array([np.sum(w * pbar * np.cos(th)), np.sum(w * pbar * np.sin(th))])
