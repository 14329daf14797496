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

__all__ = [
    "ClosedFormD0", "NewtonFormGamma0",
    "closed_form_d0", "newton_form_gamma0", "theta_max", "theta_max_newton",
    "alpha_numerator_function",
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
