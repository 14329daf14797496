"""The boundary arc in floating point: theta_max, the arc's samples, the root bracketer.

The generated kernel ``symstab._generated.kernels.boundary`` evaluates
alpha(theta), beta(theta) to about 1e-14 relative (tests/codegen/test_generated_kernels.py).
Here it is used to sample the arc, and alpha's reduced numerator R to find
where the arc ends:

* :func:`arc_end_angle` -- theta_max, the first root of alpha(theta) in
  (0, pi], isolated with a bound on R'' so that no root is stepped over
  and refined by regula falsi to a few ulps (the float counterpart of the
  30-digit :func:`symstab.symbolic.theta_max.theta_max`);
* :class:`BoundaryCurve` (:class:`symstab.numeric.engine.results.Boundary`) -- the arc from theta = 0 to theta_max, with the
  other pieces of the boundary of the stable region (z = 1 and z = -1,
  straight lines in the alpha-beta plane) where they bound it; built by
  :func:`symstab.numeric.paper.region.boundary_curve`, which finds those pieces in
  the region (so this module does not import the region engine).
"""

import fractions

import numpy as np

from ..._generated import kernels
from ..._validate import check_loop
from ...symbolic.theta_max import (
    first_sign_change,
    reduced_curvature,
    reduced_qr,
    reduced_value_slope,
)
from ..engine.results import Boundary
from ..engine.search import bracketed_root

__all__ = ["arc_end_angle", "minus_one_line", "BoundaryCurve", "KERNEL_BYTES_PER_POINT",
           "KERNEL_CHUNK_BYTES"]


def arc_end_angle(*, gamma, d, delta):
    """theta_max: the first root of alpha(theta) in (0, pi].

    The float counterpart of :func:`symstab.symbolic.theta_max.theta_max`:
    the first positive root of the reduced equation ``R`` (alpha's numerator
    over positive factors), isolated by
    :func:`~symstab.symbolic.theta_max.first_sign_change` -- every cell before
    it proved free of roots by the bound on ``|R''|``, so a narrow dip of alpha
    below zero or a root next to pi is not stepped over -- and refined by
    :func:`bracketed_root` to a few ulps.

    Parameters
    ----------
    gamma : float
        ``M_w / m``.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m >= 0``.

    Returns
    -------
    float
        theta_max; ``pi`` when alpha stays positive up to pi; ``nan`` when
        alpha < 0 just after theta = 0 (``gamma + 1 + delta (d + 1) <= 0``:
        no arc enters alpha > 0), or when ``gamma + 1 + delta (d + 1)`` is
        positive by less than its rounding (``1e-15 (|gamma + 1| + delta
        (d + 1))``).

    Examples
    --------
    >>> round(arc_end_angle(gamma=0.0, d=0, delta=0.00253125), 4)
    1.5725
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    rate = d + 1
    # R'(0) = gamma + 1 + delta (d + 1) decides whether an arc enters
    # alpha > 0; its sign decided exactly (the inputs are binary floats).
    if not fractions.Fraction(gamma) + 1 + fractions.Fraction(delta) * rate > 0:
        return float("nan")
    q, r = reduced_qr(delta)

    eps = np.finfo(float).eps

    def evaluate(t):
        return reduced_value_slope(t, gamma, rate, delta, q, r, sin=np.sin, cos=np.cos, eps=eps)

    slope0 = (gamma + 1) + delta * rate
    slope0_error = 4 * eps * (abs(gamma + 1) + delta * rate)
    if not slope0 > slope0_error:
        # R'(0) > 0 is lost in the rounding of its two terms: no arc to
        # float arithmetic.
        return float("nan")
    cells = _ARC_SCAN_CELLS * rate
    found = first_sign_change(evaluate, lambda k: np.pi * k / cells, cells, slope0=slope0,
                              slope0_error=slope0_error, root_at_end=True,
                              curvature=reduced_curvature(gamma, rate, delta, q, r))
    if found is None:
        return float(np.pi)
    lo, hi = found
    if lo == hi:
        return float(hi)
    return float(bracketed_root(lambda t: evaluate(t)[0], lo, hi))


#: Cells per period of ``sin((d + 1) theta)`` of the scan grid of
#: :func:`arc_end_angle` (halved where the bound on R'' does not prove a cell).
_ARC_SCAN_CELLS = 8


def minus_one_line(*, gamma, d, delta):
    """The z = -1 crossing: ``alpha + 2 beta = c``; returns ``c``.

    chi(-1) / (delta**2 Gamma) = (-1)**d 2 (1 + exp(-delta))
    - (alpha + 2 beta + 4 gamma) delta zoh_gap(delta) (see
    :mod:`symstab.codegen.float_forms`); far away (~ 24 / delta) for small delta,
    and at infinity (``(-1)**d inf``) for delta = 0, where z = -1 is never
    a root.
    """
    gamma, d, delta = check_loop(gamma, d, delta)
    if delta == 0.0:
        return float((-1) ** d * np.inf)
    spread = delta * float(kernels.zoh_gap(delta))
    return float((-1) ** d * 2.0 * (1.0 + np.exp(-delta)) / spread - 4.0 * gamma)


#: Working set of the boundary kernel per point (tracemalloc measured 16
#: floats per point at its peak; twice that as a margin), and the chunk it
#: is run in.
KERNEL_BYTES_PER_POINT = 8 * 32
KERNEL_CHUNK_BYTES = 32 * 2**20


#: Older name of :class:`symstab.numeric.engine.results.Boundary`, the one result type of a boundary.
BoundaryCurve = Boundary

