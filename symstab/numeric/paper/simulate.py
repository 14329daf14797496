"""The paper's sampled loop in time: many parameter points at once.

:func:`simulate` and :func:`stability_map` run the paper's loop on the loop
simulator (:meth:`symstab.Loop.simulate`, the run of every
:class:`symstab.Loop`): the loop of
:func:`~symstab.numeric.paper.simulate_theory.paper_simulated_loop` in Table I's
units (``m = T = 1``, ``b = delta``, ``K = alpha``, ``B = beta``, ``M =
gamma``; position, ``v T``, force ``f T**2 / m``), the velocity filter in
its environment and the actuator lag as its actuator, the device on its
state space from the position ``x0`` and the velocity ``v0 / T``
(``start="state"``), a point whose difference equations overflow run as
diverged (``overflow="diverge"``).  :class:`Nonidealities`,
:class:`FrictionCompensation` and :class:`StabilityMap` are importable
from here too.

Non-idealities (:class:`Nonidealities`, physical units, each off by
default) need a :class:`symstab.numeric.paper.device.Device`:

* ``encoder_resolution`` -- the sampled position is rounded to this step;
* ``force_limit`` -- the force command is clipped to this size (the
  amplifier's saturation: an unstable linear loop then grows into a bounded
  limit cycle, which the verdict calls a limit cycle, neither stable nor
  growing: :attr:`Simulation.limit_cycle`);
* ``force_resolution`` -- the force command is rounded to a multiple of
  this quantum (the DAC's step) before the clip; where the linear loop is
  stable the verdict allows the limit cycle the quantum can cause
  (:func:`~symstab.numeric.simulation.simulator.linearly_stable`);
* ``velocity_cutoff`` -- the velocity used by the damper and mass terms is
  the backward difference passed through a first-order low-pass filter
  (pole ``exp(-2 pi f_c T)``, unit DC gain); the mass term differences the
  filtered velocity;
* ``coulomb_friction`` (with ``stiction``, the breakaway force, default
  equal) -- integrated inside the period on ``substeps`` sub-steps: a moving
  device feels ``-F_c sign(v)``; a sub-step that would reverse the velocity
  ends at rest instead, and a device at rest stays there while the applied
  force is within the stiction force (:mod:`symstab.numeric.simulation.friction`, the
  model of every loop's friction);
* ``friction_compensation`` -- the command adds ``F_c sign(v_hat)``, with
  ``v_hat`` the velocity estimate: the backward difference, as for any
  loop with friction (:func:`~symstab.numeric.simulation.simulator.simulate_loop`),
  or with ``velocity_cutoff`` that difference through the velocity filter
  (the loop simulator's
  :class:`~symstab.numeric.simulation.simulator.FrictionCompensation`
  option with the filter's pole);
* ``actuator_bandwidth`` -- the applied force follows the command through a
  first-order lag of that bandwidth: the device behind its lag is stepped
  exactly on its state space (the lag is the loop's actuator, as in
  ``examples/loops/actuator_lag.toml``), at any number of sub-steps.

Stability by simulation (:func:`stability_map`): the run starts from the
position ``x0`` (``1e-100 <= |x0| <= 1e50``, see :func:`simulate`), the
sampled history at ``x0`` (the environment at rest there), a small velocity
(``v0 T = x0 / 100`` by default: starting at rest would leave the modes of
``z = 1`` unexcited at ``alpha = 0``, a constant position being an
equilibrium there) and an empty delay line; a point is unstable when the
largest ``|x|`` over the last quarter of the horizon exceeds that over the
quarter before (the slowest mode grows), or the state overflows.  A
decaying or bounded run is stable, including a limit cycle at the
resolution of the encoder.  The default horizon grows with the delay; near
the boundary the modes have ``|z|`` close to 1 and any finite horizon
leaves a band of undecidable cells, which the tests count.

The theory to compare a run with
(:func:`~symstab.numeric.paper.simulate_theory.linear_theory`) is that of the loop
simulated: its linear part, the velocity filter and the actuator lag
included (a :class:`symstab.Loop`), quantization and friction left out.  On
the README's grid (d = 10, K_w in [0, 70], B_w in [-0.1, 2], 100 x 100) with
a 100 Hz filter the simulation agrees with it on all 9918 cells it decides
(with the ideal loop's count it differed on 1163).
"""

import dataclasses
import math

import numpy as np

from ..._validate import check_array, check_loop, check_progress, check_real, delay_samples
from ..simulation.friction import substeps_of
from ..simulation.simulator import (
    QUANTUM_MIN,
    X0_MAX,
    FrictionCompensation,
    Nonidealities,
    StabilityMap,
    check_friction_size,
    check_steps,
    check_x0,
    default_horizon,
    progress_printer,
)
from .simulate_theory import fractional_start, paper_simulated_loop

__all__ = ["simulate", "stability_map", "check_device_nonideal"]


def simulate(*, alpha, beta, gamma, d, delta, steps=None, x0=1.0, v0=None, device=None,
             nonideal=None, record=False, progress=None):
    """Run the paper's sampled loop for every parameter point at once.

    :meth:`symstab.Loop.simulate` on the paper's loop in Table I's units,
    the device stepped on its state space from ``x0`` and ``v0`` (see the
    module docstring).

    Parameters
    ----------
    alpha, beta, gamma : float or array_like
        Dimensionless stiffness, damping, virtual mass (broadcast together).
    d : int or float
        Delay in samples, ``d >= 0``; a fraction of a period (``40.5``) is
        carried by the loop's fractional plant (see
        :func:`~symstab.numeric.paper.simulate_theory.fractional_start`).
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
    device : symstab.numeric.paper.device.Device
        Needed for the non-idealities (physical units).
    nonideal : Nonidealities
        Off by default.
    record : bool
        Keep every position (memory: ``steps`` times the points).
    progress : callable, bool or None
        Called with the number of steps done (every 1 % or so); True draws
        a bar (``symstab._validate.check_progress``).

    Returns
    -------
    Simulation

    Raises
    ------
    TypeError, ValueError
        For a parameter of the wrong kind or out of range (the message
        names it), and when the run would need more memory than
        ``SYMSTAB_MEMORY_LIMIT`` (see ``symstab._resources``).  Without
        ``record`` the points are simulated in chunks, so the working
        memory does not grow with their number.
    """
    from .device import Device

    if nonideal is None:
        nonideal = Nonidealities()
    elif not isinstance(nonideal, Nonidealities):
        raise TypeError(f"nonideal must be a symstab.numeric.paper.simulate.Nonidealities or None, "
                        f"got {type(nonideal).__name__}")
    if device is not None and not isinstance(device, Device):
        raise TypeError(f"device must be a symstab.Device or None, got {type(device).__name__}")
    d = delay_samples(d)
    fractional_start(d, nonideal)
    progress = check_progress(progress, lambda: progress_printer(
        "simulating", default_horizon(math.ceil(d)) if steps is None else steps))
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
    if delta is None:
        raise TypeError("delta must be a real number (or None with a device), got None")
    delta = check_loop(0.0, math.floor(d), delta)[2]
    # A fractional delay's horizon: that of the next whole delay.
    steps = check_steps(steps, math.ceil(d))
    x0 = check_x0(x0)
    v0 = x0 / 100 if v0 is None else check_real("v0", v0, low=-X0_MAX, high=X0_MAX)
    loop, fixed, run_nonideal = _device_run(nonideal, device, delta, d)
    compensation = None
    if nonideal.friction_compensation and "f_c" in fixed:
        # The estimate low-pass filtered as the paper's loop's velocity
        # filter; unfiltered, the loop simulator's own backward difference.
        pole = math.exp(-2 * math.pi * nonideal.velocity_cutoff * device.T)
        compensation = FrictionCompensation(run_nonideal.coulomb_friction, pole)
    # The device on its state space from (x0, v0 / T) (T = 1 here); a point
    # whose equations overflow (alpha = 1e308) diverges at once, as it always has.
    return loop.simulate(steps=steps, x0=x0, v0=v0, nonideal=run_nonideal, record=record,
                         progress=progress, compensation=compensation,
                         start=fractional_start(d, nonideal), overflow="diverge", **fixed,
                         K=arrays[0], B=arrays[1], M=arrays[2])


def _device_run(nonideal, device, delta, d):
    """The loop the paper's simulator runs, in Table I's units, and its checks before a run.

    Returns ``(loop, values, nonideal)``: the loop, its values but the
    plane's and ``M``, and the non-idealities in its units (forces times
    ``T^2 / m``; the velocity filter and the actuator lag are the loop's
    own, the compensation stays the switch).  Raises, naming the field,
    for a force quantum that is not a normal double in those units or a
    friction that double precision cannot step on the device
    (:func:`check_friction_size`).
    """
    # The paper's loop is a Loop in Table I's units (m = T = 1, b = delta,
    # K = alpha, B = beta, M = gamma), its filter in the environment and its
    # lag in the plant, run by the loop simulator from the state (x0, v0).
    filtered = device is not None and nonideal.velocity_cutoff is not None
    lagged = device is not None and nonideal.actuator_bandwidth is not None
    loop = paper_simulated_loop(filtered, lagged, delta == 0)
    values = {"m": 1.0, "T": 1.0, "d": d}
    if delta != 0:
        values["b"] = delta
    if filtered:
        values["f_c"] = nonideal.velocity_cutoff * device.T
    if lagged:
        values["tau"] = 1 / (2 * math.pi * nonideal.actuator_bandwidth * device.T)
    scale = 1.0 if device is None else device.T**2 / device.m   # force -> f T^2 / m
    if nonideal.force_resolution is not None and not nonideal.force_resolution * scale >= QUANTUM_MIN:
        # The run's quantum is in Table I's units: it must be a normal double there.
        raise ValueError(f"nonideal.force_resolution must be a finite real number >= "
                         f"{QUANTUM_MIN / scale!r} with this device (T^2/m times it is the run's "
                         f"quantum, which must be a normal double), got "
                         f"{nonideal.force_resolution!r}")
    run_nonideal = dataclasses.replace(
        nonideal, velocity_cutoff=None, actuator_bandwidth=None,
        **{name: None if getattr(nonideal, name) is None else getattr(nonideal, name) * scale
           for name in ("coulomb_friction", "stiction", "force_limit", "force_resolution")})
    # The plant's spaces do not hold the delay (a fractional one is refused there).
    spaces, _ = loop.friction_spaces(substeps_of(run_nonideal),
                                     **dict(values, K=0.0, B=0.0, M=0.0, d=math.floor(d)))
    check_friction_size(run_nonideal, spaces, name="nonideal.coulomb_friction", scale=scale)
    return loop, values, run_nonideal


def check_device_nonideal(nonideal, device):
    """Refuse, before a run, non-idealities the paper's simulator cannot step on ``device``.

    The checks :func:`simulate` makes before its run (a force quantum that
    is not a normal double in Table I's units, a friction whose sub-step
    overflows), for a caller that must decide before it prints or runs
    anything (the command line).

    Parameters
    ----------
    nonideal : Nonidealities
    device : symstab.numeric.paper.device.Device

    Raises
    ------
    ValueError
        Naming the field and its range.
    """
    _device_run(nonideal, device, device.delta, 0)


def stability_map(*, alpha, beta, gamma, d, delta, steps=None, x0=1.0, v0=None, device=None,
                  nonideal=None, progress=None):
    """Stable cells of an (alpha, beta) grid by simulation.

    Parameters
    ----------
    alpha, beta : array_like
        1-D grids.
    gamma, d, delta, steps, x0, v0, device, nonideal
        As in :func:`simulate`.
    progress : callable, bool or None
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
    d = delay_samples(d)
    total = default_horizon(math.ceil(d)) if steps is None else steps
    progress = check_progress(progress, lambda: progress_printer("simulating", total))
    A, B = np.meshgrid(alpha, beta, indexing="ij")
    run = simulate(alpha=A, beta=B, gamma=gamma, d=d, delta=delta, steps=steps, x0=x0, v0=v0,
                   device=device, nonideal=nonideal, progress=progress)
    with np.errstate(divide="ignore", invalid="ignore"):
        growth = np.where(run.diverged, np.inf, run.amplitude[3] / run.amplitude[2])
    return StabilityMap(alpha, beta, run.stable, run.limit_cycle, growth, run.steps, at={
        "gamma": gamma, "d": d, "delta": float(delta if delta is not None else device.delta)})

