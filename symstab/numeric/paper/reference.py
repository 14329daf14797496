"""High-precision evaluation of the derived boundary (mpmath).

These functions evaluate the SymPy derivation itself, through ``lambdify``
to mpmath at ``dps`` digits, with ``Gamma = exp(delta)``.  They are the
reference that faster numeric kernels are measured against, and what the
audit uses to reproduce the paper's numbers.
"""

import functools

import mpmath
import sympy as sp

from ..._validate import check_loop
from ...symbolic import model
from ...symbolic.boundary import boundary
from ...symbolic.theta_max import theta_max

__all__ = ["boundary_point", "alpha_max_on_arc", "arc_end"]


@functools.lru_cache(maxsize=None)
def _functions():
    bd = boundary()
    args = (model.theta, model.gamma, model.d, model.delta)
    gamma_sub = {model.Gamma: sp.exp(model.delta)}
    num_a, num_b, den = (e.subs(gamma_sub) for e in
                         (bd.alpha_numerator, bd.beta_numerator, bd.denominator))
    alpha_expr = num_a / den
    return (sp.lambdify(args, [num_a, num_b, den], modules="mpmath"),
            sp.lambdify(args, sp.diff(alpha_expr, model.theta), modules="mpmath"))


def boundary_point(theta, *, gamma, d, delta, dps=30):
    """Return ``(alpha, beta)`` on the boundary at angle ``theta`` (mpmath).

    Parameters
    ----------
    theta : float or mpmath.mpf
        Angle in (0, pi).
    gamma, d, delta
        Virtual mass ratio, delay in samples, ``b T / m``.
    dps : int
        Working precision in decimal digits.
    """
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    values, _ = _functions()
    with mpmath.workdps(dps):
        na, nb, den = values(mpmath.mpf(theta), mpmath.mpf(gamma), d, mpmath.mpf(delta))
        return na / den, nb / den


def arc_end(*, gamma, d, delta, dps=30):
    """Return ``(theta_max, beta)`` where the arc meets alpha = 0 again."""
    t = theta_max(gamma=gamma, d=d, delta=delta, dps=dps)
    if not mpmath.isfinite(t):
        return t, float("nan")
    _, b = boundary_point(t, gamma=gamma, d=d, delta=delta, dps=dps)
    return t, float(b)


def alpha_max_on_arc(*, gamma, d, delta, dps=30, grid=400):
    """The largest alpha along the arc theta in (0, theta_max).

    The arc is sampled on ``grid`` points; the best sample is refined by
    solving d alpha / d theta = 0 with mpmath's Anderson-Bjorck solver on
    the bracketing neighbours.

    Returns
    -------
    (theta, alpha, beta) : tuple of float
        ``nan`` throughout when no arc enters alpha > 0.
    """
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    t_end = theta_max(gamma=gamma, d=d, delta=delta, dps=dps)
    if not mpmath.isfinite(t_end):
        return (float("nan"),) * 3
    _, slope = _functions()
    with mpmath.workdps(dps):
        ts = [mpmath.mpf(t_end) * k / grid for k in range(1, grid)]
        alphas = [boundary_point(t, gamma=gamma, d=d, delta=delta, dps=dps)[0] for t in ts]
        k = max(range(len(ts)), key=lambda i: alphas[i])
        lo = ts[max(k - 1, 0)]
        hi = ts[min(k + 1, len(ts) - 1)]
        f = lambda t: slope(t, mpmath.mpf(gamma), d, mpmath.mpf(delta))  # noqa: E731
        if f(lo) * f(hi) < 0:
            t_star = mpmath.findroot(f, (lo, hi), solver="anderson")
        else:
            t_star = ts[k]
        a, b = boundary_point(t_star, gamma=gamma, d=d, delta=delta, dps=dps)
        return float(t_star), float(a), float(b)
