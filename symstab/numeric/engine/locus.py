"""Root locus: the closed-loop poles tracked along a path of one parameter.

:func:`locus` (any :class:`symstab.Loop`; the paper's normalised loop is
:func:`symstab.numeric.paper.paper_loop.paper_locus`, a use of it) follows every root of the characteristic
polynomial as one parameter runs through a list of values, the others
fixed -- for example the stiffness ``K`` at a fixed damping ``B``, a
vertical line of the paper's ``(beta, alpha)`` plane -- and find where a
pole crosses the unit circle.

* Roots: companion-matrix eigenvalues per point, polished by Newton steps
  on the polynomial (:func:`symstab.numeric.paper.stability.spectral_radius`
  does the same for the largest); from degree 64 on, the path's points
  after the first continue the previous point's roots by Newton's steps
  (O(degree**2) a point, not O(degree**3)), kept only where every root
  settles a clear way from the others, else the eigenvalues.
* Tracking: the roots of consecutive points are matched by distance on the
  Riemann sphere (so that a root through infinity, where the leading
  coefficient vanishes, is followed too).  A match is taken when each pole
  moved less than a third of the way to its next nearest candidate;
  elsewhere the step is halved (the new points are kept for the crossings,
  not returned), and where halving does not settle it (roots that collide,
  such as a real pair breaking away into a complex one) the optimal
  assignment of ``_assignment`` decides.  A step is halved too when a
  pole starts and ends it outside the circle but its chord dips inside:
  a crossing out and back in between two points.
* Crossings: the points where a tracked pole changes side of the circle
  bracket the crossing value, refined by
  :func:`symstab.numeric.engine.search.bracketed_root` on the modulus of the
  pole; a crossing is a complex pair (reported once, by its pole of
  positive imaginary part: the D-decomposition's arc), or a real pole
  through ``z = 1`` or ``z = -1`` (its lines).

The poles are floating-point eigenvalues: where one lies within
``ON_CIRCLE`` of the circle the point is marginal (count -1), and the
certified verdicts remain those of
:func:`symstab.numeric.paper.stability.unstable_root_counts` and
:meth:`symstab.Loop.unstable_root_counts` (tests/numeric/engine/test_locus.py
checks the counts against them at every path point).
"""

import dataclasses

import numpy as np

from ..._resources import CHUNK_BYTES, check_memory, chunk_slices
from ..._validate import check_array, check_real
from .polynomial import horner
from .roots import leading_vanishes, polish_roots
from .search import bracketed_root

__all__ = ["Locus", "Crossing", "locus", "check_path", "ON_CIRCLE"]

#: A pole whose modulus is within this of 1 is on the circle (a marginal point).
ON_CIRCLE = 1e-10
#: A match is taken when each pole moved less than this fraction of the
#: distance to its second nearest candidate.
_CLEAR_MATCH = 1.0 / 3.0
#: Most halvings of one step of the path where the match is not clear, and
#: the halvings of every step in which a pole crosses the circle.
_MAX_HALVINGS = 10
_CROSSING_HALVINGS = 4
#: Newton steps from the straight path to the crossing pole, per evaluation
#: of the crossing's bracketing (each kept only where it shrinks |chi|).
_NEWTON_STEPS = 6
#: Most points the halvings may add: this many times the path's points, plus
#: :data:`_ADDED_FIXED` (a crossing's step alone takes ``_MAX_HALVINGS``).
_MAX_ADDED = 4
_ADDED_FIXED = 256
#: A crossing pole with an imaginary part at most this is a real pole (z = +-1).
_REAL = 1e-9
#: Bytes per pole of a tracked point: the roots (complex), the tracked
#: roots, the coefficients and the matches (generous).
_BYTES_PER_POLE = 96
#: Bytes per pair of poles of one step of the path: the chordal distances of
#: two consecutive points and their temporaries in :func:`_nearest` (and in
#: ``_assignment``'s cost), a chunk of points at a time (generous).
_BYTES_PER_PAIR = 96
#: From this degree on, the path's points take their roots by continuation
#: (:func:`_roots_along`), with at most this many Newton steps a point.
_CONTINUATION_DEGREE = 64
_CONTINUATION_STEPS = 12
#: Rows of companion matrices handed to LAPACK at once (bytes).
_EIG_BATCH_BYTES = 32 * 2**20


@dataclasses.dataclass(frozen=True)
class Crossing:
    """A closed-loop pole on the unit circle, on its way out or in.

    Attributes
    ----------
    value : float
        The path parameter's value at the crossing.
    pole_index : int
        Column of :attr:`Locus.poles` that crosses (for a pair, the pole of
        positive imaginary part).
    z : complex
        The pole on the circle.
    direction : str
        ``"out"`` (the pole leaves the unit disc as the path goes on) or
        ``"in"``.
    kind : str
        ``"pair"`` (a complex pair: the arc of the D-decomposition),
        ``"z = 1"`` or ``"z = -1"`` (a real pole: those lines).
    """

    value: float
    pole_index: int
    z: complex
    direction: str
    kind: str

    @property
    def angle(self):
        """``|arg z|`` in [0, pi]: the theta of the D-decomposition's arc."""
        return float(abs(np.angle(self.z)))

    @property
    def change(self):
        """Change of the number of poles outside the circle: +-2 for a pair, +-1 for a real pole."""
        size = 2 if self.kind == "pair" else 1
        return size if self.direction == "out" else -size


@dataclasses.dataclass(frozen=True, eq=False)
class Locus:
    """The closed-loop poles along a path of one parameter.

    Attributes
    ----------
    parameter : str
        The parameter that varies along the path.
    values : ndarray, shape (n,)
        Its values, in the path's order.
    fixed : dict
        The values of the other parameters (``d`` included).
    poles : ndarray of complex, shape (n, degree)
        The poles at each value; column ``k`` is one pole's continuous
        path (``inf`` where a pole is at infinity).
    crossings : tuple of Crossing
        Every crossing of the unit circle, in the path's order.
    """

    parameter: str
    values: np.ndarray
    fixed: dict
    poles: np.ndarray
    crossings: tuple

    def plot(self, ax=None):
        """Draw the poles in the z-plane: :func:`symstab.drawing.plot_locus`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_locus

        return plot_locus(self, ax)

    def unstable_counts(self):
        """Number of poles outside the unit circle at each value (-1: marginal).

        Returns
        -------
        ndarray of int, shape (n,)
            -1 where a pole is within :data:`ON_CIRCLE` of the circle.
        """
        modulus = np.abs(self.poles)
        counts = np.count_nonzero(modulus > 1.0, axis=1)
        return np.where(np.any(np.abs(modulus - 1.0) <= ON_CIRCLE, axis=1), -1, counts)

    def spectral_radius(self):
        """Largest pole modulus at each value, shape (n,)."""
        return np.max(np.abs(self.poles), axis=1)

    def __repr__(self):
        events = ", ".join(f"{c.kind} {c.direction} at {self.parameter} = {c.value:.6g}"
                           for c in self.crossings) or "no crossing"
        return (f"Locus({self.parameter} from {self.values[0]:.6g} to {self.values[-1]:.6g}, "
                f"{len(self.values)} points, {self.poles.shape[1]} poles: {events})")


# --------------------------------------------------------------------------
# Entry points


def locus(loop, parameter, values, **fixed):
    """The closed-loop poles of a loop along a path of one parameter.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    parameter : str
        The parameter that varies (any of :attr:`symstab.Loop.parameters`
        but ``d``), e.g. ``"K"``.
    values : array_like, shape (n,)
        Its values along the path, ``n >= 2``, strictly increasing or
        strictly decreasing.
    **fixed
        Single values of the other parameters (the loop's defaults fill in
        the rest).

    Returns
    -------
    Locus

    Raises
    ------
    TypeError, ValueError
        For an unknown or missing parameter, a path that is not strictly
        monotonic, an array where a single value is expected, or a locus
        that would not fit in the memory limit.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=0, B=0.5))
    >>> path = locus(loop, "K", [100.0, 2000.0])
    >>> [(c.kind, c.direction) for c in path.crossings]
    [('pair', 'out')]
    """
    if not isinstance(parameter, str):
        raise TypeError(f"parameter must be a parameter name (str), got {type(parameter).__name__}")
    if parameter not in loop.parameters:
        raise ValueError(f"parameter {parameter!r} is not a parameter of the loop "
                         f"(parameters: {', '.join(loop.parameters)})")
    if parameter == "d":
        raise ValueError("parameter d (the delay) is an integer: the poles jump between delays "
                         "and cannot be tracked; choose a real parameter")
    if parameter in fixed:
        raise ValueError(f"{parameter} is the path's parameter: give its values as values, "
                         f"not as a fixed value")
    unknown = sorted(set(fixed) - set(loop.parameters))
    if unknown:
        raise TypeError(f"unknown parameter(s) {', '.join(unknown)}; parameters of this loop: "
                        f"{', '.join(loop.parameters)}")
    values = check_path(parameter, values)
    used = {n: v for n, v in loop.defaults.items() if n != parameter}
    used.update(fixed)
    for name, value in used.items():
        if name != "d" and np.ndim(value) != 0:
            raise ValueError(f"{name} must be a single value here (the path varies "
                             f"{parameter} only), got an array of shape {np.shape(value)}")
    used = {n: (v if n == "d" else check_real(n, v)) for n, v in used.items()}

    def coefficients(p):
        return loop.coefficients(**used, **{parameter: np.asarray(p, dtype=float)})

    return _locus(parameter, values, dict(used), coefficients)


def check_path(parameter, values):
    """The path's values as a strictly monotonic float array of at least two.

    Parameters
    ----------
    parameter : str
        The path's parameter, as the caller named it (for the messages).
    values : array_like
        Its values.

    Returns
    -------
    ndarray
        One-dimensional, strictly increasing or strictly decreasing.

    Raises
    ------
    TypeError, ValueError
        Naming ``values (of parameter)``.
    """
    values = check_array(f"values (of {parameter})", values)
    if values.ndim != 1 or values.size < 2:
        raise ValueError(f"values (of {parameter}) must be a list of at least two numbers, got "
                         f"shape {values.shape}")
    steps = np.diff(values)
    if not (np.all(steps > 0) or np.all(steps < 0)):
        raise ValueError(f"values (of {parameter}) must be strictly increasing or strictly "
                         f"decreasing (a path), got a repeat or a turn at entry "
                         f"{int(np.flatnonzero(steps * np.sign(steps[0]) <= 0)[0]) + 1}")
    return values


# --------------------------------------------------------------------------
# Roots and their matching


def _roots(c):
    """All roots of each row of ``c`` (highest power first): shape (rows, degree).

    Companion eigenvalues, polished by Newton steps; a row whose leading
    coefficient vanishes to within rounding has its missing roots at
    infinity.
    """
    c = np.asarray(c, dtype=float)
    rows, n = c.shape[0], c.shape[1] - 1
    out = np.empty((rows, n), dtype=complex)
    if n == 0:
        return out
    infinite = leading_vanishes(c)
    regular = np.flatnonzero(~infinite)
    for part in chunk_slices(len(regular), 8 * n * n, _EIG_BATCH_BYTES):
        index = regular[part]
        rows_c = c[index]
        companion = np.zeros((len(index), n, n))
        companion[:, 0, :] = -rows_c[:, 1:] / rows_c[:, :1]
        companion[:, np.arange(1, n), np.arange(n - 1)] = 1.0
        out[index] = polish_roots(rows_c, np.linalg.eigvals(companion).astype(complex))
    for k in np.flatnonzero(infinite):
        finite = np.roots(c[k]) if np.any(c[k]) else np.empty(0)
        out[k, :finite.size] = finite
        out[k, finite.size:] = complex(np.inf, 0.0)
    return out


def _distances(a, b):
    """Chordal distances between the roots of ``a`` (rows) and of ``b`` (columns), per point.

    On the Riemann sphere of diameter 1: ``|z - w| / sqrt((1 + |z|**2) (1 +
    |w|**2))``, and ``1 / sqrt(1 + |z|**2)`` from ``z`` to infinity.
    """
    a, b = a[..., :, None], b[..., None, :]
    with np.errstate(all="ignore"):
        out = np.abs(a - b) / np.sqrt((1.0 + np.abs(a) ** 2) * (1.0 + np.abs(b) ** 2))
        ia, ib = ~np.isfinite(a), ~np.isfinite(b)
        out = np.where(ia & ~ib, 1.0 / np.sqrt(1.0 + np.abs(b) ** 2), out)
        out = np.where(ib & ~ia, 1.0 / np.sqrt(1.0 + np.abs(a) ** 2), out)
    return np.where(ia & ib, 0.0, out)


def _nearest(a, b):
    """Nearest-root matches of consecutive points: ``(match, clear)``.

    ``match[i, k]`` is the root of ``b[i]`` nearest to root ``k`` of
    ``a[i]``; ``clear[i]`` says the match is a permutation in which every
    pole moved less than :data:`_CLEAR_MATCH` of the way to its second
    nearest candidate, both ways, and no pole's chord from ``a`` to ``b``
    dips inside the circle while both its ends lie outside.  Computed a
    chunk of points at a time (the distances are ``degree**2`` a point).
    """
    rows, n = a.shape
    match = np.empty((rows, n), dtype=int)
    clear = np.ones(rows, dtype=bool)
    for part in chunk_slices(rows, 96 * n * n):
        dist = _distances(a[part], b[part])
        match[part] = np.argmin(dist, axis=-1)
        if n > 1:
            parted = np.partition(dist, 1, axis=-1)
            by_row = np.all(parted[..., 0] < _CLEAR_MATCH * parted[..., 1], axis=-1)
            parted = np.partition(dist, 1, axis=-2)
            by_column = np.all(parted[..., 0, :] < _CLEAR_MATCH * parted[..., 1, :], axis=-1)
            permutation = np.all(np.sort(match[part], axis=-1) == np.arange(n), axis=-1)
            clear[part] = by_row & by_column & permutation
        end = np.take_along_axis(b[part], match[part], axis=-1)
        clear[part] &= ~np.any(_dips_inside(a[part], end), axis=-1)
    return match, clear


def _dips_inside(a, b):
    """True where the chord from ``a`` to ``b`` (both outside the circle) passes inside it."""
    with np.errstate(all="ignore"):
        step = b - a
        t = np.clip(-(np.conj(a) * step).real / np.abs(step) ** 2, 0.0, 1.0)
        closest = np.abs(a + np.nan_to_num(t) * step)
    outside = (np.abs(a) > 1.0) & (np.abs(b) > 1.0) & np.isfinite(a) & np.isfinite(b)
    return outside & (closest < 1.0)


def _assignment(cost):
    """The optimal assignment of a square cost matrix: ``column[row]``, least total cost.

    The Hungarian method in its shortest-augmenting-path form (Kuhn,
    Munkres; O(n**3)), one row added at a time, its inner loop over the
    columns vectorised.
    """
    cost = np.asarray(cost, dtype=float)
    n = cost.shape[0]
    u, v = np.zeros(n + 1), np.zeros(n + 1)
    owner = np.zeros(n + 1, dtype=int)        # owner[j]: row (1-based) holding column j
    way = np.zeros(n + 1, dtype=int)
    for row in range(1, n + 1):
        owner[0] = row
        j0 = 0
        slack = np.full(n + 1, np.inf)
        used = np.zeros(n + 1, dtype=bool)
        while True:
            used[j0] = True
            i0 = owner[j0]
            free = ~used
            free[0] = False
            reduced = cost[i0 - 1] - u[i0] - v[1:]
            better = free[1:] & (reduced < slack[1:])
            slack[1:][better] = reduced[better]
            way[1:][better] = j0
            candidates = np.where(free[1:], slack[1:], np.inf)
            j1 = int(np.argmin(candidates)) + 1
            step = candidates[j1 - 1]
            u[owner[used]] += step
            v[used] -= step
            slack[free] -= step
            j0 = j1
            if owner[j0] == 0:
                break
        while j0:
            j1 = way[j0]
            owner[j0] = owner[j1]
            j0 = j1
    column = np.empty(n, dtype=int)
    column[owner[1:] - 1] = np.arange(n)
    return column


# --------------------------------------------------------------------------
# Tracking and crossings


def _steps(a, b):
    """``(match, clear, turn)`` of consecutive points: :func:`_nearest`, and whether a pole changes side."""
    match, clear = _nearest(a, b)
    turn = np.any(_sides(a) * np.take_along_axis(_sides(b), match, axis=-1) < 0, axis=-1)
    return match, clear, turn


def _track(values, coefficients):
    """The roots along the path, refined where a match is not clear.

    Returns ``(p, tracked, kept)``: the refined path, the roots along it
    (column ``k`` one pole) and the indices of the user's values in it.
    """
    p = np.array(values, dtype=float)
    roots = _roots_along(coefficients(p))
    match, clear, turn = _steps(roots[:-1], roots[1:])
    halvings = np.zeros(len(p) - 1, dtype=int)
    added = 0
    budget = _added_budget(len(values))
    while True:
        # A step where a pole changes side is halved too: its crossing is
        # then bracketed closely, between roots that move by little.
        split = np.flatnonzero((~clear & (halvings < _MAX_HALVINGS))
                               | (turn & (halvings < _CROSSING_HALVINGS)))
        if split.size == 0 or added + split.size > budget:
            break
        middle = 0.5 * (p[split] + p[split + 1])
        fresh = _roots_near(coefficients(middle), roots[split])
        # Step ``split`` becomes (start, middle) and a new step (middle,
        # end) follows it; only those are matched again.
        left, right = _steps(roots[split], fresh), _steps(fresh, roots[split + 1])
        at = split + 1
        p = np.insert(p, at, middle)
        roots = np.insert(roots, at, fresh, axis=0)
        halvings[split] += 1
        halvings = np.insert(halvings, at, halvings[split])
        parts = []
        for whole, l_part, r_part in zip((match, clear, turn), left, right, strict=True):
            whole[split] = l_part
            parts.append(np.insert(whole, at, r_part, axis=0))
        match, clear, turn = parts
        added += split.size
    for i in np.flatnonzero(~clear):
        match[i] = _assignment(_distances(roots[i], roots[i + 1]))
    # Columns in a fixed order at the start: by real part, then imaginary part.
    order = np.lexsort((roots[0].imag, roots[0].real))
    tracked = np.empty_like(roots)
    tracked[0] = roots[0][order]
    for i in range(len(p) - 1):
        order = match[i][order]
        tracked[i + 1] = roots[i + 1][order]
    kept = np.searchsorted(p, values) if p[-1] > p[0] else \
        len(p) - 1 - np.searchsorted(p[::-1], values)
    return p, tracked, kept


def _added_budget(n):
    return _MAX_ADDED * n + _ADDED_FIXED


def _roots_along(c):
    """The roots of consecutive rows of a path: :func:`_roots`, or continued from row to row.

    From :data:`_CONTINUATION_DEGREE` on, each row's roots are Newton's
    steps on its polynomial from the previous row's roots, O(degree**2)
    where the eigenvalues are O(degree**3); they are kept only when every
    root settled (a last step below 1e-12 of its size) a clear way from
    every other root (it moved less than a third of the distance to its
    nearest neighbour, so no two converged to one root: ``degree`` distinct
    roots are all of them).  Any other row takes the eigenvalues.
    """
    c = np.asarray(c, dtype=float)
    rows, n = c.shape[0], c.shape[1] - 1
    if n < _CONTINUATION_DEGREE or rows < 2:
        return _roots(c)
    out = np.empty((rows, n), dtype=complex)
    out[0] = _roots(c[:1])[0]
    infinite = leading_vanishes(c)
    for i in range(1, rows):
        z = None if infinite[i] or not np.all(np.isfinite(out[i - 1])) else \
            _continued(c[i], out[i - 1])
        out[i] = _roots(c[i:i + 1])[0] if z is None else z
    return out


def _roots_near(c, start):
    """The roots of each row of ``c``, continued from the row of ``start`` next to it.

    As :func:`_roots_along` (from :data:`_CONTINUATION_DEGREE` on, else or
    where it fails the eigenvalues), for the halvings' new points.
    """
    c = np.asarray(c, dtype=float)
    if c.shape[1] - 1 < _CONTINUATION_DEGREE:
        return _roots(c)
    out = np.empty(start.shape, dtype=complex)
    infinite = leading_vanishes(c)
    for i in range(len(c)):
        z = None if infinite[i] or not np.all(np.isfinite(start[i])) else \
            _continued(c[i], start[i])
        out[i] = _roots(c[i:i + 1])[0] if z is None else z
    return out


def _continued(c, start):
    """The roots of ``c`` by Newton's steps from ``start``, or None where they do not settle apart."""
    row = c[None, :]
    z = start.copy()
    with np.errstate(all="ignore"):
        for _ in range(_CONTINUATION_STEPS):
            value, slope = horner(row, z[None, :])
            step = value[0] / slope[0]
            z = z - step
            if not np.all(np.isfinite(z)):
                return None
            if np.all(np.abs(step) <= 1e-12 * np.maximum(1.0, np.abs(z))):
                break
        else:
            return None
        gap = np.abs(z[:, None] - z[None, :])
        np.fill_diagonal(gap, np.inf)
        nearest = gap.min(axis=1)
        if not np.all(np.abs(z - start) < _CLEAR_MATCH * nearest):
            return None
    return z


def _sides(tracked):
    """-1 inside the circle, +1 outside, 0 on it (within :data:`ON_CIRCLE`)."""
    with np.errstate(invalid="ignore"):
        excess = np.abs(tracked) - 1.0
    return np.where(np.abs(excess) <= ON_CIRCLE, 0, np.sign(excess)).astype(int)


def _crossings(p, tracked, coefficients):
    """Every crossing of the circle along the refined path, as :class:`Crossing`."""
    sides = _sides(tracked)
    brackets = []     # (start index, end index, column)
    for k in range(tracked.shape[1]):
        seen = np.flatnonzero(sides[:, k] != 0)
        turn = np.flatnonzero(sides[seen[1:], k] != sides[seen[:-1], k])
        brackets += [(int(seen[t]), int(seen[t + 1]), k) for t in turn]
    if not brackets:
        return ()
    start, end, column = (np.array(x) for x in zip(*brackets, strict=True))
    za, zb = tracked[start, column], tracked[end, column]
    pa, pb = p[start], p[end]

    def pole(x, index):
        """The root at ``x`` that Newton's steps reach from the pole's straight path.

        The bracket is a step of a clear match, halved (up to
        :data:`_CROSSING_HALVINGS` times) because a pole crosses in it: the
        straight path is much closer to the pole than to any other root,
        and Newton's steps (O(degree) each, where the eigenvalues are
        O(degree**3)) converge to it.
        """
        guess = za[index] + (x - pa[index]) / (pb[index] - pa[index]) * (zb[index] - za[index])
        c = coefficients(x)
        return polish_roots(c, guess[:, None], steps=_NEWTON_STEPS)[:, 0]

    def excess(x, index):
        return np.abs(pole(x, index)) - 1.0

    everything = np.arange(len(start))
    # The bracketer wants lo < hi; a decreasing path has them the other way.
    value = bracketed_root(excess, np.minimum(pa, pb), np.maximum(pa, pb), indexed=True)
    z = pole(value, everything)
    out = []
    for i in everything:
        # A real root comes out of the eigenvalues (and Newton's steps on
        # real coefficients) with no imaginary part at all; a pair on the
        # circle has sin(theta).
        if abs(z[i].imag) <= _REAL:
            kind = "z = 1" if z[i].real > 0 else "z = -1"
            z_i = complex(z[i].real, 0.0)
        elif z[i].imag > 0:
            kind, z_i = "pair", complex(z[i])
        else:
            continue      # the conjugate of a pair's upper pole: reported once
        direction = "out" if sides[end[i], column[i]] > 0 else "in"
        out.append(Crossing(value=float(value[i]), pole_index=int(column[i]), z=z_i,
                            direction=direction, kind=kind))
    forward = 1.0 if p[-1] > p[0] else -1.0
    out.sort(key=lambda c: (forward * c.value, c.angle, c.pole_index))
    return tuple(out)


def _locus_bytes(n_points, degree):
    """The most bytes a locus of ``n_points`` values and ``degree`` poles holds at once.

    The path's arrays (with the halvings' points), plus the larger of the
    two chunked working sets, which are never alive together: the distance
    matrices of :func:`_nearest` (``degree**2`` a point, :data:`CHUNK_BYTES`
    a chunk but at least one point), and a batch of companion matrices
    with LAPACK's copy of each (``8 degree**2`` a point,
    :data:`_EIG_BATCH_BYTES` a batch but at least one point).  Nothing
    grows as ``degree**3``: that is the eigenvalues' time, not their memory.
    """
    n = max(int(degree), 1)
    rows = n_points + _added_budget(n_points)
    pair = _BYTES_PER_PAIR * n * n
    nearest = pair * min(rows, max(1, CHUNK_BYTES // pair))
    companion = 8 * n * n
    eigen = 2 * companion * min(rows, max(1, _EIG_BATCH_BYTES // companion))
    return rows * n * _BYTES_PER_POLE + max(nearest, eigen)


def check_locus_memory(n_points, degree):
    """Refuse a locus that would not fit in the memory limit, before any work.

    Parameters
    ----------
    n_points : int
        Values on the path.
    degree : int
        Closed-loop poles (the characteristic polynomial's degree).

    Raises
    ------
    ValueError
        If the locus's working set exceeds ``SYMSTAB_MEMORY_LIMIT`` (named,
        with the estimate).
    """
    check_memory(f"the locus of {n_points} points of {degree} poles",
                 _locus_bytes(n_points, degree))


def _locus(parameter, values, fixed, coefficients):
    first = coefficients(values[:1])
    degree = first.shape[-1] - 1
    check_locus_memory(len(values), degree)
    p, tracked, kept = _track(values, coefficients)
    crossings = _crossings(p, tracked, coefficients)
    poles = tracked[kept]
    poles.flags.writeable = False
    values = values.copy()
    values.flags.writeable = False
    return Locus(parameter=parameter, values=values, fixed=fixed, poles=poles,
                 crossings=crossings)
