"""Tests of symstab.numeric.paper.theta_bounds: theta_max certified by interval arithmetic.

Oracles: the paper's own eqs. (1), (2), (4) at 40 digits
(``oracles.first_principles_alpha``), whose sign must be + at ``lo`` and -
at ``hi`` -- independent of the reduced equation both modules share.  The
30-digit :func:`symstab.symbolic.theta_max.theta_max` is compared too; since
it scans the same reduced equation R (with its own certified step bound), it
is a cross-check of the two implementations, not an independent oracle.
"""

import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from mpmath import iv

from symstab.numeric.paper import theta_bounds
from symstab.numeric.paper.theta_bounds import NotCertified, certify_theta_max, theta_max_enclosure
from symstab.symbolic import model
from symstab.symbolic.small_theta import small_theta_limits
from symstab.symbolic.theta_max import reduced_equation, theta_max

from conftest import PAPER_DELTA, assert_message_names
from oracles import first_principles_alpha


def _sample(seed, n):
    """Seeded (gamma, d, delta) in the box of issue 12: gamma in [-1, 3], d in 0..200, delta in [1e-6, 1]."""
    rng = np.random.default_rng(seed)
    points = []
    for _ in range(n):
        delta = float(10 ** rng.uniform(-6, 0))
        d = int(rng.choice([int(rng.integers(0, 13)), int(rng.integers(0, 201))]))
        gamma = float(rng.uniform(-1, 3))
        points.append((gamma, d, delta))
    return points


SAMPLE = _sample(12, 14) + [(-1.0, 0, 1e-6), (3.0, 200, 1e-6), (-1.0, 200, 1.0), (0.0, 40, PAPER_DELTA)]


def _alpha(theta, gamma, d, delta):
    with mpmath.workdps(40):
        return first_principles_alpha(mpmath.mpf(theta), gamma, d, delta)


@pytest.mark.parametrize("gamma, d, delta", SAMPLE)
def test_enclosure_holds_the_30_digit_theta_max(gamma, d, delta):
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    assert box.lo < box.hi
    assert box.width <= 1e-10 * box.lo, box
    assert theta_max(gamma=gamma, d=d, delta=delta) in box
    # The paper's own alpha changes sign across the box.
    assert _alpha(box.lo, gamma, d, delta) > 0
    assert _alpha(box.hi, gamma, d, delta) < 0


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 40, PAPER_DELTA), (2.2, 7, 1e-3)])
def test_alpha_is_positive_before_the_enclosure(gamma, d, delta):
    """The first root: the oracle's alpha > 0 on a fine grid of (0, lo)."""
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    for k in range(1, 100):
        assert _alpha(box.lo * k / 100, gamma, d, delta) > 0, k


@pytest.mark.parametrize("gamma, delta, root", [(1000.0, 0.5, None), (1e6, 1e-6, 3.1395926)])
def test_enclosure_near_pi(gamma, delta, root):
    """d = 0 and a heavy virtual mass: the arc runs to pi, or ends in the last 1/400 of it.

    Both are cases the 30-digit scan gets wrong (it returns pi * 399/400 for the
    first and pi for the second); the paper's alpha decides them.
    """
    box = theta_max_enclosure(gamma=gamma, d=0, delta=delta)
    if root is None:
        assert math.pi in box
        for t in (3.13, 3.1337, 3.14, 3.1415):
            assert _alpha(t, gamma, 0, delta) > 0
    else:
        assert abs(box.mid - root) < 1e-6
        assert _alpha(box.lo, gamma, 0, delta) > 0 > _alpha(box.hi, gamma, 0, delta)
        assert _alpha(3.139, gamma, 0, delta) > 0


def test_a_narrow_first_dip_is_found():
    """alpha < 0 only on ~1e-4 rad near 1.7662: narrower than a sampling scan's step (~1e-3 at d = 200).

    The 30-digit scan returns the next root, 1.7961; the enclosure must hold
    the first one, where the paper's alpha turns negative.
    """
    gamma, d, delta = 2.4818442699578145, 200, 0.007024254262425767
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    assert 1.76617 < box.lo < box.hi < 1.76619
    assert _alpha(box.lo, gamma, d, delta) > 0 > _alpha(box.hi, gamma, d, delta)
    assert _alpha(1.7662, gamma, d, delta) < 0 < _alpha(1.7663, gamma, d, delta)


@pytest.mark.parametrize("gamma, lobe", [(2.4819247598228142, (1.7662, 1.7663)),
                                         (2.4819247598228147, (1.7961, 1.7962))])
def test_both_sides_of_a_jump_are_certified(gamma, lobe):
    """Adjacent floats of gamma on either side of where the first dip stops reaching alpha < 0."""
    d, delta = 200, 0.007024254262425767
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    assert lobe[0] < box.lo < box.hi < lobe[1]
    assert _alpha(box.lo, gamma, d, delta) > 0 > _alpha(box.hi, gamma, d, delta)


@pytest.mark.parametrize("delta", [1e-20, 1e-50, 1e-300, 5e-324])
@pytest.mark.parametrize("gamma, d, limit", [
    # delta -> 0: R / sin(theta) -> gamma (1 + cos theta)/2 + cos((d + 1) theta), whose first
    # root is arccos((sqrt(17) - 1)/8) for gamma = 1, d = 1 and pi / (2 (d + 1)) for gamma = 0;
    # theta_max moves by O(delta) from it, far below the box's width.
    (1.0, 1, lambda: mpmath.acos((mpmath.sqrt(17) - 1) / 8)),
    (0.0, 40, lambda: mpmath.pi / 82),
])
def test_tiny_damping_is_certified(gamma, d, limit, delta):
    # q, r from Gamma = exp(delta) cancel 3 log10(1/delta) digits: at 40 digits
    # delta = 1e-50 divided by Gamma - 1 = 0 (ZeroDivisionError) and 1e-20 was NotCertified.
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(30):
        assert box.lo < limit() < box.hi, box
    assert box.width <= 1e-14 * box.lo
    # The paper's alpha at a precision that survives its own cancellation.
    with mpmath.workdps(40 + 3 * round(-math.log10(delta))):
        assert first_principles_alpha(mpmath.mpf(box.lo), gamma, d, delta) > 0
        assert first_principles_alpha(mpmath.mpf(box.hi), gamma, d, delta) < 0


def test_short_arc_is_certified():
    """gamma just above -1 - delta (d + 1): the arc ends near theta = 0."""
    gamma = -1 - PAPER_DELTA * 3 + 1e-6
    box = theta_max_enclosure(gamma=gamma, d=2, delta=PAPER_DELTA)
    assert box.hi < 0.1
    assert _alpha(box.lo, gamma, 2, PAPER_DELTA) > 0 > _alpha(box.hi, gamma, 2, PAPER_DELTA)


def _second_root(gamma, d, delta):
    """The root of alpha after theta_max, from the paper's alpha at 40 digits."""
    first = theta_max(gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(40):
        f = lambda t: first_principles_alpha(t, gamma, d, delta)  # noqa: E731
        return float(mpmath.findroot(f, 3.7 * first))


def test_an_interval_around_a_later_root_is_refused():
    gamma, d, delta = 0.0, 40, PAPER_DELTA
    second = _second_root(gamma, d, delta)
    assert second > 2 * theta_max(gamma=gamma, d=d, delta=delta)
    assert _alpha(second * (1 - 1e-12), gamma, d, delta) * _alpha(second * (1 + 1e-12), gamma, d, delta) < 0
    with pytest.raises(NotCertified, match="first root"):
        certify_theta_max(second * (1 - 1e-12), second * (1 + 1e-12), gamma=gamma, d=d, delta=delta)


@pytest.mark.parametrize("shift", [(1.001, 1.002), (0.998, 0.999), (0.5, 0.9)])
def test_an_interval_without_the_root_is_refused(shift):
    gamma, d, delta = 0.5, 10, 0.01
    top = theta_max(gamma=gamma, d=d, delta=delta)
    with pytest.raises(NotCertified):
        certify_theta_max(top * shift[0], top * shift[1], gamma=gamma, d=d, delta=delta)


def test_a_proposed_interval_that_is_right_is_accepted():
    gamma, d, delta = 0.5, 10, 0.01
    top = theta_max(gamma=gamma, d=d, delta=delta)
    box = certify_theta_max(top * (1 - 1e-9), top * (1 + 1e-9), gamma=gamma, d=d, delta=delta)
    assert top in box and box.pieces >= 1


@pytest.mark.parametrize("gamma, d, delta", [(-1.5, 0, PAPER_DELTA), (-1.0 - 11 * 0.01, 10, 0.01),
                                             (-3.0, 5, 0.1)])
def test_no_arc_is_a_value_error(gamma, d, delta):
    with pytest.raises(ValueError) as excinfo:
        theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    assert_message_names(excinfo, "gamma")


@pytest.mark.parametrize("kwargs, name, kind", [
    (dict(gamma=0.0, d=-1, delta=0.1), "d", ValueError),
    (dict(gamma=0.0, d=2.5, delta=0.1), "d", ValueError),
    (dict(gamma=0.0, d=1, delta=0.0), "delta", ValueError),
    (dict(gamma=float("nan"), d=1, delta=0.1), "gamma", ValueError),
    (dict(gamma="1", d=1, delta=0.1), "gamma", TypeError),
])
def test_bad_loop_parameters_are_refused(kwargs, name, kind):
    with pytest.raises(kind) as excinfo:
        theta_max_enclosure(**kwargs)
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("lo, hi, name", [(0.0, 0.1, "lo"), (3.2, 3.3, "lo"), (0.2, 0.1, "hi"),
                                          (0.1, float("inf"), "hi")])
def test_bad_candidate_bounds_are_refused(lo, hi, name):
    with pytest.raises(ValueError) as excinfo:
        certify_theta_max(lo, hi, gamma=0.0, d=1, delta=0.1)
    assert_message_names(excinfo, name)


def test_reduced_equation_starts_with_the_arc_condition():
    """R'(0) = gamma + 1 + delta (d + 1): the small-theta condition of small_theta.py."""
    condition = small_theta_limits().alpha_sign_condition
    assert sp.expand(condition.lhs - reduced_equation().slope0) == 0


@pytest.mark.parametrize("theta, gamma, d, delta", [(0.3, 0.5, 3, 0.01), (2.9, -0.7, 0, 0.9),
                                                    (0.01, 2.0, 150, 1e-6), (1.2, 3.0, 40, 1.0)])
def test_interval_forms_hold_the_derived_r_and_its_slope(theta, gamma, d, delta):
    """The proof's hand-written R and R' enclose the derivation's R and dR/dtheta (40 digits)."""
    eq = reduced_equation()
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    R = sp.lambdify(args, eq.R, modules="mpmath")
    dR = sp.lambdify(args, sp.diff(eq.R, model.theta), modules="mpmath")
    old = iv.prec
    iv.prec = 170
    try:
        reduced = theta_bounds._Reduced(gamma, d, delta)
        value, slope = reduced.value(iv.mpf(theta)), reduced.slope(iv.mpf(theta))
    finally:
        iv.prec = old
    with mpmath.workdps(60):
        # theta as an mpf: a float theta times (d + 1) would round in Python.
        t, dl = mpmath.mpf(theta), mpmath.mpf(delta)
        for interval, exact in ((value, R(t, gamma, d, dl, mpmath.exp(dl))),
                                (slope, dR(t, gamma, d, dl, mpmath.exp(dl)))):
            # The endpoints as exact binary numbers (comparing an interval
            # number would round the reference at the interval context's
            # current precision).
            lo, hi = (mpmath.mpf(end) for end in interval._mpi_)
            assert lo <= exact <= hi
            assert hi - lo <= mpmath.mpf(10) ** -25 * abs(exact)
