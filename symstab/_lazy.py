"""Sub-packages whose modules load on first use, and modules that moved.

``import symstab`` costs nothing up front (the command line must handle
Ctrl-C before SymPy and NumPy load), yet ``symstab.numeric.engine.roots``
works after it whatever was imported first: each package's ``__getattr__``
imports the submodule asked for.  A module that moved keeps its old path
one release: importing it (or reaching it as an attribute) warns with a
:class:`DeprecationWarning` naming the new home and gives the module there.
"""

import importlib
import importlib.abc
import importlib.util
import sys
import warnings


def submodules(package, moved=None):
    """A module-level ``__getattr__`` for ``package`` that imports its submodules on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    moved : dict, optional
        ``{old submodule name: new dotted module path}`` of modules that
        left ``package``: ``import package.old`` and ``package.old`` still
        work, with a :class:`DeprecationWarning`.

    Returns
    -------
    callable
        ``__getattr__(name)``: the submodule ``package.name``, imported;
        ``AttributeError`` for a name that is no submodule.
    """
    moved = dict(moved or {})
    if moved:
        _MOVED.update({f"{package}.{old}": new for old, new in moved.items()})
        if not any(isinstance(finder, _MovedFinder) for finder in sys.meta_path):
            sys.meta_path.append(_MovedFinder())

    def __getattr__(name):
        if name in moved:
            return _moved_module(f"{package}.{name}", stacklevel=3)
        if name.startswith("__") or importlib.util.find_spec(f"{package}.{name}") is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return importlib.import_module(f"{package}.{name}")

    return __getattr__


#: ``{old dotted path: new dotted path}`` of every moved module.
_MOVED = {}


def _moved_module(old, *, stacklevel):
    new = _MOVED[old]
    warnings.warn(f"{old} moved to {new}; the old path goes in the next release",
                  DeprecationWarning, stacklevel=stacklevel)
    return importlib.import_module(new)


class _MovedFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """``import <old path>``: the module at its new home, under both names."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname not in _MOVED:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        # The import system's own frames sit between the importer and here.
        module = _moved_module(spec.name, stacklevel=8)
        spec.loader_state = module.__spec__     # this import's own, for exec_module
        return module

    def exec_module(self, module):
        # The import system has just given the module the old path's spec;
        # its own is put back, or its relative imports would resolve against
        # the old package, with an ImportWarning ("__package__ !=
        # __spec__.parent").
        module.__spec__ = module.__spec__.loader_state
