"""Which side of a boundary arc is stable, decided by counting roots.

The paper traces the arc ``(beta(theta), alpha(theta))``, ``0 < theta <=
theta_max``, from ``(-delta, 0)`` back to ``alpha = 0`` and decides "by
simulation" that the region beneath a *right-sided* arc is stable and the
region beneath a *left-sided* arc unstable (lines 287-300 and 325-341; a proof
is left to future work).  Here the question is settled by the argument
principle's finite form: a parameter point is stable exactly when every root
of the characteristic polynomial chi(z) lies inside the unit circle, and the
number of roots outside can change only where a root crosses it -- on the arc
(``z = exp(j theta)``), on ``alpha = 0`` (``z = 1``) or on the line
``chi(-1) = 0`` (``z = -1``).

:func:`classify` scans ``beta`` across the arc's range.  At each ``beta`` the
alpha samples are a uniform grid plus the midpoint of every gap between the
places where the arc, ``alpha = 0`` and the ``z = -1`` line cut that vertical,
so each cell the arc cuts out gets at least one sample however thin it is.
Roots come from NumPy's companion-matrix eigenvalues; the coefficients of
chi(z), affine in alpha and beta, are evaluated once per ``(gamma, d)`` at 30
digits from :func:`symstab.symbolic.loop.characteristic_polynomial` (and checked
against :func:`symstab.numeric.stability.coefficients_at`).  Stability changes are
refined by bisection, and one vertical is re-scanned with
:func:`symstab.numeric.stability.stable_alpha_intervals` as a cross-check.

:data:`FIGURE_CASES` transcribes what the paper says about each curve of
Figs. 6 and 8, and :data:`LIMIT_CASES` its limits ``gamma <= -1`` (no stable
region) and ``gamma = 2`` (largest renderable virtual mass at ``d = 0``).
Run ``python -m paper_checks.regions`` for the comparison table.
"""

import dataclasses
import functools
import math
import time

import mpmath
import numpy as np
import sympy as sp

from symstab.symbolic import model
from symstab._validate import check_loop
from symstab.symbolic.boundary import boundary
from symstab.symbolic.small_theta import small_theta_limits
from symstab.symbolic.loop import characteristic_polynomial
from symstab.numeric.stability import coefficients_at, stable_alpha_intervals, unstable_root_count
from symstab.numeric.curves import arc_end_angle

__all__ = [
    "DEFAULT_DELTA", "MARGINAL_TOL",
    "InitialDirection", "initial_direction", "side", "minus_one_line",
    "Probe", "RegionResult", "classify",
    "PaperClaim", "FIGURE_CASES", "LIMIT_CASES", "compare", "format_table",
]

#: ``b T / m`` of the paper's device (m = 0.0128 kg m^2, b = 0.0324 N m s/rad,
#: T = 1 ms), from :func:`symstab.symbolic.model.dimensionless_values`.
DEFAULT_DELTA = model.dimensionless_values(m=0.0128, b=0.0324, T=1e-3)["delta"]

#: A root whose modulus is within this of 1 is marginal: neither stable nor
#: counted as outside.
MARGINAL_TOL = 1e-9

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


def initial_direction(gamma, d, delta=DEFAULT_DELTA, *, straight_tol=1e-12):
    """Evaluate the arc's small-theta limits at a parameter point.

    Parameters
    ----------
    gamma : float
        Virtual mass ratio ``M_w / m``.
    d : int
        Loop delay in samples, ``d >= 0``.
    delta : float, optional
        ``b T / m > 0``; the paper's device by default.
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


def side(gamma, d, delta=DEFAULT_DELTA):
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
# The real-axis crossings


@functools.lru_cache(maxsize=None)
def _minus_one_function(d):
    chi = characteristic_polynomial()
    coeffs = chi.coeffs(d)
    degree = len(coeffs) - 1
    value = sp.expand(sp.Add(*[c * (-1) ** (degree - k) for k, c in enumerate(coeffs)]))
    a = sp.diff(value, model.alpha)
    b = sp.diff(value, model.beta)
    c = value.subs({model.alpha: 0, model.beta: 0})
    if sp.expand(value - a * model.alpha - b * model.beta - c) != 0 or \
            any(e.has(model.alpha, model.beta) for e in (a, b)):
        raise AssertionError(f"chi(-1) is not affine in alpha and beta at d = {d}")
    sub = {model.Gamma: sp.exp(model.delta)}
    return sp.lambdify((model.gamma, model.delta), [e.subs(sub) for e in (a, b, c)],
                       modules="mpmath")


def minus_one_line(gamma, d, delta=DEFAULT_DELTA):
    """The line on which chi(z) has a root at ``z = -1``.

    ``chi(-1) = (-1)**d delayed(-1) + direct(-1)`` is taken from
    :func:`symstab.symbolic.loop.characteristic_polynomial` with ``d`` concrete and
    split into its alpha, beta and constant parts (evaluated at 30 digits).

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
    (a, b, c) : tuple of float
        ``chi(-1) = a alpha + b beta + c``; the line is ``chi(-1) = 0``.  Not
        normalised: its sign tells which side has ``chi(-1) > 0``.

    Examples
    --------
    >>> a, b, c = minus_one_line(0.0, 0)
    >>> round(b / a, 6)
    2.0
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    with mpmath.workdps(_DPS):
        return tuple(float(v) for v in _minus_one_function(d)(gamma, delta))


def _minus_one_alpha(line, beta):
    a, b, c = line
    if a == 0.0:
        return np.full(np.shape(beta), np.nan)
    return -(b * np.asarray(beta) + c) / a


# --------------------------------------------------------------------------
# Fast root counting


@functools.lru_cache(maxsize=None)
def _coefficient_parts_function():
    chi = characteristic_polynomial()
    sub = {model.Gamma: sp.exp(model.delta)}
    delayed = [c.subs(sub) for c in chi.delayed.all_coeffs()]
    direct = chi.direct.all_coeffs()
    const = [c.subs({model.alpha: 0, model.beta: 0}).subs(sub) for c in direct]
    d_alpha = [sp.diff(c, model.alpha).subs(sub) for c in direct]
    d_beta = [sp.diff(c, model.beta).subs(sub) for c in direct]
    if any(e.has(model.alpha, model.beta) for e in d_alpha + d_beta + delayed):
        raise AssertionError("chi(z) is not affine in alpha and beta")
    return sp.lambdify((model.gamma, model.delta), [delayed, const, d_alpha, d_beta],
                       modules="mpmath")


class _AffineCoefficients:
    """chi's coefficients as ``c0 + alpha c_alpha + beta c_beta`` (floats)."""

    def __init__(self, gamma, d, delta):
        with mpmath.workdps(_DPS):
            delayed, const, d_alpha, d_beta = _coefficient_parts_function()(gamma, delta)
        size = d + len(delayed)
        self.c0 = np.zeros(size)
        self.c0[: len(delayed)] += [float(x) for x in delayed]
        self.c0[size - len(const):] += [float(x) for x in const]
        self.c_alpha = np.zeros(size)
        self.c_alpha[size - len(d_alpha):] = [float(x) for x in d_alpha]
        self.c_beta = np.zeros(size)
        self.c_beta[size - len(d_beta):] = [float(x) for x in d_beta]
        self.params = dict(gamma=gamma, d=d, delta=delta)

    def at(self, alpha, beta):
        """Rows of coefficients (highest power first) at points (alpha, beta)."""
        alpha = np.atleast_1d(np.asarray(alpha, dtype=float))[:, None]
        beta = np.atleast_1d(np.asarray(beta, dtype=float))[:, None]
        return self.c0 + alpha * self.c_alpha + beta * self.c_beta

    def check_against_library(self, alpha, beta):
        """Largest relative difference from :func:`coefficients_at`."""
        ours = self.at(alpha, beta)[0]
        ref = coefficients_at(alpha=alpha, beta=beta, **self.params)
        scale = np.abs(self.c0) + abs(alpha) * np.abs(self.c_alpha) + abs(beta) * np.abs(self.c_beta)
        return float(np.max(np.abs(ours - ref) / np.where(scale > 0, scale, 1.0)))


def _unstable_counts(coeffs, *, marginal_tol=MARGINAL_TOL, chunk=None):
    """Roots outside the unit circle, and whether any root is marginal, per row."""
    n = coeffs.shape[1] - 1
    counts = np.empty(len(coeffs), dtype=int)
    marginal = np.empty(len(coeffs), dtype=bool)
    chunk = chunk or max(64, 2_000_000 // (n * n))
    sub, sup = np.arange(1, n), np.arange(n - 1)
    for start in range(0, len(coeffs), chunk):
        block = coeffs[start:start + chunk]
        companion = np.zeros((len(block), n, n))
        companion[:, 0, :] = -block[:, 1:] / block[:, :1]
        companion[:, sub, sup] = 1.0
        modulus = np.abs(np.linalg.eigvals(companion))
        counts[start:start + chunk] = np.count_nonzero(modulus > 1.0 + marginal_tol, axis=1)
        marginal[start:start + chunk] = np.any(np.abs(modulus - 1.0) <= marginal_tol, axis=1)
    return counts, marginal


def _is_stable(coefficients, alpha, beta):
    counts, marginal = _unstable_counts(coefficients.at(alpha, beta))
    return (counts == 0) & ~marginal


# --------------------------------------------------------------------------
# The arc as a polyline and the closed curve it forms with alpha = 0


@functools.lru_cache(maxsize=None)
def _arc_functions():
    # Common subexpressions (eight sines, the powers of Gamma) are computed
    # once per point: four times faster than the plain form, at more digits.
    bd = boundary()
    return sp.lambdify((model.theta, model.gamma, model.d, model.delta, model.Gamma),
                       [bd.alpha_numerator, bd.beta_numerator, bd.denominator],
                       modules="mpmath", cse=True)


def _arc_polyline(gamma, d, delta, t_end, start, n_points):
    """(beta, alpha) along theta in [0, t_end]; theta = 0 is the start limit.

    The numerators and the denominator are O(theta**3 delta**2) out of terms
    of size 1 near the start (compare :func:`symstab.theta_max.theta_max`):
    the working precision covers that cancellation at the first point, so
    the points are the doubles nearest to the exact ones (checked at 60 more
    digits), except alpha at theta_max, which is 0 to 1e-15.  At a flat 20
    digits they were off by up to 4e-11 (relative).
    """
    f = _arc_functions()
    betas, alphas = [start[1]], [start[0]]
    lost = 3 * math.log10(n_points / t_end) + 2 * max(0.0, -math.log10(delta))
    with mpmath.workdps(20 + int(lost)):
        t_end, delta = mpmath.mpf(t_end), mpmath.mpf(delta)
        gamma_ = mpmath.exp(delta)
        for k in range(1, n_points + 1):
            na, nb, den = f(t_end * k / n_points, gamma, d, delta, gamma_)
            alphas.append(float(na / den))
            betas.append(float(nb / den))
    return np.array(betas), np.array(alphas)


@functools.lru_cache(maxsize=None)
def _curve_functions_numpy():
    bd = boundary()
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    return sp.lambdify(args, [bd.alpha_numerator, bd.beta_numerator, bd.denominator],
                       modules="numpy")


def _continuation(gamma, d, delta, t_end, n_points, limit):
    """(beta, alpha) on the rest of the boundary curve, theta in (t_end, pi).

    Double precision is enough here: these points only place extra alpha
    samples, one in each cell the curve cuts a vertical into.  Points beyond
    ``limit`` (in absolute value) are dropped, which splits the polyline.
    """
    thetas = np.linspace(t_end, np.pi, n_points + 2)[1:-1]
    na, nb, den = _curve_functions_numpy()(thetas, gamma, d, delta, np.exp(delta))
    with np.errstate(divide="ignore", invalid="ignore"):
        alphas, betas = na / den, nb / den
    keep = np.isfinite(alphas) & np.isfinite(betas) & (np.abs(alphas) < limit[1]) \
        & (np.abs(betas) < limit[0])
    return betas, alphas, keep


def _open_crossings(betas, alphas, keep, beta):
    """Alpha values where a polyline (segments with both ends kept) meets ``beta``."""
    valid = keep[:-1] & keep[1:]
    b0, a0, b1, a1 = betas[:-1][valid], alphas[:-1][valid], betas[1:][valid], alphas[1:][valid]
    hit = (b0 > beta) != (b1 > beta)
    t = (beta - b0[hit]) / (b1[hit] - b0[hit])
    return a0[hit] + t * (a1[hit] - a0[hit])


def _closed_polygon(betas, alphas):
    """Arc followed by the alpha = 0 segment back to the start."""
    return np.vstack([np.column_stack([betas, alphas]), [[betas[-1], 0.0], [betas[0], 0.0]]])


def _inside_even_odd(points, polygon):
    """Even-odd point-in-polygon (the arc may cross itself)."""
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

    ``unstable_roots`` is ``None`` when a root is marginal.
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
        End of the arc (``nan`` if no arc enters ``alpha > 0``).
    arc_beta_end : float
        beta where the arc returns to ``alpha = 0``.
    end_side : {"right", "left", "none"}
        Where the arc ends relative to its start ``beta = -delta``.
    arc_alpha_max, arc_beta_at_alpha_max : float
        Highest point of the arc polyline.
    arc_beta_range : (float, float)
        Smallest and largest beta on the arc.
    minus_one_line : (float, float, float)
        ``chi(-1) = a alpha + b beta + c``.
    beta_scan, alpha_scan : (float, float)
        The box that was scanned.
    n_samples, n_stable, n_marginal : int
        Sampled points, of which strictly stable, of which marginal.
    stable_exists : bool
    region_alpha_max, region_beta_at_alpha_max : float
        Highest stable alpha (refined to the stability edge) and its beta.
    region_beta_min, region_beta_max : float
        Extent in beta of the verticals holding a stable point (to within
        ``beta_step``).
    region_area : float
        Area of the stable set, sum of interval lengths times the beta step.
    touches_scan_edge : bool
        A stable interval reaches the edge of the scanned box (the region may
        continue beyond it).
    inside_arc : bool or None
        Every stable sample lies inside the closed curve arc + ``alpha = 0``
        (even-odd rule) or within ``tolerance`` of it; ``None`` without
        stable points.
    outside_max_distance : float
        Largest distance of a stable sample outside that curve, in units of
        the arc's extent (``beta`` span, ``alpha`` max).
    min_alpha_positive : bool
        Some beta has stable points only above ``alpha = 0``: a minimum
        stiffness.
    min_alpha_where : (float, float) or None
        ``(beta, alpha)``: the minimum stiffness on the middle one of the
        verticals that need one.
    min_alpha_betas : (float, float) or None
        First and last vertical that need a minimum stiffness.
    beta_step : float
        Spacing of the uniform verticals: the resolution of the beta extents.
    probes : tuple of Probe
        Root counts from :func:`symstab.numeric.stability.unstable_root_count` at a
        point just inside the arc below its top, above the top, below
        ``alpha = 0``, beyond the arc's end, and inside the stable set.
    library_check : dict
        The vertical through the arc's top re-scanned with
        :func:`symstab.numeric.stability.stable_alpha_intervals`: both interval
        lists and ``agrees``; also ``coefficient_error``, the largest
        relative difference of the fast coefficients from
        :func:`symstab.numeric.stability.coefficients_at`.
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
    minus_one_line: tuple
    beta_scan: tuple
    alpha_scan: tuple
    n_samples: int
    n_stable: int
    n_marginal: int
    stable_exists: bool
    region_alpha_max: float
    region_beta_at_alpha_max: float
    region_beta_min: float
    region_beta_max: float
    region_area: float
    touches_scan_edge: bool
    inside_arc: object
    outside_max_distance: float
    min_alpha_positive: bool
    min_alpha_where: object
    min_alpha_betas: object
    beta_step: float
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
            body = (f"No stable point among {self.n_samples} samples of "
                    f"beta in [{self.beta_scan[0]:.4g}, {self.beta_scan[1]:.4g}], "
                    f"alpha in [{self.alpha_scan[0]:.4g}, {self.alpha_scan[1]:.4g}]")
        else:
            body = (f"Stable: {self.n_stable}/{self.n_samples} samples, alpha max "
                    f"{self.region_alpha_max:.4g} at beta {self.region_beta_at_alpha_max:.4g}, "
                    f"beta in [{self.region_beta_min:.4g}, {self.region_beta_max:.4g}], "
                    f"inside arc: {self.inside_arc}")
            if self.min_alpha_positive:
                body += (f", minimum stiffness for beta in [{self.min_alpha_betas[0]:.4g}, "
                         f"{self.min_alpha_betas[1]:.4g}] (alpha > "
                         f"{self.min_alpha_where[1]:.4g} at beta={self.min_alpha_where[0]:.4g})")
        counts = ", ".join(f"{p.name} {p.unstable_roots}" for p in self.probes)
        return f"{head}\n{body}; roots outside |z|=1: {counts}."


def _scan_vertical(coefficients, beta, grid, breakpoints):
    """Stable alpha intervals on one vertical, with edges refined by bisection."""
    inner = np.sort(breakpoints[(breakpoints > grid[0]) & (breakpoints < grid[-1])])
    cuts = np.concatenate([[grid[0]], inner, [grid[-1]]])
    alphas = np.unique(np.concatenate([grid, 0.5 * (cuts[1:] + cuts[:-1])]))
    counts, marginal = _unstable_counts(coefficients.at(alphas, np.full(len(alphas), beta)))
    stable = (counts == 0) & ~marginal
    return alphas, stable, int(np.count_nonzero(marginal))


def _refine_edges(coefficients, edges, xtol):
    """Bisect ``[(beta, lo, hi, stable_at_lo)]`` until ``hi - lo <= xtol``."""
    if not edges:
        return np.empty(0)
    beta = np.array([e[0] for e in edges])
    lo = np.array([e[1] for e in edges])
    hi = np.array([e[2] for e in edges])
    lo_stable = np.array([e[3] for e in edges])
    steps = int(np.ceil(np.log2(max(np.max(hi - lo), xtol) / xtol)))
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        same = _is_stable(coefficients, mid, beta) == lo_stable
        lo = np.where(same, mid, lo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)


def _intervals(alphas, stable, refined_edges):
    """Turn sampled stability and refined edges into ``[(low, high)]``."""
    out = []
    edge_iter = iter(refined_edges)
    start = alphas[0] if stable[0] else None
    for k in range(1, len(alphas)):
        if stable[k] != stable[k - 1]:
            edge = next(edge_iter)
            if stable[k]:
                start = edge
            else:
                out.append((float(start), float(edge)))
                start = None
    if start is not None:
        out.append((float(start), float(alphas[-1])))
    return out


def classify(gamma, d, delta=DEFAULT_DELTA, *, n_beta=41, n_alpha=201, beta_margin=0.15,
             alpha_range=(-0.2, 1.2), arc_points=None, continuation_points=None,
             rel_xtol=1e-7, tolerance=2e-3, cross_check=True):
    """Locate the stable points around the boundary arc by counting roots.

    Parameters
    ----------
    gamma : float
        Virtual mass ratio ``M_w / m``.
    d : int
        Loop delay in samples, ``d >= 0``.
    delta : float, optional
        ``b T / m > 0``; the paper's device by default.
    n_beta : int, optional
        Uniformly spaced verticals across the arc's beta range widened by
        ``beta_margin`` of its width on each side; the vertical through the
        arc's top is added.
    n_alpha : int, optional
        Uniform alpha samples per vertical, in ``alpha_range`` times the
        arc's top alpha; the midpoints of the cells cut by the boundary
        curve, ``alpha = 0`` and the ``z = -1`` line are added.
    beta_margin : float, optional
        Margin, as a fraction of the arc's beta width.
    alpha_range : (float, float), optional
        Alpha scan range in units of the arc's top alpha.
    arc_points : int, optional
        Points of the arc polyline (30 digits); by default
        ``200 + 20 d theta_max``.
    continuation_points : int, optional
        Points of the rest of the boundary curve, ``theta_max < theta < pi``
        (double precision), whose crossings also add alpha samples; by
        default ``2000 + 200 d``.
    rel_xtol : float, optional
        Bisection tolerance on stability edges, relative to the alpha range.
    tolerance : float, optional
        Stable samples outside the closed curve but within this distance of
        it (in units of the arc's extent) still count as inside: the polyline
        cuts corners.
    cross_check : bool, optional
        Re-scan the vertical through the arc's top with
        :func:`symstab.numeric.stability.stable_alpha_intervals`.

    Returns
    -------
    RegionResult

    Raises
    ------
    TypeError, ValueError
        If a parameter has the wrong kind or is out of range.
    ValueError
        If :func:`symstab.theta_max.theta_max` returns nan: no arc enters
        ``alpha > 0`` (``alpha_theta2 <= 0``), or the arc is too short for
        its grid.

    Examples
    --------
    >>> r = classify(0.0, 0)
    >>> r.stable_exists, r.inside_arc, r.min_alpha_positive
    (True, True, False)
    """
    started = time.perf_counter()
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    for name, value in (("n_beta", n_beta), ("n_alpha", n_alpha)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 3:
            raise ValueError(f"{name} must be an integer >= 3, got {value!r}")
    start = initial_direction(gamma, d, delta)
    # The float arc end, to the last bit (symstab.numeric.curves); the 30-digit
    # theta_max agrees with it to 1e-13 (tests/test_theta_max.py).
    t_end = arc_end_angle(gamma=gamma, d=d, delta=delta)
    if not np.isfinite(t_end):
        why = ("theta_max found no arc although alpha_theta2 > 0: the arc is shorter than "
               "its first grid step" if start.alpha_theta2 > 0 else "alpha_theta2 <= 0")
        raise ValueError(f"no boundary arc to classify at gamma={gamma}, d={d}, delta={delta}: "
                         f"{why} (alpha_theta2={start.alpha_theta2:.4g})")
    n_arc = arc_points or int(200 + 20 * d * t_end)
    arc_b, arc_a = _arc_polyline(gamma, d, delta, t_end,
                                 (start.alpha_start, start.beta_start), n_arc)
    polygon = _closed_polygon(arc_b, arc_a)
    top = int(np.argmax(arc_a))
    alpha_top, beta_top = float(arc_a[top]), float(arc_b[top])
    b_lo, b_hi = float(arc_b.min()), float(arc_b.max())
    width = b_hi - b_lo
    rest = _continuation(gamma, d, delta, t_end, continuation_points or 2000 + 200 * d,
                         (100 * (abs(b_lo) + abs(b_hi)), 100 * alpha_top))
    beta_scan = (b_lo - beta_margin * width, b_hi + beta_margin * width)
    alpha_scan = (alpha_range[0] * alpha_top, alpha_range[1] * alpha_top)
    grid = np.linspace(*alpha_scan, n_alpha)
    xtol = rel_xtol * (alpha_scan[1] - alpha_scan[0])
    line = minus_one_line(gamma, d, delta)
    coefficients = _AffineCoefficients(gamma, d, delta)

    betas_uniform = np.linspace(*beta_scan, n_beta)
    betas = np.unique(np.append(betas_uniform, beta_top))
    verticals, edges = [], []
    n_samples = n_marginal = 0
    for beta in betas:
        breakpoints = np.concatenate([_crossings(polygon, beta), _open_crossings(*rest, beta),
                                      [0.0],
                                      np.atleast_1d(_minus_one_alpha(line, beta))])
        breakpoints = breakpoints[np.isfinite(breakpoints)]
        alphas, stable, marginal = _scan_vertical(coefficients, beta, grid, breakpoints)
        n_samples += len(alphas)
        n_marginal += marginal
        change = np.nonzero(stable[1:] != stable[:-1])[0]
        edges += [(beta, alphas[k], alphas[k + 1], bool(stable[k])) for k in change]
        verticals.append((beta, alphas, stable, len(change)))
    refined = _refine_edges(coefficients, edges, xtol)

    intervals, stable_points, used = {}, [], 0
    for beta, alphas, stable, n_edges in verticals:
        intervals[beta] = _intervals(alphas, stable, refined[used:used + n_edges])
        used += n_edges
        stable_points += [(beta, a) for a in alphas[stable]]
    stable_points = np.array(stable_points).reshape(-1, 2)
    n_stable = len(stable_points)
    stable_exists = n_stable > 0

    region = dict(alpha_max=float("nan"), beta_at=float("nan"), beta_min=float("nan"),
                  beta_max=float("nan"))
    touches = False
    min_alpha_where = min_alpha_betas = None
    area = 0.0
    if stable_exists:
        best = max(((hi, b) for b, ivs in intervals.items() for _, hi in ivs))
        region.update(alpha_max=best[0], beta_at=best[1],
                      beta_min=float(stable_points[:, 0].min()),
                      beta_max=float(stable_points[:, 0].max()))
        step = betas_uniform[1] - betas_uniform[0]
        area = step * sum(hi - lo for b in betas_uniform for lo, hi in intervals[b])
        edge_hits = [b for b, ivs in intervals.items() if ivs and b in (betas[0], betas[-1])]
        touches = bool(edge_hits) or any(lo <= grid[0] or hi >= grid[-1]
                                         for ivs in intervals.values() for lo, hi in ivs)
        raised = [(b, ivs[0][0]) for b, ivs in sorted(intervals.items())
                  if ivs and ivs[0][0] > 100 * xtol]
        if raised:
            min_alpha_where = tuple(float(v) for v in raised[len(raised) // 2])
            min_alpha_betas = (float(raised[0][0]), float(raised[-1][0]))

    inside_arc, outside = None, 0.0
    if stable_exists:
        scale = np.array([max(width, np.finfo(float).tiny), alpha_top])
        inside = _inside_even_odd(stable_points, polygon)
        if np.all(inside):
            inside_arc = True
        else:
            distance = _distance_to_polyline(stable_points[~inside] / scale, polygon / scale)
            outside = float(distance.max())
            inside_arc = outside <= tolerance

    probes = _probes(gamma, d, delta, polygon, beta_top, alpha_top, arc_b[-1], width,
                     stable_points)
    library_check = {"coefficient_error": max(
        coefficients.check_against_library(p.alpha, p.beta) for p in probes)}
    if cross_check:
        library = stable_alpha_intervals(beta=beta_top, gamma=gamma, d=d, delta=delta,
                                         alpha_low=grid[0], alpha_high=grid[-1], n=n_alpha,
                                         xtol=xtol)
        ours = intervals[beta_top]
        library_check.update(beta=beta_top, library=library, scan=ours,
                             agrees=_same_intervals(library, ours, grid[1] - grid[0],
                                                    1e-5 * (grid[-1] - grid[0])))

    return RegionResult(
        gamma=gamma, d=d, delta=delta, start=start, theta_max=float(t_end),
        arc_beta_end=float(arc_b[-1]),
        end_side="right" if arc_b[-1] > start.beta_start else "left",
        arc_alpha_max=alpha_top, arc_beta_at_alpha_max=beta_top,
        arc_beta_range=(b_lo, b_hi), minus_one_line=line,
        beta_scan=beta_scan, alpha_scan=alpha_scan,
        n_samples=n_samples, n_stable=n_stable, n_marginal=n_marginal,
        stable_exists=stable_exists,
        region_alpha_max=region["alpha_max"], region_beta_at_alpha_max=region["beta_at"],
        region_beta_min=region["beta_min"], region_beta_max=region["beta_max"],
        region_area=float(area), touches_scan_edge=touches,
        inside_arc=inside_arc, outside_max_distance=outside,
        min_alpha_positive=min_alpha_where is not None, min_alpha_where=min_alpha_where,
        min_alpha_betas=min_alpha_betas, beta_step=float(betas_uniform[1] - betas_uniform[0]),
        probes=probes, library_check=library_check,
        seconds=time.perf_counter() - started,
    )


def _same_intervals(library, ours, grid_step, tol):
    """Do the library's intervals match ours (ignoring ours too thin for its grid)?

    ``tol`` allows for the marginal band: the library bisects on the
    spectral radius, the scan treats ``|z| = 1 +- MARGINAL_TOL`` as unstable.
    """
    visible = [iv for iv in ours if iv[1] - iv[0] > 2 * grid_step]

    def matched(iv, others):
        return any(abs(iv[0] - o[0]) <= tol and abs(iv[1] - o[1]) <= tol for o in others)

    return all(matched(iv, ours) for iv in library) and all(matched(iv, library) for iv in visible)


def _probes(gamma, d, delta, polygon, beta_top, alpha_top, beta_end, width, stable_points):
    """Root counts at one point of each region the scan distinguishes."""
    crossings = _crossings(polygon, beta_top)
    # Even-odd: [x0, x1], [x2, x3], ... are inside; take the topmost.
    inside_alpha = (0.5 * (crossings[-2] + crossings[-1]) if len(crossings) >= 2
                    else 0.5 * alpha_top)
    points = [("inside arc", beta_top, inside_alpha),
              ("above arc top", beta_top, 1.1 * alpha_top),
              ("below alpha=0", beta_top, -0.1 * alpha_top),
              ("beyond arc end", beta_end + 0.1 * width * np.sign(beta_end - polygon[0, 0]),
               0.05 * alpha_top)]
    if len(stable_points):
        centre = stable_points[len(stable_points) // 2]
        points.append(("stable sample", float(centre[0]), float(centre[1])))
    return tuple(Probe(name, float(b), float(a),
                       unstable_root_count(alpha=float(a), beta=float(b), gamma=gamma, d=d,
                                           delta=delta, marginal_tol=MARGINAL_TOL))
                 for name, b, a in points)


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
        For "stable"/"unstable": whether a stable point was found / not
        found.  For "boundary" (a region of zero area): ``True`` when no
        stable point was found, ``None`` when one was (a positive-area
        region cannot be told from a line by sampling; see ``region_area``).
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


def main(processes=2):
    """Classify every case, print the table and each disagreement's evidence."""
    import multiprocessing

    claims = FIGURE_CASES + LIMIT_CASES
    unique = list(dict.fromkeys((c.gamma, c.d) for c in claims))
    started = time.perf_counter()
    with multiprocessing.Pool(processes) as pool:
        results = dict(zip(unique, pool.map(_classify_or_none, unique)))
    rows = [(c, results[(c.gamma, c.d)]) for c in claims]
    print(format_table(rows))
    print(f"\n{len(unique)} parameter points in {time.perf_counter() - started:.1f} s")
    for claim, result in rows:
        if result is not None and compare(claim, result) is not True:
            print(f"\n[{claim.figure} lines {claim.lines}] paper: {claim.claim}\n"
                  + result.evidence())


if __name__ == "__main__":
    main()
