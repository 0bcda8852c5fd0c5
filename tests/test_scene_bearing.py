"""The balancer on a journal-bearing support (bearing.md section 4), each check against
something computed here: a ground-frame simulation with the short-bearing film written
out by quadrature, the growth rate of a simulated perturbation, the refusals of
time-dependent scenes, bad input naming its parameter, files round-tripping."""

import math

import numpy as np
import pytest
from ground_frame import ground_rhs
from scipy.integrate import solve_ivp

import ballbal
from ballbal.bearing import Bearing, Grooves
from ballbal.exceptions import NotAutonomousError, ParameterError

BAL = ballbal.Balancer(mu=0.2, zeta=0.0, zeta_b=0.05, delta=50.0, Omega=2.0, eta=(1.0, 1.0))
SHORT = Bearing(length_ratio=0.5, model="short")
JOURNAL = Bearing(length_ratio=0.5, grooves=Grooves(8, 30.0, 1.0, side="journal"),
                  grid=(64, 8))
SLEEVE = Bearing(length_ratio=0.5, grooves=Grooves(8, 30.0, 1.0, side="sleeve"),
                 grid=(64, 8))


def on(bearing: Bearing, rho: float = 0.3, **kw: float) -> ballbal.Scene:
    return ballbal.Scene(balancer=BAL.replace(**kw), support=ballbal.BearingSupport(bearing,
                                                                                    rho))


def short_film(lam, x, y, vx, vy, n=2048):
    """Ocvirk's short-bearing force with squeeze and the half-Sommerfeld clip, by
    quadrature of its pressure P = (zeta^2 - lam^2) (3 H_theta + 6 H_tau) / H^3 over
    theta (the zeta integral is exact), in units F_S (bearing.md section 1)."""
    th = (np.arange(n) + 0.5) * 2 * np.pi / n
    c, s = np.cos(th), np.sin(th)
    h = 1 - x * c - y * s
    g = 3 * (x * s - y * c) - 6 * (vx * c + vy * s)
    g = np.minimum(g, 0.0)  # P > 0 where g < 0 (zeta^2 < lam^2)
    # F = -(1 / 2 lam) int int P n; int (zeta^2 - lam^2) dzeta = -4 lam^3 / 3
    k = (2 * lam**2 / 3) * 2 * np.pi / n
    return k * np.sum(g * c / h**3), k * np.sum(g * s / h**3)


def film_support(sc):
    """The support force in the ground frame (tests/ground_frame.py's ``support``): the
    film force (Omega / rho) F(rho X, rho X' / Omega) plus the external damper 2 zeta X'."""
    om, z = sc.balancer.Omega, sc.balancer.zeta
    rho, lam = sc.support.rho, sc.support.bearing.length_ratio

    def force(t, X, Y, dX, dY):
        fx, fy = short_film(lam, rho * X, rho * Y, rho * dX / om, rho * dY / om)
        return om / rho * fx - 2 * z * dX, om / rho * fy - 2 * z * dY

    return force


def test_rotating_frame_bearing_is_the_ground_frame_film():
    # Omega 1.5, zeta 0.02: a transient with the journal well off-centre (eps up to ~0.6)
    sc = on(SHORT, rho=0.25, Omega=1.5, zeta=0.02)
    om = sc.Omega
    y0 = np.array([0.4, -0.3, 0.5, 2.6, 0.1, -0.2, -1.2, -1.7])
    t = np.linspace(0.0, 12.0, 25)
    df = ballbal.simulate(sc, y0, t, rtol=1e-10, atol=1e-12)
    x, y = y0[0], y0[1]
    # ground state at t = 0 (theta = 0): X = q, X' = q' + Omega J q, phi = b, phi' = b' + Omega
    s0 = np.array([x, y, y0[2], y0[3], y0[4] - om * y, y0[5] + om * x,
                   y0[6] + om, y0[7] + om])
    film = film_support(sc)
    sol = solve_ivp(lambda tt, s: ground_rhs(sc, tt, s, film), (0, t[-1]), s0, t_eval=t,
                    rtol=1e-9, atol=1e-11, method="DOP853")
    th = df["theta"].to_numpy()
    X = np.cos(th) * df["x"].to_numpy() - np.sin(th) * df["y"].to_numpy()
    Y = np.sin(th) * df["x"].to_numpy() + np.cos(th) * df["y"].to_numpy()
    # (the quadrature's error at the cavitation boundary is ~1e-7 here)
    assert np.max(np.abs(X - sol.y[0])) < 1e-6
    assert np.max(np.abs(Y - sol.y[1])) < 1e-6
    for i in range(2):
        assert np.max(np.abs(th + df[f"b{i + 1}"].to_numpy() - sol.y[2 + i])) < 1e-6
    # the journal went well off-centre, so the film's nonlinearity was exercised
    assert 0.25 * np.max(np.hypot(X, Y)) > 0.1


def test_perfect_balance_on_a_plain_bearing_is_unstable_and_simulation_agrees():
    for om in (0.5, 2.0, 8.0):
        sc = on(SHORT, Omega=om)
        pb = ballbal.balanced_state(sc)
        assert pb is not None and pb.stability == "unstable"
        assert abs(pb.q[0]) < 1e-12 and abs(pb.q[1]) < 1e-12
        kinds = {e.kind: e for e in ballbal.equilibria(sc)}
        assert kinds["perfect_balance"].stability == "unstable"
    # Confirmed by simulation at Omega = 2: a perturbation of 1e-7 grows at the leading
    # eigenvalue's rate while it is small.
    sc = on(SHORT, Omega=2.0)
    pb = ballbal.balanced_state(sc)
    assert pb is not None
    lead = max(np.real(pb.eigenvalues))
    y0 = np.concatenate([pb.q, np.zeros(4)])
    y0[0] += 1e-7
    t = np.linspace(0.0, 30.0, 601)
    df = ballbal.simulate(sc, y0, t, rtol=1e-11, atol=1e-15)
    r = np.hypot(df["x"].to_numpy(), df["y"].to_numpy())
    # envelope over windows of one whirl period, 10 time units apart
    late, early = r[(t > 20) & (t <= 25)].max(), r[(t > 10) & (t <= 15)].max()
    rate = math.log(late / early) / 10.0
    assert abs(rate - lead) < 0.05 * lead, (rate, lead)
    assert r[-1] > 100 * 1e-7


def test_grooved_journal_balances_stably_and_simulation_agrees():
    sc = on(JOURNAL, Omega=2.0)
    assert sc.time_dependence is None
    pb = ballbal.balanced_state(sc)
    assert pb is not None and pb.stability == "stable"
    y0 = np.concatenate([pb.q, np.zeros(4)])
    y0[0] += 1e-3
    df = ballbal.simulate(sc, y0, np.linspace(0.0, 80.0, 81))
    r = np.hypot(df["x"].to_numpy(), df["y"].to_numpy())
    lead = max(np.real(pb.eigenvalues))
    assert r[-1] < 1e-3 * math.exp(0.5 * lead * 80.0)


@pytest.mark.parametrize(("kw", "effect"), [
    ({}, "grooved_sleeve"), ({"gravity": 0.1}, "gravity"),
    ({"impulse": ballbal.Impulse(amplitude=1.0, t0=1.0, sharpness=1.0)}, "impulse"),
])
def test_time_dependent_bearing_scenes_refuse_autonomous_analyses(kw, effect):
    bearing = SLEEVE if effect == "grooved_sleeve" else SHORT
    sc = ballbal.Scene(balancer=BAL, support=ballbal.BearingSupport(bearing, 0.3), **kw)
    assert sc.time_dependence == effect
    for call in (lambda: ballbal.periodic(sc, "R-R"), lambda: ballbal.equilibria(sc),
                 lambda: ballbal.balanced_state(sc)):
        with pytest.raises(NotAutonomousError) as err:
            call()
        assert err.value.effect == effect
    ballbal.simulate(sc, t_span=(0, 2))  # simulation always works


def test_narrow_groove_or_journal_grooves_stay_autonomous():
    assert on(JOURNAL).time_dependence is None
    # a sleeve groove of depth 0 is a plain bearing
    flat = Bearing(length_ratio=0.5, grooves=Grooves(8, 30.0, 0.0), grid=(64, 8))
    assert on(flat).time_dependence is None


def test_bad_bearing_input_names_the_parameter():
    with pytest.raises(ParameterError) as e:
        ballbal.BearingSupport(SHORT, rho=0.0)
    assert e.value.parameter == "rho"
    with pytest.raises(ParameterError) as e:
        ballbal.BearingSupport(SHORT, rho=float("nan"))
    assert e.value.parameter == "rho"
    with pytest.raises(ParameterError) as e:
        ballbal.BearingSupport("short", rho=0.3)  # type: ignore[arg-type]
    assert e.value.parameter == "bearing"
    with pytest.raises(ParameterError) as e:
        on(SHORT, Omega=0.0)
    assert e.value.parameter == "Omega"
    with pytest.raises(ParameterError) as e:
        ballbal.Scene(support=ballbal.BearingSupport(SHORT, 0.3),
                      tilt=ballbal.Tilt(a=1.0, b=1.0, j_t=0.3, j_z=0.5))
    assert e.value.parameter == "bearing"
    with pytest.raises(ParameterError) as e:
        ballbal.balance_map(on(SHORT), Omega=[1.0], depth_ratio=[0.5])
    assert e.value.parameter == "depth_ratio"
    with pytest.raises(ParameterError) as e:
        ballbal.balance_map(on(JOURNAL), Omega=[1.0], groove_angle=[120.0])
    assert e.value.parameter == "grooves.angle"
    with pytest.raises(ParameterError) as e:
        ballbal.balance_map(ballbal.Scene(balancer=BAL, springs=0.1), Omega=[1.0], rho=[0.5])
    assert e.value.parameter == "rho"


def test_balance_map_over_groove_depth_starts_from_the_plain_bearing():
    df = ballbal.balance_map(on(JOURNAL), Omega=[2.0], depth_ratio=[0.0, 1.0])
    plain = ballbal.balanced_state(on(Bearing(length_ratio=0.5, grid=(64, 8)), Omega=2.0))
    assert plain is not None
    rows = df.sort("depth_ratio").to_dicts()
    # depth 0 is the plain finite film: the same index as the plain bearing's
    assert rows[0]["stability"] == "unstable"
    assert abs(rows[0]["index"] - max(np.real(plain.eigenvalues))) < 1e-8
    assert rows[1]["stability"] == "stable"


def test_bearing_scene_file_round_trips(tmp_path):
    sc = ballbal.Scene(balancer=BAL, support=ballbal.BearingSupport(SLEEVE, 0.3))
    p = tmp_path / "bearing.toml"
    sc.save(p)
    assert ballbal.load_scene(p) == sc
    moved = sc.replace(rho=0.5, Omega=3.0)
    assert moved.support is not None and moved.support.rho == 0.5 and moved.Omega == 3.0
    with pytest.raises(ParameterError) as e:
        ballbal.Scene(balancer=BAL).replace(rho=0.5)
    assert e.value.parameter == "rho"
    p.write_text("Omega = 2.0\nballs = 2\n[bearing]\nrho = 0.4\nmodel = \"short\"\n"
                 "length_ratio = 0.5\n")
    back = ballbal.load_scene(p)
    assert back.support is not None and back.support.bearing.model == "short"
    assert back.support.rho == 0.4
    p.write_text("Omega = 2.0\n[bearing]\nrho = 0.4\n[bearing.grooves]\ncount = 4\n"
                 "angle = 30\ndepth_ratio = 1\ncolour = 2\n")
    with pytest.raises(ParameterError) as e:
        ballbal.load_scene(p)
    assert e.value.parameter == "bearing.grooves.colour"
    p.write_text("Omega = 2.0\n[bearing]\nmodel = \"short\"\n")
    with pytest.raises(ParameterError) as e:
        ballbal.load_scene(p)
    assert e.value.parameter == "bearing.rho"


def test_maps_and_scans_refuse_a_value_that_makes_the_scene_time_dependent():
    # depth 0 on the sleeve is a plain (autonomous) bearing; cutting the grooves makes
    # the scene time-periodic, which the map and the scan must refuse, not mislabel
    flat = on(Bearing(length_ratio=0.5, grooves=Grooves(8, 30.0, 0.0), grid=(64, 8)))
    assert flat.time_dependence is None
    with pytest.raises(NotAutonomousError) as e:
        ballbal.balance_map(flat, Omega=[2.0], depth_ratio=[0.0, 0.5])
    assert e.value.effect == "grooved_sleeve"
    with pytest.raises(NotAutonomousError) as e:
        ballbal.scan(flat, Omega=[2.0], depth_ratio=[0.5])
    assert e.value.effect == "grooved_sleeve"


def test_oil_whirl_orbit_by_harmonic_balance_is_what_simulation_reaches():
    # A plain short bearing with an external damper (zeta = 1): the perfect balance is
    # unstable and the rotor settles on a whirl with the balls rocking (O-O). Harmonic
    # balance and Floquet on the real film: the orbit's frequency and radius range against a
    # plain simulation from rest, measured here from the signal (zero crossings of x).
    sc = on(Bearing(length_ratio=0.5, model="short"), zeta=1.0, Omega=2.0)
    sol = ballbal.periodic(sc, "O-O")
    assert sol.status == "converged" and sol.stability == "stable"
    assert abs(sol.multipliers[0] - 1) < 1e-6  # the trivial multiplier
    # The slowest transient decays by |0.96 + 0.22i| = 0.989 per period (about 4 time
    # units): 4000 time units leave about 1e-5 of it.
    t = np.linspace(0.0, 4000.0, 800001)
    df = ballbal.simulate(sc, None, t, rtol=1e-10, atol=1e-12)
    late = t > 3700
    x = df["x"].to_numpy()[late]
    tt = t[late]
    xm = x - x.mean()
    up = np.flatnonzero((xm[:-1] < 0) & (xm[1:] >= 0))
    tc = tt[up] - xm[up] * (tt[up + 1] - tt[up]) / (xm[up + 1] - xm[up])
    period = np.diff(tc).mean()
    assert 2 * math.pi / sol.omega == pytest.approx(period, rel=1e-4)
    tau = np.linspace(0.0, 2 * math.pi, 2001)
    k = np.arange(1, (sol.coeffs.shape[1] - 1) // 2 + 1)

    def series(c: np.ndarray) -> np.ndarray:
        return c[0] + np.cos(np.outer(tau, k)) @ c[1::2] + np.sin(np.outer(tau, k)) @ c[2::2]

    r_hb = np.hypot(series(sol.coeffs[0]), series(sol.coeffs[1]))
    r_sim = np.hypot(x, df["y"].to_numpy()[late])
    assert r_hb.min() == pytest.approx(r_sim.min(), abs=1e-4)
    assert r_hb.max() == pytest.approx(r_sim.max(), abs=1e-4)


def test_lab_quantities_give_the_classical_mass_parameter():
    # w_ref = mu_oil L R^3 / (c^3 M), so Omega = M c^3 w / (mu_oil L R^3), written out.
    from ballbal.bearing import Dimensions
    from ballbal.scene import BearingSupport

    dims = Dimensions(radius=0.02, length=0.02, clearance=50e-6, viscosity=0.03)
    disk, other, balls, e, r_t, w = 0.5, 2.0, (0.01, 0.01), 2e-5, 0.03, 300.0
    sc = BearingSupport.from_lab(Bearing(length_ratio=0.5, model="short"), dims,
                                 disk_mass=disk, eccentricity=e, ball_masses=balls,
                                 track_radius=r_t, track_damping=1e-4, spin=w,
                                 other_mass=other, external_damping=3.0)
    m = disk + other + sum(balls)
    w_ref = 0.03 * 0.02 * 0.02**3 / (50e-6**3 * m)
    assert sc.balancer.Omega == pytest.approx(m * 50e-6**3 * w / (0.03 * 0.02 * 0.02**3))
    assert sc.balancer.zeta == pytest.approx(3.0 / (2 * m * w_ref))
    assert sc.balancer.zeta_b == pytest.approx(1e-4 / (2 * 0.01 * w_ref))
    assert sc.balancer.eta == pytest.approx((0.01 * r_t / (disk * e),) * 2)
    assert sc.support.rho == pytest.approx(e / 50e-6)
    with pytest.raises(ParameterError) as err:
        BearingSupport.from_lab(Bearing(length_ratio=1.0, model="short"), dims,
                                disk_mass=disk, eccentricity=e, ball_masses=balls,
                                track_radius=r_t, track_damping=1e-4, spin=w)
    assert err.value.parameter == "bearing"


def test_converting_a_spring_scene_keeps_the_lab_quantities():
    # The same lab machine two ways: a spring scene converted with w_n / w_ref, and the
    # bearing scene built from the lab quantities directly.
    from ballbal.bearing import Dimensions
    from ballbal.scene import BearingSupport

    dims = Dimensions(radius=0.02, length=0.02, clearance=50e-6, viscosity=0.03)
    lab = dict(disk_mass=0.5, eccentricity=2e-5, ball_masses=(0.01, 0.01), track_radius=0.03,
               track_damping=1e-4, spin=300.0, other_mass=2.0)
    k = 4e5
    spring = ballbal.Scene(balancer=ballbal.Balancer.from_lab(stiffness=k, damping=5.0, **lab))
    m = 2.52
    support = BearingSupport(Bearing(length_ratio=0.5, model="short"), rho=2e-5 / 50e-6)
    ratio = (k / m) ** 0.5 / BearingSupport.reference_frequency(dims, m)
    conv, changes = ballbal.to_bearing(spring, support, natural_over_reference=ratio)
    direct = BearingSupport.from_lab(support.bearing, dims, **lab)
    for f in ("mu", "delta", "Omega", "zeta_b", "eta", "zeta"):
        assert getattr(conv.balancer, f) == pytest.approx(getattr(direct.balancer, f)), f
    assert set(changes) == {"Omega", "zeta_b", "zeta", "support"}
    assert changes["zeta"] == (spring.balancer.zeta, 0.0)
