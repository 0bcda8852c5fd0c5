"""The ground-frame formulation the scene tests compare with: the Lagrangian in
ground-fixed coordinates, written here independently of ballbal."""

import math

import numpy as np
from scipy.integrate import solve_ivp

import ballbal

NOT_STATE = ["t", "theta", "X", "Y"]  # simulate() columns besides the state

def ground_rhs(scene, t, s, support=None):
    """Equations of motion in the ground frame: rotor centre (X, Y), absolute ball angles
    phi_i, disk angle theta(t) prescribed. From T = sum of m |v|^2 / 2 over rotor, the
    eccentric disk and the balls; V = support spring + gravity + ball springs; track
    damping on phi_i' - theta', support damping on (X', Y'). ``support(t, X, Y, X', Y')``,
    when given, is the support's force in place of the spring-damper's."""
    b = scene.balancer
    n = b.n_balls
    eta = np.asarray(b.eta)
    zb = np.broadcast_to(np.asarray(b.zeta_b, dtype=float), (n,))
    mu, dl, z, g = b.mu, b.delta, b.zeta, scene.gravity
    fb = mu * eta / dl
    X, Y, phi = s[0], s[1], s[2 : 2 + n]
    dX, dY, dphi = s[n + 2], s[n + 3], s[n + 4 :]
    # spin profile, written out again here
    w0, dw, th = b.Omega, 0.0, b.Omega * t
    if scene.ramp is not None:
        r = scene.ramp
        rate = (r.to - w0) / r.duration
        if r.start <= t < r.start + r.duration:
            u = t - r.start
            w0, dw, th = w0 + rate * u, rate, b.Omega * t + 0.5 * rate * u * u
        elif t >= r.start + r.duration:
            end = r.start + r.duration
            th = b.Omega * end + 0.5 * rate * r.duration**2 + r.to * (t - end)
            w0 = r.to
    fx = fy = 0.0
    if scene.impulse is not None:
        f = scene.impulse
        amp = f.amplitude * math.exp(-f.sharpness * (t - f.t0) ** 2)
        fx, fy = amp * math.cos(f.angle), amp * math.sin(f.angle)
    S, C = np.sin(phi), np.cos(phi)
    M = np.eye(n + 2)
    M[0, 2:] = M[2:, 0] = -fb * dl * S
    M[1, 2:] = M[2:, 1] = fb * dl * C
    M[2:, 2:] = np.diag(fb * dl**2)
    rhs = np.empty(n + 2)
    sx, sy = (-2 * z * dX - X, -2 * z * dY - Y) if support is None else support(
        t, X, Y, dX, dY)
    rhs[0] = (fx + sx + mu * (math.sin(th) * dw + math.cos(th) * w0**2)
              + np.sum(fb * dl * C * dphi**2))
    rhs[1] = (fy + sy - g - mu * (math.cos(th) * dw - math.sin(th) * w0**2)
              + np.sum(fb * dl * S * dphi**2))
    # ball springs: V = k dl^2 / 2 sum (phi_{j+1} - phi_j - 2 pi / n)^2, a ring closed
    # by ball n to ball 1, or Rezaee et al.'s (2017) chain without that last spring
    dv = np.zeros(n)
    if scene.springs:
        kd = scene.springs * dl**2
        for j in range(n if scene.spring_layout == "ring" else n - 1):
            nxt = (j + 1) % n
            sj = phi[nxt] - phi[j] - 2 * math.pi / n + (2 * math.pi if nxt == 0 else 0.0)
            dv[j] -= kd * sj
            dv[nxt] += kd * sj
    rhs[2:] = -2 * zb * mu * eta * dl * (dphi - w0) - g * fb * dl * C - dv
    return np.concatenate([s[n + 2 :], np.linalg.solve(M, rhs)])


def to_ground(scene, t, df):
    n = scene.n_balls
    th = df["theta"].to_numpy()
    x, y = df["x"].to_numpy(), df["y"].to_numpy()
    X = np.cos(th) * x - np.sin(th) * y
    Y = np.sin(th) * x + np.cos(th) * y
    phi = np.stack([th + df[f"b{i + 1}"].to_numpy() for i in range(n)])
    return X, Y, phi


FULL = ballbal.Scene(
    balancer=ballbal.Balancer(mu=0.25, zeta=0.03, zeta_b=(0.04, 0.05, 0.03), delta=20.0,
                              Omega=1.2, eta=(0.9, 1.1, 0.7)),
    springs=2e-3, ramp=ballbal.Ramp(to=1.8, start=5.0, duration=20.0), gravity=0.05,
    impulse=ballbal.Impulse(amplitude=0.5, t0=12.0, sharpness=2.0, angle=0.7),
)


def ground_gap(sc, y0, t):
    """Largest difference in X, Y and the ball angles between ballbal's rotating-frame
    simulation and the ground-frame formulation above, from the same initial state."""
    n = sc.n_balls
    df = ballbal.simulate(sc, y0, t, rtol=1e-11, atol=1e-13)
    X, Y, phi = to_ground(sc, t, df)
    w = sc.Omega  # theta(0) = 0, so the ground state differs only in the velocities
    g0 = np.concatenate([[y0[0], y0[1]], y0[2 : 2 + n],
                         [y0[n + 2] - w * y0[1], y0[n + 3] + w * y0[0]], w + y0[n + 4 :]])
    ref = solve_ivp(lambda tt, s: ground_rhs(sc, tt, s), (t[0], t[-1]), g0, t_eval=t,
                    rtol=1e-11, atol=1e-13, method="DOP853", max_step=0.05)
    assert ref.success
    gap = max(np.max(np.abs(X - ref.y[0])), np.max(np.abs(Y - ref.y[1])),
              np.max(np.abs(phi - ref.y[2 : 2 + n])))
    return gap, df


def canonical(q, equal, rotor=2):
    """Balls in track order as a tuple with b_1 in [-pi, pi); identical balls: the least
    of the cyclic relabellings round the ring."""
    q = np.asarray(q, dtype=float)
    o = rotor
    n = q.size - o
    forms = []
    for r in range(n if equal else 1):
        b = np.concatenate([q[o + r :], q[o : o + r] + 2 * math.pi])
        b = b - 2 * math.pi * math.floor((b[0] + math.pi) / (2 * math.pi))
        forms.append(tuple(np.round(np.concatenate([q[:o], b]), 5)))
    return min(forms)
