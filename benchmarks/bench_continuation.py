"""Continuation speed: points per second. Sections: ``equilibria`` (a branch of the
balls-together equilibria in eta with its events located, and a 100-point saddle-node
curve in (eta, Omega)). Run: python benchmarks/bench_continuation.py"""

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


if __name__ == "__main__":
    equilibria()
