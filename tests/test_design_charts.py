"""Design charts from a model (ballbal.design.balancing_chart, balanced_fraction): the
chasing band's end against a direct periodic() stability check either side of it, the
oil law's and the imbalance's columns in closed form, the balanced fraction's standard
error against the binomial formula and its value against a DOP853 count of starts from
rest written here."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.design import balanced_fraction, balancing_chart
from ballbal.exceptions import ParameterError
from ballbal.options import HarmonicBalance, PeriodicOptions

from reference import rhs_many

FN = 513.0
MODEL = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.2,
                         eta=(0.66, 0.66))
A, MB, RT = 4e-3, 2.05e-3, 0.016  # Tien's (2011) ball: radius, mass; track radius


@pytest.fixture(scope="module")
def by_zeta_b() -> ballbal.design.BalancingChart:
    return balancing_chart(MODEL, vary="zeta_b", values=[0.08, 0.2],
                           natural_frequency_rpm=FN)


def test_chasing_end_is_where_the_periodic_motion_loses_stability(by_zeta_b) -> None:
    opts = PeriodicOptions(harmonic_balance=HarmonicBalance(N=8))
    for r in by_zeta_b.table.iter_rows(named=True):
        om = r["chasing_end_rpm"] / FN
        b = MODEL.replace(zeta_b=r["zeta_b"])
        below = ballbal.periodic(b.replace(Omega=om - 0.01), "R-R", options=opts)
        assert below.status == "converged" and below.stability == "stable", (r, below)
        above = ballbal.periodic(b.replace(Omega=om + 0.02), "R-R", options=opts,
                                 guess=below)
        assert above.status != "converged" or above.stability != "stable", (r, above)
        # a sweep up ends balanced past both the chasing end and the balance's onset
        assert r["balanced_from_rpm"] == max(r["chasing_end_rpm"],
                                             r["perfect_balance_from_rpm"])
    # more track damping ends the chasing sooner
    ends = by_zeta_b.table["chasing_end_rpm"].to_list()
    assert ends[1] < ends[0]
    assert "BalancingChart" in repr(by_zeta_b) and "<table>" in by_zeta_b._repr_html_()


def test_oil_and_imbalance_columns_in_closed_form() -> None:
    ch = balancing_chart(MODEL, vary="oil_viscosity", values=[20.0, 60.0],
                         natural_frequency_rpm=FN, ball_radius=A, ball_mass=MB,
                         geometric_factor=10.0)
    wn = FN * 2 * math.pi / 60
    zb = 10.0 * 6 * math.pi * np.array([20e-3, 60e-3]) * A / (2 * MB * wn)
    assert np.allclose(ch.table["zeta_b"], zb, rtol=1e-12)
    ends = ch.table["chasing_end_rpm"].to_list()
    assert ends[1] < ends[0]  # the thicker oil ends the chasing sooner
    im = balancing_chart(MODEL, vary="imbalance", values=[30.0, 80.0],
                         natural_frequency_rpm=FN, ball_mass=MB, track_radius=RT,
                         Omega=(1.0, 1.6, 0.02))
    eta = 2.05 * 16.0 / np.array([30.0, 80.0])  # g mm over g mm
    assert np.allclose(im.table["eta"], eta, rtol=1e-12)
    assert np.allclose(im.table["eta_margin"], 2 * eta - 1, rtol=1e-12)
    # 80 g mm: 2 eta = 0.82, the balls cannot cancel it; 30 g mm: they can
    assert im.table["status"].to_list() == ["ok", "no_balance"]
    assert im.table["balanced_from_rpm"][1] is None


def from_rest_balanced(b: ballbal.Balancer, angles: np.ndarray, t_end: float) -> np.ndarray:
    """Starts from rest in the ground frame (x = y = x' = y' = 0, b_i' = -Omega) at the
    given ball angles, integrated together by DOP853; True where the disk centre has
    come to rest at the origin (the perfect balance)."""
    k = angles.shape[0]
    s0 = np.zeros((8, k))
    s0[2:4] = angles.T
    s0[6:8] = -b.Omega

    def f(t: float, y: np.ndarray) -> np.ndarray:
        return rhs_many(b, t, y.reshape(8, k)).ravel()

    end = solve_ivp(f, (0.0, t_end), s0.ravel(), method="DOP853", rtol=1e-7,
                    atol=1e-9).y[:, -1].reshape(8, k)
    return np.hypot(end[0], end[1]) + np.abs(end[6:8]).max(axis=0) < 0.05


def test_balanced_fraction_against_binomial_and_simulation() -> None:
    speed = 1.17 * FN  # Omega 1.17: some starts chase, most balance
    n = 60
    res = balanced_fraction(MODEL, speeds_rpm=[speed], natural_frequency_rpm=FN,
                            starts=n, seed=3)
    row = res.table.row(0, named=True)
    p = row["balanced"] / n
    assert row["fraction"] == pytest.approx(p, abs=1e-15)
    assert row["std_error"] == pytest.approx(math.sqrt(p * (1 - p) / n), rel=1e-12)
    assert 0.0 < p < 1.0, row  # a speed where the answer is not a certainty
    # An independent count on the same starts (the seed's angles, as basins draws
    # them), each simulated by DOP853 on the model's equations written in
    # tests/reference.py: a start near a basin's edge may go either way, no more than
    # two of them.
    angles = ballbal.basins.basins(MODEL.replace(Omega=speed / FN), samples=n, seed=3,
                                   t_end=10.0, orbits=False).table.select("b1", "b2")
    ours = from_rest_balanced(MODEL.replace(Omega=speed / FN), angles.to_numpy(), 1000.0)
    assert abs(int(ours.sum()) - row["balanced"]) <= 2, (int(ours.sum()), row)
    assert "BalancedFraction" in repr(res) and "<table>" in res._repr_html_()


@pytest.mark.parametrize(("kw", "name"), [
    ({"vary": "ball_mass"}, "vary"),
    ({"values": [-0.1]}, "values"),
    ({"values": np.ones(1001)}, "values"),
    ({"natural_frequency_rpm": 0.0}, "natural_frequency_rpm"),
    ({"vary": "oil_viscosity"}, "ball_radius"),
    ({"vary": "imbalance"}, "track_radius"),
    ({"Omega": (2.0, 1.0, 0.1)}, "Omega"),
    ({"Omega": (1.0, 2.0, 1e-6)}, "Omega"),
])
def test_balancing_chart_bad_input(kw, name) -> None:
    args = dict(vary="zeta_b", values=[0.1], natural_frequency_rpm=FN) | kw
    with pytest.raises(ParameterError) as e:
        balancing_chart(MODEL, **args)
    assert e.value.parameter == name


@pytest.mark.parametrize(("kw", "name"), [
    ({"speeds_rpm": [0.0]}, "speeds_rpm"),
    ({"starts": 0}, "starts"),
    ({"starts": 10**6}, "starts"),
    ({"seed": -1}, "seed"),
    ({"natural_frequency_rpm": -5.0}, "natural_frequency_rpm"),
])
def test_balanced_fraction_bad_input(kw, name) -> None:
    args = dict(speeds_rpm=[600.0], natural_frequency_rpm=FN, starts=10) | kw
    with pytest.raises(ParameterError) as e:
        balanced_fraction(MODEL, **args)
    assert e.value.parameter == name
