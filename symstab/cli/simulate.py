"""``symstab simulate``: simulate a loop at one point; write its trajectory as CSV.

The paper's loop by default; a loop file with ``--loop`` (its values
changed by ``--set``), run by :meth:`symstab.Loop.simulate`.

The device and delay options are those of the numeric commands
(:mod:`symstab.cli.options`), the non-idealities those of
:mod:`symstab.cli.simulation`.  The output path is checked before the
simulation and the file is written atomically (:mod:`symstab.cli.output`):
a failed or interrupted run leaves nothing behind.
"""

import io

import numpy as np

from .._resources import check_memory
from .loop_options import add_loop_options, resolve_loop, uses_loop, value_text
from .options import add_command, add_model_options, parse_list, resolve, stiffness_and_damping
from .output import check_files, write_output
from .simulation import (add_nonideal_options, check_loop_friction, loop_nonideal_text,
                         resolve_nonideal, simulated_theory, with_option_names)

__all__ = ["register", "run"]

#: Bytes of CSV text per trajectory row ("k,t,x" with 17 digits), with the
#: Python objects that build them (generous).
_TRAJECTORY_ROW_BYTES = 120


def register(subparsers):
    """Add ``symstab simulate`` to the sub-commands."""
    p = add_command(
        subparsers, "simulate", help="simulate one point; write its trajectory as CSV",
        description="Simulate the sampled loop at one stiffness-damping point, with the "
                    "encoder quantization, velocity filter, friction and actuator lag you "
                    "switch on, and compare its verdict with the root count of the loop simulated "
                    "(its linear part, the filter and the actuator lag included; quantization "
                    "and friction are left out).",
        example="symstab simulate --Td 0.01 --Kw 30 --Bw 1 --paper-encoder --out trajectory.csv",
        func=run)
    add_model_options(p)
    add_nonideal_options(p)
    p.add_argument("--alpha", help="dimensionless stiffness")
    p.add_argument("--beta", help="dimensionless damping")
    p.add_argument("--Kw", help="virtual stiffness (physical)")
    p.add_argument("--Bw", help="virtual damping (physical)")
    p.add_argument("--out", help="CSV file for the trajectory (k, t, x)")
    add_loop_options(p, "simulate")


def run(args):
    """Run ``symstab simulate``; return the exit status."""
    if args.format != "table":
        raise ValueError(f"--format {args.format}: simulate prints its verdict as text and "
                         f"writes the trajectory as CSV with --out")
    if uses_loop(args):
        return _loop(args)
    from ..numeric.paper.simulate import simulate
    from ..numeric.engine.roots import MARGINAL, STABLE, UNSTABLE
    from .._progress import progress_printer
    from ..numeric.simulation.simulator import check_steps

    setup = resolve(args)
    alpha, beta = _point(args, setup)
    nonideal, x0 = resolve_nonideal(args, setup)
    _check_out(args.out)
    steps = check_steps(args.steps, setup.d)
    record = args.out is not None
    if record:
        check_memory(f"the --out trajectory of {steps} periods", (steps + 1) * _TRAJECTORY_ROW_BYTES)
    # The theory is that of the loop simulated (its linear part), decided
    # before the run so that a refusal costs no simulation.
    theory = simulated_theory(setup, nonideal)
    code = theory.classify(alpha, beta)
    radius = theory.spectral_radius(alpha, beta)
    try:
        run = simulate(alpha=alpha, beta=beta, gamma=setup.gamma, d=setup.d,
                       delta=None if setup.physical else setup.delta, steps=steps, x0=x0,
                       device=setup.device, nonideal=nonideal, record=record,
                       progress=progress_printer("simulating", steps))
    except (TypeError, ValueError) as exc:
        # Its checks before the run (the friction against the device) name the options.
        raise with_option_names(exc) from None
    for line in setup.echo:
        print(line)
    verdict = "diverged (unstable)" if run.diverged else ("stable" if run.stable else "unstable")
    amp = run.amplitude
    print(f"point: alpha = {alpha:.10g}, beta = {beta:.10g}"
          + (f" (K_w = {float(setup.device.stiffness(alpha)):.10g} {setup.units['K_w']}, "
             f"B_w = {float(setup.device.damping(beta)):.10g} {setup.units['B_w']})" if setup.physical else ""))
    print(f"simulated {run.steps} periods from x0 = {x0:g}: {verdict}; max |x| per quarter: "
          + ", ".join(f"{a:.4g}" for a in amp))
    print(f"theory ({theory.description}): spectral radius {radius:.12g} -> "
          + {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable"}[code])
    if args.out is not None:
        k = np.arange(run.steps + 1)
        t = k * (setup.device.T if setup.physical else 1.0)
        buf = io.StringIO()
        buf.write(("k,t [s]," if setup.physical else "k,t [T],")
                  + ("x [rad]" if setup.physical and not args.linear else
                     "x [m]" if setup.physical else "x") + "\n")
        np.savetxt(buf, np.column_stack([k, t, run.positions]), delimiter=",", fmt=["%d", "%.9g", "%.17g"])
        write_output(args.out, buf.getvalue(), "--out")
        print(f"wrote the trajectory to {args.out}")
    return 0


def _loop(args):
    """A loop file simulated at its values changed by ``--set``, its root count beside."""
    from .._progress import progress_printer
    from ..numeric.simulation.simulator import check_steps
    from ..numeric.engine.roots import MARGINAL, STABLE, UNSTABLE

    setup = resolve_loop(args, plane=False)
    loop, values = setup.loop, setup.values
    nonideal, x0 = resolve_nonideal(args, None, loop)
    _check_out(args.out)
    steps = check_steps(args.steps, values["d"])
    record = args.out is not None
    # One point: its trajectory is kept (the verdict tells a mass held by
    # friction from a limit cycle by it).
    check_memory(f"the trajectory of {steps} periods", (steps + 1) * _TRAJECTORY_ROW_BYTES)
    loop.difference_equations(**values)        # a plant it cannot step is refused before the run
    check_loop_friction(nonideal, loop, values)
    code = int(loop.classify(**values))
    radius = float(loop.spectral_radius(**values))
    run = loop.simulate(steps=steps, x0=x0, nonideal=nonideal, record=True,
                        progress=progress_printer("simulating", steps), **values)
    for line in setup.echo:
        print(line)
    verdict = "diverged (unstable)" if run.diverged else ("stable" if run.stable else "unstable")
    last = run.positions[-(run.steps // 4):]
    if run.limit_cycle:
        # The simulator's class (Simulation.limit_cycle), as the map's cells.
        verdict = (f"bounded, not decaying (a limit cycle of amplitude {run.amplitude[3]:.4g}: "
                   f"neither stable nor growing)")
    elif run.stable and np.all(last == last[-1]) and nonideal.coulomb_friction is not None:
        verdict = f"stable (held at rest by friction at x = {last[-1]:.4g})"
    elif run.stable and 0.9 * run.amplitude[2] <= run.amplitude[3] <= run.floor:
        verdict = (f"bounded (a limit cycle of amplitude {run.amplitude[3]:.4g}, within "
                   f"{float(run.floor):.4g}, the most the quantization can move the "
                   f"position here)")
    print(f"simulated {run.steps} periods from x0 = {x0:g} ({loop_nonideal_text(nonideal)}): "
          f"{verdict}; max |x| per quarter: " + ", ".join(f"{a:.4g}" for a in run.amplitude))
    print(f"theory (the loop's certified root count): spectral radius {radius:.12g} -> "
          + {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable"}[code])
    if record:
        k = np.arange(run.steps + 1)
        buf = io.StringIO()
        buf.write(f"k,t [s],x (SI; {value_text(setup, 'T', values['T'])})\n")
        np.savetxt(buf, np.column_stack([k, k * float(values["T"]), run.positions]),
                   delimiter=",", fmt=["%d", "%.9g", "%.17g"])
        write_output(args.out, buf.getvalue(), "--out")
        print(f"wrote the trajectory to {args.out}")
    return 0


def _check_out(out):
    """``--out``: a .csv file in a writable folder (the trajectory is CSV), checked first."""
    if out is not None and not str(out).endswith(".csv"):
        raise ValueError(f"--out must end in .csv (the trajectory is written as CSV), got {out}")
    check_files([("--out", out)])


def _single(text, name):
    values = parse_list(text, name)
    if values.size != 1:
        raise ValueError(f"{name} takes one value here, got {values.size}")
    return float(values[0])


def _point(args, setup):
    alpha, beta = stiffness_and_damping(args, setup, _single)
    return float(alpha), float(beta)
