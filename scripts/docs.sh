#!/usr/bin/env bash
# Build the documentation site into docs/_build/html with Sphinx, warnings as errors,
# against the *installed* ballbal (pip install ".[docs]"; the wheel, not the source
# tree, is what the API reference and the gallery import).
#
#   scripts/docs.sh           small mode: the gallery on coarse grids (what CI runs)
#   scripts/docs.sh --full    the whole gallery at the resolution of its figures
#
# PYTHON (default python3) is the interpreter whose environment has ballbal[docs].
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
py=${PYTHON:-python3}
full=0
for arg in "$@"; do
  case "$arg" in
    --full) full=1 ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "docs.sh: unknown argument '$arg' (use --full or nothing)" >&2; exit 2 ;;
  esac
done
if ! "$py" -c "import sphinx, sphinx_gallery, myst_parser, pydata_sphinx_theme" 2>/dev/null; then
  echo "docs.sh: Sphinx is missing from $py's environment: pip install \".[docs]\"" >&2
  exit 1
fi
if [ "$full" = 1 ]; then unset BALLBAL_EXAMPLE_SMALL; else export BALLBAL_EXAMPLE_SMALL=1; fi
export MPLBACKEND=Agg
cd "$root/docs"
# Generated pages (API stubs, executed gallery) are rebuilt every time: a stale page of
# a removed name must not survive.
rm -rf api auto_tutorial auto_gallery _build/html _build/doctrees _build/gallery-output
start=$SECONDS
"$py" -m sphinx -b html -W --keep-going -q -j 1 . _build/html
echo "docs.sh: built $root/docs/_build/html in $(( SECONDS - start )) s ($( [ "$full" = 1 ] && echo full || echo small ) gallery)"
