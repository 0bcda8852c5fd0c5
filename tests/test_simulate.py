
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.exceptions import ParameterError

from reference import jacobi_integral, rhs

NOT_STATE = ["t", "theta", "X", "Y"]  # simulate() columns besides the state

def test_installed_not_source_tree():
    # The suite must exercise the built wheel, not python/ballbal in the checkout.
    assert "site-packages" in ballbal.__file__ or "dist-packages" in ballbal.__file__


def test_agrees_with_scipy_solve_ivp():
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.3, eta=(0.9, 1.1))
    y0 = np.array([0.1, -0.2, 0.4, 2.5, 0.0, 0.0, -1.3, -1.3])
    t = np.linspace(0, 60, 61)
    ref = solve_ivp(lambda tt, s: rhs(b, tt, s), (0, 60), y0, t_eval=t, rtol=1e-11, atol=1e-13,
                    method="DOP853")
    df = ballbal.simulate(b, y0, t, rtol=1e-10, atol=1e-12)
    cols = ["x", "y", "b1", "b2", "dx", "dy", "db1", "db2"]
    got = df.select(cols).to_numpy()
    assert np.max(np.abs(got - ref.y.T)) < 1e-7


def test_same_tolerances_as_scipy_rk45_give_same_accuracy_class():
    b = ballbal.Balancer(Omega=1.2)
    y0 = np.array([0.0, 0.0, 0.3, 1.9, 0.0, 0.0, -1.2, -1.2])
    t = np.array([50.0])
    exact = solve_ivp(lambda tt, s: rhs(b, tt, s), (0, 50), y0, t_eval=t, rtol=1e-12,
                      atol=1e-14, method="DOP853").y[:, -1]
    for rtol in (1e-5, 1e-7):
        sp = solve_ivp(lambda tt, s: rhs(b, tt, s), (0, 50), y0, t_eval=t, rtol=rtol,
                       atol=rtol * 1e-3, method="RK45").y[:, -1]
        ours = ballbal.simulate(b, y0, t, rtol=rtol, atol=rtol * 1e-3).drop(NOT_STATE)
        e_sp = np.max(np.abs(sp - exact))
        e_us = np.max(np.abs(ours.to_numpy()[-1] - exact))
        # Same method and step control: errors of the same order of magnitude.
        assert e_us < 10 * e_sp + 1e-12
        assert e_us < 1e3 * rtol


def test_jacobi_integral_conserved_without_damping():
    b = ballbal.Balancer(mu=0.3, zeta=0.0, zeta_b=0.0, delta=20, Omega=1.4, eta=(0.8, 1.2, 0.5))
    y0 = np.array([0.2, -0.1, 0.0, 2.0, 4.0, 0.05, 0.1, -0.3, 0.2, 0.1])
    t = np.linspace(0, 200, 401)
    for rtol, bound in ((1e-6, 1e-3), (1e-10, 1e-7)):
        df = ballbal.simulate(b, y0, t, rtol=rtol, atol=rtol * 1e-2)
        s = df.drop(NOT_STATE).to_numpy()
        h = jacobi_integral(b, s)
        drift = np.max(np.abs(h - h[0]))
        assert drift < bound, (rtol, drift)
    # With damping it is no longer an integral: a check that the test can fail.
    bd = b.replace(zeta=0.05)
    s = ballbal.simulate(bd, y0, t, rtol=1e-10, atol=1e-12).drop(NOT_STATE).to_numpy()
    hd = jacobi_integral(bd, s)
    assert np.max(np.abs(hd - hd[0])) > 1e-2


def test_fixed_frame_position():
    b = ballbal.Balancer()
    df = ballbal.simulate(b, t_span=(0, 10))
    r_rot = np.hypot(df["x"], df["y"])
    r_fix = np.hypot(df["X"], df["Y"])
    assert np.allclose(r_rot, r_fix)
    ph = b.Omega * df["t"].to_numpy()
    assert np.allclose(df["X"], df["x"] * np.cos(ph) - df["y"] * np.sin(ph))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"mu": float("nan")}, "mu"),
        ({"zeta": -0.1}, "zeta"),
        ({"zeta_b": float("inf")}, "zeta_b"),
        ({"delta": 0.0}, "delta"),
        ({"eta": (1.0, 0.0)}, "eta2"),
        ({"eta": ()}, "eta"),
        ({"Omega": -1.0}, "Omega"),
        ({"mu": 1.5}, "mu"),
    ],
)
def test_bad_parameters_raise_value_error_naming_them(kwargs, name):
    # Refused when the model is made, before any analysis.
    with pytest.raises(ParameterError) as err:
        ballbal.Balancer(**kwargs)
    assert err.value.parameter == name


def test_bad_times_and_state():
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(b, t_eval=[0.0, 2.0, 1.0])
    assert err.value.parameter == "t_eval"
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(b, t_eval=[0.0, float("nan")])
    assert err.value.parameter == "t_eval"
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(b, y0=[0.0] * 5, t_eval=[0.0, 1.0])
    assert err.value.parameter == "y0"
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(b, y0=[float("nan")] * 8, t_eval=[0.0, 1.0])
    assert err.value.parameter == "y0"
    with pytest.raises(ParameterError) as err:
        ballbal.simulate(b, t_span=(0, 1), rtol=-1.0)
    assert err.value.parameter == "rtol"


def test_divergent_integration_is_an_error_not_a_panic():
    # Zero support stiffness margin and a huge kick: the core must report, not crash.
    b = ballbal.Balancer()
    with pytest.raises((RuntimeError, ValueError)):
        ballbal.simulate(b, y0=[0, 0, 0, 0, 1e300, 1e300, 1e300, 1e300], t_eval=[0.0, 1.0])
