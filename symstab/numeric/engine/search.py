"""The generic searches of the engine: a grid over the circle, the root bracketer, the maximiser.

* :func:`scan_grid` -- angles that resolve an arc of ``sin(d theta)``;
* :func:`bracketed_root` -- the vectorised Illinois root of many brackets at once;
* :func:`refit_root` -- a root refined from samples of a noisy function around it;
* :func:`zoom_max` -- the maximum of a unimodal-or-not function on an interval, zoomed.
"""

import math

import numpy as np

__all__ = ["scan_grid", "bracketed_root", "refit_root", "zoom_max"]


def scan_grid(d, *, n=None, upper=np.pi):
    """Angles that resolve the arc: geometric near 0, then uniform up to ``upper``.

    The uniform spacing is below a sixteenth of the period of ``sin(d theta)``;
    the geometric part reaches down to ``1e-10`` of the first step, where
    alpha ~ theta**2 may still be tiny but keeps its sign.
    """
    n = n or max(400, 16 * (d + 1))
    step = upper / n
    near_zero = step * np.logspace(-10, -0.25, 40)
    return np.concatenate([near_zero, step * np.arange(1, n + 1)])


def bracketed_root(f, lo, hi, iterations=64, *, indexed=False):
    """Vectorised root of ``f`` in each bracket ``[lo, hi]`` (signs differ at the ends).

    The Illinois variant of regula falsi: superlinear on smooth functions (a
    dozen evaluations where bisection needs sixty), with the bracket kept.
    A bracket stops when it is a few ulps wide.

    Parameters
    ----------
    f : callable
        ``f(x)`` for arrays ``x`` of the brackets' shape; with ``indexed``,
        ``f(x, index)`` for the brackets ``index`` (flat indices) that are
        still open, so that each evaluation costs only what is left (poles
        and slow brackets then no longer set the pace for all).
    lo, hi : array_like
        The brackets (``f`` changes sign between them).
    iterations : int
        Most evaluations per bracket.

    Returns
    -------
    ndarray
        The roots, to a few ulps.
    """
    lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
    shape = lo.shape
    lo, hi = lo.ravel(), hi.ravel()
    everything = np.arange(lo.size)
    if indexed:
        def g(x, index):
            return np.asarray(f(x, index), dtype=float).ravel()
    else:
        def g(x, index):
            if index.size == lo.size:
                return np.asarray(f(x.reshape(shape)), dtype=float).ravel()
            full = 0.5 * (lo + hi)
            full[index] = x
            return np.asarray(f(full.reshape(shape)), dtype=float).ravel()[index]
    flo, fhi = g(lo, everything), g(hi, everything)
    side = np.zeros(lo.size, dtype=np.int8)   # which end was kept last time
    active = everything
    for _ in range(iterations):
        a, b = lo[active], hi[active]
        open_ = (b - a) > 4 * np.spacing(np.maximum(np.abs(a), np.abs(b)))
        active = active[open_]
        if active.size == 0:
            break
        a, b, fa, fb, sd = lo[active], hi[active], flo[active], fhi[active], side[active]
        width = b - a
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            x = b - fb * width / (fb - fa)
        x = np.where(np.isfinite(x), x, a + 0.5 * width)
        # A secant step that rounds onto an end (f there is down to its
        # rounding) goes two ulps inside instead: either that closes the
        # bracket, or the Illinois halving pulls the next steps off that end.
        # (Bisecting there instead costs a step per bit of the bracket.)
        inside = 2 * np.spacing(np.maximum(np.abs(a), np.abs(b)))
        x = np.clip(x, a + inside, b - inside)
        fx = g(x, active)
        same_as_lo = np.sign(fx) == np.sign(fa)
        # Illinois: halve the value at the end that stays, so it cannot stick.
        fb = np.where(same_as_lo & (sd == 1), 0.5 * fb, fb)
        fa = np.where(~same_as_lo & (sd == -1), 0.5 * fa, fa)
        exact = fx == 0
        lo[active] = np.where(same_as_lo | exact, x, a)
        flo[active] = np.where(same_as_lo, fx, fa)
        hi[active] = np.where(same_as_lo & ~exact, b, x)
        fhi[active] = np.where(same_as_lo, fb, fx)
        side[active] = np.where(same_as_lo, 1, -1)
    return (0.5 * (lo + hi)).reshape(shape)


def refit_root(f, root, half_width, points=17):
    """A root of ``f`` re-found as the zero of a straight line fitted around it.

    Where ``f`` is computed with an absolute error floor (a difference of
    larger terms), it is exactly 0, or of either sign, over a stretch of
    arguments around its root, and :func:`bracketed_root` stops anywhere in
    it.  The least-squares line through ``points`` values on ``[root -
    half_width, root + half_width]`` (wide enough for ``f`` to rise above
    its floor there, narrow enough for ``f`` to be straight) averages the
    floor out.  ``root`` is kept where the line is flat, where ``f`` is not
    straight there (the values stray from the line by more than 1e-2 of
    its rise over ``half_width``), or where its zero is not inside that
    stretch.

    Parameters
    ----------
    f : callable
        ``f(x)`` for a 1-D array ``x``.
    root : float
        The root to re-find.
    half_width : float
        Half the stretch fitted.
    points : int
        Values fitted (odd, so ``root`` is the middle one).

    Returns
    -------
    float
    """
    step = np.linspace(-half_width, half_width, points)
    values = np.asarray(f(root + step), dtype=float)
    if not np.all(np.isfinite(values)):
        return root
    (slope, intercept), residuals = np.polyfit(step, values, 1, full=True)[:2]
    rms = math.sqrt(float(residuals[0]) / points) if len(residuals) else 0.0
    # Only a straight f (what is left beside the line is a floor of
    # rounding, not a curve) has the line's zero for its root.
    if slope == 0 or rms > 1e-2 * abs(slope) * half_width \
            or not abs(intercept / slope) < half_width:
        return root
    return float(root - intercept / slope)


def zoom_max(f, a, b, *, rtol, points=33, enough=None):
    """Vectorised search for the maximum of f on each [a, b] by zooming grids.

    Each round evaluates ``f`` on ``points`` evenly spaced points of every
    open bracket at once and keeps the two grid steps around the best one:
    the bracket shrinks ``(points - 1) / 2`` times per call of ``f``, so a
    few calls reach a width that golden section needs dozens for.

    Parameters
    ----------
    f : callable
        ``f(x, index)``: values at ``x`` (shape ``(k, points)``) for the
        brackets ``index`` (shape ``(k,)``, flat indices still open).
    a, b : array_like
        The brackets, ``a < b``.
    rtol : float
        A bracket stops when narrower than ``rtol`` times its larger end's
        modulus (or than ``rtol`` times its first width, next to 0).  Next to a smooth maximum the values of two points ``h``
        apart differ by ``f'' h**2``, below their rounding once ``h`` is
        about ``sqrt(eps)`` of the scale: a finer grid compares noise.
    points : int
        Points per bracket and round, ``>= 3``.
    enough : callable, optional
        ``enough(fx) -> bool array``: a bracket stops at the first point
        where it holds, and that point is returned for it.

    Returns
    -------
    ndarray
        The best point of each bracket's last grid, or the point where
        ``enough`` held.

    Examples
    --------
    >>> x = zoom_max(lambda x, i: -(x - 0.3) ** 2, [0.0], [1.0], rtol=1e-9)
    >>> abs(float(x[0]) - 0.3) < 1e-9
    True
    """
    a, b = np.array(a, dtype=float).ravel(), np.array(b, dtype=float).ravel()
    best = 0.5 * (a + b)
    # Next to 0 the relative width is taken of the first bracket's width.
    floor = rtol * (b - a)
    active = np.arange(a.size)
    grid = np.linspace(0.0, 1.0, points)
    while active.size:
        lo, hi = a[active], b[active]
        x = lo[:, None] + (hi - lo)[:, None] * grid
        fx = np.asarray(f(x, active), dtype=float).reshape(x.shape)
        k = np.argmax(np.where(np.isnan(fx), -np.inf, fx), axis=1)
        rows = np.arange(active.size)
        best[active] = x[rows, k]
        done = np.zeros(active.size, dtype=bool)
        if enough is not None:
            hit = enough(fx)
            done = hit.any(axis=1)
            first = np.argmax(hit, axis=1)
            best[active[done]] = x[rows, first][done]
        a[active] = x[rows, np.maximum(k - 1, 0)]
        b[active] = x[rows, np.minimum(k + 1, points - 1)]
        width = b[active] - a[active]
        done |= width <= np.maximum(rtol * np.maximum(np.abs(a[active]), np.abs(b[active])),
                                    floor[active])
        active = active[~done]
    return best
