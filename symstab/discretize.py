"""The zero-order-hold pulse transfer function, derived from G(s).

Z[ZOH G(s)] = (1 - z^-1) Z[G(s)/s], and the z-transform of the sampled
impulse response of F(s) = G(s)/s is the sum of the residues of
F(s) z / (z - exp(s T)) at the poles of F (a double pole at s = 0 and a
simple pole at s = -b/m).  Nothing here is typed in from the paper's eq. (4).
"""

import functools

import sympy as sp

from . import model

__all__ = [
    "z_transform_by_residues",
    "pulse_transfer_function",
    "dimensionless_pulse_transfer_function",
]


def z_transform_by_residues(F, *, s=model.s, z=model.z, T=model.T):
    """Return Z[f(kT)] for a rational F(s) that is strictly proper.

    Z[f(kT)] = sum over the poles p of F of Res(F(s) z / (z - exp(s T)), p).
    """
    num, den = sp.fraction(sp.together(F))
    if sp.degree(num, s) >= sp.degree(den, s):
        raise ValueError("F(s) must be strictly proper for the residue formula")
    kernel = F * z / (z - sp.exp(s * T))
    return sp.Add(*[sp.residue(kernel, s, pole) for pole in sp.roots(den, s)])


@functools.lru_cache(maxsize=None)
def pulse_transfer_function():
    """Return Z[ZOH G(s)] in the physical parameters m, b, T.

    Returns
    -------
    sympy.Expr
        A rational function of ``z``, the derived counterpart of eq. (4).
    """
    step_response = z_transform_by_residues(model.plant() / model.s)
    return sp.factor(sp.simplify((1 - 1 / model.z) * step_response))


@functools.lru_cache(maxsize=None)
def dimensionless_pulse_transfer_function():
    """Return ``(m / T**2) Z[ZOH G(s)]`` in ``delta`` and ``Gamma``.

    With ``b = delta m / T`` the factor ``T**2 / m`` separates and the rest
    depends on ``delta`` and ``Gamma = exp(delta)`` only:
    ``N(z) / (delta**2 (z - 1) (Gamma z - 1))``.
    """
    scaled = (pulse_transfer_function() * model.m / model.T**2).subs(model.dimensionless_substitution())
    scaled = sp.simplify(scaled).subs(sp.exp(model.delta), model.Gamma)
    result = sp.factor(sp.cancel(scaled), model.z)
    if result.has(model.m) or result.has(model.T):
        raise AssertionError(f"pulse transfer function did not become dimensionless: {result}")
    return result
