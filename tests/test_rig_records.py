"""Measured records (ballbal.rig): reading, splitting a stepped sweep, per-step
features and transitions, on synthetic records whose steps, lines and levels are known
by construction (written here, not taken from ballbal)."""

from __future__ import annotations

import math

import numpy as np
import polars as pl
import pytest

from ballbal.exceptions import ParameterError, ParameterTypeError
from ballbal.rig import Record, Sensor, read_record

FS = 2000.0  # samples per second
SPEEDS = [400.0, 500.0, 600.0, 700.0, 800.0, 900.0, 1000.0, 900.0, 800.0, 700.0, 600.0]
HOLD, RAMP = 4.0, 0.5
# The "balls chase" band: a non-synchronous line at 520 rpm dominates from 800 rpm up,
# and on the way down until 700 rpm (hysteresis), as a rig's record would show.
CHASE_UP, CHASE_DOWN = 800.0, 700.0
WHIRL_RPM = 520.0
SYNC_AMP, WHIRL_AMP = 0.05, 0.4  # g


def _profile() -> tuple[np.ndarray, np.ndarray, list[tuple[float, float, float]]]:
    """Time, speed (rpm) and the (start, stop, speed) of each plateau."""
    t_parts, v_parts, plateaus = [], [], []
    t0 = 0.0
    for k, s in enumerate(SPEEDS):
        if k:
            n = int(RAMP * FS)
            tt = t0 + np.arange(n) / FS
            t_parts.append(tt)
            v_parts.append(np.linspace(SPEEDS[k - 1], s, n, endpoint=False))
            t0 += RAMP
        n = int(HOLD * FS)
        tt = t0 + np.arange(n) / FS
        t_parts.append(tt)
        v_parts.append(np.full(n, s))
        plateaus.append((t0, t0 + HOLD, s))
        t0 += HOLD
    return np.concatenate(t_parts), np.concatenate(v_parts), plateaus


def _chasing(plateaus: list[tuple[float, float, float]]) -> list[bool]:
    out, state, prev = [], False, None
    for _, _, s in plateaus:
        up = prev is None or s > prev
        state = s >= CHASE_UP if up else s >= CHASE_DOWN and state
        out.append(state)
        prev = s
    return out


def synthetic(noise: float = 0.0, seed: int = 0) -> tuple[dict[str, np.ndarray], list]:
    t, v, plateaus = _profile()
    phase = 2 * np.pi * np.cumsum(v / 60.0) / FS  # rotor angle
    chase = np.zeros_like(t, dtype=bool)
    for (a, b, _), c in zip(plateaus, _chasing(plateaus), strict=True):
        chase[(t >= a) & (t < b)] = c
    acc = SYNC_AMP * np.cos(phase) + WHIRL_AMP * chase * np.cos(2 * np.pi * WHIRL_RPM / 60 * t)
    acc += noise * np.random.default_rng(seed).standard_normal(t.size)
    # the accelerometer gives 100 mV per g; the record holds mV
    tacho = (np.mod(phase, 2 * np.pi) < 0.3).astype(float) * 5.0
    return {"t": t, "rpm": v, "acc_mV": 100.0 * acc, "tacho_V": tacho}, plateaus


SENSOR = {"acc_mV": Sensor(unit="g", sensitivity=100.0, recorded_unit="mV")}


def test_steps_are_the_plateaus() -> None:
    cols, plateaus = synthetic()
    rec = read_record(cols, speed="rpm", channels=SENSOR)
    st = rec.steps()
    assert st.height == len(plateaus)
    np.testing.assert_allclose(st["speed_rpm"].to_numpy(), [p[2] for p in plateaus],
                               atol=1e-9)
    # each plateau found within two averaging windows (0.05 s) of where it is, inside it
    start, stop = st["start"].to_numpy(), st["stop"].to_numpy()
    want0, want1 = np.array([p[0] for p in plateaus]), np.array([p[1] for p in plateaus])
    assert np.all((start >= want0) & (start < want0 + 0.11)), start - want0
    assert np.all((stop <= want1) & (stop > want1 - 0.11)), want1 - stop
    assert st["direction"].to_list()[:3] == ["first", "up", "up"]
    assert st["direction"].to_list()[-1] == "down"


def test_features_main_frequency_and_level() -> None:
    cols, plateaus = synthetic(noise=0.01)
    rec = read_record(cols, speed="rpm", channels=SENSOR)
    ft = rec.features(eccentricity=1e-4, natural_frequency_rpm=513.0)
    chase = _chasing(plateaus)
    assert ft["status"].to_list() == ["ok"] * len(plateaus)
    for k, (_, _, s) in enumerate(plateaus):
        f = ft["main_frequency_rpm"][k]
        want = WHIRL_RPM if chase[k] else s
        assert abs(f - want) < 3.0, (k, f, want)  # bins are 30 rpm; refined to ~1 rpm
        assert ft["synchronous"][k] == (not chase[k])
        # RMS of a cos of amplitude A is A / sqrt(2); the noise adds in quadrature
        a2 = SYNC_AMP**2 + (WHIRL_AMP**2 if chase[k] else 0.0)
        rms = math.sqrt(a2 / 2 + 0.01**2)
        assert abs(ft["rms"][k] - rms) < 0.02 * rms, (k, ft["rms"][k], rms)
        wn = 513.0 * 2 * math.pi / 60
        assert abs(ft["rms_model"][k] - ft["rms"][k] * 9.80665 / (1e-4 * wn**2)) < 1e-9
    assert set(ft["unit"].to_list()) == {"g"}


def test_transitions_up_and_down() -> None:
    cols, _ = synthetic(noise=0.01)
    rec = read_record(cols, speed="rpm", channels=SENSOR)
    tr = rec.transitions()
    assert tr.height == 2
    up = tr.filter(pl.col("direction") == "up").row(0, named=True)
    down = tr.filter(pl.col("direction") == "down").row(0, named=True)
    # up: synchronous at 700, chasing at 800; down: chasing at 700, synchronous at 600
    assert (up["from_speed_rpm"], up["to_speed_rpm"]) == (700.0, 800.0)
    assert up["to_state"] == "non_synchronous" and up["uncertainty_rpm"] == 50.0
    assert (down["from_speed_rpm"], down["to_speed_rpm"]) == (700.0, 600.0)
    assert down["to_state"] == "synchronous"


def test_speed_from_tacho_pulses() -> None:
    cols, plateaus = synthetic()
    rec = read_record(cols, tacho="tacho_V", channels=SENSOR)
    st = rec.steps()
    assert st.height == len(plateaus)
    # one pulse per turn: the speed is known to the sampling of the edges (1/FS of ~0.1 s)
    np.testing.assert_allclose(st["speed_rpm"].to_numpy(), [p[2] for p in plateaus],
                               rtol=2e-3)
    same = read_record(cols, speed="rpm", channels=SENSOR).transitions()
    np.testing.assert_allclose(rec.transitions()["speed_rpm"].to_numpy(),
                               same["speed_rpm"].to_numpy(), rtol=2e-3)


def test_files_csv_and_npz(tmp_path: object) -> None:
    from pathlib import Path

    d = Path(str(tmp_path))
    cols, plateaus = synthetic()
    pl.DataFrame(cols).write_csv(d / "r.csv")
    np.savez(d / "r.npz", **cols)
    for f in ("r.csv", "r.npz"):
        rec = read_record(d / f, speed="rpm", channels=SENSOR)
        assert isinstance(rec, Record) and rec.steps().height == len(plateaus)
        assert "Record(" in repr(rec) and "<table>" in rec._repr_html_()


def _same_steps(rec: Record, cols: dict[str, np.ndarray], plateaus: list) -> None:
    st = rec.steps()
    assert st.height == len(plateaus)
    assert np.allclose(st["speed_rpm"], [p[2] for p in plateaus], rtol=1e-9)
    assert np.array_equal(rec.channels["acc_mV"] if "acc_mV" in rec.channels
                          else rec.channels["rig/acc_mV"], cols["acc_mV"] / 100.0)


def test_files_matlab(tmp_path: object) -> None:
    from pathlib import Path

    from scipy.io import savemat

    d = Path(str(tmp_path))
    cols, plateaus = synthetic()
    savemat(d / "r.mat", cols | {"note": "rig 1", "grid": np.ones((3, 3))})
    rec = read_record(d / "r.mat", speed="rpm", channels=SENSOR)
    _same_steps(rec, cols, plateaus)
    # the 2-D variable and the text are not columns
    with pytest.raises(ParameterError) as e:
        read_record(d / "r.mat", speed="grid", channels=SENSOR)
    assert e.value.parameter == "speed"


def test_files_hdf5(tmp_path: object) -> None:
    from pathlib import Path

    h5py = pytest.importorskip("h5py")
    d = Path(str(tmp_path))
    cols, plateaus = synthetic()
    with h5py.File(d / "r.h5", "w") as f:
        g = f.create_group("rig")
        for k, v in cols.items():
            g.create_dataset(k, data=v)
    rec = read_record(d / "r.h5", time="rig/t", speed="rig/rpm",
                      channels={"rig/acc_mV": SENSOR["acc_mV"]})
    _same_steps(rec, cols, plateaus)


def test_files_tdms(tmp_path: object) -> None:
    from pathlib import Path

    nptdms = pytest.importorskip("nptdms")
    d = Path(str(tmp_path))
    cols, plateaus = synthetic()
    with nptdms.TdmsWriter(d / "r.tdms") as w:
        w.write_segment([nptdms.ChannelObject("rig", k, v) for k, v in cols.items()])
    rec = read_record(d / "r.tdms", speed="rpm", channels=SENSOR)
    _same_steps(rec, cols, plateaus)


def test_unknown_file_type_is_named(tmp_path: object) -> None:
    from pathlib import Path

    f = Path(str(tmp_path)) / "r.xlsx"
    f.write_bytes(b"x")
    with pytest.raises(ParameterError) as e:
        read_record(f, speed="rpm")
    assert e.value.parameter == "source" and ".tdms" in str(e.value)


def test_short_steps_are_flagged_not_fitted() -> None:
    cols, _ = synthetic()
    rec = read_record(cols, speed="rpm", channels=SENSOR)
    ft = rec.features(min_revolutions=100)  # 2 s settled at 400 rpm is ~13 turns
    assert ft["status"][0] == "too_short" and ft["main_frequency_rpm"][0] is None
    assert ft["status"][-1] == "too_short"  # 600 rpm: 20 turns


def test_bad_records_name_the_column() -> None:
    cols, _ = synthetic()
    with pytest.raises(ParameterError) as e:
        read_record(cols, channels=SENSOR)
    assert e.value.parameter == "speed"
    bad = dict(cols, t=cols["t"].copy())
    bad["t"][100] = bad["t"][99]
    with pytest.raises(ParameterError) as e:
        read_record(bad, speed="rpm", channels=SENSOR)
    assert e.value.parameter == "t" and "increase" in str(e.value)
    nan = dict(cols, acc_mV=cols["acc_mV"].copy())
    nan["acc_mV"][5] = np.nan
    with pytest.raises(ParameterError) as e:
        read_record(nan, speed="rpm", channels=SENSOR)
    assert e.value.parameter == "acc_mV"
    short = dict(cols, acc_mV=cols["acc_mV"][:-3])
    with pytest.raises(ParameterError) as e:
        read_record(short, speed="rpm", channels=SENSOR)
    assert e.value.parameter == "acc_mV" and "samples" in str(e.value)
    with pytest.raises(ParameterError) as e:
        read_record(cols, speed="nope", channels=SENSOR)
    assert e.value.parameter == "speed"
    with pytest.raises(ParameterError) as e:
        Sensor(unit="furlong")
    assert e.value.parameter == "unit"
    with pytest.raises(ParameterError) as e:
        Sensor(sensitivity=0.0)
    assert e.value.parameter == "sensitivity"
    with pytest.raises(ParameterTypeError):
        read_record(cols, speed="rpm", channels={"acc_mV": "g"})  # type: ignore[dict-item]
    with pytest.raises(ParameterError) as e:
        read_record({"t": cols["t"], "rpm": cols["rpm"], "tacho_V": np.zeros(cols["t"].size)},
                    tacho="tacho_V")
    assert e.value.parameter == "tacho"


@pytest.mark.parametrize(("module", "suffix", "extra"), [("h5py", "r.h5", "hdf5"),
                                                          ("nptdms", "r.tdms", "tdms")])
def test_missing_reader_names_its_extra(tmp_path: object, monkeypatch: pytest.MonkeyPatch,
                                        module: str, suffix: str, extra: str) -> None:
    import sys
    from pathlib import Path

    f = Path(str(tmp_path)) / suffix
    f.write_bytes(b"x")
    monkeypatch.setitem(sys.modules, module, None)  # import fails as if not installed
    with pytest.raises(ImportError, match=rf"ballbal\[{extra}\]"):
        read_record(f, speed="rpm")
