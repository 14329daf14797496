"""Tests of the vectorised stability API: spectral_radius, classify, is_stable.

Oracles (none of them goes through symstab's kernels; symstab's 30/50-digit
``boundary_point`` only places test points on the boundary):

* python-control: the closed loop of Fig. 2 built from physical values
  (``oracles.python_control_closed_loop``), its poles' largest modulus;
* the characteristic polynomial written out from the paper's eqs. (1), (2)
  and (4) with m = T = 1, b = delta (:func:`eq4_chi`), evaluated in mpmath;
  its roots by ``mpmath.polyroots`` at 40 digits (d = 40; started from
  numpy's roots, :func:`oracles.polyroots`), or by
  :func:`polished_roots`: numpy's roots of the coefficients rounded once from
  30 digits, Newton-polished at 40 digits (all of them, or those within 1e-3
  of the unit circle) and checked to be distinct (d = 200, where polyroots
  takes two minutes a point).

Measured (this revision): the python-control acceptance test keeps all 1100
random points (the closest is 5.5e-5 from radius 1), 441 of them (40 %)
stable, and is_stable agrees on every one; spectral_radius agrees with
python-control to 7.1e-12 relative on those 1100 and to 4.4e-11 on 50 points
with physical m, T; with the 40-digit roots to 4.7e-14 (d = 200) and 4e-16
(d = 40).  Next to the boundary (1e-6 relative in alpha; 368 points at
d = 10, 40, 200, about half of them with a Schur-Cohn margin below 1e-6)
classify(refine=True) agrees with the 40-digit roots everywhere;
refine=False agrees on 367 and answers MARGINAL (margin exactly 0) on one
point near the corner (-delta, 0) at gamma = 0, d = 200 whose radius is
1 - 1.75e-11.
"""

import math

import mpmath
import numpy as np
import pytest

import symstab
from symstab import MARGINAL, STABLE, UNSTABLE, classify, is_stable, spectral_radius
from symstab.numeric.paper.reference import boundary_point
from symstab.numeric.paper.stability import loop_coefficients, schur_cohn

from conftest import PAPER_DELTA, assert_message_names
from oracles import (
    dimensionless,
    first_principles_chi,
    first_principles_chi_float,
    polyroots,
    python_control_closed_loop,
    random_loop_points,
)

# --------------------------------------------------------------------------
# Independent oracle: chi(z) from the printed eqs. (1), (2), (4)
# --------------------------------------------------------------------------

#: The first-principles polynomial (tests/oracles.py), at the current mpmath
#: precision, and rounded once to floats from 30 digits.
eq4_chi = first_principles_chi
eq4_chi_float = first_principles_chi_float


def polished_roots(coeffs_mp, dps=40, near=None):
    """The roots of a polynomial at ``dps`` digits: numpy's roots, Newton-polished.

    Each float root (or, with ``near``, each one whose modulus is within
    ``near`` of 1; the others keep their float value, whose error is ~1e-12)
    is refined by Newton's method on the mpmath coefficients.  The result is
    accepted only if the ``n`` roots are distinct (so none was lost to a
    neighbour) and every Newton iteration converged.
    """
    with mpmath.workdps(dps):
        guesses = np.roots([float(c) for c in coeffs_mp])
        assert len(guesses) == len(coeffs_mp) - 1
        out = []
        for r0 in guesses:
            if near is not None and abs(abs(r0) - 1) > near:
                out.append(mpmath.mpc(complex(r0)))
                continue
            r = mpmath.mpc(complex(r0))
            for _ in range(30):
                p, dp = mpmath.polyval(coeffs_mp, r, derivative=True)
                step = p / dp
                r -= step
                if abs(step) < mpmath.mpf(10) ** (-dps + 5) * max(1, abs(r)):
                    break
            else:
                raise AssertionError(f"Newton did not converge from {r0}")
            assert abs(r - mpmath.mpc(complex(r0))) < 1e-6, "Newton wandered off"
            out.append(r)
        z = np.array([complex(r) for r in out])
        gaps = np.abs(z[:, None] - z[None, :]) + np.eye(len(z))
        assert gaps.min() > 1e-9, f"polished roots not distinct ({gaps.min()})"
        return out


def oracle_radius(alpha, beta, gamma, d, delta):
    """max |root| of eq4_chi, float, from numpy roots of 30-digit coefficients."""
    return float(np.max(np.abs(np.roots(eq4_chi_float(alpha, beta, gamma, d, delta)))))


# --------------------------------------------------------------------------
# The acceptance test: python-control on >= 1000 random points
# --------------------------------------------------------------------------

N_RANDOM = 1100
#: d in 0..12, mostly small (python-control costs ~4 ms a point).
D_WEIGHTS = np.r_[[0.2, 0.15, 0.12, 0.1, 0.08, 0.07, 0.06], [0.22 / 6] * 6]


def _random_points(seed=2025, n=N_RANDOM):
    """delta log-uniform in [1e-3, 1], gamma in [-0.9, 2.5], alpha in
    [0, 0.4/(d+1)], beta in [-0.05, 1.2]/(d+1): 40 % of them are stable
    (measured with python-control: 441 of 1100)."""
    rng = np.random.default_rng(seed)
    d = rng.choice(13, size=n, p=D_WEIGHTS)
    delta = 10 ** rng.uniform(-3, 0, n)
    gamma = rng.uniform(-0.9, 2.5, n)
    alpha = rng.uniform(0, 0.4, n) / (d + 1)
    beta = rng.uniform(-0.05, 1.2, n) / (d + 1)
    return d, delta, gamma, alpha, beta


@pytest.fixture(scope="module")
def random_points_with_python_control():
    d, delta, gamma, alpha, beta = _random_points()
    radius = np.empty(len(d))
    for i in range(len(d)):
        # Every other point in the paper device's units (m = 12.8 g, T = 1 ms),
        # the rest with m = T = 1 (b = delta): the loop depends only on Table I's
        # dimensionless variables.
        m, T = (1.0, 1.0) if i % 2 == 0 else (0.0128, 1e-3)
        loop = python_control_closed_loop(alpha=alpha[i], beta=beta[i], gamma=gamma[i],
                                          d=int(d[i]), delta=delta[i], m=m, T=T)
        radius[i] = np.max(np.abs(loop.poles()))
    return d, delta, gamma, alpha, beta, radius


def test_is_stable_agrees_with_python_control_on_1000_random_points(
        random_points_with_python_control):
    d, delta, gamma, alpha, beta, radius = random_points_with_python_control
    keep = np.abs(radius - 1.0) > 1e-6
    n_kept = int(keep.sum())
    assert n_kept >= 1000, f"only {n_kept} points away from the boundary"
    stable_share = float(np.mean(radius[keep] < 1))
    assert 0.3 <= stable_share <= 0.6, f"stable share {stable_share:.2f}: test is lopsided"
    mismatches = []
    for dd in np.unique(d):
        s = np.flatnonzero((d == dd) & keep)
        verdict = is_stable(alpha=alpha[s], beta=beta[s], gamma=gamma[s], d=int(dd), delta=delta[s])
        assert isinstance(verdict, np.ma.MaskedArray)
        assert not np.any(np.ma.getmaskarray(verdict)), "a point 1e-6 from radius 1 is marginal"
        expected = radius[s] < 1.0
        bad = np.flatnonzero(np.asarray(verdict) != expected)
        mismatches += [(int(dd), alpha[s][k], beta[s][k], gamma[s][k], delta[s][k], radius[s][k])
                       for k in bad]
    assert not mismatches, f"{len(mismatches)} of {n_kept} disagree, e.g. {mismatches[:5]}"


def test_classify_codes_agree_with_python_control(random_points_with_python_control):
    d, delta, gamma, alpha, beta, radius = random_points_with_python_control
    keep = np.abs(radius - 1.0) > 1e-6
    for dd in np.unique(d):
        s = np.flatnonzero((d == dd) & keep)
        code = classify(alpha=alpha[s], beta=beta[s], gamma=gamma[s], d=int(dd), delta=delta[s])
        assert code.dtype == np.int8
        np.testing.assert_array_equal(code, np.where(radius[s] < 1, STABLE, UNSTABLE))


def test_spectral_radius_batch_agrees_with_python_control(random_points_with_python_control):
    d, delta, gamma, alpha, beta, radius = random_points_with_python_control
    worst = 0.0
    for dd in np.unique(d):
        s = d == dd
        r = spectral_radius(alpha=alpha[s], beta=beta[s], gamma=gamma[s], d=int(dd), delta=delta[s])
        worst = max(worst, float(np.max(np.abs(r - radius[s]) / radius[s])))
    assert worst < 1e-8, worst


# --------------------------------------------------------------------------
# spectral_radius against python-control and 40-digit roots
# --------------------------------------------------------------------------

@pytest.mark.parametrize("point", random_loop_points(seed=20250, n=50, delta_range=(1e-3, 1.0)))
def test_spectral_radius_matches_python_control_poles(point):
    poles = python_control_closed_loop(**dimensionless(point), m=point["m"], T=point["T"]).poles()
    expected = float(np.max(np.abs(poles)))
    got = spectral_radius(**dimensionless(point))
    assert isinstance(got, float)
    assert abs(got - expected) <= 1e-8 * expected, (got, expected)


#: (alpha, beta, gamma, d, delta): near the region (radius ~ 1) and far from it.
HIGH_D_POINTS = [
    (3e-4, 0.02, 0.3, 40, PAPER_DELTA),
    (2e-3, -0.01, -0.5, 40, 0.05),
    (0.05, 0.5, 1.2, 40, 0.3),
    (2e-5, 0.004, 0.3, 200, PAPER_DELTA),
    (1e-4, 0.004, 0.3, 200, PAPER_DELTA),
    (1e-3, 0.1, -0.4, 200, 0.2),
]


@pytest.mark.parametrize("alpha, beta, gamma, d, delta", [p for p in HIGH_D_POINTS if p[3] == 40])
def test_spectral_radius_matches_mpmath_polyroots_at_d40(alpha, beta, gamma, d, delta):
    with mpmath.workdps(40):
        roots = polyroots(eq4_chi(alpha, beta, gamma, d, delta), maxsteps=400, extraprec=200)
        expected = max(abs(r) for r in roots)
        got = spectral_radius(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        err = abs(got - expected) / expected
    assert err < 1e-11, f"radius {got} vs {mpmath.nstr(expected, 20)}: {mpmath.nstr(err, 3)}"


@pytest.mark.parametrize("alpha, beta, gamma, d, delta", HIGH_D_POINTS)
def test_spectral_radius_matches_polished_40_digit_roots(alpha, beta, gamma, d, delta):
    with mpmath.workdps(40):
        roots = polished_roots(eq4_chi(alpha, beta, gamma, d, delta))
        expected = max(abs(r) for r in roots)
        got = spectral_radius(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        err = abs(got - expected) / expected
    assert err < 1e-11, f"radius {got} vs {mpmath.nstr(expected, 20)}: {mpmath.nstr(err, 3)}"


def test_loop_coefficients_are_a_multiple_of_the_first_principles_polynomial():
    # chi / delta**2 up to a constant factor: compare after normalising the leading term.
    for alpha, beta, gamma, d, delta in HIGH_D_POINTS[:3] + [(0.3, 0.4, 1.5, 0, PAPER_DELTA)]:
        c = loop_coefficients(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
        assert c.shape == (d + 5,)
        ref = eq4_chi_float(alpha, beta, gamma, d, delta)
        ratio = c[0] / ref[0]
        scale = np.max(np.abs(ref))
        np.testing.assert_allclose(c / ratio, ref, rtol=1e-12, atol=1e-13 * scale)


def test_vectorised_shapes_and_scalar_types():
    r = spectral_radius(alpha=np.linspace(0, 0.5, 3)[:, None], beta=np.array([0.0, 0.3, 0.6, 1.0]),
                        gamma=0.2, d=2, delta=0.01)
    assert r.shape == (3, 4)
    code = classify(alpha=np.linspace(0, 0.5, 3)[:, None], beta=np.array([0.0, 0.3, 0.6, 1.0]),
                    gamma=0.2, d=2, delta=0.01)
    assert code.shape == (3, 4) and code.dtype == np.int8
    for i in range(3):
        for j in range(4):
            a, b = np.linspace(0, 0.5, 3)[i], [0.0, 0.3, 0.6, 1.0][j]
            assert r[i, j] == pytest.approx(oracle_radius(a, b, 0.2, 2, 0.01), rel=1e-10)
            assert isinstance(classify(alpha=a, beta=b, gamma=0.2, d=2, delta=0.01), int)
            assert classify(alpha=a, beta=b, gamma=0.2, d=2, delta=0.01) == code[i, j]
    assert loop_coefficients(alpha=[0.1, 0.2], beta=0.0, gamma=0.0, d=3, delta=0.1).shape == (2, 8)
    # numpy integer and integral float delays are accepted
    assert classify(alpha=0.1, beta=0.5, gamma=0.0, d=np.int64(3), delta=0.01) == \
        classify(alpha=0.1, beta=0.5, gamma=0.0, d=3.0, delta=0.01)


# --------------------------------------------------------------------------
# Marginal points: exactly on the boundary
# --------------------------------------------------------------------------

#: (gamma, d, delta, theta): arc points that bound the stable region.  For
#: gamma = 0 and 0.5 the arc for theta in (0, theta_max) is the top of the
#: region; for gamma = 1.5, d = 0 at theta = 0.5 it is its lower edge (the
#: minimum stiffness of Fig. 7): stable above, unstable below.
MARGINAL_CASES = [
    (0.0, 0, PAPER_DELTA, 0.8, "above"),
    (0.0, 5, PAPER_DELTA, 0.13, "above"),
    (0.3, 10, 0.1, 0.06, "above"),
    (0.5, 40, PAPER_DELTA, 0.026, "above"),
    (0.0, 200, PAPER_DELTA, 0.0045, "above"),
    (1.5, 0, PAPER_DELTA, 0.5, "below"),
]


@pytest.mark.parametrize("gamma, d, delta, theta, unstable_side", MARGINAL_CASES)
def test_a_boundary_point_is_marginal_and_its_neighbours_are_not(gamma, d, delta, theta, unstable_side):
    a, b = boundary_point(theta, gamma=gamma, d=d, delta=delta, dps=50)
    alpha, beta = float(a), float(b)
    assert alpha > 0
    assert classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta) == MARGINAL
    assert is_stable(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta) is None
    alphas = np.array([alpha, alpha * (1 - 1e-6), alpha * (1 + 1e-6)])
    verdict = is_stable(alpha=alphas, beta=beta, gamma=gamma, d=d, delta=delta)
    assert verdict.mask.tolist() == [True, False, False]
    below, above = bool(verdict[1]), bool(verdict[2])
    assert below != above
    # The sides against the first-principles roots
    with mpmath.workdps(40):
        for a_side, got in ((alphas[1], below), (alphas[2], above)):
            radius = max(abs(r) for r in polished_roots(eq4_chi(a_side, beta, gamma, d, delta), near=1e-3))
            assert got == bool(radius < 1), (a_side, mpmath.nstr(radius - 1, 5))
    assert (above is False) == (unstable_side == "above")
    codes = classify(alpha=alphas, beta=beta, gamma=gamma, d=d, delta=delta)
    assert codes[0] == MARGINAL and set(codes[1:].tolist()) == {STABLE, UNSTABLE}


# --------------------------------------------------------------------------
# Schur-Cohn against eigenvalues next to the boundary
# --------------------------------------------------------------------------

def _near_boundary_points(gamma, d, delta, n_theta):
    """Arc points (anywhere in (0, pi), also where the arc only splits unstable
    gaps) moved 1e-6 relative in alpha, on both sides."""
    thetas = np.linspace(0.02, np.pi - 0.02, n_theta)
    # Also the part of the arc that bounds the region (0 < theta < theta_max);
    # the float theta_max only picks test points here.
    tmax = symstab.arc_end_angle(gamma=gamma, d=d, delta=delta)
    if math.isfinite(tmax):
        thetas = np.concatenate([thetas, tmax * np.linspace(0.05, 0.95, n_theta)])
    pts = []
    for t in thetas:
        a, b = boundary_point(float(t), gamma=gamma, d=d, delta=delta, dps=30)
        for s in (-1, 1):
            pts.append((float(a) * (1 + s * 1e-6), float(b)))
    return np.array(pts)


SC_CASES = [(0.0, 10, PAPER_DELTA), (0.7, 10, 0.2), (0.0, 40, PAPER_DELTA), (0.5, 40, 0.05),
            (0.0, 200, PAPER_DELTA), (0.3, 200, 0.01)]


@pytest.mark.parametrize("gamma, d, delta", SC_CASES)
def test_schur_cohn_agrees_with_eigenvalues_next_to_the_boundary(gamma, d, delta):
    n_theta = 6 if d == 200 else 20
    pts = _near_boundary_points(gamma, d, delta, n_theta)
    alpha, beta = pts[:, 0], pts[:, 1]
    refined = classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)
    plain = classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta, refine=False)
    expected = []
    with mpmath.workdps(40):
        for a, b in pts:
            roots = polished_roots(eq4_chi(a, b, gamma, d, delta), near=1e-3)
            radius = max(abs(r) for r in roots)
            assert abs(radius - 1) > mpmath.mpf(10) ** -12, "test point is marginal itself"
            expected.append(STABLE if radius < 1 else UNSTABLE)
    expected = np.array(expected)
    # Both verdicts occur, so the points straddle the region somewhere.
    assert STABLE in expected and UNSTABLE in expected
    bad = np.flatnonzero(refined != expected)
    assert bad.size == 0, f"refine=True: {bad.size}/{len(pts)} wrong, e.g. {pts[bad[:3]]}"
    # refine=False: the Schur-Cohn verdict as it is.  It must never be wrong;
    # as documented, it may answer MARGINAL where a reflection coefficient
    # rounds to modulus exactly 1 (margin 0).  Measured: 1 of the 24 points
    # at gamma = 0, d = 200 (alpha = 3.15e-7, beta = -2.4786e-3, near the
    # corner (-delta, 0), true radius 1 - 1.75e-11); all others agree.
    wrong = np.flatnonzero((plain != expected) & (plain != MARGINAL))
    assert wrong.size == 0, f"refine=False: {wrong.size}/{len(pts)} wrong, e.g. {pts[wrong[:3]]}"
    undecided = np.flatnonzero(plain == MARGINAL)
    if undecided.size:
        _, margin = schur_cohn(loop_coefficients(alpha=alpha[undecided], beta=beta[undecided],
                                                 gamma=gamma, d=d, delta=delta))
        assert np.all(margin == 0), margin
    assert undecided.size <= 1, f"refine=False undecided on {undecided.size}/{len(pts)}"


# --------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------

GOOD = dict(alpha=0.1, beta=0.5, gamma=0.0, d=2, delta=0.01)
FUNCTIONS = [spectral_radius, classify, is_stable, loop_coefficients]

BAD_INPUTS = [
    ("alpha", float("nan"), ValueError),
    ("beta", float("inf"), ValueError),
    ("gamma", -float("inf"), ValueError),
    ("delta", float("nan"), ValueError),
    ("alpha", [0.1, float("nan")], ValueError),
    ("beta", np.array([[0.0, float("inf")]]), ValueError),
    ("alpha", True, TypeError),
    ("gamma", np.array([True, False]), TypeError),
    ("beta", 1j, TypeError),
    ("alpha", np.array([0.1 + 0j]), TypeError),
    ("gamma", "0.5", TypeError),
    ("delta", None, TypeError),
    ("d", 2.5, ValueError),
    ("d", -1, ValueError),
    ("d", float("nan"), ValueError),
    ("d", True, TypeError),
    ("d", "3", TypeError),
    ("d", 3 + 0j, TypeError),
    ("delta", -0.1, ValueError),
    ("delta", [0.1, -1e-300], ValueError),
    ("delta", 1.5e6, ValueError),
    ("d", 10**20, ValueError),
    ("d", 1e20, ValueError),
]


@pytest.mark.parametrize("func", FUNCTIONS, ids=lambda f: f.__name__)
@pytest.mark.parametrize("name, value, exc", BAD_INPUTS)
def test_bad_input_raises_naming_the_parameter(func, name, value, exc):
    kwargs = dict(GOOD, **{name: value})
    with pytest.raises(exc) as excinfo:
        func(**kwargs)
    assert_message_names(excinfo, name)


@pytest.mark.parametrize("func", FUNCTIONS, ids=lambda f: f.__name__)
def test_arrays_that_do_not_broadcast_raise_value_error(func):
    with pytest.raises(ValueError) as excinfo:
        func(alpha=np.zeros(3), beta=np.zeros(4), gamma=0.0, d=1, delta=0.01)
    assert_message_names(excinfo, "alpha")
    assert_message_names(excinfo, "beta")


def test_classify_refine_false_is_still_vectorised_and_sane():
    alphas = np.array([0.1, 3.0])
    np.testing.assert_array_equal(
        classify(alpha=alphas, beta=0.5, gamma=0.0, d=0, delta=PAPER_DELTA, refine=False),
        [STABLE, UNSTABLE])
    # checked against the first-principles roots
    assert oracle_radius(0.1, 0.5, 0.0, 0, PAPER_DELTA) < 1 < oracle_radius(3.0, 0.5, 0.0, 0, PAPER_DELTA)


# --------------------------------------------------------------------------
# The certified root count (argument principle), clustered roots, long delays
# --------------------------------------------------------------------------

def _count_outside(alpha, beta, gamma, d, delta, dps=40, near=1e-3):
    """Roots of eq4_chi outside the unit circle, from polished 40-digit roots.

    Roots within ``near`` of the circle are Newton-polished (numpy's are
    good to ~1e-12 elsewhere).  Returns None when a root is within 1e-12 of
    the circle (too close for the oracle to be sure, so the test point is
    not used).
    """
    with mpmath.workdps(dps):
        roots = polished_roots(eq4_chi(alpha, beta, gamma, d, delta), dps=dps, near=near)
        moduli = [abs(r) for r in roots]
        if min(abs(m - 1) for m in moduli) < mpmath.mpf(10) ** -12:
            return None
        return sum(1 for m in moduli if m > 1)


@pytest.mark.parametrize("d", [0, 1, 5, 12, 40])
def test_unstable_root_counts_match_polished_roots(d):
    rng = np.random.default_rng(100 + d)
    alpha = rng.uniform(-0.3, 3.0, 12) / (d + 1)
    beta = rng.uniform(-0.5, 2.0, 12) / (d + 1)
    gamma = rng.uniform(-1.2, 2.5, 12)
    delta = 10 ** rng.uniform(-5, 1, 12)
    counts = symstab.numeric.paper.stability.unstable_root_counts(alpha=alpha, beta=beta, gamma=gamma, d=d,
                                                     delta=delta)
    checked = 0
    for i in range(12):
        expected = _count_outside(alpha[i], beta[i], gamma[i], d, delta[i])
        if expected is None:
            continue
        checked += 1
        assert counts[i] == expected, (i, alpha[i], beta[i], gamma[i], delta[i], counts[i], expected)
    assert checked >= 10


@pytest.mark.parametrize("theta", [3e-5, 5.3e-5, 1e-4, 3e-4])
def test_clustered_roots_get_the_true_verdict_or_marginal(theta):
    """gamma = -1, delta = 1e-6, d = 10: roots cluster at z = 1.

    On the arc at theta = 5.3e-5 the exact radius is 1 + 1.4e-11 and the
    eigenvalue refinement said stable; a certified answer may only be the
    truth or MARGINAL.
    """
    gamma, d, delta = -1.0, 10, 1e-6
    a, b = (float(x) for x in boundary_point(theta, gamma=gamma, d=d, delta=delta, dps=50))
    alphas = a * np.array([1.0, 1 - 1e-6, 1 + 1e-6, 1 - 1e-3, 1 + 1e-3, 0.5, 2.0])
    codes = classify(alpha=alphas, beta=b, gamma=gamma, d=d, delta=delta)
    with mpmath.workdps(80):
        for alpha, code in zip(alphas, codes, strict=True):
            roots = polyroots(eq4_chi(alpha, b, gamma, d, delta), maxsteps=400, extraprec=400)
            radius = max(abs(r) for r in roots)
            truth = STABLE if radius < 1 else UNSTABLE
            assert code in (truth, MARGINAL), (alpha, code, mpmath.nstr(radius - 1, 5))


@pytest.mark.parametrize("d", [200, 500])
def test_long_delay_verdicts_match_polished_roots(d):
    """At long delays every point goes to the certified count (O(d) a point).

    d = 500, not 1000 (until issue 41): the same paths of the library (degree over 128, no
    eigenvalues), a tenth of the oracle's cost (numpy's roots and Newton at 30 digits)."""
    alphas = np.array([1e-6, 2e-5, 1e-4, 1e-3]) if d == 200 else np.array([1e-6, 1e-4])
    beta, gamma, delta = 1e-3, 0.0, PAPER_DELTA
    codes = classify(alpha=alphas, beta=beta, gamma=gamma, d=d, delta=delta)
    counts = symstab.numeric.paper.stability.unstable_root_counts(alpha=alphas, beta=beta, gamma=gamma, d=d,
                                                     delta=delta)
    for alpha, code, count in zip(alphas, codes, counts, strict=True):
        expected = _count_outside(alpha, beta, gamma, d, delta, dps=30, near=1e-8)
        assert expected is not None
        assert count == expected
        assert code == (STABLE if expected == 0 else UNSTABLE)


def test_a_point_exactly_on_the_z_equals_1_line_is_marginal():
    # alpha = 0: chi(1) = alpha (b1 + b0) = 0, a root exactly at z = 1, and
    # (beta = 0.3 lies in the region's span) every other root inside.
    for d in (0, 60):
        assert classify(alpha=0.0, beta=0.3 / (d + 1), gamma=0.0, d=d, delta=0.01) == MARGINAL
        assert symstab.numeric.paper.stability.unstable_root_counts(alpha=0.0, beta=0.3 / (d + 1), gamma=0.0,
                                                       d=d, delta=0.01) == -1
    # With another root outside, a root on the circle does not make it marginal.
    assert classify(alpha=0.0, beta=0.5, gamma=0.3, d=7, delta=0.01) == UNSTABLE


def test_classify_a_large_grid_in_bounded_chunks(monkeypatch):
    """A 3000 x 3000 grid passed 4 GB before chunking; here 600 x 600 under a 400 MiB limit.

    The limit is what check_memory enforces on single allocations (the dense
    coefficient array alone would be 600 * 600 * 15 * 8 = 43 MB, the root
    count's arrays several times that); peak memory itself is not measured
    here (tests/cli/test_cli_extremes.py runs long delays under an address-space
    cap).  The verdicts are spot-checked against python-control.
    """
    monkeypatch.setenv("SYMSTAB_MEMORY_LIMIT", "400M")
    alpha = np.linspace(0.0, 0.5, 600)[:, None]
    beta = np.linspace(-0.1, 1.0, 600)[None, :]
    codes = classify(alpha=alpha, beta=beta, gamma=0.0, d=10, delta=PAPER_DELTA)
    assert codes.shape == (600, 600)
    # Spot-check against python-control at a few cells.
    for i, j in ((10, 100), (300, 300), (599, 599), (50, 500)):
        loop = python_control_closed_loop(alpha=float(alpha[i, 0]), beta=float(beta[0, j]),
                                          gamma=0.0, d=10, delta=PAPER_DELTA, m=1.0, T=1.0)
        radius = np.max(np.abs(loop.poles()))
        assert abs(radius - 1) > 1e-9
        assert codes[i, j] == (STABLE if radius < 1 else UNSTABLE)


@pytest.mark.parametrize("alpha", [1e120, 1e150])
def test_root_count_at_the_largest_accepted_stiffness_is_an_integer_or_marginal(alpha):
    """|chi'| ~ alpha squared overflowed in the tangent test before (review finding).

    Oracle: numpy's roots of the (scaled) coefficients, used only where no
    root is within 1e-6 of the circle.
    """
    checked = 0
    for d, delta in ((0, 0.0), (50, 0.0025), (3, 1.0)):
        count = symstab.numeric.paper.stability.unstable_root_counts(alpha=alpha, beta=0.5, gamma=0.0, d=d,
                                                        delta=delta)
        assert -1 <= count <= d + 4
        coeffs = symstab.numeric.paper.stability.loop_coefficients(alpha=alpha, beta=0.5, gamma=0.0, d=d,
                                                     delta=delta)
        moduli = np.abs(np.roots(coeffs / np.max(np.abs(coeffs))))
        if np.min(np.abs(moduli - 1)) > 1e-6:
            assert count == int(np.sum(moduli > 1))
            checked += 1
    assert checked >= 2
