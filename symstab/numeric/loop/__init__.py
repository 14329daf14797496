"""The loop: :class:`~symstab.Loop`, the model of any sampled haptic loop.

The loop object, the model (:mod:`.sampled_loop`); ``chi`` in floats, the
helper object every loop holds as ``Loop.evaluation``, and the questions
asked of ``chi`` at points (:mod:`.evaluation`); the questions of a plane
of two parameters: region, limits, boundary, stable intervals
(:mod:`.plane`); loop files (:mod:`.files`) and their units with pint
(:mod:`.quantities`).

May import: the base layer, ``symbolic``, ``codegen`` and
:mod:`symstab.numeric.engine`.  ``Loop``'s question methods are
pass-throughs to module functions of :mod:`symstab.numeric.analysis` and
:mod:`symstab.numeric.simulation`, imported inside the method (the only
upward imports, checked by ``tests/test_layers.py``).
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
