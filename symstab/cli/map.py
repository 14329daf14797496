"""``symstab map``: the stability of a stiffness-damping grid; CSV or NPZ, and a PNG.

The paper's loop is simulated at every cell (with the non-idealities of
:mod:`symstab.cli.simulation`), its root count beside; a loop file
(``--loop``) is classified by its root count at every cell, with the
D-decomposition drawn over the map, and with ``--simulate`` also simulated
(:meth:`symstab.Loop.stability_map`: encoder quantization, force
saturation, and Coulomb friction on the driven mass).  Both run one flow
(:func:`_map`): a plan checks every input first, then the cells are
classified, simulated, written and summed up the same way.  The output paths are
checked before the work and the files written atomically.
"""

import io
import math
import pathlib
import textwrap

import numpy as np

from .._resources import CHUNK_BYTES, check_memory, chunk_slices
from ..drawing import (
    LIMIT_CYCLE_COLOR,
    LIMIT_CYCLE_LABEL,
    loop_map_figure,
    png_or_none,
    probability_map_figure,
    simulated_map_figure,
)
from .loop_options import add_loop_options, resolve_loop, uncertain_box, uses_loop, value_text
from .options import add_command, add_model_options, resolve, stiffness_and_damping
from .output import check_files, write_output
from .simulation import (
    add_nonideal_options,
    check_loop_friction,
    loop_nonideal_text,
    nonideal_text,
    resolve_nonideal,
    simulated_theory,
    with_option_names,
)
from .units import tex_unit

__all__ = ["register", "run", "MAX_GRID", "map_outputs", "LOOP_MAP_HEADLINE",
           "LOOP_SIMULATE_HEADLINE"]

#: The first line of ``map --loop``: what it computes, since ``map`` of the
#: paper's loop simulates (a loop file with --simulate).
LOOP_MAP_HEADLINE = ("map --loop: root counts of the linear loop (add --simulate to simulate "
                     "every cell)")
#: The first line of ``map --loop --uncertain``.
LOOP_PROBABILITY_HEADLINE = ("map --loop --uncertain: the probability that each cell is stable "
                             "over random draws of the uncertain parameters (a certified root "
                             "count at every draw)")
#: The first line of ``map --loop --simulate``.
LOOP_SIMULATE_HEADLINE = ("map --loop --simulate: every cell simulated, the loop's certified "
                          "root count beside")

#: Bytes per map cell in the CSV and NPZ written, with the Python objects
#: that build them (generous).
_MAP_CELL_BYTES = 300


#: Memory per classified point of a map, per coefficient: the coefficients,
#: the environment's and the plant's arrays and the classifier's working
#: copies (generous).
_BYTES_PER_COEFFICIENT = 64


def register(subparsers):
    """Add ``symstab map`` to the sub-commands."""
    p = add_command(
        subparsers, "map", help="stability of a grid by simulation; write CSV or NPZ and a PNG",
        description="Simulate every point of a stiffness-damping grid and write which are "
                    "stable (CSV or NPZ, with the root count of the loop simulated beside, its "
                    "linear part with the filter and the actuator lag) and a PNG of the map with "
                    "that loop's boundary, in the units of the grid.",
        example="symstab map --Td 0.01 --Kw 0,50,100 --Bw=-0.1,1.8,100 --paper-encoder "
                "--velocity-cutoff 50 --out map.npz",
        func=run)
    add_model_options(p)
    add_nonideal_options(p)
    p.add_argument("--alpha", metavar="LOW,HIGH,N", help="alpha grid (write --alpha=LOW,... "
                                                           "when LOW is negative)")
    p.add_argument("--beta", metavar="LOW,HIGH,N", help="beta grid (--beta=-0.01,0.3,100)")
    p.add_argument("--Kw", metavar="LOW,HIGH,N", help="K_w grid (physical)")
    p.add_argument("--Bw", metavar="LOW,HIGH,N", help="B_w grid (physical; --Bw=-0.1,3,100)")
    p.add_argument("--out", required=True, help="output file, .csv or .npz")
    p.add_argument("--png", help="PNG file (default: --out with .png)")
    p.add_argument("--no-png", action="store_true", help="do not draw the PNG")
    add_loop_options(p, "map")


def run(args):
    """Run ``symstab map`` (on the loop file of ``--loop``, else the paper's loop)."""
    if args.format != "table":
        raise ValueError(f"--format {args.format}: map writes its cells with --out (.csv or "
                         f".npz)")
    if not uses_loop(args):
        return _map(_PaperMap(args))
    setup = resolve_loop(args)
    if args.x_range is None or args.y_range is None:
        raise ValueError("map --loop needs the grid: --x-range LOW,HIGH,N and --y-range LOW,HIGH,N")
    xs, ys = _grid(args.x_range, "--x-range"), _grid(args.y_range, "--y-range")
    out, png_path = map_outputs(args)
    given = [flag for flag, dest in (("--uncertain", "uncertain"), ("--margin", "margin"),
                                     ("--delay-range", "delay_range"))
             if getattr(args, dest) is not None]
    if len(given) > 1:
        raise ValueError(f"{' and '.join(given)} each map something else (the probability of "
                         f"stability, a margin, the sets of a delay range): give one of them")
    if args.uncertain is not None:
        return _probability(args, setup, xs, ys, out, png_path)
    if args.margin is not None:
        return _margin(args, setup, xs, ys, out, png_path)
    if args.delay_range is not None:
        return _delay_range(args, setup, xs, ys, out, png_path)
    return _map(_LoopMap(args, setup, xs, ys, out, png_path))


def _map(plan):
    """One map, of the paper's loop or of a loop file: ``plan`` checked, run, written, said.

    ``plan`` (a :class:`_PaperMap` or a :class:`_LoopMap`) has checked
    every input and decided the memory before anything is printed; here it
    classifies the cells by their root counts, simulates them (the paper's
    loop always, a loop file with ``--simulate``), writes the table and
    the PNG, and says what it found.
    """
    for line in plan.echo:
        print(line)
    code = plan.classify()
    simulated = plan.simulate()
    data = plan.table(code, simulated)
    image = plan.png(code, simulated) if plan.png_path is not None else None
    wrote = _write_map(plan.out, data, plan.png_path, image)
    for line in plan.summary(code, simulated):
        print(line)
    print(wrote)
    return 0


def _simulated_line(stable, limit_cycle, code, steps, conditions, against):
    """The map's line on its simulation: how many cells are stable, cycle, differ from ``code``.

    ``stable`` and ``limit_cycle`` in the orientation of ``code``.
    """
    from ..numeric.engine.roots import MARGINAL, STABLE

    decided = code != MARGINAL
    differ = int(np.count_nonzero((stable != (code == STABLE)) & decided))
    return (f"{int(stable.sum())} of {stable.size} cells stable by simulation, "
            f"{int(limit_cycle.sum())} bounded limit cycles ({steps} periods{conditions}); "
            f"{differ} of the {int(decided.sum())} cells that are not marginal differ from "
            f"{against}")


#: Largest number of grid points along one axis of ``symstab map``.
MAX_GRID = 2000


def _grid(text, name):
    parts = text.split(",")
    if len(parts) != 3:
        raise ValueError(f"{name} must be LOW,HIGH,N, got {text!r}")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise ValueError(f"{name} must be LOW,HIGH,N with a whole N, got {text!r}") from None
    # HIGH - LOW must be finite too: linspace takes it (1e308 - -1e308 is inf).
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi and np.isfinite(hi - lo)
            and 2 <= n <= MAX_GRID):
        raise ValueError(f"{name} must have finite LOW < HIGH (and HIGH - LOW finite) and "
                         f"2 <= N <= {MAX_GRID}, got {text!r}")
    return np.linspace(lo, hi, n)


def map_outputs(args):
    """``(out, png)`` paths of ``map``, checked before any work (png None with --no-png).

    ``--out`` must be a .csv or .npz file; the PNG defaults to ``--out``
    with the suffix .png.
    """
    if not args.out.endswith((".csv", ".npz")):
        raise ValueError(f"--out must end in .csv or .npz, got {args.out}")
    if args.no_png and args.png is not None:
        raise ValueError("give --png or --no-png, not both")
    png = None if args.no_png else (
        str(pathlib.Path(args.out).with_suffix(".png")) if args.png is None else args.png)
    paths = check_files([("--out", args.out), ("--png", png)])
    return paths["--out"], paths.get("--png")


class _PaperMap:
    """``symstab map`` of the paper's loop: simulated at every cell, its theory's root count beside.

    The loop simulated is the paper's with the non-idealities of the options
    (:mod:`symstab.cli.simulation`), its filter and lag in it; its linear
    part is the theory, classified before the run so that a refusal costs no
    simulation.  Everything is checked at construction.
    """

    def __init__(self, args):
        from ..numeric.paper.simulate import check_device_nonideal
        from ..numeric.simulation.simulator import check_steps

        self.args = args
        setup = self.setup = resolve(args)
        self.nonideal, self.x0 = resolve_nonideal(args, setup)
        given = self.given = {}  # the grids as the user gave them, by flag: the PNG's units

        def grid(text, flag):
            given[flag] = _grid(text, flag)
            return given[flag]

        alpha, beta = (np.atleast_1d(x) for x in stiffness_and_damping(args, setup, grid))
        self.alpha, self.beta = alpha, beta
        self.out, self.png_path = map_outputs(args)
        check_memory(f"a map of {alpha.size} x {beta.size} cells",
                     alpha.size * beta.size * _MAP_CELL_BYTES)
        # A fractional delay's horizon: that of the next whole delay.
        self.steps = check_steps(args.steps, math.ceil(setup.d))
        # The loop simulated, classified by its roots before the simulation (a
        # refusal then costs no run): its linear part, filter and lag included.
        self.theory = simulated_theory(setup, self.nonideal)
        A, B = np.meshgrid(alpha, beta, indexing="ij")
        self.code = self.theory.classify(A, B)
        if setup.physical:
            try:
                # The simulator's own checks (the friction against the device), before the echo.
                check_device_nonideal(self.nonideal, setup.device)
            except ValueError as exc:
                raise with_option_names(exc) from None
        self.echo = setup.echo

    def classify(self):
        """The root counts of the loop simulated, ``(alpha, beta)``."""
        return self.code

    def simulate(self):
        """The paper's loop simulated at every cell (the paper's adapter on the loop simulator)."""
        from .._progress import progress_printer
        from ..numeric.paper.simulate import stability_map

        setup = self.setup
        return stability_map(alpha=self.alpha, beta=self.beta, gamma=setup.gamma, d=setup.d,
                             delta=None if setup.physical else setup.delta, steps=self.steps,
                             x0=self.x0, device=setup.device, nonideal=self.nonideal,
                             progress=progress_printer("simulating", self.steps))

    def _physical(self):
        """K_w and B_w beside alpha and beta, in the units of the echo (none without a device)."""
        setup, alpha, beta = self.setup, self.alpha, self.beta
        if not setup.physical:
            return {}
        dev = setup.device
        return {"K_w": self.given.get("--Kw", np.atleast_1d(dev.stiffness(alpha))),
                "B_w": self.given.get("--Bw", np.atleast_1d(dev.damping(beta)))}

    def table(self, code, result):
        """The map's file: NPZ bytes or CSV text, by the suffix of ``--out``."""
        from ..numeric.engine.roots import STABLE

        setup, alpha, beta, steps = self.setup, self.alpha, self.beta, self.steps
        exact = code == STABLE
        physical = self._physical()
        if self.out.suffix == ".npz":
            buf = io.BytesIO()
            units = {f"{name}_unit": np.array(setup.units[name]) for name in physical}
            np.savez(buf, alpha=alpha, beta=beta, **physical, **units, stable=result.stable,
                     limit_cycle=result.limit_cycle, growth=result.growth, exact_stable=exact,
                     exact_code=code, gamma=setup.gamma, d=setup.d, delta=setup.delta,
                     steps=steps, nonidealities=np.array(nonideal_text(self.nonideal, self.args)),
                     theory=np.array(self.theory.description))
            return buf.getvalue()
        A, B = np.meshgrid(alpha, beta, indexing="ij")
        buf = io.StringIO()
        columns = ["alpha", "beta"] + [f"{name} [{setup.units[name]}]" for name in physical]
        buf.write(",".join(columns + ["stable", "limit_cycle", "exact_stable", "growth"]) + "\n")
        cells = [A.ravel(), B.ravel()]
        if physical:
            K, Bw = np.meshgrid(physical["K_w"], physical["B_w"], indexing="ij")
            cells += [K.ravel(), Bw.ravel()]
        for *values, s, c, e, g in zip(*cells, result.stable.ravel(),
                                       result.limit_cycle.ravel(), exact.ravel(),
                                       result.growth.ravel(), strict=True):
            buf.write(",".join(f"{v:.12g}" for v in values)
                      + f",{int(s)},{int(c)},{int(e)},{g:.6g}\n")
        return buf.getvalue().encode()

    def png(self, code, result):
        """The map's PNG bytes (None without matplotlib)."""
        return _paper_png(self.args, self.setup, result, self.nonideal, self.given, self.theory)

    def summary(self, code, result):
        """The lines that say what the map found."""
        return [_simulated_line(result.stable, result.limit_cycle, code, self.steps, "",
                                f"the root-counting classification of the "
                                f"{self.theory.description}")]


def _keep_nan(convert):
    """``convert`` (a Device's, which refuses NaN) applied to the finite entries only."""
    def apply(values):
        values = np.asarray(values, dtype=float)
        out = np.full(values.shape, np.nan)
        finite = np.isfinite(values)
        out[finite] = convert(values[finite])
        return out
    return apply


def _map_axes(setup, given, result):
    """``(x, y, x label, y label, to_x, to_y)`` in the units of the grids the user gave.

    ``to_x``/``to_y`` convert beta/alpha (the boundary curve) to the axes,
    keeping the NaN that break a curve between its branches.
    """
    dev, units = setup.device, setup.units
    if "--Bw" in given:
        x, xlabel, to_x = given["--Bw"], f"$B_w$ [{tex_unit(units['B_w'])}]", _keep_nan(dev.damping)
    else:
        x, xlabel, to_x = result.beta, r"$\beta = B_w T / m$", np.asarray
    if "--Kw" in given:
        y, ylabel, to_y = given["--Kw"], f"$K_w$ [{tex_unit(units['K_w'])}]", _keep_nan(dev.stiffness)
    else:
        y, ylabel, to_y = result.alpha, r"$\alpha = K_w T^2 / m$", np.asarray
    return x, y, xlabel, ylabel, to_x, to_y


def _map_title(setup, nonideal, args, steps_text):
    if setup.physical:
        dev, units = setup.device, setup.units
        loop = (f"$T_d$ = {dev.delay(setup.d) * 1e3:g} ms (d = {setup.d}), "
                f"$M_w$ = {float(dev.mass(setup.gamma)):g} {tex_unit(units['M_w'])}")
    else:
        loop = f"$\\delta$ = {setup.delta:g}, d = {setup.d}, $\\gamma$ = {setup.gamma:g}"
    return (f"stable by simulation (green, {steps_text}); {loop}\n"
            f"{nonideal_text(nonideal, args)}")


def _paper_png(args, setup, result, nonideal, given, theory):
    """The map as PNG bytes, or None without matplotlib (:func:`~symstab.drawing.png_or_none`).

    Drawn in the units of the grids the user gave (K_w, B_w or alpha, beta),
    with the non-idealities of the simulation in the title and the boundary
    of the loop simulated (its linear part, ``theory``) over it.
    """
    x, y, xlabel, ylabel, to_x, to_y = _map_axes(setup, given, result)
    arc_beta, arc_alpha, lines = theory.boundary(((result.beta[0], result.beta[-1]),
                                                  (result.alpha[0], result.alpha[-1])))
    name = ("the ideal loop, eq. (7)" if theory.loop is None
            else f"the {theory.label} (D-decomposition)")
    # result's arrays are (alpha, beta): y by x, as the map is drawn.
    return png_or_none(
        simulated_map_figure, x, y, result.stable, result.limit_cycle,
        boundary={"curve": (arc_beta, arc_alpha), "label": f"boundary of {name}", "lines": lines,
                  "plane": (result.beta, result.alpha), "to_x": to_x, "to_y": to_y},
        xlabel=xlabel, ylabel=ylabel,
        title=_map_title(setup, nonideal, args, f"{result.steps} periods"))


#: The simulation options ``map --loop`` takes with ``--simulate`` only.
_LOOP_SIMULATION_OPTIONS = (("--steps", "steps"), ("--x0", "x0"),
                            ("--encoder-resolution", "encoder_resolution"),
                            ("--paper-encoder", "paper_encoder"),
                            ("--force-limit", "force_limit"),
                            ("--force-resolution", "force_resolution"), ("--coulomb", "coulomb"),
                            ("--stiction", "stiction"), ("--substeps", "substeps"))


class _LoopMap:
    """``symstab map --loop``: a loop file's root counts at every cell, and its simulation.

    Classified by the certified root counts a chunk of x at a time; with
    ``--simulate`` also simulated (:meth:`symstab.Loop.stability_map`:
    encoder quantization, force saturation, Coulomb friction on the driven
    mass).  Everything is checked at construction.
    """

    def __init__(self, args, setup, xs, ys, out, png_path):
        for flag, dest in (("--samples", "samples"), ("--seed", "seed")):
            if getattr(args, dest) is not None:
                raise ValueError(f"{flag} counts the draws of --uncertain: add --uncertain "
                                 f"NAME=LO:HI")
        self.setup, self.xs, self.ys, self.out, self.png_path = setup, xs, ys, out, png_path
        loop, values = setup.loop, setup.values
        self.nonideal, self.x0, self.steps = _loop_simulation(args, setup, xs, ys)
        self.degree = loop.coefficients(**{setup.x: 0.0, setup.y: 0.0}, **values).shape[-1]
        # The cells are classified a chunk of x at a time; what stays is the codes
        # and the file's text.
        check_memory(f"a map of {xs.size} x {ys.size} cells",
                     xs.size * ys.size * _MAP_CELL_BYTES
                     + max(CHUNK_BYTES, ys.size * _BYTES_PER_COEFFICIENT * self.degree))
        self.echo = [LOOP_SIMULATE_HEADLINE if self.steps is not None else LOOP_MAP_HEADLINE,
                     *setup.echo]

    def classify(self):
        """The certified root counts, ``(x, y)``."""
        from .._progress import progress_printer

        setup, xs, ys = self.setup, self.xs, self.ys
        code = np.empty((xs.size, ys.size), dtype=np.int8)
        progress = progress_printer("classifying", xs.size)
        for part in chunk_slices(xs.size, ys.size * _BYTES_PER_COEFFICIENT * self.degree,
                                 CHUNK_BYTES):
            X, Y = np.meshgrid(xs[part], ys, indexing="ij")
            code[part] = setup.loop.classify(**{setup.x: X, setup.y: Y}, **setup.values)
            progress(part.stop)
        return code

    def simulate(self):
        """The loop simulated at every cell (``(y, x)``), or None without ``--simulate``."""
        from .._progress import progress_printer

        if self.steps is None:
            return None
        setup = self.setup
        return setup.loop.stability_map(self.xs, self.ys, x=setup.x, y=setup.y,
                                        steps=self.steps, x0=self.x0, nonideal=self.nonideal,
                                        progress=progress_printer("simulating", self.steps),
                                        **{k: v for k, v in setup.values.items()})

    def table(self, code, simulated):
        """The map's file: NPZ bytes or CSV text, by the suffix of ``--out``."""
        from ..numeric.engine.roots import STABLE

        setup, xs, ys = self.setup, self.xs, self.ys
        if self.out.suffix != ".npz":
            return _loop_csv(setup, xs, ys, code, simulated)
        extra = {} if simulated is None else {
            "simulated_stable": simulated.stable.T,
            "simulated_limit_cycle": simulated.limit_cycle.T, "growth": simulated.growth.T,
            "steps": self.steps, "x0": self.x0,
            "nonidealities": np.array(loop_nonideal_text(self.nonideal))}
        return _loop_npz(setup, xs, ys, setup.values, code=code, stable=code == STABLE, **extra)

    def png(self, code, simulated):
        """The map's PNG bytes (None without matplotlib)."""
        return _loop_png(self.setup, self.xs, self.ys, code, simulated)

    def summary(self, code, simulated):
        """The lines that say what the map found."""
        from ..numeric.engine.roots import MARGINAL, STABLE

        lines = [f"{int((code == STABLE).sum())} of {code.size} cells stable, "
                 f"{int((code == MARGINAL).sum())} marginal (code 1 stable, 0 marginal, -1 "
                 f"unstable; certified root counts)"]
        if simulated is not None:
            lines.append(_simulated_line(simulated.stable.T, simulated.limit_cycle, code,
                                         self.steps, f"; {loop_nonideal_text(self.nonideal)}",
                                         "the root counts (a limit cycle is not stable)"))
        return lines


def _loop_simulation(args, setup, xs, ys):
    """``(nonideal, x0, steps)`` of ``map --loop --simulate``, checked before any work.

    Without ``--simulate``: ``(None, None, None)``, and a simulation option
    given is refused.
    """
    from ..numeric.simulation.simulator import check_steps

    loop, values = setup.loop, setup.values
    if not args.simulate:
        for flag, dest in _LOOP_SIMULATION_OPTIONS:
            if getattr(args, dest) not in (None, False):
                raise ValueError(f"{flag} is an option of the simulation: add --simulate")
        return None, None, None
    nonideal, x0 = resolve_nonideal(args, None, loop)
    # A fractional delay's horizon: that of the next whole delay.
    steps = check_steps(args.steps, math.ceil(values["d"]))
    # The difference equations at one cell: a plant they cannot step is refused now.
    loop.difference_equations(**{setup.x: xs[0], setup.y: ys[0]}, **values)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    check_loop_friction(nonideal, loop, {setup.x: X, setup.y: Y, **values})
    return nonideal, x0, steps


def _loop_csv(setup, xs, ys, code, simulated=None):
    """A loop map's CSV text: a row a cell, its root count, and its simulation where one ran."""
    from ..numeric.engine.roots import STABLE

    X, Y = np.meshgrid(xs, ys, indexing="ij")
    buf = io.StringIO()
    buf.write(f"{setup.label(setup.x)},{setup.label(setup.y)},code,stable"
              + (",simulated_stable,simulated_limit_cycle,growth" if simulated is not None
                 else "") + "\n")
    columns = [X.ravel(), Y.ravel(), code.ravel()]
    if simulated is not None:
        columns += [simulated.stable.T.ravel(), simulated.limit_cycle.T.ravel(),
                    simulated.growth.T.ravel()]
    for xv, yv, c, *sim in zip(*columns, strict=True):
        row = f"{xv:.12g},{yv:.12g},{int(c)},{int(c == STABLE)}"
        if sim:
            row += f",{int(sim[0])},{int(sim[1])},{sim[2]:.6g}"
        buf.write(row + "\n")
    return buf.getvalue()


def _loop_npz(setup, xs, ys, values, **arrays):
    """A loop map's NPZ bytes: its grid, names, units, fixed values and file, and ``arrays``."""
    buf = io.BytesIO()
    np.savez(buf, x=xs, y=ys, x_name=np.array(setup.x), y_name=np.array(setup.y),
             x_unit=np.array(setup.unit(setup.x)), y_unit=np.array(setup.unit(setup.y)),
             **arrays, values=np.array([value_text(setup, n, values[n])
                                        for n in setup.loop.parameters if n in values]),
             loop=np.array(str(setup.path)))
    return buf.getvalue()


def _write_map(out, data, png_path, image):
    """The map's file and its PNG (None: none) written atomically; the line that says so."""
    write_output(out, data, "--out")
    written = [str(out)]
    if image is not None:
        write_output(png_path, image, "--png")
        written.append(str(png_path))
    return "wrote " + ", ".join(written)


def _probability(args, setup, xs, ys, out, png_path):
    """``map --loop --uncertain``: the probability of stability of every cell, its files and PNG."""
    from .._progress import progress_printer
    from ..numeric.analysis.probability import MAX_SAMPLES, draw_values

    if args.simulate:
        raise ValueError("--uncertain maps the probability of stability by root counts; "
                         "--simulate simulates the nominal loop: give one of them")
    for flag, dest in _LOOP_SIMULATION_OPTIONS:
        if getattr(args, dest) not in (None, False):
            raise ValueError(f"{flag} is an option of the simulation; --uncertain maps root "
                             f"counts: drop {flag}")
    loop, x, y = setup.loop, setup.x, setup.y
    box = uncertain_box(args, setup)
    samples = 1000 if args.samples is None else args.samples
    seed = 0 if args.seed is None else args.seed
    if not 1 <= samples <= MAX_SAMPLES:
        raise ValueError(f"--samples must be an integer from 1 to {MAX_SAMPLES}, got {samples}")
    if seed < 0:
        raise ValueError(f"--seed must be a non-negative integer, got {seed}")
    # Checked now (the counts, the seed, a delay's range), before anything is printed.
    draw_values(loop, box, samples, seed, axes=(x, y))
    # The delay drawn (d or Td) replaces the file's, in either form.
    delay = {"d", "Td"} if {"d", "Td"} & set(box) else set()
    fixed = {k: v for k, v in setup.values.items() if k not in box and k not in delay}
    check_memory(f"a map of {xs.size} x {ys.size} cells", xs.size * ys.size * _MAP_CELL_BYTES
                 + CHUNK_BYTES)
    print(LOOP_PROBABILITY_HEADLINE)
    for line in setup.echo:
        print(line)
    found = loop.stability_probability(xs, ys, x=x, y=y, uncertain=box, samples=samples,
                                       seed=seed, progress=progress_printer("drawing", samples),
                                       **fixed)
    drawn = [f"{name} ~ {text}" + (f" {setup.unit(name)}" if name != "d" and setup.unit(name)
                                   else "") for name, text in found.uncertain.items()]
    p, error, marginal = found.probability.T, found.standard_error.T, found.marginal.T
    if out.suffix == ".npz":
        data = _loop_npz(setup, xs, ys, fixed, probability=p, standard_error=error,
                         marginal=marginal, samples=samples, seed=seed,
                         uncertain=np.array(drawn))
    else:
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        buf = io.StringIO()
        buf.write(f"{setup.label(x)},{setup.label(y)},probability,standard_error,marginal\n")
        for row in zip(X.ravel(), Y.ravel(), p.ravel(), error.ravel(), marginal.ravel(),
                       strict=True):
            buf.write(f"{row[0]:.12g},{row[1]:.12g},{row[2]:.6g},{row[3]:.3g},{int(row[4])}\n")
        data = buf.getvalue()
    image = _probability_png(setup, found, fixed, drawn) if png_path is not None else None
    wrote = _write_map(out, data, png_path, image)
    between = int(np.count_nonzero((p > 0) & (p < 1)))
    print(f"{samples} draws of {', '.join(drawn)} (seed {seed}): stable at every draw in "
          f"{int(np.count_nonzero(p == 1))} of {p.size} cells, at none in "
          f"{int(np.count_nonzero(p == 0))}, at some in {between} (largest standard error "
          f"{float(error.max()):.2g}); marginal draws, counted as not stable: "
          f"{int(marginal.sum())}")
    print(wrote)
    return 0


def _margin(args, setup, xs, ys, out, png_path):
    """``map --loop --margin``: a margin at every stable cell (NaN elsewhere), its file and PNG."""
    _only_linear(args, "--margin", "a margin")
    check_memory(f"a map of {xs.size} x {ys.size} cells", xs.size * ys.size * _MAP_CELL_BYTES
                 + CHUNK_BYTES)
    what = {"modulus": "the modulus margin min|1+L|, certified",
            "delay": "the exact delay margin in samples, fractional (inf: stable up to the "
                     "limit)",
            "gain": "the gain margin (inf: no phase crossover limits the gain)"}
    print(f"map --loop --margin {args.margin}: {what[args.margin]}, of every stable cell "
          f"(NaN where not stable)")
    for line in setup.echo:
        print(line)
    found = setup.loop.margin_map(xs, ys, x=setup.x, y=setup.y, margin=args.margin,
                                  **setup.values)
    value, lower = found.values.T, found.lower.T
    if out.suffix == ".npz":
        data = _loop_npz(setup, xs, ys, setup.values, margin=value, lower=lower,
                         code=found.codes.T)
    else:
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        buf = io.StringIO()
        buf.write(f"{setup.label(setup.x)},{setup.label(setup.y)},{args.margin},lower\n")
        for row in zip(X.ravel(), Y.ravel(), value.ravel(), lower.ravel(), strict=True):
            buf.write(",".join(f"{v:.12g}" for v in row) + "\n")
        data = buf.getvalue()
    image = (png_or_none(_margin_figure, setup, found, xs, ys) if png_path is not None
             else None)
    wrote = _write_map(out, data, png_path, image)
    stable = ~np.isnan(value)
    if not stable.any():
        print(f"no stable cell among the {value.size}: the map holds NaN only")
    else:
        low, high, unit = np.nanmin(value), np.nanmax(value), ""
        finite = value[np.isfinite(value)]
        if args.margin == "delay" and finite.size:
            low, high, unit = finite.min(), finite.max(), " samples"
            # In ms too where the sample period is one value (not an axis of the map).
            period = {**setup.loop.defaults, **setup.values}.get("T")
            if period is not None and "T" not in (setup.x, setup.y):
                unit += f" ({low * period * 1e3:.4g} to {high * period * 1e3:.4g} ms)"
        print(f"{int(stable.sum())} of {value.size} cells stable; {args.margin} margin from "
              f"{low:.4g} to {high:.4g}{unit}")
    if args.margin == "delay" and np.isinf(value).any():
        print(f"{int(np.isinf(value).sum())} cells stable up to {found.delay_limit:g} samples "
              f"more (inf in the file)")
    print(wrote)
    return 0


def _delay_range(args, setup, xs, ys, out, png_path):
    """``map --loop --delay-range``: the cells stable for every constant and every varying delay."""
    from .loop_options import delay_range_option

    _only_linear(args, "--delay-range", "the sets of a delay range")
    delays = delay_range_option(args.delay_range, setup.loop, setup.values)
    values = {k: v for k, v in setup.values.items() if k not in ("d", "Td")}
    check_memory(f"a map of {xs.size} x {ys.size} cells", xs.size * ys.size * _MAP_CELL_BYTES
                 + CHUNK_BYTES)
    print(f"map --loop --delay-range: the cells stable for every constant delay from "
          f"{delays[0] * 1e3:.6g} to {delays[1] * 1e3:.6g} ms (the exact delay margin) and for "
          f"every delay varying in it by whole samples (small-gain bound, sufficient only)")
    for line in setup.echo:
        print(line)
    found = setup.loop.delay_range(xs, ys, x=setup.x, y=setup.y, delay_range=delays, **values)
    constant = found.constant.T
    varying = None if found.varying is None else found.varying.T
    if out.suffix == ".npz":
        extra = {} if varying is None else {"varying": varying}
        data = _loop_npz(setup, xs, ys, setup.values, constant=constant,
                         samples=np.array(found.samples), **extra)
    else:
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        column = (varying if varying is not None else np.full(constant.shape, -1)).ravel()
        buf = io.StringIO()
        buf.write(f"{setup.label(setup.x)},{setup.label(setup.y)},constant,varying\n")
        for xv, yv, c, v in zip(X.ravel(), Y.ravel(), constant.ravel(), column, strict=True):
            buf.write(f"{xv:.12g},{yv:.12g},{int(c)},{int(v)}\n")
        data = buf.getvalue()
    image = (png_or_none(_delay_range_figure, setup, found) if png_path is not None else None)
    wrote = _write_map(out, data, png_path, image)
    low, high = found.samples
    print(f"{int(constant.sum())} of {constant.size} cells stable for every constant delay of "
          f"{low:.6g} to {high:.6g} samples")
    print(f"{int(varying.sum())} of {varying.size} cells stable for every delay varying by whole "
          f"samples" if varying is not None else
          "every varying delay: not derived (the range's ends do not differ by whole samples; the "
          "varying column holds -1)")
    print(wrote)
    return 0


def _only_linear(args, flag, what):
    """Refuse the simulation's options beside ``flag``, a map of ``what`` of the linear loop."""
    if args.simulate:
        raise ValueError(f"{flag} maps {what} of the linear loop; --simulate simulates it: give "
                         f"one of them")
    for option, dest in _LOOP_SIMULATION_OPTIONS:
        if getattr(args, dest) not in (None, False):
            raise ValueError(f"{option} is an option of the simulation: drop it with {flag}")


def _delay_range_figure(plt, setup, found):
    """The delay-range map's figure: the two sets, labelled in the loop's units."""
    drawn = found.plot()
    labels = _axis_labels(setup)
    drawn.axes.set_xlabel(labels["xlabel"])
    drawn.axes.set_ylabel(labels["ylabel"])
    low, high = found.samples
    drawn.axes.set_title(f"loop {setup.loop.name}: stable for delays of {low:.6g} to "
                         f"{high:.6g} samples")
    return drawn.figure


def _margin_figure(plt, setup, found, xs, ys):
    """The margin map's figure: filled contours under the D-decomposition of the window."""
    region = setup.loop.region(x=setup.x, y=setup.y, x_range=(xs[0], xs[-1]),
                               y_range=(ys[0], ys[-1]), **setup.values)
    drawn = found.plot(region=region)
    labels = _axis_labels(setup)
    drawn.axes.set_xlabel(labels["xlabel"])
    drawn.axes.set_ylabel(labels["ylabel"])
    drawn.axes.set_title(f"loop {setup.loop.name}: {found.margin} margin (blank: not stable)")
    return drawn.figure


def _probability_png(setup, found, fixed, drawn):
    """The probability map as PNG bytes (None without matplotlib), the nominal boundary over it."""
    xs, ys = found.x_values, found.y_values
    rest = ", ".join(value_text(setup, n, fixed[n]).replace(" ", "\u00a0")
                     for n in setup.loop.parameters if n in fixed)
    title = "\n".join([f"loop {setup.loop.name}: probability of stability, "
                       f"{found.samples} draws"] + textwrap.wrap(", ".join(drawn), 80)
                      + textwrap.wrap(rest, 80))
    return png_or_none(probability_map_figure, found, _boundary(setup, xs, ys),
                       **_axis_labels(setup), title=title)


def _boundary(setup, xs, ys):
    """The loop's D-decomposition at ``setup.values`` over the map's window."""
    return setup.loop.boundary(x=setup.x, y=setup.y, window=((xs[0], xs[-1]), (ys[0], ys[-1])),
                               **setup.values)


def _axis_labels(setup):
    """The map's axes' names with their units: ``{"xlabel": ..., "ylabel": ...}``."""
    labels = {}
    for name, key in ((setup.x, "xlabel"), (setup.y, "ylabel")):
        unit = setup.unit(name)
        labels[key] = f"{name} [{tex_unit(unit)}]" if unit else name
    return labels


def _loop_png(setup, xs, ys, code, simulated=None):
    """The map as PNG bytes (None without matplotlib), with the D-decomposition drawn over it.

    Shaded by the root counts, or by the simulation (``simulated``, a
    :class:`~symstab.numeric.simulation.simulator.StabilityMap`) where one ran: its
    stable cells and its bounded limit cycles, each its own colour; the
    D-decomposition drawn over it is the root counts' boundary.
    """
    from ..numeric.engine.roots import MARGINAL, STABLE

    loop, x, y = setup.loop, setup.x, setup.y
    if simulated is None:
        shade = np.where(code == STABLE, 2, np.where(code == MARGINAL, 1, 0)).T
    else:
        shade = np.where(simulated.stable, 2, np.where(simulated.limit_cycle, 3, 0))
    legend = [("#7fc97f", "stable" if simulated is None else "stable by simulation")]
    if simulated is None and np.any(code == MARGINAL):
        legend.append(("#bdbdbd", "marginal"))
    if simulated is not None and np.any(simulated.limit_cycle):
        legend.append((LIMIT_CYCLE_COLOR, LIMIT_CYCLE_LABEL))
    # Wrapped to the width of the figure (a two-mass device has eight values),
    # between values only: no-break spaces inside each.
    fixed = ", ".join(value_text(setup, n, setup.values[n]).replace(" ", "\u00a0")
                      for n in loop.parameters if n in setup.values)
    how = "root counts" if simulated is None else "simulated; lines: root counts"
    title = "\n".join([f"loop {loop.name}: stable set in the ({x}, {y}) plane ({how})"]
                      + textwrap.wrap(fixed, 80))
    return png_or_none(loop_map_figure, xs, ys, shade, legend, _boundary(setup, xs, ys),
                       **_axis_labels(setup), title=title)
