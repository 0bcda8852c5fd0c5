"""ballbal: nonlinear dynamics of automatic ball balancers, on a Rust core."""

from . import (
    basins,
    bearing,
    calibration,
    continuation,
    data,
    design,
    exceptions,
    rig,
    sweep,
)
from ._native import __version__
from .accuracy import accuracy_cost, plot_accuracy_cost
from .analysis import (
    Equilibrium,
    PeriodicSolution,
    equilibria,
    periodic,
    simulate,
)
from .balance import balance_map, balanced_state, plot_balance_map
from .exceptions import ScanInterrupted
from .model import Balancer, from_disk_units, zeta_from_log_decrement
from .options import (
    Collocation,
    Floquet,
    GuessSearch,
    HarmonicBalance,
    PeriodicOptions,
    ScanOptions,
)
from .scan import flat, read_scan, scan, scan_meta
from .scene import (
    AnisotropicSupport,
    BearingSupport,
    Impulse,
    Ramp,
    Scene,
    Tilt,
    load_scene,
    to_bearing,
)
from .shaft import ShaftUnits, from_shaft_units
from .spectrum import (
    Vibration,
    label_peaks,
    line_spectrum,
    signal_spectrum,
    vibration,
)
from .transient import (
    DisturbanceResponse,
    RunUp,
    disturbance_response,
    run_up,
    track_damping_study,
)

__all__ = [
    "AnisotropicSupport",
    "Balancer",
    "BearingSupport",
    "Collocation",
    "DisturbanceResponse",
    "Equilibrium",
    "Floquet",
    "GuessSearch",
    "HarmonicBalance",
    "Impulse",
    "ScanInterrupted",
    "PeriodicOptions",
    "PeriodicSolution",
    "Ramp",
    "RunUp",
    "ScanOptions",
    "Scene",
    "ShaftUnits",
    "Tilt",
    "Vibration",
    "__version__",
    "accuracy_cost",
    "balance_map",
    "balanced_state",
    "basins",
    "bearing",
    "calibration",
    "continuation",
    "disturbance_response",
    "equilibria",
    "data",
    "design",
    "exceptions",
    "flat",
    "from_disk_units",
    "from_shaft_units",
    "label_peaks",
    "line_spectrum",
    "load_scene",
    "rig",
    "periodic",
    "plot_accuracy_cost",
    "plot_balance_map",
    "read_scan",
    "run_up",
    "scan",
    "scan_meta",
    "signal_spectrum",
    "simulate",
    "sweep",
    "to_bearing",
    "track_damping_study",
    "vibration",
    "zeta_from_log_decrement",
]
