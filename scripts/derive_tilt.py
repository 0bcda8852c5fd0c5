"""Derive the tilting-rotor equations from their Lagrangian and write them as Rust.

Run from the repository root: ``python scripts/derive_tilt.py`` (needs sympy). It
rewrites ``rust/core/src/model/tilt_terms.rs``; the tests check the result against a
closed-form whirl spectrum, the planar model and the energy integral, and
``tests/test_tilt.py`` reruns this script when sympy is installed to check the
committed file is what the derivation gives.

Coordinates (nondimensional as in ``model.md``: lengths over ``e``, time over
``1/w_n``, energies over ``M e^2 w_n^2``), in the frame turning with the disk by
``theta(t)``, ``theta' = Om``, ``Om' = dOm``:

* ``x, y``: the disk centre C (shaft station under the disk);
* ``A, B``: tilts, scaled ``A = delta alpha``, ``B = delta beta`` (the rim's axial
  displacement over ``e``), Euler angles of Rezaee et al. (2017): turn ``alpha`` about the
  rotating x axis, then ``beta`` about the new y axis;
* ``phi``: a ball's angle in the disk plane from the mass-centre direction.

Lagrangian ``L = T - V`` and Rayleigh function ``R``; the residual of row k is
``d/dt dL/dq_k' - dL/dq_k + dR/dq_k'``. Rotor part: hub mass ``mh`` at C, disk mass
``mu`` at G = C + E1 (body x axis), disk inertia about G ``J_t, J_z`` (over
``M r_t^2``: ``jt, jz``, so over ``M e^2`` they are ``jt delta^2``), shaft potential
``kc (x s_x + y s_y) + kt (s_x^2 + s_y^2)/2`` with ``s = delta (E3_x, E3_y)`` the scaled
slope of the disk normal, gravity ``g`` along ground ``-Y`` (spin axis horizontal) and
tilt damping on the slope's ground rate (coefficient ``cr``). The support's
translational spring and damper, ``(x^2 + y^2)/2`` and ``zeta |C'|^2`` (C's ground
velocity), are not here: the support is a component of its own
(``rust/core/src/model/components/support.rs``) that adds them to rows x, y. One ball
(its mass factored out, so its own row is the ball's equation over its mass, as in the
planar model): point mass ``1/delta`` at ``C + delta (cos phi E1 + sin phi E2)``,
track drag ``zb delta phi'^2``.
"""

from __future__ import annotations

import pathlib
import sys

import sympy as sp
from sympy.printing.rust import RustCodePrinter

OUT = pathlib.Path(__file__).resolve().parents[1] / "rust/core/src/model/tilt_terms.rs"

x, y, A, B, phi = sp.symbols("x y A B phi")
vx, vy, vA, vB, vphi = sp.symbols("vx vy vA vB vphi")
ax, ay, aA, aB, aphi = sp.symbols("ax ay aA aB aphi")
om, dom, th = sp.symbols("om dom th")
mh, mu, dl, idl, jt, jz, kc, kt, cr, g, zb = sp.symbols("mh mu dl idl jt jz kc kt cr g zb")

Q = [x, y, A, B, phi]
V = [vx, vy, vA, vB, vphi]
ACC = [ax, ay, aA, aB, aphi]


def ddt(f):
    """Total time derivative along the motion (theta enters only through gravity)."""
    out = dom * sp.diff(f, om) + om * sp.diff(f, th)
    for q, v, a in zip(Q, V, ACC, strict=True):
        out += sp.diff(f, q) * v + sp.diff(f, v) * a
    return out


al, be = A * idl, B * idl
ca, sa, cb, sb = sp.cos(al), sp.sin(al), sp.cos(be), sp.sin(be)
T_al = sp.Matrix([[1, 0, 0], [0, ca, sa], [0, -sa, ca]])
T_be = sp.Matrix([[cb, 0, -sb], [0, 1, 0], [sb, 0, cb]])
# body axes in rotating coordinates: columns of (T_be T_al)^T
body = (T_be * T_al).T
E1, E2, E3 = body[:, 0], body[:, 1], body[:, 2]
C = sp.Matrix([x, y, 0])
ez = sp.Matrix([0, 0, 1])


def ground_velocity(p):
    """Ground velocity of a point, in rotating components: p' + Om e_z x p."""
    return sp.Matrix([ddt(c) for c in p]) + om * ez.cross(p)


def ground_y(p):
    """Ground Y of a point given in rotating coordinates (rotate back by theta)."""
    return sp.sin(th) * p[0] + sp.cos(th) * p[1]


# Disk angular velocity in body axes: [w]x = R R'^T with R = T_be T_al T_th.
R = T_be * T_al
Rdot = R.applyfunc(ddt)
W = R * Rdot.T
# plus the frame's own turn om about the rotating z axis, seen in body axes
w_body = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]]) + R * (om * ez)

G = C + E1
vC, vG = ground_velocity(C), ground_velocity(G)
T_rot = (mh * vC.dot(vC) + mu * vG.dot(vG)) / 2 + dl**2 * (
    jt * (w_body[0] ** 2 + w_body[1] ** 2) + jz * w_body[2] ** 2
) / 2
s = sp.Matrix([dl * E3[0], dl * E3[1], 0])
V_rot = (
    kc * (x * s[0] + y * s[1])
    + kt * (s[0] ** 2 + s[1] ** 2) / 2
    + g * (mh * ground_y(C) + mu * ground_y(G))
)
s_ground_rate = ground_velocity(s)
R_rot = cr * (s_ground_rate[0] ** 2 + s_ground_rate[1] ** 2) / 2

P = C + dl * (sp.cos(phi) * E1 + sp.sin(phi) * E2)
vP = ground_velocity(P)
T_ball = vP.dot(vP) / (2 * dl)
V_ball = g * ground_y(P) / dl
R_ball = zb * dl * vphi**2


def euler_lagrange(T, Vp, Rf, coords):
    L = T - Vp
    rows = []
    for q, v in coords:
        rows.append(ddt(sp.diff(L, v)) - sp.diff(L, q) + sp.diff(Rf, v))
    return rows


def jacobians(rows, qs, vs, accs):
    K = [sp.diff(r, q) for r in rows for q in qs]
    Cm = [sp.diff(r, v) for r in rows for v in vs]
    M = [sp.diff(r, a) for r in rows for a in accs]
    return K, Cm, M


class _Printer(RustCodePrinter):
    """Rust printer whose integer literals are floats (``2*zeta`` does not compile)."""

    def _print_Integer(self, expr, _type=False):
        return f"{int(expr)}.0"

    def _print_Pow(self, expr):
        base, exp = expr.base, expr.exp
        b = self._print(base)
        if not base.is_Symbol:
            b = f"({b})"
        if exp.is_Integer:
            return f"{b}.recip()" if exp == -1 else f"{b}.powi({int(exp)})"
        if exp == sp.S.Half:
            return f"{b}.sqrt()"
        return f"{b}.powf({self._print(exp)})"


def code(e):
    return _Printer().doprint(e)


def rust_fn(name, doc, args, unpack, outputs, inline=False):
    """One Rust function writing each (slice, expressions) output after common
    subexpression elimination over all of them. ``inline``: always inlined, so that a
    caller looping over the balls hoists the trigonometry of the tilts out of the loop."""
    flat = [e for _, exprs in outputs for e in exprs]
    reps, reduced = sp.cse(flat, symbols=sp.numbered_symbols("t"), optimizations="basic")
    lines = [f"/// {doc}", "#[allow(clippy::all, unused_variables, non_snake_case)]"]
    if inline:
        lines.append("#[inline(always)]")
    lines.append(f"pub fn {name}({args}) {{")
    lines += [f"    {u}" for u in unpack]
    for sym, e in reps:
        lines.append(f"    let {sym} = {code(e)};")
    i = 0
    for slot, exprs in outputs:
        for j in range(len(exprs)):
            e = reduced[i]
            i += 1
            if e != 0:
                lines.append(f"    {slot}[{j}] = {code(e)};")
            else:
                lines.append(f"    {slot}[{j}] = 0.0;")
    lines.append("}")
    return "\n".join(lines)


def main() -> int:
    rq, rv, ra = [x, y, A, B], [vx, vy, vA, vB], [ax, ay, aA, aB]
    rotor = euler_lagrange(T_rot, V_rot, R_rot, list(zip(rq, rv, strict=True)))
    ball = euler_lagrange(T_ball, V_ball, R_ball, list(zip(Q, V, strict=True)))
    rk, rc, rm = jacobians(rotor, rq, rv, ra)
    bk, bc, bm = jacobians(ball, Q, V, ACC)
    head = '''//! Generated by `scripts/derive_tilt.py` from the tilting rotor's Lagrangian; do not
//! edit by hand (rerun the script). See that script for the coordinates and terms.

/// Rotor parameters: hub mass, disk mass, delta, 1/delta, inertias, shaft, tilt damping,
/// gravity (the support's spring and damper are a component of their own).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorConsts {
    pub mh: f64,
    pub mu: f64,
    pub dl: f64,
    pub idl: f64,
    pub jt: f64,
    pub jz: f64,
    pub kc: f64,
    pub kt: f64,
    pub cr: f64,
    pub g: f64,
}
'''
    p_unpack = [
        "let RotorConsts { mh, mu, dl, idl, jt, jz, kc, kt, cr, g } = *p;",
        "let (om, dom, th) = spin;",
    ]
    r_unpack = p_unpack + [
        "let (x, y, A, B) = (q[0], q[1], q[2], q[3]);",
        "let (vx, vy, vA, vB) = (v[0], v[1], v[2], v[3]);",
        "let (ax, ay, aA, aB) = (a[0], a[1], a[2], a[3]);",
    ]
    b_unpack = [
        "let (dl, idl, zb, g) = (p.dl, p.idl, zb, p.g);",
        "let (om, dom, th) = spin;",
        "let (x, y, A, B, phi) = (q[0], q[1], q[2], q[3], q[4]);",
        "let (vx, vy, vA, vB, vphi) = (v[0], v[1], v[2], v[3], v[4]);",
        "let (ax, ay, aA, aB, aphi) = (a[0], a[1], a[2], a[3], a[4]);",
    ]
    r_args = "p: &RotorConsts, spin: (f64, f64, f64), q: &[f64], v: &[f64], a: &[f64]"
    b_args = (
        "p: &RotorConsts, zb: f64, spin: (f64, f64, f64), q: &[f64; 5], v: &[f64; 5], "
        "a: &[f64; 5]"
    )
    parts = [
        head,
        rust_fn(
            "rotor_residual",
            "Rows x, y, A, B of the hub, disk and shaft.",
            r_args + ", out: &mut [f64]",
            r_unpack,
            [("out", rotor)],
        ),
        rust_fn(
            "rotor_jacobians",
            "Row-major 4 x 4 `dF/dq`, `dF/dv`, `dF/da` of [`rotor_residual`].",
            r_args + ", k: &mut [f64; 16], c: &mut [f64; 16], m: &mut [f64; 16]",
            r_unpack,
            [("k", rk), ("c", rc), ("m", rm)],
        ),
        rust_fn(
            "rotor_mass",
            "The `m` of [`rotor_jacobians`] alone (it depends on `q` only): what a "
            "right-hand side evaluation needs.",
            "p: &RotorConsts, q: &[f64], m: &mut [f64; 16]",
            p_unpack[:1] + ["let (x, y, A, B) = (q[0], q[1], q[2], q[3]);"],
            [("m", rm)],
            inline=True,
        ),
        rust_fn(
            "ball_residual",
            "One ball of unit mass factor: rows x, y, A, B (to be scaled by the ball's "
            "mass) and its own row (already over its mass); `q = (x, y, A, B, phi)`.",
            b_args + ", out: &mut [f64; 5]",
            b_unpack,
            [("out", ball)],
        ),
        rust_fn(
            "ball_jacobians",
            "Row-major 5 x 5 Jacobians of [`ball_residual`].",
            b_args + ", k: &mut [f64; 25], c: &mut [f64; 25], m: &mut [f64; 25]",
            b_unpack,
            [("k", bk), ("c", bc), ("m", bm)],
        ),
        rust_fn(
            "ball_mass",
            "The `m` of [`ball_jacobians`] alone (it depends on `q` only).",
            "p: &RotorConsts, q: &[f64; 5], m: &mut [f64; 25]",
            ["let (dl, idl) = (p.dl, p.idl);",
             "let (x, y, A, B, phi) = (q[0], q[1], q[2], q[3], q[4]);"],
            [("m", bm)],
            inline=True,
        ),
    ]
    text = "\n\n".join(parts) + "\n"
    if "--check" in sys.argv:
        same = OUT.read_text() == text
        print("tilt_terms.rs is", "up to date" if same else "STALE")
        return 0 if same else 1
    OUT.write_text(text)
    # Rezaee et al. (2017) eq. (7) as a check on the kinematics (unscaled angles, frame rate om)
    a_, b_ = sp.symbols("alpha beta")
    sub = {A: a_ * dl, B: b_ * dl, vA: sp.Symbol("da") * dl, vB: sp.Symbol("db") * dl}
    print([sp.simplify(c.subs(sub)) for c in w_body])
    return 0


if __name__ == "__main__":
    sys.exit(main())
