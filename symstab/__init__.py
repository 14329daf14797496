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

:mod:`~symstab.codegen.forms` rewrites the boundary and the loop polynomial in
forms that keep their digits in floating point, :mod:`~symstab.codegen.generator`
prints them as NumPy and C99 kernels into ``symstab/_generated``, and the
numeric API builds on those: :mod:`~symstab.numeric.units` (:class:`Device`),
:mod:`~symstab.numeric.curves` and :mod:`~symstab.numeric.region` (:func:`boundary_curve`), :mod:`~symstab.numeric.stability`
(:func:`spectral_radius`, :func:`is_stable`, :func:`classify`),
:mod:`~symstab.numeric.region` (:func:`limits`, :func:`best_virtual_mass`) and
:mod:`~symstab.numeric.simulate` (:func:`simulate`, :func:`stability_map`, with
the :class:`Nonidealities` of a real device).

Any other loop -- the user's own plant and virtual environment -- is a
:class:`Loop` (:mod:`~symstab.numeric.any_loop`), derived and classified the same
way, and can be read from a TOML loop file (:func:`load_loop`).  The paper's
loop is one of them: ``PAPER_LOOP`` (:mod:`~symstab.numeric.paper_loop`, built
on first use), on the same root engine (:mod:`~symstab.numeric.roots`) as the
dimensionless functions above.
"""

from .symbolic.boundary import boundary, coefficients
from .symbolic.discretize import dimensionless_pulse_transfer_function, pulse_transfer_function
from .proof.identity import IdentityResult, assert_identity, check_identity
from .symbolic.small_theta import small_theta_limits
from .symbolic.loop import characteristic_polynomial
from .symbolic.model import dimensionless_values
from .symbolic.theta_max import closed_form_d0, newton_form_gamma0, theta_max, theta_max_newton
from .symbolic.unit_circle import unit_circle_split
from .numeric.units import PAPER_DEVICE, Device
from .numeric.curves import BoundaryCurve, arc_end_angle
from .numeric.region import boundary_curve
from .numeric.stability import MARGINAL, STABLE, UNSTABLE, classify, is_stable, spectral_radius
from .numeric.region import BestVirtualMass, StabilityRegion, best_virtual_mass, limits
from .numeric.results import Limits, RobustRegion, StabilityProbability
from .numeric.any_loop import Loop, LoopBoundary, LoopLimits
from .numeric.loop_files import load_loop
from .symbolic.loop_assembly import NonPhysicalPlantWarning
from .numeric.decomposition import Branch, Cell, Decomposition
from .numeric.passivity import PassiveRegion, passive_region
from .numeric.paper_loop import paper_passive_region
from .numeric.locus import Crossing, Locus, locus
from .numeric.paper_loop import paper_locus
from .numeric.simulate import Nonidealities, Simulation, StabilityMap, simulate, stability_map
from .numeric.theta_bounds import (ThetaMaxEnclosure, certify_theta_max, theta_max_approx,
                                   theta_max_enclosure)

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
]


def __getattr__(name):
    # PAPER_LOOP is derived on first use, not on import (about a second).
    if name == "PAPER_LOOP":
        from .numeric.paper_loop import paper_loop

        return paper_loop()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
