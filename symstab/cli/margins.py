"""``symstab margins``: how far a stable point is from instability.

At one stable point of a loop file (``--loop FILE --set NAME=VALUE``) or of
the paper's loop (its device options and one stiffness and damping):
the modulus margin ``min |1 + L|`` on the unit circle (certified), every
gain and phase margin of the sampled open loop, the stable interval
through the point of each plane parameter, and the delay margin, exact and
in whole samples (:func:`symstab.numeric.analysis.margins.margins`).  With
``--delay-range TMIN TMAX``, whether the point is stable for every constant
delay of the range and for every delay that varies in it by whole samples
(:func:`symstab.numeric.analysis.delay_range.delay_range`).  An unstable or
marginal point is one line and exit 2, before any work.
"""

import math

from .loop_options import add_loop_options, resolve_setup
from .options import (
    add_command,
    add_model_options,
    add_point_options,
    parse_one,
    stiffness_and_damping,
)
from .output import emit

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab margins`` to the sub-commands."""
    p = add_command(
        subparsers, "margins", help="how far a stable point is from instability",
        description="At one stable point: the modulus margin min|1 + L| of the sampled open "
                    "loop L on the unit circle (certified to a relative 1e-9), every gain "
                    "margin (at each phase crossover) and phase margin (at each gain "
                    "crossover), the stable interval of each plane parameter through the "
                    "point, and the delay margin: the smallest added delay (exact, from the "
                    "fractional-delay derivation) at which a root reaches the unit circle, "
                    "and the fewest whole samples of added delay at which the loop is no "
                    "longer stable.",
        example="symstab margins --Td 0.005 --Kw 100 --Bw 1", func=run)
    add_model_options(p)
    add_point_options(p)
    p.add_argument("--along", metavar="NAME", action="append",
                   help="with --loop: a parameter whose stable interval through the point is "
                        "given (repeatable; default the file's plane)")
    p.add_argument("--delay-range", nargs=2, metavar=("TMIN", "TMAX"),
                   help="a range of loop delays (a time: 40ms, or seconds): stable for every "
                        "constant delay of it, and for every delay varying in it by whole "
                        "samples (a small-gain bound, sufficient only)")
    add_loop_options(p, "margins")


def run(args):
    """Run ``symstab margins``: a loop file's point (``--loop``), else the paper's."""
    setup = resolve_setup(args, plane=False)
    values = dict(setup.values)
    T = None
    if setup.paper is not None:
        alpha, beta = stiffness_and_damping(args, setup.paper, parse_one)
        values.update(K=float(alpha), B=float(beta))
        if setup.paper.physical:
            T = setup.paper.device.T
    if args.along is not None and setup.paper is not None:
        raise ValueError("--along needs a loop file: give --loop FILE (the paper's loop gives "
                         "its damping and stiffness)")
    delays = None
    if args.delay_range is not None:
        from .loop_options import delay_range_option

        delays = delay_range_option(args.delay_range, setup.loop, values)
    found = setup.loop.margins(parameters=args.along, **values)
    T = found.T if T is None and setup.paper is None else T
    columns = ["margin", "value", "theta [rad/sample]", "frequency [Hz]", "note"]
    rows = [("modulus min|1+L|", found.modulus, found.modulus_theta,
             _hz(found.modulus_theta, T), f"certified >= {found.modulus_lower:.10g}")]
    rows += [("gain", c.margin, c.theta, _hz(c.theta, T), "phase crossover") for c in found.gain]
    rows += [("phase [deg]", c.margin, c.theta, _hz(c.theta, T), "gain crossover")
             for c in found.phase]
    for p in found.parameters:
        name = setup.label(p.name)
        rows.append((f"{name} down to", p.low, None, None, f"from {p.value:.6g}"))
        rows.append((f"{name} up to", p.high, None, None, f"from {p.value:.6g}"))
    exact = found.exact_delay
    if exact is not None and exact.margin is not None:
        first = exact.switches[0]
        rows.append(("delay [samples]", first.added, first.theta, _hz(first.theta, T),
                     f"exact: a root on the unit circle at d = {first.samples:.9g}"))
    rows.append(("delay, whole [samples]", found.delay, None, None, found.delay_note))
    notes = ["L: the open loop VE(z) z^-d P(z), P the plant behind the zero-order hold "
             "(delayed by a fraction of a period where d is not whole); the exact delay "
             "margin is the fractional-delay derivation's, the whole one what added whole "
             "samples of computation can afford"]
    if T is None:
        notes.append("frequency: give the device's physical options (not --delta) for Hz")
    result = {"margins": found.as_dict()}
    if delays is not None:
        ranged = setup.loop.delay_range(delay_range=delays,
                                        **{k: v for k, v in values.items() if k != "d"})
        rows += [(quantity, value, None, None, note) for quantity, value, note in ranged.rows()]
        result["delay_range"] = ranged.as_dict()
        notes.append("every varying delay: the discrete-time Kao-Lincoln small-gain bound "
                     "(sufficient, not necessary), for delays varying by whole samples")
    emit(setup, args.format, columns, rows, notes=notes, result=result)
    return 0


def _hz(theta, T):
    return None if T is None else theta / (2 * math.pi * T)
