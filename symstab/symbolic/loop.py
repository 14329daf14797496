"""The closed-loop characteristic polynomial, for a symbolic integer delay d.

The loop 1 + VE(z) z^-d Z[ZOH G(s)] = 0 is multiplied through by
``z**(d + 2)`` times the denominator of the dimensionless pulse transfer
function.  With ``T**2 VE(z) / m = V(z) / z**2`` and
``(m / T**2) Z[ZOH G] = N(z) / D(z)`` that gives

    chi(z) = z**d * (z**2 D(z)) + V(z) N(z),

a *delayed part* ``z**2 D(z)`` (degree 4, shifted by ``z**d``) plus a *direct
part* ``V(z) N(z)`` (degree 3).  The delay never has to be fixed: the
coefficients of both parts are available in order, and ``coeffs(d)`` merges
them for a concrete delay.
"""

import dataclasses
import functools

import mpmath
import numpy as np
import sympy as sp

from .._validate import check_delay, check_real
from . import model
from .discretize import dimensionless_pulse_transfer_function
from .forms import NO_DOCSTRING

__all__ = ["LoopPolynomial", "characteristic_polynomial", "dimensionless_environment"]


def dimensionless_environment():
    """Return ``T**2 VE(z) / m`` written in alpha, beta and gamma."""
    scaled = model.virtual_environment() * model.T**2 / model.m
    return sp.expand(scaled.subs(model.dimensionless_substitution()))


@dataclasses.dataclass(frozen=True)
class LoopPolynomial:
    """chi(z) = z**d * delayed(z) + direct(z).

    Attributes
    ----------
    delayed : sympy.Poly
        Polynomial in ``z`` multiplied by ``z**d``.
    direct : sympy.Poly
        Polynomial in ``z`` not affected by the delay.
    """

    delayed: sp.Poly
    direct: sp.Poly

    def terms(self):
        """Return ``[(exponent, coefficient), ...]``, highest exponent first.

        Exponents of the delayed part are ``d + k`` with the symbol ``d``.
        Zero coefficients are left out.
        """
        out = []
        for part, shift in ((self.delayed, model.d), (self.direct, 0)):
            degree = part.degree()
            for k, c in enumerate(part.all_coeffs()):
                if c != 0:
                    out.append((shift + degree - k, c))
        return out

    def as_expr(self):
        """Return chi(z) as an expression with ``z**(d + k)`` kept symbolic."""
        return sp.Add(*[c * model.z**e for e, c in self.terms()])

    def coeffs(self, d):
        """Return the coefficients for a concrete delay ``d``, highest first.

        Parameters
        ----------
        d : int
            Delay in samples, ``d >= 0``.

        Returns
        -------
        list of sympy.Expr
            ``d + 5`` coefficients of a polynomial of degree ``d + 4``.
        """
        d = check_delay(d)
        n = d + self.delayed.degree()
        out = [sp.S.Zero] * (n + 1)
        for part, shift in ((self.delayed, d), (self.direct, 0)):
            degree = part.degree()
            for k, c in enumerate(part.all_coeffs()):
                out[n - (shift + degree - k)] += c
        return out

    @functools.cached_property
    def _numeric(self):
        args = (model.alpha, model.beta, model.gamma, model.delta)
        sub = {model.Gamma: sp.exp(model.delta)}
        return tuple(sp.lambdify(args, [c.subs(sub) for c in part.all_coeffs()], modules="mpmath",
                                 **NO_DOCSTRING) for part in (self.delayed, self.direct))

    def numeric_coeffs(self, *, alpha, beta, gamma, d, delta):
        """Return the coefficients (floats, highest first) at a parameter point.

        The coefficients are evaluated at 30 digits with ``Gamma = exp(delta)``
        and rounded once: expanded forms such as ``Gamma delta - Gamma + 1``
        (about ``delta**2 / 2``) would lose ``log10(1 / delta**2)`` digits in
        floating point.

        Raises
        ------
        ValueError
            If a parameter is not finite, ``delta <= 0`` or ``d`` is not a
            non-negative integer.
        """
        values = [mpmath.mpf(x) for x in (
            check_real("alpha", alpha), check_real("beta", beta), check_real("gamma", gamma),
            check_real("delta", delta, low=0.0, low_open=True))]
        d = check_delay(d)
        delayed_f, direct_f = self._numeric
        with mpmath.workdps(30):
            delayed = [float(x) for x in delayed_f(*values)]
            direct = [float(x) for x in direct_f(*values)]
        out = np.zeros(d + len(delayed))
        out[: len(delayed)] += delayed
        out[len(out) - len(direct):] += direct
        return out


@functools.lru_cache(maxsize=None)
def characteristic_polynomial():
    """Derive the loop's characteristic polynomial in dimensionless form.

    Returns
    -------
    LoopPolynomial
        ``chi(z) = z**d * delayed(z) + direct(z)``, affine in alpha, beta
        and gamma, whose roots are the closed-loop poles.
    """
    z = model.z
    num, den = sp.fraction(dimensionless_pulse_transfer_function())
    environment = sp.cancel(z**2 * dimensionless_environment())
    if not environment.is_polynomial(z):
        raise AssertionError(f"z**2 VE(z) is not a polynomial: {environment}")
    delayed = sp.Poly(sp.expand(z**2 * den), z)
    direct = sp.Poly(sp.expand(environment * num), z)
    return LoopPolynomial(delayed=delayed, direct=direct)
