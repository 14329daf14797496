"""A loop's questions in a plane of two of its parameters: region, limits, boundary, intervals.

Each is a function of a :class:`symstab.Loop` (the loop's methods of the
same names pass through to them).  The boundary of a parameter plane is the
D-decomposition: on ``z = exp(j theta)`` the two real equations ``Re chi =
Im chi = 0`` are linear in the plane's parameters ``(x, y)`` and solved per
``theta`` (the loop's :meth:`~symstab.Loop.arc`); ``z = 1``, ``z = -1`` and
a vanishing leading coefficient give straight lines
(:func:`symstab.numeric.engine.decomposition.decompose` cuts the plane
into cells with them).  Here: the plane's parts from the loop, the window
found and widened, the stable set's limits, and the stable intervals of
one line (:func:`symstab.numeric.engine.intervals.family_intervals`).

May import what :mod:`symstab.numeric.loop` may: the base layer,
``symbolic``, ``codegen`` and :mod:`symstab.numeric.engine`.
"""

import dataclasses
import functools
import math

import numpy as np

from ..._resources import check_memory
from ..._validate import check_array, check_box, check_count, check_real, check_window
from ..engine.arcs import RememberedArc
from ..engine.decomposition import Decomposition, Unresolved, decompose, stable_hull, window_arc
from ..engine.decomposition import lines as _lines
from ..engine.intervals import family_intervals
from ..engine.results import Boundary
from ..engine.roots import STABLE, classify_polynomials

__all__ = ["stable_intervals", "boundary", "region", "limits", "LARGEST_COORDINATE"]


#: Largest coordinate of a window of :func:`region`: products of two
#: coordinates (areas, cross products of the cells' edges) stay finite.
LARGEST_COORDINATE = 1e150

#: The four sides of a window, in the order of ``(x_min, x_max, y_min, y_max)``.
_SIDES = ("x_min", "x_max", "y_min", "y_max")
#: A free side a stable cell reaches moves out by this many widths of its window.
_GROWTH = 3


def stable_intervals(loop, name, **values):
    """The stable intervals of one parameter of a loop, the others fixed.

    The polynomial is ``A0(z) + p A1(z)`` in the parameter ``p``, so a
    root crosses the unit circle only at the ``p`` where ``A0 + p A1``
    vanishes at some ``z = exp(j theta)``: where ``Im(A0 conj A1) = 0``,
    at ``z = +-1``, and where the leading coefficient vanishes.  The
    one line engine (:func:`symstab.numeric.engine.intervals.family_intervals`)
    finds them on the structured polynomial (O(d) per angle and per
    certified count, whatever the delay) and counts the roots outside
    the circle between them.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    name : str
        A parameter in :meth:`~symstab.Loop.affine_parameters`.
    **values
        Single values of every other parameter (``d`` included).  One
        other parameter of :meth:`~symstab.Loop.affine_parameters` may be
        given a 1-D array instead: a family of parallel lines, one per
        value, scanned and counted together.

    Returns
    -------
    list of (float, float)
        Stable intervals ``(lo, hi)``, increasing; ``lo`` may be
        ``-inf`` and ``hi`` ``inf``.  Endpoints are unstable or marginal.
        A line on which every value has a root exactly at ``z = 1`` or
        ``z = -1`` has none.  For a family, one such list per value.

    Raises
    ------
    ValueError
        For more than one array, and where a line cannot be resolved in
        double precision (every stretch of it has a root on the unit
        circle to within rounding).
    """
    arrays = [k for k, v in values.items() if k != "d" and np.ndim(v) > 0]
    if len(arrays) > 1:
        raise ValueError(f"at most one parameter may be an array (a family of lines), got "
                         f"{', '.join(arrays)}")
    across = arrays[0] if arrays else None
    family = across is not None
    if not family and loop.plane is not None and name in loop.plane:
        # One line of the plane's family: the base polynomial then has
        # both plane parameters at 0, so a value that vanishes there
        # (chi(1) with K = 0) is exactly 0, as on every line of a family.
        other = loop.plane[1 - loop.plane.index(name)]
        if other in loop.defaults or other in values:
            across = other
    at = np.zeros(1)
    if across is not None:
        at = check_array(across, values.get(across, loop.defaults.get(across)))
        if at.ndim > 1:
            raise ValueError(f"{across} must be a single value or a 1-D array of values, "
                             f"got shape {at.shape}")
        at = at.reshape(-1)
        values = {k: v for k, v in values.items() if k != across}
    names = (name,) if across is None else (name, across)
    base, slopes, ends = loop.affine_parts(names, values, structured=True)
    # The crossings with the arc are re-found on the loop's arc source
    # where it is more accurate than the float parts the engine scans.
    arc = None if across is None else loop.evaluation.arc_points(across, name, values)
    runs = family_intervals(base, slopes[1] if across else None, slopes[0], at,
                            (tuple(ends[0]), tuple(ends[2]) if across else None, tuple(ends[1])),
                            arc=arc)
    if across is not None and not family:
        values = {**values, across: float(at[0])}
    for value, r in zip(at, runs, strict=True):
        if r is None:
            fixed = ", ".join(f"{k} = {v:g}" for k, v in values.items() if k != "d")
            if family:
                fixed = f"{across} = {value:g}" + (", " + fixed if fixed else "")
            raise ValueError(
                f"the loop's polynomial along {name} cannot be resolved in double precision "
                f"at {fixed}, d = {values.get('d', loop.defaults.get('d'))}: every stretch "
                f"has a root on the unit circle to within rounding (a value far outside "
                f"the loop's usual range?)")
    return runs if family else runs[0]


@dataclasses.dataclass(frozen=True)
class _PlaneParts:
    """The ``(x, y)`` plane of a loop at fixed values: ``chi = A0 + x Ax + y Ay`` and its arc."""

    x: str
    y: str
    base: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    ends: list
    arc: object
    family: tuple

    @classmethod
    def of(cls, loop, x, y, values):
        """The plane's parts from the loop (dense rows, structured family, arc source)."""
        structured, slopes, ends = loop.affine_parts((x, y), values, structured=True)
        base, ax, ay = (p.dense().reshape(-1) for p in (structured, *slopes))
        arc = loop.evaluation.arc_source(x, y, values, (structured, *slopes))
        return cls(x, y, base, ax, ay, ends, arc, (structured, *slopes))

    def decompose(self, box, refine=True):
        """:func:`~symstab.numeric.engine.decomposition.decompose` in the window ``box``.

        Without its segments (:meth:`Decomposition.with_segments` makes them
        for the window kept).
        """
        if not all(abs(v) <= LARGEST_COORDINATE for v in box):
            x, y = self.x, self.y
            raise ValueError(
                f"the {x}, {y} window {x} in [{box[0]:.3g}, {box[1]:.3g}], {y} in "
                f"[{box[2]:.3g}, {box[3]:.3g}] goes beyond {LARGEST_COORDINATE:g}, where "
                f"the cells' areas overflow double precision: give the loop's values in "
                f"units that keep the plane's numbers smaller")
        return decompose(self.base, self.ax, self.ay, self.ends, x_range=box[:2],
                         y_range=box[2:], names=(self.x, self.y), arc=self.arc,
                         family=self.family, refine=refine, segments=False)


def boundary(loop, x=None, y=None, n=1000, *, window=None, segments=False, **values):
    """The D-decomposition of a loop's ``(x, y)`` plane: its arc and lines.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x, y : str
        Two parameters entering the polynomial jointly affinely
        (default: the loop's :attr:`~symstab.Loop.plane`).
    n : int
        Angles in (0, pi), evenly spaced (without ``window``).
    window : ((float, float), (float, float)), optional
        ``(x_range, y_range)``: the arc sampled to be drawn there instead,
        adaptively (:func:`symstab.numeric.engine.decomposition.window_arc`: no
        chord in the window longer than 2e-3 of it, NaN far from it).
    segments : bool
        Also find the pieces of the z = +-1 lines that close the stable
        set (from :func:`region`: seconds at long delays).
    **values
        Single values of every other parameter.

    Returns
    -------
    symstab.numeric.engine.results.Boundary
    """
    x, y = loop.plane_of(x, y)
    n = check_count("n", n, 2)
    check_memory("the boundary", 64 * n)
    plane = _PlaneParts.of(loop, x, y, values)
    if window is None:
        theta = np.pi * (np.arange(1, n + 1) - 0.5) / n
        xs, ys, _ = plane.arc(theta)
    else:
        theta, xs, ys = window_arc(plane.arc, len(plane.base) - 1, *check_box("window", window))
    lines = {label: c for label, c in _lines(plane.base, plane.ax, plane.ay, plane.ends).items()
             if c[1] or c[2]}
    pieces = region(loop, x, y, **values).segments if segments else ()
    return Boundary(x, y, theta, xs, ys, lines=lines, segments=pieces, at=dict(values))


def region(loop, x=None, y=None, *, x_range=None, y_range=None, **values):
    """The complete D-decomposition of a loop's ``(x, y)`` plane: cells, root counts, stable set.

    Every branch of the arc (``theta`` over all of (0, pi)), the z = 1,
    z = -1 and leading-coefficient lines, the cells they cut the window
    into and the certified count of unstable roots in each
    (:func:`symstab.numeric.engine.decomposition.decompose`).  The points
    stable for every value in a box of uncertain parameters are
    :func:`symstab.numeric.analysis.robust.robust_region`'s.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x, y : str
        The plane's parameters, jointly affine (default: the loop's
        :attr:`~symstab.Loop.plane`).
    x_range, y_range : (float, float), optional
        The window.  A side not given is found.  First, where a stable
        point can be at all (:func:`symstab.numeric.engine.decomposition.stable_hull`,
        exact): when nowhere, that is the answer; when in a bounded
        polygon, no window goes beyond its box.  The window starts
        around the stable points next to the arc and the lines (or,
        when none is sampled, is the box itself, so a set too small to
        be sampled is still found, and a set not found there is empty)
        and is widened (up to 10 times) while a stable cell reaches that
        side; if it still does, the side is in
        :attr:`Decomposition.unbounded`.
    **values
        Single values of every other parameter.

    Returns
    -------
    symstab.numeric.engine.decomposition.Decomposition
        Its ``hull`` is the enclosure used (None when both ranges are
        given).  When the enclosure is empty, no point is stable and the
        decomposition has no cells (its window is the curves' extent, or
        the one given).

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=10))
    >>> found = region(loop, "B", "K")
    >>> [cell.count for cell in found.stable]
    [0]
    """
    x, y = loop.plane_of(x, y)
    given = {key: None if window is None else check_window(key, window)
             for key, window in (("x_range", x_range), ("y_range", y_range))}
    plane = _PlaneParts.of(loop, x, y, values)
    free = {"x_min": given["x_range"] is None, "x_max": given["x_range"] is None,
            "y_min": given["y_range"] is None, "y_max": given["y_range"] is None}
    # Where a stable point can be at all (exact): an empty enclosure is the
    # answer, a bounded one caps every window a free side may take.
    hull = stable_hull(plane.base, plane.ax, plane.ay) if any(free.values()) else None
    if hull is not None and hull.empty:
        auto = _curve_windows(plane)[-1]
        box = [*(given["x_range"] or auto[0]), *(given["y_range"] or auto[1])]
        return Decomposition(x=x, y=y, x_range=tuple(box[:2]), y_range=tuple(box[2:]),
                             branches=(), cells=(), mismatches=(), unbounded=(),
                             polynomial=(plane.base, plane.ax, plane.ay), hull=hull)
    enclosure = hull.box() if hull is not None else None
    # The windows' decompositions sample one arc: each angle is evaluated once
    # (the answer keeps the plain source, not the values remembered).
    source, plane = plane.arc, dataclasses.replace(plane, arc=RememberedArc(plane.arc))
    found, box = _first_decomposition(plane, given, free, hull)
    found = _widened(plane, found, box, free, enclosure).with_segments()
    return dataclasses.replace(found, hull=hull, arc=source)


def _fitted(box, cells, free):
    """The free sides of ``box`` fitted to ``cells``, a quarter of their extent around."""
    points = np.vstack([cell.outer for cell in cells])
    box = list(box)
    for k, side in enumerate(free):
        if free[side]:
            column = points[:, k // 2]
            lo, hi = float(column.min()), float(column.max())
            pad = 0.25 * (hi - lo) or 0.05 * (box[k // 2 * 2 + 1] - box[k // 2 * 2])
            box[k] = lo - pad if k % 2 == 0 else hi + pad
    return box


def _shrunk(box, cells, sides):
    """``box`` with ``sides`` moved in to the ``cells``, as far out from them as a widening grows.

    A side no stable cell reaches need not run far past the stable set: the
    set may still grow towards it with the widening of the others (a thin
    diagonal sliver does), by at most :data:`_GROWTH` times its extent.
    """
    if not cells or not sides:
        return box
    points = np.vstack([cell.outer for cell in cells])
    box = list(box)
    for side in sides:
        k = _SIDES.index(side)
        column = points[:, k // 2]
        lo, hi = float(column.min()), float(column.max())
        pad = (_GROWTH + 1) * (hi - lo)
        if pad > 0:
            box[k] = max(box[k], lo - pad) if k % 2 == 0 else min(box[k], hi + pad)
    return box


def _first_decomposition(plane, given, free, hull):
    """The first window that holds a stable cell (:func:`_start_windows`), decomposed.

    Returns ``(found, box)``.

    Raises what the last window refused, or a ValueError, when no window
    holds a stable cell and the windows tried do not hold every point that
    can be stable (to call the set empty would then be a guess).
    """
    found, refused = None, None
    for auto in _start_windows(plane, hull):
        box = [*(given["x_range"] or auto[0]), *(given["y_range"] or auto[1])]
        try:
            found, box = _decomposed_start(plane, box, free)
        except ValueError as exc:    # a first window too wide to resolve: try the next
            refused = exc
            continue
        if found.stable:
            break
    if found is None:
        raise refused
    if not found.stable and not _covers(found, hull.box() if hull is not None else None, free):
        if refused is not None:
            raise refused
        raise ValueError(
            f"no stable point in the {plane.x}, {plane.y} windows tried, and the necessary "
            f"condition for stability leaves an unbounded part of the plane (the leading "
            f"coefficient of the loop's polynomial changes in it, say), so a stable set outside "
            f"them is not excluded: give x_range and y_range")
    return found, box


def _decomposed_start(plane, box, free):
    """A first window decomposed, or narrowed to the stable cells its first pass cannot resolve.

    Returns ``(found, box)``.  A stable cell tiny beside its window (a
    sliver where the stable set is about to vanish, or next to a point
    where three arcs cross) breaks the first pass's resolution or topology:
    the window narrowed around the stable cells that pass found resolves it
    (and is checked anew; the widening still reaches every side a stable
    cell touches), without sampling the whole window up to 64 times finer.
    When that fails, the window is decomposed with the finer pass, whose
    refusal is raised.
    """
    try:
        return plane.decompose(box, refine=False), box
    except Unresolved as exc:
        narrowed = (_fitted(box, exc.attempt.stable, free)
                    if exc.attempt.stable and any(free.values()) else box)
    if narrowed != box:
        try:
            return plane.decompose(narrowed), narrowed
        except ValueError:
            pass
    return plane.decompose(box), box


def _widened(plane, found, box, free, enclosure):
    """``found`` with the free sides a stable cell reaches widened, then fitted to the stable set.

    Never past the ``enclosure``, which holds the whole stable set; once no
    stable cell reaches a free side, those sides are fitted to the stable
    set, a quarter of its extent around it.
    """
    limit = [-math.inf, math.inf, -math.inf, math.inf]
    if enclosure is not None:
        limit = [*enclosure[0], *enclosure[1]]
    fitted = not any(free.values())
    for _ in range(12):
        grow = [side for side in found.unbounded if free[side]]
        before = list(box)
        if grow:
            # The free sides no stable cell reaches are fitted to the stable set
            # as the others grow: a window tall beside a thin sliver (a first
            # window found on a step far below the set's width) samples the arc
            # finely along all of its height, seconds a decomposition.
            box = _shrunk(box, found.stable, [side for side in _SIDES
                                              if free[side] and side not in grow])
            span = (box[1] - box[0], box[3] - box[2])
            for side in grow:
                k = _SIDES.index(side)
                box[k] += (-1 if k % 2 == 0 else 1) * _GROWTH * span[k // 2]
                box[k] = max(box[k], limit[k]) if k % 2 == 0 else min(box[k], limit[k])
            if box == before:
                break
            fitted = False
        elif found.stable and not fitted:
            box = _fitted(box, found.stable, free)
            fitted = True
        else:
            break
        found = plane.decompose(box)
    return found


def limits(loop, x=None, y=None, **values):
    """The extent and area of the stable set in a loop's ``(x, y)`` plane.

    Read from :func:`region`: the stable cells' polygons give the area
    (exact up to the chords of the sampled arc), and their extreme
    vertices the extent, refined along the arc by a zooming grid search
    where the extreme is a smooth turn of the arc rather than a corner.

    Parameters
    ----------
    loop, x, y
        As in :func:`region`.
    **values
        Single values of every other parameter (and ``x_range`` /
        ``y_range`` for :func:`region`).  The robust set's limits are
        :func:`symstab.numeric.analysis.robust.robust_region`'s
        (:meth:`symstab.Loop.limits` with ``uncertain``, ``strips`` and
        ``rtol``: :attr:`~symstab.numeric.engine.results.Limits.region` is
        then the :class:`~symstab.numeric.engine.results.RobustRegion`).

    Returns
    -------
    symstab.numeric.engine.results.Limits
        Empty (``y_max`` None, ``area`` 0, :attr:`~symstab.numeric.engine.results.Limits.reason`
        says why) when no point is stable: proved, not a failure to find
        one (see :func:`region`).
    """
    for option in ("uncertain", "strips", "rtol", "progress"):
        if values.pop(option, None) is not None and option != "uncertain":
            raise TypeError(f"{option} is an option of the robust region: give uncertain too")
    found = region(loop, x, y, **values)
    at = {k: v for k, v in values.items() if k not in ("x_range", "y_range")}
    return found.limits(at=at, line=functools.partial(_stable_intervals_at, loop, found.x,
                                                      found.y, at))


def _stable_intervals_at(loop, x, y, values, at):
    """The stable ``y`` intervals of ``loop`` at ``x = at`` (:attr:`Limits.line`)."""
    return loop.stable_intervals(y, **{x: check_real(x, at)}, **values)


def _covers(found, enclosure, free):
    """Whether the window of ``found`` reaches ``enclosure`` on every free side."""
    if enclosure is None:
        return not any(free.values())
    window = (*found.x_range, *found.y_range)
    bound = (*enclosure[0], *enclosure[1])
    return all(not free[side] or (window[k] <= bound[k] if k % 2 == 0 else window[k] >= bound[k])
               for k, side in enumerate(_SIDES))


def _start_windows(plane, hull=None):
    """First windows for :func:`region`, tried in turn until one holds a stable cell.

    First the extent of stable points next to the curves (a few steps off
    the arc's points and the lines' crossings, classified at once on the
    plane's structured family ``(A0, Ax, Ay)``, and only where the ``hull``
    holds them: a point outside it is proved unstable): it is on the scale
    of the stable set however far the arc runs.  Then, when the stable set
    has a bounded enclosure (the box of the
    :func:`symstab.numeric.engine.decomposition.stable_hull`), the enclosure
    itself, which holds every stable point: a stable set too small for the
    steps is found there, and one that is not found there is empty.
    Without one, the extent of the curves themselves, without the outer 2 %
    on each side (the arc may run off to infinity), then all of it.  A
    quarter of the span is added on each side, and each window is cut to
    the enclosure.
    """
    enclosure = hull.box() if hull is not None else None
    xs, ys, _ = _curve_points(plane, per_degree=4, first_lobe=64)
    candidates = []
    if xs.size:
        # Steps on each point's own scale: its size and the distance to its
        # neighbour (at long delays the stable set is tiny beside the arc's reach).
        sx = np.abs(xs) + np.abs(np.diff(xs, append=xs[-1])) + 1e-300
        sy = np.abs(ys) + np.abs(np.diff(ys, append=ys[-1])) + 1e-300
        px, py = [], []
        for step in (1e-5, 1e-3, 1e-2, 1e-1):
            for ux, uy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                px.append(xs + ux * step * sx)
                py.append(ys + uy * step * sy)
        px, py = np.concatenate(px), np.concatenate(py)
        if hull is not None:
            held = hull.holds(px, py)
            px, py = px[held], py[held]
        candidates.append((*_stable_extent(plane, px, py), 0.0))
    out = _extent_windows(candidates, enclosure)
    if enclosure is not None:
        out.append(tuple(enclosure))
    else:
        out += [w for w in _curve_windows(plane) if w not in out]
    return out or [((-1.0, 1.0), (-1.0, 1.0))]


def _stable_extent(plane, px, py):
    """The points of ``(px, py)`` that are stable, or fewer with the same extremes in x and y.

    A point strictly inside the box of stable points already found cannot
    move the box: a quarter of the points (every fourth) is classified
    first, then only those of the rest on or outside that box.
    """
    family = plane.family

    def stable(index):
        if not len(index):
            return index
        codes = classify_polynomials(family[0].combine((px[index], py[index]), family[1:]),
                                     refine=False)
        return index[codes == STABLE]

    everything = np.arange(len(px))
    first = stable(everything[::4])
    rest = np.setdiff1d(everything, everything[::4])
    if len(first):
        x, y = px[first], py[first]
        outside = ((px[rest] <= x.min()) | (px[rest] >= x.max())
                   | (py[rest] <= y.min()) | (py[rest] >= y.max()))
        rest = rest[outside]
    found = np.sort(np.concatenate([first, stable(rest)]))
    return px[found], py[found]


def _curve_windows(plane):
    """The extent of the arc and the lines' crossings: without the outer 2 % on each side, then all."""
    xs, ys, _ = _curve_points(plane)
    return _extent_windows([(xs, ys, 0.02), (xs, ys, 0.0)]) or [((-1.0, 1.0), (-1.0, 1.0))]


def _extent_windows(candidates, enclosure=None):
    """A window per ``(xs, ys, q)``: the ``q`` to ``1 - q`` quantiles, a quarter of the span added.

    Each is cut to ``enclosure`` (``(x_range, y_range)``) when given; an
    empty or repeated window is left out.
    """
    out = []
    for cx, cy, q in candidates:
        if cx.size == 0:
            continue
        window = []
        for k, v in enumerate((cx, cy)):
            lo, hi = float(np.quantile(v, q)), float(np.quantile(v, 1 - q))
            pad = 0.25 * (hi - lo) or 0.1 * max(abs(lo), abs(hi), 1e-300)
            lo, hi = lo - pad, hi + pad
            if enclosure is not None:
                lo, hi = max(lo, enclosure[k][0]), min(hi, enclosure[k][1])
            window.append((lo, hi))
        ok = all(np.isfinite(window).ravel()) and all(lo < hi for lo, hi in window)
        if ok and tuple(window) not in out:
            out.append(tuple(window))
    return out


def _curve_points(plane, per_degree=16, first_lobe=0):
    """Points of the plane's arc (finite ones) and the lines' crossings.

    The arc at ``per_degree (n + 4)`` angles, plus ``first_lobe`` more below
    ``8 pi / (n + 4)``, where at long delays the stable set's arc lies, and
    with ``first_lobe`` 24 more spaced geometrically from ``1e-6`` of the
    first angle up to it, and as many next to pi: a stable set next to an
    end of the arc can be bounded by a piece far shorter than the grid's
    step (at gamma = -1 the paper's loop has its whole set below theta =
    0.03, under the first angle of a grid of 48).
    """
    n = len(plane.base) - 1
    m = per_degree * (n + 4)
    theta = np.pi * (np.arange(1, m + 1) - 0.5) / m
    if first_lobe:
        lobe = 8 * np.pi / (n + 4) * np.arange(1, first_lobe + 1) / first_lobe
        near = theta[0] * np.geomspace(1e-6, 1.0, 24, endpoint=False)
        theta = np.union1d(theta, np.concatenate([lobe, near, np.pi - near]))
    xs, ys, _ = plane.arc(theta)
    lines = list(_lines(plane.base, plane.ax, plane.ay, plane.ends).values())
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            (c0, c1, c2), (e0, e1, e2) = lines[i], lines[j]
            det = c1 * e2 - c2 * e1
            if det != 0:
                xs = np.append(xs, (-c0 * e2 + c2 * e0) / det)
                ys = np.append(ys, (-c1 * e0 + c0 * e1) / det)
    keep = np.isfinite(xs) & np.isfinite(ys)
    return xs[keep], ys[keep], theta
