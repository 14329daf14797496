"""A loop file's stable set in its plane, as rows and notes: shared by ``limits`` and ``design``.

:func:`limits_rows`, :func:`limits_notes` and :func:`limits_result` show a
:meth:`symstab.Loop.limits`; :func:`stable_intervals_at` the stable
intervals of y at one x, their ends classified.
"""

import math

from .output import interval_texts

__all__ = ["stable_intervals_at", "limits_rows", "limits_notes", "limits_result"]


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


def limits_rows(setup, lim):
    """The rows (quantity, value, unit, meaning) of a loop's limits in the plane of ``setup``."""
    ux, uy = setup.unit(setup.x), setup.unit(setup.y)
    area_unit = f"({ux})({uy})" if ux and uy else (ux or uy)
    x, y = setup.x, setup.y
    return [(f"{y}_max", lim.y_max, uy, f"largest stable {y}"),
            (f"{x} at {y}_max", lim.x_at_y_max, ux, f"the {x} where it is reached"),
            (f"{x}_min", lim.x_min, ux, f"leftmost {x} of the stable set"),
            (f"{x}_max", lim.x_max, ux, f"rightmost {x} of the stable set"),
            ("area", lim.area, area_unit, f"area of the stable set in the ({x}, {y}) plane")]


def limits_notes(setup, lim):
    """The notes on a loop's limits: why the stable set is empty, or that it is unbounded."""
    if lim.empty:
        return [f"no stable point in the ({setup.x}, {setup.y}) plane at these values: "
                f"{lim.reason or 'no cell of the window has every root inside the unit circle'}"]
    if math.isinf(lim.y_max) or math.isinf(lim.area):
        return [f"the stable set is unbounded in the ({setup.x}, {setup.y}) plane"]
    return []


def limits_result(lim):
    """The ``limits`` object of the JSON output of a loop's limits."""
    out = {"x": lim.x, "y": lim.y, "y_max": lim.y_max, "x_at_y_max": lim.x_at_y_max,
           "x_min": lim.x_min, "x_max": lim.x_max, "area": lim.area, "cells": lim.cells}
    return {"limits": out}
