"""Scans of autonomous scenes (ball springs, a tilting disk): checked against the plain
balancer they reduce to, and against time simulation of the attractors they report."""

import subprocess
import sys

import numpy as np
import polars as pl
import pytest

import ballbal

OMEGAS = [1.15, 1.2, 1.25]
SPRINGS = ballbal.Scene(springs=1e-5)
OFF_CENTRE = ballbal.Scene(tilt=ballbal.Tilt(a=1.8, b=2.2, j_t=0.15, j_z=0.25, zeta_r=0.05))


def test_spring_scene_scan_at_zero_stiffness_holds_the_plain_balancers_orbits():
    plain = ballbal.scan(SPRINGS.balancer, Omega=OMEGAS, threads=2)
    df = ballbal.scan(SPRINGS, Omega=OMEGAS, springs=[0.0, 1e-5], threads=2)
    assert df.drop("seconds").equals(
        ballbal.scan(SPRINGS, Omega=OMEGAS, springs=[0.0, 1e-5], threads=1).drop("seconds"))
    zero = df.filter((pl.col("springs") == 0.0) & (pl.col("status") == "converged"))
    found = plain.filter(pl.col("status") == "converged")
    assert found.height == len(OMEGAS)
    for row in found.iter_rows(named=True):
        twin = zero.filter((pl.col("Omega") == row["Omega"])
                           & ((pl.col("omega") - row["omega"]).abs() < 1e-9))
        assert twin.height == 1, row
        assert twin["stability"][0] == row["stability"]
        assert twin["max_modulus"][0] == pytest.approx(row["max_modulus"], rel=1e-6)
        assert twin["pb_stable"][0] == row["pb_stable"]
    # The springs move the orbit: the comparison above is not trivially true.
    stiff = df.filter((pl.col("springs") == 1e-5) & (pl.col("stability") == "stable"))
    shift = stiff.join(found, on="Omega")
    assert shift.height == len(OMEGAS)
    assert (shift["omega"] - shift["omega_right"]).abs().min() > 1e-3


def _simulated_ball_rate(scene, t_settle=1000.0, t_end=2000.0):
    """The balls' mean speed on the attractor reached from simulate()'s default start,
    averaged with a Hann window (a periodic part leaks only ~1/T^2 into the mean)."""
    t = np.linspace(t_settle, t_end, 10001)
    r = ballbal.simulate(scene, t_eval=np.concatenate([[0.0], t]), t0=0.0, rtol=1e-9)
    w = np.hanning(t.size)
    n = scene.n_balls
    return [float(np.sum(w * r["d" + c].to_numpy()[1:]) / w.sum())
            for c in scene.coordinates[-n:]]


@pytest.mark.parametrize("scene", [SPRINGS, OFF_CENTRE], ids=["springs", "tilt"])
def test_stable_orbits_of_a_scene_scan_are_the_simulated_attractors(scene):
    """An R-R orbit of frequency omega carries each ball once round the disk per period,
    against the spin: on it every ball's mean speed is -omega."""
    df = ballbal.scan(scene, Omega=OMEGAS[:2], threads=2)
    stable = df.filter(pl.col("stability") == "stable")
    assert stable["Omega"].to_list() == OMEGAS[:2]
    for row in stable.iter_rows(named=True):
        rates = _simulated_ball_rate(scene.replace(Omega=row["Omega"]))
        assert np.allclose(rates, -row["omega"], atol=1e-5), (row["omega"], rates)
    # Different from the plain balancer's orbit, so the effect is really in the scan.
    plain = ballbal.scan(scene.balancer, Omega=OMEGAS[:2], threads=2)
    assert (stable["omega"] - plain["omega"]).abs().min() > 2e-3


def test_a_scene_without_effects_can_scan_into_them():
    """A scan may switch an effect on: springs from 0 on a scene that has none."""
    a = ballbal.scan(ballbal.Scene(balancer=SPRINGS.balancer), Omega=[1.2],
                     springs=[0.0, 1e-5], threads=1)
    b = ballbal.scan(SPRINGS, Omega=[1.2], springs=[0.0, 1e-5], threads=1)
    assert a.drop("seconds").equals(b.drop("seconds"))
    assert a.filter(pl.col("springs") == 1e-5)["omega"].is_not_null().all()


def test_scene_axes_and_time_dependent_scenes_give_clear_errors(tmp_path):
    with pytest.raises(ValueError, match=r"^j_t: is a tilt parameter"):
        ballbal.scan(SPRINGS, Omega=[1.2], j_t=[0.1])
    with pytest.raises(ValueError, match=r"^springs: is not a parameter of the planar"):
        ballbal.scan(SPRINGS.balancer, Omega=[1.2], springs=[1e-5])
    with pytest.raises(ValueError, match=r"^tilt\.j_z: must be in \[0, 2 j_t\]"):
        ballbal.scan(OFF_CENTRE, Omega=[1.2], j_z=[0.2, 0.4])
    with pytest.raises(ValueError, match=r"^scan: .*'ramp'"):
        ballbal.scan(SPRINGS.replace(ramp=ballbal.Ramp(to=2.0)), Omega=[1.2])
    # A stored scan remembers its scene: another stiffness does not resume it.
    ballbal.scan(SPRINGS, Omega=[1.2], out=tmp_path / "s")
    with pytest.raises(ballbal.exceptions.ScanStoreError, match="differs in scene"):
        ballbal.scan(SPRINGS.replace(springs=2e-5), Omega=[1.2], out=tmp_path / "s")


def test_command_line_takes_scene_files(tmp_path):
    scene = tmp_path / "tilt.toml"
    OFF_CENTRE.replace(springs=1e-4, spring_layout="chain").save(scene)
    exe = [sys.executable, "-m", "ballbal.cli"]
    r = subprocess.run(exe + ["equilibria", "--scene", str(scene), "--Omega", "1.5"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "q = (x, y, A, B, b1, b2)" in r.stdout and "balanced" in r.stdout
    want = ballbal.balanced_state(ballbal.load_scene(scene).replace(Omega=1.5))
    line = next(x for x in r.stdout.splitlines() if x.strip().startswith("balanced"))
    printed = [float(v) for v in line.split("q=(")[1].split(")")[0].split(",")]
    assert np.allclose(printed, want.q, atol=1e-4)
    out = tmp_path / "scan"
    r = subprocess.run(exe + ["scan", str(scene), "--Omega", "1.15:1.2:0.05", "--grid",
                              "springs=0:1e-4:1e-4", "-o", str(out), "--no-progress"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    df = ballbal.read_scan(out)
    assert set(df["springs"]) == {0.0, 1e-4} and (df["status"] == "converged").any()
    assert ballbal.scan_meta(out)["scene"]["springs"]["layout"] == "chain"
    r = subprocess.run(exe + ["equilibria", "--scene", str(scene), "--balls", "3"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "balls: the scene file sets the balls" in r.stderr
