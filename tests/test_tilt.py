"""The tilting disk on a flexible shaft (Rezaee et al. 2017), checked against a closed-form whirl
spectrum, an energy integral computed from a Lagrangian written here independently,
the planar model it must reduce to, and time simulation of the stability it reports."""

import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import ballbal
from ballbal.exceptions import ParameterError

TILT = ballbal.Tilt(a=1.3, b=2.8, j_t=0.35, j_z=0.55, zeta_r=0.04)


def tilting(tilt=TILT, **kw):
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.5, eta=(1.0, 1.0))
    return ballbal.Scene(balancer=b, tilt=tilt, **kw)


@pytest.mark.parametrize(("tilt", "Omega"), [
    (TILT, 1.7),
    (TILT, 0.4),
    (ballbal.Tilt(a=2.0, b=2.0, j_t=0.3, j_z=0.6, zeta_r=0.1), 2.5),
    (ballbal.Tilt(a=0.8, b=3.0, j_t=0.5, j_z=0.0, zeta_r=0.0), 1.2),
])
def test_whirl_spectrum_of_the_stodola_green_rotor(tilt, Omega):
    """With a negligible unbalance and balls, the balanced rotor is a disk on a shaft:
    in complex whirl coordinates r = X + iY and slope w, its free motion obeys
    (s^2 + 2 zeta s + 1) r + kc w = 0, kc r + (jt s^2 + (c_r - i jz Omega) s + kt) w = 0
    (gyroscopic moment jz Omega n x n'); the rotating frame sees s - i Omega."""
    zeta = 0.04
    b = ballbal.Balancer(mu=1e-9, zeta=zeta, zeta_b=0.1, delta=50.0, Omega=Omega,
                         eta=(1.0, 1.0))
    eq = ballbal.balanced_state(ballbal.Scene(balancer=b, tilt=tilt))
    kc, kt, jt, jz = tilt.kappa_c, tilt.kappa_t, tilt.j_t, tilt.j_z
    cr = 2 * tilt.zeta_r * np.sqrt(kt * jt)
    poly = np.polymul([1, 2 * zeta, 1], [jt, cr - 1j * jz * Omega, kt]).astype(complex)
    poly[-1] -= kc**2
    rot = np.roots(poly) - 1j * Omega
    for s in np.concatenate([rot, rot.conj()]):
        assert np.min(np.abs(eq.eigenvalues - s)) < 1e-7, (s, eq.eigenvalues)
    # forward whirl stiffens with spin: the largest ground-frame frequency beats jz = 0's
    if jz > 0:
        flat = np.polymul([1, 2 * zeta, 1], [jt, cr, kt]).astype(complex)
        flat[-1] -= kc**2
        assert np.max(np.roots(poly).imag) > np.max(np.roots(flat).imag)


def test_centred_disk_started_flat_moves_as_the_planar_balancer():
    """a = b: no translation-tilt coupling; every effect on; the disk stays flat."""
    centred = ballbal.Tilt(a=2.0, b=2.0, j_t=0.3, j_z=0.5, zeta_r=0.1)
    kw = dict(springs=1e-4, gravity=0.3, ramp=ballbal.Ramp(to=2.0, start=1.0, duration=20.0),
              impulse=ballbal.Impulse(amplitude=1.0, t0=5.0, sharpness=2.0))
    flat = tilting(tilt=None, **kw)
    tilted = tilting(tilt=centred, **kw)
    y0 = [0.1, -0.2, 0.4, 2.9, 0.0, 0.3, -1.5, -1.5]
    y0t = y0[:2] + [0.0, 0.0] + y0[2:6] + [0.0, 0.0] + y0[6:]
    t = np.linspace(0, 40, 81)
    a = ballbal.simulate(flat, y0, t, rtol=1e-11, atol=1e-13)
    b = ballbal.simulate(tilted, y0t, t, rtol=1e-11, atol=1e-13)
    for c in ("x", "y", "b1", "b2", "dx", "db2", "X", "Y"):
        assert np.max(np.abs(a[c].to_numpy() - b[c].to_numpy())) < 1e-7, c
    assert np.all(b["A"].to_numpy() == 0.0) and np.all(b["dB"].to_numpy() == 0.0)


def rotation_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])


def rotation_y(b):
    c, s = np.cos(b), np.sin(b)
    return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])


def rotation_z(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def lagrangian(scene, q, v, theta, Omega):
    """L = T - V written from the physics, velocities by complex-step differentiation of
    ground-frame positions and of the ground-to-body rotation along (v, Omega)."""
    b, tl = scene.balancer, scene.tilt
    n, dl, mu = b.n_balls, b.delta, b.mu
    m = mu * np.asarray(b.eta) / dl  # ball masses over M
    hub = 1 - mu - m.sum()
    h = 1e-30

    def geometry(qq, th):
        x, y, A, B, phi = qq[0], qq[1], qq[2], qq[3], qq[4:]
        R = rotation_y(B / dl) @ rotation_x(A / dl) @ rotation_z(th)  # ground -> body
        axes = R.T  # body axes in ground coordinates (columns)
        C = rotation_z(th).T @ np.array([x, y, 0 * x])
        pts = [C, C + axes[:, 0]]
        for p in phi:
            pts.append(C + dl * (np.cos(p) * axes[:, 0] + np.sin(p) * axes[:, 1]))
        return R, pts

    qc = np.asarray(q, dtype=complex) + 1j * h * np.asarray(v)
    R, pts = geometry(qc, theta + 1j * h * Omega)
    vel = [np.imag(p) / h for p in pts]
    Rr, Rd = np.real(R), np.imag(R) / h
    W = Rr @ Rd.T  # [w]x in body axes
    w = np.array([W[2, 1], W[0, 2], W[1, 0]])
    T = 0.5 * (hub * vel[0] @ vel[0] + mu * vel[1] @ vel[1]
               + sum(mi * vk @ vk for mi, vk in zip(m, vel[2:], strict=True)))
    T += 0.5 * dl**2 * (tl.j_t * (w[0] ** 2 + w[1] ** 2) + tl.j_z * w[2] ** 2)
    # shaft: the disk normal's slope in the rotating frame, scaled by delta
    x, y = q[0], q[1]
    normal = (rotation_x(q[2] / dl).T @ rotation_y(q[3] / dl).T)[:, 2]
    sx, sy = dl * normal[0], dl * normal[1]
    V = 0.5 * (x**2 + y**2) + tl.kappa_c * (x * sx + y * sy) + 0.5 * tl.kappa_t * (sx**2 + sy**2)
    phi = np.asarray(q[4:])
    gaps = np.append(np.diff(phi), phi[0] + 2 * np.pi - phi[-1]) - 2 * np.pi / n
    if scene.spring_layout == "chain":
        gaps = gaps[:-1]  # Rezaee et al.'s (2017) chain: no spring from ball n back to ball 1
    V += 0.5 * scene.springs * dl**2 * np.sum(gaps**2)
    return T - V


def jacobi_integral(scene, q, v, theta, Omega):
    """h = T2 - T0 + V from L(v), L(-v) and L(0)."""
    L = lambda vv: lagrangian(scene, q, vv, theta, Omega)  # noqa: E731
    return 0.5 * (L(v) + L(-np.asarray(v))) - 2 * L(np.zeros_like(v))


@pytest.mark.parametrize("layout", ["ring", "chain"])
def test_undamped_tilting_rotor_keeps_its_energy_integral(layout):
    b = ballbal.Balancer(mu=0.2, zeta=0.0, zeta_b=0.0, delta=20.0, Omega=1.4,
                         eta=(0.9, 1.2, 0.7))
    tl = ballbal.Tilt(a=1.3, b=2.8, j_t=0.35, j_z=0.55, zeta_r=0.0)
    sc = ballbal.Scene(balancer=b, tilt=tl, springs=2e-3, spring_layout=layout)
    y0 = [0.3, -0.2, 0.5, -0.3, 0.2, 2.0, 4.3, 0.1, 0.2, -0.1, 0.2, 0.3, -0.4, 0.1]
    t = np.linspace(0, 100, 201)
    df = ballbal.simulate(sc, y0, t, rtol=1e-12, atol=1e-14)
    d = 7
    hs = []
    for row in df.select(["t", *_names(sc)]).iter_rows():
        q, v = np.array(row[1 : 1 + d]), np.array(row[1 + d :])
        hs.append(jacobi_integral(sc, q, v, b.Omega * row[0], b.Omega))
    hs = np.array(hs)
    # the motion exchanges energy among its parts: the check is not trivially flat
    parts = [jacobi_integral(sc.replace(springs=0.0), *_state(df, sc, i), b.Omega * t[i],
                             b.Omega) for i in range(len(t))]
    assert np.ptp(parts) > 1e-3
    # and it does see the gyroscopic and shaft terms: other ones do not give a constant
    other = "chain" if layout == "ring" else "ring"
    for wrong in (dict(j_z=0.3), dict(a=1.5), dict(spring_layout=other)):
        sw = sc.replace(**wrong)
        hw = [jacobi_integral(sw, *_state(df, sc, i), b.Omega * t[i], b.Omega)
              for i in range(len(t))]
        assert np.ptp(hw) > 1e-4, wrong
    assert np.ptp(hs) < 1e-8 * max(1.0, np.abs(hs).max()), np.ptp(hs)


def _names(sc):
    return sc.coordinates + [f"d{c}" for c in sc.coordinates]


def _state(df, sc, i):
    row = df.select(_names(sc)).row(i)
    d = len(sc.coordinates)
    return np.array(row[:d]), np.array(row[d:])


@pytest.mark.parametrize(("springs", "Omega", "zeta_b"), [
    (2e-5, 1.1, 0.0), (2e-5, 1.1, 0.1), (2e-5, 2.0, 0.1), (0.0, 0.7, 0.1), (0.0, 2.0, 0.1),
])
def test_balanced_state_stability_agrees_with_time_simulation(springs, Omega, zeta_b):
    """The eigenvalue verdict against what a small disturbance actually does."""
    sc = tilting(springs=springs).replace(Omega=Omega, zeta_b=zeta_b)
    eq = ballbal.balanced_state(sc)
    assert abs(eq.stability_index) > 0.01  # clear-cut cases only
    d = len(sc.coordinates)
    y0 = np.concatenate([eq.q, np.zeros(d)])
    y0[d:] += 1e-6  # a small kick to every rate
    t = np.linspace(0, 400, 9)
    tr = ballbal.simulate(sc, y0, t, rtol=1e-10, atol=1e-13)
    gap = [np.max(np.abs(np.array(r[:d]) - eq.q)) for r in tr.select(_names(sc)).iter_rows()]
    early = max(gap[1:3])
    if eq.stability == "stable":
        assert gap[-1] < 0.1 * early, gap
    else:
        assert gap[-1] > 3 * early, gap


def test_classic_map_of_a_centred_disk_is_the_planar_map():
    """Tilt and translation decouple for a = b, so the balanced state's stability is the
    planar perfect balance's (which the planar tests check by Routh–Hurwitz)."""
    axes = dict(Omega=np.linspace(0.6, 2.4, 10), zeta_b=[0.0, 0.02, 0.1, 0.3])
    centred = ballbal.Tilt(a=2.0, b=2.0, j_t=0.3, j_z=0.5, zeta_r=0.1)
    a = ballbal.balance_map(tilting(tilt=centred), **axes)
    b = ballbal.balance_map(tilting(tilt=None).balancer, **axes)
    assert (a["stability"] == b["stability"]).all()
    assert a.filter(a["stability"] == "stable").height > 5
    assert (a.filter(a["stability"] == "unstable").height > 5)


def test_ball_spring_run_up_springs_cut_the_peak_and_leave_a_residual_whirl():
    """Rezaee et al. (2017): the ball-spring balancer lowers the run-up's peak whirl and tilt. The
    springs' rest spacing (pi for two balls) is not the balancing spacing, so a residual
    whirl remains; it must be the one balanced_state computes at the final speed."""
    base = tilting().replace(Omega=0.3, zeta=0.05, zeta_b=0.05,
                             tilt=ballbal.Tilt(a=1.5, b=2.5, j_t=0.3, j_z=0.5, zeta_r=0.05))
    classic = ballbal.run_up(base, 2.0, 300.0)
    sprung = ballbal.run_up(base.replace(springs=2e-5), 2.0, 300.0)
    assert sprung.peak_whirl < 0.5 * classic.peak_whirl
    assert sprung.peak_tilt < 0.5 * classic.peak_tilt
    assert classic.final_whirl < 1e-6
    eq = ballbal.balanced_state(base.replace(springs=2e-5, Omega=2.0))
    assert eq.stability == "stable"
    assert sprung.final_whirl == pytest.approx(np.hypot(eq.q[0], eq.q[1]), rel=1e-3)
    assert sprung.final_tilt == pytest.approx(np.hypot(eq.q[2], eq.q[3]), rel=1e-3)


def test_periodic_solutions_of_a_tilting_rotor():
    """Centred disk: the planar R-R orbit with a flat disk (omega = 0.25141 by the spec's
    shooting), its multipliers among the tilting ones. Off-centre: a real orbit (closed
    by time simulation), Floquet and Hill's method agreeing."""
    planar = ballbal.periodic(tilting(tilt=None).replace(Omega=1.2, zeta_b=0.05), "R-R")
    centred = ballbal.Tilt(a=2.0, b=2.0, j_t=0.35, j_z=0.55, zeta_r=0.04)
    sol = ballbal.periodic(tilting(tilt=centred).replace(Omega=1.2, zeta_b=0.05), "R-R")
    assert sol.converged and sol.coeffs.shape[0] == 6
    assert sol.omega == pytest.approx(0.25141, abs=1e-5)
    assert sol.omega == pytest.approx(planar.omega, abs=1e-9)
    assert np.max(np.abs(sol.coeffs[2:4])) < 1e-10
    for m in planar.multipliers:
        assert np.min(np.abs(sol.multipliers - m)) < 1e-5
    near = ballbal.Tilt(a=1.8, b=2.2, j_t=0.35, j_z=0.55, zeta_r=0.04)
    off = ballbal.periodic(tilting(tilt=near).replace(Omega=1.2, zeta_b=0.05), "R-R", N=8)
    assert off.converged and abs(off.omega - planar.omega) > 1e-3
    assert np.max(np.abs(off.coeffs[2:4])) > 1e-3  # the disk wobbles
    assert off.verify() < 1e-5
    assert off.stability == off.hill_stability
    assert np.sort(np.abs(off.hill_multipliers))[-2] == pytest.approx(off.max_modulus, abs=1e-4)


def test_tilt_scene_files_round_trip_and_bad_input(tmp_path):
    sc = tilting(springs=1e-4)
    p = tmp_path / "tilt.toml"
    sc.save(p)
    assert ballbal.load_scene(p) == sc
    assert ballbal.load_scene(p).coordinates == ["x", "y", "A", "B", "b1", "b2"]
    with pytest.raises(ParameterError) as err:
        ballbal.Tilt(a=1.0, b=1.0, j_t=0.2, j_z=0.5)
    assert err.value.parameter == "tilt.j_z"
    with pytest.raises(ParameterError) as err:
        ballbal.Tilt(a=1.0, b=1.0, j_t=0.2, j_z=0.1, zeta_r=-1)
    assert err.value.parameter == "tilt.zeta_r"
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(sc, np.zeros(8), [0.0, 1.0])
    assert err.value.parameter == "y0"
    with pytest.raises(ValueError, match="^equilibria: .*'ramp'"):
        ballbal.equilibria(sc.replace(ramp=ballbal.Ramp(to=2.0)))


def test_generated_equations_are_what_the_derivation_gives():
    """The committed Rust terms are what scripts/derive_tilt.py derives (the test command
    points BALLBAL_REPO at the checkout, since the tests run from a copy)."""
    import sympy  # noqa: F401  (a test dependency: the check must run, not skip)

    repo = os.environ.get("BALLBAL_REPO") or pathlib.Path(__file__).resolve().parents[1]
    script = pathlib.Path(repo) / "scripts" / "derive_tilt.py"
    assert script.exists(), f"{script}: set BALLBAL_REPO to the repository checkout"
    out = subprocess.run([sys.executable, str(script), "--check"], capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr


def test_accuracy_cost_of_a_tilting_rotor():
    """The accuracy study runs on a scene: its reference closes under time simulation,
    and the error falls with the harmonics and the monodromy tolerance."""
    sc = ballbal.Scene(tilt=ballbal.Tilt(a=1.8, b=2.2, j_t=0.15, j_z=0.25, zeta_r=0.05))
    df = ballbal.accuracy_cost(sc, N=(2, 4, 8), samples=(4,), tol=(1e-6,),
                               rtol=(1e-4, 1e-8), repeats=1, reference_N=24)
    assert df["reference_closure"][0] < 1e-9
    by_n = df.filter(df["knob"] == "N")["omega_error"].to_list()
    assert by_n[0] > 1e-7 and by_n[0] > 1e3 * by_n[1] and by_n[1] > by_n[2]
    by_rtol = df.filter(df["knob"] == "rtol")["multiplier_error"].to_list()
    assert by_rtol[0] > 100 * by_rtol[1]
