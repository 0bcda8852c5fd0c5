"""What the Python/Rust boundary costs: ``balance_map`` of a 3-ball spring scene over
100 points, and 1000 ``periodic`` calls from a warm guess (harmonic balance only, where
the boundary is a large part of the call; 100 with Floquet and Hill as by default), and
1000 calls of the cheap validation entry (the boundary alone).

    python benchmarks/bench_boundary.py [BEFORE_PKG]

runs each measurement in a child process with the installed ballbal and, given
``BEFORE_PKG`` (a directory holding an older ``ballbal`` package, e.g.
``/work/ref/before_pkg``), again with that one first on ``PYTHONPATH``, and prints
both side by side. Best of three repetitions each, in CPU time of the process (all its
threads: on a shared machine wall-clock time mostly measures the neighbours).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time


def measure() -> dict[str, float]:
    import numpy as np

    import ballbal

    def best(f: object, repeat: int = 3) -> float:
        times = []
        for _ in range(repeat):
            t = time.process_time()
            f()  # type: ignore[operator]
            times.append(time.process_time() - t)
        return min(times)

    scene = ballbal.Scene(balancer=ballbal.Balancer(eta=(0.6, 0.6, 0.6)), springs=1e-3)
    omegas = np.linspace(1.1, 3.0, 100)
    out = {"balance_map_100": best(lambda: ballbal.balance_map(scene, Omega=omegas), 7)}
    # The boundary alone: the cheap validation entry, which builds the core model only
    # (before the typed boundary it took the flattened arguments).
    native = ballbal._native
    if hasattr(scene, "native_args"):
        args = (*scene.native_args(), scene.native_effects())
        out["validate_1000"] = best(lambda: [native.validate(*args) for _ in range(1000)])
    else:
        out["validate_1000"] = best(lambda: [native.validate(scene) for _ in range(1000)])
    b = ballbal.Balancer()
    seed = ballbal.periodic(b, "R-R", N=3,
                            options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))

    def loop(n: int, options: ballbal.PeriodicOptions) -> None:
        for _ in range(n):
            ballbal.periodic(b, "R-R", N=3, guess=seed, options=options)

    hb_only = ballbal.PeriodicOptions(floquet=ballbal.Floquet(monodromy=False, hill=False))
    out["periodic_1000_hb_only"] = best(lambda: loop(1000, hb_only))
    out["periodic_100_default"] = best(lambda: loop(100))
    return out


def run(pythonpath: str | None) -> dict[str, float]:
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    else:
        env.pop("PYTHONPATH", None)
    r = subprocess.run([sys.executable, __file__, "--child"], env=env, check=True,
                       capture_output=True, text=True)
    return json.loads(r.stdout.strip().splitlines()[-1])


def main() -> None:
    if sys.argv[1:] == ["--child"]:
        print(json.dumps(measure()))
        return
    before = run(sys.argv[1]) if len(sys.argv) > 1 else None
    after = run(None)
    print(f"CPU time{'':20s}{'before':>12s}{'after':>12s}{'ratio':>8s}")
    for k, v in after.items():
        b = before[k] if before else float("nan")
        print(f"{k:28s}{b * 1e3:10.1f}ms{v * 1e3:10.1f}ms{b / v:8.2f}")


if __name__ == "__main__":
    main()
