"""Where symstab is: the running package's folder and its source checkout, if any.

Light on purpose (no SymPy): the command line imports it to resolve default
paths before any command runs.
"""

import importlib.metadata
import pathlib
import re

__all__ = ["PACKAGE_DIR", "project_root", "version", "package_version"]

#: The ``symstab`` package folder that is running.
PACKAGE_DIR = pathlib.Path(__file__).resolve().parent


def project_root(package_dir=None):
    """The source checkout that holds ``package_dir``, or None for an installed copy.

    A checkout is the folder just above the package with a ``pyproject.toml``
    that names the ``symstab`` project; a copy installed by ``pip`` sits in
    ``site-packages``, which has none.

    Parameters
    ----------
    package_dir : path-like
        The ``symstab`` package folder (default: the one running).

    Returns
    -------
    pathlib.Path or None
    """
    root = pathlib.Path(package_dir or PACKAGE_DIR).resolve().parent
    try:
        text = (root / "pyproject.toml").read_text(encoding="utf-8")
    except OSError:
        return None
    return root if re.search(r"""^name\s*=\s*["']symstab["']""", text, re.M) else None


def _installed_version():
    """The installed package's version (its metadata), or None for a checkout not installed."""
    try:
        return importlib.metadata.version("symstab")
    except importlib.metadata.PackageNotFoundError:
        return None


def _checkout_version():
    """``(version, root)`` of the checkout's ``pyproject.toml``; ``(None, root)`` without one."""
    root = project_root()
    if root is None:
        return None, None
    try:
        import tomllib
    except ImportError:   # Python 3.10: no TOML reader in the standard library
        return None, root
    with open(root / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh).get("project", {}).get("version") or None, root


def version():
    """symstab's version: the installed package's metadata, else the checkout's ``pyproject.toml``.

    ``symstab.__version__``.  A checkout run without ``pip install`` has no
    metadata; a copy with neither says ``"0+unknown"``.

    Returns
    -------
    str
    """
    return _installed_version() or _checkout_version()[0] or "0+unknown"


def package_version():
    """:func:`version` as ``symstab --version`` says it: a checkout not installed is named.

    Returns
    -------
    str
    """
    installed = _installed_version()
    if installed:
        return installed
    found, root = _checkout_version()
    if found:
        return f"{found} (source checkout {root}, not installed)"
    return "unknown (not installed: no package metadata)"
