"""theta_max certified: an enclosure proved by interval arithmetic.

theta_max is the first root of alpha(theta) in (0, pi], that is the first
positive root of the reduced equation
(:func:`symstab.symbolic.theta_max.reduced_equation`)::

    R(theta) = sin(theta) (gamma (1 + q u) + cos(phi)) + (delta + r u) sin(phi),
    u = 1 - cos(theta),  phi = (d + 1) theta,

because ``N_alpha = 2 delta**2 (Gamma - 1)**2 u R`` and ``u > 0`` on (0, pi].
:func:`theta_max_enclosure` returns two floats ``lo < hi`` and a proof, in
mpmath's interval arithmetic (outward rounding, every sine and cosine
enclosed), of three facts:

1. ``R > 0`` on ``(0, a]``: ``R(0) = 0`` exactly and ``R' > 0`` on ``[0, a]``;
2. ``R > 0`` on ``[a, lo]``: the interval is cut into pieces, and on each
   piece either the interval value of ``R`` is positive, or ``R'`` has one
   sign on it and ``R`` is positive at the end where it is smallest;
3. exactly one root in ``[lo, hi]``: ``R(lo) > 0 > R(hi)`` and ``R' < 0`` on
   ``[lo, hi]``.

So ``[lo, hi]`` holds the first positive root of ``R``, and it is simple.  If
``pi`` lies in ``[lo, hi]`` that root is ``pi`` itself (``R(pi) = 0`` for every
integer ``d``): the arc runs to theta = pi.

:func:`certify_theta_max` runs the same proof on an interval the caller
proposes and raises :class:`NotCertified` when it fails.
"""

import dataclasses
import functools
import math

import mpmath
from mpmath import iv
import sympy as sp

from .._validate import check_loop, check_real
from ..symbolic import model
from ..symbolic.theta_max import reduced_equation, theta_max
from .curves import arc_end_angle

__all__ = ["ThetaMaxEnclosure", "NotCertified", "theta_max_enclosure", "certify_theta_max"]

#: Working precision of the interval arithmetic, in bits (about 50 digits):
#: q and r cancel about 2 log10(1/delta) digits (12 at delta = 1e-6) and
#: R(lo) at one ulp from the root is 1e-16 of its terms.
_PREC = 170

#: The most pieces the proof of step 2 may cut [a, lo] into before it gives up.
MAX_PIECES = 20000


class NotCertified(ArithmeticError):
    """The interval arithmetic could not prove the enclosure."""


@dataclasses.dataclass(frozen=True)
class ThetaMaxEnclosure:
    """A proved enclosure ``lo <= theta_max <= hi``.

    Attributes
    ----------
    lo, hi : float
        The bounds; ``alpha > 0`` on ``(0, lo]`` and alpha has exactly one
        root in ``[lo, hi]``, a simple one (see the module docstring).
    gamma, d, delta : float, int, float
        The loop the proof is for.
    pieces : int
        How many subintervals of ``[a, lo]`` the proof of ``R > 0`` used.
    """

    lo: float
    hi: float
    gamma: float
    d: int
    delta: float
    pieces: int

    @property
    def width(self):
        """``hi - lo``."""
        return self.hi - self.lo

    @property
    def mid(self):
        """The midpoint, a float within ``width / 2`` of theta_max."""
        return 0.5 * (self.lo + self.hi)

    def __contains__(self, theta):
        return self.lo <= theta <= self.hi


@functools.lru_cache(maxsize=None)
def _qr_functions():
    eq = reduced_equation()
    args = (model.delta, model.Gamma)
    # Plain arithmetic in delta and Gamma: lambdify's "mpmath" printer leaves
    # the integer constants as Python ints, which interval numbers accept.
    return (sp.lambdify(args, eq.q, modules="mpmath"), sp.lambdify(args, eq.r, modules="mpmath"))


class _Reduced:
    """R and R' of one loop in interval arithmetic (at the caller's ``iv.prec``)."""

    def __init__(self, gamma, d, delta):
        self.gamma = iv.mpf(gamma)
        self.delta = iv.mpf(delta)
        self.rate = iv.mpf(d + 1)
        q_of, r_of = _qr_functions()
        Gamma = iv.exp(self.delta)
        self.q = q_of(self.delta, Gamma)
        self.r = r_of(self.delta, Gamma)

    def _parts(self, x):
        s = iv.sin(x)
        u = 2 * iv.sin(x / 2) ** 2      # 1 - cos(x) without cancellation near 0
        phi = self.rate * x
        return s, u, iv.sin(phi), iv.cos(phi)

    def value(self, x):
        s, u, sp_, cp = self._parts(x)
        return s * (self.gamma * (1 + self.q * u) + cp) + (self.delta + self.r * u) * sp_

    def slope(self, x):
        s, u, sp_, cp = self._parts(x)
        c = 1 - u
        return (c * (self.gamma * (1 + self.q * u) + cp) + s * s * self.gamma * self.q
                + (self.r * s - self.rate * s) * sp_ + self.rate * (self.delta + self.r * u) * cp)


def _interval(lo, hi):
    return iv.mpf([lo, hi])


def _positive(x):
    return x.a > 0


def _negative(x):
    return x.b < 0


def _prove(reduced, lo, hi, max_pieces):
    """Steps 1-3 of the module docstring; returns the piece count or raises NotCertified."""
    lo_, hi_ = iv.mpf(lo), iv.mpf(hi)
    if not _positive(reduced.value(lo_)):
        raise NotCertified(f"R(lo) > 0 not proved at lo = {lo!r}")
    if not _negative(reduced.value(hi_)):
        raise NotCertified(f"R(hi) < 0 not proved at hi = {hi!r}")
    if not _negative(reduced.slope(_interval(lo_, hi_))):
        raise NotCertified(f"R' < 0 on [{lo!r}, {hi!r}] not proved: the root may not be unique")
    # Step 1: R(0) = 0 and R' > 0 on [0, a].
    a = mpmath.mpf(min(lo, 0.25 / float(reduced.rate)))
    for _ in range(80):
        if _positive(reduced.slope(_interval(0, a))):
            break
        a /= 2
    else:
        raise NotCertified("R' > 0 near theta = 0 not proved (the arc is too short to certify)")
    # Step 2: R > 0 on [a, lo], piece by piece.
    width = mpmath.mpf(0.25) / reduced.rate
    stack = []
    x = mpmath.mpf(lo)
    while x > a:
        stack.append((max(a, x - width), x))
        x -= width
    pieces = 0
    while stack:
        x0, x1 = stack.pop()
        pieces += 1
        if pieces > max_pieces:
            raise NotCertified(f"R > 0 on (0, lo] not proved within {max_pieces} pieces")
        X = _interval(x0, x1)
        slope = reduced.slope(X)
        if _positive(slope) and _positive(reduced.value(iv.mpf(x0))):
            continue
        if _negative(slope) and _positive(reduced.value(iv.mpf(x1))):
            continue
        if _positive(reduced.value(X)):
            continue
        middle = (x0 + x1) / 2
        if _negative(reduced.value(iv.mpf(middle))):
            raise NotCertified(f"R < 0 at theta = {float(middle)!r} < lo: [lo, hi] does not hold "
                               f"the first root")
        if x1 - x0 < mpmath.mpf(2) ** -60 * x1:
            raise NotCertified(f"R > 0 near theta = {float(middle)!r} not proved (R is too close to 0)")
        stack.append((x0, middle))
        stack.append((middle, x1))
    return pieces


def _check_domain(gamma, d, delta):
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    # gamma + 1 + delta (d + 1) decides whether an arc enters alpha > 0; its
    # sign is decided exactly (the inputs are binary floats).
    with mpmath.workprec(4096):
        slope0 = mpmath.mpf(gamma) + 1 + mpmath.mpf(delta) * (d + 1)
    if slope0 <= 0:
        raise ValueError(f"gamma must be > -1 - delta (d + 1) = {-1 - delta * (d + 1)!r} for an arc "
                         f"to enter alpha > 0 (theta_max is undefined otherwise), got {gamma!r}")
    return gamma, d, delta


def certify_theta_max(lo, hi, *, gamma, d, delta, max_pieces=MAX_PIECES):
    """Prove that ``[lo, hi]`` encloses theta_max, or refuse.

    Parameters
    ----------
    lo, hi : float
        The proposed bounds, ``0 < lo < hi`` and ``lo < pi``.
    gamma : float
        ``M_w / m``, with ``gamma > -1 - delta (d + 1)`` (an arc exists).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    max_pieces : int
        The most subintervals the proof of ``alpha > 0`` on ``(0, lo]`` may use.

    Returns
    -------
    ThetaMaxEnclosure
        ``[lo, hi]`` with the facts of the module docstring proved.

    Raises
    ------
    NotCertified
        If any of those facts could not be proved (for instance ``[lo, hi]``
        holds a later root, or none).
    TypeError, ValueError
        If an argument has the wrong kind or is out of range.
    """
    gamma, d, delta = _check_domain(gamma, d, delta)
    lo = check_real("lo", lo, low=0.0, high=math.pi, low_open=True, high_open=True)
    hi = check_real("hi", hi, low=lo, low_open=True)
    old = iv.prec
    iv.prec = _PREC
    try:
        pieces = _prove(_Reduced(gamma, d, delta), lo, hi, max_pieces)
    finally:
        iv.prec = old
    return ThetaMaxEnclosure(lo=lo, hi=hi, gamma=gamma, d=d, delta=delta, pieces=pieces)


def _root_near(reduced_mp, guess):
    """Newton on R at 40 digits from ``guess``; a float bracket of 2 ulps around the result."""
    with mpmath.workdps(40):
        x = mpmath.mpf(guess)
        for _ in range(8):
            step = reduced_mp[0](x) / reduced_mp[1](x)
            x -= step
            if abs(step) < mpmath.mpf(10) ** -35 * abs(x):
                break
        f = float(x)
    return f


@functools.lru_cache(maxsize=None)
def _reduced_mp():
    eq = reduced_equation()
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    value = sp.lambdify(args, eq.R, modules="mpmath")
    slope = sp.lambdify(args, sp.diff(eq.R, model.theta), modules="mpmath")
    return value, slope


def theta_max_enclosure(*, gamma, d, delta, max_pieces=MAX_PIECES):
    """A certified enclosure of theta_max, two floats a few ulps apart.

    A candidate root (the float :func:`symstab.arc_end_angle`, refined by
    Newton's method on the reduced equation at 40 digits; the 30-digit scan
    :func:`symstab.symbolic.theta_max.theta_max` if that fails) is bracketed
    by its neighbouring floats and the bracket is proved with
    :func:`certify_theta_max`, widened up to 2**20 ulps if a bound sits too
    close to the root for its sign to be proved.

    Parameters
    ----------
    gamma : float
        ``M_w / m``, with ``gamma > -1 - delta (d + 1)``: otherwise alpha < 0
        just after theta = 0 and no arc, hence no theta_max, exists.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    max_pieces : int
        Passed to :func:`certify_theta_max`.

    Returns
    -------
    ThetaMaxEnclosure
        ``lo <= theta_max <= hi``, proved; its relative width is about 1e-15.

    Raises
    ------
    NotCertified
        If no candidate could be proved (an arc so short, or a root so
        nearly double, that 170-bit interval arithmetic cannot separate it).
    TypeError, ValueError
        If an argument has the wrong kind or is out of range.

    Examples
    --------
    >>> box = theta_max_enclosure(gamma=0.0, d=40, delta=0.00253125)
    >>> box.lo <= 0.0398589358788432 <= box.hi, box.width < 1e-16
    (True, True)
    """
    gamma, d, delta = _check_domain(gamma, d, delta)
    value, slope = _reduced_mp()
    with mpmath.workdps(40):
        g_, dl_ = mpmath.mpf(gamma), mpmath.mpf(delta)
        G_ = mpmath.exp(dl_)
    reduced_mp = (lambda t: value(t, g_, d, dl_, G_), lambda t: slope(t, g_, d, dl_, G_))
    failures = []
    for guess in (lambda: arc_end_angle(gamma=gamma, d=d, delta=delta),
                  lambda: theta_max(gamma=gamma, d=d, delta=delta)):
        start = guess()
        if not 0 < start <= math.pi:   # nan: the float scan saw no arc
            failures.append(f"candidate {start!r}")
            continue
        root = _root_near(reduced_mp, start)
        if not 0 < root < 4:
            failures.append(f"Newton from {start!r} left (0, pi]")
            continue
        for ulps in (1, 16, 2**10, 2**20):
            step = ulps * math.ulp(root)
            lo, hi = root - step, root + step
            if lo >= math.pi:
                break
            try:
                return certify_theta_max(lo, hi, gamma=gamma, d=d, delta=delta,
                                         max_pieces=max_pieces)
            except NotCertified as exc:
                failures.append(str(exc))
                if "first root" in str(exc) or "pieces" in str(exc):
                    break
    raise NotCertified(f"theta_max not certified for gamma={gamma!r}, d={d}, delta={delta!r}: "
                       + "; ".join(failures))
