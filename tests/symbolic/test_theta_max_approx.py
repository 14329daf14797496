"""Tests of the reduced equation, its phase form, and theta_max_approx.

Oracles: the paper's eqs. (1), (2), (4) at 40 digits
(``oracles.first_principles_alpha``: its sign is the sign of the reduced R)
and the 30-digit scan :func:`symstab.symbolic.theta_max.theta_max` (the first
root, against which the stated error bound of theta_max_approx is held).
"""

import math

import mpmath
import numpy as np
import pytest
import sympy as sp

from symstab.numeric.paper.theta_bounds import APPROX_WORST_RELATIVE_ERROR, theta_max_approx
from symstab.symbolic import model
from symstab.symbolic.theta_max import (
    alpha_numerator_function,
    phase_equation,
    q_sym,
    r_sym,
    reduced_equation,
    theta_max,
    theta_max_newton,
)

from conftest import PAPER_DELTA, assert_message_names
from oracles import first_principles_alpha

#: The box of issue 12 over which the bound was measured.
CORNERS = [(g, d, dl) for g in (-1.0, 3.0) for d in (0, 200) for dl in (1e-6, 1.0)]


def _sample(seed, n):
    rng = np.random.default_rng(seed)
    points = []
    for _ in range(n):
        d = int(rng.integers(0, 6)) if rng.random() < 0.3 else int(rng.integers(0, 201))
        points.append((float(rng.uniform(-1, 3)), d, float(10 ** rng.uniform(-6, 0))))
    return points


def _reduced_mp():
    eq = reduced_equation()
    return sp.lambdify((model.theta, model.gamma, model.d, model.delta, model.Gamma), eq.R,
                       modules="mpmath")


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 40, PAPER_DELTA), (-0.9, 3, 1e-5), (2.5, 120, 0.7),
                                             (1.2, 0, 0.02)])
def test_reduced_equation_has_the_sign_of_the_papers_alpha(gamma, d, delta):
    """R > 0 exactly where the first-principles alpha > 0, on a grid of (0, pi)."""
    R = _reduced_mp()
    with mpmath.workdps(40):
        dl = mpmath.mpf(delta)
        for k in range(1, 60):
            t = mpmath.pi * k / 60 + mpmath.mpf("1e-3")
            r_value = R(t, gamma, d, dl, mpmath.exp(dl))
            alpha = first_principles_alpha(t, gamma, d, delta)
            assert (r_value > 0) == (alpha > 0), (k, r_value, alpha)


def test_reduced_equation_times_its_factors_is_n_alpha():
    eq = reduced_equation()
    scale = sp.lambdify((model.delta, model.Gamma), eq.scale, modules="mpmath")
    R, N = _reduced_mp(), alpha_numerator_function()
    # N_alpha cancels about 20 digits at theta = 0.01, delta = 1e-4: 60 digits.
    with mpmath.workdps(60):
        for theta, gamma, d, delta in [(0.3, 0.5, 3, 0.01), (2.9, -0.7, 0, 0.9), (0.01, 2.0, 150, 1e-4)]:
            t, dl = mpmath.mpf(theta), mpmath.mpf(delta)
            G = mpmath.exp(dl)
            lhs = N(t, gamma, d, dl)
            rhs = scale(dl, G) * (1 - mpmath.cos(t)) * R(t, gamma, d, dl, G)
            assert abs(lhs - rhs) <= mpmath.mpf(10) ** -30 * abs(lhs)


def test_phase_form_is_the_reduced_equation_at_numbers():
    eq, ph = reduced_equation(), phase_equation()
    phi = (model.d + 1) * model.theta
    form = (ph.A * sp.cos(phi) + ph.B * sp.sin(phi) + ph.C).subs({q_sym: eq.q, r_sym: eq.r})
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    f, g = sp.lambdify(args, form, modules="mpmath"), sp.lambdify(args, eq.R, modules="mpmath")
    with mpmath.workdps(40):
        for values in [(0.2, 1.5, 7, 0.3), (3.0, -0.2, 0, 1e-3)]:
            t, dl = mpmath.mpf(values[0]), mpmath.mpf(values[3])
            a = f(t, values[1], values[2], dl, mpmath.exp(dl))
            b = g(t, values[1], values[2], dl, mpmath.exp(dl))
            assert abs(a - b) <= mpmath.mpf(10) ** -30 * abs(b)


#: The seeded sample, the paper's device, and the benchmark's worst point (where
#: 6 Newton steps instead of 8 left 6e-11).
SAMPLE = CORNERS + _sample(7, 16) + [(0.0, 40, PAPER_DELTA), (2.5, 1, 0.3), (3.0, 200, 1e-6),
                                     (2.0687057548855345, 2, 0.8613678167788827)]


@pytest.mark.parametrize("gamma, d, delta", SAMPLE)
def test_approx_meets_its_stated_bound(gamma, d, delta):
    """The docstring's worst error holds against the 30-digit first root."""
    exact = theta_max(gamma=gamma, d=d, delta=delta)
    approx = theta_max_approx(gamma=gamma, d=d, delta=delta)
    assert abs(approx - exact) <= APPROX_WORST_RELATIVE_ERROR * exact, (approx, exact)


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 40, PAPER_DELTA), (-1.0, 0, 1e-6), (2.5, 1, 0.3),
                                             (3.0, 200, 1e-6)])
def test_papers_alpha_changes_sign_within_the_bound(gamma, d, delta):
    approx = theta_max_approx(gamma=gamma, d=d, delta=delta)
    margin = 2 * APPROX_WORST_RELATIVE_ERROR
    with mpmath.workdps(40):
        assert first_principles_alpha(mpmath.mpf(approx) * (1 - margin), gamma, d, delta) > 0
        assert first_principles_alpha(mpmath.mpf(approx) * (1 + margin), gamma, d, delta) < 0


def test_approx_beats_the_papers_newton_step_at_d40():
    """Issue 12: the paper's eq. (12) errs by about 0.5 % at d = 40."""
    exact = theta_max(gamma=0.0, d=40, delta=PAPER_DELTA)
    paper = abs(theta_max_newton(d=40, delta=PAPER_DELTA) - exact) / exact
    ours = abs(theta_max_approx(gamma=0.0, d=40, delta=PAPER_DELTA) - exact) / exact
    assert 3e-3 < paper < 1e-2
    assert ours <= APPROX_WORST_RELATIVE_ERROR


def test_no_arc_is_a_value_error():
    with pytest.raises(ValueError) as excinfo:
        theta_max_approx(gamma=-1.5, d=0, delta=0.1)
    assert_message_names(excinfo, "gamma")


@pytest.mark.parametrize("steps, kind", [(0, ValueError), (2.5, TypeError), (True, TypeError)])
def test_bad_steps_are_refused(steps, kind):
    with pytest.raises(kind) as excinfo:
        theta_max_approx(gamma=0.0, d=1, delta=0.1, steps=steps)
    assert_message_names(excinfo, "steps")


def test_approx_is_a_float_in_range():
    value = theta_max_approx(gamma=0.0, d=0, delta=PAPER_DELTA)
    assert isinstance(value, float) and 0 < value <= math.pi
