"""The one line engine: the stable intervals of ``p`` in ``chi = A0 + p A1``.

A root of ``chi`` crosses the unit circle at ``z = exp(j theta)`` only at a
real ``p`` with ``A0(z) + p A1(z) = 0``, that is where the bracket ``[A0,
A1] = Im(A0 conj A1)`` vanishes, with ``p = -Re(A0 conj A1) / |A1|**2``;
at ``theta = 0`` and ``pi`` (the roots ``z = +-1``) always, and at infinity
where the leading coefficient vanishes.  Between consecutive crossings the
number of roots outside the circle is constant: it is counted (certified,
:func:`symstab.numeric.roots.root_counts`) at one test point and carried
across each crossing by the crossing rule
(:func:`symstab.numeric.arcs.crossing_change`); every stretch the
bookkeeping calls stable is counted afresh, and a disagreement sends every
stretch to the certified count.

The polynomials stay structured (``z**s D + N``,
:class:`~symstab.numeric.polynomial.DelayedPolynomial`): the bracket over
``sin(theta)`` comes from :class:`symstab.numeric.arcs.Brackets`
(O(deg D + deg N) per angle whatever the delay, and accurate next to
``theta = 0`` and ``pi``, where ``sin(theta)`` is divided out
analytically), the counts cost O(s) each.  The bracket is scanned on
:func:`symstab.numeric.curves.scan_grid` (sixteen points per period of
``sin(s theta)``); its sign changes are refined by the root bracketer, and
at each local extremum of its modulus a golden-section search looks for a
close pair of zeros that the scan straddles.
"""

import numpy as np

from .arcs import Brackets, crossing_change
from .curves import bracketed_root, golden_max, scan_grid
from .polynomial import DelayedPolynomial, horner
from .roots import root_counts

__all__ = ["line_intervals", "Unresolved", "RESIDUAL"]

#: A candidate crossing is kept where ``|A0 + p A1|`` at its angle is at
#: most this fraction of the rounding scale ``sum |a0_k| + |p| sum |a1_k|``.
RESIDUAL = 1e-6


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


def _common(base, slope):
    """``base`` and ``slope`` with the same shift and part lengths (zeros padded on the left)."""
    if base.shift != slope.shift:
        # Dense rows and structured ones: compare them as dense rows.
        n = max(base.degree, slope.degree)
        rows = [np.concatenate([np.zeros((1, n - p.degree)), p.dense()], axis=-1)
                for p in (base, slope)]
        return tuple(DelayedPolynomial.from_dense(r) for r in rows)

    def pad(x, size):
        return np.concatenate([np.zeros(x.shape[:-1] + (size - x.shape[-1],)), x], axis=-1)

    p = max(base.delayed.shape[-1], slope.delayed.shape[-1])
    q = max(base.direct.shape[-1], slope.direct.shape[-1])
    out = []
    for chi in (base, slope):
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
    import math

    d = chi.delayed[0][::-1]
    n = chi.direct[0][::-1]
    signs_d = (-1.0) ** (chi.shift + np.arange(len(d)))
    signs_n = (-1.0) ** np.arange(len(n))
    return (math.fsum(np.concatenate([d, n])),
            math.fsum(np.concatenate([signs_d * d, signs_n * n])))


def _angles(base, slope, given):
    """Angles in [0, pi] where ``[base, slope] / sin(theta)`` may vanish, and the angles 0, pi.

    ``given`` are the polynomials as the caller gave them (dense rows are
    split into parts by :class:`~symstab.numeric.arcs.Brackets`).
    """
    brackets = Brackets(given, ((0, 1),))

    def g(theta, index=None):
        return brackets(theta)[0][:, 0]

    grid = scan_grid(base.degree, n=max(256, 16 * (base.degree + 1)))[:-1]
    grid = np.concatenate([grid, np.pi - grid[:40][::-1]])
    value, scale = brackets(grid)
    value, scale = value[:, 0], scale[:, 0]
    sign = np.sign(value)
    change = np.flatnonzero(sign[:-1] * sign[1:] < 0)
    found = [np.array([0.0, np.pi])]
    if change.size:
        found.append(bracketed_root(g, grid[change], grid[change + 1], indexed=True))
    # A zero of g within its rounding at a sample: a tangency, kept as it is.
    found.append(grid[(scale > 0) & (np.abs(value) <= 64 * np.finfo(float).eps * scale)])
    # A close pair of zeros between two samples shows as a local minimum of
    # |g| with both neighbours of one sign: look for the extremum itself.
    size = np.abs(value)
    inner = np.arange(1, len(grid) - 1)
    dip = inner[(size[inner] < size[inner - 1]) & (size[inner] <= size[inner + 1])
                & (sign[inner - 1] == sign[inner]) & (sign[inner] == sign[inner + 1])
                & (sign[inner] != 0)]
    if dip.size:
        s = sign[dip]
        lo, hi = grid[dip - 1], grid[dip + 1]
        low_point = golden_max(lambda t: -s * brackets(t)[0][:, 0], lo, hi)
        flipped = s * g(low_point) < 0
        if np.any(flipped):
            lo, hi, mid = lo[flipped], hi[flipped], low_point[flipped]
            found.append(bracketed_root(lambda t: g(t), lo, mid))
            found.append(bracketed_root(lambda t: g(t), mid, hi))
    return np.unique(np.clip(np.concatenate(found), 0.0, np.pi))


def _crossings(base, slope, ends, given):
    """``(p, theta)`` of every crossing of the line with the unit circle."""
    theta = _angles(base, slope, given)
    v0, v1 = _values(base, theta), _values(slope, theta)
    # At z = +-1 exactly (exp(j pi) has an imaginary part of 1e-16).
    for index, end in enumerate((0.0, np.pi)):
        v0[theta == end] = ends[0][index]
        v1[theta == end] = ends[1][index]
    with np.errstate(all="ignore"):
        p = -(v0 * np.conj(v1)).real / np.abs(v1) ** 2
        residual = np.abs(v0 + p * v1)
    # Rounding of A0 + p A1 on the circle is relative to the sums of the
    # coefficients' moduli, not to |A0(z)|, which cancels near a root.
    size0 = np.sum(np.abs(base.delayed)) + np.sum(np.abs(base.direct))
    size1 = np.sum(np.abs(slope.delayed)) + np.sum(np.abs(slope.direct))
    scale = size0 + np.abs(p) * size1
    keep = np.isfinite(p) & (residual <= RESIDUAL * np.where(scale > 0, scale, 1.0))
    return p[keep], theta[keep]


def line_intervals(base, slope, ends=None):
    """Stable intervals of ``p`` for the polynomials ``base + p slope``.

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
    given = (base, slope)
    base, slope = _common(_one(base, "base"), _one(slope, "slope"))
    if all(isinstance(x, DelayedPolynomial) for x in given):
        given = (base, slope)
    if ends is None:
        ends = (_end_values(base), _end_values(slope))
    p, theta = _crossings(base, slope, ends, given)
    with np.errstate(all="ignore"):
        chi = base.combine([p], [slope])
    changes = list(crossing_change(chi, slope, theta)) if p.size else []
    p = list(p)
    lead0, lead1 = float(base.leading()[0]), float(slope.leading()[0])
    if lead1 != 0:
        # The leading coefficient vanishes: a root passes through infinity,
        # outside on both sides.
        p.append(-lead0 / lead1)
        changes.append(0.0)
    p, changes = np.array(p, dtype=float), np.array(changes, dtype=float)
    keep = np.isfinite(p)
    p, changes = p[keep], changes[keep]
    # Crossings at the same p add up.
    candidates, at = np.unique(p, return_inverse=True)
    summed = np.zeros(len(candidates))
    np.add.at(summed, at, changes)
    if candidates.size == 0:
        tests = np.array([0.0])
    else:
        pad = max(1.0, float(np.max(np.abs(candidates))))
        tests = np.concatenate([[candidates[0] - pad], 0.5 * (candidates[1:] + candidates[:-1]),
                                [candidates[-1] + pad]])

    def count(index):
        return root_counts(base.combine([tests[index]], [slope]))

    counts = np.full(len(tests), -2, dtype=np.int64)     # -2: not known
    known = np.zeros(len(tests), dtype=bool)
    counts[0], known[0] = count(np.array([0]))[0], True
    for k in range(1, len(tests)):
        step = summed[k - 1]
        if counts[k - 1] >= 0 and np.isfinite(step):
            counts[k] = counts[k - 1] + int(step)
        else:
            counts[k] = count(np.array([k]))[0]
            known[k] = True
    claim = np.flatnonzero(~known & (counts <= 0))
    if claim.size:
        fresh = count(claim)
        if np.any(fresh != counts[claim]):
            counts = count(np.arange(len(tests)))
        else:
            counts[claim] = fresh
    if np.all(counts == -1):
        raise Unresolved("every stretch of the line has a root on the unit circle to within "
                         "rounding")
    edges = np.concatenate([[-np.inf], candidates, [np.inf]])
    out = []
    for k, c in enumerate(counts):
        if c != 0:
            continue
        lo, hi = float(edges[k]) + 0.0, float(edges[k + 1]) + 0.0     # no -0.0
        if out and out[-1][1] == lo:
            out[-1] = (out[-1][0], hi)
        else:
            out.append((lo, hi))
    return out
