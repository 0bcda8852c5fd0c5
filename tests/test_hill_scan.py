"""Hill's cross-check at the scan's target (``Floquet(hill_target="verdict")``: the
truncation only as large as the verdict needs) against independent estimates: the
monodromy of tests/shooting.py on the orbit (Tien's (2011) period-106 case included) and
RK45 at tight tolerances across a Tien (2011) map."""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import polars as pl
import pytest
from test_floquet_methods import shooting_multipliers

import ballbal
from ballbal.exceptions import ParameterError

from shooting import flow, match_error

STANDARD_PARAMS = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0}


def _lead(ev: np.ndarray) -> float:
    """Largest modulus apart from the trivial multiplier (the one nearest 1)."""
    ev = np.asarray(ev)
    trivial = int(np.argmin(np.abs(ev - 1.0)))
    return float(np.max(np.abs(np.delete(ev, trivial))))


def _check_against_shooting(b: ballbal.Balancer, s: ballbal.PeriodicSolution) -> None:
    y0, T = s.state(0.0), s.period
    shift = np.zeros(8)
    shift[2:4] = -2 * np.pi
    assert np.max(np.abs(flow(b, y0, T) - y0 - shift)) < 1e-7
    ref = shooting_multipliers(b, y0, T)
    v = ballbal.periodic(b, "R-R", N=s.N, guess=s,
                         options=ballbal.PeriodicOptions(
                             floquet=ballbal.Floquet(monodromy=False, hill=True,
                                                     hill_target="verdict")))
    assert v.hill_multipliers is not None
    lead = _lead(ref)
    # The verdict target stops once its estimate (which bounds the error) is a tenth
    # of the leading modulus' distance from 1, or below 1e-6.
    assert match_error(v.hill_multipliers, ref) <= max(abs(lead - 1.0) / 10, 1e-6)
    assert v.hill_stability == ("stable" if lead < 1 else "unstable")


def test_verdict_target_against_shooting_on_the_standard_case():
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.2, eta=(1.0, 1.0))
    s = ballbal.periodic(b, "R-R", N=12,
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    _check_against_shooting(b, s)


def test_verdict_target_against_shooting_on_the_hard_case():
    """Period ~106: the multipliers target needs H = 13 to 15 here; the verdict H = 5."""
    b = ballbal.Balancer(**STANDARD_PARAMS, Omega=1.0, eta=(0.7, 0.7))
    s = ballbal.periodic(b, "R-R", N=3,
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    for N in (8, 16, 24):
        s = ballbal.periodic(b, "R-R", N=N, guess=s,
                             options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    assert 106 < s.period < 107
    _check_against_shooting(b, s)


KEY = ["Omega", "eta", "type", "solution"]


@pytest.fixture(scope="module")
def standard_map() -> dict[str, pl.DataFrame]:
    """The standard Tien (2011) map (all three types, N = 3) with Hill beside every
    monodromy, with the scan's defaults (Hill where the verdict is in doubt), and with
    RK45 at rtol 1e-10 and no Hill; converged rows only."""
    b = ballbal.Balancer(**STANDARD_PARAMS)
    grid = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
    pats = ("R-R", "O-O", "R-O")
    fl = ballbal.options.SCAN_DEFAULTS.floquet
    runs = {"all": dataclasses.replace(fl, hill=True, hill_band=None), "default": fl,
            "tight": dataclasses.replace(fl, hill=False, method="rk45", rtol=1e-10,
                                         atol=1e-12, max_steps=1_000_000)}
    return {k: ballbal.scan(b, patterns=pats, N=3, **grid,
                            options=ballbal.ScanOptions(floquet=floquet))
            .filter(pl.col("status") == "converged") for k, floquet in runs.items()}


def test_scan_verdicts_agree_with_tight_rk45_across_an_omega_eta_map(
        standard_map: dict[str, pl.DataFrame]) -> None:
    """Every Hill verdict of a scan at its target is the verdict of RK45 at rtol 1e-10
    on the same series, or undetermined; undetermined only where that leading modulus
    is within 1e-3 of 1 or the tight verdict is undetermined itself."""
    hill, tight = standard_map["all"], standard_map["tight"]
    assert hill["hill_stability"].is_not_null().all()
    both = hill.join(tight, on=KEY, suffix="_tight")
    assert both.height == hill.height > 100
    assert (both["omega"] == both["omega_tight"]).all()
    opposite = both.filter((pl.col("hill_stability") != pl.col("stability_tight"))
                           & (pl.col("hill_stability") != "undetermined"))
    assert opposite.height == 0, opposite
    # A slow orbit that a seed solved with more harmonics than N = 3 (near a rotating
    # branch's infinite-period end) may leave Hill undetermined far from 1; never wrong.
    open_ = both.filter((pl.col("hill_stability") == "undetermined")
                        & (pl.col("stability_tight") != "undetermined")
                        & (pl.col("N") == 3))
    assert ((open_["max_modulus_tight"] - 1.0).abs() < 1e-3).all(), open_
    assert not both["verdicts_disagree"].any()


def test_default_scan_cross_checks_the_doubtful_verdicts(
        standard_map: dict[str, pl.DataFrame]) -> None:
    """The scan's default runs Hill on every solution whose monodromy verdict is
    undetermined or whose leading modulus is within ``SCAN_HILL_BAND`` of 1, with the
    verdicts Hill gives beside every monodromy, and skips most of the others. What it
    skips it may skip: there, Hill's verdict (computed beside every monodromy) and
    RK45's at rtol 1e-10 are the monodromy's, without exception."""
    band = ballbal.options.SCAN_HILL_BAND
    assert ballbal.options.SCAN_DEFAULTS.floquet.hill
    assert ballbal.options.SCAN_DEFAULTS.floquet.hill_band == band
    dflt = standard_map["default"].join(standard_map["all"], on=KEY, suffix="_all")
    dflt = dflt.join(standard_map["tight"], on=KEY, suffix="_tight")
    assert dflt.height == standard_map["all"].height
    doubt = ((pl.col("stability") == "undetermined")
             | ((pl.col("max_modulus") - 1.0).abs() <= band))
    checked = dflt.filter(pl.col("hill_stability").is_not_null())
    skipped = dflt.filter(pl.col("hill_stability").is_null())
    # every doubtful verdict checked, with the verdict a check of every row gives
    assert dflt.filter(doubt)["hill_stability"].is_not_null().all()
    assert (checked["hill_stability"] == checked["hill_stability_all"]).all()
    assert (checked["verdicts_disagree"] == checked["verdicts_disagree_all"]).all()
    # the rest lies beyond the band with a definite verdict (Hill off there)
    assert skipped.height > 0.5 * dflt.height
    assert ((skipped["max_modulus"] - 1.0).abs() > band).all()
    assert skipped["verdicts_disagree"].is_null().all()
    # (Hill undetermined, not opposite, on slow orbits solved with more harmonics)
    slow_open = (skipped["hill_stability_all"] == "undetermined") & (skipped["N"] > 3)
    assert ((skipped["stability"] == skipped["hill_stability_all"]) | slow_open).all()
    assert (skipped["stability"] == skipped["stability_tight"]).all()


def test_hill_target_option_is_checked():
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as e:
        ballbal.periodic(b, "R-R", N=3,
                         options=ballbal.PeriodicOptions(
                             floquet=ballbal.Floquet(hill_target="eigenvalues")))
    assert e.value.parameter == "hill_target"


def test_hill_band_option() -> None:
    """A scan cross-checks within its band by default, periodic() every solution; a band
    must be a number of at least 0."""
    from ballbal.options import SCAN_DEFAULTS, Floquet

    assert SCAN_DEFAULTS.floquet.hill_band == ballbal.options.SCAN_HILL_BAND == 0.2
    assert Floquet().hill_band is None  # periodic(): every solution
    b = ballbal.Balancer()
    with pytest.raises(ParameterError) as e:
        ballbal.scan(b, patterns=["R-R"], Omega=[1.2], eta=[1.0],
                     options=ballbal.ScanOptions(
                         floquet=dataclasses.replace(ballbal.options.SCAN_DEFAULTS.floquet,
                                                     hill_band=-0.1)))
    assert e.value.parameter == "hill_band"
    with pytest.raises(ballbal.exceptions.ParameterTypeError) as t:
        Floquet(hill_band="wide")  # type: ignore[arg-type]
    assert t.value.parameter == "hill_band"


def test_main_job_reports_the_cross_check() -> None:
    """``ballbal run`` says how many of its map's verdicts Hill cross-checked, and that
    none was contradicted."""
    r = subprocess.run([sys.executable, "-m", "ballbal.cli", "run"], capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    m = re.search(r"cross-checked (\d+) of the (\d+) verdicts .*: (\d+) the same, "
                  r"(\d+) contradicted", r.stdout)
    assert m, r.stdout
    checked, total, same, contradicted = map(int, m.groups())
    assert 0 < checked < total and same == checked and contradicted == 0


def test_scans_written_without_hill_resume_with_hill_off(tmp_path: Path) -> None:
    """A directory written with Hill off (the default before 2026-11-24) is refused by
    the new defaults with a message saying how to resume it, and resumes with
    ``Floquet(hill=False)`` (from Python and with ``ballbal scan --hill off``) to the same
    table."""
    b = ballbal.Balancer(**STANDARD_PARAMS)
    grid = {"Omega": [1.2, 1.3], "eta": [1.0]}
    off = ballbal.ScanOptions(floquet=dataclasses.replace(
        ballbal.options.SCAN_DEFAULTS.floquet, hill=False))
    first = ballbal.scan(b, patterns=["R-R"], threads=1, options=off, out=tmp_path / "s",
                         **grid)
    with pytest.raises(ballbal.exceptions.ScanStoreError, match=r"Floquet\(hill=False\) resumes"):
        ballbal.scan(b, patterns=["R-R"], threads=1, out=tmp_path / "s", **grid)
    again = ballbal.scan(b, patterns=["R-R"], threads=1, options=off, out=tmp_path / "s",
                         **grid)
    assert again.drop("seconds").equals(first.drop("seconds"))
    r = subprocess.run([sys.executable, "-m", "ballbal.cli", "scan", "--Omega", "1.2:1.31:0.1",
                        "--eta", "1.0:1.01:0.1", "--hill", "off", "--no-progress",
                        "-o", str(tmp_path / "s")], capture_output=True, text=True,
                       timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
