"""ballbal.data: Tien's (2011) chapter-4 numbers, checked against each other and against
formulas written here, and the lab helpers against synthetic records."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ballbal
from ballbal import data
from ballbal.exceptions import ParameterError


def _value(quantity: str, case: str) -> float:
    df = data.experiments()
    hit = df.filter((df["quantity"] == quantity) & (df["case"] == case))
    assert hit.height == 1, (quantity, case)
    return float(hit["value"][0])


def test_every_row_has_a_source_and_unit_column() -> None:
    df = data.experiments()
    assert df.height > 60
    assert df["source"].str.len_chars().min() > 0
    assert set(df.columns) == {"quantity", "value", "unit", "case", "source", "notes"}


@pytest.mark.parametrize(("case", "m_b", "r_t", "m_d", "e"), [
    ("single ball eta 0.54", 1.05, 17.0, 0.92, 36.0),
    ("single ball eta 0.99", 2.05, 16.0, 0.92, 36.0),
    ("single ball eta 1.85", 4.09, 15.0, 0.92, 36.0),
    ("two balls eta 0.66", 2.05, 16.0, 1.38, 36.0),
    ("two balls eta 1.30", 2.05, 16.0, 0.70, 36.0),
    ("two balls eta 0.51", 4.09, 15.0, 2.52, 48.0),
    ("two balls eta 0.64", 4.09, 15.0, 1.99, 48.0),
    ("two balls eta 1.47", 4.09, 15.0, 0.87, 48.0),
])
def test_printed_eta_follows_from_masses_and_radii(case: str, m_b: float, r_t: float,
                                                    m_d: float, e: float) -> None:
    # eta = m_b r_t / (m_d e) (model.md), rounded as Tien (2011) prints it.
    got = data.eta(m_b, r_t, data.imbalance(m_d, e))
    assert round(got, 2) == pytest.approx(_value("eta", case), abs=1e-12)


def test_imbalance_of_table_4_2() -> None:
    assert data.imbalance(0.92, 36.0) == pytest.approx(_value("imbalance", "single ball"))


def test_design_natural_frequency_of_section_4_1_2() -> None:
    # k = 17 E b h^3 / (8 l^3) with the rig's leaf springs, M = 362.1 g: 559 rpm.
    k = data.leaf_spring_stiffness(193e9, 14e-3, 0.3e-3, 50e-3)
    assert k == pytest.approx(17 * 193e9 * 14e-3 * (0.3e-3) ** 3 / (8 * (50e-3) ** 3))
    rpm = math.sqrt(k / 362.1e-3) * 60 / (2 * math.pi)
    assert round(rpm) == _value("natural_frequency_design", "rig")


def test_peak_labels_are_omega_plus_k_omega() -> None:
    # Tien's (2011) labels: each peak within 2 rpm of speed + k * whirl; the unlabelled
    # 996 rpm peak of the 800 rpm record is no such line (it is twice the ball rate).
    whirl = {"R-R 800 rpm": 302.0, "O-O 555 rpm": 24.0, "R-O 560 rpm": 39.0}
    for row in data.peaks().iter_rows(named=True):
        w = whirl[row["case"]]
        k_est = (row["frequency_rpm"] - row["speed_rpm"]) / w
        if row["k"] is None:
            assert abs(k_est - round(k_est)) > 0.3
            assert row["frequency_rpm"] == pytest.approx(2 * (row["speed_rpm"] - w), abs=2)
        else:
            assert abs(row["frequency_rpm"] - (row["speed_rpm"] + row["k"] * w)) <= 2.0
    largest = data.peaks().filter(data.peaks()["largest"])
    assert (largest["k"] == -1).all() and largest.height == 3


def test_speed_conversions_round_trip() -> None:
    assert data.rpm_to_ratio(800.0) == pytest.approx(800 / 513)
    arr = data.ratio_to_rpm(np.array([1.0, 1.3]), 513.0)
    assert np.allclose(arr, [513.0, 666.9])
    assert data.rpm_to_ratio(data.ratio_to_rpm(1.234, 557.0), 557.0) == pytest.approx(1.234)
    t = data.transitions()
    assert t.filter(t["case"] == "pads B")["Omega"][0] == pytest.approx(1.5)


@pytest.mark.parametrize("zeta", [0.02, 0.039])
def test_log_decrement_recovers_damping_from_a_noisy_decay(zeta: float) -> None:
    # x(t) = exp(-zeta wn t) cos(wd t) plus 0.2 % noise: the peak ratio of successive
    # cycles is exp(2 pi zeta / sqrt(1 - zeta^2)), so delta's zeta is zeta itself.
    rng = np.random.default_rng(7)
    wn = 2 * math.pi * 513 / 60
    wd = wn * math.sqrt(1 - zeta**2)
    t = np.linspace(0, 1.0, 20001)
    x = np.exp(-zeta * wn * t) * np.cos(wd * t) + 2e-3 * rng.standard_normal(t.size)
    # Tien (2011) low-passes first: a short moving average stands in for the filter.
    x = np.convolve(x, np.ones(21) / 21, mode="same")
    fit = data.log_decrement(x, n_peaks=5)
    assert fit.zeta == pytest.approx(zeta, rel=0.03)
    assert fit.delta == pytest.approx(2 * math.pi * zeta / math.sqrt(1 - zeta**2), rel=0.03)
    assert fit.zeta == pytest.approx(ballbal.zeta_from_log_decrement(fit.delta))


def test_log_decrement_bad_records() -> None:
    with pytest.raises(ParameterError) as e:
        data.log_decrement([1.0, 2.0])
    assert e.value.parameter == "signal"
    with pytest.raises(ParameterError) as e:
        data.log_decrement(np.sin(np.linspace(0, 6, 50)), n_peaks=5)
    assert e.value.parameter == "n_peaks"
    with pytest.raises(ParameterError) as e:
        data.eta(-1.0, 16.0, 33.0)
    assert e.value.parameter == "ball_mass"


def test_dynamics_invariant_under_mu_delta_scaling() -> None:
    # (mu, delta) -> (s mu, s delta) keeps m_b / M = mu eta / delta and scales the
    # rotor's motion: x -> s x, ball angles unchanged (lengths over e, e -> e / s).
    s = 0.5
    a = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2, eta=(0.7, 0.7))
    b = ballbal.Balancer(mu=0.2 * s, zeta=0.05, zeta_b=0.05, delta=50.0 * s, Omega=1.2,
                         eta=(0.7, 0.7))
    y0 = np.array([0.3, -0.2, 1.0, 2.5, 0.1, 0.0, -0.4, 0.2])
    y0b = y0.copy()
    y0b[[0, 1, 4, 5]] *= s
    t = np.linspace(0.0, 40.0, 401)
    ta = ballbal.simulate(a, y0, t, rtol=1e-10, atol=1e-12)
    tb = ballbal.simulate(b, y0b, t, rtol=1e-10, atol=1e-12)
    for c in ("x", "y", "dx", "dy"):
        assert np.allclose(tb[c].to_numpy(), s * ta[c].to_numpy(), atol=1e-7), c
    for c in ("b1", "b2", "db1", "db2"):
        assert np.allclose(tb[c].to_numpy(), ta[c].to_numpy(), atol=1e-7), c
    assert np.ptp(ta["b1"].to_numpy()) > 1.0  # the balls move: not a trivial check


def test_speed_conversions_refuse_what_numpy_would_convert() -> None:
    """rpm_to_ratio(None) returned NaN (numpy reads None as NaN) and True counted as
    1 rpm; both are refused, naming the argument. Arrays keep their shape."""
    from ballbal.exceptions import ParameterTypeError

    for bad in (None, True, [513.0, None], np.array([True, False]), "513"):
        with pytest.raises(ParameterTypeError) as e:
            data.rpm_to_ratio(bad)
        assert e.value.parameter == "rpm"
        with pytest.raises(ParameterTypeError) as e:
            data.ratio_to_rpm(bad)
        assert e.value.parameter == "ratio"
    for bad in (math.nan, [1.0, math.inf]):
        with pytest.raises(ParameterError) as e:
            data.rpm_to_ratio(bad)
        assert e.value.parameter == "rpm"
    r = data.rpm_to_ratio(np.array([[1026.0, -513.0]]))
    assert r.shape == (1, 2) and r.tolist() == [[2.0, -1.0]]
