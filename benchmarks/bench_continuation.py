"""Continuation speed: points per second. Sections: ``equilibria`` (a branch of the
balls-together equilibria in eta with its events located, a 100-point saddle-node
curve in (eta, Omega), and the perfect balance in Omega at eta 0.505 with the default
step, where two Hopf points 0.0215 apart make the step control subdivide a step).
Run: python benchmarks/bench_continuation.py"""

from __future__ import annotations

import time

import ballbal
from ballbal._branch import Continuation
from ballbal.continuation import equilibrium_branch, equilibrium_curve


def equilibria() -> None:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.1, delta=50, Omega=1.05, eta=(0.3, 0.3))
    opts = Continuation(ds=0.005, ds_max=0.005, max_points=200, grow=1.0)
    t = time.perf_counter()
    br = equilibrium_branch(b, "eta", start="together", range=(0.2, 5.0), options=opts)
    dt = time.perf_counter() - t
    n = br.table.height
    print(f"equilibria: branch {n} points, {br.events.height} events: {dt:.3f} s "
          f"({n / dt:.0f} points/s)")
    br = equilibrium_branch(b, "eta", start="together", range=(0.2, 1.0),
                            options=Continuation(max_points=400))
    i = br.events["type"].to_list().index("fold")
    copts = Continuation(ds=0.01, ds_max=0.01, max_points=50, grow=1.0)
    t = time.perf_counter()
    c = equilibrium_curve(br, i, "Omega", range=(0.2, 5.0), options=copts)
    dt = time.perf_counter() - t
    print(f"equilibria: saddle-node curve {c.table.height} points: {dt:.3f} s "
          f"({c.table.height / dt:.0f} points/s)")
    pb = b.replace(Omega=0.9, eta=(0.505, 0.505))
    reps = 20
    t = time.perf_counter()
    for _ in range(reps):
        br = equilibrium_branch(pb, "Omega", start="perfect_balance", range=(0.8, 1.5))
    dt = (time.perf_counter() - t) / reps
    hopf = (br.events["type"] == "hopf").sum()
    print(f"equilibria: default-step branch at eta 0.505 {br.table.height} points, {hopf} Hopf: "
          f"{dt * 1e3:.2f} ms ({br.table.height / dt:.0f} points/s)")


if __name__ == "__main__":
    equilibria()
