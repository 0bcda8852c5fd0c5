"""The planar balancer's parameters and conversions to and from lab quantities."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, fields, replace
from typing import Any

from . import _check, _native
from ._check import is_real as _is_number
from .exceptions import ParameterError, ParameterTypeError


def _tuple(name: str, v: float | Sequence[float]) -> tuple[float, ...]:
    """One value per ball (or one for all), at most :data:`~ballbal._check.MAX_BALLS`."""
    if _is_number(v):
        return (_check.real(name, v),)
    bad = ParameterTypeError(name, f"must be a number or a sequence of numbers, got {v!r:.60}",
                             value=v)
    if isinstance(v, (str, bytes)):
        raise bad
    size = len(v) if isinstance(v, Sequence) else getattr(v, "size", None)  # numpy's
    if isinstance(size, int):
        # before the values are converted: 1000 balls made equilibria() run for hours
        _check.at_most(name, size, _check.MAX_BALLS, "balls")
    try:
        items = list(v)  # type: ignore[arg-type]
    except TypeError as e:
        raise bad from e
    if not all(_is_number(x) for x in items):
        raise bad
    _check.at_most(name, len(items), _check.MAX_BALLS, "balls")  # an iterable without len
    return tuple(_check.real(_native.ball_parameter_name(name, i), x) for i, x in enumerate(items))


def _unknown_fields(cls: type, changes: dict[str, Any]) -> None:
    known = {f.name for f in fields(cls)}
    for k in changes:
        if k not in known:
            raise ParameterError(k, f"not a field of {cls.__name__} (fields: "
                                 f"{', '.join(sorted(known))})", allowed=", ".join(sorted(known)))


@dataclass(frozen=True)
class Balancer:
    """A planar automatic ball balancer in the nondimensional parameters of [Tien2011].

    ``eta`` has one entry per ball (its length is the number of balls ``n``); ``zeta_b``
    is one value shared by all balls or one per ball. The core checks the parameters
    when the balancer is made (a value out of range raises
    :class:`~ballbal.exceptions.ParameterError` naming it and its range).
    """

    mu: float = 0.2
    zeta: float = 0.05
    zeta_b: float | tuple[float, ...] = 0.05
    delta: float = 50.0
    Omega: float = 1.2
    eta: tuple[float, ...] = field(default=(1.0, 1.0))

    def __post_init__(self) -> None:
        for name in ("mu", "zeta", "delta", "Omega"):
            object.__setattr__(self, name, _check.real(name, getattr(self, name)))
        object.__setattr__(self, "eta", _tuple("eta", self.eta))
        zb = _tuple("zeta_b", self.zeta_b)
        object.__setattr__(self, "zeta_b", zb[0] if len(zb) == 1 else zb)
        _native.validate_balancer(self)

    @property
    def n_balls(self) -> int:
        """The number of balls (one per ``eta`` value)."""
        return len(self.eta)

    @property
    def coordinates(self) -> list[str]:
        """Names of the generalised coordinates, in the state's order."""
        return ["x", "y"] + [f"b{i + 1}" for i in range(self.n_balls)]

    def replace(self, **changes: Any) -> Balancer:
        """A copy with fields changed; a single number for ``eta`` sets every ball's
        value (the number of balls stays; give a sequence to change it), as
        :meth:`ballbal.Scene.replace` and scans do."""
        _unknown_fields(Balancer, changes)
        if "eta" in changes and _is_number(changes["eta"]):
            changes["eta"] = (changes["eta"],) * self.n_balls
        return replace(self, **changes)

    def validate(self) -> Balancer:
        """Check the parameters (the core's own checks, no analysis) and return self:
        a balancer is checked when it is made, so this only repeats that check."""
        _native.validate(self)
        return self

    @classmethod
    def from_lab(
        cls,
        *,
        disk_mass: float,
        eccentricity: float,
        ball_masses: Sequence[float],
        track_radius: float,
        stiffness: float,
        damping: float,
        track_damping: float,
        spin: float,
        other_mass: float = 0.0,
    ) -> Balancer:
        """Nondimensionalise lab quantities (SI units; ``spin`` in rad/s).

        ``track_damping`` is the viscous coefficient ``c_b`` on a ball's speed relative to
        the track; ``other_mass`` is the rotor and motor base mass ``M_r``.
        """
        disk_mass, eccentricity, track_radius, stiffness = (
            _check.real(k, v, 0.0, lo_open=True) for k, v in (
                ("disk_mass", disk_mass), ("eccentricity", eccentricity),
                ("track_radius", track_radius), ("stiffness", stiffness)))
        damping, track_damping, spin, other_mass = (
            _check.real(k, v, 0.0) for k, v in (
                ("damping", damping), ("track_damping", track_damping), ("spin", spin),
                ("other_mass", other_mass)))
        mb = _check.reals("ball_masses", ball_masses)
        _check.at_most("ball_masses", len(mb), _check.MAX_BALLS, "balls")
        if not mb or any(not (math.isfinite(m) and m > 0) for m in mb):
            raise ParameterError("ball_masses", "need at least one ball, every mass finite "
                                 "and > 0", allowed="(0, inf)", value=ball_masses)
        total = other_mass + disk_mass + sum(mb)
        wn = math.sqrt(stiffness / total)
        zb = tuple(track_damping / (2 * m * wn) for m in mb)
        return cls(
            mu=disk_mass / total,
            zeta=damping / (2 * total * wn),
            zeta_b=zb[0] if len(set(zb)) == 1 else zb,
            delta=track_radius / eccentricity,
            Omega=spin / wn,
            eta=tuple(m * track_radius / (disk_mass * eccentricity) for m in mb),
        )

    def to_lab(self, *, disk_mass: float, eccentricity: float, stiffness: float) -> dict[str, Any]:
        """Lab quantities for a given disk mass, eccentricity and support stiffness."""
        disk_mass, eccentricity, stiffness = (
            _check.real(k, v, 0.0, lo_open=True) for k, v in (
                ("disk_mass", disk_mass), ("eccentricity", eccentricity),
                ("stiffness", stiffness)))
        total = disk_mass / self.mu
        wn = math.sqrt(stiffness / total)
        r_t = self.delta * eccentricity
        mb = [e * disk_mass * eccentricity / r_t for e in self.eta]
        zb = [self.zeta_b] * len(mb) if isinstance(self.zeta_b, float) else list(self.zeta_b)
        return {
            "total_mass": total,
            "natural_frequency": wn,
            "spin": self.Omega * wn,
            "track_radius": r_t,
            "ball_masses": mb,
            "other_mass": total - disk_mass - sum(mb),
            "damping": 2 * self.zeta * total * wn,
            "track_damping": [2 * z * m * wn for z, m in zip(zb, mb, strict=True)],
        }


def zeta_from_log_decrement(d: float) -> float:
    """Damping ratio from a measured logarithmic decrement ``d``."""
    d = _check.real("d", d, 0.0)
    return d / math.sqrt(4 * math.pi**2 + d**2)


def from_disk_units(
    omega0: float, m0: float, e: float, C0: float = 0.05, D0: float = 0.1, n: int = 2
) -> Balancer:
    """A balancer given in units of the disk alone [EccentricRotorABB], in ballbal's parameters.

    Lengths are scaled by the track radius (``e = eps / R``), masses by the disk mass
    (``m0 = m / M``) and time by ``omega_n = sqrt(K / M)`` of the disk alone, with no
    further rotor mass; ``C0 = C / (2 sqrt(K M))`` and ``D0 = D / (m R^2 omega_n)``. The total
    mass is ``M (1 + n m0)``, hence ``Omega = omega0 sqrt(1 + n m0)``, ``eta = m0 / e``,
    ``mu = 1 / (1 + n m0)``, ``delta = 1 / e``, ``zeta = C0 / sqrt(1 + n m0)`` and
    ``zeta_b = D0 sqrt(1 + n m0) / 2``. The pitchfork point ``(0.5773, 1)`` with ``e = 2``
    is ``(Omega, eta) = (1, 0.5)``.
    """
    omega0, C0, D0 = (_check.real(k, v, 0.0) for k, v in
                      (("omega0", omega0), ("C0", C0), ("D0", D0)))
    m0 = _check.real("m0", m0, 0.0, lo_open=True)
    e = _check.real("e", e, 0.0, lo_open=True)
    n = _check.integer("n", n, 1, _check.MAX_BALLS)
    s = math.sqrt(1.0 + n * m0)
    return Balancer(
        mu=1.0 / (1.0 + n * m0),
        zeta=C0 / s,
        zeta_b=D0 * s / 2.0,
        delta=1.0 / e,
        Omega=omega0 * s,
        eta=(m0 / e,) * n,
    )


#: The parameter names in the disk's units, the ones continuation in them takes.
DISK_UNITS_PARAMETERS = ("omega0", "m0", "e", "C0", "D0")


@dataclass(frozen=True)
class DiskUnits:
    """A balancer in units of the disk alone [EccentricRotorABB], a family continuation can
    vary in these units' own parameters.

    ``omega0`` spin speed over ``sqrt(K / M)`` of the disk alone, ``m0 = m / M`` (each of
    the ``n`` balls over the disk), ``e = eps / R`` (eccentricity over track radius),
    ``C0 = C / (2 sqrt(K M))``, ``D0 = D / (m R^2 omega_n)``; see :func:`from_disk_units`
    for the conversion. ``balancer`` is the same balancer in ballbal's parameters.

    The equilibrium-continuation functions of :mod:`ballbal.continuation` accept it as
    their model and then take and report these parameter names
    (``equilibrium_branch(DiskUnits(0.3, 2.0, 2.0, 0.35, 0.35), "m0", ...)``): one of them
    moves several of ballbal's at once (``m0`` moves ``mu``, ``eta``, ``Omega``, ``zeta``
    and ``zeta_b``), and the model is rebuilt from these values at every point.
    """

    omega0: float
    m0: float
    e: float
    C0: float = 0.05
    D0: float = 0.1
    n: int = 2

    def __post_init__(self) -> None:
        for k, lo, is_open in (("omega0", 0.0, False), ("m0", 0.0, True), ("e", 0.0, True),
                               ("C0", 0.0, False), ("D0", 0.0, False)):
            object.__setattr__(self, k, _check.real(k, getattr(self, k), lo, lo_open=is_open,
                                                    finite=True))
        object.__setattr__(self, "n", _check.integer("n", self.n, 1, _check.MAX_BALLS))

    @property
    def balancer(self) -> Balancer:
        """The same balancer in ballbal's parameters (:func:`from_disk_units`)."""
        return from_disk_units(self.omega0, self.m0, self.e, C0=self.C0, D0=self.D0, n=self.n)

    @property
    def scale(self) -> float:
        """``S = sqrt(1 + n m0)``: ballbal's ``Omega`` over ``omega0``; the disk's time unit
        is ``S`` times ballbal's (its rates and eigenvalues are ballbal's over ``S``)."""
        return math.sqrt(1.0 + self.n * self.m0)

    def replace(self, **changes: Any) -> DiskUnits:
        """A copy with some of these parameters changed."""
        for k in changes:
            if k not in (*DISK_UNITS_PARAMETERS, "n"):
                raise ParameterError(k, "is not a parameter of the disk's units",
                                     allowed=", ".join(DISK_UNITS_PARAMETERS))
        return replace(self, **changes)
