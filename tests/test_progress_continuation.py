"""The core's long calls show progress (issue 34): ``progress=`` on every branch and
curve function, and on groove studies, counts the points as the core adds them (a bar,
or a callable ``f(done, total)``); the count ends at the number of rows the result
holds, never goes back, and an error raised by the callable stops the work as Ctrl-C
does."""

from __future__ import annotations

import pytest

import ballbal
from ballbal import continuation as cont
from ballbal.exceptions import ParameterTypeError

RR = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.2, eta=(1.0, 1.0))


def _record() -> tuple[list[tuple[int, int]], object]:
    calls: list[tuple[int, int]] = []
    return calls, lambda done, total: calls.append((done, total))


def _counted(calls: list[tuple[int, int]], rows: int, total: int, starts: int = 1) -> None:
    """``starts``: the halves a result is joined from; each counts the shared start, which
    the joined table holds once."""
    assert calls, "no progress reported"
    done = [d for d, _ in calls]
    assert done == sorted(done) and len(set(done)) == len(done)  # only forward
    assert done[-1] == rows + starts - 1  # every row of the result
    assert {t for _, t in calls} == {total}


def test_an_equilibrium_branch_counts_its_rows() -> None:
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    calls, cb = _record()
    br = cont.equilibrium_branch(b, "eta1", start="perfect_balance", range=(0.6, 1.4),
                                 options=cont.Continuation(max_points=30), progress=cb)
    _counted(calls, br.table.height, 30)


def test_a_periodic_branch_and_its_fold_curve_count_their_rows() -> None:
    sol = ballbal.periodic(RR, "R-R")
    calls, cb = _record()
    br = cont.periodic_branch(sol, "Omega", range=(1.2, 1.45), method="hb",
                              options=cont.Continuation(max_points=300), progress=cb)
    _counted(calls, br.table.height, 300)
    calls, cb = _record()
    curve = cont.periodic_curve(br, "fold", "eta", range=(0.95, 1.1),
                                options=cont.Continuation(ds=0.01, ds_max=0.05,
                                                          max_points=40), progress=cb)
    _counted(calls, curve.table.height, 80, starts=2)  # a curve is continued both ways


def test_an_error_in_the_callback_stops_the_work() -> None:
    sol = ballbal.periodic(RR, "R-R")

    class Enough(Exception):
        pass

    def stop(done: int, total: int) -> None:
        raise Enough(done)

    with pytest.raises(Enough):
        cont.periodic_branch(sol, "Omega", range=(0.95, 1.45), method="hb", progress=stop)


def test_progress_must_be_a_flag_or_a_callable() -> None:
    b = ballbal.Balancer(eta=(0.9, 1.1), Omega=1.5)
    with pytest.raises(ParameterTypeError) as e:
        cont.equilibrium_branch(b, "eta1", range=(0.6, 1.4), progress="yes")  # type: ignore
    assert e.value.parameter == "progress"


def test_a_groove_study_counts_its_points_whatever_the_threads() -> None:
    from ballbal.bearing import Bearing, groove_study

    for threads in (1, 2):
        calls, cb = _record()
        df = groove_study(Bearing(grid=(32, 8)), angle=[20.0, 40.0], depth_ratio=[0.5, 1.0],
                          threads=threads, progress=cb)
        _counted(calls, df.height, 4)


def test_design_charts_count_their_values() -> None:
    from ballbal.design import balanced_fraction

    calls, cb = _record()
    t = balanced_fraction(ballbal.Balancer(eta=(0.66, 0.66), zeta_b=0.2), speeds_rpm=[600, 700],
                          natural_frequency_rpm=513, starts=4, t_end=50.0, progress=cb)
    _counted(calls, t.table.height, 2)
