"""Every model, scene, component and options object refuses a bad value when it is made,
with the error an analysis would have raised at first use (issue 32: validation at
construction). The ranges are the core's; these tests only name the parameter at fault
and compare the construction's error with the analysis' one on an object made without
its checks."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import ballbal
from ballbal import Floquet, GuessSearch, HarmonicBalance, PeriodicOptions, ScanOptions
from ballbal._branch import Continuation
from ballbal._rotor import RotorImpulse
from ballbal.basins import BasinOptions
from ballbal.exceptions import ParameterError

BAD: list[tuple[str, Callable[[], Any], str]] = [
    ("mu negative", lambda: ballbal.Balancer(mu=-1.0), "mu"),
    ("mu above 1", lambda: ballbal.Balancer(mu=1.5), "mu"),
    ("zeta_b per ball", lambda: ballbal.Balancer(eta=(1.0,), zeta_b=(0.1, 0.2)), "zeta_b"),
    # mu (1 + sum(eta) / delta) = 0.9 (1 + 60 / 50) > 1: more mass than the total
    ("mass share", lambda: ballbal.Balancer(mu=0.9, eta=(30.0, 30.0)), "eta"),
    ("scene balancer", lambda: ballbal.Scene(balancer=ballbal.Balancer(delta=-1.0)), "delta"),
    ("N", lambda: HarmonicBalance(N=0), "N"),
    ("samples", lambda: HarmonicBalance(N=3, samples=4), "samples"),
    ("N_max", lambda: HarmonicBalance(N="auto", N_max=2), "N_max"),
    ("floquet rtol", lambda: Floquet(rtol=2.0), "rtol"),
    ("floquet method", lambda: Floquet(method="euler"), "method"),  # type: ignore[arg-type]
    ("hill_band", lambda: Floquet(hill_band=-0.1), "hill_band"),
    ("guess settle", lambda: GuessSearch(settle=0.0), "settle"),
    ("max_tail", lambda: PeriodicOptions(max_tail=0.0), "max_tail"),
    ("scan max_closure", lambda: ScanOptions(max_closure=-1.0), "max_closure"),
    ("block", lambda: ScanOptions(block=0), "block"),
    ("ds above ds_max", lambda: Continuation(ds=1.0), "ds"),
    ("grow", lambda: Continuation(grow=0.5), "grow"),
    ("window above t_end", lambda: BasinOptions(t_end=100.0, window=200.0), "window"),
    ("extend_factor", lambda: BasinOptions(extend_factor=0.5), "extend_factor"),
    ("impulse sharpness", lambda: RotorImpulse(sharpness=0.0), "impulse.sharpness"),
]


@pytest.mark.parametrize("what, make, name", BAD, ids=[b[0] for b in BAD])
def test_bad_value_is_refused_when_made(what: str, make: Callable[[], Any], name: str) -> None:
    with pytest.raises(ParameterError) as e:
        make()
    assert e.value.parameter == name, (what, e.value)


def _unchecked(cls: type, **values: Any) -> Any:
    """An instance of the frozen dataclass ``cls`` with ``values`` over its defaults,
    made without ``__post_init__``: what an analysis received before construction
    checked anything."""
    obj = object.__new__(cls)
    for f in dataclasses.fields(cls):
        if f.name in values:
            v = values[f.name]
        elif f.default is not dataclasses.MISSING:
            v = f.default
        else:
            v = f.default_factory()  # type: ignore[misc]
        object.__setattr__(obj, f.name, v)
    return obj


def _raised(call: Callable[[], Any]) -> BaseException:
    with pytest.raises(ParameterError) as e:
        call()
    return e.value


def test_construction_raises_what_the_analysis_raises() -> None:
    # the balancer: equilibria() on one made without checks, against the constructor
    for bad in ({"mu": -1.0}, {"mu": 0.9, "eta": (30.0, 30.0)}, {"Omega": float("nan")}):
        unchecked = _unchecked(ballbal.Balancer, **bad)
        late = _raised(lambda: ballbal.equilibria(unchecked))  # noqa: B023 - called at once
        early = _raised(lambda: ballbal.Balancer(**bad))  # noqa: B023 - called at once
        assert (type(early), early.parameter, str(early)) == (type(late), late.parameter,
                                                              str(late))
    # an option: periodic() with it, against its constructor
    hb = _unchecked(HarmonicBalance, N=0)
    object.__setattr__(hb, "_start", 0)
    object.__setattr__(hb, "_auto_target", None)
    opts = _unchecked(PeriodicOptions, harmonic_balance=hb)
    late = _raised(lambda: ballbal.periodic(ballbal.Balancer(), "R-R", options=opts))
    early = _raised(lambda: HarmonicBalance(N=0))
    assert (type(early), early.parameter, str(early)) == (type(late), late.parameter, str(late))


def test_valid_objects_still_build() -> None:
    # the defaults and edge values inside the ranges are accepted
    ballbal.Balancer()
    ballbal.Balancer(mu=1.0 / (1.0 + 2.0 / 50.0))  # exactly the whole mass: share = 1
    ballbal.Scene(springs=0.5)
    HarmonicBalance(N="auto", N_max=3)
    Floquet(method="magnus", hill_band=0.0)
    ScanOptions(block=1)
    Continuation(ds=0.05)
    BasinOptions(t_end=100.0, window=100.0)
    RotorImpulse()
    assert np.isfinite(ballbal.Balancer(Omega=1.3).Omega)
