"""Which side of a boundary arc is stable: the paper's curves against the root count.

The paper traces the arc ``(beta(theta), alpha(theta))``, ``0 < theta <=
theta_max``, from ``(-delta, 0)`` back to ``alpha = 0`` and decides "by
simulation" that the region beneath a *right-sided* arc is stable and the
region beneath a *left-sided* arc unstable (lines 287-300 and 325-341; a proof
is left to future work).  Here the question is settled by counting the roots
of the characteristic polynomial outside the unit circle, with the library's
one home for it: :class:`symstab.numeric.paper.region.StabilityRegion` (the number
of roots outside changes only where a root crosses the circle -- on the arc,
on ``alpha = 0`` (``z = 1``) or on the line ``alpha + 2 beta = c``
(``z = -1``, :func:`symstab.numeric.paper.curves.minus_one_line`) -- and is
counted along each line from its closed-form ends) and
:func:`symstab.numeric.paper.stability.unstable_root_counts` (certified) at the
probes.

What is this module's own is the paper's side of the comparison:

* :func:`initial_direction` / :func:`side` -- the direction in which the arc
  leaves ``(-delta, 0)``, the paper's "right-sided" or "left-sided", from the
  small-theta limits (:func:`symstab.symbolic.small_theta.small_theta_limits`)
  at 30 digits;
* :func:`classify` -- for one curve: its side, the stable region's extent
  (:meth:`symstab.numeric.paper.region.StabilityRegion.limits`), and whether the
  stable set lies beneath the arc, i.e. inside the closed curve arc +
  ``alpha = 0`` (even-odd rule on the arc's samples from
  :func:`symstab.numeric.paper.region.boundary_curve`), as the paper reads its
  figures;
* :data:`FIGURE_CASES` -- what the paper says about each curve of Figs. 6 and
  8 -- and :data:`LIMIT_CASES` -- its limits ``gamma <= -1`` (no stable
  region) and ``gamma = 2`` (largest renderable virtual mass at ``d = 0``) --
  with :func:`compare`.

Run ``python -m paper_checks.regions`` for the comparison table.
"""

import dataclasses
import functools
import math
import time

import mpmath
import numpy as np
import sympy as sp

from symstab._validate import check_count, check_loop, check_real
from symstab.numeric.paper.curves import arc_end_angle, minus_one_line
from symstab.numeric.paper.device import PAPER_DEVICE
from symstab.numeric.paper.region import StabilityRegion, boundary_curve
from symstab.numeric.paper.stability import unstable_root_counts
from symstab.symbolic import model
from symstab.symbolic.loop import characteristic_polynomial
from symstab.symbolic.small_theta import small_theta_limits

__all__ = [
    "InitialDirection", "initial_direction", "side",
    "Probe", "RegionResult", "classify",
    "PaperClaim", "FIGURE_CASES", "LIMIT_CASES", "compare", "format_table",
    "closed_polygon", "inside_even_odd",
    "coefficients_at", "unstable_root_count", "stable_alpha_intervals",
]

_DPS = 30


# --------------------------------------------------------------------------
# Where the arc starts and which way it leaves


@functools.lru_cache(maxsize=None)
def _start_functions():
    lim = small_theta_limits()
    sub = {model.Gamma: sp.exp(model.delta)}
    exprs = [e.subs(sub) for e in (lim.alpha_limit, lim.beta_limit,
                                   lim.alpha_theta2, lim.beta_theta2)]
    return sp.lambdify((model.gamma, model.d, model.delta), exprs, modules="mpmath")


@dataclasses.dataclass(frozen=True)
class InitialDirection:
    """How the arc leaves its starting point.

    Near theta = 0, ``beta = beta_start + beta_theta2 theta**2`` and
    ``alpha = alpha_theta2 theta**2`` (:mod:`symstab.symbolic.small_theta`).

    Attributes
    ----------
    side : {"right", "left", "straight"}
        Sign of ``beta_theta2``; "straight" when it vanishes (``abs <=
        straight_tol``), i.e. the arc leaves vertically.
    alpha_theta2, beta_theta2 : float
        The theta**2 coefficients; ``alpha_theta2 < 0`` means the arc enters
        ``alpha < 0`` and encloses nothing above the real axis.
    alpha_start, beta_start : float
        The starting point, the theta -> 0 limits (``0`` and ``-delta``).
    """

    side: str
    alpha_theta2: float
    beta_theta2: float
    alpha_start: float
    beta_start: float


def initial_direction(gamma, d, delta=PAPER_DEVICE.delta, *, straight_tol=1e-12):
    """Evaluate the arc's small-theta limits at a parameter point.

    Parameters
    ----------
    gamma : float
        Virtual mass ratio ``M_w / m``.
    d : int
        Loop delay in samples, ``d >= 0``.
    delta : float, optional
        ``b T / m > 0``; the paper's device (:data:`symstab.PAPER_DEVICE`) by
        default.
    straight_tol : float, optional
        ``|beta_theta2|`` at or below this is reported as "straight".

    Returns
    -------
    InitialDirection

    Raises
    ------
    TypeError, ValueError
        If a parameter has the wrong kind or is out of range.

    Examples
    --------
    >>> initial_direction(0.0, 0).side
    'right'
    """
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    with mpmath.workdps(_DPS):
        a0, b0, a2, b2 = (float(v) for v in _start_functions()(gamma, d, delta))
    if abs(b2) <= straight_tol:
        direction = "straight"
    else:
        direction = "right" if b2 > 0 else "left"
    return InitialDirection(direction, a2, b2, a0, b0)


def side(gamma, d, delta=PAPER_DEVICE.delta):
    """Return "right", "left" or "straight": the arc's initial direction.

    The sign of ``beta_theta2`` in ``beta = -delta + beta_theta2 theta**2``
    (:func:`symstab.symbolic.small_theta.small_theta_limits`); see :func:`initial_direction`
    for the coefficients themselves.

    Parameters
    ----------
    gamma : float
        Virtual mass ratio.
    d : int
        Delay in samples.
    delta : float, optional
        ``b T / m``.

    Returns
    -------
    str

    Examples
    --------
    >>> side(0.0, 0)
    'right'
    """
    return initial_direction(gamma, d, delta).side


# --------------------------------------------------------------------------
# The closed curve the arc forms with alpha = 0


def closed_polygon(betas, alphas):
    """The arc followed by the alpha = 0 segment back to its start, as a closed polygon.

    Parameters
    ----------
    betas, alphas : ndarray
        The arc's points, in order.

    Returns
    -------
    ndarray of shape (n + 2, 2)
        ``(beta, alpha)`` vertices: the arc, then ``(betas[-1], 0)`` and ``(betas[0], 0)``.
    """
    return np.vstack([np.column_stack([betas, alphas]), [[betas[-1], 0.0], [betas[0], 0.0]]])


def inside_even_odd(points, polygon):
    """Which points are inside ``polygon`` by the even-odd rule (the arc may cross itself).

    Parameters
    ----------
    points : ndarray of shape (k, 2)
    polygon : ndarray of shape (n, 2)
        Vertices of a closed polygon (:func:`closed_polygon`).

    Returns
    -------
    ndarray of bool, shape (k,)
    """
    x, y = points[:, 0][:, None], points[:, 1][:, None]
    x0, y0 = polygon[:-1, 0], polygon[:-1, 1]
    x1, y1 = polygon[1:, 0], polygon[1:, 1]
    straddles = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (np.count_nonzero(straddles & (x < x_cross), axis=1) % 2) == 1


def _distance_to_polyline(points, polygon):
    p = points[:, None, :]
    a, b = polygon[:-1][None], polygon[1:][None]
    ab = b - a
    length2 = np.sum(ab * ab, axis=2)
    t = np.clip(np.sum((p - a) * ab, axis=2) / np.where(length2 > 0, length2, 1.0), 0, 1)
    nearest = a + t[..., None] * ab
    return np.min(np.linalg.norm(p - nearest, axis=2), axis=1)


def _crossings(polygon, beta):
    """Alpha values where the closed polygon meets the vertical ``beta``."""
    b0, a0 = polygon[:-1, 0], polygon[:-1, 1]
    b1, a1 = polygon[1:, 0], polygon[1:, 1]
    hit = (b0 > beta) != (b1 > beta)
    t = (beta - b0[hit]) / (b1[hit] - b0[hit])
    return np.sort(a0[hit] + t * (a1[hit] - a0[hit]))


# --------------------------------------------------------------------------
# The classification


@dataclasses.dataclass(frozen=True)
class Probe:
    """Unstable-root count at one representative point.

    ``unstable_roots`` is ``None`` when a root is marginal (on the unit
    circle to within rounding, :func:`symstab.numeric.paper.stability.unstable_root_counts`).
    """

    name: str
    beta: float
    alpha: float
    unstable_roots: object


@dataclasses.dataclass(frozen=True)
class RegionResult:
    """Where the stable points are, relative to the boundary arc.

    Attributes
    ----------
    gamma, d, delta : float, int, float
        The parameter point.
    start : InitialDirection
        ``side`` (initial direction) and the theta**2 coefficients.
    theta_max : float
        End of the arc.
    arc_beta_end : float
        beta where the arc returns to ``alpha = 0``.
    end_side : {"right", "left"}
        Where the arc ends relative to its start ``beta = -delta``.
    arc_alpha_max, arc_beta_at_alpha_max : float
        Highest sample of the arc.
    arc_beta_range : (float, float)
        Smallest and largest beta on the arc.
    minus_one_line : float
        ``c`` of the line ``alpha + 2 beta = c`` on which ``z = -1`` is a
        root (:func:`symstab.numeric.paper.curves.minus_one_line`).
    limits : symstab.numeric.paper.region.Limits
        The stable region's extent, from the root count.
    stable_exists : bool
        Some point is stable.
    region_alpha_max, region_beta_at_alpha_max : float
        Highest stable alpha (the supremum) and its beta; ``nan`` without
        stable points.
    region_beta_min, region_beta_max : float
        Extent of the stable region in beta; ``nan`` without stable points.
    region_area : float
        Area of the stable region (0 without stable points).
    lines : tuple of float
        The vertical lines through the stable region on which its intervals
        were taken (``n_beta`` evenly spaced, and the one through its top).
    inside_arc : bool or None
        Every point of the stable intervals on ``lines`` (their ends and
        three points between) lies inside the closed curve arc + ``alpha =
        0`` (even-odd rule) or within ``tolerance`` of it; ``False`` for an
        unbounded region, ``None`` without stable points.
    outside_max_distance : float
        Largest distance of such a point outside that curve, in units of
        the arc's extent (``beta`` span, ``alpha`` max).
    min_alpha_positive : bool
        Some line has stable points only above ``alpha = 0``: a minimum
        stiffness.
    min_alpha_where : (float, float) or None
        ``(beta, alpha)``: the minimum stiffness on the middle one of the
        lines that need one.
    min_alpha_betas : (float, float) or None
        First and last line that need a minimum stiffness.
    probes : tuple of Probe
        Certified root counts at a point just inside the arc below its top,
        above the top, below ``alpha = 0``, beyond the arc's end, and in the
        middle of the stable set.
    library_check : dict
        Empty, or with ``cross_check``: the vertical through the arc's top
        re-scanned with the 30-digit reference
        :func:`stable_alpha_intervals`, both
        interval lists (``reference``, ``counted``) and ``agrees``.
    seconds : float
        Wall time of the call.
    """

    gamma: float
    d: int
    delta: float
    start: InitialDirection
    theta_max: float
    arc_beta_end: float
    end_side: str
    arc_alpha_max: float
    arc_beta_at_alpha_max: float
    arc_beta_range: tuple
    minus_one_line: float
    limits: object
    stable_exists: bool
    region_alpha_max: float
    region_beta_at_alpha_max: float
    region_beta_min: float
    region_beta_max: float
    region_area: float
    lines: tuple
    inside_arc: object
    outside_max_distance: float
    min_alpha_positive: bool
    min_alpha_where: object
    min_alpha_betas: object
    probes: tuple
    library_check: dict
    seconds: float

    @property
    def side(self):
        """The arc's initial direction (see :func:`side`)."""
        return self.start.side

    def evidence(self):
        """One or two lines summarising the result."""
        head = (f"gamma={self.gamma:g}, d={self.d}: leaves (-delta, 0) to the {self.side} "
                f"(beta_theta2={self.start.beta_theta2:+.4g}, "
                f"alpha_theta2={self.start.alpha_theta2:+.4g}), "
                f"ends at beta={self.arc_beta_end:.4g} ({self.end_side} of start), "
                f"arc top alpha={self.arc_alpha_max:.4g}.")
        if not self.stable_exists:
            body = f"No stable point ({self.limits.message})"
        else:
            body = (f"Stable region: alpha max {self.region_alpha_max:.4g} at beta "
                    f"{self.region_beta_at_alpha_max:.4g}, beta in [{self.region_beta_min:.4g}, "
                    f"{self.region_beta_max:.4g}], area {self.region_area:.4g}, "
                    f"inside arc: {self.inside_arc}")
            if self.min_alpha_positive:
                body += (f", minimum stiffness for beta in [{self.min_alpha_betas[0]:.4g}, "
                         f"{self.min_alpha_betas[1]:.4g}] (alpha > "
                         f"{self.min_alpha_where[1]:.4g} at beta={self.min_alpha_where[0]:.4g})")
        counts = ", ".join(f"{p.name} {p.unstable_roots}" for p in self.probes)
        return f"{head}\n{body}; roots outside |z|=1: {counts}."


def classify(gamma, d, delta=PAPER_DEVICE.delta, *, n_beta=41, arc_points=None,
             tolerance=2e-3, cross_check=False):
    """Locate the stable region around the boundary arc by counting roots.

    Parameters
    ----------
    gamma : float
        Virtual mass ratio ``M_w / m``.
    d : int
        Loop delay in samples, ``d >= 0``.
    delta : float, optional
        ``b T / m > 0``; the paper's device (:data:`symstab.PAPER_DEVICE`) by
        default.
    n_beta : int, optional
        Vertical lines, evenly spaced inside the stable region's beta range,
        whose stable intervals are tested against the arc; the line through
        the region's top is added.
    arc_points : int, optional
        Steps of theta between the arc's samples
        (:func:`symstab.numeric.paper.region.boundary_curve`, ``arc_points + 1``
        samples from theta = 0 to theta_max); by default ``200 + 20 d
        theta_max``.
    tolerance : float, optional
        Stable points outside the closed curve but within this distance of
        it (in units of the arc's extent) still count as inside: the
        polyline through the arc's samples cuts corners, and the ends of the
        stable intervals lie on the arc itself.
    cross_check : bool, optional
        Re-scan the vertical through the arc's top with the 30-digit
        reference :func:`stable_alpha_intervals`
        (about 0.2 s) and compare.

    Returns
    -------
    RegionResult

    Raises
    ------
    TypeError, ValueError
        If a parameter has the wrong kind or is out of range (``delta``
        must be positive: the arc's start direction is evaluated from the
        derivation's forms, which carry a factor ``delta**2``).
    ValueError
        If :func:`symstab.numeric.paper.curves.arc_end_angle` returns nan: no arc
        enters ``alpha > 0`` (``alpha_theta2 <= 0``), or the arc is too short
        for its grid.

    Examples
    --------
    >>> r = classify(0.0, 0)
    >>> r.stable_exists, r.inside_arc, r.min_alpha_positive
    (True, True, False)
    """
    started = time.perf_counter()
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    n_beta = check_count("n_beta", n_beta, 3)
    tolerance = check_real("tolerance", tolerance, low=0.0)
    start = initial_direction(gamma, d, delta)
    t_end = arc_end_angle(gamma=gamma, d=d, delta=delta)
    if not np.isfinite(t_end):
        why = ("theta_max found no arc although alpha_theta2 > 0: the arc is shorter than "
               "its first grid step" if start.alpha_theta2 > 0 else "alpha_theta2 <= 0")
        raise ValueError(f"no boundary arc to classify at gamma={gamma}, d={d}, delta={delta}: "
                         f"{why} (alpha_theta2={start.alpha_theta2:.4g})")
    n_arc = check_count("arc_points", arc_points, 3) if arc_points is not None \
        else int(200 + 20 * d * t_end)
    arc = boundary_curve(gamma=gamma, d=d, delta=delta, n=n_arc + 1, segments=False)
    arc_b, arc_a = arc.beta, arc.alpha
    polygon = closed_polygon(arc_b, arc_a)
    top = int(np.argmax(arc_a))
    alpha_top, beta_top = float(arc_a[top]), float(arc_b[top])
    b_lo, b_hi = float(arc_b.min()), float(arc_b.max())
    width = b_hi - b_lo

    region = StabilityRegion(gamma=gamma, d=d, delta=delta)
    lim = region.limits()
    stable_exists = not lim.empty
    bounded = stable_exists and all(math.isfinite(v) for v in
                                    (lim.alpha_max, lim.beta_left, lim.beta_right))
    lines, runs = np.empty(0), []
    if bounded:
        lines = np.linspace(lim.beta_left, lim.beta_right, n_beta + 2)[1:-1]
        if math.isfinite(lim.beta_at_alpha_max):
            lines = np.union1d(lines, [lim.beta_at_alpha_max])
        runs = region.alpha_intervals_on(lines)

    inside_arc, outside = (None, 0.0) if not stable_exists else (False, math.inf)
    points = np.array([(b, a) for b, r in zip(lines, runs, strict=True) for lo, hi in r
                       for a in np.linspace(lo, hi, 5)]).reshape(-1, 2)
    if len(points):
        inside = inside_even_odd(points, polygon)
        outside = 0.0
        if not np.all(inside):
            scale = np.array([max(width, np.finfo(float).tiny), alpha_top])
            outside = float(_distance_to_polyline(points[~inside] / scale, polygon / scale).max())
        inside_arc = outside <= tolerance

    # On alpha = 0 a root sits at z = 1: the counted intervals that start
    # there start at exactly 0, so any positive start is a minimum stiffness.
    raised = [(float(b), r[0][0]) for b, r in zip(lines, runs, strict=True) if r and r[0][0] > 0.0]
    min_alpha_where = raised[len(raised) // 2] if raised else None
    min_alpha_betas = (raised[0][0], raised[-1][0]) if raised else None

    stable_point = None
    meeting = [(b, r) for b, r in zip(lines, runs, strict=True) if r]
    if meeting:
        b, r = meeting[len(meeting) // 2]
        lo, hi = r[len(r) // 2]
        stable_point = (float(b), 0.5 * (lo + hi))
    probes = _probes(gamma, d, delta, polygon, beta_top, alpha_top, arc_b[-1], width, stable_point)

    library_check = {}
    if cross_check:
        window = (-0.2 * alpha_top, 1.2 * alpha_top)
        n_alpha = 201
        reference = stable_alpha_intervals(beta=beta_top, gamma=gamma, d=d, delta=delta,
                                           alpha_low=window[0], alpha_high=window[1],
                                           n=n_alpha, xtol=1e-7 * (window[1] - window[0]))
        counted = [(max(lo, window[0]), min(hi, window[1]))
                   for lo, hi in region.alpha_intervals(beta_top)
                   if hi > window[0] and lo < window[1]]
        library_check = dict(beta=beta_top, reference=reference, counted=counted,
                             agrees=_same_intervals(reference, counted,
                                                    (window[1] - window[0]) / (n_alpha - 1),
                                                    1e-5 * (window[1] - window[0])))

    nan = float("nan")
    return RegionResult(
        gamma=gamma, d=d, delta=delta, start=start, theta_max=float(arc.theta_max),
        arc_beta_end=float(arc_b[-1]),
        end_side="right" if arc_b[-1] > start.beta_start else "left",
        arc_alpha_max=alpha_top, arc_beta_at_alpha_max=beta_top,
        arc_beta_range=(b_lo, b_hi),
        minus_one_line=minus_one_line(gamma=gamma, d=d, delta=delta),
        limits=lim, stable_exists=stable_exists,
        region_alpha_max=nan if lim.empty else float(lim.alpha_max),
        region_beta_at_alpha_max=nan if lim.empty else float(lim.beta_at_alpha_max),
        region_beta_min=nan if lim.empty else float(lim.beta_left),
        region_beta_max=nan if lim.empty else float(lim.beta_right),
        region_area=float(lim.z_width), lines=tuple(float(b) for b in lines),
        inside_arc=inside_arc, outside_max_distance=outside,
        min_alpha_positive=bool(raised), min_alpha_where=min_alpha_where,
        min_alpha_betas=min_alpha_betas,
        probes=probes, library_check=library_check,
        seconds=time.perf_counter() - started,
    )


def _same_intervals(reference, counted, grid_step, tol):
    """Do the reference's intervals match the counted ones (ignoring those too thin for its grid)?

    The reference samples a grid of step ``grid_step`` and bisects each
    change of stability on rounded roots; ``tol`` allows for that.
    """
    visible = [iv for iv in counted if iv[1] - iv[0] > 2 * grid_step]

    def matched(iv, others):
        return any(abs(iv[0] - o[0]) <= tol and abs(iv[1] - o[1]) <= tol for o in others)

    return all(matched(iv, counted) for iv in reference) and all(matched(iv, reference) for iv in visible)


def _probes(gamma, d, delta, polygon, beta_top, alpha_top, beta_end, width, stable_point):
    """Certified root counts at one point of each region the comparison distinguishes."""
    crossings = _crossings(polygon, beta_top)
    # Even-odd: [x0, x1], [x2, x3], ... are inside; take the topmost.
    inside_alpha = (0.5 * (crossings[-2] + crossings[-1]) if len(crossings) >= 2
                    else 0.5 * alpha_top)
    points = [("inside arc", beta_top, inside_alpha),
              ("above arc top", beta_top, 1.1 * alpha_top),
              ("below alpha=0", beta_top, -0.1 * alpha_top),
              ("beyond arc end", beta_end + 0.1 * width * np.sign(beta_end - polygon[0, 0]),
               0.05 * alpha_top)]
    if stable_point is not None:
        points.append(("stable point", *stable_point))
    counts = np.atleast_1d(unstable_root_counts(
        alpha=np.array([float(a) for _, _, a in points]),
        beta=np.array([float(b) for _, b, _ in points]), gamma=gamma, d=d, delta=delta))
    return tuple(Probe(name, float(b), float(a), None if n < 0 else int(n))
                 for (name, b, a), n in zip(points, counts, strict=True))


# --------------------------------------------------------------------------
# What the paper says


@dataclasses.dataclass(frozen=True)
class PaperClaim:
    """One curve of the paper and what the paper says about it.

    Attributes
    ----------
    figure : str
        Figure and panel, or "text".
    gamma : float
    d : int
    claim : {"stable", "unstable", "boundary"}
        "boundary" is the paper's 'B': the region degenerates to a line.
    claimed_side : {"right", "left", "straight"} or None
        The side the paper gives the curve, if it gives one.
    lines : str
        Line numbers in ``000_6344edfcd45519c7.txt``.
    quote : str
    """

    figure: str
    gamma: float
    d: int
    claim: str
    claimed_side: object
    lines: str
    quote: str


_FIG6_QUOTE = ("the simulation results align with the theoretical predictions for both small "
               "and large time delays (d) and negative values of the virtual mass")
_FIG8_QUOTES = {
    "a": "for gamma < 2, all stability boundaries determined by (7) form right-sided curves, "
         "indicating stable behavior",
    "aB": "In the case of gamma = 2, the HD lies on the boundary of stability, with the curve "
          "being neither right-sided nor left-sided",
    "aU": "For gamma > 2, the stability boundaries become left-sided, indicating unstable "
          "behavior ... no stable region is observed",
    "bU": "the cases of gamma = 2 ... and gamma = 1.5 ... are now left-sided curves and, "
          "therefore, unstable",
    "bS": "All other cases are right-sided and, therefore, stable (read literally, this "
          "includes gamma = 2.2)",
    "cdS": "in the case of gamma = [0, 0.5, 1], the stability boundaries determined by (7) "
           "remain right-sided and, therefore, stable",
    "cdU": "All other cases remain left-sided, indicating instability in the HD",
}

#: Fig. 8 as the text describes it: {(d, gamma): (claim, side, lines, quote key)}.
_FIG8 = {}
for _g in (0.0, 0.5, 1.0, 1.5):
    _FIG8[(0, _g)] = ("stable", "right", "325", "a")
_FIG8[(0, 2.0)] = ("boundary", "straight", "325-327", "aB")
_FIG8[(0, 2.2)] = ("unstable", "left", "327", "aU")
for _g in (0.0, 0.5, 1.0, 2.2):
    _FIG8[(1, _g)] = ("stable", "right", "331", "bS")
for _g in (1.5, 2.0):
    _FIG8[(1, _g)] = ("unstable", "left", "331", "bU")
for _d in (5, 10):
    for _g in (0.0, 0.5, 1.0):
        _FIG8[(_d, _g)] = ("stable", "right", "333", "cdS")
    for _g in (1.5, 2.0, 2.2):
        _FIG8[(_d, _g)] = ("unstable", "left", "333", "cdU")

del _g, _d

_PANELS = {0: "(a)", 1: "(b)", 5: "(c)", 10: "(d)"}

#: The curves of Figs. 6 and 8 with the paper's verdict on each.
FIGURE_CASES = tuple(
    [PaperClaim(f"6{_PANELS[d]}", g, d, "stable", None, "264-266", _FIG6_QUOTE)
     for d in (0, 1, 5, 10) for g in (0.0, -0.25, -0.5, -0.75)]
    + [PaperClaim(f"8{_PANELS[d]}", g, d, claim, claimed_side, lines, _FIG8_QUOTES[key])
       for (d, g), (claim, claimed_side, lines, key) in _FIG8.items()]
)

#: The limits the paper states in the text: no stable region for gamma <= -1,
#: and gamma = 2 the largest renderable virtual mass without delay.
LIMIT_CASES = tuple(
    [PaperClaim("text", g, d, "unstable" if g <= -1 else "stable", None, "266",
                "when gamma <= -1, the stability region vanishes entirely")
     for d in (0, 10) for g in (-0.999, -1.0, -1.001)]
    + [PaperClaim("text/Fig. 7", 1.99, 0, "stable", "right", "287-291",
                  "for gamma < 2 ... right-sided curves ... regions beneath ... are stable"),
       PaperClaim("text/Fig. 7", 2.0, 0, "boundary", "straight", "296-298",
                  "At gamma = 2, the stability curve forms a straight line ... the boundary"),
       PaperClaim("text/Fig. 7", 2.01, 0, "unstable", "left", "293-296",
                  "For gamma > 2 ... left-sided curves ... regions beneath ... are unstable")]
)


def compare(claim, result):
    """Does the root count agree with the paper's verdict?

    Parameters
    ----------
    claim : PaperClaim
    result : RegionResult

    Returns
    -------
    bool or None
        For "stable"/"unstable": whether a stable point exists / does not.
        For "boundary" (a region of zero area): ``True`` when no point is
        stable, ``None`` when one is (the region then has an area, see
        ``region_area``, however small: not the paper's line, but not a
        plain contradiction either).
    """
    if claim.claim == "stable":
        return result.stable_exists
    if claim.claim == "unstable":
        return not result.stable_exists
    return True if not result.stable_exists else None


def format_table(rows):
    """Plain-text table of ``[(claim, result)]`` (result may be None if no arc)."""
    header = (f"{'fig':<12}{'gamma':>7}{'d':>4} {'side':<6}{'end':<6}{'a2':>9} {'stable':<7}"
              f"{'alpha_max':>10}{'at beta':>9} {'inside':<7}{'kmin':<6}{'paper':<10}"
              f"{'p.side':<9}{'agree':<6}{'s':>5}")
    lines = [header, "-" * len(header)]
    for claim, result in rows:
        if result is None:
            lines.append(f"{claim.figure:<12}{claim.gamma:>7g}{claim.d:>4} no arc "
                         f"{'':<42}{claim.claim:<10}{str(claim.claimed_side):<9}"
                         f"{str(claim.claim != 'stable'):<6}")
            continue
        agree = compare(claim, result)
        lines.append(
            f"{claim.figure:<12}{claim.gamma:>7g}{claim.d:>4} {result.side:<6}"
            f"{result.end_side:<6}{result.start.alpha_theta2:>9.3g} "
            f"{str(result.stable_exists):<7}{result.region_alpha_max:>10.4g}"
            f"{result.region_beta_at_alpha_max:>9.3g} {str(result.inside_arc):<7}"
            f"{str(result.min_alpha_positive):<6}{claim.claim:<10}"
            f"{str(claim.claimed_side):<9}{str(agree):<6}{result.seconds:>5.1f}")
    return "\n".join(lines)


def _classify_or_none(point):
    try:
        return classify(*point)
    except ValueError:
        return None


# --------------------------------------------------------------------------
# The audit's reference per point: symstab's derivation at 30 digits and
# numpy's roots (slow; independent of the generated kernels and of the
# root engine it checks)


def coefficients_at(*, alpha, beta, gamma, d, delta):
    """Coefficients of chi(z), highest power first, as floats (30-digit evaluation)."""
    return characteristic_polynomial().numeric_coeffs(
        alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)


def unstable_root_count(*, alpha, beta, gamma, d, delta, marginal_tol=1e-12):
    """Number of roots with modulus > 1, or ``None`` when one is marginal."""
    roots = np.roots(coefficients_at(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    mod = np.abs(roots)
    if np.any(np.abs(mod - 1.0) <= marginal_tol):
        return None
    return int(np.count_nonzero(mod > 1.0))


def stable_alpha_intervals(*, beta, gamma, d, delta, alpha_low=-1.0, alpha_high=6.0,
                           n=600, xtol=1e-10):
    """The stable alpha intervals at fixed beta, by a scan and bisection.

    ``alpha`` is scanned on ``n`` points of ``[alpha_low, alpha_high]``;
    each change of stability is refined by bisection on the spectral radius
    (roots of the 30-digit coefficients) to ``xtol``.  It is slow and
    independent of the generated kernels;
    :meth:`symstab.StabilityRegion.alpha_intervals` finds the same intervals
    with the line engine, fast and without a scan.

    Returns
    -------
    list of (float, float)
        The stable intervals, in increasing order; empty when none.
    """
    def rho(a):
        # The 30-digit coefficients and numpy's roots, not the generated
        # kernels: the audit uses this as a reference independent of them.
        coeffs = coefficients_at(alpha=float(a), beta=beta, gamma=gamma, d=d, delta=delta)
        return float(np.max(np.abs(np.roots(coeffs)))) - 1.0

    grid = np.linspace(alpha_low, alpha_high, n)
    stable = [rho(a) < 0 for a in grid]
    edges = []
    for k in range(1, n):
        if stable[k] != stable[k - 1]:
            lo, hi = grid[k - 1], grid[k]
            while hi - lo > xtol:
                mid = 0.5 * (lo + hi)
                if (rho(mid) < 0) == stable[k - 1]:
                    lo = mid
                else:
                    hi = mid
            edges.append(0.5 * (lo + hi))
    intervals = []
    start = grid[0] if stable[0] else None
    for edge in edges:
        if start is None:
            start = edge
        else:
            intervals.append((float(start), float(edge)))
            start = None
    if start is not None:
        intervals.append((float(start), float(grid[-1])))
    return intervals


def main(processes=2):
    """Classify every case, print the table and each disagreement's evidence."""
    import multiprocessing

    claims = FIGURE_CASES + LIMIT_CASES
    unique = list(dict.fromkeys((c.gamma, c.d) for c in claims))
    started = time.perf_counter()
    with multiprocessing.Pool(processes) as pool:
        results = dict(zip(unique, pool.map(_classify_or_none, unique), strict=True))
    rows = [(c, results[(c.gamma, c.d)]) for c in claims]
    print(format_table(rows))
    print(f"\n{len(unique)} parameter points in {time.perf_counter() - started:.1f} s")
    for claim, result in rows:
        if result is not None and compare(claim, result) is not True:
            print(f"\n[{claim.figure} lines {claim.lines}] paper: {claim.claim}\n"
                  + result.evidence())


if __name__ == "__main__":
    main()
