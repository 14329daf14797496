"""The paper's figures, regenerated from symstab's derivation and simulator.

Each ``fig*`` function computes its data with the library, has
:mod:`symstab.drawing` draw it (no matplotlib here) and returns a
:class:`FigureResult`: the figure, what the paper shows in it, and what
symstab finds -- the line that goes into the reproduction's ``index.md``.  :func:`make_figures` writes them all as PNGs.

Figures 6, 7, 8 and 10 draw the whole boundary -- the arc of eq. (7) up to
theta_max (solid) and the same curve on to theta = pi (dashed), which bounds
stable sets too (the lower edge of the gamma = 1 band in Fig. 10) -- and
fill the stable set: the cells of the exact D-decomposition with no
unstable pole (:meth:`symstab.numeric.paper.region.StabilityRegion.decomposition`).
Simulation (:func:`symstab.numeric.paper.simulate.stability_map`) is drawn over it
as a check, hatched; it takes most of the time.  Fig. 10 writes in every
cell its number of unstable closed-loop poles; Figs. 11 and 12 end the
Z-width at the gamma where the region vanishes, found by bisection.  Everything is in the paper's device
(m = 0.0128 kg m^2, b = 0.0324 N m s/rad, T = 1 ms) unless a figure says
otherwise.
"""

import dataclasses
import functools
import math
import pathlib
import sys
import time

import numpy as np

from . import drawing
from .numeric.paper.curves import arc_end_angle
from .numeric.paper.device import PAPER_DEVICE
from .numeric.paper.paper_loop import paper_passive_region
from .numeric.paper.region import (
    StabilityRegion,
    arc_polylines,
    boundary_curve,
    limits,
    vanishing_gamma,
)
from .numeric.paper.simulate import simulate
from .numeric.simulation.simulator import PAPER_ENCODER_RESOLUTION, Nonidealities

__all__ = ["FigureResult", "FIGURES", "make_figures"]

DELTA = PAPER_DEVICE.delta
#: The delays of Figs. 6, 8, 11 and 12.
DELAYS = (0, 1, 5, 10)
_COLORS = drawing.FIGURE_COLORS
#: The passive set's outline colour in Fig. 10 (drawn by :func:`symstab.drawing.physical_figure`).
_PASSIVE = drawing.PASSIVE_COLOR


@dataclasses.dataclass
class FigureResult:
    """A drawn figure and the two lines that describe it."""

    name: str
    title: str
    figure: object
    paper: str
    symstab: str


# --------------------------------------------------------------------------
# theta_max


def fig3():
    """theta_max versus gamma, d = 0 (eq. (8))."""
    import sympy as sp

    from .symbolic import model
    from .symbolic.theta_max import closed_form_d0

    gammas = np.linspace(-1.0, 2.0, 121)
    exact = np.array([arc_end_angle(gamma=g, d=0, delta=DELTA) for g in gammas])
    form = sp.lambdify((model.gamma, model.delta, model.Gamma), closed_form_d0().theta_max, "mpmath")
    import mpmath

    with mpmath.workdps(30):  # the closed form cancels near gamma = -1; 30 digits keep it exact
        closed = np.array([float(form(mpmath.mpf(g), mpmath.mpf(DELTA), mpmath.exp(DELTA)).real)
                           for g in gammas])
    fig = drawing.theta_max_gamma_figure(gammas, exact, closed)
    finite = np.isfinite(exact)
    gap = np.nanmax(np.abs(closed[finite] - exact[finite]) / exact[finite])
    return FigureResult(
        "fig03_theta_max_vs_gamma", "theta_max versus gamma (d = 0)", fig,
        "theta_max from (8) for gamma in [-1, 2]; it increases continuously with gamma.",
        f"(8) is proved equal to the derived closed form and agrees with the exact root to "
        f"{gap:.1e}; theta_max rises from {np.nanmin(exact):.3f} to {np.nanmax(exact):.3f} rad"
        + (", monotonically, as the paper says" if np.all(np.diff(exact[finite]) > 0)
           else ", but not monotonically") + "; "
        + (f"there is no arc for gamma <= {gammas[~finite].max():.3f}." if (~finite).any()
           else "an arc exists down to gamma = -1 (it needs gamma > -1 - delta)."))


def fig4():
    """theta_max versus d, gamma = 0: exact and the Newton form (12)."""
    from .symbolic.theta_max import theta_max_newton

    ds = np.arange(0, 101)
    exact = np.array([arc_end_angle(gamma=0.0, d=int(d), delta=DELTA) for d in ds])
    newton = np.array([theta_max_newton(d=int(d), delta=DELTA) if d > 0 else np.nan for d in ds])
    fig = drawing.theta_max_delay_figure(ds, exact, newton)
    err = np.abs(newton[1:] - exact[1:]) / exact[1:]
    return FigureResult(
        "fig04_theta_max_vs_d", "theta_max versus d (gamma = 0), exact and eq. (12)", fig,
        "theta_max from (12)/(47) for d in [0, 100]; it decreases as the delay grows.",
        f"the exact theta_max falls from {exact[0]:.4f} (d = 0) to {exact[-1]:.4f} rad (d = 100); "
        f"the one-step form (12) is an approximation: relative error {err[0]:.1e} at d = 1, "
        f"{err[9]:.1e} at d = 10, {err[-1]:.1e} at d = 100.")


def fig5():
    """The eq. (14) boundary (d = 0, gamma = 0), printed form against the derivation."""
    import sympy as sp

    from .paper_checks.printed import printed
    from .symbolic import model

    curve = boundary_curve(gamma=0.0, d=0, delta=DELTA, n=400, segments=False)
    args = (model.theta, model.delta, model.Gamma)
    fa = sp.lambdify(args, printed("eq14.alpha").expr, "numpy")
    fb = sp.lambdify(args, printed("eq14.beta").expr, "numpy")
    t = curve.theta[1:]
    pa, pb = fa(t, DELTA, math.exp(DELTA)), fb(t, DELTA, math.exp(DELTA))
    fig = drawing.eq14_figure(curve, pb, pa)
    gap = np.max(np.abs(pa - curve.alpha[1:])) / np.max(curve.alpha)
    return FigureResult(
        "fig05_eq14_boundary", "the eq. (14) boundary (d = 0, gamma = 0)", fig,
        "(14) against two earlier methods ([15], [24]); same start at beta = -bT/m, theta_max = "
        "1.5725 rad, beta_max = 2.",
        f"(14) is proved identical to the derived boundary (largest plotted difference "
        f"{gap:.1e} of alpha_max); theta_max = {curve.theta_max:.4f} rad, the arc runs from "
        f"beta = {curve.beta[0]:.5f} to {curve.beta[-1]:.4f}. The curves of [15], [24] are not "
        f"reproduced here (their formulas are not in the paper).")


# --------------------------------------------------------------------------
# The whole boundary, the stable set and the root counts in the cells

@functools.lru_cache(maxsize=64)
def _region(gamma, d):
    """The stable region of ``(gamma, d)``, kept: the panels, fills and verdicts share its scan."""
    return StabilityRegion(gamma=gamma, d=d, delta=DELTA)


@functools.lru_cache(maxsize=64)
def _decomposition(gamma, d, window):
    """The D-decomposition of ``window`` (``((beta0, beta1), (alpha0, alpha1))``), kept.

    Every branch of the boundary cuts the window into cells; each cell
    carries its number of unstable closed-loop poles, and the stable set
    is the union of the cells with none
    (:meth:`symstab.numeric.paper.region.StabilityRegion.decomposition`).
    """
    x_range, y_range = window
    return _region(gamma, d).decomposition(x_range=tuple(map(float, x_range)),
                                           y_range=tuple(map(float, y_range)))


def _window(gammas, d):
    """A common ``((beta0, beta1), (alpha0, alpha1))`` window for the stable regions of ``gammas`` at delay ``d``."""
    tops, lows, highs = [], [], []
    for g in gammas:
        lim = _region(g, d).limits()
        if not lim.empty:
            tops.append(lim.alpha_max)
            lows.append(lim.beta_left)
            highs.append(lim.beta_right)
    if not tops:
        return (-0.1, 2.0 / (d + 1)), (-0.04 / (d + 1), 1.0 / (d + 1))
    lo, hi = min(lows), max(highs)
    pad = 0.05 * (hi - lo)
    top = 1.12 * max(tops)
    # A strip below alpha = 0 shows the z = 1 line and that nothing under it is stable.
    return (lo - pad, hi + pad), (-0.04 * top, top)


def _arcs_window(gammas, d):
    """``((beta0, beta1), (alpha0, alpha1))`` window that holds every arc of eq. (7) of ``gammas`` whole."""
    b, a = [], []
    for g in gammas:
        curve = boundary_curve(gamma=g, d=d, delta=DELTA, n=2000, segments=False)
        b.append(curve.beta)
        a.append(curve.alpha)
    b, a = np.concatenate(b), np.concatenate(a)
    pad_b, top = 0.04 * (b.max() - b.min()), 1.06 * a.max()
    return (float(b.min() - pad_b), float(b.max() + pad_b)), (-0.04 * float(top), float(top))


def figure_horizon(d):
    """Periods simulated for the figures' maps: a third of the default horizon.

    Enough for the picture (on the paper's 32 grids it changes 6 of 320 000
    cells, all next to the boundary); the tests use the full
    :func:`symstab.numeric.paper.simulate.default_horizon`.
    """
    return 4000 + 400 * d


def _stable_maps(gammas, grids, d, **run):
    """``stability_map(alpha=alpha, beta=beta, gamma=g, d=d, **run).stable`` for each gamma.

    ``grids`` holds each gamma's ``(alpha, beta)``, all of one size.  In one
    run of the simulator (:func:`symstab.numeric.paper.simulate.simulate`,
    the run of :func:`~symstab.numeric.paper.simulate.stability_map`): it
    steps every point of every gamma together, one Python loop over the
    periods instead of one per gamma, which is most of a small grid's time.
    Each point is stepped alone all the same (its own ``K, B, M``), so its
    verdict is the one it has in its own map.
    """
    planes = [np.meshgrid(alpha, beta, indexing="ij") for alpha, beta in grids]
    A, B = (np.stack([plane[k] for plane in planes]) for k in (0, 1))
    G = np.asarray(gammas, dtype=float)[:, None, None]
    return list(simulate(alpha=A, beta=B, gamma=G, d=d, **run).stable)


def _simulated(gammas, d, window, n):
    """Simulate an ``n`` x ``n`` grid of the window's alpha >= 0 part at each of ``gammas``.

    Returns ``(beta, alpha, [stable map of each gamma])``.
    """
    (b0, b1), (a0, a1) = window
    alpha, beta = np.linspace(max(a0, 0.0), a1, n), np.linspace(b0, b1, n)
    return beta, alpha, _stable_maps(gammas, [(alpha, beta)] * len(gammas), d, delta=DELTA,
                                     steps=figure_horizon(d))


def _regions_panel(gammas, d, window, n, verdicts, beyond=True, colors=_COLORS, title=None):
    """A panel of exact stable sets, every branch of the boundary and simulation, to be drawn.

    The panel of :func:`symstab.drawing.regions_figure`; each simulated
    gamma's verdict is appended to ``verdicts``.
    """
    drawn = [g for g, _ in zip(gammas, colors, strict=False)]
    if n:
        beta, alpha, maps = _simulated(drawn, d, window, n)
    layers = []
    for k, (g, color) in enumerate(zip(drawn, colors, strict=False)):
        decomposition = _decomposition(g, d, window)
        simulated = None
        if n:
            simulated = (beta, alpha, maps[k])
            verdicts.append((g, d, "S" if maps[k].any() else "U", int(maps[k].sum()),
                             bool(decomposition.stable)))
        layers.append((color, decomposition, simulated,
                       arc_polylines(gamma=g, d=d, delta=DELTA, window=window)))
    return {"window": window, "layers": layers, "beyond": beyond, "title": title}


def _fig_overlay(name, title, suptitle, gammas, n, paper, claimed, lower=None):
    """Boundaries, exact stable sets and simulated ones; ``claimed[(gamma, d)]`` is the paper's S, U or B.

    ``title`` is the plain-text line of the reproduction's index, ``suptitle``
    the same in mathtext for the figure.  ``lower(windows)``, when given,
    returns a second row of panels under the first (Fig. 8's whole arcs and
    zoom).
    """
    verdicts, windows, top = [], {}, []
    for d in DELAYS:
        windows[d] = _arcs_window(gammas, d) if lower and d == 0 else _window(gammas, d)
        top.append(_regions_panel(gammas, d, windows[d], n, verdicts, title=f"$d = {d}$"))
    marks = {}
    for g in gammas:
        stable = [d for gg, d, v, _, _ in verdicts if gg == g and v == "S"]
        unstable = [d for gg, d, v, _, _ in verdicts if gg == g and v == "U"]
        marks[g] = ("S" if not unstable else "U" if not stable else
                    f"S at $d = {', '.join(map(str, stable))}$, U at $d = {', '.join(map(str, unstable))}$")
    fig = drawing.regions_figure(top, gammas, marks, n, suptitle,
                                 lower=None if lower is None else lower(windows))
    text = "; ".join(f"d={d}: " + ", ".join(f"{g:g} {v}" for g, dd, v, _, _ in verdicts if dd == d)
                     for d in DELAYS)
    differ = [f"gamma {g:g}, d {d}: paper {claimed[(g, d)]}, simulation {v}"
              for g, d, v, _, _ in verdicts if claimed[(g, d)] != v]
    verdict = ("every verdict agrees with the paper" if not differ
               else "differs from the paper at " + "; ".join(differ))
    counted = {(g, d): "U" if _region(g, d).limits().empty else "S"
               for g, d, _, _, _ in verdicts}
    split = [f"gamma {g:g}, d {d}" for g, d, v, _, _ in verdicts if counted[(g, d)] != v]
    check = ("root counting (symstab.limits) gives the same verdicts" if not split
             else "root counting disagrees with the simulation at " + ", ".join(split))
    return FigureResult(name, title, fig, paper,
                        "simulated verdicts (S: some stable cell, U: none): " + text + "; " + verdict
                        + "; " + check + ". Filled: the stable set by exact root counting; hatched: "
                        "stable in simulation; solid: the arc of eq. (7) up to theta_max, dashed: "
                        "the same curve beyond theta_max (another branch of the boundary); the z = -1 "
                        "line alpha + 2 beta = c lies at |c| ~ 9500, outside every panel.")


def fig6(n=100):
    """Negative virtual mass: gamma = 0, -0.25, -0.5, -0.75 at d = 0, 1, 5, 10."""
    gammas = (0.0, -0.25, -0.5, -0.75)
    return _fig_overlay("fig06_negative_mass_regions", "Fig. 6: gamma <= 0",
                        r"Fig. 6, $\gamma \leq 0$", gammas, n,
                        "stable regions shrink as d grows; every curve bounds a stable region.",
                        {(g, d): "S" for g in gammas for d in DELAYS})


def _fig8_second_row(gammas):
    """Fig. 8's lower panels: the gamma = 2 sliver at d = 0 magnified, every arc whole at d > 0."""
    def panels(windows):
        # d = 0: the sliver between the two halves of the gamma = 2 arc, at beta = -1.
        zoom = ((-1.011, -0.989), (1.978, 2.022))
        row = [_regions_panel((2.0,), 0, zoom, 0, [], beyond=False,
                              colors=(_COLORS[gammas.index(2.0)],),
                              title=r"$d = 0$, magnified: the $\gamma = 2$ sliver")]
        for d in DELAYS[1:]:
            whole = _arcs_window(gammas, d)
            # The stable sets lie in the upper panel's window: its decomposition serves.
            layers = [(color, _decomposition(g, d, windows[d]), None,
                       arc_polylines(gamma=g, d=d, delta=DELTA, window=whole))
                      for g, color in zip(gammas, _COLORS, strict=False)]
            row.append({"window": whole, "layers": layers, "beyond": False, "box": windows[d],
                        "title": f"$d = {d}$, zoomed out: every arc whole"})
        return row

    return panels


def fig8(n=100):
    """Positive virtual mass: gamma = 0 ... 2.2 at d = 0, 1, 5, 10."""
    gammas = (0.0, 0.5, 1.0, 1.5, 2.0, 2.2)
    claimed = {(g, 0): "S" for g in (0.0, 0.5, 1.0, 1.5)}
    claimed.update({(2.0, 0): "B", (2.2, 0): "U"})
    claimed.update({(g, 1): "S" for g in (0.0, 0.5, 1.0, 2.2)})
    claimed.update({(g, 1): "U" for g in (1.5, 2.0)})
    for d in (5, 10):
        claimed.update({(g, d): "S" if g <= 1 else "U" for g in gammas})
    return _fig_overlay("fig08_positive_mass_regions", "Fig. 8: gamma >= 0",
                        r"Fig. 8, $\gamma \geq 0$", gammas, n,
                        "d=0: gamma < 2 stable, 2 boundary (B), 2.2 unstable; d=1: 1.5 and 2 "
                        "unstable, the rest (2.2 included) stable; d=5, 10: 0, 0.5, 1 stable, 1.5, 2, "
                        "2.2 unstable.", claimed, lower=_fig8_second_row(gammas))


def _loop_counts(gamma, first, beta, window):
    """Root counts inside and just outside a thin loop of the arc, on the vertical ``beta``.

    ``first`` is the arc of eq. (7) as ``(beta, alpha)`` rows; it runs up
    to its tip and back, so it meets the vertical twice.  The counts are the
    certified ones of the D-decomposition's cells at a point between the two
    and one above.  Returns ``(inside, outside, alpha_tip, beta_tip)``.
    """
    ok = np.all(np.isfinite(first), axis=1)
    b, a = first[ok, 0], first[ok, 1]
    tip = int(np.argmax(a))
    heights = []
    for half in (slice(0, tip + 1), slice(tip, None)):
        order = np.argsort(b[half])
        heights.append(np.interp(beta, b[half][order], a[half][order]))
    lo, hi = sorted(heights)
    inside, outside = _decomposition(gamma, 0, window).count_at([beta, beta], [0.5 * (lo + hi), hi + 0.25])
    return int(inside), int(outside), float(a[tip]), float(b[tip])


def fig7():
    """Boundaries for gamma 0 .. 3 at d = 0 with the numbered points."""
    gammas = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
    window = ((-4.5, 2.2), (-0.25, 6.6))
    loops, layers = {}, []
    for g, color in zip(gammas, _COLORS, strict=False):
        lim = limits(gamma=g, d=0, delta=DELTA)
        tag = "U" if lim.empty else ("S, a thin sliver" if lim.z_width < 0.05 else "S")
        arc = arc_polylines(gamma=g, d=0, delta=DELTA, window=window)
        layers.append((g, color, tag, _decomposition(g, 0, window), arc))
        if lim.empty:
            loops[g] = (_loop_counts(g, arc[0], -1.5, window), color)
    points = []
    lim0 = limits(gamma=0.0, d=0, delta=DELTA)
    points.append((1, lim0.beta_at_alpha_max, lim0.alpha_max))
    for k, (g, b) in ((2, (1.0, 0.0)), (3, (1.5, -1.0))):
        runs = StabilityRegion(gamma=g, d=0, delta=DELTA).alpha_intervals(b)
        points.append((k, b, runs[-1][1]))
    lim2 = limits(gamma=2.0, d=0, delta=DELTA)
    points.append((4, lim2.beta_at_alpha_max, lim2.alpha_max))
    (lo, hi), = StabilityRegion(gamma=1.5, d=0, delta=DELTA).alpha_intervals(-0.5)
    points += [(5, -0.5, hi), (6, -0.5, lo)]
    fig = drawing.boundaries_d0_figure(layers, points, loops, window)
    text = ", ".join(f"{k}: (beta {b:.4f}, alpha {a:.4f})" for k, b, a in points)
    loop_text = "; ".join(f"gamma = {g:g}: the two parallel lines are one thin loop of eq. (7) with its "
                          f"tip at alpha {a:.2f}, beta {b:.2f} ({i} unstable poles inside it, {o} "
                          f"outside)" for g, ((i, o, a, b), _) in sorted(loops.items()))
    return FigureResult(
        "fig07_gamma_0_to_3_d0", "boundaries for gamma 0..3 at d = 0, numbered points", fig,
        "circles 1-6: alpha_max 0.6896 at beta 0.8206 (gamma 0); alpha 2 at beta 0, gamma 1; "
        "alpha ~3 at beta -1, gamma 1.5; alpha ~4 at beta -2, gamma 2; at beta = -0.5, gamma 1.5 "
        "the largest (5) and the smallest (6) stable alpha; gamma = 2 is a boundary case.",
        f"circles {text}. Circle 1 is at beta {lim0.beta_at_alpha_max:.4f}, not 0.8206 "
        f"(alpha_max {lim0.alpha_max:.5f}); at gamma = 2 the region is "
        + (f"a thin stable sliver (Z-width {lim2.z_width:.4f}), not a line" if not lim2.empty
           else "empty") + "; " + loop_text + ".")


def _mass_label(g):
    """``M_w = g m`` in mathtext: a multiple of the device's inertia (``0.5 m`` would read as metres)."""
    if g == 0:
        return r"M_w = 0"
    if g == 1:
        return r"M_w = m"
    return fr"M_w = {g:g}\,m"


def fig10(n=40):
    """Physical units at Td = 40 ms: theory and simulations, ideal and quantized + filtered."""
    qf = Nonidealities(encoder_resolution=PAPER_ENCODER_RESOLUTION, velocity_cutoff=50.0)
    found, panels, passive_k = [], [], {}
    gammas = (-0.5, 0.0, 0.5, 1.0)
    windows = [_fig10_window(g) for g in gammas]
    grids = [(np.linspace(0.0, a1, n), np.linspace(b0, b1, n)) for (b0, b1), (_, a1) in windows]
    ideal = _stable_maps(gammas, grids, 40, delta=DELTA)
    quant = _stable_maps(gammas, grids, 40, delta=None, device=PAPER_DEVICE, nonideal=qf, x0=0.01)
    for g, window, grid, maps in zip(gammas, windows, grids, zip(ideal, quant, strict=True),
                                     strict=True):
        row, panel, passive_k[g] = _fig10_panel(g, window, grid, maps)
        found.append(row)
        panels.append(panel)
    fig, written = drawing.physical_figure(panels)
    counted = dict(zip(gammas, written, strict=True))
    return FigureResult(
        "fig10_physical_td40", "physical units at Td = 40 ms, gamma = M_w/m = -0.5, 0, 0.5, 1", fig,
        "theory against simulations (ideal; quantization + filter; PI controller high/low gains) and "
        "experiments; PI(-), QF(+) gives a lower K_max than the theory.",
        _fig10_finding(found, counted, passive_k, n))


def _fig10_window(g):
    """Fig. 10's ``((beta0, beta1), (alpha0, alpha1))`` window at ``gamma = g``: the arc, padded."""
    curve = boundary_curve(gamma=g, d=40, delta=DELTA, n=1000, segments=False)
    top = 1.12 * float(curve.alpha.max())
    pad = 0.06 * float(curve.beta.max() - curve.beta.min())
    return (float(curve.beta.min()) - pad, float(curve.beta.max()) + pad), (-0.05 * top, top)


def _fig10_panel(g, window, grid, maps):
    """One panel of Fig. 10 at ``gamma = g``: the exact set, the two simulations, passivity.

    ``grid`` is the simulated ``(alpha, beta)`` of ``window``, ``maps`` the
    stable cells of the ideal and the quantized + filtered runs there.
    Returns ``((g, K_max theory, K_max ideal sim, K_max QF sim, B_max ideal sim,
    B_max QF sim), the panel to draw, the passive K_max or None)``.
    """
    dev, d = PAPER_DEVICE, 40
    # K_w and B_w are alpha and beta times constants: the plane is only rescaled.
    scale = (float(dev.damping(1.0)), float(dev.stiffness(1.0)))
    lim = limits(gamma=g, d=d, delta=DELTA)
    decomposition = _decomposition(g, d, window)
    (alpha, beta), (ideal, quant) = grid, maps
    passive = paper_passive_region(gamma=g, d=d, delta=DELTA)
    panel = {"window": window, "scale": scale, "decomposition": decomposition,
             "arc": arc_polylines(gamma=g, d=d, delta=DELTA, window=window),
             "grid": (dev.stiffness(alpha), dev.damping(beta)), "ideal": ideal,
             "quantized": quant,
             "passive": None if passive.empty else
             np.vstack([passive.polygon, passive.polygon[:1]]) * scale,
             "title": fr"${_mass_label(g)}$ ($\gamma = {g:g}$)"
                      + (", no passive point" if passive.empty else "")}
    passive_k = None if passive.empty else float(dev.stiffness(passive.y_max))
    A, Bm = np.meshgrid(alpha, beta, indexing="ij")

    def top_of(mask):
        return (dev.stiffness(A[mask].max()), dev.damping(Bm[mask].max())) if mask.any() else (0.0, 0.0)

    (ki, bi), (kq, bq) = top_of(ideal), top_of(quant)
    return (g, float(dev.stiffness(lim.alpha_max)), ki, kq, bi, bq), panel, passive_k


def _fig10_finding(found, counted, passive_k, n):
    """What symstab finds for Fig. 10, in words (the rows of :func:`_fig10_panel`)."""
    text = "; ".join(f"gamma = {g:g}: K_max theory {kt:.2f}, ideal sim {ki:.2f}, QF sim {kq:.2f} N m/rad "
                     f"(QF/ideal {kq / ki if ki else float('nan'):.2f}); B_max QF/ideal "
                     f"{bq / bi if bi else float('nan'):.2f}" for g, kt, ki, kq, bi, bq in found)
    band = sorted({c for _, _, c in counted[1.0]})
    return (
        f"{text} (grid {n} x {n}, so K and B are resolved to one cell). "
        + ("The ideal simulation reaches the theoretical K_max within two cells in every panel; "
           if all(abs(ki - kt) <= 2.5 * kt / n for _, kt, ki, _, _, _ in found)
           else "The ideal simulation falls short of the theoretical K_max by more than two cells; ")
        + ("quantization (3 arc seconds) with the 50 Hz velocity filter lowers K_max in every panel, "
           "as the paper reports. " if all(kq < ki for _, _, ki, kq, _, _ in found)
           else "quantization with the 50 Hz filter does not lower K_max in every panel, unlike the "
                "paper's report. ")
        + "The PI current-controller runs and the experiments are not modelled. At gamma = 1 the arc "
          "of eq. (7) encloses more than the stable set: the stable set is the band along its upper "
          "edge, and the band's lower edge is the same curve beyond theta_max (dashed); the cells "
          f"the boundary cuts the window into hold {', '.join(map(str, band))} unstable poles "
          "(numbers in the cells). Passivity (Colgate-Schenkel, with the delay; dashed): "
        + "; ".join(f"gamma = {g:g}: " + ("no passive point" if k is None else
                                          f"passive K_max {k:.2f} N m/rad against the stable "
                                          f"{kt:.2f}")
                    for (g, k), (_, kt, _, _, _, _) in zip(passive_k.items(), found, strict=True))
        + ("; the loop is stable far outside the passive set." if any(
            k is not None and k < kt
            for (_, k), (_, kt, _, _, _, _) in zip(passive_k.items(), found, strict=True))
           else "."))


# --------------------------------------------------------------------------
# Limits versus gamma


def _fig_limits(name, title, suptitle, gammas, paper, note):
    """beta_max, alpha_max and the Z-width versus ``gammas``, one column per delay.

    Upper row: the three on a log axis (at d = 10 alpha_max and the Z-width
    are 30 and 300 times smaller than beta_max and would lie flat on a
    linear one).  Lower row: the Z-width on a linear axis, where it can
    reach zero -- at the gamma where the region vanishes, found by
    bisection on the certified emptiness of :func:`symstab.limits`, not on
    the grid.  ``title`` is the plain-text line of the reproduction's
    index, ``suptitle`` the same in mathtext for the figure.
    """
    summary, facts, columns = [], [], []
    for d in DELAYS:
        column, fact = _limits_column(gammas, d)
        columns.append(column)
        facts.append(fact)
        am, bm, zw, edge, vanish = (fact[k] for k in ("am", "bm", "zw", "edge", "vanish"))
        k = int(np.nanargmax(am))
        summary.append(f"d={d}: alpha_max peaks at {am[k]:.4g} (gamma {gammas[k]:.2f}); "
                       f"{'last' if column['right'] else 'first'} gamma of the scan with a region "
                       f"{gammas[edge]:.2f}: alpha_max {am[edge]:.3g}, beta_max {bm[edge]:.3g}, "
                       f"Z-width {zw[edge]:.3g}"
                       + (f"; the region vanishes at gamma = {vanish[1]:.5f} (bisection on "
                          f"root counting, to {abs(vanish[1] - vanish[0]):.0e})" if vanish else ""))
    fig = drawing.limits_figure(columns, suptitle)
    return FigureResult(name, title, fig, paper, "; ".join(summary) + "; " + note(facts)
                        + " Upper panels: log scale (the three span up to three decades); lower "
                          "panels: the Z-width on a linear scale, closing to 0 at gamma*.")


def _limits_column(gammas, d):
    """The limits of ``gammas`` at delay ``d``: the column to draw and its facts for the text.

    Where the region ends inside the scan, the gamma where it vanishes
    (bisection) and a few points closer and closer to it.
    """
    rows = [limits(gamma=g, d=d, delta=DELTA) for g in gammas]
    empty = np.array([r.empty for r in rows])
    have = np.flatnonzero(~empty)
    right = gammas[0] >= 0  # Fig. 12: the region ends on the right
    edge = have[-1] if right else have[0]
    beyond = edge + 1 if right else edge - 1
    vanish, edge_rows = None, []
    if 0 <= beyond < len(gammas) and empty[beyond]:
        vanish = vanishing_gamma(d=d, delta=DELTA, inside=gammas[edge], outside=gammas[beyond])
        # A few points between the last grid gamma and the vanishing one,
        # closer and closer, show how the Z-width goes to zero.
        edge_rows = [(g, limits(gamma=g, d=d, delta=DELTA)) for g in
                     (vanish[0] + (gammas[edge] - vanish[0]) * s for s in (0.3, 0.1, 0.0))]
    g_edge = [g for g, _ in edge_rows]
    z_edge = [r.z_width for _, r in edge_rows]
    g_all = np.array(gammas, dtype=float)
    bm = np.array([np.nan if r.empty else r.beta_right for r in rows])
    am = np.array([np.nan if r.empty else r.alpha_max for r in rows])
    zw = np.array([r.z_width for r in rows])
    # beta_max and alpha_max up to the vanishing gamma (where they stay
    # finite); the Z-width on the grid only: its last few points fall by
    # decades and would stretch the log axis.
    order = np.argsort(np.concatenate([g_all, [g for g, _ in edge_rows]]))
    g_ab = np.concatenate([g_all, [g for g, _ in edge_rows]])[order]
    b_ab = np.concatenate([bm, [r.beta_right for _, r in edge_rows]])[order]
    a_ab = np.concatenate([am, [r.alpha_max for _, r in edge_rows]])[order]
    # The Z-width, linear: the grid, then the points that close on the vanishing gamma.
    order = np.argsort(np.concatenate([g_all[~empty], g_edge]))
    g_lin = np.concatenate([g_all[~empty], g_edge])[order]
    z_lin = np.concatenate([zw[~empty], z_edge])[order]
    if vanish is not None:
        g_lin = np.append(g_lin, vanish[1]) if right else np.insert(g_lin, 0, vanish[1])
        z_lin = np.append(z_lin, 0.0) if right else np.insert(z_lin, 0, 0.0)
    column = {"d": d, "log": (g_ab, b_ab, a_ab), "grid": (g_all, zw), "linear": (g_lin, z_lin),
              "vanish": None if vanish is None else vanish[1], "right": right,
              "range": (gammas[0], gammas[-1])}
    fact = dict(d=d, am=am, bm=bm, zw=zw, edge=edge, empty=empty, vanish=vanish,
                z_lin=z_lin, g_lin=g_lin)
    return column, fact


def fig11(n=22):
    """beta_max, alpha_max and Z-width versus gamma < 0, at ``n`` values of gamma from -1.05."""
    gammas = np.linspace(-1.05, 0.0, n)
    return _fig_limits("fig11_limits_negative_mass", "Fig. 11: limits versus gamma <= 0",
                       r"Fig. 11: limits versus $\gamma \leq 0$", gammas,
                       "beta_max, alpha_max and Z-width decrease continuously as gamma goes from 0 "
                       "to -1, where all are zero.",
                       lambda facts: (
                           ("all three decrease towards gamma = -1" if all(
                               np.all(np.diff(f["am"][~f["empty"]]) > 0)
                               and np.all(np.diff(f["zw"][~f["empty"]]) > 0)
                               for f in facts) else "they do not all decrease monotonically")
                           + "; the region vanishes at gamma* = " + ", ".join(
                               f"{f['vanish'][1]:.5f} (d = {f['d']})" for f in facts if f["vanish"])
                           + ", just below -1: a region exists while gamma > -1 - (d + 1) delta "
                             "(REPORT.md, claim:no_region_gamma_le_-1), so at gamma = -1 the limits "
                             "are tiny, not zero."))


def fig12(n=36):
    """beta_max, alpha_max and Z-width versus gamma > 0, at ``n`` values of gamma."""
    gammas = np.linspace(0.0, 2.5, n)
    return _fig_limits("fig12_limits_positive_mass", "Fig. 12: limits versus gamma >= 0",
                       r"Fig. 12: limits versus $\gamma \geq 0$", gammas,
                       "d = 0: largest gamma 2, beta_max falls from gamma 0 to 2; alpha_max and "
                       "Z-width rise, then fall; for d > 0 the Z-width reaches zero while beta_max "
                       "and alpha_max do not.",
                       lambda facts: "; ".join(
                           f"d={f['d']}: the Z-width "
                           + ("rises, then falls" if np.nanargmax(f["zw"]) > 0 else "falls")
                           + (f" to zero at gamma* = {f['vanish'][1]:.5f}" if f["vanish"] else "")
                           + ("; where the region ends beta_max and alpha_max are still nonzero"
                              if f["bm"][f["edge"]] > 0 and f["am"][f["edge"]] > 0 else "")
                           for f in facts) + ".")


#: Every figure, in the paper's order.
FIGURES = (fig3, fig4, fig5, fig6, fig7, fig8, fig10, fig11, fig12)


def make_figures(out_dir, progress=None):
    """Draw every figure into ``out_dir`` as PNG; return the FigureResults.

    ``progress(name, seconds)`` is called after each figure; True prints
    ``name: seconds`` on stderr (``symstab._validate.check_progress``).
    """
    from ._io import write_bytes
    from ._validate import check_progress

    progress = check_progress(progress, lambda: lambda name, seconds: print(
        f"{name}: {seconds:.1f} s", file=sys.stderr, flush=True))

    plt = drawing.pyplot()
    out = pathlib.Path(out_dir)
    results = []
    for make in FIGURES:
        start = time.perf_counter()
        result = make()
        write_bytes(out / f"{result.name}.png", drawing.png_bytes(plt, result.figure))
        result.figure = None
        results.append(result)
        if progress is not None:
            progress(result.name, time.perf_counter() - start)
    return results
