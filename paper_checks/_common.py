"""Helpers shared by the check modules: printed entries, proofs, wording."""

import sympy as sp

from symstab.identity import check_identity

from .audit import Outcome
from .printed import C, PRINTED_COEFFICIENTS, printed

__all__ = ["where", "with_printed_coefficients", "prove", "compare",
           "show", "DEVICE_DELTA"]

#: delta = b T / m of the paper's device (m = 0.0128, b = 0.0324, T = 1 ms).
DEVICE_DELTA = 0.0324 * 1e-3 / 0.0128


def where(id):
    """'eq. (N), line L' (or lines L1-L2) for a printed entry."""
    p = printed(id)
    first, last = p.lines
    span = f"line {first}" if first == last else f"lines {first}-{last}"
    return f"eq. ({p.equation}), {span}"


def with_printed_coefficients(expr):
    """Substitute the printed C1..C11 of (20)-(34) into ``expr``."""
    return sp.sympify(expr).subs({c: PRINTED_COEFFICIENTS[c.name] for c in C})


def show(expr):
    """A compact one-line rendering of an expression for the report."""
    return sp.sstr(expr)


def prove(lhs, rhs):
    """check_identity with the audit's fixed sample (deterministic)."""
    return check_identity(lhs, rhs, samples=10, dps=40, seed=0)


def _evidence(result):
    if result.equal is True:
        return "proved identical by the exact checker (w, E, Gamma rational functions; 40-digit cross-check)"
    if result.equal is False:
        return (f"differs: relative difference {result.max_rel_diff:.3g} at "
                + ", ".join(f"{k}={v:.6g}" for k, v in result.witness.items()))
    return (f"equal to 40 digits at 10 random points (max relative difference "
            f"{result.max_rel_diff:.2g}); {result.note}")


def compare(printed_expr, derived_expr, *, corrected=None, corrected_note="",
            derived_name="the derivation"):
    """Outcome of comparing a printed form with the derived one.

    ``confirmed`` when they are proved (or numerically shown) identical;
    otherwise ``erratum`` with ``corrected`` (default: the derived form),
    which is itself proved equal to the derivation.
    """
    result = prove(printed_expr, derived_expr)
    if result.equal is True:
        return Outcome("confirmed", f"equals {derived_name}: {_evidence(result)}")
    if result.equal is None and result.max_rel_diff < 1e-30:
        return Outcome("confirmed", f"equals {derived_name} numerically only (not proved exactly): "
                       f"{_evidence(result)}")
    fixed = derived_expr if corrected is None else corrected
    fixed_result = prove(fixed, derived_expr)
    if fixed_result.equal is not True:
        raise AssertionError(f"corrected form not proved: {fixed_result.note}")
    return Outcome("erratum",
                   f"printed form {_evidence(result)}; the corrected form is proved equal to "
                   f"{derived_name}. {corrected_note}".strip(),
                   corrected=show(fixed))
