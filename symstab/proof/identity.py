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

import collections
import dataclasses
import functools
import random

import mpmath
import sympy as sp
from sympy.polys.fields import field
from sympy.polys.monomials import monomial_div, monomial_lcm
from sympy.polys.polyerrors import CoercionFailed
from sympy.polys.rings import ring

from ..symbolic import model
from ..symbolic.forms import (
    NO_DOCSTRING,
    E,
    UnsupportedExpression,
    conjugate_on_circle,
    exponential_form,
    trig_form,
    w,
)

__all__ = [
    "IdentityResult", "check_identity", "assert_identity", "numeric_difference",
    # the forms it proves with, from symstab.symbolic.forms
    "w", "E", "UnsupportedExpression", "exponential_form", "trig_form", "conjugate_on_circle",
]


def _rational_difference(lhs, rhs):
    """Return a polynomial over QQ_I that is zero exactly when ``lhs - rhs`` is.

    The numerator of ``lhs - rhs`` written as a rational function (not
    reduced, see :class:`_Fraction`), or a SymPy number when no symbol is left.
    """
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
    R, *_ = ring(gens, sp.QQ_I)
    try:
        return _Fraction.of(diff, dict(zip(R.symbols, R.gens, strict=True)), R).numer
    except _NotPolynomial:
        # Outside what _Fraction builds: SymPy's field decides (and raises what it raises).
        K, *_ = field(gens, sp.QQ_I)
        return K.from_expr(diff)


class _NotPolynomial(Exception):
    """A node :class:`_Fraction` does not build."""


@dataclasses.dataclass(frozen=True)
class _Fraction:
    """``numer / denom``, two polynomials over QQ_I, never reduced.

    SymPy's rational function field cancels the gcd after every sum and
    product of the expression tree (most of the audit's time went there);
    whether a difference is zero needs only its numerator, and a numerator
    of a fraction that is never reduced is zero exactly when the reduced one
    is, the denominators being products of nonzero polynomials.  Monomial
    denominators (the powers of ``w`` and ``E`` of the exponential form)
    are kept monic and combined by their least common multiple, so that the
    sums of the trigonometric forms do not multiply them up.
    """

    numer: object
    denom: object

    @classmethod
    def of(cls, expr, gens, R):
        """The fraction of ``expr`` in the ring ``R``, ``gens`` mapping symbols to generators."""
        if expr in gens:
            return cls(gens[expr], R.one)
        if expr.is_Add:
            return functools.reduce(cls.__add__, (cls.of(a, gens, R) for a in expr.args))
        if expr.is_Mul:
            return functools.reduce(cls.__mul__, (cls.of(a, gens, R) for a in expr.args))
        if expr.is_Pow and expr.exp.is_Integer:
            return cls.of(expr.base, gens, R) ** int(expr.exp)
        if expr.is_Number or expr is sp.I:
            try:
                return cls(R.ground_new(R.domain.convert(expr)), R.one)
            except CoercionFailed:
                pass
        raise _NotPolynomial(expr)

    def __add__(self, other):
        if self.denom == other.denom:
            return _Fraction(self.numer + other.numer, self.denom)
        R = self.denom.ring
        if all(len(q) == 1 and q.LC == R.domain.one for q in (self.denom, other.denom)):
            m1, m2 = self.denom.LM, other.denom.LM
            lcm = monomial_lcm(m1, m2)
            return _Fraction(
                self.numer.mul_monom(monomial_div(lcm, m1))
                + other.numer.mul_monom(monomial_div(lcm, m2)), R({lcm: R.domain.one}))
        return _Fraction(self.numer * other.denom + other.numer * self.denom,
                         self.denom * other.denom)

    def __mul__(self, other):
        return _Fraction(self.numer * other.numer, self.denom * other.denom)._monic()

    def __pow__(self, n):
        if n >= 0:
            return _Fraction(self.numer ** n, self.denom ** n)
        if not self.numer:
            raise ZeroDivisionError("zero denominator")
        return _Fraction(self.denom ** -n, self.numer ** -n)._monic()

    def _monic(self):
        """Move the coefficient of a one-term denominator into the numerator."""
        if len(self.denom) == 1 and self.denom.LC != self.denom.ring.domain.one:
            c = self.denom.LC
            return _Fraction(self.numer.quo_ground(c), self.denom.quo_ground(c))
        return self




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
    # Abs unevaluated: its simplifications (|exp(j x)| = 1, |2 x| = 2 |x|, ...)
    # change the size by rounding only, and cost more than the evaluation.
    magnitude = sp.Add(*[sp.Abs(t, evaluate=False)
                         for t in sp.Add.make_args(lhs) + sp.Add.make_args(rhs)])
    f = sp.lambdify(symbols, [lhs, rhs, magnitude], modules="mpmath", **NO_DOCSTRING)
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
    >>> from symstab.symbolic.model import theta, d
    >>> import sympy as sp
    >>> check_identity(sp.sin((d + 1) * theta),
    ...                sp.sin(d * theta) * sp.cos(theta) + sp.cos(d * theta) * sp.sin(theta)).equal
    True
    >>> check_identity(sp.sin(2 * theta), 2 * sp.sin(theta)).equal
    False
    """
    if dps < 30:
        raise ValueError(f"dps must be an integer >= 30, got {dps!r}")
    try:
        key = (sp.sympify(lhs), sp.sympify(rhs), samples, dps, seed)
        hash(key)
    except (TypeError, sp.SympifyError):
        return _check_identity(lhs, rhs, samples=samples, dps=dps, seed=seed)
    if key not in _RESULTS:
        _RESULTS[key] = _check_identity(lhs, rhs, samples=samples, dps=dps, seed=seed)
        if len(_RESULTS) > _RESULTS_KEPT:
            _RESULTS.popitem(last=False)
    result = _RESULTS[key]
    return dataclasses.replace(result, witness=dict(result.witness))


#: Verdicts of this process by (lhs, rhs, samples, dps, seed): the audit's
#: checks prove some identities twice (an erratum's printed and corrected
#: forms against the same derived one, a form shared by two checks).  A
#: verdict that raised (RuntimeError) is not kept.
_RESULTS = collections.OrderedDict()
_RESULTS_KEPT = 1024


def _check_identity(lhs, rhs, *, samples, dps, seed):
    """:func:`check_identity` computed (no cache)."""
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
