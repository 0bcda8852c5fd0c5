"""The command line's surface (issue 32): ``--version``, one spelling per option in
every subcommand, ``--eta`` meaning what ``Balancer(eta=...)`` means, and a non-zero
exit status when the asked-for solution is not found."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import ballbal


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ballbal.cli", *args], capture_output=True,
                          text=True, timeout=300, cwd=cwd)


def test_version() -> None:
    r = cli("--version")
    assert r.returncode == 0
    assert r.stdout.split() == ["ballbal", ballbal.__version__]


def test_a_solution_not_found_exits_1_with_a_message() -> None:
    # no start settles on an O-O orbit here (periodic() reports no_guess)
    assert ballbal.periodic(ballbal.Balancer(Omega=1.1, eta=(1.3, 1.3)), "O-O").status == (
        "no_guess")
    r = cli("periodic", "--pattern", "O-O", "--Omega", "1.1", "--eta", "1.3", "1.3")
    assert r.returncode == 1
    assert "no O-O solution found" in r.stderr and "no_guess" in r.stderr


def test_eta_is_one_value_per_ball() -> None:
    # one value: one ball, as Balancer(eta=1.3)
    r = cli("equilibria", "--Omega", "1.5", "--eta", "1.3")
    assert r.returncode == 0, r.stderr
    assert "eta=[1.3]" in r.stdout and "b2" not in r.stdout
    r = cli("equilibria", "--Omega", "1.5", "--eta", "1.3", "--balls", "3")
    assert r.returncode == 0, r.stderr
    assert "eta=[1.3, 1.3, 1.3]" in r.stdout


def test_one_spelling_per_option(tmp_path: Path) -> None:
    for sub in ("periodic", "equilibria", "scan"):
        assert "--zeta-b" in cli(sub, "--help").stdout, sub
        assert "--zeta_b" not in cli(sub, "--help").stdout, sub
    out = tmp_path / "s"
    r = cli("scan", "--Omega", "1.2:1.2:0.1", "--eta", "1.0:1.0:0.1", "--zeta-b", "0.1:0.1:0.1",
            "-o", str(out), "--no-progress")
    assert r.returncode == 0, r.stderr
    assert ballbal.read_scan(out)["zeta_b"].unique().to_list() == [0.1]
