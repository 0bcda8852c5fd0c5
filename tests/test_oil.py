"""The viscosity -> zeta_b law (ballbal.oil): Stokes' drag and its definition of zeta_b
written here, the wall factor against a second published series (Bohlin's, for a sphere
on a tube's axis), zeta_b proportional to the viscosity, bad input named."""

from __future__ import annotations

import math

import pytest

from ballbal import oil
from ballbal.exceptions import ParameterError

A, M, FN = 4e-3, 2.05e-3, 513.0  # Tien's (2011) 2.05 g ball of radius 4 mm, f_n 513 rpm


def test_open_oil_is_stokes_drag() -> None:
    mu = 36.9e-3  # Pa s
    c_b = 6 * math.pi * mu * A  # N s/m, Stokes (1851)
    zeta_b = c_b / (2 * M * FN * 2 * math.pi / 60)
    assert oil.track_damping(mu, ball_radius=A, ball_mass=M,
                             natural_frequency_rpm=FN) == pytest.approx(zeta_b, rel=1e-12)
    # the geometric factor multiplies it, and geometric_factor() inverts it
    z = oil.track_damping(mu, ball_radius=A, ball_mass=M, natural_frequency_rpm=FN,
                          geometric_factor=7.5)
    assert z == pytest.approx(7.5 * zeta_b, rel=1e-12)
    assert oil.geometric_factor(z, mu, ball_radius=A, ball_mass=M,
                                natural_frequency_rpm=FN) == pytest.approx(7.5, rel=1e-12)


@pytest.mark.parametrize("lam", [0.05, 0.1, 0.2, 0.3])
def test_wall_factor_against_bohlins_series(lam: float) -> None:
    # Bohlin (1960)'s series for a sphere on a tube's axis, an independent fit of the
    # same problem; both hold to about 1 % up to a / R = 0.3
    bohlin = 1 / (1 - 2.10444 * lam + 2.08877 * lam**3 - 0.94813 * lam**5
                  - 1.372 * lam**6 + 3.87 * lam**8 - 4.19 * lam**10)
    assert oil.wall_factor(A, A / lam) == pytest.approx(bohlin, rel=0.015)


def test_wall_factor_grows_as_the_ball_fills_the_channel() -> None:
    ks = [oil.wall_factor(A, A / lam) for lam in (0.1, 0.3, 0.5, 0.7, 0.79)]
    assert all(b > a for a, b in zip(ks, ks[1:], strict=False))
    assert oil.wall_factor(A, None) == 1.0
    # the first-order term of the series: K = 1 + 2.105 a / R for a small ball
    assert oil.wall_factor(A, 1000 * A) == pytest.approx(1 + 2.105e-3, rel=1e-5)


def test_zeta_b_is_proportional_to_the_viscosity() -> None:
    kw = dict(ball_radius=A, ball_mass=M, natural_frequency_rpm=FN, channel_radius=6e-3,
              geometric_factor=3.0)
    z1 = oil.track_damping(26.3e-3, **kw)
    for mu in (36.9e-3, 76.0e-3, 144.3e-3):
        assert oil.track_damping(mu, **kw) / z1 == pytest.approx(mu / 26.3e-3, rel=1e-12)
    # and inversely proportional to the ball's mass and the natural frequency
    assert oil.track_damping(26.3e-3, **(kw | {"natural_frequency_rpm": 2 * FN})) \
        == pytest.approx(z1 / 2, rel=1e-12)


@pytest.mark.parametrize(("kw", "name"), [
    ({"viscosity": -1.0}, "viscosity"),
    ({"viscosity": math.nan}, "viscosity"),
    ({"ball_radius": 0.0}, "ball_radius"),
    ({"ball_mass": -2e-3}, "ball_mass"),
    ({"natural_frequency_rpm": 0.0}, "natural_frequency_rpm"),
    ({"channel_radius": 4.5e-3}, "channel_radius"),  # a / R = 0.89: beyond the factor
    ({"geometric_factor": 0.0}, "geometric_factor"),
])
def test_bad_input_is_named(kw: dict[str, float], name: str) -> None:
    args = dict(viscosity=0.03, ball_radius=A, ball_mass=M, natural_frequency_rpm=FN,
                channel_radius=8e-3) | kw
    mu = args.pop("viscosity")
    with pytest.raises(ParameterError) as e:
        oil.track_damping(mu, **args)
    assert e.value.parameter == name


def test_transfer_oils_round_trip() -> None:
    """Two oils whose transitions are where the model's band ends at zeta_b 0.1 and at
    twice that (twice the viscosity): the law calibrated on the first gives kappa in
    closed form and predicts the second's zeta_b, so the second's residual is within
    the band end's refinement, and its calibrated zeta_b the law's."""
    import polars as pl

    import ballbal
    from ballbal.calibration import stable_band_end, transfer_oils

    model = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.1,
                             eta=(0.66, 0.66))
    grid = (1.0, 1.6, 0.01)
    ends = [stable_band_end(model.replace(zeta_b=z), Omega=grid) * FN for z in (0.1, 0.2)]
    cases = pl.DataFrame({"case": ["thin", "thick"], "viscosity_cP": [20.0, 40.0],
                          "speed_rpm": ends, "natural_frequency_rpm": [FN, FN]})
    tr = transfer_oils(model, cases, reference=0, ball_radius=A, ball_mass=M,
                       bracket=(0.05, 0.4), Omega=grid)
    unit = 6 * math.pi * 20e-3 * A / (2 * M * FN * 2 * math.pi / 60)  # zeta_b at kappa 1
    t = tr.table
    assert tr.geometric_factor == pytest.approx(t["calibrated_zeta_b"][0] / unit, rel=1e-9)
    assert t["calibrated_zeta_b"][0] == pytest.approx(0.1, abs=1e-3)
    assert t["law_zeta_b"][1] == pytest.approx(2 * t["calibrated_zeta_b"][0], rel=1e-9)
    assert t["ratio"][1] == pytest.approx(1.0, abs=0.02)
    assert abs(t["residual_rpm"][1]) < 2.0
    assert t["status"].to_list() == ["ok", "ok"]
    assert "OilTransfer" in repr(tr) and "<table>" in tr._repr_html_()
