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

import numpy as np

from ._generated import kernels
from ._validate import check_array, check_delay
from .loop import characteristic_polynomial

__all__ = [
    "STABLE", "MARGINAL", "UNSTABLE", "MARGINAL_TOL",
    "loop_coefficients", "spectral_radius", "schur_cohn", "classify", "is_stable",
    "coefficients_at", "unstable_root_count", "stable_alpha_intervals",
]

#: Codes returned by :func:`classify`.
STABLE, MARGINAL, UNSTABLE = 1, 0, -1
#: A spectral radius within this of 1 is marginal.
MARGINAL_TOL = 1e-12
#: Points whose Schur-Cohn margin ``min |1 - |k_j|||`` is below this are
#: decided by eigenvalues: the reflection coefficients are not the radius, and
#: their rounding grows with ``1 / (1 - k_j**2)``.
_SCHUR_COHN_SAFE = 1e-6
#: Largest batch of companion matrices handed to LAPACK at once (bytes).
_EIG_BATCH_BYTES = 64 * 2**20


def _points(alpha, beta, gamma, d, delta):
    """Validate and broadcast; return (alpha, beta, gamma, delta, d, shape)."""
    arrays = [check_array("alpha", alpha), check_array("beta", beta),
              check_array("gamma", gamma), check_array("delta", delta, low=0.0, low_open=True)]
    d = check_delay(d)
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError as exc:
        raise ValueError(f"alpha, beta, gamma and delta must broadcast together: {exc}") from None
    return (*arrays, d, arrays[0].shape)


def _coefficients(alpha, beta, gamma, d, delta):
    """(..., d + 5) coefficients of chi / delta**2, highest power first."""
    c = kernels.loop_coefficients(alpha, beta, gamma, delta)
    shape = np.broadcast(alpha, beta, gamma, delta).shape
    out = np.zeros(shape + (d + 5,))
    for k in range(3):
        out[..., k] += c[k]
    for k in range(4):
        out[..., d + 1 + k] += c[3 + k]
    return out


def loop_coefficients(*, alpha, beta, gamma, d, delta):
    """Coefficients of ``chi(z) / delta**2``, highest power first.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m > 0``.

    Returns
    -------
    ndarray
        Shape ``broadcast_shape + (d + 5,)``.

    Raises
    ------
    TypeError, ValueError
        For non-real, non-finite or out-of-range parameters.
    """
    alpha, beta, gamma, delta, d, _ = _points(alpha, beta, gamma, d, delta)
    return _coefficients(alpha, beta, gamma, d, delta)


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
        value, slope = _horner(c, roots)
        with np.errstate(divide="ignore", invalid="ignore"):
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

    Parameters are as in :func:`loop_coefficients`.

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
    c = _coefficients(alpha, beta, gamma, d, delta).reshape(-1, d + 5)
    r = _radius(c).reshape(shape)
    return float(r) if r.ndim == 0 else r


def schur_cohn(coefficients):
    """Vectorised Schur-Cohn test of real polynomials (highest power first).

    For ``p(z) = p_n z**n + ... + p_0`` the reflection coefficient is
    ``k = p_0 / p_n``; every root lies in the open unit disk exactly when
    ``|k| < 1`` and the same holds for ``(p(z) - k z**n p(1/z)) / z``, of
    degree ``n - 1``.

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
        with np.errstate(divide="ignore", invalid="ignore"):
            p = q[:, :-1] / q[:, :1]
        p[~active] = 1.0
    return stable, margin


def classify(*, alpha, beta, gamma, d, delta, marginal_tol=MARGINAL_TOL, refine=True):
    """Classify parameter points as stable, unstable or marginal.

    Parameters
    ----------
    alpha, beta, gamma, d, delta
        As in :func:`loop_coefficients`.
    marginal_tol : float
        A spectral radius within this of 1 is :data:`MARGINAL`.
    refine : bool
        Decide the points whose Schur-Cohn margin is below 1e-6 by their
        eigenvalues (the default).  With ``False`` the Schur-Cohn verdict is
        returned as it is (only a margin of exactly 0 is marginal): faster at
        large ``d`` near the boundary, and in the tests it never disagreed
        with the eigenvalues where the margin was positive, but a radius
        within ``marginal_tol`` of 1 is then not recognised.

    Returns
    -------
    int or ndarray of int8
        :data:`STABLE` (1), :data:`MARGINAL` (0) or :data:`UNSTABLE` (-1).

    Examples
    --------
    >>> classify(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=0.0025) == STABLE
    True
    >>> classify(alpha=3.0, beta=0.5, gamma=0.0, d=0, delta=0.0025) == UNSTABLE
    True
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    c = _coefficients(alpha, beta, gamma, d, delta).reshape(-1, d + 5)
    stable, margin = schur_cohn(c)
    out = np.where(stable, STABLE, UNSTABLE).astype(np.int8)
    close = margin < max(_SCHUR_COHN_SAFE, marginal_tol)
    if not refine:
        out[margin == 0] = MARGINAL
    elif np.any(close):
        r = _radius(c[close])
        out[close] = np.where(np.abs(r - 1.0) <= marginal_tol, MARGINAL,
                              np.where(r < 1.0, STABLE, UNSTABLE))
    out = out.reshape(shape)
    return int(out) if out.ndim == 0 else out


def is_stable(*, alpha, beta, gamma, d, delta, marginal_tol=MARGINAL_TOL):
    """Whether each point is stable; marginal points are undecided.

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
    code = np.asarray(classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta,
                               marginal_tol=marginal_tol))
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
    :meth:`symstab.region.StabilityRegion.alpha_intervals` finds the same
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
