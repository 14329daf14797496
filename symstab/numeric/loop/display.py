"""How a :class:`symstab.Loop` shows itself in Jupyter: its model and characteristic equation in LaTeX."""

import sympy as sp

__all__ = ["loop_latex"]


def _polynomial(coefficients):
    """LaTeX of the polynomial in ``z`` with ``coefficients`` (highest power first), in that order."""
    coefficients = [sp.sympify(c) for c in coefficients]
    top = len(coefficients) - 1
    terms = []
    for k, c in zip(range(top, -1, -1), coefficients, strict=True):
        if c == 0:
            continue
        power = "" if k == 0 else "z" if k == 1 else f"z^{{{k}}}"
        factor = rf"\left({sp.latex(c)}\right)" if isinstance(c, sp.Add) else sp.latex(c)
        terms.append(power if c == 1 and power else f"{factor} {power}".strip())
    if len(terms) == 1 and terms[0].startswith(r"\left("):   # a lone sum needs no parentheses
        terms = [sp.latex(next(c for c in coefficients if c != 0))]
    if not terms:
        return "0"
    text = terms[0]
    for term in terms[1:]:
        text += f" - {term[1:].lstrip()}" if term.startswith("-") else f" + {term}"
    return text


def loop_latex(plant, environment, environment_parts, plant_parts=None):
    """LaTeX of a loop: ``G(s)``, ``VE(z)``, the ZOH plant and the characteristic equation.

    The equation is the one the engine works on (:meth:`symstab.Loop.polynomial`):
    ``1 + z**-d VE(z) P(z) = 0`` times ``z**d Ve_d(z) P_d(z)``, that is
    ``chi(z) = z**d D(z) + N(z) = 0`` with ``D = Ve_d P_d`` and ``N = Ve_n P_n``.

    Parameters
    ----------
    plant, environment : sympy.Expr
        ``G(s)`` and ``VE(z)``.
    environment_parts : (list, list)
        The coefficients of ``Ve_n`` and ``Ve_d``, highest power of ``z`` first.
    plant_parts : (list, list) or None
        The coefficients of the ZOH pulse transfer function's numerator and
        denominator ``P_n``, ``P_d``, highest power first; None for a plant
        discretised numerically (at numbers, with the matrix exponential).

    Returns
    -------
    str
        One display-math block, ``$$ ... $$``.
    """
    ve_n, ve_d = (_polynomial(part) for part in environment_parts)
    rows = [rf"G(s) &= {sp.latex(plant)}", rf"V_E(z) &= {sp.latex(environment)}"]
    if plant_parts is None:
        rows.append(r"P(z) &= \mathcal{Z}\{\mathrm{ZOH}\; G(s)\}"
                    r"\quad\text{(numerically, at the parameters' values)}")
        d_part, n_part = r"P_d(z)", r"P_n(z)"
    else:
        p_n, p_d = (_polynomial(part) for part in plant_parts)
        rows.append(rf"P(z) &= \frac{{{p_n}}}{{{p_d}}}")
        d_part, n_part = rf"\left({p_d}\right)", rf"\left({p_n}\right)"
    rows.append(rf"\chi(z) &= z^{{d}} \left({ve_d}\right) {d_part}"
                rf" + \left({ve_n}\right) {n_part} = 0")
    return "$$\\begin{aligned}" + r" \\ ".join(rows) + "\\end{aligned}$$"
