"""The numeric API, in rooms by concern (each sub-package says what it may import):

- :mod:`~symstab.numeric.engine`: the polynomial, the root engine, arcs,
  lines, the D-decomposition, the locus, the generic searches, the result
  types;
- :mod:`~symstab.numeric.loop`: :class:`symstab.Loop`, loop files and units;
- :mod:`~symstab.numeric.simulation`: any loop in time;
- :mod:`~symstab.numeric.analysis`: passivity, robust sets, probability,
  design;
- :mod:`~symstab.numeric.paper`: the paper's plane, as adapters over the rest.

The modules' old flat paths (``symstab.numeric.simulate``, ...) still import,
with a :class:`DeprecationWarning` naming the new one; they go in the next
release.
"""

from .._lazy import submodules

#: The old flat module names and where each now lives.
MOVED = {
    "polynomial": "symstab.numeric.engine.polynomial",
    "roots": "symstab.numeric.engine.roots",
    "arcs": "symstab.numeric.engine.arcs",
    "intervals": "symstab.numeric.engine.intervals",
    "locus": "symstab.numeric.engine.locus",
    "decomposition": "symstab.numeric.engine.decomposition",
    "results": "symstab.numeric.engine.results",
    "any_loop": "symstab.numeric.loop.sampled_loop",
    "loop_files": "symstab.numeric.loop.files",
    "loop_units": "symstab.numeric.loop.quantities",
    "loop_simulate": "symstab.numeric.simulation.simulator",
    "friction": "symstab.numeric.simulation.friction",
    "simulate_limit": "symstab.numeric.simulation.simulated_limit",
    "passivity": "symstab.numeric.analysis.passivity",
    "robust": "symstab.numeric.analysis.robust",
    "probability": "symstab.numeric.analysis.probability",
    "design": "symstab.numeric.analysis.design",
    "units": "symstab.numeric.paper.device",
    "stability": "symstab.numeric.paper.stability",
    "region": "symstab.numeric.paper.region",
    "curves": "symstab.numeric.paper.curves",
    "theta_bounds": "symstab.numeric.paper.theta_bounds",
    "simulate": "symstab.numeric.paper.simulate",
    "simulate_theory": "symstab.numeric.paper.simulate_theory",
    "evaluate": "symstab.numeric.paper.reference",
    "paper_loop": "symstab.numeric.paper.paper_loop",
    "sweep": "symstab.cli.sweep_store",
}

__getattr__ = submodules(__name__, MOVED)
