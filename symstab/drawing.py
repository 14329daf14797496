"""The one home of matplotlib: the style, the PNG bytes and the shared pieces of every drawing.

:mod:`symstab.figures`, the command line's PNGs (``symstab map``, ``locus``,
...) and :mod:`symstab.reproduce` draw through this module and compute
nothing here: what they draw comes from the numeric API.  matplotlib is an
extra (``pip install 'symstab[figures]'``); :func:`require_matplotlib` says
so in one line where it is missing.
"""

import io
import math
import sys

import numpy as np

__all__ = ["require_matplotlib", "pyplot", "pyplot_or_none", "png_bytes", "visible",
           "draw_lines", "label_log_axis", "design_figure", "SUPTITLE_SIZE", "PANEL_TITLE_SIZE", "LEGEND_SIZE"]

#: Font sizes (pt).  A figure's own title sits above its panels' titles, so it
#: is the largest; legends stay readable at the saved 110 dpi (6-7 pt was not).
SUPTITLE_SIZE = 13
PANEL_TITLE_SIZE = 11
LEGEND_SIZE = 8


def require_matplotlib():
    """Raise a one-line ValueError when matplotlib is missing (it is an extra)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ValueError("the figures need matplotlib: pip install 'symstab[figures]' "
                         "(or pip install matplotlib)") from None


def pyplot():
    """matplotlib.pyplot with the Agg backend and the figures' style."""
    require_matplotlib()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 10, "axes.grid": True, "grid.alpha": 0.3,
                         "savefig.dpi": 110, "figure.dpi": 110})
    return plt


def pyplot_or_none():
    """matplotlib's pyplot, or None (said on stderr) where matplotlib is not installed."""
    try:
        return pyplot()
    except ValueError:
        print("matplotlib is not installed: no PNG", file=sys.stderr)
        return None


def png_bytes(plt, fig):
    """The figure as PNG bytes (no software tag: the bytes depend on the drawing only); closes it."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def visible(values, lo, hi):
    """``values`` with NaN where far outside [lo, hi], so that a line breaks there."""
    span = hi - lo
    out = np.array(values, dtype=float)
    out[~((out > lo - 2 * span) & (out < hi + 2 * span))] = np.nan
    return out


def draw_lines(ax, lines, xs, ys, to_x=np.asarray, to_y=np.asarray):
    """Draw the D-decomposition's lines ``c0 + cx x + cy y = 0`` across a window; return the handles.

    ``xs`` and ``ys`` are the window's grids in the lines' plane; ``to_x`` and
    ``to_y`` take that plane's coordinates to the axes' (a map drawn in
    other units).
    """
    styles = {"z = 1": ("C0", "--"), "z = -1": ("C3", "--"), "leading": ("C1", ":")}
    handles = []
    for label, (c0, cx, cy) in lines.items():
        color, style = styles.get(label, ("C4", "-."))
        if cy != 0:
            px, py = xs[[0, -1]], -(c0 + cx * xs[[0, -1]]) / cy
        else:
            px, py = np.full(2, -c0 / cx), ys[[0, -1]]
        if np.all(py < ys[0]) or np.all(py > ys[-1]) or np.all(px < xs[0]) or np.all(px > xs[-1]):
            continue   # the line misses the window
        handles += ax.plot(to_x(px), to_y(py), color=color, ls=style, lw=1.2,
                           label=label.replace("leading", "leading coefficient 0")
                           .replace("z = 1", "root z = 1").replace("z = -1", "root z = -1"))
    return handles


def label_log_axis(ax):
    """Label 1-2-5 steps on a log y axis that spans less than three decades.

    Over so few decades matplotlib labels only the powers of ten -- two or
    three ticks; the steps between them are written as plain numbers.  Call
    it after plotting, so the limits are the data's.
    """
    from matplotlib import ticker

    lo, hi = ax.get_ylim()
    if math.log10(hi / lo) < 3:
        ax.yaxis.set_major_locator(ticker.LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(ticker.NullFormatter())


def design_figure(plt, found, labels, target_label):
    """A :class:`~symstab.numeric.analysis.design.Design` drawn: its target against the parameter(s) searched.

    One parameter: the target at every value evaluated (a line through the
    scan and the refinement), the values with no stable point marked at the
    bottom, the optimum and the nominal value marked.  Two: the evaluations
    coloured by the target, the same marks.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    found : symstab.numeric.analysis.design.Design
    labels : list of str
        The axis label of each parameter searched.
    target_label : str
        The target's label, with its unit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    samples = found.samples
    names = list(found.over)
    value = samples[:, -1]
    good = np.isfinite(value)
    none = value == -np.inf
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    what = "maximise " + target_label.split(" [")[0]
    if len(names) == 1:
        order = np.argsort(samples[:, 0])
        u, v = samples[order, 0], value[order]
        ax.plot(u[np.isfinite(v)], v[np.isfinite(v)], "-o", color="C0", ms=3, lw=1.2,
                label=f"{target_label.split(' [')[0]} ({int(good.sum())} evaluations)")
        if none.any():
            floor = np.min(value[good]) if good.any() else 0.0
            ax.plot(samples[none, 0], np.full(int(none.sum()), floor), "x", color="0.5",
                    label="no stable point")
        if found.nominal:
            ax.axvline(found.nominal[names[0]], color="C2", ls="--", lw=1,
                       label=f"nominal {names[0]} = {found.nominal[names[0]]:.4g}")
        if found.best is not None:
            ax.plot([found.best[names[0]]], [found.value], "*", color="C3", ms=12,
                    label=f"best {names[0]} = {found.best[names[0]]:.6g}")
        ax.set_xlabel(labels[0])
        ax.set_ylabel(target_label)
    else:
        if good.any():
            dots = ax.scatter(samples[good, 0], samples[good, 1], c=value[good], s=18,
                              cmap="viridis")
            fig.colorbar(dots, ax=ax, label=target_label)
        if none.any():
            ax.plot(samples[none, 0], samples[none, 1], "x", color="0.6", ms=4,
                    label="no stable point")
        if found.nominal:
            ax.plot([found.nominal[names[0]]], [found.nominal[names[1]]], "o", mfc="none",
                    color="C2", ms=9, label="nominal")
        if found.best is not None:
            ax.plot([found.best[names[0]]], [found.best[names[1]]], "*", color="C3", ms=14,
                    label="best " + ", ".join(f"{k} = {v:.4g}" for k, v in found.best.items()))
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
    ax.set_title(f"design: {what} over {' and '.join(names)}", fontsize=PANEL_TITLE_SIZE)
    ax.legend(fontsize=LEGEND_SIZE, loc="best")
    fig.tight_layout()
    return fig
