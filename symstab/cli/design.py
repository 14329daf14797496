"""``symstab design``: the virtual mass that maximises the renderable stiffness.

One search for both inputs (:func:`symstab.numeric.region.scan_maximum` of
:meth:`symstab.Loop.limits`, as :func:`symstab.best_virtual_mass` does):
the paper's options search the virtual mass gamma = M_w / m of the paper's
loop from no virtual mass, a loop file (``--loop``) a third parameter
(``--over NAME``, default the environment's mass term) in the range
``--range LO:HI`` (default design's gamma range times the device's mass)
from its nominal value.  Printed: the best value, the largest stable y
there and at the nominal value, the gain, the x where it is reached and
the stable intervals of y there (or at --at X).
"""

import dataclasses
import math
import sys

from .loop_limits import limits_notes, named, plane_table, stable_intervals_at
from .loop_options import add_loop_options, paper_setup, resolve_loop, uses_loop
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
    """Run ``symstab design`` on a loop file (``--loop``) or the paper's loop: one search.

    The paper's device options are the paper's loop in Table I's variables
    (:func:`symstab.cli.loop_options.paper_setup`), searched over its
    virtual mass ``M`` (gamma, with ``m = 1``) from no virtual mass; its
    table keeps Table I's names with the device's units beside them, and
    its JSON the ``best`` of :func:`symstab.best_virtual_mass`.
    """
    if uses_loop(args):
        setup = resolve_loop(args)
        name = _search_parameter(args, setup)
        notes = []
    else:
        setup = paper_setup(resolve(args, mass=False))
        name = "M"
        notes = (["the virtual mass argument --gamma/--Mw is ignored: design searches over it"]
                 if (args.gamma is not None or args.Mw is not None) else [])
    return _search(args, setup, name, notes)


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
    if setup.paper is not None:
        return 1.0, setup.paper.delta       # Table I: masses in units of m, delta = b T / m
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


def _search(args, setup, name, notes):
    """The value of ``name`` that maximises the largest stable y of the plane of ``setup``.

    One :func:`~symstab.numeric.region.scan_maximum` of :meth:`symstab.Loop.limits`
    over the range (:func:`_search_range`); a value whose plane cannot be
    resolved is skipped, said in a note.
    """
    from ..numeric.region import scan_maximum

    low, high, scale = _search_range(args, setup, name)
    if args.at is not None:
        from .._validate import check_real
        check_real(f"--at ({setup.x})", args.at)
    p, x, y = setup.name(name), setup.name(setup.x), setup.name(setup.y)
    unit = setup.unit(name)
    suffix = f" {unit}" if unit else ""
    print(f"searching {p} in [{low:.6g}, {high:.6g}]{suffix} for the largest stable "
          f"{y} of the ({x}, {y}) plane ...", file=sys.stderr, flush=True)

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
    search = {"over": p, "range": [low, high], "unit": unit, "nominal": nominal,
              "y_max_nominal": None if nominal_lim.empty else nominal_lim.y_max}
    at_nominal = ((f"{{y}}_max at {{p}} = {nominal:.6g}", None, "K_max at M_w = 0"),
                  search["y_max_nominal"], "y", "largest stable {y} at the nominal {p}")
    if found is None:
        notes += [f"no {p} in [{low:.6g}, {high:.6g}]{suffix} has a stable point in the "
                  f"({x}, {y}) plane"] + limits_notes(setup, nominal_lim)
        search.update(best=None, y_max=None, x_at_y_max=None, gain=None)
        columns, rows = plane_table(setup, [at_nominal], over=name)
        emit(setup, args.format, columns, rows, result=_result(setup, search, nominal_lim),
             notes=notes, json_rows=False)
        return 0
    best, _ = found
    lim = limits_at(best)
    gain = lim.y_max / nominal_lim.y_max if not nominal_lim.empty and nominal_lim.y_max > 0 \
        else None
    search.update(best=best, y_max=lim.y_max, x_at_y_max=lim.x_at_y_max, gain=gain)
    rows = [("{p} (best)", best, "p", "the {p} that maximises {y}_max"),
            (("{y}_max", None, "K_max"), lim.y_max, "y", "largest stable {y} at the best {p}"),
            (("{x} at {y}_max", None, "B_w at K_max"), lim.x_at_y_max, "x",
             "the {x} at which {y}_max is reached"),
            at_nominal,
            ("gain", gain, None, "{y}_max at the best {p} over that at the nominal one"),
            (("area at the best {p}", None, "Z-width at the best M_w"), lim.area, "area",
             "area of the stable set (the Z-width where {x} is a damping and {y} a stiffness)")]
    notes += limits_notes(setup, lim)
    at_best = dataclasses.replace(setup, values={**setup.values, name: best})
    at = args.at
    if at is None and not lim.empty and math.isfinite(lim.x_at_y_max):
        at = lim.x_at_y_max
    line = None
    if at is not None:
        more, line = stable_intervals_at(at_best, at)
        runs = line["intervals"]
        # At a corner of the stable set the line through the x of y_max only
        # touches it: no interval to show (the note on the sliver says why).
        if runs or args.at is not None:
            notes += [f"at the best {p} = {best:.10g}{suffix}: {text}" if k == 0 else text
                      for k, text in enumerate(more)]
        if runs:
            lo, hi = runs[-1]
            rows.append(("{y} range at the {x} of {y}_max" if args.at is None else
                         f"{{y}} range at {{x}} = {at:.6g}", hi - lo, "y",
                         "width of the top stable interval of {y} at that {x}"))
        if args.at is None and (not runs or runs[-1][1] - runs[-1][0] < 0.05 * lim.y_max):
            notes.append(f"{y}_max is reached at the tip of a thin sliver of the stable "
                         f"set: it needs precise tuning of {x}"
                         + (f"; give --at X for the stable {y} at another {x}"
                            if setup.paper is None else ""))
    if not nominal_lim.empty and math.isfinite(nominal_lim.area) \
            and lim.area < 0.05 * nominal_lim.area:
        notes.append(f"the best {p} lies where the stable set is a thin sliver (area "
                     f"{lim.area:.3g} against {nominal_lim.area:.3g} at the nominal {p}): "
                     f"the gain needs very precise tuning of {p} and {x}")
    if failed:
        where = ", ".join(f"{v:.10g}" for v, _ in failed[:3]) + (", ..." if len(failed) > 3 else "")
        notes.append(f"the limits could not be computed at {len(failed)} value(s) of {p} "
                     f"({where}{suffix}): {failed[0][1]}; the best {p} is the best of the "
                     f"others")
    if best - low < 1e-3 * (high - low) or high - best < 1e-3 * (high - low):
        notes.append(f"the best {p} is at an end of the range searched"
                     + (": widen --range" if setup.paper is None else ""))
    columns, rows = plane_table(setup, rows, over=name)
    result = _result(setup, search, lim)
    if line is not None:
        result["at"] = line
    emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def _result(setup, search, lim):
    """The JSON: the search and the limits at its best value; for the paper's options also
    ``best`` under :class:`symstab.numeric.region.BestVirtualMass`'s names."""
    out = {"search": search, "limits": named(setup, lim).as_dict()}
    if setup.paper is not None:
        out["best"] = {"gamma": search["best"], "beta": search["x_at_y_max"],
                       "alpha_max": search["y_max"], "alpha_max_gamma0": search["y_max_nominal"],
                       "gain": search["gain"], "z_width": lim.area if search["best"] is not None
                       else 0.0, "message": "" if search["best"] is not None else
                       f"no gamma in [{search['range'][0]:g}, {search['range'][1]:g}] has a "
                       f"stable region at d = {setup.paper.d}"}
    return out
