"""Forms of the boundary and the loop polynomial that keep their digits in floats.

The derivation writes everything in ``delta`` and ``Gamma = exp(delta)``.
That is exact for proofs but poor for floating point at both ends:

* small delta: the pulse-transfer numerator ``(Gamma delta - Gamma + 1) z +
  (Gamma - delta - 1)`` is about ``delta**2 / 2 (z + 1)`` out of terms of
  size 1, and the C-coefficient form of alpha(theta) loses about
  ``log10(1 / delta**2)`` digits; at ``delta = 0`` it is 0 / 0;
* large delta: ``Gamma`` overflows for delta > 709 (and its square for
  delta > 354), though the loop is perfectly well defined there.

This module divides the loop polynomial by ``delta**2 Gamma``, so that only
``r = exp(-delta)`` in (0, 1] appears, and writes the pulse-transfer
numerator with four functions of delta that are bounded, smooth on
``[0, inf)`` and evaluated without cancellation or overflow (:class:`zoh_b1`,
:class:`zoh_b0`, :class:`zoh_gap`, :class:`decay_mean`; a Taylor series below
a switch, ``expm1(-delta)`` and ``exp(-delta)`` above it)::

    b1 = (delta - 1 + r) / delta**2          -> 1/2 at 0, ~ 1/delta for large delta
    b0 = (1 - r - delta r) / delta**2        -> 1/2 at 0, ~ 1/delta**2
    gap = (b1 - b0) / delta                  -> 1/6 at 0, ~ 1/delta**2
    mean = (1 - r) / delta                   -> 1 at 0,   ~ 1/delta

so that ``chi(z) / (delta**2 Gamma) = z**(d+2) (z - 1) (z - r) + V(z) (b1 z + b0)``,
finite and nonzero at ``delta = 0`` (the frictionless double integrator).

On the unit circle, with ``G = z - r`` (whose real part is ``em - 2
sin(theta/2)**2``, ``em = -expm1(-delta) = 1 - r``), ``H = b1 z + b0`` and
``M = G conj(H)``, Cramer's rule collapses to::

    alpha = 2 tan(theta/2) Im(exp(j (d+1) theta) M) / |H|**2 + 4 gamma sin(theta/2)**2
    beta  = -Re(exp(j (d+1/2) theta) M) / (cos(theta/2) |H|**2) - 4 gamma sin(theta/2)**2

with ``|H|**2 = delta**2 gap**2 + 4 b1 b0 cos(theta/2)**2``.  The sines and
cosines of ``(d+1) theta`` and ``(2d+1) theta/2`` are :class:`sin_multiple`
and :class:`cos_multiple`: the product of the integer and the angle is
carried exactly, so they keep their relative accuracy next to ``theta =
pi``, where ``(d+1) theta`` is large and its sine small (rounding the
product first cost up to 1e-9 of alpha there).  Every form is
proved equal to the derivation by the exact checker (:func:`proofs`), with
the symbols replaced by their definitions in ``Gamma`` and ``delta``; so are
the closed forms the four functions are evaluated by above their switch.
Only their Taylor branches are numerical approximations, measured against
mpmath in the tests.
"""

import functools

import sympy as sp
from sympy.codegen.cfunctions import expm1

from ..symbolic import model
from ..symbolic.boundary import boundary
from ..symbolic.loop import characteristic_polynomial, dimensionless_environment
from ..symbolic.sampled_plant import dimensionless_step

__all__ = [
    "SeriesFunction", "zoh_b1", "zoh_b0", "zoh_gap", "decay_mean", "SERIES_FUNCTIONS",
    "MultipleAngle", "sin_multiple", "cos_multiple", "MULTIPLE_ANGLE_FUNCTIONS",
    "r", "em", "b1", "b0", "gap", "mean",
    "boundary_forms", "loop_coefficient_forms",
    "plant_step_forms", "environment_force_form", "position_history",
    "position", "velocity", "force",
    "as_derivation", "as_evaluable", "proofs",
]


class SeriesFunction(sp.Function):
    """A bounded function of ``delta >= 0`` evaluated by a series or a closed form.

    Subclasses give :meth:`definition` (in ``exp(-x)``, exact, used by the
    proofs), :meth:`closed_form` (in ``expm1(-x)`` and ``exp(-x)``, used above
    :attr:`switch`, proved equal to the definition), the Taylor coefficient
    :meth:`coefficient` and the number of :attr:`terms` kept below the
    switch (the first neglected term is below ``2**-53`` of the value on
    ``[0, switch)``).  The code printers of :mod:`symstab.codegen.generator` print a
    call of the generated helper of the same name.
    """

    nargs = 1
    #: The function, as text in ``delta`` (for generated docstrings).
    formula = ""
    switch = sp.Integer(1)
    terms = 18

    @staticmethod
    def definition(x):
        raise NotImplementedError

    @staticmethod
    def closed_form(x):
        raise NotImplementedError

    @staticmethod
    def coefficient(k):
        raise NotImplementedError

    @classmethod
    def series(cls, x):
        """Horner form of the Taylor polynomial with :attr:`terms` terms."""
        out = cls.coefficient(cls.terms - 1)
        for k in range(cls.terms - 2, -1, -1):
            out = cls.coefficient(k) + x * out
        return out

    @classmethod
    def evaluation(cls, x):
        """The evaluation rule for ``x >= 0``, as a Piecewise.

        The series below :attr:`switch`, the closed form above it; the closed
        form's argument is clipped at the switch so that a vectorised
        evaluation of both branches never divides by zero.
        """
        return sp.Piecewise((cls.series(x), x < cls.switch),
                            (cls.closed_form(sp.Max(x, cls.switch)), True))

    def _eval_rewrite_as_exp(self, x, **kwargs):
        return self.definition(x)


def _em(x):
    """``1 - exp(-x)`` without cancellation."""
    return -expm1(-x)


class zoh_b1(SeriesFunction):
    """The ZOH numerator's coefficient of z over ``delta**2 Gamma``."""

    formula = "(delta - 1 + exp(-delta)) / delta^2"
    terms = 17

    @staticmethod
    def definition(x):
        return (x - 1 + sp.exp(-x)) / x**2

    @staticmethod
    def closed_form(x):
        return (x - _em(x)) / x**2

    @staticmethod
    def coefficient(k):
        return sp.Integer(-1) ** k / sp.factorial(k + 2)


class zoh_b0(SeriesFunction):
    """The ZOH numerator's constant term over ``delta**2 Gamma``."""

    formula = "(1 - exp(-delta) - delta exp(-delta)) / delta^2"
    terms = 18

    @staticmethod
    def definition(x):
        return (1 - sp.exp(-x) - x * sp.exp(-x)) / x**2

    @staticmethod
    def closed_form(x):
        return (_em(x) - x * sp.exp(-x)) / x**2

    @staticmethod
    def coefficient(k):
        return sp.Integer(-1) ** k * (k + 1) / sp.factorial(k + 2)


class zoh_gap(SeriesFunction):
    """``(zoh_b1 - zoh_b0) / delta``, the difference of the ZOH numerator's coefficients."""

    formula = "(delta (1 + exp(-delta)) - 2 (1 - exp(-delta))) / delta^3"
    switch = sp.Integer(2)
    terms = 22

    @staticmethod
    def definition(x):
        return (x * (1 + sp.exp(-x)) - 2 * (1 - sp.exp(-x))) / x**3

    @staticmethod
    def closed_form(x):
        return (x * (1 + sp.exp(-x)) - 2 * _em(x)) / x**3

    @staticmethod
    def coefficient(k):
        return sp.Integer(-1) ** k * (k + 1) / sp.factorial(k + 3)


class decay_mean(SeriesFunction):
    """The mean of ``exp(-delta s)`` over ``s`` in [0, 1]."""

    formula = "(1 - exp(-delta)) / delta"
    terms = 18

    @staticmethod
    def definition(x):
        return (1 - sp.exp(-x)) / x

    @staticmethod
    def closed_form(x):
        return _em(x) / x

    @staticmethod
    def coefficient(k):
        return sp.Integer(-1) ** k / sp.factorial(k + 1)


#: The series-evaluated functions, in the order they are generated.
SERIES_FUNCTIONS = (zoh_b1, zoh_b0, zoh_gap, decay_mean)

class MultipleAngle(sp.Function):
    """``f(k x)`` for an integer ``k``, with the product ``k x`` carried exactly.

    ``k x`` is the sum ``hi + lo`` of two doubles (an error-free product),
    and ``f(hi + lo) = f(hi) + lo f'(hi)`` to within ``lo**2``: the value
    keeps its relative accuracy where ``k x`` is large and ``f(k x)`` small,
    as ``sin((d + 1) theta)`` next to ``theta = pi``.  Subclasses give the
    :attr:`function` (``sp.sin`` or ``sp.cos``); :meth:`definition` is
    ``function(k x)``, which the proofs substitute (:func:`as_derivation`).
    The code printers of :mod:`symstab.codegen.generator` print a call of
    the generated helper of the same name.
    """

    nargs = 2
    function = None

    def definition(self):
        k, x = self.args
        return self.function(k * x)

    def _latex(self, printer):
        return printer._print(self.definition())


class sin_multiple(MultipleAngle):
    """``sin(k x)`` for an integer ``k``, with ``k x`` carried exactly."""

    function = sp.sin


class cos_multiple(MultipleAngle):
    """``cos(k x)`` for an integer ``k``, with ``k x`` carried exactly."""

    function = sp.cos


#: The multiple-angle functions, in the order they are generated.
MULTIPLE_ANGLE_FUNCTIONS = (sin_multiple, cos_multiple)

#: Symbols of the forms: ``r = exp(-delta)``, ``em = 1 - r`` and the four
#: functions above at ``delta``.
r, em = sp.symbols("r em", positive=True)
b1, b0, gap, mean = sp.symbols("b1 b0 gap mean", positive=True)
_FUNCTION_OF = {b1: zoh_b1, b0: zoh_b0, gap: zoh_gap, mean: decay_mean}


def _circle_parts():
    """Re/Im of M = G conj(H) and |H|**2, with z = exp(j theta)."""
    th = model.theta
    c, s = sp.cos(th), sp.sin(th)
    re_G, im_G = em - 2 * sp.sin(th / 2) ** 2, s
    re_H, im_H = b1 * c + b0, b1 * s
    re_M = re_G * re_H + im_G * im_H
    im_M = im_G * re_H - re_G * im_H
    H2 = model.delta**2 * gap**2 + 4 * b1 * b0 * sp.cos(th / 2) ** 2
    return re_M, im_M, H2


@functools.lru_cache(maxsize=None)
def boundary_forms():
    """Return ``(alpha, beta)`` on the boundary in the well-conditioned form.

    Expressions in ``theta, gamma, d, delta``, the symbols :data:`em`,
    ``b1``, ``b0``, ``gap`` and the multiple-angle functions
    :class:`sin_multiple`, :class:`cos_multiple`.
    """
    th, d, g = model.theta, model.d, model.gamma
    re_M, im_M, H2 = _circle_parts()
    half = th / 2
    # exp(j (d+1) theta) and exp(j (2d+1) theta/2), with the products carried exactly.
    sin_a, cos_a = sin_multiple(d + 1, th), cos_multiple(d + 1, th)
    sin_b, cos_b = sin_multiple(2 * d + 1, half), cos_multiple(2 * d + 1, half)
    alpha = 2 * sp.tan(half) * (sin_a * re_M + cos_a * im_M) / H2 + 4 * g * sp.sin(half) ** 2
    beta = -(cos_b * re_M - sin_b * im_M) / (sp.cos(half) * H2) - 4 * g * sp.sin(half) ** 2
    return alpha, beta


@functools.lru_cache(maxsize=None)
def loop_coefficient_forms():
    """Return the coefficients of ``chi(z) / (delta**2 Gamma)``, highest power first.

    ``(delayed, direct)``: the delayed part ``z**(d+2) (z - 1) (z - r)``'s
    coefficients of ``z**(d+4)``, ``z**(d+3)``, ``z**(d+2)`` and the direct
    part ``V(z) (b1 z + b0)``'s of ``z**3 .. z**0``.  Each direct coefficient
    is written so that no difference of two large terms is left to the
    floats (``b0 - b1 = -delta gap``).
    """
    al, be, ga, dl = model.alpha, model.beta, model.gamma, model.delta
    delayed = (sp.Integer(1), -(1 + r), r)
    direct = ((al + be + ga) * b1,
              al * b0 - be * dl * gap - ga * (b1 + dl * gap),
              -be * b0 + ga * (b1 - 2 * b0),
              ga * b0)
    return delayed, direct


@functools.lru_cache(maxsize=None)
def plant_step_forms():
    """The exact one-sample plant step in the float-safe form.

    Returns ``(Phi, Gamma_u)`` (2x2 and 2x1 matrices) for the state
    ``(x, v T)`` and the force ``f T**2 / m``: ``Phi = [[1, mean], [0, r]]``,
    ``Gamma_u = [b1, mean]`` (see :mod:`symstab.symbolic.sampled_plant`); at
    ``delta = 0`` the frictionless double integrator.
    """
    return sp.Matrix([[1, mean], [0, r]]), sp.Matrix([b1, mean])


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


def _definitions():
    dl, G = model.delta, model.Gamma
    out = {r: 1 / G, em: 1 - 1 / G}
    for symbol, function in _FUNCTION_OF.items():
        out[symbol] = function.definition(dl).subs(sp.exp(-dl), 1 / G)
    return out


def as_derivation(expr):
    """Replace the symbols of the forms by their definitions in ``Gamma, delta``.

    The multiple-angle functions become the sines and cosines they evaluate.
    """
    expr = expr.replace(lambda e: isinstance(e, MultipleAngle), lambda e: e.definition())
    return expr.subs(_definitions())


def as_evaluable(expr):
    """Replace the symbols of the forms by ``exp(-delta)``, ``expm1`` and the series functions."""
    dl = model.delta
    out = {r: sp.exp(-dl), em: _em(dl)}
    out.update({symbol: function(dl) for symbol, function in _FUNCTION_OF.items()})
    return expr.subs(out)


def proofs():
    """The identities that make these forms the derivation's objects.

    Returns
    -------
    list of (name, statement, lhs, rhs)
        Each ``lhs`` is a form of this module with :func:`as_derivation`
        applied; ``rhs`` the derivation's object.  The closed forms by which
        the series functions are evaluated above their switch are proved
        equal to their definitions too.
    """
    bd = boundary()
    alpha, beta = boundary_forms()
    chi = characteristic_polynomial()
    delayed, direct = loop_coefficient_forms()
    dl, G = model.delta, model.Gamma
    scale = dl**2 * G
    out = [
        ("alpha_kernel_form", "alpha of the float-safe form = N_alpha / D", as_derivation(alpha), bd.alpha),
        ("beta_kernel_form", "beta of the float-safe form = N_beta / D", as_derivation(beta), bd.beta),
    ]
    for function in SERIES_FUNCTIONS:
        name = function.__name__
        closed = function.closed_form(dl).replace(
            lambda e: isinstance(e, expm1), lambda e: sp.exp(e.args[0]) - 1)
        out.append((f"{name}_closed_form", f"{name}: the closed form evaluated above "
                    f"delta = {function.switch} = its definition",
                    closed.subs(sp.exp(-dl), 1 / G), function.definition(dl).subs(sp.exp(-dl), 1 / G)))
    for k, (form, derived) in enumerate(zip(delayed, chi.delayed.all_coeffs()[:3], strict=True)):
        out.append((f"delayed_coefficient_{k}", f"coefficient {k} of the delayed part / (delta^2 Gamma)",
                    as_derivation(form), derived / scale))
    for k, (form, derived) in enumerate(zip(direct, chi.direct.all_coeffs(), strict=True)):
        out.append((f"direct_coefficient_{k}", f"coefficient {k} of the direct part / (delta^2 Gamma)",
                    as_derivation(form), derived / scale))
    step = dimensionless_step()
    Phi, Gamma_u = plant_step_forms()
    for (i, j) in ((0, 0), (0, 1), (1, 0), (1, 1)):
        out.append((f"plant_step_Phi_{i}{j}", f"Phi[{i},{j}] = exp(A T)[{i},{j}] (scaled)",
                    as_derivation(Phi[i, j]), step.Phi[i, j]))
    for i in range(2):
        out.append((f"plant_step_Gamma_{i}", f"Gamma_u[{i}] = (int exp(A s) ds B)[{i}] (scaled)",
                    as_derivation(Gamma_u[i]), step.Gamma_u[i]))
    return out
