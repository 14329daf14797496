"""The loop simulator: any :class:`symstab.Loop` in time, many parameter points at once.

Every period ``T`` the position is sampled, the virtual environment's
difference equation computes a force from the sampled positions, the force
waits ``d`` samples in the delay line, and a zero-order hold applies it to
the plant, stepped exactly on the samples by its pulse transfer function
``P(z)`` (derived by the loop), or on its continuous state space
(:mod:`symstab.numeric.simulation.friction`) where Coulomb friction acts inside the
period or the run starts from a state.  All points run together as NumPy
arrays, one loop over time; :func:`run_loop` is the engine,
:func:`simulate_loop` and :func:`loop_stability_map` run a loop
(:meth:`symstab.Loop.simulate`, :meth:`symstab.Loop.stability_map`), and
the paper's simulator (:mod:`symstab.numeric.paper.simulate`) runs the paper's
loop through :func:`simulate_loop` (its friction compensation, start from
the device's state and overflow rule are options of every loop's run).

A loop's run starts from positions ``x0 - k v0`` before the start (or
from its driven mass's state, ``start="state"``), no
force and the environment at rest at the sampled ``x0``, with an empty
delay line; its verdict is unstable when the largest ``|x|`` over the last
quarter of the horizon exceeds that over the quarter before and a floor
that quantization can reach (:attr:`Simulation.floor`), or the state
overflows; a run with non-idealities that keeps swinging above the floor,
neither decaying nor growing, is a limit cycle (:attr:`Simulation.limit_cycle`),
neither stable nor unstable; its theory is its own root count.
"""

import dataclasses
import functools
import math

import numpy as np

from ..._progress import progress_printer
from ..._resources import MAX_DELAY_ENV, MAX_STEPS_ENV, check_memory, chunk_slices
from ..._resources import max_delay as _max_delay
from ..._resources import max_steps as _max_steps_setting
from ..._validate import (
    DELAY_RTOL,
    check_array,
    check_count,
    check_delay,
    check_grid,
    check_progress,
    check_real,
    snap_delay,
)
from ..engine.results import PAPER_PLANE, PaperGridNames
from .friction import StatePlant, stacked_spaces, substeps_of

__all__ = ["Nonidealities", "FrictionCompensation", "Simulation", "StabilityMap",
           "default_horizon", "check_steps", "check_x0", "max_steps", "progress_printer",
           "PAPER_ENCODER_RESOLUTION", "MAX_STEPS_ENV", "run_loop", "simulate_loop",
           "loop_stability_map", "check_loop_nonideal", "default_x0", "MAX_SUBSTEPS", "X0_MIN",
           "X0_MAX", "check_friction_size", "QUANTUM_MIN", "FRICTION_STEP_MAX",
           "delay_sequence", "DELAY_LAWS", "shared_fraction"]


#: The most sub-steps per period: each multiplies the simulation's time (a
#: billion once hung it), and friction's stick and reversal times, which they
#: resolve, are first order in ``1/substeps``: a thousand is far past any use.
MAX_SUBSTEPS = 1000

#: The paper's encoder: better than 3 arc seconds after quadrature and gear
#: train (Section VI), in rad.
PAPER_ENCODER_RESOLUTION = math.radians(3 / 3600)
#: ``|x|`` above this is divergence: the run stops for that point.
_OVERFLOW = 1e100
#: Periods between overflow checks.
_CHECK_EVERY = 8
#: A limit cycle's swing over the last quarter stays within this fraction of
#: the third's.  Its sampled peaks differ by up to 2e-4 between quarters (the
#: paper's loop saturated at 0.05 N m, d = 10); a linear mode changes by this
#: much over a quarter only within about 2e-6 of |z| = 1 at the default
#: horizon, the band that no finite run decides.
_SUSTAINED = 1e-2
#: A swing below this fraction of the amplitude is rounding, not motion: a
#: mass settling off zero at K = 0 keeps a swing of 1e-11 of its position.
_MOVING = 1e-8
#: Allowed size of the initial state.  The verdict compares the largest ``|x|``
#: of the last two quarters and calls ``|x| > _OVERFLOW`` divergence: a start at
#: zero never moves (0 <= 0 reads as stable), and a stable point needs room
#: above ``|x0|`` for its transient before the overflow threshold (50 orders of
#: magnitude), as a decaying or growing run needs room below it before
#: subnormal numbers lose the ratio (about 200 orders down to 1e-308).
X0_MIN = 1e-100
#: The largest allowed size of the initial state (see ``X0_MIN``).
X0_MAX = _OVERFLOW * 1e-50


@dataclasses.dataclass(frozen=True)
class Nonidealities:
    """Departures from the ideal loop, in physical units; ``None``/False is off.

    Attributes
    ----------
    encoder_resolution : float
        Position quantum (m or rad), at least :data:`QUANTUM_MIN`, the
        smallest normal double: the positions are divided by it, and a
        subnormal quantum overflows every quotient (a value whose quotient
        overflows is far above the quantum's precision and rounds to
        itself).
    velocity_cutoff : float
        Cut-off of the velocity filter (Hz), in (0, Nyquist): the paper's
        simulator's, whose adapter writes the filter into the paper's
        loop's environment (a loop file writes it into its own).
    coulomb_friction : float
        Coulomb friction force (N or N m), >= 0, and small enough that its
        change of the state over a sub-step is a double
        (:func:`check_friction_size`, checked against the loop's plant
        before a run).
    stiction : float
        Breakaway force (N or N m), >= coulomb_friction (default: equal).
    friction_compensation : bool
        Add ``coulomb_friction * sign(v_hat)`` to the command, ``v_hat``
        the loop simulator's velocity estimate from the sampled position
        (any loop with Coulomb friction, :func:`simulate_loop`): the
        backward difference, ``FrictionCompensation(coulomb_friction,
        pole=0)``, unless the run's ``compensation=`` option gives the
        estimate's filter pole (the paper's simulator,
        :func:`symstab.numeric.paper.simulate.simulate`, gives its velocity
        filter's).
    actuator_bandwidth : float
        First-order lag of the applied force (Hz), > 0: the paper's
        simulator's, whose adapter writes the lag into the paper's loop's
        plant (a loop file writes it into its own).
    substeps : int
        Sub-steps per period, 1 to :data:`MAX_SUBSTEPS`: friction is
        decided at their ends (the actuator lag is exact at any number).
    force_limit : float
        Largest force command (N or N m), > 0: the command is clipped to it.
    force_resolution : float
        Force quantum (N or N m), at least :data:`QUANTUM_MIN`: the command
        is rounded to a multiple of it (a DAC's step), then clipped to
        ``force_limit``.
    """

    encoder_resolution: float = None
    velocity_cutoff: float = None
    coulomb_friction: float = None
    stiction: float = None
    friction_compensation: bool = False
    actuator_bandwidth: float = None
    substeps: int = 20
    force_limit: float = None
    force_resolution: float = None

    def __post_init__(self):
        # Checked at construction, so that a wrong kind never reaches a run:
        # friction_compensation="no" would otherwise switch compensation on.
        if self.encoder_resolution is not None:
            _check_quantum("encoder_resolution", self.encoder_resolution, "positions")
        if self.velocity_cutoff is not None:
            check_real("velocity_cutoff", self.velocity_cutoff, low=0.0, low_open=True)
        if self.coulomb_friction is not None:
            check_real("coulomb_friction", self.coulomb_friction, low=0.0)
        if self.stiction is not None:
            if self.coulomb_friction is None:
                raise ValueError("stiction needs coulomb_friction")
            check_real("stiction", self.stiction, low=self.coulomb_friction)
        if not isinstance(self.friction_compensation, (bool, np.bool_)):
            raise TypeError(f"friction_compensation must be True or False, "
                            f"got {type(self.friction_compensation).__name__} "
                            f"{self.friction_compensation!r}")
        if self.friction_compensation and self.coulomb_friction is None:
            raise ValueError("friction_compensation needs coulomb_friction")
        if self.actuator_bandwidth is not None:
            check_real("actuator_bandwidth", self.actuator_bandwidth, low=0.0, low_open=True)
        if self.force_limit is not None:
            check_real("force_limit", self.force_limit, low=0.0, low_open=True)
        if self.force_resolution is not None:
            _check_quantum("force_resolution", self.force_resolution, "force commands")
            if self.coulomb_friction is not None:
                # The verdict's floor for the quantum bounds the linear loop's response.
                raise ValueError("force_resolution with coulomb_friction: the verdict allows "
                                 "a force quantum's limit cycle by a bound on the linear "
                                 "loop's response, which friction does not have; simulate "
                                 "them one at a time")
        if isinstance(self.substeps, (bool, np.bool_)) or \
                not isinstance(self.substeps, (int, np.integer)):
            raise TypeError(f"substeps must be an integer >= 1, got "
                            f"{type(self.substeps).__name__} {self.substeps!r}")
        if not 1 <= self.substeps <= MAX_SUBSTEPS:
            raise ValueError(f"substeps must be an integer from 1 to {MAX_SUBSTEPS}, "
                             f"got {self.substeps!r}")

    def check(self, T):
        """Validate against the sample period ``T``; raise ValueError naming the field.

        The fields themselves are checked at construction; what depends on
        ``T`` is the velocity filter's cut-off, below the Nyquist frequency.

        Parameters
        ----------
        T : float
            The sample period (s).

        Raises
        ------
        ValueError
            Naming ``velocity_cutoff`` and its range when it is not below ``0.5 / T``.
        """
        if self.velocity_cutoff is not None:
            check_real("velocity_cutoff", self.velocity_cutoff, low=0.0, low_open=True,
                       high=0.5 / T, high_open=True)

    @property
    def ideal(self):
        return (self.encoder_resolution is None and self.velocity_cutoff is None
                and self.coulomb_friction is None and self.actuator_bandwidth is None
                and self.force_limit is None and self.force_resolution is None)


@dataclasses.dataclass(frozen=True)
class FrictionCompensation:
    """The loop simulator's friction compensation: the command adds ``coulomb * sign(v_hat)``.

    ``v_hat`` is the simulator's velocity estimate from the sampled (quantized)
    position, ``v_hat[k] = pole v_hat[k-1] + (1 - pole) (x_s[k] - x_s[k-1])``,
    a position change per period (its sign is all that counts): the backward
    difference at ``pole = 0``, low-pass filtered otherwise.  An option of
    :func:`simulate_loop` and :func:`run_loop`;
    ``Nonidealities(friction_compensation=True)`` is
    ``FrictionCompensation(coulomb_friction)`` where the option is not
    given (the paper's simulator gives it, with the pole of its velocity
    filter).

    Attributes
    ----------
    coulomb : float
        The force added (the loop's force unit), finite and >= 0.
    pole : float
        The estimate's low-pass pole, ``0 <= pole < 1`` (default 0).
    """

    coulomb: float
    pole: float = 0.0

    def __post_init__(self):
        check_real("compensation.coulomb", self.coulomb, low=0.0)
        check_real("compensation.pole", self.pole, low=0.0, high=1.0, high_open=True)



#: The smallest quantum (encoder or force): the smallest normal double.
QUANTUM_MIN = float(np.finfo(float).tiny)
#: The largest change of the state the friction may make over a sub-step:
#: below double precision's largest number (1.8e308) with room to add it to
#: the rest of the step.
FRICTION_STEP_MAX = 1e300


def _check_quantum(name, quantum, divided):
    """Check a quantum: a finite double of at least :data:`QUANTUM_MIN` (ValueError naming it).

    The run divides the values it rounds by the quantum.  A subnormal
    quantum (1e-320) keeps fewer than 53 significant bits and overflows
    every such quotient above 1.8e-12: each run diverged.  From a normal
    quantum on, a quotient that overflows is of a value the quantum is far
    below the precision of, which rounding leaves as it is
    (:func:`_rounded`).
    """
    check_real(name, quantum, low=0.0, low_open=True)
    if not quantum >= QUANTUM_MIN:
        raise ValueError(f"{name} must be a finite real number >= {QUANTUM_MIN!r} (the smallest "
                         f"normal double: below it the quantum loses its significant bits and "
                         f"the {divided} divided by it overflow), got {quantum!r}")


def _rounded(values, quantum):
    """``values`` rounded to multiples of ``quantum``; as they are where the quotient overflows.

    (A quotient that overflows is of a value whose precision the quantum
    is far below: its own multiple to the last bit.)
    """
    out = np.empty_like(values)
    with np.errstate(over="ignore", invalid="ignore"):
        _round_into(out, values, quantum)
    return out


def _round_into(out, values, quantum):
    """``out[...] =`` :func:`_rounded` ``(values, quantum)``, for a caller that ignores overflow.

    The run's loop (:func:`_run`) sets NumPy's error state once for all its
    periods: entering it again in every period cost a fifth of a run's time.
    (``np.rint`` is ``np.round`` to no decimals, without its dispatch.)
    """
    np.divide(values, quantum, out=out)
    np.rint(out, out=out)
    np.multiply(out, quantum, out=out)
    finite = np.isfinite(out)
    if np.count_nonzero(finite) != finite.size:     # (all(): four times the time)
        np.copyto(out, values, where=~finite)


def check_friction_size(nonideal, spaces, name="nonideal.coulomb_friction", scale=1.0):
    """Refuse a Coulomb friction larger than double precision can step on the plants ``spaces``.

    A sub-step adds ``-gamma_f F`` to the state (:mod:`symstab.numeric.simulation.friction`); the friction is refused when its largest entry would pass
    :data:`FRICTION_STEP_MAX`, from where adding it overflows and a held
    mass reads as diverged.  Below it any friction is stepped: a large one
    stops the mass within the sub-step where it stands.

    Parameters
    ----------
    nonideal : Nonidealities
        In the units of the spaces.
    spaces : list of FrictionSpace
    name : str
        The friction's name in the message (the CLI's ``--coulomb``).
    scale : float
        The spaces' unit of force over the caller's (the message gives the
        caller's).

    Raises
    ------
    ValueError
        Naming ``name`` and its range on these plants.
    """
    friction = nonideal.coulomb_friction
    if not friction:
        return
    largest = max(float(np.max(np.abs(space.gamma_f))) for space in spaces)
    if largest > 0 and friction * largest > FRICTION_STEP_MAX:
        limit = FRICTION_STEP_MAX / largest / scale
        raise ValueError(f"{name} must be a real number from 0 to {limit:.3g} on this plant (a "
                         f"sub-step changes its state by up to {largest * scale:.3g} per unit "
                         f"of friction, and double precision steps a change up to "
                         f"{FRICTION_STEP_MAX:g}), got {friction / scale:g}")


def default_horizon(d):
    """Periods simulated by default: long enough for the slow modes near the boundary.

    ``12000 + 800 d``: on the paper's 100 x 100 grids (d in 0..10, eight
    virtual masses) every cell that no boundary curve crosses then gets the
    exact verdict; with ``4000 + 400 d`` six cells whose slowest mode grows
    by 1e-4 to 5e-4 per period still looked stable.  Slower growth needs a
    longer horizon.
    """
    return 12000 + 800 * check_delay(d)


def default_x0(nonideal):
    """The initial position when none is given: 1, or 0.01 with non-idealities.

    A quantized or saturated run starts within a few hundred encoder counts
    of the paper's (0.01 rad is 688 of its 3 arc-second counts), where its
    limit cycles are seen; an ideal loop is linear, so any start will do.
    """
    return 1.0 if nonideal is None or nonideal.ideal else 0.01


def check_x0(x0):
    """Return the initial position ``x0`` as a float in ``X0_MIN <= |x0| <= X0_MAX``.

    Raises
    ------
    TypeError, ValueError
        Naming ``x0`` and the range.
    """
    x0 = check_real("x0", x0)
    if not X0_MIN <= abs(x0) <= X0_MAX:
        raise ValueError(f"x0 must be a finite real number with {X0_MIN:g} <= |x0| <= {X0_MAX:g} "
                         f"(the verdict compares amplitudes and calls |x| > {_OVERFLOW:g} "
                         f"divergence), got {x0!r}")
    return x0


def check_steps(steps, d):
    """Return ``steps`` (None: :func:`default_horizon` of ``d``) as an int from 8 to :func:`max_steps`.

    Raises
    ------
    ValueError
        Naming ``steps``, the range and the variable that raises the limit.
    """
    steps = default_horizon(d) if steps is None else steps
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 8:
        raise ValueError(f"steps must be an integer >= 8, got {steps!r}")
    steps = int(steps)
    limit = max_steps(d)
    if steps > limit:
        raise ValueError(f"steps must be an integer from 8 to {limit}, got {steps} (about "
                         f"{steps * 3e-5 / 3600:.2g} hours per point; raise the limit with "
                         f"{MAX_STEPS_ENV})")
    return steps


#: The random laws of a varying delay (:func:`delay_sequence`).
DELAY_LAWS = ("uniform",)


def delay_sequence(delays, steps=None, seed=None):
    """The delay of every period of a run whose delay varies, checked: ``(sequence, steps)``.

    Parameters
    ----------
    delays : array_like of int or tuple
        The delay of each period in whole samples, a 1-D array of ``steps``
        entries from 0 to ``SYMSTAB_MAX_DELAY``; or ``("uniform", d_min,
        d_max)``: each period's delay drawn independently, uniform on the
        whole samples ``d_min .. d_max`` (both included), by
        ``numpy.random.default_rng(seed)``.
    steps : int, optional
        Periods (default: the array's length, or :func:`default_horizon`
        of ``d_max`` for a random sequence).
    seed : int, optional
        The random sequence's seed, >= 0 (default 0: the same run each
        time); only with a random sequence.

    Returns
    -------
    (ndarray of int64, int)
        The ``(steps,)`` delays and ``steps``.

    Raises
    ------
    TypeError, ValueError
        Naming ``delays``, ``steps`` or ``seed`` and the allowed values.
    """
    if isinstance(delays, tuple) and delays and isinstance(delays[0], str):
        if delays[0] not in DELAY_LAWS or len(delays) != 3:
            raise ValueError(f"delays must be ('uniform', d_min, d_max) or an array of whole "
                             f"samples, got {delays!r}")
        d_min, d_max = (check_delay(bound, name=f"{name} of delays")
                        for name, bound in zip(("d_min", "d_max"), delays[1:], strict=True))
        if d_min > d_max:
            raise ValueError(f"delays: d_min must be at most d_max, got {d_min} > {d_max}")
        steps = check_steps(steps, d_max)
        seed = 0 if seed is None else check_count("seed", seed, 0)
        check_memory(f"the delays of {steps} periods", 8 * steps)
        return np.random.default_rng(seed).integers(d_min, d_max + 1, size=steps), steps
    if seed is not None:
        raise ValueError("seed draws a random delay sequence: give delays=('uniform', d_min, "
                         "d_max), or drop seed")
    if isinstance(delays, (str, bytes, dict)):
        raise TypeError(f"delays must be an array of whole samples or ('uniform', d_min, d_max), "
                        f"got {type(delays).__name__}")
    sequence = check_array("delays", delays, low=0.0)
    if sequence.ndim != 1 or sequence.size < 8:
        raise ValueError(f"delays must be a 1-D array of at least 8 delays, one a period, got "
                         f"shape {sequence.shape}")
    whole = np.floor(sequence) == sequence
    limit = _max_delay()
    if not whole.all() or sequence.max() > limit:
        first = int(np.flatnonzero(~whole | (sequence > limit))[0])
        raise ValueError(f"delays must be whole samples from 0 to {limit} (raise the limit with "
                         f"{MAX_DELAY_ENV}), got {sequence[first]!r} (entry {first})")
    steps = check_steps(sequence.size if steps is None else steps, int(sequence.max()))
    if steps != sequence.size:
        raise ValueError(f"delays must have one delay a period: steps = {steps} periods, got "
                         f"{sequence.size} delays")
    return sequence.astype(np.int64), steps


def max_steps(d):
    """The largest ``steps`` accepted at delay ``d``.

    ``SYMSTAB_MAX_STEPS`` (default 10 million), or :func:`default_horizon`
    of ``d`` when that is longer.
    """
    return max(_max_steps_setting(), default_horizon(d))


@dataclasses.dataclass(frozen=True)
class Simulation:
    """What a run returns.

    Attributes
    ----------
    positions : ndarray or None
        ``(steps + 1, *shape)`` positions (with ``record=True``).
    amplitude : ndarray
        ``(4, *shape)``: the largest ``|x|`` in each quarter of the run.
    diverged : ndarray of bool
        The state overflowed (``|x| > 1e100``).
    stable : ndarray of bool
        Not diverged, not a limit cycle, and the last quarter's amplitude
        does not exceed the third's or the floor (see the module docstring).
    steps : int
    floor : ndarray
        The amplitude up to which a run counts as bounded whatever it does:
        four encoder counts, plus, with a force quantum, half the quantum
        times the l1 norm of the linear loop's pulse response where the
        linear loop is stable (the most its rounding can move the position).
    limit_cycle : ndarray of bool
        A run with non-idealities that keeps swinging, neither decaying nor
        growing, above the floor: a bounded limit cycle (a saturated
        unstable loop's), neither stable nor unstable.  Never set for the
        ideal loop, which is linear.
    delays : ndarray of int or float, or None
        ``(steps,)``: the delay of every period in samples where it varied
        (:func:`simulate_loop`'s ``delays``; the drawn sequence where it was
        random; floats with their shared fraction of a period); None for a
        fixed delay.
    """

    positions: object
    amplitude: np.ndarray
    diverged: np.ndarray
    stable: np.ndarray
    steps: int
    floor: np.ndarray
    limit_cycle: np.ndarray
    delays: object = None

    def plot(self, ax=None, *, T=None):
        """Draw the recorded positions: :func:`symstab.drawing.plot_simulation`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        T : float, optional
            The sample period in s: time in seconds (default: samples).

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_simulation

        return plot_simulation(self, ax, T=T)

    @property
    def bounded(self):
        """Stable or a limit cycle: the runs that neither grow nor diverge."""
        return self.stable | self.limit_cycle

    def __repr__(self):
        stable = np.asarray(self.stable)
        n_stable, n_diverged = int(np.count_nonzero(stable)), int(np.count_nonzero(self.diverged))
        n_cycles = int(np.count_nonzero(self.limit_cycle))
        size = f"{stable.size} point{'s' if stable.size != 1 else ''}"
        if stable.ndim > 1:
            size += " (" + " x ".join(map(str, stable.shape)) + ")"
        recorded = ", positions recorded" if self.positions is not None else ""
        if self.delays is not None:
            recorded += (f", delay per period from {int(np.min(self.delays))} to "
                         f"{int(np.max(self.delays))} samples")
        cycles = f"{n_cycles} limit cycle{'s' if n_cycles != 1 else ''}, " if n_cycles else ""
        n_unstable = stable.size - n_stable - n_cycles
        return (f"Simulation({size}, {self.steps} steps: {n_stable} stable, {cycles}"
                f"{n_unstable} unstable of which {n_diverged} diverged{recorded})")


def _run_chunks(make_run, n_points, point_bytes, *, steps, d, record, progress, nonideal, shape,
                pulse_of=None):
    """Run ``n_points`` in chunks of about :data:`~symstab._resources.CHUNK_BYTES`; the :class:`Simulation`.

    The driver of every run: ``make_run(part)`` builds the state of the
    points ``part`` (an :class:`_AnyLoop`) of ``point_bytes`` each.  Recording keeps every position, so it runs in
    one chunk and its memory is checked first.  ``pulse_of(part)``, with
    a force quantum: the linear loop's response to a unit force pulse at
    the points of ``part`` it bounds (an :class:`_AnyLoop` or None), whose
    l1 norm over the run sets their verdict's floor (``_verdict``).
    """
    if record:
        check_memory(f"recording {steps} periods of {n_points} point(s) at d = {d}",
                     8 * (steps + 1) * n_points + point_bytes * n_points)
    else:
        # The chunks bound the working set; what stays is the result.
        check_memory(f"simulating {n_points} point(s)", 8 * 11 * n_points)
    chunks = [slice(0, n_points)] if record else chunk_slices(n_points, point_bytes)
    amplitude, swing = np.zeros((4, n_points)), np.zeros((4, n_points))
    diverged = np.zeros(n_points, dtype=bool)
    positions = np.empty((steps + 1, n_points)) if record else None
    response = np.zeros(n_points) if pulse_of is not None else None
    report = max(1, steps // 100)
    # Each chunk runs once, or twice with the pulse response: the bar counts runs.
    n_runs = len(chunks) * (1 if pulse_of is None else 2)
    for number, part in enumerate(chunks):
        run = make_run(part)
        # Recorded positions must never hold an overflowed value: check every period then.
        run.check_every = 1 if record else _CHECK_EVERY
        runs_done = number * (n_runs // len(chunks))
        _run(run, steps, amplitude[:, part], None if positions is None else positions[:, part],
             progress, report, runs_done, n_runs, swing=swing[:, part])
        diverged[part] = run.diverged
        run = None          # the pulse response's chunk takes its place
        if pulse_of is not None:
            response[part] = _pulse_l1(pulse_of(part), steps, progress, report, runs_done + 1,
                                       n_runs)
    return _verdict(amplitude, swing, diverged, positions, shape, steps, nonideal, response)


def _pulse_l1(pulse, steps, progress, report, chunk, n_chunks):
    """``sum_{k=1}^{steps} |h[k]|`` of a pulse response run ``(run, points)``, at every point of the chunk.

    ``points`` (bool) are those of the chunk that ``run`` holds; the
    others get 0.
    """
    run, points = pulse
    out = np.zeros(points.size)
    if run is None:
        if progress is not None:
            progress(((chunk + 1) * steps) // n_chunks)
        return out
    total = np.zeros(run.x.size)
    with np.errstate(over="ignore", invalid="ignore"):
        _run(run, steps, np.zeros((4, run.x.size)), None, progress, report, chunk, n_chunks,
             total=total)
    # A point whose response overflowed has no bound: it keeps no floor.
    out[points] = np.where(run.diverged, 0.0, total)
    return out


def _run(run, steps, amplitude, positions, progress, report, chunk, n_chunks, total=None,
         swing=None):
    """Advance ``run`` ``steps`` periods, keeping the largest |x| of each quarter.

    ``progress`` hears the steps done over all chunks, scaled to ``steps``;
    ``total``, if given, accumulates ``|x|`` of every period after the start;
    ``swing``, if given, gets each quarter's half range of ``x`` (half of
    its largest less its smallest value).  The run advances in blocks
    (:meth:`_AnyLoop.advance`) that end at each quarter's end (and at every
    period when it records: a diverged point's positions are zero from the
    period it is found in).
    """
    if positions is not None:
        positions[0] = run.x
    # The signed extremes of each quarter: the largest |x| and the swing (a
    # limit cycle keeps its swing; a mass held off zero keeps |x| with none).
    high, low = np.full((4, run.size), -np.inf), np.full((4, run.size), np.inf)
    magnitude = np.empty(run.size) if total is not None else None
    extreme = np.empty(run.size)
    every = run.check_every
    # A period of a run that records, sums and reports nothing is its step
    # and its extremes only (d = 0 and 1: a period is a few microseconds).
    plain = total is None and positions is None and progress is None
    maximum, minimum = np.maximum, np.minimum
    # One error state for every period (run.advance() counts on it); the
    # quarters' rows as views made once, not in every period.
    with np.errstate(over="ignore", invalid="ignore"):
        for q, (start, stop) in enumerate(_quarters(steps)):
            high_q, low_q = high[q], low[q]
            if plain and run.block == 1:
                run.advance_each(stop - start, high_q, low_q)
                continue
            k = start
            while k < stop:
                count = min(run.block, stop - k) if every > 1 else 1
                run.advance(count)
                if count == 1:
                    x = run.x
                    maximum(high_q, x, out=high_q)
                    minimum(low_q, x, out=low_q)
                    if plain:
                        k += 1
                        continue
                    block = x[None]
                else:
                    block = run.positions
                    np.maximum(high_q, np.maximum.reduce(block, axis=0, out=extreme), out=high_q)
                    np.minimum(low_q, np.minimum.reduce(block, axis=0, out=extreme), out=low_q)
                if total is not None:
                    for x in block:      # in order: the sum is the same to the last bit
                        np.abs(x, out=magnitude)
                        total += magnitude
                if positions is not None:
                    positions[k + 1:k + 1 + count] = block
                if progress is not None:
                    for done in range(k + 1, k + count + 1):
                        if done % report == 0 or done == steps:
                            progress((chunk * steps + done) // n_chunks)
                k += count
        run.freeze_diverged()
    with np.errstate(invalid="ignore"):
        np.maximum(high, -low, out=amplitude)
        if swing is not None:
            np.multiply(high - low, 0.5, out=swing)


def _quarters(steps):
    """``(start, stop)`` of each quarter's periods: ``k // (steps // 4)``, the last open-ended."""
    quarter = steps // 4      # steps >= 8 (check_steps)
    return [(q * quarter, (q + 1) * quarter if q < 3 else steps) for q in range(4)]


@dataclasses.dataclass(frozen=True)
class StabilityMap(PaperGridNames):
    """Stability by simulation on a grid of the ``(x, y)`` plane.

    Attributes
    ----------
    y_values, x_values : ndarray
        The 1-D grids.
    stable : ndarray of bool
        Shape ``(len(y_values), len(x_values))``.
    limit_cycle : ndarray of bool
        Same shape: the cells whose run settles into a bounded limit cycle
        (:attr:`Simulation.limit_cycle`), neither stable nor growing.
    growth : ndarray
        Last quarter's amplitude over the third's (``inf`` when diverged).
    steps : int
        Periods simulated.
    x, y : str
        The plane (``"beta"``, ``"alpha"``: the paper's, Table I's variables).
    at : dict
        The other parameters' values (the paper's ``gamma``, ``d``, ``delta``).

    Notes
    -----
    In the paper's plane ``alpha`` and ``beta`` are aliases of the grids and
    ``gamma``, ``d``, ``delta`` of :attr:`at`, as in
    :class:`~symstab.numeric.engine.results.Limits`.
    """

    y_values: np.ndarray
    x_values: np.ndarray
    stable: np.ndarray
    limit_cycle: np.ndarray
    growth: np.ndarray
    steps: int
    x: str = PAPER_PLANE[0]
    y: str = PAPER_PLANE[1]
    at: dict = dataclasses.field(default_factory=dict)

    def plot(self, ax=None, *, boundary=None):
        """Draw the map, a boundary over it if given: :func:`symstab.drawing.plot_map`.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Where to draw (default: a new figure's axes).
        boundary : symstab.numeric.engine.results.Boundary, optional
            The loop's D-decomposition in the map's plane, drawn over it.

        Returns
        -------
        symstab.drawing.Plot
            Its ``figure``, ``axes`` and ``artists``.
        """
        from ...drawing import plot_map

        return plot_map(self, ax, boundary=boundary)



# --------------------------------------------------------------------------
# Any loop: its plant's pulse transfer function and its environment, stepped


#: Floats held per point besides the delay line, the histories and the
#: blocks: the velocity estimate, the extremes and a few more.
_ANY_LOOP_FLOATS = 8
#: Buffers of rows in time (:class:`_AnyLoop`): the positions, samples,
#: forces and commands (each with its spare rows; two temporaries have a
#: block's).
_BUFFERS = 4
#: The most periods a block runs (:meth:`_AnyLoop.advance`): past a few
#: dozen, the Python work per block is a small part of a period's.
_BLOCK_MAX = 32
#: The most bytes of a block's rows of one signal: a block of many points
#: that outgrows the processor's cache runs slower than one period at a
#: time (whose NumPy calls cost little beside the arithmetic then).
_BLOCK_BYTES = 256 * 1024


def _spare_rows(block):
    """Rows of a buffer after its past: a few blocks, or 16 periods (moved back when full)."""
    return max(4 * block, 16)


def _block_rows(d, n_points=1):
    """Periods a block of ``n_points`` of a loop with delay ``d`` runs: ``d``, from 1 to
    :data:`_BLOCK_MAX`, and rows of at most :data:`_BLOCK_BYTES`."""
    return max(1, min(d, _BLOCK_MAX, _BLOCK_BYTES // (8 * n_points)))


def simulate_loop(loop, *, steps=None, x0=1.0, v0=None, nonideal=None, record=False,
                  progress=None, compensation=None, start="samples", overflow="raise",
                  delays=None, seed=None, **values):
    """Run a :class:`symstab.Loop` in time for every parameter point at once.

    The plant's exact ZOH step on the samples, the environment's difference
    equation and the delay line; stable when the last quarter of the run
    does not outgrow the third (:func:`simulate`'s verdict).

    The plant is its exact ZOH step on the samples: the difference equation
    of ``P(z) = Z[ZOH G] = P_n / P_d``, whose coefficients the loop derives
    (by residues, or the matrix exponential at 30 digits where there is no
    closed form), ``P_d(z) y = P_n(z) u``.  The environment is its
    difference equation ``Ve_d(z) f = Ve_n(z) x_s`` on the sampled position
    ``x_s``, and the force waits ``d`` samples: ``u[k] = -f[k - d]``, the
    loop whose characteristic polynomial is ``chi = z**d Ve_d P_d + Ve_n
    P_n`` (:meth:`symstab.Loop.polynomial`).  The run starts from the
    position ``x0``, earlier positions ``x0 - k v0`` (``start="samples"``)
    or the driven mass's velocity ``v0 / T`` (``start="state"``), the
    sampled history at ``x0``, no force and an empty delay line; the
    verdict is :func:`simulate`'s.  The difference equations are computed a
    chunk of points at a time, so the working memory does not grow with
    the points (only the result does).

    Non-idealities (:class:`Nonidealities`, physical units):
    ``encoder_resolution`` rounds the sampled position, ``force_resolution``
    rounds the force command to its quantum and ``force_limit`` clips it (a
    saturated unstable loop may settle into a bounded limit cycle, which the
    verdict calls a limit cycle, :attr:`Simulation.limit_cycle`, neither
    stable nor growing; a quantized one, where the linear
    loop is stable, is bounded up to :attr:`Simulation.floor`, the most the
    rounding can move it).  ``coulomb_friction`` (with ``stiction``
    and ``substeps``) acts on the loop's driven mass, after its
    :attr:`~symstab.Loop.actuator`: the plant is then stepped on its
    continuous state space, ``substeps`` exact sub-steps a period, with the
    paper's simulator's stick and reversal rules
    (:mod:`symstab.numeric.simulation.friction`).  ``friction_compensation``
    adds ``coulomb_friction * sign(v_hat)`` to the command, ``v_hat`` the
    simulator's own velocity estimate, the backward difference of the
    sampled position (:class:`FrictionCompensation` with ``pole = 0``),
    unless ``compensation`` is given.  A velocity filter or an actuator lag
    is part of a loop's own environment or plant.

    The delay may vary from period to period by whole samples
    (``delays``): the plant's input at period ``k`` is then ``-f[k -
    delta_k]``, the force computed ``delta_k`` periods earlier (one of the
    last ``d_max + 1``), run one period at a time.  The sequence is the
    delay: ``d`` and ``Td`` are not given (the loop's default is unused);
    a fraction of a period all its delays share is the plant's (the
    modified z-transform, as a fixed fractional delay's), and a delay that
    varies inside a sample is not modelled.  A random sequence
    is drawn once for the run and every point runs it, so that the points
    of a map differ by their parameters only, not by their draws (and the
    sequence is the result's :attr:`Simulation.delays`; for independent
    draws, run each point with its own ``seed``).  Non-idealities are
    those of a fixed delay but the force quantum, whose verdict floor is
    the fixed-delay loop's pulse response.

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    steps : int, optional
        Periods (default: 12000 + 800 d).
    x0, v0 : float
        Initial position and its change per period (default ``x0 / 100``).
    nonideal : Nonidealities, optional
        Encoder quantization, force saturation, and Coulomb friction on
        the driven mass (after :attr:`~symstab.Loop.actuator`) with its
        compensation: only the fields above (and ``substeps``).
    record : bool
        Keep every position.
    progress : callable, optional
        Called with the number of steps done.
    compensation : FrictionCompensation, optional
        Add ``coulomb * sign(v_hat)`` to every force command, ``v_hat`` the
        simulator's velocity estimate low-pass filtered with the option's
        pole (:class:`FrictionCompensation`).  Default: off, or with
        ``nonideal.friction_compensation`` the backward difference's
        ``FrictionCompensation(nonideal.coulomb_friction)``; given, it is
        the compensation either way (the paper's simulator gives the pole
        of its velocity filter).
    start : {"samples", "state"}
        Where the plant starts: its sampled history ``x0 - k v0``, ``k = 0,
        1, ...`` with no force (default), or the driven mass's state, the
        position ``x0`` and the velocity ``v0 / T`` with the rest of the
        plant at rest, the plant then stepped on its state space (needs a
        driven mass, :meth:`symstab.Loop.driven_mass`, and one ``T``).
    overflow : {"raise", "diverge"}
        A point whose difference equations overflow double precision (``K
        = 1e308``) is refused before the run (default), or run as a point
        that diverges at once (the paper's simulator).
    delays : array_like of int or tuple, optional
        A delay that varies (see above): the delay of every period in whole
        samples, a 1-D array of ``steps`` entries (the same for every
        point); or ``("uniform", d_min, d_max)``, each period's delay
        uniform on the whole samples ``d_min .. d_max``
        (:func:`delay_sequence`).  Each may share a fraction of a period
        (``("uniform", 2.5, 4.5)``, :func:`shared_fraction`): carried by the
        plant, as a fixed delay's.  Default None: the fixed delay ``d``.
    seed : int, optional
        The random sequence's seed (default 0); only with ``("uniform",
        ...)``.
    **values
        The loop's parameters (or their defaults); arrays broadcast, ``d``
        one number of samples (whole or not) or ``Td`` seconds, neither
        with ``delays``.

    Returns
    -------
    Simulation
        Of the broadcast shape of the values.

    Raises
    ------
    TypeError, ValueError
        For a value of the wrong kind or out of range, a non-ideality a
        general loop does not have, a plant with direct feed-through (its
        ``P_n`` as high as ``P_d``: the sampled position would depend on the
        force of the same instant), or a run that does not fit in memory.

    Examples
    --------
    >>> from symstab import Loop
    >>> loop = Loop("1/(m*s**2 + b*s)", "K + B*(z - 1)/(T*z)")
    >>> run = simulate_loop(loop, K=[100.0, 3000.0], B=0.5, m=0.0128, b=0.0324, T=1e-3, d=1,
    ...                     steps=4000)
    >>> run.stable.tolist()
    [True, False]
    """
    nonideal = check_loop_nonideal(nonideal, loop)
    compensation = _compensation_of(nonideal, compensation)
    if start not in ("samples", "state"):
        raise ValueError(f"start must be 'samples' or 'state', got {start!r}")
    if overflow not in ("raise", "diverge"):
        raise ValueError(f"overflow must be 'raise' or 'diverge', got {overflow!r}")
    check_progress(progress)   # a wrong kind is refused before the work
    fraction = 0.0
    if delays is not None:
        delays, steps, values, fraction = _varying_delay(delays, steps, seed, nonideal, values)
    elif seed is not None:
        raise ValueError("seed draws a random delay sequence: give delays=('uniform', d_min, "
                         "d_max), or drop seed")
    parts_of, d, shape, parts_floats, period = _parts_by_chunk(loop, values, overflow)
    steps = check_steps(steps, d)
    progress = check_progress(progress, lambda: progress_printer("simulating", steps))
    x0 = check_x0(x0)
    v0 = x0 / 100 if v0 is None else check_real("v0", v0, low=-X0_MAX, high=X0_MAX)
    spaces = state = None
    if start == "state":
        if np.ndim(period):
            raise ValueError(f"start='state' needs one sample period T (the velocity is v0 / T), "
                             f"got T of shape {np.shape(period)}")
        _check_driven_mass(loop, "start='state'")
        state = (x0, v0 / float(period))
    if nonideal.coulomb_friction is not None or state is not None:
        spaces, inverse = loop.friction_spaces(substeps_of(nonideal), **values)
        check_friction_size(nonideal, spaces)
        spaces = (spaces, inverse.ravel())
    run = run_loop(parts_of, int(np.prod(shape)), d=d, steps=steps, x0=x0, v0=v0,
                   nonideal=nonideal, record=record, progress=progress, shape=shape,
                   spaces=spaces, state=state, parts_floats=parts_floats,
                   compensation=compensation, delays=delays,
                   linear_stable=linearly_stable(loop, nonideal, values, shape))
    return run if not fraction else dataclasses.replace(run, delays=run.delays + fraction)


def _varying_delay(delays, steps, seed, nonideal, values):
    """``(sequence, steps, values, fraction)`` of a run whose delay varies.

    The sequence in whole samples; the values with ``d = d_max`` plus the
    fraction of a period every delay shares (:func:`shared_fraction`): the
    whole ``d_max`` sizes the buffers, the fraction is the plant's, as a
    fixed delay's is.
    """
    given = [name for name in ("d", "Td") if name in values]
    if given:
        raise TypeError(f"give the delay once: {given[0]} (a fixed delay) or delays (one a "
                        f"period, a fraction of a period in each: 2.5, 3.5, ...), not both")
    if nonideal.force_resolution is not None:
        raise ValueError("nonideal.force_resolution with delays: the verdict's floor for a force "
                         "quantum is the fixed-delay loop's pulse response; simulate a varying "
                         "delay without it")
    delays, fraction = shared_fraction(delays)
    sequence, steps = delay_sequence(delays, steps, seed)
    d_max = int(sequence.max())
    return sequence, steps, {**values, "d": d_max + fraction if fraction else d_max}, fraction


def shared_fraction(delays):
    """``(delays, fraction)``: delays that share a fraction of a period, in whole samples, and it.

    A delay that varies by whole samples around a fixed fraction of a
    period (a computation and an amplifier that take half a sample, a
    network that adds whole ones): ``("uniform", 2.5, 4.5)`` or ``[2.5,
    3.5, ...]`` is ``("uniform", 2, 4)`` or ``[2, 3, ...]`` and 0.5, the
    fraction carried by the plant (the modified z-transform) as a fixed
    delay's.  Whole delays give themselves and 0.0; what is not a law or
    an array of numbers is given back for :func:`delay_sequence` to refuse.

    Raises
    ------
    ValueError
        Delays with different fractions of a period (within
        ``DELAY_RTOL``): a delay that varies inside
        a sample moves the hold's switching instant from period to period,
        which is not modelled.
    """
    law = isinstance(delays, tuple) and bool(delays) and isinstance(delays[0], str)
    if isinstance(delays, (str, bytes, dict)) or (law and len(delays) != 3):
        return delays, 0.0
    try:
        x = snap_delay(np.asarray(delays[1:] if law else delays, dtype=float))
    except (TypeError, ValueError):
        return delays, 0.0
    if x.ndim != 1 or not x.size or not np.all(np.isfinite(x)) or np.any(x < 0):
        return delays, 0.0
    whole = np.floor(x)
    fractions = x - whole
    if not np.any(fractions):
        return delays, 0.0
    if np.ptp(fractions) > DELAY_RTOL * max(1.0, float(x.max())):
        raise ValueError(f"delays that vary must share one fraction of a period (whole samples "
                         f"around a fixed part: 2.5, 3.5, 4.5), got fractions from "
                         f"{fractions.min():.6g} to {fractions.max():.6g}; a delay that varies "
                         f"inside a sample is not modelled")
    whole = whole.astype(np.int64)
    return ((delays[0], int(whole[0]), int(whole[1])) if law else whole), float(fractions[0])


def _compensation_of(nonideal, compensation):
    """The :class:`FrictionCompensation` of a run: ``compensation``, else the switch's (or None)."""
    if compensation is not None and not isinstance(compensation, FrictionCompensation):
        raise TypeError(f"compensation must be a FrictionCompensation or None, got "
                        f"{type(compensation).__name__}")
    if compensation is None and nonideal.friction_compensation:
        # The simulator's own estimate, the backward difference (pole 0).
        return FrictionCompensation(nonideal.coulomb_friction)
    return compensation


def _parts_by_chunk(loop, values, overflow):
    """A loop's difference equations a chunk of points at a time.

    Returns ``(parts_of, d, shape, parts_floats, T)``: ``parts_of(part)``
    gives ``(a, b, c, e)`` of the points ``part`` (a slice of the raveled
    broadcast ``shape``), each ``(points, k)``; the floats a point's
    equations take; the sample period (an array where it varies).  With
    ``overflow="raise"`` every chunk is computed once here, so that a value
    the equations refuse (an overflow, a leading coefficient 0, direct
    feed-through) is refused before the run.
    """
    prepared, d, shape = loop.evaluation.prepare(values)
    n_points = int(np.prod(shape))
    flat = {name: np.broadcast_to(value, shape).ravel() if value.ndim else value
            for name, value in prepared.items()}
    if overflow == "diverge":
        equations = loop.difference_parts
    else:
        def equations(chunk):
            return loop.difference_equations(**chunk)

    def parts_of(part):
        size = len(range(n_points)[part])
        parts, _, _ = equations({**{name: value[part] if value.ndim else value
                                    for name, value in flat.items()}, "d": d})
        return [np.broadcast_to(p, (size, p.shape[-1])) for p in parts]

    if overflow == "raise":
        # About 64 floats a point while the equations are computed.
        for part in chunk_slices(n_points, 8 * 64):
            parts_of(part)
    first = parts_of(slice(0, 1))
    orders = first[1].shape[-1] + first[3].shape[-1]
    return parts_of, d, shape, 2 * orders + sum(p.shape[-1] for p in first), prepared["T"]


def _check_driven_mass(loop, name):
    """Raise ValueError naming ``name`` where ``loop`` has no driven mass (friction, a state)."""
    try:
        _ = loop.driven_mass
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None


def linearly_stable(loop, nonideal, values, shape):
    """Where ``loop``'s linear part is stable at ``values`` (raveled), if ``nonideal`` quantizes the force.

    The certified root count (:meth:`symstab.Loop.unstable_root_counts`)
    at every point: 0 is stable; a marginal point (-1) is not.  None
    without a force quantum (no run needs it).
    """
    if nonideal.force_resolution is None:
        return None
    counts = loop.unstable_root_counts(**values)
    return np.broadcast_to(np.asarray(counts) == 0, shape).ravel()


def run_loop(parts_of, n_points, *, d, steps, x0, v0, nonideal, record, progress, shape,
             spaces=None, state=None, compensation=None, parts_floats=64, linear_stable=None,
             delays=None):
    """Run ``n_points`` of a loop a chunk at a time: the one engine; the :class:`Simulation`.

    Parameters
    ----------
    parts_of : callable
        ``parts_of(part)``: the difference equations ``(a, b, c, e)`` of
        the points ``part`` (a slice), as :meth:`symstab.Loop.difference_equations`.
    n_points, d, steps, x0, v0, record, progress
        As :func:`simulate_loop` (checked by the caller).
    nonideal : Nonidealities
        Encoder, force limit and friction, in the loop's units.
    shape : tuple
        The shape of the result (``n_points`` in all).
    spaces : (list of FrictionSpace, ndarray of int), optional
        The plant on its state space (:mod:`symstab.numeric.simulation.friction`),
        each point's index into the list; default: ``P(z)`` on the samples.
    state : (float, float), optional
        With ``spaces``: start from the mass's position and velocity (the
        rest of the plant at rest), not from positions ``x0 - k v0``.
    compensation : FrictionCompensation, optional
        Friction compensation on the simulator's velocity estimate (the
        paper's simulator gives its filter's pole).
    parts_floats : int
        Floats a point's difference equations take (for the chunk size).
    linear_stable : ndarray of bool, optional
        ``(n_points,)``: the points whose linear loop is stable (a certified
        root count of 0); needed with a force quantum, whose verdict floor
        they get (``_verdict``).
    delays : ndarray of int, optional
        ``(steps,)``: the delay of every period (:func:`delay_sequence`),
        at most ``d``, which is then the longest; run one period at a time.
        Default: the fixed delay ``d``.
    """
    if compensation is not None:
        compensation = (compensation.coulomb, compensation.pole)
    if delays is not None and (nonideal.force_resolution is not None
                               or np.shape(delays) != (steps,)):
        raise ValueError("a varying delay needs one delay a period and no force quantum")

    def pulse(part):
        # The linear loop's response to a unit force pulse, at its stable points only.
        points = np.asarray(linear_stable[part], dtype=bool)
        if not points.any():
            return None, points
        return _AnyLoop([p[points] for p in parts_of(part)], d, 0.0, 0.0, Nonidealities(),
                        pulse=1.0), points

    if nonideal.force_resolution is not None and (
            linear_stable is None or np.shape(linear_stable) != (n_points,)):
        raise ValueError("a force quantum's verdict needs linear_stable, one bool a point")
    pulse_of = None if nonideal.force_resolution is None else pulse
    point_bytes = 8 * (d + 1 + parts_floats + _ANY_LOOP_FLOATS + 2 * _block_rows(d)
                       + _BUFFERS * _spare_rows(_block_rows(d)))
    if delays is not None:
        point_bytes = 8 * (d + 1 + parts_floats + _ANY_LOOP_FLOATS + 2 + _BUFFERS * _spare_rows(1))
    if spaces is None and delays is None:
        def make_run(part):
            return _AnyLoop(parts_of(part), d, x0, v0, nonideal, compensation=compensation)
    elif spaces is None:
        def make_run(part):
            return _VaryingLoop(parts_of(part), d, x0, v0, nonideal, delays,
                                compensation=compensation)
    else:
        spaces, inverse = spaces
        n = spaces[0].phi.shape[0]
        # The state, its two candidates and their temporaries; per-point matrices.
        point_bytes += 8 * (6 * n + 4 + (0 if len(spaces) == 1 else 2 * n * n + 10 * n))

        def make_run(part):
            space = stacked_spaces(spaces, inverse[part])
            if delays is not None:
                return _VaryingStateLoop(parts_of(part), d, x0, v0, nonideal, space, delays,
                                         state=state, compensation=compensation)
            return _StateLoop(parts_of(part), d, x0, v0, nonideal, space, state=state,
                              compensation=compensation)
    run = _run_chunks(make_run, n_points, point_bytes, steps=steps, d=d, record=record,
                      progress=progress, nonideal=nonideal, shape=shape, pulse_of=pulse_of)
    return run if delays is None else dataclasses.replace(run, delays=delays)


def check_loop_nonideal(nonideal, loop=None, friction_name="nonideal.coulomb_friction"):
    """``nonideal`` (None: ideal) as the :class:`Nonidealities` of a general loop, or raise.

    A general loop has encoder quantization, force quantization and a force
    limit, and Coulomb friction on its driven mass (with ``loop``: checked
    to have one, :meth:`symstab.Loop.driven_mass`), compensated on the loop
    simulator's velocity estimate with ``friction_compensation``
    (:func:`simulate_loop`); the velocity filter and the actuator lag are
    refused: they belong in its environment and plant.  ``friction_name``
    names the friction in the message (the CLI's ``--coulomb``).
    """
    nonideal = Nonidealities() if nonideal is None else nonideal
    if not isinstance(nonideal, Nonidealities):
        raise TypeError(f"nonideal must be a symstab.numeric.paper.simulate.Nonidealities or None, "
                        f"got {type(nonideal).__name__}")
    for field, instead in (("velocity_cutoff", "write the filter into the loop's environment"),
                           ("actuator_bandwidth", "write the lag into the loop's plant")):
        if getattr(nonideal, field) is not None:
            raise ValueError(f"nonideal.{field}: {instead} (the paper's simulator, "
                             f"symstab.simulate, has it)")
    if loop is not None and nonideal.coulomb_friction is not None:
        _check_driven_mass(loop, friction_name)
    return nonideal


def _verdict(amplitude, swing, diverged, positions, shape, steps, nonideal, response=None):
    """The :class:`Simulation` of a run: stable, a limit cycle, or unstable.

    Unstable when the last quarter outgrows the third.  Amplitudes up to a
    floor count as bounded whatever they do: four encoder counts (a
    quantization limit cycle), plus, with a force quantum ``q``, at the
    points whose linear loop is stable, ``q / 2`` times ``response``, the
    l1 norm over the run of the linear loop's response to a unit force
    pulse.  Rounding adds to each command an error of at most ``q / 2``; by
    superposition the position departs from the run without the quantum by
    at most ``q / 2`` times that norm, and that run decays where the linear
    loop is stable: a limit cycle within the floor is the quantum's, not
    growth.  (Without a floor, a limit cycle's last quarter exceeds the
    third as often as not: on the paper's loop at d = 5 with a 1 mN m
    quantum, 543 of 1 515 stable cells were called unstable.)  ``response``
    is 0 where the linear loop is not stable.

    A run of a loop with non-idealities is a limit cycle
    (:attr:`Simulation.limit_cycle`), neither stable nor unstable, when it
    keeps swinging: the half range of ``x`` over the last quarter
    (``swing``) is above the floor and :data:`_MOVING` of the amplitude (a
    mass held at rest off zero by friction has none), within
    :data:`_SUSTAINED` of the third quarter's (not decaying, not growing),
    and the largest ``|x|`` no more than that above the third's (not
    drifting away).  The sampled peak of a periodic motion differs from one
    quarter to the next by up to 2e-4 (a saturated paper loop), so the
    plain comparison called half of such cycles growing and half stable.
    A linear loop has no limit cycle: a run of the ideal loop that neither
    grows nor decays is on the boundary, and stays the comparison's.
    """
    amplitude[:, diverged] = np.inf
    floor = 4 * nonideal.encoder_resolution if nonideal.encoder_resolution else 0.0
    if response is not None:
        floor = floor + nonideal.force_resolution / 2 * response
    floor = np.broadcast_to(floor, diverged.shape)
    bounded = ~diverged & (amplitude[3] <= np.maximum(amplitude[2], floor))
    with np.errstate(invalid="ignore"):
        limit_cycle = (~diverged & (swing[3] > np.maximum(floor, _MOVING * amplitude[3]))
                       & (np.abs(swing[3] - swing[2]) <= _SUSTAINED * swing[2])
                       & (amplitude[3] <= (1 + _SUSTAINED) * amplitude[2]))
    if nonideal.ideal:
        limit_cycle[:] = False
    return Simulation(
        positions=None if positions is None else positions.reshape((steps + 1,) + shape),
        amplitude=amplitude.reshape((4,) + shape),
        diverged=diverged.reshape(shape), stable=(bounded & ~limit_cycle).reshape(shape),
        steps=steps, floor=floor.reshape(shape), limit_cycle=limit_cycle.reshape(shape))


def _terms(columns):
    """``[(k, coefficient), ...]`` of the nonzero columns of ``(N, k)`` coefficients.

    Each coefficient an array of the N points, even where they are equal:
    NumPy multiplies by an array in half the time it takes to convert a
    float (the product is the same double).
    """
    return [(k, np.ascontiguousarray(columns[:, k])) for k in range(columns.shape[1])
            if not np.all(columns[:, k] == 0)]


class _AnyLoop:
    """A loop's samples for N points: :meth:`advance` runs a block of periods.

    ``a``, ``b``: the plant's ``P_d`` (monic, without its leading 1) and
    ``P_n`` (its coefficients of ``z**(n-1) .. 1``); ``c``, ``e``: the
    environment's ``Ve_d`` (monic, without its leading 1) and ``Ve_n``
    (``z**m .. 1``).  Each signal (the positions ``x``, the sampled
    positions, the forces and the commands ``u``, whose plant input is
    ``-u``) is a buffer of rows in time, oldest first: the past a period
    reads, then the rows of the block being computed.

    A block is up to ``d`` periods (:func:`_block_rows`): the plant
    reads commands ``d`` periods old, all known when the block starts, so
    its positions come first, then the block's samples, forces and
    commands.  What is not a recursion (the rounding, the sums over past
    commands and samples, the non-idealities of the command) runs on the
    block's rows in one NumPy call each; the recursions (the sums over past
    positions and forces) run period by period.  Every number is computed
    by the same operations in the same order as one period at a time, so
    the runs are the same to the last bit; the Python work per period is a
    few calls (the paper's loop at d >= 8: four), not twenty.
    """

    #: A delay that varies from period to period (:class:`_VaryingLoop`):
    #: blocks of one period, the plant stepped after the environment.
    varying = False

    def __init__(self, parts, d, x0, v0, nonideal, compensation=None, pulse=None,
                 positions_unread=False):
        a, b, c, e = parts
        n_points = a.shape[0]
        # Each sum keeps its nonzero terms only (a backward difference's Ve_d
        # is z**k: no force feedback at all).
        self.a, self.c = _terms(a), _terms(c)
        self.minus_b = _terms(-b)
        # (Its newest term apart, made once: unpacking it took a tenth of a period.)
        self._b_first, self._b_rest = self.minus_b[0], self.minus_b[1:]
        self.e0, self.e = np.ascontiguousarray(e[:, 0]), _terms(e[:, 1:])
        self.d = d
        self.quantum = nonideal.encoder_resolution
        self.force_limit = nonideal.force_limit
        self.force_quantum = nonideal.force_resolution
        n, m = a.shape[1], c.shape[1]
        self.n, self.m = n, m
        self.size = n_points
        self.block = 1 if self.varying else _block_rows(d, n_points)
        # The plant steps first where it reads no command of this period (a
        # fixed d >= 1); a varying delay may be 0 in any period.
        self._plant_first = bool(d) and not self.varying
        rows = self.block
        self.compensation = compensation
        # A force added to the first command only (the pulse response).
        self.pulse = pulse
        self._make_buffers(x0, v0, c, e, positions_unread)
        # Friction compensation: (F_c, filter pole) on the velocity
        # estimate, the filtered backward difference of the sampled position.
        self.v_hat = np.zeros(n_points)
        self._tmp = np.empty((rows, n_points))
        self._more = np.empty((rows, n_points)) if compensation is not None else None
        # The filter's pole at every point: an array multiplies faster than a float.
        self._pole = None if compensation is None else np.full(n_points, compensation[1])
        self.filled = 0          # rows of the last block, not yet shifted into the past
        self.k = 0
        self.diverged = np.zeros(n_points, dtype=bool)
        self.check_every = _CHECK_EVERY

    def _make_buffers(self, x0, v0, c, e, positions_unread):
        """The buffers of the signals in time, at the run's start; which of them are one.

        Two signals share a buffer where they are equal and nothing reads
        their difference, which saves a copy a period: the samples are the
        positions where the plant does not read its past positions
        (``positions_unread``: on its state space) and there is no encoder
        (:attr:`samples_are_positions`); the commands are the forces where
        no non-ideality or pulse changes the command, the environment does
        not read its past forces (``Ve_d = z**m``) and the forces at rest at
        the start are finite (what the overflow checks would read of them
        before the run's own; :attr:`commands_are_forces`).
        """
        n, m, d, n_points = self.n, self.m, self.d, self.size
        start = np.full(n_points, float(x0))
        sampled = self._sample(start)
        # The environment at rest at the sampled x0: its force Ve(1) x_s
        # (none where Ve has a pole at z = 1, an integrator's).
        with np.errstate(all="ignore"):
            dc_gain = np.where(1 + c.sum(axis=1) != 0, e.sum(axis=1) / (1 + c.sum(axis=1)), 0.0)
        resting_force = dc_gain * sampled
        self.samples_are_positions = positions_unread and not self.quantum
        self.commands_are_forces = (
            not self.c and self.compensation is None and self.pulse is None
            and self.force_quantum is None and self.force_limit is None
            and bool(np.isfinite(resting_force).all()))
        # The past each buffer keeps before its block: x[k-n] .. x[k] (the
        # overflow check reads x[k-n]), u[k-d-n] .. u[k-1], the samples and
        # forces of the last m periods (one sample at least: the velocity
        # estimate's); a shared buffer keeps the longer past.
        past_x = max(n + 1, max(m, 1) + 1) if self.samples_are_positions else n + 1
        past_u = max(d + n, m) if self.commands_are_forces else d + n
        self.past = (past_x, past_u, past_x - 1 if self.samples_are_positions else max(m, 1),
                     past_u if self.commands_are_forces else m)
        # keep_x, ...: the row of each buffer where the block starts; the
        # blocks follow one another in the spare rows, which are moved back
        # to the start (the past only) when they run out.
        self.keep_x, self.keep_u, self.keep_s, self.keep_f = self.past
        self.spare = _spare_rows(self.block)
        self.X = np.empty((self.keep_x + self.spare, n_points))
        self.U = np.zeros((self.keep_u + self.spare, n_points))
        self.S = self.X if self.samples_are_positions else np.empty(
            (self.keep_s + self.spare, n_points))
        self.F = self.U if self.commands_are_forces else np.empty(
            (self.keep_f + self.spare, n_points))
        # The buffers each with its past, moved back by _shift.
        own = (True, True, not self.samples_are_positions, not self.commands_are_forces)
        self._moved = [(buffer, keep) for buffer, keep, mine in zip(
            (self.X, self.U, self.S, self.F), self.past, own, strict=True) if keep and mine]
        if self.samples_are_positions:
            # The sampled history at x0, of which the newest is the position.
            self.X[:self.keep_x] = start
        else:
            # x[k] = x0; x[k-i] = x0 - i v0 before the start; no force applied yet.
            self.X[n] = start
            for i in range(1, n + 1):
                self.X[n - i] = x0 - i * v0
            self.S[:self.keep_s] = sampled
        if not self.commands_are_forces:
            self.F[:m] = resting_force

    # The buffers' rows as lists of views, made when first used (a run in
    # blocks uses one or two; a chunk made every view, which in a run of
    # many small chunks took as long as the run): indexing a list takes a
    # fifth of the time of making a view.
    @functools.cached_property
    def _x_rows(self):
        return list(self.X)

    @functools.cached_property
    def _u_rows(self):
        return list(self.U)

    @functools.cached_property
    def _s_rows(self):
        return self._x_rows if self.S is self.X else list(self.S)

    @functools.cached_property
    def _f_rows(self):
        return self._u_rows if self.F is self.U else list(self.F)

    def _sample(self, x):
        q = self.quantum
        return x if not q else _rounded(x, q)

    @property
    def x(self):
        """The newest position (a view of the buffer)."""
        return self._x_rows[self.keep_x - 1 + self.filled]

    @property
    def positions(self):
        """The positions the last block computed, ``(rows, N)`` (views of the buffer)."""
        return self.X[self.keep_x:self.keep_x + self.filled]

    def advance(self, count):
        """``count`` periods, at most :attr:`block`; the caller ignores overflow and invalid values.

        (:func:`_run`'s error state.)  The block's positions are then
        :attr:`positions`.  The overflow check runs where one period at a
        time would run it, after every :attr:`check_every` periods, on the
        values of that period, still in the buffers: a point then frozen has
        diverged whatever it does after (its verdict does not read them).
        """
        if self.filled:
            self._shift(self.filled)
        start, every = self.k, self.check_every
        if count == 1:
            # The checks below for one period, without their ranges: this
            # runs every period at d = 0 and 1.
            self._one_period()
            self.filled = 1
            self.k = start + 1
            if (start + 1) % every == 0 and not self._calm(1, 1):
                self.freeze_diverged(1)
            return
        # d >= 2 (count <= d): the plant reads no command of the block.
        self._plant_block(count)
        self._environment_block(count)
        self.filled = count
        self.k += count
        checks = range(start - start % every + every, self.k + 1, every)
        if checks and not self._calm(checks[0] - start, checks[-1] - start):
            for done in checks:
                self.freeze_diverged(done - start)

    def advance_each(self, count, high, low):
        """``count`` blocks of one period (:meth:`advance`), each position folded into the extremes.

        ``high`` and ``low`` get the largest and smallest value of each
        point, in place (:func:`_run`'s, for a run that records, sums and
        reports nothing, its periods one at a time, d = 0 and 1: a period
        is a few microseconds, a third of them the calls around it).
        """
        maximum, minimum, one_period = np.maximum, np.minimum, self._one_period
        every, rows, past, spare = self.check_every, self._x_rows, self.past[0], self.spare
        for _ in range(count):
            if self.filled:
                # _shift(1) where the rows do not run out.
                if self.keep_x + 1 - past + self.block <= spare:
                    self.filled = 0
                    self.keep_x += 1
                    self.keep_u += 1
                    self.keep_s += 1
                    self.keep_f += 1
                else:
                    self._shift(1)
            one_period()
            self.filled = 1
            self.k += 1
            if self.k % every == 0 and not self._calm(1, 1):
                self.freeze_diverged(1)
            x = rows[self.keep_x]
            maximum(high, x, out=high)     # (positional: deprecated for these two, slow)
            minimum(low, x, out=low)

    def _shift(self, count):
        """The last block's rows join the past; back to the buffers' start when the rows run out."""
        self.filled = 0
        moved = self.keep_x + count - self.past[0]
        if moved + self.block <= self.spare:
            self.keep_x += count
            self.keep_u += count
            self.keep_s += count
            self.keep_f += count
            return
        for buffer, keep in self._moved:
            buffer[:keep] = buffer[moved:moved + keep]
        self.keep_x, self.keep_u, self.keep_s, self.keep_f = self.past

    def _combine(self, out, terms, buffer, first_row, sign):
        """``out (+/-)= c * buffer[first_row - k:][:rows]`` for each term ``(k, c)``, in order."""
        rows = out.shape[0]
        tmp = self._tmp[:rows]
        combine = np.add if sign > 0 else np.subtract
        for k, coefficient in terms:
            start = first_row - k
            combine(out, np.multiply(coefficient, buffer[start:start + rows], out=tmp), out=out)

    def _recur(self, rows, terms, first_row, count):
        """``rows[first_row + r] -= c * rows[first_row + r - 1 - k]`` per term, period by period."""
        tmp = self._tmp[0]
        for r in range(first_row, first_row + count):
            row = rows[r]
            for k, coefficient in terms:
                np.subtract(row, np.multiply(coefficient, rows[r - 1 - k], out=tmp), out=row)

    def _plant_block(self, count):
        """The plant's next ``count`` samples: ``P_d(z) y = P_n(z) u``, ``u = -command``."""
        kx = self.keep_x
        out = self.X[kx:kx + count]
        # u[j - d - k] of the periods j of the block, the newest term first.
        first_u = self.keep_u - self.d
        (k, first), *rest = self.minus_b
        np.multiply(first, self.U[first_u - k:first_u - k + count], out=out)
        self._combine(out, rest, self.U, first_u, 1)
        self._recur(self._x_rows, self.a, kx, count)

    def _environment_block(self, count):
        """The samples, forces and commands of the block's periods (its positions known)."""
        q, kx, ks, kf, ku = self.quantum, self.keep_x, self.keep_s, self.keep_f, self.keep_u
        positions = self.X[kx - 1:kx - 1 + count]
        sampled = self.S[ks:ks + count]
        if q:
            _round_into(sampled, positions, q)
        elif not self.samples_are_positions:
            np.copyto(sampled, positions)
        force = self.F[kf:kf + count]
        np.multiply(self.e0, sampled, out=force)
        self._combine(force, self.e, self.S, ks - 1, 1)
        if self.c:
            self._recur(self._f_rows, self.c, kf, count)
        command = self.U[ku:ku + count]
        if self.compensation is not None:
            self._compensated(command, force, sampled, count)
            self.pulse = None
        else:
            if not self.commands_are_forces:
                np.copyto(command, force)
            if self.pulse is not None:
                command[0] = force[0] + self.pulse
                self.pulse = None
        # The environment keeps its own force; the command sent is rounded
        # to the DAC's step and clipped to its range.
        if self.force_quantum is not None:
            _round_into(command, command.copy(), self.force_quantum)
        if self.force_limit is not None:
            np.clip(command, -self.force_limit, self.force_limit, out=command)

    def _one_period(self):
        """A block of one period on the buffers' rows, views made once: no slicing.

        The operations of :meth:`_plant_block` and :meth:`_environment_block`
        on one row (d = 0 or 1, or a recorded run: blocks of one period,
        where making the views of a block took as long as the arithmetic).
        """
        if self._plant_first:
            self._plant_one()
        tmp, multiply, add = self._tmp[0], np.multiply, np.add
        ks, kf = self.keep_s, self.keep_f
        S, F = self._s_rows, self._f_rows
        sampled, force = S[ks], F[kf]
        if self.quantum:
            _round_into(sampled, self._x_rows[self.keep_x - 1], self.quantum)
        elif not self.samples_are_positions:
            np.copyto(sampled, self._x_rows[self.keep_x - 1])
        # Positional outs: the keyword costs a fifth of a call on small arrays.
        multiply(self.e0, sampled, force)
        for k, coefficient in self.e:
            add(force, multiply(coefficient, S[ks - 1 - k], tmp), force)
        for k, coefficient in self.c:
            np.subtract(force, multiply(coefficient, F[kf - 1 - k], tmp), force)
        command = self._u_rows[self.keep_u]
        if self.compensation is not None:
            ku = self.keep_u
            self._compensated(self.U[ku:ku + 1], self.F[kf:kf + 1], self.S[ks:ks + 1], 1)
            self.pulse = None
        else:
            if not self.commands_are_forces:
                np.copyto(command, force)
            if self.pulse is not None:
                np.add(force, self.pulse, out=command)
                self.pulse = None
        if self.force_quantum is not None:
            _round_into(command, command.copy(), self.force_quantum)
        if self.force_limit is not None:
            np.clip(command, -self.force_limit, self.force_limit, out=command)
        if not self._plant_first:
            self._plant_one()

    def _plant_one(self):
        """:meth:`_plant_block` of one period on the rows."""
        X, U, tmp, multiply = self._x_rows, self._u_rows, self._tmp[0], np.multiply
        kx, first_u = self.keep_x, self.keep_u - self.d
        out = X[kx]
        k, first = self._b_first
        multiply(first, U[first_u - k], out)
        for k, coefficient in self._b_rest:
            np.add(out, multiply(coefficient, U[first_u - k], tmp), out)
        for k, coefficient in self.a:
            np.subtract(out, multiply(coefficient, X[kx - 1 - k], tmp), out)

    def _compensated(self, command, force, sampled, count):
        """``command = force - F_c sign(v_hat)``, ``v_hat`` filtered period by period."""
        coulomb, pole = self.compensation
        change = self._tmp[:count]
        np.subtract(sampled, self.S[self.keep_s - 1:self.keep_s - 1 + count], out=change)
        np.multiply(1 - pole, change, out=change)
        estimate, v_hat, pole = self._more[:count], self.v_hat, self._pole
        for r in range(count):
            np.add(np.multiply(pole, v_hat, out=estimate[r]), change[r], out=estimate[r])
            v_hat = estimate[r]
        self.v_hat = v_hat.copy()
        np.sign(estimate, out=estimate)
        np.subtract(force, np.multiply(coulomb, estimate, out=estimate), out=command)

    def _unfinite(self, filled):
        """Per point: a history the plant reads is not finite (x[k-n..k-1], u[k-d-n..k-d-1]).

        ``k`` the period after the block's first ``filled`` rows.
        """
        newest_x, newest_u = self.keep_x - 1 + filled, self.keep_u - 1 + filled
        n, d = self.n, self.d
        bad = ~np.isfinite(self.X[newest_x - n:newest_x]).all(axis=0)
        bad |= ~np.isfinite(self.U[newest_u - d - n + 1:newest_u - d + 1]).all(axis=0)
        return bad

    def _calm(self, first, last):
        """True when no check after ``first`` to ``last`` rows of the block can find a point.

        A quick test of the values those checks read (:meth:`freeze_diverged`
        is exact): every position below the overflow, and the sums of the
        commands and forces finite (a sum that overflows sends the checks to
        the exact test).  The caller ignores overflow (:func:`_run`).
        """
        x, u, f = self.keep_x - 1, self.keep_u - 1 - self.d, self.keep_f - 1
        return bool(np.maximum.reduce(np.abs(self.X[x + first - self.n:x + last + 1]), axis=None)
                    < _OVERFLOW) and math.isfinite(
            np.add.reduce(self.U[u + first - self.n + 1:u + last + 1], axis=None)
            + np.add.reduce(self.F[f + first - self.m + 1:f + last + 1], axis=None))

    def freeze_diverged(self, filled=None):
        """Mark the points whose state left [-1e100, 1e100] or is not finite; zero them.

        The state after the block's first ``filled`` rows (default: all).
        """
        filled = self.filled if filled is None else filled
        if self._calm(filled, filled):
            return
        bad = ~(np.abs(self.X[self.keep_x - 1 + filled]) < _OVERFLOW) | self._unfinite(filled)
        newest_f = self.keep_f - 1 + filled
        bad |= ~np.isfinite(self.F[newest_f - self.m + 1:newest_f + 1]).all(axis=0)
        if bad.any():
            self.diverged |= bad
            for buffer in (self.X, self.U, self.S, self.F):
                buffer[:, bad] = 0.0
            self.v_hat[bad] = 0.0
            self._freeze_plant(bad)

    def _freeze_plant(self, bad):
        """Zero the plant's own state of the points ``bad`` (a state space has one)."""


class _StateLoop(_AnyLoop):
    """A loop whose plant is a :class:`~symstab.numeric.simulation.friction.StatePlant`: on its state space.

    With Coulomb friction on its mass, or started from a state: ``state =
    (x0, v0)``, the mass's position and velocity (the rest of the plant at
    rest) rather than a history of positions.
    """

    def __init__(self, parts, d, x0, v0, nonideal, space, state=None, compensation=None):
        super().__init__(parts, d, x0, v0, nonideal, compensation=compensation,
                         positions_unread=True)
        coulomb = nonideal.coulomb_friction
        stiction = nonideal.stiction if nonideal.stiction is not None else coulomb
        self._unfinite_at = {}
        if state is None:
            self.plant = StatePlant.from_history(space, x0, v0, self.size, nonideal)
        else:
            start = np.zeros((space.phi.shape[0], self.size))
            start[0], start[1] = state
            self.plant = StatePlant(space, start, np.full(self.size, state[1] == 0),
                                    substeps=substeps_of(nonideal), coulomb=coulomb,
                                    stiction=stiction)

    def _plant_block(self, count):
        # The state space holds the plant's past: one period at a time; the
        # state's check of each period that has one is kept for the block's
        # checks (:meth:`_AnyLoop.advance`).
        first_u, every, start = self.keep_u - self.d, self.check_every, self.k
        self._unfinite_at = {}
        for r in range(count):
            self.plant.step(self.U[first_u + r], -1.0, out=self._x_rows[self.keep_x + r])
            if (start + r + 1) % every == 0:
                self._check_plant(r + 1)

    def _plant_one(self):
        self._step_plant(self.keep_u - self.d)

    def _step_plant(self, command_row):
        """One period of the plant driven by the command in row ``command_row`` of the buffer."""
        self.plant.step(self._u_rows[command_row], -1.0, out=self._x_rows[self.keep_x])
        self._unfinite_at = {}
        if (self.k + 1) % self.check_every == 0:
            self._check_plant(1)

    def _check_plant(self, filled):
        """Keep the points whose plant state is not finite after ``filled`` rows of the block.

        (Every period of a recorded run: count_nonzero, not any(), at a
        quarter of its time on a few points.)
        """
        ok = self.plant.finite()
        if np.count_nonzero(ok) != ok.size:
            self._unfinite_at[filled] = ~ok

    def _unfinite(self, filled):
        # The plant's past is its state, whose check the block kept.
        return self._unfinite_at.get(filled, np.zeros(self.size, dtype=bool))

    def _calm(self, first, last):
        return not self._unfinite_at and super()._calm(first, last)

    def freeze_diverged(self, filled=None):
        if filled is None:
            # The run's end: the plant's state now.
            bad = ~self.plant.finite()
            if bad.any():
                self._unfinite_at[self.filled] = bad | self._unfinite(self.filled)
        super().freeze_diverged(filled)

    def _freeze_plant(self, bad):
        self.plant.freeze(bad)


def _lags(delays, n, d_max):
    """The delay of each period ``k`` at index ``k + n`` (``d_max`` before the start), for indexing.

    A memoryview: its items are Python ints (a NumPy scalar index costs
    more than the row it picks); before the start the commands read are
    the empty delay line's zeros whatever the delay.
    """
    lags = np.concatenate([np.full(n, d_max, dtype=np.int64), np.asarray(delays, dtype=np.int64)])
    return memoryview(lags)


class _VaryingLoop(_AnyLoop):
    """A loop whose delay varies by whole samples from period to period, one period at a time.

    ``d`` is the longest delay, the commands the buffers keep; ``delays``
    the delay ``delta_k`` of every period: the plant's input at period
    ``k`` is ``-u[k - delta_k]``, ``u`` the commands (a period's, and those
    of the periods before it its plant still reads, each with its own
    delay).  Each product is :meth:`_AnyLoop._plant_one`'s in the same
    order: at a constant delay the run is the fixed delay's to the last bit.
    """

    varying = True

    def __init__(self, parts, d, x0, v0, nonideal, delays, compensation=None):
        super().__init__(parts, d, x0, v0, nonideal, compensation=compensation)
        self._lags = _lags(delays, self.n, d)

    def _plant_one(self):
        X, U, tmp, multiply = self._x_rows, self._u_rows, self._tmp[0], np.multiply
        kx, ku, lags, now = self.keep_x, self.keep_u, self._lags, self.k + self.n
        out = X[kx]
        # The input of period k - i is the command of period k - i - delta_{k-i}.
        i, first = self._b_first
        multiply(first, U[ku - i - lags[now - i]], out)
        for i, coefficient in self._b_rest:
            np.add(out, multiply(coefficient, U[ku - i - lags[now - i]], tmp), out)
        for i, coefficient in self.a:
            np.subtract(out, multiply(coefficient, X[kx - 1 - i], tmp), out)


class _VaryingStateLoop(_StateLoop):
    """:class:`_VaryingLoop` with the plant on its state space (friction, a start from a state)."""

    varying = True

    def __init__(self, parts, d, x0, v0, nonideal, space, delays, state=None, compensation=None):
        super().__init__(parts, d, x0, v0, nonideal, space, state=state,
                         compensation=compensation)
        self._lags = _lags(delays, self.n, d)

    def _plant_one(self):
        self._step_plant(self.keep_u - self._lags[self.k + self.n])


def loop_stability_map(loop, x_values, y_values, *, x=None, y=None, steps=None, x0=1.0, v0=None,
                       nonideal=None, progress=None, **values):
    """Stable cells of an ``(x, y)`` grid of a loop by simulation (:func:`simulate_loop` on each).

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    x_values, y_values : array_like
        1-D grids of the plane's parameters.
    x, y : str, optional
        The plane (default: the loop's :attr:`~symstab.Loop.plane`).
    steps, x0, v0, nonideal
        As in :func:`simulate_loop`.
    progress : callable or True
        As in :func:`simulate_loop`; ``True`` draws a progress bar on
        stderr for runs over 2 s.
    **values
        Single values of the other parameters.

    Returns
    -------
    StabilityMap
        ``stable`` of shape ``(len(y_values), len(x_values))``.
    """
    x, y = loop.plane_of(x, y)
    x_values, y_values = check_grid(x, y, x_values, y_values, values)
    Y, X = np.meshgrid(y_values, x_values, indexing="ij")
    run = simulate_loop(loop, steps=steps, x0=x0, v0=v0, nonideal=nonideal, progress=progress,
                        **{x: X, y: Y}, **values)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = np.where(run.diverged, np.inf, run.amplitude[3] / run.amplitude[2])
    at = {k: v for k, v in {**loop.defaults, **values}.items() if k not in (x, y)}
    return StabilityMap(y_values, x_values, run.stable, run.limit_cycle, growth, run.steps,
                        x=x, y=y, at=at)
