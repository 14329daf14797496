"""``symstab boundary``: the paper's stability boundary, or a loop file's D-decomposition.

The paper's loop: the arc alpha(theta), beta(theta) of eq. (7) for one
virtual mass, delay and device, with K_w and B_w in physical units, and
the straight segments that close the region.  A loop file (``--loop``):
the (x, y) at which z = exp(j theta) is a closed-loop pole, the lines on
which a pole is at z = 1, z = -1 or infinity, and the pieces of them that
close the stable set (from its D-decomposition, :meth:`symstab.Loop.region`).
"""

import math
import sys

from .._resources import check_memory
from .loop_options import add_loop_options, resolve_setup
from .options import add_command, add_model_options
from .output import BYTES_PER_ROW, emit
from .units import physical_columns

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab boundary`` to the sub-commands."""
    p = add_command(
        subparsers, "boundary", help="the stability boundary alpha(theta), beta(theta)",
        description="Compute the stability boundary arc alpha(theta), beta(theta) of the "
                    "paper's eq. (7) for one virtual mass, delay and device, with K_w and B_w "
                    "in physical units, and the straight segments that close the region.",
        example="symstab boundary --Td 0.01 --n 11", func=run)
    add_model_options(p)
    p.add_argument("--n", type=int, default=101, help="points on the arc (default 101)")
    add_loop_options(p, "boundary")


def run(args):
    """Run ``symstab boundary``: a loop file's D-decomposition (``--loop``), else the paper's arc.

    The paper's device options are the paper's loop in Table I's variables
    (:func:`symstab.cli.loop_options.resolve_setup`); for them the rows are
    eq. (7)'s arc up to theta_max, for a loop file the whole arc and the
    z = +-1 lines; for both the segments of those lines that close the
    stable set (:attr:`symstab.numeric.engine.decomposition.Decomposition.segments`).
    """
    from .._validate import check_count
    from ..numeric.paper.region import boundary_curve

    setup = resolve_setup(args)
    n = check_count("n", args.n, 2)
    check_memory(f"--n {n} boundary points", n * BYTES_PER_ROW)
    paper = setup.paper
    if paper is None or paper.fractional:
        # Eq. (7) is for a whole delay: a fractional one is the paper's loop's D-decomposition.
        curve, columns, rows, notes, result = _decomposition(setup, n)
    else:
        curve = boundary_curve(gamma=paper.gamma, d=paper.d, delta=paper.delta, n=n)
        columns = ["theta [rad]", "alpha", "beta"]
        rows = list(zip(curve.theta, curve.alpha, curve.beta, strict=True))
        if paper.physical:
            columns += physical_columns(paper, ["K_w", "B_w"])
            rows = [r + (paper.device.stiffness(r[1]), paper.device.damping(r[2])) for r in rows]
        notes = [curve.message] if curve.empty else [f"theta_max = {curve.theta_max:.15g} rad"]
        result = {"theta_max": curve.theta_max, "message": curve.message}
    segments = curve.segments
    x, y = setup.name(setup.x), setup.name(setup.y)
    plane = f"({setup.label(setup.x)}, {setup.label(setup.y)})"
    notes += [f"boundary segment ({g.root}): {plane} from ({g.x0:.10g}, {g.y0:.10g}) to "
              f"({g.x1:.10g}, {g.y1:.10g})" for g in segments]
    result["segments"] = [{"root": g.root, f"{x}0": g.x0, f"{y}0": g.y0, f"{x}1": g.x1,
                           f"{y}1": g.y1} for g in segments]
    emit(setup, args.format, columns, rows, result=result, notes=notes)
    return 0


def _decomposition(setup, n):
    """The D-decomposition's arc, lines and segments of the plane: (curve, columns, rows, notes, json).

    A loop file's, or the paper's loop's at a fractional delay (in Table
    I's names, with the device's units beside them where it is physical).
    """
    x, y = setup.name(setup.x), setup.name(setup.y)
    # The stable set's straight pieces: its D-decomposition (seconds at long delays).
    print(f"finding the ({x}, {y}) plane's stable set for the segments that close it ...",
          file=sys.stderr, flush=True)
    try:
        curve = setup.loop.boundary(x=setup.x, y=setup.y, n=n, segments=True, **setup.values)
    except ValueError as exc:
        curve = setup.loop.boundary(x=setup.x, y=setup.y, n=n, **setup.values)
        notes = [f"the segments that close the stable set were not found: {exc}"]
    else:
        notes = []
    columns = ["theta [rad]", setup.label(setup.x), setup.label(setup.y)]
    rows = list(zip(curve.theta, curve.x_values, curve.y_values, strict=True))
    paper = setup.paper
    if paper is not None and paper.physical:
        columns += physical_columns(paper, ["B_w", "K_w"])
        rows = [r + (float(paper.device.damping(r[1])), float(paper.device.stiffness(r[2])))
                for r in rows]
    notes.insert(0, f"D-decomposition: z = exp(j theta) is a closed-loop pole at ({x}, {y}) "
                    f"(nan: the 2 x 2 system is singular at that theta)")
    notes += [_line_text(setup, label, line) for label, line in curve.lines.items()]
    if not curve.lines:
        notes.append("no real-root or leading-coefficient line crosses this plane")
    result = {"lines": {label: dict(zip(("c0", "cx", "cy"), line, strict=True))
                        for label, line in curve.lines.items()}}
    return curve, columns, rows, notes, result


def _signed(terms):
    """``"a + b x - c y"`` from ``[(a, ""), (b, "x"), (c, "y")]`` (the first term keeps its sign).

    Terms that are exactly 0 are left out ("K = 0", not "K = 0 + 0 B"): the
    lines' coefficients are exact zeros where the loop makes them so.
    """
    terms = [(value, name) for value, name in terms if value != 0] or [(0.0, "")]
    text = ""
    for k, (value, name) in enumerate(terms):
        number = f"{abs(value) if k else value:.10g}" + (f" {name}" if name else "")
        text += number if k == 0 else f" {'-' if math.copysign(1.0, value) < 0 else '+'} {number}"
    return text


def _line_text(setup, label, line):
    """``z = 1: c0 + cx x + cy y = 0``, and solved for y (or x) when it can be."""
    c0, cx, cy = line
    x, y = setup.name(setup.x), setup.name(setup.y)
    text = f"line {label}: {_signed([(c0, ''), (cx, x), (cy, y)])} = 0"
    if cy != 0:
        text += f", i.e. {y} = {_signed([(-c0 / cy + 0.0, ''), (-cx / cy + 0.0, x)])}"
    elif cx != 0:
        text += f", i.e. {x} = {-c0 / cx + 0.0:.10g}"
    return text
