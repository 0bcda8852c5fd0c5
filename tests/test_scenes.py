"""Scenes: each effect checked against a formulation written here independently (the
Lagrangian in ground-fixed coordinates), against limits, and for clear errors."""

import itertools
import math

import numpy as np
import polars as pl
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import root

import ballbal
from ballbal.scene import scene_from_dict

from reference import jacobi_integral

NOT_STATE = ["t", "theta", "X", "Y"]  # simulate() columns besides the state

def ground_rhs(scene, t, s):
    """Equations of motion in the ground frame: rotor centre (X, Y), absolute ball angles
    phi_i, disk angle theta(t) prescribed. From T = sum of m |v|^2 / 2 over rotor, the
    eccentric disk and the balls; V = support spring + gravity + ball springs; track
    damping on phi_i' - theta', support damping on (X', Y')."""
    b = scene.balancer
    n = b.n_balls
    eta = np.asarray(b.eta)
    zb = np.broadcast_to(np.asarray(b.zeta_b, dtype=float), (n,))
    mu, dl, z, g = b.mu, b.delta, b.zeta, scene.gravity
    fb = mu * eta / dl
    X, Y, phi = s[0], s[1], s[2 : 2 + n]
    dX, dY, dphi = s[n + 2], s[n + 3], s[n + 4 :]
    # spin profile, written out again here
    w0, dw, th = b.Omega, 0.0, b.Omega * t
    if scene.ramp is not None:
        r = scene.ramp
        rate = (r.to - w0) / r.duration
        if r.start <= t < r.start + r.duration:
            u = t - r.start
            w0, dw, th = w0 + rate * u, rate, b.Omega * t + 0.5 * rate * u * u
        elif t >= r.start + r.duration:
            end = r.start + r.duration
            th = b.Omega * end + 0.5 * rate * r.duration**2 + r.to * (t - end)
            w0 = r.to
    fx = fy = 0.0
    if scene.impulse is not None:
        f = scene.impulse
        amp = f.amplitude * math.exp(-f.sharpness * (t - f.t0) ** 2)
        fx, fy = amp * math.cos(f.angle), amp * math.sin(f.angle)
    S, C = np.sin(phi), np.cos(phi)
    M = np.eye(n + 2)
    M[0, 2:] = M[2:, 0] = -fb * dl * S
    M[1, 2:] = M[2:, 1] = fb * dl * C
    M[2:, 2:] = np.diag(fb * dl**2)
    rhs = np.empty(n + 2)
    rhs[0] = (fx - 2 * z * dX - X + mu * (math.sin(th) * dw + math.cos(th) * w0**2)
              + np.sum(fb * dl * C * dphi**2))
    rhs[1] = (fy - 2 * z * dY - Y - g - mu * (math.cos(th) * dw - math.sin(th) * w0**2)
              + np.sum(fb * dl * S * dphi**2))
    # ball springs: V = k dl^2 / 2 sum (phi_{j+1} - phi_j - 2 pi / n)^2, a ring closed
    # by ball n to ball 1, or seed 004's chain without that last spring
    dv = np.zeros(n)
    if scene.springs:
        kd = scene.springs * dl**2
        for j in range(n if scene.spring_layout == "ring" else n - 1):
            nxt = (j + 1) % n
            sj = phi[nxt] - phi[j] - 2 * math.pi / n + (2 * math.pi if nxt == 0 else 0.0)
            dv[j] -= kd * sj
            dv[nxt] += kd * sj
    rhs[2:] = -2 * zb * mu * eta * dl * (dphi - w0) - g * fb * dl * C - dv
    return np.concatenate([s[n + 2 :], np.linalg.solve(M, rhs)])


def to_ground(scene, t, df):
    n = scene.n_balls
    th = df["theta"].to_numpy()
    x, y = df["x"].to_numpy(), df["y"].to_numpy()
    X = np.cos(th) * x - np.sin(th) * y
    Y = np.sin(th) * x + np.cos(th) * y
    phi = np.stack([th + df[f"b{i + 1}"].to_numpy() for i in range(n)])
    return X, Y, phi


FULL = ballbal.Scene(
    balancer=ballbal.Balancer(mu=0.25, zeta=0.03, zeta_b=(0.04, 0.05, 0.03), delta=20.0,
                              Omega=1.2, eta=(0.9, 1.1, 0.7)),
    springs=2e-3, ramp=ballbal.Ramp(to=1.8, start=5.0, duration=20.0), gravity=0.05,
    impulse=ballbal.Impulse(amplitude=0.5, t0=12.0, sharpness=2.0, angle=0.7),
)


def ground_gap(sc, y0, t):
    """Largest difference in X, Y and the ball angles between ballbal's rotating-frame
    simulation and the ground-frame formulation above, from the same initial state."""
    n = sc.n_balls
    df = ballbal.simulate(sc, y0, t, rtol=1e-11, atol=1e-13)
    X, Y, phi = to_ground(sc, t, df)
    w = sc.Omega  # theta(0) = 0, so the ground state differs only in the velocities
    g0 = np.concatenate([[y0[0], y0[1]], y0[2 : 2 + n],
                         [y0[n + 2] - w * y0[1], y0[n + 3] + w * y0[0]], w + y0[n + 4 :]])
    ref = solve_ivp(lambda tt, s: ground_rhs(sc, tt, s), (t[0], t[-1]), g0, t_eval=t,
                    rtol=1e-11, atol=1e-13, method="DOP853", max_step=0.05)
    assert ref.success
    gap = max(np.max(np.abs(X - ref.y[0])), np.max(np.abs(Y - ref.y[1])),
              np.max(np.abs(phi - ref.y[2 : 2 + n])))
    return gap, df


def test_every_effect_against_the_ground_frame_lagrangian():
    y0 = np.array([0.2, -0.1, 0.3, 2.0, 4.5, 0.05, 0.1, -0.2, 0.1, 0.3])
    t = np.linspace(0.0, 40.0, 81)
    gap, df = ground_gap(FULL, y0, t)
    assert gap < 1e-7
    # and the effects do something: without them the motion differs
    plain = ballbal.simulate(FULL.balancer, y0, t, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(plain["x"].to_numpy() - df["x"].to_numpy())) > 1e-2


def test_spring_chain_against_the_ground_frame_lagrangian():
    y0 = np.array([0.2, -0.1, 0.3, 2.0, 4.5, 0.05, 0.1, -0.2, 0.1, 0.3])
    t = np.linspace(0.0, 40.0, 81)
    chain = FULL.replace(spring_layout="chain")
    gap, df = ground_gap(chain, y0, t)
    assert gap < 1e-7
    ring = ballbal.simulate(FULL, y0, t, rtol=1e-11, atol=1e-13)
    assert np.max(np.abs(ring["b1"].to_numpy() - df["b1"].to_numpy())) > 1e-2


def test_two_ball_ring_is_a_chain_of_twice_the_stiffness():
    b = ballbal.Balancer(Omega=1.3, zeta_b=0.05)
    y0 = np.array([0.1, 0.0, 0.4, 2.9, 0.0, 0.1, -1.3, -1.0])
    t = np.linspace(0.0, 60.0, 61)
    ring = ballbal.simulate(ballbal.Scene(balancer=b, springs=1e-3), y0, t, rtol=1e-11,
                            atol=1e-13)
    chain = ballbal.simulate(ballbal.Scene(balancer=b, springs=2e-3, spring_layout="chain"),
                             y0, t, rtol=1e-11, atol=1e-13)
    half = ballbal.simulate(ballbal.Scene(balancer=b, springs=1e-3, spring_layout="chain"),
                            y0, t, rtol=1e-11, atol=1e-13)
    cols = ["x", "y", "b1", "b2"]
    assert np.max(np.abs(ring.select(cols).to_numpy() - chain.select(cols).to_numpy())) < 1e-9
    assert np.max(np.abs(ring.select(cols).to_numpy() - half.select(cols).to_numpy())) > 1e-3
    eq_r = ballbal.equilibria(ballbal.Scene(balancer=b, springs=1e-3))
    eq_c = ballbal.equilibria(ballbal.Scene(balancer=b, springs=2e-3, spring_layout="chain"))
    assert [e.kind for e in eq_r] == [e.kind for e in eq_c]
    for u, v in zip(eq_r, eq_c, strict=True):
        assert np.allclose(u.q, v.q, atol=1e-9)


@pytest.mark.parametrize("effect", ["springs", "ramp", "gravity", "impulse"])
def test_each_effect_alone_against_the_ground_frame(effect):
    kw = {"springs": 0.0, "ramp": None, "gravity": 0.0, "impulse": None}
    kw[effect] = getattr(FULL, effect)
    sc = ballbal.Scene(balancer=FULL.balancer, **kw)
    y0 = np.array([0.1, 0.1, 0.0, 2.1, 4.2, 0.0, 0.0, -1.2, -1.2, -1.2])
    gap, _ = ground_gap(sc, y0, np.linspace(0.0, 30.0, 31))
    assert gap < 1e-7


def test_effects_at_zero_equal_the_planar_model():
    b = FULL.balancer
    off = ballbal.Scene(balancer=b, ramp=ballbal.Ramp(to=b.Omega, start=0.0, duration=3.0),
                        impulse=ballbal.Impulse(amplitude=0.0, t0=1.0, sharpness=1.0))
    assert off._effects_on()  # the scene path really runs
    t = np.linspace(0, 50, 101)
    a = ballbal.simulate(b, t_span=(0, 50))
    c = ballbal.simulate(off, t_span=(0, 50))
    assert np.max(np.abs(a.drop("t").to_numpy() - c.drop("t").to_numpy())) < 1e-12
    assert t.size == 101


def test_spring_potential_joins_the_jacobi_integral():
    """Undamped, constant spin: T2 - T0 + V_support + V_springs is conserved; without the
    spring term it is not (so the spring force is the gradient of that potential)."""
    b = ballbal.Balancer(mu=0.3, zeta=0.0, zeta_b=0.0, delta=20, Omega=1.4, eta=(0.8, 1.2, 0.5))
    k = 3e-3
    sc = ballbal.Scene(balancer=b, springs=k)
    y0 = np.array([0.2, -0.1, 0.0, 2.0, 4.0, 0.05, 0.1, -0.3, 0.2, 0.1])
    t = np.linspace(0, 200, 401)
    s = ballbal.simulate(sc, y0, t, rtol=1e-10, atol=1e-12).drop(NOT_STATE).to_numpy()
    beta = s[:, 2:5]
    sp = np.stack([beta[:, 1] - beta[:, 0], beta[:, 2] - beta[:, 1],
                   beta[:, 0] + 2 * np.pi - beta[:, 2]], axis=1) - 2 * np.pi / 3
    v_springs = 0.5 * k * b.delta**2 * np.sum(sp**2, axis=1)
    h = jacobi_integral(b, s) + v_springs
    assert np.max(np.abs(h - h[0])) < 1e-7
    h_wrong = jacobi_integral(b, s)
    assert np.max(np.abs(h_wrong - h_wrong[0])) > 1e-3


def test_periodic_solution_with_springs_is_a_real_orbit():
    base = ballbal.periodic(ballbal.Balancer(), "R-R", N=8)
    s = ballbal.periodic(ballbal.Scene(springs=1e-5), "R-R", N=12, guess=base)
    assert s.converged and abs(s.omega - base.omega) > 1e-3  # the springs matter
    assert s.verify() < 1e-6  # time simulation of the same scene closes the orbit
    assert not s.verdicts_disagree and s.stability == s.hill_stability


@pytest.mark.parametrize(("kw", "effect"), [
    ({"ramp": ballbal.Ramp(to=2.0)}, "ramp"), ({"gravity": 0.1}, "gravity"),
    ({"impulse": ballbal.Impulse(amplitude=1.0, t0=1.0, sharpness=1.0)}, "impulse"),
])
def test_time_dependent_scenes_refuse_harmonic_balance(kw, effect):
    sc = ballbal.Scene(**kw)
    assert sc.time_dependence == effect
    with pytest.raises(ValueError, match=f"^periodic: .*'{effect}'"):
        ballbal.periodic(sc, "R-R")
    with pytest.raises(ValueError, match=f"^equilibria: .*'{effect}'"):
        ballbal.equilibria(sc)
    with pytest.raises(ValueError, match=f"^scan: .*'{effect}'"):
        ballbal.scan(sc, Omega=[1.2], eta=[1.0])
    ballbal.simulate(sc, t_span=(0, 5))  # simulation always works


def test_scene_without_effects_is_the_balancer():
    sc = ballbal.Scene(balancer=ballbal.Balancer(Omega=1.3))
    a = ballbal.scan(sc, Omega=[1.2], eta=[1.0])
    b = ballbal.scan(sc.balancer, Omega=[1.2], eta=[1.0])
    assert a.drop("seconds").equals(b.drop("seconds"))


def test_scene_files_round_trip(tmp_path):
    p = tmp_path / "full.toml"
    FULL.save(p)
    assert ballbal.load_scene(p) == FULL
    chain = FULL.replace(spring_layout="chain")
    chain.save(p)
    assert ballbal.load_scene(p) == chain
    flat = tmp_path / "flat.toml"
    flat.write_text("mu = 0.2\nOmega = 1.3\neta = 0.9\nballs = 3\n")
    sc = ballbal.load_scene(flat)
    assert sc.balancer.eta == (0.9, 0.9, 0.9) and not sc._effects_on()


@pytest.mark.parametrize(("text", "parameter"), [
    ("mu = 0.2\nzetta = 0.1\n", "zetta"),
    ("[balancer]\nmu = 0.2\n[spring]\nstiffness = 1.0\n", "spring"),
    ("[balancer]\nmu = 0.2\n[springs]\nk = 1.0\n", "springs.k"),
    ("[balancer]\nmu = 0.2\n[springs]\nstiffness = 1.0\nlayout = 'star'\n", "spring_layout"),
    ("[balancer]\nmu = 0.2\n[ramp]\nstart = 1.0\n", "ramp.to"),
    ("[balancer]\nmu = 0.2\n[ramp]\nto = 2.0\nduration = 0.0\n", "ramp.duration"),
    ("[balancer]\nmu = 2.0\n", "mu"),
    ("mu = 'x'\n", "mu"),
    ("[balancer]\nmu = 0.2\n[gravity]\ng = -1.0\n", "gravity"),
    ("[balancer]\neta = [1.0]\n[springs]\nstiffness = 0.1\n", "springs"),
    ("mu = 0.2\n[balancer]\nzeta = 0.1\n", "mu"),
    ("mu = = 1\n", "path"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\nj_z = 0.7\n", "tilt.j_z"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 0.0\nb = 2.0\nj_t = 0.3\nj_z = 0.1\n", "tilt.a"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\n", "tilt.j_z"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\nj_z = 0.1\nJ = 1\n",
     "tilt.J"),
])
def test_malformed_scene_files_say_what_is_wrong(tmp_path, text, parameter):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(ballbal.exceptions.ParameterError) as info:
        ballbal.load_scene(p)
    assert info.value.parameter == parameter, str(info.value)


values = st.one_of(st.floats(allow_nan=True), st.integers(-3, 3), st.text(max_size=3),
                   st.sampled_from(["ring", "chain"]),
                   st.booleans(), st.lists(st.floats(0.1, 2.0), max_size=3))
keys = st.sampled_from(["mu", "zeta", "zeta_b", "delta", "Omega", "eta", "balls", "k", "x"])
tables = st.sampled_from(["springs", "ramp", "gravity", "impulse", "tilt", "balancer",
                          "bearing"])
inner = st.dictionaries(st.sampled_from(["stiffness", "to", "start", "duration", "g",
                                         "amplitude", "t0", "sharpness", "angle", "a", "b",
                                         "j_t", "j_z", "zeta_r", "mu", "q", "layout"]),
                        values, max_size=5)


@settings(max_examples=150, deadline=None)
@given(st.dictionaries(keys, values, max_size=6), st.dictionaries(tables, inner, max_size=3))
def test_random_scene_dictionaries_give_a_scene_or_a_clear_error(flat, tabs):
    d = {**flat, **tabs}
    try:
        sc = scene_from_dict(d)
    except ValueError as e:
        assert str(e) and ":" in str(e)
        return
    assert isinstance(sc, ballbal.Scene)
    assert scene_from_dict(sc.to_dict()) == sc


def test_speed_disturbance_ends_in_the_closed_form_perfect_balance():
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, zeta_b=0.1, eta=(0.8, 0.8))
    res = ballbal.disturbance_response(b, to=2.5, t_end=1500)
    assert res.final_r < 1e-6 and res.settle_time is not None
    end = res.trajectory.row(-1, named=True)
    angle = math.acos(-1 / (2 * 0.8))  # perfect balance, closed form
    got = sorted(abs(math.remainder(end[k], 2 * math.pi)) for k in ("b1", "b2"))
    assert np.allclose(got, angle, atol=1e-6)
    assert res.peak > 10 * 0.01  # the disturbance really throws the rotor out


def test_track_damping_trade_off_of_seed_001():
    """More track damping: a smaller peak; past a point, a longer settling; the combined
    index has an interior optimum."""
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, eta=(1.0, 1.0))
    zb = [0.01, 0.05, 0.1, 0.2, 0.4, 0.8]
    df = ballbal.track_damping_study(b, zb, to=2.5, t_end=2000)
    peak = df["peak"].to_list()
    settle = df["settle_time"].to_list()
    assert all(p1 > p2 for p1, p2 in zip(peak, peak[1:], strict=False)), peak
    assert settle[5] > settle[4] > settle[2] and settle[0] > settle[2], settle
    best = df.filter(pl.col("optimal"))["zeta_b"][0]
    assert zb[0] < best < zb[-1], df


def test_disturbance_needs_a_stable_balanced_state_and_an_autonomous_scene():
    with pytest.raises(ballbal.exceptions.ParameterError) as info:
        ballbal.disturbance_response(ballbal.Balancer(Omega=1.2), to=1.5)
    assert info.value.parameter == "model"
    with pytest.raises(ballbal.exceptions.NotAutonomousError) as e:
        ballbal.disturbance_response(ballbal.Scene(gravity=0.1), to=1.5)
    assert e.value.effect == "gravity"


@pytest.mark.parametrize("tilt", [None, ballbal.Tilt(a=1.8, b=2.2, j_t=0.15, j_z=0.25,
                                                     zeta_r=0.05)])
def test_speed_disturbance_of_a_spring_balancer_settles_in_its_balanced_state(tilt):
    """Springs leave a residual whirl; after the disturbance the simulation must come to
    rest in the balanced state at the new speed, computed as an equilibrium."""
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, zeta_b=0.1)
    sc = ballbal.Scene(balancer=b, springs=1e-4, tilt=tilt)
    res = ballbal.disturbance_response(sc, to=2.5, t_end=1500)
    target = ballbal.balanced_state(sc.replace(Omega=2.5))
    assert target.stability == "stable"
    end = res.trajectory.row(-1, named=True)
    q = np.array([end[c] for c in sc.coordinates])
    # identical balls: the same state whichever ball is where (they may swap places)
    o = len(sc.coordinates) - sc.n_balls
    assert np.allclose(canonical(q, True, o), canonical(target.q, True, o), atol=1e-5)
    assert res.final_r == pytest.approx(math.hypot(*target.q[:2]), abs=1e-6)
    assert res.final_r > 0.1  # the springs' residual whirl, not a perfect balance
    start = math.hypot(*ballbal.balanced_state(sc).q[:2])
    assert res.peak > max(start, res.final_r) + 0.05  # thrown out by the disturbance



def steady_residual(scene, q):
    """An equilibrium in the rotating frame is the configuration q turning rigidly at
    Omega in the ground frame: ground_rhs must give the centripetal accelerations."""
    n, w = scene.n_balls, scene.Omega
    x, y = q[0], q[1]
    s = np.concatenate([[x, y], q[2:], [-w * y, w * x], np.full(n, w)])
    acc = ground_rhs(scene, 0.0, s)[n + 2 :]
    return acc - np.concatenate([[-w * w * x, -w * w * y], np.zeros(n)])


def canonical(q, equal, rotor=2):
    """Balls in track order as a tuple with b_1 in [-pi, pi); identical balls: the least
    of the cyclic relabellings round the ring."""
    q = np.asarray(q, dtype=float)
    o = rotor
    n = q.size - o
    forms = []
    for r in range(n if equal else 1):
        b = np.concatenate([q[o + r :], q[o : o + r] + 2 * math.pi])
        b = b - 2 * math.pi * math.floor((b[0] + math.pi) / (2 * math.pi))
        forms.append(tuple(np.round(np.concatenate([q[:o], b]), 5)))
    return min(forms)


def reference_spring_equilibria(scene, per):
    """The test's own search: scipy's root on steady_residual from starts in track order,
    keeping solutions still in track order."""
    n = scene.n_balls
    equal = len(set(scene.balancer.eta)) == 1
    grid = 2 * math.pi * (np.arange(per) + 0.23) / per
    found = set()
    for b1 in grid[::2]:
        for offs in itertools.combinations(grid, n - 1):
            q0 = np.concatenate([[0.0, 0.0, b1], b1 + np.array(offs)])
            r = root(lambda q: steady_residual(scene, q), q0, tol=1e-13)
            if not r.success or np.max(np.abs(steady_residual(scene, r.x))) > 1e-10:
                continue
            b = r.x[2:]
            if np.all(np.diff(np.append(b, b[0] + 2 * math.pi)) >= -1e-9):
                found.add(canonical(r.x, equal))
    return found


@pytest.mark.parametrize(("eta", "Omega", "springs", "per", "count"), [
    ((1.0, 1.0), 1.2, 1e-5, 16, 2), ((1.0, 1.0), 1.2, 2e-2, 16, 2),
    ((0.9, 1.1, 0.7), 1.2, 3e-2, 12, 2), ((0.9, 1.1, 0.7), 0.8, 1e-5, 12, 6),
    ((0.9, 1.1, 0.7), 0.95, 1e-5, 12, 6),
])
def test_equilibria_with_springs_are_those_of_the_ground_frame_formulation(
        eta, Omega, springs, per, count):
    sc = ballbal.Scene(balancer=ballbal.Balancer(eta=eta, Omega=Omega), springs=springs)
    eqs = ballbal.equilibria(sc)
    ref = reference_spring_equilibria(sc, per)
    got = [canonical(e.q, len(set(eta)) == 1) for e in eqs]
    assert len(set(got)) == len(got) == len(ref) == count
    for g in got:
        assert any(np.max(np.abs(np.subtract(g, r))) < 1e-4 for r in ref), g
    balanced = [e for e in eqs if e.kind == "balanced"]
    expected = ballbal.balanced_state(sc)
    assert len(balanced) == (expected is not None)
    if expected is not None:
        assert np.allclose(balanced[0].q, expected.q, atol=1e-9)


@pytest.mark.parametrize(("Omega", "springs"), [(1.2, 1e-3), (0.8, 1e-5)])
def test_stability_of_equilibria_with_springs_agrees_with_time_simulation(Omega, springs):
    b = ballbal.Balancer(eta=(0.9, 1.1, 0.7), Omega=Omega)
    sc = ballbal.Scene(balancer=b, springs=springs)
    eqs = ballbal.equilibria(sc)
    assert {e.stability for e in eqs} == {"stable", "unstable"}
    d = len(sc.coordinates)
    kick = 1e-6 * np.array([1.0, -0.7, 0.5, -0.3, 0.8])
    for e in eqs:
        y0 = np.concatenate([e.q + kick, np.zeros(d)])
        t = np.linspace(0.0, 1500.0, 3)
        df = ballbal.simulate(sc, y0, t, rtol=1e-11, atol=1e-14)
        dev = np.max(np.abs(df[len(t) - 1].select(sc.coordinates).to_numpy()[0] - e.q))
        if e.stability == "stable":
            assert dev < 0.2 * 1e-6, (e.kind, dev)
        else:
            assert dev > 5 * 1e-6, (e.kind, dev)
