"""The derivation in SymPy: the model, the ZOH pulse transfer function, the loop
polynomial, its split on the unit circle, the boundary, theta_max and the
small-theta limits, and any loop's symbolic assembly.
"""

from .._lazy import submodules

__getattr__ = submodules(__name__)
