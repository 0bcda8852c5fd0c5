"""What accuracy costs in time, at the thesis' standard case (Omega 1.2, eta 1.0) and its
hard case (Omega 1.0, eta 0.7: slow rotation, period about 106, near resonance).

    python examples/accuracy_cost.py [output-directory]     # under a minute a point

Prints the tables and writes accuracy_cost.png (error against time, one curve per knob,
with the Pareto front) and the tables as Parquet.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import polars as pl  # noqa: E402

import ballbal  # noqa: E402

CASES = {
    "standard (Omega 1.2, eta 1.0)": ballbal.Balancer(Omega=1.2, eta=(1.0, 1.0)),
    "hard (Omega 1.0, eta 0.7)": ballbal.Balancer(Omega=1.0, eta=(0.7, 0.7)),
}


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "accuracy_cost")
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    pl.Config.set_tbl_rows(40)
    pl.Config.set_tbl_cols(12)
    for ax, (name, b) in zip(axes, CASES.items(), strict=True):
        df = ballbal.accuracy_cost(b, "R-R")
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
