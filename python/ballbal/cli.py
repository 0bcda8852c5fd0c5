"""Command line: ``ballbal run`` solves Tien's (2011) standard case; ``ballbal periodic``
and ``ballbal equilibria`` take parameters, or a scene file (``--scene SCENE.toml``,
whose balancer the parameter options given change); ``ballbal scan SCENE.toml --Omega 1:2:0.1
--eta 0.4:1.5:0.1 -o out.parquet`` maps a parameter plane (Ctrl-C keeps the finished
chunks, running the same command again resumes) and ``ballbal plot out.parquet`` draws
the map. Options are spelled with hyphens (``--zeta-b``) in every subcommand; ``--eta``
takes one value per ball, as ``Balancer(eta=...)``. Exit status: 0 done, 1 the numerics
failed or the asked-for solution was not found, 2 bad input, 130 interrupted."""

from __future__ import annotations

import argparse
import re
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path
from typing import NoReturn

import numpy as np

from ._native import __version__
from .analysis import equilibria, periodic
from .exceptions import BallbalError, ParameterError, ScanInterrupted, ScanStoreError
from .model import Balancer
from .options import SCAN_DEFAULTS, SCAN_HILL_BAND
from .scan import SCANNABLE, read_scan, scan, scan_meta
from .scene import MAX_BALLS, Scene, load_scene


class _Parser(argparse.ArgumentParser):
    """Usage errors as one ``ballbal: error: <parameter>: ...`` line, exit status 2,
    like every other error of the command."""

    def error(self, message: str) -> NoReturn:
        m = re.match(r"argument (?:-\w/)?-*([\w-]+)(?:/\S+)?: (.*)", message, re.S)
        if m:
            message = f"{m.group(1).replace('-', '_')}: {m.group(2)}"
        elif m := re.match(r"the following arguments are required: (.*)", message):
            first = m.group(1).split(",")[0].split("/")[-1].lstrip("-")
            message = f"{first}: required (see '{self.prog} --help')"
        elif m := re.match(r"(unrecognized arguments|ambiguous option): (\S*)(.*)", message,
                           re.S):
            flag = m.group(2).split("=")[0]
            # An option is named as typed; a stray value belongs to the command line.
            name = flag.lstrip("-").replace("-", "_") if flag.startswith("-") else ""
            name = name or "cmd"
            message = f"{name}: {m.group(1)}: {m.group(2)}{m.group(3)}"
        else:
            message = f"cmd: {message}"
        _fail(message)


def _fail(message: str, status: int = 2) -> NoReturn:
    print(f"ballbal: error: {' '.join(message.split())}", file=sys.stderr)
    sys.exit(status)


def _load(path: str, parameter: str) -> Scene:
    """A scene file, with errors about the file itself named by the CLI's parameter."""
    try:
        return load_scene(path)
    except ParameterError as e:
        if e.parameter == "path":
            raise ParameterError(parameter, e.message, value=path) from e
        raise

_DEFAULTS = {"mu": 0.2, "zeta": 0.05, "zeta_b": 0.05, "delta": 50.0, "Omega": 1.2}


def _model(a: argparse.Namespace) -> Balancer | Scene:
    given = {k: getattr(a, k) for k in _DEFAULTS if getattr(a, k) is not None}
    if a.scene is not None:
        if a.balls is not None:
            raise ValueError("balls: the scene file sets the balls; give --eta to change "
                             "their masses")
        sc = _load(a.scene, "scene")
        if a.eta is not None:
            given["eta"] = a.eta[0] if len(a.eta) == 1 else tuple(a.eta)
        return sc.replace(**given)
    if a.balls is not None and not 1 <= a.balls <= MAX_BALLS:
        raise ParameterError("balls", f"must be an integer in [1, {MAX_BALLS}], got {a.balls}",
                             allowed=f"[1, {MAX_BALLS}]")
    if a.balls is not None and a.eta is not None and len(a.eta) > 1 and len(a.eta) != a.balls:
        raise ParameterError("balls", f"{a.balls} balls but {len(a.eta)} values of --eta")
    # --eta is Balancer(eta=...): one value per ball (one value is one ball); --balls
    # repeats a single value
    if a.eta is None:
        eta = [1.0] * (2 if a.balls is None else a.balls)
    elif len(a.eta) == 1 and a.balls is not None:
        eta = a.eta * a.balls
    else:
        eta = a.eta
    return Balancer(**{**_DEFAULTS, **given}, eta=tuple(eta))


def _params(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scene", default=None, help="scene TOML (springs, tilt, ...)")
    p.add_argument("--mu", type=float, default=None, help="default 0.2")
    p.add_argument("--zeta", type=float, default=None, help="default 0.05")
    p.add_argument("--zeta-b", dest="zeta_b", type=float, default=None, help="default 0.05")
    p.add_argument("--delta", type=float, default=None, help="default 50")
    p.add_argument("--Omega", type=float, default=None, help="default 1.2")
    p.add_argument("--eta", type=float, nargs="+", default=None,
                   help="one value per ball, as Balancer(eta=...): '--eta 1.3' is one ball, "
                        "'--eta 1.3 1.3' two (default: two balls of 1.0)")
    p.add_argument("--balls", type=int, default=None,
                   help="number of equal balls, each of the one --eta value (default 2 "
                        "without --eta)")


def _print_equilibria(b: Balancer | Scene) -> None:
    eta = b.balancer.eta if isinstance(b, Scene) else b.eta
    names = b.coordinates if isinstance(b, Scene) else ["x", "y"] + [
        f"b{i + 1}" for i in range(b.n_balls)]
    print(f"Equilibria at Omega={b.Omega}, eta={list(eta)}, q = ({', '.join(names)}):")
    eqs = equilibria(b)
    family = [e for e in eqs if e.neutral > 0]
    for e in eqs:
        if e.neutral > 0 and e is not family[0]:
            continue  # points of one family of perfect balances (n >= 3): shown once
        rh = ""
        if e.routh_hurwitz is not None:
            rh = f", Routh-Hurwitz {'stable' if e.routh_hurwitz else 'not stable'}"
        q = ", ".join(f"{v:+.4f}" for v in e.q)
        print(f"  {e.kind:16s} q=({q})  {e.stability} (index {e.stability_index:+.4g}{rh})")
        if e.neutral > 0 and len(family) > 1:
            idx = [f.stability_index for f in family]
            kinds = sorted({f.stability for f in family})
            print(f"  {'':16s} ... one of {len(family)} points found on the family of "
                  f"perfect balances ({e.neutral} neutral direction(s)); {', '.join(kinds)}, "
                  f"index {min(idx):+.4g} to {max(idx):+.4g}")


def _print_periodic(b: Balancer | Scene, pattern: str, N: int) -> bool:
    """Prints the solution; False (and why, on stderr) when none was found."""
    t = time.perf_counter()
    s = periodic(b, pattern, N=N)
    dt = time.perf_counter() - t
    if not s.converged:
        print(f"ballbal: no {pattern} solution found (N={N}): {s.status} after "
              f"{s.iterations} iterations", file=sys.stderr)
        return False
    assert s.multipliers is not None  # a converged solve has its multipliers
    mods = " ".join(f"{m:.4f}" for m in np.sort(np.abs(s.multipliers))[::-1])
    print(f"  {s.type} N={N}: omega={s.omega:.6f} (period {s.period:.3f}), {s.stability}; "
          f"|multipliers| {mods}; trivial error {s.trivial_error:.1e}; residual "
          f"{s.residual:.1e}; orbit closure by simulation {s.verify():.1e}; Hill's method: "
          f"{s.hill_stability}; {dt * 1e3:.1f} ms")
    return True


def _print_map(b: Balancer) -> None:
    t = time.perf_counter()
    df = scan(b, Omega=(1.0, 2.0, 0.1), eta=(0.4, 1.5, 0.1), patterns=["R-R", "O-O", "R-O"])
    dt = time.perf_counter() - t
    print(f"Scan of the Tien (2011) grid (zeta {b.zeta}, zeta_b {b.zeta_b}; R-R, O-O, R-O; "
          f"{dt:.2f} s): S stable R-R, u unstable R-R, o other stable type, "
          "+ perfect balance stable, . nothing")
    oms = sorted(set(df["Omega"].to_list()))
    print("  eta  " + "".join(f"{om:>4.1f}" for om in oms))
    for eta in sorted(set(df["eta"].to_list()), reverse=True):
        line = []
        for om in oms:
            here = df.filter((df["Omega"] == om) & (df["eta"] == eta))
            ok = here.filter(here["status"] == "converged")
            rr = ok.filter(ok["type"] == "R-R")["stability"].to_list()
            other = ok.filter((ok["type"] != "R-R") & (ok["stability"] == "stable")).height
            c = ("S" if "stable" in rr else "u" if rr else "o" if other else
                 "+" if here["pb_stable"][0] else ".")
            line.append(f"{c:>4}")
        print(f"  {eta:3.1f}  " + "".join(line))
    ok = df.filter(df["status"] == "converged")
    checked = ok.filter(ok["hill_stability"].is_not_null())
    same = int((checked["hill_stability"] == checked["stability"]).sum())
    print(f"  Hill's method cross-checked {checked.height} of the {ok.height} verdicts (those in "
          f"doubt: undetermined, or the leading multiplier within {SCAN_HILL_BAND} of the "
          f"unit circle or within ten times the monodromy's error of it): {same} the same, "
          f"{int(checked['verdicts_disagree'].sum())} contradicted")


def _scan(a: argparse.Namespace) -> int:
    b = _load(a.scene, "scene") if a.scene is not None else Balancer()
    grid: dict[str, str] = {n: getattr(a, n) for n in SCANNABLE if getattr(a, n) is not None}
    for g in a.grid:
        name, sep, spec = g.partition("=")
        if not sep:
            raise ParameterError("grid", f"give NAME=START:STOP:STEP, got {g!r}")
        grid[name.strip()] = spec
    t = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ScanInterrupted)
            # --hill doubt: the default band; all: Hill beside every monodromy; off: none.
            fl = SCAN_DEFAULTS.floquet
            floquet = {"doubt": fl, "all": replace(fl, hill=True, hill_band=None),
                       "off": replace(fl, hill=False)}[a.hill]
            df = scan(b, grid=grid, patterns=a.types, N=a.N,
                      options=replace(SCAN_DEFAULTS, floquet=floquet), threads=a.threads,
                      chunk=a.chunk, out=a.out, progress=not a.no_progress)
    except ScanStoreError as e:  # another scan's directory, or one in use
        print(f"ballbal: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # Outside the chunks' work (validation, reading back): nothing new to keep.
        print(f"\nballbal scan: interrupted; run the same command to resume from {a.out}",
              file=sys.stderr)
        return 130
    interrupted = False
    for w in caught:
        if issubclass(w.category, ScanInterrupted):
            interrupted = True
        else:  # not ours to swallow
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    found = df.filter(df["status"] == "converged")
    stable = found.filter(found["stability"] == "stable")
    summary = (f"{df.height} rows, {found.height} solutions ({stable.height} stable) "
               f"in {time.perf_counter() - t:.1f} s -> {a.out}")
    if interrupted:
        # 128 + SIGINT, as a shell reports a process stopped by Ctrl-C.
        print(f"\nballbal scan: interrupted: {summary} (finished chunks only); run the same "
              "command again to resume", file=sys.stderr)
        return 130
    print(f"ballbal scan: {summary}")
    return 0


def _plot(a: argparse.Namespace) -> int:
    try:
        import matplotlib
    except ImportError as e:
        # One line naming the extra, not a traceback: matplotlib is optional.
        raise ParameterError("cmd", "'ballbal plot' needs matplotlib, which is not "
                             "installed: pip install \"ballbal[plot]\"") from e

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .plot import scan_map

    d = Path(a.scan_dir)
    if not d.is_dir():
        raise ParameterError("scan_dir", f"{d} is not a directory (a scan written by "
                             "'ballbal scan -o DIR')")
    if not any(d.glob("chunk-*.parquet")):
        raise ParameterError("scan_dir", f"{d} holds no scan (no chunk-*.parquet)")
    try:
        df = read_scan(d)
        names = list(scan_meta(d)["grid"])
    except ParameterError as e:
        raise ParameterError("scan_dir", e.message) from e
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise ParameterError("scan_dir", f"{d} cannot be read as a scan: {e}") from e
    if len(names) < 2:
        raise ParameterError("scan_dir", "a map needs a scan over two parameters")
    found = sorted(t for t in df["type"].unique().to_list() if t is not None)
    if a.type is not None and a.type not in found:
        raise ParameterError("type", f"no {a.type!r} rows in this scan (types: "
                             f"{', '.join(found) or 'none'})", allowed=", ".join(found))
    types = [a.type] if a.type else found
    if not types:
        raise ParameterError("scan_dir", "the scan has no rows to plot")
    fig, axes = plt.subplots(1, len(types), figsize=(5.5 * len(types), 4.5), squeeze=False)
    for ax, ty in zip(axes[0], types, strict=True):
        scan_map(df, x=names[0], y=names[1], type=ty, ax=ax)
    fig.tight_layout()
    out = a.out or str(a.scan_dir).rstrip("/") + ".png"
    if not out.strip():
        raise ParameterError("out", "must be a non-empty file name")
    try:
        fig.savefig(out, dpi=120)
    except (OSError, ValueError) as e:
        raise ParameterError("out", f"cannot write the image {out}: {e}") from e
    print(f"ballbal plot: {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = _Parser(prog="ballbal", description=__doc__)
    ap.add_argument("--version", action="version", version=f"ballbal {__version__}")
    sub = ap.add_subparsers(dest="cmd", required=True, parser_class=_Parser)
    sub.add_parser("run", help="Tien's (2011) standard case: equilibria and R-R solution")
    pp = sub.add_parser("periodic", help="a periodic solution with Floquet stability")
    _params(pp)
    pp.add_argument("--pattern", default="R-R")
    pp.add_argument("--N", type=int, default=3)
    pe = sub.add_parser("equilibria", help="all equilibria with stability")
    _params(pe)
    ps = sub.add_parser("scan", help="scan a parameter grid; one Parquet row per solution")
    ps.add_argument("scene", nargs="?", help="scene TOML (default: Tien's (2011) standard case)")
    for name in SCANNABLE:
        # one spelling for every subcommand: --zeta-b, as periodic and equilibria
        ps.add_argument(f"--{name.replace('_', '-')}", dest=name, metavar="START:STOP:STEP")
    ps.add_argument("--grid", action="append", default=[], metavar="NAME=START:STOP:STEP",
                    help="any scannable parameter, e.g. 'eta1=0.5:1.5:0.1' (the first ball's eta)")
    ps.add_argument("--types", nargs="+", default=["R-R"], help="e.g. R-R O-O R-O")
    ps.add_argument("--N", type=int, default=3)
    ps.add_argument("--threads", type=int, default=None)
    ps.add_argument("--chunk", type=int, default=None)
    ps.add_argument("-o", "--out", required=True, help="output directory (Parquet chunks)")
    ps.add_argument("--hill", choices=["doubt", "all", "off"], default="doubt",
                    help="Hill's cross-check of the verdicts in doubt (default), of all, or "
                         "none ('off' resumes directories written before 2026-11-24)")
    ps.add_argument("--no-progress", action="store_true")
    pl_ = sub.add_parser("plot", help="plot a scan written by 'ballbal scan'")
    pl_.add_argument("scan_dir")
    pl_.add_argument("--type", default=None, help="solution type (default: each one found)")
    pl_.add_argument("-o", "--out", default=None, help="image file (default: <scan_dir>.png)")
    a = ap.parse_args(argv)
    try:
        if a.cmd == "run":
            b = Balancer()
            print(f"ballbal: Tien (2011) standard case {b}")
            _print_equilibria(b)
            print("Periodic solutions (balls merged, rotating):")
            found = [_print_periodic(b, "R-R", N) for N in (3, 8)]
            _print_map(b.replace(zeta_b=0.1))
            if not all(found):
                return 1
        elif a.cmd == "scan":
            return _scan(a)
        elif a.cmd == "plot":
            return _plot(a)
        elif a.cmd == "periodic":
            # the asked-for result not found: status 1, as a failed computation
            return 0 if _print_periodic(_model(a), a.pattern, a.N) else 1
        else:
            _print_equilibria(_model(a))
    except (ValueError, TypeError) as e:
        # Bad input: ParameterError, ParameterTypeError, NotAutonomousError.
        return _report(e, 2)
    except OSError as e:
        name = "out" if a.cmd in ("scan", "plot") else "scene"
        return _report(ParameterError(name, f"{e.strerror or e}: {e.filename or ''}"), 2)
    except BallbalError as e:
        # The numerics failed (IntegrationError, ...): not a usage error.
        return _report(e, 1)
    except KeyboardInterrupt:
        print("ballbal: interrupted", file=sys.stderr)
        return 130
    return 0


def _report(e: BaseException, status: int) -> int:
    print(f"ballbal: error: {' '.join(str(e).split())}", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
