from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

Effects = (
    tuple[float, tuple[float, float, float] | None, float,
          tuple[float, float, float, float] | None,
          tuple[float, float, float, float, float] | None, bool]
    | None
)
PlanarArgs = tuple[float, float, list[float], float, float, list[float]]

__version__: str

def simulate(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    y0: npt.NDArray[np.float64], t0: float, t_eval: npt.NDArray[np.float64], rtol: float,
    atol: list[float], effects: Effects = None, max_steps: int = 10_000_000,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int, int]: ...
def validate(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    effects: Effects = None,
) -> None: ...
def equilibria(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    effects: Effects = None,
) -> list[dict[str, Any]]: ...
def balanced_states(
    points: list[tuple[PlanarArgs, Effects]],
) -> list[dict[str, Any] | None]: ...
def periodic(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    pattern: str, n_harm: int, samples: int | None, tol: float, step_tol: float, max_iter: int,
    guess_omega: float | None, guess_coeffs: npt.NDArray[np.float64] | None, floquet: bool,
    f_rtol: float, f_atol: float, margin: float, max_steps: int, settle: float, window: float,
    guess_rtol: float, auto: float | None, n_max: int, hill: bool, max_closure: float = 6.0,
    max_trivial: float = 0.1, max_tail: float = 0.25, effects: Effects = None,
) -> dict[str, Any]: ...
def orbit_closure(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    sol_omega: float, coeffs: npt.NDArray[np.float64], winding: list[float], rtol: float,
    atol: float, effects: Effects = None,
) -> float: ...
def scan(
    mu: float, zeta: float, zeta_b: list[float], delta: float, omega: float, eta: list[float],
    names: list[str], values: list[list[float]], patterns: list[str], n_harm: int,
    samples: int | None, tol: float, step_tol: float, max_iter: int, floquet: bool,
    f_rtol: float, f_atol: float, margin: float, max_steps: int, settle: float, window: float,
    guess_rtol: float, auto: float | None, n_max: int, hill: bool, seeds: int, starts: int,
    chunk: int, max_tail: float, threads: int,
    chunks: list[int], on_chunk: Callable[[int, dict[str, Any]], None],
    effects: Effects = None, block: int | None = None,
) -> None: ...
def default_chunk(lens: list[int]) -> int: ...
def certificate_seconds() -> float: ...
