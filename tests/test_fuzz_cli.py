"""Fuzzing the command line (issue 13): whatever the arguments, ``ballbal`` exits 0 (1 when
the solution asked for is not found), or
2 with one ``ballbal: error: <parameter>: ...`` line on stderr, and never prints a
traceback or a Rust panic. Valid settings are kept cheap (few balls, one-point scans)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_fuzz_api import NAMES

FUZZ = settings(max_examples=30, derandomize=True, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
LIMIT = 60.0  # seconds per command; the cheap commands here take about one

WORD = st.one_of(
    st.sampled_from(["1.2", "0.5", "-1", "0", "nan", "inf", "x", "", "1e400", "2.5", "3",
                     "R-R", "rr", "1:2:0.5", "1.2:1.2:0.1", "a:b:c", "--", "-o"]),
    st.text(alphabet="0123456789.-:eRO x", max_size=8))
FLAGS = ["--mu", "--zeta", "--zeta-b", "--delta", "--Omega", "--eta", "--balls", "--scene",
         "--pattern", "--N", "--types", "--threads", "--chunk", "--grid", "-o", "--type",
         "--bogus"]


def run(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballbal.cli", *args], capture_output=True,
                          text=True, timeout=LIMIT, cwd=cwd)


def check(args: list[str], cwd: Path, typed: set[str]) -> None:
    r = run(args, cwd)
    assert "Traceback" not in r.stderr, (args, r.stderr)
    assert "panicked" not in r.stderr and "PanicException" not in r.stderr, (args, r.stderr)
    assert r.returncode in (0, 1, 2), (args, r.returncode, r.stderr)
    if r.returncode == 1:  # only a solution not found, said in one line
        lines = [x for x in r.stderr.splitlines() if x.strip()]
        assert len(lines) == 1 and re.match(r"ballbal: no \S+ solution found", lines[0]), (
            args, r.stderr)
    if r.returncode == 2:
        lines = [x for x in r.stderr.splitlines() if x.strip()]
        assert len(lines) == 1, (args, r.stderr)
        m = re.match(r"ballbal: error: ([\w.\[\]-]+): ", lines[0])
        assert m, (args, lines[0])
        name = re.sub(r"\[\d+\]$", "", m.group(1))
        assert name in NAMES or name in typed, (args, lines[0])


def options(draw: st.DrawFn, flags: list[str]) -> list[str]:
    out: list[str] = []
    for _ in range(draw(st.integers(0, 3))):
        out.append(draw(st.sampled_from(flags)))
        out += draw(st.lists(WORD, min_size=0, max_size=2))
    return out


@st.composite
def periodic_args(draw: st.DrawFn) -> list[str]:
    cmd = draw(st.sampled_from(["periodic", "equilibria"]))
    # Few balls: equilibria of many balls are a search that takes long by itself.
    base = ["--balls", draw(st.sampled_from(["1", "2", "3"]))]
    return [cmd, *base, *options(draw, FLAGS)]


@st.composite
def scan_args(draw: st.DrawFn) -> list[str]:
    args = ["scan", "--Omega", draw(st.sampled_from(["1.2:1.2:0.1", "1.3", "x", "1:0:0.1"])),
            "--no-progress", "--threads", "1"]
    if draw(st.booleans()):
        args += ["-o", draw(st.sampled_from(["out", "", "file/sub", "out"]))]
    return args + options(draw, ["--eta", "--mu", "--types", "--N", "--chunk", "--grid",
                                 "--threads", "--bogus"])


@FUZZ
@given(st.one_of(periodic_args(), scan_args()))
def test_cli(tmp_path_factory: pytest.TempPathFactory, args: list[str]) -> None:
    cwd = tmp_path_factory.mktemp("cli")
    (cwd / "file").write_text("not a directory")
    (cwd / "scene.toml").write_text("Omega = 1.2\nballs = 2\n")
    (cwd / "bad.toml").write_bytes("Omega = 1.2".encode("utf-16"))
    typed = {"bogus", "grid", "types", "type"}
    check(args, cwd, typed)


@settings(FUZZ, max_examples=12)
@given(st.lists(st.sampled_from(["scene.toml", "bad.toml", "none.toml", "file", ".", "", "-x",
                                 "--type", "R-R", "X-X", "-o", "out.png", "out.nope",
                                 "file/x.png"]), max_size=4))
def test_cli_plot(tmp_path_factory: pytest.TempPathFactory, rest: list[str]) -> None:
    cwd = tmp_path_factory.mktemp("plot")
    (cwd / "file").write_text("x")
    (cwd / "scene.toml").write_text("Omega = 1.2\nballs = 2\n")
    (cwd / "bad.toml").write_bytes(b"\xff\xfe")
    check(["plot", *rest], cwd, {"x"})


def test_plot_without_matplotlib_is_one_line_naming_the_extra(tmp_path: Path) -> None:
    """Without matplotlib 'ballbal plot' printed a traceback. A package that fails to
    import stands in for the missing one."""
    import os

    shim = tmp_path / "shim" / "matplotlib"
    shim.mkdir(parents=True)
    (shim / "__init__.py").write_text("raise ImportError('No module named matplotlib')\n")
    path = [str(tmp_path / "shim"), *filter(None, [os.environ.get("PYTHONPATH")])]
    r = subprocess.run([sys.executable, "-m", "ballbal.cli", "plot", "out"],
                       capture_output=True, text=True, timeout=LIMIT, cwd=tmp_path,
                       env={**os.environ, "PYTHONPATH": os.pathsep.join(path)})
    assert "Traceback" not in r.stderr, r.stderr
    assert r.returncode == 2
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("ballbal: error: cmd: ")
    assert 'pip install "ballbal[plot]"' in lines[0]
