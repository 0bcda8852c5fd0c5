"""Codimension-two flags on curves of periodic bifurcations (ballbal.continuation.
periodic_curve): the cusp (CP) of a fold curve.

The merged R-R branch at mu 0.2, zeta 0.05, zeta_b 0.1, delta 50, eta 1 snakes in Omega
before its infinite-period end: a pair of folds (LP) at Omega ~1.2312 and ~1.2381. Their
fold curves in (Omega, eta) are one curve that turns back at a cusp near
(1.1170, 0.4604): the pair merges there, and below its eta no fold of the pair is left.
Checked here against computations other than the flag's location: the one-parameter
branch's own LP events (dp/ds changing sign), the fold curve continued from the other
fold of the pair, and the turning point of the curve's table fitted by a parabola.

(One-parameter branches at fixed Omega or eta next to the cusp do not serve as a check
here: the orbits are near-homoclinic (omega ~0.04), a branch in eta moves ~1e-5 in eta
in 150 points, and Newton from a neighbouring curve point diverges for shifts of 1e-4.)
"""

from __future__ import annotations

from functools import cache

import numpy as np

import ballbal
from ballbal.continuation import Continuation, Curve, periodic_branch, periodic_curve

N = 8
OPTS = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N),
                               floquet=ballbal.Floquet(monodromy=False, hill=False))


@cache
def branch() -> ballbal.continuation.Branch:
    b = ballbal.Balancer(mu=0.2, zeta=0.05, delta=50.0, zeta_b=0.1, Omega=1.2, eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=OPTS)
    return periodic_branch(start, "Omega", range=(0.95, 1.9), periodic_options=OPTS,
                           options=Continuation(ds=0.05, ds_max=0.2, max_points=120))


def _fold_pair() -> tuple[int, int]:
    ev = branch().events
    lp = [(i, om) for i, (t, om) in enumerate(ev.select("type", "Omega").rows())
          if t == "fold" and 1.225 < om < 1.24]
    # the snake's folds alternate; the pair around the CP: ~1.2312 and ~1.2381
    near = [i for i, om in lp if abs(om - 1.2312) < 2e-3 or abs(om - 1.2381) < 2e-3]
    assert len(near) == 2, ev
    return near[0], near[1]


@cache
def fold_curve(which: int) -> Curve:
    return periodic_curve(branch(), _fold_pair()[which], "eta", range=(0.4, 1.1),
                          range1=(0.9, 1.9), periodic_options=OPTS,
                          options=Continuation(ds=0.02, ds_max=0.05, max_points=200))


def _cusp(c: Curve) -> tuple[float, float, int]:
    cp = c.points.filter(c.points["type"] == "CP")
    assert cp.height == 1, c.points
    return float(cp["Omega"][0]), float(cp["eta"][0]), int(cp["row"][0])


def test_the_fold_pair_merges_at_the_cusp() -> None:
    c = fold_curve(0)
    om_cp, eta_cp, r = _cusp(c)
    assert abs(om_cp - 1.117) < 2e-3 and abs(eta_cp - 0.4604) < 2e-3
    t = c.table
    om, eta = t["Omega"].to_numpy(), t["eta"].to_numpy()
    # on each side of the cusp the curve reaches eta = 1, where the branch's own LP events
    # (dp/ds changing sign) are the fold pair
    ev = branch().events
    pair = sorted(float(ev["Omega"][i]) for i in _fold_pair())
    ends = []
    for side in (slice(0, r), slice(r, None)):
        o, e = om[side], eta[side]
        order = np.arange(len(e))[::-1] if side.start == 0 else np.arange(len(e))
        j = next(int(i) for i in order if e[i] >= 1.0)
        i = j + 1 if side.start == 0 else j - 1  # the row before it, from the cusp
        assert e[i] <= 1.0 <= e[j], (e.min(), e.max())
        ends.append(o[j] if e[j] == 1.0 else
                    o[i] + (1.0 - e[i]) * (o[j] - o[i]) / (e[j] - e[i]))
    # linear interpolation between rows ~0.03 apart in eta: ~1e-4 in Omega
    np.testing.assert_allclose(sorted(ends), pair, atol=5e-4)
    # none of the pair's folds below the cusp's eta
    assert eta.min() > eta_cp - 1e-4


def test_the_cusp_is_the_curves_turning_point() -> None:
    # the flag is located by the reversal of the curve's direction; here: the minimum of
    # Omega along the curve, from a parabola through the table's rows around it
    c = fold_curve(0)
    om_cp, eta_cp, r = _cusp(c)
    t = c.table
    s = t["omega"].to_numpy()  # monotone along the curve through the cusp
    om = t["Omega"].to_numpy()
    k = int(np.argmin(om))
    assert abs(k - r) <= 1
    # the rows lie ~2e-4 to 1e-3 apart in Omega; fits through 3 and through 5 rows
    # agree with each other to ~1e-5 (the orbits are near-homoclinic, omega ~0.04)
    for h, deg in ((1, 2), (2, 3)):
        idx = np.arange(k - h, k + h + 1)
        p = np.polyfit(s[idx], om[idx], deg)
        roots = np.roots(np.polyder(p))
        roots = roots[np.abs(roots.imag) < 1e-12].real
        s_star = roots[np.argmin(np.abs(roots - s[k]))]
        assert np.polyval(np.polyder(p, 2), s_star) > 0  # a minimum: the curve turns back
        om_star = float(np.polyval(p, s_star))
        eta_star = float(np.polyval(np.polyfit(s[idx], t["eta"].to_numpy()[idx], deg),
                                    s_star))
        assert abs(om_star - om_cp) < 3e-5, (h, om_star, om_cp)
        assert abs(eta_star - eta_cp) < 1e-5, (h, eta_star, eta_cp)


def test_the_other_fold_of_the_pair_reaches_the_same_cusp() -> None:
    # continued from the pair's other LP event, a different start and path
    a = _cusp(fold_curve(0))
    b = _cusp(fold_curve(1))
    assert abs(a[0] - b[0]) < 1e-8 and abs(a[1] - b[1]) < 1e-8, (a, b)
