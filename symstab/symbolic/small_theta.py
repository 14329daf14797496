"""Where every boundary arc starts: the small-theta Taylor limits.

The numerators and the denominator of alpha(theta), beta(theta) are expanded
in powers of theta with the delay ``d`` symbolic.  Near theta = 0::

    alpha(theta) = a2 theta**2 + O(theta**4)
    beta(theta)  = -delta + b2 theta**2 + O(theta**4)

so every arc starts at (beta, alpha) = (-delta, 0), and it enters
``alpha > 0`` exactly when ``a2 > 0``.
"""

import dataclasses
import functools

import sympy as sp

from . import model
from .boundary import boundary

__all__ = ["SmallThetaLimits", "small_theta_limits", "taylor_coefficients"]


@dataclasses.dataclass(frozen=True)
class SmallThetaLimits:
    """The Taylor limits of the boundary at theta -> 0.

    Attributes
    ----------
    alpha_limit, beta_limit : sympy.Expr
        Limits of alpha and beta as theta -> 0+.
    alpha_theta2, beta_theta2 : sympy.Expr
        Coefficients of theta**2 in alpha(theta) and beta(theta).
    start_slope : sympy.Expr
        d alpha / d beta at the starting point (``alpha_theta2 / beta_theta2``).
    alpha_sign_condition : sympy.Expr
        A relational that holds exactly when alpha > 0 for small theta > 0
        (``alpha_theta2 > 0`` with the positive factors removed).
    """

    alpha_limit: sp.Expr
    beta_limit: sp.Expr
    alpha_theta2: sp.Expr
    beta_theta2: sp.Expr
    start_slope: sp.Expr
    alpha_sign_condition: sp.Basic


def _trig_taylor(expr, order):
    """``expr`` with each sin(c theta), cos(c theta) replaced by its Taylor polynomial.

    ``c`` may depend on any symbol but theta (here it is ``d + k``).  The
    result agrees with ``expr`` to ``O(theta**(order + 1))``; when it is a
    polynomial in theta its coefficients are read off directly.  The
    boundary forms are sums of such terms: their limits take 0.15 s this
    way, where ``sympy.series`` of the whole expressions took 2.7 s (the
    same coefficients, the same factored forms).  Returns None when
    ``expr`` holds any other function of theta.
    """
    theta = model.theta
    replace = {}
    for func in expr.atoms(sp.sin, sp.cos):
        if not func.has(theta):
            continue
        c = sp.expand(func.args[0] / theta)
        if c.has(theta):
            return None
        first = 1 if isinstance(func, sp.sin) else 0
        replace[func] = sp.Add(*[(-1) ** (k // 2) * (c * theta) ** k / sp.factorial(k)
                                 for k in range(first, order + 1, 2)])
    taylor = expr.xreplace(replace)
    if any(f.has(theta) for f in taylor.atoms(sp.Function)):
        return None
    return taylor


def taylor_coefficients(expr, order):
    """The Taylor coefficients of ``expr`` in theta at 0, factored.

    Parameters
    ----------
    expr : sympy.Expr
        A function of :data:`symstab.symbolic.model.theta` analytic at 0.
    order : int
        The highest power kept.

    Returns
    -------
    list of sympy.Expr
        ``order + 1`` coefficients, of theta**0 to theta**order, each
        through :func:`sympy.factor`.
    """
    taylor = _trig_taylor(expr, order)
    if taylor is not None:
        try:
            poly = sp.Poly(taylor, model.theta)
        except sp.PolynomialError:     # theta also in a denominator or a root
            poly = None
        if poly is not None:
            return [sp.factor(poly.coeff_monomial(model.theta**k)) for k in range(order + 1)]
    series = sp.expand(sp.series(expr, model.theta, 0, order + 1).removeO())
    return [sp.factor(series.coeff(model.theta, k)) for k in range(order + 1)]


def _quotient_series(num, den, order):
    """Coefficients of num/den in theta, given both as coefficient lists.

    Power-series division: with ``den`` starting at theta**lead, the
    quotient's coefficient k is ``(num[k + lead] - sum_j q[j] den[k - j +
    lead]) / den[lead]``, up to ``order - lead``.
    """
    lead = next(k for k, c in enumerate(den) if c != 0)
    if any(c != 0 for c in num[:lead]):
        raise AssertionError("num/den has a pole at theta = 0")
    quotient = []
    for k in range(order + 1 - lead):
        rest = num[k + lead] - sp.Add(*[quotient[j] * den[k - j + lead] for j in range(k)])
        quotient.append(sp.factor(rest / den[lead]))
    return quotient


@functools.lru_cache(maxsize=None)
def small_theta_limits():
    """Derive the limits and leading terms of the boundary at theta = 0.

    Returns
    -------
    SmallThetaLimits
    """
    bd = boundary()
    order = 5
    den = taylor_coefficients(bd.denominator, order)
    alpha = _quotient_series(taylor_coefficients(bd.alpha_numerator, order), den, 3)
    beta = _quotient_series(taylor_coefficients(bd.beta_numerator, order), den, 3)
    a2 = sp.factor(alpha[2])
    # Remove factors that are positive on the model's domain (delta > 0,
    # Gamma = exp(delta) > 1 so Gamma - 1 > 0 and squares).
    sign_factor = sp.S.One
    for factor, power in sp.factor_list(a2)[1]:
        if not (factor.is_positive or factor == model.Gamma - 1 or power % 2 == 0):
            sign_factor *= factor**power
    coeff, _ = sp.factor_list(a2)
    condition = sp.Gt(sp.sign(coeff) * sign_factor, 0)
    return SmallThetaLimits(
        alpha_limit=alpha[0],
        beta_limit=beta[0],
        alpha_theta2=a2,
        beta_theta2=sp.factor(beta[2]),
        start_slope=sp.factor(a2 / beta[2]),
        alpha_sign_condition=condition,
    )
