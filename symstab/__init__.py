"""symstab: symbolic derivation and verification of haptic-rendering stability.

symstab re-derives, from the plant and the virtual environment, the stability
boundary of a 1-DOF haptic device with a zero-order hold, a constant loop
delay of ``d`` samples and a virtual mass-spring-damper (Mashayekhi et al.,
IEEE Trans. Haptics, 2025), and checks the paper's printed equations against
it.

The modules follow the data flow: :mod:`~symstab.model` (symbols, plant,
environment) -> :mod:`~symstab.discretize` (ZOH pulse transfer function) ->
:mod:`~symstab.loop` (characteristic polynomial) ->
:mod:`~symstab.unit_circle` -> :mod:`~symstab.boundary` (alpha(theta),
beta(theta), C-coefficients) -> :mod:`~symstab.small_theta`,
:mod:`~symstab.theta_max`; :mod:`~symstab.identity` is the exact equality
checker and :mod:`~symstab.derive` writes everything out.

:mod:`~symstab.kernel_forms` rewrites the boundary and the loop polynomial in
forms that keep their digits in floating point, :mod:`~symstab.codegen`
prints them as NumPy and C99 kernels into ``symstab/_generated``, and the
numeric API builds on those: :mod:`~symstab.units` (:class:`Device`),
:mod:`~symstab.curves` (:func:`boundary_curve`), :mod:`~symstab.stability`
(:func:`spectral_radius`, :func:`is_stable`, :func:`classify`) and
:mod:`~symstab.region` (:func:`limits`, :func:`best_virtual_mass`).

Any other loop -- the user's own plant and virtual environment -- is a
:class:`Loop` (:mod:`~symstab.any_loop`), derived and classified the same
way, and can be read from a TOML loop file (:func:`load_loop`).
"""

from .boundary import boundary, coefficients
from .discretize import dimensionless_pulse_transfer_function, pulse_transfer_function
from .identity import IdentityResult, assert_identity, check_identity
from .small_theta import small_theta_limits
from .loop import characteristic_polynomial
from .model import dimensionless_values
from .theta_max import closed_form_d0, newton_form_gamma0, theta_max, theta_max_newton
from .unit_circle import unit_circle_split
from .units import PAPER_DEVICE, Device
from .curves import BoundaryCurve, arc_end_angle, boundary_curve
from .stability import MARGINAL, STABLE, UNSTABLE, classify, is_stable, spectral_radius
from .region import BestVirtualMass, Limits, StabilityRegion, best_virtual_mass, limits
from .any_loop import Loop, LoopBoundary, LoopLimits
from .loop_files import load_loop

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
    "Loop", "LoopBoundary", "LoopLimits", "load_loop",
]
