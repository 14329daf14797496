"""Eqs. (7), (11), (14), (18)-(34): the boundary and its coefficients.

(7)   alpha, beta = (... C1..C5 ...) / (C6 + delta^2 C7 + delta C8)      line 183
(11)  the gamma = 0 case                                                  line 219
(14)  the d = 0, gamma = 0 case                                           line 241
(18), (19)  real and imaginary parts of the characteristic equation       lines 535-539
(20)-(34)   K1..K4 and C1..C11                                            lines 545-575
"""

import sympy as sp

from symstab.symbolic import model
from symstab.symbolic.boundary import boundary, coefficients
from symstab.symbolic.unit_circle import unit_circle_split

from ._common import compare, prove, show, where, with_printed_coefficients
from .audit import Outcome, check
from .printed import C, printed

C1, C2, C3, C4, C5, C6, C7, C8, C9, C10, C11 = C
g, dl = model.gamma, model.delta


def _derived(part, *, gamma=None, d=None):
    """Derived alpha or beta, optionally at a fixed gamma and/or delay d."""
    bd = boundary()
    expr = {"alpha": bd.alpha, "beta": bd.beta}[part]
    subs = {}
    if gamma is not None:
        subs[model.gamma] = gamma
    if d is not None:
        subs[model.d] = d
    return expr.subs(subs)


@check("eq7.alpha", kind="equation", where=where("eq7.alpha"),
       claim="alpha(theta) = (gamma C1 + gamma delta^2 C2 + gamma delta C3 + delta^3 C4 + delta^2 C5)"
             "/(C6 + delta^2 C7 + delta C8)")
def eq7_alpha():
    return compare(with_printed_coefficients(printed("eq7.alpha").expr), _derived("alpha"),
                   derived_name="alpha(theta) solved from the unit-circle split")


#: beta of (7) with the numerator's last terms as in (11) and (69), and the
#: gamma delta term carrying C9 (defined in (32) and otherwise unused).
BETA_CORRECTED = (-g * C1 - g * dl**2 * C2 + g * dl * C9 + dl**3 * C10 + dl**2 * C11) / (
    C6 + dl**2 * C7 + dl * C8)


@check("eq7.beta", kind="equation", where=where("eq7.beta"),
       claim="beta(theta) = (-gamma C1 - gamma delta^2 C2 + gamma delta C3 + delta^3 C4 + delta^2 C5)"
             "/(C6 + delta^2 C7 + delta C8)")
def eq7_beta():
    return compare(
        with_printed_coefficients(printed("eq7.beta").expr), _derived("beta"),
        corrected=with_printed_coefficients(BETA_CORRECTED),
        corrected_note=("Two slips: the delta^3, delta^2 terms take C10, C11 (as in (11), (69)), "
                        "not C4, C5; and the gamma delta term is +gamma delta C9 = -gamma delta C3. "
                        "Corrected, with the printed C's: " + show(BETA_CORRECTED) + "."),
        derived_name="beta(theta) solved from the unit-circle split")


@check("eq11.alpha", kind="equation", where=where("eq11.alpha"),
       claim="gamma = 0: alpha = (delta^3 C4 + delta^2 C5)/(C6 + delta^2 C7 + delta C8)")
def eq11_alpha():
    return compare(with_printed_coefficients(printed("eq11.alpha").expr),
                   _derived("alpha", gamma=0), derived_name="alpha(theta) at gamma = 0")


@check("eq11.beta", kind="equation", where=where("eq11.beta"),
       claim="gamma = 0: beta = (delta^3 C10 + delta^2 C11)/(C6 + delta^2 C7 + delta C8)")
def eq11_beta():
    return compare(with_printed_coefficients(printed("eq11.beta").expr),
                   _derived("beta", gamma=0), derived_name="beta(theta) at gamma = 0")


@check("eq14.alpha", kind="equation", where=where("eq14.alpha"),
       claim="d = 0, gamma = 0: alpha(theta) in closed form")
def eq14_alpha():
    return compare(printed("eq14.alpha").expr, _derived("alpha", gamma=0, d=0),
                   derived_name="alpha(theta) at d = 0, gamma = 0")


@check("eq14.beta", kind="equation", where=where("eq14.beta"),
       claim="d = 0, gamma = 0: beta(theta) in closed form")
def eq14_beta():
    return compare(printed("eq14.beta").expr, _derived("beta", gamma=0, d=0),
                   derived_name="beta(theta) at d = 0, gamma = 0")


def _split_check(id, index, label):
    derived = unit_circle_split()[index]
    result = prove(printed(id).expr, derived)
    if result.equal is True:
        return Outcome("confirmed", f"proved equal to the derived {label} part of chi(e^(j theta))")
    # Say which harmonics differ: compare the coefficient of each alpha,
    # beta, gamma monomial separately.
    params = [model.alpha, model.beta, model.gamma]
    diff_terms = []
    for sym in params + [None]:
        if sym is None:
            pr = printed(id).expr.subs({p: 0 for p in params})
            de = derived.subs({p: 0 for p in params})
            name = "the parameter-free part"
        else:
            pr = sp.expand(printed(id).expr).coeff(sym)
            de = sp.expand(derived).coeff(sym)
            name = f"the {sym} terms"
        if prove(pr, de).equal is not True:
            diff_terms.append(name)
    return Outcome(
        "erratum",
        f"differs from the derived {label} part in {', '.join(diff_terms)} (the same slips as "
        f"the printed (5), of which it is the split); the derived part is the split of chi(z), "
        f"whose roots match python-control's closed-loop poles",
        corrected=show(derived))


@check("eq18", kind="equation", where=where("eq18"), claim="Re chi(e^(j theta)) = 0")
def eq18():
    return _split_check("eq18", 0, "real")


@check("eq19", kind="equation", where=where("eq19"), claim="Im chi(e^(j theta)) = 0")
def eq19():
    return _split_check("eq19", 1, "imaginary")


def _coefficient_check(name, equation):
    id = f"eq{equation}"
    return compare(printed(id).expr, coefficients()[name],
                   derived_name=f"the derived {name} (coefficient of its monomial in the Cramer solution)")


_COEFFICIENT_EQUATIONS = {
    "K1": 20, "K2": 21, "K3": 22, "K4": 23, "C1": 24, "C2": 25, "C3": 26, "C4": 27,
    "C5": 28, "C6": 29, "C7": 30, "C8": 31, "C9": 32, "C10": 33, "C11": 34,
}


def _register_coefficient(name, equation):
    @check(f"eq{equation}", kind="equation", where=where(f"eq{equation}"),
           claim=f"{name} as printed")
    def _check():
        return _coefficient_check(name, equation)
    return _check


for _name, _equation in _COEFFICIENT_EQUATIONS.items():
    _register_coefficient(_name, _equation)
