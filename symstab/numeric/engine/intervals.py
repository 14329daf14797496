"""The one line engine: the stable intervals of ``p`` in ``chi = A0 + p A1``.

A root of ``chi`` crosses the unit circle at ``z = exp(j theta)`` only at a
real ``p`` with ``A0(z) + p A1(z) = 0``, that is where the bracket ``[A0,
A1] = Im(A0 conj A1)`` vanishes, with ``p = -Re(A0 conj A1) / |A1|**2``;
at ``theta = 0`` and ``pi`` (the roots ``z = +-1``) always, and at infinity
where the leading coefficient vanishes.  Between consecutive crossings the
number of roots outside the circle is constant: it is counted (certified,
:func:`symstab.numeric.engine.roots.root_counts`) at one test point and carried
across each crossing by the crossing rule
(:func:`symstab.numeric.engine.arcs.crossing_change`); every stretch the
bookkeeping calls stable is counted afresh, and a disagreement sends every
stretch to the certified count.

The polynomials stay structured (``z**s D + N``,
:class:`~symstab.numeric.engine.polynomial.DelayedPolynomial`): the bracket over
``sin(theta)`` comes from :class:`symstab.numeric.engine.arcs.Brackets`
(O(deg D + deg N) per angle whatever the delay, and accurate next to
``theta = 0`` and ``pi``, where ``sin(theta)`` is divided out
analytically), the counts cost O(s) each.  The bracket is scanned on
:func:`symstab.numeric.engine.search.scan_grid` (sixteen points per period of
``sin(s theta)``); its sign changes are refined by the root bracketer, and
at each local minimum of its modulus a zooming grid
(:func:`symstab.numeric.engine.search.zoom_max`) looks for a close pair of zeros
that the scan straddles.

A family of parallel lines ``A0 + v Av + p A1`` (a plane's vertical or
horizontal lines, :func:`family_intervals`) shares its brackets, ``[A0 + v
Av, A1] = [A0, A1] + v [Av, A1]``: the scan is one evaluation for every
line, and the refinements, the dips and the counts of all lines are done
together, one vectorised call per step.  :func:`line_intervals` is a family
of one line.
"""

import math

import numpy as np

from ..._resources import chunk_slices
from .arcs import Brackets, crossing_change
from .polynomial import DelayedPolynomial, horner
from .roots import root_counts
from .search import bracketed_root, scan_grid, zoom_max

__all__ = ["line_intervals", "family_intervals", "Unresolved", "RESIDUAL"]

#: A candidate crossing is kept where ``|A0 + p A1|`` at its angle is at
#: most this fraction of the rounding scale ``sum |a0_k| + |p| sum |a1_k|``.
RESIDUAL = 1e-6
#: A dip of the bracket is searched down to this relative width in theta:
#: about sqrt(eps), below which the values next to a smooth minimum differ
#: by less than their rounding.
_DIP_RTOL = 1e-9
#: A crossing is re-found on an accurate arc source within this relative
#: distance of the angle the coefficients gave (they are good to about
#: 1e-11 where they cancel next to z = 1).
_POLISH = 1e-9


class Unresolved(ArithmeticError):
    """Every stretch of a line has a root on the unit circle to within rounding."""


def _one(polynomial, name):
    """A :class:`DelayedPolynomial` of one polynomial (dense rows are split into parts)."""
    if isinstance(polynomial, DelayedPolynomial):
        if len(polynomial) != 1:
            raise ValueError(f"{name} must be one polynomial, got {len(polynomial)}")
        return polynomial.flat()
    row = np.asarray(polynomial, dtype=float)
    if row.ndim != 1 or row.size == 0:
        raise ValueError(f"{name} must be one non-empty row of coefficients, got shape {row.shape}")
    return DelayedPolynomial.from_dense(row[None, :])


def _common(polynomials):
    """The polynomials with one shift and the same part lengths (zeros padded on the left)."""
    if len({chi.shift for chi in polynomials}) > 1:
        # Dense rows and structured ones: compare them as dense rows.
        n = max(chi.degree for chi in polynomials)
        return tuple(DelayedPolynomial.from_dense(
            np.concatenate([np.zeros((1, n - chi.degree)), chi.dense()], axis=-1))
            for chi in polynomials)

    def pad(x, size):
        return np.concatenate([np.zeros(x.shape[:-1] + (size - x.shape[-1],)), x], axis=-1)

    p = max(chi.delayed.shape[-1] for chi in polynomials)
    q = max(chi.direct.shape[-1] for chi in polynomials)
    out = []
    for chi in polynomials:
        near = chi.near_one
        if near is not None and chi.delayed.shape[-1] != p:
            near = tuple(pad(x, p) for x in near)
        out.append(DelayedPolynomial(pad(chi.delayed, p), pad(chi.direct, q), chi.shift, near))
    return tuple(out)


def _values(chi, theta):
    """``chi(exp(j theta))`` of one polynomial at the angles, ``z**s`` from the angle itself."""
    z = np.exp(1j * theta)[None, :]
    d, _ = horner(chi.delayed, z)
    n, _ = horner(chi.direct, z)
    return (np.exp(1j * chi.shift * theta) * d[0] + n[0])


def _end_values(chi):
    """``chi(1)`` and ``chi(-1)``, each a sum rounded once."""
    d = chi.delayed[0][::-1]
    n = chi.direct[0][::-1]
    signs_d = (-1.0) ** (chi.shift + np.arange(len(d)))
    signs_n = (-1.0) ** np.arange(len(n))
    return (math.fsum(np.concatenate([d, n])),
            math.fsum(np.concatenate([signs_d * d, signs_n * n])))


class _Family:
    """The brackets ``g_v = [base + v across, slope] / sin(theta)`` of a family of lines.

    ``[base + v across, slope] = [base, slope] + v [across, slope]``: two
    sine series evaluated once per angle serve every line.
    """

    def __init__(self, given, at):
        self.brackets = Brackets(given, ((0, 2), (1, 2)))
        self.at = at

    def __call__(self, theta, line):
        """``g`` and its rounding scale at the angles ``theta`` of the lines ``line`` (flat)."""
        value, scale = self.brackets(theta)
        v = self.at[line]
        return value[:, 0] + v * value[:, 1], scale[:, 0] + np.abs(v) * scale[:, 1]


def _angles(family, n_lines, degree):
    """``(line, theta)``: the angles in [0, pi] where each line's bracket may vanish, and 0, pi.

    The bracket is scanned on :func:`~symstab.numeric.engine.search.scan_grid`;
    its sign changes are refined by the root bracketer; a zero within its
    rounding at a sample (a tangency) is kept as it is; and a local minimum
    of ``|g|`` between samples of one sign is searched (a zooming grid) for
    a close pair of zeros that the scan straddles.  Every line's brackets
    are refined together.
    """
    grid = scan_grid(degree, n=max(256, 16 * (degree + 1)))[:-1]
    grid = np.concatenate([grid, np.pi - grid[:40][::-1]])
    value0, scale0 = family.brackets(grid)
    lines, thetas = [np.repeat(np.arange(n_lines), 2)], [np.tile([0.0, np.pi], n_lines)]
    brackets = []          # (line, lo, hi) of sign changes, refined together at the end
    # Lines are taken in chunks of a bounded table of the bracket's values.
    for part in chunk_slices(n_lines, 48 * len(grid)):
        v = family.at[part][:, None]
        value = value0[None, :, 0] + v * value0[None, :, 1]
        scale = scale0[None, :, 0] + np.abs(v) * scale0[None, :, 1]
        sign = np.sign(value)
        line, k = np.nonzero(sign[:, :-1] * sign[:, 1:] < 0)
        brackets.append((line + part.start, grid[k], grid[k + 1]))
        line, k = np.nonzero((scale > 0) & (np.abs(value) <= 64 * np.finfo(float).eps * scale))
        lines.append(line + part.start)
        thetas.append(grid[k])
        # A close pair of zeros between two samples shows as a local minimum
        # of |g| with both neighbours of one sign.
        size = np.abs(value)
        middle = slice(1, -1)
        dip = ((size[:, middle] < size[:, :-2]) & (size[:, middle] <= size[:, 2:])
               & (sign[:, :-2] == sign[:, middle]) & (sign[:, middle] == sign[:, 2:])
               & (sign[:, middle] != 0))
        line, k = np.nonzero(dip)
        k = k + 1
        if line.size:
            line = line + part.start
            s = sign[line - part.start, k]
            lo, hi = grid[k - 1], grid[k + 1]
            low_point = zoom_max(
                lambda t, i, s=s, line=line: -s[i, None]
                * family(t.ravel(), np.repeat(line[i], t.shape[1]))[0].reshape(t.shape),
                lo, hi, rtol=_DIP_RTOL, enough=lambda fx: fx > 0)
            flipped = s * family(low_point, line)[0] < 0
            mid = low_point[flipped]
            brackets.append((line[flipped], lo[flipped], mid))
            brackets.append((line[flipped], mid, hi[flipped]))
    line = np.concatenate([b[0] for b in brackets])
    if line.size:
        lo = np.concatenate([b[1] for b in brackets])
        hi = np.concatenate([b[2] for b in brackets])
        lines.append(line)
        thetas.append(bracketed_root(lambda t, i: family(t, line[i])[0], lo, hi, indexed=True))
    line, theta = np.concatenate(lines), np.clip(np.concatenate(thetas), 0.0, np.pi)
    # One crossing per line and angle.
    line, theta = np.unique(np.stack([line.astype(float), theta]), axis=1)
    return line.astype(np.int64), theta


def _crossings(polynomials, at, ends, given):
    """``(line, p, theta)`` of every crossing of the lines with the unit circle."""
    base, across, slope = polynomials
    line, theta = _angles(_Family(given, at), len(at), base.degree)
    v = at[line]
    v0 = _values(base, theta) + v * _values(across, theta)
    v1 = _values(slope, theta)
    # At z = +-1 exactly (exp(j pi) has an imaginary part of 1e-16).
    for index, end in enumerate((0.0, np.pi)):
        here = theta == end
        v0[here] = ends[0][index] + v[here] * ends[1][index]
        v1[here] = ends[2][index]
    with np.errstate(all="ignore"):
        p = -(v0 * np.conj(v1)).real / np.abs(v1) ** 2
        residual = np.abs(v0 + p * v1)
    # Rounding of A0 + p A1 on the circle is relative to the sums of the
    # coefficients' moduli, not to |A0(z)|, which cancels near a root.
    size = [np.sum(np.abs(chi.delayed)) + np.sum(np.abs(chi.direct)) for chi in polynomials]
    scale = size[0] + np.abs(v) * size[1] + np.abs(p) * size[2]
    keep = np.isfinite(p) & (residual <= RESIDUAL * np.where(scale > 0, scale, 1.0))
    return line[keep], p[keep], theta[keep]


def _polished(line, p, theta, at, arc):
    """The crossings at ``0 < theta < pi`` refined on an arc source where it has them.

    ``arc(theta) -> (value, position)``: the line value of the arc's point
    at ``theta`` and its position along the line (NaN where the source has
    nothing better to offer).  Each crossing's angle is re-found as the
    root of ``value(theta) - v`` within ``1e-9`` of its own; where the
    source has no sign change there, the crossing stays as it was.
    """
    inner = np.flatnonzero((theta > 0) & (theta < np.pi))
    if arc is None or inner.size == 0:
        return p, theta
    lo = np.maximum(theta[inner] * (1 - _POLISH), np.finfo(float).tiny)
    hi = np.minimum(theta[inner] * (1 + _POLISH), np.pi * (1 - np.finfo(float).eps))
    target = at[line[inner]]
    f_lo, f_hi = arc(lo)[0] - target, arc(hi)[0] - target
    ok = np.isfinite(f_lo) & np.isfinite(f_hi) & (np.sign(f_lo) * np.sign(f_hi) < 0)
    if not ok.any():
        return p, theta
    which, target = inner[ok], target[ok]
    root = bracketed_root(lambda t, i: arc(t)[0] - target[i], lo[ok], hi[ok], indexed=True)
    position = arc(root)[1]
    good = np.isfinite(position)
    p, theta = p.copy(), theta.copy()
    p[which[good]], theta[which[good]] = position[good], root[good]
    return p, theta


def _prepared(given, ends):
    """The three polynomials of a family (a zero ``across`` for None), as given and structured, and their ends."""
    base, across, slope = given
    if across is None:
        across = _one(base, "base")
        across = DelayedPolynomial(np.zeros_like(across.delayed), np.zeros_like(across.direct),
                                   across.shift)
        if ends is not None:
            ends = (ends[0], (0.0, 0.0), ends[-1])
    given = (base, across, slope)
    polynomials = _common([_one(p, name)
                           for p, name in zip(given, ("base", "across", "slope"), strict=True)])
    if all(isinstance(x, DelayedPolynomial) for x in given):
        given = polynomials
    if ends is None:
        ends = [_end_values(chi) for chi in polynomials]
    return polynomials, given, ends


def _carry(counts, steps, first):
    """Counts carried across the crossings from each known one (in place); -2 where unknown.

    ``counts`` holds each line's stretches in turn (``first``: the index of
    each line's first stretch, and one past the end); ``steps[k]`` is the
    change from stretch ``k`` to ``k + 1`` of the same line.  Returns the
    first stretch of each line whose count is still unknown (its step was
    lost, or it follows a marginal stretch).
    """
    need = []
    for start, stop in zip(first[:-1], first[1:], strict=True):
        for k in range(start + 1, stop):
            if counts[k] != -2:
                continue
            if counts[k - 1] >= 0 and np.isfinite(steps[k - 1]):
                counts[k] = counts[k - 1] + int(steps[k - 1])
            else:
                need.append(k)
                break
    return np.array(need, dtype=np.int64)


def family_intervals(base, across, slope, at, ends=None, *, arc=None):
    """Stable intervals of ``p`` on each line ``base + v across + p slope``, ``v`` in ``at``.

    The lines of a family share their brackets and are scanned, refined and
    counted together: a plane's vertical (or horizontal) lines at once.

    Parameters
    ----------
    base, across, slope : DelayedPolynomial or ndarray
        One polynomial each, real and finite: structured (a common shift)
        or dense rows, highest power first; ``across`` may be None (one
        line, ``at = [0]``).
    at : array_like
        The values ``v`` of the lines (a 1-D sequence of finite reals).
    ends : three pairs of float, optional
        ``base``, ``across`` and ``slope`` at ``z = 1`` and ``z = -1``,
        where the caller knows them better than the sums of the coefficients
        (a loop's plant at 30 digits, a value known to vanish exactly);
        ``across``'s pair is not read when ``across`` is None.
    arc : callable, optional
        ``arc(theta) -> (v, p)``: the point where ``exp(j theta)`` is a
        root, as the value ``v`` of its line and its position ``p`` on it,
        from a source more accurate than the coefficients (a closed form;
        NaN where it is not).  Each crossing at ``0 < theta < pi`` is then
        re-found on it (``_POLISH``).

    Returns
    -------
    list
        For each line, its stable intervals ``(lo, hi)`` as
        :func:`line_intervals` returns them: none on a line where ``z = 1``
        or ``z = -1`` is a root at every ``p`` (its ends vanish exactly);
        ``None`` where every stretch of the line has a root on the unit
        circle to within rounding.

    Examples
    --------
    >>> z, one = np.array([1.0, 0.0]), np.array([0.0, 1.0])
    >>> family_intervals(z, one, one, [0.0, 0.5])      # z + v + p
    [[(-1.0, 1.0)], [(-1.5, 0.5)]]
    """
    at = np.asarray(at, dtype=float).ravel()
    polynomials, given, ends = _prepared((base, across, slope), ends)
    base, across, slope = polynomials
    line, p, theta = _crossings(polynomials, at, ends, given)
    p, theta = _polished(line, p, theta, at, arc)
    with np.errstate(all="ignore"):
        chi = base.combine([at[line], p], [across, slope])
    changes = crossing_change(chi, slope, theta) if p.size else np.empty(0)
    lead1 = float(slope.leading()[0])
    if lead1 != 0:
        # The leading coefficient vanishes: a root passes through infinity,
        # outside on both sides.
        line = np.concatenate([line, np.arange(len(at))])
        p = np.concatenate([p, -(float(base.leading()[0]) + at * float(across.leading()[0])) / lead1])
        changes = np.concatenate([changes, np.zeros(len(at))])
    keep = np.isfinite(p)
    line, p, changes = line[keep], p[keep], changes[keep]
    # Crossings at the same p of one line add up.
    key, where = np.unique(np.stack([line.astype(float), p]), axis=1, return_inverse=True)
    where = where.ravel()
    candidate_line, candidates = key[0].astype(np.int64), key[1]
    summed = np.zeros(len(candidates))
    np.add.at(summed, where, changes)
    # Each line's stretches: below its first candidate, between, above its last.
    per_line = np.bincount(candidate_line, minlength=len(at))
    first = np.concatenate([[0], np.cumsum(per_line + 1)])
    test_line = np.repeat(np.arange(len(at)), per_line + 1)
    tests = np.zeros(first[-1])
    edges_lo = np.full(first[-1], -np.inf)
    edges_hi = np.full(first[-1], np.inf)
    steps = np.full(first[-1], np.nan)
    # The candidates are sorted by line, then p: each line's are one slice.
    start = np.cumsum(per_line) - per_line
    for i in np.flatnonzero(per_line):
        mine = slice(start[i], start[i] + per_line[i])
        c = candidates[mine]
        s = slice(first[i], first[i + 1])
        pad = max(1.0, float(np.max(np.abs(c))))
        tests[s] = np.concatenate([[c[0] - pad], 0.5 * (c[1:] + c[:-1]), [c[-1] + pad]])
        edges_lo[s][1:] = c
        edges_hi[s][:-1] = c
        steps[s][:-1] = summed[mine]

    def count(index):
        return root_counts(base.combine([at[test_line[index]], tests[index]], [across, slope]))

    counts = np.full(first[-1], -2, dtype=np.int64)     # -2: not known
    known = np.zeros(first[-1], dtype=bool)
    need = first[:-1]
    while need.size:
        counts[need], known[need] = count(need), True
        need = _carry(counts, steps, first)
    claim = np.flatnonzero(~known & (counts <= 0))
    if claim.size:
        fresh = count(claim)
        wrong = np.unique(test_line[claim[fresh != counts[claim]]])
        counts[claim] = fresh
        if wrong.size:
            redo = np.flatnonzero(np.isin(test_line, wrong))
            counts[redo] = count(redo)
    # z = 1 or z = -1 a root along the whole line, exactly: marginal everywhere.
    on_circle = np.zeros(len(at), dtype=bool)
    for index in (0, 1):
        on_circle |= (ends[0][index] + at * ends[1][index] == 0) & (ends[2][index] == 0)
    out = []
    for i in range(len(at)):
        s = slice(first[i], first[i + 1])
        if on_circle[i]:
            out.append([])
            continue
        if np.all(counts[s] == -1):
            out.append(None)
            continue
        runs = []
        for c, lo, hi in zip(counts[s], edges_lo[s], edges_hi[s], strict=True):
            if c != 0:
                continue
            lo, hi = float(lo) + 0.0, float(hi) + 0.0     # no -0.0
            if runs and runs[-1][1] == lo:
                runs[-1] = (runs[-1][0], hi)
            else:
                runs.append((lo, hi))
        out.append(runs)
    return out


def line_intervals(base, slope, ends=None):
    """Stable intervals of ``p`` for the polynomials ``base + p slope``.

    One line of :func:`family_intervals`.

    Parameters
    ----------
    base, slope : DelayedPolynomial or ndarray
        One polynomial each, real and finite: structured (a common shift)
        or dense rows, highest power first.
    ends : ((float, float), (float, float)), optional
        ``base`` and ``slope`` at ``z = 1`` and ``z = -1``, where the caller
        knows them better than the sums of the coefficients (a loop's plant
        at 30 digits).

    Returns
    -------
    list of (float, float)
        Stable intervals ``(lo, hi)``, increasing and disjoint; ``lo`` may
        be ``-inf`` and ``hi`` ``inf``.  The ends are crossings: unstable
        or marginal.

    Raises
    ------
    Unresolved
        When every stretch has a root on the circle to within rounding.

    Examples
    --------
    >>> line_intervals(np.array([1.0, 0.0]), np.array([0.0, 1.0]))   # z + p
    [(-1.0, 1.0)]
    """
    if ends is not None:
        ends = (ends[0], None, ends[1])
    runs, = family_intervals(base, None, slope, [0.0], ends)
    if runs is None:
        raise Unresolved("every stretch of the line has a root on the unit circle to within "
                         "rounding")
    return runs
