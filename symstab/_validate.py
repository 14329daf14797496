"""Input validation, in one place, for every public entry point.

Wrong kinds raise :class:`TypeError`; wrong values raise :class:`ValueError`
whose message names the parameter and the allowed range.
"""

import math
import numbers

import numpy as np

from ._resources import MAX_DELAY_ENV, max_delay

__all__ = ["check_real", "check_count", "check_delay", "check_delay_samples", "split_delay",
           "snap_delay", "check_array", "check_grid", "check_delta", "check_loop", "check_progress", "DELTA_MAX", "PARAMETER_MAX"]


def _describe_range(low, high, low_open, high_open):
    if low is None and high is None:
        return "a finite real number"
    parts = []
    if low is not None:
        parts.append(f"{'>' if low_open else '>='} {low:g}")
    if high is not None:
        parts.append(f"{'<' if high_open else '<='} {high:g}")
    return "a finite real number " + " and ".join(parts)


def check_real(name, value, *, low=None, high=None, low_open=False, high_open=False):
    """Return ``value`` as a float after checking it is finite and in range.

    Raises
    ------
    TypeError
        If ``value`` is not a real number (bool and complex included).
    ValueError
        If ``value`` is NaN, infinite or outside the range.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__}")
    try:
        x = float(value)
    except OverflowError:
        x = math.inf
    allowed = _describe_range(low, high, low_open, high_open)
    bad = not math.isfinite(x)
    if low is not None:
        bad = bad or x < low or (low_open and x == low)
    if high is not None:
        bad = bad or x > high or (high_open and x == high)
    if bad:
        raise ValueError(f"{name} must be {allowed}, got {value!r}")
    return x


def check_count(name, value, low):
    """Return an integer count ``value >= low`` as an ``int``.

    The one check of every count parameter (``n``, ``n_beta``, ...): a
    non-integer kind (bool, float, str, None) is a :class:`TypeError`, an
    integer below ``low`` a :class:`ValueError`, both naming ``name``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer >= {low}, got {type(value).__name__}")
    if value < low:
        raise ValueError(f"{name} must be an integer >= {low}, got {value!r}")
    return int(value)


def check_delay(d, *, name="d"):
    """Return the loop delay ``d`` (in samples) as an ``int``.

    ``d`` must be a non-negative integer; an integral float such as ``3.0``
    is accepted, ``2.5`` is not.
    """
    if isinstance(d, bool) or not isinstance(d, numbers.Real):
        raise TypeError(f"delay {name} must be a non-negative integer, got {type(d).__name__}")
    if isinstance(d, numbers.Integral):
        k = int(d)
    else:
        x = float(d)
        if not (math.isfinite(x) and x.is_integer()):
            raise ValueError(f"delay {name} must be a non-negative integer, got {d!r}")
        k = int(x)
    if k < 0:
        raise ValueError(f"delay {name} must be a non-negative integer, got {d!r}")
    limit = max_delay()
    if k > limit:
        raise ValueError(f"delay {name} must be an integer from 0 to {limit}, got {d!r} "
                         f"(raise the limit with {MAX_DELAY_ENV})")
    return k


def check_delay_samples(ratio, *, name="Td / T", rtol=1e-9):
    """Return a delay ratio such as ``Td / T`` as an ``int``.

    The ratio of two floats is rarely an exact integer (40e-3 / 1e-3 is
    40.00000000000001), so a relative tolerance ``rtol`` is allowed.
    """
    x = check_real(name, ratio, low=0.0)
    k = round(x)
    if abs(x - k) > rtol * max(1.0, abs(x)):
        raise ValueError(
            f"{name} must be a non-negative whole number of samples, got {ratio!r}"
        )
    return check_delay(int(k), name=name)


#: A delay within this relative distance of a whole number of samples is that
#: number (``40e-3 / 1e-3`` is 40.00000000000001): the ratio of two floats.
DELAY_RTOL = 1e-9


def snap_delay(samples):
    """A delay in samples (a float array), each within :data:`DELAY_RTOL` of a whole number that number.

    ``floor`` of it is the whole part :func:`split_delay` takes: callers
    that group delays by their whole part (one whole ``d`` a call) use it.
    """
    x = np.asarray(samples, dtype=float)
    near = np.round(x)
    return np.where(np.abs(x - near) <= DELAY_RTOL * np.maximum(1.0, x), near, x)


def split_delay(samples, *, name="d"):
    """A delay in samples, ``d + eps``, split: ``(d, eps)`` with a whole ``d`` and ``0 <= eps < 1``.

    Parameters
    ----------
    samples : float or array_like
        The delay in samples (``Td / T``), non-negative; arrays must share
        their whole part.  Within :data:`DELAY_RTOL` of a whole number it
        is that number.
    name : str
        The delay's name in messages (``d``, ``Td / T``).

    Returns
    -------
    (int, ndarray or None)
        The whole samples (at most ``SYMSTAB_MAX_DELAY``) and the fraction
        of a period per point, None where every point is whole.

    Raises
    ------
    TypeError, ValueError
        Not a real number, negative, not finite, beyond the limit, or
        points with different whole parts.
    """
    x = snap_delay(check_array(name, samples, low=0.0))
    whole = np.floor(x)
    if whole.size and np.any(whole != whole.flat[0]):
        raise ValueError(f"the delay {name} must have one whole number of samples over the points, "
                         f"got {int(whole.min())} to {int(whole.max())}; ask each whole part "
                         f"apart")
    limit = max_delay()
    d = int(whole.flat[0]) if whole.size else 0
    if x.size and float(x.max()) > limit:
        raise ValueError(f"delay {name} must be from 0 to {limit} samples, got "
                         f"{float(x.max())!r} (raise the limit with {MAX_DELAY_ENV})")
    eps = x - whole
    return d, (eps if np.any(eps != 0) else None)


def delay_samples(samples, *, name="d"):
    """One delay in samples, ``d + eps``: an ``int`` when whole, else the float (``40.5``).

    Checked as :func:`split_delay` checks it (within :data:`DELAY_RTOL` of a
    whole number it is that number).

    Raises
    ------
    TypeError, ValueError
        Not one real number, negative, not finite, or beyond
        ``SYMSTAB_MAX_DELAY``.
    """
    if np.ndim(samples) != 0:
        raise ValueError(f"delay {name} must be one number of samples, got an array of shape "
                         f"{np.shape(samples)}")
    whole, fraction = split_delay(check_real(f"delay {name}", samples, low=0.0), name=name)
    return whole if fraction is None else whole + float(fraction)


def check_array(name, value, *, low=None, low_open=False, high=None):
    """Return ``value`` as a float ndarray after checking every entry.

    Scalars become 0-d arrays.  Booleans, complex numbers and non-numeric
    objects raise :class:`TypeError`; NaN, infinite or out-of-range entries
    raise :class:`ValueError` naming ``name`` and the allowed range.
    """
    try:
        arr = np.asarray(value)
    except ValueError:   # a ragged nested list
        raise ValueError(f"{name} must be a real number or a rectangular array of real numbers, "
                         f"got a ragged {type(value).__name__}") from None
    if arr.dtype == bool or arr.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be a real number or an array of real numbers, "
                        f"got {type(value).__name__} of {arr.dtype}")
    arr = arr.astype(float)
    bad = ~np.isfinite(arr)
    if low is not None:
        bad |= (arr <= low) if low_open else (arr < low)
    if high is not None:
        bad |= arr > high
    if np.any(bad):
        first = arr[bad].flat[0]
        allowed = _describe_range(low, high, low_open, False)
        where = "" if arr.ndim == 0 else f" (entry {int(np.flatnonzero(bad.ravel())[0])})"
        raise ValueError(f"{name} must be {allowed}, got {float(first)!r}{where}")
    return arr


#: The largest |alpha|, |beta|, |gamma| the numeric API accepts: the root
#: count squares and multiplies them, and past ~1e154 that overflows.
PARAMETER_MAX = 1e150

#: The largest delta = b T / m accepted.  The kernels are accurate to a few
#: ulps up to here (tests/codegen/test_generated_kernels.py); far beyond it the
#: products of the ZOH coefficients (~ 1 / delta**3) underflow.
DELTA_MAX = 1e6


def check_delta(delta, *, name="delta"):
    """Return ``delta = b T / m`` as a float in ``[0, DELTA_MAX]``.

    ``delta = 0`` is a frictionless (or friction-compensated) device.
    """
    return check_real(name, delta, low=0.0, high=DELTA_MAX)


def check_loop(gamma, d, delta, *, zero_delta=True):
    """Validate the loop parameters of a dimensionless entry point.

    Returns ``(gamma, d, delta)`` as ``(float, int, float)``; ``delta`` must
    be in ``[0, DELTA_MAX]``, and positive with ``zero_delta=False`` (the
    high-precision references evaluate the derivation's forms in ``Gamma``
    and ``delta``, whose common factor ``delta**2`` vanishes at 0).
    """
    out = check_real("gamma", gamma), check_delay(d), check_delta(delta)
    if not zero_delta and out[2] == 0:
        raise ValueError("delta must be > 0 for the high-precision reference (the derivation's "
                         "forms carry a factor delta**2); the float API (classify, "
                         "boundary_curve, arc_end_angle, limits) accepts delta = 0")
    return out


def check_window(name, value):
    """Return a window ``(lo, hi)`` of two finite reals with ``lo < hi``."""
    arr = check_array(name, value)
    if arr.shape != (2,):
        raise ValueError(f"{name} must be a pair (lo, hi), got an array of shape {arr.shape}")
    lo, hi = float(arr[0]), float(arr[1])
    if not lo < hi:
        raise ValueError(f"{name} must be (lo, hi) with lo < hi, got ({lo:g}, {hi:g})")
    return lo, hi


def check_box(name, value, names=("x", "y")):
    """Return a drawing window ``((x0, x1), (y0, y1))``, each pair as :func:`check_window`."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        x, y = names
        raise TypeError(f"{name} must be (({x}0, {x}1), ({y}0, {y}1)), got {value!r}")
    return check_window(f"{name}[0]", value[0]), check_window(f"{name}[1]", value[1])


def check_progress(progress, bar=None):
    """A ``progress`` argument as a callable taking the work done so far, or None.

    The one normalisation of every ``progress`` argument of symstab.

    Parameters
    ----------
    progress : None, bool or callable
        None or False: no progress is reported.  True: the caller's progress
        bar, ``bar()``.  A callable: called with the work done so far (what
        that counts is the caller's: steps, draws, delays, chunks).
    bar : callable, optional
        Makes the bar that True asks for, e.g. ``lambda:
        progress_printer("simulating", steps)``
        (:func:`symstab._progress.progress_printer`: drawn on
        stderr when it is a terminal, for work over 2 s).  Without it, True
        reports nothing.

    Returns
    -------
    callable or None

    Raises
    ------
    TypeError
        For anything else (a number, a string).

    Examples
    --------
    >>> check_progress(False) is None and check_progress(None) is None
    True
    >>> check_progress(print) is print
    True
    """
    if progress is None or progress is False or progress is np.False_:
        return None
    if progress is True or progress is np.True_:
        return None if bar is None else bar()
    if callable(progress):
        return progress
    raise TypeError(f"progress must be True, False, None or a callable taking the work done so "
                    f"far, got {type(progress).__name__}")


def check_grid(x, y, x_values, y_values, values):
    """The grids of a map's axes ``x`` and ``y`` as 1-D float arrays, checked.

    Each must be a non-empty 1-D array of finite numbers (:func:`check_array`),
    and an axis must not also be given a single value in ``values``.
    """
    x_values, y_values = check_array(x, x_values), check_array(y, y_values)
    if x_values.ndim != 1 or y_values.ndim != 1 or not x_values.size or not y_values.size:
        raise ValueError(f"the grids of {x} and {y} must be 1-D and not empty")
    for name in (x, y):
        if name in values:
            raise TypeError(f"{name} is an axis of the map: give its grid, not a value")
    return x_values, y_values
