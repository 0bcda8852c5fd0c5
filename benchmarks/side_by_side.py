"""Run benchmark scripts under two builds in one go and print their figures side by side:
a build from before a change (a directory holding its ``ballbal`` package, e.g. a copy of
``python/ballbal`` with its ``_native`` library) and the installed one.

    python benchmarks/side_by_side.py OLD_DIR [bench_scene.py bench_periodic.py ...]

The two builds alternate (old, new, old, new) so that a burst of load on a shared machine
hits both; each line of output is shown for both runs of each build, and every number on
a line is followed by the ratio new / old of the better (smaller) run.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
DEFAULT = ["bench_scene.py", "bench_periodic.py", "bench_simulate.py"]
NUM = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def run(script: str, old: str | None) -> list[str]:
    env = dict(os.environ)
    if old is not None:
        env["PYTHONPATH"] = old + os.pathsep + env.get("PYTHONPATH", "")
    out = subprocess.run([sys.executable, str(HERE / script)], env=env, capture_output=True,
                         text=True, check=False)
    if out.returncode:
        why = out.stderr.strip().splitlines()[-1] if out.stderr else out.returncode
        return [f"(failed: {why})"]
    return out.stdout.rstrip().splitlines()


def best(a: list[str], b: list[str]) -> list[str]:
    """Line by line, each number the smaller of two runs (timings only grow with noise)."""
    if len(a) != len(b):
        return a
    res = []
    for la, lb in zip(a, b, strict=True):
        na, nb = NUM.findall(la), NUM.findall(lb)
        if len(na) != len(nb):
            res.append(la)
            continue
        it = iter(str(min(float(x), float(y))) for x, y in zip(na, nb, strict=True))
        res.append(NUM.sub(lambda _m: next(it), la))
    return res


def main(argv: list[str]) -> int:
    old = argv[1]
    scripts = argv[2:] or DEFAULT
    for s in scripts:
        o1, n1, o2, n2 = run(s, old), run(s, None), run(s, old), run(s, None)
        o, n = best(o1, o2), best(n1, n2)
        print(f"== {s}  (old build: {old}; new: installed)")
        for i in range(max(len(o), len(n))):
            lo = o[i] if i < len(o) else ""
            ln = n[i] if i < len(n) else ""
            no, nn = NUM.findall(lo), NUM.findall(ln)
            ratios = ""
            if no and len(no) == len(nn):
                r = [float(b) / float(a) for a, b in zip(no, nn, strict=True) if float(a) != 0.0]
                ratios = "  new/old: " + " ".join(f"{x:.3f}" for x in r)
            print(f"  old | {lo}")
            print(f"  new | {ln}{ratios}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
