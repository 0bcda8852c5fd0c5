# The native module's functions as rust/py/src/lib.rs declares them (checked by
# `python -m mypy.stubtest ballbal._native` in scripts/test.sh). pyo3 accepts any sequence
# for a `Vec`; the stub asks for lists, as the facade passes them.
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = [
    "simulate", "validate", "equilibria", "balanced_states", "periodic", "orbit_closure",
    "scan", "default_chunk", "certificate_seconds", "__version__",
]

# Private: type aliases of the stub only (the module has no such names).

_Effects = (
    tuple[float, tuple[float, float, float] | None, float,
          tuple[float, float, float, float] | None,
          tuple[float, float, float, float, float] | None, bool]
    | None
)
_PlanarArgs = tuple[float, float, list[float], float, float, list[float]]

__version__: str

# simulate returns (y, theta, accepted steps, rejected steps, right-hand-side evaluations)
def simulate(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    y0: npt.NDArray[np.float64], t0: float, t_eval: npt.NDArray[np.float64], rtol: float,
    atol: list[float], effects: _Effects = None, max_steps: int = 10_000_000,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int, int]: ...
def validate(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    effects: _Effects = None,
) -> None: ...
def equilibria(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    effects: _Effects = None,
) -> list[dict[str, Any]]: ...
def balanced_states(
    points: list[tuple[_PlanarArgs, _Effects]],
) -> list[dict[str, Any] | None]: ...
def periodic(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    pattern: str, n_harm: int, samples: int | None, tol: float, step_tol: float, max_iter: int,
    guess_omega: float | None, guess_coeffs: npt.NDArray[np.float64] | None, floquet: bool,
    f_rtol: float, f_atol: float, margin: float, max_steps: int, settle: float, window: float,
    guess_rtol: float, auto: float | None, n_max: int, hill: bool,
    # The core's MAX_CLOSURE = 6.0, MAX_TRIVIAL = 0.1, MAX_TAIL = 0.25: pyo3 shows a
    # constant default as `...`, so the stub says no more.
    max_closure: float = ..., max_trivial: float = ..., max_tail: float = ...,
    effects: _Effects = None,
) -> dict[str, Any]: ...
def orbit_closure(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    sol_omega: float, coeffs: npt.NDArray[np.float64], winding: list[float], rtol: float,
    atol: float, effects: _Effects = None,
) -> float: ...
def scan(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    names: list[str], values: list[list[float]], patterns: list[str], n_harm: int,
    samples: int | None, tol: float, step_tol: float, max_iter: int, floquet: bool,
    f_rtol: float, f_atol: float, margin: float, max_steps: int, settle: float, window: float,
    guess_rtol: float, auto: float | None, n_max: int, hill: bool, seeds: int, starts: int,
    chunk: int, max_tail: float, threads: int,
    chunks: list[int], on_chunk: Callable[[int, dict[str, Any]], None],
    effects: _Effects = None, block: int | None = None, max_closure: float = ...,
    max_trivial: float = ...,
) -> None: ...
def default_chunk(lens: list[int]) -> int: ...
def certificate_seconds() -> float: ...
