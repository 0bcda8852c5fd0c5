"""Seed 004's (Rezaee et al. 2017) own parameters into ballbal's: the Jeffcott reduction
against the disk-units converter, the balanced ball angles of its eq. (43), the whirl
spectrum of the shaft written here in SI units, and its statement that without track
damping the balancer cannot balance."""

import math

import numpy as np
import pytest

import ballbal
from ballbal.exceptions import ParameterError
from ballbal.shaft import ShaftUnits, from_shaft_units


@pytest.mark.parametrize(("omega_bar", "m_bar", "eps_bar", "lam", "zeta_t"), [
    (1.5, 0.01, 0.01, 0.1, 0.1),
    (0.4, 0.05, 0.02, 0.3, 0.02),
    (3.0, 0.2, 0.1, 0.0, 0.0),
])
def test_flat_disk_at_mid_span_is_the_disk_units_balancer(omega_bar, m_bar, eps_bar, lam,
                                                          zeta_t):
    """At mid-span c_t / sqrt(k0 M) = zeta_t (eq. 36 with L^3 / (3 E I) = 16 / k0), twice
    [EccentricRotorABB]'s C0 = c_t / (2 sqrt(k0 M)); D0 is lam by both definitions."""
    got = from_shaft_units(omega_bar, m_bar, eps_bar, lam, zeta_t, a=3.0, b=3.0).balancer
    want = ballbal.from_disk_units(omega_bar, m_bar, eps_bar, C0=zeta_t / 2, D0=lam)
    for k in ("mu", "zeta", "zeta_b", "delta", "Omega"):
        assert getattr(got, k) == pytest.approx(getattr(want, k), rel=1e-12, abs=1e-15), k
    assert got.eta == pytest.approx(want.eta, rel=1e-12)


@pytest.mark.parametrize(("m_bar", "eps_bar"), [(0.01, 0.01), (0.02, 0.03), (0.05, 0.011)])
def test_balanced_ball_angles_are_eq_43(m_bar, eps_bar):
    """Eq. (43): phi_1 = -phi_2 = arccos(-eps_bar / (2 m_bar)), on the tilting disk too."""
    sc = from_shaft_units(2.0, m_bar, eps_bar, 0.1, 0.1, zeta_r=0.1, a=4.0, b=7.0,
                          j_t=0.3, j_z=0.5, n=2)
    eq = ballbal.balanced_state(sc)
    assert eq is not None
    phi = math.acos(-eps_bar / (2 * m_bar))
    b1, b2 = eq.q[4], eq.q[5]
    assert sorted([b1, b2]) == pytest.approx([-phi, phi], abs=1e-8)
    assert np.max(np.abs(eq.q[:4])) < 1e-8


def test_whirl_spectrum_in_si_units():
    """A steel shaft (10 mm, 0.15 + 0.25 m) with a 1 kg disk, written here in SI units:
    complex whirl r = X + iY and slope w obey
    (M s^2 + c_t s + K11) r + K12 w = 0, K12 r + (J_t s^2 + (c_r - i J_z omega) s + K22) w = 0
    with K11 = 3EI (1/a^3 + 1/b^3), K12 = 3EI (1/a^2 - 1/b^2), K22 = 3EI (1/a + 1/b)
    (the slope-deflection matrix of the simply supported shaft). Balls of 1e-6 kg barely
    move it. ballbal's rotating-frame eigenvalue lam is the ground rate s / w_n - i Omega,
    with w_n = omega / Omega. The tilt damping acts on the ground-frame tilt rate here as in
    ballbal (the paper's acts on the Euler angles' rates, which turn with the disk)."""
    E, d, a, b = 2.1e11, 0.01, 0.15, 0.25
    inertia = math.pi * d**4 / 64
    M, m, R, eps, omega = 1.0, 1e-6, 0.03, 3e-8, 400.0
    J_t, J_z, c_t, c_r = 6.25e-4, 1.25e-3, 20.0, 0.01
    su = ShaftUnits.from_physical(E=E, I=inertia, a=a, b=b, M=M, m=m, R=R, eps=eps,
                                  omega=omega, D=1e-9, c_t=c_t, c_r=c_r, J_t=J_t, J_z=J_z)
    sc = su.scene
    eq = ballbal.balanced_state(sc)
    ei3 = 3 * E * inertia
    k11, k12, k22 = ei3 * (1 / a**3 + 1 / b**3), ei3 * (1 / a**2 - 1 / b**2), ei3 * (1 / a + 1 / b)
    poly = np.polymul([M + 2 * m, c_t, k11], [J_t, c_r - 1j * J_z * omega, k22]).astype(complex)
    poly[-1] -= k12**2
    Omega = sc.Omega
    w_n = omega / Omega
    rot = np.roots(poly) / w_n - 1j * Omega
    for s in np.concatenate([rot, rot.conj()]):
        err = np.min(np.abs(eq.eigenvalues - s))
        assert err < 1e-4 * abs(s), (s, eq.eigenvalues)
    # eq. 36's frequency unit is the tilt-free stiffness over the disk's mass
    k0 = k11 - k12**2 / k22
    assert ShaftUnits.omega0(E=E, I=inertia, a=a, b=b, M=M) == pytest.approx(
        math.sqrt(k0 / M), rel=1e-12)


@pytest.mark.parametrize("omega_bar", [2.0, 3.0, 4.0])
def test_without_track_damping_the_balancer_cannot_balance(omega_bar):
    """Rezaee et al. (2017), fig. 5's remark: for lam = 0 the balancer cannot balance;
    with lam = 0.1 (figs 4-5's parameters m_bar = eps_bar = 0.01, zeta_t = zeta_r = 0.1)
    it does well above the critical speed."""
    kw = dict(zeta_r=0.1, a=4.0, b=6.0, j_t=0.3, j_z=0.5)
    undamped = ballbal.balanced_state(from_shaft_units(omega_bar, 0.01, 0.01, 0.0, 0.1, **kw))
    assert undamped is not None and undamped.stability != "stable"
    damped = ballbal.balanced_state(from_shaft_units(omega_bar, 0.01, 0.01, 0.1, 0.1, **kw))
    assert damped is not None and damped.stability == "stable"


@pytest.mark.parametrize(("kw", "name"), [
    (dict(m_bar=0.0), "m_bar"),
    (dict(eps_bar=-1.0), "eps_bar"),
    (dict(lam=float("nan")), "lam"),
    (dict(j_t=0.3), "j_z"),
    (dict(j_t=0.3, j_z=0.7), "j_z"),
    (dict(n=0), "n"),
    (dict(n=1, k_d=0.1), "k_d"),
])
def test_bad_input_names_the_parameter(kw, name):
    args = dict(omega_bar=1.0, m_bar=0.01, eps_bar=0.01, lam=0.1, zeta_t=0.1) | kw
    with pytest.raises(ParameterError) as e:
        ShaftUnits(**args)
    assert e.value.parameter == name


def test_bad_physical_input_names_the_parameter():
    with pytest.raises(ParameterError) as e:
        ShaftUnits.from_physical(E=-1.0, I=1e-9, a=0.1, b=0.1, M=1.0, m=0.01, R=0.03,
                                 eps=1e-4, omega=100.0)
    assert e.value.parameter == "E"


def test_balance_map_in_the_papers_axes():
    """Each row's verdict is that of the scene converted at its own (omega_bar, lam)."""
    kw = dict(zeta_r=0.1, a=4.0, b=6.0, j_t=0.3, j_z=0.5)
    su = ShaftUnits(1.0, 0.01, 0.01, 0.1, 0.1, **kw)
    df = su.balance_map([0.8, 2.0, 3.0], [0.0, 0.1, 0.3])
    assert df.height == 9
    assert sorted(set(df["omega_bar"])) == [0.8, 2.0, 3.0]
    assert sorted(set(df["lam"])) == pytest.approx([0.0, 0.1, 0.3], abs=1e-15)
    for row in df.iter_rows(named=True):
        eq = ballbal.balanced_state(from_shaft_units(row["omega_bar"], 0.01, 0.01,
                                                     row["lam"], 0.1, **kw))
        assert eq.stability == row["stability"], row
    assert set(df.filter(df["lam"] == 0.0)["stability"]) == {"unstable"}
    with pytest.raises(ParameterError) as e:
        su.balance_map([-1.0, 1.0])
    assert e.value.parameter == "omega_bar"
