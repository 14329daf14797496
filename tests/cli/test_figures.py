"""The figures' text (issue 13): symbols in mathtext, readable sizes, labelled log axes.

A new user read "M_w = 0 m" as metres, saw literal "T_d" and "gamma <= 0" in
suptitles, squinted at 6 pt legends under suptitles smaller than the panel
titles, got two labels on Fig. 4's log axis and "first root of alpha" as a
legend.  These tests read the drawn figures' text artists; the figures are
built with small grids (the text does not depend on them).
"""

import re

import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib.legend  # noqa: E402
import matplotlib.text  # noqa: E402

from symstab import drawing, figures  # noqa: E402

# Small grids and gamma scans: the text is the same as at full size.
_SMALL = {"fig3": {}, "fig4": {}, "fig5": {}, "fig6": {"n": 4}, "fig7": {}, "fig8": {"n": 4},
          "fig10": {"n": 6}, "fig11": {"n": 4}, "fig12": {"n": 4}}
_PANELLED = ("fig6", "fig8", "fig10", "fig11", "fig12")


@pytest.fixture(scope="module")
def drawn():
    """Figures by name, built when a test first asks (each xdist worker builds its own)."""
    plt = drawing.pyplot()
    made = {}

    class Lazy(dict):
        def __missing__(self, name):
            fig = getattr(figures, name)(**_SMALL[name]).figure
            fig.canvas.draw()  # tick labels get their text only when drawn
            made[name] = self[name] = fig
            return fig

    yield Lazy()
    for fig in made.values():
        plt.close(fig)


def _texts(fig):
    return [t.get_text() for t in fig.findobj(matplotlib.text.Text) if t.get_text()]


def _outside_math(text):
    """``text`` without its ``$...$`` mathtext spans."""
    return re.sub(r"\$[^$]*\$", " ", text)


def test_every_figure_is_checked():
    assert set(_SMALL) == {f.__name__ for f in figures.FIGURES}


@pytest.mark.parametrize("name", list(_SMALL))
def test_symbols_are_mathtext_not_plain_ascii(drawn, name):
    texts = _texts(drawn[name])
    assert texts, name
    for text in texts:
        plain = _outside_math(text)
        for raw in ("T_d", "M_w", "K_w", "B_w", "<=", ">=", "gamma", "theta", "alpha", "beta"):
            assert raw not in plain, f"{name}: {raw!r} outside mathtext in {text!r}"
        # "0 m" reads as metres; the virtual mass is a multiple of m, 0 \cdot m.
        assert not re.search(r"\d m\b", text), f"{name}: {text!r}"


@pytest.mark.parametrize("name", ("fig3", "fig4"))
def test_theta_max_legend_in_plain_words(drawn, name):
    legend, = drawn[name].axes[0].get_legend().get_texts()[:1]
    assert "root" not in legend.get_text()
    assert r"\theta_{\max}" in legend.get_text()


@pytest.mark.parametrize("name", _PANELLED)
def test_suptitle_is_larger_than_every_panel_title(drawn, name):
    fig = drawn[name]
    assert fig._suptitle is not None and fig._suptitle.get_text()
    panels = [ax.title.get_fontsize() for ax in fig.axes if ax.title.get_text()]
    assert len(panels) >= 4
    assert fig._suptitle.get_fontsize() > max(panels)


@pytest.mark.parametrize("name", list(_SMALL))
def test_legends_are_at_least_8_points(drawn, name):
    legends = drawn[name].findobj(matplotlib.legend.Legend)
    assert legends, name
    for legend in legends:
        for text in legend.get_texts():
            assert text.get_fontsize() >= 8, (name, text.get_text(), text.get_fontsize())


def _labelled_ticks(ax):
    lo, hi = ax.get_ylim()
    return [t.label1.get_text() for t in ax.yaxis.get_major_ticks()
            if t.label1.get_visible() and t.label1.get_text() and lo <= t.get_loc() <= hi]


def test_fig4_log_axis_has_enough_labels(drawn):
    ax = drawn["fig4"].axes[0]
    assert ax.get_yscale() == "log"
    labels = _labelled_ticks(ax)
    assert len(labels) >= 4, labels
    assert r"$d = T_d / T$" in ax.get_xlabel()


@pytest.mark.parametrize("name", ("fig11", "fig12"))
def test_limits_log_axes_have_at_least_three_labels(drawn, name):
    upper, lower = drawn[name].axes[:4], drawn[name].axes[4:8]
    assert len(lower) == 4
    for ax in upper:
        assert ax.get_yscale() == "log"
        assert "log scale" in ax.get_ylabel()
        assert len(_labelled_ticks(ax)) >= 3, (ax.get_title(), _labelled_ticks(ax))
    for ax in lower:  # the Z-width where it can reach zero
        assert ax.get_yscale() == "linear" and "linear scale" in ax.get_ylabel()


# --------------------------------------------------------------------------
# What the figures show (issue 12): every curve, every branch, the Z-width's
# end, counts that are right, legends off the data.

DELTA = figures.DELTA


def _numpy_unstable(alpha, beta, gamma, d):
    """Closed-loop poles outside the unit circle, by numpy's eigenvalue roots (the oracle)."""
    from symstab.numeric.paper.stability import loop_coefficients

    c = loop_coefficients(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=DELTA)
    return int(np.sum(np.abs(np.roots(c)) > 1.0))


def _panels(fig, d):
    return [ax for ax in fig.axes if f"$d = {d}$" in ax.get_title()]


@pytest.mark.parametrize("name, gammas, delays", [
    ("fig6", (0.0, -0.25, -0.5, -0.75), figures.DELAYS),
    ("fig7", (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0), (0,)),
    ("fig8", (0.0, 0.5, 1.0, 1.5, 2.0, 2.2), figures.DELAYS)])
def test_every_named_arc_is_whole_in_some_panel_of_its_delay(drawn, name, gammas, delays):
    # Fig. 8 showed gamma = 1.5, 2 and 2.2 at d = 1 as stubs at the left edge;
    # Fig. 7 cut the tips of gamma = 2.5 and 3, which then read as two lines each.
    from symstab.numeric.paper.region import boundary_curve

    fig = drawn[name]
    for d in delays:
        panels = _panels(fig, d)
        assert panels, (name, d)
        for g in gammas:
            arc = boundary_curve(gamma=g, d=d, delta=DELTA, n=400, segments=False)
            inside = [ax for ax in panels
                      if ax.get_xlim()[0] <= arc.beta.min() and arc.beta.max() <= ax.get_xlim()[1]
                      and ax.get_ylim()[0] <= arc.alpha.min() and arc.alpha.max() <= ax.get_ylim()[1]]
            assert inside, f"{name}: the arc of gamma = {g}, d = {d} is cut by every panel of d = {d}"


def test_fig8_gamma_2_sliver_has_a_panel_where_it_is_visible(drawn):
    # The sliver is 0.007 wide in alpha: invisible at the scale of the d = 0 panel.
    fig = drawn["fig8"]
    best = 0.0
    for ax in _panels(fig, 0):
        (b0, b1), (a0, a1) = ax.get_xlim(), ax.get_ylim()
        stable = [_numpy_unstable(a, b, 2.0, 0) == 0
                  for a in np.linspace(a0, a1, 25)[1:-1] for b in np.linspace(b0, b1, 25)[1:-1]]
        best = max(best, np.mean(stable))
    assert best >= 0.05, best


def _data_points(ax):
    """Display coordinates of every plotted vertex inside ``ax``'s limits."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    out = []
    for line in ax.lines:
        xy = np.asarray(line.get_xydata(), dtype=float)
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        xy = xy[(xy[:, 0] >= min(x0, x1)) & (xy[:, 0] <= max(x0, x1))
                & (xy[:, 1] >= min(y0, y1)) & (xy[:, 1] <= max(y0, y1))]
        if len(xy):
            out.append(ax.transData.transform(xy))
    return np.concatenate(out) if out else np.empty((0, 2))


@pytest.mark.parametrize("name", list(_SMALL))
def test_no_legend_covers_a_plotted_point(drawn, name):
    # Fig. 8's legend hid the gamma = 1 tip at d = 10, Fig. 10's the top of the arc.
    fig = drawn[name]
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    renderer = fig.canvas.get_renderer()
    for legend in legends:
        box = legend.get_window_extent(renderer).padded(-1.0)
        for ax in fig.axes:
            points = _data_points(ax)
            covered = ((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                       & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))
            assert not covered.any(), (name, ax.get_title(), int(covered.sum()))


@pytest.mark.parametrize("name, right", [("fig11", False), ("fig12", True)])
def test_z_width_closes_to_zero_where_the_region_vanishes(drawn, name, right):
    # Fig. 12 left a gap between the last stable gamma of the grid and the
    # "no stable region" band; the Z-width never reached 0.
    from symstab.numeric.paper.region import limits

    lower = drawn[name].axes[4:8]
    assert len(lower) == 4, "a lower row of linear Z-width panels"
    for ax, d in zip(lower, figures.DELAYS, strict=True):
        line, = ax.lines[:1]
        g, z = line.get_xdata(), line.get_ydata()
        end, before = (-1, -2) if right else (0, 1)
        assert z[end] == 0.0 and z[before] > 0.0
        vanish = g[end]
        # The end is where the region vanishes: none there, one 1e-4 inside.
        inward = -1e-4 if right else 1e-4
        assert limits(gamma=vanish, d=d, delta=DELTA).empty
        assert not limits(gamma=vanish + inward, d=d, delta=DELTA).empty
        # The "no stable region" band starts there: no unclassified gap.
        band, = [p for p in ax.patches if p.get_facecolor()[0] == 1.0 and p.get_facecolor()[1] == 0.0]
        x0, x1 = band.get_x(), band.get_x() + band.get_width()
        assert (x0 if right else x1) == pytest.approx(vanish, abs=1e-12)


def test_fig10_draws_the_lower_edge_of_the_gamma_1_band(drawn):
    # Panel (d) drew eq. (7) only up to theta_max: the stable band's lower
    # edge was not drawn and half the loop read as a disagreement.
    from symstab.numeric.paper.device import PAPER_DEVICE as dev
    from symstab.numeric.paper.region import StabilityRegion

    ax = drawn["fig10"].axes[3]
    assert r"M_w = m$" in ax.get_title()  # not "1 m"
    region = StabilityRegion(gamma=1.0, d=40, delta=DELTA)
    lines = [ax.transData.transform(line.get_xydata()) for line in ax.lines]

    def distance(p):
        """Pixels from ``p`` to the nearest drawn segment."""
        best = np.inf
        for xy in lines:
            a, b = xy[:-1], xy[1:]
            ok = np.all(np.isfinite(a), axis=1) & np.all(np.isfinite(b), axis=1)
            a, b = a[ok], b[ok]
            ab = b - a
            t = np.clip(np.sum((p - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0, 1)
            if len(a):
                best = min(best, float(np.min(np.hypot(*(a + t[:, None] * ab - p).T))))
        return best

    checked = 0
    for b in np.linspace(0.012, 0.03, 4):
        (lo, hi), = region.alpha_intervals(b)
        assert lo > 0.0
        # numpy's roots confirm the edge: stable just above it, not just below.
        assert _numpy_unstable(lo * 1.01, b, 1.0, 40) == 0 < _numpy_unstable(lo * 0.99, b, 1.0, 40)
        edge = ax.transData.transform([(dev.damping(b), dev.stiffness(lo))])[0]
        assert distance(edge) < 1.0, (b, lo)  # within a pixel
        checked += 1
    assert checked == 4


def test_fig10_counts_in_the_cells_agree_with_numpy_roots(drawn):
    from symstab.numeric.paper.device import PAPER_DEVICE as dev

    fig = drawn["fig10"]
    for ax, g in zip(fig.axes[:4], (-0.5, 0.0, 0.5, 1.0), strict=True):
        counts = [t for t in ax.texts if t.get_text().isdigit()]
        assert len(counts) >= 2, ax.get_title()
        for t in counts:
            B, K = t.get_position()
            alpha, beta = K / dev.stiffness(1.0), B / dev.damping(1.0)
            assert _numpy_unstable(alpha, beta, g, 40) == int(t.get_text()), (g, B, K)


def test_fig10_passive_outline_lies_in_the_stable_set(drawn):
    # Colgate-Schenkel: a passive environment on the passive device is stable,
    # so the outline drawn as passive must lie in the stable set (numpy's roots).
    from symstab.numeric.paper.device import PAPER_DEVICE as dev

    ax = drawn["fig10"].axes[1]  # gamma = 0: the only panel with a passive set
    outline, = [line for line in ax.lines if line.get_color() == figures._PASSIVE]
    xy = np.asarray(outline.get_xydata())
    centre = xy.mean(axis=0)
    for B, K in centre + 0.98 * (xy[::max(1, len(xy) // 40)] - centre):
        alpha, beta = K / dev.stiffness(1.0), B / dev.damping(1.0)
        assert _numpy_unstable(alpha, beta, 0.0, 40) == 0, (B, K)
    for ax in drawn["fig10"].axes[:4]:
        has_outline = any(line.get_color() == figures._PASSIVE for line in ax.lines)
        assert has_outline != ("no passive point" in ax.get_title()), ax.get_title()


def test_fig7_numbers_are_not_struck_through(drawn):
    # The numbers sat at the circles' centres, on the curves.
    fig = drawn["fig7"]
    ax = fig.axes[0]
    renderer = fig.canvas.get_renderer()
    numbers = [t for t in ax.texts if t.get_text() in {"1", "2", "3", "4", "5", "6"}]
    assert len(numbers) == 6
    points = _data_points(ax)
    for t in numbers:
        box = t.get_window_extent(renderer)
        inside = ((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                  & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))
        assert not inside.any(), t.get_text()


@pytest.mark.parametrize("name", ("fig6", "fig8", "fig10"))
def test_simulation_is_a_hatched_check_over_the_exact_fill(drawn, name):
    # The simulated map was the only shading; now the exact stable cells are
    # filled and the simulation is hatched over them.
    import matplotlib.patches

    fig = drawn[name]
    for ax in fig.axes[:4]:
        fills = [p for p in ax.patches if isinstance(p, matplotlib.patches.PathPatch) and p.get_fill()]
        hatched = [c for c in ax.collections if any(getattr(c, "hatches", None) or [c.get_hatch()])]
        assert fills, ax.get_title()
        assert hatched, ax.get_title()
