"""Notebook-first results (issue 34): every result object prints a short summary (at
most six lines, 600 characters) that states its key numbers as its own fields give
them, shows an HTML table, and draws itself with labelled axes; bifurcation diagrams
draw stable parts solid and unstable ones dashed, with the events named. The figures
share one style: every registry parameter has a symbol, markers follow the grid, maps
carry their fixed parameters."""

from __future__ import annotations

import math
import pickle
import re
from functools import cache
from typing import Any

import matplotlib
import numpy as np
import polars as pl
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.text import Annotation  # noqa: E402

import ballbal  # noqa: E402
from ballbal import _native, _style, bearing  # noqa: E402
from ballbal import continuation as cont  # noqa: E402
from ballbal._rotor import RotorOnBearing, simulate_rotor  # noqa: E402
from ballbal.calibration import Calibration, Transition  # noqa: E402
from ballbal.data import log_decrement  # noqa: E402
from ballbal.plot import scan_map  # noqa: E402
from ballbal.rig import Sensor, read_record  # noqa: E402
from ballbal.sweep import speed_sweep  # noqa: E402

SHORT = bearing.Bearing(length_ratio=0.5, model="short")
MAX_CHARS, MAX_LINES = 600, 6


@cache
def periodic() -> ballbal.PeriodicSolution:
    sol = ballbal.periodic(ballbal.Balancer(eta=(0.9, 1.1)), "R-R", N=6)
    assert sol.converged
    return sol


@cache
def periodic_branch() -> cont.Branch:
    return cont.periodic_branch(periodic(), "eta1", range=(0.5, 1.5),
                                options=cont.Continuation(max_points=25))


@cache
def equilibrium_branch() -> cont.Branch:
    # units of the disk alone: the together state's branch has a fold (stable on one
    # side, unstable on the other), test_disk_units' setting
    units = cont.DiskUnits(omega0=0.3, m0=2.0, e=2.0, C0=0.35, D0=0.35)
    return cont.equilibrium_branch(units, "omega0", start="together", range=(0.25, 2.2),
                                   options=cont.Continuation(ds=0.02, ds_max=0.05,
                                                             max_points=300))


@cache
def fold_curve() -> cont.Curve:
    br = equilibrium_branch()
    return cont.equilibrium_curve(br, "fold", "m0", range=(0.5, 5.0),
                                  options=cont.Continuation(ds=0.02, ds_max=0.05,
                                                            max_points=300))


def _record() -> Any:
    t = np.linspace(0.0, 20.0, 20_001)
    rpm = np.where(t < 10.0, 600.0, 900.0)
    acc = 50.0 * np.sin(2 * np.pi * rpm / 60.0 * t)
    return read_record({"t": t, "rpm": rpm, "acc_mV": acc}, speed="rpm",
                       channels={"acc_mV": Sensor(unit="g", sensitivity=100.0,
                                                  recorded_unit="mV")})


def _calibration() -> Calibration:
    # the display only: a result written here, not fitted
    est = pl.DataFrame({"parameter": ["zeta_b"], "value": [0.1], "std_error": [0.01],
                        "ci_low": [0.08], "ci_high": [0.12], "determined": [True]})
    res = pl.DataFrame({"step": [0, 1], "speed_rpm": [600.0, 900.0],
                        "quantity": ["main_frequency_rpm"] * 2, "measured": [100.0, 120.0],
                        "model": [101.0, 119.0], "residual": [-1.0, 1.0]})
    return Calibration(model=ballbal.Balancer(), natural_frequency_rpm=500.0, estimates=est,
                       residuals=res, level=0.95, dof=1, scale=1.4, evaluations=10,
                       message="ok")


# name -> (maker, has a plot)
RESULTS: dict[str, tuple[Any, bool]] = {
    "PeriodicSolution": (periodic, True),
    "Equilibrium": (lambda: ballbal.equilibria(ballbal.Balancer(Omega=1.5))[0], True),
    "Branch (periodic)": (periodic_branch, True),
    "Branch (equilibrium)": (equilibrium_branch, True),
    "Curve": (fold_curve, True),
    "Sweep": (lambda: speed_sweep(ballbal.Balancer(), (0.8, 1.6, 0.2), dwell=200.0,
                                  record=50.0), True),
    "Basins": (lambda: ballbal.basins.basins(ballbal.Balancer(Omega=1.35), n=4), True),
    "FilmForce": (lambda: bearing.film_force(SHORT, (0.3, 0.1), field=True), True),
    "BearingEquilibrium": (lambda: bearing.equilibrium(SHORT, (1.0, 0.0)), True),
    "Stability": (lambda: bearing.stability(SHORT, (1.0, 0.0)), True),
    # eight numbers, all in the summary
    "Coefficients": (lambda: bearing.coefficients(SHORT, (0.3, 0.4)), False),
    "RotorTrajectory": (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.01, 0.0),
                                               (0.0, 100.0), samples=301), True),
    "DisturbanceResponse": (lambda: ballbal.disturbance_response(
        ballbal.Balancer(Omega=3.0), 2.5, t_end=200.0), True),
    "RunUp": (lambda: ballbal.run_up(ballbal.Balancer(Omega=0.5), 2.0, 50.0, settle=50.0),
              True),
    # four numbers, all in the summary
    "Vibration": (lambda: periodic().vibration(), False),
    "LogDecrement": (lambda: log_decrement(np.exp(-0.005 * np.arange(2000))
                                           * np.sin(0.1 * np.arange(2000))), True),
    "Record": (_record, True),
    "Calibration": (_calibration, True),
    # one value with its interval, all in the summary
    "Transition": (lambda: Transition(parameter="zeta_b", speed_rpm=900.0,
                                      uncertainty_rpm=10.0, value=0.1, low=0.09, high=0.11,
                                      status="ok", reach_rpm=(None, None)), False),
}


@cache
def made(name: str) -> Any:
    return RESULTS[name][0]()


@pytest.mark.parametrize("name", list(RESULTS))
def test_repr_is_short_and_html_a_table(name: str) -> None:
    x = made(name)
    text = repr(x)
    assert 0 < len(text) <= MAX_CHARS, (name, len(text), text[:200])
    assert text.count("\n") + 1 <= MAX_LINES, (name, text)
    assert "<table" in x._repr_html_()
    # a summary, not the dataclass' field dump
    assert "=array(" not in text and "shape: (" not in text


@pytest.mark.parametrize("name", [n for n, (_, p) in RESULTS.items() if p])
def test_plot_labels_every_axis(name: str) -> None:
    x = made(name)
    drawn = x.plot()
    fig = drawn if hasattr(drawn, "get_axes") else drawn.figure
    axes = [a for a in fig.get_axes() if a.get_label() != "<colorbar>"]
    assert axes
    for a in axes:
        # stacked panels sharing their x axis label it once, on one of them
        xlabels = [b.get_xlabel().strip() for b in a.get_shared_x_axes().get_siblings(a)]
        assert any(xlabels) and a.get_ylabel().strip(), (name, a)
        assert a.lines or a.collections or a.images or a.patches, (name, "empty axes")
    plt.close(fig)


@pytest.mark.parametrize("name", [n for n, (_, p) in RESULTS.items() if not p])
def test_results_without_a_plot_say_why(name: str) -> None:
    x = made(name)
    assert not hasattr(x, "plot")
    assert "No ``plot``" in " ".join((type(x).__doc__ or "").split())


def test_periodic_solution_summary_states_its_fields() -> None:
    s = periodic()
    text = repr(s)
    for part in (s.type, s.stability, f"ω={s.omega:.5g}", f"Ω={s.balancer.Omega:.4g}",
                 f"|μ|max={s.max_modulus:.3g}", f"(N={s.N})"):
        assert part in text, (part, text)
    # the HTML table has the frequency to four digits as well
    assert f"{s.omega:.4g}" in s._repr_html_()


def test_periodic_plot_draws_the_ground_frame_orbit() -> None:
    # The ground-frame panel is Z = (x + i y) exp(i Omega t), computed here from the
    # rotating-frame history at the same times: the panel's line must be it.
    s = periodic()
    fig = s.plot()
    ground = fig.axes[1]
    xd, yd = ground.lines[0].get_data()
    spin = s.balancer.Omega
    t_end = max(s.period, 3 * 2 * math.pi / spin)
    t = np.linspace(0.0, t_end, xd.size)
    h = s.time_history(t)
    z = (h["x"].to_numpy() + 1j * h["y"].to_numpy()) * np.exp(1j * spin * t)
    assert np.max(np.abs(xd - z.real)) < 1e-9 and np.max(np.abs(yd - z.imag)) < 1e-9
    # ball angles: one line per ball, the balls' labels
    assert len(fig.axes[2].lines) == s.balancer.n_balls
    plt.close(fig)


def test_failed_solution_summary_names_the_status() -> None:
    s = periodic()
    from dataclasses import replace

    failed = replace(s, status="not_converged", omega=None)
    assert "not_converged" in repr(failed) and "ω=" not in repr(failed)


def test_equilibrium_summary_states_its_fields() -> None:
    e = made("Equilibrium")
    text = repr(e)
    assert e.kind in text and e.stability in text
    assert f"{e.stability_index:.4g}" in text
    assert f"{math.hypot(e.q[0], e.q[1]):.4g}" in text


def _segments(ax: Any) -> list[tuple[str, np.ndarray]]:
    return [(ln.get_linestyle(), np.asarray(ln.get_xdata(), float)) for ln in ax.lines
            if len(ln.get_xdata()) > 1]


def test_branch_diagram_draws_stability_and_names_events() -> None:
    br = equilibrium_branch()
    verdicts = br.table["stability"].to_list()
    assert "stable" in verdicts and "unstable" in verdicts  # both parts to draw
    ax = br.plot()
    x = br.table[br.parameter].to_numpy()
    styles = {"stable": "-", "unstable": "--"}
    for style, xs in _segments(ax):
        # the interior points of a drawn piece all have the verdict its style says
        # (its ends are shared with the neighbouring pieces)
        rows = [int(np.argmin(np.abs(x - v))) for v in xs[1:-1]]
        seen = {verdicts[i] for i in rows}
        assert len(seen) <= 1, seen
        if seen:
            assert styles.get(seen.pop(), ":") == style
    drawn = {ls for ls, _ in _segments(ax)}
    assert {"-", "--"} <= drawn
    # each event named by its first alias in the core's vocabulary (fold -> LP)
    short = {name: aliases[0] for name, aliases, _ in cont.event_vocabulary()}
    # (events located close together share one label: "BP+LP")
    named = {n for t in ax.texts if isinstance(t, Annotation) for n in t.get_text().split("+")}
    assert named == {short[kind] for kind in br.events["type"].to_list()}
    # the summary counts what the table holds
    text = repr(br)
    assert f"{br.table.height} points" in text and br.stop in text
    n_stable = br.table.filter(pl.col("stability") == "stable").height
    assert f"({n_stable} stable)" in text
    plt.close(ax.figure)


def test_branch_plot_y_is_the_disk_offset_by_default() -> None:
    br = equilibrium_branch()
    ax = br.plot()
    q = br.table["q"].to_list()
    r = np.array([math.hypot(v[0], v[1]) for v in q])
    ys = np.concatenate([ln.get_ydata() for ln in ax.lines if len(ln.get_xdata()) > 1])
    assert np.all(np.min(np.abs(ys[:, None] - r[None, :]), axis=1) < 1e-12)
    assert ax.get_ylabel() == _style.label("r")
    plt.close(ax.figure)
    with pytest.raises(ballbal.exceptions.ParameterError) as e:
        br.plot(y="nonsense")
    assert e.value.parameter == "y"


def test_curve_plot_marks_its_codimension_two_points() -> None:
    cv = fold_curve()
    assert cv.points.height
    ax = cv.plot()
    names = [t.get_text() for t in ax.texts if isinstance(t, Annotation)]
    assert sorted(names) == sorted(cv.points["type"].to_list())
    p1, p2 = cv.parameters
    assert ax.get_xlabel() == _style.label(p1) and ax.get_ylabel() == _style.label(p2)
    # the fixed disk parameters are written over the curve, not the varied ones
    cap = " ".join(t.get_text() for t in ax.texts if not isinstance(t, Annotation))
    assert r"$C_0$ = 0.35" in cap and r"$e$ = 2" in cap
    assert _style.symbol(p1) not in cap and _style.symbol(p2) not in cap
    plt.close(ax.figure)


def test_sweep_plot_draws_up_and_down() -> None:
    sw = made("Sweep")
    fig = sw.plot()
    ax = fig.axes[0]
    labels = [ln.get_label() for ln in ax.lines]
    assert "up" in labels and "down" in labels
    up = sw.table.filter(pl.col("direction") == "up")
    line = ax.lines[labels.index("up")]
    assert np.allclose(line.get_xdata(), up["Omega"].to_numpy())
    text = repr(sw)
    assert f"{sw.table.height} steps" in text
    plt.close(fig)


def test_film_force_summary_hides_the_pressure_field() -> None:
    f = made("FilmForce")
    assert f.pressure is not None and f.pressure.size > 1000
    assert f"ε={f.eccentricity:.4g}" in repr(f)
    assert "pressure field {}x{}".format(*f.pressure.shape) in repr(f)


def test_pickle_and_equality_keep_working() -> None:
    for name in ("BearingEquilibrium", "Vibration", "Sweep"):
        x = made(name)
        y = pickle.loads(pickle.dumps(x))
        assert repr(y) == repr(x)
    beq = made("BearingEquilibrium")
    assert beq == pickle.loads(pickle.dumps(beq))
    v = made("Vibration")
    assert v == pickle.loads(pickle.dumps(v))


# -- the style -----------------------------------------------------------------------------


def test_every_registry_parameter_has_a_symbol() -> None:
    for p in _native.parameters():
        name = p["name"]
        assert _style.symbol(name) != name, name
        assert _style.symbol(name).startswith("$"), name
        if p["per_ball"]:
            # the first ball's name ends in 1 and so does its subscript, as b1's does
            assert re.search(r"_\{([a-z]+,)?1\}\$$", _style.symbol(f"{name}1")), name
    # Omega and omega differ in more than case
    assert _style.label("Omega") == r"$\Omega$ ($\omega_n$)"
    assert _style.label("omega") == r"$\omega$ ($\omega_n$)"
    assert _style.label("t") == r"$t$ ($1/\omega_n$)"
    assert _style.label("not_a_quantity") == "not_a_quantity"


def test_marker_size_follows_the_grid() -> None:
    fig, ax = plt.subplots(figsize=(6, 4.5))
    bbox = ax.get_window_extent()
    width = bbox.width * 72.0 / fig.dpi
    height = bbox.height * 72.0 / fig.dpi
    sizes = {}
    for n in (5, 21, 61):
        s = _style.grid_marker_size(ax, n, n)
        sizes[n] = s
        # a marker's width (sqrt of its area in points squared) fits its cell
        assert math.sqrt(s) <= min(width, height) / n + 1e-9
    assert sizes[61] < sizes[21] <= sizes[5]
    plt.close(fig)


def test_scan_map_carries_its_fixed_parameters_and_symbols() -> None:
    model = ballbal.Balancer(mu=0.25, zeta=0.04)
    df = ballbal.scan(model, Omega=[1.1, 1.2, 1.3], eta=[0.8, 1.0], patterns=["R-R"])
    ax = scan_map(df)
    assert ax.get_xlabel() == _style.label("Omega")
    assert ax.get_ylabel() == _style.label("eta")
    cap = " ".join(t.get_text() for t in ax.texts)
    assert r"$\mu$ = 0.25" in cap and r"$\zeta$ = 0.04" in cap
    assert r"$\Omega$" not in cap and r"$\eta$" not in cap  # the axes are not fixed
    # the outer markers are not cut: the limits reach half a cell beyond them
    lo, hi = ax.get_xlim()
    assert lo <= 1.1 - 0.05 + 1e-12 and hi >= 1.3 + 0.05 - 1e-12
    plt.close(ax.figure)


# -- progress on the long Python-side loops --------------------------------------------


class _Calls:
    def __init__(self) -> None:
        self.calls: list[tuple[int, int]] = []

    def __call__(self, done: int, total: int) -> None:
        self.calls.append((done, total))


def test_progress_counts_the_steps_of_the_long_loops(capsys: Any) -> None:
    speeds = [0.8, 1.0, 1.2]  # explicit values (a 3-tuple is start, stop, step)
    cb = _Calls()
    speed_sweep(ballbal.Balancer(), speeds, dwell=50.0, record=None, progress=cb)
    steps = 2 * len(speeds) - 1  # up, then down without repeating the top speed
    assert cb.calls == [(k, steps) for k in range(1, steps + 1)]

    cb = _Calls()
    r = ballbal.basins.basins(ballbal.Balancer(Omega=1.35), n=4, orbits=False,
                              chunk=5, progress=cb)
    assert cb.calls and cb.calls[-1] == (16, 16) == (r.table.height, r.table.height)
    assert np.all(np.diff([done for done, _ in cb.calls]) > 0)

    cb = _Calls()
    ballbal.track_damping_study(ballbal.Balancer(Omega=3.0), [0.05, 0.1], 2.5, t_end=100.0,
                                progress=cb)
    assert cb.calls == [(1, 2), (2, 2)]

    cb = _Calls()
    ballbal.accuracy_cost(ballbal.Balancer(), N=(3, 4), samples=(), tol=(), rtol=(),
                          magnus_rtol=(), base_N=6, reference_N=8, repeats=1, progress=cb)
    assert cb.calls == [(1, 2), (2, 2)]

    # True: a tqdm bar (or a line on stderr without tqdm), on stderr, not stdout
    speed_sweep(ballbal.Balancer(), speeds, dwell=50.0, record=None, progress=True)
    out = capsys.readouterr()
    assert "speed sweep" in out.err and out.out == ""


def test_progress_must_be_a_flag_or_a_callable() -> None:
    with pytest.raises(ballbal.exceptions.ParameterTypeError) as e:
        speed_sweep(ballbal.Balancer(), (0.8, 1.0), dwell=50.0, progress="yes")  # type: ignore[arg-type]
    assert e.value.parameter == "progress"


def test_every_label_is_valid_mathtext() -> None:
    # a malformed label raises only when drawn: draw them all
    fig, ax = plt.subplots()
    names = [*_style.QUANTITIES, "eta2", "zeta_b1", "b3", "db2"]
    for i, name in enumerate(names):
        ax.text(0.0, i, _style.label(name))
    fig.canvas.draw()
    plt.close(fig)
