"""The stable set in a plane, as rows and notes: shared by ``limits`` and ``design``.

:func:`limits_table` and :func:`limits_notes` show a
:meth:`symstab.Loop.limits` (a loop file's, or the paper's loop in Table
I's names for the paper's device options), :func:`passive_notes` the
passive set beside it, :func:`stable_intervals_at` the stable intervals of
y at one x, their ends classified.
"""

import dataclasses
import math

from .output import interval_texts, number_text

__all__ = ["LIMITS", "stable_intervals_at", "named", "plane_table", "limits_table", "limits_notes",
           "passive_notes"]


def stable_intervals_at(setup, at):
    """The stable intervals of y at x = ``at``, their ends classified: (notes, json).

    For the paper's device options (``setup.paper``) in Table I's names,
    and in the device's units too where it is physical.
    """
    from .._validate import check_real

    x, y = setup.name(setup.x), setup.name(setup.y)
    at = check_real(f"--at ({x})" if setup.paper is None else x, at)
    runs = setup.loop.stable_intervals(setup.y, **{setup.x: at}, **setup.values)
    unit_x = f" {setup.unit(setup.x)}" if setup.unit(setup.x) else ""
    unit_y = f" {setup.unit(setup.y)}" if setup.unit(setup.y) else ""
    codes = [tuple(setup.loop.classify(**{setup.x: at, setup.y: end}, **setup.values)
                   if math.isfinite(end) else None for end in run) for run in runs]
    text, ends, kinds = interval_texts(runs, codes, y, setup.unit(setup.y))
    notes = [f"stable {y} at {x} = {at:.10g}{unit_x}: {text}"]
    if setup.paper is not None and setup.paper.physical and runs:
        device, units = setup.paper.device, setup.paper.units
        physical = [tuple(end if math.isinf(end) else float(device.stiffness(end)) for end in run)
                    for run in runs]
        # The ends' note in the units the device was given in.
        text, ends, _ = interval_texts(physical, codes, "K_w", units["K_w"])
        notes.append(f"stable K_w at B_w = {float(device.damping(at)):.10g} {units['B_w']}: {text}")
    if ends:
        notes.append(ends)
    # The z = 1 line of a loop with an integrator lies at y = 0 up to rounding
    # (1e-12 of the interval): no minimum worth naming.
    if runs and runs[0][0] > 1e-9 * (runs[0][1] - runs[0][0]):
        notes.append(f"a minimum is needed: {y} > {runs[0][0]:.10g}{unit_y}")
    return notes, {"x": at, "intervals": [list(r) for r in runs], "ends": kinds}


#: The quantities of ``limits``: (field of :class:`~symstab.numeric.engine.results.Limits`,
#: name in the plane ``(x, y)``, the paper's name in Table I's plane and in the
#: device's units, meaning, what its unit is).  The paper's names say what each is:
#: ``beta_left``/``beta_right`` are the ends of the stable set's beta range, which a
#: reader of the paper would otherwise take for its beta_min = -delta, the damping
#: where the boundary arc starts.
LIMITS = (
    ("y_max", "{y}_max", ("alpha_max", "K_max"), "largest stable {y}", "y"),
    ("x_at_y_max", "{x} at {y}_max", ("beta_at_alpha_max", "B_w at K_max"),
     "the {x} at which {y}_max is reached", "x"),
    ("x_min", "{x}_min", ("beta_left", "B_left"), "leftmost {x} of the stable set", "x"),
    ("x_max", "{x}_max", ("beta_right", "B_right"), "rightmost {x} of the stable set", "x"),
    ("area", "area", ("z_width", "Z-width"), "area of the stable set in the ({x}, {y}) plane",
     "area"),
)


def _units(setup, physical=False, over=None):
    """The unit of each kind of quantity: the loop's; none in Table I's plane, the device's if ``physical``.

    Kinds: ``x``, ``y``, ``area``, and ``p`` and ``q``, the parameters
    ``over`` (design's: a name or a pair of names).
    """
    ux, uy = setup.unit(setup.x), setup.unit(setup.y)
    up, uq = (setup.unit(name) for name in _searched(over))
    if physical:
        ux, uy, up = (setup.paper.units[k] for k in ("B_w", "K_w", "M_w"))
    force = None if setup.paper is not None else force_unit(setup)
    return {"x": ux, "y": uy, "p": up, "q": uq,
            "area": f"({ux})({uy})" if ux and uy else (ux or uy), None: "",
            "force": "" if force is None else force.si}


def force_unit(setup):
    """The loop's force unit, from a stiffness of its plane: a ``ForceUnit``, or None.

    The plane's ``y`` (else ``x``) times the position, where it is a
    stiffness in the file's units: ``N/m`` gives ``N``, ``N m/rad`` gives
    ``N m``.  None where neither has a stiffness unit (the force's unit is
    then not known).
    """
    from ..numeric.loop.quantities import unit_info

    forces = {unit_info("N").dimensions, unit_info("N m").dimensions}
    for name in (setup.y, setup.x):
        unit = setup.unit(name)
        if not unit:
            continue
        position = "rad" if unit_info(unit).angle < 0 else "m"
        force = unit_info(f"({unit}) * {position}")
        if force.dimensions in forces and not force.angle:
            return ForceUnit(force.si, force.dimensions, unit)
    return None


@dataclasses.dataclass(frozen=True)
class ForceUnit:
    """A loop's force unit: its SI name, its dimension, and the stiffness unit it comes from."""

    si: str
    dimensions: tuple
    stiffness: str


def _searched(over):
    """``(p, q)``: design's searched parameters (a name, a pair or None), "" where none."""
    names = (over,) if isinstance(over, str) else tuple(over or ())
    return (names + ("", ""))[:2]


def _physical(setup, kind, value):
    """A value of Table I's plane in the paper's device's units (``kind`` as :func:`_units`)."""
    device = setup.paper.device
    if value is None or kind is None:
        return value
    if kind == "y":
        return float(device.stiffness(value))
    if kind == "x":
        return float(device.damping(value))
    if kind == "p":
        return float(device.mass(value))
    return value * (device.m / device.T) * (device.m / device.T**2)


def named(setup, lim):
    """``lim`` in the plane's printed names (Table I's for the paper's device options)."""
    return dataclasses.replace(lim, x=setup.name(setup.x), y=setup.name(setup.y), at={})


def plane_table(setup, rows, *, over=None):
    """``(columns, rows)`` of quantities of the plane of ``setup``, for :func:`symstab.cli.output.emit`.

    ``rows`` are ``(name, value, kind, meaning)``: ``name`` and ``meaning``
    templates in ``{x}``, ``{y}``, ``{p}`` and ``{q}`` (the parameters ``over``),
    ``kind`` that of :func:`_units`, and ``name`` a tuple ``(name, Table
    I's name, physical name)`` where the paper's names are not the
    template's (None: the template's).  A loop's rows are ``(quantity,
    value, unit, meaning)`` in its units; the paper's device options give
    Table I's names and values, and for a physical device the same quantity
    in the device's units beside them (``K_w``, ``B_w``, ``M_w``).
    """
    names = {"x": setup.name(setup.x), "y": setup.name(setup.y),
             **{k: setup.name(n) if n else "" for k, n in zip("pq", _searched(over), strict=True)}}
    physical_names = {"x": "B_w", "y": "K_w", "p": "M_w"}
    paper = setup.paper
    physical = paper is not None and paper.physical
    units = _units(setup, physical, over)
    out = []
    for name, value, kind, meaning in rows:
        name, table_one, label = (name + (None, None))[:3] if isinstance(name, tuple) else (
            name, None, None)
        if paper is None:
            row = (name.format(**names), value, units[kind])
        else:
            row = (table_one or name.format(**names), value)
            if physical:
                row += (label or name.format(**physical_names), _physical(setup, kind, value),
                        units[kind])
        out.append(row + (meaning.format(**names),))
    columns = (["quantity", "value"] + (["unit"] if paper is None else [])
               + (["physical", "physical value", "unit"] if physical else []) + ["meaning"])
    return columns, out


def limits_table(setup, lim):
    """``(columns, rows)`` of the limits ``lim`` of the plane of ``setup`` (:func:`plane_table`)."""
    return plane_table(setup, [((name, *paper_names), getattr(lim, field), kind, meaning)
                               for field, name, paper_names, meaning, kind in LIMITS])


def limits_notes(setup, lim):
    """The notes on limits: why the stable set is empty, or that it is unbounded."""
    x, y = setup.name(setup.x), setup.name(setup.y)
    if lim.empty:
        why = lim.reason.removeprefix("the stable set is empty: ") or \
            "no cell of the window has every root inside the unit circle"
        return [f"the stable set of the ({x}, {y}) plane is empty at these values: {why}"]
    if math.isinf(lim.y_max) or math.isinf(lim.area):
        return [f"the stable set is unbounded in the ({x}, {y}) plane"]
    return []


def passive_notes(setup, lim):
    """The passive set beside the stable one: (notes, json), one line per fact.

    Colgate and Schenkel's condition with the device's friction ``b`` and
    the delay (:func:`symstab.numeric.analysis.passivity.passive_region`).  A loop
    it does not cover (no ``b``, a plant other than ``1/(m s**2 + b s)``)
    gets a note saying why, not an error: the stable limits stand on their
    own.
    """
    from ..numeric.analysis.passivity import passive_region

    x, y = setup.name(setup.x), setup.name(setup.y)
    paper = setup.paper
    if paper is not None and paper.delta == 0:
        # The frictionless paper's loop has no b: no passive set with an interior.
        out = {"x": x, "y": y, "y_max": None, "x_at_y_max": None, "area": 0.0,
               "alpha_max": None, "beta_at_alpha_max": None}
        return ["passive set (Colgate-Schenkel): none, the device has no damping "
                "(delta = 0)"], out
    try:
        region = passive_region(setup.loop, x=setup.x, y=setup.y, **setup.values).renamed(x, y)
    except (ValueError, TypeError, ArithmeticError) as exc:
        return [f"passive set (Colgate-Schenkel) not computed: {exc}"], {"error": str(exc)}
    units = _units(setup)
    ux, uy, ua = (f" {units[k]}" if units[k] else "" for k in ("x", "y", "area"))
    out = {"x": x, "y": y, "y_max": region.y_max, "x_at_y_max": region.x_at_y_max,
           "area": region.area, "bounded": region.bounded,
           "x_range": list(region.x_range), "y_range": list(region.y_range)}
    if paper is not None:      # Table I's names, as the stable limits have them
        out.update(alpha_max=region.y_max, beta_at_alpha_max=region.x_at_y_max)
    if region.empty:
        where = (f"gamma = {paper.gamma:.6g}, d = {paper.d}, delta = {paper.delta:.6g}"
                 if paper is not None else
                 f"b = {setup.values.get('b', math.nan):.10g}"
                 + (f" {setup.unit('b')}" if setup.unit("b") else ""))
        return [f"passive set (Colgate-Schenkel, with the delay): no passive point in the "
                f"({x}, {y}) plane at {where}"], out
    notes = [f"passive {y}_max = {region.y_max:.10g}{uy} at {x} = {region.x_at_y_max:.10g}{ux} "
             f"(Colgate-Schenkel with the delay; stable {y}_max = "
             f"{number_text(lim.y_max) or 'none'})"]
    if setup.paper is not None and setup.paper.physical:
        units = _units(setup, physical=True)
        k_max, b_at = (_physical(setup, k, v) for k, v in (("y", region.y_max),
                                                           ("x", region.x_at_y_max)))
        out.update(K_max=k_max, B_w_at_K_max=b_at)
        notes.append(f"passive K_max = {k_max:.10g} {units['y']} at B_w = {b_at:.10g} "
                     f"{units['x']}")
    if region.bounded:
        notes.append(f"passive area = {region.area:.10g}{ua} in the "
                     f"({x}, {y}) plane (stable area = {number_text(lim.area) or 'none'})")
    else:
        notes.append(f"the passive set is unbounded; its area inside {x} in "
                     f"[{region.x_range[0]:.6g}, {region.x_range[1]:.6g}], {y} in "
                     f"[{region.y_range[0]:.6g}, {region.y_range[1]:.6g}] is {region.area:.10g}")
    return notes, out
