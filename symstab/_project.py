"""Where symstab is: the running package's folder and its source checkout, if any.

Light on purpose (no SymPy): the command line imports it to resolve default
paths before any command runs.
"""

import pathlib
import re

__all__ = ["PACKAGE_DIR", "project_root"]

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
