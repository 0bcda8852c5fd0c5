"""Sphinx configuration of ballbal's documentation site (built by scripts/docs.sh).

The API reference is generated from the *installed* package: every name in
``ballbal.__all__`` and in each public submodule's ``__all__`` gets a page, so a name a
module adds shows up without editing a list here. The tutorial and the gallery are
sphinx-gallery scripts, executed in the build; ``BALLBAL_EXAMPLE_SMALL=1`` (set by
scripts/docs.sh unless ``--full``) makes them use coarse grids."""

from __future__ import annotations

import pathlib
import sys

import ballbal

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from api_pages import write_api_pages  # noqa: E402

project = "ballbal"
author = "the ballbal developers"
copyright = "the ballbal developers (MIT licence)"
release = ballbal.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax served from the site itself, not a CDN: the pages' equations render
    # offline (and in CI's browser test, which has no network).
    "sphinx-mathjax-offline",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "matplotlib.sphinxext.plot_directive",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
# results.md and measurements.md are included by benchmarks.md, not pages of their own.
exclude_patterns = ["_build", "**.ipynb_checkpoints", "tutorial/GALLERY_HEADER.rst",
                    "results.md", "measurements.md", "**/*.py.md5", "**/*.codeobj.json"]
templates_path = ["_templates"]

# --- Markdown pages (MyST): $...$ maths, ```{directive} blocks, headings as anchors
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# --- API reference
write_api_pages(HERE / "api")
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "show-inheritance": False,
                           "member-order": "bysource"}
autodoc_typehints = "description"
autodoc_typehints_format = "short"
# The docstrings are plain reST with :func:/:class: roles, not numpydoc sections;
# napoleon only reads the odd "Returns:" block and leaves the rest alone.
napoleon_google_docstring = True
napoleon_numpy_docstring = True
# Type hints name polars/numpy/tqdm types that this site does not document (no network
# for intersphinx in CI): a reference that cannot be resolved is not an error.
nitpicky = False
suppress_warnings = ["autosummary.import_cycle"]

# --- Executed tutorial and gallery
sphinx_gallery_conf = {
    # The gallery is the repository's examples/ (one source for the scripts that
    # tests/test_examples.py checks and the pages that show them); the tutorial is a
    # script of its own.
    "examples_dirs": ["tutorial", "../examples"],
    "gallery_dirs": ["auto_tutorial", "auto_gallery"],
    "filename_pattern": r"\.py$",
    "reset_argv": "gallery_args.argv",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
    "show_memory": False,
    "reset_modules": ("matplotlib",),
    "capture_repr": (),
}

# --- HTML
html_theme = "pydata_sphinx_theme"
html_title = f"ballbal {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
html_last_updated_fmt = None
