"""Seed 001's three ball-mass cases (2 m R below, at and above M eps): the transient
studies start from the steady state at the starting speed, which for light balls is not a
balance but the balls settled against the imbalance, an equilibrium in closed form."""

import cmath
import math

import numpy as np
import pytest

import ballbal


def settled_against(mu, zeta, Omega, eta):  # noqa: N803
    """Two equal balls together at b, at rest: the centre z = x + iy obeys
    A z = mu Omega^2 (1 + 2 eta e^{ib}), A = 1 - Omega^2 + 2 i zeta Omega, and each ball
    needs the centre on its line, b = arg z or arg z + pi (s = +1, -1). With
    z = rho e^{i phi}: e^{i phi} (A rho - 2 s eta mu Omega^2) = mu Omega^2, so
    |A rho - 2 s eta mu Omega^2| = mu Omega^2, a quadratic in rho. Returns every
    (rho, b, residual |1 + 2 eta e^{ib}|)."""
    a = complex(1 - Omega**2, 2 * zeta * Omega)
    f = mu * Omega**2
    out = []
    for s in (1.0, -1.0):
        c2, c1, c0 = abs(a) ** 2, -4 * s * eta * f * a.real, 4 * eta**2 * f**2 - f**2
        for rho in np.roots([c2, c1, c0]):
            if abs(rho.imag) > 1e-12 or rho.real <= 0:
                continue
            rho = rho.real
            phi = -cmath.phase(a * rho - 2 * s * eta * f)
            b = phi if s > 0 else phi + math.pi
            out.append((rho, b, abs(1 + 2 * eta * cmath.exp(1j * b))))
    return out


def _angle_gap(u, v):
    return abs(math.remainder(u - v, 2 * math.pi))


@pytest.mark.parametrize("eta", [0.3, 0.45])
def test_light_balls_settle_against_the_imbalance_in_closed_form(eta):
    """Below capacity (eta < 1/2): the disturbance starts where the balls settle against
    the imbalance at Omega = 2 and ends there at Omega = 2.5, both the closed form."""
    mu, zeta = 0.2, 0.05
    b = ballbal.Balancer(mu=mu, zeta=zeta, zeta_b=0.1, Omega=2.0, eta=(eta, eta))
    res = ballbal.disturbance_response(b, to=2.5, t_end=1500)
    for row, Omega in ((res.trajectory.row(0, named=True), 2.0),  # noqa: N806
                       (res.trajectory.row(-1, named=True), 2.5)):
        rho, ang, residual = min(settled_against(mu, zeta, Omega, eta), key=lambda t: t[2])
        assert residual == pytest.approx(1 - 2 * eta, abs=0.05)  # nearly straight opposite
        assert math.hypot(row["x"], row["y"]) == pytest.approx(rho, rel=1e-5)
        assert _angle_gap(row["b1"], ang) < 1e-5 and _angle_gap(row["b2"], ang) < 1e-5
    assert res.final_r == pytest.approx(
        min(settled_against(mu, zeta, 2.5, eta), key=lambda t: t[2])[0], rel=1e-5)
    assert res.settle_time is not None
    start_r = min(settled_against(mu, zeta, 2.0, eta), key=lambda t: t[2])[0]
    assert res.peak > start_r + 0.05  # the disturbance throws the rotor out


def test_the_three_mass_cases_of_seed_001():
    """Below, at and above capacity (eta 0.4, 0.5, 0.8): all three run; only the last
    ends balanced; the residual vibration of the light balls is the closed form's, and at
    capacity the balls end together opposite the imbalance (cos b = -1, r -> 0)."""
    mu, zeta = 0.2, 0.05
    finals = {}
    for eta in (0.4, 0.5, 0.8):
        b = ballbal.Balancer(mu=mu, zeta=zeta, Omega=2.0, eta=(eta, eta))
        df = ballbal.track_damping_study(b, [0.05, 0.2], to=2.5, t_end=1500)
        assert df.height == 2
        finals[eta] = df["final_r"].to_list()
    light = min(settled_against(mu, zeta, 2.5, 0.4), key=lambda t: t[2])[0]
    assert finals[0.4] == pytest.approx([light, light], rel=1e-4)
    assert max(finals[0.5]) < 2e-3  # marginal: approached slowly, not exactly reached
    assert max(finals[0.8]) < 1e-6


def test_an_unstable_balance_above_capacity_is_still_refused():
    """Heavy balls below the resonance: the balanced state exists but is unstable; the
    study does not start from some other state instead."""
    b = ballbal.Balancer(Omega=0.6, eta=(0.8, 0.8))
    with pytest.raises(ballbal.exceptions.ParameterError) as e:
        ballbal.disturbance_response(b, to=2.0)
    assert e.value.parameter == "model"
