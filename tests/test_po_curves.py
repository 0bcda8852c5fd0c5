"""Two-parameter curves of periodic bifurcations (ballbal.continuation.periodic_curve),
checked against scipy shooting written here, against one-parameter branches run at the
curve points' second parameter (event location by bisection on the branch, a different
computation from the augmented system), and against a fine scan's verdicts."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ballbal
from ballbal.continuation import Continuation, Curve, periodic_branch, periodic_curve
from ballbal.exceptions import ParameterError

from reference import rhs
from shooting import newton

STD = dict(mu=0.2, zeta=0.05, delta=50.0)
N = 8
OPTS = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N))
NO_FLOQUET = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N),
                                     floquet=ballbal.Floquet(monodromy=False, hill=False))

# The branch's PD event is located on the monodromy's multipliers.
MONODROMY = ballbal.PeriodicOptions(harmonic_balance=ballbal.HarmonicBalance(N=N),
                                    floquet=ballbal.Floquet(hill=False))


def standard(Omega: float, eta: float, zeta_b: float = 0.05) -> ballbal.Balancer:
    return ballbal.Balancer(**STD, zeta_b=zeta_b, Omega=Omega, eta=(eta, eta))


# --- shooting (as in test_po_continuation.py / shooting.py) -----------------------------

def _flow(b: ballbal.Balancer, y0: np.ndarray, T: float) -> np.ndarray:
    r = solve_ivp(lambda t, s: rhs(b, t, s), (0, T), y0, rtol=1e-11, atol=1e-13,
                  method="DOP853")
    return r.y[:, -1]


def _monodromy(b: ballbal.Balancer, y0: np.ndarray, T: float, h: float = 1e-6) -> np.ndarray:
    """Central differences of the flow over one period (the variational equations with
    a differenced Jacobian integrate far slower here, for the same multipliers)."""
    n2 = len(y0)
    M = np.empty((n2, n2))
    for j in range(n2):
        e = np.zeros(n2)
        e[j] = h
        M[:, j] = (_flow(b, y0 + e, T) - _flow(b, y0 - e, T)) / (2 * h)
    return M


def shoot_merged(b: ballbal.Balancer, y_guess: np.ndarray, T_guess: float,
                 winding: np.ndarray) -> tuple[float, np.ndarray]:
    """A merged orbit (b1 = b2) by shooting on the merged states, where it is isolated
    even at a branch point of the separating mode (phase: the balls' angle fixed): the
    period and the full monodromy's eigenvalues."""
    n2 = len(y_guess)
    d = n2 // 2
    shift = np.zeros(n2)
    shift[:d] = 2 * np.pi * winding
    free = [0, 1, d, d + 1, d + 2]  # x, y, x', y', b'
    rows = [0, 1, 2, d, d + 1, d + 2]

    def state(z: np.ndarray) -> np.ndarray:
        y0 = y_guess.copy()
        y0[free] = z[:-1]
        y0[3], y0[d + 3] = y0[2], y0[d + 2]
        return y0

    def F(z: np.ndarray) -> np.ndarray:
        y0 = state(z)
        return (_flow(b, y0, z[-1]) - y0 - shift)[rows]

    z = newton(F, np.append(y_guess[free], T_guess))
    return float(z[-1]), np.linalg.eigvals(_monodromy(b, state(z), z[-1]))


def _shoot_row(c: Curve, k: int) -> tuple[ballbal.Balancer, float, np.ndarray]:
    s = c.meta["solutions"][k]
    y = s.state(0.0)
    assert abs(y[2] - y[3]) < 1e-12 and abs(y[6] - y[7]) < 1e-12  # merged
    T, ev = shoot_merged(s.balancer, y, s.period, np.asarray(s.winding))
    return s.balancer, T, ev


# --- the branches and curves ---------------------------------------------------------

@cache
def band_end(eta: float = 1.0) -> ballbal.continuation.Branch:
    """The merged R-R band's upper end in Omega (BP, then LP) at zeta_b 0.05."""
    start = ballbal.periodic(standard(1.2, eta), "R-R", options=OPTS)
    return periodic_branch(start, "Omega", range=(1.2, 1.9), periodic_options=NO_FLOQUET,
                           options=Continuation(ds=0.05, ds_max=0.2, max_points=80))


def _event(br: ballbal.continuation.Branch, kind: str) -> int:
    types = br.events["type"].to_list()
    assert kind in types, types
    return types.index(kind)


@cache
def band_curve(kind: str) -> Curve:
    br = band_end()
    return periodic_curve(br, _event(br, kind), "eta", range=(0.9, 1.1),
                          options=Continuation(ds=0.02, ds_max=0.05, max_points=30))


@cache
def pd_curve() -> Curve:
    """Merged R-R at zeta_b 0.05, Omega 1.2: a multiplier passes -1 near eta 0.86; the
    PD curve in (eta, Omega)."""
    start = ballbal.periodic(standard(1.2, 0.9), "R-R", options=OPTS)
    br = periodic_branch(start, "eta", range=(0.8, 0.9), periodic_options=MONODROMY,
                         options=Continuation(ds=0.01, ds_max=0.02, forward=False,
                                              max_points=60))
    return periodic_curve(br, "period_doubling", "Omega", range=(1.15, 1.25), range1=(0.3, 1.5),
                          options=Continuation(ds=0.05, ds_max=0.2, max_points=8))


def test_pd_curve_points_have_a_multiplier_minus_one_by_shooting() -> None:
    c = pd_curve()
    t = c.table
    assert c.kind == "period_doubling" and c.meta["together"]
    assert t.height >= 10 and float(t["Omega"].max() - t["Omega"].min()) > 0.05
    assert np.all(np.abs(t["test"].to_numpy()) < 1e-8)
    # The far end (the start is the branch's own event); a shooting costs seconds here.
    for k in (t.height - 1,):
        b, T, ev = _shoot_row(c, k)
        assert b.eta[0] == pytest.approx(t["eta"][k], abs=0)
        assert abs(T - t["period"][k]) < 1e-4 * T
        # Measured 1e-9 at N = 8: the harmonic balance's truncation is far below this.
        assert np.min(np.abs(ev + 1)) < 1e-6, (t["eta"][k], t["Omega"][k], ev)


@pytest.mark.parametrize("kind", ["branch_point", "fold"])
def test_band_end_curves_agree_with_branches_at_fixed_eta(kind: str) -> None:
    c = band_curve(kind)
    t = c.table
    assert c.kind == kind and c.meta["together"]
    assert float(t["eta"].min()) < 0.95 and float(t["eta"].max()) > 1.05
    for k in (0, t.height - 1):
        eta = float(t["eta"][k])
        br = band_end(eta)
        ev = br.events.filter(br.events["type"] == kind)
        assert ev.height >= 1, (eta, br.events)
        assert abs(float(ev["Omega"][0]) - t["Omega"][k]) < 1e-7, (eta, ev, t[k])


def test_branch_point_curve_against_shooting() -> None:
    # On the BP curve the merged balls' separation multiplier is +1: two multipliers
    # at 1 (with the trivial one), the others inside the unit circle.
    c = band_curve("branch_point")
    k = c.table.height - 1
    _, _, ev = _shoot_row(c, k)
    near = np.sort(np.abs(ev - 1))
    assert near[1] < 1e-6, ev  # measured 3e-8
    assert near[2] > 1e-2, ev


def test_scan_verdicts_lie_on_the_right_side_of_the_band_end() -> None:
    """Merged R-R rows of a fine (Omega, eta) scan: a converged one lies left of the LP
    curve, a stable one left of the BP curve, except within one grid step."""
    bp, lp = band_curve("branch_point").table.sort("eta"), band_curve("fold").table.sort("eta")
    step = 0.01
    etas = np.array([0.92, 1.0, 1.08])
    # From Omega 1.3: simulation finds no R-R start near the band end, the scan's
    # lattice carries it up from where it does.
    oms = np.arange(1.3, 1.9 + 1e-9, step)
    df = ballbal.scan(standard(1.8, 1.0), Omega=oms, eta=etas, patterns=("R-R",), N=N)
    df = df.filter((df["status"] == "converged") & df["separation_error"].is_not_null())
    checked = {"stable": 0, "converged": 0}
    for r in df.iter_rows(named=True):
        om_bp = np.interp(r["eta"], bp["eta"].to_numpy(), bp["Omega"].to_numpy())
        om_lp = np.interp(r["eta"], lp["eta"].to_numpy(), lp["Omega"].to_numpy())
        assert r["Omega"] <= om_lp + step, (r["Omega"], r["eta"], om_lp)
        checked["converged"] += 1
        if r["stability"] == "stable":
            assert r["Omega"] <= om_bp + step, (r["Omega"], r["eta"], om_bp)
            checked["stable"] += 1
    assert checked["stable"] > 100 and checked["converged"] > 200
    # And the verdicts reach the curves: the band's end is where they say.
    for eta in etas:
        rows = df.filter(df["eta"] == eta)
        om_bp = np.interp(eta, bp["eta"].to_numpy(), bp["Omega"].to_numpy())
        om_lp = np.interp(eta, lp["eta"].to_numpy(), lp["Omega"].to_numpy())
        top_stable = float(rows.filter(rows["stability"] == "stable")["Omega"].max())
        assert om_bp - step <= top_stable, (eta, top_stable, om_bp)
        assert om_lp - step <= float(rows["Omega"].max()), (eta, om_lp)


def test_bad_inputs_name_the_parameter() -> None:
    br = band_end()
    i = _event(br, "branch_point")
    cases: list[tuple[dict[str, object], str]] = [
        (dict(event=99, parameter2="eta", range=(0.9, 1.1)), "event"),
        (dict(event=i, parameter2="nope", range=(0.9, 1.1)), "parameter2"),
        (dict(event=i, parameter2="Omega", range=(0.9, 1.1)), "parameter2"),
        (dict(event=i, parameter2="eta", range=(1.1, 0.9)), "range"),
        (dict(event=i, parameter2="eta", range=(1.2, 1.3)), "range"),
        (dict(event=i, parameter2="eta", range=(0.9, 1.1), range1=(2.0, 3.0)),
         "range1"),
    ]
    for kw, name in cases:
        with pytest.raises(ParameterError) as e:
            periodic_curve(br, **kw)  # type: ignore[arg-type]
        assert e.value.parameter == name, (kw, e.value)
    with pytest.raises(ParameterError) as e:
        Continuation(ds=-1.0)
    assert e.value.parameter == "ds"
    with pytest.raises(ParameterError) as e:
        periodic_curve("x", 0, "eta", range=(0.9, 1.1))  # type: ignore[arg-type]
    assert e.value.parameter == "branch"
