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

from .loop_limits import limits_notes, limits_result, limits_rows, stable_intervals_at
from .loop_options import add_loop_options, resolve_setup
from .options import add_command, add_model_options
from .output import emit, number_text

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab limits`` to the sub-commands."""
    p = add_command(
        subparsers, "limits", help="alpha_max, the beta range and the Z-width",
        description="Compute the largest stable stiffness alpha_max (K_max), the damping at "
                    "which it is reached, the range of damping over the stable region and its "
                    "area (Z-width), and with --beta/--Bw the stable stiffness intervals at that "
                    "damping.",
        example="symstab limits --Td 0.04 --Mw 0.0128", func=run)
    p.epilog = "quantities (table rows and JSON keys of \"limits\"):\n" + "\n".join(
        textwrap.fill(meaning, 79, initial_indent=f"  {name:<18} ", subsequent_indent=" " * 21)
        for name, _, meaning, _, _ in _LIMITS) + "\n\n" + p.epilog
    add_model_options(p)
    x = p.add_mutually_exclusive_group()
    x.add_argument("--beta", type=float, help="also give the stable alpha interval(s) at this beta")
    x.add_argument("--Bw", type=float, help="also give the stable K_w interval(s) at this damping")
    add_loop_options(p, "limits")


def run(args):
    """Run ``symstab limits``: a loop file's plane (``--loop``), else the paper's; one flow.

    The paper's device options are the paper's loop in Table I's variables
    (:func:`symstab.cli.loop_options.resolve_setup`); its table keeps Table
    I's names (alpha_max, ..., z_width) with the device's units beside them.
    """
    from ..numeric.region import limits

    setup = resolve_setup(args)
    at = _line(args, setup)         # checked before the work
    if setup.paper is None:
        # Seconds at long delays (the plane's D-decomposition, and the passive set): say what runs.
        print(f"scanning the ({setup.x}, {setup.y}) plane for the extent of the stable set ...",
              file=sys.stderr, flush=True)
        lim = setup.loop.limits(x=setup.x, y=setup.y, **setup.values)
        columns, rows = ["quantity", "value", "unit", "meaning"], limits_rows(setup, lim)
        notes, result = limits_notes(setup, lim), limits_result(lim)
    else:
        paper = setup.paper
        lim = limits(gamma=paper.gamma, d=paper.d, delta=paper.delta)
        columns, rows = _limits_rows(paper, lim)
        notes, result = _paper_notes(paper, lim), {"limits": _limits_json(lim)}
    if at is not None:
        more, line = stable_intervals_at(setup, at)
        notes += more
        if setup.paper is None:
            result["at"] = line
        else:
            result["alpha_intervals"] = {"beta": line["x"], "intervals": line["intervals"],
                                         "ends": line["ends"]}
    more, result["passive"] = (_loop_passive(setup, lim) if setup.paper is None
                               else _passive(setup.paper, lim))
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


def _paper_notes(setup, lim):
    """Why the paper's region is empty, or that its leftmost beta is not the paper's beta_min."""
    notes = [lim.message] if lim.message else []
    if not lim.empty and not math.isclose(lim.beta_left, -setup.delta, rel_tol=1e-9, abs_tol=1e-12):
        notes.append(f"beta_left = {lim.beta_left:.10g} is the leftmost beta of the stable region; "
                     f"the paper's beta_min = -delta = {-setup.delta:.10g} is where the boundary "
                     "arc starts (theta = 0)")
    return notes


#: The quantities of ``symstab limits``: (name in the table and the JSON, attribute of
#: :class:`symstab.numeric.region.Limits`, meaning, physical name, physical unit).  The
#: names say what each is: ``beta_left``/``beta_right`` are the ends of the
#: stable region's beta range, which a reader of the paper would otherwise take
#: for its beta_min = -delta, the damping where the boundary arc starts.
_LIMITS = (
    ("alpha_max", "alpha_max", "largest stable alpha = K_w T^2 / m (the renderable stiffness)",
     "K_max", "K_w"),
    ("beta_at_alpha_max", "beta_at_alpha_max", "the beta at which alpha_max is reached",
     "B_w at K_max", "B_w"),
    ("beta_left", "beta_left", "leftmost beta of the stable region (not the paper's "
     "beta_min = -delta, where the boundary arc starts)", "B_left", "B_w"),
    ("beta_right", "beta_right", "rightmost beta of the stable region", "B_right", "B_w"),
    ("z_width", "z_width", "area of the stable region in the (beta, alpha) plane", "Z-width", None),
)


def _limits_rows(setup, lim):
    rows = []
    for name, attribute, _, label, unit in _LIMITS:
        value = getattr(lim, attribute)
        row = [name, value]
        if setup.physical:
            dev = setup.device
            if value is None:
                phys = None
            elif unit == "K_w":
                phys = dev.stiffness(value)
            elif unit == "B_w":
                phys = dev.damping(value)
            else:  # area in the (B_w, K_w) plane
                phys = value * (dev.m / dev.T) * (dev.m / dev.T**2)
            row += [label, phys, setup.units[unit] if unit else
                    f"({setup.units['B_w']})({setup.units['K_w']})"]
        rows.append(tuple(row))
    columns = ["quantity", "value"] + (["physical", "physical value", "unit"] if setup.physical else [])
    return columns, rows


def _limits_json(lim):
    """The ``limits`` object of the JSON output, under the names of the table."""
    out = {name: getattr(lim, attribute) for name, attribute, _, _, _ in _LIMITS}
    out["message"] = lim.message
    return out


def _passive(setup, lim):
    """The passive set beside the stable region: (notes, json), one line per fact.

    Colgate and Schenkel's condition with the device's friction and the
    delay (:func:`symstab.numeric.paper_loop.paper_passive_region`).
    """
    from ..numeric.paper_loop import paper_passive_region

    if setup.delta == 0:
        return (["passive set (Colgate-Schenkel): none, the device has no damping (delta = 0)"],
                {"alpha_max": None, "beta_at_alpha_max": None, "area": 0.0})
    region = paper_passive_region(gamma=setup.gamma, d=setup.d, delta=setup.delta)
    if region.empty:
        return ([f"passive set (Colgate-Schenkel, with the delay): no passive point at "
                 f"gamma = {setup.gamma:.6g}, d = {setup.d}, delta = {setup.delta:.6g}"],
                {"alpha_max": None, "beta_at_alpha_max": None, "area": 0.0})
    out = {"alpha_max": region.y_max, "beta_at_alpha_max": region.x_at_y_max,
           "area": region.area}
    notes = [f"passive alpha_max = {region.y_max:.10g} at beta = {region.x_at_y_max:.10g} "
             f"(Colgate-Schenkel with the delay; stable alpha_max = "
             f"{number_text(lim.alpha_max) or 'none'})"]
    if setup.physical:
        dev = setup.device
        k_max, b_at = float(dev.stiffness(region.y_max)), float(dev.damping(region.x_at_y_max))
        out.update(K_max=k_max, B_w_at_K_max=b_at)
        notes.append(f"passive K_max = {k_max:.10g} {setup.units['K_w']} at B_w = {b_at:.10g} "
                     f"{setup.units['B_w']}")
    notes.append(f"passive area = {region.area:.10g} in the (beta, alpha) plane (stable "
                 f"z_width = {number_text(lim.z_width) or 'none'})")
    return notes, out


def _loop_passive(setup, lim):
    """The passive set beside the stable one: (notes, json), one line per fact.

    Colgate and Schenkel's condition with the device's friction ``b``
    (:func:`symstab.numeric.passivity.passive_region`); a loop it does not
    cover (no ``b``, a plant other than ``1/(m s**2 + b s)``) gets a note
    saying why, not an error: the stable limits stand on their own.
    """
    from ..numeric.passivity import passive_region

    x, y = setup.x, setup.y
    try:
        region = passive_region(setup.loop, x=x, y=y, **setup.values)
    except (ValueError, TypeError, ArithmeticError) as exc:
        return [f"passive set (Colgate-Schenkel) not computed: {exc}"], {"error": str(exc)}
    ux, uy = setup.unit(x), setup.unit(y)
    area_unit = f"({ux})({uy})" if ux and uy else (ux or uy)
    out = {"x": x, "y": y, "y_max": region.y_max, "x_at_y_max": region.x_at_y_max,
           "area": region.area, "bounded": region.bounded,
           "x_range": list(region.x_range), "y_range": list(region.y_range)}
    if region.empty:
        return [f"passive set (Colgate-Schenkel, damping b = {setup.values.get('b', math.nan):.10g}"
                f"{' ' + setup.unit('b') if setup.unit('b') else ''}): no passive point in the "
                f"({x}, {y}) plane"], out
    notes = [f"passive {y}_max = {region.y_max:.10g}{' ' + uy if uy else ''} at {x} = "
             f"{region.x_at_y_max:.10g}{' ' + ux if ux else ''} (Colgate-Schenkel with the "
             f"delay; stable {y}_max = {lim.y_max:.10g})"]
    if region.bounded:
        notes.append(f"passive area = {region.area:.10g}{' ' + area_unit if area_unit else ''} "
                     f"(stable area = {lim.area:.10g})")
    else:
        notes.append(f"the passive set is unbounded; its area inside {x} in "
                     f"[{region.x_range[0]:.6g}, {region.x_range[1]:.6g}], {y} in "
                     f"[{region.y_range[0]:.6g}, {region.y_range[1]:.6g}] is {region.area:.10g}")
    return notes, out
