"""Where the roots of a loop's characteristic polynomial are: one engine for every loop.

Every function takes a :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial`
``chi(z) = z**shift D(z) + N(z)`` (one polynomial per row) and never expands
it on a long delay:

* :func:`root_counts` -- the certified number of roots outside the unit
  circle, by the argument principle on the circle: O(deg D + deg N) per
  angle, O(d) angles, so O(d) per polynomial;
* :func:`schur_cohn` -- the float Schur-Cohn test of dense coefficients
  (the fast path for short delays) with its margin;
* :func:`classify_polynomials` -- stable, marginal or unstable: Schur-Cohn
  where its margin is safe, the certified count elsewhere;
* :func:`spectral_radius` -- the largest root modulus: companion-matrix
  eigenvalues for short delays; for long ones bisection on the radius with
  certified counts on ``|z| = r`` and Newton steps on the structured
  polynomial (O(d) per step), so that ``d = 2000`` does not cost an
  eigenvalue problem of order 2000.

The paper's dimensionless functions (:mod:`symstab.numeric.paper.stability`) and
:class:`symstab.Loop` both build a :class:`DelayedPolynomial` and call these.
"""

import functools
import math

import numpy as np

from ..._resources import CHUNK_BYTES, check_memory, chunk_slices
from .polynomial import DelayedPolynomial, horner

__all__ = [
    "STABLE", "MARGINAL", "UNSTABLE", "COEFFICIENT_ULPS",
    "root_counts", "schur_cohn", "classify_polynomials", "leading_vanishes",
    "spectral_radius", "polish_roots", "circle_minimum", "EIGENVALUES_UP_TO_DEGREE",
]

#: Codes of :func:`classify_polynomials`.
STABLE, MARGINAL, UNSTABLE = 1, 0, -1
#: Relative accuracy assumed of given coefficients, in units of 2**-53 of
#: the largest of their part (delayed or direct); the generated kernels are
#: measured within a few (tests/test_generated_kernels.py).
COEFFICIENT_ULPS = 64
#: Points whose Schur-Cohn margin ``min |1 - |k_j|||`` is below this are
#: re-decided by the certified root count: the reflection coefficients are
#: not the radius, and their rounding grows with ``1 / (1 - k_j**2)``.
_SCHUR_COHN_SAFE = 1e-6
#: From this degree on every point goes to the root count: it is O(d) per
#: point where Schur-Cohn is O(d**2), and at long delays the stable points'
#: Schur-Cohn margins fall below the safe level anyway.
_COUNT_ALL_FROM_DEGREE = 52
_U = 2.0**-53
#: Bisection rounds of an arc of the circle before a point is called
#: marginal, and the most arcs of one point left open at once.
_MAX_ROUNDS = 48
_MAX_OPEN_ARCS = 1024
#: A part longer than this is evaluated by direct powers, not Horner's scheme.
_HORNER_TERMS = 16
#: Largest table of cos(k theta), sin(k theta) for a part on the first pass's grid (bytes).
_TABLE_BYTES = 8 * 2**20
#: Most (angle, coefficient) terms of one direct-power evaluation.
_DIRECT_TERMS = 2**16
#: Up to this degree the spectral radius comes from companion eigenvalues
#: (O(n**3)); above it from certified counts on circles (O(n) each).
EIGENVALUES_UP_TO_DEGREE = 128
#: Rows of companion matrices handed to LAPACK at once (bytes).
_EIG_BATCH_BYTES = 64 * 2**20


def leading_vanishes(chi):
    """Polynomials whose leading coefficient is 0 to within rounding: a root at infinity.

    Such a loop is ill-posed; :func:`root_counts` and
    :func:`classify_polynomials` call it marginal.  Also True where a
    coefficient is not finite.  ``chi`` is a :class:`DelayedPolynomial` or
    dense rows (highest power first); the result has its shape.
    """
    if not isinstance(chi, DelayedPolynomial):
        chi = DelayedPolynomial.from_dense(chi)
    n = chi.degree
    p, q = chi.delayed.shape[-1], chi.direct.shape[-1]
    with np.errstate(all="ignore"):
        # The leading coefficient against the part(s) it comes from: each
        # part's coefficients carry errors relative to that part's size.
        scale = np.zeros(chi.shape)
        if chi.shift + p - 1 == n:
            scale = np.maximum(scale, np.max(np.abs(chi.delayed), axis=-1))
        if q - 1 == n:
            scale = np.maximum(scale, np.max(np.abs(chi.direct), axis=-1))
        finite = (np.all(np.isfinite(chi.delayed), axis=-1)
                  & np.all(np.isfinite(chi.direct), axis=-1))
        return ~finite | ~(np.abs(chi.leading()) > 2 * _U * (n + 1) * COEFFICIENT_ULPS * scale)


def _part_values(c, theta, rows=None, grid=None):
    """``P(z)`` and ``z P'(z)`` at ``z = exp(j theta)`` for a part ``c``.

    With ``rows`` None, every row of ``c`` at every angle of the 1-D
    ``theta`` (shape ``(N, M)``), which is the grid ``grid = (n_arcs,
    which)`` of :func:`_grid` if given; else row ``rows[k]`` at ``theta[k]``
    (shape ``(K,)``).
    """
    n_terms = c.shape[1]
    if rows is None:
        if grid is None or 16 * n_terms * len(theta) > _TABLE_BYTES:
            z = np.exp(1j * theta)[None, :]
            value, slope = horner(c, z)
            return value, slope * z
        # Products with a table shared by every row: far cheaper than
        # Horner's scheme on (rows, angles) arrays.
        cos_k, sin_k, k_cos_k, k_sin_k = _grid_table(n_terms, *grid)
        return _product(c, (cos_k, sin_k)), _product(c, (k_cos_k, k_sin_k))
    if n_terms <= _HORNER_TERMS:
        z = np.exp(1j * theta)[:, None]
        value, slope = horner(c[rows], z)
        return value[:, 0], (slope * z)[:, 0]
    powers = np.arange(n_terms - 1, -1, -1, dtype=float)
    value = np.empty(len(rows), dtype=complex)
    slope = np.empty(len(rows), dtype=complex)
    for part in chunk_slices(len(rows), n_terms, 16 * _DIRECT_TERMS):
        terms = c[rows[part]] * np.exp(1j * np.multiply.outer(theta[part], powers))
        value[part] = np.sum(terms, axis=1)
        slope[part] = np.sum(terms * powers, axis=1)
    return value, slope


@functools.lru_cache(maxsize=8)
def _grid(n_arcs):
    """The first pass's angles: the arcs' ends and midpoints (read-only)."""
    ends = np.linspace(0.0, np.pi, n_arcs + 1)
    mids = 0.5 * (ends[:-1] + ends[1:])
    for part in (ends, mids):
        part.flags.writeable = False
    return ends, mids


@functools.lru_cache(maxsize=16)
def _grid_table(n_terms, n_arcs, which):
    """``cos(k theta)``, ``sin(k theta)`` and both times ``k``, ``k = n_terms - 1 .. 0``, on a grid of :func:`_grid`."""
    theta = _grid(n_arcs)[which]
    powers = np.arange(n_terms - 1, -1, -1, dtype=float)
    angles = np.multiply.outer(powers, theta)
    cos_k, sin_k = np.cos(angles), np.sin(angles)
    table = (cos_k, sin_k, cos_k * powers[:, None], sin_k * powers[:, None])
    for part in table:
        part.flags.writeable = False
    return table


def _product(c, table):
    """``c @ (cos + j sin)`` for real rows ``c`` and a (cos, sin) table, as a complex array.

    Two real products written into the result's parts; short parts use
    einsum (no BLAS threads: on a busy machine a threaded BLAS call with
    three terms took 100 times longer than this).
    """
    cos_k, sin_k = table
    out = np.empty((c.shape[0], cos_k.shape[1]), dtype=complex)
    if c.shape[1] <= _HORNER_TERMS:
        out.real = np.einsum("rk,km->rm", c, cos_k)
        out.imag = np.einsum("rk,km->rm", c, sin_k)
    else:
        out.real = c @ cos_k
        out.imag = c @ sin_k
    return out


@functools.lru_cache(maxsize=16)
def _near_one_table(n_terms, n_arcs, which):
    """Tables of ``w**k``, ``z k w**(k-1)`` and ``|w|**k`` (``w = z - 1``, ``k = n_terms - 1 .. 0``) on a grid."""
    theta = _grid(n_arcs)[which]
    w, z = _near_one(theta)
    powers = np.arange(n_terms - 1, -1, -1)
    w_k = w[None, :] ** powers[:, None]
    slope = np.zeros_like(w_k)
    slope[:-1] = z[None, :] * powers[:-1, None] * w[None, :] ** (powers[:-1, None] - 1)
    table = (w_k.real.copy(), w_k.imag.copy(), slope.real.copy(), slope.imag.copy(), np.abs(w_k))
    for part in table:
        part.flags.writeable = False
    return table


def _near_one(theta):
    """``w = z - 1`` and ``z`` at ``z = exp(j theta)``; ``w`` without cancellation near ``z = 1``."""
    half = np.sin(0.5 * theta)
    return -2.0 * half * half + 1j * np.sin(theta), np.exp(1j * theta)


def _delayed_values(part, theta, rows=None, grid=None):
    """``D``, ``z D'`` and a bound on the rounding of ``D`` for a delayed part.

    ``part`` is ``(c, None, e0)``: coefficients in powers of ``z`` and the
    (per-row) bound ``e0`` of their evaluation, or ``(c, (e, err), k)``
    with the same part in powers of ``w = z - 1`` (``e``) and the absolute
    error bound of each of those coefficients (``err``); then ``D`` is
    evaluated in ``w``, so that it keeps its relative accuracy where it is
    small near ``z = 1`` (a plant pole there), and ``k`` is the rounding
    factor of that evaluation.  Shapes as in :func:`_part_values`.
    """
    c, shifted, factor = part
    if shifted is None:
        value, slope = _part_values(c, theta, rows, grid)
        bound = factor if rows is None else factor[rows]
        return value, slope, (bound[:, None] if rows is None else bound)
    e, err = shifted
    n_terms = e.shape[1]
    if rows is None and grid is not None:
        w_re, w_im, s_re, s_im, w_abs = _near_one_table(n_terms, *grid)
        value = _product(e, (w_re, w_im))
        slope = _product(e, (s_re, s_im))
        size = np.einsum("rk,km->rm", factor * np.abs(e) + err, w_abs)
        return value, slope, size
    if rows is None:
        rows = np.repeat(np.arange(len(e)), len(theta))
        theta = np.tile(theta, len(e))
        value, slope, size = _delayed_values(part, theta, rows)
        shape = (len(e), -1)
        return value.reshape(shape), slope.reshape(shape), size.reshape(shape)
    w, z = _near_one(theta)
    value, slope = horner(e[rows], w[:, None])
    size, _ = horner(factor * np.abs(e[rows]) + err[rows], np.abs(w)[:, None])
    return value[:, 0], (z[:, None] * slope)[:, 0], size[:, 0]


def _sums(c):
    """``S_k = sum_j j**k |c_j|`` for k = 0, 1, 2 (``j`` the power), per row."""
    powers = np.arange(c.shape[1] - 1, -1, -1, dtype=float)
    a = np.abs(c)
    return np.sum(a, axis=1), np.sum(powers * a, axis=1), np.sum(powers**2 * a, axis=1)


def root_counts(chi, *, coefficient_ulps=COEFFICIENT_ULPS):
    """Certified number of roots outside the unit circle, per polynomial.

    The argument principle over ``theta`` in [0, pi] (the coefficients are
    real): the change of ``arg chi(exp(j theta))`` is summed arc by arc, and
    an arc counts only when its whole image provably misses 0, either
    because a bound on ``|d chi / d theta|`` over the arc and a bound on the
    rounding keep it inside a disc that excludes 0 (first order), or
    because a bound on the second derivative keeps it inside a tube around
    the midpoint's tangent that excludes 0 (second order: a simple root
    next to the circle costs a few halvings).  Other arcs are halved, up to
    48 times.  With ``chi = z**s D + N`` the bounds are those of the parts
    (``|D|``, ``|D'|`` local, by Taylor steps from the midpoint, capped by
    the sums of the coefficients' moduli) and of the phase ``exp(j s
    theta)``, so one angle costs O(deg D + deg N) and a polynomial O(s).
    The count is exact for every polynomial whose coefficients are within
    ``coefficient_ulps`` units of ``2**-53`` times the largest coefficient
    of their own part (of ``D`` or of ``N``; with ``near_one``, each of
    ``D``'s coefficients in powers of ``z - 1`` within that many units of
    itself plus its given bound).

    Parameters
    ----------
    chi : DelayedPolynomial
        The polynomials (any shape).
    coefficient_ulps : float
        The error assumed of each coefficient, as above.

    Returns
    -------
    ndarray of int64, shape ``chi.shape``
        Roots with modulus > 1; -1 where a root lies on the circle to
        within rounding, or the leading coefficient vanishes (marginal).

    Examples
    --------
    >>> chi = DelayedPolynomial([1.0, 0.0, -4.0], [0.0], shift=0)   # z**2 - 4
    >>> int(root_counts(chi))
    2
    """
    if not isinstance(chi, DelayedPolynomial):
        raise TypeError(f"chi must be a DelayedPolynomial, got {type(chi).__name__}")
    shape = chi.shape
    rows = chi.flat()
    n = rows.degree
    counts = np.full(len(rows), -1, dtype=np.int64)
    live = np.flatnonzero(~leading_vanishes(rows))
    if n == 0:
        counts[live] = 0
        return counts.reshape(shape)
    n_arcs = max(64, 8 * n)
    p, q = rows.delayed.shape[1], rows.direct.shape[1]
    # Per row: the first pass's complex arrays on 2 n_arcs + 1 angles, and
    # the direct-power tables of long parts.
    per_row = 16 * (2 * n_arcs + 1) * (8 + (p > _HORNER_TERMS) + (q > _HORNER_TERMS))
    check_memory(f"the root count at degree {n}", per_row)
    for part in chunk_slices(len(live), per_row, CHUNK_BYTES):
        index = live[part]
        near_one = None if rows.near_one is None else tuple(x[index] for x in rows.near_one)
        counts[index] = _count_chunk(rows.delayed[index], rows.direct[index], rows.shift,
                                     n_arcs, coefficient_ulps, near_one)
    return counts.reshape(shape)


def _count_chunk(delayed, direct, s, n_arcs, coefficient_ulps, near_one=None):
    """Roots outside the circle of one chunk of rows: :func:`root_counts`'s argument principle.

    The steps, each vectorised over every row and arc of the chunk: the
    rows' bounds (:func:`_chunk_bounds`), the first pass on the shared grid
    (:func:`_first_pass`), rounds of the arc test (:func:`_arcs_pass`)
    that halve the arcs it did not pass (:meth:`_Arcs.halve`), and the
    count from the summed argument change (:func:`_whole_count`).
    """
    n_rows = len(delayed)
    n = max(s + delayed.shape[1] - 1, direct.shape[1] - 1)
    bounds = _chunk_bounds(delayed, direct, s, coefficient_ulps, near_one)
    arcs, undecided = _first_pass(bounds, n_arcs)
    change = np.zeros(n_rows)
    for _ in range(_MAX_ROUNDS):
        if arcs.row.size == 0:
            break
        ok, step = _arcs_pass(bounds, arcs)
        np.add.at(change, arcs.row[ok], step)
        bad = ~ok
        # A row whose open arcs multiply has |chi| within rounding of 0 along
        # a stretch of the circle (clustered roots on it): marginal.
        crowded = np.bincount(arcs.row[bad], minlength=n_rows) > _MAX_OPEN_ARCS
        undecided |= crowded
        bad &= ~crowded[arcs.row]
        if not bad.any():
            break
        arcs = arcs.halve(bad, bounds)
        if not np.all(arcs.hi > arcs.lo):
            undecided[np.unique(arcs.row[~(arcs.hi > arcs.lo)])] = True
    else:
        undecided[np.unique(arcs.row)] = True
    return _whole_count(change, undecided, n)


class _ChunkBounds:
    """One chunk's rows scaled, with the sums and rounding bounds every arc test reads.

    ``part`` is the delayed part as :func:`_delayed_values` takes it,
    ``direct`` the direct part, ``s`` the shift; ``sd*``/``sn*`` the sums
    :func:`_sums` of the delayed and direct parts, ``e_*`` the per-row
    rounding bounds of their values (``0``) and slopes (``1``), and
    ``spin_error`` that of the phase ``exp(j s theta)``.
    """

    __slots__ = ("part", "direct", "s", "sd0", "sd1", "sd2", "sn0", "sn1", "sn2",
                 "e_d0", "e_d1", "e_n0", "e_n1", "spin_error")

    def __init__(self, **fields):
        for name, value in fields.items():
            setattr(self, name, value)


def _chunk_bounds(delayed, direct, s, coefficient_ulps, near_one):
    """The first step: rows divided by their largest coefficient, and their error bounds.

    A step of its own because the bounds depend on the rows only: every
    round of the arc test reads them, indexed by each arc's row.
    """
    with np.errstate(all="ignore"):
        scale = np.maximum(np.max(np.abs(delayed), axis=1), np.max(np.abs(direct), axis=1))
        scale = np.where(scale > 0, scale, 1.0)[:, None]
    delayed, direct = delayed / scale, direct / scale
    sd0, sd1, sd2 = _sums(delayed)
    sn0, sn1, sn2 = _sums(direct)
    # Horner's rounding (complex: a few units per step, doubled for the
    # bounds' own rounding) plus the coefficients' own error.  The phase
    # exp(j s theta) carries the rounding of s theta (s pi units) and of exp.
    e_d0 = 2 * _U * (8 * (delayed.shape[1] + 1) + coefficient_ulps) * sd0
    e_d1 = 2 * _U * (8 * (delayed.shape[1] + 1) + coefficient_ulps) * sd1
    e_n0 = 2 * _U * (8 * (direct.shape[1] + 1) + coefficient_ulps) * sn0
    e_n1 = 2 * _U * (8 * (direct.shape[1] + 1) + coefficient_ulps) * sn1
    spin_error = 2 * _U * (s * np.pi + 8)
    if near_one is None:
        part = (delayed, None, e_d0)
    else:
        # In powers of z - 1 each coefficient is taken with its own relative
        # error (coefficient_ulps) and the absolute bound given with it.
        e, err = near_one
        part = (delayed, (e / scale, err / scale),
                2 * _U * (8 * (delayed.shape[1] + 1) + coefficient_ulps))
    return _ChunkBounds(part=part, direct=direct, s=s, sd0=sd0, sd1=sd1, sd2=sd2, sn0=sn0,
                        sn1=sn1, sn2=sn2, e_d0=e_d0, e_d1=e_d1, e_n0=e_n0, e_n1=e_n1,
                        spin_error=spin_error)


class _Arcs:
    """The open arcs of a chunk, one entry per arc (flat arrays, any row).

    ``row`` is the arc's row, ``lo``/``hi`` its ends' angles; ``chi_lo``,
    ``chi_mid``, ``chi_hi`` chi at its ends and midpoint, ``dchi_mid`` chi'
    at the midpoint; ``dm``, ``d1m``, ``nm``, ``n1m`` the moduli of ``D``,
    ``z D'``, ``N``, ``z N'`` there and ``e_dm`` the rounding bound of
    ``D`` there.
    """

    __slots__ = ("row", "lo", "hi", "chi_lo", "chi_mid", "chi_hi", "dchi_mid",
                 "dm", "d1m", "nm", "n1m", "e_dm")

    def __init__(self, *columns):
        for name, value in zip(self.__slots__, columns, strict=True):
            setattr(self, name, value)

    def take(self, keep):
        """The arcs where ``keep`` is True."""
        return _Arcs(*(getattr(self, name)[keep] for name in self.__slots__))

    def halve(self, bad, bounds):
        """The arcs ``bad`` halved, ``[lo, mid]`` and ``[mid, hi]``, with their midpoints' values.

        The step that makes the test's next round finer: only the
        midpoints are new, the ends are the old arcs' ends and midpoints.
        """
        row, lo, hi = self.row[bad], self.lo[bad], self.hi[bad]
        chi_lo, chi_mid, chi_hi = self.chi_lo[bad], self.chi_mid[bad], self.chi_hi[bad]
        mid = 0.5 * (lo + hi)
        row = np.concatenate([row, row])
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
        chi_lo, chi_hi = np.concatenate([chi_lo, chi_mid]), np.concatenate([chi_mid, chi_hi])
        mid = 0.5 * (lo + hi)
        s = bounds.s
        with np.errstate(all="ignore"):
            d_val, d_slope, e_dm = _delayed_values(bounds.part, mid, row)
            n_val, n_slope = _part_values(bounds.direct, mid, row)
            spin = np.exp(1j * (s * mid))
            chi_mid = spin * d_val + n_val
            dchi_mid = 1j * (spin * (s * d_val + d_slope) + n_slope)
        return _Arcs(row, lo, hi, chi_lo, chi_mid, chi_hi, dchi_mid, np.abs(d_val),
                     np.abs(d_slope), np.abs(n_val), np.abs(n_slope), e_dm)


def _first_pass(bounds, n_arcs):
    """The second step: every row's ``n_arcs`` arcs of [0, pi] on grids shared by every row.

    The arcs' ends (chi only) and midpoints (chi, chi' and the parts'
    sizes for the bounds) come from tables of the grid, far cheaper than
    the halved arcs' own evaluations; a row with a root at z = 1 or -1 to
    within rounding is marginal at once (returned in ``undecided``),
    without halving arcs down to it.  Returns ``(arcs, undecided)``.
    """
    part, direct, s = bounds.part, bounds.direct, bounds.s
    n_rows = len(direct)
    ends, mids = _grid(n_arcs)
    with np.errstate(all="ignore"):
        d_end, _, e_end = _delayed_values(part, ends, grid=(n_arcs, 0))
        n_end, _ = _part_values(direct, ends, grid=(n_arcs, 0))
        chi_end = np.exp(1j * (s * ends))[None, :] * d_end + n_end
        d_val, d_slope, e_mid = _delayed_values(part, mids, grid=(n_arcs, 1))
        n_val, n_slope = _part_values(direct, mids, grid=(n_arcs, 1))
        spin = np.exp(1j * (s * mids))[None, :]
        chi_mid = (spin * d_val + n_val).ravel()
        dchi_mid = (1j * (spin * (s * d_val + d_slope) + n_slope)).ravel()
    ends_error = (np.broadcast_to(e_end, d_end.shape)[:, [0, -1]].T + bounds.e_n0
                  + (bounds.spin_error + 8 * _U) * np.abs(d_end[:, [0, -1]]).T
                  + 2 * _U * np.abs(n_end[:, [0, -1]]).T)
    on_circle = np.any(np.abs(chi_end[:, [0, -1]]).T <= 2 * ends_error, axis=0)

    row = np.repeat(np.arange(n_rows), n_arcs)
    lo = np.broadcast_to(ends[:-1], (n_rows, n_arcs)).ravel()
    hi = np.broadcast_to(ends[1:], (n_rows, n_arcs)).ravel()
    chi_lo, chi_hi = chi_end[:, :-1].ravel(), chi_end[:, 1:].ravel()
    dm, d1m, nm, n1m = (np.abs(x).ravel() for x in (d_val, d_slope, n_val, n_slope))
    e_dm = np.broadcast_to(e_mid, d_val.shape).ravel()
    arcs = _Arcs(row, lo, hi, chi_lo, chi_mid, chi_hi, dchi_mid, dm, d1m, nm, n1m, e_dm)
    if on_circle.any():
        arcs = arcs.take(~on_circle[row])
    return arcs, on_circle.copy()


def _arcs_pass(bounds, arcs):
    """The third step: which arcs provably keep chi's image off 0, and their argument change.

    An arc passes on the first-order test (a disc from a bound on
    ``|chi'|`` over the arc) or, failing it, on the second-order one (a
    tube around the midpoint's tangent).  Returns ``(ok, step)``: a mask
    over the arcs and the argument change over each passed arc.
    """
    b, s, row, dm, e_dm = bounds, bounds.s, arcs.row, arcs.dm, arcs.e_dm
    chi_mid = arcs.chi_mid
    half = 0.5 * (arcs.hi - arcs.lo)
    with np.errstate(all="ignore"):
        # Bounds over the arc of the true |D|, |D'| and |N'|: Taylor from
        # the midpoint (|D''| <= S_2(D) on the circle), capped by the sums.
        d_at = dm + e_dm
        d1_at = arcs.d1m + b.e_d1[row]
        d_max = np.minimum(b.sd0[row] + b.e_d0[row],
                           d_at + half * (d1_at + 0.5 * half * b.sd2[row]))
        d1_max = np.minimum(b.sd1[row], d1_at + half * b.sd2[row])
        n1_max = np.minimum(b.sn1[row], arcs.n1m + b.e_n1[row] + half * b.sn2[row])
        error = (e_dm + b.e_n0[row] + (b.spin_error + 8 * _U) * dm
                 + 2 * _U * arcs.nm) * (1 + 8 * _U)
        size = np.abs(chi_mid)
        ok = (s * d_max + d1_max + n1_max) * half * (1 + 4 * _U) + error < size
        # Second order, for the arcs the first did not pass: chi(theta) =
        # chi_m + chi'_m t + R, |t| <= h, |R| <= M2 h**2 / 2 with M2 =
        # s**2 |D| + 2 s |D'| + S_2(D) + S_2(N); the tube around that
        # segment must miss 0.
        i = np.flatnonzero(~ok)
        r_i = row[i]
        h_i = half[i]
        curve = s * s * d_max[i] + 2 * s * d1_max[i] + b.sd2[r_i] + b.sn2[r_i]
        slope_error = ((b.spin_error + 8 * _U) * (s * dm[i] + arcs.d1m[i]) + s * e_dm[i]
                       + b.e_d1[r_i] + b.e_n1[r_i] + 8 * _U * arcs.n1m[i])
        radius = (0.5 * curve * h_i**2 + error[i] + slope_error * h_i) * (1 + 8 * _U)
        # The nearest point to 0 on the segment: t = -Re(chi_m / chi'_m)
        # (a quotient, not |chi'_m|**2, which could overflow); a flat
        # segment (chi'_m = 0) is its midpoint; anything not finite fails.
        c_i, dc_i = chi_mid[i], arcs.dchi_mid[i]
        flat = dc_i == 0
        t = np.where(flat, 0.0, -np.real(c_i / np.where(flat, 1.0, dc_i)))
        t = np.clip(t, -h_i, h_i)
        near = np.abs(c_i + dc_i * t) * (1 - 4 * _U)
        ok[i] = np.isfinite(t) & np.isfinite(near) & (near > radius)
        # The image of a passed arc lies in a convex set that misses 0
        # (a disc or a tube), so its argument changes by less than pi:
        # one angle gives the change.
        step = np.angle(arcs.chi_hi[ok] / arcs.chi_lo[ok])
    return ok, step


def _whole_count(change, undecided, n):
    """The last step: the roots outside the circle from the argument change, -1 where undecided.

    For real coefficients the change of the argument over the half circle
    is pi times the number of roots inside (the argument principle and the
    conjugate symmetry): a change far from a whole multiple of pi is a
    bug, not a marginal row.
    """
    inside = change / np.pi
    whole = np.rint(inside)
    if np.any(~undecided & (np.abs(inside - whole) > 0.25)):
        raise AssertionError("the certified argument change is not a multiple of pi")
    return np.where(undecided, -1, n - whole.astype(np.int64))


def schur_cohn(coefficients):
    """Vectorised Schur-Cohn test of real polynomials (highest power first).

    For ``p(z) = p_n z**n + ... + p_0`` the reflection coefficient is
    ``k = p_0 / p_n``; every root lies in the open unit disk exactly when
    ``|k| < 1`` and the same holds for ``(p(z) - k z**n p(1/z)) / z``, of
    degree ``n - 1``.  In floating point the verdict is reliable only where
    the margin is not small (:func:`classify_polynomials` re-decides the
    others).

    Parameters
    ----------
    coefficients : ndarray, shape (N, n + 1)
        Leading coefficients must be nonzero.

    Returns
    -------
    stable : ndarray of bool, shape (N,)
        All roots strictly inside the unit circle.
    margin : ndarray, shape (N,)
        ``min |1 - |k_j||`` over the steps taken (up to the first
        ``|k_j| >= 1``): how close the test came to the other verdict.
    """
    p = np.array(coefficients, dtype=float)
    n_points = p.shape[0]
    stable = np.ones(n_points, dtype=bool)
    margin = np.full(n_points, np.inf)
    active = np.ones(n_points, dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(p.shape[1] - 1):
            k = p[:, -1] / p[:, 0]
            size = np.abs(k)
            margin = np.where(active, np.minimum(margin, np.abs(1.0 - size)), margin)
            failed = active & ~(size < 1.0)
            stable &= ~failed
            active &= ~failed
            # One step of the recursion, normalised so that the leading
            # coefficient stays 1 (the sizes neither overflow nor underflow);
            # rows already decided are reset to a harmless polynomial.
            q = p - k[:, None] * p[:, ::-1]
            p = q[:, :-1] / q[:, :1]
            p[~active] = 1.0
    return stable, margin


def classify_polynomials(chi, *, refine=True):
    """Stable, marginal or unstable, per polynomial.

    Below degree 52 the float Schur-Cohn test (:func:`schur_cohn`) decides
    the polynomials it decides with a margin of at least 1e-6: that verdict
    carries no error bound; it agreed with 50- and 80-digit root counts on
    every point tried (the tests, and 44 800 points with margins from 1e-6
    to 1e-2 in a review).  Every other polynomial, and every one from
    degree 52 on, is decided by the certified count of :func:`root_counts`.
    :data:`MARGINAL` means a root on the unit circle to within the rounding
    of the coefficients, or a leading coefficient that vanishes (a root at
    infinity: an ill-posed loop).

    Parameters
    ----------
    chi : DelayedPolynomial or array_like
        The polynomials; dense coefficient rows (highest power first, shape
        ``(..., n + 1)``) are accepted too.
    refine : bool
        Re-decide the polynomials the float test does not decide safely (the
        default).  With ``False`` the Schur-Cohn verdict is returned as it
        is (only a margin of exactly 0 is marginal): faster where a wrong
        verdict next to the boundary does no harm.  From degree 52 on, a
        structured polynomial (short parts) gets the certified count's
        verdict either way.

    Returns
    -------
    ndarray of int8, shape ``chi.shape``
        :data:`STABLE` (1), :data:`MARGINAL` (0) or :data:`UNSTABLE` (-1).
    """
    if not isinstance(chi, DelayedPolynomial):
        chi = DelayedPolynomial.from_dense(chi)
    shape = chi.shape
    rows = chi.flat()
    n = rows.degree
    out = np.full(len(rows), MARGINAL, dtype=np.int8)
    live = np.flatnonzero(~leading_vanishes(rows))
    if n == 0:
        out[live] = STABLE
        return out.reshape(shape)
    short = max(rows.delayed.shape[1], rows.direct.shape[1]) <= _HORNER_TERMS
    if n >= _COUNT_ALL_FROM_DEGREE and (refine or short):
        # The count of a structured polynomial is O(n) where Schur-Cohn is
        # O(n**2): from this degree on it is the faster test as well as the
        # certified one (dense rows without refinement keep Schur-Cohn).
        close = live
    else:
        close = []
        for part in chunk_slices(len(live), 8 * (n + 1) * 4):
            index = live[part]
            dense = rows.take(index).dense()
            with np.errstate(all="ignore"):
                dense /= np.max(np.abs(dense), axis=1, keepdims=True)
            stable, margin = schur_cohn(dense)
            out[index] = np.where(stable, STABLE, UNSTABLE)
            if not refine:
                out[index[margin == 0]] = MARGINAL
            else:
                close.append(index[margin < _SCHUR_COHN_SAFE])
        close = np.concatenate(close) if close else np.empty(0, dtype=np.int64)
    if len(close):
        counts = root_counts(rows.take(close))
        out[close] = np.where(counts < 0, MARGINAL, np.where(counts == 0, STABLE, UNSTABLE))
    return out.reshape(shape)


#: The largest relative move of a Newton polish of eigenvalues: they are off
#: by about sqrt(eps) (1e-8) at a double root, far less elsewhere.
_POLISH_STEP = 1e-6


def polish_roots(c, roots, steps=3, max_step=math.inf):
    """Newton steps on dense coefficients ``c`` (rows), kept only where they shrink ``|p|``.

    Companion eigenvalues carry errors of a few 1e-12 near other roots (at
    alpha = 0 the root z = 1 came out as 1 - 4e-12); a few Newton steps on
    the coefficients bring them to the accuracy the coefficients allow.  A
    step longer than ``max_step`` times ``max(|z|, 1)`` is not taken (for
    eigenvalues, which are close already: from a double root at z = 1 a step
    once jumped to the root 0).
    """
    for _ in range(steps):
        with np.errstate(all="ignore"):
            value, slope = horner(c, roots)
            trial = roots - value / slope
            better = (np.isfinite(trial) & (np.abs(horner(c, trial)[0]) < np.abs(value))
                      & (np.abs(trial - roots) <= max_step * np.maximum(np.abs(roots), 1.0)))
        roots = np.where(better, trial, roots)
    return roots


def _eigen_radius(coefficients):
    """Spectral radius of each row of a (N, n + 1) dense array: companion eigenvalues, polished."""
    n_points, n1 = coefficients.shape
    n = n1 - 1
    out = np.empty(n_points)
    batch = max(1, _EIG_BATCH_BYTES // (8 * n * n))
    for start in range(0, n_points, batch):
        c = coefficients[start:start + batch]
        companion = np.zeros((len(c), n, n))
        companion[:, 0, :] = -c[:, 1:] / c[:, :1]
        companion[:, np.arange(1, n), np.arange(n - 1)] = 1.0
        roots = np.linalg.eigvals(companion)
        top = np.argsort(-np.abs(roots), axis=-1)[:, :min(2, n)]
        largest = polish_roots(c, np.take_along_axis(roots, top, axis=-1), max_step=_POLISH_STEP)
        out[start:start + batch] = np.max(np.abs(largest), axis=-1)
    return out


def spectral_radius(chi):
    """Largest root modulus of each polynomial.

    Up to degree 128: batched companion eigenvalues, the two largest of each
    row polished by Newton steps (about 1e-14 where the largest root is
    simple, about 1e-8 where two nearly coincide).  Above: the radius is
    bracketed by certified counts of the roots outside ``|z| = r``
    (:func:`root_counts` of :meth:`DelayedPolynomial.on_radius`, O(d) each)
    to 1e-7, then the largest root itself is found by Newton steps on the
    structured polynomial from the smallest ``|chi|`` on the bracket's upper
    circle and accepted where it lands in the bracket (to about 1e-14 where
    it is simple; otherwise the bracket's middle, to 1e-7).  The root is
    accepted only with certified counts on both sides of it (none outside a
    circle just above, one outside or on a circle just below).  Next to
    ``z = 1`` at short sample periods the values of ``chi`` in double
    precision limit the radius to about 1e-10 to 1e-9 (measured against 50
    digits: 7.6e-11 at ``T`` = 10 us, d = 129).

    Parameters
    ----------
    chi : DelayedPolynomial or array_like
        The polynomials (dense rows, highest power first, are accepted);
        leading coefficients nonzero.

    Returns
    -------
    ndarray of float, shape ``chi.shape``
    """
    if not isinstance(chi, DelayedPolynomial):
        chi = DelayedPolynomial.from_dense(chi)
    shape = chi.shape
    rows = chi.flat()
    n = rows.degree
    out = np.empty(len(rows))
    if n == 0:
        out[:] = 0.0
    elif n <= EIGENVALUES_UP_TO_DEGREE:
        check_memory(f"the spectral radius of degree {n}", 4 * 8 * n * n)
        for part in chunk_slices(len(rows), 8 * (n + 1)):
            dense = rows.take(part).dense()
            out[part] = _eigen_radius(dense)
    else:
        for part in chunk_slices(len(rows), 16 * 8 * (16 * n + 1)):
            out[part] = _structured_radius(rows.take(part))
    return out.reshape(shape)


def _outside(chi, radius):
    """Certified count outside ``|z| = radius`` per row; a marginal count (root on it) is -1."""
    return root_counts(chi.on_radius(radius))


def _structured_radius(chi):
    n_rows = len(chi)
    # A bracket [lo, hi]: no root outside |z| = hi, one outside (or on) lo,
    # grown geometrically from the unit circle.
    lo = np.zeros(n_rows)
    hi = np.ones(n_rows)
    grow = _outside(chi, hi) != 0
    factor = 2.0
    while np.any(grow):
        index = np.flatnonzero(grow)
        lo[index] = hi[index]
        hi[index] = hi[index] * factor
        if np.any(hi[index] > 1e300):
            raise ValueError("the spectral radius is too large for double precision")
        grow[index] = _outside(chi.take(index), hi[index]) != 0
        factor *= factor
    # From below: halve until a root is outside (a row whose roots are all
    # at 0 to within 1e-300 keeps lo = 0 and gets radius 0).
    fall = lo == 0
    while np.any(fall):
        index = np.flatnonzero(fall)
        low = 0.5 * hi[index]
        found = _outside(chi.take(index), low) != 0
        lo[index[found]] = low[found]
        hi[index[~found]] = low[~found]
        fall[index[found | (low < 1e-300)]] = False
    out = np.zeros(n_rows)
    todo = np.flatnonzero(lo > 0)
    tolerance = _BRACKET
    while todo.size:
        _bisect(chi, lo, hi, todo, tolerance)
        z = _newton_in_bracket(chi.take(todo), lo[todo], hi[todo])
        modulus = np.abs(z)
        landed = np.isfinite(modulus) & (modulus >= lo[todo]) & (modulus <= hi[todo])
        # Accepted when no root lies outside a circle just above it and one
        # lies outside or on a circle just below (then it is the largest to
        # within that margin); a count that is marginal
        # there (the root itself within rounding of that circle) is tried
        # again a little farther out.  A root outside: the bracket moves up.
        accepted = np.zeros(todo.size, dtype=bool)
        check = np.flatnonzero(landed)
        for margin in _ACCEPT:
            if not check.size:
                break
            above = modulus[check] * (1 + margin)
            counts = _outside(chi.take(todo[check]), above)
            # Newton's last iterate need not be a root: it is the radius
            # only if a root is also outside (or on) a circle just below it.
            inside = np.flatnonzero(counts == 0)
            below = modulus[check[inside]] * (1 - margin)
            none_below = _outside(chi.take(todo[check[inside]]), below) == 0
            accepted[check[inside[~none_below]]] = True
            hi[todo[check[inside[none_below]]]] = below[none_below]
            up = (counts > 0) & (above < hi[todo[check]])
            lo[todo[check[up]]] = above[up]
            check = check[counts < 0]
        out[todo[accepted]] = modulus[accepted]
        missed = todo[~accepted]
        if tolerance <= _FINAL_BRACKET:
            out[missed] = 0.5 * (lo[missed] + hi[missed])
            break
        todo, tolerance = missed, _FINAL_BRACKET
    return out


#: Relative width of the bracket before Newton steps take over, the margins
#: of the certified check of the root they find (the first whose count is
#: not marginal decides), and the width of the bisection a rejected root
#: falls back on.
_BRACKET = 1e-4
_ACCEPT = (1e-11, 1e-9, 1e-7)
_FINAL_BRACKET = 1e-13


def _bisect(chi, lo, hi, rows, tolerance):
    """Bisect ``[lo, hi]`` of ``rows`` in place (on log r) to relative width ``tolerance``."""
    while True:
        open_ = rows[hi[rows] - lo[rows] > tolerance * hi[rows]]
        if not open_.size:
            return
        middle = np.sqrt(lo[open_] * hi[open_])
        outside = _outside(chi.take(open_), middle) != 0
        lo[open_[outside]] = middle[outside]
        hi[open_[~outside]] = middle[~outside]


def _newton_in_bracket(chi, lo, hi):
    """A root near the annulus ``lo <= |z| <= hi`` of each row, by Newton steps.

    The start is the angle of the smallest ``|chi|`` on the circle ``|z| =
    hi``; the steps use ``chi / z**s`` outside the unit circle and ``chi``
    inside (neither overflows).
    """
    n = chi.degree
    theta = np.linspace(0.0, np.pi, 8 * n + 1)
    scaled = chi.on_radius(hi)
    d_val, _ = _part_values(scaled.delayed, theta)
    n_val, _ = _part_values(scaled.direct, theta)
    size = np.abs(np.exp(1j * scaled.shift * theta)[None, :] * d_val + n_val)
    z = hi * np.exp(1j * theta[np.argmin(size, axis=1)])
    s = chi.shift
    for _ in range(40):
        with np.errstate(all="ignore"):
            dv, ds = (x[:, 0] for x in horner(chi.delayed, z[:, None]))
            nv, ns = (x[:, 0] for x in horner(chi.direct, z[:, None]))
            power = np.exp(-s * np.log(z))
            outer = np.abs(z) >= 1
            # chi / z**s and chi' / z**s outside; chi and chi' inside.
            value = np.where(outer, dv + nv * power, dv / power + nv)
            slope = np.where(outer, s * dv / z + ds + ns * power, (s * dv / z + ds) / power + ns)
            step = value / slope
            z = np.where(np.isfinite(step), z - step, z)
        if np.all(~np.isfinite(step) | (np.abs(step) <= 4e-16 * np.abs(z))):
            break
    return z


# --------------------------------------------------------------------------
# The smallest |1 + L| on the circle (the modulus margin)

#: Rounds of halving the arcs not yet certified, and the most open at once.
_MINIMUM_ROUNDS = 60
_MINIMUM_OPEN_ARCS = 4096


def circle_minimum(chi, *, rtol=1e-9, coefficient_ulps=COEFFICIENT_ULPS):
    """Certified smallest ``|chi / (z**s D)| = |1 + N / (z**s D)|`` on the unit circle, per polynomial.

    For ``chi = z**s D + N`` the open loop is ``L = N / (z**s D)`` and
    ``1 + L = chi / (z**s D)``; on the circle ``|z**s| = 1``, so the
    modulus margin ``min |1 + L(exp(j theta))|`` over ``theta`` in [0, pi]
    is ``min |chi| / |D|``.  It is certified without dividing (``D`` has a
    root at ``z = 1`` for a plant with an integrator): ``|1 + L| >= mu``
    everywhere if and only if ``F = |chi|**2 - mu**2 |D|**2 >= 0``
    everywhere, and ``F`` is bounded below on each arc by its midpoint
    value and slope and a bound on its second derivative (from the same
    sums of the coefficients' moduli as :func:`root_counts`), with the
    rounding of the values.  Arcs not certified are halved; their
    midpoints lower the best value found so far, and ``mu`` follows it,
    so the smallest value and its certificate are found together:
    ``lower <= min |1 + L| <= upper`` with ``lower = upper (1 - rtol)``.

    Parameters
    ----------
    chi : DelayedPolynomial
        The polynomials (any shape).
    rtol : float
        The relative width of the certified bracket, in (0, 0.5).
    coefficient_ulps : float
        The error assumed of each coefficient, as in :func:`root_counts`.

    Returns
    -------
    (ndarray, ndarray, ndarray)
        ``lower``, ``upper`` and the ``theta`` (rad/sample, in [0, pi])
        where ``upper`` is attained, each of shape ``chi.shape``.  Where
        ``|chi|`` is too small beside its rounding for a bracket ``rtol``
        wide (next to the boundary), the bracket proved is a thousand, a
        million ... times wider (up to ``lower = 0.75 upper``); ``lower``
        is 0 where the minimum cannot be separated from 0 at all (a root of
        ``chi`` on the circle to within rounding: a marginal point) or the
        halving gave up (more open arcs than twice the first grid's).

    Examples
    --------
    >>> # z - 1/2 = z (1 + L) with L = -1/(2 z): |1 + L| is smallest at z = 1.
    >>> lower, upper, theta = circle_minimum(DelayedPolynomial([1.0], [-0.5], shift=1))
    >>> round(float(upper), 12), float(theta)
    (0.5, 0.0)
    """
    if not isinstance(chi, DelayedPolynomial):
        raise TypeError(f"chi must be a DelayedPolynomial, got {type(chi).__name__}")
    if not 0 < rtol < 0.5:
        raise ValueError(f"rtol must be in (0, 0.5), got {rtol!r}")
    shape = chi.shape
    rows = chi.flat()
    n_arcs = max(64, 8 * max(rows.degree, 1))
    out = np.zeros((3, len(rows)))
    # Per row: the first grid's arcs (ten complex values each) and their halves,
    # up to twice as many open.
    per_row = 16 * 12 * (n_arcs + 2) * 4
    check_memory(f"the modulus margin at degree {rows.degree}", per_row)
    todo = np.arange(len(rows))
    # Next to the boundary |chi| is small beside the rounding of its value, and
    # a bracket of width rtol cannot be proved: those rows are tried again
    # with the bracket a thousand times wider, up to a quarter.
    while todo.size:
        for part in chunk_slices(todo.size, per_row, CHUNK_BYTES):
            index = todo[part]
            near_one = None if rows.near_one is None else tuple(x[index] for x in rows.near_one)
            bounds = _chunk_bounds(rows.delayed[index], rows.direct[index], rows.shift,
                                   coefficient_ulps, near_one)
            out[:, index] = _chunk_minimum(bounds, len(index), rtol, n_arcs)
        todo = todo[(out[0, todo] == 0) & (out[1, todo] > 0)]
        if rtol >= 0.25:
            break
        rtol = min(0.25, 1e3 * rtol)
    return tuple(part.reshape(shape) for part in out)


class _MinimumArcs:
    """The open arcs of :func:`circle_minimum` (any row): their ends and midpoint values."""

    __slots__ = ("row", "lo", "hi", "chi", "dchi", "d", "dd", "n", "dn", "e_d")

    def __init__(self, bounds, row, lo, hi):
        self.row, self.lo, self.hi = row, lo, hi
        mid = 0.5 * (lo + hi)
        s = bounds.s
        with np.errstate(all="ignore"):
            d_val, d_slope, self.e_d = _delayed_values(bounds.part, mid, row)
            n_val, n_slope = _part_values(bounds.direct, mid, row)
            spin = np.exp(1j * (s * mid))
            self.chi = spin * d_val + n_val
            self.dchi = 1j * (spin * (s * d_val + d_slope) + n_slope)
        # d/dtheta of D(exp(j theta)) is j z D'(z).
        self.d, self.dd, self.n, self.dn = d_val, 1j * d_slope, n_val, n_slope

    def values(self):
        """``|chi| / |D|`` at the midpoints (inf where ``D`` is 0)."""
        with np.errstate(all="ignore"):
            return np.abs(self.chi) / np.abs(self.d)

    def halves(self, bounds, keep):
        """The arcs ``keep`` halved, ``[lo, mid]`` and ``[mid, hi]``, evaluated."""
        row, lo, hi = self.row[keep], self.lo[keep], self.hi[keep]
        mid = 0.5 * (lo + hi)
        return _MinimumArcs(bounds, np.concatenate([row, row]), np.concatenate([lo, mid]),
                            np.concatenate([mid, hi]))


def _certified(bounds, arcs, mu):
    """Which arcs provably keep ``|chi|**2 - mu**2 |D|**2`` above 0 (second-order Taylor bound).

    ``mu`` is per arc.  The bounds over an arc of ``|D|``, ``|D'|``, ``|N|``,
    ``|N'|`` are Taylor steps from the midpoint capped by the sums, as in
    :func:`_arcs_pass`; with them ``|F''| <= 2 (|chi'|**2 + |chi| |chi''|) + 2
    mu**2 (|D'|**2 + |D| |D''|)`` bounds ``F = |chi|**2 - mu**2 |D|**2`` below
    by ``F(m) - |F'(m)| h - max|F''| h**2 / 2`` minus the rounding of the
    values and of the slope.
    """
    b, s, r = bounds, bounds.s, arcs.row
    half = 0.5 * (arcs.hi - arcs.lo)
    with np.errstate(all="ignore"):
        dm, e_dm = np.abs(arcs.d), arcs.e_d
        d1_at, n1_at = np.abs(arcs.dd) + b.e_d1[r], np.abs(arcs.dn) + b.e_n1[r]
        d_max = np.minimum(b.sd0[r] + b.e_d0[r], dm + e_dm + half * (d1_at + 0.5 * half * b.sd2[r]))
        d1_max = np.minimum(b.sd1[r], d1_at + half * b.sd2[r])
        n_max = np.minimum(b.sn0[r] + b.e_n0[r],
                           np.abs(arcs.n) + b.e_n0[r] + half * (n1_at + 0.5 * half * b.sn2[r]))
        n1_max = np.minimum(b.sn1[r], n1_at + half * b.sn2[r])
        c0, c1 = d_max + n_max, s * d_max + d1_max + n1_max
        c2 = s * s * d_max + 2 * s * d1_max + b.sd2[r] + b.sn2[r]
        second = 2 * (c1 * c1 + c0 * c2) + 2 * mu * mu * (d1_max * d1_max + d_max * b.sd2[r])
        size = np.abs(arcs.chi)
        e_chi = e_dm + b.e_n0[r] + (b.spin_error + 8 * _U) * dm + 2 * _U * np.abs(arcs.n)
        value = size * size - mu * mu * dm * dm
        slope = 2 * np.real(np.conj(arcs.chi) * arcs.dchi - mu * mu * np.conj(arcs.d) * arcs.dd)
        # The rounding of chi' (as in _arcs_pass) and of D' enters through F'(m) h.
        e_dchi = ((b.spin_error + 8 * _U) * (s * dm + np.abs(arcs.dd)) + s * e_dm + b.e_d1[r]
                  + b.e_n1[r] + 8 * _U * np.abs(arcs.dn))
        e_slope = 2 * (e_dchi * (size + e_chi) + np.abs(arcs.dchi) * e_chi
                       + mu * mu * (b.e_d1[r] * (dm + e_dm) + np.abs(arcs.dd) * e_dm))
        error = ((2 * size + e_chi) * e_chi + mu * mu * (2 * dm + e_dm) * e_dm + e_slope * half
                 + 32 * _U * (size * size + mu * mu * dm * dm
                              + half * (2 * c0 * c1 + 2 * mu * mu * d_max * d1_max)))
        low = value - np.abs(slope) * half - 0.5 * second * half * half - error
    return np.isfinite(low) & (low > 0)


def _lowered(upper, theta, arcs):
    """``upper`` and ``theta`` per row, lowered to the arcs' smallest midpoint values."""
    values = arcs.values()
    finite = np.isfinite(values)
    if not finite.any():
        return
    row, values = arcs.row[finite], values[finite]
    mids = 0.5 * (arcs.lo + arcs.hi)[finite]
    order = np.lexsort((values, row))
    first = order[np.r_[True, row[order][1:] != row[order][:-1]]]
    better = values[first] < upper[row[first]]
    upper[row[first[better]]] = values[first[better]]
    theta[row[first[better]]] = mids[first[better]]


def _chunk_minimum(bounds, n_rows, rtol, n_arcs):
    """``(lower, upper, theta)`` of :func:`circle_minimum` for one chunk's rows."""
    ends = np.linspace(0.0, np.pi, n_arcs + 1)
    every = np.arange(n_rows)
    upper, theta = np.full(n_rows, np.inf), np.zeros(n_rows)
    # The ends of [0, pi] are candidates too (an arc's midpoint never is one).
    _lowered(upper, theta, _MinimumArcs(bounds, np.repeat(every, 2),
                                        np.tile([0.0, np.pi], n_rows),
                                        np.tile([0.0, np.pi], n_rows)))
    arcs = _MinimumArcs(bounds, np.repeat(every, n_arcs), np.tile(ends[:-1], n_rows),
                        np.tile(ends[1:], n_rows))
    _lowered(upper, theta, arcs)
    lower = np.zeros(n_rows)
    open_rows = np.ones(n_rows, dtype=bool)
    for _ in range(_MINIMUM_ROUNDS):
        ok = _certified(bounds, arcs, upper[arcs.row] * (1 - rtol))
        failing = np.bincount(arcs.row[~ok], minlength=n_rows)
        done = open_rows & (failing == 0)
        lower[done] = upper[done] * (1 - rtol)
        # A row whose open arcs multiply beyond its first grid has |chi| within
        # rounding of 0 on a stretch of the circle (or many minima of one depth:
        # a long delay's flat |L|), and the halving gives up there.
        open_rows &= (failing > 0) & (failing <= max(_MINIMUM_OPEN_ARCS, 2 * n_arcs))
        keep = ~ok & open_rows[arcs.row]
        if not keep.any():
            break
        arcs = arcs.halves(bounds, keep)
        _lowered(upper, theta, arcs)
    return lower, upper, theta
