"""Every error ballbal raises on purpose.

Bad input is a :class:`ParameterError` (a ``ValueError``) or :class:`ParameterTypeError`
(also a ``TypeError``): both carry ``.parameter`` (the name as the caller wrote it) and,
where one exists, ``.allowed`` (the allowed range or values as text), so that code can
match on the parameter instead of the message. Failures of the numerics at run time are
:class:`RuntimeError` subclasses. A Rust panic is an :class:`InternalError`, never a
``pyo3_runtime.PanicException``.

The Rust core maps its errors to these classes in one place (the binding's ``to_py``).
"""

from __future__ import annotations

__all__ = [
    "BallbalError",
    "EigenSolverError",
    "IntegrationError",
    "InternalError",
    "NotAutonomousError",
    "ParameterError",
    "ParameterTypeError",
    "ScanInterrupted",
    "ScanStoreError",
    "ScanStoreWarning",
    "StiffError",
]


class BallbalError(Exception):
    """Base class of every exception ballbal raises on purpose."""


class ParameterError(BallbalError, ValueError):
    """A parameter is outside its allowed range or otherwise unusable.

    ``parameter``: its name (``"Omega"``, ``"eta2"`` (the second ball's: balls are
    named from 1, as the coordinates ``b1``, ``b2``), ``"N"``, ``"t_span"``, ...);
    ``allowed``: the allowed range or values as text, or ``None``; ``value``: what was
    given, where it can be shown.
    """

    def __init__(self, parameter: str, message: str, *, allowed: str | None = None,
                 value: object = None) -> None:
        self.parameter = parameter
        self.allowed = allowed
        self.value = value
        self.message = message
        text = message if message.startswith(f"{parameter}:") else f"{parameter}: {message}"
        super().__init__(text)

    def __reduce__(self) -> tuple[object, ...]:
        # Exceptions travel between processes (executors, Dask): keep the fields.
        return (_rebuild, (type(self), self.parameter, self.message, self.allowed, self.value))


def _rebuild(cls: type[ParameterError], parameter: str, message: str, allowed: str | None,
             value: object) -> ParameterError:
    return cls(parameter, message, allowed=allowed, value=value)


class ParameterTypeError(ParameterError, TypeError):
    """A parameter has the wrong type (a string where a number is needed, ...)."""


class NotAutonomousError(BallbalError, ValueError):
    """The analysis needs an autonomous scene (no ramp, gravity or impulse);
    ``effect`` names the effect that makes this one time dependent."""

    def __init__(self, effect: str, message: str | None = None) -> None:
        self.effect = effect
        super().__init__(message or (
            f"this analysis needs an autonomous scene, but the effect '{effect}' makes it "
            "time dependent"))

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.effect, str(self)))


class IntegrationError(BallbalError, RuntimeError):
    """The time integrator could not proceed (step size underflow, step budget spent,
    a non-finite state)."""


class StiffError(IntegrationError):
    """The equations are too stiff for the explicit integrator at these parameters
    (steps limited by stability, not accuracy)."""


class EigenSolverError(BallbalError, RuntimeError):
    """An eigenvalue computation did not converge."""


class InternalError(BallbalError, RuntimeError):
    """A defect in ballbal (a Rust panic caught at the boundary): please report it."""


class ScanStoreError(BallbalError, RuntimeError):
    """A scan directory cannot be used: another process holds its lock, or it belongs
    to a different scan."""


class ScanInterrupted(UserWarning):
    """A scan was stopped (Ctrl-C) before every chunk finished; the table holds the
    finished chunks, and a scan with ``out=`` resumes from them when run again."""


class ScanStoreWarning(UserWarning):
    """A file of a scan directory was damaged (unreadable, truncated, not this scan's):
    it is set aside as ``<name>.damaged`` and recomputed; the message names it."""
