"""Colgate and Schenkel's passive set with a fractional loop delay ``(d + eps) T`` against oracles.

Oracles:

* the lifted quadratic form (:func:`oracles.lifted_least_damping`): each
  period cut into ``N`` sub-intervals, the least passive damping at an
  angle is an ``N x N`` eigenvalue, with ``H`` evaluated from the
  environment's coefficients (numpy) or by python-control; nothing of the
  module's 2x2 reduction or its Dirichlet kernels;
* a closed form derived here: a spring ``K`` behind ``(d + eps) T`` at
  ``theta = 0`` (where the lifted form is largest) has ``R = -K (2 d + 1)/2``
  and ``h = K``, so its least damping is ``K c`` with ``c`` the larger root of
  ``(c - eps T (2 d + 3)/2)(c - (1 - eps) T (2 d + 1)/2) = eps (1 - eps) T**2
  (d + 1)**2``;
* continuity in the delay: ``eps -> 0`` and ``eps -> 1`` meet the whole
  delays' sets (checked by their own tests against closed forms).
"""

import math

import numpy as np
import pytest

import symstab
from symstab.numeric.analysis.passivity import _prepare_plane, passive_region

from conftest import PAPER_B, PAPER_M, PAPER_T, REPO
from oracles import lifted_least_damping, loop_coefficients, python_control_parts

PAPER_ENVIRONMENT = "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)"
#: The sweep of the region checks: theta = pi k / n, k = 1..n.
SWEEP = np.pi * np.arange(1, 3001) / 3000


def paper_loop(**values):
    defaults = dict(m=PAPER_M, b=PAPER_B, T=PAPER_T, d=0, M=0.0)
    defaults.update(values)
    return symstab.Loop("1/(m*s**2 + b*s)", PAPER_ENVIRONMENT, plane=("B", "K"), values=defaults)


def paper_h(point, d, theta):
    """``H = VE z**-d`` of the paper's environment at ``point`` (``K, B, M``), from its formula."""
    u = 1 - np.exp(-1j * theta)
    ve = point["K"] + point["B"] * u / PAPER_T + point.get("M", 0.0) * u**2 / PAPER_T**2
    return ve * np.exp(-1j * d * theta)


def lifted_margin(h_of, point, damping, d, eps, theta=SWEEP):
    """``max_theta b*(theta) - damping`` by the lifted form on the sweep (``eps`` a multiple of 1/4)."""
    m = round(4 * eps)
    assert m == 4 * eps
    return float(lifted_least_damping(h_of(point, d, theta), theta, PAPER_T, m, 4).max() - damping)


def check_region(region, h_of, d, eps, rng, n_points=60):
    """contains() agrees with the lifted form at random points of the window (``K >= 0`` static)."""
    (x0, x1), (y0, y1) = region.x_range, region.y_range
    xs, ys = rng.uniform(x0, x1, n_points), rng.uniform(y0, y1, n_points)
    decided = {True: 0, False: 0}
    for x, y, verdict in zip(xs, ys, region.contains(xs, ys), strict=True):
        point = {region.x: x, region.y: y}
        margin = lifted_margin(h_of, point, PAPER_B, d, eps)
        if abs(margin) < 2e-3 * PAPER_B or abs(point["K"]) < 1e-9:
            continue    # within the sweep's resolution of the boundary
        truth = margin < 0 and point["K"] > 0
        assert verdict == truth, (point, margin)
        decided[truth] += 1
    assert decided[True] >= 3 and decided[False] >= 3, decided


# --------------------------------------------------------------------------
# The least damping at an angle


@pytest.mark.parametrize("d", [0, 3])
@pytest.mark.parametrize("m, N", [(1, 4), (2, 4), (3, 4), (3, 8)])
def test_least_damping_at_an_angle_is_the_lifted_form(d, m, N):
    K, B, M = 2000.0, 3.0, 2e-6
    theta = np.array([1e-3, 0.1, 0.7, 1.5, 2.9, np.pi])
    num = np.array([K + B / PAPER_T + M / PAPER_T**2, -B / PAPER_T - 2 * M / PAPER_T**2,
                    M / PAPER_T**2])
    plane = _prepare_plane(num, np.zeros(3), np.zeros(3), np.array([1.0, 0.0, 0.0]), d, PAPER_T,
                           PAPER_B, None, m / N)
    mine = plane.at(theta, 0.0, 0.0) + PAPER_B
    expected = lifted_least_damping(paper_h(dict(K=K, B=B, M=M), d, theta), theta, PAPER_T, m, N)
    np.testing.assert_allclose(mine, expected, rtol=1e-9)


@pytest.mark.parametrize("eps", [0.25, 0.5, 0.75])
def test_least_damping_of_an_example_loop_by_python_control(eps):
    # The low-pass filtered damper: H from python-control's own evaluation.
    loop = symstab.load_loop(REPO / "examples" / "loops" / "lowpass_velocity.toml")
    values = dict(loop.defaults, d=2)
    _, environment, delay = python_control_parts(loop, values)
    theta = np.array([1e-3, 0.05, 0.4, 1.2, 2.5, np.pi])
    z = np.exp(1j * theta)
    H = np.array([environment(zi) * delay(zi) for zi in z])
    *_, num, den = loop_coefficients(loop, values)
    plane = _prepare_plane(np.array(num, dtype=float), np.zeros(len(num)), np.zeros(len(num)),
                           np.array(den, dtype=float), 2, PAPER_T, PAPER_B, None, eps)
    mine = plane.at(theta, 0.0, 0.0) + PAPER_B
    expected = lifted_least_damping(H, theta, PAPER_T, round(4 * eps), 4)
    np.testing.assert_allclose(mine, expected, rtol=1e-9)


# --------------------------------------------------------------------------
# A spring behind a fraction of a sample


def spring_least_damping(d, eps, T):
    """``c``: the least passive damping per unit of stiffness at ``theta = 0`` (module docstring)."""
    p = eps * T * (2 * d + 3) / 2 + (1 - eps) * T * (2 * d + 1) / 2
    q = eps * T * (2 * d + 3) / 2 * (1 - eps) * T * (2 * d + 1) / 2 - eps * (1 - eps) * T**2 * (
        d + 1)**2
    return p / 2 + math.sqrt(p**2 / 4 - q)


def test_spring_behind_half_a_sample():
    # T = K = 1: (b - 3/4)(b - 1/4) = 1/4, b* = (1 + sqrt(5)/2)/2, more than
    # the 1 halfway between Colgate's 1/2 (d = 0) and 3/2 (d = 1).
    c = spring_least_damping(0, 0.5, 1.0)
    assert c == pytest.approx((1 + math.sqrt(5) / 2) / 2, rel=1e-15)
    loop = symstab.Loop("1/(m*s**2 + b*s)", "K", values=dict(m=1.0, T=1.0, d=0.5))
    region = passive_region(loop, x="b", y="K")
    b = 1.0
    assert region.contains([b, b], [b / c * (1 - 1e-5), b / c * (1 + 1e-5)]).tolist() == [True,
                                                                                         False]


@pytest.mark.parametrize("d, eps", [(0, 0.5), (3, 0.25), (1, 0.75)])
def test_delayed_spring_bound_is_at_theta_zero(d, eps):
    c = spring_least_damping(d, eps, PAPER_T)
    lifted = lifted_least_damping(np.exp(-1j * d * SWEEP), SWEEP, PAPER_T, round(4 * eps), 4)
    assert lifted.max() <= c * (1 + 1e-9)
    assert lifted[0] == pytest.approx(c, rel=1e-5)       # theta = pi/3000, next to 0
    region = passive_region(paper_loop(d=d + eps))
    k = PAPER_B / c
    assert region.contains([0.0, 0.0], [k * (1 - 1e-5), k * (1 + 1e-5)]).tolist() == [True, False]


# --------------------------------------------------------------------------
# The region


@pytest.mark.parametrize("d, eps, M", [(1, 0.5, 0.0), (0, 0.25, 2e-6), (2, 0.75, -4e-6)])
def test_paper_region_against_the_lifted_form(d, eps, M):
    region = passive_region(paper_loop(d=d + eps, M=M))
    assert region.bounded
    check_region(region, lambda p, dd, t: paper_h(dict(p, M=M), dd, t), d, eps,
                 np.random.default_rng(11 + d))


def test_example_loop_region_against_the_lifted_form():
    loop = symstab.load_loop(REPO / "examples" / "loops" / "lowpass_velocity.toml")
    values = dict(loop.defaults)
    region = passive_region(loop, d=1.5)
    parts = {name: python_control_parts(loop, dict(values, K=float(name == "K"),
                                                   B=float(name == "B")))[1]
             for name in ("K", "B")}
    z = np.exp(1j * SWEEP)
    responses = {name: np.array([tf(zi) for zi in z]) for name, tf in parts.items()}

    def h_of(point, d, theta):
        assert theta is SWEEP
        return (point["K"] * responses["K"] + point["B"] * responses["B"]) * z**-d

    check_region(region, h_of, 1, 0.5, np.random.default_rng(5))


def test_vertices_lie_within_the_tolerance_of_the_boundary():
    # Each vertex is on a cut that every passive point meets, so b*(theta) >= b
    # there at some angle; and the cuts stop when b*(theta) <= b (1 + 1e-6) at
    # every vertex.  The lifted form is refined around its sweep's best angle.
    d, eps, M = 1, 0.5, 2e-6
    region = passive_region(paper_loop(d=d + eps, M=M))
    assert len(region.polygon) > 50
    rng = np.random.default_rng(3)
    for vertex in region.polygon[rng.choice(len(region.polygon), 12, replace=False)]:
        point = {"B": vertex[0], "K": vertex[1], "M": M}
        values = lifted_least_damping(paper_h(point, d, SWEEP), SWEEP, PAPER_T, 2, 4)
        k = int(np.argmax(values))
        # Down to theta = 1e-4 (the oracle's G = H/(z - 1) loses digits below),
        # where b* is within 1e-8 of its value at 0 (it is even in theta).
        fine = np.linspace(max(SWEEP[k] - SWEEP[0], 1e-4), min(SWEEP[k] + SWEEP[0], np.pi), 4001)
        best = lifted_least_damping(paper_h(point, d, fine), fine, PAPER_T, 2, 4).max()
        margin = max(best, values.max()) - PAPER_B
        if abs(vertex[1]) < 1e-9:
            assert margin <= 1.01e-6 * PAPER_B     # on K = 0: the static edge
        else:
            assert -1e-7 * PAPER_B <= margin <= 1.01e-6 * PAPER_B, (vertex, margin)


def test_continuity_at_whole_delays():
    for whole, near in ((0, 1e-7), (1, 1 - 1e-7)):
        at_whole, at_near = (passive_region(paper_loop(d=d)) for d in (whole, near))
        assert at_near.y_max == pytest.approx(at_whole.y_max, rel=1e-5)
        assert at_near.area == pytest.approx(at_whole.area, rel=1e-5)


def test_delay_in_seconds_and_the_facade():
    loop = paper_loop()
    in_samples = loop.passive_region(d=1.5)
    in_seconds = loop.passive_region(Td=1.5 * PAPER_T)
    np.testing.assert_array_equal(in_samples.polygon, in_seconds.polygon)
    assert repr(in_samples).startswith("PassiveRegion(K_max=")
