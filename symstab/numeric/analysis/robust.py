"""Robust regions: the points of a plane stable for every value of uncertain parameters in a box.

The guarantee.  A point ``(x, y)`` is called *robustly stable* over a box
``Q`` of parameter values (and a range of delays) when, for every delay,

1. it is stable at one value of the box (its certified root count,
   :meth:`symstab.Loop.unstable_root_counts`, is 0 at the box's centre);
2. the leading coefficient of the characteristic polynomial does not
   vanish anywhere on the piece of the plane and the box it is certified on;
3. no root reaches the unit circle anywhere: ``chi(exp(j theta); x, y, q)
   != 0`` for every ``theta`` in [0, pi] and every ``q`` in ``Q`` (zero
   exclusion; ``theta`` in [pi, 2 pi] is the conjugate).

The piece of the plane, the box and [0, pi] are connected, so by 2 and 3 the
number of roots outside the circle is the same everywhere on it, and by 1 it
is 0.

Delays.  A range of whole delays (``uncertain={"d": (8, 12)}``) is each of
them.  A range in seconds (``Td``) or with a fractional end (``d = (1.5,
2.25)``) is every delay of the continuum ``(d + eps) T``: it is split by
whole part ``d``, ``eps`` in ``[eps0, eps1]`` within [0, 1] for each (``eps =
1`` is ``d + 1`` samples), and ``eps`` is one more side of the box, halved
like the others (:data:`FRACTION_DEPTH` more times).  The plant then carries
the fraction (the modified z-transform, ``chi = z**d (z P_d) Ve_d + N_eps
Ve_n``), enclosed over an interval of ``eps`` by
:func:`symstab.symbolic.discretize.interval_fractional_zoh` (``N_eps = w L0 +
P_n``: only ``w L0`` depends on ``eps``, so ``z = 1`` stays the integrator's
pole however wide the interval).  Each piece of delays is connected and 1 is
checked at a delay of each, so the guarantee holds for every delay of the
range, not a sample of them.  A fractional nominal delay is a piece of no
width.

How zero exclusion is proved.  The plane is cut into vertical strips ``x``
in ``[x0, x1]``; each strip holds *pieces*, trapezoids whose bottom and top
run straight from an interval of ``y`` at ``x0`` to one at ``x1``; a point
of a piece has a ``t`` in [0, 1] (0 on its bottom, 1 on its top), and
intervals of ``t`` are certified.  Over a sub-box of ``Q`` the
coefficients of ``chi = A0 + x Ax + y Ay`` are enclosed in intervals
(:func:`symstab.symbolic.discretize.interval_zoh` for the plant, interval
arithmetic on the environment's symbolic coefficients, all in powers of ``w
= z - 1``, so that the integrator's pole ``z = 1`` is kept however wide the
box).  Over an interval of ``theta`` each part is enclosed in a disk: its
value and slope at the middle with the interval's midpoint coefficients, a
bound of the second derivative times ``h**2 / 2``, the coefficients' radii,
and a bound on the rounding.  On a cell (piece x ``theta``-interval x
sub-box) the zeros of ``chi`` are enclosed twice (``_excluded``):

* in the strip: ``chi`` is within ``a + b |y|`` of ``P + y Y`` and the
  ``y`` where it may vanish solve a quadratic inequality (``_failing``),
  the strip's width costing ``a`` first order in it;
* in a *capsule* (``_capsules``): the tangent segment of the curve
  where ``chi = 0`` (a 2 x 2 real solve at the middle and its derivative),
  widened by a radius second order in the ``theta``-width, where the map
  ``(x, y) -> x Ax + y Ay`` is well conditioned (not next to ``theta`` = 0
  or pi).

Their ``t`` on the piece, intersected, is where zero exclusion may fail on
the cell.  Where it meets what is still open, the search (branch and bound)
halves the ``theta``-interval or the sub-box, whichever costs more, until
what halving could still remove is within ``rtol`` of the window's height,
or ``theta`` is 1e-12 wide, or the box has been halved :data:`BOX_DEPTH`
times; what is then left is *marked*, and what is marked is *marginal*:
never counted stable.

Where to look.  A strip's pieces join, in order, the intervals of ``y`` its
two edges hold in common over a grid of values of the box (its corners,
centre and midpoints) and every whole delay, or the ends and middle of each
piece of a continuum of delays (the one line engine,
:meth:`symstab.Loop.stable_intervals`): a point of an edge outside them is
unstable at one of those values.  Where the edges hold different numbers
of intervals (a corner, an end of the set) the strip is halved, down to
``rtol`` of the window's width; a strip still uneven then looks only where
its edges overlap.  A point inside a strip outside its pieces is not
examined, so never claimed robust.

The result is a union of trapezoids: an inner approximation of the robust
set whose area converges as the square of the strips' width (the pieces'
sides are chords of the boundary;
:class:`symstab.numeric.engine.results.RobustRegion`).
"""

import collections
import dataclasses
import itertools
import threading

import mpmath
import numpy as np
import sympy as sp
from mpmath.libmp import to_float

from ..._resources import chunk_slices
from ..._validate import (
    check_count,
    check_delay,
    check_progress,
    check_real,
    check_window,
    snap_delay,
    split_delay,
)
from ...symbolic import model
from ...symbolic.discretize import interval_fractional_zoh, interval_product, interval_zoh
from ...symbolic.loop_assembly import poly_coeffs
from ..engine.results import RobustRegion

__all__ = ["robust_region", "BOX_DEPTH", "FRACTION_DEPTH", "MAX_CELLS"]

#: Most halvings of the uncertain box along one branch of the search.
BOX_DEPTH = 10
#: More halvings along a branch when the box has a fraction of a period as a side
#: (a range of delays): a side more to halve.
FRACTION_DEPTH = 4
#: Most cells (strip x y x theta x sub-box) examined in one robust region;
#: what is left then is marginal.
MAX_CELLS = 20_000_000
#: Narrowest theta-interval the search halves to.
_THETA_WIDTH = 1e-12
#: theta-intervals per term of the polynomial at the start.
_THETA_PER_TERM = 8
#: Values per uncertain parameter on the grid that finds the candidates.
_GRID = 3
#: Enclosures kept for the next robust region of the same loop, box and values
#: (:func:`_enclosures_of`): enclosing the sub-boxes is most of a region's work, and
#: ``limits``, another delay or another window ask for the same sub-boxes again.
_KEPT_ENCLOSURES = 4
_ENCLOSURES = collections.OrderedDict()
#: One thread at a time encloses (mpmath's precision is global) or reads the kept ones.
_LOCK = threading.RLock()
#: Most points :func:`_split` asks the line engine for in one round, looking ahead.
_LOOK_AHEAD = 32
#: Digits of the interval arithmetic.
_DIGITS = 30
_EPS = 2.0 ** -52


def _bound(expr, values):
    """An :mod:`mpmath.iv` enclosure of a SymPy expression over intervals of its symbols.

    Walks the expression tree (nothing is compiled or executed): sums,
    products, integer powers, rationals, floats (their decimal value
    enclosed), ``exp`` and ``sqrt``.
    """
    iv = mpmath.iv
    if expr.is_Symbol:
        return values[expr.name]
    if expr.is_Integer:
        return iv.mpf(int(expr))
    if expr.is_Rational:
        return iv.mpf(int(expr.p)) / iv.mpf(int(expr.q))
    if expr.is_Float:
        # The literal's decimal value and its stored binary one (exactly, as
        # a rational), both enclosed.
        exact = sp.Rational(expr)
        binary = iv.mpf(int(exact.p)) / iv.mpf(int(exact.q))
        decimal = iv.mpf(str(expr))
        return iv.mpf([min(binary.a, decimal.a), max(binary.b, decimal.b)])
    if expr == sp.pi:
        return iv.pi
    if expr == sp.E:
        return iv.e
    if expr.is_Add:
        total = iv.mpf(0)
        for term in expr.args:
            total += _bound(term, values)
        return total
    if expr.is_Mul:
        total = iv.mpf(1)
        for term in expr.args:
            total *= _bound(term, values)
        return total
    if expr.is_Pow:
        base, exponent = expr.args
        if exponent.is_Integer:
            b = _bound(base, values)
            n = int(exponent)
            return b ** n if n >= 0 else 1 / b ** -n
        if exponent == sp.Rational(1, 2):
            return iv.sqrt(_bound(base, values))
        return iv.exp(_bound(exponent, values) * iv.log(_bound(base, values)))
    if isinstance(expr, sp.exp):
        return iv.exp(_bound(expr.args[0], values))
    raise TypeError(f"robust regions cannot bound {type(expr).__name__} in the loop's "
                    f"coefficients ({expr})")


def _midpoint_radius(values):
    """Float midpoints and radii enclosing a list of :mod:`mpmath.iv` numbers.

    The ends are rounded to doubles (mpmath's float() rounds towards zero:
    up to an ulp each), so the radius adds 2 eps of their size.
    """
    lo = np.array([to_float(v._mpi_[0]) for v in values])
    hi = np.array([to_float(v._mpi_[1]) for v in values])
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError("the loop's coefficients are not bounded over the box (a division by "
                         "an interval that holds 0, or values too large?)")
    mid = 0.5 * lo + 0.5 * hi
    radius = (np.maximum(hi - mid, mid - lo) * (1 + 4 * _EPS)
              + 2 * _EPS * (np.abs(lo) + np.abs(hi)) + np.where(hi > lo, 5e-324, 0.0))
    return mid, radius


class _Enclosures:
    """Interval coefficients of ``chi = A0 + x Ax + y Ay`` in ``w = z - 1``, per sub-box.

    Sub-boxes are made by halving (:meth:`children`) and enclosed once
    each.  ``mid`` and ``rad`` hold, per sub-box, ``(3 parts, 2 kinds,
    terms)``: the parts ``A0, Ax, Ay``, the kinds the delayed ``Ve_d P_d``
    and direct ``Ve_n P_n`` polynomials, highest power of ``w`` first.
    With a ``fraction`` ``(eps0, eps1)`` of a period, the box has one more
    side, ``eps``, and the kinds are ``Ve_d (z P_d)`` and ``Ve_n N_eps``
    (:func:`~symstab.symbolic.discretize.interval_fractional_zoh`): ``chi``
    over the delays ``(d + eps) T`` for the ``d`` of the shift.
    """

    def __init__(self, loop, x, y, box, fixed, fraction=None):
        self.names = tuple(box)
        self.fixed = fixed
        self.fractional = fraction is not None
        symbols = {str(s): s for s in loop.symbols.values()}
        ve_n, ve_d = loop.environment_parts
        k = loop.environment_delay
        ve_d = list(ve_d)[:len(ve_d) - k]
        w = sp.Dummy("w")
        plane = {symbols[x]: 0, symbols[y]: 0}

        def in_w(coefficients, slope):
            n = len(coefficients) - 1
            expr = sp.Add(*[c * (w + 1) ** (n - i) for i, c in enumerate(coefficients)])
            expr = sp.diff(expr, symbols[slope]) if slope else expr
            expr = sp.expand(expr.subs(plane))
            out = sp.Poly(expr, w).all_coeffs() if expr != 0 else [sp.Integer(0)]
            return [sp.Integer(0)] * (n + 1 - len(out)) + out

        self.environment = [(in_w(ve_d, slope), in_w(ve_n, slope)) for slope in (None, x, y)]
        num, den = sp.fraction(sp.cancel(sp.together(loop.plant)))
        self.plant = (poly_coeffs(num, model.s), poly_coeffs(den, model.s))
        sides = [box[n] for n in self.names] + ([fraction] if self.fractional else [])
        self.boxes = [np.array(sides, dtype=float).reshape(-1, 2)]
        # A box of no width (one value, one fraction of a period) is never halved.
        self.most_depth = BOX_DEPTH + (FRACTION_DEPTH if self.fractional else 0)
        self.depth = [0 if np.any(self.boxes[0][:, 1] > self.boxes[0][:, 0]) else self.most_depth]
        self._children = {}
        self.mid, self.rad = [], []
        self._stacked = None
        self._fractions = {}
        with _LOCK:
            self._enclose(0)

    def _enclose(self, index):
        iv = mpmath.iv
        before = iv.prec
        iv.dps = _DIGITS
        try:
            values = {n: iv.mpf(float(v)) for n, v in self.fixed.items()}
            sides = [iv.mpf([float(lo), float(hi)]) for lo, hi in self.boxes[index]]
            values.update(zip(self.names, sides, strict=False))
            p_n, p_d = self._plant(index, values, sides[-1] if self.fractional else None)
            mids, rads = [], []
            for ve_d, ve_n in self.environment:
                parts = (interval_product([_bound(c, values) for c in ve_d], p_d),
                         interval_product([_bound(c, values) for c in ve_n], p_n))
                pairs = [_midpoint_radius(p) for p in parts]
                mids.append([p[0] for p in pairs])
                rads.append([p[1] for p in pairs])
        finally:
            iv.prec = before
        n_d, n_n = len(mids[0][0]), len(mids[0][1])
        n = max(n_d, n_n)
        mid = np.zeros((3, 2, n))
        rad = np.zeros((3, 2, n))
        for p in range(3):
            for kind, size in ((0, n_d), (1, n_n)):
                mid[p, kind, n - size:] = mids[p][kind]
                rad[p, kind, n - size:] = rads[p][kind]
        self.mid.append(mid)
        self.rad.append(rad)
        self.sizes = (n_d, n_n)

    def _plant(self, index, values, eps):
        """The plant's interval parts over sub-box ``index`` (``values``: its sides'):
        ``(P_n, P_d)``, or ``(N_eps, z P_d)`` over ``eps`` when fractional, the part free
        of ``eps`` kept per box of the other sides (halving ``eps`` alone reuses it)."""
        if not self.fractional:
            return interval_zoh(*[[_bound(c, values) for c in part] for part in self.plant],
                                values["T"])
        key = self.boxes[index][:-1].tobytes()
        if key not in self._fractions:
            self._fractions[key] = interval_fractional_zoh(
                *[[_bound(c, values) for c in part] for part in self.plant], values["T"])
        return self._fractions[key](eps)

    def stacked(self):
        """``(mid, rad)`` of every sub-box enclosed so far, as two arrays (stacked again only
        when sub-boxes were added)."""
        if self._stacked is None or len(self._stacked[0]) != len(self.mid):
            self._stacked = (np.array(self.mid), np.array(self.rad))
        return self._stacked

    def children(self, index):
        """The two halves of sub-box ``index`` (along its relatively widest side), enclosed."""
        with _LOCK:
            return self._halves(index)

    def _halves(self, index):
        if index not in self._children:
            box = self.boxes[index]
            scale = np.maximum(np.abs(box).max(axis=1), 1e-300)
            if self.fractional:
                scale[-1] = 1.0         # eps: in periods (its own size would halve it first)
            width = (box[:, 1] - box[:, 0]) / scale
            side = int(np.argmax(width))
            middle = 0.5 * (box[side, 0] + box[side, 1])
            pair = []
            for part in ((box[side, 0], middle), (middle, box[side, 1])):
                child = box.copy()
                child[side] = part
                self.boxes.append(child)
                self.depth.append(self.depth[index] + 1)
                self._enclose(len(self.boxes) - 1)
                pair.append(len(self.boxes) - 1)
            self._children[index] = tuple(pair)
        return self._children[index]

    def leading(self, shift):
        """Per sub-box and part, the leading coefficient (midpoint, radius) of ``z**shift D + N``."""
        n_d, n_n = self.sizes
        top_d, top_n = shift + n_d - 1, n_n - 1
        n = max(n_d, n_n)
        mid = np.array(self.mid)
        rad = np.array(self.rad)
        lead_mid = np.zeros(mid.shape[:2])
        lead_rad = np.zeros(mid.shape[:2])
        if top_d >= top_n:
            lead_mid += mid[:, :, 0, n - n_d]
            lead_rad += rad[:, :, 0, n - n_d]
        if top_n >= top_d:
            lead_mid += mid[:, :, 1, n - n_n]
            lead_rad += rad[:, :, 1, n - n_n]
        return lead_mid, lead_rad


def _enclosures_of(loop, x, y, box, fixed, fraction=None):
    """The loop's :class:`_Enclosures` over ``box``, kept (:data:`_KEPT_ENCLOSURES`) by what
    they are made of -- the plant, the environment, the plane and the values, not the loop
    object -- with the sub-boxes enclosed so far (each is enclosed the same way whenever it
    is asked for, so a kept one gives the same region); ``fraction`` as :class:`_Enclosures`."""
    key = (sp.srepr(loop.plant), sp.srepr(tuple(loop.environment_parts)),
           loop.environment_delay, x, y, tuple(box.items()), tuple(sorted(fixed.items())),
           fraction)
    with _LOCK:
        if key in _ENCLOSURES:
            _ENCLOSURES.move_to_end(key)
            return _ENCLOSURES[key]
        enclosures = _Enclosures(loop, x, y, box, fixed, fraction)
        _ENCLOSURES[key] = enclosures
        while len(_ENCLOSURES) > _KEPT_ENCLOSURES:
            _ENCLOSURES.popitem(last=False)
        return enclosures


def _parts_on_arc(enclosures, shift, theta, h, box):
    """Each part of ``chi`` on ``theta`` in ``[theta - h, theta + h]``, over sub-box ``box``.

    Returns per cell and part (``A0, Ax, Ay``): the value and the
    ``theta``-slope at ``theta`` (midpoint coefficients), a bound of the
    second ``theta``-derivative, the coefficients' radii summed on the
    interval's largest ``|w|``, and a bound of the rounding of the value.
    Along ``z = exp(j theta)``, ``d/dtheta = j z d/dz``; for ``z**s w**k``
    (``w = z - 1``) twice that is ``s**2 z**s w**k + (s k + k (s + 1))
    z**(s + 1) w**(k - 1) + k (k - 1) z**(s + 2) w**(k - 2)``, bounded with
    ``|w| <= 2 sin(theta_max / 2)``.
    """
    mid, rad = enclosures.stacked()
    mid, rad = mid[box], rad[box]                # (n, 3 parts, 2 kinds, L)
    n_terms = mid.shape[-1]
    k = np.arange(n_terms - 1, -1, -1, dtype=float)
    z = np.exp(1j * theta)
    w = z - 1.0
    om = 2.0 * np.sin(np.minimum(theta + h, np.pi) / 2)[:, None]
    powers = w[:, None] ** k
    slopes = np.zeros_like(powers)
    slopes[:, :-1] = k[:-1] * w[:, None] ** (k[:-1] - 1)
    om_k = om ** k
    om_1 = np.where(k >= 1, om ** np.maximum(k - 1, 0), 0.0)
    om_2 = np.where(k >= 2, om ** np.maximum(k - 2, 0), 0.0)
    om_up = np.maximum(om, 1.0)
    slope_size = np.where(k >= 1, k * om_up ** np.maximum(k - 1, 0), 0.0)
    shape = mid.shape[:2]
    value, slope = np.zeros(shape, dtype=complex), np.zeros(shape, dtype=complex)
    second, coefficient, rounding = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    slope_rounding = np.zeros(shape)
    for kind, s in ((0, float(shift)), (1, 0.0)):
        a = mid[:, :, kind, :]
        rotate = np.exp(1j * s * theta)[:, None] if s else 1.0
        f = rotate * np.einsum("npk,nk->np", a, powers)
        value += f
        slope += 1j * (s * f + rotate * z[:, None] * np.einsum("npk,nk->np", a, slopes))
        absolute = np.abs(a)
        bound = s * s * om_k + (s * k + k * (s + 1)) * om_1 + k * (k - 1) * om_2
        second += np.einsum("npk,nk->np", absolute, bound)
        coefficient += np.einsum("npk,nk->np", rad[:, :, kind, :], om_k)
        # Of the sums, and of exp(j s theta) (an error in its phase s theta).
        rounding += 32 * _EPS * (n_terms + 4) * np.einsum(
            "npk,nk->np", absolute, om_up ** k) * (1.0 + s * (theta + h)[:, None])
        slope_rounding += 32 * _EPS * (n_terms + 4) * np.einsum(
            "npk,nk->np", absolute, s * om_up ** k + slope_size) * (1.0 + s * (theta + h)[:, None])
    return value, slope, second, coefficient, rounding, slope_rounding


def _excluded(enclosures, shift, theta, h, box, piece):
    """The ``t`` of a piece where zero exclusion fails on a cell (piece x theta-interval x sub-box).

    A piece is a trapezoid of the plane: ``x`` in ``[x0, x1]``, ``y =
    lo(x) + t (hi(x) - lo(x))`` with ``t`` in [0, 1] and ``lo``, ``hi``
    straight from ``(lo0, hi0)`` at ``x0`` to ``(lo1, hi1)`` at ``x1``
    (``piece``: a :class:`_Pieces` row per cell).  Two enclosures of the
    points where ``chi`` may vanish on the cell, both sound; what is
    returned is in both:

    * the strip's (``_failing``): with ``P = A0 + xc Ax`` and ``Y =
      Ay`` at the middle of the ``theta``-interval, ``chi`` lies within ``a
      + b |y|`` of ``P + y Y`` on the cell, ``a`` and ``b`` summing what
      the ``theta``-width, the coefficients' radii, the strip's width and
      the rounding cost, so it cannot vanish where ``|P + y Y| > a + b
      |y|``; what the strip's width costs is first order in it;
    * the capsule's (``_capsules``): the zeros lie within ``rho`` of
      a segment of the zero curve's tangent, ``rho`` second order in the
      ``theta``-width; it does not exist where the real map ``(x, y) ->
      x Ax + y Ay`` is nearly singular (``theta`` next to 0 or pi).

    The narrower of the two leads the search: what the ``theta``-width
    and the coefficients' radii cost (to choose which to halve) and how much
    of the set halving could still remove, in ``t`` (the capsule's:
    ``rho``'s share; the strip's: the set's width in ``y`` beyond what the
    strip's width and the rounding cost, which no halving removes, over the
    piece's height).

    Returns ``(pieces, theta_cost, box_cost, reducible)``: the set as
    intervals of ``t`` (empty: lo > hi), the two costs (comparable with
    each other only) and what halving could remove.
    """
    value, slope, second, coefficient, rounding, slope_rounding = _parts_on_arc(
        enclosures, shift, theta, h, box)
    xc, hx = 0.5 * (piece.x0 + piece.x1), 0.5 * (piece.x1 - piece.x0)
    h2 = 0.5 * h * h
    P = value[:, 0] + xc * value[:, 1]
    Y = value[:, 2]
    ax = np.abs(xc)
    theta_a = h * np.abs(slope[:, 0] + xc * slope[:, 1]) + h2 * (second[:, 0] + ax * second[:, 1])
    theta_b = h * np.abs(slope[:, 2]) + h2 * second[:, 2]
    box_a = coefficient[:, 0] + ax * coefficient[:, 1]
    box_b = coefficient[:, 2]
    # |Ax| anywhere on the cell, times the strip's half-width.
    strip_a = hx * (np.abs(value[:, 1]) + h * np.abs(slope[:, 1]) + h2 * second[:, 1]
                    + coefficient[:, 1])
    round_a = rounding[:, 0] + (ax + hx) * rounding[:, 1]
    round_b = rounding[:, 2]
    strip_y = _failing(P, Y, theta_a + box_a + strip_a + round_a, theta_b + box_b + round_b)
    # What no halving removes: the strip's width times |Ax| at the cell's middle (its
    # theta-width and radii are the halvings' to remove), and the rounding.
    fixed_y = _failing(P, Y, hx * np.abs(value[:, 1]) + round_a, round_b)
    strip = [piece.to_t(lo, hi) for lo, hi in strip_y]
    y_lo = np.minimum(piece.lo0, piece.lo1)
    y_hi = np.maximum(piece.hi0, piece.hi1)
    height = piece.height
    with np.errstate(invalid="ignore", over="ignore"):
        reducible = np.nan_to_num((_covered(strip_y, y_lo, y_hi) - _covered(fixed_y, y_lo, y_hi))
                                  / height, nan=np.inf)
    # The costs where they are largest on the part of the piece that matters.
    far = np.zeros(len(P))
    for lo, hi in strip_y:
        lo, hi = np.maximum(lo, y_lo), np.minimum(hi, y_hi)
        far = np.where(lo <= hi, np.maximum(far, np.maximum(np.abs(lo), np.abs(hi))), far)
    theta_cost = (theta_a + far * theta_b) / height
    box_cost = (box_a + far * box_b) / height

    valid, t_lo, t_hi, rho_theta, rho_box = _capsules(
        value, slope, second, coefficient, rounding, slope_rounding, h, piece)
    # The capsule leads where it is the narrower on the piece (next to theta
    # = 0 or pi, where it fattens as 1 / sigma, the strip's may be).
    lead = valid & (_covered([(t_lo, t_hi)], 0.0, 1.0) <= _covered(strip, 0.0, 1.0))
    pieces = [(np.where(valid, np.maximum(lo, t_lo), lo), np.where(valid, np.minimum(hi, t_hi), hi))
              for lo, hi in strip]
    theta_cost = np.where(lead, rho_theta, theta_cost)
    box_cost = np.where(lead, rho_box, box_cost)
    reducible = np.where(lead, rho_theta + rho_box, reducible)
    return pieces, theta_cost, box_cost, reducible


def _covered(pairs, lo, hi):
    """Per cell, how much of ``[lo, hi]`` the intervals ``pairs`` cover (their overlaps counted
    again)."""
    return sum(np.maximum(np.minimum(b, hi) - np.maximum(a, lo), 0.0) for a, b in pairs)


def _capsules(value, slope, second, coefficient, rounding, slope_rounding, h, piece):
    """Per cell, the ``t`` of the piece within ``rho`` of the zero curve's tangent segment.

    With the midpoint coefficients, ``chi(v, theta) = a0(theta) +
    M(theta) v`` for ``v = (x, y)``, ``M`` the real 2 x 2 map of the
    complex ``Ax, Ay``.  At the middle ``theta_c`` of the interval,
    ``v*`` solves ``chi = 0`` and ``v'`` its ``theta``-derivative; along
    ``v_L(u) = v* + u v'`` (``|u| <= h``), ``g(u) = chi(v_L(u), theta_c +
    u)`` is bounded by ``G = |g(0)| + h |g'(0)| + h**2 / 2 sup |g''|``
    (``g''  = a0'' + M'' v_L + 2 M' v'``; ``g(0)`` and ``g'(0)`` are
    rounding, evaluated and bounded).  A zero ``v`` of the true ``chi``
    (coefficients within ``c0 + c1 |x| + c2 |y|`` of the midpoint ones)
    at ``theta_c + u`` satisfies ``|M(theta) (v - v_L(u))| <= G + c0 + c1
    |x| + c2 |y|``, and ``|M(theta) e| >= sigma |e|`` with ``sigma`` the
    smallest singular value of ``M(theta_c)`` less ``h sup |M'|`` and the
    rounding, so ``|v - v_L(u)| <= rho = (G + c0 + c1 X + c2 Y) / (sigma
    - c1 - c2)`` (``X, Y`` bounds of ``|x|, |y|`` on the segment): the
    zeros lie in the capsule (segment ``v* +- h v'`` widened by ``rho``).

    Its ``t`` on the piece: the segment is clipped to ``x`` in ``[x0 -
    rho, x1 + rho]``; ``t`` is monotone along it (a ratio of affine
    functions), so its range is that of the ends, widened by ``rho`` times
    a bound of ``|grad t|``.

    Returns ``(valid, t_lo, t_hi, rho_theta, rho_box)``: where a capsule
    exists (``sigma > c1 + c2``), its ``t``-range (empty: lo > hi), and
    what the ``theta``-width and the coefficients' radii add to the range.
    """
    a0, cx, cy = value[:, 0], value[:, 1], value[:, 2]
    s0, sx, sy = slope[:, 0], slope[:, 1], slope[:, 2]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        det = cx.real * cy.imag - cx.imag * cy.real
        det_error = 4 * _EPS * (np.abs(cx.real * cy.imag) + np.abs(cx.imag * cy.real))

        def solve(rhs):
            return ((rhs.real * cy.imag - cy.real * rhs.imag) / det,
                    (cx.real * rhs.imag - rhs.real * cx.imag) / det)

        xs, ys = solve(-a0)
        dx, dy = solve(-(s0 + xs * sx + ys * sy))
        r0 = np.abs(a0 + xs * cx + ys * cy) + rounding[:, 0] + np.abs(xs) * rounding[:, 1] \
            + np.abs(ys) * rounding[:, 2] + 8 * _EPS * (np.abs(a0) + np.abs(xs * cx)
                                                        + np.abs(ys * cy))
        r1 = (np.abs(s0 + xs * sx + ys * sy + dx * cx + dy * cy) + slope_rounding[:, 0]
              + np.abs(xs) * slope_rounding[:, 1] + np.abs(ys) * slope_rounding[:, 2]
              + np.abs(dx) * rounding[:, 1] + np.abs(dy) * rounding[:, 2]
              + 8 * _EPS * (np.abs(s0) + np.abs(xs * sx) + np.abs(ys * sy) + np.abs(dx * cx)
                            + np.abs(dy * cy)))
        X, Y = np.abs(xs) + h * np.abs(dx), np.abs(ys) + h * np.abs(dy)
        # |Ax'|, |Ay'| anywhere on the interval.
        d1 = np.abs(sx) + slope_rounding[:, 1] + h * second[:, 1]
        d2 = np.abs(sy) + slope_rounding[:, 2] + h * second[:, 2]
        g2 = second[:, 0] + X * second[:, 1] + Y * second[:, 2] + 2 * (
            d1 * np.abs(dx) + d2 * np.abs(dy))
        G = r0 + h * r1 + 0.5 * h * h * g2
        # In the scaled (x / ux, y / uy) the map's columns have length 1 at
        # theta_c; sigma is its smallest singular value anywhere on the cell.
        ux, uy = 1.0 / np.abs(cx), 1.0 / np.abs(cy)
        sigma = ((np.abs(det) * ux * uy - det_error * ux * uy) / (np.sqrt(2.0) * (1 + 8 * _EPS))
                 - np.hypot(rounding[:, 1] * ux, rounding[:, 2] * uy)
                 - h * np.hypot(d1 * ux, d2 * uy))
        c0, c1, c2 = coefficient[:, 0], coefficient[:, 1], coefficient[:, 2]
        denominator = sigma - c1 * ux - c2 * uy
        rho_theta = G / denominator
        rho_box = (c0 + c1 * X + c2 * Y) / denominator
        rho = rho_theta + rho_box
        # A zero is within (ux rho, uy rho) of the segment, in x and in y.
        rx, ry = ux * rho, uy * rho
        valid = (denominator > 0) & np.isfinite(rx) & np.isfinite(ry) & np.isfinite(xs) \
            & np.isfinite(ys) & np.isfinite(dx) & np.isfinite(dy)
        # The segment v* + s h v' (|s| <= 1) clipped to x in [x0 - rx, x1 + rx].
        ex, ey = h * dx, h * dy
        a, b = piece.x0 - rx, piece.x1 + rx
        inside = (xs >= a) & (xs <= b)
        s_a, s_b = (a - xs) / ex, (b - xs) / ex
        moving = np.abs(ex) > 0
        s_lo = np.maximum(np.where(moving, np.minimum(s_a, s_b), np.where(inside, -1.0, np.inf)),
                          -1.0)
        s_hi = np.minimum(np.where(moving, np.maximum(s_a, s_b), np.where(inside, 1.0, -np.inf)),
                          1.0)
        meets = s_lo <= s_hi
        s_lo, s_hi = np.where(meets, s_lo, 0.0), np.where(meets, s_hi, 0.0)
        lo_slope, height_slope = piece.lo_slope, piece.height_slope
        floor = np.minimum(piece.hi0 - piece.lo0, piece.hi1 - piece.lo1) \
            - rx * np.abs(height_slope)
        ends = []
        for s in (s_lo, s_hi):
            px, py = xs + s * ex, ys + s * ey
            above = py - (piece.lo0 + lo_slope * (px - piece.x0))
            ends.append((above, above / (piece.hi0 - piece.lo0 + height_slope * (px - piece.x0))))
        reach = np.maximum(np.abs(ends[0][0]), np.abs(ends[1][0])) + ry + rx * np.abs(lo_slope)
        # |t(v) - t(q)| for |x_v - x_q| <= rx, |y_v - y_q| <= ry, per unit of rho.
        lipschitz = (uy + ux * (np.abs(lo_slope) + reach / floor * np.abs(height_slope))) / floor
        t_lo = np.minimum(ends[0][1], ends[1][1]) - rho * lipschitz
        t_hi = np.maximum(ends[0][1], ends[1][1]) + rho * lipschitz
        t_lo, t_hi = t_lo - 1e-9 * (1 + np.abs(t_lo)), t_hi + 1e-9 * (1 + np.abs(t_hi))
        valid &= (floor > 0) & np.isfinite(t_lo) & np.isfinite(t_hi)
        t_lo = np.where(meets, t_lo, np.inf)
        t_hi = np.where(meets, t_hi, -np.inf)
        scale = np.where(np.isfinite(lipschitz), lipschitz, 0.0)
    return valid, t_lo, t_hi, rho_theta * scale, rho_box * scale


def _failing(P, Y, a, b):
    """``{y : |P + y Y| <= a + b |y|}`` per cell, as four intervals ``(lo, hi)`` (empty: lo > hi).

    On ``y >= 0`` (sign +1) and ``y <= 0`` (sign -1) the inequality is
    ``f(y) = A y**2 + B y + c <= 0`` with ``A = |Y|**2 - b**2``, ``B = 2
    (Re(P conj Y) - sign a b)``, ``c = |P|**2 - a**2``.  Where ``A > 0``
    (beyond its rounding) it holds between the roots; elsewhere (``A``
    taken below 0, which only adds to the set) outside them, or everywhere
    without real roots.  Where ``A > 0`` the discriminant is computed as
    ``4 (a**2 |Y|**2 + b**2 |P|**2 - 2 sign a b Re(P conj Y) - Im(P conj
    Y)**2)``, which does not cancel where ``P`` and ``Y`` are nearly
    parallel (at a root's crossing; ``B**2 - 4 A c`` there is rounding
    noise), and taken at the top of its rounding (the set can only grow);
    elsewhere at the bottom.  The roots are then moved outwards by 1e-7 of
    their size (a double root's ends move by sqrt(eps) of it).
    """
    Y2, P2 = np.abs(Y) ** 2, np.abs(P) ** 2
    A = Y2 - b * b
    c = P2 - a * a
    product = P * np.conj(Y)
    re, im = np.real(product), np.imag(product)
    convex = A > 8 * _EPS * (Y2 + b * b)
    A = np.where(convex, A, np.minimum(A, -1e-300))
    pieces = []
    for sign in (1.0, -1.0):
        B = 2 * (re - sign * a * b)
        with np.errstate(over="ignore", invalid="ignore"):
            quarter = a * a * Y2 + b * b * P2 - 2 * sign * a * b * re - im * im
            above = quarter + 16 * _EPS * (a * a * Y2 + b * b * P2 + 2 * a * b * np.abs(re)
                                            + im * im)
            disc = B * B - 4 * A * c
            below = disc - 16 * _EPS * (B * B + 4 * np.abs(A * c))
            use = np.where(convex, 4 * above, below)
        real = np.where(convex, use >= 0, use > 0)
        root = np.sqrt(np.where(real, use, 0.0))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            r1 = np.minimum((-B - root) / (2 * A), (-B + root) / (2 * A))
            r2 = np.maximum((-B - root) / (2 * A), (-B + root) / (2 * A))
            slack = np.nan_to_num(1e-7 * (np.abs(r1) + np.abs(r2)), posinf=np.inf) + 1e-300
        half = (0.0, np.inf) if sign > 0 else (-np.inf, 0.0)
        # A > 0: [r1, r2] where real, else nothing.
        inner_lo = np.where(convex & real, r1 - slack, np.inf)
        inner_hi = np.where(convex & real, r2 + slack, -np.inf)
        # A <= 0: (-inf, r1] and [r2, inf) where real, else the whole line.
        left_hi = np.where(~convex, np.where(real, r1 + slack, np.inf), -np.inf)
        right_lo = np.where(~convex, np.where(real, r2 - slack, -np.inf), np.inf)
        for lo, hi in ((inner_lo, inner_hi), (np.full(P.shape, -np.inf), left_hi),
                       (right_lo, np.full(P.shape, np.inf))):
            lo, hi = np.maximum(np.nan_to_num(lo, nan=-np.inf), half[0]), np.minimum(
                np.nan_to_num(hi, nan=np.inf), half[1])
            pieces.append((lo, hi))
    return pieces


class _Columns:
    """A dataclass of equally long arrays, one row per item."""

    def take(self, keep):
        """The rows ``keep`` (an index array or a mask)."""
        return type(self)(*(getattr(self, f.name)[keep] for f in dataclasses.fields(self)))


@dataclasses.dataclass
class _Pieces(_Columns):
    """Trapezoids of the plane: ``x`` in ``[x0, x1]``, ``y`` from ``lo`` to ``hi``, each straight
    from its value at ``x0`` (``lo0``, ``hi0``) to that at ``x1``; a point's ``t`` is where it
    lies between them (0 on ``lo``, 1 on ``hi``)."""

    x0: np.ndarray
    x1: np.ndarray
    lo0: np.ndarray
    hi0: np.ndarray
    lo1: np.ndarray
    hi1: np.ndarray

    def _slope(self, a, b):
        width = self.x1 - self.x0
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(width > 0, (b - a) / width, 0.0)

    @property
    def lo_slope(self):
        return self._slope(self.lo0, self.lo1)

    @property
    def height_slope(self):
        return self._slope(self.hi0 - self.lo0, self.hi1 - self.lo1)

    @property
    def height(self):
        return np.maximum(self.hi0 - self.lo0, self.hi1 - self.lo1)

    def to_t(self, lo, hi):
        """The ``t``-range of the rectangles ``[x0, x1] x [lo, hi]`` (empty where lo > hi).

        ``t`` is increasing in ``y`` and monotone in ``x`` (a ratio of
        affine functions): its extremes are at the corners.
        """
        with np.errstate(invalid="ignore", over="ignore"):
            corners = [(y - base) / (top - base) for y in (lo, hi)
                       for base, top in ((self.lo0, self.hi0), (self.lo1, self.hi1))]
            t_lo, t_hi = np.minimum.reduce(corners), np.maximum.reduce(corners)
            # Each end moved out by 1e-12 of its size (the rounding).
            t_lo = t_lo - 1e-12 * (1 + np.abs(t_lo))
            t_hi = t_hi + 1e-12 * (1 + np.abs(t_hi))
        empty = (lo > hi) | np.isnan(t_lo) | np.isnan(t_hi)
        return np.where(empty, np.inf, t_lo), np.where(empty, -np.inf, t_hi)

    def ends(self, p, t_lo, t_hi):
        """``(lo0, hi0, lo1, hi1)`` of piece ``p`` between ``t_lo`` and ``t_hi``."""
        lo0, lo1 = float(self.lo0[p]), float(self.lo1[p])
        d0, d1 = float(self.hi0[p]) - lo0, float(self.hi1[p]) - lo1
        return (lo0 + t_lo * d0, lo0 + t_hi * d0, lo1 + t_lo * d1, lo1 + t_hi * d1)


@dataclasses.dataclass
class _Cells(_Columns):
    """Cells of the search: a piece (``strip``: its index), a theta-interval, a sub-box."""

    strip: np.ndarray
    t0: np.ndarray
    t1: np.ndarray
    box: np.ndarray

    @staticmethod
    def join(parts):
        return _Cells(*(np.concatenate([getattr(p, f.name) for p in parts])
                        for f in dataclasses.fields(_Cells)))

    def __len__(self):
        return len(self.strip)


def _merge(intervals):
    """Sorted, disjoint union of a list of (lo, hi)."""
    out = []
    for lo, hi in sorted(intervals):
        if out and lo <= out[-1][1]:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return [(a, b) for a, b in out]


def _subtract(intervals, removed):
    """``intervals`` less the union ``removed`` (both lists of (lo, hi); removed merged)."""
    out = []
    for lo, hi in intervals:
        start = lo
        for a, b in removed:
            if b <= start or a >= hi:
                continue
            if a > start:
                out.append((start, a))
            start = max(start, b)
        if start < hi:
            out.append((start, hi))
    return out


def _span_table(open_spans):
    """The pieces' open spans as two arrays ``(lo, hi)``, a row per piece (its index), a column
    per span (empty: ``inf, -inf``): built once per round of the search, read by :func:`_clip`."""
    most = max((len(v) for v in open_spans.values()), default=0)
    size = max(open_spans, default=-1) + 1
    lo, hi = np.full((size, most), np.inf), np.full((size, most), -np.inf)
    rows = [(s, j, a, b) for s, spans in open_spans.items() for j, (a, b) in enumerate(spans)]
    if rows:
        s, j, a, b = zip(*rows, strict=True)
        lo[s, j], hi[s, j] = a, b
    return lo, hi


def _clip(strips, pieces, table):
    """The pieces' parts in each cell's strip's open spans (``table``, :func:`_span_table`): a
    list of ``(lo, hi)`` arrays (empty: lo > hi)."""
    span_lo, span_hi = table[0][strips], table[1][strips]
    return [(np.maximum(lo, span_lo[:, j]), np.minimum(hi, span_hi[:, j]))
            for lo, hi in pieces for j in range(span_lo.shape[1])]


def _mark(marked, strips, parts):
    """Add every non-empty part to its strip's marked list, and merge the lists that grew."""
    touched = set()
    for lo, hi in parts:
        some = lo <= hi
        for s, a, b in zip(strips[some], lo[some], hi[some], strict=True):
            marked[int(s)].append((float(a), float(b)))
            touched.add(int(s))
    for s in touched:
        marked[s] = _merge(marked[s])
    return touched


def _certify(enclosures, shift, geometry, candidates, tol, budget):
    """Branch and bound over theta and the box: ``(marked, examined, exhausted)``.

    Each cell (piece x theta-interval x sub-box) excludes zero for every
    ``t`` of its piece (``geometry``, :class:`_Pieces`) outside a few
    intervals (``_excluded``).  A cell whose intervals miss the piece's
    open ``t`` (``candidates``) is done; one that meets them is halved in
    ``theta`` or the box (whichever costs more), until what the halvings
    can remove is within ``tol`` (per piece, in ``t``), or nothing is left
    to halve: then the intervals, clipped to the candidates, are *marked*.
    ``marked[piece]`` (merged) is where zero exclusion did not close; the
    rest of the candidates is certified.
    """
    n_terms = shift + enclosures.mid[0].shape[-1]
    n_theta = max(16, _THETA_PER_TERM * n_terms)
    edges = np.linspace(0.0, np.pi, n_theta + 1)
    marked = {s: [] for s in candidates}
    strips = np.array(sorted(candidates), dtype=np.int64)
    if not len(strips):
        return marked, 0, False
    cells = _Cells(np.repeat(strips, n_theta), np.tile(edges[:-1], len(strips)),
                   np.tile(edges[1:], len(strips)), np.zeros(n_theta * len(strips), dtype=np.int64))
    examined = 0
    per_cell = 8 * 16 * 6 * enclosures.mid[0].shape[-1]
    open_spans = {s: _subtract(spans, marked[s]) for s, spans in candidates.items()}
    while len(cells):
        table = _span_table(open_spans)
        if examined + len(cells) > budget:
            # Out of budget: whatever the cells left could still reach is marginal.
            for s in np.unique(cells.strip):
                marked[int(s)] = _merge(marked[int(s)] + open_spans[int(s)])
            return {s: _merge(v) for s, v in marked.items()}, examined, True
        examined += len(cells)
        found = []
        for part in chunk_slices(len(cells), per_cell):
            c = cells.take(part)
            theta, h = 0.5 * (c.t0 + c.t1), 0.5 * (c.t1 - c.t0)
            pieces, theta_cost, box_cost, reducible = _excluded(
                enclosures, shift, theta, h, c.box, geometry.take(c.strip))
            meets = np.zeros(len(c), dtype=bool)
            for lo, hi in _clip(c.strip, pieces, table):
                meets |= lo <= hi
            if not meets.any():
                continue
            found.append((c.take(meets), [(lo[meets], hi[meets]) for lo, hi in pieces],
                          theta_cost[meets], box_cost[meets], reducible[meets]))
        if not found:
            break
        c = _Cells.join([f[0] for f in found])
        pieces = [tuple(np.concatenate([f[1][k][j] for f in found]) for j in range(2))
                  for k in range(len(found[0][1]))]
        theta_cost, box_cost, reducible = (np.concatenate([f[k] for f in found]) for k in (2, 3, 4))
        parts = _clip(c.strip, pieces, table)
        left = np.zeros(len(c))
        with np.errstate(over="ignore", invalid="ignore"):
            for lo, hi in parts:
                left += np.maximum(hi - lo, 0.0)
        meets = left > 0
        c, theta_cost, box_cost, left = c.take(meets), theta_cost[meets], box_cost[meets], left[meets]
        reducible = reducible[meets]
        parts = [(lo[meets], hi[meets]) for lo, hi in parts]
        can_theta = (c.t1 - c.t0) > _THETA_WIDTH
        can_box = np.array(enclosures.depth)[c.box] < enclosures.most_depth
        # Done when what is left open, or what halving could still remove,
        # is within the resolution, or the width that costs more cannot be
        # halved again (halving the other would not close the cell).
        theta_first = theta_cost >= box_cost
        done = ((left <= tol[c.strip]) | (reducible <= tol[c.strip])
                | np.where(theta_first, ~can_theta, ~can_box))
        for s in _mark(marked, c.strip[done], [(lo[done], hi[done]) for lo, hi in parts]):
            open_spans[s] = _subtract(candidates[s], marked[s])
        split_theta = ~done & theta_first
        split_box = ~done & ~split_theta
        children = []
        pick = c.take(split_theta)
        if len(pick):
            middle = 0.5 * (pick.t0 + pick.t1)
            children += [dataclasses.replace(pick, t1=middle), dataclasses.replace(pick, t0=middle)]
        pick = c.take(split_box)
        if len(pick):
            # Each sub-box halved once, however many cells it holds.
            boxes, where = np.unique(pick.box, return_inverse=True)
            pairs = np.array([enclosures.children(int(b)) for b in boxes])[where.ravel()]
            children += [dataclasses.replace(pick, box=pairs[:, 0]),
                         dataclasses.replace(pick, box=pairs[:, 1])]
        if not children:
            break
        cells = _Cells.join(children)
    return {s: _merge(v) for s, v in marked.items()}, examined, False


def _grid(box):
    """The values of the box the candidates are found at: corners, centre, midpoints."""
    axes = [np.linspace(lo, hi, _GRID) if hi > lo else np.array([lo]) for lo, hi in box.values()]
    return [dict(zip(box, point, strict=True)) for point in itertools.product(*axes)]


@dataclasses.dataclass(frozen=True)
class _DelayPiece:
    """The delays ``(d + eps) T`` of one whole part ``d``, ``eps`` in ``fraction = (eps0, eps1)``
    (``0 <= eps0 <= eps1 <= 1``; ``eps = 1`` is ``d + 1`` samples), every one of them; or, with
    ``fraction`` None, the whole delay ``d`` alone."""

    d: int
    fraction: tuple = None

    @property
    def samples(self):
        """The delays in samples the candidates are found at: ``d``, or the ends and middle."""
        if self.fraction is None:
            return (self.d,)
        low, high = self.fraction
        return tuple(sorted({self.d + low, self.d + 0.5 * (low + high), self.d + high}))

    @property
    def middle(self):
        """The delay in samples the root counts are taken at."""
        return self.samples[len(self.samples) // 2]


def _delay_pieces(low, high, name):
    """Every delay from ``low`` to ``high`` samples, as :class:`_DelayPiece` (one per whole part).

    The ends are first taken as :func:`~symstab._validate.snap_delay` does
    (within 1e-9 of a whole number, that number); an end that is not whole is
    then moved out by a few units of rounding (the ratio ``Td / T`` of two
    floats), so that the pieces hold the range given.
    """
    low, high = (float(v) for v in snap_delay([low, high]))
    split_delay(high, name=name)        # within SYMSTAB_MAX_DELAY
    if low == high:
        d, eps = split_delay(low, name=name)
        return (_DelayPiece(d, None if eps is None else (float(eps), float(eps))),)
    low = low if low.is_integer() else max(low - 4 * _EPS * low, np.floor(low))
    high = high if high.is_integer() else min(high + 4 * _EPS * high, np.ceil(high))
    return tuple(_DelayPiece(d, (max(low - d, 0.0), min(high - d, 1.0)))
                 for d in range(int(np.floor(low)), int(np.ceil(high))))


def _check_uncertain(loop, uncertain, axes):
    """``(box, delay)``: the continuous parameters' (lo, hi), and the delay range as given,
    ``("d" or "Td", (lo, hi))`` (None: none), checked."""
    if not isinstance(uncertain, dict) or not uncertain:
        raise TypeError(f"uncertain must be a non-empty dict {{name: (low, high)}}, got "
                        f"{uncertain!r}")
    box, delay = {}, None
    for name, spec in uncertain.items():
        where = f"uncertain[{name!r}]"
        if name not in loop.parameters and name != "Td":
            raise ValueError(f"uncertain: {name!r} is not a parameter of the loop (its "
                             f"parameters: {', '.join(loop.parameters)}; Td: the delay in "
                             f"seconds)")
        if name in axes:
            raise ValueError(f"uncertain: {name} is an axis of the ({axes[0]}, {axes[1]}) plane")
        if not isinstance(spec, (tuple, list)) or len(spec) != 2:
            raise TypeError(f"{where} must be (low, high), got {spec!r}")
        if name in ("d", "Td"):
            if delay is not None:
                raise ValueError("uncertain: give the delay range once, as d (samples) or Td "
                                 "(seconds)")
            low, high = (check_real(f"{where} bounds", v, low=0.0) for v in spec)
            if not low <= high:
                raise ValueError(f"{where}: (low, high) must have low <= high, got {spec!r}")
            whole = name == "d" and low.is_integer() and high.is_integer()
            delay = (name, (int(low), int(high)) if whole else (low, high))
            continue
        low, high = (check_real(f"{where} bounds", v) for v in spec)
        if not low <= high:
            raise ValueError(f"{where}: (low, high) must have low <= high, got {spec!r}")
        if name == "T" and low <= 0:
            raise ValueError(f"{where}: the period must be positive, got {spec!r}")
        box[name] = (float(low), float(high))
    return box, delay


def _delays(loop, values, box, delay):
    """``(values, pieces)``: ``values`` without the delay, and the delays to certify.

    A range ``delay`` (:func:`_check_uncertain`): ``d`` with whole ends,
    each whole delay in it; ``d`` with a fractional end, or ``Td`` (seconds,
    over the period), every delay in it (:func:`_delay_pieces`).  Else the one
    delay given (``d``, else ``Td``) or the loop's.  A delay in seconds over an
    uncertain period is refused: its fraction of a period would vary over the box.
    """
    values = dict(values)
    given = {k: values.pop(k) for k in ("d", "Td") if k in values}
    shown = given or {k: v for k, v in loop.defaults.items() if k in ("d", "Td")}
    if delay is not None:
        name, (low, high) = delay
        if name == "d" and isinstance(low, int):
            check_delay(high, name="uncertain['d']'s high end")
            return values, tuple(_DelayPiece(d) for d in range(low, high + 1))
    elif "d" in shown:
        name, low = "d", check_real("d", shown["d"], low=0.0)
        high = low
    elif "Td" in shown:
        name, low = "Td", check_real("Td", shown["Td"], low=0.0)
        high = low
    else:
        raise TypeError("missing value for d")
    if name == "d":
        return values, _delay_pieces(low, high, "d")
    if "T" in box:
        raise ValueError(f"robust regions take a delay Td in seconds over a fixed period: with T "
                         f"uncertain its fraction of a period varies; give the delay in samples, "
                         f"d (got Td = {low!r}" + ("" if high == low else f" to {high!r}") + " s)")
    T = check_real("T", {**loop.defaults, **values}.get("T", np.nan), low=0.0, low_open=True)
    return values, _delay_pieces(low / T, high / T, "Td / T")


def robust_region(loop, x=None, y=None, *, uncertain, strips=64, rtol=1e-6, x_range=None,
                  y_range=None, budget=MAX_CELLS, progress=None, **values):
    """The points of a loop's ``(x, y)`` plane stable for every value in a box.

    The robust region: the module states the guarantee and says how it is
    built.  It is a :class:`~symstab.numeric.engine.results.RobustRegion`
    with the nominal decomposition (at the box's centre,
    :func:`symstab.numeric.loop.plane.region`) beside it; its
    ``limits()`` are the robust set's (:meth:`symstab.Loop.limits` with
    ``uncertain``).

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x, y : str, optional
        The plane's parameters: environment parameters, jointly affine
        (default: the loop's :attr:`~symstab.Loop.plane`).
    uncertain : dict
        ``{name: (low, high)}``: the box of the plant's and environment's
        parameters (``T`` included), and the delay: ``d`` with whole ends,
        each whole delay of the range; ``Td`` (seconds, over a fixed ``T``)
        or ``d`` with a fractional end, every delay of the range, a
        continuum (the module's "Delays").
    strips : int
        Vertical strips across the window (1 to 100 000); those where the
        set has a corner or an end are halved (at most ``4 strips`` more).
    rtol : float
        Resolution of the certified intervals' ends, as a fraction of the
        window's height (1e-12 to 1e-2).
    x_range, y_range : (float, float), optional
        The window; default: the nominal stable set's (at the box's
        centre), which holds the robust set.  ``x_range = (x0, x0)`` is one
        line.
    budget : int
        Most cells examined (:data:`MAX_CELLS`); beyond, marginal (and
        :attr:`~symstab.numeric.engine.results.RobustRegion.exhausted` says so).
    progress : callable, bool or None, optional
        Called with the number of delays done: 0 once the input is checked
        and the work begins, then after each delay; True draws a bar
        (``symstab._validate.check_progress``).
    **values
        Values of the other parameters.

    Returns
    -------
    symstab.numeric.engine.results.RobustRegion

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)",
    ...             values=dict(m=0.0128, b=0.0324, T=1e-3, d=10))
    >>> robust = robust_region(loop, "B", "K", uncertain={"b": (0.0162, 0.0648)}, strips=16)
    >>> 0 < robust.area < robust.nominal.area
    True

    Every delay from 1.5 to 2.5 ms (at B = 1 the set at 2.5 ms ends at K =
    301.1, the one at 1.5 ms at 465.4):

    >>> delays = robust_region(loop, "B", "K", uncertain={"Td": (0.0015, 0.0025)}, strips=8)
    >>> bool(delays.contains(1.0, 250.0)), bool(delays.contains(1.0, 320.0))
    (True, False)
    """
    x, y = loop.plane_of(x, y)
    strips = check_count("strips", strips, 1)
    if strips > 100_000:
        raise ValueError(f"strips must be from 1 to 100000, got {strips}")
    rtol = check_real("rtol", rtol)
    if not 1e-12 <= rtol <= 1e-2:
        raise ValueError(f"rtol must be from 1e-12 to 1e-2, got {rtol!r}")
    box, delay, pieces, fixed = _check_robust_values(loop, x, y, uncertain, values)
    centre = {n: 0.5 * (lo + hi) for n, (lo, hi) in box.items()}
    centre_d = pieces[len(pieces) // 2].middle
    # Every corner of the box is asked of the loop (its domain: a pole that
    # cancels, a period that is not positive) before any work.
    for corner in itertools.product(*box.values()):
        loop.unstable_root_counts(**fixed, **dict(zip(box, corner, strict=True)), d=centre_d,
                                  **{x: 0.0, y: 0.0})

    from ..._progress import progress_printer

    progress = check_progress(progress, lambda: progress_printer("delays", len(pieces)))
    given_x, y_range = _check_robust_window(x_range, y_range)
    line = given_x is not None and given_x[0] == given_x[1]
    try:
        enclosures = {p.fraction: _enclosures_of(loop, x, y, box, fixed, p.fraction)
                      for p in pieces}
    except (ValueError, ZeroDivisionError, OverflowError) as exc:
        words = ", ".join(f"{k} in [{lo:g}, {hi:g}]" for k, (lo, hi) in box.items())
        raise ValueError(f"uncertain: {words or 'the delays'}: {exc}") from None
    at = dict(fixed) if delay is not None else {**fixed, "d": centre_d}
    nominal = loop.region(x, y, x_range=None if line else given_x, y_range=y_range, **fixed,
                          **centre, d=centre_d)
    if not nominal.stable:
        return RobustRegion.empty_set(x, y, box, delay, nominal, at,
                                      "the stable set at the box's centre is empty")
    points = np.vstack([cell.outer for cell in nominal.stable])
    x_lo, x_hi = given_x or (float(points[:, 0].min()), float(points[:, 0].max()))
    y_lo, y_hi = y_range or (float(points[:, 1].min()), float(points[:, 1].max()))
    window = (x_lo, x_hi, y_lo, y_hi)
    samples = sorted({s for p in pieces for s in p.samples})
    edges, geometry, owner = _strip_geometry(loop, x, y, fixed, box, samples, window, strips,
                                             rtol)
    tol = np.full(len(owner), rtol * (y_hi - y_lo) / 4) / np.maximum(geometry.height, 1e-300)
    marked, examined, exhausted = _certify_delays(enclosures, loop.environment_delay, geometry,
                                                  len(owner), pieces, tol, budget, progress)
    found, status = _piece_status(loop, x, y, enclosures, geometry, marked, pieces,
                                  {**fixed, **centre})
    robust, marginal = _strip_intervals(found, status, marked, geometry, owner, len(edges) - 1)
    touched = tuple(side for side in nominal.unbounded if _touches(side, edges, robust, window))
    return RobustRegion.from_strips(x, y, box, delay, edges, robust, marginal, nominal, at,
                                    examined=examined, exhausted=exhausted, unbounded=touched)


def _check_robust_values(loop, x, y, uncertain, values):
    """``(box, delay, pieces, fixed)``: :func:`robust_region`'s parameters, checked.

    The box of the uncertain continuous parameters, the delay range as given
    (None: one delay), the delays to certify (:class:`_DelayPiece`: the
    uncertain range, else the one given), and the values of every other
    parameter but the plane's, as floats.  A step of its own: every
    question about the input is asked here, before any work.
    """
    for name in (x, y):
        if name not in loop.environment_names or name in loop.plant_names or name == "T":
            raise ValueError(f"robust regions take a plane of the environment's parameters; "
                             f"{name} is not one")
    box, delay = _check_uncertain(loop, uncertain, (x, y))
    values, pieces = _delays(loop, values, box, delay)
    if delay is not None and delay[1][0] == delay[1][1]:
        delay = None                    # a range of one delay: that delay
    unknown = set(values) - set(loop.parameters)
    if unknown:
        raise TypeError(f"unknown parameter(s) {', '.join(sorted(unknown))}; parameters of "
                        f"this loop: {', '.join(loop.parameters)}")
    fixed = {**loop.defaults, **values}
    for name in list(box) + ["d", "Td"]:
        fixed.pop(name, None)
    fixed.pop(x, None)
    fixed.pop(y, None)
    missing = [n for n in loop.symbols if n not in fixed and n not in box and n not in (x, y)]
    if missing:
        raise TypeError(f"missing value(s) for {', '.join(missing)}")
    for name, v in fixed.items():
        fixed[name] = check_real(name, v)
    return box, delay, pieces, fixed


def _check_robust_window(x_range, y_range):
    """``(x_range, y_range)`` checked; ``x_range = (x0, x0)``, one line, is allowed."""
    given_x = None
    if x_range is not None:
        given_x = check_window("x_range", (x_range[0], x_range[1] + 1.0)) if (
            isinstance(x_range, (tuple, list)) and len(x_range) == 2
            and x_range[0] == x_range[1]) else check_window("x_range", x_range)
        given_x = (given_x[0], float(x_range[1]))
    if y_range is not None:
        y_range = check_window("y_range", y_range)
    return given_x, y_range


def _strip_geometry(loop, x, y, fixed, box, delays, window, strips, rtol):
    """``(edges, geometry, owner)``: the strips of the window and the pieces where to look.

    The first step of the work: on each strip's edges, the intervals of
    ``y`` stable at every delay of ``delays`` (in samples: the whole delays,
    or the ends and middles of a continuum's pieces) and grid value of the
    box; strips whose
    edges see different numbers of them are halved (:func:`_split`), and
    each strip's intervals are joined into trapezoids
    (:func:`_trapezoids`: ``geometry``, and ``owner``, each one's strip).
    """
    x_lo, x_hi, y_lo, y_hi = window
    grid = _grid(box)

    def look(xs):
        # Where to look on each line x: stable at every delay and grid value.
        found = [[(y_lo, y_hi)] for _ in xs]
        for d in delays:
            for point in grid:
                spans = loop.stable_intervals(y, **{x: np.asarray(xs)}, **fixed, **point, d=d)
                found = [_intersect(a, b) for a, b in zip(found, spans, strict=True)]
        return found

    edges = list(np.linspace(x_lo, x_hi, strips + 1)) if x_hi > x_lo else [x_lo, x_lo]
    edges, spans = _split(look, edges, look(edges), (x_hi - x_lo) * rtol, 4 * strips)
    geometry, owner = _trapezoids(edges, spans)
    return edges, geometry, owner


def _certify_delays(enclosures, environment_delay, geometry, n_pieces, delays, tol, budget,
                    progress):
    """``(marked, examined, exhausted)``: the pieces' spans not certified, at every delay.

    The second step: zero exclusion (:func:`_certify`) piece of delays by
    piece (:class:`_DelayPiece`, with ``enclosures`` per fraction of a
    period), each looking only where the pieces before certified;
    ``marked`` holds, per piece of the plane, the spans of ``t`` left open.
    ``progress`` is called with 0, then with the number of delay pieces done.
    """
    marked = {p: [] for p in range(n_pieces)}
    examined, exhausted = 0, False
    if progress is not None:
        progress(0)
    for done, delay in enumerate(delays, 1):
        found, n, out = _certify(enclosures[delay.fraction], delay.d + environment_delay,
                                 geometry, {p: _subtract([(0.0, 1.0)], marked[p]) for p in marked},
                                 tol, budget - examined)
        examined += n
        exhausted |= out
        for p in marked:
            marked[p] = _merge(marked[p] + found[p])
        if progress is not None:
            progress(done)
    return marked, examined, exhausted


def _piece_status(loop, x, y, enclosures, geometry, marked, delays, at_centre):
    """``(pieces, status)``: the certified pieces, each robust (0), marginal (1) or unstable (2).

    The third step: each certified piece's root count at one point (the
    box's centre, ``at_centre``) at a delay of every piece of delays (a
    whole delay, or the middle of a continuum: zero exclusion holds over
    all of it, so one count is its count), and its leading coefficient; a
    count of -1 (undecided) or a leading coefficient that may vanish leave
    it marginal, a count above 0 unstable (not robust).
    """
    pieces = [(p, a, b) for p in marked for a, b in _subtract([(0.0, 1.0)], marked[p])]
    where = np.array([p for p, _, _ in pieces], dtype=np.int64)
    inner = geometry.take(where)
    middle = np.array([0.5 * (a + b) for _, a, b in pieces])
    px = 0.5 * (inner.x0 + inner.x1)
    py = 0.5 * (inner.lo0 + inner.lo1) + middle * 0.5 * (inner.hi0 - inner.lo0 + inner.hi1
                                                         - inner.lo1)
    status = np.zeros(len(pieces), dtype=int)      # 0 robust, 1 marginal, 2 unstable
    for delay in delays:
        counts = np.atleast_1d(loop.unstable_root_counts(**at_centre, d=delay.middle,
                                                         **{x: px, y: py})) \
            if pieces else np.zeros(0, dtype=int)
        lead_mid, lead_rad = enclosures[delay.fraction].leading(delay.d + loop.environment_delay)
        for k, (p, a, b) in enumerate(pieces):
            ends = geometry.ends(p, a, b)
            if counts[k] > 0:
                status[k] = 2
            elif status[k] == 0 and not (counts[k] == 0 and _lead_excluded(
                    lead_mid, lead_rad, px[k], 0.5 * (inner.x1[k] - inner.x0[k]),
                    min(ends), max(ends))):
                status[k] = 1
    return pieces, status


def _strip_intervals(pieces, status, marked, geometry, owner, n_strips):
    """``(robust, marginal)``: per strip, the trapezoids' ends of each kind, from the bottom up.

    The last step: robust pieces, and marginal ones with the spans left
    open (not unstable ones), as :meth:`_Pieces.ends` in their strips.
    """
    robust = [[] for _ in range(n_strips)]
    marginal = [[] for _ in range(n_strips)]
    for k, (p, a, b) in enumerate(pieces):
        if status[k] < 2:
            (robust if status[k] == 0 else marginal)[owner[p]].append(
                geometry.ends(p, a, b))
    for p, spans in marked.items():
        marginal[owner[p]] += [geometry.ends(p, max(a, 0.0), min(b, 1.0))
                               for a, b in spans if a < 1.0 and b > 0.0]
    robust = [sorted(r, key=lambda e: e[0] + e[2]) for r in robust]
    marginal = [sorted(m, key=lambda e: e[0] + e[2]) for m in marginal]
    return robust, marginal


def _split(look, edges, spans, narrowest, most):
    """Halve the strips whose edges see different numbers of intervals (a corner, an end).

    Down to ``narrowest`` wide and at most ``most`` new edges; returns the
    edges and the intervals at each.  The line engine's cost is mostly per
    call, so a round asks at once for the midpoints that the next rounds'
    halvings of its strips may need (:func:`_halvings`, up to
    :data:`_LOOK_AHEAD` points): the same edges in a few calls, not one a
    round.
    """
    edges, spans = list(edges), list(spans)
    known = {}
    added = 0
    while added < most:
        halve = [i for i in range(len(edges) - 1)
                 if len(spans[i]) != len(spans[i + 1]) and edges[i + 1] - edges[i] > narrowest]
        halve = halve[:most - added]
        if not halve:
            break
        middles = [0.5 * (edges[i] + edges[i + 1]) for i in halve]
        wanted = [(edges[i], edges[i + 1])
                  for i, m in zip(halve, middles, strict=True) if m not in known]
        if wanted:
            depth = max(1, int(np.log2(_LOOK_AHEAD / len(wanted) + 1)))
            ahead = [m for a, b in wanted for m in _halvings(a, b, depth)]
            known.update(zip(ahead, look(ahead), strict=True))
        found = [known[m] for m in middles]
        for i, m, f in sorted(zip(halve, middles, found, strict=True), reverse=True):
            edges.insert(i + 1, m)
            spans.insert(i + 1, f)
        added += len(halve)
    return np.array(edges, dtype=float), spans


def _halvings(a, b, depth):
    """The midpoints of ``[a, b]`` halved ``depth`` times over, as :func:`_split` computes them."""
    middle = 0.5 * (a + b)
    if depth == 1:
        return [middle]
    return [middle] + _halvings(a, middle, depth - 1) + _halvings(middle, b, depth - 1)


def _trapezoids(edges, spans):
    """The pieces to certify: per strip, the intervals at its edges joined in order where they are
    as many (a trapezoid each), else the intervals common to both (a rectangle each).

    Returns the pieces (:class:`_Pieces`) and each one's strip.
    """
    rows, owner = [], []
    for i in range(len(edges) - 1):
        left, right = spans[i], spans[i + 1]
        if len(left) == len(right):
            pairs = [(a[0], a[1], b[0], b[1]) for a, b in zip(left, right, strict=True)]
        else:
            pairs = [(lo, hi, lo, hi) for lo, hi in _intersect(left, right)]
        for row in pairs:
            rows.append((edges[i], edges[i + 1], *row))
            owner.append(i)
    table = np.array(rows, dtype=float).reshape(-1, 6)
    return _Pieces(*table.T.copy()), owner


def _touches(side, edges, robust, window):
    """Whether the robust set reaches a side of the window."""
    x_lo, x_hi, y_lo, y_hi = window
    filled = [i for i, spans in enumerate(robust) if spans]
    if not filled:
        return False
    if side == "x_min":
        return filled[0] == 0 and edges[0] <= x_lo
    if side == "x_max":
        return filled[-1] == len(robust) - 1 and edges[-1] >= x_hi
    if side == "y_min":
        return min(min(spans[0][0], spans[0][2]) for spans in robust if spans) <= y_lo
    return max(max(spans[-1][1], spans[-1][3]) for spans in robust if spans) >= y_hi


def _intersect(a, b):
    """Intersection of two sorted lists of disjoint intervals."""
    out, i, j = [], 0, 0
    while i < len(a) and j < len(b):
        lo, hi = max(a[i][0], b[j][0]), min(a[i][1], b[j][1])
        if lo < hi:
            out.append((float(lo), float(hi)))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out


def _lead_excluded(lead_mid, lead_rad, xc, hx, a, b):
    """Whether the leading coefficient cannot vanish on the strip's rectangle, over the box."""
    yc, hy = 0.5 * (a + b), 0.5 * (b - a)
    m, r = lead_mid[0], lead_rad[0]    # the root box encloses every sub-box
    centre = m[0] + xc * m[1] + yc * m[2]
    radius = (r[0] + abs(xc) * r[1] + abs(yc) * r[2] + hx * (abs(m[1]) + r[1])
              + hy * (abs(m[2]) + r[2]) + 8 * _EPS * (abs(m[0]) + abs(xc * m[1]) + abs(yc * m[2])))
    return abs(centre) > radius
