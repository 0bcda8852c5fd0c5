"""A rigid rotor on one journal bearing (fixed frame, no balls): ballbal._rotor.

Every expected number is computed here independently of the core: the short (Ocvirk)
bearing's force by Gauss quadrature of its pressure over the positive region, the static
equilibrium from the closed-form load-eccentricity relation, the linear whirl threshold from
the eigenvalues of the rotor on finite-difference coefficients of that force, and a
trajectory from scipy's solve_ivp.
"""

from __future__ import annotations

import math
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ballbal.bearing import Bearing, RotorImpulse, RotorOnBearing, simulate_rotor
from ballbal.exceptions import ParameterError

from ocvirk import LAM
from ocvirk import film_force as short_force

SHORT = Bearing(length_ratio=LAM, model="short")


def static_eccentricity(load: float) -> float:
    """Ocvirk: W / F0 = eps sqrt(16 eps^2 + pi^2 (1 - eps^2)) / (4 (1 - eps^2)^2)."""
    return brentq(lambda e: e * math.sqrt(16 * e * e + math.pi**2 * (1 - e * e))
                  / (4 * (1 - e * e) ** 2) - load, 1e-9, 1 - 1e-9, xtol=1e-15)


def static_position(load: float) -> tuple[float, float]:
    """Load along +x, rotation counter-clockwise: the journal sits at the attitude angle
    psi ahead of the load, tan psi = pi sqrt(1 - eps^2) / (4 eps)."""
    e = static_eccentricity(load)
    psi = math.atan2(math.pi * math.sqrt(1 - e * e), 4 * e)
    return e * math.cos(psi), e * math.sin(psi)


def coefficients(x: float, y: float, h: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    k, c = np.zeros((2, 2)), np.zeros((2, 2))
    for j in range(4):
        d = np.zeros(4)
        d[j] = h
        s = np.array([x, y, 0.0, 0.0])
        col = -(short_force(*(s + d)) - short_force(*(s - d))) / (2 * h)
        (k if j < 2 else c)[:, j % 2] = col
    return k, c


def max_real(k: np.ndarray, c: np.ndarray, m: float) -> tuple[float, float]:
    a = np.zeros((4, 4))
    a[0, 2] = a[1, 3] = 1
    a[2:, :2] = -k / m
    a[2:, 2:] = -c / m
    ev = np.linalg.eigvals(a)
    i = np.argmax(ev.real)
    return ev[i].real, abs(ev[i].imag)


def rotor(m: float, load: float, **kw: object) -> RotorOnBearing:
    return RotorOnBearing(SHORT, m, gravity=load / m, **kw)  # type: ignore[arg-type]


def test_two_starts_settle_on_the_closed_form_equilibrium() -> None:
    load = 5.73  # static eps ~ 0.8: stable at every speed
    xe, ye = static_position(load)
    finals = []
    for eps0 in (0.75, 0.3):
        tr = simulate_rotor(rotor(1.0, load), (0.0, eps0), (0.0, 150.0), samples=301)
        assert tr.outcome == "completed", tr.message
        last = tr.table.row(-1, named=True)
        finals.append((last["x"], last["y"]))
        assert abs(last["x"] - xe) < 1e-5 and abs(last["y"] - ye) < 1e-5, (last, xe, ye)
        # The film then carries the weight: f = (-W, 0).
        assert abs(last["fx"] + load) < 1e-4 * load and abs(last["fy"]) < 1e-4 * load
    assert np.allclose(finals[0], finals[1], atol=1e-5)


def growth(tr: object, xe: float, ye: float) -> float:
    """Ratio of the deviation's amplitude over the last tenth to the first tenth."""
    t = tr.table  # type: ignore[attr-defined]
    d = np.hypot(t["x"].to_numpy() - xe, t["y"].to_numpy() - ye)
    n = len(d) // 10
    return float(d[-n:].max() / d[:n].max())


def whirl_ratio(tr: object, xe: float) -> float:
    t = tr.table  # type: ignore[attr-defined]
    tau, dx = t["tau"].to_numpy(), t["x"].to_numpy() - xe
    half = len(tau) // 2
    s = np.sign(dx[half:])
    ups = np.nonzero((s[:-1] < 0) & (s[1:] >= 0))[0] + half
    # linear interpolation of the up-crossings; whirl period over spin period 2 pi
    tc = tau[ups] - dx[ups] * (tau[ups + 1] - tau[ups]) / (dx[ups + 1] - dx[ups])
    return float(2 * math.pi / np.mean(np.diff(tc)))


def test_whirl_threshold_from_the_eigenvalues_matches_simulation() -> None:
    load = 0.5  # static eps ~ 0.41 on the short bearing
    xe, ye = static_position(load)
    k, c = coefficients(xe, ye)
    assert max_real(k, c, 1e-3)[0] < 0  # a light rotor is stable
    m_star = brentq(lambda m: max_real(k, c, m)[0], 1e-3, 1e3, xtol=1e-10)
    nu = max_real(k, c, m_star)[1]
    assert 0.4 < nu < 0.6  # oil whirl: near half the spin frequency
    runs = {}
    for f in (0.85, 1.15):
        r = rotor(f * m_star, load)
        tr = simulate_rotor(r, (xe + 0.01, ye), (0.0, 400.0), samples=8001, rtol=1e-9,
                            atol=1e-12)
        assert tr.outcome == "completed", tr.message
        runs[f] = tr
    assert growth(runs[0.85], xe, ye) < 0.5
    assert growth(runs[1.15], xe, ye) > 2.0
    # the growing whirl turns at the linear whirl frequency (just above the threshold it
    # still grows slowly, so the linear ratio holds to a few per cent)
    ratio = whirl_ratio(runs[1.15], xe)
    lin = max_real(k, c, 1.15 * m_star)[1]
    assert abs(ratio - lin) < 0.02 * lin and 0.4 < ratio < 0.55, (ratio, lin, nu)


def test_stable_at_every_speed_above_eps_0756() -> None:
    load = 5.73  # eps ~ 0.8
    xe, ye = static_position(load)
    k, c = coefficients(xe, ye)
    assert all(max_real(k, c, m)[0] < 0 for m in np.geomspace(1e-3, 1e4, 50))
    tr = simulate_rotor(rotor(30.0, load), (xe + 0.02, ye), (0.0, 600.0), samples=601)
    assert tr.outcome == "completed"
    assert growth(tr, xe, ye) < 0.1


def test_centred_unloaded_rotor_on_a_plain_bearing_is_unstable() -> None:
    tr = simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.01, 0.0), (0.0, 300.0), samples=301)
    assert tr.outcome in ("completed", "contact")
    assert tr.table["eccentricity"].max() > 0.1


def test_contact_is_an_outcome_with_its_time() -> None:
    # Far above the rigid-body critical speed the journal orbits about the mass centre at
    # radius ~ e_u / c = 3 > 1; the film cannot hold m (3 - 0.98) ~ 2000 F_S.
    r = RotorOnBearing(SHORT, 1000.0, unbalance=3.0)
    tr = simulate_rotor(r, (0.1, 0.0), (0.0, 100.0), samples=1001)
    assert tr.outcome == "contact" and tr.contact_time is not None
    assert tr.t_end == tr.contact_time < 100.0
    last = tr.table.row(-1, named=True)
    assert last["tau"] == tr.contact_time and abs(last["eccentricity"] - 0.98) < 1e-8
    assert tr.table["tau"].max() == tr.contact_time


@pytest.mark.parametrize("method", ["explicit", "implicit"])
def test_trajectory_matches_solve_ivp(method: str) -> None:
    m, gn, rho = 2.0, 0.4, 0.05
    imp = RotorImpulse(amplitude=5.0, center=3.0, sharpness=2.0, direction=30.0)
    r = RotorOnBearing(SHORT, m, gravity=gn, unbalance=rho, impulse=imp,
                       unbalance_phase=20.0)
    t = np.linspace(0.0, 30.0, 61)
    tol = (1e-10, 1e-12) if method == "explicit" else (1e-7, 1e-10)
    tr = simulate_rotor(r, (0.2, 0.1, 0.0, 0.05), (0.0, 30.0), t_eval=t, rtol=tol[0],
                        atol=tol[1], method=method)
    assert tr.outcome == "completed", tr.message
    di = math.radians(30.0)

    def rhs(tau: float, s: np.ndarray) -> list[float]:
        f = short_force(*s)
        kick = 5.0 * gn * math.exp(-2.0 * (tau - 3.0) ** 2)
        ph = tau + math.radians(20.0)
        return [s[2], s[3],
                f[0] / m + gn + rho * math.cos(ph) + kick * math.cos(di),
                f[1] / m + rho * math.sin(ph) + kick * math.sin(di)]

    ref = solve_ivp(rhs, (0.0, 30.0), [0.2, 0.1, 0.0, 0.05], t_eval=t, rtol=1e-11,
                    atol=1e-13, method="DOP853")
    got = tr.table.select("x", "y", "vx", "vy").to_numpy().T
    err = np.abs(got - ref.y).max()
    assert err < (1e-7 if method == "explicit" else 2e-4), err
    # the film force columns are the force at the rows
    f = np.array([short_force(*s) for s in ref.y.T])
    assert np.allclose(tr.table["fx"], f[:, 0], atol=2e-4 if method == "implicit" else 1e-6)


def test_from_dimensions_gives_the_mass_parameter() -> None:
    b = Bearing(length_ratio=1.0, model="short")
    r = RotorOnBearing.from_dimensions(b, radius=0.01, length=0.02, clearance=1e-5,
                                       viscosity=0.01, mass=0.5, speed=500.0,
                                       unbalance=1e-6)
    assert math.isclose(r.mass_parameter, 0.5 * 1e-15 * 500 / (0.01 * 0.02 * 1e-6))
    assert math.isclose(r.gravity, 9.81 / (1e-5 * 500**2))
    assert math.isclose(r.unbalance, 0.1)


@pytest.mark.parametrize(("make", "name"), [
    (lambda: RotorOnBearing(SHORT, -1.0), "mass_parameter"),
    (lambda: RotorOnBearing(SHORT, 1.0, gravity=-1.0), "gravity"),
    (lambda: RotorOnBearing(SHORT, 1.0, unbalance=-0.1), "unbalance"),
    (lambda: RotorOnBearing(SHORT, 1.0, impulse=RotorImpulse()), "impulse.amplitude"),
    (lambda: RotorOnBearing(SHORT, 1.0, gravity=1.0, impulse=RotorImpulse(sharpness=0.0)),
     "impulse.sharpness"),
    (lambda: RotorOnBearing(SHORT, "a"), "mass_parameter"),  # type: ignore[arg-type]
    (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.99, 0.0), (0, 1)), "x0"),
    (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.1, 0.0, 0.0), (0, 1)), "x0"),
    (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.1, 0.0), (0, 1),
                            eps_contact=1.5), "eps_contact"),
    (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.1, 0.0), (0, 1),
                            method="bdf"), "method"),
    (lambda: simulate_rotor(RotorOnBearing(SHORT, 1.0), (0.1, 0.0), (0, 1),
                            t_eval=[0.5, 0.2]), "t_eval"),
    (lambda: RotorOnBearing.from_dimensions(SHORT, radius=0.01, length=0.01,
                                            clearance=-1e-5, viscosity=0.01, mass=1,
                                            speed=100), "clearance"),
    (lambda: RotorOnBearing.from_dimensions(SHORT, radius=0.01, length=0.02,
                                            clearance=1e-5, viscosity=0.01, mass=1,
                                            speed=100), "length"),
])
def test_bad_input_names_the_parameter(make: object, name: str) -> None:
    with pytest.raises(ParameterError) as e:
        make()  # type: ignore[operator]
    assert e.value.parameter == name


def test_ctrl_c_stops_a_long_run() -> None:
    code = (
        "import sys\nfrom ballbal.bearing import RotorOnBearing, simulate_rotor\n"
        "from ballbal.bearing import Bearing\n"
        "r = RotorOnBearing(Bearing(length_ratio=0.5, model='short'), 1.0, gravity=5.0,"
        " unbalance=0.05)\n"
        "print('ready', flush=True)\n"
        "try:\n    simulate_rotor(r, (0.1, 0.0), (0.0, 1e8), samples=2, max_steps=10**9)\n"
        "except KeyboardInterrupt:\n    sys.exit(7)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    assert p.wait(timeout=10) == 7


def test_a_crawl_near_the_wall_is_reported_stiff_and_the_implicit_method_finishes() -> None:
    # A light rotor pressed towards the wall (weight 250 F_S, static eps ~ 0.97): the
    # squeeze film's damping over the mass parameter is ~ 1e7, far beyond the explicit
    # step's stability limit over a time span of 50.
    r = RotorOnBearing(SHORT, 1e-4, gravity=2.5e6)
    tr = simulate_rotor(r, (0.9, 0.0), (0.0, 50.0), samples=6, eps_contact=0.995,
                        stiff_steps=10_000)
    assert tr.outcome == "stiff" and tr.stiff_eccentricity is not None
    assert tr.stiff_eccentricity > 0.9 and tr.t_end < 50.0
    tr = simulate_rotor(r, (0.9, 0.0), (0.0, 50.0), samples=6, eps_contact=0.995,
                        method="implicit")
    assert tr.outcome == "completed", tr.message
    # it settles where the film carries the weight (Ocvirk's closed form)
    xe, ye = static_position(250.0)
    last = tr.table.row(-1, named=True)
    assert abs(last["x"] - xe) < 1e-4 and abs(last["y"] - ye) < 1e-4


def test_plot_trajectory_draws_orbit_and_tangential_force() -> None:
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from ballbal.bearing import plot_trajectory

    tr = simulate_rotor(rotor(1.0, 5.73), (0.0, 0.3), (0.0, 20.0), samples=101)
    orbit, force = plot_trajectory({"a": tr, "b": tr}, title="t")
    assert isinstance(orbit, Figure) and isinstance(force, Figure)
    assert len(force.axes[0].lines) == 2
