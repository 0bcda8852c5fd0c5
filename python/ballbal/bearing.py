"""Hydrodynamic journal bearings, plain and herringbone-grooved ([Yen2005], ``bearing.md``).

Nondimensional description of the film (``bearing.md`` section 1): ``length_ratio`` is
``L / D``; positions are over the radial clearance ``c``, pressures over
``mu w R^2 / c^2`` and forces over ``F_S = mu w L R^3 / c^2``.

:class:`Grooves` are symmetric herringbone grooves over the bearing's length, on the
stationary ``"sleeve"`` (Yen's (2005) configuration) or on the rotating ``"journal"``; the
angle is in degrees **from the circumferential direction** (90 would be axial grooves).
The apex at the mid-plane points in the direction in which the smooth surface moves
relative to the grooved one, so the grooves pump towards the mid-plane.

Film forces and what follows from them (the guide's "Journal bearings"):
:func:`film_force` (force, pressure field), :func:`equilibrium` (journal position under a
load), :func:`coefficients` (linearised stiffness and damping), :func:`stability` (whirl
threshold of a rigid rotor), :func:`plot_pressure`; :class:`Dimensions` converts to and
from SI units.

Conventions: the fixed frame ``(x, y)``, spin ``w > 0`` counter-clockwise; the journal
centre at ``c (x, y)``, velocity ``c w (x', y')``; angles in radians. A force's
``radial`` component is along the line of centres, positive towards the bearing centre
(restoring), its ``tangential`` one along ``(-sin phi, cos phi)`` (the direction of
rotation), ``phi`` the direction of the journal centre (and of the minimum film). The
**attitude** angle is ``atan2(tangential, radial)``: the journal lies at the load's
direction turned by the attitude in the direction of rotation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from . import _check
from ._geometry import CAVITATION as CAVITATION
from ._geometry import CELLS_PER_PITCH as CELLS_PER_PITCH
from ._geometry import MODELS as MODELS
from ._geometry import PLAIN_GRID as PLAIN_GRID
from ._geometry import SIDES as SIDES
from ._geometry import Bearing, Grooves, _bearing, default_grid
from ._groove_study import groove_study, plot_groove_study
from ._rotor import (
    RotorImpulse,
    RotorOnBearing,
    RotorTrajectory,
    SpinUp,
    plot_trajectory,
    rotor_equilibrium,
    simulate_rotor,
)
from ._style import Summarised
from .exceptions import ParameterError, ParameterTypeError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "Bearing", "BearingEquilibrium", "Coefficients", "Dimensions", "FilmForce", "Grooves",
    "RotorImpulse", "RotorOnBearing", "RotorTrajectory", "SpinUp", "Stability", "coefficients",
    "default_grid", "equilibrium", "film_force", "plot_pressure", "plot_trajectory",
    "rotor_equilibrium", "simulate_rotor", "stability", "groove_study", "plot_groove_study",
]

# The geometry lives in ._geometry, which the rotor and the groove study (re-exported
# below) import without importing this module; shown as this module's.
for _obj in (Bearing, Grooves, default_grid):
    _obj.__module__ = __name__


def _pair(name: str, v: Any) -> tuple[float, float]:
    items = _check.sequence(name, v)
    if len(items) != 2:
        raise ParameterError(name, f"must be two numbers (x, y), got {len(items)}",
                             allowed="two finite numbers", value=v)
    x, y = (_check.real(f"{name}[{k}]", items[k], finite=True) for k in range(2))
    return x, y


@dataclass(frozen=True)
class Dimensions:
    """Physical size of a bearing, SI units: journal ``radius`` R [m], ``length`` L [m],
    radial ``clearance`` c [m] and ``viscosity`` mu [Pa s]. The nondimensional film
    (``length_ratio`` = L/D) converts with the scales below at spin ``speed`` w [rad/s]."""

    radius: float
    length: float
    clearance: float
    viscosity: float

    def __post_init__(self) -> None:
        for name in ("radius", "length", "clearance", "viscosity"):
            object.__setattr__(self, name, _check.real(name, getattr(self, name), 0.0,
                                                      lo_open=True, finite=True))
        if self.clearance >= self.radius:
            raise ParameterError("clearance", "must be smaller than the radius",
                                 allowed=f"(0, {self.radius})", value=self.clearance)

    @property
    def length_ratio(self) -> float:
        """``L / D``."""
        return self.length / (2.0 * self.radius)

    def force_scale(self, speed: float) -> float:
        """``F_S = mu w L R^3 / c^2`` [N]: forces of this module are in ``F_S``."""
        w = _check.real("speed", speed, 0.0, lo_open=True, finite=True)
        return self.viscosity * w * self.length * self.radius**3 / self.clearance**2

    def pressure_scale(self, speed: float) -> float:
        """``mu w R^2 / c^2`` [Pa]: pressures of this module are in this unit."""
        w = _check.real("speed", speed, 0.0, lo_open=True, finite=True)
        return self.viscosity * w * self.radius**2 / self.clearance**2

    def stiffness_scale(self, speed: float) -> float:
        """``F_S / c`` [N/m], the unit of :func:`coefficients`' ``K``."""
        return self.force_scale(speed) / self.clearance

    def damping_scale(self, speed: float) -> float:
        """``F_S / (c w)`` [N s/m], the unit of :func:`coefficients`' ``C``."""
        return self.force_scale(speed) / (self.clearance * speed)

    def sommerfeld(self, speed: float, load: float) -> float:
        """Sommerfeld number ``S = mu N L D (R/c)^2 / W``, ``N = w / 2 pi`` rev/s, load
        ``W`` [N]."""
        w = _check.real("load", load, 0.0, lo_open=True, finite=True)
        n = _check.real("speed", speed, 0.0, lo_open=True, finite=True) / (2.0 * math.pi)
        return (self.viscosity * n * self.length * 2.0 * self.radius
                * (self.radius / self.clearance) ** 2 / w)

    def force(self, f: FilmForce, speed: float) -> tuple[float, float]:
        """A film force's ``(F_x, F_y)`` in newtons."""
        _film_force("f", f)
        k = self.force_scale(speed)
        return (f.fx * k, f.fy * k)

    def pressure(self, f: FilmForce, speed: float) -> npt.NDArray[np.float64]:
        """A film force's pressure field in pascals (``film_force(..., field=True)``)."""
        _film_force("f", f)
        if f.pressure is None:
            raise ParameterError("field", "the film force carries no pressure field: "
                                 "call film_force(..., field=True)")
        return f.pressure * self.pressure_scale(speed)


@dataclass(frozen=True, repr=False)
class FilmForce(Summarised):
    """The film's force on the journal, nondimensional (module doc: units, conventions).

    ``fx, fy``: fixed frame, units ``F_S``; ``radial`` (positive towards the centre) and
    ``tangential`` (positive in the direction of rotation); ``eccentricity`` ``e / c``;
    ``position_angle`` ``phi`` of the journal centre, radians; ``attitude`` radians
    (``atan2(tangential, radial)``); ``load`` = ``|F| / F_S``; ``sommerfeld`` = ``S = mu N L D
    (R/c)^2 / W = 1 / (pi |F| / F_S)`` with this force as the load ``W``; ``peak_pressure``
    over ``mu w R^2 / c^2``; ``min_film`` ``h_min / c`` (over the lands). With
    ``field=True``: ``pressure[i, j]`` at ``(theta[i], zeta[j])``, ``zeta = z / R`` in
    ``[-L/D, L/D]``."""

    fx: float
    fy: float
    radial: float
    tangential: float
    eccentricity: float
    position_angle: float
    attitude: float
    load: float
    sommerfeld: float
    peak_pressure: float
    min_film: float
    pressure: npt.NDArray[np.float64] | None = None
    theta: npt.NDArray[np.float64] | None = None
    zeta: npt.NDArray[np.float64] | None = None

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        grid = ("no pressure field" if self.pressure is None
                else "pressure field {}x{}".format(*self.pressure.shape))
        head = (f"FilmForce ε={self.eccentricity:.4g} load={self.load:.4g} "
                f"attitude={math.degrees(self.attitude):.1f}° S={self.sommerfeld:.4g} ({grid})")
        return head, [("eccentricity e/c", self.eccentricity),
                      ("F_x, F_y (F_S)", f"{self.fx:.4g}, {self.fy:.4g}"),
                      ("radial, tangential (F_S)", f"{self.radial:.4g}, {self.tangential:.4g}"),
                      ("attitude (deg)", math.degrees(self.attitude)),
                      ("Sommerfeld S", self.sommerfeld), ("peak pressure", self.peak_pressure),
                      ("minimum film h/c", self.min_film), ("field", grid)]

    def plot(self, ax: Axes | None = None) -> Figure:
        """The pressure field (:func:`plot_pressure`; needs ``field=True``); returns the
        figure."""
        return plot_pressure(self, ax=ax)


def _film_force(name: str, f: Any) -> FilmForce:
    if not isinstance(f, FilmForce):
        raise ParameterTypeError(name, f"must be a ballbal.bearing.FilmForce, got "
                                 f"{type(f).__name__}", allowed="FilmForce", value=f)
    return f


def film_force(bearing: Bearing, position: Any, velocity: Any = (0.0, 0.0), *,
               field: bool = False, tau: float = 0.0) -> FilmForce:
    """Film force at journal ``position`` ``(x, y)`` (units ``c``, eccentricity below 1)
    and ``velocity`` ``(x', y')`` (units ``c w``); ``tau`` is the journal's angle ``w t``
    (only journal grooves of the ``finite`` model depend on it). ``field=True`` adds the
    pressure field."""
    from . import _native

    b = _bearing(bearing)
    d = _native.bearing_force(b, _pair("position", position), _pair("velocity", velocity),
                              _check.real("tau", tau, finite=True),
                              _check.boolean("field", field))
    return FilmForce(load=math.hypot(d["fx"], d["fy"]), **d)


@dataclass(frozen=True, repr=False)
class BearingEquilibrium(Summarised):
    """Static journal position under a load: ``position`` ``(x, y)`` (units ``c``),
    ``eccentricity``, ``attitude`` (radians from the load's direction to the journal's, in
    the direction of rotation), ``load`` ``(W_x, W_y)`` in ``F_S``, ``sommerfeld`` ``S = 1
    / (pi |W| / F_S)``, Newton ``iterations``."""

    position: tuple[float, float]
    eccentricity: float
    attitude: float
    load: tuple[float, float]
    sommerfeld: float
    iterations: int

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        head = (f"BearingEquilibrium ε={self.eccentricity:.4g} "
                f"attitude={math.degrees(self.attitude):.1f}° S={self.sommerfeld:.4g} "
                f"at ({self.position[0]:.4g}, {self.position[1]:.4g})")
        return head, [("position x, y (c)", f"{self.position[0]:.4g}, {self.position[1]:.4g}"),
                      ("eccentricity e/c", self.eccentricity),
                      ("attitude (deg)", math.degrees(self.attitude)),
                      ("load W_x, W_y (F_S)", f"{self.load[0]:.4g}, {self.load[1]:.4g}"),
                      ("Sommerfeld S", self.sommerfeld), ("Newton iterations", self.iterations)]

    def plot(self, ax: Any = None) -> Any:
        """The journal's position inside the clearance circle and the load's direction;
        returns the axes."""
        from ._figures import bearing_equilibrium

        return bearing_equilibrium(self, ax)


def _load(load: Any, dimensions: Dimensions | None, speed: float | None) -> tuple[float, float]:
    """The load in ``F_S``: a magnitude (along ``-y``) or ``(W_x, W_y)``; in newtons with
    ``dimensions`` and ``speed``."""
    if _check.is_real(load):
        w = (0.0, -_check.real("load", load, 0.0, lo_open=True, finite=True))
    else:
        w = _pair("load", load)
        if w == (0.0, 0.0):
            raise ParameterError("load", "must not be zero", allowed="|load| > 0")
    if _dimensions(dimensions, speed) is None:
        return w
    assert dimensions is not None and speed is not None
    k = dimensions.force_scale(speed)
    w = (w[0] / k, w[1] / k)
    if not (math.isfinite(w[0]) and math.isfinite(w[1])):
        raise ParameterError("load", f"{load!r:.60} N is {w} in F_S at these dimensions and "
                             "speed: too large to be a film load", value=load)
    return w


def _dimensions(dimensions: Any, speed: Any) -> Dimensions | None:
    """``dimensions`` (or None), checked with the ``speed`` it needs."""
    if dimensions is None:
        if speed is not None:
            raise ParameterError("speed", "a speed needs dimensions= (the results are then "
                                 "in SI units)")
        return None
    if not isinstance(dimensions, Dimensions):
        raise ParameterTypeError("dimensions", f"must be ballbal.bearing.Dimensions, got "
                                 f"{type(dimensions).__name__}", allowed="Dimensions or None",
                                 value=dimensions)
    if speed is None:
        raise ParameterError("speed", "dimensions= needs the speed [rad/s]")
    _check.real("speed", speed, 0.0, lo_open=True, finite=True)
    return dimensions


def equilibrium(bearing: Bearing, load: Any, *, dimensions: Dimensions | None = None,
                speed: float | None = None) -> BearingEquilibrium:
    """Journal position where the film carries ``load``: a magnitude (along ``-y``,
    gravity) or a vector ``(W_x, W_y)``, in ``F_S``, or in newtons with ``dimensions`` and
    ``speed`` [rad/s]. Newton on the two coordinates."""
    from . import _native

    w = _load(load, dimensions, speed)
    d = _native.bearing_equilibrium(_bearing(bearing), w)
    return BearingEquilibrium(
        position=(d["x"], d["y"]), eccentricity=d["eccentricity"], attitude=d["attitude"],
        load=w, sommerfeld=1.0 / (math.pi * math.hypot(*w)), iterations=d["iterations"],
    )


@dataclass(frozen=True, repr=False)
class Coefficients(Summarised):
    """Linearised film at a static position, ``f(q0 + dq, dq') ~ f(q0) - K dq - C dq'``,
    ``[i, j]`` = force ``i`` per displacement (velocity) ``j``, ``x, y`` fixed frame:
    ``k`` in ``F_S / c``, ``c`` in ``F_S / (c w)``; ``k_si`` [N/m] and ``c_si`` [N s/m] when
    dimensions and speed are given. No ``plot``: eight numbers, all in its summary."""

    k: npt.NDArray[np.float64]
    c: npt.NDArray[np.float64]
    k_si: npt.NDArray[np.float64] | None = None
    c_si: npt.NDArray[np.float64] | None = None

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        def m(a: Any) -> str:
            return "[[{:.4g}, {:.4g}], [{:.4g}, {:.4g}]]".format(*np.asarray(a).ravel())
        head = f"Coefficients K={m(self.k)} C={m(self.c)}"
        rows: list[tuple[str, Any]] = [("K (F_S/c)", m(self.k)), ("C (F_S/(c ω))", m(self.c))]
        if self.k_si is not None and self.c_si is not None:
            rows += [("K (N/m)", m(self.k_si)), ("C (N s/m)", m(self.c_si))]
        return head, rows


def coefficients(bearing: Bearing, position: Any, *, dimensions: Dimensions | None = None,
                 speed: float | None = None) -> Coefficients:
    """Stiffness and damping at ``position`` (a static journal position, units ``c``):
    derivatives of the discrete film from one factorisation for the finite and
    narrow-groove models (half-Sommerfeld or no cavitation), central differences of the
    force otherwise."""
    from . import _native

    b, q = _bearing(bearing), _pair("position", position)
    dims = _dimensions(dimensions, speed)
    k, c = _native.bearing_coefficients(b, q)
    if dims is None:
        return Coefficients(k=k, c=c)
    assert speed is not None
    return Coefficients(k=k, c=c, k_si=k * dims.stiffness_scale(speed),
                        c_si=c * dims.damping_scale(speed))


@dataclass(frozen=True, repr=False)
class Stability(Summarised):
    """Whirl threshold of a rigid rotor (mass ``M``, fixed frame, no balls) on the bearing
    at the equilibrium under the load ``W``.

    ``threshold_speed``: the spin at the threshold over ``sqrt(W / (M c))`` (``sqrt(g / c)``
    for a weight), at this operating point (this Sommerfeld number): faster whirls;
    ``inf`` stable at every speed, ``0`` unstable at every speed. ``whirl_ratio``: whirl
    over spin frequency at the threshold. ``critical_mass``: the mass parameter ``M c w^2 /
    F_S`` there. Also the ``equilibrium`` and the ``coefficients`` there."""

    threshold_speed: float
    whirl_ratio: float
    critical_mass: float
    equilibrium: BearingEquilibrium
    coefficients: Coefficients

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        head = (f"Stability threshold speed={self.threshold_speed:.4g} "
                f"whirl ratio={self.whirl_ratio:.4g} critical mass={self.critical_mass:.4g} "
                f"at ε={self.equilibrium.eccentricity:.4g}")
        return head, [("threshold speed", self.threshold_speed),
                      ("whirl ratio", self.whirl_ratio), ("critical mass", self.critical_mass),
                      ("eccentricity e/c", self.equilibrium.eccentricity),
                      ("Sommerfeld S", self.equilibrium.sommerfeld)]

    def plot(self, ax: Any = None) -> Any:
        """The equilibrium it was computed at (:meth:`BearingEquilibrium.plot`)."""
        return self.equilibrium.plot(ax)


def stability(bearing: Bearing, load: Any, *, dimensions: Dimensions | None = None,
              speed: float | None = None) -> Stability:
    """Rigid-rotor whirl threshold under ``load`` (as :func:`equilibrium`'s), from the
    linearised film (Lund's closed form for one film)."""
    from . import _native

    w = _load(load, dimensions, speed)
    d = _native.bearing_stability(_bearing(bearing), w)
    eq = BearingEquilibrium(
        position=(d["x"], d["y"]), eccentricity=d["eccentricity"], attitude=d["attitude"],
        load=w, sommerfeld=1.0 / (math.pi * math.hypot(*w)), iterations=0,
    )
    return Stability(threshold_speed=d["threshold_speed"], whirl_ratio=d["whirl_ratio"],
                     critical_mass=d["critical_mass"], equilibrium=eq,
                     coefficients=Coefficients(k=d["k"], c=d["c"]))


def plot_pressure(force_or_bearing: FilmForce | Bearing, position: Any = None,
                  velocity: Any = (0.0, 0.0), *, ax: Axes | None = None) -> Figure:
    """Contour of the film pressure over ``theta`` (degrees) and ``zeta = z / R``, the
    minimum film marked. Give a :class:`FilmForce` computed with ``field=True``, or a
    :class:`Bearing` and a ``position`` (and ``velocity``)."""
    from .plot import _pyplot

    _check.axes("ax", ax)
    if isinstance(force_or_bearing, Bearing):
        if position is None:
            raise ParameterError("position", "a bearing needs the journal position")
        f = film_force(force_or_bearing, position, velocity, field=True)
    elif isinstance(force_or_bearing, FilmForce):
        f = force_or_bearing
    else:
        raise ParameterTypeError("force_or_bearing", f"must be a FilmForce or a Bearing, got "
                                 f"{type(force_or_bearing).__name__}",
                                 allowed="FilmForce, Bearing", value=force_or_bearing)
    if f.pressure is None or f.theta is None or f.zeta is None:
        raise ParameterError("force_or_bearing", "the film force carries no pressure "
                             "field: call film_force(..., field=True)")
    plt = _pyplot()
    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 3.5))
    else:
        fig = ax.figure
    cs = ax.contourf(np.degrees(f.theta), f.zeta, f.pressure.T, levels=24, cmap="viridis")
    fig.colorbar(cs, ax=ax, label="P = p c² / (μ ω R²)")
    phi = math.degrees(f.position_angle) % 360.0
    ax.axvline(phi, color="w", ls="--", lw=1.0, label=f"minimum film h/c = {f.min_film:.3g}")
    ax.set_xlabel(r"$\theta$ (deg)")
    ax.set_ylabel(r"$z/R$")
    ax.set_title(f"ε = {f.eccentricity:.3g}, attitude {math.degrees(f.attitude):.1f}°, "
                 f"P_max = {f.peak_pressure:.3g}")
    ax.legend(loc="upper right", fontsize="small")
    return fig
