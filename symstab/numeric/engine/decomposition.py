"""The complete D-decomposition of a parameter plane: every branch, every cell, its root count.

For a loop whose characteristic polynomial is affine in two parameters,

    chi(z; x, y) = A0(z) + x Ax(z) + y Ay(z),

the number of roots outside the unit circle can change only where a root
crosses the circle (or passes through infinity).  The places where it can
happen cut the plane into *cells*:

* the **arc**: for each ``theta`` in (0, pi), ``chi(exp(j theta)) = 0`` is
  two real equations, linear in ``(x, y)``, with one solution -- a curve
  parametrised by ``theta`` over the whole of (0, pi), which may cross itself
  and run off to infinity (where the 2 x 2 system is singular) and come back;
  the paper draws only its first piece, from ``theta = 0`` to ``theta_max``;
* the **z = 1** and **z = -1** lines, ``chi(+-1) = 0`` (a real root on the
  circle), straight lines because ``chi(+-1)`` is affine in ``(x, y)``;
* the **leading** line, where the leading coefficient vanishes (a root
  through infinity; it stays outside the circle, so the count does not change
  across it, but the polynomial's degree does).

The arc's two ends are exact: as ``theta -> 0`` the equations become
``chi(1) = chi'(1) = 0`` and as ``theta -> pi`` ``chi(-1) = chi'(-1) = 0``,
two linear equations each.

:func:`decompose` samples the arc adaptively inside a window, intersects all
the pieces with each other and with the window's edges, builds the planar
graph and walks its faces: each bounded face is a :class:`Cell` (a polygon,
with holes where another piece floats inside it).  Each cell's count of
unstable roots is the certified argument-principle count
(:func:`symstab.numeric.engine.roots.root_counts`) at one interior
point, and every edge shared by two cells is checked against the crossing
rule: across the arc the count changes by 2 (a complex pair), across
``z = +-1`` by 1 and across the leading line by 0.  The stable set is the
union of the cells with count 0; its area (the Z-width when the plane is
damping and stiffness) is exact up to the chords of the sampled arc.
"""

import dataclasses
import math

import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from ..._resources import check_memory, chunk_slices
from .arcs import CramerArc
from .polynomial import DelayedPolynomial
from .results import Limits, Segment, html_table
from .roots import STABLE, classify_polynomials, leading_vanishes, root_counts
from .search import bracketed_root, refit_root, zoom_max

__all__ = ["Branch", "Cell", "Decomposition", "StableHull", "Unresolved", "decompose", "arc_points",
           "sample_arc", "window_arc", "stable_hull", "stable_ranges"]

#: The margin (of coefficients scaled to their largest term) below which
#: :func:`stable_ranges` calls a box empty: far past HiGHS's 1e-7 tolerance.
_LP_MARGIN = 1e-6
#: Change of the unstable count across each piece (crossing rule); the
#: window's edges are labelled ``"window"``.
_CHANGE = {"arc": 2, "z = 1": 1, "z = -1": 1, "leading": 0}
#: Longest chord of the sampled arc, as a fraction of the window.
_CHORD = 2e-3
#: Largest turn between two chords of the arc (radians), unless both are
#: shorter than _TURN_FLOOR (a fraction of the window): a loop smaller than
#: that is not followed turn by turn (its sag is below 1e-6 of the window).
_TURN = 0.05
_TURN_FLOOR = 1e-4
#: Rounds of arc refinement and points the arc may have in all.
_ROUNDS = 40
_MAX_ARC_POINTS = 400_000
#: Rounds of refinement of the arc where it crosses a piece, and the angle
#: step it stops at.
_CROSSING_ROUNDS = 6
_CROSSING_GAP = 1e-9
#: Distance (in units of the window) within which two nodes are one.
_MERGE = 1e-10
#: Largest sag of the arc's chords on a stable cell's boundary, as a
#: fraction of the cell's thinner extent.
_RESOLUTION = 1e-3
#: Smallest extent of a stable cell, as a fraction of the window's.
_SMALLEST = 1e-5
#: Most pairs of chords one decomposition may intersect.
_MAX_PAIRS = 20_000_000
#: Smallest area of a cell, as a fraction of the window's (a cycle of the
#: graph with less is a path walked there and back, not a cell).
_AREA = 1e-24
#: Relative width in theta to which an extreme of the arc is searched: the
#: extreme's value is then exact to rounding (it is flat there).
_EXTREME_RTOL = 1e-12
#: Tolerance on the segment parameters of an intersection.
_ENDS = 1e-9
#: Distance (in units of the window) within which a vertex is on a line and
#: an arc chord (a corner), and the most a corner may move when re-found on
#: the arc (a chord's sag is far below it).
_CORNER = 1e-9
_CORNER_MOVE = 1e-4


@dataclasses.dataclass(frozen=True, repr=False)
class Branch:
    """One piece of the D-decomposition, clipped to nothing: as sampled.

    Attributes
    ----------
    label : str
        ``"arc"``, ``"z = 1"``, ``"z = -1"`` or ``"leading"``.
    points : ndarray, shape (n, 2)
        ``(x, y)`` along the piece; rows of NaN separate its parts (where the
        arc runs off to infinity).
    theta : ndarray or None
        The arc's angle at each point (NaN at the separators); None for a line.
    """

    label: str
    points: np.ndarray
    theta: object = None

    def __repr__(self):
        parts = 1 + int(np.sum(np.isnan(self.points[:, 0])))
        return f"Branch({self.label!r}, {len(self.points)} points, {parts} part(s))"


@dataclasses.dataclass(frozen=True, repr=False)
class Cell:
    """A cell of the D-decomposition: a polygon on which the root count is constant.

    Attributes
    ----------
    outer : ndarray, shape (n, 2)
        The boundary, counter-clockwise, not closed (the last vertex is not
        the first again).
    holes : tuple of ndarray
        Boundaries of the holes, clockwise.
    count : int
        Closed-loop roots outside the unit circle inside the cell
        (certified; where the certified bounds cannot close, a stable cell is
        still recognised by the Schur-Cohn test with a safe margin).  A cell
        whose count cannot be decided either way is an error
        (:func:`decompose` raises), not a count.
    point : tuple of float
        The interior point where ``count`` was computed.
    area : float
        Area of the cell (holes excluded).
    """

    outer: np.ndarray
    holes: tuple
    count: int
    point: tuple
    area: float

    def __repr__(self):
        holes = f", {len(self.holes)} hole(s)" if self.holes else ""
        return (f"Cell(count={self.count}, area={self.area:.6g}, {len(self.outer)} vertices{holes}, "
                f"point=({self.point[0]:.6g}, {self.point[1]:.6g}))")

    def contains(self, x, y):
        """Whether points lie inside the cell.

        Parameters
        ----------
        x, y : array_like
            Coordinates (broadcast together).

        Returns
        -------
        ndarray of bool
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        inside = _inside(self.outer, x, y)
        for hole in self.holes:
            inside &= ~_inside(hole, x, y)
        return inside


#: What an empty decomposition does not exclude (the hull, when empty, is a proof).
_UNRESOLVED = (" (a stable sliver too thin for the sampled arc to draw, as next to a point "
               "where the set vanishes, is not excluded)")


@dataclasses.dataclass(frozen=True, repr=False)
class Decomposition:
    """The D-decomposition of an ``(x, y)`` plane inside a window.

    Attributes
    ----------
    x, y : str
        The plane's parameters.
    x_range, y_range : tuple of float
        The window.
    branches : tuple of Branch
        Every piece: the arc over all of (0, pi) and the lines.
    cells : tuple of Cell
        The cells the pieces cut the window into.
    mismatches : tuple
        ``(i, j, label, change)`` for each pair of neighbouring cells whose
        counts break the crossing rule across a piece ``label`` (empty when
        every count is consistent).
    unbounded : tuple of str
        The window's sides (``"x_min"``, ``"x_max"``, ``"y_min"``,
        ``"y_max"``) that a stable cell touches: the stable set may go on
        beyond them.
    polynomial : tuple of ndarray
        ``(A0, Ax, Ay)``, the coefficients the decomposition is of.
    resolution : float
        The largest sag of the sampled arc's chords on a stable cell's
        boundary (chord length times turn over 8), as a fraction of the
        cell's thinner extent (:func:`decompose` keeps it below 1e-3).
    hull : StableHull or None
        The proved enclosure of the stable set the window was chosen from
        (:meth:`symstab.Loop.region`); when it is empty the decomposition has
        no cells: no point of the plane is stable, and none was sampled.
    arc : symstab.numeric.engine.arcs.ArcSource or None
        The source the arc was sampled from (None: the structured Cramer
        solve of :attr:`polynomial`).
    segments : tuple of symstab.numeric.engine.results.Segment
        The pieces of the z = 1 and z = -1 lines that bound the stable set
        (a stable cell's edges on them: across such a line the count
        changes, so the other side is unstable), joined where they meet,
        each end where the arc meets the line re-found on the arc.  An end
        on a side of the window in :attr:`unbounded` is where the window
        cuts the piece, not where it ends.  Empty in a decomposition made
        with ``segments=False`` (:func:`decompose`) until
        :meth:`with_segments`.
    _pending : tuple
        Private: what :meth:`with_segments` makes the segments of (each
        line's ``(c0, cx, cy)`` and the ``(label, ends)`` of the stable
        cells' pieces on z = +-1), empty once they are made.
    """

    x: str
    y: str
    x_range: tuple
    y_range: tuple
    branches: tuple
    cells: tuple
    mismatches: tuple
    unbounded: tuple
    polynomial: tuple = dataclasses.field(default=(), compare=False)
    resolution: float = 0.0
    hull: object = dataclasses.field(default=None, compare=False)
    arc: object = dataclasses.field(default=None, compare=False)
    segments: tuple = ()
    _pending: tuple = dataclasses.field(default=(), compare=False, repr=False)

    def plot(self, ax=None, **kwargs):
        """Draw the decomposition: :func:`symstab.drawing.plot_region`.

        The stable set filled, the arc and the lines, and each cell's number
        of unstable closed-loop poles where it has room.

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

        Examples
        --------
        >>> import symstab
        >>> drawn = symstab.PAPER_LOOP.region(d=40).plot()      # doctest: +SKIP
        >>> drawn.figure.savefig("region.png")                  # doctest: +SKIP
        """
        from ...drawing import plot_region

        return plot_region(self, ax, **kwargs)

    @property
    def stable(self):
        """The cells with no root outside the unit circle."""
        return tuple(c for c in self.cells if c.count == 0)

    @property
    def area(self):
        """Area of the stable set inside the window (the Z-width for damping and stiffness)."""
        return float(sum(c.area for c in self.stable))

    def contains(self, x, y):
        """Whether points lie in the stable set.

        Parameters
        ----------
        x, y : array_like
            Coordinates (broadcast together).

        Returns
        -------
        ndarray of bool
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        out = np.zeros(x.shape, dtype=bool)
        for cell in self.stable:
            out |= cell.contains(x, y)
        return out

    def count_at(self, x, y):
        """The unstable count of the cell containing each point.

        Parameters
        ----------
        x, y : array_like
            Coordinates (broadcast together).

        Returns
        -------
        ndarray of int
            The cell's count; -2 outside every cell (on a boundary, or
            outside the window).
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        out = np.full(x.shape, -2, dtype=np.int64)
        for cell in self.cells:
            out[cell.contains(x, y)] = cell.count
        return out

    def extreme(self, coordinate, sense=1):
        """The largest (``sense=1``) or smallest (``sense=-1``) coordinate of the stable set.

        The extreme vertex of the stable cells; where it is a corner (the arc
        meets a line), re-found on the arc; where it is a smooth turn of the
        arc (its neighbours along the arc are on the same cell's boundary),
        refined along the arc by a zooming grid in theta (search.zoom_max).

        Parameters
        ----------
        coordinate : {"x", "y"}
            Which coordinate.
        sense : {1, -1}
            Maximum or minimum.

        Returns
        -------
        value, other : float
            The extreme value and the other coordinate where it is reached
            (NaN, NaN if the stable set is empty).
        """
        if coordinate not in ("x", "y") or sense not in (1, -1):
            raise ValueError(f"coordinate must be 'x' or 'y' and sense 1 or -1, got "
                             f"{coordinate!r}, {sense!r}")
        k = 0 if coordinate == "x" else 1
        best, cell_of = None, None
        for cell in self.stable:
            i = int(np.argmax(sense * cell.outer[:, k]))
            if best is None or sense * cell.outer[i, k] > sense * best[k]:
                best, cell_of = cell.outer[i], cell
        if best is None:
            return math.nan, math.nan
        arc = next((b for b in self.branches if b.label == "arc"), None)
        value, other = float(best[k]), float(best[1 - k])
        if arc is None or not self.polynomial:
            return value, other
        scale = np.array([self.x_range[1] - self.x_range[0], self.y_range[1] - self.y_range[0]])
        corner = self._corner(arc, best, scale)
        if corner is not None:
            return float(corner[k]), float(corner[1 - k])
        near = np.hypot(*((arc.points - best) / scale).T)
        j = int(np.nanargmin(near)) if np.isfinite(near).any() else -1
        if j < 1 or j >= len(arc.points) - 1 or near[j] > 1e-9:
            return value, other
        neighbours = arc.points[[j - 1, j + 1]]
        theta = arc.theta[[j - 1, j + 1]]
        if not np.all(np.isfinite(theta)):
            return value, other
        on_ring = [np.min(np.hypot(*((cell_of.outer - q) / scale).T)) < 1e-9 for q in neighbours]
        if not all(on_ring):
            return value, other
        arc = self.arc if self.arc is not None else CramerArc(*self.polynomial)

        def f(t, _):
            return sense * arc(t.ravel())[k].reshape(t.shape)

        t = float(zoom_max(f, [theta[0]], [theta[1]], rtol=_EXTREME_RTOL)[0])
        xy = [float(v[0]) for v in arc(np.array([t]))[:2]]
        # The arc's own extreme, if it is not cut off by a line the cell is on one side of.
        beside = all(side(np.array(xy)) * side(np.array(cell_of.point)) >= 0
                     or abs(side(np.array(xy))) <= _CORNER for _, side in self._sides(scale))
        if sense * xy[k] >= sense * value and beside:
            return xy[k], xy[1 - k]
        return value, other

    def _sides(self, scale):
        """``(branch, side)`` per line: ``side(points)``, the signed distance in window units."""
        for line in self.branches:
            if line.label == "arc":
                continue
            ends = line.points[np.all(np.isfinite(line.points), axis=1)]
            if len(ends) < 2:
                continue
            origin, direction = ends[0] / scale, (ends[-1] - ends[0]) / scale
            length = float(np.hypot(*direction))
            if length == 0:
                continue
            normal = np.array([-direction[1], direction[0]]) / length
            yield line, (lambda points, origin=origin, normal=normal:
                         (points / scale - origin) @ normal)

    def _corner(self, arc, vertex, scale):
        """A vertex where the arc meets a line, re-found on the arc: ``(x, y)`` or None.

        The chords' crossing is off the curves' by the chord's sag (1e-10
        to 1e-8 of the window); here the arc's angle between the chord's
        ends is the root of the line's equation along it (the source's own
        accuracy, 1e-13).  A vertex at an end of the arc (``theta = 0`` or
        ``pi``, on ``z = +-1``) is that end, from the arc source.  None where
        ``vertex`` is neither on one line and one arc chord nor at an end.
        """
        # The arc's ends (theta = 0, pi) are on z = +-1, and exact.
        at_end = np.flatnonzero(np.isin(arc.theta, (0.0, np.pi)))
        if at_end.size:
            gap = np.hypot(*((arc.points[at_end] - vertex) / scale).T)
            if gap.min() < _CORNER:
                return arc.points[at_end[int(np.argmin(gap))]].copy()
        unit = vertex / scale
        for _, side in self._sides(scale):
            if abs(float(side(vertex))) > _CORNER:
                continue
            # The arc's chords through the vertex that cross the line.
            g = side(arc.points)
            a, b = arc.points[:-1] / scale, arc.points[1:] / scale
            t = np.clip(np.einsum("ij,ij->i", unit - a, b - a)
                        / np.maximum(np.einsum("ij,ij->i", b - a, b - a), 1e-300), 0.0, 1.0)
            gap = np.hypot(*(a + t[:, None] * (b - a) - unit).T)
            crossing = (np.sign(g[:-1]) * np.sign(g[1:]) < 0) & (gap < _CORNER)
            if not crossing.any():
                continue
            j = int(np.flatnonzero(crossing)[np.argmin(gap[crossing])])
            source = self.arc if self.arc is not None else CramerArc(*self.polynomial)

            def along(theta, source=source, side=side):
                xs, ys = source(theta.ravel())[:2]
                return side(np.column_stack([xs, ys])).reshape(theta.shape)

            root = bracketed_root(along, [arc.theta[j]], [arc.theta[j + 1]])[0]
            # The line's equation along the arc is a difference of larger
            # terms next to a flat corner: fitted over 2e-3 of the chord
            # around the root, its rounding floor averages out.
            width = max(1e-3 * (arc.theta[j + 1] - arc.theta[j]), 64 * np.spacing(root))
            root = refit_root(along, root, width)
            xs, ys = source(np.array([root]))[:2]
            point = np.array([float(xs[0]), float(ys[0])])
            if np.all(np.isfinite(point)) and float(np.hypot(*((point - vertex) / scale))) < _CORNER_MOVE:
                return point
        return None

    def limits(self, *, at=None, line=None):
        """The extent and area of the stable set, read from this decomposition.

        The stable cells' polygons give the area (exact up to the chords of
        the sampled arc), their extreme vertices the extent (:meth:`extreme`,
        refined along the arc where the extreme is a smooth turn of it); a
        side in :attr:`unbounded` makes its extreme, and the area, infinite.

        Parameters
        ----------
        at : dict, optional
            The values of the other parameters (:attr:`Limits.at`).
        line : callable, optional
            ``line(x) -> [(lo, hi), ...]``, the stable intervals of ``y`` at
            ``x`` (:attr:`Limits.line`).

        Returns
        -------
        symstab.numeric.engine.results.Limits
            Empty, with the reason, when no cell is stable.
        """
        at = {} if at is None else at
        if not self.stable:
            return Limits.empty_set(self.x, self.y, "the stable set is empty: " + self._why_empty(),
                                    cells=0, at=at, line=line, decomposition=self)
        (y_max, x_at), (x_min, _), (x_max, _) = (self.extreme(*which) for which in
                                                  (("y", 1), ("x", -1), ("x", 1)))
        sides = set(self.unbounded)
        y_max = np.inf if "y_max" in sides else y_max
        x_min = -np.inf if "x_min" in sides else x_min
        x_max = np.inf if "x_max" in sides else x_max
        area = np.inf if sides else self.area
        return Limits(self.x, self.y, float(y_max), float(x_at), float(x_min), float(x_max),
                      float(area), cells=len(self.stable), at=at, line=line, decomposition=self)

    def _why_empty(self):
        """Why no cell is stable: the hull's proof, or what the window held."""
        hull = self.hull
        if hull is not None and hull.empty:
            return hull.reason
        where = (f"{self.x} in [{self.x_range[0]:.6g}, {self.x_range[1]:.6g}], {self.y} in "
                 f"[{self.y_range[0]:.6g}, {self.y_range[1]:.6g}]")
        box = hull.box(0.0) if hull is not None else None
        if box is not None and all(w[0] <= b[0] and b[1] <= w[1]
                                   for w, b in zip((self.x_range, self.y_range), box, strict=True)):
            return (f"every cell of the window {where}, which holds every point that passes the "
                    f"necessary condition of the roots inside the unit circle, has a root "
                    f"outside it{_UNRESOLVED}")
        return f"every cell of the window {where} has a root outside the unit circle{_UNRESOLVED}"

    def with_segments(self):
        """This decomposition with its :attr:`segments` made, where ``decompose`` left them.

        Re-finding their ends on the arc costs a root search each: a caller
        that decomposes several windows and keeps one (:meth:`symstab.Loop.region`)
        makes them for that one only.

        Returns
        -------
        Decomposition
        """
        if not self._pending:
            return self
        lines, pieces = self._pending
        segments = [self._segment(label, lines, ends) for label, ends in pieces]
        segments.sort(key=lambda g: (g.root != "z=1", g.x0))
        return dataclasses.replace(self, segments=tuple(segments), _pending=())

    def renamed(self, x, y):
        """The same decomposition with the plane's parameters called ``x`` and ``y``.

        Parameters
        ----------
        x, y : str
            The new names.
        """
        segments = tuple(dataclasses.replace(g, x=x, y=y) for g in self.segments)
        return dataclasses.replace(self, x=x, y=y, segments=segments)

    def _segment(self, label, lines, ends):
        """The :class:`~symstab.numeric.engine.results.Segment` of line ``label`` between two cell vertices.

        An end where the arc meets the line is re-found on the arc
        (:meth:`_corner`), one where the other of z = +-1 crosses it is the
        two lines' crossing; every end is then put on the line exactly
        (``y`` from ``x``, or ``x`` from ``y`` for a line steep in the
        window), so a piece of ``y = 0`` has ``y`` 0, not a rounding of it.
        ``lines`` holds each line's ``(c0, cx, cy)``.
        """
        arc = next((b for b in self.branches if b.label == "arc"), None)
        sx, sy = self.x_range[1] - self.x_range[0], self.y_range[1] - self.y_range[0]
        c0, cx, cy = lines[label]
        points = []
        for end in ends:
            corner = self._corner(arc, end, np.array([sx, sy])) if arc is not None else None
            u, v = (float(w) for w in (end if corner is None else corner))
            other = lines["z = 1" if label == "z = -1" else "z = -1"]
            e0, ex, ey = other
            det = cx * ey - cy * ex
            if det != 0 and abs(e0 + ex * u + ey * v) <= _CORNER * math.hypot(ex * sx, ey * sy):
                u, v = (-c0 * ey + cy * e0) / det, (-cx * e0 + c0 * ex) / det
            elif abs(cy) * sy >= abs(cx) * sx:
                v = -(c0 + cx * u) / cy
            else:
                u = -(c0 + cy * v) / cx
            points.append((u + 0.0, v + 0.0))
        (u0, v0), (u1, v1) = sorted(points)
        return Segment(label.replace(" ", ""), u0, v0, u1, v1, self.x, self.y)

    def __repr__(self):
        counts = sorted({c.count for c in self.cells})
        where = (f"Decomposition({self.x} in [{self.x_range[0]:.6g}, {self.x_range[1]:.6g}], "
                 f"{self.y} in [{self.y_range[0]:.6g}, {self.y_range[1]:.6g}]: ")
        if self.hull is not None and self.hull.empty and not self.cells:
            return where + "no point of the plane is stable)"
        return where + (f"{len(self.cells)} cells, counts {counts}, {len(self.stable)} stable, "
                        f"stable area {self.area:.6g})")

    def _repr_html_(self):
        """Jupyter's view: the window, the stable set's area and the cells per root count."""
        rows = [(self.x, f"[{self.x_range[0]:.6g}, {self.x_range[1]:.6g}]"),
                (self.y, f"[{self.y_range[0]:.6g}, {self.y_range[1]:.6g}]"),
                ("stable area", self.area), ("stable cells", len(self.stable))]
        counts = sorted({c.count for c in self.cells})
        rows += [(f"cells with {n} unstable pole{'s' if n != 1 else ''}",
                  sum(c.count == n for c in self.cells)) for n in counts]
        if self.unbounded:
            rows.append(("stable set reaches", ", ".join(self.unbounded)))
        if self.hull is not None and self.hull.empty and not self.cells:
            rows.append(("no point is stable", self.hull.reason))
        return html_table(f"D-decomposition of the ({self.x}, {self.y}) plane", rows)


# --------------------------------------------------------------------------
# The pieces


def arc_points(base, ax, ay, theta):
    """The arc: the ``(x, y)`` at which ``exp(j theta)`` is a root, and the system's determinant.

    ``base + x ax + y ay`` vanishes there: its real and imaginary parts are
    two linear equations in ``(x, y)``, solved by Cramer's rule with the
    factor ``sin(theta)`` of every determinant divided out exactly
    (:class:`symstab.numeric.engine.arcs.CramerArc`, accurate to about 1e-13 also
    next to ``theta = 0`` and ``pi``).  NaN where the system is singular
    (the arc runs off to infinity).

    Parameters
    ----------
    base, ax, ay : ndarray or DelayedPolynomial
        Coefficient rows of ``A0``, ``Ax``, ``Ay`` (highest power first),
        or the structured polynomials of a loop's plane (a common shift).
    theta : array_like
        Angles in (0, pi).

    Returns
    -------
    x, y, det : ndarray
        ``det`` is the determinant over ``sin(theta)`` (its sign, which
        tells the branches apart, is the determinant's on (0, pi)).
    """
    return CramerArc(base, ax, ay)(theta)


def lines(base, ax, ay, ends):
    """``{"z = 1": (c0, cx, cy), "z = -1": ..., "leading": ...}``: ``c0 + cx x + cy y = 0``.

    ``ends`` holds the values at ``z = 1`` and ``z = -1`` of ``A0``, ``Ax``
    and ``Ay`` (three pairs); the leading line is the leading coefficients.
    """
    out = {label: tuple(float(e[index]) for e in ends)
           for index, label in enumerate(("z = 1", "z = -1"))}
    out["leading"] = (float(base[0]), float(ax[0]), float(ay[0]))
    return out


def sample_arc(arc, n, to_unit, samples=None, fine=1.0):
    """The arc's adaptive samples: refined until every chord near the window is short and straight.

    The one sampler of an arc in a window (the D-decomposition's, the
    figures'): a grid of ``max(1024, 32 (n + 4))`` angles, closing in on
    ``theta = 0`` and ``pi`` geometrically, then halved where a chord near
    the window is longer than 2e-3 of it, turns by more than 0.05 rad
    from the next, or passes through infinity (the determinant changes
    sign), up to 400 000 angles.

    Parameters
    ----------
    arc : symstab.numeric.engine.arcs.ArcSource
        ``arc(theta) -> (x, y, det)``.
    n : int
        The polynomial's degree.
    to_unit : callable
        ``to_unit(x, y) -> (u, v)``: window units, the window being [0, 1]**2.
    samples : tuple, optional
        The ``(theta, x, y, det)`` of a previous call with more angles
        added (NaN where not yet evaluated): only those are evaluated.
    fine : float
        The chord and turn limits' factor.

    Returns
    -------
    theta, x, y, det : ndarray
        Increasing angles in (0, pi) and the arc there (split the arc where
        ``det`` changes sign: through infinity).
    """
    if samples is None:
        m = max(1024, 32 * (n + 4))
        theta = np.pi * np.arange(1, m) / m
        # The chords to the exact ends (theta = 0, pi), added by _pieces, are
        # never split: angles closing in on both ends geometrically keep them
        # short (from theta = 0 to pi / m the arc can cross a good part of a
        # small stable cell at its corner).
        near = theta[0] * np.geomspace(1e-6, 1.0, 20, endpoint=False)
        theta = np.concatenate([near, theta, np.pi - near[::-1]])
        xs, ys, det = arc(theta)
    else:
        theta, xs, ys, det = (np.array(a, dtype=float) for a in samples)
        new = np.isnan(det)
        if new.any():
            xs[new], ys[new], det[new] = arc(theta[new])
    for _ in range(_ROUNDS):
        u, v = to_unit(xs, ys)
        finite = np.isfinite(u) & np.isfinite(v)
        du, dv = np.diff(u), np.diff(v)
        length = np.hypot(du, dv)
        both = finite[1:] & finite[:-1]
        # A chord matters if it may pass near the window (padded by its length).
        lo_u, hi_u = np.minimum(u[1:], u[:-1]), np.maximum(u[1:], u[:-1])
        lo_v, hi_v = np.minimum(v[1:], v[:-1]), np.maximum(v[1:], v[:-1])
        near = both & (hi_u > -0.5) & (lo_u < 1.5) & (hi_v > -0.5) & (lo_v < 1.5)
        split = near & (length > _CHORD * fine)
        # A sharp turn between two chords near the window: refine both.  (The
        # headings only of the chords near it: the arc may run far beyond it.)
        pair = np.flatnonzero(near[1:] & near[:-1])
        angle = np.zeros(len(du))
        with np.errstate(invalid="ignore", divide="ignore"):
            angle[near] = np.arctan2(dv[near], du[near])
        sharp = np.zeros(max(len(near) - 1, 0), dtype=bool)
        sharp[pair] = (_turns_over(angle[pair + 1] - angle[pair], _TURN)
                       & (length[pair + 1] + length[pair] > _TURN_FLOOR * fine**2))
        split[1:] |= sharp
        split[:-1] |= sharp
        # Through infinity, or into a singular point: follow it closer.
        flip = (np.sign(det[1:]) != np.sign(det[:-1])) | (finite[1:] != finite[:-1])
        split |= flip & (np.diff(theta) > 1e-13)
        split &= np.diff(theta) > 4e-16 * np.pi
        if not split.any():
            break
        if len(theta) + int(split.sum()) > _MAX_ARC_POINTS:
            break
        mids = 0.5 * (theta[1:] + theta[:-1])[split]
        order = np.argsort(np.concatenate([theta, mids]), kind="stable")
        theta, xs, ys, det = (np.concatenate([a, b])[order]
                              for a, b in zip((theta, xs, ys, det), (mids, *arc(mids)),
                                              strict=True))
    return theta, xs, ys, det


def _turns_over(change, limit):
    """Whether the turns ``change`` (differences of headings in [-pi, pi]) exceed ``limit`` (< 1).

    ``abs(angle(exp(1j change))) > limit``, the turn taken the short way
    round, decided bit for bit as that expression decides it: computed so
    only where ``|change|`` is within 1e-6 of ``limit`` or of ``2 pi -
    limit`` (elsewhere the rounding of the complex exponential cannot
    move it across ``limit``), at a fraction of its cost.
    """
    size = np.abs(change)
    over = (size > limit) & (size < 2 * np.pi - limit)
    close = (np.abs(size - limit) < 1e-6) | (np.abs(size - (2 * np.pi - limit)) < 1e-6)
    if close.any():
        over[close] = np.abs(np.angle(np.exp(1j * change[close]))) > limit
    return over


def window_arc(arc, n, x_range, y_range, *, angles=()):
    """The arc to draw in a window: :func:`sample_arc`'s angles, NaN far from the window.

    Parameters
    ----------
    arc : symstab.numeric.engine.arcs.ArcSource
        ``arc(theta) -> (x, y, det)``.
    n : int
        The polynomial's degree.
    x_range, y_range : (float, float)
        The window.
    angles : sequence of float
        More angles to have among the samples (an end of a piece to draw).

    Returns
    -------
    theta, x, y : ndarray
        Increasing angles in (0, pi) and the arc there; NaN where it is not
        finite or more than five window widths away (through a pole the arc
        runs to infinity and comes back from the other side: a straight
        chord across would be drawn).
    """
    (x0, x1), (y0, y1) = x_range, y_range
    sx, sy = x1 - x0, y1 - y0
    theta, xs, ys, _ = sample_arc(arc, n, lambda x, y: ((np.asarray(x) - x0) / sx,
                                                        (np.asarray(y) - y0) / sy))
    extra = np.setdiff1d(np.asarray(angles, dtype=float), theta)
    if extra.size:
        order = np.argsort(np.concatenate([theta, extra]), kind="stable")
        more = arc(extra)
        theta, xs, ys = (np.concatenate([a, b])[order] for a, b in
                         zip((theta, xs, ys), (extra, more[0], more[1]), strict=True))
    with np.errstate(invalid="ignore"):
        far = ~(np.isfinite(xs) & np.isfinite(ys)) \
            | (xs < x0 - 5 * sx) | (xs > x1 + 5 * sx) | (ys < y0 - 5 * sy) | (ys > y1 + 5 * sy)
    xs, ys = np.where(far, np.nan, xs), np.where(far, np.nan, ys)
    return theta, xs, ys


def _pieces(base, ax, ay, ends, arc_ends, theta, xs, ys, sign, to_unit, from_unit, box):
    """The branches (in the plane's units) and the polylines to intersect (in window units).

    Each polyline is ``(points, label, theta)`` (``theta`` None for a line
    and for the window's edges), cut to the runs of segments that reach the
    window.  The arc's ends at ``theta = 0`` and ``pi``, ``arc_ends = (x,
    y)``, are the arc source's (there its equations are ``chi(+-1) =
    chi'(+-1) = 0``), None where that system is singular.
    """
    polylines, branches = [], []
    u, v = to_unit(xs, ys)
    finite = np.isfinite(u) & np.isfinite(v)
    end_x, end_y = arc_ends
    ends_xy = [(x, y) if math.isfinite(x) and math.isfinite(y) else None
               for x, y in zip(end_x.tolist(), end_y.tolist(), strict=True)]
    cut = np.flatnonzero((sign[1:] != sign[:-1]) | ~finite[1:] | ~finite[:-1]) + 1
    arc_rows, arc_theta = [], []
    for part in np.split(np.arange(len(theta)), cut):
        part = part[finite[part]]
        if len(part) == 0:
            continue
        pts = np.column_stack([u[part], v[part]])
        th = theta[part]
        # The exact ends at theta = 0 and pi, when this part reaches them
        # (kept as they are in the branch, not taken back from window units).
        rows = from_unit(pts)
        if part[0] == 0 and ends_xy[0] is not None:
            pts = np.vstack([np.column_stack(to_unit(*ends_xy[0])), pts])
            rows = np.vstack([ends_xy[0], rows])
            th = np.concatenate([[0.0], th])
        if part[-1] == len(theta) - 1 and ends_xy[1] is not None:
            pts = np.vstack([pts, np.column_stack(to_unit(*ends_xy[1]))])
            rows = np.vstack([rows, ends_xy[1]])
            th = np.concatenate([th, [np.pi]])
        arc_rows.append(rows)
        arc_theta.append(th)
        if len(pts) >= 2:
            polylines.append((pts, "arc", th))
    if arc_rows:
        gap = np.full((1, 2), np.nan)
        branches.append(Branch("arc", np.vstack(sum(([r, gap] for r in arc_rows), [])[:-1]),
                               np.concatenate(sum(([t, [np.nan]] for t in arc_theta), [])[:-1])))
    for label, c in lines(base, ax, ay, ends).items():
        if not (c[1] or c[2]):
            continue
        seg = _clip_line(c, box)
        if seg is None:
            continue
        branches.append(Branch(label, seg))
        polylines.append((np.column_stack(to_unit(seg[:, 0], seg[:, 1])), label, None))
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]], dtype=float)
    polylines.append((square, "window", None))
    # Keep only the runs of segments that reach the window.
    kept = []
    for pts, label, th in polylines:
        lo, hi = np.minimum(pts[1:], pts[:-1]), np.maximum(pts[1:], pts[:-1])
        near = ((hi[:, 0] >= -1e-9) & (lo[:, 0] <= 1 + 1e-9)
                & (hi[:, 1] >= -1e-9) & (lo[:, 1] <= 1 + 1e-9))
        idx = np.flatnonzero(near)
        for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if len(idx) else ():
            keep = slice(run[0], run[-1] + 2)
            kept.append((pts[keep], label, None if th is None else th[keep]))
    return kept, tuple(branches)


def _clip_line(c, box):
    """The segment of ``c0 + cx x + cy y = 0`` inside ``box`` (x0, x1, y0, y1), or None."""
    c0, cx, cy = c
    x0, x1, y0, y1 = box
    points = []
    if cy != 0:
        for xv in (x0, x1):
            points.append((xv, -(c0 + cx * xv) / cy))
    if cx != 0:
        for yv in (y0, y1):
            points.append((-(c0 + cy * yv) / cx, yv))
    sx, sy = x1 - x0, y1 - y0
    inside = [(px, py) for px, py in points
              if x0 - 1e-9 * sx <= px <= x1 + 1e-9 * sx and y0 - 1e-9 * sy <= py <= y1 + 1e-9 * sy]
    if len(inside) < 2:
        return None
    inside.sort()
    return np.array([inside[0], inside[-1]])


# --------------------------------------------------------------------------
# The planar graph


class _Nodes:
    """Points of the plane (window units), merged when closer than :data:`_MERGE`."""

    def __init__(self):
        self.xy = []
        self._grid = {}

    def add(self, u, v):
        key = (math.floor(u / _MERGE), math.floor(v / _MERGE))
        for du in (-1, 0, 1):
            for dv in (-1, 0, 1):
                for index in self._grid.get((key[0] + du, key[1] + dv), ()):
                    pu, pv = self.xy[index]
                    if abs(pu - u) <= _MERGE and abs(pv - v) <= _MERGE:
                        return index
        self.xy.append((u, v))
        self._grid.setdefault(key, []).append(len(self.xy) - 1)
        return len(self.xy) - 1


def _merged_nodes(points):
    """The node of each of ``points`` (rows, in order), as :class:`_Nodes` would add them.

    Returns ``(node, xy)``: the node index of each point and the nodes'
    points, numbered in the order of the points that made them.  A point
    given again is its node again, and a point with no other within
    :data:`_MERGE` is a node of its own: only the few points that have a
    close neighbour are merged one by one, by :class:`_Nodes`, in their
    order (the tens of thousands of chords' ends of a finely sampled arc
    would take seconds there).
    """
    # np.unique(points, axis=0, return_index=True, return_inverse=True) by hand: a
    # stable sort by x then y (np.unique along rows sorts a structured view, slower).
    order = np.lexsort((points[:, 1], points[:, 0]))
    ordered = points[order]
    fresh = np.ones(len(ordered), dtype=bool)      # (empty where there are no points)
    fresh[1:] = (ordered[1:, 0] != ordered[:-1, 0]) | (ordered[1:, 1] != ordered[:-1, 1])
    unique, first = ordered[fresh], order[fresh]
    inverse = np.empty(len(points), dtype=np.intp)
    inverse[order] = np.cumsum(fresh) - 1
    close = _has_close_neighbour(unique)
    made = ~close        # the unique points that make a node
    merged = np.arange(len(unique))
    greedy, made_by = _Nodes(), []
    for u in np.flatnonzero(close)[np.argsort(first[close], kind="stable")]:
        index = greedy.add(float(unique[u, 0]), float(unique[u, 1]))
        if index == len(made_by):
            made_by.append(u)
            made[u] = True
        merged[u] = made_by[index]
    makers = np.flatnonzero(made)
    makers = makers[np.argsort(first[makers], kind="stable")]
    number = np.empty(len(unique), dtype=np.int64)
    number[makers] = np.arange(len(makers))
    return number[merged][inverse], unique[makers]


#: Largest table of box comparisons :func:`_pairs_with` makes (segments chosen times all).
_MAX_PAIRS_WITH = 4_000_000


#: Neighbours in x compared at most, before the points of a vertical run are all merged one by one.
_MAX_SHIFTS = 64


def _has_close_neighbour(xy):
    """Whether each of the distinct points ``xy`` has another within :data:`_MERGE` (max norm)."""
    close = np.zeros(len(xy), dtype=bool)
    order = np.argsort(xy[:, 0], kind="stable")
    x, y = xy[order, 0], xy[order, 1]
    shift = 1
    while shift < len(xy):
        near_x = x[shift:] - x[:-shift] <= _MERGE
        if not near_x.any():
            break
        if shift > _MAX_SHIFTS:
            # Many points on one vertical: every point with an x-neighbour
            # that close is merged one by one (the same nodes, just slower).
            run = np.r_[x[1:] - x[:-1] <= _MERGE, False] | np.r_[False, x[1:] - x[:-1] <= _MERGE]
            close[order[run]] = True
            break
        near = near_x & (np.abs(y[shift:] - y[:-shift]) <= _MERGE)
        close[order[shift:][near]] = True
        close[order[:-shift][near]] = True
        shift += 1
    return close


def _segments(polylines):
    """Flatten polylines into segments: start, end, polyline index, position in it."""
    starts, ends, owner, position = [], [], [], []
    for k, (points, _, _) in enumerate(polylines):
        count = len(points) - 1
        starts.append(points[:-1])
        ends.append(points[1:])
        owner.append(np.full(count, k))
        position.append(np.arange(count))
    return (np.concatenate(starts), np.concatenate(ends), np.concatenate(owner),
            np.concatenate(position))


def _candidate_pairs(lo, hi):
    """Pairs ``i < j`` of segments whose bounding boxes overlap.

    Short segments (the sampled arc) are hashed into a grid of cells as
    large as the longest of them, so each lies in at most four cells and
    only segments sharing a cell are paired; the few long ones (the lines,
    the window's edges) are paired with every segment whose box meets
    theirs.  The pairs are taken in one step each (a pair's boxes are
    compared before it is sorted: a long piece meets few of the arc's
    thousand chords).
    """
    n = len(lo)
    extent = np.maximum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
    long_ = extent > 0.02
    short = np.flatnonzero(~long_)
    pairs = []
    if len(short):
        h = max(float(np.max(extent[short])), 1e-6)
        # The cells of a box's four corners (columns compared one by one:
        # NumPy's any along a row of three is slow).
        x = np.floor(np.concatenate([lo[short, 0], lo[short, 0], hi[short, 0], hi[short, 0]])
                     / h).astype(np.int64)
        y = np.floor(np.concatenate([lo[short, 1], hi[short, 1], lo[short, 1], hi[short, 1]])
                     / h).astype(np.int64)
        segment = np.tile(short, 4)
        # Sorted by cell, then segment, each (cell, segment) once.
        order = _lexicographic(x, y, segment, n)
        x, y, segment = x[order], y[order], segment[order]
        new_cell = np.r_[True, (x[1:] != x[:-1]) | (y[1:] != y[:-1])]
        fresh = new_cell | np.r_[True, segment[1:] != segment[:-1]]
        segment, new_cell = segment[fresh], new_cell[fresh]
        # Each segment is paired with those after it in its grid cell.
        starts = np.flatnonzero(new_cell)
        sizes = np.diff(np.r_[starts, len(segment)])
        after = np.repeat(sizes, sizes) - (np.arange(len(segment)) - np.repeat(starts, sizes)) - 1
        total = int(after.sum()) + int(long_.sum()) * n
        if total > _MAX_PAIRS:
            raise ValueError(f"the window holds too many pieces of the boundary ({total:,} pairs of "
                             f"chords to intersect, more than {_MAX_PAIRS:,}): narrow it")
        check_memory("the D-decomposition's pairs of chords", 48 * total)
        pairs += _cell_pairs(segment, after, lo, hi)
    wide = np.flatnonzero(long_)
    if len(wide):
        a, b = np.nonzero(_meet(lo[wide, None, :], hi[wide, None, :], lo, hi))
        pairs.append(np.stack([wide[a], b], axis=1))
    pairs = np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)
    if not len(pairs):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    pairs = np.sort(pairs, axis=1)
    # Sorted and deduplicated by hand: np.unique hashes integers (NumPy 2.3+),
    # 50 times slower than this sort on the 10**5 keys of a fine pass.
    key = np.sort(pairs[:, 0] * n + pairs[:, 1])
    key = key[np.r_[True, key[1:] != key[:-1]]]
    i, j = key // n, key % n
    return i[i != j], j[i != j]


def _pairs_with(lo, hi, among):
    """The pairs ``i < j`` of :func:`_candidate_pairs` with ``i`` or ``j`` in the mask ``among``.

    Each of the few segments in ``among`` is compared with every segment's
    box at once; many of them are left to :func:`_candidate_pairs`.
    """
    n = len(lo)
    chosen = np.flatnonzero(among)
    if len(chosen) * n > _MAX_PAIRS_WITH:
        return _candidate_pairs(lo, hi)
    a, b = np.nonzero(_meet(lo[chosen, None, :], hi[chosen, None, :], lo, hi))
    i, j = chosen[a], b
    # Sorted and deduplicated as _candidate_pairs does it.
    key = np.sort(np.minimum(i, j) * n + np.maximum(i, j))
    key = key[np.r_[True, key[1:] != key[:-1]]] if len(key) else key
    i, j = key // n, key % n
    return i[i != j], j[i != j]


def _lexicographic(x, y, segment, n):
    """``np.lexsort((segment, y, x))`` (``segment`` below ``n``), as one sort of one key.

    Three stable sorts cost three times one; a key ``(x, y, segment)`` that
    does not fit in 62 bits falls back to them.
    """
    kx, ky = x - x.min(), y - y.min()
    rows, columns = int(kx.max()) + 1, int(ky.max()) + 1
    if rows * columns * max(n, 1) >= 2**62:
        return np.lexsort((segment, y, x))
    return np.argsort((kx * columns + ky) * n + segment, kind="stable")


def _cell_pairs(segment, after, lo, hi):
    """The pairs of each ``segment`` with the ``after`` next ones in its cell whose boxes meet.

    Made and compared about 10**6 pairs at a time (a row's partners are
    the rows just below it: its cell's segments are consecutive).
    """
    out = []
    cumulative = np.cumsum(after)
    cuts = np.searchsorted(cumulative, np.arange(1_000_000, int(cumulative[-1]), 1_000_000))
    cuts = [0, *cuts.tolist(), len(segment)]
    for start, stop in zip(cuts[:-1], cuts[1:], strict=True):
        counts = after[start:stop]
        row = np.repeat(np.arange(start, stop), counts)
        # The k-th partner of a row is k rows below it.
        step = np.arange(len(row)) - np.repeat(np.cumsum(counts) - counts, counts) + 1
        i, j = segment[row], segment[row + step]
        meet = _meet(lo[i], hi[i], lo[j], hi[j])
        out.append(np.stack([i[meet], j[meet]], axis=1))
    return out


def _meet(lo_a, hi_a, lo_b, hi_b):
    """Whether boxes ``a`` meet boxes ``b`` (corners in the last axis; the rest broadcast)."""
    return ((lo_a[..., 0] <= hi_b[..., 0]) & (lo_b[..., 0] <= hi_a[..., 0])
            & (lo_a[..., 1] <= hi_b[..., 1]) & (lo_b[..., 1] <= hi_a[..., 1]))


def _intersections(p, q, owner, position, among=None):
    """All pairs of crossing segments: (i, j, t_i, t_j), or those with a segment ``among``.

    ``among`` (a mask of the segments) keeps only the pairs with at least
    one segment in it: each pair's crossing is the one all pairs give.  The
    ends' touches (:func:`_end_touches`) are all found either way.
    """
    r = q - p
    lo = np.minimum(p, q) - 1e-12
    hi = np.maximum(p, q) + 1e-12
    ii, jj = _candidate_pairs(lo, hi) if among is None else _pairs_with(lo, hi, among)
    out = []
    for part in range(0, len(ii), 1_000_000):
        i, j = ii[part:part + 1_000_000], jj[part:part + 1_000_000]
        # Neighbours along one polyline share their end point: not a crossing.
        keep = ~((owner[i] == owner[j]) & (np.abs(position[i] - position[j]) == 1))
        i, j = i[keep], j[keep]
        if not len(i):
            continue
        ri, rj = r[i], r[j]
        w = p[j] - p[i]
        denom = ri[:, 0] * rj[:, 1] - ri[:, 1] * rj[:, 0]
        with np.errstate(all="ignore"):
            t = (w[:, 0] * rj[:, 1] - w[:, 1] * rj[:, 0]) / denom
            s = (w[:, 0] * ri[:, 1] - w[:, 1] * ri[:, 0]) / denom
        ok = ((np.abs(denom) > 1e-300) & (t >= -_ENDS) & (t <= 1 + _ENDS)
              & (s >= -_ENDS) & (s <= 1 + _ENDS))
        out.append(np.stack([i[ok], j[ok], np.clip(t[ok], 0, 1), np.clip(s[ok], 0, 1)], axis=1))
    hits = np.concatenate(out) if out else np.zeros((0, 4))
    return np.concatenate([hits, _end_touches(p, q, owner, position)])


def _end_touches(p, q, owner, position):
    """A piece that ends on another (the arc at theta = 0 or pi ends on z = +-1).

    It may arrive tangentially, where the crossing of two chords is
    ill-conditioned: so each piece's end point is also projected on every
    segment, and one within :data:`_MERGE` of it touches it there.  The
    ends are projected together, in chunks of :data:`CHUNK_BYTES`.
    """
    first = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    last = np.flatnonzero(np.r_[owner[1:] != owner[:-1], True])
    ends = np.concatenate([first, last])
    at = np.concatenate([p[first], q[last]])
    t_end = np.concatenate([np.zeros(len(first)), np.ones(len(last))])
    r = q - p
    length2 = r[:, 0] * r[:, 0] + r[:, 1] * r[:, 1]
    # A segment can be that close only if its box, widened by more than
    # _MERGE and the rounding of the projection, holds the end.  (Columns
    # compared one by one: NumPy's reductions along a row of two are slow.)
    lo, hi = np.minimum(p, q), np.maximum(p, q)
    size = np.maximum(np.abs(lo), np.abs(hi))
    margin = 2 * _MERGE + 1e-12 * np.maximum(size[:, 0], size[:, 1])
    lo, hi = lo - margin[:, None], hi + margin[:, None]
    out = [np.zeros((0, 4))]
    for part in chunk_slices(len(ends), 16 * len(p)):
        point = at[part, None, :]
        k, j = np.nonzero(_meet(point, point, lo, hi) & (owner != owner[ends[part], None]))
        point = at[part][k]
        with np.errstate(all="ignore"):
            s = np.clip(np.sum((point - p[j]) * r[j], axis=-1) / length2[j], 0.0, 1.0)
        gap = np.hypot(p[j, 0] + s * r[j, 0] - point[:, 0], p[j, 1] + s * r[j, 1] - point[:, 1])
        near = gap <= _MERGE
        out.append(np.column_stack([ends[part][k[near]], j[near], t_end[part][k[near]],
                                    s[near]]).astype(float))
    return np.concatenate(out)


def _faces(xy, edges):
    """The cycles of the planar graph: lists of half-edge indices, each face on its left."""
    src = np.concatenate([edges[:, 0], edges[:, 1]])
    dst = np.concatenate([edges[:, 1], edges[:, 0]])
    n_edges = len(edges)
    twin = np.concatenate([np.arange(n_edges, 2 * n_edges), np.arange(n_edges)])
    angle = np.arctan2(xy[dst, 1] - xy[src, 1], xy[dst, 0] - xy[src, 0])
    order = np.lexsort((angle, src))
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    first = np.searchsorted(src[order], np.arange(len(xy)))
    degree = np.bincount(src, minlength=len(xy))
    # Next half-edge of the face on the left: at the head, the edge just
    # clockwise of the way back.
    t = twin
    head = dst
    nxt = order[first[head] + (rank[t] - first[head] - 1) % degree[head]]
    # Walked in Python lists: indexing NumPy arrays one element at a time is slower.
    nxt = nxt.tolist()
    seen = [False] * len(src)
    cycles = []
    for h in range(len(src)):
        if seen[h]:
            continue
        cycle = []
        while not seen[h]:
            seen[h] = True
            cycle.append(h)
            h = nxt[h]
        cycles.append(cycle)
    return src, dst, twin, cycles


def _signed_area(poly):
    x, y = poly[:, 0], poly[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _inside(poly, x, y):
    """Even-odd point-in-polygon test, vectorised over points."""
    inside = np.zeros(np.shape(x), dtype=bool)
    px, py = poly[:, 0], poly[:, 1]
    qx, qy = np.roll(px, -1), np.roll(py, -1)
    for ax_, ay_, bx, by in zip(px, py, qx, qy, strict=True):
        crosses = (ay_ > y) != (by > y)
        with np.errstate(all="ignore"):
            xc = ax_ + (y - ay_) * (bx - ax_) / (by - ay_)
        inside ^= crosses & (x < xc)
    return inside


def _inside_intervals(sides, values, axis):
    """The inside intervals of the lines ``axis-coordinate = value`` through the rings, per value.

    ``sides`` holds each ring's ``(ring, ring rolled by one)``: its sides' two
    ends.  All the lines at once (each crossing computed as for one line).
    """
    values = np.asarray(values, dtype=float)
    other = 1 - axis
    line, cuts = [], []
    for a, b in sides:
        crosses = (a[None, :, axis] > values[:, None]) != (b[None, :, axis] > values[:, None])
        row, side = np.nonzero(crosses)
        a_, b_ = a[side], b[side]
        line.append(row)
        cuts.append(a_[:, other] + (values[row] - a_[:, axis]) * (b_[:, other] - a_[:, other])
                    / (b_[:, axis] - a_[:, axis]))
    line = np.concatenate(line) if line else np.zeros(0, dtype=np.intp)
    cuts = np.concatenate(cuts) if cuts else np.zeros(0)
    order = np.lexsort((cuts, line))
    line, cuts = line[order], cuts[order]
    bounds = np.searchsorted(line, np.arange(len(values) + 1))
    out = []
    for start, stop in zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True):
        mine = cuts[start:stop]
        out.append(mine.reshape(-1, 2) if len(mine) % 2 == 0 else np.zeros((0, 2)))
    return out


#: The heights, as fractions of a polygon's, of the lines :func:`_interior_point` tries, in turn.
_PROBES = (0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875, 0.0625, 0.9375, 0.03125, 0.96875)


def _interior_point(rings):
    """A point well inside the polygon ``rings`` (outer first, then holes), in window units."""
    outer = rings[0]
    v0, v1 = outer[:, 1].min(), outer[:, 1].max()
    best, best_width = None, -1.0
    sides = [(ring, np.roll(ring, -1, axis=0)) for ring in rings]
    heights = [v0 + f * (v1 - v0) for f in _PROBES]
    for v, intervals in zip(heights, _inside_intervals(sides, heights, 1), strict=True):
        for lo, hi in intervals:
            if hi - lo > best_width:
                best, best_width = (0.5 * (lo + hi), v), hi - lo
    if best is None:
        return None
    # Centre it vertically too, on the vertical line through it.
    u = best[0]
    spans = _inside_intervals(sides, [u], 0)[0]
    for lo, hi in spans:
        if lo <= best[1] <= hi:
            return (u, 0.5 * (lo + hi))
    return best


# --------------------------------------------------------------------------
# Where a stable point can be


@dataclasses.dataclass(frozen=True, repr=False)
class StableHull:
    """Convex polygons that hold every stable point of a plane (see :func:`stable_hull`).

    Attributes
    ----------
    polygons : tuple of ndarray, shape (k, 2)
        The bounded polygons' vertices, counter-clockwise (one polygon when
        the leading coefficient keeps its sign over the plane); empty when
        no point is stable or when a polygon is unbounded.
    bounded : bool
        False when the condition leaves an unbounded part of the plane
        (then :attr:`polygons` is empty and says nothing).
    reason : str
        Why no point is stable, when that is proved; else empty.
    """

    polygons: tuple
    bounded: bool
    reason: str = ""

    @property
    def empty(self):
        """True when no point of the plane is stable (proved, exactly)."""
        return bool(self.reason)

    def box(self, pad=0.05):
        """``(x_range, y_range)`` around the polygons, ``pad`` of their span added on each side.

        Parameters
        ----------
        pad : float
            Fraction of the polygons' span added on each side.

        Returns
        -------
        tuple of (float, float) or None
            None when the hull is unbounded or empty.
        """
        if not self.bounded or not self.polygons:
            return None
        points = np.vstack(self.polygons)
        out = []
        for column in points.T:
            lo, hi = float(column.min()), float(column.max())
            # The vertices are exact rationals rounded once: a few ulps out is enough,
            # the pad keeps the stable set's edges off the window's.
            margin = pad * (hi - lo) + 8 * np.spacing(max(abs(lo), abs(hi), 1e-300))
            out.append((float(lo - margin), float(hi + margin)))
        return tuple(out)

    def holds(self, x, y):
        """Whether each point ``(x, y)`` may be stable: False proves it unstable.

        True everywhere when the hull is unbounded, False everywhere when it
        is empty.  The vertices are the exact ones rounded once, so a point
        within ``1e-9`` of a polygon's span outside an edge still counts as
        held (the answer errs on the side of "may be stable").

        Parameters
        ----------
        x, y : array_like
            Points of the plane (broadcast together).

        Returns
        -------
        ndarray of bool
        """
        x, y = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        if self.empty:
            return np.zeros(x.shape, dtype=bool)
        if not self.bounded:
            return np.ones(x.shape, dtype=bool)
        px, py = x.ravel(), y.ravel()
        out = np.zeros(px.shape, dtype=bool)
        for polygon in self.polygons:
            span = float(np.max(np.ptp(polygon, axis=0))) or 1.0
            start = polygon
            edge = np.roll(polygon, -1, axis=0) - start
            slack = -1e-9 * span * np.hypot(edge[:, 0], edge[:, 1])[:, None]
            # Counter-clockwise: inside is to the left of every edge.
            for part in chunk_slices(len(px), 8 * len(polygon)):
                with np.errstate(invalid="ignore"):
                    cross = (edge[:, 0, None] * (py[None, part] - start[:, 1, None])
                             - edge[:, 1, None] * (px[None, part] - start[:, 0, None]))
                out[part] |= np.all(cross >= slack, axis=0)
        return out.reshape(x.shape)

    def __repr__(self):
        if self.empty:
            return f"StableHull(empty: {self.reason})"
        if not self.bounded:
            return "StableHull(unbounded)"
        return f"StableHull({len(self.polygons)} polygon(s), box {self.box(0.0)})"


def _exact_rows(rows):
    """Float rows as Python integers with one common power of two (exact)."""
    ratios = [[float(v).as_integer_ratio() for v in row] for row in rows]
    shift = max(den.bit_length() for row in ratios for _, den in row)
    return [[num << (shift - den.bit_length()) for num, den in row] for row in ratios]


def _plus_minus(n, j):
    """Coefficients (lowest power first) of ``(w + 1)**j (w - 1)**(n - j)``, exact integers.

    From ``(w**2 - 1) f' = (n w + n - 2 j) f``: ``(m + 1) a[m + 1] = (m - 1 -
    n) a[m - 1] - (n - 2 j) a[m]``, with ``a[0] = (-1)**(n - j)``; O(n)
    products (the division is exact).
    """
    a = [0] * (n + 1)
    a[0] = -1 if (n - j) % 2 else 1
    previous = 0
    for m in range(n):
        a[m + 1] = ((m - 1 - n) * previous - (n - 2 * j) * a[m]) // (m + 1)
        previous = a[m]
    return a


def _bilinear(c):
    """Coefficients ``q_k`` (``q[k]`` of ``w**k``) of ``(w - 1)**n c((w + 1) / (w - 1))``, exactly.

    ``c`` holds Python integers, highest power first, so ``q = sum_i c[i]
    (w + 1)**(n - i) (w - 1)**i``: one O(n) recurrence
    (:func:`_plus_minus`) per nonzero coefficient.  A loop's rows are
    nonzero only next to their ends (``z**d D(z) + N(z)``), so a long delay
    costs O(n) big-integer products per row, not the O(n**2) of a shift.
    """
    n = len(c) - 1
    q = [0] * (n + 1)
    for i, v in enumerate(c):
        if v:
            q = [acc + v * t for acc, t in zip(q, _plus_minus(n, n - i), strict=True)]
    return q


def _approximate(rows):
    """Integer rows as floats, each row scaled by its own power of two (the same half-plane)."""
    out = np.empty((len(rows), 3))
    for k, row in enumerate(rows):
        shift = max(max(abs(v).bit_length() for v in row) - 60, 0)
        out[k] = [float(v >> shift) if v >= 0 else -float(-v >> shift) for v in row]
    return out


def _tightest(lines, approximate, i):
    """Indices of the rows to try first on line ``i``: those that bound it tightest in floats."""
    a, b, c = approximate[i]
    A, B, C = approximate.T
    norm = b * b + c * c
    with np.errstate(all="ignore"):
        g = A - a * (B * b + C * c) / norm
        h = C * b - B * c
        t = -g / h
    order = []
    for rising in (True, False):
        index = np.flatnonzero(((h > 0) if rising else (h < 0)) & np.isfinite(t))
        if index.size:
            order.append(int(index[np.argmax(t[index]) if rising else np.argmin(t[index])]))
    parallel = np.flatnonzero(np.abs(h) <= 1e-12 * (np.abs(C * b) + np.abs(B * c)))
    if parallel.size:
        order.append(int(parallel[np.argmin(g[parallel])]))
    return order


def _line_interval(lines, i, order):
    """The exact feasible interval of ``t`` on line ``i``: (lo, hi) as (numerator, denominator) or None.

    ``order`` lists rows to intersect first, so an empty interval is found
    after a few; ``False`` when it is empty.
    """
    a, b, c = lines[i]
    norm = b * b + c * c
    lo = hi = None           # (numerator, positive denominator) of t
    seen = set()
    for j in list(order) + list(range(len(lines))):
        if j in seen:
            continue
        seen.add(j)
        aj, bj, cj = lines[j]
        # p(t) = p0 + t (-c, b), p0 = -a (b, c) / norm; row j there is
        # (a_j norm - a (b_j b + c_j c)) / norm + t (c_j b - b_j c).
        g = aj * norm - a * (bj * b + cj * c)
        h = (cj * b - bj * c) * norm
        if h == 0:
            if g < 0:
                return False
            continue
        bound = (-g, h) if h > 0 else (g, -h)
        if h > 0 and (lo is None or bound[0] * lo[1] > lo[0] * bound[1]):
            lo = bound
        if h < 0 and (hi is None or bound[0] * hi[1] < hi[0] * bound[1]):
            hi = bound
        if lo is not None and hi is not None and lo[0] * hi[1] >= hi[0] * lo[1]:
            return False
    return lo, hi


def _float_candidates(approximate):
    """Lines whose feasible interval is not empty in floating point, with a wide slack.

    A first guess of the polygon's edges, O(lines**2) float operations in
    chunks; :func:`_half_plane_polygon` proves or rejects it exactly.  Also
    returns, per line, the two rows that bound its interval tightest from
    below and from above (``-1`` where none): with the line, the triples to
    try for a proof that nothing is feasible (:func:`_infeasible_triple`).
    """
    a, b, c = approximate.T
    norm = b * b + c * c
    keep = np.zeros(len(approximate), dtype=bool)
    below = np.full(len(approximate), -1)
    above = np.full(len(approximate), -1)
    for part in chunk_slices(len(approximate), 8 * 4 * len(approximate)):
        ai, bi, ci, ni = (v[part, None] for v in (a, b, c, norm))
        with np.errstate(all="ignore"):
            g = a[None, :] - ai * (b[None, :] * bi + c[None, :] * ci) / ni
            h = c[None, :] * bi - b[None, :] * ci
            t = -g / h
            rising, falling = np.where(h > 0, t, -np.inf), np.where(h < 0, t, np.inf)
            below[part], above[part] = np.argmax(rising, axis=1), np.argmin(falling, axis=1)
            lo, hi = np.max(rising, axis=1), np.min(falling, axis=1)
            below[part] = np.where(np.isfinite(lo), below[part], -1)
            above[part] = np.where(np.isfinite(hi), above[part], -1)
            scale = np.abs(g) + np.abs(a[None, :])
            # Parallel rows that exclude the line by far.
            parallel = np.abs(h) <= 1e-9 * (np.abs(c[None, :] * bi) + np.abs(b[None, :] * ci))
            excluded = np.any(parallel & (g < -1e-6 * scale), axis=1)
            width = np.maximum(np.abs(lo), np.abs(hi))
            keep[part] = ~excluded & ~(hi - lo < -1e-6 * np.where(np.isfinite(width), width, 0))
    return np.flatnonzero(keep), below, above


def _infeasible_triple(lines, triple):
    """Whether three exact rows prove that no point is inside all of them (Farkas, exactly).

    With ``l_1 = [r_2, r_3]``, ``l_2 = [r_3, r_1]``, ``l_3 = [r_1, r_2]``
    (the 2 x 2 determinants of the rows' ``(b, c)``), ``sum l_j (b_j, c_j)
    = 0``; when every ``l_j`` has one sign ``s`` and ``s sum l_j a_j <=
    0``, the rows' weighted sum is a constant ``<= 0`` that an interior
    point would make positive.  By Helly's theorem an empty intersection of
    half-planes has such a triple; this only checks the one given.
    """
    (a1, b1, c1), (a2, b2, c2), (a3, b3, c3) = (lines[k] for k in triple)
    weights = (b2 * c3 - b3 * c2, b3 * c1 - b1 * c3, b1 * c2 - b2 * c1)
    total = weights[0] * a1 + weights[1] * a2 + weights[2] * a3
    if all(w >= 0 for w in weights) and any(weights):
        return total <= 0
    if all(w <= 0 for w in weights) and any(weights):
        return total >= 0
    return False


def _closed_cycle(edges):
    """Whether the edges' exact end points, sorted around their mean, are joined by those edges.

    ``edges`` are ``(vertex, vertex)`` pairs of Fractions.  True proves that
    the convex polygon of the vertices is the whole feasible set: each side
    lies on a constraint's line, with the feasible set on its inner side.
    """
    vertices = sorted({v for edge in edges for v in edge})
    if len(vertices) < 3:
        return False
    cx = sum(v[0] for v in vertices) / len(vertices)
    cy = sum(v[1] for v in vertices) / len(vertices)
    vertices.sort(key=lambda v: math.atan2(float(v[1] - cy), float(v[0] - cx)))
    sides = {frozenset(edge) for edge in edges if edge[0] != edge[1]}
    return all(frozenset((u, v)) in sides
               for u, v in zip(vertices, vertices[1:] + vertices[:1], strict=True))


def _half_plane_polygon(rows):
    """The polygon ``{a + b x + c y >= 0 for every row}`` with exact integer rows.

    Returns ``(vertices, bounded, interior)``: the vertices as Fractions,
    counter-clockwise (empty when unbounded), whether it is bounded, and
    whether its interior is non-empty.  Each line's feasible interval is
    the intersection of the others' half-lines on it (a one-dimensional
    programme per line, in exact rationals); the rows that bound it
    tightest in floating point are tried first, so a line that is no edge
    is dismissed after a few exact products.  The lines that are edges in
    floating point go first: when their exact sides close into a polygon
    (:func:`_closed_cycle`), that is the answer, and the other lines are
    never solved exactly (O(lines) exact products instead of
    O(lines**2)); otherwise every line is.
    """
    from fractions import Fraction

    constant = [r for r in rows if r[1] == 0 and r[2] == 0]
    if any(a <= 0 for a, _, _ in constant):
        return [], True, False
    lines = [r for r in rows if r[1] != 0 or r[2] != 0]
    if not lines:
        return [], False, True
    approximate = _approximate(lines)
    first, below, above = _float_candidates(approximate)
    if first.size == 0:
        # Empty in floating point: look for an exact proof among the lines'
        # own witnesses before solving every line.
        for i in range(len(lines)):
            if below[i] >= 0 and above[i] >= 0 and _infeasible_triple(
                    lines, (i, int(below[i]), int(above[i]))):
                return [], True, False
    for group in (first, None):
        vertices, edges, bounded = [], [], True
        for i in (first if group is not None else range(len(lines))):
            a, b, c = lines[i]
            interval = _line_interval(lines, i, _tightest(lines, approximate, i))
            if interval is False:
                continue
            lo, hi = interval
            if lo is None or hi is None:
                bounded = False          # a feasible ray: proved unbounded either way
                break
            norm = b * b + c * c
            ends = tuple((Fraction(-a * b, norm) - t * c, Fraction(-a * c, norm) + t * b)
                         for t in (Fraction(*lo), Fraction(*hi)))
            vertices.extend(ends)
            edges.append(ends)
        if not bounded or group is None or _closed_cycle(edges):
            break
    if not bounded:
        return [], False, True
    vertices = list(set(vertices))
    if len(vertices) < 3:
        return [], True, False
    cx = sum(v[0] for v in vertices) / len(vertices)
    cy = sum(v[1] for v in vertices) / len(vertices)
    # The mean of the vertices is inside unless the polygon is flat (a segment).
    interior = all(a + b * cx + c * cy > 0 for a, b, c in rows)
    vertices.sort(key=lambda v: math.atan2(float(v[1] - cy), float(v[0] - cx)))
    return vertices, True, interior


def stable_hull(base, ax, ay):
    """Where a stable point of ``chi = base + x ax + y ay`` can be: a proved convex enclosure.

    If every root of ``chi`` (degree ``n``, leading coefficient nonzero)
    lies inside the unit circle, the bilinear map ``z = (w + 1) / (w - 1)``
    takes them into the open left half-plane, so ``q(w) = (w - 1)**n
    chi((w + 1) / (w - 1))`` is a Hurwitz polynomial of degree ``n``
    (its leading coefficient is ``chi(1)``, nonzero) and all its ``n + 1``
    coefficients are nonzero and of one sign (Stodola's necessary
    condition).  Each ``q_k`` is affine in ``(x, y)``, so the stable set
    lies inside ``{s q_k(x, y) > 0 for every k}`` for ``s = 1`` or ``s =
    -1``: at most two convex polygons.  (``q_n = chi(1)`` and ``q_0 = (-1)**n
    chi(-1)`` are the z = +-1 conditions; ``2**-n q`` are the barycentric
    coordinates of ``chi`` over ``(z + 1)**k (z - 1)**(n - k)``, whose convex
    hull is that of the Schur-stable polynomials of degree ``n``: no
    condition linear in the coefficients is sharper.)

    Exact for the coefficients as given: they are turned into integers and
    the transform and the polygons are computed in exact arithmetic, so an
    empty enclosure proves that no point is stable.

    Parameters
    ----------
    base, ax, ay : array_like, shape (n + 1,)
        Coefficients (highest power first) of ``A0``, ``Ax`` and ``Ay``.

    Returns
    -------
    StableHull

    Examples
    --------
    ``z**2 + x z + y``: the hull is the stable triangle ``|x| < 1 + y < 2``.

    >>> hull = stable_hull([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
    >>> hull.polygons[0].tolist()
    [[0.0, -1.0], [2.0, 1.0], [-2.0, 1.0]]

    ``z**2 + x z + 3`` is never stable (the product of its roots is 3):

    >>> stable_hull([1.0, 0.0, 3.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]).empty
    True
    """
    rows = np.array([base, ax, ay], dtype=float)
    if rows.ndim != 2 or not np.all(np.isfinite(rows)):
        raise ValueError("base, ax and ay must be finite coefficient rows of one length")
    # Leading zeros shared by all three are not part of the polynomial.
    keep = np.flatnonzero(np.any(rows != 0, axis=0))
    if keep.size == 0:
        return StableHull((), True, "the polynomial is 0 everywhere in the plane: no point is stable")
    rows = rows[:, keep[0]:]
    exact = _exact_rows(rows)
    q = [_bilinear(row) for row in exact]
    polygons, bounded = [], True
    for s in (1, -1):
        half_planes = [(s * q0, s * qx, s * qy) for q0, qx, qy in zip(*q, strict=True)]
        vertices, side_bounded, interior = _half_plane_polygon(half_planes)
        if not side_bounded:
            bounded = False
        elif interior:
            polygons.append(np.array([[float(u), float(v)] for u, v in vertices]))
    if not bounded:
        return StableHull((), False)
    if not polygons:
        return StableHull((), True, "the coefficients of (w - 1)**n chi((w + 1)/(w - 1)) are "
                                    "never all of one sign in the plane (Stodola's necessary "
                                    "condition for the roots inside the unit circle): no point "
                                    "is stable")
    return StableHull(tuple(polygons), True)


def stable_ranges(rows, bounds):
    """Where a stable point of ``chi = rows[0] + sum_k u_k rows[k + 1]`` can be, per parameter.

    :func:`stable_hull`'s necessary condition (Stodola's: the ``n + 1``
    coefficients of ``(w - 1)**n chi((w + 1)/(w - 1))``, each affine in the
    ``u_k``, nonzero and of one sign) in any number of parameters, some
    bounded: for each sign a linear programme
    (:func:`scipy.optimize.linprog`, HiGHS) gives the largest margin by
    which every coefficient, scaled to its largest term, can be of that
    sign, and the least and greatest value of each bounded parameter where
    they all are.  What a search over a parameter of the loop uses to
    bracket the values that can have a stable point at all.

    Parameters
    ----------
    rows : array_like, shape (k + 1, n + 1)
        Coefficients (highest power first) of ``A0`` and of the slope in each
        parameter.
    bounds : sequence of k (float, float) or None
        Each parameter's range, or None where it is free (a plane's axis).

    Returns
    -------
    list of (float, float) or None
        Per parameter, the range (inside its bounds) outside which no point
        is stable; None when no point of the bounded box is stable (the
        margin is below ``-1e-6`` for both signs: the coefficients are never
        all of one sign there).  A programme that does not solve, or whose
        margin is within 1e-6 of 0, leaves the bounds as they are.

    Examples
    --------
    ``z**2 + x z + y`` with ``y`` in [0.5, 3]: stable only for ``|y| < 1``.

    >>> [tuple(round(v, 9) for v in r) for r in stable_ranges(
    ...     [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], [None, (0.5, 3.0)])]
    [(-inf, inf), (0.5, 1.0)]
    >>> print(stable_ranges([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ...                     [None, (1.5, 3.0)]))
    None
    """
    from scipy.optimize import linprog

    rows = np.array(rows, dtype=float)
    bounds = [None if b is None else (float(b[0]), float(b[1])) for b in bounds]
    if rows.ndim != 2 or rows.shape[0] != len(bounds) + 1 or not np.all(np.isfinite(rows)):
        raise ValueError("rows must be finite coefficient rows, one more than the bounds")
    keep = np.flatnonzero(np.any(rows != 0, axis=0))
    given = [(-math.inf, math.inf) if b is None else b for b in bounds]
    if keep.size == 0:
        return None
    exact = [_bilinear(row) for row in _exact_rows(rows[:, keep[0]:])]
    # One coefficient's terms over its largest, exactly (binomials overflow floats).
    q = []
    for terms in zip(*exact, strict=True):
        top = max(abs(v) for v in terms)
        q.append([float(v / top) if top else 0.0 for v in terms])
    q = np.array(q)                                           # (n + 1, k + 1)
    k = len(bounds)
    box = [(None, None) if b is None else b for b in bounds]
    out, feasible, unclear = None, False, False
    for sign in (1.0, -1.0):
        a = sign * q
        norm = np.abs(a).max(axis=1)
        a = a[norm > 0] / norm[norm > 0, None]
        # s q_j(u) >= t for every j, t as large as can be (capped: a free
        # direction may be unbounded).
        a_ub = np.column_stack([-a[:, 1:], np.ones(len(a))])
        margin = linprog(np.r_[np.zeros(k), -1.0], A_ub=a_ub, b_ub=a[:, 0],
                         bounds=box + [(None, 1.0)], method="highs")
        if margin.status != 0:
            unclear = True
            continue
        if -margin.fun <= 0:
            # Proved only well past the solver's tolerance (1e-7 on these
            # scaled rows): a margin that small either way is not decided.
            unclear |= -margin.fun > -_LP_MARGIN
            continue
        feasible = True
        ranges = []
        for j in range(k):
            if bounds[j] is None:
                ranges.append(given[j])
                continue
            ends = []
            for direction in (1.0, -1.0):
                cost = np.zeros(k + 1)
                cost[j] = direction
                end = linprog(cost, A_ub=a_ub, b_ub=a[:, 0], bounds=box + [(0.0, 0.0)],
                              method="highs")
                ends.append(float(end.x[j]) if end.status == 0 else direction * -math.inf)
            ranges.append((max(ends[0], given[j][0]), min(ends[1], given[j][1])))
        out = ranges if out is None else [(min(r[0], o[0]), max(r[1], o[1]))
                                          for r, o in zip(ranges, out, strict=True)]
    if unclear:
        # Neither proved empty nor bracketed: the ranges as given (a stable
        # point at a margin below the programme's tolerance is not excluded).
        return given
    if not feasible:
        return None
    return out


# --------------------------------------------------------------------------
# The decomposition


class Unresolved(ValueError):
    """A window :func:`decompose` refuses, with what its first, coarser pass found.

    Attributes
    ----------
    attempt : Decomposition
        The pass with the arc sampled at the usual length when it broke no
        crossing rule, else the finer one: its stable cells say where to
        narrow the window (:meth:`symstab.Loop.region` does; the narrowed
        window is decomposed and checked anew).
    """

    def __init__(self, message, attempt):
        super().__init__(message)
        self.attempt = attempt


def decompose(base, ax, ay, ends, *, x_range, y_range, names=("x", "y"), arc=None, family=None,
              refine=True, segments=True):
    """The D-decomposition of ``chi = base + x ax + y ay`` inside a window.

    Parameters
    ----------
    base, ax, ay : ndarray, shape (n + 1,)
        Coefficients (highest power first) of ``A0``, ``Ax`` and ``Ay``.
    ends : sequence of three pairs
        The values at ``z = 1`` and ``z = -1`` of ``A0``, ``Ax`` and ``Ay``
        (exact ones where the caller has them: the z = +-1 lines come from
        these).
    x_range, y_range : (float, float)
        The window, ``lo < hi``, finite.
    names : (str, str)
        The plane's parameter names.
    arc : symstab.numeric.engine.arcs.ArcSource, optional
        Where the arc's points come from: by default the structured Cramer
        solve of ``base, ax, ay`` (:class:`symstab.numeric.engine.arcs.CramerArc`);
        the paper's plane passes its closed form
        (:class:`symstab.numeric.engine.arcs.ClosedFormArc`), a loop its structured
        polynomials' solve.
    family : (DelayedPolynomial, DelayedPolynomial, DelayedPolynomial), optional
        ``A0``, ``Ax`` and ``Ay`` again in their structure (one polynomial
        each, a common shift): the cells' root counts are taken on it,
        O(d) per cell where the dense rows cost O(d**2).
    refine : bool
        Sample the arc finer where the first pass leaves the crossing rule
        broken or a stable cell too small for its chords (default).  False
        raises :class:`Unresolved` at once there: a caller that only looks
        for where the stable set is (to narrow its window) saves the finer
        pass, which may take up to 64 times the chords.
    segments : bool
        Make the :attr:`Decomposition.segments` (default); False leaves
        them to :meth:`Decomposition.with_segments`.

    Returns
    -------
    Decomposition

    Raises
    ------
    ValueError
        If the window is not finite with ``lo < hi``.
    Unresolved
        (a ValueError) If two neighbouring cells break the crossing rule
        even with the arc sampled finer, or a stable cell is too small for
        the window (the window is too coarse for the curves in it).

    Examples
    --------
    ``z**2 + x z + y``: the z = 1 line ``1 + x + y = 0``, the z = -1 line
    ``1 - x + y = 0`` and the arc ``y = 1`` bound the stable triangle
    ``|x| < 1 + y < 2`` of area 4.

    >>> found = decompose([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0],
    ...                   [(1.0, 1.0), (1.0, -1.0), (1.0, 1.0)], x_range=(-3, 3), y_range=(-2, 2))
    >>> sorted(cell.count for cell in found.cells), round(found.area, 12)
    ([0, 1, 1, 2, 2], 4.0)
    """
    if arc is None:
        arc = CramerArc(*(np.asarray(c, dtype=float) for c in (base, ax, ay)))
    found = _decompose(base, ax, ay, ends, x_range=x_range, y_range=y_range, names=names,
                       fine=1.0, arc=arc, family=family)
    coarse = None if found.mismatches else found
    if refine and (found.mismatches or found.resolution > _RESOLUTION):
        # A stable cell small for its window: the arc sampled finer (not
        # beyond 64 times: a window that needs more is refused below).
        fine = max(min(0.125, 0.5 * _RESOLUTION / max(found.resolution, 1e-300)), 1 / 64)
        fine = 1 / 64 if math.isinf(found.resolution) else fine
        found = _decompose(base, ax, ay, ends, x_range=x_range, y_range=y_range, names=names,
                           fine=fine, arc=arc, family=family)
    if found.resolution > _RESOLUTION:
        raise Unresolved(
            f"the stable set is too small to be resolved in the window {found.x} in "
            f"[{found.x_range[0]:g}, {found.x_range[1]:g}], {found.y} in "
            f"[{found.y_range[0]:g}, {found.y_range[1]:g}]: narrow the window around it",
            coarse or found)
    if found.mismatches:
        i, j, label, change = found.mismatches[0]
        raise Unresolved(
            f"the D-decomposition of {found.x} in [{found.x_range[0]:g}, {found.x_range[1]:g}], "
            f"{found.y} in [{found.y_range[0]:g}, {found.y_range[1]:g}] is not resolved: across "
            f"the {label} piece the counts of two neighbouring cells ({found.cells[i].count}, "
            f"{found.cells[j].count}) differ by {abs(change)}, not {_CHANGE[label]}; narrow "
            f"the window around the region of interest", coarse or found)
    return found.with_segments() if segments else found


def _decompose(base, ax, ay, ends, *, x_range, y_range, names, fine, arc, family=None):
    """:func:`decompose` with the arc's chords ``fine`` times the usual length.

    The steps: the pieces traced in the window and crossed
    (:func:`_trace`), the planar graph of their segments split at the
    crossings (:func:`_split_at_crossings`, :func:`_prune_edges`), its
    faces with holes and an interior point each (:class:`_Faces`), the
    cells' root counts (:func:`_cell_counts`), and what the result reports
    of them: the cells, the crossing rule's mismatches, the window's sides
    a stable cell touches and how finely the arc draws the stable cells.
    """
    base, ax, ay = (np.asarray(c, dtype=float) for c in (base, ax, ay))
    window = _Window(x_range, y_range, names)
    polylines, branches, (p, q, owner, _), hits = _trace(base, ax, ay, ends, arc, window, fine)
    n_segments = len(p)
    check_memory(f"the D-decomposition's {n_segments} segments", 64 * n_segments * 64)
    labels = [label for _, label, _ in polylines]
    xy, edges, edge_label = _split_at_crossings(p, q, owner, labels, hits)
    edges, edge_label = _prune_edges(xy, edges, edge_label)
    cells = []
    mismatches = []
    if len(edges):
        faces = _Faces(xy, edges, edge_label)
        points = window.from_unit(np.array(faces.points).reshape(-1, 2))
        counts = _cell_counts(base, ax, ay, family, points, names)
        scale = window.sx * window.sy
        for n, f in enumerate(faces.keep):
            outer = window.from_unit(faces.rings[f])
            hole_rings = tuple(window.from_unit(faces.rings[h]) for h in faces.holes[f])
            area = scale * (faces.areas[f] + sum(faces.areas[h] for h in faces.holes[f]))
            point = (float(points[n, 0]), float(points[n, 1]))
            cells.append(Cell(outer, hole_rings, int(counts[n]), point, float(area)))
        mismatches = _crossing_mismatches(faces, counts)
        stable = [f for n, f in enumerate(faces.keep) if counts[n] == 0]
        unbounded = _unbounded_sides(faces, stable, xy)
        sides = _line_sides([faces.cycles[f] for f in stable], faces.src, faces.dst,
                            faces.half_label)
        resolution = _resolution(faces, stable, xy)
    else:
        unbounded, sides = (), []
        resolution = 0.0
    found = Decomposition(x=names[0], y=names[1], x_range=(window.x0, window.x1),
                          y_range=(window.y0, window.y1), branches=tuple(branches),
                          cells=tuple(cells), mismatches=tuple(mismatches), unbounded=unbounded,
                          polynomial=(base, ax, ay), resolution=resolution, arc=arc)
    # The segments are made by Decomposition.with_segments, for the passes kept.
    pieces = tuple((label, window.from_unit(xy[[a, b]])) for label, a, b in sides)
    return dataclasses.replace(found, _pending=(lines(base, ax, ay, ends), pieces))


class _Window:
    """The window ``[x0, x1] x [y0, y1]``, checked, and its map to the unit square.

    The decomposition's geometry works in window units (the window is
    ``[0, 1]**2``), so that its tolerances (:data:`_MERGE`, ...) are
    fractions of the window whatever the parameters' units.
    """

    def __init__(self, x_range, y_range, names):
        self.x0, self.x1 = (float(v) for v in x_range)
        self.y0, self.y1 = (float(v) for v in y_range)
        for name, (lo, hi) in ((names[0], (self.x0, self.x1)), (names[1], (self.y0, self.y1))):
            if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
                raise ValueError(f"the window of {name} must be finite with lo < hi, got "
                                 f"({lo}, {hi})")
        self.sx, self.sy = self.x1 - self.x0, self.y1 - self.y0
        self.box = (self.x0, self.x1, self.y0, self.y1)

    def to_unit(self, x, y):
        """``(u, v)``: points of the plane in window units."""
        return (np.asarray(x) - self.x0) / self.sx, (np.asarray(y) - self.y0) / self.sy

    def from_unit(self, uv):
        """Rows ``(x, y)`` of the plane from rows ``(u, v)`` in window units."""
        return np.column_stack([self.x0 + self.sx * uv[:, 0], self.y0 + self.sy * uv[:, 1]])


def _trace(base, ax, ay, ends, arc, window, fine):
    """The first step: the pieces in the window as segments, and where they cross.

    The arc is sampled, cut into pieces with the lines (:func:`_pieces`)
    and its chords crossed with every piece's; where the arc crosses a
    piece it is sampled finer (:func:`_hot_angles`), up to
    :data:`_CROSSING_ROUNDS` times, until the chords' crossings are the
    curves'.  Returns ``(polylines, branches, (p, q, owner, position),
    hits)`` of the last round.
    """
    samples, known = None, None
    arc_ends = arc(np.array([0.0, np.pi]))[:2]      # the same in every round
    for round_ in range(_CROSSING_ROUNDS):
        samples = sample_arc(arc, len(base) - 1, window.to_unit, samples, fine)
        theta, xs, ys, det = samples
        sign = np.sign(det)
        polylines, branches = _pieces(base, ax, ay, ends, arc_ends, theta, xs, ys, sign,
                                      window.to_unit, window.from_unit, window.box)
        p, q, owner, position = _segments(polylines)
        if round_ == _CROSSING_ROUNDS - 1:
            hits = _intersections(p, q, owner, position)
            break
        if known is None:
            hits = _intersections(p, q, owner, position)
            hot = _hot_angles(hits, polylines, owner, position)
        else:
            # Two chords the last round had too crossed there as they do now:
            # had that made an angle hot, one of them would have been split.
            # So the hot angles are those of the pairs with a new chord.
            new = _new_chords(polylines, owner, position, _sorted_difference(theta, known))
            hot = _hot_angles(_intersections(p, q, owner, position, among=new), polylines,
                              owner, position)
            if not hot:
                hits = _intersections(p, q, owner, position)
        if not hot:
            break
        known = theta
        # The angles added are evaluated by the next round's sampling, the
        # others are kept.
        hot = np.unique(np.asarray(hot, dtype=float))
        hot = hot[~_members(theta, hot)]
        order = np.argsort(np.concatenate([theta, hot]), kind="stable")
        unknown = np.full(len(hot), np.nan)
        samples = tuple(np.concatenate([a, b])[order] for a, b in
                        zip(samples, (hot, unknown, unknown, unknown), strict=True))
    return polylines, branches, (p, q, owner, position), hits


def _new_chords(polylines, owner, position, added):
    """Which segments are the arc's chords with an end at one of the angles ``added``."""
    new = np.zeros(len(owner), dtype=bool)
    for k, (_, _, th) in enumerate(polylines):
        if th is None:
            continue
        fresh = _members(added, th)
        mine = np.flatnonzero(owner == k)
        new[mine] = fresh[position[mine]] | fresh[position[mine] + 1]
    return new


def _members(sorted_values, x):
    """``np.isin(x, sorted_values)`` for ``sorted_values`` sorted: a binary search, not a sort."""
    x = np.asarray(x, dtype=float)
    if not len(sorted_values):
        return np.zeros(x.shape, dtype=bool)
    index = np.minimum(np.searchsorted(sorted_values, x), len(sorted_values) - 1)
    return sorted_values[index] == x


def _sorted_difference(a, b):
    """``np.setdiff1d(a, b)`` for ``b`` sorted, without sorting an ``a`` already increasing."""
    if len(a) > 1 and not (a[1:] > a[:-1]).all():
        return np.setdiff1d(a, b)
    return a[~_members(b, a)]


def _hot_angles(hits, polylines, owner, position):
    """Angles of the arc to add around the crossings of its chords with a piece.

    Where the arc crosses a piece, the crossing of two chords is off the
    curves' by the chords' sag: two new angles close around it make the
    chord through it 32 times shorter, its sag 1000 times.  Empty when
    every crossing's chord is short enough (or at an end, or near 0 or pi).
    """
    hot = []
    for i, j, ti, tj in hits:
        for k, t in ((int(i), ti), (int(j), tj)):
            th = polylines[owner[k]][2]
            if th is None or not (1e-6 < t < 1 - 1e-6):
                continue
            a_, b_ = th[position[k]], th[position[k] + 1]
            if b_ - a_ > _CROSSING_GAP and 1e-4 < a_ and b_ < np.pi - 1e-4:
                middle = a_ + t * (b_ - a_)
                hot.extend([max(a_, middle - (b_ - a_) / 64), min(b_, middle + (b_ - a_) / 64)])
    return hot


def _split_at_crossings(p, q, owner, labels, hits):
    """The second step: the planar graph of the segments ``p -> q`` split at their crossings.

    Nodes closer than :data:`_MERGE` are one (:func:`_merged_nodes`).  Returns
    ``(xy, edges, edge_label)``: the nodes' points, the edges as pairs of
    nodes and each edge's piece's label.
    """
    hits = np.asarray(hits, dtype=float).reshape(-1, 4)
    cut_i, cut_j = hits[:, 0].astype(np.int64), hits[:, 1].astype(np.int64)
    crossings = p[cut_i] + hits[:, 2:3] * (q[cut_i] - p[cut_i])
    ends = np.column_stack([p, q]).reshape(-1, 2)     # p[0], q[0], p[1], q[1], ...
    node, xy = _merged_nodes(np.concatenate([crossings, ends]))
    crossing_node, start, finish = node[:len(hits)], node[len(hits)::2], node[len(hits) + 1::2]
    cuts = {}
    for i, j, ti, tj, at in zip(cut_i.tolist(), cut_j.tolist(), hits[:, 2].tolist(),
                                hits[:, 3].tolist(), crossing_node.tolist(), strict=True):
        cuts.setdefault(i, []).append((ti, at))
        cuts.setdefault(j, []).append((tj, at))
    # A segment without a crossing is one edge; a crossed one an edge per stretch.
    pieces = [np.column_stack([start, finish])]
    at = [np.arange(len(p))]
    for k, entries in cuts.items():
        entries = sorted([(0.0, int(start[k])), (1.0, int(finish[k]))] + entries)
        pieces[0][k] = -1
        pieces.append(np.array([(a, b) for (_, a), (_, b)
                                in zip(entries[:-1], entries[1:], strict=True)],
                               dtype=np.int64))
        at.append(np.full(len(pieces[-1]), k))
    edges, at = np.concatenate(pieces), np.concatenate(at)
    order = np.argsort(at, kind="stable")
    edges, at = edges[order], at[order]
    keep = (edges[:, 0] != edges[:, 1]) & (edges[:, 0] >= 0)
    edges, at = edges[keep], at[keep]
    edge_label = np.array(labels, dtype=object)[owner[at]] if len(at) else np.zeros(0, object)
    return xy, edges, edge_label


def _prune_edges(xy, edges, edge_label):
    """The edges that bound cells: one per pair of nodes, inside the window, none dangling.

    Where a piece runs along the window's edge, the edge is the piece's.
    """
    order = np.argsort(edge_label == "window", kind="stable")
    edges, edge_label = edges[order], edge_label[order]
    key = np.sort(edges, axis=1)
    _, unique = np.unique(key, axis=0, return_index=True)
    unique = np.sort(unique)
    edges, edge_label = edges[unique], edge_label[unique]
    mid = 0.5 * (xy[edges[:, 0]] + xy[edges[:, 1]])
    inside = np.all((mid >= -1e-9) & (mid <= 1 + 1e-9), axis=1)
    edges, edge_label = edges[inside], edge_label[inside]
    # Dangling pieces bound no cell.
    while len(edges):
        degree = np.bincount(edges.ravel(), minlength=len(xy))
        loose = (degree[edges[:, 0]] < 2) | (degree[edges[:, 1]] < 2)
        if not loose.any():
            break
        edges, edge_label = edges[~loose], edge_label[~loose]
    return edges, edge_label


class _Faces:
    """The third step: the faces of the planar graph that are cells, with their holes.

    ``src``, ``dst``, ``twin`` and ``half_label`` describe the half-edges,
    ``cycles`` the faces as lists of half-edges (each face on its left),
    ``rings`` and ``areas`` their points and signed areas (window units);
    ``holes[f]`` the floating pieces inside face ``f``, ``face_of`` the
    face of each half-edge (-1 where none), and ``keep``/``points`` the
    faces that have an interior point, with that point (window units).
    """

    def __init__(self, xy, edges, edge_label):
        self.src, self.dst, self.twin, self.cycles = _faces(xy, edges)
        self.half_label = np.concatenate([edge_label, edge_label])
        self.rings = [xy[self.src[c]] for c in self.cycles]
        self.areas = np.array([_signed_area(r) for r in self.rings])
        faces, self.holes = self._holes(xy, edges)
        self.face_of = np.full(len(self.src), -1)
        self.keep, self.points = [], []
        for f in faces:
            self.face_of[self.cycles[f]] = f
            ring_list = [self.rings[f]] + [self.rings[h] for h in self.holes[f]]
            pt = _interior_point(ring_list)
            if pt is None:
                continue
            self.keep.append(f)
            self.points.append(pt)

    def _holes(self, xy, edges):
        """``(faces, {face: [holes]})``: the faces of positive area, floating pieces in them.

        A floating piece (a component of the graph apart from the window's)
        is a cycle of negative area, put into the smallest face of another
        component that holds it.
        """
        src, cycles, rings, areas = self.src, self.cycles, self.rings, self.areas
        component = _components(len(xy), edges)
        faces = [k for k in range(len(cycles)) if areas[k] > _AREA]
        holes = {k: [] for k in faces}
        # The window's corner (0, 0): a node of the window's own component.
        corner = component[int(np.flatnonzero(np.max(np.abs(xy), axis=1) <= _MERGE)[0])]
        for k in range(len(cycles)):
            if areas[k] > _AREA or component[src[cycles[k][0]]] == corner:
                continue
            if areas[k] > -_AREA:
                continue
            probe = rings[k][0]
            own = component[src[cycles[k][0]]]
            around = [f for f in faces if component[src[cycles[f][0]]] != own
                      and _inside(rings[f], probe[0], probe[1])]
            if around:
                holes[min(around, key=lambda f: areas[f])].append(k)
        return faces, holes


def _cell_counts(base, ax, ay, family, points, names):
    """The fourth step: the unstable root count of each cell at its interior point.

    ``family`` (:func:`decompose`'s) keeps the count O(d) per cell.  Where
    the count's bounds cannot be closed in double precision (long delays:
    thousands of roots near the circle), the float Schur-Cohn test with its
    safe margin can still tell a stable cell; a cell neither decides is a
    ValueError.  A leading coefficient that vanishes counts -1.
    """
    if family is not None:
        chi = family[0].combine((points[:, 0], points[:, 1]), family[1:])
    else:
        chi = DelayedPolynomial.from_dense(
            base[None, :] + points[:, :1] * ax[None, :] + points[:, 1:] * ay[None, :])
    counts = root_counts(chi) if len(points) else np.zeros(0, dtype=np.int64)
    infinite = leading_vanishes(chi)
    counts[infinite] = -1
    open_ = np.flatnonzero((counts == -1) & ~infinite)
    if len(open_):
        counts[open_[classify_polynomials(chi.take(open_)) == STABLE]] = 0
        open_ = np.flatnonzero((counts == -1) & ~infinite)
    if len(open_):
        p = points[open_[0]]
        raise ValueError(
            f"the unstable roots of {len(open_)} of the {len(points)} cells cannot be counted in "
            f"double precision (degree {len(base) - 1}; e.g. at {names[0]} = {p[0]:.6g}, "
            f"{names[1]} = {p[1]:.6g}): roots too close to the unit circle for the "
            f"certified count")
    return counts


def _crossing_mismatches(faces, counts):
    """The crossing rule across each edge between two counted cells: the pairs that break it.

    ``(cell, cell, label, change)`` for each pair of neighbouring cells
    whose counts differ across a piece by other than :data:`_CHANGE` of its
    label (the arc sampled too coarsely, or a window too wide).
    """
    count_of = dict(zip(faces.keep, counts, strict=True))
    index_of = {f: n for n, f in enumerate(faces.keep)}
    face_of, twin, half_label = faces.face_of, faces.twin, faces.half_label
    mismatches = []
    # Only the half-edges between two counted cells (none on the window) are compared.
    counted = np.isin(face_of, list(count_of))
    between = np.flatnonzero(counted & counted[twin] & (half_label != "window"))
    # Each pair of cells and piece once, at its first half-edge.
    a, b = face_of[between], face_of[twin[between]]
    labels = half_label[between]
    kinds = sorted(set(labels.tolist()))
    code = np.zeros(len(labels), dtype=np.int64)
    for n, label in enumerate(kinds):
        code[labels == label] = n
    # One integer per (cell, cell, label), its first half-edge by a stable sort:
    # np.unique along rows sorts a structured view, many times slower.
    size = int(face_of.max()) + 1 if len(face_of) else 1
    key = (np.minimum(a, b).astype(np.int64) * size + np.maximum(a, b)) * len(kinds) + code
    order = np.argsort(key, kind="stable")
    fresh = np.ones(len(order), dtype=bool)        # (empty: no half-edge between cells)
    fresh[1:] = key[order][1:] != key[order][:-1]
    first = order[fresh]
    for h in between[np.sort(first)].tolist():
        a, b = int(face_of[h]), int(face_of[twin[h]])
        label = half_label[h]
        ca, cb = count_of[a], count_of[b]
        if ca < 0 or cb < 0:
            continue
        if abs(int(ca) - int(cb)) != _CHANGE[label]:
            mismatches.append((index_of[a], index_of[b], label, int(cb) - int(ca)))
    return mismatches


def _unbounded_sides(faces, stable, xy):
    """The window's sides the ``stable`` faces have an edge on (x_min, x_max, y_min, y_max).

    A piece running along the window's edge is the piece's, not the
    window's: only half-edges labelled ``"window"`` count.
    """
    touched = set()
    for f in stable:
        for h in faces.cycles[f]:
            if faces.half_label[h] == "window":
                u, v = 0.5 * (xy[faces.src[h]] + xy[faces.dst[h]])
                touched.add("x_min" if u < 1e-6 else "x_max" if u > 1 - 1e-6
                            else "y_min" if v < 1e-6 else "y_max")
    return tuple(side for side in ("x_min", "x_max", "y_min", "y_max") if side in touched)


def _resolution(faces, stable, xy):
    """How finely the arc draws the ``stable`` faces: the chords' largest sag over a cell's extent.

    Infinite for a cell thinner than :data:`_SMALLEST` of the window: the
    merging and end tolerances are the window's and would be visible on it.
    """
    resolution = 0.0
    for f in stable:
        extent = float(np.min(np.ptp(faces.rings[f], axis=0)))
        if extent < _SMALLEST:
            return math.inf
        cycle = np.array(faces.cycles[f])
        on_arc = faces.half_label[cycle] == "arc"
        both = on_arc & np.roll(on_arc, 1)
        if both.any() and extent > 0:
            # The sag of two chords meeting at an angle phi is about
            # L phi / 8: against the cell's thinner extent.
            step = xy[faces.dst[cycle]] - xy[faces.src[cycle]]
            length = np.hypot(step[:, 0], step[:, 1])
            heading = np.arctan2(step[:, 1], step[:, 0])
            phi = np.abs(np.angle(np.exp(1j * (heading - np.roll(heading, 1)))))
            sag = np.maximum(length, np.roll(length, 1)) * phi / 8
            resolution = max(resolution, float(np.max(sag[both])) / extent)
    return resolution


def _line_sides(rings, src, dst, half_label):
    """``(label, first node, last node)`` of each run of the rings' half-edges on z = +-1.

    A stable cell's boundary runs counter-clockwise, so two stable cells
    that meet on one line (where an arc touches it) continue each other's
    run head to tail.
    """
    step = {}
    for ring in rings:
        for h in ring:
            if half_label[h] in ("z = 1", "z = -1"):
                step[half_label[h], int(src[h])] = int(dst[h])
    tails = {(label, b) for (label, _), b in step.items()}
    out = []
    for (label, a), b in sorted(step.items()):
        if (label, a) not in step or (label, a) in tails:
            continue            # not the first half-edge of a run (or already walked)
        del step[label, a]
        while (label, b) in step:
            b = step.pop((label, b))
        out.append((label, a, b))
    return out


def _components(n, edges):
    """The connected component of each of ``n`` nodes joined by ``edges`` (labels, equal or not)."""
    graph = scipy.sparse.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                                    shape=(n, n))
    return scipy.sparse.csgraph.connected_components(graph, directed=False)[1]
