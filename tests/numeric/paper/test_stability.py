"""symstab.numeric.paper.stability, and the 30-digit per-point oracles, against python-control's poles."""

import numpy as np
import pytest

from symstab.numeric.paper.reference import boundary_point
from symstab.numeric.paper.stability import spectral_radius

from conftest import PAPER_DELTA
from oracles import (
    coefficients_at,
    dimensionless,
    python_control_closed_loop,
    random_loop_points,
    stable_alpha_intervals,
    unstable_root_count,
)


@pytest.mark.parametrize("point", random_loop_points(seed=7, n=20, delta_range=(1e-3, 1.0)))
def test_spectral_radius_matches_python_control(point):
    poles = python_control_closed_loop(**dimensionless(point), m=point["m"], T=point["T"]).poles()
    expected = float(np.max(np.abs(poles)))
    assert spectral_radius(**dimensionless(point)) == pytest.approx(expected, rel=1e-8)


@pytest.mark.parametrize("point", random_loop_points(seed=8, n=20, delta_range=(1e-3, 1.0)))
def test_unstable_root_count_matches_python_control(point):
    poles = python_control_closed_loop(**dimensionless(point), m=point["m"], T=point["T"]).poles()
    mod = np.abs(poles)
    if np.any(np.abs(mod - 1) < 1e-6):
        pytest.skip("too close to the boundary for a float oracle")
    assert unstable_root_count(**dimensionless(point)) == int(np.count_nonzero(mod > 1))


def test_a_point_on_the_boundary_has_a_root_at_exp_j_theta_and_is_marginal():
    a, b = boundary_point(0.8, gamma=0.5, d=2, delta=0.2)
    roots = np.roots(coefficients_at(alpha=float(a), beta=float(b), gamma=0.5, d=2, delta=0.2))
    assert np.min(np.abs(roots - np.exp(0.8j))) < 1e-9
    assert unstable_root_count(alpha=float(a), beta=float(b), gamma=0.5, d=2, delta=0.2,
                               marginal_tol=1e-9) is None


def test_coefficients_have_degree_d_plus_4():
    assert len(coefficients_at(alpha=1, beta=0, gamma=0, d=7, delta=0.1)) == 12


def test_stable_interval_edges_are_stability_changes():
    (lo, hi), = stable_alpha_intervals(beta=-0.5, gamma=1.5, d=0, delta=PAPER_DELTA)
    assert lo > 1.0  # Fig. 7, circle 6: a minimum stiffness is needed
    for edge in (lo, hi):
        inside = spectral_radius(alpha=edge + (hi - lo) * 1e-3 * (1 if edge == lo else -1),
                                 beta=-0.5, gamma=1.5, d=0, delta=PAPER_DELTA)
        outside = spectral_radius(alpha=edge - (hi - lo) * 1e-3 * (1 if edge == lo else -1),
                                  beta=-0.5, gamma=1.5, d=0, delta=PAPER_DELTA)
        assert inside < 1 < outside


def test_no_stable_interval_for_a_large_negative_mass():
    assert stable_alpha_intervals(beta=0.0, gamma=-1.5, d=0, delta=PAPER_DELTA) == []
