"""Multiplier certificates of codimension-two points on curves of periodic bifurcations
(ballbal.continuation.periodic_curve, ``points["status"]``): a flag is a sign change of
a truncated Galerkin determinant; only a point whose monodromy has the multipliers the
label needs is ``confirmed``.

Checked against shooting written here (Newton on the closure of flows by
``ballbal.simulate``, the monodromy by central differences of the flows:
tests/test_ns_curves.py's helpers), not against the harmonic balance or the package's
monodromy."""

from __future__ import annotations

from functools import cache

import numpy as np
import polars as pl
from scipy.integrate import solve_ivp
from test_codim2 import fold_curve
from test_ns_curves import _flow, _monodromy
from test_po_curves import MONODROMY, NO_FLOQUET, standard

import ballbal
from ballbal.continuation import Continuation, Curve, periodic_branch, periodic_curve

from reference import rhs


def shoot(b: ballbal.Balancer, y: np.ndarray, T: float, winding: np.ndarray,
          h: float = 1e-6) -> tuple[float, np.ndarray]:
    """Newton on ``phi_T(y0) - y0 - 2 pi winding = 0`` (unknowns: the state but the
    first ball's angle, which fixes the phase, and ``T``; the Jacobian from the
    monodromy and the flow's velocity), from a close start: the period and the
    monodromy's eigenvalues at the closed orbit. ``h``: the differences' step (small:
    on the snake a perturbation grows ~900-fold over a period, and its square's term
    would move the trivial multiplier by 1e-2 at h = 1e-4)."""
    shift = np.zeros(8)
    shift[:4] = 2 * np.pi * np.asarray(winding)
    free = [i for i in range(8) if i != 2]
    y = y.copy()
    for _ in range(6):
        M = _monodromy(b, y, T, h)  # type: ignore[arg-type]
        end = _flow(b, y, T)  # type: ignore[arg-type]
        r = end - y - shift
        if np.max(np.abs(r)) < 1e-9:
            return T, np.linalg.eigvals(M)
        J = np.column_stack([(M - np.eye(8))[:, free], rhs(b, T, end)])
        step = np.linalg.solve(J, -r)
        y[free] += step[:-1]
        T += step[-1]
    raise AssertionError(f"shooting did not close: {np.max(np.abs(r))}")


@cache
def fold_flip_curve() -> Curve:
    """The merged R-R at zeta_b 0.05 continued down in eta at Omega 1.16: a multiplier
    passes -1 near eta 0.279; its PD curve in (eta, Omega) meets the fold curve where the
    Tien's (2011) period-doubling tongue ends, near (0.2805, 1.1574)."""
    s = ballbal.periodic(standard(1.16, 0.30), "R-R", options=MONODROMY)
    br = periodic_branch(s, "eta", range=(0.25, 0.30), periodic_options=MONODROMY,
                         options=Continuation(ds=0.01, ds_max=0.02, forward=False,
                                              max_points=40))
    i = br.events["type"].to_list().index("period_doubling")
    return periodic_curve(br, i, "Omega", range=(1.155, 1.1605), range1=(0.25, 0.4),
                          periodic_options=NO_FLOQUET,
                          options=Continuation(ds=0.005, ds_max=0.01, max_points=30))


def _flag_labels(c: Curve) -> list[str]:
    return [lab for f in c.table["flag"].drop_nulls() for lab in f.split(",")]


def _bifurcations_are_confirmed(c: Curve) -> None:
    """The table presents a bare label only for a confirmed point; every located point
    carries its certificate."""
    p = c.points
    assert {"status", "gap", "residual", "own_residual", "error"} <= set(p.columns)
    assert set(p["status"]) <= {"confirmed", "rejected", "undetermined"}
    confirmed = p.filter(pl.col("status") == "confirmed")["type"].to_list()
    bare = [lab for lab in _flag_labels(c) if not lab.endswith("?")
            and not lab.startswith("not ")]
    assert sorted(bare) == sorted(confirmed), (bare, p)


def test_fold_flip_is_confirmed_and_shooting_finds_its_multipliers() -> None:
    c = fold_flip_curve()
    _bifurcations_are_confirmed(c)
    p = c.points.filter(pl.col("type") == "LPPD")
    assert p.height == 1, c.points
    assert p["status"][0] == "confirmed", p
    eta_s, om_s, r = float(p["eta"][0]), float(p["Omega"][0]), int(p["row"][0])
    assert abs(eta_s - 0.2805) < 1e-3 and abs(om_s - 1.1574) < 1e-3
    # Shooting at the curve rows either side of the flag: the PD curve's -1 is there at
    # both, and the second multiplier at +1 (the fold's, next to the trivial one) changes
    # side between them; its secant zero in Omega is the flag's.
    gaps, oms = [], []
    for k in (r - 1, r):
        s = c.meta["solutions"][k]
        y = s.state(0.0)
        T, ev = shoot(s.balancer, y, s.period, np.asarray(s.winding))
        assert abs(T / s.period - 1) < 1e-6, (T, s.period)
        assert np.min(np.abs(ev + 1)) < 1e-5, ev  # measured 1.2e-7, 1.1e-7 (N = 8)
        near = ev[np.argsort(np.abs(ev - 1))]
        # the trivial multiplier (measured 1e-7, 2e-7; two real multipliers ~0.02 apart
        # near +1 amplify the differenced monodromy's error)
        assert abs(near[0] - 1) < 1e-5, ev
        assert abs(near[1].imag) < 1e-9, ev
        gaps.append(near[1].real - 1)
        oms.append(float(c.table["Omega"][k]))
    assert gaps[0] * gaps[1] < 0, gaps
    zero = oms[0] - gaps[0] * (oms[1] - oms[0]) / (gaps[1] - gaps[0])
    # measured 1e-6 (fold multiplier 1 + 0.025 and 1 - 0.015 at rows 2.7e-4 apart in
    # Omega); 2e-5 allows for the secant's curvature over the bracket
    assert abs(zero - om_s) < 2e-5, (zero, om_s, oms, gaps)
    # the certificate's own numbers: a gap of a few 1e-6 against an error of ~1e-5
    assert float(p["gap"][0]) < 1e-4 and float(p["residual"][0]) <= 10 * float(p["error"][0])


def test_near_homoclinic_flags_are_not_presented_as_bifurcations() -> None:
    """The snake's fold curve at zeta_b 0.1 (test_codim2.py): omega ~0.04, LPPD flags
    within 1e-4 of BP flags. The N = 8 series there is no orbit to the accuracy a -1
    check needs: the flow from its initial state does not come back (measured here with
    scipy), so no label may be confirmed."""
    c = fold_curve(0)
    _bifurcations_are_confirmed(c)
    lppd = c.points.filter(pl.col("type") == "LPPD")
    assert lppd.height >= 2, c.points
    assert (lppd["status"] != "confirmed").all(), lppd
    r = int(lppd["row"][0])
    s = c.meta["solutions"][r]
    y0 = s.state(0.0)

    end = solve_ivp(lambda t, x: rhs(s.balancer, t, x), (0, s.period), y0, rtol=1e-10,
                    atol=1e-12, method="DOP853").y[:, -1]
    shift = np.zeros(8)
    shift[:4] = 2 * np.pi * np.asarray(s.winding)
    # a closed orbit comes back to 1e-8 here; this series misses by far more
    assert np.max(np.abs(end - y0 - shift)) > 1e-3


def test_plot_marks_only_confirmed_points() -> None:
    import matplotlib
    matplotlib.use("Agg")
    from ballbal.plot import scan_map

    c = fold_curve(0)
    df = pl.DataFrame({"Omega": [1.1, 1.2], "eta": [0.5, 0.5], "pb_stable": [True, True],
                       "type": ["R-R", "R-R"], "status": ["converged", "converged"],
                       "stability": ["stable", "stable"]})
    ax = scan_map(df, x="Omega", y="eta", curves=[c])
    stars = [ln for ln in ax.lines if ln.get_marker() == "*"]
    n_conf = c.points.filter(pl.col("status") == "confirmed").height
    assert sum(len(ln.get_xdata()) for ln in stars) == n_conf
    hollow = [ln for ln in ax.lines if ln.get_marker() == "o"]
    assert sum(len(ln.get_xdata()) for ln in hollow) == c.points.height - n_conf


@cache
def snake() -> ballbal.continuation.Branch:
    """The merged R-R at mu 0.2, zeta 0.05, zeta_b 0.1, delta 50, eta 1 continued up in
    Omega from 1.2: its BP and LP at ~1.40, then back down onto the unstable snake, whose
    first fold (~1.2177) has a PD right past it (multipliers of modulus ~900)."""
    b = ballbal.Balancer(mu=0.2, zeta=0.05, delta=50.0, zeta_b=0.1, Omega=1.2,
                         eta=(1.0, 1.0))
    start = ballbal.periodic(b, "R-R", options=MONODROMY)
    return periodic_branch(start, "Omega", range=(0.95, 1.9), periodic_options=MONODROMY,
                           options=Continuation(ds=0.05, ds_max=0.2, max_points=50))


def test_snake_period_doubling_against_shooting() -> None:
    """The snake's first PD, shot at the event's Omega from the event's orbit: a
    multiplier at -1 and the same period. The tolerance: the event is located to
    ``event_tol`` = 1e-7 in Omega, where the multiplier moves at |dlambda/dOmega| ~4e3
    (between the two rows after it, both shot here): 4e-4; the N = 8 series' truncation and
    the differenced monodromy add ~1e-6 (the largest multiplier, ~809, agrees with the
    branch's to 2e-8). Measured: 2.2e-6."""
    br = snake()
    ev = br.events
    types = ev["type"].to_list()
    assert "period_doubling" in types, ev
    i = types.index("period_doubling")
    k = int(ev["index"][i])
    assert 1.2 < float(ev["Omega"][i]) < 1.25
    assert float(br.table["max_modulus"][k]) > 100  # the snake's: strongly unstable
    s = br.event_solutions[i]
    T, m = shoot(s.balancer, s.state(0.0), s.period, np.asarray(s.winding))
    # measured 1e-13: the N = 8 series' period
    assert abs(T / s.period - 1) < 1e-8, (T, s.period)
    lam = []
    for r in (k, k + 1):
        sr = br.solutions[r]
        _, mr = shoot(sr.balancer, sr.state(0.0), sr.period, np.asarray(sr.winding))
        real = mr[np.abs(mr.imag) < 1e-8].real
        lam.append(real[real < -1].max())  # the multiplier that went through -1
    om = br.table["Omega"].to_numpy()[[k, k + 1]]
    slope = abs((lam[1] - lam[0]) / (om[1] - om[0]))
    assert 1e3 < slope < 1e5, slope
    tol = float(br.meta["event_tol"]) * slope + 1e-5
    gap = float(np.min(np.abs(m + 1)))
    assert gap < tol, (gap, tol, m)
    # the trivial multiplier: the differenced monodromy's own error (measured 1.3e-6)
    assert float(np.min(np.abs(m - 1))) < 1e-5, m
