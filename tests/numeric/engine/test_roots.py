"""The one root engine (symstab.numeric.engine.roots) on structured polynomials.

Oracles: mpmath's polyroots at 50 digits of the same (exactly represented)
coefficients, and python-control's poles of the paper's closed loop.
"""

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from symstab.numeric.engine import roots
from symstab.numeric.engine.polynomial import DelayedPolynomial
from symstab.numeric.paper.stability import paper_polynomial


def _exact_moduli(chi):
    """Root moduli of each row at 50 digits (the float coefficients taken as exact)."""
    out = []
    for row in chi.flat().dense():
        row = list(row)
        zeros = 0
        while row and row[-1] == 0:        # roots at 0, which polyroots does not converge on
            row.pop()
            zeros += 1
        with mpmath.workdps(50):
            r = mpmath.polyroots([mpmath.mpf(float(c)) for c in row], maxsteps=400,
                                 extraprec=600) if len(row) > 1 else []
            out.append(sorted([abs(x) for x in r] + [mpmath.mpf(0)] * zeros, reverse=True))
    return out


def _count_oracle(moduli, gap=1e-8):
    """Roots outside, or None where one is within ``gap`` of the circle (left to the marginal test)."""
    if min(abs(m - 1) for m in moduli) < gap:
        return None
    return sum(1 for m in moduli if m > 1)


# Coefficients 0 or of modulus >= 1e-3 (a 1e-255 coefficient puts a root at
# 1e-255, where a relative test of the radius means nothing).
coefficient = st.floats(-3, 3, allow_nan=False).map(lambda c: 0.0 if abs(c) < 1e-3 else c)
structured = st.builds(
    lambda s, d, n, scale: DelayedPolynomial(d, [c * scale for c in n], s),
    st.integers(0, 40),
    st.lists(coefficient, min_size=1, max_size=5).filter(lambda c: c[0] != 0),
    st.lists(coefficient, min_size=1, max_size=5),
    st.sampled_from([1e-3, 0.1, 1.0, 10.0]),
).filter(lambda chi: chi.shift + chi.delayed.shape[-1] > chi.direct.shape[-1])


@settings(max_examples=25, deadline=None)
@given(structured)
def test_root_counts_and_spectral_radius_match_50_digit_roots(chi):
    """The count and the radius against the same 50-digit roots (one test since issue 41: the
    two tests computed the same roots of polynomials drawn from the same strategy)."""
    moduli = _exact_moduli(chi)[0]
    expected = _count_oracle(moduli)
    got = int(roots.root_counts(chi))
    if expected is None:
        assert got in (-1, sum(1 for m in moduli if m > 1))
    else:
        assert got == expected
    radius = float(moduli[0])
    assert abs(float(roots.spectral_radius(chi)) - radius) <= 1e-9 * radius


def _largest_root_mp(chi):
    """|z| of the largest root: Newton steps at 50 digits from numpy's roots.

    numpy's roots serve only as the start; the dense coefficients are exact
    as floats.
    """
    c = chi.flat().dense()[0]
    start = np.roots(c)
    z0 = start[np.argmax(np.abs(start))]
    with mpmath.workdps(50):
        z = mpmath.mpc(complex(z0))
        coeffs = [mpmath.mpf(float(x)) for x in c]
        for _ in range(8):
            value, slope = mpmath.polyval(coeffs, z, derivative=True)
            z -= value / slope
        return float(abs(z))


@pytest.mark.parametrize("d", [150, 400])
def test_long_delay_radius_without_eigenvalues(d):
    """The structured radius (degree > 128) against polished 50-digit roots near the largest."""
    chi = paper_polynomial(alpha=2e-5, beta=0.004, gamma=0.3, d=d, delta=0.00253125)
    expected = _largest_root_mp(chi)
    assert abs(float(roots.spectral_radius(chi)) - expected) <= 1e-12 * expected


def test_the_structured_radius_is_a_root_not_newtons_last_step():
    """A largest root next to z = 1 at a small angle (T = 10 us, d = 129).

    Newton's last iterate was accepted with only "no root outside it"
    checked: 1.0000162 for a radius of 1.000000000002.  Evaluating chi in
    double precision so close to z = 1 leaves about 1e-10.
    """
    m, b, T, B, K = 0.0128, 0.0324, 1e-5, 0.02, 40.45783066836089
    chi = paper_polynomial(alpha=K * T**2 / m, beta=B * T / m, gamma=0.0, d=129, delta=b * T / m)
    expected = _largest_root_mp(chi)
    assert abs(float(roots.spectral_radius(chi)) - expected) <= 1e-9 * expected


def test_a_polish_does_not_jump_from_a_double_root_to_another():
    """[1, -2, 1, -5e-37, 0]: Newton from the double root at 1 jumped to the root 0 (radius 0)."""
    chi = np.array([[1.0, -2.0, 1.0, -5e-37, 0.0]])
    assert float(roots.spectral_radius(chi)[0]) == pytest.approx(1.0, abs=1e-7)


def test_near_one_form_keeps_counts_next_to_z_equal_1():
    """With D in powers of z - 1 the paper's count decides 1e-12 from its boundary at tiny delta."""
    alpha = 1e-9 * np.array([1 - 1e-9, 1 + 1e-9])
    chi = paper_polynomial(alpha=alpha, beta=0.0, gamma=0.0, d=3, delta=1e-9)
    got = roots.root_counts(chi)
    moduli = _exact_moduli(chi)
    for g, m in zip(got, moduli, strict=True):
        expected = _count_oracle(m, gap=0)
        assert g in (expected, -1)
    dense = roots.root_counts(DelayedPolynomial.from_dense(chi.dense()))
    # The z-basis evaluation may only be less decided, never different.
    assert np.all((dense == got) | (dense == -1))


def test_leading_coefficient_is_judged_against_its_own_part():
    """A huge direct part does not make the exact leading 1 'vanish' (alpha = 1e150)."""
    chi = paper_polynomial(alpha=1e150, beta=0.5, gamma=0.0, d=50, delta=0.0025)
    assert not roots.leading_vanishes(chi)
    vanishing = DelayedPolynomial([1e-30, 1.0], [2.0], 0)         # 1e-30 z + 3
    assert roots.leading_vanishes(vanishing)
    assert int(roots.root_counts(vanishing)) == -1


def test_paper_counts_match_python_control_poles():
    control = pytest.importorskip("control")
    m, b, T = 0.0128, 0.0324, 1e-3
    for d, K, B in [(0, 300.0, 0.5), (5, 40.0, 0.05), (40, 3.0, 0.01), (40, 6.0, 0.01)]:
        plant = control.c2d(control.tf([1.0], [m, b, 0.0]), T, "zoh")
        z = control.tf([1.0, 0.0], [1.0], T)
        env = K + B * (z - 1) / (T * z)
        loop = control.feedback(plant * control.tf([1.0], [1.0] + [0.0] * d, T) * env, 1)
        expected = int(np.sum(np.abs(control.poles(loop)) > 1))
        delta = b * T / m
        got = int(roots.root_counts(paper_polynomial(alpha=K * T**2 / m, beta=B * T / m, gamma=0.0,
                                                     d=d, delta=delta)))
        assert got == expected


def test_classify_agrees_with_counts_across_the_schur_cohn_threshold():
    rng = np.random.default_rng(7)
    alpha, beta = rng.uniform(-0.2, 0.2, 400), rng.uniform(-0.5, 1.0, 400)
    for d in (40, 47, 48, 60):
        chi = paper_polynomial(alpha=alpha * 1e-2, beta=beta * 1e-1, gamma=0.2, d=d, delta=0.0025)
        codes = roots.classify_polynomials(chi)
        counts = roots.root_counts(chi)
        decided = counts >= 0
        assert np.array_equal(codes[decided] == roots.STABLE, counts[decided] == 0)


def test_bad_input_is_refused():
    with pytest.raises(TypeError, match="DelayedPolynomial"):
        roots.root_counts(np.ones((2, 3)))
    with pytest.raises(ValueError, match="shift"):
        DelayedPolynomial([1.0], [1.0], -1)
    with pytest.raises(ValueError, match="radius"):
        DelayedPolynomial([1.0], [1.0], 2).on_radius(0.0)
