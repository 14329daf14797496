"""The largest y a loop renders in simulation: the simulated counterpart of ``Limits.y_max``.

:func:`simulated_limit` asks the question a design by simulation asks (the
target ``maximize="simulated"`` of :meth:`symstab.Loop.design`): with the
non-idealities given (encoder quantization, a force limit), what is the
largest stiffness ``y`` at which the simulated loop neither grows nor
settles into a limit cycle above a stated amplitude?

A run is *accepted* when the simulator calls it bounded (stable or a limit
cycle: not diverged, not growing, :attr:`Simulation.bounded
<symstab.Simulation.bounded>`) **and** the largest ``|x|`` of its last quarter is
at most ``amplitude``.  A slow decay still above ``amplitude`` at the end
of the run is not accepted: the run is too short to call it settled.

The search runs in the window of the loop's certified stable set (the
linear :meth:`symstab.Loop.limits` of the same loop, which the
non-idealities perturb): ``x`` over the set's extent, ``y`` from 0 to 1.25
times its ``y_max``, with the ``x`` of the linear ``y_max`` among the grid's.  A grid of ``n_x x n_y`` runs first; then, in the
columns whose top accepted cell is the highest, the bracket between that
cell and the next is divided into nine, ``refine`` times, all columns in one
run each.  The answer is the top of an accepted run found, refined to
:attr:`SimulatedLimit.resolution`; an accepted band narrower than a grid
step that no grid point hits can be missed.

The refinement step is not the answer's accuracy.  Near the limit the loop
decays slowly and the quantization keeps limit cycles of a few counts, so
whether a run ends below the amplitude changes from one ``y`` to the next
(a ragged edge): for the paper's device at d = 5 with its encoder and ten
counts, the top accepted ``K`` of nearby columns and cut-offs differs by
about 1 %.  Compare simulated limits to that accuracy.
"""

import dataclasses
import math

import numpy as np

from ..._validate import check_count, check_progress, check_real

__all__ = ["SimulatedLimit", "simulated_limit"]

#: The window's top over the linear y_max: room for a non-ideality that
#: stabilises (a force limit bounds an unstable loop).
_TOP = 1.25
#: Sub-points per bracket in each refinement round.
_SECTIONS = 8


@dataclasses.dataclass(frozen=True)
class SimulatedLimit:
    """What :func:`simulated_limit` found.

    Attributes
    ----------
    x, y : str
        The plane.
    y_max : float or None
        The largest ``y`` of an accepted run (None when no run is
        accepted, :attr:`reason` says why).
    x_at_y_max : float or None
        The ``x`` of that run.
    amplitude : float
        The largest ``|x|`` accepted in the run's last quarter.
    x0 : float
        The runs' initial position.
    nonideal : Nonidealities
        The runs' non-idealities.
    linear : Limits
        The certified limits of the loop without non-idealities: the window.
    resolution : float
        The step in ``y`` of the last refinement.
    runs : int
        Points simulated.
    steps : int
        Periods of each run.
    at_top : bool
        A run at the window's top (1.25 times the linear ``y_max``) was
        accepted: the simulated limit may lie above the window.
    reason : str
        Why there is no answer; else empty.
    """

    x: str
    y: str
    y_max: object
    x_at_y_max: object
    amplitude: float
    x0: float
    nonideal: object
    linear: object
    resolution: object
    runs: int
    steps: int
    at_top: bool = False
    reason: str = ""

    @property
    def area(self):
        """The linear stable set's area (the simulated target measures ``y`` only)."""
        return self.linear.area

    def __repr__(self):
        if self.y_max is None:
            return f"SimulatedLimit({self.x}, {self.y}: {self.reason})"
        return (f"SimulatedLimit({self.x}, {self.y}: {self.y}_max={self.y_max:.6g} at "
                f"{self.x}={self.x_at_y_max:.6g} (linear {self.linear.y_max:.6g}), "
                f"amplitude <= {self.amplitude:.3g}, {self.runs} runs)")


def simulated_limit(loop, *, x=None, y=None, amplitude, nonideal=None, steps=None, x0=None,
                    n=(12, 16), refine=3, progress=None, **values):
    """The largest ``y`` at which the simulated loop neither grows nor ends above ``amplitude``.

    The simulated counterpart of :meth:`symstab.Loop.limits`' ``y_max``,
    with the non-idealities the linear model leaves out (encoder
    quantization, a force limit, Coulomb friction): runs of
    :meth:`symstab.Loop.simulate` on a grid over the certified stable set,
    refined in ``y`` (the module says how, and how accurate it is).  Not
    certified.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x, y : str, optional
        The plane, ``y`` the stiffness (default: the loop's
        :attr:`~symstab.Loop.plane`).
    amplitude : float
        The largest ``|x|`` (the position's unit) accepted in the last
        quarter of a run, ``> 0``: a limit cycle above it, or a decay not
        below it by the end, is not accepted.
    nonideal : symstab.numeric.paper.simulate.Nonidealities, optional
        Encoder quantization and force limit (:func:`~symstab.numeric.simulation.simulator.simulate_loop`).
    steps, x0 : optional
        As in :meth:`symstab.Loop.simulate`; ``x0`` default 1, or 0.01 with
        non-idealities (:func:`~symstab.numeric.simulation.simulator.default_x0`, as
        the command line), from which ``amplitude`` is reached.
    n : (int, int)
        The first grid's points in ``x`` and ``y``, each ``>= 3`` (the ``x`` of
        the linear ``y_max`` is added to the grid in ``x``).
    refine : int
        Refinement rounds (each divides the step in ``y`` by nine), ``>= 0``.
    progress : callable, bool or None, optional
        Called with the runs done so far (one per grid or round); True draws
        a bar (``symstab._validate.check_progress``).
    **values
        Single values of the loop's other parameters.

    Returns
    -------
    SimulatedLimit

    Raises
    ------
    TypeError, ValueError
        As :meth:`symstab.Loop.simulate` and :meth:`symstab.Loop.limits`,
        and for an ``amplitude`` that is not a positive number or a linear
        stable set unbounded in ``x``.

    Examples
    --------
    >>> from symstab import Loop
    >>> from symstab.numeric.paper.simulate import Nonidealities
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
    >>> found = simulated_limit(loop, x="B", y="K", amplitude=1e-3, steps=3000,
    ...                         nonideal=Nonidealities(encoder_resolution=1e-5),
    ...                         m=0.0128, b=0.0324, T=1e-3, d=1)
    >>> 0.9 * found.linear.y_max < found.y_max < found.linear.y_max
    True
    """
    from .simulator import check_loop_nonideal, check_x0, default_x0

    x, y = loop.plane_of(x, y)
    amplitude = check_real("amplitude", amplitude, low=0.0, low_open=True)
    nonideal = check_loop_nonideal(nonideal, loop)
    x0 = default_x0(nonideal) if x0 is None else check_x0(x0)
    n_x, n_y = _grid_size(n)
    refine = check_count("refine", refine, 0)
    from ..._progress import progress_printer

    # A run per grid and per refinement round.
    progress = check_progress(progress, lambda: progress_printer("simulating", 1 + refine))
    for name in (x, y):
        if name in values:
            raise TypeError(f"{name} is an axis of the ({x}, {y}) plane: it takes no value here")
    linear = loop.limits(x, y, **values)
    common = dict(x=x, y=y, amplitude=amplitude, x0=x0, nonideal=nonideal, linear=linear)
    if linear.y_max is None or not linear.y_max > 0:
        why = linear.reason or f"its largest stable {y} is {linear.y_max:.6g}, not above 0"
        return SimulatedLimit(y_max=None, x_at_y_max=None, resolution=None, runs=0, steps=0,
                              reason=f"the linear loop has no stable point with {y} > 0: {why}",
                              **common)
    if not (math.isfinite(linear.x_min) and math.isfinite(linear.x_max)
            and math.isfinite(linear.y_max)):
        raise ValueError(f"the stable set of the linear loop is unbounded ({x} in "
                         f"[{linear.x_min:.6g}, {linear.x_max:.6g}], {y}_max = "
                         f"{linear.y_max:.6g}): the simulation needs a bounded window")
    # The column of the linear y_max is one of the grid's: the simulated limit
    # is compared with the linear one at the same x.
    xs = np.union1d(np.linspace(linear.x_min, linear.x_max, n_x),
                    [linear.x_at_y_max] if math.isfinite(linear.x_at_y_max) else [])
    n_x = xs.size
    ys = np.linspace(0.0, _TOP * linear.y_max, n_y)
    count = {"runs": 0, "points": 0, "steps": 0}

    def accepted(x_points, y_points):
        run = loop.simulate(steps=steps, x0=x0, nonideal=nonideal,
                            **{x: x_points, y: y_points}, **values)
        count["runs"] += 1
        count["points"] += x_points.size
        count["steps"] = run.steps
        if progress is not None:
            progress(count["runs"])
        return np.asarray(run.bounded & (run.amplitude[3] <= amplitude))

    Y, X = np.meshgrid(ys, xs, indexing="ij")
    grid = accepted(X.ravel(), Y.ravel()).reshape(n_y, n_x)
    columns = np.flatnonzero(grid.any(axis=0))
    if not columns.size:
        return SimulatedLimit(y_max=None, x_at_y_max=None, resolution=ys[1] - ys[0],
                              runs=count["points"], steps=count["steps"],
                              reason=f"no run of the {n_x} x {n_y} grid over the linear "
                                     f"stable set is accepted (each grew, or its last "
                                     f"quarter's |x| exceeded {amplitude:.3g})", **common)
    top = np.array([np.flatnonzero(grid[:, j]).max() for j in columns])
    highest = top.max()
    at_top = bool(highest == n_y - 1)
    # Only the columns whose top accepted cell is the highest can hold the
    # answer: another's bracket ends below where these begin.
    columns = columns[top == highest]
    low = np.full(columns.size, ys[highest])
    step = ys[1] - ys[0]
    if not at_top:
        for _ in range(refine):
            step /= _SECTIONS + 1
            offsets = step * np.arange(1, _SECTIONS + 1)
            Ys = low[:, None] + offsets[None, :]
            ok = accepted(np.repeat(xs[columns], _SECTIONS), Ys.ravel()).reshape(Ys.shape)
            # The new bracket starts at the highest accepted sub-point.
            for i in range(columns.size):
                hits = np.flatnonzero(ok[i])
                if hits.size:
                    low[i] = Ys[i, hits.max()]
    best = int(np.argmax(low))
    return SimulatedLimit(y_max=float(low[best]), x_at_y_max=float(xs[columns[best]]),
                          resolution=float(step), runs=count["points"], steps=count["steps"],
                          at_top=at_top, **common)


def _grid_size(n):
    """``(n_x, n_y)`` of ``n`` (one int for both, or a pair), each ``>= 3``."""
    if isinstance(n, (tuple, list)) and len(n) == 2:
        return check_count("n[0]", n[0], 3), check_count("n[1]", n[1], 3)
    try:
        size = check_count("n", n, 3)
    except TypeError:
        raise TypeError(f"n must be an integer >= 3 or a pair of them, got {n!r}") from None
    return size, size
