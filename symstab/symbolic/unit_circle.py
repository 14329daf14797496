"""The characteristic polynomial on the unit circle z = exp(j theta).

Every coefficient of chi(z) is real, so each term ``c z**n`` contributes
``c cos(n theta)`` to the real part and ``c sin(n theta)`` to the imaginary
part.  The split is done by SymPy (``as_real_imag`` with ``theta`` and ``d``
real) and kept in trigonometric form with the symbolic delay ``d``.
"""

import functools

import sympy as sp

from . import model
from .loop import characteristic_polynomial

__all__ = ["on_unit_circle", "unit_circle_split"]


def on_unit_circle():
    """Return chi(exp(j theta)) with ``z**(d + k) = exp(j (d + k) theta)``."""
    return sp.Add(*[c * sp.exp(sp.I * e * model.theta)
                    for e, c in characteristic_polynomial().terms()])


@functools.lru_cache(maxsize=None)
def unit_circle_split():
    """Return ``(real, imag)``: chi(exp(j theta)) = real + j imag.

    Both parts are trigonometric polynomials in ``theta`` and ``d theta``,
    affine in alpha, beta and gamma: the derived counterparts of the
    Appendix's eqs. (18) and (19).
    """
    real, imag = sp.S.Zero, sp.S.Zero
    for term in sp.Add.make_args(on_unit_circle()):
        re_part, im_part = term.as_real_imag()
        real += re_part
        imag += im_part
    collect = [model.alpha, model.beta, model.gamma]
    return (sp.collect(sp.expand(real), collect), sp.collect(sp.expand(imag), collect))
