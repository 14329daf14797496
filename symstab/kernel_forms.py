"""Forms of the boundary and the loop polynomial that keep their digits in floats.

The derivation writes everything in ``delta`` and ``Gamma = exp(delta)``.
That is exact for proofs but poor for floating point: the pulse-transfer
numerator ``(Gamma delta - Gamma + 1) z + (Gamma - delta - 1)`` is about
``delta**2 / 2 (z + 1)`` out of terms of size 1, and the C-coefficient form
of alpha(theta) loses about ``log10(1 / delta**2)`` digits.

This module rewrites the same objects in quantities that are all of size 1
or carry their smallness as an explicit factor:

``em1 = expm1(delta)``
    ``Gamma - 1``, evaluated without cancellation.
``phi3 = (exp(delta) - 1 - delta - delta**2 / 2) / delta**3``
    :class:`exprel3`, evaluated from its Taylor series for small delta;
    with it ``phi2 = 1/2 + delta phi3 = (Gamma - 1 - delta) / delta**2``.
``P = (Gamma delta - Gamma + 1) / delta**2 = 1 - (1 - delta) phi2``,
``Q = (Gamma - delta - 1) / delta**2 = phi2``
    the pulse-transfer numerator divided by ``delta**2``, so that
    ``chi(z) / delta**2 = z**(d+2) (z - 1) (Gamma z - 1) + V(z) (P z + Q)``;
    ``P - Q = delta (1/2 + (delta - 2) phi3)`` without cancellation.

On the unit circle, with ``G = Gamma z - 1`` (whose real part is
``em1 cos(theta) - 2 sin(theta/2)**2``), ``H = P z + Q`` and
``M = G conj(H)``, Cramer's rule collapses to::

    alpha = 2 tan(theta/2) Im(exp(j (d+1) theta) M) / |H|**2 + 4 gamma sin(theta/2)**2
    beta  = -Re(exp(j (d+1/2) theta) M) / (cos(theta/2) |H|**2) - 4 gamma sin(theta/2)**2

with ``|H|**2 = (P - Q)**2 + 4 P Q cos(theta/2)**2``.  Every form is proved
equal to the derivation by the exact checker (:func:`proofs`), with
``em1 = Gamma - 1`` and ``phi3`` replaced by its definition; only the
evaluation of :class:`exprel3` itself is a numerical approximation, measured
against mpmath in the tests.
"""

import functools

import sympy as sp
from sympy.codegen.cfunctions import expm1

from . import model
from .boundary import boundary
from .loop import characteristic_polynomial, dimensionless_environment
from .sampled_plant import dimensionless_step

__all__ = [
    "exprel3", "EXPREL3_SWITCH", "exprel3_series", "exprel3_piecewise",
    "em1", "phi3", "pulse_numerator_parts", "boundary_forms", "loop_coefficient_forms",
    "plant_step_forms", "environment_force_form", "position_history",
    "position", "velocity", "force",
    "as_derivation", "as_evaluable", "proofs",
]

#: Below this delta, :class:`exprel3` is evaluated from its Taylor series.
#: Above it the closed form cancels by at most (e - 1) / (e - 2.5), about 8,
#: in relative terms; at 1/2 it would be about 27.
EXPREL3_SWITCH = sp.Integer(1)
#: Terms of the series: the first neglected one, delta**17 / 20!, is below
#: 2**-53 relative to phi3 >= 1/6 for delta < 1.
_EXPREL3_TERMS = 17


class exprel3(sp.Function):
    """``(exp(x) - 1 - x - x**2 / 2) / x**3``, continuous at ``x = 0`` (= 1/6).

    Code printers print it as a call of the generated helper of that name.
    """

    nargs = 1

    def _eval_rewrite_as_exp(self, x, **kwargs):
        return (sp.exp(x) - 1 - x - x**2 / 2) / x**3


def exprel3_series(x):
    """Horner form of the first terms of exprel3's Taylor series, sum x**k / (k+3)!."""
    out = 1 / sp.factorial(_EXPREL3_TERMS + 2)
    for k in range(_EXPREL3_TERMS - 2, -1, -1):
        out = 1 / sp.factorial(k + 3) + x * out
    return out


def exprel3_piecewise(x):
    """The evaluation rule of :class:`exprel3` for ``x > 0``, as a Piecewise.

    The series below :data:`EXPREL3_SWITCH`, the closed form with ``expm1``
    above it; the closed form's argument is clipped at the switch so that a
    vectorised evaluation of both branches never divides by zero.
    """
    xs = sp.Max(x, EXPREL3_SWITCH)
    return sp.Piecewise((exprel3_series(x), x < EXPREL3_SWITCH),
                        ((expm1(xs) - xs - xs**2 / 2) / xs**3, True))


#: Symbols standing for ``expm1(delta)`` and ``exprel3(delta)`` in the forms.
em1 = sp.Symbol("em1", positive=True)
phi3 = sp.Symbol("phi3", positive=True)


def pulse_numerator_parts():
    """Return ``(P, Q, P - Q)`` in ``delta`` and ``phi3``."""
    dl = model.delta
    phi2 = sp.Rational(1, 2) + dl * phi3
    return 1 - (1 - dl) * phi2, phi2, dl * (sp.Rational(1, 2) + (dl - 2) * phi3)


def _circle_parts():
    """Re/Im of M = G conj(H) and |H|**2, with z = exp(j theta)."""
    th = model.theta
    P, Q, P_minus_Q = pulse_numerator_parts()
    c, s = sp.cos(th), sp.sin(th)
    re_G, im_G = em1 * c - 2 * sp.sin(th / 2) ** 2, (1 + em1) * s
    re_H, im_H = P * c + Q, P * s
    re_M = re_G * re_H + im_G * im_H
    im_M = im_G * re_H - re_G * im_H
    H2 = P_minus_Q**2 + 4 * P * Q * sp.cos(th / 2) ** 2
    return re_M, im_M, H2


@functools.lru_cache(maxsize=None)
def boundary_forms():
    """Return ``(alpha, beta)`` on the boundary in the well-conditioned form.

    Expressions in ``theta, gamma, d, delta`` and the symbols :data:`em1`,
    :data:`phi3`.
    """
    th, d, g = model.theta, model.d, model.gamma
    re_M, im_M, H2 = _circle_parts()
    half = th / 2
    a = (d + 1) * th
    b = (2 * d + 1) * th / 2
    alpha = 2 * sp.tan(half) * (sp.sin(a) * re_M + sp.cos(a) * im_M) / H2 + 4 * g * sp.sin(half) ** 2
    beta = -(sp.cos(b) * re_M - sp.sin(b) * im_M) / (sp.cos(half) * H2) - 4 * g * sp.sin(half) ** 2
    return alpha, beta


@functools.lru_cache(maxsize=None)
def loop_coefficient_forms():
    """Return the coefficients of ``chi(z) / delta**2``, highest power first.

    ``(delayed, direct)``: the delayed part's coefficients of ``z**(d+4)``,
    ``z**(d+3)``, ``z**(d+2)`` and the direct part's of ``z**3 .. z**0``,
    in ``alpha, beta, gamma, delta`` and :data:`em1`, :data:`phi3`.
    """
    z = model.z
    P, Q, _ = pulse_numerator_parts()
    Gamma = 1 + em1
    V = model.alpha * z**2 + model.beta * z * (z - 1) + model.gamma * (z - 1) ** 2
    delayed = sp.Poly(z**2 * (z - 1) * (Gamma * z - 1), z).all_coeffs()[:3]
    direct = sp.Poly(sp.expand(V * (P * z + Q)), z).all_coeffs()
    return tuple(sp.collect(c, [model.alpha, model.beta, model.gamma]) for c in delayed), \
        tuple(sp.collect(c, [model.alpha, model.beta, model.gamma]) for c in direct)


@functools.lru_cache(maxsize=None)
def plant_step_forms():
    """The exact one-sample plant step in the float-safe form.

    Returns ``(Phi, Gamma_u)`` (2x2 and 2x1 matrices) for the state
    ``(x, v T)`` and the force ``f T**2 / m``: ``Phi = [[1, em1 / (delta
    Gamma)], [0, 1 / Gamma]]``, ``Gamma_u = [P / Gamma, em1 / (delta Gamma)]``
    with ``Gamma = 1 + em1`` (see :mod:`symstab.sampled_plant`).
    """
    P, _, _ = pulse_numerator_parts()
    G = 1 + em1
    ratio = em1 / (model.delta * G)
    return sp.Matrix([[1, ratio], [0, 1 / G]]), sp.Matrix([P / G, ratio])


#: Sampled positions x(k), x(k-1), x(k-2) as the environment sees them.
position_history = sp.symbols("x_k x_km1 x_km2", real=True)
#: The plant state (x, v T) and the held force f T**2 / m.
position, velocity, force = sp.symbols("position velocity force", real=True)


@functools.lru_cache(maxsize=None)
def environment_force_form():
    """The force ``f T**2 / m`` of eq. (1) on the sampled positions.

    ``-T**2 VE(z) / m`` applied to the position sequence, read off the
    derivation's environment as a polynomial in ``1 / z``.
    """
    q = sp.Symbol("q")
    ve = sp.expand(dimensionless_environment().subs(model.z, 1 / q))
    poly = sp.Poly(ve, q)
    if poly.degree() > 2:
        raise AssertionError(f"VE(z) reaches further back than two samples: {ve}")
    return -sp.Add(*[sp.collect(poly.coeff_monomial(q**k), [model.alpha, model.beta, model.gamma])
                     * position_history[k] for k in range(3)])


def as_derivation(expr):
    """Replace :data:`em1` and :data:`phi3` by their definitions in ``Gamma, delta``."""
    dl, G = model.delta, model.Gamma
    return expr.subs({em1: G - 1, phi3: (G - 1 - dl - dl**2 / 2) / dl**3})


def as_evaluable(expr):
    """Replace :data:`em1` and :data:`phi3` by ``expm1(delta)`` and ``exprel3(delta)``."""
    return expr.subs({em1: expm1(model.delta), phi3: exprel3(model.delta)})


def proofs():
    """The identities that make these forms the derivation's objects.

    Returns
    -------
    list of (name, statement, lhs, rhs)
        Each ``lhs`` is a form of this module with :func:`as_derivation`
        applied; ``rhs`` the derivation's object.
    """
    bd = boundary()
    alpha, beta = boundary_forms()
    chi = characteristic_polynomial()
    delayed, direct = loop_coefficient_forms()
    dl2 = model.delta**2
    out = [
        ("alpha_kernel_form", "alpha of the float-safe form = N_alpha / D", as_derivation(alpha), bd.alpha),
        ("beta_kernel_form", "beta of the float-safe form = N_beta / D", as_derivation(beta), bd.beta),
    ]
    for k, (form, derived) in enumerate(zip(delayed, chi.delayed.all_coeffs()[:3])):
        out.append((f"delayed_coefficient_{k}", f"coefficient {k} of the delayed part / delta^2",
                    as_derivation(form), derived / dl2))
    for k, (form, derived) in enumerate(zip(direct, chi.direct.all_coeffs())):
        out.append((f"direct_coefficient_{k}", f"coefficient {k} of the direct part / delta^2",
                    as_derivation(form), derived / dl2))
    step = dimensionless_step()
    Phi, Gamma_u = plant_step_forms()
    for (i, j) in ((0, 0), (0, 1), (1, 0), (1, 1)):
        out.append((f"plant_step_Phi_{i}{j}", f"Phi[{i},{j}] = exp(A T)[{i},{j}] (scaled)",
                    as_derivation(Phi[i, j]), step.Phi[i, j]))
    for i in range(2):
        out.append((f"plant_step_Gamma_{i}", f"Gamma_u[{i}] = (int exp(A s) ds B)[{i}] (scaled)",
                    as_derivation(Gamma_u[i]), step.Gamma_u[i]))
    return out
