"""Stability of parameter points: spectral radius and root-counting classification.

A parameter point is stable when every root of the characteristic polynomial
chi(z) lies strictly inside the unit circle.  The vectorised functions here
take arrays of ``alpha, beta, gamma, delta`` (broadcast together) and one
integer delay ``d``:

* :func:`loop_coefficients` -- the coefficients of ``chi(z) / delta**2`` from
  the generated kernel (:mod:`symstab._generated.kernels`), whose forms keep
  their digits for small delta;
* :func:`spectral_radius` -- the largest root modulus, from batched
  eigenvalues of companion matrices;
* :func:`classify` -- stable, unstable or marginal, by a vectorised
  Schur-Cohn test (``d + 4`` steps of O(d) array work whatever the number of
  points); the few points whose Schur-Cohn reflection coefficients come
  close to modulus 1 are decided by their eigenvalues instead, and a point
  whose spectral radius is within ``marginal_tol`` of 1 is reported as
  :data:`MARGINAL`, not guessed;
* :func:`is_stable` -- the same as a masked boolean array (masked where
  marginal), or ``True``/``False``/``None`` for a single point.

The per-point functions at the end (:func:`coefficients_at`,
:func:`unstable_root_count`, :func:`stable_alpha_intervals`) evaluate the
coefficients at 30 digits through mpmath; they are the slow reference the
audit was built on.
"""

import functools

import numpy as np

from .._generated import kernels
from .._resources import CHUNK_BYTES, check_memory, chunk_slices
from .._validate import DELTA_MAX, PARAMETER_MAX, check_array, check_delay
from ..symbolic.loop import characteristic_polynomial

__all__ = [
    "STABLE", "MARGINAL", "UNSTABLE",
    "loop_coefficients", "spectral_radius", "schur_cohn", "unstable_root_counts",
    "classify", "is_stable",
    "coefficients_at", "unstable_root_count", "stable_alpha_intervals",
    "polynomial_root_counts", "classify_polynomials", "polynomial_spectral_radius",
]

#: Codes returned by :func:`classify`.
STABLE, MARGINAL, UNSTABLE = 1, 0, -1
#: Points whose Schur-Cohn margin ``min |1 - |k_j|||`` is below this are
#: re-decided by the certified root count: the reflection coefficients are
#: not the radius, and their rounding grows with ``1 / (1 - k_j**2)``.
_SCHUR_COHN_SAFE = 1e-6
#: From this delay on, every point goes to the root count: it is O(d) per
#: point where Schur-Cohn is O(d**2), and at long delays the stable points'
#: Schur-Cohn margins fall below the safe level anyway.
_COUNT_ALL_FROM_DELAY = 48
#: Relative accuracy assumed of the generated coefficients, in units of
#: 2**-53; measured at most a few (tests/test_generated_kernels.py).
_COEFFICIENT_ULPS = 64
_U = 2.0**-53
#: Bisection rounds of an arc of the circle before a point is called
#: marginal, and the most arcs of one point left open at once.
_MAX_ROUNDS = 48
_MAX_OPEN_ARCS = 1024
#: Most terms (angles times coefficients) of a halving round of
#: :func:`polynomial_root_counts` evaluated by direct powers (else Horner).
_DIRECT_TERMS = 2**16
#: Largest table of cos(k theta), sin(k theta) kept for the first pass of
#: :func:`polynomial_root_counts` (bytes; four are cached).
_TABLE_BYTES = 4 * 2**20
#: Rows of companion matrices handed to LAPACK at once (bytes).
_EIG_BATCH_BYTES = 64 * 2**20


def _points(alpha, beta, gamma, d, delta):
    """Validate and broadcast; return (alpha, beta, gamma, delta, d, shape)."""
    bound = dict(low=-PARAMETER_MAX, high=PARAMETER_MAX)
    arrays = [check_array("alpha", alpha, **bound), check_array("beta", beta, **bound),
              check_array("gamma", gamma, **bound),
              check_array("delta", delta, low=0.0, high=DELTA_MAX)]
    d = check_delay(d)
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError as exc:
        raise ValueError(f"alpha, beta, gamma and delta must broadcast together: {exc}") from None
    return (*arrays, d, arrays[0].shape)


def _kernel_coefficients(alpha, beta, gamma, delta):
    """The seven distinct coefficients of chi / (delta**2 Gamma), as (N,) arrays.

    Finite for every input :func:`_points` accepts: |alpha|, |beta|,
    |gamma| <= PARAMETER_MAX and the ZOH functions of delta are at most 1.
    """
    c = kernels.loop_coefficients(alpha, beta, gamma, delta)
    shape = np.broadcast(alpha, beta, gamma, delta).shape
    return [np.broadcast_to(np.asarray(ck, dtype=float), shape).ravel() for ck in c]


def _one_minus_r(delta, shape):
    """``em = 1 - exp(-delta)`` per point, for the factored ``z - r`` of the root count."""
    return np.broadcast_to(-np.expm1(-delta), shape).ravel()


def _dense(c7, d, rows=slice(None)):
    """(N, d + 5) coefficients, highest power first, from the seven distinct ones."""
    n_rows = len(c7[0][rows])
    out = np.zeros((n_rows, d + 5))
    for k in range(3):
        out[:, k] += c7[k][rows]
    for k in range(4):
        out[:, d + 1 + k] += c7[3 + k][rows]
    return out


def loop_coefficients(*, alpha, beta, gamma, d, delta):
    """Coefficients of ``chi(z) / (delta**2 exp(delta))``, highest power first.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    ndarray
        Shape ``broadcast_shape + (d + 5,)``; the leading coefficient is 1.

    Raises
    ------
    TypeError, ValueError
        For non-real, non-finite or out-of-range parameters, or an array
        that would not fit in the memory limit.
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    check_memory(f"the coefficients of {int(np.prod(shape))} points at d = {d}",
                 8 * (d + 5) * int(np.prod(shape)))
    c7 = _kernel_coefficients(alpha, beta, gamma, delta)
    return _dense(c7, d).reshape(shape + (d + 5,))


def _horner(c, z):
    """p(z) and p'(z) for rows of coefficients ``c`` (highest first) at points ``z``."""
    value = np.zeros_like(z)
    slope = np.zeros_like(z)
    for k in range(c.shape[1]):
        slope = slope * z + value
        value = value * z + c[:, k, None]
    return value, slope


def _polish(c, roots, steps=3):
    """Newton steps on the polynomial itself, kept only where they shrink |p|.

    Companion eigenvalues carry errors of a few 1e-12 near other roots (at
    alpha = 0 the root z = 1 came out as 1 - 4e-12); a few Newton steps on
    the coefficients bring them to the accuracy the coefficients allow.
    """
    for _ in range(steps):
        with np.errstate(all="ignore"):
            value, slope = _horner(c, roots)
            trial = roots - value / slope
            better = np.isfinite(trial) & (np.abs(_horner(c, trial)[0]) < np.abs(value))
        roots = np.where(better, trial, roots)
    return roots


def _radius(coefficients):
    """Spectral radius of each row of a (N, n + 1) coefficient array.

    Batched companion-matrix eigenvalues; the two largest roots of each row
    are polished by Newton steps (:func:`_polish`).
    """
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
        largest = _polish(c, np.take_along_axis(roots, top, axis=-1))
        out[start:start + batch] = np.max(np.abs(largest), axis=-1)
    return out


def spectral_radius(*, alpha, beta, gamma, d, delta):
    """Largest modulus of the closed-loop poles (batched eigenvalues).

    The roots come from companion-matrix eigenvalues, the two largest of
    each point polished by Newton steps on the polynomial: about 1e-14
    where the largest root is simple, but only about the square root of
    that (1e-8) where two roots nearly coincide.  For a verdict use
    :func:`classify`, which is certified; this is the O(d**3) per point
    measure of how far a point is from the boundary.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    float or ndarray
        A float for scalar parameters, else an array of the broadcast shape.

    Examples
    --------
    >>> r = spectral_radius(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=0.0025)
    >>> bool(r < 1)
    True
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    n = d + 4
    size = int(np.prod(shape))
    # One companion matrix and its workspace must fit (LAPACK's O(n**2)).
    check_memory(f"the spectral radius at d = {d}", 4 * 8 * n * n)
    c7 = _kernel_coefficients(alpha, beta, gamma, delta)
    r = np.empty(size)
    for rows in chunk_slices(size, 8 * (d + 5)):
        r[rows] = _radius(_dense(c7, d, rows))
    r = r.reshape(shape)
    return float(r) if r.ndim == 0 else r


def schur_cohn(coefficients):
    """Vectorised Schur-Cohn test of real polynomials (highest power first).

    For ``p(z) = p_n z**n + ... + p_0`` the reflection coefficient is
    ``k = p_0 / p_n``; every root lies in the open unit disk exactly when
    ``|k| < 1`` and the same holds for ``(p(z) - k z**n p(1/z)) / z``, of
    degree ``n - 1``.  In floating point the verdict is reliable only where
    the margin is not small (:func:`classify` re-decides the others).

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


def _circle_values(theta, d, em, r, c3, c4, c5, c6):
    """chi and d chi / d theta at ``z = exp(j theta)``, ``|z - 1|`` and ``|z - r|``.

    ``chi / (delta**2 Gamma) = exp(j (d+2) theta) A + B`` with ``A = (z -
    1)(z - r)`` in the factored form (``cos(theta) - r = em - 2
    sin(theta/2)**2`` has no cancellation) and ``B = c3 z**3 + c4 z**2 + c5
    z + c6``.  Rows of the parameters broadcast against columns of ``theta``.
    """
    s_half = np.sin(0.5 * theta)
    sin_t = np.sin(theta)
    z_minus_1 = -2.0 * s_half**2 + 1j * sin_t
    z_minus_r = (em - 2.0 * s_half**2) + 1j * sin_t
    a = z_minus_1 * z_minus_r
    z = np.exp(1j * theta)
    b = ((c3 * z + c4) * z + c5) * z + c6
    spin = np.exp(1j * ((d + 2) * theta))
    # d/d theta = j z d/dz.
    a_slope = 1j * z * (z_minus_1 + z_minus_r)
    b_slope = 1j * z * ((3 * c3 * z + 2 * c4) * z + c5)
    chi_slope = spin * (1j * (d + 2) * a + a_slope) + b_slope
    return spin * a + b, chi_slope, 2.0 * np.abs(s_half), np.abs(z_minus_r)


def unstable_root_counts(*, alpha, beta, gamma, d, delta):
    """Number of closed-loop poles outside the unit circle, certified.

    The argument principle on the unit circle: with ``chi(exp(j theta)) =
    exp(j (d+2) theta) A + B`` (:func:`_circle_values`), the number of roots
    inside is the change of ``arg chi`` over ``theta`` in [0, pi] divided by
    pi (the coefficients are real).  The change is summed arc by arc, and an
    arc counts only when a bound on ``|d chi / d theta|`` over it and a
    bound on the rounding error keep its whole image inside a disc that
    excludes 0 (first order), or a bound on the second derivative keeps it
    inside a tube around the midpoint's tangent that excludes 0 (second
    order: a simple root next to the circle then costs a few halvings); other
    arcs are halved, up to 48 times.  The count is then
    exact for the polynomial whose coefficients are within 64 ulps of the
    generated kernel's (measured within a few ulps of the exact ones).  O(d)
    per point.

    Parameters are as in :func:`loop_coefficients`.

    Returns
    -------
    int or ndarray of int
        The number of roots with modulus > 1, or -1 where a root lies on
        the unit circle to within rounding (a marginal point).

    Examples
    --------
    >>> int(unstable_root_counts(alpha=3.0, beta=0.5, gamma=0.0, d=0, delta=0.0025))
    2
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    c7 = _kernel_coefficients(alpha, beta, gamma, delta)
    em = _one_minus_r(delta, shape)
    out = _root_counts(c7, em, d)
    out = out.reshape(shape)
    return int(out) if out.ndim == 0 else out


def _root_counts(c7, em, d, rows=None):
    """Certified counts of roots outside the circle for rows of ``c7`` (-1: marginal)."""
    if rows is None:
        rows = np.arange(len(em))
    n_arcs = max(64, 8 * (d + 4))
    counts = np.empty(len(rows), dtype=np.int64)
    per_row = 16 * (2 * n_arcs + 1) * 6
    for part in chunk_slices(len(rows), per_row, CHUNK_BYTES):
        counts[part] = _root_counts_chunk([c[rows[part]] for c in c7], em[rows[part]], d, n_arcs)
    return counts


def _root_counts_chunk(c7, em, d, n_arcs):
    c3, c4, c5, c6 = (c[:, None] for c in c7[3:])
    r = c7[2][:, None]
    em = em[:, None]
    n_rows = len(em)
    b_sum = np.abs(c3) + np.abs(c4) + np.abs(c5) + np.abs(c6)
    # |d B / d theta| <= sum k |b_k|.  For A = (z - 1)(z - r) the bounds are
    # local (|dz / d theta| = 1): on an arc of half-width h around z_m,
    # |A| <= (|z_m - 1| + h)(|z_m - r| + h), |A'| <= |z_m - 1| + |z_m - r| + 2 h.
    b_slope = 3 * np.abs(c3) + 2 * np.abs(c4) + np.abs(c5)
    b_curve = 9 * np.abs(c3) + 4 * np.abs(c4) + np.abs(c5)
    # Rounding of chi at one angle, doubled for the bounds' own rounding:
    # the phase (d+2) theta and the factored A carry errors relative to |A|;
    # B those of its evaluation and of the coefficients themselves (64 ulps).
    b_error = 2 * _U * (8 + _COEFFICIENT_ULPS) * b_sum
    args = (d, em, r, c3, c4, c5, c6)

    theta = np.linspace(0.0, np.pi, 2 * n_arcs + 1)
    with np.errstate(all="ignore"):
        chi, dchi, to_one, to_r = _circle_values(theta[None, :], *args)
    row = np.repeat(np.arange(n_rows), n_arcs)
    lo, mid, hi = (np.broadcast_to(theta[k:len(theta) - 2 + k:2], (n_rows, n_arcs)).ravel()
                   for k in range(3))
    chi_lo, chi_mid, chi_hi = (chi[:, k:chi.shape[1] - 2 + k:2].ravel() for k in range(3))
    to_one, to_r, dchi_mid = (np.broadcast_to(x[:, 1::2], (n_rows, n_arcs)).ravel()
                              for x in (to_one, to_r, dchi))
    change = np.zeros(n_rows)
    undecided = np.zeros(n_rows, dtype=bool)
    for _ in range(_MAX_ROUNDS):
        half = 0.5 * (hi - lo)
        a_max = (to_one + half) * (to_r + half)
        slope = (d + 2) * a_max + to_one + to_r + 2 * half + b_slope[row, 0]
        error = 2 * _U * (4 * np.pi * (d + 4) + 16) * a_max + b_error[row, 0]
        ok = slope * half * (1 + 4 * _U) + error < np.abs(chi_mid)
        # Second order: chi(theta) = chi_m + chi'_m t + R, |t| <= h, with
        # |R| <= M2 h**2 / 2; the tube around that segment must miss 0.
        a_slope_max = to_one + to_r + 2 * half
        curve = ((d + 2) ** 2 * a_max + 2 * (d + 2) * a_slope_max + a_slope_max + 2
                 + b_curve[row, 0])
        slope_error = (2 * (d + 4) * error + 2 * _U * (8 + _COEFFICIENT_ULPS) * b_slope[row, 0]
                       + 16 * _U * a_slope_max)
        radius = (0.5 * curve * half**2 + error + slope_error * half) * (1 + 8 * _U)
        with np.errstate(all="ignore"):
            # The nearest point to 0 on the segment: t = -Re(chi_m / chi'_m)
            # (a quotient, not |chi'_m|**2, which could overflow); a flat
            # segment (chi'_m = 0) is its midpoint; anything not finite fails.
            flat = dchi_mid == 0
            t = np.where(flat, 0.0, -np.real(chi_mid / np.where(flat, 1.0, dchi_mid)))
            t = np.clip(t, -half, half)
            near = np.abs(chi_mid + dchi_mid * t) * (1 - 4 * _U)
            ok |= np.isfinite(t) & np.isfinite(near) & (near > radius)
        with np.errstate(all="ignore"):
            step = np.angle(chi_hi / chi_mid) - np.angle(chi_lo / chi_mid)
        np.add.at(change, row[ok], step[ok])
        bad = ~ok
        # A row whose open arcs multiply has |chi| within rounding of 0 along
        # a stretch of the circle (clustered roots on it): marginal.
        crowded = np.bincount(row[bad], minlength=n_rows) > _MAX_OPEN_ARCS
        undecided |= crowded
        bad &= ~crowded[row]
        if not bad.any():
            break
        # Halve the arcs that did not pass: [lo, mid] and [mid, hi].
        row, lo, mid, hi = row[bad], lo[bad], mid[bad], hi[bad]
        chi_lo, chi_mid, chi_hi = chi_lo[bad], chi_mid[bad], chi_hi[bad]
        q1, q3 = 0.5 * (lo + mid), 0.5 * (mid + hi)
        sub = (d, em[row], r[row], c3[row], c4[row], c5[row], c6[row])
        with np.errstate(all="ignore"):
            chi_q1, dchi_q1, one_q1, r_q1 = _circle_values(q1[:, None], *sub)
            chi_q3, dchi_q3, one_q3, r_q3 = _circle_values(q3[:, None], *sub)
        row = np.concatenate([row, row])
        lo, hi, mid = np.concatenate([lo, mid]), np.concatenate([mid, hi]), np.concatenate([q1, q3])
        chi_lo, chi_hi = np.concatenate([chi_lo, chi_mid]), np.concatenate([chi_mid, chi_hi])
        chi_mid = np.concatenate([chi_q1.ravel(), chi_q3.ravel()])
        dchi_mid = np.concatenate([dchi_q1.ravel(), dchi_q3.ravel()])
        to_one = np.concatenate([np.broadcast_to(one_q1, r_q1.shape).ravel(),
                                 np.broadcast_to(one_q3, r_q3.shape).ravel()])
        to_r = np.concatenate([r_q1.ravel(), r_q3.ravel()])
        if not np.all(hi > lo):
            undecided[np.unique(row[~(hi > lo)])] = True
    else:
        undecided[np.unique(row)] = True
    inside = change / np.pi
    whole = np.rint(inside)
    if np.any(~undecided & (np.abs(inside - whole) > 0.25)):
        raise AssertionError("the certified argument change is not a multiple of pi")
    return np.where(undecided, -1, (d + 4) - whole.astype(np.int64))


def classify(*, alpha, beta, gamma, d, delta, refine=True):
    """Classify parameter points as stable, unstable or marginal.

    A fast floating-point Schur-Cohn test (:func:`schur_cohn`) decides the
    points it decides with a margin of at least 1e-6 (below d = 48): that
    verdict carries no error bound; it agreed with 50- and 80-digit root
    counts on every point tried (the tests, and 44 800 points with margins
    from 1e-6 to 1e-2 in a review).  Every other point, and every point
    from d = 48 on, is decided by the certified root count of
    :func:`unstable_root_counts`.  :data:`MARGINAL` means that a root lies
    on the unit circle to within the rounding of the coefficients (a point
    on the boundary, to about 1e-13 relative): the verdict is then not
    certain either way.

    Parameters
    ----------
    alpha, beta, gamma, d, delta
        As in :func:`loop_coefficients`.
    refine : bool
        Re-decide the points the float test does not decide safely (the
        default).  With ``False`` the Schur-Cohn verdict is returned as it is
        (only a margin of exactly 0 is marginal): faster where a wrong
        verdict next to the boundary does no harm.

    Returns
    -------
    int or ndarray of int8
        :data:`STABLE` (1), :data:`MARGINAL` (0) or :data:`UNSTABLE` (-1).

    Raises
    ------
    TypeError, ValueError
        For non-real, non-finite or out-of-range parameters (``delta`` in
        [0, 1e6], ``|alpha|, |beta|, |gamma| <= 1e150``, ``d`` up to
        ``SYMSTAB_MAX_DELAY``).

    Examples
    --------
    >>> classify(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=0.0025) == STABLE
    True
    >>> classify(alpha=3.0, beta=0.5, gamma=0.0, d=0, delta=0.0025) == UNSTABLE
    True
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    c7 = _kernel_coefficients(alpha, beta, gamma, delta)
    em = _one_minus_r(delta, shape)
    size = len(em)
    out = np.empty(size, dtype=np.int8)
    if refine and d >= _COUNT_ALL_FROM_DELAY:
        counts = _root_counts(c7, em, d)
        out[:] = np.where(counts < 0, MARGINAL, np.where(counts == 0, STABLE, UNSTABLE))
        return _shaped(out, shape)
    for rows in chunk_slices(size, 8 * (d + 5) * 4):
        stable, margin = schur_cohn(_dense(c7, d, rows))
        part = np.where(stable, STABLE, UNSTABLE).astype(np.int8)
        if not refine:
            part[margin == 0] = MARGINAL
        else:
            close = np.flatnonzero(margin < _SCHUR_COHN_SAFE)
            if close.size:
                counts = _root_counts(c7, em, d, np.arange(size)[rows][close])
                part[close] = np.where(counts < 0, MARGINAL,
                                       np.where(counts == 0, STABLE, UNSTABLE))
        out[rows] = part
    return _shaped(out, shape)


def polynomial_spectral_radius(coefficients):
    """Largest root modulus of each row of real polynomials (highest power first).

    Batched companion eigenvalues, the largest polished by Newton steps, as
    in :func:`spectral_radius`; rows are processed in chunks.

    Parameters
    ----------
    coefficients : ndarray, shape (N, n + 1)
        Leading coefficients nonzero.

    Returns
    -------
    ndarray, shape (N,)
    """
    p = np.asarray(coefficients, dtype=float)
    n = p.shape[1] - 1
    check_memory(f"the spectral radius of degree {n}", 4 * 8 * n * n)
    out = np.empty(len(p))
    for rows in chunk_slices(len(p), 8 * (n + 1)):
        out[rows] = _radius(p[rows])
    return out


def _horner_circle(p, theta):
    """p(exp(j theta)) and d p / d theta for rows of ``p`` and columns of ``theta``."""
    z = np.exp(1j * theta)
    n = p.shape[1] - 1
    value = np.zeros(np.broadcast(p[:, :1], z).shape, dtype=complex)
    slope = np.zeros_like(value)
    for k in range(n + 1):
        slope = slope * z + value
        value = value * z + p[:, k, None]
    # d/d theta = j z d/dz.
    return value, 1j * z * slope


def _circle_direct(p, theta):
    """p(exp(j theta)) and its first two derivatives in theta, for row ``k`` of ``p`` at ``theta[k]``.

    The powers ``z**k = exp(j k theta)`` in one vectorised step: for the few
    angles of a halving round this costs less than ``n`` steps of Horner's
    scheme, and it rounds well within the same bound (the argument ``k
    theta`` carries at most ``k pi`` units, exp and the product a few, the
    sum ``n``: at most ``(pi + 1) n + 5`` units of ``S_0``, and of ``S_1``
    (``S_2``) for the first (second) derivative, as ``S_{k+1} <= n S_k``;
    measured below half of that against mpmath).
    """
    n = p.shape[1] - 1
    powers = np.arange(n, -1, -1, dtype=float)
    z_k = np.exp(1j * theta[:, None] * powers)
    terms = p * z_k
    slope_terms = terms * powers
    return (np.sum(terms, axis=1), 1j * np.sum(slope_terms, axis=1),
            -np.sum(slope_terms * powers, axis=1))


@functools.lru_cache(maxsize=4)
def _circle_table(n, n_points):
    """``cos(k theta)``, ``sin(k theta)`` for ``k = n .. 0`` and ``theta = linspace(0, pi, n_points)``.

    Shape ``(n + 1, n_points)`` each, read-only; None when the pair would
    take more than ``_TABLE_BYTES`` (then Horner's scheme, which needs no
    table).
    """
    if 16 * (n + 1) * n_points > _TABLE_BYTES:
        return None
    angles = np.multiply.outer(np.arange(n, -1, -1, dtype=float), np.linspace(0.0, np.pi, n_points))
    table = (np.cos(angles), np.sin(angles))
    for part in table:
        part.flags.writeable = False
    return table


def polynomial_root_counts(coefficients, *, coefficient_ulps=_COEFFICIENT_ULPS):
    """Certified number of roots outside the unit circle of real polynomials.

    The argument principle over ``theta`` in [0, pi], as in
    :func:`unstable_root_counts`, for any real polynomial: an arc counts
    when, with ``S_k = sum_j j**k |c_j|``, the first-order bound
    ``S_1 h`` plus the rounding of Horner's scheme keeps its image off 0, or
    the second-order tube (``S_2 h**2 / 2``) around the midpoint's tangent
    misses 0; other arcs are halved, up to 48 times.  The count is exact for
    every polynomial whose coefficients are within ``coefficient_ulps`` ulps
    of the given ones (relative to ``S_0``).

    Parameters
    ----------
    coefficients : ndarray, shape (N, n + 1)
        Real coefficients, highest power first, leading ones nonzero.
    coefficient_ulps : float
        Error assumed of each coefficient, in units of ``2**-53 S_0``.

    Returns
    -------
    ndarray of int, shape (N,)
        Roots with modulus > 1, or -1 where a root is on the circle to
        within rounding (marginal).
    """
    p = np.asarray(coefficients, dtype=float)
    n = p.shape[1] - 1
    n_arcs = max(64, 8 * n)
    counts = np.empty(len(p), dtype=np.int64)
    per_row = 16 * (2 * n_arcs + 1) * 4 + 8 * (n + 1) * (2 * n_arcs + 1)
    for part in chunk_slices(len(p), per_row, CHUNK_BYTES):
        counts[part] = _polynomial_counts_chunk(p[part], n_arcs, coefficient_ulps)
    return counts


def _polynomial_counts_chunk(p, n_arcs, coefficient_ulps):
    n = p.shape[1] - 1
    n_rows = len(p)
    scale = np.max(np.abs(p), axis=1, keepdims=True)
    # A row of zeros (every coefficient underflowed) has no roots to count.
    zero = scale[:, 0] == 0
    p = p / np.where(scale == 0, 1.0, scale)
    powers = np.arange(n, -1, -1, dtype=float)
    s0 = np.sum(np.abs(p), axis=1)
    s1 = np.sum(powers * np.abs(p), axis=1)
    s2 = np.sum(powers**2 * np.abs(p), axis=1)
    s3 = np.sum(powers**3 * np.abs(p), axis=1)
    # Horner's rounding at |z| = 1 (complex: a few units per step, doubled for
    # the bounds' own rounding), plus the coefficients' own error.
    error = 2 * _U * (8 * (n + 2) + coefficient_ulps) * s0
    slope_error = 2 * _U * (8 * (n + 2) + coefficient_ulps) * s1
    curve_error = 2 * _U * (8 * (n + 2) + coefficient_ulps) * s2

    # A root at z = 1 or -1 to within rounding: marginal, without halving
    # arcs down to it.
    signs = (-1.0) ** powers
    on_circle = ((np.abs(np.sum(p, axis=1)) <= error)
                 | (np.abs(np.sum(p * signs, axis=1)) <= error))
    theta = np.linspace(0.0, np.pi, 2 * n_arcs + 1)
    table = _circle_table(n, len(theta))
    with np.errstate(all="ignore"):
        if table is None:
            chi, dchi = _horner_circle(p, theta[None, :])
            # No second derivative: the tube uses the global bound S_2.
            d2chi = np.full(dchi.shape, np.inf)
        else:
            # The same values as a product with cos(k theta), sin(k theta):
            # rounding as in _circle_direct, at a fraction of Horner's cost.
            cos_k, sin_k = table
            weighted, weighted2 = p * powers, p * powers**2
            chi = p @ cos_k + 1j * (p @ sin_k)
            dchi = -(weighted @ sin_k) + 1j * (weighted @ cos_k)
            d2chi = -(weighted2 @ cos_k) - 1j * (weighted2 @ sin_k)
    row = np.repeat(np.arange(n_rows), n_arcs)
    lo, mid, hi = (np.broadcast_to(theta[k:len(theta) - 2 + k:2], (n_rows, n_arcs)).ravel()
                   for k in range(3))
    chi_lo, chi_mid, chi_hi = (chi[:, k:chi.shape[1] - 2 + k:2].ravel() for k in range(3))
    dchi_mid = dchi[:, 1::2].ravel()
    d2chi_mid = np.abs(d2chi[:, 1::2]).ravel()
    change = np.zeros(n_rows)
    undecided = on_circle | zero
    live = ~on_circle[row]
    row, lo, mid, hi = row[live], lo[live], mid[live], hi[live]
    chi_lo, chi_mid, chi_hi, dchi_mid = chi_lo[live], chi_mid[live], chi_hi[live], dchi_mid[live]
    d2chi_mid = d2chi_mid[live]
    for _ in range(_MAX_ROUNDS):
        if row.size == 0:
            break
        half = 0.5 * (hi - lo)
        ok = s1[row] * half * (1 + 4 * _U) + error[row] < np.abs(chi_mid)
        # |chi''| on the arc is at most S_2, and at most |chi''_m| (plus its
        # rounding e_2) + S_3 |t|: the tangent's remainder is at most the
        # smaller of S_2 h**2 / 2 and (|chi''_m| + e_2) h**2 / 2 + S_3 h**3 / 6.
        with np.errstate(all="ignore"):
            remainder = np.minimum(0.5 * s2[row] * half**2,
                                   (0.5 * (d2chi_mid + curve_error[row]) + s3[row] * half / 6) * half**2)
        radius = (remainder + error[row] + slope_error[row] * half) * (1 + 8 * _U)
        with np.errstate(all="ignore"):
            flat = dchi_mid == 0
            t = np.where(flat, 0.0, -np.real(chi_mid / np.where(flat, 1.0, dchi_mid)))
            t = np.clip(t, -half, half)
            near = np.abs(chi_mid + dchi_mid * t) * (1 - 4 * _U)
            ok |= np.isfinite(t) & np.isfinite(near) & (near > radius)
            step = np.angle(chi_hi / chi_mid) - np.angle(chi_lo / chi_mid)
        np.add.at(change, row[ok], step[ok])
        bad = ~ok
        crowded = np.bincount(row[bad], minlength=n_rows) > _MAX_OPEN_ARCS
        undecided |= crowded
        bad &= ~crowded[row]
        if not bad.any():
            break
        row, lo, mid, hi = row[bad], lo[bad], mid[bad], hi[bad]
        chi_lo, chi_mid, chi_hi = chi_lo[bad], chi_mid[bad], chi_hi[bad]
        row = np.concatenate([row, row])
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
        chi_lo, chi_hi = np.concatenate([chi_lo, chi_mid]), np.concatenate([chi_mid, chi_hi])
        mid = 0.5 * (lo + hi)
        with np.errstate(all="ignore"):
            if row.size * (n + 1) <= _DIRECT_TERMS:
                chi_mid, dchi_mid, d2chi_mid = _circle_direct(p[row], mid)
                d2chi_mid = np.abs(d2chi_mid)
            else:
                chi_mid, dchi_mid = (x[:, 0] for x in _horner_circle(p[row], mid[:, None]))
                d2chi_mid = np.full(row.size, np.inf)
        if not np.all(hi > lo):
            undecided[np.unique(row[~(hi > lo)])] = True
    else:
        undecided[np.unique(row)] = True
    inside = change / np.pi
    whole = np.rint(inside)
    if np.any(~undecided & (np.abs(inside - whole) > 0.25)):
        raise AssertionError("the certified argument change is not a multiple of pi")
    return np.where(undecided, -1, n - whole.astype(np.int64))


def _leading_vanishes(coefficients, scale=None):
    """Rows whose leading coefficient is 0 to within rounding: a root at infinity.

    The test of :func:`classify_polynomials` (which calls such a row
    :data:`MARGINAL`), on its own for callers that count roots.

    Parameters
    ----------
    coefficients : ndarray, shape (N, n + 1)
        Real coefficients, highest power first.
    scale : ndarray, shape (N,), optional
        ``max |c_j|`` of each row, if known.

    Returns
    -------
    ndarray of bool, shape (N,)
        Also True for a row that is not finite.
    """
    p = np.asarray(coefficients, dtype=float)
    n = p.shape[1] - 1
    with np.errstate(all="ignore"):
        if scale is None:
            scale = np.max(np.abs(p), axis=1)
        return ~(np.abs(p[:, 0]) > 2 * _U * (n + 1) * _COEFFICIENT_ULPS * scale)


def classify_polynomials(coefficients, *, refine=True):
    """Classify real polynomials by their roots: stable, unstable or marginal.

    The same decision as :func:`classify`, for any polynomials: the float
    Schur-Cohn test decides the rows it decides with a margin of at least
    1e-6 (below degree 48); every other row is decided by the certified
    count of :func:`polynomial_root_counts`.  A row whose leading
    coefficient vanishes to within rounding has a root at infinity (an
    ill-posed loop) and is :data:`MARGINAL`.

    Parameters
    ----------
    coefficients : array_like, shape (..., n + 1)
        Real coefficients, highest power first.
    refine : bool
        As in :func:`classify`.

    Returns
    -------
    ndarray of int8, shape (...)
        :data:`STABLE`, :data:`MARGINAL` or :data:`UNSTABLE`.
    """
    p = np.asarray(coefficients, dtype=float)
    shape = p.shape[:-1]
    p = p.reshape(-1, p.shape[-1])
    n = p.shape[1] - 1
    out = np.full(len(p), MARGINAL, dtype=np.int8)
    scale = np.max(np.abs(p), axis=1)
    live = np.flatnonzero(~_leading_vanishes(p, scale))
    if n == 0:
        out[live] = STABLE
        return out.reshape(shape)
    if refine and n >= _COUNT_ALL_FROM_DELAY:
        close = live
    else:
        close = []
        for rows in chunk_slices(len(live), 8 * (n + 1) * 4):
            index = live[rows]
            stable, margin = schur_cohn(p[index] / scale[index, None])
            out[index] = np.where(stable, STABLE, UNSTABLE)
            if not refine:
                out[index[margin == 0]] = MARGINAL
            else:
                close.append(index[margin < _SCHUR_COHN_SAFE])
        close = np.concatenate(close) if close else np.empty(0, dtype=np.int64)
    if refine and len(close):
        counts = polynomial_root_counts(p[close])
        out[close] = np.where(counts < 0, MARGINAL, np.where(counts == 0, STABLE, UNSTABLE))
    return out.reshape(shape)


def _shaped(codes, shape):
    codes = codes.reshape(shape)
    return int(codes) if codes.ndim == 0 else codes


def is_stable(*, alpha, beta, gamma, d, delta):
    """Whether each point is stable; marginal points are undecided.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    bool or None, or numpy.ma.MaskedArray of bool
        For a single point ``True``, ``False`` or ``None`` (marginal); for
        arrays a masked boolean array, masked where the point is marginal.

    Examples
    --------
    >>> is_stable(alpha=[0.1, 3.0], beta=0.5, gamma=0.0, d=0, delta=0.0025).tolist()
    [True, False]
    """
    code = np.asarray(classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    if code.ndim == 0:
        return None if code == MARGINAL else bool(code == STABLE)
    return np.ma.MaskedArray(code == STABLE, mask=code == MARGINAL)


# --------------------------------------------------------------------------
# Per-point reference at 30 digits (the audit's)


def coefficients_at(*, alpha, beta, gamma, d, delta):
    """Coefficients of chi(z), highest power first, as floats (30-digit evaluation)."""
    return characteristic_polynomial().numeric_coeffs(
        alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)


def unstable_root_count(*, alpha, beta, gamma, d, delta, marginal_tol=1e-12):
    """Number of roots with modulus > 1, or ``None`` when one is marginal."""
    roots = np.roots(coefficients_at(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    mod = np.abs(roots)
    if np.any(np.abs(mod - 1.0) <= marginal_tol):
        return None
    return int(np.count_nonzero(mod > 1.0))


def stable_alpha_intervals(*, beta, gamma, d, delta, alpha_low=-1.0, alpha_high=6.0,
                           n=600, xtol=1e-10):
    """The stable alpha intervals at fixed beta, by a scan and bisection.

    ``alpha`` is scanned on ``n`` points of ``[alpha_low, alpha_high]``;
    each change of stability is refined by bisection on the spectral radius
    (roots of the 30-digit coefficients) to ``xtol``.  It is slow and
    independent of the generated kernels;
    :meth:`symstab.numeric.region.StabilityRegion.alpha_intervals` finds the same
    intervals from the boundary curves, fast and without a scan.

    Returns
    -------
    list of (float, float)
        The stable intervals, in increasing order; empty when none.
    """
    def rho(a):
        # The 30-digit coefficients and numpy's roots, not the generated
        # kernels: the audit uses this as a reference independent of them.
        coeffs = coefficients_at(alpha=float(a), beta=beta, gamma=gamma, d=d, delta=delta)
        return float(np.max(np.abs(np.roots(coeffs)))) - 1.0

    grid = np.linspace(alpha_low, alpha_high, n)
    stable = [rho(a) < 0 for a in grid]
    edges = []
    for k in range(1, n):
        if stable[k] != stable[k - 1]:
            lo, hi = grid[k - 1], grid[k]
            while hi - lo > xtol:
                mid = 0.5 * (lo + hi)
                if (rho(mid) < 0) == stable[k - 1]:
                    lo = mid
                else:
                    hi = mid
            edges.append(0.5 * (lo + hi))
    intervals = []
    start = grid[0] if stable[0] else None
    for edge in edges:
        if start is None:
            start = edge
        else:
            intervals.append((float(start), float(edge)))
            start = None
    if start is not None:
        intervals.append((float(start), float(grid[-1])))
    return intervals
