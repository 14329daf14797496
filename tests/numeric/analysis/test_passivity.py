"""Colgate and Schenkel's passive set (symstab.numeric.analysis.passivity) against independent oracles.

Oracles:

* closed forms derived by hand (in the module docstring and here): the
  virtual wall ``K + B (1 - 1/z)/T`` at ``d = 0`` is passive iff ``b > K T/2
  + |B|`` (Colgate and Schenkel's result), so the set is the triangle with
  corners ``(B, K) = (-b, 0), (b, 0), (0, 2 b/T)``; a spring behind ``d``
  samples is passive iff ``0 <= K <= 2 b / ((2 d + 1) T)``; a virtual mass
  alone (``d = 0``) iff ``-8 b T/9 < M < b T/2``;
* a brute-force check: the printed condition ``T / (2 (1 - cos w T)) Re{(1 -
  e^{-j w T}) H(e^{j w T})}`` evaluated with mpmath at 30 digits on a dense
  sweep of ``w``, with ``H`` written here from the environment's formula
  (not from the module's cosine series), at random points of the plane;
  points whose margin is within the sweep's resolution are skipped.  The
  condition is linear in the parameters: each one's coefficient is swept
  at 30 digits once per test (where the cancellation next to ``w = 0`` is),
  and a point's sum of them is taken in floats, whose rounding is bounded
  and asserted below 1e-6 of the damping, far inside the skipped band.
"""

import functools
import math

import mpmath
import numpy as np
import pytest

import symstab
from symstab.numeric.analysis.passivity import PassiveRegion, passive_region
from symstab.numeric.paper.paper_loop import paper_passive_region

from conftest import PAPER_B, PAPER_DELTA, PAPER_M, PAPER_T, REPO

PAPER_ENVIRONMENT = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"


def paper_loop(**values):
    defaults = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T, d=0, M=0.0)
    defaults.update(values)
    return symstab.Loop("1/(m*s**2 + b*s)", PAPER_ENVIRONMENT, plane=("B", "K"), values=defaults)


# --------------------------------------------------------------------------
# The brute-force oracle


def _one_minus_inverse(theta):
    """``1 - exp(-j theta) = 2 j sin(theta/2) exp(-j theta/2)``, without the cancellation of
    ``1 - cos(theta)`` next to 0 (at theta = 1e-12 it leaves 6 of 30 digits)."""
    return 2j * mpmath.sin(theta / 2) * mpmath.expj(-theta / 2)


def _angle_terms(environment_terms, T, d, thetas):
    """Per angle of ``thetas``, the coefficient of each parameter in the printed right-hand side.

    ``environment_terms(u, z)`` returns ``{name: H_name(z)}``, the part of
    ``VE(z)`` multiplying each parameter (``u = 1 - 1/z``); the delay and the
    factor ``T / (2 (1 - cos theta)) Re{(1 - e^{-j theta}) ...}`` are applied
    here, at 30 digits.
    """
    out = []
    with mpmath.workdps(30):
        for theta in thetas:
            z = mpmath.expj(theta)
            u = _one_minus_inverse(theta)
            weight = T / (4 * mpmath.sin(theta / 2)**2)
            delay = mpmath.expj(-d * theta)
            out.append({name: weight * mpmath.re(u * h * delay)
                        for name, h in environment_terms(u, z).items()})
    return out


def sweep_terms(environment_terms, T, d, n=3000):
    """``{name: coefficients}`` on the sweep ``theta = pi k / n``, ``k = 1..n``.

    Each coefficient is computed at 30 digits (:func:`_angle_terms`) and
    rounded to a float: the margin at a point (:func:`worst_margin`) is their
    sum weighted by the point's (float) values.
    """
    with mpmath.workdps(30):
        thetas = [mpmath.pi * k / n for k in range(1, n + 1)]
    terms = _angle_terms(environment_terms, T, d, thetas)
    return {name: np.array([float(t[name]) for t in terms]) for name in terms[0]}


def worst_margin(terms, point, damping):
    """``max_theta RHS - damping`` at ``point`` (a dict of the parameters) on the sweep.

    The sum over the parameters is taken in floats: each coefficient carries
    one rounding of its 30-digit value and each product and sum one more, so
    the sum is within ``(2 + number of parameters)`` units of rounding of the
    sum of the terms' sizes, asserted here to be below 1e-6 of the damping
    (the verdicts skip margins within 2e-3 of it).
    """
    products = np.array([terms[name] * point[name] for name in terms])
    rounding = (2 + len(products)) * 2.0**-53 * float(np.abs(products).sum(axis=0).max())
    assert rounding < 1e-6 * damping, (point, rounding)
    return float(products.sum(axis=0).max() - damping)


def check_against_sweep(region, terms, damping, fixed, static, rng, n_points=60, box=None):
    """contains() agrees with the sweep at random points of ``box`` (default the window)."""
    (x0, x1), (y0, y1) = box or (region.x_range, region.y_range)
    xs = rng.uniform(x0, x1, n_points)
    ys = rng.uniform(y0, y1, n_points)
    passive = region.contains(xs, ys)
    decided = {True: 0, False: 0}
    for x, y, verdict in zip(xs, ys, passive, strict=True):
        point = dict(fixed, **{region.x: x, region.y: y})
        margin = worst_margin(terms, point, damping)
        if abs(margin) < 2e-3 * damping or abs(static(point)) < 1e-9:
            continue    # within the sweep's resolution of the boundary
        truth = margin < 0 and static(point) > 0
        assert verdict == truth, (point, margin)
        decided[truth] += 1
    # Both sides of the boundary were exercised.
    assert decided[True] >= 3 and decided[False] >= 3, decided


def paper_terms(u, z):
    return {"K": 1, "B": u / PAPER_T, "M": u**2 / PAPER_T**2}


# --------------------------------------------------------------------------
# Closed forms


def test_virtual_wall_is_colgate_and_schenkels_triangle():
    region = passive_region(paper_loop(), d=0)
    b, T = PAPER_B, PAPER_T
    expected = np.array([[0.0, 2 * b / T], [-b, 0.0], [b, 0.0]])
    assert region.bounded and len(region.polygon) == 3
    for corner in expected:
        distance = np.min(np.abs(region.polygon - corner) / [b, 2 * b / T], axis=0)
        assert np.all(distance < 1e-9), (corner, region.polygon)
    assert region.area == pytest.approx(2 * b**2 / T, rel=1e-9)
    assert region.y_max == pytest.approx(2 * b / T, rel=1e-13)
    assert abs(region.x_at_y_max) < 1e-9 * b
    # Counter-clockwise.
    assert region.area > 0


@pytest.mark.parametrize("d", [1, 3, 10])
def test_delayed_spring_loses_kt_of_damping_per_sample(d):
    region = passive_region(paper_loop(d=d))
    k_max = 2 * PAPER_B / ((2 * d + 1) * PAPER_T)
    inside = region.contains([0.0, 0.0, 0.0], [1e-6 * k_max, k_max * (1 - 1e-5), k_max * (1 + 1e-5)])
    assert inside.tolist() == [True, True, False]
    # theta = 0 gives K T (2 d + 1)/2 - B < b everywhere on the set (the
    # damper helps): every vertex obeys it, and the passive K_max exceeds
    # the spring's alone.
    K, B = region.polygon[:, 1], region.polygon[:, 0]
    assert np.all(K * PAPER_T * (2 * d + 1) / 2 - B <= PAPER_B * (1 + 1e-6))
    assert region.y_max > k_max * 1.01


@pytest.mark.parametrize("d", [0, 5, 40])
def test_paper_set_scales_with_the_damping(d):
    """At gamma = 0 the condition is homogeneous in (alpha, beta, delta): region(delta) = delta region(1).

    A fixed unit of 1 in the scaled plane lost the set to rounding for
    delta <= 1e-6 (empty at d = 0, area/delta**2 = 2e-8 instead of 0.30 at
    d = 5).  Closed forms: at beta = 0 the set is the delayed spring's,
    0 <= alpha < 2 delta / (2 d + 1); at d = 0 it is alpha/2 + |beta| < delta,
    of area 2 delta**2 and alpha_max = 2 delta.
    """
    reference = paper_passive_region(gamma=0.0, d=d, delta=1.0)
    for delta in (1e-12, 1e-9, 1e-6, 1.0):
        # delta = 1 is the reference itself (computed once: the same call).
        region = reference if delta == 1.0 else paper_passive_region(gamma=0.0, d=d, delta=delta)
        assert not region.empty and region.bounded, (delta, region)
        spring = 2 * delta / (2 * d + 1)
        inside = region.contains([0.0] * 3, [1e-3 * spring, spring * (1 - 1e-5), spring * (1 + 1e-5)])
        assert inside.tolist() == [True, True, False], (delta, region)
        assert region.area / delta**2 == pytest.approx(reference.area, rel=1e-9), delta
        assert region.y_max / delta == pytest.approx(reference.y_max, rel=1e-9), delta
        if d == 0:
            assert region.area == pytest.approx(2 * delta**2, rel=1e-9)
            assert region.y_max == pytest.approx(2 * delta, rel=1e-12)


def test_loop_set_of_a_tiny_damping_is_the_wall_triangle():
    """b = 1e-12 with examples/loops/paper.toml's defaults K = 2, B = 0.1: K_max = 2 b / T.

    The defaults once set the plane's unit, 1e11 times the set's size: the
    set came out empty.
    """
    b = 1e-12
    loop = symstab.load_loop(REPO / "examples" / "loops" / "paper.toml")
    region = passive_region(loop, b=b, d=0, M=0.0)
    assert region.y_max == pytest.approx(2 * b / PAPER_T, rel=1e-9)
    assert region.area == pytest.approx(2 * b**2 / PAPER_T, rel=1e-9)


def test_virtual_mass_alone():
    loop = symstab.Loop("1/(m*s**2 + b*s)", PAPER_ENVIRONMENT, plane=("M", "K"),
                        values=dict(m=PAPER_M, b=PAPER_B, T=PAPER_T, d=0, B=0.0))
    region = passive_region(loop)
    upper, lower = PAPER_B * PAPER_T / 2, -8 * PAPER_B * PAPER_T / 9
    ms = [upper * (1 - 1e-5), upper * (1 + 1e-5), lower * (1 - 1e-5), lower * (1 + 1e-5)]
    assert region.contains(ms, [0.0] * 4).tolist() == [True, False, True, False]


def test_negative_static_stiffness_is_not_passive():
    # The frequency condition holds at K = -1 N/m, B = 0 (K T/2 < b), but a
    # slow pull returns |K| x**2 / 2 of energy: not passive.
    terms = sweep_terms(paper_terms, PAPER_T, 0, n=200)
    assert worst_margin(terms, {"K": -1.0, "B": 0.0, "M": 0.0}, PAPER_B) < 0
    region = passive_region(paper_loop(), d=0)
    assert region.contains([0.0, 0.0], [-1.0, 1.0]).tolist() == [False, True]


# --------------------------------------------------------------------------
# Against the brute-force sweep


@pytest.mark.parametrize("d, M", [(0, 0.0), (1, 0.0), (4, 2e-6), (10, -4e-6)])
def test_physical_loop_against_the_sweep(d, M):
    rng = np.random.default_rng(1200 + d)
    region = passive_region(paper_loop(d=d, M=M))
    terms = sweep_terms(paper_terms, PAPER_T, d)
    k_scale = 2 * PAPER_B / PAPER_T / (d + 1)
    check_against_sweep(region, terms, PAPER_B, {"M": M}, lambda p: p["K"], rng,
                        box=((-1.5 * PAPER_B, 1.5 * PAPER_B), (-0.1 * k_scale, 1.5 * k_scale)))


@pytest.mark.parametrize("gamma, d", [(0.0, 2), (0.3 * PAPER_DELTA, 5), (-0.6 * PAPER_DELTA, 1)])
def test_paper_normalised_form_against_the_sweep(gamma, d):
    # delta > 1/(2 (1 - cos th)) Re{(1 - e^{-j th}) (alpha + beta u + gamma u**2) e^{-j th d}}:
    # the physical condition times T/m, T = 1 here.
    delta = PAPER_DELTA
    region = paper_passive_region(gamma=gamma, d=d, delta=delta)
    assert not region.empty
    terms = sweep_terms(lambda u, z: {"alpha": 1, "beta": u, "gamma": u**2}, 1.0, d)
    rng = np.random.default_rng(77 + d)
    check_against_sweep(region, terms, delta, {"gamma": gamma}, lambda p: p["alpha"], rng)


@pytest.mark.parametrize("d", [0, 2])
def test_filtered_velocity_environment_against_the_sweep(d):
    # A pole inside the circle: the damper on a low-pass filtered velocity.
    # At d = 0 the Laurent polynomial N(z) D(1/z) has a positive power (the
    # -D_{k-1} terms of the series).
    loop = symstab.load_loop(REPO / "examples" / "loops" / "lowpass_velocity.toml")
    f_c = 50.0
    region = passive_region(loop, d=d)
    a = mpmath.exp(-2 * mpmath.pi * f_c * PAPER_T)
    terms = sweep_terms(lambda u, z: {"K": 1, "B": (1 - a) * (z - 1) / (PAPER_T * (z - a))},
                        PAPER_T, d)
    rng = np.random.default_rng(5 + d)
    check_against_sweep(region, terms, PAPER_B, {}, lambda p: p["K"], rng)


@functools.lru_cache(maxsize=None)
def _refinement_grid(environment_terms, T, d, n):
    """``(grid, terms)``: the midpoints ``pi (k + 1/2)/n`` and their 30-digit coefficients.

    The same for every vertex of a region: computed once per delay.
    """
    with mpmath.workdps(30):
        grid = [mpmath.pi * (k + mpmath.mpf(1) / 2) / n for k in range(n)]
    return grid, _angle_terms(environment_terms, T, d, grid)


def refined_worst_margin(environment_terms, point, damping, T, d, n=2000):
    """``max_theta RHS - damping`` at 30 digits: the sweep, then a golden-section search
    around its three best local maxima (an end point counts as one).

    Each step keeps one of its two inner points and its value (the golden ratio puts it
    where the next step's other point goes): one evaluation a step, not two (until issue 41).
    """
    def rhs(theta):
        z = mpmath.expj(theta)
        u = _one_minus_inverse(theta)
        h = sum(mpmath.mpf(point[name]) * term
                for name, term in environment_terms(u, z).items())
        return T / (4 * mpmath.sin(theta / 2)**2) * mpmath.re(u * h * mpmath.expj(-d * theta))

    grid, terms = _refinement_grid(environment_terms, T, d, n)
    with mpmath.workdps(30):
        names = list(terms[0])
        weights = [mpmath.mpf(point[name]) for name in names]
        values = [mpmath.fdot([t[name] for name in names], weights) for t in terms]
        peaks = [k for k in range(n) if (k == 0 or values[k] >= values[k - 1])
                 and (k == n - 1 or values[k] >= values[k + 1])]
        peaks.sort(key=lambda k: -values[k])
        best = max(values)
        ratio = (mpmath.sqrt(5) - 1) / 2
        for k in peaks[:3]:
            a = grid[k - 1] if k else mpmath.mpf(10) ** -12
            b = grid[k + 1] if k < n - 1 else mpmath.pi
            x1, x2 = b - ratio * (b - a), a + ratio * (b - a)
            f1, f2 = rhs(x1), rhs(x2)
            for _ in range(90):
                if f1 < f2:
                    a, x1, f1 = x1, x2, f2
                    x2 = a + ratio * (b - a)
                    f2 = rhs(x2)
                else:
                    b, x2, f2 = x2, x1, f1
                    x1 = b - ratio * (b - a)
                    f1 = rhs(x1)
            best = max(best, rhs((a + b) / 2))
        return float(best - damping)


@pytest.mark.parametrize("d", [4, 300])
def test_vertices_lie_within_the_tolerance_of_the_boundary(d):
    # Every vertex of the polygon is outside the passive set of b (it is an
    # intersection of half-planes the set obeys) and inside that of
    # b (1 + 1e-6) (the cutting planes' tolerance): -rounding <= margin <= 1e-6 b.
    # A grid of angles alone leaves vertices 1e-5 b out on the curved parts.
    # At d = 300 the condition is evaluated as a sum of Dirichlet kernels in
    # closed form, not as a cosine series of 300 terms.
    M = 2e-6
    region = passive_region(paper_loop(d=d, M=M))
    assert len(region.polygon) > 50        # the boundary is curved here
    rng = np.random.default_rng(3)
    for vertex in region.polygon[rng.choice(len(region.polygon), 12, replace=False)]:
        point = {"B": vertex[0], "K": vertex[1], "M": M}
        margin = refined_worst_margin(paper_terms, point, PAPER_B, PAPER_T, d)
        if abs(vertex[1]) < 1e-9:
            assert margin <= 1.01e-6 * PAPER_B     # on K = 0: the static edge
        else:
            assert -1e-12 * PAPER_B <= margin <= 1.01e-6 * PAPER_B, (vertex, margin)


def test_physical_and_normalised_forms_agree():
    d, gamma = 3, 0.2 * PAPER_DELTA
    physical = passive_region(paper_loop(d=d, M=gamma * PAPER_M))
    normal = paper_passive_region(gamma=gamma, d=d, delta=PAPER_DELTA)
    assert physical.y_max * PAPER_T**2 / PAPER_M == pytest.approx(normal.y_max, rel=1e-6)
    assert physical.x_at_y_max * PAPER_T / PAPER_M == pytest.approx(normal.x_at_y_max, rel=1e-3)
    scale = (PAPER_T / PAPER_M) * (PAPER_T**2 / PAPER_M)
    assert physical.area * scale == pytest.approx(normal.area, rel=1e-6)


# --------------------------------------------------------------------------
# Windows, unbounded sets, the dataclass


def test_unbounded_set_is_clipped_and_flagged():
    # The damping as an axis: b >= K T (2 d + 1)/2, K >= 0 is a cone.
    region = passive_region(paper_loop(d=2), x="b", y="K", B=0.0)
    assert not region.bounded and math.isinf(region.y_max)
    (x0, x1), (y0, y1) = region.x_range, region.y_range
    # Clipped to its window on every side.
    assert np.all(region.polygon[:, 0] >= x0 - 1e-12) and np.all(region.polygon[:, 1] <= y1 + 1e-9)
    assert np.all(region.polygon[:, 0] <= x1 + 1e-12) and np.all(region.polygon[:, 1] >= y0 - 1e-9)
    b = 0.02
    k = 2 * b / (5 * PAPER_T)
    assert region.contains([b, b], [k * (1 - 1e-6), k * (1 + 1e-6)]).tolist() == [True, False]


def test_a_window_that_cuts_the_set_is_flagged():
    region = passive_region(paper_loop(), d=0, x_range=(-1.0, 1.0), y_range=(0.0, 10.0))
    assert not region.bounded
    assert region.polygon[:, 1].max() == pytest.approx(10.0)
    assert region.y_max == pytest.approx(2 * PAPER_B / PAPER_T)
    whole = passive_region(paper_loop(), d=0, x_range=(-1.0, 1.0), y_range=(-1.0, 100.0))
    assert whole.bounded and whole.area == pytest.approx(2 * PAPER_B**2 / PAPER_T, rel=1e-9)


def test_empty_set():
    # At d = 0, theta = pi gives alpha/2 + beta + 2 gamma <= delta and theta = 0
    # gives alpha/2 - beta <= delta; their sum and alpha >= 0 need gamma <= delta.
    region = paper_passive_region(gamma=0.5, d=0, delta=PAPER_DELTA)
    assert region.empty and region.polygon.shape == (0, 2) and region.area == 0.0
    # None, as an empty Limits says (it was NaN)
    assert region.y_max is None and region.x_at_y_max is None and "no passive point" in repr(region)
    assert not region.contains(0.0, 0.0)


def test_repr_and_contains_shapes():
    region = paper_passive_region(gamma=0.0, d=1, delta=PAPER_DELTA)
    assert isinstance(region, PassiveRegion)
    text = repr(region)
    assert text.startswith("PassiveRegion(alpha_max=") and "bounded" in text
    assert region.contains(np.zeros((2, 3)), 1e-4).shape == (2, 3)
    # Counter-clockwise: positive signed area.
    x, y = region.polygon.T
    assert np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0


# --------------------------------------------------------------------------
# Refusals


@pytest.mark.parametrize("make, kwargs, error, words", [
    (lambda: symstab.load_loop(REPO / "examples" / "loops" / "frictionless.toml"), {},
     ValueError, "damping"),
    (lambda: symstab.load_loop(REPO / "examples" / "loops" / "actuator_lag.toml"), {},
     ValueError, "1/(m*s**2 + b*s)"),
    (lambda: paper_loop(), {"damping": "m"}, ValueError, "1/(m*s**2 + m*s)"),
    (lambda: paper_loop(), {"x": "m", "y": "K"}, ValueError, "'m' does not enter"),
    (lambda: paper_loop(), {"x": "T", "y": "K"}, ValueError, "x: 'T'"),
    (lambda: paper_loop(), {"nonsense": 1.0}, TypeError, "nonsense"),
    (lambda: paper_loop(), {"b": -1.0}, ValueError, "b must be"),
    (lambda: paper_loop(), {"d": 1, "Td": 1e-3}, TypeError, "give the delay once"),
    (lambda: paper_loop(), {"x_range": (1.0, 0.0), "y_range": (0.0, 1.0)}, ValueError, "x_range"),
    (lambda: paper_loop(), {"x_range": (0.0, 1.0)}, ValueError, "y_range"),
    (lambda: symstab.Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(z - a)", plane=("B", "K"),
                          values=dict(m=1.0, b=1.0, T=1e-3, d=0, a=0.5, B=1.0)),
     {"x": "a", "y": "K"}, ValueError, "'a'"),
    (lambda: symstab.Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(z - a)", plane=("B", "K"),
                          values=dict(m=1.0, b=1.0, T=1e-3, d=0, a=1.5)),
     {}, ValueError, "stable H(z)"),
    (lambda: symstab.Loop("1/(m*s**2 + b*s)", "K*B + B*(z - 1)/z",
                          values=dict(m=1.0, b=1.0, T=1e-3, d=0)),
     {"x": "B", "y": "K"}, ValueError, "affinely"),
])
def test_refusals_name_the_fault(make, kwargs, error, words):
    with pytest.raises(error, match=None) as info:
        passive_region(make(), **kwargs)
    assert words in str(info.value)


def test_paper_refusals():
    with pytest.raises(ValueError, match="delta"):
        paper_passive_region(gamma=0.0, d=0, delta=0.0)
    with pytest.raises(ValueError, match="delay d"):
        paper_passive_region(gamma=0.0, d=-1, delta=0.1)
    with pytest.raises(TypeError, match="gamma"):
        paper_passive_region(gamma="1", d=0, delta=0.1)
