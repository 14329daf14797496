"""Exact equality of expressions in theta with a symbolic integer delay d.

The boundary expressions are trigonometric polynomials in theta whose
frequencies involve the symbolic delay ``d`` (``sin((d + 1) theta)``,
``cos(theta (2 d + 1) / 2)``, ...).  ``simplify()`` is slow on them and
silently incomplete.  Instead, :func:`exponential_form` writes every such
function in two new variables::

    w = exp(j theta / 2)        E = exp(j d theta)

so that ``cos(p theta / 2 + q d theta) = (w**p E**q + w**-p E**-q) / 2`` and
``exp(delta) = Gamma``.  The expression becomes a rational function of ``w``,
``E``, ``Gamma`` and the other symbols, and two expressions are identical when
their difference is the zero rational function.  This is a proof:

* a rational identity with ``w, E, Gamma`` independent stays true under any
  substitution, in particular ``E = w**(2 d)`` for every integer ``d`` and
  ``Gamma = exp(delta)``;
* conversely ``delta`` and ``exp(delta)`` are algebraically independent, and
  an identity in ``w`` and ``w**(2 d)`` for *every* integer ``d`` forces the
  coefficient of each power of ``E`` to vanish, so nothing is lost.

Every verdict is backed by a randomized evaluation at 40 significant digits
with mpmath (``Gamma = exp(delta)``, ``d`` a random integer): a proof that the
numbers contradict raises, and a difference that is not a rational identity
is reported with the point that shows it.

:func:`trig_form` is the inverse map: it turns a real Laurent polynomial in
``w`` and ``E`` back into a sum of cosines and sines of ``theta`` and
``d theta``.
"""

import dataclasses
import random

import mpmath
import sympy as sp
from sympy.polys.fields import field

from . import model

__all__ = [
    "w", "E", "UnsupportedExpression", "IdentityResult",
    "exponential_form", "trig_form", "conjugate_on_circle",
    "check_identity", "assert_identity", "numeric_difference",
]

#: exp(j theta / 2)
w = sp.Symbol("w")
#: exp(j d theta)
E = sp.Symbol("E")

_TRIG = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)


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

    def rec(e):
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


def _rational_difference(lhs, rhs):
    """Return ``lhs - rhs`` as an element of a rational function field."""
    # A float stands for its exact binary value; replace it before any
    # arithmetic, which would round 5/2 - 1e-20 back to the float 2.5.
    lhs, rhs = (sp.sympify(x) for x in (lhs, rhs))
    lhs, rhs = (x.xreplace({f: sp.Rational(f) for f in x.atoms(sp.Float)}) for x in (lhs, rhs))
    diff = exponential_form(lhs) - exponential_form(rhs)
    # Opaque subexpressions (sqrt of a parameter, atan, ...) become free
    # generators: an identity with them free holds under any value they take.
    opaque = {}
    for f in sorted(diff.atoms(sp.Function, sp.Pow), key=sp.default_sort_key):
        if isinstance(f, sp.Pow) and f.exp.is_Integer:
            continue
        if f.has(model.theta):
            raise UnsupportedExpression(f"{f} depends on theta")
        opaque[f] = sp.Dummy(f"opaque{len(opaque)}")
    diff = diff.xreplace(opaque)
    gens = sorted(diff.free_symbols, key=sp.default_sort_key)
    if not gens:
        return sp.nsimplify(diff) if diff.is_Float else sp.simplify(diff)
    K, *_ = field(gens, sp.QQ_I)
    return K.from_expr(diff)


def _sample_point(symbols, rng):
    """A random point of the model's domain for the given symbols."""
    point = {}
    dlt = mpmath.mpf(rng.uniform(0.01, 1.0))
    for sym in symbols:
        if sym.is_integer:
            point[sym] = rng.randint(0, 15)
        elif sym == model.delta:
            point[sym] = dlt
        elif sym == model.Gamma:
            point[sym] = mpmath.exp(dlt) if model.delta in symbols else \
                mpmath.mpf(rng.uniform(1.01, 2.7))
        elif sym == model.theta:
            point[sym] = mpmath.mpf(rng.uniform(0.05, 3.05))
        elif sym.is_positive:
            point[sym] = mpmath.mpf(rng.uniform(0.05, 2.0))
        else:
            point[sym] = mpmath.mpf(rng.uniform(-2.0, 2.0))
    return point


def numeric_difference(lhs, rhs, *, samples=12, dps=40, seed=0):
    """Largest relative difference of ``lhs`` and ``rhs`` over random points.

    The difference is relative to the largest of ``|lhs|``, ``|rhs|`` and the
    sum of the sizes of their terms.  Both are evaluated with mpmath at ``dps`` digits, ``Gamma = exp(delta)``
    and ``d`` a random integer in 0..15.

    Returns
    -------
    (float, dict)
        The largest relative difference and the point where it occurred.
    """
    lhs, rhs = sp.sympify(lhs), sp.sympify(rhs)
    symbols = sorted(lhs.free_symbols | rhs.free_symbols, key=sp.default_sort_key)
    # The scale of a sum is the sum of its terms' sizes: an identity "X = 0"
    # whose X evaluates to 1e-45 out of terms of size 1 is satisfied.
    magnitude = sp.Add(*[sp.Abs(t) for t in sp.Add.make_args(lhs) + sp.Add.make_args(rhs)])
    f = sp.lambdify(symbols, [lhs, rhs, magnitude], modules="mpmath")
    rng = random.Random(seed)
    worst, worst_point = 0.0, {}
    done = tries = 0
    with mpmath.workdps(dps):
        while done < samples and tries < 20 * samples:
            tries += 1
            point = _sample_point(symbols, rng)
            try:
                a, c, size = f(*[point[sym] for sym in symbols])
            except (ZeroDivisionError, ValueError):
                continue  # a pole of either side: draw another point
            scale = max(abs(a), abs(c), size)
            if not (mpmath.isfinite(scale)):
                continue
            rel = abs(a - c) / scale if scale > 0 else mpmath.mpf(0)
            done += 1
            if rel >= worst:
                worst, worst_point = float(rel), {str(k): float(v) for k, v in point.items()}
    if done == 0:
        raise ValueError("could not evaluate the expressions at any sample point")
    return worst, worst_point


@dataclasses.dataclass(frozen=True)
class IdentityResult:
    """The verdict of :func:`check_identity`.

    Attributes
    ----------
    equal : bool or None
        ``True``: proved identical as rational functions of ``w, E, Gamma``;
        ``False``: shown different (a sample point with a relative difference
        above ``10**-(dps - 10)``); ``None``: outside the exact class and not
        contradicted by the numbers.
    method : str
        ``"exact"`` or ``"numeric"``.
    max_rel_diff : float
        Largest relative difference seen over the random samples.
    witness : dict
        The sample point of that difference.
    note : str
        Why the verdict is what it is.
    """

    equal: object
    method: str
    max_rel_diff: float
    witness: dict
    note: str = ""

    def __bool__(self):
        return self.equal is True


def check_identity(lhs, rhs, *, samples=12, dps=40, seed=0):
    """Decide whether ``lhs == rhs`` identically in theta, d and the parameters.

    Parameters
    ----------
    lhs, rhs : sympy expressions
        Expressions in ``theta``, ``d``, ``delta``, ``Gamma`` and the other
        model symbols.
    samples : int
        Random points of the mpmath cross-check.
    dps : int
        Working precision of the cross-check (>= 30).
    seed : int
        Seed of the random points (the verdict is deterministic).

    Returns
    -------
    IdentityResult

    Raises
    ------
    RuntimeError
        If the exact proof and the numbers disagree (a defect of the checker).

    Examples
    --------
    >>> from symstab.model import theta, d
    >>> import sympy as sp
    >>> check_identity(sp.sin((d + 1) * theta),
    ...                sp.sin(d * theta) * sp.cos(theta) + sp.cos(d * theta) * sp.sin(theta)).equal
    True
    >>> check_identity(sp.sin(2 * theta), 2 * sp.sin(theta)).equal
    False
    """
    if dps < 30:
        raise ValueError(f"dps must be an integer >= 30, got {dps!r}")
    tol = 10.0 ** -(dps - 10)
    rel, point = numeric_difference(lhs, rhs, samples=samples, dps=dps, seed=seed)
    try:
        difference = _rational_difference(lhs, rhs)
    except UnsupportedExpression as exc:
        if rel > tol:
            return IdentityResult(False, "numeric", rel, point,
                                  f"not exact-checkable ({exc}); numbers differ")
        return IdentityResult(None, "numeric", rel, point,
                              f"not exact-checkable ({exc}); equal to {dps} digits "
                              f"at {samples} random points")
    if difference == 0:
        if rel > tol:
            raise RuntimeError(
                f"exact checker proved an identity that differs numerically by {rel:.3g} "
                f"at {point}")
        return IdentityResult(True, "exact", rel, point, "difference is the zero rational function")
    if rel > tol:
        return IdentityResult(False, "exact", rel, point, "difference is a nonzero rational function")
    return IdentityResult(None, "exact", rel, point,
                          "nonzero rational difference that vanished at every sample point")


def assert_identity(lhs, rhs, **kwargs):
    """Raise :class:`AssertionError` unless :func:`check_identity` proves ``lhs == rhs``.

    Parameters
    ----------
    lhs, rhs : sympy.Expr
        The two sides.
    **kwargs
        Passed to :func:`check_identity`.

    Returns
    -------
    IdentityResult
    """
    result = check_identity(lhs, rhs, **kwargs)
    if result.equal is not True:
        raise AssertionError(
            f"not proved identical ({result.method}: {result.note}; "
            f"max relative difference {result.max_rel_diff:.3g} at {result.witness})")
    return result


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
