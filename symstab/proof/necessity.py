"""Necessary conditions for stability of the paper's loop, proved for every delay d.

The loop is stable when every root of chi(z) lies strictly inside the unit
circle.  chi has real coefficients, degree ``n = d + 4`` and leading
coefficient ``a_n``; three classical necessary conditions (the first steps of
Jury's test) follow from its values at ``z = 1``, ``z = -1`` and ``z = 0``,
and a fourth from its slope at ``z = 1``:

* **z = 1.**  When ``a_n chi(1) < 0``, chi changes sign on ``[1, inf)``
  (``chi(x) -> sign(a_n) inf``): a real root ``> 1`` (intermediate values).
  When ``chi(1) = 0``, z = 1 is a root.  For this loop ``chi(1) = alpha q(delta)``
  with ``q > 0`` and ``a_n > 0``: **alpha <= 0 is never stable** (alpha < 0: a
  real root > 1; alpha = 0: a root at z = 1).
* **z = 1, first order: the minimum damping.**  If every root ``z_i`` is
  inside the circle, ``chi'(1) / chi(1) = sum 1 / (1 - z_i)`` and each
  ``Re 1 / (1 - z_i) > 1/2``, so ``2 chi'(1) - n chi(1) > 0`` (with
  ``chi(1) > 0``).  For this loop that is, for every d and gamma (gamma drops
  out), **beta > -delta + s(d, delta) alpha** with
  ``s = d/2 + 1/delta - Gamma/(Gamma - 1)``; for ``d >= 2``, ``s > 0`` and
  beta > -delta (the paper's minimum damping ``B_w > -b``) is necessary.
* **z = -1.**  ``(-1)**n chi(x) -> sign(a_n) inf`` as ``x -> -inf``, so
  ``a_n (-1)**n chi(-1) < 0`` gives a real root ``< -1`` and ``chi(-1) = 0``
  a root at z = -1.  For this loop ``(-1)**n chi(-1) = a(delta) (alpha + 2 beta
  - c)`` with ``-(-1)**d a > 0``: stability needs ``alpha + 2 beta < c_even``
  for even d (a *maximum* damping) and ``alpha + 2 beta > c_odd`` for odd d (a
  *minimum* damping), ``c = (-1)**d C(delta) - 4 gamma``.
* **z = 0.**  ``|a_0 / a_n|`` is the product of the root moduli, so every
  root inside the circle needs ``|a_0| < |a_n|``.  Here ``a_0 = gamma g(delta)``
  with ``g > 0``: **|gamma| >= gamma_max(delta) = a_n / g is never stable**,
  and ``gamma_max(delta) > 2`` with ``gamma_max -> 2`` as ``delta -> 0``.

The delay is never fixed: chi is ``z**d`` times the delayed part plus the
direct part (:class:`symstab.symbolic.loop.LoopPolynomial`), so at z = 1 the
power ``1**(d + k)`` is 1 for every d, at z = -1 the two parities ``d = 2 k``
and ``d = 2 k + 1`` (``k >= 0`` a symbolic integer) cover every d, and the
leading and constant terms are found by comparing the exponents ``d + k``
with the assumption ``d >= 0`` (SymPy must decide each comparison).

Every object is built from :func:`symstab.symbolic.loop.characteristic_polynomial`,
never transcribed.  Two kinds of facts make the proofs:

* *identities* (``chi(1) = alpha q``, ...), returned by :func:`proofs` and
  proved by ``symstab derive`` with the exact checker
  (:func:`symstab.proof.identity.check_identity`, step ``07_proofs``);
* *signs*: an expression ``f(delta, Gamma)`` is positive for every
  ``delta > 0`` with ``Gamma = exp(delta)`` when ``f(0) = f'(0) = ... =
  f^(m-1)(0) = 0`` and SymPy's assumptions decide ``f^(m)(delta) > 0`` for
  ``delta > 0`` (integrate m times).  They are decided when the conditions
  are built; one that SymPy cannot decide raises :class:`ProofFailed`.

:func:`necessary_conditions` returns the records; ``symstab derive`` writes
them as step ``08_necessity`` and fails when a proof fails.
"""

import dataclasses
import functools
import re

import sympy as sp

from ..symbolic import model
from ..symbolic.loop import characteristic_polynomial
from .identity import check_identity

__all__ = ["ProofFailed", "SignFact", "NecessaryCondition", "positive_for_positive_delta",
           "necessary_conditions", "proofs", "objects"]

#: ``d = 2 k`` or ``d = 2 k + 1``: the two parities of the delay.
k = sp.Symbol("k", integer=True, nonnegative=True)

#: Highest derivative order the sign proofs try.
_MAX_ORDER = 6


class ProofFailed(AssertionError):
    """A step of a necessity proof does not hold for the derived polynomial."""


@dataclasses.dataclass(frozen=True)
class SignFact:
    """``expression > 0`` for every ``delta > 0`` (``Gamma = exp(delta)``).

    Attributes
    ----------
    name : str
    expression : sympy.Expr
        In ``delta`` and ``Gamma``.
    order : int
        ``m``: the derivatives of order ``< m`` vanish at ``delta = 0``.
    derivative : sympy.Expr
        The ``m``-th derivative in ``delta`` (``Gamma = exp(delta)``),
        which SymPy decides positive for ``delta > 0``.
    """

    name: str
    expression: sp.Expr
    order: int
    derivative: sp.Expr

    @property
    def note(self):
        """How it was proved, in one line."""
        if self.order == 0:
            return f"SymPy decides {sp.sstr(self.derivative)} > 0 for delta > 0"
        vanish = ", ".join(("f" + "'" * j if j < 3 else f"f^({j})") + "(0)" for j in range(self.order))
        return (f"with Gamma = exp(delta): {vanish} = 0 and the derivative of order "
                f"{self.order}, {sp.sstr(self.derivative)}, is > 0 for delta > 0")


@dataclasses.dataclass(frozen=True)
class NecessaryCondition:
    """One proved necessary condition for stability.

    Attributes
    ----------
    name : str
    theorem : str
        The statement, for every integer ``d >= 0``, ``delta > 0`` and real
        ``alpha, beta, gamma``.
    objects : tuple of (name, description, sympy.Expr)
        The derived objects the theorem names.
    identities : tuple of (name, statement, lhs, rhs)
        Proved by the exact checker in ``symstab derive``.
    signs : tuple of SignFact
        Decided when the record was built.
    decisions : tuple of str
        Other facts decided when the record was built (exponent comparisons
        for symbolic ``d >= 0``, a lemma), each saying how.
    """

    name: str
    theorem: str
    objects: tuple
    identities: tuple
    signs: tuple
    decisions: tuple


def positive_for_positive_delta(expression, *, name="f", max_order=_MAX_ORDER):
    """Prove ``expression > 0`` for every ``delta > 0`` with ``Gamma = exp(delta)``.

    Parameters
    ----------
    expression : sympy.Expr
        A polynomial in ``delta``, ``Gamma`` (and ``exp(delta)``), no other
        symbol.
    name : str
        Names the fact (and the failure).
    max_order : int
        Highest derivative tried.

    Returns
    -------
    SignFact

    Raises
    ------
    ProofFailed
        If the expression has other symbols, a lower derivative does not
        vanish at 0 (then the expression is not positive near 0 or the
        argument does not apply) or no derivative up to ``max_order`` is
        decided positive.

    Examples
    --------
    >>> from symstab.symbolic.model import delta, Gamma
    >>> positive_for_positive_delta(Gamma - 1 - delta).order
    2
    """
    f = sp.sympify(expression).subs(model.Gamma, sp.exp(model.delta))
    extra = f.free_symbols - {model.delta}
    if extra:
        raise ProofFailed(f"sign of {name}: {sp.sstr(expression)} depends on {sorted(map(str, extra))}")
    for order in range(max_order + 1):
        factored = sp.factor(f)
        if factored.is_positive is True:
            return SignFact(name, sp.sympify(expression), order, factored)
        at_zero = sp.simplify(f.subs(model.delta, 0))
        if at_zero != 0:
            raise ProofFailed(f"sign of {name}: the derivative of order {order} of "
                              f"{sp.sstr(expression)} is {sp.sstr(at_zero)} at delta = 0, "
                              "not 0, and SymPy cannot decide its sign")
        f = sp.diff(f, model.delta)
    raise ProofFailed(f"sign of {name}: no derivative of {sp.sstr(expression)} up to order "
                      f"{max_order} is decided positive for delta > 0")


def _decide(statement, value):
    """Record a symbolic decision that must be True for every ``d >= 0``."""
    if value is not True:
        raise ProofFailed(f"not decided for every integer d >= 0: {statement} (SymPy: {value})")
    return statement


def _extreme_term(chi, *, highest):
    """The term of chi whose exponent exceeds (or is below) every other one for every d >= 0.

    Returns ``(exponent, coefficient, decisions)``.
    """
    terms = [(sp.sympify(e), c) for e, c in chi.terms()]
    for exponent, coefficient in terms:
        gaps = [(exponent - other) if highest else (other - exponent)
                for other, _ in terms if other != exponent]
        if all(gap.is_positive is True for gap in gaps):
            others = [other for other, _ in terms if other != exponent]
            relation = "exceeds" if highest else "is below"
            decision = _decide(f"for every integer d >= 0: {sp.sstr(exponent)} {relation} every other "
                               f"exponent of chi ({', '.join(sp.sstr(e) for e in others)}) "
                               "[decided by SymPy's assumptions]",
                               all(gap.is_positive for gap in gaps))
            return exponent, coefficient, (decision,)
    which = "highest" if highest else "lowest"
    raise ProofFailed(f"no exponent of chi is the {which} for every d >= 0: "
                      f"{[sp.sstr(e) for e, _ in terms]}")


def _alpha_positive(chi, leading):
    """z = 1: chi(1) = alpha q with q > 0 and a_n > 0."""
    n, lc, decisions = leading
    alpha = model.alpha
    at_one = sp.expand(chi.as_expr().subs(model.z, 1))
    if at_one.has(model.d):
        raise ProofFailed(f"chi(1) depends on d: {at_one}")
    q = sp.factor(sp.diff(at_one, alpha))
    theorem = (f"chi(1) = alpha * ({sp.sstr(q)}) with {sp.sstr(q)} > 0 and the leading coefficient "
               f"a_n = {sp.sstr(lc)} > 0 (n = {sp.sstr(n)}): for alpha < 0, chi(1) < 0 < chi(+inf), "
               "so chi has a real root > 1; for alpha = 0, z = 1 is a root. "
               "alpha <= 0 is never stable, for every d >= 0, delta > 0, beta and gamma.")
    return NecessaryCondition(
        name="alpha_positive",
        theorem=theorem,
        objects=(("leading_exponent", "degree n of chi for every d >= 0", n),
                 ("leading_coefficient", "a_n, the coefficient of z^n", lc),
                 ("chi_at_1", "chi(1) (1^(d + j) = 1 for every d)", at_one),
                 ("chi_at_1_factor", "q = d chi(1) / d alpha", q)),
        identities=(("necessity_chi_at_1_is_alpha_q", f"chi(1) = alpha * ({sp.sstr(q)}), for every d",
                     at_one, alpha * q),),
        signs=(positive_for_positive_delta(lc, name="leading coefficient a_n"),
               positive_for_positive_delta(q, name="q = chi(1) / alpha")),
        decisions=decisions)


def _minus_one_line(chi, leading):
    """z = -1: (-1)**n chi(-1) = a (alpha + 2 beta - c) per parity of d."""
    n, _, _ = leading
    alpha, beta, gamma = model.alpha, model.beta, model.gamma
    objects, identities, signs = [], [], []
    lines = {}
    for parity, label in ((0, "even"), (1, "odd")):
        delay = 2 * k + parity
        value = sp.expand(((-1) ** n * chi.as_expr()).subs(model.d, delay).subs(model.z, -1))
        if value.has(k):
            raise ProofFailed(f"(-1)^n chi(-1) depends on d beyond its parity ({label} d): {value}")
        a = sp.factor(sp.diff(value, alpha))
        g = sp.factor(sp.diff(value, gamma))
        rest = sp.factor(value.subs({alpha: 0, beta: 0, gamma: 0}))
        c = -(g * gamma + rest) / a
        # Written as C(delta) + slope * gamma: the line moves with gamma only.
        c = sp.factor(c.subs(gamma, 0)) + sp.factor(sp.diff(c, gamma)) * gamma
        sign = 1 - 2 * parity     # (-1)**d
        identities.append((f"necessity_chi_at_minus_1_{label}_d",
                           f"{label} d: (-1)^n chi(-1) = ({sp.sstr(a)}) (alpha + 2 beta) "
                           f"+ ({sp.sstr(g)}) gamma + ({sp.sstr(rest)})",
                           value, a * (alpha + 2 * beta) + g * gamma + rest))
        signs.append(positive_for_positive_delta(-sign * a, name=f"-(-1)^d a, {label} d"))
        objects.append((f"chi_at_minus_1_{label}_d", f"(-1)^n chi(-1) for {label} d", value))
        objects.append((f"minus_one_line_{label}_d",
                        f"c: chi(-1) = 0 on alpha + 2 beta = c, {label} d", c))
        lines[label] = c
    theorem = (
        "(-1)^n chi(-1) = a (alpha + 2 beta - c) with -(-1)^d a > 0 and a_n > 0: where "
        "(-1)^d (alpha + 2 beta - c) > 0, (-1)^n chi(-1) < 0 and chi has a real root < -1; on the "
        "line, z = -1 is a root. Stability needs alpha + 2 beta < c for even d (a maximum damping) "
        "and alpha + 2 beta > c for odd d (a minimum damping, beta > (c - alpha) / 2), with "
        f"c = {sp.sstr(lines['even'])} (even d), c = {sp.sstr(lines['odd'])} (odd d).")
    return NecessaryCondition(name="minus_one_line", theorem=theorem, objects=tuple(objects),
                              identities=tuple(identities), signs=tuple(signs), decisions=leading[2])


def _gamma_bound(chi, leading):
    """z = 0: |a_0| < a_n with a_0 = gamma g."""
    _, lc, _ = leading
    gamma = model.gamma
    zero, a0, decisions = _extreme_term(chi, highest=False)
    if zero != 0:
        raise ProofFailed(f"the lowest exponent of chi is {zero}, not 0 for every d")
    g = sp.factor(sp.diff(a0, gamma))
    gamma_max = sp.factor(lc / g)
    limit = sp.limit(gamma_max.subs(model.Gamma, sp.exp(model.delta)), model.delta, 0, "+")
    theorem = (
        f"The constant term a_0 = gamma * ({sp.sstr(g)}) with {sp.sstr(g)} > 0; every root inside "
        "the unit circle needs |a_0| < a_n (their product has modulus |a_0| / a_n), so "
        f"|gamma| >= gamma_max = {sp.sstr(gamma_max)} is never stable, for every d, alpha and beta. "
        f"gamma_max > 2 for every delta > 0 (a_n - 2 g > 0) and gamma_max -> {sp.sstr(limit)} "
        "as delta -> 0.")
    return NecessaryCondition(
        name="gamma_bound",
        theorem=theorem,
        objects=(("constant_term", "a_0, the coefficient of z^0 for every d >= 0", a0),
                 ("constant_term_factor", "g = d a_0 / d gamma", g),
                 ("gamma_max", "gamma_max = a_n / g", gamma_max),
                 ("gamma_max_small_delta", "lim gamma_max as delta -> 0+", limit)),
        identities=(("necessity_constant_term_is_gamma_g", f"a_0 = gamma * ({sp.sstr(g)}), for every d",
                     a0, gamma * g),),
        signs=(positive_for_positive_delta(g, name="g = a_0 / gamma"),
               positive_for_positive_delta(sp.expand(lc - 2 * g), name="a_n - 2 g")),
        decisions=decisions)


def _minimum_damping(chi, leading):
    """z = 1, first order: 2 chi'(1) - n chi(1) > 0, a line through (-delta, 0)."""
    n, _, decisions = leading
    alpha, beta, gamma, z = model.alpha, model.beta, model.gamma, model.z
    at_one = sp.expand(chi.as_expr().subs(z, 1))
    slope_at_one = sp.expand(sp.diff(chi.as_expr(), z).subs(z, 1))
    if slope_at_one.has(z):
        raise ProofFailed(f"chi'(1) still depends on z: {slope_at_one}")
    condition = sp.expand(2 * slope_at_one - n * at_one)
    scale = sp.factor(sp.diff(condition, beta))
    start = sp.factor(-condition.subs({alpha: 0, beta: 0, gamma: 0}) / scale)
    slope = sp.factor(-sp.diff(condition, alpha) / scale)
    # Re 1/(1 - z) > 1/2 inside the unit circle: with z = x + j y,
    # Re 1/(1 - z) - 1/2 = (1 - |z|**2) / (2 |1 - z|**2).
    # The lemma holds for any z, not only for this loop: it is proved here, once,
    # and not among the derivation's identities (whose symbols are the model's).
    x, y = sp.symbols("x y", real=True)
    lemma = "Re 1/(1 - z) - 1/2 = (1 - |z|^2) / (2 |1 - z|^2) for z = x + j y"
    result = check_identity(sp.re(1 / (1 - x - sp.I * y)) - sp.Rational(1, 2),
                            (1 - x**2 - y**2) / (2 * ((1 - x)**2 + y**2)))
    if result.equal is not True:
        raise ProofFailed(f"lemma not proved: {lemma} ({result.note})")
    identities = [("necessity_minimum_damping_line",
                   f"2 chi'(1) - n chi(1) = ({sp.sstr(scale)}) (beta - ({sp.sstr(start)}) "
                   f"- ({sp.sstr(slope)}) alpha), for every d",
                   condition, scale * (beta - start - slope * alpha))]
    # For d = 2 + j (j >= 0) the slope times the positive scale is affine in j
    # with a positive coefficient and a positive value at j = 0.
    j = sp.Symbol("j", integer=True, nonnegative=True)
    scaled = sp.expand((slope * scale).subs(model.d, 2 + j))
    if sp.Poly(scaled, j).degree() > 1:
        raise ProofFailed(f"slope * scale is not affine in d: {scaled}")
    signs = (positive_for_positive_delta(scale, name="scale = d (2 chi'(1) - n chi(1)) / d beta"),
             positive_for_positive_delta(scaled.coeff(j, 1), name="d (slope * scale) / d d"),
             positive_for_positive_delta(scaled.subs(j, 0), name="slope * scale at d = 2"))
    theorem = (
        "If every root z_i is inside the unit circle, chi'(1) / chi(1) = sum 1/(1 - z_i) and "
        "Re 1/(1 - z_i) > 1/2, so chi'(1) / chi(1) > n/2; with chi(1) > 0 (alpha > 0, "
        f"alpha_positive): 2 chi'(1) - n chi(1) = ({sp.sstr(scale)}) (beta - ({sp.sstr(start)}) "
        f"- s alpha) > 0 with the scale > 0, i.e. the minimum damping beta > {sp.sstr(start)} "
        f"+ s alpha, s = {sp.sstr(slope)}, for every d and gamma (gamma drops out). "
        "For d >= 2, s > 0, so beta > -delta is necessary; for d = 0, 1 the line leans "
        "to beta < -delta as alpha grows.")
    return NecessaryCondition(
        name="minimum_damping",
        theorem=theorem,
        objects=(("chi_prime_at_1", "chi'(1) (d/dz z^(d + j) = d + j at z = 1)", slope_at_one),
                 ("minimum_damping_start", "beta where the line meets alpha = 0", start),
                 ("minimum_damping_slope", "s: the line is beta = start + s alpha", slope)),
        identities=tuple(identities), signs=signs,
        decisions=decisions + (f"{lemma} [proved by the exact checker]",))


@functools.lru_cache(maxsize=None)
def _conditions(chi):
    leading = _extreme_term(chi, highest=True)
    return (_alpha_positive(chi, leading), _minimum_damping(chi, leading),
            _minus_one_line(chi, leading), _gamma_bound(chi, leading))


def necessary_conditions():
    """Prove the necessary conditions for the derived characteristic polynomial.

    Returns
    -------
    tuple of NecessaryCondition
        ``alpha_positive`` (z = 1), ``minimum_damping`` (chi'(1)),
        ``minus_one_line`` (z = -1) and ``gamma_bound`` (z = 0).  Their sign facts and exponent comparisons
        are decided here; their identities are proved by ``symstab derive``
        (:func:`proofs`).

    Raises
    ------
    ProofFailed
        If a sign or an exponent comparison does not hold (or SymPy cannot
        decide it) for the derived polynomial.
    """
    return _conditions(characteristic_polynomial())


def proofs():
    """The identities of the necessity proofs, for the exact checker.

    Returns
    -------
    list of (name, statement, lhs, rhs)
    """
    return [identity for condition in necessary_conditions() for identity in condition.identities]


def objects():
    """The objects and decided facts of the proofs, for ``symstab derive`` (step 08).

    Returns
    -------
    tuple of (name, description, sympy object)
        The derived objects, then one ``sympy.true`` per theorem, sign fact
        and exponent comparison, its description saying how it was proved.
    """
    out = []
    for condition in necessary_conditions():
        out += list(condition.objects)
        for fact in condition.signs:
            out.append((f"{condition.name}_sign_{_slug(fact.name)}",
                        f"{fact.name}: {sp.sstr(fact.expression)} > 0 for delta > 0 [proved: {fact.note}]",
                        sp.S.true))
        for j, decision in enumerate(condition.decisions):
            out.append((f"{condition.name}_decision_{j}", decision, sp.S.true))
        out.append((f"{condition.name}_theorem", condition.theorem, sp.S.true))
    return tuple(out)


def _slug(text):
    return re.sub(r"[^0-9a-z]+", "_", text.lower()).strip("_")
