"""Scene files (TOML) for the planar balancer: its parameters, nothing else yet.

A file holds the keys of :class:`~ballbal.Balancer` (``mu, zeta, zeta_b, delta, Omega,
eta``) and optionally ``balls`` (equal balls when ``eta`` is one number). Unknown keys
are errors, so a misspelt parameter never silently falls back to a default.
"""

from __future__ import annotations

import os
import sys
from dataclasses import fields
from typing import Any

from .model import Balancer

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def balancer_from_dict(d: dict[str, Any], where: str = "scene") -> Balancer:
    known = {f.name for f in fields(Balancer)} | {"balls"}
    unknown = sorted(set(d) - known)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)} "
                         f"(allowed: {', '.join(sorted(known))})")
    d = dict(d)
    balls = d.pop("balls", None)
    if balls is not None:
        if not isinstance(balls, int) or balls < 1:
            raise ValueError(f"balls: must be an integer >= 1, got {balls!r}")
        eta = d.get("eta", 1.0)
        if isinstance(eta, (int, float)):
            d["eta"] = (float(eta),) * balls
        elif len(eta) != balls:
            raise ValueError(f"eta: has {len(eta)} values but balls = {balls}")
    b = Balancer(**d)
    return b.validate()


def load_scene(path: str | os.PathLike[str]) -> Balancer:
    try:
        with open(path, "rb") as f:
            d = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"scene: {path} is not valid TOML: {e}") from e
    return balancer_from_dict(d, where=str(path))
