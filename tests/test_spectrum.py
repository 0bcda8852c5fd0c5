"""Ground-frame spectra and the vibration indicator (ballbal.spectrum), each checked
against something computed another way: Tien's (2011) published Fourier magnitudes, the
series evaluated in time, simulations (ballbal's and an independent ground-frame
formulation), and synthetic signals with known lines."""

import math

import numpy as np
import polars as pl
import pytest
from ground_frame import ground_rhs

import ballbal
from ballbal import spectrum as sp
from ballbal.exceptions import ParameterError

STANDARD_MU_DELTA = dict(mu=0.2, delta=50.0)


def _continue(b, pattern, steps, N):
    sol = ballbal.periodic(b, pattern, N=N)
    assert sol.converged, sol.status
    for ch in steps:
        b = b.replace(**ch)
        sol = ballbal.periodic(b, pattern, N=N, guess=sol)
        assert sol.converged, (ch, sol.status)
    return b, sol


@pytest.fixture(scope="module")
def rr():
    """Table 4-7's R-R: zeta 0.02, zeta_b 0.1, Omega 1.3, eta 0.7 (omega 0.32), reached by
    continuation from Tien's (2011) standard R-R (a simulation from rest lands elsewhere)."""
    b = ballbal.Balancer(**STANDARD_MU_DELTA, zeta=0.05, zeta_b=0.05, Omega=1.2, eta=(1.0, 1.0))
    return _continue(b, "R-R", [dict(zeta_b=0.1, zeta=0.02), dict(Omega=1.3),
                                dict(eta=(0.7, 0.7))], N=3)


@pytest.fixture(scope="module")
def ro():
    """Table 4-7's R-O, at zeta = 0.02 (model.md: the printed zeta = 0.1 is a typo),
    continued from a point where simulation finds it (as test_periodic does)."""
    b = ballbal.Balancer(**STANDARD_MU_DELTA, zeta=0.02, zeta_b=0.05, Omega=1.4, eta=(0.8, 0.8))
    return _continue(b, "R-O", [dict(zeta_b=0.075), dict(zeta_b=0.1), dict(Omega=1.35),
                                dict(Omega=1.3), dict(eta=(0.7, 0.7))], N=3)


@pytest.fixture(scope="module")
def oo():
    b = ballbal.Balancer(**STANDARD_MU_DELTA, zeta=0.1, zeta_b=0.1, Omega=1.1, eta=(1.3, 1.3))
    return _continue(b, "O-O", [], N=3)


def _harmonics_from_lines(spec):
    """|a_0| and sqrt(a_m^2 + b_m^2) of x and of y, rebuilt from the line table's
    amplitudes and phases: C_k = A exp(+-i phase_x), x_m = c_m + conj(c_-m),
    y_m = -i (c_m - conj(c_-m)) (the inverse of the module's map, written from the
    phase convention of its docstring)."""
    k = spec["k"].to_numpy()
    f = spec["frequency"].to_numpy()
    c = spec["amplitude"].to_numpy() * np.exp(
        1j * np.where(f >= 0, 1, -1) * spec["phase_x"].to_numpy())
    line = dict(zip(k.tolist(), c, strict=True))
    n = int(k.max())
    hx = [abs(line[0].real)] + [abs(line[m] + np.conj(line[-m])) for m in range(1, n + 1)]
    hy = [abs(line[0].imag)] + [abs(line[m] - np.conj(line[-m])) for m in range(1, n + 1)]
    return np.array(hx), np.array(hy)


# Tien (2011) table 4-7, "Fourier spectra of the periodic solutions": |a_0|,
# sqrt(a_1^2 + b_1^2), sqrt(a_2^2 + b_2^2), sqrt(a_3^2 + b_3^2) of x and y, N = 3.
TABLE_4_7 = {
    "R-R": ([0.5064, 4.8416, 0.0251, 0.0004], [0.1138, 4.8383, 0.0252, 0.0004]),
    "O-O": ([0.0069, 0.1685, 0.0147, 0.0003], [0.0466, 0.2754, 0.0068, 0.0004]),
    "R-O": ([0.2533, 3.5455, 0.0127, 0.0025], [0.2707, 3.6167, 0.0196, 0.0024]),
}


@pytest.mark.parametrize("case", ["R-R", "O-O", "R-O"])
def test_lines_reproduce_table_4_7(case, rr, oo, ro):
    b, sol = {"R-R": rr, "O-O": oo, "R-O": ro}[case]
    assert sol.type == case and sol.N == 3
    spec = sol.spectrum("displacement")
    assert spec["k"].to_list() == [-3, -2, -1, 0, 1, 2, 3]
    assert np.allclose(spec["frequency"], b.Omega + spec["k"].to_numpy() * sol.omega,
                       rtol=0, atol=1e-15)
    hx, hy = _harmonics_from_lines(spec)
    px, py = TABLE_4_7[case]
    # printed to 4 decimals (+-5e-5); Tien (2011) stopped Newton at 1 % relative
    # coefficient change, which leaves its first harmonics 1e-4 off the converged series
    tol = 5e-5 + 2e-4 * np.array(px)
    assert np.all(np.abs(hx - px) <= tol), (hx, px)
    tol = 5e-5 + 2e-4 * np.array(py)
    assert np.all(np.abs(hy - py) <= tol), (hy, py)
    # Tien's (2011) frequencies: omega 0.32 (R-R), 0.09 (O-O), 0.30 (R-O); main line
    # Omega - omega (its figures 4-12, 4-27, 4-28 and section 4-4-7)
    assert abs(sol.omega - {"R-R": 0.32, "O-O": 0.09, "R-O": 0.30}[case]) < 0.005
    acc = sol.spectrum("acceleration")
    assert acc.sort("amplitude")["k"][-1] == -1


def _orbit_ground(b, sol, t):
    """Z, Z' of the series evaluated in time (time_history), rotated to the ground."""
    th = sol.time_history(t)
    z = th["x"].to_numpy() + 1j * th["y"].to_numpy()
    dz = th["dx"].to_numpy() + 1j * th["dy"].to_numpy()
    rot = np.exp(1j * b.Omega * t)
    return rot * z, rot * (dz + 1j * b.Omega * z)


@pytest.mark.parametrize("case", ["R-R", "O-O", "R-O"])
def test_parseval_on_the_series(case, rr, oo, ro):
    b, sol = {"R-R": rr, "O-O": oo, "R-O": ro}[case]
    m = 64  # > 2 N + 1: the uniform mean of a degree-2N trigonometric polynomial is exact
    t = np.arange(m) * sol.period / m
    Z, V = _orbit_ground(b, sol, t)
    for q, sig in (("displacement", Z), ("velocity", V)):
        spec = sol.spectrum(q)
        lines = spec["amplitude"].to_numpy()
        ms = np.mean(np.abs(sig) ** 2)
        assert abs(np.sum(lines**2) - ms) <= 1e-13 * ms, q
        # and point by point, as the docstring's X = A cos(|f| t + phase_x), Y likewise
        arg = np.outer(t, np.abs(spec["frequency"].to_numpy()))
        X = np.cos(arg + spec["phase_x"].to_numpy()) @ lines
        Y = np.cos(arg + spec["phase_y"].to_numpy()) @ lines
        scale = np.max(np.abs(sig))
        assert np.max(np.abs(X + 1j * Y - sig)) <= 1e-13 * scale, q


@pytest.fixture(scope="module")
def rr8(rr):
    b, sol = rr
    return b, ballbal.periodic(b, "R-R", N=8, guess=sol)


def _one_period_sim(b, sol, per_period, periods=2):
    """A simulation from the orbit's state, sampled per_period times a period; the
    ground_signal rows of its second period (away from the trimmed ends)."""
    h = sol.period / per_period
    t = np.arange(periods * per_period + 8) * h
    sim = ballbal.simulate(b, sol.state(0.0), t, rtol=1e-12, atol=1e-14)
    return sim, h


def test_parseval_on_a_simulation(rr8):
    b, sol = rr8
    sim, h = _one_period_sim(b, sol, 512)
    for q in ("displacement", "velocity", "acceleration"):
        g = sp.ground_signal(sim, q)
        g = g.filter((pl.col("t") >= sol.period - h / 2) & (pl.col("t") < 2 * sol.period - h / 2))
        assert g.height == 512
        ms = np.mean(g["X"].to_numpy() ** 2 + g["Y"].to_numpy() ** 2)
        lines = sol.spectrum(q)["amplitude"].to_numpy()
        # simulation tolerance 1e-12, series truncation (N = 8) and, for the
        # acceleration, the difference formula ((f h)^4 / 30 ~ 1e-8 here)
        assert abs(np.sum(lines**2) - ms) <= 1e-6 * ms, (q, np.sum(lines**2), ms)


def test_fft_of_a_long_simulation_finds_the_lines(rr8):
    b, sol = rr8
    h = 0.05
    t = np.arange(0.0, 60 * sol.period, h)
    sim = ballbal.simulate(b, sol.state(0.0), t, rtol=1e-10, atol=1e-12)
    spec = sp.signal_spectrum(sp.ground_signal(sim, "acceleration"))
    assert spec["direction"].n_unique() >= 2  # two-sided
    f = spec["frequency"].to_numpy()
    a = spec["amplitude"].to_numpy()
    bin_ = f[1] - f[0]
    exact = sol.spectrum("acceleration")
    strong = exact.filter(pl.col("relative_amplitude") > 1e-3)
    assert strong.height >= 3
    for fk, ak in strong.select("frequency", "amplitude").iter_rows():
        near = np.flatnonzero(np.abs(f - fk) <= 6 * bin_)
        j = near[np.argmax(a[near])]
        assert abs(f[j] - fk) <= bin_, (fk, f[j])
        assert abs(a[j] - ak) <= 0.01 * ak, (fk, a[j], ak)
    # and labelling the FFT's peaks gives back the lines' k (omega estimated)
    peaks = sp.label_peaks(spec, b.Omega, threshold=1e-3)
    assert peaks["in_family"].all()
    assert abs(peaks["omega"][0] - sol.omega) < 0.1 * bin_
    assert set(peaks["k"].to_list()) == set(strong["k"].to_list())


def test_hann_and_flattop_scaling_on_a_synthetic_whirl():
    h = 0.02
    t = np.arange(20000) * h
    f1, f2 = 1.2345, -0.77  # a forward and a backward whirl
    Z = 0.8 * np.exp(1j * (f1 * t + 0.3)) + 0.25 * np.exp(1j * (f2 * t - 1.0))
    for window, loss in (("flattop", 0.0025), ("hann", 0.16)):
        spec = sp.signal_spectrum(t, Z.real, Z.imag, window=window)
        for fk, ak in ((f1, 0.8), (f2, 0.25)):
            part = spec.filter((pl.col("frequency") - fk).abs() < 0.01)
            peak = part["amplitude"].max()
            assert ak * (1 - loss) <= peak <= ak * (1 + 1e-3), (window, fk, peak)
        fwd = spec.filter(pl.col("direction") == "forward")["amplitude"].max()
        bwd = spec.filter(pl.col("direction") == "backward")["amplitude"].max()
        assert fwd > 0.7 and 0.2 < bwd < 0.3
    # one-sided spectrum of X alone: a cosine of amplitude A gives A
    one = sp.signal_spectrum(t, 0.5 * np.cos(2.0 * t + 0.4))
    assert abs(one["amplitude"].max() - 0.5) < 0.5 * 0.0025
    # psd: Parseval over the bins, rectangular window, a whole number of periods
    x = np.cos(2 * np.pi * 50 * np.arange(1000) / 1000) + 0.3
    p = sp.signal_spectrum(np.arange(1000) * h, x, window="rect", scaling="psd")
    df = p["frequency"][1] - p["frequency"][0]
    assert abs(p["amplitude"].sum() * df - np.mean(x**2)) < 1e-12


def _rig_tone(rpm, amp, t):
    return amp * np.cos(2 * np.pi * rpm / 60 * t)


def test_label_peaks_on_a_synthetic_record_flags_the_off_family_line():
    """The 800 rpm R-R record of Tien's (2011) section 4-4-2 rebuilt as a signal in
    seconds: lines at 498 (ball whirl, largest), 800 (spin), 1102 rpm, an off-family
    line at 996 rpm (twice the ball whirl), a little noise."""
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 60.0, 1 / 500)  # 60 s at 500 Hz
    x = (_rig_tone(498, 1.0, t) + _rig_tone(800, 0.3, t) + _rig_tone(1102, 0.1, t)
         + _rig_tone(996, 0.08, t) + 0.01 * rng.standard_normal(t.size))
    spec = sp.signal_spectrum(t, x, time_unit="s", natural_frequency_rpm=513)
    assert {"frequency", "frequency_hz", "frequency_rpm"} <= set(spec.columns)
    peaks = sp.label_peaks(spec, 800.0, column="frequency_rpm", threshold=0.03)
    got = {round(f): (k, fam) for f, k, fam in
           peaks.select("frequency", "k", "in_family").iter_rows()}
    assert set(got) == {498, 800, 996, 1102}
    assert got[498] == (-1, True) and got[800] == (0, True) and got[1102] == (1, True)
    assert got[996][1] is False
    assert abs(peaks["omega"][0] - 302) < 0.2


def test_label_lines_recovers_the_measured_labels():
    """Section 4-4-7's measured peaks (rpm) and their labels as Tien (2011) gives them."""
    oo = sp.label_lines([507, 532, 555, 579, 602, 627], 555)  # O-O at 555 rpm
    assert oo["k"].to_list() == [-2, -1, 0, 1, 2, 3] and oo["in_family"].all()
    assert abs(oo["omega"][0] - 24) < 0.5  # "about 24 rpm"
    ro = sp.label_lines([482, 521, 560, 599, 638], 560)  # R-O at 560 rpm
    assert ro["k"].to_list() == [-2, -1, 0, 1, 2] and ro["in_family"].all()
    assert abs(ro["omega"][0] - 39) < 1e-9
    rr = sp.label_lines([498, 800, 996, 1102], 800)  # R-R at 800 rpm (section 4-4-2)
    assert rr["in_family"].to_list() == [True, True, False, True]
    assert rr.filter(pl.col("in_family"))["k"].to_list() == [-1, 0, 1]
    # a given omega is used as is
    fixed = sp.label_lines([498, 800, 996, 1102], 800, omega=302)
    assert (fixed["omega"] == 302).all() and fixed["k"].to_list() == [-1, 0, 1, 1]


def test_label_peaks_on_a_simulated_o_o_motion(oo):
    b, sol3 = oo
    sol = ballbal.periodic(b, "O-O", N=8, guess=sol3)
    h = 0.1
    t = np.arange(0.0, 30 * sol.period, h)
    sim = ballbal.simulate(b, sol.state(0.0), t, rtol=1e-9, atol=1e-11)
    spec = sp.signal_spectrum(sp.ground_signal(sim, "acceleration"))
    peaks = sp.label_peaks(spec, b.Omega, threshold=0.01)
    exact = sol.spectrum("acceleration").filter(pl.col("relative_amplitude") > 0.015)
    assert peaks["in_family"].all()
    assert sorted(peaks["k"].to_list()) == sorted(exact["k"].to_list()) == [-2, -1, 0, 1, 2]
    assert abs(peaks["omega"][0] - sol.omega) < 1e-3 * sol.omega


def _ground_acceleration(b, sim):
    """X'', Y'' from the independent ground-frame equations of tests/ground_frame.py at
    the simulated states."""
    sc = ballbal.Scene(balancer=b)
    n = b.n_balls
    out = []
    for r in sim.iter_rows(named=True):
        rot = complex(math.cos(r["theta"]), math.sin(r["theta"]))
        z = complex(r["x"], r["y"])
        Z = rot * z
        V = rot * (complex(r["dx"], r["dy"]) + 1j * b.Omega * z)
        phi = [r["theta"] + r[f"b{i + 1}"] for i in range(n)]
        dphi = [b.Omega + r[f"db{i + 1}"] for i in range(n)]
        s = np.array([Z.real, Z.imag, *phi, V.real, V.imag, *dphi])
        acc = ground_rhs(sc, r["t"], s)[n + 2 : n + 4]
        out.append(complex(acc[0], acc[1]))
    return np.array(out)


@pytest.mark.parametrize("case", ["R-R", "R-O"])
def test_vibration_indicator_exact_against_simulation(case, rr8, ro):
    b, sol = rr8 if case == "R-R" else (ro[0], ballbal.periodic(ro[0], "R-O", N=8,
                                                                 guess=ro[1]))
    v = sol.vibration()
    assert v.exact and v.mean_error < 1e-13 * v.mean
    per = 400
    sim, h = _one_period_sim(b, sol, per)
    one = sim.filter((pl.col("t") >= sol.period - h / 2) & (pl.col("t") < 2 * sol.period - h / 2))
    assert one.height == per
    a = np.abs(_ground_acceleration(b, one))
    # the trapezoid mean of 400 samples of this analytic periodic function is converged;
    # min / max of samples h apart sit within (h |g''| / 2)^2-ish of the true extrema
    assert abs(v.mean - a.mean()) <= 1e-7 * v.mean
    assert abs(v.rms - np.sqrt(np.mean(a**2))) <= 1e-7 * v.rms
    assert 0 <= v.max - a.max() <= 1e-4 * v.max
    assert 0 <= a.min() - v.min <= 1e-4 * v.max
    # the same from the simulation table (its difference-formula acceleration), over
    # the same whole period
    vs = sp.vibration(sim, t_min=sol.period - 2.5 * h)
    assert not vs.exact
    g = sp.ground_signal(sim).filter(pl.col("t") < 2 * sol.period - h / 2)
    ga = np.hypot(g["X"].to_numpy(), g["Y"].to_numpy())[-per:]
    # the difference formula's error, (f h)^4 / 30 = 2e-7 for the main line here
    assert abs(ga.mean() - v.mean) <= 1e-6 * v.mean
    assert abs(vs.max - v.max) <= 1e-4 * v.max
    # a denser exact evaluation agrees with the adaptive one to round-off
    k = sol.spectrum("acceleration")
    C = k["amplitude"].to_numpy() * np.exp(1j * k["phase_x"].to_numpy()
                                           * np.sign(k["frequency"].to_numpy()))
    s = np.linspace(0, 2 * np.pi, 200_001)[:-1]
    g = np.abs(np.exp(1j * np.outer(s, k["k"].to_numpy())) @ C)
    assert abs(g.mean() - v.mean) < 1e-12 * v.mean
    assert 0 <= v.max - g.max() < 1e-9 * v.max and 0 <= g.min() - v.min < 1e-9 * v.max


def test_equilibrium_spectrum_is_the_synchronous_line():
    b = ballbal.Balancer(**STANDARD_MU_DELTA, zeta=0.05, zeta_b=0.05, Omega=1.6, eta=(0.3, 0.3))
    eqs = ballbal.equilibria(b)
    eq = next(e for e in eqs if math.hypot(e.q[0], e.q[1]) > 1e-3)
    with pytest.raises(ParameterError) as err:
        sp.line_spectrum(eq)
    assert err.value.parameter == "Omega"
    spec = sp.line_spectrum(eq, "acceleration", Omega=b.Omega)
    r = math.hypot(eq.q[0], eq.q[1])
    assert spec.height == 1 and spec["k"][0] == 0 and spec["frequency"][0] == b.Omega
    assert abs(spec["amplitude"][0] - b.Omega**2 * r) < 1e-14
    # a simulation from the equilibrium: |Z''| stays Omega^2 r (difference formula:
    # (Omega h)^4 / 30 = 4e-8)
    y0 = np.concatenate([eq.q, np.zeros(eq.q.size)])
    sim = ballbal.simulate(b, y0, np.arange(0, 30, 0.02), rtol=1e-12, atol=1e-14)
    vs = sp.vibration(sim)
    v = sp.vibration(eq, Omega=b.Omega)
    assert v.min == v.max == v.mean
    assert abs(vs.max - v.mean) < 1e-6 * v.mean and abs(vs.min - v.mean) < 1e-6 * v.mean


def test_units_and_filters(rr):
    b, sol = rr
    s = sol.spectrum("acceleration", natural_frequency_rpm=513, eccentricity=1e-3,
                     min_relative=1e-3)
    assert s["relative_amplitude"].min() >= 1e-3 and s["relative_amplitude"].max() == 1
    assert np.allclose(s["frequency_rpm"], s["frequency"] * 513)
    assert np.allclose(s["frequency_hz"], s["frequency"] * 513 / 60)
    wn = 2 * np.pi * 513 / 60
    assert np.allclose(s["amplitude_si"], s["amplitude"] * 1e-3 * wn**2)
    v = sol.spectrum("velocity", natural_frequency_hz=513 / 60, eccentricity=1e-3)
    assert np.allclose(v["amplitude_si"], v["amplitude"] * 1e-3 * wn)
    d = sol.spectrum("displacement")
    a = sol.spectrum("acceleration")
    assert np.allclose(a["amplitude"], d["amplitude"] * d["frequency"] ** 2, rtol=1e-14)
    # X of each line leads Y by a quarter turn when forward
    fwd = a.filter(pl.col("direction") == "forward")
    dphi = np.angle(np.exp(1j * (fwd["phase_x"] - fwd["phase_y"]).to_numpy()))
    assert np.allclose(dphi, np.pi / 2)


def test_bad_arguments_name_the_parameter(rr):
    b, sol = rr
    cases = [
        (lambda: sol.spectrum("jerk"), "quantity"),
        (lambda: sol.spectrum(natural_frequency_hz=8, natural_frequency_rpm=500),
         "natural_frequency_rpm"),
        (lambda: sol.spectrum(natural_frequency_rpm=-1), "natural_frequency_rpm"),
        (lambda: sol.spectrum(eccentricity=1e-3), "eccentricity"),
        (lambda: sol.spectrum(Omega=1.2), "Omega"),
        (lambda: sp.signal_spectrum([0, 1, 3, 4, 5, 6, 7, 8], np.ones(8)), "t"),
        (lambda: sp.signal_spectrum(np.arange(10.0), np.ones(9)), "X"),
        (lambda: sp.signal_spectrum(np.arange(10.0), np.ones(10), window="kaiser"), "window"),
        (lambda: sp.signal_spectrum(np.arange(10.0), np.ones(10), two_sided=True),
         "two_sided"),
        (lambda: sp.label_lines([1.0, 2.0], 1.5, tol=0.9), "tol"),
        (lambda: sp.waterfall([]), "items"),
    ]
    for call, name in cases:
        with pytest.raises(ParameterError) as err:
            call()
        assert err.value.parameter == name


def test_waterfall_table_and_plots(rr, tmp_path):
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    b, sol = rr
    items = [(1.3, sol.spectrum()), (1.35, sol.spectrum())]
    w = sp.waterfall(items)
    assert w.columns[0] == "Omega" and w.height == 2 * sol.spectrum().height
    assert w.filter(pl.col("Omega") == 1.35).drop("Omega").equals(sol.spectrum())
    ax = sp.plot_waterfall(w)
    ax2 = sp.plot_spectrum(sol.spectrum())
    ax2.figure.savefig(tmp_path / "s.png")
    # the speed axis in the plot style's symbol and unit (ballbal._style)
    assert ax.get_ylabel() == r"$\Omega$ ($\omega_n$)" and (tmp_path / "s.png").stat().st_size > 0


def test_ground_signal_during_a_ramp_matches_the_ground_frame_equations():
    """The disk's rate theta' is read off the theta column: during a run-up the
    accelerations still agree with the independent ground-frame formulation."""
    b = ballbal.Balancer(**STANDARD_MU_DELTA, zeta=0.05, zeta_b=0.05, Omega=1.0, eta=(0.7, 0.7))
    ramp = ballbal.Ramp(to=1.6, start=5.0, duration=20.0)
    sc = ballbal.Scene(balancer=b, ramp=ramp)
    h = 0.01
    sim = ballbal.simulate(sc, None, np.arange(0.0, 30.0, h), rtol=1e-12, atol=1e-14)
    g = sp.ground_signal(sim, "acceleration")
    rate = (ramp.to - b.Omega) / ramp.duration
    n = b.n_balls
    worst = 0.0
    rows = sim.slice(4, sim.height - 8)  # ground_signal's rows: two trimmed per end, twice
    for r, (X2, Y2) in zip(rows.iter_rows(named=True), g.select("X", "Y").iter_rows(),
                           strict=True):
        t = r["t"]
        if min(abs(t - ramp.start), abs(t - ramp.start - ramp.duration)) < 4.5 * h:
            continue  # the rate has kinks: the two nested difference formulas span 4 h
        w = b.Omega + rate * min(max(t - ramp.start, 0.0), ramp.duration)
        rot = complex(math.cos(r["theta"]), math.sin(r["theta"]))
        z = complex(r["x"], r["y"])
        Z, V = rot * z, rot * (complex(r["dx"], r["dy"]) + 1j * w * z)
        s = np.array([Z.real, Z.imag, *[r["theta"] + r[f"b{i + 1}"] for i in range(n)],
                      V.real, V.imag, *[w + r[f"db{i + 1}"] for i in range(n)]])
        acc = ground_rhs(sc, t, s)[n + 2 : n + 4]
        worst = max(worst, abs(complex(X2 - acc[0], Y2 - acc[1])) / abs(complex(*acc)))
    assert worst < 1e-6, worst


def test_an_unconverged_solution_is_a_parameter_error_naming_it() -> None:
    """A solve that did not converge has no lines: that was a plain ValueError."""
    s = ballbal.periodic(ballbal.Balancer(), "R-R", N=3,
                         options=ballbal.PeriodicOptions(
                             harmonic_balance=ballbal.HarmonicBalance(max_iter=1)))
    assert s.omega is None
    for f, name in ((sp.line_spectrum, "solution"), (sp.vibration, "source")):
        with pytest.raises(ParameterError) as e:
            f(s)
        assert e.value.parameter == name


def test_peak_labelling_is_bounded() -> None:
    """The line spacing is estimated in n^2 work over n peaks: more than MAX_LINES are
    refused, and so is a max_peaks above it (label_peaks took up to 10**6)."""
    from ballbal import _check

    with pytest.raises(ParameterError) as e:
        sp.label_lines(np.linspace(0.0, 5.0, _check.MAX_LINES + 1), 1.2)
    assert e.value.parameter == "frequencies"
    f = np.linspace(0.0, 5.0, 400)
    table = pl.DataFrame({"frequency": f, "amplitude": np.exp(-((f - 1.2) / 0.02) ** 2)})
    with pytest.raises(ParameterError) as e:
        sp.label_peaks(table, 1.2, max_peaks=_check.MAX_LINES + 1)
    assert e.value.parameter == "max_peaks"
    peaks = sp.label_peaks(table, 1.2, max_peaks=_check.MAX_LINES)
    assert peaks.height == 1 and abs(peaks["frequency"][0] - 1.2) < 1e-3
