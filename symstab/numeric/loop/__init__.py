"""The loop: :class:`~symstab.Loop`, the model of any sampled haptic loop.

The loop object and its evaluation (:mod:`.sampled_loop`), loop files
(:mod:`.files`) and their units with pint (:mod:`.quantities`).

May import: the base layer, ``symbolic``, ``codegen`` and
:mod:`symstab.numeric.engine`.  ``Loop``'s question methods are
pass-throughs to module functions of :mod:`symstab.numeric.analysis` and
:mod:`symstab.numeric.simulation`, imported inside the method (the only
upward imports, checked by ``tests/test_layers.py``).
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
