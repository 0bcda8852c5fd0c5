"""Continuation of solution branches and bifurcation curves (issue 15)."""

from ._po_continuation import Branch, Continuation, periodic_branch

__all__ = ["Branch", "Continuation", "periodic_branch"]
