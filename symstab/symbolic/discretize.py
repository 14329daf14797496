"""The zero-order-hold pulse transfer function, derived from G(s).

Z[ZOH G(s)] = (1 - z^-1) Z[G(s)/s], and the z-transform of the sampled
impulse response of F(s) = G(s)/s is the sum of the residues of
F(s) z / (z - exp(s T)) at the poles of F (a double pole at s = 0 and a
simple pole at s = -b/m).  Nothing here is typed in from the paper's eq. (4).
"""

import functools

import sympy as sp

from . import model

__all__ = [
    "z_transform_by_residues", "written_poles", "zoh_pulse_transfer_function", "numeric_zoh",
    "pulse_transfer_function",
    "dimensionless_pulse_transfer_function",
]


def z_transform_by_residues(F, *, s=model.s, z=model.z, T=model.T):
    """Return Z[f(kT)] for a rational F(s) that is strictly proper.

    Z[f(kT)] = sum over the poles p of F of Res(F(s) z / (z - exp(s T)), p).
    """
    num, den = sp.fraction(sp.together(F))
    if sp.degree(num, s) >= sp.degree(den, s):
        raise ValueError("F(s) must be strictly proper for the residue formula")
    kernel = F * z / (z - sp.exp(s * T))
    return sp.Add(*[sp.residue(kernel, s, pole) for pole in sp.roots(den, s)])


@functools.lru_cache(maxsize=None)
def pulse_transfer_function():
    """Return Z[ZOH G(s)] in the physical parameters m, b, T.

    Returns
    -------
    sympy.Expr
        A rational function of ``z``, the derived counterpart of eq. (4).
    """
    step_response = z_transform_by_residues(model.plant() / model.s)
    return sp.factor(sp.simplify((1 - 1 / model.z) * step_response))


@functools.lru_cache(maxsize=None)
def dimensionless_pulse_transfer_function():
    """Return ``(m / T**2) Z[ZOH G(s)]`` in ``delta`` and ``Gamma``.

    With ``b = delta m / T`` the factor ``T**2 / m`` separates and the rest
    depends on ``delta`` and ``Gamma = exp(delta)`` only:
    ``N(z) / (delta**2 (z - 1) (Gamma z - 1))``.
    """
    scaled = (pulse_transfer_function() * model.m / model.T**2).subs(model.dimensionless_substitution())
    scaled = sp.simplify(scaled).subs(sp.exp(model.delta), model.Gamma)
    result = sp.factor(sp.cancel(scaled), model.z)
    if result.has(model.m) or result.has(model.T):
        raise AssertionError(f"pulse transfer function did not become dimensionless: {result}")
    return result


def written_poles(F, s=model.s):
    """Poles of a rational ``F(s)`` with multiplicities, if SymPy writes them briefly.

    Returns ``{pole: multiplicity}`` when the denominator factors, over the
    parameters, into factors of degree 1 or 2 in ``s``: each pole is then
    ``-b/m`` or ``(-b +- sqrt(b**2 - 4 m k)) / (2 m)`` (a complex pair when
    the factor is underdamped; their terms of the pulse transfer function
    add up to a real one).  Otherwise ``None``: the roots of a cubic or a
    quartic in radicals are too large to be worth carrying, and the plant
    is discretised numerically (:func:`numeric_zoh`).
    """
    _, den = sp.fraction(sp.together(F))
    _, factors = sp.factor_list(sp.expand(den), s)
    poles = {}
    for factor, power in factors:
        degree = sp.degree(factor, s)
        if degree == 0:
            continue
        if degree > 2:
            return None
        for pole, multiplicity in sp.roots(factor, s).items():
            poles[pole] = poles.get(pole, 0) + power * multiplicity
    return poles


def zoh_pulse_transfer_function(G, *, s=model.s, z=model.z, T=model.T):
    """Z[ZOH G(s)] for a proper rational ``G(s)`` whose poles SymPy writes (:func:`written_poles`).

    ``(1 - 1/z) Z[G(s) / s]``, with ``Z[G(s) / s]`` the sum over the poles
    ``p`` of ``G(s) / s`` of the residues of ``G(s) / s * z / (z - exp(s
    T))``: at a simple pole ``N(p) / D'(p) * z / (z - exp(p T))`` (a series
    expansion there is needlessly slow for a complex pair), at a repeated
    one by SymPy's ``residue`` (a frictionless mass ``1 / (m s**2)`` has a
    triple pole of ``G / s`` at 0).

    Returns
    -------
    sympy.Expr
        A rational function of ``z`` (``cancel``-ed), with ``exp`` of the
        poles times ``T`` in its coefficients.

    Raises
    ------
    ValueError
        If ``G`` is not proper, or its denominator has a factor of degree 3
        or more in ``s`` (then use :func:`numeric_zoh`).
    """
    F = sp.together(G / s)
    poles = written_poles(F, s)
    if poles is None:
        raise ValueError("the plant's denominator has a factor of degree 3 or more in s over "
                         "its parameters: its poles are not written in closed form")
    num, den = sp.fraction(F)
    if sp.degree(num, s) >= sp.degree(den, s):
        raise ValueError("G(s) must be proper")
    slope = sp.diff(den, s)
    kernel = F * z / (z - sp.exp(s * T))
    terms = []
    for pole, multiplicity in poles.items():
        if multiplicity == 1:
            terms.append(num.subs(s, pole) / slope.subs(s, pole) * z / (z - sp.exp(pole * T)))
        else:
            terms.append(sp.residue(kernel, s, pole))
    return sp.cancel(sp.together((1 - 1 / z) * sp.Add(*terms)))


def _charpoly(A):
    """Characteristic polynomial det(z I - A) of an mpmath matrix, highest power first.

    Faddeev-LeVerrier: exact in exact arithmetic, and at 30+ digits more than
    good enough for the few states of a haptic device.
    """
    import mpmath

    n = A.rows
    coefficients = [mpmath.mpf(1)]
    M = mpmath.zeros(n, n)
    for k in range(1, n + 1):
        M = A * M + coefficients[-1] * mpmath.eye(n)
        AM = A * M
        coefficients.append(-sum(AM[i, i] for i in range(n)) / k)
    return coefficients


def numeric_zoh(numerator, denominator, T, *, dps=30):
    """Z[ZOH G] of a numeric proper ``G(s)`` by the matrix exponential.

    ``G = num / den`` (coefficients highest power first) is realised in
    controllable canonical form ``(A, B, C, D)``; ``exp([[A, B], [0, 0]] T)``
    gives ``Phi`` and ``Gamma``, and

        Z[ZOH G](z) = C (z I - Phi)^-1 Gamma + D
                    = (det(z I - Phi + Gamma C) - det(z I - Phi)) / det(z I - Phi) + D

    by the matrix determinant lemma.  Everything is computed at ``dps``
    digits with mpmath.

    Returns
    -------
    (list of mpmath.mpf, list of mpmath.mpf)
        Numerator and denominator of the pulse transfer function in ``z``,
        highest power first; the denominator is monic of the plant's order.
    """
    import mpmath

    with mpmath.workdps(dps):
        den = [mpmath.mpf(c) for c in denominator]
        num = [mpmath.mpf(c) for c in numerator]
        while den and den[0] == 0:
            den.pop(0)
        n = len(den) - 1
        if n < 1:
            raise ValueError("the plant must have at least one pole")
        num = [c / den[0] for c in num]
        den = [c / den[0] for c in den]
        if len(num) > n + 1:
            if any(c != 0 for c in num[: len(num) - n - 1]):
                raise ValueError("the plant must be proper (degree of numerator <= degree of denominator)")
            num = num[len(num) - n - 1:]
        num = [mpmath.mpf(0)] * (n + 1 - len(num)) + num
        direct = num[0]
        rest = [num[k] - direct * den[k] for k in range(1, n + 1)]
        A = mpmath.zeros(n + 1, n + 1)
        for j in range(n):
            A[0, j] = -den[j + 1]
        for i in range(1, n):
            A[i, i - 1] = 1
        A[0, n] = 1
        E = mpmath.expm(A * T)
        Phi = E[:n, :n]
        Gamma = E[:n, n]
        C = mpmath.matrix([rest])
        open_loop = _charpoly(Phi)
        shifted = _charpoly(Phi - Gamma * C)
        numerator = [shifted[k] - open_loop[k] + direct * open_loop[k] for k in range(n + 1)]
        return numerator, open_loop
