"""Bounded sizes and right errors in the bearing modules (issue 30): a grid, groove count,
groove study or thread count too large is refused before anything is allocated, in Python
and in scene files, by a ParameterError naming the parameter; so are the physical
parameters (rho, groove depth) that make the model meaningless; errors that named the
wrong parameter or were not ballbal's now name the right one.

A refused size must raise before the work it would cost: the calls here that the old
code ran (or hung in) return at once. No timing is asserted."""

from __future__ import annotations

import math

import pytest

import ballbal as bb
from ballbal import bearing as br
from ballbal.exceptions import ParameterError


def raises(cls: type[Exception], parameter: str, f: object, *args: object,
           **kw: object) -> ParameterError:
    with pytest.raises(cls) as e:
        f(*args, **kw)  # type: ignore[operator]
    assert isinstance(e.value, ParameterError)
    assert e.value.parameter == parameter, (e.value.parameter, str(e.value))
    return e.value


# --- bearing support and grooves ------------------------------------------------

def test_rho_has_a_range_in_python_files_and_scans(tmp_path) -> None:
    """equilibria on a bearing scene with rho = 1e300 never returned; rho = 1e5 did not
    either. rho = e / c above 1e3 leaves the journal inside the clearance only at the
    balanced state: refused wherever rho is given."""
    b = br.Bearing(model="short", length_ratio=0.5)
    raises(ParameterError, "rho", bb.BearingSupport, b, 1e300)
    sc = bb.Scene(support=bb.BearingSupport(b, 0.3))
    raises(ParameterError, "rho", sc.replace, rho=1e5)
    p = tmp_path / "s.toml"
    p.write_text("Omega = 1.2\nballs = 2\n[bearing]\nrho = 1e300\nmodel = \"short\"\n")
    raises(ParameterError, "rho", bb.load_scene, p)
    raises(ParameterError, "rho", bb.scan, sc, rho=[0.3, 1e300], threads=1)
    # The largest rho allowed still gives the perfect balance.
    eqs = bb.equilibria(sc.replace(rho=1e3))
    assert [e.kind for e in eqs] == ["perfect_balance"]
    assert max(abs(v) for v in eqs[0].q[:2]) < 1e-12


def test_equilibria_of_a_finite_film_scene_at_a_high_speed_return() -> None:
    """The least-squares Newton's SVD had no iteration limit: on this scene (a finite
    film at Omega = 10) it spun for minutes without an answer. Now a start whose
    Jacobian is not finite, or whose SVD does not converge, has failed, and the search
    goes on to the others and ends."""
    b = br.Bearing(length_ratio=0.5, grid=(64, 8))
    sc = bb.Scene(balancer=bb.Balancer(Omega=10.0), support=bb.BearingSupport(b, 1.0))
    eqs = bb.equilibria(sc)
    # The perfect balance of two balls of eta = 1 is an equilibrium at any speed: the
    # disk centre on the axis (the film then carries nothing) and eta sum exp(i b) = -1,
    # the balls at +-120 degrees from the imbalance.
    pb = [e for e in eqs if e.kind == "perfect_balance"]
    assert len(pb) == 1
    x, y, b1, b2 = pb[0].q
    assert abs(x) < 1e-9 and abs(y) < 1e-9
    assert abs(1 + math.cos(b1) + math.cos(b2)) < 1e-9
    assert abs(math.sin(b1) + math.sin(b2)) < 1e-9


def test_bottomless_grooves_are_refused_before_the_solve() -> None:
    """depth_ratio=1e300 made the conductance H^3 overflow: an EigenSolverError ("not
    positive definite") from film_force. Now the groove is refused, also in a study."""
    raises(ParameterError, "grooves.depth_ratio", br.Grooves, count=8, angle=30.0,
           depth_ratio=1e300)
    raises(ParameterError, "depth_ratio", br.groove_study, br.Bearing(grid=(64, 8)),
           depth_ratio=[1.0, 1e300])
