"""symstab: symbolic derivation and verification of haptic-rendering stability.

symstab re-derives, from the plant and the virtual environment, the stability
boundary of a 1-DOF haptic device with a zero-order hold, a constant loop
delay of ``d`` samples and a virtual mass-spring-damper (Mashayekhi et al.,
IEEE Trans. Haptics, 2025), and checks the paper's printed equations against
it.

The modules follow the data flow: :mod:`~symstab.symbolic.model` (symbols, plant,
environment) -> :mod:`~symstab.symbolic.discretize` (ZOH pulse transfer function) ->
:mod:`~symstab.symbolic.loop` (characteristic polynomial) ->
:mod:`~symstab.symbolic.unit_circle` -> :mod:`~symstab.symbolic.boundary` (alpha(theta),
beta(theta), C-coefficients) -> :mod:`~symstab.symbolic.small_theta`,
:mod:`~symstab.symbolic.theta_max`; :mod:`~symstab.proof.identity` is the exact equality
checker and :mod:`~symstab.proof.derive` writes everything out.

:mod:`~symstab.codegen.float_forms` rewrites the boundary and the loop polynomial in
forms that keep their digits in floating point, :mod:`~symstab.codegen.generator`
prints them as NumPy and C99 kernels into ``symstab/_generated``, and the
numeric API builds on those: :mod:`~symstab.numeric.paper.device` (:class:`Device`),
:mod:`~symstab.numeric.paper.curves` and :mod:`~symstab.numeric.paper.region` (:func:`boundary_curve`), :mod:`~symstab.numeric.paper.stability`
(:func:`spectral_radius`, :func:`is_stable`, :func:`classify`),
:mod:`~symstab.numeric.paper.region` (:func:`limits`, :func:`best_virtual_mass`) and
:mod:`~symstab.numeric.paper.simulate` (:func:`simulate`, :func:`stability_map`, with
the :class:`Nonidealities` of a real device).

Any other loop -- the user's own plant and virtual environment -- is a
:class:`Loop` (:mod:`~symstab.numeric.loop.sampled_loop`), derived and classified the same
way, and can be read from a TOML loop file (:func:`load_loop`).  The paper's
loop is one of them: ``PAPER_LOOP`` (:mod:`~symstab.numeric.paper.paper_loop`, built
on first use), on the same root engine (:mod:`~symstab.numeric.engine.roots`) as the
dimensionless functions above.
"""

import importlib

#: Where each public name lives (module below ``symstab``).  Imported on first
#: use (PEP 562), so that ``import symstab`` -- and the command line, which
#: must handle Ctrl-C before SymPy and NumPy load -- costs nothing up front.
_HOMES = {
    "symbolic.boundary": ("boundary", "coefficients"),
    "symbolic.discretize": ("dimensionless_pulse_transfer_function", "pulse_transfer_function"),
    "proof.identity": ("IdentityResult", "assert_identity", "check_identity"),
    "symbolic.small_theta": ("small_theta_limits",),
    "symbolic.loop": ("characteristic_polynomial",),
    "symbolic.model": ("dimensionless_values",),
    "symbolic.theta_max": ("closed_form_d0", "newton_form_gamma0", "theta_max", "theta_max_newton"),
    "symbolic.unit_circle": ("unit_circle_split",),
    "numeric.engine.roots": ("MARGINAL", "STABLE", "UNSTABLE"),
    "numeric.engine.results": ("Limits", "RobustRegion", "StabilityProbability"),
    "numeric.engine.decomposition": ("Branch", "Cell", "Decomposition"),
    "numeric.engine.locus": ("Crossing", "Locus", "locus"),
    "numeric.loop.sampled_loop": ("Loop", "LoopBoundary", "LoopLimits"),
    "numeric.loop.files": ("load_loop",),
    "symbolic.loop_assembly": ("NonPhysicalPlantWarning",),
    "numeric.simulation.simulator": ("Nonidealities", "Simulation", "StabilityMap"),
    "numeric.analysis.passivity": ("PassiveRegion", "passive_region"),
    "numeric.analysis.margins": ("MarginMap", "Margins", "NyquistCrossing", "ParameterMargin"),
    "numeric.analysis.noise": ("ForceNoise",),
    "numeric.analysis.delays": ("DelayMargin", "DelaySwitch"),
    "numeric.analysis.delay_range": ("DelayRange", "DelayRangeMap", "DelayRangeRegion"),
    "numeric.paper.device": ("PAPER_DEVICE", "Device"),
    "numeric.paper.curves": ("BoundaryCurve", "arc_end_angle"),
    "numeric.paper.stability": ("classify", "is_stable", "spectral_radius"),
    "numeric.paper.region": ("boundary_curve", "BestVirtualMass", "StabilityRegion",
                             "best_virtual_mass", "limits"),
    "numeric.paper.paper_loop": ("paper_passive_region", "paper_locus"),
    "numeric.paper.simulate": ("simulate", "stability_map"),
    "numeric.paper.theta_bounds": ("ThetaMaxEnclosure", "certify_theta_max", "theta_max_approx",
                                   "theta_max_enclosure"),
}
_HOME_OF = {name: module for module, names in _HOMES.items() for name in names}

#: The sub-packages and modules, importable as attributes (``symstab.numeric``).
_SUBMODULES = ("symbolic", "codegen", "proof", "numeric", "cli", "drawing", "figures",
               "reproduce")

__all__ = [
    "boundary", "coefficients",
    "pulse_transfer_function", "dimensionless_pulse_transfer_function",
    "IdentityResult", "check_identity", "assert_identity",
    "small_theta_limits", "characteristic_polynomial", "dimensionless_values",
    "closed_form_d0", "newton_form_gamma0", "theta_max", "theta_max_newton",
    "unit_circle_split",
    "Device", "PAPER_DEVICE",
    "BoundaryCurve", "arc_end_angle", "boundary_curve",
    "STABLE", "MARGINAL", "UNSTABLE", "classify", "is_stable", "spectral_radius",
    "StabilityRegion", "Limits", "limits", "BestVirtualMass", "best_virtual_mass",
    "Loop", "LoopBoundary", "LoopLimits", "load_loop", "PAPER_LOOP", "NonPhysicalPlantWarning",
    "Decomposition", "Cell", "Branch",
    "PassiveRegion", "passive_region", "paper_passive_region",
    "Locus", "Crossing", "locus", "paper_locus",
    "ThetaMaxEnclosure", "theta_max_enclosure", "certify_theta_max",
    "theta_max_approx",
    "Nonidealities", "Simulation", "simulate", "StabilityMap", "stability_map",
    "StabilityProbability",
    "RobustRegion",
    "Margins", "NyquistCrossing", "ParameterMargin", "MarginMap", "ForceNoise",
    "DelayMargin", "DelaySwitch", "DelayRange", "DelayRangeMap", "DelayRangeRegion",
]


def __getattr__(name):
    if name == "__version__":
        # From the installed package's metadata (one file read, on first use).
        from ._project import version

        globals()[name] = version()
        return globals()[name]
    if name == "PAPER_LOOP":
        # Derived on first use, and again each time it is asked for (cached
        # by paper_loop()): about a second the first time.
        from .numeric.paper.paper_loop import paper_loop

        return paper_loop()
    if name in _HOME_OF:
        value = getattr(importlib.import_module(f"{__name__}.{_HOME_OF[name]}"), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__) | {"__version__"})
