"""The experiments of [Tien2011] as data (chapter 4), and lab-side helpers.

Every experimental number of Tien's (2011) chapter 4 is here with its source (section,
table or figure), its unit and notes: :func:`experiments` returns them as one long
polars table, :func:`peaks` the spectral peaks of the measured records with the labels
Tien (2011) gives them, :func:`transitions` the measured critical speeds.

Tien's (2011) figures did not survive transcription: only numbers stated in its text and
tables are here. Where the text and a table disagree, or a stated number does not follow
from the others, both are kept and the notes say which reproduces.

Lab helpers: :func:`imbalance` (``m_d e``), :func:`eta` (``m_b r_t / (m_d e)``),
:func:`rpm_to_ratio` / :func:`ratio_to_rpm` (speeds against the natural frequency),
:func:`leaf_spring_stiffness` (the rig's support design, section 4-1-2) and
:func:`log_decrement` (section 4-4-6's fit of a free-decay record).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import polars as pl

from . import _check
from ._style import Summarised
from .exceptions import ParameterError, ParameterTypeError
from .model import zeta_from_log_decrement

__all__ = [
    "experiments", "peaks", "transitions", "imbalance", "eta", "rpm_to_ratio",
    "ratio_to_rpm", "leaf_spring_stiffness", "log_decrement", "LogDecrement",
    "NATURAL_FREQUENCY_RPM", "MODEL_PARAMETERS", "residual_imbalance", "single_ball",
]

#: The rig's measured first natural frequency without balls (section 4-1-2), rpm.
NATURAL_FREQUENCY_RPM = 513.0

#: The model parameters Tien (2011) compares with its rig (section 4-4-2, fig. 4-13: its
#: MIHB "at mu 0.2, zeta 0.05, zeta_b 0.05, delta 50" with f_n = 513 rpm). The rig's own
#: disk mass and support damping without pads are not stated.
MODEL_PARAMETERS: dict[str, float] = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0}

# (quantity, value, unit, case, source, notes)
_ROWS: list[tuple[str, float, str, str, str, str]] = [
    # 4-1-2: the rig
    ("system_mass", 362.1, "g", "rig", "4-1-2", "total mass M used in the design"),
    ("leaf_width", 14.0, "mm", "rig", "4-1-2", "L-shaped stainless leaf springs, four"),
    ("leaf_thickness", 0.3, "mm", "rig", "4-1-2", ""),
    ("leaf_length", 50.0, "mm", "rig", "4-1-2", ""),
    ("leaf_modulus", 193.0, "GPa", "rig", "4-1-2", "stainless steel"),
    ("natural_frequency_design", 559.0, "rpm", "rig", "4-1-2",
     "from k = 17 E b h^3 / (8 l^3) and M = 362.1 g"),
    ("natural_frequency", 513.0, "rpm", "rig", "4-1-2, fig. 4-4",
     "measured first natural frequency, balls removed; lower than designed"),
    ("second_natural_frequency", 1508.0, "rpm", "rig", "4-1-2, fig. 4-4", "measured"),
    ("max_speed_design", 2400.0, "rpm", "rig", "4-1-2", "motor torque limit"),
    ("max_speed", 1000.0, "rpm", "rig", "4-1-2",
     "out-of-plane vibration above it: the planar model stops describing the rig"),
    ("lowpass_cutoff", 50.0, "Hz", "rig", "4-4-2, 4-4-6", "3000 rpm, before amplitudes"),
    ("baseline_amplitude", 2.0, "mV", "rig", "4-3, fig. 4-7",
     "no imbalance, no balls: the perfectly balanced reference"),
    # 4-3: single ball
    ("imbalance_hole_radius", 36.0, "mm", "single ball", "4-3", ""),
    ("imbalance_mass", 0.92, "g", "single ball", "4-3", "bolt and washers"),
    ("imbalance", 33.12, "g mm", "single ball", "4-3, table 4-2", "m_d e = 0.92 g x 36 mm"),
    ("ball_mass", 1.05, "g", "single ball eta 0.54", "4-3", "ball radius 3 mm"),
    ("track_radius", 17.0, "mm", "single ball eta 0.54", "4-3", "of the ball's centre"),
    ("eta", 0.54, "", "single ball eta 0.54", "table 4-2", ""),
    ("residual_imbalance", 15.24, "g mm", "single ball eta 0.54", "4-3",
     "stated; 33.12 - 1.05 x 17 = 15.27"),
    ("ball_mass", 2.05, "g", "single ball eta 0.99", "4-3", "ball radius 4 mm"),
    ("track_radius", 16.0, "mm", "single ball eta 0.99", "4-3", ""),
    ("eta", 0.99, "", "single ball eta 0.99", "table 4-2", ""),
    ("ball_mass", 4.09, "g", "single ball eta 1.85", "4-3", "ball radius 5 mm"),
    ("track_radius", 15.0, "mm", "single ball eta 1.85", "4-3", ""),
    ("eta", 1.85, "", "single ball eta 1.85", "table 4-2", ""),
    ("residual_imbalance", 28.15, "g mm", "single ball eta 1.85", "4-3",
     "stated (over-balance); 4.09 x 15 - 33.12 = 28.23"),
    ("speed_step", 25.0, "rpm", "single ball", "4-3", "from 525 rpm up to 1000 rpm"),
    ("speed_min", 513.0, "rpm", "single ball", "4-3", "the first record, at the natural "
     "frequency; then 525 rpm"),
    ("speed_max", 1000.0, "rpm", "single ball", "4-3", ""),
    ("vibration_rank_balanced", 1.0, "", "single ball eta 1.85", "4-3, fig. 4-7",
     "largest of the three at the balanced equilibrium (1 = largest); no balls larger still"),
    ("vibration_rank_balanced", 2.0, "", "single ball eta 0.54", "4-3, fig. 4-7", ""),
    ("vibration_rank_balanced", 3.0, "", "single ball eta 0.99", "4-3, fig. 4-7",
     "close to the 2 mV baseline of no imbalance"),
    ("vibration_rank_rotating", 1.0, "", "single ball eta 1.85", "4-3, fig. 4-8",
     "in the rotating periodic motion; all three above no balls"),
    ("vibration_rank_rotating", 2.0, "", "single ball eta 0.99", "4-3, fig. 4-8", ""),
    ("vibration_rank_rotating", 3.0, "", "single ball eta 0.54", "4-3, fig. 4-8", ""),
    # 4-4: two balls
    ("ball_mass", 2.05, "g", "two balls eta 0.66", "4-4-1", "ball radius 4 mm, track 16 mm"),
    ("track_radius", 16.0, "mm", "two balls eta 0.66", "4-4-1", ""),
    ("imbalance_mass", 1.38, "g", "two balls eta 0.66", "4-4-1", "at 36 mm"),
    ("imbalance_hole_radius", 36.0, "mm", "two balls eta 0.66", "4-4-1", ""),
    ("eta", 0.66, "", "two balls eta 0.66", "4-4-1", ""),
    ("speed", 800.0, "rpm", "R-R 800 rpm", "4-4-2, fig. 4-11", "eta 0.66, no oil"),
    ("ball_whirl", 302.0, "rpm", "R-R 800 rpm", "4-4-2",
     "omega-bar = 5.03 Hz: the rotating-frame fundamental omega f_n"),
    ("imbalance_mass", 0.70, "g", "two balls eta 1.30", "4-4-2", "at 36 mm"),
    ("eta", 1.30, "", "two balls eta 1.30", "4-4-2, fig. 4-13", ""),
    ("main_frequency_min", 490.0, "rpm", "two balls eta 1.30", "4-4-2, fig. 4-13",
     "measured Omega - omega over the speeds, 25 rpm steps"),
    ("main_frequency_max", 500.0, "rpm", "two balls eta 1.30", "4-4-2, fig. 4-13", ""),
    ("main_frequency_model_min", 460.0, "rpm", "two balls eta 1.30", "4-4-2, fig. 4-13",
     "Tien's (2011) MIHB at mu 0.2, zeta 0.05, zeta_b 0.05, delta 50, f_n 513 rpm"),
    ("main_frequency_model_max", 510.0, "rpm", "two balls eta 1.30", "4-4-2, fig. 4-13", ""),
    ("main_frequency_max_error", 6.0, "%", "two balls eta 1.30", "4-4-2", "model vs rig"),
    # 4-4-3: track damping (oils)
    ("oil_kinematic_viscosity_40C", 3.8, "cSt", "oil A (WD-40)", "table 4-3", ""),
    ("oil_kinematic_viscosity_40C", 35.2, "cSt", "oil B (ATF DEXRON-III)", "table 4-3", ""),
    ("oil_kinematic_viscosity_40C", 128.0, "cSt", "oil C (SAE 15W-50)", "table 4-3", ""),
    ("oil_viscosity", 26.3, "cP", "oil (1) 25%A-75%B", "table 4-4", "at 16 C"),
    ("oil_viscosity", 36.9, "cP", "oil (2) 10%A-90%B", "table 4-4", "at 16 C"),
    ("oil_viscosity", 76.0, "cP", "oil (3) 100%B", "table 4-4", "at 16 C"),
    ("oil_viscosity", 12.3, "cP", "oil (4) 40%A-60%B", "table 4-4", "at 27 C"),
    ("oil_viscosity", 19.2, "cP", "oil (5) 25%A-75%B", "table 4-4", "at 27 C"),
    ("oil_viscosity", 30.8, "cP", "oil (6) 10%A-90%B", "table 4-4", "at 27 C"),
    ("oil_viscosity", 50.1, "cP", "oil (7) 100%B", "table 4-4", "at 27 C"),
    ("oil_viscosity", 144.3, "cP", "oil (8) 80%B-20%C", "table 4-4", "at 27 C"),
    ("oil_viscosity", 232.8, "cP", "oil (9) 100%C", "table 4-4", "at 27 C"),
    # 4-4-5: balancing capacity
    ("ball_mass", 4.09, "g", "two balls 4-4-5", "4-4-5",
     "printed 4.05 g; the printed eta values follow from 4.09 g (the 5 mm ball of 4-3)"),
    ("track_radius", 15.0, "mm", "two balls 4-4-5", "4-3", "the 5 mm ball's track"),
    ("imbalance_hole_radius", 48.0, "mm", "two balls 4-4-5", "4-4-5", ""),
    ("imbalance_mass", 2.52, "g", "two balls eta 0.51", "4-4-5", ""),
    ("eta", 0.51, "", "two balls eta 0.51", "4-4-5", ""),
    ("imbalance_mass", 1.99, "g", "two balls eta 0.64", "4-4-5", ""),
    ("eta", 0.64, "", "two balls eta 0.64", "4-4-5", ""),
    ("imbalance_mass", 0.87, "g", "two balls eta 1.47", "4-4-5", ""),
    ("eta", 1.47, "", "two balls eta 1.47", "4-4-5", ""),
    # 4-4-6: support damping (rubber pads)
    ("natural_frequency", 521.0, "rpm", "pads A", "table 4-5", ""),
    ("zeta", 0.020, "", "pads A", "table 4-5", "from the log decrement, 5 peaks"),
    ("natural_frequency", 543.0, "rpm", "pads B", "table 4-5", ""),
    ("zeta", 0.030, "", "pads B", "table 4-5", ""),
    ("natural_frequency", 557.0, "rpm", "pads C", "table 4-5", ""),
    ("zeta", 0.039, "", "pads C", "table 4-5", ""),
    # 4-4-7 and table 4-6: other periodic motions
    ("amplitude", 2.32, "mV", "O-O 555 rpm", "4-4-7, table 4-6", "oil (7), pads B"),
    ("amplitude", 4.98, "mV", "R-R 555 rpm", "4-4-7, table 4-6", ""),
    ("amplitude", 4.16, "mV", "R-O 560 rpm", "table 4-6",
     "the table's value; the text of 4-4-7 says 4.98 mV"),
    ("amplitude", 5.13, "mV", "R-R 560 rpm", "4-4-7, table 4-6", ""),
    ("ball_whirl", 24.0, "rpm", "O-O 555 rpm", "4-4-7", "about 24 rpm (line spacing)"),
    ("ball_whirl", 39.0, "rpm", "R-O 560 rpm", "4-4-7", "line spacing"),
]

# (case, speed rpm, peak rpm, k or None when not of the form Omega + k omega, largest, source)
_PEAKS: list[tuple[str, float, float, int | None, bool, str]] = [
    ("R-R 800 rpm", 800.0, 498.0, -1, True, "4-4-2, fig. 4-11"),
    ("R-R 800 rpm", 800.0, 800.0, 0, False, "4-4-2, fig. 4-11"),
    ("R-R 800 rpm", 800.0, 996.0, None, False, "4-4-2, fig. 4-11: twice the ball rotation"),
    ("R-R 800 rpm", 800.0, 1102.0, 1, False, "4-4-2, fig. 4-11"),
    ("O-O 555 rpm", 555.0, 507.0, -2, False, "4-4-7, fig. 4-24"),
    ("O-O 555 rpm", 555.0, 532.0, -1, True, "4-4-7, fig. 4-24"),
    ("O-O 555 rpm", 555.0, 555.0, 0, False, "4-4-7, fig. 4-24"),
    ("O-O 555 rpm", 555.0, 579.0, 1, False, "4-4-7, fig. 4-24"),
    ("O-O 555 rpm", 555.0, 602.0, 2, False, "4-4-7, fig. 4-24"),
    ("O-O 555 rpm", 555.0, 627.0, 3, False, "4-4-7, fig. 4-24"),
    ("R-O 560 rpm", 560.0, 482.0, -2, False, "4-4-7, fig. 4-26"),
    ("R-O 560 rpm", 560.0, 521.0, -1, True, "4-4-7, fig. 4-26"),
    ("R-O 560 rpm", 560.0, 560.0, 0, False, "4-4-7, fig. 4-26"),
    ("R-O 560 rpm", 560.0, 599.0, 1, False, "4-4-7, fig. 4-26"),
    ("R-O 560 rpm", 560.0, 638.0, 2, False, "4-4-7, fig. 4-26"),
]

# (case, varied, value, unit, direction, speed rpm, natural frequency rpm, source, notes)
_TRANSITIONS: list[tuple[str, str, float, str, str, float, float, str, str]] = [
    ("oil 76.0 cP", "oil_viscosity", 76.0, "cP", "up", 675.0, 513.0, "4-4-3, fig. 4-14",
     "stable R-R seen over [513, 675] rpm, eta 0.66"),
    ("oil 36.9 cP", "oil_viscosity", 36.9, "cP", "up", 800.0, 513.0, "4-4-3, fig. 4-14",
     "[513, 800] rpm"),
    ("oil 26.3 cP", "oil_viscosity", 26.3, "cP", "up", 950.0, 513.0, "4-4-3, fig. 4-14",
     "[513, 950] rpm"),
    ("oil 36.9 cP, tapped", "oil_viscosity", 36.9, "cP", "up", 775.0, 513.0,
     "4-4-4, fig. 4-17", "the support tapped at each speed: balls separate for good"),
    ("eta 0.51", "eta", 0.51, "", "up", 880.0, 513.0, "4-4-5, fig. 4-18",
     "oil (8) 144.3 cP, 5 rpm steps from 850 rpm"),
    ("eta 0.64", "eta", 0.64, "", "up", 895.0, 513.0, "4-4-5, fig. 4-18", ""),
    ("eta 1.47", "eta", 1.47, "", "up", 900.0, 513.0, "4-4-5, fig. 4-18", ""),
    ("pads C", "zeta", 0.039, "", "up", 1.4 * 557.0, 557.0, "4-4-6, fig. 4-22",
     "stable R-R over Omega in [1, 1.4]; oil (4) 12.3 cP"),
    ("pads B", "zeta", 0.030, "", "up", 1.5 * 543.0, 543.0, "4-4-6, fig. 4-22",
     "Omega in [1, 1.5]"),
]


def experiments() -> pl.DataFrame:
    """Every experimental number of Tien's (2011) chapter 4: one row per number with
    ``quantity, value, unit, case, source, notes``."""
    cols = list(zip(*_ROWS, strict=True))
    return pl.DataFrame(
        {name: list(col) for name, col in
         zip(("quantity", "value", "unit", "case", "source", "notes"), cols, strict=True)},
        schema={"quantity": pl.String, "value": pl.Float64, "unit": pl.String,
                "case": pl.String, "source": pl.String, "notes": pl.String},
    )


def peaks() -> pl.DataFrame:
    """The measured spectral peaks (rpm) with Tien's (2011) labels: ``k`` for a line at
    ``Omega + k omega``, null for a peak of no such form; ``largest`` marks the highest."""
    cols = list(zip(*_PEAKS, strict=True))
    return pl.DataFrame(
        {name: list(col) for name, col in
         zip(("case", "speed_rpm", "frequency_rpm", "k", "largest", "source"), cols,
             strict=True)},
        schema={"case": pl.String, "speed_rpm": pl.Float64, "frequency_rpm": pl.Float64,
                "k": pl.Int64, "largest": pl.Boolean, "source": pl.String},
    )


def transitions() -> pl.DataFrame:
    """Measured critical speeds: where the balls left the rotating motion (R-R) for the
    perfect balance as the speed was stepped up, with what was varied."""
    cols = list(zip(*_TRANSITIONS, strict=True))
    df = pl.DataFrame(
        {name: list(col) for name, col in
         zip(("case", "varied", "value", "unit", "direction", "speed_rpm",
              "natural_frequency_rpm", "source", "notes"), cols, strict=True)},
    )
    return df.with_columns(
        (pl.col("speed_rpm") / pl.col("natural_frequency_rpm")).alias("Omega"))


def imbalance(mass: float, radius: float) -> float:
    """The imbalance ``m_d e`` of a mass at a radius (units multiply: g and mm give g mm)."""
    return (_check.real("mass", mass, 0.0, lo_open=True)
            * _check.real("radius", radius, 0.0, lo_open=True))


def eta(ball_mass: float, track_radius: float, imbalance: float) -> float:
    """Balancing capacity ``m_b r_t / (m_d e)`` of one ball (consistent units)."""
    mb = _check.real("ball_mass", ball_mass, 0.0, lo_open=True)
    rt = _check.real("track_radius", track_radius, 0.0, lo_open=True)
    u = _check.real("imbalance", imbalance, 0.0, lo_open=True)
    return mb * rt / u


def residual_imbalance(imbalance: float, eta: Any, angles: Any = math.pi) -> float:
    """The imbalance ``m_d e |1 + sum eta_i exp(i b_i)|`` the disk and its balls leave
    (units of ``imbalance``): ``eta`` one capacity or several, ``angles`` the balls' angles
    from the disk's mass centre (default: straight opposite it, ``pi``). ``eta`` may also
    be an :class:`~ballbal.Equilibrium`, whose own ``residual_imbalance`` is scaled.
    Tien's (2011) section 4-3: 33.12 g mm with one ball of eta 0.54 opposite leaves
    15.24 g mm, with eta 1.85 (over-balance) 28.15 g mm."""
    from .analysis import Equilibrium
    from .analysis import residual_imbalance as relative

    u = _check.real("imbalance", imbalance, 0.0, lo_open=True)
    if isinstance(eta, Equilibrium):
        return u * eta.residual_imbalance
    e = np.asarray(_check.reals("eta", eta))
    if not np.all(np.isfinite(e) & (e >= 0)):
        raise ParameterError("eta", "must be finite and >= 0", allowed=">= 0", value=eta)
    b = np.asarray(_check.reals("angles", angles))
    if b.size not in (1, e.size) or not np.all(np.isfinite(b)):
        raise ParameterError("angles", f"must be one finite angle or {e.size}",
                             allowed="finite angles (rad)", value=angles)
    return u * relative(e, np.broadcast_to(b, e.shape))


def single_ball() -> pl.DataFrame:
    """The single-ball experiment of section 4-3, one row per ball: ``ball_mass`` (g),
    ``track_radius`` (mm), ``eta`` from them and the stated imbalance 33.12 g mm,
    ``eta_stated`` (table 4-2), the stated ``residual_imbalance`` (g mm, null where the
    text gives none) and the vibration ranks of figures 4-7 (balanced equilibrium) and
    4-8 (rotating motion), 1 = largest."""
    t = experiments().filter(pl.col("case").str.starts_with("single ball eta"))
    rows = []
    for case in sorted(set(t["case"].to_list())):
        v = dict(t.filter(pl.col("case") == case).select("quantity", "value").iter_rows())
        mb, rt = v["ball_mass"], v["track_radius"]
        rows.append({"case": case, "ball_mass": mb, "track_radius": rt,
                     "eta": eta(mb, rt, 33.12), "eta_stated": v["eta"],
                     "residual_imbalance": v.get("residual_imbalance"),
                     "rank_balanced": int(v["vibration_rank_balanced"]),
                     "rank_rotating": int(v["vibration_rank_rotating"])})
    return pl.DataFrame(rows, schema={
        "case": pl.String, "ball_mass": pl.Float64, "track_radius": pl.Float64,
        "eta": pl.Float64, "eta_stated": pl.Float64, "residual_imbalance": pl.Float64,
        "rank_balanced": pl.Int64, "rank_rotating": pl.Int64}).sort("eta")


def _values(name: str, v: Any) -> Any:
    """A finite number, or an array of them in ``v``'s shape. ``None`` (which numpy
    reads as NaN) and ``True`` (as 1) are refused, not converted."""
    if _check.is_real(v):
        return _check.real(name, v, finite=True)
    if v is None or isinstance(v, (bool, np.bool_, str, bytes)):
        raise ParameterTypeError(name, f"must be a number or an array of numbers, got "
                                 f"{v!r:.60}", value=v)
    flat = _check.array(name, v)
    if not np.all(np.isfinite(flat)):
        raise ParameterError(name, "must be finite numbers", allowed="finite numbers",
                             value=v)
    return flat.reshape(np.shape(v))


def rpm_to_ratio(rpm: Any, natural_frequency_rpm: float = NATURAL_FREQUENCY_RPM) -> Any:
    """A speed or frequency in rpm as a ratio to the natural frequency (scalar or array;
    negative for a backward whirl)."""
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, lo_open=True)
    return _values("rpm", rpm) / fn


def ratio_to_rpm(ratio: Any, natural_frequency_rpm: float = NATURAL_FREQUENCY_RPM) -> Any:
    """A frequency ratio (to the natural frequency) in rpm (scalar or array)."""
    fn = _check.real("natural_frequency_rpm", natural_frequency_rpm, 0.0, lo_open=True)
    return _values("ratio", ratio) * fn


def leaf_spring_stiffness(modulus: float, width: float, thickness: float,
                          length: float) -> float:
    """Stiffness ``17 E b h^3 / (8 l^3)`` of the rig's L-shaped leaf-spring support, the
    formula of Tien's (2011) section 4-1-2 (its reference [20]); SI units give N/m."""
    e, b, h, l_ = (_check.real(k, v, 0.0, lo_open=True) for k, v in (
        ("modulus", modulus), ("width", width), ("thickness", thickness), ("length", length)))
    return 17.0 * e * b * h**3 / (8.0 * l_**3)


@dataclass(frozen=True, repr=False)
class LogDecrement(Summarised):
    """A log-decrement fit: ``delta`` (the slope of ``ln x_i`` against peak number ``i``,
    negated), the damping ratio ``zeta = delta / sqrt(4 pi^2 + delta^2)``, the peaks used
    (index into the record, value) and the fit's residual standard deviation."""

    delta: float
    zeta: float
    peak_index: np.ndarray
    peak_value: np.ndarray
    residual: float

    def _summary(self) -> tuple[str, list[tuple[str, Any]]]:
        head = (f"LogDecrement δ={self.delta:.4g} ζ={self.zeta:.4g} from "
                f"{len(self.peak_value)} peaks (residual {self.residual:.2g})")
        return head, [("log decrement δ", self.delta), ("damping ratio ζ", self.zeta),
                      ("peaks", len(self.peak_value)), ("fit residual", self.residual)]

    def plot(self, ax: Any = None) -> Any:
        """The peaks' logarithms and the fitted line; returns the axes."""
        from ._figures import log_decrement

        return log_decrement(self, ax)


def log_decrement(signal: Sequence[float] | np.ndarray, *, n_peaks: int = 5) -> LogDecrement:
    """Section 4-4-6's fit: the first ``n_peaks`` cycle peaks of a free-decay record,
    ``ln x_i`` against ``i`` by least squares; the slope is ``-delta``.

    A cycle peak is the largest sample of a positive lobe (between sign changes); lobes
    under 5 % of the record's largest value (noise about a zero crossing) are skipped, and
    so is a lobe whose largest sample is the record's first or last (a cut cycle). A noisy
    record should be low-pass filtered first, as Tien (2011) did (50 Hz).
    """
    x = _check.array("signal", signal)
    if x.size < 3 or not np.all(np.isfinite(x)):
        raise ParameterError("signal", "must be a finite 1-D record of at least 3 samples",
                             allowed="finite 1-D array")
    n = _check.integer("n_peaks", n_peaks, 2)
    pos = x > 0
    edges = np.flatnonzero(np.diff(pos.astype(np.int8))) + 1
    bounds = np.concatenate(([0], edges, [x.size]))
    floor = 0.05 * float(np.max(x))
    found = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        if not pos[a]:
            continue
        i = a + int(np.argmax(x[a:b]))
        if 0 < i < x.size - 1 and x[i] > floor:
            found.append(i)
    idx = np.asarray(found, dtype=np.int64)
    if idx.size < n:
        raise ParameterError(
            "n_peaks", f"the record has {idx.size} cycle peaks, fewer than {n}",
            allowed=f"<= {idx.size}", value=n_peaks)
    idx = idx[:n]
    v = x[idx]
    i = np.arange(n, dtype=float)
    slope, intercept = np.polyfit(i, np.log(v), 1)
    res = np.log(v) - (slope * i + intercept)
    d = -float(slope)
    if d < 0:
        raise ParameterError("signal", "the peaks grow: not a decaying record",
                             allowed="a free decay")
    return LogDecrement(delta=d, zeta=zeta_from_log_decrement(d), peak_index=idx,
                        peak_value=v, residual=float(np.sqrt(np.mean(res**2))))
