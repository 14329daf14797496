"""Eqs. (8)-(10), (12), (13), (15) and Appendices C, D (35)-(63): theta_max.

(8)-(10)  theta_max for d = 0, any gamma                        lines 196-204
(12), (13)  the one-Newton-step theta_max for gamma = 0          lines 223-231
(15)      theta_max for d = 0, gamma = 0                         line 250
(35)-(47) Appendix C: the d = 0 closed form                      lines 581-630
(48)-(63) Appendix D: the gamma = 0 Newton form                  lines 647-716
"""

import mpmath
import sympy as sp

from symstab.numeric.paper.device import PAPER_DEVICE
from symstab.symbolic import model
from symstab.symbolic.boundary import boundary, coefficients
from symstab.symbolic.theta_max import closed_form_d0, newton_form_gamma0, theta_max

from ._common import Memo, compare, prove, show, where, with_printed_coefficients
from .audit import Outcome, check
from .printed import PRINTED_D0_COEFFICIENTS, printed, u, xi

theta, d, dl, Gamma, g = model.theta, model.d, model.delta, model.Gamma, model.gamma


def _tan_half_squared(theta_expr):
    """tan(theta/2)**2 of a printed 2 atan(sqrt(X)) form, i.e. X."""
    return sp.tan(theta_expr / 2) ** 2


def _closed_form_check(id, *, gamma=None):
    cf = closed_form_d0()
    u_d = cf.u_root if gamma is None else cf.u_root.subs(g, gamma)
    derived = u_d / (2 - u_d)
    result = prove(_tan_half_squared(printed(id).expr), derived)
    if result.equal is True:
        return Outcome("confirmed",
                       "tan^2(theta_max/2) of the printed form is proved equal to u/(2-u) with the "
                       "derived root u of N_alpha/sin(theta) = k u (A u + B) at d = 0; "
                       "2 atan(sqrt(u/(2-u))) = arccos(1-u) on 0 <= u <= 2")
    return Outcome("erratum", f"tan^2(theta_max/2) differs from the derived u/(2-u): {result.note}",
                   corrected=show(2 * sp.atan(sp.sqrt(derived))))


@check("eq8", kind="equation", where=where("eq8"), claim="d = 0: theta_max = 2 atan(sqrt(u/(2-u)))")
def eq8():
    return _closed_form_check("eq8")


@check("eq47", kind="equation", where=where("eq47"), claim="theta_max = 2 atan(sqrt(u/(2-u)))")
def eq47():
    return _closed_form_check("eq47")


@check("eq15", kind="equation", where=where("eq15"), claim="d = 0, gamma = 0: theta_max in closed form")
def eq15():
    return _closed_form_check("eq15", gamma=0)


def _u_check(id):
    return compare(printed(id).expr, closed_form_d0().u_root,
                   derived_name="the derived root u = -B/A of N_alpha/sin(theta) at d = 0")


@check("eq9", kind="equation", where=where("eq9"), claim="u = -(1-Gamma)^2 delta^2 (gamma+1+delta)/(2A)")
def eq9():
    return _u_check("eq9")


@check("eq46", kind="equation", where=where("eq46"), claim="u = -K2 delta^2 (gamma+1+delta)/(2A)")
def eq46():
    return _u_check("eq46")


def _printed_B():
    """The constant term (1/2) K2 delta^2 (gamma + 1 + delta) printed in (43)-(45)."""
    return sp.expand(printed("eq45").expr).coeff(u, 0)


def _A_check(id):
    cf = closed_form_d0()
    # A is defined up to the scale of N_alpha: compare the ratio A/B.
    result = prove(printed(id).expr * cf.B, cf.A * _printed_B())
    if result.equal is True:
        return Outcome("confirmed", "A / ((1/2) K2 delta^2 (gamma+1+delta)) is proved equal to the "
                       "derived A/B of N_alpha/sin(theta) = k u (A u + B) at d = 0")
    return Outcome("erratum", f"A/B differs from the derivation ({result.note})",
                   corrected=show(sp.factor(cf.A * _printed_B() / cf.B)))


@check("eq10", kind="equation", where=where("eq10"), claim="A of the d = 0 closed form")
def eq10():
    return _A_check("eq10")


@check("eq44", kind="equation", where=where("eq44"), claim="A of the d = 0 closed form")
def eq44():
    return _A_check("eq44")


@check("eq45", kind="equation", where=where("eq45"), claim="A u + (1/2) K2 delta^2 (gamma+1+delta) = 0")
def eq45():
    root = sp.solve(printed("eq45").expr, u)
    if len(root) != 1:
        raise AssertionError("(45) is not linear in u")
    return compare(root[0], closed_form_d0().u_root,
                   derived_name="the derived nontrivial root u of N_alpha at d = 0")


@check("eq36", kind="equation", where=where("eq36"),
       claim="theta_max (d = 0) zeroes gamma C1 + gamma delta^2 C2 + gamma delta C3 + delta^3 C4 "
             "+ delta^2 C5")
def eq36():
    return compare(with_printed_coefficients(printed("eq36").expr), boundary().alpha_numerator,
                   derived_name="the derived numerator N_alpha of alpha(theta)")


@check("eq43", kind="equation", where=where("eq43"),
       claim="d = 0: Phi = 8 s_h c_h u (A u + (1/2) K2 delta^2 (gamma+1+delta))")
def eq43():
    return compare(printed("eq43").expr, boundary().alpha_numerator.subs(d, 0),
                   derived_name="the derived N_alpha at d = 0")


def _register_d0_coefficient(name, equation):
    for form in ("lhs", "rhs"):
        id = f"eq{equation}.{form}"

        @check(id, kind="equation", where=where(id),
               claim=f"{name} at d = 0 ({'first' if form == 'lhs' else 'second'} printed form)")
        def _check(form=form):
            return compare(PRINTED_D0_COEFFICIENTS[name][form], coefficients()[name].subs(d, 0),
                           derived_name=f"the derived {name} at d = 0")


for _name, _equation in (("C1", 37), ("C2", 38), ("C3", 39), ("C4", 40), ("C5", 41)):
    _register_d0_coefficient(_name, _equation)


@check("eq42.rhs", kind="equation", where=where("eq42.rhs"), claim="u = 1 - cos(theta) = 2 s_h^2")
def eq42_rhs():
    return compare(printed("eq42.rhs").expr, 1 - sp.cos(theta), derived_name="1 - cos(theta)")


def _notation(id, what):
    return Outcome("not-checkable", f"notation only: defines {what}; nothing to check by itself "
                   f"(the equations that use it are checked)")


for _id, _what in (("eq35.s_h", "s_h = sin(theta/2)"), ("eq35.c_h", "c_h = cos(theta/2)"),
                   ("eq35.c", "c = cos(theta)"), ("eq42.lhs", "u := 1 - cos(theta)"),
                   ("eq50.sh", "sh = sin(theta/2)"), ("eq50.ch", "ch = cos(theta/2)"),
                   ("eq50.s", "s = sin(theta)"), ("eq50.c", "c = cos(theta)")):
    check(_id, kind="equation", where=where(_id), claim=_what)(
        lambda _id=_id, _what=_what: _notation(_id, _what))


@check("eq50.Gamma", kind="equation", where=where("eq50.Gamma"), claim="Gamma = e^delta")
def eq50_gamma():
    return compare(printed("eq50.Gamma").expr, Gamma, derived_name="Table I's Gamma = exp(delta)")


# -- Appendix D: gamma = 0 ---------------------------------------------------

def _phi():
    return newton_form_gamma0().phi


@check("eq48", kind="equation", where=where("eq48"), claim="gamma = 0: delta C4 + C5 = 0 at theta_max")
def eq48():
    return compare(with_printed_coefficients(printed("eq48").expr), _phi(),
                   derived_name="the derived N_alpha / delta^2 at gamma = 0")


@check("eq49", kind="equation", where=where("eq49"),
       claim="Phi = A_S sin((d+1) theta) + A_D sin(d theta) exactly")
def eq49():
    return compare(printed("eq49").expr, _phi(),
                   derived_name="the derived N_alpha / delta^2 at gamma = 0")


def _split_part(id, part):
    nf = newton_form_gamma0()
    return compare(printed(id).expr, getattr(nf, part),
                   derived_name=f"the derived {part} of N_alpha/delta^2 = A_S sin((d+1)theta) + A_D sin(d theta)")


for _id, _part in (("eq13.A_S", "A_S"), ("eq51", "A_S"), ("eq13.A_D", "A_D"), ("eq52", "A_D")):
    check(_id, kind="equation", where=where(_id), claim=f"{_part}(theta) as printed")(
        lambda _id=_id, _part=_part: _split_part(_id, _part))


@check("eq53", kind="equation", where=where("eq53"), claim="B(theta) in A_S = delta B - ...")
def eq53():
    derived_B = sp.expand(newton_form_gamma0().A_S).coeff(dl, 1)
    return compare(printed("eq53").expr, derived_B,
                   derived_name="the delta-coefficient of the derived A_S")


def _theta0_check(id):
    return compare(printed(id).expr, newton_form_gamma0().theta0,
                   derived_name="the Newton start of the derived gamma = 0 form, the first positive "
                   "zero of cos((d+1) theta)")


@check("eq13.theta0", kind="equation", where=where("eq13.theta0"), claim="theta_0 = pi/(2(d+1))")
def eq13_theta0():
    return _theta0_check("eq13.theta0")


@check("eq56", kind="equation", where=where("eq56"), claim="theta_0 = pi/(2(d+1))")
def eq56():
    return _theta0_check("eq56")


@check("eq54", kind="equation", where=where("eq54"),
       claim="d/dtheta sin((d+1) theta) = (d+1) cos((d+1) theta)")
def eq54():
    eq = printed("eq54").expr
    return compare(eq.lhs.doit(), eq.rhs, derived_name="SymPy's derivative")


@check("eq55", kind="equation", where=where("eq55"),
       claim="cos((d+1) theta) = 0 at theta = (2k+1) pi/(2(d+1))")
def eq55():
    k = [s for s in printed("eq55").expr.free_symbols if s.name == "k"][0]
    value = sp.cos((d + 1) * printed("eq55").expr)
    if sp.simplify(value) == 0:
        return Outcome("confirmed", "cos((d+1)(2k+1) pi/(2(d+1))) = cos((2k+1) pi/2) = 0 for integer k "
                       "(SymPy, exactly)")
    worst = max(abs(float(value.subs({k: kk, d: dd}))) for kk in range(6) for dd in range(20))
    if worst > 1e-12:
        return Outcome("erratum", f"|cos((d+1) theta_k)| reaches {worst:.3g} (k in 0..5, d in 0..19)",
                       corrected="theta_k = (2k+1) pi / (2(d+1))")
    return Outcome("confirmed", f"|cos((d+1) theta_k)| <= {worst:.1g} for k in 0..5, d in 0..19")


def _eq57(id):
    eq = printed(id).expr
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        f = sp.lambdify(d, eq.lhs - eq.rhs, modules="mpmath")
        for dd in range(0, 201):
            worst = max(worst, abs(f(dd)))
    verdict = "confirmed" if worst < mpmath.mpf(10) ** -35 else "erratum"
    if verdict == "erratum":
        theta0 = newton_form_gamma0().theta0
        fixed = sp.sin(sp.pi / 2 - theta0) if id.endswith("sin") else sp.cos(sp.pi / 2 - theta0)
        return Outcome(verdict, f"differs by up to {float(worst):.3g}", corrected=show(fixed))
    return Outcome("confirmed", "|lhs - rhs| < 1e-35 at 40 digits for every d in 0..200 "
                   "(d theta_0 = pi/2 - theta_0)")


check("eq57.sin", kind="equation", where=where("eq57.sin"),
      claim="sin(d theta_0) = cos(pi/(2(d+1)))")(lambda: _eq57("eq57.sin"))
check("eq57.cos", kind="equation", where=where("eq57.cos"),
      claim="cos(d theta_0) = sin(pi/(2(d+1)))")(lambda: _eq57("eq57.cos"))


@check("eq59", kind="equation", where=where("eq59"), claim="Phi'(theta) by the product rule")
def eq59():
    return compare(printed("eq59").expr, sp.diff(printed("eq49").expr, theta),
                   derived_name="d/dtheta of the printed (49)")


@check("eq60", kind="equation", where=where("eq60"), claim="A'_S(theta)")
def eq60():
    target = sp.diff(printed("eq51").expr, theta)
    corrected = printed("eq60").expr.subs(xi, sp.sin(theta))
    return compare(printed("eq60").expr, target, corrected=corrected,
                   corrected_note="The symbol xi is never defined; with xi = sin(theta) the printed "
                   "form is d/dtheta of (51).",
                   derived_name="d/dtheta of the printed (51) (itself proved equal to the derived A_S)")


@check("eq61", kind="equation", where=where("eq61"), claim="A'_D(theta)")
def eq61():
    return compare(printed("eq61").expr, sp.diff(printed("eq52").expr, theta),
                   derived_name="d/dtheta of the printed (52)")


@check("eq62", kind="equation", where=where("eq62"), claim="B'(theta)")
def eq62():
    return compare(printed("eq62").expr, sp.diff(printed("eq53").expr, theta),
                   derived_name="d/dtheta of the printed (53)")


#: Delays over which the one-step Newton forms are measured.
NEWTON_DELAYS = (1, 2, 3, 5, 10, 20, 40, 100, 200)


@Memo
def _exact_theta_max_gamma0(dd):
    """The exact theta_max at gamma = 0 on the paper's device, shared by (12), (58), (63)."""
    return theta_max(gamma=0.0, d=dd, delta=PAPER_DEVICE.delta)


def prefetch():
    """The shared results of these checks, ``[(Memo, args), ...]``: computed first, in parallel."""
    return [(_exact_theta_max_gamma0, (dd,)) for dd in sorted(NEWTON_DELAYS, reverse=True)]


def _newton_error(expr, label):
    f = sp.lambdify((d, dl, Gamma), expr, modules="mpmath")
    derived = sp.lambdify((d, dl, Gamma), newton_form_gamma0().theta_newton, modules="mpmath")
    rows = []
    with mpmath.workdps(30):
        delta = mpmath.mpf(PAPER_DEVICE.delta)
        for dd in NEWTON_DELAYS:
            approx = f(dd, delta, mpmath.exp(delta))
            step = derived(dd, delta, mpmath.exp(delta))
            exact = _exact_theta_max_gamma0(dd)
            rows.append((dd, float(approx), exact, float(abs(approx - exact) / exact),
                         float(abs(approx - step) / abs(step))))
    worst = max(rows, key=lambda r: r[3])
    same = max(r[4] for r in rows)
    table = ", ".join(f"d={r[0]}: {r[3]:.1e}" for r in rows)
    return Outcome("approximation",
                   f"{label}; it equals symstab's one Newton step on the derived N_alpha to "
                   f"{same:.1e} relative. Relative error against the exact first root of alpha "
                   f"(paper's device, delta = {PAPER_DEVICE.delta:.6g}): {table}; largest {worst[3]:.2e} "
                   f"at d = {worst[0]} ({worst[1]:.6f} vs exact {worst[2]:.6f})")


@check("eq12", kind="equation", where=where("eq12"), claim="gamma = 0: theta_max by one Newton step")
def eq12():
    return _newton_error(printed("eq12").expr, "one Newton step from theta_0 with A_S, A_D of (13)")


@check("eq58", kind="equation", where=where("eq58"), claim="theta_max ~ theta_0 - Phi(theta_0)/Phi'(theta_0)")
def eq58():
    return _newton_error(printed("eq58").expr, "one Newton step with the printed (49), (59)")


@check("eq63", kind="equation", where=where("eq63"), claim="the compact Newton form of theta_max")
def eq63():
    expr = printed("eq63").expr.subs(xi, sp.sin(newton_form_gamma0().theta0))
    return _newton_error(expr, "with the undefined xi of (60) read as sin(theta_0) (see eq60)")
