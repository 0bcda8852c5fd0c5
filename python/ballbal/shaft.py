"""A ball(-spring) balancer on a flexible shaft in the units of [Rezaee2017].

Rezaee et al. (2017) carry a disk (mass ``M``, mass centre at ``eps`` from the shaft,
transverse and polar inertia ``J_t, J_z``) on a massless, simply supported shaft of
bending stiffness ``E I`` and length ``L``, the disk at ``a`` from one bearing and ``b = L -
a`` from the other; ``n`` balls of mass ``m`` roll on a track of radius ``R`` with viscous
drag torque ``D phi'``, optionally joined by circumferential springs ``k_d R^2`` (the
chain of their eq. 16); ``c_t`` damps the disk centre, ``c_r`` its tilt. Their eq. (36)
makes these nondimensional::

    omega0 = sqrt(3 E I L / (M a^2 b^2))     (the shaft's stiffness at the disk, tilt free,
                                             over the disk's mass)
    omega_bar = omega / omega0,  m_bar = m / M,  eps_bar = eps / R,
    lam = D / (m R^2 omega0),  zeta_t = c_t / 4 sqrt(L^3 / (3 M E I)),
    zeta_r = c_r / 4 sqrt(L / (J_t E I)).

ballbal's time unit is ``w_n = sqrt(k / M_tot)`` with ``k = 3 E I (1/a^3 + 1/b^3)`` the
shaft's stiffness at the disk with the tilt held (:class:`~ballbal.Tilt`: beam theory
then gives the coupling and tilt stiffness) and ``M_tot = M (1 + n m_bar)``; its lengths
are over ``eps``. With ``s = sqrt((1 + n m_bar) a b / (a^2 - a b + b^2))`` (``w_n`` is
``omega0 / s``)::

    Omega = s omega_bar,  mu = 1 / (1 + n m_bar),  eta = m_bar / eps_bar,
    delta = 1 / eps_bar,  zeta_b = s lam / 2,
    zeta = 2 zeta_t (a b / L^2) sqrt(a b / ((a^2 - a b + b^2) (1 + n m_bar))),
    tilt.zeta_r = 2 zeta_r sqrt(a b) / (sqrt(3) L),  springs = k_d / k,
    tilt.a, tilt.b = a / R, b / R;  tilt.j_t, tilt.j_z = J / (M_tot R^2).

At mid-span (``a = b``) ``k`` is the tilt-free stiffness, ``s = sqrt(1 + n m_bar)``, and
without the tilt this is [EccentricRotorABB]'s :func:`~ballbal.from_disk_units` with
``C0 = zeta_t / 2`` and ``D0 = lam``.

One difference in the physics, not the units: the paper's Rayleigh function damps the
rates of its Euler angles, which are taken after the spin rotation (so ``c_r`` turns
with the disk, as internal damping would), while ballbal's ``zeta_r`` damps the disk
normal's rate in the ground frame. The two agree without spin; with spin the paper's
tilt damping is destabilising above the tilt critical speed and ballbal's is not.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np
import polars as pl

from . import _check
from .exceptions import ParameterError
from .model import Balancer
from .scene import Scene, Tilt


@dataclass(frozen=True)
class ShaftUnits:
    """A balancer on a flexible shaft in [Rezaee2017]'s parameters (its eq. 36).

    ``omega_bar``: spin over ``omega0`` (>= 0); ``m_bar``: each ball's mass over the
    disk's (> 0); ``eps_bar``: the disk's eccentricity over the track radius (> 0);
    ``lam``: track damping ``D / (m R^2 omega0)`` (>= 0); ``zeta_t``, ``zeta_r``:
    translational and tilt damping as eq. 36 defines them (>= 0); ``a``, ``b``: the
    disk's distances from the bearings over the track radius ``R`` (> 0); ``j_t``,
    ``j_z``: the disk's transverse and polar moments of inertia over ``M R^2`` (``M`` the
    disk's mass; ``0 <= j_z <= 2 j_t``), both None for a disk that does not tilt (the
    Jeffcott rotor the paper reduces to for its fig. 3; then only ``a / b`` matters);
    ``k_d``: the ball springs' stiffness over ``M omega0^2`` (>= 0; the paper's chain of
    ``n - 1`` springs); ``n``: number of equal balls (1 to
    :data:`~ballbal._check.MAX_BALLS`). Convert with :attr:`scene` (the module
    documentation gives the formulas).
    """

    omega_bar: float
    m_bar: float
    eps_bar: float
    lam: float
    zeta_t: float
    zeta_r: float = 0.0
    a: float = 1.0
    b: float = 1.0
    j_t: float | None = None
    j_z: float | None = None
    k_d: float = 0.0
    n: int = 2

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "n":
                v = _check.integer("n", v, 1, _check.MAX_BALLS)
            elif f.name in ("j_t", "j_z"):
                if v is not None:
                    v = _check.real(f.name, v, 0.0, lo_open=f.name == "j_t", finite=True)
            else:
                positive = f.name in ("m_bar", "eps_bar", "a", "b")
                v = _check.real(f.name, v, 0.0, lo_open=positive, finite=True)
            object.__setattr__(self, f.name, v)
        if (self.j_t is None) != (self.j_z is None):
            raise ParameterError("j_z", "j_t and j_z are given together (a tilting disk) "
                                 "or both None (a flat disk)")
        if self.j_t is not None and self.j_z is not None and self.j_z > 2 * self.j_t:
            raise ParameterError("j_z", f"must be in [0, 2 j_t] = [0, {2 * self.j_t}] (a "
                                 f"rigid body's polar moment is at most the sum of the "
                                 f"other two), got {self.j_z}", allowed=f"[0, {2 * self.j_t}]")
        if self.k_d > 0 and self.n < 2:
            raise ParameterError("k_d", "ball springs need at least 2 balls")

    @property
    def scale(self) -> float:
        """``s``: ballbal's ``Omega`` over ``omega_bar`` (``omega0 / w_n``); ballbal's
        rates and eigenvalues times ``1 / s`` are in units of ``omega0``."""
        a, b = self.a, self.b
        return math.sqrt((1 + self.n * self.m_bar) * a * b / (a * a - a * b + b * b))

    @property
    def scene(self) -> Scene:
        """The same machine in ballbal's parameters (the module documentation's formulas)."""
        a, b, n = self.a, self.b, self.n
        length = a + b
        total = 1 + n * self.m_bar  # M_tot / M
        q = a * a - a * b + b * b
        zeta = 2 * self.zeta_t * (a * b / length**2) * math.sqrt(a * b / (q * total))
        bal = Balancer(mu=1 / total, zeta=zeta, zeta_b=self.scale * self.lam / 2,
                       delta=1 / self.eps_bar, Omega=self.scale * self.omega_bar,
                       eta=(self.m_bar / self.eps_bar,) * n)
        tilt = None
        if self.j_t is not None and self.j_z is not None:
            tilt = Tilt(a=a, b=b, j_t=self.j_t / total, j_z=self.j_z / total,
                        zeta_r=2 * self.zeta_r * math.sqrt(a * b) / (math.sqrt(3) * length))
        # k_d over M omega0^2 = k0, ballbal's over k = k0 q / (a b)
        return Scene(balancer=bal, tilt=tilt, springs=self.k_d * a * b / q,
                     spring_layout="chain")

    def balance_map(
        self,
        omega_bar: Sequence[float] | np.ndarray | tuple[float, float, float] | str,
        lam: Sequence[float] | np.ndarray | tuple[float, float, float] | str | None = None,
    ) -> pl.DataFrame:
        """The balanced state's stability (:func:`ballbal.balance_map`) over the paper's
        axes: spins ``omega_bar`` and, if given, track dampings ``lam`` (else this one's),
        the other parameters this one's (the paper's figs 3 and 4; for its fig. 5, one map
        per ``m_bar``). Both map linearly onto ballbal's ``Omega = s omega_bar`` and
        ``zeta_b = s lam / 2``; the table gains columns ``omega_bar`` and ``lam``."""
        from .balance import balance_map

        s = self.scale
        om = _check.axis("omega_bar", omega_bar, _check.MAX_MAP_POINTS)
        axes: dict[str, np.ndarray] = {"Omega": s * om}
        if lam is not None:
            axes["zeta_b"] = s * _check.axis("lam", lam, _check.MAX_MAP_POINTS) / 2
        for name, v in (("omega_bar", om), ("lam", axes.get("zeta_b"))):
            if v is not None and np.any(v < 0):
                raise ParameterError(name, "every value must be >= 0", allowed="[0, inf)",
                                     value=float(np.min(v)))
        df = balance_map(self.scene, **axes)
        # the caller's values, by position (Omega / s would not give them back exactly)
        cols = [pl.Series("omega_bar", om[df["Omega_index"].to_numpy()])]
        if lam is not None:
            lams = 2 * axes["zeta_b"] / s
            cols.append(pl.Series("lam", lams[df["zeta_b_index"].to_numpy()]))
        else:
            cols.append(pl.Series("lam", np.full(df.height, self.lam)))
        return df.with_columns(cols)

    @classmethod
    def from_physical(
        cls,
        *,
        E: float,  # noqa: N803 - the paper's symbols
        I: float,  # noqa: N803, E741
        a: float,
        b: float,
        M: float,  # noqa: N803
        m: float,
        R: float,  # noqa: N803
        eps: float,
        omega: float,
        D: float = 0.0,  # noqa: N803
        c_t: float = 0.0,
        c_r: float = 0.0,
        J_t: float | None = None,  # noqa: N803
        J_z: float | None = None,  # noqa: N803
        k_d: float = 0.0,
        n: int = 2,
    ) -> ShaftUnits:
        """The paper's nondimensional parameters from SI quantities: Young's modulus
        ``E`` [Pa] and second moment of area ``I`` [m^4] of the shaft, the disk's
        distances ``a, b`` [m] from the bearings (``L = a + b``), disk mass ``M`` [kg],
        ball mass ``m`` [kg], track radius ``R`` [m], eccentricity ``eps`` [m], spin
        ``omega`` [rad/s], track damping ``D`` [N m s], translational and tilt damping
        ``c_t`` [N s/m], ``c_r`` [N m s], the disk's inertias ``J_t, J_z`` [kg m^2] (None:
        flat disk), ball springs ``k_d`` [N/m] (the spring force is ``k_d R`` times the
        angle), ``n`` balls. All must be finite; sizes and masses > 0, the rest >= 0."""
        for name, v in (("E", E), ("I", I), ("a", a), ("b", b), ("M", M), ("m", m),
                        ("R", R), ("eps", eps)):
            _check.real(name, v, 0.0, lo_open=True, finite=True)
        for name, v in (("omega", omega), ("D", D), ("c_t", c_t), ("c_r", c_r),
                        ("k_d", k_d)):
            _check.real(name, v, 0.0, finite=True)
        length = a + b
        omega0 = cls.omega0(E=E, I=I, a=a, b=b, M=M)
        j = None if J_t is None else _check.real("J_t", J_t, 0.0, lo_open=True, finite=True)
        jz = None if J_z is None else _check.real("J_z", J_z, 0.0, finite=True)
        zeta_r = 0.0
        if j is not None:
            zeta_r = c_r / 4 * math.sqrt(length / (j * E * I))
        return cls(
            omega_bar=omega / omega0, m_bar=m / M, eps_bar=eps / R,
            lam=D / (m * R * R * omega0),
            zeta_t=c_t / 4 * math.sqrt(length**3 / (3 * M * E * I)), zeta_r=zeta_r,
            a=a / R, b=b / R,
            j_t=None if j is None else j / (M * R * R),
            j_z=None if jz is None else jz / (M * R * R),
            k_d=k_d / (M * omega0 * omega0), n=n)

    @staticmethod
    def omega0(*, E: float, I: float, a: float, b: float, M: float) -> float:  # noqa: N803, E741
        """The paper's frequency unit ``sqrt(3 E I L / (M a^2 b^2))`` [rad/s] (SI inputs
        as :meth:`from_physical`)."""
        for name, v in (("E", E), ("I", I), ("a", a), ("b", b), ("M", M)):
            _check.real(name, v, 0.0, lo_open=True, finite=True)
        return math.sqrt(3 * E * I * (a + b) / (M * a * a * b * b))


def from_shaft_units(
    omega_bar: float,
    m_bar: float,
    eps_bar: float,
    lam: float,
    zeta_t: float,
    **geometry: float | int | None,
) -> Scene:
    """A balancer on a flexible shaft given in [Rezaee2017]'s parameters (its eq. 36), as a
    ballbal scene: ``ShaftUnits(omega_bar, m_bar, eps_bar, lam, zeta_t, **geometry).scene``
    (``geometry``: ``zeta_r, a, b, j_t, j_z, k_d, n``; see :class:`ShaftUnits` for each
    parameter's meaning and range, and the module documentation for the formulas)."""
    return ShaftUnits(omega_bar, m_bar, eps_bar, lam, zeta_t, **geometry).scene  # type: ignore[arg-type]
