"""Tests of symstab.symbolic.small_theta: the boundary near theta = 0.

Oracle: alpha(theta), beta(theta) solved directly from eq. (2) with eqs. (1)
and (4) (oracles.first_principles_boundary_point) at 80 digits and a tiny
theta, so that alpha / theta^2 and (beta + delta) / theta^2 approximate the
Taylor coefficients to O(theta^2).
"""

import mpmath
import pytest
import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.small_theta import small_theta_limits

from conftest import PAPER_DELTA, assert_rel_close
from oracles import first_principles_boundary_point

THETA = mpmath.mpf("1e-12")

#: (gamma, d, delta)
CASES = [(0.0, 0, PAPER_DELTA), (0.0, 40, PAPER_DELTA), (-0.75, 10, PAPER_DELTA),
         (1.7, 3, 0.2), (-0.5, 0, 0.9), (2.4, 12, 1e-3), (-0.95, 1, 0.01)]


def _subs(expr, gamma, d, delta):
    with mpmath.workdps(60):
        dl = mpmath.mpf(delta)
        f = sp.lambdify((model.gamma, model.d, model.delta, model.Gamma), expr, modules="mpmath")
        return f(mpmath.mpf(gamma), d, dl, mpmath.exp(dl))


def test_alpha_limit_is_zero():
    assert small_theta_limits().alpha_limit == 0


def test_beta_limit_is_minus_delta():
    assert sp.simplify(small_theta_limits().beta_limit + model.delta) == 0


@pytest.mark.parametrize("gamma, d, delta", CASES)
def test_limits_match_eq2_at_tiny_theta(gamma, d, delta):
    """small_theta_limits()'s alpha_limit and beta_limit, evaluated at the case
    (60 digits), against the exact boundary of eq. (2) at theta = 1e-12 (80
    digits): the boundary is within O(theta^2) = 1e-24 (times the Taylor
    coefficient, below 1e4 in every case) of its limits."""
    lim = small_theta_limits()
    alpha_limit = _subs(lim.alpha_limit, gamma, d, delta)
    beta_limit = _subs(lim.beta_limit, gamma, d, delta)
    with mpmath.workdps(80):
        alpha, beta = first_principles_boundary_point(THETA, gamma, d, delta)
        assert abs(alpha - alpha_limit) < mpmath.mpf(10) ** -20, ("alpha(0+)", alpha, alpha_limit)
        assert_rel_close(beta_limit, beta, mpmath.mpf(10) ** -18, "beta(0+)")


@pytest.mark.parametrize("gamma, d, delta", CASES)
def test_alpha_theta2_matches_eq2(gamma, d, delta):
    lim = small_theta_limits()
    with mpmath.workdps(80):
        alpha, _ = first_principles_boundary_point(THETA, gamma, d, delta)
        expected = alpha / THETA**2
    assert_rel_close(_subs(lim.alpha_theta2, gamma, d, delta), expected, mpmath.mpf(10) ** -15,
                     "alpha_theta2")


@pytest.mark.parametrize("gamma, d, delta", CASES)
def test_beta_theta2_and_start_slope_match_eq2(gamma, d, delta):
    lim = small_theta_limits()
    with mpmath.workdps(80):
        alpha, beta = first_principles_boundary_point(THETA, gamma, d, delta)
        a2 = alpha / THETA**2
        b2 = (beta + mpmath.mpf(delta)) / THETA**2
    assert_rel_close(_subs(lim.beta_theta2, gamma, d, delta), b2, mpmath.mpf(10) ** -15, "beta_theta2")
    assert_rel_close(_subs(lim.start_slope, gamma, d, delta), a2 / b2, mpmath.mpf(10) ** -15,
                     "start_slope")


def test_alpha_theta2_finite_difference_is_not_a_fluke():
    # Richardson check of the oracle itself: alpha/theta^2 at 1e-12 and 2e-12 agree.
    with mpmath.workdps(80):
        a1 = first_principles_boundary_point(THETA, 0.3, 5, 0.05)[0] / THETA**2
        a2 = first_principles_boundary_point(2 * THETA, 0.3, 5, 0.05)[0] / (2 * THETA) ** 2
        assert_rel_close(a1, a2, mpmath.mpf(10) ** -20, "alpha/theta^2")


@pytest.mark.parametrize("d, delta", [(0, PAPER_DELTA), (4, 0.05), (20, 1e-3)])
@pytest.mark.parametrize("offset", [-0.05, -0.001, 0.001, 0.05])
def test_alpha_sign_condition_predicts_sign_of_alpha_near_zero(d, delta, offset):
    """Around the gamma where the condition flips, it must agree with alpha's sign."""
    lim = small_theta_limits()
    # Locate where alpha_theta2 vanishes with a root-finder on the oracle alpha / theta^2.
    with mpmath.workdps(60):
        def a2(g):
            return first_principles_boundary_point(mpmath.mpf("1e-9"), g, d, delta)[0] / mpmath.mpf("1e-18")

        gamma_star = mpmath.findroot(a2, (mpmath.mpf(-3), mpmath.mpf(0)), solver="anderson")
        gamma = gamma_star + offset
        alpha, _ = first_principles_boundary_point(mpmath.mpf("1e-6"), gamma, d, delta)
    holds = lim.alpha_sign_condition.subs({model.gamma: sp.Float(str(gamma), 40), model.d: d,
                                           model.delta: sp.Float(delta, 40),
                                           model.Gamma: sp.exp(sp.Float(delta, 40))})
    assert bool(holds) is bool(alpha > 0)


# The Taylor coefficients are read from trigonometric Taylor polynomials
# (symstab.symbolic.small_theta._trig_taylor) instead of sympy.series; sympy.series is
# the oracle for both the fast path and its fallback.
_t, _d, _g = model.theta, model.d, model.Gamma


@pytest.mark.parametrize("expr, fast", [
    (_g * sp.sin((_d + 2) * _t) - 3 * sp.cos(_d * _t) + _d**2 * sp.sin(2 * _t)**2, True),
    (sp.cos(_t) * sp.sin(_d * _t - _t) / (_g - 1) + sp.exp(model.delta), True),
    (sp.sin(model.delta) * sp.sin(_t) + sp.cos(2), True),   # constants stay as they are
    (sp.sin(_t + 1) + sp.cos(_d * _t), False),    # not c * theta: falls back
    (sp.exp(_t) * sp.sin(_t), False),             # another function of theta
    (sp.sin(_d * _t) / _t + sp.cos(_t), True),    # not a polynomial after all: falls back
])
def test_taylor_coefficients_equal_sympy_series(expr, fast):
    from symstab.symbolic.small_theta import _trig_taylor, taylor_coefficients

    order = 5
    assert (_trig_taylor(expr, order) is not None) is fast
    series = sp.expand(sp.series(expr, _t, 0, order + 1).removeO())
    expected = [series.coeff(_t, k) for k in range(order + 1)]
    got = taylor_coefficients(expr, order)
    assert [sp.simplify(a - b) for a, b in zip(got, expected, strict=True)] == [0] * (order + 1)


def test_boundary_forms_take_the_fast_path():
    from symstab.symbolic.boundary import boundary
    from symstab.symbolic.small_theta import _trig_taylor

    bd = boundary()
    for expr in (bd.alpha_numerator, bd.beta_numerator, bd.denominator):
        assert _trig_taylor(expr, 5) is not None


def test_quotient_series_against_sympy_series():
    from symstab.symbolic.small_theta import _quotient_series

    x = sp.Symbol("x")
    num = [0, _g, 2, -_d, 1, 0]
    den = [0, _g - 1, _d, 0, 3, 1]
    n = sp.Add(*[c * x**k for k, c in enumerate(num)])
    dd = sp.Add(*[c * x**k for k, c in enumerate(den)])
    series = sp.expand(sp.series(n / dd, x, 0, 4).removeO())
    got = _quotient_series(num, den, 4)
    assert len(got) == 4
    assert [sp.simplify(q - series.coeff(x, k)) for k, q in enumerate(got)] == [0] * 4
    with pytest.raises(AssertionError, match="pole"):
        _quotient_series([1, 0, 0], [0, 1, 0], 2)
