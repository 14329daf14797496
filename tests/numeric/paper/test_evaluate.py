"""symstab.numeric.paper.reference against a first-principles boundary (eqs. (1), (2), (4))."""

import mpmath
import numpy as np
import pytest

from symstab.numeric.paper.reference import alpha_max_on_arc, arc_end, boundary_point
from symstab.symbolic.theta_max import theta_max

from conftest import PAPER_DELTA
from oracles import first_principles_alpha, first_principles_boundary_point


@pytest.mark.parametrize("theta, gamma, d, delta", [
    (0.3, 0.0, 0, PAPER_DELTA), (1.1, 1.5, 0, PAPER_DELTA), (0.05, -0.5, 10, PAPER_DELTA),
    (0.7, 2.2, 3, 0.4), (2.0, 0.3, 1, 1e-4),
])
def test_boundary_point_matches_first_principles(theta, gamma, d, delta):
    with mpmath.workdps(40):
        a, b = boundary_point(theta, gamma=gamma, d=d, delta=delta, dps=40)
        ea, eb = first_principles_boundary_point(theta, gamma, d, delta)
        assert abs(a - ea) <= mpmath.mpf(10) ** -30 * max(1, abs(ea))
        assert abs(b - eb) <= mpmath.mpf(10) ** -30 * max(1, abs(eb))


@pytest.mark.parametrize("gamma, d", [(0.0, 0), (1.0, 0), (0.5, 5), (-0.5, 1)])
def test_alpha_max_is_the_top_of_the_arc(gamma, d):
    t_star, a_star, _ = alpha_max_on_arc(gamma=gamma, d=d, delta=PAPER_DELTA)
    t_end = theta_max(gamma=gamma, d=d, delta=PAPER_DELTA)
    grid = np.linspace(t_end * 1e-3, t_end * (1 - 1e-3), 300)
    with mpmath.workdps(30):
        sampled = max(float(first_principles_alpha(t, gamma, d, PAPER_DELTA)) for t in grid)
    assert 0 < t_star < t_end
    assert a_star >= sampled * (1 - 1e-12)
    assert a_star <= sampled * (1 + 1e-3)  # the grid misses the top by O(step^2) only


def test_arc_end_is_where_alpha_returns_to_zero():
    t, b = arc_end(gamma=0.0, d=0, delta=PAPER_DELTA)
    with mpmath.workdps(40):
        a_fp, b_fp = first_principles_boundary_point(t, 0.0, 0, PAPER_DELTA)
    assert abs(float(a_fp)) < 1e-12
    assert b == pytest.approx(float(b_fp), rel=1e-12)


def test_no_arc_gives_nan():
    assert all(np.isnan(alpha_max_on_arc(gamma=-3.0, d=0, delta=PAPER_DELTA)))


def test_bad_input_names_the_parameter():
    with pytest.raises(ValueError, match="delta"):
        boundary_point(0.5, gamma=0.0, d=0, delta=0.0)
    with pytest.raises(ValueError, match="delay d"):
        alpha_max_on_arc(gamma=0.0, d=-1, delta=0.1)
