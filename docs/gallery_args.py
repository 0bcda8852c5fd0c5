"""The command line each gallery script is run with in the documentation build.

The gallery is ``examples/``: scripts that write their figures and tables into an
output directory given on the command line. In the build that directory is
``docs/_build/gallery-output/NAME`` (the figures shown on the pages are the open
matplotlib figures, captured by sphinx-gallery), so a build never writes into the
source tree."""

from __future__ import annotations

import pathlib
from typing import Any

OUTPUT = pathlib.Path(__file__).resolve().parent / "_build" / "gallery-output"


def argv(gallery_conf: dict[str, Any], script_vars: dict[str, Any]) -> list[str]:
    """sphinx-gallery's ``reset_argv``: the arguments after the script's name."""
    name = pathlib.Path(script_vars["src_file"]).stem
    out = OUTPUT / name
    out.mkdir(parents=True, exist_ok=True)
    if name.startswith("plot_"):
        return []
    return [str(out)]
