"""``symstab design``: the virtual mass that maximises the renderable stiffness.

The paper's loop: the virtual mass gamma = M_w / m that maximises the
largest stable stiffness for one delay and device, with that stiffness,
its damping and the gain over no virtual mass.  A loop file (``--loop``):
the same search over a third parameter (``--over NAME``, default the
environment's mass term) in the range ``--range LO:HI`` (default design's
gamma range times the device's mass), with the same routine
(:func:`symstab.numeric.region.scan_maximum`): the best value, the largest
stable y there and at the nominal value, the x where it is reached, and the
stable intervals of y there (or at --at X).
"""

import dataclasses
import math
import sys

from .loop_limits import limits_notes, limits_table, named, stable_intervals_at
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


#: The SI units of a mass term (linear, rotary) and of the matching damping.
_MASS_UNITS = {"kg": "N s/m", "kg m^2": "N m s/rad"}


def _search_parameter(args, setup):
    """The parameter ``--over`` names, or the environment's mass term (refused if none)."""
    loop = setup.loop
    others = [n for n in loop.parameters if n not in (setup.x, setup.y, "d")]
    name = args.over
    if name is None:
        names = {str(s) for s in loop.environment.free_symbols}
        masses = [n for n in others if n in names and setup.unit(n) in _MASS_UNITS]
        if len(masses) != 1:
            why = "no mass term" if not masses else f"several mass terms ({', '.join(masses)})"
            raise ValueError(f"design --loop: the environment of {args.loop} has {why}: give "
                             f"--over NAME, the parameter to search (candidates: "
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


def _search_range(args, setup, name):
    """``(low, high, scale)``: the values searched and the size below which tolerances are absolute."""
    device = _device_mass(setup, name)
    if args.search_range is not None:
        from .._validate import check_real

        text = args.search_range
        parts = text.split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            low, high = (check_real("--range", float(v)) for v in parts)
        except (ValueError, TypeError):
            raise ValueError(f"--range must be LO:HI, two finite numbers, got {text!r}") from None
        if not low < high:
            raise ValueError(f"--range LO:HI must have LO < HI, got {text!r}")
        scale = device[0] if device else max(abs(low), abs(high))
        return low, high, scale
    if device is None:
        unit = setup.unit(name)
        raise ValueError(f"--over {name}: give --range LO:HI{f' (in {unit})' if unit else ''}; "
                         f"the default range is design's gamma range times the device's mass, "
                         f"for a mass term of a loop whose plant has a mass in its unit")
    mass, damping = device
    delta = damping * setup.values["T"] / mass
    # design's gamma range (best_virtual_mass), times the mass.
    return mass * (-1.0 - (setup.values["d"] + 1) * delta + 1e-3), mass * 3.0, mass


def _loop(args):
    """A loop file: the value of a third parameter that maximises the largest stable y."""
    from ..numeric.region import scan_maximum

    setup = resolve_loop(args)
    name = _search_parameter(args, setup)
    low, high, scale = _search_range(args, setup, name)
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
    unit = setup.unit(name)
    suffix = f" {unit}" if unit else ""
    print(f"searching {name} in [{low:.6g}, {high:.6g}]{suffix} for the largest stable "
          f"{setup.y} of the ({setup.x}, {setup.y}) plane ...", file=sys.stderr, flush=True)

    def limits_at(value):
        return setup.loop.limits(x=setup.x, y=setup.y, **{**setup.values, name: value})

    failed = []

    def y_max(value):
        # A plane the decomposition cannot resolve (a stable set shrinking to
        # a sliver) is a point without an answer, said in a note: not the end
        # of a search that has others.
        try:
            lim = limits_at(value)
        except ValueError as exc:
            failed.append((value, str(exc)))
            return math.nan
        return -math.inf if lim.empty else lim.y_max

    found = scan_maximum(y_max, low, high, rtol=1e-6, scale=scale)
    nominal = setup.values[name]
    nominal_lim = limits_at(nominal)
    uy = setup.unit(setup.y)
    x, y = setup.x, setup.y
    search = {"over": name, "range": [low, high], "unit": unit, "nominal": nominal,
              "y_max_nominal": None if nominal_lim.empty else nominal_lim.y_max}
    if found is None:
        rows = [(f"{y}_max at {name} = {nominal:.6g}", search["y_max_nominal"], uy,
                 f"largest stable {y} at the nominal {name}")]
        notes = [f"no {name} in [{low:.6g}, {high:.6g}]{suffix} has a stable point in the "
                 f"({x}, {y}) plane"] + limits_notes(setup, nominal_lim)
        search.update(best=None, y_max=None, x_at_y_max=None, gain=None)
        emit(setup, args.format, ["quantity", "value", "unit", "meaning"], rows,
             result={"search": search}, notes=notes, json_rows=False)
        return 0
    best, _ = found
    lim = limits_at(best)
    gain = lim.y_max / nominal_lim.y_max if not nominal_lim.empty and nominal_lim.y_max > 0 \
        else None
    search.update(best=best, y_max=lim.y_max, x_at_y_max=lim.x_at_y_max, gain=gain)
    rows = [(f"{name} (best)", best, unit, f"the {name} that maximises {y}_max"),
            (f"{y}_max", lim.y_max, uy, f"largest stable {y} at the best {name}"),
            limits_table(setup, lim)[1][1],
            (f"{y}_max at {name} = {nominal:.6g}", search["y_max_nominal"], uy,
             f"largest stable {y} at the nominal {name} (the file's or --set)"),
            ("gain", gain, "", f"{y}_max at the best {name} over that at the nominal one")]
    notes = limits_notes(setup, lim)
    result = {"search": search, "limits": named(setup, lim).as_dict()}
    at_best = dataclasses.replace(setup, values={**setup.values, name: best})
    at = args.at
    if at is None and not lim.empty and math.isfinite(lim.x_at_y_max):
        at = lim.x_at_y_max
    if at is not None:
        more, result["at"] = stable_intervals_at(at_best, at)
        notes += [f"at the best {name} = {best:.10g}{suffix}: {line}" if k == 0 else line
                  for k, line in enumerate(more)]
        runs = result["at"]["intervals"]
        if runs:
            lo, hi = runs[-1]
            rows.append((f"{y} range at {x} = {at:.6g}", hi - lo, uy,
                         f"width of the top stable interval of {y} at that {x}"))
        if args.at is None and (not runs or runs[-1][1] - runs[-1][0] < 0.05 * lim.y_max):
            notes.append(f"{y}_max is reached at the tip of a thin sliver of the stable "
                         f"set: it needs precise tuning of {x}; give --at X for the "
                         f"stable {y} at another {x}")
    if not nominal_lim.empty and math.isfinite(nominal_lim.area) \
            and lim.area < 0.05 * nominal_lim.area:
        notes.append(f"the best {name} lies where the stable set is a thin sliver (area "
                     f"{lim.area:.3g} against {nominal_lim.area:.3g} at the nominal {name}): "
                     f"the gain needs very precise tuning of {name} and {x}")
    if failed:
        where = ", ".join(f"{v:.10g}" for v, _ in failed[:3]) + (", ..." if len(failed) > 3 else "")
        notes.append(f"the limits could not be computed at {len(failed)} value(s) of {name} "
                     f"({where}{suffix}): {failed[0][1]}; the best {name} is the best of the "
                     f"others")
    if best - low < 1e-3 * (high - low) or high - best < 1e-3 * (high - low):
        notes.append(f"the best {name} is at an end of the range searched: widen --range")
    emit(setup, args.format, ["quantity", "value", "unit", "meaning"], rows, result=result,
         notes=notes, json_rows=False)
    return 0
