"""One ``Limits`` for every loop: the paper's dimensionless limits and a Loop's are one type.

Oracles: the two engines that fill it are different algorithms on different
polynomial kernels (crossings counted along lines in the paper's plane,
:mod:`symstab.numeric.paper.region`; the D-decomposition of the loop's structured
polynomial, :mod:`symstab.numeric.engine.decomposition`), so their agreement after
the change of units is a check of both; python-control's closed-loop poles
decide the points on either side of the top.
"""

import numpy as np
import pytest

import symstab
from symstab.numeric.engine.results import Limits
from symstab.numeric.paper.device import PAPER_DEVICE

from oracles import first_principles_chi, python_control_closed_loop

control = pytest.importorskip("control")


@pytest.mark.parametrize("d", [0, 5, 40])
def test_the_paper_and_its_loop_give_one_type_that_agrees(d):
    """symstab.limits and PAPER_LOOP.limits: the same type, the same set after the change of units."""
    paper = symstab.limits(gamma=0.0, d=d, delta=PAPER_DEVICE.delta)
    loop = symstab.PAPER_LOOP.limits(d=d)
    assert type(paper) is type(loop) is Limits is symstab.Limits is symstab.LoopLimits
    assert (paper.x, paper.y, loop.x, loop.y) == ("beta", "alpha", "B", "K")
    # Table I names are the fields in the paper's plane.
    assert (paper.alpha_max, paper.beta_left, paper.beta_right, paper.z_width) == (
        paper.y_max, paper.x_min, paper.x_max, paper.area)
    assert loop.y_max == pytest.approx(float(PAPER_DEVICE.stiffness(paper.y_max)), rel=1e-6)
    assert loop.x_min == pytest.approx(float(PAPER_DEVICE.damping(paper.x_min)), rel=1e-6)
    assert loop.x_max == pytest.approx(float(PAPER_DEVICE.damping(paper.x_max)), rel=1e-6)
    # The two areas: polygons against the 801-line rule (low by up to 1e-4).
    scale = float(PAPER_DEVICE.stiffness(1.0) * PAPER_DEVICE.damping(1.0))
    assert loop.area == pytest.approx(paper.area * scale, rel=1e-4)


def test_the_top_is_the_top_by_python_control():
    """Just below PAPER_LOOP's K_max at its B the loop is stable, just above unstable (poles)."""
    d = 5
    lim = symstab.PAPER_LOOP.limits(d=d)
    beta, m, T = float(PAPER_DEVICE.beta(lim.x_at_y_max)), PAPER_DEVICE.m, PAPER_DEVICE.T
    radii = []
    for factor in (1 - 1e-6, 1 + 1e-6):
        closed = python_control_closed_loop(alpha=float(PAPER_DEVICE.alpha(factor * lim.y_max)),
                                            beta=beta, gamma=0.0, d=d, delta=PAPER_DEVICE.delta,
                                            m=m, T=T)
        radii.append(float(np.max(np.abs(closed.poles()))))
    assert radii[0] < 1 < radii[1]


def test_paper_names_are_refused_outside_the_paper_plane():
    """alpha_max of a (B, K) result would be K_max in N/m under a dimensionless name: refused."""
    lim = symstab.PAPER_LOOP.limits(d=5)
    for name, field in (("alpha_max", "y_max"), ("z_width", "area"), ("beta_left", "x_min")):
        with pytest.raises(AttributeError, match=rf"{name} is the paper's name .* use {field}"):
            getattr(lim, name)
    with pytest.raises(AttributeError, match="alpha_interval is the paper's name .* intervals_at"):
        lim.alpha_interval(0.1)


def test_every_loops_limits_answer_the_line_question():
    """intervals_at(x) of a loop's limits is its stable_intervals (python-control on both sides of
    the top); in the paper's plane alpha_interval is the same question in Table I's names."""
    loop = symstab.PAPER_LOOP
    lim = loop.limits(d=5)
    (lo, hi), = lim.intervals_at(lim.x_at_y_max)
    assert (lo, hi) == tuple(loop.stable_intervals("K", B=lim.x_at_y_max, d=5)[0])
    assert hi == pytest.approx(lim.y_max, rel=1e-6)
    beta = float(PAPER_DEVICE.beta(lim.x_at_y_max))
    radii = [float(np.max(np.abs(python_control_closed_loop(
        alpha=float(PAPER_DEVICE.alpha(k)), beta=beta, gamma=0.0, d=5, delta=PAPER_DEVICE.delta,
        m=PAPER_DEVICE.m, T=PAPER_DEVICE.T).poles()))) for k in (hi * (1 - 1e-6), hi * (1 + 1e-6))]
    assert radii[0] < 1 < radii[1]
    paper = symstab.limits(gamma=1.5, d=0, delta=PAPER_DEVICE.delta)
    assert paper.alpha_interval(-0.5) == paper.region.alpha_intervals(-0.5)
    assert 1 < paper.minimum_stiffness(-0.5) < 1.3          # Fig. 7's circle 6
    with pytest.raises(TypeError, match="beta"):
        paper.alpha_interval("a")


def test_limits_and_their_loop_pickle():
    """A Limits travels to another process with its loop: the same numbers, the same line answers."""
    import pickle

    lim = symstab.PAPER_LOOP.limits(d=5)
    back = pickle.loads(pickle.dumps(lim))
    assert back == lim and back.as_dict() == lim.as_dict()
    assert back.intervals_at(lim.x_at_y_max) == lim.intervals_at(lim.x_at_y_max)
    loop = pickle.loads(pickle.dumps(symstab.PAPER_LOOP))
    assert loop.units == symstab.PAPER_LOOP.units and loop.plane == ("B", "K")
    assert loop.limits(d=5) == lim
    # The paper's limits carry their region, whose decomposition (closures
    # of the generated kernel) is made again where it is needed.
    region = symstab.StabilityRegion(gamma=0.0, d=5, delta=PAPER_DEVICE.delta)
    segments, paper = region.line_segments(), region.limits()
    back = pickle.loads(pickle.dumps(paper))
    assert back.as_dict() == paper.as_dict() and back.region.line_segments() == segments
    assert back.alpha_interval(0.05) == paper.alpha_interval(0.05)


def test_an_empty_set_reads_the_same_from_both():
    """Proved empty sets: y_max None, area 0, a reason, from the paper's engine and from a Loop."""
    paper = symstab.limits(gamma=2.1, d=40, delta=PAPER_DEVICE.delta)
    loop = symstab.PAPER_LOOP.limits(d=1, M=2.1 * PAPER_DEVICE.m)
    for lim in (paper, loop):
        assert lim.empty and lim.y_max is None and lim.area == 0.0 and lim.reason
        assert lim.message == lim.reason
        assert "empty" in repr(lim)


def test_json_keys_of_the_paper_plane_are_table_one():
    """as_dict keeps the paper's keys in its plane and the plane's own names elsewhere."""
    paper = symstab.limits(gamma=0.0, d=1, delta=PAPER_DEVICE.delta).as_dict()
    assert list(paper) == ["gamma", "d", "delta", "alpha_max", "beta_at_alpha_max", "beta_left",
                           "beta_right", "z_width", "message"]
    loop = symstab.PAPER_LOOP.limits(d=1).as_dict()
    assert {"y_max", "x_at_y_max", "x_min", "x_max", "area", "cells"} <= set(loop)
    assert loop["d"] == 1 and loop["x"] == "B"


@pytest.mark.parametrize("gamma, d", [(0.0, 0), (0.5, 3), (-0.5, 10)])
def test_the_papers_boundary_lines_are_where_a_real_root_is_on_the_circle(gamma, d):
    """Points of boundary_curve's z = +-1 lines make chi(+-1) vanish (30-digit printed-equation chi)."""
    import mpmath

    delta = PAPER_DEVICE.delta
    curve = symstab.boundary_curve(gamma=gamma, d=d, delta=delta, n=16, segments=False)
    assert type(curve) is symstab.BoundaryCurve
    assert (curve.gamma, curve.d, curve.delta) == (gamma, d, delta)
    assert set(curve.lines) == {"z = 1", "z = -1"}
    with mpmath.workdps(30):
        for label, z in (("z = 1", 1), ("z = -1", -1)):
            c0, cb, ca = curve.lines[label]
            for beta in (0.01, 0.3):
                alpha = -(c0 + cb * beta) / ca
                chi = first_principles_chi(alpha, beta, gamma, d, delta)
                value = mpmath.polyval(chi, z)
                scale = sum(abs(c) for c in chi)
                assert abs(value) < 1e-12 * scale, (label, beta)


def test_a_loops_boundary_is_the_same_type_with_the_planes_names():
    """Loop.boundary and boundary_curve: one Boundary; the paper's names only in its plane."""
    loop = symstab.PAPER_LOOP.boundary(d=5, n=64)
    paper = symstab.boundary_curve(gamma=0.0, d=5, delta=PAPER_DEVICE.delta, n=64, segments=False)
    assert type(loop) is type(paper) is symstab.LoopBoundary is symstab.BoundaryCurve
    assert (loop.x, loop.y) == ("B", "K") and set(loop.lines) >= {"z = 1", "z = -1"}
    with pytest.raises(AttributeError, match="use y_values"):
        _ = loop.alpha
    with pytest.raises(AttributeError, match="paper's"):
        _ = loop.gamma
    # The arc starts at (beta, alpha) = (-delta, 0): the names are not swapped.
    assert (paper.beta[0], paper.alpha[0]) == (-PAPER_DEVICE.delta, 0.0)
    assert (paper.x_values[0], paper.y_values[0]) == (-PAPER_DEVICE.delta, 0.0)


def test_limits_show_as_an_html_table_in_jupyter_with_every_text_escaped():
    """Issue 42, item 5: a Limits in a notebook is a table of as_dict(); a reason (which may
    name a user's parameter) is text, never markup."""
    found = Limits("B", "K", 4.958841, 0.297, -0.0324, 0.5113, 1.804, cells=1,
                   reason="<b>K</b> & more", at={"d": 40})
    shown = found._repr_html_()
    assert shown.startswith("<table><caption>Limits(B, K at d=40)</caption>")
    assert "<tr><th style='text-align:left'>y_max</th><td>4.95884</td></tr>" in shown
    assert "&lt;b&gt;K&lt;/b&gt; &amp; more" in shown and "<b>" not in shown
    assert shown.count("<tr>") == len(found.as_dict())
    empty = Limits.empty_set("B", "K", "no stable point")._repr_html_()
    assert "<th style='text-align:left'>y_max</th><td></td>" in empty


def test_a_region_and_a_robust_set_show_as_html_tables_in_jupyter():
    """Issue 42, item 5: the D-decomposition's table counts its cells by their number of
    unstable poles (the counts of its cells, read independently here), and names the window;
    a robust set's table gives its area beside the nominal one's."""
    from symstab.numeric.engine.results import RobustRegion

    region = symstab.PAPER_LOOP.region(d=5)
    shown = region._repr_html_()
    assert shown.startswith("<table><caption>D-decomposition of the (B, K) plane</caption>")
    for n in {c.count for c in region.cells}:
        cells = [c for c in region.cells if c.count == n]
        plural = "s" if n != 1 else ""
        assert (f"<th style='text-align:left'>cells with {n} unstable pole{plural}</th>"
                f"<td>{len(cells)}</td>") in shown
    assert f"<td>{region.area:.6g}</td>" in shown
    robust = RobustRegion("B", "K", {"m<1>": (0.012, 0.0136)}, np.array([0.0, 0.1]),
                          (((0.0, 2.0, 0.0, 3.0),),), ((),), nominal=region)
    shown = robust._repr_html_()
    assert "<th style='text-align:left'>m&lt;1&gt;</th><td>[0.012, 0.0136]</td>" in shown
    assert f"<td>{robust.area:.6g}</td>" in shown and f"<td>{region.area:.6g}</td>" in shown
