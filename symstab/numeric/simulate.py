"""The sampled haptic loop in time: many parameter points at once.

Every period ``T`` the position is sampled, the virtual environment of
eq. (1) computes a force from the sampled positions
(:func:`symstab._generated.kernels.environment_force`), the force waits
``d`` samples, and a zero-order hold applies it to the device, whose state
advances by the exact step derived in :mod:`symstab.symbolic.sampled_plant`
(:func:`symstab._generated.kernels.plant_step_coefficients`).  The state
lives in Table I's units: position, ``v T``, force ``f T**2 / m``.  All
points run together as NumPy arrays, one loop over time.

Non-idealities (:class:`Nonidealities`, physical units, each off by
default) need a :class:`symstab.numeric.units.Device`:

* ``encoder_resolution`` -- the sampled position is rounded to this step;
* ``force_limit`` -- the force command is clipped to this size (the
  amplifier's saturation: an unstable linear loop then grows into a bounded
  limit cycle, which the verdict calls bounded, not growing);
* ``velocity_cutoff`` -- the velocity used by the damper and mass terms is
  the backward difference passed through a first-order low-pass filter
  (pole ``exp(-2 pi f_c T)``, unit DC gain); the mass term differences the
  filtered velocity;
* ``coulomb_friction`` (with ``stiction``, the breakaway force, default
  equal) -- integrated inside the period on ``substeps`` sub-steps: a moving
  device feels ``-F_c sign(v)``; a sub-step that would reverse the velocity
  ends at rest instead, and a device at rest stays there while the applied
  force is within the stiction force (:mod:`symstab.numeric.friction`, the
  model of every loop's friction);
* ``friction_compensation`` -- the command adds ``F_c sign(v_hat)``, with
  ``v_hat`` the (filtered) velocity estimate;
* ``actuator_bandwidth`` -- the applied force follows the command through a
  first-order lag of that bandwidth: the device behind its lag is stepped
  exactly on its state space (the lag is the loop's actuator, as in
  ``examples/loops/actuator_lag.toml``), at any number of sub-steps.

Stability by simulation (:func:`stability_map`): the run starts from the
position ``x0`` (``1e-100 <= |x0| <= 1e50``, see :func:`simulate`), the history at ``x0`` and a small velocity (``v0 T = x0 /
100`` by default: starting at rest would leave the modes of ``z = 1``
unexcited at ``alpha = 0``, a constant position being an equilibrium there),
with an empty delay line; a point is unstable when the
largest ``|x|`` over the last quarter of the horizon exceeds that over the
quarter before (the slowest mode grows), or the state overflows.  A
decaying or bounded run is stable, including a limit cycle at the
resolution of the encoder.  The default horizon grows with the delay; near
the boundary the modes have ``|z|`` close to 1 and any finite horizon
leaves a band of undecidable cells, which the tests count.

Any :class:`symstab.Loop` runs the same way (:func:`simulate_loop`,
:meth:`symstab.Loop.simulate`, :meth:`symstab.Loop.stability_map`): its
plant's exact ZOH step on the samples (with Coulomb friction, on its state
space, :mod:`symstab.numeric.friction`), its environment's difference
equation, the delay line, the same verdict; its theory is its own root
count.

The theory to compare a run with
(:func:`~symstab.numeric.simulate_theory.linear_theory`) is that of the loop
simulated: its linear part, the velocity filter and the actuator lag
included (a :class:`symstab.Loop`), quantization and friction left out.  On
the README's grid (d = 10, K_w in [0, 70], B_w in [-0.1, 2], 100 x 100) with
a 100 Hz filter the simulation agrees with it on all 9918 cells it decides
(with the ideal loop's count it differed on 1163).
"""

import dataclasses
import functools
import math
import sys
import time

import numpy as np

from .._generated import kernels
from .._resources import MAX_STEPS_ENV, check_memory, chunk_slices
from .._resources import max_steps as _max_steps_setting
from .._validate import check_array, check_delay, check_loop, check_real
from .friction import FrictionPlant, friction_space, stacked_spaces
from .results import PAPER_PLANE, PaperGridNames

__all__ = ["Nonidealities", "Simulation", "simulate", "StabilityMap", "stability_map",
           "default_horizon", "check_steps", "check_x0", "max_steps", "progress_printer", "PAPER_ENCODER_RESOLUTION",
           "MAX_STEPS_ENV", "simulate_loop", "loop_stability_map", "check_loop_nonideal",
           "default_x0"]

#: The most sub-steps per period: each multiplies the simulation's time (a
#: billion once hung it), and friction's stick and reversal times, which they
#: resolve, are first order in ``1/substeps``: a thousand is far past any use.
MAX_SUBSTEPS = 1000

#: The paper's encoder: better than 3 arc seconds after quadrature and gear
#: train (Section VI), in rad.
PAPER_ENCODER_RESOLUTION = math.radians(3 / 3600)
#: |x| above this is divergence: the run stops for that point.
_OVERFLOW = 1e100
#: Periods between overflow checks.
_CHECK_EVERY = 8
#: Allowed size of the initial state.  The verdict compares the largest |x|
#: of the last two quarters and calls |x| > _OVERFLOW divergence: a start at
#: zero never moves (0 <= 0 reads as stable), and a stable point needs room
#: above |x0| for its transient before the overflow threshold (50 orders of
#: magnitude), as a decaying or growing run needs room below it before
#: subnormal numbers lose the ratio (about 200 orders down to 1e-308).
X0_MIN = 1e-100
X0_MAX = _OVERFLOW * 1e-50
#: Floats held per point besides the delay line: position, velocity, two
#: sampled positions, filter and actuator states, four amplitudes, three
#: environment coefficients, alpha, beta, gamma and about six temporaries.
_FLOATS_PER_POINT = 22
@dataclasses.dataclass(frozen=True)
class Nonidealities:
    """Departures from the ideal loop, in physical units; ``None``/False is off.

    Attributes
    ----------
    encoder_resolution : float
        Position quantum (m or rad), > 0.
    velocity_cutoff : float
        Cut-off of the velocity filter (Hz), in (0, Nyquist).
    coulomb_friction : float
        Coulomb friction force (N or N m), >= 0.
    stiction : float
        Breakaway force (N or N m), >= coulomb_friction (default: equal).
    friction_compensation : bool
        Add ``coulomb_friction * sign(v_hat)`` to the command.
    actuator_bandwidth : float
        First-order lag of the applied force (Hz), > 0.
    substeps : int
        Sub-steps per period, 1 to :data:`MAX_SUBSTEPS`: friction is
        decided at their ends (the actuator lag is exact at any number).
    force_limit : float
        Largest force command (N or N m), > 0: the command is clipped to it.
    """

    encoder_resolution: float = None
    velocity_cutoff: float = None
    coulomb_friction: float = None
    stiction: float = None
    friction_compensation: bool = False
    actuator_bandwidth: float = None
    substeps: int = 20
    force_limit: float = None

    def __post_init__(self):
        # Checked at construction, so that a wrong kind never reaches a run:
        # friction_compensation="no" would otherwise switch compensation on.
        if self.encoder_resolution is not None:
            check_real("encoder_resolution", self.encoder_resolution, low=0.0, low_open=True)
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
                and self.force_limit is None)

    @property
    def needs_substeps(self):
        """Friction and the actuator lag act inside the period; the rest on samples."""
        return self.coulomb_friction is not None or self.actuator_bandwidth is not None


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
        The state overflowed (|x| > 1e100).
    stable : ndarray of bool
        Not diverged, and the last quarter's amplitude does not exceed the
        third's (see the module docstring).
    steps : int
    """

    positions: object
    amplitude: np.ndarray
    diverged: np.ndarray
    stable: np.ndarray
    steps: int

    def __repr__(self):
        stable = np.asarray(self.stable)
        n_stable, n_diverged = int(np.count_nonzero(stable)), int(np.count_nonzero(self.diverged))
        size = f"{stable.size} point{'s' if stable.size != 1 else ''}"
        if stable.ndim > 1:
            size += " (" + " x ".join(map(str, stable.shape)) + ")"
        recorded = ", positions recorded" if self.positions is not None else ""
        return (f"Simulation({size}, {self.steps} steps: {n_stable} stable, "
                f"{stable.size - n_stable} unstable of which {n_diverged} diverged{recorded})")


def progress_printer(label, total, stream=None, min_seconds=2.0):
    """A callback ``(done)`` that draws a bar once a run takes longer than ``min_seconds``.

    The bar is drawn on ``stream`` (default ``sys.stderr``) only when it is
    a terminal: redrawn with carriage returns, it would be noise in a log
    file or a pipe (and a second "line" before an error message there).
    """
    stream = sys.stderr if stream is None else stream
    start = time.perf_counter()
    state = {"last": 0.0}
    isatty = getattr(stream, "isatty", None)
    if not (isatty is not None and isatty()):
        return lambda done: None

    def update(done):
        now = time.perf_counter() - start
        if now < min_seconds or (now - state["last"] < 0.2 and done < total):
            return
        state["last"] = now
        frac = done / total
        bar = "#" * int(30 * frac)
        eta = now / frac - now if frac > 0 else 0.0
        stream.write(f"\r{label} [{bar:<30}] {100 * frac:5.1f}%  {now:5.1f} s, ~{eta:4.0f} s left")
        if done >= total:
            stream.write("\n")
        stream.flush()

    return update


def simulate(*, alpha, beta, gamma, d, delta, steps=None, x0=1.0, v0=None, device=None,
             nonideal=None, record=False, progress=None):
    """Run the sampled loop for every parameter point at once.

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping, virtual mass (broadcast together).
    d : int
        Delay in samples, ``d >= 0``.
    delta : float
        ``b T / m``; with a ``device`` it must equal ``device.delta``
        (pass ``None`` to take it from the device).
    steps : int
        Periods to simulate, from 8 to :func:`max_steps` (default
        :func:`default_horizon`).
    x0 : float
        Initial position (m or rad); the sampled history starts there too.
        ``1e-100 <= |x0| <= 1e50`` (:data:`X0_MIN`, :data:`X0_MAX`): the
        verdict compares amplitudes, which a start at zero never has, and
        calls ``|x| > 1e100`` divergence, which a stable point's transient
        must stay below.
    v0 : float
        Initial velocity times T (position per period); default ``x0 / 100``;
        ``|v0| <= 1e50``.
    device : symstab.numeric.units.Device
        Needed for the non-idealities (physical units).
    nonideal : Nonidealities
        Off by default.
    record : bool
        Keep every position (memory: ``steps`` times the points).
    progress : callable
        Called with the number of steps done (every 1 % or so).

    Returns
    -------
    Simulation

    Raises
    ------
    TypeError, ValueError
        For a parameter of the wrong kind or out of range (the message
        names it), and when the run would need more memory than
        ``SYMSTAB_MEMORY_LIMIT`` (see :mod:`symstab._resources`).  Without
        ``record`` the points are simulated in chunks, so the working
        memory does not grow with their number.
    """
    from .units import Device

    if nonideal is None:
        nonideal = Nonidealities()
    elif not isinstance(nonideal, Nonidealities):
        raise TypeError(f"nonideal must be a symstab.numeric.simulate.Nonidealities or None, "
                        f"got {type(nonideal).__name__}")
    if device is not None and not isinstance(device, Device):
        raise TypeError(f"device must be a symstab.Device or None, got {type(device).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable taking the number of steps done, or None, "
                        f"got {type(progress).__name__}")
    if device is not None:
        nonideal.check(device.T)
        if delta is None:
            delta = device.delta
        else:
            # The loop's rule for delta lives in check_loop (gamma is checked below).
            delta = check_loop(0.0, 0, delta)[2]
            if not math.isclose(delta, device.delta, rel_tol=1e-12):
                raise ValueError(f"delta must equal the device's b T / m = {device.delta!r}, "
                                 f"got {delta!r}")
    elif not nonideal.ideal:
        raise ValueError("nonideal needs a device (physical units)")
    arrays = np.broadcast_arrays(check_array("alpha", alpha), check_array("beta", beta),
                                 check_array("gamma", gamma))
    shape = arrays[0].shape
    alpha, beta, gamma = (a.ravel() for a in arrays)
    if delta is None:
        raise TypeError("delta must be a real number (or None with a device), got None")
    _, d, delta = check_loop(0.0, d, delta)
    steps = check_steps(steps, d)
    x0 = check_x0(x0)
    v0 = x0 / 100 if v0 is None else check_real("v0", v0, low=-X0_MAX, high=X0_MAX)
    return _run_chunks(
        lambda part: _Loop(alpha[part], beta[part], gamma[part], d, delta, x0, v0, device,
                           nonideal),
        alpha.size, 8 * (d + 1 + _FLOATS_PER_POINT), steps=steps, d=d, record=record,
        progress=progress, nonideal=nonideal, shape=shape)


def _run_chunks(make_run, n_points, point_bytes, *, steps, d, record, progress, nonideal, shape):
    """Run ``n_points`` in chunks of about :data:`~symstab._resources.CHUNK_BYTES`; the :class:`Simulation`.

    The one driver of both simulators: ``make_run(part)`` builds the state
    of the points ``part`` (a :class:`_Loop` or an :class:`_AnyLoop`) of
    ``point_bytes`` each.  Recording keeps every position, so it runs in
    one chunk and its memory is checked first.
    """
    if record:
        check_memory(f"recording {steps} periods of {n_points} point(s) at d = {d}",
                     8 * (steps + 1) * n_points + point_bytes * n_points)
    else:
        # The chunks bound the working set; what stays is the result.
        check_memory(f"simulating {n_points} point(s)", 8 * 6 * n_points)
    chunks = [slice(0, n_points)] if record else chunk_slices(n_points, point_bytes)
    amplitude = np.zeros((4, n_points))
    diverged = np.zeros(n_points, dtype=bool)
    positions = np.empty((steps + 1, n_points)) if record else None
    report = max(1, steps // 100)
    for number, part in enumerate(chunks):
        run = make_run(part)
        # Recorded positions must never hold an overflowed value: check every period then.
        run.check_every = 1 if record else _CHECK_EVERY
        _run(run, steps, amplitude[:, part], None if positions is None else positions[:, part],
             progress, report, number, len(chunks))
        diverged[part] = run.diverged
    return _verdict(amplitude, diverged, positions, shape, steps, nonideal)


def _run(run, steps, amplitude, positions, progress, report, chunk, n_chunks):
    """Advance ``run`` ``steps`` periods, keeping the largest |x| of each quarter.

    ``progress`` hears the steps done over all chunks, scaled to ``steps``.
    """
    quarter = steps // 4
    if positions is not None:
        positions[0] = run.x
    magnitude = np.empty_like(run.x)
    for k in range(steps):
        with np.errstate(over="ignore", invalid="ignore"):
            run.step()
        q = min(k // quarter, 3)
        np.abs(run.x, out=magnitude)
        np.maximum(amplitude[q], magnitude, out=amplitude[q])
        if positions is not None:
            positions[k + 1] = run.x
        if progress is not None and ((k + 1) % report == 0 or k + 1 == steps):
            progress((chunk * steps + k + 1) // n_chunks)
    run.freeze_diverged()


@functools.lru_cache(maxsize=64)
def _paper_space(delta, bandwidth, substeps):
    """The :class:`~symstab.numeric.friction.FrictionSpace` of the paper's device in Table I's units.

    The mass ``1 / (s**2 + delta s)`` (``m = T = 1``), behind the lag
    ``bandwidth / (s + bandwidth)`` (``bandwidth = 2 pi f_a T``) when there is one.
    """
    actuator = [[bandwidth], [1, bandwidth]] if bandwidth else [[1], [1]]
    return friction_space(actuator + [[1], [1, delta, 0]], 1, substeps)


class _Loop:
    """The loop's state for N points; :meth:`step` advances one period."""

    def __init__(self, alpha, beta, gamma, d, delta, x0, v0, device, nonideal):
        n = alpha.size
        self.alpha, self.beta, self.gamma, self.d = alpha, beta, gamma, d
        self.nonideal = nonideal
        self.x = np.full(n, x0)
        self.v = np.full(n, v0)           # v T
        # Sampled x(k-1), x(k-2): the loop starts at rest.  Two arrays, not
        # one (2, n) array, so that the ideal step can swap them instead of copying.
        self.history = [np.array(self._sample(self.x), dtype=float) for _ in range(2)]
        self.forces = np.zeros((d + 1, n))  # commands waiting in the delay line
        self.k = 0
        self.diverged = np.zeros(n, dtype=bool)
        phi01, phi11, g0, g1 = kernels.plant_step_coefficients(delta)
        self.phi01, self.phi11, self.g0, self.g1 = (float(c) for c in (phi01, phi11, g0, g1))
        self.plant = None
        if device is not None:
            force_scale = device.T**2 / device.m   # physical force -> f T^2 / m
            self.coulomb = (nonideal.coulomb_friction or 0.0) * force_scale
            self.filter_pole = (math.exp(-2 * math.pi * nonideal.velocity_cutoff * device.T)
                                if nonideal.velocity_cutoff else None)
            self.force_limit = (None if nonideal.force_limit is None
                                else nonideal.force_limit * force_scale)
            if nonideal.needs_substeps:
                # Friction and the actuator lag act inside the period: the
                # device (behind its lag) is stepped on its state space, in
                # Table I's units (m = T = 1), with the loop simulator's friction.
                bandwidth = (2 * math.pi * nonideal.actuator_bandwidth * device.T
                             if nonideal.actuator_bandwidth else None)
                space = _paper_space(float(delta), bandwidth, nonideal.substeps)
                state = np.zeros((space.phi.shape[0], n))
                state[0], state[1] = self.x, self.v
                stiction = (nonideal.stiction if nonideal.stiction is not None
                            else (nonideal.coulomb_friction or 0.0)) * force_scale
                self.plant = FrictionPlant(space, state, self.v == 0,
                                           substeps=nonideal.substeps, coulomb=self.coulomb,
                                           stiction=stiction)
        else:
            self.coulomb = 0.0
            self.filter_pole = None
            self.force_limit = None
        self.v_hat = np.zeros(n)          # filtered velocity estimate (times T)
        self.ideal = nonideal.ideal and not nonideal.friction_compensation
        if self.ideal:
            # The force of eq. (1) is linear in the three sampled positions:
            # its coefficients, read from the generated kernel at unit
            # positions, turn each period into a few in-place products.
            # (A coefficient that overflows makes its point diverge at once.)
            unit, zero = np.ones(n), np.zeros(n)
            with np.errstate(over="ignore", invalid="ignore"):
                self.coefficients = [
                    np.asarray(kernels.environment_force(
                        *(unit if j == i else zero for j in range(3)), alpha, beta, gamma),
                        dtype=float)
                    for i in range(3)]
            self._scratch = np.empty(n)

    def _sample(self, x):
        q = self.nonideal.encoder_resolution
        return x if not q else q * np.round(x / q)

    def _command(self, xs):
        x1, x2 = self.history
        if self.filter_pole is None:
            force = kernels.environment_force(xs, x1, x2, self.alpha, self.beta, self.gamma)
            v_est = xs - x1
        else:
            # K x + B v_hat + M (v_hat - v_hat_prev): the damper and mass terms
            # see the filtered velocity (backward difference, first-order LPF).
            a = self.filter_pole
            v_new = a * self.v_hat + (1 - a) * (xs - x1)
            force = -(self.alpha * xs + self.beta * v_new + self.gamma * (v_new - self.v_hat))
            self.v_hat = v_new
            v_est = v_new
        if self.nonideal.friction_compensation:
            force = force + self.coulomb * np.sign(v_est)
        return force

    def step(self):
        if self.ideal:
            self._step_ideal()
        else:
            self._step_general()
        # Overflow is checked every few periods (a third of the work per
        # period otherwise); in between, inf and nan stay confined to their
        # own points and are reset here.
        if self.k % self.check_every == 0:
            self.freeze_diverged()

    def _step_ideal(self):
        """One period of the ideal loop, in place: the general step's sums, in its order."""
        x, v, tmp = self.x, self.v, self._scratch
        c0, c1, c2 = self.coefficients
        x1, x2 = self.history
        command = self.forces[self.k % (self.d + 1)]
        # Summed in the generated kernel's order, so the force is bit-identical.
        np.multiply(c2, x2, out=command)
        np.multiply(c0, x, out=tmp)
        command += tmp
        np.multiply(c1, x1, out=tmp)
        command += tmp
        x2[...] = x               # becomes x(k-1); the old x(k-1) becomes x(k-2)
        self.history = [x2, x1]
        held = self.forces[(self.k - self.d) % (self.d + 1)] if self.k >= self.d else None
        self.k += 1
        # x + phi01 v + g0 f and phi11 v + g1 f, summed in that order.
        np.multiply(self.phi01, v, out=tmp)
        x += tmp
        v *= self.phi11
        if held is not None:
            np.multiply(self.g0, held, out=tmp)
            x += tmp
            np.multiply(self.g1, held, out=tmp)
            v += tmp

    def _step_general(self):
        xs = self._sample(self.x)
        command = self._command(xs)
        if self.force_limit is not None:
            command = np.clip(command, -self.force_limit, self.force_limit)
        self.history[1][...] = self.history[0]
        self.history[0][...] = xs
        slot = self.k % (self.d + 1)
        self.forces[slot] = command
        held = self.forces[(self.k - self.d) % (self.d + 1)] if self.k >= self.d else 0.0 * command
        self.k += 1
        if self.plant is None:
            x, v = self.x, self.v
            self.x = x + self.phi01 * v + self.g0 * held
            self.v = self.phi11 * v + self.g1 * held
        else:
            self.x = self.plant.step(held)
            self.v = self.plant.state[1]

    def freeze_diverged(self):
        """Mark the points whose state left [-1e100, 1e100] or is not finite; zero them."""
        bad = ~(np.abs(self.x) < _OVERFLOW) | ~np.isfinite(self.v)
        if self.plant is not None:
            bad |= ~np.all(np.isfinite(self.plant.state), axis=0)
        if bad.any():
            self.diverged |= bad
            self.x[bad] = 0.0
            self.v[bad] = 0.0
            self.forces[:, bad] = 0.0
            for sampled in self.history:
                sampled[bad] = 0.0
            self.v_hat[bad] = 0.0
            if self.plant is not None:
                self.plant.freeze(bad)


@dataclasses.dataclass(frozen=True)
class StabilityMap(PaperGridNames):
    """Stability by simulation on a grid of the ``(x, y)`` plane.

    Attributes
    ----------
    y_values, x_values : ndarray
        The 1-D grids.
    stable : ndarray of bool
        Shape ``(len(y_values), len(x_values))``.
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
    :class:`~symstab.numeric.results.Limits`.
    """

    y_values: np.ndarray
    x_values: np.ndarray
    stable: np.ndarray
    growth: np.ndarray
    steps: int
    x: str = PAPER_PLANE[0]
    y: str = PAPER_PLANE[1]
    at: dict = dataclasses.field(default_factory=dict)


def stability_map(*, alpha, beta, gamma, d, delta, steps=None, x0=1.0, v0=None, device=None,
                  nonideal=None, progress=None):
    """Stable cells of an (alpha, beta) grid by simulation.

    Parameters
    ----------
    alpha, beta : array_like
        1-D grids.
    gamma, d, delta, steps, x0, v0, device, nonideal
        As in :func:`simulate`.
    progress : callable or True
        ``True`` draws a progress bar on stderr for runs over 2 s.

    Returns
    -------
    StabilityMap

    Raises
    ------
    TypeError, ValueError
        As :func:`simulate`; the grid is simulated in chunks, so the working
        memory does not grow with it (only the result does).
    """
    alpha = check_array("alpha", alpha)
    beta = check_array("beta", beta)
    if alpha.ndim != 1 or beta.ndim != 1:
        raise ValueError("alpha and beta must be 1-D grids")
    gamma = check_real("gamma", gamma)
    d = check_delay(d)
    if progress is not None and progress is not True and not callable(progress):
        raise TypeError(f"progress must be True, a callable taking the number of steps done, "
                        f"or None, got {type(progress).__name__}")
    total = default_horizon(d) if steps is None else steps
    if progress is True:
        progress = progress_printer("simulating", total)
    A, B = np.meshgrid(alpha, beta, indexing="ij")
    run = simulate(alpha=A, beta=B, gamma=gamma, d=d, delta=delta, steps=steps, x0=x0, v0=v0,
                   device=device, nonideal=nonideal, progress=progress)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = np.where(run.diverged, np.inf, run.amplitude[3] / run.amplitude[2])
    return StabilityMap(alpha, beta, run.stable, growth, run.steps, at={
        "gamma": gamma, "d": d, "delta": float(delta if delta is not None else device.delta)})


# --------------------------------------------------------------------------
# Any loop: its plant's pulse transfer function and its environment, stepped


#: Floats held per point besides the delay line and the histories: the
#: position, the sampled position, the force and about five temporaries.
_ANY_LOOP_FLOATS = 8


def simulate_loop(loop, *, steps=None, x0=1.0, v0=None, nonideal=None, record=False,
                  progress=None, **values):
    """Run a :class:`symstab.Loop` for every parameter point at once (:meth:`symstab.Loop.simulate`).

    The plant is its exact ZOH step on the samples: the difference equation
    of ``P(z) = Z[ZOH G] = P_n / P_d``, whose coefficients the loop derives
    (by residues, or the matrix exponential at 30 digits where there is no
    closed form), ``P_d(z) y = P_n(z) u``.  The environment is its
    difference equation ``Ve_d(z) f = Ve_n(z) x_s`` on the sampled position
    ``x_s``, and the force waits ``d`` samples: ``u[k] = -f[k - d]``, the
    loop whose characteristic polynomial is ``chi = z**d Ve_d P_d + Ve_n
    P_n`` (:meth:`symstab.Loop.polynomial`).  The run starts from the
    position ``x0``, earlier positions ``x0 - k v0``, the sampled history at
    ``x0``, no force and an empty delay line; the verdict is
    :func:`simulate`'s.

    Non-idealities (:class:`Nonidealities`, physical units):
    ``encoder_resolution`` rounds the sampled position and ``force_limit``
    clips the force command (a saturated
    unstable loop may settle into a bounded limit cycle, which the verdict
    calls bounded, not growing).  ``coulomb_friction`` (with ``stiction``
    and ``substeps``) acts on the loop's driven mass, after its
    :attr:`~symstab.Loop.actuator`: the plant is then stepped on its
    continuous state space, ``substeps`` exact sub-steps a period, with the
    paper's simulator's stick and reversal rules
    (:mod:`symstab.numeric.friction`).  A velocity filter or an actuator
    lag is part of a loop's own environment or plant.

    Parameters
    ----------
    loop : symstab.Loop
    steps, x0, v0, record, progress
        As in :func:`simulate` (``v0`` is a position change per period,
        default ``x0 / 100``).
    nonideal : Nonidealities, optional
        Only the fields above (and ``substeps``).
    **values
        The loop's parameters (or their defaults); arrays broadcast, ``d``
        one integer.

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
    """
    nonideal = check_loop_nonideal(nonideal, loop)
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable taking the number of steps done, or None, "
                        f"got {type(progress).__name__}")
    parts, d, shape = loop.difference_equations(**values)
    steps = check_steps(steps, d)
    x0 = check_x0(x0)
    v0 = x0 / 100 if v0 is None else check_real("v0", v0, low=-X0_MAX, high=X0_MAX)
    n_points = int(np.prod(shape))
    parts = [np.broadcast_to(p, shape + p.shape[-1:]).reshape(n_points, p.shape[-1])
             for p in parts]
    orders = parts[1].shape[-1] + parts[3].shape[-1]
    point_bytes = 8 * (d + 1 + 2 * orders + sum(p.shape[-1] for p in parts) + _ANY_LOOP_FLOATS)
    if nonideal.coulomb_friction is None:
        def make_run(part):
            return _AnyLoop([p[part] for p in parts], d, x0, v0, nonideal)
    else:
        spaces, inverse = loop.friction_spaces(nonideal.substeps, **values)
        n = spaces[0].phi.shape[0]
        # The state, its two candidates and their temporaries; per-point matrices.
        point_bytes += 8 * (6 * n + 4 + (0 if len(spaces) == 1 else 2 * n * n + 10 * n))

        def make_run(part):
            space = stacked_spaces(spaces, inverse.ravel()[part])
            return _FrictionLoop([p[part] for p in parts], d, x0, v0, nonideal, space)
    return _run_chunks(make_run, n_points, point_bytes, steps=steps, d=d, record=record,
                       progress=progress, nonideal=nonideal, shape=shape)


def check_loop_nonideal(nonideal, loop=None):
    """``nonideal`` (None: ideal) as the :class:`Nonidealities` of a general loop, or raise.

    A general loop has encoder quantization, a force limit and Coulomb
    friction on its driven mass (with ``loop``: checked to have one,
    :meth:`symstab.Loop.driven_mass`); the velocity filter and the actuator
    lag belong in its environment and plant, and friction compensation
    needs the paper's velocity estimate.
    """
    nonideal = Nonidealities() if nonideal is None else nonideal
    if not isinstance(nonideal, Nonidealities):
        raise TypeError(f"nonideal must be a symstab.numeric.simulate.Nonidealities or None, "
                        f"got {type(nonideal).__name__}")
    for field, instead in (("velocity_cutoff", "write the filter into the loop's environment"),
                           ("actuator_bandwidth", "write the lag into the loop's plant"),
                           ("friction_compensation", "a general loop has no velocity estimate "
                            "to compensate with")):
        if getattr(nonideal, field) not in (None, False):
            raise ValueError(f"nonideal.{field}: {instead} (the paper's simulator, "
                             f"symstab.simulate, has it)")
    if loop is not None and nonideal.coulomb_friction is not None:
        try:
            loop.driven_mass
        except ValueError as exc:
            raise ValueError(f"nonideal.coulomb_friction: {exc}") from None
    return nonideal


def _verdict(amplitude, diverged, positions, shape, steps, nonideal):
    """The :class:`Simulation` of a run: unstable when the last quarter outgrows the third."""
    amplitude[:, diverged] = np.inf
    floor = 4 * nonideal.encoder_resolution if nonideal.encoder_resolution else 0.0
    stable = ~diverged & (amplitude[3] <= np.maximum(amplitude[2], floor))
    return Simulation(
        positions=None if positions is None else positions.reshape((steps + 1,) + shape),
        amplitude=amplitude.reshape((4,) + shape),
        diverged=diverged.reshape(shape), stable=stable.reshape(shape), steps=steps)


def _terms(columns):
    """``[(k, coefficient), ...]`` of the nonzero columns of ``(N, k)`` coefficients.

    A column equal at every point is a float (a scalar product is faster).
    """
    out = []
    for k in range(columns.shape[1]):
        column = columns[:, k]
        if np.all(column == 0):
            continue
        out.append((k, float(column[0]) if np.all(column == column[0]) else
                    np.ascontiguousarray(column)))
    return out


class _AnyLoop:
    """A loop's samples for N points: :meth:`step` advances one period.

    ``a``, ``b``: the plant's ``P_d`` (monic, without its leading 1) and
    ``P_n`` (its coefficients of ``z**(n-1) .. 1``); ``c``, ``e``: the
    environment's ``Ve_d`` (monic, without its leading 1) and ``Ve_n``
    (``z**m .. 1``).  Histories are lists, newest first, rotated (no copies);
    the delay line is a ring of the commands themselves, and the plant's
    input history keeps the commands ``f`` (its sum has ``-b``: ``u = -f``).
    """

    def __init__(self, parts, d, x0, v0, nonideal):
        a, b, c, e = parts
        n_points = a.shape[0]
        # Each sum keeps its nonzero terms only (a backward difference's Ve_d
        # is z**k: no force feedback at all), with a float coefficient where
        # every point has the same (the plant of a plane of the environment).
        self.a, self.c = _terms(a), _terms(c)
        self.minus_b = _terms(-b)
        self.e0, self.e = e[:, 0], _terms(e[:, 1:])
        self.e0 = float(self.e0[0]) if np.all(self.e0 == self.e0[0]) else self.e0
        self.d = d
        self.quantum = nonideal.encoder_resolution
        self.force_limit = nonideal.force_limit
        n, m = a.shape[1], c.shape[1]
        self.x = np.full(n_points, float(x0))
        # y[k-1], y[k-2], ... before the start: x0 - k v0; no force applied yet.
        self.y_past = [np.full(n_points, x0 - k * v0) for k in range(1, n + 1)]
        self.f_past_plant = [np.zeros(n_points) for _ in range(n)]
        sampled = self._sample(self.x)
        self.s_past = [np.array(sampled) for _ in range(m)]
        self.f_past = [np.zeros(n_points) for _ in range(m)]
        self.line = [np.zeros(n_points) for _ in range(d + 1)]
        self._scratch = np.empty(n_points)
        self.k = 0
        self.diverged = np.zeros(n_points, dtype=bool)
        self.check_every = _CHECK_EVERY

    def _sample(self, x):
        q = self.quantum
        return x if not q else q * np.round(x / q)

    def _sum(self, out, terms, history, sign):
        tmp = self._scratch
        for k, coefficient in terms:
            np.multiply(coefficient, history[k], out=tmp)
            if sign > 0:
                out += tmp
            else:
                out -= tmp

    def step(self):
        # The environment's force from the sampled position of this instant.
        # (self.x is a new array every period, so the histories may keep it.)
        sampled = self._sample(self.x)
        force = np.multiply(self.e0, sampled)
        self._sum(force, self.e, self.s_past, 1)
        self._sum(force, self.c, self.f_past, -1)
        if self.s_past:
            self.s_past = [sampled] + self.s_past[:-1]
            self.f_past = [force] + self.f_past[:-1]
        # The environment keeps its own force; the command sent is clipped.
        command = (force if self.force_limit is None
                   else np.clip(force, -self.force_limit, self.force_limit))
        slot = self.k % (self.d + 1)
        self.line[slot] = command
        self.k += 1
        # The command of d periods ago (d = 0: this one) drives the plant.
        self.x = self._plant_step(self.line[(slot + 1) % (self.d + 1)] if self.d else command)
        if self.k % self.check_every == 0:
            self.freeze_diverged()

    def _plant_step(self, command):
        """The plant's next sample under ``u = -command``: ``P_d(z) y = P_n(z) u``."""
        self.y_past = [self.x] + self.y_past[:-1]
        self.f_past_plant = [command] + self.f_past_plant[:-1]
        (k, first), *rest = self.minus_b
        x = np.multiply(first, self.f_past_plant[k])
        self._sum(x, rest, self.f_past_plant, 1)
        self._sum(x, self.a, self.y_past, -1)
        return x

    def freeze_diverged(self):
        """Mark the points whose state left [-1e100, 1e100] or is not finite; zero them."""
        bad = ~(np.abs(self.x) < _OVERFLOW)
        for history in (self.y_past, self.f_past_plant, self.f_past):
            for value in history:
                bad |= ~np.isfinite(value)
        if bad.any():
            self.diverged |= bad
            self.x[bad] = 0.0
            for history in (self.line, self.y_past, self.f_past_plant, self.s_past, self.f_past):
                for value in history:
                    value[bad] = 0.0


class _FrictionLoop(_AnyLoop):
    """A loop whose plant is a :class:`~symstab.numeric.friction.FrictionPlant`: Coulomb friction on its mass."""

    def __init__(self, parts, d, x0, v0, nonideal, space):
        super().__init__(parts, d, x0, v0, nonideal)
        self.y_past = self.f_past_plant = []      # the state space holds the plant's past
        self.plant = FrictionPlant.from_history(space, x0, v0, self.x.size, nonideal)

    def _plant_step(self, command):
        return self.plant.step(-command)

    def freeze_diverged(self):
        bad = ~(np.abs(self.x) < _OVERFLOW) | ~np.all(np.isfinite(self.plant.state), axis=0)
        if bad.any():
            self.plant.freeze(bad)
            self.x[bad] = np.inf        # marked diverged below, with everything zeroed
        super().freeze_diverged()


def loop_stability_map(loop, x_values, y_values, *, x=None, y=None, steps=None, x0=1.0, v0=None,
                       nonideal=None, progress=None, **values):
    """Stable cells of an ``(x, y)`` grid of a loop by simulation (:meth:`symstab.Loop.stability_map`).

    Parameters
    ----------
    loop : symstab.Loop
    x_values, y_values : array_like
        1-D grids of the plane's parameters.
    x, y : str, optional
        The plane (default: the loop's :attr:`~symstab.Loop.plane`).
    steps, x0, v0, nonideal, progress
        As in :func:`simulate_loop` (``progress=True`` draws a bar).
    **values
        Single values of the other parameters.

    Returns
    -------
    StabilityMap
    """
    x_values, y_values = check_array(x, x_values), check_array(y, y_values)
    if x_values.ndim != 1 or y_values.ndim != 1:
        raise ValueError(f"the grids of {x} and {y} must be 1-D")
    for name in (x, y):
        if name in values:
            raise TypeError(f"{name} is an axis of the map: give its grid, not a value")
    if progress is True:
        progress = progress_printer("simulating", check_steps(
            steps, check_delay(values.get("d", loop.defaults.get("d", 0)))))
    Y, X = np.meshgrid(y_values, x_values, indexing="ij")
    run = simulate_loop(loop, steps=steps, x0=x0, v0=v0, nonideal=nonideal, progress=progress,
                        **{x: X, y: Y}, **values)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = np.where(run.diverged, np.inf, run.amplitude[3] / run.amplitude[2])
    at = {k: v for k, v in {**loop.defaults, **values}.items() if k not in (x, y)}
    return StabilityMap(y_values, x_values, run.stable, growth, run.steps, x=x, y=y, at=at)
