"""Sphinx configuration of the symstab manual.

Build it with ``sphinx-build -W --keep-going -n -b html docs docs/_build/html``
(``pip install ".[docs]"`` first).  No network: there is no intersphinx, and the
names of other libraries that the docstrings mention are the only ones left
unresolved (``nitpick_ignore_regex`` below).
"""

import os
import pathlib

import symstab

DOCS = pathlib.Path(__file__).resolve().parent
REPO = DOCS.parent

project = "symstab"
author = "The symstab developers"
copyright = "The symstab developers"
release = symstab.__version__
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "numpydoc",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "matplotlib.sphinxext.plot_directive",
    "sphinx_copybutton",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
# derivations/ is a link to the repository's notebooks; its generated/ and
# figures/ folders are data, not pages.
exclude_patterns = ["_build", "derivations/generated", "derivations/figures", "**/.ipynb_checkpoints"]

nitpicky = True
# Names of other libraries in the docstrings: without intersphinx (the build
# needs no network) they have no target here.  Only they are ignored.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|sympy|sp|scipy|matplotlib|mpmath|control|dask|distributed|pint)(\..*)?"),
    (r"py:.*", r"(ndarray|array_like|array-like|ArrayLike|Expr|Symbol|Poly|Basic|Matrix|Rational"
               r"|TransferFunction|Figure|Axes|Quantity|mpf|mpc|iv\.mpf|rv_frozen|Client)"),
]

# --- MyST and notebooks ----------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
# The notebooks are stored without outputs (tests/test_docs.py): the build
# executes every one, and a cell that raises fails it.
nb_execution_mode = "force"
nb_execution_timeout = 600
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True

# --- API reference ---------------------------------------------------------
templates_path = ["_templates"]
autosummary_generate = True
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- The command line ------------------------------------------------------
# sphinxarg imports symstab.cli.commands and calls build_parser.

# --- Figures drawn at build time ------------------------------------------
plot_include_source = True
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 100)]
plot_pre_code = "import numpy as np\nimport matplotlib.pyplot as plt\nimport symstab"
plot_working_directory = str(REPO)

# --- HTML ---------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"symstab {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path = []
