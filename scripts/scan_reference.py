"""Save, or compare, scan reference tables for the scan-speed work (issue 17).

    python scripts/scan_reference.py save DIR      # with the build before the change
    python scripts/scan_reference.py compare DIR   # with the build after it

Saved as Parquet: Tien (2011) grid (Omega 1.0-2.0, eta 0.4-1.5, step 0.1; mu 0.2,
delta 50, N 3, R-R / O-O / R-O) for all nine zeta x zeta_b maps of Tien (2011) (zeta in
{0.02, 0.05, 0.1}, zeta_b in {0.05, 0.1, 0.2}), and the fine grid (101 x 111, step 0.01,
R-R, N 3, zeta = zeta_b = 0.05).

``compare`` checks, per table, on the rows keyed by (grid point, type, orbit): a new
row is paired with the reference row of its point and type whose omega is nearest
(within ``MATCH_TOL``), since new orbits renumber the others:

* no solution lost: every key converged in the reference is converged now; new ones
  (solutions a scan used to miss) are listed, allowed;
* the same verdicts (``stability``), except rows whose certificate now says
  ``undetermined`` and rows that were ``undetermined`` and are now settled (both listed,
  allowed);
* rows that the verdict's error bound refined to more harmonics (``N`` differs) are
  listed and left out of the omega and multiplier comparison below;
* omega within 1e-8, multipliers within 1e-5 relative to ``max(1, |multiplier|)``
  (sorted by modulus, then angle: a strongly unstable orbit's multipliers of modulus
  1e3 carry the integration's relative error, not an absolute one), on converged rows;
  multipliers missing on one side only where the new verdict is ``undetermined`` (a
  Floquet estimate that failed its certificate);

A reference O-O row whose series is at round-off (``tail`` below 1e-12: an equilibrium,
which solves the equations at any omega) is refused by the certificate added on
2026-11-24 (status ``equilibrium``): such rows are listed as refused, not lost, and the
remaining solutions at their point are renumbered in their order before the comparison;
a converged O-O row at round-off in the new table is a failure.

It prints a summary per table (rows, converged, stable, verdict changes, max
differences) to quote. Exit status 1 if any check fails.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import polars as pl

import ballbal

MAP_GRID = {"Omega": (1.0, 2.0, 0.1), "eta": (0.4, 1.5, 0.1)}
FINE = {"Omega": (1.0, 2.0, 0.01), "eta": (0.4, 1.5, 0.01)}
ZETAS, ZETA_BS = (0.02, 0.05, 0.1), (0.05, 0.1, 0.2)
PATTERNS = ("R-R", "O-O", "R-O")
OMEGA_TOL, MULT_TOL = 1e-8, 1e-5
# Same orbit in both tables: omega within this (relative; a row the bound refined to
# more harmonics moves by its truncation error, below 1e-4 on the Tien (2011) grids).
MATCH_TOL = 1e-4
KEY = ["Omega", "eta", "type", "solution"]
STILL_TAIL = 1e-12


def tables() -> dict[str, tuple[ballbal.Balancer, dict, tuple[str, ...]]]:
    out = {}
    for z in ZETAS:
        for zb in ZETA_BS:
            b = ballbal.Balancer(mu=0.2, zeta=z, zeta_b=zb, delta=50.0)
            out[f"thesis_z{z}_zb{zb}"] = (b, MAP_GRID, PATTERNS)
    out["fine_rr"] = (ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50.0), FINE,
                      ("R-R",))
    return out


def run(name: str) -> pl.DataFrame:
    b, grid, pats = tables()[name]
    return ballbal.scan(b, patterns=list(pats), N=3, **grid)


def _sorted_multipliers(m: list | None) -> np.ndarray:
    if m is None:
        return np.zeros(0, dtype=complex)
    z = np.array([d["re"] + 1j * d["im"] for d in m])
    return z[np.lexsort((np.angle(z), np.abs(z)))]


def _keyed(df: pl.DataFrame) -> pl.DataFrame:
    return df.with_columns(pl.col("Omega").round(9), pl.col("eta").round(9))


def _still() -> pl.Expr:
    return ((pl.col("status") == "converged") & (pl.col("type") == "O-O")
            & (pl.col("tail") < STILL_TAIL))


def _renumbered(df: pl.DataFrame) -> pl.DataFrame:
    return df.with_columns(
        (pl.col("solution").rank("ordinal").over(["Omega", "eta", "type"]) - 1)
        .cast(pl.Int64).alias("solution"))


def _matched(rc: pl.DataFrame, nc: pl.DataFrame) -> pl.DataFrame:
    """``nc`` with each row's ``solution`` replaced by the number of the reference row
    of its point and type that is the same orbit (nearest omega, within ``MATCH_TOL``
    relative, one to one), or by a number above every reference one if none is: new
    orbits of a type renumber the others (rows are ordered by omega), so the solution
    number alone would pair different orbits."""
    groups = ["Omega", "eta", "type"]
    ref_of: dict[tuple, list[tuple[int, float]]] = {}
    for r in rc.select([*groups, "solution", "omega"]).iter_rows():
        ref_of.setdefault(r[:3], []).append((r[3], r[4]))
    numbers = []
    fresh = 1000
    taken: dict[tuple, set[int]] = {}
    for r in nc.select([*groups, "omega"]).iter_rows():
        g, w = r[:3], r[3]
        used = taken.setdefault(g, set())
        best = min(((abs(w - wr), k) for k, wr in ref_of.get(g, []) if k not in used),
                   default=None)
        if best is not None and best[0] <= MATCH_TOL * max(1.0, abs(w)):
            used.add(best[1])
            numbers.append(best[1])
        else:
            numbers.append(fresh)
            fresh += 1
    return nc.with_columns(pl.Series("solution", numbers, dtype=nc["solution"].dtype))


def compare_table(name: str, ref: pl.DataFrame, new: pl.DataFrame) -> tuple[bool, str]:
    ref, new = _keyed(ref), _keyed(new)
    refused = ref.filter(_still())
    still_new = new.filter(_still())
    ref = _renumbered(ref.filter(~_still()))
    rc = ref.filter(pl.col("status") == "converged")
    nc = _matched(rc, new.filter(pl.col("status") == "converged"))
    lost = rc.join(nc, on=KEY, how="anti")
    gained = nc.join(rc, on=KEY, how="anti")
    both = rc.join(nc, on=KEY, how="inner", suffix="_new")
    changed = both.filter(pl.col("stability") != pl.col("stability_new"))
    undetermined = changed.filter(pl.col("stability_new") == "undetermined")
    settled = changed.filter(pl.col("stability") == "undetermined")
    bad_verdicts = changed.filter((pl.col("stability_new") != "undetermined")
                                  & (pl.col("stability") != "undetermined"))
    # Rows the verdict's bound refined to more harmonics carry that series' omega and
    # multipliers: compared only at the harmonics both tables used.
    refined = both.filter(pl.col("N_new") != pl.col("N"))
    both = both.filter(pl.col("N_new") == pl.col("N"))
    d_omega = float((both["omega"] - both["omega_new"]).abs().max() or 0.0)
    d_mult = 0.0
    mult_missing = 0
    for a, c, v in zip(both["multipliers"].to_list(), both["multipliers_new"].to_list(),
                       both["stability_new"].to_list(), strict=True):
        x, y = _sorted_multipliers(a), _sorted_multipliers(c)
        if x.size != y.size:
            mult_missing += v != "undetermined"
            continue
        if x.size:
            d_mult = max(d_mult, float((np.abs(x - y) / np.maximum(1.0, np.abs(x))).max()))
    ok = (lost.height == 0 and bad_verdicts.height == 0
          and d_omega <= OMEGA_TOL and d_mult <= MULT_TOL and mult_missing == 0
          and still_new.height == 0 and ref.height <= new.height)
    stable_r = int((rc["stability"] == "stable").sum())
    stable_n = int((nc["stability"] == "stable").sum())
    lines = [f"{name:<22} rows {ref.height:>6}/{new.height:<6} converged {rc.height:>5}/"
             f"{nc.height:<5} stable {stable_r:>5}/{stable_n:<5} lost {lost.height} "
             f"new {gained.height} verdicts changed {changed.height} "
             f"(undetermined {undetermined.height}, settled {settled.height}) "
             f"refined {refined.height} max|d omega| {d_omega:.1e} "
             f"max|d mult| {d_mult:.1e} refused as equilibria {refused.height}"
             f"{'' if ok else '  FAIL'}"]
    for label, rows in (("lost", lost), ("new", gained), ("verdict", bad_verdicts),
                        ("now undetermined", undetermined), ("settled", settled),
                        ("refused", refused),
                        ("converged at round-off", still_new)):
        for r in rows.head(10).iter_rows(named=True):
            lines.append(f"    {label}: Omega {r['Omega']} eta {r['eta']} {r['type']} "
                         f"#{r['solution']} {r['stability']}"
                         + (f" -> {r['stability_new']}" if "stability_new" in r else ""))
    if mult_missing:
        lines.append(f"    multipliers present in one table only: {mult_missing} rows")
    return ok, "\n".join(lines)


def main() -> None:
    if len(sys.argv) != 3 or sys.argv[1] not in ("save", "compare"):
        sys.exit(__doc__)
    mode, d = sys.argv[1], Path(sys.argv[2])
    d.mkdir(parents=True, exist_ok=True)
    all_ok = True
    for name in tables():
        t = time.perf_counter()
        df = run(name)
        dt = time.perf_counter() - t
        path = d / f"{name}.parquet"
        if mode == "save":
            df.write_parquet(path)
            conv = df.filter(pl.col("status") == "converged")
            print(f"saved {name:<22} rows {df.height:>6} converged {conv.height:>5} "
                  f"({dt:.1f} s)")
        else:
            ok, text = compare_table(name, pl.read_parquet(path), df)
            all_ok &= ok
            print(text, flush=True)
    if mode == "compare":
        print("all tables within the rules" if all_ok else "SOME TABLES DIFFER")
        sys.exit(0 if all_ok else 1)


if __name__ == "__main__":
    main()
