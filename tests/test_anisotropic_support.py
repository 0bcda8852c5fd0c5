"""The ground-fixed support unequal in X and Y (a rig's frame): equal axes are the isotropic
support, rescaled; unequal axes give the two free-vibration frequencies sqrt(k_x),
sqrt(k_y) of the closed form, read from a simulation's ground-frame spectrum."""

import math

import numpy as np
import pytest

import ballbal
from ballbal.exceptions import NotAutonomousError, ParameterError

Y0 = [0.1, -0.2, 0.4, 2.9, 0.0, 0.3, -1.5, -1.5]


def test_unit_axes_are_the_isotropic_support():
    b = ballbal.Balancer(Omega=1.5, zeta=0.05, zeta_b=0.1, eta=(0.8, 0.8))
    sc = ballbal.Scene(balancer=b, support=ballbal.AnisotropicSupport())
    assert sc.time_dependence is None
    t = np.linspace(0, 40, 81)
    a = ballbal.simulate(b, Y0, t, rtol=1e-11, atol=1e-13)
    s = ballbal.simulate(sc, Y0, t, rtol=1e-11, atol=1e-13)
    for c in ("x", "y", "b1", "b2", "dx", "dy"):
        assert np.max(np.abs(a[c].to_numpy() - s[c].to_numpy())) < 1e-7, c


def test_equal_stiff_axes_are_a_faster_time_unit():
    """k_x = k_y = k2: the balancer with w_n' = sqrt(k2) w_n, i.e. Omega, zeta, zeta_b over
    sqrt(k2), and every eigenvalue times sqrt(k2)."""
    k2, zeta = 2.0, 0.04
    b = ballbal.Balancer(mu=0.2, zeta=zeta, zeta_b=0.1, Omega=2.5, eta=(0.8, 0.8))
    sc = ballbal.Scene(balancer=b, support=ballbal.AnisotropicSupport(k2, k2))
    r = math.sqrt(k2)
    ref = b.replace(Omega=2.5 / r, zeta=zeta / r, zeta_b=0.1 / r)
    got = ballbal.balanced_state(sc)
    want = ballbal.balanced_state(ref)
    assert got.stability == want.stability
    for s in want.eigenvalues * r:
        assert np.min(np.abs(got.eigenvalues - s)) < 1e-8 * max(1.0, abs(s))


def _peak(signal, dt):
    """Frequency (rad per time unit) of the largest line, Hann window and a parabola
    through the log magnitudes of the top bin and its neighbours."""
    w = np.hanning(signal.size)
    mag = np.abs(np.fft.rfft((signal - signal.mean()) * w))
    i = int(np.argmax(mag[1:])) + 1
    la, lb, lc = np.log(mag[i - 1:i + 2])
    shift = 0.5 * (la - lc) / (la - 2 * lb + lc)
    return 2 * math.pi * (i + shift) / (signal.size * dt)


@pytest.mark.parametrize(("k_x", "k_y", "Omega"), [(1.0, 3.77, 0.3), (0.6, 1.4, 1.1)])
def test_free_vibration_has_the_two_closed_form_frequencies(k_x, k_y, Omega):  # noqa: N803
    """Undamped, a negligible unbalance and balls: in the ground frame X and Y vibrate
    apart, at sqrt(k_x) and sqrt(k_y) whatever the spin."""
    b = ballbal.Balancer(mu=1e-6, zeta=0.0, zeta_b=0.1, Omega=Omega, eta=(1.0, 1.0))
    sup = ballbal.AnisotropicSupport(k_x, k_y)
    sc = ballbal.Scene(balancer=b, support=sup)
    assert sc.time_dependence == "anisotropic_support"
    dt = 0.05
    t = np.arange(0.0, 3000.0, dt)
    df = ballbal.simulate(sc, [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], t, rtol=1e-10,
                          atol=1e-12)
    fx, fy = _peak(df["X"].to_numpy(), dt), _peak(df["Y"].to_numpy(), dt)
    assert fx == pytest.approx(math.sqrt(k_x), rel=2e-3)
    assert fy == pytest.approx(math.sqrt(k_y), rel=2e-3)
    assert sup.natural_frequencies() == pytest.approx((math.sqrt(k_x), math.sqrt(k_y)))


def test_unequal_axes_are_simulation_only_and_saved_in_scene_files(tmp_path):
    sc = ballbal.Scene(support=ballbal.AnisotropicSupport(1.0, 2.5, zeta_y=0.1))
    with pytest.raises(NotAutonomousError) as e:
        ballbal.equilibria(sc)
    assert e.value.effect == "anisotropic_support"
    p = tmp_path / "rig.toml"
    sc.save(p)
    assert ballbal.load_scene(p) == sc


@pytest.mark.parametrize(("kw", "name"), [
    (dict(k_x=0.0), "support.k_x"),
    (dict(k_y=2e4), "support.k_y"),
    (dict(k_y=float("inf")), "support.k_y"),
    (dict(zeta_x=-0.1), "support.zeta_x"),
    (dict(zeta_y=float("nan")), "support.zeta_y"),
])
def test_bad_axes_name_the_parameter(kw, name):
    with pytest.raises(ParameterError) as e:
        ballbal.AnisotropicSupport(**kw)
    assert e.value.parameter == name
