"""The zero-order-hold pulse transfer function, derived from G(s).

Z[ZOH G(s)] = (1 - z^-1) Z[G(s)/s], and the z-transform of the sampled
impulse response of F(s) = G(s)/s is the sum of the residues of
F(s) z / (z - exp(s T)) at the poles of F (a double pole at s = 0 and a
simple pole at s = -b/m).  Nothing here is typed in from the paper's eq. (4).
"""

import functools
import math

import sympy as sp

from . import model

__all__ = [
    "z_transform_by_residues", "written_poles", "zoh_pulse_transfer_function",
    "fractional_zoh_pulse_transfer_function", "fractional_delay_identities", "numeric_zoh",
    "numeric_fractional_zoh",
    "interval_zoh", "interval_fractional_zoh", "interval_product",
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
    # factor() alone writes it as simplify() then factor() did (the same
    # srepr, without simplify's 0.15 s in every process that derives).
    return sp.factor((1 - 1 / model.z) * step_response)


@functools.lru_cache(maxsize=None)
def dimensionless_pulse_transfer_function():
    """Return ``(m / T**2) Z[ZOH G(s)]`` in ``delta`` and ``Gamma``.

    With ``b = delta m / T`` the factor ``T**2 / m`` separates and the rest
    depends on ``delta`` and ``Gamma = exp(delta)`` only:
    ``N(z) / (delta**2 (z - 1) (Gamma z - 1))``.
    """
    scaled = (pulse_transfer_function() * model.m / model.T**2).subs(model.dimensionless_substitution())
    # cancel() and factor() give the form a simplify() first gave (the same srepr).
    result = sp.factor(sp.cancel(scaled.subs(sp.exp(model.delta), model.Gamma)), model.z)
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
    poles = _written_poles(sp.sympify(F), s)
    return None if poles is None else dict(poles)


@functools.lru_cache(maxsize=64)
def _written_poles(F, s):
    """:func:`written_poles`, kept: a loop asks when it is built (which ZOH?) and again when it
    derives its ZOH by residues (a factorisation over the parameters each time)."""
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
    return sp.cancel(sp.together((1 - 1 / z) * _step_transform(G, 0, s, z, T)))


def fractional_zoh_pulse_transfer_function(G, eps, *, s=model.s, z=model.z, T=model.T):
    """Z[ZOH G(s)] with the hold's output delayed by ``eps`` of a period: the modified z-transform.

    The plant's input is the held command delayed by ``eps T``, ``0 <= eps
    < 1`` (a loop delay of ``(d + eps) T`` is this times ``z**-d``).  With
    ``f`` the step response of ``G`` (``f(0) = 0`` for a strictly proper
    ``G``), the sampled output is ``(1 - 1/z) sum_k f((k - eps) T) z**-k``,
    and ``sum_k f((k - eps) T) z**-k = z**-1 sum_j f((j + 1 - eps) T) z**-j``
    is the modified z-transform of ``F = G / s`` at ``m = 1 - eps``: the sum
    over the poles ``p`` of ``F`` of the residues of ``F(s) exp((1 - eps) s
    T) z / (z - exp(s T))`` (Jury; Åström and Wittenmark, *Computer-Controlled
    Systems*, sec. 2.3 write the same with the state-space Γ₀ and Γ₁).  So::

        P_eps(z) = (z - 1) / z**2 * sum_p Res(F(s) exp((1 - eps) s T) z / (z - exp(s T)), p)

    ``eps = 0`` is :func:`zoh_pulse_transfer_function` (the residues' sum at
    ``m = 1`` is ``z (Z[F] - f(0))``) and ``eps -> 1`` is it times ``1 / z``,
    one more sample of delay: :func:`fractional_delay_identities` proves both.

    Parameters
    ----------
    G : sympy.Expr
        A strictly proper rational ``G(s)`` whose poles SymPy writes
        (:func:`written_poles`).
    eps : sympy.Symbol or number
        The fraction of a period, ``0 <= eps < 1``.

    Returns
    -------
    sympy.Expr
        A rational function of ``z`` (``cancel``-ed) whose coefficients hold
        ``exp(p T)`` and ``exp((1 - eps) p T)``.

    Raises
    ------
    ValueError
        If ``G`` is not strictly proper (a direct feedthrough makes the
        output jump at ``eps T``, inside the period), or its poles are not
        written (a factor of degree 3 or more).

    Examples
    --------
    >>> m, b, T, eps, s, z = sp.symbols("m b T epsilon s z", positive=True)
    >>> P = fractional_zoh_pulse_transfer_function(1 / (m * s**2), eps, s=s, z=z, T=T)
    >>> sp.factor(P)
    T**2*(epsilon**2*z**2 - 2*epsilon**2*z + epsilon**2 - 2*epsilon*z**2 + 2*epsilon*z + z**2 + z)/(2*m*z*(z - 1)**2)
    """
    num, den = sp.fraction(sp.together(G))
    if sp.degree(num, s) >= sp.degree(den, s):
        raise ValueError("G(s) must be strictly proper for a fractional delay: a direct "
                         "feedthrough makes the output jump inside the period")
    return sp.cancel(sp.together((z - 1) / z**2 * _step_transform(G, 1 - eps, s, z, T)))


def _step_transform(G, shift, s, z, T):
    """``sum_p Res(G(s) / s * exp(shift s T) * z / (z - exp(s T)), p)`` over the poles of ``G / s``.

    ``shift = 0``: the z-transform of the sampled step response; ``shift = 1
    - eps``: its modified z-transform.  A simple pole's residue is written
    directly, a repeated one's is SymPy's ``residue``.
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
    kernel = F * sp.exp(shift * s * T) * z / (z - sp.exp(s * T))
    terms = []
    for pole, multiplicity in poles.items():
        if multiplicity == 1:
            terms.append(num.subs(s, pole) / slope.subs(s, pole) * sp.exp(shift * pole * T)
                         * z / (z - sp.exp(pole * T)))
        else:
            terms.append(sp.residue(kernel, s, pole))
    return sp.Add(*terms)


def fractional_delay_identities(G, *, s=model.s, z=model.z, T=model.T):
    """The two limits of a fractional delay, proved: ``(P_0 - P, P_1 - P / z)``, both exactly 0.

    ``P`` is :func:`zoh_pulse_transfer_function` of ``G`` and ``P_eps``
    :func:`fractional_zoh_pulse_transfer_function`: no fraction is today's
    integer-delay plant, and a whole period of it is one more sample of
    delay.  Each difference is ``cancel``-ed with the exponentials of the
    poles as independent generators (a rational identity in them holds for
    their values), so a zero here is a proof.

    Returns
    -------
    (sympy.Expr, sympy.Expr)
    """
    eps = sp.Dummy("epsilon")
    plant = zoh_pulse_transfer_function(G, s=s, z=z, T=T)
    fractional = fractional_zoh_pulse_transfer_function(G, eps, s=s, z=z, T=T)
    # exp((1 - eps) p T) is exp(p T) at eps = 0 and 1 at eps = 1, written as SymPy writes them
    # in the integer-delay plant: cancel() takes them as the same generators.
    return (sp.cancel(sp.together(fractional.subs(eps, 0) - plant)),
            sp.cancel(sp.together(fractional.subs(eps, 1) - plant / z)))


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
        augmented, C, direct, n = _realisation(numerator, denominator)
        E = mpmath.expm(augmented * T)
        Phi, Gamma = E[:n, :n], E[:n, n]
        open_loop = _charpoly(Phi)
        shifted = _charpoly(Phi - Gamma * C)
        numerator = [shifted[k] - open_loop[k] + direct * open_loop[k] for k in range(n + 1)]
        return numerator, open_loop


def numeric_fractional_zoh(numerator, denominator, T, eps, *, dps=30):
    """:func:`fractional_zoh_pulse_transfer_function` of a numeric ``G(s)``, by the matrix exponential.

    The hold's output delayed by ``eps T`` inside the period (Åström and
    Wittenmark, sec. 2.3): ``x[k+1] = Phi x[k] + Gamma0 u[k] + Gamma1 u[k-1]``
    with ``Gamma0 = int_0^((1 - eps) T) exp(A s) ds B`` and ``Gamma1 = exp(A
    (1 - eps) T) int_0^(eps T) exp(A s) ds B`` (each from the exponential of
    the augmented matrix, as :func:`numeric_zoh`), so::

        P_eps(z) = C (z I - Phi)^-1 (Gamma0 + Gamma1 / z)
                 = (z L0(z) + L1(z)) / (z det(z I - Phi)),
        Lk(z) = det(z I - Phi + Gammak C) - det(z I - Phi)

    by the matrix determinant lemma, at ``dps`` digits.

    Parameters
    ----------
    numerator, denominator : sequence of float
        ``G(s)``, highest power first, strictly proper.
    T : float
        The sample period, > 0.
    eps : float
        The fraction of a period, ``0 <= eps < 1``.

    Returns
    -------
    (list of mpmath.mpf, list of mpmath.mpf)
        Numerator and denominator in ``z``, highest power first, both of
        the plant's order plus one; the denominator is ``z`` times
        :func:`numeric_zoh`'s.

    Raises
    ------
    ValueError
        For a plant with a direct feedthrough, or ``eps`` outside ``[0, 1)``.
    """
    import mpmath

    if not 0 <= eps < 1:
        raise ValueError(f"eps must be a fraction of a period, 0 <= eps < 1, got {eps!r}")
    with mpmath.workdps(dps):
        augmented, C, direct, n = _realisation(numerator, denominator)
        if direct != 0:
            raise ValueError("G(s) must be strictly proper for a fractional delay: a direct "
                             "feedthrough makes the output jump inside the period")
        late = mpmath.expm(augmented * ((1 - mpmath.mpf(eps)) * T))
        early = mpmath.expm(augmented * (mpmath.mpf(eps) * T))
        Phi = mpmath.expm(augmented[:n, :n] * T)
        gamma0, gamma1 = late[:n, n], late[:n, :n] * early[:n, n]
        open_loop = _charpoly(Phi)
        first, second = (_charpoly(Phi - gamma * C) for gamma in (gamma0, gamma1))
        numerator = [mpmath.mpf(0)] * (n + 2)
        for k in range(n + 1):
            numerator[k] += first[k] - open_loop[k]         # z L0(z)
            numerator[k + 1] += second[k] - open_loop[k]    # L1(z)
        return numerator, open_loop + [mpmath.mpf(0)]


def _realisation(numerator, denominator):
    """``(augmented, C, D, n)``: ``G(s)`` in controllable canonical form, at the working precision.

    ``augmented = [[A, B], [0, 0]]`` (its exponential times ``t`` holds
    ``exp(A t)`` and ``int_0^t exp(A s) ds B``), ``C`` a row, ``D`` the
    direct term, ``n`` the order.
    """
    import mpmath

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
    return A, mpmath.matrix([rest]), direct, n


def _interval_expm1(M, n):
    """An enclosure of ``exp(M) - I`` for an ``n x n`` matrix ``M`` of :mod:`mpmath.iv` numbers.

    ``M`` is a list of rows.  Taylor terms until the remainder's bound
    ``mu**(K + 1) / (K + 1)! / (1 - mu / (K + 2))`` (``mu`` the infinity
    norm, at most 1/2 after scaling by a power of 2) is below 1e-40 (at most
    40 terms), that bound added to every entry, then squared back as ``X (X
    + 2 I)`` (``exp(2 M) - I`` from ``X = exp(M) - I``): the ``- I`` is
    never formed by subtraction, so a pole next to ``z = 1`` keeps its
    digits (the expm1 of a matrix).

    The matrix products run on mpmath's raw intervals (``libmpi``, the
    functions :mod:`mpmath.iv` calls, at its precision: the same
    enclosures) and skip the exact zeros of a realisation's companion
    matrix (adding ``0 x`` to a sum at full precision changes nothing):
    the robust regions enclose thousands of sub-boxes.
    """
    from mpmath import iv
    from mpmath.libmp import (
        fhalf,
        finf,
        fone,
        from_float,
        from_int,
        fzero,
        mpf_gt,
        mpf_lt,
        mpf_neg,
        mpf_shift,
        mpi_abs,
        mpi_add,
        mpi_div,
        mpi_mul,
        mpi_pow,
        mpi_sub,
        to_float,
    )
    from mpmath.libmp.libmpi import mpi_zero

    prec = iv.prec
    M = [[c._mpi_ for c in row] for row in M]
    mu = fzero
    for row in M:
        total = mpi_zero
        for c in row:
            total = mpi_add(total, mpi_abs(c, prec), prec)
        if mpf_gt(total[1], mu):
            mu = total[1]
    if mu == finf:
        raise ValueError("the plant's realisation is not bounded over the box")
    scale = 0
    while mpf_gt(mu, fhalf):
        mu, scale = mpf_shift(mu, -1), scale + 1
    if scale:
        factor = (mpf_shift(fone, -scale),) * 2
        M = [[mpi_mul(c, factor, prec) for c in row] for row in M]
    X = [[mpi_zero] * n for _ in range(n)]
    term = [[(fone, fone) if i == j else mpi_zero for j in range(n)] for i in range(n)]
    mu_float = to_float(mu)
    mu = (mu, mu)
    tiny = from_float(1e-40)
    for k in range(1, 41):
        divisor = (from_int(k),) * 2
        term = [[c if c == mpi_zero else mpi_div(c, divisor, prec) for c in row]
                for row in _raw_product(term, M, prec)]
        X = [[x if t == mpi_zero else mpi_add(x, t, prec) for x, t in zip(rx, rt, strict=True)]
             for rx, rt in zip(X, term, strict=True)]
        # mu is an upper bound of ||M|| (rounded up by the interval sum).  The
        # bound decreases with k: where a float estimate of it is far above
        # 1e-40, the enclosure's check cannot stop the series yet.
        if k < 40 and mu_float ** (k + 1) / math.factorial(k + 1) > 1e-38:
            continue
        rest = mpi_div(mpi_div(mpi_pow(mu, (from_int(k + 1),) * 2, prec),
                               _interval_factorial(k + 1, prec), prec),
                       mpi_sub((fone, fone), mpi_div(mu, (from_int(k + 2),) * 2, prec), prec),
                       prec)
        if mpf_lt(rest[1], tiny):
            break
    rest = (mpf_neg(rest[1]), rest[1])
    X = [[mpi_add(x, rest, prec) for x in row] for row in X]
    two = (from_int(2),) * 2
    for _ in range(scale):
        X = _raw_product(X, [[mpi_add(x, two, prec) if i == j else x for j, x in enumerate(row)]
                             for i, row in enumerate(X)], prec)
    return [[iv.make_mpf(x) for x in row] for row in X]


def _raw_product(a, b, prec):
    """``a b`` for square matrices of raw mpmath intervals, exact zero products skipped."""
    from mpmath.libmp import mpi_add, mpi_mul
    from mpmath.libmp.libmpi import mpi_zero

    n = len(a)
    out = []
    for i in range(n):
        row = []
        for j in range(n):
            total = mpi_zero
            for k in range(n):
                if a[i][k] != mpi_zero and b[k][j] != mpi_zero:
                    total = mpi_add(total, mpi_mul(a[i][k], b[k][j], prec), prec)
            row.append(total)
        out.append(row)
    return out


@functools.lru_cache(maxsize=None)
def _interval_factorial(k, prec):
    """``iv.factorial(k)`` at ``prec`` bits (the current precision) as a raw interval, once."""
    from mpmath import iv

    return iv.factorial(k)._mpi_


def interval_zoh(numerator, denominator, T):
    """Enclosures of Z[ZOH G]'s coefficients in ``w = z - 1`` over intervals of G's coefficients.

    The interval counterpart of :func:`numeric_zoh` (same realisation),
    for the robust regions of :mod:`symstab.numeric.analysis.robust`:
    ``numerator`` and ``denominator`` are :class:`mpmath.iv.mpf` intervals
    of ``G``'s coefficients in ``s`` (highest power first) and ``T`` one of
    the period.  ``Psi = exp([[A, B], [0, 0]] T) - I`` is enclosed with a
    bounded Taylor remainder, and the coefficients in ``w`` come from
    ``det(w I - (Phi - I))`` and ``C adj(w I - (Phi - I)) Gamma + D det(...)``
    (by cofactors), never from a difference of two characteristic
    polynomials: an integrator's pole ``z = 1`` then leaves ``P_d(1)``
    zero to within the Taylor remainder (below 1e-40) however wide the
    intervals, and the rest stays within a few times the true spread of the
    coefficients.

    Parameters
    ----------
    numerator, denominator : list of mpmath.iv.mpf
        ``G``'s numerator and denominator coefficients in ``s``, highest
        power first.
    T : mpmath.iv.mpf
        The sample period.

    Returns
    -------
    (list of mpmath.iv.mpf, list of mpmath.iv.mpf)
        ``P_n`` and ``P_d`` in powers of ``w = z - 1``, highest first;
        ``P_d`` monic of the plant's order.

    Raises
    ------
    ValueError
        If the denominator's leading coefficient can vanish, or the plant
        is not proper.
    """
    rest, direct, n, A = _interval_realisation(numerator, denominator)
    X = _interval_expm1(_scaled(A, T), n + 1)
    entries = _shifted_entries(X, n)
    p_d = _poly_det(entries)
    gamma = [X[j][n] for j in range(n)]
    term = _adjugate_term(_cofactors(entries, rest), rest, gamma)
    return _poly_add([direct * c for c in p_d], term), p_d


def interval_fractional_zoh(numerator, denominator, T):
    """Enclosures of the fractional-delay plant's ``(N_eps, z P_d)`` in ``w = z - 1``, per interval of ``eps``.

    The interval counterpart of :func:`numeric_fractional_zoh` and the
    fractional one of :func:`interval_zoh` (same realisation): returns a
    function of an interval ``eps`` of the fraction of a period (within
    [0, 1]) whose enclosures hold for every ``eps`` in it.  With ``Gamma0 =
    int_0^((1 - eps) T) exp(A s) ds B`` and ``Gamma = Gamma0 + Gamma1`` (the
    whole period's; ``Gamma1 = exp(A (1 - eps) T) int_0^(eps T) exp(A s) ds B``
    is the rest of the integral), ``P_eps = C (z I - Phi)^-1 (Gamma0 +
    Gamma1 / z) = N_eps / (z P_d)`` with::

        N_eps = z L0 + (P_n - L0) = w L0 + P_n,   L0 = C adj(w I - (Phi - I)) Gamma0,

    ``P_n, P_d`` :func:`interval_zoh`'s and ``L0`` by the same cofactors.
    Only ``Gamma0`` depends on ``eps``, and only through ``w L0``: the
    integrator's pole ``z = 1`` is kept as by :func:`interval_zoh`,
    ``N_eps(1) = P_n(1)`` whatever the width of ``eps``, and what does not depend on ``eps`` (``Phi``, ``P_n``,
    ``z P_d``, the cofactors) is computed once, here.  At ``eps = 1``
    (``Gamma0 = 0``) ``N_eps`` is ``P_n``: the plant of one more whole
    sample, so that the pieces of a delay range meet; at ``eps = 0`` it is
    ``z P_n``.

    Parameters
    ----------
    numerator, denominator : list of mpmath.iv.mpf
        ``G``'s numerator and denominator coefficients in ``s``, highest
        power first; ``G`` strictly proper.
    T : mpmath.iv.mpf
        The sample period.

    Returns
    -------
    callable
        ``eps -> (N_eps, z P_d)``, ``eps`` an :class:`mpmath.iv.mpf` within
        [0, 1]: ``N_eps`` (of the plant's order) and ``z P_d`` (monic, of the
        order plus one) in powers of ``w = z - 1``, highest first, lists of
        :class:`mpmath.iv.mpf` at the precision of the call.

    Raises
    ------
    ValueError
        As :func:`interval_zoh`; and for a direct feedthrough (here), or an
        ``eps`` not within [0, 1] (by the function).

    Examples
    --------
    >>> from mpmath import iv
    >>> at = interval_fractional_zoh([iv.mpf(1)], [iv.mpf(1), iv.mpf(0)], iv.mpf(1))
    >>> n_eps, z_p_d = at(iv.mpf([0.25, 0.5]))       # G = 1/s: ((1 - eps) z + eps) / (z (z - 1))
    >>> [(round(float(c.a), 9), round(float(c.b), 9)) for c in n_eps]
    [(0.5, 0.75), (1.0, 1.0)]
    >>> [(round(float(c.a), 9), round(float(c.b), 9)) for c in z_p_d[:2]], float(z_p_d[2].b) < 1e-40
    ([(1.0, 1.0), (1.0, 1.0)], True)
    """
    from mpmath import iv

    rest, direct, n, A = _interval_realisation(numerator, denominator)
    if not (direct.a == 0 and direct.b == 0):
        raise ValueError("G(s) must be strictly proper for a fractional delay: a direct "
                         "feedthrough makes the output jump inside the period")
    X = _interval_expm1(_scaled(A, T), n + 1)
    entries = _shifted_entries(X, n)
    p_d = _poly_det(entries)
    cofactors = _cofactors(entries, rest)
    p_n = _adjugate_term(cofactors, rest, [X[j][n] for j in range(n)])
    z_p_d = _poly_add(p_d + [iv.mpf(0)], p_d)

    starts = {}

    def at(eps):
        if not (eps.a >= 0 and eps.b <= 1):
            raise ValueError(f"eps must be within [0, 1] (a fraction of a period), got {eps}")
        l0 = _adjugate_term(cofactors, rest, _late_integral(A, n, (1 - eps) * T, starts))
        # L0 has degree n - 1 (its first of n + 1 terms is an exact 0): w L0 is its
        # terms moved up by one, within n + 1 terms.
        return _poly_add(l0[1:] + [iv.mpf(0)], p_n), list(z_p_d)

    return at


def _late_integral(A, n, tau, starts):
    """``Gamma0 = int_0^tau exp(A s) ds B`` over an interval ``tau = [t0, t1]``, enclosed as
    ``Gamma0(t0) + exp(A t0) Gamma0([0, t1 - t0])``.

    The exponential at the point ``t0`` (kept in ``starts``: the halves of an
    interval share an end) is as narrow as the working precision; the one over
    the interval starts at 0 and is as wide as the interval, whose Taylor terms
    then hardly overestimate -- unlike ``exp(A tau)`` with ``tau`` wide, whose
    squarings multiply the interval's width (an actuator's fast pole: a hundred
    times the true spread of ``N_eps``).
    """
    from mpmath import iv

    start = iv.mpf(tau.a)
    key = start._mpi_
    if key not in starts:
        starts[key] = _interval_expm1(_scaled(A, start), n + 1)
    head = starts[key]
    tail = _interval_expm1(_scaled(A, tau - start), n + 1)
    return [head[j][n] + tail[j][n] + sum((head[j][k] * tail[k][n] for k in range(n)), iv.mpf(0))
            for j in range(n)]


def _interval_realisation(numerator, denominator):
    """``(rest, direct, n, A)``: :func:`_realisation` of interval coefficients, before the period.

    ``A`` is the augmented ``[[A, B], [0, 0]]`` as a list of rows (exact
    zeros where the companion form has them), ``rest`` the row ``C``.
    """
    from mpmath import iv

    den = list(denominator)
    while den and den[0].a == 0 and den[0].b == 0:
        den.pop(0)
    n = len(den) - 1
    if n < 1:
        raise ValueError("the plant must have at least one pole")
    if n > MAX_INTERVAL_ORDER:
        raise ValueError(f"the plant's order is {n}: robust regions take plants of order up to "
                         f"{MAX_INTERVAL_ORDER}")
    if 0 in den[0]:
        raise ValueError("the leading coefficient of the plant's denominator can vanish in the box")
    num = list(numerator)
    if len(num) > n + 1:
        if any(not (c.a == 0 and c.b == 0) for c in num[:len(num) - n - 1]):
            raise ValueError("the plant must be proper (degree of numerator <= degree of denominator)")
        num = num[len(num) - n - 1:]
    num = [c / den[0] for c in num]
    den = [c / den[0] for c in den]
    num = [iv.mpf(0)] * (n + 1 - len(num)) + num
    direct = num[0]
    rest = [num[k] - direct * den[k] for k in range(1, n + 1)]
    A = [[None] * (n + 1) for _ in range(n + 1)]
    for j in range(n):
        A[0][j] = -den[j + 1]
    for i in range(1, n):
        A[i][i - 1] = iv.mpf(1)
    A[0][n] = iv.mpf(1)
    return rest, direct, n, A


def _scaled(A, t):
    """``A t`` (exact zeros, None in ``A``, kept exact)."""
    from mpmath import iv

    return [[iv.mpf(0) if c is None else c * t for c in row] for row in A]


def _shifted_entries(X, n):
    """``w I - Psi`` (``Psi`` the top-left ``n x n`` block of ``X``) as a matrix of polynomials in
    ``w``: its determinant and adjugate by cofactors keep an exact zero column of ``Psi`` (an
    integrator's) an exact zero of ``P_d(1)``."""
    from mpmath import iv

    return [[[iv.mpf(1), -X[i][j]] if i == j else [-X[i][j]] for j in range(n)]
            for i in range(n)]


def _cofactors(entries, rest):
    """``{(i, j): (-1)**(i + j) det(minor without row j, column i)}`` of ``entries``
    (:func:`_shifted_entries`), for the ``i`` where ``C`` (``rest``) is not an exact 0: the
    adjugate's entries that ``C adj(w I - Psi)`` reads."""
    from mpmath import iv

    n = len(entries)
    out = {}
    for i in range(n):
        if rest[i].a == 0 and rest[i].b == 0:
            continue
        for j in range(n):
            minor = [[entries[r][c] for c in range(n) if c != i] for r in range(n) if r != j]
            cofactor = _poly_det(minor) if minor else [iv.mpf(1)]
            out[i, j] = [-c for c in cofactor] if (i + j) % 2 else cofactor
    return out


def _adjugate_term(cofactors, rest, gamma):
    """``C adj(w I - Psi) Gamma`` from :func:`_cofactors`, ``n + 1`` terms in ``w``."""
    from mpmath import iv

    n = len(rest)
    out = [iv.mpf(0)] * (n + 1)
    for (i, j), cofactor in cofactors.items():
        weight = rest[i] * gamma[j]
        if weight.a == 0 and weight.b == 0:
            continue
        for k, c in enumerate(reversed(cofactor)):
            out[n - k] += weight * c
    return out


#: The largest plant order :func:`interval_zoh` takes (its determinants are
#: cofactor expansions, n! products).
MAX_INTERVAL_ORDER = 6


def _poly_add(a, b):
    """Sum of two polynomials (lists highest first) of :mod:`mpmath.iv` numbers."""
    from mpmath import iv

    n = max(len(a), len(b))
    a = [iv.mpf(0)] * (n - len(a)) + list(a)
    b = [iv.mpf(0)] * (n - len(b)) + list(b)
    return [x + y for x, y in zip(a, b, strict=True)]


def interval_product(a, b):
    """Product of two polynomials of :mod:`mpmath.iv` numbers (enclosing every product).

    On mpmath's raw intervals (what :mod:`mpmath.iv` calls, at its
    precision: the same enclosures), exact zero products skipped.

    Parameters
    ----------
    a, b : list of mpmath.iv.mpf
        Coefficients, highest power first.

    Returns
    -------
    list of mpmath.iv.mpf
    """
    from mpmath import iv
    from mpmath.libmp import mpi_add, mpi_mul
    from mpmath.libmp.libmpi import mpi_zero

    prec = iv.prec
    a = [x._mpi_ for x in a]
    b = [y._mpi_ for y in b]
    out = [mpi_zero] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        if x == mpi_zero:
            continue
        for j, y in enumerate(b):
            if y != mpi_zero:
                out[i + j] = mpi_add(out[i + j], mpi_mul(x, y, prec), prec)
    return [iv.make_mpf(c) for c in out]


def _poly_det(matrix):
    """Determinant of a square matrix of polynomials, by cofactors along the first row."""
    n = len(matrix)
    if n == 1:
        return list(matrix[0][0])
    total = [matrix[0][0][0] * 0]
    for j in range(n):
        entry = matrix[0][j]
        if all(c.a == 0 and c.b == 0 for c in entry):
            continue
        minor = [row[:j] + row[j + 1:] for row in matrix[1:]]
        term = interval_product(entry, _poly_det(minor))
        total = _poly_add(total, term if j % 2 == 0 else [-c for c in term])
    return total
