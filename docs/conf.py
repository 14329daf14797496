"""Sphinx configuration of the symstab manual.

Build it with ``sphinx-build -W --keep-going -n -b html docs docs/_build/html``
(``pip install ".[docs]"`` first).  No network: there is no intersphinx, and the
names of other libraries that the docstrings mention are the only ones left
unresolved (``nitpick_ignore_regex`` below).
"""

import functools
import pathlib
import sys

import symstab

DOCS = pathlib.Path(__file__).resolve().parent
REPO = DOCS.parent
# docs/_ext: the command line's parser as the CLI reference renders it, the
# notebooks run in one shared kernel, and numpydoc's template compiled once.
sys.path.insert(0, str(DOCS / "_ext"))

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
    # numpydoc's docstring template compiled once per build, not once per docstring.
    "numpydoc_template",
    "sphinx.ext.mathjax",
    # MathJax served from the site itself (the build and the pages need no network).
    "sphinx-mathjax-offline",
    "sphinxarg.ext",
    "matplotlib.sphinxext.plot_directive",
    "sphinx_copybutton",
    "shared_kernel",
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
    (r"py:.*", r"(numpy|sympy|scipy|matplotlib|mpmath|control|dask|distributed|pint)(\..*)?"),
    # Python's standard library (a signature's annotation).
    (r"py:.*", r"fractions\..*"),
]

# --- MyST and notebooks ----------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
# The notebooks write display math $$...$$ inside their paragraphs, as Jupyter reads it.
myst_dmath_double_inline = True
myst_heading_anchors = 3
# The notebooks are stored without outputs (tests/test_docs.py): the build
# executes every one, in one shared kernel (docs/_ext/shared_kernel.py: myst-nb
# would start one per notebook), and a cell that raises fails it.
nb_execution_mode = "off"
nb_merge_streams = True

# --- API reference ---------------------------------------------------------
templates_path = ["_templates"]
autosummary_generate = True
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# The library's signatures are annotated; it has no ``# type:`` comment for
# autodoc to read (reading them parses the source of every function again: about
# a second of the build).
autodoc_use_type_comments = False


def _not_described_here():
    """For each module of the library, the classes its page must not describe again.

    A class has one description, under one name: those of ``symstab.__all__``
    on their top-level page (``symstab.Loop``, its module's name being its
    canonical name), the others on the page of the module that defines them;
    a module that re-exports a class (in its ``__all__``) links to it.
    """
    import importlib
    import pkgutil

    # An alias (BoundaryCurve for Boundary) is described on its top page as an
    # alias: its class is described on its module's page.
    public = {id(getattr(symstab, name)) for name in symstab.__all__
              if getattr(getattr(symstab, name), "__name__", None) == name}
    found = {}
    for info in pkgutil.walk_packages(symstab.__path__, "symstab."):
        if any(part.startswith("_") for part in info.name.split(".")) or info.name.startswith("symstab.cli"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if isinstance(obj, type) and (id(obj) in public or obj.__module__ != info.name):
                found.setdefault(info.name, []).append(name)
    return found


autosummary_context = {"not_described_here": _not_described_here()}

# --- The command line ------------------------------------------------------
# sphinxarg calls docs/_ext/cli_reference.build_parser: symstab.cli.commands.build_parser's
# parser, its terminal-laid texts made literal for reST.

# --- Figures drawn at build time ------------------------------------------
plot_include_source = True
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 100)]
plot_pre_code = "import numpy as np\nimport matplotlib.pyplot as plt\nimport symstab"
plot_working_directory = str(REPO)

# Option names (--check, --loop) keep their two hyphens: no dashes from smart quotes.
smartquotes_action = "qe"
# Every code fence of the pages names its language; what has none (the command
# line's usage and its hand-laid tables) is plain text.
highlight_language = "text"

# --- HTML ---------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"symstab {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path = []

autosummary_ignore_module_all = False


# --- References by short name ------------------------------------------------
# The docstrings name symstab's own objects as their module does
# (:func:`decompose`, :data:`MARGINAL`, :class:`Nonidealities` where the module
# imported it, :attr:`symstab.Loop.plane`), which Sphinx resolves only when the
# name is documented under exactly that name.  Such a name is resolved here to
# the documented description of the same object: the name as the module or
# class that mentions it sees it, else the one documented name ending with it,
# else (an attribute a class lists in its Attributes section, without an entry
# of its own) that class.  Private names are never resolved: a name that
# matches nothing stays a warning.


@functools.cache
def _lookup(path):
    """The object a dotted path names, or None (remembered: a build does not change modules)."""
    import importlib

    parts = path.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            for part in parts[cut:]:
                obj = getattr(obj, part)
        except AttributeError:
            return None
        return obj
    return None


_DOCUMENTED = {}


def _documented(env):
    """symstab's documented objects: name -> entry, id(object) -> names, last part -> names."""
    # Filtered again only when the domain has changed (its size): a build asks
    # this for every unresolved name.
    every = env.get_domain("py").objects
    if _DOCUMENTED.get("count") != len(every):
        objects = {name: entry for name, entry in every.items() if name.startswith("symstab.")}
        by_id, by_last = {}, {}
        for name in objects:
            obj = _lookup(name)
            if obj is not None:
                by_id.setdefault(id(obj), []).append(name)
            by_last.setdefault(name.rsplit(".", 1)[-1], []).append(name)
        _DOCUMENTED.update(count=len(every), objects=objects, by_id=by_id, by_last=by_last)
    return _DOCUMENTED["objects"], _DOCUMENTED["by_id"], _DOCUMENTED["by_last"]


def _lists(obj, attribute):
    """Whether the docstring of ``obj`` (or of a class it derives from) has an entry ``attribute : ...``."""
    import inspect
    import re

    for klass in inspect.getmro(obj if isinstance(obj, type) else type(obj)):
        for line in inspect.cleandoc(klass.__doc__ or "").splitlines():
            entry = re.match(r"([\w, ]+?)(?: :|$)", line)
            if entry and not line.startswith(" ") and attribute in entry.group(1).split(", "):
                return True
    return False


def _page_scopes(refdoc):
    """The scopes of the object whose reference page ``refdoc`` is: its module, its class."""
    if not refdoc.startswith("reference/generated/"):
        return []
    obj = _lookup(refdoc.rsplit("/", 1)[1])
    if obj is None or type(obj).__name__ == "module":
        return []
    if not (isinstance(obj, type) or callable(obj)):
        obj = type(obj)          # a documented instance (PAPER_LOOP): its class's names
    module = getattr(obj, "__module__", None) or ""
    scopes = [f"{module}.{obj.__qualname__}."] if isinstance(obj, type) else []
    qualname = getattr(obj, "__qualname__", "")
    if "." in qualname:          # a method: its class
        scopes.append(f"{module}.{qualname.rsplit('.', 1)[0]}.")
    return scopes + [f"{module}."] if module.startswith("symstab") else []


def _resolve(env, target, module, cls, page=()):
    objects, by_id, by_last = _documented(env)
    scopes = [f"{module}.{cls}." if module and cls else None, f"{module}." if module else None,
              *page, "symstab.", ""]
    candidates = [scope + target for scope in scopes if scope is not None]
    for name in candidates:
        if name in objects:
            return name
    for name in candidates:
        obj = _lookup(name) if name.startswith("symstab.") else None
        same = [n for n in by_id.get(id(obj), ())
                if n.rsplit(".", 1)[-1] == target.rsplit(".", 1)[-1] or isinstance(obj, type)]
        if obj is not None and same:
            return min(same, key=len)
    found = [name for name in by_last.get(target.rsplit(".", 1)[-1], ())
             if name.endswith("." + target)]
    if len(found) == 1:
        return found[0]
    owner, attribute = target.rsplit(".", 1) if "." in target else (cls, target)
    if owner:
        owner = _resolve(env, owner, module, None)
        # An attribute the class lists in its docstring's Attributes section.
        if (owner is not None and objects[owner].objtype in ("class", "exception", "data")
                and _lists(_lookup(owner), attribute)):
            return owner
    return None


def _resolve_short_names(app, env, node, contnode):
    from sphinx.util.nodes import make_refnode

    target = node.get("reftarget", "")
    if node.get("refdomain") != "py" or target.startswith("symstab._") or "._" in target or target.startswith("_"):
        return None
    name = _resolve(env, target.lstrip(".~"), node.get("py:module"), node.get("py:class"),
                    _page_scopes(node["refdoc"]))
    if name is None:
        return None
    entry = _documented(env)[0][name]
    return make_refnode(app.builder, node["refdoc"], entry.docname, entry.node_id, contnode, name)


def setup(app):
    app.connect("missing-reference", _resolve_short_names)
