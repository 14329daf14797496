"""Exact stability classification by counting characteristic roots.

A parameter point is stable when every root of chi(z) lies strictly inside
the unit circle.  The coefficients are computed from the derivation at 30
digits (so that ``Gamma delta - Gamma + 1 ~ delta**2 / 2`` keeps its digits
for small delta) and the roots by NumPy's companion-matrix eigenvalues.  A
spectral radius within ``marginal_tol`` of 1 is reported as marginal rather
than guessed.
"""

import numpy as np

from .loop import characteristic_polynomial

__all__ = ["coefficients_at", "spectral_radius", "unstable_root_count", "stable_alpha_intervals"]


def coefficients_at(*, alpha, beta, gamma, d, delta):
    """Coefficients of chi(z), highest power first, as floats (30-digit evaluation)."""
    return characteristic_polynomial().numeric_coeffs(
        alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta)


def spectral_radius(*, alpha, beta, gamma, d, delta):
    """Largest modulus of the closed-loop poles at one parameter point."""
    roots = np.roots(coefficients_at(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    return float(np.max(np.abs(roots)))


def unstable_root_count(*, alpha, beta, gamma, d, delta, marginal_tol=1e-12):
    """Number of roots with modulus > 1, or ``None`` when one is marginal."""
    roots = np.roots(coefficients_at(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    mod = np.abs(roots)
    if np.any(np.abs(mod - 1.0) <= marginal_tol):
        return None
    return int(np.count_nonzero(mod > 1.0))


def stable_alpha_intervals(*, beta, gamma, d, delta, alpha_low=-1.0, alpha_high=6.0,
                           n=600, xtol=1e-10):
    """The stable alpha intervals at fixed beta, by root counting.

    ``alpha`` is scanned on ``n`` points of ``[alpha_low, alpha_high]``;
    each change of stability is refined by bisection on the spectral radius
    (mpmath's ``findroot`` with the bisection solver) to ``xtol``.

    Returns
    -------
    list of (float, float)
        The stable intervals, in increasing order; empty when none.
    """
    def rho(a):
        return spectral_radius(alpha=float(a), beta=beta, gamma=gamma, d=d, delta=delta) - 1.0

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
