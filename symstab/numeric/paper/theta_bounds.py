"""theta_max certified by interval arithmetic, and approximated in closed form.

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
2. ``R > 0`` on ``[a, lo]``: the interval is cut into pieces by bisection,
   and on each piece either ``R'`` has one sign and ``R`` is positive at the
   end where it is smallest, or the interval value of ``R`` (plain, or the
   mean-value form ``R(m) + R'(X) (X - m)``) is positive;
3. exactly one root in ``[lo, hi]``: ``R(lo) > 0 > R(hi)`` and ``R' < 0`` on
   ``[lo, hi]``.

So ``[lo, hi]`` holds the first positive root of ``R``, and it is simple.  If
``pi`` lies in ``[lo, hi]`` that root is ``pi`` itself (``R(pi) = 0`` for every
integer ``d``): the arc runs to theta = pi.

:func:`certify_theta_max` runs the same proof on an interval the caller
proposes and raises :class:`NotCertified` when it fails.

:func:`theta_max_approx` is the float closed form: a start from the model's
small-theta series and a fixed number of Newton steps on the phase form of
``R`` (:func:`symstab.symbolic.theta_max.phase_equation`).
"""

import dataclasses
import functools
import math

import mpmath
import sympy as sp
from mpmath import iv

from ..._validate import check_count, check_loop, check_real
from ...symbolic import model
from ...symbolic.theta_max import (
    phase_equation,
    q_sym,
    r_sym,
    reduced_qr,
    reduced_qr_functions,
    reduced_value_slope,
)
from .curves import arc_end_angle

__all__ = ["ThetaMaxEnclosure", "NotCertified", "theta_max_enclosure", "certify_theta_max",
           "theta_max_approx", "APPROX_WORST_RELATIVE_ERROR"]

#: Working precision of the interval arithmetic, in bits (about 50 digits):
#: R(lo) at one ulp from the root is 1e-16 of its terms.  q and r, which
#: cancel with a small delta, are enclosed at more (:func:`_qr_bits`).
_PREC = 170

#: The most pieces the proof of step 2 may cut [a, lo] into before it gives up.
MAX_PIECES = 20000


def _qr_bits(delta, bits):
    """Bits at which q, r from delta and Gamma = exp(delta) keep ``bits`` of their own.

    Their formulas cancel the O(1) terms down to q = O(1) and r = O(delta):
    about ``3 log2(1/delta)`` bits are lost for delta < 1 (at 40 digits
    Gamma = 1 exactly for delta = 1e-50, a division by zero).
    """
    return bits + 32 + (3 * math.ceil(-math.log2(delta)) if delta < 1 else 0)


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


class _Reduced:
    """R and R' of one loop in interval arithmetic (at the caller's ``iv.prec``).

    The formulas are :func:`~symstab.symbolic.theta_max.reduced_value_slope`'s,
    the ones the 30-digit and the float scans for theta_max use.  q and r
    are enclosed at the raised precision of :func:`_qr_bits` (their
    cancellation grows with log(1/delta)), the rest at the caller's.
    """

    def __init__(self, gamma, d, delta):
        self.gamma = iv.mpf(gamma)
        self.delta = iv.mpf(delta)
        self.rate = iv.mpf(d + 1)
        q_of, r_of = reduced_qr_functions()
        old = iv.prec
        iv.prec = _qr_bits(delta, old)
        try:
            wide_delta = iv.mpf(delta)
            Gamma = iv.exp(wide_delta)
            self.q = q_of(wide_delta, Gamma)
            self.r = r_of(wide_delta, Gamma)
        finally:
            iv.prec = old

    def _both(self, x):
        return reduced_value_slope(x, self.gamma, self.rate, self.delta, self.q, self.r,
                                   sin=iv.sin, cos=iv.cos)

    def value(self, x):
        return self._both(x)[0]

    def slope(self, x):
        return self._both(x)[1]


def _interval(lo, hi):
    return iv.mpf([lo, hi])


def _positive(x):
    return x.a > 0


def _negative(x):
    return x.b < 0


def _positive_near_zero(reduced, upper):
    """Step 1: an ``a <= upper`` with ``R' > 0`` on ``[0, a]``, so ``R > 0`` on ``(0, a]``."""
    a = mpmath.mpf(min(upper, 0.25 / float(reduced.rate)))
    for _ in range(80):
        if _positive(reduced.slope(_interval(0, a))):
            return a
        a /= 2
    raise NotCertified("R' > 0 near theta = 0 not proved (the arc is too short to certify)")


def _piece_positive(reduced, x0, x1):
    """True if ``R > 0`` on ``[x0, x1]`` is proved."""
    slope = reduced.slope(_interval(x0, x1))
    if _positive(slope) and _positive(reduced.value(iv.mpf(x0))):
        return True
    if _negative(slope) and _positive(reduced.value(iv.mpf(x1))):
        return True
    if _positive(reduced.value(_interval(x0, x1))):
        return True
    # The mean-value form R(m) + R'(X) (X - m): near a minimum of R that
    # almost touches zero R' is small on X, and this bound is quadratic in
    # the width where the plain one is linear (thousands of pieces fewer).
    middle = (x0 + x1) / 2
    return _positive(reduced.value(iv.mpf(middle)) + slope * _interval(x0 - middle, x1 - middle))


def _too_narrow(x0, x1):
    return x1 - x0 < mpmath.mpf(2) ** -60 * x1


def _prove(reduced, lo, hi, max_pieces):
    """Steps 1-3 of the module docstring; returns the piece count or raises NotCertified."""
    lo_, hi_ = iv.mpf(lo), iv.mpf(hi)
    if not _positive(reduced.value(lo_)):
        raise NotCertified(f"R(lo) > 0 not proved at lo = {lo!r}")
    if not _negative(reduced.value(hi_)):
        raise NotCertified(f"R(hi) < 0 not proved at hi = {hi!r}")
    if not _negative(reduced.slope(_interval(lo_, hi_))):
        raise NotCertified(f"R' < 0 on [{lo!r}, {hi!r}] not proved: the root may not be unique")
    a = _positive_near_zero(reduced, mpmath.mpf(lo))
    # Step 2: R > 0 on [a, lo], piece by piece.
    # One piece to start: bisection puts short pieces only where R is
    # small for its variation (in the jump regime R stays far from 0 on most
    # of (0, lo), and fixed pieces of a quarter period cost 10 times more).
    stack = [(a, mpmath.mpf(lo))]
    pieces = 0
    while stack:
        x0, x1 = stack.pop()
        pieces += 1
        if pieces > max_pieces:
            raise NotCertified(f"R > 0 on (0, lo] not proved within {max_pieces} pieces")
        if _piece_positive(reduced, x0, x1):
            continue
        middle = (x0 + x1) / 2
        if _negative(reduced.value(iv.mpf(middle))):
            raise NotCertified(f"R < 0 at theta = {float(middle)!r} < lo: [lo, hi] does not hold "
                               f"the first root")
        if _too_narrow(x0, x1):
            raise NotCertified(f"R > 0 near theta = {float(middle)!r} not proved (R is too close to 0)")
        stack.append((x0, middle))
        stack.append((middle, x1))
    return pieces


def _first_root_search(reduced, max_pieces):
    """The first root of R located by the same interval tests, left to right.

    Pieces of ``[a, pi + 1/(4 (d + 1))]`` are taken leftmost first: each is
    either proved positive, or found to hold a sign change with ``R' < 0``
    (its left end is the right end of a piece proved positive, so this is
    the first root), or bisected.  Returns the root to about 1e-17 (by
    bisection on point values); :func:`certify_theta_max` then proves it.
    This finds roots between two close ones that a sampling scan steps over.
    """
    a = _positive_near_zero(reduced, mpmath.pi)
    stack = [(a, mpmath.pi + mpmath.mpf(0.25) / reduced.rate)]
    pieces = 0
    while stack:
        x0, x1 = stack.pop()
        pieces += 1
        if pieces > max_pieces:
            break
        if _piece_positive(reduced, x0, x1):
            continue
        if _negative(reduced.value(iv.mpf(x1))) and _negative(reduced.slope(_interval(x0, x1))):
            for _ in range(70):
                middle = (x0 + x1) / 2
                value = reduced.value(iv.mpf(middle))
                if _positive(value):
                    x0 = middle
                elif _negative(value):
                    x1 = middle
                else:
                    break
            return float((x0 + x1) / 2)
        if _too_narrow(x0, x1):
            break
        middle = (x0 + x1) / 2
        stack.append((middle, x1))
        stack.append((x0, middle))
    raise NotCertified(f"the first root of R was not isolated within {pieces} pieces")


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


def _root_near(gamma, d, delta, guess):
    """Newton on R at 40 digits from ``guess``; the root as a float.

    R is :func:`~symstab.symbolic.theta_max.reduced_value_slope` with q, r
    taken at the precision of :func:`_qr_bits` (40 digits' worth), so a
    tiny delta neither cancels them to noise nor divides by Gamma - 1 = 0.
    """
    q_of, r_of = reduced_qr_functions()
    with mpmath.workprec(_qr_bits(delta, 133)):
        wide_delta = mpmath.mpf(delta)
        Gamma = mpmath.exp(wide_delta)
        q, r = q_of(wide_delta, Gamma), r_of(wide_delta, Gamma)
    with mpmath.workdps(40):
        g_, dl_, q, r = mpmath.mpf(gamma), mpmath.mpf(delta), +q, +r
        x = mpmath.mpf(guess)
        for _ in range(8):
            value, slope = reduced_value_slope(x, g_, d + 1, dl_, q, r,
                                               sin=mpmath.sin, cos=mpmath.cos)
            step = value / slope
            x -= step
            if abs(step) < mpmath.mpf(10) ** -35 * abs(x):
                break
        f = float(x)
    return f


def _search(gamma, d, delta, max_pieces):
    old = iv.prec
    iv.prec = _PREC
    try:
        return _first_root_search(_Reduced(gamma, d, delta), max_pieces)
    finally:
        iv.prec = old


def theta_max_enclosure(*, gamma, d, delta, max_pieces=MAX_PIECES):
    """A certified enclosure of theta_max, two floats a few ulps apart.

    A candidate root (the float :func:`symstab.arc_end_angle`; if that is
    not the first root, a left-to-right interval search that cannot step
    over a root; both refined by Newton's method on the reduced equation at
    40 digits) is bracketed by its neighbouring floats and the bracket is proved with
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
    >>> round(box.mid, 12), box.width < 1e-16
    (0.039858935879, True)
    """
    gamma, d, delta = _check_domain(gamma, d, delta)
    failures = []
    for guess in (lambda: arc_end_angle(gamma=gamma, d=d, delta=delta),
                  lambda: _search(gamma, d, delta, max_pieces)):
        try:
            start = guess()
        except NotCertified as exc:
            failures.append(str(exc))
            continue
        if not 0 < start <= math.pi:   # nan: the float scan saw no arc
            failures.append(f"candidate {start!r}")
            continue
        root = _root_near(gamma, d, delta, start)
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


# -- The closed-form approximation -------------------------------------------

#: Newton steps of :func:`theta_max_approx` after its start.
APPROX_STEPS = 8

#: The bound the tests hold :func:`theta_max_approx` to over gamma in [-1, 3],
#: d in 0..200, delta in [1e-6, 1]: 100 times its measured worst relative
#: error, 8.8e-16 (benchmarks/bench_theta_max_approx.py; a margin for another
#: platform's libm, not for a different algorithm).
APPROX_WORST_RELATIVE_ERROR = 1e-13


@functools.lru_cache(maxsize=None)
def _phase_functions():
    """Float A, A', B, B', C, C' of the phase form, and kappa."""
    eq = phase_equation()
    theta = model.theta
    args = (theta, model.gamma, model.delta, q_sym, r_sym)
    parts = [eq.A, sp.diff(eq.A, theta), eq.B, sp.diff(eq.B, theta), eq.C, sp.diff(eq.C, theta)]
    kappa = sp.lambdify((model.gamma, model.d, model.delta, q_sym, r_sym), eq.kappa, modules="math")
    return sp.lambdify(args, parts, modules="math"), kappa


class _Phase:
    """``h = (d+1) theta - psi - sign arccos(x) - 2 pi k`` and its slope, in floats."""

    def __init__(self, gamma, d, delta):
        self.gamma, self.rate, self.delta = gamma, d + 1, delta
        self.q, self.r = reduced_qr(delta)
        self.parts = _phase_functions()[0]

    def window(self, t):
        """``(C - rho, d(C - rho)/dtheta)``: positive where R cannot vanish."""
        A, Ap, B, Bp, C, Cp = self.parts(t, self.gamma, self.delta, self.q, self.r)
        rho = math.hypot(A, B)
        return C - rho, Cp - (A * Ap + B * Bp) / rho

    def phase(self, t, k=0, sign=1):
        """``(h, dh/dtheta, x')``, or None where ``|x| >= 1`` (no root of R there)."""
        A, Ap, B, Bp, C, Cp = self.parts(t, self.gamma, self.delta, self.q, self.r)
        rho2 = A * A + B * B
        # rho**2 - C**2 = B**2 + A**2 (1 + g)(1 - g) with g = gamma (1 + q u),
        # each factor summed from exact parts: at gamma = -1 and a short arc
        # x = -C/rho is 1 - 1e-7, and arccos(x) from a rounded x loses half
        # its digits.
        u = 2 * math.sin(t / 2) ** 2
        gqu = self.gamma * self.q * u
        sine2 = B * B + A * A * ((1 + self.gamma) + gqu) * ((1 - self.gamma) - gqu)
        if not sine2 > 0:
            return None
        rho = math.sqrt(rho2)
        sine = math.sqrt(sine2)
        x_slope = -(Cp - C * (A * Ap + B * Bp) / rho2) / rho
        h = self.rate * t - math.atan2(B, A) - sign * math.atan2(sine, -C) - 2 * math.pi * k
        slope = self.rate - (A * Bp - B * Ap) / rho2 + sign * x_slope * rho / sine
        return h, slope, x_slope


def _first_branch(ph, start, steps):
    """Newton on k = 0 from ``start``; None if an iterate leaves the domain or has not converged."""
    t, step = start, math.inf
    for _ in range(steps):
        got = ph.phase(t)
        if got is None:
            return None
        step = got[0] / got[1]
        t -= step
        if not 0 < t <= math.pi:
            return None
    return t if abs(step) <= 1e-6 * t else None


def _after_window(ph, steps):
    """The first root after the window where ``C > rho`` (heavy virtual mass).

    The window closes at theta_c (``C = rho``, Newton from its delta -> 0
    value ``u = (1/gamma - 1)/q``).  Beyond it the band ``|phi - psi - pi|
    < pi - arccos(x)`` where R < 0 opens like ``sqrt(theta - theta_c)``: R's
    first root is where the band first meets the phase, either catching it
    from behind (sign -1) or at the next band (sign +1).  The start solves
    that meeting with the band's square-root growth, and Newton runs in
    ``y = sqrt(theta - theta_c)`` where the square root is regular.
    """
    u = min(2.0, (1 / ph.gamma - 1) / ph.q)
    tc = math.acos(1 - u)
    for _ in range(4):
        value, slope = ph.window(tc)
        tc -= value / slope
    A, Ap, B, Bp, C, Cp = ph.parts(tc, ph.gamma, ph.delta, ph.q, ph.r)
    rho2 = A * A + B * B
    rho = math.sqrt(rho2)
    x_slope = -(Cp - C * (A * Ap + B * Bp) / rho2) / rho
    drift = ph.rate - (A * Bp - B * Ap) / rho2
    behind = ph.rate * tc - math.atan2(B, A) - math.pi
    k = math.floor(behind / (2 * math.pi))
    offset = behind - 2 * math.pi * k
    disc = 2 * x_slope - 4 * drift * offset
    if disc >= 0:
        sign, y = -1, (math.sqrt(2 * x_slope) - math.sqrt(disc)) / (2 * drift)
    else:
        sign, y = 1, (-math.sqrt(2 * x_slope)
                      + math.sqrt(2 * x_slope + 4 * drift * (2 * math.pi - offset))) / (2 * drift)
    if tc + y * y >= math.pi:
        return math.pi
    for _ in range(steps):
        got = ph.phase(tc + y * y, k + 1, sign)
        if got is None:
            return math.nan
        y -= got[0] / (2 * y * got[1])
    return min(math.pi, tc + y * y)


def theta_max_approx(*, gamma, d, delta, steps=APPROX_STEPS):
    """theta_max in closed form: a derived start and a fixed number of Newton steps.

    No fitted constant: the start is the smaller of the paper's
    ``pi / (2 (d + 1))`` and the short-arc end ``sqrt(slope0 / kappa)`` from
    the model's small-theta series (:class:`~symstab.symbolic.theta_max.PhaseEquation`),
    and ``steps`` Newton steps solve ``(d + 1) theta = psi(theta) +
    arccos(x(theta))``.  When a heavy virtual mass (gamma > 1) opens a
    window where R cannot vanish before that root, the root after the
    window is taken instead (see ``_after_window``).

    Measured worst relative error against the certified enclosure
    (:func:`theta_max_enclosure`) over gamma in [-1, 3], d in 0..200, delta in
    [1e-6, 1], with 8 steps: 8.8e-16 (at gamma = 2.069, d = 2, delta =
    0.861; median 0) on 4512 points, a 14 x 12 x 9 grid with the box's
    corners and 3000 seeded random points (``python
    benchmarks/bench_theta_max_approx.py --grid full --random 3000``); with
    6 steps it was 6.3e-11 at the same point.  :data:`APPROX_WORST_RELATIVE_ERROR`
    is the bound the tests hold it to.  On the same points the paper's one
    Newton step (eq. (12), gamma = 0 only) errs by up to 5.4 (d = 3, delta =
    0.3; 5.3e-3 at d = 40 on the paper's device), and the same step with the
    gamma terms kept by up to 560 (gamma = -1, d = 1, delta = 1e-6).

    Not covered by that measurement: the thin sets of parameters where a
    dip of alpha just touches zero, so that theta_max jumps to a later lobe.
    At d = 200, delta = 0.00702 the jump is at gamma = 2.48192475982281445
    (certified on both sides); this form takes the later root from 7.1e-11
    below it, an error of 1.7 % in that sliver.  Nor is anything outside
    the box.

    Parameters
    ----------
    gamma : float
        ``M_w / m``, with ``gamma > -1 - delta (d + 1)`` (an arc exists).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.
    steps : int
        Newton steps after the start (the measured error is for 8).

    Returns
    -------
    float
        The approximate theta_max in (0, pi]; ``nan`` if the Newton
        iterates leave the domain (never seen in the box).

    Raises
    ------
    TypeError, ValueError
        If an argument has the wrong kind or is out of range.

    Examples
    --------
    >>> round(theta_max_approx(gamma=0.0, d=40, delta=0.00253125), 12)
    0.039858935879
    """
    gamma, d, delta = _check_domain(gamma, d, delta)
    steps = check_count("steps", steps, 1)
    ph = _Phase(gamma, d, delta)
    kappa = _phase_functions()[1](gamma, d, delta, ph.q, ph.r)
    slope0 = gamma + 1 + delta * (d + 1)
    start = math.pi / (2 * (d + 1))
    if kappa > 0:
        start = min(start, math.sqrt(slope0 / kappa))
    root = _first_branch(ph, start, steps)
    if root is None and gamma > 1:
        root = _after_window(ph, steps)
    return math.nan if root is None else root
