"""Track damping from the oil: the model's ``zeta_b`` of a ball moving through an
oil-filled track, from the oil's viscosity and the track's geometry.

A ball of radius ``a`` moving at speed ``U`` through a viscous oil at small Reynolds
number feels Stokes' drag ``F = 6 pi mu a U`` [Stokes1851]. In a track the walls are
close, and the drag grows: for a sphere moving along the axis of a cylindrical channel
of radius ``R`` Haberman and Sayre's wall factor [HabermanSayre1958]::

    K(lam) = (1 - 0.75857 lam^5)
             / (1 - 2.1050 lam + 2.0865 lam^3 - 1.7068 lam^5 + 0.72603 lam^6),
    lam = a / R,

multiplies it (1 in open oil, growing without bound as the ball fills the channel).
A real track is not a round tube and the ball rolls on its floor; what that changes
is lumped into one dimensionless ``geometric_factor`` ``kappa``, the same for every
oil in the same track, calibrated once (:func:`geometric_factor`). The viscous
coefficient on the ball's speed relative to the track is then

    c_b = kappa K(a / R) 6 pi mu a,

and the model's track damping ``zeta_b = c_b / (2 m_b w_n)`` ([Tien2011], the
definition of ``zeta_b``; ``m_b`` the ball's mass, ``w_n`` the rig's natural frequency
in rad/s). The track's radius does not enter: ``c_b`` acts on the ball's speed along
the track, whatever the track's radius. ``zeta_b`` is proportional to the viscosity:
that is what lets one calibration transfer between oils, and what
:func:`ballbal.calibration.transfer_oils` tests against measured transitions.

Units: viscosity in Pa s (1 cP = 1e-3 Pa s), lengths in metres, mass in kilograms,
the natural frequency in rpm.
"""

from __future__ import annotations

import math

from . import _check
from .exceptions import ParameterError

__all__ = ["wall_factor", "track_damping", "geometric_factor", "CENTIPOISE"]

#: One centipoise in Pa s.
CENTIPOISE = 1e-3
#: Largest ball-to-channel radius ratio Haberman and Sayre's factor is used to (their
#: series was fitted, and checked against measurement, up to about 0.8).
MAX_RADIUS_RATIO = 0.8
_RPM_TO_RAD = 2.0 * math.pi / 60.0


def wall_factor(ball_radius: float, channel_radius: float | None) -> float:
    """Haberman and Sayre's factor on Stokes' drag [HabermanSayre1958] for a ball of
    radius ``ball_radius`` moving along the axis of a channel of radius
    ``channel_radius`` (metres; half the track's width); 1 when ``channel_radius`` is
    None (no walls). Their ratio is kept below :data:`MAX_RADIUS_RATIO`."""
    a = _check.real("ball_radius", ball_radius, 0.0, math.inf, lo_open=True, hi_open=True)
    if channel_radius is None:
        return 1.0
    r = _check.real("channel_radius", channel_radius, 0.0, math.inf, lo_open=True,
                    hi_open=True)
    lam = a / r
    if lam >= MAX_RADIUS_RATIO:
        raise ParameterError("channel_radius", f"must exceed ball_radius / "
                             f"{MAX_RADIUS_RATIO} = {a / MAX_RADIUS_RATIO:.4g} m (the "
                             f"wall factor's range), got {r:.4g} m",
                             allowed=f"({a / MAX_RADIUS_RATIO:.4g}, inf)", value=r)
    return (1 - 0.75857 * lam**5) / (1 - 2.1050 * lam + 2.0865 * lam**3
                                     - 1.7068 * lam**5 + 0.72603 * lam**6)


def _geometry(ball_radius: float, ball_mass: float, natural_frequency_rpm: float,
              channel_radius: float | None) -> float:
    """``K 6 pi a / (2 m_b w_n)``: ``zeta_b`` per unit viscosity and unit ``kappa``."""
    a = _check.real("ball_radius", ball_radius, 0.0, math.inf, lo_open=True, hi_open=True)
    m = _check.real("ball_mass", ball_mass, 0.0, math.inf, lo_open=True, hi_open=True)
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, math.inf,
                     lo_open=True, hi_open=True)
    return wall_factor(a, channel_radius) * 6.0 * math.pi * a / (2.0 * m * fn * _RPM_TO_RAD)


def track_damping(viscosity: float, *, ball_radius: float, ball_mass: float,
                  natural_frequency_rpm: float, channel_radius: float | None = None,
                  geometric_factor: float = 1.0) -> float:
    """The model's ``zeta_b`` for a ball of ``ball_radius`` [m] and ``ball_mass`` [kg]
    in a track filled with an oil of dynamic ``viscosity`` [Pa s], on a rig of natural
    frequency ``natural_frequency_rpm``: ``kappa K 6 pi mu a / (2 m_b w_n)`` (module
    docstring). ``channel_radius`` [m]: half the track's width, for the wall factor
    :func:`wall_factor` (None: none). ``geometric_factor``: ``kappa``, from
    :func:`geometric_factor` (1: Stokes' drag in the channel, no more)."""
    mu = _check.real("viscosity", viscosity, 0.0, math.inf, hi_open=True)
    kappa = _check.real("geometric_factor", geometric_factor, 0.0, math.inf, lo_open=True,
                        hi_open=True)
    return kappa * mu * _geometry(ball_radius, ball_mass, natural_frequency_rpm,
                                  channel_radius)


def geometric_factor(zeta_b: float, viscosity: float, *, ball_radius: float,
                     ball_mass: float, natural_frequency_rpm: float,
                     channel_radius: float | None = None) -> float:
    """``kappa``: the factor for which :func:`track_damping` gives ``zeta_b`` (a
    calibrated value, e.g. from :func:`ballbal.calibration.calibrate_transition`) at
    ``viscosity`` [Pa s]; the other arguments as there."""
    zb = _check.real("zeta_b", zeta_b, 0.0, math.inf, lo_open=True, hi_open=True)
    mu = _check.real("viscosity", viscosity, 0.0, math.inf, lo_open=True, hi_open=True)
    return zb / (mu * _geometry(ball_radius, ball_mass, natural_frequency_rpm,
                                channel_radius))
