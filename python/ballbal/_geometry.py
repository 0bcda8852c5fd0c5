"""A journal bearing's geometry and film model (:class:`Bearing`, :class:`Grooves`), shown
and documented as :mod:`ballbal.bearing`'s: apart from it so that the rigid rotor and the
groove study, which :mod:`ballbal.bearing` re-exports, use them without importing it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import _check, _native
from .exceptions import ParameterError, ParameterTypeError

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
    pitch in (0, 1), over the central ``grooved_length`` fraction of the length. At most
    :data:`~ballbal._check.MAX_GROOVES` grooves, at most ``1e3`` clearances deep (deeper
    grooves change no force)."""

    count: int
    angle: float
    depth_ratio: float
    width_ratio: float = 0.5
    grooved_length: float = 1.0
    side: str = "sleeve"

    def __post_init__(self) -> None:
        object.__setattr__(self, "count", _check.integer("grooves.count", self.count, 1,
                                                         _check.MAX_GROOVES))
        for name in ("angle", "depth_ratio", "width_ratio", "grooved_length"):
            object.__setattr__(
                self, name, _check.real(f"grooves.{name}", getattr(self, name), finite=True)
            )
        object.__setattr__(self, "side", _check.string("grooves.side", self.side))
        _validate(Bearing(grooves=self))


def default_grid(grooves: Grooves | None, model: str = "finite") -> tuple[int, int]:
    """The finite-volume grid used when a bearing gives none (narrow-groove theory need
    not resolve the grooves: the plain grid)."""
    if grooves is None or model == "narrow_groove":
        return PLAIN_GRID
    per = max(CELLS_PER_PITCH, -(-256 // grooves.count))
    return (grooves.count * per, 32)


@dataclass(frozen=True)
class Bearing:
    """A journal bearing: ``length_ratio`` = L/D, optional :class:`Grooves`, the
    ``cavitation`` condition (``"half_sommerfeld"``, the seed's and the default;
    ``"reynolds"``; ``"none"``), the film ``model`` (``"short"``, ``"long"``,
    ``"finite"``, ``"narrow_groove"``) and the grid ``(n_theta, n_zeta)`` of the finite
    and narrow-groove models (``None``: :func:`default_grid`); at most
    :data:`~ballbal._check.MAX_BEARING_CELLS` cells
    (:data:`~ballbal._check.MAX_NARROW_GROOVE_CELLS` narrow-groove), ``n_theta`` at most
    :data:`~ballbal._check.MAX_BEARING_THETA` and ``n_zeta`` at most
    :data:`~ballbal._check.MAX_BEARING_ZETA` (so that Ctrl-C stops a film solve within
    about a second).

    ``"narrow_groove"`` is Vohr and Chow's narrow-groove theory: the grooves smoothed into
    an anisotropic film, exact as the groove count grows, on a grid that need not resolve
    them (without grooves it is the plain finite film)."""

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
        # Before the default grid, which reads the grooves' count.
        if self.grooves is not None and not isinstance(self.grooves, Grooves):
            raise ParameterTypeError(
                "grooves",
                f"grooves must be ballbal.bearing.Grooves or None, got "
                f"{type(self.grooves).__name__}",
                allowed="Grooves or None", value=self.grooves,
            )
        narrow = self.model == "narrow_groove"
        if self.grid is None:
            object.__setattr__(self, "grid",
                               _grid(*default_grid(self.grooves, self.model), narrow))
        else:
            g = _check.sequence("grid", self.grid)
            if len(g) != 2:
                raise ParameterError(
                    "grid", f"grid must be (n_theta, n_zeta), got {self.grid!r:.60}",
                    allowed="two integers",
                )
            object.__setattr__(self, "grid", _grid(g[0], g[1], narrow))
        _validate(self)


def _grid(n_theta: Any, n_zeta: Any, narrow: bool) -> tuple[int, int]:
    """A grid's cell counts, refused before any solve when one axis or the total is
    above its bound (:data:`~ballbal._check.MAX_BEARING_CELLS`, for the narrow-groove
    model :data:`~ballbal._check.MAX_NARROW_GROOVE_CELLS`, and the per-axis ones); the
    smallest sizes are the core's to check."""
    nt = _check.integer("grid.n_theta", n_theta, 0, _check.MAX_BEARING_THETA)
    nz = _check.integer("grid.n_zeta", n_zeta, 0, _check.MAX_BEARING_ZETA)
    most = _check.MAX_NARROW_GROOVE_CELLS if narrow else _check.MAX_BEARING_CELLS
    if nt * nz > most:
        name = "grid.n_theta" if nt >= nz else "grid.n_zeta"
        what = "the narrow-groove grid" if narrow else "the grid"
        raise ParameterError(
            name, f"{what} ({nt}, {nz}) has {nt * nz} cells, at most {most} "
            "(n_theta * n_zeta)", allowed=f"n_theta * n_zeta <= {most}", value=(nt, nz))
    return nt, nz


def _validate(bearing: Bearing) -> None:
    _native.validate_bearing(bearing)


def _bearing(bearing: Any) -> Bearing:
    if not isinstance(bearing, Bearing):
        raise ParameterTypeError(
            "bearing", f"must be ballbal.bearing.Bearing, got {type(bearing).__name__}",
            allowed="Bearing",
        )
    return bearing
