"""What reading and reducing a measured record costs: a stepped sweep of 10^6 samples
(20 steps, 2 kHz, one accelerometer and a tachometer) written as CSV and NPZ, read,
split into its steps and reduced to per-step features. Issue 35 asks for reading and
splitting a 10^6-sample record in under 1 s.

    python benchmarks/bench_rig.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
import polars as pl

from ballbal.rig import Sensor, read_record

FS, HOLD, RAMP = 2000.0, 24.0, 1.0


def record(n_steps: int = 20) -> dict[str, np.ndarray]:
    speeds = np.linspace(300.0, 1250.0, n_steps)
    parts = []
    for k, s in enumerate(speeds):
        if k:
            parts.append(np.linspace(speeds[k - 1], s, int(RAMP * FS), endpoint=False))
        parts.append(np.full(int(HOLD * FS), s))
    v = np.concatenate(parts)
    t = np.arange(v.size) / FS
    phase = 2 * np.pi * np.cumsum(v / 60.0) / FS
    rng = np.random.default_rng(1)
    acc = 0.05 * np.cos(phase) + 0.01 * rng.standard_normal(t.size)
    tacho = (np.mod(phase, 2 * np.pi) < 0.3) * 5.0
    return {"t": t, "rpm": v, "acc": 100.0 * acc, "tacho": tacho}


def _best(f: object, repeat: int = 3) -> float:
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()  # type: ignore[operator]
        out.append(time.perf_counter() - t0)
    return min(out)


def main() -> None:
    cols = record()
    n = cols["t"].size
    sensor = {"acc": Sensor(unit="g", sensitivity=100.0, recorded_unit="mV")}
    with tempfile.TemporaryDirectory() as d:
        csv, npz = Path(d) / "r.csv", Path(d) / "r.npz"
        pl.DataFrame(cols).write_csv(csv)
        np.savez(npz, **cols)
        print(f"record: {n} samples, 20 steps (best of 3, seconds)")
        print(f"{'what':44s} {'s':>8s}")
        for what, f in [
            ("read .npz + split (speed column)",
             lambda: read_record(npz, speed="rpm", channels=sensor).steps()),
            ("read .csv + split (speed column)",
             lambda: read_record(csv, speed="rpm", channels=sensor).steps()),
            ("read .npz + split (tachometer)",
             lambda: read_record(npz, tacho="tacho", channels=sensor).steps()),
            ("read .npz + split + features (20 spectra)",
             lambda: read_record(npz, speed="rpm", channels=sensor).features()),
        ]:
            print(f"{what:44s} {_best(f):8.3f}")


if __name__ == "__main__":
    main()
