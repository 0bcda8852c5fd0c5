"""Fuzzing the bearing, rotor, groove-study, spectrum and data modules (issue 30), as
test_fuzz_api.py fuzzes the older entry points: whatever the arguments, a call returns
or raises a ``ballbal.exceptions`` class whose ``.parameter`` names a real parameter.

Valid settings are kept cheap (closed-form films, grids of a few hundred cells, short
runs, axes of one or two values); sizes above their bounds are among the bad values, and
must be refused without the work they would cost (the guard of test_fuzz_api bounds
each case's time)."""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
import polars as pl
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_fuzz_api import BAD, FUZZ, NAMES, check, count, kwargs, num, sometimes

import ballbal
import ballbal as bb
from ballbal import _check, data, spectrum
from ballbal import bearing as br

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The parameters of these modules (test_fuzz_api's NAMES has the models' and analyses').
NAMES.update({
    # bearing
    "length_ratio", "grooves", "cavitation", "grid", "grid.n_theta", "grid.n_zeta",
    "grooves.count", "grooves.angle", "grooves.depth_ratio", "grooves.width_ratio",
    "grooves.grooved_length", "grooves.side", "side", "position", "velocity", "field",
    "tau", "load", "dimensions", "speed", "radius", "length", "clearance", "viscosity",
    "f", "force_or_bearing", "ax", "bearing", "rho",
    # rotor
    "rotor", "mass_parameter", "unbalance", "gravity_direction", "unbalance_phase",
    "impulse.center", "impulse.direction", "mass", "g", "x0", "eps_contact",
    "stiff_steps", "method", "factor_reuse", "trajectories", "title",
    # groove study
    "angle", "depth_ratio", "width_ratio", "count", "df", "x", "y", "by",
    # spectra
    "quantity", "solution", "source", "natural_frequency_hz", "natural_frequency_rpm",
    "min_relative", "t_min", "t", "X", "Y", "scaling", "time_unit", "two_sided",
    "detrend", "frequencies", "amplitudes", "k_max", "omega", "spectrum", "column",
    "amplitude", "threshold", "min_separation", "max_peaks", "items", "name", "label",
    "height", "table",
    # data
    "rpm", "ratio", "modulus", "width", "thickness", "signal", "n_peaks", "imbalance",
    "ball_mass", "track_radius", "angles",
})

FEW = settings(FUZZ, max_examples=40)
#: A size above its bound, or a count no machine could hold.
HUGE = st.sampled_from([_check.MAX_BEARING_CELLS + 1, 10**7, 10**12, 2**63, 10**30])


def axis(valid: st.SearchStrategy[Any]) -> st.SearchStrategy[Any]:
    """An axis of a groove study: one or two values, or something that is not."""
    return sometimes(st.lists(valid, min_size=1, max_size=2),
                     st.one_of(BAD, st.just([]), st.lists(BAD, min_size=1, max_size=2),
                               st.just(np.zeros((2, 2)))))


GRID = sometimes(st.tuples(st.sampled_from([16, 32, 64]), st.sampled_from([2, 4, 8])),
                 st.one_of(BAD, st.tuples(HUGE, st.integers(2, 8)),
                           st.tuples(st.integers(8, 64), HUGE),
                           st.tuples(count(0, 9), count(0, 3)), st.just((64, 8, 2))))
GROOVES = st.builds(
    br.Grooves, count=st.sampled_from([2, 4, 8]), angle=st.floats(10, 80),
    depth_ratio=st.floats(0, 2), width_ratio=st.floats(0.3, 0.7),
    side=st.sampled_from(["sleeve", "journal"]))
GROOVE_FIELDS = dict(
    count=sometimes(st.integers(1, 8), st.one_of(BAD, HUGE, st.integers(-3, 0))),
    angle=num(5, 85), depth_ratio=sometimes(st.floats(0, 2), st.one_of(
        BAD, st.sampled_from([1e300, _check.MAX_GROOVES * 1.0, -0.5]))),
    width_ratio=num(0.2, 0.8), grooved_length=num(0.3, 1.0),
    side=sometimes(st.sampled_from(["sleeve", "journal"]), st.one_of(BAD, st.just("both"))))
#: Cheap bearings that are valid: closed forms and small grids (n_theta a multiple of
#: the groove count with at least 8 cells per pitch).
GOOD_BEARING = st.one_of(
    st.builds(br.Bearing, length_ratio=st.floats(0.2, 1.5), model=st.just("short")),
    st.builds(br.Bearing, length_ratio=st.floats(0.5, 3.0), model=st.just("long")),
    st.builds(br.Bearing, length_ratio=st.floats(0.3, 1.5), grid=st.just((32, 4))),
    st.builds(br.Bearing, length_ratio=st.floats(0.3, 1.5), grooves=GROOVES,
              model=st.sampled_from(["finite", "narrow_groove"]), grid=st.just((64, 4))))
BEARING = sometimes(GOOD_BEARING, BAD)
PAIR = sometimes(st.tuples(st.floats(-0.6, 0.6), st.floats(-0.6, 0.6)), st.one_of(
    BAD, st.tuples(num(-2, 2), num(-2, 2)), st.lists(st.floats(-1, 1), max_size=3),
    st.just((1e300, 0.0))))
DIMENSIONS = sometimes(
    st.builds(br.Dimensions, radius=st.floats(0.01, 0.05), length=st.floats(0.01, 0.05),
              clearance=st.floats(1e-5, 1e-4), viscosity=st.floats(0.001, 0.1)),
    BAD)


@FUZZ
@given(kwargs(**GROOVE_FIELDS), kwargs(
    length_ratio=num(0.2, 2), cavitation=sometimes(
        st.sampled_from(["half_sommerfeld", "reynolds", "none"]), BAD),
    model=sometimes(st.sampled_from(["short", "long", "finite", "narrow_groove"]),
                    st.one_of(BAD, st.just("Finite"))),
    grid=GRID, grooves=st.one_of(st.none(), BAD)))
def test_bearing(groove_kw: dict[str, Any], kw: dict[str, Any]) -> None:
    g = check(br.Grooves, **{"count": 8, "angle": 30.0, "depth_ratio": 1.0, **groove_kw})
    if isinstance(g, br.Grooves) and "grooves" not in kw:
        kw["grooves"] = g
    b = check(br.Bearing, **kw)
    if isinstance(b, br.Bearing):
        assert b.grid is not None and math.prod(b.grid) <= _check.MAX_BEARING_CELLS
        if math.prod(b.grid) <= 4096:
            check(br.film_force, b, (0.3, 0.1), field=True)


@FUZZ
@given(BEARING, PAIR, kwargs(velocity=PAIR, field=sometimes(st.booleans(), BAD),
                             tau=num(-10, 10)))
def test_film_force(bearing: Any, position: Any, kw: dict[str, Any]) -> None:
    f = check(br.film_force, bearing, position, **kw)
    if isinstance(f, br.FilmForce):
        assert math.isfinite(f.fx) and math.isfinite(f.fy)
        dims = br.Dimensions(radius=0.02, length=0.02, clearance=5e-5, viscosity=0.02)
        check(dims.force, f, kw.get("tau", 500.0))
        check(dims.pressure, f, 500.0)
        check(br.plot_pressure, f, ax=kw.get("velocity"))
        plt.close("all")
    check(dims_method, position)


def dims_method(f: Any) -> Any:
    """A Dimensions method given something that is not a film force."""
    dims = br.Dimensions(radius=0.02, length=0.02, clearance=5e-5, viscosity=0.02)
    return dims.force(f, 500.0)


@FUZZ
@given(BEARING, sometimes(st.one_of(st.floats(0.05, 3), st.tuples(
    st.floats(-2, 2), st.floats(-3, -0.1))), st.one_of(BAD, st.just((0.0, 0.0)))),
    kwargs(dimensions=DIMENSIONS, speed=num(10, 1000)), PAIR)
def test_equilibrium_coefficients_stability(bearing: Any, load: Any, kw: dict[str, Any],
                                            position: Any) -> None:
    if "dimensions" in kw and _check.is_real(load):
        load = load * 1e-3  # newtons: a film that carries it
    check(br.equilibrium, bearing, load, **kw)
    check(br.coefficients, bearing, position, **kw)
    check(br.stability, bearing, load, **kw)


@FEW
@given(kwargs(radius=num(0.01, 0.05), length=num(0.01, 0.05), clearance=num(1e-5, 1e-4),
              viscosity=num(1e-3, 0.1)), num(1, 1000), num(1, 100))
def test_dimensions(kw: dict[str, Any], speed: Any, load: Any) -> None:
    kw = {"radius": 0.02, "length": 0.02, "clearance": 5e-5, "viscosity": 0.02, **kw}
    d = check(br.Dimensions, **kw)
    if isinstance(d, br.Dimensions):
        for m in (d.force_scale, d.pressure_scale, d.stiffness_scale, d.damping_scale):
            check(m, speed)
        check(d.sommerfeld, speed, load)


IMPULSE = sometimes(st.builds(br.RotorImpulse, amplitude=st.floats(0, 5),
                              center=st.floats(0, 2), sharpness=st.floats(0.5, 5),
                              direction=st.floats(-180, 180)), BAD)
ROTOR_FIELDS = dict(gravity=num(0, 1), unbalance=num(0, 0.3),
                    impulse=st.one_of(st.none(), IMPULSE), gravity_direction=num(-180, 180),
                    unbalance_phase=num(-180, 180))


@FUZZ
@given(BEARING, num(0.5, 5), kwargs(**ROTOR_FIELDS),
       kwargs(amplitude=num(0, 5), center=num(0, 2), sharpness=num(0.1, 5),
              direction=num(-180, 180)))
def test_rotor(bearing: Any, mass: Any, kw: dict[str, Any], imp: dict[str, Any]) -> None:
    check(br.RotorImpulse, **imp)
    r = check(br.RotorOnBearing, bearing, mass, **kw)
    if isinstance(r, br.RotorOnBearing):
        check(br.rotor_equilibrium, r)


SPAN = sometimes(st.tuples(st.floats(0, 0.5), st.floats(0.6, 2.0)), st.one_of(
    BAD, st.tuples(num(-1, 1), num(-1, 2)), st.lists(st.floats(0, 2), max_size=3),
    st.just((0.0, 1e308)), st.just((-1e308, 1e308)), st.just((2.0, 1.0))))


@FEW
@given(GOOD_BEARING.filter(lambda b: b.model in ("short", "long") or b.grooves is None),
       sometimes(st.one_of(st.just("equilibrium"), st.tuples(st.floats(-0.3, 0.3),
                                                             st.floats(-0.3, 0.3))),
                 st.one_of(BAD, st.just("centre"), st.lists(st.floats(-1, 1), max_size=5))),
       SPAN, kwargs(
           samples=sometimes(st.integers(2, 50), st.one_of(BAD, HUGE, st.integers(-2, 1))),
           t_eval=st.one_of(st.none(), st.lists(st.floats(0, 2), max_size=4).map(sorted),
                            BAD),
           rtol=num(1e-8, 1e-3), atol=num(1e-12, 1e-6), max_steps=count(1, 5000),
           eps_contact=num(0.5, 0.99), stiff_steps=count(1, 5000),
           method=sometimes(st.sampled_from(["explicit", "implicit"]), BAD),
           factor_reuse=st.one_of(st.none(), num(1e-12, 1e-3))))
def test_simulate_rotor(bearing: Any, x0: Any, span: Any, kw: dict[str, Any]) -> None:
    rotor = br.RotorOnBearing(bearing, 2.0, gravity=0.2)
    kw.setdefault("max_steps", 5000)
    tr = check(br.simulate_rotor, rotor, x0, span, **kw)
    if isinstance(tr, br.RotorTrajectory):
        check(br.plot_trajectory, tr, title=kw.get("method"))
        check(br.plot_trajectory, {"a": tr, 3: tr})
        plt.close("all")
    check(br.plot_trajectory, x0)


@FEW
@given(sometimes(st.just(br.Bearing(model="short", length_ratio=0.5)), BAD),
       kwargs(radius=num(0.01, 0.05), length=num(0.01, 0.05), clearance=num(1e-5, 1e-4),
              viscosity=num(1e-3, 0.1), mass=num(0.1, 10), speed=num(10, 1000),
              unbalance=num(0, 1e-5), g=num(0, 10), impulse=st.one_of(st.none(), IMPULSE)))
def test_rotor_from_dimensions(bearing: Any, kw: dict[str, Any]) -> None:
    kw = {"radius": 0.02, "length": 0.02, "clearance": 5e-5, "viscosity": 0.02,
          "mass": 1.0, "speed": 500.0, **kw}
    check(br.RotorOnBearing.from_dimensions, bearing, **kw)


RHO = sometimes(st.floats(0.05, 2), st.one_of(BAD, st.sampled_from([1e3 + 1, 1e300, 0.0])))
TOML_GRID = st.sampled_from(["[32, 4]", "[64, 8]", "[8000, 2000]", "[10000000, 10000000]",
                             "[64]", "64", "[64.0, 8.0]", "[-1, 8]", '"x"', "[32, 4, 2]"])
TOML_GROOVES = st.sampled_from([
    "", "[bearing.grooves]\ncount = 4\nangle = 30.0\ndepth_ratio = 1.0\n",
    "[bearing.grooves]\ncount = 1000000000\nangle = 30.0\ndepth_ratio = 1.0\n",
    "[bearing.grooves]\ncount = 4\nangle = 30.0\ndepth_ratio = 1e300\n",
    "[bearing.grooves]\ncount = 4\nangle = 30.0\n",
    "[bearing.grooves]\ncount = 4\nangle = 30.0\ndepth_ratio = 1.0\nbogus = 1\n"])


@FEW
@given(sometimes(st.just(br.Bearing(model="short", length_ratio=0.5)), BAD), RHO,
       st.sampled_from(["short", "finite", "narrow_groove", "long", "x"]), TOML_GRID,
       TOML_GROOVES, st.sampled_from(["0.3", "1e300", "1e5", "-1", '"x"', "1000.0"]))
def test_bearing_support_and_scene_files(tmp_path_factory: pytest.TempPathFactory,
                                         bearing: Any, rho: Any, model: str, grid: str,
                                         grooves: str, rho_text: str) -> None:
    NAMES.update({"bearing.grooves", "bearing.grooves.bogus"})
    support = check(bb.BearingSupport, bearing, rho)
    if isinstance(support, bb.BearingSupport):
        sc = check(bb.Scene, support=support)
        if isinstance(sc, bb.Scene):
            check(bb.equilibria, sc)
            check(sc.replace, rho=rho_text if rho_text.startswith('"') else float(rho_text))
    p = tmp_path_factory.mktemp("scene") / "s.toml"
    p.write_text(f"Omega = 1.2\nballs = 2\n[bearing]\nrho = {rho_text}\nmodel = \"{model}\"\n"
                 f"grid = {grid}\n{grooves}")
    sc = check(bb.load_scene, p)
    if isinstance(sc, bb.Scene):
        assert sc.support is not None and sc.support.rho <= 1e3
        assert math.prod(sc.support.bearing.grid or (0,)) <= _check.MAX_BEARING_CELLS


STUDY_BEARING = sometimes(st.sampled_from([
    br.Bearing(model="short", length_ratio=0.5), br.Bearing(grid=(32, 4)),
    br.Bearing(grooves=br.Grooves(4, 30.0, 1.0), model="narrow_groove", grid=(32, 4)),
    br.Bearing(grid=(256, 128))]), BAD)


@FEW
@given(STUDY_BEARING, kwargs(
    angle=axis(st.floats(5, 85)), depth_ratio=axis(st.floats(0, 2)),
    width_ratio=axis(st.floats(0.3, 0.7)), length_ratio=st.one_of(st.none(), axis(
        st.floats(0.3, 1.5))),
    count=sometimes(st.lists(st.sampled_from([2, 4]), min_size=1, max_size=2), st.one_of(
        BAD, st.just([]), st.lists(st.one_of(HUGE, st.integers(-1, 0), BAD), min_size=1,
                                   max_size=2))),
    eccentricity=num(0.1, 0.8), threads=st.one_of(st.none(), sometimes(st.just(1), st.one_of(
        BAD, HUGE, st.integers(-1, 0), st.just(_check.MAX_THREADS + 1))))))
def test_groove_study(bearing: Any, kw: dict[str, Any]) -> None:
    if bearing == br.Bearing(grid=(256, 128)):
        # A grid valid alone that the counts below round past the cell bound: only
        # the refusal is cheap.
        kw["count"] = [_check.MAX_GROOVES]
    kw.setdefault("threads", 1)
    df = check(br.groove_study, bearing, **kw)
    if isinstance(df, pl.DataFrame):
        assert df.height == math.prod(len(kw.get(k) or [0]) for k in (
            "angle", "depth_ratio", "width_ratio", "length_ratio", "count"))
        for x, y, by in (("angle", "load", None), ("count", "k_centre", "angle"),
                         ("nope", "load", None), (3, "load", None), ("angle", "load", "x")):
            check(br.plot_groove_study, df, x, y, by=by)
        plt.close("all")
    check(br.plot_groove_study, kw.get("angle"))


# --- spectra ------------------------------------------------------------------------

@functools.cache
def solutions() -> dict[str, Any]:
    """A converged periodic solution, an unconverged one, an equilibrium, a simulation."""
    b = bb.Balancer()
    return {"converged": bb.periodic(b, "R-R", N=3),
            "failed": bb.periodic(b, "R-R", N=3,
                                  options=ballbal.PeriodicOptions(
                                      harmonic_balance=ballbal.HarmonicBalance(max_iter=1))),
            "equilibrium": bb.equilibria(b)[0],
            "simulation": bb.simulate(b, t_span=(0.0, 20.0), t_eval=np.arange(0, 20, 0.05))}


SOURCE = sometimes(st.sampled_from(["converged", "failed", "equilibrium", "simulation"]),
                   st.one_of(BAD, st.just("empty")))
QUANTITY = sometimes(st.sampled_from(["displacement", "velocity", "acceleration"]),
                     st.one_of(BAD, st.just("jerk")))
NATURAL = dict(natural_frequency_hz=st.one_of(st.none(), num(1, 50)),
               natural_frequency_rpm=st.one_of(st.none(), num(60, 3000)))


def source(key: Any) -> Any:
    if key == "empty":
        return pl.DataFrame({"t": [0.0]})
    return solutions().get(key, key) if isinstance(key, str) else key


@FUZZ
@given(SOURCE, QUANTITY, kwargs(Omega=st.one_of(st.none(), num(0.5, 2)),
                                eccentricity=st.one_of(st.none(), num(1e-5, 1e-3)),
                                min_relative=num(0, 1), **NATURAL), num(0, 15))
def test_line_spectrum_and_vibration(key: Any, quantity: Any, kw: dict[str, Any],
                                     t_min: Any) -> None:
    src = source(key)
    if not isinstance(src, pl.DataFrame):
        check(spectrum.line_spectrum, src, quantity, **kw)
    check(spectrum.vibration, src, quantity, Omega=kw.get("Omega"), t_min=t_min)
    if isinstance(src, pl.DataFrame):
        check(spectrum.ground_signal, src, quantity, t_min=t_min)


SIGNAL = st.one_of(st.just("sim"), st.lists(st.floats(-1, 1), min_size=0, max_size=12),
                   st.lists(st.floats(allow_nan=True), max_size=10), BAD)


@FUZZ
@given(SIGNAL, st.one_of(st.none(), SIGNAL), kwargs(
    window=sometimes(st.sampled_from(["flattop", "hann", "rect"]), BAD),
    scaling=sometimes(st.sampled_from(["amplitude", "psd"]), BAD),
    two_sided=st.one_of(st.none(), st.booleans(), BAD), detrend=sometimes(st.booleans(), BAD),
    time_unit=sometimes(st.sampled_from(["nondimensional", "s"]), BAD), **NATURAL))
def test_signal_spectrum(x: Any, y: Any, kw: dict[str, Any]) -> None:
    sig = spectrum.ground_signal(solutions()["simulation"])
    n = sig.height if x == "sim" else len(x) if isinstance(x, list) else 10
    t = np.arange(n) * 0.05
    xs = sig["X"].to_numpy() if x == "sim" else x
    ys = sig["Y"].to_numpy()[:n] if y == "sim" else y
    sp = check(spectrum.signal_spectrum, t, xs, ys, **kw)
    if isinstance(sp, pl.DataFrame) and "amplitude" in sp.columns and "frequency" in sp.columns:
        check(spectrum.label_peaks, sp, 1.2)
        check(spectrum.plot_spectrum, sp)
        w = check(spectrum.waterfall, [(1.2, sp), (1.3, sp)])
        if isinstance(w, pl.DataFrame):
            check(spectrum.plot_waterfall, w)
        plt.close("all")
    check(spectrum.signal_spectrum, sig, **kw)


@FUZZ
@given(sometimes(st.lists(st.floats(-5, 5), min_size=0, max_size=8), st.one_of(
    BAD, st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
    st.just(np.ones(_check.MAX_LINES + 1)))), num(0.5, 2), kwargs(
        omega=st.one_of(st.none(), num(0.05, 1)), amplitudes=st.one_of(
            st.none(), st.lists(st.floats(0, 1), max_size=8), BAD),
        tol=num(0.01, 0.4), k_max=count(1, 10)))
def test_label_lines(freqs: Any, omega_big: Any, kw: dict[str, Any]) -> None:
    check(spectrum.label_lines, freqs, omega_big, **kw)


def _spectrum_table(kind: str) -> Any:
    f = np.linspace(0, 5, 400)
    a = np.exp(-((f - 1.2) / 0.02) ** 2) + 0.3 * np.exp(-((f - 0.95) / 0.02) ** 2)
    tables = {"good": pl.DataFrame({"frequency": f, "amplitude": a}),
              "text": pl.DataFrame({"frequency": [str(v) for v in f], "amplitude": a}),
              "short": pl.DataFrame({"frequency": f[:2], "amplitude": a[:2]}),
              "nan": pl.DataFrame({"frequency": f, "amplitude": a * np.nan}),
              "lines": spectrum.line_spectrum(solutions()["converged"])}
    return tables.get(kind, kind)


@settings(FUZZ, max_examples=25)
@given(sometimes(st.sampled_from(["good", "lines"]), st.one_of(
    BAD, st.sampled_from(["text", "short", "nan"]))), num(0.5, 2), kwargs(
        omega=st.one_of(st.none(), num(0.05, 1)),
        column=sometimes(st.just("frequency"), st.one_of(BAD, st.just("amplitude"))),
        amplitude=sometimes(st.just("amplitude"), st.one_of(BAD, st.just("k"))),
        threshold=num(0, 1), min_separation=st.one_of(st.none(), num(0, 1)),
        max_peaks=sometimes(st.integers(1, 40), st.one_of(BAD, HUGE)), tol=num(0.01, 0.4),
        k_max=count(1, 10)))
def test_label_peaks_and_plots(kind: Any, omega_big: Any, kw: dict[str, Any]) -> None:
    table = _spectrum_table(kind) if isinstance(kind, str) else kind
    check(spectrum.label_peaks, table, omega_big, **kw)
    check(spectrum.plot_spectrum, table, column=kw.get("column", "frequency"),
          amplitude=kw.get("amplitude", "amplitude"), label=kw.get("threshold", 0.05),
          ax=kw.get("omega"))
    check(spectrum.waterfall, [(omega_big, table)] if isinstance(table, pl.DataFrame)
          else table)
    check(spectrum.plot_waterfall, table, name=kw.get("column", "Omega"))
    plt.close("all")


# --- data -----------------------------------------------------------------------------

VALUES = sometimes(st.one_of(st.floats(-2000, 2000), st.lists(st.floats(0, 2000), max_size=4),
                             st.just(np.full((2, 2), 513.0))),
                   st.one_of(BAD, st.just([1.0, None]), st.just([True, False]),
                             st.just(np.array(["a"]))))


@FUZZ
@given(VALUES, st.one_of(st.just(...), num(100, 1000)), num(0.1, 5), num(1, 50),
       num(1, 100), sometimes(st.one_of(st.floats(0, 2), st.lists(st.floats(0, 2),
                                                                 min_size=1, max_size=3)),
                              BAD),
       st.one_of(st.just(...), sometimes(st.floats(-4, 4), st.one_of(
           BAD, st.lists(st.floats(-4, 4), max_size=4)))))
def test_data(values: Any, fn: Any, mass: Any, radius: Any, u: Any, eta: Any,
              angles: Any) -> None:
    nat = {} if fn is ... else {"natural_frequency_rpm": fn}
    r = check(data.rpm_to_ratio, values, **nat)
    if not isinstance(r, BaseException):
        assert np.all(np.isfinite(r)) and np.shape(r) == np.shape(values)
        back = check(data.ratio_to_rpm, r, **nat)
        assert np.allclose(back, values)
    check(data.imbalance, mass, radius)
    check(data.eta, mass, radius, u)
    check(data.residual_imbalance, u, eta, *(() if angles is ... else (angles,)))
    check(data.leaf_spring_stiffness, 193e9, radius, mass, u)


@FEW
@given(sometimes(st.sampled_from(["decay"]), st.one_of(
    BAD, st.lists(st.floats(-1, 1), max_size=6), st.just([1.0, math.nan, 0.5]))),
    sometimes(st.integers(2, 6), st.one_of(BAD, HUGE, st.integers(-1, 1))))
def test_log_decrement(signal: Any, n_peaks: Any) -> None:
    if signal == "decay":
        t = np.linspace(0, 20, 2001)
        signal = np.exp(-0.05 * t) * np.cos(2 * np.pi * t)
    r = check(data.log_decrement, signal, n_peaks=n_peaks)
    if isinstance(r, data.LogDecrement):
        # e^(-0.05 t) over one period (t = 1): delta = 0.05.
        assert abs(r.delta - 0.05) < 2e-3
