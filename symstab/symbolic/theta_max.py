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
  delta), bracketed on a grid and refined by mpmath's Anderson-Bjorck solver.
"""

import dataclasses
import functools
import math

import mpmath
import sympy as sp

from . import model
from .._validate import check_loop
from .boundary import boundary
from .forms import E, exponential_form, trig_form, w
from .small_theta import taylor_coefficients

__all__ = [
    "ClosedFormD0", "NewtonFormGamma0",
    "closed_form_d0", "newton_form_gamma0", "theta_max", "theta_max_newton",
    "alpha_numerator_function", "ReducedEquation", "reduced_equation",
    "PhaseEquation", "phase_equation",
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
    return sp.lambdify(args, boundary().alpha_numerator, modules="mpmath", cse=True)


@functools.lru_cache(maxsize=None)
def alpha_numerator_function():
    """mpmath function ``f(theta, gamma, d, delta)`` of ``N_alpha``."""
    f = _alpha_numerator_gamma()
    return lambda theta, gamma, d, delta: f(theta, gamma, d, delta, mpmath.exp(delta))


def theta_max(*, gamma, d, delta, dps=30):
    """Exact theta_max: the first root of alpha(theta) in (0, pi].

    The numerator of alpha is sampled on a grid fine enough for the delay
    (spacing below a quarter period of ``sin(d theta)``), the first sign
    change after theta = 0 is bracketed, and mpmath's Anderson-Bjorck solver
    refines it at ``dps`` digits.

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
        (no arc enters alpha > 0; see :mod:`symstab.symbolic.small_theta`), or when the
        arc is shorter than ``1e-10 pi / n`` for the scan's ``n`` points.

    Examples
    --------
    >>> round(theta_max(gamma=0.0, d=0, delta=0.0324e-3 / 0.0128), 4)
    1.5725
    """
    gamma, d, delta = check_loop(gamma, d, delta, zero_delta=False)
    f = _alpha_numerator_gamma()
    # N_alpha ~ theta**3 delta**2 near 0 out of terms of size 1: the extra
    # digits keep its sign right down to the first grid point, pi/n * 1e-10;
    # on the uniform grid (theta >= pi/n) it cancels at most
    # log10(n**3 / delta**2) digits, so fewer extra digits do there.
    n = max(400, 16 * (d + 1))
    uniform_extra = 10 + int(3 * math.log10(n) + 2 * max(0.0, -math.log10(delta)))
    with mpmath.workdps(dps + 40):
        g_, d_ = mpmath.mpf(gamma), mpmath.mpf(delta)
        e_ = mpmath.exp(d_)
        g = lambda t: f(t, g_, d, d_, e_)  # noqa: E731
        step = mpmath.pi / n
        short = [step * mpmath.mpf(10) ** (-k / mpmath.mpf(4)) for k in range(40, 0, -1)]
        uniform = [step * k for k in range(1, n + 1)]
        grid = short + uniform
        values = [g(t) for t in short]
        with mpmath.workdps(dps + min(40, uniform_extra)):
            values += [g(t) for t in uniform]
        if values[0] <= 0:
            return float("nan")
        for k in range(1, len(grid)):
            if values[k] == 0:
                return float(grid[k])
            if values[k] < 0 < values[k - 1]:
                # N_alpha grows like exp(2 delta): a tolerance on its value
                # means nothing at large delta, so keep the bracket instead.
                lo, hi = grid[k - 1], grid[k]
                root = mpmath.findroot(g, (lo, hi), solver="anderson", verify=False)
                if not lo <= root <= hi:
                    root = mpmath.findroot(g, (lo, hi), solver="bisect", verify=False)
                return float(root)
        return float(mpmath.pi)


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
                       modules="mpmath")


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
