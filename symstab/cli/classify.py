"""``symstab classify``: stable, unstable or marginal, with the spectral radius.

The verdict counts the roots of the loop polynomial outside the unit
circle (Schur-Cohn, or a certified count by the argument principle where
that is not decisive), at stiffness-damping points of the paper's loop or
at a loop file's values changed by ``--set`` (comma lists: several points).
"""

import numpy as np

from .loop_options import add_loop_options, broadcast, point_count, resolve_loop, uses_loop
from .options import add_command, add_model_options, parse_list, resolve, stiffness_and_damping
from .output import emit
from .units import physical_columns

__all__ = ["register", "run"]

#: Above this delay ``classify`` gives verdicts without the spectral radius
#: (eigenvalues of a (d + n)-square companion matrix per point: O(d**3)
#: time and O(d**2) memory, where the verdict itself is O(d)).
_RADIUS_MAX_DELAY = 1000


def register(subparsers):
    """Add ``symstab classify`` to the sub-commands."""
    p = add_command(
        subparsers, "classify", help="stable, unstable or marginal, with the spectral radius",
        description="Decide by counting the roots of the loop polynomial outside the unit "
                    "circle (Schur-Cohn, or a certified count by the argument principle where "
                    "that is not decisive) whether each stiffness-damping point is stable, "
                    "unstable or marginal, and give the spectral radius of the loop.",
        example="symstab classify --Td 0.01 --Kw 1,3,10 --Bw 0.2", func=run)
    add_model_options(p)
    p.add_argument("--alpha", help="dimensionless stiffness(es), comma-separated")
    p.add_argument("--beta", help="dimensionless damping(s), comma-separated")
    p.add_argument("--Kw", help="virtual stiffness(es), comma-separated (physical)")
    p.add_argument("--Bw", help="virtual damping(s), comma-separated (physical)")
    add_loop_options(p, "classify")


def run(args):
    """Run ``symstab classify`` (on the loop file of ``--loop``, else the paper's loop)."""
    return _loop(args) if uses_loop(args) else _paper(args)


def _paper(args):
    """The verdicts and spectral radii of the paper's loop at --alpha/--Kw, --beta/--Bw."""
    from ..numeric.stability import MARGINAL, STABLE, classify, spectral_radius

    setup = resolve(args)
    alpha, beta = (np.atleast_1d(x) for x in stiffness_and_damping(args, setup, parse_list))
    try:
        alpha, beta = np.broadcast_arrays(alpha, beta)
    except ValueError:
        raise ValueError(f"--alpha/--Kw and --beta/--Bw must have the same length or one value, "
                         f"got {alpha.size} and {beta.size}") from None
    kwargs = dict(alpha=alpha, beta=beta, gamma=setup.gamma, d=setup.d, delta=setup.delta)
    code = np.atleast_1d(classify(**kwargs))
    notes = []
    if setup.d <= _RADIUS_MAX_DELAY:
        radius = np.atleast_1d(spectral_radius(**kwargs))
    else:
        # Eigenvalues of (d + 4)-square companion matrices: O(d**3) time and
        # O(d**2) memory a point, where the verdict itself is O(d).
        radius = np.full(alpha.shape, np.nan)
        notes.append(f"spectral radius not computed for d > {_RADIUS_MAX_DELAY} (eigenvalues of "
                     f"a {setup.d + 4}-square matrix per point); the verdicts are certified "
                     f"root counts")
    verdict = np.where(code == STABLE, "stable", np.where(code == MARGINAL, "marginal", "unstable"))
    columns = ["alpha", "beta"]
    rows = [(a, b) for a, b in zip(alpha, beta)]
    if setup.physical:
        columns += physical_columns(setup, ["K_w", "B_w"])
        rows = [r + (setup.device.stiffness(r[0]), setup.device.damping(r[1])) for r in rows]
    columns += ["spectral radius", "verdict"]
    rows = [r + (rad, str(v)) for r, rad, v in zip(rows, radius, verdict)]
    emit(setup, args.format, columns, rows, notes=notes)
    return 0


def _loop(args):
    """The verdicts, spectral radii and unstable pole counts of a loop file."""
    from ..numeric.stability import MARGINAL, STABLE

    setup = resolve_loop(args, plane=False, lists=True)
    loop, values = setup.loop, broadcast(setup.values)
    n = point_count(setup.values)
    for name, value in values.items():
        if name != "d" and np.ndim(value) == 0:
            values[name] = np.full(n, float(value))
    code = np.atleast_1d(loop.classify(**values))
    counts = np.atleast_1d(loop.unstable_root_counts(**values))
    notes = []
    if setup.values["d"] <= _RADIUS_MAX_DELAY:
        radius = np.atleast_1d(loop.spectral_radius(**values))
    else:
        radius = np.full(code.shape, np.nan)
        notes.append(f"spectral radius not computed for d > {_RADIUS_MAX_DELAY} (eigenvalues of "
                     f"a large companion matrix per point); the verdicts are certified root counts")
    names = list(setup.given) or ([n for n in loop.plane] if loop.plane else [])
    names = [n for n in names if n != "d"]
    columns = [setup.label(n) for n in names] + ["spectral radius", "unstable poles", "verdict"]
    rows = []
    for k in range(n):
        verdict = "stable" if code[k] == STABLE else "marginal" if code[k] == MARGINAL else "unstable"
        # A marginal verdict (a pole on the circle, or at infinity: the leading
        # coefficient lost in rounding) has no count to trust.
        poles = None if counts[k] < 0 or code[k] == MARGINAL else int(counts[k])
        rows.append(tuple(float(np.broadcast_to(values[m], (n,))[k]) for m in names)
                    + (float(radius[k]), poles, verdict))
    notes.append("unstable poles: closed-loop poles outside the unit circle, a certified count "
                 "(empty where marginal: a pole on the circle to within rounding, or at "
                 "infinity where the leading coefficient vanishes)")
    emit(setup, args.format, columns, rows, notes=notes)
    return 0
