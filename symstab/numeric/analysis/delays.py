"""The delay margin, exact: the added delays at which a loop's stability switches.

A loop delay of ``(d + eps) T`` with a fraction ``0 <= eps < 1`` of a
period is derived exactly (the modified z-transform:
:attr:`symstab.Loop.polynomial` at a fractional ``d``), and the roots of
``chi`` move continuously with the delay, also across whole samples
(``eps -> 1`` is ``d + 1``, proved by
:func:`symstab.symbolic.discretize.fractional_delay_identities`).  So the
loop's stability changes with the delay only where a root crosses the unit
circle, and :func:`delay_margin` finds those delays:

1. the certified verdict (:meth:`symstab.Loop.classify`) on a grid of
   added delays, ``step`` of a sample apart (16 points a sample by
   default), from the point's delay up to ``limit`` samples more; the
   plant at each fraction of the grid is derived once and shared by every
   whole part;
2. each change of verdict (stable to not, or back) bracketed by two
   neighbours of the grid, refined by the one root bracketer
   (:func:`symstab.numeric.engine.search.bracketed_root`) on the spectral
   radius less 1, to a few ulps of the delay;
3. the crossing's frequency: where ``|chi / (z**s D)|`` is smallest on the
   circle there (:func:`symstab.numeric.engine.roots.circle_minimum`).

This is not a phase margin divided by a crossover frequency (which the
sampled loop's fractional delay does not obey: the hold's aliases turn
with it too), and not a scan of whole samples: the delay found is that of
the fractional derivation, exact to the bracket's ulps.  What a grid cannot
promise: a window of stability (or of instability) shorter than ``step``
between two points of the grid, entered and left within it, is not seen.
"""

import dataclasses
import math

import numpy as np

from ..._validate import check_real, snap_delay, split_delay
from ..engine.results import html_table
from ..engine.roots import STABLE, circle_minimum
from ..engine.search import bracketed_root
from ..loop.evaluation import FRACTION
from .margins import delay_limit_of, phase_crossings, stable_point

__all__ = ["DelaySwitch", "DelayMargin", "delay_margin"]

#: Points of the grid per sample of delay (the default ``step`` is its inverse).
STEPS_PER_SAMPLE = 16


@dataclasses.dataclass(frozen=True)
class DelaySwitch:
    """A delay at which the loop's stability switches: a root crosses the unit circle.

    Attributes
    ----------
    samples : float
        The loop's delay there, in samples (``d + eps``).
    added : float
        The delay added to the point's, in samples.
    T : float
        The sample period, s.
    theta : float
        The root's angle on the circle, rad/sample, in [0, pi].
    stable_after : bool
        Whether the loop is stable just beyond this delay (stability
        regained) or not (lost).
    """

    samples: float
    added: float
    T: float
    theta: float
    stable_after: bool

    @property
    def seconds(self):
        """The loop's delay there, s."""
        return self.samples * self.T

    @property
    def added_seconds(self):
        """The delay added, s."""
        return self.added * self.T

    @property
    def frequency(self):
        """The crossing frequency, Hz: ``theta / (2 pi T)``."""
        return self.theta / (2 * math.pi * self.T)


@dataclasses.dataclass(frozen=True)
class DelayMargin:
    """The delay margin of a loop at a stable point, and its stability switches.

    Attributes
    ----------
    point : dict
        The parameters' values (``d`` the delay in samples, fractional or
        whole).
    T : float
        The sample period, s.
    switches : tuple of DelaySwitch
        Every switch found up to ``limit`` samples more, by increasing delay
        (lost, regained, lost, ...).
    limit : float
        The most samples added that were examined.
    step : float
        The grid's step, samples.
    """

    point: dict
    T: float
    switches: tuple
    limit: float
    step: float

    @property
    def margin(self):
        """The smallest added delay at which the loop is not stable, samples (None: none found)."""
        return self.switches[0].added if self.switches else None

    @property
    def seconds(self):
        """:attr:`margin` in seconds (None: none found)."""
        return None if self.margin is None else self.margin * self.T

    @property
    def frequency(self):
        """The first crossing's frequency, Hz (None: none found)."""
        return self.switches[0].frequency if self.switches else None

    def rows(self):
        """``(quantity, value, where)`` rows, for tables."""
        if self.limit == 0:
            return [("delay margin", "not examined",
                     "d is the largest delay accepted (SYMSTAB_MAX_DELAY)")]
        if not self.switches:
            return [("delay margin", "none", f"stable up to {self.limit:g} samples more")]
        out = []
        for k, s in enumerate(self.switches):
            what = "delay margin" if k == 0 else ("stable again" if s.stable_after
                                                  else "unstable again")
            out.append((what, f"{s.added:.9g} samples ({s.added_seconds:.6g} s)",
                        f"at d = {s.samples:.9g}, {s.frequency:.6g} Hz"))
        return out

    def __repr__(self):
        width = max(len(r[0]) for r in self.rows())
        lines = [f"DelayMargin at {_point_text(self.point)} (up to {self.limit:g} samples more)"]
        lines += [f"  {q:<{width}}  {v}  ({w})" for q, v, w in self.rows()]
        return "\n".join(lines)

    def _repr_html_(self):
        return html_table(f"Delay margin at {_point_text(self.point)}",
                          [(q, f"{v} ({w})") for q, v, w in self.rows()])

    def as_dict(self):
        """The margin and switches as plain numbers (JSON-ready)."""
        return {"point": dict(self.point), "T": self.T, "limit": self.limit, "step": self.step,
                "margin": self.margin, "seconds": self.seconds, "frequency": self.frequency,
                "switches": [dict(dataclasses.asdict(s), seconds=s.seconds,
                                  frequency=s.frequency) for s in self.switches]}


def _point_text(point):
    return ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in point.items())


def delay_margin(loop, *, limit=None, step=None, every=None, **values):
    """The exact delay margin of a loop at a stable point, and the delays where stability switches.

    See the module's docstring for the method and what a grid of ``step``
    cannot see.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    limit : float, optional
        The most samples added to the point's delay that are examined
        (default ``max(100, 10 (d + 1))``, within ``SYMSTAB_MAX_DELAY``).
    step : float, optional
        The grid's step in samples, in (0, 1] (default 1/16).
    every : bool, optional
        Find every switch up to ``limit`` (stability lost, regained, lost
        again ...), not only the first (the margin), where the scan stops.
        Default: every switch when ``limit`` is given, else the first.
    **values
        A single value of every parameter (or its default); the delay as
        ``d`` (samples, fractional or whole) or ``Td`` (seconds).

    Returns
    -------
    DelayMargin

    Raises
    ------
    ValueError
        At a point that is not stable, for an array of values, or a
        ``limit`` or ``step`` out of range.

    Examples
    --------
    >>> from symstab import PAPER_LOOP
    >>> found = PAPER_LOOP.delay_margin(K=2.0, B=0.1, d=40, limit=20)
    >>> round(found.margin, 6), round(found.frequency, 4)
    (9.640327, 11.6962)
    """
    point = stable_point(loop, values, "the delay margin")
    T = float(point["T"])
    start = float(point["d"])
    step = 1.0 / STEPS_PER_SAMPLE if step is None else check_real(
        "step", step, low=0.0, low_open=True, high=1.0)
    every = (limit is not None) if every is None else bool(every)
    limit = float(delay_limit_of(start, limit, name="limit", whole=False))
    if limit == 0:
        return DelayMargin(point, T, (), 0.0, step)
    n = int(math.ceil(limit / step - 1e-9))
    grid = start + step * np.arange(n + 1)
    grid[-1] = min(grid[-1], start + limit)
    switches, end = _switches(loop, point, grid, first_only=not every)
    return DelayMargin(point, T, tuple(switches), float(end - start), step)


def _switches(loop, point, grid, *, first_only):
    """The switches along ``grid`` (one whole sample of it at a time), and the last delay examined.

    With ``first_only``, the scan stops at the first switch (the margin).
    """
    wholes = np.floor(snap_delay(grid))
    out, before, last = [], True, grid[0]
    for whole in np.unique(wholes):
        where = np.flatnonzero(wholes == whole)
        stable = _stable_on(loop, point, grid[where])
        # The neighbour before each point: the last of the previous sample for the first.
        previous = np.concatenate([[before], stable[:-1]])
        for k in np.flatnonzero(stable != previous):
            i = where[k]
            out.append(_switch(loop, point, grid[i - 1], grid[i], bool(stable[k]),
                               float(point["T"])))
            if first_only:
                return out, grid[i]
        before, last = stable[-1], grid[where[-1]]
    return out, last


def _stable_on(loop, point, delays):
    """Whether the loop is stable at each of ``delays`` (samples, one whole part): one call."""
    d, eps = split_delay(delays, name="d")
    given = {**{k: v for k, v in point.items() if k != "d"}, "d": d}
    if eps is not None:
        # The fractions as they are, the plant at each derived once for every whole part.
        given[FRACTION] = eps
    return np.broadcast_to(loop.classify(**given), delays.shape) == STABLE


def _switch(loop, point, low, high, stable_after, T):
    """The :class:`DelaySwitch` between two delays of the grid whose verdicts differ."""
    base = {k: v for k, v in point.items() if k != "d"}

    def excess(x):
        return np.array([float(loop.spectral_radius(**base, d=float(t))) - 1.0
                         for t in np.ravel(x)]).reshape(np.shape(x))

    # The radius is continuous in the delay; at the ends it is on either side of 1.
    samples = float(bracketed_root(excess, [low], [high])[0])
    return DelaySwitch(samples=samples, added=samples - float(point["d"]), T=T,
                       theta=_crossing_angle(loop.polynomial(**base, d=samples), T),
                       stable_after=stable_after)


def _crossing_angle(chi, T):
    """The angle of ``chi``'s root on the unit circle, ``chi`` taken at a switch.

    A root on the circle is at a gain crossover (``|L| = 1``) or at ``z =
    +-1``, where ``L`` may have a pole (a Tustin damper's ``z = -1``: the
    plant's sampling zero crosses it); the candidate where ``|chi|`` is
    smallest beside its coefficients' sizes, or the certified minimum of
    ``|1 + L|`` where no candidate is a root to 1e-8 of them.
    """
    delayed, direct = chi.delayed.reshape(-1), chi.direct.reshape(-1)
    candidates = [c.theta for c in phase_crossings(delayed, direct, chi.shift, T)]
    candidates = np.array(candidates + [0.0, math.pi])
    dense = chi.dense().reshape(-1)
    residual = (np.abs(np.polyval(dense, np.exp(1j * candidates)))
                / np.sum(np.abs(dense)))
    best = int(np.argmin(residual))
    if residual[best] <= 1e-8:
        return float(candidates[best])
    return float(circle_minimum(chi)[2])

