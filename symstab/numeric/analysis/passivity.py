"""Passivity beside stability: Colgate and Schenkel's condition as a region of a plane.

The theorem (J. E. Colgate and G. G. Schenkel, "Passivity of a class of
sampled-data systems: application to haptic interfaces", J. Robotic Systems
14(1), 37-47, 1997; quoted as a necessary and sufficient condition in
J. M. Brown and J. E. Colgate's virtual-wall work at Northwestern).  Its
hypotheses, as this module applies them:

* the device is one degree of freedom, a rigid mass ``m`` with viscous
  friction ``b``, ``G(s) = 1/(m s**2 + b s)``, driven by an ideal actuator
  and read by an ideal position sensor (no quantisation, no Coulomb
  friction, no actuator dynamics);
* its position is sampled every ``T`` seconds, the virtual environment is a
  linear time-invariant pulse transfer function ``H(z)`` from the sampled
  position to the force, and a zero-order hold applies the force;
* passivity is that of the port the operator holds (force in, velocity
  out), for any operator; nothing is assumed about the operator.

Then the system is passive if and only if

    b > T / (2 (1 - cos(w T))) Re{(1 - exp(-j w T)) H(exp(j w T))}

for ``0 <= w <= pi / T`` (at ``w = 0`` the limit).  The device's mass does not
appear.  Necessity comes from a small-gain argument and sufficiency from
Parseval's theorem (the paper's abstract).  The frequency response of ``H``
describes the environment only when ``H`` is stable, so this module refuses
an environment with a pole on or outside the unit circle (with a pole on it
the bound is infinite at that frequency).

The loop's delay belongs to the environment: ``H(z) = VE(z) z**-d``, since
the force the hold applies at step ``k`` is ``VE`` applied to the position
of step ``k - d``.

Derivation used here.  With ``theta = w T`` and ``u = 1 - exp(-j theta)``,
``2 (1 - cos theta) = |u|**2`` and ``u / |u|**2 = 1 / conj(u) = 1/2 + (j/2)
cot(theta/2)``, so the condition reads

    b > (T/2) [Re H - cot(theta/2) Im H]       (theta in [0, pi]).

Writing ``H = N(z) z**-d / D(z) = P(z) / |D(z)|**2`` on the circle, with the
Laurent polynomial ``P(z) = N(z) D(1/z) z**-d = sum_k p_k z**k``, each term
gives ``p_k sin(theta/2 - k theta) / sin(theta/2)``: the Dirichlet kernel
``D_m(theta) = 1 + 2 sum_{i<=m} cos(i theta)`` with ``m = -k`` for ``k <= 0``
and ``-D_{k-1}`` for ``k >= 1``.  So the right-hand side is a cosine
polynomial divided by the cosine polynomial ``|D|**2``, evaluated without the
``0/0`` of the printed form at ``theta = 0`` (where it is ``H(1) - 2 H'(1)``).

Two consequences, checked by the tests:

* the virtual wall ``K + B (1 - 1/z)/T`` at ``d = 0`` gives ``b > K T/2 - B
  cos(theta)``: passive if and only if ``b > K T/2 + |B|`` (Colgate and
  Schenkel's closed form);
* a spring behind ``d`` samples of delay gives ``b > (K T/2) D_d(theta)``,
  largest at ``theta = 0``: passive if and only if ``K T (2 d + 1)/2 < b``,
  i.e. each sample of delay costs as much as ``K T`` of damping.  With a
  damper as well the ``theta = 0`` bound is ``K T (2 d + 1)/2 - B``: with a
  delay, positive virtual damping raises the passive stiffness.

A fractional delay ``Td = (d + eps) T``, ``0 < eps < 1``.  The force ``f_k =
(H x)_k`` (``H = VE z**-d``, ``x_k = x(kT)``) is then held on ``[(k + eps) T,
(k + 1 + eps) T)``: not a pulse transfer function of the samples, so the
condition is derived again from the port's energy ``int (b v**2 + f v) dt``,
which passivity asks to be ``>= 0`` (from rest) for every velocity.  Split
each period at ``(k + eps) T``: ``a_k = x((k + eps) T) - x(kT)``, ``c_k =
x((k + 1) T) - x((k + eps) T)``.  The force depends on the samples only, and
``f_k`` works ``f_k (c_k + a_{k+1})``; for given ``a_k, c_k`` the least
``int v**2`` over the period is ``a_k**2/(eps T) + c_k**2/((1 - eps) T)``
(Cauchy-Schwarz; equality for ``x`` piecewise linear).  So passivity is

    sum_k [b a_k**2/(eps T) + b c_k**2/((1 - eps) T) + f_k (c_k + a_{k+1})] >= 0

for all sequences.  With ``x_{k+1} - x_k = a_k + c_k``, ``F = G (A + C)``, ``G
= H/(z - 1)``, and Parseval, this holds if and only if for every ``theta``
the Hermitian matrix

    M(theta) = diag(b/(eps T), b/((1 - eps) T)) + Herm(conj(G) [[z, 1], [z, 1]])

is positive semidefinite (``v = (A, C)``, ``Herm(P) = (P + P^H)/2``).  With
``R = Re G`` (bounded on the circle: ``-T R`` is the whole delay's bound
above, evaluated by its Dirichlet kernels) and ``h = H / z`` (one more
sample of delay),

    M = [[b/(eps T) + R - Re h, R - h/2], [R - conj(h)/2, b/((1 - eps) T) + R]],

since ``conj(G) z = conj(G / z)`` and ``G / z = G - h``.  Scaled by
``sqrt(eps T)`` and ``sqrt((1 - eps) T)``, with ``r = -T R``, it is ``M' =
[[b - eps (r + T Re h), -s (r + T h/2)], [.., b - (1 - eps) r]]``, ``s =
sqrt(eps (1 - eps))``, affine in ``b`` and in the plane's parameters.  The
least passive damping at ``theta``, ``b*(theta)``, is the larger root of

    (b - eps (r + T Re h)) (b - (1 - eps) r) = eps (1 - eps) abs(r + T h/2)**2,

which makes both diagonal entries ``>= 0`` as well.  Checks: ``eps -> 0``
forces ``a = 0`` and gives ``b >= r`` (Colgate and Schenkel at ``d``);
``eps -> 1`` forces ``c = 0`` and gives ``b >= r + T Re h``, their bound at
``d + 1``; the velocity constant over the period (``v = (sqrt(eps),
sqrt(1 - eps))``) gives ``b >= r + eps T Re h``, the two bounds interpolated,
a necessary condition only.  A spring ``K`` behind half a sample (``d = 0``,
``eps = 1/2``) at ``theta = 0``: ``r = K T/2``, ``T h = K T``, ``(b - 3 K T/4)
(b - K T/4) = (K T/2)**2``, ``b* = (1 + sqrt(5)/2) K T/2 = 1.0590 K T``, more
than the ``K T`` halfway between ``K T/2`` (``d = 0``) and ``3 K T/2`` (``d =
1``).  The tests compare ``b*`` with an independent lifting (each period cut
into ``N`` pieces, an ``N x N`` eigenvalue).

One condition the frequency inequality does not contain is added: a static
stiffness ``H(1) < 0`` is not passive (pulled slowly from 0 to ``x`` the device
returns ``|H(1)| x**2 / 2`` of energy while the friction takes ``b x**2 /
duration``, which vanishes), so the passive set also requires ``H(1) >= 0``
(``K >= 0`` for the paper's environment).

The region.  The plane's parameters enter ``H`` affinely (the denominator
must not depend on them), so each ``theta`` gives a half-plane (a whole
delay) or a convex set ``M'(theta) >= 0`` (a spectrahedron, a fractional
one), and the passive set is their intersection: a convex set.  It is computed as a polygon by
cutting planes: the half-planes of a grid of ``theta`` (16 points per period
of the highest harmonic, at least 1024) cut a large box; then, at every
vertex, the worst ``theta`` is found (the grid, then a zooming-grid search
around each of the best local maxima) and its half-plane cuts the vertex off
when the condition fails there by more than ``1e-6 b``.  When no vertex
fails, every vertex satisfies the condition with ``b (1 + 1e-6)``, so by
convexity the polygon lies between the passive sets of the damping ``b`` and
``b (1 + 1e-6)`` (the worst ``theta`` being found by a refined search, not
certified).  A curved part of the boundary (where the worst ``theta`` moves
along it) becomes many short edges.  With a fractional delay the grid's
half-planes are three necessary ones per angle (``v^H M' v >= 0`` for ``v =
(1, 0)``, ``(0, 1)`` and the constant velocity's), the failure at a vertex
is ``b*(theta) - b`` and its cut is ``v^H M'(theta*, p) v >= 0`` with ``v``
the eigenvector of the least eigenvalue of ``M'(theta*, p0)`` at the failing
vertex ``p0``: linear in the point ``p``, met by every passive point, failed
by ``p0``.
"""

import dataclasses
import math

import numpy as np
import sympy as sp

from ..._validate import check_real, split_delay
from ..engine.search import zoom_max

__all__ = ["PassiveRegion", "passive_region"]

#: Relative tolerance of the condition at the polygon's vertices (of the damping).
_RTOL = 1e-6
#: Fewest angles on the grid of theta in [0, pi].
_MIN_GRID = 1024
#: Most cutting-plane rounds and most vertices before giving up.
_MAX_ROUNDS = 60
_MAX_VERTICES = 200_000
#: Half-size of the first box, in units of the plane's natural scale.
_BOX = 1e4
#: Local maxima of the grid refined per vertex.
_REFINED_PEAKS = 3


@dataclasses.dataclass(frozen=True)
class PassiveRegion:
    """The passive set of a plane: a convex polygon.

    Attributes
    ----------
    x, y : str
        The plane's parameters (columns of ``polygon``).
    polygon : ndarray
        Vertices ``(n, 2)``, counter-clockwise; shape ``(0, 2)`` when the
        set is empty.
    bounded : bool
        False when the set reaches beyond the window (it was clipped to it:
        the set is unbounded, or larger than the window given).
    x_range, y_range : tuple of float
        The window.
    area : float
        Area of the polygon (inside the window).
    y_max : float or None
        Largest ``y`` of a passive point (``inf`` if the set is unbounded
        upwards, None if it is empty, as in :class:`~symstab.numeric.engine.results.Limits`),
        e.g. the passive ``K_max``.
    x_at_y_max : float or None
        The ``x`` where it is reached (the middle of a horizontal top edge;
        None if the set is empty).
    """

    x: str
    y: str
    polygon: np.ndarray
    bounded: bool
    x_range: tuple
    y_range: tuple
    area: float
    y_max: object
    x_at_y_max: object
    # The half-planes c0 + cx x + cy y <= 0 whose intersection the polygon
    # is (before the window): set by _solve, read by contains().
    _halfplanes: np.ndarray = dataclasses.field(default=None, init=False, repr=False,
                                                compare=False)

    def plot(self, ax=None, *, region=None):
        """Draw the passive polygon: :func:`symstab.drawing.plot_passive`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        region : symstab.numeric.engine.decomposition.Decomposition, optional
            The plane's stable set (:meth:`symstab.Loop.region`), drawn under it.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_passive

        return plot_passive(self, ax, region=region)

    @property
    def empty(self):
        """True when no point is passive."""
        return len(self.polygon) == 0

    def contains(self, x, y):
        """Whether each point ``(x, y)`` is in the passive set (arrays broadcast).

        Decided by the half-planes of the polygon before the window clipped
        it, so points outside the window are answered too.  A point within
        the tolerance of the boundary (the condition failing by less than
        ``1e-6`` of the damping) may be called passive.

        Parameters
        ----------
        x, y : float or array_like
            Points of the plane.

        Returns
        -------
        ndarray of bool
        """
        from ..._validate import check_array

        x = check_array(self.x, x)
        y = check_array(self.y, y)
        x, y = np.broadcast_arrays(x, y)
        if self.empty:
            return np.zeros(x.shape, dtype=bool)
        h = self._halfplanes
        out = np.ones(x.shape, dtype=bool)
        for c0, cx, cy in h:
            # Rows are normalised (|(cx, cy)| = 1 in the scaled plane, see
            # _Plane.rows); a relative slack of 1e-12 absorbs the rounding
            # of a point on an edge.
            out &= c0 + cx * x + cy * y <= 1e-12 * (abs(c0) + abs(cx * x) + abs(cy * y))
        return out

    def renamed(self, x, y):
        """The same region with the plane's parameters called ``x`` and ``y``.

        Parameters
        ----------
        x, y : str
            The new names.
        """
        out = dataclasses.replace(self, x=x, y=y)
        object.__setattr__(out, "_halfplanes", self._halfplanes)
        return out

    def __repr__(self):
        if self.empty:
            return f"PassiveRegion({self.x}, {self.y}: no passive point)"
        where = "bounded" if self.bounded else (
            f"clipped to {self.x} in [{self.x_range[0]:.6g}, {self.x_range[1]:.6g}], "
            f"{self.y} in [{self.y_range[0]:.6g}, {self.y_range[1]:.6g}]")
        return (f"PassiveRegion({self.y}_max={self.y_max:.6g} at {self.x}={self.x_at_y_max:.6g}, "
                f"area={self.area:.6g}, {len(self.polygon)} vertices, {where})")


# --------------------------------------------------------------------------
# The condition, term by term in Dirichlet kernels


def _laurent(num, den, d):
    """``(p, lowest)``: ``P(z) = N(z) D(1/z) z**-d = sum_i p[i] z**(lowest + i)``.

    ``num`` and ``den`` are real coefficients, highest power first; ``p``
    is short (``len(num) + len(den) - 1`` terms) whatever the delay.
    """
    ascending = np.asarray(num, dtype=float)[::-1]
    # den highest first is D(1/z) in ascending powers from z**-(len(den) - 1).
    return np.convolve(ascending, np.asarray(den, dtype=float)), -(len(den) - 1) - d


def _kernels(orders, theta):
    """Dirichlet kernels ``D_m(theta) = sin((m + 1/2) theta) / sin(theta/2)`` (``2 m + 1`` at 0).

    Shape ``theta.shape + orders.shape``; ``theta`` in [0, pi].
    """
    theta = np.asarray(theta, dtype=float)[..., None]
    half = np.sin(0.5 * theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        values = np.sin((orders + 0.5) * theta) / half
    return np.where(half == 0, 2.0 * orders + 1.0, values)


@dataclasses.dataclass
class _Plane:
    """The condition ``a0(theta) + x ax(theta) + y ay(theta) <= 0`` of a plane, in damping units.

    ``a = scale (C0 + x Cx + y Cy) / R - damping`` with ``C = |D|**2 [Re H
    - cot(theta/2) Im H]`` of the three numerators (the base and the two
    slopes) and ``R = |D|**2``.  Each ``C`` is a short sum of Dirichlet
    kernels (see the module docstring), evaluated in closed form: a point
    costs the same at any delay.  ``damping_axis`` is 0 or 1 when the
    damping itself is the plane's x or y (then ``damping`` is 0 and the axis
    carries ``-1``).  ``static`` is ``(h0, hx, hy)``: ``H(1)``, which must
    be ``>= 0``.  ``sx, sy`` scale the plane to order one.
    """

    weights: np.ndarray        # (n, 3): each numerator's p_k times the kernel's sign
    orders: np.ndarray         # (n,): the order m of each term's kernel
    den: np.ndarray            # D, highest power first
    scale: float
    damping: float
    damping_axis: object
    static: tuple
    sx: float = 1.0
    sy: float = 1.0

    @property
    def harmonic(self):
        """The highest harmonic of ``cos(k theta)`` in the condition (the grid's resolution)."""
        return int(max(self.orders.max(), len(self.den) - 1))

    def terms(self, theta):
        """``(a0, ax, ay)`` at the angles ``theta`` (each of ``theta``'s shape), unscaled axes."""
        theta = np.asarray(theta, dtype=float)
        values = np.moveaxis(_kernels(self.orders, theta) @ self.weights, -1, 0)   # (3,) + shape
        r = np.abs(np.polyval(self.den, np.exp(1j * theta)))**2
        a = self.scale * values / r
        a[0] = a[0] - self.damping
        if self.damping_axis is not None:
            a[1 + self.damping_axis] = a[1 + self.damping_axis] - 1.0
        return a

    def value(self, terms, vx, vy):
        """The condition's failure in damping units from :meth:`terms`, at the scaled points.

        ``terms[i]`` broadcasts against ``vx`` and ``vy``; here it is ``a``.
        """
        return terms[0] + vx * self.sx * terms[1] + vy * self.sy * terms[2]

    def at(self, theta, vx, vy):
        """The failure at angle ``theta[i]`` and the (scaled) point ``(vx[i], vy[i])``."""
        return self.value(self.terms(theta), vx, vy)

    def rows(self, theta):
        """Half-planes ``c0 + cx x' + cy y' <= 0`` in the scaled plane, normalised."""
        a0, ax, ay = self.terms(np.atleast_1d(theta))[:3]
        rows = np.stack([a0, ax * self.sx, ay * self.sy], axis=-1)
        return _normalise(rows)

    def cuts(self, theta, vx, vy):
        """The half-planes that cut off the failing scaled points ``(vx, vy)`` at their worst ``theta``.

        A whole delay's condition is one half-plane per angle, whatever the point.
        """
        return self.rows(np.unique(theta))

    def static_row(self):
        h0, hx, hy = self.static
        return _normalise(np.array([[-h0, -hx * self.sx, -hy * self.sy]]))


@dataclasses.dataclass
class _FractionalPlane(_Plane):
    """The condition of a delay ``(d + eps) T`` with ``0 < eps < 1``: a 2x2 matrix per angle.

    ``M'(theta) = [[b - eps (r + T Re h), -s (r + T h/2)], [-s (r + T
    conj(h)/2), b - (1 - eps) r]]`` must be positive semidefinite, with ``s
    = sqrt(eps (1 - eps))``, ``r = -T R`` the whole delay's bound
    (:class:`_Plane`'s ``a + b``) and ``h = H(z)/z`` (module docstring).
    :meth:`terms` adds the rows ``T Re h`` and ``T Im h`` of the three
    numerators to the whole delay's three; :meth:`value` is the least
    passive damping ``b*(theta)`` less the damping.  ``num`` holds the three
    numerators (highest power first, one length), ``d`` the whole samples.
    """

    eps: float = 0.0
    period: float = 0.0
    num: np.ndarray = None
    d: int = 0

    @property
    def harmonic(self):
        """One more than the whole delay's: ``h`` carries one more sample of delay."""
        return super().harmonic + 1

    def terms(self, theta):
        """``(a0, ax, ay, T Re h0, .., T Im h0, ..)``: nine rows at the angles ``theta``."""
        theta = np.asarray(theta, dtype=float)
        z = np.exp(1j * theta)
        shift = self.period * np.exp(-1j * (self.d + 1) * theta) / np.polyval(self.den, z)
        h = np.stack([np.polyval(c, z) * shift for c in self.num])
        return np.concatenate([super().terms(theta), h.real, h.imag])

    def _damping(self, vx, vy):
        """The damping at the scaled points: the constant, or the axis that is it."""
        if self.damping_axis is None:
            return self.damping
        return vx * self.sx if self.damping_axis == 0 else vy * self.sy

    def _parts(self, terms, vx, vy):
        """``(b, r, T Re h, T Im h)`` at the scaled points (``terms`` broadcast as in :meth:`value`)."""
        b = self._damping(vx, vy)
        r = super().value(terms[:3], vx, vy) + b
        return (b, r, super().value(terms[3:6], vx, vy), super().value(terms[6:], vx, vy))

    def value(self, terms, vx, vy):
        """``b*(theta) - b``: the larger root of ``det M' = 0`` less the damping."""
        b, r, hr, hi = self._parts(terms, vx, vy)
        e = self.eps
        alpha, beta = e * (r + hr), (1 - e) * r
        gamma = e * (1 - e) * ((r + 0.5 * hr)**2 + (0.5 * hi)**2)
        return 0.5 * (alpha + beta) + np.sqrt((0.5 * (alpha - beta))**2 + gamma) - b

    def _form(self, terms, v1, v2):
        """``(c0, cx, cy)`` of ``-v^H M' v`` (unscaled axes) for unit vectors ``v = (v1, v2)``."""
        e, s = self.eps, math.sqrt(self.eps * (1 - self.eps))
        unit = np.eye(3)
        b = unit[0] * self.damping if self.damping_axis is None else unit[1 + self.damping_axis]
        r = terms[:3] + b[:, None]
        hr, hi = terms[3:6], terms[6:]
        w1, w2 = np.abs(v1)**2, np.abs(v2)**2
        cross = np.conj(v1) * v2
        mixed = cross.real * (r + 0.5 * hr) - cross.imag * (0.5 * hi)
        return w1 * e * (r + hr) + w2 * (1 - e) * r + 2 * s * mixed - b[:, None]

    def _scaled_rows(self, form):
        c0, cx, cy = form
        return _normalise(np.stack([c0, cx * self.sx, cy * self.sy], axis=-1))

    def rows(self, theta):
        """Three necessary half-planes per angle: ``v = (1, 0)``, ``(0, 1)`` and
        ``(sqrt(eps), sqrt(1 - eps))`` (a velocity constant over the period:
        Colgate's bound interpolated, ``b >= r + eps T Re h``)."""
        terms = self.terms(np.atleast_1d(theta))
        e = self.eps
        return np.concatenate([self._scaled_rows(self._form(terms, v1, v2))
                               for v1, v2 in ((1.0, 0.0), (0.0, 1.0),
                                              (math.sqrt(e), math.sqrt(1 - e)))])

    def cuts(self, theta, vx, vy):
        """At each failing point, ``v^H M'(theta, p) v >= 0`` with ``v`` the least eigenvector there.

        Linear in the point, met by every passive point, failed by the point
        (where ``M'`` has a negative eigenvalue).
        """
        terms = self.terms(theta)
        b, r, hr, hi = self._parts(terms, vx, vy)
        e, s = self.eps, math.sqrt(self.eps * (1 - self.eps))
        matrix = np.empty((len(theta), 2, 2), dtype=complex)
        matrix[:, 0, 0] = b - e * (r + hr)
        matrix[:, 1, 1] = b - (1 - e) * r
        matrix[:, 0, 1] = -s * (r + 0.5 * (hr + 1j * hi))
        matrix[:, 1, 0] = np.conj(matrix[:, 0, 1])
        vectors = np.linalg.eigh(matrix)[1][:, :, 0]
        return np.unique(self._scaled_rows(self._form(terms, vectors[:, 0], vectors[:, 1])), axis=0)


def _normalise(rows):
    norm = np.hypot(rows[:, 1], rows[:, 2])
    scale = np.where(norm > 0, norm, 1.0)
    return rows / scale[:, None]


# --------------------------------------------------------------------------
# Convex polygons cut by half-planes


def _clip(vertices, row):
    """The convex polygon ``vertices`` (counter-clockwise) cut by ``c0 + cx x + cy y <= 0``.

    ``row`` is ``(c0, cx, cy)``, Python floats or NumPy ones (the same arithmetic).
    """
    c0, cx, cy = row
    s = c0 + cx * vertices[:, 0] + cy * vertices[:, 1]
    inside = s <= 0
    count = int(inside.sum())
    if count == len(inside):
        return vertices
    if not count:
        return vertices[:0]
    m = len(vertices)
    # Convex: the inside vertices are one cyclic run; k is its first, l its last.
    # (Slices, not np.roll: this runs once per cutting line, thousands of times.)
    k = int(np.flatnonzero(inside & ~_previous(inside))[0])
    run = (np.arange(count) + k) % m
    last = int(run[-1])

    def cut(i, j):
        t = s[i] / (s[i] - s[j])
        return vertices[i] + t * (vertices[j] - vertices[i])

    enter = cut((k - 1) % m, k)
    leave = cut(last, (last + 1) % m)
    out = np.concatenate([[enter], vertices[run], [leave]])
    return _tidy(out)


def _previous(a):
    """``np.roll(a, 1, axis=0)``: each row's predecessor, cyclically."""
    return np.concatenate([a[-1:], a[:-1]])


def _tidy(vertices):
    """Drop consecutive vertices that coincide to rounding."""
    if len(vertices) < 2:
        return vertices
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    span = max(float(extent[0]), float(extent[1]), 1e-300)
    before = vertices - _previous(vertices)
    step = np.hypot(before[:, 0], before[:, 1])
    # Many lines through one corner (at d = 0 every theta's line passes
    # through the wall's apex) give copies of it a few ulps apart.
    keep = step > 1e-9 * span
    kept = int(keep.sum())
    if not kept:
        return vertices[:1]
    if kept < len(vertices):
        vertices = vertices[keep]
        if len(vertices) < 4:
            return vertices
        before = vertices - _previous(vertices)
        step = np.hypot(before[:, 0], before[:, 1])
    elif len(vertices) < 4:
        return vertices
    # A vertex where the boundary does not turn (a grid line through a
    # corner cuts it at the corner) is no vertex.  Each vertex's step to
    # the next is the next one's step from it: the same differences.
    after = np.concatenate([before[1:], before[:1]])
    after_step = np.concatenate([step[1:], step[:1]])
    turn = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
    straight = np.abs(turn) <= 1e-12 * step * after_step
    bent = int(len(straight) - straight.sum())
    return vertices[~straight] if bent >= 3 else vertices


def _box(half_x, half_y, centre=(0.0, 0.0)):
    cx, cy = centre
    return np.array([[cx - half_x, cy - half_y], [cx + half_x, cy - half_y],
                     [cx + half_x, cy + half_y], [cx - half_x, cy + half_y]])


def _clip_all(vertices, rows):
    # Python floats: a NumPy scalar's every operation costs more, for the same arithmetic.
    for row in np.asarray(rows, dtype=float).tolist():
        if len(vertices) == 0:
            break
        if abs(row[1]) == 0 and abs(row[2]) == 0:
            if row[0] > 0:
                return vertices[:0]
            continue
        vertices = _clip(vertices, row)
    return vertices if len(vertices) >= 3 else vertices[:0]


def _polish(vertices, rows):
    """Each vertex recomputed as the crossing of the two most transverse lines through it.

    Clipping leaves a corner where many lines meet (the wall's apex, where
    every theta's line passes) a few ulps off, and :func:`_tidy` keeps one
    of its copies; the crossing of two well-separated lines through it is
    accurate to rounding.  A vertex that would move further than the
    lines' closeness to it stays where it is.
    """
    if len(vertices) < 3:
        return vertices
    span = max(float(np.ptp(vertices[:, 0])), float(np.ptp(vertices[:, 1])), 1e-300)
    near = 1e-8 * span
    out = vertices.copy()
    for start in range(0, len(vertices), 256):
        block = vertices[start:start + 256]
        s = rows[None, :, 0] + rows[None, :, 1] * block[:, 0, None] + rows[None, :, 2] * block[:, 1, None]
        for i, active in enumerate(np.abs(s) <= near):
            lines = rows[active]
            if len(lines) < 2:
                continue
            cross = lines[:, None, 1] * lines[None, :, 2] - lines[:, None, 2] * lines[None, :, 1]
            j, k = np.unravel_index(int(np.argmax(np.abs(cross))), cross.shape)
            det = cross[j, k]
            if abs(det) < 1e-6:
                continue
            (c0, c1, c2), (e0, e1, e2) = lines[j], lines[k]
            point = np.array([(-c0 * e2 + c2 * e0) / det, (-c1 * e0 + c0 * e1) / det])
            if np.max(np.abs(point - block[i])) <= near / abs(det):
                out[start + i] = point
    return out


def _area(vertices):
    if len(vertices) < 3:
        return 0.0
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


# --------------------------------------------------------------------------
# The worst angle at a point


def _grid(n_series):
    n = max(_MIN_GRID, 16 * (n_series + 1))
    return np.linspace(0.0, np.pi, n + 1)


def _worst(plane, grid, table, vx, vy):
    """``(value, theta)``: the largest ``a`` over ``theta`` in [0, pi] at each scaled point.

    The grid (``table`` holds ``a0, ax, ay`` on it) gives the best local
    maxima, and a zooming-grid search (:func:`~symstab.numeric.engine.search.zoom_max`)
    between each one's neighbours refines them.
    """
    best = np.empty(len(vx))
    where = np.empty(len(vx))
    # Chunks of vertices keep each (vertices x grid) table to 8 MB (a few
    # such tables are alive at once).
    rows_per_chunk = max(1, 2**20 // len(grid))
    for start in range(0, len(vx), rows_per_chunk):
        sl = slice(start, start + rows_per_chunk)
        values = plane.value(table[:, None, :], vx[sl, None], vy[sl, None])
        padded = np.pad(values, ((0, 0), (1, 1)), constant_values=-np.inf)
        peak = (padded[:, 1:-1] >= padded[:, :-2]) & (padded[:, 1:-1] >= padded[:, 2:])
        ranked = np.where(peak, values, -np.inf)
        top = np.argsort(-ranked, axis=1)[:, :_REFINED_PEAKS]
        rows = np.arange(values.shape[0])[:, None]
        top_values = ranked[rows, top]
        lo = grid[np.maximum(top - 1, 0)]
        hi = grid[np.minimum(top + 1, len(grid) - 1)]
        px = np.broadcast_to(vx[sl, None], top.shape)
        py = np.broadcast_to(vy[sl, None], top.shape)
        valid = np.isfinite(top_values)
        lo, hi, px, py = lo[valid], hi[valid], px[valid], py[valid]
        # Down to 1e-9 of the angle: the maximum's value is then exact to rounding.
        theta = zoom_max(lambda t, i, px=px, py=py: plane.at(t, px[i, None], py[i, None]),
                         lo, hi, rtol=1e-9)
        refined = np.full(top.shape, -np.inf)
        refined[valid] = plane.at(theta, px, py)
        angles = np.full(top.shape, np.nan)
        angles[valid] = theta
        # The grid's own value wins where the search found less (an end point).
        better = top_values > refined
        refined = np.where(better, top_values, refined)
        angles = np.where(better, grid[top], angles)
        pick = np.argmax(refined, axis=1)
        best[sl] = refined[rows[:, 0], pick]
        where[sl] = angles[rows[:, 0], pick]
    return best, where


# --------------------------------------------------------------------------
# The region


def _solve(plane, x, y, x_range, y_range, hints=(0.0, 0.0)):
    """The :class:`PassiveRegion` of a prepared plane.

    ``hints`` are sizes of the axes (the loop's defaults) used only where
    the condition gives no scale of its own (no line crosses that axis).
    The steps: the plane's scale (:func:`_natural_scales`), the polygon cut
    to the condition (:func:`_passive_polygon`), the window
    (:func:`_fitted_window`) and the region in the plane's units
    (:func:`_region_of`).
    """
    grid = _grid(plane.harmonic)
    table = plane.terms(grid)
    plane.sx, plane.sy = _natural_scales(table, hints)
    polygon, rows, on_box = _passive_polygon(plane, grid, table)
    window = _fitted_window(plane, polygon, on_box, x_range, y_range)
    halfplanes = rows * np.array([1.0, 1.0 / plane.sx, 1.0 / plane.sy])
    if len(polygon) == 0:
        return _with_halfplanes(PassiveRegion(x, y, np.zeros((0, 2)), True, tuple(window[0]),
                                              tuple(window[1]), 0.0, None, None),
                                halfplanes)
    return _with_halfplanes(_region_of(plane, x, y, polygon, on_box, window), halfplanes)


def _natural_scales(table, hints):
    """``[sx, sy]``: the plane's natural scale, where the grid's lines cross the axes.

    The set's own scale wins over the hint: the cuts start in a box of
    :data:`_BOX` units and drop vertices closer than 1e-9 of the polygon's
    span, so a unit much larger than the set (a hint of 1 with a damping
    of 1e-6) loses it to rounding (an empty set).  1 where neither gives one.
    """
    scales = []
    for axis, hint in ((1, hints[0]), (2, hints[1])):
        slope = np.abs(table[axis])
        big = slope >= 1e-3 * slope.max() if slope.max() > 0 else np.zeros_like(slope, dtype=bool)
        with np.errstate(all="ignore"):
            ratio = np.abs(table[0][big]) / slope[big]
        ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
        s = float(np.median(ratio)) if ratio.size else 0.0
        if not s > 0:
            s = abs(hint)
        scales.append(s if s > 0 else 1.0)
    return scales


def _cut(plane, grid, table, tolerance, polygon, rows):
    """Cutting planes until every vertex meets the condition to ``tolerance``: ``(polygon, rows)``.

    Each round adds the half-plane of the worst angle at every failing
    vertex (:func:`_worst`); an ArithmeticError if the boundary needs more
    than :data:`_MAX_VERTICES` vertices or :data:`_MAX_ROUNDS` rounds.
    """
    for _ in range(_MAX_ROUNDS):
        if len(polygon) == 0:
            return polygon, rows
        value, theta = _worst(plane, grid, table, polygon[:, 0], polygon[:, 1])
        failing = value > tolerance
        if not failing.any():
            return polygon, rows
        new = plane.cuts(theta[failing], polygon[failing, 0], polygon[failing, 1])
        rows = np.concatenate([rows, new])
        polygon = _clip_all(polygon, new)
        if len(polygon) > _MAX_VERTICES:
            raise ArithmeticError(f"the passive set's boundary needs more than "
                                  f"{_MAX_VERTICES} vertices to meet the tolerance")
    raise ArithmeticError(f"the passive set did not converge in {_MAX_ROUNDS} rounds of "
                          f"cutting planes")


def _passive_polygon(plane, grid, table):
    """``(polygon, rows, on_box)``: the passive set (scaled units), its half-planes, far vertices.

    The grid's half-planes cut a far box (:data:`_BOX`), then
    :func:`_cut` adds the worst angles' until the condition holds; a
    vertex on the far box (``on_box``, per coordinate) means the set runs
    off to infinity.  A bounded set is cut again in a box fitted to it.
    """
    tolerance = _RTOL * (plane.damping if plane.damping_axis is None else
                         (plane.sx, plane.sy)[plane.damping_axis])
    rows = np.concatenate([plane.static_row(), plane.rows(grid)])
    polygon, rows = _cut(plane, grid, table, tolerance, _clip_all(_box(_BOX, _BOX), rows), rows)
    on_box = np.abs(polygon) >= _BOX * (1 - 1e-9)
    unbounded = bool(on_box.any()) if len(polygon) else False
    if len(polygon) and not unbounded:
        # Redo the cuts in a box fitted to the set: its vertices then carry
        # the rounding of its own size, not of the far box's, which merged
        # vertices closer than 1e-9 of its span, and a polished corner has
        # moved: every vertex is checked again (at d = 300 one was 2.3e-6 b
        # outside).
        lo, hi = polygon.min(axis=0), polygon.max(axis=0)
        half = np.maximum(hi - lo, 1e-300)
        polygon = _polish(_clip_all(_box(half[0], half[1], (lo + hi) / 2), rows), rows)
        polygon, rows = _cut(plane, grid, table, tolerance, polygon, rows)
        on_box = np.zeros(polygon.shape, dtype=bool)
    return polygon, rows, on_box


def _fitted_window(plane, polygon, on_box, x_range, y_range):
    """``((x0, x1), (y0, y1))``: the window given, else the polygon's box with a margin.

    A bounded set gets 5 % of its size around it; a set that runs off
    gets its finite vertices' box grown by its own size (at least the
    scaled plane's unit, the set's natural size); an empty set the
    plane's unit around 0.
    """
    if len(polygon) == 0:
        return (x_range, y_range) if x_range is not None else (
            (-plane.sx, plane.sx), (-plane.sy, plane.sy))
    if x_range is not None:
        return (x_range, y_range)
    unbounded = bool(on_box.any())
    finite = polygon[~on_box.any(axis=1)] if unbounded else polygon
    if len(finite) == 0:
        finite = np.zeros((1, 2))
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    span = hi - lo
    if unbounded:
        grow = np.maximum(span, 1.0)
    else:
        grow = 0.05 * np.maximum(span, 1e-9 * np.maximum(np.abs(hi), 1.0))
    unscale = np.array([plane.sx, plane.sy])
    lo, hi = (lo - grow) * unscale, (hi + grow) * unscale
    return ((float(lo[0]), float(hi[0])), (float(lo[1]), float(hi[1])))


def _region_of(plane, x, y, polygon, on_box, window):
    """The :class:`PassiveRegion` of a non-empty scaled ``polygon``, clipped to ``window``.

    Its highest point is infinite where the highest vertex is a corner of
    the far box (nothing but the box stops the set going up).
    """
    full = polygon * np.array([plane.sx, plane.sy]) + 0.0     # no -0.0
    (x0, x1), (y0, y1) = window
    inside = (full[:, 0] >= x0) & (full[:, 0] <= x1) & (full[:, 1] >= y0) & (full[:, 1] <= y1)
    bounded = not on_box.any() and bool(inside.all())
    clipped = full
    for row in ((x0, -1.0, 0.0), (-x1, 1.0, 0.0), (y0, 0.0, -1.0), (-y1, 0.0, 1.0)):
        clipped = _clip_all(clipped, np.array([row]))
    top_vertex = int(np.argmax(polygon[:, 1]))
    if on_box[top_vertex].any():
        y_max, x_at = math.inf, math.nan
    else:
        top = full[:, 1].max()
        level = full[:, 1] >= top - 1e-12 * max(abs(top), 1e-300)
        y_max = float(top)
        x_at = float(0.5 * (full[level, 0].min() + full[level, 0].max()))
    return PassiveRegion(x, y, clipped if len(clipped) else np.zeros((0, 2)), bounded,
                         (float(x0), float(x1)), (float(y0), float(y1)), _area(clipped), y_max,
                         x_at)


def _with_halfplanes(region, halfplanes):
    object.__setattr__(region, "_halfplanes", halfplanes)
    return region


def _check_window(name, value):
    if value is None:
        return None
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a pair (low, high), got {value!r}") from None
    lo, hi = check_real(f"{name}[0]", lo), check_real(f"{name}[1]", hi)
    if not lo < hi:
        raise ValueError(f"{name} must have low < high, got ({lo!r}, {hi!r})")
    return lo, hi


def _windows(x_range, y_range):
    x_range, y_range = _check_window("x_range", x_range), _check_window("y_range", y_range)
    if (x_range is None) != (y_range is None):
        raise ValueError("give both x_range and y_range, or neither (the window is then "
                         "fitted to the set)")
    return x_range, y_range


def _check_stable_denominator(den, what):
    den = np.asarray(den, dtype=float)
    if den[0] == 0:
        raise ValueError(f"{what}: the denominator's leading coefficient vanishes at these values")
    roots = np.roots(den)
    if roots.size and np.max(np.abs(roots)) >= 1 - 1e-12:
        raise ValueError(f"{what} has a pole at |z| = {np.max(np.abs(roots)):.6g} >= 1: "
                         f"Colgate and Schenkel's condition needs a stable H(z)")


def _prepare_plane(base, slope_x, slope_y, den, d, period, damping, damping_axis, eps=0.0):
    """The :class:`_Plane` of a whole delay ``d`` (``eps = 0``), else the :class:`_FractionalPlane`."""
    length = max(len(base), len(slope_x), len(slope_y))
    pad = [np.pad(np.asarray(c, dtype=float), (length - len(c), 0)) for c in (base, slope_x, slope_y)]
    terms = [_laurent(c, den, d) for c in pad]     # one length and lowest power for the three
    p = np.stack([t[0] for t in terms], axis=1)
    powers = terms[0][1] + np.arange(len(p))
    # A term p z**k contributes p D_{-k} (k <= 0) or -p D_{k-1} (k >= 1).
    orders = np.where(powers <= 0, -powers, powers - 1)
    weights = np.where(powers <= 0, 1.0, -1.0)[:, None] * p
    at_one = float(np.sum(den))
    static = tuple(float(np.sum(c)) / at_one for c in pad)
    parts = (weights, orders.astype(float), np.asarray(den, dtype=float), period / 2,
             0.0 if damping_axis is not None else damping, damping_axis, static)
    if not eps:
        return _Plane(*parts)
    return _FractionalPlane(*parts, eps=eps, period=period, num=np.stack(pad), d=d)


# --------------------------------------------------------------------------
# Any loop


def passive_region(loop, x=None, y=None, *, damping="b", x_range=None, y_range=None, **values):
    """The passive set of a loop's environment, with its delay, in an ``(x, y)`` plane.

    Colgate and Schenkel's condition (module docstring) for
    ``H(z) = VE(z) z**-d``, the loop's environment behind its delay, with the
    device's viscous friction ``damping``:

        b > T / (2 (1 - cos theta)) Re{(1 - e^{-j theta}) H(e^{j theta})}

    for ``theta = w T`` in [0, pi], and ``H(1) >= 0``.  A delay of ``d + eps``
    samples (``0 < eps < 1``, the force held from ``(k + eps) T``) asks a 2x2
    matrix per angle to be positive semidefinite instead (module docstring):
    exact, not an interpolation between the whole delays.

    Parameters
    ----------
    loop : symstab.Loop
        The loop (used through its plant, environment, parameters and
        defaults).  Its plant must be a mass with viscous friction,
        ``1/(m s**2 + b s)`` with ``b`` the ``damping`` parameter: the
        theorem covers that device only.
    x, y : str, optional
        The plane: parameters of the environment (entering its numerator
        jointly affinely, not its denominator) or the damping itself;
        default the loop's ``plane``.
    damping : str
        The plant parameter that is the device's viscous friction.
    x_range, y_range : (float, float), optional
        The window; by default the polygon's bounding box with a 5 % margin
        (an unbounded set: its finite vertices' box grown by its own size).
    **values
        Values of the other parameters (``d``, ``T``, the damping, the
        environment's parameters), else the loop's defaults; the delay as
        ``d`` in samples (a fraction of a period included) or ``Td`` in
        seconds.  Other plant
        parameters (the mass) do not enter the condition and may be given.

    Returns
    -------
    PassiveRegion

    Raises
    ------
    TypeError, ValueError
        If a parameter is unknown, missing or out of range; if the plant is
        not ``1/(m s**2 + damping s)``; if ``x`` or ``y`` does not enter the
        condition affinely (named), or enters the environment's
        denominator; if the environment has a pole on or outside the unit
        circle.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)", plane=("B", "K"))
    >>> r = passive_region(loop, m=0.0128, b=0.0324, T=1e-3, d=0)
    >>> round(r.y_max, 9)          # K T / 2 + |B| < b: K_max = 2 b / T at B = 0
    64.8

    A spring behind half a sample needs ``b > (1 + sqrt(5)/2) K T / 2``:

    >>> spring = Loop("1/(m*s**2 + b*s)", "K")
    >>> cone = passive_region(spring, "b", "K", m=1.0, T=1.0, d=0.5)
    >>> cone.contains(1.0, [0.9442, 0.9443]).tolist()    # 1 / 1.05902 = 0.94427
    [True, False]
    """
    parameters, x, y = _check_passive_plane(loop, x, y, damping)
    x_range, y_range = _windows(x_range, y_range)

    symbols = {name: sp.Symbol(name) for name in parameters}
    environment = loop.environment
    env_symbols = {str(s): s for s in environment.free_symbols}
    plant_symbols = {str(s): s for s in loop.plant.free_symbols}
    symbols.update(env_symbols)
    symbols.update(plant_symbols)
    _check_device(loop, damping, symbols[damping])
    env_names = [n for n in parameters if n in env_symbols and n != "T"]
    d, eps, T, b, numbers = _passive_values(loop, parameters, x, y, damping, env_names, symbols,
                                       env_symbols, values)
    num, den = _environment_coefficients(environment, symbols, x, y, damping)

    def evaluate(coefficients, at):
        sub = dict(numbers)
        for name in (x, y):
            if name != damping:
                sub[symbols[name]] = at.get(name, 0)
        return np.array([float(sp.N(sp.sympify(c).subs(sub), 30)) for c in coefficients])

    base = evaluate(num, {})
    slopes = [evaluate(num, {name: 1}) - base if name != damping else np.zeros_like(base)
              for name in (x, y)]
    den_values = evaluate(den, {})
    if not (np.all(np.isfinite(base)) and np.all(np.isfinite(den_values))):
        raise ValueError("the environment is not finite at these values")
    _check_stable_denominator(den_values, f"the environment VE(z) = {environment}")
    damping_axis = (0 if x == damping else 1) if damping in (x, y) else None
    plane = _prepare_plane(base, slopes[0], slopes[1], den_values, d, T, b, damping_axis, eps)
    defaults = getattr(loop, "defaults", {})
    hints = tuple(abs(float(defaults[n])) if isinstance(defaults.get(n), (int, float)) else 0.0
                  for n in (x, y))
    return _solve(plane, x, y, x_range, y_range, hints)


def _check_passive_plane(loop, x, y, damping):
    """``(parameters, x, y)``: the loop's parameters and the plane, default the loop's, checked.

    The first of :func:`passive_region`'s checks: the damping and the
    plane's axes name parameters (not ``d`` or ``T``), two different ones.
    """
    if not isinstance(damping, str):
        raise TypeError(f"damping must be a parameter name (str), got {type(damping).__name__}")
    parameters = tuple(loop.parameters)
    if damping not in parameters:
        raise ValueError(f"damping: {damping!r} is not a parameter of this loop (parameters: "
                         f"{', '.join(parameters)}); name the device's viscous friction")
    if x is None and y is None and getattr(loop, "plane", None) is not None:
        x, y = loop.plane
    if x is None or y is None:
        raise TypeError("give the plane's parameters x and y (this loop has no default plane)")
    for axis, name in (("x", x), ("y", y)):
        if not isinstance(name, str):
            raise TypeError(f"{axis} must be a parameter name (str), got {type(name).__name__}")
        if name not in parameters or name in ("d", "T"):
            raise ValueError(f"{axis}: {name!r} is not a parameter the plane can take (parameters: "
                             f"{', '.join(p for p in parameters if p not in ('d', 'T'))})")
    if x == y:
        raise ValueError(f"the plane's parameters must differ, got {x!r} twice")
    return parameters, x, y


def _check_device(loop, damping, b_symbol):
    """A ValueError unless the loop's plant is the theorem's device: 1/G = m s**2 + b s exactly."""
    from ...symbolic import model

    inverse = sp.cancel(1 / loop.plant)
    try:
        poly = sp.Poly(inverse, model.s)
    except sp.PolynomialError:
        poly = None
    coefficients = poly.all_coeffs() if poly is not None else []
    if (len(coefficients) != 3 or coefficients[2] != 0 or sp.expand(coefficients[1] - b_symbol) != 0
            or coefficients[0].has(b_symbol)):
        raise ValueError(f"Colgate and Schenkel's condition covers a device 1/(m*s**2 + "
                         f"{damping}*s) (a mass with viscous friction {damping}); this loop's "
                         f"plant is {loop.plant}")


def _passive_values(loop, parameters, x, y, damping, env_names, symbols, env_symbols, values):
    """``(d, eps, T, b, numbers)``: the values the condition needs, checked (``b`` None on an axis).

    ``numbers`` maps the environment's symbols off the plane (and ``T``)
    to 30-digit floats.  Only the environment's parameters and the damping
    may be the plane's axes; a value is needed for each of them that is
    not one, for ``d`` and for ``T``.
    """
    from ...symbolic import model

    unknown = set(values) - set(parameters) - {"Td"}
    if unknown:
        raise TypeError(f"unknown parameter(s) {', '.join(sorted(unknown))}; parameters of this "
                        f"loop: {', '.join(parameters)}")
    if "Td" in values and "d" in values:
        raise TypeError("give the delay once: d (in samples) or Td (in seconds), not both")
    given = dict(getattr(loop, "defaults", {}))
    given.update(values)
    if "Td" in given and "d" not in values:
        T = check_real("T", given.get("T"), low=0.0, low_open=True)
        given["d"] = check_real("Td", given.pop("Td"), low=0.0) / T
    for axis in (x, y):
        given.pop(axis, None)
    for name in (x, y):
        if name != damping and name not in env_names:
            raise ValueError(f"parameter {name!r} does not enter the passivity condition (only "
                             f"the environment's parameters and the damping {damping!r} do)")
    need = ["d", "T"] + [damping] * (damping not in (x, y)) + [n for n in env_names
                                                                 if n not in (x, y)]
    missing = [n for n in need if n not in given]
    if missing:
        raise TypeError(f"missing value(s) for {', '.join(missing)}")
    d, fraction = split_delay(given["d"], name="d")
    T = check_real("T", given["T"], low=0.0, low_open=True)
    b = None
    if damping not in (x, y):
        b = check_real(damping, given[damping], low=0.0, low_open=True)
    numbers = {symbols[n]: sp.Float(repr(check_real(n, given[n])), 30)
               for n in env_names if n not in (x, y)}
    numbers[model.T] = sp.Float(repr(T), 30)
    if "T" in env_symbols:
        numbers[env_symbols["T"]] = sp.Float(repr(T), 30)
    return d, 0.0 if fraction is None else float(fraction), T, b, numbers


def _environment_coefficients(environment, symbols, x, y, damping):
    """``(num, den)``: VE(z)'s coefficients in z (SymPy), the plane's axes checked in them.

    An axis other than the damping must enter the numerator affinely (both
    jointly) and not the denominator: the passive set is then an
    intersection of half-planes.
    """
    from ...symbolic import model
    from ...symbolic.loop_assembly import is_affine

    num, den = sp.fraction(sp.cancel(sp.together(environment)))
    num = sp.Poly(sp.expand(num), model.z).all_coeffs()
    den = sp.Poly(sp.expand(den), model.z).all_coeffs()
    axes = [symbols[n] for n in (x, y) if n != damping]
    for name in (x, y):
        if name != damping and any(c.has(symbols[name]) for c in den):
            raise ValueError(f"parameter {name!r} enters the environment's denominator: the "
                             f"passive set is then not an intersection of half-planes")
    for name in (x, y):
        if name != damping and not is_affine(num, [symbols[name]]):
            raise ValueError(f"parameter {name!r} does not enter the environment affinely")
    if len(axes) == 2 and not is_affine(num, axes):
        raise ValueError(f"parameters {x!r} and {y!r} do not enter the environment jointly "
                         f"affinely (a product of the two appears)")
    return num, den
