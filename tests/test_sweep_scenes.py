"""Speed sweeps of scenes: a scene that is the plain balancer by other code (the
composed components, a tilting disk at mid-span started flat) sweeps as the balancer
does; a tilting disk's state is carried over a speed step with its axis' ground-frame
motion continuous; a spring balancer rests at each step in its balanced state, whose
support acceleration is r Omega^2."""

import math

import numpy as np
import pytest

import ballbal
from ballbal.exceptions import NotAutonomousError
from ballbal.sweep import carry_over, speed_sweep

SPEEDS = np.round(np.arange(1.0, 1.8 + 1e-9, 0.1), 3)


def standard(omega: float = 1.2) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=omega,
                            eta=(0.7, 0.7))


@pytest.fixture(scope="module")
def plain() -> ballbal.sweep.Sweep:
    return speed_sweep(standard(), SPEEDS, dwell=1000.0)


@pytest.mark.parametrize("scene", [
    ballbal.Scene(balancer=standard(), support=ballbal.AnisotropicSupport(1.0, 1.0)),
    ballbal.Scene(balancer=standard(), tilt=ballbal.Tilt(a=2.0, b=2.0, j_t=0.3, j_z=0.5)),
], ids=["unit_axes", "mid_span_tilt"])
def test_a_scene_that_is_the_balancer_sweeps_as_the_balancer(plain, scene):
    sw = speed_sweep(scene, SPEEDS, dwell=1000.0)
    assert sw.up == plain.up and sw.down == plain.down
    assert sw.table["label"].to_list() == plain.table["label"].to_list()
    a, b = sw.table["vibration"].to_numpy(), plain.table["vibration"].to_numpy()
    assert np.allclose(a, b, rtol=1e-4, atol=1e-7), (a, b)
    # the sweep really has both motions and both transitions
    assert plain.up is not None and plain.down is not None
    assert {"perfect_balance", "merged_R-R"} <= set(plain.table["label"])


def _rotation(axis: int, a):
    c, s = np.cos(a), np.sin(a)
    if axis == 0:
        return np.array([[1, 0, 0], [0, c, s], [0, -s, c]])
    if axis == 1:
        return np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def _axis_motion(y, omega, delta, theta=0.7):
    """The disk normal in the ground frame and its rate, from the rotation ground -> body
    R = R_y(B / delta) R_x(A / delta) R_z(theta) (complex-step derivative along the
    state's rates and the spin), and the centre's ground position and velocity; ``y`` is
    ``x, y, A, B, b1, b2`` and their rates."""
    h = 1e-30
    A = y[2] + 1j * h * y[8]
    B = y[3] + 1j * h * y[9]
    th = theta + 1j * h * omega
    R = _rotation(1, B / delta) @ _rotation(0, A / delta) @ _rotation(2, th)
    normal = R.T[:, 2]
    Z = (y[0] + 1j * y[1]) * np.exp(1j * theta)
    dZ = (y[6] + 1j * y[7] + 1j * omega * (y[0] + 1j * y[1])) * np.exp(1j * theta)
    return np.real(normal), np.imag(normal) / h, Z, dZ


@pytest.mark.parametrize("delta", [50.0, 3.0])
def test_carry_over_keeps_a_tilting_disks_axis_motion(delta):
    rng = np.random.default_rng(4)
    y = np.concatenate([rng.normal(size=4) * [1, 1, 0.3 * delta, 0.2 * delta],
                        rng.normal(size=4)])
    y = np.concatenate([y[:4], [0.4, -1.1], y[4:], [0.3, -0.2]])  # x, y, A, B, b1, b2
    a, b = 1.3, 1.75
    z = carry_over(y, a, b, 2, 6, delta=delta)
    n0, dn0, Z0, dZ0 = _axis_motion(y, a, delta)
    n1, dn1, Z1, dZ1 = _axis_motion(z, b, delta)
    assert np.allclose(n0, n1, atol=1e-14) and np.allclose(dn0, dn1, atol=1e-12)
    assert abs(Z0 - Z1) < 1e-14 and abs(dZ0 - dZ1) < 1e-12
    assert np.allclose(y[:6], z[:6])  # positions
    assert np.allclose(z[10:] + b, y[10:] + a)  # the balls' absolute rates


def test_a_spring_balancer_rests_in_its_balanced_state_at_each_step():
    """Springs leave a residual whirl r at rest in the disk frame: the support moves on a
    circle, |Z''| = r Omega^2, r from the balanced state found by Newton's method."""
    b = ballbal.Balancer(Omega=2.0, zeta=0.05, zeta_b=0.1)
    sc = ballbal.Scene(balancer=b, springs=1e-4)
    speeds = [2.0, 2.25, 2.5]
    start = ballbal.balanced_state(sc)
    y0 = np.concatenate([start.q, np.zeros(start.q.size)])
    sw = speed_sweep(sc, speeds, dwell=1500.0, direction="up", y0=y0, kick=0.0)
    for row in sw.table.iter_rows(named=True):
        eq = ballbal.balanced_state(sc.replace(Omega=row["Omega"]))
        r = math.hypot(*eq.q[:2])
        assert r > 0.05  # a residual whirl, not a perfect balance
        assert row["at_rest"], row
        assert row["vibration"] == pytest.approx(r * row["Omega"] ** 2, rel=1e-4)


def test_a_time_dependent_scene_is_refused():
    with pytest.raises(NotAutonomousError) as e:
        speed_sweep(ballbal.Scene(gravity=0.1), [1.0, 1.1])
    assert e.value.effect == "gravity"
    with pytest.raises(NotAutonomousError) as e:
        speed_sweep(ballbal.Scene(support=ballbal.AnisotropicSupport(1.0, 2.0)), [1.0, 1.1])
    assert e.value.effect == "anisotropic_support"
