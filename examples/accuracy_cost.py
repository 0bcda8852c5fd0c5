"""Accuracy against cost
=====================

What accuracy costs in time, at Tien's (2011) standard case (Omega 1.2, eta 1.0) and its
hard case (Omega 1.0, eta 0.7: slow rotation, period about 106, near resonance). The
Floquet multipliers' cost is shown for both monodromy methods: RK45 (knob ``rtol``) and
sixth-order Magnus steps (knob ``magnus``), at the same multiplier errors.

    python examples/accuracy_cost.py [output-directory]     # under a minute a point

Prints the tables and writes accuracy_cost.png (error against time, one curve per knob,
with the Pareto front) and the tables as Parquet.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402

import ballbal  # noqa: E402

# BALLBAL_EXAMPLE_SMALL=1 (tests/test_examples.py): the standard case with a few settings
# per knob, written into a temporary directory unless one is given.
SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"

CASES = {
    "standard (Omega 1.2, eta 1.0)": ballbal.Balancer(Omega=1.2, eta=(1.0, 1.0)),
    "hard (Omega 1.0, eta 0.7)": ballbal.Balancer(Omega=1.0, eta=(0.7, 0.7)),
}
KNOBS: dict[str, Any] = {}
if SMALL:
    CASES = dict(list(CASES.items())[:1])
    KNOBS = {"N": (2, 4), "samples": (8,), "tol": (1e-7,), "rtol": (1e-6,),
             "magnus_rtol": (1e-6,), "base_N": 6,
             "reference_N": 10, "repeats": 1}


def main() -> None:
    default = tempfile.mkdtemp(prefix="accuracy_cost-") if SMALL else "accuracy_cost"
    out = Path(sys.argv[1] if len(sys.argv) > 1 else default)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, len(CASES), figsize=(6.5 * len(CASES), 4.8), squeeze=False)
    pl.Config.set_tbl_rows(40)
    pl.Config.set_tbl_cols(12)
    for ax, (name, b) in zip(axes[0], CASES.items(), strict=True):
        df = ballbal.accuracy_cost(b, "R-R", **KNOBS)
        df.write_parquet(out / f"{name.split()[0]}.parquet")
        print(f"\n{name}: reference closure by simulation "
              f"{df['reference_closure'][0]:.1e}")
        print(df.select("knob", "value", "seconds", "iterations", "floquet_steps",
                        "omega_error", "multiplier_error", "trivial_error", "verdict_ok")
              .with_columns((pl.col("seconds") * 1e6).round(0).alias("µs"))
              .drop("seconds"))
        ballbal.plot_accuracy_cost(df, ax=ax, title=name)
    fig.tight_layout()
    fig.savefig(out / "accuracy_cost.png", dpi=110)
    print(f"\nfigure and tables in {out}/")


if __name__ == "__main__":
    main()
