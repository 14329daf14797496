"""The stability boundary alpha(theta), beta(theta) and its C-coefficients.

On the unit circle the real and imaginary parts of chi(exp(j theta)) are two
equations, linear in alpha and beta (:mod:`symstab.symbolic.unit_circle`).  SymPy
solves them by Cramer's rule; the determinant is the common denominator.

Each numerator and the denominator is then written as a polynomial in gamma
and delta with ``Gamma`` kept as its own symbol, and every coefficient is put
in a canonical trigonometric form (a sum of sines and cosines of
``p theta / 2 + q d theta``) through :func:`symstab.proof.identity.trig_form`.  The
Cramer determinant already reads ``C6 + delta**2 C7 + delta C8`` with
``C7 = K3 sin(theta)``; no rescaling is applied.

The coefficients are named as in the paper's eqs. (7), (11) and (20)-(34) by
the monomial they multiply, so that the audit can compare them term by term:

========  ==========================  ========  ==========================
name      coefficient of              name      coefficient of
========  ==========================  ========  ==========================
C1        gamma          in N_alpha   C6        1        in the denominator
C2        gamma delta^2  in N_alpha   C7        delta^2  in the denominator
C3        gamma delta    in N_alpha   C8        delta    in the denominator
C4        delta^3        in N_alpha   C9        gamma delta  in N_beta
C5        delta^2        in N_alpha   C10       delta^3  in N_beta
                                      C11       delta^2  in N_beta
========  ==========================  ========  ==========================

The remaining monomials of ``N_beta`` (gamma and gamma delta^2) are the
negatives of C1 and C2 (:func:`beta_relations`).
"""

import dataclasses
import functools

import sympy as sp

from . import model
from .discretize import dimensionless_pulse_transfer_function
from .forms import conjugate_on_circle, exponential_form, trig_form, w
from .unit_circle import unit_circle_split

__all__ = [
    "Boundary", "boundary", "coefficients", "beta_relations",
    "ALPHA_MONOMIALS", "BETA_MONOMIALS", "DENOMINATOR_MONOMIALS",
]

#: Name of the coefficient of gamma**i delta**j, per numerator.
ALPHA_MONOMIALS = {(1, 0): "C1", (1, 2): "C2", (1, 1): "C3", (0, 3): "C4", (0, 2): "C5"}
BETA_MONOMIALS = {(1, 1): "C9", (0, 3): "C10", (0, 2): "C11"}
DENOMINATOR_MONOMIALS = {(0, 0): "C6", (0, 2): "C7", (0, 1): "C8"}


def _gamma_delta_terms(expr):
    """Split ``expr`` into {(i, j): trig coefficient of gamma**i delta**j}."""
    laurent = sp.expand(exponential_form(expr))
    poly = sp.Poly(laurent, model.gamma, model.delta)
    return {monomial: sp.factor(trig_form(c)) for monomial, c in sorted(poly.terms())}


def _assemble(terms):
    return sp.Add(*[c * model.gamma**i * model.delta**j for (i, j), c in sorted(terms.items())])


@dataclasses.dataclass(frozen=True)
class Boundary:
    """alpha(theta) = N_alpha / D and beta(theta) = N_beta / D.

    Attributes
    ----------
    alpha_terms, beta_terms, denominator_terms : dict
        ``{(i, j): c}``: the coefficient ``c(theta, d, Gamma)`` of
        ``gamma**i delta**j``.
    """

    alpha_terms: dict
    beta_terms: dict
    denominator_terms: dict

    @property
    def alpha_numerator(self):
        return _assemble(self.alpha_terms)

    @property
    def beta_numerator(self):
        return _assemble(self.beta_terms)

    @property
    def denominator(self):
        return _assemble(self.denominator_terms)

    @property
    def alpha(self):
        """alpha(theta) on the boundary."""
        return self.alpha_numerator / self.denominator

    @property
    def beta(self):
        """beta(theta) on the boundary."""
        return self.beta_numerator / self.denominator


@functools.lru_cache(maxsize=None)
def boundary():
    """Solve Re chi = Im chi = 0 for alpha and beta (Cramer's rule).

    Returns
    -------
    Boundary
    """
    real, imag = unit_circle_split()
    A, rhs = sp.linear_eq_to_matrix([real, imag], [model.alpha, model.beta])
    det = A.det()
    with_alpha = A.copy()
    with_alpha[:, 0] = rhs
    with_beta = A.copy()
    with_beta[:, 1] = rhs
    return Boundary(
        alpha_terms=_gamma_delta_terms(with_alpha.det()),
        beta_terms=_gamma_delta_terms(with_beta.det()),
        denominator_terms=_gamma_delta_terms(det),
    )


def _trig_quotient(num, den):
    """Exact quotient of two trigonometric polynomials, in trigonometric form."""
    q = sp.cancel(sp.expand(exponential_form(num)) / sp.expand(exponential_form(den)))
    return sp.factor(trig_form(q))


def _pulse_numerator_modulus_squared():
    """|N(exp(j theta))|**2 for the numerator N(z) of the pulse transfer function."""
    num, _ = sp.fraction(dimensionless_pulse_transfer_function())
    n = sp.expand(num.subs(model.z, w**2))
    return sp.expand(n * conjugate_on_circle(n))


@functools.lru_cache(maxsize=None)
def coefficients():
    """Return the derived C1..C11 and K1..K4 as a dict of expressions.

    ``K2 = |N|**2 / |z - 1|**2`` at ``delta = 0`` and ``K3`` is the
    ``delta**2`` coefficient of ``|N|**2``, where ``N(z)`` is the numerator of
    the pulse transfer function; ``K1 = C1 / K2``; ``K4`` is the coefficient
    of ``sin(theta/2)`` once ``C10`` is divided by ``-2 cos((2d+1) theta/2)``
    (the factor its delay harmonics share).
    """
    bd = boundary()
    out = {}
    for terms, names in ((bd.alpha_terms, ALPHA_MONOMIALS),
                         (bd.beta_terms, BETA_MONOMIALS),
                         (bd.denominator_terms, DENOMINATOR_MONOMIALS)):
        for monomial, name in names.items():
            out[name] = terms.get(monomial, sp.S.Zero)
    n2 = sp.Poly(_pulse_numerator_modulus_squared(), model.delta)
    z_minus_1_sq = sp.expand((w**2 - 1) * (w**-2 - 1))
    out["K2"] = sp.factor(sp.cancel(n2.coeff_monomial(1) / z_minus_1_sq))
    out["K3"] = sp.factor(trig_form(n2.coeff_monomial(model.delta**2)))
    out["K1"] = _trig_quotient(out["C1"], out["K2"])
    shared = -2 * sp.cos(model.theta * (2 * model.d + 1) / 2)
    q = sp.expand(trig_form(sp.cancel(exponential_form(out["C10"]) / exponential_form(shared))))
    out["K4"] = sp.factor(q.coeff(sp.sin(model.theta / 2)))
    return dict(sorted(out.items(), key=lambda kv: (kv[0][0], int(kv[0][1:]))))


def beta_relations():
    """The monomials of N_beta that repeat alpha's coefficients.

    Returns
    -------
    dict
        ``{(i, j): (coefficient in N_beta, expected)}`` for gamma (expected
        ``-C1``) and gamma delta**2 (expected ``-C2``), plus every monomial of
        either numerator that the C-names do not cover (expected ``0``).
    """
    bd = boundary()
    c = coefficients()
    out = {(1, 0): (bd.beta_terms.get((1, 0), 0), -c["C1"]),
           (1, 2): (bd.beta_terms.get((1, 2), 0), -c["C2"])}
    for terms, names, tag in ((bd.alpha_terms, ALPHA_MONOMIALS, "alpha"),
                              (bd.beta_terms, BETA_MONOMIALS, "beta")):
        for monomial, value in terms.items():
            if monomial not in names and not (tag == "beta" and monomial in out):
                out[(tag,) + monomial] = (value, sp.S.Zero)
    return out
