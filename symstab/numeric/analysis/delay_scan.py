"""The one search of the exact delay margin, for one point or many at once.

Along a grid of delays (``step`` of a sample apart, from the points' delay
up), the certified verdict (:meth:`symstab.Loop.classify`) of every point
still searched: one call per whole part of the grid, the grid's fractions of
that sample as one array (the fractional plant is derived once per fraction
and shared by every point: the plant does not hold a plane's parameters, and
when it does each row is derived once still).  Each change of verdict is a
bracket of two neighbours of the grid, refined by the one root bracketer
(:func:`symstab.numeric.engine.search.bracketed_root`, every bracket at
once) on the spectral radius less 1, continuous in the delay (also across
whole samples), while ``chi``'s degree allows companion eigenvalues (128:
a few evaluations close the bracket); above, where each radius is a
bisection of certified counts of its own (some fifty times a verdict's cost
at a few hundred samples of delay), on the certified verdict itself
(``+-1/2``: not stable or stable), which narrows each bracket an evaluation
down to a few ulps of the delay.

:func:`symstab.numeric.analysis.delays.delay_margin` (one point, every
switch or the first) and the delay-margin map
(:func:`symstab.numeric.analysis.margins.margin_map`, the first switch of
every stable point of a grid of the plane) both search with this module.
"""

import math

import numpy as np

from ..engine.roots import EIGENVALUES_UP_TO_DEGREE, STABLE
from ..engine.search import bracketed_root
from ..loop.evaluation import FRACTION

__all__ = ["STEPS_PER_SAMPLE", "delay_grid", "verdict_changes", "crossing_delays",
           "first_crossings"]

#: Points of the grid per sample of delay (the default ``step`` is its inverse).
STEPS_PER_SAMPLE = 16


def delay_grid(start, limit, step):
    """The delays searched: ``start``, ``start + step``, ... up to ``start + limit`` (the last)."""
    n = int(math.ceil(limit / step - 1e-9))
    grid = start + step * np.arange(n + 1)
    grid[-1] = min(grid[-1], start + limit)
    return grid


def verdict_changes(loop, values, points, grid, *, first_only, first_whole=None):
    """Where each point's verdict changes along ``grid``, and how far each was examined.

    Parameters
    ----------
    loop : symstab.Loop
    values : dict
        Single values of the parameters the points share (the delay apart).
    points : dict
        ``{name: 1-D array}`` of the parameters that differ between the
        points, all of one length (``{}``: one point).
    grid : ndarray
        The delays, samples, increasing; ``grid[0]`` the points' own, where
        they are stable.
    first_only : bool
        Stop each point at its first change (the loss of stability).
    first_whole : callable, optional
        ``first_whole(chi)``: for each point of a
        :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial`
        (flat), the first whole number of samples added to its shift at
        which it can be unstable (inf: at none), given that it is stable
        (:func:`symstab.numeric.analysis.margins.first_whole_delays`).  With
        a whole number of grid points a sample, each fraction of the grid
        is such a family (``chi = z**d (z P_d) Ve_d + N_eps Ve_n``: at a
        fixed ``eps`` the whole samples added are ``z**-k``): once the
        first sample of the grid is stable, the grid's points of each
        fraction before its bound are known stable and not asked.

    Returns
    -------
    (ndarray, ndarray, ndarray, ndarray)
        ``rows, index, stable_after`` of each change (the point, the grid's
        index after the change, the verdict there), by point then delay;
        and the last index of the grid examined per point.
    """
    n = _count(points)
    wholes = np.floor(grid)
    per = _per_sample(grid) if first_whole is not None else None
    before = np.ones(n, dtype=bool)
    examined = np.zeros(n, dtype=np.int64)
    # The first index of the grid not known stable, per point.
    ask_from = np.zeros(n)
    pending = np.arange(n)
    found = [(np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=bool))]
    for whole in np.unique(wholes):
        if pending.size == 0:
            break
        cols = np.flatnonzero(wholes == whole)
        asked = pending[ask_from[pending] <= cols[-1]]
        if asked.size:
            stable = _stable_at(loop, values, {k: v[asked] for k, v in points.items()},
                                int(whole), grid[cols] - whole, asked.size)
            previous = np.concatenate([before[asked, None], stable[:, :-1]], axis=1)
            changed = stable != previous
            if first_only:
                changed &= np.cumsum(changed, axis=1) == 1
            rows, k = np.nonzero(changed)
            found.append((asked[rows], cols[k], stable[rows, k]))
            before[asked] = stable[:, -1]
        examined[pending] = cols[-1]
        if first_only and asked.size:
            lost = changed.any(axis=1)
            examined[asked[lost]] = cols[np.argmax(changed[lost], axis=1)]
            pending = np.setdiff1d(pending, asked[lost])
        if per is not None and cols[0] < per <= cols[-1] + 1:
            # The first sample examined: each fraction's base (stable where no change was found).
            calm = np.setdiff1d(pending, np.concatenate([f[0] for f in found]))
            ask_from[calm] = _known_stable(loop, values, points, grid[:per], calm, first_whole)
    rows, index, after = (np.concatenate(parts) for parts in zip(*found, strict=True))
    order = np.lexsort((index, rows))
    return rows[order], index[order], after[order], examined


def _per_sample(grid):
    """Points of ``grid`` a sample when that is a whole number (its fractions repeat), else None."""
    if grid.size < 3:
        return None
    per = 1.0 / (grid[1] - grid[0])
    return int(round(per)) if abs(per - round(per)) <= 1e-9 * per and grid.size > per else None


def _known_stable(loop, values, points, bases, rows, first_whole):
    """The first index of the grid not known stable, for the points ``rows`` stable at ``bases``.

    ``bases``: the grid's first sample, one point of each fraction; the
    point of fraction ``j`` after ``k`` whole samples is the grid's ``j + k
    len(bases)``.
    """
    per = bases.size
    bound = np.empty((rows.size, per))
    wholes = np.floor(bases)
    for whole in np.unique(wholes):
        j = np.flatnonzero(wholes == whole)
        chi = loop.polynomial(**_given(values, {k: v[rows] for k, v in points.items()},
                                       int(whole), bases[j] - whole, (-1, 1)))
        bound[:, j] = np.broadcast_to(np.reshape(first_whole(chi), chi.shape),
                                      (rows.size, j.size))
    return np.min(np.arange(per) + per * bound, axis=1)


def crossing_delays(loop, values, points, rows, low, high):
    """The delay at which point ``rows[i]``'s verdict changes in ``[low[i], high[i]]``.

    Every bracket at once (:func:`~symstab.numeric.engine.search.bracketed_root`
    with ``indexed``), on the spectral radius less 1 up to degree
    :data:`~symstab.numeric.engine.roots.EIGENVALUES_UP_TO_DEGREE`, else on
    ``+1/2`` where not stable and ``-1/2`` where stable (the module's
    docstring says why); each evaluation one call of the loop per whole part
    of the delays asked (the fractions an array).  Returns the delays,
    samples, to a few ulps: where a root is on the circle to within the
    rounding of the radius, or of the verdict.
    """
    rows = np.asarray(rows, dtype=np.int64)
    if rows.size == 0:
        return np.zeros(0)
    # chi's degree less its whole delay: the method is chosen per whole part (the same for
    # a point alone and in a grid).
    base = loop.polynomial(**_given(values, {n: v[rows[:1]] for n, v in points.items()}, 0,
                                    np.array([0.5]), (-1,))).degree

    def excess(x, index):
        out = np.empty(x.size)
        wholes = np.floor(x)
        for whole in np.unique(wholes):
            k = np.flatnonzero(wholes == whole)
            at = ({n: v[rows[index[k]]] for n, v in points.items()}, int(whole), x[k] - whole)
            if whole + base <= EIGENVALUES_UP_TO_DEGREE:
                # Continuous in the delay; at the ends on either side of 1.
                out[k] = _radius(loop, values, *at) - 1.0
            else:
                out[k] = np.where(_stable_at(loop, values, *at, k.size, paired=True), -0.5, 0.5)
        return out

    return bracketed_root(excess, low, high, indexed=True)


def first_crossings(loop, values, points, start, limit, step, first_whole=None):
    """Each point's exact delay margin: the first added delay at which it is not stable.

    The first change of :func:`verdict_changes` along :func:`delay_grid`
    (``first_whole`` as there) refined by :func:`crossing_delays`.  Returns an array over the points,
    samples added to ``start``, ``inf`` where stable up to ``limit`` more.
    """
    out = np.full(_count(points), np.inf)
    if limit <= 0:
        return out
    grid = delay_grid(start, limit, step)
    rows, index, _, _ = verdict_changes(loop, values, points, grid, first_only=True,
                                        first_whole=first_whole)
    out[rows] = crossing_delays(loop, values, points, rows, grid[index - 1], grid[index]) - start
    return out


def _count(points):
    """How many points: the length of the arrays of ``points`` (1 with none)."""
    sizes = {np.size(v) for v in points.values()}
    if len(sizes) > 1:
        raise ValueError(f"the points' values must have one length, got {sorted(sizes)}")
    return sizes.pop() if sizes else 1


def _given(values, points, whole, fractions, shape):
    """A call's values: the points' (broadcast to ``shape``), the whole delay, the fractions."""
    given = {**values, **{k: np.reshape(v, shape) for k, v in points.items()}, "d": whole}
    # The fractions as they are (0 too), the plant at each derived once for every point.
    given[FRACTION] = fractions
    return given


def _stable_at(loop, values, points, whole, fractions, n, *, paired=False):
    """Whether each of ``n`` points is stable at each delay ``whole + fractions``: ``(n, m)``.

    ``paired``: point ``i`` at ``whole + fractions[i]`` only, 1-D.
    """
    shape = (-1,) if paired else (-1, 1)
    code = loop.classify(**_given(values, points, whole, fractions, shape))
    return np.broadcast_to(np.asarray(code) == STABLE, (n,) if paired else (n, fractions.size))


def _radius(loop, values, points, whole, fractions):
    """The spectral radius of each point at its delay ``whole + fractions[i]``: 1-D."""
    radius = loop.spectral_radius(**_given(values, points, whole, fractions, (-1,)))
    return np.broadcast_to(np.asarray(radius, dtype=float), fractions.shape)
