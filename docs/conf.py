"""Sphinx configuration of balancer's documentation site.

Build it with ``python -m sphinx -W -b html docs <output folder>`` (``tests/test_docs.py`` does,
warnings as errors). Nothing is fetched from the network: no intersphinx, no link checks.
The spec format's key reference is generated from ``balancer/spec/schema.py`` while the site is
built (``_ext/balancer_docs.py``); the command line's from its parser (sphinx-argparse); the
Python API's from the docstrings (autodoc, napoleon).
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path[:0] = [str(DOCS.parent), str(DOCS / "_ext")]

import balancer  # noqa: E402 - from this checkout, whatever is installed

project = "balancer"
author = "the balancer developers"
copyright = "the balancer developers"  # noqa: A001 - Sphinx's name
release = version = balancer.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinxarg.ext",
    "balancer_docs",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build"]
root_doc = "index"
# Straight quotes stay straight: "+" and "" are values a spec holds, not prose.
smartquotes = False

myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_preserve_defaults = True
napoleon_google_docstring = False
napoleon_numpy_docstring = True

html_theme = "alabaster"
html_title = f"balancer {release}"
html_theme_options = {"description": "Dynamic balancing of planar linkages", "fixed_sidebar": True}
html_static_path: list[str] = []
