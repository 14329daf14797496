"""``symstab limits``: the largest stable stiffness, the damping range, the stable area.

The paper's loop: alpha_max (K_max), the damping at which it is reached,
the range of damping over the stable region and its area (Z-width), with
--beta/--Bw the stable stiffness intervals at that damping.  A loop file
(``--loop``): the same in its plane (with --at X the stable y at x = X).
Both give the passive set (Colgate-Schenkel) beside the stable one.  With
``--uncertain NAME=LO:HI`` (a loop file) the limits are the robust set's:
the points stable for every value of the box
(:func:`symstab.numeric.analysis.robust.robust_region`), drawn with ``--png``
beside the nominal set.
"""

import math
import sys
import textwrap

from .loop_limits import (
    LIMITS,
    limits_notes,
    limits_table,
    named,
    passive_notes,
    stable_intervals_at,
)
from .loop_options import add_loop_options, resolve_setup, uncertain_box
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
    if setup.paper is None and args.uncertain is not None:
        return _robust(args, setup, at)
    for flag, dest in (("--strips", "strips"), ("--png", "png")):
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{flag} is an option of the robust limits: add --uncertain NAME=LO:HI")
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


#: The most strips ``--strips`` takes (as :func:`symstab.numeric.analysis.robust.robust_region`).
_MAX_STRIPS = 100_000


def _delay_pieces(setup, box):
    """How many delays the robust region certifies one after the other (its progress): each
    whole delay of a whole range, else one piece per whole part of the continuum."""
    import math

    from .._validate import snap_delay

    if "d" in box and isinstance(box["d"][0], int):
        return box["d"][1] - box["d"][0] + 1
    if "d" not in box and "Td" not in box:
        return 1
    low, high = box["d"] if "d" in box else (
        v / {**setup.loop.defaults, **setup.values}["T"] for v in box["Td"])
    low, high = (float(v) for v in snap_delay([low, high]))
    return max(1, math.ceil(high) - math.floor(low))


def _announcer(setup, box, strips):
    """The robust region's ``progress``: what runs, said once the library has accepted the box
    (a refusal stays one line), then a bar over its delays.

    Seconds to minutes: a plant of higher order, a box of several parameters
    and many strips or delays cost more (README).
    """
    from .._progress import progress_printer

    delays = _delay_pieces(setup, box)
    continuum = "Td" in box or ("d" in box and not isinstance(box["d"][0], int))
    bar = progress_printer("delays", delays)

    def progress(done):
        if done == 0:
            print(f"certifying the ({setup.name(setup.x)}, {setup.name(setup.y)}) plane for "
                  f"every value of the box ({strips} strips, {delays} "
                  f"{'piece(s) of a continuum of delays' if continuum else 'delay(s)'}, "
                  f"{len([k for k in box if k not in ('d', 'Td')])} continuous parameter(s)) ...",
                  file=sys.stderr, flush=True)
        bar(done)

    return progress


def _robust(args, setup, at):
    """``limits --loop --uncertain``: the robust set's limits, certified; its PNG with --png."""
    from ..drawing import png_of, require_matplotlib, robust_figure
    from .output import check_files, write_output

    strips = 64 if args.strips is None else args.strips
    if not 1 <= strips <= _MAX_STRIPS:
        raise ValueError(f"--strips must be an integer from 1 to {_MAX_STRIPS}, got {strips}")
    png = None
    if args.png is not None:
        if not args.png.endswith(".png"):
            raise ValueError(f"--png must end in .png, got {args.png}")
        png = check_files([("--png", args.png)])["--png"]
        require_matplotlib()      # matplotlib is there before the work starts
    # A box of zero width is the nominal set, certified the robust way.
    box = uncertain_box(args, setup, point=True)
    delay = {"d", "Td"} & set(box)
    values = {k: v for k, v in setup.values.items() if k not in box and not (delay and k in
                                                                            ("d", "Td"))}
    progress = _announcer(setup, box, strips)
    try:
        lim = setup.loop.limits(x=setup.x, y=setup.y, uncertain=box, strips=strips,
                                progress=progress, **values)
    except ValueError as exc:
        # The library names its argument; here it came from the option.
        if str(exc).startswith("uncertain: "):
            raise ValueError(f"--{exc}") from None
        raise
    region = lim.region
    columns, rows = limits_table(setup, lim)
    x, y = setup.name(setup.x), setup.name(setup.y)
    box_text = ", ".join(
        f"{name} in [{lo:.6g}, {hi:.6g}]" + (" s" if name == "Td" else "" if name == "d" or
                                            not setup.unit(name) else f" {setup.unit(name)}")
        for name, (lo, hi) in box.items())
    nominal = region.nominal
    used = len(region.edges) - 1 if len(region.edges) else strips
    # The strips where the set has a corner or an end are halved: say so
    # when the count differs from the one asked for.
    if used > strips:
        halved = (f"{strips} strips asked for, {used} after halving those where the set has "
                  f"a corner or an end")
    elif used < strips:
        halved = "one line: the window has no width in x"
    else:
        halved = f"{strips} strips"
    notes = [f"robust: the points of the ({x}, {y}) plane stable for every {box_text}, "
             f"certified by zero exclusion (interval arithmetic over the box and theta; "
             f"{halved}; each with trapezoids of certified y)"]
    if lim.empty:
        notes.append(f"the robust set is empty: {lim.reason}")
    else:
        nominal_limits = nominal.limits() if nominal is not None and nominal.stable else None
        if nominal_limits is not None:
            notes.append(f"nominal (the box's centre): {y}_max = {nominal_limits.y_max:.6g}, "
                         f"area = {nominal_limits.area:.6g}; robust: {y}_max = "
                         f"{lim.y_max:.6g}, area = {lim.area:.6g} "
                         f"({lim.area / nominal_limits.area:.1%} of it)")
        notes.append(f"marginal (the certificate did not close): area {region.marginal_area:.3g}; "
                     f"more strips make the trapezoids fit closer")
        if region.exhausted:
            notes.append("the search stopped at its budget of cells: what it left open is "
                         "marginal")
    result = {"limits": lim.as_dict(),
              "robust": {"uncertain": {k: list(v) for k, v in box.items()},
                         "strips": strips, "marginal_area": region.marginal_area,
                         "nominal_area": None if nominal is None else nominal.area,
                         "exhausted": region.exhausted}}
    if at is not None:
        spans = lim.intervals_at(at)
        text = ", ".join(f"[{lo:.10g}, {hi:.10g}]" for lo, hi in spans) or "none"
        notes.append(f"robust {y} at {x} = {at:.10g}: {text}")
        result["at"] = {"x": at, "intervals": [list(r) for r in spans]}
    if png is not None:
        image = png_of(robust_figure, region, setup.label(setup.x), setup.label(setup.y))
        write_output(png, image, "--png")
        notes.append(f"wrote {png}")
    emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0
