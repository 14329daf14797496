"""The paper's stable region in Table I's (beta, alpha) plane, and what it lets a user render.

The paper's loop is :data:`~symstab.numeric.paper.paper_loop.PAPER_LOOP`; at the
dimensionless point ``(gamma, d, delta)`` it is that loop with ``m = T =
1`` (:func:`~symstab.numeric.paper.paper_loop.paper_point`), whose plane ``(B,
K)`` is the paper's ``(beta, alpha)``.  Everything here is the one engine
of every loop in the paper's names:

* :class:`StabilityRegion` -- the stable intervals on any vertical or
  horizontal line (:meth:`symstab.Loop.stable_intervals`, the one line
  engine :func:`symstab.numeric.engine.intervals.family_intervals`), the complete
  D-decomposition of a window, and the pieces of ``z = +-1`` that bound the
  region (for :func:`boundary_curve`);
* :func:`limits` -- alpha_max, the beta range and the Z-width
  (:meth:`symstab.Loop.limits`, the polygons of the stable cells);
* :func:`best_virtual_mass` -- the gamma that maximises alpha_max
  (:meth:`symstab.Loop.design` over the loop's ``M``);
* :func:`boundary_curve` -- the arc of eq. (7) from its generated kernel.
"""

import collections.abc
import dataclasses
import functools
import math
import warnings

import numpy as np

from ..._resources import check_memory, chunk_slices
from ..._validate import check_array, check_box, check_count, check_loop, check_real, check_window
from ..engine.decomposition import window_arc
from ..engine.results import PAPER_PLANE, Boundary
from .curves import KERNEL_BYTES_PER_POINT, KERNEL_CHUNK_BYTES, arc_end_angle, minus_one_line
from .paper_loop import closed_form_arc, paper_arc, paper_point

__all__ = ["StabilityRegion", "limits", "vanishing_gamma", "BestVirtualMass", "best_virtual_mass",
           "boundary_curve", "arc_polylines"]

class StabilityRegion:
    """The stable set of one ``(gamma, d, delta)`` in the (beta, alpha) plane.

    Its line questions are those of :data:`~symstab.numeric.paper.paper_loop.PAPER_LOOP`
    at :func:`~symstab.numeric.paper.paper_loop.paper_point` (``alpha`` is its
    ``K``, ``beta`` its ``B``), answered by the one line engine: the
    crossings of a line with the unit circle (the arc, ``z = +-1`` and the
    leading coefficient's zero), the certified count of roots outside the
    circle at one point and the crossing rule between them, every stable
    stretch counted afresh.  Its limits are read from the loop's D-decomposition
    (:meth:`symstab.numeric.engine.decomposition.Decomposition.limits`), made once
    for them and for :meth:`line_segments`.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.

    Examples
    --------
    >>> r = StabilityRegion(gamma=1.5, d=0, delta=0.00253125)
    >>> [(round(lo, 3), round(hi, 3)) for lo, hi in r.alpha_intervals(-0.5)]
    [(1.266, 2.232)]
    """

    def __repr__(self):
        return f"StabilityRegion(gamma={self.gamma:g}, d={self.d}, delta={self.delta:g})"

    def __init__(self, *, gamma, d, delta):
        self.gamma, self.d, self.delta = check_loop(gamma, d, delta)
        #: ``c`` of the z = -1 line ``alpha + 2 beta = c``
        #: (:func:`~symstab.numeric.paper.curves.minus_one_line`).
        self.minus_one = minus_one_line(gamma=self.gamma, d=self.d, delta=self.delta)

    def __getstate__(self):
        # The cached decomposition holds its arc source (closures of the
        # generated kernel): a copy in another process makes its own on use.
        return {k: v for k, v in self.__dict__.items() if k not in ("_region", "_limits")}

    def decomposition(self, x_range, y_range):
        """The complete D-decomposition of a window of the (beta, alpha) plane.

        Every branch of eq. (7) over all of (0, pi) -- not only the first
        arc, up to theta_max --, the z = 1 line (alpha = 0) and the z = -1
        line, the cells they cut the window into and each cell's certified
        count of unstable roots (:meth:`symstab.Loop.region` of the paper's loop).

        Parameters
        ----------
        x_range : (float, float)
            The window's beta, ``lo < hi``.
        y_range : (float, float)
            The window's alpha, ``lo < hi``.

        Returns
        -------
        symstab.numeric.engine.decomposition.Decomposition
            With ``x = "beta"``, ``y = "alpha"``.

        Examples
        --------
        >>> r = StabilityRegion(gamma=0.0, d=10, delta=0.00253125)
        >>> cells = r.decomposition((-0.05, 0.2), (-0.001, 0.0062)).cells
        >>> sorted(cell.count for cell in cells)
        [0, 1, 2, 3]
        """
        x_range = check_window("x_range", x_range)
        y_range = check_window("y_range", y_range)
        loop, point = paper_point(gamma=self.gamma, d=self.d, delta=self.delta)
        found = loop.region("B", "K", x_range=x_range, y_range=y_range, **point)
        return found.renamed(*PAPER_PLANE)

    def alpha_intervals(self, beta):
        """The stable alpha intervals at damping ``beta``.

        Parameters
        ----------
        beta : float
            Dimensionless damping.

        Returns
        -------
        list of (float, float)
            Increasing, disjoint; empty when no alpha is stable.  An interval
            that does not start at 0 shows the minimum stiffness needed.
        """
        return self._intervals("beta", [check_real("beta", beta)])[0]

    def beta_intervals(self, alpha):
        """The stable beta intervals at stiffness ``alpha`` (as :meth:`alpha_intervals`).

        Parameters
        ----------
        alpha : float
            Dimensionless stiffness.
        """
        return self._intervals("alpha", [check_real("alpha", alpha)])[0]

    def alpha_intervals_on(self, betas):
        """The stable alpha intervals on many vertical lines at once.

        The same intervals as :meth:`alpha_intervals` at each ``beta``, with
        the lines scanned, refined and counted together (a family of lines
        of :meth:`symstab.Loop.stable_intervals`): many times faster than a
        loop over the lines when there are many.

        Parameters
        ----------
        betas : array_like of float
            Dimensionless dampings, one line each (a 1-D sequence).

        Returns
        -------
        list of list of (float, float)
            For each line, as :meth:`alpha_intervals` returns it.

        Raises
        ------
        TypeError, ValueError
            For a non-real or non-finite ``beta``, or ``betas`` that is not
            one-dimensional.
        """
        values = check_array("betas", betas)
        if values.ndim != 1:
            raise ValueError(f"betas must be a one-dimensional sequence, got shape {values.shape}")
        return self._intervals("beta", values)

    def _intervals(self, axis, values):
        """The stable intervals of the other coordinate on the lines ``axis = value``."""
        loop, point = paper_point(gamma=self.gamma, d=self.d, delta=self.delta)
        free, line = ("K", "B") if axis == "beta" else ("B", "K")
        return loop.stable_intervals(free, **{line: np.atleast_1d(values)}, **point)

    # -- where the region is ----------------------------------------------

    @functools.cached_property
    def _limits(self):
        """The limits of this region, read from its D-decomposition (:meth:`Decomposition.limits`)."""
        found = self._region.limits(at={"gamma": self.gamma, "d": self.d, "delta": self.delta},
                                    line=self.alpha_intervals)
        return dataclasses.replace(found, x=PAPER_PLANE[0], y=PAPER_PLANE[1], region=self)

    @functools.cached_property
    def _region(self):
        """The D-decomposition around the stable region (:meth:`symstab.Loop.region`)."""
        loop, point = paper_point(gamma=self.gamma, d=self.d, delta=self.delta)
        return loop.region("B", "K", **point)

    def line_segments(self):
        """The pieces of z = 1 (alpha = 0) and z = -1 that bound the stable region.

        The stable cells' edges on those lines
        (:attr:`symstab.numeric.engine.decomposition.Decomposition.segments`),
        joined where they meet; an end where the arc meets the line is
        re-found on the arc.

        Returns
        -------
        tuple of :class:`symstab.numeric.engine.results.Segment`
            In the (beta, alpha) plane.
        """
        return self._region.renamed(*PAPER_PLANE).segments

    def alpha_max(self):
        """``(alpha_max, beta at alpha_max)``, or ``None`` when the region is empty (see :meth:`limits`)."""
        lim = self._limits
        return None if lim.empty else (lim.y_max, lim.x_at_y_max)

    def beta_range(self):
        """``(beta_min, beta_max)`` of the stable region, or ``None`` when it is empty (see :meth:`limits`)."""
        lim = self._limits
        return None if lim.empty else (lim.x_min, lim.x_max)

    def limits(self, *, n_beta=None):
        """alpha_max, the beta range and the Z-width (see :func:`limits`).

        Parameters
        ----------
        n_beta : None
            Deprecated and ignored: the Z-width is the area of the stable
            polygons, not an integral over ``n_beta`` vertical lines.
        """
        _deprecated_n_beta(n_beta)
        return self._limits


def _deprecated_n_beta(n_beta):
    if n_beta is not None:
        check_count("n_beta", n_beta, 3)    # still refused as before, while it is deprecated
        warnings.warn("n_beta is deprecated and ignored: the Z-width is now the area of the "
                      "stable polygons of the D-decomposition (no line integration)",
                      DeprecationWarning, stacklevel=3)


def limits(*, gamma, d, delta, n_beta=None):
    """Renderable limits of one virtual mass, delay and device.

    The paper's loop in Table I's plane, on the engine of every loop
    (:meth:`symstab.Loop.limits`, through :meth:`StabilityRegion.limits`):
    the stable cells of the D-decomposition of the (beta, alpha) plane, their
    extreme vertices (refined along the arc) and the area of their polygons.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    n_beta : None
        Deprecated and ignored (the Z-width was a trapezoid rule over
        ``n_beta`` vertical lines; it is now the polygons' area).

    Returns
    -------
    Limits
        Empty (``alpha_max is None``, ``z_width == 0``, with a message) when
        no point is stable.

    Examples
    --------
    >>> lim = limits(gamma=0.0, d=0, delta=0.00253125)
    >>> round(lim.alpha_max, 4), round(lim.beta_right, 4)
    (0.6897, 2.0034)
    >>> lim  # doctest: +ELLIPSIS
    Limits(gamma=0, d=0, delta=0.00253125: alpha_max=0.68967 at beta=0.827933, beta from ...)
    """
    _deprecated_n_beta(n_beta)
    gamma, d, delta = check_loop(gamma, d, delta)
    return _region_at(gamma.hex(), d, delta.hex()).limits()


@functools.lru_cache(maxsize=32)
def _region_at(gamma_hex, d, delta_hex):
    """The :class:`StabilityRegion` of one point (its floats in hex: -0.0 is not 0.0), kept.

    Its limits are asked again at once: a figure's scan of gamma, then the
    bisection of :func:`vanishing_gamma` from two of its gammas, then the
    gamma it ends at.  32 regions hold about 3 MB.
    """
    return StabilityRegion(gamma=float.fromhex(gamma_hex), d=d, delta=float.fromhex(delta_hex))


def vanishing_gamma(*, d, delta, inside, outside, tol=5e-5):
    """Where the stable region vanishes along gamma: ``(last gamma with a region, first without)``.

    Bisection between ``inside`` (a gamma with a stable region) and
    ``outside`` (one without) on the certified emptiness of :func:`limits`,
    until the two are ``tol`` apart.  A gamma first tries a few vertical
    lines across the last region found (the line engine, a hundredth of a
    D-decomposition): a stable stretch on one, counted by the certified root
    count, is a region, and only a gamma where the lines find none is
    decomposed.  Next to the vanishing point the set
    can be too small to decide (alpha_max below about 1e-12, where two
    roots meet at z = 1, and the engine refuses): such a gamma moves neither
    end, and the search goes on between it and ``outside``.  The bracket
    returned is a pair the engine decided, wider than ``tol`` when the
    search ran into such gammas; an "empty" next to the vanishing point can
    be a sliver thinner than the engine resolves (:meth:`symstab.Loop.limits`
    says so in its reason).

    Parameters
    ----------
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
    inside, outside : float
        The two ends; either may be the larger.
    tol : float
        Width of the bracket to stop at, > 0.

    Returns
    -------
    (float, float)
        ``(inside, outside)``, moved towards each other.

    Raises
    ------
    ValueError
        If ``inside`` has no stable region or ``outside`` has one.

    Examples
    --------
    A region exists while gamma > -1 - (d + 1) delta:

    >>> lo, hi = vanishing_gamma(d=0, delta=0.00253125, inside=-0.5, outside=-1.5, tol=1e-3)
    >>> hi <= -1.00253125 <= lo
    True
    """
    _, d, delta = check_loop(0.0, d, delta)
    inside, outside = check_real("inside", inside), check_real("outside", outside)
    tol = check_real("tol", tol, low=0.0, low_open=True)
    found = limits(gamma=inside, d=d, delta=delta)
    if found.empty:
        raise ValueError(f"inside = {inside!r} must be a gamma with a stable region (d = {d})")
    if not limits(gamma=outside, d=d, delta=delta).empty:
        raise ValueError(f"outside = {outside!r} must be a gamma without a stable region (d = {d})")
    probe, lines = inside, _lines_across(found)
    while abs(outside - inside) > tol and abs(outside - probe) > tol:
        middle = 0.5 * (probe + outside)
        if _crosses_a_stable_stretch(middle, d, delta, lines):
            inside = probe = middle
            continue
        try:
            found = limits(gamma=middle, d=d, delta=delta)
        except ValueError:
            probe = middle
            continue
        if found.empty:
            outside = middle
        else:
            inside = probe = middle
            lines = _lines_across(found)
    return inside, outside


def _lines_across(found, n=7):
    """Dampings of ``n`` vertical lines across the stable region of ``found``, a :class:`Limits`."""
    inner = np.linspace(found.x_min, found.x_max, n + 2)[1:-1]
    return np.union1d(inner, [found.x_at_y_max])


def _crosses_a_stable_stretch(gamma, d, delta, betas):
    """Whether a vertical line at one of ``betas`` holds a stable alpha at ``gamma``.

    A stable stretch of a line is counted by the line engine's certified
    root count: a gamma where one is found has a stable region, with no
    D-decomposition to make (a bisection step that has one costs a
    hundredth of one that makes it).  False says nothing: the lines may
    miss the region, or be refused next to where it vanishes.
    """
    try:
        stretches = StabilityRegion(gamma=gamma, d=d, delta=delta).alpha_intervals_on(betas)
    except ValueError:
        return False
    return any(stretches)


@dataclasses.dataclass(frozen=True)
class BestVirtualMass:
    """The virtual mass that maximises the renderable stiffness.

    Attributes
    ----------
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
    gamma, beta : float or None
        The best ``M_w / m`` and the damping at which alpha_max is reached.
    alpha_max : float or None
        alpha_max at that gamma (a supremum of the stable region).
    alpha_max_gamma0 : float or None
        alpha_max with no virtual mass.
    gain : float or None
        ``alpha_max / alpha_max_gamma0``.
    z_width : float
        Area of the stable region at the best gamma: how much room there is.
        At d = 0 the optimum lies where the region shrinks to nothing (near
        gamma = 2); the gain is real but needs very precise tuning, as the
        paper says.
    message : str
        Empty, or why there is no result (no gamma of the range has a region).
    """

    d: int
    delta: float
    gamma: float
    beta: float
    alpha_max: float
    alpha_max_gamma0: float
    gain: float
    z_width: float = 0.0
    message: str = ""


def _check_gamma_range(gamma_range):
    """``(low, high)``: two finite reals with ``low < high``."""
    if isinstance(gamma_range, (str, bytes)) or not isinstance(gamma_range, collections.abc.Sequence) \
            and not isinstance(gamma_range, np.ndarray):
        raise TypeError(f"gamma_range must be a pair (low, high) of real numbers, "
                        f"got {type(gamma_range).__name__}")
    if len(gamma_range) != 2:
        raise ValueError(f"gamma_range must be a pair (low, high) of real numbers, "
                         f"got {len(gamma_range)} item(s): {gamma_range!r}")
    low = check_real("gamma_range[0]", gamma_range[0])
    high = check_real("gamma_range[1]", gamma_range[1])
    if not low < high:
        raise ValueError(f"gamma_range must be a pair (low, high) with low < high, got {gamma_range!r}")
    return low, high


def best_virtual_mass(*, d, delta, gamma_range=None, n=17):
    """The gamma (and beta) that maximise alpha_max, and the gain over gamma = 0.

    :meth:`symstab.Loop.design` of the paper's loop in Table I's variables
    (:func:`~symstab.numeric.paper.paper_loop.paper_point`) over its virtual mass
    ``M = gamma``: alpha_max(gamma) is scanned on ``n`` points of
    ``gamma_range`` (default from just above ``-1 - (d + 1) delta``, below
    which no arc exists, to 3) and the best scan point is refined by Brent's
    bounded search between its neighbours (:mod:`symstab.numeric.analysis.design`).

    Parameters
    ----------
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    gamma_range : (float, float), optional
        ``(low, high)``, finite, ``low < high``: the gammas scanned.
    n : int
        Points of the scan, ``n >= 3``.

    Returns
    -------
    BestVirtualMass
        With ``None`` values and a message when no gamma of the range has a
        stable region.

    Raises
    ------
    TypeError, ValueError
        For bad ``d``, ``delta``, ``gamma_range`` or ``n``.

    Examples
    --------
    >>> best = best_virtual_mass(d=0, delta=0.00253125)
    >>> 5 < best.gain < 6.5
    True
    """
    _, d, delta = check_loop(0.0, d, delta)
    n = check_count("n", n, 3)
    if gamma_range is None:
        gamma_range = (-1.0 - (d + 1) * delta + 1e-3, 3.0)
    g_lo, g_hi = _check_gamma_range(gamma_range)
    loop, values = paper_point(gamma=0.0, d=d, delta=delta)
    found = loop.design(over={"M": (g_lo, g_hi)}, x="B", y="K", n=n, **values)
    if found.best is None:
        return BestVirtualMass(d, delta, None, None, None, None, None, 0.0,
                               f"no gamma in [{g_lo:g}, {g_hi:g}] has a stable region at d = {d}")
    best = found.limits
    return BestVirtualMass(d, delta, found.best["M"], best.x_at_y_max, best.y_max,
                           float(found.value_nominal), found.gain, best.area)


def _arc_points(gamma, d, delta):
    """``theta -> (beta, alpha)``: the paper's arc source's points, without its determinant.

    The curves drawn need no determinant (a Cramer solve per angle, three
    times the closed form's cost).
    """
    _, values = paper_point(gamma=gamma, d=d, delta=delta)
    return closed_form_arc("B", "K", values)


def boundary_curve(*, gamma, d, delta, n=1000, segments=True):
    """Sample the boundary arc from theta = 0 to theta_max.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    n : int
        Number of points on the arc, ``n >= 2``; about 24 bytes each are
        kept, so ``n`` is limited by the memory limit
        (``symstab._resources``, ``SYMSTAB_MEMORY_LIMIT``).
    segments : bool
        Also find the straight pieces (z = +-1) that bound the stable region
        (a stability scan; skip it when only the arc is wanted).

    Returns
    -------
    symstab.numeric.engine.results.Boundary
        In the paper's plane: ``alpha`` and ``beta`` (aliases of
        ``y_values`` and ``x_values``), ``theta_max``, ``segments``.

    Raises
    ------
    TypeError, ValueError
        For a non-real, non-finite or out-of-range parameter, and
        ValueError for an ``n`` whose arrays would exceed the memory limit.

    Examples
    --------
    >>> c = boundary_curve(gamma=0.0, d=0, delta=0.00253125, n=5, segments=False)
    >>> float(c.alpha[0]), round(float(c.beta[0]), 8), round(c.theta_max, 4)
    (0.0, -0.00253125, 1.5725)
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    n = check_count("n", n, 2)
    # theta, alpha and beta are kept; the kernel's temporaries are chunked.
    check_memory(f"boundary_curve with n = {n} points", 3 * 8 * n + KERNEL_CHUNK_BYTES)
    t_end = arc_end_angle(gamma=gamma, d=d, delta=delta)
    at = {"gamma": gamma, "d": d, "delta": delta}
    # c0 + c_beta beta + c_alpha alpha = 0: z = 1 is alpha = 0, z = -1 is alpha + 2 beta = c.
    lines = {"z = 1": (0.0, 0.0, 1.0)}
    c = minus_one_line(gamma=gamma, d=d, delta=delta)
    if math.isfinite(c):
        lines["z = -1"] = (-c, 2.0, 1.0)
    if not np.isfinite(t_end):
        empty = np.empty(0)
        return Boundary(*PAPER_PLANE, empty, empty, empty, lines=lines, theta_max=t_end,
                        reason="no boundary arc: alpha < 0 just after theta = 0, so the arc "
                               "never enters alpha > 0 (1 + gamma + (d + 1) delta <= 0 or close "
                               "to it)", at=at)
    theta = np.linspace(0.0, t_end, n)
    alpha, beta = np.empty(n), np.empty(n)
    points = _arc_points(gamma, d, delta)
    for part in chunk_slices(n, KERNEL_BYTES_PER_POINT, KERNEL_CHUNK_BYTES):
        beta[part], alpha[part] = points(theta[part])
    # The ends are exact: the arc starts at (-delta, 0) and ends on alpha = 0.
    alpha[0], beta[0] = 0.0, -delta
    if t_end < np.pi:
        alpha[-1] = 0.0
    pieces = ()
    if segments:
        pieces = StabilityRegion(gamma=gamma, d=d, delta=delta).line_segments()
    return Boundary(*PAPER_PLANE, theta, beta, alpha, lines=lines, segments=pieces, theta_max=t_end,
                    at=at)


def arc_polylines(*, gamma, d, delta, window):
    """The whole boundary arc, 0 < theta < pi, as polylines to draw in ``window``.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples.
    delta : float
        ``b T / m``.
    window : ((float, float), (float, float))
        ``((beta0, beta1), (alpha0, alpha1))``, the part of the plane drawn.

    Returns
    -------
    (ndarray, ndarray)
        ``(first, beyond)``, each an ``(n, 2)`` array of ``(beta, alpha)``
        rows: the arc of eq. (7) from theta = 0 to theta_max, and the rest up
        to pi (empty when there is no theta_max).  Rows of NaN cut the curve
        where it runs far from the window -- through a pole it goes to
        infinity and comes back from the other side, and a straight line
        across would be drawn.  The arc is sampled as the D-decomposition
        samples it (:func:`symstab.numeric.engine.decomposition.window_arc`):
        inside the window no chord is longer than 2e-3 of it nor turns by
        more than 0.05 rad from the next.
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    (b0, b1), (a0, a1) = check_box("window", window, PAPER_PLANE)
    t_max = arc_end_angle(gamma=gamma, d=d, delta=delta)
    theta, beta, alpha = window_arc(paper_arc(gamma=gamma, d=d, delta=delta), d + 4, (b0, b1),
                                    (a0, a1), angles=[t_max] if np.isfinite(t_max) else [])
    points = np.column_stack([beta, alpha])
    # The arc starts exactly at the corner (-delta, 0), the z = 1 root's line.
    points = np.vstack([[-delta, 0.0], points])
    if not np.isfinite(t_max):
        return np.empty((0, 2)), points
    k = int(np.searchsorted(theta, t_max)) + 1
    if np.isfinite(points[k, 1]):
        points[k, 1] = 0.0              # theta_max is where the arc meets alpha = 0
    return points[: k + 1], points[k:]
