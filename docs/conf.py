"""Sphinx configuration of the schuler documentation (``make docs`` builds it into ``docs/_build/html``).

Why these tools: Sphinx is the scientific-Python standard (numpy, scipy,
matplotlib, python-control document themselves with it, so our users know the
layout); numpydoc reads the numpydoc docstrings the package is written in
(Parameters with units, Returns, Notes with the source's equations, References);
autosummary generates the API reference from the installed package, so a new
system gets its pages without editing the docs; sphinx-gallery executes the
example scripts at every build and puts their figures on their pages, so a
broken example breaks the build; myst-parser reads the Markdown pages
(``conventions.md``, ``architecture.md``, the change notes) as they are;
pydata-sphinx-theme is the maintained theme of that ecosystem. The build is
offline: no intersphinx, MathJax served from the build (the files of
sphinx-mathjax-offline, copied by ``_ext/schuler_docs.py``),
and the theme's fonts and icons are its own files. ``make docs`` runs Sphinx
with ``-W --keep-going``: every warning fails the build.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
# the gallery runs the INS's parallel numba loops in this process before `-j auto` forks the readers:
# GNU OpenMP cannot survive a fork, numba's fork-safe layers can
os.environ.setdefault("NUMBA_THREADING_LAYER", "forksafe")

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))

from sphinx_gallery.sorting import ExplicitOrder  # noqa: E402

import schuler  # noqa: E402

GALLERY = DOCS.parent / "examples" / "gallery"
SYSTEM_ORDER = ("errors", "vertical", "calibrate", "align", "north", "navigate", "mission", "aided", "engine",
                "imu")
"""Gallery sections in the guide's order; a new system's folder is built after them ("*")."""

project = "schuler"
author = "the schuler developers"
copyright = "the schuler developers"
release = schuler.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "schuler_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# lab.md is read on its own (README) and included by guide/lab.md
exclude_patterns = ["_build", "lab.md", "gallery/**/*.ipynb", "gallery/**/*.py", "gallery/**/*.zip", "**/*.md5"]
templates_path = ["_templates"]
default_role = "code"
nitpicky = False

# the API reference: autosummary over the package (api/index.rst is written by schuler_docs from the package)
autosummary_generate = True
# every module's own public names (not __all__, which would hide a package's submodules)
autosummary_ignore_module_all = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"
autodoc_inherit_docstrings = False
autoclass_content = "class"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

myst_heading_anchors = 3

# MathJax offline: its menu could switch on the speech explorer, which fetches rule files from a CDN
mathjax3_config = {"options": {"enableMenu": False}}

sphinx_gallery_conf = {
    "examples_dirs": str(GALLERY),
    "subsection_order": ExplicitOrder([*(f"../examples/gallery/{name}" for name in SYSTEM_ORDER), "*"]),
    "gallery_dirs": "gallery",
    "backreferences_dir": "gallery/backreferences",
    "doc_module": ("schuler",),
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "default_thumb_file": None,
    "show_memory": False,
    "write_computation_times": False,  # its pages load jQuery and DataTables from CDNs
    "show_signature": False,
    "capture_repr": (),
    "reset_modules": ("matplotlib",),
}

html_theme = "pydata_sphinx_theme"
html_title = f"schuler {release}"
html_static_path = ["_static"]
html_css_files = ["schuler.css"]
html_show_sourcelink = False
html_copy_source = False
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 7,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "getting-started": [], "bibliography": []}
