import numpy as np
import pytest

import ballbal
from ballbal.exceptions import ParameterError


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def test_perfect_balance_closed_form_and_existence():
    for eta in (0.5, 0.7, 1.3):
        b = ballbal.Balancer(Omega=1.5, eta=(eta, eta))
        pb = [e for e in ballbal.equilibria(b) if e.kind == "perfect_balance"]
        assert len(pb) == 1
        q = pb[0].q
        assert np.allclose(q[:2], 0.0)
        assert np.isclose(np.cos(q[2]), -1 / (2 * eta)) and abs(_wrap(q[3] + q[2])) < 1e-12
        assert pb[0].residual < 1e-13
    b = ballbal.Balancer(Omega=1.5, eta=(0.49, 0.49))
    assert all(e.kind != "perfect_balance" for e in ballbal.equilibria(b))


@pytest.mark.parametrize(("omega0", "m0", "e"), [(1.5, 2.0, 2.0), (0.4, 0.6, 2.0), (2.0, 1.2, 1.5)])
def test_unbalanced_equilibria_match_closed_forms_in_disk_units(omega0, m0, e):
    """[EccentricRotorABB] eqs (11) and (12) in its own units, converted to Tien's (2011) units."""
    C0 = 0.05
    b = ballbal.from_disk_units(omega0, m0, e, C0=C0, D0=0.1)
    eqs = ballbal.equilibria(b)
    k = 1 - omega0**2 * (1 + 2 * m0)
    den = k**2 + (2 * C0 * omega0) ** 2
    # balls opposite, eq (12): lengths over R -> over eps: divide by e
    xo = e * omega0**2 * k / den / e
    yo = -2 * e * omega0**3 * C0 / den / e
    opp = [q.q for q in eqs if q.kind == "opposite"]
    assert len(opp) == 1
    assert np.allclose(opp[0][:2], [xo, yo], atol=1e-12)
    assert np.isclose(np.tan(opp[0][2]), -2 * omega0 * C0 / k)
    # balls together, eq (11): two branches where the arccos argument is admissible
    arg = -4 * m0 * omega0 * C0 / (e * np.sqrt(den))
    tog = [q.q for q in eqs if q.kind == "together"]
    if abs(arg) > 1:
        assert tog == []
        return
    # Eq (11) as transcribed gives the ball angle with its sign flipped; its own
    # condition, rederived here, is sin(phi + atan2(2 C0 omega0, k)) = arg, and eq (11)'s
    # expressions for x and y hold at those angles.
    assert len(tog) == 2
    phi0 = np.arctan2(2 * C0 * omega0, k)
    for q in tog:
        phi = q[2]
        assert abs(np.sin(phi + phi0) - arg) < 1e-12
        c2 = 2 * m0 * np.cos(phi) + e
        x = (k * omega0**2 * c2 + 4 * m0 * omega0**3 * C0 * np.sin(phi)) / den / e
        y = (2 * k * m0 * omega0**2 * np.sin(phi) - 2 * omega0**3 * C0 * c2) / den / e
        assert np.allclose(q[:2], [x, y], atol=1e-12)
    assert abs(_wrap(tog[0][2] - tog[1][2])) > 1e-3


def test_pitchfork_point_in_disk_units_converts():
    b = ballbal.from_disk_units(0.5773, 1.0, 2.0)
    assert abs(b.Omega - 1.0) < 1e-4 and b.eta == (0.5, 0.5)


def test_routh_hurwitz_agrees_with_eigenvalues_on_grid():
    checked = 0
    for Om in np.arange(0.5, 3.0001, 0.1):
        for eta in np.arange(0.5, 1.5001, 0.1):
            for e in ballbal.equilibria(ballbal.Balancer(Omega=Om, eta=(eta, eta), zeta_b=0.1)):
                assert e.residual < 1e-12
                if abs(e.stability_index) > 1e-6:
                    assert e.routh_hurwitz == (e.stability == "stable"), (Om, eta, e.kind)
                    checked += 1
    assert checked > 500


def test_characteristic_polynomial_matches_tien2011_eq_2_17():
    """Coefficients a1, a2, a7, a8 of Tien's (2011) degree-8 polynomial (eq. 2.17) at the
    perfect balance, written out independently here."""
    mu, z, zb, dl = 0.2, 0.05, 0.1, 50.0
    for Om, eta in ((1.2, 1.0), (2.0, 0.8), (0.7, 1.4)):
        b = ballbal.Balancer(mu=mu, zeta=z, zeta_b=zb, delta=dl, Omega=Om, eta=(eta, eta))
        pb = next(e for e in ballbal.equilibria(b) if e.kind == "perfect_balance")
        db = pb.q[2] - pb.q[3]
        em = eta * mu
        D = 2 * dl**2 - 4 * dl * em + em**2 - em**2 * np.cos(2 * db)
        a1 = 8 * dl * (dl - em) * (z + zb) / D
        a2 = 4 * (Om**2 - dl * (em * (1 - 3 * Om**2 + 4 * z * zb)
                                + dl * (-1 + Om**2 - 2 * (z**2 + 4 * z * zb + zb**2)))) / D
        a7 = 8 * dl * em * Om**4 * (-1 + Om**2) * zb / D
        a8 = 2 * em**2 * Om**8 * np.sin(db) ** 2 / D
        p = pb.char_poly
        assert p[0] == 1.0
        assert np.allclose([p[1], p[7], p[8]], [a1, a7, a8], rtol=1e-10)
        # a2 to a6 as transcribed carry slips (a2 even has the wrong sign), so only the
        # coefficients that survived transcription are compared; the roots check the rest.
        del a2
        # eigenvalues are the polynomial's roots
        roots = np.sort_complex(np.roots(p))
        assert np.allclose(roots, np.sort_complex(pb.eigenvalues), atol=1e-8)


def test_stability_index_is_largest_real_part():
    e = ballbal.equilibria(ballbal.Balancer(Omega=1.1, eta=(1.3, 1.3), zeta=0.1, zeta_b=0.1))[0]
    assert e.kind == "perfect_balance"
    assert e.stability_index == pytest.approx(np.max(e.eigenvalues.real))
    # Spec: at Omega = 1.1, eta = 1.3 the leading eigenvalues are 0.0024 +- 0.0900i (Hopf).
    lead = e.eigenvalues[np.argmax(e.eigenvalues.real)]
    assert abs(lead.real - 0.0024) < 1e-4 and abs(abs(lead.imag) - 0.0900) < 1e-4


def test_unequal_and_many_balls_numeric():
    b = ballbal.Balancer(Omega=1.6, eta=(0.7, 0.9))
    eqs = ballbal.equilibria(b)
    pb = [e for e in eqs if e.kind == "perfect_balance"]
    # unequal balls: the configuration and its mirror image are distinct equilibria
    assert len(pb) == 2
    assert np.allclose(pb[0].q[2:], -pb[1].q[2:])
    q = pb[0].q
    assert abs(0.7 * np.cos(q[2]) + 0.9 * np.cos(q[3]) + 1) < 1e-10
    assert abs(0.7 * np.sin(q[2]) + 0.9 * np.sin(q[3])) < 1e-10
    three = ballbal.equilibria(ballbal.Balancer(Omega=1.6, eta=(0.5, 0.5, 0.5)))
    assert any(e.kind == "perfect_balance" and e.neutral == 1 for e in three)
    assert all(e.residual < 1e-9 for e in three)


def test_lab_conversion_round_trip_and_published_example():
    # spec: m_d e = 33.12 g mm, m_b = 2.05 g, r_t = 16 mm gives eta = 0.99
    b = ballbal.Balancer.from_lab(disk_mass=0.03312, eccentricity=1e-3, ball_masses=[2.05e-3] * 2,
                                  track_radius=16e-3, stiffness=2e4, damping=5.0,
                                  track_damping=1e-4, spin=300.0, other_mass=0.5)
    assert round(b.eta[0], 2) == 0.99
    lab = b.to_lab(disk_mass=0.03312, eccentricity=1e-3, stiffness=2e4)
    assert np.isclose(lab["spin"], 300.0) and np.isclose(lab["damping"], 5.0)
    assert np.allclose(lab["ball_masses"], [2.05e-3] * 2)
    assert np.isclose(lab["other_mass"], 0.5)
    assert np.allclose(lab["track_damping"], [1e-4] * 2)
    d = 0.3
    z = ballbal.zeta_from_log_decrement(d)
    # free decay of a damped oscillator: ln(x_k / x_{k+1}) = 2 pi z / sqrt(1 - z^2)
    assert np.isclose(2 * np.pi * z / np.sqrt(1 - z**2), d)
    with pytest.raises(ParameterError) as err:
        ballbal.Balancer.from_lab(disk_mass=1, eccentricity=1, ball_masses=[1], track_radius=1,
                                  stiffness=-1, damping=0, track_damping=0, spin=1)
    assert err.value.parameter == "stiffness"
