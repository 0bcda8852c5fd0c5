"""A rotor on a journal bearing spun up by a prescribed speed profile (seed 002's start-up).

The expected trajectory is integrated here with scipy's DOP853 from Newton's law written
in the test: the short (Ocvirk) bearing's half-Sommerfeld film with the journal's speed
``s`` entering Reynolds' right-hand side directly (``6 s dH/dtheta + 12 dH/dtau``, not
the core's scaling of the film at full speed), and the unbalance's mass centre on the
angle ``theta(tau)`` of the ramp law written here, differentiated twice by hand.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ballbal.bearing import Bearing, RotorOnBearing, SpinUp, simulate_rotor
from ballbal.exceptions import ParameterError

from ocvirk import LAM
from ocvirk import film_force as short_force

SHORT = Bearing(length_ratio=LAM, model="short")


def ramp(tau: float, start: float, duration: float) -> tuple[float, float, float]:
    """Speed, its rate and the journal's angle of a linear run-up."""
    if tau < duration:
        k = (1 - start) / duration
        return start + k * tau, k, start * tau + 0.5 * k * tau * tau
    return 1.0, 0.0, 0.5 * (1 + start) * duration + tau - duration


@pytest.mark.parametrize("start", [0.0, 0.3])
def test_run_up_matches_newton_integrated_here(start: float) -> None:
    m, gn, rho, dur, phase = 2.0, 0.4, 0.05, 12.0, math.radians(25.0)
    r = RotorOnBearing(SHORT, m, gravity=gn, unbalance=rho, unbalance_phase=25.0,
                       spin_up=SpinUp(start, dur))
    y0 = [0.3, -0.2, 0.0, 0.0]
    t = np.linspace(0.0, 30.0, 61)
    tr = simulate_rotor(r, y0, (0.0, 30.0), t_eval=t, rtol=1e-10, atol=1e-12)
    assert tr.outcome == "completed", tr.message

    def rhs(tau: float, q: np.ndarray) -> list[float]:
        s, ds, th = ramp(tau, start, dur)
        f = short_force(*q, s)
        # journal centre = mass centre - rho_u (cos, sin)(theta + phase): its acceleration
        # is f / m + g - rho_u d2/dtau2 (cos, sin)(theta + phase)
        c, sn = math.cos(th + phase), math.sin(th + phase)
        return [q[2], q[3],
                f[0] / m + gn + rho * (s * s * c + ds * sn),
                f[1] / m + rho * (s * s * sn - ds * c)]

    ref = solve_ivp(rhs, (0.0, 30.0), y0, t_eval=t, rtol=1e-11, atol=1e-13,
                    method="DOP853", max_step=0.5)
    got = tr.table.select("x", "y", "vx", "vy").to_numpy().T
    err = np.abs(got - ref.y).max()
    assert err < 1e-6, err
    # the film columns are the film at the rows' speed
    f = np.array([short_force(*q, ramp(tt, start, dur)[0])
                  for tt, q in zip(t, ref.y.T, strict=True)])
    assert np.allclose(tr.table["fx"], f[:, 0], atol=1e-5)
    assert np.allclose(tr.table["fy"], f[:, 1], atol=1e-5)


def test_after_the_ramp_the_rotor_is_the_sudden_start_shifted_in_phase() -> None:
    """Past the ramp the equations are the sudden start's with the unbalance turned back by
    the angle lost on the ramp, (1 - start) duration / 2: without unbalance both runs end
    on the same static equilibrium."""
    r_ramp = RotorOnBearing(SHORT, 1.0, gravity=1.0, spin_up=SpinUp(0.2, 10.0))
    r_now = RotorOnBearing(SHORT, 1.0, gravity=1.0)
    a = simulate_rotor(r_ramp, (0.1, 0.0), (0.0, 300.0), samples=3)
    b = simulate_rotor(r_now, (0.1, 0.0), (0.0, 300.0), samples=3)
    ea, eb = a.table.row(-1, named=True), b.table.row(-1, named=True)
    assert abs(ea["x"] - eb["x"]) < 1e-6 and abs(ea["y"] - eb["y"]) < 1e-6


@pytest.mark.parametrize("kw,name", [
    ({"start": 1.0}, "spin_up.start"), ({"start": -0.1}, "spin_up.start"),
    ({"duration": 0.0}, "spin_up.duration"), ({"duration": math.inf}, "spin_up.duration"),
    ({"duration": 1e13}, "spin_up.duration"),
])
def test_bad_run_up_names_the_parameter(kw: dict[str, float], name: str) -> None:
    with pytest.raises(ParameterError) as e:
        SpinUp(**kw)
    assert e.value.parameter == name
