"""Checks the scaling of the journal-bearing support (bearing.md section 4) symbolically.

Lab quantities: rotor mass ``M``, unbalance eccentricity ``e``, spin ``w``, bearing radius
``R``, length ``L``, radial clearance ``c``, oil viscosity ``mu``. The film engine's force
is ``F_S F(X, V)`` with ``F_S = mu w L R^3 / c^2``, ``X`` the journal position over ``c``
and ``V`` its velocity over ``c w``, both in the fixed frame. ballbal's units on a bearing:
lengths over ``e``, time over ``1 / w_ref`` with ``w_ref = C_S / M``, ``C_S = mu L R^3 /
c^3``, forces over ``M e w_ref^2``; ``Omega = w / w_ref``, ``rho = e / c``.

Checked here, for an arbitrary film function ``F``:

1. the ground velocity of the centre, written in the disk's components, is
   ``q' + Omega J q`` (``J`` the quarter turn), so ``V = rho R(theta) (q' + Omega J q) /
   Omega``;
2. the film force over ``M e w_ref^2`` is ``(Omega / rho) F(rho q_fixed, rho
   q_fixed' / Omega)``;
3. with the isotropic linear film ``F = -k X - c_f V`` the support is the spring–damper
   ``Omega k q + c_f q_ground'``: stiffness 1 needs ``k = 1 / Omega``.

Run: ``python scripts/derive_bearing_support.py`` (prints ``ok``).
"""

from __future__ import annotations

import sympy as sp


def main() -> None:
    t, M, e, w, R, L, c, mu = sp.symbols("t M e w R L c mu", positive=True)
    ts = sp.symbols("t_s", positive=True)  # nondimensional time w_ref t
    x, y = sp.Function("x"), sp.Function("y")
    cs = mu * L * R**3 / c**3
    w_ref = cs / M
    omega = w / w_ref
    rho = e / c
    th = omega * ts  # disk angle in nondimensional time (= w t)

    # 1. ground velocity in the disk's components
    rot = sp.Matrix([[sp.cos(th), -sp.sin(th)], [sp.sin(th), sp.cos(th)]])
    jq = sp.Matrix([[0, -1], [1, 0]])
    q = sp.Matrix([x(ts), y(ts)])
    ground = rot * q
    lhs = rot.T * ground.diff(ts)
    rhs = q.diff(ts) + omega * jq * q
    assert sp.simplify(lhs - rhs) == sp.zeros(2, 1)

    # 2. physical force -> ballbal units. Position X = e (R q) / c; velocity in c w units:
    # d(e R q)/dt = e w_ref d(R q)/dt_s, over c w.
    X = e * ground / c
    V = e * w_ref * ground.diff(ts) / (c * w)
    assert sp.simplify(X - rho * ground) == sp.zeros(2, 1)
    assert sp.simplify(V - rho * ground.diff(ts) / omega) == sp.zeros(2, 1)
    f_s = mu * w * L * R**3 / c**2
    unit = M * e * w_ref**2
    assert sp.simplify(f_s / unit - omega / rho) == 0

    # 3. the linear film is the spring-damper
    k, cf = sp.symbols("k c_f", positive=True)
    force = (omega / rho) * (-k * X - cf * V)
    support = -(omega * k * ground + cf * ground.diff(ts))
    assert sp.simplify(force - support) == sp.zeros(2, 1)
    print("ok")


if __name__ == "__main__":
    main()
