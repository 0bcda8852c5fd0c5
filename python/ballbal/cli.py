"""Command line: ``ballbal run`` solves the thesis' standard case; ``ballbal periodic``
and ``ballbal equilibria`` take parameters."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from .analysis import equilibria, periodic
from .model import Balancer


def _balancer(a: argparse.Namespace) -> Balancer:
    eta = a.eta if len(a.eta) > 1 else a.eta * a.balls
    return Balancer(mu=a.mu, zeta=a.zeta, zeta_b=a.zeta_b, delta=a.delta, Omega=a.Omega, eta=eta)


def _params(p: argparse.ArgumentParser) -> None:
    p.add_argument("--mu", type=float, default=0.2)
    p.add_argument("--zeta", type=float, default=0.05)
    p.add_argument("--zeta-b", dest="zeta_b", type=float, default=0.05)
    p.add_argument("--delta", type=float, default=50.0)
    p.add_argument("--Omega", type=float, default=1.2)
    p.add_argument("--eta", type=float, nargs="+", default=[1.0])
    p.add_argument("--balls", type=int, default=2, help="number of equal balls if one eta")


def _print_equilibria(b: Balancer) -> None:
    print(f"Equilibria at Omega={b.Omega}, eta={list(b.eta)}:")
    for e in equilibria(b):
        rh = ""
        if e.routh_hurwitz is not None:
            rh = f", Routh-Hurwitz {'stable' if e.routh_hurwitz else 'not stable'}"
        q = ", ".join(f"{v:+.4f}" for v in e.q)
        print(f"  {e.kind:16s} q=({q})  {e.stability} (index {e.stability_index:+.4g}{rh})")


def _print_periodic(b: Balancer, pattern: str, N: int) -> None:
    t = time.perf_counter()
    s = periodic(b, pattern, N=N)
    dt = time.perf_counter() - t
    if not s.converged:
        print(f"  {pattern} N={N}: {s.status} after {s.iterations} iterations")
        return
    mods = " ".join(f"{m:.4f}" for m in np.sort(np.abs(s.multipliers))[::-1])
    print(f"  {s.type} N={N}: omega={s.omega:.6f} (period {s.period:.3f}), {s.stability}; "
          f"|multipliers| {mods}; trivial error {s.trivial_error:.1e}; residual "
          f"{s.residual:.1e}; orbit closure by simulation {s.verify():.1e}; {dt * 1e3:.1f} ms")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="ballbal", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("run", help="the thesis' standard case: equilibria and R-R solution")
    pp = sub.add_parser("periodic", help="a periodic solution with Floquet stability")
    _params(pp)
    pp.add_argument("--pattern", default="R-R")
    pp.add_argument("--N", type=int, default=3)
    pe = sub.add_parser("equilibria", help="all equilibria with stability")
    _params(pe)
    a = ap.parse_args(argv)
    try:
        if a.cmd == "run":
            b = Balancer()
            print(f"ballbal: thesis standard case {b}")
            _print_equilibria(b)
            print("Periodic solutions (balls merged, rotating):")
            for N in (3, 8):
                _print_periodic(b, "R-R", N)
        elif a.cmd == "periodic":
            _print_periodic(_balancer(a), a.pattern, a.N)
        else:
            _print_equilibria(_balancer(a))
    except ValueError as e:
        print(f"ballbal: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
