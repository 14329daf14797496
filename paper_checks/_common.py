"""Helpers shared by the check modules: printed entries, proofs, wording."""

import functools

import sympy as sp

from symstab.proof.identity import check_identity

from .outcome import Outcome
from .printed import PRINTED_COEFFICIENTS, C, printed, section_of

__all__ = ["where", "place", "with_printed_coefficients", "prove", "compare",
           "show", "Memo"]


class Memo:
    """Cache of an expensive, deterministic function of hashable arguments.

    Like ``functools.lru_cache``, and besides: it has a name by which a
    worker process finds it, and its values can be computed elsewhere and
    filled in (see :func:`paper_checks.audit.run_audit`), so that checks
    which share a result compute it once between them.
    """

    #: Every Memo by name, for the workers.
    registry = {}

    def __init__(self, func):
        functools.update_wrapper(self, func)
        self.func = func
        self.name = f"{func.__module__}.{func.__qualname__}"
        self.values = {}
        if self.name in Memo.registry:
            raise ValueError(f"Memo {self.name!r} defined twice")
        Memo.registry[self.name] = self

    def compute(self, args):
        """The value at ``args`` (a tuple), computed now; the cache is not consulted."""
        return self.func(*args)

    def __call__(self, *args):
        if args not in self.values:
            self.values[args] = self.compute(args)
        return self.values[args]

    @classmethod
    def fill(cls, cached):
        """Add ``{name: {args: value}}`` computed elsewhere to the caches."""
        for name, values in cached.items():
            cls.registry[name].values.update(values)


def where(id):
    """'eq. (N), Sec. X' for a printed entry: its number and the part of the paper holding it."""
    p = printed(id)
    return f"eq. ({p.equation}), {place(*p.lines)}"


def place(*cited, note=""):
    """Where a claim stands in the paper, in the words of a reader who has the paper.

    Parameters
    ----------
    *cited : int or str
        Lines of the paper file (provenance, kept in the check's source),
        each named by its section (:func:`paper_checks.printed.section_of`),
        or a text such as ``"Fig. 10(d) caption"``, kept as it is.
    note : str, optional
        Added in parentheses, e.g. ``"circle 1 of Fig. 7"``.

    Returns
    -------
    str
        The parts, each once, in the order cited, joined by "; ".
    """
    parts = list(dict.fromkeys(item if isinstance(item, str) else section_of(item)
                               for item in cited))
    return "; ".join(parts) + (f" ({note})" if note else "")


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
