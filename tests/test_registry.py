"""The facade's parameter lists and scan schema are the core's (served by the native
module), not copies kept by hand: every listed name is one the core varies, a name
outside them is refused with the core's own error, and a scan table's columns are the
served schema."""

import importlib
import math

import polars as pl
import pytest

import ballbal
from ballbal import _native
from ballbal.bearing import Bearing, Grooves
from ballbal.exceptions import ParameterError

# the module, not the function ballbal.scan
scan_module = importlib.import_module("ballbal.scan")

BAL = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0, Omega=1.2,
                       eta=(1.0, 1.0))
TILT = ballbal.Tilt(a=1.8, b=2.2, j_t=0.15, j_z=0.25, zeta_r=0.05)
GROOVED = Bearing(length_ratio=0.5, grooves=Grooves(8, 30.0, 1.0, side="journal"),
                  grid=(64, 8))
#: Every component a scan can vary: springs and gravity on the tilting disk's scene, the
#: bearing's parameters on a grooved bearing.
SCENES = [ballbal.Scene(balancer=BAL, springs=1e-5, tilt=TILT),
          ballbal.Scene(balancer=BAL, support=ballbal.BearingSupport(GROOVED, 0.3))]


def _value(model, name):
    """The model's own value of a scannable parameter, read from the Python objects."""
    b = model.balancer if isinstance(model, ballbal.Scene) else model
    if hasattr(b, name):
        v = getattr(b, name)
        return float(v[0] if isinstance(v, tuple) else v)
    if name in ("springs", "gravity"):
        return float(getattr(model, name))
    if model.tilt is not None and hasattr(model.tilt, name):
        return float(getattr(model.tilt, name))
    bearing = model.support.bearing
    return {"rho": model.support.rho, "depth_ratio": bearing.grooves.depth_ratio,
            "groove_angle": bearing.grooves.angle}[name]


def test_every_listed_name_is_one_the_core_varies_and_no_other():
    listed = set(scan_module.SCANNABLE) | set(scan_module.SCENE_SCANNABLE)
    accepted = set()
    for model in [BAL, *SCENES]:
        keys = _native.parameter_keys(model)
        accepted |= set(keys)
        for name in keys:
            # The core sets the name on this model (to its own value) without complaint.
            _native.check_axes(model, [name])
    assert listed == accepted
    # The planar balancer's are exactly SCANNABLE, in the registry's order.
    assert tuple(_native.parameter_keys(BAL)) == scan_module.SCANNABLE
    # A name is checked as a name: every ball's eta on balls of different eta (no one
    # value of the model's) is a name the core varies.
    _native.check_axes(BAL.replace(eta=(0.8, 1.2)), ["eta", "eta2", "zeta_b"])
    # Gravity is varied by the core (at 0: above it a scene is time-dependent); the
    # hand-kept list of before left it out.
    assert "gravity" in scan_module.SCENE_SCANNABLE


@pytest.mark.parametrize("name", ["mu", "zeta", "zeta_b", "delta", "Omega", "eta"])
def test_every_planar_name_scans(name):
    v = _value(BAL, name)
    df = ballbal.scan(BAL, **{name: [v]}, patterns=["R-R"], threads=1)
    assert df[name].to_list() == [v] * df.height
    assert df.filter(pl.col("status") == "converged").height >= 1


def test_gravity_scans_at_zero_and_is_refused_above():
    sc = ballbal.Scene(balancer=BAL, springs=1e-5)
    df = ballbal.scan(sc, Omega=[1.2], gravity=[0.0], patterns=["R-R"], threads=1)
    assert df.filter(pl.col("status") == "converged").height >= 1
    with pytest.raises(ballbal.exceptions.NotAutonomousError):
        ballbal.scan(sc, Omega=[1.2], gravity=[0.0, 0.1], patterns=["R-R"], threads=1)


@pytest.mark.parametrize("model, name", [(BAL, "springs"), (BAL, "j_t"), (BAL, "spin"),
                                         (SCENES[0], "rho"), (SCENES[1], "zeta_r"),
                                         (SCENES[0], "eta3"), (SCENES[0], "ramp.to")])
def test_a_name_the_core_does_not_vary_is_refused_with_the_cores_error(model, name):
    with pytest.raises(ParameterError) as facade:
        ballbal.scan(model, Omega=[1.2], **{name: [0.5]}, threads=1)
    # The core's own scan of the same grid, past the facade.
    with pytest.raises(ParameterError) as core:
        _native.scan(model, ["Omega", name], [[1.2], [0.5]], ["R-R"],
                     ballbal.ScanOptions(block=1), 1, 1, [0], lambda c, d: None)
    assert str(facade.value) == str(core.value)
    assert facade.value.parameter == name


def test_registry_ranges_are_the_ones_models_are_checked_with():
    """Each planar parameter's served range: its open ends are refused and a value
    just inside is accepted when a Balancer is made (light balls on a heavy rim, so
    that the total-mass bound, which joins mu, delta and eta, stays far)."""
    light = BAL.replace(delta=1e4, eta=(1e-3, 1e-3))
    for p in _native.parameters():
        if not (p["planar"] and p["key"]):
            continue  # a scene's, or a drive's ramp (set as a whole, not by name)
        name = p["key"]
        for end, is_open, inward in ((p["lo"], p["lo_open"], 1.0),
                                     (p["hi"], p["hi_open"], -1.0)):
            if math.isinf(end):
                continue
            inside = end + inward * 1e-3 * max(1.0, abs(end))
            light.replace(**{name: _balls(name, inside)}).validate()
            if is_open:
                with pytest.raises(ParameterError) as e:
                    light.replace(**{name: _balls(name, end)})
                assert e.value.parameter.startswith(name)
            else:
                light.replace(**{name: _balls(name, end)}).validate()


def _balls(name, v):
    # eta is one value per ball (two here); zeta_b may be one for all.
    return (v, v) if name == "eta" else v


def test_a_scan_tables_columns_are_the_served_schema():
    df = ballbal.scan(BAL, Omega=[1.2, 1.25], patterns=["R-R", "O-O"], threads=1)
    served = _native.scan_schema()
    dtypes = {"float": pl.Float64, "count": pl.Int64, "flag": pl.Boolean,
              "label": pl.String,
              "multipliers": pl.List(pl.Struct({"re": pl.Float64, "im": pl.Float64}))}
    axes = ["Omega", "Omega_index"]
    model_columns = [c for c in scan_module._model_values(BAL) if c not in axes]
    assert df.columns == axes + [n for n, _ in served] + model_columns
    for name, kind in served:
        assert df.schema[name] == dtypes[kind], name
    # The multipliers hold the trivial multiplier 1 of an autonomous orbit.
    row = df.filter(pl.col("status") == "converged").row(0, named=True)
    assert min(abs(complex(m["re"], m["im"]) - 1) for m in row["multipliers"]) < 1e-4
    # A table of no rows (an empty store's) has the same columns and dtypes.
    empty = scan_module._empty(["Omega"], model_columns)
    assert empty.schema == df.schema
