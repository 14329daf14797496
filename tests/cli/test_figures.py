"""The figures' text (issue 13): symbols in mathtext, readable sizes, labelled log axes.

A new user read "M_w = 0 m" as metres, saw literal "T_d" and "gamma <= 0" in
suptitles, squinted at 6 pt legends under suptitles smaller than the panel
titles, got two labels on Fig. 4's log axis and "first root of alpha" as a
legend.  These tests read the drawn figures' text artists; the figures are
built with small grids (the text does not depend on them).
"""

import re

import pytest

pytest.importorskip("matplotlib")

import matplotlib.legend  # noqa: E402
import matplotlib.text  # noqa: E402

from symstab import figures  # noqa: E402

# Small grids and gamma scans: the text is the same as at full size.
_SMALL = {"fig3": {}, "fig4": {}, "fig5": {}, "fig6": {"n": 4}, "fig7": {}, "fig8": {"n": 4},
          "fig10": {"n": 6}, "fig11": {"n": 4}, "fig12": {"n": 4}}
_PANELLED = ("fig6", "fig8", "fig10", "fig11", "fig12")


@pytest.fixture(scope="module")
def drawn():
    """Figures by name, built when a test first asks (each xdist worker builds its own)."""
    plt = figures.pyplot()
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
    assert len(panels) == 4
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
    for ax in drawn[name].axes:
        assert ax.get_yscale() == "log"
        assert len(_labelled_ticks(ax)) >= 3, (ax.get_title(), _labelled_ticks(ax))
