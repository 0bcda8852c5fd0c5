#!/usr/bin/env bash
# Run the tests on a CPU without AVX/AVX2/FMA, emulated, to show that they pass when the
# core's round-off differs from this machine's.
#
# A manual check, not part of CI (.ci/run and scripts/test.sh do not call it): emulation is
# 5-20x slower than the CPU, and the check matters only when a reference solver or the core
# changes. Why it exists: the round-off of the core's results depends on the CPU. faer (via
# pulp) picks its SIMD kernels when it runs (AVX2+FMA where the CPU has them, SSE
# otherwise), and glibc picks FMA variants of sin, cos, exp, log, pow, atan, atan2 when it
# loads. A test whose reference solver converges only from some start round-offs passed
# here and failed on a fresh CI machine; this runs the tests on the other path.
#
# How: qemu-x86_64 (Debian's qemu-user, installed with apt-get if missing) runs the venv's
# interpreter as a "-cpu Nehalem" (SSE4.2, no AVX) CPU. A shadow venv whose bin/python
# wraps qemu makes sys.executable emulated too, so tests that start `python -m ballbal.cli`
# are not run natively. Polars' default runtime needs AVX2 (it dies with SIGILL under
# emulation): its "compat" runtime of the same version is installed into a temporary
# directory (not into the venv) and forced with POLARS_FORCE_PKG.
#
# First it prints key numbers (float.hex) natively, natively with glibc's libm held to its
# SSE code, and emulated, and how many differ (scripts/low_simd_numbers.py); then it runs
# pytest under emulation on a copy of the repository's tests/, as scripts/test.sh does.
#
# Usage: BALLBAL_VENV=/path/to/venv scripts/test_low_simd.sh [pytest args]
#   BALLBAL_VENV  a venv with ballbal installed with its [test] extra (required)
#   BALLBAL_REPO  the repository whose tests/ are run (default: this script's)
#   LOW_SIMD_CPU  qemu's CPU model (default Nehalem; `qemu-x86_64 -cpu help` lists them)
#   LOW_SIMD_SKIP_NUMBERS=1  skip the comparison of numbers
# With no pytest args it runs the files whose reference solvers start from the core's
# output, with -x. Example: BALLBAL_VENV=/work/venv scripts/test_low_simd.sh \
#   tests/test_periodic.py -x -q
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
venv=${BALLBAL_VENV:?set BALLBAL_VENV to a venv with ballbal[test] installed}
venv=$(cd "$venv" && pwd)
repo=$(cd "${BALLBAL_REPO:-$root}" && pwd)
cpu=${LOW_SIMD_CPU:-Nehalem}

stamp() { echo "== [$(( SECONDS / 60 ))m$(( SECONDS % 60 ))s] $*"; }

if [ "$(uname -m)" != x86_64 ]; then
  echo "test_low_simd.sh: needs an x86-64 host (the emulated CPU is an older x86-64)" >&2
  exit 2
fi
if ! command -v qemu-x86_64 >/dev/null 2>&1; then
  stamp "installing qemu-user (apt-get)"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq qemu-user >/dev/null
fi
qemu=$(command -v qemu-x86_64)
py="$venv/bin/python"
[ -x "$py" ] || { echo "test_low_simd.sh: no $py" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The shadow venv: its pyvenv.cfg and lib/ are the venv's, its python runs under qemu.
shadow="$work/venv"
mkdir -p "$shadow/bin"
cp "$venv/pyvenv.cfg" "$shadow/"
ln -s "$venv/lib" "$shadow/lib"
cat > "$shadow/bin/python" <<EOF
#!/bin/sh
exec "$qemu" -cpu "$cpu" -0 "$shadow/bin/python" "$py" "\$@"
EOF
chmod +x "$shadow/bin/python"
ln -s python "$shadow/bin/python3"

# Polars: split into a front package and runtimes since 1.34; the "compat" runtime runs
# on any x86-64.
polars=$("$py" - <<'EOF'
import importlib.metadata as md
import importlib.util as iu
if iu.find_spec("polars") is None:
    print("none")
elif iu.find_spec("_polars_runtime_compat") is not None:
    print("compat")
elif iu.find_spec("_polars_runtime_32") or iu.find_spec("_polars_runtime_64"):
    print(md.version("polars"))
else:
    print("monolithic")
EOF
)
case "$polars" in
  none) ;;
  compat) export POLARS_FORCE_PKG=compat ;;
  monolithic)
    echo "WARNING: polars < 1.34 has no compat runtime to add; if it dies with SIGILL," \
      "install polars-lts-cpu of the same version into the venv" >&2 ;;
  *)
    stamp "polars-runtime-compat==$polars into $work/overlay (the venv is not changed)"
    "$py" -m pip install -q --no-deps --disable-pip-version-check --target "$work/overlay" \
      "polars-runtime-compat==$polars"
    export PYTHONPATH="$work/overlay${PYTHONPATH:+:$PYTHONPATH}"
    export POLARS_FORCE_PKG=compat ;;
esac

cd "$work"
stamp "emulated interpreter ($qemu -cpu $cpu)"
"$shadow/bin/python" - <<'EOF'
import sys

import numpy as np

try:
    from numpy._core._multiarray_umath import __cpu_features__ as f
except ImportError:
    from numpy.core._multiarray_umath import __cpu_features__ as f
import ballbal

print(f"sys.prefix {sys.prefix}, ballbal {ballbal.__version__} from {ballbal.__file__}")
print(f"numpy {np.__version__} sees AVX {f.get('AVX')}, AVX2 {f.get('AVX2')}, "
      f"FMA3 {f.get('FMA3')}")
if f.get("AVX2") or f.get("FMA3"):
    sys.exit("the emulated CPU has AVX2 or FMA: choose another LOW_SIMD_CPU")
EOF

if [ "${LOW_SIMD_SKIP_NUMBERS:-0}" != 1 ]; then
  numbers="$root/scripts/low_simd_numbers.py"
  stamp "key numbers: native, native with libm held to SSE, emulated (-cpu $cpu)"
  "$py" "$numbers" --large > "$work/native.txt"
  GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-FMA4 "$py" "$numbers" --large \
    > "$work/libm-sse.txt"
  "$shadow/bin/python" "$numbers" --large > "$work/emulated.txt"
  grep '^#' "$work/emulated.txt" || true
  "$py" "$numbers" --compare "$work/native.txt" "$work/libm-sse.txt" "$work/emulated.txt"
  if cmp -s "$work/native.txt" "$work/emulated.txt"; then
    echo "WARNING: no number differs: the emulated run takes the same round-off path" >&2
  fi
fi

if [ $# -eq 0 ]; then
  set -- -x tests/test_periodic.py tests/test_po_curves.py tests/test_po_continuation.py \
    tests/test_codim2_certificates.py tests/test_floquet_methods.py tests/test_hill_scan.py \
    tests/test_ns_curves.py tests/test_po_switch.py
fi
stamp "pytest under qemu-x86_64 -cpu $cpu: $*"
cp -r "$repo/tests" "$work/tests"
export BALLBAL_REPO="$repo"
status=0
"$shadow/bin/python" -m pytest -q -p no:cacheprovider "$@" || status=$?
stamp "done (pytest exit $status)"
exit "$status"
