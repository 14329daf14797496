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
   whole part; once the grid's first sample is stable, each fraction's
   points before the phase argument's first whole delay at that fraction
   are known stable and skipped (:mod:`.delay_scan`, which
   :func:`symstab.numeric.analysis.margins.margin_map` searches every
   point of a map with);
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

from ..._validate import check_real
from ..engine.results import html_table
from ..engine.roots import circle_minimum
from .delay_scan import STEPS_PER_SAMPLE, crossing_delays, delay_grid, verdict_changes
from .margins import (
    delay_limit_of,
    first_whole_delays,
    phase_crossings,
    point_text,
    stable_point,
)

__all__ = ["DelaySwitch", "DelayMargin", "delay_margin"]

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
        lines = [f"DelayMargin at {point_text(self.point)} (up to {self.limit:g} samples more)"]
        lines += [f"  {q:<{width}}  {v}  ({w})" for q, v, w in self.rows()]
        return "\n".join(lines)

    def _repr_html_(self):
        return html_table(f"Delay margin at {point_text(self.point)}",
                          [(q, f"{v} ({w})") for q, v, w in self.rows()])

    def as_dict(self):
        """The margin and switches as plain numbers (JSON-ready)."""
        return {"point": dict(self.point), "T": self.T, "limit": self.limit, "step": self.step,
                "margin": self.margin, "seconds": self.seconds, "frequency": self.frequency,
                "switches": [dict(dataclasses.asdict(s), seconds=s.seconds,
                                  frequency=s.frequency) for s in self.switches]}



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
    (16.615744, 2.1744)
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
    base = {k: v for k, v in point.items() if k != "d"}
    grid = delay_grid(start, limit, step)
    rows, index, after, examined = verdict_changes(loop, base, {}, grid, first_only=not every,
                                                   first_whole=first_whole_delays)
    samples = crossing_delays(loop, base, {}, rows, grid[index - 1], grid[index])
    switches = tuple(
        DelaySwitch(samples=float(s), added=float(s) - start, T=T,
                    theta=_crossing_angle(loop.polynomial(**base, d=float(s)), T),
                    stable_after=bool(a))
        for s, a in zip(samples, after, strict=True))
    return DelayMargin(point, T, switches, float(grid[examined[0]] - start), step)


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

