#!/usr/bin/env bash
# The project's test command: Rust unit tests, then the wheel built from source and
# installed into a fresh virtual environment, and pytest run against that install
# (from outside the source tree, so `import ballbal` cannot pick up python/ballbal).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
py=${PYTHON:-python3}
export CARGO_TERM_COLOR=never

stamp() { echo "== [$(( SECONDS / 60 ))m$(( SECONDS % 60 ))s] $*"; }
stamp "cargo test (core, no Python)"
cargo test --release -p ballbal-core
stamp "cargo fmt --check, cargo clippy"
if cargo fmt --version >/dev/null 2>&1; then
  cargo fmt --all -- --check
fi
if cargo clippy --version >/dev/null 2>&1; then
  cargo clippy --release --all-targets -- -D warnings
  # The core's studies (behind the `studies` feature) are not run, but must not rot.
  cargo clippy --release -p ballbal-core --all-targets --features studies -- -D warnings
else
  # rustup's default profile has clippy; a minimal toolchain may not (it cannot be fetched).
  echo "WARNING: cargo clippy is not installed: the lint gate is skipped" >&2
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
stamp "build wheel"
"$py" -m venv "$work/build-env"
"$work/build-env/bin/pip" install -q --upgrade pip "maturin>=1.5,<2"
"$work/build-env/bin/maturin" build --release --out "$work/dist" -q
wheel=$(ls "$work"/dist/ballbal-*.whl)

stamp "install $(basename "$wheel") into a clean venv"
"$py" -m venv "$work/venv"
"$work/venv/bin/pip" install -q --upgrade pip
"$work/venv/bin/pip" install -q "$wheel[test,plot,lint,progress,docs]"

stamp "ruff, mypy, stubtest"
"$work/venv/bin/ruff" check --no-cache python tests benchmarks examples scripts docs
# The source package, typed against the venv's numpy and polars; ballbal._native is read
# from python/ballbal/_native.pyi (mypy cannot read the extension, so a missing stub fails).
"$work/venv/bin/python" -m mypy --cache-dir "$work/mypy-cache" python/ballbal
# The stub against the installed extension module, from outside the source tree.
(cd "$work" && "$work/venv/bin/python" -m mypy.stubtest ballbal._native)

stamp "documentation site (scripts/docs.sh: Sphinx, warnings as errors, gallery small)"
# Built once here against the installed wheel; tests/test_docs_site.py checks it and
# opens it in headless Chromium.
PYTHON="$work/venv/bin/python" bash scripts/docs.sh
export BALLBAL_DOCS_HTML="$root/docs/_build/html"

stamp "pytest against the installed package"
cp -r tests "$work/tests"
export BALLBAL_REPO="$root"
cd "$work"
"$work/venv/bin/python" -m pytest -q -p no:cacheprovider tests "$@"
