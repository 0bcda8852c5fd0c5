# The native module's functions as rust/py/src/entries.rs declares them (checked by
# `python -m mypy.stubtest ballbal._native` in scripts/test.sh). The model is a
# ballbal.Balancer or ballbal.Scene and the options the dataclasses of ballbal.options,
# read by attribute. pyo3 accepts any sequence for a `Vec`; the stub asks for lists, as
# the facade passes them.
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ._branch import Continuation
from ._rotor import RotorOnBearing
from .basins import BasinOptions
from .bearing import Bearing
from .model import Balancer
from .options import (
    Collocation,
    Floquet,
    GuessSearch,
    HarmonicBalance,
    PeriodicOptions,
    ScanOptions,
)
from .scene import Scene

__all__ = [
    "simulate", "validate", "equilibria", "balanced_states", "event_vocabulary",
    "event_name", "equilibrium_branch",
    "equilibrium_switch", "equilibrium_curve", "periodic", "orbit_closure",
    "balance_map", "scan", "default_chunk", "certificate_seconds", "scan_stage_seconds",
    "hb_stage_profile", "hb_stage_seconds",
    "scan_work_counts", "scan_profile", "scan_wave_order",
    "parameters", "parse_parameter", "ball_parameter_name", "parameter_keys", "check_axes",
    "scan_schema",
    "validate_bearing", "validate_balancer", "validate_harmonic_balance", "validate_floquet",
    "validate_guess", "validate_periodic_options", "validate_continuation",
    "validate_basin_options", "validate_collocation", "collocation_states",
    "collocation_follow",
    "validate_rotor", "rotor_equilibrium", "rotor_from_dimensions", "simulate_rotor",
    "bearing_force", "bearing_equilibrium", "bearing_coefficients", "bearing_stability",
    "basins", "attractor_series", "classify_state",
    "groove_study", "periodic_branch", "periodic_curve", "switch_periodic", "switch_hopf",
    "__version__",
]

__version__: str

# simulate returns (y, theta, accepted steps, rejected steps, right-hand-side evaluations)
def simulate(
    model: Balancer | Scene, y0: npt.NDArray[np.float64], t0: float,
    t_eval: npt.NDArray[np.float64], rtol: float, atol: list[float], max_steps: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int, int]: ...
def validate(model: Balancer | Scene) -> None: ...
def validate_bearing(bearing: Bearing) -> None: ...
# Checks run when an object is made (rust/py/src/checks.rs): the core's own checks.
def validate_balancer(balancer: Balancer) -> None: ...
def validate_harmonic_balance(options: HarmonicBalance) -> None: ...
def validate_floquet(options: Floquet) -> None: ...
def validate_guess(options: GuessSearch) -> None: ...
def validate_periodic_options(options: PeriodicOptions | ScanOptions) -> None: ...
def validate_continuation(options: Continuation) -> None: ...
def validate_basin_options(options: BasinOptions) -> None: ...
def validate_collocation(options: Collocation) -> None: ...
# A collocation orbit's states (rust/py/src/collocation.rs): shape (len(t), 2 d)
def collocation_states(
    mesh: npt.NDArray[np.float64], states: npt.NDArray[np.float64], period: float,
    winding: list[float], t: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]: ...
# Natural continuation of a collocation orbit: lists param, period, mesh_error; ntst
def collocation_follow(
    model: Balancer | Scene, parameter: str, mesh: npt.NDArray[np.float64],
    states: npt.NDArray[np.float64], period: float, winding: list[float], target: float,
    step: float, min_step: float, options: Collocation,
) -> dict[str, Any]: ...
# Film forces (rust/py/src/bearing.rs): dicts of floats, arrays where named.
def bearing_force(
    bearing: Bearing, position: tuple[float, float], velocity: tuple[float, float],
    tau: float, field: bool,
) -> dict[str, Any]: ...
def bearing_equilibrium(bearing: Bearing, load: tuple[float, float]) -> dict[str, Any]: ...
def bearing_coefficients(
    bearing: Bearing, position: tuple[float, float],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def bearing_stability(bearing: Bearing, load: tuple[float, float]) -> dict[str, Any]: ...
def groove_study(
    bearing: Bearing, angle: Sequence[float], depth_ratio: Sequence[float],
    width_ratio: Sequence[float], length_ratio: Sequence[float], count: Sequence[int],
    eccentricity: float, threads: int | None = None,
    progress: Callable[[int], object] | None = None,
) -> dict[str, list[Any]]: ...
def equilibria(model: Balancer | Scene) -> list[dict[str, Any]]: ...
def balanced_states(models: Sequence[Balancer | Scene]) -> list[dict[str, Any] | None]: ...
# disk_units: a ballbal.model.DiskUnits (read by attribute): continue in its parameters
def event_vocabulary() -> list[tuple[str, list[str], str]]: ...
def event_name(text: str, parameter: str = "event") -> str: ...
def equilibrium_branch(model: Balancer | Scene, parameter: str, q: Sequence[float], kind: str,
                       range: tuple[float, float], options: Any, both: bool = False,
                       disk_units: Any = None, at: Sequence[float] | None = None,
                       stop: Sequence[str] | None = None,
                       progress: Callable[[int], object] | None = None) -> dict[str, Any]: ...
def equilibrium_switch(model: Balancer | Scene, parameter: str, x: Sequence[float], p: float,
                       tangent: Sequence[float], range: tuple[float, float],
                       options: Any, disk_units: Any = None,
                       progress: Callable[[int], object] | None = None) -> dict[str, Any]: ...
def equilibrium_curve(model: Balancer | Scene, kind: str, parameter: str, parameter2: str,
                      q: Sequence[float], p1: float, together: bool,
                      range: tuple[float, float], options: Any,
                      disk_units: Any = None,
                      progress: Callable[[int], object] | None = None) -> dict[str, Any]: ...
# (status, equilibrium dict or None) per point: "ok", "no_balance" or "not_converged"
def balance_map(
    model: Balancer | Scene, names: list[str], points: list[list[float]],
) -> list[tuple[str, dict[str, Any] | None]]: ...
def periodic(
    model: Balancer | Scene, pattern: str, options: PeriodicOptions,
    guess: tuple[float, npt.NDArray[np.float64]] | None = None,
    windings: list[int] | None = None,
    homotopy: tuple[list[tuple[str, float]], bool] | None = None,
    method: str = "hb", collocation: Collocation | None = None,
) -> dict[str, Any]: ...
def orbit_closure(
    model: Balancer | Scene, omega: float, coeffs: npt.NDArray[np.float64],
    winding: list[float], rtol: float, atol: float,
) -> float: ...
def scan(
    model: Balancer | Scene, names: list[str], values: list[list[float]], patterns: list[str],
    options: ScanOptions, chunk: int, threads: int, chunks: list[int],
    on_chunk: Callable[[int, dict[str, Any]], None],
) -> None: ...
def default_chunk(lens: list[int]) -> int: ...
def certificate_seconds() -> float: ...
def scan_stage_seconds() -> list[float]: ...
def hb_stage_profile(on: bool) -> None: ...
def hb_stage_seconds() -> list[float]: ...
def scan_work_counts() -> list[int]: ...
def scan_profile() -> list[list[float]]: ...
def scan_wave_order(longest_first: bool) -> None: ...
# The core's parameter registry and result schema (ballbal.scan derives its lists)
def parameters() -> list[dict[str, Any]]: ...
def parse_parameter(name: str) -> tuple[str, int | None]: ...
def ball_parameter_name(key: str, ball: int) -> str: ...
def parameter_keys(model: Balancer | Scene) -> list[str]: ...
def check_axes(model: Balancer | Scene, names: list[str]) -> None: ...
def scan_schema() -> list[tuple[str, str]]: ...

# rust/py/src/rotor.rs: a rigid rotor on one journal bearing (ballbal._rotor)
def validate_rotor(rotor: RotorOnBearing) -> None: ...
def rotor_equilibrium(rotor: RotorOnBearing) -> tuple[float, float]: ...
def rotor_from_dimensions(
    bearing: Bearing, radius: float, length: float, clearance: float, viscosity: float,
    mass: float, speed: float, unbalance: float, g: float,
) -> tuple[float, float, float]: ...
def simulate_rotor(
    rotor: RotorOnBearing, x0: tuple[float, float, float, float], t0: float,
    t_eval: npt.NDArray[np.float64], rtol: float, atol: float, max_steps: int,
    eps_contact: float, stiff_steps: int, method: str, factor_reuse: float | None,
) -> dict[str, Any]: ...
def basins(
    model: Balancer | Scene, starts: list[list[float]], options: BasinOptions, threads: int,
    chunk: int, chunks: list[int], on_chunk: Callable[[int, dict[str, Any]], None],
) -> None: ...
# (omega, coefficients, rotating) of the attractor reached from y0, or None; with
# rotating, over `turns` whole turns per period
def attractor_series(
    model: Balancer | Scene, y0: npt.NDArray[np.float64], n_harm: int, settle: float,
    window: float, rtol: float, atol: float, rotating: list[bool] | None = None,
    turns: int = 1,
) -> tuple[float, npt.NDArray[np.float64], list[bool]] | None: ...
# (one row of basins' columns, the state reached)
def classify_state(
    model: Balancer | Scene, y0: npt.NDArray[np.float64], options: BasinOptions,
) -> tuple[dict[str, Any], npt.NDArray[np.float64]]: ...
def switch_periodic(
    model: Balancer | Scene, parameter: str, omega: float, coeffs: npt.NDArray[np.float64],
    winding: list[float], kind: str, amplitude: float, options: PeriodicOptions,
) -> tuple[dict[str, Any], float, tuple[float, float]]: ...
def switch_hopf(
    model: Balancer | Scene, parameter: str, q: list[float], amplitude: float,
    options: PeriodicOptions,
) -> tuple[dict[str, Any], float, tuple[float, float]]: ...

# rust/py/src/po_continuation.rs: {"points": [dict], "events": [dict], "stop": str}
def periodic_branch(
    model: Balancer | Scene, parameter: str,
    start: tuple[float, npt.NDArray[np.float64], list[float]], p_range: tuple[float, float],
    continuation: Continuation, options: PeriodicOptions, min_omega: float, event_tol: float,
    both: bool = False, at: Sequence[float] | None = None, stop: Sequence[str] | None = None,
    stop_period: float | None = None, method: str = "hb",
    collocation: Collocation | None = None, progress: Callable[[int], object] | None = None,
) -> dict[str, Any]: ...
# {"kind", "together", "points": [solution dict + p1, p2, test, test_*], "special", "stop"}
# special: [{"type", "p1", "p2", "omega", "row", "status" ("confirmed" | "rejected" |
#   "undetermined"), "gap", "residual", "own_residual", "error"}]
def periodic_curve(
    model: Balancer | Scene, kind: str, parameter: str, parameter2: str,
    start: tuple[float, npt.NDArray[np.float64], list[float]], range: tuple[float, float],
    range1: tuple[float, float], continuation: Continuation, options: PeriodicOptions,
    locate_tol: float, progress: Callable[[int], object] | None = None,
) -> dict[str, Any]: ...
