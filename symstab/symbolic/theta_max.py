"""Where a boundary arc ends: theta_max, the first positive root of alpha(theta).

The boundary is traced from theta = 0 (where alpha = 0, beta = -delta) to the
first theta > 0 at which alpha returns to zero.  The denominator of alpha is
``|N(exp(j theta))|**2 sin(theta)``, positive on (0, pi), so theta_max is the
first positive root of the numerator ``N_alpha(theta)``.

Three forms are derived here:

* :func:`closed_form_d0` -- for d = 0, ``N_alpha / sin(theta)`` is a
  polynomial in ``u = 1 - cos(theta)`` of the form ``u (A u + B)``; the
  nontrivial root gives ``theta_max = 2 atan(sqrt(u / (2 - u)))``.
* :func:`newton_form_gamma0` -- for gamma = 0, ``N_alpha / delta**2`` is
  written as ``A_S sin((d+1) theta) + A_D sin(d theta)`` and one Newton step
  from ``theta_0 = pi / (2 (d + 1))`` approximates the root.
* :func:`theta_max` -- the exact first positive root for any (gamma, d,
  delta), isolated by :func:`first_sign_change` and refined by mpmath's
  Anderson-Bjorck solver.

:func:`first_sign_change` is the one scan for the first root of the reduced
equation R (:func:`reduced_equation`) in every arithmetic: it proves each
cell before the root free of roots with a bound on ``|R''|``
(:func:`reduced_curvature`), so it cannot step over a narrow dip of alpha
below zero nor a root next to theta = pi.  The float
:func:`symstab.numeric.paper.curves.arc_end_angle` uses it too, and the interval
enclosure (:mod:`symstab.numeric.paper.theta_bounds`) shares its R
(:func:`reduced_value_slope`) and q, r.
"""

import dataclasses
import functools
import math

import mpmath
import numpy as np
import sympy as sp

from .._validate import check_loop
from . import model
from .boundary import boundary
from .forms import NO_DOCSTRING, E, exponential_form, trig_form, w
from .small_theta import taylor_coefficients

__all__ = [
    "ClosedFormD0", "NewtonFormGamma0",
    "closed_form_d0", "newton_form_gamma0", "theta_max", "theta_max_newton",
    "alpha_numerator_function", "ReducedEquation", "reduced_equation",
    "PhaseEquation", "phase_equation",
    "reduced_qr", "reduced_qr_functions", "reduced_value_slope", "reduced_curvature",
    "first_sign_change", "RootNotIsolated",
]

#: u = 1 - cos(theta), the variable of the d = 0 closed form.
u = sp.Symbol("u", nonnegative=True)


@dataclasses.dataclass(frozen=True)
class ClosedFormD0:
    """theta_max for d = 0: the nontrivial root of ``A u + B``.

    Attributes
    ----------
    A, B : sympy.Expr
        ``N_alpha / sin(theta) = k u (A u + B)`` at d = 0, for a constant k.
    u_root : sympy.Expr
        ``-B / A``; it lies in (0, 2) when the arc ends before theta = pi.
    theta_max : sympy.Expr
        ``2 atan(sqrt(u_root / (2 - u_root)))``.
    """

    A: sp.Expr
    B: sp.Expr
    u_root: sp.Expr
    theta_max: sp.Expr


@functools.lru_cache(maxsize=None)
def closed_form_d0():
    """Derive the d = 0 closed form of theta_max (any gamma)."""
    num = boundary().alpha_numerator.subs(model.d, 0)
    c, sn = sp.symbols("c sn")
    poly = sp.Poly(sp.expand(sp.expand_trig(num)).subs(
        {sp.sin(model.theta): sn, sp.cos(model.theta): c}), sn)
    reduced = sp.expand(sp.Add(*[co * sn ** (k % 2) * (1 - c**2) ** (k // 2)
                                 for (k,), co in poly.terms()]))
    quotient, remainder = sp.div(reduced, sn, sn)
    if remainder != 0:
        raise AssertionError("N_alpha at d = 0 is not sin(theta) times a polynomial in cos(theta)")
    in_u = sp.Poly(sp.expand(quotient.subs(c, 1 - u)), u)
    if in_u.degree() != 2 or in_u.coeff_monomial(1) != 0:
        raise AssertionError(f"N_alpha / sin(theta) at d = 0 is not u (A u + B): {in_u}")
    k = sp.Poly(in_u.as_expr(), model.gamma, model.delta, model.Gamma, u).LC()
    A = sp.factor(in_u.coeff_monomial(u**2) / k)
    B = sp.factor(in_u.coeff_monomial(u) / k)
    root = sp.factor(-B / A)
    return ClosedFormD0(A=A, B=B, u_root=root,
                        theta_max=2 * sp.atan(sp.sqrt(root / (2 - root))))


@dataclasses.dataclass(frozen=True)
class NewtonFormGamma0:
    """One Newton step for theta_max at gamma = 0 (any d).

    Attributes
    ----------
    phi : sympy.Expr
        ``N_alpha / delta**2`` at gamma = 0.
    A_S, A_D : sympy.Expr
        ``phi = A_S sin((d+1) theta) + A_D sin(d theta)``.
    theta0 : sympy.Expr
        ``pi / (2 (d + 1))``, where ``sin((d+1) theta)`` peaks.
    theta_newton : sympy.Expr
        ``theta0 - phi(theta0) / phi'(theta0)``.
    """

    phi: sp.Expr
    A_S: sp.Expr
    A_D: sp.Expr
    theta0: sp.Expr
    theta_newton: sp.Expr


@functools.lru_cache(maxsize=None)
def newton_form_gamma0():
    """Derive the Newton-step form of theta_max for gamma = 0."""
    theta, d = model.theta, model.d
    phi = sp.expand(boundary().alpha_numerator.subs(model.gamma, 0) / model.delta**2)
    # phi = F E + conj(F) / E; with cos(d theta) = (sin((d+1) theta) -
    # sin(d theta) cos(theta)) / sin(theta) it becomes A_S S1 + A_D S0.
    laurent = sp.Poly(sp.expand(exponential_form(phi) * E), E)
    F = laurent.coeff_monomial(E**2)
    Fc = laurent.coeff_monomial(1)
    re_F, im_F = sp.expand((F + Fc) / 2), sp.expand((F - Fc) / (2 * sp.I))
    sin_t = (w**2 - w**-2) / (2 * sp.I)
    cos_t = (w**2 + w**-2) / 2
    # Collected in delta (A_S = delta B + ...), which also keeps the form
    # that srepr round-trips (factor() would give Mul(-2, Add(...))).
    A_S = sp.collect(sp.expand(trig_form(sp.cancel(2 * re_F / sin_t))), model.delta, sp.factor)
    A_D = sp.factor(trig_form(sp.cancel(-2 * im_F - 2 * re_F * cos_t / sin_t)))
    form = A_S * sp.sin((d + 1) * theta) + A_D * sp.sin(d * theta)
    theta0 = sp.pi / (2 * (d + 1))
    step = (form / sp.diff(form, theta)).subs(theta, theta0)
    return NewtonFormGamma0(phi=phi, A_S=A_S, A_D=A_D, theta0=theta0,
                            theta_newton=theta0 - step)


@functools.lru_cache(maxsize=None)
def _alpha_numerator_gamma():
    # N_alpha(theta, gamma, d, delta, Gamma) with its common subexpressions
    # (the sines, the powers of Gamma) evaluated once: five times faster
    # than the plain form, which recomputes exp(delta) in every term.
    args = (model.theta, model.gamma, model.d, model.delta, model.Gamma)
    return sp.lambdify(args, boundary().alpha_numerator, modules="mpmath", cse=True,
                       **NO_DOCSTRING)


@functools.lru_cache(maxsize=None)
def alpha_numerator_function():
    """mpmath function ``f(theta, gamma, d, delta)`` of ``N_alpha``."""
    f = _alpha_numerator_gamma()
    return lambda theta, gamma, d, delta: f(theta, gamma, d, delta, mpmath.exp(delta))


def theta_max(*, gamma, d, delta, dps=30):
    """Exact theta_max: the first root of alpha(theta) in (0, pi].

    The first positive root of the reduced equation ``R`` (``N_alpha = scale
    u R`` with ``scale u > 0`` on (0, pi], :class:`ReducedEquation`), isolated
    by :func:`first_sign_change`: every grid cell before it is proved free of
    roots by the bound on ``|R''|`` of :func:`reduced_curvature` (halved where it
    is not), so no root is stepped over, however narrow the dip of alpha below
    zero or close to theta = pi; mpmath's Anderson-Bjorck solver then refines
    it at ``dps`` digits.

    Parameters
    ----------
    gamma : float
        Dimensionless virtual mass M_w / m.
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``: the derivation's N_alpha carries a factor that
        vanishes at delta = 0, so this reference refuses it (the float
        :func:`symstab.arc_end_angle` handles delta = 0).
    dps : int
        mpmath working precision.

    Returns
    -------
    float
        theta_max in (0, pi]; ``pi`` when alpha does not return to zero
        before theta = pi, and ``nan`` when alpha < 0 just after theta = 0
        (``gamma + 1 + delta (d + 1) <= 0``: no arc enters alpha > 0; see
        :mod:`symstab.symbolic.small_theta`).

    Raises
    ------
    TypeError, ValueError
        If an argument has the wrong kind or is out of range.
    RootNotIsolated
        If R is so close to zero over so long a stretch that the scan's
        budget of points runs out (never seen).

    Examples
    --------
    >>> round(theta_max(gamma=0.0, d=0, delta=0.0324e-3 / 0.0128), 4)
    1.5725
    """
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    rate = d + 1
    # gamma + 1 + delta (d + 1) = R'(0) decides whether an arc enters alpha
    # > 0; decided exactly (the inputs are binary floats).
    with mpmath.workprec(4096):
        if not mpmath.mpf(gamma) + 1 + mpmath.mpf(delta) * rate > 0:
            return float("nan")
    # R has no O(theta**3) cancellation (N_alpha has): 10 guard digits do
    # for R, and q, r cancel about 4 log10(1/delta) more.
    work = dps + 10
    with mpmath.workdps(work + 10 + int(4 * max(0.0, -math.log10(delta)))):
        g_, dl_ = mpmath.mpf(gamma), mpmath.mpf(delta)
        q_of, r_of = reduced_qr_functions()
        G_ = mpmath.exp(dl_)
        q_, r_ = q_of(dl_, G_), r_of(dl_, G_)
    with mpmath.workdps(work):
        q_, r_ = +q_, +r_
        eps = mpmath.mpf(2) ** (-mpmath.mp.prec)

        def evaluate(ts):
            rows = [reduced_value_slope(t, g_, rate, dl_, q_, r_, sin=mpmath.sin, cos=mpmath.cos, eps=eps)
                    for t in ts]
            return tuple(np.array([row[j] for row in rows], dtype=object) for j in range(4))

        slope0 = g_ + 1 + dl_ * rate
        n = max(64, 4 * rate)

        def points(ks):
            return np.array([mpmath.pi * int(k) / n for k in ks], dtype=object)

        found = first_sign_change(evaluate, points, n, slope0=slope0,
                                  slope0_error=4 * eps * (abs(g_ + 1) + dl_ * rate),
                                  curvature=reduced_curvature(g_, rate, dl_, q_, r_), root_at_end=True,
                                  chunk=32)
        if found is None:
            return float(mpmath.pi)
        lo, hi = found

        def g(t):
            return reduced_value_slope(t, g_, rate, dl_, q_, r_, sin=mpmath.sin, cos=mpmath.cos)[0]

        if lo == hi or g(hi) == 0:
            return float(hi)
        root = mpmath.findroot(g, (lo, hi), solver="anderson", verify=False)
        if not lo <= root <= hi:
            root = mpmath.findroot(g, (lo, hi), solver="bisect", verify=False)
        return float(root)


def theta_max_newton(*, d, delta):
    """theta_max for gamma = 0 by the one-step Newton form (approximate).

    One Newton step on ``N_alpha / delta**2 = A_S sin((d+1) theta) + A_D
    sin(d theta)`` from ``theta_0 = pi / (2 (d + 1))``
    (:func:`newton_form_gamma0`, the paper's eq. (12)).

    Parameters
    ----------
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m > 0``.

    Returns
    -------
    float
        The Newton estimate of theta_max; :func:`theta_max` gives the exact
        root.

    Raises
    ------
    TypeError, ValueError
        If ``d`` or ``delta`` has the wrong kind or is out of range
        (``delta = 0`` included).
    """
    _, d, delta = check_loop(0.0, d, delta, zero_delta=False)
    # The Newton quotient cancels: evaluate at 30 digits from the exact
    # binary value of delta (a 15-digit Float lost up to 1e-7 at d = 100).
    with mpmath.workdps(30):
        dl = mpmath.mpf(delta)
        return float(_newton_function()(d, dl, mpmath.exp(dl)))


@functools.lru_cache(maxsize=None)
def _newton_function():
    return sp.lambdify((model.d, model.delta, model.Gamma), newton_form_gamma0().theta_newton,
                       modules="mpmath", **NO_DOCSTRING)


# -- The reduced equation: theta_max in the general case -------------------

@dataclasses.dataclass(frozen=True)
class ReducedEquation:
    """N_alpha with its positive factors divided out, for any (gamma, d, delta).

    With ``u = 1 - cos(theta)`` and ``phi = (d + 1) theta``::

        N_alpha = scale * u * R(theta)
        R(theta) = sin(theta) (gamma (1 + q u) + cos(phi)) + (delta + r u) sin(phi)

    ``scale = 2 delta**2 (Gamma - 1)**2 > 0`` and ``u > 0`` on (0, pi], so
    theta_max is the first positive root of ``R``.  ``R`` has one
    high-frequency pair, ``cos(phi)`` and ``sin(phi)``, where ``N_alpha``
    has five sines ``sin((d + k) theta)`` that cancel to ``O(theta**3)``
    near 0, so interval arithmetic and Newton's method work well on it; and
    ``R(theta) = slope0 theta + O(theta**3)`` with ``slope0 = gamma + 1 +
    delta (d + 1)``: an arc enters alpha > 0 exactly when ``slope0 > 0``.

    Attributes
    ----------
    scale, q, r : sympy.Expr
        Functions of ``delta`` and ``Gamma`` only (``q -> -1/2`` and
        ``r -> 0`` as ``delta -> 0``).
    R : sympy.Expr
        ``R(theta)`` in theta, gamma, d, delta, Gamma.
    slope0 : sympy.Expr
        ``dR/dtheta`` at theta = 0.
    """

    scale: sp.Expr
    q: sp.Expr
    r: sp.Expr
    R: sp.Expr
    slope0: sp.Expr


@functools.lru_cache(maxsize=None)
def reduced_equation():
    """Derive :class:`ReducedEquation` from the boundary's ``N_alpha``.

    Every ``sin(k theta + d theta)`` of ``N_alpha`` is written around
    ``phi = (d + 1) theta`` as ``sin(phi) cos(j theta) + cos(phi) sin(j
    theta)``, and the low-frequency factors as polynomials in ``u`` by
    Chebyshev's polynomials; the result is proved equal to ``N_alpha`` by the
    exponential form (exactly, for symbolic d).

    Raises
    ------
    AssertionError
        If the derivation no longer has the shape stated in
        :class:`ReducedEquation`.
    """
    theta, d, delta, Gamma, gamma = model.theta, model.d, model.delta, model.Gamma, model.gamma
    num = sp.expand(boundary().alpha_numerator)
    by_rate = {}
    for sine in num.atoms(sp.sin):
        rate = sp.expand(sine.args[0] / theta)
        by_rate[rate] = sp.expand(by_rate.get(rate, 0) + num.coeff(sine))
    c = 1 - u
    S = C = P = sp.S.Zero
    for rate, coeff in by_rate.items():
        offset = sp.expand(rate - (d + 1))
        if rate.has(d):
            if not offset.is_integer:
                raise AssertionError(f"N_alpha has sin({rate} theta): not an integer offset from d + 1")
            j = int(offset)
            S += coeff * sp.chebyshevt(abs(j), c)
            if j:
                C += coeff * sp.sign(j) * sp.chebyshevu(abs(j) - 1, c)
        else:
            if not (rate.is_integer and rate > 0 and sp.expand(coeff / gamma).free_symbols <= {delta, Gamma}):
                raise AssertionError(f"N_alpha has {coeff} sin({rate} theta): not gamma times a harmonic")
            P += coeff / gamma * sp.chebyshevu(int(rate) - 1, c)
    P, S, C = (sp.Poly(sp.expand(e), u).all_coeffs()[::-1] for e in (P, S, C))
    P, S, C = ([sp.factor(x) for x in e] + [0] * (3 - len(e)) for e in (P, S, C))
    scale = P[1]
    if not (P[0] == S[0] == C[0] == C[2] == 0 and len(P) == len(S) == len(C) == 3
            and sp.expand(C[1] - scale) == 0 and sp.expand(S[1] - delta * scale) == 0
            and sp.factor(scale - 2 * delta**2 * (Gamma - 1) ** 2) == 0):
        raise AssertionError(f"N_alpha is not scale u R(theta): P={P}, S={S}, C={C}")
    q, r = sp.factor(P[2] / scale), sp.factor(S[2] / scale)
    phi = (d + 1) * theta
    uu = 1 - sp.cos(theta)
    # scale u R, written with the polynomial coefficients (q and r divide by scale).
    rebuilt = (sp.sin(theta) * (gamma * (P[1] * uu + P[2] * uu**2) + C[1] * uu * sp.cos(phi))
               + (S[1] * uu + S[2] * uu**2) * sp.sin(phi))
    if sp.expand(exponential_form(num - rebuilt)) != 0:
        raise AssertionError("scale u R(theta) differs from N_alpha")
    R = sp.sin(theta) * (gamma * (1 + q * uu) + sp.cos(phi)) + (delta + r * uu) * sp.sin(phi)
    slope0 = sp.factor(sp.diff(R, theta).subs(theta, 0))
    return ReducedEquation(scale=scale, q=q, r=r, R=R, slope0=slope0)


#: Placeholders for the functions q(delta), r(delta) of :class:`ReducedEquation`
#: in :class:`PhaseEquation`: a float evaluator supplies them in a form that
#: does not cancel at small delta.
q_sym, r_sym = sp.symbols("q r", real=True)


@dataclasses.dataclass(frozen=True)
class PhaseEquation:
    """The reduced equation as a phase condition, the start of theta_max_approx.

    ``R = A cos(phi) + B sin(phi) + C`` with ``phi = (d + 1) theta``,
    ``u = 2 sin(theta/2)**2 = 1 - cos(theta)`` and::

        A = sin(theta),  B = delta + r u,  C = gamma (1 + q u) sin(theta),

    low-frequency functions of theta only.  With ``rho = hypot(A, B)``,
    ``psi = atan2(B, A)`` and ``x = -C / rho``, ``R = rho (cos(phi - psi) -
    x)``, so wherever ``|x| <= 1`` the roots of R solve::

        (d + 1) theta = psi(theta) +- arccos(x(theta)) + 2 pi k

    for an integer k: a fixed-point form whose right side varies slowly
    with theta, on which Newton's method converges from far away.

    Attributes
    ----------
    A, B, C : sympy.Expr
        In theta, gamma, delta and the placeholders :data:`q_sym`, :data:`r_sym`.
    kappa : sympy.Expr
        ``R = slope0 theta - kappa theta**3 + O(theta**5)`` (in d, gamma,
        delta, q, r); ``sqrt(slope0 / kappa)`` estimates a short arc's end.
    """

    A: sp.Expr
    B: sp.Expr
    C: sp.Expr
    kappa: sp.Expr


@functools.lru_cache(maxsize=None)
def phase_equation():
    """Derive :class:`PhaseEquation` from :func:`reduced_equation`.

    Raises
    ------
    AssertionError
        If ``A cos(phi) + B sin(phi) + C`` is not the reduced ``R``.
    """
    theta, d, gamma = model.theta, model.d, model.gamma
    eq = reduced_equation()
    # u = 2 sin(theta/2)**2, not 1 - cos(theta): a float evaluator keeps
    # its relative accuracy near theta = 0, where short arcs end.
    uu = 2 * sp.sin(theta / 2) ** 2
    A = sp.sin(theta)
    B = model.delta + r_sym * uu
    C = gamma * (1 + q_sym * uu) * sp.sin(theta)
    phi = (d + 1) * theta
    R = A * sp.cos(phi) + B * sp.sin(phi) + C
    if sp.cancel(sp.expand(exponential_form(R.subs({q_sym: eq.q, r_sym: eq.r}) - eq.R))) != 0:
        raise AssertionError("A cos(phi) + B sin(phi) + C is not the reduced equation")
    series = taylor_coefficients(R, 3)
    if sp.expand(series[1] - eq.slope0) != 0 or series[0] != 0 or series[2] != 0:
        raise AssertionError(f"R does not start as slope0 theta: {series}")
    return PhaseEquation(A=A, B=B, C=C, kappa=sp.factor(-series[3]))


# -- The first root of R: a scan that cannot step over one ------------------
#
# theta_max (30 digits, here), the float arc_end_angle (symstab.numeric.paper.curves)
# and the certified enclosure (symstab.numeric.paper.theta_bounds) all need R and
# R' in one non-symbolic arithmetic or another; the formulas live here, below
# all three.

def reduced_qr(delta):
    """q(delta), r(delta) of :class:`ReducedEquation` as floats, without cancellation.

    With ``e2 = (expm1(delta) - delta) / delta**2`` and ``e3 = (e2 - 1/2) /
    delta`` (both by their Taylor series for delta <= 1)::

        q = -2 e2 (1 - e2 (1 - delta)) / (1 + delta e2)**2
        r = -delta (2 e3 + delta e2**2) / (1 + delta e2)**2

    (the symbolic q, r divided through by delta**4 and delta**3); for delta > 1,
    where nothing cancels, the symbolic q, r written in ``E = exp(-delta)``
    (no overflow at large delta)::

        q = -2 (1 - (1 + delta) E) (delta - 1 + E) / (delta (1 - E))**2
        r = -(1 - 2 delta E - E**2) / (1 - E)**2

    ``q`` lies in [-1/2, 0) and ``r`` in (-1, 0]; delta = 0 gives (-1/2, 0).

    Parameters
    ----------
    delta : float
        ``b T / m >= 0`` (not validated: the callers have).

    Returns
    -------
    (float, float)
    """
    if delta <= 1.0:
        # e3 = sum delta**k / (k + 3)!: 18 terms reach 1e-20 at delta = 1.
        e3, term = 0.0, 1.0 / 6.0
        for k in range(18):
            e3 += term
            term *= delta / (k + 4)
        e2 = 0.5 + delta * e3
        den = (1.0 + delta * e2) ** 2
        return -2.0 * e2 * (1.0 - e2 * (1.0 - delta)) / den, -delta * (2.0 * e3 + delta * e2**2) / den
    E = math.exp(-delta)
    one_minus = -math.expm1(-delta)
    q = -2.0 * (1.0 - (1.0 + delta) * E) * (delta - 1.0 + E) / (delta * one_minus) ** 2
    r = -(1.0 - 2.0 * delta * E - E * E) / one_minus**2
    return q, r


@functools.lru_cache(maxsize=None)
def reduced_qr_functions():
    """``q(delta, Gamma)``, ``r(delta, Gamma)`` of :class:`ReducedEquation` for mpmath.

    Plain arithmetic in delta and Gamma: lambdify's "mpmath" printer leaves
    the integer constants as Python ints, so interval numbers (``mpmath.iv``)
    work too.  They cancel about ``2 log10(1/delta)`` digits each.
    """
    eq = reduced_equation()
    args = (model.delta, model.Gamma)
    return tuple(sp.lambdify(args, part, modules="mpmath", **NO_DOCSTRING)
                 for part in (eq.q, eq.r))


def reduced_value_slope(t, gamma, rate, delta, q, r, *, sin, cos, eps=None):
    """``R(t)`` and ``R'(t)`` of :class:`ReducedEquation` in any arithmetic.

    ``sin`` and ``cos`` pick it: :mod:`numpy`'s for float arrays, :mod:`mpmath`'s
    for mpf, ``mpmath.iv``'s for intervals (the certified enclosure).
    ``rate = d + 1``; ``u = 2 sin(t/2)**2`` keeps its relative accuracy near 0.

    With ``eps`` (the unit roundoff of the arithmetic) two more results bound
    the rounding errors of the value and the slope: ``eps`` times a multiple
    of the sizes of their terms, each sine and cosine of ``phi`` taken as
    wrong by the rounding of ``phi = rate t`` too (``eps rate t``).  Near
    theta = 0 the terms are O(t), so the bound is relative there, like R's
    own accuracy.
    """
    s = sin(t)
    u = 2 * sin(t / 2) ** 2
    phi = rate * t
    sp_, cp = sin(phi), cos(phi)
    vers = 2 * sin(phi / 2) ** 2     # 1 - cos(phi)
    # gamma (1 + q u) + cos(phi), summed from parts that are small together
    # near theta = 0 when gamma is near -1 (a short arc): gamma + 1 is exact
    # there for binary gamma (Sterbenz) and R keeps its relative accuracy.
    w = (gamma + 1) + gamma * q * u - vers
    b = delta + r * u
    value = s * w + b * sp_
    slope = (1 - u) * w + s * s * gamma * q + (r * s - rate * s) * sp_ + rate * b * cp
    if eps is None:
        return value, slope
    a_s, a_b, a_sp, a_cp = abs(s), abs(b), abs(sp_), abs(cp)
    shift = rate * abs(t)            # |rounding of phi| / eps
    w_size = abs(gamma + 1) + 2 * abs(gamma * q * u) + 2 * vers + shift * a_sp
    sp_size = a_sp + shift * a_cp
    value_error = 16 * eps * (a_s * w_size + (a_b + abs(r * u)) * sp_size)
    slope_error = 16 * eps * ((abs(1 - u) + u) * w_size + s * s * abs(gamma * q)
                              + a_s * (abs(r) + rate) * sp_size
                              + rate * (a_b + abs(r * u)) * (a_cp + shift * a_sp))
    return value, slope, value_error, slope_error


def reduced_curvature(gamma, rate, delta, q, r):
    """A bound on ``|R''(theta)|`` over all real theta.

    With ``g = gamma (1 + q u)`` and ``b = delta + r u`` (``u`` in [0, 2], so
    ``|g| <= |gamma| max(1, |1 + 2q|)`` and ``|b| <= max(|delta|, |delta + 2r|)``)::

        R'' = -sin g + 3 gamma q sin cos - (1 + rate**2) sin cos(phi)
              - 2 rate cos sin(phi) + r cos sin(phi) + 2 r rate sin cos(phi)
              - rate**2 b sin(phi)

    bounded term by term.
    """
    gmax = abs(gamma) * max(1, abs(1 + 2 * q))
    bmax = max(abs(delta), abs(delta + 2 * r))
    return (gmax + abs(gamma * q) * 3 / 2 + (1 + rate) ** 2 + abs(r) * (1 + 2 * rate)
            + rate**2 * bmax)


class RootNotIsolated(ArithmeticError):
    """:func:`first_sign_change` ran out of its budget of points."""


#: Open cells halved per round of :func:`first_sign_change`, leftmost first:
#: bounds its work where R stays within its rounding of zero over a stretch.
_HALVED_PER_ROUND = 64


def first_sign_change(evaluate, points, cells, *, slope0, slope0_error, curvature, root_at_end,
                      chunk=256, max_points=100000):
    """The first root of R in ``(points(0), points(cells)]``, isolated without stepping over one.

    R vanishes at ``points(0) = 0`` (theta = 0) with slope ``slope0 > 0``, and
    also at the last point if ``root_at_end`` (theta = pi, where ``R(pi) = 0``
    for every integer d).  A cell ``[a, b]`` of the grid is proved free of
    roots when on each half the Taylor bound from its end stays positive: with ``|R''| <=
    curvature = C`` and ``h = b - a``, ``R(a) > 0`` and ``R(a) + R'(a) h/2 -
    C h**2/8 > 0`` (and the same from b), or, at an end where R is exactly 0,
    ``R'`` pointing into the cell by more than ``C h/4``; every value and
    slope is taken at the worst end of its rounding error.  Cells before the
    first point where R <= 0 that are not proved are halved (the leftmost
    ``_HALVED_PER_ROUND`` each round), and so on, until every cell before
    that point is proved and ``R' < 0`` is proved on the cell that ends
    there, so that it holds one root, the first.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(t) -> (R, R', error of R, error of R')`` for a 1-D array
        ``t`` (float, or object arrays of mpf), as
        :func:`reduced_value_slope` with ``eps``.
    points : callable
        ``points(k)`` for an integer array ``k`` in ``0..cells``: the grid,
        increasing from ``points(0) = 0`` to the end of the search.
    cells : int
        Cells of the grid.
    slope0, slope0_error : number
        ``R'(0) > 0`` and its rounding error.
    curvature : number
        A bound on ``|R''|`` (:func:`reduced_curvature`).
    root_at_end : bool
        R vanishes exactly at the last point, ``points(cells)``.
    chunk : int
        Cells of the grid evaluated at a time, from the left (the rest only
        if R > 0 is proved on all of them).
    max_points : int
        Budget of points per chunk.

    Returns
    -------
    tuple or None
        ``(lo, hi)``: the first root lies in ``[lo, hi]``, R changes sign
        there (``R(lo) > 0 >= R(hi)``) and is decreasing (or the bracket is
        a few ulps wide); ``(t, t)`` where the first root could not be
        separated from zero by the evaluation's rounding (R is within its
        rounding of 0 at ``t``, a root to working precision); ``None`` when
        R > 0 between the first and the last point: the first root is the
        last point.

    Raises
    ------
    RootNotIsolated
        If more than ``max_points`` points were needed.
    """
    origin = points(np.arange(1))
    nought = origin[0] * 0
    # The grid is made and taken ``chunk`` cells at a time from the left: at
    # a long delay the arc ends in the first few of thousands of cells.
    start = (origin, np.array([nought]), np.array([slope0]), np.array([nought]),
             np.array([slope0_error]), np.array([True]))
    for first in range(1, cells + 1, chunk):
        more = points(np.arange(first, min(first + chunk, cells + 1)))
        values = evaluate(more)
        # start[5] (the zero flags) has no counterpart in values: it is extended below.
        t, v, p, ve, pe = (np.concatenate([old, new])
                           for old, new in zip(start, (more,) + tuple(values), strict=False))
        zero = np.concatenate([start[5], np.zeros(more.size, dtype=bool)])
        if root_at_end and first + chunk > cells:
            v[-1], ve[-1] = nought, nought
            zero[-1] = True
        found = _isolate(evaluate, t, v, p, ve, pe, zero, curvature, max_points)
        if found is not None:
            return found
        start = tuple(x[-1:] for x in (t, v, p, ve, pe, zero))
    return None


def _isolate(evaluate, t, v, p, ve, pe, zero, curvature, max_points):
    """:func:`first_sign_change` on one stretch; None if every cell of it is proved free of roots."""
    while True:
        bad = np.flatnonzero(np.asarray((v <= 0) & ~zero, dtype=bool))
        k = int(bad[0]) if bad.size else None
        if k is not None:
            t, v, p, ve, pe, zero = t[:k + 1], v[:k + 1], p[:k + 1], ve[:k + 1], pe[:k + 1], zero[:k + 1]
        a, b = t[:-1], t[1:]
        h = b - a
        drop = curvature * h * h / 8
        va, vb = v[:-1] - ve[:-1], v[1:] - ve[1:]          # lower bounds of R
        pa, pb = p[:-1] - pe[:-1], p[1:] + pe[1:]          # R' at its worst for each end
        proved = (np.where(zero[:-1], pa - curvature * h / 4 > 0,
                           (va > 0) & (va + pa * h / 2 - drop > 0))
                  & np.where(zero[1:], -pb - curvature * h / 4 > 0,
                             (vb > 0) & (vb - pb * h / 2 - drop > 0)))
        proved = np.asarray(proved, dtype=bool)
        if k is not None:
            # The last cell holds a sign change: the first root, and the
            # only one if R' < 0 on it (R' <= R'(end) + C h/2 on each half).
            bound = curvature * h[-1] / 2
            proved[-1] = bool(p[-2] + pe[-2] + bound < 0 and p[-1] + pe[-1] + bound < 0)
        open_ = np.flatnonzero(~proved)[:_HALVED_PER_ROUND]
        if open_.size == 0:
            return None if k is None else (t[k - 1], t[k])
        middle = (a[open_] + b[open_]) / 2
        stuck = np.flatnonzero(np.asarray((middle <= a[open_]) | (middle >= b[open_]), dtype=bool))
        if stuck.size:
            if stuck[0] == 0:
                i = int(open_[0])
                if k is not None and i == t.size - 2:
                    # A sign change a few ulps wide (from 0 itself: the
                    # arc is that short).
                    return (t[k], t[k]) if zero[k - 1] else (t[k - 1], t[k])
                # The first open cell is a few ulps wide and R is not
                # separated from 0 on it: a root to working precision.
                at = t[i + 1] if zero[i] or zero[i + 1] or v[i + 1] < v[i] else t[i]
                return at, at
            open_, middle = open_[:stuck[0]], middle[:stuck[0]]
        if t.size + open_.size > max_points:
            raise RootNotIsolated(f"the first root of R was not isolated within {max_points} points")
        mv, mp, mve, mpe = evaluate(middle)
        at = open_ + 1
        t, v, p = np.insert(t, at, middle), np.insert(v, at, mv), np.insert(p, at, mp)
        ve, pe, zero = np.insert(ve, at, mve), np.insert(pe, at, mpe), np.insert(zero, at, False)
