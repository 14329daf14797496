"""Proofs: the exact identity checker and every proof obligation, and the
derivation files that ``symstab derive`` writes and checks for drift.
"""

from .._lazy import submodules

__getattr__ = submodules(__name__)
