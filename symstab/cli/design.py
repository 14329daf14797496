"""``symstab design``: the virtual mass that maximises the renderable stiffness.

The paper's loop: the virtual mass gamma = M_w / m that maximises the
largest stable stiffness for one delay and device, with that stiffness,
its damping and the gain over no virtual mass.  A loop file (``--loop``):
the largest stable y, the x where it is reached, and the stable intervals
of y there (or at --at X).
"""

import dataclasses
import math
import sys

from .loop_limits import limits_notes, limits_result, limits_rows, stable_intervals_at
from .loop_options import add_loop_options, resolve_loop, uses_loop
from .options import add_command, add_model_options, resolve
from .output import emit

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab design`` to the sub-commands."""
    p = add_command(
        subparsers, "design", help="the virtual mass that maximises the renderable stiffness",
        description="Search the virtual mass gamma = M_w / m that maximises the largest stable "
                    "stiffness for one delay and device, and report that stiffness, its damping "
                    "and the gain over no virtual mass.",
        example="symstab design --Td 0.04", func=run)
    add_model_options(p)
    add_loop_options(p, "design")


def run(args):
    """Run ``symstab design`` (on the loop file of ``--loop``, else the paper's loop)."""
    return _loop(args) if uses_loop(args) else _paper(args)


def _paper(args):
    """The best virtual mass of the paper's loop for one delay and device."""
    from ..numeric.region import best_virtual_mass, limits

    setup = resolve(args, mass=False)
    print("searching gamma for the largest renderable stiffness ...", file=sys.stderr, flush=True)
    best = best_virtual_mass(d=setup.d, delta=setup.delta)
    rows = [("gamma (best)", best.gamma), ("beta at alpha_max", best.beta),
            ("alpha_max", best.alpha_max), ("alpha_max at gamma = 0", best.alpha_max_gamma0),
            ("gain", best.gain), ("Z-width at the best gamma", best.z_width)]
    columns = ["quantity", "value"]
    if setup.physical:
        dev, u = setup.device, setup.units
        area = dev.m**2 / dev.T**3
        physical = [(dev.mass(best.gamma), "M_w", u["M_w"]), (dev.damping(best.beta), "B_w", u["B_w"]),
                    (dev.stiffness(best.alpha_max), "K_max", u["K_w"]),
                    (dev.stiffness(best.alpha_max_gamma0), "K_max (M_w = 0)", u["K_w"]),
                    (best.gain, "gain", ""),
                    (best.z_width * area, "Z-width", f"({u['B_w']})({u['K_w']})")]
        columns += ["physical", "physical value", "unit"]
        rows = [r + (label, value, unit) for r, (value, label, unit) in zip(rows, physical)]
    result = {"best": {k: v for k, v in dataclasses.asdict(best).items() if k not in ("d", "delta")}}
    notes = ["the virtual mass argument --gamma/--Mw is ignored: design searches over it"] \
        if (args.gamma is not None or args.Mw is not None) else []
    if best.z_width < 0.05 * limits(gamma=0.0, d=setup.d, delta=setup.delta).z_width:
        notes.append("the best gamma lies where the stable region is a thin sliver: the gain "
                     "needs very precise tuning of the virtual mass and damping")
    emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def _loop(args):
    """A loop file's largest stable y and the stable intervals of y there."""
    setup = resolve_loop(args)
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
    print(f"searching the ({setup.x}, {setup.y}) plane for the largest stable {setup.y} ...",
          file=sys.stderr, flush=True)
    lim = setup.loop.limits(x=setup.x, y=setup.y, **setup.values)
    rows = limits_rows(setup, lim)[:2]
    notes = limits_notes(setup, lim)
    result = limits_result(lim)
    at = args.at
    if at is None and not lim.empty and math.isfinite(lim.x_at_y_max):
        at = lim.x_at_y_max
    if at is not None:
        more, result["at"] = stable_intervals_at(setup, at)
        notes += more
        runs = result["at"]["intervals"]
        if runs:
            lo, hi = runs[-1]
            rows.append((f"{setup.y} range at {setup.x} = {at:.6g}", hi - lo, setup.unit(setup.y),
                         f"width of the top stable interval of {setup.y} at that {setup.x}"))
            if args.at is None and hi - lo < 0.05 * lim.y_max:
                notes.append(f"{setup.y}_max is reached at the tip of a thin sliver of the stable "
                             f"set: it needs precise tuning of {setup.x}; give --at X for the "
                             f"stable {setup.y} at another {setup.x}")
    notes.append(f"design --loop does not search a third parameter (the paper's design searches "
                 f"the virtual mass): compare {setup.y}_max for a few --set values of it")
    emit(setup, args.format, ["quantity", "value", "unit", "meaning"], rows, result=result,
         notes=notes, json_rows=False)
    return 0
