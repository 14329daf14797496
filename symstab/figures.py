"""The paper's figures, regenerated from symstab's derivation and simulator.

Each ``fig*`` function computes its data with the library, draws it with
matplotlib and returns a :class:`FigureResult`: the figure, what the paper
shows in it, and what symstab finds -- the line that goes into the
reproduction's ``index.md``.  :func:`make_figures` writes them all as PNGs.

Figures 6, 8 and 10 overlay stable areas found by simulation
(:func:`symstab.numeric.simulate.stability_map`) on the theoretical boundaries;
they take most of the time.  Everything is in the paper's device
(m = 0.0128 kg m^2, b = 0.0324 N m s/rad, T = 1 ms) unless a figure says
otherwise.
"""

import dataclasses
import io
import math
import pathlib
import time

import numpy as np

from .numeric.curves import arc_end_angle
from .numeric.region import boundary_curve
from .numeric.region import StabilityRegion, limits
from .numeric.simulate import PAPER_ENCODER_RESOLUTION, Nonidealities, stability_map
from .numeric.units import PAPER_DEVICE

__all__ = ["FigureResult", "FIGURES", "make_figures", "pyplot", "require_matplotlib"]

DELTA = PAPER_DEVICE.delta
#: The delays of Figs. 6, 8, 11 and 12.
DELAYS = (0, 1, 5, 10)
_COLORS = ("#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2")
#: Font sizes (pt).  A figure's own title sits above its panels' titles, so it
#: is the largest; legends stay readable at the saved 110 dpi (6-7 pt was not).
SUPTITLE_SIZE = 13
PANEL_TITLE_SIZE = 11
LEGEND_SIZE = 8
#: Legend of the arc's end angle in Figs. 3 and 4, in words rather than in
#: the derivation's terms ("first root of alpha").
_THETA_MAX_EXACT = r"exact: where the arc ends, $\alpha(\theta_{\max}) = 0$"


@dataclasses.dataclass
class FigureResult:
    """A drawn figure and the two lines that describe it."""

    name: str
    title: str
    figure: object
    paper: str
    symstab: str


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


def _label_log_axis(ax):
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


def _labels(ax, physical=False):
    if physical:
        ax.set_xlabel(r"$B_w$ (N m s/rad)")
        ax.set_ylabel(r"$K_w$ (N m/rad)")
    else:
        ax.set_xlabel(r"$\beta = B_w T/m$")
        ax.set_ylabel(r"$\alpha = K_w T^2/m$")


# --------------------------------------------------------------------------
# theta_max


def fig3():
    """theta_max versus gamma, d = 0 (eq. (8))."""
    from .symbolic.theta_max import closed_form_d0
    from .symbolic import model
    import sympy as sp

    plt = pyplot()
    gammas = np.linspace(-1.0, 2.0, 121)
    exact = np.array([arc_end_angle(gamma=g, d=0, delta=DELTA) for g in gammas])
    form = sp.lambdify((model.gamma, model.delta, model.Gamma), closed_form_d0().theta_max, "mpmath")
    import mpmath

    with mpmath.workdps(30):  # the closed form cancels near gamma = -1; 30 digits keep it exact
        closed = np.array([float(form(mpmath.mpf(g), mpmath.mpf(DELTA), mpmath.exp(DELTA)).real)
                           for g in gammas])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(gammas, exact, "-", color=_COLORS[0], lw=2, label=_THETA_MAX_EXACT)
    ax.plot(gammas[::6], closed[::6], "o", color=_COLORS[1], ms=4, label="closed form (8)")
    ax.set_xlabel(r"$\gamma = M_w/m$")
    ax.set_ylabel(r"$\theta_{\max}$ (rad)")
    ax.set_title(r"Fig. 3: $\theta_{\max}$ versus $\gamma$, $d = 0$")
    ax.legend()
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
    plt = pyplot()
    import sympy as sp
    from .symbolic import model
    from .symbolic.theta_max import newton_form_gamma0

    ds = np.arange(0, 101)
    exact = np.array([arc_end_angle(gamma=0.0, d=int(d), delta=DELTA) for d in ds])
    form = sp.lambdify((model.d, model.delta, model.Gamma), newton_form_gamma0().theta_newton, "mpmath")
    newton = np.array([float(form(int(d), DELTA, math.exp(DELTA))) if d > 0 else np.nan for d in ds])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.semilogy(ds, exact, "-", color=_COLORS[0], lw=2, label=_THETA_MAX_EXACT)
    ax.semilogy(ds[1:], newton[1:], "--", color=_COLORS[1], lw=1.5, label="one Newton step, eq. (12)")
    ax.set_xlabel(r"delay $d = T_d / T$ (samples)")
    ax.set_ylabel(r"$\theta_{\max}$ (rad)")
    _label_log_axis(ax)  # theta_max spans two decades, 1.6 to 0.017 rad
    ax.set_title(r"Fig. 4: $\theta_{\max}$ versus $d$, $\gamma = 0$")
    ax.legend()
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
    from .symbolic import model
    from paper_checks.printed import printed

    plt = pyplot()
    curve = boundary_curve(gamma=0.0, d=0, delta=DELTA, n=400, segments=False)
    args = (model.theta, model.delta, model.Gamma)
    fa = sp.lambdify(args, printed("eq14.alpha").expr, "numpy")
    fb = sp.lambdify(args, printed("eq14.beta").expr, "numpy")
    t = curve.theta[1:]
    pa, pb = fa(t, DELTA, math.exp(DELTA)), fb(t, DELTA, math.exp(DELTA))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(curve.beta, curve.alpha, "-", color=_COLORS[2], lw=2.5,
            label=r"symstab (derived for any $d$ and $\gamma$)")
    ax.plot(pb, pa, "--", color=_COLORS[0], lw=1.5, label="eq. (14) as printed")
    _labels(ax)
    ax.set_title(r"Fig. 5: boundary for $d = 0$, $\gamma = 0$")
    ax.legend()
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
# Boundaries over simulated stable areas


def _window(gammas, d):
    """A common (alpha, beta) window for the regions of ``gammas`` at delay ``d``."""
    tops, lows, highs = [], [], []
    for g in gammas:
        lim = limits(gamma=g, d=d, delta=DELTA, n_beta=101)
        if not lim.empty:
            tops.append(lim.alpha_max)
            lows.append(lim.beta_left)
            highs.append(lim.beta_right)
    if not tops:
        return (0.0, 1.0 / (d + 1)), (-0.1, 2.0 / (d + 1))
    lo, hi = min(lows), max(highs)
    pad = 0.05 * (hi - lo)
    return (0.0, 1.12 * max(tops)), (lo - pad, hi + pad)


def figure_horizon(d):
    """Periods simulated for the figures' maps: a third of the default horizon.

    Enough for the picture (on the paper's 32 grids it changes 6 of 320 000
    cells, all next to the boundary); the tests use the full
    :func:`symstab.numeric.simulate.default_horizon`.
    """
    return 4000 + 400 * d


def _overlay(ax, gammas, d, n, verdicts):
    (a0, a1), (b0, b1) = _window(gammas, d)
    alpha, beta = np.linspace(a0, a1, n), np.linspace(b0, b1, n)
    for g, color in zip(gammas, _COLORS):
        result = stability_map(alpha=alpha, beta=beta, gamma=g, d=d, delta=DELTA,
                               steps=figure_horizon(d))
        if result.stable.any():
            ax.contourf(beta, alpha, result.stable.astype(float), levels=[0.5, 1.5],
                        colors=[color], alpha=0.25)
        curve = boundary_curve(gamma=g, d=d, delta=DELTA, n=1500, segments=False)
        verdict = "S" if result.stable.any() else "U"
        verdicts.append((g, d, verdict, int(result.stable.sum())))
        if not curve.empty:
            ax.plot(curve.beta, curve.alpha, "-", color=color, lw=1.4,
                    label=fr"$\gamma$ = {g:g} ({verdict})")
        else:
            ax.plot([], [], "-", color=color, label=fr"$\gamma$ = {g:g} (no arc)")
    ax.set_xlim(b0, b1)
    ax.set_ylim(a0, a1)
    ax.set_title(f"$d = {d}$ (simulated {figure_horizon(d)} periods)", fontsize=PANEL_TITLE_SIZE)
    _labels(ax)
    ax.legend(fontsize=LEGEND_SIZE, loc="upper right")


def _fig_overlay(name, title, suptitle, gammas, n, paper, claimed):
    """Boundaries over simulated areas; ``claimed[(gamma, d)]`` is the paper's S, U or B.

    ``title`` is the plain-text line of the reproduction's index, ``suptitle``
    the same in mathtext for the figure.
    """
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    verdicts = []
    for ax, d in zip(axes.ravel(), DELAYS):
        _overlay(ax, gammas, d, n, verdicts)
    fig.suptitle(suptitle + " (curves: theory, eq. (7); shaded: stable by simulation, "
                 fr"${n} \times {n}$ grid)", fontsize=SUPTITLE_SIZE)
    fig.tight_layout()
    text = "; ".join(f"d={d}: " + ", ".join(f"{g:g} {v}" for g, dd, v, _ in verdicts if dd == d)
                     for d in DELAYS)
    differ = [f"gamma {g:g}, d {d}: paper {claimed[(g, d)]}, simulation {v}"
              for g, d, v, _ in verdicts if claimed[(g, d)] != v]
    verdict = ("every verdict agrees with the paper" if not differ
               else "differs from the paper at " + "; ".join(differ))
    counted = {(g, d): "U" if limits(gamma=g, d=d, delta=DELTA, n_beta=21).empty else "S"
               for g, d, _, _ in verdicts}
    split = [f"gamma {g:g}, d {d}" for g, d, v, _ in verdicts if counted[(g, d)] != v]
    check = ("root counting (symstab.limits) gives the same verdicts" if not split
             else "root counting disagrees with the simulation at " + ", ".join(split))
    return FigureResult(name, title, fig, paper,
                        "simulated verdicts (S: some stable cell, U: none): " + text + "; " + verdict
                        + "; " + check + ".")


def fig6(n=100):
    """Negative virtual mass: gamma = 0, -0.25, -0.5, -0.75 at d = 0, 1, 5, 10."""
    gammas = (0.0, -0.25, -0.5, -0.75)
    return _fig_overlay("fig06_negative_mass_regions", "Fig. 6: gamma <= 0",
                        r"Fig. 6: $\gamma \leq 0$", gammas, n,
                        "stable regions shrink as d grows; every curve bounds a stable region.",
                        {(g, d): "S" for g in gammas for d in DELAYS})


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
                        r"Fig. 8: $\gamma \geq 0$", gammas, n,
                        "d=0: gamma < 2 stable, 2 boundary (B), 2.2 unstable; d=1: 1.5 and 2 "
                        "unstable, the rest (2.2 included) stable; d=5, 10: 0, 0.5, 1 stable, 1.5, 2, "
                        "2.2 unstable.", claimed)


def fig7():
    """Boundaries for gamma 0 .. 3 at d = 0 with the numbered points."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    gammas = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
    for g, color in zip(gammas, _COLORS):
        curve = boundary_curve(gamma=g, d=0, delta=DELTA, n=2000, segments=False)
        lim = limits(gamma=g, d=0, delta=DELTA, n_beta=101)
        tag = "U" if lim.empty else ("S, a thin sliver" if lim.z_width < 0.05 else "S")
        if not curve.empty:
            ax.plot(curve.beta, curve.alpha, "-", color=color, lw=1.5, label=fr"$\gamma$ = {g:g} ({tag})")
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
    for k, b, a in points:
        ax.plot(b, a, "o", ms=13, mfc="none", mec="k")
        ax.annotate(str(k), (b, a), ha="center", va="center", fontsize=8)
    ax.axvline(-0.5, color="k", ls="--", lw=0.8)
    ax.set_xlim(-2.5, 2.2)
    ax.set_ylim(0, 4.5)
    _labels(ax)
    ax.set_title(r"Fig. 7: boundaries for $d = 0$; S: a stable region, U: none (root counting)")
    ax.legend(fontsize=LEGEND_SIZE, loc="upper right")
    text = ", ".join(f"{k}: (beta {b:.4f}, alpha {a:.4f})" for k, b, a in points)
    return FigureResult(
        "fig07_gamma_0_to_3_d0", "boundaries for gamma 0..3 at d = 0, numbered points", fig,
        "circles 1-6: alpha_max 0.6896 at beta 0.8206 (gamma 0); alpha 2 at beta 0, gamma 1; "
        "alpha ~3 at beta -1, gamma 1.5; alpha ~4 at beta -2, gamma 2; at beta = -0.5, gamma 1.5 "
        "the largest (5) and the smallest (6) stable alpha; gamma = 2 is a boundary case.",
        f"circles {text}. Circle 1 is at beta {lim0.beta_at_alpha_max:.4f}, not 0.8206 "
        f"(alpha_max {lim0.alpha_max:.5f}); at gamma = 2 the region is "
        + (f"a thin stable sliver (Z-width {lim2.z_width:.4f}), not a line." if not lim2.empty
           else "empty."))


def fig10(n=40):
    """Physical units at Td = 40 ms: theory and simulations, ideal and quantized + filtered."""
    plt = pyplot()
    dev, d = PAPER_DEVICE, 40
    qf = Nonidealities(encoder_resolution=PAPER_ENCODER_RESOLUTION, velocity_cutoff=50.0)
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    found = []
    for ax, g in zip(axes.ravel(), (-0.5, 0.0, 0.5, 1.0)):
        lim = limits(gamma=g, d=d, delta=DELTA)
        alpha = np.linspace(0, 1.25 * lim.alpha_max, n)
        beta = np.linspace(lim.beta_left, 1.2 * lim.beta_right, n)
        ideal = stability_map(alpha=alpha, beta=beta, gamma=g, d=d, delta=DELTA)
        quant = stability_map(alpha=alpha, beta=beta, gamma=g, d=d, delta=None, device=dev,
                              nonideal=qf, x0=0.01)
        K, B = dev.stiffness(alpha), dev.damping(beta)
        ax.contourf(B, K, ideal.stable.astype(float), levels=[0.5, 1.5], colors=["#9ecae1"], alpha=0.6)
        ax.contour(B, K, quant.stable.astype(float), levels=[0.5], colors=["#2ca02c"],
                   linestyles="--", linewidths=1.5)
        curve = boundary_curve(gamma=g, d=d, delta=DELTA, n=1000, segments=False)
        ax.plot(dev.damping(curve.beta), dev.stiffness(curve.alpha), "k-", lw=1.5)
        ax.plot([], [], "k-", label="theory, eq. (7)")
        ax.plot([], [], "s", color="#9ecae1", label="simulation, ideal (PI(-), QF(-))")
        ax.plot([], [], "--", color="#2ca02c", label="simulation, quantized + 50 Hz filter (PI(-), QF(+))")
        # M_w is a multiple of the device's inertia m; "0.5 m" would read as metres.
        ax.set_title(fr"$M_w = {g:g} \cdot m$ ($\gamma = {g:g}$), $T_d = 40$ ms",
                     fontsize=PANEL_TITLE_SIZE)
        _labels(ax, physical=True)
        ax.legend(fontsize=LEGEND_SIZE, loc="upper right")
        A, Bm = np.meshgrid(alpha, beta, indexing="ij")

        def top(mask):
            return (dev.stiffness(A[mask].max()), dev.damping(Bm[mask].max())) if mask.any() else (0.0, 0.0)

        (ki, bi), (kq, bq) = top(ideal.stable), top(quant.stable)
        found.append((g, float(dev.stiffness(lim.alpha_max)), ki, kq, bi, bq))
    fig.suptitle(r"Fig. 10: physical units, $T_d = 40$ ms (the PI current-controller cases and "
                 "the experiments are not modelled)", fontsize=SUPTITLE_SIZE)
    fig.tight_layout()
    text = "; ".join(f"gamma = {g:g}: K_max theory {kt:.2f}, ideal sim {ki:.2f}, QF sim {kq:.2f} N m/rad "
                     f"(QF/ideal {kq / ki if ki else float('nan'):.2f}); B_max QF/ideal "
                     f"{bq / bi if bi else float('nan'):.2f}" for g, kt, ki, kq, bi, bq in found)
    return FigureResult(
        "fig10_physical_td40", "physical units at Td = 40 ms, gamma = M_w/m = -0.5, 0, 0.5, 1", fig,
        "theory against simulations (ideal; quantization + filter; PI controller high/low gains) and "
        "experiments; PI(-), QF(+) gives a lower K_max than the theory.",
        f"{text} (grid {n} x {n}, so K and B are resolved to one cell). "
        + ("The ideal simulation reaches the theoretical K_max within two cells in every panel; "
           if all(abs(ki - kt) <= 2.5 * kt / n for _, kt, ki, _, _, _ in found)
           else "The ideal simulation falls short of the theoretical K_max by more than two cells; ")
        + ("quantization (3 arc seconds) with the 50 Hz velocity filter lowers K_max in every panel, "
           "as the paper reports. " if all(kq < ki for _, _, ki, kq, _, _ in found)
           else "quantization with the 50 Hz filter does not lower K_max in every panel, unlike the "
                "paper's report. ")
        + "The PI current-controller runs and the experiments are not modelled. At gamma = 1 the arc "
          "of eq. (7) encloses more than the stable set, which is the band along its upper edge "
          "(the lower edge is another part of the boundary).")


def _fig_limits(name, title, suptitle, gammas, paper, note):
    """beta_max, alpha_max and Z-width versus ``gammas``, one panel per delay.

    ``title`` is the plain-text line of the reproduction's index, ``suptitle``
    the same in mathtext for the figure.
    """
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5))
    summary, facts = [], []
    for ax, d in zip(axes.ravel(), DELAYS):
        rows = [limits(gamma=g, d=d, delta=DELTA, n_beta=101) for g in gammas]
        bm = np.array([np.nan if r.empty else r.beta_right for r in rows])
        am = np.array([np.nan if r.empty else r.alpha_max for r in rows])
        zw = np.array([r.z_width for r in rows])
        # One log axis: at d = 10 alpha_max and the Z-width are 30 and 300
        # times smaller than beta_max and would lie flat on a linear one.
        ax.set_yscale("log")
        ax.plot(gammas, bm, "-", color=_COLORS[0], lw=1.8, label=r"$\beta_{\max}$")
        ax.plot(gammas, am, "--", color=_COLORS[1], lw=1.8, label=r"$\alpha_{\max}$")
        ax.plot(gammas, np.where(zw > 0, zw, np.nan), ":", color=_COLORS[3], lw=2.2,
                label="Z-width (area)")
        empty = np.array([r.empty for r in rows])
        if empty.any():
            ax.fill_between(gammas, 0, 1, where=empty, color="red", alpha=0.15,
                            transform=ax.get_xaxis_transform(), label="no stable region")
        ax.set_xlabel(r"$\gamma = M_w/m$")
        ax.set_ylabel("dimensionless (log scale)")
        _label_log_axis(ax)
        ax.set_title(f"$d = {d}$", fontsize=PANEL_TITLE_SIZE)
        ax.legend(fontsize=LEGEND_SIZE)
        k = int(np.nanargmax(am))
        edge = np.flatnonzero(~empty)[0 if gammas[0] < 0 else -1]
        facts.append(dict(d=d, am=am, bm=bm, zw=zw, edge=edge, empty=empty))
        summary.append(f"d={d}: alpha_max peaks at {am[k]:.4g} (gamma {gammas[k]:.2f}); "
                       f"{'first' if gammas[0] < 0 else 'last'} gamma of the scan with a region "
                       f"{gammas[edge]:.2f}: alpha_max {am[edge]:.3g}, beta_max {bm[edge]:.3g}, "
                       f"Z-width {zw[edge]:.3g}")
    fig.suptitle(suptitle, fontsize=SUPTITLE_SIZE)
    fig.tight_layout()
    return FigureResult(name, title, fig, paper, "; ".join(summary) + "; " + note(facts))


def fig11(n=26):
    """beta_max, alpha_max and Z-width versus gamma < 0, at ``n`` values of gamma."""
    gammas = np.linspace(-1.0, 0.0, n)
    return _fig_limits("fig11_limits_negative_mass", "Fig. 11: limits versus gamma <= 0",
                       r"Fig. 11: limits versus $\gamma \leq 0$", gammas,
                       "beta_max, alpha_max and Z-width decrease continuously as gamma goes from 0 "
                       "to -1, where all are zero.",
                       lambda facts: (
                           ("all three decrease towards gamma = -1" if all(
                               np.all(np.diff(f["am"]) > 0) and np.all(np.diff(f["zw"]) > 0)
                               for f in facts) else "they do not all decrease monotonically")
                           + ("; at gamma = -1 they are tiny, not zero: a region exists while "
                              "gamma > -1 - (d + 1) delta (REPORT.md, claim:no_region_gamma_le_-1)"
                              if all(f["zw"][0] > 0 for f in facts) else "; at gamma = -1 they are 0")
                           + "."))


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
                           + (" to zero" if f["empty"][-1] else "")
                           + ("; where the region ends beta_max and alpha_max are still nonzero"
                              if f["bm"][f["edge"]] > 0 and f["am"][f["edge"]] > 0 else "")
                           for f in facts) + ".")


#: Every figure, in the paper's order.
FIGURES = (fig3, fig4, fig5, fig6, fig7, fig8, fig10, fig11, fig12)


def make_figures(out_dir, progress=None):
    """Draw every figure into ``out_dir`` as PNG; return the FigureResults.

    ``progress(name, seconds)`` is called after each figure.
    """
    from .proof.derive import write_bytes

    plt = pyplot()
    out = pathlib.Path(out_dir)
    results = []
    for make in FIGURES:
        start = time.perf_counter()
        result = make()
        buf = io.BytesIO()
        result.figure.savefig(buf, format="png", metadata={"Software": None})
        plt.close(result.figure)
        write_bytes(out / f"{result.name}.png", buf.getvalue())
        result.figure = None
        results.append(result)
        if progress is not None:
            progress(result.name, time.perf_counter() - start)
    return results
