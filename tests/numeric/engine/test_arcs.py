"""The arc sources of symstab.numeric.engine.arcs against a 50-digit mpmath solve.

The oracle solves Re chi = Im chi = 0 for (x, y) at z = exp(j theta) with
mpmath at 50 digits on the same float coefficients the source is given (so
the comparison measures the source's arithmetic, not the rounding of the
coefficients), for the paper's loop and every example loop's default plane.
"""

import glob
import os

import mpmath
import numpy as np
import pytest

import symstab
from symstab.numeric.engine import decomposition
from symstab.numeric.engine.arcs import CramerArc, sine_ratio
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.paper.paper_loop import paper_arc
from symstab.numeric.paper.stability import paper_polynomial

EXAMPLES = sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples",
                                         "loops", "*.toml")))
#: The acceptance test of issue 19: angles in [1e-6, pi - 1e-6].
THETA = np.unique(np.concatenate([np.geomspace(1e-6, 0.1, 25),
                                  np.linspace(0.1, np.pi - 0.1, 60),
                                  np.pi - np.geomspace(1e-6, 0.1, 25)]))
TOLERANCE = 1e-12


def _terms(p):
    flat = p.flat()
    delayed, direct = flat.delayed[0], flat.direct[0]
    return ([(p.shift + len(delayed) - 1 - i, c) for i, c in enumerate(delayed)]
            + [(len(direct) - 1 - i, c) for i, c in enumerate(direct)])


def oracle(polynomials, theta):
    """(x, y, det / sin theta) at each angle, 50 digits, from the float coefficients."""
    terms = [_terms(p) for p in polynomials]
    out = []
    with mpmath.workdps(50):
        for t in theta:
            t = mpmath.mpf(float(t))
            z = mpmath.expj(t)
            a0, cx, cy = (sum(mpmath.mpf(float(c)) * z**k for k, c in tt) for tt in terms)
            det = cx.real * cy.imag - cy.real * cx.imag
            x = (-a0.real * cy.imag + cy.real * a0.imag) / det
            y = (-cx.real * a0.imag + a0.real * cx.imag) / det
            out.append((x, y, det / mpmath.sin(t)))
    return out


def relative_error(xs, ys, reference):
    """max |(x, y) - reference| / max(|x_ref|, |y_ref|) over the angles (norm-wise)."""
    worst = 0.0
    for x, y, (rx, ry, _) in zip(xs, ys, reference, strict=True):
        if not (np.isfinite(x) and np.isfinite(y)):
            return np.inf        # max() would skip a NaN
        scale = max(abs(rx), abs(ry))
        worst = max(worst, float(max(abs(x - rx), abs(y - ry)) / scale))
    return worst


def paper_basis(gamma, d, delta):
    """The paper's (beta, alpha) plane as structured polynomials: base, d/d beta, d/d alpha."""
    at = [paper_polynomial(alpha=a, beta=b, gamma=gamma, d=d, delta=delta)
          for a, b in ((0.0, 0.0), (0.0, 1.0), (1.0, 0.0))]
    base = at[0]
    return (base,) + tuple(DelayedPolynomial(p.delayed - base.delayed, p.direct - base.direct,
                                             base.shift) for p in at[1:])


def loop_basis(path):
    loop = symstab.load_loop(path)
    base, (ax, ay), _ = loop.affine_parts(loop.plane, {}, structured=True)
    return base, ax, ay


BASES = [pytest.param(lambda p=p: loop_basis(p), id=os.path.basename(p)) for p in EXAMPLES] + [
    pytest.param(lambda g=g, d=d, dl=dl: paper_basis(g, d, dl), id=f"paper-gamma{g}-d{d}-delta{dl}")
    for g, d, dl in ((0.0, 10, 0.00253125), (1.5, 0, 0.00253125), (-0.5, 100, 0.01))]


@pytest.mark.parametrize("make", BASES)
def test_cramer_arc_matches_the_50_digit_solve(make):
    polynomials = make()
    reference = oracle(polynomials, THETA)
    xs, ys, det = CramerArc(*polynomials)(THETA)
    assert relative_error(xs, ys, reference) <= TOLERANCE
    # The determinant with sin(theta) divided out, too.
    worst = max(float(abs(v - r[2]) / abs(r[2])) for v, r in zip(det, reference, strict=True))
    assert worst <= TOLERANCE


@pytest.mark.parametrize("path", EXAMPLES, ids=os.path.basename)
def test_loop_arc_matches_the_model_with_exact_coefficients(path):
    # Loop.arc against the 50-digit solve of the loop's own model
    # (oracles.loop_arc_mp): nothing rounded to doubles but the angle.  With
    # the coefficients rounded to doubles first (the Cramer oracle above) the
    # arc is that far off the model next to z = 1 and z = -1, where a plant
    # zero or pole makes the brackets cancel: 1.4e-9 for lowpass_velocity at
    # pi - 1e-6.
    from oracles import loop_arc_mp

    loop = symstab.load_loop(path)
    xs, ys, _ = loop.arc()(THETA)
    reference = [point + (None,) for point in loop_arc_mp(loop, THETA)]
    assert relative_error(xs, ys, reference) <= TOLERANCE


@pytest.mark.parametrize("name", ["lowpass_velocity.toml", "paper.toml"])
def test_stable_interval_ends_on_the_arc_match_the_model(name):
    # Where the line B = const leaves the stable set across the arc (at
    # theta of about 0.01 for these loops at d = 40), the line engine's
    # crossing is re-found on Loop.arc: 9e-12 off the model before, found on
    # the float parts.  Oracle: the crossing of the 40-digit arc of the model.
    from oracles import loop_arc_mp

    loop = symstab.load_loop(os.path.join(os.path.dirname(EXAMPLES[0]), name))
    x, y = loop.plane
    lim = loop.limits()
    at = lim.x_min + 0.1 * (lim.x_max - lim.x_min)
    top = max(hi for _, hi in loop.stable_intervals(y, **{x: at}))
    theta = np.linspace(1e-4, 0.2, 2001)
    xs = loop.arc()(theta)[0] - at
    i = int(np.flatnonzero(np.sign(xs[1:]) * np.sign(xs[:-1]) < 0)[0])
    with mpmath.workdps(40):
        t = mpmath.findroot(lambda t: loop_arc_mp(loop, [t], dps=40)[0][0] - at,
                            (mpmath.mpf(theta[i]), mpmath.mpf(theta[i + 1])), solver="anderson")
        want = loop_arc_mp(loop, [t], dps=40)[0][1]
    assert abs(top - want) <= 1e-13 * abs(want), (top, want)


@pytest.mark.parametrize("make", BASES)
def test_dense_rows_give_the_same_arc(make):
    # A dense row is one part (shift 0): the same accuracy, more terms per angle.
    polynomials = make()
    reference = oracle(polynomials, THETA)
    xs, ys, _ = CramerArc(*(p.dense().reshape(-1) for p in polynomials))(THETA)
    assert relative_error(xs, ys, reference) <= TOLERANCE


def test_sine_ratio_against_mpmath():
    m = np.array([1, 2, 3, 7, 40, 41, 1001, 5004])
    with mpmath.workdps(50):
        for t in (1e-9, 1e-6, 1e-3, 0.7, 1.5, 1.6, np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9):
            got = sine_ratio(m, t)
            tt = mpmath.mpf(float(t))
            want = [mpmath.sin(int(k) * tt) / mpmath.sin(tt) for k in m]
            for g, w in zip(got, want, strict=True):
                assert abs(g - w) <= 4e-16 * (1 + abs(int(m[-1]) * tt)) * max(1, abs(w)), (t, g, w)


def test_sine_ratio_at_the_ends_is_its_limit():
    # sin(m theta)/sin(theta) -> m at 0 and (-1)**(m + 1) m at pi (U_{m-1}(+-1));
    # at theta = 0 the quotient was 0/0 = NaN with a RuntimeWarning.  np.pi
    # is 1.2e-16 short of pi: there the quotient of two sines, each to its
    # last bit, is the limit to rounding.
    m = np.array([1, 2, 3, 40, 41])
    assert sine_ratio(m, 0.0).tolist() == [1, 2, 3, 40, 41]
    limit = np.array([1, -2, 3, -40, 41])
    assert np.all(np.abs(sine_ratio(m, np.pi) - limit) <= 4e-16 * np.abs(limit))


@pytest.mark.parametrize("gamma, d, delta", [(0.0, 10, 0.00253125), (-0.5, 40, 0.1),
                                             (1.5, 1, 2.0), (0.5, 200, 1e-5)])
def test_paper_loops_closed_form_arc_matches_the_printed_model_on_the_whole_circle(gamma, d, delta):
    # PAPER_LOOP's arc hook in Table I's variables (m = T = 1: B = beta,
    # K = alpha), against the 50-digit solve of the printed eqs. (1), (2),
    # (4): exact coefficients, not the rounded ones the Cramer oracle uses.
    from symstab.numeric.paper.paper_loop import closed_form_arc, paper_point

    from oracles import first_principles_boundary_point

    _, values = paper_point(gamma=gamma, d=d, delta=delta)
    beta, alpha = closed_form_arc("B", "K", values)(THETA)
    with mpmath.workdps(50):
        reference = [first_principles_boundary_point(float(t), gamma, d, delta)[::-1] + (None,)
                     for t in THETA]
    assert relative_error(beta, alpha, reference) <= TOLERANCE


def test_closed_form_is_the_paper_arc():
    # The paper's arc source (the closed form of the generated kernel, with
    # PAPER_LOOP's determinant) is the same arc as the structured solve of
    # the paper's polynomial: the points differ by the rounding of the
    # polynomial's coefficients (to 1e-9 here), the determinants (the same
    # polynomial up to a positive factor) have the same sign.
    gamma, d, delta = 0.0, 10, 0.00253125
    theta = THETA[(THETA > 1e-3) & (THETA < 3.0)]
    bx, ay_, det = paper_arc(gamma=gamma, d=d, delta=delta)(theta)
    cx, cy, cdet = CramerArc(*paper_basis(gamma, d, delta))(theta)
    assert np.array_equal(np.sign(det), np.sign(cdet)) and np.all(det != 0)
    scale = np.maximum(np.abs(cx), np.abs(cy))
    assert np.max(np.maximum(np.abs(bx - cx), np.abs(ay_ - cy)) / scale) < 1e-9


def test_singular_determinant_gives_nan():
    # ax and ay proportional: the system is singular at every angle.
    base = np.array([1.0, 0.3, 0.2])
    ax = np.array([0.0, 1.0, 0.5])
    xs, ys, det = CramerArc(base, ax, 2 * ax)(np.array([0.1, 1.0, 3.0]))
    assert np.all(np.isnan(xs)) and np.all(np.isnan(ys))
    assert np.all(det == 0)


def test_bad_input():
    with pytest.raises(ValueError, match="finite"):
        CramerArc(np.array([1.0, np.nan]), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match="one non-empty row"):
        CramerArc(np.ones((2, 2)), np.array([1.0, 0.0]), np.array([0.0, 1.0]))
    with pytest.raises(ValueError, match="common shift"):
        CramerArc(DelayedPolynomial([1.0], [1.0], 3), DelayedPolynomial([1.0], [0.0], 2),
                  DelayedPolynomial([0.0], [1.0], 3))


@pytest.mark.parametrize("make", BASES)
def test_arc_points_of_dense_rows_match_the_50_digit_solve(make):
    # decomposition.arc_points (the plane's public arc) takes its arc from arcs.py.
    polynomials = make()
    reference = oracle(polynomials, THETA)
    xs, ys, _ = decomposition.arc_points(*(p.dense().reshape(-1) for p in polynomials), THETA)
    assert relative_error(xs, ys, reference) <= TOLERANCE
