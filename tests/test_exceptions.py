"""The core's errors arrive as `ballbal.exceptions` classes with their fields, through the
binding's one mapping; the classes survive pickling (executors and Dask send them back)."""

import pickle

import pytest

import ballbal
from ballbal import Balancer, Ramp, Scene
from ballbal.exceptions import (
    BallbalError,
    NotAutonomousError,
    ParameterError,
    ParameterTypeError,
)


@pytest.mark.parametrize(
    ("changes", "parameter", "allowed"),
    [
        ({"mu": 1.5}, "mu", "(0, 1)"),
        ({"zeta": -0.1}, "zeta", "[0, inf)"),
        ({"delta": 0.0}, "delta", "(0, inf)"),
        ({"eta": (1.0, -2.0)}, "eta2", "(0, inf)"),
    ],
)
def test_core_range_error_carries_parameter_and_range(changes, parameter, allowed):
    with pytest.raises(ParameterError) as info:
        ballbal.equilibria(Balancer(**changes))
    err = info.value
    assert err.parameter == parameter
    assert err.allowed == allowed
    assert isinstance(err, ValueError) and isinstance(err, BallbalError)


def test_not_autonomous_names_the_effect():
    scene = Scene(Balancer(), ramp=Ramp(to=2.0, start=0.0, duration=10.0))
    with pytest.raises(NotAutonomousError) as info:
        ballbal.equilibria(scene)
    assert info.value.effect == "ramp"
    assert isinstance(info.value, ValueError)


def test_exceptions_pickle_with_their_fields():
    e = ParameterTypeError("N", "must be an integer", allowed="[1, 256]", value="x")
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is ParameterTypeError
    assert (back.parameter, back.allowed, back.value) == ("N", "[1, 256]", "x")
    assert isinstance(back, TypeError) and isinstance(back, ValueError)
    n = pickle.loads(pickle.dumps(NotAutonomousError("gravity")))
    assert n.effect == "gravity"
