"""Exponential and trigonometric forms of expressions in theta with a symbolic delay d.

:func:`exponential_form` writes every trigonometric function of ``theta``
and ``d theta`` in two new variables::

    w = exp(j theta / 2)        E = exp(j d theta)

so that ``cos(p theta / 2 + q d theta) = (w**p E**q + w**-p E**-q) / 2`` and
``exp(delta) = Gamma``: the expression becomes a rational function of ``w``,
``E``, ``Gamma`` and the other symbols.  :func:`trig_form` is the inverse
map, from a real Laurent polynomial in ``w`` and ``E`` back to cosines and
sines.  The derivation uses these forms to write the boundary and theta_max;
the exact identity checker (:mod:`symstab.proof.identity`) proves with them.
"""

import inspect

import sympy as sp

from . import model

__all__ = ["w", "E", "UnsupportedExpression", "exponential_form", "trig_form", "conjugate_on_circle"]


#: exp(j theta / 2)
w = sp.Symbol("w")
#: exp(j d theta)
E = sp.Symbol("E")

_TRIG = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)

#: Keyword arguments for ``sympy.lambdify`` that leave the whole expression out
#: of the generated function's docstring: printing it is a quarter to three
#: quarters of lambdify's time on the long closed forms (SymPy >= 1.13).
NO_DOCSTRING = ({"docstring_limit": 0}
                if "docstring_limit" in inspect.signature(sp.lambdify).parameters else {})


class _exp_atom(sp.Function):
    """exp(x) as an opaque generator that SymPy does not simplify."""


class UnsupportedExpression(ValueError):
    """The expression is outside the class the exact checker can decide."""


def _phase_monomial(arg, theta, d):
    """Return exp(j arg) as ``const * w**p * E**q`` for arg linear in theta."""
    arg = sp.expand(arg)
    rate = sp.expand(sp.diff(arg, theta))
    offset = sp.expand(arg - rate * theta)
    if offset.has(theta) or rate.has(theta):
        raise UnsupportedExpression(f"argument {arg} is not linear in {theta}")
    rate_poly = sp.Poly(rate, d) if rate.has(d) else sp.Poly(rate, d, domain="QQ")
    if rate_poly.degree() > 1 or not rate_poly.free_symbols <= {d}:
        raise UnsupportedExpression(f"argument {arg}: frequency {rate} is not p/2 + q d")
    q = rate_poly.coeff_monomial(d)
    p = 2 * rate_poly.coeff_monomial(1)
    if not (sp.Integer(p) == p and p.is_integer and sp.sympify(q).is_integer):
        raise UnsupportedExpression(f"argument {arg}: frequency {rate} is not p/2 + q d")
    if offset.has(d):
        raise UnsupportedExpression(f"argument {arg}: d appears outside the frequency")
    return sp.exp(sp.I * offset) * w ** int(p) * E ** int(q)


def exponential_form(expr, *, theta=model.theta, d=model.d, delta=model.delta,
                     Gamma=model.Gamma):
    """Rewrite ``expr`` as a rational expression in ``w``, ``E`` and ``Gamma``.

    Trigonometric functions of ``p theta / 2 + q d theta + c`` (integers
    ``p, q``, constant ``c``) and ``exp(j (...))`` become monomials in ``w``
    and ``E``; ``exp(k delta)`` becomes ``Gamma**k``.

    Raises
    ------
    UnsupportedExpression
        If ``theta`` occurs anywhere else (bare, squared inside a sine, under
        a square root, ...).
    """
    expr = sp.sympify(expr)
    # The forms repeat their subexpressions (sin(d theta) dozens of times):
    # each distinct one is rewritten once.
    done = {}

    def rec(e):
        if e not in done:
            done[e] = rewrite(e)
        return done[e]

    def rewrite(e):
        if not e.has(theta) and not e.has(sp.exp):
            return e
        if e == theta:
            raise UnsupportedExpression(f"{theta} occurs outside a trigonometric function")
        if isinstance(e, _TRIG):
            x = _phase_monomial(e.args[0], theta, d)
            xi = 1 / x
            c, s_ = (x + xi) / 2, (x - xi) / (2 * sp.I)
            return {sp.sin: s_, sp.cos: c, sp.tan: s_ / c, sp.cot: c / s_,
                    sp.sec: 1 / c, sp.csc: 1 / s_}[type(e)]
        if isinstance(e, sp.exp):
            arg = sp.expand(e.args[0])
            if arg.has(theta):
                return _phase_monomial(sp.expand(arg / sp.I), theta, d)
            k = sp.expand(arg / delta)
            if k.is_Rational:
                return Gamma**k
            # exp(c x) -> X**c with one generator X per x, so that exp(x) and
            # exp(-x) are seen as reciprocals (SymPy would fold X**-1 back).
            coeff, rest = arg.as_coeff_Mul()
            if coeff.is_Rational:
                return _exp_atom(rest) ** coeff
            return sp.exp(rec(arg))
        if e.is_Atom:
            return e
        if e.is_Function and e.has(theta):
            raise UnsupportedExpression(f"{e.func} of {theta} is not supported")
        return e.func(*[rec(a) for a in e.args])

    return rec(expr)


def conjugate_on_circle(expr):
    """Complex conjugate of a rational expression in ``w, E`` with real symbols.

    On the unit circle ``conj(w) = 1/w`` and ``conj(E) = 1/E``; every other
    symbol of the model is real.
    """
    return sp.sympify(expr).subs({w: 1 / w, E: 1 / E, sp.I: -sp.I}, simultaneous=True)


def _laurent_terms(expr):
    """Return {(p, q): coeff} for a Laurent polynomial in ``w`` and ``E``."""
    num, den = sp.fraction(sp.together(sp.expand(expr)))
    den_poly = sp.Poly(den, w, E)
    if len(den_poly.terms()) != 1:
        raise UnsupportedExpression("not a Laurent polynomial in w and E")
    (dp, dq), dc = den_poly.terms()[0]
    terms = {}
    for (p, q), c in sp.Poly(sp.expand(num), w, E).terms():
        key = (p - dp, q - dq)
        terms[key] = terms.get(key, 0) + c / dc
    return terms


def trig_form(expr, *, theta=model.theta, d=model.d):
    """Write a real Laurent polynomial in ``w, E`` as cosines and sines.

    Each pair ``c w**p E**q + c' w**-p E**-q`` becomes
    ``(c + c') cos(phi) + j (c - c') sin(phi)`` with
    ``phi = p theta / 2 + q d theta``, oriented so that ``p > 0`` (or
    ``p == 0, q > 0``).

    Raises
    ------
    UnsupportedExpression
        If ``expr`` is not a Laurent polynomial, or is not real on the circle.
    """
    terms = _laurent_terms(expr)
    out = sp.S.Zero
    seen = set()
    for key in sorted(terms):
        if key in seen:
            continue
        p, q = key
        mirror = (-p, -q)
        seen.update({key, mirror})
        if (p, q) == (0, 0):
            c0 = sp.expand(terms[key])
            if sp.im(c0) != 0:
                raise UnsupportedExpression("constant term is not real")
            out += c0
            continue
        if p < 0 or (p == 0 and q < 0):
            p, q, key, mirror = -p, -q, mirror, key
        c, cc = terms.get(key, 0), terms.get(mirror, 0)
        cos_c = sp.factor(sp.expand(c + cc))
        sin_c = sp.factor(sp.expand(sp.I * (c - cc)))
        if cos_c.has(sp.I) or sin_c.has(sp.I):
            raise UnsupportedExpression("expression is not real on the unit circle")
        phi = sp.Rational(p, 2) * theta + q * d * theta
        out += cos_c * sp.cos(phi) + sin_c * sp.sin(phi)
    return out
