"""The paper's loop: Table I's dimensionless plane, as adapters over the engine.

The paper's device and its units (:mod:`.device`), ``PAPER_LOOP``
(:mod:`.paper_loop`), stability in (alpha, beta, gamma) (:mod:`.stability`),
the paper's region and line questions (:mod:`.region`), the paper's arc and
theta_max in floating point (:mod:`.curves`) and certified
(:mod:`.theta_bounds`), the paper's simulator (:mod:`.simulate`) and its
linear theory (:mod:`.simulate_theory`), and the 30-digit reference of the
derived boundary (:mod:`.reference`).

May import everything of :mod:`symstab.numeric`; only the front ends,
``paper_checks`` and ``symstab/__init__.py`` import it.
"""

from ..._lazy import submodules

__getattr__ = submodules(__name__)
