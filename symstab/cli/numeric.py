"""The numeric sub-commands of ``symstab``: boundary, limits, classify, design.

Each takes the device and delay either in physical units (``--m --b --T``,
default the paper's device, and ``--Td``) or dimensionless (``--delta --d``),
the virtual mass as ``--Mw`` (physical) or ``--gamma``, and prints a table,
CSV or JSON.  Physical inputs are echoed with the output and results are
given in both unit systems.  Validation happens in the library, and sizes
(``--n``, list lengths) are checked against the memory limit
(:func:`symstab._resources.check_memory`) before the work; the caller
(:func:`symstab.cli.commands.main`) turns ``ValueError``/``TypeError`` into one line
on stderr and exit status 2.
"""

import argparse
import csv
import dataclasses
import io
import json
import math
import sys
import textwrap

import numpy as np

from . import loop as cli_loop
from .._resources import check_memory

__all__ = ["add_commands"]

FORMATS = ("table", "csv", "json")
#: Memory per printed row: the row as Python objects (a tuple of up to six
#: floats) and its text.  Measured with tracemalloc on 100000 rows of five
#: columns: 900 bytes (JSON), 800 (table), 390 (CSV).
_BYTES_PER_ROW = 1000


@dataclasses.dataclass(frozen=True)
class Setup:
    """The resolved inputs of a numeric command."""

    device: object  # symstab.numeric.units.Device or None (dimensionless input)
    gamma: float
    d: int
    delta: float
    units: dict
    echo: tuple  # lines describing the inputs
    mass: bool = True  # False: the command searches over gamma; no virtual mass is an input

    @property
    def physical(self):
        return self.device is not None

    def as_dict(self):
        out = {"gamma": self.gamma} if self.mass else {}
        out.update(d=self.d, delta=self.delta)
        if self.physical:
            out.update(m=self.device.m, b=self.device.b, T=self.device.T,
                       Td=self.device.delay(self.d))
            if self.mass:
                out.update(M_w=self.device.mass(self.gamma))
            out.update(units=self.units)
        return out


#: The one rule for the units of the paper's device options (also in the README).
UNITS_RULE = ("Units: the device options are rotary by default, as the paper's device is a "
              "paddle (m and M_w in kg m^2, b and B_w in N m s/rad, K_w in N m/rad); --linear "
              "reads and prints the same numbers as a sliding mass's (kg, N s/m, N/m): the "
              "equations are the same, only the units' names change.  T and Td are in s.  A "
              "loop file (--loop) has its own units, converted to SI; --linear does not apply "
              "to it.")


def _add_model_options(p):
    g = p.add_argument_group("device and delay (physical; default: the paper's device)",
                             textwrap.fill(UNITS_RULE, 77))
    g.add_argument("--m", type=float, help="effective mass (inertia), kg m^2 (kg with --linear), "
                                           "> 0 (default 0.0128)")
    g.add_argument("--b", type=float, help="viscous friction, N m s/rad (N s/m with --linear), "
                                           ">= 0 (default 0.0324)")
    g.add_argument("--T", type=float, help="sample period, s, > 0 (default 0.001)")
    g.add_argument("--Td", type=float, help="loop delay, s, a whole number of periods (default 0)")
    g = p.add_argument_group("device and delay (dimensionless, instead of --m --b --T --Td)")
    g.add_argument("--delta", type=float, help="b T / m, from 0 (frictionless) to 1e6")
    g.add_argument("--d", type=_integer, help="delay in samples, an integer >= 0 (also allowed "
                                               "with the physical options instead of --Td)")
    g = p.add_argument_group("virtual mass")
    x = g.add_mutually_exclusive_group()
    x.add_argument("--gamma", type=float, help="M_w / m (default 0)")
    x.add_argument("--Mw", type=float, help="virtual mass, kg m^2 (kg with --linear)")
    p.add_argument("--linear", action="store_true",
                   help="linear units (kg, N s/m, N/m) instead of the rotary default (kg m^2, "
                        "N m s/rad, N m/rad) for the device options and the results: the same "
                        "numbers; not with --loop")
    p.add_argument("--format", choices=FORMATS, default="table", help="output format (default: table)")


def _integer(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value.is_integer() and value >= 0):
        raise argparse.ArgumentTypeError(f"delay d must be a non-negative integer, got {text!r}")
    return int(value)


def _resolve(args, *, mass=True):
    """Turn the parsed options into a :class:`Setup` (raises ValueError).

    ``mass=False`` (``design``, which searches over the virtual mass) leaves
    the virtual mass out of the echo and of the JSON inputs.
    """
    from ..numeric.units import PAPER_DEVICE, Device

    physical = [name for name in ("m", "b", "T", "Td") if getattr(args, name) is not None]
    if args.delta is not None:
        if physical:
            raise ValueError(f"--delta (dimensionless) cannot be combined with --{physical[0]} "
                             "(physical); give one or the other")
        if args.Mw is not None:
            raise ValueError("--Mw needs a physical device (--m); use --gamma with --delta")
        from .._validate import check_loop
        gamma, d, delta = check_loop(0.0 if args.gamma is None else args.gamma,
                                     0 if args.d is None else args.d, args.delta)
        echo = (f"dimensionless: delta = {delta:.6g}, d = {d}"
                + (f", gamma = {gamma:.6g}" if mass else ""),)
        return Setup(None, gamma, d, delta, {}, echo, mass)
    if args.Td is not None and args.d is not None:
        raise ValueError("give the delay once: --Td (seconds) or --d (samples)")
    device = Device(m=PAPER_DEVICE.m if args.m is None else args.m,
                    b=PAPER_DEVICE.b if args.b is None else args.b,
                    T=PAPER_DEVICE.T if args.T is None else args.T)
    if args.d is not None:
        from .._validate import check_delay
        d = check_delay(args.d)
    else:
        d = device.delay_samples(0.0 if args.Td is None else args.Td)
    gamma = device.gamma(args.Mw) if args.Mw is not None else (0.0 if args.gamma is None else args.gamma)
    from .._validate import check_real
    gamma = check_real("gamma", gamma)
    units = device.units(rotary=not args.linear)
    mass_unit = units["M_w"]
    echo = (f"device: m = {device.m:g} {mass_unit}, b = {device.b:g} {units['B_w']}, "
            f"T = {device.T:g} s; delay Td = {device.delay(d):g} s (d = {d})"
            + (f"; virtual mass M_w = {device.mass(gamma):g} {mass_unit} (gamma = {gamma:g})"
               if mass else ""),
            f"dimensionless: delta = b T / m = {device.delta:.6g}")
    return Setup(device, gamma, d, device.delta, units, echo, mass)


# --------------------------------------------------------------------------
# Output


def _number(x):
    if x is None:
        return ""
    if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
        return str(int(x))
    if isinstance(x, str):
        return x
    x = float(x)
    return "nan" if math.isnan(x) else f"{x:.10g}"


def _end_text(value):
    # -0.0 (an end computed as -c0/c1 with c0 = 0) is the end 0.
    return "-inf" if value == -math.inf else "inf" if value == math.inf else f"{value + 0.0:.10g}"


def _listed(words):
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def interval_texts(runs, codes, name, unit="", *, stable_ends="boundary"):
    """Stable intervals as text, open at every end that is not stable, and what those ends are.

    A stable set is open: an interval's end is on the boundary, where a pole
    is on the unit circle (marginal), so "[0, ...]" would call a point stable
    that is not.  The ends are printed as computed, and exact where they are
    exact (the z = 1 line of a plant with an integrator is K = 0).

    Parameters
    ----------
    runs : list of (float, float)
        The stable intervals, increasing; an end may be infinite.
    codes : list of (int, int)
        The classification (:data:`symstab.numeric.stability.MARGINAL`,
        ``UNSTABLE`` or ``STABLE``) of each finite end (ignored for infinite ones).
    name, unit : str
        The parameter along the intervals, and its unit.
    stable_ends : {"boundary", "closed"}
        What an end classified stable is: a computed boundary point, stable
        only by its rounding ("boundary", the default), or a stable end of
        the range searched (a path's end: "closed", printed with a bracket).

    Returns
    -------
    (str, str or None, list)
        ``"(0, 108.8220385) N/m"`` (or ``"none"``), the note on the ends
        (None without finite ends) and, per interval, the kind of each end
        (``"marginal"``, ``"unstable"``, ``"boundary"``, ``"stable"`` or
        ``"infinite"``) for JSON.
    """
    from ..numeric.stability import MARGINAL, STABLE, UNSTABLE

    if stable_ends not in ("boundary", "closed"):
        raise ValueError(f"stable_ends must be 'boundary' or 'closed', got {stable_ends!r}")
    suffix = f" {unit}" if unit else ""
    if not runs:
        return "none", None, []
    closed = [tuple(stable_ends == "closed" and code == STABLE and not math.isinf(value)
                    for value, code in zip(run, pair)) for run, pair in zip(runs, codes)]
    text = ", ".join(f"{'[' if shut[0] else '('}{_end_text(lo)}, {_end_text(hi)}"
                     f"{']' if shut[1] else ')'}"
                     for (lo, hi), shut in zip(runs, closed)) + suffix
    kinds, found = [], {"marginal": [], "unstable": [], "boundary": []}
    for (lo, hi), pair in zip(runs, codes):
        row = []
        for value, code in zip((lo, hi), pair):
            if math.isinf(value):
                row.append("infinite")
                continue
            if stable_ends == "closed" and code == STABLE:
                row.append("stable")
                continue
            # A finite end the root count calls stable is on the boundary to
            # within the rounding of the end itself: not stable either.
            kind = "marginal" if code == MARGINAL else "unstable" if code == UNSTABLE else "boundary"
            row.append(kind)
            if _end_text(value) not in found[kind]:
                found[kind].append(_end_text(value))
        kinds.append(row)
    said = {"marginal": "marginal (a pole on the unit circle)", "unstable": "unstable",
            "boundary": "on the boundary to within rounding"}
    parts = [f"{said[kind]} at {name} = {_listed(values)}{suffix}"
             for kind, values in found.items() if values]
    note = ("open intervals: their ends are not stable; " + "; ".join(parts)) if parts else None
    return text, note, kinds


def _emit(setup, fmt, columns, rows, *, result=None, notes=(), out=None, json_rows=True):
    """Print ``rows`` (tuples matching ``columns``) in ``fmt``.

    ``result`` is the JSON payload besides the rows; ``notes`` are lines
    printed after a table (and kept in JSON as "notes").
    """
    out = out or sys.stdout
    if fmt == "json":
        payload = {"inputs": setup.as_dict(), **(result or {})}
        if rows and json_rows:
            payload["rows"] = [dict(zip(columns, (None if isinstance(v, float) and math.isnan(v)
                                                  else v for v in row))) for row in rows]
        if notes:
            payload["notes"] = list(notes)
        json.dump(_plain(payload), out, indent=1, sort_keys=False)
        out.write("\n")
        return
    if fmt == "csv":
        for line in setup.echo:
            print(line, file=sys.stderr)
        for line in notes:
            print(line, file=sys.stderr)
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow([_number(v) for v in row])
        out.write(buf.getvalue())
        return
    for line in setup.echo:
        print(line, file=out)
    if rows:
        cells = [list(columns)] + [[_number(v) for v in row] for row in rows]
        widths = [max(len(r[i]) for r in cells) for i in range(len(columns))]
        print(file=out)
        for k, r in enumerate(cells):
            print("  ".join(c.rjust(w) for c, w in zip(r, widths)).rstrip(), file=out)
            if k == 0:
                print("  ".join("-" * w for w in widths), file=out)
    if notes:
        print(file=out)
        for line in notes:
            print(line, file=out)


def _plain(x):
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None if math.isnan(x) else ("inf" if x > 0 else "-inf")
    return x


def _physical_columns(setup, names):
    """Column labels with units for K_w, B_w (physical setups only)."""
    return [f"{n} [{setup.units[n]}]" for n in names]


# --------------------------------------------------------------------------
# Commands


def _cmd_boundary(args):
    if cli_loop.uses_loop(args):
        return cli_loop.run(args)
    from ..numeric.region import boundary_curve

    setup = _resolve(args)
    check_memory(f"--n {args.n} boundary points", args.n * _BYTES_PER_ROW)
    curve = boundary_curve(gamma=setup.gamma, d=setup.d, delta=setup.delta, n=args.n)
    columns = ["theta [rad]", "alpha", "beta"]
    rows = list(zip(curve.theta, curve.alpha, curve.beta))
    if setup.physical:
        columns += _physical_columns(setup, ["K_w", "B_w"])
        rows = [r + (setup.device.stiffness(r[1]), setup.device.damping(r[2])) for r in rows]
    notes = [curve.message] if curve.empty else [f"theta_max = {curve.theta_max:.15g} rad"]
    for seg in curve.segments:
        notes.append(f"boundary segment ({seg.root}): (beta, alpha) from ({seg.beta0:.10g}, "
                     f"{seg.alpha0:.10g}) to ({seg.beta1:.10g}, {seg.alpha1:.10g})")
    result = {"theta_max": curve.theta_max, "message": curve.message,
              "segments": [dataclasses.asdict(s) for s in curve.segments]}
    _emit(setup, args.format, columns, rows, result=result, notes=notes)
    return 0


#: The quantities of ``symstab limits``: (name in the table and the JSON, attribute of
#: :class:`symstab.numeric.region.Limits`, meaning, physical name, physical unit).  The
#: names say what each is: ``beta_left``/``beta_right`` are the ends of the
#: stable region's beta range, which a reader of the paper would otherwise take
#: for its beta_min = -delta, the damping where the boundary arc starts.
_LIMITS = (
    ("alpha_max", "alpha_max", "largest stable alpha = K_w T^2 / m (the renderable stiffness)",
     "K_max", "K_w"),
    ("beta_at_alpha_max", "beta_at_alpha_max", "the beta at which alpha_max is reached",
     "B_w at K_max", "B_w"),
    ("beta_left", "beta_left", "leftmost beta of the stable region (not the paper's "
     "beta_min = -delta, where the boundary arc starts)", "B_left", "B_w"),
    ("beta_right", "beta_right", "rightmost beta of the stable region", "B_right", "B_w"),
    ("z_width", "z_width", "area of the stable region in the (beta, alpha) plane", "Z-width", None),
)


def _limits_rows(setup, lim):
    rows = []
    for name, attribute, _, label, unit in _LIMITS:
        value = getattr(lim, attribute)
        row = [name, value]
        if setup.physical:
            dev = setup.device
            if value is None:
                phys = None
            elif unit == "K_w":
                phys = dev.stiffness(value)
            elif unit == "B_w":
                phys = dev.damping(value)
            else:  # area in the (B_w, K_w) plane
                phys = value * (dev.m / dev.T) * (dev.m / dev.T**2)
            row += [label, phys, setup.units[unit] if unit else
                    f"({setup.units['B_w']})({setup.units['K_w']})"]
        rows.append(tuple(row))
    columns = ["quantity", "value"] + (["physical", "physical value", "unit"] if setup.physical else [])
    return columns, rows


def _limits_json(lim):
    """The ``limits`` object of the JSON output, under the names of the table."""
    out = {name: getattr(lim, attribute) for name, attribute, _, _, _ in _LIMITS}
    out["message"] = lim.message
    return out


def _passive(setup, lim):
    """The passive set beside the stable region: (notes, json), one line per fact.

    Colgate and Schenkel's condition with the device's friction and the
    delay (:func:`symstab.numeric.passivity.paper_passive_region`).
    """
    from ..numeric.passivity import paper_passive_region

    if setup.delta == 0:
        return (["passive set (Colgate-Schenkel): none, the device has no damping (delta = 0)"],
                {"alpha_max": None, "beta_at_alpha_max": None, "area": 0.0})
    region = paper_passive_region(gamma=setup.gamma, d=setup.d, delta=setup.delta)
    if region.empty:
        return ([f"passive set (Colgate-Schenkel, with the delay): no passive point at "
                 f"gamma = {setup.gamma:.6g}, d = {setup.d}, delta = {setup.delta:.6g}"],
                {"alpha_max": None, "beta_at_alpha_max": None, "area": 0.0})
    out = {"alpha_max": region.y_max, "beta_at_alpha_max": region.x_at_y_max,
           "area": region.area}
    notes = [f"passive alpha_max = {region.y_max:.10g} at beta = {region.x_at_y_max:.10g} "
             f"(Colgate-Schenkel with the delay; stable alpha_max = "
             f"{_number(lim.alpha_max) or 'none'})"]
    if setup.physical:
        dev = setup.device
        k_max, b_at = float(dev.stiffness(region.y_max)), float(dev.damping(region.x_at_y_max))
        out.update(K_max=k_max, B_w_at_K_max=b_at)
        notes.append(f"passive K_max = {k_max:.10g} {setup.units['K_w']} at B_w = {b_at:.10g} "
                     f"{setup.units['B_w']}")
    notes.append(f"passive area = {region.area:.10g} in the (beta, alpha) plane (stable "
                 f"z_width = {_number(lim.z_width) or 'none'})")
    return notes, out


def _cmd_limits(args):
    if cli_loop.uses_loop(args):
        return cli_loop.run(args)
    from ..numeric.region import limits

    setup = _resolve(args)
    lim = limits(gamma=setup.gamma, d=setup.d, delta=setup.delta)
    columns, rows = _limits_rows(setup, lim)
    notes = [lim.message] if lim.message else []
    if not lim.empty and not math.isclose(lim.beta_left, -setup.delta, rel_tol=1e-9, abs_tol=1e-12):
        notes.append(f"beta_left = {lim.beta_left:.10g} is the leftmost beta of the stable region; "
                     f"the paper's beta_min = -delta = {-setup.delta:.10g} is where the boundary "
                     "arc starts (theta = 0)")
    result = {"limits": _limits_json(lim)}
    damping = None
    if args.beta is not None or args.Bw is not None:
        if args.Bw is not None:
            if not setup.physical:
                raise ValueError("--Bw needs a physical device; use --beta with --delta")
            damping = float(setup.device.beta(args.Bw))
        else:
            damping = args.beta
        from .._validate import check_real
        damping = check_real("beta", damping)
        runs = [] if lim.empty else lim.alpha_interval(damping)
        from ..numeric.stability import classify

        codes = [tuple(int(classify(alpha=end, beta=damping, gamma=setup.gamma, d=setup.d,
                                    delta=setup.delta)) if math.isfinite(end) else None
                       for end in run) for run in runs]
        text, ends, kinds = interval_texts(runs, codes, "alpha")
        notes.append(f"stable alpha at beta = {damping:.10g}: {text}")
        if setup.physical and runs:
            dev = setup.device

            def stiffness(alpha):
                return alpha if math.isinf(alpha) else float(dev.stiffness(alpha))

            physical = [tuple(stiffness(end) for end in run) for run in runs]
            text, ends, _ = interval_texts(physical, codes, "K_w", setup.units["K_w"])
            notes.append(f"stable K_w at B_w = {float(dev.damping(damping)):.10g} "
                         f"{setup.units['B_w']}: {text}")
        if ends:
            notes.append(ends)
        if runs and runs[0][0] > 0:
            notes.append(f"a minimum stiffness is needed: alpha > {runs[0][0]:.10g}")
        result["alpha_intervals"] = {"beta": damping, "intervals": [list(r) for r in runs],
                                     "ends": kinds}
    more, result["passive"] = _passive(setup, lim)
    notes += more
    _emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def _parse_list(text, name):
    """The numbers of a comma-separated list; an empty item ("1,,3") is an error."""
    items = [v.strip() for v in text.split(",")]
    if not any(items):
        raise ValueError(f"{name} must name at least one number")
    if not all(items):
        raise ValueError(f"{name} must be a comma-separated list of numbers without empty "
                         f"items, got {text!r}")
    try:
        values = [float(v) for v in items]
    except ValueError:
        raise ValueError(f"{name} must be a comma-separated list of numbers, got {text!r}") from None
    return np.array(values)


def stiffness_and_damping(args, setup, parse):
    """(alpha, beta) from --alpha/--Kw and --beta/--Bw, each read by ``parse(text, flag)``."""
    if (args.alpha is None) == (args.Kw is None) or (args.beta is None) == (args.Bw is None):
        raise ValueError("give the stiffness (--alpha or --Kw) and the damping (--beta or --Bw), once each")
    if (args.Kw is not None or args.Bw is not None) and not setup.physical:
        raise ValueError("--Kw and --Bw need a physical device; use --alpha and --beta with --delta")
    alpha = parse(args.alpha, "--alpha") if args.alpha is not None else \
        setup.device.alpha(parse(args.Kw, "--Kw"))
    beta = parse(args.beta, "--beta") if args.beta is not None else \
        setup.device.beta(parse(args.Bw, "--Bw"))
    return alpha, beta


#: Above this delay ``symstab classify`` gives verdicts without the spectral radius.
_RADIUS_MAX_DELAY = 1000


def _cmd_classify(args):
    if cli_loop.uses_loop(args):
        return cli_loop.run(args)
    from ..numeric.stability import MARGINAL, STABLE, classify, spectral_radius

    setup = _resolve(args)
    alpha, beta = (np.atleast_1d(x) for x in stiffness_and_damping(args, setup, _parse_list))
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
        columns += _physical_columns(setup, ["K_w", "B_w"])
        rows = [r + (setup.device.stiffness(r[0]), setup.device.damping(r[1])) for r in rows]
    columns += ["spectral radius", "verdict"]
    rows = [r + (rad, str(v)) for r, rad, v in zip(rows, radius, verdict)]
    _emit(setup, args.format, columns, rows, notes=notes)
    return 0


def _cmd_design(args):
    if cli_loop.uses_loop(args):
        return cli_loop.run(args)
    from ..numeric.region import best_virtual_mass, limits

    setup = _resolve(args, mass=False)
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
    _emit(setup, args.format, columns, rows, result=result, notes=notes, json_rows=False)
    return 0


def add_commands(sub):
    """Register the numeric sub-commands on an argparse sub-parser set."""
    from .commands import add_command

    p = add_command(
        sub, "boundary", help="the stability boundary alpha(theta), beta(theta)",
        description="Compute the stability boundary arc alpha(theta), beta(theta) of the "
                    "paper's eq. (7) for one virtual mass, delay and device, with K_w and B_w "
                    "in physical units, and the straight segments that close the region.",
        example="symstab boundary --Td 0.01 --n 11", func=_cmd_boundary)
    _add_model_options(p)
    p.add_argument("--n", type=int, default=101, help="points on the arc (default 101)")
    cli_loop.add_loop_options(p, "boundary")

    p = add_command(
        sub, "limits", help="alpha_max, the beta range and the Z-width",
        description="Compute the largest stable stiffness alpha_max (K_max), the damping at "
                    "which it is reached, the range of damping over the stable region and its "
                    "area (Z-width), and with --beta/--Bw the stable stiffness intervals at that "
                    "damping.",
        example="symstab limits --Td 0.04 --Mw 0.0128", func=_cmd_limits)
    p.epilog = "quantities (table rows and JSON keys of \"limits\"):\n" + "\n".join(
        textwrap.fill(meaning, 79, initial_indent=f"  {name:<18} ", subsequent_indent=" " * 21)
        for name, _, meaning, _, _ in _LIMITS) + "\n\n" + p.epilog
    _add_model_options(p)
    x = p.add_mutually_exclusive_group()
    x.add_argument("--beta", type=float, help="also give the stable alpha interval(s) at this beta")
    x.add_argument("--Bw", type=float, help="also give the stable K_w interval(s) at this damping")
    cli_loop.add_loop_options(p, "limits")

    p = add_command(
        sub, "classify", help="stable, unstable or marginal, with the spectral radius",
        description="Decide by counting the roots of the loop polynomial outside the unit "
                    "circle (Schur-Cohn, or a certified count by the argument principle where "
                    "that is not decisive) whether each stiffness-damping point is stable, "
                    "unstable or marginal, and give the spectral radius of the loop.",
        example="symstab classify --Td 0.01 --Kw 1,3,10 --Bw 0.2", func=_cmd_classify)
    _add_model_options(p)
    p.add_argument("--alpha", help="dimensionless stiffness(es), comma-separated")
    p.add_argument("--beta", help="dimensionless damping(s), comma-separated")
    p.add_argument("--Kw", help="virtual stiffness(es), comma-separated (physical)")
    p.add_argument("--Bw", help="virtual damping(s), comma-separated (physical)")
    cli_loop.add_loop_options(p, "classify")

    p = add_command(
        sub, "design", help="the virtual mass that maximises the renderable stiffness",
        description="Search the virtual mass gamma = M_w / m that maximises the largest stable "
                    "stiffness for one delay and device, and report that stiffness, its damping "
                    "and the gain over no virtual mass.",
        example="symstab design --Td 0.04", func=_cmd_design)
    _add_model_options(p)
    cli_loop.add_loop_options(p, "design")
