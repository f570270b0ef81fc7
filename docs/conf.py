"""Sphinx configuration of lookdev's documentation site.

Build it from the repository root (``scripts/test.sh`` does, with warnings as errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Pages are MyST Markdown; the API reference is generated from the numpydoc docstrings;
citations (``:cite:`Burley2012```) resolve against ``docs/references.bib``.
"""

from __future__ import annotations

import importlib.metadata
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

project = "lookdev"
author = "the lookdev authors"
copyright = "the lookdev authors, Apache-2.0"
release = importlib.metadata.version("lookdev")
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinxcontrib.bibtex",
    "lookdev_docs",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "measurements/data", "README.md"]
templates_path = ["_templates"]

# MyST: ::: fences for directives, $…$ maths, header anchors for links into sections.
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3

# The API reference: one page per module, generated at build time from the docstrings.
autosummary_generate = True
autosummary_imported_members = False
# Each object is documented once, in the module that defines it (not where re-exported).
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autodoc_member_order = "bysource"
add_module_names = False

# numpydoc: the docstrings' own sections; no per-class member tables (autodoc lists them).
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

bibtex_bibfiles = ["references.bib"]
bibtex_default_style = "alpha"
bibtex_reference_style = "author_year"

html_theme = "furo"
html_title = f"lookdev {release}"
html_static_path = ["_static"]
html_logo = None
