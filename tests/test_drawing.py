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


def test_a_robust_set_draws_its_certified_and_marginal_bands_and_the_nominal_outline(region_d40):
    """Two strips with one band each (joined into one polygon) and a marginal band."""
    from symstab.numeric.engine.results import RobustRegion

    region = RobustRegion("B", "K", {"m": (0.0120, 0.0136)}, np.array([0.0, 0.1, 0.2]),
                          (((0.0, 2.0, 0.0, 3.0),), ((0.0, 3.0, 0.0, 2.5),)),
                          ((), ((3.0, 3.2, 2.5, 2.6),)), nominal=region_d40)
    drawn = region.plot()
    (robust,) = drawn.artists["robust"]
    np.testing.assert_array_equal(robust.get_xy()[:-1], region.polygons[0])
    (marginal,) = drawn.artists["marginal"]
    np.testing.assert_array_equal(marginal.get_xy()[:-1],
                                  [(0.1, 3.0), (0.2, 2.5), (0.2, 2.6), (0.1, 3.2)])
    assert len(drawn.artists["nominal"]) == len(region_d40.stable)
    assert "m in [0.012, 0.0136]" in drawn.axes.get_title()


def test_a_probability_map_draws_its_grid_and_the_boundary_given():
    from symstab.numeric.engine.results import StabilityProbability

    p = np.array([[0.0, 0.5, 1.0], [0.25, 0.75, 1.0]])
    found = StabilityProbability(np.array([0.0, 1.0]), np.array([0.0, 0.1, 0.2]), p,
                                 np.zeros_like(p), np.zeros(p.shape, int), 100, 1,
                                 {"m": "uniform"}, "B", "K")
    drawn = found.plot(boundary=symstab.PAPER_LOOP.boundary(d=40))
    (mesh,) = drawn.artists["probability"]
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).ravel(), p.ravel())
    assert drawn.artists["colorbar"][0].ax.get_ylabel() == "probability of stability"
    assert drawn.artists["boundary"]


def test_a_design_marks_its_optimum_its_nominal_value_and_the_values_without_a_stable_point():
    from symstab.numeric.analysis.design import Design

    samples = np.array([[0.0, 10.0], [0.01, 14.0], [0.02, 12.0], [0.03, -np.inf]])
    found = Design("y_max", "B", "K", {"M": (0.0, 0.03)}, {"M": 0.01}, 14.0, {"M": 0.0}, 10.0,
                   None, samples, {"M": 0.01})
    drawn = found.plot()
    (best,) = drawn.artists["best"]
    assert best.get_xydata().tolist() == [[0.01, 14.0]]
    (line,) = drawn.artists["target"]
    assert line.get_xydata().tolist() == [[0.0, 10.0], [0.01, 14.0], [0.02, 12.0]]
    (none,) = drawn.artists["none"]
    assert none.get_xydata().tolist() == [[0.03, 10.0]]
    (nominal,) = drawn.artists["nominal"]
    assert list(nominal.get_xdata()) == [0.0, 0.0]
    assert drawn.axes.get_ylabel() == "y_max" and drawn.axes.get_xlabel() == "M"


def test_a_design_with_a_budget_draws_its_front_and_shades_the_values_over_it():
    """Values 0, 1, 2 within a budget of 0.5, 3 over it (the budget's scan: 2.5 meets it, 2.75
    does not): the front is the three rows within it, the budget a line, and the search's
    panel shades [2.5, 3] (to the last value within the budget)."""
    from symstab.numeric.analysis.design import Design

    samples = np.array([[0.0, 10.0], [1.0, 12.0], [2.0, 11.0], [2.5, 13.0]])
    noise = np.array([0.1, 0.2, 0.3, 0.5])
    scan = np.array([[0.0, 0.1], [1.0, 0.2], [2.0, 0.3], [2.5, 0.5], [2.75, 0.6], [3.0, 0.7]])
    found = Design("y_max", "B", "K", {"f_c": (0.0, 3.0)}, {"f_c": 2.5}, 13.0, {}, None, None,
                   samples, {"f_c": 1.0}, noise_limit=0.5, encoder_resolution=1e-6,
                   noise_at={"B": 1.0, "K": 2.0}, noise=noise, noise_samples=scan)
    drawn = found.plot_pareto()
    (front,) = drawn.artists["front"]
    assert front.get_xydata().tolist() == [[0.1, 10.0], [0.2, 12.0], [0.5, 13.0]]
    (limit,) = drawn.artists["limit"]
    assert list(limit.get_xdata()) == [0.5, 0.5]
    (best,) = drawn.artists["best"]
    assert best.get_xydata().tolist() == [[0.5, 13.0]]
    search = found.plot()
    (span,) = search.artists["over budget"]
    # (A Rectangle from matplotlib 3.9, a Polygon before.)
    xs = ([span.get_x(), span.get_x() + span.get_width()] if hasattr(span, "get_width")
          else np.asarray(span.get_xy())[:, 0])
    assert {round(float(x), 12) for x in xs} == {2.5, 3.0}
    without = Design("y_max", "B", "K", {"f_c": (0.0, 3.0)}, None, None, {}, None, None,
                     samples, {"f_c": 1.0})
    with pytest.raises(ValueError, match="recorded no force noise"):
        without.plot_pareto()


def test_a_passive_set_draws_its_polygon_over_the_stable_set(region_d40):
    passive = symstab.PAPER_LOOP.passive_region(d=40)
    drawn = passive.plot(region=region_d40)
    (polygon,) = drawn.artists["passive"]
    np.testing.assert_array_equal(polygon.get_xy()[:-1], passive.polygon)
    assert len(drawn.artists["stable"]) == len(region_d40.stable)
    labels = [t.get_text() for t in drawn.axes.get_legend().get_texts()]
    assert "passive" in labels and "stable (root counting)" in labels


def test_a_locus_draws_every_pole_and_marks_its_crossings():
    """K along [0, 10] N m/rad at d = 40: K_max is about 4.96 there, so poles cross."""
    found = symstab.locus(symstab.PAPER_LOOP, "K", np.linspace(0.0, 10.0, 60), B=0.3, d=40)
    drawn = found.plot()
    (dots,) = drawn.artists["poles"]
    inside = np.isfinite(found.poles) & (np.abs(found.poles) <= 3.0)
    assert len(dots.get_offsets()) == int(inside.sum())
    marks = sum(2 if c.kind == "pair" else 1 for c in found.crossings)
    assert found.crossings and len(drawn.artists["crossings"]) == marks
    (circle,) = drawn.artists["circle"]
    assert np.allclose(np.hypot(*circle.get_xydata().T), 1.0)


def test_a_recorded_run_draws_its_positions_and_a_run_without_them_says_so():
    values = dict(K=[1.0, 50.0], B=0.2, d=5)
    run = symstab.PAPER_LOOP.simulate(steps=300, record=True, **values)
    drawn = run.plot(T=1e-3)
    assert len(drawn.artists["positions"]) == 2
    for line, column in zip(drawn.artists["positions"], run.positions.T, strict=True):
        np.testing.assert_array_equal(line.get_ydata(), column)
    assert drawn.artists["positions"][0].get_xdata()[-1] == pytest.approx(0.3)
    with pytest.raises(ValueError, match="record=True"):
        symstab.PAPER_LOOP.simulate(steps=10, **values).plot()


def test_a_simulated_map_draws_its_verdicts_and_the_boundary():
    K, B = np.linspace(0.0, 8.0, 6), np.linspace(0.0, 0.5, 5)
    found = symstab.PAPER_LOOP.stability_map(B, K, steps=400, d=40)
    drawn = found.plot(boundary=symstab.PAPER_LOOP.boundary(d=40))
    (mesh,) = drawn.artists["cells"]
    np.testing.assert_array_equal(np.asarray(mesh.get_array()).reshape(found.stable.shape),
                                  found.stable.astype(int))
    assert drawn.artists["boundary"] and drawn.axes.get_xlabel() == found.x
