"""Continuation and bifurcations: branches of solutions in one parameter with located
bifurcations, branch switching, and two-parameter bifurcation curves."""

from ballbal._branch import Branch, Continuation, Curve
from ballbal._eq_continuation import (
    equilibrium_branch,
    equilibrium_curve,
    switch_equilibrium,
)
from ballbal._po_continuation import periodic_branch
from ballbal._po_curves import periodic_curve
from ballbal._po_switch import switch
from ballbal.model import Seed003, from_seed003

__all__ = ["Branch", "Continuation", "Curve", "Seed003", "equilibrium_branch",
           "equilibrium_curve", "from_seed003", "periodic_branch", "periodic_curve", "switch",
           "switch_equilibrium"]
