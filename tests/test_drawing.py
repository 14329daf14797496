"""Results draw themselves: ``plot()`` on a region, its limits and a boundary.

Each drawing is checked by its artists against the result it drew (the
filled stable cells, the arc's points, the counts written, the marked
optimum), not only for running.  The figures are drawn on matplotlib's Agg
backend (no display).
"""

import sys

import matplotlib
import numpy as np
import pytest

import symstab

matplotlib.use("Agg")


@pytest.fixture(scope="module")
def region_d40():
    """The paper's loop at T_d = 40 ms: its (B, K) plane's D-decomposition."""
    return symstab.PAPER_LOOP.region(d=40)


@pytest.fixture(autouse=True)
def _close_figures():
    import matplotlib.pyplot as plt

    yield
    plt.close("all")


def test_a_region_draws_its_stable_set_curves_and_counts(region_d40):
    from matplotlib.figure import Figure

    drawn = region_d40.plot()
    assert isinstance(drawn.figure, Figure) and drawn.axes in drawn.figure.axes
    # One filled patch per stable cell, each outlining that cell.
    assert len(drawn.artists["stable"]) == len(region_d40.stable) >= 1
    for patch, cell in zip(drawn.artists["stable"], region_d40.stable, strict=True):
        vertices = patch.get_path().vertices
        assert np.allclose(vertices[:len(cell.outer)], cell.outer) or np.allclose(
            vertices[:len(cell.outer)], cell.outer[::-1])
    # The arc is the decomposition's own (its points, NaN separators included).
    (arc_branch,) = [b for b in region_d40.branches if b.label == "arc"]
    (arc,) = drawn.artists["arc"]
    np.testing.assert_array_equal(np.asarray(arc.get_xydata()), arc_branch.points)
    assert len(drawn.artists["lines"]) == len(region_d40.branches) - 1
    # Every count written is its cell's, at the point where it was counted.
    assert drawn.artists["counts"]
    counts = {(float(c.point[0]), float(c.point[1])): c.count for c in region_d40.cells}
    for text in drawn.artists["counts"]:
        assert counts[tuple(float(v) for v in text.get_position())] == int(text.get_text())
    assert (drawn.axes.get_xlabel(), drawn.axes.get_ylabel()) == ("B", "K")
    assert drawn.axes.get_xlim() == pytest.approx(region_d40.x_range)


def test_limits_mark_their_largest_stiffness_on_the_set_they_were_read_from(region_d40):
    limits = region_d40.limits()
    assert limits.decomposition is region_d40
    fig, ax = matplotlib.pyplot.subplots()
    drawn = limits.plot(ax=ax, counts=False)
    assert drawn.axes is ax and drawn.figure is fig and drawn.artists["counts"] == []
    (marker,) = drawn.artists["marker"]
    assert marker.get_xydata().tolist() == [[limits.x_at_y_max, limits.y_max]]
    assert f"{limits.y_max:.6g}" in marker.get_label()


def test_limits_without_a_decomposition_say_so(region_d40):
    """Limits made by hand, or sent to another process (the decomposition's arc is made of
    closures, which do not pickle), have nothing to draw: a ValueError says so."""
    import pickle

    from symstab.numeric.engine.results import Limits

    with pytest.raises(ValueError, match="no D-decomposition"):
        Limits("B", "K", 1.0, 0.0, -1.0, 1.0, 2.0).plot()
    back = pickle.loads(pickle.dumps(region_d40.limits()))
    assert back.decomposition is None and back == region_d40.limits()
    with pytest.raises(ValueError, match="no D-decomposition"):
        back.plot()


def test_a_boundary_draws_its_arc_and_the_lines_in_view():
    curve = symstab.PAPER_LOOP.boundary(d=5)
    drawn = curve.plot()
    (arc,) = drawn.artists["arc"]
    np.testing.assert_array_equal(arc.get_xdata(), curve.x_values)
    np.testing.assert_array_equal(arc.get_ydata(), curve.y_values)
    # The z = 1 line of the paper's plane (K = 0) is in view: drawn, at K = 0.
    labels = {line.get_label(): line for line in drawn.artists["lines"]}
    assert "root z = 1" in labels and np.all(labels["root z = 1"].get_ydata() == 0)


def test_without_matplotlib_plot_names_the_extra(region_d40, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)
    with pytest.raises(ImportError, match=r"symstab\[figures\]"):
        region_d40.plot()
