"""Delays in a range: stable for every constant delay, and for every delay that varies.

A networked or loaded loop's delay is not one number but a range
``[Td_min, Td_max]``.  Two questions, two sets (:func:`delay_range`,
:func:`delay_range_map`):

* **every constant delay in the range**: stable at ``Td_min`` and no root
  reaches the unit circle before ``Td_max``: the exact delay margin
  (:func:`symstab.numeric.analysis.delays.delay_margin`) from ``Td_min`` is
  beyond ``Td_max - Td_min``.  The ends may be fractional samples.
* **every delay sequence in the range**, changing from sample to sample by
  whole samples (``u[k] = -f[k - delta_k]``, ``delta_k`` any of ``d_min ...
  d_max``; around a fixed fraction of a period, the plant's, where the ends
  share one: 2.5 to 4.5 samples): a sufficient small-gain criterion, the discrete-time form of
  Kao and Lincoln's bound for time-varying delays (C.-Y. Kao and B.
  Lincoln, "Simple stability criteria for systems with time-varying
  delays", *Automatica* 40(8), 2004; its sampled-data use is the *jitter
  margin* of A. Cervin, B. Lincoln, J. Eker, K.-E. Årzén and G. Buttazzo,
  2004).  With ``N = d_max - d_min`` and ``L = N_chi / (z**s D)`` the loop
  at ``d_min``::

      f[k - delta_k] - f[k - d_min] = -sum of at most N differences f[j] - f[j-1],

  an operator of gain at most ``N`` on the differences (each window holds at
  most ``N`` of them, each difference is in at most ``N`` windows:
  Cauchy-Schwarz), around the nominal loop whose map from that
  perturbation to the differences is ``(1 - z**-1) L / (1 + L)``.  By the
  small-gain theorem the loop is stable for every such sequence if it is
  stable at ``d_min`` and::

      N |exp(j theta) - 1| |L / (1 + L)| < 1   for every theta,

  that is ``min |chi| / (N |(z - 1) N_chi|) > 1`` on the circle, certified
  by :func:`symstab.numeric.engine.roots.circle_minimum` (a bracket of
  relative width ``rtol``, proved by bounds on the circle).

**Conservatism.** The criterion is sufficient, not necessary: it allows any
sequence, also the worst one, and bounds a norm by a product of norms; a
point outside the varying set may well be stable for the sequences a real
network makes, and the constant set always holds the varying one.  It is
derived for delays that vary by whole samples, around a fraction of a period
that does not vary (the plant with the fraction, the modified z-transform, in
``L``): a delay that varies inside a sample moves the hold's switching
instant from period to period, which this operator does not describe, so a
range whose ends do not differ by whole samples (2.5 to 4.25) gets the
constant set only (the varying one is None, and says why).
"""

import dataclasses
import math

import numpy as np

from ..._resources import MAX_DELAY_ENV, max_delay
from ..._validate import DELAY_RTOL, check_real, snap_delay
from ..engine.polynomial import DelayedPolynomial
from ..engine.results import html_table
from ..engine.roots import STABLE, circle_minimum
from .margins import classified_point

__all__ = ["DelayRange", "delay_range", "DelayRangeMap", "delay_range_map",
           "DelayRangeRegion", "delay_range_region"]

@dataclasses.dataclass(frozen=True)
class DelayRange:
    """A point's stability over a range of delays (:func:`symstab.numeric.analysis.delay_range.delay_range`).

    Attributes
    ----------
    point : dict
        The parameters' values, ``d`` the range's lower end in samples.
    T : float
        The sample period, s.
    samples : (float, float)
        The range in samples, ``(Td_min / T, Td_max / T)``.
    constant : bool
        Stable at every constant delay of the range.
    margin : float or None
        The exact delay margin from the lower end, samples (None: none up
        to the upper end); ``constant`` is ``margin is None``.
    varying : bool or None
        Stable for every sequence of whole-sample delays in the range, by
        the small-gain criterion (a sufficient one); None where it is not
        derived (ends that do not differ by whole samples: :attr:`why`).
    gain_margin : float or None
        ``min |chi| / (N |(z - 1) N_chi|)`` on the circle (the criterion
        holds above 1): its certified lower bound.
    why : str
        What ``varying`` says, in words.
    """

    point: dict
    T: float
    samples: tuple
    constant: bool
    margin: object
    varying: object
    gain_margin: object
    why: str

    def rows(self):
        """``(quantity, value, note)`` rows, for tables."""
        low, high = self.samples
        constant = ("stable" if self.constant else
                    f"unstable from {low + self.margin:.9g} samples")
        varying = {True: "stable", False: "not shown stable", None: "not derived"}[self.varying]
        return [("every constant delay", constant, f"{low:.9g} to {high:.9g} samples"),
                ("every varying delay", varying, self.why)]

    def as_dict(self):
        """The sets as plain values (JSON-ready)."""
        return {"point": dict(self.point), "T": self.T, "samples": list(self.samples),
                "constant": self.constant, "margin": self.margin, "varying": self.varying,
                "gain_margin": self.gain_margin, "why": self.why}

    def __repr__(self):
        low, high = self.samples
        lines = [f"DelayRange({low:.6g} to {high:.6g} samples, T = {self.T:g} s)"]
        lines += [f"  {q}: {v} ({w})" for q, v, w in self.rows()]
        return "\n".join(lines)

    def _repr_html_(self):
        return html_table("Delays in a range", [(q, f"{v} ({w})") for q, v, w in self.rows()])


def _period(loop, given):
    """The sample period of a question's values (or the loop's default), checked."""
    T = {**loop.defaults, **given}.get("T")
    if T is None:
        raise TypeError("missing value(s) for T")
    return check_real("T", T, low=0.0, low_open=True)


def _range_samples(delay_range, T):
    """``(low, high, shared)``: the range in samples, and whether its ends share a fraction of a period.

    ``shared``: ``high - low`` is a whole number of samples (within
    ``DELAY_RTOL``), whole ends included.
    """
    try:
        low, high = delay_range
    except (TypeError, ValueError):
        raise TypeError(f"delay_range must be (Td_min, Td_max) in seconds, got "
                        f"{delay_range!r}") from None
    low = check_real("delay_range's Td_min", low, low=0.0)
    high = check_real("delay_range's Td_max", high, low=0.0)
    if high < low:
        raise ValueError(f"delay_range must have Td_min <= Td_max, got ({low:g}, {high:g})")
    if high / T > max_delay():
        raise ValueError(f"delay_range's Td_max is {high / T:g} samples; at most "
                         f"{max_delay():g} (raise the limit with {MAX_DELAY_ENV})")
    low, high = (float(x) for x in snap_delay([low / T, high / T]))
    width = high - low
    return low, high, abs(width - round(width)) <= DELAY_RTOL * max(1.0, high)


def range_in_samples(loop, delay_range, **values):
    """``(low, high, shared)``: a delay range in samples at the question's period, checked.

    What :func:`delay_range` and :func:`delay_range_map` check first: the
    command line calls it before it prints or computes anything.

    Parameters
    ----------
    loop : symstab.Loop
    delay_range : (float, float)
        ``(Td_min, Td_max)``, seconds.
    **values
        The question's values (``T`` here, or the loop's).

    Returns
    -------
    (float, float, bool)
        The ends in samples and whether they share a fraction of a period
        (the varying set is derived).
    """
    return _range_samples(delay_range, _period(loop, values))


def _gain_bracket(chi, n_samples, rtol):
    """Certified ``(lower, upper)`` of ``min |chi| / (N |(z - 1) N_chi|)`` per polynomial of ``chi``."""
    dense = np.atleast_2d(chi.dense().reshape(-1, chi.dense().shape[-1]))
    direct = np.atleast_2d(chi.direct.reshape(-1, chi.direct.shape[-1]))
    # (z - 1) N_chi, times N: the "delayed" part of chi written as D' + (chi - D').
    scaled = n_samples * np.concatenate([direct, np.zeros((len(direct), 1))], axis=1)
    scaled[:, 1:] -= n_samples * direct
    pad = np.zeros((len(dense), dense.shape[1] - scaled.shape[1]))
    rest = dense - np.concatenate([pad, scaled], axis=1)
    lower, upper, _ = circle_minimum(DelayedPolynomial(scaled, rest, 0), rtol=rtol)
    return np.reshape(lower, chi.shape), np.reshape(upper, chi.shape)


def delay_range(loop, *, delay_range, rtol=1e-6, **values):
    """Whether a point is stable for every constant delay, and every varying one, in a range.

    See the module's docstring for the two criteria and the second's
    conservatism.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    delay_range : (float, float)
        ``(Td_min, Td_max)``, seconds.
    rtol : float
        The relative width of the small-gain bound's certified bracket.
    **values
        A single value of every other parameter (or its default); a delay
        given here is replaced by the range's.

    Returns
    -------
    DelayRange

    Examples
    --------
    >>> from symstab import PAPER_LOOP
    >>> found = PAPER_LOOP.delay_range(delay_range=(0.002, 0.004), K=20.0, B=0.5)
    >>> found.constant, found.varying
    (True, True)
    """
    given = {k: v for k, v in values.items() if k not in ("d", "Td")}
    T = _period(loop, given)
    low, high, shared = _range_samples(delay_range, T)
    point, code = classified_point(loop, {**given, "d": low})
    if code != STABLE:
        return DelayRange(point, T, (low, high), False, 0.0, False if shared else None, None,
                          "not stable at the range's lower end")
    found = loop.delay_margin(limit=high - low, every=False, **point) if high > low else None
    margin = None if found is None else found.margin
    if not shared:
        return DelayRange(point, T, (low, high), margin is None, margin, None, None,
                          "derived for delays that vary by whole samples; the range's ends do "
                          "not differ by whole samples")
    if high == low:
        return DelayRange(point, T, (low, high), True, None, True, math.inf,
                          "a range of one delay")
    lower, _ = _gain_bracket(loop.polynomial(**point), round(high - low),
                             check_real("rtol", rtol, low=0.0, low_open=True, high=0.5,
                                        high_open=True))
    lower = float(lower)
    return DelayRange(point, T, (low, high), margin is None, margin, lower > 1, lower,
                      f"small-gain bound {lower:.6g} " + ("> 1" if lower > 1 else "<= 1"))


@dataclasses.dataclass(frozen=True)
class DelayRangeMap:
    """The two sets of a delay range over a grid of a plane (:func:`symstab.numeric.analysis.delay_range.delay_range_map`).

    Attributes
    ----------
    x, y : str
        The plane's parameters.
    x_values, y_values : ndarray
        The grid (1-D).
    samples : (float, float)
        The range in samples.
    constant : ndarray of bool
        Stable for every constant delay of the range, shape ``(len(y_values), len(x_values))``.
    varying : ndarray of bool or None
        Stable for every delay sequence varying by whole samples (the
        small-gain criterion); None where the ends do not differ by whole
        samples.
    at : dict
        The other parameters' values.
    """

    x: str
    y: str
    x_values: np.ndarray
    y_values: np.ndarray
    samples: tuple
    constant: np.ndarray
    varying: object
    at: dict

    def __repr__(self):
        low, high = self.samples
        varying = ("not derived" if self.varying is None else
                   f"{int(np.count_nonzero(self.varying))} every varying delay")
        return (f"DelayRangeMap({low:.6g} to {high:.6g} samples over {len(self.x_values)} x "
                f"{len(self.y_values)} points of ({self.x}, {self.y}): "
                f"{int(np.count_nonzero(self.constant))} stable for every constant delay, "
                f"{varying})")

    def plot(self, ax=None):
        """Draw the two sets over the grid: :func:`symstab.drawing.plot_delay_range_map`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).

        Returns
        -------
        symstab.drawing.Plot
        """
        from ...drawing import plot_delay_range_map

        return plot_delay_range_map(self, ax)


def delay_range_map(loop, x_values, y_values, *, delay_range, x=None, y=None, rtol=1e-6,
                    **values):
    """The two sets of :func:`symstab.numeric.analysis.delay_range.delay_range` at every point of a grid.

    The constant set from the exact delay margin map
    (:meth:`symstab.Loop.margin_map` with ``margin="delay"``) at the range's
    lower end; the varying set from the small-gain bound of all stable
    points at once.

    Parameters
    ----------
    loop : symstab.Loop
    x_values, y_values : array_like
        The grid (1-D).
    delay_range : (float, float)
        ``(Td_min, Td_max)``, seconds.
    x, y : str, optional
        The plane (default the loop's).
    rtol : float
        As in :func:`delay_range`.
    **values
        Single values of the other parameters.

    Returns
    -------
    DelayRangeMap
    """
    x, y = loop.plane_of(x, y)
    given = {k: v for k, v in values.items() if k not in ("d", "Td")}
    T = _period(loop, given)
    low, high, shared = _range_samples(delay_range, T)
    found = loop.margin_map(x_values, y_values, x=x, y=y, margin="delay",
                            delay_limit=max(high - low, 1e-9), **given, d=low)
    stable = ~np.isnan(found.values)
    constant = stable & (found.values > high - low)
    varying = (_varying_set(loop, (x, found.x_values), (y, found.y_values), given, (low, high),
                            rtol, stable) if shared else None)
    return DelayRangeMap(x, y, found.x_values, found.y_values, (low, high), constant, varying,
                         dict(given))


def _varying_set(loop, x, y, given, samples, rtol, stable=None):
    """Where the small-gain criterion holds over a grid: ``(len(y), len(x))`` of bool.

    ``x``, ``y`` are ``(name, values)``; ``samples`` the range's ends, a whole number of
    samples apart;
    ``stable``, the grid's stability at the lower end where known (else
    classified here).
    """
    (x, xs), (y, ys), (low, high) = x, y, samples
    X, Y = np.meshgrid(xs, ys)
    if stable is None:
        stable = loop.classify(**given, d=low, **{x: X, y: Y}) == STABLE
    varying = np.array(stable, dtype=bool)
    if high > low and varying.any():
        chi = loop.polynomial(**given, d=low, **{x: X[varying], y: Y[varying]})
        lower, _ = _gain_bracket(chi, round(high - low), rtol)
        varying[varying] = np.asarray(lower) > 1
    return varying


@dataclasses.dataclass(frozen=True)
class DelayRangeRegion:
    """The two sets of a delay range in a plane (:func:`delay_range_region`, :meth:`symstab.Loop.region`).

    Attributes
    ----------
    constant : symstab.numeric.engine.results.RobustRegion
        The points stable for every constant delay of the range, certified
        for the continuum of delays (zero exclusion with the fraction of a
        period as a side of the box): an inner approximation, as every
        robust region.
    grid : DelayRangeMap
        Both sets on a grid of the region's window: ``constant`` the
        certified region's points, ``varying`` those of the small-gain
        criterion for delays varying by whole samples (None where the
        range's ends do not differ by whole samples).
    """

    constant: object
    grid: DelayRangeMap

    def __repr__(self):
        low, high = self.grid.samples
        varying = ("not derived" if self.grid.varying is None else
                   f"{int(np.count_nonzero(self.grid.varying))} of its "
                   f"{self.grid.varying.size} points")
        state = "empty" if self.constant.empty else "certified"
        return (f"DelayRangeRegion({low:.6g} to {high:.6g} samples in ({self.grid.x}, "
                f"{self.grid.y}): every constant delay {state}; every varying delay on a "
                f"{len(self.grid.x_values)} x {len(self.grid.y_values)} grid, {varying})")

    def plot(self, ax=None):
        """Draw the certified constant set, the varying one's grid over it.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).

        Returns
        -------
        symstab.drawing.Plot
            The robust region's drawing, with artists ``"varying"`` added.
        """
        from ...drawing import plot_delay_range_region

        return plot_delay_range_region(self, ax)


def delay_range_region(loop, x=None, y=None, *, delay_range, x_range=None, y_range=None, n=61,
                       strips=64, rtol=1e-6, progress=None, **values):
    """Every constant delay of a range as a certified region of a plane, every varying one on a grid.

    The constant set is :func:`symstab.numeric.analysis.robust.robust_region`'s
    with ``uncertain={"Td": delay_range}`` (with the other parameters'
    ranges of ``uncertain`` given too): certified for every delay of the
    range, the fraction of a period one more side of the box.  The varying
    set is the small-gain criterion of :func:`delay_range` (ends a whole number of samples apart,
    ends only) at the points of an ``n x n`` grid of the region's window
    stable at the lower end.

    Parameters
    ----------
    loop : symstab.Loop
    x, y : str, optional
        The plane (default the loop's).
    delay_range : (float, float)
        ``(Td_min, Td_max)``, seconds.
    x_range, y_range, strips, progress
        As :func:`~symstab.numeric.analysis.robust.robust_region`.
    n : int
        Points of the grid per side (default 61).
    rtol : float
        The robust region's and the small-gain bracket's (as theirs).
    **values
        Single values of the other parameters (a delay is the range's).

    Returns
    -------
    DelayRangeRegion
    """
    from ..._validate import check_count
    from .robust import robust_region

    n = check_count("n", n, 2)
    given = {k: v for k, v in values.items() if k not in ("d", "Td")}
    T = _period(loop, given)
    low, high, shared = _range_samples(delay_range, T)
    if "uncertain" in given:
        raise TypeError("delay_range is the region's uncertain delay: use robust_region with "
                        "uncertain={'Td': ..., ...} for a box of other parameters as well")
    region = robust_region(loop, x, y, uncertain={"Td": tuple(delay_range)}, strips=strips,
                           rtol=rtol, x_range=x_range, y_range=y_range, progress=progress,
                           **given)
    xs = np.linspace(*region.nominal.x_range, n)
    ys = np.linspace(*region.nominal.y_range, n)
    X, Y = np.meshgrid(xs, ys)
    constant = np.asarray(region.contains(X, Y), dtype=bool)
    varying = (_varying_set(loop, (region.x, xs), (region.y, ys), given, (low, high),
                            min(rtol, 0.25)) if shared else None)
    grid = DelayRangeMap(region.x, region.y, xs, ys, (low, high), constant, varying, dict(given))
    return DelayRangeRegion(region, grid)
