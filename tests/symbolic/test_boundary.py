"""Tests of symstab.boundary: alpha(theta), beta(theta) and their coefficients."""

import functools

import mpmath
import numpy as np
import pytest
import sympy as sp

from symstab import arc_end_angle
from symstab.symbolic import model
from symstab.symbolic.boundary import (
    ALPHA_MONOMIALS,
    BETA_MONOMIALS,
    DENOMINATOR_MONOMIALS,
    beta_relations,
    boundary,
    coefficients,
)

from conftest import PAPER_DELTA, assert_rel_close
from oracles import (
    boundary_point_mp,
    chi_mp,
    first_principles_boundary_point,
    loop_coefficients_mp,
)

ARGS = (model.theta, model.gamma, model.d, model.delta, model.Gamma)


def _boundary_points(seed, n, per_arc=2):
    """(theta, gamma, d, delta) with theta in (0, theta_max), ``per_arc`` per arc.

    theta_max from the float kernel (:func:`symstab.arc_end_angle`): the points
    only need to lie on the arc, and collection (in every worker) then derives
    nothing; the exact :func:`theta_max` is the subject of test_theta_max.py.
    """
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        gamma = float(rng.uniform(-0.9, 2.5))
        d = int(rng.integers(0, 13))
        delta = float(10 ** rng.uniform(-4, 0))
        top = arc_end_angle(gamma=gamma, d=d, delta=delta)
        out += [(float(top * rng.uniform(0.02, 0.98)), gamma, d, delta) for _ in range(per_arc)]
    return out


POINTS = _boundary_points(11, 15)


@pytest.mark.parametrize("theta, gamma, d, delta", POINTS)
def test_boundary_point_puts_a_root_on_the_unit_circle(theta, gamma, d, delta):
    """chi(exp(j theta)) = 0 at (alpha(theta), beta(theta)), with the loop's coefficients."""
    with mpmath.workdps(40):
        alpha, beta = boundary_point_mp(theta, gamma, d, delta)
        coeffs = loop_coefficients_mp(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        value, size = chi_mp(mpmath.expj(mpmath.mpf(theta)), coeffs)
        assert abs(value) <= mpmath.mpf(10) ** -25 * size, (alpha, beta, value, size)


@pytest.mark.parametrize("theta, gamma, d, delta", POINTS[:15])
def test_boundary_equals_cramer_solution_of_eq2(theta, gamma, d, delta):
    with mpmath.workdps(40):
        alpha, beta = boundary_point_mp(theta, gamma, d, delta)
        ref_alpha, ref_beta = first_principles_boundary_point(theta, gamma, d, delta)
        assert_rel_close(alpha, ref_alpha, mpmath.mpf(10) ** -25, "alpha")
        assert_rel_close(beta, ref_beta, mpmath.mpf(10) ** -25, "beta")


def test_boundary_point_is_not_a_root_off_the_boundary():
    # The check above must be able to fail: move alpha off the boundary.
    theta, gamma, d, delta = POINTS[0]
    with mpmath.workdps(40):
        alpha, beta = boundary_point_mp(theta, gamma, d, delta)
        coeffs = loop_coefficients_mp(alpha=alpha * (1 + mpmath.mpf(10) ** -6), beta=beta,
                                       gamma=gamma, d=d, delta=delta)
        value, size = chi_mp(mpmath.expj(mpmath.mpf(theta)), coeffs)
        assert abs(value) > mpmath.mpf(10) ** -15 * size


@functools.lru_cache(maxsize=None)
def _denominator_function():
    return sp.lambdify(ARGS, boundary().denominator, modules="mpmath")


@pytest.mark.parametrize("delta", [1e-4, PAPER_DELTA, 0.3, 1.0])
def test_denominator_is_numerator_modulus_squared_times_sin(delta):
    """D(theta) = |Gamma N4(e^{j theta})|^2 sin(theta), N4 the numerator of eq. (4)."""
    f = _denominator_function()
    with mpmath.workdps(40):
        dl = mpmath.mpf(delta)
        G = mpmath.exp(dl)
        for k in range(1, 40):
            t = mpmath.pi * k / 40
            zz = mpmath.expj(t)
            # numerator of eq. (4) with m = T = 1, b = delta
            n4 = (mpmath.exp(-dl) - 1 + dl) * zz + 1 - (1 + dl) * mpmath.exp(-dl)
            D = f(t, 0, 3, dl, G)
            assert D > 0
            assert_rel_close(D, abs(G * n4) ** 2 * mpmath.sin(t), mpmath.mpf(10) ** -25, f"theta={t}")


def test_boundary_terms_use_only_named_monomials(bd):
    assert set(bd.alpha_terms) <= set(ALPHA_MONOMIALS)
    assert set(bd.denominator_terms) <= set(DENOMINATOR_MONOMIALS)
    assert set(bd.beta_terms) <= set(BETA_MONOMIALS) | {(1, 0), (1, 2)}


def _numeric_pairs(pairs, seed=3):
    rng = np.random.default_rng(seed)
    with mpmath.workdps(40):
        for key, (lhs, rhs) in pairs.items():
            f = sp.lambdify(ARGS, [sp.sympify(lhs), sp.sympify(rhs)], modules="mpmath")
            for _ in range(5):
                dl = mpmath.mpf(10 ** rng.uniform(-3, 0))
                args = (mpmath.mpf(rng.uniform(0.05, 3.0)), mpmath.mpf(rng.uniform(-1, 2)),
                        int(rng.integers(0, 12)), dl, mpmath.exp(dl))
                a, b = f(*args)
                yield key, a, b


def test_beta_relations_hold_numerically():
    for key, a, b in _numeric_pairs(beta_relations()):
        assert abs(a - b) <= mpmath.mpf(10) ** -30 * (abs(a) + abs(b) + 1), key


def test_numerators_and_denominator_are_the_C_forms(bd):
    """eq. (7): N_alpha = g C1 + g d^2 C2 + g d C3 + d^3 C4 + d^2 C5 etc., numerically."""
    c = coefficients()
    g, dl = model.gamma, model.delta
    pairs = {
        "alpha": (bd.alpha_numerator,
                  g * c["C1"] + g * dl**2 * c["C2"] + g * dl * c["C3"] + dl**3 * c["C4"] + dl**2 * c["C5"]),
        "beta": (bd.beta_numerator,
                 -g * c["C1"] - g * dl**2 * c["C2"] + g * dl * c["C9"] + dl**3 * c["C10"] + dl**2 * c["C11"]),
        "den": (bd.denominator, c["C6"] + dl**2 * c["C7"] + dl * c["C8"]),
        "C1=K1K2": (c["C1"], c["K1"] * c["K2"]),
    }
    for key, a, b in _numeric_pairs(pairs):
        assert abs(a - b) <= mpmath.mpf(10) ** -30 * (abs(a) + abs(b) + 1e-30), key


def test_K2_K3_K4_match_their_definitions_in_the_docstring():
    """K2 = |N|^2/|z-1|^2 at delta = 0 and K3 = delta^2 coefficient of |N|^2 (N of eq. (4) times Gamma)."""
    c = coefficients()
    f = sp.lambdify((model.theta, model.Gamma), [c["K2"], c["K3"]], modules="mpmath")
    with mpmath.workdps(40):
        for t, G in [(0.4, 1.3), (2.0, 2.5), (3.0, 1.01)]:
            t, G = mpmath.mpf(t), mpmath.mpf(G)
            zz = mpmath.expj(t)

            # |Gamma N4|^2, N4 the numerator of eq. (4), e^-delta -> 1/Gamma
            def n2(dl, G=G, zz=zz):
                return abs(G * ((1 / G - 1 + dl) * zz + 1 - (1 + dl) / G)) ** 2

            K2, K3 = f(t, G)
            assert_rel_close(K2, n2(0) / abs(zz - 1) ** 2, mpmath.mpf(10) ** -30, "K2")
            # n2 is quadratic in delta: its delta^2 coefficient by finite differences
            assert_rel_close(K3, (n2(1) - 2 * n2(0) + n2(-1)) / 2, mpmath.mpf(10) ** -30, "K3")

