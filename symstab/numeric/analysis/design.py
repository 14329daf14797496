"""The design search: the value of one or two loop parameters that maximises a target.

:meth:`symstab.Loop.design` asks: which virtual mass (filter cut-off, sample
period, ...) gives the largest renderable stiffness, the largest Z-width or
the largest passive stiffness?  Each evaluation is a certified answer of the
one engine at one value of the searched parameters:

* ``"y_max"`` -- :attr:`Limits.y_max <symstab.numeric.engine.results.Limits.y_max>`
  of :meth:`symstab.Loop.limits` (``K_max`` in the plane ``(B, K)``);
* ``"area"`` -- :attr:`Limits.area <symstab.numeric.engine.results.Limits.area>`,
  the Z-width where ``x`` is a damping and ``y`` a stiffness;
* ``"passive"`` -- ``y_max`` of :meth:`symstab.Loop.passive_region` (the
  passive ``K_max``);
* ``"simulated"`` -- ``y_max`` of
  :func:`~symstab.numeric.simulation.simulated_limit.simulated_limit`: the largest
  ``y`` whose simulated run, with the non-idealities given, neither grows
  nor ends above a stated ``amplitude`` (not certified: a simulation,
  resolved to its grid).

A value where no point is stable has no target (``-inf``); one the engine
cannot resolve (a stable set shrinking to a sliver it refuses) is skipped
and reported in :attr:`Design.failed`.

The search (:func:`maximize_scalar`, :func:`maximize_box`) is a coarse scan
first, so that a second maximum is not missed, then ``scipy.optimize``
from the best scan point: a bounded scalar search (Brent's method,
:func:`scipy.optimize.minimize_scalar`) in one parameter, Nelder-Mead with
bounds (:func:`scipy.optimize.minimize`) in two.  The scan includes the
nominal value, and zooms into a run of stable values that holds fewer than
five scan points (a narrow band of stable values, such as the virtual
masses of a loop with a fast device, is resolved before the refinement
rather than missed).  Where the searched parameters enter the loop's
polynomial affinely with the plane's (a virtual mass), the scan is laid
over the values where Stodola's necessary condition can hold
(:func:`~symstab.numeric.engine.decomposition.stable_ranges`), so a narrow band
in a wide range is bracketed first, and a range where it holds nowhere is
proved to have no stable point.  Otherwise a band that holds neither a
scan point nor the nominal value can still be missed: then the message
says so (never a bare "none"), :attr:`Design.spacing` says the scan's
step, and ``n`` makes it finer.

A delay held in seconds while the sample period is searched (``delay``)
is ``d = delay / T`` samples at each ``T``, a fraction of a period
included (the modified z-transform carries it, and the passive set's
condition for a fractional delay): the target is continuous in ``T`` and
searched as any other parameter.

A design can also count a cost: with an encoder (``encoder_resolution``)
the force noise of its quantization at a rendered point of the plane
(:func:`~symstab.numeric.analysis.noise.force_noise_rms`) is recorded at
every value evaluated (:attr:`Design.pareto`, the values no other beats on
both the target and the noise), and with a budget (``noise_limit``, one
parameter searched) only the values whose noise fits are candidates: the
line is scanned for the noise first, the edges where it crosses the budget
are bisected, and the target is maximised over the pieces left (each by
:func:`maximize_scalar`).  Stability has no noise criterion, so a search
over a velocity filter's cut-off answers "the highest"; with a budget the
answer is the highest cut-off whose noise fits.
"""

import dataclasses
import math

import numpy as np

from ..._validate import check_count, check_progress, check_real, check_window

__all__ = ["TARGETS", "Design", "design", "maximize_scalar", "maximize_box", "box_corners"]

#: What a design maximises, with what it is.
TARGETS = {
    "y_max": "the largest stable y (K_max in the (B, K) plane)",
    "area": "the area of the stable set (the Z-width in the (B, K) plane)",
    "passive": "the largest passive y (the passive K_max in the (B, K) plane)",
    "simulated": "the largest y whose simulated run settles below the amplitude given",
}
#: The relative accuracy of the search by default: a simulated target is
#: resolved to its grid, about 1e-4 of its y_max, so finer is wasted.
_RTOL = {"simulated": 1e-3}
#: A run of stable scan values shorter than this is zoomed into before refining.
_MIN_RUN = 5
#: Zooms at most (each divides the step by about n / 2).
_MAX_ZOOMS = 8
#: Evaluations of the local refinement at most.
_MAX_REFINE = 200
#: Scan points of each part of a line cut by a noise budget, at least.
_PIECE_POINTS = 5


@dataclasses.dataclass(frozen=True)
class Design:
    """What :meth:`symstab.Loop.design` found.

    Attributes
    ----------
    target : str
        What was maximised: a key of :data:`TARGETS`.
    x, y : str
        The plane whose stable (or passive) set the target measures.
    over : dict
        ``{name: (low, high)}``: the parameters searched and their ranges.
    best : dict or None
        ``{name: value}`` at the optimum; None when no value evaluated has
        a stable point (:attr:`message` says whether that is proved for the
        whole range or which values were not examined).
    value : float or None
        The target there.
    nominal : dict
        ``{name: value}`` of the searched parameters as given or defaulted
        (empty when one has no value).
    value_nominal : float or None
        The target at the nominal values (None where there are none; ``-inf``
        when no point is stable there).
    limits : object or None
        At the optimum: the :class:`~symstab.numeric.engine.results.Limits` of the
        plane (targets ``y_max``, ``area``) or the
        :class:`~symstab.numeric.analysis.passivity.PassiveRegion` (``passive``) or
        the :class:`~symstab.numeric.simulation.simulated_limit.SimulatedLimit`
        (``simulated``).
    samples : ndarray
        Every evaluation, ``(k, len(over) + 1)``: the parameters' values,
        then the target (``-inf`` no stable point, NaN not resolved), in
        the order evaluated.
    spacing : dict
        ``{name: step}`` of the first scan (over the bracket of values where
        a stable point can be, for an affine parameter): a band of stable
        values narrower than this that holds no scan point can be missed.
    failed : tuple of (dict, str)
        The values the engine could not resolve, with its message.
    values : dict
        The other parameters' values, as given.
    message : str
        Why there is no optimum; else empty.
    delay : float or None
        The loop delay held in seconds while ``T`` varies (``d = delay /
        T`` samples at each value, a fraction of a period included), or
        None (``d`` as given).
    noise_limit : float or None
        The noise budget searched within, or None.
    encoder_resolution : float or None
        The encoder's quantum of the force noise, or None (no noise).
    noise_at : dict
        The rendered ``{x: value, y: value}`` where the noise is measured.
    noise : ndarray or None
        The force RMS at each row of :attr:`samples` (``inf`` where the
        rendered point is not stable), or None without an encoder.
    noise_samples : ndarray or None
        ``(k, len(over) + 1)``: every value where the noise was evaluated
        (the budget's scan and the bisection of its edges, and the
        samples), then the noise, in increasing values.
    """

    target: str
    x: str
    y: str
    over: dict
    best: object
    value: object
    nominal: dict
    value_nominal: object
    limits: object
    samples: np.ndarray
    spacing: dict
    failed: tuple = ()
    values: dict = dataclasses.field(default_factory=dict)
    message: str = ""
    delay: object = None
    noise_limit: object = None
    encoder_resolution: object = None
    noise_at: dict = dataclasses.field(default_factory=dict)
    noise: object = None
    noise_samples: object = None

    def plot(self, ax=None, **kwargs):
        """Draw the target at each value evaluated: :func:`symstab.drawing.plot_design`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        **kwargs
            ``target_label``: as in :func:`symstab.drawing.plot_design`.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_design

        return plot_design(self, ax, **kwargs)

    def plot_pareto(self, ax=None, **kwargs):
        """Draw the target against the force noise: :func:`symstab.drawing.plot_pareto`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        **kwargs
            ``target_label``, ``noise_label``: as in :func:`symstab.drawing.plot_pareto`.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_pareto

        return plot_pareto(self, ax, **kwargs)

    @property
    def best_d(self):
        """The delay in samples at the optimum: ``delay / T`` (fractional) where it is held in seconds."""
        if self.best is None:
            return None
        if self.delay is None:
            return self.values.get("d")
        return self.delay / self.best.get("T", self.values.get("T"))

    @property
    def gain(self):
        """:attr:`value` over :attr:`value_nominal`, where both are finite and positive; else None."""
        if self.value is None or self.value_nominal is None:
            return None
        if not (math.isfinite(self.value) and math.isfinite(self.value_nominal)
                and self.value_nominal > 0):
            return None
        return self.value / self.value_nominal

    @property
    def best_noise(self):
        """The force RMS at the optimum (None without an encoder or an optimum)."""
        if self.noise is None or self.best is None:
            return None
        key = tuple(self.best[name] for name in self.over)
        rows = np.flatnonzero((self.samples[:, :-1] == key).all(axis=1))
        return float(self.noise[rows[0]])

    @property
    def budget_binds(self):
        """Whether the optimum lies at the edge of the noise budget (its noise within 0.1 % of it).

        Then a larger budget (or a finer encoder) buys a larger target.
        """
        best = self.best_noise
        return (self.noise_limit is not None and best is not None
                and best >= (1 - 1e-3) * self.noise_limit)

    @property
    def pareto(self):
        """The values evaluated that no other beats on both counts: a higher target, less noise.

        Returns
        -------
        ndarray or None
            Rows ``(*values, target, noise)`` of :attr:`samples` whose
            target is finite and higher than that of every row with no more
            noise, in increasing noise (and target); None without an
            encoder.
        """
        if self.noise is None:
            return None
        rows = np.column_stack([self.samples, self.noise])
        rows = rows[np.isfinite(rows[:, -2]) & np.isfinite(rows[:, -1])]
        rows = rows[np.lexsort((-rows[:, -2], rows[:, -1]))]
        keep = []
        for row in rows:
            if not keep or row[-2] > keep[-1][-2]:
                keep.append(row)
        return np.array(keep, dtype=float).reshape(-1, self.samples.shape[1] + 1)

    @property
    def at_edge(self):
        """The searched parameters whose optimum lies within 1e-3 of the range's width of an end."""
        if self.best is None:
            return ()
        out = []
        for name, (lo, hi) in self.over.items():
            if min(self.best[name] - lo, hi - self.best[name]) < 1e-3 * (hi - lo):
                out.append(name)
        return tuple(out)

    def __repr__(self):
        over = ", ".join(f"{n} in [{lo:.6g}, {hi:.6g}]" for n, (lo, hi) in self.over.items())
        if self.best is None:
            return f"Design({self.target} over {over}: {self.message})"
        best = ", ".join(f"{n}={v:.6g}" for n, v in self.best.items())
        gain = f", gain {self.gain:.4g}" if self.gain is not None else ""
        held = ("" if self.delay is None else
                f", delay {self.delay:.6g} s = {self.best_d:.6g} samples")
        noise = "" if self.noise is None else f", force noise {self.best_noise:.4g}" + (
            "" if self.noise_limit is None else f" within {self.noise_limit:.4g}")
        return (f"Design({self.target} over {over}: {best}, {self.target}={self.value:.6g}"
                f"{held}{gain}{noise})")

    def as_dict(self):
        """The numbers, for tables and JSON."""
        return {"target": self.target, "x": self.x, "y": self.y,
                "over": {n: list(r) for n, r in self.over.items()}, "best": self.best,
                "value": self.value, "nominal": self.nominal,
                "value_nominal": self.value_nominal, "gain": self.gain,
                "evaluations": int(self.samples.shape[0]), "spacing": self.spacing,
                "failed": len(self.failed), "message": self.message, "delay": self.delay,
                "best_d": self.best_d, "noise_limit": self.noise_limit, "encoder_resolution": self.encoder_resolution,
                "noise_at": self.noise_at or None, "best_noise": self.best_noise}


class _Evaluations:
    """The target at points of the searched box, each evaluated once and remembered."""

    def __init__(self, f, progress):
        # Called directly by maximize_scalar and maximize_box: the total is
        # not known there, so True reports nothing (design draws a bar).
        self.f, self.progress = f, check_progress(progress)
        self.seen = {}

    def __call__(self, point):
        key = tuple(float(v) for v in np.atleast_1d(point))
        if key not in self.seen:
            self.seen[key] = float(self.f(key))
            if self.progress is not None:
                self.progress(len(self.seen))
        return self.seen[key]

    def best(self):
        """``(point, value)`` of the largest finite (or +inf) value seen, or None."""
        found = [(v, p) for p, v in self.seen.items() if not math.isnan(v) and v > -math.inf]
        if not found:
            return None
        value, point = max(found)
        return point, value

    def penalised(self, point):
        """The value to minimise: minus the target, and past the worst value where there is none."""
        value = self(point)
        if math.isnan(value) or value == -math.inf:
            finite = [v for v in self.seen.values() if math.isfinite(v)]
            worst = min(finite, default=0.0)
            return -(worst - abs(worst) - 1.0)
        return -value


def maximize_scalar(f, low, high, n=17, *, include=(), rtol=1e-6, progress=None):
    """The x of [low, high] that maximises a scalar ``f``: a scan, then Brent's method.

    ``f`` is evaluated on ``n`` evenly spaced points of ``[low, high]`` and
    at the values ``include`` that lie inside; a run of finite values that
    holds the best one and fewer than five points is scanned again between
    its infeasible neighbours (up to eight times).  The best point is then
    refined by :func:`scipy.optimize.minimize_scalar` (``method="bounded"``)
    between its neighbours, to ``rtol`` times the larger of ``|x|`` and the
    bracket's width; at an end of the range that ``f`` rises to (lower a
    thousandth of a step inside), the end is the maximum.

    Parameters
    ----------
    f : callable
        ``f(x) -> float``; ``-inf`` where there is nothing to maximise (no
        stable point), NaN where it could not be evaluated.
    low, high : float
        The interval searched, ``low < high``.
    n : int
        Points of the scan, ``n >= 3``.
    include : iterable of float
        Points evaluated with the scan (the nominal value).
    rtol : float
        Relative accuracy of the optimum, ``> 0``.
    progress : callable, optional
        Called with the number of evaluations so far.

    Returns
    -------
    (float, float, list) or (None, None, list)
        The best point seen and ``f`` there (None when ``f`` has no finite
        value at any point evaluated), and every evaluation ``[(x, f(x)), ...]``.

    Examples
    --------
    >>> x, value, _ = maximize_scalar(lambda x: -(x - 0.3)**2, 0.0, 1.0)
    >>> round(x, 5), value <= 0
    (0.3, True)
    """
    from scipy.optimize import minimize_scalar

    low, high = check_window("the interval searched", (low, high))
    n = check_count("n", n, 3)
    rtol = check_real("rtol", rtol, low=0.0, low_open=True)
    evaluate = _Evaluations(lambda p: f(p[0]), progress)
    xs = sorted(set(np.linspace(low, high, n).tolist())
                | {float(v) for v in include if low <= v <= high})
    for x in xs:
        evaluate(x)
    for _ in range(_MAX_ZOOMS):
        found = evaluate.best()
        if found is None or not math.isfinite(found[1]):
            break
        xs = sorted(p[0] for p in evaluate.seen)
        ok = [math.isfinite(evaluate.seen[(x,)]) for x in xs]
        k = xs.index(found[0][0])
        i, j = k, k
        while i > 0 and ok[i - 1]:
            i -= 1
        while j < len(xs) - 1 and ok[j + 1]:
            j += 1
        if j - i + 1 >= _MIN_RUN:
            break
        a, b = xs[max(i - 1, 0)], xs[min(j + 1, len(xs) - 1)]
        for x in np.linspace(a, b, n):
            evaluate(float(x))
    found = evaluate.best()
    if found is None:
        return None, None, [(p[0], v) for p, v in evaluate.seen.items()]
    (x_best,), value = found
    if math.isfinite(value):
        xs = sorted(p[0] for p in evaluate.seen)
        k = xs.index(x_best)
        a, b = xs[max(k - 1, 0)], xs[min(k + 1, len(xs) - 1)]
        if a < b and not _rising_to_end(evaluate, x_best, value, low, high, a, b):
            minimize_scalar(lambda x: evaluate.penalised(x), bounds=(a, b), method="bounded",
                            options={"xatol": rtol * max(abs(x_best), b - a),
                                     "maxiter": _MAX_REFINE})
        (x_best,), value = evaluate.best()
    return x_best, value, [(p[0], v) for p, v in evaluate.seen.items()]


def _rising_to_end(evaluate, x_best, value, low, high, a, b):
    """Whether the best point is an end of ``[low, high]`` that ``f`` rises to.

    Brent's bounded search never evaluates its ends: with the maximum at the
    end of the range (a target rising with a filter's cut-off), it creeps
    towards it by golden sections, 25 evaluations to reach ``rtol``, each a
    certified answer.  A point a thousandth of the neighbour's step inside
    the end, below it, shows the end is the local maximum there, as Brent
    would have found it (an interior maximum higher than the end, between
    the two, is a second local maximum, which Brent does not promise either).
    """
    if x_best not in (low, high):
        return False
    inside = x_best + (1e-3 if x_best == low else -1e-3) * (b - a)
    return evaluate(inside) < value


def maximize_box(f, box, n=9, *, include=(), rtol=1e-6, progress=None):
    """The point of a 2-D box that maximises ``f``: a grid, then Nelder-Mead with bounds.

    ``f`` is evaluated on an ``n x n`` grid of the box and at the points
    ``include`` inside it; while fewer than four grid points have a finite
    value, the grid is laid again over the box those points and their
    neighbours span (up to eight times).  The best point is refined by
    :func:`scipy.optimize.minimize` (``method="Nelder-Mead"``, bounded by
    the box) from a simplex one grid step wide, in coordinates scaled to the
    box, to ``rtol`` of the box's width.

    Parameters
    ----------
    f : callable
        ``f((u, v)) -> float``; ``-inf`` where there is nothing to maximise,
        NaN where it could not be evaluated.
    box : ((float, float), (float, float))
        The ranges of the two parameters.
    n : int
        Grid points per parameter, ``n >= 3``.
    include : iterable of (float, float)
        Points evaluated with the grid (the nominal values).
    rtol : float
        Relative accuracy of the optimum, ``> 0``.
    progress : callable, optional
        Called with the number of evaluations so far.

    Returns
    -------
    (tuple, float, list) or (None, None, list)
        As :func:`maximize_scalar`, with points ``(u, v)``.

    Examples
    --------
    >>> p, value, _ = maximize_box(lambda p: -(p[0] - 0.3)**2 - (p[1] + 1)**2,
    ...                            ((0.0, 1.0), (-2.0, 2.0)))
    >>> round(p[0], 4), round(p[1], 4)
    (0.3, -1.0)
    """
    from scipy.optimize import minimize

    (u0, u1), (v0, v1) = (check_window(f"box[{k}]", r) for k, r in enumerate(box))
    n = check_count("n", n, 3)
    rtol = check_real("rtol", rtol, low=0.0, low_open=True)
    evaluate = _Evaluations(f, progress)
    for p in include:
        if u0 <= p[0] <= u1 and v0 <= p[1] <= v1:
            evaluate((float(p[0]), float(p[1])))
    step = ((u1 - u0) / (n - 1), (v1 - v0) / (n - 1))
    grid = ((u0, u1), (v0, v1))
    for _ in range(_MAX_ZOOMS + 1):
        us, vs = np.linspace(*grid[0], n), np.linspace(*grid[1], n)
        for u in us:
            for v in vs:
                evaluate((float(u), float(v)))
        finite = [p for p in evaluate.seen if math.isfinite(evaluate.seen[p])]
        if len(finite) >= 4 or not finite:
            break
        du, dv = (us[1] - us[0]), (vs[1] - vs[0])
        pu, pv = [p[0] for p in finite], [p[1] for p in finite]
        grid = ((max(u0, min(pu) - du), min(u1, max(pu) + du)),
                (max(v0, min(pv) - dv), min(v1, max(pv) + dv)))
        if not (grid[0][0] < grid[0][1] and grid[1][0] < grid[1][1]):
            break
        step = ((grid[0][1] - grid[0][0]) / (n - 1), (grid[1][1] - grid[1][0]) / (n - 1))
    found = evaluate.best()
    if found is None:
        return None, None, list(evaluate.seen.items())
    point, value = found
    if math.isfinite(value):
        width = np.array([u1 - u0, v1 - v0])
        origin = np.array([u0, v0])
        start = (np.array(point) - origin) / width
        cell = np.array(step) / width

        def scaled(q):
            q = np.clip(q, 0.0, 1.0)
            return evaluate.penalised(tuple((origin + q * width).tolist()))

        simplex = np.array([start, start + [cell[0], 0.0], start + [0.0, cell[1]]])
        # A simplex vertex past the box is reflected inside it.
        simplex = np.where(simplex > 1.0, 2 * start - simplex, simplex).clip(0.0, 1.0)
        minimize(scaled, start, method="Nelder-Mead", bounds=[(0.0, 1.0), (0.0, 1.0)],
                 options={"initial_simplex": simplex, "xatol": rtol,
                          "fatol": rtol * abs(value) if value else rtol,
                          "maxfev": _MAX_REFINE})
        point, value = evaluate.best()
    return point, value, list(evaluate.seen.items())


def _check_over(loop, over, x, y):
    """``{name: (low, high)}``: one or two parameters of the loop, outside the plane."""
    if not isinstance(over, dict) or not 1 <= len(over) <= 2:
        raise TypeError(f"over must be a dict of one or two {{name: (low, high)}}, got {over!r}")
    out = {}
    others = [p for p in loop.parameters if p not in (x, y, "d")]
    for name, window in over.items():
        if name not in loop.parameters:
            raise ValueError(f"over: {name!r} is not a parameter of the loop (candidates: "
                             f"{', '.join(others)})")
        if name == "d":
            raise ValueError("over: the delay d is a whole number of samples; design once per delay")
        if name in (x, y):
            raise ValueError(f"over: {name} is an axis of the ({x}, {y}) plane; search another "
                             f"parameter (candidates: {', '.join(others)})")
        out[name] = check_window(f"over[{name!r}]", window)
    return out


def design(loop, *, over, maximize="y_max", x=None, y=None, n=None, rtol=None, damping="b",
           delay=None, progress=None, amplitude=None, nonideal=None, x0=None, steps=None,
           noise_limit=None, encoder_resolution=None, noise_at=None, **values):
    """The value of one or two parameters that maximises K_max, the Z-width, the passive K_max
    or the simulated K_max.

    Each evaluation of the linear targets is a certified answer at one
    value of the searched parameters (:meth:`symstab.Loop.limits`, or
    :meth:`symstab.Loop.passive_region` for ``maximize="passive"``); the simulated
    target is :func:`~symstab.numeric.simulation.simulated_limit.simulated_limit`
    (runs of :meth:`symstab.Loop.simulate` with the non-idealities given).  The
    search is a coarse scan, then
    ``scipy.optimize`` (the module says how, and what it can miss).

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    over : dict
        ``{name: (low, high)}``, one or two parameters outside the plane
        (not ``d``), e.g. ``{"M": (0.0, 0.04)}``.
    maximize : str
        ``"y_max"`` (the largest stable ``y``, K_max; also the plane's
        ``y`` by name, ``"K_max"`` in the ``(B, K)`` plane), ``"area"`` (the
        Z-width), ``"passive"`` (the passive K_max) or ``"simulated"``
        (the largest ``y`` whose simulated run neither grows nor ends
        above ``amplitude``).
    x, y : str, optional
        The plane (default: the loop's :attr:`~symstab.Loop.plane`;
        :meth:`symstab.Loop.design` resolves it).
    n : int, optional
        Scan points per parameter, ``>= 3`` (default 17 for one
        parameter, 9 for two).
    rtol : float, optional
        Relative accuracy of the optimum (default 1e-6; 1e-3 for
        ``"simulated"``, which is resolved to its grid).
    damping : str
        The device's viscous friction, for ``maximize="passive"``.
    delay : float, optional
        The loop delay in seconds, held while the sample period ``T``
        is searched: ``d = delay / T`` samples at each value, a
        fraction of a period included (instead of ``d``).
    progress : callable, optional
        Called with the number of evaluations so far.
    amplitude : float
        ``maximize="simulated"`` only (and needed there): the largest
        ``|x|`` accepted in the last quarter of a run (the position's
        unit).
    nonideal, x0, steps : optional
        ``maximize="simulated"`` only: as in :meth:`symstab.Loop.simulate` (``x0``
        default 1, or 0.01 with non-idealities, as ``symstab design``;
        ``steps`` is periods, so with ``delay`` and ``T`` searched a
        fixed ``steps`` is a shorter time at a smaller ``T``).
    noise_limit : float, optional
        A noise budget: the largest force RMS accepted
        (:func:`~symstab.numeric.analysis.noise.force_noise`, the force's
        unit) at the rendered point ``noise_at``; values of the one
        parameter searched whose noise exceeds it are not candidates (the
        edges of those that meet it are bisected to ``rtol`` before the
        search).  Needs ``encoder_resolution``.
    encoder_resolution : float, optional
        The encoder's quantum ``q`` (the position's unit), > 0.  Given
        alone, the force noise is recorded at every value evaluated
        (:attr:`Design.noise`, the front :attr:`Design.pareto`) without
        bounding it.
    noise_at : dict, optional
        ``{x: value, y: value}``: the environment rendered while the noise
        is measured (default: the loop's values of ``x`` and ``y``).  At a
        value where it is not stable the noise is unbounded.
    **values
        Single values of the other parameters; the searched ones' values
        here (or defaults) are the nominal point the gain is measured
        against.

    Returns
    -------
    symstab.numeric.analysis.design.Design

    Raises
    ------
    TypeError, ValueError
        For a parameter that is unknown, the delay, an axis of the
        plane, a range that is not ``(low, high)`` with ``low < high``,
        or an unknown target.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z) + M*(z - 1)**2/(T**2*z**2)",
    ...             plane=("B", "K"))
    >>> best = design(loop, x="B", y="K", over={"M": (0.0, 0.03)}, m=0.0128, b=0.0324,
    ...               T=1e-3, d=1, M=0.0, rtol=1e-3)
    >>> 0.006 < best.best["M"] < 0.02 and best.gain > 2
    True
    """
    if maximize == f"{y}_max":
        maximize = "y_max"      # K_max in the (B, K) plane
    if maximize not in TARGETS:
        raise ValueError(f"maximize must be one of {', '.join(map(repr, TARGETS))} (or "
                         f"{y}_max), got {maximize!r}")
    over = _check_over(loop, over, x, y)
    simulation = _check_simulation(maximize, amplitude, nonideal, x0, steps, loop)
    rtol = _RTOL.get(maximize, 1e-6) if rtol is None else rtol
    names = tuple(over)
    n = (17 if len(names) == 1 else 9) if n is None else check_count("n", n, 3)
    from ..._progress import progress_printer

    progress = check_progress(progress, lambda: progress_printer("designing", n**len(names) + 40))
    delay = _check_design_names(loop, maximize, x, y, damping, delay, values)
    merged = {**loop.defaults, **values}
    nominal = {name: float(merged[name]) for name in names if name in merged}
    if len(nominal) != len(names):
        nominal = {}

    def at(point):
        """The values at a point of the search; with ``delay``, d = delay / T there."""
        out = {**values, **dict(zip(names, point, strict=True))}
        if delay is not None:
            out["d"] = delay / out.get("T", loop.defaults.get("T"))
        return out

    budget = _check_budget(loop, x, y, names, noise_limit, encoder_resolution, noise_at, at)
    _check_values_once(loop, maximize, x, y, damping, over, at, simulation, steps)
    search = _Search(loop, maximize, x, y, damping, names, at, simulation)
    include = [tuple(nominal[n_] for n_ in names)] if nominal else []
    # Where a stable point can be at all: the searched box narrowed to it, or
    # proved empty (then nothing is scanned).
    bracket = _bracket(loop, maximize, x, y, names, over, at) if delay is None else over
    searched = over if bracket is None else bracket
    pieces = None if bracket is None else _budget_pieces(budget, searched, n, rtol,
                                                         include)
    best, value, seen = (None, None, []) if bracket is None or pieces == [] else _maximize_over(
        search.target, names, searched, n, include, rtol, progress, pieces)
    samples = np.array([[*p, v] for p, v in seen], dtype=float).reshape(-1, len(names) + 1)
    spacing = {k: (hi - lo) / (n - 1) for k, (lo, hi) in searched.items()}
    value_nominal = None
    if nominal:
        key = tuple(nominal[k] for k in names)
        hits = [v for p, v in seen if tuple(p) == key]
        value_nominal = hits[0] if hits else search.target(key)
        if value_nominal is not None and math.isnan(value_nominal):
            value_nominal = None
    common = dict(target=maximize, x=x, y=y, over=over, nominal=nominal,
                  value_nominal=value_nominal, samples=samples, spacing=spacing,
                  failed=tuple(search.failed), values=dict(values), delay=delay,
                  **({} if budget is None else budget.fields(samples)))
    if best is None:
        message = (_over_budget(budget, x, y, searched) if pieces == [] else
                   _not_found(maximize, simulation, x, y, over, searched, bracket, samples,
                              spacing, search.failed))
        return Design(best=None, value=None, limits=None, message=message, **common)
    return Design(best=dict(zip(names, (float(v) for v in best), strict=True)), value=float(value),
                  limits=search.answer(best), **common)


class _Search:
    """The target at a point of the search (NaN where the engine refused, with why).

    The best answer so far is kept (not every answer: each holds its
    decomposition): it is the Design's limits, and near a vanishing stable
    set one costs a second.
    """

    def __init__(self, loop, maximize, x, y, damping, names, at, simulation):
        self.ask = (loop, maximize, x, y, damping)
        self.names, self.at, self.simulation = names, at, simulation
        self.failed, self.kept = [], {}

    def answer(self, point):
        """The answer (Limits, PassiveRegion, SimulatedLimit) at ``point``."""
        key = tuple(float(v) for v in point)
        if key in self.kept:
            return self.kept[key][1]
        return _answer(*self.ask, self.at(key), self.simulation)

    def target(self, point):
        """The target's number at ``point``; NaN (and the reason kept) where refused."""
        try:
            found = self.answer(point)
            value = _target(self.ask[1], found)
            if not self.kept or value > next(iter(self.kept.values()))[0]:
                self.kept.clear()
                self.kept[tuple(float(v) for v in point)] = (value, found)
            return value
        except ValueError as exc:
            self.failed.append((dict(zip(self.names, point, strict=True)), str(exc)))
            return math.nan


def _check_budget(loop, x, y, names, noise_limit, encoder_resolution, noise_at, at):
    """The noise budget of a design (checked), or None without an encoder.

    ``encoder_resolution`` alone records the force noise at every value
    evaluated (the Pareto front); ``noise_limit`` also bounds it.  The
    noise is measured at the rendered point ``noise_at`` of the plane
    (default: the loop's values of ``x`` and ``y``).
    """
    if encoder_resolution is None:
        for name, given in (("noise_limit", noise_limit), ("noise_at", noise_at)):
            if given is not None:
                raise TypeError(f"{name} needs encoder_resolution: the encoder's quantum q (the "
                                f"position's unit), whose rounding error is the force noise")
        return None
    q = check_real("encoder_resolution", encoder_resolution, low=0.0, low_open=True)
    limit = math.inf if noise_limit is None else check_real("noise_limit", noise_limit, low=0.0,
                                                            low_open=True)
    if noise_limit is not None and len(names) != 1:
        raise ValueError(f"noise_limit: a noise budget is searched over one parameter (where the "
                         f"noise meets it is bracketed on a line), got {len(names)}: "
                         f"{', '.join(names)}")
    if noise_at is None:
        missing = [name for name in (x, y) if name not in loop.defaults]
        if missing:
            raise TypeError(f"the force noise is measured at a rendered point of the ({x}, {y}) "
                            f"plane, and the loop has no value of {' and '.join(missing)}: give "
                            f"noise_at={{{x!r}: ..., {y!r}: ...}}")
        noise_at = {x: loop.defaults[x], y: loop.defaults[y]}
    if not isinstance(noise_at, dict) or set(noise_at) != {x, y}:
        raise TypeError(f"noise_at must be a dict of the plane's two values, {{{x!r}: ..., "
                        f"{y!r}: ...}}, got {noise_at!r}")
    rendered = {name: check_real(f"noise_at[{name!r}]", noise_at[name]) for name in (x, y)}
    return _Budget(loop, q, limit, rendered, at)


class _Budget:
    """The force noise at the rendered point for each value searched, against a limit.

    :func:`~symstab.numeric.analysis.noise.force_noise_rms` of the loop at the
    values of the search's point and the rendered ``(x, y)``: ``inf`` where
    the rendered point is not stable (no budget is met there).
    """

    def __init__(self, loop, q, limit, rendered, at):
        self.loop, self.q, self.limit, self.rendered, self.at = loop, q, limit, rendered, at
        self.seen, self.step = {}, 0.0

    def __call__(self, point):
        """The force RMS at ``point`` of the search (remembered)."""
        from .noise import force_noise_rms

        key = tuple(float(v) for v in point)
        if key not in self.seen:
            self.seen[key] = force_noise_rms(self.loop, self.q, {**self.at(key), **self.rendered})
        return self.seen[key]

    def meets(self, x):
        """Whether the noise at the one parameter's value ``x`` is within the limit."""
        return self((x,)) <= self.limit

    def pieces(self, pieces, n, rtol, include=()):
        """The parts of each piece of the line where the noise meets the limit.

        Each piece is scanned at ``n`` points and at the values ``include``
        inside it (the nominal value); where two neighbours differ, the
        edge is bisected to ``rtol`` of the piece's width (and of ``|x|``).
        A part narrower than that is the one value ``(a, a)``.  A part
        narrower than a scan step between two points over the limit is not
        seen: :attr:`step` is the scan's, for the message.
        """
        out = []
        for a, b in pieces:
            xs = sorted(set(np.linspace(a, b, n).tolist())
                        | {float(v) for v in include if a <= v <= b})
            self.step = max(self.step, (b - a) / (n - 1))
            ok = [self.meets(x) for x in xs]
            tol = rtol * max(abs(a), abs(b), b - a)
            left = None
            for k, x in enumerate(xs):
                if ok[k] and left is None:
                    left = a if k == 0 else self._edge(x, xs[k - 1], tol)
                if ok[k] and (k == len(xs) - 1 or not ok[k + 1]):
                    right = b if k == len(xs) - 1 else self._edge(x, xs[k + 1], tol)
                    out.append((left, right))
                    left = None
        return out

    def _edge(self, good, bad, tol):
        """The last value from ``good`` (within the limit) towards ``bad`` (over it) that meets it."""
        while abs(bad - good) > tol:
            middle = 0.5 * (good + bad)
            good, bad = (middle, bad) if self.meets(middle) else (good, middle)
        return good

    def fields(self, samples):
        """The :class:`Design`'s fields of the budget, its noise at each of ``samples``."""
        scan = sorted(self.seen.items())
        return dict(noise_limit=None if math.isinf(self.limit) else self.limit,
                    encoder_resolution=self.q, noise_at=dict(self.rendered),
                    noise=np.array([self(row[:-1]) for row in samples], dtype=float),
                    noise_samples=np.array([[*p, v] for p, v in scan], dtype=float).reshape(
                        len(scan), samples.shape[1]))


def _budget_pieces(budget, searched, n, rtol, include):
    """The pieces of the line within the noise budget (``[]``: none), or None without a limit."""
    if budget is None or math.isinf(budget.limit):
        return None
    (name, window), = searched.items()
    return budget.pieces([window], n, rtol, [p[0] for p in include])


def _over_budget(budget, x, y, searched):
    """The message of a design none of whose values scanned meets the noise budget."""
    (name, (lo, hi)), = searched.items()
    rendered = ", ".join(f"{k} = {v:.6g}" for k, v in budget.rendered.items())
    (where,), least = min(budget.seen.items(), key=lambda item: item[1])
    between = (f"; between them (steps of {budget.step:.3g}) the range was not examined: a band "
               f"narrower than a step may meet it (give a finer n)")
    if math.isinf(least):
        return (f"no value of {name} in [{lo:.6g}, {hi:.6g}] meets the noise budget: the "
                f"rendered point {rendered} is not stable at any of the {len(budget.seen)} "
                f"values evaluated, so its force noise is unbounded there{between}")
    return (f"no value of {name} in [{lo:.6g}, {hi:.6g}] evaluated meets the noise budget "
            f"{budget.limit:.6g}: the least force noise at {rendered} of the "
            f"{len(budget.seen)} values evaluated is {least:.6g} (at {name} = {where:.6g})"
            f"{between}")


def _check_design_names(loop, maximize, x, y, damping, delay, values):
    """The delay in seconds (checked, or None): the plane's and the damping's names are the loop's.

    A step of :func:`design`'s input checks: the axes take no value, and a
    delay is given in seconds (``delay``, or the loop's ``Td`` among
    ``values``, taken out of them here, or the loop's default ``Td``) or
    in samples, once.
    """
    for axis, name in (("x", x), ("y", y)) + ((("damping", damping),) if maximize == "passive"
                                                 else ()):
        if name not in loop.parameters:
            need = (": maximize='passive' needs the device's viscous friction"
                    if axis == "damping" else "")
            raise ValueError(f"{axis}: {name!r} is not a parameter of the loop{need} "
                             f"(parameters: {', '.join(loop.parameters)})")
    for name in (x, y):
        if name in values:
            raise TypeError(f"{name} is an axis of the ({x}, {y}) plane: it takes no value here")
    if "Td" in values:
        if delay is not None:
            raise TypeError("give the delay in seconds once: delay or Td, not both")
        delay = values.pop("Td")
    if delay is None and "d" not in values and "Td" in loop.defaults:
        delay = loop.defaults["Td"]     # the loop's own delay is in seconds
    if delay is not None:
        delay = check_real("delay", delay, low=0.0)
        if "d" in values:
            raise TypeError("give the delay in seconds (delay) or in samples (d), not both")
    return delay


def _check_values_once(loop, maximize, x, y, damping, over, at, simulation, steps):
    """The values asked of the loop once, at the box's middle (and its corners), before the scan.

    A wrong value is then the caller's error, not a value of the searched
    parameter without an answer: the polynomial at the middle, the
    passivity theorem's plant with ``maximize="passive"``, and the
    simulation's horizon at every corner's delay (held in seconds, ``d``
    varies with ``T``).
    """
    middle = tuple(0.5 * (lo + hi) for lo, hi in over.values())
    loop.polynomial(**{**at(middle), x: 0.0, y: 0.0})
    if maximize == "passive":
        # A plant the passivity theorem does not cover is refused here, once.
        loop.passive_region(x, y, damping=damping, **at(middle))
    if simulation:
        from ..simulation.simulator import check_steps

        for corner in box_corners(over):
            held = at(tuple(corner.values())).get("d", loop.defaults.get("d", 0))
            check_steps(steps, math.ceil(held))


def _maximize_over(target, names, searched, n, include, rtol, progress, pieces=None):
    """``(best, value, seen)``: the search of ``target`` over ``searched``, points as tuples.

    Two parameters: :func:`maximize_box`.  One: :func:`maximize_scalar`
    over the range, or over ``pieces`` (the parts of the range within a
    noise budget) :func:`_maximize_line`.
    """
    if len(names) == 2:
        return maximize_box(target, tuple(searched[k] for k in names), n,
                            include=include, rtol=rtol, progress=progress)
    if pieces is None:
        best, value, seen = maximize_scalar(lambda v: target((v,)), *searched[names[0]], n,
                                            include=[p[0] for p in include], rtol=rtol,
                                            progress=progress)
    else:
        best, value, seen = _maximize_line(lambda v: target((v,)), pieces, n,
                                           [p[0] for p in include], rtol, progress)
    best = None if best is None else (best,)
    return best, value, [((p,), v) for p, v in seen]


def _maximize_line(f, pieces, n, include, rtol, progress):
    """The best ``f`` over closed pieces of a line (a piece ``(a, a)`` is the one value ``a``).

    ``f`` is one continuous function cut into parts (by a noise budget),
    each searched by :func:`maximize_scalar` with ``n`` points
    (``_PIECE_POINTS`` at least each when there are several).  A one-value
    piece is evaluated.
    """
    seen = {}

    def counted(x):
        if x not in seen:
            seen[x] = f(x)
            if progress is not None:
                progress(len(seen))
        return seen[x]

    wide = [(a, b) for a, b in pieces if a < b]
    for a, b in pieces:
        if a == b:
            counted(a)
    points = n if len(wide) == 1 else max(_PIECE_POINTS, n // max(len(wide), 1))
    for a, b in wide:
        maximize_scalar(counted, a, b, points,
                        include=[v for v in include if a <= v <= b], rtol=rtol)
    found = [(v, x) for x, v in seen.items() if not math.isnan(v) and v > -math.inf]
    if not found:
        return None, None, list(seen.items())
    value, best = max(found)
    return best, value, list(seen.items())


def _not_found(maximize, simulation, x, y, over, searched, bracket, samples, spacing, failed):
    """The message of a design that found no point: proved (Stodola) or not seen on the scan.

    Raises
    ------
    ValueError
        If the target could not be computed at any value searched (none
        was merely without a point).
    """
    if failed and not np.any(samples[:, -1] == -np.inf):
        what = {"passive": "passive set", "simulated": "simulated limit"}.get(maximize, "limits")
        raise ValueError(f"the {what} could not "
                         f"be computed at any of the {len(samples)} values searched: "
                         f"{failed[0][1]}")
    ranges = ", ".join(f"{k} in [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in over.items())
    what = {"passive": "passive point",
            "simulated": f"point whose simulated run settles below "
                         f"{simulation.get('amplitude', 0):.3g}"}.get(maximize, "stable point")
    if bracket is None:
        return (f"no value of {ranges} has a {what} in the ({x}, {y}) plane: proved "
                f"(Stodola's necessary condition, the coefficients of (w - 1)**n "
                f"chi((w + 1)/(w - 1)) all of one sign, holds nowhere in the range)")
    # Only the values evaluated are known: a band of them narrower than
    # the scan's step can lie between two.
    inside = ", ".join(f"{k} in [{lo:.6g}, {hi:.6g}]" for k, (lo, hi) in searched.items())
    narrowed = (f"; outside {inside} none is stable (Stodola's necessary condition)"
                if searched != over else "")
    return (f"no {what} in the ({x}, {y}) plane was found at the {len(samples)} "
            f"values of {inside} evaluated (steps of "
            f"{', '.join(f'{s:.3g}' for s in spacing.values())}){narrowed}; between "
            f"them the range was not examined: a band of values narrower than a step "
            f"may hold one (give a finer n)")


def _bracket(loop, maximize, x, y, names, over, at):
    """``over`` narrowed to where a stable point can be, or None when it can be nowhere.

    Where the searched parameters enter the characteristic polynomial affinely
    with the plane's (a virtual mass, say), Stodola's necessary condition is
    linear in all of them (:func:`symstab.numeric.engine.decomposition.stable_ranges`):
    a narrow band of stable values inside a wide range is bracketed before
    the scan instead of stepped over, and a range where the condition holds
    nowhere is proved to have no stable point.  Elsewhere (a sample period, a
    filter's cut-off, the passive target) ``over`` as given.
    """
    from ..engine.decomposition import stable_ranges

    if maximize == "passive" or not loop.affine_in((x, y, *names)):
        return over
    try:
        base, slopes, _ = loop.affine_parts((x, y), at(tuple(0.0 for _ in names)))
        rows = [base, *slopes]
        for k in range(len(names)):
            unit = at(tuple(float(j == k) for j in range(len(names))))
            rows.append(loop.affine_parts((x, y), unit)[0] - base)
    except ValueError:
        return over         # 0 or 1 is not a value of the parameter: no bracket
    ranges = stable_ranges(rows, [None, None, *over.values()])
    if ranges is None:
        return None
    out = {}
    for name, (lo, hi), (low, high) in zip(names, ranges[2:], over.values(), strict=True):
        # Wider than the programme's ends by more than its tolerance (never
        # past the range).
        pad = 1e-6 * (high - low)
        lo, hi = max(low, lo - pad), min(high, hi + pad)
        out[name] = (lo, hi) if lo < hi else (low, high)
    return out


def _check_simulation(maximize, amplitude, nonideal, x0, steps, loop=None):
    """The simulation's settings of ``maximize="simulated"`` (checked), else ``{}``."""
    given = {k: v for k, v in (("amplitude", amplitude), ("nonideal", nonideal), ("x0", x0),
                               ("steps", steps)) if v is not None}
    if maximize != "simulated":
        if given:
            raise TypeError(f"{', '.join(given)}: only with maximize='simulated' (the other "
                            f"targets are certified, not simulated)")
        return {}
    from ..simulation.simulator import check_loop_nonideal, check_x0, default_x0

    if amplitude is None:
        raise TypeError("maximize='simulated' needs amplitude: the largest |x| accepted at the "
                        "end of a run (the position's unit)")
    nonideal = check_loop_nonideal(nonideal, loop)
    return {"amplitude": check_real("amplitude", amplitude, low=0.0, low_open=True),
            "nonideal": nonideal, "x0": default_x0(nonideal) if x0 is None else check_x0(x0),
            "steps": steps}


def box_corners(over):
    """``[{name: value}, ...]``: the corners of the box ``{name: (low, high)}`` searched."""
    corners = [{}]
    for name, ends in over.items():
        corners = [{**c, name: v} for c in corners for v in ends]
    return corners


def _answer(loop, maximize, x, y, damping, values, simulation):
    """The answer whose number is the target: Limits, PassiveRegion or SimulatedLimit."""
    if maximize == "simulated":
        from ..simulation.simulated_limit import simulated_limit

        return simulated_limit(loop, x=x, y=y, **simulation, **values)
    if maximize == "passive":
        return loop.passive_region(x, y, damping=damping, **values)
    return loop.limits(x, y, **values)


def _target(maximize, answer):
    """The target's number of an answer; ``-inf`` where no point is stable (passive)."""
    if answer.y_max is None:
        return -math.inf
    return float(answer.area if maximize == "area" else answer.y_max)
