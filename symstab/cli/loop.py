"""``--loop FILE`` and ``--set NAME=VALUE``: the numeric commands on any loop.

``boundary``, ``limits``, ``classify``, ``design`` and ``map`` take a loop
file (:func:`symstab.load_loop`) instead of the paper's device options; the
file's default values are changed with ``--set NAME=VALUE`` (repeatable) and
the parameter plane is the file's ``plane`` unless ``--x``/``--y`` name
another.  The file's values are converted to SI when it is read
(:mod:`symstab.numeric.loop_units`); a ``--set`` value is in the file's unit
for that parameter, or in the unit it gives (``--set T=0.5ms``), converted
the same way and checked against the file's bounds.  Everything else on the
command line (``--at``, ``--x-range``, ``--y-range``) and every result is in
the SI unit the labels show, and every value used is echoed with its unit
(as written, then as used where they differ).

The paper's device options (``--m --b --T --Td --delta --gamma --Mw`` and
the stiffness and damping options) are refused with ``--loop`` (one line
saying which ``--set`` replaces them); ``--d`` is the one that keeps its
meaning and sets the delay ``d``.  Everything is checked before the work:
the ``--set`` syntax, the file, the names, the plane, the values (the loop
evaluated once at the given point) and the output paths.  The caller
(:func:`symstab.cli.commands.main`) turns ``ValueError``/``TypeError`` into one line
``symstab <command>: error: ...`` and exit status 2.
"""

import dataclasses
import io
import math
import re
import sys
import textwrap

import numpy as np

from .._resources import CHUNK_BYTES, check_memory, chunk_slices

__all__ = ["add_loop_options", "uses_loop", "run"]

#: The paper's device options every numeric command has, with the ``--set``
#: that replaces each under ``--loop`` (None: nothing does, as for the simulation options).
_DEVICE_OPTIONS = (
    ("--m", "m", "--set m=..."), ("--b", "b", "--set b=..."), ("--T", "T", "--set T=..."),
    ("--Td", "Td", "--set d=... (the delay in samples)"),
    ("--delta", "delta", "--set with the loop's own parameters"),
    ("--gamma", "gamma", "--set with the loop's virtual mass, e.g. --set M=..."),
    ("--Mw", "Mw", "--set with the loop's virtual mass, e.g. --set M=..."),
    ("--linear", "linear", None),
)
#: Stiffness and damping options: points (classify, limits) and grids (map).
_POINT_OPTIONS = (
    ("--alpha", "alpha", "--set with the loop's parameters, e.g. --set K=..."),
    ("--beta", "beta", "--set with the loop's parameters, e.g. --set B=..."),
    ("--Kw", "Kw", "--set with the loop's parameters, e.g. --set K=..."),
    ("--Bw", "Bw", "--set with the loop's parameters, e.g. --set B=..."),
)
_GRID_OPTIONS = tuple((flag, dest, "--x-range/--y-range (the plane is --x/--y)")
                      for flag, dest, _ in _POINT_OPTIONS)
#: The simulation options of ``map``: a general loop has no simulator.
_SIMULATION_OPTIONS = tuple(
    (flag, dest, None) for flag, dest in (
        ("--encoder-resolution", "encoder_resolution"), ("--paper-encoder", "paper_encoder"),
        ("--velocity-cutoff", "velocity_cutoff"), ("--coulomb", "coulomb"),
        ("--stiction", "stiction"), ("--friction-compensation", "friction_compensation"),
        ("--actuator-bandwidth", "actuator_bandwidth"), ("--substeps", "substeps"),
        ("--steps", "steps"), ("--x0", "x0")))

#: The options each command refuses with ``--loop``.
_REFUSED = {
    "boundary": _DEVICE_OPTIONS,
    "limits": _DEVICE_OPTIONS + (("--beta", "beta", "--at X (the stable y at x = X)"),
                                 ("--Bw", "Bw", "--at X (the stable y at x = X)")),
    "classify": _DEVICE_OPTIONS + _POINT_OPTIONS,
    "design": _DEVICE_OPTIONS,
    "map": _DEVICE_OPTIONS + _GRID_OPTIONS + _SIMULATION_OPTIONS,
}
#: The options that only mean something with ``--loop``, per command.
_LOOP_ONLY = {
    "boundary": ("set_values", "x", "y"),
    "limits": ("set_values", "x", "y", "at"),
    "classify": ("set_values",),
    "design": ("set_values", "x", "y", "at"),
    "map": ("set_values", "x", "y", "x_range", "y_range"),
}
_FLAGS = {"set_values": "--set", "x": "--x", "y": "--y", "at": "--at",
          "x_range": "--x-range", "y_range": "--y-range"}

#: Memory per classified point of a map, per coefficient: the coefficients,
#: the environment's and the plant's arrays and the classifier's working
#: copies (generous).
_BYTES_PER_COEFFICIENT = 64
#: Bytes per map cell in the CSV and NPZ written (as cli_simulate's map).
_MAP_CELL_BYTES = 300

_EXAMPLE = "examples/loops/paper.toml"


#: What each command gives for a loop file, for its --help.
_WHAT = {
    "boundary": "boundary --loop gives the D-decomposition of the plane: the (x, y) at which "
                "z = exp(j theta) is a closed-loop pole, and the lines c0 + cx x + cy y = 0 "
                "on which a pole is at z = 1, z = -1 or infinity (leading coefficient 0).",
    "limits": "limits --loop gives the largest stable y, the x where it is reached, the x "
              "extent and the area of the stable set in the plane (with --at X the stable "
              "intervals of y at x = X).",
    "classify": "classify --loop gives the verdict, the spectral radius and the certified "
                "number of closed-loop poles outside the unit circle at the file's values "
                "changed by --set (comma lists: several points).",
    "design": "design --loop gives the largest stable y, the x where it is reached, and the "
              "stable intervals of y at that x (or at --at X).",
    "map": "map --loop classifies every cell of an x-y grid by its root count (no "
           "simulation) and draws the D-decomposition over it.",
}
#: The example of each command with a loop file.
_LOOP_EXAMPLES = {
    "boundary": f"symstab boundary --loop {_EXAMPLE} --set d=10 --n 11",
    "limits": f"symstab limits --loop {_EXAMPLE} --set M=0.0128 --at 0.3",
    "classify": f"symstab classify --loop {_EXAMPLE} --set K=1,3,10 --set B=0.2",
    "design": f"symstab design --loop {_EXAMPLE} --set d=10",
    "map": f"symstab map --loop {_EXAMPLE} --x-range=-0.1,0.6,141 --y-range=0,6,121 "
           "--out map.npz",
}


def add_loop_options(p, command):
    """Add ``--loop``, ``--set`` (and the plane options) of ``command`` to parser ``p``.

    Call it after the command's other options: the refused ones are recorded
    with their defaults, so that a refused option is recognised when given.
    """
    g = p.add_argument_group(
        "any loop (instead of the device options above)",
        textwrap.fill(f"A loop file (TOML, see {_EXAMPLE}) names the plant, the environment, the "
                      "default values and their units, converted to SI when the file is read; "
                      "--set changes a value, in the file's unit for it or in the unit it "
                      "gives.  --at, the ranges and the results are in the SI units shown.  "
                      f"{_WHAT[command]}  With --loop the paper's device options are refused "
                      "(--d still sets the delay d).", 77)
        + f"\nexample: {_LOOP_EXAMPLES[command]}")
    g.add_argument("--loop", metavar="FILE", help="loop file (TOML)")
    many = " (classify: a comma-separated list, one point per entry)" if command == "classify" else ""
    g.add_argument("--set", metavar="NAME=VALUE", action="append", dest="set_values",
                   help="set a parameter of the loop: VALUE is in the unit the file gives NAME "
                        "(SI where the file gives a bare number), or in the unit written after "
                        "it (--set T=0.5ms, --set \"K=3 N/mm\"), of the same dimension; "
                        "converted to SI and checked against the file's bounds; repeatable; d "
                        f"is a whole number of samples{many}")
    if command != "classify":
        g.add_argument("--x", metavar="NAME", help="horizontal parameter of the plane "
                                                   "(default: the file's plane)")
        g.add_argument("--y", metavar="NAME", help="vertical parameter of the plane "
                                                   "(default: the file's plane)")
    if command in ("limits", "design"):
        g.add_argument("--at", type=float, metavar="X",
                       help="also give the stable intervals of y at x = X"
                            + (" (default: the x of the largest y)" if command == "design" else ""))
    if command == "map":
        g.add_argument("--x-range", metavar="LOW,HIGH,N", help="grid of x (--x-range=-0.1,0.6,200)")
        g.add_argument("--y-range", metavar="LOW,HIGH,N", help="grid of y (--y-range=0,6,200)")
    refused = tuple((flag, dest, p.get_default(dest), instead)
                    for flag, dest, instead in _REFUSED[command])
    p.set_defaults(loop_command=command, loop_refused=refused)


def uses_loop(args):
    """True when the command runs on a loop file; refuses loop options without one."""
    if getattr(args, "loop", None) is not None:
        return True
    for dest in _LOOP_ONLY[args.loop_command]:
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{_FLAGS[dest]} needs a loop file: give --loop FILE "
                             f"(e.g. --loop {_EXAMPLE})")
    return False


def run(args):
    """Run ``args.loop_command`` on the loop file of ``args.loop``."""
    return _COMMANDS[args.loop_command](args)


# --------------------------------------------------------------------------
# Inputs


def _refuse_device_options(args):
    for flag, dest, default, instead in args.loop_refused:
        if getattr(args, dest, default) != default:
            if flag == "--linear":
                raise ValueError("--linear names the units of the paper's device options (rotary "
                                 "by default, linear with --linear: the same numbers); with "
                                 "--loop every value is in the units of the loop file, "
                                 "converted to SI: drop --linear")
            if instead is None:
                raise ValueError(f"{flag} is an option of the paper's device simulation; "
                                 f"map --loop classifies the loop by its roots and takes no "
                                 f"simulation options")
            raise ValueError(f"{flag} is an option of the paper's device; with --loop use "
                             f"{instead}")


#: A number at the start of a --set value, before its unit (0.25ms, 1e-3 s, 3 1/s).
_LEADING_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")


def _split_unit(text, flag):
    """``("0.25", "ms")`` from ``"0.25ms"`` or ``"0.25 ms"``; ``(text, None)`` without a unit.

    A list takes one unit, after its last value (``1,3,10 N/mm``).
    """
    head, comma, last = text.rpartition(",")
    last = last.strip()
    try:
        float(last)
        return text, None
    except ValueError:
        pass
    number = _LEADING_NUMBER.match(last)
    unit = last[number.end():].strip() if number else ""
    if not number or not unit:
        return text, None   # not a number: said so by _parse_number
    if "," in unit:
        raise ValueError(f"{flag}: give the unit once, after the last value")
    return head + comma + number.group(), unit


def _parse_number(name, text, flag, *, lists):
    """The value(s) of one ``--set``: a float, d an integer; a list where allowed."""
    items = [t.strip() for t in text.split(",")]
    if len(items) > 1 and not lists:
        raise ValueError(f"{flag}: {name} takes one value here (lists are for classify)")
    if not all(items):
        raise ValueError(f"{flag}: VALUE must be a number"
                         + (" or a comma-separated list without empty items" if lists else ""))
    values = []
    for item in items:
        try:
            value = float(item)
        except ValueError:
            raise ValueError(f"{flag}: {item!r} is not a number") from None
        if not math.isfinite(value):
            raise ValueError(f"{flag}: {name} must be a finite number, got {item!r}")
        if name == "d":
            from .._validate import check_delay
            try:
                value = check_delay(value)
            except ValueError as exc:
                raise ValueError(f"{flag}: {exc}") from None
        values.append(value)
    if name == "d" and len(values) > 1:
        raise ValueError(f"{flag}: d takes one value (run classify once per delay)")
    return values if len(values) > 1 else values[0]


def _parse_sets(texts, *, lists):
    """``{name: (value, unit)}`` of the ``--set NAME=VALUE [UNIT]`` options, in the order given.

    ``unit`` is None where the option gives none (the file's unit is meant).
    """
    out = {}
    for text in texts or ():
        flag = f"--set {text}"
        name, eq, value = text.partition("=")
        name = name.strip()
        if not eq or not name:
            raise ValueError(f"{flag}: expected NAME=VALUE, e.g. --set K=300")
        if name in out:
            raise ValueError(f"--set {name} is given twice; give each parameter once")
        value, unit = _split_unit(value, flag)
        out[name] = (_parse_number(name, value, flag, lists=lists), unit)
    return out


def _convert_sets(loop, sets):
    """The ``--set`` values in SI: (values, written), converted as the file's own.

    A value without a unit is in the file's unit for that parameter (SI where
    the file gives a bare number); one with a unit is converted from it,
    which must have the dimension of the parameter (from the file's unit, or
    implied by the loop).  ``written`` keeps what was typed, for the echo.
    """
    from ..numeric.loop_units import FileParameters, convert

    known = getattr(loop, "file_parameters", None) or FileParameters({})
    values, written = {}, {}
    for name, (value, unit) in sets.items():
        flag = f"--set {name}"
        file_unit = known.file_unit(name)
        if unit is None:
            unit = file_unit
        many = isinstance(value, list)
        items = [convert(name, v, unit, where=flag) for v in (value if many else [value])]
        info = items[0].info
        expected = (known.values[name].info.dimensions if file_unit is not None and name != "d"
                    else known.dimensions.get(name))
        if info is not None and expected is not None and info.dimensions != tuple(expected):
            from ..numeric.loop_units import dimension_name
            raise ValueError(f"{flag}: unit {unit!r} is {dimension_name(info.dimensions)}, and "
                             f"{name} is in {dimension_name(expected)}"
                             + (f" (the file gives it in {file_unit!r})" if file_unit else ""))
        values[name] = [i.si_value for i in items] if many else items[0].si_value
        written[name] = (value, items[0].unit, items[0].si_unit)
    return values, written


@dataclasses.dataclass(frozen=True)
class LoopSetup:
    """The resolved inputs of a loop command: what :func:`symstab.cli.numeric._emit` prints."""

    path: str
    loop: object          # symstab.Loop
    values: dict          # every value used, axes excluded
    given: tuple          # names set on the command line
    x: str = None
    y: str = None
    echo: tuple = ()
    #: What the file or a --set wrote where it differs from the SI value used:
    #: {name: (value as written, unit as written, SI unit)}.
    written: dict = dataclasses.field(default_factory=dict)

    def unit(self, name):
        return self.loop.units.get(name, "")

    def label(self, name):
        """``"K [N/m]"``, or the bare name when the file gives no unit."""
        unit = self.unit(name)
        return f"{name} [{unit}]" if unit else name

    def as_dict(self):
        loop = self.loop
        out = {"loop": self.path, "name": loop.name, "plant": str(loop.plant),
               "environment": str(loop.environment), "zoh": loop.zoh_method,
               "values": {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                          for k, v in self.values.items()},
               "set": list(self.given)}
        if self.x is not None:
            out["plane"] = {"x": self.x, "y": self.y}
        out["units"] = {k: loop.units[k] for k in loop.parameters if k in loop.units}
        written = {k: {"value": v, "unit": u} for k, (v, u, _) in self.written.items()
                   if k in self.values}
        if written:
            out["as_written"] = written   # converted to "values", in "units"
        return out


def _quantity_text(name, value):
    if isinstance(value, (list, tuple, np.ndarray)):
        return f"{name} = [" + ", ".join(f"{v:.10g}" for v in value) + "]"
    return f"{name} = {value:.10g}" if isinstance(value, float) else f"{name} = {value}"


def _quantity(setup, name, value):
    """``"K = 300 N/m"``, ``"K = [1, 3] N/m"``, ``"d = 40 samples"``, ``"T = 0.25 ms (0.00025 s)"``.

    A value the file or a ``--set`` gave in another unit is shown as written
    and, in brackets, as used (SI).
    """
    unit = setup.unit(name) or ("samples" if name == "d" else "")
    if unit == "samples" and value == 1:
        unit = "sample"
    text = _quantity_text(name, value) + (f" {unit}" if unit else "")
    if name in setup.written and name != "d":
        given, given_unit, _ = setup.written[name]
        shown = _quantity_text(name, given) + f" {given_unit}"
        if shown != text:
            return f"{shown} ({text.partition(' = ')[2]})"
    return text


def _echo(setup):
    loop = setup.loop
    lines = [f"loop {loop.name} ({setup.path}): G(s) = {loop.plant}, VE(z) = {loop.environment}"
             f"; ZOH by {loop.zoh_method}"]
    parts = [_quantity(setup, n, setup.values[n]) + (" (--set)" if n in setup.given else "")
             for n in loop.parameters if n in setup.values]
    lines.append("values: " + ", ".join(parts))
    if setup.x is not None:
        lines.append(f"plane: x = {setup.label(setup.x)}, y = {setup.label(setup.y)}")
    return tuple(lines)


def _load(path):
    from ..numeric.loop_files import load_loop

    return load_loop(path)


def _plane(args, loop):
    x, y = args.x, args.y
    if (x is None) != (y is None):
        raise ValueError("give the plane as both --x NAME and --y NAME, or neither "
                         "(the file's plane)")
    if x is None:
        if loop.plane is None:
            raise ValueError(f"the loop file {args.loop} names no plane: give --x NAME --y NAME "
                             f"(affine parameters: {', '.join(loop.affine_parameters()) or 'none'})")
        x, y = loop.plane
    return x, y


def _resolve(args, *, plane=True, lists=False):
    """Check every input of a loop command and return its :class:`LoopSetup`.

    Raises ValueError (one line for the user) before any long work: the
    values are checked by evaluating the loop once (the plane's D-
    decomposition at two angles, or the polynomial at the given points).
    """
    _refuse_device_options(args)
    sets = _parse_sets(args.set_values, lists=lists)
    if getattr(args, "d", None) is not None:
        if "d" in sets:
            raise ValueError("give the delay once: --d or --set d=...")
        sets["d"] = (args.d, None)
    loop = _load(args.loop)
    unknown = [n for n in sets if n not in loop.parameters]
    if unknown:
        raise ValueError(f"--set {unknown[0]}: {unknown[0]!r} is not a parameter of the loop in "
                         f"{args.loop} (parameters: {', '.join(loop.parameters)})")
    sets, written_sets = _convert_sets(loop, sets)
    x = y = None
    axes = ()
    if plane:
        x, y = _plane(args, loop)
        for name in (x, y):
            if name not in loop.parameters:
                raise ValueError(f"{'--x' if name == x else '--y'} {name}: not a parameter of the "
                                 f"loop in {args.loop} (parameters: {', '.join(loop.parameters)})")
        axes = (x, y)
        for axis, name in (("x", x), ("y", y)):
            if name in sets:
                hint = ("; use --at for the stable intervals at one x"
                        if axis == "x" and hasattr(args, "at") else "")
                raise ValueError(f"--set {name}: {name} is the plane's {axis} axis and takes no "
                                 f"single value here{hint}")
    values = {n: v for n, v in loop.defaults.items() if n not in axes}
    values.update(sets)
    missing = [n for n in loop.parameters if n not in values and n not in axes]
    if missing:
        raise ValueError(f"no value for {', '.join(missing)}: the loop file {args.loop} gives "
                         f"none; add --set {missing[0]}=VALUE")
    known = getattr(loop, "file_parameters", None)
    written = {}
    if known is not None:
        from ..numeric.loop_units import check_bounds

        written = {n: (v.value, v.unit, v.si_unit) for n, v in known.values.items()
                   if v.converted}
        # The bounds the file declares hold at the --set values too (the
        # file's own were checked when it was read).
        check_bounds(known, values, skip=axes, where=lambda names: (
            ", ".join(f"--set {n}=..." for n in sets if n in names) or str(args.loop)))
    written.update({n: w for n, w in written_sets.items()})
    if plane:
        loop.boundary(x=x, y=y, n=2, **values)   # checks the plane (affine) and the values
        point = {**values, x: 0.0, y: 0.0}
    else:
        check_memory("the points' coefficients", 8 * _points(values) * (values["d"] + 64))
        point = _broadcast(values)
    # An overflow in the plant's pulse transfer function (exp(-b T / m) at
    # T = 1e300, say) is a ValueError of the loop's, here before the work.
    loop.coefficients(**point)
    setup = LoopSetup(str(args.loop), loop, values, tuple(sets), x, y, written=written)
    return dataclasses.replace(setup, echo=_echo(setup))


def _points(values):
    return max((len(v) for v in values.values() if isinstance(v, list)), default=1)


def _broadcast(values):
    """The values as arrays of one length (lists of one length or single values)."""
    lengths = {n: len(v) for n, v in values.items() if isinstance(v, list)}
    if len(set(lengths.values())) > 1:
        text = ", ".join(f"{n} has {k}" for n, k in lengths.items())
        raise ValueError(f"--set lists must have the same length or one value: {text}")
    return {n: (np.array(v, dtype=float) if isinstance(v, list) else v) for n, v in values.items()}


# --------------------------------------------------------------------------
# Commands


def _emit(setup, fmt, columns, rows, **kwargs):
    from .numeric import _emit as emit

    emit(setup, fmt, columns, rows, **kwargs)


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
    x, y = setup.x, setup.y
    text = f"line {label}: {_signed([(c0, ''), (cx, x), (cy, y)])} = 0"
    if cy != 0:
        text += f", i.e. {y} = {_signed([(-c0 / cy + 0.0, ''), (-cx / cy + 0.0, x)])}"
    elif cx != 0:
        text += f", i.e. {x} = {-c0 / cx + 0.0:.10g}"
    return text


def _cmd_boundary(args):
    from .._validate import check_count
    from .numeric import _BYTES_PER_ROW

    setup = _resolve(args)
    n = check_count("n", args.n, 2)
    check_memory(f"--n {n} boundary points", n * _BYTES_PER_ROW)
    curve = setup.loop.boundary(x=setup.x, y=setup.y, n=n, **setup.values)
    columns = ["theta [rad]", setup.label(setup.x), setup.label(setup.y)]
    rows = list(zip(curve.theta, curve.x_values, curve.y_values))
    notes = [f"D-decomposition: z = exp(j theta) is a closed-loop pole at ({setup.x}, {setup.y}) "
             "(nan: the 2 x 2 system is singular at that theta)"]
    notes += [_line_text(setup, label, line) for label, line in curve.lines.items()]
    if not curve.lines:
        notes.append("no real-root or leading-coefficient line crosses this plane")
    result = {"lines": {label: dict(zip(("c0", "cx", "cy"), line))
                        for label, line in curve.lines.items()}}
    _emit(setup, args.format, columns, rows, result=result, notes=notes)
    return 0


def _intervals(setup, at):
    """The stable intervals of y at x = ``at``: (rows, notes, json)."""
    from .._validate import check_real

    at = check_real(f"--at ({setup.x})", at)
    from .numeric import interval_texts

    runs = setup.loop.stable_intervals(setup.y, **{setup.x: at}, **setup.values)
    unit_x = f" {setup.unit(setup.x)}" if setup.unit(setup.x) else ""
    unit_y = f" {setup.unit(setup.y)}" if setup.unit(setup.y) else ""
    codes = [tuple(setup.loop.classify(**{setup.x: at, setup.y: end}, **setup.values)
                   if math.isfinite(end) else None for end in run) for run in runs]
    text, ends, kinds = interval_texts(runs, codes, setup.y, setup.unit(setup.y))
    notes = [f"stable {setup.y} at {setup.x} = {at:.10g}{unit_x}: {text}"]
    if ends:
        notes.append(ends)
    # The z = 1 line of a loop with an integrator lies at y = 0 up to rounding
    # (1e-12 of the interval): no minimum worth naming.
    if runs and runs[0][0] > 1e-9 * (runs[0][1] - runs[0][0]):
        notes.append(f"a minimum is needed: {setup.y} > {runs[0][0]:.10g}{unit_y}")
    return notes, {"x": at, "intervals": [list(r) for r in runs], "ends": kinds}


def _limits_rows(setup, lim):
    ux, uy = setup.unit(setup.x), setup.unit(setup.y)
    area_unit = f"({ux})({uy})" if ux and uy else (ux or uy)
    x, y = setup.x, setup.y
    return [(f"{y}_max", lim.y_max, uy, f"largest stable {y}"),
            (f"{x} at {y}_max", lim.x_at_y_max, ux, f"the {x} where it is reached"),
            (f"{x}_min", lim.x_min, ux, f"leftmost {x} of the stable set"),
            (f"{x}_max", lim.x_max, ux, f"rightmost {x} of the stable set"),
            ("area", lim.area, area_unit, f"area of the stable set in the ({x}, {y}) plane")]


def _limits_notes(setup, lim):
    if lim.empty:
        return [f"no stable point in the ({setup.x}, {setup.y}) plane at these values: "
                f"{lim.reason or 'no cell of the window has every root inside the unit circle'}"]
    if math.isinf(lim.y_max) or math.isinf(lim.area):
        return [f"the stable set is unbounded in the ({setup.x}, {setup.y}) plane"]
    return []


def _limits_result(lim):
    out = {"x": lim.x, "y": lim.y, "y_max": lim.y_max, "x_at_y_max": lim.x_at_y_max,
           "x_min": lim.x_min, "x_max": lim.x_max, "area": lim.area, "cells": lim.cells}
    return {"limits": out}


def _passive(setup, lim):
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


def _cmd_limits(args):
    setup = _resolve(args)
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
    # Seconds at long delays (the plane's D-decomposition, and the passive set): say what runs.
    print(f"scanning the ({setup.x}, {setup.y}) plane for the extent of the stable set ...",
          file=sys.stderr, flush=True)
    lim = setup.loop.limits(x=setup.x, y=setup.y, **setup.values)
    rows = _limits_rows(setup, lim)
    notes = _limits_notes(setup, lim)
    result = _limits_result(lim)
    if args.at is not None:
        more, result["at"] = _intervals(setup, args.at)
        notes += more
    more, result["passive"] = _passive(setup, lim)
    notes += more
    _emit(setup, args.format, ["quantity", "value", "unit", "meaning"], rows, result=result,
          notes=notes, json_rows=False)
    return 0


def _cmd_design(args):
    setup = _resolve(args)
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
    print(f"searching the ({setup.x}, {setup.y}) plane for the largest stable {setup.y} ...",
          file=sys.stderr, flush=True)
    lim = setup.loop.limits(x=setup.x, y=setup.y, **setup.values)
    rows = _limits_rows(setup, lim)[:2]
    notes = _limits_notes(setup, lim)
    result = _limits_result(lim)
    at = args.at
    if at is None and not lim.empty and math.isfinite(lim.x_at_y_max):
        at = lim.x_at_y_max
    if at is not None:
        more, result["at"] = _intervals(setup, at)
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
    _emit(setup, args.format, ["quantity", "value", "unit", "meaning"], rows, result=result,
          notes=notes, json_rows=False)
    return 0


#: Above this delay ``classify --loop`` gives verdicts without the spectral radius
#: (eigenvalues of a (d + n)-square companion matrix per point).
_RADIUS_MAX_DELAY = 1000


def _cmd_classify(args):
    from ..numeric.stability import MARGINAL, STABLE

    setup = _resolve(args, plane=False, lists=True)
    loop, values = setup.loop, _broadcast(setup.values)
    n = _points(setup.values)
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
    _emit(setup, args.format, columns, rows, notes=notes)
    return 0


def _cmd_map(args):
    from .commands import write_output
    from .simulate import _grid, map_outputs
    from ..numeric.simulate import progress_printer
    from ..numeric.stability import MARGINAL, STABLE

    setup = _resolve(args)
    if args.x_range is None or args.y_range is None:
        raise ValueError("map --loop needs the grid: --x-range LOW,HIGH,N and --y-range LOW,HIGH,N")
    xs, ys = _grid(args.x_range, "--x-range"), _grid(args.y_range, "--y-range")
    out, png_path = map_outputs(args)
    loop, values = setup.loop, setup.values
    degree = loop.coefficients(**{setup.x: 0.0, setup.y: 0.0}, **values).shape[-1]
    # The cells are classified a chunk of x at a time; what stays is the codes
    # and the file's text.
    check_memory(f"a map of {xs.size} x {ys.size} cells",
                 xs.size * ys.size * _MAP_CELL_BYTES
                 + max(CHUNK_BYTES, ys.size * _BYTES_PER_COEFFICIENT * degree))
    for line in setup.echo:
        print(line)
    code = np.empty((xs.size, ys.size), dtype=np.int8)
    progress = progress_printer("classifying", xs.size)
    for part in chunk_slices(xs.size, ys.size * _BYTES_PER_COEFFICIENT * degree, CHUNK_BYTES):
        X, Y = np.meshgrid(xs[part], ys, indexing="ij")
        code[part] = loop.classify(**{setup.x: X, setup.y: Y}, **values)
        progress(part.stop)
    stable = code == STABLE
    if out.suffix == ".npz":
        buf = io.BytesIO()
        np.savez(buf, x=xs, y=ys, x_name=np.array(setup.x), y_name=np.array(setup.y),
                 x_unit=np.array(setup.unit(setup.x)), y_unit=np.array(setup.unit(setup.y)),
                 code=code, stable=stable,
                 values=np.array([_quantity(setup, n, values[n]) for n in loop.parameters
                                  if n in values]),
                 loop=np.array(str(setup.path)))
        data = buf.getvalue()
    else:
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        buf = io.StringIO()
        buf.write(f"{setup.label(setup.x)},{setup.label(setup.y)},code,stable\n")
        for xv, yv, c in zip(X.ravel(), Y.ravel(), code.ravel()):
            buf.write(f"{xv:.12g},{yv:.12g},{int(c)},{int(c == STABLE)}\n")
        data = buf.getvalue()
    image = _png(setup, xs, ys, code) if png_path is not None else None
    write_output(out, data, "--out")
    written = [str(out)]
    if image is not None:
        write_output(png_path, image, "--png")
        written.append(str(png_path))
    print(f"{int(stable.sum())} of {code.size} cells stable, {int((code == MARGINAL).sum())} "
          f"marginal (code 1 stable, 0 marginal, -1 unstable; certified root counts)")
    print("wrote " + ", ".join(written))
    return 0


def _visible(values, lo, hi):
    """``values`` with NaN where far outside [lo, hi], so that a line breaks there."""
    span = hi - lo
    out = np.array(values, dtype=float)
    out[~((out > lo - 2 * span) & (out < hi + 2 * span))] = np.nan
    return out


def draw_lines(ax, lines, xs, ys, to_x=np.asarray, to_y=np.asarray):
    """Draw the D-decomposition's lines ``c0 + cx x + cy y = 0`` across a window; return the handles.

    ``xs`` and ``ys`` are the window's grids in the lines' plane; ``to_x`` and
    ``to_y`` take that plane's coordinates to the axes' (a map drawn in
    other units).
    """
    styles = {"z = 1": ("C0", "--"), "z = -1": ("C3", "--"), "leading": ("C1", ":")}
    handles = []
    for label, (c0, cx, cy) in lines.items():
        color, style = styles.get(label, ("C4", "-."))
        if cy != 0:
            px, py = xs[[0, -1]], -(c0 + cx * xs[[0, -1]]) / cy
        else:
            px, py = np.full(2, -c0 / cx), ys[[0, -1]]
        if np.all(py < ys[0]) or np.all(py > ys[-1]) or np.all(px < xs[0]) or np.all(px > xs[-1]):
            continue   # the line misses the window
        handles += ax.plot(to_x(px), to_y(py), color=color, ls=style, lw=1.2,
                           label=label.replace("leading", "leading coefficient 0")
                           .replace("z = 1", "root z = 1").replace("z = -1", "root z = -1"))
    return handles


def _png(setup, xs, ys, code):
    """The map as PNG bytes (None without matplotlib), with the D-decomposition drawn over it."""
    from .simulate import _tex_unit
    from ..figures import pyplot
    from ..numeric.stability import MARGINAL, STABLE

    try:
        plt = pyplot()
    except ValueError:
        print("matplotlib is not installed: no PNG", file=sys.stderr)
        return None
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    loop, x, y = setup.loop, setup.x, setup.y
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    shade = np.where(code == STABLE, 2, np.where(code == MARGINAL, 1, 0)).T
    ax.pcolormesh(xs, ys, shade, shading="nearest", vmin=0, vmax=2,
                  cmap=ListedColormap(["white", "#bdbdbd", "#7fc97f"]))
    curve = loop.boundary(x=x, y=y, n=4000, **setup.values)
    bx, by = _visible(curve.x_values, xs[0], xs[-1]), _visible(curve.y_values, ys[0], ys[-1])
    bx[np.isnan(by)] = np.nan
    handles = [Patch(facecolor="#7fc97f", label="stable")]
    if np.any(code == MARGINAL):
        handles.append(Patch(facecolor="#bdbdbd", label="marginal"))
    if np.any(np.isfinite(bx)):
        handles += ax.plot(bx, by, "k-", lw=1.2, label=r"$z = e^{j\theta}$ root (D-decomposition)")
    handles += draw_lines(ax, curve.lines, xs, ys)
    ax.set_xlim(xs[0], xs[-1])
    ax.set_ylim(ys[0], ys[-1])

    def axis_label(name):
        unit = setup.unit(name)
        return f"{name} [{_tex_unit(unit)}]" if unit else name

    ax.set_xlabel(axis_label(x))
    ax.set_ylabel(axis_label(y))
    # Wrapped to the width of the figure (a two-mass device has eight values),
    # between values only: no-break spaces inside each.
    fixed = ", ".join(_quantity(setup, n, setup.values[n]).replace(" ", "\u00a0")
                      for n in loop.parameters if n in setup.values)
    ax.set_title("\n".join([f"loop {loop.name}: stable set in the ({x}, {y}) plane (root counts)"]
                           + textwrap.wrap(fixed, 90)), fontsize=9)
    ax.legend(handles=handles, loc="best", fontsize=8, framealpha=0.9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


_COMMANDS = {"boundary": _cmd_boundary, "limits": _cmd_limits, "classify": _cmd_classify,
             "design": _cmd_design, "map": _cmd_map}
