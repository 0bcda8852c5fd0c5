"""Continuation: branches of solutions in one parameter with located bifurcations,
branch switching, and two-parameter bifurcation curves."""

from ballbal._eq_continuation import (
    equilibrium_branch,
    equilibrium_curve,
    from_seed003,
    switch_equilibrium,
)

__all__ = ["equilibrium_branch", "equilibrium_curve", "from_seed003", "switch_equilibrium"]
