"""Sphinx configuration of the peridyn documentation site.

Build: ``python -m sphinx -W -b html docs docs/_build/html`` (``.ci/run`` does it, warnings as
errors). The pages are the Markdown files of ``docs/`` (MyST), the gallery is ``examples/``
(sphinx-gallery runs each script and keeps its figures), the CLI pages are generated from the
argument parsers (``_ext/cli_pages.py``) and the API reference from the docstrings (autodoc,
NumPy style through napoleon).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

from gallery_figures import SavedFigures  # noqa: E402

from peridyn import __version__  # noqa: E402

project = "peridyn"
author = "the peridyn developers"
copyright = "2026, the peridyn developers"  # noqa: A001 - Sphinx's name
release = version = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "cli_pages",
    "case_reference",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip", "gallery/*.json"]
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
# two classes with an attribute of the same name (e.g. ``dim``) make a type reference ambiguous
suppress_warnings = ["myst.header", "ref.python"]

autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_numpy_docstring = True
napoleon_google_docstring = False

sphinx_gallery_conf = {
    "image_scrapers": ("matplotlib", SavedFigures(HERE.parent / "examples" / "peridyn-out")),
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": str(HERE / "gallery"),
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "plot_gallery": os.environ.get("PERIDYN_DOCS_GALLERY", "True"),
}

html_theme = "furo"
html_title = f"peridyn {release}"
