"""Stability of the paper's loop in its dimensionless plane (Table I's variables).

A parameter point is stable when every root of the characteristic polynomial
chi(z) lies strictly inside the unit circle.  The functions here take arrays
of ``alpha, beta, gamma, delta`` (broadcast together) and one integer delay
``d``, build the loop's structured polynomial from the generated kernel
(:func:`paper_polynomial`: ``chi / (delta**2 Gamma) = z**(d+2) (z - 1)(z -
exp(-delta)) + B(z)``, in forms that keep their digits for small delta) and
hand it to the one root engine, :mod:`symstab.numeric.engine.roots`, that every
:class:`symstab.Loop` uses too; they have no algorithm of their own:

* :func:`loop_coefficients` -- the dense coefficients (short delays, oracles);
* :func:`spectral_radius` -- the largest root modulus;
* :func:`unstable_root_counts` -- the certified number of roots outside;
* :func:`classify` -- stable, unstable or marginal;
* :func:`is_stable` -- the same as a masked boolean array (masked where
  marginal), or ``True``/``False``/``None`` for a single point.
"""

import numpy as np

from ..._generated import kernels
from ..._resources import check_memory
from ..._validate import DELTA_MAX, PARAMETER_MAX, check_array, check_delay
from ..engine import roots
from ..engine.polynomial import DelayedPolynomial
from ..engine.roots import MARGINAL, STABLE, UNSTABLE, classify_polynomials, schur_cohn

__all__ = [
    "STABLE", "MARGINAL", "UNSTABLE",
    "loop_coefficients", "paper_polynomial", "spectral_radius", "schur_cohn",
    "unstable_root_counts", "classify", "is_stable", "classify_polynomials",
]


def _points(alpha, beta, gamma, d, delta):
    """Validate and broadcast; return (alpha, beta, gamma, delta, d, shape)."""
    bound = dict(low=-PARAMETER_MAX, high=PARAMETER_MAX)
    arrays = [check_array("alpha", alpha, **bound), check_array("beta", beta, **bound),
              check_array("gamma", gamma, **bound),
              check_array("delta", delta, low=0.0, high=DELTA_MAX)]
    d = check_delay(d)
    try:
        arrays = np.broadcast_arrays(*arrays)
    except ValueError as exc:
        raise ValueError(f"alpha, beta, gamma and delta must broadcast together: {exc}") from None
    return (*arrays, d, arrays[0].shape)


def _kernel_coefficients(alpha, beta, gamma, delta):
    """The seven distinct coefficients of chi / (delta**2 Gamma), as (N,) arrays.

    Finite for every input :func:`_points` accepts: |alpha|, |beta|,
    |gamma| <= PARAMETER_MAX and the ZOH functions of delta are at most 1.
    """
    c = kernels.loop_coefficients(alpha, beta, gamma, delta)
    shape = np.broadcast(alpha, beta, gamma, delta).shape
    return [np.broadcast_to(np.asarray(ck, dtype=float), shape).ravel() for ck in c]


def _polynomial(alpha, beta, gamma, delta, d, shape):
    """The structured chi of validated, broadcast points, one row per point."""
    c7 = _kernel_coefficients(alpha, beta, gamma, delta)
    # The delayed part (z - 1)(z - r) is w**2 + (1 - r) w in w = z - 1:
    # exact, with 1 - r = -expm1(-delta) to an ulp.
    em = np.broadcast_to(-np.expm1(-delta), shape).ravel()
    near_one = np.stack([np.ones_like(em), em, np.zeros_like(em)], axis=-1)
    return DelayedPolynomial(np.stack(c7[:3], axis=-1), np.stack(c7[3:], axis=-1), d + 2,
                             near_one=(near_one, np.zeros_like(near_one)))


def paper_polynomial(*, alpha, beta, gamma, d, delta):
    """The paper's ``chi(z) / (delta**2 exp(delta))`` as a structured polynomial.

    ``z**(d+2) D(z) + N(z)`` with ``D = (z - 1)(z - exp(-delta))`` (also
    kept in powers of ``z - 1``) and the cubic ``N = V(z)(b1 z + b0)``, from
    the generated kernel; the input of every function of
    :mod:`symstab.numeric.engine.roots`.  Parameters as in :func:`loop_coefficients`.

    Returns
    -------
    DelayedPolynomial
        Of the broadcast shape.

    Examples
    --------
    >>> chi = paper_polynomial(alpha=0.1, beta=0.5, gamma=0.0, d=3, delta=0.0025)
    >>> chi.degree, chi.shift
    (7, 5)
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    chi = _polynomial(alpha, beta, gamma, delta, d, shape)
    return DelayedPolynomial(chi.delayed.reshape(shape + (3,)), chi.direct.reshape(shape + (4,)),
                             chi.shift, near_one=tuple(x.reshape(shape + (3,)) for x in chi.near_one))


def loop_coefficients(*, alpha, beta, gamma, d, delta):
    """Coefficients of ``chi(z) / (delta**2 exp(delta))``, highest power first.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    ndarray
        Shape ``broadcast_shape + (d + 5,)``; the leading coefficient is 1.

    Raises
    ------
    TypeError, ValueError
        For non-real, non-finite or out-of-range parameters, or an array
        that would not fit in the memory limit.
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    check_memory(f"the coefficients of {int(np.prod(shape))} points at d = {d}",
                 8 * (d + 5) * int(np.prod(shape)))
    return _polynomial(alpha, beta, gamma, delta, d, shape).dense().reshape(shape + (d + 5,))


def spectral_radius(*, alpha, beta, gamma, d, delta):
    """Largest modulus of the closed-loop poles.

    :func:`symstab.numeric.engine.roots.spectral_radius` of the loop's polynomial:
    companion eigenvalues polished by Newton steps up to degree 128 (about
    1e-14 where the largest root is simple, but only about the square root
    of that, 1e-8, where two roots nearly coincide), certified counts on
    circles and Newton steps on the structured polynomial above (O(d) per
    step).  For a verdict use :func:`classify`, which is certified; this is
    the measure of how far a point is from the boundary.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    float or ndarray
        A float for scalar parameters, else an array of the broadcast shape.

    Examples
    --------
    >>> r = spectral_radius(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=0.0025)
    >>> bool(r < 1)
    True
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    r = roots.spectral_radius(_polynomial(alpha, beta, gamma, delta, d, shape)).reshape(shape)
    return float(r) if r.ndim == 0 else r


def unstable_root_counts(*, alpha, beta, gamma, d, delta):
    """Number of closed-loop poles outside the unit circle, certified.

    :func:`symstab.numeric.engine.roots.root_counts` of the loop's polynomial: the
    argument principle on the unit circle with bounds that make each arc's
    contribution certain, O(d) per point.  The count is exact for the
    polynomial whose coefficients are within 64 ulps of the generated
    kernel's (measured within a few ulps of the exact ones), the delayed
    part ``(z - 1)(z - exp(-delta))`` taken in powers of ``z - 1`` so that
    it keeps its digits next to ``z = 1``.

    Parameters are as in :func:`loop_coefficients`.

    Returns
    -------
    int or ndarray of int
        The number of roots with modulus > 1, or -1 where a root lies on
        the unit circle to within rounding (a marginal point).

    Examples
    --------
    >>> int(unstable_root_counts(alpha=3.0, beta=0.5, gamma=0.0, d=0, delta=0.0025))
    2
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    out = roots.root_counts(_polynomial(alpha, beta, gamma, delta, d, shape)).reshape(shape)
    return int(out) if out.ndim == 0 else out


def classify(*, alpha, beta, gamma, d, delta, refine=True):
    """Classify parameter points as stable, unstable or marginal.

    :func:`symstab.numeric.engine.roots.classify_polynomials` of the loop's
    polynomial: a fast floating-point Schur-Cohn test decides the points it
    decides with a margin of at least 1e-6 (below d = 48): that verdict
    carries no error bound; it agreed with 50- and 80-digit root counts on
    every point tried (the tests, and 44 800 points with margins from 1e-6
    to 1e-2 in a review).  Every other point, and every point from d = 48
    on, is decided by the certified root count of
    :func:`unstable_root_counts`.  :data:`MARGINAL` means that a root lies
    on the unit circle to within the rounding of the coefficients (a point
    on the boundary, to about 1e-13 relative): the verdict is then not
    certain either way.

    Parameters
    ----------
    alpha, beta, gamma, d, delta
        As in :func:`loop_coefficients`.
    refine : bool
        Re-decide the points the float test does not decide safely (the
        default).  With ``False`` the Schur-Cohn verdict is returned as it is
        (only a margin of exactly 0 is marginal): faster where a wrong
        verdict next to the boundary does no harm.

    Returns
    -------
    int or ndarray of int8
        :data:`STABLE` (1), :data:`MARGINAL` (0) or :data:`UNSTABLE` (-1).

    Raises
    ------
    TypeError, ValueError
        For non-real, non-finite or out-of-range parameters (``delta`` in
        [0, 1e6], ``|alpha|, |beta|, |gamma| <= 1e150``, ``d`` up to
        ``SYMSTAB_MAX_DELAY``).

    Examples
    --------
    >>> classify(alpha=0.1, beta=0.5, gamma=0.0, d=0, delta=0.0025) == STABLE
    True
    >>> classify(alpha=3.0, beta=0.5, gamma=0.0, d=0, delta=0.0025) == UNSTABLE
    True
    """
    alpha, beta, gamma, delta, d, shape = _points(alpha, beta, gamma, d, delta)
    codes = classify_polynomials(_polynomial(alpha, beta, gamma, delta, d, shape), refine=refine)
    return _shaped(codes, shape)


def _shaped(codes, shape):
    codes = codes.reshape(shape)
    return int(codes) if codes.ndim == 0 else codes


def is_stable(*, alpha, beta, gamma, d, delta):
    """Whether each point is stable; marginal points are undecided.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping and virtual mass (broadcast).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float or array_like
        ``b T / m``, from 0 (frictionless) to ``DELTA_MAX`` (1e6).

    Returns
    -------
    bool or None, or numpy.ma.MaskedArray of bool
        For a single point ``True``, ``False`` or ``None`` (marginal); for
        arrays a masked boolean array, masked where the point is marginal.

    Examples
    --------
    >>> is_stable(alpha=[0.1, 3.0], beta=0.5, gamma=0.0, d=0, delta=0.0025).tolist()
    [True, False]
    """
    code = np.asarray(classify(alpha=alpha, beta=beta, gamma=gamma, d=d, delta=delta))
    if code.ndim == 0:
        return None if code == MARGINAL else bool(code == STABLE)
    return np.ma.MaskedArray(code == STABLE, mask=code == MARGINAL)
