"""Tests of symstab.proof.identity: the exact equality checker and its forms."""

import mpmath
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from symstab.proof.identity import (
    IdentityResult,
    assert_identity,
    check_identity,
    numeric_difference,
)
from symstab.symbolic import model
from symstab.symbolic.boundary import coefficients
from symstab.symbolic.forms import E, UnsupportedExpression, exponential_form, trig_form, w

theta, d, delta, Gamma = model.theta, model.d, model.delta, model.Gamma
sin, cos = sp.sin, sp.cos
half = theta / 2

#: The paper's Appendix B, as printed (only the entries the derivation confirms).
PAPER_K1 = 32 * sin(half) ** 5 * cos(half)                      # eq. (20)
PAPER_K2 = (1 - Gamma) ** 2                                      # eq. (21)
PAPER_K3 = 1 + Gamma**2 - 2 * Gamma * cos(theta)                 # eq. (22)
PAPER_C6 = -2 * PAPER_K2 * sin(theta) * (cos(theta) - 1)         # eq. (29)

TRUE_IDENTITIES = {
    "sin_sum": (sin((d + 1) * theta), sin(d * theta) * cos(theta) + cos(d * theta) * sin(theta)),
    "product_sin_cos": (2 * sin(d * theta) * cos(theta), sin((d + 1) * theta) + sin((d - 1) * theta)),
    "product_cos_cos": (2 * cos(d * theta) * cos(theta), cos((d + 1) * theta) + cos((d - 1) * theta)),
    "product_sin_sin": (2 * sin(d * theta) * sin(theta), cos((d - 1) * theta) - cos((d + 1) * theta)),
    "half_angle_delay": (cos((2 * d + 1) * theta / 2),
                         cos(d * theta) * cos(half) - sin(d * theta) * sin(half)),
    # Appendix D: sin(x + theta) - 2 sin x + sin(x - theta) = -4 sin^2(theta/2) sin x, x = d theta
    "second_difference": (sin(d * theta + theta) - 2 * sin(d * theta) + sin(d * theta - theta),
                          -4 * sin(half) ** 2 * sin(d * theta)),
    "tan": (sp.tan(theta), sin(theta) / cos(theta)),
    "gamma_is_exp_delta": (Gamma**2 * sin(theta), sp.exp(2 * delta) * sin(theta)),
}

FALSE_IDENTITIES = {
    "double_angle": (sin(2 * theta), 2 * sin(theta)),
    "sin_sum_wrong": (sin((d + 1) * theta), sin(d * theta) + sin(theta)),
    "gamma_perturbed_float": (Gamma, sp.exp(delta) * 1.0000001),
    "gamma_perturbed_rational": (Gamma, sp.exp(delta) * sp.Rational(10000001, 10000000)),
    "half_angle_wrong_sign": (cos((2 * d + 1) * theta / 2),
                              cos(d * theta) * cos(half) + sin(d * theta) * sin(half)),
    "constant": (sp.Integer(1), sp.Integer(2)),
}


@pytest.mark.parametrize("name", sorted(TRUE_IDENTITIES))
def test_check_identity_proves_true_identities(name):
    result = check_identity(*TRUE_IDENTITIES[name])
    assert result.equal is True and result.method == "exact"
    assert bool(result) is True


@pytest.mark.parametrize("name", sorted(FALSE_IDENTITIES))
def test_check_identity_refutes_false_identities(name):
    lhs, rhs = FALSE_IDENTITIES[name]
    result = check_identity(lhs, rhs)
    assert result.equal is False
    assert bool(result) is False
    assert result.max_rel_diff > 1e-10
    assert set(result.witness) == {str(s) for s in (sp.sympify(lhs) - rhs).free_symbols}


def test_paper_K1_equals_derived_K1():
    assert check_identity(coefficients()["K1"], PAPER_K1).equal is True


def test_derived_C7_is_K3_sin_theta():
    assert check_identity(coefficients()["C7"], PAPER_K3 * sin(theta)).equal is True


def test_paper_C6_equals_derived_C6():
    assert check_identity(coefficients()["C6"], PAPER_C6).equal is True


def test_paper_K1_with_tiny_rational_change_is_refuted():
    result = check_identity(coefficients()["K1"], PAPER_K1 + sp.Rational(1, 10**20) * sin(theta))
    assert result.equal is False


def test_paper_K1_with_tiny_float_change_is_refuted():
    result = check_identity(coefficients()["K1"], PAPER_K1 + 1e-20 * sin(theta))
    assert result.equal is False


def test_K1_with_wrong_power_is_refuted():
    assert check_identity(coefficients()["K1"], 32 * sin(half) ** 4 * cos(half)).equal is False


@pytest.mark.parametrize("lhs, rhs", [
    (sp.sqrt(theta) * sin(2 * theta), 2 * sp.sqrt(theta) * sin(theta) * cos(theta)),
    (theta * sin(2 * theta), 2 * theta * sin(theta) * cos(theta)),
    (sin(theta / 4) ** 2, (1 - cos(half)) / 2),          # frequency 1/4: outside p/2 + q d
    (sin(theta**2) * cos(theta**2), sin(2 * theta**2) / 2),
])
def test_check_identity_is_undecided_outside_the_class(lhs, rhs):
    result = check_identity(lhs, rhs)
    assert result.equal is None and result.method == "numeric"
    assert bool(result) is False


def test_check_identity_refutes_numerically_outside_the_class():
    result = check_identity(theta * sin(2 * theta), 2 * theta * sin(theta))
    assert result.equal is False and result.method == "numeric"


def test_check_identity_requires_30_digits():
    with pytest.raises(ValueError, match="dps"):
        check_identity(sin(theta), sin(theta), dps=20)


def test_assert_identity():
    assert isinstance(assert_identity(*TRUE_IDENTITIES["sin_sum"]), IdentityResult)
    with pytest.raises(AssertionError):
        assert_identity(*FALSE_IDENTITIES["double_angle"])
    with pytest.raises(AssertionError):
        assert_identity(theta * sin(2 * theta), 2 * theta * sin(theta) * cos(theta))


@pytest.mark.parametrize("lhs, rhs, equal", [
    (1 / (Gamma + 1) + 1 / (Gamma - 1), 2 * Gamma / (Gamma**2 - 1), True),
    (1 / (Gamma + 1) + 1 / (Gamma - 1), 2 / (Gamma**2 - 1), False),
    (Gamma / (3 * sin(theta)) + 1 / (2 * sin(theta)), (2 * Gamma + 3) / (6 * sin(theta)), True),
    (Gamma / (3 * sin(theta)) + 1 / (2 * cos(theta)), (2 * Gamma + 3) / (6 * sin(theta)), False),
    ((1 / (Gamma - 1) - 1 / Gamma) ** 2 * Gamma**2 * (Gamma - 1) ** 2, sp.Integer(1), True),
])
def test_rational_differences_with_unreduced_denominators(lhs, rhs, equal):
    """The difference is never reduced (sums of fractions over other denominators,
    monomial denominators with a coefficient): zero exactly when it is zero."""
    result = check_identity(lhs, rhs)
    assert result.equal is equal and result.method == "exact"


def test_a_repeated_check_is_answered_from_the_process_cache(monkeypatch):
    """The audit proves some identities twice: the second verdict is the first one's."""
    from symstab.proof import identity

    x = 3 * d * theta
    lhs, rhs = sin(x + theta), sin(x) * cos(theta) + cos(x) * sin(theta)
    first = check_identity(lhs, rhs, seed=41)

    def refuse(*args, **kwargs):
        raise AssertionError("computed again")

    monkeypatch.setattr(identity, "numeric_difference", refuse)
    again = check_identity(lhs, rhs, seed=41)
    assert again == first and again.equal is True
    again.witness.clear()                 # a caller's edit does not reach the cache
    assert check_identity(lhs, rhs, seed=41).witness == first.witness != {}
    with pytest.raises(AssertionError, match="computed again"):
        check_identity(lhs, rhs, seed=42)  # another sample is another check


def test_numeric_difference_is_relative():
    rel, point = numeric_difference(sin(theta), sin(theta) * (1 + sp.Rational(1, 1000)))
    assert 1e-4 < rel < 1e-3 and "theta" in point


# exponential_form / trig_form ------------------------------------------------

def _at(expr, theta_value, d_value, delta_value=0.3):
    """Evaluate an expression in theta, d, delta, Gamma, w, E at a point (40 digits)."""
    with mpmath.workdps(40):
        t = mpmath.mpf(theta_value)
        dl = mpmath.mpf(delta_value)
        values = {theta: t, d: d_value, delta: dl, Gamma: mpmath.exp(dl),
                  w: mpmath.expj(t / 2), E: mpmath.expj(d_value * t)}
        symbols = sorted(expr.free_symbols, key=sp.default_sort_key)
        return sp.lambdify(symbols, expr, modules="mpmath")(*[values[s] for s in symbols])


SAMPLE_POINTS = [(0.37, 0), (1.3, 3), (2.9, 11), (-0.8, 6)]


@pytest.mark.parametrize("expr", [
    sin((2 * d + 3) * theta / 2), cos(d * theta) * sin(half) ** 3, Gamma * cos(3 * theta) - sp.exp(delta),
    sp.tan(theta + d * theta), sp.exp(sp.I * (d + 2) * theta),
])
def test_exponential_form_is_the_same_function(expr):
    form = exponential_form(expr)
    assert not form.has(theta) and not form.has(sp.exp(delta))
    for t, k in SAMPLE_POINTS:
        with mpmath.workdps(40):
            a, b = _at(expr, t, k), _at(form, t, k)
            assert abs(a - b) <= mpmath.mpf(10) ** -32 * (1 + abs(a))


@pytest.mark.parametrize("expr", [
    sin((2 * d + 3) * theta / 2) * Gamma - 3 * cos(d * theta),
    sin(half) ** 5 * cos(half),
    (Gamma**2 + 1 - 2 * Gamma * cos(theta)) * sin(theta) * cos(d * theta + half),
])
def test_trig_form_inverts_exponential_form(expr):
    back = trig_form(exponential_form(expr))
    assert not back.has(w) and not back.has(E) and not back.has(sp.I)
    for t, k in SAMPLE_POINTS:
        with mpmath.workdps(40):
            a, b = _at(expr, t, k), _at(back, t, k)
            assert abs(a - b) <= mpmath.mpf(10) ** -32 * (1 + abs(a))


@pytest.mark.parametrize("expr", [
    theta, theta * sin(theta), sin(theta**2), sp.sqrt(theta), sin(theta / 4), sin(d**2 * theta),
    sin(theta + d), sp.log(theta),
])
def test_exponential_form_rejects_theta_outside_trig(expr):
    with pytest.raises(UnsupportedExpression):
        exponential_form(expr)


def test_unsupported_expression_is_a_value_error():
    assert issubclass(UnsupportedExpression, ValueError)


@pytest.mark.parametrize("expr", [w**2, 1 / (w - 1), sp.I, w**2 + 1 / w**2 + sp.I * E])
def test_trig_form_rejects_non_real_or_non_laurent(expr):
    with pytest.raises(UnsupportedExpression):
        trig_form(expr)


# Property-based: random trigonometric polynomials ---------------------------

_frequency = st.tuples(st.integers(-4, 4), st.integers(-2, 2))        # p theta/2 + q d theta
_coefficient = st.tuples(st.integers(-3, 3).filter(bool), st.integers(0, 2), st.integers(0, 1))


def _term(coef, kind, freq):
    (c, gamma_power, delta_power), (p, q) = coef, freq
    phi = sp.Rational(p, 2) * theta + q * d * theta
    return c * Gamma**gamma_power * delta**delta_power * (sin if kind else cos)(phi)


_terms = st.lists(st.tuples(_coefficient, st.booleans(), _frequency), min_size=1, max_size=5)
_nonzero_term = st.tuples(_coefficient, st.booleans(), _frequency).filter(
    lambda t: not (t[1] and t[2] == (0, 0)))   # sin(0) is zero

_SETTINGS = settings(suppress_health_check=[HealthCheck.too_slow])


def _poly(terms):
    return sp.Add(*[_term(*t) for t in terms])


@_SETTINGS
@given(_terms)
def test_random_trig_polynomial_equals_itself(terms):
    f = _poly(terms)
    assert check_identity(f, f).equal is True


@_SETTINGS
@given(_terms)
def test_random_trig_polynomial_equals_its_expanded_form(terms):
    f = _poly(terms)
    assert check_identity(f, sp.expand_trig(f)).equal is True


@_SETTINGS
@given(_terms, _nonzero_term)
def test_random_trig_polynomial_differs_from_itself_plus_a_term(terms, extra):
    f = _poly(terms)
    result = check_identity(f, f + _term(*extra))
    assert result.equal is False


@_SETTINGS
@given(_terms)
def test_random_trig_polynomial_round_trips_through_exponential_form(terms):
    f = _poly(terms)
    back = trig_form(exponential_form(f))
    for t, k in SAMPLE_POINTS[:2]:
        with mpmath.workdps(40):
            a, b = _at(f, t, k), _at(back, t, k)
            assert abs(a - b) <= mpmath.mpf(10) ** -30 * (1 + abs(a))
