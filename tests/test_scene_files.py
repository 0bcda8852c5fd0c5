"""Scene files (TOML) and dictionaries: round trips and clear errors."""


import pytest
from ground_frame import FULL
from hypothesis import given, settings
from hypothesis import strategies as st

import ballbal
from ballbal.scene import scene_from_dict


def test_scene_files_round_trip(tmp_path):
    p = tmp_path / "full.toml"
    FULL.save(p)
    assert ballbal.load_scene(p) == FULL
    chain = FULL.replace(spring_layout="chain")
    chain.save(p)
    assert ballbal.load_scene(p) == chain
    flat = tmp_path / "flat.toml"
    flat.write_text("mu = 0.2\nOmega = 1.3\neta = 0.9\nballs = 3\n")
    sc = ballbal.load_scene(flat)
    assert sc.balancer.eta == (0.9, 0.9, 0.9) and not sc._effects_on()


@pytest.mark.parametrize(("text", "parameter"), [
    ("mu = 0.2\nzetta = 0.1\n", "zetta"),
    ("[balancer]\nmu = 0.2\n[spring]\nstiffness = 1.0\n", "spring"),
    ("[balancer]\nmu = 0.2\n[springs]\nk = 1.0\n", "springs.k"),
    ("[balancer]\nmu = 0.2\n[springs]\nstiffness = 1.0\nlayout = 'star'\n", "spring_layout"),
    ("[balancer]\nmu = 0.2\n[ramp]\nstart = 1.0\n", "ramp.to"),
    ("[balancer]\nmu = 0.2\n[ramp]\nto = 2.0\nduration = 0.0\n", "ramp.duration"),
    ("[balancer]\nmu = 2.0\n", "mu"),
    ("mu = 'x'\n", "mu"),
    ("[balancer]\nmu = 0.2\n[gravity]\ng = -1.0\n", "gravity"),
    ("[balancer]\neta = [1.0]\n[springs]\nstiffness = 0.1\n", "springs"),
    ("mu = 0.2\n[balancer]\nzeta = 0.1\n", "mu"),
    ("mu = = 1\n", "path"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\nj_z = 0.7\n", "tilt.j_z"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 0.0\nb = 2.0\nj_t = 0.3\nj_z = 0.1\n", "tilt.a"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\n", "tilt.j_z"),
    ("[balancer]\nmu = 0.2\n[tilt]\na = 1.0\nb = 2.0\nj_t = 0.3\nj_z = 0.1\nJ = 1\n",
     "tilt.J"),
])
def test_malformed_scene_files_say_what_is_wrong(tmp_path, text, parameter):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(ballbal.exceptions.ParameterError) as info:
        ballbal.load_scene(p)
    assert info.value.parameter == parameter, str(info.value)


values = st.one_of(st.floats(allow_nan=True), st.integers(-3, 3), st.text(max_size=3),
                   st.sampled_from(["ring", "chain"]),
                   st.booleans(), st.lists(st.floats(0.1, 2.0), max_size=3))
keys = st.sampled_from(["mu", "zeta", "zeta_b", "delta", "Omega", "eta", "balls", "k", "x"])
tables = st.sampled_from(["springs", "ramp", "gravity", "impulse", "tilt", "balancer",
                          "bearing"])
inner = st.dictionaries(st.sampled_from(["stiffness", "to", "start", "duration", "g",
                                         "amplitude", "t0", "sharpness", "angle", "a", "b",
                                         "j_t", "j_z", "zeta_r", "mu", "q", "layout"]),
                        values, max_size=5)


@settings(max_examples=150, deadline=None)
@given(st.dictionaries(keys, values, max_size=6), st.dictionaries(tables, inner, max_size=3))
def test_random_scene_dictionaries_give_a_scene_or_a_clear_error(flat, tabs):
    d = {**flat, **tabs}
    try:
        sc = scene_from_dict(d)
    except ValueError as e:
        assert str(e) and ":" in str(e)
        return
    assert isinstance(sc, ballbal.Scene)
    assert scene_from_dict(sc.to_dict()) == sc
