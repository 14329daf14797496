"""``--loop FILE`` and ``--set NAME=VALUE``: the options of the commands on any loop.

``boundary``, ``limits``, ``classify``, ``design`` and ``map`` take a loop
file (:func:`symstab.load_loop`) instead of the paper's device options; the
file's default values are changed with ``--set NAME=VALUE`` (repeatable) and
the parameter plane is the file's ``plane`` unless ``--x``/``--y`` name
another.  The file's values are converted to SI when it is read
(:mod:`symstab.numeric.loop.quantities`); a ``--set`` value is in the file's unit
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
import math
import re
import sys
import textwrap
import warnings

import numpy as np

from .._resources import check_memory

__all__ = ["uncertain_box", "DEVICE_OPTIONS", "POINT_OPTIONS", "EXAMPLE", "LINEAR_WITH_LOOP", "add_loop_options",
           "uses_loop", "split_unit", "parse_number", "convert_sets", "LoopSetup", "value_text",
           "loop_echo", "load_loop_file", "add_delay", "check_names", "loop_values", "resolve_loop",
           "resolve_setup", "paper_setup", "TABLE_ONE", "point_count", "broadcast", "range_text",
           "converted_range", "check_box", "check_corners"]


#: The paper's device options every numeric command has, with the ``--set``
#: that replaces each under ``--loop`` (None: nothing does, as for the simulation options).
DEVICE_OPTIONS = (
    ("--m", "m", "--set m=..."), ("--b", "b", "--set b=..."), ("--T", "T", "--set T=..."),
    ("--Td", "Td", "--set Td=... (the delay in time, e.g. --set Td=40.5ms) or --set d=... "
                   "(in samples)"),
    ("--delta", "delta", "--set with the loop's own parameters"),
    ("--gamma", "gamma", "--set with the loop's virtual mass, e.g. --set M=..."),
    ("--Mw", "Mw", "--set with the loop's virtual mass, e.g. --set M=..."),
    ("--linear", "linear", None),
)

#: Stiffness and damping options: points (classify, limits) and grids (map).
POINT_OPTIONS = (
    ("--alpha", "alpha", "--set with the loop's parameters, e.g. --set K=..."),
    ("--beta", "beta", "--set with the loop's parameters, e.g. --set B=..."),
    ("--Kw", "Kw", "--set with the loop's parameters, e.g. --set K=..."),
    ("--Bw", "Bw", "--set with the loop's parameters, e.g. --set B=..."),
)

_GRID_OPTIONS = tuple((flag, dest, "--x-range/--y-range (the plane is --x/--y)")
                      for flag, dest, _ in POINT_OPTIONS)

#: The simulation options of the paper's device that a general loop has not:
#: its filter and lag are the loop's own environment and plant.
_SIMULATION_OPTIONS = (
    ("--velocity-cutoff", "velocity_cutoff",
     "a velocity filter written into the loop file's environment (examples/loops/"
     "lowpass_velocity.toml)"),
    ("--actuator-bandwidth", "actuator_bandwidth",
     "an actuator lag written into the loop file's plant (examples/loops/actuator_lag.toml)"))

#: The options each command refuses with ``--loop``.
_REFUSED = {
    "boundary": DEVICE_OPTIONS,
    "limits": DEVICE_OPTIONS + (("--beta", "beta", "--at X (the stable y at x = X)"),
                                ("--Bw", "Bw", "--at X (the stable y at x = X)")),
    "classify": DEVICE_OPTIONS + POINT_OPTIONS,
    "margins": DEVICE_OPTIONS + POINT_OPTIONS,
    "design": DEVICE_OPTIONS,
    "map": DEVICE_OPTIONS + _GRID_OPTIONS + _SIMULATION_OPTIONS,
    "simulate": DEVICE_OPTIONS + POINT_OPTIONS + _SIMULATION_OPTIONS,
}

#: The options that only mean something with ``--loop``, per command.
_LOOP_ONLY = {
    "boundary": ("set_values", "x", "y"),
    "limits": ("set_values", "x", "y", "at", "uncertain", "strips", "png"),
    "classify": ("set_values",),
    "margins": ("set_values",),
    "design": ("set_values", "x", "y", "at", "over", "search_range", "delay"),
    "map": ("set_values", "x", "y", "x_range", "y_range", "simulate", "uncertain", "samples",
            "seed", "margin", "delay_range"),
    "simulate": ("set_values", "delays", "seed"),
}

_FLAGS = {"set_values": "--set", "x": "--x", "y": "--y", "at": "--at",
          "x_range": "--x-range", "y_range": "--y-range", "over": "--over",
          "search_range": "--range", "simulate": "--simulate", "delay": "--delay",
          "uncertain": "--uncertain", "samples": "--samples", "seed": "--seed",
          "margin": "--margin", "delays": "--delays", "delay_range": "--delay-range",
          "strips": "--strips", "png": "--png"}


EXAMPLE = "examples/loops/paper.toml"

#: The paper's loop's parameters in Table I's variables (with m = T = 1).
TABLE_ONE = {"K": "alpha", "B": "beta", "M": "gamma", "b": "delta"}


#: What each command gives for a loop file, for its --help.
_WHAT = {
    "boundary": "boundary --loop gives the D-decomposition of the plane: the (x, y) at which "
                "z = exp(j theta) is a closed-loop pole, the lines c0 + cx x + cy y = 0 "
                "on which a pole is at z = 1, z = -1 or infinity (leading coefficient 0), "
                "and the pieces of them that close the stable set.",
    "limits": "limits --loop gives the largest stable y, the x where it is reached, the x "
              "extent and the area of the stable set in the plane (with --at X the stable "
              "intervals of y at x = X).",
    "classify": "classify --loop gives the verdict, the spectral radius and the certified "
                "number of closed-loop poles outside the unit circle at the file's values "
                "changed by --set (comma lists: several points).",
    "design": "design --loop searches one or two parameters outside the plane (--over "
              "NAME=LO:HI, default the environment's mass term, e.g. M) for the largest "
              "stable y, area, passive y or simulated y (--maximize), as design searches the virtual "
              "mass, and gives the best values, the target there and at the nominal values, "
              "the x where y_max is reached and the stable intervals of y at that x (or at "
              "--at X).",
    "simulate": "simulate --loop runs the loop at the file's values changed by --set (the "
                "plant's exact ZOH step, the environment's difference equation, the delay "
                "line; encoder quantization and force saturation in the loop's SI "
                "units) and compares the verdict with its certified root count.",
    "margins": "margins --loop gives, at the file's values changed by --set (a stable "
               "point), the modulus margin min|1+L| (certified), every gain and phase "
               "margin, the stable interval of each plane parameter through the point and "
               "the delay margin in whole samples.",
    "map": "map --loop classifies every cell of an x-y grid by its certified root count "
           "and draws the D-decomposition over it; with --simulate it also simulates every "
           "cell and compares.",
}
#: The example of each command with a loop file.
_LOOP_EXAMPLES = {
    "boundary": f"symstab boundary --loop {EXAMPLE} --set d=10 --n 11",
    "limits": f"symstab limits --loop {EXAMPLE} --set M=0.0128 --at 0.3",
    "classify": f"symstab classify --loop {EXAMPLE} --set K=1,3,10 --set B=0.2",
    "design": f"symstab design --loop {EXAMPLE} --set d=10",
    "simulate": f"symstab simulate --loop {EXAMPLE} --set K=3 --set B=0.2 --out trajectory.csv",
    "margins": f"symstab margins --loop {EXAMPLE} --set K=3 --set B=0.2",
    "map": f"symstab map --loop {EXAMPLE} --x-range=-0.1,0.6,141 --y-range=0,6,121 "
           "--out map.npz",
}


def add_loop_options(p, command):
    """Add ``--loop``, ``--set`` (and the plane options) of ``command`` to parser ``p``.

    Call it after the command's other options: the refused ones are recorded
    with their defaults, so that a refused option is recognised when given.
    """
    g = p.add_argument_group(
        "any loop (instead of the device options above)",
        textwrap.fill(f"A loop file (TOML, see {EXAMPLE}) names the plant, the environment, the "
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
                        "converted to SI and checked against the file's bounds; repeatable; "
                        "the delay is d in samples (40.5: a fraction of a period more) or Td in "
                        f"time (--set Td=40.5ms), one value{many}")
    if command not in ("classify", "simulate", "margins"):
        g.add_argument("--x", metavar="NAME", help="horizontal parameter of the plane "
                                                   "(default: the file's plane)")
        g.add_argument("--y", metavar="NAME", help="vertical parameter of the plane "
                                                   "(default: the file's plane)")
    if command in ("limits", "design"):
        g.add_argument("--at", type=float, metavar="X",
                       help="also give the stable intervals of y at x = X"
                            + (" (default: the x of the largest y)" if command == "design" else ""))
    if command == "limits":
        g.add_argument("--uncertain", metavar="NAME=LO:HI", action="append",
                       help="the robust limits instead: of the points stable for every value of "
                            "NAME in LO:HI (its SI unit, or the unit written after HI: --uncertain "
                            "\"b=0.02:0.045 N*m*s/rad\"; d: the whole delays LO..HI, or every "
                            "delay where an end is fractional; Td=LO:HI: every delay, in time, "
                            "1.5ms:2.5ms), certified by zero exclusion; repeatable for a box")
        g.add_argument("--strips", type=int, metavar="N",
                       help="with --uncertain: vertical strips across the plane (default 64; "
                            "more strips, a larger certified set and a longer run)")
        g.add_argument("--png", metavar="FILE",
                       help="with --uncertain: draw the robust set beside the nominal one "
                            "(a .png file)")
    if command == "design":
        g.add_argument("--over", metavar="NAME[=LO:HI]", action="append",
                       help="a parameter searched, with its range in its SI unit or in the "
                            "unit written after it (--over \"f_c=20:400 Hz\"); repeat for two "
                            "parameters (default: the environment's mass term, a parameter of "
                            "it in kg or kg m^2 outside the plane)")
        g.add_argument("--range", metavar="LO:HI", dest="search_range",
                       help="the range of a single --over NAME given without one (default "
                            "for a mass term: design's gamma range, -1 - (d + 1) delta + 0.001 "
                            "to 3, times the device's mass: the sum of the plant's parameters "
                            "in the unit of the mass term, with delta = b T / mass where the "
                            "loop has a damping b, else 0)")
    if command == "map":
        _add_map_options(g)
    refused = tuple((flag, dest, p.get_default(dest), instead)
                    for flag, dest, instead in _REFUSED[command])
    p.set_defaults(loop_command=command, loop_refused=refused)


def _add_map_options(g):
    """``map --loop``'s own options: what it maps (a classification by default) and its grid."""
    g.add_argument("--simulate", action="store_true", default=None,
                   help="also simulate every cell (the plant's exact ZOH step, the "
                        "environment's difference equation, the delay line; with "
                        "--steps, --x0, --encoder-resolution, --force-limit, "
                        "--force-resolution in the "
                        "loop's SI units)")
    g.add_argument("--uncertain", metavar="NAME=LO:HI", action="append",
                   help="instead of one classification, the probability that each cell is "
                        "stable when NAME is drawn uniformly from LO:HI (its SI unit, or "
                        "the unit written after HI: --uncertain \"b=0.02:0.045 N*m*s/rad\"; "
                        "d: the whole delays LO..HI, drawn continuously where an end is "
                        "fractional; Td=LO:HI in time, 1.5ms:2.5ms); repeatable")
    g.add_argument("--margin", choices=("modulus", "delay", "gain"),
                   help="instead of the classification, a margin at every stable cell: "
                        "modulus, min|1+L| on the unit circle, certified; delay, the exact "
                        "delay margin (the smallest added delay, samples, at which a root "
                        "reaches the circle); gain, the smallest factor of the loop gain "
                        "that does (the other cells hold NaN)")
    g.add_argument("--delay-range", nargs=2, metavar=("TMIN", "TMAX"),
                   help="instead of the classification, the cells stable for every "
                        "constant loop delay from TMIN to TMAX (a time: 40ms, or seconds; "
                        "the exact delay margin) and for every delay varying in it by whole "
                        "samples (a small-gain bound, sufficient only)")
    g.add_argument("--samples", type=int, metavar="N",
                   help="draws with --uncertain (default 1000)")
    g.add_argument("--seed", type=int, metavar="S",
                   help="seed of the draws with --uncertain (default 0: the same map every "
                        "run)")
    g.add_argument("--x-range", metavar="LOW,HIGH,N", help="grid of x (--x-range=-0.1,0.6,200)")
    g.add_argument("--y-range", metavar="LOW,HIGH,N", help="grid of y (--y-range=0,6,200)")


def uses_loop(args):
    """True when the command runs on a loop file; refuses loop options without one."""
    if getattr(args, "loop", None) is not None:
        return True
    for dest in _LOOP_ONLY[args.loop_command]:
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{_FLAGS[dest]} needs a loop file: give --loop FILE "
                             f"(e.g. --loop {EXAMPLE})")
    return False


# --------------------------------------------------------------------------
# Inputs


#: Why ``--linear`` is refused with ``--loop``.
LINEAR_WITH_LOOP = ("--linear names the units of the paper's device options (rotary by default, "
                    "linear with --linear: the same numbers); with --loop every value is in the "
                    "units of the loop file, converted to SI: drop --linear")


def _refuse_device_options(args):
    for flag, dest, default, instead in args.loop_refused:
        if getattr(args, dest, default) != default:
            if flag == "--linear":
                raise ValueError(LINEAR_WITH_LOOP)
            if instead is None:
                raise ValueError(f"{flag} is an option of the paper's device simulation: "
                                 f"Coulomb friction needs the plant's velocity, which a loop "
                                 f"file's simulator does not model yet")
            raise ValueError(f"{flag} is an option of the paper's device; with --loop use "
                             f"{instead}")


#: A number at the start of a --set value, before its unit (0.25ms, 1e-3 s, 3 1/s).
_LEADING_NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")


def split_unit(text, flag):
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
        return text, None   # not a number: said so by parse_number
    if "," in unit:
        raise ValueError(f"{flag}: give the unit once, after the last value")
    return head + comma + number.group(), unit


def time_value(text, flag):
    """A delay given on the command line (``"2ms"``, ``"0.002"``: seconds without a unit), in s.

    Converted as a loop delay ``Td`` is: a unit must be a time; not negative.
    """
    from .._validate import check_real
    from ..numeric.loop.quantities import convert

    text, unit = split_unit(text.strip(), flag)
    value = parse_number("Td", text, flag, lists=False)
    return check_real(flag, convert("Td", value, unit, where=flag).si_value, low=0.0)


def delay_range_option(texts, loop, values):
    """``--delay-range TMIN TMAX``: ``(Td_min, Td_max)`` in s, checked before any work.

    Each a time (:func:`time_value`), ``TMIN <= TMAX``, within
    ``SYMSTAB_MAX_DELAY`` at the period of ``values`` (or the loop's).
    """
    from .._validate import check_real
    from ..numeric.analysis.delay_range import range_in_samples

    delays = tuple(time_value(text, "--delay-range") for text in texts)
    check_real("--delay-range's TMAX", delays[1], low=delays[0])
    range_in_samples(loop, delays, **{k: v for k, v in values.items() if k not in ("d", "Td")})
    return delays


def parse_number(name, text, flag, *, lists, written=None):
    """The value(s) of one ``--set``: a float, d an integer; a list where allowed.

    ``written`` is the value as the user wrote it, unit included
    (``"5.1 ms"``): the messages show it (default ``text``).
    """
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
            shown = item if len(items) > 1 or written is None else written.strip()
            raise ValueError(f"{flag}: {name} must be a finite number, got {shown!r}")
        if name == "d":
            value = _samples(value, flag, (written if written is not None else text).strip())
        values.append(value)
    if name in ("d", "Td") and len(values) > 1:
        raise ValueError(f"{flag}: {name} takes one value (run classify once per delay)")
    return values if len(values) > 1 else values[0]


def _samples(value, flag, shown):
    """``--set d=VALUE``: an int when whole, else the float (40.5); refused outside 0 to the limit."""
    from .._validate import delay_samples

    try:
        return delay_samples(value, name="d")
    except ValueError:
        from .._resources import max_delay
        raise ValueError(f"{flag}: delay d must be a number of samples from 0 to {max_delay()} "
                         f"(unit \"samples\", or none; 40.5 is a fraction of a period more), "
                         f"got {shown!r}") from None


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
        number, unit = split_unit(value, flag)
        out[name] = (parse_number(name, number, flag, lists=lists, written=value), unit)
    return out


def convert_sets(loop, sets, flag="--set"):
    """The ``--set`` values in SI: (values, written), converted as the file's own.

    A value without a unit is in the file's unit for that parameter (SI where
    the file gives a bare number); one with a unit is converted from it,
    which must have the dimension of the parameter (from the file's unit, or
    implied by the loop).  ``written`` keeps what was typed, for the echo.
    Messages name ``flag NAME`` (``--over`` for design's ranges).
    """
    from ..numeric.loop.quantities import FileParameters, convert

    known = getattr(loop, "file_parameters", None) or FileParameters({})
    values, written = {}, {}
    option = flag
    for name, (value, unit) in sets.items():
        flag = f"{option} {name}"
        file_unit = known.file_unit(name)
        if unit is None:
            unit = file_unit
        many = isinstance(value, list)
        items = [convert(name, v, unit, where=flag) for v in (value if many else [value])]
        info = items[0].info
        expected = (known.values[name].info.dimensions if file_unit is not None and name != "d"
                    else known.dimensions.get(name))
        if info is not None and expected is not None and info.dimensions != tuple(expected):
            from ..numeric.loop.quantities import dimension_name
            raise ValueError(f"{flag}: unit {unit!r} is {dimension_name(info.dimensions)}, and "
                             f"{name} is in {dimension_name(expected)}"
                             + (f" (the file gives it in {file_unit!r})" if file_unit else ""))
        if info is not None and expected is not None:
            # The dimension fits; an angle (a number to pint) must fit too.
            from ..numeric.loop.quantities import check_angle, parameter_angle
            own_info = known.values[name].info if file_unit is not None else None
            check_angle(name, info, parameter_angle(tuple(expected), own_info), where=flag,
                        si_unit=items[0].si_unit if own_info is None else
                        (file_unit if own_info.angle else None))
        values[name] = [i.si_value for i in items] if many else items[0].si_value
        written[name] = (value, items[0].unit, items[0].si_unit)
    return values, written


@dataclasses.dataclass(frozen=True)
class LoopSetup:
    """The resolved inputs of a loop command: what :func:`symstab.cli.output.emit` prints."""

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
    #: The paper's device options (a :class:`symstab.cli.options.Setup`) where
    #: they gave the loop: ``loop`` is then the paper's loop in Table I's
    #: variables (:func:`symstab.numeric.paper.paper_loop.paper_point`).
    paper: object = None

    def unit(self, name):
        return "" if self.paper is not None else self.loop.units.get(name, "")

    @property
    def d(self):
        """The delay in samples (an int, or a float for a fractional delay)."""
        return self.values.get("d")

    @property
    def fractional(self):
        """Whether the delay is not a whole number of samples (``d = 40.5``)."""
        return self.d is not None and not float(self.d).is_integer()

    def name(self, name):
        """A parameter's name as printed: Table I's for the paper's device options."""
        return TABLE_ONE.get(name, name) if self.paper is not None else name

    def label(self, name):
        """``"K [N/m]"``, or the bare name when the file gives no unit (Table I's for the paper)."""
        if self.paper is not None:
            return TABLE_ONE.get(name, name)
        unit = self.unit(name)
        return f"{name} [{unit}]" if unit else name

    def as_dict(self):
        if self.paper is not None:
            return self.paper.as_dict()
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
                   if k in self.values or k == "Td"}
        if written:
            out["as_written"] = written   # converted to "values", in "units"
        return out


def range_text(text, flag, *, point=False):
    """``(low, high, unit)`` of ``LO:HI`` with an optional unit after HI (``--over``, ``--uncertain``;
    ``point``: ``LO == HI`` allowed)."""
    from .._validate import check_real

    head, colon, tail = text.partition(":")
    tail, unit = split_unit(tail.strip(), flag)
    try:
        if not colon:
            raise ValueError
        low, high = (check_real(flag, float(v)) for v in (head, tail))
    except (ValueError, TypeError):
        raise ValueError(f"{flag} must be LO:HI, two finite numbers (a unit may follow), "
                         f"got {text!r}") from None
    if not (low <= high if point else low < high):
        raise ValueError(f"{flag}: LO:HI must have LO {'<=' if point else '<'} HI, got {text!r}")
    if not math.isfinite(high - low):
        raise ValueError(f"{flag}: HI - LO must be finite (below 1.8e308), got {text!r}")
    return low, high, unit


def converted_range(setup, name, low, high, unit, *, flag):
    """``(low, high)`` in SI: converted from ``unit`` as a ``--set`` value is (None: SI)."""
    if unit is None:
        return low, high
    values, _ = convert_sets(setup.loop, {name: ([low, high], unit)}, flag=flag)
    low, high = values[name]
    return float(low), float(high)


def check_box(setup, box, flag):
    """Every corner of the box ``{name: (low, high)}`` within the file's bounds and the loop's domain.

    ``flag`` names the option that gave the box (``--over``, ``--uncertain``).
    """
    check_corners(setup.loop, setup.values, setup.x, setup.y, box,
                  " ".join(f"{flag} {n}" for n in box))


def check_corners(loop, values, x, y, box, where):
    """Every corner of ``box`` (``{name: (low, high)}``; ``d`` whole) at ``values``, checked.

    Within the loop file's bounds and the loop's domain (its polynomial
    exists there, the plane's parameters at 0); the message begins with
    ``where`` and names the corner.
    """
    from ..numeric.analysis.design import box_corners
    from ..numeric.loop.quantities import FileParameters, check_bounds

    known = getattr(loop, "file_parameters", None) or FileParameters({})
    for corner in box_corners(box):
        corner = {n: int(v) if n == "d" and float(v).is_integer() else float(v)
                  for n, v in corner.items()}
        # The corner's delay replaces the other form's (d in samples, Td in time).
        other = {"d": "Td", "Td": "d"}
        at_corner = {**{k: v for k, v in values.items()
                        if not (k in other and other[k] in corner)}, **corner}
        check_bounds(known, at_corner, skip=(x, y), where=lambda names: where)
        try:
            loop.polynomial(**{**at_corner, x: 0.0, y: 0.0})
        except (TypeError, ValueError) as exc:
            at = ", ".join(f"{k} = {v:.6g}" for k, v in corner.items())
            raise ValueError(f"{where}: at {at}: {exc}") from None


def _quantity_text(name, value):
    if isinstance(value, (list, tuple, np.ndarray)):
        return f"{name} = [" + ", ".join(f"{v:.10g}" for v in value) + "]"
    return f"{name} = {value:.10g}" if isinstance(value, float) else f"{name} = {value}"


def value_text(setup, name, value):
    """``"K = 300 N/m"``, ``"K = [1, 3] N/m"``, ``"d = 40 samples"``, ``"T = 0.25 ms (0.00025 s)"``.

    A value the file or a ``--set`` gave in another unit is shown as written
    and, in brackets, as used (SI).
    """
    unit = setup.unit(name) or ("samples" if name == "d" else "")
    if unit == "samples" and value == 1:
        unit = "sample"
    text = _quantity_text(name, value) + (f" {unit}" if unit else "")
    if name == "d" and "Td" in setup.written:
        # Given in time: "Td = 40.5 ms (d = 40.5 samples)".
        given, given_unit, _ = setup.written["Td"]
        return f"{_quantity_text('Td', given)} {given_unit} ({text})"
    if name in setup.written and name != "d":
        given, given_unit, _ = setup.written[name]
        shown = _quantity_text(name, given) + f" {given_unit}"
        if shown != text:
            return f"{shown} ({text.partition(' = ')[2]})"
    return text


def loop_echo(setup):
    """The lines that echo a loop command's inputs: the loop, every value used, the plane."""
    loop = setup.loop
    lines = [f"loop {loop.name} ({setup.path}): G(s) = {loop.plant}, VE(z) = {loop.environment}"
             f"; ZOH by {loop.zoh_method}"]
    given = set(setup.given) | ({"d"} if "Td" in setup.given else set())
    parts = [value_text(setup, n, setup.values[n]) + (" (--set)" if n in given else "")
             for n in loop.parameters if n in setup.values]
    lines.append("values: " + ", ".join(parts))
    if setup.x is not None:
        lines.append(f"plane: x = {setup.label(setup.x)}, y = {setup.label(setup.y)}")
    return tuple(lines)


def load_loop_file(path):
    """The :class:`symstab.Loop` of the loop file at ``path`` (:func:`symstab.load_loop`)."""
    from ..numeric.loop.files import load_loop

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


def add_delay(args, sets):
    """Add ``--d`` to ``sets`` (``{name: (value, unit)}`` of the ``--set`` options), once."""
    if getattr(args, "d", None) is not None:
        if "d" in sets:
            raise ValueError("give the delay once: --d or --set d=...")
        sets["d"] = (args.d, None)
    return sets


def check_names(args, loop, names):
    """Refuse the first of ``names`` (given with ``--set``) that is not a parameter of ``loop``.

    ``Td`` is the delay ``d`` in time.
    """
    if "Td" in names and "d" in names:
        raise ValueError("give the delay once: --set Td=... (in time) or --set d=... / --d "
                         "(in samples)")
    unknown = [n for n in names if n not in loop.parameters and n != "Td"]
    if unknown:
        raise ValueError(f"--set {unknown[0]}: {unknown[0]!r} is not a parameter of the loop in "
                         f"{args.loop} (parameters: {', '.join(loop.parameters)})")


def loop_values(args, loop, sets, written_sets, *, skip=()):
    """``(values, written)``: the file's defaults but ``skip``, changed by ``sets``, checked.

    ``sets`` are the ``--set`` values in SI (:func:`convert_sets`, which also
    gives ``written_sets``); a parameter without a value, or a value outside
    the bounds the file declares, is a ValueError.  ``written`` is what the
    file or a ``--set`` wrote where it differs from the SI value used
    (:attr:`LoopSetup.written`).
    """
    values = {n: v for n, v in loop.defaults.items() if n not in skip}
    if {"d", "Td"} & set(sets):
        # The delay given replaces the file's, in whichever form the file gave it.
        values.pop("d", None)
        values.pop("Td", None)
    values.update(sets)
    seconds = _delay_in_time(args, loop, values, sets, written_sets, skip)
    missing = [n for n in loop.parameters if n not in values and n not in skip]
    if missing:
        raise ValueError(f"no value for {', '.join(missing)}: the loop file {args.loop} gives "
                         f"none; add --set {missing[0]}=VALUE")
    known = getattr(loop, "file_parameters", None)
    written = {}
    if known is not None:
        from ..numeric.loop.quantities import check_bounds

        written = {n: (v.value, v.unit, v.si_unit) for n, v in known.values.items()
                   if v.converted}
        # The bounds the file declares hold at the --set values too (the
        # file's own were checked when it was read).
        check_bounds(known, values, skip=skip, where=lambda names: (
            ", ".join(f"--set {n}=..." for n in sets if n in names) or str(args.loop)))
    written.update(written_sets)
    written.pop("Td", None)     # the file's Td, where --set d=... replaced it
    if seconds is not None:
        written["Td"] = seconds
    return values, written


def _delay_in_time(args, loop, values, sets, written_sets, skip):
    """Turn a delay in time (``Td``, the file's or ``--set``'s) into ``values["d"]``, in samples.

    The commands count in samples (``Td / T``, 40.5 where it is not whole,
    as :meth:`symstab.Loop.classify` reads ``Td``), so ``T`` must be one
    value.  Returns ``(Td as written, its unit, "s")`` for the echo, or
    None where the delay is given in samples.
    """
    if "Td" not in values:
        return None
    Td = values.pop("Td")
    where = "--set Td" if "Td" in sets else f"the loop file {args.loop}'s Td"
    if "T" in skip or isinstance(values.get("T"), list) or "T" not in values:
        raise ValueError(f"{where}: a delay in time needs one sample period T (here T is "
                         f"{'an axis of the plane' if 'T' in skip else 'not one value'}): "
                         f"give the delay in samples, --set d=...")
    from .._validate import check_real, split_delay

    Td = check_real("Td", Td, low=0.0)
    try:
        whole, fraction = split_delay(Td / values["T"], name="Td / T")
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    values["d"] = whole if fraction is None else whole + float(fraction)
    if "Td" in written_sets:
        given, unit, _ = written_sets.pop("Td")
        return given, unit or "s", "s"
    entry = getattr(loop, "file_parameters", None)
    entry = entry.values.get("Td") if entry is not None and "Td" not in sets else None
    return (Td, "s", "s") if entry is None else (entry.value, entry.unit or "s", "s")


def _report_plant(args, caught):
    """One stderr line for a plant that is not a physical device's; other warnings as they were.

    The first :class:`~symstab.symbolic.loop_assembly.NonPhysicalPlantWarning`
    is printed as ``symstab <command>: warning: ...`` (with how many other
    points have one), and the rest of the command does not repeat it (the
    CLI's warning filters are restored when the command ends).
    """
    from ..symbolic.loop_assembly import NonPhysicalPlantWarning

    plant = [w for w in caught if issubclass(w.category, NonPhysicalPlantWarning)]
    for w in caught:
        if not issubclass(w.category, NonPhysicalPlantWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if plant:
        more = (f" (and at {len(plant) - 1} other point{'s' if len(plant) > 2 else ''})"
                if len(plant) > 1 else "")
        print(f"symstab {args.command}: warning: {plant[0].message}{more}", file=sys.stderr)
        warnings.simplefilter("ignore", NonPhysicalPlantWarning)


def resolve_loop(args, *, plane=True, lists=False):
    """Check every input of a loop command and return its :class:`LoopSetup`.

    Raises ValueError (one line for the user) before any long work: the
    values are checked by evaluating the loop once (the plane's D-
    decomposition at two angles, or the polynomial at the given points).
    """
    _refuse_device_options(args)
    sets = _parse_sets(args.set_values, lists=lists)
    add_delay(args, sets)
    loop = load_loop_file(args.loop)
    check_names(args, loop, sets)
    sets, written_sets = convert_sets(loop, sets)
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
    values, written = loop_values(args, loop, sets, written_sets, skip=axes)
    from ..symbolic.loop_assembly import NonPhysicalPlantWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", NonPhysicalPlantWarning)
        if plane:
            loop.boundary(x=x, y=y, n=2, **values)   # checks the plane (affine) and the values
            point = {**values, x: 0.0, y: 0.0}
        else:
            check_memory("the points' coefficients", 8 * point_count(values) * (values["d"] + 64))
            point = broadcast(values)
        # An overflow in the plant's pulse transfer function (exp(-b T / m) at
        # T = 1e300, say) is a ValueError of the loop's, here before the work.
        loop.coefficients(**point)
    _report_plant(args, caught)
    setup = LoopSetup(str(args.loop), loop, values, tuple(sets), x, y, written=written)
    return dataclasses.replace(setup, echo=loop_echo(setup))


def resolve_setup(args, *, plane=True, lists=False):
    """The :class:`LoopSetup` of a command: the loop file of ``--loop``, else the paper's options.

    The paper's device options (:func:`symstab.cli.options.resolve`) are
    shorthand for the paper's loop: :func:`~symstab.numeric.paper.paper_loop.paper_point`
    at their ``gamma, d, delta``, whose plane ``(B, K)`` is Table I's
    ``(beta, alpha)``, with :attr:`LoopSetup.paper` the device for the
    physical columns and the echo.
    """
    if uses_loop(args):
        return resolve_loop(args, plane=plane, lists=lists)
    from .options import resolve

    return paper_setup(resolve(args), plane=plane)


def paper_setup(paper, *, plane=True):
    """The :class:`LoopSetup` of the paper's device options ``paper`` (a resolved ``Setup``).

    The paper's loop at ``m = T = 1``
    (:func:`~symstab.numeric.paper.paper_loop.paper_point`): its parameters are
    Table I's variables, its plane ``(B, K)`` is ``(beta, alpha)``.
    """
    from ..numeric.paper.paper_loop import paper_point

    loop, values = paper_point(gamma=paper.gamma, d=math.floor(paper.d), delta=paper.delta)
    # A fractional delay is in samples, so the same at m = T = 1: the loop's
    # engine takes it (its closed forms, eq. (5) and (7), are for whole d).
    values["d"] = paper.d
    x, y = ("B", "K") if plane else (None, None)
    return LoopSetup("", loop, values, (), x, y, echo=paper.echo, paper=paper)


def point_count(values):
    """The number of points given: the length of the longest ``--set`` list, else 1."""
    return max((len(v) for v in values.values() if isinstance(v, list)), default=1)


def broadcast(values):
    """The values as arrays of one length (lists of one length or single values)."""
    lengths = {n: len(v) for n, v in values.items() if isinstance(v, list)}
    if len(set(lengths.values())) > 1:
        text = ", ".join(f"{n} has {k}" for n, k in lengths.items())
        raise ValueError(f"--set lists must have the same length or one value: {text}")
    return {n: (np.array(v, dtype=float) if isinstance(v, list) else v) for n, v in values.items()}


def uncertain_box(args, setup, *, point=False):
    """``{name: (low, high)}`` of the ``--uncertain`` options, in SI, checked against the file
    (``point``: a range of zero width allowed).

    The delay as ``d=LO:HI`` in samples (whole ends: whole delays; a
    fractional end: a continuum) or ``Td=LO:HI`` in time (``1.5ms:2.5ms``, or
    a unit after HI, seconds without one), once, within ``SYMSTAB_MAX_DELAY``.
    """
    loop = setup.loop
    others = [n for n in loop.parameters if n not in (setup.x, setup.y)] + ["Td"]
    given = {text.partition("=")[0].strip() for text in (args.set_values or [])}
    box = {}
    for text in args.uncertain:
        name, eq, window = text.partition("=")
        name = name.strip()
        if not eq or not name:
            raise ValueError(f"--uncertain {text}: expected NAME=LO:HI, e.g. --uncertain "
                             f"b=0.02:0.045")
        if name in box:
            raise ValueError(f"--uncertain {name} is given twice; give each parameter once")
        if name in given:
            raise ValueError(f"--uncertain {name}: {name} is also given by --set; give it once")
        if name not in loop.parameters and name != "Td":
            raise ValueError(f"--uncertain {name}: not a parameter of the loop in {args.loop} "
                             f"(candidates: {', '.join(others)})")
        if name in (setup.x, setup.y):
            raise ValueError(f"--uncertain {name}: {name} is an axis of the ({setup.x}, "
                             f"{setup.y}) plane; give another parameter (candidates: "
                             f"{', '.join(others)})")
        if name == "Td":
            box[name] = _time_range(window, point=point)
            continue
        low, high, unit = range_text(window, f"--uncertain {name}", point=point)
        if name == "d":
            if unit not in (None, "samples") or low < 0:
                raise ValueError(f"--uncertain d: the delay in samples, >= 0 (a fraction of a "
                                 f"period included; Td=LO:HI in time), got {window!r}")
            whole = low.is_integer() and high.is_integer()
            box[name] = (int(low), int(high)) if whole else (low, high)
        else:
            box[name] = converted_range(setup, name, low, high, unit, flag="--uncertain")
    _check_uncertain_delay(setup, box, given)
    check_box(setup, {k: v for k, v in box.items() if k != "d"}, "--uncertain")
    return box


def _time_range(window, *, point):
    """``(low, high)`` in seconds of ``--uncertain Td=LO:HI``: each end a time (``1.5ms``), or
    the unit after HI for both, seconds without one (:func:`time_value`)."""
    flag = "--uncertain Td"
    head, colon, tail = window.partition(":")
    if not colon or not head.strip() or not tail.strip():
        raise ValueError(f"{flag} must be LO:HI, two times (1.5ms:2.5ms, or 1.5:2.5 ms), got "
                         f"{window!r}")
    _, unit = split_unit(tail.strip(), flag)
    _, head_unit = split_unit(head.strip(), flag)
    head = head.strip() if head_unit or not unit else f"{head.strip()} {unit}"
    low, high = time_value(head, flag), time_value(tail.strip(), flag)
    if not (low <= high if point else low < high):
        raise ValueError(f"{flag}: LO:HI must have LO {'<=' if point else '<'} HI, got "
                         f"{window!r}")
    return low, high


def _check_uncertain_delay(setup, box, given):
    """The delay of ``--uncertain`` given once (not with ``--set``'s) and within
    ``SYMSTAB_MAX_DELAY``; in time, over a fixed ``T``."""
    from .._validate import split_delay

    delays = [n for n in ("d", "Td") if n in box]
    if not delays:
        return
    if len(delays) > 1 or {"d", "Td"} & given:
        raise ValueError(f"--uncertain {delays[0]}: give the delay once (--uncertain d=LO:HI "
                         f"in samples or Td=LO:HI in time, not with the other or --set)")
    low, high = box[delays[0]]
    if delays[0] == "Td":
        if "T" in box:
            raise ValueError("--uncertain Td: a delay in time over an uncertain T varies in "
                             "samples over the box; give --uncertain d=LO:HI in samples")
        period = {**setup.loop.defaults, **setup.values}.get("T")
        low, high = low / period, high / period
    try:
        split_delay(high, name=f"--uncertain {delays[0]}" + (" / T" if delays[0] == "Td" else ""))
    except ValueError as exc:
        raise ValueError(str(exc)) from None
