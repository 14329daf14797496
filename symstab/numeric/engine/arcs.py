"""The arc of a loop's parameter plane: where ``exp(j theta)`` is a root, with sin(theta) divided out.

For a plane of two affine parameters, ``chi = A0 + x Ax + y Ay``, the root
``z = exp(j theta)`` is two real equations, linear in ``(x, y)``.  With
``[P, Q] = Im(P(z) conj Q(z))`` Cramer's rule reads::

    x = [A0, Ay] / [Ay, Ax],    y = [Ax, A0] / [Ay, Ax].

For real coefficients ``[P, Q] = sum_jk p_j q_k sin((j - k) theta)``: every
bracket carries a factor ``sin(theta)``, so the solve is 0/0 at ``theta = 0``
and ``pi``, and Cramer's rule on the values ``P(z)``, ``Q(z)`` loses the
digits of that factor (8 of them at ``theta = 1e-4``).  Here each bracket is
the sine series ``sum_m e_m sin(m theta)`` with exact coefficients ``e_m``
(the products ``p_j q_k`` summed without rounding, once per plane), divided
by ``sin(theta)`` term by term: ``sin(m theta) / sin(theta)`` (Chebyshev's
``U_{m-1}(cos theta)``) is computed from ``m theta`` carried exactly (the
generated ``sin_multiple``), so it keeps its digits at both ends.

A :class:`~symstab.numeric.engine.polynomial.DelayedPolynomial` ``z**s D + N``
gives each bracket three clusters of frequencies (``D`` with ``D`` and ``N``
with ``N`` near 0, ``D`` with ``N`` near ``s``): O(deg D + deg N) terms per
angle whatever the delay.

Two arc sources share one interface, ``source(theta) -> (x, y, det)``:

* :class:`CramerArc` -- the solve above, for any loop;
* :class:`ClosedFormArc` -- a loop whose arc SymPy derived in closed form
  (the paper's: the generated kernel ``symstab._generated.kernels.boundary``,
  :func:`symstab.numeric.paper.paper_loop.paper_arc`), with the determinant's sign
  from the structured solve.

:func:`crossing_change` is the one crossing-direction rule: how the number of
roots outside the circle changes when a parameter moves through a point
where a root is on the circle.
"""

import dataclasses
import fractions
import functools
import math

import numpy as np

from ..._generated import kernels
from .polynomial import DelayedPolynomial

__all__ = ["ArcSource", "Brackets", "CramerArc", "ClosedFormArc", "RememberedArc",
           "ExactPolynomial", "sine_ratio", "crossing_change", "SINGULAR", "END_ANGLE",
           "EXACT_TERMS"]

#: The determinant is called singular (the arc is at infinity, x and y NaN)
#: where it is at most this fraction of the rounding scale of its sine
#: series, ``sum_m |e_m sin(m theta) / sin(theta)|``.
SINGULAR = 1e-12
#: Below this angle (and above pi less it) the brackets are polynomials in
#: ``sin(theta/2)**2`` (``cos(theta/2)**2``) with exact coefficients.
END_ANGLE = np.pi / 3
#: Longest part (terms of D or N) whose brackets are summed exactly.
EXACT_TERMS = 64
#: The low part of pi: ``pi = np.pi + _PI_LOW`` to 2**-106.
_PI_LOW = 1.2246467991473532e-16
#: Veltkamp's constant, 2**27 + 1: splits a double into two halves of 26 bits.
_SPLIT = 134217729.0


@dataclasses.dataclass(frozen=True)
class ExactPolynomial:
    """One real polynomial ``z**shift D(z) + N(z)`` with exact rational coefficients.

    What an arc source needs where rounding the coefficients to doubles
    would cost the arc its digits: a plant zero or pole next to ``z = 1``
    or ``z = -1`` makes the brackets cancel there, and the coefficients'
    rounding (1e-16 of them) is then 1e-9 of the arc (a loop's plant at
    30 digits, :meth:`symstab.Loop.arc`).

    Attributes
    ----------
    delayed, direct : tuple of fractions.Fraction
        The coefficients of ``D`` and ``N``, highest power first.
    shift : int
        The power of ``z`` on the delayed part.
    """

    delayed: tuple
    direct: tuple
    shift: int


def _exact(x):
    """``x`` as a Fraction, exactly (a double is its binary value)."""
    return x if isinstance(x, fractions.Fraction) else fractions.Fraction(float(x))


def _parts(polynomial):
    """``(D, N, shift)`` of one real polynomial ``z**shift D(z) + N(z)`` (rows highest first).

    ``polynomial`` is a :class:`DelayedPolynomial` of one row or a 1-D row of
    dense coefficients (taken as ``N``, ``shift = 0``).
    """
    if isinstance(polynomial, ExactPolynomial):
        rows = [np.array([_exact(c) for c in part], dtype=object)
                for part in (polynomial.delayed, polynomial.direct)]
        if not all(len(r) for r in rows):
            raise ValueError("delayed and direct must have at least one coefficient each")
        return rows[0], rows[1], int(polynomial.shift)
    if isinstance(polynomial, DelayedPolynomial):
        if len(polynomial) != 1:
            raise ValueError(f"an arc source takes one polynomial per part, got {len(polynomial)}")
        flat = polynomial.flat()
        delayed, direct, shift = flat.delayed[0], flat.direct[0], polynomial.shift
    else:
        direct = np.asarray(polynomial, dtype=float)
        if direct.ndim != 1 or direct.size == 0:
            raise ValueError("dense coefficients of an arc source must be one non-empty row, "
                             f"got shape {direct.shape}")
        delayed, shift = np.zeros(1), 0
    for part in (delayed, direct):
        if not np.all(np.isfinite(part)):
            raise ValueError("the coefficients of an arc source must be finite")
    return np.asarray(delayed, dtype=float), np.asarray(direct, dtype=float), int(shift)


def _split_dense(rows):
    """Dense rows as :class:`DelayedPolynomial` with a common shift at their longest run of zeros.

    A loop's dense ``chi = z**d D + N`` has zeros between the two parts; split
    there, the brackets' end forms stay short whatever the delay.
    """
    rows = [np.asarray(r, dtype=float) for r in rows]
    for r in rows:
        if r.ndim != 1 or r.size == 0:
            raise ValueError("dense coefficients of an arc source must be one non-empty row, "
                             f"got shape {r.shape}")
    n = max(len(r) for r in rows)
    rows = [np.concatenate([np.zeros(n - len(r)), r]) for r in rows]
    powers = np.flatnonzero(np.any(np.stack(rows) != 0, axis=0)[::-1])    # ascending powers
    shift = top = 0
    if len(powers) > 1:
        gaps = np.diff(powers)
        k = int(np.argmax(gaps))
        if gaps[k] > 1:
            shift, top = int(powers[k + 1]), int(powers[k])
    if shift == 0:
        return [DelayedPolynomial(np.zeros(1), r, 0) for r in rows]
    return [DelayedPolynomial(r[:n - shift], r[n - 1 - top:], shift) for r in rows]


def _terms(parts):
    """``(powers, coefficients)`` of the nonzero terms of ``z**shift D + N``."""
    delayed, direct, shift = parts
    powers = np.concatenate([shift + np.arange(len(delayed) - 1, -1, -1),
                             np.arange(len(direct) - 1, -1, -1)])
    coefficients = np.concatenate([delayed, direct])
    keep = np.array([c != 0 for c in coefficients], dtype=bool)
    return powers[keep].astype(np.int64), coefficients[keep]


def _integers(rows):
    """Rows of exact values (doubles or Fractions) as integers over one denominator.

    Returns ``(rows, denominator)``: Python integers ``round(value *
    denominator)``, exactly (the denominator is the least common multiple
    of the values' own), so sums of their products are exact without the
    reductions a Fraction makes at each step.
    """
    ratios = [[x.as_integer_ratio() for x in row] for row in rows]
    denominator = math.lcm(*(d for row in ratios for _, d in row))
    return [[n * (denominator // d) for n, d in row] for row in ratios], denominator


def _laurent(a, b):
    """``A(z) B(1/z)`` exactly, for integer rows ``a``, ``b`` (highest first): ``{power: int}``."""
    out = {}
    pa, pb = len(a) - 1, len(b) - 1
    b = [(j, y) for j, y in enumerate(b) if y != 0]
    for i, x in enumerate(a):
        if x == 0:
            continue
        for j, y in b:
            k = (pa - i) - (pb - j)
            out[k] = out.get(k, 0) + x * y
    return out


def _add(a, b, sign=1):
    out = dict(a)
    for k, v in b.items():
        out[k] = out.get(k, 0) + sign * v
    return out


@functools.lru_cache(maxsize=None)
def _chebyshev_in_u(k):
    """Integer coefficients (lowest first) in ``u`` of ``T_k(1 - 2u)`` and ``U_{k-1}(1 - 2u)``."""
    def times_x(p):                        # (1 - 2u) p
        out = list(p) + [0]
        for i, c in enumerate(p):
            out[i + 1] -= 2 * c
        return out

    def step(a, b):                        # 2 (1 - 2u) a - b
        out = [2 * c for c in times_x(a)]
        for i, c in enumerate(b):
            out[i] -= c
        return out

    t, u = [[1], times_x([1])], [[0], [1]]
    for _ in range(2, k + 1):
        t.append(step(t[-1], t[-2]))
        u.append(step(u[-1], u[-2]))
    return tuple(t[k]), tuple(u[k])


def _end_series(laurent, mirror, denominator):
    """``Re L`` and ``Im L / sin(theta)`` of a Laurent polynomial as polynomials in ``u`` (lowest first).

    ``u = sin(theta / 2)**2`` (``cos theta = 1 - 2u``), or with ``mirror``
    ``u = cos(theta / 2)**2`` (``cos theta = 2u - 1``), where the
    coefficients carry ``(-1)**k``.  ``laurent``'s values are integers
    over ``denominator``: exact, rounded once (an integer quotient is
    correctly rounded).
    """
    top = max([abs(k) for k in laurent] + [0])
    real = [0] * (top + 1)
    imag = [0] * (top + 1)
    for k in range(0, top + 1):
        plus, minus = laurent.get(k, 0), laurent.get(-k, 0)
        t, u = _chebyshev_in_u(k) if k else ([1], [])
        flip = (-1) ** k if mirror else 1
        cos_k = (plus + minus) if k else plus
        for i, c in enumerate(t):
            real[i] += flip * c * cos_k
        if k:
            sin_k = plus - minus
            for i, c in enumerate(u):
                imag[i] += -flip * c * sin_k if mirror else c * sin_k
    return (np.array([c / denominator for c in real], dtype=float),
            np.array([c / denominator for c in imag], dtype=float))


def _two_product(a, b):
    """``a * b = p + e`` exactly (Dekker, no FMA): ``(p, e)``."""
    p = a * b
    with np.errstate(over="ignore", invalid="ignore"):
        ca, cb = _SPLIT * a, _SPLIT * b
        a_hi = ca - (ca - a)
        b_hi = cb - (cb - b)
        a_lo, b_lo = a - a_hi, b - b_hi
        e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
    return p, np.where(np.isfinite(e), e, 0.0)


def _bracket(first, second):
    """The sine series of ``Im(P conj Q)``: frequencies ``m > 0`` and exact coefficients ``e_m``.

    ``Im(P conj Q) = sum_m e_m sin(m theta)`` with ``e_m`` the sum of
    ``p_j q_k`` over ``j - k = m`` less the sum over ``j - k = -m``; each
    ``e_m`` is that sum of exact products rounded once (``math.fsum``).
    """
    (pj, p), (qk, q) = first, second
    if p.dtype == object or q.dtype == object:
        # Exact coefficients: the sums in integers over one denominator, rounded once.
        (p, q), scale = _integers([[_exact(a) for a in p], [_exact(b) for b in q]])
        sums = {}
        for j, a in zip(pj.tolist(), p, strict=True):
            for k, b in zip(qk.tolist(), q, strict=True):
                if j != k:
                    term = a * b
                    sums[abs(j - k)] = sums.get(abs(j - k), 0) + (term if j > k else -term)
        frequencies = sorted(m for m, e in sums.items() if e != 0)
        return (np.array(frequencies, dtype=float),
                np.array([sums[m] / (scale * scale) for m in frequencies], dtype=float))
    m = np.subtract.outer(pj, qk).ravel()
    hi, lo = _two_product(np.multiply.outer(p, np.ones_like(q)).ravel(),
                          np.multiply.outer(np.ones_like(p), q).ravel())
    sign = np.sign(m)
    m = np.abs(m)
    keep = m > 0
    m, sign, hi, lo = m[keep], sign[keep], hi[keep], lo[keep]
    order = np.argsort(m, kind="stable")
    m, sign, hi, lo = m[order], sign[order], hi[order], lo[order]
    frequencies, start = np.unique(m, return_index=True)
    stop = np.append(start[1:], len(m))
    terms = np.concatenate([(sign * hi)[:, None], (sign * lo)[:, None]], axis=1)
    # strict=False: with no term of nonzero frequency (m empty), stop is [0] beside no start.
    e = np.array([math.fsum(terms[a:b].ravel()) for a, b in zip(start, stop, strict=False)],
                 dtype=float)
    keep = e != 0
    return frequencies[keep].astype(float), e[keep]


def _multiple(m, theta, cosine=True):
    """``sin(m theta) / sin(theta)`` and ``cos(m theta)``, accurate at both ends of (0, pi).

    ``m theta`` is carried exactly by the generated helpers
    (:func:`symstab._generated.kernels.sin_multiple`, ``cos_multiple``), so
    ``sin(m theta)`` keeps its relative accuracy next to ``pi`` as
    ``sin(theta)`` does; at ``theta = 0`` the ratio is its limit ``m``.
    Without ``cosine``, the ratio alone (the cosine is None).
    """
    m = np.asarray(m, dtype=float)
    theta = np.asarray(theta, dtype=float)
    other = None
    if cosine:
        # The generated helpers' two sums of one exact product (Dekker's, as
        # they make it) and of one sine and cosine of it.
        hi, lo = _two_product(m, theta)
        sin_hi, cos_hi = np.sin(hi), np.cos(hi)
        numerator, other = sin_hi + lo * cos_hi, cos_hi - lo * sin_hi
    else:
        numerator = kernels.sin_multiple(m, theta)
    denominator = np.sin(theta)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(denominator == 0, m, numerator / denominator)
    return ratio, other


def sine_ratio(m, theta):
    """``sin(m theta) / sin(theta)`` (``U_{m-1}(cos theta)``), accurate at both ends of (0, pi).

    ``m theta`` is carried to the last bit, so the ratio keeps its relative
    accuracy as ``theta -> 0`` or ``pi`` (the
    limits ``m`` and ``(-1)**(m+1) m``), where the quotient of two rounded
    sines would not.

    Parameters
    ----------
    m : array_like
        Positive integers (as floats or ints).
    theta : array_like
        Angles in [0, pi]; broadcast against ``m``.

    Returns
    -------
    ndarray

    Examples
    --------
    >>> float(sine_ratio(3, 1e-9))
    3.0
    >>> float(sine_ratio(2, np.pi - 1e-9))
    -2.0
    >>> float(sine_ratio(5, 0.0))                # the limit
    5.0
    """
    return _multiple(m, theta, cosine=False)[0]


class ArcSource:
    """The interface of an arc source: ``source(theta) -> (x, y, det)``.

    ``x`` and ``y`` are the point of the plane at which ``exp(j theta)`` is
    a root (NaN where the arc is at infinity), ``det`` the determinant of
    the 2 x 2 system with ``sin(theta)`` divided out: its sign tells the
    branches apart where the arc runs off to infinity and back.
    """

    def __call__(self, theta):
        raise NotImplementedError


class Brackets:
    """Brackets ``[P, Q] / sin(theta)`` of real polynomials, accurate at both ends of (0, pi).

    ``[P, Q] = Im(P(z) conj Q(z))`` at ``z = exp(j theta)`` carries a factor
    ``sin(theta)``; here it is divided out analytically (see the module
    notes and :class:`CramerArc`): the sine series ``sum_m e_m sin(m theta)
    / sin(theta)`` with exact ``e_m`` in the middle, and next to ``0`` and
    ``pi`` polynomials in ``u = sin(theta/2)**2`` (``cos(theta/2)**2``)
    with exactly computed coefficients.  The one evaluator of brackets:
    :class:`CramerArc` solves its 2 x 2 system with three of them, the line
    engine (:mod:`symstab.numeric.engine.intervals`) finds the crossings of a line
    from one.

    Parameters
    ----------
    polynomials : sequence of DelayedPolynomial, ExactPolynomial or ndarray
        One polynomial each, real and finite: :class:`DelayedPolynomial`
        rows of one polynomial or :class:`ExactPolynomial` (exact
        coefficients: each bracket's coefficients summed in rational
        arithmetic, rounded once), with a common shift; or 1-D dense
        coefficient rows (highest power first; split at their longest run
        of zeros).
    pairs : sequence of (int, int)
        The brackets ``[polynomials[i], polynomials[j]]`` wanted.

    Examples
    --------
    >>> b = Brackets([np.array([1.0, 0.0]), np.array([0.0, 1.0])], [(0, 1)])   # [z, 1]
    >>> value, scale = b(np.array([1e-9]))
    >>> float(value[0, 0])                 # Im(z) / sin(theta)
    1.0
    """

    def __init__(self, polynomials, pairs):
        polynomials = list(polynomials)
        if not all(isinstance(p, (DelayedPolynomial, ExactPolynomial)) for p in polynomials):
            polynomials = _split_dense([p.dense().reshape(-1) if isinstance(p, DelayedPolynomial)
                                        else p for p in polynomials])
        parts = [_parts(p) for p in polynomials]
        shifts = {p[2] for p in parts}
        if len(shifts) != 1:
            raise ValueError(f"the polynomials of a bracket must have a common shift, got "
                             f"{sorted(shifts)}")
        self.shift = shifts.pop()
        self.pairs = tuple((int(i), int(j)) for i, j in pairs)
        terms = [_terms(p) for p in parts]
        series = [_bracket(terms[i], terms[j]) for i, j in self.pairs]
        # One table of sin(m theta) / sin(theta) for the frequencies of all brackets.
        self._frequencies = np.unique(np.concatenate([m for m, _ in series]))
        self._coefficients = np.zeros((len(series), len(self._frequencies)))
        for row, (m, e) in zip(self._coefficients, series, strict=True):
            row[np.searchsorted(self._frequencies, m)] = e
        longest = max(max(len(p[0]), len(p[1])) for p in parts)
        self._ends = None
        if longest <= EXACT_TERMS:
            # (bracket, form, power of u) at theta = 0 and at pi, lowest power first.
            forms = [self._end_forms(parts[i], parts[j]) for i, j in self.pairs]
            size = max(len(f) for bracket in forms for end in bracket for f in end)
            self._ends = np.zeros((2, len(series), 3, size))
            for b, bracket in enumerate(forms):
                for end, three in enumerate(bracket):
                    for f, c in enumerate(three):
                        self._ends[end, b, f, :len(c)] = c
            # Per end, a row per power of u: the forms' coefficients, then their
            # moduli (one Horner's scheme evaluates both).
            flat = self._ends.reshape(2, 3 * len(series), size)
            self._horner = np.stack([np.concatenate([f, np.abs(f)]).T for f in flat])

    @property
    def frequencies(self):
        """How many frequencies the sine series have together: the cost of one angle."""
        return len(self._frequencies)

    def _end_forms(self, p, q):
        """The three polynomials in ``u`` of a bracket, at theta = 0 and at pi."""
        (dp, np_, s), (dq, nq, _) = p, q
        # The products summed exactly, as integers over one denominator.
        if s == 0:
            (p_, q_), scale = _integers([np.polyadd(dp, np_), np.polyadd(dq, nq)])
            l0, c = _laurent(p_, q_), {}
        else:
            (dp, np_, dq, nq), scale = _integers([dp, np_, dq, nq])
            l0 = _add(_laurent(dp, dq), _laurent(np_, nq))
            c = _add(_laurent(dp, nq), _laurent(dq, np_), -1)
        out = []
        for mirror in (False, True):
            g = _end_series(l0, mirror, scale * scale)[1]
            cr, ci = _end_series(c, mirror, scale * scale)
            out.append((g, cr, ci))
        return tuple(out)

    def _middle(self, theta):
        """The brackets by their sine series, and their rounding scales: both (M, k)."""
        k = len(self.pairs)
        if self._frequencies.size == 0:
            return np.zeros((len(theta), k)), np.zeros((len(theta), k))
        ratio = sine_ratio(self._frequencies[None, :], theta[:, None])
        # Sums over the frequencies as elementwise products (see _at_end).
        value = np.stack([np.sum(ratio * e, axis=1) for e in self._coefficients], axis=1)
        size = np.abs(ratio)
        scale = np.stack([np.sum(size * np.abs(e), axis=1) for e in self._coefficients], axis=1)
        return value, scale

    def _at_end(self, theta, mirror):
        """The brackets by their polynomials in u, and their rounding scales: both (M, k).

        ``mirror`` (one per angle) says which end's polynomials: at ``pi``
        rather than at 0.  Both ends are evaluated in one pass, each angle
        with its own end's coefficients.
        """
        k = len(self.pairs)
        half = 0.5 * np.where(mirror, (np.pi - theta) + _PI_LOW, theta)
        u = np.sin(half) ** 2
        # Horner's scheme on an (M, 6 k) array, the values and their scales
        # side by side: a matrix product this skinny costs more in BLAS's
        # threads than it computes.
        if mirror.all() or not mirror.any():
            rows = self._horner[int(mirror[0])]
        else:
            rows = self._horner[mirror.astype(np.intp)].transpose(1, 0, 2)
        both = np.zeros((len(u), rows.shape[-1]))
        column = u[:, None]
        for row in rows[::-1]:
            both *= column
            both += row
        value, scale = both[:, :3 * k], both[:, 3 * k:]
        if self.shift:
            ratio, cosine = _multiple(self.shift, theta)
        else:
            ratio = cosine = np.zeros(theta.shape)
        # The three forms' sum as np.sum along a row of three adds it (from 0.0,
        # left to right: the same bits), a few times faster as columns.
        value, scale = value.reshape(-1, k, 3), scale.reshape(-1, k, 3)
        ratio, cosine = ratio[:, None], cosine[:, None]
        return ((0.0 + value[:, :, 0]) + value[:, :, 1] * ratio + value[:, :, 2] * cosine,
                (0.0 + scale[:, :, 0]) + scale[:, :, 1] * np.abs(ratio)
                + scale[:, :, 2] * np.abs(cosine))

    def __call__(self, theta):
        """The brackets over sin(theta) and their rounding scales at angles in (0, pi): (M, k) each.

        The scale is the sum of the moduli of the terms summed, the size of
        a bracket's rounding error in units of the precision.
        """
        theta = np.asarray(theta, dtype=float).ravel()
        k = len(self.pairs)
        value, scale = np.empty((len(theta), k)), np.empty((len(theta), k))
        chunk = max(1, 2**20 // max(1, len(self._frequencies)))
        for start in range(0, len(theta), chunk):
            part = slice(start, start + chunk)
            t = theta[part]
            if self._ends is None:
                value[part], scale[part] = self._middle(t)
                continue
            v, c = np.empty((len(t), k)), np.empty((len(t), k))
            high = t > np.pi - END_ANGLE
            end = (t < END_ANGLE) | high
            if end.any():
                v[end], c[end] = self._at_end(t[end], high[end])
            if not end.all():
                v[~end], c[~end] = self._middle(t[~end])
            value[part], scale[part] = v, c
        return value, scale


class CramerArc(ArcSource):
    """The arc of ``A0 + x Ax + y Ay`` by Cramer's rule with sin(theta) divided out analytically.

    Parameters
    ----------
    base, ax, ay : DelayedPolynomial, ExactPolynomial or ndarray
        One polynomial each: :class:`DelayedPolynomial` rows of one
        polynomial or :class:`ExactPolynomial`, with a common shift (the
        structured basis of a loop's plane), or 1-D dense coefficient rows
        (highest power first).  Real and finite.

    Notes
    -----
    Each bracket ``[P, Q] = Im(P conj Q)`` of ``P = z**s D_P + N_P`` is
    ``Im L0 + Im(z**s C)`` with the short Laurent polynomials ``L0 = D_P
    D_Q(1/z) + N_P N_Q(1/z)`` and ``C = D_P N_Q(1/z) - D_Q N_P(1/z)``, their
    coefficients exact (rational arithmetic on the given doubles, once).
    Next to ``theta = 0`` (below :data:`END_ANGLE`) the bracket over
    ``sin(theta)`` is ``G(u) + sin(s theta) / sin(theta) Re C(u) + cos(s
    theta) (Im C / sin theta)(u)``, each a polynomial in ``u =
    sin(theta/2)**2`` with exactly computed coefficients rounded once
    (``T_k`` and ``U_{k-1}`` of ``cos theta = 1 - 2u``): the cancellation of
    the monomial coefficients next to ``z = 1`` (a pole of the plant there,
    say) is done exactly, not in rounding.  Next to ``pi`` the same in ``u
    = cos(theta/2)**2``; in between the sine series ``sum_m e_m sin(m
    theta) / sin(theta)`` with exact ``e_m``.  Each angle costs
    O(frequencies), ``O(deg D + deg N)`` for a structured basis (a dense
    row is one part: O(degree)).  Parts longer than
    :data:`EXACT_TERMS` skip the end forms (the sine series everywhere,
    accurate near the ends only where the coefficients do not cancel).

    Where the determinant is at most :data:`SINGULAR` of its rounding scale
    (the sum of the moduli of its terms) the branch is at infinity (or
    undetermined): ``x`` and ``y`` are NaN there, as they were for the
    plain Cramer solve on the values.

    Examples
    --------
    >>> arc = CramerArc(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]),
    ...                 np.array([0.0, 0.0, 1.0]))        # z**2 + x z + y
    >>> x, y, det = arc(np.array([np.pi / 2]))
    >>> round(float(x[0]), 12), float(y[0])
    (-0.0, 1.0)
    """

    def __init__(self, base, ax, ay):
        # x = [A0, Ay] / [Ay, Ax], y = [Ax, A0] / [Ay, Ax].
        self._brackets = Brackets((base, ax, ay), ((0, 2), (1, 0), (2, 1)))
        self.shift = self._brackets.shift

    def __call__(self, theta):
        """``(x, y, det)`` at angles ``theta`` in (0, pi), each of ``theta``'s shape.

        ``det`` is ``Im(Ay conj Ax) / sin(theta)``; ``x``, ``y`` are NaN where
        it is singular (see the class notes).
        """
        theta = np.asarray(theta, dtype=float)
        shape = theta.shape
        value, scale = self._brackets(theta.ravel())
        nx, ny, dv = value[:, 0], value[:, 1], value[:, 2]
        with np.errstate(all="ignore"):
            singular = ~(np.abs(dv) > SINGULAR * scale[:, 2])
            xs = np.where(singular, np.nan, nx / dv)
            ys = np.where(singular, np.nan, ny / dv)
        return xs.reshape(shape), ys.reshape(shape), dv.reshape(shape)


class ClosedFormArc(ArcSource):
    """An arc in closed form, with the determinant's sign from a Cramer solve.

    Parameters
    ----------
    points : callable
        ``theta -> (x, y)``: the closed form (SymPy's, sin(theta) divided
        out symbolically), for angles in (0, pi).
    determinant : ArcSource
        The source whose determinant (its sign marks the branches through
        infinity) goes with the points: the :class:`CramerArc` of the same
        plane.

    Examples
    --------
    >>> cramer = CramerArc(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]),
    ...                    np.array([0.0, 0.0, 1.0]))            # z**2 + x z + y
    >>> arc = ClosedFormArc(lambda t: (-2 * np.cos(t), np.ones_like(t)), cramer)
    >>> x, y, det = arc(np.array([np.pi / 3]))
    >>> round(float(x[0]), 12), float(y[0])
    (-1.0, 1.0)
    """

    def __init__(self, points, determinant):
        if not callable(points) or not isinstance(determinant, ArcSource):
            raise TypeError("points must be callable and determinant an ArcSource")
        self._points, self._determinant = points, determinant

    def __call__(self, theta):
        """``(x, y, det)`` at angles ``theta`` in (0, pi)."""
        theta = np.asarray(theta, dtype=float)
        x, y = self._points(theta)
        det = self._determinant(theta)[2]
        x = np.broadcast_to(np.asarray(x, dtype=float), theta.shape).copy()
        y = np.broadcast_to(np.asarray(y, dtype=float), theta.shape).copy()
        return x, y, det


class RememberedArc(ArcSource):
    """An arc source that answers a batch of angles asked for again from memory.

    The decompositions of one plane in several windows
    (:func:`symstab.numeric.loop.plane.region`) each sample the arc first at
    the same grid of angles (:func:`symstab.numeric.engine.decomposition.sample_arc`):
    the grid is evaluated once.  A batch is remembered whole (looking up
    single angles costs more than the few a window's halvings share with
    another's).

    Parameters
    ----------
    source : ArcSource
        The arc.

    Examples
    --------
    >>> cramer = CramerArc(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]),
    ...                    np.array([0.0, 0.0, 1.0]))            # z**2 + x z + y
    >>> arc = RememberedArc(cramer)
    >>> first = arc(np.array([np.pi / 3, np.pi / 2]))
    >>> again = arc(np.array([np.pi / 3, np.pi / 2]))            # remembered
    >>> arc.evaluated
    1
    """

    def __init__(self, source):
        if not isinstance(source, ArcSource):
            raise TypeError(f"source must be an ArcSource, got {type(source).__name__}")
        self.source = source
        self._batches = {}

    @property
    def evaluated(self):
        """How many batches the source has evaluated."""
        return len(self._batches)

    def __call__(self, theta):
        """``(x, y, det)`` at angles ``theta``, each of ``theta``'s shape (new arrays)."""
        theta = np.asarray(theta, dtype=float)
        key = (theta.shape, theta.tobytes())
        if key not in self._batches:
            self._batches[key] = tuple(np.array(v, dtype=float) for v in self.source(theta))
        return tuple(v.copy() for v in self._batches[key])


def _part_slope(c, z):
    """``P(z)`` and ``z P'(z)`` for rows ``c`` (highest first) at points ``z`` (one per row)."""
    value = np.zeros(z.shape, dtype=complex)
    slope = np.zeros(z.shape, dtype=complex)
    for k in range(c.shape[-1]):
        slope = slope * z + value
        value = value * z + c[..., k]
    return value, slope * z


def _sizes(c, shift):
    """``sum_k |c_k| (shift + k)`` and ``sum_k |c_k|`` of rows ``c`` (highest first)."""
    powers = shift + np.arange(c.shape[-1] - 1, -1, -1, dtype=float)
    return np.sum(np.abs(c) * powers, axis=-1), np.sum(np.abs(c), axis=-1)


def crossing_change(chi, slope, theta):
    """How the number of roots outside the unit circle changes through crossings.

    The one crossing-direction rule.  At a crossing the polynomial ``chi``
    (of a family ``chi(s)``) has the root ``z = exp(j theta)``; as the
    parameter ``s`` increases the root moves with ``dz/ds = -chi_s(z) /
    chi'(z)`` and leaves the circle where ``Re(conj(z) dz/ds) > 0``, that
    is where ``-Re(chi_s(z) conj(z chi'(z))) > 0``: a complex pair (``0 <
    theta < pi``) adds 2 roots outside, a real root (``theta = 0, pi``) 1.
    The powers of ``z`` come from the angle (``z**shift = exp(j shift
    theta)``), not from a rounded ``z``.

    Parameters
    ----------
    chi : DelayedPolynomial
        One polynomial per crossing (shape ``(N,)``), at the crossing's
        parameter value.
    slope : DelayedPolynomial
        ``d chi / ds``, the same shift and part lengths; its rows broadcast
        against ``chi``'s.
    theta : array_like, shape (N,)
        The crossings' angles in [0, pi].

    Returns
    -------
    ndarray
        ``+-2`` (a pair), ``+-1`` (``z = +-1``), NaN where the radial
        velocity is within its rounding (``2e-15 (1 + degree theta)`` times
        the sizes of ``z chi'`` and ``chi_s``: the phases ``k theta`` carry
        an absolute error of ``k theta`` ulps): a tangency, a corner or a
        multiple root, undecided.
    """
    theta = np.asarray(theta, dtype=float).ravel()
    rows = chi.flat()
    moving = DelayedPolynomial(slope.delayed, slope.direct, slope.shift)
    shape = (len(theta),)
    if moving.shape != shape:
        moving = DelayedPolynomial(np.broadcast_to(moving.delayed, shape + moving.delayed.shape[-1:]),
                                   np.broadcast_to(moving.direct, shape + moving.direct.shape[-1:]),
                                   moving.shift)
    if rows.shape != shape or moving.shift != rows.shift:
        raise ValueError(f"chi must have one polynomial per angle ({len(theta)}) and slope "
                         f"chi's shift, got {rows.shape} and shift {moving.shift} vs {rows.shift}")
    s = rows.shift
    z = np.exp(1j * theta)
    power = np.exp(1j * s * theta)
    d_value, d_slope = _part_slope(rows.delayed, z)
    n_value, n_slope = _part_slope(rows.direct, z)
    z_chi_slope = power * (s * d_value + d_slope) + n_slope
    m_d, _ = _part_slope(moving.delayed, z)
    m_n, _ = _part_slope(moving.direct, z)
    partial = power * m_d + m_n
    radial = -np.real(partial * np.conj(z_chi_slope))
    chi_size = _sizes(rows.delayed, s)[0] + _sizes(rows.direct, 0)[0]
    moving_size = _sizes(moving.delayed, s)[1] + _sizes(moving.direct, 0)[1]
    noise = 2e-15 * (1.0 + rows.degree * theta) * chi_size * moving_size
    multiplicity = np.where((theta > 0) & (theta < np.pi), 2.0, 1.0)
    with np.errstate(invalid="ignore"):
        clear = np.isfinite(radial) & (np.abs(radial) > noise)
    return np.where(clear, multiplicity * np.sign(radial), np.nan)
