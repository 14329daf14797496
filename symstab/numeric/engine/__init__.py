"""The engine: what every loop's questions are computed with.

The characteristic polynomial kept in its structure (:mod:`.polynomial`),
the one root engine with the classes ``STABLE``/``MARGINAL``/``UNSTABLE``
(:mod:`.roots`), the arc of a plane (:mod:`.arcs`), the one line engine
(:mod:`.intervals`), the D-decomposition (:mod:`.decomposition`), the root
locus (:mod:`.locus`), the generic searches (:mod:`.search`: the grid, the
root bracketer, the maximiser) and one result type per question
(:mod:`.results`).

May import: the base layer, ``symbolic`` and ``codegen``; nothing else of
``numeric``.  Knows no loop object and no paper: it takes polynomials,
arcs and callables.
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
