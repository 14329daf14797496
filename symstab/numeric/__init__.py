"""The numeric API on the generated kernels: stability, the region engine and
limits, boundary curves, units, simulation, the 30-digit reference, and
:class:`symstab.Loop` for any loop.
"""


def __getattr__(name):
    # Modules load on first use (``symstab.numeric.stability`` after ``import symstab``).
    import importlib
    import importlib.util

    if name.startswith("__") or importlib.util.find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return importlib.import_module(f"{__name__}.{name}")
