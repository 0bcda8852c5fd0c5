"""What checking an object when it is made costs: the native check each constructor
runs (the core's own checks), timed alone per object, and the whole constructor beside
it. Issue 32 asks for under 5 us per object.

    python benchmarks/bench_validation.py
"""

from __future__ import annotations

import timeit
from collections.abc import Callable
from typing import Any

import ballbal
from ballbal import _native
from ballbal._branch import Continuation
from ballbal.basins import BasinOptions
from ballbal.options import Floquet, GuessSearch, HarmonicBalance, PeriodicOptions, ScanOptions


def _us(f: Callable[[], Any], n: int = 20000) -> float:
    """Best of five runs of ``n`` calls, microseconds per call."""
    return min(timeit.repeat(f, number=n, repeat=5)) / n * 1e6


def main() -> None:
    b = ballbal.Balancer()
    s = ballbal.Scene(springs=0.5)
    rows: list[tuple[str, Callable[[], Any], Callable[[], Any]]] = [
        ("Balancer", lambda: _native.validate_balancer(b), ballbal.Balancer),
        ("Scene (springs)", lambda: _native.validate(s), lambda: ballbal.Scene(springs=0.5)),
        ("HarmonicBalance", lambda: _native.validate_harmonic_balance(HB), HarmonicBalance),
        ("Floquet", lambda: _native.validate_floquet(FQ), Floquet),
        ("GuessSearch", lambda: _native.validate_guess(GS), GuessSearch),
        ("PeriodicOptions", lambda: _native.validate_periodic_options(PO),
         lambda: PeriodicOptions(HB, FQ, GS)),
        ("ScanOptions", lambda: _native.validate_periodic_options(SO),
         lambda: ScanOptions(HB, FQ, GS)),
        ("Continuation", lambda: _native.validate_continuation(CO), Continuation),
        ("BasinOptions", lambda: _native.validate_basin_options(BO), BasinOptions),
    ]
    print(f"{'object':<18}{'check [us]':>12}{'constructor [us]':>18}")
    worst = 0.0
    for name, check, make in rows:
        c = _us(check)
        worst = max(worst, c)
        print(f"{name:<18}{c:>12.2f}{_us(make, 5000):>18.2f}")
    print(f"largest check: {worst:.2f} us per object (target < 5 us)")


HB, FQ, GS = HarmonicBalance(), Floquet(), GuessSearch()
PO, SO = PeriodicOptions(), ScanOptions()
CO, BO = Continuation(), BasinOptions()

if __name__ == "__main__":
    main()
