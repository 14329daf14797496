"""Simulation: any loop in time.

The loop simulator with its non-idealities (:mod:`.simulator`), Coulomb
friction on the plant's state space (:mod:`.friction`) and the simulated
K_max (:mod:`.simulated_limit`).

May import: the base layer, ``symbolic``, ``codegen``,
:mod:`symstab.numeric.engine` and :mod:`symstab.numeric.loop`.
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
