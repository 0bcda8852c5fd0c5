"""Scenes: the planar balancer plus the physical effects a user switches on.

A scene is a :class:`Balancer` with optional effects (``model.md`` units: lengths over
the eccentricity ``e``, time over ``1/w_n``, forces over ``M e w_n^2``):

* ``springs``: circumferential springs between neighbouring balls, stiffness ``k_d / k``,
  rest spacing ``2 pi / n`` (the ball-spring balancer of [Rezaee2017]); ``spring_layout``
  ``"ring"`` (n springs, ball n to ball 1 closing the ring) or ``"chain"`` (the
  [Rezaee2017] form: n - 1 springs, ball 1 to ball n; for two balls a ring of stiffness k
  is a chain of 2 k);
* ``ramp``: the spin changes linearly from ``Omega`` to ``ramp.to`` over
  ``ramp.duration`` from ``ramp.start`` (a run-up, or the speed disturbance of [TwoBallStrength]);
* ``gravity``: ``g / (e w_n^2)`` for a horizontal spin axis (gravity along -Y of the
  ground frame; the disk's x axis is along +X at t = 0);
* ``impulse``: Yen's (2005) load on the rotor ``amplitude exp(-sharpness (t - t0)^2)``
  along the ground direction ``angle``;
* ``tilt``: the disk tilts on a flexible, simply supported shaft, with gyroscopic
  coupling (Rezaee et al. 2017; :class:`Tilt`). The state gains two coordinates after ``x, y``:
  ``A, B``, the Euler tilts ``alpha, beta`` scaled by ``delta`` (the track rim's axial
  displacement over ``e``; radians are ``A / delta``).

The support is the isotropic spring–damper of ``model.md`` unless ``support`` is a
:class:`BearingSupport`: a hydrodynamic journal bearing (:class:`ballbal.bearing.Bearing`)
with ``rho = e / c`` (unbalance eccentricity over radial clearance). On a bearing there is
no spring, so the units change: time is over ``1 / w_ref`` with ``w_ref = C_S / M``,
``C_S = mu_oil L R^3 / c^3`` (``M`` the translating mass, ``mu_oil`` the viscosity, ``R``,
``L``, ``c`` the journal radius, length and clearance), forces over ``M e w_ref^2``;
``Omega = w / w_ref`` is the classical mass parameter ``M c^3 w / (mu_oil L R^3)``.
``zeta`` becomes an external damper on the centre's ground velocity in parallel with the
film, ``c_ext / (2 M w_ref)`` (0 for the film alone); ``zeta_b`` is ``c_b / (2 m_b w_ref)``.
Converting a spring–damper scene keeps the numbers but not their meaning: a ratio over
``w_n`` becomes one over ``w_ref``, so the same lab ``zeta_b`` is ``zeta_b w_n / w_ref``.
:meth:`BearingSupport.from_lab` builds a bearing scene from lab quantities (``w_ref`` is
:meth:`BearingSupport.reference_frequency`); :func:`to_bearing` converts a spring–damper
scene and returns what changed (``Omega`` and ``zeta_b`` times ``w_n / w_ref``, ``zeta``
to 0).
``support`` may instead be an :class:`AnisotropicSupport`: a ground-fixed spring–damper
whose stiffness and damping differ between the ground axes X and Y (a rig's frame; a
second support resonance at ``sqrt(k_y) w_n``); it makes the scene time-periodic (effect
``"anisotropic_support"``) unless both axes are equal.
A plain bearing, grooves on the journal or narrow-groove theory keep the scene
autonomous; resolved grooves (``model="finite"``) on the stationary sleeve make it
time-periodic (effect ``"grooved_sleeve"``): simulation only.

Every analysis accepts a scene. Time simulation works with any; periodic solutions,
Floquet, equilibria, scans and the balanced state need an autonomous scene (no ramp,
gravity, impulse or grooved sleeve: asking is an error that names the effect).

Files (TOML): the balancer's keys at the top level or in ``[balancer]`` (``balls`` for
equal balls), and optional tables ``[springs] stiffness, layout`` (``"ring"`` when
omitted), ``[ramp] to, start,
duration``, ``[gravity] g``, ``[impulse] amplitude, t0, sharpness, angle``, ``[tilt] a,
b, j_t, j_z, zeta_r``, ``[bearing] rho, length_ratio, cavitation, model, grid`` with an
optional ``[bearing.grooves] count, angle, depth_ratio, width_ratio, grooved_length,
side``, or ``[anisotropic_support] k_x, k_y, zeta_x, zeta_y`` (the dampings optional).
Unknown keys and tables are errors.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

from . import _check, _native
from .bearing import Bearing, Dimensions, Grooves
from .exceptions import ParameterError, ParameterTypeError
from .model import Balancer, _is_number

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def _num(where: str, v: Any) -> float:
    return _check.real(where, v, finite=True)


def _core_check(**part: Any) -> None:
    """A scene part's ranges, checked by the core (where they are defined once) when the
    part is made: the default balancer with only this part switched on."""
    from . import _native

    _native.validate(Scene(**part))


@dataclass(frozen=True)
class Ramp:
    to: float
    start: float = 0.0
    duration: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _num(f"ramp.{f.name}", getattr(self, f.name)))
        _core_check(ramp=self)


@dataclass(frozen=True)
class Impulse:
    amplitude: float
    t0: float
    sharpness: float
    angle: float = -math.pi / 2

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _num(f"impulse.{f.name}", getattr(self, f.name)))
        _core_check(impulse=self)


@dataclass(frozen=True)
class Tilt:
    """A disk that tilts on a massless, simply supported shaft (Rezaee et al. 2017).

    ``a, b``: the disk's distances from the two bearings, over the track radius ``r_t``;
    ``j_t, j_z``: the disk's transverse and polar moments of inertia about its mass
    centre, over ``M r_t^2``; ``zeta_r``: tilt damping ratio ``c_r / (2 sqrt(J_t
    k_phiphi))``, on the disk normal's rate in the ground frame. The shaft's stiffness at
    the disk is the ``k`` of ``w_n``; beam theory then fixes the coupling and tilt
    stiffnesses :attr:`kappa_c` and :attr:`kappa_t`. ``a == b`` (disk at mid-span)
    decouples translation and tilt.
    """

    a: float
    b: float
    j_t: float
    j_z: float
    zeta_r: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            object.__setattr__(self, f.name, _num(f"tilt.{f.name}", getattr(self, f.name)))
        _core_check(tilt=self)

    @property
    def kappa_c(self) -> float:
        """Translation–tilt coupling stiffness, over ``k r_t``."""
        a, b = self.a, self.b
        return a * b * (a - b) / (a * a - a * b + b * b)

    @property
    def kappa_t(self) -> float:
        """Tilt stiffness, over ``k r_t^2``."""
        a, b = self.a, self.b
        return a * a * b * b / (a * a - a * b + b * b)


@dataclass(frozen=True)
class BearingSupport:
    """The disk centre carried by a journal bearing: the film ``bearing`` and ``rho = e /
    c``, the unbalance eccentricity over the radial clearance (the journal sits at ``rho
    (x, y)`` clearances from the centre). See the module documentation for the units."""

    bearing: Bearing
    rho: float

    def __post_init__(self) -> None:
        if not isinstance(self.bearing, Bearing):
            raise ParameterTypeError("bearing", f"must be a ballbal.bearing.Bearing, got "
                                     f"{type(self.bearing).__name__}")
        object.__setattr__(self, "rho", _num("rho", self.rho))
        _core_check(support=self)

    @property
    def time_dependence(self) -> str | None:
        """``"grooved_sleeve"`` when resolved grooves on the sleeve make the film
        time-periodic in the disk's frame, else None."""
        g = self.bearing.grooves
        if (g is not None and g.side == "sleeve" and g.depth_ratio > 0
                and self.bearing.model == "finite"):
            return "grooved_sleeve"
        return None

    @staticmethod
    def reference_frequency(dimensions: Dimensions, mass: float) -> float:
        """``w_ref = C_S / M`` [rad/s] with ``C_S = mu_oil L R^3 / c^3``: the bearing
        scene's time unit, in place of a spring's ``sqrt(k / M)``; ``mass`` is the
        translating mass ``M`` [kg]."""
        m = _check.real("mass", mass, 0.0, lo_open=True)
        d = dimensions
        return d.viscosity * d.length * d.radius**3 / (d.clearance**3 * m)

    @classmethod
    def from_lab(
        cls,
        bearing: Bearing,
        dimensions: Dimensions,
        *,
        disk_mass: float,
        eccentricity: float,
        ball_masses: Sequence[float],
        track_radius: float,
        track_damping: float,
        spin: float,
        other_mass: float = 0.0,
        external_damping: float = 0.0,
    ) -> Scene:
        """A balancer on this bearing from lab quantities (SI units, ``spin`` in rad/s).

        As :meth:`Balancer.from_lab`, with the bearing's ``w_ref`` (:meth:`
        reference_frequency`) in place of ``sqrt(k / M)``: ``Omega = spin / w_ref`` (the
        mass parameter ``M c^3 w / (mu_oil L R^3)``), ``zeta = external_damping / (2 M
        w_ref)`` (a damper beside the film, 0 for none), ``zeta_b = c_b / (2 m_b w_ref)``,
        and ``rho = e / c``. The bearing's ``length_ratio`` must be the dimensions' ``L / D``.
        """
        if not isinstance(bearing, Bearing):
            raise ParameterTypeError("bearing", "must be a ballbal.bearing.Bearing",
                                     allowed="Bearing")
        if not math.isclose(bearing.length_ratio, dimensions.length_ratio, rel_tol=1e-9):
            raise ParameterError(
                "bearing", f"length_ratio {bearing.length_ratio} is not the dimensions' L/D "
                f"{dimensions.length_ratio}", allowed=f"{dimensions.length_ratio}")
        ecc = _check.real("eccentricity", eccentricity, 0.0, lo_open=True)
        mb = _check.reals("ball_masses", ball_masses)
        total = (_check.real("other_mass", other_mass, 0.0)
                 + _check.real("disk_mass", disk_mass, 0.0, lo_open=True) + sum(mb))
        w_ref = cls.reference_frequency(dimensions, total)
        # Balancer.from_lab with a stiffness giving sqrt(k / M) = w_ref
        bal = Balancer.from_lab(
            disk_mass=disk_mass, eccentricity=ecc, ball_masses=mb, track_radius=track_radius,
            stiffness=w_ref**2 * total, damping=external_damping, track_damping=track_damping,
            spin=spin, other_mass=other_mass)
        return Scene(balancer=bal, support=cls(bearing, ecc / dimensions.clearance))


#: Largest stiffness of an anisotropic support's axis over the ``k`` of ``w_n`` (the core's
#: bound: beyond it the support's period is far below the model's time unit).
MAX_AXIS_STIFFNESS = 1e4


@dataclass(frozen=True)
class AnisotropicSupport:
    """A support fixed to the ground, unequal in the ground axes ``X`` and ``Y`` (a rig's
    plate or frame stiffer one way than the other): the disk centre feels
    ``-(k_x X + 2 zeta_x X', k_y Y + 2 zeta_y Y')`` in place of the isotropic ``-(X + 2
    zeta X')``.

    ``k_x, k_y``: stiffness over the ``k`` of ``w_n`` (in ``(0, 1e4]``; 1 is the isotropic
    support's); ``zeta_x, zeta_y``: damping ratios ``c / (2 M w_n)`` (>= 0), None for the
    balancer's ``zeta``. Without spin the disk has the two natural frequencies
    ``sqrt(k_x)``, ``sqrt(k_y)`` (units of ``w_n``, balls of negligible mass), so a rig
    with one resonance at ``w_n`` and a second at ``w_2`` has ``k_y = (w_2 / w_n)^2``.
    Seen from the rotating disk the unequal axes turn, so the scene depends on time
    (effect ``"anisotropic_support"``): simulation, spectra and run-ups, not equilibria,
    periodic solutions or scans. With equal axes it is the isotropic support.
    """

    k_x: float = 1.0
    k_y: float = 1.0
    zeta_x: float | None = None
    zeta_y: float | None = None

    def __post_init__(self) -> None:
        for k in ("k_x", "k_y"):
            object.__setattr__(self, k, _check.real(f"support.{k}", getattr(self, k), 0.0,
                                                    MAX_AXIS_STIFFNESS, lo_open=True))
        for k in ("zeta_x", "zeta_y"):
            v = getattr(self, k)
            if v is not None:
                object.__setattr__(self, k, _check.real(f"support.{k}", v, 0.0, finite=True))
        _core_check(support=self)

    def dampings(self, zeta: float) -> tuple[float, float]:
        """``(zeta_x, zeta_y)`` with a None taken as the balancer's ``zeta``."""
        return (zeta if self.zeta_x is None else self.zeta_x,
                zeta if self.zeta_y is None else self.zeta_y)

    def natural_frequencies(self) -> tuple[float, float]:
        """``(sqrt(k_x), sqrt(k_y))``: the undamped frequencies of the disk on this
        support without spin and with balls of negligible mass, in units of ``w_n``."""
        return (math.sqrt(self.k_x), math.sqrt(self.k_y))


def to_bearing(scene: Scene, support: BearingSupport, *,
               natural_over_reference: float) -> tuple[Scene, dict[str, tuple[Any, Any]]]:
    """The same machine with its spring–damper replaced by ``support``, and what changed.

    A spring–damper scene's rates are over ``w_n = sqrt(k / M)``, a bearing scene's over
    ``w_ref = C_S / M``; ``natural_over_reference = w_n / w_ref`` converts them: the
    returned scene keeps the lab speed, track damping and masses, so ``Omega`` and
    ``zeta_b`` are multiplied by the ratio; the support damping ``zeta`` has no film
    counterpart and becomes 0 (give an external damper by replacing it). The dict maps each
    changed parameter to ``(old, new)``; ``"support"`` is always in it.
    """
    r = _check.real("natural_over_reference", natural_over_reference, 0.0, lo_open=True,
                    finite=True)
    if not isinstance(scene, Scene) or scene.support is not None:
        raise ParameterError("scene", "must be a Scene on the spring–damper support",
                             allowed="Scene with support=None")
    if not isinstance(support, BearingSupport):
        raise ParameterTypeError("support", "must be a BearingSupport",
                                 allowed="BearingSupport")
    b = scene.balancer
    zb = b.zeta_b * r if isinstance(b.zeta_b, float) else tuple(z * r for z in b.zeta_b)
    new = scene.replace(Omega=b.Omega * r, zeta_b=zb, zeta=0.0, support=support)
    changes: dict[str, tuple[Any, Any]] = {
        "Omega": (b.Omega, new.balancer.Omega),
        "zeta_b": (b.zeta_b, new.balancer.zeta_b),
        "zeta": (b.zeta, 0.0),
        "support": ("spring-damper", support),
    }
    return new, changes


@dataclass(frozen=True)
class Scene:
    balancer: Balancer = field(default_factory=Balancer)
    springs: float = 0.0
    ramp: Ramp | None = None
    gravity: float = 0.0
    impulse: Impulse | None = None
    tilt: Tilt | None = None
    spring_layout: str = "ring"
    support: BearingSupport | AnisotropicSupport | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.balancer, Balancer):
            raise ParameterTypeError("balancer", f"must be a Balancer, got "
                                     f"{type(self.balancer).__name__}")
        object.__setattr__(self, "springs", _check.real("springs", self.springs, 0.0))
        object.__setattr__(self, "gravity", _check.real("gravity", self.gravity, 0.0))
        if self.springs > 0 and self.balancer.n_balls < 2:
            raise ParameterError("springs", "ball springs need at least 2 balls")
        if not isinstance(self.spring_layout, str) or self.spring_layout not in ("ring", "chain"):
            raise ParameterError("spring_layout", f"must be 'ring' or 'chain', "
                                 f"got {self.spring_layout!r:.60}", allowed="ring, chain")
        for name, kinds in (("ramp", (Ramp,)), ("impulse", (Impulse,)), ("tilt", (Tilt,)),
                            ("support", (BearingSupport, AnisotropicSupport))):
            v = getattr(self, name)
            if v is not None and not isinstance(v, kinds):
                shown = " or ".join(k.__name__ for k in kinds)
                raise ParameterTypeError(name, f"must be a {shown} or None, got "
                                         f"{type(v).__name__}")
        # the effects' ranges and what they ask of the rest (a support needs Omega > 0
        # and a planar disk), checked once, in the core, when the scene is made
        from . import _native

        _native.validate(self)

    # the interface the analyses use, shared with Balancer
    @property
    def n_balls(self) -> int:
        """The number of balls of the scene's balancer."""
        return self.balancer.n_balls

    @property
    def Omega(self) -> float:  # noqa: N802 - Tien's (2011) symbol
        """The spin ratio of the scene's balancer."""
        return self.balancer.Omega

    @property
    def coordinates(self) -> list[str]:
        """Names of the generalised coordinates, in the state's order."""
        rotor = ["x", "y"] + (["A", "B"] if self.tilt is not None else [])
        return rotor + [f"b{i + 1}" for i in range(self.n_balls)]

    def replace(self, **changes: Any) -> Scene:
        """A copy with fields changed; balancer fields (``Omega``, ``eta``, ...) and tilt
        fields (``j_t``, ``a``, ...) may be given directly; a single ``eta`` sets every
        ball's."""
        known = (_BALANCER_FIELDS | _TILT_FIELDS | {f.name for f in fields(Scene)}
                 | {"rho"})
        for k in changes:
            if k not in known:
                raise ParameterError(k, "not a field of the scene, its balancer or its tilt "
                                     f"(fields: {', '.join(sorted(known))})")
        bal = {k: changes.pop(k) for k in list(changes) if k in _BALANCER_FIELDS}
        if "eta" in bal and _is_number(bal["eta"]):
            bal["eta"] = (bal["eta"],) * self.n_balls  # one value: every ball, as in scans
        tl = {k: changes.pop(k) for k in list(changes) if k in _TILT_FIELDS}
        if bal:
            changes["balancer"] = self.balancer.replace(**bal).validate()
        if "rho" in changes:
            rho = changes.pop("rho")
            if not isinstance(self.support, BearingSupport):
                raise ParameterError("rho", "the scene has no bearing support to change")
            changes["support"] = replace(self.support, rho=rho)
        if tl:
            if self.tilt is None:
                raise ParameterError(next(iter(tl)), "the scene has no tilt to change")
            changes["tilt"] = replace(self.tilt, **tl)
        return replace(self, **changes)

    def _effects_on(self) -> bool:
        """Whether any effect is on (else every analysis runs the planar code)."""
        return bool(self.springs != 0 or self.ramp is not None or self.gravity != 0
                    or self.impulse is not None or self.tilt is not None
                    or self.support is not None)

    @property
    def time_dependence(self) -> str | None:
        """The effect that makes the scene time dependent, or None if it is autonomous."""
        if self.ramp is not None:
            return "ramp"
        if self.gravity != 0:
            return "gravity"
        if self.impulse is not None:
            return "impulse"
        if isinstance(self.support, AnisotropicSupport):
            s = self.support
            if s.k_x != s.k_y or len(set(s.dampings(self.balancer.zeta))) > 1:
                return "anisotropic_support"
        elif self.support is not None:
            return self.support.time_dependence
        return None

    def to_dict(self) -> dict[str, Any]:
        """The scene as nested dictionaries, the tables of its TOML file
        (:func:`~ballbal.load_scene` reads them back)."""
        d: dict[str, Any] = {"balancer": asdict(self.balancer)}
        b = d["balancer"]
        b["eta"] = list(b["eta"])
        if isinstance(b["zeta_b"], tuple):
            b["zeta_b"] = list(b["zeta_b"])
        if self.springs or self.spring_layout != "ring":
            d["springs"] = {"stiffness": self.springs}
            if self.spring_layout != "ring":
                d["springs"]["layout"] = self.spring_layout
        if self.ramp is not None:
            d["ramp"] = asdict(self.ramp)
        if self.gravity:
            d["gravity"] = {"g": self.gravity}
        if self.impulse is not None:
            d["impulse"] = asdict(self.impulse)
        if self.tilt is not None:
            d["tilt"] = asdict(self.tilt)
        if isinstance(self.support, AnisotropicSupport):
            d["anisotropic_support"] = {k: v for k, v in asdict(self.support).items()
                                        if v is not None}
        elif self.support is not None:
            bearing = self.support.bearing
            t: dict[str, Any] = {"rho": self.support.rho,
                                 "length_ratio": bearing.length_ratio,
                                 "cavitation": bearing.cavitation, "model": bearing.model,
                                 "grid": list(bearing.grid or ())}
            if bearing.grooves is not None:
                t["grooves"] = asdict(bearing.grooves)
            d["bearing"] = t
        return d

    def to_toml(self) -> str:
        """The scene as the text of a TOML file (see :meth:`to_dict`)."""
        lines: list[str] = []
        for table, values in self.to_dict().items():
            lines.append(f"[{table}]")
            subs = {k: v for k, v in values.items() if isinstance(v, dict)}
            for k, v in values.items():
                if k not in subs:
                    lines.append(f"{k} = {_toml_value(v)}")
            lines.append("")
            for sub, inner in subs.items():
                lines.append(f"[{table}.{sub}]")
                for k, v in inner.items():
                    lines.append(f"{k} = {_toml_value(v)}")
                lines.append("")
        return "\n".join(lines)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_toml` to ``path`` (UTF-8), for :func:`~ballbal.load_scene`."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.to_toml())


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return '"' + v + '"'  # layout names only: no quotes or escapes inside
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, int) and not isinstance(v, bool):
        return str(v)  # groove counts and grids
    return repr(float(v))


_TABLES = {"springs": {"stiffness", "layout"}, "ramp": {"to", "start", "duration"},
           "gravity": {"g"}, "impulse": {"amplitude", "t0", "sharpness", "angle"},
           "tilt": {"a", "b", "j_t", "j_z", "zeta_r"},
           "bearing": {"rho", "length_ratio", "grooves", "cavitation", "model", "grid"},
           "anisotropic_support": {"k_x", "k_y", "zeta_x", "zeta_y"}}
_REQUIRED = {"springs": {"stiffness"}, "ramp": {"to"}, "gravity": {"g"},
             "impulse": {"amplitude", "t0", "sharpness"}, "tilt": {"a", "b", "j_t", "j_z"},
             "bearing": {"rho"}, "anisotropic_support": {"k_x", "k_y"}}
_GROOVE_KEYS = {f.name for f in fields(Grooves)}
#: A scene file is a few lines; anything much longer is the wrong file.
MAX_SCENE_BYTES = 1 << 20
_BALANCER_FIELDS = {f.name for f in fields(Balancer)}
_TILT_FIELDS = {f.name for f in fields(Tilt)}


#: Most balls a scene file may ask for with ``balls`` (every model's bound).
MAX_BALLS = _check.MAX_BALLS


def balancer_from_dict(d: dict[str, Any], where: str = "scene") -> Balancer:
    known = {f.name for f in fields(Balancer)} | {"balls"}
    unknown = sorted(set(d) - known)
    if unknown:
        raise ParameterError(unknown[0], f"{where}: unknown key(s) {', '.join(unknown)} "
                             f"(allowed: {', '.join(sorted(known))})",
                             allowed=", ".join(sorted(known)))
    d = dict(d)
    balls = d.pop("balls", None)
    if balls is not None:
        balls = _check.integer("balls", balls, 1, MAX_BALLS)
        eta = d.get("eta", 1.0)
        if _is_number(eta):
            d["eta"] = (float(eta),) * balls
        elif not isinstance(eta, list) or len(eta) != balls:
            raise ParameterError("eta", f"must be one number or {balls} numbers "
                                 f"(balls = {balls})")
    return Balancer(**d).validate()


def scene_from_dict(d: dict[str, Any], where: str = "scene") -> Scene:
    if not isinstance(d, dict):
        raise ParameterTypeError("scene", f"{where}: a scene is a table of keys, got "
                                 f"{type(d).__name__}")
    if not d:
        # An empty file is more likely a mistake than a request for the default scene.
        raise ParameterError("scene", f"{where}: the scene is empty; give at least the "
                             "balancer's keys (e.g. Omega = 1.2, balls = 2)")
    tables = {k for k, v in d.items() if isinstance(v, dict)}
    unknown = sorted(tables - set(_TABLES) - {"balancer"})
    if unknown:
        raise ParameterError(unknown[0], f"{where}: unknown table(s) {', '.join(unknown)} "
                             f"(allowed: balancer, {', '.join(_TABLES)})",
                             allowed="balancer, " + ", ".join(_TABLES))
    not_tables = sorted(set(_TABLES) & (set(d) - tables))
    if not_tables:
        k = not_tables[0]
        raise ParameterTypeError(k, f"{where}: '{k}' must be a table ([{k}] with keys "
                                 f"{', '.join(sorted(_TABLES[k]))})")
    if "balancer" in d and "balancer" not in tables:
        raise ParameterTypeError("balancer", f"{where}: 'balancer' must be a table")
    if "balancer" in tables:
        flat = sorted(set(d) - tables)
        if flat:
            raise ParameterError(flat[0], f"{where}: key(s) {', '.join(flat)} outside a "
                                 "table; put the balancer's keys in [balancer]")
        b = balancer_from_dict(d["balancer"], where)
    else:
        b = balancer_from_dict({k: v for k, v in d.items() if k not in tables}, where)
    for t in sorted(tables & set(_TABLES)):
        extra = sorted(set(d[t]) - _TABLES[t])
        if extra:
            raise ParameterError(f"{t}.{extra[0]}", f"{t}: unknown key(s) {', '.join(extra)} "
                                 f"(allowed: {', '.join(sorted(_TABLES[t]))})",
                                 allowed=", ".join(sorted(_TABLES[t])))
        missing = sorted(k for k in _REQUIRED[t] if k not in d[t])
        if missing:
            raise ParameterError(f"{t}.{missing[0]}", f"{where}: [{t}] needs "
                                 f"{', '.join(missing)}")
    support: BearingSupport | AnisotropicSupport | None = None
    if "bearing" in d:
        if "anisotropic_support" in d:
            raise ParameterError("anisotropic_support", f"{where}: a scene has one support, "
                                 "[bearing] or [anisotropic_support], not both")
        support = _support_from_dict(d["bearing"], where)
    elif "anisotropic_support" in d:
        support = AnisotropicSupport(**d["anisotropic_support"])
    try:
        return Scene(
            balancer=b,
            support=support,
            springs=d["springs"]["stiffness"] if "springs" in d else 0.0,
            spring_layout=d["springs"].get("layout", "ring") if "springs" in d else "ring",
            ramp=Ramp(**d["ramp"]) if "ramp" in d else None,
            gravity=d["gravity"]["g"] if "gravity" in d else 0.0,
            impulse=Impulse(**d["impulse"]) if "impulse" in d else None,
            tilt=Tilt(**d["tilt"]) if "tilt" in d else None,
        )
    except (KeyError, TypeError) as e:
        raise ParameterError("scene", f"{where}: incomplete effect table ({e})") from e


def _support_from_dict(t: dict[str, Any], where: str) -> BearingSupport:
    """The ``[bearing]`` table (keys checked by the caller) as a :class:`BearingSupport`."""
    t = dict(t)
    rho = t.pop("rho")
    g = t.pop("grooves", None)
    grooves = None
    if g is not None:
        if not isinstance(g, dict):
            raise ParameterTypeError("bearing.grooves", f"{where}: [bearing.grooves] must be a "
                                     "table")
        extra = sorted(set(g) - _GROOVE_KEYS)
        if extra:
            raise ParameterError(f"bearing.grooves.{extra[0]}", f"{where}: unknown key(s) "
                                 f"{', '.join(extra)} (allowed: "
                                 f"{', '.join(sorted(_GROOVE_KEYS))})",
                                 allowed=", ".join(sorted(_GROOVE_KEYS)))
        try:
            grooves = Grooves(**g)
        except TypeError as e:
            raise ParameterError("bearing.grooves", f"{where}: [bearing.grooves] needs count, "
                                 f"angle and depth_ratio ({e})") from e
    if isinstance(t.get("grid"), list):
        t["grid"] = tuple(t["grid"])
    return BearingSupport(bearing=Bearing(grooves=grooves, **t), rho=rho)


def load_scene(path: str | os.PathLike[str]) -> Scene:
    """A scene from a TOML file (see the module's description of the format); a file
    that cannot be read or is not a scene is a :class:`ParameterError` naming ``path``
    (or the key at fault)."""
    _check.path("path", path)
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_SCENE_BYTES + 1)
    except OSError as e:
        raise ParameterError("path", f"cannot read the scene file {path}: "
                             f"{e.strerror or e}", value=path) from e
    if len(data) > MAX_SCENE_BYTES:
        raise ParameterError("path", f"{path} is larger than {MAX_SCENE_BYTES} bytes: not a "
                             "scene file", value=path)
    try:
        d = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise ParameterError("path", f"{path} is not UTF-8 text (a binary file, or another "
                             f"encoding such as UTF-16): {e.reason} at byte {e.start}",
                             value=path) from e
    except tomllib.TOMLDecodeError as e:
        raise ParameterError("path", f"{path} is not valid TOML: {e}", value=path) from e
    except RecursionError as e:
        raise ParameterError("path", f"{path} nests tables or arrays too deeply to be a "
                             "scene", value=path) from e
    if not d:
        # An empty file is more likely a mistake than a request for the default scene.
        raise ParameterError("path", f"{path} holds no keys; give at least the balancer's "
                             "(e.g. Omega = 1.2, balls = 2)", value=path)
    return scene_from_dict(d, where=str(path))


def model_argument(name: str, v: Any) -> Balancer | Scene:
    """A :class:`Balancer` or :class:`Scene` (what every analysis takes first)."""
    if not isinstance(v, (Balancer, Scene)):
        raise ParameterTypeError(
            name, f"must be a ballbal.Balancer or ballbal.Scene, got {type(v).__name__}",
            value=v)
    return v


def model_at(model: Balancer | Scene, parameter: str, value: float) -> Balancer | Scene:
    """``model`` with ``parameter`` set to ``value``. A per-ball name sets one ball's
    value, balls named from 1 as the core names them (``"eta1"`` is the ball whose angle
    is ``b1``, ``Balancer.eta[0]``)."""
    try:
        name, i = _native.parse_parameter(parameter)
    except ParameterError:
        i = None  # not a registry name: the model's own fields say whether it has it
    if i is None:
        return model.replace(**{parameter: value})
    bal = model.balancer if isinstance(model, Scene) else model
    if i >= bal.n_balls:
        first, last = (_native.ball_parameter_name(name, j) for j in (0, bal.n_balls - 1))
        raise ParameterError(parameter, f"names ball {i + 1} of a balancer with {bal.n_balls}",
                             allowed=f"{first} to {last}")
    old = getattr(bal, name)
    vals = list(old) if isinstance(old, (tuple, list)) else [old] * bal.n_balls
    vals[i] = value
    return model.replace(**{name: tuple(vals)})
