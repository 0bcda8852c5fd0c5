"""Speed sweeps (Tien's (2011) section 4-2 procedure) on its bistable case: mu 0.2,
zeta 0.05, zeta_b 0.05, delta 50, eta 0.7. Steps of 0.05 dwelling 1000 time units (the
perfect balance decays at 0.004 or faster from Omega 1.2 up, the R-R orbit settles
within a few hundred); a step costs a few milliseconds."""

import numpy as np
import polars as pl
import pytest

import ballbal
from ballbal.exceptions import ParameterError
from ballbal.sweep import carry_over, speed_sweep

STEP = 0.05
SPEEDS = np.round(np.arange(1.0, 1.8 + 1e-9, STEP), 3)


def standard(omega: float = 1.2) -> ballbal.Balancer:
    return ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=omega,
                            eta=(0.7, 0.7))


@pytest.fixture(scope="module")
def sweep() -> ballbal.sweep.Sweep:
    return speed_sweep(standard(), SPEEDS, dwell=1000.0)


def test_up_transition_is_where_the_stable_rr_branch_ends(sweep):
    # A fine scan of the R-R orbit over Omega (harmonic balance + Floquet).
    df = ballbal.scan(standard(), Omega=(1.3, 1.7, 0.01), eta=[0.7], patterns=["R-R"])
    stable = df.filter(pl.col("stability") == "stable")["Omega"]
    end = float(stable.max())
    assert sweep.up is not None
    assert end < sweep.up <= end + STEP + 0.01 + 1e-9, (end, sweep.up)


def test_down_transition_is_the_perfect_balance_stability_boundary(sweep):
    # The perfect balance's stability from its eigenvalues, on a fine grid going down.
    om = np.round(np.arange(1.4, 1.0, -0.005), 4)
    stable = [next(e for e in ballbal.equilibria(standard(o)) if e.kind == "perfect_balance")
              .stability == "stable" for o in om]
    boundary = float(om[stable.index(False)])  # first unstable speed going down
    assert sweep.down is not None
    assert boundary - STEP - 0.005 <= sweep.down <= boundary + 1e-9, (boundary, sweep.down)
    assert sweep.hysteresis is not None and sweep.hysteresis > 0


def test_table_and_vibration(sweep):
    t = sweep.table
    assert t.height == 2 * len(SPEEDS) - 1
    assert t["direction"].to_list() == ["up"] * len(SPEEDS) + ["down"] * (len(SPEEDS) - 1)
    # At the perfect balance the support does not move: |Z''| vanishes; on R-R it does not.
    pb = t.filter((pl.col("label") == "perfect_balance") & (pl.col("Omega") > 1.3))
    rr = t.filter(pl.col("label") == "merged_R-R")
    assert pb.height > 0 and rr.height > 0
    assert pb["vibration"].max() < 1e-4 < rr["vibration"].min()
    # A merged R-R step's mean ball rate is the orbit's omega (harmonic balance).
    r = rr.filter(pl.col("Omega") == 1.4).row(0, named=True)
    sol = ballbal.periodic(standard(1.4), "R-R")
    assert abs(r["omega"] - sol.omega) < 1e-4 * sol.omega


def test_carry_over_keeps_the_ground_frame_state():
    rng = np.random.default_rng(1)
    y = rng.normal(size=8)
    a, b = 1.3, 1.45
    z = carry_over(y, a, b, 2, 4)

    def ground(s, om):  # Z, Z' (at theta = 0) and the balls' absolute rates
        Z = s[0] + 1j * s[1]
        dZ = s[4] + 1j * s[5] + 1j * om * Z
        return Z, dZ, om + s[6], om + s[7]

    assert np.allclose(ground(y, a), ground(z, b))
    assert np.allclose(y[:4], z[:4])


def test_a_slow_ramp_gives_the_same_transitions(sweep):
    # The sweep's rate: one step per dwell. Going up from the merged R-R at 1.3, the
    # last whole turn of a ball; going down from the perfect balance at 1.45, the first.
    rate = STEP / 1000.0

    def turns(df):
        k = np.floor(df["b1"].to_numpy() / (2 * np.pi))
        return df["t"].to_numpy()[np.nonzero(np.diff(k))[0]]

    T = (1.8 - 1.3) / rate
    up = ballbal.Scene(balancer=standard(1.3), ramp=ballbal.Ramp(to=1.8, duration=T))
    df = ballbal.simulate(up, [0, 0, 0.3, 0.302, 0, 0, -1.3, -1.3],
                          t_eval=np.arange(0, T, 0.5), rtol=1e-6, atol=1e-8)
    om_up = 1.3 + rate * turns(df)[-1]
    assert abs(om_up - sweep.up) <= STEP
    T = (1.45 - 1.0) / rate
    m = standard(1.45)
    pb = next(e for e in ballbal.equilibria(m) if e.kind == "perfect_balance")
    y0 = np.concatenate([pb.q, np.zeros(4)])
    y0[2:4] += (1e-3, -1e-3)
    down = ballbal.Scene(balancer=m, ramp=ballbal.Ramp(to=1.0, duration=T))
    df = ballbal.simulate(down, y0, t_eval=np.arange(0, T, 0.5), rtol=1e-6, atol=1e-8)
    om_down = 1.45 - rate * turns(df)[0]
    assert abs(om_down - sweep.down) <= STEP


def test_errors():
    with pytest.raises(ParameterError) as e:
        speed_sweep(standard(), [1.2, 1.1])
    assert e.value.parameter == "speeds"
    with pytest.raises(ParameterError) as e:
        speed_sweep(standard(), [1.2, 1.3], direction="sideways")  # type: ignore[arg-type]
    assert e.value.parameter == "direction"


def test_waterfall_puts_the_main_line_at_omega_minus_ball_rate(sweep):
    # Tien's (2011) main vibration frequency on R-R is Omega - omega (section 4-4-2): at
    # every merged R-R step the largest line of the recorded spectrum sits there, within
    # two bins (record 100: bins of 2 pi / 100 in rad per time; the flat-top window's
    # main lobe is five bins wide) and forward (positive frequency).
    wf = sweep.waterfall()
    assert set(wf["step"].unique()) == set(sweep.table["step"])
    rr = sweep.table.filter(pl.col("label") == "merged_R-R")
    for r in rr.iter_rows(named=True):
        sp = wf.filter(pl.col("step") == r["step"])
        top = sp.sort("amplitude", descending=True).row(0, named=True)
        assert abs(top["frequency"] - (r["Omega"] - r["omega"])) < 2 * (2 * np.pi / 100)
