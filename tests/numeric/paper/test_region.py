"""Tests of the boundary arc and the stable region: arc_end_angle, boundary_curve,
StabilityRegion, limits, best_virtual_mass and Device.

Oracles:

* ``symstab.theta_max`` (30 digits) and the certified interval enclosure
  ``theta_max_enclosure`` for the float theta_max;
* ``oracles.first_principles_boundary_point``: the boundary solved directly
  from the printed eqs. (1), (2), (4) with mpmath;
* ``symstab.numeric.paper.reference.alpha_max_on_arc`` and ``boundary_point`` (30 digits);
* the area under the arc by Green's theorem, ``A = int alpha dbeta`` along
  the first-principles arc, with ``mpmath.quad`` and ``mpmath.diff``;
* brute-force scans and grids classified point by point, whose edge points
  are checked with the roots of the first-principles polynomial
  (:func:`eq4_chi_float`).

Measured (this revision): arc_end_angle agrees with the 30-digit theta_max to
7.3e-16 relative (worst of the 70 grid cases), and both are nan in the 4
cases without an arc; the curve's points agree with the
first-principles boundary to 2.3e-13 (alpha) and 4.6e-14 (beta); alpha_max
(gamma = 0) agrees with alpha_max_on_arc to 4.4e-16, beta_min with -delta to
2.2e-13, beta_max (gamma = 0, d = 0) with beta(theta_max) to 2e-12, z_width
with the Green's-theorem area to 1.6e-6 .. 2.0e-6 relative (trapezoid rule
on 801 verticals); the 400 x 400 grid for gamma = 1.5, d = 0 agrees with
alpha_max within 0.3 cell, with the beta range within 0.6 cell and with the
area to 0.2 % (0.036 of the edge cells' area).

The sliver at the gamma best_virtual_mass returns for d = 0 (about 2e-7 wide
in alpha) was once missed by the region's probes (alpha_max 2.2e-6 too low);
test_alpha_max_at_the_best_gamma_is_the_top_of_the_region guards it.
"""

import functools
import math
import re

import mpmath
import numpy as np
import pytest

import symstab
from symstab import (
    PAPER_DEVICE,
    STABLE,
    Device,
    StabilityRegion,
    arc_end_angle,
    best_virtual_mass,
    boundary_curve,
    classify,
    limits,
)
from symstab.numeric.paper.reference import alpha_max_on_arc, boundary_point

from conftest import PAPER_DELTA, assert_message_names
from oracles import (
    first_principles_boundary_point,
    first_principles_chi_float,
    first_principles_radius,
    stable_alpha_intervals,
    theta_max_box_sample,
)

#: The first-principles polynomial of eqs. (1), (2), (4) (tests/oracles.py),
#: at 30 digits, rounded once to floats.
eq4_chi_float = first_principles_chi_float


@functools.lru_cache(maxsize=None)
def theta_max_30(gamma, d, delta):
    """symstab.theta_max (30 digits), cached: it costs 0.3 s a call."""
    return symstab.theta_max(gamma=gamma, d=d, delta=delta)


@functools.lru_cache(maxsize=None)
def arc_top_30(gamma, d, delta):
    """symstab.numeric.paper.reference.alpha_max_on_arc (30 digits), cached."""
    return alpha_max_on_arc(gamma=gamma, d=d, delta=delta)


def oracle_radius(alpha, beta, gamma, d, delta):
    """Largest root modulus of the first-principles polynomial (30-digit coefficients)."""
    return float(np.max(np.abs(np.roots(eq4_chi_float(alpha, beta, gamma, d, delta)))))


# --------------------------------------------------------------------------
# arc_end_angle against the 30-digit theta_max
# --------------------------------------------------------------------------

THETA_GRID = [(g, d, dl) for g in (-0.75, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0)
              for d in (0, 1, 5, 10, 40) for dl in (PAPER_DELTA, 0.1)]
#: No arc: 1 + gamma + (d + 1) delta < 0.
NAN_CASES = [(-1.2, 0, PAPER_DELTA), (-1.2, 0, 0.1), (-1.2, 5, PAPER_DELTA), (-1.5, 0, PAPER_DELTA)]


@pytest.mark.parametrize("gamma, d, delta", THETA_GRID + NAN_CASES)
def test_arc_end_angle_matches_30_digit_theta_max(gamma, d, delta):
    got = arc_end_angle(gamma=gamma, d=d, delta=delta)
    expected = theta_max_30(gamma, d, delta)
    assert isinstance(got, float)
    if math.isnan(expected):
        assert math.isnan(got), f"arc_end_angle {got}, theta_max nan"
        assert 1 + gamma + (d + 1) * delta < 0
    else:
        assert abs(got - expected) <= 1e-13 * expected, (got, expected)


#: Where a grid scan goes wrong (see tests/symbolic/test_theta_max.py): the arc
#: runs to pi, a root inside the last cell, and a dip of alpha below 0 only
#: ~1e-4 rad wide, which the float scan stepped over (returning 1.7961).
MISSED = [(1000.0, 0, 0.5), (1e6, 0, 1e-6), (2.4818442699578145, 200, 0.007024254262425767)]


@pytest.mark.parametrize("gamma, d, delta", MISSED + theta_max_box_sample(2012, 12))
def test_arc_end_angle_is_the_certified_first_root(gamma, d, delta):
    """Against the interval enclosure; 1e-12: R in floats at gamma = 1e6 is conditioned to ~5e-14."""
    from symstab.numeric.paper.theta_bounds import theta_max_enclosure
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    got = arc_end_angle(gamma=gamma, d=d, delta=delta)
    assert abs(got - box.mid) <= 1e-12 * box.mid, (got, box)


@pytest.mark.parametrize("segments", [False, True])
def test_boundary_curve_stops_at_a_narrow_first_dip(segments):
    """The arc ends where alpha first reaches 0 (1.76618), not at the next root 1.7961.

    With the straight segments too: their line scan thinned its lines to a
    negative count there, and took the lobe's end from a grid of alpha.
    """
    from oracles import first_principles_alpha
    gamma, d, delta = MISSED[2]
    curve = boundary_curve(gamma=gamma, d=d, delta=delta, n=50, segments=segments)
    assert curve.theta_max == pytest.approx(1.7661805108331596, rel=1e-14)
    assert curve.theta[-1] <= curve.theta_max
    with mpmath.workdps(40):
        assert first_principles_alpha(mpmath.mpf("1.7662"), gamma, d, delta) < 0


@pytest.mark.parametrize("gamma, d, delta", [(-1 - 3 * PAPER_DELTA + 1e-9, 2, PAPER_DELTA),
                                             (-1 - 41 * PAPER_DELTA + 1e-12, 40, PAPER_DELTA)])
def test_arc_end_angle_of_a_very_short_arc(gamma, d, delta):
    """gamma + 1 + delta (d + 1) = 1e-9 and 1e-12: R keeps its relative accuracy near 0.

    The oracle is the interval enclosure (0.06 s here; the 30-digit
    ``symstab.theta_max`` agrees with it to 16 digits but isolates a root
    this close to 0 in about two minutes at d = 40).
    """
    from symstab.numeric.paper.theta_bounds import theta_max_enclosure
    box = theta_max_enclosure(gamma=gamma, d=d, delta=delta)
    assert box.hi < 1e-4 and box.hi - box.lo <= 1e-12 * box.lo
    assert arc_end_angle(gamma=gamma, d=d, delta=delta) == pytest.approx(box.mid, rel=1e-3)


def test_the_nan_cases_give_an_empty_curve_with_a_message():
    for gamma, d, delta in NAN_CASES:
        c = boundary_curve(gamma=gamma, d=d, delta=delta, n=10)
        assert c.empty and math.isnan(c.theta_max)
        assert c.theta.size == c.alpha.size == c.beta.size == 0
        assert isinstance(c.message, str) and c.message
        assert c.segments == ()


# --------------------------------------------------------------------------
# boundary_curve
# --------------------------------------------------------------------------

CURVE_CASES = [(0.0, 0, PAPER_DELTA), (1.5, 0, PAPER_DELTA), (0.5, 40, PAPER_DELTA),
               (-0.5, 5, 0.1), (2.4, 0, 0.5)]


@pytest.mark.parametrize("gamma, d, delta", CURVE_CASES)
def test_boundary_curve_starts_at_minus_delta_and_ends_on_alpha_zero(gamma, d, delta):
    n = 257
    c = boundary_curve(gamma=gamma, d=d, delta=delta, n=n, segments=False)
    assert not c.empty and c.message == ""
    assert c.theta.shape == c.alpha.shape == c.beta.shape == (n,)
    assert c.theta[0] == 0.0 and c.alpha[0] == 0.0
    assert c.beta[0] == pytest.approx(-delta, rel=1e-15)
    assert c.theta[-1] == c.theta_max
    expected_tmax = theta_max_30(gamma, d, delta)
    assert abs(c.theta_max - expected_tmax) <= 1e-13 * expected_tmax
    assert np.all(np.diff(c.theta) > 0)
    assert c.alpha[-1] == 0.0
    assert np.all(c.alpha[1:-1] > 0), "alpha(theta) > 0 strictly inside (0, theta_max)"
    # theta_max is a root of the first-principles alpha(theta): the Newton
    # correction alpha / alpha' there is within 1e-13 of theta_max.
    with mpmath.workdps(30):
        f = lambda t: first_principles_boundary_point(t, gamma, d, delta)[0]  # noqa: E731
        tm = mpmath.mpf(c.theta_max)
        correction = f(tm) / mpmath.diff(f, tm)
        assert abs(correction) <= 1e-13 * tm, mpmath.nstr(correction, 5)
        # and the arc's first point after 0 rises into alpha > 0 as eq. (2) says
        assert f(mpmath.mpf(c.theta[1])) > 0


@pytest.mark.parametrize("gamma, d, delta", CURVE_CASES)
def test_boundary_curve_points_lie_on_the_first_principles_boundary(gamma, d, delta):
    n = 2001
    c = boundary_curve(gamma=gamma, d=d, delta=delta, n=n, segments=False)
    with mpmath.workdps(30):
        for k in (1, 7, 50, n // 4, n // 2, 3 * n // 4, n - 50, n - 2):
            a, b = first_principles_boundary_point(c.theta[k], gamma, d, delta)
            assert abs(c.alpha[k] - a) <= 1e-10 * abs(a), (k, c.alpha[k], mpmath.nstr(a, 17))
            assert abs(c.beta[k] - b) <= 1e-10 * abs(b), (k, c.beta[k], mpmath.nstr(b, 17))


def test_boundary_curve_with_1e5_points():
    n = 10**5
    c = boundary_curve(gamma=0.5, d=10, delta=PAPER_DELTA, n=n)
    assert c.theta.shape == c.alpha.shape == c.beta.shape == (n,)
    assert np.all(np.isfinite(c.alpha)) and np.all(np.isfinite(c.beta))
    assert np.all(c.alpha[1:-1] > 0)
    np.testing.assert_allclose(np.diff(c.theta), c.theta_max / (n - 1), rtol=1e-9)
    rng = np.random.default_rng(5)
    with mpmath.workdps(30):
        for k in rng.integers(1, n - 1, 5):
            a, b = first_principles_boundary_point(c.theta[k], 0.5, 10, PAPER_DELTA)
            assert abs(c.alpha[k] - a) <= 1e-10 * abs(a)
            assert abs(c.beta[k] - b) <= 1e-10 * abs(b)


@pytest.mark.parametrize("n, error", [(1, ValueError), (0, ValueError), (-3, ValueError),
                                      (2.5, TypeError), (10.0, TypeError), ("10", TypeError),
                                      (True, TypeError), (None, TypeError)])
def test_boundary_curve_rejects_bad_n(n, error):
    """Wrong kinds are TypeError, wrong values ValueError (the project's convention)."""
    with pytest.raises(error) as excinfo:
        boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=n, segments=False)
    assert_message_names(excinfo, "n")


def test_boundary_curve_accepts_numpy_integer_n():
    c = boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=np.int64(2), segments=False)
    assert c.theta.shape == (2,)


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 0, PAPER_DELTA), (1.5, 0, PAPER_DELTA),
                                             (-0.5, 5, 0.1), (0.5, 200, 1e-4)])
def test_boundary_curve_z1_segment_closes_the_region(gamma, d, delta):
    c = boundary_curve(gamma=gamma, d=d, delta=delta, n=100)
    z1 = [s for s in c.segments if s.root == "z=1"]
    assert len(z1) == 1
    s = z1[0]
    assert s.alpha0 == s.alpha1 == 0.0
    assert s.beta0 == pytest.approx(-delta, rel=1e-12)
    _, b_end = boundary_point(theta_max_30(gamma, d, delta),
                              gamma=gamma, d=d, delta=delta, dps=30)
    assert s.beta1 == pytest.approx(float(b_end), rel=1e-9)
    # Independently: just above alpha = 0 the first-principles loop is stable
    # between the segment's ends and unstable just outside them.
    eps = 1e-7
    width = s.beta1 - s.beta0
    for beta, stable in ((s.beta0 + 0.01 * width, True), (0.5 * (s.beta0 + s.beta1), True),
                         (s.beta1 - 0.01 * width, True), (s.beta0 - 0.01 * width, False),
                         (s.beta1 + 0.01 * width, False)):
        assert (oracle_radius(eps, beta, gamma, d, delta) < 1) == stable, beta


# --------------------------------------------------------------------------
# alpha_intervals against a brute-force scan
# --------------------------------------------------------------------------

#: (gamma, d, delta, beta, starts_at_zero or None for "no interval")
INTERVAL_CASES = [
    (1.5, 0, PAPER_DELTA, -0.5, False),     # Fig. 7, circle 6: a minimum stiffness
    (1.5, 0, PAPER_DELTA, 0.3, True),
    (0.0, 0, PAPER_DELTA, 0.5, True),
    (0.0, 0, PAPER_DELTA, 1.9, True),
    (0.0, 5, PAPER_DELTA, 0.1, True),
    (0.0, 40, PAPER_DELTA, 0.02, True),
    (0.5, 40, PAPER_DELTA, 0.02, True),
    (0.9, 10, 0.05, 0.11, False),
    (0.9, 10, 0.05, 0.1, True),
    (2.0, 0, PAPER_DELTA, -1.9, False),     # the thin gamma = 2 sliver
    (-0.5, 2, 0.3, 0.2, True),
    (0.0, 0, PAPER_DELTA, 2.5, None),       # right of the region
    (0.0, 0, PAPER_DELTA, -0.01, None),     # left of the corner (-delta, 0)
]


@pytest.mark.parametrize("gamma, d, delta, beta, starts_at_zero", INTERVAL_CASES)
def test_alpha_intervals_match_a_brute_force_scan(gamma, d, delta, beta, starts_at_zero):
    runs = StabilityRegion(gamma=gamma, d=d, delta=delta).alpha_intervals(beta)
    _assert_runs_match_a_brute_force_scan(runs, gamma, d, delta, beta, starts_at_zero)


def _assert_runs_match_a_brute_force_scan(runs, gamma, d, delta, beta, starts_at_zero):
    """``runs`` at ``beta`` against 20 001 classified points and first-principles radii."""
    if runs:
        lo, hi = runs[0][0], runs[-1][1]
        width = hi - lo
        grid = np.linspace(lo - 0.25 * width, hi + 0.25 * width, 20001)
    else:
        grid = np.linspace(-0.5, 5.0, 20001)
    step = grid[1] - grid[0]
    stable = np.asarray(classify(alpha=grid, beta=beta, gamma=gamma, d=d, delta=delta)) == STABLE
    edges = np.diff(np.r_[0, stable.astype(np.int8), 0])
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    if starts_at_zero is None:
        assert runs == [] and first.size == 0
        return
    assert len(first) == len(runs), (runs, grid[first], grid[last])
    for (a0, a1), i, j in zip(runs, first, last, strict=True):
        assert a0 < a1
        assert a0 <= grid[i] <= a0 + step and a1 - step <= grid[j] <= a1, ((a0, a1), grid[i], grid[j])
        # the scan's edges, checked with the first-principles roots
        def radius(a):
            return oracle_radius(a, beta, gamma, d, delta)

        assert radius(grid[i]) < 1 < radius(grid[i - 1])
        assert radius(grid[j]) < 1 < radius(grid[j + 1])
    if starts_at_zero:
        assert runs[0][0] == pytest.approx(0.0, abs=1e-15)
    else:
        assert runs[0][0] > 0
    minimum = limits(gamma=gamma, d=d, delta=delta).minimum_stiffness(beta)
    assert minimum == runs[0][0]


#: The cases of INTERVAL_CASES that share a region, grouped: one call per region.
_CASES_BY_REGION = {}
for _case in INTERVAL_CASES:
    _CASES_BY_REGION.setdefault(_case[:3], []).append(_case[3:])


@pytest.mark.parametrize("gamma, d, delta", list(_CASES_BY_REGION))
def test_alpha_intervals_on_many_lines_match_a_brute_force_scan(gamma, d, delta):
    """The lines are found and counted together: each gets its own intervals
    (the lines are given in decreasing order; at gamma = 0, d = 0 two of them
    meet no stable point)."""
    cases = sorted(_CASES_BY_REGION[(gamma, d, delta)], key=lambda c: -c[0])
    region = StabilityRegion(gamma=gamma, d=d, delta=delta)
    runs = region.alpha_intervals_on([beta for beta, _ in cases])
    assert len(runs) == len(cases)
    for r, (beta, starts_at_zero) in zip(runs, cases, strict=True):
        _assert_runs_match_a_brute_force_scan(r, gamma, d, delta, beta, starts_at_zero)


def _arc_point_at_beta(gamma, d, delta, beta, near_alpha):
    """The 40-digit arc point (alpha, beta) of the first principles with this beta, next to near_alpha."""
    from symstab._generated import kernels

    theta = np.linspace(1e-7, np.pi - 1e-7, 200_001)
    alpha_f, beta_f = kernels.boundary(theta, gamma, d, delta)
    g = beta_f - beta
    k = np.flatnonzero(np.isfinite(g[:-1]) & np.isfinite(g[1:]) & (np.sign(g[:-1]) != np.sign(g[1:]))
                       & (np.abs(g[:-1] - g[1:]) < 1.0))          # not a pole
    k = k[np.argmin(np.abs(alpha_f[k] - near_alpha))]
    with mpmath.workdps(40):
        t = mpmath.findroot(lambda t: first_principles_boundary_point(t, gamma, d, delta)[1] - beta,
                            (theta[k], theta[k + 1]), solver="anderson")
        return float(first_principles_boundary_point(t, gamma, d, delta)[0]), float(t)


@pytest.mark.parametrize("gamma, d, delta, betas", [
    (0.5, 40, PAPER_DELTA, [0.001, 0.0076, 0.0208, 0.0405]),
    (0.0, 10, PAPER_DELTA, [0.001, 0.034, 0.067, 0.134])])
def test_interval_ends_keep_the_closed_forms_digits(gamma, d, delta, betas):
    """The top of each stable alpha interval is the arc point on the line, to 1e-13 (40-digit oracle).

    Next to theta = 0 the loop's coefficients cancel (z = 1 is a root of the
    plant's denominator and of the environment's B and M terms) and the
    crossings they give are 1e-12 off (6e-13 at gamma = 0.5, d = 40, theta
    = 0.009); refined on eq. (7)'s closed form they are not.
    """
    runs = StabilityRegion(gamma=gamma, d=d, delta=delta).alpha_intervals_on(betas)
    for beta, r in zip(betas, runs, strict=True):
        top = r[-1][1]
        want, theta = _arc_point_at_beta(gamma, d, delta, beta, top)
        assert top == pytest.approx(want, rel=1e-13, abs=0), (beta, theta)


def test_a_corner_of_the_arc_with_alpha_zero_keeps_its_digits():
    """Where the arc meets alpha = 0 (the z = 1 segment's end at gamma = -1.001, d = 0), to 1e-13.

    The corner is ill-conditioned on the coefficients (alpha is flat there:
    an absolute 1e-16 in alpha moves it by 1.6e-11); on the closed form it
    is not.
    """
    gamma, d, delta = -1.001, 0, PAPER_DELTA
    (segment,) = boundary_curve(gamma=gamma, d=d, delta=delta, n=3).segments
    with mpmath.workdps(40):
        t = mpmath.findroot(lambda t: first_principles_boundary_point(t, gamma, d, delta)[0],
                            (0.07, 0.09), solver="anderson")
        want = float(first_principles_boundary_point(t, gamma, d, delta)[1])
    assert segment.beta1 == pytest.approx(want, rel=1e-13, abs=0)


def test_refit_root_averages_a_rounding_floor_and_leaves_a_curve_alone():
    """A straight f rounded to a quantum: the fitted zero is the true one; a curved f keeps its root.

    f(x) = s (x - r) rounded to q = 2**-60 (as alpha next to the flat corner
    above) is exactly 0 over a stretch q / s wide, where the bracketer
    stops anywhere; the line through values around it has its zero at r.
    Next to a double root, (x - 1)**2 - w**2 is no straight line over the
    fitted stretch, and the bracketed root stays.
    """
    from symstab.numeric.engine.search import bracketed_root, refit_root

    r, s, q = 0.0782554498112388, 2.4e-3, 2.0**-60

    def f(x):
        return q * np.round(s * (np.asarray(x) - r) / q)

    plateau = q / s
    lo, hi = r - 7e-10, r + 3e-10
    found = bracketed_root(f, [lo], [hi])[0]
    assert abs(found - r) > 0.1 * plateau               # somewhere on the stretch of zeros
    assert abs(refit_root(f, found, 1e-3 * (hi - lo)) - r) < 0.01 * plateau

    def g(x):
        return (np.asarray(x) - 1.0) ** 2 - 2e-4 ** 2

    assert refit_root(g, 1.0002, 1e-3) == 1.0002


@pytest.mark.parametrize("betas, error", [
    ([[0.1, 0.2]], ValueError), ([0.1, np.nan], ValueError), (["a"], TypeError), ([True], TypeError)])
def test_alpha_intervals_on_refuses_bad_lines(betas, error):
    with pytest.raises(error, match="betas"):
        StabilityRegion(gamma=0.0, d=0, delta=PAPER_DELTA).alpha_intervals_on(betas)


def test_minimum_stiffness_of_fig7_circle6_is_above_one():
    (lo, hi), = StabilityRegion(gamma=1.5, d=0, delta=PAPER_DELTA).alpha_intervals(-0.5)
    assert 1.0 < lo < hi
    # lo is where the arc crosses beta = -0.5 (the lower edge): a root on the circle
    with mpmath.workdps(30):
        f = lambda t: first_principles_boundary_point(t, 1.5, 0, PAPER_DELTA)[1] + mpmath.mpf("0.5")  # noqa: E731
        grid = [mpmath.mpf(k) / 100 for k in range(1, 300)]
        roots = [mpmath.findroot(f, (a, b), solver="anderson")
                 for a, b in zip(grid[:-1], grid[1:], strict=True) if f(a) * f(b) < 0]
        alphas = sorted(float(first_principles_boundary_point(t, 1.5, 0, PAPER_DELTA)[0]) for t in roots)
    assert min(abs(lo - a) for a in alphas) <= 1e-12 * lo, (lo, alphas)
    assert min(abs(hi - a) for a in alphas) <= 1e-12 * hi, (hi, alphas)


def test_beta_intervals_match_a_brute_force_scan():
    region = StabilityRegion(gamma=1.5, d=0, delta=PAPER_DELTA)
    alpha = 2.0
    runs = region.beta_intervals(alpha)
    assert runs
    lo, hi = runs[0][0], runs[-1][1]
    grid = np.linspace(lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo), 20001)
    step = grid[1] - grid[0]
    stable = np.asarray(classify(alpha=alpha, beta=grid, gamma=1.5, d=0, delta=PAPER_DELTA)) == STABLE
    edges = np.diff(np.r_[0, stable.astype(np.int8), 0])
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    assert len(first) == len(runs)
    for (b0, b1), i, j in zip(runs, first, last, strict=True):
        assert b0 <= grid[i] <= b0 + step and b1 - step <= grid[j] <= b1


# --------------------------------------------------------------------------
# limits
# --------------------------------------------------------------------------

GAMMA0_DELAYS = [0, 1, 5, 10, 40]


@pytest.fixture(scope="module")
def gamma0_limits():
    return {d: limits(gamma=0.0, d=d, delta=PAPER_DELTA) for d in GAMMA0_DELAYS}


@pytest.mark.parametrize("d", GAMMA0_DELAYS)
def test_alpha_max_at_gamma0_is_the_top_of_the_arc(gamma0_limits, d):
    lim = gamma0_limits[d]
    _, a_ref, b_ref = arc_top_30(0.0, d, PAPER_DELTA)
    assert abs(lim.alpha_max - a_ref) <= 1e-9 * a_ref, (lim.alpha_max, a_ref)
    # the arc's top is flat, so its beta is known to about sqrt(1e-16)
    assert abs(lim.beta_at_alpha_max - b_ref) <= 1e-6 * abs(b_ref), (lim.beta_at_alpha_max, b_ref)


BETA_MIN_CASES = [(0.0, d, PAPER_DELTA) for d in GAMMA0_DELAYS] + [
    (0.5, 40, PAPER_DELTA), (1.0, 1, 0.1), (0.9, 10, 0.05)]


@pytest.mark.parametrize("gamma, d, delta", BETA_MIN_CASES)
def test_beta_min_is_the_arc_start(gamma, d, delta):
    lim = limits(gamma=gamma, d=d, delta=delta)
    assert abs(lim.beta_min + delta) <= 1e-9 * delta, (lim.beta_min, -delta)
    # Independently: a point under the arc's start is stable, and nothing at
    # beta = -delta (1 + 1e-3) is (a scan of alpha up to 1.5 alpha_max).
    a1, b1 = (float(x) for x in first_principles_boundary_point(1e-2 / (d + 1), gamma, d, delta))
    assert b1 > -delta and a1 > 0
    assert oracle_radius(0.5 * a1, b1, gamma, d, delta) < 1
    scan = np.linspace(-0.1 * lim.alpha_max, 1.5 * lim.alpha_max, 2001)
    left = np.asarray(classify(alpha=scan, beta=-delta * (1 + 1e-3), gamma=gamma, d=d, delta=delta))
    assert not np.any(left == STABLE)


def test_beta_max_at_gamma0_d0_is_the_end_of_the_arc(gamma0_limits):
    lim = gamma0_limits[0]
    t = theta_max_30(0.0, 0, PAPER_DELTA)
    _, b = boundary_point(t, gamma=0.0, d=0, delta=PAPER_DELTA, dps=30)
    assert abs(lim.beta_max - float(b)) <= 1e-12 * float(b), (lim.beta_max, b)


@pytest.mark.parametrize("gamma, d, delta", [(-0.5, 0, 2.0), (0.0, 1, 0.1), (0.0, 5, 1e-4),
                                             (1.5, 0, 0.1), (0.5, 0, 2.0)])
def test_beta_max_is_the_corner_of_the_arc_on_alpha_zero(gamma, d, delta):
    # The region's right end is the corner where the arc ends on alpha = 0
    # (theta_max).  The polygons' vertex there is where two chords cross, off
    # the curves by a chord's sag (up to 2e-9 relative); it is re-found on
    # the arc.  Oracle: the first-principles arc at theta_max, 50 digits.
    lim = limits(gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(50):
        t = mpmath.findroot(lambda t: first_principles_boundary_point(t, gamma, d, delta)[0],
                            mpmath.mpf(theta_max_30(gamma, d, delta)))
        b = first_principles_boundary_point(t, gamma, d, delta)[1]
    assert abs(lim.beta_max - float(b)) <= 1e-12 * abs(float(b)), (lim.beta_max, b)


def green_area(gamma, d, delta):
    """Area enclosed by the arc (0 <= theta <= theta_max) and alpha = 0.

    Green's theorem: the closing piece on alpha = 0 adds nothing, so
    A = int_0^theta_max alpha(theta) beta'(theta) dtheta along the
    first-principles arc (eq. (2)), at 30 digits.
    """
    with mpmath.workdps(30):
        tm = mpmath.mpf(theta_max_30(gamma, d, delta))
        # refine the float theta_max on the first-principles alpha
        fa = lambda t: first_principles_boundary_point(t, gamma, d, delta)[0]  # noqa: E731
        fb = lambda t: first_principles_boundary_point(t, gamma, d, delta)[1]  # noqa: E731
        tm = mpmath.findroot(fa, tm)
        return mpmath.quad(lambda t: fa(t) * mpmath.diff(fb, t), [0, tm / 4, tm / 2, 3 * tm / 4, tm])


@pytest.mark.parametrize("d", GAMMA0_DELAYS)
def test_z_width_at_gamma0_is_the_area_under_the_arc(gamma0_limits, d):
    area = green_area(0.0, d, PAPER_DELTA)
    z = gamma0_limits[d].z_width
    err = abs(z - area) / area
    # trapezoid rule on 801 verticals: measured 1.6e-6 .. 2.0e-6
    assert err < 1e-5, f"z_width {z} vs {mpmath.nstr(area, 15)}: {mpmath.nstr(err, 3)}"


def test_limits_match_a_400x400_grid_for_gamma_1_5():
    lim = limits(gamma=1.5, d=0, delta=PAPER_DELTA)
    nb = na = 400
    b_lo, b_hi, a_lo, a_hi = -1.3, 0.9, -0.1, 3.4
    hb, ha = (b_hi - b_lo) / nb, (a_hi - a_lo) / na
    betas = b_lo + hb * (np.arange(nb) + 0.5)
    alphas = a_lo + ha * (np.arange(na) + 0.5)
    B, A = np.meshgrid(betas, alphas)
    stable = np.asarray(classify(alpha=A, beta=B, gamma=1.5, d=0, delta=PAPER_DELTA)) == STABLE
    # the region is inside the box
    assert not (stable[0].any() or stable[-1].any() or stable[:, 0].any() or stable[:, -1].any())
    # nothing stable above alpha_max or outside the beta range; the grid's extremes
    # are within its resolution (a corner may cost a cell in each direction)
    assert A[stable].max() <= lim.alpha_max
    assert lim.alpha_max - A[stable].max() <= 2 * ha + 2 * hb
    assert lim.beta_min <= B[stable].min() <= lim.beta_min + 2 * hb + ha
    assert lim.beta_max - 2 * hb - ha <= B[stable].max() <= lim.beta_max
    # area: the grid's error is bounded by the cells on the region's edge
    area = stable.sum() * ha * hb
    edge = np.zeros_like(stable)
    for axis in (0, 1):
        change = np.diff(stable.astype(np.int8), axis=axis) != 0
        if axis == 0:
            edge[:-1] |= change
            edge[1:] |= change
        else:
            edge[:, :-1] |= change
            edge[:, 1:] |= change
    edge_area = edge.sum() * ha * hb
    assert abs(area - lim.z_width) <= 0.1 * edge_area, (area, lim.z_width, edge_area)
    # and the stable cells next to the top are confirmed by the first-principles roots
    k = np.argmax(np.where(stable, A, -np.inf))
    assert oracle_radius(A.flat[k], B.flat[k], 1.5, 0, PAPER_DELTA) < 1


# --------------------------------------------------------------------------
# long delays (the region found by counting crossings, issue 10)
# --------------------------------------------------------------------------

def schur_cohn_stable(coeffs):
    """All roots of a real polynomial (highest power first) strictly inside the
    unit circle: the textbook Schur-Cohn recursion on the reflection
    coefficients ``k = p_0 / p_n``, written here apart from the library's.
    Reliable for points whose roots keep ~1e-6 from the circle."""
    p = np.array(coeffs, dtype=float)
    while p.size > 1:
        k = p[-1] / p[0]
        if not abs(k) < 1:
            return False
        p = (p - k * p[::-1])[:-1]
        p = p / p[0]
    return True


def first_principles_arc_alphas(beta, gamma, d, delta, theta_end, n=64):
    """alpha of the first-principles arc (eq. (2)) where its beta equals ``beta``,
    for theta in (0, theta_end): a scan and mpmath.findroot at 30 digits."""
    with mpmath.workdps(30):
        f = lambda t: first_principles_boundary_point(t, gamma, d, delta)[1] - beta  # noqa: E731
        grid = [mpmath.mpf(theta_end) * k / n for k in range(1, n + 1)]
        values = [f(t) for t in grid]
        roots = [mpmath.findroot(f, (a, b), solver="anderson")
                 for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True)
                 if fa * fb < 0]
        return [float(first_principles_boundary_point(t, gamma, d, delta)[0]) for t in roots]


@pytest.mark.parametrize("gamma, d, delta, beta", [
    (0.5, 200, 1e-4, 0.003), (0.5, 200, 1e-4, 0.0068), (0.0, 200, PAPER_DELTA, 0.004),
    (0.5, 1000, 1e-4, 0.001),
])
def test_long_delay_alpha_interval_matches_first_principles(gamma, d, delta, beta):
    """At d = 200 and 1000 the stable alpha interval is [0, top]: the top lies on
    the first-principles arc (30 digits), points inside it are stable and points
    just outside are not (Schur-Cohn on the 30-digit eq. (4) coefficients)."""
    runs = StabilityRegion(gamma=gamma, d=d, delta=delta).alpha_intervals(beta)
    assert len(runs) == 1, runs
    lo, hi = runs[0]
    assert lo == 0.0          # chi(1) = alpha (n1 + n0) (eq. (4)): z = 1 is a root at alpha = 0
    arc = first_principles_arc_alphas(beta, gamma, d, delta, theta_end=4.0 / (d + 1))
    assert arc and min(abs(hi - a) for a in arc) <= 1e-9 * hi, (hi, arc)
    width = hi - lo
    for alpha, stable in ((0.5 * (lo + hi), True), (lo + 1e-3 * width, True),
                          (hi - 1e-3 * width, True), (hi + 1e-3 * width, False),
                          (lo - 1e-3 * width, False)):
        assert schur_cohn_stable(eq4_chi_float(alpha, beta, gamma, d, delta)) == stable, alpha


def test_limits_at_d_200_agree_with_the_30_digit_interval_scan():
    """limits() at d = 200: the interval at beta_at_alpha_max reaches alpha_max, and the
    slow 30-digit reference scan (oracles.stable_alpha_intervals, roots of the
    30-digit coefficients) finds the same interval at another beta."""
    gamma, d, delta, beta = 0.5, 200, 1e-4, 0.003
    lim = limits(gamma=gamma, d=d, delta=delta)
    assert abs(lim.beta_min + delta) <= 1e-9 * delta
    top = lim.alpha_interval(lim.beta_at_alpha_max)
    assert top and top[-1][1] == pytest.approx(lim.alpha_max, rel=1e-6)
    (lo, hi), = lim.alpha_interval(beta)
    # three scan points (-0.3, 0.45, 1.2 of the top) and bisection to 1e-6: ~45 root finds
    ref = stable_alpha_intervals(beta=beta, gamma=gamma, d=d, delta=delta,
                                                   alpha_low=-0.3 * hi, alpha_high=1.2 * hi,
                                                   n=3, xtol=1e-6 * hi)
    assert len(ref) == 1
    assert abs(ref[0][0] - lo) <= 2e-6 * hi and abs(ref[0][1] - hi) <= 2e-6 * hi, (ref, (lo, hi))


# --------------------------------------------------------------------------
# count parameters and gamma_range (issue 10: one rule for every count)
# --------------------------------------------------------------------------

COUNT_CALLS = {
    "boundary_curve n": (lambda v: boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=v,
                                                  segments=False), "n", 2),
    "best_virtual_mass n": (lambda v: best_virtual_mass(d=0, delta=PAPER_DELTA, n=v), "n", 3),
    # Deprecated (ignored), but still checked as before.
    "limits n_beta": (lambda v: limits(gamma=0.0, d=0, delta=PAPER_DELTA, n_beta=v), "n_beta", 3),
}


_BAD_COUNTS = [(801.0, TypeError), (2.5, TypeError), ("5", TypeError), (True, TypeError),
               (None, TypeError), (1, ValueError), (-4, ValueError)]


# None is n_beta's default (not given), so it is no bad value there.
@pytest.mark.parametrize("call, value, error", [
    (call, value, error) for call in sorted(COUNT_CALLS) for value, error in _BAD_COUNTS
    if not (value is None and COUNT_CALLS[call][1] == "n_beta")])
def test_every_count_parameter_follows_one_rule(call, value, error):
    """A non-integer kind is a TypeError, an integer out of range a ValueError, both
    naming the parameter (limits(n_beta=801.0) was a ValueError, boundary_curve(n=2.0)
    a TypeError)."""
    function, name, low = COUNT_CALLS[call]
    with pytest.raises(error) as excinfo:
        function(value)
    assert_message_names(excinfo, name)
    if error is ValueError:
        assert f">= {low}" in str(excinfo.value)


def test_n_beta_is_deprecated_and_changes_nothing():
    """The Z-width is the polygons' area now: ``n_beta`` (the old line count) warns and is ignored."""
    plain = limits(gamma=0.0, d=2, delta=PAPER_DELTA)
    with pytest.warns(DeprecationWarning, match="n_beta"):
        old = limits(gamma=0.0, d=2, delta=PAPER_DELTA, n_beta=101)
    with pytest.warns(DeprecationWarning, match="n_beta"):
        StabilityRegion(gamma=0.0, d=2, delta=PAPER_DELTA).limits(n_beta=101)
    assert old.as_dict() == plain.as_dict()


@pytest.mark.parametrize("gamma_range, error", [
    ((0,), ValueError), ((0.0, 1.0, 2.0), ValueError), ((1.0, 0.0), ValueError),
    ((0.5, 0.5), ValueError), ((0.0, math.inf), ValueError), ((math.nan, 1.0), ValueError),
    (1.5, TypeError), ("01", TypeError), ((0.0, "1"), TypeError), (None, None),
])
def test_best_virtual_mass_validates_gamma_range(request, gamma_range, error):
    """gamma_range=(0,) was an IndexError; (0, 1, 2) was silently cut to (0, 1)."""
    if error is None:     # the default range is fine: the module's d = 0 search used it
        assert request.getfixturevalue("best_d0").d == 0
        return
    with pytest.raises(error) as excinfo:
        best_virtual_mass(d=0, delta=PAPER_DELTA, gamma_range=gamma_range)
    assert_message_names(excinfo, "gamma_range")


def test_boundary_curve_refuses_an_n_that_does_not_fit(monkeypatch):
    """boundary --n 1000000000 grew to 23 GB; now it is refused before any work,
    naming n and the limit."""
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "1G")
    with pytest.raises(ValueError) as excinfo:
        boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=10**9)
    assert_message_names(excinfo, "n")
    assert "1000000000" in str(excinfo.value) and "1 GiB" in str(excinfo.value)
    assert "SYMSTAB_MEMORY_LIMIT" in str(excinfo.value)
    # within the limit it works, in chunks: 2e6 points need 48 MB
    c = boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=2 * 10**6, segments=False)
    assert c.alpha.shape == (2 * 10**6,) and np.all(np.isfinite(c.alpha))
    assert abs(c.theta_max - theta_max_30(0.0, 0, PAPER_DELTA)) <= 1e-13


# --------------------------------------------------------------------------
# empty regions
# --------------------------------------------------------------------------

@pytest.mark.parametrize("gamma, d, delta", [(2.2, 5, PAPER_DELTA), (-1.5, 0, PAPER_DELTA)])
def test_empty_region(gamma, d, delta):
    lim = limits(gamma=gamma, d=d, delta=delta)
    assert lim.empty
    assert isinstance(lim.message, str) and lim.message
    assert lim.z_width == 0
    for key, value in lim.as_dict().items():
        if key != "message":
            assert value is None or (isinstance(value, (int, float)) and math.isfinite(value)), (key, value)
    assert lim.alpha_interval(0.0) == [] and lim.minimum_stiffness(0.0) is None
    region = StabilityRegion(gamma=gamma, d=d, delta=delta)
    assert region.alpha_max() is None and region.beta_range() is None
    # brute force: a grid over a wide box and probes next to the arc find nothing stable
    B, A = np.meshgrid(np.linspace(-4, 2, 300), np.linspace(-0.5, 6, 300))
    assert not np.any(np.asarray(classify(alpha=A, beta=B, gamma=gamma, d=d, delta=delta)) == STABLE)
    theta = np.linspace(1e-3, np.pi - 1e-3, 400)
    with mpmath.workdps(30):
        arc = [tuple(float(x) for x in first_principles_boundary_point(t, gamma, d, delta)) for t in theta]
    arc = np.array(arc)
    probes = [(arc[:, 0] * (1 + s) + e, arc[:, 1] + f) for s in (-1e-6, 1e-6, 0) for e in (0, 1e-9)
              for f in (-1e-6, 0, 1e-6)]
    for a, b in probes:
        assert not np.any(np.asarray(classify(alpha=a, beta=b, gamma=gamma, d=d, delta=delta)) == STABLE)


# --------------------------------------------------------------------------
# best_virtual_mass (slow: one call per delay; conftest's session fixtures best_d0 and
# best_d40, which test_design reads too)
# --------------------------------------------------------------------------

@pytest.mark.parametrize("which, d, others", [
    ("best_d0", 0, (0.5, 1.0, 1.5, 1.9, 2.0, -0.5)),
    ("best_d40", 40, (0.5, 0.9, -0.3)),
])
def test_best_virtual_mass_is_a_maximiser(request, gamma0_limits, which, d, others):
    best = request.getfixturevalue(which)
    assert best.d == d and best.delta == PAPER_DELTA
    assert best.gain > 1
    assert best.gain == pytest.approx(best.alpha_max / best.alpha_max_gamma0, rel=1e-15)
    assert best.alpha_max_gamma0 == pytest.approx(gamma0_limits[d].alpha_max, rel=1e-12)
    _, a_ref, _ = arc_top_30(0.0, d, PAPER_DELTA)
    assert best.alpha_max_gamma0 == pytest.approx(a_ref, rel=1e-9)
    at_best = limits(gamma=best.gamma, d=d, delta=PAPER_DELTA)
    assert best.alpha_max == pytest.approx(at_best.alpha_max, rel=1e-12)
    for g in others + (best.gamma * (1 - 1e-3),):
        other = limits(gamma=g, d=d, delta=PAPER_DELTA).alpha_max
        if other is not None:
            assert other <= best.alpha_max * (1 + 1e-12), (g, other, best.alpha_max)
    # The reported top is on the edge of the first-principles region: within
    # 4 ulps below it the largest root is on the unit circle to 1e-9.  (At
    # d = 0 the top is a corner where two roots meet, so the radius moves by
    # about 3e-9 per ulp of alpha, and np.roots of rounded coefficients is
    # off by 1e-8: 40-digit roots.)
    below = [best.alpha_max - k * np.spacing(best.alpha_max) for k in range(5)]
    radii = [first_principles_radius(a, best.beta, best.gamma, d, PAPER_DELTA) for a in below]
    assert min(radii) < 1 + 1e-9, radii


@pytest.mark.parametrize("which, d", [("best_d0", 0), ("best_d40", 40)])
def test_alpha_max_at_the_best_gamma_is_the_top_of_the_region(request, which, d):
    """No stable point lies above alpha_max (a fine local grid, checked with eq. (2))."""
    best = request.getfixturevalue(which)
    a_top, b_top = best.alpha_max, best.beta
    # Columns 2e-8 relative apart over +-2.5e-6 relative in beta; rows from
    # 1e-9 to 2.5e-6 relative above alpha_max, 1e-8 relative apart (at d = 40,
    # where the top is the smooth top of the arc, 1e-7 and 5e-8 apart over
    # +-1e-5).  A top reported further below the region's than that is
    # caught by the 1e-9 agreement with the 30-digit arc top above.
    n, span = (251, 2.5e-6) if d == 0 else (201, 1e-5)
    betas = b_top + abs(b_top) * np.linspace(-span, span, n)
    alphas = a_top * (1 + np.linspace(1e-9, span, n - 1))
    B, A = np.meshgrid(betas, alphas)
    stable = np.asarray(classify(alpha=A, beta=B, gamma=best.gamma, d=d, delta=PAPER_DELTA)) == STABLE
    confirmed = []
    order = np.argsort(-np.where(stable, A, -np.inf), axis=None)[:20]
    for k in order[stable.flat[order]]:
        r = oracle_radius(A.flat[k], B.flat[k], best.gamma, d, PAPER_DELTA)
        if r < 1:
            confirmed.append((A.flat[k], B.flat[k], r - 1))
    assert not confirmed, (
        f"{len(confirmed)} stable points above alpha_max = {a_top!r} (beta = {b_top!r}, "
        f"gamma = {best.gamma!r}); highest (alpha, beta, radius - 1): {confirmed[0]}, "
        f"{(confirmed[0][0] - a_top) / a_top:.2e} relative above")


# --------------------------------------------------------------------------
# Device
# --------------------------------------------------------------------------

def test_paper_device():
    assert (PAPER_DEVICE.m, PAPER_DEVICE.b, PAPER_DEVICE.T) == (0.0128, 0.0324, 1e-3)
    assert PAPER_DEVICE.delta == 0.0324e-3 / 0.0128
    assert PAPER_DEVICE.delay_samples(40e-3) == 40
    assert type(PAPER_DEVICE.delay_samples(40e-3)) is int
    assert PAPER_DEVICE.delay_samples(0.0) == 0
    assert PAPER_DEVICE.delay(40) == pytest.approx(40e-3, rel=1e-15)
    # Table I by hand: alpha = K_w T^2 / m, beta = B_w T / m, gamma = M_w / m
    assert PAPER_DEVICE.alpha(1280.0) == pytest.approx(1280.0 * 1e-6 / 0.0128, rel=1e-15)
    assert PAPER_DEVICE.beta(2.0) == pytest.approx(2.0 * 1e-3 / 0.0128, rel=1e-15)
    assert PAPER_DEVICE.gamma(0.0064) == pytest.approx(0.5, rel=1e-15)


@pytest.mark.parametrize("device", [PAPER_DEVICE, Device(m=2.0, b=3.0, T=0.5), Device(m=0.3, b=1e-4, T=2.5e-4)])
def test_device_conversions_round_trip(device):
    rng = np.random.default_rng(1)
    K = 10 ** rng.uniform(-2, 5, 50)
    Bw = rng.uniform(-10, 10, 50)
    M = rng.uniform(-1, 3, 50)
    m, T = device.m, device.T
    assert device.delta == pytest.approx(device.b * T / m, rel=1e-15)
    np.testing.assert_allclose(device.alpha(K), K * T**2 / m, rtol=1e-15)
    np.testing.assert_allclose(device.beta(Bw), Bw * T / m, rtol=1e-15)
    np.testing.assert_allclose(device.gamma(M), M / m, rtol=1e-15)
    np.testing.assert_allclose(device.stiffness(device.alpha(K)), K, rtol=1e-14)
    np.testing.assert_allclose(device.damping(device.beta(Bw)), Bw, rtol=1e-14)
    np.testing.assert_allclose(device.mass(device.gamma(M)), M, rtol=1e-14)
    a = rng.uniform(0, 3, 50)
    np.testing.assert_allclose(device.alpha(device.stiffness(a)), a, rtol=1e-14)
    np.testing.assert_allclose(device.beta(device.damping(a)), a, rtol=1e-14)
    np.testing.assert_allclose(device.gamma(device.mass(a)), a, rtol=1e-14)
    for d in (0, 1, 7, 40, 200):
        assert device.delay_samples(device.delay(d)) == d
    assert isinstance(device.alpha(1.0), float) and isinstance(device.stiffness(0.1), float)
    assert isinstance(device.alpha([1.0, 2.0]), np.ndarray)


@pytest.mark.parametrize("name, value", [
    (name, value) for name in ("m", "b", "T") for value in (0.0, -1.0, float("nan"), float("inf"))
    if (name, value) != ("b", 0.0)])   # b = 0 is a frictionless device (tests/numeric/paper/test_units.py)
def test_device_rejects_bad_parameters(name, value):
    kwargs = dict(m=0.0128, b=0.0324, T=1e-3)
    kwargs[name] = value
    with pytest.raises(ValueError) as excinfo:
        Device(**kwargs)
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("Td", [40.5e-3, 1.5e-3, 1e-4, -1e-3, float("nan"), float("inf")])
def test_delay_samples_rejects_bad_delays(Td):
    with pytest.raises(ValueError) as excinfo:
        PAPER_DEVICE.delay_samples(Td)
    assert_message_names(excinfo, "Td")


def test_device_rejects_non_numbers():
    with pytest.raises(TypeError) as excinfo:
        Device(m=True, b=0.0324, T=1e-3)
    assert_message_names(excinfo, "m")
    with pytest.raises(TypeError) as excinfo:
        PAPER_DEVICE.stiffness(1j)
    assert_message_names(excinfo, "alpha")
    with pytest.raises(ValueError) as excinfo:
        PAPER_DEVICE.alpha([1.0, float("nan")])
    assert_message_names(excinfo, "K_w")


def test_limits_and_region_print_their_content():
    """Issue 13: Limits printed as region=<symstab.numeric.paper.region.StabilityRegion object at 0x...>."""
    lim = symstab.limits(gamma=0.0, d=0, delta=PAPER_DELTA)
    text = repr(lim)
    assert " at 0x" not in text
    assert f"alpha_max={lim.alpha_max:.6g}" in text and "z_width=" in text
    assert repr(lim.region) == "StabilityRegion(gamma=0, d=0, delta=0.00253125)"
    empty = symstab.limits(gamma=2.2, d=5, delta=PAPER_DELTA)
    assert "empty" in repr(empty) and " at 0x" not in repr(empty)


def test_limits_names_the_region_beta_range_left_and_right():
    lim = symstab.limits(gamma=1.5, d=0, delta=PAPER_DELTA)
    # The leftmost beta of the region is not the paper's beta_min = -delta here.
    assert lim.beta_left < -PAPER_DELTA
    assert (lim.beta_min, lim.beta_max) == (lim.beta_left, lim.beta_right)
    assert {"beta_left", "beta_right"} <= set(lim.as_dict())


def test_boundary_curve_prints_a_summary_not_its_arrays():
    curve = symstab.boundary_curve(gamma=0.0, d=0, delta=PAPER_DELTA, n=1000)
    text = repr(curve)
    assert "array(" not in text and "1000 points" in text
    assert f"theta_max={curve.theta_max:.6g}" in text
    assert "no arc" in repr(symstab.boundary_curve(gamma=-3.0, d=0, delta=PAPER_DELTA, n=10))


@pytest.mark.parametrize("d", [0, 5, 10])
def test_vanishing_gamma_brackets_the_derived_end_of_the_arc(d):
    """The region shrinks to nothing where the arc's start vanishes, gamma* = -1 - (d + 1) delta
    (REPORT.md, claim:no_region_gamma_le_-1): the bisection's decided bracket holds it."""
    from symstab.numeric.paper.region import vanishing_gamma

    star = -1.0 - (d + 1) * PAPER_DELTA
    inside, outside = vanishing_gamma(d=d, delta=PAPER_DELTA, inside=-0.9, outside=-1.2, tol=1e-4)
    assert outside <= star <= inside and inside - outside <= 1e-4
    assert limits(gamma=outside, d=d, delta=PAPER_DELTA).empty
    assert not limits(gamma=inside, d=d, delta=PAPER_DELTA).empty


def test_vanishing_gamma_refuses_ends_on_the_wrong_side():
    from symstab.numeric.paper.region import vanishing_gamma

    with pytest.raises(ValueError, match="inside"):
        vanishing_gamma(d=0, delta=PAPER_DELTA, inside=-1.2, outside=-1.3)
    with pytest.raises(ValueError, match="outside"):
        vanishing_gamma(d=0, delta=PAPER_DELTA, inside=-0.5, outside=0.0)
    with pytest.raises(ValueError, match="tol"):
        vanishing_gamma(d=0, delta=PAPER_DELTA, inside=-0.5, outside=-1.2, tol=0.0)


@pytest.mark.parametrize("gamma, d", [(0.0, 0), (0.5, 5), (1.0, 10)])
def test_arc_polylines_lie_on_the_boundary_by_python_control(gamma, d):
    """Every drawn arc point has a closed-loop pole on the unit circle (python-control's poles of
    the sampled loop); the first piece starts at the corner (-delta, 0) and ends on alpha = 0."""
    from symstab.numeric.paper.region import arc_polylines

    from oracles import python_control_closed_loop

    window = ((-0.5, 2.5), (-0.1, 4.0))
    first, beyond = arc_polylines(gamma=gamma, d=d, delta=PAPER_DELTA, window=window)
    assert tuple(first[0]) == (-PAPER_DELTA, 0.0)
    assert abs(first[-1][1]) <= 1e-9 and np.array_equal(first[-1], beyond[0])
    points = np.vstack([first, beyond])
    points = points[np.all(np.isfinite(points), axis=1)]
    for beta, alpha in points[np.linspace(1, len(points) - 1, 12).astype(int)]:
        poles = python_control_closed_loop(alpha=alpha, beta=beta, gamma=gamma, d=d,
                                           delta=PAPER_DELTA, m=1.0, T=1.0).poles()
        assert np.min(np.abs(np.abs(poles) - 1.0)) <= 1e-7, (beta, alpha)


@pytest.mark.parametrize("window, error, name", [(1.0, TypeError, "window"), ("ab", TypeError, "window"),
                                                 (((0, 1),), TypeError, "window"),
                                                 (((1, 0), (0, 1)), ValueError, "window[0]"),
                                                 (((0, 1), (0, np.nan)), ValueError, "window[1]")])
def test_arc_polylines_refuses_a_bad_window_naming_it(window, error, name):
    from symstab.numeric.paper.region import arc_polylines

    with pytest.raises(error, match=re.escape(name)):
        arc_polylines(gamma=0.0, d=0, delta=PAPER_DELTA, window=window)
    with pytest.raises(error, match=re.escape(name)):
        symstab.PAPER_LOOP.boundary(d=0, window=window)
