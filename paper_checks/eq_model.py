"""Eqs. (1)-(6), (16), (17): the model, the pulse transfer function, the loop.

(1)  VE(z) = K_w + B_w (z-1)/(T z) + M_w (z-1)^2/(T^2 z^2)          line 149
(2)  Delta = 1 + VE(z) z^-d Z[ZOH G(s)] = 0                         line 163
(3)  Z[ZOH G(s)] = Z[(1 - e^{-Ts})/s * 1/(m s^2 + b s)]            line 167
(4)  the ZOH pulse transfer function in closed form                  line 171
(5)  the characteristic polynomial in dimensionless form             line 175
(6)  z = e^{j theta}                                                 line 179
(16), (17)  the PI gains of the current controller                   lines 398, 402
"""

import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.discretize import pulse_transfer_function
from symstab.symbolic.loop import characteristic_polynomial

from ._common import compare, prove, show, where
from .audit import Outcome, check
from .printed import printed


@check("eq1", kind="equation", where=where("eq1"),
       claim="VE(z) = K_w + B_w (z-1)/(Tz) + M_w (z-1)^2/(T^2 z^2)")
def eq1():
    return compare(printed("eq1").expr, model.virtual_environment(),
                   derived_name="symstab's model VE(z)")


@check("eq3", kind="equation", where=where("eq3"),
       claim="ZOH G(s) = (1 - e^{-Ts})/s * 1/(m s^2 + b s)")
def eq3():
    return compare(printed("eq3").expr, model.zero_order_hold() * model.plant(),
                   derived_name="symstab's ZOH times G(s)")


@check("eq4", kind="equation", where=where("eq4"),
       claim="Z[ZOH G(s)] in closed form")
def eq4():
    return compare(printed("eq4").expr, pulse_transfer_function(),
                   derived_name="Z[ZOH G(s)] derived by residues")


@check("eq2", kind="equation", where=where("eq2"),
       claim="characteristic equation 1 + VE(z) z^-d Z[ZOH G(s)] = 0")
def eq2():
    derived = 1 + model.virtual_environment() * model.z**(-model.d) * pulse_transfer_function()
    return compare(printed("eq2").expr, derived,
                   derived_name="1 + VE z^-d Z[ZOH G] with the derived pulse transfer function")


def _by_power(expr):
    """{exponent: coefficient} of a polynomial in z with exponents k or d + k."""
    E = sp.Symbol("E_d")
    expr = sp.expand(sp.sympify(expr))
    expr = expr.replace(lambda e: e.is_Pow and e.base == model.z and e.exp.has(model.d),
                        lambda e: E * model.z ** sp.expand(e.exp - model.d))
    poly = sp.Poly(expr, model.z, E)
    out = {}
    for (k, e), c in poly.terms():
        out[k + model.d * e] = c
    return out


@check("eq5", kind="equation", where=where("eq5"),
       claim="dimensionless characteristic polynomial of (2)")
def eq5():
    derived = characteristic_polynomial()
    printed_terms = _by_power(printed("eq5").expr)
    derived_terms = {e: c for e, c in derived.terms()}
    wrong, affine_broken = [], []
    powers = sorted(set(printed_terms) | set(derived_terms), key=sp.default_sort_key)
    params = (model.alpha, model.beta, model.gamma)
    for power in powers:
        if sp.Poly(printed_terms.get(power, 0), *params).total_degree() > 1:
            affine_broken.append(f"z^{power}")
        result = prove(printed_terms.get(power, 0), derived_terms.get(power, 0))
        if result.equal is not True:
            wrong.append(f"z^{power}: printed {show(sp.factor(printed_terms.get(power, 0)))}, "
                         f"derived {show(sp.factor(derived_terms.get(power, 0)))}")
    if not wrong:
        return Outcome("confirmed", "every coefficient proved equal to the derived chi(z)")
    affine = (f"the printed {', '.join(affine_broken)} coefficients have products of parameters "
              f"although chi is affine in (alpha, beta, gamma); " if affine_broken else "")
    return Outcome(
        "erratum",
        f"{len(wrong)} of {len(powers)} coefficients differ from chi(z) = z^(d+2) D(z) + V(z) N(z) "
        f"derived from (1), (3) and Table I (whose roots match python-control's poles in the "
        f"tests); {affine}" + "; ".join(wrong),
        corrected=show(derived.as_expr()))


@check("eq6", kind="equation", where=where("eq6"), claim="z = e^{j theta} on the unit circle")
def eq6():
    return compare(printed("eq6").expr, sp.cos(model.theta) + sp.I * sp.sin(model.theta),
                   derived_name="cos(theta) + j sin(theta)")


def _gains(id, label):
    kp, ki = printed(id).expr
    return Outcome("not-checkable",
                   f"{label} PI gains Kp = {kp} mV/A, Ki = {ki} mV/(A ms) of the Maxon driver: "
                   f"experimental settings in electrical units, outside the linear model")


@check("eq16", kind="equation", where=where("eq16"), claim="low PI gains Kp = Ki = 600")
def eq16():
    return _gains("eq16", "low")


@check("eq17", kind="equation", where=where("eq17"), claim="high PI gains Kp = Ki = 6000")
def eq17():
    return _gains("eq17", "high")
