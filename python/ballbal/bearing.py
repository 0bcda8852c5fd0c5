"""Hydrodynamic journal bearings, plain and herringbone-grooved (seed 002, ``bearing.md``).

Nondimensional description of the film (``bearing.md`` section 1): ``length_ratio`` is
``L / D``; positions are over the radial clearance ``c``, pressures over
``mu w R^2 / c^2`` and forces over ``F_S = mu w L R^3 / c^2``.

:class:`Grooves` are symmetric herringbone grooves over the bearing's length, on the
stationary ``"sleeve"`` (the seed's configuration) or on the rotating ``"journal"``; the
angle is in degrees **from the circumferential direction** (90 would be axial grooves).
The apex at the mid-plane points in the direction in which the smooth surface moves
relative to the grooved one, so the grooves pump towards the mid-plane.
"""

from __future__ import annotations

from dataclasses import dataclass

from . import _check

MODELS = ("short", "long", "finite", "narrow_groove")
CAVITATION = ("half_sommerfeld", "reynolds", "none")
SIDES = ("sleeve", "journal")

#: Finite-volume grid of a plain bearing when none is given: ``(n_theta, n_zeta)``.
PLAIN_GRID = (128, 32)
#: Cells per groove pitch of a grooved bearing's default grid (``n_theta`` is this times
#: the groove count, at least 256).
CELLS_PER_PITCH = 16


@dataclass(frozen=True)
class Grooves:
    """Herringbone grooves: ``count`` grooves at ``angle`` degrees from the circumferential
    direction, ``depth_ratio`` = groove depth / clearance, ``width_ratio`` = groove width /
    pitch in (0, 1), over the central ``grooved_length`` fraction of the length."""

    count: int
    angle: float
    depth_ratio: float
    width_ratio: float = 0.5
    grooved_length: float = 1.0
    side: str = "sleeve"

    def __post_init__(self) -> None:
        object.__setattr__(self, "count", _check.integer("grooves.count", self.count, 1))
        for name in ("angle", "depth_ratio", "width_ratio", "grooved_length"):
            object.__setattr__(
                self, name, _check.real(f"grooves.{name}", getattr(self, name), finite=True)
            )
        object.__setattr__(self, "side", _check.string("grooves.side", self.side))
        _validate(Bearing(grooves=self))


def default_grid(grooves: Grooves | None) -> tuple[int, int]:
    """The finite-volume grid used when a bearing gives none."""
    if grooves is None:
        return PLAIN_GRID
    per = max(CELLS_PER_PITCH, -(-256 // grooves.count))
    return (grooves.count * per, 32)


@dataclass(frozen=True)
class Bearing:
    """A journal bearing: ``length_ratio`` = L/D, optional :class:`Grooves`, the
    ``cavitation`` condition (``"half_sommerfeld"``, the seed's and the default;
    ``"reynolds"``; ``"none"``), the film ``model`` (``"short"``, ``"long"``,
    ``"finite"``, ``"narrow_groove"``) and the finite model's ``grid`` ``(n_theta,
    n_zeta)`` (``None``: :func:`default_grid`)."""

    length_ratio: float = 1.0
    grooves: Grooves | None = None
    cavitation: str = "half_sommerfeld"
    model: str = "finite"
    grid: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "length_ratio", _check.real("length_ratio", self.length_ratio, finite=True)
        )
        object.__setattr__(self, "cavitation", _check.string("cavitation", self.cavitation))
        object.__setattr__(self, "model", _check.string("model", self.model))
        if self.grid is None:
            object.__setattr__(self, "grid", default_grid(self.grooves))
        else:
            g = _check.sequence("grid", self.grid)
            if len(g) != 2:
                from .exceptions import ParameterError

                raise ParameterError(
                    "grid", f"grid must be (n_theta, n_zeta), got {self.grid!r}",
                    allowed="two integers",
                )
            object.__setattr__(
                self,
                "grid",
                (_check.integer("grid.n_theta", g[0]), _check.integer("grid.n_zeta", g[1])),
            )
        if self.grooves is not None and not isinstance(self.grooves, Grooves):
            from .exceptions import ParameterTypeError

            raise ParameterTypeError(
                "grooves",
                f"grooves must be ballbal.bearing.Grooves or None, got "
                f"{type(self.grooves).__name__}",
                allowed="Grooves or None",
            )
        _validate(self)


def _validate(bearing: Bearing) -> None:
    from . import _native

    _native.validate_bearing(bearing)
