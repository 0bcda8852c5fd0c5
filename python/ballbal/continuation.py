"""Continuation and bifurcations: branches of solutions in one parameter with located
bifurcations, branch switching, and two-parameter bifurcation curves.

Every branch names its events with one vocabulary (:func:`event_vocabulary`, served by
the core): ``fold``, ``branch_point``, ``hopf``, ``period_doubling``,
``neimark_sacker`` and ``infinite_period``. Every function that takes an event
(:func:`equilibrium_curve`, :func:`periodic_curve`, :func:`switch`,
:func:`switch_equilibrium`) takes a row of the branch's ``events`` table or a name (the
first event of that kind), the names' aliases (AUTO's ``LP``, ``BP``, ``HB``, ``PD``,
``NS`` / ``TR``) in any case too.
"""

from ballbal._branch import Branch, Continuation, Curve, event_name, event_vocabulary
from ballbal._eq_continuation import (
    equilibrium_branch,
    equilibrium_curve,
    switch_equilibrium,
)
from ballbal._po_continuation import periodic_branch
from ballbal._po_curves import periodic_curve
from ballbal._po_switch import switch
from ballbal.model import DiskUnits, from_disk_units

__all__ = ["Branch", "Continuation", "Curve", "DiskUnits", "equilibrium_branch", "event_name",
           "event_vocabulary",
           "equilibrium_curve", "from_disk_units", "periodic_branch", "periodic_curve", "switch",
           "switch_equilibrium"]
