"""Calibration (ballbal.calibrate) recovers model parameters from synthetic stepped-sweep
records made independently: scipy's DOP853 on the model's equations written in
tests/reference.py, the ground-frame acceleration formed here, sensor noise added; the
95 % intervals are checked for coverage over noise draws and the estimates for bias."""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.calibration import calibrate
from ballbal.exceptions import ParameterError
from ballbal.rig import Sensor, read_record

from reference import rhs, rhs_many

FN = 513.0  # rpm, the thesis rig's natural frequency
WN = FN * 2 * math.pi / 60
TRUE = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50.0, Omega=1.0, eta=(1.0, 1.0))
OMEGAS = (1.0, 1.05, 1.1, 1.15, 1.2, 1.25)
SETTLE, RECORD, DT = 500.0, 1300.0, 0.05  # model time units
NOISE = 1.0  # the main line's acceleration amplitude is 1.6-3.2


@cache
def clean_sweep() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), speed (rpm), ground-frame acceleration X'' (in e w_n^2) and the rotor
    angle, step after step, each step settled from the previous step's end state (the
    first from the balls turning slowly against the disk, which the chasing motion
    attracts)."""
    n = 2
    s = np.array([0.0, 0.0, 0.0, 0.05, 0.0, 0.0, -0.07, -0.07])
    ts, rpm, acc, ang = [], [], [], []
    t_off = 0.0
    for Om in OMEGAS:
        b = TRUE.replace(Omega=Om)
        s = solve_ivp(lambda t, y, b=b: rhs(b, t, y), (0, SETTLE), s, method="DOP853",
                      rtol=1e-9, atol=1e-11).y[:, -1]
        grid = np.arange(0.0, RECORD, DT)
        r = solve_ivp(lambda t, y, b=b: rhs(b, t, y), (0, RECORD), s, method="DOP853",
                      rtol=1e-9, atol=1e-11, t_eval=grid)
        Y = r.y
        dd = rhs_many(b, 0.0, Y)[n + 2 : n + 4]
        x, y, vx, vy = Y[0], Y[1], Y[n + 2], Y[n + 3]
        # Z'' = e^{i Om t} ((x'' + i y'') + 2 i Om (x' + i y') - Om^2 (x + i y))
        Z2 = np.exp(1j * Om * grid) * ((dd[0] + 1j * dd[1]) + 2j * Om * (vx + 1j * vy)
                                       - Om**2 * (x + 1j * y))
        ts.append(t_off + grid / WN)
        rpm.append(np.full(grid.size, Om * FN))
        acc.append(Z2.real)
        ang.append(Om * grid)
        t_off += grid.size * DT / WN
        s = r.y[:, -1]
    return np.concatenate(ts), np.concatenate(rpm), np.concatenate(acc), np.concatenate(ang)


def noisy(seed: int) -> dict[str, np.ndarray]:
    t, v, a, ang = clean_sweep()
    noise = NOISE * np.random.default_rng(seed).standard_normal(t.size)
    return {"t": t, "rpm": v, "acc": a + noise, "tacho": (np.mod(ang, 2 * np.pi) < 0.4) * 5.0}


SENSOR = {"acc": Sensor(unit="m/s^2")}
STEPS = {"settle": 0.05, "min_duration": 5.0}


def test_the_synthetic_record_is_the_chasing_motion() -> None:
    rec = read_record(noisy(0), speed="rpm", channels=SENSOR)
    ft = rec.features(**STEPS)
    assert ft.height == len(OMEGAS) and ft["status"].to_list() == ["ok"] * len(OMEGAS)
    assert not any(ft["synchronous"].to_list())  # the balls chase at every step


def test_zeta_b_intervals_cover_the_truth_over_noise_draws() -> None:
    start = TRUE.replace(zeta_b=0.08)
    est, covered, se = [], 0, []
    for seed in range(20):
        ft = read_record(noisy(seed), speed="rpm", channels=SENSOR).features(**STEPS)
        fit = calibrate(start, ft, ["zeta_b"], natural_frequency_rpm=FN)
        row = fit.estimates.row(0, named=True)
        assert row["determined"], fit
        est.append(row["value"])
        se.append(row["std_error"])
        covered += row["ci_low"] <= TRUE.zeta_b <= row["ci_high"]
    est_a = np.array(est)
    assert covered >= 17, (covered, est, se)
    # unbiased within the spread of the 20 estimates
    assert abs(est_a.mean() - TRUE.zeta_b) < 3 * est_a.std(ddof=1) / math.sqrt(20), est
    # the quoted errors are the scatter's size (within a factor of two)
    assert 0.5 < np.mean(se) / est_a.std(ddof=1) < 2.0, (se, est)


SCALE = 2.5  # the synthetic sensor's units per e w_n^2 (a rig's mV per model unit)


def scaled(seed: int) -> dict[str, np.ndarray]:
    """The sweep as a sensor of scale SCALE records it, with unit noise."""
    t, v, a, ang = clean_sweep()
    noise = NOISE * np.random.default_rng(1000 + seed).standard_normal(t.size)
    return {"t": t, "rpm": v, "acc": SCALE * a + noise,
            "tacho": (np.mod(ang, 2 * np.pi) < 0.4) * 5.0}


def test_main_amplitude_is_the_simulated_lines() -> None:
    """The features' main-line amplitude against the simulated signal's, found here by
    a least-squares fit of a cosine at the main frequency to the noise-free record."""
    t, v, a, _ = clean_sweep()
    ft = read_record({"t": t, "rpm": v, "acc": a}, speed="rpm",
                     channels=SENSOR).features(**STEPS)
    for row in ft.iter_rows(named=True):
        k = (np.abs(v - row["speed_rpm"]) < 1e-9)
        tk, ak = t[k], a[k]
        keep = tk >= tk[0] + STEPS["settle"] * (tk[-1] - tk[0])
        w = 2 * math.pi * row["main_frequency_rpm"] / 60
        basis = np.column_stack([np.cos(w * tk[keep]), np.sin(w * tk[keep]),
                                 np.ones(keep.sum())])
        c = np.linalg.lstsq(basis, ak[keep], rcond=None)[0]
        # other lines leak into a plain fit: 2 % of the main line
        assert row["main_amplitude"] == pytest.approx(math.hypot(c[0], c[1]), rel=0.02)


def test_level_and_sensor_scale_intervals_cover_the_truth() -> None:
    """zeta_b and the sensor scale from the main frequency and the main line's
    amplitude together, over 20 noise draws."""
    start = TRUE.replace(zeta_b=0.08)
    est, se, covered = [], [], np.zeros(2, dtype=int)
    for seed in range(20):
        ft = read_record(scaled(seed), speed="rpm", channels=SENSOR).features(**STEPS)
        fit = calibrate(start, ft, ["zeta_b", "sensor_scale"], natural_frequency_rpm=FN,
                        fit=("main_frequency", "main_amplitude"))
        e = fit.estimates
        assert e["determined"].all() and e["confounded_with"].is_null().all(), fit
        est.append(e["value"].to_numpy())
        se.append(e["std_error"].to_numpy())
        covered += ((e["ci_low"].to_numpy() <= (TRUE.zeta_b, SCALE))
                    & ((TRUE.zeta_b, SCALE) <= e["ci_high"].to_numpy()))
    est_a, se_a = np.array(est), np.array(se)
    assert (covered >= 17).all(), (covered, est_a, se_a)
    spread = est_a.std(axis=0, ddof=1)
    assert (np.abs(est_a.mean(axis=0) - (TRUE.zeta_b, SCALE))
            < 3 * spread / math.sqrt(20)).all(), est_a
    assert (0.5 < se_a.mean(axis=0) / spread).all() and (se_a.mean(axis=0) / spread
                                                         < 2.0).all(), (se_a, spread)
    # the model's amplitudes times the fitted scale against the measured, per step
    amp = fit.residuals.filter(fit.residuals["quantity"] == "main_amplitude")
    assert amp.height == len(OMEGAS)
    assert np.all(np.abs(amp["residual"].to_numpy()) < 0.05 * amp["measured"].to_numpy())


def test_sensor_scale_refused_without_amplitudes() -> None:
    ft = read_record(scaled(0), speed="rpm", channels=SENSOR).features(**STEPS)
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["zeta_b", "sensor_scale"], natural_frequency_rpm=FN)
    assert e.value.parameter == "free"
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["zeta_b"], natural_frequency_rpm=FN, fit=("main_amplitude",))
    assert e.value.parameter == "sensor_scale"
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["zeta_b"], natural_frequency_rpm=FN, fit=("level",))
    assert e.value.parameter == "fit"


def test_calibration_from_tacho_pulses() -> None:
    rec = read_record(noisy(100), tacho="tacho", channels=SENSOR)
    ft = rec.features(**STEPS)
    fit = calibrate(TRUE.replace(zeta_b=0.13), ft, ["zeta_b"], natural_frequency_rpm=FN)
    row = fit.estimates.row(0, named=True)
    assert row["ci_low"] <= TRUE.zeta_b <= row["ci_high"], fit
    assert "zeta_b" in repr(fit) and "<table>" in fit._repr_html_()


def test_calibration_refuses_what_it_cannot_fit() -> None:
    ft = read_record(noisy(0), speed="rpm", channels=SENSOR).features(**STEPS)
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["Omega"], natural_frequency_rpm=FN)
    assert e.value.parameter == "free"
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["zeta_b", "zeta_b"], natural_frequency_rpm=FN)
    assert e.value.parameter == "free"
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft.head(1), ["zeta_b"], natural_frequency_rpm=FN)
    assert e.value.parameter == "features"
    with pytest.raises(ParameterError) as e:
        calibrate(TRUE, ft, ["zeta_b"], natural_frequency_rpm=-1.0)
    assert e.value.parameter == "natural_frequency_rpm"


# --- the transition speed: where a sweep up leaves the chasing motion -----------------

BAND = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.16, delta=50.0, Omega=1.1, eta=(0.66, 0.66))


@cache
def sweep_up() -> list[tuple[float, bool]]:
    """A sweep up simulated here (DOP853 on tests/reference.py), the state carried from
    step to step as a rig carries it (the ground-frame state is continuous: x' -= D y,
    y' += D x, b' += D for a speed step D = Omega_before - Omega_after): (Omega, chasing)
    per step, chasing when the balls still turn against the disk at the step's end."""
    n = 2
    s = np.array([0.0, 0.0, 0.0, 0.05, 0.0, 0.0, -0.1, -0.1])
    out, prev = [], None
    for Om in (1.10, 1.12, 1.14, 1.16, 1.18):
        if prev is not None:
            D = prev - Om
            s = s.copy()
            s[n + 2] -= D * s[1]
            s[n + 3] += D * s[0]
            s[n + 4 :] += D
        b = BAND.replace(Omega=Om)
        r = solve_ivp(lambda t, y, b=b: rhs(b, t, y), (0, 3000.0), s, method="DOP853",
                      rtol=1e-8, atol=1e-10, dense_output=True)
        s = r.y[:, -1]
        tail = r.sol(np.linspace(2500.0, 3000.0, 2001))
        chasing = bool(np.abs(tail[n + 4 :].mean(axis=1)).max() > 1e-3)
        out.append((Om, chasing))
        prev = Om
    return out


def test_band_end_is_where_a_simulated_sweep_stops_chasing() -> None:
    from ballbal.calibration import calibrate_transition, stable_band_end

    steps = sweep_up()
    chasing = [c for _, c in steps]
    # the simulated sweep chases, then balances, once
    k = chasing.index(False)
    assert all(chasing[:k]) and not any(chasing[k:]), steps
    om_lo, om_hi = steps[k - 1][0], steps[k][0]
    end = stable_band_end(BAND)
    assert end is not None and om_lo <= end < om_hi, (end, steps)
    # Calibrated from that transition (the midpoint, half a step either side), zeta_b
    # holds the simulated model's value.
    tr = calibrate_transition(BAND.replace(zeta_b=0.05), 0.5 * (om_lo + om_hi) * FN,
                              natural_frequency_rpm=FN, uncertainty_rpm=0.5 * (om_hi - om_lo) * FN,
                              bracket=(0.05, 0.4))
    assert tr.status == "ok" and tr.low is not None and tr.high is not None, tr
    assert tr.low <= BAND.zeta_b <= tr.high, tr
