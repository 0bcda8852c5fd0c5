"""Where a scan or a basin grid runs is given one way: the call's keywords ``threads=``,
``chunk=``, ``executor=``, ``progress=``, ``out=`` (and a scan's ``lazy=``), the same
names and checks in both; never also as an object beside them (issue 32: ``scan`` took
both an ``Execution`` and keywords of the same names overriding it, ``basins`` only the
object)."""

from __future__ import annotations

import pytest

import ballbal
from ballbal.basins import BasinOptions, basins
from ballbal.exceptions import ParameterError, ParameterTypeError

B = ballbal.Balancer(eta=(0.7, 0.7), zeta_b=0.05, Omega=1.2)
OPTS = BasinOptions(t_end=5.0, window=2.0)


@pytest.mark.parametrize("name, value", [("chunk", 0), ("threads", 0), ("out", 3)])
def test_scan_and_basins_refuse_the_same_keyword_naming_it(name: str, value: object) -> None:
    with pytest.raises((ParameterError, ParameterTypeError)) as e:
        ballbal.scan(B, Omega=[1.2], **{name: value})
    assert e.value.parameter == name
    with pytest.raises((ParameterError, ParameterTypeError)) as f:
        basins(B, samples=2, seed=1, options=OPTS, **{name: value})
    assert f.value.parameter == name
    assert type(e.value) is type(f.value)


def test_an_execution_object_is_refused_with_the_keywords_to_use() -> None:
    with pytest.raises(ParameterTypeError) as e:
        ballbal.scan(B, Omega=[1.2], execution={"threads": 1})
    assert e.value.parameter == "execution"
    assert "threads=" in str(e.value) and "out=" in str(e.value)
    with pytest.raises(TypeError):
        basins(B, samples=2, seed=1, options=OPTS, execution={"threads": 1})  # type: ignore


def test_progress_is_reported_the_same_way_by_both() -> None:
    seen: dict[str, list[tuple[int, int]]] = {"scan": [], "basins": []}
    ballbal.scan(B, Omega=[1.1, 1.2, 1.3], threads=1, chunk=1,
                 progress=lambda d, t: seen["scan"].append((d, t)))
    basins(B, samples=4, seed=1, options=OPTS, threads=1, chunk=2, orbits=False,
           progress=lambda d, t: seen["basins"].append((d, t)))
    for calls in seen.values():
        assert calls and calls[-1][0] == calls[-1][1]  # done == total at the end
        assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:], strict=False))
