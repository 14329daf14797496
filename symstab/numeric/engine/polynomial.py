"""The characteristic polynomial of a delayed loop, kept in its structure.

Every loop symstab handles closes through a delay of ``d`` samples, so its
characteristic polynomial is a short *delayed part* ``D(z)`` shifted by a
power of ``z`` plus a short *direct part* ``N(z)``::

    chi(z) = z**shift D(z) + N(z),

with ``shift = d`` for a :class:`symstab.Loop` (``D = Ve_d P_d``, ``N = Ve_n
P_n``) and ``shift = d + 2`` for the paper's kernel (``D = (z - 1)(z -
exp(-delta))``, ``N`` the cubic ``V(z)(b1 z + b0)``).  Its degree grows with
the delay but ``D`` and ``N`` do not, so :class:`DelayedPolynomial` keeps the
two parts and never expands ``chi`` on a hot path: a value on the circle
costs O(deg D + deg N), not O(d).  The dense coefficients (:meth:`dense`)
are for short delays and for oracles.

Rows: ``delayed`` has shape ``(..., p + 1)`` and ``direct`` ``(..., q + 1)``
(highest power first, leading shapes broadcast), one polynomial per leading
index, all with the same ``shift``.
"""

import numpy as np

from ..._resources import check_memory

__all__ = ["DelayedPolynomial", "horner"]


def horner(c, z):
    """``p(z)`` and ``p'(z)`` for rows of coefficients ``c`` (highest first).

    ``c`` has shape ``(N, n + 1)`` and ``z`` shape ``(N, M)`` (or anything
    that broadcasts against ``c[:, k, None]``).
    """
    value = np.zeros(np.broadcast(c[:, :1], z).shape, dtype=np.result_type(c, z))
    slope = np.zeros_like(value)
    for k in range(c.shape[1]):
        slope = slope * z + value
        value = value * z + c[:, k, None]
    return value, slope


class DelayedPolynomial:
    """Real polynomials ``chi(z) = z**shift D(z) + N(z)``, one per row.

    Parameters
    ----------
    delayed : array_like, shape (..., p + 1)
        Coefficients of ``D`` (highest power first).
    direct : array_like, shape (..., q + 1)
        Coefficients of ``N`` (highest power first); the leading shapes of
        both broadcast.
    shift : int
        The power of ``z`` on the delayed part, ``>= 0``.
    near_one : (array_like, array_like), optional
        The delayed part again in powers of ``w = z - 1`` (highest first,
        the same length as ``delayed``) and an absolute error bound of each
        of those coefficients.  Where ``D`` has a root near ``z = 1`` (a
        plant pole ``exp(p T)`` with ``p T`` small) its coefficients in
        ``z`` cancel there; in ``w`` they do not, and the root count keeps
        its digits: the paper's ``(z - 1)(z - exp(-delta))`` is ``w**2 +
        (1 - exp(-delta)) w``.

    Examples
    --------
    >>> chi = DelayedPolynomial([1.0, -0.5], [0.25], shift=3)   # z**4 - z**3/2 + 1/4
    >>> chi.dense().tolist()
    [1.0, -0.5, 0.0, 0.0, 0.25]
    >>> chi.degree
    4
    """

    __slots__ = ("delayed", "direct", "shift", "near_one")

    def __init__(self, delayed, direct, shift, near_one=None):
        delayed = np.asarray(delayed, dtype=float)
        direct = np.asarray(direct, dtype=float)
        if delayed.ndim < 1 or direct.ndim < 1 or not delayed.shape[-1] or not direct.shape[-1]:
            raise ValueError("delayed and direct must have at least one coefficient each")
        if isinstance(shift, (bool, np.bool_)) or not isinstance(shift, (int, np.integer)) or shift < 0:
            raise ValueError(f"shift must be a non-negative integer, got {shift!r}")
        try:
            shape = np.broadcast_shapes(delayed.shape[:-1], direct.shape[:-1])
        except ValueError as exc:
            raise ValueError(f"delayed and direct rows must broadcast together: {exc}") from None
        self.delayed = np.broadcast_to(delayed, shape + delayed.shape[-1:])
        self.direct = np.broadcast_to(direct, shape + direct.shape[-1:])
        self.shift = int(shift)
        if near_one is not None:
            shifted, error = (np.asarray(x, dtype=float) for x in near_one)
            if shifted.shape[-1] != delayed.shape[-1] or error.shape[-1] != delayed.shape[-1]:
                raise ValueError("near_one must have as many coefficients as delayed")
            near_one = (np.broadcast_to(shifted, self.delayed.shape),
                        np.broadcast_to(error, self.delayed.shape))
        self.near_one = near_one

    def _with(self, delayed, direct, near_one):
        return DelayedPolynomial(delayed, direct, self.shift, near_one)

    @classmethod
    def from_dense(cls, coefficients):
        """The polynomials of dense coefficient rows (``shift = 0``, no direct part)."""
        coefficients = np.asarray(coefficients, dtype=float)
        return cls(coefficients, np.zeros(coefficients.shape[:-1] + (1,)), 0)

    def __repr__(self):
        return (f"DelayedPolynomial(shape={self.shape}, shift={self.shift}, "
                f"delayed degree {self.delayed.shape[-1] - 1}, direct degree "
                f"{self.direct.shape[-1] - 1})")

    @property
    def shape(self):
        """The leading shape: one polynomial per index."""
        return self.delayed.shape[:-1]

    @property
    def degree(self):
        """The nominal degree ``max(shift + p, q)`` (the leading coefficient may vanish)."""
        return max(self.shift + self.delayed.shape[-1] - 1, self.direct.shape[-1] - 1)

    def __len__(self):
        return int(np.prod(self.shape))

    def flat(self):
        """The same polynomials as one row per polynomial (shape ``(N,)``)."""
        def rows(x):
            return x.reshape(-1, x.shape[-1])

        near = None if self.near_one is None else tuple(rows(x) for x in self.near_one)
        return self._with(rows(self.delayed), rows(self.direct), near)

    def take(self, index):
        """The rows ``index`` (an index into the first axis)."""
        near = None if self.near_one is None else tuple(x[index] for x in self.near_one)
        return self._with(self.delayed[index], self.direct[index], near)

    def combine(self, weights, others):
        """``self + sum(w * other)``: a point of an affine family, row by row.

        ``weights`` are arrays broadcasting against :attr:`shape`; every
        ``other`` has the same ``shift`` and part lengths.  The parts in
        powers of ``z - 1`` are combined where every term has them (their
        error bounds grow by the rounding of the sum).
        """
        delayed = np.array(self.delayed, dtype=float)
        direct = np.array(self.direct, dtype=float)
        near = self.near_one
        if near is not None:
            near = [np.array(near[0]), np.array(near[1])]
        for w, other in zip(weights, others, strict=True):
            if (other.shift != self.shift or other.delayed.shape[-1] != delayed.shape[-1]
                    or other.direct.shape[-1] != direct.shape[-1]):
                raise ValueError("an affine family needs parts of the same structure")
            w = np.asarray(w, dtype=float)[..., None]
            delayed = delayed + w * other.delayed
            direct = direct + w * other.direct
            if near is not None and other.near_one is not None:
                term = w * other.near_one[0]
                near[1] = near[1] + np.abs(w) * other.near_one[1] + 2 ** -52 * (
                    np.abs(near[0]) + np.abs(term))
                near[0] = near[0] + term
            else:
                near = None
        return self._with(delayed, direct, None if near is None else tuple(near))

    def dense(self):
        """Dense coefficients, highest power first: shape ``shape + (degree + 1,)``."""
        n = self.degree
        check_memory(f"the dense coefficients of {len(self)} polynomials of degree {n}",
                     8 * max(1, len(self)) * (n + 1))
        out = np.zeros(self.shape + (n + 1,))
        p, q = self.delayed.shape[-1], self.direct.shape[-1]
        top = n - (self.shift + p - 1)
        out[..., top:top + p] += self.delayed
        out[..., n + 1 - q:] += self.direct
        return out

    def leading(self):
        """The coefficient of ``z**degree``."""
        n = self.degree
        p, q = self.delayed.shape[-1], self.direct.shape[-1]
        out = np.zeros(self.shape)
        if self.shift + p - 1 == n:
            out = out + self.delayed[..., 0]
        if q - 1 == n:
            out = out + self.direct[..., 0]
        return out

    def __call__(self, z):
        """``chi(z)`` and ``chi'(z)`` at points ``z`` (shape ``shape + z.shape[-1:]``, rows flat).

        ``z**shift`` is taken as ``exp(shift log z)``, so a long delay costs
        no more than a short one; ``z = 0`` gives ``N(0)``.
        """
        rows = self.flat()
        z = np.asarray(z, dtype=complex)
        z = np.broadcast_to(z, (len(rows),) + z.shape[-1:]) if z.ndim else np.full((len(rows), 1), z)
        d_value, d_slope = horner(rows.delayed, z)
        n_value, n_slope = horner(rows.direct, z)
        s = self.shift
        with np.errstate(all="ignore"):
            power = np.where(z == 0, 0.0 if s else 1.0, np.exp(s * np.log(np.where(z == 0, 1, z))))
            below = np.where(z == 0, 0.0 if s > 1 else float(s == 1),
                             power / np.where(z == 0, 1, z))
        value = power * d_value + n_value
        slope = s * below * d_value + power * d_slope + n_slope
        return value, slope

    def on_radius(self, radius):
        """The polynomials ``chi(radius w)`` in ``w``, scaled so that they neither overflow nor underflow.

        A root of ``chi`` of modulus ``rho`` is a root of the result of
        modulus ``rho / radius``: the number of roots outside the circle
        ``|z| = radius`` is the number of roots of the result outside the
        unit circle.  ``radius`` (> 0) broadcasts against :attr:`shape`.
        """
        radius = np.asarray(radius, dtype=float)
        if np.any(~(radius > 0)) or np.any(~np.isfinite(radius)):
            raise ValueError("radius must be positive and finite")
        log_r = np.log(radius)[..., None]
        p, q = self.delayed.shape[-1], self.direct.shape[-1]
        s = self.shift
        # chi(r w) = r**s w**s D(r w) + N(r w); divide by r**max(s, 0 if r < 1) ...
        # i.e. by r**s when r > 1 (the direct part then shrinks) and by 1 when
        # r < 1 (the delayed part shrinks): the larger part keeps its size.
        k_d = np.arange(p - 1, -1, -1, dtype=float)
        k_n = np.arange(q - 1, -1, -1, dtype=float)
        shrink = np.minimum(log_r, 0.0) * s
        grow = np.maximum(log_r, 0.0) * s
        with np.errstate(under="ignore"):
            delayed = self.delayed * np.exp(k_d * log_r + shrink)
            direct = self.direct * np.exp(k_n * log_r - grow)
        return DelayedPolynomial(delayed, direct, s)   # the parts in z - 1 do not carry over
