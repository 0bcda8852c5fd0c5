"""Census of attractors: does a default ``ballbal.scan`` list every stable motion that
simulation reaches? (issue 31)

What it measures: at random parameter points (mu 0.05-0.4, zeta and zeta_b 0.01-0.2,
delta 10-100, Omega 0.5-3, eta 0.2-2; two equal balls, two unequal balls, three balls)
and at a handful of points near stability changes named in issue 31, the attractors that
simulation from random starts settles on, and whether ballbal lists them.

How:

* Simulation is independent of ballbal: scipy's ``solve_ivp(method="DOP853")`` on the
  equations of ``tests/reference.py`` (the repository's ``tests/`` directory is put on
  ``sys.path`` to import it). The integrator calls a transcription of
  ``reference.rhs`` that solves its mass matrix by block elimination in plain floats
  (about ten times faster than ``numpy.linalg.solve`` on a 4 x 4); at every point it is
  checked against ``reference.rhs`` itself at random states (``--reference-rhs`` uses
  ``reference.rhs`` throughout). State ``[x, y, b_1..b_n, x', y', b_1'..b_n']``, rotating
  frame, dimensionless time.
* Starts: disk displaced up to 0.5, balls anywhere on the track; every other start at
  rest in the ground frame (the rig's start), the others with random disk velocities
  and ball rates from ``-1.2 Omega`` to ``0.2 Omega`` relative to the disk.
* Each start is integrated for ``--settle`` time units, then window after window of
  ``--window`` units (up to ``--t-max``). In a window: an *equilibrium* if every velocity
  stays below 1e-7 (the *perfect balance* if the disk centre is also at the axis); else
  the section is the first drifting ball's angle crossing a fixed level modulo 2 pi (or,
  with no ball drifting by a full turn, ``x' = 0`` downwards) and the motion is
  *periodic* when the section state repeats after ``k <= 4`` crossings. Its period ``T``
  gives ``omega = 2 pi / T`` and each ball's winding (whole turns relative to the disk
  per period); the pattern has ``R`` for a ball with non-zero winding, else ``O``,
  joined with ``-`` in ballbal's ball order. This is ballbal's convention
  (``PeriodicSolution``: ``q_j = ... + w_j omega t``, ``w_j = -1`` for a rotating ball,
  ``omega`` the orbit's frequency), so a ballbal R-R orbit has windings ``(-1, -1)``.
  A start is settled when the section returns to 1e-6 (relative to the largest
  velocity), or when two consecutive windows agree (same pattern and windings, ``omega``
  to 1e-5 relative, velocity amplitude to 1e-3) with returns within 1e-3 and shrinking
  by at least 10 %; otherwise it is *unsettled* (quasi-periodic, chaotic, near-neutral
  or slower than ``--t-max``): reported, never counted as a miss. A motion too slow
  for its window (fewer than 10 section crossings: a rotating branch near its
  infinite-period end, periods of thousands) gets doubling windows up to ``--t-slow``
  (cheap: the integrator's steps are long there).
* ballbal is then run as a user would, at default options and with every pattern of the
  ball count and the period doubling of each (``"R-R[-2,-2]"``, ``"O-R[0,-2]"``: every
  rotating ball two turns per period), on a 1-point grid at the point and, separately,
  on a small grid holding it (5 Omega values 0.05 apart times 3 eta values 0.1 apart;
  ``eta1`` for unequal balls). A periodic attractor is *listed* by a scan when a row
  at the point has its type (pattern, with the windings for one that turns more than
  once per period, up to relabelling identical balls), ``stability == "stable"`` and
  ``|omega_row - omega_sim| <= max(3 trivial_error, 1e-3 omega)`` plus the simulation's
  own uncertainty: issue 31 measured the scan's frequency error below 1.36
  ``trivial_error``, and 1e-3 is far below the spacing of coexisting orbits of one
  pattern. The perfect balance is listed when the row's ``pb_stable`` is true; another
  stable equilibrium, which scans have no rows for, when ``ballbal.equilibria()`` lists it
  as stable at the same disk position (1e-4).
* *Missed*: an attractor simulation settled on that the scan (1-point or small grid)
  does not list as above. For each missed orbit the benchmark gives its leading
  non-trivial multiplier modulus twice: independently (monodromy by central differences
  of the DOP853 flow over one period) and by ``ballbal.periodic()`` started from the
  simulated orbit's Fourier series (N = 3 and ``N="auto"``). Stable scan rows that no
  start reached are printed for information (basins can be small). ``returns`` is the
  section's relative return distance in the last window (and the window before):
  shrinking means converging; one that stays near 1e-7 marks an orbit within about 1e-5
  of a stability change (or a thin torus), where 8000 time units cannot tell.

Run (from the repository root, with ballbal importable)::

    python benchmarks/bench_census.py --quick
    python benchmarks/bench_census.py --points 30 --starts 16 --seed 31 [--jobs 2]

``--points`` random points besides the issue's points (``--no-issue-points`` drops
those; ``--only issue-verdict,random-3]`` keeps the points whose labels match). The seed
is printed; the same seed gives the same points and starts. About 1 s of CPU per start
(a 48-point x 24-start census: 15 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import itertools
import math
import multiprocessing as mp
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import polars as pl
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import ballbal  # noqa: E402

from reference import rhs as reference_rhs  # noqa: E402

TWO_PI = 2.0 * math.pi
#: Every velocity below this over a window: an equilibrium.
EQ_SPEED = 1e-7
#: Section returns this close: a converged periodic orbit.
RETURN_TIGHT = 1e-6
#: Section returns this close in two agreeing windows: a (slowly converging) periodic orbit.
RETURN_LOOSE = 1e-3
#: Most section crossings per period looked for.
K_MAX = 4
#: The disk centre this near the axis at an equilibrium: the perfect balance.
PB_RADIUS = 1e-4


@dataclass(frozen=True)
class Point:
    """One parameter point (nondimensional, as ``ballbal.Balancer``)."""

    label: str
    mu: float
    zeta: float
    zeta_b: float
    delta: float
    Omega: float
    eta: tuple[float, ...]

    @property
    def n(self) -> int:
        """Number of balls."""
        return len(self.eta)

    def balancer(self, **changes: Any) -> ballbal.Balancer:
        """The point as a ``ballbal.Balancer`` (with fields changed)."""
        b = ballbal.Balancer(mu=self.mu, zeta=self.zeta, zeta_b=self.zeta_b,
                             delta=self.delta, Omega=self.Omega, eta=self.eta)
        return b.replace(**changes) if changes else b

    def plain(self) -> SimpleNamespace:
        """The parameters as a plain namespace for ``reference.rhs`` (no ballbal object)."""
        return SimpleNamespace(mu=self.mu, zeta=self.zeta, zeta_b=self.zeta_b,
                               delta=self.delta, Omega=self.Omega, eta=self.eta)

    def describe(self) -> str:
        """The point as a ``Balancer(...)`` call."""
        eta = ", ".join(f"{e:.4g}" for e in self.eta)
        return (f"Balancer(mu={self.mu:.4g}, zeta={self.zeta:.4g}, zeta_b={self.zeta_b:.4g}, "
                f"delta={self.delta:.4g}, Omega={self.Omega:.11g}, eta=({eta}))")

    def relabellings(self) -> list[tuple[int, ...]]:
        """Every permutation of the balls that only swaps identical balls."""
        perms = []
        for p in itertools.permutations(range(self.n)):
            if all(self.eta[p[i]] == self.eta[i] for i in range(self.n)):
                perms.append(p)
        return perms


def make_rhs(p: Point) -> Callable[[float, np.ndarray], np.ndarray]:
    """``reference.rhs`` transcribed to plain floats: the ball rows of ``M a = -g`` give
    ``a_b = (h + S a_x - C a_y) / delta``, which leaves a 2 x 2 system for ``a_x, a_y``."""
    n = p.n
    m = [p.mu * e for e in p.eta]
    om, z, dl, mu = p.Omega, p.zeta, p.delta, p.mu
    om2 = om * om
    zb2dl = 2.0 * p.zeta_b * dl

    def f(t: float, s: np.ndarray) -> np.ndarray:
        v = s.tolist()
        x, y = v[0], v[1]
        vx, vy = v[n + 2], v[n + 3]
        g0 = 2 * z * vx - 2 * om * vy + (1 - om2) * x - 2 * z * om * y - mu * om2
        g1 = 2 * z * vy + 2 * om * vx + (1 - om2) * y + 2 * z * om * x
        a11 = a22 = 1.0
        a12 = 0.0
        r1, r2 = 0.0, 0.0
        ss, cc, hh = [], [], []
        for i in range(n):
            b, vb, mi = v[2 + i], v[n + 4 + i], m[i]
            sn, cs = math.sin(b), math.cos(b)
            w2 = (om + vb) ** 2
            g0 -= mi * w2 * cs
            g1 -= mi * w2 * sn
            h = -(2 * om * (cs * vx + sn * vy) + zb2dl * vb + om2 * (x * sn - y * cs))
            k = mi / dl
            a11 -= k * sn * sn
            a22 -= k * cs * cs
            a12 += k * sn * cs
            r1 += k * sn * h
            r2 -= k * cs * h
            ss.append(sn)
            cc.append(cs)
            hh.append(h)
        r1 -= g0
        r2 -= g1
        det = a11 * a22 - a12 * a12
        ax = (r1 * a22 - a12 * r2) / det
        ay = (a11 * r2 - a12 * r1) / det
        out = v[n + 2:] + [ax, ay]
        out += [(hh[i] + ss[i] * ax - cc[i] * ay) / dl for i in range(n)]
        return np.array(out)

    return f


def check_rhs(p: Point, rng: np.random.Generator) -> float:
    """Largest difference between :func:`make_rhs` and ``reference.rhs`` at random states
    (raises if above 1e-10 relative: the transcription must be the reference's)."""
    f = make_rhs(p)
    ns = p.plain()
    worst = 0.0
    for _ in range(20):
        s = np.concatenate([rng.normal(0, 0.5, 2), rng.uniform(-7, 7, p.n),
                            rng.normal(0, 1.0, 2), rng.uniform(-2 * p.Omega, p.Omega, p.n)])
        a, b = f(0.0, s), reference_rhs(ns, 0.0, s)
        worst = max(worst, float(np.max(np.abs(a - b)) / (1.0 + np.max(np.abs(b)))))
    if worst > 1e-10:
        raise RuntimeError(f"fast rhs differs from reference.rhs by {worst:.2e} at {p.label}")
    return worst


@dataclass
class Settings:
    """Simulation settings (CLI options)."""

    settle: float
    window: float
    t_max: float
    t_slow: float
    rtol: float
    atol: float
    reference_rhs: bool


@dataclass
class Outcome:
    """Where one start settled."""

    kind: str  # perfect_balance, equilibrium, periodic, unsettled, failed
    pattern: str = ""
    windings: tuple[int, ...] = ()
    omega: float = math.nan
    unc: float = 0.0  # omega's uncertainty, or an equilibrium's distance from its state
    k: int = 0
    returns: float = math.nan
    radius: float = math.nan  # mean |x + i y| over the window (tells orbits apart)
    speed: float = math.nan  # largest velocity over the window (the motion's size)
    section: np.ndarray | None = None  # the window's last section state
    prev_returns: float = math.nan  # the window before's returns (shrinking: converging)
    slow: bool = False  # too few section crossings in the window to look for a period
    q: tuple[float, ...] = ()  # equilibrium position
    t_end: float = 0.0
    seconds: float = 0.0
    coeffs: np.ndarray | None = None  # Fourier series of the orbit (ballbal's layout)
    note: str = ""


def start_state(p: Point, rng: np.random.Generator, at_rest: bool) -> np.ndarray:
    """A random start: disk displaced up to 0.5, balls anywhere on the track. ``at_rest``:
    everything at rest in the ground frame (the rig's start: ball rates ``-Omega``, ``x'
    = Omega y``, ``y' = -Omega x``); else disk velocities up to 0.5 and ball rates
    between at rest in the ground frame and beyond and a little faster than the disk
    (``-1.2 Omega .. 0.2 Omega`` relative to it)."""
    n = p.n
    xy = rng.uniform(-0.5, 0.5, 2)
    beta = rng.uniform(0, TWO_PI, n)
    if at_rest:
        v = [p.Omega * xy[1], -p.Omega * xy[0]] + [-p.Omega] * n
        return np.concatenate([xy, beta, v])
    return np.concatenate([xy, beta, rng.uniform(-0.5, 0.5, 2),
                           rng.uniform(-1.2 * p.Omega, 0.2 * p.Omega, n)])


def _wrap(d: np.ndarray) -> np.ndarray:
    return (d + math.pi) % TWO_PI - math.pi


def _section_returns(ye: np.ndarray, n: int, k: int) -> float:
    """Largest distance between section states ``k`` crossings apart (ball angles modulo
    2 pi), over the second half of the window's crossings."""
    lo = max(0, ye.shape[0] // 2 - k)
    a, b = ye[lo:-k], ye[lo + k:]
    d = b - a
    d[:, 2:2 + n] = _wrap(d[:, 2:2 + n])
    return float(np.max(np.abs(d)))


def _levels(n: int) -> list[Callable[[float, np.ndarray], float]]:
    """Section events: ball ``i``'s angle crossing ``2 pi j`` (any direction: the ``sin``
    of half the angle changes sign there; ballbal's phase condition puts its first
    rotating ball there at ``t = 0``), then ``x' = 0`` downwards."""
    evs: list[Any] = []
    for i in range(n):
        def ev(t: float, s: np.ndarray, i: int = i) -> float:
            return math.sin(0.5 * s[2 + i])
        evs.append(ev)

    def vx(t: float, s: np.ndarray) -> float:
        return float(s[n + 2])
    vx.direction = -1  # type: ignore[attr-defined]
    evs.append(vx)
    return evs


def _window(f: Callable[[float, np.ndarray], np.ndarray], p: Point, s: np.ndarray,
            t0: float, width: float, cfg: Settings,
            prev_speed: float | None) -> tuple[Outcome, np.ndarray]:
    """Integrate one window and read the motion off it (not yet a verdict)."""
    n = p.n
    sol = solve_ivp(f, (t0, t0 + width), s, method="DOP853", rtol=cfg.rtol,
                    atol=cfg.atol, events=_levels(n))
    if sol.status != 0:
        return Outcome("failed", note=sol.message), s
    y = sol.y
    end = y[:, -1]
    speed = float(np.max(np.abs(y[n + 2:])))
    radius = float(np.mean(np.hypot(y[0], y[1])))
    # Velocities decaying window to window: an equilibrium, approached at the rate
    # ``lam`` (weakly damped ball modes: time constants near 1000 are common), so the
    # state is about ``speed / lam`` from it.
    unc = 0.0
    if prev_speed is not None and speed < 1e-5 and speed < 0.7 * prev_speed:
        lam = math.log(prev_speed / speed) / width
        unc = speed / lam
    if speed < EQ_SPEED or unc:
        # Not yet at rest, the disk may still be far from the axis: the balls' residual
        # imbalance |1 + sum eta_i exp(i b_i)| tells a perfect balance then (it is at
        # least 1 - sum eta_i where none exists).
        imbalance = abs(1.0 + sum(e * complex(math.cos(b), math.sin(b))
                                  for e, b in zip(p.eta, end[2:2 + n], strict=True)))
        at_axis = (math.hypot(end[0], end[1]) < PB_RADIUS
                   or (unc > 0 and imbalance < 1e-2))
        kind = "perfect_balance" if at_axis else "equilibrium"
        q = tuple(float(v) for v in end[:n + 2])
        return Outcome(kind, q=q, radius=radius, returns=speed, speed=speed,
                       unc=unc), end
    drift = (end[2:2 + n] - s[2:2 + n]) / TWO_PI
    rotating = [i for i in range(n) if abs(drift[i]) >= 1.0]
    which = rotating[0] if rotating else n
    te, ye = sol.t_events[which], sol.y_events[which]
    best: Outcome | None = None
    for k in range(1, K_MAX + 1):
        if te.size < 2 * k + 2:
            break
        # relative to the motion's size: a decaying ripple returns to round-off too
        r = _section_returns(ye, n, k) / speed
        if r < RETURN_LOOSE:
            periods = (te.size - 1) // k
            i0 = te.size - 1 - periods * k
            T = (te[-1] - te[i0]) / periods
            w = tuple(int(round(v)) for v in (ye[i0 + k, 2:2 + n] - ye[i0, 2:2 + n]) / TWO_PI)
            pattern = "-".join("R" if wi else "O" for wi in w)
            best = Outcome("periodic", pattern=pattern, windings=w, omega=TWO_PI / T, k=k,
                           returns=r, radius=radius, speed=speed, section=ye[-1].copy())
            break
    if best is None:
        pattern = "-".join("R" if abs(d) >= 1.0 else "O" for d in drift)
        rates = ", ".join(f"{TWO_PI * d / width:+.4f}" for d in drift)
        best = Outcome("unsettled", pattern=pattern, radius=radius, speed=speed,
                       slow=te.size < 2 * K_MAX + 2,
                       note=f"mean ball rates {rates}")
    return best, end


def _series(f: Callable[[float, np.ndarray], np.ndarray], p: Point, o: Outcome,
            cfg: Settings, N: int = 8) -> np.ndarray:
    """The orbit through its section state as ballbal's Fourier series: ``q_j(tau) = a_0
    + sum a_m cos(m tau) + b_m sin(m tau) + w_j tau``, rows ``[a_0, a_1, b_1, ..., a_N,
    b_N]``, in ballbal's phase (first rotating ball at angle 0 at ``tau = 0``, which the
    section state has; with no rotating ball, no ``sin tau`` in ``x``)."""
    if o.section is None:
        raise ValueError("no section state")
    n = p.n
    K = 64
    T = TWO_PI / o.omega
    t = np.linspace(0.0, T, K, endpoint=False)
    sol = solve_ivp(f, (0.0, T), o.section, method="DOP853", rtol=cfg.rtol, atol=cfg.atol,
                    t_eval=t)
    q = sol.y[:n + 2].copy()
    w = np.array([0.0, 0.0, *o.windings])
    q -= np.outer(w, TWO_PI * t / T)
    c = np.fft.rfft(q, axis=1)[:, :N + 1] / K
    c[:, 1:] *= 2
    if not any(o.windings):
        # shift time so that x has no sin(tau): q(tau + phi) multiplies c_m by e^{i m phi}
        phi = -math.atan2(c[0, 1].imag, c[0, 1].real)
        c *= np.exp(1j * phi * np.arange(N + 1))
    out = np.zeros((n + 2, 2 * N + 1))
    out[:, 0] = c[:, 0].real
    out[:, 1::2] = c[:, 1:].real
    out[:, 2::2] = -c[:, 1:].imag
    # whole turns off the ball angles (the first rotating ball then starts at 0)
    out[2:, 0] -= TWO_PI * np.round(out[2:, 0] / TWO_PI)
    return out


def simulate_start(task: tuple[Point, int, int, Settings]) -> Outcome:
    """Simulate one start to its attractor (run in a worker process)."""
    p, seed, j, cfg = task
    clock = time.process_time()
    rng = np.random.default_rng([seed, j])
    f: Callable[[float, np.ndarray], np.ndarray]
    if cfg.reference_rhs:
        ns = p.plain()

        def f(t: float, s: np.ndarray) -> np.ndarray:
            return reference_rhs(ns, t, s)
    else:
        f = make_rhs(p)
    s = start_state(p, rng, at_rest=j % 2 == 0)
    sol = solve_ivp(f, (0.0, cfg.settle), s, method="DOP853", rtol=cfg.rtol, atol=cfg.atol)
    if sol.status != 0:
        return Outcome("failed", note=sol.message, seconds=time.process_time() - clock)
    s, t = sol.y[:, -1], cfg.settle
    prev: Outcome | None = None
    result: Outcome | None = None
    width = cfg.window
    while t + width <= (cfg.t_slow if prev is not None and prev.slow else cfg.t_max) + 1e-9:
        o, s_next = _window(f, p, s, t, width, cfg, None if prev is None else prev.speed)
        t += width
        if o.slow:
            # A slow motion (a rotating branch near its infinite-period end: periods of
            # thousands) is cheap to integrate: windows double, up to --t-slow.
            width = min(2 * width, max(cfg.t_slow - t, cfg.window))
        if o.kind == "failed":
            result = o
            break
        if o.kind in ("perfect_balance", "equilibrium"):
            result = o
            break
        if o.kind == "periodic":
            agree = (prev is not None and prev.kind == "periodic"
                     and prev.pattern == o.pattern and prev.windings == o.windings
                     and abs(prev.omega - o.omega) <= 1e-5 * o.omega
                     and abs(prev.speed - o.speed) <= 1e-3 * o.speed
                     # still converging: an orbit whose returns stall is too near neutral
                     # (or a thin torus) for this window to tell
                     and o.returns < 0.9 * prev.returns)
            if o.returns < RETURN_TIGHT or agree:
                o.prev_returns = prev.returns if prev is not None else math.nan
                o.unc = (abs(prev.omega - o.omega) if prev is not None
                               and prev.kind == "periodic" else 0.0)
                o.unc = max(o.unc, 1e-8 * o.omega)
                result = o
                s = s_next
                break
        prev = o
        s = s_next
    if result is None:
        result = prev if prev is not None else Outcome("unsettled")
        if result.kind == "periodic":
            result.note = f"returns {result.returns:.1e}, windows disagree"
        result.kind = "unsettled"
    result.t_end = t
    if result.kind == "periodic":
        # The orbit's series from a section state (for periodic() on a miss).
        try:
            result.coeffs = _series(f, p, result, cfg)
        except (ValueError, RuntimeError):
            result.coeffs = None
    result.seconds = time.process_time() - clock
    return result


# --------------------------------------------------------------------------- points


def random_points(count: int, rng: np.random.Generator) -> list[Point]:
    """``count`` points over the issue's box: 40 % two equal balls, 40 % two unequal, 20 %
    three (unequal) balls."""
    pts = []
    for i in range(count):
        mu = rng.uniform(0.05, 0.4)
        zeta, zeta_b = rng.uniform(0.01, 0.2), rng.uniform(0.01, 0.2)
        delta, om = rng.uniform(10, 100), rng.uniform(0.5, 3.0)
        u = rng.uniform()
        if u < 0.4:
            eta: tuple[float, ...] = (rng.uniform(0.2, 2.0),) * 2
        elif u < 0.8:
            eta = tuple(rng.uniform(0.2, 2.0, 2))
        else:
            eta = tuple(rng.uniform(0.2, 2.0, 3))
        r = lambda v: float(np.round(v, 4))  # noqa: E731 - printable parameters
        pts.append(Point(f"random-{i}", r(mu), r(zeta), r(zeta_b), r(delta), r(om),
                         tuple(r(e) for e in eta)))
    return pts


def issue_points() -> list[Point]:
    """Points near stability changes, from issue 31."""
    th = dict(mu=0.2, zeta=0.02, zeta_b=0.1, delta=50.0)
    return [
        # Tien's (2011) stable R-O of its table 4-7 (omega 0.3047), in the first bullet's map
        Point("issue-map-1.3-0.7", th["mu"], th["zeta"], th["zeta_b"], th["delta"], 1.3,
              (0.7, 0.7)),
        # where that map's perfect balance is unstable and its scan lists no stable orbit
        # (0.9) or only unstable R-R rows (1.3, 1.4)
        Point("issue-map-0.9-1.0", th["mu"], th["zeta"], th["zeta_b"], th["delta"], 0.9,
              (1.0, 1.0)),
        Point("issue-map-1.3-1.4", th["mu"], th["zeta"], th["zeta_b"], th["delta"], 1.3,
              (1.4, 1.4)),
        Point("issue-map-1.0-1.2", th["mu"], th["zeta"], th["zeta_b"], th["delta"], 1.0,
              (1.2, 1.2)),
        # "stable" at N = 3 with |mu| 0.99998, truly 1.0000036
        Point("issue-verdict", 0.25, 0.08, 0.02, 20.0, 1.3584277344, (1.0, 1.0)),
        # unequal balls: periodic() finds a stable R-O (homotopy) that scans do not list
        Point("issue-unequal-1.7", 0.2, 0.02, 0.05, 50.0, 1.7, (0.9, 1.1)),
        Point("issue-unequal-1.8", 0.2, 0.02, 0.05, 50.0, 1.8, (0.9, 1.1)),
        # periodic(..., N=8) says no_guess; homotopy from Omega 1.2 finds the stable R-R
        Point("issue-discovery", 0.2, 0.05, 0.05, 50.0, 1.75, (1.0, 1.0)),
    ]


# --------------------------------------------------------------------------- scans


def all_patterns(n: int) -> list[str]:
    """Every rotation pattern of ``n`` balls, ballbal's ball order, and the period
    doubling of each with a rotating ball (``"R-O[-2,0]"``: every rotating ball two
    turns per period), as scan types."""
    plain = ["-".join(c) for c in itertools.product("RO", repeat=n)]
    doubled = [type_name(q, tuple(-2 if c == "R" else 0 for c in q.split("-")))
               for q in plain if "R" in q]
    return plain + doubled


def type_name(pattern: str, windings: Sequence[int]) -> str:
    """ballbal's scan type of an orbit: its pattern, with the windings in brackets when
    some ball turns more than once per period."""
    if all(abs(w) <= 1 for w in windings):
        return pattern
    return f"{pattern}[{','.join(str(w) for w in windings)}]"


def _parse_type(kind: str) -> tuple[list[str], list[int] | None]:
    """Letters and (for a wound type) windings of a scan type name."""
    pattern, _, rest = kind.partition("[")
    wind = [int(w) for w in rest.rstrip("]").split(",")] if rest else None
    return pattern.split("-"), wind


@dataclass
class ScanResult:
    """The scan rows at the point: from the 1-point grid and from the small grid."""

    one: pl.DataFrame
    grid: pl.DataFrame
    seconds: float
    grid_points: int


def scan_point(p: Point) -> ScanResult:
    """``ballbal.scan`` at default options, every pattern and its period doubling, as a
    user would call it."""
    b = p.balancer()
    pats = all_patterns(p.n)
    t = time.perf_counter()
    one = ballbal.scan(b, Omega=[p.Omega], patterns=pats)
    oms = [p.Omega + d * 0.05 for d in (-2, -1, 0, 1, 2)]
    e0 = p.eta[0]
    etas = [e for e in (e0 - 0.1, e0, e0 + 0.1) if e > 0.05]
    axis = "eta" if len(set(p.eta)) == 1 else "eta1"
    grid = ballbal.scan(b, grid={"Omega": oms, axis: etas}, patterns=pats)
    seconds = time.perf_counter() - t
    at = grid.filter((pl.col("Omega") == p.Omega) & (pl.col(axis) == e0))
    if at.height == 0:
        raise RuntimeError(f"the small grid lost the point {p.label}")
    return ScanResult(one, at, seconds, len(oms) * len(etas))


@dataclass
class Attractor:
    """Starts that settled on the same motion."""

    example: Outcome
    starts: int = 1

    @property
    def kind(self) -> str:
        return self.example.kind


def _canonical(p: Point, o: Outcome) -> tuple[str, tuple[int, ...]]:
    """Pattern and windings up to relabelling identical balls (smallest form)."""
    forms = []
    for perm in p.relabellings():
        w = tuple(o.windings[i] for i in perm)
        forms.append(("-".join("R" if x else "O" for x in w), w))
    return min(forms)


def _relabelled_types(p: Point, kind: str) -> set[str]:
    """A scan type's names under every relabelling of identical balls."""
    letters, wind = _parse_type(kind)
    out = set()
    for perm in p.relabellings():
        pattern = "-".join(letters[i] for i in perm)
        out.add(pattern if wind is None else type_name(pattern, [wind[i] for i in perm]))
    return out


def group(p: Point, outcomes: Sequence[Outcome]) -> tuple[list[Attractor], list[Outcome]]:
    """Distinct attractors (and the unsettled or failed starts)."""
    atts: list[Attractor] = []
    other: list[Outcome] = []
    for o in outcomes:
        if o.kind in ("unsettled", "failed"):
            other.append(o)
            continue
        for a in atts:
            e = a.example
            if e.kind != o.kind:
                continue
            if o.kind == "perfect_balance":
                same = True
            elif o.kind == "equilibrium":
                same = (math.hypot(e.q[0] - o.q[0], e.q[1] - o.q[1])
                        < max(1e-4, 3 * (e.unc + o.unc)))
            else:
                same = (_canonical(p, e) == _canonical(p, o)
                        and abs(e.omega - o.omega) <= 1e-4 * o.omega + 10 * (e.unc
                                                                          + o.unc))
            if same:
                a.starts += 1
                # keep the best converged example (for periodic() on a miss)
                if o.returns < e.returns:
                    a.example = o
                break
        else:
            atts.append(Attractor(o))
    return atts, other


def _tol(omega: float, trivial_error: float | None, unc: float) -> float:
    te = 0.0 if trivial_error is None or math.isnan(trivial_error) else trivial_error
    return max(3.0 * te, 1e-3 * omega) + 10.0 * unc


def listed(p: Point, a: Attractor, rows: pl.DataFrame,
           eqs: list[ballbal.Equilibrium]) -> tuple[bool, str]:
    """Whether the scan rows (and, for equilibria off the axis, ``equilibria()``) list
    the attractor; with the nearest row when they do not."""
    o = a.example
    if o.kind == "perfect_balance":
        ok = bool(rows["pb_stable"].fill_null(False).any())
        return ok, "" if ok else f"pb_exists {rows['pb_exists'][0]}, pb_stable " \
            f"{rows['pb_stable'][0]}"
    if o.kind == "equilibrium":
        near = [e for e in eqs
                if math.hypot(e.q[0] - o.q[0], e.q[1] - o.q[1]) < max(1e-4, 3 * o.unc)]
        ok = any(e.stability == "stable" for e in near)
        return ok, "" if ok else ("equilibria(): " + (", ".join(
            f"{e.kind} {e.stability}" for e in near) or "none there"))
    pats = _relabelled_types(p, type_name(o.pattern, o.windings))
    cand = rows.filter(pl.col("type").is_in(sorted(pats)) & pl.col("omega").is_not_null())
    for r in cand.iter_rows(named=True):
        if (r["stability"] == "stable"
                and abs(r["omega"] - o.omega) <= _tol(o.omega, r["trivial_error"],
                                                      o.unc)):
            return True, f"d_omega {abs(r['omega'] - o.omega):.1e}"
    if cand.height == 0:
        return False, f"no {type_name(o.pattern, o.windings)} row"
    r = min(cand.iter_rows(named=True), key=lambda r: abs(r["omega"] - o.omega))
    return False, (f"nearest {r['type']} row: omega {r['omega']:.6f} {r['stability']} "
                   f"|mu| {r['max_modulus']}")


def unreached(p: Point, atts: list[Attractor], rows: pl.DataFrame) -> list[str]:
    """Stable rows (and a stable perfect balance) that no start reached."""
    out = []
    if bool(rows["pb_stable"].fill_null(False).any()) and not any(
            a.kind == "perfect_balance" for a in atts):
        out.append("perfect balance (pb_stable)")
    for r in rows.filter(pl.col("stability") == "stable").iter_rows(named=True):
        pats = _relabelled_types(p, r["type"])
        hit = any(a.kind == "periodic"
                  and type_name(a.example.pattern, a.example.windings) in pats
                  and abs(r["omega"] - a.example.omega)
                  <= _tol(a.example.omega, r["trivial_error"], a.example.unc)
                  for a in atts)
        if not hit:
            out.append(f"{r['type']} omega {r['omega']:.6f} |mu| {r['max_modulus']:.4f}")
    return out


def periodic_verdicts(p: Point, o: Outcome) -> str:
    """ballbal's ``periodic()`` from the simulated orbit's series (N = 3 and auto)."""
    if o.coeffs is None:
        return "no series"
    b = p.balancer()
    parts = []
    for N in (3, "auto"):
        try:
            s = ballbal.periodic(b, o.pattern, guess=(o.omega, o.coeffs),
                                 windings=list(o.windings), N=N)
            mod = "-" if s.max_modulus is None else f"{s.max_modulus:.6f}"
            om = "-" if s.omega is None else f"{s.omega:.6f}"
            parts.append(f"N={N}: {s.status} omega {om} {s.stability} |mu| {mod}")
        except Exception as e:  # noqa: BLE001 - reported, the census goes on
            parts.append(f"N={N}: {type(e).__name__}: {e}")
    return "; ".join(parts)


def monodromy_modulus(p: Point, o: Outcome) -> float:
    """Largest non-trivial Floquet multiplier modulus of the simulated orbit, independent
    of ballbal: the monodromy matrix by central differences of the DOP853 flow over one
    period (rtol 1e-12) from the section state; the eigenvalue nearest 1 is the trivial
    one. Good to about 1e-6, not for orbits closer than that to a stability change."""
    if o.section is None:
        return math.nan
    f = make_rhs(p)
    T = TWO_PI / o.omega
    s0 = o.section

    def flow(s: np.ndarray) -> np.ndarray:
        return np.asarray(solve_ivp(f, (0.0, T), s, method="DOP853", rtol=1e-12,
                                    atol=1e-13).y[:, -1])

    d = s0.size
    m = np.empty((d, d))
    for i in range(d):
        h = 1e-6 * (1.0 + abs(s0[i]))
        e = np.zeros(d)
        e[i] = h
        m[:, i] = (flow(s0 + e) - flow(s0 - e)) / (2 * h)
    mult = np.linalg.eigvals(m)
    trivial = int(np.argmin(np.abs(mult - 1.0)))
    return float(np.max(np.abs(np.delete(mult, trivial))))


def describe(o: Outcome) -> str:
    """One attractor in a few words."""
    if o.kind == "perfect_balance":
        return "perfect balance"
    if o.kind == "equilibrium":
        return f"equilibrium x {o.q[0]:+.5f} y {o.q[1]:+.5f}"
    w = ",".join(str(v) for v in o.windings)
    return (f"{o.pattern} omega {o.omega:.6f} windings ({w}) k {o.k} returns {o.returns:.0e}"
            f" (window before {o.prev_returns:.0e})")


# --------------------------------------------------------------------------- main


def main(argv: Sequence[str] | None = None) -> int:
    """Run the census and print the per-point tables and totals."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    ap.add_argument("--points", type=int, default=30, help="random points (default 30)")
    ap.add_argument("--starts", type=int, default=24, help="starts per point (default 24)")
    ap.add_argument("--seed", type=int, default=31, help="random seed (default 31)")
    ap.add_argument("--quick", action="store_true",
                    help="2 issue points + 2 random points, 6 starts, short windows")
    ap.add_argument("--no-issue-points", action="store_true",
                    help="only random points")
    ap.add_argument("--only", default="",
                    help="only the points whose label contains one of these comma-separated "
                    "strings (e.g. issue,random-8])")
    ap.add_argument("--jobs", type=int, default=2, help="simulation processes (default 2)")
    ap.add_argument("--settle", type=float, default=1500.0,
                    help="transient before the first window (default 1500)")
    ap.add_argument("--window", type=float, default=500.0, help="window length (default 500)")
    ap.add_argument("--t-max", type=float, default=8000.0,
                    help="longest simulation (default 8000)")
    ap.add_argument("--t-slow", type=float, default=100000.0,
                    help="longest simulation of a motion too slow for its windows (default "
                    "1e5; the windows double)")
    ap.add_argument("--rtol", type=float, default=1e-10, help="DOP853 rtol (default 1e-10)")
    ap.add_argument("--atol", type=float, default=1e-11, help="DOP853 atol (default 1e-11)")
    ap.add_argument("--reference-rhs", action="store_true",
                    help="integrate reference.rhs itself (about 10 times slower)")
    args = ap.parse_args(argv)
    for name in ("points", "starts", "jobs"):
        if getattr(args, name) < (0 if name == "points" else 1):
            ap.error(f"--{name} must be at least {0 if name == 'points' else 1}")
    if not 0 < args.window <= args.t_max <= args.t_slow or args.settle < 0:
        ap.error("need 0 < --window <= --t-max <= --t-slow and --settle >= 0")
    if args.quick:
        args.points, args.starts = 2, 6
        args.settle, args.window, args.t_max, args.t_slow = 800.0, 400.0, 3000.0, 2e4
    cfg = Settings(args.settle, args.window, args.t_max, args.t_slow, args.rtol, args.atol,
                   args.reference_rhs)
    rng = np.random.default_rng(args.seed)
    points = [] if args.no_issue_points else issue_points()
    if args.quick:
        points = points[:2]
    points += random_points(args.points, rng)
    # Each point's starts are seeded by its place in the whole list, so that --only
    # simulates the same starts as the full census.
    keep = args.only.split(",")
    numbered = [(i, p) for i, p in enumerate(points) if any(k in f"{p.label}]" for k in keep)]
    points = [p for _, p in numbered]
    if not points:
        ap.error(f"--only {args.only!r} matches no point")
    print(f"census: seed {args.seed}, {len(points)} points x {args.starts} starts, "
          f"settle {cfg.settle:g}, window {cfg.window:g}, t_max {cfg.t_max:g} (slow motions "
          f"{cfg.t_slow:g}), DOP853 rtol "
          f"{cfg.rtol:g} atol {cfg.atol:g}, {args.jobs} processes, ballbal {ballbal.__file__}")
    worst = max(check_rhs(p, rng) for p in points)
    print(f"rhs transcription vs tests/reference.py::rhs: largest relative difference "
          f"{worst:.1e}")

    tasks = [(p, args.seed * 1000 + i, j, cfg) for i, p in numbered
             for j in range(args.starts)]
    t0 = time.perf_counter()
    outcomes: list[Outcome] = []
    with mp.get_context("fork").Pool(args.jobs) as pool:
        for done, o in enumerate(pool.imap(simulate_start, tasks, chunksize=1), 1):
            outcomes.append(o)
            if done % args.starts == 0:
                print(f"  simulated {done}/{len(tasks)} starts, "
                      f"{time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    sim_wall = time.perf_counter() - t0
    sim_cpu = sum(o.seconds for o in outcomes)

    totals = dict(attractors=0, periodic=0, missed_one=0, missed_grid=0, near_neutral=0,
                  unsettled=0, failed=0, unreached=0)
    scan_seconds = 0.0
    misses: list[str] = []
    for i, p in enumerate(points):
        outs = outcomes[i * args.starts:(i + 1) * args.starts]
        atts, other = group(p, outs)
        sr = scan_point(p)
        scan_seconds += sr.seconds
        eqs = ballbal.equilibria(p.balancer()) if any(
            a.kind == "equilibrium" for a in atts) else []
        print(f"\n[{p.label}] {p.describe()}")
        print(f"  scan {sr.seconds:.2f} s ({sr.grid_points}-point grid + 1 point); "
              f"pb_exists {sr.one['pb_exists'][0]} pb_stable {sr.one['pb_stable'][0]}")
        for a in atts:
            totals["attractors"] += 1
            totals["periodic"] += a.kind == "periodic"
            ok1, why1 = listed(p, a, sr.one, eqs)
            okg, whyg = listed(p, a, sr.grid, eqs)
            totals["missed_one"] += not ok1
            totals["missed_grid"] += not okg
            tag = ("listed" if ok1 and okg else
                   "MISSED" if not ok1 and not okg else
                   "MISSED by 1-point" if not ok1 else "MISSED by grid")
            print(f"  {describe(a.example)}  [{a.starts} starts]  {tag}"
                  f"  (1-point: {why1 or 'ok'}; grid: {whyg or 'ok'})")
            if not (ok1 and okg):
                extra = ""
                if a.kind == "periodic":
                    mod = monodromy_modulus(p, a.example)
                    if abs(mod - 1.0) < 1e-3:
                        totals["near_neutral"] += 1
                        tag += " (near-neutral)"
                    extra = (f"independent |mu| {mod:.6f}; "
                             f"ballbal periodic() from the simulated orbit: "
                             f"{periodic_verdicts(p, a.example)}")
                if extra:
                    print(f"      {extra}")
                misses.append(f"{p.label}: {p.describe()}: {describe(a.example)} "
                              f"[{tag}] {extra}")
        for o in other:
            totals["unsettled" if o.kind == "unsettled" else "failed"] += 1
        if other:
            kinds = sorted({f"{o.kind} {o.pattern} {o.note}".strip() for o in other})
            print(f"  unsettled/failed starts: {len(other)}: " + " | ".join(kinds))
        never = sorted(set(unreached(p, atts, sr.one)) | set(unreached(p, atts, sr.grid)))
        totals["unreached"] += len(never)
        for u in never:
            print(f"  (stable in the scan, reached by no start: {u})")

    n_starts = len(outcomes)
    print("\n== totals ==")
    print(f"points {len(points)}, starts {n_starts}, attractors {totals['attractors']} "
          f"(periodic {totals['periodic']}), missed by the 1-point scan "
          f"{totals['missed_one']}, missed by the small-grid scan {totals['missed_grid']} "
          f"(of the misses, orbits with |mu| within 1e-3 of 1 by the independent "
          f"monodromy: {totals['near_neutral']}), "
          f"unsettled starts {totals['unsettled']}, failed starts {totals['failed']}, "
          f"stable scan entries no start reached {totals['unreached']}")
    print(f"time: simulation {sim_wall:.0f} s wall ({sim_cpu:.0f} s CPU in {args.jobs} "
          f"processes, {sim_cpu / max(n_starts, 1):.1f} s per start), scans "
          f"{scan_seconds:.1f} s")
    if misses:
        print("missed:")
        for m in misses:
            print(f"  {m}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
