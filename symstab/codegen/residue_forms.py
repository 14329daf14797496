"""Float-safe forms of a residue-path plant's coefficients: each exponential through ``exprel_k``.

The residues write a plant's pulse transfer function as sums of
exponentials ``exp(u)``, ``u`` a pole times ``T`` (or times ``eps T``, ``(1
- eps) T`` with a fractional delay).  For small ``|u|`` those sums cancel:
the paper's ``1/(m s**2 + b s)`` has a numerator of order ``delta**2`` made
of terms of order 1 (``delta = b T / m``), so that ``delta = 1e-3`` costs
six digits in double precision and ``delta = 1e-8`` all of them.

:func:`float_safe` writes every ``exp(u)`` as its Taylor polynomial and an
exact remainder,

    exp(u) = sum_{j < k} u**j / j! + u**k exprel_k(u),
    exprel_k(u) = (exp(u) - sum_{j < k} u**j / j!) / u**k,

and expands: the polynomial parts that cancel cancel exactly, in SymPy,
and what remains carries its small factors (``u**2`` and so on) as
products, not differences.  ``exprel_k`` (:func:`exprel`, a
:class:`~symstab.codegen.float_forms.SeriesFunction`) is bounded and smooth
on the real line, evaluated by its Taylor series for ``|u| <`` its switch
and by its closed form (with ``expm1``) above.  Both rewrites are
identities: :func:`proofs` states them for the exact checker, the form
against the derivation (``exprel_k`` replaced by its definition) and each
closed form against its definition; only the Taylor branches are numerical,
and the tests measure them against mpmath.

The forms are measured, not assumed, to keep their digits (the tests and
``docs/guide/c_kernels.md``): the rewrite removes the cancellation of the
polynomial parts, not every one.  A difference the plant itself makes --
two poles that meet (``b tau = m`` in ``1/((tau s + 1)(m s**2 + b s))``),
or ``eps -> 1``, where ``N_eps``'s leading coefficient tends to 0 -- still
costs digits of the coefficients it touches.
"""

import functools
import math

import sympy as sp
from sympy.codegen.cfunctions import expm1

from .float_forms import SeriesFunction
from .generator import Kernel

__all__ = ["Exprel", "exprel", "float_safe", "as_exponentials", "helper_kernels", "proofs"]


class Exprel(SeriesFunction):
    """``exprel_k(x) = (exp(x) - sum_{j < k} x**j / j!) / x**k`` for real ``x`` of either sign.

    ``k`` is :attr:`order`; :func:`exprel` makes the class of each order.
    At ``x = 0`` it is ``1 / k!``; it is positive and increasing.  Below the
    switch in ``|x|`` its Taylor polynomial ``sum_j x**j / (k + j)!`` (the
    terms alternate for ``x < 0``, summed with at most ``exp(2 |x|)`` times
    the value: a few bits), above it the closed form with ``expm1``.
    """

    order = 1
    switch = sp.Integer(2)

    @classmethod
    def definition(cls, x):
        k = cls.order
        return (sp.exp(x) - sum(x**j / sp.factorial(j) for j in range(k))) / x**k

    @classmethod
    def closed_form(cls, x):
        k = cls.order
        return (expm1(x) - sum(x**j / sp.factorial(j) for j in range(1, k))) / x**k

    @classmethod
    def coefficient(cls, j):
        return 1 / sp.factorial(cls.order + j)

    @classmethod
    def evaluation(cls, x):
        """The series for ``|x| <`` :attr:`switch`, the closed form above.

        The closed form divides by ``max(|x|, switch)**k sign(x)**k``, which
        is ``x**k`` where it is used, so that a vectorised evaluation of both
        branches (``numpy.where``) never divides by 0.
        """
        k = cls.order
        closed = cls.closed_form(x) * x**k / sp.Max(sp.Abs(x), cls.switch)**k
        if k % 2:
            closed *= sp.sign(x)
        return sp.Piecewise((cls.series(x), sp.Abs(x) < cls.switch), (closed, True))


def _terms(k, switch=2):
    """Terms of the Taylor polynomial of ``exprel_k`` on ``|x| < switch``.

    The first neglected term ``switch**n / (k + n)!`` below ``2**-53`` of the
    smallest value there, ``exprel_k(-switch) > exp(-switch) / k!``.
    """
    n = 1
    while switch**n / math.factorial(k + n) >= 2.0**-53 * math.exp(-switch) / math.factorial(k):
        n += 1
    return n


@functools.lru_cache(maxsize=None)
def exprel(k):
    """The :class:`Exprel` class of order ``k >= 1``, named ``exprel<k>`` (one per process).

    Parameters
    ----------
    k : int

    Returns
    -------
    type
        A SymPy function class of one argument.
    """
    if not isinstance(k, int) or k < 1:
        raise ValueError(f"the order k of exprel_k must be an integer >= 1, got {k!r}")
    # The metaclass of SymPy functions makes the class (what a class statement would do).
    return type(Exprel)(f"exprel{k}", (Exprel,), {
        "order": k, "terms": _terms(k),
        "formula": f"(exp(x) - sum_(j < {k}) x^j / j!) / x^{k}",
        "__doc__": f"exprel_{k}(x) = (exp(x) - sum_(j < {k}) x^j / j!) / x^{k}, "
                   f"1/{math.factorial(k)} at x = 0."})


def float_safe(expr, order):
    """``expr`` with every ``exp(u)`` written as ``sum_{j < order} u**j / j! + u**order exprel_order(u)``.

    Expanded, so that the polynomial parts cancel exactly where they cancel.

    Parameters
    ----------
    expr : sympy.Expr
        A coefficient as derived (a polynomial in exponentials).
    order : int
        ``k``: the plant's poles of ``G(s) / s`` counted with their
        multiplicity is enough for the cancellation of the poles at 0.

    Returns
    -------
    sympy.Expr
    """
    function = exprel(order)

    def taylor(e):
        u = e.args[0]
        return sum(u**j / sp.factorial(j) for j in range(order)) + u**order * function(u)

    return sp.expand(sp.sympify(expr).replace(lambda e: isinstance(e, sp.exp), taylor))


def as_exponentials(expr):
    """Each ``exprel_k(u)`` of ``expr`` replaced by its definition in ``exp(u)``."""
    return expr.replace(lambda e: isinstance(e, Exprel), lambda e: type(e).definition(e.args[0]))


def _used(exprs):
    """The :class:`Exprel` classes in ``exprs``, by order."""
    found = {type(f) for e in exprs for f in sp.sympify(e).atoms(sp.Function)
             if isinstance(f, Exprel)}
    return sorted(found, key=lambda f: f.order)


def helper_kernels(exprs):
    """The generated helpers of the :class:`Exprel` functions in ``exprs`` (by order).

    Parameters
    ----------
    exprs : iterable of sympy.Expr

    Returns
    -------
    list of symstab.codegen.generator.Kernel
        One function of one double each, printed before the kernels that
        call it.
    """
    x = sp.Symbol("x", real=True)
    return [Kernel(f.__name__, ((x, "double", "the argument, any real (exp(x) must not "
                                               "overflow: x < 709)"),),
                   ((f.__name__, f.evaluation(x), f.formula),),
                   f"{f.formula}, 1/{math.factorial(f.order)} at x = 0: a Taylor polynomial "
                   f"of {f.terms} terms for |x| < {f.switch}, expm1 above.")
            for f in _used(exprs)]


def proofs(pairs):
    """The identities that make float-safe forms the derivation's objects.

    Parameters
    ----------
    pairs : iterable of (name, statement, form, derived)
        A form of :func:`float_safe` and the object it was made from.

    Returns
    -------
    list of (name, statement, lhs, rhs)
        Each form with its :class:`Exprel` functions replaced by their
        definitions against the derived object, then each closed form
        (``expm1`` written ``exp - 1``) against its definition.
    """
    pairs = list(pairs)
    out = [(name, statement, as_exponentials(form), derived)
           for name, statement, form, derived in pairs]
    x = sp.Symbol("x", real=True)
    for f in _used(form for _, _, form, _ in pairs):
        closed = f.closed_form(x).replace(lambda e: isinstance(e, expm1),
                                          lambda e: sp.exp(e.args[0]) - 1)
        out.append((f"{f.__name__}_closed_form", f"{f.__name__}: the closed form evaluated "
                    f"for |x| >= {f.switch} = its definition", closed, f.definition(x)))
    return out
