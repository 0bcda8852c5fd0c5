"""ballbal: nonlinear dynamics of automatic ball balancers, on a Rust core."""

from ._native import __version__
from .analysis import (
    Equilibrium,
    PeriodicSolution,
    equilibria,
    periodic,
    simulate,
)
from .model import Balancer, from_seed003, zeta_from_log_decrement
from .scan import scan

__all__ = [
    "Balancer",
    "Equilibrium",
    "PeriodicSolution",
    "__version__",
    "equilibria",
    "from_seed003",
    "periodic",
    "scan",
    "simulate",
    "zeta_from_log_decrement",
]
