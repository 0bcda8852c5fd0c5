"""The options as frozen dataclasses (ballbal.options), read by the native module by
attribute, the one way to pass them: the flat keywords of before are refused with the
field that replaces each; one schema for a periodic solution in periodic() and scan();
the first argument is ``model`` everywhere."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

import ballbal
from ballbal import (
    Floquet,
    GuessSearch,
    HarmonicBalance,
    PeriodicOptions,
    ScanOptions,
)
from ballbal.exceptions import ParameterError, ParameterTypeError

B = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2, eta=(1.0, 1.0))


def test_options_are_frozen_and_checked_when_made():
    o = PeriodicOptions()
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.max_tail = 1.0  # type: ignore[misc]
    for make, name in [(lambda: HarmonicBalance(N=2.0), "N"),  # type: ignore[arg-type]
                       (lambda: HarmonicBalance(tol="1e-3"), "tol"),  # type: ignore[arg-type]
                       (lambda: Floquet(hill=1), "hill"),  # type: ignore[arg-type]
                       (lambda: GuessSearch(seeds=1.5), "seeds"),  # type: ignore[arg-type]
                       (lambda: PeriodicOptions(floquet=None), "floquet"),  # type: ignore
                       (lambda: ballbal.scan(ballbal.Balancer(), Omega=[1.2],
                                             out=3), "out")]:  # type: ignore[arg-type]
        with pytest.raises(ParameterTypeError) as e:
            make()
        assert e.value.parameter == name
    # Values are the core's to judge, when the option is made (issue 32).
    with pytest.raises(ParameterError) as e:
        Floquet(rtol=2.0)
    assert e.value.parameter == "rtol" and e.value.allowed == "(0, 1)"


def test_guess_tolerances_reach_the_core():
    # periodic() used a hidden guess tolerance (1e-9) that no argument could change:
    # now GuessSearch.rtol is read, and an impossible value is refused by the core.
    with pytest.raises(ParameterError) as e:
        GuessSearch(rtol=1.5)
    assert e.value.parameter == "guess_rtol"
    with pytest.raises(ParameterError) as e:
        GuessSearch(rtol=0.0, atol=0.0)
    assert e.value.parameter == "guess_rtol"


def test_the_harmonics_keyword_and_the_options_give_the_same_solution():
    flat = ballbal.periodic(B, "R-R", N=5,
                            options=ballbal.PeriodicOptions(
                                floquet=ballbal.Floquet(rtol=1e-7, atol=1e-9, hill=False),
                                guess=ballbal.GuessSearch(settle=800.0)))
    opts = PeriodicOptions(harmonic_balance=HarmonicBalance(N=5),
                           floquet=Floquet(rtol=1e-7, atol=1e-9, hill=False),
                           guess=GuessSearch(settle=800.0))
    new = ballbal.periodic(B, "R-R", options=opts)
    assert new.converged and flat.converged
    assert new.omega == flat.omega
    assert np.array_equal(new.coeffs, flat.coeffs)
    assert np.array_equal(new.multipliers, flat.multipliers)
    # N given with options changes their harmonics.
    both = ballbal.periodic(B, "R-R", options=opts, N=3)
    assert both.N == 3


#: Every flat option keyword of before and the field that replaces it, written out here
#: (not read from ballbal) so that a keyword or a field lost on either side fails.
REMOVED = {
    "target": "harmonic_balance.target", "N_max": "harmonic_balance.N_max",
    "samples": "harmonic_balance.samples", "tol": "harmonic_balance.tol",
    "step_tol": "harmonic_balance.step_tol", "max_iter": "harmonic_balance.max_iter",
    "floquet": "floquet.monodromy", "hill": "floquet.hill", "rtol": "floquet.rtol",
    "atol": "floquet.atol", "margin": "floquet.margin", "max_steps": "floquet.max_steps",
    "max_trivial": "floquet.max_trivial", "floquet_method": "floquet.method",
    "hill_target": "floquet.hill_target", "hill_band": "floquet.hill_band",
    "refine": "floquet.refine", "settle": "guess.settle", "window": "guess.window",
    "guess_rtol": "guess.rtol", "guess_atol": "guess.atol", "seeds": "guess.seeds",
    "starts": "guess.starts", "max_closure": "max_closure", "max_tail": "max_tail",
    "block": "block",
}


@pytest.mark.parametrize("keyword", sorted(REMOVED))
def test_a_removed_flat_keyword_is_refused_naming_its_field(keyword):
    calls = [("periodic", "PeriodicOptions", lambda kw: ballbal.periodic(B, **kw)),
             ("scan", "ScanOptions", lambda kw: ballbal.scan(B, Omega=[1.2], **kw)),
             ("switch", "PeriodicOptions",
              lambda kw: ballbal.continuation.switch(B, parameter="Omega", **kw))]
    for where, cls, call in calls:
        if keyword == "block" and cls == "PeriodicOptions":
            # A scan's option, which periodic() never took: Python's own error.
            with pytest.raises(TypeError, match="unexpected keyword argument 'block'"):
                call({keyword: 1})
            continue
        with pytest.raises(ParameterTypeError) as e:
            call({keyword: 1})
        assert isinstance(e.value, TypeError)
        assert e.value.parameter == keyword
        msg = str(e.value)
        assert f"{where}() takes no {keyword}=" in msg and f"{cls}.{REMOVED[keyword]}" in msg
        # The field named exists on that class.
        obj = {"PeriodicOptions": PeriodicOptions(), "ScanOptions": ScanOptions()}[cls]
        for part in REMOVED[keyword].split("."):
            obj = getattr(obj, part)


def test_an_unknown_keyword_is_pythons_type_error():
    with pytest.raises(TypeError, match="unexpected keyword argument 'nonsense'") as e:
        ballbal.periodic(B, nonsense=1)
    assert not isinstance(e.value, ParameterTypeError)
    # A value refused by an option names the option's field.
    with pytest.raises(ParameterTypeError) as e2:
        Floquet(monodromy=None)  # type: ignore[arg-type]
    assert e2.value.parameter == "monodromy"


def test_scan_fingerprint_of_the_flat_keywords_is_unchanged():
    # meta.json's options (the scan directory's fingerprint) as ballbal wrote them before
    # the option classes, for the defaults: directories written then still resume.
    from ballbal.scan import _meta_options

    old = {"N": 3, "auto": None, "N_max": 32, "hill": False, "samples": None,
           "tol": 1e-10, "step_tol": 1e-8, "max_iter": 50, "floquet": True, "rtol": 1e-6,
           "atol": 1e-9, "margin": 1e-6, "max_steps": 20_000, "settle": 1000.0,
           "window": 2000.0, "guess_rtol": 1e-5, "seeds": 4, "starts": 4, "max_tail": 0.25,
           "max_closure": 6.0, "max_trivial": 0.1}
    # They were computed with RK45 monodromies and no Hill: only those options resume
    # them.
    rk45 = dataclasses.replace(ScanOptions().floquet, method="rk45", hill=False)
    got = _meta_options(ScanOptions(floquet=rk45))
    assert json.dumps(got) == json.dumps(old)
    assert _meta_options(ScanOptions()) == {
        **old, "hill": True, "floquet_method": "magnus", "hill_target": "verdict",
        "hill_band": ballbal.options.SCAN_HILL_BAND}
    # A band without a monodromy runs no Hill: recorded as floquet=False scans were.
    off = dataclasses.replace(ScanOptions().floquet, monodromy=False, method="rk45")
    assert _meta_options(ScanOptions(floquet=off)) == {**old, "floquet": False}
    hb = dataclasses.replace(ScanOptions().harmonic_balance, N="auto")
    auto = _meta_options(ScanOptions(harmonic_balance=hb))
    assert (auto["N"], auto["auto"]) == (3, 1e-4)  # the scan's default target
    # A guess atol the flat keywords could not express is recorded.
    assert _meta_options(ScanOptions(guess=GuessSearch(rtol=1e-5, atol=1e-7)))[
        "guess_atol"] == 1e-7


def test_scan_options_in_full_equal_the_defaults_replaced(tmp_path):
    """Options written out in full and the scan's defaults with three fields replaced
    are the same table and the same fingerprint (that of the flat keywords of before,
    ``seeds=2, starts=2, max_steps=10_000``)."""
    grid = {"Omega": [1.2, 1.25], "eta": [1.0]}
    d = ballbal.options.SCAN_DEFAULTS
    flat = ballbal.scan(B, threads=1, **grid, options=dataclasses.replace(
        d, floquet=dataclasses.replace(d.floquet, max_steps=10_000),
        guess=dataclasses.replace(d.guess, seeds=2, starts=2)))
    opts = ScanOptions(floquet=Floquet(rtol=1e-6, atol=1e-9, max_steps=10_000, hill=True,
                                       method="magnus", hill_target="verdict",
                                       hill_band=ballbal.options.SCAN_HILL_BAND),
                       guess=GuessSearch(settle=1000.0, window=2000.0, rtol=1e-5,
                                         atol=1e-5 * 1e-3, seeds=2, starts=2))
    new = ballbal.scan(B, options=opts, threads=1, out=tmp_path / "s",
                       **grid)
    assert new.drop("seconds").equals(flat.drop("seconds"))
    meta = ballbal.scan_meta(tmp_path / "s")
    assert meta["options"]["seeds"] == 2 and "guess_atol" not in meta["options"]


def test_periodic_and_scan_share_the_solution_schema():
    grid = {"Omega": [1.2], "eta": [1.0]}
    # Hill beside every monodromy (no band), as periodic() runs it.
    o = ScanOptions(floquet=dataclasses.replace(ScanOptions().floquet, hill=True,
                                                hill_band=None))
    df = ballbal.scan(B, threads=1, options=o, **grid)
    row = df.row(0, named=True)
    # The scan's options as periodic() options: the same orbit, the same numbers.
    s = ballbal.periodic(B, "R-R", options=PeriodicOptions(
        harmonic_balance=o.harmonic_balance, floquet=o.floquet, guess=o.guess))
    names = {"status", "omega", "stability", "max_modulus", "trivial_error", "residual",
             "tail", "closure", "separation_error", "pivot_ratio", "iterations",
             "floquet_steps", "N", "target_met", "hill_stability", "verdicts_disagree",
             "omega_error", "modulus_error", "modulus_error_source"}
    assert names <= set(df.columns)
    for n in names:
        assert hasattr(s, n), n
    assert row["status"] == s.status == "converged"
    assert abs(row["omega"] - s.omega) < 1e-9
    assert abs(row["pivot_ratio"] - s.pivot_ratio) < 1e-6 * s.pivot_ratio
    # Multipliers: {re, im} structs in the table, complex numbers in the solution.
    assert s.multipliers is not None
    tab = np.array([complex(m["re"], m["im"]) for m in row["multipliers"]])
    assert np.allclose(np.sort_complex(tab), np.sort_complex(s.multipliers), atol=1e-6)


def test_the_pivot_ratio_has_one_name():
    # 0.1's deprecated alias `condition` is gone (there are no 0.1 users to keep).
    s = ballbal.periodic(B, "R-R",
                         options=ballbal.PeriodicOptions(floquet=ballbal.Floquet(hill=False)))
    assert not hasattr(s, "condition") and s.pivot_ratio >= 1


CALLS = {
    "equilibria": (ballbal.equilibria, "balancer", {}),
    "simulate": (ballbal.simulate, "balancer", {"t_eval": [0.0, 1.0]}),
    "periodic": (ballbal.periodic, "balancer",
                 {"options": PeriodicOptions(floquet=Floquet(monodromy=False, hill=False))}),
    "run_up": (ballbal.run_up, "scene", {"to": 1.3, "duration": 1.0, "settle": 1.0}),
}


@pytest.mark.parametrize("which", sorted(CALLS))
def test_first_argument_is_model_and_the_old_name_is_gone(which):
    f, old, kw = CALLS[which]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        f(model=B, **kw)
    # 0.1's keyword is refused, not translated with a warning.
    with pytest.raises(TypeError):
        f(**{old: B}, **kw)


def test_the_flattened_native_arguments_are_gone():
    for name in ("native_args", "native_effects", "effects_tuple"):
        assert not hasattr(ballbal.Balancer(), name)
        assert not hasattr(ballbal.Scene(), name)
    # The native entry points take the model itself and leave its values to the core.
    ballbal._native.validate(ballbal.Scene(springs=1e-3))
    with pytest.raises(ParameterError) as e:
        ballbal._native.validate(ballbal.Scene(balancer=B.replace(mu=1.5), springs=1e-3))
    assert (e.value.parameter, e.value.allowed) == ("mu", "(0, 1)")
