"""``symstab locus``: the closed-loop poles along a path of the stiffness or the damping.

The paper's loop takes the device and delay options of the numeric
commands (:mod:`symstab.cli.options`) and a path: one of the stiffness
(``--Kw``/``--alpha``) and the damping (``--Bw``/``--beta``) as a range
``LOW:HIGH[:N]``, the other as one value.  A loop file takes ``--loop FILE``
and ``--set NAME=VALUE``, one of the ``--set`` values a range.  The
crossings of the unit circle (:func:`symstab.numeric.engine.locus.locus`) are
printed as one table; ``--png`` draws the poles in the z-plane, coloured by
the path's parameter, beside their largest modulus along the path.  Every
input is checked before the work; the PNG is written atomically.
"""

import dataclasses
import math
import sys

import numpy as np

from ..drawing import locus_figure, png_of
from .loop_options import (
    DEVICE_OPTIONS,
    EXAMPLE,
    LINEAR_WITH_LOOP,
    POINT_OPTIONS,
    LoopSetup,
    add_delay,
    check_names,
    convert_sets,
    load_loop_file,
    loop_echo,
    loop_values,
    paper_setup,
    parse_number,
    split_unit,
)
from .options import add_command, add_model_options, resolve
from .output import check_outputs, emit, interval_texts, write_output
from .units import tex_unit

__all__ = ["register", "run"]


#: Points of a path given as LOW:HIGH, and the most a path may have.
DEFAULT_POINTS = 401
MAX_POINTS = 100_000
#: The paper's options refused with --loop, and what replaces each (those of
#: the other numeric commands, but --linear, which locus does not have).
_DEVICE_OPTIONS = tuple(option for option in DEVICE_OPTIONS
                        if option[0] != "--linear") + POINT_OPTIONS


def register(subparsers):
    """Add ``symstab locus`` to the sub-commands."""
    p = add_command(
        subparsers, "locus", help="the closed-loop poles along a path of the stiffness or the damping",
        description="Track every closed-loop pole as the stiffness (or the damping) runs "
                    "along a range, the other fixed, and list where a pole crosses the unit "
                    "circle: a complex pair (the boundary arc, at the angle theta, oscillating "
                    "at theta / (2 pi T)) or a real pole at z = 1 or z = -1; --png draws the "
                    "poles in the z-plane and their largest modulus along the path.",
        example="symstab locus --Td 0.04 --Bw 0.1 --Kw 0:30 --png locus.png", func=run)
    add_model_options(p)
    g = p.add_argument_group(
        "the path (one option a range LOW:HIGH or LOW:HIGH:N, default N = "
        f"{DEFAULT_POINTS}; a negative LOW needs '=', e.g. --Kw=-5:30)")
    g.add_argument("--alpha", help="dimensionless stiffness: a range, or one value")
    g.add_argument("--beta", help="dimensionless damping: a range, or one value")
    g.add_argument("--Kw", help="virtual stiffness (physical): a range, or one value")
    g.add_argument("--Bw", help="virtual damping (physical): a range, or one value")
    p.add_argument("--png", metavar="FILE", help="also draw the locus as PNG")
    g = p.add_argument_group(
        "any loop (instead of the device and path options above)",
        f"A loop file (TOML, see {EXAMPLE}); --set NAME=VALUE changes a value in its "
        "units, and one --set gives the path as a range, e.g. --set K=0:30.  --d still sets "
        f"the delay.\nexample: symstab locus --loop {EXAMPLE} --set B=0.1 --set K=0:30 "
        "--png locus.png")
    g.add_argument("--loop", metavar="FILE", help="loop file (TOML)")
    g.add_argument("--set", metavar="NAME=VALUE", action="append", dest="set_values",
                   help="set a parameter of the loop, or give the path as NAME=LOW:HIGH[:N]; "
                        "repeatable")


# --------------------------------------------------------------------------
# Inputs


def _is_range(text):
    return text is not None and ":" in text


def _path(text, flag):
    """The values of a range ``LOW:HIGH`` or ``LOW:HIGH:N``."""
    parts = [t.strip() for t in text.split(":")]
    if len(parts) not in (2, 3):
        raise ValueError(f"{flag} must be LOW:HIGH or LOW:HIGH:N, got {text!r}")
    try:
        low, high = float(parts[0]), float(parts[1])
    except ValueError:
        raise ValueError(f"{flag} must be LOW:HIGH or LOW:HIGH:N with numbers, got {text!r}") \
            from None
    n = DEFAULT_POINTS
    if len(parts) == 3:
        try:
            n = int(parts[2])
        except ValueError:
            raise ValueError(f"{flag}: N must be a whole number of points, got {parts[2]!r}") \
                from None
    if not (math.isfinite(low) and math.isfinite(high) and math.isfinite(high - low)):
        raise ValueError(f"{flag} must have finite LOW and HIGH, got {text!r}")
    if low == high:
        raise ValueError(f"{flag} must have LOW != HIGH (a path), got {text!r}")
    if not 2 <= n <= MAX_POINTS:
        raise ValueError(f"{flag}: N must be from 2 to {MAX_POINTS}, got {n}")
    return np.linspace(low, high, n)


def _single(text, flag):
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{flag} must be a number (or a range LOW:HIGH), got {text!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{flag} must be a finite number, got {text!r}")
    return value


class _View:
    """What the output needs: the inputs' echo, the locus and how to show its parameter."""

    def __init__(self, setup, locus, name, unit, tex, show, T, dimensionless=None, given=None,
                 fixed=None):
        self.setup = setup          # a LoopSetup (setup.paper: the paper's device options)
        self.locus = locus
        self.name = name            # "K_w", "alpha", "K"
        self.unit = unit
        self.tex = tex              # the axis label, mathtext
        self.show = show            # path values -> shown values
        self.T = T                  # sample period (s) or None
        self.dimensionless = dimensionless   # "alpha" or "beta" beside a physical value
        self.given = given          # the path as the user gave it (in the shown units)
        self.fixed = fixed          # the paper's options: (name, value) of the fixed one of alpha, beta
        self.symbol = {"K_w": "$K_w$", "B_w": "$B_w$", "alpha": r"$\alpha$",
                       "beta": r"$\beta$"}.get(name, name)

    def label(self):
        return f"{self.name} [{self.unit}]" if self.unit else self.name

    def count(self, values):
        """Certified unstable root counts along the path (:meth:`symstab.Loop.unstable_root_counts`)."""
        setup, locus = self.setup, self.locus
        return setup.loop.unstable_root_counts(**locus.fixed, **{locus.parameter: values})


def _paper(args):
    """The paper's options: the paper's loop (:func:`paper_setup`), its path ``K`` or ``B``."""
    for flag, dest in (("--set", "set_values"),):
        if getattr(args, dest) is not None:
            raise ValueError(f"{flag} needs a loop file: give --loop FILE "
                             f"(e.g. --loop {EXAMPLE})")
    setup = paper_setup(resolve(args), plane=False)
    paper = setup.paper
    stiffness = [(f, getattr(args, d)) for f, d in (("--alpha", "alpha"), ("--Kw", "Kw"))
                 if getattr(args, d) is not None]
    damping = [(f, getattr(args, d)) for f, d in (("--beta", "beta"), ("--Bw", "Bw"))
               if getattr(args, d) is not None]
    if len(stiffness) != 1 or len(damping) != 1:
        raise ValueError("give the stiffness (--alpha or --Kw) and the damping (--beta or --Bw), "
                         "once each, one of them a range LOW:HIGH (the path)")
    (s_flag, s_text), (d_flag, d_text) = stiffness[0], damping[0]
    if _is_range(s_text) == _is_range(d_text):
        raise ValueError(f"exactly one of {s_flag} and {d_flag} must be a range LOW:HIGH "
                         f"(the path), the other one value; got {s_flag} {s_text} and "
                         f"{d_flag} {d_text}")
    for flag in (s_flag, d_flag):
        if flag in ("--Kw", "--Bw") and not paper.physical:
            raise ValueError(f"{flag} needs a physical device; use --alpha and --beta with "
                             f"--delta")
    path_flag, path_text, fixed_flag, fixed_text = (
        (s_flag, s_text, d_flag, d_text) if _is_range(s_text) else (d_flag, d_text, s_flag, s_text))
    given = _path(path_text, path_flag)
    fixed = _single(fixed_text, fixed_flag)
    dev = paper.device
    to_dimensionless = {"--alpha": np.asarray, "--beta": np.asarray,
                        "--Kw": (lambda v: dev.alpha(v)), "--Bw": (lambda v: dev.beta(v))}
    parameter = "alpha" if path_flag in ("--alpha", "--Kw") else "beta"
    other = "beta" if parameter == "alpha" else "alpha"
    values = np.asarray(to_dimensionless[path_flag](given), dtype=float)
    fixed_value = float(to_dimensionless[fixed_flag](fixed))
    fixed_name = fixed_flag[2:]
    unit_of = {"Kw": "K_w", "Bw": "B_w"}
    fixed_text = (f"{unit_of[fixed_name]} = {fixed:.10g} {paper.units[unit_of[fixed_name]]}"
                  if fixed_name in unit_of else f"{fixed_name} = {fixed:.10g}")
    if fixed_name in unit_of:
        fixed_text += f" ({other} = {fixed_value:.10g})"
    setup = _with_echo(setup, f"path: {unit_of.get(path_flag[2:], path_flag[2:])} from "
                              f"{given[0]:.10g} to {given[-1]:.10g} ({given.size} points) at "
                              f"{fixed_text}")
    if path_flag == "--Kw":
        show, name, unit = dev.stiffness, "K_w", paper.units["K_w"]
        tex = f"$K_w$ [{tex_unit(unit)}]"
    elif path_flag == "--Bw":
        show, name, unit = dev.damping, "B_w", paper.units["B_w"]
        tex = f"$B_w$ [{tex_unit(unit)}]"
    else:
        show, name, unit = np.asarray, parameter, ""
        tex = r"$\alpha = K_w T^2 / m$" if parameter == "alpha" else r"$\beta = B_w T / m$"
    # The paper's loop at m = T = 1, whose (B, K) is (beta, alpha).
    plane = {"alpha": "K", "beta": "B"}
    return _track(setup, plane[parameter], values, {plane[other]: fixed_value}, name=name,
                  unit=unit, tex=tex, show=lambda v: np.asarray(show(v), dtype=float),
                  T=dev.T if paper.physical else None,
                  dimensionless=parameter if path_flag in ("--Kw", "--Bw") else None,
                  given=given, fixed=(other, fixed_value))


#: From this many poles on, say on stderr what runs (some seconds: 8 s for
#: 401 points at 204 poles on a busy machine).
_ANNOUNCE_DEGREE = 150


def _track(setup, parameter, path, others, **shown):
    """Track the poles of ``setup.loop`` along ``parameter`` (``path``), ``others`` fixed: a :class:`_View`.

    The memory is decided first, so that a refusal is the one error line;
    a long run says on stderr what runs.
    """
    from ..numeric.engine.locus import check_locus_memory, locus

    values = {**setup.values, **others}
    degree = setup.loop.coefficients(**values, **{parameter: path[0]}).shape[-1] - 1
    check_locus_memory(path.size, degree)
    if degree >= _ANNOUNCE_DEGREE:
        print(f"tracking {degree} closed-loop poles at {path.size}+ points ...", file=sys.stderr,
              flush=True)
    return _View(setup, locus(setup.loop, parameter, path, **values), **shown)


def _with_echo(setup, line):
    return dataclasses.replace(setup, echo=tuple(setup.echo) + (line,))


def _loop(args):
    """A loop file: resolve ``--loop``/``--set``, the path one ``--set NAME=LOW:HIGH``."""
    for flag, dest, instead in _DEVICE_OPTIONS:
        if getattr(args, dest) is not None:
            raise ValueError(f"{flag} is an option of the paper's device; with --loop use "
                             f"{instead}")
    if args.linear:
        raise ValueError(LINEAR_WITH_LOOP)
    sets, path = {}, None
    for text in args.set_values or ():
        flag = f"--set {text}"
        name, eq, value = text.partition("=")
        name = name.strip()
        if not eq or not name:
            raise ValueError(f"{flag}: expected NAME=VALUE or NAME=LOW:HIGH, e.g. --set K=0:30")
        if name in sets or (path is not None and path[0] == name):
            raise ValueError(f"--set {name} is given twice; give each parameter once")
        if _is_range(value):
            if path is not None:
                raise ValueError(f"{flag}: the path is already --set {path[0]}=...; give one "
                                 f"range (the others single values)")
            if name == "d":
                raise ValueError(f"{flag}: the delay d is a whole number of samples, not a path")
            path = (name, _path(value, flag))
        else:
            value, unit = split_unit(value, flag)
            sets[name] = (parse_number(name, value, flag, lists=False), unit)
    if path is None:
        raise ValueError("give the path as one --set NAME=LOW:HIGH[:N], e.g. --set K=0:30")
    add_delay(args, sets)
    loop = load_loop_file(args.loop)
    check_names(args, loop, list(sets) + [path[0]])
    # In the file's units, as every --set (symstab.cli.loop_options): to SI here.
    sets, written = convert_sets(loop, sets)
    ends = convert_sets(loop, {path[0]: ([path[1][0], path[1][-1]], None)})[0][path[0]]
    path = (path[0], np.linspace(ends[0], ends[1], path[1].size))
    values, written = loop_values(args, loop, sets, written, skip=(path[0],))
    name, given = path
    setup = LoopSetup(str(args.loop), loop, values, tuple(sets), written=written)
    unit = setup.unit(name)
    setup = _with_echo(dataclasses.replace(setup, echo=loop_echo(setup)),
                       f"path: {name} from {given[0]:.10g} to {given[-1]:.10g}"
                       f"{' ' + unit if unit else ''} ({given.size} points)")
    T = values.get("T") if "T" in loop.parameters else None
    return _track(setup, name, given, {}, name=name, unit=unit,
                  tex=f"{name} [{tex_unit(unit)}]" if unit else name,
                  show=lambda v: np.asarray(v, dtype=float), T=None if T is None else float(T),
                  given=given)


# --------------------------------------------------------------------------
# Output


def _stretches(view):
    """``[(low, high, count)]``: the path cut at its crossings, with the unstable count of each.

    The count of one stretch comes from a path point in it (the tracked
    poles) and is carried across each crossing by its change (+-2 a pair,
    +-1 a real pole); ``None`` where no point of the path says.
    """
    locus = view.locus
    values, counts = locus.values, locus.unstable_counts()
    forward = 1.0 if values[-1] > values[0] else -1.0
    cuts = [c.value for c in locus.crossings]
    edges = [float(values[0])] + cuts + [float(values[-1])]
    # The stretch of each path point: the crossings it has passed.
    position = np.searchsorted(forward * np.array(cuts), forward * values, side="right")
    known = {}
    for k, c in zip(position, counts, strict=True):
        if c >= 0 and k not in known:
            known[int(k)] = int(c)
    out = [None] * (len(cuts) + 1)
    if known:
        start = min(known)
        out[start] = known[start]
        for k in range(start + 1, len(out)):
            out[k] = out[k - 1] + locus.crossings[k - 1].change
        for k in range(start - 1, -1, -1):
            out[k] = out[k + 1] - locus.crossings[k].change
    return [(edges[k], edges[k + 1], out[k]) for k in range(len(out))]


def _certified(view):
    """Certified root counts at the path's points (:meth:`symstab.Loop.unstable_root_counts`)."""
    return np.atleast_1d(view.count(view.locus.values))


#: A crossing value within this fraction of the path's span from 0 is
#: printed as 0: the eigenvalues put a root at z = 1 for K = 0 at K = 1e-12 or so.
_ZERO = 1e-9


def _snap(view, value):
    span = abs(view.locus.values[-1] - view.locus.values[0])
    return 0.0 if abs(value) <= _ZERO * span else float(value)


def _printed(view, value):
    """The shown value of a path value (0 where it is 0 to within rounding)."""
    return float(view.show(_snap(view, value)))


def _rows(view):
    locus = view.locus
    columns = [view.label()]
    if view.dimensionless:
        columns.append(view.dimensionless)
    columns += ["crossing", "direction", "theta [rad]"]
    if view.T is not None:
        columns.append("frequency [Hz]")
    columns.append("unstable poles after")
    stretches = _stretches(view)
    rows = []
    for k, c in enumerate(locus.crossings):
        row = [_printed(view, c.value)]
        if view.dimensionless:
            row.append(_snap(view, c.value))
        row += [c.kind, c.direction, c.angle]
        if view.T is not None:
            row.append(c.angle / (2 * math.pi * view.T))
        after = stretches[k + 1][2]
        row.append(after)
        rows.append(tuple(row))
    return columns, rows, stretches


def _notes(view, stretches, certified):
    locus = view.locus
    notes = []
    if not locus.crossings:
        count = stretches[0][2]
        notes.append(f"no pole crosses the unit circle along the path; "
                     f"{'unknown' if count is None else count} pole(s) outside it throughout")
    from ..numeric.engine.roots import MARGINAL, STABLE, UNSTABLE

    stable, codes = [], []
    ends = {float(locus.values[0]): certified[0], float(locus.values[-1]): certified[-1]}
    for lo, hi, c in stretches:
        if c != 0:
            continue
        # A crossing has a pole on the unit circle (marginal, an open end); an
        # end of the path is what its certified count says (stable: closed).
        pair = [MARGINAL if value not in ends else
                STABLE if ends[value] == 0 else MARGINAL if ends[value] < 0 else UNSTABLE
                for value in (lo, hi)]
        shown = [_printed(view, lo), _printed(view, hi)]
        order = (0, 1) if shown[0] <= shown[1] else (1, 0)
        stable.append(tuple(shown[k] for k in order))
        codes.append(tuple(pair[k] for k in order))
    text, ends_note, _ = interval_texts(stable, codes, view.name, view.unit or "",
                                        stable_ends="closed")
    notes.append(f"stable along the path: {view.name} in {text}")
    if ends_note:
        notes.append(ends_note)
    if any(_snap(view, c.value) == 0.0 != c.value for c in locus.crossings):
        notes.append(f"a crossing within {_ZERO:g} of the path's span from 0 is printed as 0 "
                     f"(the eigenvalues' rounding; the JSON output keeps the value found)")
    notes.append(f"{locus.poles.shape[1]} closed-loop poles tracked at {len(locus.values)} points; "
                 "theta: the crossing pole's angle, the boundary arc's parameter")
    counts = locus.unstable_counts()
    both = (counts >= 0) & (certified >= 0)
    differ = np.flatnonzero(both & (counts != certified))
    if differ.size:
        first = differ[0]
        notes.append(f"warning: the tracked poles and the certified root count disagree at "
                     f"{differ.size} point(s), first at {view.name} = "
                     f"{view.given[first]:.10g} ({counts[first]} against "
                     f"{certified[first]}): trust the certified count (symstab classify)")
    else:
        notes.append(f"the unstable counts agree with the certified root count at all "
                     f"{int(both.sum())} decided path points"
                     + (f" ({int((~both).sum())} marginal)" if (~both).any() else ""))
    return notes


def _json(view, stretches, certified):
    locus = view.locus
    return {"path": {"parameter": view.name, "unit": view.unit,
                     "low": float(view.given[0]), "high": float(view.given[-1]),
                     "n": int(len(locus.values))},
            "crossings": [{"value": float(view.show(c.value)), "parameter_value": c.value,
                           "kind": c.kind, "direction": c.direction, "theta": c.angle,
                           "z": [c.z.real, c.z.imag], "pole": c.pole_index}
                          for c in locus.crossings],
            "stretches": [{"low": float(view.show(lo)), "high": float(view.show(hi)),
                           "unstable_poles": c} for lo, hi, c in stretches],
            "certified_agree": bool(np.all((locus.unstable_counts() == certified)
                                           | (locus.unstable_counts() < 0) | (certified < 0)))}


def run(args):
    """Run ``symstab locus``; return the exit status."""
    png = None
    if args.png is not None:
        png = check_outputs([("--png", args.png, "file")])["--png"]
        from ..drawing import require_matplotlib
        require_matplotlib()
    view = _loop(args) if args.loop is not None else _paper(args)
    certified = _certified(view)
    columns, rows, stretches = _rows(view)
    notes = _notes(view, stretches, certified)
    image = (png_of(locus_figure, view.locus, view.given, view.show, stretches,
                    symbol=view.symbol, tex=view.tex, title=_title(view))
             if png is not None else None)
    if image is not None:
        write_output(png, image, "--png")
        notes.append(f"wrote {png}")
    emit(view.setup, args.format, columns, rows, result=_json(view, stretches, certified),
         notes=notes, json_rows=False)
    return 0


# --------------------------------------------------------------------------
# The figure


def _title(view):
    setup = view.setup
    if setup.paper is None:
        fixed = ", ".join(f"{n} = {v:g}" + (f" {setup.unit(n)}" if setup.unit(n) else "")
                          for n, v in setup.values.items() if n != "d")
        return (f"root locus of the loop {setup.loop.name} along {view.name}: {fixed}, "
                f"d = {setup.values['d']:.10g}")
    paper = setup.paper
    other, fixed = view.fixed
    if paper.physical:
        dev, units = paper.device, paper.units
        if other == "beta":
            where = f"$B_w$ = {float(dev.damping(fixed)):g} {units['B_w']}"
        else:
            where = f"$K_w$ = {float(dev.stiffness(fixed)):g} {units['K_w']}"
        return (f"root locus at {where}, $T_d$ = {paper.d * dev.T * 1e3:g} ms "
                f"($d$ = {paper.d:.10g}), $M_w$ = {float(dev.mass(paper.gamma)):g} "
                f"{tex_unit(units['M_w'])}")
    symbol = r"\beta" if other == "beta" else r"\alpha"
    return (f"root locus at ${symbol}$ = {fixed:g}, $\\gamma$ = {paper.gamma:g}, $d$ = {paper.d:.10g}, "
            f"$\\delta$ = {paper.delta:g}")
