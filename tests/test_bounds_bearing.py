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
from ballbal import _check
from ballbal import bearing as br
from ballbal.exceptions import ParameterError, ParameterTypeError

G8 = br.Grooves(count=8, angle=30.0, depth_ratio=1.0)


def raises(cls: type[Exception], parameter: str, f: object, *args: object,
           **kw: object) -> ParameterError:
    with pytest.raises(cls) as e:
        f(*args, **kw)  # type: ignore[operator]
    assert isinstance(e.value, ParameterError)
    assert e.value.parameter == parameter, (e.value.parameter, str(e.value))
    return e.value


# --- bearing grids and grooves ------------------------------------------------------

def test_the_issues_grids_are_refused_naming_the_axis() -> None:
    """grid=(8000, 2000) took 42 s and 8.4 GB per film solve; (10**7, 10**7) had no bound
    anywhere. Both are refused when the bearing is made, before any solve."""
    e = raises(ParameterError, "grid.n_zeta", br.Bearing, grooves=G8, grid=(8000, 2000))
    assert str(_check.MAX_BEARING_ZETA) in str(e)
    raises(ParameterError, "grid.n_theta", br.Bearing, grooves=G8, grid=(10**7, 10**7))


def test_a_grid_with_too_many_cells_in_all_is_refused() -> None:
    """Each axis within its bound, the product above MAX_BEARING_CELLS: the longer axis is
    the one named (the one to cut)."""
    nt, nz = _check.MAX_BEARING_THETA, 32
    assert nt * nz > _check.MAX_BEARING_CELLS
    e = raises(ParameterError, "grid.n_theta", br.Bearing, grooves=G8, grid=(nt, nz))
    assert e.allowed is not None and str(_check.MAX_BEARING_CELLS) in e.allowed
    # The largest grid allowed is accepted (it is only made here, not solved).
    assert br.Bearing(grooves=G8, grid=(1024, 256)).grid == (1024, 256)


def test_a_narrow_groove_grid_has_the_lower_bound() -> None:
    """The narrow-groove factorisation is the slower one between Ctrl-C polls: a grid the
    finite film accepts is refused there, naming the longer axis and the bound."""
    assert _check.MAX_NARROW_GROOVE_CELLS < 1024 * 256 <= _check.MAX_BEARING_CELLS
    e = raises(ParameterError, "grid.n_theta", br.Bearing, grooves=G8,
               model="narrow_groove", grid=(1024, 256))
    assert e.allowed is not None and str(_check.MAX_NARROW_GROOVE_CELLS) in e.allowed
    assert br.Bearing(grooves=G8, model="narrow_groove", grid=(512, 256)).grid == (512, 256)


def test_grid_bounds_hold_in_scene_files(tmp_path) -> None:
    p = tmp_path / "s.toml"
    p.write_text("Omega = 1.2\nballs = 2\n[bearing]\nrho = 0.3\ngrid = [8000, 2000]\n"
                 "[bearing.grooves]\ncount = 8\nangle = 30.0\ndepth_ratio = 1.0\n")
    raises(ParameterError, "grid.n_zeta", bb.load_scene, p)
    p.write_text("Omega = 1.2\nballs = 2\n[bearing]\nrho = 0.3\n"
                 "[bearing.grooves]\ncount = 1000000000\nangle = 30.0\ndepth_ratio = 1.0\n")
    raises(ParameterError, "grooves.count", bb.load_scene, p)


def test_a_billion_grooves_are_refused() -> None:
    e = raises(ParameterError, "grooves.count", br.Grooves, count=10**9, angle=30.0,
               depth_ratio=1.0)
    assert e.allowed == f"[1, {_check.MAX_GROOVES}]"
    # The most grooves allowed have their default grid within the bounds.
    g = br.Grooves(count=_check.MAX_GROOVES, angle=30.0, depth_ratio=1.0)
    nt, nz = br.default_grid(g)
    assert nt <= _check.MAX_BEARING_THETA and nt * nz <= _check.MAX_BEARING_CELLS


def test_grooves_that_are_not_grooves_name_grooves() -> None:
    """Bearing(grooves=8) raised AttributeError (the default grid read 8.count)."""
    raises(ParameterTypeError, "grooves", br.Bearing, grooves=8)
    raises(ParameterTypeError, "grooves", br.Bearing, grooves="x", grid=(64, 16))


def test_bottomless_grooves_are_refused_before_the_solve() -> None:
    """depth_ratio=1e300 made the conductance H^3 overflow: an EigenSolverError ("not
    positive definite") from film_force. Now the groove is refused, also in a study."""
    raises(ParameterError, "grooves.depth_ratio", br.Grooves, count=8, angle=30.0,
           depth_ratio=1e300)
    raises(ParameterError, "depth_ratio", br.groove_study, br.Bearing(grid=(64, 8)),
           depth_ratio=[1.0, 1e300])


def test_what_is_not_dimensions_or_a_film_force_is_named() -> None:
    """These reached an attribute of the wrong object: AttributeError."""
    b = br.Bearing(model="short", length_ratio=0.5)
    raises(ParameterTypeError, "dimensions", br.coefficients, b, (0.1, 0.0), dimensions=3,
           speed=500.0)
    dims = br.Dimensions(radius=0.02, length=0.02, clearance=5e-5, viscosity=0.02)
    for method in (dims.force, dims.pressure):
        raises(ParameterTypeError, "f", method, (0.1, 0.2), 500.0)
    raises(ParameterTypeError, "trajectories", br.plot_trajectory, {"run": 3})
    raises(ParameterTypeError, "df", br.plot_groove_study, [1, 2])


# --- groove study -----------------------------------------------------------------

def test_groove_study_threads_are_capped_like_a_scans() -> None:
    """threads=10**6 had no cap (a scan's threads= has MAX_THREADS). The eccentricity
    is out of range too, so that the old code, which checked it first, failed at once
    naming that instead."""
    b = br.Bearing(model="short", length_ratio=0.5)
    for n in (_check.MAX_THREADS + 1, 10**6):
        raises(ParameterError, "threads", br.groove_study, b, threads=n, eccentricity=2.0)


def test_groove_study_points_and_grids_are_bounded() -> None:
    """The product of the axes, each point's grid (the bearing's n_theta rounded up to 8
    cells per pitch of its groove count) and the cells the threads hold at once. Each
    case also has an eccentricity out of range, which the old code checked first."""
    b = br.Bearing(grid=(64, 8))
    n = math.isqrt(_check.MAX_GROOVE_POINTS) + 1
    many = [float(x) for x in range(n)]
    raises(ParameterError, "depth_ratio", br.groove_study, b, angle=[30.0],
           depth_ratio=[1.0 + x / n for x in many], width_ratio=[0.3 + 0.4 * x / n
                                                                for x in many],
           eccentricity=2.0)
    # MAX_GROOVES (512) grooves round n_theta = 256 up to 8 cells per pitch: 4096 x 128
    # = 2^19 cells.
    raises(ParameterError, "count", br.groove_study, br.Bearing(grid=(256, 128)),
           count=[8, _check.MAX_GROOVES], eccentricity=2.0)
    # Five threads, five points of 2^18 cells each: 5 x 2^18 cells at once.
    raises(ParameterError, "threads", br.groove_study, br.Bearing(grid=(1024, 256)),
           angle=[20.0, 30.0, 40.0, 50.0, 60.0], threads=5, eccentricity=2.0)


# --- rotor --------------------------------------------------------------------------

def test_a_backward_time_span_is_named_t_span() -> None:
    """simulate_rotor made its output times from t_span; the core then named those
    (t_eval), which the caller never gave."""
    rotor = br.RotorOnBearing(br.Bearing(model="short", length_ratio=0.5), 2.0, gravity=0.2)
    for span in ((5.0, 1.0), (0.0, 0.0), (0.0, math.inf), (-1e308, 1e308)):
        raises(ParameterError, "t_span", br.simulate_rotor, rotor, (0.1, 0.0), span)
    raises(ParameterError, "t_span[0]", br.simulate_rotor, rotor, (0.1, 0.0),
           (math.nan, 1.0))


def test_rotor_from_dimensions_names_a_bad_bearing() -> None:
    """A bearing of the wrong type reached the core's conversion: pyo3's TypeError."""
    raises(ParameterTypeError, "bearing", br.RotorOnBearing.from_dimensions, "plain",
           radius=0.02, length=0.02, clearance=1e-4, viscosity=0.01, mass=1.0, speed=500.0)


# --- bearing support ------------------------------------------------------------------

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
