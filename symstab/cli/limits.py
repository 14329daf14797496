"""``symstab limits``: the largest stable stiffness, the damping range, the stable area.

The paper's loop: alpha_max (K_max), the damping at which it is reached,
the range of damping over the stable region and its area (Z-width), with
--beta/--Bw the stable stiffness intervals at that damping.  A loop file
(``--loop``): the same in its plane (with --at X the stable y at x = X).
Both give the passive set (Colgate-Schenkel) beside the stable one.
"""

import math
import sys
import textwrap

from .loop_limits import LIMITS, limits_notes, limits_table, named, passive_notes, \
    stable_intervals_at
from .loop_options import add_loop_options, resolve_setup
from .options import add_command, add_model_options
from .output import emit

__all__ = ["register", "run"]

#: From this delay on (samples) ``limits`` says on stderr what runs: about a
#: second for the paper's loop at d = 100 and ten at d = 1000 (the passive set too).
_ANNOUNCE_DELAY = 100


def register(subparsers):
    """Add ``symstab limits`` to the sub-commands."""
    p = add_command(
        subparsers, "limits", help="alpha_max, the beta range and the Z-width",
        description="Compute the largest stable stiffness alpha_max (K_max), the damping at "
                    "which it is reached, the range of damping over the stable region and its "
                    "area (Z-width), and with --beta/--Bw the stable stiffness intervals at that "
                    "damping.",
        example="symstab limits --Td 0.04 --Mw 0.0128", func=run)
    p.epilog = ("quantities (table rows and JSON keys of \"limits\"; alpha = K_w T^2 / m,\n"
                "beta = B_w T / m; with --loop the rows are named in the file's plane, K_max, ...,\n"
                "and the JSON keys are y_max, x_at_y_max, x_min, x_max, area):\n"
                + "\n".join(textwrap.fill(meaning.format(x="beta", y="alpha"), 79,
                                         initial_indent=f"  {name:<18} ",
                                         subsequent_indent=" " * 21)
                            for _, _, (name, _), meaning, _ in LIMITS) + "\n\n" + p.epilog)
    add_model_options(p)
    x = p.add_mutually_exclusive_group()
    x.add_argument("--beta", type=float, help="also give the stable alpha interval(s) at this beta")
    x.add_argument("--Bw", type=float, help="also give the stable K_w interval(s) at this damping")
    add_loop_options(p, "limits")


def run(args):
    """Run ``symstab limits`` on a loop file (``--loop``) or the paper's loop: one flow.

    The paper's device options are the paper's loop in Table I's variables
    (:func:`symstab.cli.loop_options.resolve_setup`); its table keeps Table
    I's names (alpha_max, ..., z_width) with the device's units beside them.
    """
    setup = resolve_setup(args)
    at = _line(args, setup)         # checked before the work
    if setup.values["d"] >= _ANNOUNCE_DELAY:
        # Seconds at long delays (the plane's D-decomposition, and the passive set): say what runs.
        print(f"scanning the ({setup.name(setup.x)}, {setup.name(setup.y)}) plane for the "
              "extent of the stable set ...", file=sys.stderr, flush=True)
    lim = named(setup, setup.loop.limits(x=setup.x, y=setup.y, **setup.values))
    columns, rows = limits_table(setup, lim)
    notes, result = limits_notes(setup, lim), {"limits": lim.as_dict()}
    delta = None if setup.paper is None or lim.empty else setup.paper.delta
    if delta is not None and not math.isclose(lim.x_min, -delta, rel_tol=1e-9, abs_tol=1e-12):
        notes.append(f"beta_left = {lim.x_min:.10g} is the leftmost beta of the stable region; "
                     f"the paper's beta_min = -delta = {-delta:.10g} is where the boundary arc "
                     "starts (theta = 0)")
    if at is not None:
        more, line = stable_intervals_at(setup, at)
        notes += more
        if setup.paper is None:
            result["at"] = line
        else:
            result["alpha_intervals"] = {"beta": line["x"], "intervals": line["intervals"],
                                         "ends": line["ends"]}
    more, result["passive"] = passive_notes(setup, lim)
    notes += more
    emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def _line(args, setup):
    """The x of the stable intervals asked for (--at X, or the paper's --beta/--Bw), or None."""
    from .._validate import check_real

    if setup.paper is None:
        return None if args.at is None else check_real(f"--at ({setup.x})", args.at)
    if args.Bw is not None:
        if not setup.paper.physical:
            raise ValueError("--Bw needs a physical device; use --beta with --delta")
        return check_real("beta", float(setup.paper.device.beta(args.Bw)))
    return None if args.beta is None else check_real("beta", args.beta)
