"""Tests of symstab.symbolic.loop: the closed-loop characteristic polynomial.

The main oracle is python-control: the physical loop of Fig. 2 built from
``control.c2d`` and ``control.feedback`` must have the same poles as the
derived dimensionless polynomial.
"""

import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy.optimize import linear_sum_assignment

from symstab.symbolic import model

from conftest import assert_message_names, assert_rel_close
from oracles import (
    delta_of_z,
    dimensionless,
    loop_coefficients_mp,
    python_control_closed_loop,
    random_loop_points,
)

alpha, beta, gamma, delta, Gamma, z = (model.alpha, model.beta, model.gamma, model.delta,
                                       model.Gamma, model.z)

POINTS = random_loop_points(seed=20250611, n=60)
# numeric_coeffs evaluates the expanded coefficients in floating point, which
# cancels like (Gamma delta - Gamma + 1) ~ -delta^2/2: relative error ~ eps/delta^2.
# Its python-control comparison therefore starts at delta = 1e-3; below that see
# test_numeric_coeffs_loses_accuracy_for_small_delta.
POINTS_NUMERIC = random_loop_points(seed=20250612, n=60, delta_range=(1e-3, 1.0))


def _exact_coefficients(point):
    """The derived polynomial at a point, evaluated at 30 digits, as floats."""
    with mpmath.workdps(30):
        return np.array([float(c) for c in loop_coefficients_mp(**dimensionless(point))])


def _control_poles(point):
    return python_control_closed_loop(**point).poles()


def _spectral_radius(roots):
    return float(np.max(np.abs(roots)))


def _point_id(point):
    return "d={d}-delta={delta:.2e}-gamma={gamma:.2f}".format(**point)


# python-control oracle ---------------------------------------------------

@pytest.mark.parametrize("point", POINTS, ids=[_point_id(p) for p in POINTS])
def test_spectral_radius_matches_python_control(point):
    """Derived chi (evaluated exactly) vs python-control, delta in [1e-4, 1]."""
    roots = np.roots(_exact_coefficients(point))
    assert len(roots) == point["d"] + 4
    assert_rel_close(_spectral_radius(roots), _spectral_radius(_control_poles(point)), 1e-8,
                     "spectral radius")


@pytest.mark.parametrize("point", POINTS_NUMERIC, ids=[_point_id(p) for p in POINTS_NUMERIC])
def test_numeric_coeffs_spectral_radius_matches_python_control(loop, point):
    coeffs = loop.numeric_coeffs(**dimensionless(point))
    assert_rel_close(_spectral_radius(np.roots(coeffs)), _spectral_radius(_control_poles(point)),
                     1e-8, "spectral radius")


def _root_condition_numbers(coeffs, roots):
    """kappa(r) = sum |c_k| |r|^k / (|r| |chi'(r)|): relative sensitivity of r."""
    powers = np.arange(len(coeffs))[::-1]
    deriv = np.polyder(coeffs)
    return np.array([np.sum(np.abs(coeffs) * np.abs(r) ** powers) / (abs(r) * abs(np.polyval(deriv, r)))
                     for r in roots])


@pytest.mark.parametrize("point", POINTS[:30], ids=[_point_id(p) for p in POINTS[:30]])
def test_every_well_conditioned_root_matches_python_control(point):
    coeffs = _exact_coefficients(point)
    roots = np.roots(coeffs)
    poles = _control_poles(point)
    # A loop that is not minimal (VE(z) over more powers of z than T^2 z^2) would
    # carry extra poles at exactly z = 0: any pole beyond chi's roots must be one.
    extra = np.abs(poles) == 0
    assert extra.sum() == len(poles) - len(roots)
    poles = poles[~extra]
    cost = np.abs(poles[:, None] - roots[None, :])
    rows, cols = linear_sum_assignment(cost)
    kappa = _root_condition_numbers(coeffs, roots)
    checked = 0
    for i, j in zip(rows, cols, strict=True):
        # A root with condition number kappa moves by ~kappa * 1e-16 relative
        # under rounding of the coefficients; compare those up to kappa = 1e4.
        if kappa[j] < 1e4:
            checked += 1
            assert cost[i, j] <= 1e-8 * max(1.0, abs(roots[j])), (roots[j], poles[i], kappa[j])
    assert checked >= 2


def test_closed_loop_degree_is_d_plus_4(loop):
    for d in (0, 1, 7):
        point = dict(alpha=1.0, beta=0.5, gamma=0.3, d=d, delta=0.01, m=0.05, T=1e-3)
        poles = _control_poles(point)
        assert np.count_nonzero(poles) == d + 4 == len(loop.coeffs(d)) - 1


@pytest.mark.parametrize("delta_value", [1e-4, 1e-5])
def test_numeric_coeffs_loses_accuracy_for_small_delta(loop, delta_value):
    point = dict(alpha=0.5, beta=0.2, gamma=0.3, d=2, delta=delta_value)
    with mpmath.workdps(30):
        exact = loop_coefficients_mp(**point)
    numeric = loop.numeric_coeffs(**point)
    for e, x in zip(exact, numeric, strict=True):
        assert abs(x - float(e)) <= 1e-12 * abs(float(e)), (float(e), x)


SMALL_DELTA_POINT = dict(alpha=0.5, beta=0.2, gamma=0.3, d=2, m=0.05, T=1e-3)


@pytest.mark.parametrize("delta_value", [1e-5, 1e-6])
def test_exact_spectral_radius_small_delta_matches_python_control(delta_value):
    point = dict(SMALL_DELTA_POINT, delta=delta_value)
    assert_rel_close(_spectral_radius(np.roots(_exact_coefficients(point))),
                     _spectral_radius(_control_poles(point)), 1e-10, "spectral radius")


@pytest.mark.parametrize("delta_value", [1e-5, 1e-6])
def test_numeric_coeffs_spectral_radius_small_delta(loop, delta_value):
    point = dict(SMALL_DELTA_POINT, delta=delta_value)
    reference = _spectral_radius(_control_poles(point))
    assert_rel_close(_spectral_radius(np.roots(loop.numeric_coeffs(**dimensionless(point)))),
                     reference, 1e-8, "numeric_coeffs")


# First principles ------------------------------------------------------

@pytest.mark.parametrize("d", [0, 1, 2, 5])
def test_chi_is_eq2_cleared_of_denominators(loop, d):
    """chi(z) = Gamma delta^2 (z - 1)(z - 1/Gamma) z^(d+2) Delta(z), Delta from eqs. (1), (2), (4)."""
    point = dict(alpha="0.7", beta="-0.4", gamma="1.3", delta="0.05")
    with mpmath.workdps(40):
        p = {k: mpmath.mpf(v) for k, v in point.items()}
        G = mpmath.exp(p["delta"])
        coeffs = loop_coefficients_mp(**p, d=d)
        for zz in (mpmath.mpc(0.3, 0.8), mpmath.mpc(-1.1, 0.2), mpmath.mpf(2.5)):
            chi = mpmath.polyval(coeffs, zz)
            expected = (G * p["delta"] ** 2 * (zz - 1) * (zz - 1 / G) * zz ** (d + 2)
                        * delta_of_z(zz, d=d, **p))
            assert_rel_close(chi, expected, mpmath.mpf(10) ** -30, f"z={zz}")


@pytest.mark.parametrize("d", [0, 1, 2, 6])
def test_coeffs_has_d_plus_5_entries_and_equals_as_expr(loop, d):
    coeffs = loop.coeffs(d)
    assert len(coeffs) == d + 5
    expr = sp.expand(loop.as_expr().subs(model.d, d))
    assert sp.Poly(expr, z).all_coeffs() == [sp.expand(c) for c in coeffs]


def test_coeffs_leading_coefficient_is_nonzero(loop):
    for d in (0, 3):
        assert sp.simplify(loop.coeffs(d)[0] - Gamma * delta**2) == 0


def test_chi_is_affine_in_alpha_beta_gamma(loop):
    for _, c in loop.terms():
        assert sp.Poly(c, alpha, beta, gamma).total_degree() <= 1, c


def test_printed_eq5_is_not_affine(loop):
    """Eq. (5)'s z^2 and z coefficients hold alpha*gamma terms; the derived ones cannot."""
    printed_z2 = -(alpha * (1 + delta - Gamma * (1 - 2 * gamma)) + beta * (Gamma * (gamma - 2) + delta)
                   + gamma * (3 * (1 - Gamma) + delta) + 2 * delta)
    printed_z1 = alpha * gamma * Gamma + beta * (gamma - Gamma) + gamma * (3 * (1 - Gamma) + 2 * delta) + delta
    derived = dict((e, c) for e, c in loop.terms())
    for printed, power in ((printed_z2, 2), (printed_z1, 1)):
        assert sp.Poly(printed, alpha, gamma).coeff_monomial(alpha * gamma) != 0
        assert sp.Poly(derived[power], alpha, gamma).coeff_monomial(alpha * gamma) == 0


@pytest.mark.parametrize("d", [0, 1, 4])
def test_open_loop_roots_at_zero_gains(loop, d):
    """alpha = beta = gamma = 0: roots 0 (d + 2 times), 1 and exp(-delta)."""
    coeffs = [sp.expand(c.subs({alpha: 0, beta: 0, gamma: 0})) for c in loop.coeffs(d)]
    roots = sp.roots(sp.Poly(coeffs, z))
    assert roots == {sp.S.Zero: d + 2, sp.S.One: 1, 1 / Gamma: 1}


def test_terms_exponents_are_symbolic_in_d(loop):
    exponents = [e for e, _ in loop.terms()]
    assert exponents[:3] == [model.d + 4, model.d + 3, model.d + 2]
    assert exponents[3:] == [3, 2, 1, 0]


# numeric_coeffs input checks --------------------------------------------

_GOOD = dict(alpha=1.0, beta=0.5, gamma=0.2, d=3, delta=0.01)


@pytest.mark.parametrize("name, value", [
    ("alpha", math.nan), ("beta", math.inf), ("gamma", -math.inf), ("delta", 0.0),
    ("delta", -0.1), ("d", -1), ("d", 2.5),
])
def test_numeric_coeffs_rejects_bad_values_naming_them(loop, name, value):
    with pytest.raises(ValueError) as excinfo:
        loop.numeric_coeffs(**{**_GOOD, name: value})
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("name, value", [("alpha", "1"), ("d", "3"), ("delta", None), ("beta", True)])
def test_numeric_coeffs_rejects_wrong_kinds(loop, name, value):
    with pytest.raises(TypeError):
        loop.numeric_coeffs(**{**_GOOD, name: value})


def test_numeric_coeffs_rejects_unknown_keyword(loop):
    with pytest.raises(TypeError):
        loop.numeric_coeffs(**_GOOD, Gamma=1.0)


@pytest.mark.parametrize("d", [-1, 1.5])
def test_coeffs_rejects_bad_delay(loop, d):
    with pytest.raises(ValueError):
        loop.coeffs(d)
