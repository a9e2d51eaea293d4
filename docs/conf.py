"""Sphinx configuration of the fenics-drill manual (``make docs``).

Sphinx with MyST: the pages are Markdown, as they read on GitHub; autodoc builds the API reference from the
docstrings; sphinx-gallery runs the scripts of ``demos/gallery/`` when the site is built and shows their figures;
the scene reference is generated from the Scene dataclasses (:func:`fenics_drill.scene.describe_keys`) by
``_ext/generated_reference.py``.  ``make docs`` builds with warnings as errors, so a broken internal link fails.
"""

import sys
from pathlib import Path

import fenics_drill

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE / "_ext"))

project = "fenics-drill"
author = "fenics-drill developers"
release = fenics_drill.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 copied into _static: the equations render without internet access
    "sphinx_gallery.gen_gallery",
    "generated_reference",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 4
exclude_patterns = ["_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip", "**/*.codeobj.json"]

html_theme = "furo"
html_title = f"fenics-drill {release}"
html_static_path = []

autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}

sphinx_gallery_conf = {
    "examples_dirs": [str(HERE.parent / "demos" / "gallery")],
    "gallery_dirs": ["gallery"],
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
}

# An ambiguous short name in a docstring (``q`` of two classes) resolves to the first; not worth a failure.
suppress_warnings = ["config.cache", "ref.python"]


def _plain_bars(app, what, name, obj, options, lines):
    """The docstrings are plain text where |x| is an absolute value, not an RST substitution."""
    lines[:] = [line.replace("|", "\\|") for line in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars)
