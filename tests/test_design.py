"""Design charts in lab units: the natural frequency and capacity in closed form, the
critical speed confirmed by time simulation on either side of it, under-capacity balls
reported, bad input named."""

import math

import numpy as np
import pytest

import ballbal
from ballbal.design import critical_speed_chart
from ballbal.exceptions import ParameterError

# Tien's (2011) rig, roughly: m_d e = 33.12 g mm, 2.05 g balls on a 16 mm track, a
# support resonance near 513 rpm
LAB = dict(disk_mass=0.3, eccentricity=33.12e-6 / 0.3, ball_mass=2.05e-3, track_radius=0.016,
           stiffness=1443.0, damping=2.7, track_damping=0.022, other_mass=0.2)
RPM = 60 / (2 * math.pi)


@pytest.fixture(scope="module")
def chart():
    return critical_speed_chart(vary="ball_mass", values=[0.8e-3, 1.5e-3, 2e-3, 3e-3],
                                max_rpm=2000.0, **LAB)


def test_closed_form_columns(chart):
    t = chart.table
    m = t["ball_mass"].to_numpy()
    total = LAB["disk_mass"] + LAB["other_mass"] + 2 * m
    assert np.allclose(t["natural_frequency_rpm"], np.sqrt(LAB["stiffness"] / total) * RPM,
                       rtol=1e-12)
    eta = m * LAB["track_radius"] / (LAB["disk_mass"] * LAB["eccentricity"])
    assert np.allclose(t["eta"], eta, rtol=1e-12)
    # 0.8 g: 2 eta = 0.77 < 1, the balls cannot cancel the imbalance
    assert t["status"].to_list() == ["no_balance", "ok", "ok", "ok"]
    crit = t["critical_speed_rpm"].to_numpy()[1:]
    assert np.all(crit > t["natural_frequency_rpm"].to_numpy()[1:])
    assert np.all(np.diff(crit) > 0)  # heavier balls: balanced from a higher speed here


@pytest.mark.parametrize("factor", [0.96, 1.04])
def test_critical_speed_by_simulation(chart, factor):
    """Just below the critical speed a perturbed perfect balance runs away; just above
    it returns (simulation from the closed-form ball angles arccos(-1 / (2 eta)))."""
    row = chart.table.filter(chart.table["ball_mass"] == 2e-3).row(0, named=True)
    lab = {k: v for k, v in LAB.items() if k != "ball_mass"}
    b = ballbal.Balancer.from_lab(ball_masses=[2e-3, 2e-3],
                                  spin=factor * row["critical_speed_rpm"] / RPM, **lab)
    angle = math.acos(-1 / (2 * row["eta"]))
    y0 = [0.0, 0.0, angle + 1e-3, -angle - 5e-4, 0.0, 0.0, 0.0, 0.0]
    df = ballbal.simulate(b, y0, np.linspace(0, 4000, 401), rtol=1e-10, atol=1e-12)
    dev = abs(df["b1"][-1] - angle) + abs(df["b2"][-1] + angle)
    if factor < 1:
        assert dev > 1.0  # left the balance
    else:
        assert dev < 1e-6


def test_track_radius_chart():
    ch = critical_speed_chart(vary="track_radius", values=[0.008, 0.02], max_rpm=2000.0,
                              spins=100, **LAB)
    t = ch.table
    assert t["status"].to_list() == ["no_balance", "ok"]
    eta = t["track_radius"].to_numpy() * LAB["ball_mass"] / (LAB["disk_mass"]
                                                             * LAB["eccentricity"])
    assert np.allclose(t["eta"], eta, rtol=1e-12)


@pytest.mark.parametrize(("kw", "name"), [
    (dict(vary="oil"), "vary"),
    (dict(values=[-1.0]), "values"),
    (dict(values=[]), "values"),
    (dict(values=np.ones(1001)), "values"),
    (dict(spins=1), "spins"),
    (dict(max_rpm=0.0), "max_rpm"),
    (dict(disk_mass=-1.0), "disk_mass"),
])
def test_bad_input_is_named(kw, name):
    args = dict(vary="ball_mass", values=[2e-3], max_rpm=2000.0) | LAB | kw
    with pytest.raises(ParameterError) as e:
        critical_speed_chart(**args)
    assert e.value.parameter == name
