"""Tests of symstab.theta_max: where a boundary arc ends.

Oracle: the first positive root of alpha(theta) solved from eq. (2) with
eqs. (1) and (4) (oracles.first_principles_theta_max), at 40 digits.
"""

import functools
import math

import mpmath
import numpy as np
import pytest
import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.theta_max import closed_form_d0, theta_max, theta_max_newton

from conftest import PAPER_DELTA, assert_message_names, assert_rel_close
from oracles import first_principles_alpha, first_principles_theta_max, theta_max_box_sample

#: (gamma, d, delta) with an arc that ends before pi.
ARCS = [(0.0, 0, PAPER_DELTA), (-0.5, 0, PAPER_DELTA), (0.0, 5, PAPER_DELTA),
        (-0.75, 10, PAPER_DELTA), (1.0, 1, PAPER_DELTA), (0.4, 3, 0.05), (-0.3, 12, 0.8),
        (2.2, 7, 1e-3), (0.0, 40, PAPER_DELTA)]


@pytest.mark.parametrize("gamma, d, delta", ARCS)
def test_theta_max_is_a_root_of_alpha(gamma, d, delta):
    """alpha changes sign across theta_max within a relative 1e-9 bracket."""
    top = theta_max(gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(40):
        top = mpmath.mpf(top)
        assert first_principles_alpha(top * (1 - mpmath.mpf(1e-9)), gamma, d, delta) > 0
        assert first_principles_alpha(top * (1 + mpmath.mpf(1e-9)), gamma, d, delta) < 0


@pytest.mark.parametrize("gamma, d, delta", ARCS)
def test_theta_max_is_the_first_root(gamma, d, delta):
    """alpha > 0 on a fine grid of (0, theta_max)."""
    top = theta_max(gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(40):
        for k in range(1, 200):
            t = mpmath.mpf(top) * k / 200
            assert first_principles_alpha(t, gamma, d, delta) > 0, t


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, PAPER_DELTA), (0.0, 5, PAPER_DELTA),
                                             (0.4, 3, 0.05), (-0.3, 12, 0.8)])
def test_theta_max_to_double_precision(gamma, d, delta):
    reference = first_principles_theta_max(gamma, d, delta)
    assert_rel_close(theta_max(gamma=gamma, d=d, delta=delta), reference, 1e-13, "theta_max")


@pytest.mark.parametrize("gamma, d, delta", [(-0.9, 0, PAPER_DELTA), (2.0, 1, PAPER_DELTA),
                                             (1.0, 1, PAPER_DELTA)])
def test_theta_max_to_double_precision_with_virtual_mass(gamma, d, delta):
    reference = first_principles_theta_max(gamma, d, delta)
    assert_rel_close(theta_max(gamma=gamma, d=d, delta=delta), reference, 1e-13, "theta_max")


def test_theta_max_of_paper_device_is_1_5725():
    """Section IV-C: theta_max = 1.5725 rad for gamma = 0, d = 0 (printed to 4 decimals)."""
    assert round(theta_max(gamma=0.0, d=0, delta=PAPER_DELTA), 4) == 1.5725


@pytest.mark.parametrize("d", [0, 3])
@pytest.mark.parametrize("gamma", [-1.5, -3.0, -10.0])
def test_theta_max_is_nan_when_no_arc_enters_alpha_positive(gamma, d):
    assert math.isnan(theta_max(gamma=gamma, d=d, delta=PAPER_DELTA))
    with mpmath.workdps(40):  # the oracle agrees: alpha < 0 just after 0
        assert first_principles_alpha(mpmath.mpf("1e-4"), gamma, d, PAPER_DELTA) < 0


def test_theta_max_of_a_short_arc():
    gamma = -1 - PAPER_DELTA + 1e-6
    reference = first_principles_theta_max(gamma, 0, PAPER_DELTA, n=4000)
    assert reference is not None and reference < math.pi / 400
    assert_rel_close(theta_max(gamma=gamma, d=0, delta=PAPER_DELTA), reference, 1e-9, "theta_max")


# The d = 0 closed form ---------------------------------------------------

def _closed_form_mp(gamma, delta):
    f = sp.lambdify((model.gamma, model.delta, model.Gamma), closed_form_d0().theta_max,
                    modules="mpmath")
    dl = mpmath.mpf(delta)
    return f(mpmath.mpf(gamma), dl, mpmath.exp(dl))


def _printed_eq8(gamma, delta):
    """Eqs. (8)-(10) as printed."""
    G = mpmath.exp(delta)
    A = gamma * ((1 - G) ** 2 - delta * (G**2 - 1) + G * delta**2) + G * delta**2 * (1 - G + delta)
    u = -(1 - G) ** 2 * delta**2 * (gamma + 1 + delta) / (2 * A)
    return 2 * mpmath.atan(mpmath.sqrt(u / (2 - u)))


D0_GAMMAS = [-0.85, -0.5, 0.0, 0.5, 1.0, 1.5, 2.1]


@pytest.mark.parametrize("gamma", D0_GAMMAS)
def test_closed_form_d0_equals_theta_max(gamma):
    # rtol 1e-9, not 1e-15: see test_theta_max_to_double_precision_with_virtual_mass.
    with mpmath.workdps(40):
        closed = _closed_form_mp(gamma, PAPER_DELTA)
    assert_rel_close(theta_max(gamma=gamma, d=0, delta=PAPER_DELTA), closed, 1e-9, "theta_max")


@pytest.mark.parametrize("gamma, delta", [(g, PAPER_DELTA) for g in (-0.85, 0.0, 2.1)]
                         + [(-0.5, 0.1), (1.0, 0.7)])
def test_closed_form_d0_is_the_root_of_eq2(gamma, delta):
    with mpmath.workdps(40):
        closed = _closed_form_mp(gamma, delta)
        assert_rel_close(closed, first_principles_theta_max(gamma, 0, delta), mpmath.mpf(10) ** -25,
                         "closed form")


@pytest.mark.parametrize("gamma", D0_GAMMAS)
def test_closed_form_d0_equals_printed_eqs_8_to_10(gamma):
    with mpmath.workdps(40):
        dl = mpmath.mpf(PAPER_DELTA)
        assert_rel_close(_closed_form_mp(gamma, dl), _printed_eq8(mpmath.mpf(gamma), dl),
                         mpmath.mpf(10) ** -30, "eq. (8)")


def test_printed_eq15_gamma0_matches_eq2():
    """Eq. (15) (gamma = 0, d = 0) against the first-principles root."""
    with mpmath.workdps(40):
        dl = mpmath.mpf(PAPER_DELTA)
        G = mpmath.exp(dl)
        x = (G - 1) ** 2 * (1 + dl)
        printed = 2 * mpmath.atan(mpmath.sqrt(x / (4 * G * (G - 1 - dl) - x)))
        assert_rel_close(printed, first_principles_theta_max(0, 0, dl), mpmath.mpf(10) ** -25, "eq. (15)")


# The gamma = 0 Newton form ------------------------------------------------

#: (d, observed relative error bound) for the paper's delta; the Newton step is
#: an approximation whose error grows with d: observed 1.8e-6 (d=0),
#: 1.1e-4 (d=5), 1.4e-3 (d=20), 5.3e-3 (d=40).
NEWTON = [(0, 5e-6), (1, 3e-5), (2, 1e-4), (5, 3e-4), (10, 1e-3), (20, 4e-3), (40, 1.5e-2)]


@pytest.mark.parametrize("d, rtol", NEWTON)
def test_newton_form_is_close_to_exact_for_gamma0(d, rtol):
    reference = first_principles_theta_max(0, d, PAPER_DELTA)
    assert_rel_close(theta_max_newton(d=d, delta=PAPER_DELTA), reference, rtol, "Newton")


def test_newton_form_error_grows_with_d():
    errors = [abs(theta_max_newton(d=d, delta=PAPER_DELTA) - theta_max(gamma=0.0, d=d, delta=PAPER_DELTA))
              / theta_max(gamma=0.0, d=d, delta=PAPER_DELTA) for d in (0, 2, 10, 40)]
    assert errors == sorted(errors)


# Input checks -------------------------------------------------------------

_GOOD = dict(gamma=0.0, d=0, delta=PAPER_DELTA)


@pytest.mark.parametrize("name, value", [
    ("gamma", math.nan), ("gamma", math.inf), ("d", -1), ("d", 2.5), ("delta", 0.0),
    ("delta", -1e-3), ("delta", math.nan),
])
def test_theta_max_rejects_bad_values_naming_them(name, value):
    with pytest.raises(ValueError) as excinfo:
        theta_max(**{**_GOOD, name: value})
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("name, value", [("d", -1), ("d", 2.5), ("delta", 0.0), ("delta", math.inf)])
def test_theta_max_newton_rejects_bad_values_naming_them(name, value):
    kwargs = {"d": 0, "delta": PAPER_DELTA, name: value}
    with pytest.raises(ValueError) as excinfo:
        theta_max_newton(**kwargs)
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("name, value", [("gamma", "0"), ("d", None), ("delta", True)])
def test_theta_max_rejects_wrong_kinds(name, value):
    with pytest.raises(TypeError):
        theta_max(**{**_GOOD, name: value})


def test_theta_max_is_keyword_only():
    with pytest.raises(TypeError):
        theta_max(0.0, 0, PAPER_DELTA)


@pytest.mark.parametrize("delta", [400.0, 710.0, 1e4])
def test_theta_max_at_large_delta_agrees_with_the_float_arc_end(delta):
    """N_alpha grows like exp(2 delta): findroot's value tolerance failed at 710."""
    from symstab import arc_end_angle
    exact = theta_max(gamma=0.5, d=3, delta=delta)
    assert exact == pytest.approx(arc_end_angle(gamma=0.5, d=3, delta=delta), rel=1e-13)


@pytest.mark.parametrize("func", ["theta_max", "boundary_point", "theta_max_newton"])
def test_references_refuse_delta_zero_instead_of_dividing_zero_by_zero(func):
    import symstab
    from symstab.numeric.paper.reference import boundary_point
    calls = {"theta_max": lambda: theta_max(gamma=0.0, d=0, delta=0.0),
             "boundary_point": lambda: boundary_point(0.5, gamma=0.0, d=0, delta=0.0),
             "theta_max_newton": lambda: symstab.theta_max_newton(d=0, delta=0.0)}
    with pytest.raises(ValueError, match="delta must be > 0 for the high-precision reference"):
        calls[func]()


# No root stepped over: the scan isolates with a bound on R'' ------------------
#
# Oracles: the certified interval enclosure (symstab.numeric.paper.theta_bounds,
# its R proved equal to the derivation's in tests/numeric/paper/test_theta_bounds.py)
# and the paper's alpha from eqs. (1), (2), (4) at 40 digits, whose sign must
# be + just below theta_max and - just above.

#: Cases the grid scan got wrong: the arc runs to pi (N(pi) = 0 in the last
#: cell; it returned pi * 399/400), a root inside the last cell (it returned
#: pi), and a dip of alpha below 0 only ~1e-4 rad wide (it returned the next
#: root, 1.7961).
MISSED = [(1000.0, 0, 0.5), (1e6, 0, 1e-6), (2.4818442699578145, 200, 0.007024254262425767)]


@pytest.mark.parametrize("gamma, d, delta", MISSED + theta_max_box_sample(1212, 10))
def test_theta_max_is_the_certified_first_root(gamma, d, delta):
    from symstab.numeric.paper.theta_bounds import theta_max_enclosure
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    top = theta_max(gamma=gamma, d=d, delta=delta)
    assert box.lo <= top <= box.hi, (top, box)
    if box.hi < math.pi:
        with mpmath.workdps(40):
            t = mpmath.mpf(top)
            assert first_principles_alpha(t * (1 - mpmath.mpf(1e-12)), gamma, d, delta) > 0
            assert first_principles_alpha(t * (1 + mpmath.mpf(1e-12)), gamma, d, delta) < 0


def test_a_dip_narrower_than_the_old_grid_step_ends_the_arc():
    """alpha < 0 on about 1e-4 rad around 1.7662 (d = 200: the old step was 1e-3)."""
    gamma, d, delta = MISSED[2]
    assert theta_max(gamma=gamma, d=d, delta=delta) == pytest.approx(1.7661805108331596, rel=1e-15)
    with mpmath.workdps(40):
        assert first_principles_alpha(mpmath.mpf("1.7662"), gamma, d, delta) < 0
        assert first_principles_alpha(mpmath.mpf("1.7663"), gamma, d, delta) > 0


def test_an_arc_that_runs_to_pi_returns_pi():
    gamma, d, delta = MISSED[0]
    assert theta_max(gamma=gamma, d=d, delta=delta) == math.pi
    with mpmath.workdps(40):
        for t in ("3.13", "3.1337", "3.14", "3.1415"):
            assert first_principles_alpha(mpmath.mpf(t), gamma, d, delta) > 0, t


@functools.lru_cache(maxsize=None)   # one differentiation and lambdify per order, not per case
def _reduced_mp(derivative):
    from symstab.symbolic.theta_max import reduced_equation
    eq = reduced_equation()
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    return sp.lambdify(args, sp.diff(eq.R, model.theta, derivative), modules="mpmath")


@pytest.mark.parametrize("gamma, d, delta", [(-1.0, 0, 1e-6), (3.0, 200, 1.0), (0.0, 40, PAPER_DELTA),
                                             (1e6, 0, 1e-6), (-0.5, 7, 30.0), (2.0, 1, 1e4)])
def test_curvature_bound_holds_the_derived_second_derivative(gamma, d, delta):
    """reduced_curvature >= |R''| of the derivation's R, on a fine grid of [0, pi] (40 digits)."""
    from symstab.symbolic.theta_max import reduced_curvature, reduced_qr
    second = _reduced_mp(2)
    q, r = reduced_qr(delta)
    bound = reduced_curvature(gamma, d + 1, delta, q, r)
    with mpmath.workdps(40):
        dl = mpmath.mpf(delta)
        G = mpmath.exp(dl)
        worst = max(abs(second(mpmath.pi * k / 2000, gamma, d, dl, G)) for k in range(2001))
    assert worst <= bound
    assert bound <= 10 * worst      # a bound, not a blanket


@pytest.mark.parametrize("delta", [0.0, 1e-9, 1e-6, 0.0025, 0.3, 1.0, 1.0000001, 2.0, 30.0, 800.0, 1e5])
def test_float_q_r_are_the_derived_ones(delta):
    """The series (delta <= 1) and the exp(-delta) form (delta > 1) against the symbolic q, r at 60 digits."""
    from symstab.symbolic.theta_max import reduced_equation, reduced_qr
    q, r = reduced_qr(delta)
    if delta == 0.0:
        assert (q, r) == (-0.5, 0.0)
        return
    eq = reduced_equation()
    with mpmath.workdps(60):
        dl = mpmath.mpf(delta)
        values = {model.delta: dl, model.Gamma: mpmath.exp(dl)}
        q_exact = sp.lambdify(tuple(values), eq.q, modules="mpmath")(*values.values())
        r_exact = sp.lambdify(tuple(values), eq.r, modules="mpmath")(*values.values())
        assert abs(q - q_exact) <= 4e-16 * abs(q_exact)
        assert abs(r - r_exact) <= 4e-16 * abs(r_exact)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_float_rounding_bounds_hold(seed):
    """The float R, R' lie within the error bounds of reduced_value_slope of the 40-digit ones."""
    from symstab.symbolic.theta_max import reduced_qr, reduced_value_slope
    value, slope = _reduced_mp(0), _reduced_mp(1)
    for gamma, d, delta in theta_max_box_sample(seed, 4) + [(-1.0 - 3e-3 + 1e-9, 2, 1e-3)]:
        q, r = reduced_qr(delta)
        t = np.concatenate([np.geomspace(1e-9, 0.1, 20), np.linspace(0.1, np.pi, 200)])
        v, p, ve, pe = reduced_value_slope(t, gamma, d + 1, delta, q, r, sin=np.sin, cos=np.cos,
                                           eps=np.finfo(float).eps)
        with mpmath.workdps(40):
            dl = mpmath.mpf(delta)
            G = mpmath.exp(dl)
            for k, x in enumerate(t):
                x = mpmath.mpf(x)
                assert abs(v[k] - value(x, gamma, d, dl, G)) <= ve[k], (gamma, d, delta, x)
                assert abs(p[k] - slope(x, gamma, d, dl, G)) <= pe[k], (gamma, d, delta, x)
