"""Continuation and bifurcations: branches, switching, two-parameter curves."""

from ._po_switch import switch as switch
