"""Groove study (ballbal._groove_study): checked against a plain finite-volume film written
here with scipy (the same conservative scheme, solved on the whole grid), central
differences of that film's force, and itself on 1 and 2 threads."""

from __future__ import annotations

import math

import numpy as np
import polars as pl
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ballbal._groove_study import groove_study, plot_groove_study
from ballbal.bearing import Bearing
from ballbal.exceptions import ParameterError

GRID = (64, 16)


def plain_force(lam: float, x: float, y: float, vx: float = 0.0, vy: float = 0.0,
                grid: tuple[int, int] = GRID) -> tuple[float, float]:
    """Half-Sommerfeld film force (units mu w L R^3 / c^2) of a plain bearing: cell-centred
    finite volumes, face conductances H^3 (the film at a theta face, the film averaged
    over a zeta face's theta span), Couette term 6 dz (H_e - H_w), squeeze 12 dH/dtau
    integrated over the cell, P = 0 half a cell beyond the ends; the full 2-D grid."""
    nt, nz = grid
    dth, dz = 2 * math.pi / nt, 2 * lam / nz
    th = np.arange(nt + 1) * dth
    s, c = np.sin(th), np.cos(th)
    hf = 1 - x * c[:nt] - y * s[:nt]                     # film at theta face i
    hc = 1 - x * np.diff(s) / dth + y * np.diff(c) / dth  # film averaged over cell i
    kt = hf**3 * dz / dth
    kz = hc**3 * dth / dz
    idx = np.arange(nt * nz).reshape(nt, nz)
    rows, cols, vals = [], [], []
    diag = np.zeros((nt, nz))
    for i in range(nt):
        ie = (i + 1) % nt
        for j in range(nz):
            # east theta face (face ie) couples (i, j) with (ie, j)
            rows += [idx[i, j], idx[ie, j]]
            cols += [idx[ie, j], idx[i, j]]
            vals += [-kt[ie], -kt[ie]]
            diag[i, j] += kt[ie]
            diag[ie, j] += kt[ie]
            if j + 1 < nz:
                rows += [idx[i, j], idx[i, j + 1]]
                cols += [idx[i, j + 1], idx[i, j]]
                vals += [-kz[i], -kz[i]]
                diag[i, j] += kz[i]
                diag[i, j + 1] += kz[i]
        diag[i, 0] += 2 * kz[i]
        diag[i, nz - 1] += 2 * kz[i]
    m = sp.csc_matrix((vals + list(diag.ravel()), (rows + list(idx.ravel()),
                                                    cols + list(idx.ravel()))),
                      shape=(nt * nz, nt * nz))
    he = np.roll(hf, -1)
    sq = -12 * dz * (vx * np.diff(s) - vy * np.diff(c))
    rhs = np.repeat(6 * dz * (he - hf) + sq, nz)
    p = np.maximum(spla.spsolve(m, -rhs), 0.0).reshape(nt, nz)
    col = p.sum(axis=1) * dz / (2 * lam)
    return float(-(col * np.diff(s)).sum()), float((col * np.diff(c)).sum())


def test_depth_zero_is_the_plain_film_and_its_central_differences() -> None:
    eps = 0.6
    df = groove_study(Bearing(grid=GRID), angle=[30.0], depth_ratio=[0.0, 1.0],
                      eccentricity=eps, threads=1)
    assert df["status"].to_list() == ["ok", "ok"]
    row = df.filter(pl.col("depth_ratio") == 0.0).row(0, named=True)
    fx, fy = plain_force(1.0, eps, 0.0)
    load = math.hypot(fx, fy)
    assert row["load"] == pytest.approx(load, rel=1e-10)
    # journal at +x: radial component -fx (towards the centre), tangential fy
    assert row["attitude"] == pytest.approx(math.degrees(math.atan2(fy, -fx)), abs=1e-8)
    assert row["sommerfeld"] == pytest.approx(1 / (math.pi * load), rel=1e-10)
    h = 1e-6
    for name, kw in [("kxx", {"x": eps + h}), ("kyx", {"x": eps + h}),
                     ("kxy", {"y": h}), ("kyy", {"y": h}),
                     ("cxx", {"vx": h}), ("cyx", {"vx": h}),
                     ("cxy", {"vy": h}), ("cyy", {"vy": h})]:
        plus = {"x": eps, "y": 0.0, "vx": 0.0, "vy": 0.0, **kw}
        key = next(iter(kw))
        minus = dict(plus, **{key: plus[key] - 2 * h})
        comp = 0 if name[1] == "x" else 1
        d = -(plain_force(1.0, **plus)[comp] - plain_force(1.0, **minus)[comp]) / (2 * h)
        assert row[name] == pytest.approx(d, rel=1e-5, abs=1e-6 * load), name


def test_grooves_give_concentric_direct_stiffness() -> None:
    df = groove_study(Bearing(grid=GRID), angle=[30.0], depth_ratio=[0.0, 1.0],
                      eccentricity=0.3, threads=1)
    plain = df.filter(pl.col("depth_ratio") == 0.0).row(0, named=True)
    grooved = df.filter(pl.col("depth_ratio") == 1.0).row(0, named=True)
    assert abs(plain["k_centre"]) < 1e-9 * abs(plain["k_centre_cross"])
    assert grooved["k_centre"] > 0.05 * abs(grooved["k_centre_cross"])


def test_same_table_on_one_and_two_threads() -> None:
    kw = dict(angle=[20.0, 50.0], depth_ratio=[0.5, 1.0], width_ratio=[0.5],
              length_ratio=[0.5, 1.0], count=[8], eccentricity=0.4)
    a = groove_study(Bearing(grid=GRID), threads=1, **kw)  # type: ignore[arg-type]
    b = groove_study(Bearing(grid=GRID), threads=2, **kw)  # type: ignore[arg-type]
    assert a.height == 8
    assert a.equals(b)


@pytest.mark.parametrize("axis,value", [
    ("angle", [0.0]), ("angle", [100.0]), ("depth_ratio", [-0.5]), ("width_ratio", [1.2]),
    ("length_ratio", [0.0]), ("count", [0]), ("angle", []), ("depth_ratio", "1.0"),
    ("eccentricity", 1.0), ("threads", 0),
])
def test_bad_axes_name_the_axis(axis: str, value: object) -> None:
    with pytest.raises(ParameterError) as e:
        groove_study(Bearing(grid=GRID), **{axis: value})  # type: ignore[arg-type]
    assert e.value.parameter == axis


def test_unresolved_groove_is_a_status_not_an_error() -> None:
    # 8 cells per pitch cannot hold a 5 % groove: that point fails, the other runs.
    df = groove_study(Bearing(grid=GRID), width_ratio=[0.05, 0.5], threads=1)
    assert df["status"][0] != "ok" and math.isnan(df["load"][0])
    assert df["status"][1] == "ok"


def test_plot_draws_one_line_per_value_of_the_other_axis() -> None:
    import matplotlib

    matplotlib.use("Agg")
    df = groove_study(Bearing(grid=GRID), angle=[30.0, 60.0], depth_ratio=[0.5, 1.0],
                      threads=1)
    fig = plot_groove_study(df, x="angle", y="k_centre")
    lines = fig.axes[0].get_lines()
    assert len(lines) == 2
    np.testing.assert_allclose(
        lines[1].get_ydata(),
        df.filter(pl.col("depth_ratio") == 1.0).sort("angle")["k_centre"].to_numpy())
    with pytest.raises(ParameterError):
        plot_groove_study(df, x="nope")
