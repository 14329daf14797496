"""``symstab classify``: stable, unstable or marginal, with the spectral radius.

The verdict counts the roots of the loop polynomial outside the unit
circle (Schur-Cohn, or a certified count by the argument principle where
that is not decisive), at a loop file's values changed by ``--set`` (comma
lists: several points) or at stiffness-damping points of the paper's loop,
whose device options are shorthand for it (one computation either way).
"""

import sys

import numpy as np

from .._resources import check_memory
from .loop_options import add_loop_options, broadcast, resolve_setup
from .options import (
    add_command,
    add_model_options,
    add_point_options,
    parse_list,
    stiffness_and_damping,
)
from .output import emit
from .units import physical_columns

__all__ = ["register", "run"]

#: From this many points times the degree on, the radius takes seconds
#: (0.3 s a point at d = 5000): ``classify`` says on stderr what runs.
_ANNOUNCE_WORK = 100_000
#: The most stable points whose delay margin is given (each is a search of its own).
MAX_DELAY_MARGINS = 100


def register(subparsers):
    """Add ``symstab classify`` to the sub-commands."""
    p = add_command(
        subparsers, "classify", help="stable, unstable or marginal, with the spectral radius",
        description="Decide by counting the roots of the loop polynomial outside the unit "
                    "circle (Schur-Cohn, or a certified count by the argument principle where "
                    "that is not decisive) whether each stiffness-damping point is stable, "
                    "unstable or marginal, and give the spectral radius of the loop and the "
                    "number of its poles outside the unit circle; at a stable point, the "
                    "delay margin: the smallest delay added (in samples, exact, fractional) "
                    "at which a root reaches the unit circle.",
        example="symstab classify --Td 0.01 --Kw 1,3,10 --Bw 0.2", func=run)
    add_model_options(p)
    add_point_options(p, lists=True)
    add_loop_options(p, "classify")


def run(args):
    """Run ``symstab classify``: a loop file's points (``--loop``), else the paper's."""
    from ..numeric.engine.roots import MARGINAL, STABLE

    setup = resolve_setup(args, plane=False, lists=True)
    if setup.paper is None:
        values = broadcast(setup.values)
        names = [n for n in (setup.given or setup.loop.plane or ()) if n not in ("d", "Td")]
    else:
        # --alpha/--Kw and --beta/--Bw: K and B of the paper's loop in Table I's variables.
        alpha, beta = (np.atleast_1d(x) for x in stiffness_and_damping(args, setup.paper, parse_list))
        if alpha.size != beta.size and 1 not in (alpha.size, beta.size):
            raise ValueError(f"--alpha/--Kw and --beta/--Bw must have the same length or one "
                             f"value, got {alpha.size} and {beta.size}")
        values = {**setup.values, "K": alpha, "B": beta}
        names = ["K", "B"]
    n = max(np.size(v) for k, v in values.items() if k != "d")
    check_memory("the points' polynomials", 8 * n * (values["d"] + 64))
    values = {k: (v if k == "d" else np.broadcast_to(np.asarray(v, dtype=float), (n,)))
              for k, v in values.items()}
    loop = setup.loop
    code = loop.classify(**values)
    counts = loop.unstable_root_counts(**values)
    if n * (values["d"] + 4) >= _ANNOUNCE_WORK:
        # The radius costs about ten verdicts (counts on circles, Newton steps): say what runs.
        print(f"computing the spectral radius of {n} point(s) at delay d = {values['d']} ...",
              file=sys.stderr, flush=True)
    radius = loop.spectral_radius(**values)
    columns = [setup.label(m) for m in names]
    rows = [tuple(float(values[m][k]) for m in names) for k in range(n)]
    if setup.paper is not None and setup.paper.physical:
        device = setup.paper.device
        columns += physical_columns(setup.paper, ["K_w", "B_w"])
        rows = [r + (float(device.stiffness(r[0])), float(device.damping(r[1]))) for r in rows]
    columns += ["spectral radius", "unstable poles", "verdict", "delay margin [samples]"]
    margins, note = _delay_margins(loop, values, code == STABLE)
    for k in range(n):
        verdict = "stable" if code[k] == STABLE else "marginal" if code[k] == MARGINAL else "unstable"
        # A marginal verdict (a pole on the circle, or at infinity: the leading
        # coefficient lost in rounding) has no count to trust.
        poles = None if counts[k] < 0 or code[k] == MARGINAL else int(counts[k])
        rows[k] += (float(radius[k]), poles, verdict, margins[k])
    notes = ["unstable poles: closed-loop poles outside the unit circle, a certified count "
             "(empty where marginal: a pole on the circle to within rounding, or at "
             "infinity where the leading coefficient vanishes)", note]
    emit(setup, args.format, columns, rows, notes=notes)
    return 0


def _delay_margins(loop, values, stable):
    """The exact delay margin at each stable point (None elsewhere), and the table's note on it."""
    from ..numeric.analysis.margins import delay_limit_of

    n = len(stable)
    out = [None] * n
    if np.count_nonzero(stable) > MAX_DELAY_MARGINS:
        return out, (f"delay margin: left out, more than {MAX_DELAY_MARGINS} stable points (each "
                     f"is a search of its own; symstab margins gives one point's)")
    limit = delay_limit_of(float(values["d"]), None, whole=False)
    for k in np.flatnonzero(stable):
        point = {name: (v if name == "d" else float(v[k])) for name, v in values.items()}
        found = loop.delay_margin(**point)
        out[k] = found.margin
    return out, (f"delay margin: the smallest added delay at which a root reaches the unit "
                 f"circle (Loop.delay_margin), empty where none is found up to {limit:g} "
                 f"samples more or the point is not stable")
