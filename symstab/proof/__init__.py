"""Proofs: the exact identity checker and every proof obligation, and the
derivation files that ``symstab derive`` writes and checks for drift.
"""


def __getattr__(name):
    # Modules load on first use (``symstab.numeric.stability`` after ``import symstab``).
    import importlib
    import importlib.util

    if name.startswith("__") or importlib.util.find_spec(f"{__name__}.{name}") is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return importlib.import_module(f"{__name__}.{name}")
