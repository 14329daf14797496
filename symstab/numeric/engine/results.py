"""One result type per question, for every loop.

:class:`Limits` answers "what does this plane's stable set let a device
render": the largest ``y`` of a stable point, where it is reached, the
extent in ``x`` and the area.  :class:`Boundary` answers "where can a root
cross the unit circle": the arc (a root at ``exp(j theta)``) and the lines of
the real roots and of a root at infinity.  A :class:`symstab.Loop` gives it for any
plane (:meth:`symstab.Loop.limits`), the paper's dimensionless functions for
the plane ``(beta, alpha)`` of Table I (:func:`symstab.limits`,
:meth:`symstab.StabilityRegion.limits`); there, and only there, the paper's
names are aliases of the fields (``alpha_max`` is ``y_max``, ``z_width`` is
``area``, a boundary's ``alpha`` is its ``y_values``, ...).
"""

import dataclasses
import functools
import html

import numpy as np

from ..._validate import check_real

__all__ = ["Limits", "Boundary", "Segment", "StabilityProbability", "RobustRegion", "html_table"]

#: The paper's dimensionless plane: x = beta (damping), y = alpha (stiffness).
PAPER_PLANE = ("beta", "alpha")


def paper_alias(name, field):
    """A property ``name`` of a result in the paper's (beta, alpha) plane: ``field`` there, else AttributeError."""
    def get(self):
        if (self.x, self.y) != PAPER_PLANE:
            raise AttributeError(
                f"{name} is the paper's name in its (beta, alpha) plane; this result is in "
                f"the ({self.x}, {self.y}) plane: use {field}")
        return getattr(self, field)

    get.__name__ = name
    get.__doc__ = f"The paper's name of ``{field}`` (the (beta, alpha) plane only)."
    return property(get)


def paper_parameter(name):
    """A property ``name``: the paper's parameter ``at[name]`` of a result in its (beta, alpha) plane."""
    def get(self):
        if (self.x, self.y) != PAPER_PLANE or name not in self.at:
            raise AttributeError(f"{name} is a parameter of the paper's (beta, alpha) plane; "
                                 f"this result is in the ({self.x}, {self.y}) plane: see at")
        return self.at[name]

    get.__name__ = name
    get.__doc__ = f"The paper's ``{name}`` (``at[{name!r}]``; the (beta, alpha) plane only)."
    return property(get)


def html_table(caption, rows):
    """An HTML table of ``rows`` (name, value) for Jupyter, every text escaped.

    Numbers are shown to 6 significant digits, None as an empty cell.

    Parameters
    ----------
    caption : str
    rows : iterable of (str, object)

    Returns
    -------
    str
    """
    def cell(value):
        if value is None:
            return ""
        if isinstance(value, float):
            return f"{value:.6g}"
        return html.escape(str(value))

    body = "".join(f"<tr><th style='text-align:left'>{html.escape(str(name))}</th>"
                   f"<td>{cell(value)}</td></tr>" for name, value in rows)
    return f"<table><caption>{html.escape(caption)}</caption>{body}</table>"


def _head(kind, result):
    """``Limits(gamma=0, d=5, delta=0.00253: `` in the paper's plane, ``Limits(B, K at d=5: `` else."""
    where = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                      for k, v in result.at.items())
    if (result.x, result.y) == PAPER_PLANE and where:
        return f"{kind}({where}: "
    return f"{kind}({result.x}, {result.y}{' at ' + where if where else ''}: "


@dataclasses.dataclass(frozen=True, repr=False)
class Limits:
    """The extent and area of the stable set in an ``(x, y)`` parameter plane.

    Attributes
    ----------
    x, y : str
        The plane's parameters (``"beta"``, ``"alpha"`` for the paper's
        dimensionless plane).
    y_max : float or None
        Largest ``y`` of a stable point (``inf`` if unbounded; None when no
        point is stable).
    x_at_y_max : float or None
        The ``x`` where it is reached (NaN when the set is unbounded there).
    x_min, x_max : float or None
        Extent of the stable set in ``x``.
    area : float
        Area of the stable set in the plane (the Z-width when ``x`` and
        ``y`` are damping and stiffness); 0 when empty, ``inf`` when
        unbounded.
    cells : int or None
        The stable cells of the D-decomposition the numbers were read from
        (the set's connected pieces), where one was made.
    reason : str
        Why the set is empty or unbounded; else empty.
    region : object
        What the numbers describe: the paper's
        :class:`~symstab.numeric.paper.region.StabilityRegion`, or None.
    at : dict
        The values of the other parameters, as given.
    line : callable or None
        ``line(x) -> [(lo, hi), ...]``: the stable intervals of ``y`` at
        ``x`` (:meth:`intervals_at`), where the limits came from a loop.
    decomposition : Decomposition or None
        The D-decomposition the numbers were read from (what :meth:`plot`
        draws), where they were read from one.  Not pickled (its arc is
        computed by closures): limits sent to another process draw nothing.

    Notes
    -----
    In the paper's plane the names of Table I are aliases:
    ``alpha_max`` (``y_max``), ``beta_at_alpha_max`` (``x_at_y_max``),
    ``beta_left`` and ``beta_min`` (``x_min``), ``beta_right`` and
    ``beta_max`` (``x_max``), ``z_width`` (``area``); ``message`` is
    ``reason`` in every plane.  Elsewhere those names raise
    :class:`AttributeError` rather than answer for another plane.
    """

    x: str
    y: str
    y_max: object
    x_at_y_max: object
    x_min: object
    x_max: object
    area: float
    cells: object = None
    reason: str = ""
    region: object = None
    at: dict = dataclasses.field(default_factory=dict)
    line: object = dataclasses.field(default=None, compare=False)
    decomposition: object = dataclasses.field(default=None, compare=False, repr=False)

    alpha_max = paper_alias("alpha_max", "y_max")
    beta_at_alpha_max = paper_alias("beta_at_alpha_max", "x_at_y_max")
    beta_left = paper_alias("beta_left", "x_min")
    beta_min = paper_alias("beta_min", "x_min")
    beta_right = paper_alias("beta_right", "x_max")
    beta_max = paper_alias("beta_max", "x_max")
    z_width = paper_alias("z_width", "area")

    @property
    def message(self):
        """Another name of :attr:`reason`."""
        return self.reason

    @property
    def empty(self):
        """True when no point of the plane is stable (see :attr:`reason`)."""
        return self.y_max is None

    def __getstate__(self):
        # The decomposition's arc source is made of closures, which do not pickle.
        return {**self.__dict__, "decomposition": None}

    @classmethod
    def empty_set(cls, x, y, reason, **fields):
        """Limits of an empty stable set (``y_max`` None, ``area`` 0)."""
        return cls(x, y, None, None, None, None, 0.0, reason=reason, **fields)

    def __repr__(self):
        head = _head("Limits", self)
        if self.empty:
            return head + f"empty, {self.reason or 'no stable point'})"
        if (self.x, self.y) == PAPER_PLANE:
            text = (f"alpha_max={self.y_max:.6g} at beta={self.x_at_y_max:.6g}, beta from "
                    f"{self.x_min:.6g} to {self.x_max:.6g}, z_width={self.area:.6g}")
        else:
            text = (f"{self.y}_max={self.y_max:.6g} at {self.x}={self.x_at_y_max:.6g}, "
                    f"{self.x} in [{self.x_min:.6g}, {self.x_max:.6g}], area={self.area:.6g}")
        return head + text + (f", {self.reason!r})" if self.reason else ")")

    def _repr_html_(self):
        """Jupyter's view: :meth:`as_dict` as a table."""
        return html_table(_head("Limits", self)[:-2] + ")", self.as_dict().items())

    def plot(self, ax=None, **kwargs):
        """Draw the stable set, its largest ``y`` marked: :func:`symstab.drawing.plot_limits`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        **kwargs
            ``counts``, ``color``: as in :func:`symstab.drawing.plot_region`.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_limits

        return plot_limits(self, ax, **kwargs)

    def as_dict(self):
        """The numbers, for tables and JSON (the paper's names in its plane)."""
        if (self.x, self.y) == PAPER_PLANE:
            return {**self.at, "alpha_max": self.y_max, "beta_at_alpha_max": self.x_at_y_max,
                    "beta_left": self.x_min, "beta_right": self.x_max, "z_width": self.area,
                    "message": self.reason}
        return {**self.at, "x": self.x, "y": self.y, "y_max": self.y_max,
                "x_at_y_max": self.x_at_y_max, "x_min": self.x_min, "x_max": self.x_max,
                "area": self.area, "cells": self.cells, "reason": self.reason}

    # The line questions, answered by the one line engine of the loop.

    def intervals_at(self, x):
        """The stable ``y`` intervals at ``x``: :meth:`symstab.Loop.stable_intervals` on this plane.

        Parameters
        ----------
        x : float
            The value of the plane's ``x``.

        Returns
        -------
        list of (float, float)
            Increasing, disjoint; empty when no ``y`` is stable.

        Raises
        ------
        AttributeError
            For limits that did not come from a loop (no :attr:`line`).
        """
        if self.line is None:
            raise AttributeError(f"these limits of the ({self.x}, {self.y}) plane did not come "
                                 f"from a loop: no line engine to ask")
        return self.line(x)

    def alpha_interval(self, beta):
        """The stable alpha intervals at ``beta`` (the paper's name of :meth:`intervals_at`).

        Parameters
        ----------
        beta : float
            Dimensionless damping.
        """
        if (self.x, self.y) != PAPER_PLANE:
            raise AttributeError(f"alpha_interval is the paper's name in its (beta, alpha) plane; "
                                 f"this result is in the ({self.x}, {self.y}) plane: use "
                                 f"intervals_at")
        return self.intervals_at(check_real("beta", beta))

    def minimum_stiffness(self, beta):
        """The smallest stable alpha at ``beta`` (0 unless a minimum stiffness is needed).

        ``None`` when nothing is stable at ``beta``.

        Parameters
        ----------
        beta : float
            Dimensionless damping.
        """
        runs = self.alpha_interval(beta)
        return runs[0][0] if runs else None


@dataclasses.dataclass(frozen=True)
class Segment:
    """A straight piece of the stable set's boundary, from ``(x0, y0)`` to ``(x1, y1)``.

    Attributes
    ----------
    root : str
        Which real root is on the unit circle along it: ``"z=1"`` or
        ``"z=-1"``.
    x0, y0, x1, y1 : float
        Its ends, ``x0 <= x1``.
    x, y : str
        The plane's parameters.

    Notes
    -----
    In the paper's plane ``beta0``, ``alpha0``, ``beta1``, ``alpha1`` are
    aliases of the ends.
    """

    root: str
    x0: float
    y0: float
    x1: float
    y1: float
    x: str = "x"
    y: str = "y"

    beta0 = paper_alias("beta0", "x0")
    alpha0 = paper_alias("alpha0", "y0")
    beta1 = paper_alias("beta1", "x1")
    alpha1 = paper_alias("alpha1", "y1")


class PaperGridNames:
    """The paper's names of a result over the plane's ``x_values``, ``y_values`` and ``at``.

    In the paper's (beta, alpha) plane ``alpha`` and ``beta`` are the grids
    (``y_values``, ``x_values``) and ``gamma``, ``d``, ``delta`` the values
    in ``at``; elsewhere they raise :class:`AttributeError`.  Shared by
    :class:`Boundary` and :class:`symstab.numeric.paper.simulate.StabilityMap`.
    """

    alpha = paper_alias("alpha", "y_values")
    beta = paper_alias("beta", "x_values")
    gamma = paper_parameter("gamma")
    d = paper_parameter("d")
    delta = paper_parameter("delta")


@dataclasses.dataclass(frozen=True, repr=False)
class Boundary(PaperGridNames):
    """Where a root of the characteristic polynomial crosses the unit circle, in an ``(x, y)`` plane.

    Attributes
    ----------
    x, y : str
        The plane's parameters (``"beta"``, ``"alpha"`` for the paper's
        dimensionless plane).
    theta : ndarray
        Angles of the arc's points: ``z = exp(j theta)`` is a root at
        ``(x_values, y_values)``.  A loop's boundary samples all of (0, pi);
        the paper's :func:`symstab.boundary_curve` the stable region's arc,
        from theta = 0 to :attr:`theta_max`.  Empty when there is no arc.
    x_values, y_values : ndarray
        The arc's points (NaN where the 2 x 2 system is singular: the arc is
        at infinity there).
    lines : dict
        ``{"z = 1": (c0, cx, cy), "z = -1": ..., "leading": ...}``: the line
        ``c0 + cx x + cy y = 0`` on which that real root (or a root at
        infinity) appears; a line that does not exist in the plane is left
        out.
    segments : tuple of Segment
        The pieces of those lines that bound the stable set, where they
        were found (the paper's :func:`symstab.boundary_curve`, from the
        stable cells of its D-decomposition).
    theta_max : float
        Where the stable region's arc ends (the paper's plane; NaN else).
    reason : str
        Why there is no arc, when there is none.
    at : dict
        The values of the other parameters, as given.

    Notes
    -----
    In the paper's plane ``alpha`` and ``beta`` are aliases of
    ``y_values`` and ``x_values``, and ``gamma``, ``d``, ``delta``
    read :attr:`at`; ``message`` is :attr:`reason` in every plane.
    """

    x: str
    y: str
    theta: np.ndarray
    x_values: np.ndarray
    y_values: np.ndarray
    lines: dict = dataclasses.field(default_factory=dict)
    segments: tuple = ()
    theta_max: float = float("nan")
    reason: str = ""
    at: dict = dataclasses.field(default_factory=dict)


    @property
    def message(self):
        """Another name of :attr:`reason`."""
        return self.reason

    @property
    def empty(self):
        """True when there is no arc."""
        return self.theta.size == 0

    def __repr__(self):
        head = _head("Boundary", self)
        if self.empty:
            return head + f"no arc, {self.reason!r})"
        finite = np.isfinite(self.x_values) & np.isfinite(self.y_values)
        if (self.x, self.y) == PAPER_PLANE and self.segments is not None and np.isfinite(
                self.theta_max):
            n = len(self.segments)
            return head + (f"{self.theta.size} points, theta_max={self.theta_max:.6g}, alpha up to "
                           f"{float(np.max(self.y_values)):.6g}, beta from "
                           f"{float(np.min(self.x_values)):.6g} to "
                           f"{float(np.max(self.x_values)):.6g}, {n} straight "
                           f"segment{'s' if n != 1 else ''})")
        return head + (f"{int(finite.sum())} arc points, lines "
                       f"{', '.join(self.lines) or 'none'})")

    def plot(self, ax=None, **kwargs):
        """Draw the arc and the lines in view: :func:`symstab.drawing.plot_boundary`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        **kwargs
            ``x_range``, ``y_range``: the window (as in
            :func:`symstab.drawing.plot_boundary`).

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_boundary

        return plot_boundary(self, ax, **kwargs)


@dataclasses.dataclass(frozen=True, repr=False)
class StabilityProbability:
    """The probability that each cell of an ``(x, y)`` grid is stable, over uncertain parameters.

    Attributes
    ----------
    y_values, x_values : ndarray
        The 1-D grids.
    probability : ndarray
        ``(len(y_values), len(x_values))``: the fraction of the draws at
        which the cell is stable (certified root counts).
    standard_error : ndarray
        Its Monte Carlo standard error, ``sqrt(p (1 - p) / samples)``.
    marginal : ndarray of int
        Draws at which the cell was marginal (counted as not stable).
    samples, seed : int
        The draws and the seed of the generator that drew them.
    uncertain : dict
        Each uncertain parameter's distribution in words.
    x, y : str
        The plane.
    at : dict
        The values of the other parameters.
    """

    y_values: np.ndarray
    x_values: np.ndarray
    probability: np.ndarray
    standard_error: np.ndarray
    marginal: np.ndarray
    samples: int
    seed: int
    uncertain: dict
    x: str
    y: str
    at: dict = dataclasses.field(default_factory=dict)

    def plot(self, ax=None, *, boundary=None):
        """Draw the probability over the grid: :func:`symstab.drawing.plot_probability`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        boundary : symstab.numeric.engine.results.Boundary, optional
            The nominal loop's boundary, drawn over the map.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_probability

        return plot_probability(self, ax, boundary=boundary)

    def __repr__(self):
        p = self.probability
        drawn = ", ".join(f"{k} ~ {v}" for k, v in self.uncertain.items())
        return (f"StabilityProbability({self.x} x {self.y}: {p.shape[1]} x {p.shape[0]} cells, "
                f"{self.samples} draws of {drawn}: {int(np.count_nonzero(p == 1))} always stable, "
                f"{int(np.count_nonzero((p > 0) & (p < 1)))} sometimes, "
                f"{int(np.count_nonzero(p == 0))} never; largest standard error "
                f"{float(np.max(self.standard_error)):.2g})")


@dataclasses.dataclass(frozen=True, repr=False, eq=False)
class RobustRegion:
    """The points of an ``(x, y)`` plane stable for every value of uncertain parameters.

    :func:`symstab.numeric.analysis.robust.robust_region` states the guarantee and
    how it is proved.  The set is a union of trapezoids, one strip of ``x``
    by a certified band of ``y`` whose ends run straight from the strip's
    left edge to its right one: an inner approximation of the robust set.

    Attributes
    ----------
    x, y : str
        The plane.
    uncertain : dict
        ``{name: (low, high)}``: the box and the delay range as given
        (``d``: the first and last delay in samples, whole or not; ``Td``:
        in seconds).
    edges : ndarray
        The strips' edges in ``x`` (two equal edges: one line).
    intervals : tuple of tuple
        Per strip, the robustly stable bands ``(lo0, hi0, lo1, hi1)``: the
        interval of ``y`` at the strip's left edge and at its right edge.
    marginal : tuple of tuple
        Per strip, the bands (as ``intervals``) where the certificate did
        not close (neither called stable nor unstable).
    nominal : symstab.numeric.engine.decomposition.Decomposition
        The D-decomposition at the box's centre, to be drawn beside.
    at : dict
        The values of the other parameters.
    reason : str
        Why the set is empty; else empty.
    examined : int
        Cells the branch and bound examined.
    exhausted : bool
        Whether it stopped at its budget of cells (what was left open is
        then marginal).
    unbounded : tuple of str
        The window's sides the nominal set goes beyond and the robust set
        reaches: it may go on there too (its limits are then infinite).
    """

    x: str
    y: str
    uncertain: dict
    edges: np.ndarray
    intervals: tuple
    marginal: tuple
    nominal: object = dataclasses.field(default=None, compare=False)
    at: dict = dataclasses.field(default_factory=dict)
    reason: str = ""
    examined: int = 0
    exhausted: bool = False
    unbounded: tuple = ()

    def plot(self, ax=None):
        """Draw the certified and marginal sets: :func:`symstab.drawing.plot_robust`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_robust

        return plot_robust(self, ax)

    @classmethod
    def from_strips(cls, x, y, box, delay, edges, robust, marginal, nominal, at, examined=0,
                    exhausted=False, unbounded=()):
        """The region from each strip's intervals (the reason said when it is empty).

        Parameters
        ----------
        x, y : str
            The plane.
        box : dict
            ``{name: (low, high)}`` of the continuous parameters.
        delay : (str, (float, float)) or None
            The uncertain delay, ``("d", (low, high))`` in samples or
            ``("Td", (low, high))`` in seconds, as given; None for one
            delay (in ``at``).
        edges : array_like
            The strips' edges.
        robust, marginal : list of list of (float, float, float, float)
            Per strip, the certified and the marginal bands ``(lo0, hi0,
            lo1, hi1)``.
        nominal : Decomposition
            The decomposition at the box's centre.
        at : dict
            The other parameters' values.
        examined, exhausted, unbounded :
            As the attributes.
        """
        uncertain = dict(box) if delay is None else {**box, delay[0]: delay[1]}
        region = cls(x, y, uncertain, np.asarray(edges, dtype=float),
                     tuple(tuple(r) for r in robust), tuple(tuple(m) for m in marginal),
                     nominal, dict(at), examined=examined, exhausted=exhausted,
                     unbounded=tuple(unbounded))
        if not region.empty:
            return region
        box_text = ", ".join(f"{k} in [{lo:g}, {hi:g}]" for k, (lo, hi) in uncertain.items())
        strips = len(region.edges) - 1
        why = (f"no point is stable for every {box_text}: on the edges of the {strips} strips "
               f"the stable sets at the box's corners, centre and midpoints have no common point"
               if not any(marginal) else
               f"no point could be certified stable for every {box_text} (marginal where the "
               f"stable sets at its corners, centre and midpoints overlap)")
        return dataclasses.replace(region, reason=why)

    @classmethod
    def empty_set(cls, x, y, box, delay, nominal, at, reason):
        """An empty region, with why.

        Parameters
        ----------
        x, y, box, delay, nominal, at :
            As :meth:`from_strips`.
        reason : str
            Why it is empty.
        """
        uncertain = dict(box) if delay is None else {**box, delay[0]: delay[1]}
        return cls(x, y, uncertain, np.zeros(0), (), (), nominal, dict(at), reason=reason)

    @property
    def empty(self):
        """Whether no point is robustly stable."""
        return not any(self.intervals)

    def _bands(self, which):
        """Rows ``(x0, x1, lo0, hi0, lo1, hi1)``, one per band."""
        out = [(self.edges[i], self.edges[i + 1], *band)
               for i, bands in enumerate(which) for band in bands]
        return np.array(out, dtype=float).reshape(-1, 6)

    @functools.cached_property
    def _robust_bands(self):
        """``_bands(self.intervals)``, built once (read-only): a Python loop over thousands of
        strips that every ``contains`` and ``intervals_at`` read."""
        rows = self._bands(self.intervals)
        rows.flags.writeable = False
        return rows

    @staticmethod
    def _areas(r):
        return (r[:, 1] - r[:, 0]) * 0.5 * ((r[:, 3] - r[:, 2]) + (r[:, 5] - r[:, 4]))

    @property
    def area(self):
        """Area of the robust set (the trapezoids' sum)."""
        return float(np.sum(self._areas(self._robust_bands)))

    @property
    def marginal_area(self):
        """Area where the certificate did not close."""
        return float(np.sum(self._areas(self._bands(self.marginal))))

    @property
    def polygons(self):
        """The robust set's outlines, counter-clockwise: runs of strips with one band each, touching
        across the edge between them, join into one polygon."""
        out, run = [], []

        def close(run):
            if not run:
                return
            bottom = [p for i, (lo0, _, lo1, _) in run
                      for p in ((self.edges[i], lo0), (self.edges[i + 1], lo1))]
            top = [p for i, (_, hi0, _, hi1) in reversed(run)
                   for p in ((self.edges[i + 1], hi1), (self.edges[i], hi0))]
            out.append(np.array(bottom + top))

        for i, bands in enumerate(self.intervals):
            if len(bands) == 1 and run and run[-1][0] == i - 1 \
                    and len(self.intervals[i - 1]) == 1 \
                    and bands[0][0] < run[-1][1][3] and run[-1][1][2] < bands[0][1]:
                run.append((i, bands[0]))
                continue
            close(run)
            run = []
            if len(bands) == 1:
                run = [(i, bands[0])]
            else:
                for band in bands:
                    close([(i, band)])
        close(run)
        return tuple(out)

    def _ends_at(self, x):
        """Per band: its strip holds ``x`` (mask) and its ``(lo, hi)`` there."""
        r = self._robust_bands
        x = np.asarray(x, dtype=float)[..., None]
        width = r[:, 1] - r[:, 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            f = np.where(width > 0, (x - r[:, 0]) / np.where(width > 0, width, 1.0), 0.0)
        lo = r[:, 2] + f * (r[:, 4] - r[:, 2])
        hi = r[:, 3] + f * (r[:, 5] - r[:, 3])
        return (r[:, 0] <= x) & (x <= r[:, 1]), lo, hi

    def contains(self, x, y):
        """Whether points are in the robust set (a trapezoid, its top and bottom sides excluded).

        Parameters
        ----------
        x, y : array_like
            Coordinates (broadcast together).

        Returns
        -------
        ndarray of bool
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        # A band's ends are not certified (an end is where a marked piece or
        # a sampled stable interval ends): open in y.
        holds, lo, hi = self._ends_at(x)
        return np.any(holds & (lo < y[..., None]) & (y[..., None] < hi), axis=-1)

    def intervals_at(self, x):
        """The robust intervals of ``y`` at ``x`` (those of the strips holding it, merged).

        Parameters
        ----------
        x : float
            The value of the plane's ``x``.

        Returns
        -------
        list of (float, float)
        """
        holds, lo, hi = self._ends_at(float(x))
        out = []
        for a, b in sorted(zip(lo[holds].tolist(), hi[holds].tolist(), strict=True)):
            if out and a <= out[-1][1]:
                out[-1] = (out[-1][0], max(out[-1][1], b))
            else:
                out.append((a, b))
        return out

    def limits(self):
        """The robust set's extent and area as :class:`Limits` (``region`` is this)."""
        if self.empty:
            return Limits.empty_set(self.x, self.y, self.reason, cells=0, region=self,
                                    at=self.at, line=self.intervals_at)
        r = self._robust_bands
        # The highest end is at a strip's edge.
        band, side = np.unravel_index(int(np.argmax(r[:, [3, 5]])), (len(r), 2))
        sides = set(self.unbounded)
        return Limits(self.x, self.y, np.inf if "y_max" in sides else float(r[band, 3 + 2 * side]),
                      float(r[band, side]),
                      -np.inf if "x_min" in sides else float(r[:, 0].min()),
                      np.inf if "x_max" in sides else float(r[:, 1].max()),
                      np.inf if sides else self.area, cells=len(self.polygons), region=self,
                      reason=("the robust set reaches the window's " + ", ".join(sorted(sides))
                              + " side, which the nominal set goes beyond") if sides else "",
                      at=self.at, line=self.intervals_at)

    def __repr__(self):
        box = ", ".join(f"{k} in [{lo:g}, {hi:g}]" for k, (lo, hi) in self.uncertain.items())
        if self.empty:
            return f"RobustRegion({self.x} x {self.y}, {box}: empty: {self.reason})"
        nominal = self.nominal.area if self.nominal is not None else float("nan")
        more = ", stopped at its budget" if self.exhausted else ""
        return (f"RobustRegion({self.x} x {self.y}, {box}: area {self.area:.6g} "
                f"(nominal {nominal:.6g}), marginal {self.marginal_area:.3g}, "
                f"{len(self.edges) - 1} strips{more})")

    def _repr_html_(self):
        """Jupyter's view: the box, the robust set's area beside the nominal one's, the margin."""
        rows = [(k, f"[{lo:.6g}, {hi:.6g}]") for k, (lo, hi) in self.uncertain.items()]
        if self.empty:
            rows.append(("empty", self.reason))
        else:
            rows += [("area (stable for every value)", self.area),
                     ("area at the box's centre",
                      self.nominal.area if self.nominal is not None else None),
                     ("marginal area (not certified)", self.marginal_area),
                     ("strips", len(self.edges) - 1), ("cells examined", self.examined)]
            if self.exhausted:
                rows.append(("stopped", "at its budget of cells: what was open is marginal"))
        return html_table(f"robust stable set in the ({self.x}, {self.y}) plane", rows)
