"""The derivation in SymPy: the model, the ZOH pulse transfer function, the loop
polynomial, its split on the unit circle, the boundary, theta_max and the
small-theta limits, and any loop's symbolic assembly.
"""


def __getattr__(name):
    # Modules load on first use (``symstab.numeric.stability`` after ``import symstab``).
    import importlib
    import importlib.util

    if name.startswith("__") or importlib.util.find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return importlib.import_module(f"{__name__}.{name}")
