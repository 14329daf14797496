"""``symstab simulate``: simulate a loop at one point; write its trajectory as CSV.

The paper's loop by default (its options build the paper's loop, with the
velocity filter and the actuator lag in it, run by the paper's adapter on
the loop simulator, :func:`symstab.numeric.paper.simulate.simulate`); a
loop file with ``--loop`` (its values changed by ``--set``), run by
:meth:`symstab.Loop.simulate`.  Both go through one flow: a plan of the run
(checked before anything runs or is printed), the run, the same verdict
(stable, a limit cycle, held at rest by friction) and the same files.

The device and delay options are those of the numeric commands
(:mod:`symstab.cli.options`), the non-idealities those of
:mod:`symstab.cli.simulation`.  The output path is checked before the
simulation and the file is written atomically (:mod:`symstab.cli.output`):
a failed or interrupted run leaves nothing behind.
"""

import dataclasses
import io
import math
import re

import numpy as np

from .._resources import check_memory
from .loop_options import add_loop_options, loop_echo, resolve_loop, uses_loop, value_text
from .options import (
    add_command,
    add_model_options,
    add_point_options,
    parse_one,
    resolve,
    stiffness_and_damping,
)
from .output import check_files, write_output
from .simulation import (
    add_nonideal_options,
    check_loop_friction,
    loop_nonideal_text,
    resolve_nonideal,
    simulated_theory,
    with_option_names,
)

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
    add_point_options(p)
    p.add_argument("--out", help="CSV file for the trajectory (k, t, x)")
    g = p.add_argument_group("a delay that varies from period to period (with --loop)")
    g.add_argument("--delays", metavar="uniform:DMIN:DMAX",
                   help="each period's delay drawn uniformly from the whole samples DMIN..DMAX, "
                        "instead of the loop's d (Loop.simulate's delays); both may share a "
                        "fraction of a period, the plant's (uniform:2.5:4.5)")
    g.add_argument("--seed", type=int, metavar="S",
                   help="seed of the --delays draws (default 0: the same run every time)")
    add_loop_options(p, "simulate")


@dataclasses.dataclass
class _Plan:
    """One simulation, checked and ready to run: what the flow prints and writes around it.

    The paper's options and a loop file (``--loop``) each build one; the
    rest of ``symstab simulate`` is the same for both.
    """

    run: object             # run(): the Simulation (the paper's loop or the loop file's)
    x0: float
    nonideal: object        # the Nonidealities simulated
    code: int               # the theory's root count: STABLE, MARGINAL or UNSTABLE
    radius: float           # the theory's spectral radius
    theory: str             # what the theory is, for its line
    echo: list              # the inputs' echo, printed once the run is done
    point: str = None       # the point's line (the paper's options), or None
    conditions: str = ""    # the non-idealities beside the run's line (a loop file's)
    csv_header: str = ""    # the trajectory's CSV header (without its newline)
    period: float = 1.0     # seconds (or periods) per step, the CSV's t column
    record: bool = False    # the trajectory is kept (for --out, or the verdict)


def run(args):
    """Run ``symstab simulate``; return the exit status."""
    if args.format != "table":
        raise ValueError(f"--format {args.format}: simulate prints its verdict as text and "
                         f"writes the trajectory as CSV with --out")
    plan = _loop_plan(args) if uses_loop(args) else _paper_plan(args)
    return _simulate(args, plan)


def _paper_plan(args):
    """The paper's loop at one point of the paper's options: the loop simulated, its theory."""
    from .._progress import progress_printer
    from ..numeric.paper.simulate import simulate
    from ..numeric.simulation.simulator import check_steps

    setup = resolve(args)
    alpha, beta = _point(args, setup)
    nonideal, x0 = resolve_nonideal(args, setup)
    _check_out(args.out)
    # A fractional delay's horizon: that of the next whole delay.
    steps = check_steps(args.steps, math.ceil(setup.d))
    record = args.out is not None
    if record:
        check_memory(f"the --out trajectory of {steps} periods", (steps + 1) * _TRAJECTORY_ROW_BYTES)
    # The theory is that of the loop simulated (its linear part), decided
    # before the run so that a refusal costs no simulation.
    theory = simulated_theory(setup, nonideal)
    code = theory.classify(alpha, beta)
    radius = theory.spectral_radius(alpha, beta)

    def run_paper():
        try:
            return simulate(alpha=alpha, beta=beta, gamma=setup.gamma, d=setup.d,
                            delta=None if setup.physical else setup.delta, steps=steps, x0=x0,
                            device=setup.device, nonideal=nonideal, record=record,
                            progress=progress_printer("simulating", steps))
        except (TypeError, ValueError) as exc:
            # Its checks before the run (the friction against the device) name the options.
            raise with_option_names(exc) from None

    point = (f"point: alpha = {alpha:.10g}, beta = {beta:.10g}"
             + (f" (K_w = {float(setup.device.stiffness(alpha)):.10g} {setup.units['K_w']}, "
                f"B_w = {float(setup.device.damping(beta)):.10g} {setup.units['B_w']})"
                if setup.physical else ""))
    header = (("k,t [s]," if setup.physical else "k,t [T],")
              + ("x [rad]" if setup.physical and not args.linear else
                 "x [m]" if setup.physical else "x"))
    return _Plan(run_paper, x0, nonideal, code, radius, theory.description, setup.echo,
                 point=point, csv_header=header,
                 period=setup.device.T if setup.physical else 1.0, record=record)


def _loop_plan(args):
    """A loop file at its values changed by ``--set``: the loop simulated, its root count."""
    from .._progress import progress_printer
    from ..numeric.simulation.simulator import check_steps

    setup = resolve_loop(args, plane=False)
    delays, setup = _varying_delays(args, setup)
    loop, values = setup.loop, setup.values
    nonideal, x0 = resolve_nonideal(args, None, loop)
    _check_out(args.out)
    # A fractional delay's horizon: that of the next whole delay.
    steps = check_steps(args.steps, math.ceil(values["d"]))
    # One point: its trajectory is kept (the verdict tells a mass held by
    # friction from a limit cycle by it).
    check_memory(f"the trajectory of {steps} periods", (steps + 1) * _TRAJECTORY_ROW_BYTES)
    loop.difference_equations(**values)        # a plant it cannot step is refused before the run
    check_loop_friction(nonideal, loop, values)
    code = int(loop.classify(**values))
    radius = float(loop.spectral_radius(**values))
    theory, conditions = "the loop's certified root count", loop_nonideal_text(nonideal)
    varying = {}
    if delays is not None:
        # The run's delay is the sequence's; the theory that of its longest fixed delay.
        varying = {"delays": delays, "seed": args.seed}
        values = {name: value for name, value in values.items() if name != "d"}
        if nonideal.force_resolution is not None:
            raise ValueError("--force-resolution with --delays: the verdict's floor for a force "
                             "quantum is the fixed-delay loop's pulse response; drop one")
        theory += f" at the longest delay, a fixed d = {delays[2]}; a varying delay has none"
        conditions += (f"; delay uniform on {delays[1]}..{delays[2]} samples, drawn with seed "
                       f"{0 if args.seed is None else args.seed}")

    def run_file():
        return loop.simulate(steps=steps, x0=x0, nonideal=nonideal, record=True,
                             progress=progress_printer("simulating", steps), **varying, **values)

    return _Plan(run_file, x0, nonideal, code, radius, theory,
                 setup.echo, conditions=f" ({conditions})",
                 csv_header=f"k,t [s],x (SI; {value_text(setup, 'T', values['T'])})",
                 period=float(values["T"]), record=True)


def _varying_delays(args, setup):
    """``(delays, setup)``: ``--delays uniform:DMIN:DMAX`` as ``("uniform", DMIN, DMAX)`` (or None).

    With it the setup's ``d`` is the longest delay (its horizon, its
    theory and the checks of its plant) and its echo leaves ``d`` out.
    """
    from ..numeric.simulation.simulator import delay_sequence, shared_fraction

    if args.delays is None:
        if args.seed is not None:
            raise ValueError("--seed draws the delays of --delays uniform:DMIN:DMAX: give "
                             "--delays, or drop --seed")
        return None, setup
    law, *bounds = args.delays.split(":")
    try:
        ends = [float(b) if "." in b else int(b) for b in bounds]
    except ValueError:
        ends = None
    if law != "uniform" or len(bounds) != 2 or ends is None:
        raise ValueError(f"--delays must be uniform:DMIN:DMAX with samples 0 <= DMIN <= DMAX "
                         f"(whole, or sharing a fraction: uniform:2.5:4.5), got {args.delays!r}")
    delays = ("uniform", *ends)
    given = [name for name in ("d", "Td") if name in setup.given]
    if given:
        raise ValueError(f"--delays is the delay: drop --set {given[0]}=... (or --d)")
    try:
        # Checked before anything runs.
        whole, fraction = shared_fraction(delays)
        delay_sequence(whole, 8, args.seed)
    except (TypeError, ValueError) as exc:
        raise ValueError(re.sub(r"(?<![\w-])(delays|seed)\b", r"--\1", str(exc))) from None
    longest = whole[2] + fraction if fraction else whole[2]
    setup = dataclasses.replace(setup, values={**setup.values, "d": longest})
    echo = loop_echo(dataclasses.replace(setup, values={
        name: value for name, value in setup.values.items() if name != "d"}))
    return delays, dataclasses.replace(setup, echo=echo)


def _simulate(args, plan):
    """Run ``plan``; print the inputs, the verdict and the theory; write the trajectory."""
    from ..numeric.engine.roots import MARGINAL, STABLE, UNSTABLE

    run = plan.run()
    for line in plan.echo:
        print(line)
    if plan.point is not None:
        print(plan.point)
    print(f"simulated {run.steps} periods from x0 = {plan.x0:g}{plan.conditions}: "
          f"{_verdict(run, plan.nonideal)}; max |x| per quarter: "
          + ", ".join(f"{a:.4g}" for a in run.amplitude))
    print(f"theory ({plan.theory}): spectral radius {plan.radius:.12g} -> "
          + {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable"}[plan.code])
    if args.out is not None:
        k = np.arange(run.steps + 1)
        buf = io.StringIO()
        buf.write(plan.csv_header + "\n")
        np.savetxt(buf, np.column_stack([k, k * plan.period, run.positions]), delimiter=",",
                   fmt=["%d", "%.9g", "%.17g"])
        write_output(args.out, buf.getvalue(), "--out")
        print(f"wrote the trajectory to {args.out}")
    return 0


def _verdict(run, nonideal):
    """The run's verdict in words: stable, unstable, a limit cycle, held at rest by friction."""
    verdict = "diverged (unstable)" if run.diverged else ("stable" if run.stable else "unstable")
    if run.limit_cycle:
        # The simulator's class (Simulation.limit_cycle), as the map's cells.
        return (f"bounded, not decaying (a limit cycle of amplitude {run.amplitude[3]:.4g}: "
                f"neither stable nor growing)")
    if run.positions is not None:
        last = run.positions[-(run.steps // 4):]
        if run.stable and np.all(last == last[-1]) and nonideal.coulomb_friction is not None:
            return f"stable (held at rest by friction at x = {last[-1]:.4g})"
    if run.stable and 0.9 * run.amplitude[2] <= run.amplitude[3] <= run.floor:
        return (f"bounded (a limit cycle of amplitude {run.amplitude[3]:.4g}, within "
                f"{float(run.floor):.4g}, the most the quantization can move the "
                f"position here)")
    return verdict


def _check_out(out):
    """``--out``: a .csv file in a writable folder (the trajectory is CSV), checked first."""
    if out is not None and not str(out).endswith(".csv"):
        raise ValueError(f"--out must end in .csv (the trajectory is written as CSV), got {out}")
    check_files([("--out", out)])


def _point(args, setup):
    alpha, beta = stiffness_and_damping(args, setup, parse_one)
    return float(alpha), float(beta)
