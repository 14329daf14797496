"""The one home of matplotlib: the style, the PNG bytes, every PNG of the CLI and the figures.

The command line's PNGs (``symstab map``, ``locus``, ``limits``,
``design``) and the paper's figures (:mod:`symstab.figures`, which
:mod:`symstab.reproduce` saves) are drawn here whole, each by a function
that returns its figure (:func:`png_of` makes a command's PNG bytes of
it): the command or the figure computes (through the numeric API) and
hands the results over; nothing here computes a stability question (what
is drawn where, such as which cells have room for their root count, is
decided here).  No module of
:mod:`symstab.cli` imports matplotlib (``tests/test_layers.py``).  matplotlib is an
extra (``pip install 'symstab[figures]'``); :func:`require_matplotlib` says
so in one line where it is missing.
"""

import io
import math
import sys

import numpy as np

__all__ = ["Plot", "plot_region", "plot_limits", "plot_boundary", "plot_robust",
           "plot_probability", "plot_design", "plot_pareto", "plot_passive", "plot_locus",
           "plot_simulation", "plot_map", "plot_margin_map", "plot_delay_range_map", "plot_delay_range_region",
           "require_matplotlib", "pyplot",
           "pyplot_or_none", "png_bytes", "visible",
           "draw_lines", "label_log_axis", "png_of", "png_or_none", "design_figure",
           "simulated_map_figure", "loop_map_figure", "probability_map_figure", "robust_figure",
           "locus_figure",
           "theta_max_gamma_figure", "theta_max_delay_figure", "eq14_figure", "regions_figure",
           "boundaries_d0_figure", "physical_figure", "limits_figure", "FIGURE_COLORS",
           "PASSIVE_COLOR",
           "LIMIT_CYCLE_COLOR", "LIMIT_CYCLE_LABEL", "SUPTITLE_SIZE", "PANEL_TITLE_SIZE",
           "LEGEND_SIZE"]

#: Font sizes (pt).  A figure's own title sits above its panels' titles, so it
#: is the largest; legends stay readable at the saved 110 dpi (6-7 pt was not).
SUPTITLE_SIZE = 13
PANEL_TITLE_SIZE = 11
LEGEND_SIZE = 8

#: The colour and legend of a map's cell whose run settles into a bounded
#: limit cycle (:attr:`symstab.numeric.simulation.simulator.Simulation.limit_cycle`):
#: neither stable (green) nor growing (white).
LIMIT_CYCLE_COLOR = "#fdb863"
LIMIT_CYCLE_LABEL = "bounded limit cycle (simulated)"


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


def png_of(figure, *args, **kwargs):
    """The figure that ``figure`` draws, as PNG bytes (:func:`png_bytes`).

    Parameters
    ----------
    figure : callable
        ``figure(plt, *args, **kwargs)`` draws with ``plt`` (:func:`pyplot`)
        and returns the :class:`matplotlib.figure.Figure`, as
        :func:`design_figure` and the maps' figures do.
    *args, **kwargs
        Handed to ``figure``.

    Returns
    -------
    bytes

    Raises
    ------
    ValueError
        Where matplotlib is missing, in one line (:func:`require_matplotlib`).
    """
    plt = pyplot()
    return png_bytes(plt, figure(plt, *args, **kwargs))


def png_or_none(figure, *args, **kwargs):
    """:func:`png_of`, or None (said on stderr) where matplotlib is missing.

    Parameters
    ----------
    figure, *args, **kwargs
        As in :func:`png_of`.

    Returns
    -------
    bytes or None
    """
    plt = pyplot_or_none()
    return None if plt is None else png_bytes(plt, figure(plt, *args, **kwargs))


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


def design_figure(plt, found, labels, target_label, noise_label="force noise (RMS)"):
    """A :class:`~symstab.numeric.analysis.design.Design` drawn: its target against the parameter(s) searched.

    One parameter: the target at every value evaluated (a line through the
    scan and the refinement), the values with no stable point marked at the
    bottom, the optimum and the nominal value marked.  Two: the evaluations
    coloured by the target, the same marks.  Where the design recorded the
    force noise (an encoder given), a second panel: the target against the
    noise (:func:`plot_pareto`).

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    found : symstab.numeric.analysis.design.Design
    labels : list of str
        The axis label of each parameter searched.
    target_label : str
        The target's label, with its unit.
    noise_label : str
        The force noise's label, with its unit.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if found.noise is None:
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        _draw_design(ax, found, labels, target_label)
    else:
        fig, (ax, front) = plt.subplots(1, 2, figsize=(11.0, 4.4))
        _draw_design(ax, found, labels, target_label)
        _draw_pareto(front, found, target_label, noise_label)
    fig.tight_layout()
    return fig


def _draw_design(ax, found, labels, target_label):
    """:func:`design_figure`'s drawing on ``ax``: ``{"target", "best", "nominal", "none"}`` artists."""
    fig = ax.figure
    samples = found.samples
    names = list(found.over)
    value = samples[:, -1]
    good = np.isfinite(value)
    none = value == -np.inf
    artists = {"target": [], "none": [], "nominal": [], "best": []}
    what = "maximise " + target_label.split(" [")[0]
    if len(names) == 1:
        order = np.argsort(samples[:, 0])
        u, v = samples[order, 0], value[order]
        artists["target"] += ax.plot(
            u[np.isfinite(v)], v[np.isfinite(v)], "-o", color="C0", ms=3, lw=1.2,
            label=f"{target_label.split(' [')[0]} ({int(good.sum())} evaluations)")
        if none.any():
            floor = np.min(value[good]) if good.any() else 0.0
            artists["none"] += ax.plot(samples[none, 0], np.full(int(none.sum()), floor), "x",
                                       color="0.5", label="no stable point")
        if found.nominal:
            artists["nominal"].append(ax.axvline(
                found.nominal[names[0]], color="C2", ls="--", lw=1,
                label=f"nominal {names[0]} = {found.nominal[names[0]]:.4g}"))
        if found.best is not None:
            artists["best"] += ax.plot([found.best[names[0]]], [found.value], "*", color="C3",
                                       ms=12, label=f"best {names[0]} = {found.best[names[0]]:.6g}")
        artists["over budget"] = _shade_over_budget(ax, found)
        ax.set_xlabel(labels[0])
        ax.set_ylabel(target_label)
    else:
        if good.any():
            dots = ax.scatter(samples[good, 0], samples[good, 1], c=value[good], s=18,
                              cmap="viridis")
            fig.colorbar(dots, ax=ax, label=target_label)
            artists["target"].append(dots)
        if none.any():
            artists["none"] += ax.plot(samples[none, 0], samples[none, 1], "x", color="0.6",
                                       ms=4, label="no stable point")
        if found.nominal:
            artists["nominal"] += ax.plot([found.nominal[names[0]]], [found.nominal[names[1]]],
                                          "o", mfc="none", color="C2", ms=9, label="nominal")
        if found.best is not None:
            artists["best"] += ax.plot(
                [found.best[names[0]]], [found.best[names[1]]], "*", color="C3", ms=14,
                label="best " + ", ".join(f"{k} = {v:.4g}" for k, v in found.best.items()))
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
    ax.set_title(f"design: {what} over {' and '.join(names)}", fontsize=PANEL_TITLE_SIZE)
    ax.legend(fontsize=LEGEND_SIZE, loc="best")
    return artists


def _shade_over_budget(ax, found):
    """Shade the values of the one parameter searched whose force noise is over the budget.

    From the budget's scan (:attr:`~symstab.numeric.analysis.design.Design.noise_samples`,
    whose edges are bisected): each run of values over it, to its neighbours within it.
    """
    if found.noise_limit is None or found.noise_samples is None:
        return []
    (name, (low, high)), = found.over.items()
    x, noise = found.noise_samples[:, 0], found.noise_samples[:, -1]
    # Beyond the values scanned (a bracket of Stodola's condition) no point is stable, the
    # rendered one neither: unbounded noise.
    if x[0] > low:
        x, noise = np.r_[low, x], np.r_[np.inf, noise]
    if x[-1] < high:
        x, noise = np.r_[x, high], np.r_[noise, np.inf]
    over = noise > found.noise_limit
    spans, k = [], 0
    while k < len(x):
        if not over[k]:
            k += 1
            continue
        j = k
        while j + 1 < len(x) and over[j + 1]:
            j += 1
        lo, hi = x[k - 1] if k > 0 else x[k], x[j + 1] if j + 1 < len(x) else x[j]
        spans.append(ax.axvspan(lo, hi, color="0.88", zorder=0,
                                label=None if spans else "force noise over the budget"))
        k = j + 1
    ax.set_xlim(low - 0.02 * (high - low), high + 0.02 * (high - low))
    return spans


def _draw_pareto(ax, found, target_label, noise_label):
    """:func:`plot_pareto`'s drawing on ``ax``: ``{"samples", "front", "best", "limit"}`` artists."""
    rows = np.column_stack([found.samples, found.noise])
    rows = rows[np.isfinite(rows[:, -2]) & np.isfinite(rows[:, -1])]
    front = found.pareto
    target = target_label.split(" [")[0]
    artists = {"samples": [], "front": [], "best": [], "limit": []}
    artists["samples"] += ax.plot(rows[:, -1], rows[:, -2], "o", color="0.7", ms=3,
                                  label=f"values evaluated ({len(rows)})")
    artists["front"] += ax.plot(front[:, -1], front[:, -2], "-o", color="C0", ms=3, lw=1.2,
                                label=f"Pareto front ({len(front)})")
    if found.noise_limit is not None:
        artists["limit"].append(ax.axvline(found.noise_limit, color="C3", ls="--", lw=1,
                                           label=f"noise budget {found.noise_limit:.4g}"))
    if not len(rows):
        ax.text(0.5, 0.5, "the rendered point is stable at no value evaluated:\nits force noise "
                "is unbounded", transform=ax.transAxes, ha="center", va="center")
    if found.best is not None and math.isfinite(found.best_noise):
        name = next(iter(found.over))
        artists["best"] += ax.plot([found.best_noise], [found.value], "*", color="C3", ms=12,
                                   label=f"best {name} = {found.best[name]:.6g}"
                                   if len(found.over) == 1 else "best")
    ax.set_xlabel(noise_label)
    ax.set_ylabel(target_label)
    at = ", ".join(f"{k} = {v:.4g}" for k, v in found.noise_at.items())
    ax.set_title(f"{target} against the force noise at {at}", fontsize=PANEL_TITLE_SIZE)
    ax.legend(fontsize=LEGEND_SIZE, loc="best")
    return artists


# --------------------------------------------------------------------------
# symstab map


def simulated_map_figure(plt, x, y, stable, limit_cycle, *, boundary, xlabel, ylabel, title):
    """The paper's map simulated.

    The cells shaded by the simulation's verdict (stable green, a bounded
    limit cycle :data:`LIMIT_CYCLE_COLOR`), the boundary of the loop
    simulated drawn over them.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    x, y : numpy.ndarray
        The grids of the axes (in the units the user gave).
    stable, limit_cycle : numpy.ndarray of bool
        The simulation's verdicts, ``(y, x)``.
    boundary : dict
        ``curve`` (the arc's ``(x, y)`` in the plane's coordinates, NaN
        between branches), ``label`` (the arc's legend), ``lines`` (the
        D-decomposition's lines, as :func:`draw_lines`), ``plane`` (the
        grids ``(x, y)`` in the plane's coordinates), ``to_x`` and ``to_y``
        (the plane's coordinates to the axes').
    xlabel, ylabel, title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    to_x, to_y = boundary["to_x"], boundary["to_y"]
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    ax.pcolormesh(x, y, np.where(stable, 1, np.where(limit_cycle, 2, 0)),
                  shading="nearest", cmap=ListedColormap(["white", "#7fc97f", LIMIT_CYCLE_COLOR]),
                  vmin=0, vmax=2)
    arc_x, arc_y = boundary["curve"]
    drawn = []
    if np.any(np.isfinite(arc_x)):
        drawn += ax.plot(to_x(arc_x), to_y(arc_y), "k-", lw=1.2, label=boundary["label"])
    drawn += draw_lines(ax, boundary["lines"], *boundary["plane"], to_x, to_y)
    if np.any(limit_cycle):
        drawn.append(Patch(facecolor=LIMIT_CYCLE_COLOR, label=LIMIT_CYCLE_LABEL))
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    if drawn:
        ax.legend(handles=drawn, loc="upper right", fontsize=9)
    fig.tight_layout()
    return fig


def _loop_boundary(ax, curve, xs, ys, label=""):
    """A loop's D-decomposition (a :class:`~symstab.numeric.engine.results.Boundary`) on ``ax``.

    Returns the legend's handles.
    """
    bx, by = visible(curve.x_values, xs[0], xs[-1]), visible(curve.y_values, ys[0], ys[-1])
    bx[np.isnan(by)] = np.nan
    handles = []
    if np.any(np.isfinite(bx)):
        handles += ax.plot(bx, by, "k-", lw=1.2,
                           label=label + r"$z = e^{j\theta}$ root (D-decomposition)")
    return handles + draw_lines(ax, curve.lines, xs, ys)


def _map_frame(ax, xs, ys, xlabel, ylabel):
    """A map's limits and its axes' names."""
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)


def loop_map_figure(plt, xs, ys, shade, legend, curve, *, xlabel, ylabel, title):
    """A loop file's map, its D-decomposition over it.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    xs, ys : numpy.ndarray
        The grids.
    shade : numpy.ndarray of int
        ``(y, x)``: 0 unstable (white), 1 marginal (grey), 2 stable (green),
        3 a bounded limit cycle (:data:`LIMIT_CYCLE_COLOR`).
    legend : list of (str, str)
        ``(colour, label)`` of each shade named in the legend.
    curve : symstab.numeric.engine.results.Boundary
        The loop's D-decomposition over the window.
    xlabel, ylabel, title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    ax.pcolormesh(xs, ys, shade, shading="nearest", vmin=0, vmax=3,
                  cmap=ListedColormap(["white", "#bdbdbd", "#7fc97f", LIMIT_CYCLE_COLOR]))
    handles = [Patch(facecolor=color, label=label) for color, label in legend]
    handles += _loop_boundary(ax, curve, xs, ys)
    _map_frame(ax, xs, ys, xlabel, ylabel)
    ax.set_title(title, fontsize=9)
    ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.9)
    fig.tight_layout()
    return fig


def probability_map_figure(plt, found, curve, *, xlabel, ylabel, title):
    """The probability of stability, the nominal loop's boundary over it.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    found : symstab.numeric.engine.results.StabilityProbability
    curve : symstab.numeric.engine.results.Boundary
        The nominal loop's D-decomposition over the window.
    xlabel, ylabel, title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    _draw_probability(ax, found, curve, xlabel, ylabel)
    ax.set_title(title, fontsize=8)
    fig.tight_layout()
    return fig


def _draw_probability(ax, found, curve, xlabel, ylabel):
    """:func:`probability_map_figure`'s drawing on ``ax`` (``curve`` may be None).

    Returns ``{"probability": [mesh], "colorbar": [colorbar], "boundary": [...]}``.
    """
    xs, ys = found.x_values, found.y_values
    mesh = ax.pcolormesh(xs, ys, found.probability, shading="nearest", vmin=0.0, vmax=1.0,
                         cmap="Greens")
    bar = ax.figure.colorbar(mesh, ax=ax, label="probability of stability")
    handles = [] if curve is None else _loop_boundary(ax, curve, xs, ys, "nominal loop: ")
    _map_frame(ax, xs, ys, xlabel, ylabel)
    if handles:
        ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.9)
    return {"probability": [mesh], "colorbar": [bar], "boundary": handles}


# --------------------------------------------------------------------------
# symstab limits --uncertain


def robust_figure(plt, region, xlabel, ylabel):
    """The robust set (filled), what stayed marginal and the nominal set's outline.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    region : symstab.numeric.engine.results.RobustRegion
        The robust set, with the nominal loop's region.
    xlabel, ylabel : str
        The axes' names.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    _draw_robust(ax, region, xlabel, ylabel)
    fig.tight_layout()
    return fig


def _draw_robust(ax, region, xlabel, ylabel):
    """:func:`robust_figure`'s drawing on ``ax``: ``{"nominal", "marginal", "robust"}`` artists."""
    from matplotlib.patches import Patch, Polygon

    artists = {"nominal": [], "marginal": [], "robust": []}
    nominal = region.nominal
    if nominal is not None:
        for k, cell in enumerate(nominal.stable):
            ring = np.vstack([cell.outer, cell.outer[:1]])
            artists["nominal"] += ax.plot(ring[:, 0], ring[:, 1], color="0.2", lw=1.0,
                                          label="stable at the box's centre" if k == 0 else None)
    for i, bands in enumerate(region.marginal):
        x0, x1 = region.edges[i], region.edges[i + 1]
        for lo0, hi0, lo1, hi1 in bands:
            artists["marginal"].append(ax.add_patch(Polygon(
                [(x0, lo0), (x1, lo1), (x1, hi1), (x0, hi0)], closed=True,
                facecolor="#f4a582", edgecolor="none")))
    # The robust set's outlines (runs of strips joined: no seams between them).
    for outline in region.polygons:
        artists["robust"].append(ax.add_patch(Polygon(outline, closed=True, facecolor="#4393c3",
                                                      edgecolor="none")))
    handles, _ = ax.get_legend_handles_labels()
    handles += [Patch(color="#4393c3", label="stable for every value of the box"),
                Patch(color="#f4a582", label="marginal (not certified)")]
    ax.legend(handles=handles, loc="best", fontsize=8)
    if nominal is not None:
        ax.set_xlim(*nominal.x_range)
        ax.set_ylim(*nominal.y_range)
    box = ", ".join(f"{k} in [{lo:.4g}, {hi:.4g}]" for k, (lo, hi) in region.uncertain.items())
    ax.set_title(f"robust stable set: {box}", fontsize=9)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    return artists


# --------------------------------------------------------------------------
# symstab locus

#: Poles farther out than this are left out of the z-plane panel (said in its title).
_PLANE_LIMIT = 3.0


def _zoom(poles, crossings, limit):
    """``(x0, x1, y0, y1)``: a square window on where the poles move and cross.

    The bounding box of the poles that move at least a tenth as far as the
    one that moves most, with the crossings; if that is most of the plane,
    the stretch of the first crossing pole's path (a pair's first) near
    its crossing, or where a pole comes nearest the circle.
    """
    finite = np.isfinite(poles) & (np.abs(poles) <= limit)
    steps = np.where(finite[1:] & finite[:-1], np.abs(np.diff(np.where(finite, poles, 0), axis=0)),
                     0.0)
    moved = steps.sum(axis=0)
    points = [complex(c.z) for c in crossings] + [complex(c.z).conjugate() for c in crossings]
    if moved.max() > 0:
        columns = moved >= 0.1 * moved.max()
        points += list(poles[:, columns][finite[:, columns]])
    half = _half_width(points)
    if half is None or half > 0.4 * limit:
        if crossings:
            pick = next((c for c in crossings if c.kind == "pair"), crossings[0])
            path = poles[:, pick.pole_index]
            near = finite[:, pick.pole_index] & (np.abs(path - pick.z) <= 0.3)
            points = [complex(pick.z), complex(pick.z).conjugate()] + list(path[near])
        else:
            distance = np.where(finite, np.abs(np.abs(poles) - 1.0), np.inf)
            points = [complex(poles.flat[int(np.argmin(distance))])]
        half = max(_half_width(points), 0.05)
    box = np.array(points)
    centre = (0.5 * (box.real.min() + box.real.max()), 0.5 * (box.imag.min() + box.imag.max()))
    return centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half


def _half_width(points):
    if not points:
        return None
    box = np.array(points)
    return max(0.5 * max(np.ptp(box.real), np.ptp(box.imag)) * 1.15, 0.01)


_MARKS = {"pair": ("*", "C3", "complex pair crossing"), "z = 1": ("s", "C1", "real pole crossing"),
          "z = -1": ("D", "C1", "real pole crossing")}


def _plane(ax, locus, shown, symbol, norm, limit, window=None):
    """One z-plane panel: the poles coloured by the path's value, the circle, the crossings."""
    poles = locus.poles
    finite = np.isfinite(poles)
    keep = finite & (np.abs(poles) <= limit)
    if window is not None:
        x0, x1, y0, y1 = window
        keep &= (poles.real >= x0) & (poles.real <= x1) & (poles.imag >= y0) & (poles.imag <= y1)
    colour = np.broadcast_to(shown[:, None], poles.shape)
    theta = np.linspace(0, 2 * np.pi, 20001)
    ax.plot(np.cos(theta), np.sin(theta), color="0.25", lw=1.0, zorder=1,
            label=r"unit circle $|z| = 1$")
    dots = ax.scatter(poles.real[keep], poles.imag[keep], c=colour[keep], s=4, cmap="viridis",
                      norm=norm, zorder=2, linewidths=0)
    start = keep[0]
    ax.plot(poles.real[0][start], poles.imag[0][start], "o", mfc="none", mec="0.4", ms=4,
            mew=0.7, lw=0, zorder=3,
            label=f"poles at the start, {symbol} = {shown[0]:.4g}")
    labelled = set()
    for k, c in enumerate(locus.crossings):
        marker, color, label = _MARKS[c.kind]
        for imag in ((c.z.imag, -c.z.imag) if c.kind == "pair" else (c.z.imag,)):
            ax.plot([c.z.real], [imag], marker, color=color, mec="k", ms=11, zorder=4,
                    label=None if label in labelled else label)
            labelled.add(label)
        ax.annotate(f"{k + 1}", (c.z.real, c.z.imag), xytext=(8, 6), textcoords="offset points",
                    fontsize=10, fontweight="bold", zorder=5,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
    if window is None:
        ax.set_xlim(-limit, limit)
        ax.set_ylim(-limit, limit)
    else:
        ax.set_xlim(window[0], window[1])
        ax.set_ylim(window[2], window[3])
    ax.set_aspect("equal")
    ax.set_xlabel(r"Re $z$")
    ax.set_ylabel(r"Im $z$")
    return dots


def locus_figure(plt, locus, given, show, stretches, *, symbol, tex, title):
    """A root locus: the z-plane, a zoom on where the poles cross, the largest modulus.

    Parameters
    ----------
    plt : module
        :func:`pyplot`.
    locus : symstab.numeric.engine.locus.Locus
    given : array_like
        The path's values as the user gave them (in the units shown).
    show : callable
        The path's values to the units shown.
    stretches : list of (float, float, int or None)
        The path's stretches (in the path's values) and the poles outside the
        circle along each (None: undecided).
    symbol : str
        The path's parameter in mathtext, for the legend.
    tex : str
        The path's axis label, mathtext.
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import Normalize
    from matplotlib.patches import Rectangle

    shown = np.asarray(given, dtype=float)
    poles = locus.poles
    finite = np.isfinite(poles)
    radius = float(np.max(np.abs(poles[finite]))) if finite.any() else 1.0
    limit = min(max(1.15, 1.05 * radius), _PLANE_LIMIT)
    norm = Normalize(vmin=float(min(shown[0], shown[-1])), vmax=float(max(shown[0], shown[-1])))
    fig = plt.figure(figsize=(11.5, 10.5))
    grid = fig.add_gridspec(2, 2, height_ratios=[1.25, 1.0])
    ax, zx, bx = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, :])
    dots = _plane(ax, locus, shown, symbol, norm, limit)
    window = _zoom(poles, locus.crossings, limit)
    _plane(zx, locus, shown, symbol, norm, limit, window)
    ax.add_patch(Rectangle((window[0], window[2]), window[1] - window[0], window[3] - window[2],
                           fill=False, ec="C3", lw=1.0, ls="--", zorder=6))
    hidden = bool((finite & (np.abs(poles) > limit)).any())
    ax.set_title("closed-loop poles in the $z$-plane" + (
        f"\n(poles beyond $|z|$ = {limit:g} not shown)" if hidden else ""),
        fontsize=PANEL_TITLE_SIZE)
    zx.set_title("zoom on the dashed square: where the poles move and cross",
                 fontsize=PANEL_TITLE_SIZE)
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.505), ncol=4,
               fontsize=LEGEND_SIZE + 1, frameon=False)
    # The largest modulus along the path, the stable stretches shaded.
    rho = locus.spectral_radius()
    bx.plot(shown, rho, color="C0", lw=1.6, label=r"largest pole modulus $\max|z|$")
    bx.axhline(1.0, color="0.25", lw=1.0, ls="--", label=r"$|z| = 1$")
    first = True
    top = bx.get_ylim()[1]
    for lo, hi, count in stretches:
        lo, hi = sorted((float(show(lo)), float(show(hi))))
        if count == 0:
            bx.axvspan(lo, hi, color="#7fc97f", alpha=0.35, lw=0,
                       label="stable (no pole outside)" if first else None)
            first = False
        if count is not None and hi - lo > 0.06 * abs(shown[-1] - shown[0]):
            bx.text(0.5 * (lo + hi), top, f"{count} outside", ha="center", va="bottom",
                    fontsize=9, color="0.2")
    for k, c in enumerate(locus.crossings):
        x = float(show(c.value))
        marker, color, _ = _MARKS[c.kind]
        bx.axvline(x, color=color, lw=0.9, ls=":")
        bx.plot([x], [1.0], marker, color=color, mec="k", ms=9, zorder=4)
        # Alternately below and above the line: neighbouring crossings stay apart.
        bx.annotate(f"{k + 1}", (x, 1.0), xytext=(6, -14 if k % 2 == 0 else 6),
                    textcoords="offset points",
                    fontsize=10, fontweight="bold")
    bx.set_xlabel(tex)
    bx.set_ylabel(r"$\max|z|$")
    bx.set_xlim(float(min(shown[0], shown[-1])), float(max(shown[0], shown[-1])))
    bx.set_title("largest pole modulus along the path; crossings numbered as in the table, "
                 "poles outside the circle counted above", fontsize=PANEL_TITLE_SIZE, pad=18)
    bx.legend(fontsize=LEGEND_SIZE + 1, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3,
              frameon=False)
    fig.suptitle(title, fontsize=SUPTITLE_SIZE)
    fig.subplots_adjust(left=0.07, right=0.89, top=0.92, bottom=0.1, hspace=0.45, wspace=0.22)
    # The colour bar beside the z-plane panels, in an axes of its own (so
    # that it takes no width from the zoom).
    place = zx.get_position()
    bar = fig.colorbar(dots, cax=fig.add_axes([0.91, place.y0, 0.015, place.height]))
    bar.set_label("pole colour: " + tex)
    return fig


# --------------------------------------------------------------------------
# The paper's figures (symstab.figures computes what they show)

#: The figures' colours, one per gamma of a panel.
FIGURE_COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")
#: Legend of the arc's end angle in Figs. 3 and 4, in words rather than in
#: the derivation's terms ("first root of alpha").
_THETA_MAX_EXACT = r"exact: where the arc ends, $\alpha(\theta_{\max}) = 0$"
#: Styles of the boundary's parts, shared by the panels and the legends.
_ARC = {"ls": "-", "lw": 1.6}                       # eq. (7): theta from 0 to theta_max
_BEYOND = {"ls": (0, (4, 2)), "lw": 0.9}            # the same curve for theta_max < theta < pi
_Z_ONE = {"color": "0.35", "ls": "-", "lw": 0.9}    # alpha = 0: a root at z = 1
#: How the simulation is drawn: hatched, over the exact stable set's fill.
_SIM_HATCH = "////"
#: Opacity of the exact stable set's fill.
_FILL_ALPHA = 0.28
#: Colour of the passive set's outline (a test finds the outline by it).
PASSIVE_COLOR = "#d62728"
_PASSIVE = PASSIVE_COLOR
#: Caption of the root counts, for the figures' legends.
_COUNTS_NOTE = ("numbers: closed-loop poles outside the unit circle in that cell "
                "(certified root count)")


def _plane_labels(ax, physical=False):
    if physical:
        ax.set_xlabel(r"$B_w$ (N m s/rad)")
        ax.set_ylabel(r"$K_w$ (N m/rad)")
    else:
        ax.set_xlabel(r"$\beta = B_w T/m$")
        ax.set_ylabel(r"$\alpha = K_w T^2/m$")


def theta_max_gamma_figure(gammas, exact, closed):
    """Fig. 3: theta_max versus gamma (d = 0), the exact end of the arc and eq. (8) as dots.

    Parameters
    ----------
    gammas, exact, closed : numpy.ndarray
        The gammas, the exact theta_max and the closed form (8) at each.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = pyplot().subplots(figsize=(6, 4))
    ax.plot(gammas, exact, "-", color=FIGURE_COLORS[0], lw=2, label=_THETA_MAX_EXACT)
    ax.plot(gammas[::6], closed[::6], "o", color=FIGURE_COLORS[1], ms=4, label="closed form (8)")
    ax.set_xlabel(r"$\gamma = M_w/m$")
    ax.set_ylabel(r"$\theta_{\max}$ (rad)")
    ax.set_title(r"Fig. 3: $\theta_{\max}$ versus $\gamma$, $d = 0$")
    ax.legend()
    return fig


def theta_max_delay_figure(ds, exact, newton):
    """Fig. 4: theta_max versus d (gamma = 0), exact and one Newton step (12), log scale.

    Parameters
    ----------
    ds, exact, newton : numpy.ndarray
        The delays, the exact theta_max and eq. (12) at each (NaN at d = 0).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = pyplot().subplots(figsize=(6, 4))
    ax.semilogy(ds, exact, "-", color=FIGURE_COLORS[0], lw=2, label=_THETA_MAX_EXACT)
    ax.semilogy(ds[1:], newton[1:], "--", color=FIGURE_COLORS[1], lw=1.5,
                label="one Newton step, eq. (12)")
    ax.set_xlabel(r"delay $d = T_d / T$ (samples)")
    ax.set_ylabel(r"$\theta_{\max}$ (rad)")
    label_log_axis(ax)  # theta_max spans two decades, 1.6 to 0.017 rad
    ax.set_title(r"Fig. 4: $\theta_{\max}$ versus $d$, $\gamma = 0$")
    ax.legend()
    return fig


def eq14_figure(curve, printed_beta, printed_alpha):
    """Fig. 5: the derived boundary (d = 0, gamma = 0) and eq. (14) as printed over it.

    Parameters
    ----------
    curve : symstab.numeric.paper.region.BoundaryCurve
        The boundary as symstab derives it.
    printed_beta, printed_alpha : numpy.ndarray
        Eq. (14) as printed, at the curve's angles.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = pyplot().subplots(figsize=(6, 4))
    ax.plot(curve.beta, curve.alpha, "-", color=FIGURE_COLORS[2], lw=2.5,
            label=r"symstab (derived for any $d$ and $\gamma$)")
    ax.plot(printed_beta, printed_alpha, "--", color=FIGURE_COLORS[0], lw=1.5,
            label="eq. (14) as printed")
    _plane_labels(ax)
    ax.set_title(r"Fig. 5: boundary for $d = 0$, $\gamma = 0$")
    ax.legend()
    return fig


def _shade_cells(ax, decomposition, color, scale=(1.0, 1.0)):
    """Fill the stable cells of a D-decomposition, holes included.

    ``decomposition`` is a :class:`symstab.numeric.engine.decomposition.Decomposition`
    (x = beta, y = alpha); ``scale`` multiplies its coordinates into the
    plotted units.  Returns the patches.
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    sx, sy = scale

    def ring(points, clockwise):
        # A hole must wind the other way round than its outline to be left empty.
        x, y = points[:, 0] * sx, points[:, 1] * sy
        area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
        if (area < 0) != clockwise:
            x, y = x[::-1], y[::-1]
        vertices = np.column_stack([np.append(x, x[0]), np.append(y, y[0])])
        codes = np.full(len(vertices), Path.LINETO)
        codes[0], codes[-1] = Path.MOVETO, Path.CLOSEPOLY
        return vertices, codes

    patches = []
    for cell in decomposition.stable:
        parts = [ring(cell.outer, False)] + [ring(h, True) for h in cell.holes]
        path = Path(np.concatenate([v for v, _ in parts]), np.concatenate([c for _, c in parts]))
        patches.append(ax.add_patch(PathPatch(path, facecolor=color, edgecolor="none",
                                              alpha=_FILL_ALPHA, zorder=1)))
    return patches


def _count_text(ax, x, y, count):
    ax.text(x, y, str(count), ha="center", va="center", fontsize=10, fontweight="bold",
            color="0.15", zorder=5,
            bbox={"boxstyle": "circle,pad=0.2", "fc": "white", "ec": "0.5", "lw": 0.6,
                  "alpha": 0.85})


def _pixels_to_edge(ax, ring, point):
    """Distance in pixels from ``point`` to the closed polyline ``ring`` (both in data units)."""
    xy = ax.transData.transform(np.vstack([ring, ring[:1]]))
    p = ax.transData.transform([point])[0]
    a, ab = xy[:-1], np.diff(xy, axis=0)
    t = np.clip(np.sum((p - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300),
                0.0, 1.0)
    return float(np.min(np.hypot(*(a + t[:, None] * ab - p).T)))


def _write_counts(ax, decomposition, scale=(1.0, 1.0), room=9.0):
    """Write its number of unstable closed-loop poles in every cell with room for it.

    The number goes at the cell's interior point, where the decomposition
    counted it (Schur-Cohn, checked against the crossing rule); cells whose
    point lies within ``room`` pixels of the cell's edge are left
    unlabelled, so no number sits on a curve.  Call it after the axes'
    limits are set.  Returns the ``(beta, alpha, count)`` written.
    """
    sx, sy = scale
    written = []
    for cell in decomposition.cells:
        if cell.count < 0:
            continue  # marginal or unresolved: no number to write
        x, y = cell.point
        rings = [cell.outer * (sx, sy)] + [h * (sx, sy) for h in cell.holes]
        if min(_pixels_to_edge(ax, r, (x * sx, y * sy)) for r in rings) < room:
            continue
        _count_text(ax, x * sx, y * sy, cell.count)
        written.append((float(x), float(y), int(cell.count)))
    return written


def _draw_arc(ax, arc, color, scale=(1.0, 1.0), beyond=True):
    """Draw the arc of eq. (7) (solid) and, with ``beyond``, the rest of it up to pi (dashed).

    ``arc`` is ``(first, rest)`` of :func:`symstab.numeric.paper.region.arc_polylines`.
    """
    first, rest = arc
    sx, sy = scale
    if len(first):
        ax.plot(first[:, 0] * sx, first[:, 1] * sy, color=color, zorder=3, **_ARC)
    if beyond and len(rest):
        ax.plot(rest[:, 0] * sx, rest[:, 1] * sy, color=color, zorder=3, **_BEYOND)


def _hatch_stable(ax, beta, alpha, stable, color, scale=(1.0, 1.0)):
    """Hatch the cells a simulated map found stable (``stable`` is ``(alpha, beta)``)."""
    import matplotlib

    if stable.any():
        with matplotlib.rc_context({"hatch.color": color, "hatch.linewidth": 0.7}):
            ax.contourf(beta * scale[0], alpha * scale[1], stable.astype(float),
                        levels=[0.5, 1.5], colors="none", hatches=[_SIM_HATCH], zorder=2)


def _style_handles(color="k", beyond=True, z_one=True):
    """Legend handles for the boundary's parts."""
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=color, **_ARC,
                      label=r"eq. (7), $0 < \theta \leq \theta_{\max}$")]
    if beyond:
        handles.append(Line2D([], [], color=color, **_BEYOND,
                              label=r"the same curve, $\theta_{\max} < \theta < \pi$"))
    if z_one:
        handles.append(Line2D([], [], **_Z_ONE, label=r"$\alpha = 0$: a root at $z = 1$"))
    return handles


def _legend_below(fig, handles, ncol):
    """One legend for the whole figure, under the panels, where it covers nothing.

    Lays the panels out in the space above it (call it last, after the
    suptitle).
    """
    legend = fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=LEGEND_SIZE + 1,
                        frameon=False, bbox_to_anchor=(0.5, 0.0))
    height = legend.get_window_extent(fig.canvas.get_renderer()).height / fig.bbox.height
    fig.tight_layout(rect=(0, height + 0.01, 1, 1))
    return legend


def _regions_panel(ax, panel):
    """One panel of stable sets: the z = 1 line, each layer's fill, hatch and arc, the frame.

    ``panel``: ``window``, ``layers`` (each ``(color, decomposition, simulated
    or None, arc)``, ``simulated`` as ``(beta, alpha, stable)``), ``beyond``,
    and optionally ``box`` (a window outlined on it) and ``title``.
    """
    from matplotlib.patches import Rectangle

    (b0, b1), (a0, a1) = panel["window"]
    ax.axhline(0.0, zorder=2, **_Z_ONE)
    for color, decomposition, simulated, arc in panel["layers"]:
        _shade_cells(ax, decomposition, color)
        if simulated is not None:
            _hatch_stable(ax, *simulated, color)
        _draw_arc(ax, arc, color, beyond=panel["beyond"])
    if panel.get("box") is not None:
        (zb0, zb1), (za0, za1) = panel["box"]
        ax.add_patch(Rectangle((zb0, za0), zb1 - zb0, za1 - za0, fill=False, ec="k", lw=1.0,
                               zorder=6))
    ax.set_xlim(b0, b1)
    ax.set_ylim(a0, a1)
    _plane_labels(ax)
    if panel.get("title") is not None:
        ax.set_title(panel["title"], fontsize=PANEL_TITLE_SIZE)


def regions_figure(top, gammas, marks, n, suptitle, lower=None):
    """Figs. 6 and 8: the stable sets of ``gammas`` at each delay, simulation hatched over them.

    Parameters
    ----------
    top : list of dict
        The upper panels, one a delay (see ``_regions_panel``).
    gammas : sequence of float
        The gammas drawn, in :data:`FIGURE_COLORS`' order.
    marks : dict
        ``{gamma: the verdict in the legend}``.
    n : int
        The simulated grid's size, for the legend.
    suptitle : str
        The figure's title (mathtext) before its common part.
    lower : list of dict, optional
        Fig. 8's lower row: its first panel is magnified from the first upper
        panel (outlined there, with a note), the others are drawn whole.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    plt = pyplot()
    if lower is None:
        fig, axes = plt.subplots(2, 2, figsize=(11, 9.4))
        first_row = axes.ravel()
    else:
        fig, axes = plt.subplots(2, 4, figsize=(16, 9.4))
        first_row = axes[0]
    for ax, panel in zip(first_row, top, strict=True):
        _regions_panel(ax, panel)
    if lower is not None:
        zoom = lower[0]
        _regions_panel(axes[1][0], zoom)
        (b0, b1), (a0, a1) = zoom["window"]
        axes_top = axes[1][0].figure.axes[0]
        axes_top.add_patch(Rectangle((b0, a0), b1 - b0, a1 - a0, fill=False, ec="k", lw=1.0,
                                     zorder=6))
        axes_top.annotate("magnified below", (b1, a0), xytext=(12, -18),
                          textcoords="offset points", fontsize=8,
                          arrowprops={"arrowstyle": "-", "lw": 0.6})
        for ax, panel in zip(axes[1][1:], lower[1:], strict=True):
            _regions_panel(ax, panel)
    handles = [Line2D([], [], color=c, lw=2.5, label=fr"$\gamma = {g:g}$ ({marks[g]})")
               for g, c in zip(gammas, FIGURE_COLORS, strict=False)]
    handles += _style_handles() + [
        Patch(facecolor="0.6", alpha=_FILL_ALPHA + 0.1, label="stable (root counting, exact)"),
        Patch(facecolor="none", edgecolor="0.3", hatch=_SIM_HATCH,
              label=fr"stable by simulation, ${n} \times {n}$ grid (a check)")]
    fig.suptitle(suptitle + ": the boundary, the exact stable sets (filled; S: stable region, "
                 "U: none) and a simulated check (hatched)", fontsize=SUPTITLE_SIZE)
    _legend_below(fig, handles, ncol=5 if lower else 3)
    return fig


def boundaries_d0_figure(layers, points, loops, window):
    """Fig. 7: the boundaries of gamma 0 .. 3 at d = 0, the numbered points, the thin loops.

    Parameters
    ----------
    layers : list of tuple
        ``(gamma, color, verdict, decomposition, arc)`` a gamma.
    points : list of (int, float, float)
        The numbered points: ``(number, beta, alpha)``.
    loops : dict
        ``{gamma: ((inside, outside, alpha_tip, beta_tip), color)}``: the
        root counts inside and outside a gamma's thin loop, and its tip.
    window : tuple
        ``((beta0, beta1), (alpha0, alpha1))``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(11, 6.4))
    ax.axhline(0.0, zorder=2, **_Z_ONE)
    for g, color, tag, decomposition, arc in layers:
        _shade_cells(ax, decomposition, color)
        _draw_arc(ax, arc, color)
        ax.plot([], [], color=color, lw=2.5, label=fr"$\gamma = {g:g}$ ({tag})")
    # Each number sits beside its circle, on a white box, where no curve runs.
    offsets = {1: (0, -17), 2: (18, 8), 3: (0, 17), 4: (0, 17), 5: (20, 4), 6: (30, 0)}
    for k, b, a in points:
        ax.plot(b, a, "o", ms=11, mfc="none", mec="k", mew=1.2, zorder=6)
        ax.annotate(str(k), (b, a), xytext=offsets[k], textcoords="offset points", ha="center",
                    va="center", fontsize=9, fontweight="bold", zorder=7,
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none"})
    ax.axvline(-0.5, color="k", ls=":", lw=0.8, zorder=2)
    ax.annotate(r"$\beta = -0.5$", (-0.5, 3.7), xytext=(4, 0), textcoords="offset points",
                fontsize=8, va="center")
    for row, (g, ((inside, outside, a_tip, b_tip), color)) in enumerate(sorted(loops.items())):
        ax.annotate(fr"$\gamma = {g:g}$: both lines are one thin loop of eq. (7)," "\n"
                    fr"its tip at $\alpha = {a_tip:.2f}$; {inside} poles outside the unit" "\n"
                    f"circle inside the loop, {outside} outside it: no stable cell",
                    (b_tip, a_tip), xytext=(-0.3, 4.75 + 1.1 * row), textcoords="data",
                    fontsize=8, color=color, va="center", zorder=7,
                    bbox={"boxstyle": "round,pad=0.25", "fc": "white", "ec": color, "lw": 0.6},
                    arrowprops={"arrowstyle": "->", "color": color, "lw": 0.8})
    (b0, b1), (a0, a1) = window
    ax.set_xlim(b0, b1)
    ax.set_ylim(a0, a1)
    _plane_labels(ax)
    ax.set_title(r"Fig. 7: boundaries for $d = 0$; S: a stable region (filled), U: none "
                 "(root counting)", fontsize=PANEL_TITLE_SIZE + 1)
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + _style_handles(), fontsize=LEGEND_SIZE + 1, loc="upper left",
              bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    return fig


def physical_figure(panels):
    """Fig. 10: four panels in physical units, the exact set, two simulations, passivity, counts.

    Parameters
    ----------
    panels : list of dict
        Each: ``window`` (in beta, alpha), ``scale`` (to B_w, K_w),
        ``decomposition``, ``arc``, ``grid`` (the maps' ``(B_w, K_w)``),
        ``ideal`` and ``quantized`` (the simulated maps' stable cells),
        ``passive`` (the passive set's closed outline in B_w, K_w, or None)
        and ``title``.

    Returns
    -------
    (matplotlib.figure.Figure, list)
        The figure and, a panel each, the ``(beta, alpha, count)`` of the
        root counts written in its cells.
    """
    import matplotlib
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(11, 9.6))
    counted = []
    for ax, panel in zip(axes.ravel(), panels, strict=True):
        scale = panel["scale"]
        (b0, b1), (a0, a1) = panel["window"]
        ax.axhline(0.0, zorder=2, **_Z_ONE)
        _shade_cells(ax, panel["decomposition"], "#4292c6", scale)
        K, B = panel["grid"]
        with matplotlib.rc_context({"hatch.color": "#08519c", "hatch.linewidth": 0.6}):
            ax.contourf(B, K, panel["ideal"].astype(float), levels=[0.5, 1.5], colors="none",
                        hatches=[_SIM_HATCH], zorder=2)
        ax.contour(B, K, panel["quantized"].astype(float), levels=[0.5], colors=["#2ca02c"],
                   linestyles="--", linewidths=1.6, zorder=4)
        _draw_arc(ax, panel["arc"], "k", scale)
        if panel["passive"] is not None:
            outline = panel["passive"]
            ax.plot(outline[:, 0], outline[:, 1], color=_PASSIVE, ls="--", lw=1.5, zorder=5)
        ax.set_xlim(b0 * scale[0], b1 * scale[0])
        ax.set_ylim(a0 * scale[1], a1 * scale[1])
        counted.append(_write_counts(ax, panel["decomposition"], scale))
        ax.set_title(panel["title"], fontsize=PANEL_TITLE_SIZE)
        _plane_labels(ax, physical=True)
    handles = _style_handles("k") + [
        Patch(facecolor="#4292c6", alpha=_FILL_ALPHA + 0.1, label="stable (root counting, exact)"),
        Patch(facecolor="none", edgecolor="#08519c", hatch=_SIM_HATCH,
              label="stable in simulation, ideal: PI(−), QF(−) (a check)"),
        Line2D([], [], color="#2ca02c", ls="--", lw=1.6,
               label="edge of the stable set in simulation, quantized + 50 Hz filter: PI(−), "
                     "QF(+)"),
        Line2D([], [], color=_PASSIVE, ls="--", lw=1.5, label="passive (Colgate–Schenkel)"),
        Line2D([], [], ls="none", marker="$2$", color="0.15", ms=8, label=_COUNTS_NOTE)]
    fig.suptitle(r"Fig. 10: physical units, $T_d = 40$ ms (the PI current-controller cases and "
                 "the experiments are not modelled)", fontsize=SUPTITLE_SIZE)
    _legend_below(fig, handles, ncol=2)
    return fig, counted


def _limits_column(ax, lin, column):
    """One delay's column of Figs. 11 and 12: the three limits (log), the Z-width (linear)."""
    ax.set_yscale("log")
    g_ab, b_ab, a_ab = column["log"]
    g_all, zw = column["grid"]
    with np.errstate(invalid="ignore"):
        ax.plot(g_ab, np.where(b_ab > 0, b_ab, np.nan), "-", color=FIGURE_COLORS[0], lw=1.8)
        ax.plot(g_ab, np.where(a_ab > 0, a_ab, np.nan), "--", color=FIGURE_COLORS[1], lw=1.8)
        ax.plot(g_all, np.where(zw > 0, zw, np.nan), ":", color=FIGURE_COLORS[3], lw=2.2)
    g_lin, z_lin = column["linear"]
    lin.plot(g_lin, z_lin, ":", color=FIGURE_COLORS[3], lw=2.2)
    lin.set_ylim(0.0, 1.1 * float(np.max(z_lin)))
    vanish, right, (g0, g1) = column["vanish"], column["right"], column["range"]
    for a in (ax, lin):
        if vanish is not None:
            lo, hi = (vanish, g1) if right else (g0, vanish)
            a.axvspan(lo, hi, color="red", alpha=0.15, lw=0)
            a.axvline(vanish, color="red", lw=0.9)
        a.set_xlim(g0, g1)
    if vanish is not None:
        lin.annotate(fr"$\gamma^* = {vanish:.4f}$", (vanish, 0.0),
                     xytext=(-6 if right else 6, 30), textcoords="offset points",
                     ha="right" if right else "left", fontsize=9, color="darkred",
                     arrowprops={"arrowstyle": "->", "color": "darkred", "lw": 0.8},
                     bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none"})
    lin.set_xlabel(r"$\gamma = M_w/m$")
    ax.set_ylabel("dimensionless, log scale")
    lin.set_ylabel("Z-width, linear scale")
    label_log_axis(ax)
    ax.set_title(f"$d = {column['d']}$", fontsize=PANEL_TITLE_SIZE)


def limits_figure(columns, suptitle):
    """Figs. 11 and 12: beta_max, alpha_max and the Z-width versus gamma, a column a delay.

    Parameters
    ----------
    columns : list of dict
        Each: ``d``; ``log``, the ``(gamma, beta_max, alpha_max)`` drawn on
        the log axis; ``grid``, ``(gamma, Z-width)`` of the scan; ``linear``,
        the ``(gamma, Z-width)`` closing on the vanishing gamma; ``vanish``,
        that gamma or None; ``right``, True where the region ends on the
        right; ``range``, the gammas' first and last.
    suptitle : str
        The figure's title (mathtext) before its common part.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    plt = pyplot()
    fig, axes = plt.subplots(2, 4, figsize=(16, 8.6), sharex=True)
    for k, column in enumerate(columns):
        _limits_column(axes[0, k], axes[1, k], column)
    handles = [Line2D([], [], color=FIGURE_COLORS[0], lw=1.8, label=r"$\beta_{\max}$"),
               Line2D([], [], color=FIGURE_COLORS[1], ls="--", lw=1.8, label=r"$\alpha_{\max}$"),
               Line2D([], [], color=FIGURE_COLORS[3], ls=":", lw=2.2,
                      label="Z-width (area of the stable set)"),
               Patch(facecolor="red", alpha=0.15,
                     label=r"no stable region (from $\gamma^*$, found by bisection on root "
                           r"counting)")]
    fig.suptitle(suptitle + ": upper row on a log scale, lower row the Z-width on a linear scale",
                 fontsize=SUPTITLE_SIZE)
    _legend_below(fig, handles, ncol=4)
    return fig


# --------------------------------------------------------------------------
# Results that draw themselves: ``result.plot(ax=None)`` on a user's axes
# --------------------------------------------------------------------------

class Plot:
    """What a result's ``plot()`` drew: its figure, its axes and its artists by role.

    As python-control's ``ControlPlot``: keep it to restyle what was drawn
    (``p.artists["stable"]``), to add to the axes, or to save the figure.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : matplotlib.axes.Axes
    artists : dict
        ``{role: [artist, ...]}``: ``"stable"`` (the filled stable set),
        ``"arc"`` and ``"lines"`` (the D-decomposition's curves),
        ``"counts"`` (the root counts written in the cells), ``"marker"``
        (a marked point), as the result drew them.
    """

    def __init__(self, figure, axes, artists):
        self.figure = figure
        self.axes = axes
        self.artists = artists

    def __repr__(self):
        drawn = ", ".join(f"{role}: {len(a)}" for role, a in self.artists.items())
        return f"Plot({drawn})"

    def savefig(self, *args, **kwargs):
        """The figure's :meth:`matplotlib.figure.Figure.savefig`."""
        return self.figure.savefig(*args, **kwargs)


def _axes(ax):
    """``(figure, axes)``: ``ax`` and its figure, or a new figure's axes (pyplot's backend)."""
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("plot() needs matplotlib: pip install 'symstab[figures]' "
                          "(or pip install matplotlib)") from None
    if ax is None:
        figure, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
        return figure, ax
    return ax.figure, ax


#: The fill of a stable set drawn by a result's ``plot()``.
STABLE_COLOR = "#4292c6"

#: How a result's ``plot()`` draws the D-decomposition's pieces.
_PIECE_STYLE = {"arc": {"color": "k", "lw": 1.2},
                "z = 1": {"color": "C0", "ls": "--", "lw": 1.2},
                "z = -1": {"color": "C3", "ls": "--", "lw": 1.2},
                "leading": {"color": "C1", "ls": ":", "lw": 1.2}}
_PIECE_LABEL = {"arc": r"a root at $z = e^{j\theta}$", "z = 1": "a root at $z = 1$",
                "z = -1": "a root at $z = -1$", "leading": "a root at infinity"}


def _pieces(ax, branches):
    """The decomposition's pieces on ``ax``, one legend entry per kind: ``(arc, lines)``."""
    arc, lines = [], []
    for branch in branches:
        style = _PIECE_STYLE.get(branch.label, _PIECE_STYLE["leading"])
        seen = arc if branch.label == "arc" else lines
        label = _PIECE_LABEL.get(branch.label, branch.label)
        if any(getattr(a, "get_label", lambda: "")() == label for a in arc + lines):
            label = "_nolegend_"
        seen += ax.plot(branch.points[:, 0], branch.points[:, 1], label=label, zorder=3,
                        **style)
    return arc, lines


def plot_region(decomposition, ax=None, *, counts=True, color=STABLE_COLOR):
    """Draw a D-decomposition: the stable set filled, the curves, each cell's root count.

    What :meth:`symstab.numeric.engine.decomposition.Decomposition.plot`
    (and so ``loop.region(...).plot()``) draws.

    Parameters
    ----------
    decomposition : symstab.numeric.engine.decomposition.Decomposition
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    counts : bool, optional
        Write the number of unstable closed-loop poles in every cell with
        room for it (default True).
    color : str, optional
        The stable set's fill.

    Returns
    -------
    Plot
        Artists ``"stable"``, ``"arc"``, ``"lines"``, ``"counts"``.

    Raises
    ------
    ImportError
        Without matplotlib (the ``figures`` extra).
    """
    figure, ax = _axes(ax)
    from matplotlib.patches import Patch

    stable = _shade_cells(ax, decomposition, color)
    arc, lines = _pieces(ax, decomposition.branches)
    ax.set_xlim(*decomposition.x_range)
    ax.set_ylim(*decomposition.y_range)
    ax.set_xlabel(decomposition.x)
    ax.set_ylabel(decomposition.y)
    written = []
    if counts:
        before = len(ax.texts)
        _write_counts(ax, decomposition)
        written = list(ax.texts[before:])
    handles = [Patch(facecolor=color, alpha=_FILL_ALPHA + 0.1, label="stable (root counting)")]
    handles += [a for a in arc + lines if not a.get_label().startswith("_")]
    ax.legend(handles=handles, loc="best", fontsize=LEGEND_SIZE)
    return Plot(figure, ax, {"stable": stable, "arc": arc, "lines": lines, "counts": written})


def plot_limits(limits, ax=None, **kwargs):
    """Draw the stable set that ``limits`` were read from, its largest ``y`` marked.

    What :meth:`symstab.numeric.engine.results.Limits.plot` draws.

    Parameters
    ----------
    limits : symstab.numeric.engine.results.Limits
        Limits of a decomposition (:meth:`symstab.Loop.limits`,
        :func:`symstab.limits`).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    **kwargs
        Handed to :func:`plot_region`.

    Returns
    -------
    Plot
        :func:`plot_region`'s artists, and ``"marker"``: the point
        ``(x_at_y_max, y_max)``.

    Raises
    ------
    ValueError
        For limits that hold no decomposition to draw.
    ImportError
        Without matplotlib.
    """
    if limits.decomposition is None:
        raise ValueError("these limits hold no D-decomposition to draw (they were not read "
                         "from one)")
    drawn = plot_region(limits.decomposition, ax, **kwargs)
    marker = []
    if not limits.empty and np.isfinite(limits.y_max) and np.isfinite(limits.x_at_y_max):
        marker = drawn.axes.plot([limits.x_at_y_max], [limits.y_max], "o", color="#d62728",
                                 zorder=6, label=f"{limits.y}_max = {limits.y_max:.6g}")
        handles = drawn.axes.get_legend().legend_handles + marker
        drawn.axes.legend(handles=handles, loc="best", fontsize=LEGEND_SIZE)
    drawn.artists["marker"] = marker
    return drawn


def plot_boundary(boundary, ax=None, *, x_range=None, y_range=None):
    """Draw a boundary: the arc where a root is on the unit circle, and the lines in view.

    What :meth:`symstab.numeric.engine.results.Boundary.plot` draws.  A
    loop's arc covers all of (0, pi) and may run off to very large values:
    the default window holds its central points (from the 10th to the 90th
    percentile in each coordinate, widened by half that span on each side).

    Parameters
    ----------
    boundary : symstab.numeric.engine.results.Boundary
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    x_range, y_range : (float, float), optional
        The window (default: as above).

    Returns
    -------
    Plot
        Artists ``"arc"`` and ``"lines"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    figure, ax = _axes(ax)
    x, y = np.asarray(boundary.x_values, float), np.asarray(boundary.y_values, float)
    arc = ax.plot(x, y, zorder=3, label=_PIECE_LABEL["arc"], **_PIECE_STYLE["arc"]) \
        if len(x) else []
    finite = np.isfinite(x) & np.isfinite(y)
    for values, given, limit in ((x[finite], x_range, ax.set_xlim),
                                 (y[finite], y_range, ax.set_ylim)):
        if given is None and len(values):
            lo, hi = np.percentile(values, [10, 90])
            span = (hi - lo) or max(abs(hi), 1.0)
            given = (lo - span / 2, hi + span / 2)
        if given is not None:
            limit(*given)
    ax.set_xlabel(boundary.x)
    ax.set_ylabel(boundary.y)
    xs, ys = ax.get_xlim(), ax.get_ylim()
    lines = draw_lines(ax, boundary.lines, np.linspace(*xs, 2), np.linspace(*ys, 2))
    ax.set_xlim(*xs)
    ax.set_ylim(*ys)
    ax.legend(loc="best", fontsize=LEGEND_SIZE)
    return Plot(figure, ax, {"arc": arc, "lines": lines})


def plot_robust(region, ax=None):
    """Draw a robust set: certified (filled), marginal, and the nominal set's outline.

    What :meth:`symstab.numeric.engine.results.RobustRegion.plot` draws (the
    PNG of ``symstab limits --uncertain``).

    Parameters
    ----------
    region : symstab.numeric.engine.results.RobustRegion
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).

    Returns
    -------
    Plot
        Artists ``"robust"``, ``"marginal"``, ``"nominal"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    figure, ax = _axes(ax)
    return Plot(figure, ax, _draw_robust(ax, region, region.x, region.y))


def plot_delay_range_region(found, ax=None):
    """Draw a delay range's two sets in a plane: the certified constant set, the varying grid over it.

    What :meth:`symstab.numeric.analysis.delay_range.DelayRangeRegion.plot`
    draws: the robust region of every constant delay of the range
    (:func:`plot_robust`'s drawing) and, hatched over it, the grid's points
    the small-gain criterion shows stable for every varying sequence.

    Parameters
    ----------
    found : symstab.numeric.analysis.delay_range.DelayRangeRegion
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).

    Returns
    -------
    Plot
        Artists ``"robust"``, ``"marginal"``, ``"nominal"`` and ``"varying"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    from matplotlib.patches import Patch

    figure, ax = _axes(ax)
    artists = _draw_robust(ax, found.constant, found.constant.x, found.constant.y)
    grid = found.grid
    artists["varying"] = []
    handles, _ = ax.get_legend_handles_labels()
    if grid.varying is not None and np.any(grid.varying):
        artists["varying"] = [ax.contourf(grid.x_values, grid.y_values,
                                          np.asarray(grid.varying, float), levels=[0.5, 1.5],
                                          colors="none", hatches=["////"])]
        handles.append(Patch(facecolor="none", hatch="////",
                             label="every varying delay (small gain, on a grid)"))
    handles += [Patch(color="#4393c3", label="every constant delay (certified)"),
                Patch(color="#f4a582", label="marginal (not certified)")]
    ax.legend(handles=handles, loc="best", fontsize=LEGEND_SIZE, framealpha=0.9)
    low, high = grid.samples
    ax.set_title(f"stable for delays of {low:.6g} to {high:.6g} samples", fontsize=9)
    return Plot(figure, ax, artists)


def plot_probability(found, ax=None, *, boundary=None):
    """Draw the probability of stability over its grid, a boundary over it if given.

    What :meth:`symstab.numeric.engine.results.StabilityProbability.plot`
    draws (the PNG of ``symstab map --uncertain``).

    Parameters
    ----------
    found : symstab.numeric.engine.results.StabilityProbability
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    boundary : symstab.numeric.engine.results.Boundary, optional
        The nominal loop's D-decomposition (:meth:`symstab.Loop.boundary`),
        drawn over the map.

    Returns
    -------
    Plot
        Artists ``"probability"`` (the mesh), ``"colorbar"``, ``"boundary"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    figure, ax = _axes(ax)
    return Plot(figure, ax, _draw_probability(ax, found, boundary, found.x, found.y))


def plot_design(found, ax=None, *, target_label=None):
    """Draw a design: its target at every value evaluated, the optimum and the nominal marked.

    What :meth:`symstab.numeric.analysis.design.Design.plot` draws (the PNG
    of ``symstab design --png``).

    Parameters
    ----------
    found : symstab.numeric.analysis.design.Design
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    target_label : str, optional
        The target's axis label (default: its name,
        :attr:`~symstab.numeric.analysis.design.Design.target`).

    Returns
    -------
    Plot
        Artists ``"target"``, ``"best"``, ``"nominal"``, ``"none"`` (the
        values with no stable point).

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    figure, ax = _axes(ax)
    label = found.target if target_label is None else target_label
    return Plot(figure, ax, _draw_design(ax, found, list(found.over), label))


def plot_pareto(found, ax=None, *, target_label=None, noise_label="force noise (RMS)"):
    """Draw a design's target against the force noise: every value evaluated and the Pareto front.

    What :meth:`symstab.numeric.analysis.design.Design.plot_pareto` draws
    (the right panel of ``symstab design --png`` with an encoder): the
    budget as a vertical line, the optimum marked.

    Parameters
    ----------
    found : symstab.numeric.analysis.design.Design
        A design that recorded the force noise (``encoder_resolution``).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    target_label, noise_label : str, optional
        The axes' labels (default: the target's name; "force noise (RMS)").

    Returns
    -------
    Plot
        Artists ``"samples"``, ``"front"``, ``"best"``, ``"limit"``.

    Raises
    ------
    ValueError
        For a design without the force noise.
    ImportError
        Without matplotlib.
    """
    if found.noise is None:
        raise ValueError("the design recorded no force noise: give encoder_resolution to "
                         "Loop.design")
    figure, ax = _axes(ax)
    label = found.target if target_label is None else target_label
    return Plot(figure, ax, _draw_pareto(ax, found, label, noise_label))


def plot_passive(passive, ax=None, *, region=None):
    """Draw a passive set (its polygon), the stable set beside it if given.

    What :meth:`symstab.numeric.analysis.passivity.PassiveRegion.plot` draws.

    Parameters
    ----------
    passive : symstab.numeric.analysis.passivity.PassiveRegion
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    region : symstab.numeric.engine.decomposition.Decomposition, optional
        The stable set of the same plane (:meth:`symstab.Loop.region`),
        drawn under it: passive points are stable, not the other way round.

    Returns
    -------
    Plot
        Artists ``"passive"`` and, with ``region``, :func:`plot_region`'s.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    from matplotlib.patches import Patch, Polygon

    figure, ax = _axes(ax)
    artists = plot_region(region, ax, counts=False).artists if region is not None else {}
    handles = list(ax.get_legend().legend_handles) if ax.get_legend() else []
    artists["passive"] = []
    if len(passive.polygon):
        artists["passive"].append(ax.add_patch(Polygon(
            passive.polygon, closed=True, facecolor=PASSIVE_COLOR, edgecolor=PASSIVE_COLOR,
            alpha=0.45, lw=1.2, zorder=2)))
    handles.append(Patch(facecolor=PASSIVE_COLOR, alpha=0.45, label="passive"))
    if region is None:
        ax.set_xlim(*passive.x_range)
        ax.set_ylim(*passive.y_range)
        ax.set_xlabel(passive.x)
        ax.set_ylabel(passive.y)
    ax.legend(handles=handles, loc="best", fontsize=LEGEND_SIZE)
    return Plot(figure, ax, artists)


def plot_locus(locus, ax=None):
    """Draw a root locus in the z-plane: the poles coloured by the path's value, the crossings.

    What :meth:`symstab.numeric.engine.locus.Locus.plot` draws (the upper
    left panel of ``symstab locus``'s PNG).

    Parameters
    ----------
    locus : symstab.numeric.engine.locus.Locus
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).

    Returns
    -------
    Plot
        Artists ``"poles"`` (the scatter), ``"circle"``, ``"crossings"``
        (a marker per crossing, and its mirror for a pair) and
        ``"colorbar"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    from matplotlib.colors import Normalize

    figure, ax = _axes(ax)
    values = np.asarray(locus.values, dtype=float)
    finite = np.isfinite(locus.poles)
    radius = float(np.max(np.abs(locus.poles[finite]))) if finite.any() else 1.0
    limit = min(max(1.15, 1.05 * radius), _PLANE_LIMIT)
    norm = Normalize(vmin=float(values.min()), vmax=float(values.max()))
    before = len(ax.lines)
    dots = _plane(ax, locus, values, locus.parameter, norm, limit)
    lines = ax.lines[before:]
    bar = figure.colorbar(dots, ax=ax, label=locus.parameter)
    ax.legend(loc="best", fontsize=LEGEND_SIZE)
    return Plot(figure, ax, {"poles": [dots], "circle": lines[:1], "crossings": lines[2:],
                             "colorbar": [bar]})


def plot_simulation(run, ax=None, *, T=None):
    """Draw a recorded run: the position at each sample, one line per point simulated.

    What :meth:`symstab.numeric.simulation.simulator.Simulation.plot` draws.

    Parameters
    ----------
    run : symstab.numeric.simulation.simulator.Simulation
        A run with its positions (``record=True``).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    T : float, optional
        The sample period in s: the time axis in seconds (default: in
        samples).

    Returns
    -------
    Plot
        Artists ``"positions"``, one line per point.

    Raises
    ------
    ValueError
        For a run without its positions.
    ImportError
        Without matplotlib.
    """
    if run.positions is None:
        raise ValueError("this run did not record its positions: simulate with record=True")
    figure, ax = _axes(ax)
    positions = np.asarray(run.positions, dtype=float)
    positions = positions.reshape(len(positions), -1)
    k = np.arange(len(positions)) * (1.0 if T is None else float(T))
    lines = ax.plot(k, positions, lw=1.0)
    ax.set_xlabel("sample k" if T is None else "time [s]")
    ax.set_ylabel("position x")
    stable = np.asarray(run.stable).ravel()
    if len(lines) == 1:
        ax.set_title("stable" if stable[0] else ("bounded limit cycle"
                                                 if np.asarray(run.limit_cycle).ravel()[0]
                                                 else "not stable"), fontsize=PANEL_TITLE_SIZE)
    return Plot(figure, ax, {"positions": lines})


def plot_map(found, ax=None, *, boundary=None):
    """Draw a simulated stability map: stable cells, bounded limit cycles, a boundary over it.

    What :meth:`symstab.numeric.simulation.simulator.StabilityMap.plot`
    draws (the PNG of ``symstab map``, in the map's own plane).

    Parameters
    ----------
    found : symstab.numeric.simulation.simulator.StabilityMap
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    boundary : symstab.numeric.engine.results.Boundary, optional
        The loop's D-decomposition in the same plane, drawn over the map.

    Returns
    -------
    Plot
        Artists ``"cells"`` (the mesh) and ``"boundary"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    figure, ax = _axes(ax)
    xs, ys = np.asarray(found.x_values, float), np.asarray(found.y_values, float)
    shade = np.where(found.stable, 1, np.where(found.limit_cycle, 2, 0))
    mesh = ax.pcolormesh(xs, ys, shade, shading="nearest", vmin=0, vmax=2,
                         cmap=ListedColormap(["white", "#7fc97f", LIMIT_CYCLE_COLOR]))
    handles = [Patch(facecolor="#7fc97f", label="stable (simulated)")]
    if np.any(found.limit_cycle):
        handles.append(Patch(facecolor=LIMIT_CYCLE_COLOR, label=LIMIT_CYCLE_LABEL))
    drawn = [] if boundary is None else _loop_boundary(ax, boundary, xs, ys)
    _map_frame(ax, xs, ys, found.x, found.y)
    ax.legend(handles=handles + drawn, loc="best", fontsize=LEGEND_SIZE, framealpha=0.9)
    return Plot(figure, ax, {"cells": [mesh], "boundary": drawn})


def plot_margin_map(found, ax=None, *, region=None, levels=None):
    """Draw a margin map as filled contours, a decomposition over it if given.

    What :meth:`symstab.numeric.analysis.margins.MarginMap.plot` draws.
    Points that are not stable hold NaN and are left blank.

    Parameters
    ----------
    found : symstab.numeric.analysis.margins.MarginMap
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).
    region : symstab.numeric.engine.decomposition.Decomposition, optional
        The loop's decomposition in the same plane: its curves drawn over the map.
    levels : int or sequence of float, optional
        The contour levels (default 10).

    Returns
    -------
    Plot
        Artists ``"margin"`` (the filled contours), ``"colorbar"``, ``"arc"``
        and ``"lines"``.

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    figure, ax = _axes(ax)
    xs, ys = np.asarray(found.x_values, float), np.asarray(found.y_values, float)
    artists = {"margin": [], "colorbar": [], "arc": [], "lines": []}
    values = np.asarray(found.values, float)
    if found.margin in ("delay", "gain"):
        # Stable beyond the delays examined, or no gain limit (inf): drawn as the top level.
        top = np.nanmax(np.where(np.isinf(values), np.nan, values), initial=0.0) + 1
        values = np.where(np.isinf(values), top, values)
    if np.isfinite(values).any():
        style = {}
        if found.margin == "gain" and levels is None and np.nanmin(values) > 0:
            # A gain margin is a factor: levels evenly spaced on a log scale.
            from matplotlib.colors import LogNorm

            levels = np.geomspace(np.nanmin(values), np.nanmax(values), 11)
            style["norm"] = LogNorm(levels[0], levels[-1])
        filled = ax.contourf(xs, ys, values, levels=10 if levels is None else levels,
                             cmap="viridis", **style)
        bar = figure.colorbar(filled, ax=ax)
        if "norm" in style:
            from matplotlib.ticker import FuncFormatter, NullLocator

            bar.set_ticks(levels)
            bar.ax.yaxis.set_minor_locator(NullLocator())
            bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))
        bar.set_label({"modulus": r"modulus margin $\min_\theta |1 + L(e^{j\theta})|$",
                       "delay": "delay margin (samples added, exact)",
                       "gain": "gain margin (factor)"}[found.margin])
        artists["margin"], artists["colorbar"] = [filled], [bar]
    if region is not None:
        artists["arc"], artists["lines"] = _pieces(ax, region.branches)
        ax.legend(loc="best", fontsize=LEGEND_SIZE, framealpha=0.9)
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])
    ax.set_xlabel(found.x)
    ax.set_ylabel(found.y)
    ax.set_title(f"{found.margin} margin (blank: not stable)")
    return Plot(figure, ax, artists)


def plot_delay_range_map(found, ax=None):
    """Draw the two sets of a delay range over a grid: every constant delay, every varying one.

    What :meth:`symstab.numeric.analysis.delay_range.DelayRangeMap.plot`
    draws: the points stable for every constant delay of the range shaded
    light, those the small-gain criterion shows stable for every varying
    sequence shaded dark over them (none where it is not derived).

    Parameters
    ----------
    found : symstab.numeric.analysis.delay_range.DelayRangeMap
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure's axes).

    Returns
    -------
    Plot
        Artists ``"constant"`` and ``"varying"`` (filled contours).

    Raises
    ------
    ImportError
        Without matplotlib.
    """
    from matplotlib.patches import Patch

    figure, ax = _axes(ax)
    xs, ys = np.asarray(found.x_values, float), np.asarray(found.y_values, float)
    artists = {"constant": [], "varying": []}
    low, high = found.samples
    handles = []
    for key, mask, color, label in (
            ("constant", found.constant, "#9ecae1", "every constant delay"),
            ("varying", found.varying, "#08519c", "every varying delay (small gain)")):
        if mask is None or not np.any(mask):
            continue
        artists[key] = [ax.contourf(xs, ys, np.asarray(mask, float), levels=[0.5, 1.5],
                                    colors=[color])]
        handles.append(Patch(color=color, label=label))
    if handles:
        ax.legend(handles=handles, loc="best", fontsize=LEGEND_SIZE, framealpha=0.9)
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])
    ax.set_xlabel(found.x)
    ax.set_ylabel(found.y)
    varying = "" if found.varying is not None else " (varying: not derived)"
    ax.set_title(f"stable for delays of {low:g} to {high:g} samples{varying}")
    return Plot(figure, ax, artists)
