"""``Loop.region(..., delay_range=...)``: a delay range's two sets in a plane.

The constant set is the robust region over the continuum of delays (its
engine is tested in test_robust*.py); here, against oracles that are not
symstab's: the state-space discretisation's spectral radius (Van Loan's
block exponential, tests/oracles.py) over a fine grid of delays of the
range at points of the certified set, and the varying set's grid against
the small-gain criterion of :meth:`symstab.Loop.delay_range` at single
points (itself checked against python-control's frequency response).
"""

import numpy as np
import pytest

import symstab

from conftest import REPO
from oracles import fractional_delay_oracle

PAPER = REPO / "examples" / "loops" / "paper.toml"

pytestmark = pytest.mark.usefixtures("loop_cache_dir")


@pytest.fixture(scope="module")
def loop():
    return symstab.load_loop(PAPER)


@pytest.fixture(scope="module")
def found(loop, session_cache_dir):
    return loop.region(delay_range=(0.002, 0.004), x_range=(0.0, 1.5), y_range=(0.0, 300.0),
                       n=21, strips=16)


def test_certified_points_are_stable_at_every_delay_of_the_range(loop, found):
    grid = found.grid
    assert grid.samples == (2.0, 4.0)
    rows, cols = np.nonzero(grid.constant)
    assert rows.size > 20 and not grid.constant.all()
    pick = np.random.default_rng(0).choice(rows.size, 12, replace=False)
    for i, j in zip(rows[pick], cols[pick], strict=True):
        point = {**loop.defaults, "B": grid.x_values[j], "K": grid.y_values[i]}
        oracle = fractional_delay_oracle(loop, point)
        radii = [oracle(tau)[0] for tau in np.linspace(2.0, 4.0, 81)]
        assert max(radii) < 1, (point, max(radii))


def test_certified_points_have_the_exact_margins_constant_set(loop, found):
    grid = found.grid
    rows, cols = np.nonzero(grid.constant)
    for i, j in list(zip(rows, cols, strict=True))[::max(1, rows.size // 6)]:
        at = loop.delay_range(delay_range=(0.002, 0.004), B=grid.x_values[j], K=grid.y_values[i])
        assert at.constant


def test_the_varying_grid_is_the_point_criterion(loop, found):
    grid = found.grid
    assert grid.varying is not None and grid.varying.any() and not grid.varying.all()
    for i, j in [(1, 10), (5, 5), (10, 20), (15, 12), (20, 3)]:
        at = loop.delay_range(delay_range=(0.002, 0.004), B=grid.x_values[j], K=grid.y_values[i])
        assert grid.varying[i, j] == bool(at.varying), (i, j, at)


def test_ends_not_a_whole_number_of_samples_apart_have_no_varying_set(loop):
    found = loop.region(delay_range=(0.0025, 0.00375), x_range=(0.0, 1.5),
                        y_range=(0.0, 300.0), n=5, strips=8)
    assert found.grid.samples == pytest.approx((2.5, 3.75)) and found.grid.varying is None
    assert "not derived" in repr(found)


@pytest.mark.parametrize("change, error, needle", [
    (dict(n=1), ValueError, "n must be"),
    (dict(delay_range=(0.004, 0.002)), ValueError, "Td_min <= Td_max"),
    (dict(uncertain={"b": (0.02, 0.04)}), TypeError, "use robust_region"),
])
def test_bad_input_is_refused_naming_it(loop, change, error, needle):
    kwargs = dict(delay_range=(0.002, 0.004), x_range=(0.0, 1.5), y_range=(0.0, 300.0))
    kwargs.update(change)
    with pytest.raises(error, match=needle):
        loop.region(**kwargs)


def test_the_drawing_shows_both_sets(found):
    pytest.importorskip("matplotlib")
    drawn = found.plot()
    assert drawn.artists["robust"] and drawn.artists["varying"]
    labels = [t.get_text() for t in drawn.axes.get_legend().get_texts()]
    assert "every constant delay (certified)" in labels
    assert "every varying delay (small gain, on a grid)" in labels
    assert drawn.axes.get_title() == "stable for delays of 2 to 4 samples"
