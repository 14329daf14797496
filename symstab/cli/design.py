"""``symstab design``: the parameter values that maximise K_max, the Z-width or the passive K_max.

One search for both inputs (:meth:`symstab.Loop.design`, as
:func:`symstab.best_virtual_mass` does): the paper's options search the
virtual mass gamma = M_w / m of the paper's loop from no virtual mass; a loop
file (``--loop``) one or two parameters outside the plane (``--over
NAME=LO:HI``, repeatable; default the environment's mass term over design's
gamma range times the device's mass) from their nominal values.
``--maximize`` picks the target: the largest stable y (``K_max``, the
default), the area of the stable set (``area``, the Z-width) or the largest
passive y (``passive``).  Printed: the best values, the target there and at
the nominal values, the gain, the x where y_max is reached and the stable
intervals of y there (or at --at X); ``--png`` draws the target against the
parameter(s) searched.
"""

import dataclasses
import math
import sys

from .loop_limits import force_unit, limits_notes, named, plane_table, stable_intervals_at
from .loop_options import (
    EXAMPLE,
    add_loop_options,
    check_box,
    converted_range,
    paper_setup,
    range_text,
    resolve_loop,
    split_unit,
    uses_loop,
    value_text,
)
from .options import add_command, add_model_options, resolve
from .output import check_outputs, emit, write_output
from .simulation import add_nonideal_options, loop_nonideal_text, resolve_nonideal

__all__ = ["register", "run"]

#: ``--maximize``'s words: the target of :meth:`symstab.Loop.design` each names
#: (``{y}_max``, e.g. ``K_max``, is ``y_max`` too).
_TARGET_WORDS = {"y_max": "y_max", "K_max": "y_max", "area": "area", "Z-width": "area",
                 "z_width": "area", "passive": "passive", "simulated": "simulated"}
#: The options of the simulated target (``--maximize simulated``) only: flag, dest.
_SIMULATION_FLAGS = (("--amplitude", "amplitude"), ("--encoder-resolution", "encoder_resolution"),
                     ("--force-limit", "force_limit"),
                     ("--force-resolution", "force_resolution"), ("--coulomb", "coulomb"),
                     ("--stiction", "stiction"), ("--substeps", "substeps"),
                     ("--steps", "steps"), ("--x0", "x0"))
#: The scan's points per parameter at most: each is a certified region.
MAX_POINTS = 201
#: The scan's points in all at most (two parameters: ``--points`` squared).
MAX_EVALUATIONS = 2000


def register(subparsers):
    """Add ``symstab design`` to the sub-commands."""
    p = add_command(
        subparsers, "design", help="the virtual mass (or any parameter) that maximises K_max",
        description="Search the virtual mass gamma = M_w / m (with --loop: one or two "
                    "parameters of the loop) that maximises the largest stable stiffness, the "
                    "Z-width or the passive stiffness for one delay and device, and report "
                    "the optimum, the target there and at the nominal value, and the gain.",
        example="symstab design --Td 0.04", func=run)
    add_model_options(p)
    g = p.add_argument_group("the search")
    g.add_argument("--maximize", metavar="TARGET", default="K_max",
                   help="what to maximise: K_max (the largest stable y of the plane; also "
                        "y_max or the plane's {y}_max), area (the area of the stable set, the "
                        "Z-width; also Z-width), passive (the largest passive y, "
                        "Colgate-Schenkel with the delay) or simulated (with --loop: the "
                        "largest y whose simulated run, with the non-idealities given, "
                        "neither grows nor ends above --amplitude) (default: K_max)")
    g.add_argument("--points", metavar="N", type=int,
                   help=f"scan points per parameter before the refinement, 3 to {MAX_POINTS} "
                        f"(default 17 for one parameter, 9 for two)")
    g.add_argument("--png", metavar="FILE", help="also draw the target against the parameter(s) "
                                                 "searched as PNG")
    g.add_argument("--delay", metavar="TIME",
                   help="with --loop: hold the loop delay at TIME (s, or with a unit: 5ms) "
                        "while the sample period is searched (--over T=...): d = TIME / T "
                        "samples at each T, a fraction of a period included, instead of the "
                        "file's d (a delay given in time, --set Td=... or the file's Td, is "
                        "held so without it)")
    g.add_argument("--amplitude", metavar="X", type=float,
                   help="with --maximize simulated: the largest |x| accepted in the last "
                        "quarter of a run, in the loop's position unit (m or rad), from --x0; "
                        "a limit cycle above it, or a decay not below it by the end, is "
                        "refused (--steps counts periods: with --delay and --over T a fixed "
                        "--steps is a shorter time at a smaller T)")
    g.add_argument("--noise-limit", metavar="F",
                   help="with --loop and --encoder-resolution: a noise budget, the largest RMS "
                        "force of the encoder's quantization at the rendered point (--noise-at), "
                        "in the loop's force unit (N or N m) or with a unit (10mN); only values "
                        "of the one parameter searched that meet it are candidates")
    g.add_argument("--noise-at", metavar=("X", "Y"), nargs=2,
                   help="with --encoder-resolution: the point of the plane rendered while the "
                        "force noise is measured, x then y, each in the file's unit or with a "
                        "unit (default: the file's values of x and y)")
    add_nonideal_options(p, loop_only=True)
    add_loop_options(p, "design")


def run(args):
    """Run ``symstab design`` on a loop file (``--loop``) or the paper's loop: one search.

    The paper's device options are the paper's loop in Table I's variables
    (:func:`symstab.cli.loop_options.paper_setup`), searched over its
    virtual mass ``M`` (gamma, with ``m = 1``) from no virtual mass; its
    table keeps Table I's names with the device's units beside them, and
    its JSON the ``best`` of :func:`symstab.best_virtual_mass`.
    """
    target = _target(args.maximize)
    # (0 is a value given: only None is "not given".)
    # (--encoder-resolution is also the force noise's encoder, for every target.)
    given = [flag for flag, dest in _SIMULATION_FLAGS if getattr(args, dest) is not None
             and dest != "encoder_resolution"]
    if target != "simulated" and given:
        raise ValueError(f"{given[0]} is an option of the simulated target: add --maximize "
                         f"simulated (with --loop)")
    if args.points is not None and not 3 <= args.points <= MAX_POINTS:
        raise ValueError(f"--points must be an integer from 3 to {MAX_POINTS}, got {args.points}")
    png = check_outputs([("--png", args.png, "file")]).get("--png")
    delay = None
    if uses_loop(args):
        setup = resolve_loop(args)
        over = _search_over(args, setup)
        delay = _delay(args, setup, over)
        notes = []
    elif target == "simulated":
        raise ValueError(f"--maximize simulated simulates a loop file: give --loop FILE (the "
                         f"paper's device: --loop {EXAMPLE})")
    else:
        if args.gamma is not None or args.Mw is not None:
            raise ValueError(f"{'--gamma' if args.gamma is not None else '--Mw'}: design "
                             f"searches the virtual mass, from no virtual mass (gamma = 0) to "
                             f"the best; drop it")
        setup = paper_setup(resolve(args, mass=False))
        d, delta = setup.paper.d, setup.paper.delta
        over = {"M": (-1.0 - (d + 1) * delta + 1e-3, 3.0)}    # best_virtual_mass's range
        notes = []
    if target == "passive" and setup.paper is not None and setup.paper.delta == 0:
        raise ValueError("--maximize passive: the device has no damping (delta = 0), so no "
                         "point is passive")
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
        # The line at x = --at is asked again at the best values: tried once now, so
        # that an x the line engine refuses is refused before the search.
        setup.loop.stable_intervals(setup.y, **{setup.x: args.at}, **setup.values)
    if args.points is not None and args.points ** len(over) > MAX_EVALUATIONS:
        raise ValueError(f"--points {args.points} with {len(over)} parameters is "
                         f"{args.points ** len(over)} scan points, above {MAX_EVALUATIONS} (each "
                         f"is a certified region, about 0.1 to 1 s): give fewer --points")
    simulation = _simulation(args, setup.loop) if target == "simulated" else {}
    noise = _noise(args, setup, over)
    return _search(args, setup, over, target, notes, png, delay, simulation, noise)


def _noise(args, setup, over):
    """``Loop.design``'s noise arguments from --encoder-resolution, --noise-limit, --noise-at.

    Checked before the search; ``{}`` without an encoder (no noise).
    """
    if args.encoder_resolution is None:
        for flag, value in (("--noise-limit", args.noise_limit), ("--noise-at", args.noise_at)):
            if value is not None:
                raise ValueError(f"{flag} needs --encoder-resolution Q: the encoder's quantum "
                                 f"(the loop's position unit, m or rad), whose rounding error "
                                 f"is the force noise")
        return {}
    if args.maximize in ("simulated",) and args.noise_limit is None and args.noise_at is None:
        return {}       # the simulator's quantizer only: the noise on asking for it
    if setup.paper is not None:
        raise ValueError(f"--encoder-resolution: the force noise of a design is a loop "
                         f"file's (its forces in N or N m): give --loop {EXAMPLE}")
    from .._validate import check_real

    out = {"encoder_resolution": check_real("--encoder-resolution", args.encoder_resolution,
                                            low=0.0, low_open=True)}
    if args.noise_limit is not None:
        if len(over) != 1:
            raise ValueError(f"--noise-limit: a noise budget is searched over one parameter, "
                             f"got {len(over)} (--over {' and '.join(over)})")
        out["noise_limit"] = _noise_limit(args.noise_limit, setup)
    x, y = setup.x, setup.y
    if args.noise_at is not None:
        out["noise_at"] = _noise_at(args.noise_at, setup)
    elif x not in setup.loop.defaults or y not in setup.loop.defaults:
        missing = [n for n in (x, y) if n not in setup.loop.defaults]
        raise ValueError(f"--encoder-resolution: the force noise is measured at a rendered "
                         f"point of the ({x}, {y}) plane, and {args.loop} gives no value of "
                         f"{' and '.join(missing)}: give --noise-at X Y")
    return out


def _noise_limit(text, setup):
    """``--noise-limit`` in the loop's force unit (SI): a bare number, or converted from its unit."""
    from .._validate import check_real
    from ..numeric.loop.quantities import unit_info
    from .options import parse_one

    number, unit = split_unit(text.strip(), "--noise-limit")
    value = parse_one(number, "--noise-limit")
    if unit is not None:
        force = force_unit(setup)
        if force is None:
            raise ValueError(f"--noise-limit {text}: the force's unit of this loop is not known "
                             f"(neither {setup.x} nor {setup.y} has a stiffness unit in the "
                             f"file): give a bare number in the loop's force unit")
        try:
            info = unit_info(unit)
        except ValueError as exc:
            raise ValueError(f"--noise-limit {text}: {exc}") from None
        if info.dimensions != force.dimensions or info.angle:
            raise ValueError(f"--noise-limit {text}: {unit!r} is not a unit of this loop's "
                             f"force, which is in {force.si} (its stiffness in "
                             f"{force.stiffness})")
        value *= float(info.factor)
    return check_real("--noise-limit", value, low=0.0, low_open=True)


def _noise_at(texts, setup):
    """``--noise-at X Y``: the rendered point of the plane in SI, converted as ``--set`` values are."""
    from .loop_options import convert_sets, parse_number

    sets = {}
    for name, text in zip((setup.x, setup.y), texts, strict=True):
        number, unit = split_unit(text.strip(), "--noise-at")
        sets[name] = (parse_number(name, number, "--noise-at", lists=False), unit)
    values, _ = convert_sets(setup.loop, sets, flag="--noise-at")
    return values


def _simulation(args, loop):
    """The settings of the simulated target, checked before the search (``Loop.design``'s)."""

    if args.amplitude is None:
        raise ValueError("--maximize simulated needs --amplitude X: the largest |x| accepted at "
                         "the end of a run, in the loop's position unit (m or rad)")
    from .._validate import check_real

    amplitude = check_real("--amplitude", args.amplitude, low=0.0, low_open=True)
    nonideal, x0 = resolve_nonideal(args, None, loop)
    # The horizon at each delay searched is checked by Loop.design before its scan.
    return {"amplitude": amplitude, "nonideal": nonideal, "x0": x0,
            "steps": args.steps}


def _delay(args, setup, over):
    """The delay held in seconds as ``T`` is searched, or None (``d`` held in samples).

    ``--delay`` (converted as a ``--set T=...`` value is); without it, a
    delay given in time (``--set Td=...``, the file's ``Td``) while ``T``
    is searched: it is ``Td / T`` samples at every ``T``, as the library
    reads ``Td``.
    """
    if args.delay is None:
        if "T" in over and "Td" in setup.written:
            return setup.values["d"] * setup.values["T"]
        return None
    if {"d", "Td"} & set(setup.given):
        raise ValueError("--delay holds the delay in seconds as T varies: drop --d / --set d / "
                         "--set Td")
    from .loop_options import time_value

    return time_value(args.delay, "--delay")


def _target(word):
    """The target of :meth:`symstab.Loop.design` that ``--maximize`` names."""
    target = _TARGET_WORDS.get(word)
    if target is None and word.endswith("_max") and word[:-4].isidentifier():
        target = "y_max"      # the plane's {y}_max, checked against the plane in _search
    if target is None:
        raise ValueError(f"--maximize must be K_max (or y_max, or the plane's {{y}}_max), area "
                         f"(or Z-width) or passive, got {word!r}")
    return target


#: The SI units of a mass term (linear, rotary) and of the matching damping.
_MASS_UNITS = {"kg": "N s/m", "kg m^2": "N m s/rad"}


def _search_over(args, setup):
    """``{name: (low, high)}`` of ``--over`` (and ``--range``), checked before the search."""
    texts = args.over or [None]
    if len(texts) > 2:
        raise ValueError(f"--over is given {len(texts)} times: design searches one or two "
                         f"parameters")
    over = {}
    for text in texts:
        name, window = (None, None) if text is None else _over_text(text)
        name = _search_parameter(args, setup, name)
        if name in over:
            raise ValueError(f"--over {name} is given twice; give each parameter once")
        if window is None and args.search_range is not None:
            if len(texts) > 1:
                raise ValueError("--range is the range of a single --over NAME: with two "
                                 "parameters give --over NAME=LO:HI for each")
            window = range_text(args.search_range, "--range")
        elif window is not None and args.search_range is not None:
            raise ValueError(f"--over {text} gives its range: drop --range {args.search_range}")
        if window is None:
            window = _default_range(setup, name)
        else:
            window = converted_range(setup, name, *window, flag="--over")
        over[name] = window
    check_box(setup, over, "--over")
    return over


def _over_text(text):
    """``(name, (low, high, unit) or None)`` of one ``--over NAME[=LO:HI [UNIT]]``."""
    name, eq, window = text.partition("=")
    name = name.strip()
    if not name:
        raise ValueError(f"--over {text}: expected NAME or NAME=LO:HI, e.g. --over M=0:0.03")
    return name, (range_text(window, f"--over {name}") if eq else None)


def _search_parameter(args, setup, name):
    """The parameter ``--over`` names, or the environment's mass term (refused if none)."""
    loop = setup.loop
    others = [n for n in loop.parameters if n not in (setup.x, setup.y, "d")]
    if name is None:
        names = {str(s) for s in loop.environment.free_symbols}
        masses = [n for n in others if n in names and setup.unit(n) in _MASS_UNITS]
        axes = [n for n in (setup.x, setup.y) if n in names and setup.unit(n) in _MASS_UNITS]
        if not masses and axes:
            raise ValueError(f"design --loop: the environment's mass term {axes[0]} is an axis "
                             f"of the ({setup.x}, {setup.y}) plane: give --over NAME=LO:HI, the "
                             f"parameter to search (candidates: {', '.join(others)})")
        if len(masses) != 1:
            why = "no mass term" if not masses else f"several mass terms ({', '.join(masses)})"
            raise ValueError(f"design --loop: the environment of {args.loop} has {why}: give "
                             f"--over NAME=LO:HI, the parameter to search (candidates: "
                             f"{', '.join(others)})")
        return masses[0]
    if name not in loop.parameters:
        raise ValueError(f"--over {name}: not a parameter of the loop in {args.loop} "
                         f"(candidates: {', '.join(others)})")
    if name == "d":
        raise ValueError("--over d: the delay is a whole number of samples; run design once "
                         "per delay (--set d=...)")
    if name in (setup.x, setup.y):
        raise ValueError(f"--over {name}: {name} is an axis of the ({setup.x}, {setup.y}) plane; "
                         f"search another parameter (candidates: {', '.join(others)})")
    return name


def _device_mass(setup, name):
    """The device's mass for the default range of a mass term: (mass, damping) or None.

    The sum of the plant's parameters in the unit of ``name`` (``m``;
    ``m1 + m2`` for two masses), and the loop's ``b`` where it has one in
    the matching damping unit (else 0).
    """
    unit = setup.unit(name)
    if unit not in _MASS_UNITS:
        return None
    plant = {str(s) for s in setup.loop.plant.free_symbols}
    masses = [setup.values[n] for n in setup.loop.parameters
              if n in plant and n != name and setup.unit(n) == unit]
    if not masses or not sum(masses) > 0:
        return None
    damping = setup.values.get("b", 0.0) if setup.unit("b") == _MASS_UNITS[unit] else 0.0
    return float(sum(masses)), float(damping)


def _default_range(setup, name):
    """design's gamma range times the device's mass, for a mass term; else refused."""
    device = _device_mass(setup, name)
    if device is None:
        unit = setup.unit(name)
        raise ValueError(f"--over {name}: give its range, --over {name}=LO:HI"
                         f"{f' (in {unit})' if unit else ''}; the default range is design's "
                         f"gamma range times the device's mass, for a mass term of a loop "
                         f"whose plant has a mass in its unit")
    mass, damping = device
    delta = damping * setup.values["T"] / mass
    return mass * (-1.0 - (setup.values["d"] + 1) * delta + 1e-3), mass * 3.0


#: ``(row name, Table I's name, physical name)`` and meaning of each target.
_TARGET_ROWS = {
    "y_max": (("{y}_max", None, "K_max"), "largest stable {y}"),
    "area": (("area", "z_width", "Z-width"), "area of the stable set (the Z-width where {x} "
             "is a damping and {y} a stiffness)"),
    "passive": (("passive {y}_max", "passive alpha_max", "passive K_max"),
                "largest passive {y} (Colgate-Schenkel with the delay)"),
    "simulated": (("simulated {y}_max", None, "simulated K_max"),
                  "largest {y} whose simulated run neither grows nor ends above the amplitude"),
}


def _search(args, setup, over, target, notes, png, delay=None, simulation=None, noise=None):
    """The values of ``over`` that maximise ``target`` in the plane of ``setup``: one design."""
    names = tuple(over)
    found = _run_design(args, setup, over, target, delay, simulation, noise or {})
    at_nominal = _nominal_row(setup, found, names, target)
    if found.best is None:
        search = _search_json(setup, found, names, None)
        notes += ([found.message] + _failed_notes(found)
                  + limits_notes(setup, _limits(setup, found.nominal, delay))
                  + _noise_notes(setup, found))
        columns, rows = plane_table(setup, [at_nominal], over=names)
        _write_png(png, setup, found, notes)
        emit(setup, args.format, columns, rows, result=_result(setup, search, None),
             notes=notes, json_rows=False)
        return 0
    # The plane's certified limits at the best values, whatever the target.
    if target == "passive":
        lim = _limits(setup, found.best, delay)
    elif target == "simulated":
        lim = found.limits.linear
    else:
        lim = found.limits
    search = _search_json(setup, found, names, lim)
    rows = _best_rows(found, names, target, lim, at_nominal)
    notes += limits_notes(setup, lim)
    if target == "simulated":
        notes += _simulation_notes(setup, found, simulation)
    line = _at_the_best(args, setup, found, target, lim, delay, rows, notes)
    notes += _failed_notes(found)
    for name in found.at_edge:
        notes.append(f"the best {setup.name(name)} is at an end of the range searched"
                     + (f": widen --over {name}=LO:HI" if setup.paper is None else ""))
    notes += _noise_notes(setup, found)
    columns, rows = plane_table(setup, rows, over=names)
    result = _result(setup, search, lim)
    if line is not None:
        result["at"] = line
    _write_png(png, setup, found, notes)
    emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def _run_design(args, setup, over, target, delay, simulation, noise):
    """Check ``--maximize`` against the plane and run the design, saying what it searches."""
    from .._progress import progress_printer

    names = tuple(over)
    y_word = setup.name(setup.y)
    # K_max names the plane's y_max where y is the stiffness (K, or the paper's alpha).
    allowed = {"y_max", f"{y_word}_max"} | ({"K_max"} if y_word in ("K", "alpha") else set())
    if args.maximize.endswith("_max") and args.maximize not in allowed:
        raise ValueError(f"--maximize {args.maximize}: the plane's y is {y_word}; give "
                         f"{y_word}_max (or y_max), area or passive")
    x, y = setup.name(setup.x), y_word
    units = {n: setup.unit(n) for n in names}
    ranges = ", ".join(f"{setup.name(n)} in [{lo:.6g}, {hi:.6g}]"
                       + (f" {units[n]}" if units[n] else "") for n, (lo, hi) in over.items())
    what = {"y_max": f"the largest stable {y}", "area": "the largest area of the stable set",
            "passive": f"the largest passive {y}",
            "simulated": f"the largest {y} whose simulated run settles below "
                         f"{(simulation or {}).get('amplitude', 0):.4g}"}[target]
    n = args.points or (17 if len(names) == 1 else 9)
    progress = progress_printer("design", n**len(names) + 40)

    def evaluated(k):
        # Said at the first evaluation: the design checks its inputs before, and a
        # refusal there is one line.
        if k == 1:
            print(f"searching {ranges} for {what} of the ({x}, {y}) plane ...",
                  file=sys.stderr, flush=True)
        progress(min(k, n**len(names) + 39))

    found = setup.loop.design(over=over, maximize=target, x=setup.x, y=setup.y, n=n,
                              progress=evaluated, delay=delay, **(simulation or {}), **noise,
                              **{k: v for k, v in setup.values.items()
                                 if not (delay is not None and k == "d")})
    progress(n**len(names) + 40)
    return found


def _nominal_row(setup, found, names, target):
    """The table's row of the target at the nominal values of the parameters searched."""
    label, meaning = _TARGET_ROWS[target]
    y = setup.name(setup.y)
    nominal_text = ", ".join(f"{{{k}}} = {setup.values[name]:.6g}"
                             for k, name in zip("pq", names, strict=False))
    value_nominal = found.value_nominal
    return (((label[0] + f" at {nominal_text}"),
             None if setup.paper is None else
             f"{label[1] or label[0].format(y=y)} at gamma = 0",
             f"{label[2]} at M_w = 0"),
            value_nominal if value_nominal is None or value_nominal > -math.inf else None,
            "area" if target == "area" else "y", f"{meaning} at the nominal "
            + " and ".join(f"{{{k}}}" for k in "pq"[:len(names)]))


def _best_rows(found, names, target, lim, at_nominal):
    """The table's rows of a design that found a best value: it, the target, the limits there."""
    label, meaning = _TARGET_ROWS[target]
    kind = "area" if target == "area" else "y"
    rows = [(f"{{{k}}} (best)", found.best[name], k, f"the {{{k}}} that maximises {label[0]}")
            for k, name in zip("pq", names, strict=False)]
    rows.append((label, found.value, kind, f"{meaning} at the best "
                 + " and ".join(f"{{{k}}}" for k in "pq"[:len(names)])))
    if target == "simulated":
        rows.append((("{x} of the simulated {y}_max", None, "B_w of the simulated K_max"),
                     found.limits.x_at_y_max, "x", "the {x} of the run that reaches it"))
    if target != "y_max" and not lim.empty:
        rows.append((("{y}_max", None, "K_max"), lim.y_max, "y", "largest stable {y} there"
                     + (" (linear, certified)" if target == "simulated" else "")))
    if not lim.empty:
        rows.append((("{x} at {y}_max", None, "B_w at K_max"), lim.x_at_y_max, "x",
                     "the {x} at which {y}_max is reached"))
    rows += [at_nominal, ("gain", found.gain, None, f"{label[0]} at the best over that at "
                          f"the nominal value")]
    if found.noise is not None:
        bounded = found.best_noise if math.isfinite(found.best_noise) else None
        rows.append(("force noise at the best", bounded, "force", "RMS force of the "
                     "encoder's quantization at the rendered point, at the best "
                     + " and ".join(f"{{{k}}}" for k in "pq"[:len(names)])))
    if found.noise_limit is not None:
        rows.append(("noise limit", found.noise_limit, "force", "the budget"))
    if target != "area":
        rows.append((("area at the best {p}" if len(names) == 1 else "area there", None,
                      "Z-width at the best M_w"), lim.area, "area",
                     "area of the stable set (the Z-width where {x} is a damping and {y} a "
                     "stiffness)"))
    return rows


def _at_the_best(args, setup, found, target, lim, delay, rows, notes):
    """The stable intervals at the best values (a row and notes added); their JSON or None.

    Also the notes on the delay held in seconds and on a best value at the
    tip of a thin sliver of the stable set.
    """
    x, y = setup.name(setup.x), setup.name(setup.y)
    names = tuple(found.over)
    units = {n: setup.unit(n) for n in names}
    at_best = dataclasses.replace(setup, values=_at(setup, found.best, delay))
    if delay is not None:
        T = at_best.values["T"]
        notes.append(f"the delay is held at {delay:.6g} s: d = {delay:.6g} s / T samples; at "
                     f"the best T = {T:.6g} s, d = {found.best_d:.6g}")
    at = args.at
    if at is None and not lim.empty and math.isfinite(lim.x_at_y_max):
        at = lim.x_at_y_max
    line = None
    best_text = ", ".join(f"{setup.name(k)} = {v:.10g}" + (f" {units[k]}" if units[k] else "")
                          for k, v in found.best.items())
    if at is not None:
        more, line = stable_intervals_at(at_best, at)
        runs = line["intervals"]
        # At a corner of the stable set the line through the x of y_max only
        # touches it: no interval to show (the note on the sliver says why).
        if runs or args.at is not None:
            notes += [f"at the best {best_text}: {text}" if k == 0 else text
                      for k, text in enumerate(more)]
        if runs:
            lo, hi = runs[-1]
            rows.append(("{y} range at the {x} of {y}_max" if args.at is None else
                         f"{{y}} range at {{x}} = {at:.6g}", hi - lo, "y",
                         "width of the top stable interval of {y} at that {x}"))
        if args.at is None and target == "y_max" and \
                (not runs or runs[-1][1] - runs[-1][0] < 0.05 * lim.y_max):
            notes.append(f"{y}_max is reached at the tip of a thin sliver of the stable "
                         f"set: it needs precise tuning of {x}"
                         + (f"; give --at X for the stable {y} at another {x}"
                            if setup.paper is None else ""))
    nominal_lim = _limits(setup, found.nominal, delay) if found.nominal else None
    if nominal_lim is not None and not nominal_lim.empty and math.isfinite(nominal_lim.area) \
            and lim.area < 0.05 * nominal_lim.area:
        notes.append(f"the best {best_text} lies where the stable set is a thin sliver (area "
                     f"{lim.area:.3g} against {nominal_lim.area:.3g} at the nominal values): "
                     f"the gain needs very precise tuning of {', '.join(names)} and {x}")
    return line


#: Values whose simulated target lies within this fraction of the best are ties: near
#: the limit the accepted set's edge is ragged (quantization limit cycles near the
#: amplitude); for the paper's device at d = 5 the target varies by about 1 % between
#: nearby values (measured, symstab/numeric/simulation/simulated_limit.py).
SIMULATED_TIE = 0.01


def _simulation_notes(setup, found, simulation):
    """What the simulated target is: the runs, the non-idealities, its resolution, the ties."""
    y = setup.name(setup.y)
    simulated = found.limits
    out = [f"simulated: {loop_nonideal_text(simulation['nonideal'])}, x0 = "
           f"{simulation['x0']:g}, {simulated.steps} periods per run; a run is accepted when "
           f"it does not grow and its last quarter's |x| is at most "
           f"{simulation['amplitude']:.4g} (not certified: simulated {y}_max refined to steps "
           f"of {simulated.resolution:.3g})"]
    if simulation["nonideal"].encoder_resolution is not None or \
            simulation["nonideal"].force_resolution is not None:
        ties = found.samples[found.samples[:, -1] >= (1 - SIMULATED_TIE) * found.value]
        spans = ", ".join(f"{setup.name(n)} from {ties[:, k].min():.6g} to "
                          f"{ties[:, k].max():.6g}" for k, n in enumerate(found.over))
        out.append(f"the edge of the accepted runs is ragged where quantization cycles come "
                   f"near the amplitude (for the paper's device the simulated {y}_max varies "
                   f"by about 1 % between nearby values): the values searched within "
                   f"{SIMULATED_TIE:.0%} of the best are {spans}")
    if simulated.at_top:
        out.append(f"the simulated {y}_max is at the top of its window (1.25 times the linear "
                   f"{y}_max): it may lie higher")
    return out


def _noise_notes(setup, found):
    """The force noise's notes: the encoder and the rendered point, whether the budget binds,
    and the Pareto front of the target against the noise (none without an encoder)."""
    if found.encoder_resolution is None:
        return []
    force = force_unit(setup)
    unit = f" {force.si}" if force is not None else ""
    at = ", ".join(value_text(setup, k, v) for k, v in found.noise_at.items())
    out = [f"force noise: an encoder quantum of {found.encoder_resolution:.4g} "
           f"{_position_unit(setup)}, uniform and white, through the closed loop at the rendered "
           f"point {at} (exact: the H2 norm; unbounded where that point is not stable)"]
    if found.best is not None and math.isinf(found.best_noise):
        out.append(f"the rendered point {at} is not stable at the best value: its force noise "
                   f"is unbounded there (give --noise-at X Y inside the stable set)")
    if found.budget_binds:
        out.append(f"the noise budget binds: at the best value the force noise reaches "
                   f"{found.noise_limit:.4g}{unit}; a larger budget or a finer encoder buys more")
    front = found.pareto
    if front is not None and len(front):
        label = _TARGET_ROWS[found.target][0][0].format(y=setup.name(setup.y))
        out.append(f"Pareto front: the values evaluated that no other beats on both {label} "
                   f"and force noise")
        heads = [setup.label(n) for n in found.over] + [label, "force noise" + (
            f" [{force.si}]" if force is not None else "")]
        cells = [heads] + [[f"{v:.6g}" for v in row[:-1]] + [f"{row[-1]:.4g}"] for row in front]
        widths = [max(len(r[k]) for r in cells) for k in range(len(heads))]
        out += ["  " + "  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True))
                for r in cells]
    return out


def _position_unit(setup):
    """The loop's position unit: rad where its stiffness (:func:`force_unit`'s) is per radian,
    else m; where the force's unit is not known, words saying so."""
    force = force_unit(setup)
    if force is None:
        return "(the loop's position unit)"
    return "rad" if "rad" in force.stiffness else "m"


def _failed_notes(found):
    """A note on the values the engine could not resolve (none when it resolved all)."""
    if not found.failed:
        return []
    where = "; ".join(", ".join(f"{k} = {v:.10g}" for k, v in point.items())
                      for point, _ in found.failed[:3]) + ("; ..." if len(found.failed) > 3 else "")
    return [f"the {'limits' if found.target != 'passive' else 'passive set'} could not be "
            f"computed at {len(found.failed)} value(s) ({where}): {found.failed[0][1]}; the "
            f"best is the best of the others"]


def _at(setup, point, delay):
    """The values at ``point`` of the searched parameters (``d`` held by ``delay`` if given)."""
    values = {**setup.values, **point}
    if delay is not None:
        values["d"] = delay / values["T"]
    return values


def _limits(setup, point, delay=None):
    """:meth:`symstab.Loop.limits` of the plane at ``point`` of the searched parameters."""
    return setup.loop.limits(x=setup.x, y=setup.y, **_at(setup, point, delay))


def _search_json(setup, found, names, lim):
    """The search for JSON: one parameter as numbers, two as ``{name: ...}``.

    ``y_max`` and ``x_at_y_max`` are the stable set's at the optimum (``lim``,
    the plane's :class:`~symstab.numeric.engine.results.Limits`), whatever the target.
    """
    one = len(names) == 1
    y_max = None if lim is None or lim.y_max is None else lim.y_max
    out = {"over": setup.name(names[0]) if one else [setup.name(n) for n in names],
           "maximize": found.target,
           "range": list(found.over[names[0]]) if one else {n: list(r) for n, r in
                                                             found.over.items()},
           "unit": setup.unit(names[0]) if one else {n: setup.unit(n) for n in names},
           "nominal": (found.nominal.get(names[0]) if one else found.nominal or None),
           "value_nominal": found.value_nominal,
           "best": None if found.best is None else (found.best[names[0]] if one else found.best),
           "value": found.value, "gain": found.gain,
           "evaluations": int(found.samples.shape[0]),
           "spacing": found.spacing[names[0]] if one else found.spacing}
    if found.delay is not None:
        # Held in seconds as T varies: d = delay / T samples, fractional.
        out.update(delay=found.delay, best_d=found.best_d)
    if found.target == "y_max":
        out["y_max_nominal"] = (found.value_nominal if found.value_nominal is not None
                                and found.value_nominal > -math.inf else None)
    out["y_max"] = y_max
    out["x_at_y_max"] = None if lim is None else lim.x_at_y_max
    if found.encoder_resolution is not None:
        front = found.pareto
        out["noise"] = {"encoder_resolution": found.encoder_resolution,
                        "noise_limit": found.noise_limit, "at": found.noise_at,
                        "best": (found.best_noise if found.best_noise is None
                                 or math.isfinite(found.best_noise) else None),
                        "binds": found.budget_binds,
                        "pareto": [{**{setup.name(n): v for n, v in zip(found.over, row,
                                                                           strict=False)},
                                    "target": row[-2], "noise": row[-1]} for row in front]}
    if found.target == "simulated":
        simulated = found.limits
        out["simulated"] = None if simulated is None else {
            "x_at_y_max": simulated.x_at_y_max, "resolution": simulated.resolution,
            "amplitude": simulated.amplitude, "steps": simulated.steps, "x0": simulated.x0,
            "at_top": simulated.at_top, "nonideal": loop_nonideal_text(simulated.nonideal)}
    return out


def _result(setup, search, lim):
    """The JSON: the search and the limits at its best value; for the paper's options also
    ``best`` under :class:`symstab.numeric.paper.region.BestVirtualMass`'s names."""
    out = {"search": search, "limits": None if lim is None else named(setup, lim).as_dict()}
    if setup.paper is not None and search["maximize"] == "y_max":
        out["best"] = {"gamma": search["best"], "beta": search["x_at_y_max"],
                       "alpha_max": search["y_max"], "alpha_max_gamma0": search["y_max_nominal"],
                       "gain": search["gain"], "z_width": lim.area if search["best"] is not None
                       else 0.0, "message": "" if search["best"] is not None else
                       f"no gamma in [{search['range'][0]:g}, {search['range'][1]:g}] has a "
                       f"stable region at d = {setup.paper.d}"}
    return out


def _write_png(png, setup, found, notes):
    """Draw the target against the searched parameter(s) into ``png`` (if given); beside it,
    with an encoder, the target against the force noise."""
    if png is None:
        return
    from ..drawing import design_figure, png_of

    names = tuple(found.over)
    labels = [setup.label(n) for n in names]
    label, _ = _TARGET_ROWS[found.target]
    y = setup.name(setup.y)
    unit = {"y_max": setup.unit(setup.y), "passive": setup.unit(setup.y),
            "simulated": setup.unit(setup.y)}.get(
        found.target, f"({setup.unit(setup.x)})({setup.unit(setup.y)})"
        if setup.unit(setup.x) and setup.unit(setup.y) else "")
    target_label = label[0].format(y=y) + (f" [{unit}]" if unit else "")
    force = force_unit(setup)
    noise_label = "force noise (RMS)" + (f" [{force.si}]" if force is not None else "")
    write_output(png, png_of(design_figure, found, labels, target_label, noise_label), "--png")
    notes.append(f"wrote {png}")
