"""Code generation: the float-safe forms the kernels are generated from, the
printers and file layout (``symstab/_generated``), and any loop's kernels.
"""

from .._lazy import submodules

#: Modules that moved: ``forms`` shared its name with :mod:`symstab.symbolic.forms`.
MOVED = {"forms": "symstab.codegen.float_forms"}

__getattr__ = submodules(__name__, MOVED)
