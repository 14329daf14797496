"""Appendix E, eqs. (64)-(70): the start of every arc and the sign of alpha.

(64)  K1 ~ 16 theta^5 and K2..K4                          line 732
(65)  leading orders of C1..C11 near theta = 0              line 737
(66), (69)  alpha and beta restated with the C's            lines 742, 758
(67)  alpha near theta = 0                                  line 747
(68)  lim alpha = 0+                                        line 753
(70)  lim beta = -delta                                     line 762
"""

import mpmath
import sympy as sp

from symstab.numeric.paper.device import PAPER_DEVICE
from symstab.numeric.paper.reference import boundary_point
from symstab.symbolic import model
from symstab.symbolic.boundary import boundary, coefficients
from symstab.symbolic.small_theta import small_theta_limits, taylor_coefficients

from ._common import compare, show, where, with_printed_coefficients
from .audit import Outcome, check
from .eq_boundary import BETA_CORRECTED
from .printed import Delta, const, eta, printed, xi

theta = model.theta


def _leading(expr, order=8):
    """(power, coefficient) of the leading term of ``expr`` in theta."""
    for p, c in enumerate(taylor_coefficients(expr, order - 1)):
        if c != 0:
            return p, c
    raise AssertionError(f"no term below theta^{order}")


@check("eq64.K1", kind="equation", where=where("eq64.K1"), claim="K1 ~ 16 theta^5 near theta = 0")
def eq64_k1():
    power, coeff = _leading(coefficients()["K1"])
    pp, pc = _leading(printed("eq64.K1").expr)
    if (power, sp.simplify(coeff - pc)) == (pp, 0):
        return Outcome("approximation", f"leading term {show(coeff)} theta^{power} confirmed")
    corrected = coeff * theta**power
    series = sp.series(coefficients()["K1"], theta, 0, 9)
    return Outcome("erratum",
                   f"the derived K1 (proved equal to (20)) has the series {show(series)}; the printed "
                   f"{show(pc * theta**pp)} is {show(pc / coeff)} times its leading term",
                   corrected=f"K1 ~ {show(corrected)}")


for _name in ("K2", "K3", "K4"):
    check(f"eq64.{_name}", kind="equation", where=where(f"eq64.{_name}"),
          claim=f"{_name} as in (21)-(23)")(
        lambda _name=_name: compare(printed(f"eq64.{_name}").expr, coefficients()[_name],
                                    derived_name=f"the derived {_name}"))

_UNDEFINED = {Delta: "Delta", eta: "eta", xi: "xi", const: "(const)"}


def _c_order(name):
    derived_power, derived_coeff = _leading(coefficients()[name])
    expr = printed(f"eq65.{name}").expr
    undefined = [s for s in (Delta, eta, xi, const) if expr.has(s)]
    # With the placeholder set to 1, the printed form's own leading term.
    shape = expr.subs({s: 1 for s in undefined})
    power, coeff = _leading(shape)
    needed = sp.factor(derived_coeff / coeff)
    placeholder = ", ".join(_UNDEFINED[s] for s in undefined) or "none"
    if power != derived_power:
        return Outcome("erratum",
                       f"leading power theta^{power} printed, theta^{derived_power} derived "
                       f"(coefficient {show(derived_coeff)})",
                       corrected=f"{name} ~ {show(derived_coeff)} theta^{derived_power}")
    return Outcome("approximation",
                   f"leading power theta^{power} confirmed by the series of the derived {name}, whose "
                   f"leading term is {show(derived_coeff)} theta^{power}; the placeholder ({placeholder}) "
                   f"must be {show(needed)}; the paper does not say what it is")


for _i in range(1, 12):
    check(f"eq65.C{_i}", kind="equation", where=where(f"eq65.C{_i}"),
          claim=f"C{_i} near theta = 0 as printed")(lambda _i=_i: _c_order(f"C{_i}"))


@check("eq66", kind="equation", where=where("eq66"),
       claim="alpha = (gamma C1 + ... + delta^2 C5)/(C6 + delta^2 C7 + delta C8)")
def eq66():
    return compare(with_printed_coefficients(printed("eq66").expr), boundary().alpha,
                   derived_name="alpha(theta) solved from the unit-circle split")


@check("eq69", kind="equation", where=where("eq69"),
       claim="beta = (-gamma C1 - gamma delta^2 C2 + gamma delta C3 + delta^3 C10 + delta^2 C11)"
             "/(C6 + delta^2 C7 + delta C8)")
def eq69():
    return compare(with_printed_coefficients(printed("eq69").expr), boundary().beta,
                   corrected=with_printed_coefficients(BETA_CORRECTED),
                   corrected_note="The gamma delta term is +gamma delta C9 = -gamma delta C3: "
                   + show(BETA_CORRECTED) + ".",
                   derived_name="beta(theta) solved from the unit-circle split")


@check("eq67", kind="equation", where=where("eq67"), claim="alpha near theta = 0, leading orders")
def eq67():
    lim = small_theta_limits()
    expr = printed("eq67").expr
    # The only values of the undefined Delta, eta that make (67) the leading
    # order of the derivation (C4 ~ Delta theta^3, C5 ~ eta theta^3).
    fill = {Delta: _leading(coefficients()["C4"])[1], eta: _leading(coefficients()["C5"])[1]}
    f = sp.lambdify((theta, model.gamma, model.d, model.delta, model.Gamma), expr.subs(fill),
                    modules="mpmath")
    rows = []
    with mpmath.workdps(30):
        delta = mpmath.mpf(PAPER_DEVICE.delta)
        for g, d, t in ((0.0, 0, 0.01), (0.0, 0, 0.1), (1.0, 0, 0.1), (0.0, 10, 0.05)):
            exact = boundary_point(t, gamma=g, d=d, delta=PAPER_DEVICE.delta)[0]
            approx = f(mpmath.mpf(t), mpmath.mpf(g), d, delta, mpmath.exp(delta))
            rows.append(f"gamma={g:g}, d={d}, theta={t:g}: {float(abs(approx / exact - 1)):.1e}")
    return Outcome("approximation",
                   f"Delta and eta are never defined; with the values the series require "
                   f"(Delta = {show(fill[Delta])}, eta = {show(fill[eta])}) its leading term is the "
                   f"derived alpha ~ ({show(lim.alpha_theta2)}) theta^2. Relative error against the "
                   f"exact alpha (paper's device): " + "; ".join(rows))


@check("eq68", kind="equation", where=where("eq68"), claim="lim_{theta->0+} alpha = 0+ (for every gamma, d)")
def eq68():
    lim = small_theta_limits()
    if lim.alpha_limit != 0:
        return Outcome("erratum", f"the derived limit is {show(lim.alpha_limit)}",
                       corrected=f"lim alpha = {show(lim.alpha_limit)}")
    threshold = gamma_threshold()
    if threshold is None:
        return Outcome("confirmed", f"alpha = ({show(lim.alpha_theta2)}) theta^2 + ..., positive for all "
                       f"gamma, d")
    return Outcome(
        "erratum",
        f"the limit is 0, but alpha = ({show(lim.alpha_theta2)}) theta^2 + O(theta^4) (Taylor series of "
        f"the derived alpha with symbolic d), so alpha approaches 0 from above only when "
        f"{show(lim.alpha_sign_condition)}, i.e. gamma > {show(threshold)}; the argument of (67) takes "
        f"every term positive, which fails below that gamma",
        corrected=f"lim alpha = 0, from above iff {show(lim.alpha_sign_condition)}")


def gamma_threshold():
    """The gamma below which alpha < 0 next to theta = 0 (None if there is none)."""
    lim = small_theta_limits()
    roots = sp.solve(lim.alpha_theta2, model.gamma)
    return sp.factor(roots[0]) if len(roots) == 1 else None


@check("eq70", kind="equation", where=where("eq70"), claim="lim_{theta->0} beta = -delta")
def eq70():
    return compare(printed("eq70").expr, small_theta_limits().beta_limit,
                   derived_name="the Taylor limit of the derived beta")
