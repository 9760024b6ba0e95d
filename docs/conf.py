"""Sphinx configuration of the rawehelix documentation (``make docs``).

The pages are Markdown (MyST), as the project's pages always were, read by
Debian 12's python3-myst-parser 0.18 and sphinx 5.3 with the furo theme
(scripts/install.sh).  The reference pages are generated from the code at
build time (docs/_ext/rawehelix_reference.py: the command line from its
argparse parser, the scene keys from the parameter dataclasses) or by autodoc
(the Python API); nothing in the build runs a solve.
"""

from __future__ import annotations

import importlib
import os
import importlib.util
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))


def _markdown_it_beside_myst():
    """Import the markdown-it-py that sits beside myst-parser (Debian's 2.1).

    The venv may hold a newer one (pyvista brings rich, rich markdown-it-py
    4.x), which shadows Debian's and breaks myst-parser 0.18: its footnote and
    deflist plugins call the older ParserBlock.tokenize.  Importing the package
    once from myst-parser's folder makes every later ``import markdown_it`` of
    this build use it; nothing else is taken from there."""
    spec = importlib.util.find_spec("myst_parser")
    if spec is None or "markdown_it" in sys.modules:
        return
    sys.path.insert(0, str(Path(spec.origin).parents[1]))
    try:
        importlib.import_module("markdown_it")
    finally:
        sys.path.pop(0)


_markdown_it_beside_myst()

import rawehelix  # noqa: E402  (the worktree's editable install)

project = "rawehelix"
author = "the rawehelix authors"
copyright = "2026, " + author
release = version = rawehelix.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "rawehelix_reference",
]
source_suffix = {".md": "markdown"}
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]  # Debian 12 myst-parser 0.18
myst_heading_anchors = 3

# The site's pages are index.md and the four folders of its toctree.  Everything
# else under docs/ is data that pages and tests read (summary.json, CSV, figures,
# the generated tables of the studies), not a page: leave it out of the build.
# Except converge/: its generated tables (converge/Q/converge.md, written by
# `rawehelix converge`) are pages of explanation/convergence.md's toctree.
SITE = {"index.md", "tutorials", "howto", "explanation", "reference", "converge", "conf.py",
        "_static", "_templates", "_ext", "_build"}
exclude_patterns = sorted(p.name for p in HERE.iterdir() if p.name not in SITE)
exclude_patterns += ["_build", "**/summary.json", "**/runs"]

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {}
# the heavy modules are imported lazily inside the functions; nothing to mock
nitpicky = False

html_theme = "furo"
html_title = f"rawehelix {release}"
html_static_path = ["_static"]
html_logo = None
html_css_files = ["custom.css"]

# Maths: Debian's MathJax 2 (libjs-mathjax, a dependency of python3-sphinx) where
# the build machine has it, so a page read offline renders its maths; elsewhere
# Sphinx's default (MathJax 3 from its CDN).  RAWEHELIX_DOCS_CDN_MATHJAX=1 forces
# the CDN for a site that is served to others.
_LOCAL_MATHJAX = Path("/usr/share/javascript/mathjax/MathJax.js")
if _LOCAL_MATHJAX.exists() and not os.environ.get("RAWEHELIX_DOCS_CDN_MATHJAX"):
    mathjax_path = _LOCAL_MATHJAX.as_uri() + "?config=TeX-AMS_CHTML"
    mathjax2_config = {"tex2jax": {"processClass": "math",
                                   "ignoreClass": "tex2jax_ignore|mathjax_ignore"}}
