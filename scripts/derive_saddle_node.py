"""Derives the saddle-node (fold) curve of the balls-together equilibria of the planar
two-ball balancer (model.md section 2) symbolically, as tests/test_eq_continuation.py
uses it: with b_1 = b_2 = b at rest the static equations are linear in (x, y); solved,
the balls' equation reduces to A sin b + Omega cos b = -2 eta Omega,
A = (1 - Omega^2) / (2 zeta), which has a solution b iff A^2 + Omega^2 >= 4 eta^2 Omega^2;
two together equilibria merge (a fold) on equality:

    (1 - Omega^2)^2 = 4 zeta^2 Omega^2 (4 eta^2 - 1)

independent of mu, delta and zeta_b. Run: python scripts/derive_saddle_node.py
"""

import sympy as sp

x, y, b, mu, eta, zeta, Om = sp.symbols("x y b mu eta zeta Omega", real=True)
m = mu * eta
s, c = sp.sin(b), sp.cos(b)
# static residuals (velocities and accelerations zero), both balls at b
Fx = (1 - Om**2) * x - 2 * zeta * Om * y - 2 * m * Om**2 * c - mu * Om**2
Fy = 2 * zeta * Om * x + (1 - Om**2) * y - 2 * m * Om**2 * s
Fb = m * Om**2 * (x * s - y * c)
sol = sp.solve([Fx, Fy], [x, y], dict=True)[0]
g = sp.simplify(Fb.subs(sol) / (m * Om**2))
# g = 0  <=>  A sin b + Omega cos b + 2 eta Omega = 0 (up to a positive factor)
A = (1 - Om**2) / (2 * zeta)
target = A * s + Om * c + 2 * eta * Om
ratio = sp.simplify(sp.numer(sp.together(g)) / sp.numer(sp.together(target)))
print("balls' equation / (A sin b + Omega cos b + 2 eta Omega) =", ratio)
assert sp.diff(ratio, b) == 0, "not the together equation"
# fold: g and dg/db vanish together: eliminate b with sin^2 + cos^2 = 1
S, C = sp.symbols("S C", real=True)
eqs = [A * S + Om * C + 2 * eta * Om, A * C - Om * S]
sc = sp.solve(eqs, [S, C], dict=True)[0]
fold = sp.factor(sp.numer(sp.together(sc[S] ** 2 + sc[C] ** 2 - 1)))
print("fold condition:", fold, "= 0")
closed = (1 - Om**2) ** 2 - 4 * zeta**2 * Om**2 * (4 * eta**2 - 1)
# one factor, (1 - Omega^2)^2 + 4 zeta^2 Omega^2 (A^2 + Omega^2 up to 4 zeta^2), is positive
positive = (1 - Om**2) ** 2 + 4 * zeta**2 * Om**2
assert sp.simplify(fold / (closed * positive)).is_constant(), "closed form mismatch"
print("saddle-node curve: (1 - Omega^2)^2 = 4 zeta^2 Omega^2 (4 eta^2 - 1)")
print("eta(Omega) =", sp.sqrt(sp.Rational(1, 4) + (1 - Om**2) ** 2 / (16 * zeta**2 * Om**2)))
