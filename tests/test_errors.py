"""Every bad input is a ballbal.exceptions class naming its parameter (issue 13): one
test per input that used to give another exception type, a message without the name,
or no error at all."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ballbal as bb
from ballbal.exceptions import (
    IntegrationError,
    NotAutonomousError,
    ParameterError,
    ParameterTypeError,
)

B = bb.Balancer()


def raises(exc: type[BaseException], parameter: str, f: Any, *args: Any,
           **kw: Any) -> ParameterError:
    with pytest.raises(exc) as info:
        f(*args, **kw)
    e = info.value
    assert isinstance(e, ParameterError), repr(e)
    assert e.parameter == parameter, (e.parameter, str(e))
    return e


#: The option class that holds each option (the options are passed as these).
OPTION = {"max_iter": bb.HarmonicBalance, "N_max": bb.HarmonicBalance,
          "samples": bb.HarmonicBalance, "tol": bb.HarmonicBalance,
          "step_tol": bb.HarmonicBalance, "target": bb.HarmonicBalance,
          "max_steps": bb.Floquet, "rtol": bb.Floquet, "margin": bb.Floquet,
          "seeds": bb.GuessSearch, "starts": bb.GuessSearch, "settle": bb.GuessSearch,
          "window": bb.GuessSearch}

# --- counts: negative values were OverflowError, non-integers were truncated ---------

@pytest.mark.parametrize("kw", ["max_iter", "max_steps", "N_max", "samples"])
@pytest.mark.parametrize("value", [-1, 2.5, True, "3", 2**70])
def test_periodic_counts(kw: str, value: Any) -> None:
    exc = ParameterTypeError if not isinstance(value, int) or isinstance(value, bool) \
        else ParameterError
    raises(exc, kw, OPTION[kw], **{kw: value})


@pytest.mark.parametrize("value", [-1, 0, 257, 2.0, True])
def test_periodic_N(value: Any) -> None:
    raises(ParameterError, "N", bb.periodic, B, "R-R", N=value)


@pytest.mark.parametrize("kw", ["seeds", "starts", "threads", "chunk", "max_iter", "N_max",
                                "max_steps", "samples"])
@pytest.mark.parametrize("value", [-1, 1.5, False])
def test_scan_counts(kw: str, value: Any) -> None:
    if kw in OPTION:  # refused when the option is made
        raises(ParameterError, kw, OPTION[kw], **{kw: value})
    else:
        raises(ParameterError, kw, bb.scan, B, Omega=[1.2], **{kw: value})


def test_scan_threads_upper_bound() -> None:
    raises(ParameterError, "threads", bb.scan, B, Omega=[1.2], threads=10**6)


# --- numbers: strings and None gave messages without the parameter's name ------------

@pytest.mark.parametrize("kw", ["rtol", "tol", "step_tol", "margin", "settle", "window",
                                "target"])
@pytest.mark.parametrize("value", ["abc", None, [1e-8]])
def test_periodic_reals(kw: str, value: Any) -> None:
    raises(ParameterTypeError, kw, OPTION[kw], **{kw: value})


@pytest.mark.parametrize("kw", ["rtol", "atol", "t0"])
def test_simulate_reals(kw: str) -> None:
    raises(ParameterTypeError, kw, bb.simulate, B, t_eval=[0.0, 1.0], **{kw: "x"})


def test_simulate_arrays_named() -> None:
    raises(ParameterTypeError, "y0", bb.simulate, B, ["a"] * 8, t_eval=[0.0, 1.0])
    raises(ParameterTypeError, "t_eval", bb.simulate, B, None, ["x", "y"])


@pytest.mark.parametrize("field", ["mu", "zeta", "delta", "Omega"])
def test_balancer_fields(field: str) -> None:
    raises(ParameterTypeError, field, bb.Balancer, **{field: "1.0"})
    raises(ParameterTypeError, field, bb.Balancer, **{field: None})
    raises(ParameterError, field, bb.Balancer, **{field: 10**400})


def test_balancer_eta_entry_named() -> None:
    raises(ParameterTypeError, "eta", bb.Balancer, eta=[1.0, "x"])
    raises(ParameterError, "eta", B.replace, eta="1")


def test_unknown_field_is_named() -> None:
    # dataclasses.replace raised TypeError("unexpected keyword argument").
    raises(ParameterError, "Omgea", B.replace, Omgea=1.0)
    raises(ParameterError, "Omgea", bb.Scene().replace, Omgea=1.0)


# --- the model argument: None gave AttributeError ----------------------------------

@pytest.mark.parametrize("f", [bb.simulate, bb.equilibria, bb.periodic, bb.balanced_state,
                               bb.run_up])
@pytest.mark.parametrize("value", [None, "balancer", 1.0])
def test_model_argument(f: Any, value: Any) -> None:
    # The first argument is called "model" in every analysis.
    name = "model"
    kw: dict[str, Any] = {"to": 2.0, "duration": 1.0} if f is bb.run_up else {}
    if f is bb.simulate:
        kw["t_eval"] = [0.0]
    raises(ParameterTypeError, name, f, value, **kw)


def test_model_argument_of_maps() -> None:
    raises(ParameterTypeError, "model", bb.scan, None, Omega=[1.2])
    raises(ParameterTypeError, "model", bb.balance_map, None, Omega=[1.2])
    raises(ParameterTypeError, "model", bb.disturbance_response, None, 2.0)


# --- times: dt = 0 was ZeroDivisionError, t_span = (0, inf) blamed t_eval ------------

def test_dt_zero() -> None:
    raises(ParameterError, "dt", bb.disturbance_response, B, 2.0, dt=0.0)
    raises(ParameterError, "dt", bb.run_up, bb.Scene(), 2.0, 1.0, dt=0.0)


@pytest.mark.parametrize("span", [(0, math.inf), (0, math.nan), (0, 0)])
def test_t_span_values(span: tuple[float, float]) -> None:
    raises(ParameterError, "t_span", bb.simulate, B, t_span=span)


@pytest.mark.parametrize("span", [(0, 1, 2), (1,), ()])
def test_t_span_not_a_pair(span: tuple[float, ...]) -> None:
    # (0, 1, 2) used to run from 0 to 1 without a word.
    raises(ParameterError, "t_span", bb.simulate, B, t_span=span)


def test_t_span_types() -> None:
    raises(ParameterTypeError, "t_span", bb.simulate, B, t_span="0:1")
    raises(ParameterTypeError, "t_span", bb.simulate, B, t_span=(0, "1"))


# --- simulate's step budget --------------------------------------------------------

def test_simulate_max_steps_is_a_keyword() -> None:
    # Tien (2011) start's balls rotate with period ~5: 1e4 time units need far more
    # than 100 steps, so the budget runs out, with a message naming the keyword.
    with pytest.raises(IntegrationError, match="max_steps"):
        bb.simulate(B, t_eval=[0.0, 1e4], max_steps=100)
    df = bb.simulate(B, t_eval=[0.0, 1.0], max_steps=10_000)
    assert df.height == 2
    raises(ParameterError, "max_steps", bb.simulate, B, t_eval=[0.0, 1.0], max_steps=0)
    raises(ParameterError, "max_steps", bb.simulate, B, t_eval=[0.0, 1.0], max_steps=-5)


def test_simulate_huge_span_ends_at_the_budget() -> None:
    with pytest.raises(IntegrationError):
        bb.simulate(B, t_span=(0.0, 1e300), max_steps=1000)


# --- patterns ---------------------------------------------------------------------

@pytest.mark.parametrize("pattern", ["RR", "r-r", " R-R ", "R_R", "R--R"])
def test_pattern_canonical_form(pattern: str) -> None:
    e = raises(ParameterError, "pattern", bb.periodic, B, pattern,
               options=bb.PeriodicOptions(floquet=bb.Floquet(monodromy=False)))
    assert '"R-R"' in str(e)  # shows the canonical form


def test_pattern_type() -> None:
    raises(ParameterTypeError, "pattern", bb.periodic, B, None)
    raises(ParameterTypeError, "patterns", bb.scan, B, Omega=[1.2], patterns=[1])


def test_duplicated_patterns() -> None:
    raises(ParameterError, "patterns", bb.scan, B, Omega=[1.2], patterns=["R-R", "R-R"])


def test_scan_pattern_canonical_form() -> None:
    raises(ParameterError, "pattern", bb.scan, B, Omega=[1.2], patterns=["rr"])


# --- out= and grid limits -----------------------------------------------------------

def test_empty_out(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    raises(ParameterError, "out", bb.scan, B, Omega=[1.2], out="")
    raises(ParameterTypeError, "out", bb.scan, B, Omega=[1.2], out=3)
    assert os.listdir(tmp_path) == []


def test_grid_limits() -> None:
    # 1e12 points: refused before any value is made (was MemoryError).
    raises(ParameterError, "Omega", bb.scan, B, Omega=(1.0, 2.0, 1e-12))
    raises(ParameterError, "Omega", bb.scan, B, Omega=(0.0, 1e300, 1e-300))
    big = np.linspace(1.0, 2.0, 10_000)
    e = raises(ParameterError, "Omega", bb.scan, B, Omega=big, eta=big[:1000] - 0.5)
    assert e.allowed is not None


def test_balance_map_limits_and_axes() -> None:
    raises(ParameterError, "Omgea", bb.balance_map, B, Omgea=[1.0])
    raises(ParameterError, "a", bb.balance_map, B, a=[1.0])
    raises(ParameterError, "Omega", bb.balance_map, B, Omega="1.0")  # a string is a range
    big = np.linspace(1.0, 2.0, 3000)
    raises(ParameterError, "Omega", bb.balance_map, B, Omega=big, eta=big)


def test_run_up_duration_limit() -> None:
    raises(ParameterError, "duration", bb.run_up, bb.Scene(), 2.0, 1e12)
    raises(ParameterError, "t_end", bb.disturbance_response, B, 2.0, t_end=1e12)


def test_run_up_takes_a_balancer() -> None:
    # It raised TypeError about 'ramp': a Balancer runs up as a scene without effects.
    b = bb.Balancer(Omega=0.5)
    r = bb.run_up(b, 0.6, 1.0, settle=1.0, dt=0.5)
    s = bb.run_up(bb.Scene(balancer=b), 0.6, 1.0, settle=1.0, dt=0.5)
    assert r.trajectory.equals(s.trajectory)


def test_disturbance_needs_autonomous_scene() -> None:
    sc = bb.Scene(gravity=0.1)
    with pytest.raises(NotAutonomousError) as info:
        bb.disturbance_response(sc, 2.0)
    assert info.value.effect == "gravity"


# --- scene files -----------------------------------------------------------------

def _file(tmp_path: Path, data: bytes) -> Path:
    p = tmp_path / "scene.toml"
    p.write_bytes(data)
    return p


@pytest.mark.parametrize("data", [
    b"\x00\xff\xfe\x89PNG\r\n",
    "Omega = 1.3\n".encode("utf-16"),
    b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    b"x = " + b"{y = " * 3000 + b"1" + b"}" * 3000 + b"\n",
    b"Omega = \n",
    b"",
    b"# only a comment\n",
])
def test_bad_scene_files(tmp_path: Path, data: bytes) -> None:
    raises(ParameterError, "path", bb.load_scene, _file(tmp_path, data))


def test_missing_scene_file(tmp_path: Path) -> None:
    raises(ParameterError, "path", bb.load_scene, tmp_path / "nope.toml")
    raises(ParameterError, "path", bb.load_scene, tmp_path)
    raises(ParameterError, "path", bb.load_scene, "")
    raises(ParameterTypeError, "path", bb.load_scene, None)


@pytest.mark.parametrize("text, parameter", [
    ("Omgea = 1.2\n", "Omgea"),
    ("[balancer]\nOmega = 1.2\n[rampp]\nto = 2\n", "rampp"),
    ("Omega = 1.2\n[ramp]\nto = 2\nspeed = 3\n", "ramp.speed"),
    ("Omega = 1.2\n[ramp]\nstart = 2\n", "ramp.to"),
    ("Omega = 'fast'\n", "Omega"),
    ("balls = 0\n", "balls"),
    ("balls = 2.5\n", "balls"),
    ("balls = 100000000\n", "balls"),
    ("eta = [1, 'x']\n", "eta"),
    ("springs = 1.0\n", "springs"),
    ("[balancer]\nOmega = 1.2\n[springs]\nstiffness = -1\n", "springs"),
    ("[balancer]\nOmega = 1.2\n[tilt]\na = 1\nb = 1\nj_t = 0.1\nj_z = 5\n", "tilt.j_z"),
])
def test_scene_file_keys(tmp_path: Path, text: str, parameter: str) -> None:
    raises(ParameterError, parameter, bb.load_scene, _file(tmp_path, text.encode()))


# --- the command line -------------------------------------------------------------

def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballbal.cli", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


def assert_usage_error(r: subprocess.CompletedProcess[str], parameter: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr, r.stderr
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith(f"ballbal: error: {parameter}:"), r.stderr


def test_cli_missing_and_unreadable_files(tmp_path: Path) -> None:
    assert_usage_error(cli("equilibria", "--scene", str(tmp_path / "no.toml")), "scene")
    assert_usage_error(cli("equilibria", "--scene", str(tmp_path)), "scene")
    bad = _file(tmp_path, "Omega = 1".encode("utf-16"))
    assert_usage_error(cli("periodic", "--scene", str(bad)), "scene")
    assert_usage_error(cli("scan", str(tmp_path / "no.toml"), "--Omega", "1:1.1:0.1",
                           "-o", str(tmp_path / "o")), "scene")
    assert_usage_error(cli("plot", str(tmp_path / "none")), "scan_dir")


def test_cli_bad_out(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert_usage_error(cli("scan", "--Omega", "1.2:1.2:0.1", "-o", str(blocker / "sub"),
                           "--no-progress"), "out")
    assert_usage_error(cli("scan", "--Omega", "1.2:1.2:0.1", "-o", "", "--no-progress"), "out")


def test_cli_balls_zero() -> None:
    # --balls 0 meant 2 balls.
    assert_usage_error(cli("equilibria", "--balls", "0"), "balls")
    assert_usage_error(cli("equilibria", "--balls", "-3"), "balls")


def test_cli_argparse_errors_are_one_line() -> None:
    assert_usage_error(cli("periodic", "--N", "x"), "N")
    assert_usage_error(cli("periodic", "--zeta-b", "y"), "zeta_b")
    assert_usage_error(cli("scan", "--Omega", "1:2:0.5"), "out")
    assert_usage_error(cli("periodic", "--pattern", "rr"), "pattern")


def test_cli_plot_unknown_type(tmp_path: Path) -> None:
    out = tmp_path / "s"
    r = cli("scan", "--Omega", "1.2:1.3:0.1", "--eta", "1:1:0.1", "-o", str(out),
            "--no-progress", "--threads", "1")
    assert r.returncode == 0, r.stderr
    assert_usage_error(cli("plot", str(out), "--type", "X-X"), "type")
    assert_usage_error(cli("plot", str(out), "-o", str(tmp_path / "a.unknownext")), "out")
    assert not list(tmp_path.glob("*.png"))
