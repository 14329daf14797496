"""Analysis: the questions asked of a loop beyond its stable set.

Passivity (:mod:`.passivity`), robust sets over a box of uncertain
parameters (:mod:`.robust`), the probability of stability
(:mod:`.probability`) and the design search (:mod:`.design`).

May import: the base layer, ``symbolic``, ``codegen``,
:mod:`symstab.numeric.engine`, :mod:`symstab.numeric.loop` and
:mod:`symstab.numeric.simulation` (the design's simulated target).
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
